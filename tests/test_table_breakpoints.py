"""The stiffness table's breakpoints are the physics (issue: staircases in sweeps).

The analytic k_h(phi), e(phi) tables carry, on top of their uniform nodes, the angles
where a tooth pair starts or stops carrying load and where a pair enters or leaves the
path of contact. Checked against truths that do not come from the table:

* a breakpoint is where a pair's load changes from zero to positive: the load sharing
  evaluated 1e-9 of a mesh period to either side (not the table); without gaps the
  breakpoints are the path ends A and E of the textbook kinematics;
* the mean and the harmonics of k_h converge to those of the function itself (sampled
  densely, plain average and FFT), and at 360 nodes the breakpoints make the error far
  smaller than the uniform grid alone;
* over a fine clearance sweep the k_h harmonics change smoothly: no step departs from the
  average of its neighbours' steps (the uniform table fails this: it snaps);
* the integrals of a piecewise-linear curve on non-uniform nodes (means, zone means,
  Fourier coefficients) against closed forms.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearwear.analytic.tvms import mesh_stiffness
from gearwear.geometry.curves import curve_mean, fourier_coefficients, harmonic_amplitudes, interval_integral
from gearwear.geometry.flank import FlankSpec, Relief, hpstc_diameters_m
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.wear import WearSpec
from gearwear.jobs.simulate import stiffness_input
from gearwear.scene.model import scene_from_dict

from pairs import ALPHA25, DRIVER_LARGER, HIGH_CONTACT
from pairs import UNEQUAL as UNEQUAL_PAIR
from scenes import paper_pair_from, with_paper

UNEQUAL = {
    "pair": {
        "teeth": [23, 47],
        "module_mm": 3.0,
        "profile_shift": [0.2, -0.1],
        "face_width_mm": 30.0,
        "hub_radius_mm": [12.5, 25.0],
    },
    "operating": {"speed_rpm": 1500, "torque_Nm": 120},
}
# the driver is the larger gear: the same pair the other way round, the same tooth forces
BIG_DRIVER = {
    "pair": {
        "teeth": [47, 23],
        "module_mm": 3.0,
        "profile_shift": [-0.1, 0.2],
        "face_width_mm": 30.0,
        "hub_radius_mm": [25.0, 12.5],
    },
    "operating": {"speed_rpm": 1500, "torque_Nm": 240},
}
PAPER = paper_pair_from({})
PAIRS = {
    "paper": (PAPER, 40.0),
    "23/47": (paper_pair_from(UNEQUAL), 120.0),
    "47/23": (paper_pair_from(BIG_DRIVER), 240.0),
}


def kinematic_angles(pair, centre_distance_m: float) -> tuple[float, float]:
    """(theta_A, theta_E) in one mesh period by hand: the line of action T1T2 = C' sin a'
    (cos a' = (r_b1 + r_b2) / C'), A where the gear's tip circle crosses it,
    d_A = T1T2 - sqrt(r_a2^2 - r_b2^2), E where the pinion's does, d_E = sqrt(r_a1^2 - r_b1^2);
    a pair is at d_A + r_b1 theta + j p_b (theta = 0: a pair at A), so one leaves at E at
    theta_E = ((d_E - d_A) mod p_b) / r_b1, p_b = 2 pi r_b1 / z1."""
    g1, g2 = pair.gear(0), pair.gear(1)
    rb1, rb2 = g1.base_radius_m, g2.base_radius_m
    t1t2 = centre_distance_m * math.sin(math.acos((rb1 + rb2) / centre_distance_m))
    d_A = t1t2 - math.sqrt(g2.tip_radius_m**2 - rb2**2)
    d_E = math.sqrt(g1.tip_radius_m**2 - rb1**2)
    pb = 2 * math.pi * rb1 / pair.teeth[0]
    return 0.0, math.fmod(d_E - d_A, pb) / rb1


def _relief():
    d1, d2 = hpstc_diameters_m(MeshGeometry(PAPER, PAPER.centre_distance_m))
    return FlankSpec(tip_relief=(Relief(15e-6, d1), Relief(15e-6, d2)))


CASES = {
    "paper, 30.5 um clearance": (PAPER, dict(torque_Nm=40.0, clearance_m=30.5e-6)),
    "paper, severe wear": (PAPER, dict(torque_Nm=40.0, wear=WearSpec(phase="severe"))),
    "paper, mild wear, energy method": (PAPER, dict(torque_Nm=40.0, wear=WearSpec(phase="mild"), method="energy")),
    "paper, tip relief": (PAPER, dict(torque_Nm=40.0, flank=_relief())),
    "23/47 shifted, mild wear, 20 um": (
        PAIRS["23/47"][0],
        dict(torque_Nm=120.0, wear=WearSpec(phase="mild"), clearance_m=20e-6),
    ),
    "47/23, the driver has more teeth": (PAIRS["47/23"][0], dict(torque_Nm=240.0, clearance_m=10e-6)),
}


@pytest.mark.parametrize("name", CASES)
def test_breakpoints_are_where_a_pair_starts_or_stops_carrying_load(name):
    pair, kw = CASES[name]
    r = mesh_stiffness(pair, **kw)
    P = r.mesh.mesh_angle_rad
    kin = kinematic_angles(pair, r.mesh.centre_distance_m)
    assert all(np.min(np.abs(r.breakpoints_rad - k)) < 1e-12 * P for k in kin)
    loads = [b for b in r.breakpoints_rad if min(abs(b - k) for k in kin) > 1e-9 * P]
    # every pair starts and stops carrying load in a mesh period (with wear it may lift
    # off and touch again near a path end)
    assert len(loads) >= 2 and len(loads) % 2 == 0
    delta = 1e-9 * P
    for b in loads:
        assert delta < b < P - delta  # one mesh period: the slots keep their pairs
        q = mesh_stiffness(pair, angles_rad=[b - delta, b, b + delta], **kw)
        F = q.pair_load_N
        changed = np.flatnonzero((F[0] > 0) != (F[2] > 0))
        assert changed.size == 1, F
        j = changed[0]
        assert min(F[0, j], F[2, j]) == 0.0 and max(F[0, j], F[2, j]) > 0.0
        assert F[1, j] == 0.0  # the node holds the side without the pair
        # the table's node there is that value
        node = np.argmin(np.abs(r.angle_rad - b))
        assert r.pair_load_N[node, j] == 0.0 and r.k_N_per_m[node] == pytest.approx(q.k_N_per_m[1], rel=1e-12)
        # and the other pairs carry the whole load, T / r_b1
        assert F.sum(axis=1) == pytest.approx(np.full(3, kw["torque_Nm"] / pair.gear(0).base_radius_m), rel=1e-12)


@pytest.mark.parametrize("name", ["paper", "23/47", "47/23"])
def test_without_gaps_the_breakpoints_are_the_path_ends(name):
    """Unworn, nominal flanks, no corner contact: a pair carries load exactly while it is
    on the path [A, E], so the table's breakpoints are theta_A and theta_E by hand and the
    number of loaded pairs jumps there (the table has the one-sided values on both sides)."""
    pair, torque = PAIRS[name]
    r = mesh_stiffness(pair, torque_Nm=torque, corner_contact=False)
    P = r.mesh.mesh_angle_rad
    th_A, th_E = kinematic_angles(pair, pair.centre_distance_m)
    assert r.breakpoints_rad == pytest.approx([th_A, th_E], abs=1e-12 * P)
    eps = r.mesh.contact_ratio
    n0 = math.floor(eps)
    q = mesh_stiffness(
        pair, torque_Nm=torque, corner_contact=False, angles_rad=[th_E - 1e-9 * P, th_E + 1e-9 * P, P - 1e-9 * P]
    )
    assert list(q.pairs_in_contact) == [n0 + 1, n0, n0]
    at = np.argmin(np.abs(r.angle_rad - th_E))
    assert r.pairs_in_contact[at] == n0 + 1 and r.pairs_in_contact[at + 1] == n0
    assert r.angle_rad[at + 1] - r.angle_rad[at] < 1e-6 * P
    assert r.pairs_in_contact[0] == n0 + 1 and r.pairs_in_contact[-1] == n0 and r.angle_rad[-1] > P * (1 - 1e-6)


def _dense(pair, kw, n=2**15):
    """The function itself at n uniform angles: its mean and harmonics (plain average and
    FFT of the samples; no table)."""
    P = 2 * math.pi / pair.teeth[0]
    k = mesh_stiffness(pair, angles_rad=np.arange(n) * (P / n), **kw).k_N_per_m
    c = np.fft.rfft(k) / n
    return float(k.mean()), 2 * np.abs(c[1:11])


@pytest.mark.parametrize("name", ["paper, 30.5 um clearance", "paper, severe wear", "23/47 shifted, mild wear, 20 um"])
def test_mean_and_harmonics_converge_and_the_breakpoints_win(name):
    pair, kw = CASES[name]
    mean_ref, h_ref = _dense(pair, kw)

    def errors(points, breakpoints):
        r = mesh_stiffness(pair, points=points, breakpoints=breakpoints, **kw)
        return (
            abs(r.mean_N_per_m / mean_ref - 1),
            float(np.max(np.abs(r.harmonics_N_per_m(10) - h_ref)) / h_ref.max()),
        )

    m90, h90 = errors(90, True)
    m360, h360 = errors(360, True)
    mu, hu = errors(360, False)
    assert m360 < m90 and h360 < h90
    assert m360 < 1e-4 and h360 < 1e-3
    assert m360 < mu / 10 and h360 < hu / 10, (m360, mu, h360, hu)


def _clearance_sweep(doc, breakpoints=True):
    """Complex k_h harmonics 1-10 (geometry.curves.fourier_coefficients of the tables the
    dynamics get) over 20-40 um bearing clearance in 0.5 um steps."""
    out = []
    for c in np.arange(20.0, 40.01, 0.5):
        sc = scene_from_dict(
            with_paper({**doc, "effects": {"bearing_clearance": {"clearance_um": float(c)}}}, base="paper-clearance")
        )
        st = stiffness_input(sc, breakpoints=breakpoints)
        out.append(fourier_coefficients(st.phi, st.k, 2 * math.pi / sc.pair.teeth[0], 10))
    return np.array(out)


def step_deviation(c: np.ndarray) -> np.ndarray:
    """Per interior step i and harmonic: |s_i - (s_i-1 + s_i+1) / 2| / max(|s_i-1|, |s_i|,
    |s_i+1|), s the steps of the complex coefficient. A smooth curve gives O(step), a jump
    between two nodes almost 1."""
    s = np.diff(c, axis=0)
    scale = np.maximum(np.maximum(np.abs(s[:-2]), np.abs(s[2:])), np.abs(s[1:-1]))
    return np.abs(s[1:-1] - 0.5 * (s[:-2] + s[2:])) / scale


@pytest.mark.parametrize("doc", [{}, UNEQUAL, BIG_DRIVER], ids=["paper", "23/47", "47/23"])
def test_harmonics_vary_continuously_with_clearance(doc):
    worst = step_deviation(_clearance_sweep(doc)).max()
    # measured: 0.3 % (paper), 0.5 % (23/47), 0.2 % (47/23)
    assert worst < 0.02, worst
    if not doc:
        # the uniform table snaps: a step where a contact edge crosses a node departs from its
        # neighbours by ~100 % (the test can see a staircase)
        assert step_deviation(_clearance_sweep(doc, breakpoints=False)).max() > 0.5


# -- integrals of a periodic piecewise-linear curve on non-uniform nodes ---------------------


def _triangle(L=0.3, n=37, seed=3):
    """v = |x - L / 2| on random non-uniform nodes in [0, L) that include 0 and L / 2 (its
    kinks): the interpolant is v itself."""
    x = np.sort(np.r_[0.0, 0.5 * L, np.random.default_rng(seed).uniform(0, L, n)])
    return x, np.abs(x - 0.5 * L), L


def test_mean_and_fourier_coefficients_of_a_triangle_wave():
    """|x - L/2| = L/4 + sum over odd q of 2 L / (pi q)^2 cos(2 pi q x / L)."""
    x, v, L = _triangle()
    assert curve_mean(x, v, L) == pytest.approx(L / 4, rel=1e-13)
    q = np.arange(1, 11)
    expect = np.where(q % 2 == 1, 2 * L / (math.pi * q) ** 2, 0.0)
    assert harmonic_amplitudes(x, v, L, 10) == pytest.approx(expect, abs=1e-14 * L)
    c = fourier_coefficients(x, v, L, 3)
    assert c[0].real == pytest.approx(L / math.pi**2, rel=1e-12) and abs(c[0].imag) < 1e-14 * L
    # a plain average of the node values misweights the clustered region
    assert abs(np.mean(v) - L / 4) > 1e-3 * L


def test_interval_integrals_of_a_triangle_wave():
    x, v, L = _triangle()

    def F(t):  # integral of |s - L/2| from 0 to t in [0, L]
        return np.where(t <= L / 2, L / 2 * t - t * t / 2, L * L / 4 - (L / 2 * (L - t) - (L - t) ** 2 / 2))

    for a, b in ((0.0, 0.5 * L), (0.1 * L, 0.73 * L), (0.6 * L, L), (0.9 * L, 1.2 * L)):
        exact = float(F(min(b, L)) - F(a)) + (float(F(b - L)) if b > L else 0.0)
        assert interval_integral(x, v, L, a, b) == pytest.approx(exact, rel=1e-12)


def test_the_dynamics_mean_of_a_breakpoint_table_is_the_curves():
    """dynamics.model.table_mean (its own segment integral) and the curve's mean agree on a
    non-uniform table, and the table holds the nodes the load sharing put there."""
    from gearwear.dynamics.model import table_mean

    r = mesh_stiffness(PAPER, clearance_m=30.5e-6)
    P = r.mesh.mesh_angle_rad
    assert np.ptp(np.diff(r.angle_rad)) > 0.5 * P / 360  # not uniform
    assert np.all(np.diff(r.angle_rad) > 1e-12 * P) and r.angle_rad[-1] < P
    assert table_mean(r.angle_rad, r.k_N_per_m, P) == pytest.approx(r.mean_N_per_m, rel=1e-13)


def test_the_table_length_is_a_scene_key():
    from gearwear.core.validation import InputError

    sc = scene_from_dict(with_paper({"effects": {"mesh_stiffness": {"points_per_mesh_period": 90}}}))
    st = stiffness_input(sc)
    P = 2 * math.pi / 30
    uniform = np.arange(90) * (P / 90)
    assert len(st.phi) > 90 and np.all(np.min(np.abs(st.phi[None, :] - uniform[:, None]), axis=1) < 1e-15)
    assert np.all(np.diff(st.phi) > 0) and st.phi[-1] < P
    with pytest.raises(InputError, match=r"^effects\.mesh_stiffness\.points_per_mesh_period = 90: only used with"):
        scene_from_dict(with_paper({"effects": {"mesh_stiffness": {"source": "fem", "points_per_mesh_period": 90}}}))


# -- the edge search: a root resolved only to an ulp must not stall it -------------------
#
# f = Delta_k - g_k is the difference of two approaches of ~1e-5 m, so near its root it is
# noise of an ulp of them (~1e-21 m) or exactly 0. Bisection then narrowed the bracket to
# the tolerance for ~20 more load sharings (the paper pair with severe wear: 26 instead of
# 6, a worn table 2.6x dearer). Checked on functions of that kind whose roots are known,
# against scipy's brentq on smooth ones, and by the count of load sharings on real tables.


def _cancelling(roots: np.ndarray, slope: float, offset: float = 1e-5):
    """f_i(x) = (offset + slope (x - r_i)) - offset: linear, computed as the difference of
    two nearly equal numbers like Delta_k - g_k (exactly 0 or an ulp of ``offset`` near r_i)."""
    return lambda x, i: (offset + slope * (x - roots[i])) - offset


@pytest.mark.parametrize("slope", [1e-3, -1e-3, 3e-6, -2e-5])
def test_edge_search_ends_at_a_root_known_only_to_an_ulp(slope):
    from gearwear.analytic.tvms_nodes import bracket_roots

    rng = np.random.default_rng(5)
    r = rng.uniform(0.1, 0.2, 64)
    a, b = r - rng.uniform(1e-6, 5e-3, 64), r + rng.uniform(1e-6, 5e-3, 64)
    tol = 1e-14 * 0.21
    root, calls = bracket_roots(_cancelling(r, slope), a, b, tol)
    resolution = 4 * np.spacing(1e-5) / abs(slope)  # where f is noise
    assert np.all(np.abs(root - r) <= tol + resolution)
    assert np.all(_cancelling(r, slope)(root, np.arange(r.size)) <= 0.0)  # the unloaded side
    assert calls <= 12, calls  # superlinear to the noise, then one step of tol / 2


@pytest.mark.parametrize(
    "fun",
    [
        lambda x: x**3 - 2.0,
        lambda x: np.exp(-x) - x,
        lambda x: np.tan(x) - 1.0,
        lambda x: 1e-9 * (x - 0.3) * (1.0 + x * x),
    ],
)
def test_edge_search_agrees_with_brentq_on_smooth_functions(fun):
    from scipy.optimize import brentq

    from gearwear.analytic.tvms_nodes import bracket_roots

    a = np.array([0.0, 0.1, 0.2, -0.5])
    b = np.array([1.5, 1.4, 1.3, 1.2])
    ok = np.sign(fun(a)) != np.sign(fun(b))
    a, b = a[ok], b[ok]
    tol = 1e-13
    root, _ = bracket_roots(lambda x, i: fun(x), a, b, tol)
    for ai, bi, ri in zip(a, b, root):
        assert abs(ri - brentq(fun, ai, bi, xtol=1e-16, rtol=4 * np.finfo(float).eps, maxiter=500)) <= tol + 1e-15


WORN_EDGES = {
    **CASES,
    # where the search stalled before those rules (load sharings then: 25, 34, 23, 35, 34)
    "paper, 31.5 um wear, 12 N m": (PAPER, dict(torque_Nm=12.0, wear=WearSpec(max_depth_m=3.153571428571429e-05))),
    "23/47, 6.1 um wear": (UNEQUAL_PAIR, dict(torque_Nm=18.4, wear=WearSpec(max_depth_m=6.142857142857144e-06))),
    "47/23, 31.5 um wear": (DRIVER_LARGER, dict(torque_Nm=37.6, wear=WearSpec(max_depth_m=3.153571428571429e-05))),
    "29/61, contact ratio > 2, 9.0 um wear": (
        HIGH_CONTACT,
        dict(torque_Nm=15.466666666666669, wear=WearSpec(max_depth_m=8.964285714285716e-06)),
    ),
    "17/31 at 25 deg, 11.8 um wear": (
        ALPHA25,
        dict(torque_Nm=18.133333333333333, wear=WearSpec(max_depth_m=1.1785714285714287e-05)),
    ),
}


@pytest.mark.parametrize("name", WORN_EDGES)
def test_the_edge_search_costs_a_few_load_sharings(name, monkeypatch):
    import gearwear.analytic.tvms_nodes as tn

    calls = []
    solve = tn._solve

    def counted(s, x, period, without=None):
        if without is not None:  # an evaluation of f by the edge search
            calls.append(np.size(x))
        return solve(s, x, period, without)

    monkeypatch.setattr(tn, "_solve", counted)
    pair, kw = WORN_EDGES[name]
    mesh_stiffness(pair, **kw)
    assert len(calls) <= 18, len(calls)
