"""Tooth-pair contact by FE influence coefficients (fem.pair): equilibrium,
complementarity, contact zones, wear, the Weber local term, and the FE body
compliance against the Ishikawa/Weber slice model with the extra physics switched off."""

import math
import time

import numpy as np
import pytest

from analytic.ishikawa import hertz_approach_m
from geometry.spec import default_pair
from geometry.wear import WearSpec
from fem.pair import compare_with_analytic, pair_contact, weber_approach_m


@pytest.fixture(scope="module")
def pair():
    return default_pair()


@pytest.fixture(scope="module")
def nominal(pair):
    # reduced run: 8 positions (the analytic model needs >= 8), coarse mesh (mesh_scale 4: ~2 % from the converged mean)
    return pair_contact(pair, positions=8, mesh_scale=4.0)


@pytest.fixture(scope="module")
def severe(pair):
    return pair_contact(pair, wear=WearSpec(phase="severe"), positions=8, mesh_scale=4.0)


def test_loads_sum_to_total_and_stay_in_path(nominal, severe):
    for r in (nominal, severe):
        F = r.total_load_N
        assert F == pytest.approx(40.0 / r.pair.gear(0).base_radius_m)
        assert np.all(np.abs(r.pair_load_N.sum(axis=1) - F) <= 1e-9 * F)
        assert np.all(r.pair_load_N >= 0.0)
        assert np.all(r.pair_load_N[~r.pair_in_path] == 0.0)


def test_stiffness_positive_and_secant_definition(nominal):
    r = nominal
    assert np.all(r.k_N_per_m > 0) and np.all(r.ste_m > 0)
    # unworn: k = sum F_k / STE = F / STE, no excitation
    assert r.k_N_per_m == pytest.approx(r.total_load_N / r.ste_m, rel=1e-12)
    assert np.all(r.excitation_m == 0.0)
    # Weber's approach is concave in F (F ln(1/F)): the tangent stiffness is higher
    assert np.all(r.k_tangent_N_per_m > r.k_N_per_m)


def test_single_and_double_contact_zones(nominal):
    r = nominal
    z = r.zone_masks()
    dbl = z["A"] | z["C"]
    assert dbl.any() and z["B"].any()
    assert np.all(r.pairs_in_contact[dbl] == 2) and np.all(r.pairs_in_contact[z["B"]] == 1)
    zm = r.zone_means()
    assert zm["double"] > 1.3 * zm["single"]


def test_slot_to_tooth_mapping_gives_one_line_of_action(nominal):
    # simultaneous contact forces on each gear share one direction (the LOA)
    assert nominal.meta["direction_mismatch_rad"] < 1e-9
    # identical unworn gears share one factorized body
    assert nominal.meta["shared_body"]


def test_angles_and_slots_as_analytic(nominal):
    cmp = compare_with_analytic(nominal)
    an = cmp["analytic"]
    assert np.array_equal(an.angle_rad, nominal.angle_rad)
    assert np.allclose(an.pair_d_m, nominal.pair_d_m, rtol=0, atol=1e-15)
    assert np.array_equal(an.pair_in_path, nominal.pair_in_path)
    assert np.array_equal(an.pairs_in_contact, nominal.pairs_in_contact)
    assert np.isfinite(cmp["mean_rel_diff"]) and cmp["per_position_rel_diff"].shape == (8,)


def test_severe_wear_meshes_and_runs(nominal, severe):
    r = severe
    assert not r.meta["shared_body"]  # worn flanks: each gear has its own mesh
    assert np.all(r.k_N_per_m > 0)
    # the wear gap opens: the STE grows and a wear excitation appears
    assert np.all(r.ste_m > nominal.ste_m)
    assert np.all(r.excitation_m > 0)
    # worn secant stiffness: F = k (STE - e)
    assert r.total_load_N == pytest.approx(0.0 + r.k_N_per_m[0] * (r.ste_m[0] - r.excitation_m[0]), rel=1e-10)


def test_weber_formula_by_hand():
    F, h1, h2, R, E, nu, b = 500.0, 3.5e-3, 3.2e-3, 12e-3, 206e9, 0.3, 0.02
    a = math.sqrt(4 * (F / b) * R / (math.pi * E / (2 * (1 - nu ** 2))))
    ref = 2 * F * (1 - nu ** 2) / (math.pi * E * b) * (math.log(2 * h1 / a) + math.log(2 * h2 / a) - nu / (1 - nu))
    assert weber_approach_m(F, h1, h2, R, E, nu, b) == pytest.approx(ref, rel=1e-14)
    # plane stress: 1/E instead of (1 - nu^2)/E and nu instead of nu/(1 - nu)
    a_s = math.sqrt(4 * (F / b) * R / (math.pi * E / 2))
    ref_s = 2 * F / (math.pi * E * b) * (math.log(2 * h1 / a_s) + math.log(2 * h2 / a_s) - nu)
    assert weber_approach_m(F, h1, h2, R, E, nu, b, plane="stress") == pytest.approx(ref_s, rel=1e-14)
    assert weber_approach_m(0.0, h1, h2, R, E, nu, b) == 0.0


def test_bad_inputs(pair):
    with pytest.raises(ValueError):
        pair_contact(pair, positions=1)
    with pytest.raises(ValueError):
        pair_contact(pair, torque_Nm=-1.0)
    with pytest.raises(ValueError):
        pair_contact(pair, local_contact="hertz3d")


@pytest.mark.slow
def test_fe_body_matches_slice_model_without_extra_physics(pair):
    """With what the Ishikawa model leaves out switched off (no coupling between teeth
    through the rim, its Hertz law Eq. 5) and plane strain, the FE bodies reproduce the
    Ishikawa/Weber slice compliance: the mean mesh stiffness within 5 %."""
    r = pair_contact(pair, positions=8, mesh_scale=2.0, plane="strain", coupling=False, local_contact="eq5")
    cmp = compare_with_analytic(r)
    assert abs(cmp["mean_rel_diff"]) < 0.05, cmp["mean_rel_diff"]
    # the rim coupling makes the full model softer in double contact
    full = pair_contact(pair, positions=8, mesh_scale=2.0, plane="strain", local_contact="eq5")
    z = r.zone_masks()
    dbl = z["A"] | z["C"]
    assert np.all(full.k_N_per_m[dbl] < r.k_N_per_m[dbl])
    assert full.k_N_per_m[z["B"]] == pytest.approx(r.k_N_per_m[z["B"]], rel=1e-9)
    # Eq. 5 versus Weber at the full load: Weber is the more compliant
    assert hertz_approach_m(r.total_load_N, pair.material, pair.face_width_m) < weber_approach_m(
        r.total_load_N, 3.5e-3, 3.5e-3, 12.8e-3, 206e9, 0.3, pair.face_width_m)


@pytest.mark.slow
def test_mesh_convergence_and_budget(pair):
    """Default mesh at 24 positions within the 3 min budget; halving the element sizes
    from mesh_scale 2 to 1 changes the mean by less than 0.5 %."""
    t0 = time.perf_counter()
    fine = pair_contact(pair, positions=24)
    wall = time.perf_counter() - t0
    assert wall < 180.0
    coarse = pair_contact(pair, positions=24, mesh_scale=2.0)
    assert abs(coarse.mean_N_per_m / fine.mean_N_per_m - 1) < 0.005
    zm = fine.zone_means()
    assert zm["double"] > 1.3 * zm["single"]
