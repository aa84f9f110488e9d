"""The atlas's feasibility checks (geometry.design_space) against kinematics worked by hand on
non-paper pairs, a second implementation (the generated tooth outline, MeshGeometry,
check_pair) and hypothesis over valid pairs; and the Sobol design space's bookkeeping
(gearwear.jobs.atlas_space): every design feasible, every reject rejected for its reason,
counts that add up, the same designs for the same seed."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings

from gearwear.core.validation import InputError
from gearwear.geometry.design_space import (
    REASONS,
    contact_ratio,
    interference_margins_m,
    rejection,
    tip_thickness_m,
)
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.profile import INVOLUTE, tooth_profile
from gearwear.geometry.spec import PairSpec, check_pair, inv, pointed_tip_radius_m
from tests.pairs import ALPHA25, DRIVER_LARGER, HIGH_CONTACT, UNEQUAL, by_hand_radii, valid_pairs

PAIRS = {"unequal_23_47": UNEQUAL, "driver_larger_47_23": DRIVER_LARGER, "alpha25": ALPHA25, "hcr": HIGH_CONTACT}


def _hand_tip_thickness(pair: PairSpec, i: int) -> float:
    """s_a = 2 r_a (s / (2 r) + inv(alpha) - inv(alpha_a)), s = m (pi / 2 + 2 x tan alpha), every
    radius from tests.pairs.by_hand_radii (ISO 21771 written out)."""
    r = by_hand_radii(pair, i)
    a = pair.pressure_angle_rad
    s = pair.module_m * (0.5 * math.pi + 2 * pair.profile_shift[i] * math.tan(a))
    alpha_a = math.acos(r["base"] / r["tip"])
    return 2 * r["tip"] * (s / (2 * r["pitch"]) + inv(a) - inv(alpha_a))


@pytest.mark.parametrize("name", PAIRS)
def test_tip_thickness_by_hand_and_from_the_generated_outline(name):
    pair = PAIRS[name]
    for i in (0, 1):
        g = pair.gear(i)
        assert tip_thickness_m(g) == pytest.approx(_hand_tip_thickness(pair, i), rel=1e-12)
        # second route: the rack-generated profile's last involute point, at the tip circle
        prof = tooth_profile(g)
        last = np.flatnonzero(prof.region == INVOLUTE)[-1]
        assert prof.radius[last] == pytest.approx(g.tip_radius_m, rel=1e-9)
        assert tip_thickness_m(g) == pytest.approx(2 * g.tip_radius_m * prof.half_angle[last], rel=1e-7)


def test_tip_thickness_is_zero_at_the_pointed_tip_radius():
    for pair in (UNEQUAL, ALPHA25):
        g = pair.gear(0)
        sharp = replace(g, tip_diameter_m=2 * pointed_tip_radius_m(g))
        assert abs(tip_thickness_m(sharp)) < 1e-9 * g.module_m
        inside = replace(g, tip_diameter_m=1.9 * g.base_radius_m)
        assert tip_thickness_m(inside) == -math.inf


@pytest.mark.parametrize("name", PAIRS)
def test_contact_ratio_by_hand_and_from_mesh_geometry(name):
    """epsilon = (sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a_w sin alpha_w) / (pi m cos alpha)."""
    pair = PAIRS[name]
    r1, r2 = by_hand_radii(pair, 0), by_hand_radii(pair, 1)
    a_w = r1["a_w"]
    alpha_w = math.acos((r1["base"] + r2["base"]) / a_w)
    path = math.sqrt(r1["tip"] ** 2 - r1["base"] ** 2) + math.sqrt(r2["tip"] ** 2 - r2["base"] ** 2)
    hand = (path - a_w * math.sin(alpha_w)) / (math.pi * pair.module_m * math.cos(pair.pressure_angle_rad))
    assert contact_ratio(pair) == pytest.approx(hand, rel=1e-12)
    assert contact_ratio(pair) == pytest.approx(MeshGeometry(pair, pair.centre_distance_m).contact_ratio, rel=1e-12)
    if name == "hcr":
        assert contact_ratio(pair) > 2.0


def _hand_margins(pair: PairSpec) -> tuple[float, float]:
    """Interference margins by hand: the rack's straight flank ends at height
    y_T = -(h_f* - x) m + rho (1 - sin alpha) (rho = rho* m), which generates the involute from
    roll length r sin(alpha) + y_T / sin(alpha) (Litvin ch. 10); contact on the pinion flank starts
    at d_A = T1T2 - sqrt(r_a2^2 - r_b2^2), on the gear flank at T1T2 - d_E from T2."""
    a = pair.pressure_angle_rad
    r = [by_hand_radii(pair, i) for i in (0, 1)]
    rho = pair.rack_tip_radius_coefficient * pair.module_m
    start = []
    for i in (0, 1):
        y_t = -(pair.dedendum_coefficient - pair.profile_shift[i]) * pair.module_m + rho * (1 - math.sin(a))
        start.append(r[i]["pitch"] * math.sin(a) + y_t / math.sin(a))
    a_w = r[0]["a_w"]
    L = a_w * math.sin(math.acos((r[0]["base"] + r[1]["base"]) / a_w))
    d_A = L - math.sqrt(r[1]["tip"] ** 2 - r[1]["base"] ** 2)
    d_E = math.sqrt(r[0]["tip"] ** 2 - r[0]["base"] ** 2)
    return d_A - start[0], (L - d_E) - start[1]


@pytest.mark.parametrize("name", PAIRS)
def test_interference_margins_by_hand(name):
    pair = PAIRS[name]
    got, hand = interference_margins_m(pair), _hand_margins(pair)
    for g, h in zip(got, hand):
        assert g == pytest.approx(h, rel=1e-9, abs=1e-12)
    assert min(got) > 0  # these pairs are accepted by check_pair


@pytest.mark.parametrize("name,flank", [("unequal_23_47", 0), ("driver_larger_47_23", 1)])
def test_a_mate_tip_past_the_form_circle_is_interference(name, flank):
    """The largest mate tip that clears the form circle of flank i, r_a,j = sqrt(r_b,j^2 + (T1T2 -
    r_b,i u_Nf,i)^2), i.e. the mate's reach on the line of action grown by the margin: 1 um below
    it the pair is feasible, 1 um above it the tip cuts the fillet (rejected as interference, and
    check_pair refuses it too). Flank 0: the 47-tooth gear's tip on the 23-tooth pinion; flank 1:
    the 47-tooth driver's tip on the 23-tooth gear."""
    pair = PAIRS[name]
    mate = pair.gear(1 - flank)
    margin = interference_margins_m(pair)[flank]
    reach_now = math.sqrt(mate.tip_radius_m**2 - mate.base_radius_m**2)
    ra_max = math.hypot(mate.base_radius_m, reach_now + margin)

    def tips(ra):
        d = [2 * g.tip_radius_m for g in pair.gears]
        d[1 - flank] = 2 * ra
        return tuple(d)

    clear = replace(pair, tip_diameter_m=tips(ra_max - 1e-6))
    cuts = replace(pair, tip_diameter_m=tips(ra_max + 1e-6))
    assert interference_margins_m(clear)[flank] > 0 > interference_margins_m(cuts)[flank]
    assert rejection(clear) is None
    assert rejection(cuts) == "interference"
    with pytest.raises(InputError, match="interference"):
        check_pair(cuts)


