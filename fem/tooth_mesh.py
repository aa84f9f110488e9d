"""The meshed full gear of the FE single tooth (``fem.tooth``): element sizes, the outline
with curved edges, the worn flank and the root-crack cut.

Units: SI (m). Element sizes (:func:`mesh_sizes`) and the crack-tip size
(:func:`default_crack_tip_size_m`) are in m; :func:`tooth_mesh` returns a :class:`ToothMesh`.

Mesh
----
One mesh for all positions: tooth 0 is sampled at its element size (``load_m``
on the involute and tip, ``fillet_m`` on the fillets and root lands), both fillets
and the whole active flank are refined, the other teeth are sampled at
0.2 ``global_m``. The element sizes, the size gradient and the boundary sampling
scale with ``mesh_scale`` (the size field h(x) becomes mesh_scale x h(x)). With P2
(order 2) every outline edge also carries the point of the true curve at half its
arc length, Gmsh meshes the edge as the parabola through the three points, and
the analysis uses Gmsh's 6-node triangles as they are (isoparametric, mid-side
nodes on the curve): the boundary follows the involute and fillet to ~1 nm
(the 1 nm source polyline, ``geometry.sampling.FINE_SAG_M``) instead of the chord
sag h^2 / (8 rho) of straight edges (1.4 um on the involute, 10 um in the fillet at
0.4 mm). P1 (order 1) keeps straight edges, their sag part of the h-refinement.

Worn flank: ``worn_geometry="morph"`` (default) moves the nominal mesh onto the worn
flank (``fem.tooth_flank``), so nominal and worn models have the same topology;
``worn_geometry="remesh"`` meshes the worn outline instead.

Root crack
----------
``crack=`` (``geometry.crack.Crack``: depth q, angle nu to the centre line) puts a
straight crack on tooth 0's loaded fillet, from the ISO 6336-3 30-deg point inward and
downward, as a true cut: the mouth becomes an outline vertex, the crack line is an
embedded curve whose nodes Gmsh's Crack plugin duplicates (``fem.mesh``), so both
faces are free and can separate or slide; nothing models contact of the faces
(the loaded flank's fillet is the tension side, where the crack opens: the mouth
opening per unit load, ``ToothFE.crack_mouth_opening_m_per_N``, is > 0). The tip is
refined to ``crack_tip_size_m`` (default 1/4 of the fillet size or of the depth).
Measured on the paper pinion at the default level, 1 mm crack at 45 deg
(tests/test_crack.py): tip sizes 0.2, 0.05, 0.0125 mm change the compliance by
0.15, 0.11, 0.12 % then 0.02, 0.06, 0.03 % (SAP, mid, top: observed order 0.5-1.5,
about 1 as a r^(1/2) tip field gives), a 0.05 mm crack is within 0.04 % of the intact
tooth, and 0.5, 1, 2 mm raise the compliance by about 2, 7 and 20 %. This is 1.8-6.3
times the increase of the analytic reduced-section model (``analytic.energy``,
``analytic.ishikawa``), which leaves out the crack's own rotational flexibility at
the root.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import skfem

from gearwear.core.validation import fail
from gearwear.fem.mesh import GearMesh, MeshSizes, mesh_full_gear
from gearwear.geometry.crack import Crack, crack_mouth_arc
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.polyline import with_midpoints
from gearwear.geometry.profile import (
    FILLET,
    INVOLUTE,
    ROOT_LAND,
    TIP_LAND,
    ToothProfile,
    ring_outline,
    tooth_outline,
    tooth_profile,
)
from gearwear.geometry.sampling import FINE_SAG_M, profile_at, region_junctions, resample_profile
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec, flank_depth, key_roll_angles

from .tooth_flank import _flank_nodes, morph_to_worn

#: Element sizes at mesh_scale = 1 (m); the sizes, the size gradient and the
#: boundary sampling are multiplied by mesh_scale (see mesh_sizes). Chosen with
#: fem.convergence: at scale 1 (49.8k P2 dofs, curved 6-node elements) the
#: compliance is within 0.03 % of the Richardson extrapolation at every position
#: (observed order 4.0; 0.13 % and order 2.5 with straight-edged elements), differs
#: from the 1/sqrt(2) level by < 0.03 %, and the 21-position curve takes 1.2-1.6 s
#: on 2 cores.
GLOBAL_M = 4.0e-3
LOAD_M = 0.40e-3
FILLET_M = 0.40e-3
GROWTH = 0.3
FILLET_DIST_M = 1.2e-3
LOAD_DIST_M = 1.2e-3

OTHER_SPACING = 0.2  # polygon spacing of teeth 1 .. z-1, as a fraction of global_m
WORN_GEOMETRIES = ("morph", "remesh")
#: default crack-tip element size as a fraction of the fillet size (see tests/test_crack.py
#: for the convergence of the cracked compliance with it)
CRACK_TIP_FRACTION = 0.25


def mesh_sizes(mesh_scale: float = 1.0) -> MeshSizes:
    """Element sizes at ``mesh_scale``: the size field h(x) becomes mesh_scale x h(x).

    Gmsh's threshold field is h(d) = min(global, fine + growth (d - dist)) at distance
    d from a refinement point, so scaling global, fine and growth by s and keeping the
    fine-zone radius dist scales it exactly (scaling dist too would leave the graded
    zone, most of the elements, unrefined)."""
    s = float(mesh_scale)
    if not (math.isfinite(s) and s > 0):
        raise fail("mesh_scale", repr(mesh_scale), "", "must be finite and > 0")
    return MeshSizes(
        global_m=GLOBAL_M * s,
        fillet_m=FILLET_M * s,
        load_m=LOAD_M * s,
        fillet_dist_m=FILLET_DIST_M,
        load_dist_m=LOAD_DIST_M,
        growth=GROWTH * s,
    )


def gear_polygon(loaded, nominal, other) -> np.ndarray:
    """Closed CCW outline: tooth 0 with the ``loaded`` right and ``nominal`` left flank,
    teeth 1 .. z-1 from ``other`` (profiles or point arrays; quadratic chains stay
    quadratic chains)."""
    t0, rest = tooth_outline(loaded, nominal), tooth_outline(other)
    return ring_outline(lambda k: t0 if k == 0 else rest, nominal.gear.teeth)


@dataclass
class ToothMesh:
    """The meshed gear of :func:`tooth_mesh` (SI units).

    mesh            the analysis mesh: Gmsh's 6-node triangles (order 2, curved
                    boundary, ``fem.mesh.CurvedMeshTri2``) or 3-node ones (order 1),
                    morphed onto the worn flank when worn_geometry == "morph"
    gear_mesh       the Gmsh result (boundaries "bore", "outer" index mesh.facets)
    nominal, loaded fine source profiles of tooth 0 (loaded = worn right flank or nominal)
    meshed_poly     the resampled right flank that was meshed (order 2: a quadratic
                    chain, vertex, edge mid-point, vertex, ...)
    flank_nodes     mesh nodes (``mesh.doflocs`` indices) on tooth 0's right flank,
                    root -> tip: vertices and, order 2, the mid-side nodes between
    flank_node_s    their profile arc parameter s (m), as on ``nominal``/``loaded``
    crack, crack_xy the root crack of tooth 0 and its (mouth, tip) in the mesh (m),
                    None without one; its faces are ``gear_mesh.boundaries["crack"]``
    """

    mesh: skfem.Mesh
    gear_mesh: GearMesh
    nominal: ToothProfile
    loaded: ToothProfile
    meshed_poly: ToothProfile
    flank_nodes: np.ndarray
    flank_node_s: np.ndarray
    worn_geometry: str
    mesh_s: float
    morph_s: float
    crack: Crack | None = None
    crack_xy: np.ndarray | None = None

    @property
    def flank_vertices(self) -> np.ndarray:
        """Mesh vertices on tooth 0's right flank, root -> tip."""
        return self.flank_nodes[self.flank_nodes < self.mesh.nvertices]

    @property
    def flank_s(self) -> np.ndarray:
        """Profile arc parameter s (m) of :attr:`flank_vertices`."""
        return self.flank_node_s[self.flank_nodes < self.mesh.nvertices]

    def flank_curve(self) -> tuple[np.ndarray, int, int]:
        """The meshed flank as it is in the analysis mesh, root -> tip, as a quadratic
        chain (order 1: straight edges), and the first and last vertex of its
        involute (vertex k is chain point 2 k)."""
        xy = self.mesh.doflocs[:, self.flank_nodes].T
        v = self.flank_nodes < self.mesh.nvertices
        if np.all(v):  # straight edges: the mid-points are the chord centres
            chain = np.empty((2 * len(xy) - 1, 2))
            chain[0::2], chain[1::2] = xy, 0.5 * (xy[:-1] + xy[1:])
            vs = self.flank_node_s
        else:
            if not (np.all(v[0::2]) and not np.any(v[1::2]) and v[-1]):
                raise RuntimeError("the flank nodes do not alternate vertex / mid-side node")
            chain, vs = xy, self.flank_node_s[0::2]
        poly = self.meshed_poly
        k_inv = np.flatnonzero(poly.region == INVOLUTE)
        eps = 1e-9 * poly.gear.tip_radius_m
        on_inv = np.flatnonzero((vs >= poly.s[k_inv[0]] - eps) & (vs <= poly.s[k_inv[-1]] + eps))
        return chain, int(on_inv[0]), int(on_inv[-1])


