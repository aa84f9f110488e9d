"""The tooth-pair slot layout and the contact zones (geometry.kinematics, geometry.curves)
against kinematics worked by hand for the paper pair (z = 30/30, m = 5 mm, alpha = 20
deg, addendum m, no shift, C = 150 mm): the start and end of action on the line of
action, the contact ratio, and the share of double contact epsilon - 1."""

import math

import numpy as np
import pytest

from gearwear.geometry.curves import CurveStats, zone_means
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import default_pair

Z, M, ALPHA, C = 30, 5e-3, math.radians(20.0), 0.150
R_B = 0.5 * M * Z * math.cos(ALPHA)  # base radius, both gears
R_A = 0.5 * M * Z + M  # tip radius
PERIOD = 2 * math.pi / Z  # pinion rotation per mesh period


def hand_path(centre_distance_m):
    """(d_A, d_E, epsilon) from the tip circles crossing the line of action."""
    alpha_w = math.acos(2 * R_B / centre_distance_m)
    t1t2 = centre_distance_m * math.sin(alpha_w)
    g_a = math.sqrt(R_A**2 - R_B**2)  # tip circle to the base tangency point
    d_A, d_E = t1t2 - g_a, g_a
    return d_A, d_E, (d_E - d_A) / (math.pi * M * math.cos(ALPHA))


@pytest.fixture(scope="module")
def mesh():
    pair = default_pair()
    return MeshGeometry(pair, pair.centre_distance_m)


def test_slot_positions_are_entry_plus_roll_plus_pitches(mesh):
    d_A, _, _ = hand_path(C)
    theta = np.array([0.0, 0.3 * PERIOD, 0.9 * PERIOD])
    j, d = mesh.slots(theta)
    assert list(j) == [-1, 0, 1, 2, 3]  # ceil(1.65) + 3 slots: one pitch before A to beyond E
    p_b = math.pi * M * math.cos(ALPHA)
    assert d == pytest.approx(d_A + R_B * theta[:, None] + j[None, :] * p_b, rel=1e-12)
    # one mesh period moves every pair one slot on
    assert mesh.slots(PERIOD)[1][:-1] == pytest.approx(mesh.slots(0.0)[1][1:], rel=1e-12)


@pytest.mark.parametrize("slot", [0, 1, 2])
def test_a_pair_enters_and_leaves_at_the_hand_computed_start_and_end_of_action(mesh, slot):
    """Slot j's pair is on the path from theta = -j T (its roll brings it to d_A) to
    theta = (d_E - d_A) / r_b - j T: start and end of action over the base radius."""
    d_A, d_E, _ = hand_path(C)
    step = PERIOD / 20000
    theta = np.arange(-3 * PERIOD, 3 * PERIOD, step)
    j, d = mesh.slots(theta)
    on = mesh.in_path(d[:, list(j).index(slot)])
    first, last = theta[on][0], theta[on][-1]
    assert first == pytest.approx(-slot * PERIOD, abs=step)
    assert last == pytest.approx((d_E - d_A) / R_B - slot * PERIOD, abs=step)
    # it leaves where the pinion's roll angle reaches the tip's, tan(arccos(r_b / r_a))
    assert d[on, list(j).index(slot)][-1] / R_B == pytest.approx(math.tan(math.acos(R_B / R_A)), abs=step)


@pytest.mark.parametrize("clearance_m", [0.0, 0.1e-3])
def test_double_contact_share_is_epsilon_minus_one(clearance_m):
    pair = default_pair()
    m = MeshGeometry(pair, C + clearance_m)
    _, _, eps = hand_path(C + clearance_m)
    assert 1 < eps < 2
    assert m.contact_ratio == pytest.approx(eps, rel=1e-12)
    assert m.double_contact_share == pytest.approx(eps - 1, rel=1e-12)
    n = 20000
    theta = np.arange(n) * (PERIOD / n)
    on_path = m.in_path(m.slots(theta)[1]).sum(axis=1)
    assert set(np.unique(on_path)) == {1, 2}
    assert np.mean(on_path == 2) == pytest.approx(eps - 1, abs=2.0 / n)
    # the zones: A then C halve the double interval 0 <= theta <= (eps - 1) T; B is the rest
    z = m.contact_zones(theta)
    assert np.array_equal(z["A"] | z["C"], on_path == 2)
    assert np.array_equal(z["B"], on_path == 1)
    assert not np.any(z["A"] & z["C"])
    split = 0.5 * (eps - 1) * PERIOD
    assert theta[z["A"]].max() < split <= theta[z["C"]].min() + PERIOD / n
    assert theta[z["C"]].max() == pytest.approx((eps - 1) * PERIOD, abs=PERIOD / n)


def test_below_unit_contact_ratio_there_is_no_double_zone():
    pair = default_pair()
    m = MeshGeometry(pair, C + 5e-3)
    d_A, d_E, eps = hand_path(C + 5e-3)
    assert eps < 1 and m.double_contact_share == 0.0
    theta = np.linspace(0, PERIOD, 1000, endpoint=False)
    z = m.contact_zones(theta)
    assert not z["A"].any() and not z["C"].any()
    assert np.array_equal(z["B"], R_B * theta <= d_E - d_A + 1e-15)


class _Curve(CurveStats):
    def __init__(self, mesh, angle_rad, k):
        self.mesh, self.angle_rad, self.k_N_per_m = mesh, angle_rad, k


def test_zone_means_and_lengths(mesh):
    """k = 3 on the double zones and 1 on the single zone (a table with nodes on both
    sides of the zone edges, so its piecewise-linear interpolant is that step): the means
    are 3 and 1, the lengths (eps - 1) and (2 - eps) of the 12 deg period."""
    _, _, eps = hand_path(C)
    edge = (eps - 1) * math.pi * M * math.cos(ALPHA) / R_B
    theta = np.union1d(np.arange(360) * (PERIOD / 360), [edge, edge + 1e-12 * PERIOD, PERIOD * (1 - 1e-12)])
    double = R_B * theta <= (eps - 1) * math.pi * M * math.cos(ALPHA) * (1 + 1e-14)
    k = np.where(double, 3.0, 1.0)
    zm = _Curve(mesh, theta, k).zone_means()
    assert zm["double"] == pytest.approx(3.0, rel=1e-9) and zm["single"] == pytest.approx(1.0, rel=1e-9)
    assert zm["double_deg"] == pytest.approx((eps - 1) * 12.0, rel=1e-12)
    assert zm["single_deg"] == pytest.approx((2 - eps) * 12.0, rel=1e-12)
    empty = {"A": np.zeros(3, bool), "B": np.ones(3, bool), "C": np.zeros(3, bool)}
    out = zone_means([1.0, 2.0, 6.0], empty)
    assert math.isnan(out["double"]) and out["single"] == 3.0
