"""Classical fixed-step RK4 (compiled) on the precomputed table schedule.

    k1 = f(t, z),  k2 = f(t + h/2, z + h/2 k1),  k3 = f(t + h/2, z + h/2 k2),  k4 = f(t + h, z + h k3)
    z(t + h) = z + h/6 (k1 + 2 k2 + 2 k3 + k4)

Steps ``h = T_m / N`` from t = 0 (T_m the mesh period in s, N ``steps_per_mesh_period``):
the step grid repeats every table period (``table_periods`` mesh periods), so
``dynamics.table_time.rk4_schedule`` builds one table period's grid once, before
integrating: steps whose table breaks would show are split into sub-steps ending on them
(RK4 across a kink of the interpolant is Simpson's rule on a slope jump; the policy and
the stated error of the breaks left inside steps: ``table_time.split_nodes``,
``kink_defect``), and k, e are sampled exactly at each sub-step's three stage times. The
loop reads them by index (no interpolation in the hot loop). The contact modes follow the
stage states (a piecewise right-hand side, first order across contact events; ``dopri5``
locates them). Samples between sub-step ends: cubic Hermite with the exact derivative at
both ends.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .kernel_rhs import _rhs
from .kernel_state import INNER, ST_DIVERGED, ST_OK, _counters, _lc1, _lc4, _put, _tup
from .params import P_KC


@njit(**INNER)
def _bounded(z, zlim):
    return abs(z[4]) < zlim and abs(z[0]) < zlim and abs(z[2]) < zlim


@njit(**INNER)
def _hermite10(z0, f0, z1, f1, th, h, dst):
    t2 = th * th
    t3 = t2 * th
    h00 = 2 * t3 - 3 * t2 + 1
    h10 = (t3 - 2 * t2 + th) * h
    h01 = -2 * t3 + 3 * t2
    h11 = (t3 - t2) * h
    for i in range(10):
        dst[i] = h00 * z0[i] + h10 * f0[i] + h01 * z1[i] + h11 * f1[i]


@njit(cache=True)
def rk4(z0, h, n_steps, t_out, zlim, p, hs, toff, kq, eq, dkq, deq, ends, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """Classical RK4 on the fixed grid h = T_m / N from t = 0, split at significant table kinks.

    (hs, toff, kq, eq, dkq, deq, ends) is one table period's schedule
    (``model.rk4_schedule``; ``table_periods`` mesh periods, one for a healthy pair):
    sub-step lengths, their end times within the table period, k and
    e at each sub-step's three stage times, their slopes, and which sub-steps end on a
    step boundary. The schedule repeats every period, so every stage reads the exact
    table value. Samples at the sorted times ``t_out``: the sub-step state where a
    sample falls on a sub-step end (step boundaries and table nodes), else cubic
    Hermite inside the sub-step.
    Returns (out (n_out, 10 or 14), counters [steps, sub-steps, 0, samples, status, 0], z_end)."""
    nz = z0.shape[0]
    n_out = t_out.shape[0]
    out = np.empty((n_out, nz))
    p_kc = p[P_KC]
    z = _tup(z0)
    W = (0.0, 0.0, 0.0, 0.0)
    if sw_en is not None:
        W = (z0[10], z0[11], z0[12], z0[13])
    Q = hs.shape[0]
    T = toff[Q - 1]
    tol = 1e-9 * h
    ko = 0
    q = 0
    status = ST_OK
    n_done = 0
    n_sub = 0
    n_per = 0
    t_prev = 0.0
    fa = np.empty(10)
    fb = np.empty(10)
    za = np.empty(10)
    zc = np.empty(10)
    while ko < n_out and t_out[ko] <= tol:
        _put(out[ko], z, W, sw_en)
        ko += 1
    while n_done < n_steps:
        hq = hs[q]
        ka = p_kc
        km = p_kc
        kc = p_kc
        ea = 0.0
        em = 0.0
        ec = 0.0
        dk = 0.0
        de = 0.0
        if sw_tv is not None:
            ka = kq[3 * q]
            km = kq[3 * q + 1]
            kc = kq[3 * q + 2]
            dk = dkq[q]
        if sw_te is not None:
            ea = eq[3 * q]
            em = eq[3 * q + 1]
            ec = eq[3 * q + 2]
            de = deq[q]
        d1, F1, w1 = _rhs(z, ka, ea, dk, de, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
        d2, F2, w2 = _rhs(_lc1(z, hq, 0.5, d1), km, em, dk, de, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
        d3, F3, w3 = _rhs(_lc1(z, hq, 0.5, d2), km, em, dk, de, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
        d4, F4, w4 = _rhs(_lc1(z, hq, 1.0, d3), kc, ec, dk, de, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
        h6 = hq / 6.0
        z1 = _lc4(z, hq, 1 / 6, d1, 1 / 3, d2, 1 / 3, d3, 1 / 6, d4)
        if sw_en is not None:
            W = (
                W[0] + h6 * (w1[0] + 2.0 * (w2[0] + w3[0]) + w4[0]),
                W[1] + h6 * (w1[1] + 2.0 * (w2[1] + w3[1]) + w4[1]),
                W[2] + h6 * (w1[2] + 2.0 * (w2[2] + w3[2]) + w4[2]),
                W[3] + h6 * (w1[3] + 2.0 * (w2[3] + w3[3]) + w4[3]),
            )
        n_sub += 1
        t1 = n_per * T + toff[q]
        tol_t = tol + 8.9e-16 * t1  # 4 ulp of t: the grids are computed differently
        have_fb = False
        while ko < n_out and t_out[ko] <= t1 + tol_t:
            if t_out[ko] >= t1 - tol_t:
                _put(out[ko], z1, W, sw_en)
            else:
                # inside a sub-step (the output grid is not on the sub-step grid, or table
                # nodes the schedule left inside it): cubic Hermite with the exact f at
                # both ends, the end's f once per sub-step
                if not have_fb:
                    fB, _, _ = _rhs(z1, kc, ec, 0.0, 0.0, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
                    for i in range(10):
                        za[i] = z[i]
                        fa[i] = d1[i]
                        zc[i] = z1[i]
                        fb[i] = fB[i]
                    have_fb = True
                _hermite10(za, fa, zc, fb, max((t_out[ko] - t_prev) / hq, 0.0), hq, out[ko])
                if sw_en is not None:
                    for i in range(4):
                        out[ko, 10 + i] = W[i]
            ko += 1
        z = z1
        t_prev = t1
        if ends[q] != 0:
            n_done += 1
            if not _bounded(z, zlim):
                status = ST_DIVERGED
                break
        q += 1
        if q == Q:
            q = 0
            n_per += 1
    zend = np.empty(nz)
    _put(zend, z, W, sw_en)
    counters = _counters(n_done, n_sub, 0, ko, status, 0)
    return out, counters, zend
