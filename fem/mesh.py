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
``MeshError``          every input or meshing failure (a ``ValueError``)

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

import itertools
import math
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterator

import gmsh
import meshio
import numpy as np
import skfem

from gearwear.core import interrupts
from gearwear.core.atomic import atomic_write
from gearwear.geometry.polyline import project_to_segments

__all__ = [
    "MeshError",
    "MeshSizes",
    "GearMesh",
    "mesh_full_gear",
    "mesh_sector",
    "write_mesh",
    "triangle_quality",
]


class MeshError(ValueError):
    """Invalid geometry / sizes, or a meshing failure (one-line message)."""


# ---------------------------------------------------------------------------
# data classes
# ---------------------------------------------------------------------------


def _positive(name: str, value: float | None, allow_none: bool = False) -> float | None:
    """``value`` as a finite float > 0 (or None if allowed); MeshError naming ``name``."""
    if value is None:
        if allow_none:
            return None
        raise MeshError(f"{name} must be given, got None")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise MeshError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(v) and v > 0.0):
        raise MeshError(f"{name} must be finite and > 0, got {value!r}")
    return v


@dataclass(frozen=True)
class MeshSizes:
    """Target element sizes (edge lengths, metres) and refinement extents.

    Refinement is a Distance+Threshold field per feature, combined with a Min
    field: within ``*_dist_m`` of a refinement point the size is the fine
    size; beyond it the size grows linearly with slope ``growth`` (metres of
    size per metre of distance) until it reaches ``global_m``.

    global_m     size far from all features (also the upper size cap).
    fillet_m     size near the points passed as ``fillet_points_xy`` (tooth
                 root fillets, where bending stress peaks); None = no fillet
                 refinement.
    load_m       size near ``refine_points_xy`` (load / contact points, where
                 Hertzian contact stresses need resolving); None = none.
    fillet_dist_m, load_dist_m
                 radius of the uniformly fine zone; None = 4 x the fine size.
    growth       size gradient outside the fine zone (dimensionless, > 0);
                 0.25 keeps neighbouring elements within ~25 % of each other.
    """

    global_m: float
    fillet_m: float | None = None
    load_m: float | None = None
    fillet_dist_m: float | None = None
    load_dist_m: float | None = None
    growth: float = 0.25

    def __post_init__(self) -> None:
        _positive("MeshSizes.global_m", self.global_m)
        _positive("MeshSizes.fillet_m", self.fillet_m, allow_none=True)
        _positive("MeshSizes.load_m", self.load_m, allow_none=True)
        _positive("MeshSizes.fillet_dist_m", self.fillet_dist_m, allow_none=True)
        _positive("MeshSizes.load_dist_m", self.load_dist_m, allow_none=True)
        _positive("MeshSizes.growth", self.growth)
        for name in ("fillet_m", "load_m"):
            v = getattr(self, name)
            if v is not None and v > self.global_m:
                raise MeshError(
                    f"MeshSizes.{name}={v!r} is larger than global_m={self.global_m!r}"
                )


@dataclass(frozen=True, eq=False)
class GearMesh:
    """A meshed gear body.

    mesh           CurvedMeshTri2 (order 2) or skfem.MeshTri (order 1);
                   coordinates in metres, all elements counter-clockwise.
                   ``mesh.boundaries`` holds the same facet groups.
    boundaries     facet-index arrays (indices into ``mesh.facets``):
                   full gear: "bore" (hub circle), "outer" (toothed polygon);
                   sector: "hub_arc", "outer", "cut_right" (radial cut at
                   angle_from, on the right when looking outward from the
                   centre), "cut_left" (radial cut at angle_to).
    area_m2        area of the meshed region, by exact quadrature of the
                   isoparametric (P2) or affine (P1) element geometry.
    exact_area_m2  exact area of the intended region (true circular bore; see
                   module docstring).
    order          geometric order (1 or 2).
    n_elements     number of triangles.
    build_time_s   wall time spent in gmsh + conversion (informational).
    """

    mesh: "skfem.MeshTri2"
    boundaries: dict[str, np.ndarray]
    area_m2: float
    exact_area_m2: float
    hub_radius_m: float
    order: int
    build_time_s: float = field(default=0.0)

    @property
    def n_elements(self) -> int:
        return int(self.mesh.t.shape[1])

    @property
    def area_rel_error(self) -> float:
        return abs(self.area_m2 - self.exact_area_m2) / self.exact_area_m2


# ---------------------------------------------------------------------------
# input validation (pure numpy)
# ---------------------------------------------------------------------------


def _as_points(a, name: str, min_points: int) -> np.ndarray:
    try:
        p = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise MeshError(f"{name} must be an (N,2) array of floats") from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise MeshError(f"{name} must have shape (N,2), got {p.shape}")
    if p.shape[0] < min_points:
        raise MeshError(f"{name} needs at least {min_points} points, got {p.shape[0]}")
    if not np.all(np.isfinite(p)):
        i = int(np.nonzero(~np.all(np.isfinite(p), axis=1))[0][0])
        raise MeshError(f"{name} has a non-finite point at index {i}: {p[i].tolist()}")
    return p


