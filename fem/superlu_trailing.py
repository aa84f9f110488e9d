"""The trailing block of SuperLU's factors read in place, without converting the factors.

scipy's ``SuperLU`` object gives its factors only as whole CSC matrices (``lu.L``,
``lu.U``): one conversion of SuperLU's supernodal storage copies every nonzero of both
(15.6M for the paper pinion, about 1.2-1.4 s, as long as the factorization itself). The
static condensation of fem.pair_body needs only the trailing m x m block of L (the last
m columns, m = 2142 of 89808) and the diagonal of U there. Both lie in L's supernodal
store (SuperLU's ``SCformat``; Demmel, Eisenstat, Gilbert, Li & Liu, SIAM J. Matrix Anal.
Appl. 20 (1999) 720): a supernode of columns fsupc .. lsupc - 1 keeps, for each of its
columns j, one dense column of nsupr values over the supernode's row list
``rowind[rowind_colptr[fsupc] : rowind_colptr[fsupc + 1]]``, whose rows < j are U's
entries inside the supernode, row j is U's diagonal (the pivot) and rows > j are L's
(L's unit diagonal is implicit). This module views that store through the object's C
layout (scipy/sparse/linalg/_dsolve/_superluobject.h: ``PyObject_HEAD; npy_intp m, n;
SuperMatrix L, U; int *perm_r, *perm_c; ...``; ``SuperMatrix`` = three enums, nrow,
ncol, ``void *Store``) and copies the few supernodes that cover the last m columns.

The layout is checked before anything is read (the object's sizes, L of storage type
SLU_SC, double, lower-trapezoidal unit; U of type SLU_NC; the permutations equal the
public ``perm_r``, ``perm_c``; the supernode maps consistent with n and with each
column's length); on any mismatch :func:`trailing_block` returns None and the caller
converts the factors instead. fem.pair_body also checks the condensed result against an
independent solve with the same factors (``lu.solve``).
"""

from __future__ import annotations

import ctypes

import numpy as np

__all__ = ["trailing_block"]

# enum values of SuperLU's supermatrix.h
_SLU_NC, _SLU_SC = 0, 3  # Stype_t: column-wise, supernodal
_SLU_D = 1  # Dtype_t: double
_SLU_TRLU, _SLU_TRU = 1, 4  # Mtype_t: lower trapezoidal with unit diagonal, upper triangular

_PTR = ctypes.sizeof(ctypes.c_void_p)
_HEAD = ctypes.sizeof(ctypes.c_ssize_t) + _PTR  # PyObject_HEAD: refcount, type


class _SuperMatrix(ctypes.Structure):
    _fields_ = [
        ("Stype", ctypes.c_int),
        ("Dtype", ctypes.c_int),
        ("Mtype", ctypes.c_int),
        ("nrow", ctypes.c_int),
        ("ncol", ctypes.c_int),
        ("Store", ctypes.c_void_p),
    ]


class _LUObject(ctypes.Structure):
    _fields_ = [
        ("head", ctypes.c_byte * _HEAD),
        ("m", ctypes.c_ssize_t),
        ("n", ctypes.c_ssize_t),
        ("L", _SuperMatrix),
        ("U", _SuperMatrix),
        ("perm_r", ctypes.POINTER(ctypes.c_int)),
        ("perm_c", ctypes.POINTER(ctypes.c_int)),
    ]


class _SCformat(ctypes.Structure):
    _fields_ = [
        ("nnz", ctypes.c_int),
        ("nsuper", ctypes.c_int),
        ("nzval", ctypes.POINTER(ctypes.c_double)),
        ("nzval_colptr", ctypes.POINTER(ctypes.c_int)),
        ("rowind", ctypes.POINTER(ctypes.c_int)),
        ("rowind_colptr", ctypes.POINTER(ctypes.c_int)),
        ("col_to_sup", ctypes.POINTER(ctypes.c_int)),
        ("sup_to_col", ctypes.POINTER(ctypes.c_int)),
    ]


