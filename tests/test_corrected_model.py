"""The atlas-corrected model (gearwear.stiffness.corrected): its coordinates rest on a
similarity of the 2D contact problem, its zone bookkeeping on the kinematic zone lengths, its
interpolation recovers a known function, and its domain is enforced.

Pairs: the unequal shifted 23/47 (tests/pairs.py UNEQUAL), the same gears with the larger one
driving (DRIVER_LARGER) and the 29/61 pair of contact ratio above 2 (HIGH_CONTACT)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from gearwear.analytic.tvms import mesh_stiffness
from gearwear.core.validation import InputError
from gearwear.stiffness import corrected as cm

from pairs import DRIVER_LARGER, HIGH_CONTACT, UNEQUAL


def scaled(pair, s: float):
    """Every length of ``pair`` times ``s``."""
    return dataclasses.replace(
        pair,
        module_m=pair.module_m * s,
        face_width_m=pair.face_width_m * s,
        hub_radius_m=tuple(h * s for h in pair.hub_radius_m),
    )


@pytest.mark.parametrize("pair", [UNEQUAL, DRIVER_LARGER], ids=["23_47", "47_23"])
def test_energy_method_obeys_the_similarity_of_the_load_number(pair):
    """Lengths x 2 and torque x 8 (line load x 2, w / (E m) fixed): k_h / b is the same curve;
    torque x 3 alone (another load number) is not the same (corner contact), so the load
    number is a coordinate the surrogate needs."""
    T = 120.0
    a = mesh_stiffness(pair, method="energy", torque_Nm=T)
    b = mesh_stiffness(scaled(pair, 2.0), method="energy", torque_Nm=8 * T)
    c = mesh_stiffness(pair, method="energy", torque_Nm=3 * T)
    ka = a.mean_N_per_m / pair.face_width_m
    assert b.mean_N_per_m / (2 * pair.face_width_m) == pytest.approx(ka, rel=1e-4)
    assert abs(c.mean_N_per_m / pair.face_width_m / ka - 1) > 1e-2
    assert np.allclose(cm.descriptors(pair, T), cm.descriptors(scaled(pair, 2.0), 8 * T), rtol=0, atol=1e-12)


def test_pair_fe_obeys_the_similarity_of_the_load_number():
    """The resolved pair FE (coarse: mesh_scale 2, 4 positions) at m 3 mm and at m 6 mm with the
    line load doubled: the same k_h / b, bore-fixed and mesh-only, to the meshes' similarity."""
    from gearwear.fem.pair import pair_contact

    T = 120.0
    fa = pair_contact(UNEQUAL, positions=4, torque_Nm=T, mesh_scale=2.0)
    fb = pair_contact(scaled(UNEQUAL, 2.0), positions=4, torque_Nm=8 * T, mesh_scale=2.0)
    b = UNEQUAL.face_width_m
    assert fb.mean_N_per_m / (2 * b) == pytest.approx(fa.mean_N_per_m / b, rel=1e-4)
    assert fb.meta["mesh_only_mean_N_per_m"] / (2 * b) == pytest.approx(fa.meta["mesh_only_mean_N_per_m"] / b, rel=1e-4)


@pytest.mark.parametrize("pair", [UNEQUAL, DRIVER_LARGER, HIGH_CONTACT], ids=["23_47", "47_23", "29_61"])
def test_zone_values_give_the_zone_means_of_the_curve(pair):
    """(lo, hi) from the atlas's columns (mean, single, double, epsilon) equal the means over
    the zones of n0 and n0 + 1 pairs integrated from the curve itself."""
    k = mesh_stiffness(pair, method="energy", torque_Nm=100.0)
    z = k.zone_means()
    eps = k.mesh.contact_ratio
    n0 = math.floor(eps)
    lo, hi = cm.zone_values(k.mean_N_per_m, z["single"], z["double"], eps)
    assert lo == pytest.approx(z["by_count"][n0], rel=1e-10)
    assert hi == pytest.approx(z["by_count"][n0 + 1], rel=1e-9)


def _synthetic(n: int, seed: int):
    """Designs in a box like the atlas's and a smooth known log ratio over them."""
    rng = np.random.default_rng(seed)
    lo = np.array([14, 1.0, 14.5, 1.0, -0.5, -0.5, math.log(1.5), math.log(1.5), -12.0])
    hi = np.array([100, 5.0, 25.0, 1.4, 1.0, 1.0, math.log(12.0), math.log(12.0), -8.0])
    X = lo + (hi - lo) * rng.random((n, len(lo)))
    U = (X - lo) / (hi - lo)
    y = 0.1 * np.sin(2 * U[:, 0]) - 0.2 * U[:, 6] ** 2 + 0.05 * U[:, 2] * U[:, 4] - 0.08 * np.exp(-3 * U[:, 8])
    return X, y


def test_the_surrogate_recovers_a_smooth_function_out_of_sample():
    X, y = _synthetic(400, 1)
    held = np.zeros(len(y), bool)
    held[::5] = True
    err = cm.holdout_errors(X, {"mean": y}, held)["mean"]
    assert len(err) == held.sum()
    assert np.median(np.abs(err)) < 5e-3 and np.max(np.abs(err)) < 3e-2
    # a fit on every design interpolates its designs (smoothing from the candidates)
    f = cm.fit(X, {"mean": y})
    assert f.smoothing["mean"] in cm.SMOOTHINGS
    assert np.max(np.abs(f.predict(X)["mean"] - y)) < 1e-2