def tooth_mesh(
    pair: PairSpec,
    gear_index: int = 0,
    wear: WearSpec | None = None,
    order: int = 2,
    mesh_scale: float = 1.0,
    load_radii_m=None,
    worn_geometry: str = "morph",
    crack: Crack | None = None,
    crack_tip_size_m: float | None = None,
) -> ToothMesh:
    """Mesh the full gear for loads on tooth 0's right flank.

    Tooth 0 is sampled at its element size (``load_m`` on the involute and tip land,
    ``fillet_m`` on fillets and root lands), the other teeth at OTHER_SPACING x
    global_m, all with curved edges for order 2. Refined: the flank from 2 load_m
    below the lowest to load_m above the highest of ``load_radii_m`` (default: SAP to
    tip) and both fillets of tooth 0.

    ``crack``: a straight root crack on tooth 0's loaded flank (``geometry.crack``),
    meshed as a cut with two free faces (``fem.mesh.mesh_full_gear(crack_xy=...)``):
    the mouth is made an outline vertex (the nearest non-junction fillet vertex moves
    onto it, or it is inserted), the tip is refined to ``crack_tip_size_m`` (default
    :func:`default_crack_tip_size_m`). Not combined with wear.
    """
    if crack is not None and wear is not None and not wear.is_unworn:
        raise ValueError("crack with a worn flank: not supported (mesh the crack on the nominal tooth)")
    if order not in (1, 2):
        raise fail("order", str(order), "", "must be 1 or 2")
    if worn_geometry not in WORN_GEOMETRIES:
        raise fail("worn_geometry", repr(worn_geometry), "", f"must be one of {WORN_GEOMETRIES}")
    g = pair.gear(gear_index)
    mg = MeshGeometry(pair, pair.centre_distance_m)
    sizes = mesh_sizes(mesh_scale)
    worn = wear is not None and not wear.is_unworn
    # the polygons come from a wear-independent source, so every wear state of a level
    # gets the identical nominal mesh; the worn flank is sampled with the wear peaks
    base = tooth_profile(g, sag_m=FINE_SAG_M, extra_roll=key_roll_angles(mg, gear_index))
    nominal = tooth_profile(g, sag_m=FINE_SAG_M, extra_roll=key_roll_angles(mg, gear_index, wear)) if worn else base
    loaded = nominal.worn(flank_depth(nominal, gear_index, mg, wear)) if worn and wear else nominal
    spacing = {ROOT_LAND: sizes.fillet_m, FILLET: sizes.fillet_m, INVOLUTE: sizes.load_m, TIP_LAND: sizes.load_m}
    # order 2: every outline edge carries its arc mid-point, Gmsh meshes it as the
    # quadratic through the three points and puts its mid-side nodes on the curve
    quad = order == 2
    crack_xy = None
    if crack is None:
        nominal_poly = resample_profile(base, spacing, midpoints=quad)
    else:
        nominal_poly, crack_xy = _with_crack_mouth(base, spacing, quad, crack)
    remesh = worn and worn_geometry == "remesh"
    meshed_poly = resample_profile(loaded, spacing, midpoints=quad) if remesh else nominal_poly
    other = resample_profile(base, {r: OTHER_SPACING * sizes.global_m for r in spacing}, midpoints=quad)
    outline = gear_polygon(meshed_poly, nominal_poly, other)
    step = 2 if quad else 1  # the vertices of a quadratic chain

    if load_radii_m is None:
        load_radii_m = [mg.start_of_active_profile_m[gear_index], g.tip_radius_m]
    R = np.sort(np.atleast_1d(np.asarray(load_radii_m, dtype=float)))
    inv = np.flatnonzero(meshed_poly.region == INVOLUTE)
    s_c = np.interp(R, meshed_poly.radius[inv], meshed_poly.s[inv])
    load_m = float(sizes.load_m or sizes.global_m)  # mesh_sizes always sets load_m
    s_ref = np.arange(s_c[0] - 2 * load_m, s_c[-1] + load_m, 0.5 * load_m)
    refine = np.column_stack([np.interp(s_ref, meshed_poly.s, meshed_poly.xy[:, k]) for k in (0, 1)])
    vert = nominal_poly.xy[::step]
    reg = nominal_poly.region[::step]
    fil = vert[(reg == FILLET) | (reg == ROOT_LAND)]
    fillets = np.vstack([fil, fil * np.array([-1.0, 1.0])])
    t0 = time.perf_counter()
    if crack is None:
        gm = mesh_full_gear(
            outline[::step],
            g.hub_radius_m,
            sizes,
            refine_points_xy=refine,
            fillet_points_xy=fillets,
            order=order,
            outline_mid_xy=outline[1::2] if quad else None,
        )
    else:
        tip_m = default_crack_tip_size_m(crack, mesh_scale) if crack_tip_size_m is None else crack_tip_size_m
        gm = mesh_full_gear(
            outline[::step],
            g.hub_radius_m,
            sizes,
            refine_points_xy=refine,
            fillet_points_xy=fillets,
            order=order,
            outline_mid_xy=outline[1::2] if quad else None,
            crack_xy=crack_xy,
            crack_tip_size_m=tip_m,
        )
    t_mesh = time.perf_counter() - t0

    # the meshed flank of tooth 0: its nodes sorted root -> tip, with their profile
    # parameter; vertices lie on the source polyline, Gmsh's own nodes on the
    # quadratic edges within ~1e-8 m of it, every other node >= one spacing away
    t0 = time.perf_counter()
    mesh = gm.mesh
    nodes, s_n = _flank_nodes(
        mesh, gm.boundaries["outer"], loaded if remesh else nominal, 1e-3 * mesh_scale * min(LOAD_M, FILLET_M)
    )
    if crack is not None:  # the open crack mouth is two coincident nodes: keep one on the flank chain
        xy = mesh.doflocs[:, nodes].T
        keep = np.concatenate([[True], np.linalg.norm(np.diff(xy, axis=0), axis=1) > 1e-12 * g.tip_radius_m])
        nodes, s_n = nodes[keep], s_n[keep]
    if worn and not remesh:  # same topology as the nominal model
        mesh = morph_to_worn(
            mesh, np.concatenate([gm.boundaries["outer"], gm.boundaries["bore"]]), nodes, s_n, nominal, loaded
        )
    return ToothMesh(
        mesh=mesh,
        gear_mesh=gm,
        nominal=nominal,
        loaded=loaded,
        meshed_poly=meshed_poly,
        flank_nodes=nodes,
        flank_node_s=s_n,
        worn_geometry=(worn_geometry if worn else "nominal"),
        mesh_s=t_mesh,
        morph_s=time.perf_counter() - t0,
        crack=crack,
        crack_xy=crack_xy,
    )


