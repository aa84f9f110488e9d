"""Table nodes of ``analytic.tvms``: the uniform grid with the breakpoints of the physics as
exact nodes.

A pair starts carrying load where Delta - g_k changes sign: with gaps (wear, flank
modifications, a corner's separation) that angle moves with the clearance, the wear and
the load. On a fixed grid the curve would snap when such an edge crosses a
node (a staircase in every sweep), so the table holds the breakpoints as exact nodes
(:func:`_table_nodes`): the uniform grid of ``points`` per mesh period, the kinematic
path ends A and E (:func:`kinematic_breaks_rad`), every angle where a pair starts or
stops carrying load (a root of Delta_k - g_k between neighbouring grid nodes where the
loaded set changes, :func:`_edge_roots`) with graded nodes on its loaded side (the
secant stiffness rises there like x^0.11: GRADED_WIDTH), and one-sided limits where a
pair is loaded at A or E (no corner contact). Every node holds the curve evaluated there,
the table is periodic over its span, and the harmonics of the piecewise-linear curve vary
continuously with the parameters (tests/test_table_breakpoints.py; the default grid:
benchmarks/bench_table_points.py).

Units: pinion angles in rad; widths and tolerances are fractions of a mesh period
P = 2 pi / z1 (GRADED_WIDTH, JUMP_OFFSET, ROOT_TOL, MERGE_TOL).
"""

from __future__ import annotations

import math

import numpy as np

from gearwear.geometry.kinematics import MeshGeometry

from .tvms_contact import _Contact, _solve

# -- table nodes: the breakpoints of the physics --------------------------------------

#: where a pair starts to carry load its secant stiffness rises from 0 to most of its
#: value over a vanishing load (energy: a jump to 1 / c; Ishikawa: F / (c F + a F^0.9),
#: which behaves like x^0.11 in the distance x from the breakpoint, so that its
#: piecewise-linear interpolant on a uniform grid converges only like h^1.1). Nodes at
#: x_i = W (i / N)^GRADED_POWER, i = 1 .. N = ceil(W / h), W = GRADED_WIDTH of a mesh
#: period, on the loaded side restore second order for x^p with p > 2 / GRADED_POWER - 1
#: (the standard graded mesh; cells grow from ~W (h / W)^3 to ~3 h)
GRADED_WIDTH, GRADED_POWER = 1.0 / 16, 3.0
#: a jump at a kinematic node (a pair loaded at A or E without corner contact) gets a
#: second node this far (fraction of a mesh period) on its other side: the one-sided limit
JUMP_OFFSET = 1e-9
#: a breakpoint is bracketed to this fraction of a mesh period
ROOT_TOL = 1e-14
#: nodes closer than this fraction of a mesh period are one node (the dynamics steps
#: over nodes within 1e-12 of a period of each other)
MERGE_TOL = 1e-11


def kinematic_breaks_rad(mesh: MeshGeometry) -> np.ndarray:
    """Pinion angles (rad) in [0, 2 pi / z1) where a pair enters or leaves the path of
    contact: at theta = 0 the entering pair is at A (slot 0, MeshGeometry.slots), at
    theta_E one leaves at E (MeshGeometry.exit_angle_rad; the images of A and E one base
    pitch away are the same angles one mesh period later)."""
    th_E = mesh.exit_angle_rad
    P = mesh.mesh_angle_rad
    if MERGE_TOL * P < th_E < P * (1 - MERGE_TOL):
        return np.array([0.0, th_E])
    return np.array([0.0])


def graded_offsets_rad(P: float, h: float) -> np.ndarray:
    """Distances (rad) of the graded nodes from a breakpoint (see GRADED_WIDTH): mesh
    period P, grid step h."""
    W = GRADED_WIDTH * P
    N = max(int(math.ceil(W / h)), 1)
    return W * (np.arange(1, N + 1) / N) ** GRADED_POWER


