"""The tables on the time axis: k(t), e(t), the times of their nodes, the RK4 schedule.

The nominal pinion angle is ``phi = omega_p t`` (rad; omega_p in rad/s); the tables repeat
every table period ``P = table_periods 2 pi / z_p`` (``GearDynamics.table_period_rad``):

    k(t) = k~(u),   dk/dt = omega_p dk~/dphi (u),   u = omega_p t - P floor(omega_p t / P)

with ``k~`` the periodic interpolant (``dynamics.interpolant``; the same for e). The
interpolant's breaks (slope jumps of the linear interpolant, every node of the cubic
spline) are where exact window integrals and the adaptive solver split:
``table_node_times`` gives the times at which phi passes a node (one period's sorted nodes
tiled, no sort), ``rk4_schedule`` the fixed-step RK4 grid of one table period, with k and e
at every stage time, split at the breaks where their error would show (``split_nodes``:
RK4 across a kink is Simpson's rule on a slope jump, second order locally; the error of
the breaks left inside steps is ``kink_defect``). Times in s, k in N/m, e in m.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .interpolant import _eval_coefficients
from .params import P_PER, derived

if TYPE_CHECKING:
    from .model import GearDynamics


def _table_eval(model: GearDynamics, t, which: str):
    """The periodic table interpolant (``model.interpolation``) and its time derivative at t."""
    par, phi, phx, kc, ec = derived(model)
    P = par[P_PER]
    ph = model.omega_p * np.asarray(t, float)
    u = ph - P * np.floor(ph / P)
    val, dv = _eval_coefficients(phx, kc if which == "k" else ec, u)
    return val, dv * model.omega_p


def _breaks(model: GearDynamics, c: np.ndarray, rel: float = 1e-12) -> np.ndarray:
    """Per table node: is it a break of the interpolant (extended coefficients c)? Linear:
    where the slope jumps (collinear nodes are not); cubic spline: every node (its third
    derivative jumps)."""
    if model.interpolation == "cubic":
        return np.ones(c.shape[0] - 1, dtype=bool)
    scale = float(np.max(np.abs(c[:, 1]))) or 1.0
    return np.abs(np.diff(c[:, 1])) > rel * scale


def peano(p: int, theta):
    """Simpson's rule (RK4's quadrature of the explicit time dependence) on [0, h] for an
    integrand whose p-th derivative jumps by 1 at theta h: error (exact - Simpson) / h^(p+1),

        E_p(theta) = (1 - theta)^(p+1) / (p+1)! - (4 (1/2 - theta)_+^p + (1 - theta)^p) / (6 p!)

    p = 1 (a kink of the linear interpolant): -1/72 <= E_1 <= 1/24 (1/24 at mid-step);
    p = 3 (a node of the cubic spline, whose third derivative jumps): |E_3| <= 1/1152.
    Zero at theta = 0 and 1 (a break on a step end costs nothing)."""
    th = np.asarray(theta, float)
    fp = math.factorial(p)
    return (1 - th) ** (p + 1) / (fp * (p + 1)) - (4 * np.clip(0.5 - th, 0.0, None) ** p + (1 - th) ** p) / (6 * fp)


#: a step is split at its breaks when its kink weight (``split_nodes``) exceeds this
SPLIT_WEIGHT = 1e-6
#: a step that holds at most this many breaks is split at them whatever their weight (a
#: table as coarse as the step grid there: exact, for at most 1 + SPLIT_ALWAYS sub-steps)
SPLIT_ALWAYS = 2
#: at most this many breaks are split per step on average over a table period (the steps
#: with the largest weight first): the schedule never holds more than
#: (1 + SPLIT_MAX_PER_STEP) sub-steps per step on average, whatever the table
SPLIT_MAX_PER_STEP = 8


def _jumps(model: GearDynamics, c: np.ndarray) -> tuple[int, np.ndarray]:
    """(p, jump) per table node: the order p of the derivative of the interpolant (in
    phi, rad) that jumps there and the signed jump (linear: slope, unit/rad; cubic: third
    derivative 6 c3, unit/rad^3)."""
    if model.interpolation == "cubic":
        return 3, 6.0 * np.diff(c[:, 3])
    return 1, np.diff(c[:, 1])


def _inner_breaks(model: GearDynamics, N: int, snap: float):
    """The breaks inside the steps of one table period (not within ``snap`` steps of a
    step end): their node index, phase (rad), step index and position theta in the step."""
    par, phi, phx, kc, ec = derived(model)
    dph = par[P_PER] / N
    idx = np.flatnonzero(_breaks(model, kc) | _breaks(model, ec))
    rel = np.asarray(phi, float)[idx] / dph
    inside = np.abs(rel - np.rint(rel)) >= snap
    idx, rel = idx[inside], rel[inside]
    step = np.clip(np.floor(rel).astype(np.int64), 0, N - 1)
    return idx, np.asarray(phi, float)[idx], step, rel - step


def split_nodes(model: GearDynamics, steps_per_period: int, snap: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """The policy: which breaks of the interpolant the RK4 schedule ends sub-steps on.

    The kink weight of a step of dphi = omega_p h rad is the leading-order error that RK4
    makes across the breaks j inside it (``peano``), relative to the step's mesh impulse
    h k_m delta_s (k_m the mean stiffness, N/m; delta_s = |F_s| / k_m + max|e|, m):

        W = dphi^p (|sum_j E_p(theta_j) [k^(p)]_j| / k_m + |sum_j E_p(theta_j) [e^(p)]_j| / delta_s)

    ([k^(p)]_j the jump of d^p k / dphi^p at break j, theta_j its place in the step)

    A step with W > SPLIT_WEIGHT, or with at most SPLIT_ALWAYS breaks (the table as coarse
    as the steps there), is split at its breaks, the others are not (at most
    SPLIT_MAX_PER_STEP N breaks per period: the steps with the largest W first). Sharp
    edges (large, same-signed slope jumps) are split as before; a smooth curve sampled
    finer than the steps is not (its jumps follow the curve's curvature and their Simpson
    errors cancel: the signed sum is of the order of the table's own O(spacing^2)
    interpolation error), so its cost is the step count's. Returns (split, unsplit): the
    phases (rad) in [0, P) of the breaks split and of those left inside steps."""
    par, phi, phx, kc, ec = derived(model)
    N = int(steps_per_period) * model.table_periods
    dph = par[P_PER] / N
    idx, ph, step, theta = _inner_breaks(model, N, snap)
    p, jk = _jumps(model, kc)
    _, je = _jumps(model, ec)
    E = peano(p, theta) * dph**p
    km = max(abs(model.k_mean), 1e-300)
    e_max = float(np.max(np.abs(np.asarray(model.e_table, float)))) if model.te_excitation else 0.0
    ds = abs(model.F_s) / km + e_max
    W = np.zeros(N)
    size = np.zeros(idx.size)
    if model.tvms:
        W += np.abs(np.bincount(step, weights=E * jk[idx], minlength=N)) / km
        size += np.abs(jk[idx]) / km
    if model.te_excitation:
        W += np.abs(np.bincount(step, weights=E * je[idx], minlength=N)) / max(ds, 1e-300)
        size += np.abs(je[idx]) / max(ds, 1e-300)
    # a coarse step (at most SPLIT_ALWAYS breaks) is split whatever its weight: exact, at
    # most 1 + SPLIT_ALWAYS sub-steps
    W[np.bincount(step, minlength=N) <= SPLIT_ALWAYS] = np.inf
    cand = np.flatnonzero(W[step] > SPLIT_WEIGHT)
    # the steps with the largest weight first, within a step the largest jumps; at most
    # SPLIT_MAX_PER_STEP breaks per step on average over the period
    order = cand[np.lexsort((-size[cand], step[cand], -W[step[cand]]))]
    keep = np.zeros(idx.size, dtype=bool)
    keep[order[: SPLIT_MAX_PER_STEP * N]] = True
    return ph[keep], ph[~keep]


def kink_defect(model: GearDynamics, steps_per_period: int, snap: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """The leading-order error of the breaks the schedule leaves inside its sub-steps, per
    sub-step of one table period (``rk4_schedule``'s Q sub-steps): (Sk, Se) with

        Sk_q = sum_j h_q^(p+1) E_p(theta_j) [d^p k / dt^p]_j    (N s / m for p = 1)
        Se_q = sum_j h_q^(p+1) E_p(theta_j) [d^p e / dt^p]_j    (m s for p = 1)

    over the unsplit breaks j in sub-step q (length h_q in s, break at theta_j h_q; the
    jumps in time units, omega_p^p times those in phi). RK4 integrates the explicit time
    dependence of the mesh force F = c_h delta' + k(t) (delta - e(t)) by Simpson's rule
    (stages at 0, h/2, h), so, to leading order in h omega (omega the fastest mode), the
    sub-step differs from the exact flow of the interpolated model as if the mesh force
    lacked the impulse

        I_q = Sk_q (delta - e) - k Se_q,    |I_q| <= |Sk_q| max|delta - e| + max(k) |Se_q|   (N s)

    (q' high by I_q / m_e, y_p' by I_q cos a / m_p, x_p' by I_q sin a / m_p, the gear's
    velocities the opposite), on top of RK4's own O(h^5). Zero for a schedule split at all
    its breaks."""
    par, phi, phx, kc, ec = derived(model)
    N = int(steps_per_period) * model.table_periods
    w = model.omega_p
    split, unsplit = split_nodes(model, steps_per_period, snap)
    pts = np.union1d(np.arange(N + 1) * (par[P_PER] / N), split)
    q = np.clip(np.searchsorted(pts, unsplit, side="right") - 1, 0, pts.size - 2)
    hq = np.diff(pts)
    theta = (unsplit - pts[q]) / hq[q]
    idx = np.searchsorted(phi, unsplit)
    p, jk = _jumps(model, kc)
    _, je = _jumps(model, ec)
    c = peano(p, theta) * (hq[q] / w) ** (p + 1) * w**p
    Q = hq.size
    Sk = np.bincount(q, weights=c * jk[idx], minlength=Q) if model.tvms else np.zeros(Q)
    Se = np.bincount(q, weights=c * je[idx], minlength=Q) if model.te_excitation else np.zeros(Q)
    return Sk, Se


def rk4_schedule(model: GearDynamics, steps_per_period: int, snap: float = 1e-9):
    """The fixed-step RK4 grid of one table period, split at the table's significant breaks.

    Steps are h = T_m / N from t = 0 (``steps_per_period`` = N per *mesh* period), so the
    grid repeats every table period of L = ``table_periods`` mesh periods: the schedule
    holds L N steps (for L = 1 one mesh period, as before). The periodic linear
    interpolant has a kink at every table node (a cubic spline a jump of its third
    derivative); RK4 across a kink is only second-order accurate locally (Simpson's rule
    on a function with a slope jump). A step whose breaks have a large kink weight
    (``split_nodes``: W > SPLIT_WEIGHT, at most SPLIT_MAX_PER_STEP per step on average) is
    split into
    sub-steps that end on them; the other breaks stay inside their steps, and their
    leading-order error is ``kink_defect``. Each stage samples k(t) and e(t), the table's
    interpolant, exactly at its time (start, middle, end of the sub-step), whether or not
    a break lies between them. A node within ``snap`` steps of a step boundary is taken
    as on it (its error is O(snap h^2)). The sub-steps per table period are L N plus the
    split breaks, at most (1 + SPLIT_MAX_PER_STEP) L N: built once from one period of
    nodes (searchsorted; O(L N + n) work for n table rows), never from the run's node times.

    Returns (hs, toff, kq, eq, dkq, deq, ends): sub-step lengths in s (Q,), the time of
    each sub-step's end from the start of the table period (Q,), k and e at the 3Q stage
    times (start, middle, end of each sub-step), dk/dt and de/dt over each sub-step (Q,;
    the energy accumulators: the slope at the middle where no break lies inside, else
    the secant (v(end) - v(start)) / h, the sub-step's exact mean slope) and a 0/1 flag
    per sub-step that ends on a step boundary."""
    par, phi, phx, kc, ec = derived(model)
    P = par[P_PER]
    N = int(steps_per_period) * model.table_periods  # steps per table period
    dph = P / N
    bounds = np.arange(N + 1) * dph
    split, unsplit = split_nodes(model, steps_per_period, snap)
    pts = np.union1d(bounds, split)
    a, b = pts[:-1], pts[1:]
    mid = 0.5 * (a + b)
    hi = phx.size - 2
    # each stage on the segment that holds it: the start from the right, the end from the
    # left (for a sub-step that holds no break all three are its one segment)
    seg_m = np.clip(np.searchsorted(phx, mid, side="right") - 1, 0, hi)
    seg_a = np.clip(np.searchsorted(phx, a, side="right") - 1, 0, hi)
    seg_b = np.clip(np.searchsorted(phx, b, side="left") - 1, 0, hi)
    seg_a = np.minimum(seg_a, seg_m)
    seg_b = np.maximum(seg_b, seg_m)
    w = model.omega_p
    out = [np.diff(pts) / w, b / w]
    inner = (np.searchsorted(unsplit, b, side="left") - np.searchsorted(unsplit, a, side="right")) > 0
    for c in (kc, ec):
        v = []
        for x, sg in ((a, seg_a), (mid, seg_m), (b, seg_b)):
            cs = c[sg]
            d = x - phx[sg]
            v.append(cs[:, 0] + d * (cs[:, 1] + d * (cs[:, 2] + d * cs[:, 3])))
        out.append(np.column_stack(v).ravel())
    for c, vq in zip((kc, ec), out[2:4]):
        cs = c[seg_m]
        dm = mid - phx[seg_m]
        slope = (cs[:, 1] + dm * (2 * cs[:, 2] + 3 * dm * cs[:, 3])) * w
        secant = (vq[2::3] - vq[0::3]) / (np.diff(pts) / w)
        out.append(np.where(inner, secant, slope))
    on_bound = np.abs(b / dph - np.rint(b / dph)) < 1e-12 * N
    out.append(on_bound.astype(np.int64))
    return tuple(out)


def table_node_times(model: GearDynamics, t0: float, t1: float) -> np.ndarray:
    """Times in (t0, t1) at which the pinion angle passes a table node (the breaks of the
    k and e interpolants; the table repeats every table period); empty when neither
    table varies."""
    if not (model.tvms or model.te_excitation):
        return np.empty(0)
    P = model.table_period_rad
    w = model.omega_p
    phi = derived(model)[1]
    # one period's nodes (sorted, in [0, P)) tiled over the periods: sorted without a sort
    m = np.arange(np.floor(w * t0 / P) - 1, np.ceil(w * t1 / P) + 1)
    t = ((phi[None, :] + P * m[:, None]) / w).ravel()
    return t[np.searchsorted(t, t0, side="right") : np.searchsorted(t, t1, side="left")]
