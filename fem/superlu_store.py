"""SuperLU's L factor read in place, without converting the factors (SI-free: indices and
the factor's values).

scipy's ``SuperLU`` object gives its factors only as whole CSC matrices (``lu.L``,
``lu.U``): one conversion of SuperLU's supernodal storage copies every nonzero of both
(10-16M for a paper pinion body, about 1.2-1.4 s, as long as the factorization itself).
The static condensation of fem.condensation needs only the pivots and the border rows of
L (its last m rows, m = 2142 of 89808). Both lie in L's supernodal store (SuperLU's
``SCformat``; Demmel, Eisenstat, Gilbert, Li & Liu, SIAM J. Matrix Anal. Appl. 20 (1999)
720): a supernode of columns fsupc .. lsupc - 1 keeps, for each of its columns j, one
dense column of nsupr values over the supernode's row list
``rowind[rowind_colptr[fsupc] : rowind_colptr[fsupc + 1]]``, whose rows < j are U's
entries inside the supernode, row j is U's diagonal (the pivot) and rows > j are L's
(L's unit diagonal is implicit). This module views that store through the object's C
layout (scipy/sparse/linalg/_dsolve/_superluobject.h: ``PyObject_HEAD; npy_intp m, n;
SuperMatrix L, U; int *perm_r, *perm_c; ...``; ``SuperMatrix`` = three enums, nrow,
ncol, ``void *Store``) as numpy arrays (:func:`supernodal_store`) and gathers the border
(:func:`border_rows`).

The layout is checked before anything is read (the object's sizes, L of storage type
SLU_SC, double, lower-trapezoidal unit; U of type SLU_NC; the permutations equal the
public ``perm_r``, ``perm_c``; the supernode maps consistent with n and with each
column's length; every supernode's row list starting with its own columns); on any
mismatch :func:`supernodal_store` returns None and the caller converts the factors
instead. fem.condensation also checks the Schur complement against an independent solve
with the same factors (``lu.solve``).
"""

from __future__ import annotations

import ctypes
import sys
from dataclasses import dataclass

import numpy as np

__all__ = ["SupernodalStore", "supernodal_store", "border_rows"]

# enum values of SuperLU's supermatrix.h
_SLU_NC, _SLU_SC = 0, 3  # Stype_t: column-wise, supernodal
_SLU_D = 1  # Dtype_t: double
_SLU_TRLU, _SLU_TRU = 1, 4  # Mtype_t: lower trapezoidal with unit diagonal, upper triangular

_HEAD = object.__basicsize__  # sizeof(PyObject): PyObject_HEAD of this interpreter's build


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
    if lu.shape != (n, n) or n == 0 or sys.implementation.name != "cpython":
        return None  # id() is the object's address in CPython only
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


@dataclass(frozen=True)
class SupernodalStore:
    """SuperLU's L (SCformat) of an n x n factorization, as numpy views of its arrays:
    supernode k holds columns first[k] .. first[k + 1] - 1, its row list is
    rowind[row_start[k] : row_start[k] + nrows[k]] (its own columns first, in order), and
    column j's nrows values start at nzval[col_ptr[j]] (a dense nrows x width block per
    supernode: rows < j are U's, row j the pivot U[j, j], rows > j L's)."""

    n: int
    first: np.ndarray
    row_start: np.ndarray
    nrows: np.ndarray
    col_ptr: np.ndarray
    rowind: np.ndarray
    nzval: np.ndarray

    def pivots(self) -> np.ndarray:
        """U[j, j] of every column (n,)."""
        j = np.arange(self.n)
        k = np.repeat(np.arange(len(self.nrows)), np.diff(self.first))
        return self.nzval[self.col_ptr[j] + (j - self.first[k])]


def supernodal_store(lu) -> SupernodalStore | None:
    """The supernodal store of the SuperLU object ``lu`` (views, valid while ``lu``
    lives), or None when its C layout or its supernode maps are not the expected ones."""
    got = _store(lu)
    if got is None:
        return None
    sc, n = got
    ns = sc.nsuper + 1  # SuperLU stores the number of supernodes minus one
    if not 0 < ns <= n:
        return None
    col_ptr, row_ptr = _ints(sc.nzval_colptr, n + 1), _ints(sc.rowind_colptr, n + 1)
    col_to_sup, first = _ints(sc.col_to_sup, n), _ints(sc.sup_to_col, ns + 1)
    if first[0] != 0 or first[ns] != n or np.any(np.diff(first) <= 0) or col_ptr[0] != 0:
        return None
    width = np.diff(first)
    if not np.array_equal(col_to_sup, np.repeat(np.arange(ns), width)):
        return None
    start = row_ptr[first[:-1]]
    nrows = row_ptr[first[:-1] + 1] - start
    # every column of a supernode holds nrows values; the row lists follow each other
    if np.any(nrows < width) or not np.array_equal(np.diff(col_ptr), nrows[col_to_sup]):
        return None
    if start[0] != 0 or not np.array_equal(start[1:], start[:-1] + nrows[:-1]):
        return None
    nzval = np.ctypeslib.as_array(sc.nzval, shape=(int(col_ptr[n]),))
    rowind = _ints(sc.rowind, int(start[-1] + nrows[-1]))
    j = np.arange(n)
    own = rowind[np.repeat(start, width) + (j - np.repeat(first[:-1], width))]
    if not np.array_equal(own, j) or rowind.min() < 0 or rowind.max() >= n:
        return None  # the supernode's own columns come first in its row list
    return SupernodalStore(n, first, start, nrows, col_ptr, rowind, nzval)


def border_rows(store: SupernodalStore, o: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, v): every entry L[o + i, j] = v of L's rows o .. n - 1 in its columns j < o
    (the border block L_BI of a factorization whose last n - o rows are B), each once."""
    k_of = np.repeat(np.arange(len(store.nrows)), store.nrows)  # supernode of each row-list position
    pos = np.flatnonzero(store.rowind >= o)
    k = k_of[pos]
    f = store.first[k]
    cnt = np.minimum(store.first[k + 1], o) - f  # the supernode's columns left of o
    keep = cnt > 0
    pos, k, f, cnt = pos[keep], k[keep], f[keep], cnt[keep]
    rep = np.repeat(np.arange(len(pos)), cnt)
    j = f[rep] + (np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt))
    v = store.nzval[store.col_ptr[j] + (pos - store.row_start[k])[rep]]
    return store.rowind[pos][rep] - o, j, v
