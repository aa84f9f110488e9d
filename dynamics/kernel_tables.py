"""The periodic table interpolant in compiled code (the adaptive integrator's view).

The kernels read k (N/m) and e (m) from the per-segment coefficients of
``dynamics.params`` (``kx``, ``ex``: (n + 1, 4) over the periodic-extended nodes ``phx``,
rad). At time t (s) the pinion angle is ``phi = omega_p t``; ``_segment`` finds the segment
i and the table-period count m (directly for a uniform table, by bisection otherwise),
``_table_at`` evaluates the held segment

    k = c0 + c1 d + c2 d^2 + c3 d^3,   dk/dt = omega_p (c1 + 2 c2 d + 3 c3 d^2),
    d = omega_p t - m P - phx_i                                   (P: table period, rad)

(the same for e), and ``_next_node_time`` gives the time of the next node, where an
adaptive step must end (so that each step sees a polynomial). The fixed-step RK4 reads k
and e from a precomputed schedule instead (``dynamics.table_time.rk4_schedule``).
"""

from __future__ import annotations

import math

from numba import njit

from .kernel_state import INNER
from .params import P_DPHI, P_KC, P_OM, P_PER, P_PHI0, P_UNI


@njit(**INNER)
def _bisect_right(a, x):
    """The index j with a[j-1] <= x < a[j] in the sorted array a (0 .. len(a)), as
    ``np.searchsorted(a, x, side="right")``. Written out because numba's searchsorted
    compiles its string argument and every array-kind variant: seconds on a first run."""
    lo = 0
    hi = a.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if x < a[mid]:
            hi = mid
        else:
            lo = mid + 1
    return lo


@njit(**INNER)
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
        i = _bisect_right(phx, u) - 1
    if i < 0:
        i = 0
    if i > n2 - 2:
        i = n2 - 2
    return i, m


@njit(**INNER)
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


@njit(**INNER)
def _next_node_time(t, p, phi):
    """Time of the first table node strictly after t (the linear table's kinks)."""
    P = p[P_PER]
    om = p[P_OM]
    n = phi.shape[0]
    ph = om * t
    m = math.floor(ph / P)
    u = ph - m * P
    j = _bisect_right(phi, u)
    kk = int(m) * n + j
    for _ in range(3):
        tn = (phi[kk % n] + (kk // n) * P) / om
        if tn > t * (1.0 + 1e-15) + 1e-300 and (tn - t) * om > 1e-12 * P:
            return tn
        kk += 1
    return (phi[kk % n] + (kk // n) * P) / om
