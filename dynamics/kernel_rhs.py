"""The compiled right-hand side of the reduced 5-DOF model: scalar physics on tuples.

The equations of ``dynamics.equations`` (paper Eqs. 7-10, 17-20, corrected as in
``dynamics.model``) on scalars, for numba. ``_kin``: the mesh kinematics (delta, delta' in
m and m/s, the backlash half-width b in m, the gradients ``G = d delta / d(y_p, x_p, y_g,
x_g)`` and ``Gb = d b / d(...)``). ``_rhs``: the state derivative, the mesh force F_m (N)
and the energy rates (W). ``_gvals``: the ``NG = 10`` switching functions (m), positive
while in contact:

    s - b, -s - b     drive flank, back flank (s = delta - e)
    +-u_j - b_b       bearing j = y_p, x_p, y_g, x_g on its upper, lower stop

The parameters ``p`` are the vector of ``dynamics.params`` (SI). The effect switches
``sw_bl`` (backlash / flank law), ``sw_cl`` (bearing clearance), ``sw_dyn`` (dynamic centre
distance), ``sw_en`` (energy rates) are ``None`` or ``True``: one specialisation per effect
set (``dynamics.kernels``). ``_rhs`` is inlined at numba's IR level (``inline="always"``)
into RK4: left to LLVM it stayed a call that copied the 23-value parameter tuple four times
per step (1.33x a plain C loop; inlined 0.95x, ``benchmarks/bench_rk4_vs_c.py``). Dormand-
Prince calls the single compiled ``_rhs_frozen`` instead (a cold compile of 8 inlined copies).
"""

from __future__ import annotations

import math

from numba import njit

from .kernel_state import INNER
from .params import P_B, P_BB, P_C0, P_CA, P_CBG, P_CBP, P_CH, P_FS, P_INV0, P_KB, P_ME, P_MG, P_MP, P_PAPER, P_RS, P_SA

NG = 10  # switching functions: s-b, -s-b, then +-u_j - b_b for y_p, x_p, y_g, x_g


@njit(**INNER)
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


@njit(**INNER)
def _dead(u, bb):
    if u > bb:
        return u - bb
    if u < -bb:
        return u + bb
    return 0.0


@njit(**INNER)
def _dead_mode(u, m, bb):
    if m == 1:
        return u - bb
    if m == -1:
        return u + bb
    return 0.0


@njit(inline="always", **INNER)
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
    dz = (
        z[5],
        z[6],
        z[7],
        z[8],
        z[9],
        (Q0 - cbp * z[5] - kb * f0) / p[P_MP],
        (Q1 - cbp * z[6] - kb * f1) / p[P_MP],
        (Q2 - cbg * z[7] - kb * f2) / p[P_MG],
        (Q3 - cbg * z[8] - kb * f3) / p[P_MG],
        (p[P_FS] - F) / p[P_ME],
    )
    if sw_en is not None:
        w = (
            p[P_FS] * z[9],
            cbp * (z[5] * z[5] + z[6] * z[6]) + cbg * (z[7] * z[7] + z[8] * z[8]) + fd * dd,
            0.5 * dk * (fdv * fdv + fbk * fbk),
            -k * (fdv + fbk) * de,
        )
    else:
        w = (0.0, 0.0, 0.0, 0.0)
    return dz, F, w


@njit(**INNER)
def _rhs_frozen(z, k, e, dk, de, p, modes, sw_bl, sw_cl, sw_dyn, sw_en):
    """``_rhs`` as one compiled function (its IR inlined here once), for Dormand-Prince's
    7 stages and restarts: inlining ``_rhs`` at each of those 8 call sites made numba type,
    lower and optimise 8 copies of it, the larger part of a cold dopri5 compile. The
    adaptive step is dominated by its error control, dense output and event checks, where a
    call per stage costs little (``benchmarks/bench_dynamics.py``, the compile rows)."""
    return _rhs(z, k, e, dk, de, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)


@njit(**INNER)
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
        return (g0, g1, z[0] - bb, -z[0] - bb, z[1] - bb, -z[1] - bb, z[2] - bb, -z[2] - bb, z[3] - bb, -z[3] - bb)
    return (g0, g1, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, -1.0)
