"""The gear blanks' torsion as its own term of the pair FE (fem.pair, "The blank's torsion").

The FE holds each gear at its bore, so its mesh stiffness holds the torsion of both blanks
between bore and teeth. It reports the mesh stiffness with the blanks' torsion below the
reference circle r_ref = r_f - 2 m (not below the bore) taken out, and each blank's
torsional stiffness T / theta_ref. Independent truths, on the unequal 23/47 pair (coarse
mesh as tests/test_any_pair_fem.py: the blank is a smooth annulus, which P2 elements
resolve at any of these sizes):

* Closed form. The mean rotation of a circle (the n = 0 Fourier part of u_theta) in a solid
  annulus held at its bore and loaded anywhere outside the circle obeys
  mu (u'' + u'/r - u/r^2) = 0 with the torque T = 2 pi r^2 b tau_r_theta through every
  circle, so theta(r) = T / (4 pi G b) (1 / r_bore^2 - 1 / r^2): k_blank = T / theta_ref =
  4 pi G b / (1 / r_bore^2 - 1 / r_ref^2) (in-plane shear: the same in plane stress and
  plane strain), whatever the teeth do.
* Identity. The approach along the line of action splits as STE = STE_mesh +
  r_b1 theta_1 + r_b2 theta_2, so STE / F = STE_mesh / F + r_b1^2 / k_1 + r_b2^2 / k_2 with
  the closed-form k: to 1 % for three bore pairs.
* The reading is a rigid motion: a rigid rotation phi of the body reads phi.
* Statics: the pinion's contact moment is the driving torque T, the gear's T z2 / z1.
* The class of bug "a quantity silently holds a body term": between two thick-rim bores the
  mesh-only stiffness moves by less than the part that stays in it by construction (the
  blank's bending under the net tooth force, n = 1: estimated by the 2D point-force
  solution), while the bore-fixed one moves by the closed-form torsion, many times more.
"""

import functools
import math

import numpy as np
import pytest

from gearwear.core.validation import InputError
from gearwear.fem.pair import pair_contact, pair_model
from gearwear.fem.pair_body import blank_reading

from pairs import UNEQUAL, checked

CONTACT_SCALE, MESH_SCALE = 3.0, 1.5  # as tests/test_any_pair_fem.py
POSITIONS = 8
TORQUE = 120.0
BORES_MM = ((12.5, 25.0), (18.0, 40.0), (24.0, 55.0))


def with_bores(bores_mm):
    return checked(
        teeth=UNEQUAL.teeth,
        module_m=UNEQUAL.module_m,
        profile_shift=UNEQUAL.profile_shift,
        face_width_m=UNEQUAL.face_width_m,
        hub_radius_m=tuple(b * 1e-3 for b in bores_mm),
    )


@functools.lru_cache(maxsize=None)
def cycle(bores_mm):
    """A coarse FE cycle of the 23/47 pair with these bores (once per test process)."""
    return pair_contact(
        with_bores(bores_mm),
        positions=POSITIONS,
        torque_Nm=TORQUE,
        contact_scale=CONTACT_SCALE,
        mesh_scale=MESH_SCALE,
        extended=False,
    )


def by_hand(g):
    """(r_b, r_f, r_ref, G) of a gear, written out: r_b = m z cos(alpha) / 2,
    r_f = m z / 2 - (1.25 - x) m, r_ref = max(r_f - 2 m, bore), G = E / (2 (1 + nu))."""
    m, z, x = g.module_m, g.teeth, g.profile_shift
    r_f = m * z / 2 - (1.25 - x) * m
    E, nu = g.material.youngs_modulus_Pa, g.material.poisson_ratio
    return m * z * math.cos(math.radians(20.0)) / 2, r_f, max(r_f - 2 * m, g.hub_radius_m), E / (2 * (1 + nu))


def annulus_k(g) -> float:
    """Closed-form torsional stiffness (N m/rad) of the solid annulus bore..r_ref."""
    _, _, r_ref, G = by_hand(g)
    if r_ref <= g.hub_radius_m:
        return math.inf
    return 4 * math.pi * G * g.face_width_m / (1 / g.hub_radius_m**2 - 1 / r_ref**2)


@pytest.mark.parametrize("bores_mm", BORES_MM[1:], ids=lambda b: f"bores_{b[0]:g}_{b[1]:g}mm")
def test_bore_fixed_is_mesh_plus_both_blanks_in_closed_form(bores_mm):
    """(The first bore pair is checked in test_mesh_only_does_not_hold_the_blank_torsion, which
    needs its cycle too: one test process builds its bodies.)"""
    check_identity_and_closed_form(bores_mm)