def test_undercut_at_the_hand_limit():
    """No undercut while z >= 2 (h_f* - rho* (1 - sin alpha) - x) / sin^2(alpha): 20 deg, h_f* 1.25,
    rho* 0.38, x 0 gives z_min = 2 (1.25 - 0.38 (1 - 0.34202)) / 0.116978 = 17.1: 17 teeth are
    undercut, 18 are not (a 17/40 pair with x1 = 0.1 is not)."""
    z_min = 2 * (1.25 - 0.38 * (1 - math.sin(math.radians(20)))) / math.sin(math.radians(20)) ** 2
    assert 17 < z_min < 18
    base = dict(module_m=2e-3, hub_radius_m=(8e-3, 20e-3), teeth=(17, 40))
    assert rejection(PairSpec(**base)) == "undercut"
    assert rejection(PairSpec(**{**base, "teeth": (18, 40)})) is None
    x_min = 1.25 - 0.38 * (1 - math.sin(math.radians(20))) - 8.5 * math.sin(math.radians(20)) ** 2
    assert rejection(PairSpec(**{**base, "profile_shift": (x_min + 1e-6, 0.0)})) is None


def test_a_thin_tip_is_rejected_at_the_stated_limit():
    """ALPHA25's pinion (17 teeth, 25 deg) with more and more profile shift: rejected as pointed_tip
    exactly when its tip thickness (by hand) drops below 0.2 m, even where check_pair still accepts
    it (> 0)."""
    seen = set()
    for x1 in np.linspace(0.3, 1.3, 41):
        p = replace(ALPHA25, profile_shift=(float(x1), 0.1))
        try:
            s_a = min(_hand_tip_thickness(p, 0), _hand_tip_thickness(p, 1))
        except ValueError:
            continue
        why = rejection(p)
        if s_a < 0.2 * p.module_m:
            assert why == "pointed_tip", (x1, s_a)
            seen.add("thin")
        elif why is None:
            seen.add("ok")
        if 0 < s_a < 0.2 * p.module_m:
            try:
                check_pair(p)
                seen.add("check_pair accepts a thin tip")
            except InputError:
                pass
    assert {"thin", "ok", "check_pair accepts a thin tip"} <= seen


def test_contact_ratio_below_one_is_rejected():
    """A stub tooth (h_a* 0.5, 25 deg) on 20/20: epsilon by hand < 1, so rejected for it."""
    p = PairSpec(
        teeth=(20, 20),
        module_m=3e-3,
        pressure_angle_rad=math.radians(25),
        addendum_coefficient=0.5,
        dedendum_coefficient=0.75,
        rack_tip_radius_coefficient=0.25,
        hub_radius_m=(10e-3, 10e-3),
    )
    r = by_hand_radii(p, 0)
    eps = (2 * math.sqrt(r["tip"] ** 2 - r["base"] ** 2) - r["a_w"] * math.sin(math.radians(25))) / (
        math.pi * 3e-3 * math.cos(math.radians(25))
    )
    assert eps < 1.0
    assert rejection(p) == "contact_ratio"
    assert rejection(p, min_contact_ratio=0.5) is None