def test_a_target_missing_at_some_designs_is_fitted_on_the_others():
    X, y = _synthetic(120, 2)
    y2 = y.copy()
    y2[::3] = np.nan  # e.g. no single-contact zone above epsilon = 2
    f = cm.fit(X, {"mean": y, "lo": y2, "hi": np.full_like(y, np.nan)})
    assert f.models["hi"] is None and np.isnan(f.predict(X[:2])["hi"]).all()
    assert np.max(np.abs(f.predict(X[1::3])["lo"] - y[1::3])) < 2e-2


def test_the_domain_is_enforced():
    X, y = _synthetic(200, 3)
    f = cm.fit(X, {"mean": y})
    inside = X[0]
    cm.check_domain(f, inside)
    out = inside.copy()
    out[0] = 140.0
    with pytest.raises(InputError) as e:
        cm.check_domain(f, out)
    msg = str(e.value)
    assert msg.startswith("pair.teeth[0] = 140") and "must be in [" in msg and "\n" not in msg
    thin = inside.copy()
    thin[6] = math.log(1.2)
    with pytest.raises(InputError, match=r"^gear 0 rim \(r_f - bore\) / m = 1.2: must be in \[1.5"):
        cm.check_domain(f, thin)
    # the keys name the smaller gear's index: 1 when the larger gear drives
    with pytest.raises(InputError, match=r"^pair.teeth\[1\] = 140"):
        cm.check_domain(f, out, small=1)
    # the atlas's axes widen the box to the design space the samples fill the inside of
    box_lo, box_hi = f.lo.copy(), f.hi.copy()
    box_lo[0], box_hi[0] = 10.0, 150.0
    cm.check_domain(f, out, box=(box_lo, box_hi))
    # inside the box but off the designs: the atlas gives both gears one rim thickness, so a
    # pair with a thin pinion rim and a solid gear rim lies in a gap of the design
    rng = np.random.default_rng(4)
    D = np.tile(X[0], (300, 1))
    D[:, 0] = rng.uniform(14, 100, len(D))
    D[:, 6] = D[:, 7] = rng.uniform(math.log(1.5), math.log(12.0), len(D))
    g = cm.fit(D, {"mean": 0.01 * D[:, 0] + 0.1 * D[:, 6]})
    said: list[str] = []
    cm.check_domain(g, D[5], warn=said.append)
    assert said == []
    off = D[5].copy()
    off[6], off[7] = D[:, 6].min(), D[:, 6].max()
    cm.check_domain(g, off, warn=said.append)
    assert len(said) == 1 and "from the nearest atlas design" in said[0] and "\n" not in said[0]


@pytest.mark.parametrize("pair", [UNEQUAL, DRIVER_LARGER], ids=["unequal", "driver_larger"])
def test_the_descriptors_do_not_depend_on_which_gear_drives(pair):
    """The mean and zone means of k_h are a property of the two flanks in contact, so the
    descriptors take the smaller gear as "1" whichever drives; the line load is the
    normal force over the face width from either gear (T1 / r_b1 = T2 / r_b2)."""
    swapped = dataclasses.replace(
        pair,
        teeth=pair.teeth[::-1],
        profile_shift=pair.profile_shift[::-1],
        hub_radius_m=pair.hub_radius_m[::-1],
    )
    T1 = 150.0
    T2 = T1 * pair.gear(1).base_radius_m / pair.gear(0).base_radius_m
    np.testing.assert_allclose(cm.descriptors(pair, T1), cm.descriptors(swapped, T2), rtol=1e-14)
    d = cm.descriptors(pair, T1)
    assert d[0] == min(pair.teeth) and d[1] == max(pair.teeth) / min(pair.teeth)


def test_design_box_is_the_atlas_axes():
    inputs = {
        "axes.pinion_teeth": [14, 100],
        "axes.ratio": [1.0, 5.0],
        "axes.pressure_angle_deg": [14.5, 25.0],
        "axes.addendum_coefficient": [1.0, 1.4],
        "axes.profile_shift": [-0.5, 1.0],
        "axes.rim_thickness_module": [1.5, 12.0],
        "axes.line_load_N_per_mm": [20.0, 1000.0],
        "pair.youngs_modulus_GPa": 200.0,
        "pair.poisson_ratio": 0.3,
        "pair.module_mm": 2.0,
        "fe.plane": "strain",
    }
    lo, hi = cm.design_box(inputs)
    assert lo[:6] == [14, 1.0, 14.5, 1.0, -0.5, -0.5] and hi[:6] == [100, 5.0, 25.0, 1.4, 1.0, 1.0]
    assert lo[6] == lo[7] == pytest.approx(math.log(1.5)) and hi[7] == pytest.approx(math.log(12.0))
    # w / (E' m) with E' = E / (1 - nu^2) in plane strain: 20 N/mm = 2e4 N/m
    assert lo[8] == pytest.approx(math.log(2e4 * (1 - 0.09) / (200e9 * 2e-3)))