def check_identity_and_closed_form(bores_mm):
    pair = with_bores(bores_mm)
    fe = cycle(bores_mm)
    rb = [by_hand(g)[0] for g in pair.gears]
    F = TORQUE / rb[0]
    k_closed = [annulus_k(g) for g in pair.gears]
    assert all(math.isfinite(k) for k in k_closed)  # r_f - 2 m lies above both bores here
    assert fe.meta["blank_reference_radius_m"] == pytest.approx([by_hand(g)[2] for g in pair.gears], rel=1e-12)
    # the FE's blank stiffness against the closed form
    assert fe.meta["blank_torsional_stiffness_Nm_per_rad"] == pytest.approx(k_closed, rel=1e-2)
    # and at every position: theta > 0 (both circles turn with the contact moment)
    assert np.all(fe.blank_rotation_rad > 0)
    assert np.allclose(fe.blank_torque_Nm / fe.blank_rotation_rad, k_closed, rtol=1e-2, atol=0)
    # statics: the pinion's contact moment is T; the gear's T z2 / z1 (off-LOA arms: 1e-3, as test_any_pair_fem)
    assert np.allclose(fe.blank_torque_Nm[:, 0], TORQUE, rtol=1e-9, atol=0)
    assert np.allclose(fe.blank_torque_Nm[:, 1], TORQUE * pair.teeth[1] / pair.teeth[0], rtol=1e-3, atol=0)
    # the identity, in compliance per position and for the cycle's secant stiffness
    c_blanks = sum(r * r / k for r, k in zip(rb, k_closed))
    assert np.allclose(fe.ste_m / F, fe.mesh_ste_m / F + c_blanks, rtol=1e-2, atol=0)
    no_gap = np.all(fe.meta["pair_gap_m"][fe.pair_load_N > 0] == 0)  # healthy: no corner contact at these angles
    if no_gap:
        assert np.allclose(1 / fe.k_N_per_m, 1 / fe.mesh_k_N_per_m + c_blanks, rtol=1e-2, atol=0)
    # removing a compliance stiffens; the mesh-only mean is what meta reports
    assert np.all(fe.mesh_k_N_per_m > fe.k_N_per_m)
    assert fe.meta["mesh_only_mean_N_per_m"] == pytest.approx(float(np.mean(fe.mesh_k_N_per_m)), rel=1e-12)
    # the tangent too: the blanks are a constant compliance in series
    assert np.allclose(1 / fe.k_tangent_N_per_m, 1 / fe.mesh_k_tangent_N_per_m + c_blanks, rtol=1e-2, atol=0)
    # the reading is a rigid motion: a rigid rotation phi (u = phi (-y, x)) of each body reads phi
    pm = pair_model(pair, torque_Nm=TORQUE, contact_scale=CONTACT_SCALE, mesh_scale=MESH_SCALE)
    for body in pm.bodies:
        _, A = blank_reading(body.model, body.gear)
        xy = body.model.basis.doflocs
        phi = 1e-4
        U = np.zeros(body.model.ndofs)
        U[0::2], U[1::2] = -phi * xy[1, 0::2], phi * xy[0, 1::2]
        assert A @ U == pytest.approx([phi, 0.0, 0.0], abs=1e-9 * phi)
        shift = np.zeros(body.model.ndofs)
        shift[0::2] = 1e-6
        assert A @ shift == pytest.approx([0.0, 1e-6, 0.0], abs=1e-12 * 1e-6 * 1e3)


def test_mesh_only_does_not_hold_the_blank_torsion():
    """Two thick-rim bores (8/16 and 12.5/25 mm: r_ref - r_bore >= r_bore). The bore-fixed
    compliance changes by the closed-form torsion of both annuli. The mesh-only one keeps
    what lies outside the torsion by construction: mainly the blank's bending under the net
    tooth force F (n = 1), whose change is estimated by the 2D point force on a disc
    (Kelvin), per gear F (1 + kappa) / (8 pi G b) ln(r_bore,2 / r_bore,1) with
    kappa = (3 - nu) / (1 + nu) (plane stress); the rest (n >= 2) decays like
    (r_bore / r_ref)^(2 n). The mesh-only change must stay below twice that estimate, which
    is several times below the torsion it must not hold. (Also the identity of
    test_bore_fixed_is_mesh_plus_both_blanks_in_closed_form for the 12.5/25 mm bores.)"""
    thick, ref = (8.0, 16.0), BORES_MM[0]
    check_identity_and_closed_form(ref)
    a, b = cycle(thick), cycle(ref)
    pair = with_bores(ref)
    kappa_terms = 0.0
    torsion = 0.0
    for gi, g in enumerate(pair.gears):
        rb, _, _, G = by_hand(g)
        nu = g.material.poisson_ratio
        kappa = (3 - nu) / (1 + nu)
        kappa_terms += (1 + kappa) / (8 * math.pi * G * g.face_width_m) * math.log(ref[gi] / thick[gi])
        g_thick = with_bores(thick).gear(gi)
        torsion += rb**2 * (1 / annulus_k(g_thick) - 1 / annulus_k(g))
    # cycle-mean compliances (1 / k is additive per position, its mean too)
    dc_mesh = float(np.mean(1 / a.mesh_k_N_per_m) - np.mean(1 / b.mesh_k_N_per_m))
    dc_fixed = float(np.mean(1 / a.k_N_per_m) - np.mean(1 / b.k_N_per_m))
    assert torsion > 5 * 2 * kappa_terms  # the test can tell the two apart
    assert abs(dc_mesh) < 2 * kappa_terms
    assert dc_fixed == pytest.approx(torsion + dc_mesh, rel=1e-2)


