"""Isoparametric 6-node triangle meshes that scikit-fem can probe.

``skfem.MeshTri2`` has no element finder (``Mesh2D2.element_finder`` raises
NotImplementedError), so ``Basis.probes`` cannot evaluate a field at a point of a curved
mesh. ``CurvedMeshTri2`` adds one: a KD-tree over the corner centroids proposes candidate
elements, and Newton on the quadratic map x(xi) finds the reference point; the first
candidate whose barycentric coordinates are all >= -1e-9 wins. ``inverted_elements`` flags
elements whose quadratic map folds (det J <= 0 at the corners, edge mid-points or centroid).
Self-contained (numpy, scipy, scikit-fem) so that it could be offered upstream."""

from __future__ import annotations

import numpy as np
import skfem

#: candidates per point of the element search (nearest corner centroids)
_FINDER_CANDIDATES = 8


class CurvedMeshTri2(skfem.MeshTri2):
    """``skfem.MeshTri2`` (isoparametric 6-node triangles) whose points can be located,
    so ``Basis.probes`` works on it (skfem's quadratic meshes have no element finder).

    A point's candidates are the elements with the nearest corner centroids; the
    isoparametric map of each is inverted by Newton's method (x = sum N_i(X) x_i,
    X <- X + DF(X)^-1 (x - F(X))) and the element whose reference coordinates are
    inside (barycentric coordinates >= -1e-9) wins. A curved boundary element holds
    points outside its corner triangle (the boundary bulges by up to the chord sag),
    which the straight-triangle search of ``MeshTri1`` would miss."""

    def element_finder(self, mapping=None):
        if mapping is None:
            mapping = self._mapping()
        from scipy.spatial import cKDTree

        tree = cKDTree(self.p[:, self.t].mean(axis=1).T)
        nel = self.t.shape[1]

        def violation(pts, cand):
            n, k = cand.shape
            x = np.repeat(pts, k, axis=1)[:, :, None]
            tind = cand.ravel()
            X = np.full(x.shape, 1.0 / 3.0)
            with np.errstate(all="ignore"):
                for _ in range(12):
                    X = X + np.einsum("ijkl,jkl->ikl", mapping.invDF(X, tind), x - mapping.F(X, tind))
                v = np.max([-X[0, :, 0], -X[1, :, 0], X[0, :, 0] + X[1, :, 0] - 1.0], axis=0)
            return np.nan_to_num(v, nan=np.inf).reshape(n, k)

        def finder(x, y):
            pts = np.vstack([np.atleast_1d(x), np.atleast_1d(y)]).astype(float)
            _, cand = tree.query(pts.T, min(_FINDER_CANDIDATES, nel))
            cand = cand.reshape(pts.shape[1], -1)
            v = violation(pts, cand)
            best = np.argmin(v, axis=1)
            out = cand[np.arange(len(best)), best]
            for i in np.flatnonzero(v[np.arange(len(best)), best] > 1e-9):
                vi = np.concatenate(
                    [
                        violation(pts[:, i : i + 1], np.arange(j, min(j + 4096, nel))[None])[0]
                        for j in range(0, nel, 4096)
                    ]
                )
                if vi.min() > 1e-9:
                    raise ValueError(f"point {pts[:, i].tolist()} is outside of the mesh")
                out[i] = int(np.argmin(vi))
            return out

        return finder


def inverted_elements(mesh) -> np.ndarray:
    """True for every element whose map is not orientation-preserving: a corner
    triangle with signed area <= 0, or (6-node elements) det J <= 0 at a corner, an
    edge mid-point or the centroid. det J is quadratic on a 6-node triangle, so
    these seven points catch every fold that matters in practice."""
    t = mesh.dofs.element_dofs if isinstance(mesh, skfem.MeshTri2) else mesh.t
    x = np.asarray(mesh.doflocs).T[t.T]  # (nel, 3 or 6, 2)
    e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    sa = e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0]  # twice the signed corner area
    bad = sa <= 0
    if x.shape[1] == 6:
        bad |= np.any(_p2_dets(x) <= 0, axis=0)
    return bad


def _p2_dets(x: np.ndarray) -> np.ndarray:
    """det J of the 6-node isoparametric map (nodes [v0, v1, v2, m01, m12, m20]; x:
    (nel, 6, 2)) at the corners, the edge mid-points and the centroid: (7, nel)."""
    out = []
    for xi, eta in ((0, 0), (1, 0), (0, 1), (0.5, 0), (0.5, 0.5), (0, 0.5), (1 / 3, 1 / 3)):
        l0 = 1.0 - xi - eta
        # dN/dxi, dN/deta for nodes [v0, v1, v2, m01, m12, m20]
        dxi = np.array([-(4 * l0 - 1), 4 * xi - 1, 0.0, 4 * (l0 - xi), 4 * eta, -4 * eta])
        deta = np.array([-(4 * l0 - 1), 0.0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l0 - eta)])
        jx = np.einsum("k,ekd->ed", dxi, x)
        je = np.einsum("k,ekd->ed", deta, x)
        out.append(jx[:, 0] * je[:, 1] - jx[:, 1] * je[:, 0])
    return np.stack(out)