@settings(max_examples=60, deadline=None)
@given(valid_pairs())
def test_any_accepted_pair_passes_exactly_when_its_tip_and_ratio_do(pair):
    """check_pair accepts every valid pair; the atlas's stricter limits reject it exactly for a tip
    thinner than 0.2 m or a contact ratio below 1, and its contact ratio is MeshGeometry's."""
    why = rejection(pair)
    thin = min(tip_thickness_m(g) for g in pair.gears) < 0.2 * pair.module_m
    eps = MeshGeometry(pair, pair.centre_distance_m).contact_ratio
    assert contact_ratio(pair) == pytest.approx(eps, rel=1e-12)
    assert min(interference_margins_m(pair)) >= -1e-12 * pair.centre_distance_m
    expected = "pointed_tip" if thin else ("contact_ratio" if eps < 1 else None)
    assert why == expected


# -- the Sobol design space ---------------------------------------------------------------------


@pytest.mark.filterwarnings("ignore:The balance properties of Sobol")
def test_design_space_bookkeeping_and_reproducibility():
    from gearwear.jobs.atlas_space import design_space
    from gearwear.jobs.atlas_spec import parse

    values = parse({"designs": 40, "seed": 11, "axes": {"profile_shift": [-0.5, 1.5]}}).values
    a = design_space(values)
    b = design_space(values)
    assert [d.row() for d in a.designs] == [d.row() for d in b.designs]
    assert len(a.designs) == 40 and set(a.rejects) == set(REASONS)
    assert len(a.designs) + sum(a.rejects.values()) == a.drawn
    assert a.rejects["pointed_tip"] > 0  # shifts up to 1.5 sharpen tips
    for d in a.designs:
        check_pair(d.pair)
        assert contact_ratio(d.pair) >= 1.0
        assert min(tip_thickness_m(g) for g in d.pair.gears) >= 0.2 * d.pair.module_m
        z1, z2 = d.pair.teeth
        assert 14 <= z1 <= 100 and 1.0 - 0.5 / z1 <= z2 / z1 <= 5.0 + 0.5 / z1
        assert 14.5 <= math.degrees(d.pair.pressure_angle_rad) <= 25.0
        assert 1.5 - 1e-12 <= d.rim_thickness_module <= 12.0 + 1e-12
        # the load: w = T / (r_b1 b)
        w = d.torque_Nm / (d.pair.gear(0).base_radius_m * d.pair.face_width_m) / 1e3
        assert w == pytest.approx(d.line_load_N_per_mm, rel=1e-12) and 20 <= w <= 1000
        # the rim: bore = r_f - s_R unless that is below the smallest bore
        for g in d.pair.gears:
            s_r = (g.root_radius_m - g.hub_radius_m) / g.module_m
            assert s_r == pytest.approx(d.rim_thickness_module, rel=1e-9) or g.hub_radius_m == pytest.approx(
                0.2 * g.root_radius_m, rel=1e-12
            )
    # the rejects: redraw the sequence and check each one's reason
    from scipy.stats import qmc

    from gearwear.jobs.atlas_space import DIMENSIONS, design_at

    u = qmc.Sobol(DIMENSIONS, scramble=True, seed=11).random(a.drawn)
    kept = {d.index for d in a.designs}
    counts = {r: 0 for r in REASONS}
    for i in range(a.drawn):
        why = rejection(design_at(u[i], i, values).pair)
        assert (why is None) == (i in kept)
        if why is not None:
            counts[why] += 1
    assert counts == a.rejects


def test_design_space_spans_the_axes():
    """500 designs of the default SPEC reach every corner the issue names: 14 and 100 teeth,
    ratios near 1 and 5, 14.5 and 25 deg, contact ratios above 2, rims near 1.5 m, loads near 20
    and 1000 N/mm."""
    from gearwear.jobs.atlas_space import design_space
    from gearwear.jobs.atlas_spec import parse

    ds = design_space(parse({}).values).designs
    z1 = [d.pair.teeth[0] for d in ds]
    ratio = [d.pair.teeth[1] / d.pair.teeth[0] for d in ds]
    alpha = [math.degrees(d.pair.pressure_angle_rad) for d in ds]
    eps = [contact_ratio(d.pair) for d in ds]
    assert len(ds) == 500
    assert min(z1) <= 16 and max(z1) >= 98
    assert min(ratio) < 1.1 and max(ratio) > 4.8
    assert min(alpha) < 15 and max(alpha) > 24.5
    assert sum(e >= 2 for e in eps) >= 25 and min(eps) >= 1
    assert min(d.rim_thickness_module for d in ds) < 1.6
    assert min(d.line_load_N_per_mm for d in ds) < 25 and max(d.line_load_N_per_mm for d in ds) > 900
