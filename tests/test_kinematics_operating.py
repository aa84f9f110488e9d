"""Kinematics and operating geometry against textbook formulas and hand computation."""

import math

import numpy as np
import pytest

from gearwear.core.validation import InputError
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import backlash, centre_distance, operating_geometry
from gearwear.geometry.profile import tooth_profile
from gearwear.geometry.spec import default_pair

from scenes import paper_pair_from


def textbook_contact_ratio(z1, z2, m, alpha, a):
    """epsilon = (sqrt(ra1^2-rb1^2) + sqrt(ra2^2-rb2^2) - a sin(alpha')) / (pi m cos(alpha))."""
    r1, r2 = m * z1 / 2, m * z2 / 2
    rb1, rb2 = r1 * math.cos(alpha), r2 * math.cos(alpha)
    ra1, ra2 = r1 + m, r2 + m
    aw = math.acos((rb1 + rb2) / a)
    return (math.sqrt(ra1**2 - rb1**2) + math.sqrt(ra2**2 - rb2**2) - a * math.sin(aw)) / (
        math.pi * m * math.cos(alpha)
    )


def test_paper_contact_ratio_matches_textbook():
    pair = default_pair()
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    eps = textbook_contact_ratio(30, 30, 5e-3, math.radians(20), 0.150)
    assert mesh.contact_ratio == pytest.approx(eps, rel=1e-12)
    assert mesh.contact_ratio == pytest.approx(1.65, abs=0.01)
    assert mesh.base_pitch_m == pytest.approx(2 * math.pi * pair.gear(0).base_radius_m / 30, rel=1e-14)


def test_contacts_average_count_equals_contact_ratio():
    pair = default_pair()
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    theta = np.linspace(0, mesh.mesh_angle_rad, 200001, endpoint=False)
    c = mesh.contacts(theta)
    assert set(np.unique(c.count)) == {1, 2}
    assert c.count.mean() == pytest.approx(mesh.contact_ratio, abs=1e-4)
    # entering pair at theta = 0 sits at the start of active profile on the pinion
    first = mesh.contacts(0.0)
    j = np.flatnonzero(first.active[0])
    assert np.isclose(first.d[0, j], mesh.path_start_m).any()
    # at the pitch point the radii are the operating pitch radii and sum to C'
    rw1, rw2 = mesh.operating_pitch_radii_m
    assert mesh.pinion_radius_at(mesh.pitch_point_m) == pytest.approx(rw1, rel=1e-14)
    assert mesh.gear_radius_at(mesh.pitch_point_m) == pytest.approx(rw2, rel=1e-14)
    assert rw1 + rw2 == pytest.approx(mesh.centre_distance_m, rel=1e-14)
    # the end of contact is the pinion tip
    assert mesh.pinion_radius_at(mesh.path_end_m) == pytest.approx(pair.gear(0).tip_radius_m, rel=1e-14)


def test_zero_clearance_gives_nominal_geometry_exactly():
    pair = default_pair()
    og = operating_geometry(pair, 0.0)
    nominal = MeshGeometry(pair, pair.centre_distance_m)
    assert og.centre_distance_m == pair.centre_distance_m
    assert og.pressure_angle_rad == pair.pressure_angle_rad
    assert og.backlash_m == 0.0
    assert og.contact_ratio == nominal.contact_ratio
    assert og.contact_line_length_m == nominal.path_length_m


def test_centre_distance_linear_and_contact_ratio_falls():
    pair = default_pair()
    bc = np.linspace(0, 100e-6, 11)
    C = np.array([centre_distance(pair, c) for c in bc])
    eps = np.array([operating_geometry(pair, c).contact_ratio for c in bc])
    alpha = np.array([operating_geometry(pair, c).pressure_angle_rad for c in bc])
    fit = np.polyfit(bc, C, 1)
    assert np.max(np.abs(np.polyval(fit, bc) - C)) < 1e-3 * (C[-1] - C[0])  # linear
    assert fit[0] == pytest.approx(1.0, abs=1e-3)  # d C' / d BC = 1 (Eq. 11, small BC)
    assert np.all(np.diff(eps) < 0) and np.all(np.diff(alpha) > 0)


