"""Limits of the gear-pair geometry (issue 12): tip inside the base circle, pointed teeth,
undercut, tip/root interference, ISO 21771 tip shortening and given tip/root diameters.

Every expected value is worked out here by hand from textbook/ISO 21771 relations (the
involute function, the line of action, the rack-generation of the form circle), not read
back from the code's own checks.
"""

from __future__ import annotations

import math
import re

import pytest
from scipy.optimize import brentq

from gearwear.core.validation import InputError
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.profile import form_radius_m, tooth_profile
from gearwear.geometry.spec import PairSpec

from scenes import paper_pair_from

ALPHA = math.radians(20.0)
M = 5e-3


def inv(a: float) -> float:
    return math.tan(a) - a


def refused(pair: dict) -> str:
    with pytest.raises(InputError) as err:
        paper_pair_from({"pair": pair})
    msg = str(err.value)
    assert "\n" not in msg and "domain" not in msg
    return msg


def quoted_range(msg: str) -> tuple[float, float]:
    lo, hi = re.search(r"must be in [\[(]([-\d.e+]+), ([-\d.e+]+)[\])]", msg).groups()
    return float(lo), float(hi)


def working(z1: int, z2: int, x1: float, x2: float, alpha: float = ALPHA, m: float = M):
    """(alpha_w, a_w, k) by hand: inv(alpha_w) = inv(alpha) + 2 (x1 + x2) tan(alpha) / (z1 + z2)
    (solved by bracketing, not Newton), a_w = a cos(alpha) / cos(alpha_w), ISO 21771 tip
    alteration k = (a_w - a) / m - (x1 + x2)."""
    target = inv(alpha) + 2 * (x1 + x2) * math.tan(alpha) / (z1 + z2)
    a_w_angle = brentq(lambda t: inv(t) - target, 1e-6, 1.5, xtol=1e-15, rtol=1e-15)
    a = 0.5 * m * (z1 + z2)
    a_w = a * math.cos(alpha) / math.cos(a_w_angle)
    return a_w_angle, a_w, (a_w - a) / m - (x1 + x2)


def tip_radius(z, x, k, ha=1.0, m=M):
    return 0.5 * m * z + (ha + x + k) * m


# -- 1. tip circle inside the base circle; pointed teeth -----------------------------------


def test_tip_inside_base_circle_is_one_line_with_the_shift_range():
    pair = {"teeth": [8, 30], "profile_shift": [-1.5, 0], "allow_undercut": True, "hub_radius_mm": [5, 40]}
    msg = refused(pair)
    assert msg.startswith("pair.profile_shift[0] = -1.5: must be in ")
    assert "inside the base circle" in msg
    lo, hi = quoted_range(msg)
    # by hand: the unshortened tip r + (1 + x) m clears r cos(alpha) for x > -1 - z (1 - cos a) / 2
    assert -1.5 < -1 - 4 * (1 - math.cos(ALPHA))
    # the sum x1 + x2 needs inv(alpha_w) > 0: x1 > -inv(alpha) (z1 + z2) / (2 tan(alpha))
    x_sum_min = -inv(ALPHA) * 38 / (2 * math.tan(ALPHA))
    assert lo == pytest.approx(x_sum_min, abs=1e-4) and lo > x_sum_min
    # the upper bound: a pointed tip (tip thickness zero, ISO 21771 with the tip shortening)
    rb = 0.5 * M * 8 * math.cos(ALPHA)

    def half_tip(x):
        _, _, k = working(8, 30, x, 0.0)
        ra = tip_radius(8, x, k)
        return (math.pi / 2 + 2 * x * math.tan(ALPHA)) / 8 + inv(ALPHA) - inv(math.acos(rb / ra))

    assert half_tip(hi) >= 0 > half_tip(hi + 2e-4)


def test_pointed_tooth_states_the_allowed_shift():
    msg = refused({"teeth": [8, 30], "profile_shift": [2, 0], "hub_radius_mm": [5, 40]})
    assert msg.startswith("pair.profile_shift[0] = 2: must be in ") and "pointed" in msg
    lo, hi = quoted_range(msg)
    assert lo < hi < 2


# -- 2. undercut ---------------------------------------------------------------------------


