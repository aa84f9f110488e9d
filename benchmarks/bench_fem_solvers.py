"""Sparse solvers for the condensation of a pair-FE body (fem.pair_body), measured.

What the 24-position cycle needs from the solver, per body: the condensed flexibility
G = (K^-1)_BB of the m condensed dofs B (drive flanks and tooth 0's centre line; m = 2142
for the paper pinion of 116k dofs) and the blank reading h = (K^-1 a)_B for its 3
functionals a. Every position then works on G and h only (no further sparse solve).

On the real system of the paper pair's body (K_ff, B and a exactly as fem.pair_body builds
them), each candidate that installs here as a wheel computes (G, h); the table gives its
wall time (ordering + factorization + the solves or the Schur complement for G and h, best
of RUNS, the direct candidates run in turns) and its accuracy max |G - G_ref| / max |G_ref|
(and the same for h) against the current solver (fem.condensation.condensed_flexibility:
SuperLU of the arrowhead [[K_II, 0], [K_BI, I]], S from the border L_BI read in place):

* scipy SuperLU: the current solver (the arrowhead, interior in METIS nested dissection of
  the node graph, pymetis); K with B last and G from the trailing factor blocks of scipy's
  converted factors (the solver before issue 27's arrowhead) with the interior ordered by
  the same METIS node graph, by SuperLU's MMD (the order before METIS), by COLAMD, or by
  METIS on the dof graph;
* scipy SuperLU of K_ff (minimum degree) and m + 3 solves with the identity columns of B
  (the plain way, without the Schur complement);
* CHOLMOD through cholespy (supernodal Cholesky, its own ordering): factorization and the
  m + 3 right-hand sides (cholespy exposes no factor, so no Schur complement);
* MKL PARDISO through pypardiso: factorization (SPD, upper triangle) and the m + 3
  right-hand sides; and PARDISO's own Schur complement (iparm 36) of the bordered matrix
  [[K, a^T], [a, I]] over B and the 3 border rows, through the same MKL library (pypardiso
  has no Schur call: MKL's pardiso through ctypes here);
* QDLDL (simplicial LDL^T, AMD) and pyamg (smoothed aggregation as the preconditioner of
  scipy's CG, rtol 1e-12);
* the candidates that need one solve (or one CG run) per column of B (SuperLU without the
  Schur complement, cholespy, PARDISO's plain solve, QDLDL, pyamg) are timed on a block of
  columns and extrapolated to m + 3 ("extrapolated" in the JSON, * in the table): the
  whole m + 3 columns at once take n (m + 3) doubles twice (3 GB) and were stopped at 14 GB;
* not installable as wheels here: scikit-sparse (CHOLMOD; an sdist that needs the
  SuiteSparse headers and libraries from system packages) and python-mumps (its only wheel
  for this Python, 0.0.2, is built against numpy 1 and fails to import under numpy 2).

Results: benchmarks/results/bench_fem_solvers.json. Timings are printed, never asserted.
The machine is shared (2 cores): every candidate runs RUNS times in one process, the
minimum counts (the extrapolated ones run once).
"""

from __future__ import annotations

import ctypes
import importlib.util
import json
import math
import platform
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import scipy
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

from gearwear.fem.pair_body import _condensed_flexibility, _interior_order, blank_reading
from gearwear.fem.pair_model import _BODY_CACHE, pair_model
from gearwear.geometry.spec import default_pair

RUNS = 3
BLOCK = 128  # right-hand sides timed for the per-column solvers (extrapolated to m + 3)
OUT = Path(__file__).resolve().parent / "results" / "bench_fem_solvers.json"


def system():
    """(K_ff csc, positions of B in K_ff, reading rows over the free dofs (3, n), G_ref,
    h_ref, the body's model and B's x dofs) of the paper pair's body."""
    _BODY_CACHE.clear()
    pm = pair_model(default_pair())
    body = pm.bodies[0]
    model = body.model
    pos = np.full(model.ndofs, -1)
    pos[model.free] = np.arange(len(model.free))
    Bf = pos[body.dofs]
    Kff = model.K[model.free][:, model.free].tocsc()
    _, a = blank_reading(model, body.gear)
    a_free = np.asarray(a.toarray() if sp.issparse(a) else a)[:, model.free]
    return Kff, Bf, a_free, body.G, body.blank_h, model, body.dofs[0::2]


