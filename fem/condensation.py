"""Static condensation of a stiffness matrix onto a set of dofs B: the flexibility
G = (K^-1)_BB = S^-1 of the Schur complement S = K_BB - K_BI K_II^-1 K_IB (m/N), and the
readings h = (K^-1 a)_B of given functionals, from one sparse factorization (SI units).

The free dofs are ordered interior first (METIS nested dissection of the node graph,
:func:`interior_order`) and B last, and factorized by SuperLU without pivoting (K is
symmetric positive definite). The trailing blocks of the factors are then the Schur
complement, S = L_BB U_BB = L_BB D L_BB^T, so G follows from one dense Cholesky inversion
(LAPACK dpotri) of C = L_BB D^1/2. L_BB is read from SuperLU's supernodal store in place
(fem.superlu_trailing: no conversion of the whole factors, which costs as much as the
factorization); one solve with the same factors checks G on a random load on B.
"""

from __future__ import annotations

import time

import numpy as np
import pymetis
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

from .superlu_trailing import trailing_block

__all__ = ["condensed_flexibility", "interior_order", "node_graph_order", "mirror_lower"]

CHECK_RTOL = 1e-8  # G r against the solve K^-1 r on B (round-off is ~1e-13 on the gear bodies)
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


def _converted_block(lu, m: int) -> tuple[np.ndarray, np.ndarray]:
    """(T, d) as fem.superlu_trailing.trailing_block, from scipy's conversion of the whole
    factors (``lu.L``, ``lu.U``): the fallback when the in-place read is not available."""
    L, U = lu.L, lu.U
    n = L.shape[0]
    ip = L.indptr[n - m :]
    s = int(ip[0])
    T = np.zeros((m, m))
    # column j of L_BB is row j of T
    T[np.repeat(np.arange(m), np.diff(ip)), L.indices[s:] - (n - m)] = L.data[s:]
    return T, U.diagonal()[n - m :]


def _inverse_from_factor(T: np.ndarray, d: np.ndarray) -> np.ndarray:
    """G = S^-1 (m, m) C-ordered, exactly symmetric, from T and the pivots d
    (fem.superlu_trailing.trailing_block), S = L_BB D L_BB^T = C C^T, C = L_BB D^1/2.
    T is overwritten (it becomes G)."""
    if not np.all(d > 0):
        raise RuntimeError("the Schur complement of the condensed dofs is not positive definite")
    s = np.sqrt(d)
    T *= s[:, None]  # row j of T is column j of L_BB: times sqrt(d_j)
    T[np.diag_indices(len(d))] = s  # L's unit diagonal
    C = T.T  # Fortran order: LAPACK works in place, its lower triangle is C
    # one BLAS thread: OpenBLAS's threaded dpotri (dtrtri + dlauum) took 6.2 s against
    # 0.39 s on one thread for m = 2142 on the 2-core machine (best of 3 each)
    with threadpool_limits(1, user_api="blas"):
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

    With B ordered last and no pivoting (K is SPD), the trailing blocks of SuperLU's
    factors give the Schur complement S = L_BB U_BB with U_BB = D L_BB^T (D = diag U_BB,
    the LDL^T form of a symmetric factorization), so S = C C^T with the Cholesky factor
    C = L_BB D^1/2 and G = S^-1 = C^-T C^-1 (LAPACK dpotri: 2/3 m^3 flops, against 2 m^3
    for two triangular solves with the identity). The same solve as h checks G: for a
    random load r on B, G r = (K^-1 r)_B to CHECK_RTOL (else the factors are read again
    through scipy's conversion, and a second mismatch is an error)."""
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
    t1 = time.perf_counter()
    opts = dict(diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    lu = spla.splu(Kp, permc_spec="NATURAL", **opts)
    n = len(order)
    if not (np.array_equal(lu.perm_r, np.arange(n)) and np.array_equal(lu.perm_c, np.arange(n))):
        raise RuntimeError("SuperLU reordered the condensed system; the Schur block is not trailing")
    t2 = time.perf_counter()
    m = len(Bf)
    # the right-hand sides: the reading functionals and the check's random load on B
    # (the permuted system solves P K P^T (P x) = P a; B is the trailing block)
    rhs = np.zeros((n, (0 if reading is None else len(reading)) + 1))
    if reading is not None:
        rhs[:, :-1] = reading[:, model.free][:, order].T
    r = np.random.default_rng(_CHECK_SEED).standard_normal(m)
    rhs[n - m :, -1] = r
    x = lu.solve(rhs)[n - m :]
    read = trailing_block(lu, m)
    for attempt in ("in place", "converted"):
        G = _inverse_from_factor(*(read if read is not None else _converted_block(lu, m)))
        err = np.linalg.norm(G @ r - x[:, -1]) / np.linalg.norm(x[:, -1])
        if err <= CHECK_RTOL:
            break
        if attempt == "converted":
            raise RuntimeError(f"the condensed flexibility does not match a solve ({err:.1e} relative)")
        read = None
    h = x[:, :-1].T.copy() if reading is not None else None
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
            "factor_converted": int(read is None),
        },
    )
