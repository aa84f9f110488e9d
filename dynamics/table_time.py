"""The tables on the time axis: k(t), e(t), the times of their nodes, the RK4 schedule.

The nominal pinion angle is ``phi = omega_p t`` (rad; omega_p in rad/s); the tables repeat
every table period ``P = table_periods 2 pi / z_p`` (``GearDynamics.table_period_rad``):

    k(t) = k~(u),   dk/dt = omega_p dk~/dphi (u),   u = omega_p t - P floor(omega_p t / P)

with ``k~`` the periodic interpolant (``dynamics.interpolant``; the same for e). The
interpolant's breaks (slope jumps of the linear interpolant, every node of the cubic
spline) are where exact window integrals and the solvers split: ``table_node_times`` gives
the times at which phi passes a node, ``rk4_schedule`` the fixed-step RK4 grid of one table
period split at the breaks, with k and e at every stage time (RK4 across a kink is only
second order). Times in s, k in N/m, e in m.
"""

from __future__ import annotations

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


def rk4_schedule(model: GearDynamics, steps_per_period: int, snap: float = 1e-9):
    """The fixed-step RK4 grid of one table period, split at the table's breaks.

    Steps are h = T_m / N from t = 0 (``steps_per_period`` = N per *mesh* period), so the
    grid repeats every table period of L = ``table_periods`` mesh periods: the schedule
    holds L N steps (for L = 1 one mesh period, as before). The
    periodic linear interpolant has a kink at every table node; RK4 across a kink is
    only second-order accurate (Simpson's rule on a function with a slope jump), so a
    step that contains nodes is split into sub-steps that end on them. Each sub-step
    then sees a polynomial k(t) and e(t), sampled exactly at its three stage times
    (start, middle, end), and RK4 keeps its 4th order for any table length and any N.
    A node within ``snap`` steps of a step boundary is taken as on it (its error is
    O(snap h^2)).

    Returns (hs, toff, kq, eq, dkq, deq, ends): sub-step lengths in s (Q,), the time of
    each sub-step's end from the start of the table period (Q,), k and e at the 3Q stage
    times (start, middle, end of each sub-step), dk/dt and de/dt at each sub-step's
    middle (Q,; the energy accumulators) and a 0/1 flag per sub-step that ends on a
    step boundary."""
    par, phi, phx, kc, ec = derived(model)
    P = par[P_PER]
    N = int(steps_per_period) * model.table_periods  # steps per table period
    dph = P / N
    bounds = np.arange(N + 1) * dph
    nodes = np.asarray(phi, float)[_breaks(model, kc) | _breaks(model, ec)]
    rel = nodes / dph
    off = np.abs(rel - np.rint(rel)) < snap
    pts = np.union1d(bounds, nodes[~off])
    a, b = pts[:-1], pts[1:]
    mid = 0.5 * (a + b)
    # each stage on the segment that holds the sub-step (a sub-step never crosses a break)
    seg = np.clip(np.searchsorted(phx, mid, side="right") - 1, 0, phx.size - 2)
    w = model.omega_p
    out = [np.diff(pts) / w, b / w]
    d = np.column_stack([a, mid, b]) - phx[seg][:, None]
    for c in (kc, ec):
        cs = c[seg]
        out.append((cs[:, 0, None] + d * (cs[:, 1, None] + d * (cs[:, 2, None] + d * cs[:, 3, None]))).ravel())
    for c in (kc, ec):
        cs = c[seg]
        dm = d[:, 1]
        out.append((cs[:, 1] + dm * (2 * cs[:, 2] + 3 * dm * cs[:, 3])) * w)
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
    m = np.arange(np.floor(w * t0 / P) - 1, np.ceil(w * t1 / P) + 1)
    t = ((phi[None, :] + P * m[:, None]) / w).ravel()
    return np.sort(t[(t > t0) & (t < t1)])