def test_thin_rim_has_no_blank_term():
    """A pinion bore above r_f - 2 m: r_ref is the bore, no blank term for the pinion (its
    whole rim stays in the mesh stiffness); the gear's term is unchanged in kind."""
    bores = (26.0, 55.0)
    pair = with_bores(bores)
    _, r_f, r_ref, _ = by_hand(pair.gear(0))
    assert r_f - 2 * pair.module_m < pair.gear(0).hub_radius_m == r_ref
    fe = cycle(bores)
    assert fe.meta["blank_reference_radius_m"][0] == pair.gear(0).hub_radius_m
    assert math.isinf(fe.meta["blank_torsional_stiffness_Nm_per_rad"][0])
    assert np.all(fe.blank_rotation_rad[:, 0] == 0)
    rb2 = by_hand(pair.gear(1))[0]
    assert np.allclose(fe.ste_m - fe.mesh_ste_m, rb2 * fe.blank_rotation_rad[:, 1], rtol=1e-12, atol=0)
    assert fe.meta["blank_torsional_stiffness_Nm_per_rad"][1] == pytest.approx(annulus_k(pair.gear(1)), rel=1e-2)
    # what the FE-based sources hand on: the mesh-only curve with "excluded", reported beside the bore-fixed one
    from gearwear.jobs.stiffness import Curve, fem_curve

    r = fem_curve(
        pair,
        POSITIONS,
        TORQUE,
        0.0,
        None,
        blank_torsion="excluded",
        contact_scale=CONTACT_SCALE,
        mesh_scale=MESH_SCALE,
        extended=False,
    )
    assert np.array_equal(r.k_N_per_m, fe.mesh_k_N_per_m) and np.array_equal(r.ste_m, fe.mesh_ste_m)
    s = Curve("excluded", "fem", None, 0.0, r).summary()
    # the same mean, summed in another order (the curve statistics integrate the piecewise-linear
    # curve, geometry.curves; the FE averages its uniform positions): equal to round-off
    assert s["mean_N_per_m"] == pytest.approx(s["mesh_only_mean_N_per_m"], rel=1e-14)
    assert s["bore_fixed_mean_N_per_m"] == fe.mean_N_per_m
    assert s["blank_torsional_stiffness_Nm_per_rad"][0] is None  # no blank term: null in JSON, not inf
    assert s["blank_reference_radius_mm"] == pytest.approx([26.0, by_hand(pair.gear(1))[2] * 1e3], rel=1e-12)


# -- what the scenes give the dynamics -----------------------------------------------------


def test_blank_torsion_key_only_with_the_fe_sources():
    from gearwear.jobs.simulate import blank_torsion
    from gearwear.scene.model import scene_from_dict

    base = {
        "pair": {"teeth": [23, 47], "module_mm": 3.0, "face_width_mm": 30.0},
        "operating": {"speed_rpm": 1500, "torque_Nm": 120},
    }
    for src in ("analytic", "constant"):
        with pytest.raises(InputError, match="blank_torsion"):
            scene_from_dict({**base, "effects": {"mesh_stiffness": {"source": src, "blank_torsion": "excluded"}}})
    for src in ("fem", "calibrated"):
        sc = scene_from_dict({**base, "effects": {"mesh_stiffness": {"source": src, "blank_torsion": "excluded"}}})
        assert blank_torsion(sc.effects["mesh_stiffness"]) == "excluded"
        sc = scene_from_dict({**base, "effects": {"mesh_stiffness": {"source": src}}})
        assert blank_torsion(sc.effects["mesh_stiffness"]) == "in_series"  # today's: the bodies held at their bores


def test_calibrated_table_without_blank_torsion():
    """1 / k_mesh = 1 / k - c_b, STE_mesh = STE - F c_b with F = k (STE - e): the mesh force
    F is unchanged and e is kept."""
    from gearwear.stiffness.calibration import without_blank_torsion
    from gearwear.stiffness.tables import StiffnessTable

    k = np.array([3e8, 4e8, 5e8])
    e = np.array([0.0, 1e-6, 2e-6])
    F = 2000.0
    tab = StiffnessTable(np.arange(3.0), k, e, e + F / k, np.array([1, 2, 2]), {"blank_compliance_m_per_N": 5e-10})
    out = without_blank_torsion(tab)
    assert np.allclose(1 / out.k_N_per_m, 1 / k - 5e-10, rtol=1e-12)
    assert np.allclose(out.k_N_per_m * (out.ste_m - out.excitation_m), F, rtol=1e-12)
    assert np.array_equal(out.excitation_m, e)
