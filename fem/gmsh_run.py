"""One Gmsh run, headless, deterministic and serialised: the session (fresh model, fixed
options, one thread, fixed seed, a process-wide lock since gmsh is a singleton), the
background size field, the outline and bore curves, the optional crack, and the extraction of
nodes, elements and named boundaries. Returns raw arrays; ``fem.mesh_checks`` turns them into a
checked scikit-fem mesh."""

from __future__ import annotations

import itertools
import math
import threading
from contextlib import contextmanager
from typing import Iterator

import gmsh
import numpy as np

from gearwear.core import interrupts

from .mesh_spec import MeshError, MeshSizes
from .outline import _vertex_sizes

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


def _add_size_fields(
    sizes: MeshSizes,
    point_tags: dict[str, list[int]],
    curve_tags: list[int],
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


def _run_gmsh(
    build,
    sizes,
    fillet_pts,
    load_pts,
    order,
    n_circle,
    crack: dict | None = None,
    extrude: tuple[float, np.ndarray] | None = None,
) -> dict:
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
                geo.extrude(
                    [(2, surface)],
                    0.0,
                    0.0,
                    float(depth),
                    numElements=[1] * len(fractions),
                    heights=[float(f) for f in fractions],
                    recombine=False,
                )
                geo.synchronize()
            if crack is None:
                _add_size_fields(sizes, point_tags, [c for v in groups.values() for c in v])
            else:
                _add_size_fields(
                    sizes,
                    point_tags,
                    [c for k, v in groups.items() if k != "crack" for c in v],
                    crack_tip=(crack["tip"], crack["tip_size_m"]),
                )
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
    gmsh.option.setNumber("Mesh.HighOrderOptimize", 2)  # elastic + optimization
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
    return {
        "conn": conn,
        "tags": np.asarray(tags, dtype=np.int64),
        "xyz": np.asarray(coords, dtype=np.float64).reshape(-1, 3),
    }


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


def _add_arcs(center: int, r: float, a0: float, a1: float, start: int | None, end: int | None, size: float):
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
