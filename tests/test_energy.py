"""Potential-energy tooth compliance: beam theory on prismatic teeth, direct adaptive
quadrature of the defining integrals on the real profile, Gauss convergence, physical
monotonicity, wear, the Sainsot table evaluated by hand, and the literature / ISO range."""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import quad

from gearwear.analytic.energy import (
    beam_compliance,
    foundation_compliance,
    hertz_compliance_linear,
    sainsot_coefficients,
    tooth_compliance,
)
from gearwear.analytic.iso6336 import iso6336_stiffness
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.loading import half_thickness_at_height, load_points, root_section
from gearwear.geometry.profile import INVOLUTE, tooth_profile
from gearwear.geometry.spec import Material, default_pair

STEEL = Material(206e9, 0.3)
B = 20e-3


@pytest.fixture(scope="module")
def paper():
    pair = default_pair()
    prof = tooth_profile(pair.gear(0))
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    radii = np.linspace(mesh.start_of_active_profile_m[0], pair.gear(0).tip_radius_m, 120)
    return pair, prof, mesh, radii


def _prismatic(t):
    return lambda y: np.full_like(np.asarray(y, dtype=float), t)


def test_prismatic_tooth_is_timoshenko_cantilever():
    t, y_M, L = 3e-3, 0.07, 8e-3
    E, G = STEEL.youngs_modulus_Pa, STEEL.shear_modulus_Pa
    I, A = (2 * t) ** 3 * B / 12, 2 * t * B
    # extra breaks inside the span must not matter
    bend, shear, axial = beam_compliance(
        _prismatic(t), [y_M, y_M + 0.3 * L, y_M + L], t, y_M + L, 0.0, STEEL, B, n_gauss=4
    )
    assert bend[0] == pytest.approx(L**3 / (3 * E * I), rel=1e-10)
    assert shear[0] == pytest.approx(1.2 * L / (G * A), rel=1e-10)
    assert axial[0] == 0.0
    # several load heights at once (partial pieces of different lengths)
    Ls = np.array([0.1, 0.3, 0.5, 0.77, 1.0]) * L
    bend, shear, _ = beam_compliance(_prismatic(t), [y_M, y_M + 0.3 * L, y_M + L], t, y_M + Ls, 0.0, STEEL, B)
    np.testing.assert_allclose(bend, Ls**3 / (3 * E * I), rtol=1e-10)
    np.testing.assert_allclose(shear, 1.2 * Ls / (G * A), rtol=1e-10)


def test_prismatic_tooth_pure_compression():
    """w = 90 deg with the load on the axis: only the bar compliance L / (E A) remains."""
    t, y_M, L = 3e-3, 0.07, 8e-3
    bend, shear, axial = beam_compliance(_prismatic(t), [y_M, y_M + L], 0.0, y_M + L, math.pi / 2, STEEL, B)
    assert axial[0] == pytest.approx(L / (STEEL.youngs_modulus_Pa * 2 * t * B), rel=1e-10)
    # cos(pi/2) = 6e-17 in floating point: the other terms vanish to that order
    assert bend[0] < 1e-25 * axial[0] and shear[0] < 1e-25 * axial[0]


def test_tapered_tooth_against_adaptive_quadrature():
    """Smooth non-uniform x(y), oblique load off the axis: the moment expansion agrees
    with direct adaptive integration of the defining integrals."""
    y_M = 0.068

    def x(y):
        return 5e-3 - 0.25 * (np.asarray(y) - y_M) + 40.0 * (np.asarray(y) - y_M) ** 2

    E, G = STEEL.youngs_modulus_Pa, STEEL.shear_modulus_Pa
    y_F = np.array([0.071, 0.0745, 0.079])
    x_F = x(y_F)
    w = np.array([0.12, 0.3, 0.47])
    bend, shear, axial = beam_compliance(x, [y_M, 0.072, 0.080], x_F, y_F, w, STEEL, B)
    for i in range(3):
        a, s = math.cos(w[i]), math.sin(w[i])
        kb = quad(
            lambda y: (a * (y_F[i] - y) - s * x_F[i]) ** 2 / (E * (2 * x(y)) ** 3 * B / 12),
            y_M,
            y_F[i],
            epsabs=0,
            epsrel=1e-13,
        )[0]
        ks = quad(lambda y: 1.2 * a**2 / (G * 2 * x(y) * B), y_M, y_F[i], epsabs=0, epsrel=1e-13)[0]
        ka = quad(lambda y: s**2 / (E * 2 * x(y) * B), y_M, y_F[i], epsabs=0, epsrel=1e-13)[0]
        assert bend[i] == pytest.approx(kb, rel=1e-11)
        assert shear[i] == pytest.approx(ks, rel=1e-11)
        assert axial[i] == pytest.approx(ka, rel=1e-11)


