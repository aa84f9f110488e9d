"""Compiled right-hand side and integrators (numba, no Python per step).

Specialisation mechanism
------------------------
Every effect switch is passed to the kernels as an argument that is either ``None``
(effect absent) or ``True`` (effect present): ``sw_tv`` (time-varying stiffness),
``sw_bl`` (backlash), ``sw_cl`` (bearing clearance), ``sw_te`` (transmission-error
excitation), ``sw_dyn`` (dynamic centre distance), ``sw_en`` (energy accumulators).
Numba compiles one specialisation per argument *type* signature, so each effect set
gets its own machine code; inside it every ``if sw is not None:`` test is on a
``NoneType`` or ``bool`` argument and numba's dead-branch pruning removes the disabled
branches before type inference (absent effects cost nothing, not even a test). The
specialisations are cached on disk by numba (``cache=True``), one entry per signature
in the same index, so a later process loads them instead of compiling.

(A closure factory capturing boolean constants was tried first: numba keys its disk
cache on the pickled closure cells, and a closure that captures another jitted function
pickles differently in every process, so those kernels were recompiled on every run.
Type-level specialisation gives the same pruned code and a working disk cache.)

State vector ``z``: y_p, x_p, y_g, x_g, q, then their velocities; with the energy
switch four quadrature states follow: input work int F_s q' dt, dissipated energy,
parametric stiffness work int 1/2 (dk/dt) f^2 dt and excitation work -int k f de/dt dt.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .model import (P_B, P_BB, P_C0, P_CA, P_CBG, P_CBP, P_CH, P_DPHI, P_FS, P_INV0, P_KB,
                    P_KC, P_ME, P_MG, P_MP, P_OM, P_PAPER, P_PER, P_PHI0, P_RS, P_SA, P_UNI)  # noqa: F401

# Dormand-Prince 5(4) tableau and Shampine's 4th-order continuous extension (as scipy RK45)
_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0])
_A = np.zeros((7, 6))
_A[1, :1] = [1 / 5]
_A[2, :2] = [3 / 40, 9 / 40]
_A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
_A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
_A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
_A[6, :6] = [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
_E = np.array([-71 / 57600, 0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40])
_PD = np.array([
    [1, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
    [0, 0, 0, 0],
    [0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
    [0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
    [0, 127303824393 / 49829197408, -318862633887 / 49829197408, 701980252875 / 199316789632],
    [0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
    [0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423]])

NG = 10  # switching functions: s-b, -s-b, then +-u_j - b_b for y_p, x_p, y_g, x_g


@njit(cache=True)
def _segment(tseg, par, phx):
    """Table segment index (in the periodic-extended table) and period count at tseg."""
    P = par[P_PER]
    ph = par[P_OM] * tseg
    m = math.floor(ph / P)
    u = ph - m * P
    n2 = phx.shape[0]
    if par[P_UNI] > 0.5:
        i = int(math.floor((u - par[P_PHI0]) / par[P_DPHI])) + 1
    else:
        i = int(np.searchsorted(phx, u, side="right")) - 1
    if i < 0:
        i = 0
    if i > n2 - 2:
        i = n2 - 2
    return i, m


@njit(cache=True)
def _mesh(t, tseg, z, par, phx, kx, ex, sw_tv, sw_te, sw_dyn):
    """Mesh kinematics: (b, s = delta - e, delta', k, dk/dt, de/dt, G0..G4, Gb0..Gb3).

    G = d delta / d(y_p, x_p, y_g, x_g, q), Gb = d b / d(y_p, x_p, y_g, x_g) (dynamic only)."""
    Y = z[0] - z[2]
    if sw_dyn is not None:
        dx = par[P_C0] + z[3] - z[1]
        dy = z[2] - z[0]
        C = math.sqrt(dx * dx + dy * dy)
        ca = par[P_RS] / C
        if ca > 1.0:
            ca = 1.0
        sa = math.sqrt(1.0 - ca * ca)
        b = par[P_B] + par[P_RS] * (sa / ca - math.atan2(sa, ca) - par[P_INV0])
        c0 = -dy / C
        c1 = -dx / C
        c2 = dy / C
        c3 = dx / C
        w = -Y * ca / C
        G0 = ca + w * c0
        G1 = w * c1
        G2 = -ca + w * c2
        G3 = w * c3
        Gb0 = sa * c0
        Gb1 = sa * c1
        Gb2 = sa * c2
        Gb3 = sa * c3
        delta = z[4] + Y * ca
    else:
        sa = par[P_SA]
        ca = par[P_CA]
        b = par[P_B]
        G0 = ca
        G1 = sa
        G2 = -ca
        G3 = -sa
        Gb0 = 0.0
        Gb1 = 0.0
        Gb2 = 0.0
        Gb3 = 0.0
        delta = z[4] + (z[1] - z[3]) * sa + Y * ca
    dd = z[9] + G0 * z[5] + G1 * z[6] + G2 * z[7] + G3 * z[8]
    k = par[P_KC]
    dk = 0.0
    e = 0.0
    de = 0.0
    if sw_tv is not None or sw_te is not None:
        i, m = _segment(tseg, par, phx)
        u = par[P_OM] * t - m * par[P_PER]
        wd = phx[i + 1] - phx[i]
        if sw_tv is not None:
            sl = (kx[i + 1] - kx[i]) / wd
            k = kx[i] + sl * (u - phx[i])
            dk = sl * par[P_OM]
        if sw_te is not None:
            sl = (ex[i + 1] - ex[i]) / wd
            e = ex[i] + sl * (u - phx[i])
            de = sl * par[P_OM]
    return b, delta - e, dd, k, dk, de, G0, G1, G2, G3, Gb0, Gb1, Gb2, Gb3


@njit(cache=True)
def _bear(u, mj, from_state, bb):
    if from_state:
        mj = 1 if u > bb else (-1 if u < -bb else 0)
    if mj == 1:
        return u - bb
    if mj == -1:
        return u + bb
    return 0.0


@njit(cache=True)
def _eval(t, tseg, z, modes, from_state, dz, par, phx, kx, ex,
          sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """Right-hand side. modes = (drive flank, back flank, y_p, x_p, y_g, x_g): flank
    contact flags in {0, 1}, bearing modes in {-1, 0, 1}; with from_state they are taken
    from z (plain piecewise function, used by RK4). Returns the mesh force F_m."""
    b, s, dd, k, dk, de, G0, G1, G2, G3, Gb0, Gb1, Gb2, Gb3 = _mesh(
        t, tseg, z, par, phx, kx, ex, sw_tv, sw_te, sw_dyn)
    ch = par[P_CH]
    if sw_bl is not None:
        if from_state:
            drv = s > b
            bck = s < -b
        else:
            drv = modes[0] == 1
            bck = modes[1] == 1
        fdv = s - b if drv else 0.0
        fbk = s + b if bck else 0.0
        fd = ch * dd if (drv or bck or par[P_PAPER] > 0.5) else 0.0
    else:
        fdv = s
        fbk = 0.0
        fd = ch * dd
    F = fd + k * (fdv + fbk)
    Q0 = -F * G0
    Q1 = -F * G1
    Q2 = -F * G2
    Q3 = -F * G3
    if sw_dyn is not None:
        kf = k * (fdv - fbk)
        Q0 += kf * Gb0
        Q1 += kf * Gb1
        Q2 += kf * Gb2
        Q3 += kf * Gb3
    kb = par[P_KB]
    if sw_cl is not None:
        bb = par[P_BB]
        f0 = _bear(z[0], modes[2], from_state, bb)
        f1 = _bear(z[1], modes[3], from_state, bb)
        f2 = _bear(z[2], modes[4], from_state, bb)
        f3 = _bear(z[3], modes[5], from_state, bb)
    else:
        f0 = z[0]
        f1 = z[1]
        f2 = z[2]
        f3 = z[3]
    cbp = par[P_CBP]
    cbg = par[P_CBG]
    dz[0] = z[5]
    dz[1] = z[6]
    dz[2] = z[7]
    dz[3] = z[8]
    dz[4] = z[9]
    dz[5] = (Q0 - cbp * z[5] - kb * f0) / par[P_MP]
    dz[6] = (Q1 - cbp * z[6] - kb * f1) / par[P_MP]
    dz[7] = (Q2 - cbg * z[7] - kb * f2) / par[P_MG]
    dz[8] = (Q3 - cbg * z[8] - kb * f3) / par[P_MG]
    dz[9] = (par[P_FS] - F) / par[P_ME]
    if sw_en is not None:
        dz[10] = par[P_FS] * z[9]
        dz[11] = cbp * (z[5] * z[5] + z[6] * z[6]) + cbg * (z[7] * z[7] + z[8] * z[8]) + fd * dd
        dz[12] = 0.5 * dk * (fdv * fdv + fbk * fbk)
        dz[13] = -k * (fdv + fbk) * de
    return F


@njit(cache=True)
def _gfun(t, tseg, z, g, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn):
    """Switching functions; a function is 'active' (flank / bearing in contact) when > 0."""
    if sw_bl is not None:
        b, s, dd, k, dk, de, G0, G1, G2, G3, Gb0, Gb1, Gb2, Gb3 = _mesh(
            t, tseg, z, par, phx, kx, ex, sw_tv, sw_te, sw_dyn)
        g[0] = s - b
        g[1] = -s - b
    if sw_cl is not None:
        bb = par[P_BB]
        for j in range(4):
            g[2 + 2 * j] = z[j] - bb
            g[3 + 2 * j] = -z[j] - bb


@njit(cache=True)
def _modes_from_act(act, modes):
    modes[0] = 1 if act[0] else 0
    modes[1] = 1 if act[1] else 0
    for j in range(4):
        modes[2 + j] = 1 if act[2 + 2 * j] else (-1 if act[3 + 2 * j] else 0)


@njit(cache=True)
def _next_node_time(t, par, phi):
    """Time of the first table node strictly after t (the linear table's kinks)."""
    P = par[P_PER]
    om = par[P_OM]
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
def _hermite(y0, f0, y1, f1, th, h, out):
    t2 = th * th
    t3 = t2 * th
    h00 = 2 * t3 - 3 * t2 + 1
    h10 = t3 - 2 * t2 + th
    h01 = -2 * t3 + 3 * t2
    h11 = t3 - t2
    for i in range(y0.shape[0]):
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i]


@njit(cache=True)
def rk4(z0, h, n_steps, t_out0, dt_out, n_out, par, phi, phx, kx, ex,
        sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """Classical RK4 with fixed step h from t = 0; samples at t_out0 + k dt_out by cubic
    Hermite interpolation (exact at the step points). Returns (out, counters, z_end)."""
    nz = z0.shape[0]
    out = np.empty((n_out, nz))
    z = z0.copy()
    z1 = np.empty(nz)
    zt = np.empty(nz)
    k1 = np.empty(nz)
    k2 = np.empty(nz)
    k3 = np.empty(nz)
    k4 = np.empty(nz)
    k1n = np.empty(nz)
    modes = np.zeros(6, dtype=np.int64)
    _eval(0.0, 0.5 * h, z, modes, True, k1, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
    ko = 0
    t = 0.0
    for n in range(n_steps):
        t1 = (n + 1) * h
        tm = t + 0.5 * h
        for i in range(nz):
            zt[i] = z[i] + 0.5 * h * k1[i]
        _eval(tm, tm, zt, modes, True, k2, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
        for i in range(nz):
            zt[i] = z[i] + 0.5 * h * k2[i]
        _eval(tm, tm, zt, modes, True, k3, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
        for i in range(nz):
            zt[i] = z[i] + h * k3[i]
        _eval(t1, tm, zt, modes, True, k4, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
        for i in range(nz):
            z1[i] = z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        # k1 of the next step (segment chosen by the next step's midpoint)
        _eval(t1, t1 + 0.5 * h, z1, modes, True, k1n, par, phx, kx, ex,
              sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
        while ko < n_out:
            to = t_out0 + ko * dt_out
            if to > t1 + 1e-9 * h:
                break
            th = (to - t) / h
            if th < 0.0:
                th = 0.0
            if th > 1.0:
                th = 1.0
            if th <= 1e-12:
                out[ko, :] = z
            elif th >= 1.0 - 1e-12:
                out[ko, :] = z1
            else:
                _hermite(z, k1, z1, k1n, th, h, out[ko])
            ko += 1
        for i in range(nz):
            z[i] = z1[i]
            k1[i] = k1n[i]
        t = t1
        if not np.isfinite(z[4]):
            break
    counters = np.array([n_steps, 0, 0, ko], dtype=np.int64)
    return out, counters, z


@njit(cache=True)
def _dense(z, K, h, th, PD, out, nz):
    """Dormand-Prince continuous extension at theta in [0, 1]."""
    t2 = th * th
    t3 = t2 * th
    t4 = t3 * th
    for i in range(nz):
        acc = 0.0
        for s in range(7):
            c = PD[s, 0] * th + PD[s, 1] * t2 + PD[s, 2] * t3 + PD[s, 3] * t4
            acc += c * K[s, i]
        out[i] = z[i] + h * acc


@njit(cache=True)
def _stages(t, h, tseg, z, K, zt, znew, modes, A, C, par, phx, kx, ex,
            sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    nz = z.shape[0]
    for s in range(1, 7):
        for i in range(nz):
            acc = 0.0
            for r in range(s):
                acc += A[s, r] * K[r, i]
            zt[i] = z[i] + h * acc
        ts = t + C[s] * h if s < 6 else t + h
        if s == 6:
            for i in range(nz):
                znew[i] = zt[i]
        _eval(ts, tseg, zt, modes, False, K[s], par, phx, kx, ex,
              sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)


@njit(cache=True)
def _illinois(t, h, tseg, z, K, PD, gi, act_i, a, fa, bq, fb, zs, gs, par, phx, kx, ex,
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
        _gfun(t + c * h, tseg, zs, gs, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
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
def dopri5(z0, t_end, t_out0, dt_out, n_out, rtol, atol, h0, hmax, max_steps, gidx,
           par, phi, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """Adaptive Dormand-Prince 5(4) from t = 0 with event location.

    The contact modes are frozen during a step (each mode's right-hand side is smooth).
    After a step passes the error test, the switching functions listed in ``gidx`` are
    checked at 4 points of the dense output; at the first sign change the crossing is
    located on the interpolant by the Illinois method to ~1e-13 s, the step is redone
    to end exactly there, the crossed function's mode flips, and integration restarts.
    With time-varying tables, steps also end on the table nodes (kinks of the linear
    interpolant). Returns (out, counters [accepted, rejected, events, samples], z_end).
    """
    nz = z0.shape[0]
    nerr = 10
    out = np.empty((n_out, nz))
    A = _A
    C = _C
    E = _E
    PD = _PD
    K = np.empty((7, nz))
    z = z0.copy()
    znew = np.empty(nz)
    zt = np.empty(nz)
    zd = np.empty(nz)
    modes = np.zeros(6, dtype=np.int64)
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
    tn = _next_node_time(t, par, phi) if clip else 1e300
    tseg = 0.5 * min(hp, tn) if clip else 0.0
    if ng > 0:
        _gfun(t, tseg, z, gcur, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
        for q in range(ng):
            act[gidx[q]] = gcur[gidx[q]] > 0.0
        _modes_from_act(act, modes)
    _eval(t, tseg, z, modes, False, K[0], par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
    ko = 0
    n_acc = 0
    n_rej = 0
    n_ev = 0
    n_zero = 0
    skip_events = False
    while t < t_end and n_acc + n_rej < max_steps:
        h = min(hp, hmax)
        clipped = False
        last = False
        if t + h >= t_end:
            h = t_end - t
            last = True
            clipped = True
        if clip:
            if tn <= t:
                tn = _next_node_time(t, par, phi)
            if t + h >= tn:
                h = tn - t
                clipped = True
                last = tn >= t_end
        hit_node = clip and (t + h >= tn)
        tseg = t + 0.5 * h
        _stages(t, h, tseg, z, K, zt, znew, modes, A, C, par, phx, kx, ex,
                sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
        en = 0.0
        for i in range(nerr):
            ei = 0.0
            for s in range(7):
                ei += E[s] * K[s, i]
            ei *= h
            sc = atol[i] + rtol * max(abs(z[i]), abs(znew[i]))
            en += (ei / sc) ** 2
        en = math.sqrt(en / nerr)
        if not np.isfinite(en):
            en = 1e10
        if en > 1.0:
            n_rej += 1
            hp = h * max(0.2, 0.9 * en ** -0.2)
            continue
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
                    for i in range(nz):
                        zd[i] = znew[i]
                else:
                    _dense(z, K, h, th, PD, zd, nz)
                _gfun(t + th * h, tseg, zd, g, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
                for q in range(ng):
                    gi = gidx[q]
                    if (g[gi] > 0.0) != act[gi]:
                        r = _illinois(t, h, tseg, z, K, PD, gi, act[gi], thp, gprev[gi], th, g[gi],
                                      zt, gs, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
                        roots[gi] = r
                        if r < best:
                            best = r
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
                        tseg = t + 0.5 * h_ev
                        _stages(t, h_ev, tseg, z, K, zt, znew, modes, A, C, par, phx, kx, ex,
                                sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
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
                _modes_from_act(act, modes)
                n_ev += 1
        skip_events = False
        if h_used > 0.0:
            while ko < n_out:
                to = t_out0 + ko * dt_out
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
            for i in range(nz):
                z[i] = znew[i]
            n_acc += 1
        if not np.isfinite(z[4]):
            break
        if clip and t >= tn:
            tn = _next_node_time(t, par, phi)
        if event or (hit_node and (sw_en is not None)):
            # restart: the right-hand side changed (mode flip, or a new table segment
            # whose slope enters the energy integrands)
            hn = min(hp, tn - t) if clip else hp
            _eval(t, t + 0.5 * hn, z, modes, False, K[0], par, phx, kx, ex,
                  sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en)
            if ng > 0:
                _gfun(t, t + 0.5 * hn, z, gcur, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
            if n_zero > 20:
                skip_events = True
                n_zero = 0
        else:
            for i in range(nz):
                K[0, i] = K[6, i]
            if ran:
                for q in range(ng):
                    gcur[gidx[q]] = g[gidx[q]]
            elif ng > 0:
                _gfun(t, t, z, gcur, par, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn)
        if not event:
            fac = 5.0 if en < 1e-10 else min(5.0, max(0.2, 0.9 * en ** -0.2))
            if clipped:
                hp = max(hp, h * fac) if fac >= 1.0 else min(hp, h * fac)
            else:
                hp = h * fac
    counters = np.array([n_acc, n_rej, n_ev, ko], dtype=np.int64)
    return out, counters, z