def test_eq11_with_static_load_is_a_fixed_point():
    pair = default_pair()
    T, kb, bc = 40.0, 2.6e8, 20e-6
    og = operating_geometry(pair, bc, T, kb)
    a = og.pressure_angle_rad
    Fn = T / pair.gear(0).base_radius_m
    C = 0.150
    expected = math.hypot(C + 2 * Fn * math.sin(a) / kb + bc, 2 * Fn * math.cos(a) / kb + bc)
    assert og.centre_distance_m == pytest.approx(expected, rel=1e-14)


def test_backlash_hand_computation_and_thickness_route():
    pair = default_pair()
    Cp = 0.1501  # 0.1 mm beyond nominal
    # hand computation: alpha' = acos(150 cos 20 / 150.1); j_n = 2 C cos(alpha) (inv alpha' - inv alpha)
    a = math.radians(20.0)
    ap = math.acos(150.0 * math.cos(a) / 150.1)
    hand = 2 * 0.150 * math.cos(a) * ((math.tan(ap) - ap) - (math.tan(a) - a))
    assert backlash(pair, Cp) == pytest.approx(hand, rel=1e-9)
    assert hand * 1e6 == pytest.approx(68.5, abs=0.5)
    # paper Eq. 13 route: (circular pitch - s_w1 - s_w2) cos(alpha') on the operating pitch circles
    mesh = MeshGeometry(pair, Cp)
    rw1, rw2 = mesh.operating_pitch_radii_m
    s1 = tooth_profile(pair.gear(0)).thickness_at_radius(rw1)
    s2 = tooth_profile(pair.gear(1)).thickness_at_radius(rw2)
    eq13 = (2 * math.pi * rw1 / 30 - s1 - s2) * math.cos(mesh.pressure_angle_rad)
    assert float(eq13) == pytest.approx(backlash(pair, Cp), rel=1e-9)
    # the printed Eq. 15 (C' for C) overstates it by C'/C
    assert backlash(pair, Cp, form="printed") == pytest.approx(hand * Cp / 0.150, rel=1e-9)


def test_profile_shifted_pair_zero_backlash_at_working_distance():
    pair = paper_pair_from({"pair": {"teeth": [20, 45], "profile_shift": [0.4, 0.1], "hub_radius_mm": [20, 40]}})
    Cw = pair.centre_distance_m
    assert backlash(pair, Cw) == pytest.approx(0.0, abs=1e-15)
    mesh = MeshGeometry(pair, Cw)
    rw1, rw2 = mesh.operating_pitch_radii_m
    s1 = tooth_profile(pair.gear(0)).thickness_at_radius(rw1)
    s2 = tooth_profile(pair.gear(1)).thickness_at_radius(rw2)
    # zero backlash: the two thicknesses fill the operating circular pitch exactly
    assert float(s1 + s2) == pytest.approx(2 * math.pi * rw1 / 20, rel=1e-12)


def test_contact_ratio_below_one_and_out_of_mesh():
    pair = default_pair()
    og = operating_geometry(pair, 5.0e-3)
    assert og.contact_ratio < 1.0
    c = og.mesh.contacts(np.linspace(0, og.mesh.mesh_angle_rad, 1000, endpoint=False))
    assert c.count.min() == 0  # gaps without contact
    with pytest.raises(InputError, match="out of mesh"):
        operating_geometry(pair, 10.0e-3)
    with pytest.raises(InputError, match="clearance_um"):
        operating_geometry(pair, -1e-6)


HIGH_CONTACT_RATIO = {
    "teeth": [60, 60],
    "pressure_angle_deg": 14.5,
    "addendum_coefficient": 1.4,
    "dedendum_coefficient": 1.7,
    "rack_tip_radius_coefficient": 0.1,
    "allow_undercut": True,
}


