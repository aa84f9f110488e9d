"""Tooth profile: involute identities, ISO thickness formulas, and generation checked
by simulating the rack cutter (it never cuts into the tooth it generated, and it
touches every generated point)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearwear.geometry.profile import (
    FILLET,
    INVOLUTE,
    TIP_LAND,
    RackGeometry,
    UndercutError,
    fillet_points,
    gear_outline,
    involute_points,
    polygon_area,
    tooth_profile,
)
from gearwear.geometry.spec import GearSpec, PairSpec, default_pair


@pytest.fixture(scope="module")
def paper():
    pair = default_pair()
    return pair, tooth_profile(pair.gear(0))


def test_paper_pair_radii(paper):
    pair, prof = paper
    g = pair.gear(0)
    # Table 2 of the paper gives 70.47 mm; r_b = (m z / 2) cos(20 deg) = 70.4769 mm
    assert g.base_radius_m * 1e3 == pytest.approx(70.477, abs=5e-4)
    assert g.root_radius_m == pytest.approx(g.pitch_radius_m - 1.25 * g.module_m, abs=1e-15)
    assert prof.radius.min() == pytest.approx(g.root_radius_m, abs=1e-12)
    assert prof.radius.max() == pytest.approx(g.pitch_radius_m + g.module_m, abs=1e-12)


def test_pitch_thickness_is_half_pitch(paper):
    pair, prof = paper
    g = pair.gear(0)
    s = prof.thickness_at_radius(g.pitch_radius_m)
    assert abs(float(s) - math.pi * g.module_m / 2) < 1e-9


def test_involute_identity_and_normals(paper):
    pair, prof = paper
    rb = pair.gear(0).base_radius_m
    inv = prof.region == INVOLUTE
    r2 = prof.radius[inv] ** 2
    assert np.max(np.abs(r2 - (rb**2 + (rb * prof.roll[inv]) ** 2))) < 1e-15
    assert np.max(np.abs(np.linalg.norm(prof.normal, axis=1) - 1.0)) < 1e-12


def test_normals_orthogonal_to_curve_tangent(paper):
    """Finite-difference tangents of the exact curves are orthogonal to the normals."""
    pair, prof = paper
    g = pair.gear(0)
    rack = RackGeometry.of(g)
    u = prof.roll[prof.region == INVOLUTE]
    psi_b = prof.psi_b
    eps = 1e-7
    p1, _ = involute_points(g.base_radius_m, psi_b, u + eps)
    p0, _ = involute_points(g.base_radius_m, psi_b, u - eps)
    _, n = involute_points(g.base_radius_m, psi_b, u)
    t = (p1 - p0) / np.linalg.norm(p1 - p0, axis=1)[:, None]
    assert np.max(np.abs(np.sum(t * n, axis=1))) < 1e-7
    phi = np.linspace(rack.phi_root, rack.phi_tangent, 50)[1:-1]
    q1, _ = fillet_points(rack, phi + eps)
    q0, _ = fillet_points(rack, phi - eps)
    _, nf = fillet_points(rack, phi)
    tf = (q1 - q0) / np.linalg.norm(q1 - q0, axis=1)[:, None]
    assert np.max(np.abs(np.sum(tf * nf, axis=1))) < 1e-6
    # outward: the normal of the right flank points away from the tooth axis
    assert np.all(prof.normal[prof.region == INVOLUTE][:, 0] > 0)


def test_fillet_joins_flank_without_gap_and_tangentially(paper):
    pair, prof = paper
    g = pair.gear(0)
    rack = RackGeometry.of(g)
    q, nq = fillet_points(rack, np.array([rack.phi_tangent]))
    u_F = math.sqrt((prof.form_radius_m / g.base_radius_m) ** 2 - 1.0)
    p, npnt = involute_points(g.base_radius_m, prof.psi_b, np.array([u_F]))
    assert np.linalg.norm(q - p) < 1e-12
    assert np.linalg.norm(nq - npnt) < 1e-9
    # polyline has no jumps: consecutive points closer than 0.5 mm (sag tolerance 0.2 um)
    assert np.max(np.linalg.norm(np.diff(prof.xy, axis=0), axis=1)) < 0.5e-3
    assert np.all(np.diff(prof.s) > 0)
    regions = prof.region
    assert set(np.unique(regions)) >= {FILLET, INVOLUTE, TIP_LAND}


def _rack_signed_distance(rack: RackGeometry, pts_rack: np.ndarray) -> np.ndarray:
    """Signed distance (m) of points (rack frame) from the cutter tooth that cuts the
    right flank: negative inside. The tooth is the wedge {right of the flank line, above
    the tip line} with the corner rounded by rho; modelled as the inner wedge (offset by
    rho) dilated by rho."""
    a = rack.alpha
    x_c, y_c = rack.round_centre
    rho = rack.round_radius
    x, y = pts_rack[:, 0], pts_rack[:, 1]
    n1 = np.array([math.cos(a), math.sin(a)])  # into the cutter, normal to the flank
    h1 = (x - x_c) * n1[0] + (y - y_c) * n1[1]
    h2 = y - y_c
    d1_dir = np.array([-math.sin(a), math.cos(a)])  # up the flank from C
    along1 = (x - x_c) * d1_dir[0] + (y - y_c) * d1_dir[1]
    along2 = x - x_c
    corner = np.hypot(x - x_c, y - y_c)
    dist = corner.copy()
    dist = np.where((h1 < 0) & (along1 >= 0), np.minimum(dist, -h1), dist)
    dist = np.where((h2 < 0) & (along2 >= 0), np.minimum(dist, -h2), dist)
    inside = (h1 >= 0) & (h2 >= 0)
    return np.where(inside, -rho - np.minimum(h1, h2), dist - rho)


def _to_rack(pts: np.ndarray, phi: float, r: float) -> np.ndarray:
    c, s = math.cos(phi), math.sin(phi)
    X = c * pts[:, 0] + s * pts[:, 1]
    Y = -s * pts[:, 0] + c * pts[:, 1]
    return np.column_stack([X - r * phi, Y - r])


def _gear(teeth: int, shift: float, undercut: bool, **kw) -> GearSpec:
    """One rack-generated gear, unchecked as a pair: these tests are about the single
    gear's profile (a pinion undercut this much interferes with most mates, which the
    pair check refuses; tests/test_geometry_limits.py covers that)."""
    return PairSpec(
        teeth=(teeth, 1000),
        profile_shift=(shift, 0.0),
        allow_undercut=undercut,
        hub_radius_m=(0.2 * teeth * kw.get("module_m", 5e-3), 0.4),
        **kw,
    ).gear(0)


@pytest.mark.parametrize("teeth,shift,undercut", [(30, 0.0, False), (17, 0.4, False), (12, 0.0, True)])
def test_rack_never_penetrates_and_touches_every_point(teeth, shift, undercut):
    g = _gear(teeth, shift, undercut)
    prof = tooth_profile(g)
    assert prof.undercut == undercut
    rack = RackGeometry.of(g)
    r = g.pitch_radius_m
    flank = (prof.region == FILLET) | (prof.region == INVOLUTE)
    pts = prof.xy[flank]
    best = np.full(len(pts), np.inf)
    for phi in np.linspace(rack.phi_tangent - 0.6, 0.6, 6001):
        sd = _rack_signed_distance(rack, _to_rack(pts, phi, r))
        assert sd.min() > -1e-9, f"cutter penetrates the tooth by {-sd.min():.3e} m at phi={phi}"
        best = np.minimum(best, sd)
    # every generated point is touched by the cutter in some position
    assert best.max() < 2e-7


@pytest.mark.parametrize("teeth,shift,expected", [(12, 0.0, True), (12, 0.3, False), (17, 0.0, True), (18, 0.0, False)])
def test_undercut_detection(teeth, shift, expected):
    if expected:
        with pytest.raises(UndercutError, match="undercut"):
            tooth_profile(_gear(teeth, shift, False))
        assert tooth_profile(_gear(teeth, shift, True)).undercut
    else:
        assert not tooth_profile(_gear(teeth, shift, False)).undercut


def test_gear_outline_area_matches_independent_estimate(paper):
    """Area of the toothed disc = root disc + z teeth; each tooth's area over the root
    circle from the polar integral 1/2 int r^2 dbeta of its half outline."""
    pair, prof = paper
    g = pair.gear(0)
    out = gear_outline(prof)
    area = polygon_area(out)
    assert area > 0  # counter-clockwise
    # polar integral over the right half tooth: A_half = 1/2 int R^2 dbeta (beta from pi/z to 0)
    beta = np.arctan2(prof.xy[:, 0], prof.xy[:, 1])
    R = prof.radius
    half = 0.5 * np.sum(0.5 * (R[1:] ** 2 + R[:-1] ** 2) * -np.diff(beta))
    # trapezoid in beta is second-order exact on the polar curve; compare loosely
    assert area == pytest.approx(2 * g.teeth * half, rel=1e-5)


@settings(max_examples=40, deadline=None)
@given(
    teeth=st.integers(18, 150),
    module_mm=st.floats(0.5, 20.0),
    alpha_deg=st.floats(14.5, 25.0),
    shift=st.floats(-0.2, 0.6),
)
def test_profile_properties_hold_for_any_valid_gear(teeth, module_mm, alpha_deg, shift):
    """ISO 21771 thickness s = m (pi/2 + 2 x tan alpha); involute identity; radii."""
    a = math.radians(alpha_deg)
    rho_star = 0.25 if alpha_deg > 22 else 0.38
    # ISO undercut limit with a rounded rack: z_min = 2 (h_f* - x - rho* (1 - sin a)) / sin^2 a
    z_min = 2 * (1.25 - shift - rho_star * (1 - math.sin(a))) / math.sin(a) ** 2
    g = _gear(teeth, shift, True, module_m=module_mm * 1e-3, pressure_angle_rad=a, rack_tip_radius_coefficient=rho_star)
    prof = tooth_profile(g)
    assert prof.undercut == (teeth < z_min)
    m = module_mm * 1e-3
    s_iso = m * (math.pi / 2 + 2 * shift * math.tan(a))
    if g.pitch_radius_m >= prof.form_radius_m:
        assert abs(float(prof.thickness_at_radius(g.pitch_radius_m)) - s_iso) < 1e-9 * max(1.0, module_mm)
    inv = prof.region == INVOLUTE
    rb = g.base_radius_m
    assert np.allclose(prof.radius[inv] ** 2, rb**2 * (1 + prof.roll[inv] ** 2), rtol=1e-13, atol=0)
    assert prof.radius.min() == pytest.approx(g.pitch_radius_m - (1.25 - shift) * m, rel=1e-12)
    assert np.all(np.diff(prof.s) > 0)
    assert np.allclose(np.linalg.norm(prof.normal, axis=1), 1.0, atol=1e-12)