def test_undercut_refusal_names_the_scene_keys_and_the_limits():
    msg = refused({"teeth": [12, 30], "hub_radius_mm": [10, 40]})
    # ISO limit with the rack tip round rho* = 0.38: no undercut while
    # (z / 2) sin^2(alpha) >= h_f* - x - rho* (1 - sin(alpha))
    depth = 1.25 - 0.38 * (1 - math.sin(ALPHA))
    z_min = math.ceil(2 * depth / math.sin(ALPHA) ** 2)
    x_min = depth - 6 * math.sin(ALPHA) ** 2
    assert z_min == 18
    m = re.fullmatch(
        r"pair\.teeth\[0\] = 12: undercut by the basic rack at profile_shift 0 \(needs pair\.teeth >= "
        r"(\d+) or pair\.profile_shift\[0\] >= ([\d.]+)\); pair\.allow_undercut = true generates the "
        r"undercut profile",
        msg,
    )
    assert m, msg
    assert int(m.group(1)) == z_min
    assert x_min <= float(m.group(2)) < x_min + 1e-4
    # the quoted shift is enough
    p = paper_pair_from(
        {"pair": {"teeth": [12, 30], "profile_shift": [float(m.group(2)), 0.0], "hub_radius_mm": [10, 40]}}
    )
    assert not tooth_profile(p.gear(0)).undercut


# -- 3. tip/root interference --------------------------------------------------------------


def test_classical_rack_limit_z_min_17():
    """A pinion meshing with a rack (here a 1000-tooth gear) interferes below
    z_min = 2 h_a* / sin^2(alpha) = 17.1 whatever its cut: the rack's tip line passes the
    interference point T1."""
    assert 2 / math.sin(ALPHA) ** 2 == pytest.approx(17.097, abs=1e-3)
    msg = refused({"teeth": [16, 1000], "allow_undercut": True, "hub_radius_mm": [10, 40]})
    assert msg.startswith("pair.profile_shift[0] = 0: tip/root interference") and "T1" in msg
    # by hand: contact would start before T1, d_A = C sin(alpha) - sqrt(r_a2^2 - r_b2^2) < 0
    r2, C = 0.5 * M * 1000, 0.5 * M * 1016
    assert C * math.sin(ALPHA) - math.sqrt((r2 + M) ** 2 - (r2 * math.cos(ALPHA)) ** 2) < 0
    # 18 teeth, not undercut: contact starts above the form circle cut by the rack's flank end
    pair = paper_pair_from({"pair": {"teeth": [18, 1000], "hub_radius_mm": [10, 40]}})
    r1, C = 0.5 * M * 18, 0.5 * M * 1018
    y_T = -(1.25 - 0.38 * (1 - math.sin(ALPHA))) * M  # lower end of the rack's straight flank
    roll_F = r1 * math.sin(ALPHA) + y_T / math.sin(ALPHA)  # r_b u_F, from T1 along the line of action
    d_A = C * math.sin(ALPHA) - math.sqrt((r2 + M) ** 2 - (r2 * math.cos(ALPHA)) ** 2)
    assert 0 < roll_F < d_A
    assert MeshGeometry(pair, pair.centre_distance_m).path_start_m == pytest.approx(d_A, abs=1e-12)


def test_classical_equal_gears_limit():
    """Equal gears (h_a* = 1, alpha = 20 deg) need z >= 2 / (3 sin^2 a) (1 + sqrt(1 + 3 sin^2 a)) = 12.3
    teeth (e.g. Shigley, Eq. 13-11 with m_G = 1) when the involute reaches down to the
    base circle. A rack with h_f* = 1.05 and rho* = 0.45 cuts the 13-tooth involute
    almost to it."""
    s2 = math.sin(ALPHA) ** 2
    assert 2 / (3 * s2) * (1 + math.sqrt(1 + 3 * s2)) == pytest.approx(12.32, abs=0.01)
    rack = {"dedendum_coefficient": 1.05, "rack_tip_radius_coefficient": 0.45, "hub_radius_mm": [10, 10]}
    pair = paper_pair_from({"pair": {"teeth": [13, 13], **rack}})
    assert not tooth_profile(pair.gear(0)).undercut
    msg = refused({"teeth": [12, 12], "allow_undercut": True, **rack})
    assert "tip/root interference" in msg and "beyond its interference point T1" in msg


