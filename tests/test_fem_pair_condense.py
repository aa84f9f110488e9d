"""The static condensation of the pair bodies (fem.pair_body) against dense linear algebra.

On a small plane-stress P2 model (a unit square held on one side) the condensed
flexibility G = (K^-1)_BB of a set of boundary dofs and the reading h = (K^-1 a)_B must
equal the dense inverse of the free stiffness matrix; the interior order (nested
dissection) must be a permutation that keeps each node's dofs together."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
import skfem

from gearwear.fem.elasticity import assemble
from gearwear.fem.pair_body import _condensed_flexibility, _interior_order
from gearwear.geometry.spec import Material


@pytest.fixture(scope="module")
def model():
    mesh = skfem.MeshTri.init_sqsymmetric().refined(3)
    left = mesh.facets_satisfying(lambda x: np.isclose(x[0], 0.0))
    steel = Material(youngs_modulus_Pa=206e9, poisson_ratio=0.3, density_kg_per_m3=7850.0)
    return assemble(mesh, steel, 0.02, left, plane="stress", order=2, factorize=False)


def _dense_inverse(model) -> np.ndarray:
    """K^-1 over all dofs, zero on the fixed ones (numpy's dense inverse of K_ff)."""
    Kff = model.K[model.free][:, model.free].toarray()
    inv = np.zeros((model.ndofs, model.ndofs))
    inv[np.ix_(model.free, model.free)] = np.linalg.inv(Kff)
    return inv


def test_interior_order_keeps_nodes_whole_and_reduces_fill(model):
    Kff = model.K[model.free][:, model.free].tocsc()
    order = _interior_order(Kff)
    n = Kff.shape[0]
    assert np.array_equal(np.sort(order), np.arange(n))  # a permutation
    assert np.array_equal(order[0::2] + 1, order[1::2]) and np.all(order[0::2] % 2 == 0)  # (x, y) pairs
    assert np.array_equal(order, _interior_order(Kff))  # deterministic
    opts = dict(diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    natural = spla.splu(Kff, permc_spec="NATURAL", **opts)
    nd = spla.splu(Kff[order][:, order].tocsc(), permc_spec="NATURAL", **opts)
    assert nd.nnz < natural.nnz


def test_condensed_flexibility_equals_the_dense_inverse(model):
    right = model.mesh.facets_satisfying(lambda x: np.isclose(x[0], 1.0))
    top = model.mesh.facets_satisfying(lambda x: np.isclose(x[1], 1.0))
    # x dofs of the vertices and mid-side nodes on the right and top sides (y dof = x dof + 1)
    xd = np.unique(model.basis.get_dofs(facets=np.concatenate([right, top])).all("u^1"))
    xd = xd[model.basis.doflocs[0, xd] > 0.0]  # the corner (0, 1) is held
    rng = np.random.default_rng(7)
    a = rng.standard_normal((3, model.ndofs))
    G, h, tim = _condensed_flexibility(model, xd, a)
    inv = _dense_inverse(model)
    B = np.column_stack([xd, xd + 1]).ravel()
    G_ref = inv[np.ix_(B, B)]
    h_ref = (inv @ a.T)[B].T
    assert tim["condensed_dofs"] == len(B)
    assert np.array_equal(G, G.T)
    assert np.max(np.abs(G - G_ref)) <= 1e-10 * np.max(np.abs(G_ref))
    assert np.max(np.abs(h - h_ref)) <= 1e-10 * np.max(np.abs(h_ref))


def _arrowhead(model, n_b: int):
    """(M, Kp, o): the free stiffness with its last n_b dofs as B, and the arrowhead
    [[K_II, 0], [K_BI, I]] of fem.condensation (Kp's first o columns, then I)."""
    import scipy.sparse as sp

    Kp = model.K[model.free][:, model.free].tocsc()
    n = Kp.shape[0]
    o = n - n_b
    M = sp.bmat([[Kp[:o, :o], None], [Kp[o:, :o], sp.identity(n_b)]]).tocsc()
    return M, Kp, o


def test_border_read_in_place_equals_scipys_factors(model):
    """fem.superlu_store reads L_BI and diag U from SuperLU's supernodal store in place:
    the same entries as scipy's conversion of the whole factors (lu.L, lu.U)."""
    from gearwear.fem.superlu_store import border_rows, supernodal_store

    M, _, o = _arrowhead(model, 40)
    lu = spla.splu(M, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    store = supernodal_store(lu)
    assert store is not None
    assert np.array_equal(store.pivots(), lu.U.diagonal())
    i, j, v = border_rows(store, o)
    n = M.shape[0]
    mine = np.zeros((n - o, o))
    mine[i, j] = v
    assert np.array_equal(mine, lu.L[o:, :o].toarray())


@pytest.mark.parametrize("dense_from", [1, 10**9, 6])  # all columns through dsyrk, none, a split
def test_schur_from_border_equals_the_dense_schur_complement(model, dense_from):
    from gearwear.fem.condensation import schur_from_border
    from gearwear.fem.superlu_store import border_rows, supernodal_store

    M, Kp, o = _arrowhead(model, 40)
    lu = spla.splu(M, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    store = supernodal_store(lu)
    S = schur_from_border(Kp[o:, o:], *border_rows(store, o), store.pivots(), dense_from=dense_from)
    K = Kp.toarray()
    S_ref = K[o:, o:] - K[o:, :o] @ np.linalg.solve(K[:o, :o], K[:o, o:])
    assert np.array_equal(S, S.T)
    assert np.max(np.abs(S - S_ref)) <= 1e-10 * np.max(np.abs(S_ref))


def test_condensed_flexibility_without_the_in_place_read(model, monkeypatch):
    """When SuperLU's layout is not the expected one (supernodal_store gives None) the
    border comes from scipy's conversion of the factors: the same G and h."""
    from gearwear.fem import condensation

    top = model.mesh.facets_satisfying(lambda x: np.isclose(x[1], 1.0))
    xd = np.unique(model.basis.get_dofs(facets=top).all("u^1"))
    xd = xd[model.basis.doflocs[0, xd] > 0.0]
    a = np.random.default_rng(3).standard_normal((2, model.ndofs))
    G, h, tim = _condensed_flexibility(model, xd, a)
    assert tim["factor_read_in_place"] == 1
    monkeypatch.setattr(condensation, "supernodal_store", lambda lu: None)
    G2, h2, tim2 = _condensed_flexibility(model, xd, a)
    assert tim2["factor_read_in_place"] == 0
    assert np.max(np.abs(G2 - G)) <= 1e-12 * np.max(np.abs(G))
    assert np.max(np.abs(h2 - h)) <= 1e-12 * np.max(np.abs(h))


class _AtOnce:
    """An executor that runs each task at once, in this thread (the serial build)."""

    def __init__(self, **kw):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def submit(self, fn):
        from concurrent.futures import Future

        fut = Future()
        fut.set_result(fn())
        return fut


def _driver_larger_bodies():
    """Both bodies of DRIVER_LARGER (47/23, shifted) at coarse sizes, built afresh."""
    from gearwear.fem import pair_model as pmod

    from pairs import DRIVER_LARGER

    pmod._BODY_CACHE.clear()
    pm = pmod.pair_model(DRIVER_LARGER, contact_scale=3.0, mesh_scale=2.0)
    pmod._BODY_CACHE.clear()
    assert pm.bodies[0] is not pm.bodies[1]
    assert {"gear0_factorize_s", "gear1_factorize_s"} <= set(pm.timings)
    return pm.bodies


def test_two_bodies_built_overlapped_equal_the_serial_builds(monkeypatch):
    """fem.pair_model builds two distinct bodies overlapped (the first one's condensation in
    a worker thread while the second is meshed): the same bodies to the bit as built one
    after the other (an executor that runs each task at once, in this thread).
    DRIVER_LARGER (47/23, shifted), coarse sizes."""
    from gearwear.fem import pair_model as pmod

    overlapped = _driver_larger_bodies()
    monkeypatch.setattr(pmod, "ThreadPoolExecutor", _AtOnce)
    serial = _driver_larger_bodies()
    for a, b in zip(overlapped, serial):
        assert a.gear == b.gear
        assert np.array_equal(a.G, b.G) and np.array_equal(a.blank_h, b.blank_h)
        assert np.array_equal(a.dofs, b.dofs)


def test_overlapped_bodies_round_alike_whatever_the_interleaving(monkeypatch):
    """The bug's class: a process-wide setting (the BLAS thread count) held by each body's own
    ``with`` block, undone under the other body. Forced here: the worker thread's body enters
    its Cholesky first, the main thread's body enters its own, the worker's body leaves its
    block before the main one factorizes. Per-block limits left the main body on two BLAS
    threads (dpotrf rounds differently there), so its flexibility differed from the serial
    build; held by pair_model's caller (fem.process_settings) both bodies are the serial ones
    to the bit. DRIVER_LARGER (47/23, shifted), coarse sizes."""
    import threading
    import types

    from gearwear.fem import condensation
    from gearwear.fem import pair_model as pmod

    def worker() -> bool:
        return threading.current_thread().name.startswith("gearwear-body")

    with monkeypatch.context() as m:
        m.setattr(pmod, "ThreadPoolExecutor", _AtOnce)
        serial = _driver_larger_bodies()

    worker_inside, main_inside, worker_left = threading.Event(), threading.Event(), threading.Event()
    real_sla, real_inverse = condensation.sla, condensation._inverse

    def dpotrf(*a, **k):
        if worker():
            worker_inside.set()
            assert main_inside.wait(60)
        else:
            assert worker_inside.wait(60)
            main_inside.set()
            assert worker_left.wait(60)
        return real_sla.lapack.dpotrf(*a, **k)

    def inverse(S):
        try:
            return real_inverse(S)
        finally:
            if worker():
                worker_left.set()

    lapack = types.SimpleNamespace(dpotrf=dpotrf, dpotri=real_sla.lapack.dpotri)
    monkeypatch.setattr(condensation, "sla", types.SimpleNamespace(lapack=lapack, blas=real_sla.blas))
    monkeypatch.setattr(condensation, "_inverse", inverse)
    overlapped = _driver_larger_bodies()
    assert worker_left.is_set() and main_inside.is_set()  # the interleaving happened
    for a, b in zip(overlapped, serial):
        assert np.array_equal(a.G, b.G) and np.array_equal(a.blank_h, b.blank_h)


@pytest.mark.parametrize("corrupt", ["values", "pivots"])
def test_a_wrong_in_place_read_falls_back_to_scipys_factors(model, monkeypatch, corrupt):
    """A scipy whose private layout passes fem.superlu_store's checks but reads wrong values
    (or wrong pivots) must not give a wrong G or a false 'not positive definite': the
    solve check catches it and scipy's public conversion of the factors decides."""
    from gearwear.fem import condensation

    top = model.mesh.facets_satisfying(lambda x: np.isclose(x[1], 1.0))
    xd = np.unique(model.basis.get_dofs(facets=top).all("u^1"))
    xd = xd[model.basis.doflocs[0, xd] > 0.0]
    a = np.random.default_rng(3).standard_normal((2, model.ndofs))
    G, h, _ = _condensed_flexibility(model, xd, a)
    real_rows = condensation.border_rows

    class Wrong:
        def __init__(self, store):
            self.store = store

        def pivots(self):
            d = self.store.pivots()
            return -d if corrupt == "pivots" else d

    def rows(store, o):
        i, j, v = real_rows(store.store, o)
        return i, j, (1.5 * v if corrupt == "values" else v)

    real_store = condensation.supernodal_store
    monkeypatch.setattr(condensation, "supernodal_store", lambda lu: Wrong(real_store(lu)))
    monkeypatch.setattr(condensation, "border_rows", rows)
    G2, h2, tim2 = _condensed_flexibility(model, xd, a)
    assert tim2["factor_read_in_place"] == 0
    assert np.max(np.abs(G2 - G)) <= 1e-12 * np.max(np.abs(G))
    assert np.max(np.abs(h2 - h)) <= 1e-12 * np.max(np.abs(h))