def test_pairs_on_path_and_zone_shares_above_a_contact_ratio_of_two():
    """z = 60/60, alpha = 14.5 deg, h_a* = 1.4: epsilon = 2.907 by the textbook formula.
    Over a mesh period 3 pairs are on the path for (epsilon - 2) of it and 2 pairs for
    (3 - epsilon); the mean number of pairs is epsilon."""
    pair = paper_pair_from({"pair": HIGH_CONTACT_RATIO})
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    m, a = 5e-3, math.radians(14.5)
    r = 30 * m
    rb, ra = r * math.cos(a), r + 1.4 * m
    eps = (2 * math.sqrt(ra**2 - rb**2) - 2 * r * math.sin(a)) / (math.pi * m * math.cos(a))
    assert eps == pytest.approx(2.907, abs=1e-3)
    assert mesh.contact_ratio == pytest.approx(eps, rel=1e-12)
    n = 20000
    theta = np.arange(n) * (mesh.mesh_angle_rad / n)
    pairs = mesh.pairs_on_path(theta)
    assert set(np.unique(pairs)) == {2, 3}
    assert pairs.mean() == pytest.approx(eps, abs=2.0 / n)
    assert np.mean(pairs == 3) == pytest.approx(eps - 2, abs=2.0 / n)
    shares = mesh.zone_shares()
    assert shares[3] == pytest.approx(eps - 2, rel=1e-12) and shares[2] == pytest.approx(3 - eps, rel=1e-12)
    # the same count as the slot bookkeeping (contacts on the path)
    assert np.mean(mesh.contacts(theta).count != pairs) < 1e-3


def _step_curve(mesh, per_pair):
    """k = per_pair x (pairs on the path) as a piecewise-linear table that is that step
    function: 360 uniform nodes plus nodes on both sides of the zone edges, where a pair
    leaves at E: d_A + r_b1 theta + j p_b = d_E, theta_E = ((d_E - d_A) mod p_b) / r_b1,
    and where one enters at A (theta = 0, the period's end)."""
    from gearwear.geometry.curves import CurveStats

    class Curve(CurveStats):
        def __init__(self, theta, k):
            self.mesh, self.angle_rad, self.k_N_per_m = mesh, theta, k

    P = mesh.mesh_angle_rad
    th_E = math.fmod(mesh.path_end_m - mesh.path_start_m, mesh.base_pitch_m) / mesh.pair.gear(0).base_radius_m
    theta = np.union1d(np.arange(360) * (P / 360), [th_E, th_E + 1e-12 * P, P * (1 - 1e-12)])
    return Curve(theta, per_pair * mesh.pairs_on_path(theta))


def test_zone_means_by_number_of_pairs_never_nan():
    pair = paper_pair_from({"pair": HIGH_CONTACT_RATIO})
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    z = _step_curve(mesh, 1e8).zone_means()  # 1e8 N/m per pair on the path
    assert z["by_count"][1] is None and set(z["by_count"]) == {1, 2, 3}
    assert z["by_count"][2] == pytest.approx(2e8, rel=1e-9) and z["by_count"][3] == pytest.approx(3e8, rel=1e-9)
    assert math.isnan(z["single"]) and z["double"] == z["by_count"][2]
    assert z["deg_by_count"][3] == pytest.approx((mesh.contact_ratio - 2) * 6.0, rel=1e-12)
    assert z["single_deg"] == 0.0
    # a contact ratio below 1: the gap is the zone of 0 pairs
    low = MeshGeometry(default_pair(), default_pair().centre_distance_m + 5e-3)
    assert low.contact_ratio < 1
    z = _step_curve(low, 5.0).zone_means()["by_count"]
    assert set(z) == {0, 1, 2, 3} and z[2] is None and z[3] is None
    assert z[0] == pytest.approx(0.0, abs=1e-9) and z[1] == pytest.approx(5.0, rel=1e-9)


def test_contact_ratio_below_one_is_stated():
    pair = default_pair()
    og = operating_geometry(pair, 5.0e-3)
    eps = og.contact_ratio
    assert eps == pytest.approx(textbook_contact_ratio(30, 30, 5e-3, math.radians(20), og.centre_distance_m), rel=1e-12)
    (w,) = og.mesh.contact_ratio_warnings()
    assert w.startswith(
        f"contact ratio {eps:.3f} < 1: no pair is in contact on the path of contact for "
        f"{100 * (1 - eps):.1f} % of each mesh period"
    )
    assert MeshGeometry(pair, pair.centre_distance_m).contact_ratio_warnings() == []
    with pytest.raises(InputError, match=r"^method = 'fem': needs a contact ratio >= 1"):
        og.mesh.require_overlap("fem")
