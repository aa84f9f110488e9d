"""Profile modifications, measured deviations and a spall, through the analytic load
sharing, against kinematics worked out by hand (issue 13).

At a load so small that the elastic approach is ~1e-10 m, the loaded static TE is the
smallest initial separation among the pairs that can touch: the transmission error of
the kinematics alone. For a linear tip relief of amount C_a on both gears from their
highest point of single contact (HPSTC) to the tip, the pair entering at d in [A, B]
(on the gear's relieved tip) has the gap C_a (d_B - d) / (d_B - d_A) and the pair
leaving one base pitch ahead (on the pinion's relieved tip) C_a (d - d_A) / (d_B - d_A):
in every double-contact zone the TE is a triangle of height C_a / 2, and 0 in single
contact. Parabolic: the gaps are squared ratios, the peak is C_a / 4.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearwear.analytic.harris import harris_map
from gearwear.analytic.tvms import mesh_stiffness
from gearwear.core.validation import InputError
from gearwear.geometry.faults import FaultSpec, Spall, spall_gap_m
from gearwear.geometry.flank import Deviation, FlankSpec, Relief, hpstc_diameters_m
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.scene.model import scene_from_dict

from scenes import paper_pair_from, with_paper

PAIR = paper_pair_from({})
MESH = MeshGeometry(PAIR, PAIR.centre_distance_m)
LIGHT_NM = 1e-4  # elastic approach ~1e-10 m: the TE is the kinematics
CA = 20e-6


def _hand_triangle(theta, power=1.0):
    """TE (m) of a relief C_a on both tips from the HPSTC, by hand (module docstring)."""
    A, E, pb = MESH.path_start_m, MESH.path_end_m, MESH.base_pitch_m
    d = A + PAIR.gear(0).base_radius_m * theta
    Ld = E - pb - A  # double-contact length d_B - d_A
    x = (d - A) / Ld
    return np.where(d <= A + Ld, CA * np.minimum(x, 1 - x) ** power, 0.0)


@pytest.mark.parametrize("shape,power", [("linear", 1.0), ("parabolic", 2.0)])
def test_tip_relief_te_at_near_zero_load_is_the_hand_worked_kinematics(shape, power):
    d1, d2 = hpstc_diameters_m(MESH)
    flank = FlankSpec(tip_relief=(Relief(CA, d1, shape), Relief(CA, d2, shape)))
    r = mesh_stiffness(PAIR, points=720, torque_Nm=LIGHT_NM, flank=flank)
    hand = _hand_triangle(r.angle_rad, power)
    peak = CA / 2**power
    assert np.max(hand) == pytest.approx(peak, rel=5e-3)  # the grid passes the apex
    assert np.max(np.abs(r.ste_m - hand)) < 0.02 * peak


def test_root_relief_on_both_gears_equals_the_tip_relief_kinematically():
    """The pinion's root relief from its lowest point of single contact (d_B) down to the
    SAP (d_A) opens the same gaps as the gear's tip relief from its HPSTC (also d_B) to its
    tip (also d_A), and vice versa: both loads and TE agree at any load."""
    dB, dD = MESH.single_contact_limits_m
    lp1, lp2 = 2 * float(MESH.pinion_radius_at(dB)), 2 * float(MESH.gear_radius_at(dD))
    h1, h2 = hpstc_diameters_m(MESH)
    tip = FlankSpec(tip_relief=(Relief(CA, h1), Relief(CA, h2)))
    root = FlankSpec(root_relief=(Relief(CA, lp1), Relief(CA, lp2)))
    for T in (LIGHT_NM, 40.0, 400.0):
        a = mesh_stiffness(PAIR, points=360, torque_Nm=T, flank=tip)
        b = mesh_stiffness(PAIR, points=360, torque_Nm=T, flank=root)
        assert np.max(np.abs(a.ste_m - b.ste_m)) < 1e-12
        assert np.allclose(a.k_N_per_m, b.k_N_per_m, rtol=1e-9)


def test_long_tip_relief_at_the_design_load_halves_the_te_peak_to_peak():
    """Harris: C_a = the single-pair deflection at the design load (the TE of the
    unmodified pair in single contact), from the HPSTC to the tip on both gears."""
    design = 40.0
    nominal = mesh_stiffness(PAIR, points=360, torque_Nm=design)
    ca = float(np.mean(nominal.ste_m[nominal.zone_masks()["B"]]))
    d1, d2 = hpstc_diameters_m(MESH)
    flank = FlankSpec(tip_relief=(Relief(ca, d1), Relief(ca, d2)))
    hm = harris_map(PAIR, flank, [0.5 * design, design, 2 * design])
    assert hm.modified_ste_pp_m[1] <= 0.5 * hm.nominal_ste_pp_m[1]
    # the map's shape: the relief costs TE at light load and the design load is near its minimum
    assert hm.modified_ste_pp_m[0] > hm.modified_ste_pp_m[1] < hm.modified_ste_pp_m[2]


def test_constant_measured_deviation_shifts_the_te_and_leaves_the_stiffness():
    """Material removed uniformly from a flank moves every pair by the same gap: the TE
    rises by exactly that, the loads and the stiffness do not change."""
    c = 7e-6
    dev = Deviation((0.140, 0.162), (c, c))
    base = mesh_stiffness(PAIR, points=180, torque_Nm=40.0)
    moved = mesh_stiffness(PAIR, torque_Nm=40.0, flank=FlankSpec(deviation=(dev, None)), angles_rad=base.angle_rad)
    assert np.max(np.abs(moved.ste_m - base.ste_m - c)) < 1e-13
    assert np.allclose(moved.k_N_per_m, base.k_N_per_m, rtol=1e-10)


def test_measured_deviation_sampling_a_relief_reproduces_it():
    d1, d2 = hpstc_diameters_m(MESH)
    relief = Relief(CA, d1)
    from gearwear.geometry.flank import relief_depth_m

    dia = np.linspace(140e-3, 2 * PAIR.gear(0).tip_radius_m, 400)
    h = relief_depth_m(relief, PAIR, 0, "tip", dia / 2)
    dev = Deviation(tuple(dia), tuple(h))
    a = mesh_stiffness(PAIR, points=360, torque_Nm=LIGHT_NM, flank=FlankSpec(tip_relief=(relief, None)))
    b = mesh_stiffness(PAIR, points=360, torque_Nm=LIGHT_NM, flank=FlankSpec(deviation=(dev, None)))
    assert np.max(np.abs(a.ste_m - b.ste_m)) < 0.01 * CA


def test_spall_gap_is_bridged_by_the_mating_flank():
    """A short deep pit: at its middle the mating flank rests on its edges, the gap is
    (L/2)^2 / (2 R') with R' the relative radius of curvature, not the depth."""
    g = PAIR.gear(0)
    rb = g.base_radius_m
    d0 = MESH.pitch_point_m
    length = 0.5e-3
    u0 = d0 / rb
    s0 = 0.5 * rb * u0**2 - 0.5 * length  # the spall centred on the pitch point
    ua = math.sqrt(2 * s0 / rb)
    spall = Spall(0, 0, 2 * rb * math.hypot(1, ua), length, 30e-6)
    L = MESH.line_of_action_m
    R_rel = d0 * (L - d0) / L
    gap = float(spall_gap_m(spall, MESH, np.array([d0]))[0])
    assert gap == pytest.approx((0.5 * length) ** 2 / (2 * R_rel), rel=1e-9)
    # zero outside and at the edges, never deeper than the pit
    d = np.linspace(MESH.path_start_m, MESH.path_end_m, 2001)
    gd = spall_gap_m(spall, MESH, d)
    assert gd.min() == 0.0 and gd.max() <= 30e-6
    wide = Spall(0, 0, spall.start_diameter_m, 4e-3, 10e-6)
    assert float(spall_gap_m(wide, MESH, np.array([d0 + 1e-3]))[0]) == pytest.approx(10e-6)


def test_spall_in_single_contact_raises_the_te_by_its_bridged_gap_once_per_revolution():
    """Pinion tooth 0 with a short pit at the pitch point (single contact for the paper
    pair): at near-zero load the TE there is the bridged gap, and only on that tooth's
    passage; every other mesh period is the healthy one."""
    g = PAIR.gear(0)
    rb = g.base_radius_m
    step = MESH.base_pitch_m / 240  # LOA travel per curve point: centre the pit on one
    d0 = MESH.path_start_m + round((MESH.pitch_point_m - MESH.path_start_m) / step) * step
    length = 0.5e-3
    ua = math.sqrt(2 * (0.5 * rb * (d0 / rb) ** 2 - 0.5 * length) / rb)
    spall = Spall(0, 0, 2 * rb * math.hypot(1, ua), length, 30e-6)
    # uniform tables (no breakpoint nodes): the same angles in every mesh period
    r = mesh_stiffness(PAIR, points=240, torque_Nm=LIGHT_NM, faults=FaultSpec(spall=spall), breakpoints=False)
    healthy = mesh_stiffness(PAIR, points=240, torque_Nm=LIGHT_NM, breakpoints=False)
    assert r.periods == 30 and r.ste_m.shape == (30 * 240,)
    L = MESH.line_of_action_m
    expect = (0.5 * length) ** 2 / (2 * d0 * (L - d0) / L)
    assert np.max(r.ste_m) == pytest.approx(expect, rel=0.02)
    # tooth 0 meets the path in periods 0 and 1 (contact ratio 1.7); the rest is healthy
    rest = r.ste_m.reshape(30, 240)[2:]
    assert np.max(np.abs(rest - healthy.ste_m[None, :])) < 1e-15


def test_fault_on_the_gear_spans_the_gear_revolution():
    pair = paper_pair_from({"pair": {"teeth": [20, 31]}})
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    rb = pair.gear(1).base_radius_m
    sap = mesh.start_of_active_profile_m[1]
    spall = Spall(1, 5, 2 * sap * 1.01, 1e-3, 20e-6)
    r = mesh_stiffness(pair, points=64, torque_Nm=40.0, faults=FaultSpec(spall=spall), breakpoints=False)
    assert r.periods == 31 and len(r.angle_rad) == 31 * 64
    assert np.all(np.isfinite(r.k_N_per_m)) and rb > 0
    # the faulty pair is the one of gear tooth 5: first in contact 5 mesh periods in
    rows = np.flatnonzero(np.any(r.faulty_pair & r.pair_in_path, axis=1))
    assert rows[0] // 64 == 5


@pytest.mark.parametrize(
    "table,key",
    [
        ({"tip_relief": {"amount_um": 20, "start_diameter_mm": 170}}, "flank.tip_relief.start_diameter_mm"),
        ({"tip_relief": {"amount_um": 20, "start_diameter_mm": 140}}, "flank.tip_relief.start_diameter_mm"),
        ({"tip_relief": {"amount_um": 2000, "start_diameter_mm": 155}}, "flank.tip_relief.amount_um"),
        (
            {
                "tip_relief": {"amount_um": 20, "start_diameter_mm": 155},
                "root_relief": {"amount_um": 20, "start_diameter_mm": 156},
            },
            "flank.root_relief.start_diameter_mm",
        ),
    ],
)
def test_bad_flank_tables_are_refused_in_one_line(table, key):
    with pytest.raises(InputError) as exc:
        scene_from_dict(with_paper({"flank": table}))
    msg = str(exc.value)
    assert msg.startswith(key) and "\n" not in msg and ("mm" in msg or "um" in msg), msg


@pytest.mark.parametrize(
    "spall,key",
    [
        ({"tooth": 30, "start_diameter_mm": 150, "length_mm": 1, "depth_um": 20}, "faults.spall.tooth"),
        ({"start_diameter_mm": 100, "length_mm": 1, "depth_um": 20}, "faults.spall.start_diameter_mm"),
        ({"start_diameter_mm": 158, "length_mm": 5, "depth_um": 20}, "faults.spall.length_mm"),
    ],
)
def test_bad_spalls_are_refused_in_one_line(spall, key):
    with pytest.raises(InputError) as exc:
        scene_from_dict(with_paper({"faults": {"spall": spall}}))
    assert str(exc.value).startswith(key) and "\n" not in str(exc.value)


def test_root_crack_softens_only_its_tooth_pair_and_grows_with_depth():
    """A crack on pinion tooth 0 (Chen & Shao reduced section): the mesh periods in which
    tooth 0 is not in contact are the healthy ones to the last bit, those with it are
    softer, more so for a deeper crack, and a vanishing crack gives the healthy curve."""
    from gearwear.geometry.faults import CrackFault

    # uniform tables (no breakpoint nodes): the same angles in every mesh period
    healthy = mesh_stiffness(PAIR, points=90, torque_Nm=40.0, breakpoints=False)
    k_min = []
    for depth in (1e-6, 0.5e-3, 1e-3, 2e-3):
        r = mesh_stiffness(
            PAIR,
            points=90,
            torque_Nm=40.0,
            breakpoints=False,
            faults=FaultSpec(crack=CrackFault(0, 0, depth, math.radians(45))),
        )
        k = r.k_N_per_m.reshape(30, 90)
        # tooth 0 enters at period 0 and leaves within period 1 (contact ratio 1.65); tip-corner
        # contact reaches into the neighbouring periods 29 (approach) and 2 (exit)
        assert np.array_equal(k[3:29], np.broadcast_to(healthy.k_N_per_m, (26, 90)))
        assert np.all(k[:2] <= healthy.k_N_per_m * (1 + 1e-12))
        k_min.append(float(k[:2].min()))
    assert k_min[0] == pytest.approx(healthy.k_N_per_m.min(), rel=1e-5)
    assert k_min[0] > k_min[1] > k_min[2] > k_min[3]