def default_crack_tip_size_m(crack: Crack, mesh_scale: float = 1.0, fillet_m: float | None = None) -> float:
    """Default crack-tip element size (m): CRACK_TIP_FRACTION x the fillet size
    (``fillet_m``, by default the single tooth's at ``mesh_scale``; the pair bodies pass
    theirs), and at most that fraction of the crack depth (so a short crack still has
    several elements along it)."""
    fillet = mesh_sizes(mesh_scale).fillet_m if fillet_m is None else fillet_m
    assert fillet is not None  # mesh_sizes always sets it
    return CRACK_TIP_FRACTION * min(fillet, float(crack.depth_m))


def _with_crack_mouth(base: ToothProfile, spacing: dict, quad: bool, crack: Crack):
    """(resampled right flank, crack_xy): ``resample_profile`` with the crack mouth as
    a vertex, and the crack's (mouth vertex, tip) (m). The nearest vertex moves onto
    the mouth unless it is a region junction or an end (then the mouth is inserted),
    so the edges next to it stay between half and 1.5 spacings long."""
    mouth, tip, s_m = crack_mouth_arc(base, crack)
    sn = resample_profile(base, spacing).s
    k = int(np.argmin(np.abs(sn - s_m)))
    fixed = base.s[region_junctions(base)]
    if np.min(np.abs(fixed - sn[k])) <= 1e-12 * base.s[-1]:
        sn = np.sort(np.concatenate([sn, [s_m]]))
    else:
        sn = sn.copy()
        sn[k] = s_m
    poly = profile_at(base, with_midpoints(sn) if quad else sn)
    v = poly.xy[::2] if quad else poly.xy
    mouth_v = v[int(np.argmin(np.abs((poly.s[::2] if quad else poly.s) - s_m)))]
    return poly, np.array([mouth_v, tip])
