"""The loaded flank in the FE single-tooth mesh (``fem.tooth``): the mesh nodes on it, and
the nominal mesh morphed onto the worn flank.

Worn flank: by default the *nominal* mesh is morphed (``worn_geometry="morph"``):
the nodes on tooth 0's right flank (vertices and mid-side nodes) move by -h(s) n(s)
onto the worn flank and the interior vertices follow by a harmonic (Laplace)
extension of that displacement, the other mid-side nodes with their edges. Nominal
and worn models then have the same topology by construction, so the wear effect
(0.01-0.12 % of the compliance for 10-30 um, of the order of the 0.03 %
discretisation error of the default level) is not mixed with a change of mesh.
``worn_geometry="remesh"`` meshes the worn outline instead; at the default level
it agrees with the morph to 0.002 % for severe wear.

The morph (:func:`morph_to_worn`): a node on the flank at profile arc parameter s moves by

    D(s) = (worn - nominal)(s) = -h(s) n(s)    [m]

(h the wear depth, n the outward unit normal of the nominal flank); the interior vertices
take the harmonic extension of the boundary displacement, the P1 solution of

    div grad D = 0  in the gear,   D given on its boundary (0 off the worn flank),

and every other mid-side node moves with the mean of its edge's two vertices. The flank
nodes come from :func:`_flank_nodes` (the vertices within a tolerance of the flank polyline
and the mid-side nodes between them, with their profile arc parameter s, m).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse.linalg as spla
import skfem
from skfem import Basis, ElementTriP1, asm
from skfem.models.poisson import laplace

from gearwear.fem.mesh import MeshError, inverted_elements
from gearwear.geometry.polyline import project_to_polyline
from gearwear.geometry.profile import ToothProfile


def _flank_nodes(mesh, facets: np.ndarray, flank: ToothProfile, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes on the flank polyline, sorted root -> tip, and their profile arc parameter
    s: the vertices of ``facets`` within ``tol`` (m) of it and, on a 6-node mesh, the
    mid-side nodes of the facets between two of them (``mesh.doflocs`` indices)."""
    f = np.asarray(facets)
    nodes = np.unique(mesh.facets[:, f])
    nodes = nodes[project_to_polyline(mesh.p[:, nodes].T, flank.xy, max_distance=tol).distance <= tol]
    if isinstance(mesh, skfem.MeshTri2):
        both = np.isin(mesh.facets[:, f], nodes).all(axis=0)
        nodes = np.concatenate([nodes, mesh.nvertices + f[both]])
    pr = project_to_polyline(mesh.doflocs[:, nodes].T, flank.xy)
    s = flank.s[pr.segment] + pr.t * (flank.s[pr.segment + 1] - flank.s[pr.segment])
    order = np.argsort(s, kind="stable")
    return nodes[order], s[order]


def morph_to_worn(
    mesh,
    boundary_facets: np.ndarray,
    flank_nodes: np.ndarray,
    flank_s: np.ndarray,
    nominal: ToothProfile,
    loaded: ToothProfile,
):
    """The nominal mesh with tooth 0's right flank moved onto the worn flank.

    ``flank_nodes`` are the mesh nodes (``mesh.doflocs`` indices: vertices and, on a
    6-node mesh, mid-side nodes) on the nominal flank and ``flank_s`` their profile arc
    parameter s (linear along each source segment); each moves by
    (worn - nominal)(s) = -h(s) n(s). The other boundary vertices stay; interior
    vertices get the harmonic extension of the boundary displacement (P1 Laplace on
    the vertices with those Dirichlet values, which keeps elements valid for
    displacements well below the element size), and every other mid-side node moves
    with the mean of its edge's two vertices (an unmoved edge keeps its shape).
    Checked: no element may fold (``fem.mesh.inverted_elements``).
    """
    disp = np.column_stack([np.interp(flank_s, nominal.s, loaded.xy[:, k] - nominal.xy[:, k]) for k in (0, 1)])
    nv = mesh.nvertices
    basis = Basis(mesh, ElementTriP1())
    L = asm(laplace, basis).tocsr()
    fixed = np.unique(mesh.facets[:, boundary_facets])
    free = np.setdiff1d(np.arange(nv), fixed)
    D = np.zeros((nv, 2))
    vert = flank_nodes < nv
    D[flank_nodes[vert]] = disp[vert]
    if free.size:
        lu = spla.splu(L[free][:, free].tocsc())
        D[free] = lu.solve(-np.asarray(L[free][:, fixed] @ D[fixed]))
    p = np.array(mesh.doflocs, dtype=float)
    p[:, :nv] += D.T
    if p.shape[1] > nv:  # mid-side node of facet f is node nv + f
        p[:, nv:] += 0.5 * (D[mesh.facets[0]] + D[mesh.facets[1]]).T
        p[:, flank_nodes[~vert]] = mesh.doflocs[:, flank_nodes[~vert]] + disp[~vert].T
    out = replace(mesh, doflocs=p)
    bad = inverted_elements(out)
    if np.any(bad):
        raise MeshError(
            f"morphing the mesh onto the worn flank inverts {int(np.sum(bad))} elements "
            "(wear depth comparable to the element size; use worn_geometry='remesh')"
        )
    return out
