"""From Gmsh's raw arrays to a checked scikit-fem mesh: the conversion (P1, or curved P2
through ``fem.curved_mesh``), the element quality (normalised radius ratio), and the exact
region checks (elements fill what their named boundaries enclose; that region is the
intended one after the bore's and the split curved edges' P2 defects, computed exactly).
The equations are in the docstrings and in ``fem.mesh`` ("Geometry and the exact area")."""

from __future__ import annotations

import time

import numpy as np
import skfem

from .curved_mesh import CurvedMeshTri2, _p2_dets
from .mesh_spec import GearMesh, MeshError
from .outline import _cross

# Meshes whose worst corner triangle is below this normalised radius ratio are
# rejected: Frontal-Delaunay gives > 0.3 on sane input, so anything this low
# means the geometry has a gap narrower than the requested element size.
MIN_QUALITY = 0.05


def _to_skfem(raw: dict, order: int, scale: float):
    conn = raw["conn"]
    tag2row = np.full(int(raw["tags"].max()) + 1, -1, dtype=np.int64)
    tag2row[raw["tags"]] = np.arange(raw["tags"].size)
    # canonical numbering: corner vertices first (sorted by gmsh tag), then
    # mid-side nodes -- skfem then keeps vertex indices unchanged, which lets
    # us map boundary lines to facets by index
    corners = np.unique(conn[:, :3])
    mids = np.setdiff1d(np.unique(conn), corners) if order == 2 else np.zeros(0, np.int64)
    used = np.concatenate([corners, mids])
    new = np.full(tag2row.size, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    t = new[conn]
    pts = raw["xyz"][tag2row[used], :2].copy()
    nv = corners.size

    # gmsh surface normals may point to -z: make every element CCW
    v = pts[t[:, :3]]
    sa = _cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    flip = sa < 0
    if order == 2:
        t[flip] = t[flip][:, [0, 2, 1, 5, 4, 3]]
    else:
        t[flip] = t[flip][:, [0, 2, 1]]
    v = pts[t[:, :3]]
    sa = _cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    if np.any(sa <= 1e-14 * scale**2):
        raise MeshError(f"mesh has {int(np.count_nonzero(sa <= 1e-14 * scale**2))} degenerate triangles")

    if order == 2:
        x = pts[t]  # (nel, 6, 2)
        dets = _p2_dets(x)
        if np.any(dets <= 0):
            e = int(np.argmin(dets.min(axis=0)))
            raise MeshError(
                "a curved P2 element has a non-positive Jacobian near "
                f"{x[e, :3].mean(axis=0).tolist()} m (hub circle too close to the outline "
                "for the element size?)"
            )
        # det J is quadratic: the edge-midpoint rule (weights 1/6) is exact
        area = float(np.sum(dets[3:6]) / 6.0)
        mesh = CurvedMeshTri2(np.ascontiguousarray(pts.T), np.ascontiguousarray(t.T))
    else:
        area = float(np.sum(sa) / 2.0)
        mesh = skfem.MeshTri(np.ascontiguousarray(pts.T), np.ascontiguousarray(t.T), sort_t=False)

    # boundary lines -> facet indices via sorted vertex-pair keys
    f = np.sort(mesh.facets, axis=0).astype(np.int64)
    fkey = f[0] * nv + f[1]
    order_f = np.argsort(fkey)
    skey = fkey[order_f]
    bfac = set(mesh.boundary_facets().tolist())
    boundaries = {}
    for gname, ln in raw["lines"].items():
        if ln.shape[0] == 0:
            raise MeshError(f"boundary group '{gname}' has no mesh edges")
        lv = np.sort(new[ln], axis=1)
        if np.any(lv < 0) or np.any(lv >= nv):
            raise MeshError(f"boundary group '{gname}' is not attached to the mesh")
        k = lv[:, 0] * nv + lv[:, 1]
        pos = np.searchsorted(skey, k)
        pos = np.clip(pos, 0, skey.size - 1)
        if not np.all(skey[pos] == k):
            raise MeshError(f"boundary group '{gname}' edges are not mesh facets")
        facets = np.sort(order_f[pos]).astype(np.int32)
        if not set(facets.tolist()) <= bfac:
            raise MeshError(f"boundary group '{gname}' contains interior facets")
        boundaries[gname] = facets
    mesh = mesh.with_boundaries(boundaries)
    return mesh, boundaries, area


def _hub_arc_defect(mesh, facets: np.ndarray, r: float, order: int) -> float:
    """Area the discretised hub arc adds vs the true arc (>= 0: mesh bigger)."""
    p = mesh.p
    e = mesh.facets[:, facets]
    a, b = p[:, e[0]].T, p[:, e[1]].T
    theta = np.abs(np.arctan2(_cross(a, b), np.einsum("ij,ij->i", a, b)))
    phi = theta / 2
    seg = r**2 * (phi - np.sin(phi) * np.cos(phi))
    if order == 2:
        approx = 4.0 / 3.0 * r**2 * np.sin(phi) * (1 - np.cos(phi))
    else:
        approx = 0.0
    return float(np.sum(seg - approx))


def _boundary_area(mesh, facets: np.ndarray, mids: np.ndarray | None = None) -> float:
    """(1/2) closed-integral of x dy - y dx over the boundary ``facets``, each oriented with the
    mesh on its left: for a 6-node edge x(t) = a + t (b - a) + 4 t (1 - t) e,
    e = m - (a + b) / 2, exactly (1/2) cross(a, b) + (2/3) cross(e, b - a). ``mids`` (one row
    per facet) replaces the mesh's mid-side nodes m (the area of another parabola through
    the same ends)."""
    f = np.asarray(facets)
    a = mesh.p[:, mesh.facets[0, f]].T
    b = mesh.p[:, mesh.facets[1, f]].T
    c = mesh.p[:, mesh.t[:3, mesh.f2t[0, f]]].mean(axis=1).T
    swap = _cross(b - a, c - a) < 0
    a, b = np.where(swap[:, None], b, a), np.where(swap[:, None], a, b)
    if mids is not None:
        e = mids - 0.5 * (a + b)
    elif isinstance(mesh, skfem.MeshTri2):
        e = mesh.doflocs[:, mesh.nvertices + f].T - 0.5 * (a + b)
    else:
        e = 0.0 * a
    return float(0.5 * np.sum(_cross(a, b)) + 2.0 / 3.0 * np.sum(_cross(e, b - a)))


def _bezier(a, c, b, t):
    """Points, first and second derivatives of the quadratic Bezier curves (a, c, b) at t."""
    t = t[:, None]
    x = (1 - t) ** 2 * a + 2 * t * (1 - t) * c + t**2 * b
    return x, 2 * (1 - t) * (c - a) + 2 * t * (b - c), 2 * (a - 2 * c + b)


def _project(a, c, b, x, t):
    """Parameter and distance of the point of each Bezier (a, c, b) nearest to x (Newton on
    |B(t) - x|^2 from t, kept in [0, 1])."""
    for _ in range(30):
        p, d1, d2 = _bezier(a, c, b, t)
        r = p - x
        h = np.sum(d1 * d1, axis=1) + np.sum(r * d2, axis=1)
        t = np.clip(t - np.sum(r * d1, axis=1) / np.where(h > 0, h, 1.0), 0.0, 1.0)
    return t, np.linalg.norm(_bezier(a, c, b, t)[0] - x, axis=1)


def _split_edge_defect(mesh, facets: np.ndarray, chain: tuple, scale: float) -> float:
    """Area enclosed by the P2 ``facets`` of a curved outline minus the area of the outline
    itself (m^2, signed as :func:`_boundary_area`).

    Each outline edge i is the quadratic Bezier B_i(t) through a, m, b (control point
    2 m - (a + b) / 2). Where gmsh splits it, it puts the nodes on B_i but the mid-side node
    at the arc-length middle of the piece [t_a, t_b], not at B_i((t_a + t_b) / 2); the 6-node
    edge is then a slightly different parabola through the same three curve points. The
    piece of B_i is itself a parabola whose area to the chord is exactly
    (2/3) cross(B_i((t_a + t_b) / 2) - (a + b) / 2, b - a), so the mesh boundary with these
    mid-points encloses the outline exactly, and the difference is the defect. Unsplit edges
    contribute 0. Every node of the facets must lie on its edge's curve (1e-9 of the
    outline's size), or the mesh is not of this outline (MeshError)."""
    poly, mids = chain
    ne = len(mids)
    a0, b0 = poly[:ne], np.roll(poly, -1, axis=0)[:ne]
    m0 = np.where(np.isfinite(mids), mids, 0.5 * (a0 + b0))  # a straight edge: m the midpoint
    c0 = 2.0 * m0 - 0.5 * (a0 + b0)
    f = np.asarray(facets)
    pa, pb = mesh.p[:, mesh.facets[0, f]].T, mesh.p[:, mesh.facets[1, f]].T
    pm = mesh.doflocs[:, mesh.nvertices + f].T
    # the edge of each facet: the one of (nearest edge midpoint's edge and its two
    # neighbours) its mid-side node lies on, the piece of the curve between its ends
    from scipy.spatial import cKDTree

    ts = np.linspace(0.0, 1.0, 17)
    samples = _bezier(np.repeat(a0, ts.size, 0), np.repeat(c0, ts.size, 0), np.repeat(b0, ts.size, 0), np.tile(ts, ne))[
        0
    ]
    e0 = cKDTree(samples).query(pm)[1] // ts.size
    best_d = np.full(len(f), np.inf)
    edge = e0.copy()
    for shift in (0, -1, 1):
        e = (e0 + shift) % ne
        _, d = _project(a0[e], c0[e], b0[e], pm, np.full(len(f), 0.5))
        better = d < best_d
        best_d, edge = np.where(better, d, best_d), np.where(better, e, edge)
    a, c, b = a0[edge], c0[edge], b0[edge]
    ta, da = _project(a, c, b, pa, np.zeros(len(f)))
    tb, db = _project(a, c, b, pb, np.ones(len(f)))
    off = np.maximum(np.maximum(da, db), best_d)
    if np.any(off > 1e-9 * scale):
        k = int(np.argmax(off))
        raise MeshError(
            f"an outline node of the mesh is {off[k]:.3g} m off its curve near {(pm[k] * 1e3).round(3).tolist()} mm"
        )
    true_mid = _bezier(a, c, b, 0.5 * (ta + tb))[0]
    return _boundary_area(mesh, f) - _boundary_area(mesh, f, mids=true_mid)


def _finish(raw, order, scale, exact_area, r_hub, hub_name, t0, chain=None) -> GearMesh:
    """The checked GearMesh of a gmsh run. ``chain`` = (outline points, edge mid-points) of a
    curved outline (order 2), whose boundary group is "outer"."""
    mesh, boundaries, area = _to_skfem(raw, order, scale)
    q = triangle_quality(mesh)
    if q.min() < MIN_QUALITY:
        e = int(np.argmin(q))
        raise MeshError(
            f"mesh quality too low: min radius ratio {q[e]:.3g} < {MIN_QUALITY} near "
            f"{mesh.p[:, mesh.t[:3, e]].mean(axis=1).tolist()} m (feature narrower than "
            "the element size? reduce sizes.global_m)"
        )
    # never return a silently wrong mesh: the elements must fill the region their
    # named boundaries enclose (a hole has unnamed boundary facets, an overlap adds
    # area), and that region must be the exact one up to the discretised bore and,
    # on a curved outline, the pieces of its edges that gmsh split (both exact)
    enclosed = sum(_boundary_area(mesh, f) for f in boundaries.values())
    if abs(area - enclosed) > 1e-9 * exact_area:
        raise MeshError(
            f"meshed area {area!r} m^2 differs from the {enclosed!r} m^2 its boundaries enclose "
            f"(rel {abs(area - enclosed) / exact_area:.3e}: a hole or an overlap)"
        )
    expected = exact_area + _hub_arc_defect(mesh, boundaries[hub_name], r_hub, order)
    if chain is not None:
        expected += _split_edge_defect(mesh, boundaries["outer"], chain, scale)
    if abs(enclosed - expected) > 1e-9 * exact_area:
        raise MeshError(
            f"meshed region {enclosed!r} m^2 differs from the expected {expected!r} m^2 "
            f"(rel {abs(enclosed - expected) / exact_area:.3e})"
        )
    return GearMesh(
        mesh=mesh,
        boundaries=boundaries,
        area_m2=area,
        exact_area_m2=exact_area,
        hub_radius_m=r_hub,
        order=order,
        build_time_s=time.perf_counter() - t0,
    )


def triangle_quality(mesh) -> np.ndarray:
    """Normalised radius ratio ``2 r_in / R_circ`` of each element's corner triangle.

    1 for an equilateral triangle, -> 0 for slivers; negative for clockwise
    (inverted) corner triangles, so a valid mesh has all values in (0, 1].
    Mid-side nodes of P2 elements are ignored (their validity is checked by
    the mesher's Jacobian test instead).  Accepts a skfem mesh or a GearMesh.
    """
    m = mesh.mesh if isinstance(mesh, GearMesh) else mesh
    p = np.asarray(m.p)[:2]
    t = np.asarray(m.t)[:3]
    a, b, c = p[:, t[0]].T, p[:, t[1]].T, p[:, t[2]].T
    la = np.linalg.norm(b - c, axis=1)
    lb = np.linalg.norm(c - a, axis=1)
    lc = np.linalg.norm(a - b, axis=1)
    area = 0.5 * _cross(b - a, c - a)
    return 16.0 * area * np.abs(area) / (la * lb * lc * (la + lb + lc))
