"""One Dormand-Prince 5(4) step on tuples, its dense output and its energy quadratures.

With the tableau of ``dynamics.dormand_prince`` (Dormand & Prince 1980, first same as last;
Shampine 1986 for the continuous extension), from (t, z) with ``k1 = f(t, z)`` given:

    k_s = f(t + C_s h, z + h sum_j A_sj k_j)   (s = 2 .. 6)
    z_new = z + h sum_s B_s k_s,   k7 = f(t + h, z_new),   err = h sum_s E_s k_s
    z(t + theta h) = z + h sum_s k_s sum_q P_sq theta^(q + 1)      (``_dense``, 0 <= theta <= 1)

The contact modes are frozen over the step (``modes``) and the table segment is held
(``dynamics.kernel_tables``), so each step integrates a smooth right-hand side. The energy
quadratures (J) take the 5th-order weights on their rates (``_dp_energy``).
"""

from __future__ import annotations

from numba import njit

from .dormand_prince import A2, A3, A4, A5, A6, B, C, E
from .kernel_rhs import _rhs_frozen
from .kernel_state import INNER, _lc1, _lc2, _lc3, _lc4, _lc5, _lc6, _put, _tup
from .kernel_tables import _table_at


@njit(**INNER)
def _dp_stages(t, h, i, m, z, k1, w1, p, modes, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """Stages 2-7 of Dormand-Prince 5(4) on tuples (k1 = f(t, z) given, FSAL).
    Returns (z_new, (k2..k7), (w2..w7), error estimate tuple h sum E_s k_s)."""
    kt, et, dkt, det = _table_at(t + C[1] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k2, F, w2 = _rhs_frozen(_lc1(z, h, A2[0], k1), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    kt, et, dkt, det = _table_at(t + C[2] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k3, F, w3 = _rhs_frozen(_lc2(z, h, A3[0], k1, A3[1], k2), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    kt, et, dkt, det = _table_at(t + C[3] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k4, F, w4 = _rhs_frozen(
        _lc3(z, h, A4[0], k1, A4[1], k2, A4[2], k3), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en
    )
    kt, et, dkt, det = _table_at(t + C[4] * h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k5, F, w5 = _rhs_frozen(
        _lc4(z, h, A5[0], k1, A5[1], k2, A5[2], k3, A5[3], k4), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en
    )
    kt, et, dkt, det = _table_at(t + h, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k6, F, w6 = _rhs_frozen(
        _lc5(z, h, A6[0], k1, A6[1], k2, A6[2], k3, A6[3], k4, A6[4], k5),
        kt,
        et,
        dkt,
        det,
        p,
        modes,
        sw_bl,
        sw_cl,
        sw_dyn,
        sw_en,
    )
    zn = _lc5(z, h, B[0], k1, B[2], k3, B[3], k4, B[4], k5, B[5], k6)
    k7, F, w7 = _rhs_frozen(zn, kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    err = _lc6(zero, h, E[0], k1, E[2], k3, E[3], k4, E[4], k5, E[5], k6, E[6], k7)
    return zn, (k2, k3, k4, k5, k6, k7), (w2, w3, w4, w5, w6, w7), err


@njit(**INNER)
def _f_first(t, i, m, z, p, modes, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """f(t, z) and the energy rates at a (re)start of the adaptive integration."""
    kt, et, dkt, det = _table_at(t, i, m, p, phx, kx, ex, sw_tv, sw_te)
    k1, F1, w1 = _rhs_frozen(_tup(z), kt, et, dkt, det, p, modes, sw_bl, sw_cl, sw_dyn, sw_en)
    return k1, w1


@njit(**INNER)
def _dp_store(K, k1, w1, ks, ws, zn, znew, sw_en):
    """Stage derivatives into K (dense output, event location), z_new into znew[:10]."""
    _put(K[0], k1, w1, sw_en)
    for s in range(6):
        _put(K[s + 1], ks[s], ws[s], sw_en)
    for r in range(10):
        znew[r] = zn[r]


@njit(**INNER)
def _dp_energy(z, K, h, znew):
    """Energy quadratures: the 5th-order weights of the states (A[6]) on their rates."""
    for r in range(10, z.shape[0]):
        znew[r] = z[r] + h * (B[0] * K[0, r] + B[2] * K[2, r] + B[3] * K[3, r] + B[4] * K[4, r] + B[5] * K[5, r])


@njit(**INNER)
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
        out[i] = z[i] + h * (b0 * K[0, i] + b2 * K[2, i] + b3 * K[3, i] + b4 * K[4, i] + b5 * K[5, i] + b6 * K[6, i])
