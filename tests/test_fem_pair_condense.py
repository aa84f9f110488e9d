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