def best(fn, runs):
    """(last result, minimum wall time s)."""
    out, ts = None, []
    for _ in range(runs):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return out, min(ts)


def rhs_identity(n, Bf, a_free):
    """The m + 3 right-hand sides: the identity columns of B, then the readings."""
    E = np.zeros((n, len(Bf) + a_free.shape[0]))
    E[Bf, np.arange(len(Bf))] = 1.0
    E[:, len(Bf) :] = a_free.T
    return E


# --- scipy SuperLU ----------------------------------------------------------------------


def superlu_current(model, xd, a):
    G, h, _ = _condensed_flexibility(model, xd, a)
    return G, h


def superlu_schur_with(interior_order):
    """SuperLU with B last and the interior in ``interior_order(K_II)`` (positions),
    G from the trailing blocks as in fem.pair_body."""

    def run(Kff, Bf, a_free):
        n, m = Kff.shape[0], len(Bf)
        isB = np.zeros(n, dtype=bool)
        isB[Bf] = True
        interior = np.flatnonzero(~isB)
        oi = interior_order(Kff[interior][:, interior].tocsc())
        order = np.concatenate([interior[oi], Bf])
        lu = spla.splu(
            Kff[order][:, order].tocsc(),
            permc_spec="NATURAL",
            diag_pivot_thresh=0.0,
            options={"SymmetricMode": True},
        )
        L, U = lu.L, lu.U
        ip = L.indptr[n - m :]
        s = int(ip[0])
        Lbb = np.zeros((m, m))
        Lbb[L.indices[s:] - (n - m), np.repeat(np.arange(m), np.diff(ip))] = L.data[s:]
        C = Lbb * np.sqrt(U.diagonal()[n - m :])
        with threadpool_limits(1, user_api="blas"):
            Gl = scipy.linalg.lapack.dpotri(C, lower=1, overwrite_c=1)[0]
        G = np.tril(Gl) + np.tril(Gl, -1).T
        h = lu.solve(np.ascontiguousarray(a_free[:, order].T))[n - m :].T
        return G, h, int(L.nnz + U.nnz)

    return run


def mmd_order(Kii):
    """SuperLU's own MMD on K_II + K_II^T (the order before fem.pair_body used METIS), taken
    from an ILU that drops every entry (same perm_c as splu, no numerical factorization)."""
    lu = spla.spilu(
        Kii,
        permc_spec="MMD_AT_PLUS_A",
        drop_tol=np.inf,
        fill_factor=1.0,
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    return np.argsort(lu.perm_c)


def colamd_order(Kii):
    lu = spla.spilu(Kii, permc_spec="COLAMD", drop_tol=np.inf, fill_factor=1.0, diag_pivot_thresh=0.0)
    return np.argsort(lu.perm_c)


def metis_dof_order(Kii):
    """METIS nested dissection (pymetis) of the dof graph of K_II (perm: new -> old);
    fem.pair_body orders the node graph instead."""
    import pymetis

    n = Kii.shape[0]
    A = sp.csr_matrix((np.ones(Kii.nnz), Kii.indices, Kii.indptr), shape=Kii.shape)
    A = ((A + A.T) > 0).astype(np.int8).tocsr()
    A.setdiag(0)
    A.eliminate_zeros()
    perm, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(A.indptr, A.indices))
    return np.asarray(perm)[:n]


def superlu_plain(Kff, Bf, a_free, ncols=None):
    lu = spla.splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    E = rhs_identity(Kff.shape[0], Bf, a_free)
    return lu.solve(E[:, :ncols] if ncols else E)


# --- CHOLMOD (cholespy), PARDISO (pypardiso / MKL), QDLDL, pyamg ------------------------


