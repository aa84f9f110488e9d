"""Compiled right-hand side and integrators (numba, no Python per step).

Specialisation mechanism
------------------------
Every effect switch is passed to the kernels as an argument that is either ``None``
(effect absent) or ``True`` (effect present): ``sw_tv`` (time-varying stiffness),
``sw_bl`` (backlash / two-flank law), ``sw_cl`` (bearing clearance), ``sw_te``
(transmission-error excitation), ``sw_dyn`` (dynamic centre distance), ``sw_en``
(energy accumulators). Numba compiles one specialisation per argument *type*
signature, so each effect set gets its own machine code; inside it every
``if sw is not None:`` test is on a ``NoneType`` or ``bool`` argument and numba's
dead-branch pruning removes the disabled branches before type inference (absent
effects cost nothing, not even a test). The specialisations are cached on disk
(``cache=True``).

Speed structure
---------------
The right-hand side works on scalars: the state is a 10-tuple, the parameters a
tuple of floats, and the result a tuple. Tuples are values in numba (no reference
counting, no heap). ``_rhs`` is inlined at numba's IR level (``inline="always"``):
left to LLVM it stayed a call that copied the 23-value parameter tuple four times per
step (1.33x a plain C loop; inlined 0.95x, ``benchmarks/bench_rk4_vs_c.py``).

The stiffness contract
----------------------
The solver sees the periodic interpolant of the table (linear by default, or a periodic
cubic spline, ``GearDynamics.interpolation``), at the exact time of every stage:

* RK4 (fixed step ``h = T_m / N`` from t = 0): the step grid repeats every table
  period (``table_periods`` mesh periods; ``p[P_PER]`` is that period in rad, the mesh
  period for a one-period table), so ``model.rk4_schedule`` builds one table period's
  grid (``table_periods * N`` steps) once, before integrating:
  steps that contain table nodes are split into sub-steps ending on them (RK4 across
  a kink of the interpolant drops to second order), and k, e are sampled exactly at
  each sub-step's three stage times. The loop reads them by index (no interpolation
  in the hot loop; any table length, any N; 4th order throughout).
* Dormand-Prince: every step ends on the next table node (the interpolant's kinks
  are at known times), so each step integrates a polynomial right-hand side; inside
  a step the table segment is fixed and evaluated at each stage time. Switching events
  (flank contact, bearing contact) are located and stepped to, and those inside the
  output window are returned with the state and both one-sided derivatives, so that the
  exact window integrals split there too (``analysis.event_pieces``).

State ``z``: y_p, x_p, y_g, x_g, q, then their velocities; with the energy switch four
quadrature states follow: input work int F_s q' dt, dissipated energy, parametric
stiffness work int 1/2 (dk/dt) f^2 dt and excitation work -int k f de/dt dt.

Status codes returned by the integrators: 0 finished, 1 step budget exhausted,
2 step size below the minimum, 3 diverged (non-finite or unbounded state).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .dormand_prince import A2, A3, A4, A5, A6, B, C, E
from .dormand_prince import P as DENSE_P
from .model import (P_B, P_BB, P_C0, P_CA, P_CBG, P_CBP, P_CH, P_DPHI, P_FS, P_INV0, P_KB,
                    P_KC, P_ME, P_MG, P_MP, P_OM, P_PAPER, P_PER, P_PHI0, P_RS, P_SA, P_UNI)

# the Dormand-Prince 5(4) tableau and Shampine's dense output (dynamics.dormand_prince)
_PD = DENSE_P

NG = 10  # switching functions: s-b, -s-b, then +-u_j - b_b for y_p, x_p, y_g, x_g
ST_OK, ST_BUDGET, ST_HMIN, ST_DIVERGED = 0, 1, 2, 3
# one row per located event in the output window: t, the state, f before (old mode), f after
EV_T, EV_Z, EV_F0, EV_F1, EV_COLS = 0, 1, 11, 21, 31


# ------------------------------------------------------------------------------------
# scalar physics (tuples in, tuples out)
# ------------------------------------------------------------------------------------
@njit(cache=True)
def _kin(z, p, sw_dyn):
    """Mesh kinematics: (delta, delta', b, G0..G3, Gb0..Gb3), G = d delta/d(y_p, x_p,
    y_g, x_g) (d delta/dq = 1), Gb = d b/d(...) (dynamic coupling only)."""
    Y = z[0] - z[2]
    if sw_dyn is not None:
        dx = p[P_C0] + z[3] - z[1]
        dy = z[2] - z[0]
        C = math.sqrt(dx * dx + dy * dy)
        ca = p[P_RS] / C
        if ca > 1.0:
            ca = 1.0
        sa = math.sqrt(1.0 - ca * ca)
        b = p[P_B] + p[P_RS] * (sa / ca - math.atan2(sa, ca) - p[P_INV0])
        iC = 1.0 / C
        c0 = -dy * iC
        c1 = -dx * iC
        w = -Y * ca * iC
        G0 = ca + w * c0
        G1 = w * c1
        G2 = -ca - w * c0
        G3 = -w * c1
        Gb0 = sa * c0
        Gb1 = sa * c1
        delta = z[4] + Y * ca
    else:
        sa = p[P_SA]
        ca = p[P_CA]
        b = p[P_B]
        G0 = ca
        G1 = sa
        G2 = -ca
        G3 = -sa
        Gb0 = 0.0
        Gb1 = 0.0
        delta = z[4] + (z[1] - z[3]) * sa + Y * ca
    dd = z[9] + G0 * z[5] + G1 * z[6] + G2 * z[7] + G3 * z[8]
    return delta, dd, b, G0, G1, G2, G3, Gb0, Gb1


@njit(cache=True)
def _dead(u, bb):
    if u > bb:
        return u - bb
    if u < -bb:
        return u + bb
    return 0.0


@njit(cache=True)
def _dead_mode(u, m, bb):
    if m == 1:
        return u - bb
    if m == -1:
        return u + bb
    return 0.0


@njit(cache=True, inline="always")
def _rhs(z, k, e, dk, de, p, modes, sw_bl, sw_cl, sw_dyn, sw_en):
    """Right-hand side of the reduced 5-DOF model (``dynamics.model``).

    z: 10-tuple of states; k, e: mesh stiffness (N/m) and excitation (m) at this time,
    dk, de their time derivatives (energy accumulators only). modes: ``None`` (contact
    states from z: a plain piecewise function, RK4) or a 6-tuple (drive flank, back
    flank, y_p, x_p, y_g, x_g) frozen over an adaptive step (flank flags in {0, 1},
    bearing modes in {-1, 0, 1}). Returns (dz 10-tuple, F_m, energy rates 4-tuple)."""
    delta, dd, b, G0, G1, G2, G3, Gb0, Gb1 = _kin(z, p, sw_dyn)
    s = delta - e
    if sw_bl is not None:
        if modes is None:
            drv = s > b
            bck = s < -b
        else:
            drv = modes[0] == 1
            bck = modes[1] == 1
        fdv = s - b if drv else 0.0
        fbk = s + b if bck else 0.0
        fd = p[P_CH] * dd if (drv or bck or p[P_PAPER] > 0.5) else 0.0
    else:
        fdv = s
        fbk = 0.0
        fd = p[P_CH] * dd
    F = fd + k * (fdv + fbk)
    Q0 = -F * G0
    Q1 = -F * G1
    Q2 = -F * G2
    Q3 = -F * G3
    if sw_dyn is not None:
        kf = k * (fdv - fbk)
        Q0 += kf * Gb0
        Q1 += kf * Gb1
        Q2 -= kf * Gb0
        Q3 -= kf * Gb1
    if sw_cl is not None:
        bb = p[P_BB]
        if modes is None:
            f0 = _dead(z[0], bb)
            f1 = _dead(z[1], bb)
            f2 = _dead(z[2], bb)
            f3 = _dead(z[3], bb)
        else:
            f0 = _dead_mode(z[0], modes[2], bb)
            f1 = _dead_mode(z[1], modes[3], bb)
            f2 = _dead_mode(z[2], modes[4], bb)
            f3 = _dead_mode(z[3], modes[5], bb)
    else:
        f0 = z[0]
        f1 = z[1]
        f2 = z[2]
        f3 = z[3]
    kb = p[P_KB]
    cbp = p[P_CBP]
    cbg = p[P_CBG]
    dz = (z[5], z[6], z[7], z[8], z[9],
          (Q0 - cbp * z[5] - kb * f0) / p[P_MP],
          (Q1 - cbp * z[6] - kb * f1) / p[P_MP],
          (Q2 - cbg * z[7] - kb * f2) / p[P_MG],
          (Q3 - cbg * z[8] - kb * f3) / p[P_MG],
          (p[P_FS] - F) / p[P_ME])
    if sw_en is not None:
        w = (p[P_FS] * z[9],
             cbp * (z[5] * z[5] + z[6] * z[6]) + cbg * (z[7] * z[7] + z[8] * z[8]) + fd * dd,
             0.5 * dk * (fdv * fdv + fbk * fbk),
             -k * (fdv + fbk) * de)
    else:
        w = (0.0, 0.0, 0.0, 0.0)
    return dz, F, w


@njit(cache=True)
def _gvals(z, e, p, sw_bl, sw_cl, sw_dyn):
    """Switching functions (a function is 'active', in contact, when > 0)."""
    g0 = 0.0
    g1 = 0.0
    if sw_bl is not None:
        delta, dd, b, G0, G1, G2, G3, Gb0, Gb1 = _kin(z, p, sw_dyn)
        s = delta - e
        g0 = s - b
        g1 = -s - b
    if sw_cl is not None:
        bb = p[P_BB]
        return (g0, g1, z[0] - bb, -z[0] - bb, z[1] - bb, -z[1] - bb,
                z[2] - bb, -z[2] - bb, z[3] - bb, -z[3] - bb)
    return (g0, g1, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0)


@njit(cache=True)
def _tup(a):
    return (a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], a[9])


@njit(cache=True)
def _put(dst, z, w, sw_en):
    for i in range(10):
        dst[i] = z[i]
    if sw_en is not None:
        for i in range(4):
            dst[10 + i] = w[i]


@njit(cache=True)
def _bounded(z, zlim):
    return abs(z[4]) < zlim and abs(z[0]) < zlim and abs(z[2]) < zlim


@njit(cache=True)
def _hermite10(z0, f0, z1, f1, th, h, dst):
    t2 = th * th
    t3 = t2 * th
    h00 = 2 * t3 - 3 * t2 + 1
    h10 = (t3 - 2 * t2 + th) * h
    h01 = -2 * t3 + 3 * t2
    h11 = (t3 - t2) * h
    for i in range(10):
        dst[i] = h00 * z0[i] + h10 * f0[i] + h01 * z1[i] + h11 * f1[i]


# ------------------------------------------------------------------------------------
# fixed-step RK4
# ------------------------------------------------------------------------------------
@njit(cache=True)
def rk4(z0, h, n_steps, t_out, zlim, p, hs, toff, kq, eq, dkq, deq, ends,
        sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """Classical RK4 on the fixed grid h = T_m / N from t = 0, split at table kinks.

    (hs, toff, kq, eq, dkq, deq, ends) is one table period's schedule
    (``model.rk4_schedule``; ``table_periods`` mesh periods, one for a healthy pair):
    sub-step lengths, their end times within the table period, k and
    e at each sub-step's three stage times, their slopes, and which sub-steps end on a
    step boundary. The schedule repeats every period, so every stage reads the exact
    table value. Samples at the sorted times ``t_out``: the sub-step state where a
    sample falls on a sub-step end (step boundaries and table nodes), else cubic
    Hermite inside the sub-step.
    Returns (out (n_out, 10 or 14), counters [steps, sub-steps, 0, samples, status], z_end)."""
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
            W = (W[0] + h6 * (w1[0] + 2.0 * (w2[0] + w3[0]) + w4[0]),
                 W[1] + h6 * (w1[1] + 2.0 * (w2[1] + w3[1]) + w4[1]),
                 W[2] + h6 * (w1[2] + 2.0 * (w2[2] + w3[2]) + w4[2]),
                 W[3] + h6 * (w1[3] + 2.0 * (w2[3] + w3[3]) + w4[3]))
        n_sub += 1
        t1 = n_per * T + toff[q]
        tol_t = tol + 8.9e-16 * t1     # 4 ulp of t: the grids are computed differently
        while ko < n_out and t_out[ko] <= t1 + tol_t:
            if t_out[ko] >= t1 - tol_t:
                _put(out[ko], z1, W, sw_en)
            else:
                # inside a sub-step (the output grid is not on the sub-step grid): cubic
                # Hermite with the exact f at both ends (k is linear inside a sub-step)
                fB, _, _ = _rhs(z1, kc, ec, 0.0, 0.0, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
                for i in range(10):
                    za[i] = z[i]
                    fa[i] = d1[i]
                    zc[i] = z1[i]
                    fb[i] = fB[i]
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
    counters = np.array([n_done, n_sub, 0, ko, status], dtype=np.int64)
    return out, counters, zend


# Tuple linear combinations z + h sum a_j k_j of 1..6 stage derivatives (Dormand-Prince
# stages): unrolled so that LLVM keeps every stage in registers.
@njit(cache=True)
def _lc1(z, h, a0, k0):
    return (z[0] + h * (a0 * k0[0]),
            z[1] + h * (a0 * k0[1]),
            z[2] + h * (a0 * k0[2]),
            z[3] + h * (a0 * k0[3]),
            z[4] + h * (a0 * k0[4]),
            z[5] + h * (a0 * k0[5]),
            z[6] + h * (a0 * k0[6]),
            z[7] + h * (a0 * k0[7]),
            z[8] + h * (a0 * k0[8]),
            z[9] + h * (a0 * k0[9]))


@njit(cache=True)
def _lc2(z, h, a0, k0, a1, k1):
    return (z[0] + h * (a0 * k0[0] + a1 * k1[0]),
            z[1] + h * (a0 * k0[1] + a1 * k1[1]),
            z[2] + h * (a0 * k0[2] + a1 * k1[2]),
            z[3] + h * (a0 * k0[3] + a1 * k1[3]),
            z[4] + h * (a0 * k0[4] + a1 * k1[4]),
            z[5] + h * (a0 * k0[5] + a1 * k1[5]),
            z[6] + h * (a0 * k0[6] + a1 * k1[6]),
            z[7] + h * (a0 * k0[7] + a1 * k1[7]),
            z[8] + h * (a0 * k0[8] + a1 * k1[8]),
            z[9] + h * (a0 * k0[9] + a1 * k1[9]))


@njit(cache=True)
def _lc3(z, h, a0, k0, a1, k1, a2, k2):
    return (z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0]),
            z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1]),
            z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2]),
            z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3]),
            z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4]),
            z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5]),
            z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6]),
            z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7]),
            z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8]),
            z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9]))


@njit(cache=True)
def _lc4(z, h, a0, k0, a1, k1, a2, k2, a3, k3):
    return (z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0] + a3 * k3[0]),
            z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1] + a3 * k3[1]),
            z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2] + a3 * k3[2]),
            z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3] + a3 * k3[3]),
            z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4] + a3 * k3[4]),
            z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5] + a3 * k3[5]),
            z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6] + a3 * k3[6]),
            z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7] + a3 * k3[7]),
            z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8] + a3 * k3[8]),
            z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9] + a3 * k3[9]))


@njit(cache=True)
def _lc5(z, h, a0, k0, a1, k1, a2, k2, a3, k3, a4, k4):
    return (z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0] + a3 * k3[0] + a4 * k4[0]),
            z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1] + a3 * k3[1] + a4 * k4[1]),
            z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2] + a3 * k3[2] + a4 * k4[2]),
            z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3] + a3 * k3[3] + a4 * k4[3]),
            z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4] + a3 * k3[4] + a4 * k4[4]),
            z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5] + a3 * k3[5] + a4 * k4[5]),
            z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6] + a3 * k3[6] + a4 * k4[6]),
            z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7] + a3 * k3[7] + a4 * k4[7]),
            z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8] + a3 * k3[8] + a4 * k4[8]),
            z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9] + a3 * k3[9] + a4 * k4[9]))


@njit(cache=True)
def _lc6(z, h, a0, k0, a1, k1, a2, k2, a3, k3, a4, k4, a5, k5):
    return (z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0] + a3 * k3[0] + a4 * k4[0] + a5 * k5[0]),
            z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1] + a3 * k3[1] + a4 * k4[1] + a5 * k5[1]),
            z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2] + a3 * k3[2] + a4 * k4[2] + a5 * k5[2]),
            z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3] + a3 * k3[3] + a4 * k4[3] + a5 * k5[3]),
            z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4] + a3 * k3[4] + a4 * k4[4] + a5 * k5[4]),
            z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5] + a3 * k3[5] + a4 * k4[5] + a5 * k5[5]),
            z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6] + a3 * k3[6] + a4 * k4[6] + a5 * k5[6]),
            z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7] + a3 * k3[7] + a4 * k4[7] + a5 * k5[7]),
            z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8] + a3 * k3[8] + a4 * k4[8] + a5 * k5[8]),
            z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9] + a3 * k3[9] + a4 * k4[9] + a5 * k5[9]))


@njit(cache=True)
def _dp_stages(t, h, i, m, z, k1, w1, p, modes, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """Stages 2-7 of Dormand-Prince 5(4) on tuples (k1 = f(t, z) given, FSAL).
    Returns (z_new, (k2..k7), (w2..w7), error estimate tuple h sum E_s k_s)."""
    kt, et, dkt, det = _table_at(t + C[1] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k2, F, w2 = _rhs(_lc1(z, h, A2[0], k1), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    kt, et, dkt, det = _table_at(t + C[2] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k3, F, w3 = _rhs(_lc2(z, h, A3[0], k1, A3[1], k2), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    kt, et, dkt, det = _table_at(t + C[3] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k4, F, w4 = _rhs(_lc3(z, h, A4[0], k1, A4[1], k2, A4[2], k3), kt, et, dkt, det, p, modes,
                     sw_bl, sw_cl, sw_dyn, sw_en)
    kt, et, dkt, det = _table_at(t + C[4] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k5, F, w5 = _rhs(_lc4(z, h, A5[0], k1, A5[1], k2, A5[2], k3, A5[3], k4),
                     kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    kt, et, dkt, det = _table_at(t + h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k6, F, w6 = _rhs(_lc5(z, h, A6[0], k1, A6[1], k2, A6[2], k3, A6[3], k4, A6[4], k5), kt, et, dkt, det, p, modes,
                     sw_bl, sw_cl, sw_dyn, sw_en)
    zn = _lc5(z, h, B[0], k1, B[2], k3, B[3], k4, B[4], k5, B[5], k6)
    k7, F, w7 = _rhs(zn, kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    err = _lc6(zero, h, E[0], k1, E[2], k3, E[3], k4, E[4], k5, E[5], k6, E[6], k7)
    return zn, (k2, k3, k4, k5, k6, k7), (w2, w3, w4, w5, w6, w7), err


@njit(cache=True)
def _f_first(t, i, m, z, p, modes, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """f(t, z) and the energy rates at a (re)start of the adaptive integration."""
    kt, et, dkt, det = _table_at(t, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k1, F1, w1 = _rhs(_tup(z), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    return k1, w1


@njit(cache=True)
def _dp_store(K, k1, w1, ks, ws, zn, znew, sw_en):
    """Stage derivatives into K (dense output, event location), z_new into znew[:10]."""
    _put(K[0], k1, w1, sw_en)
    for s in range(6):
        _put(K[s + 1], ks[s], ws[s], sw_en)
    for r in range(10):
        znew[r] = zn[r]


@njit(cache=True)
def _dp_energy(z, K, h, znew):
    """Energy quadratures: the 5th-order weights of the states (A[6]) on their rates."""
    for r in range(10, z.shape[0]):
        znew[r] = z[r] + h * (B[0] * K[0, r] + B[2] * K[2, r] + B[3] * K[3, r]
                              + B[4] * K[4, r] + B[5] * K[5, r])


# ------------------------------------------------------------------------------------
# adaptive Dormand-Prince 5(4) with event location
# ------------------------------------------------------------------------------------
@njit(cache=True)
def _segment(tseg, p, phx):
    """Table segment index (in the periodic-extended table) and table-period count at
    tseg (``p[P_PER]`` is the table period, ``GearDynamics.table_period_rad``)."""
    P = p[P_PER]
    ph = p[P_OM] * tseg
    m = math.floor(ph / P)
    u = ph - m * P
    n2 = phx.shape[0]
    if p[P_UNI] > 0.5:
        i = int(math.floor((u - p[P_PHI0]) / p[P_DPHI])) + 1
    else:
        i = int(np.searchsorted(phx, u, side="right")) - 1
    if i < 0:
        i = 0
    if i > n2 - 2:
        i = n2 - 2
    return i, m


@njit(cache=True)
def _table_at(t, i, m, p, phx, kx, ex, sw_tv, sw_te):
    """(k, e, dk/dt, de/dt) at time t on the held table segment i of period m; kx, ex are
    the segments' polynomial coefficients (``model.segment_coefficients``)."""
    k = p[P_KC]
    e = 0.0
    dk = 0.0
    de = 0.0
    if sw_tv is not None or sw_te is not None:
        d = p[P_OM] * t - m * p[P_PER] - phx[i]
        if sw_tv is not None:
            k = kx[i, 0] + d * (kx[i, 1] + d * (kx[i, 2] + d * kx[i, 3]))
            dk = (kx[i, 1] + d * (2.0 * kx[i, 2] + 3.0 * d * kx[i, 3])) * p[P_OM]
        if sw_te is not None:
            e = ex[i, 0] + d * (ex[i, 1] + d * (ex[i, 2] + d * ex[i, 3]))
            de = (ex[i, 1] + d * (2.0 * ex[i, 2] + 3.0 * d * ex[i, 3])) * p[P_OM]
    return k, e, dk, de


