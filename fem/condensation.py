"""Static condensation of a stiffness matrix onto a set of dofs B: the flexibility
G = (K^-1)_BB = S^-1 of the Schur complement S = K_BB - K_BI K_II^-1 K_IB (m/N), and the
readings h = (K^-1 a)_B of given functionals, from one sparse factorization (SI units).

The free dofs are ordered interior first (METIS nested dissection of the node graph,
:func:`node_graph_order`) and B last. SuperLU factorizes, without pivoting (K is symmetric
positive definite), the arrowhead M = [[K_II, 0], [K_BI, I]]: its factors carry the border
L_BI = K_BI L_II^-T D^-1, read in place from SuperLU's supernodal store (fem.superlu_store:
no conversion of the whole factors, which costs as much as the factorization), so
S = K_BB - L_BI D L_BI^T (:func:`schur_from_border`) and G = S^-1 by one dense Cholesky
factorization and inversion (LAPACK dpotrf, dpotri). One solve with the same factors
checks S on a random vector (:func:`condensed_flexibility`).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pymetis
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .process_settings import one_blas_thread
from .superlu_store import border_rows, supernodal_store

__all__ = ["condensed_flexibility", "interior_order", "node_graph_order", "mirror_lower", "schur_from_border"]

CHECK_RTOL = 1e-8  # S r against the solve with the same factors (round-off is ~1e-13 on the gear bodies)
DENSE_COLUMN_ROWS = 150  # border columns with this many rows or more go through dsyrk
_CHECK_SEED = 20270  # the check's random load on B (fixed: every run and process alike)


def node_graph_order(K, keep: np.ndarray) -> np.ndarray:
    """Fill-reducing order (positions in ``keep``, new -> old) of the dofs ``keep`` of the
    vector stiffness K (x and y dofs of node k at 2 k, 2 k + 1; ``keep`` whole nodes,
    sorted, x before y): METIS's multilevel nested dissection (METIS_NodeND through
    pymetis; Karypis & Kumar, SIAM J. Sci. Comput. 20 (1998) 359) of the graph of the
    nodes of ``keep`` (node i ~ node j where any of their dofs couple in K), each node's
    x and y dofs kept together.

    Why: on a 2D mesh nested dissection leaves O(n log n) fill against the larger fill of
    minimum degree; for the paper pinion (88k interior dofs, B = 2142 last) SuperLU's
    factors have 15.6M nonzeros with it against 21.2M with SuperLU's own MMD order
    (benchmarks/bench_fem_solvers.py). The node graph is half the size of the dof graph
    (faster ordering, same fill), and is read from K's pattern directly (no sparse
    products or sums of the interior block). METIS's default seed is fixed: the order,
    and so every result, is the same in every run and worker process."""
    keep = np.asarray(keep)
    n = len(keep)
    if n % 2 or not (np.array_equal(keep[0::2] + 1, keep[1::2]) and np.all(keep[0::2] % 2 == 0)):
        raise RuntimeError("the ordered dofs do not come in (x, y) pairs")
    K = sp.csr_matrix(K)
    node = np.full(K.shape[0] // 2 + 1, -1)
    node[keep[0::2] // 2] = np.arange(n // 2)
    rows = node[np.repeat(np.arange(K.shape[0]) // 2, np.diff(K.indptr))]
    cols = node[K.indices // 2]
    on = (rows >= 0) & (cols >= 0) & (rows != cols)
    g = sp.csr_matrix((np.ones(int(on.sum()), dtype=np.int8), (rows[on], cols[on])), shape=(n // 2, n // 2))
    g.sum_duplicates()  # canonical: sorted, one entry per neighbour
    perm = np.asarray(pymetis.nested_dissection(pymetis.CSRAdjacency(g.indptr, g.indices))[0])
    return np.column_stack([2 * perm, 2 * perm + 1]).ravel()


def interior_order(Kii) -> np.ndarray:
    """Fill-reducing order (positions, new -> old) of a block K_II whose dofs come in
    (x, y) pairs of whole nodes (2 k, 2 k + 1): :func:`node_graph_order` of all its dofs."""
    n = Kii.shape[0]
    if n % 2:
        raise RuntimeError("the interior dofs do not come in (x, y) pairs")
    return node_graph_order(Kii, np.arange(n))


def mirror_lower(A: np.ndarray, block: int = 256) -> np.ndarray:
    """A (m, m) C-ordered made symmetric in place from its upper triangle (A[i, j] = A[j, i]
    for i > j), in square blocks (a whole transposed copy of a 37 MB matrix costs
    several times more on this machine's memory than block copies that stay in cache)."""
    m = A.shape[0]
    for i in range(0, m, block):
        ie = min(i + block, m)
        d = A[i:ie, i:ie]
        lo = np.tril_indices(ie - i, -1)
        d[lo] = d.T[lo]
        for j in range(ie, m, block):
            je = min(j + block, m)
            A[j:je, i:ie] = A[i:ie, j:je].T
    return A


def _border(lu, o: int, in_place: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool]:
    """(i, j, v, d, in_place): the border L_BI of the arrowhead factorization
    (:func:`condensed_flexibility`), L[o + i, j] = v for j < o, and the pivots d = diag U,
    read in place (fem.superlu_store; in_place True), or through scipy's conversion of the
    whole factors when that store is not available or ``in_place`` is False."""
    store = supernodal_store(lu) if in_place else None
    if store is not None:
        return (*border_rows(store, o), store.pivots(), True)
    L = lu.L[o:, :o].tocoo()
    return L.row, L.col, L.data, lu.U.diagonal(), False


def schur_from_border(Kbb, i, j, v, d, dense_from: int = DENSE_COLUMN_ROWS) -> np.ndarray:
    """S = K_BB - L_BI D L_BI^T (m, m), C-ordered, both triangles, from K_BB (sparse), the
    border entries L_BI[i, j] = v and the pivots d (D = diag d over the columns j). Columns
    of L_BI with ``dense_from`` or more rows (the separators high in the elimination tree,
    where the contributions are dense) go through one BLAS rank-k update (dsyrk), the
    others through a sparse product: the multiply count is sum over columns of (rows of
    the column)^2 either way (1.1e9 for the paper pinion) without a dense product over all
    14k columns."""
    m = Kbb.shape[0]
    x = v * np.sqrt(d[j])
    count = np.bincount(j)
    dc = np.flatnonzero(count >= dense_from)
    dense = count[j] >= dense_from
    where = np.full(len(count), -1)
    where[dc] = np.arange(len(dc))
    Y = np.zeros((len(dc), m))  # rows: the dense columns of L_BI D^1/2
    Y[where[j[dense]], i[dense]] = x[dense]
    Xs = sp.csr_matrix((x[~dense], (i[~dense], j[~dense])), shape=(m, len(count)))
    S = (sp.csr_matrix(Kbb) - Xs @ Xs.T).toarray()
    with one_blas_thread():
        # in place on S's Fortran view: its lower triangle (S's upper one) -= Y^T Y
        sla.blas.dsyrk(-1.0, Y.T, beta=1.0, c=S.T, lower=1, overwrite_c=1)
    return mirror_lower(S)


def _inverse(S: np.ndarray) -> np.ndarray:
    """G = S^-1 (m, m) C-ordered, exactly symmetric, of the symmetric positive definite S
    (overwritten): LAPACK dpotrf and dpotri in place on its Fortran view."""
    # one BLAS thread: OpenBLAS's threaded dpotri (dtrtri + dlauum) took 6.2 s against
    # 0.39 s on one thread for m = 2142 on the 2-core machine (best of 3 each), and the
    # thread count sets dpotrf's rounding; held for overlapping bodies (fem.process_settings)
    with one_blas_thread():
        C, info = sla.lapack.dpotrf(S.T, lower=1, overwrite_a=1, clean=0)
        if info != 0:
            raise RuntimeError(f"the Schur complement of the condensed dofs is not positive definite (dpotrf {info})")
        Gl, info = sla.lapack.dpotri(C, lower=1, overwrite_c=1)
    if info != 0:
        raise RuntimeError(f"LAPACK dpotri failed (info {info})")
    # Gl's lower triangle (Fortran) is the upper one of its C-ordered transpose
    return mirror_lower(np.ascontiguousarray(Gl.T))


def condensed_flexibility(
    model, xdofs: np.ndarray, reading: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray | None, dict]:
    """(G, h, timings): G = (K^-1)_BB for B = the x and y dofs of ``xdofs`` (order x0, y0,
    x1, y1, ...) of the ElasticModel ``model`` (fem.elasticity, K and its free dofs), and
    the rows h = (K^-1 a)_B for the reading functionals a = ``reading`` (rows over all
    dofs; None: h is None). By reciprocity (K symmetric) a . U = a . K^-1 f = h . f_B for
    any load f on B: one more solve per functional with the factors, none per load.

    The free dofs ordered interior I first (:func:`node_graph_order`) and B last, SuperLU
    factorizes the arrowhead M = [[K_II, 0], [K_BI, I]] without pivoting (K is SPD): its
    factors are L = [[L_II, 0], [L_BI, I]], U = [[D L_II^T, 0], [0, I]] with
    L_BI = K_BI L_II^-T D^-1, so the Schur complement is

        S = K_BB - K_BI K_II^-1 K_IB = K_BB - L_BI D L_BI^T      (:func:`schur_from_border`)

    and G = S^-1 by LAPACK dpotrf + dpotri. Why the arrowhead: with K itself (B last and
    coupled) SuperLU also factorizes the dense m x m trailing block with its column panels,
    which took 0.75 of its 1.1 s CPU for the paper pinion (m = 2142); M's factorization costs
    0.36 s, the border's product 0.2 s and the dense Cholesky and inversion 0.3 s. The same
    factors solve M y = [a_I; a_B], y_B = a_B - K_BI K_II^-1 a_I, so h = G y_B; and for a
    random v on B the solve with [K_IB v; K_BB v] gives S v, which checks S (to CHECK_RTOL)
    against SuperLU's own solve."""
    t0 = time.perf_counter()
    B = np.column_stack([xdofs, xdofs + 1]).ravel()
    pos = np.full(model.ndofs, -1)
    pos[model.free] = np.arange(len(model.free))
    Bf = pos[B]
    if np.any(Bf < 0):
        raise RuntimeError("a condensed flank dof is fixed")
    isB = np.zeros(model.ndofs, dtype=bool)
    isB[B] = True
    isB[model.fixed] = True
    # B's (x, y) pairs are whole nodes, and so are the fixed dofs: the interior's are too
    interior_dofs = np.flatnonzero(~isB)
    interior = pos[interior_dofs]
    # fill-reducing order of the interior (nested dissection), then the condensed dofs
    # last, and no further reordering
    order = np.concatenate([interior[node_graph_order(model.K, interior_dofs)], Bf])
    dofs = model.free[order]
    Kp = model.K[dofs][:, dofs].tocsc()
    n, m = Kp.shape[0], len(Bf)
    o = n - m
    # M: K's first o columns (K_II over K_BI), then the identity on B
    e = int(Kp.indptr[o])
    M = sp.csc_matrix(
        (
            np.concatenate([Kp.data[:e], np.ones(m)]),
            np.concatenate([Kp.indices[:e], np.arange(o, n, dtype=Kp.indices.dtype)]),
            np.concatenate([Kp.indptr[: o + 1], e + np.arange(1, m + 1, dtype=Kp.indptr.dtype)]),
        ),
        shape=(n, n),
    )
    t1 = time.perf_counter()
    lu = spla.splu(M, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    if not (np.array_equal(lu.perm_r, np.arange(n)) and np.array_equal(lu.perm_c, np.arange(n))):
        raise RuntimeError("SuperLU reordered the condensed system; the border is not L_BI")
    t2 = time.perf_counter()
    # right-hand sides of M: the reading functionals [a_I; a_B], the check [K_IB r; K_BB r]
    r = np.random.default_rng(_CHECK_SEED).standard_normal(m)
    rhs = np.zeros((n, (0 if reading is None else len(reading)) + 1))
    if reading is not None:
        rhs[:, :-1] = reading[:, dofs].T
    rhs[:, -1] = Kp[:, o:] @ r
    y = lu.solve(rhs)[o:]
    for in_place in (True, False):
        # the in-place read first; if its S disagrees with the solve (a scipy whose private
        # layout passed fem.superlu_store's checks and still differs), scipy's public
        # conversion of the factors decides
        i, j, v, d, in_place = _border(lu, o, in_place)
        positive = bool(np.all(d[:o] > 0))
        err = math.inf
        if positive:
            S = schur_from_border(Kp[o:, o:], i, j, v, d)
            err = float(np.linalg.norm(S @ r - y[:, -1]) / np.linalg.norm(y[:, -1]))
        if err <= CHECK_RTOL or not in_place:
            break
    if not positive:
        raise RuntimeError("the interior stiffness is not positive definite")
    if not err <= CHECK_RTOL:
        raise RuntimeError(f"the Schur complement of the condensed dofs does not match a solve ({err:.1e} relative)")
    G = _inverse(S)
    # h = G y_B by numpy's own loops, not BLAS: the thread count of a threaded BLAS product
    # sets its summation order, and threadpool_limits is process-wide, so two bodies
    # condensed at once (fem.pair_model overlaps them) could set it for each other and h
    # differed from the serial build in its last bits (~20 ms for the paper pinion)
    h = np.einsum("ij,jk->ki", G, y[:, :-1], optimize=False) if reading is not None else None
    t3 = time.perf_counter()
    return (
        G,
        h,
        {
            "ordering_s": t1 - t0,
            "factorize_s": t2 - t1,
            "flexibility_s": t3 - t2,
            "condensed_dofs": m,
            "factor_nnz": int(lu.nnz),
            "factor_read_in_place": int(in_place),
        },
    )