def block_columns(m, k=BLOCK):
    """k columns spread over B (the timed block of the per-column solvers)."""
    return list(range(0, m, max(1, m // k)))[:k]


def cholespy_block(Kff, Bf, a_free):
    """(X of the block, its columns, factorization time)."""
    from cholespy import CholeskySolverD, MatrixType

    t = time.perf_counter()
    C = Kff.tocoo()
    solver = CholeskySolverD(
        Kff.shape[0], C.row.astype(np.int32), C.col.astype(np.int32), C.data.astype(np.float64), MatrixType.COO
    )
    setup = time.perf_counter() - t
    cols = block_columns(len(Bf))
    E = np.ascontiguousarray(rhs_identity(Kff.shape[0], Bf, a_free)[:, cols])
    X = np.zeros_like(E)
    solver.solve(E, X)
    return X, cols, setup


def pardiso_block(Kff, Bf, a_free):
    """(X of the block, its columns, factorization time)."""
    import pypardiso

    t = time.perf_counter()
    s = pypardiso.PyPardisoSolver(mtype=2)  # real symmetric positive definite
    A = sp.triu(Kff, format="csr")
    A.sort_indices()
    s.factorize(A)
    setup = time.perf_counter() - t
    cols = block_columns(len(Bf))
    X = s.solve(A, rhs_identity(Kff.shape[0], Bf, a_free)[:, cols])
    s.free_memory(everything=True)
    return X, cols, setup


def pardiso_schur(Kff, Bf, a_free):
    """PARDISO's Schur complement (iparm 36 = 1) of the bordered matrix
    [[K, a^T], [a, I]] over B and the 3 border rows: [[S, y], [y^T, .]] with
    S = K_BB - K_BI K_II^-1 K_IB and y = a_B^T - K_BI K_II^-1 a_I^T; then G = S^-1,
    h = (G y)^T (real symmetric, mtype -2)."""
    import pypardiso

    # a handle of its own: pypardiso sets argtypes on its handle's pardiso
    lib = ctypes.CDLL(pypardiso.PyPardisoSolver().libmkl._name)
    n, m, r = Kff.shape[0], len(Bf), a_free.shape[0]
    # the border's own block does not enter S or y (the Schur rows are not eliminated):
    # the identity keeps PARDISO's required diagonal entries
    Ka = sp.bmat([[Kff, sp.csr_matrix(a_free.T)], [sp.csr_matrix(a_free), sp.identity(r)]], format="csr")
    Ka = sp.triu(Ka, format="csr")
    Ka.sort_indices()
    N = n + r
    schur = np.concatenate([Bf, n + np.arange(r)])
    perm = np.zeros(N, dtype=np.int32)
    perm[schur] = 1
    iparm = np.zeros(64, dtype=np.int32)
    iparm[0] = 1  # non-default iparm
    iparm[1] = 2  # METIS ordering
    iparm[34] = 1  # zero-based ia, ja
    iparm[35] = 1  # Schur complement, returned in x (dense, row-major)
    iparm[9] = 8  # pivot perturbation 1e-8 (MKL's default for symmetric indefinite)
    pt = np.zeros(64, dtype=np.int64)
    ia, ja = Ka.indptr.astype(np.int32), Ka.indices.astype(np.int32)
    data = Ka.data.astype(np.float64)
    ms = len(schur)
    x = np.zeros(ms * ms)
    b = np.zeros(max(N, ms * ms))
    err = ctypes.c_int32(0)
    i32 = ctypes.c_int32

    def call(phase):
        lib.pardiso(
            pt.ctypes.data_as(ctypes.c_void_p),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(-2)),
            ctypes.byref(i32(phase)),
            ctypes.byref(i32(N)),
            data.ctypes.data_as(ctypes.c_void_p),
            ia.ctypes.data_as(ctypes.c_void_p),
            ja.ctypes.data_as(ctypes.c_void_p),
            perm.ctypes.data_as(ctypes.c_void_p),
            ctypes.byref(i32(1)),
            iparm.ctypes.data_as(ctypes.c_void_p),
            ctypes.byref(i32(0)),
            b.ctypes.data_as(ctypes.c_void_p),
            x.ctypes.data_as(ctypes.c_void_p),
            ctypes.byref(err),
        )
        if err.value != 0:
            raise RuntimeError(f"PARDISO error {err.value} in phase {phase}")

    call(12)
    Sa = x.reshape(ms, ms)
    Sa = np.triu(Sa) + np.triu(Sa, 1).T if not np.allclose(Sa, Sa.T) else Sa
    S, y = Sa[:m, :m], Sa[:m, m:]
    call(-1)  # release PARDISO's memory
    c, low = scipy.linalg.cho_factor(S, lower=True)
    G = scipy.linalg.cho_solve((c, low), np.eye(m))
    return 0.5 * (G + G.T), (G @ y).T


def qdldl_block(Kff, Bf, a_free):
    import qdldl

    s = qdldl.Solver(sp.triu(Kff, format="csc"), upper=True)
    E = rhs_identity(Kff.shape[0], Bf, a_free)
    return s, E


def rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def main():
    t0 = time.perf_counter()
    Kff, Bf, a_free, G_ref, h_ref, model, xd = system()
    n, m = Kff.shape[0], len(Bf)
    a_full = np.zeros((a_free.shape[0], model.ndofs))
    a_full[:, model.free] = a_free
    print(
        f"paper pair body: {n} free dofs, m = {m} condensed, nnz(K_ff) = {Kff.nnz} "
        f"(built in {time.perf_counter() - t0:.1f} s)"
    )
    rows = []

    def add(name, fn, how, extrapolate_cols=None, note="", runs=RUNS, timed=None):
        try:
            if isinstance(timed, Exception):
                raise timed
            out, wall = timed if timed is not None else best(fn, runs)
        except Exception as exc:  # noqa: BLE001 - a candidate that fails is a result
            rows.append({"solver": name, "how": how, "status": f"failed: {type(exc).__name__}: {exc}"[:300]})
            print(f"  {name:<46} failed: {exc}")
            return
        extra = {}
        if extrapolate_cols is not None:
            X, cols, setup = out
            Gc = X[Bf][:, [c for c in cols if c < m]] if len(cols) else None
            acc_G = rel(Gc, G_ref[:, [c for c in cols if c < m]]) if Gc is not None else float("nan")
            per_col = (wall - setup) / len(cols)
            wall_est = setup + per_col * (m + a_free.shape[0])
            extra = {"timed_columns": len(cols), "setup_s": setup, "per_column_s": per_col, "extrapolated": True}
            row = {"solver": name, "how": how, "wall_s": wall_est, "acc_G": acc_G, "acc_h": None, **extra}
        else:
            G, h = out[:2]
            row = {"solver": name, "how": how, "wall_s": wall, "acc_G": rel(G, G_ref), "acc_h": rel(h, h_ref)}
            if len(out) > 2:
                row["factor_nnz"] = out[2]
        if note:
            row["note"] = note
        row["status"] = "ok"
        rows.append(row)
        acc_h = "" if row["acc_h"] is None else f"{row['acc_h']:.1e}"
        print(f"  {name:<46}{row['wall_s']:>9.2f}{'*' if extra else ' '}  G {row['acc_G']:.1e}  h {acc_h:<8} {how}")

    print(f"  {'solver':<46}{'wall (s)':>9}   accuracy vs current (max rel)")
    # the direct candidates (G and h whole) in turns, RUNS rounds: each sees the same load
    direct = [
        (
            "scipy SuperLU arrowhead, METIS node graph (current)",
            lambda: superlu_current(model, xd, a_full),
            "fem.condensation: S = K_BB - L_BI D L_BI^T from the border read in place",
        )
    ]
    variants = (
        ("METIS node graph (trailing blocks, before)", _interior_order),
        ("MMD", mmd_order),
        ("COLAMD", colamd_order),
        ("METIS dof graph", metis_dof_order),
    )
    for label, order in variants:
        direct.append(
            (
                f"scipy SuperLU, B last, {label}",
                lambda o=order: superlu_schur_with(o)(Kff, Bf, a_free),
                "interior order " + label,
            )
        )
    if importlib.util.find_spec("pypardiso"):
        direct.append(
            (
                "MKL PARDISO Schur complement (iparm 36)",
                lambda: pardiso_schur(Kff, Bf, a_free),
                "bordered matrix, METIS, Schur over B + 3",
            )
        )
    timed: dict = {}
    for _ in range(RUNS):
        for name, fn, _how in direct:
            if isinstance(timed.get(name), Exception):
                continue
            try:
                out, wall = best(fn, 1)
            except Exception as exc:  # noqa: BLE001 - recorded by add()
                timed[name] = exc
                continue
            timed[name] = (out, min(wall, timed[name][1])) if name in timed else (out, wall)
    for name, fn, how in direct:
        add(name, fn, how, timed=timed[name])

    def plain_block():
        cols = block_columns(m, 16)
        t = time.perf_counter()
        lu = spla.splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        setup = time.perf_counter() - t
        E = rhs_identity(n, Bf, a_free)
        return lu.solve(np.ascontiguousarray(E[:, cols])), cols, setup

    def reindex(fn):
        # per-column solvers return X for the chosen columns; map to the full column ids
        def run():
            X, cols, setup = fn()
            Xf = np.zeros((n, m + a_free.shape[0]))
            Xf[:, cols] = X
            return Xf, cols, setup

        return run

    add(
        "scipy SuperLU of K_ff, m + 3 solves",
        reindex(plain_block),
        "factorize, solve identity columns",
        extrapolate_cols=True,
        runs=1,
    )
    if importlib.util.find_spec("cholespy"):
        add(
            "CHOLMOD (cholespy), m + 3 solves",
            reindex(lambda: cholespy_block(Kff, Bf, a_free)),
            "factorize, solve identity columns",
            extrapolate_cols=True,
            runs=1,
        )
    else:
        rows.append({"solver": "CHOLMOD (cholespy)", "status": "not installed"})
    if importlib.util.find_spec("pypardiso"):
        add(
            "MKL PARDISO (pypardiso), m + 3 solves",
            reindex(lambda: pardiso_block(Kff, Bf, a_free)),
            "SPD factorize, solve identity columns",
            extrapolate_cols=True,
            runs=1,
        )
    else:
        rows.append({"solver": "MKL PARDISO (pypardiso)", "status": "not installed"})
    if importlib.util.find_spec("qdldl"):

        def q():
            cols = block_columns(m, 32)
            t = time.perf_counter()
            s, E = qdldl_block(Kff, Bf, a_free)
            setup = time.perf_counter() - t
            X = np.column_stack([s.solve(E[:, c]) for c in cols])
            return X, cols, setup

        add(
            "QDLDL (simplicial LDL^T, AMD), per column",
            reindex(q),
            "factorize, one solve per column",
            extrapolate_cols=True,
            runs=1,
        )
    if importlib.util.find_spec("pyamg"):

        def amg():
            cols = block_columns(m, 4)
            t = time.perf_counter()
            import pyamg

            # near-null space: the plane rigid motions (1, 0), (0, 1), (-y, x) at each free dof
            xy = model.basis.doflocs[:, model.free]
            isx = (model.free % 2) == 0  # ElementVector: x dof 2 k, y dof 2 k + 1
            rigid = np.column_stack([isx, ~isx, np.where(isx, -xy[1], xy[0])]).astype(float)
            ml = pyamg.smoothed_aggregation_solver(Kff.tocsr(), B=rigid, symmetry="symmetric", max_coarse=500)
            setup = time.perf_counter() - t
            M = ml.aspreconditioner(cycle="V")
            E = rhs_identity(n, Bf, a_free)
            X = np.column_stack([spla.cg(Kff, E[:, c], rtol=1e-12, atol=0.0, M=M, maxiter=2000)[0] for c in cols])
            return X, cols, setup

        add(
            "pyamg SA-preconditioned CG (rtol 1e-12), per column",
            reindex(amg),
            "one CG run per column",
            extrapolate_cols=True,
            runs=1,
        )
    rows += [
        {
            "solver": "CHOLMOD (scikit-sparse)",
            "status": "does not install: no wheel (sdist needs SuiteSparse system packages)",
        },
        {
            "solver": "MUMPS (python-mumps)",
            "status": "does not work: the only cp311 wheel (0.0.2) is built against numpy 1 (ImportError, numpy 2)",
        },
    ]
    doc = {
        "benchmark": "bench_fem_solvers",
        "created_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "scipy": scipy.__version__,
        "system": {
            "pair": "paper 30/30, 40 N m, plane stress, P2",
            "free_dofs": int(n),
            "condensed_dofs": int(m),
            "nnz_K": int(Kff.nnz),
        },
        "runs": RUNS,
        "timing": "minimum of RUNS in one process; extrapolated: from a block of columns; shared 2-core machine",
        "rows": rows,
    }
    for row in rows:  # JSON has no NaN
        row.update({k: None for k, v in row.items() if isinstance(v, float) and not math.isfinite(v)})
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"  * extrapolated to m + 3 = {m + 3} columns from a timed block; results -> {OUT}")


if __name__ == "__main__":
    main()
