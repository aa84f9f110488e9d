"""Analytic mesh stiffness: beam theory, convergence, a second model, ISO 6336,
load-sharing equilibrium/compatibility, wear and clearance trends, continuity."""

import math

import numpy as np
import pytest

from gearwear.analytic.ishikawa import hertz_approach_m, slice_beam_compliance, tooth_compliance
from gearwear.analytic.iso6336 import iso6336_stiffness
from gearwear.analytic.tvms import corner_gap_m, mesh_stiffness
from gearwear.core.validation import InputError
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.profile import tooth_profile
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import WearSpec


@pytest.fixture(scope="module")
def pair():
    return default_pair()


@pytest.fixture(scope="module")
def curves(pair):
    return {
        w: mesh_stiffness(pair, points=360, wear=None if w == "unworn" else WearSpec(phase=w))
        for w in ("unworn", "mild", "severe")
    }


@pytest.mark.parametrize("w_deg,x_F", [(0.0, 0.0), (20.0, 3e-3), (35.0, 1e-3)])
def test_slices_exact_for_prismatic_beam(w_deg, x_F):
    """Constant thickness t: Castigliano on M = F (cos w u - sin w x_F) gives
    [c^2 L^3/3 - c s x_F L^2 + s^2 x_F^2 L] / (E I) + 1.2 c^2 L / (G A) + s^2 L / (E A)."""
    E, nu, b, t, L = 206e9, 0.3, 0.02, 8e-3, 10e-3
    w = math.radians(w_deg)
    c, s = math.cos(w), math.sin(w)
    I, A, G = t**3 * b / 12, t * b, E / (2 * (1 + nu))
    for n in (1, 7, 64):
        bend, shear, axial = slice_beam_compliance(
            lambda y: np.full_like(y, t), np.array([0.0]), np.array([L]), np.array([x_F]), np.array([w]), E, nu, b, n
        )
        assert bend[0] == pytest.approx(
            (c * c * L**3 / 3 - c * s * x_F * L**2 + s * s * x_F**2 * L) / (E * I), rel=1e-12
        )
        assert shear[0] == pytest.approx(1.2 * c * c * L / (G * A), rel=1e-12)
        assert axial[0] == pytest.approx(s * s * L / (E * A), rel=1e-12)


def test_slice_convergence_is_second_order(pair):
    prof = tooth_profile(pair.gear(0))
    R = np.array([71.8e-3, 75e-3, 79.5e-3])
    vals = [tooth_compliance(prof, R, pair.materials[0], pair.face_width_m, n).total_m_per_N for n in (16, 32, 64, 128)]
    d1, d2, d3 = (np.abs(vals[i + 1] - vals[i]) for i in range(3))
    # midpoint slices: second order where the beam is long (pitch, tip); near the SAP the
    # beam is ~3 mm long and the change is already at the polyline's resolution
    order = np.log2(d2 / d3)[1:]
    assert np.all((order > 1.7) & (order < 2.3)), order
    assert d3[0] / vals[3][0] < 1e-5
    # 64 slices (the default) are converged to < 2e-4 relative
    assert np.all(np.abs(vals[2] - vals[3]) / vals[3] < 2e-4)


def test_ishikawa_and_energy_agree(pair):
    ish = mesh_stiffness(pair, method="ishikawa")
    en = mesh_stiffness(pair, method="energy")
    assert abs(ish.mean_N_per_m / en.mean_N_per_m - 1) < 0.10

    def ratio(r):
        single = r.pairs_in_contact == 1
        return r.k_N_per_m[~single].mean() / r.k_N_per_m[single].mean()

    assert abs(ratio(ish) / ratio(en) - 1) < 0.10


@pytest.mark.parametrize("method", ["ishikawa", "energy"])
def test_mean_within_15_percent_of_iso6336(pair, method):
    """ISO 6336-1 c_gamma_alpha b assumes the theoretical path of contact, so compare
    the curve without tip-corner contact (bore radius 40 mm)."""
    iso = iso6336_stiffness(pair, torque_Nm=40.0)
    r = mesh_stiffness(pair, method=method, corner_contact=False)
    print(f"{method}: mean {r.mean_N_per_m:.4e} N/m, ISO c_gamma_alpha b {iso.mesh_stiffness_N_per_m:.4e} N/m")
    assert abs(r.mean_N_per_m / iso.mesh_stiffness_N_per_m - 1) < 0.15


