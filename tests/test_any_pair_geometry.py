"""Geometry of pairs other than the paper's: identities that hold for any spur pair,
checked on random valid pairs (hypothesis) and on the named unequal, shifted, 25 deg and
high-contact-ratio pairs of tests/pairs.py.

Every expected value is written out here from ISO 21771 / textbook involute geometry
(radii, inv(alpha_w), the path of contact from the tip circles, the backlash from the base
circles and from the tooth thicknesses); none is copied from the tool's output. The paper
pair (30/30, x 0/0) is symmetric in pinion and gear, so only these pairs can tell r_b1 from
r_b2, z1 from z2 or the pinion's tip from the gear's.
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings

from gearwear.core.validation import InputError
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import backlash
from gearwear.geometry.profile import FILLET, INVOLUTE, TIP_LAND, tooth_profile
from gearwear.geometry.spec import PairSpec, check_pair, inv

from pairs import DRIVER_LARGER, NAMED, UNEQUAL, WITH_PAPER, by_hand_radii, by_hand_working_pressure_angle, valid_pairs


def _by_hand_path(pair: PairSpec, a: float) -> tuple[float, float]:
    """(path of contact, operating pressure angle) at centre distance a from the by-hand
    radii: g = sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin(alpha'),
    cos(alpha') = (r_b1 + r_b2) / a."""
    r = [by_hand_radii(pair, i) for i in (0, 1)]
    ap = math.acos((r[0]["base"] + r[1]["base"]) / a)
    g = sum(math.sqrt(ri["tip"] ** 2 - ri["base"] ** 2) for ri in r) - a * math.sin(ap)
    return g, ap


# -- identities for any valid pair ---------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(valid_pairs())
def test_base_pitches_equal_and_base_radii_fill_the_working_centre_distance(pair):
    """Two involute gears mesh only with equal base pitches, 2 pi r_b,i / z_i = pi m cos(alpha)
    for both; and at the zero-backlash centre distance the line of action is tangent to both
    base circles, r_b1 + r_b2 = a_w cos(alpha_w), with inv(alpha_w) = inv(alpha) +
    2 (x1 + x2) tan(alpha) / (z1 + z2) solved here by bisection."""
    pb = math.pi * pair.module_m * math.cos(pair.pressure_angle_rad)
    for i, g in enumerate(pair.gears):
        assert 2 * math.pi * g.base_radius_m / pair.teeth[i] == pytest.approx(pb, rel=1e-13)
        assert g.base_pitch_m == pytest.approx(pb, rel=1e-13)
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    assert mesh.base_pitch_m == pytest.approx(pb, rel=1e-13)
    a_w = pair.zero_backlash_centre_distance_m
    alpha_w = by_hand_working_pressure_angle(pair)
    assert pair.working_pressure_angle_rad == pytest.approx(alpha_w, rel=1e-12, abs=1e-15)
    assert mesh.pressure_angle_rad == pytest.approx(alpha_w, rel=1e-12, abs=1e-15)
    rb = [by_hand_radii(pair, i)["base"] for i in (0, 1)]
    assert rb[0] + rb[1] == pytest.approx(a_w * math.cos(alpha_w), rel=1e-12)
    assert a_w == pytest.approx(by_hand_radii(pair, 0)["a_w"], rel=1e-12)


@settings(max_examples=60, deadline=None)
@given(valid_pairs())
def test_contact_ratio_is_the_path_from_the_tip_circles_over_the_base_pitch(pair):
    """epsilon = [sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a' sin(alpha')] / p_b with
    every radius written out from ISO 21771 (tip shortening k included); the path starts
    on the gear's tip circle (d_A = T1T2 - sqrt(r_a2^2 - r_b2^2)) and ends on the pinion's
    (d_E = sqrt(r_a1^2 - r_b1^2)); the pitch point is T1C = r_b1 tan(alpha'), and the
    operating pitch radii r_b,i / cos(alpha') are in the ratio z2 / z1."""
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    r = [by_hand_radii(pair, i) for i in (0, 1)]
    for i, g in enumerate(pair.gears):
        assert g.tip_radius_m == pytest.approx(r[i]["tip"], rel=1e-12)
        assert g.root_radius_m == pytest.approx(r[i]["root"], rel=1e-12)
    g_path, ap = _by_hand_path(pair, r[0]["a_w"])
    pb = math.pi * pair.module_m * math.cos(pair.pressure_angle_rad)
    assert mesh.path_length_m == pytest.approx(g_path, rel=1e-9, abs=1e-15)
    assert mesh.contact_ratio == pytest.approx(g_path / pb, rel=1e-9, abs=1e-12)
    L = r[0]["a_w"] * math.sin(ap)
    assert mesh.path_end_m == pytest.approx(math.sqrt(r[0]["tip"] ** 2 - r[0]["base"] ** 2), rel=1e-12)
    assert mesh.path_start_m == pytest.approx(
        L - math.sqrt(r[1]["tip"] ** 2 - r[1]["base"] ** 2), rel=1e-9, abs=1e-12 * L
    )
    assert mesh.pitch_point_m == pytest.approx(r[0]["base"] * math.tan(ap), rel=1e-12)
    rw1, rw2 = mesh.operating_pitch_radii_m
    assert rw2 / rw1 == pytest.approx(pair.teeth[1] / pair.teeth[0], rel=1e-12)
    assert rw1 + rw2 == pytest.approx(pair.centre_distance_m, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(valid_pairs())
def test_swapping_pinion_and_gear_mirrors_the_mesh(pair):
    """The same two gears with the roles swapped (teeth, shifts, bores reversed) mesh at the
    same centre distance with the same path of contact and contact ratio; the path runs
    the other way (d -> T1T2 - d) and the pitch point mirrors. A formula that reads one
    gear's radii for the other's breaks this on any unequal pair."""
    swapped = replace(
        pair, teeth=pair.teeth[::-1], profile_shift=pair.profile_shift[::-1], hub_radius_m=pair.hub_radius_m[::-1]
    )
    check_pair(swapped)
    m, s = MeshGeometry(pair, pair.centre_distance_m), MeshGeometry(swapped, swapped.centre_distance_m)
    L = m.line_of_action_m
    assert s.centre_distance_m == pytest.approx(m.centre_distance_m, rel=1e-13)
    assert s.line_of_action_m == pytest.approx(L, rel=1e-12)
    assert s.contact_ratio == pytest.approx(m.contact_ratio, rel=1e-10)
    assert s.path_start_m == pytest.approx(L - m.path_end_m, rel=1e-10, abs=1e-12 * L)
    assert s.path_end_m == pytest.approx(L - m.path_start_m, rel=1e-10, abs=1e-12 * L)
    assert s.pitch_point_m == pytest.approx(L - m.pitch_point_m, rel=1e-10)


# -- the named pairs -----------------------------------------------------------------------


@pytest.mark.parametrize("name", list(WITH_PAPER))
@pytest.mark.parametrize("i", [0, 1])
def test_generated_profile_has_the_iso_thickness_and_radii(name, i):
    """On the generated flank (the polyline the FE and the slice models use): every involute
    point at radius R has the half angle s(R) / (2 R) with the ISO 21771 thickness
    s(R) = 2 R (s / (2 r) + inv(alpha) - inv(alpha_R)), s = m (pi/2 + 2 x tan alpha),
    cos(alpha_R) = r_b / R; its normal line is tangent to the base circle (distance r_b
    from the centre); the flank reaches from the root circle r_f to the tip circle r_a
    (by-hand radii) and the tip land has the thickness s(r_a)."""
    pair = WITH_PAPER[name]
    g = pair.gear(i)
    r = by_hand_radii(pair, i)
    m, x, alpha = pair.module_m, pair.profile_shift[i], pair.pressure_angle_rad
    s_ref = m * (0.5 * math.pi + 2 * x * math.tan(alpha))

    def half_angle(R):
        alpha_R = np.arccos(r["base"] / np.asarray(R))
        return s_ref / (2 * r["pitch"]) + inv(alpha) - (np.tan(alpha_R) - alpha_R)

    prof = tooth_profile(g)
    inv_pts = prof.region == INVOLUTE
    R = prof.radius[inv_pts]
    beta = np.arctan2(prof.xy[inv_pts, 0], prof.xy[inv_pts, 1])
    assert np.allclose(beta, half_angle(R), rtol=0, atol=1e-12)
    xy, n = prof.xy[inv_pts], prof.normal[inv_pts]
    assert np.allclose(np.abs(xy[:, 0] * n[:, 1] - xy[:, 1] * n[:, 0]), r["base"], rtol=1e-10, atol=0)
    assert R.min() >= r["base"] * (1 - 1e-12)
    assert prof.radius.min() == pytest.approx(r["root"], rel=1e-12)
    assert prof.radius.max() == pytest.approx(r["tip"], rel=1e-12)
    tip = prof.region == TIP_LAND
    assert np.allclose(prof.radius[tip], r["tip"], rtol=1e-12, atol=0)
    on_tip_circle = np.abs(prof.radius - r["tip"]) <= 1e-12 * r["tip"]  # the tip land and the involute's end
    beta_tip = np.arctan2(prof.xy[on_tip_circle, 0], prof.xy[on_tip_circle, 1]).max()
    assert beta_tip == pytest.approx(half_angle(r["tip"]), abs=1e-12)
    # the fillet joins the involute below the start of the active profile of this flank
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    sap = mesh.start_of_active_profile_m[i]
    assert prof.radius[prof.region == FILLET].max() <= sap * (1 + 1e-12)
    # and the start of active profile is where the mate's tip circle meets the line of action
    mate = by_hand_radii(pair, 1 - i)
    L = mesh.line_of_action_m
    roll_len = L - math.sqrt(mate["tip"] ** 2 - mate["base"] ** 2)
    assert sap == pytest.approx(math.hypot(r["base"], roll_len), rel=1e-12)


@pytest.mark.parametrize("name", list(NAMED))
def test_backlash_at_an_installed_centre_distance(name):
    """Mounted at a > a_w the pair opens the normal backlash 2 (r_b1 + r_b2)(inv alpha' -
    inv alpha_w) (cos alpha' = (r_b1 + r_b2) / a, alpha_w by bisection), which is also the
    operating circular pitch minus both tooth thicknesses on the operating pitch circles
    times cos(alpha') (paper Eq. 13; the thicknesses by ISO 21771, written out); zero at a_w.
    The contact ratio (path from the tip circles, by hand) falls as a grows."""
    base = NAMED[name]
    r = [by_hand_radii(base, i) for i in (0, 1)]
    a_w, alpha_w = r[0]["a_w"], by_hand_working_pressure_angle(base)
    rb_sum = r[0]["base"] + r[1]["base"]
    alpha = base.pressure_angle_rad
    eps = []
    assert base.centre_distance_m == pytest.approx(a_w, rel=1e-13)
    for extra in (0.0, 0.05e-3, 0.2e-3, 0.5e-3):
        a = base.centre_distance_m + extra  # the library's a_w: a by-hand one may be 1 ulp below
        pair = replace(base, installed_centre_distance_m=a)
        check_pair(pair)
        assert pair.centre_distance_m == a
        ap = math.acos(rb_sum / a)
        hand = 2 * rb_sum * (inv(ap) - inv(alpha_w))
        j = backlash(pair, pair.centre_distance_m)
        assert j == pytest.approx(hand, rel=1e-9, abs=1e-15)
        # Eq. 13 through the thicknesses on the operating pitch circles r_w,i = r_b,i / cos(alpha')
        s_w = []
        for i in (0, 1):
            rw = r[i]["base"] / math.cos(ap)
            s_ref = base.module_m * (0.5 * math.pi + 2 * base.profile_shift[i] * math.tan(alpha))
            s_w.append(2 * rw * (s_ref / (2 * r[i]["pitch"]) + inv(alpha) - inv(ap)))
        p_w = 2 * math.pi * r[0]["base"] / math.cos(ap) / base.teeth[0]
        assert (p_w - s_w[0] - s_w[1]) * math.cos(ap) == pytest.approx(hand, rel=1e-7, abs=1e-13)
        mesh = MeshGeometry(pair, pair.centre_distance_m)
        assert mesh.pressure_angle_rad == pytest.approx(ap, rel=1e-12)
        g_path, _ = _by_hand_path(base, a)
        assert mesh.contact_ratio == pytest.approx(g_path / base.gear(0).base_pitch_m, rel=1e-9)
        eps.append(mesh.contact_ratio)
    assert eps[0] == pytest.approx(MeshGeometry(base, base.centre_distance_m).contact_ratio, rel=1e-12)
    assert np.all(np.diff(eps) < 0)


def test_mirrored_pairs_share_centre_distance_backlash_and_contact_ratio():
    """UNEQUAL and DRIVER_LARGER are the same two gears with the driver swapped: at every
    installed centre distance they have the same backlash and contact ratio."""
    for extra in (0.0, 0.3e-3):
        a = UNEQUAL.centre_distance_m + extra
        p, q = (replace(x, installed_centre_distance_m=a) for x in (UNEQUAL, DRIVER_LARGER))
        assert backlash(p, a) == pytest.approx(backlash(q, a), rel=1e-12, abs=1e-18)
        mp, mq = MeshGeometry(p, a), MeshGeometry(q, a)
        assert mp.contact_ratio == pytest.approx(mq.contact_ratio, rel=1e-12)


@pytest.mark.parametrize("name", list(NAMED))
def test_installed_centre_distance_below_a_w_is_refused_in_one_line(name):
    """Closer than the zero-backlash a_w the flanks would interpenetrate: check_pair refuses
    it with a one-line InputError that names installed_centre_distance_m."""
    base = NAMED[name]
    a_w = by_hand_radii(base, 0)["a_w"]
    with pytest.raises(InputError) as err:
        check_pair(replace(base, installed_centre_distance_m=a_w - 10e-6))
    msg = str(err.value)
    assert "installed_centre_distance_m" in msg and "\n" not in msg
    check_pair(replace(base, installed_centre_distance_m=base.centre_distance_m))  # a_w itself is allowed