@njit(cache=True)
def _g_arr(t, i, m, za, g, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn):
    k, e, dk, de = _table_at(t, i, m, p, phx, kx, ex, sw_tv, sw_te)
    gv = _gvals(_tup(za), e, p, sw_bl, sw_cl, sw_dyn)
    for q in range(NG):
        g[q] = gv[q]


@njit(cache=True)
def _bmode(up, down):
    return 1 if up else (-1 if down else 0)


@njit(cache=True)
def _modes_tuple(act):
    return (1 if act[0] else 0, 1 if act[1] else 0, _bmode(act[2], act[3]), _bmode(act[4], act[5]),
            _bmode(act[6], act[7]), _bmode(act[8], act[9]))


@njit(cache=True)
def _next_node_time(t, p, phi):
    """Time of the first table node strictly after t (the linear table's kinks)."""
    P = p[P_PER]
    om = p[P_OM]
    n = phi.shape[0]
    ph = om * t
    m = math.floor(ph / P)
    u = ph - m * P
    j = int(np.searchsorted(phi, u, side="right"))
    kk = int(m) * n + j
    for _ in range(3):
        tn = (phi[kk % n] + (kk // n) * P) / om
        if tn > t * (1.0 + 1e-15) + 1e-300 and (tn - t) * om > 1e-12 * P:
            return tn
        kk += 1
    return (phi[kk % n] + (kk // n) * P) / om


@njit(cache=True)
def _dense(z, K, h, th, PD, out, nz):
    """Dormand-Prince continuous extension at theta in [0, 1]."""
    t2 = th * th
    t3 = t2 * th
    t4 = t3 * th
    b0 = PD[0, 0] * th + PD[0, 1] * t2 + PD[0, 2] * t3 + PD[0, 3] * t4
    b2 = PD[2, 0] * th + PD[2, 1] * t2 + PD[2, 2] * t3 + PD[2, 3] * t4
    b3 = PD[3, 0] * th + PD[3, 1] * t2 + PD[3, 2] * t3 + PD[3, 3] * t4
    b4 = PD[4, 0] * th + PD[4, 1] * t2 + PD[4, 2] * t3 + PD[4, 3] * t4
    b5 = PD[5, 0] * th + PD[5, 1] * t2 + PD[5, 2] * t3 + PD[5, 3] * t4
    b6 = PD[6, 0] * th + PD[6, 1] * t2 + PD[6, 2] * t3 + PD[6, 3] * t4
    for i in range(nz):
        out[i] = z[i] + h * (b0 * K[0, i] + b2 * K[2, i] + b3 * K[3, i] + b4 * K[4, i]
                             + b5 * K[5, i] + b6 * K[6, i])


@njit(cache=True)
def _illinois(t, h, i, m, z, K, PD, gi, act_i, a, fa, bq, fb, zs, gs, p, phx, kx, ex,
              sw_tv, sw_bl, sw_cl, sw_te, sw_dyn):
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


@njit(cache=True)
def _ev_put(ev, n, t, z, f0, f1):
    """Row n of the event record (grown by doubling when full): time, state, one-sided
    derivatives. Returns the (possibly new) buffer."""
    if n == ev.shape[0]:
        grown = np.empty((2 * n, EV_COLS))
        grown[:n] = ev
        ev = grown
    ev[n, EV_T] = t
    for r in range(10):
        ev[n, EV_Z + r] = z[r]
        ev[n, EV_F0 + r] = f0[r]
        ev[n, EV_F1 + r] = f1[r]
    return ev


@njit(cache=True)
def dopri5(z0, t_end, t_out, rtol, atol, h0, hmax, hmin, max_steps, zlim, gidx,
           p, phi, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
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
    zt = np.empty(nz)           # scratch for the event root finder
    zd = np.empty(nz)
    act = np.zeros(NG, dtype=np.bool_)
    g = np.zeros(NG)
    gs = np.zeros(NG)
    gcur = np.zeros(NG)
    gprev = np.zeros(NG)
    roots = np.full(NG, 2.0)
    ng = gidx.shape[0]
    t = 0.0
    clip = (sw_tv is not None) or (sw_te is not None)
    hp = h0                      # step proposed by the error controller
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
    n_rec = 0
    t_lo = t_out[0] if n_out > 0 else 0.0
    t_hi = t_out[n_out - 1] if n_out > 0 else -1.0
    n_zero = 0
    ev_rate = 0.0                # moving average of events per step (chatter diagnosis)
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
        zn, ks, ws, errt = _dp_stages(t, h, si, sm, _tup(z), k1, w1, p, modes, phx, kx, ex,
                                      sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
        en = 0.0
        for r in range(nerr):
            sc = atol[r] + rtol * max(abs(z[r]), abs(zn[r]))
            en += (errt[r] / sc) ** 2
        en = math.sqrt(en / nerr)
        if not np.isfinite(en):
            en = 1e10
        if en > 1.0:
            n_rej += 1
            hp = h * max(0.2, 0.9 * en ** -0.2)
            if hp < hmin:
                status = ST_HMIN
                break
            continue
        # the stage rows feed the dense output (samples, event checks) and the energy
        # quadratures; a step that needs none of them skips the copy
        if (sw_en is not None or (ng > 0 and not skip_events)
                or (ko < n_out and t_out[ko] <= t + h * (1.0 + 1e-12))):
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
                        rt = _illinois(t, h, si, sm, z, K, PD, gi, act[gi], thp, gprev[gi], th, g[gi],
                                       zt, gs, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
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
                        zn, ks, ws, errt = _dp_stages(t, h_ev, si, sm, _tup(z), k1, w1, p, modes, phx, kx,
                                                      ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
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
                    out[ko, :] = znew
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
        if not (np.isfinite(z[4]) and abs(z[4]) < zlim and abs(z[0]) < zlim and abs(z[2]) < zlim):
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
            fac = 5.0 if en < 1e-10 else min(5.0, max(0.2, 0.9 * en ** -0.2))
            if clipped:
                hp = max(hp, h * fac) if fac >= 1.0 else min(hp, h * fac)
            else:
                hp = h * fac
    counters = np.array([n_acc, n_rej, n_ev, ko, status, int(1000.0 * ev_rate)], dtype=np.int64)
    return out, counters, z, t, ev[:n_rec].copy()


@njit(cache=True)
def rhs_at(t, z, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """The compiled right-hand side at time t with the contact modes from the state
    (what RK4 integrates), as a 14-array (10 states, 4 energy rates): for tests."""
    i, m = _segment(t, p, phx)
    k, e, dk, de = _table_at(t, i, m, p, phx, kx, ex, sw_tv, sw_te)
    dz, F, w = _rhs(_tup(z), k, e, dk, de, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
    out = np.zeros(14)
    _put(out, dz, w, sw_en)
    return out