def _edge_roots(
    s: _Contact, a: np.ndarray, b: np.ndarray, period: np.ndarray, col: np.ndarray, tol: float
) -> np.ndarray:
    """Angles where the pair in slot ``col`` of mesh period ``period`` starts or stops
    carrying load, one per row, bracketed by a and b (loaded at one end only).

    The pair carries load exactly where Delta_k(theta) > g_k(theta), Delta_k the approach
    of the other pairs without it (with it unloaded the load sharing is theirs; the
    complementarity solution is unique), so the breakpoint is the root of the smooth
    f = Delta_k - g_k (the full Delta has a kink there), found by :func:`bracket_roots`
    (one load sharing per iteration for all the brackets). Returns the end of the final
    bracket (width <= tol) on the unloaded side: the table's node there holds the
    one-sided value without that pair."""

    def f(x: np.ndarray, i: np.ndarray) -> np.ndarray:
        _, delta, _, gap, *_ = _solve(s, x, period[i], without=col[i])
        return delta - gap[np.arange(i.size), col[i]]

    return bracket_roots(f, a, b, tol)[0]


def bracket_roots(f, a, b, tol: float) -> tuple[np.ndarray, int]:
    """Roots of f(x, i) (the values at x of the functions of rows i) bracketed by a and b
    (f changes sign between them), all rows at once: (for every row the end of its final
    bracket, of width <= tol, where f <= 0; the number of calls of f).

    Illinois false position (the secant of the bracket's ends, an end kept twice in a row
    has its value halved), bisection if it has not converged in 40 steps. An f that is the
    difference of two nearly equal quantities (here Delta_k - g_k, two approaches of
    ~1e-5 m) resolves its root only to an ulp of them (~1e-21 m): near the root it is noise
    of that size, or exactly 0. Two rules keep that noise from stalling the search, where
    bisection used to narrow the bracket to tol for ~20 more calls (most of a worn table's
    cost): an x where f is exactly 0 is the root (its bracket closes on it), and a step
    never lands closer than tol / 2 to an end (Brent's minimum step), so where the secant
    falls on an end whose f is noise the next step brackets the root to tol."""
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)
    rows = np.arange(a.size)
    fa, fb = f(a, rows), f(b, rows)
    calls = 2
    kept_b = np.zeros(a.size, dtype=bool)  # the last step replaced a, keeping b
    for it in range(200):
        act = np.abs(b - a) > tol
        if not act.any():
            break
        i = rows[act]
        x = 0.5 * (a[i] + b[i])
        lo, hi = np.minimum(a[i], b[i]), np.maximum(a[i], b[i])
        if it < 40:
            secant = (a[i] * fb[i] - b[i] * fa[i]) / np.where(fb[i] != fa[i], fb[i] - fa[i], 1.0)
            on = (secant >= lo) & (secant <= hi)  # NaN is not
            x = np.where(on, np.clip(secant, lo + 0.5 * tol, hi - 0.5 * tol), x)
        fx = f(x, i)
        calls += 1
        zero = fx == 0.0  # the root, to the resolution of f
        if zero.any():
            a[i[zero]], b[i[zero]] = x[zero], x[zero]
            fa[i[zero]], fb[i[zero]] = 0.0, 0.0
        same = (fx > 0) == (fa[i] > 0)
        # Illinois: an end kept twice in a row has its value halved, so it cannot stall
        ia, ib = i[same], i[~same]
        fb[ia[kept_b[ia]]] *= 0.5
        fa[ib[~kept_b[ib]]] *= 0.5
        a[ia], fa[ia] = x[same], fx[same]
        b[ib], fb[ib] = x[~same], fx[~same]
        kept_b[ia], kept_b[ib] = True, False
    return np.where(fa > 0, b, a), calls


