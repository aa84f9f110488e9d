"""Adaptive Dormand-Prince 5(4) with event location (the compiled driver).

Error control on the 10 states: ``err_n = sqrt(mean_r (err_r / (atol_r + rtol max(|z_r|,
|z_new,r|)))^2)``; a step with ``err_n > 1`` is rejected and retried with
``h max(0.2, 0.9 err_n^(-1/5))``, an accepted one proposes ``h min(5, max(0.2,
0.9 err_n^(-1/5)))`` (Hairer, Norsett & Wanner, Solving ODEs I, II.4). One step:
``dynamics.kernel_dp_step``. With time-varying tables every step ends on the next table
node (``dynamics.kernel_tables``). After an accepted step the switching functions are
checked on the dense output and the first crossing is located (``dynamics.kernel_events``);
the step is redone to end there, the mode flips and the integration restarts, so each step
integrates a smooth right-hand side. Guards and status codes: ``dynamics.kernel_state``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .dormand_prince import P as DENSE_P
from .kernel_dp_step import _dense, _dp_energy, _dp_stages, _dp_store, _f_first
from .kernel_events import EV_COLS, _ev_put, _first_rows, _g_arr, _illinois, _modes_tuple
from .kernel_rhs import NG
from .kernel_state import ST_BUDGET, ST_DIVERGED, ST_HMIN, ST_OK, _counters, _tup
from .kernel_tables import _next_node_time, _segment

# the Dormand-Prince 5(4) tableau and Shampine's dense output (dynamics.dormand_prince)
_PD = DENSE_P


@njit(cache=True)
def dopri5(
    z0,
    t_end,
    t_out,
    rtol,
    atol,
    h0,
    hmax,
    hmin,
    max_steps,
    zlim,
    gidx,
    p,
    phi,
    phx,
    kx,
    ex,
    sw_tv,
    sw_bl,
    sw_cl,
    sw_te,
    sw_dyn,
    sw_en,
):
    """Adaptive Dormand-Prince 5(4) from t = 0 with event location.

    The contact modes are frozen during a step (each mode's right-hand side is smooth).
    After a step passes the error test, the switching functions listed in ``gidx`` are
    checked at 4 points of the dense output; at the first sign change the crossing is
    located on the interpolant by the Illinois method to ~1e-13 s, the step is redone
    to end exactly there, the crossed function's mode flips, and integration restarts.
    With time-varying tables, steps also end on the table nodes (kinks of the linear
    interpolant). Guards: at most ``max_steps`` steps (accepted + rejected), a step
    proposed below ``hmin`` stops (status 2), a state beyond ``zlim`` stops (status 3).
    Every event at a time inside the output window [t_out[0], t_out[-1]] is recorded (one
    row of ``EV_COLS``: time, state, the derivative in the old mode (the last stage of the
    step that ends on the event, or the step's first stage for an event of zero length)
    and in the new mode (the restart's first stage)): the state is smooth between
    events, not across them, so exact window integrals must split their pieces there.
    Returns (out, counters [accepted, rejected, events, samples, status, events per
    1000 steps averaged over the last ~1000 steps], z and t at the stop, event rows)."""
    nz = z0.shape[0]
    nerr = 10
    n_out = t_out.shape[0]
    out = np.empty((n_out, nz))
    PD = _PD
    K = np.empty((7, nz))
    z = z0.copy()
    znew = np.empty(nz)
    zt = np.empty(nz)  # scratch for the event root finder
    zd = np.empty(nz)
    # np.empty and element stores throughout: np.zeros, np.full and slice stores each
    # compile their own numpy overloads on a first run
    act = np.empty(NG, dtype=np.bool_)
    g = np.empty(NG)
    gs = np.empty(NG)
    gcur = np.empty(NG)
    gprev = np.empty(NG)
    roots = np.empty(NG)
    for q in range(NG):
        act[q] = False
        g[q] = 0.0
        gs[q] = 0.0
        gcur[q] = 0.0
        gprev[q] = 0.0
        roots[q] = 2.0
    ng = gidx.shape[0]
    t = 0.0
    clip = (sw_tv is not None) or (sw_te is not None)
    hp = h0  # step proposed by the error controller
    tn = _next_node_time(t, p, phi) if clip else 1e300
    si, sm = _segment(0.5 * min(hp, tn), p, phx) if clip else (0, 0)
    if ng > 0:
        _g_arr(t, si, sm, z, gcur, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
        for q in range(ng):
            act[gidx[q]] = gcur[gidx[q]] > 0.0
    modes = _modes_tuple(act)
    k1, w1 = _f_first(t, si, sm, z, p, modes, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
    ko = 0
    n_acc = 0
    n_rej = 0
    n_ev = 0
    ev = np.empty((64, EV_COLS))
    # np.int64, not a literal 0: numba types the first call of _ev_put with Literal[int](0)
    # before the loop unifies the count to int64, and compiled _ev_put and _first_rows twice
    n_rec = np.int64(0)
    t_lo = t_out[0] if n_out > 0 else 0.0
    t_hi = t_out[n_out - 1] if n_out > 0 else -1.0
    n_zero = 0
    ev_rate = 0.0  # moving average of events per step (chatter diagnosis)
    status = ST_OK
    skip_events = False
    while t < t_end:
        if n_acc + n_rej >= max_steps:
            status = ST_BUDGET
            break
        h = min(hp, hmax)
        clipped = False
        last = False
        if t + h >= t_end:
            h = t_end - t
            last = True
            clipped = True
        if clip:
            if tn <= t:
                tn = _next_node_time(t, p, phi)
            if t + h >= tn:
                h = tn - t
                clipped = True
                last = tn >= t_end
        hit_node = clip and (t + h >= tn)
        if clip:
            si, sm = _segment(t + 0.5 * h, p, phx)
        zn, ks, ws, errt = _dp_stages(
            t, h, si, sm, _tup(z), k1, w1, p, modes, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en
        )
        en = 0.0
        for r in range(nerr):
            sc = atol[r] + rtol * max(abs(z[r]), abs(zn[r]))
            en += (errt[r] / sc) ** 2
        en = math.sqrt(en / nerr)
        if not math.isfinite(en):
            en = 1e10
        if en > 1.0:
            n_rej += 1
            hp = h * max(0.2, 0.9 * en**-0.2)
            if hp < hmin:
                status = ST_HMIN
                break
            continue
        # the stage rows feed the dense output (samples, event checks) and the energy
        # quadratures; a step that needs none of them skips the copy
        if sw_en is not None or (ng > 0 and not skip_events) or (ko < n_out and t_out[ko] <= t + h * (1.0 + 1e-12)):
            _dp_store(K, k1, w1, ks, ws, zn, znew, sw_en)
            if sw_en is not None:
                _dp_energy(z, K, h, znew)
        else:
            for r in range(10):
                znew[r] = zn[r]
        # ---- event detection on the dense output ----
        h_used = h
        event = False
        ran = False
        if ng > 0 and not skip_events:
            ran = True
            best = 2.0
            thp = 0.0
            for q in range(ng):
                gprev[gidx[q]] = gcur[gidx[q]]
                roots[gidx[q]] = 2.0
            for sidx in range(1, 5):
                th = 0.25 * sidx
                if sidx == 4:
                    for r in range(nz):
                        zd[r] = znew[r]
                else:
                    _dense(z, K, h, th, PD, zd, nz)
                _g_arr(t + th * h, si, sm, zd, g, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
                for q in range(ng):
                    gi = gidx[q]
                    if (g[gi] > 0.0) != act[gi]:
                        rt = _illinois(
                            t,
                            h,
                            si,
                            sm,
                            z,
                            K,
                            PD,
                            gi,
                            act[gi],
                            thp,
                            gprev[gi],
                            th,
                            g[gi],
                            zt,
                            gs,
                            p,
                            phx,
                            kx,
                            ex,
                            sw_tv,
                            sw_bl,
                            sw_cl,
                            sw_te,
                            sw_dyn,
                        )
                        roots[gi] = rt
                        if rt < best:
                            best = rt
                if best <= 1.0:
                    break
                for q in range(ng):
                    gprev[gidx[q]] = g[gidx[q]]
                thp = th
            if best <= 1.0:
                event = True
                h_ev = best * h
                if h_ev > (1e-15 + 4e-16 * abs(t)):
                    if best < 1.0:
                        zn, ks, ws, errt = _dp_stages(
                            t,
                            h_ev,
                            si,
                            sm,
                            _tup(z),
                            k1,
                            w1,
                            p,
                            modes,
                            phx,
                            kx,
                            ex,
                            sw_tv,
                            sw_bl,
                            sw_cl,
                            sw_te,
                            sw_dyn,
                            sw_en,
                        )
                        _dp_store(K, k1, w1, ks, ws, zn, znew, sw_en)
                        if sw_en is not None:
                            _dp_energy(z, K, h_ev, znew)
                        last = False
                        hit_node = False
                    h_used = h_ev
                    n_zero = 0
                else:
                    h_used = 0.0
                    n_zero += 1
                tolf = 4.0 * (1e-13 + 4e-16 * abs(t)) / h
                for q in range(ng):
                    gi = gidx[q]
                    if roots[gi] <= best + tolf:
                        act[gi] = not act[gi]
                modes = _modes_tuple(act)
                n_ev += 1
        skip_events = False
        ev_rate = 0.999 * ev_rate + (0.001 if event else 0.0)
        if h_used > 0.0:
            while ko < n_out:
                to = t_out[ko]
                if to > t + h_used * (1.0 + 1e-12):
                    break
                th = (to - t) / h_used
                if th < 0.0:
                    th = 0.0
                if th >= 1.0:
                    # an element loop: a slice assignment compiles numba's shape-mismatch
                    # error message (string formatting), 6 s of a first run's compile
                    for r in range(nz):
                        out[ko, r] = znew[r]
                else:
                    _dense(z, K, h_used, th, PD, out[ko], nz)
                ko += 1
            if last:
                t = t_end
            elif hit_node:
                t = tn
            else:
                t = t + h_used
            for r in range(nz):
                z[r] = znew[r]
            n_acc += 1
        if not (math.isfinite(z[4]) and abs(z[4]) < zlim and abs(z[0]) < zlim and abs(z[2]) < zlim):
            status = ST_DIVERGED
            break
        if clip and t >= tn:
            tn = _next_node_time(t, p, phi)
        if event or (hit_node and (sw_en is not None)):
            # restart: the right-hand side changed (mode flip, or a new table segment
            # whose slope enters the energy integrands)
            hn = min(hp, tn - t) if clip else hp
            if clip:
                si, sm = _segment(t + 0.5 * hn, p, phx)
            f_old = ks[5] if h_used > 0.0 else k1
            k1, w1 = _f_first(t, si, sm, z, p, modes, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
            if event and t_lo <= t <= t_hi:
                ev = _ev_put(ev, n_rec, t, z, f_old, k1)
                n_rec += 1
            if ng > 0:
                _g_arr(t, si, sm, z, gcur, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
            if n_zero > 20:
                skip_events = True
                n_zero = 0
        else:
            k1 = ks[5]
            w1 = ws[5]
            if ran:
                for q in range(ng):
                    gcur[gidx[q]] = g[gidx[q]]
            elif ng > 0:
                _g_arr(t, si, sm, z, gcur, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
        if not event:
            fac = 5.0 if en < 1e-10 else min(5.0, max(0.2, 0.9 * en**-0.2))
            if clipped:
                hp = max(hp, h * fac) if fac >= 1.0 else min(hp, h * fac)
            else:
                hp = h * fac
    counters = _counters(n_acc, n_rej, n_ev, ko, status, int(1000.0 * ev_rate))
    return out, counters, z, t, _first_rows(ev, n_rec, n_rec)
