"""Sliding and wear on pairs other than the paper's: the specific sliding from the angular
velocities, and the wear depths from Archard's law and the contact counts, worked by hand
and checked on random valid pairs (hypothesis) and on the named unequal pairs.

Why not the paper pair: with z1 = z2 the specific sliding is the same whether a formula
uses z1/z2 or z2/z1, and pinion and gear teeth meet equally often, so a swapped index is
invisible; every check here has z1 != z2.

Model (geometry/wear.py docstring): at LOA position d the involute curvature radii are
rho1 = d and rho2 = T1T2 - d; the surface speeds along the profiles are v_i = omega_i rho_i
with omega2 = omega1 z1 / z2, and the specific sliding is zeta_i = (v_i - v_j) / v_i.
Archard: one passage of the Hertz band removes h = k |zeta| int p dx = k |zeta| w_bar,
w_bar = (load share) F / b away from the load-sharing steps (equal sharing: 1 pair 1,
2 pairs 1/2, 3 pairs 1/3), F = T / r_b1. Each tooth meets its mate once per revolution of
its own gear: a pinion tooth N1 = n1 t times, a gear tooth N2 = N1 z1 / z2 times.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.profile import INVOLUTE, tooth_profile
from gearwear.geometry.wear import WearSpec, flank_depth, specific_sliding, wear_on_line_of_action

from pairs import NAMED, by_hand_radii, by_hand_working_pressure_angle, valid_pairs


def _hand_line(pair):
    """(T1T2, r_b1, r_b2, d_C) written out: T1T2 = a_w sin(alpha_w), d_C = r_b1 tan(alpha_w)."""
    r = [by_hand_radii(pair, i) for i in (0, 1)]
    aw = by_hand_working_pressure_angle(pair)
    return r[0]["a_w"] * math.sin(aw), r[0]["base"], r[1]["base"], r[0]["base"] * math.tan(aw)


def _hand_sliding(pair, d):
    """(zeta1, zeta2) at LOA positions d from the angular velocities (omega1 = 1)."""
    L = _hand_line(pair)[0]
    z1, z2 = pair.teeth
    omega1, omega2 = 1.0, z1 / z2
    v1, v2 = omega1 * d, omega2 * (L - d)
    return (v1 - v2) / v1, (v2 - v1) / v2


def _path(pair, n=201):
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    return mesh, np.linspace(mesh.path_start_m, mesh.path_end_m, n)


# -- specific sliding, any pair --------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(valid_pairs())
def test_specific_sliding_is_the_velocity_ratio_worked_by_hand(pair):
    """zeta_1 = (v1 - v2) / v1 and zeta_2 = (v2 - v1) / v2 with v_i = omega_i rho_i and
    omega2 = omega1 z1 / z2, along the whole path of contact; hence (1 - zeta1)(1 - zeta2)
    = 1 everywhere, and both vanish at the pitch point d_C = r_b1 tan(alpha') (by hand),
    where the flanks roll without sliding."""
    mesh, d = _path(pair)
    d = d[d > 1e-9 * mesh.line_of_action_m]  # rho1 = 0 at T1: the sliding is unbounded there
    zeta1, zeta2 = specific_sliding(mesh, d)
    h1, h2 = _hand_sliding(pair, d)
    scale = 1.0 + np.abs(h1) + np.abs(h2)
    assert np.all(np.abs(zeta1 - h1) <= 1e-9 * scale)
    assert np.all(np.abs(zeta2 - h2) <= 1e-9 * scale)
    assert np.allclose((1 - zeta1) * (1 - zeta2), 1.0, rtol=1e-9, atol=0)
    dC = _hand_line(pair)[3]
    z1c, z2c = specific_sliding(mesh, np.array([dC]))
    assert abs(z1c[0]) < 1e-9 and abs(z2c[0]) < 1e-9


def _check_archard_by_hand(pair):
    """Archard after t hours at n1 rpm, anywhere farther than the Hertz band from a
    load-sharing step: pinion depth k |zeta1| (s F / b) n1 60 t and gear depth
    k |zeta2| (s F / b) n1 60 t z1 / z2, with the equal load share s = 1 / (number of pairs
    on the path) counted here by hand (pairs one base pitch apart, within [d_A, d_E]: up to
    three above a contact ratio of 2). Zero at the pitch point (pure rolling)."""
    spec = WearSpec(hours=3.0, speed_rpm=900.0, torque_Nm=25.0, archard_k_m2_per_N=1e-16)
    mesh, d = _path(pair, 401)
    A, E, pb = mesh.path_start_m, mesh.path_end_m, mesh.base_pitch_m
    rb1 = by_hand_radii(pair, 0)["base"]
    w = spec.torque_Nm / rb1 / pair.face_width_m
    # away from every A + k p_b and E - k p_b by more than the largest Hertz half-width
    E_star = 1.0 / sum((1 - m.poisson_ratio**2) / m.youngs_modulus_Pa for m in pair.materials)
    a_max = math.sqrt(4 * w * (mesh.line_of_action_m / 4) / (math.pi * E_star))
    steps = np.concatenate([A + pb * np.arange(0, 4), E - pb * np.arange(0, 4)])
    keep = np.min(np.abs(d[:, None] - steps[None, :]), axis=1) > 1.5 * a_max
    d = d[keep]
    pairs_on_path = sum(((d + k * pb >= A) & (d + k * pb <= E)).astype(int) for k in range(-4, 5))
    share = 1.0 / pairs_on_path
    zeta1, zeta2 = _hand_sliding(pair, d)
    N1 = spec.speed_rpm * 60 * spec.hours
    N2 = N1 * pair.teeth[0] / pair.teeth[1]
    h1, h2 = wear_on_line_of_action(mesh, spec, d)
    k = spec.archard_k_m2_per_N
    ref = k * w * N1  # the depth at |zeta| = 1 in single contact
    assert np.allclose(h1, k * np.abs(zeta1) * share * w * N1, rtol=1e-9, atol=1e-12 * ref)
    assert np.allclose(h2, k * np.abs(zeta2) * share * w * N2, rtol=1e-9, atol=1e-12 * ref)
    h1c, h2c = wear_on_line_of_action(mesh, spec, np.array([_hand_line(pair)[3]]))
    assert abs(h1c[0]) < 1e-9 * ref and abs(h2c[0]) < 1e-9 * ref
    return pairs_on_path


@settings(max_examples=40, deadline=None)
@given(valid_pairs())
def test_archard_depth_by_hand_for_any_pair(pair):
    """See _check_archard_by_hand: the depth is k |zeta| (F / b) / n_pairs times the
    contacts of each gear's tooth (the gear's z1 / z2 times the pinion's)."""
    _check_archard_by_hand(pair)


@pytest.mark.parametrize("name", list(NAMED))
def test_archard_depth_by_hand_on_the_named_pairs(name):
    """As above on the named pairs; the 29/61 pair (contact ratio 2.06) has stretches with
    three pairs on the path, where equal sharing gives each a third of the load."""
    counts = _check_archard_by_hand(NAMED[name])
    assert counts.max() == (3 if NAMED[name].teeth == (29, 61) else 2)


# -- the named pairs ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(NAMED))
@pytest.mark.parametrize("how", [dict(hours=50.0), dict(phase="severe"), dict(hours=50.0, model="paper_eq1")])
def test_pinion_to_gear_depth_ratio_at_one_contact_point(name, how):
    """Whatever sets the magnitude (hours, a named phase, Archard or paper Eq. 1), both flanks
    at one contact point pass through the same band under the same load, so per contact
    h1c / h2c = |zeta1| / |zeta2|, and the gear's teeth make z1 / z2 as many contacts as
    the pinion's: h1 / h2 = (|zeta1| / |zeta2|) (z2 / z1) (zeta by hand)."""
    pair = NAMED[name]
    mesh, d = _path(pair, 301)
    dC = _hand_line(pair)[3]
    d = d[np.abs(d - dC) > 1e-3 * mesh.base_pitch_m]  # 0 / 0 at the pitch point
    h1, h2 = wear_on_line_of_action(mesh, WearSpec(**how), d)
    zeta1, zeta2 = _hand_sliding(pair, d)
    z1, z2 = pair.teeth
    assert np.all(h1 > 0) and np.all(h2 > 0)
    assert np.allclose(h1 / h2, np.abs(zeta1) / np.abs(zeta2) * z2 / z1, rtol=1e-9, atol=0)


@pytest.mark.parametrize("name", list(NAMED))
def test_flank_depth_maps_each_flank_to_its_own_contact_point(name):
    """On the generated flanks: a pinion point of roll u meets the gear at d = r_b1 u, a gear
    point of roll u at d = T1T2 - r_b2 u (by hand), and carries that contact's depth of its
    own gear; zero at the roll of the pitch point, tan(alpha') on both flanks; growing toward
    the tip and toward the root inside every load zone."""
    pair = NAMED[name]
    spec = WearSpec(hours=20.0)
    L, rb1, rb2, dC = _hand_line(pair)
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    u_c = math.tan(by_hand_working_pressure_angle(pair))
    for i, rb in enumerate((rb1, rb2)):
        prof = tooth_profile(pair.gear(i), extra_roll=[u_c])
        h = flank_depth(prof, i, mesh, spec)
        u_all = np.where(prof.region == INVOLUTE, prof.roll, np.nan)
        d_all = rb * u_all if i == 0 else L - rb * u_all
        # the active flank (beyond it flank_depth tapers the depth to zero over taper_m)
        inv_pts = (d_all >= mesh.path_start_m) & (d_all <= mesh.path_end_m)
        d = d_all[inv_pts]
        expected = wear_on_line_of_action(mesh, spec, d)[i]
        assert np.allclose(h[inv_pts], expected, rtol=1e-9, atol=1e-12 * h.max())
        at_pitch = np.flatnonzero(np.abs(prof.roll - u_c) < 1e-12)
        assert at_pitch.size == 1 and h[at_pitch[0]] < 1e-9 * h.max()
        # within each load zone (between the sharing steps A + k p_b, E - k p_b, by hand, and
        # away from them by the band) the depth grows with the distance from the pitch point
        A, E, pb = mesh.path_start_m, mesh.path_end_m, mesh.base_pitch_m
        steps = np.sort(np.concatenate([A + pb * np.arange(4), E - pb * np.arange(4), [dC]]))
        steps = steps[(steps >= A) & (steps <= E)]
        band = 0.3e-3
        for lo, hi in zip(steps[:-1], steps[1:]):
            sel = (d > lo + band) & (d < hi - band)
            if sel.sum() < 3:
                continue
            order = np.argsort(np.abs(d[sel] - dC))
            assert np.all(np.diff(h[inv_pts][sel][order]) > 0), (i, lo, hi)


@settings(max_examples=25, deadline=None)
@given(pair=valid_pairs(), n1=st.floats(100.0, 6000.0), ratio=st.floats(1.1, 5.0), depth_um=st.floats(1.0, 20.0))
def test_a_scene_wear_spec_carries_the_speed_only_for_running_hours(pair, n1, ratio, depth_um):
    """A depth (or a phase) fixes the magnitude and the profile is the same at any speed, so
    the scene's wear spec is the same object at two speeds (what lets scenes that differ in
    the speed share a stiffness table); running hours count the contacts, so there the spec
    differs and the depth is in proportion to the speed (N1 = n1 t: Archard's depth is linear
    in the passages), on random valid pairs."""
    from gearwear.geometry.wear import max_depths_m
    from gearwear.scene.model import wear_from_dict

    n2 = n1 * ratio
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    a, b = (wear_from_dict({"max_depth_um": depth_um}, 50.0, n, None) for n in (n1, n2))
    assert a == b
    ha, hb = (wear_on_line_of_action(mesh, s, np.linspace(mesh.path_start_m, mesh.path_end_m, 21)) for s in (a, b))
    assert all(np.array_equal(x, y) for x, y in zip(ha, hb))
    a, b = (wear_from_dict({"hours": 1.0}, 50.0, n, None) for n in (n1, n2))
    assert a != b
    for da, db in zip(max_depths_m(mesh, a), max_depths_m(mesh, b)):
        assert db == pytest.approx(ratio * da, rel=1e-12)