def _table_nodes(s: _Contact, points: int) -> tuple[np.ndarray, ...]:
    """Table nodes with the breakpoints of the physics: (angle over the ``periods`` mesh
    periods, ascending in [0, span); the same as an angle in its mesh period and that
    period, the pair (local, period) at which the node is evaluated; the breakpoints).

    The uniform grid of ``points`` per mesh period, plus per period: the kinematic
    breaks (a pair at A or E, :func:`kinematic_breaks_rad`); the angles where a pair
    starts or stops carrying load (Delta = g_k, :func:`_edge_roots`, searched between
    neighbouring nodes where a pair's loaded state changes while it stays a candidate),
    each with a graded cluster on its loaded side; and at a kinematic break where the
    loaded set jumps, the one-sided limit JUMP_OFFSET away."""
    P = s.mesh.mesh_angle_rad
    h = P / points
    kin = kinematic_breaks_rad(s.mesh)
    local = np.union1d(np.arange(points) * h, np.r_[kin, P])  # closed period [0, P]
    n_loc = local.size
    per = np.repeat(np.arange(s.periods), n_loc)
    th = np.tile(local, s.periods)
    F, _, c, *_ = _solve(s, th, per)
    cand = np.isfinite(c)
    on = F > 0
    # neighbours inside one period where a slot's pair changes its loaded state
    i, k = np.nonzero((on[:-1] != on[1:]) & cand[:-1] & cand[1:])
    keep = (i + 1) % n_loc != 0
    i, k = i[keep], k[keep]
    roots = _edge_roots(s, th[i], th[i + 1], per[i], k, ROOT_TOL * P) if i.size else th[:0]
    side = np.where(on[i + 1, k], 1.0, -1.0)  # towards the loaded side
    offsets = graded_offsets_rad(P, h)
    graded = (roots[:, None] + side[:, None] * offsets).ravel()
    # one-sided limits at a kinematic break where the loaded set jumps
    eps = JUMP_OFFSET * P
    kin_th, kin_per = np.tile(kin, s.periods), np.repeat(np.arange(s.periods), kin.size)
    jumps = []
    F0 = _solve(s, kin_th, kin_per)[0]
    for sign in (-1.0, 1.0):
        Fs = _solve(s, kin_th + sign * eps, kin_per)[0]
        jump = np.any((Fs > 0) != (F0 > 0), axis=1)
        jumps.append((kin_th[jump] + sign * eps, kin_per[jump]))
    uni = (np.tile(np.arange(points) * h, s.periods), np.repeat(np.arange(s.periods), points))
    breaks = (np.r_[roots, kin_th], np.r_[per[i], kin_per])
    # priority: breakpoints, one-sided limits, graded clusters, the uniform grid
    groups = [
        breaks,
        (np.concatenate([x for x, _ in jumps]), np.concatenate([n for _, n in jumps])),
        (graded, np.repeat(per[i], offsets.size)),
        uni,
    ]
    local = np.concatenate([g[0] for g in groups])
    period = np.concatenate([g[1] for g in groups])
    prio = np.concatenate([np.full(g[0].size, q) for q, g in enumerate(groups)])
    span = s.periods * P
    ang = np.mod(local + period * P, span)
    keep = merge_nodes(ang, prio, span, MERGE_TOL * P)
    return ang[keep], local[keep], period[keep], np.sort(np.mod(breaks[0] + breaks[1] * P, span))


def merge_nodes(angle: np.ndarray, priority: np.ndarray, span: float, tol: float) -> np.ndarray:
    """Indices of the nodes to keep, in ascending angle: of nodes closer than ``tol`` to
    each other (also across the wrap from ``span`` to 0) only one of the lowest priority
    number is kept."""
    order = np.argsort(angle, kind="stable")
    ang, prio = angle[order], priority[order]
    cluster = np.r_[0, np.cumsum(np.diff(ang) > tol)]
    if ang.size > 1 and ang[0] + span - ang[-1] <= tol:
        cluster[cluster == cluster[-1]] = 0  # the last nodes are the first ones, one span on
    best = np.lexsort((prio, cluster))  # by cluster, then priority
    first = np.r_[True, np.diff(cluster[best]) > 0]
    return order[np.sort(best[first])]