def test_real_profile_against_adaptive_quadrature(paper):
    """On the rack-generated profile, the defining integrals by scipy's adaptive
    quadrature (told where the polyline vertices are) give the same compliances."""
    pair, prof, mesh, _ = paper
    g = pair.gear(0)
    R = np.array([mesh.start_of_active_profile_m[0], g.pitch_radius_m, g.tip_radius_m])
    c = tooth_compliance(prof, R, STEEL, B)
    lp = load_points(prof, R)
    y_M, _ = root_section(prof)
    E, G = STEEL.youngs_modulus_Pa, STEEL.shear_modulus_Pa

    def x(y):
        return float(half_thickness_at_height(prof, np.array([y]))[0])

    for i in range(len(R)):
        a, s = math.cos(lp.w_rad[i]), math.sin(lp.w_rad[i])
        verts = np.unique(prof.xy[:, 1][(prof.xy[:, 1] > y_M) & (prof.xy[:, 1] < lp.y_m[i])])
        opts = dict(points=verts, limit=4 * len(verts) + 50, epsabs=0, epsrel=1e-12)
        kb = quad(
            lambda y: (a * (lp.y_m[i] - y) - s * lp.x_m[i]) ** 2 / (E * (2 * x(y)) ** 3 * B / 12),
            y_M,
            lp.y_m[i],
            **opts,
        )[0]
        kA = quad(lambda y: 1.0 / (2 * x(y) * B), y_M, lp.y_m[i], **opts)[0]
        assert c.bending_m_per_N[i] == pytest.approx(kb, rel=1e-9)
        assert c.shear_m_per_N[i] == pytest.approx(1.2 * a**2 / G * kA, rel=1e-9)
        assert c.axial_m_per_N[i] == pytest.approx(s**2 / E * kA, rel=1e-9)


def test_gauss_convergence(paper):
    pair, prof, _, radii = paper
    ref = tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m, n_gauss=32).total_m_per_N
    for n in (8, 16):
        c = tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m, n_gauss=n).total_m_per_N
        c2 = tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m, n_gauss=2 * n).total_m_per_N
        assert np.max(np.abs(c2 / c - 1.0)) < 1e-6
        assert np.max(np.abs(c / ref - 1.0)) < 1e-6
    # the check has teeth: one point per piece (midpoint rule) is measurably off (~1e-4)
    c1 = tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m, n_gauss=1).total_m_per_N
    assert np.max(np.abs(c1 / ref - 1.0)) > 1e-8


def test_compliance_grows_from_sap_to_tip(paper):
    pair, prof, _, radii = paper
    c = tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m)
    assert np.all(np.diff(c.total_m_per_N) > 0)
    assert np.all(np.diff(c.bending_m_per_N) > 0)
    assert np.all(np.diff(c.foundation_m_per_N) > 0)
    for k in (c.bending_m_per_N, c.shear_m_per_N, c.axial_m_per_N, c.foundation_m_per_N):
        assert np.all(k > 0)


def test_worn_tooth_more_compliant(paper):
    pair, prof, _, radii = paper
    depth = np.where(prof.region == INVOLUTE, 30e-6, 0.0)
    worn = prof.worn(depth)
    c0 = tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m).total_m_per_N
    cw = tooth_compliance(worn, radii, pair.materials[0], pair.face_width_m).total_m_per_N
    assert np.all(cw > c0)


