"""Switching events of the adaptive integrator: detection, location, record.

The ``NG = 10`` switching functions of ``dynamics.kernel_rhs._gvals`` (flank contacts
``+-s - b``, bearing stops ``+-u_j - b_b``, m) are evaluated on the dense output
(``_g_arr``); a sign change inside a step is located on the interpolant by the Illinois
method (regula falsi that halves the value kept at a bracket end retained twice; Dowell &
Jarratt, BIT 11:168-174, 1971) to a bracket of ~1e-13 s (``_illinois``). The contact modes
are a 6-tuple (drive flank, back flank in {0, 1}; bearings y_p, x_p, y_g, x_g in
{-1, 0, 1}), ``_modes_tuple``. An event inside the output window is recorded by
``_ev_put`` as a row of ``EV_COLS = 31`` values: ``EV_T`` the time (s), from ``EV_Z`` the
10 states, from ``EV_F0`` the 10 derivatives in the old mode and from ``EV_F1`` those in the
new mode (the state is smooth between events, not across them; ``dynamics.analysis.
event_pieces`` splits the window integrals there).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .kernel_dp_step import _dense
from .kernel_rhs import NG, _gvals
from .kernel_state import INNER, _tup
from .kernel_tables import _table_at

# one row per located event in the output window: t, the state, f before (old mode), f after
EV_T, EV_Z, EV_F0, EV_F1, EV_COLS = 0, 1, 11, 21, 31


@njit(**INNER)
def _g_arr(t, i, m, za, g, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn):
    k, e, dk, de = _table_at(t, i, m, p, phx, kx, ex, sw_tv, sw_te)
    gv = _gvals(_tup(za), e, p, sw_bl, sw_cl, sw_dyn)
    for q in range(NG):
        g[q] = gv[q]


@njit(**INNER)
def _bmode(up, down):
    return 1 if up else (-1 if down else 0)


@njit(**INNER)
def _modes_tuple(act):
    return (
        1 if act[0] else 0,
        1 if act[1] else 0,
        _bmode(act[2], act[3]),
        _bmode(act[4], act[5]),
        _bmode(act[6], act[7]),
        _bmode(act[8], act[9]),
    )


@njit(**INNER)
def _illinois(
    t, h, i, m, z, K, PD, gi, act_i, a, fa, bq, fb, zs, gs, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn
):
    """Crossing of switching function gi on the dense output inside [a, bq] (theta units);
    a is on the current side, bq on the other. Returns the new-side end of the final
    bracket (width <= ~1e-13 s)."""
    nz = z.shape[0]
    if act_i and fa <= 0.0:
        fa = 1e-300
    if (not act_i) and fa > 0.0:
        fa = -1e-300
    tol = (1e-13 + 4e-16 * abs(t)) / h
    side = 0
    for _ in range(200):
        if bq - a <= tol:
            break
        c = bq - fb * (bq - a) / (fb - fa)
        if not (c > a and c < bq):
            c = 0.5 * (a + bq)
        _dense(z, K, h, c, PD, zs, nz)
        _g_arr(t + c * h, i, m, zs, gs, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
        gc = gs[gi]
        if (gc > 0.0) == act_i:
            a = c
            fa = gc
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            bq = c
            fb = gc
            if side == 1:
                fa *= 0.5
            side = 1
    return bq


@njit(**INNER)
def _first_rows(ev, n, rows):
    """A new (rows, EV_COLS) buffer holding the first n rows of ev (rows >= n). Element
    loops, not ``new[:n] = ev[:n]``: numba's slice assignment compiles its broadcasting and
    error-message machinery, seconds on a first run."""
    new = np.empty((rows, EV_COLS))
    for a in range(n):
        for c in range(EV_COLS):
            new[a, c] = ev[a, c]
    return new


@njit(**INNER)
def _ev_put(ev, n, t, z, f0, f1):
    """Row n of the event record (grown by doubling when full): time, state, one-sided
    derivatives. Returns the (possibly new) buffer."""
    if n == ev.shape[0]:
        ev = _first_rows(ev, n, 2 * n)
    ev[n, EV_T] = t
    for r in range(10):
        ev[n, EV_Z + r] = z[r]
        ev[n, EV_F0 + r] = f0[r]
        ev[n, EV_F1 + r] = f1[r]
    return ev
