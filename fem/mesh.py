"""Gmsh meshing of planar spur-gear bodies, returned as scikit-fem meshes.

The API is deliberately generic: it meshes *a region bounded by a given
polygon* (the toothed outline, optionally with curved edges) and a hub circle,
so it does not care how the tooth profile was generated (``geometry/profile.py``
supplies the polygon). All lengths are in metres, all angles in radians, areas
in m^2.

Public API
----------
``MeshSizes``          element sizes and refinement-zone extents
``GearMesh``           result: scikit-fem mesh + named boundary facets + area
``mesh_full_gear``     whole gear: outline polygon minus the bore disc
``mesh_sector``        a sector: toothed polyline, two radial cuts, hub arc
``write_mesh``         atomic ``.msh`` / ``.vtu`` output through meshio
``triangle_quality``   per-element normalised radius ratio
``inverted_elements``  elements whose (isoparametric) map folds
``CurvedMeshTri2``     the order-2 mesh class: skfem.MeshTri2 with point location
``MeshError``          every meshing failure (a ``ValueError``; from a design: a bug)
``MeshInputError``     an input the mesher refuses as impossible (a ``MeshError`` and an
                       ``InputError`` of gearwear.core.validation)

Modules (each one idea; this module holds the drivers and the export)
-------
``fem.mesh_spec``      MeshSizes, GearMesh, MeshError, MeshInputError
``fem.outline``        outline checks and curved-edge geometry
``fem.gmsh_run``       one serialised, deterministic Gmsh run and its raw arrays
``fem.mesh_checks``    conversion to scikit-fem, quality, exact region checks
``fem.curved_mesh``    CurvedMeshTri2 and inverted_elements (self-contained)

Geometry and the "exact area"
-----------------------------
The toothed boundary runs through exactly the given points. Each edge is a
straight segment (its P2 mid-side node at the segment midpoint) or, when a
mid-point ``m`` of the true curve is given for it (``outline_mid_xy``), the
quadratic Bezier curve through a, m, b (control point 2 m - (a + b) / 2, so
B(1/2) = m): gmsh places second-order nodes on its curves at arc-length
fractions (``Mesh.SecondOrderLinear = 0``), so the mid-side node of an
unsplit curved edge is m and the isoparametric element edge is the parabola
through a, m, b. An involute or fillet sampled at 0.4 mm is then within ~1 nm
of its mid-side nodes instead of the chord sag h^2 / (8 rho) (1-10 um).
The bore / hub arc is a *true circular arc* in gmsh, its mid-side nodes on
the circle.  The exact area of the region is therefore

* full gear: ``shoelace(outline) + bulges - pi * r_hub**2``, with the bulge
  ``(2/3) cross(m - (a + b) / 2, b - a)`` of each curved edge (the area
  between a parabola and its chord);
* sector:    Green's theorem along polyline (+ bulges) + straight cuts + true
  hub arc, i.e. ``0.5 * sum(cross(P_i, P_i+1)) + 0.5*cross(P_n, H_to)
  + 0.5*cross(H_from, P_0) - 0.5 * r_hub**2 * (angle_to - angle_from)``.

A parabola through three points of a circle under-estimates each circular
segment by ``r^2 * phi^5 / 30`` (``phi`` = half the subtended angle): the bore's
P2 area defect, computed exactly, and kept below 1e-8 of the region area by
forcing enough bore elements (``Mesh.MinimumCircleNodes``).
Where gmsh splits a curved outline edge it places the new nodes on the Bezier
curve but each mid-side node at the arc-length middle of its piece, so the
6-node edge is another parabola through the same three curve points; the area
it adds or loses against the true piece is computed exactly too
(``_split_edge_defect``), after checking that every outline node lies on its
curve.  Every mesh is checked twice: its elements must fill exactly (1e-9) the
region its named boundaries enclose (a hole or an overlap fails), and that
region must be the exact one to 1e-9 after the bore defect and the split
defect.

Element sizes
-------------
Background field = Min of
* a constant ``sizes.global_m``;
* Distance+Threshold fields around ``fillet_points_xy`` (-> ``fillet_m``) and
  ``refine_points_xy`` (-> ``load_m``), constant within ``*_dist_m`` and then
  growing with slope ``growth``;
* an ``Extend`` field that grades from the boundary edge lengths into the
  interior with the same slope.
Size-from-curvature and extend-from-boundary are off; geometric points carry
the local outline spacing so a sector's straight cuts grade from the root to
the hub.  Every outline edge is at least one element edge, so the outline
spacing is a lower bound on the boundary element size: give the mesher an
outline sampled roughly at the boundary size you want (40 points per tooth is
fine; 400 points per tooth on the gear below gives ~127 000 triangles, ~8 s).
A mesh whose worst element has radius ratio < ``MIN_QUALITY`` (0.05) is
rejected with ``MeshError`` (it means a gap narrower than the element size).

scikit-fem mesh class
---------------------
Order 2 returns :class:`CurvedMeshTri2`, a ``skfem.MeshTri2`` (isoparametric
6-node triangles; use it with ``ElementTriP2`` or lower-order bases) that also
locates points, so ``basis.probes`` works (skfem's ``MeshTri2`` has no element
finder).  Its ``t`` holds the three corner vertices (indices
``0 .. mesh.nvertices-1`` of ``mesh.p``); the mid-side node of facet f is node
``mesh.nvertices + f`` (the edge DOFs, ``mesh.dofs.element_dofs[3:]`` for
edges 01, 12, 02).  Order 1 returns ``skfem.MeshTri`` built with
``sort_t=False`` so that all elements keep their counter-clockwise orientation
(skfem's default sorts the connectivity, which scrambles orientation; only
Hermite-type ``ElementGlobal`` elements care about that).

Boundaries
----------
Each boundary group is the set of gmsh curves it was built from (outline
lines or curves, hub arcs, cut lines); their 1D mesh edges are mapped to skfem facet
indices through the corner-vertex pairs, and checked to be boundary facets.
The groups partition ``mesh.boundary_facets()``.

Cracks
------
``mesh_full_gear(crack_xy=(mouth, tip))`` meshes a straight crack as a cut: the
segment from an outline point (the mouth) to an interior tip is embedded in the
surface, so its 1D mesh edges are element edges, and after the element order is set
Gmsh's ``Crack`` plugin (Dimension 1, the crack curve as PhysicalGroup, the mouth
point as OpenBoundaryPhysicalGroup) duplicates every node on it except the tip's,
P2 mid-side nodes included: the elements on one side use the copies. Boundary group
"crack" holds the edges of both faces (free surfaces; their areas cancel in the
exact-area check, the crack encloses none). A Distance+Threshold field refines the
tip to ``crack_tip_size_m`` within twice that distance and grades out with
``sizes.growth``. The plugin's own options are set on every use; Gmsh has no getter
for them, so they are not restored in a caller's session.

Determinism
-----------
One thread, fixed algorithm (Frontal-Delaunay, ``Mesh.Algorithm = 6``), fixed
random seed, a fresh gmsh model per call, nodes renumbered canonically: the
same input gives bit-identical ``doflocs`` and ``t``.  gmsh is a process-wide
singleton, so calls are serialised with a lock.

Size (``pytest -s tests/test_mesh.py -k timing`` prints the wall time): the full
30-tooth, module-5 gear (tip 80 mm, root 68.75 mm, hub 40 mm, 40 outline
points per tooth), global 3 mm, 0.5 mm at all 60 fillets and 0.2 mm at one
load point: 22 249 P2 triangles, 46 181 nodes, area error 1e-8 relative.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import gmsh
import meshio
import numpy as np
import skfem

from gearwear.core.atomic import atomic_write

from .curved_mesh import CurvedMeshTri2, inverted_elements
from .gmsh_run import _add_arcs, _add_outline, _hub_size, _run_gmsh
from .mesh_checks import _finish, triangle_quality
from .mesh_spec import GearMesh, MeshError, MeshInputError, MeshSizes
from .outline import (
    _as_mids,
    _as_points,
    _as_refine_points,
    _bulge_area,
    _check_crack,
    _check_hub,
    _check_order,
    _check_refine,
    _check_simple_closed,
    _cross,
    _min_dist_to_origin,
    _origin_inside,
    _with_mids,
    _wrap,
)

__all__ = [
    "MeshError",
    "MeshInputError",
    "MeshSizes",
    "GearMesh",
    "mesh_full_gear",
    "mesh_sector",
    "write_mesh",
    "triangle_quality",
    "inverted_elements",
    "CurvedMeshTri2",
    "SolidMesh",
    "mesh_sector_solid",
]


def mesh_full_gear(
    outline_xy: np.ndarray,
    hub_radius_m: float,
    sizes: MeshSizes,
    refine_points_xy: np.ndarray | None = None,
    fillet_points_xy: np.ndarray | None = None,
    order: int = 2,
    outline_mid_xy: np.ndarray | None = None,
    crack_xy: np.ndarray | None = None,
    crack_tip_size_m: float | None = None,
) -> GearMesh:
    """Mesh a whole gear: the polygon ``outline_xy`` minus the bore disc.

    outline_xy        (N,2) m, closed polygon (last point NOT repeated),
                      counter-clockwise, simple, centred on the origin.
    hub_radius_m      bore radius, 0 < r < min distance of outline to origin.
    sizes             MeshSizes.
    refine_points_xy  (K,2) m load/contact points, refined to ``sizes.load_m``.
    fillet_points_xy  (M,2) m fillet points, refined to ``sizes.fillet_m``.
    order             2 -> CurvedMeshTri2 (a skfem.MeshTri2, default),
                      1 -> skfem.MeshTri.
    outline_mid_xy    (N,2) m, optional, order 2 only: a point of the true
                      curve between outline points i and i+1 (mid-point of
                      edge i, ideally at half its arc length); the edge is
                      then meshed as the quadratic through the three points
                      and its P2 mid-side nodes lie on it. NaN rows keep an
                      edge straight.
    crack_xy          (2,2) m, optional: a straight crack from its mouth
                      crack_xy[0], which must be an outline point, to its tip
                      crack_xy[1] inside the region. The crack is a cut with
                      two free faces: its nodes are duplicated (all but the
                      tip), boundary group "crack" holds both faces' edges.
    crack_tip_size_m  element size at the crack tip (default: sizes.fillet_m,
                      else global_m), graded with sizes.growth from 2 x the
                      tip size on.

    Boundary groups: "outer" (polygon edges) and "bore" (hub circle), taken
    from the gmsh curves they were meshed on, and "crack" with ``crack_xy``.  Exact area:
    ``shoelace(outline) + bulges - pi r^2``, the bulge of a curved edge being
    ``(2/3) cross(m - (a+b)/2, b - a)``.
    """
    t0 = time.perf_counter()
    order = _check_order(order)
    poly = _as_points(outline_xy, "outline_xy", 3)
    scale = float(np.max(np.abs(poly)))
    if scale <= 0:
        raise MeshInputError("outline_xy is degenerate (all points at the origin)")
    fillet_pts = _as_refine_points(fillet_points_xy, "fillet_points_xy")
    load_pts = _as_refine_points(refine_points_xy, "refine_points_xy")
    _check_refine(sizes, fillet_pts, load_pts)
    mids = _as_mids(outline_mid_xy, poly, True, order)
    curve = _with_mids(poly, mids)
    _check_simple_closed(curve, "outline_xy", scale)
    twice_area = float(np.sum(_cross(poly, np.roll(poly, -1, axis=0)))) + 2.0 * _bulge_area(poly, mids)
    if twice_area <= 0:
        raise MeshInputError(f"outline_xy must be counter-clockwise (signed area {twice_area / 2!r} m^2 <= 0)")
    if not _origin_inside(curve):
        raise MeshInputError("outline_xy does not enclose the origin (gear must be centred)")
    r = _check_hub(hub_radius_m, _min_dist_to_origin(curve, closed=True))
    exact = 0.5 * twice_area - math.pi * r**2
    n_circle, hub_h = _hub_size(r, exact, sizes)
    crack = _check_crack(crack_xy, crack_tip_size_m, poly, curve, r, sizes, scale)

    def build():
        geo = gmsh.model.geo
        outer, ptags = _add_outline(poly, mids, closed=True)
        c = geo.addPoint(0.0, 0.0, 0.0)
        p0 = geo.addPoint(r, 0.0, 0.0, hub_h)
        bore = _add_arcs(c, r, 0.0, 2 * math.pi, p0, p0, hub_h)
        lo = geo.addCurveLoop(outer)
        lb = geo.addCurveLoop(bore)
        geo.addPlaneSurface([lo, lb])
        if crack is not None:
            tx, ty = crack["tip_xy"]
            crack["mouth"] = ptags[crack["mouth_index"]]
            crack["tip"] = geo.addPoint(float(tx), float(ty), 0.0, crack["tip_size_m"])
            crack["line"] = geo.addLine(crack["mouth"], crack["tip"])
        return {"outer": outer, "bore": bore}

    raw = _run_gmsh(build, sizes, fillet_pts, load_pts, order, n_circle, crack=crack)
    return _finish(raw, order, scale, exact, r, "bore", t0, chain=None if mids is None else (poly, mids))


def _sector(
    outline_xy,
    hub_radius_m,
    angle_from_rad,
    angle_to_rad,
    sizes,
    refine_points_xy,
    fillet_points_xy,
    order,
    ray_tol_rad,
    outline_mid_xy,
):
    """Validated sector geometry: (build, exact area, hub radius, scale, fillet points,
    load points, hub nodes floor, curved chain or None) for :func:`mesh_sector` and
    :func:`mesh_sector_solid`."""
    poly = _as_points(outline_xy, "outline_xy", 2)
    try:
        a0, a1 = float(angle_from_rad), float(angle_to_rad)
    except (TypeError, ValueError):
        raise MeshInputError("angle_from_rad / angle_to_rad must be numbers") from None
    if not (math.isfinite(a0) and math.isfinite(a1)):
        raise MeshInputError(f"sector angles must be finite, got {a0!r}, {a1!r}")
    if not (0.0 < a1 - a0 < 2 * math.pi):
        raise MeshInputError(
            f"sector angles out of order: need 0 < angle_to - angle_from < 2*pi, got angle_from={a0!r}, angle_to={a1!r}"
        )
    scale = float(np.max(np.abs(poly)))
    fillet_pts = _as_refine_points(fillet_points_xy, "fillet_points_xy")
    load_pts = _as_refine_points(refine_points_xy, "refine_points_xy")
    _check_refine(sizes, fillet_pts, load_pts)
    for name, p, a in (("first", poly[0], a0), ("last", poly[-1], a1)):
        ang = math.atan2(p[1], p[0])
        if np.hypot(*p) <= 0 or abs(_wrap(ang - a)) > ray_tol_rad:
            raise MeshInputError(
                f"{name} point of outline_xy {p.tolist()} is not on the ray at {a!r} rad (its polar angle is {ang!r})"
            )
    mids = _as_mids(outline_mid_xy, poly, False, order)
    curve = _with_mids(poly, mids)
    if poly.shape[0] > 1:
        dmin = _min_dist_to_origin(curve, closed=False)
    else:
        dmin = float(np.hypot(*poly[0]))
    r = _check_hub(hub_radius_m, dmin)
    h_from = np.array([r * math.cos(a0), r * math.sin(a0)])
    h_to = np.array([r * math.cos(a1), r * math.sin(a1)])
    # the chord H_to->H_from lies inside the hub disc, the polyline outside:
    # checking this closed polygon covers polyline, cuts and arc
    _check_simple_closed(np.vstack([curve, h_to, h_from]), "sector boundary", scale)
    green = float(np.sum(_cross(poly[:-1], poly[1:]))) + 2.0 * _bulge_area(poly, mids)
    green += float(_cross(poly[-1], h_to) + _cross(h_from, poly[0]))
    exact = 0.5 * green - 0.5 * r**2 * (a1 - a0)
    if exact <= 0:
        raise MeshInputError(
            f"sector region has non-positive area {exact!r} m^2 "
            "(outline_xy must run counter-clockwise from angle_from to angle_to)"
        )

    n_circle, hub_h = _hub_size(r, exact, sizes)

    def build():
        geo = gmsh.model.geo
        outer, ptags = _add_outline(poly, mids, closed=False)
        c = geo.addPoint(0.0, 0.0, 0.0)
        ht = geo.addPoint(float(h_to[0]), float(h_to[1]), 0.0, hub_h)
        hf = geo.addPoint(float(h_from[0]), float(h_from[1]), 0.0, hub_h)
        cut_left = geo.addLine(ptags[-1], ht)
        hub = _add_arcs(c, r, a1, a0, ht, hf, hub_h)  # clockwise, keeps the loop CCW
        cut_right = geo.addLine(hf, ptags[0])
        loop = geo.addCurveLoop(outer + [cut_left] + hub + [cut_right])
        geo.addPlaneSurface([loop])
        return {"outer": outer, "hub_arc": hub, "cut_left": [cut_left], "cut_right": [cut_right]}

    return build, exact, r, scale, fillet_pts, load_pts, n_circle, None if mids is None else (poly, mids)


def mesh_sector(
    outline_xy: np.ndarray,
    hub_radius_m: float,
    angle_from_rad: float,
    angle_to_rad: float,
    sizes: MeshSizes,
    refine_points_xy: np.ndarray | None = None,
    fillet_points_xy: np.ndarray | None = None,
    order: int = 2,
    ray_tol_rad: float = 1e-8,
    outline_mid_xy: np.ndarray | None = None,
) -> GearMesh:
    """Mesh a gear sector bounded by a toothed polyline, two cuts and the hub arc.

    outline_xy      (N,2) m open polyline along the toothed boundary,
                    counter-clockwise (increasing polar angle) from the ray at
                    ``angle_from_rad`` to the ray at ``angle_to_rad`` (first /
                    last point on those rays within ``ray_tol_rad``).
    angle_*_rad     0 < angle_to - angle_from < 2 pi.
    outline_mid_xy  (N-1,2) m, optional: curved edges, as in :func:`mesh_full_gear`.
    Other arguments as in :func:`mesh_full_gear`.

    The cuts are straight lines from the polyline end points to the hub
    circle points at the two angles.  Boundary groups: "outer", "hub_arc",
    "cut_right" (at angle_from) and "cut_left" (at angle_to).  Exact area by
    Green's theorem with the true hub arc (see module docstring).
    """
    t0 = time.perf_counter()
    order = _check_order(order)
    build, exact, r, scale, fillet_pts, load_pts, n_circle, chain = _sector(
        outline_xy,
        hub_radius_m,
        angle_from_rad,
        angle_to_rad,
        sizes,
        refine_points_xy,
        fillet_points_xy,
        order,
        ray_tol_rad,
        outline_mid_xy,
    )
    raw = _run_gmsh(build, sizes, fillet_pts, load_pts, order, n_circle)
    return _finish(raw, order, scale, exact, r, "hub_arc", t0, chain=chain)


@dataclass(frozen=True, eq=False)
class SolidMesh:
    """A gear sector extruded along z (straight 4-node tetrahedra, metres).

    mesh        skfem.MeshTet over the sector x [0, depth_m]; the element layers
                end on the planes ``planes_z_m`` (0 first, depth_m last).
    section     GearMesh of the z = 0 face: Gmsh's surface mesh that the
                extrusion swept, i.e. exactly the triangles of every layer plane
                (order 1, groups as :func:`mesh_sector`).
    boundaries  facet groups of ``mesh`` (indices into mesh.facets): "hub_arc",
                "cut_right", "cut_left" (the swept section groups), "bottom"
                (z = 0), "top" (z = depth_m), "outer" (the swept toothed outline).
    """

    mesh: skfem.MeshTet
    section: GearMesh
    boundaries: dict[str, np.ndarray]
    planes_z_m: np.ndarray
    build_time_s: float = field(default=0.0)

    @property
    def depth_m(self) -> float:
        return float(self.planes_z_m[-1])

    @property
    def n_elements(self) -> int:
        return int(self.mesh.t.shape[1])


def mesh_sector_solid(
    outline_xy: np.ndarray,
    hub_radius_m: float,
    angle_from_rad: float,
    angle_to_rad: float,
    sizes: MeshSizes,
    planes_z_m,
    refine_points_xy: np.ndarray | None = None,
    fillet_points_xy: np.ndarray | None = None,
    ray_tol_rad: float = 1e-8,
) -> SolidMesh:
    """The sector of :func:`mesh_sector` (order 1, straight edges) swept along +z by
    Gmsh's structured extrusion: one element layer between consecutive ``planes_z_m``
    (increasing, from 0), each triangular prism split into three tetrahedra
    (``recombine`` off), so every layer plane carries the section's own triangles.

    The section is meshed by the same Gmsh options and size fields as the 2D meshes
    (one thread, fixed algorithm and seed: deterministic); boundary groups of the solid
    are found from the section groups they sweep and from the planes z = 0 / z = depth.
    """
    t0 = time.perf_counter()
    planes = np.asarray(planes_z_m, dtype=float)
    if (
        planes.ndim != 1
        or len(planes) < 2
        or planes[0] != 0.0
        or np.any(np.diff(planes) <= 0)
        or not np.all(np.isfinite(planes))
    ):
        raise MeshInputError("planes_z_m must increase strictly from 0 (at least two planes)")
    build, exact, r, scale, fillet_pts, load_pts, n_circle, _ = _sector(
        outline_xy,
        hub_radius_m,
        angle_from_rad,
        angle_to_rad,
        sizes,
        refine_points_xy,
        fillet_points_xy,
        1,
        ray_tol_rad,
        None,
    )
    depth = float(planes[-1])
    raw = _run_gmsh(build, sizes, fillet_pts, load_pts, 1, n_circle, extrude=(depth, planes[1:] / depth))
    section = _finish(raw, 1, scale, exact, r, "hub_arc", t0)
    mesh = _tet_mesh(raw["solid"], scale)
    sec = section.mesh
    # a solid facet belongs to the swept section group whose edge its (x, y) corners lie on
    boundaries = _solid_boundaries(mesh, sec, section.boundaries, depth, scale)
    return SolidMesh(mesh, section, boundaries, planes, time.perf_counter() - t0)


def _tet_mesh(raw: dict, scale: float) -> skfem.MeshTet:
    """skfem.MeshTet of Gmsh's 4-node tetrahedra (nodes in Gmsh tag order), each
    element positively oriented."""
    conn = raw["conn"]
    used = np.unique(conn)
    new = np.full(int(used.max()) + 1, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    t = new[conn]
    tag2row = np.full(int(raw["tags"].max()) + 1, -1, dtype=np.int64)
    tag2row[raw["tags"]] = np.arange(raw["tags"].size)
    p = raw["xyz"][tag2row[used]]
    v = p[t]
    vol = np.einsum("ij,ij->i", np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), v[:, 3] - v[:, 0])
    t[vol < 0] = t[vol < 0][:, [0, 2, 1, 3]]
    if np.any(np.abs(vol) <= 1e-15 * scale**3):
        raise MeshError(f"solid mesh has {int(np.sum(np.abs(vol) <= 1e-15 * scale**3))} degenerate tetrahedra")
    return skfem.MeshTet(np.ascontiguousarray(p.T), np.ascontiguousarray(t.T), sort_t=False)


def _solid_boundaries(mesh: skfem.MeshTet, sec, sec_groups: dict, depth: float, scale: float) -> dict:
    """Facet groups of the swept solid: "bottom", "top" by their z, and each section
    group by the section edge under the facet (its corners' (x, y) on one edge)."""
    bf = mesh.boundary_facets()
    xyz = mesh.p[:, mesh.facets[:, bf]]  # (3, 3 corners, n)
    z = xyz[2]
    tol = 1e-9 * scale
    out = {"bottom": bf[np.all(np.abs(z) <= tol, axis=0)], "top": bf[np.all(np.abs(z - depth) <= tol, axis=0)]}
    side = bf[~(np.all(np.abs(z) <= tol, axis=0) | np.all(np.abs(z - depth) <= tol, axis=0))]
    # section vertex of each corner (the solid's nodes lie on the section's vertices in x, y)
    from scipy.spatial import cKDTree

    tree = cKDTree(sec.p.T)
    corners = mesh.facets[:, side]
    d, iv = tree.query(mesh.p[:2, corners.ravel()].T)
    if np.any(d > tol):
        raise MeshError("the solid's nodes do not lie over the section's vertices")
    iv = iv.reshape(corners.shape)
    nv = sec.p.shape[1]
    edge_of = {}
    for name, facets in sec_groups.items():
        e = np.sort(sec.facets[:, facets], axis=0)
        for a, b in e.T:
            edge_of[int(a) * nv + int(b)] = name
    names = []
    for col in iv.T:
        u = np.unique(col)
        if len(u) != 2:
            raise MeshError("a side facet of the solid is not over one section edge")
        names.append(edge_of.get(int(u[0]) * nv + int(u[1])))
    names_a = np.array(names, dtype=object)
    for name in sec_groups:
        out[name] = side[names_a == name]
    if sum(len(v) for v in out.values()) != len(bf):
        raise MeshError("the solid's boundary groups do not cover its boundary")
    return {k: np.asarray(v, dtype=np.int64) for k, v in out.items()}


def _to_meshio(gm: GearMesh, with_lines: bool) -> meshio.Mesh:
    m = gm.mesh
    pts = np.zeros((m.doflocs.shape[1], 3))
    pts[:, :2] = m.doflocs.T
    if gm.order == 2:
        # skfem edge DOFs follow facets (0,1), (1,2), (0,2): the same as the
        # gmsh/VTK 6-node triangle order v0 v1 v2 m01 m12 m20
        cells = [("triangle6", m.dofs.element_dofs.T.astype(np.int64))]
        ltype = "line3"
    else:
        cells = [("triangle", m.t.T.astype(np.int64))]
        ltype = "line"
    phys = [np.full(m.t.shape[1], 1, dtype=np.int64)]
    field_data = {"domain": np.array([1, 2])}
    if with_lines:
        for k, (name, fac) in enumerate(sorted(gm.boundaries.items()), start=2):
            lc = m.facets[:, fac].T.astype(np.int64)
            if gm.order == 2:
                lc = np.hstack([lc, m.dofs.facet_dofs[:, fac].T.astype(np.int64)])
            cells.append((ltype, lc))
            phys.append(np.full(fac.size, k, dtype=np.int64))
            field_data[name] = np.array([k, 1])
    cell_data = {"gmsh:physical": phys, "gmsh:geometrical": [x.copy() for x in phys]}
    return meshio.Mesh(pts, cells, cell_data=cell_data, field_data=field_data)


def write_mesh(gm: GearMesh, path_msh: str | None = None, path_vtu: str | None = None) -> None:
    """Write ``gm`` as gmsh ``.msh`` (v2.2 ASCII, with named physical groups
    for the domain and every boundary) and/or ``.vtu`` (triangles only).

    Each file is written to a temporary name in the target directory and
    moved into place with ``os.replace``, so readers never see partial files.
    """
    if path_msh is not None:
        mm = _to_meshio(gm, with_lines=True)
        atomic_write(path_msh, lambda p: meshio.write(p, mm, file_format="gmsh22", binary=False))
    if path_vtu is not None:
        mv = _to_meshio(gm, with_lines=False)
        mv = meshio.Mesh(mv.points, mv.cells[:1], cell_data={"quality": [triangle_quality(gm)]})
        atomic_write(path_vtu, lambda p: meshio.write(p, mv, file_format="vtu"))