def test_sainsot_coefficients_by_hand():
    h, th = 2.0, 0.1
    L = -5.574e-5 / th**2 - 1.9986e-3 * h**2 - 2.3015e-4 * h / th + 4.7702e-3 / th + 0.0271 * h + 6.8045
    M = 60.111e-5 / th**2 + 28.100e-3 * h**2 - 83.431e-4 * h / th - 9.9256e-3 / th + 0.1624 * h + 0.9086
    P = -50.952e-5 / th**2 + 185.50e-3 * h**2 + 0.0538e-4 * h / th + 53.300e-3 / th + 0.2895 * h + 0.9236
    Q = -6.2042e-5 / th**2 + 9.0889e-3 * h**2 - 4.0964e-4 * h / th + 7.8297e-3 / th - 0.1472 * h + 0.6904
    c = sainsot_coefficients(h, th)
    for key, val in zip("LMPQ", (L, M, P, Q)):
        assert float(c[key]) == pytest.approx(val, rel=1e-12)
    # and the compliance formula with them: u_f / S_f = 0.4, w = 20 deg
    w = math.radians(20.0)
    expect = math.cos(w) ** 2 / (206e9 * B) * (L * 0.4**2 + M * 0.4 + P * (1 + Q * math.tan(w) ** 2))
    got = foundation_compliance(w, 4e-3, 10e-3, h, th, STEEL, B)
    assert float(got) == pytest.approx(expect, rel=1e-12)


def test_foundation_inputs_and_fit_range_flag(paper):
    pair, prof, _, radii = paper
    c = tooth_compliance(prof, radii[:3], pair.materials[0], pair.face_width_m)
    g = pair.gear(0)
    assert c.h_fi == pytest.approx(g.root_radius_m / g.hub_radius_m, rel=1e-15)
    _, x_M = root_section(prof)
    assert c.theta_f_rad == pytest.approx(x_M / g.root_radius_m, rel=1e-15)
    assert c.foundation_in_fit_range
    # a tiny bore puts h_fi far outside the fit: flagged, still computed
    small_bore = tooth_profile(replace(g, hub_radius_m=4e-3))
    cs = tooth_compliance(small_bore, radii[:3], pair.materials[0], pair.face_width_m)
    assert not cs.foundation_in_fit_range
    assert np.all(np.isfinite(cs.foundation_m_per_N))


def test_hertz_linear():
    k = 1.0 / hertz_compliance_linear(STEEL, B)
    assert k == pytest.approx(math.pi * 206e9 * B / (4 * (1 - 0.3**2)), rel=1e-15)


def test_pitch_point_stiffness_in_literature_and_iso_range(paper):
    """Single-tooth stiffness per unit face width at the pitch point, m = 5 mm, z = 30
    steel: the literature's 1e10..3e10 N/m per m, to which this project adds the bracket
    implied by ISO 6336-1 through 1/c_pair = 2/c_tooth + 1/c_Hertz, between the measured
    (c') and the theoretical (c'_th) single pair stiffness."""
    pair, prof, _, _ = paper
    c = tooth_compliance(prof, pair.gear(0).pitch_radius_m, pair.materials[0], pair.face_width_m)
    k_per_width = 1.0 / (float(c.total_m_per_N[0]) * pair.face_width_m)
    print(f"\nsingle-tooth stiffness at the pitch point: {k_per_width:.4g} N/m per m of face width")
    iso = iso6336_stiffness(pair)
    h = hertz_compliance_linear(pair.materials[0], 1.0) * 1e9  # mm um / N per mm of width
    tooth = [2.0 / (1.0 / cp - h) * 1e9 for cp in (iso.c_prime, iso.c_th_prime)]  # N/m per m
    print(f"ISO-implied single-tooth range: {tooth[0]:.4g} .. {tooth[1]:.4g} N/m per m")
    assert 1e10 < k_per_width < 4e10
    assert tooth[0] < k_per_width < tooth[1]


def test_contact_below_root_section_rejected(paper):
    pair, prof, _, _ = paper
    with pytest.raises(ValueError):
        tooth_compliance(prof, pair.gear(0).root_radius_m + 1e-6, pair.materials[0], pair.face_width_m)