def test_interference_boundary_on_the_mates_tip_diameter():
    """Hand-worked boundary: on the line of action (length T1T2 = a_w sin(alpha_w)) the
    pinion flank's involute starts at roll length r_b1 u_F from T1, with u_F from the
    rack's flank end (r_b u_F = r sin(alpha) + y_T / sin(alpha)). The gear tip may reach
    down to there: r_a2,max = sqrt(r_b2^2 + (T1T2 - r_b1 u_F)^2). Just below: accepted,
    just above: refused, naming both radii. (z = 13/40, rack h_f* = 1.05, rho* = 0.45:
    d_a2,max = 208.57 mm, below the default 210 mm and the tip-clearance limit 210.5 mm.)"""
    rack = {"dedendum_coefficient": 1.05, "rack_tip_radius_coefficient": 0.45, "hub_radius_mm": [10, 40]}
    z1, z2 = 13, 40
    r1, r2 = 0.5 * M * z1, 0.5 * M * z2
    rb1, rb2 = r1 * math.cos(ALPHA), r2 * math.cos(ALPHA)
    y_T = -(1.05 - 0.45 * (1 - math.sin(ALPHA))) * M
    roll_F = r1 * math.sin(ALPHA) + y_T / math.sin(ALPHA)
    r_form = math.hypot(rb1, roll_F)
    T1T2 = (r1 + r2) * math.sin(ALPHA)
    ra2_max = math.hypot(rb2, T1T2 - roll_F)
    assert 2e3 * ra2_max == pytest.approx(208.57, abs=0.01)
    assert "tip/root interference" in refused({"teeth": [z1, z2], **rack})  # the default gear tip, 210 mm
    d_ok = 2 * ra2_max * 0.999 * 1e3
    pair = paper_pair_from({"pair": {"teeth": [z1, z2], "tip_diameter_mm": [75.0, d_ok], **rack}})
    assert form_radius_m(pair.gear(0)) == pytest.approx(r_form, abs=1e-12)
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    assert mesh.start_of_active_profile_m[0] > r_form
    d_bad = 2 * ra2_max * 1.001 * 1e3
    msg = refused({"teeth": [z1, z2], "tip_diameter_mm": [75.0, d_bad], **rack})
    assert msg.startswith(f"pair.tip_diameter_mm[1] = {d_bad:g} mm: must be in ")
    assert f"r_Nf = {r_form * 1e3:.4f} mm" in msg
    r_contact = math.hypot(rb1, T1T2 - math.sqrt((d_bad / 2e3) ** 2 - rb2**2))
    assert f"r = {r_contact * 1e3:.4f} mm" in msg
    assert f"<= {2e3 * ra2_max:.4f} mm" in msg
    assert quoted_range(msg)[1] == pytest.approx(2e3 * ra2_max, abs=1e-3)


