"""2D linear elasticity with scikit-fem: plane stress (default) or plane strain.

Strong form: div sigma = 0, sigma = lambda tr(eps) I + 2 mu eps, on a body of
thickness b (the face width). Plane strain uses the 3D Lame constants
lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)); plane stress replaces
lambda by lambda* = 2 lambda mu / (lambda + 2 mu) = E nu / (1 - nu^2)
(Zienkiewicz & Taylor, The FEM, vol. 1, ch. 6). The stiffness matrix is
K = b * int eps(v) : sigma(u) dA with Lagrange P1 or P2 triangles.

The fixed boundary (the bore) is eliminated; the reduced matrix is factorized once
(SuperLU) and any number of load cases are solved as right-hand sides.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import skfem
from skfem import Basis, ElementTriP1, ElementTriP2, ElementVector, FacetBasis, asm
from skfem.helpers import dot
from skfem.models.elasticity import lame_parameters

from gearwear.core.validation import fail
from gearwear.geometry.spec import Material

from .elasticity_blocks import isotropic_stiffness
from .mesh import CurvedMeshTri2


def lame(material: Material, plane: str = "stress") -> tuple[float, float]:
    """(lambda, mu) for plane stress or plane strain, Pa."""
    lam, mu = lame_parameters(material.youngs_modulus_Pa, material.poisson_ratio)
    if plane == "stress":
        lam = 2.0 * lam * mu / (lam + 2.0 * mu)
    elif plane != "strain":
        raise fail("plane", repr(plane), "", "must be 'stress' or 'strain'")
    return lam, mu


def located(mesh) -> skfem.Mesh:
    """The mesh itself, or for a plain ``skfem.MeshTri2`` the same mesh as a
    :class:`~gearwear.fem.mesh.CurvedMeshTri2`, whose points can be probed."""
    if isinstance(mesh, skfem.MeshTri2) and not isinstance(mesh, CurvedMeshTri2):
        return CurvedMeshTri2(**{f.name: getattr(mesh, f.name) for f in fields(mesh) if f.init})
    return mesh


@dataclass
class ElasticModel:
    """Assembled and factorized elasticity problem with fixed dofs eliminated."""

    mesh: skfem.Mesh
    basis: Basis
    K: sp.csr_matrix
    free: np.ndarray
    fixed: np.ndarray
    lu: Any  # scipy SuperLU, or None without factorization
    thickness_m: float
    plane: str
    order: int
    timings: dict = field(default_factory=dict)

    @property
    def ndofs(self) -> int:
        return self.basis.N

    def solve(self, F: np.ndarray) -> np.ndarray:
        """Displacements for load vector(s) F (N,) or (N, k); fixed dofs are zero."""
        F = np.asarray(F, dtype=float)
        t0 = time.perf_counter()
        single = F.ndim == 1
        F2 = F[:, None] if single else F
        U = np.zeros_like(F2)
        U[self.free] = self.lu.solve(np.ascontiguousarray(F2[self.free]))
        self.timings["solve_s"] = self.timings.get("solve_s", 0.0) + time.perf_counter() - t0
        return U[:, 0] if single else U

    def probe(self, points_xy: np.ndarray) -> sp.csr_matrix:
        """Matrix P with (P @ U) = displacement components at points: rows 2 i (x), 2 i + 1 (y)."""
        pts = np.asarray(points_xy, dtype=float).reshape(-1, 2)
        Pm = self.basis.probes(pts.T)  # (2 npts, N): first all x components, then all y
        n = len(pts)
        order = np.empty(2 * n, dtype=int)
        order[0::2] = np.arange(n)
        order[1::2] = n + np.arange(n)
        return Pm.tocsr()[order]


def assemble(
    mesh,
    material: Material,
    thickness_m: float,
    fixed_facets: np.ndarray,
    plane: str = "stress",
    order: int = 2,
    factorize: bool = True,
) -> ElasticModel:
    """Assemble K on ``mesh`` with P1/P2 elements, fix the dofs on ``fixed_facets`` and
    factorize (``factorize=False``: no factorization, ``lu`` is None; fem.pair_body
    condenses the matrix itself).

    The mesh is used as given: a 6-node (Gmsh order 2) mesh is isoparametric, its
    mid-side nodes on the curved boundary are the P2 nodes; a 3-node mesh has
    straight edges."""
    t0 = time.perf_counter()
    m = located(mesh)
    scalar = ElementTriP2() if order == 2 else ElementTriP1()
    basis = Basis(m, ElementVector(scalar), intorder=2 * order)
    lam, mu = lame(material, plane)
    # skfem.models.elasticity.linear_elasticity's matrix, from three scalar blocks (fem.elasticity_blocks)
    sbasis = Basis(m, scalar, intorder=2 * order)
    if not np.array_equal(basis.element_dofs[0::2], 2 * sbasis.element_dofs):
        raise RuntimeError("unexpected dof numbering of the vector basis")
    K = isotropic_stiffness(sbasis, lam, mu) * thickness_m
    fixed = basis.get_dofs(facets=np.asarray(fixed_facets)).all()
    free = np.setdiff1d(np.arange(basis.N), fixed)
    t1 = time.perf_counter()
    if not factorize:
        return ElasticModel(m, basis, K.tocsr(), free, fixed, None, thickness_m, plane, order, {"assemble_s": t1 - t0})
    Kff = K[free][:, free].tocsc()
    # K_ff is symmetric positive definite: a symmetric fill-reducing ordering of
    # A^T + A without pivoting gives ~40 % fewer factor nonzeros than COLAMD with
    # partial pivoting (gear meshes, 57k dofs: 4.6M vs 7.4M), i.e. faster
    # factorization and multi-right-hand-side solves; no pivoting is stable for SPD.
    lu = spla.splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    t2 = time.perf_counter()
    return ElasticModel(
        m, basis, K.tocsr(), free, fixed, lu, thickness_m, plane, order, {"assemble_s": t1 - t0, "factorize_s": t2 - t1}
    )


def traction_load(model: ElasticModel, facets: np.ndarray, traction) -> np.ndarray:
    """Load vector of a surface traction on ``facets``: f = b int_Gamma t . v ds.

    ``traction(x, y)`` returns the traction vector (N/m^2 per unit thickness, i.e. Pa)
    as an array of shape (2, ...) at the quadrature points."""
    fb = FacetBasis(model.mesh, model.basis.elem, facets=np.asarray(facets), intorder=2 * model.order + 2)

    @skfem.LinearForm
    def form(v, w):
        t = traction(w.x[0], w.x[1])
        return dot(t, v)

    return asm(form, fb) * model.thickness_m