def test_load_sharing_equilibrium_and_compatibility(pair, curves):
    for name, r in curves.items():
        F = r.total_load_N
        assert np.max(np.abs(r.pair_load_N.sum(axis=1) / F - 1)) < 1e-9
        assert np.all(np.isfinite(r.k_N_per_m)) and np.all(r.k_N_per_m > 0)
    # unworn double contact: both pairs deflect by the same approach (compatibility)
    r = mesh_stiffness(pair, points=36, corner_contact=False)
    mesh = r.mesh
    from gearwear.analytic.tvms import _profiles

    prof = _profiles(pair, None, mesh.centre_distance_m)[0][0]  # the same flank polyline
    for i in range(len(r.angle_rad)):
        loaded = np.flatnonzero(r.pair_load_N[i] > 0)
        for k in loaded:
            d = r.pair_d_m[i, k]
            c1 = tooth_compliance(prof, np.array([mesh.pinion_radius_at(d)]), pair.materials[0], pair.face_width_m)
            c2 = tooth_compliance(prof, np.array([mesh.gear_radius_at(d)]), pair.materials[0], pair.face_width_m)
            Fk = r.pair_load_N[i, k]
            approach = (c1.total_m_per_N[0] + c2.total_m_per_N[0]) * Fk + hertz_approach_m(Fk, pair.materials[0], 0.02)
            assert approach == pytest.approx(r.ste_m[i], rel=1e-9)


def test_worn_pair_can_carry_zero_load(curves):
    r = curves["severe"]
    in_path = r.pair_in_path.sum(axis=1)
    loaded = (r.pair_load_N > 0).sum(axis=1)
    assert np.any((in_path == 2) & (loaded == 1))


def test_wear_lowers_stiffness_most_at_double_zone_entry(curves):
    u, m, s = (curves[k] for k in ("unworn", "mild", "severe"))
    assert u.mean_N_per_m > m.mean_N_per_m > s.mean_N_per_m
    mesh = u.mesh
    rb1 = u.pair.gear(0).base_radius_m
    d_entry = mesh.path_start_m + rb1 * u.angle_rad
    B, D = mesh.single_contact_limits_m
    entry = d_entry <= mesh.path_start_m + 0.1 * (B - mesh.path_start_m)  # first 10 % of the double zone
    single = (d_entry > B + 0.5e-3) & (d_entry < mesh.path_start_m + mesh.base_pitch_m - 0.5e-3)
    for worn in (m, s):
        drop = 1 - worn.k_N_per_m / u.k_N_per_m
        assert drop[entry].mean() > 0.3  # tip entry: the entering worn pair carries nothing
        assert drop[single].mean() < 0.01  # single contact: only the thinner teeth
        assert drop[entry].mean() > 10 * drop[single].mean()


def test_clearance_lowers_mean_stiffness_and_double_zone(pair):
    """Paper section 3.2.1 claims both that k_h 'increases' and that its average
    'decreases' with clearance: the physics gives the decrease."""
    res = [mesh_stiffness(pair, clearance_m=c * 1e-6) for c in (0, 50, 100, 200)]
    means = np.array([r.mean_N_per_m for r in res])
    eps = np.array([r.contact_ratio for r in res])
    assert np.all(np.diff(means) < 0) and np.all(np.diff(eps) < 0)
    assert np.all(np.diff([r.max_N_per_m for r in res]) < 0)


@pytest.mark.parametrize("wear", [None, "severe"])
def test_transmission_error_is_continuous(pair, wear):
    """Halving the angle step halves the largest step of the STE: no jumps."""
    spec = WearSpec(phase=wear) if wear else None
    jumps = [np.abs(np.diff(mesh_stiffness(pair, points=n, wear=spec).ste_m)).max() for n in (720, 1440, 2880)]
    assert jumps[1] / jumps[0] < 0.6 and jumps[2] / jumps[1] < 0.6


def test_corner_gap_matches_second_order_contact_geometry(pair):
    """Near A the gear tip corner lies on the extended gear involute at arc length
    s ~ rho_2 (d_A - d) / r_b2 from the touching point, so it clears the pinion flank
    by kappa s^2 / 2 with kappa = 1/rho_1 + 1/rho_2 (relative curvature)."""
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    A = mesh.path_start_m
    rho1, rho2 = A, mesh.line_of_action_m - A
    for dd in (5e-5, 1e-4, 2e-4):
        s = rho2 * dd / pair.gear(1).base_radius_m
        expected = 0.5 * (1 / rho1 + 1 / rho2) * s**2
        assert corner_gap_m(mesh, np.array([A - dd]), "entry")[0] == pytest.approx(expected, rel=0.03)
    assert corner_gap_m(mesh, np.array([A]), "entry")[0] == pytest.approx(0.0, abs=1e-15)
    assert corner_gap_m(mesh, np.array([mesh.path_end_m]), "exit")[0] == pytest.approx(0.0, abs=1e-15)


def test_bad_inputs_are_clear_errors_not_nan(pair):
    with pytest.raises(InputError, match="torque_Nm = 0 N m"):
        mesh_stiffness(pair, torque_Nm=0.0)
    with pytest.raises(InputError, match="points = 4"):
        mesh_stiffness(pair, points=4)
    with pytest.raises(InputError, match="wear depth"):
        mesh_stiffness(pair, wear=WearSpec(max_depth_m=12e-3))
    with pytest.raises(InputError, match="^method = 'fem'"):  # its own parameter name; the CLI says --method
        mesh_stiffness(pair, method="fem")