def test_five_tooth_pair_with_undercut_is_refused(capsys):
    from gearwear.cli import main

    rc = main(
        [
            "stiffness",
            "--set",
            "pair.teeth=[5,5]",
            "--set",
            "pair.allow_undercut=true",
            "--set",
            "pair.hub_radius_mm=[3,3]",
            "--json",
        ]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert err[0].startswith("gearwear: error: pair.profile_shift[0] = 0: tip/root interference")
    # by hand: T1T2 = 2 r sin(alpha) = 8.55 mm, and the tip circle meets the line of action
    # sqrt(r_a^2 - r_b^2) = 12.97 mm from T2, i.e. 4.42 mm beyond T1
    r, rb, ra = 12.5e-3, 12.5e-3 * math.cos(ALPHA), 17.5e-3
    beyond = math.sqrt(ra**2 - rb**2) - 2 * r * math.sin(ALPHA)
    assert f"{beyond * 1e3:.3f} mm beyond its interference point T1" in err[0]


def test_form_radius_is_the_generated_involute_start():
    """With and without undercut, the form radius the pair check uses is where the
    generated profile's involute starts; without undercut it is the textbook point the
    rack's flank end generates."""
    for teeth, undercut in ((30, False), (18, False), (12, True), (5, True)):
        g = PairSpec(teeth=(teeth, 1000), allow_undercut=undercut, hub_radius_m=(3e-3, 0.4)).gear(0)
        prof = tooth_profile(g)
        assert prof.undercut == undercut
        assert form_radius_m(g) == prof.form_radius_m
        if not undercut:
            y_T = -(1.25 - 0.38 * (1 - math.sin(ALPHA))) * M
            roll = 0.5 * M * teeth * math.sin(ALPHA) + y_T / math.sin(ALPHA)
            assert prof.form_radius_m == pytest.approx(math.hypot(g.base_radius_m, roll), abs=1e-13)
        else:
            assert prof.form_radius_m > g.base_radius_m


# -- 4. ISO 21771 tip shortening -----------------------------------------------------------


@pytest.mark.parametrize("teeth,shift", [((21, 37), (0.25, -0.10)), ((20, 40), (0.6, 0.4)), ((25, 31), (0.3, -0.3))])
def test_tip_shortening_keeps_the_bottom_clearance(teeth, shift):
    (z1, z2), (x1, x2) = teeth, shift
    pair = paper_pair_from({"pair": {"teeth": list(teeth), "profile_shift": list(shift), "hub_radius_mm": [20, 30]}})
    _, a_w, k = working(z1, z2, x1, x2)
    assert k <= 0.0
    if x1 + x2 == 0:
        assert k == 0.0 and pair.tip_alteration_coefficient == 0.0
    assert pair.centre_distance_m == pytest.approx(a_w, abs=1e-12)
    assert pair.tip_alteration_coefficient == pytest.approx(k, abs=1e-12)
    g1, g2 = pair.gears
    assert g1.tip_radius_m == pytest.approx(tip_radius(z1, x1, k), abs=1e-12)
    assert g2.tip_radius_m == pytest.approx(tip_radius(z2, x2, k), abs=1e-12)
    # bottom clearance c* m = (h_f* - h_a*) m = 0.25 m at both roots
    assert a_w - g1.tip_radius_m - g2.root_radius_m == pytest.approx(0.25 * M, abs=1e-12)
    assert a_w - g2.tip_radius_m - g1.root_radius_m == pytest.approx(0.25 * M, abs=1e-12)
    # the profiles, the path of contact and the contact ratio use the shortened tips
    assert tooth_profile(g1).radius.max() == pytest.approx(g1.tip_radius_m, abs=1e-12)
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    alpha_w = math.acos((g1.base_radius_m + g2.base_radius_m) / a_w)
    path = (
        math.sqrt(g1.tip_radius_m**2 - g1.base_radius_m**2)
        + math.sqrt(g2.tip_radius_m**2 - g2.base_radius_m**2)
        - a_w * math.sin(alpha_w)
    )
    assert mesh.contact_ratio == pytest.approx(path / (math.pi * M * math.cos(ALPHA)), rel=1e-12)


def test_x_sum_one_worked_example():
    """z = 20/40, m = 5 mm, x1 + x2 = 1.0: inv(alpha_w) = inv 20 deg + 2 tan 20 deg / 60
    = 0.0149044 + 0.0121323 = 0.0270367, alpha_w = 24.197 deg, a_w = 150 cos 20 deg /
    cos alpha_w = 154.530 mm (y = 0.9061), k = y - 1 = -0.0939: the tips lose 0.47 mm."""
    alpha_w, a_w, k = working(20, 40, 0.6, 0.4)
    assert inv(ALPHA) + 2 * math.tan(ALPHA) / 60 == pytest.approx(0.0270367, abs=1e-7)
    assert math.degrees(alpha_w) == pytest.approx(24.197, abs=1e-3)
    assert a_w == pytest.approx(154.530e-3, abs=1e-6)
    assert k == pytest.approx(-0.0939, abs=1e-4)
    pair = paper_pair_from({"pair": {"teeth": [20, 40], "profile_shift": [0.6, 0.4], "hub_radius_mm": [20, 30]}})
    assert pair.gear(0).tip_radius_m == pytest.approx(50e-3 + 1.6 * M + k * M, abs=1e-12)


def test_given_tip_and_root_diameters():
    pair = paper_pair_from({"pair": {"tip_diameter_mm": [159.0, 158.0], "root_diameter_mm": [137.0, 138.0]}})
    g1, g2 = pair.gears
    assert (g1.tip_radius_m, g2.tip_radius_m) == (79.5e-3, 79.0e-3)
    assert g1.root_radius_m == pytest.approx(68.5e-3, abs=1e-15)
    # the root diameter is the tool dedendum h_f* = (d - d_f) / (2 m) + x
    assert g1.dedendum_coefficient == pytest.approx((150 - 137) / 10, abs=1e-12)
    prof = tooth_profile(g1)
    assert prof.radius.min() == pytest.approx(68.5e-3, abs=1e-12)
    assert prof.radius.max() == pytest.approx(79.5e-3, abs=1e-12)
    # the form circle follows the tool: r_b u_F = r sin(alpha) + y_T / sin(alpha)
    y_T = -(1.3 - 0.38 * (1 - math.sin(ALPHA))) * M
    roll = 75e-3 * math.sin(ALPHA) + y_T / math.sin(ALPHA)
    assert prof.form_radius_m == pytest.approx(math.hypot(g1.base_radius_m, roll), abs=1e-12)


@pytest.mark.parametrize(
    "key,value",
    [
        ("tip_diameter_mm", [175.0, 160.0]),
        ("tip_diameter_mm", [140.0, 160.0]),
        ("root_diameter_mm", [141.0, 137.5]),
        ("root_diameter_mm", [120.0, 137.5]),
    ],
)
def test_given_diameters_out_of_range(key, value):
    msg = refused({key: value})
    assert msg.startswith(f"pair.{key}[0] = {value[0]:g} mm: must be in ")
    lo, hi = quoted_range(msg)
    assert not lo < value[0] <= hi
    # base circle 140.95 mm; tip clearance: d_f1 < 2 a_w - d_a2 = 140 mm (default gear tip 160 mm)
    if key == "tip_diameter_mm":
        assert lo >= 2 * 75 * math.cos(ALPHA)
    else:
        assert hi == pytest.approx(140.0, abs=1e-9)


# -- 5. contact ratio above 2 and below 1 in the summaries -----------------------------------

HIGH_CR = [
    "--set",
    "pair.teeth=[60,60]",
    "--set",
    "pair.pressure_angle_deg=14.5",
    "--set",
    "pair.addendum_coefficient=1.4",
    "--set",
    "pair.dedendum_coefficient=1.7",
    "--set",
    "pair.rack_tip_radius_coefficient=0.1",
    "--set",
    "pair.allow_undercut=true",
]


def _json_run(argv, capsys):
    import json

    from gearwear.cli import main

    rc = main(argv)
    out, err = capsys.readouterr()
    assert rc == 0, err
    return json.loads(out)  # the strict parser: NaN would not get here as a number


def test_stiffness_json_above_a_contact_ratio_of_two(capsys):
    import json

    d = _json_run(["stiffness", *HIGH_CR, "--json", "--method", "ishikawa", "--points", "120"], capsys)
    assert 2.9 < d["contact_ratio"] < 3
    assert d["single_zone_mean_N_per_m"] is None
    zm = d["zone_means_N_per_m"]
    assert zm["1"] is None and zm["2"] > 0 and zm["3"] > zm["2"]  # three pairs share the load: stiffer
    assert d["double_zone_mean_N_per_m"] == zm["2"]
    eps, period = d["contact_ratio"], 6.0
    assert d["zone_lengths_deg"]["3"] == pytest.approx((eps - 2) * period, rel=1e-9)
    assert d["zone_lengths_deg"]["2"] == pytest.approx((3 - eps) * period, rel=1e-9)
    assert d["warnings"] == []
    json.dumps(d, allow_nan=False)


def test_contact_ratio_below_one_in_the_summaries(capsys):
    from gearwear.cli import main

    d = _json_run(["stiffness", "--clearance-um", "5000", "--json"], capsys)
    eps = d["contact_ratio"]
    assert eps < 1 and d["double_zone_mean_N_per_m"] is None
    assert d["warnings"] and d["warnings"][0].startswith(f"contact ratio {eps:.3f} < 1")
    assert f"{100 * (1 - eps):.1f} % of each mesh period" in d["warnings"][0]
    g = _json_run(["geometry", "--no-mesh", "--clearance-um", "5000", "--json"], capsys)
    assert g["warnings"] == [d["warnings"][0]]
    # ISO 6336 has no mean stiffness without overlapping pairs: one line naming --method
    assert main(["stiffness", "--clearance-um", "5000", "--method", "iso6336"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(
        "gearwear: error: --method = 'iso6336': ISO 6336-1 method B needs a contact ratio >= 1"
    )


def test_interference_of_a_large_pinion_shift_and_the_fix_it_names():
    """z = 30/30, x = +1.3/-0.3 (ISO 53 rack): the rack that cut the pinion was withdrawn so
    far that its flank end (y_T above the pitch line) starts the involute at
    r_b u_F = r sin(alpha) + y_T / sin(alpha); the shortened gear tip reaches below it.
    More shift on the gear (x2 = +0.3) clears it; the message names that key."""

    def pinion_margin(x1, x2):
        alpha_w, a_w, k = working(30, 30, x1, x2)
        r, rb = 75e-3, 75e-3 * math.cos(ALPHA)
        ra2 = tip_radius(30, x2, k)
        d_A = a_w * math.sin(alpha_w) - math.sqrt(ra2**2 - rb**2)
        y_T = -(1.25 - x1) * M + 0.38 * M * (1 - math.sin(ALPHA))
        return d_A - (r * math.sin(ALPHA) + y_T / math.sin(ALPHA))

    assert pinion_margin(1.3, -0.3) < 0 < pinion_margin(1.3, 0.3)
    msg = refused({"profile_shift": [1.3, -0.3]})
    assert msg.startswith("pair.profile_shift[1] = -0.3: tip/root interference: the gear tip circle")
    assert msg.endswith("or more profile shift on the gear")
    paper_pair_from({"pair": {"profile_shift": [1.3, 0.3]}})