def _ints(ptr, n: int) -> np.ndarray:
    return np.ctypeslib.as_array(ptr, shape=(n,))


def _store(lu):
    """(SCformat of L, n) of the SuperLU object ``lu``, or None when its C layout is not
    the expected one."""
    n = int(lu.shape[0])
    if lu.shape != (n, n) or n == 0:
        return None
    obj = _LUObject.from_address(id(lu))
    L, U = obj.L, obj.U
    if (obj.m, obj.n) != (n, n) or (L.nrow, L.ncol, U.nrow, U.ncol) != (n, n, n, n):
        return None
    expected = (_SLU_SC, _SLU_D, _SLU_TRLU, _SLU_NC, _SLU_D, _SLU_TRU)
    if (L.Stype, L.Dtype, L.Mtype, U.Stype, U.Dtype, U.Mtype) != expected:
        return None
    if not (L.Store and obj.perm_r and obj.perm_c):
        return None
    if not (np.array_equal(_ints(obj.perm_r, n), lu.perm_r) and np.array_equal(_ints(obj.perm_c, n), lu.perm_c)):
        return None
    return _SCformat.from_address(L.Store), n


def trailing_block(lu, m: int) -> tuple[np.ndarray, np.ndarray] | None:
    """(T, d) of the last m columns of SuperLU's factors (scipy ``SuperLU`` of an n x n
    matrix factorized without row or column permutation): T (m, m) C-ordered holds
    T[j, i] = L[n - m + i, n - m + j] for i > j (the trailing block of L, transposed,
    i.e. T read in Fortran order is L_BB's strict lower triangle), T's other entries are
    unspecified (U's entries inside supernodes, the pivots); d (m,) the pivots
    U[j, j] of those columns. None when the object's layout is not the expected one."""
    got = _store(lu)
    if got is None:
        return None
    sc, n = got
    if not (0 < m <= n) or sc.nsuper < 0:
        return None
    ns = sc.nsuper + 1  # SuperLU stores the number of supernodes minus one
    col_ptr, row_ptr = _ints(sc.nzval_colptr, n + 1), _ints(sc.rowind_colptr, n + 1)
    col_to_sup, sup_to_col = _ints(sc.col_to_sup, n), _ints(sc.sup_to_col, ns + 1)
    if sup_to_col[0] != 0 or sup_to_col[ns] != n or col_to_sup[n - 1] != ns - 1 or col_ptr[0] != 0:
        return None
    nzval = np.ctypeslib.as_array(sc.nzval, shape=(int(col_ptr[n]),))
    rowind = _ints(sc.rowind, int(row_ptr[n]))
    o = n - m
    T = np.zeros((m, m))
    d = np.empty(m)
    for k in range(int(col_to_sup[o]), ns):
        f, last = int(sup_to_col[k]), int(sup_to_col[k + 1])  # columns f .. last - 1
        r0, nr = int(row_ptr[f]), int(row_ptr[f + 1] - row_ptr[f])
        # each column of a supernode holds nr values (a dense nr x (last - f) block)
        if nr < last - f or np.any(np.diff(col_ptr[f : last + 1]) != nr) or np.any(col_to_sup[f:last] != k):
            return None
        rows = rowind[r0 : r0 + nr]
        if not np.array_equal(rows[: last - f], np.arange(f, last)) or np.any(rows >= n) or np.any(rows < 0):
            return None  # the supernode's own columns come first in its row list
        block = nzval[col_ptr[f] : col_ptr[f] + nr * (last - f)].reshape(last - f, nr)
        c0 = max(f, o)
        keep = rows >= o
        T[np.ix_(np.arange(c0, last) - o, rows[keep] - o)] = block[c0 - f :, keep]
        d[c0 - o : last - o] = block[np.arange(c0 - f, last - f), np.arange(c0 - f, last - f)]
    return T, d