def _as_refine_points(a, name: str) -> np.ndarray:
    if a is None:
        return np.zeros((0, 2))
    p = np.asarray(a, dtype=np.float64)
    if p.ndim == 1 and p.shape == (2,):
        p = p[None, :]
    if p.size == 0:
        return np.zeros((0, 2))
    return _as_points(p, name, 1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _check_simple_closed(poly: np.ndarray, name: str, scale: float) -> None:
    """Raise MeshError if the closed polygon has degenerate or crossing edges.

    Sweep-and-prune on x, exact orientation tests on the surviving pairs:
    about 0.1 s for 12 000 vertices of a gear outline.
    """
    n = poly.shape[0]
    a = poly
    b = np.roll(poly, -1, axis=0)
    tol = 1e-9 * scale
    seg_len = np.linalg.norm(b - a, axis=1)
    if np.any(seg_len <= tol):
        i = int(np.argmax(seg_len <= tol))
        raise MeshError(
            f"{name}: zero-length edge (duplicate consecutive points) at index {i}: "
            f"{a[i].tolist()}"
            + (" (do not repeat the first point at the end)" if i == n - 1 else "")
        )
    # adjacent edges folding back onto each other (a spike of zero width)
    d0 = b - a
    d1 = np.roll(d0, -1, axis=0)
    cr = _cross(d0, d1)
    dt = np.einsum("ij,ij->i", d0, d1)
    fold = (np.abs(cr) <= 1e-12 * seg_len * np.roll(seg_len, -1)) & (dt < 0)
    if np.any(fold):
        i = int(np.argmax(fold))
        raise MeshError(f"{name}: edges fold back on themselves at vertex {(i + 1) % n}")
    if n <= 3:
        return
    lo = np.minimum(a, b) - tol
    hi = np.maximum(a, b) + tol
    # sweep along x: after sorting by lo_x, the only possible partners of a
    # segment are the following ones whose lo_x <= its hi_x
    order = np.argsort(lo[:, 0], kind="stable")
    slo = lo[order, 0]
    last = np.searchsorted(slo, hi[order, 0], side="right")  # exclusive
    counts = np.maximum(last - np.arange(n) - 1, 0)
    csum = np.cumsum(counts)
    s0 = 0
    while s0 < n:
        # blocks of at most ~2e6 candidate pairs keep memory bounded
        base = csum[s0 - 1] if s0 else 0
        s1 = max(s0 + 1, int(np.searchsorted(csum, base + 2_000_000, side="right")))
        s1 = min(s1, n)
        c = counts[s0:s1]
        tot = int(c.sum())
        if tot:
            ps = np.repeat(np.arange(s0, s1), c)
            off = np.arange(tot) - np.repeat(np.cumsum(c) - c, c)
            i = order[ps]
            j = order[ps + 1 + off]
            keep = (lo[i, 1] <= hi[j, 1]) & (hi[i, 1] >= lo[j, 1])
            d = np.abs(i - j)
            keep &= (d != 1) & (d != n - 1)  # neighbours share a vertex
            _raise_if_crossing(a, b, i[keep], j[keep], tol, name)
        s0 = s1


def _raise_if_crossing(a, b, gi, jc, tol, name) -> None:
    if gi.size == 0:
        return
    p1, p2, q1, q2 = a[gi], b[gi], a[jc], b[jc]
    o1 = _cross(q2 - q1, p1 - q1)
    o2 = _cross(q2 - q1, p2 - q1)
    o3 = _cross(p2 - p1, q1 - p1)
    o4 = _cross(p2 - p1, q2 - p1)
    proper = (o1 * o2 < 0) & (o3 * o4 < 0)
    dmin = np.minimum.reduce(
        [
            project_to_segments(p1, q1, q2)[1],
            project_to_segments(p2, q1, q2)[1],
            project_to_segments(q1, p1, p2)[1],
            project_to_segments(q2, p1, p2)[1],
        ]
    )
    bad = proper | (dmin <= tol)
    if np.any(bad):
        k = int(np.argmax(bad))
        e1, e2 = sorted((int(gi[k]), int(jc[k])))
        raise MeshError(
            f"{name} is self-intersecting: edge {e1} ({a[e1].tolist()}->{b[e1].tolist()}) "
            f"meets edge {e2} ({a[e2].tolist()}->{b[e2].tolist()})"
        )


def _min_dist_to_origin(poly: np.ndarray, closed: bool) -> float:
    a = poly
    b = np.roll(poly, -1, axis=0) if closed else poly[1:]
    if not closed:
        a = poly[:-1]
    return float(np.min(project_to_segments(np.zeros_like(a), a, b)[1]))


def _origin_inside(poly: np.ndarray) -> bool:
    # crossing-number test on the ray +x from the origin
    a = poly
    b = np.roll(poly, -1, axis=0)
    crosses = (a[:, 1] > 0) != (b[:, 1] > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = a[:, 0] + (0.0 - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return bool(np.count_nonzero(crosses & (x > 0)) % 2 == 1)


def _check_hub(hub_radius_m: float, dmin: float) -> float:
    r = float(_positive("hub_radius_m", hub_radius_m) or 0.0)
    if r >= dmin:
        raise MeshError(
            f"hub_radius_m={r!r} is not strictly inside the outline "
            f"(minimum distance of the outline from the origin is {dmin!r})"
        )
    return r


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


# ---------------------------------------------------------------------------
# gmsh session handling
# ---------------------------------------------------------------------------

# Meshes whose worst corner triangle is below this normalised radius ratio are
# rejected: Frontal-Delaunay gives > 0.3 on sane input, so anything this low
# means the geometry has a gap narrower than the requested element size.
MIN_QUALITY = 0.05

_GMSH_LOCK = threading.RLock()  # gmsh is a process-global singleton: serialise
_MODEL_COUNTER = itertools.count()

# Options that make meshing headless, deterministic and background-field ruled.
_BASE_OPTIONS: dict[str, float] = {
    "General.Terminal": 0,
    "General.Verbosity": 1,  # errors only (they come back as exceptions)
    "General.NumThreads": 1,
    "Mesh.MaxNumThreads1D": 1,
    "Mesh.MaxNumThreads2D": 1,
    "Mesh.RandomSeed": 1,
    "Mesh.RandomFactor": 1e-9,
    "Mesh.Algorithm": 6,  # Frontal-Delaunay: best-shaped triangles in 2D
    # a curved outline edge is one element like a straight one unless the size
    # field asks for more (gmsh's default puts at least 2 on every curved curve)
    "Mesh.MinimumCurveNodes": 2,
    # relative accuracy of the size integral along a curve (default 1e-9): at 1e-6 the
    # 1D mesh of 1300 curved outline edges takes 0.3 s instead of 0.8 s
    "Mesh.LcIntegrationPrecision": 1e-6,
    # point sizes are set deliberately (outline spacing, hub spacing) so that
    # the straight cuts of a sector grade from the fine outline to the hub
    "Mesh.MeshSizeFromPoints": 1,
    "Mesh.MeshSizeExtendFromBoundary": 0,  # the background field rules
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeMin": 0,
    "Mesh.SecondOrderLinear": 0,  # P2 bore mid-nodes on the true circle
    "Mesh.HighOrderOptimize": 0,
    "Mesh.ElementOrder": 1,
    "Mesh.RecombineAll": 0,
    "Mesh.SaveAll": 0,
}


@contextmanager
def _gmsh_session(options: dict[str, float]) -> Iterator[None]:
    """Fresh gmsh model with our options; always cleaned up.

    If gmsh was not initialised we own the session and finalise it (also on
    exceptions). If a caller already initialised gmsh we work in a private
    model, then remove it, restore their current model and every option we
    touched, and leave gmsh initialised.
    """
    with _GMSH_LOCK:
        owned = not gmsh.isInitialized()
        saved: dict[str, float] = {}
        prev_model = None
        if owned:
            gmsh.initialize(readConfigFiles=False, interruptible=False)
            interrupts.rearm()  # Gmsh resets SIGINT and SIGTERM to their default actions
        else:
            try:
                prev_model = gmsh.model.getCurrent()
            except Exception:
                prev_model = None
        name = f"gearwear_mesh_{next(_MODEL_COUNTER)}"
        try:
            for k, v in options.items():
                if not owned:
                    saved[k] = gmsh.option.getNumber(k)
                gmsh.option.setNumber(k, v)
            gmsh.model.add(name)
            yield
        finally:
            if owned:
                gmsh.finalize()
                interrupts.rearm()
            else:
                try:
                    gmsh.model.setCurrent(name)
                    gmsh.model.remove()
                except Exception:
                    pass
                for k, v in saved.items():
                    try:
                        gmsh.option.setNumber(k, v)
                    except Exception:
                        pass
                if prev_model is not None:
                    try:
                        gmsh.model.setCurrent(prev_model)
                    except Exception:
                        pass


def _first_line(exc: BaseException) -> str:
    s = str(exc).strip().splitlines()
    return s[0] if s else type(exc).__name__


# ---------------------------------------------------------------------------
# geometry + fields in gmsh
# ---------------------------------------------------------------------------


def _add_size_fields(
    sizes: MeshSizes, point_tags: dict[str, list[int]], curve_tags: list[int],
    crack_tip: tuple[int, float] | None = None,
) -> None:
    """Distance+Threshold per refinement kind, Min with a constant global size.

    ``crack_tip`` = (point tag, size): one more Threshold, ``size`` within 2 ``size``
    of the tip, then growing with ``sizes.growth``: the fine zone scales with the tip
    size, so refining it refines the crack-tip mesh self-similarly."""
    fld = gmsh.model.mesh.field
    thresholds = []
    # The polygon edges are mesh edges, so the boundary is at least as fine
    # as the outline spacing.  Grade from that spacing into the interior at
    # the same rate as the refinement zones; without it a dense outline next
    # to global-size interior elements produces slivers.
    ext = fld.add("Extend")
    fld.setNumbers(ext, "CurvesList", curve_tags)
    fld.setNumber(ext, "DistMax", float(sizes.global_m) / sizes.growth)
    fld.setNumber(ext, "SizeMax", float(sizes.global_m))
    fld.setNumber(ext, "Power", 1.0)
    thresholds.append(ext)
    for kind, fine, dist in (
        ("fillet", sizes.fillet_m, sizes.fillet_dist_m),
        ("load", sizes.load_m, sizes.load_dist_m),
    ):
        tags = point_tags.get(kind, [])
        if fine is None or not tags:
            continue
        d = fld.add("Distance")
        fld.setNumbers(d, "PointsList", tags)
        th = fld.add("Threshold")
        dmin = 4.0 * fine if dist is None else float(dist)
        fld.setNumber(th, "InField", d)
        fld.setNumber(th, "SizeMin", float(fine))
        fld.setNumber(th, "SizeMax", float(sizes.global_m))
        fld.setNumber(th, "DistMin", dmin)
        fld.setNumber(th, "DistMax", dmin + (sizes.global_m - fine) / sizes.growth)
        thresholds.append(th)
    if crack_tip is not None:
        tag, fine = crack_tip
        d = fld.add("Distance")
        fld.setNumbers(d, "PointsList", [tag])
        th = fld.add("Threshold")
        fld.setNumber(th, "InField", d)
        fld.setNumber(th, "SizeMin", float(fine))
        fld.setNumber(th, "SizeMax", float(sizes.global_m))
        fld.setNumber(th, "DistMin", 2.0 * fine)
        fld.setNumber(th, "DistMax", 2.0 * fine + (sizes.global_m - fine) / sizes.growth)
        thresholds.append(th)
    const = fld.add("MathEval")
    fld.setString(const, "F", repr(float(sizes.global_m)))
    mn = fld.add("Min")
    fld.setNumbers(mn, "FieldsList", thresholds + [const])
    fld.setAsBackgroundMesh(mn)


def _circle_nodes_floor(r_hub: float, exact_area: float) -> int:
    # per-segment P2 defect r^2 phi^5/30 with N segments per full circle ->
    # total pi^5 r^2 / (30 N^4); keep it below 1e-8 * exact_area.
    n = (math.pi**5 * r_hub**2 / (30.0 * 1e-8 * exact_area)) ** 0.25
    return int(max(16, math.ceil(n)))


def _run_gmsh(build, sizes, fillet_pts, load_pts, order, n_circle, crack: dict | None = None,
              extrude: tuple[float, np.ndarray] | None = None) -> dict:
    """Build geometry via ``build()`` (returns {group: [curve tags]}), mesh, extract.

    Every curve not listed under a group other than "outer" is "outer".

    ``crack``: filled by ``build()`` with the tags of the crack line ("line"), its mouth
    on the outline ("mouth") and its tip ("tip"), plus the tip size ("tip_size_m").
    The line is embedded in the surface (its 1D mesh edges become element edges) and,
    after the element order is set, Gmsh's Crack plugin duplicates its nodes: the
    elements on one side get the copies, so the two crack faces are separate boundary
    edges. The mouth is in the plugin's OpenBoundaryPhysicalGroup (duplicated too: the
    crack opens onto the outline), the tip is not (the faces meet there). The faces
    form the boundary group "crack".
    """
    options = dict(_BASE_OPTIONS)
    options["Mesh.MeshSizeMax"] = float(sizes.global_m)
    options["Mesh.MinimumCircleNodes"] = int(n_circle)
    try:
        with _gmsh_session(options):
            groups = build()
            # free geometric points: only the Distance fields see them, they
            # are not embedded in the surface (no forced mesh nodes)
            geo = gmsh.model.geo
            g = float(sizes.global_m)
            point_tags = {
                "fillet": [geo.addPoint(float(x), float(y), 0.0, g) for x, y in fillet_pts],
                "load": [geo.addPoint(float(x), float(y), 0.0, g) for x, y in load_pts],
            }
            geo.synchronize()  # once: it is slow for thousands of curves
            surface = None
            if extrude is not None:
                surface = gmsh.model.getEntities(2)[0][1]
                depth, fractions = extrude
                geo.extrude([(2, surface)], 0.0, 0.0, float(depth), numElements=[1] * len(fractions),
                            heights=[float(f) for f in fractions], recombine=False)
                geo.synchronize()
            if crack is None:
                _add_size_fields(sizes, point_tags, [c for v in groups.values() for c in v])
            else:
                _add_size_fields(sizes, point_tags, [c for k, v in groups.items() if k != "crack" for c in v],
                                 crack_tip=(crack["tip"], crack["tip_size_m"]))
                surface = gmsh.model.getEntities(2)[0][1]
                gmsh.model.mesh.embed(1, [crack["line"]], 2, surface)
            gmsh.model.mesh.generate(2 if extrude is None else 3)
            if order == 2:
                gmsh.model.mesh.setOrder(2)
                _untangle_curved()
            if crack is not None:
                groups["crack"] = _split_crack(crack["line"], crack["mouth"])
            raw = _extract(groups, order, surface)
            if extrude is not None:
                raw["solid"] = _extract_tets()
            return raw
    except MeshError:
        raise
    except Exception as exc:  # gmsh raises plain Exception; keep one line
        raise MeshError(f"gmsh failed to mesh the gear body: {_first_line(exc)}") from None


def _untangle_curved() -> None:
    """Where a P2 element folded (its mid-side nodes on a curved outline bulge past its
    interior corner: a thin element under a tightly curved fillet), let Gmsh's high-order
    optimizer move the interior nodes until every element is valid (scaled Jacobian > 0).
    Meshes without a fold are left exactly as they are (the optimizer is not run)."""
    types, etags, _ = gmsh.model.mesh.getElements(dim=2)
    tags = np.concatenate([np.asarray(t, dtype=np.int64) for t in etags]) if len(etags) else np.zeros(0, np.int64)
    if tags.size == 0:
        return
    q = np.asarray(gmsh.model.mesh.getElementQualities(tags, "minSJ"))
    if np.all(q > 0):
        return
    gmsh.option.setNumber("Mesh.HighOrderOptimize", 2)   # elastic + optimization
    gmsh.model.mesh.optimize("HighOrder")


def _split_crack(line: int, mouth: int) -> list[int]:
    """Run Gmsh's Crack plugin on the embedded curve ``line`` (mouth point ``mouth`` open);
    returns the curve tags of both crack faces (the original curve and the plugin's new
    discrete one, which holds the duplicated nodes)."""
    before = {t for _, t in gmsh.model.getEntities(1)}
    pg = gmsh.model.addPhysicalGroup(1, [line])
    po = gmsh.model.addPhysicalGroup(0, [mouth])
    plugin = gmsh.plugin
    plugin.setNumber("Crack", "Dimension", 1)
    plugin.setNumber("Crack", "PhysicalGroup", pg)
    plugin.setNumber("Crack", "OpenBoundaryPhysicalGroup", po)
    plugin.setNumber("Crack", "NormalX", 0.0)
    plugin.setNumber("Crack", "NormalY", 0.0)
    plugin.setNumber("Crack", "NormalZ", 1.0)
    plugin.setNumber("Crack", "NewPhysicalGroup", 0)
    plugin.run("Crack")
    new = sorted({t for _, t in gmsh.model.getEntities(1)} - before)
    if len(new) != 1:
        raise MeshError(f"gmsh's Crack plugin made {len(new)} new curves, expected 1")
    return [line] + new


def _extract(groups: dict[str, list[int]], order: int, surface: int | None = None) -> dict:
    """Triangles and boundary-group edges of the meshed surface (``surface``: only that
    surface and the edges of the group curves, as in a swept model)."""
    etype = 9 if order == 2 else 2  # 6-node / 3-node triangle
    nper = 6 if order == 2 else 3
    types, _, node_tags = gmsh.model.mesh.getElements(dim=2, tag=-1 if surface is None else surface)
    conn = []
    for ty, nt in zip(types, node_tags):
        if ty != etype:
            raise MeshError(f"gmsh produced unexpected 2D element type {int(ty)}")
        conn.append(np.asarray(nt, dtype=np.int64).reshape(-1, nper))
    if not conn or sum(c.shape[0] for c in conn) == 0:
        raise MeshError("gmsh produced no triangles (boundary recovery failed?)")
    conn_all = np.vstack(conn)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    tags = np.asarray(tags, dtype=np.int64)
    xyz = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    # one query for all boundary edges, then per-curve queries only for the
    # few non-polygon curves; "outer" is the remainder (thousands of curves)
    nl = 3 if order == 2 else 2
    if surface is None:
        _, ltags, lnt = gmsh.model.mesh.getElements(dim=1)
    else:
        per = [gmsh.model.mesh.getElements(dim=1, tag=c) for v in groups.values() for c in v]
        ltags = [x for _, et, _ in per for x in et]
        lnt = [x for _, _, nt in per for x in nt]
    all_tags = np.zeros(0, np.int64)
    all_nodes = np.zeros((0, nl), np.int64)
    if len(ltags):
        all_tags = np.concatenate([np.asarray(x, dtype=np.int64) for x in ltags])
        all_nodes = np.vstack([np.asarray(x, dtype=np.int64).reshape(-1, nl) for x in lnt])
    lines = {}
    claimed = []
    for gname, ctags in groups.items():
        if gname == "outer":
            continue
        parts: list[np.ndarray] = []
        for c in ctags:
            _, et, _ = gmsh.model.mesh.getElements(dim=1, tag=c)
            parts.extend(np.asarray(x, dtype=np.int64) for x in et)
        et = np.concatenate(parts) if parts else np.zeros(0, np.int64)
        claimed.append(et)
        lines[gname] = all_nodes[np.isin(all_tags, et), :2]
    rest = ~np.isin(all_tags, np.concatenate(claimed)) if claimed else np.ones(all_tags.size, bool)
    lines["outer"] = all_nodes[rest, :2]
    return {"conn": conn_all, "tags": tags, "xyz": xyz, "lines": lines}


def _extract_tets() -> dict:
    """4-node tetrahedra of the meshed volume and all node coordinates."""
    types, _, node_tags = gmsh.model.mesh.getElements(dim=3)
    if any(int(ty) != 4 for ty in types) or not len(types):
        raise MeshError(f"gmsh produced 3D element types {[int(t) for t in types]}, expected tetrahedra (4)")
    conn = np.vstack([np.asarray(nt, dtype=np.int64).reshape(-1, 4) for nt in node_tags])
    tags, coords, _ = gmsh.model.mesh.getNodes()
    return {"conn": conn, "tags": np.asarray(tags, dtype=np.int64),
            "xyz": np.asarray(coords, dtype=np.float64).reshape(-1, 3)}


# ---------------------------------------------------------------------------
# conversion to scikit-fem
# ---------------------------------------------------------------------------


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
                vi = np.concatenate([violation(pts[:, i:i + 1], np.arange(j, min(j + 4096, nel))[None])[0]
                                     for j in range(0, nel, 4096)])
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
    sa = _cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    bad = sa <= 0
    if x.shape[1] == 6:
        bad |= np.any(_p2_dets(x) <= 0, axis=0)
    return bad



def _p2_dets(x: np.ndarray) -> np.ndarray:
    """det J of the 6-node isoparametric map (nodes [v0, v1, v2, m01, m12, m20]; x:
    (nel, 6, 2)) at the corners, the edge mid-points and the centroid: (7, nel)."""
    out = []
    for xi, eta in ((0, 0), (1, 0), (0, 1), (.5, 0), (.5, .5), (0, .5), (1 / 3, 1 / 3)):
        l0 = 1.0 - xi - eta
        # dN/dxi, dN/deta for nodes [v0, v1, v2, m01, m12, m20]
        dxi = np.array([-(4 * l0 - 1), 4 * xi - 1, 0.0, 4 * (l0 - xi), 4 * eta, -4 * eta])
        deta = np.array([-(4 * l0 - 1), 0.0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l0 - eta)])
        jx = np.einsum("k,ekd->ed", dxi, x)
        je = np.einsum("k,ekd->ed", deta, x)
        out.append(jx[:, 0] * je[:, 1] - jx[:, 1] * je[:, 0])
    return np.stack(out)


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
        raise MeshError(
            f"mesh has {int(np.count_nonzero(sa <= 1e-14 * scale ** 2))} degenerate triangles"
        )

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
        mesh = skfem.MeshTri(
            np.ascontiguousarray(pts.T), np.ascontiguousarray(t.T), sort_t=False
        )

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
    x = (1 - t) ** 2 * a + 2 * t * (1 - t) * c + t ** 2 * b
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
    m0 = np.where(np.isfinite(mids), mids, 0.5 * (a0 + b0))   # a straight edge: m the midpoint
    c0 = 2.0 * m0 - 0.5 * (a0 + b0)
    f = np.asarray(facets)
    pa, pb = mesh.p[:, mesh.facets[0, f]].T, mesh.p[:, mesh.facets[1, f]].T
    pm = mesh.doflocs[:, mesh.nvertices + f].T
    # the edge of each facet: the one of (nearest edge midpoint's edge and its two
    # neighbours) its mid-side node lies on, the piece of the curve between its ends
    from scipy.spatial import cKDTree
    ts = np.linspace(0.0, 1.0, 17)
    samples = _bezier(np.repeat(a0, ts.size, 0), np.repeat(c0, ts.size, 0), np.repeat(b0, ts.size, 0),
                      np.tile(ts, ne))[0]
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
        raise MeshError(f"an outline node of the mesh is {off[k]:.3g} m off its curve near "
                        f"{(pm[k] * 1e3).round(3).tolist()} mm")
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


def _check_order(order) -> int:
    if order not in (1, 2):
        raise MeshError(f"order must be 1 or 2, got {order!r}")
    return int(order)


def _check_refine(sizes, fillet_pts, load_pts) -> None:
    if not isinstance(sizes, MeshSizes):
        raise MeshError(f"sizes must be a MeshSizes, got {type(sizes).__name__}")
    if fillet_pts.shape[0] and sizes.fillet_m is None:
        raise MeshError("fillet_points_xy given but sizes.fillet_m is None")
    if load_pts.shape[0] and sizes.load_m is None:
        raise MeshError("refine_points_xy given but sizes.load_m is None")


def _vertex_sizes(poly: np.ndarray, closed: bool) -> np.ndarray:
    """Longest adjacent edge per vertex: never splits an outline edge, but
    gives the end of a cut line the local outline spacing."""
    b = np.roll(poly, -1, axis=0) if closed else poly[1:]
    a = poly if closed else poly[:-1]
    L = np.linalg.norm(b - a, axis=1)
    if closed:
        return np.maximum(L, np.roll(L, 1))
    out = np.empty(poly.shape[0])
    out[0], out[-1] = L[0], L[-1]
    out[1:-1] = np.maximum(L[:-1], L[1:])
    return out


def _as_mids(mids, poly: np.ndarray, closed: bool, order: int) -> np.ndarray | None:
    """Mid-points (n_edges, 2) of the outline edges, NaN rows for straight edges."""
    if mids is None:
        return None
    if order != 2:
        raise MeshError("outline_mid_xy needs order 2 (a curved edge is a quadratic element edge)")
    ne = len(poly) if closed else len(poly) - 1
    try:
        m = np.asarray(mids, dtype=np.float64)
    except (TypeError, ValueError):
        raise MeshError("outline_mid_xy must be an (N,2) array of floats") from None
    if m.shape != (ne, 2):
        raise MeshError(f"outline_mid_xy must have shape ({ne}, 2) (one point per outline edge), got {m.shape}")
    fin = np.isfinite(m)
    if np.any(fin[:, 0] != fin[:, 1]):
        raise MeshError("outline_mid_xy: a row must be two numbers or two NaNs (straight edge)")
    a, b = poly[:ne], np.roll(poly, -1, axis=0)[:ne]
    off = np.linalg.norm(m - 0.5 * (a + b), axis=1)
    # beyond a quarter of the chord the quadratic edge bends too far to be meshed
    bad = fin[:, 0] & (off > 0.25 * np.linalg.norm(b - a, axis=1))
    if np.any(bad):
        i = int(np.argmax(bad))
        raise MeshError(f"outline_mid_xy[{i}] = {m[i].tolist()} is more than a quarter of its edge "
                        "away from the edge's midpoint")
    return m


def _with_mids(poly: np.ndarray, mids: np.ndarray | None) -> np.ndarray:
    """The outline with the finite mid-points inserted (a finer polygon of the curve)."""
    if mids is None:
        return poly
    ne = len(mids)
    rows = [poly[:1]]
    for i in range(ne):
        if np.isfinite(mids[i, 0]):
            rows.append(mids[i:i + 1])
        if i + 1 < len(poly):
            rows.append(poly[i + 1:i + 2])
    return np.vstack(rows)


def _bulge_area(poly: np.ndarray, mids: np.ndarray | None) -> float:
    """Area between the chords and the quadratic edges x(t) = a + t (b - a) + 4 t (1 - t) e,
    e = mid - (a + b) / 2, each (2/3) cross(e, b - a) (positive outward of a CCW
    boundary)."""
    if mids is None:
        return 0.0
    ne = len(mids)
    a, b = poly[:ne], np.roll(poly, -1, axis=0)[:ne]
    e = mids - 0.5 * (a + b)
    fin = np.isfinite(e[:, 0])
    return float(2.0 / 3.0 * np.sum(_cross(e[fin], (b - a)[fin])))


def _add_outline(poly: np.ndarray, mids: np.ndarray | None, closed: bool) -> tuple[list[int], list[int]]:
    """The outline in gmsh, (curve tags, point tags): a point per vertex carrying the
    local outline spacing, and one curve per edge, a line or a quadratic Bezier curve through the edge's
    mid-point (control point 2 m - (a + b) / 2 puts B(1/2) on m), so Gmsh's
    second-order nodes lie on the curve, not on the chord."""
    geo = gmsh.model.geo
    sizes = _vertex_sizes(poly, closed)
    ptags = [geo.addPoint(float(x), float(y), 0.0, float(h)) for (x, y), h in zip(poly, sizes)]
    n = len(ptags)
    curves = []
    for i in range(n if closed else n - 1):
        j = (i + 1) % n
        if mids is None or not np.isfinite(mids[i, 0]):
            curves.append(geo.addLine(ptags[i], ptags[j]))
            continue
        c = 2.0 * mids[i] - 0.5 * (poly[i] + poly[j])
        pc = geo.addPoint(float(c[0]), float(c[1]), 0.0, float(sizes[i]))
        curves.append(geo.addBezier([ptags[i], pc, ptags[j]]))
    return curves, ptags


def _hub_size(r: float, exact_area: float, sizes: MeshSizes) -> tuple[int, float]:
    """(minimum number of hub-circle nodes, hub element size)."""
    n_circle = _circle_nodes_floor(r, exact_area)
    return n_circle, min(float(sizes.global_m), 2 * math.pi * r / n_circle)


def _add_arcs(center: int, r: float, a0: float, a1: float, start: int | None,
              end: int | None, size: float):
    """Circle arcs from angle a0 to a1 (either direction), each <= 90 deg."""
    geo = gmsh.model.geo
    n = max(1, int(math.ceil(abs(a1 - a0) / (math.pi / 2) - 1e-12)))
    angs = np.linspace(a0, a1, n + 1)
    pts = []
    for k, a in enumerate(angs):
        if k == 0 and start is not None:
            pts.append(start)
        elif k == n and end is not None:
            pts.append(end)
        else:
            pts.append(geo.addPoint(r * math.cos(a), r * math.sin(a), 0.0, size))
    return [geo.addCircleArc(pts[k], center, pts[k + 1]) for k in range(n)]


# ---------------------------------------------------------------------------
# public API
# ---------------------------------------------------------------------------


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
        raise MeshError("outline_xy is degenerate (all points at the origin)")
    fillet_pts = _as_refine_points(fillet_points_xy, "fillet_points_xy")
    load_pts = _as_refine_points(refine_points_xy, "refine_points_xy")
    _check_refine(sizes, fillet_pts, load_pts)
    mids = _as_mids(outline_mid_xy, poly, True, order)
    curve = _with_mids(poly, mids)
    _check_simple_closed(curve, "outline_xy", scale)
    twice_area = float(np.sum(_cross(poly, np.roll(poly, -1, axis=0)))) + 2.0 * _bulge_area(poly, mids)
    if twice_area <= 0:
        raise MeshError(
            f"outline_xy must be counter-clockwise (signed area {twice_area / 2!r} m^2 <= 0)"
        )
    if not _origin_inside(curve):
        raise MeshError("outline_xy does not enclose the origin (gear must be centred)")
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


def _check_crack(crack_xy, tip_size, poly, curve, r_hub, sizes, scale) -> dict | None:
    """Validated crack data for :func:`mesh_full_gear` (None without a crack): the
    mouth must be an outline point (so the crack line starts on the boundary), the tip
    strictly inside the region (inside the outline, outside the bore)."""
    if crack_xy is None:
        if tip_size is not None:
            raise MeshError("crack_tip_size_m given without crack_xy")
        return None
    c = _as_points(crack_xy, "crack_xy", 2)
    if c.shape != (2, 2):
        raise MeshError(f"crack_xy must have shape (2,2) (mouth, tip), got {c.shape}")
    d = np.hypot(poly[:, 0] - c[0, 0], poly[:, 1] - c[0, 1])
    i = int(np.argmin(d))
    if d[i] > 1e-12 * scale:
        raise MeshError(f"crack_xy mouth {c[0].tolist()} is not an outline point (nearest at {d[i]!r} m)")
    if not (_origin_inside(curve - c[1]) and math.hypot(*c[1]) > r_hub):
        raise MeshError(f"crack_xy tip {c[1].tolist()} is not inside the meshed region")
    if float(np.hypot(*(c[1] - c[0]))) <= 1e-9 * scale:
        raise MeshError("crack_xy: the crack has zero length")
    default = sizes.fillet_m if sizes.fillet_m is not None else sizes.global_m
    h = _positive("crack_tip_size_m", default if tip_size is None else tip_size)
    assert h is not None  # _positive returns its value unless allow_none
    if h > sizes.global_m:
        raise MeshError(f"crack_tip_size_m={h!r} is larger than global_m={sizes.global_m!r}")
    return {"mouth_index": i, "tip_xy": c[1].copy(), "tip_size_m": float(h)}


def _sector(outline_xy, hub_radius_m, angle_from_rad, angle_to_rad, sizes, refine_points_xy,
            fillet_points_xy, order, ray_tol_rad, outline_mid_xy):
    """Validated sector geometry: (build, exact area, hub radius, scale, fillet points,
    load points, hub nodes floor, curved chain or None) for :func:`mesh_sector` and
    :func:`mesh_sector_solid`."""
    poly = _as_points(outline_xy, "outline_xy", 2)
    try:
        a0, a1 = float(angle_from_rad), float(angle_to_rad)
    except (TypeError, ValueError):
        raise MeshError("angle_from_rad / angle_to_rad must be numbers") from None
    if not (math.isfinite(a0) and math.isfinite(a1)):
        raise MeshError(f"sector angles must be finite, got {a0!r}, {a1!r}")
    if not (0.0 < a1 - a0 < 2 * math.pi):
        raise MeshError(
            f"sector angles out of order: need 0 < angle_to - angle_from < 2*pi, "
            f"got angle_from={a0!r}, angle_to={a1!r}"
        )
    scale = float(np.max(np.abs(poly)))
    fillet_pts = _as_refine_points(fillet_points_xy, "fillet_points_xy")
    load_pts = _as_refine_points(refine_points_xy, "refine_points_xy")
    _check_refine(sizes, fillet_pts, load_pts)
    for name, p, a in (("first", poly[0], a0), ("last", poly[-1], a1)):
        ang = math.atan2(p[1], p[0])
        if np.hypot(*p) <= 0 or abs(_wrap(ang - a)) > ray_tol_rad:
            raise MeshError(
                f"{name} point of outline_xy {p.tolist()} is not on the ray at "
                f"{a!r} rad (its polar angle is {ang!r})"
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
        raise MeshError(
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
        outline_xy, hub_radius_m, angle_from_rad, angle_to_rad, sizes, refine_points_xy, fillet_points_xy,
        order, ray_tol_rad, outline_mid_xy)
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
    if planes.ndim != 1 or len(planes) < 2 or planes[0] != 0.0 or np.any(np.diff(planes) <= 0) \
            or not np.all(np.isfinite(planes)):
        raise MeshError("planes_z_m must increase strictly from 0 (at least two planes)")
    build, exact, r, scale, fillet_pts, load_pts, n_circle, _ = _sector(
        outline_xy, hub_radius_m, angle_from_rad, angle_to_rad, sizes, refine_points_xy, fillet_points_xy,
        1, ray_tol_rad, None)
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
    if np.any(np.abs(vol) <= 1e-15 * scale ** 3):
        raise MeshError(f"solid mesh has {int(np.sum(np.abs(vol) <= 1e-15 * scale ** 3))} degenerate tetrahedra")
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
        mv = meshio.Mesh(mv.points, mv.cells[:1],
                         cell_data={"quality": [triangle_quality(gm)]})
        atomic_write(path_vtu, lambda p: meshio.write(p, mv, file_format="vtu"))
