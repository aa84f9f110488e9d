"""The integrators' state as numba tuples: copy in and out, linear combinations, status codes.

State ``z``: 10 values, ``y_p, x_p, y_g, x_g, q`` (m) and their rates (m/s), held as a
10-tuple in the hot loops (tuples are values in numba: no reference counting, no heap).
With the energy switch four quadrature states (J) follow in the arrays: the input work
``int F_s q' dt``, the dissipated energy, the parametric stiffness work
``int 1/2 (dk/dt) f^2 dt`` and the excitation work ``-int k f (de/dt) dt``.

``_lc1`` .. ``_lc6``: ``z + h sum_j a_j k_j`` over 1..6 stage derivatives (the Runge-Kutta
stage sums), unrolled so that LLVM keeps every stage in registers.

Status codes the integrators return: ``ST_OK`` 0 finished, ``ST_BUDGET`` 1 step budget
exhausted, ``ST_HMIN`` 2 step size below the minimum, ``ST_DIVERGED`` 3 diverged
(non-finite or unbounded state).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

ST_OK, ST_BUDGET, ST_HMIN, ST_DIVERGED = 0, 1, 2, 3

#: njit options of every kernel function that only other kernels call (all but ``rk4``,
#: ``dopri5`` and ``rhs_at``): no CPython or C-callable wrapper, which numba otherwise
#: generates for each compiled function (unboxing code for every argument, a few tenths
#: of a second of a cold first run per function of tuple arguments; they are never called
#: from Python). Cached on disk like the entry points.
#: (``Any`` values: numba's type stubs do not list the two wrapper options)
INNER: dict[str, Any] = dict(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)


@njit(**INNER)
def _counters(a, b, c, d, e, f):
    """The integrators' int64 counter array. Element stores, not ``np.array([...])``:
    numba compiles list-to-array conversion with its reflection machinery (slow first run)."""
    out = np.empty(6, dtype=np.int64)
    out[0] = a
    out[1] = b
    out[2] = c
    out[3] = d
    out[4] = e
    out[5] = f
    return out


@njit(**INNER)
def _tup(a):
    return (a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], a[9])


@njit(**INNER)
def _put(dst, z, w, sw_en):
    for i in range(10):
        dst[i] = z[i]
    if sw_en is not None:
        for i in range(4):
            dst[10 + i] = w[i]


@njit(**INNER)
def _lc1(z, h, a0, k0):
    return (
        z[0] + h * (a0 * k0[0]),
        z[1] + h * (a0 * k0[1]),
        z[2] + h * (a0 * k0[2]),
        z[3] + h * (a0 * k0[3]),
        z[4] + h * (a0 * k0[4]),
        z[5] + h * (a0 * k0[5]),
        z[6] + h * (a0 * k0[6]),
        z[7] + h * (a0 * k0[7]),
        z[8] + h * (a0 * k0[8]),
        z[9] + h * (a0 * k0[9]),
    )


@njit(**INNER)
def _lc2(z, h, a0, k0, a1, k1):
    return (
        z[0] + h * (a0 * k0[0] + a1 * k1[0]),
        z[1] + h * (a0 * k0[1] + a1 * k1[1]),
        z[2] + h * (a0 * k0[2] + a1 * k1[2]),
        z[3] + h * (a0 * k0[3] + a1 * k1[3]),
        z[4] + h * (a0 * k0[4] + a1 * k1[4]),
        z[5] + h * (a0 * k0[5] + a1 * k1[5]),
        z[6] + h * (a0 * k0[6] + a1 * k1[6]),
        z[7] + h * (a0 * k0[7] + a1 * k1[7]),
        z[8] + h * (a0 * k0[8] + a1 * k1[8]),
        z[9] + h * (a0 * k0[9] + a1 * k1[9]),
    )


@njit(**INNER)
def _lc3(z, h, a0, k0, a1, k1, a2, k2):
    return (
        z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0]),
        z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1]),
        z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2]),
        z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3]),
        z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4]),
        z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5]),
        z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6]),
        z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7]),
        z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8]),
        z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9]),
    )


@njit(**INNER)
def _lc4(z, h, a0, k0, a1, k1, a2, k2, a3, k3):
    return (
        z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0] + a3 * k3[0]),
        z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1] + a3 * k3[1]),
        z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2] + a3 * k3[2]),
        z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3] + a3 * k3[3]),
        z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4] + a3 * k3[4]),
        z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5] + a3 * k3[5]),
        z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6] + a3 * k3[6]),
        z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7] + a3 * k3[7]),
        z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8] + a3 * k3[8]),
        z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9] + a3 * k3[9]),
    )


@njit(**INNER)
def _lc5(z, h, a0, k0, a1, k1, a2, k2, a3, k3, a4, k4):
    return (
        z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0] + a3 * k3[0] + a4 * k4[0]),
        z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1] + a3 * k3[1] + a4 * k4[1]),
        z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2] + a3 * k3[2] + a4 * k4[2]),
        z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3] + a3 * k3[3] + a4 * k4[3]),
        z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4] + a3 * k3[4] + a4 * k4[4]),
        z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5] + a3 * k3[5] + a4 * k4[5]),
        z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6] + a3 * k3[6] + a4 * k4[6]),
        z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7] + a3 * k3[7] + a4 * k4[7]),
        z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8] + a3 * k3[8] + a4 * k4[8]),
        z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9] + a3 * k3[9] + a4 * k4[9]),
    )


@njit(**INNER)
def _lc6(z, h, a0, k0, a1, k1, a2, k2, a3, k3, a4, k4, a5, k5):
    return (
        z[0] + h * (a0 * k0[0] + a1 * k1[0] + a2 * k2[0] + a3 * k3[0] + a4 * k4[0] + a5 * k5[0]),
        z[1] + h * (a0 * k0[1] + a1 * k1[1] + a2 * k2[1] + a3 * k3[1] + a4 * k4[1] + a5 * k5[1]),
        z[2] + h * (a0 * k0[2] + a1 * k1[2] + a2 * k2[2] + a3 * k3[2] + a4 * k4[2] + a5 * k5[2]),
        z[3] + h * (a0 * k0[3] + a1 * k1[3] + a2 * k2[3] + a3 * k3[3] + a4 * k4[3] + a5 * k5[3]),
        z[4] + h * (a0 * k0[4] + a1 * k1[4] + a2 * k2[4] + a3 * k3[4] + a4 * k4[4] + a5 * k5[4]),
        z[5] + h * (a0 * k0[5] + a1 * k1[5] + a2 * k2[5] + a3 * k3[5] + a4 * k4[5] + a5 * k5[5]),
        z[6] + h * (a0 * k0[6] + a1 * k1[6] + a2 * k2[6] + a3 * k3[6] + a4 * k4[6] + a5 * k5[6]),
        z[7] + h * (a0 * k0[7] + a1 * k1[7] + a2 * k2[7] + a3 * k3[7] + a4 * k4[7] + a5 * k5[7]),
        z[8] + h * (a0 * k0[8] + a1 * k1[8] + a2 * k2[8] + a3 * k3[8] + a4 * k4[8] + a5 * k5[8]),
        z[9] + h * (a0 * k0[9] + a1 * k1[9] + a2 * k2[9] + a3 * k3[9] + a4 * k4[9] + a5 * k5[9]),
    )
