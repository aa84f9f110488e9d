"""Single-tooth compliance of a spur gear by the finite element method.

Reference model
---------------
The whole gear body with all z teeth (``geometry.mesh.mesh_full_gear``), bore
clamped (u = 0 on r = r_hub), 2D linear elasticity, plane stress by default with
thickness = face width b (``fem.elasticity``). Only tooth 0 (centred on +y) is
loaded. The rim under the loaded tooth is part of the tooth's "foundation" (Weber's
delta_2), so a sector model needs cut conditions that the full gear does not; the
full gear is the reference and no sector is used.

Load positions
--------------
Contact radii R on the loaded (right) flank of tooth 0, equally spaced in roll
angle u (i.e. along the line of action, d = r_b u for the pinion) from the start of
active profile (SAP, ``MeshGeometry.start_of_active_profile_m``) to the contact
whose Hertz patch ends one half-width below the tip corner (see :func:`load_radii`).

Load: a Hertzian pressure patch, not a point force
--------------------------------------------------
A point force makes the 2D displacement log-singular at the load point (the local
solution never converges and pollutes the convergence elsewhere). Each load is the
Hertz line-contact pressure (Johnson, *Contact Mechanics*, 1985, Eqs. 4.43-4.45)

    p(s) = p0 sqrt(1 - s^2 / a^2),  |s| <= a,  p0 = 2 F / (pi a b),
    a = sqrt(4 w R_eq / (pi E*)),   w = F / b,   1 / R_eq = 1 / rho_1 + 1 / rho_2

(s = arc length along the flank from the contact point, rho_i the involute
curvature radii at the LOA position, ``geometry.wear.hertz_half_width``) with the
full normal load F (default T / r_b1 = 568 N at T = 40 N m; the model is linear,
F only sets a, about 56-64 um here). The traction is p e_F, e_F = -(cos w, sin w)
the mesh-force direction of ``geometry.loading`` (the line of action = the inward
nominal involute normal at the contact). On the nominal flank e_F equals the local
inward normal -n up to O(a / rho) ~ 1e-2 rad at the patch edges (symmetric, so the
resultant agrees to O((a / rho)^2)); on a worn flank the local normal tilts by
dh/ds (up to ~0.3 rad where the wear ramps in at the SAP), while the pair model
(``analytic.tvms``) measures compliance along the LOA, so the force is kept on it.

The patch is narrower than the flank elements, so the consistent load vector is
integrated with n-point Gauss-Chebyshev quadrature of the 2nd kind (exact for the
square-root weight; nodes t_k = cos(k pi / (n + 1)), weights
w_k = pi / (n + 1) sin^2(k pi / (n + 1)), sum w_k = pi / 2) through point
evaluation of the shape functions phi on the meshed flank polygon:

    f = (2 F / pi) sum_k w_k e_F phi(x(s_c + a t_k))

which has the exact resultant F e_F (partition of unity). The centre-line
measure below is insensitive to the patch: changing a by a factor 4 (load x 1/4 ..
x 16) changes the compliance by < 0.1 %.

Compliance measure
------------------
The displacement of the tooth centre-line point (0, R) (x = 0 in the tooth frame,
the load radius) projected on e_F:

    c = u(0, R) . e_F / F    [m/N for face width b]
    c [um / (N/mm)] = c [m/N] * 1e6 * b [mm]

It excludes the local contact flattening (the pair model adds it as the Hertzian
delta_3) and is the FE counterpart of Ishikawa's delta_1 + delta_2; the app layer
(``gearwear.stiffness.comparison``) evaluates that and the energy method at the same radii on
the same (worn) profiles, which :class:`ToothFE` carries for it.

Mesh and solution
-----------------
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
The stiffness matrix is factorized once and all positions are solved as
right-hand sides.

Worn flank: by default the *nominal* mesh is morphed (``worn_geometry="morph"``):
the nodes on tooth 0's right flank (vertices and mid-side nodes) move by -h(s) n(s)
onto the worn flank and the interior vertices follow by a harmonic (Laplace)
extension of that displacement, the other mid-side nodes with their edges. Nominal
and worn models then have the same topology by construction, so the wear effect
(0.01-0.12 % of the compliance for 10-30 um, of the order of the 0.03 %
discretisation error of the default level) is not mixed with a change of mesh.
``worn_geometry="remesh"`` meshes the worn outline instead; at the default level
it agrees with the morph to 0.002 % for severe wear.

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
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse.linalg as spla
import skfem
from skfem import Basis, ElementTriP1, asm
from skfem.models.poisson import laplace

from gearwear.core.validation import fail
from gearwear.fem.mesh import GearMesh, MeshError, MeshSizes, inverted_elements, mesh_full_gear
from gearwear.geometry.crack import Crack, crack_mouth_arc
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.loading import load_points
from gearwear.geometry.polyline import cumulative_length, project_to_polyline, quadratic_eval, with_midpoints
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
from gearwear.geometry.wear import WearSpec, flank_depth, hertz_half_width, key_roll_angles

from .elasticity import assemble

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

#: Default transmitted torque (N m) of the paper pair (section 3.1); the default
#: normal load is T / r_b1 (pinion base radius) for either gear.
DEFAULT_TORQUE_NM = 40.0

OTHER_SPACING = 0.2  # polygon spacing of teeth 1 .. z-1, as a fraction of global_m
PATCH_POINTS = 48  # Gauss-Chebyshev points per Hertz patch
# sub-steps per flank edge when measuring arc length on it: a 0.4 mm edge at 14 mm
# curvature radius is 1e-8 relative longer than its 16 sub-chords
EDGE_SUBSTEPS = 16
TIP_MARGIN_HALF_WIDTHS = 2.0  # top load: patch centre 2 a (arc length) below the tip corner
WORN_GEOMETRIES = ("morph", "remesh")
#: default crack-tip element size as a fraction of the fillet size (see tests/test_crack.py
#: for the convergence of the cracked compliance with it)
CRACK_TIP_FRACTION = 0.25


@dataclass
class ToothFE:
    """FE single-tooth compliance at load positions from SAP to tip.

    Arrays have one entry per load position (SI unless the name says otherwise).
    Compliances are in um per (N/mm): deflection per load per unit face width.
    ``timings`` (s): mesh_s, assemble_s (incl. the morph), factorize_s, solve_s
    (load vectors, solves, probes), fem_s (their sum) and total_s (whole call,
    incl. profiles). ``nominal`` and ``loaded`` are the fine source profiles of the
    tooth the model was built from (loaded: its worn right flank, else nominal).
    """

    pair: PairSpec
    gear_index: int
    wear_label: str
    order: int
    plane: str
    mesh_scale: float
    load_N: float
    radius_m: np.ndarray
    roll_rad: np.ndarray
    half_width_m: np.ndarray
    force_direction: np.ndarray  # (n, 2) unit vectors e_F of the applied force
    fem_compliance_um_per_N_per_mm: np.ndarray
    ndofs: int
    n_elements: int
    worn_geometry: str = "morph"
    timings: dict = field(default_factory=dict)
    nominal: ToothProfile | None = None
    loaded: ToothProfile | None = None
    crack: Crack | None = None
    crack_tip_size_m: float | None = None
    crack_mouth_opening_m_per_N: np.ndarray | None = None  # (n,) CMOD per unit load, > 0: open

    @property
    def radius_mm(self) -> np.ndarray:
        return self.radius_m * 1e3

    @property
    def roll_angle_deg(self) -> np.ndarray:
        return np.degrees(self.roll_rad)

    @property
    def wall_s(self) -> float:
        """Wall time of the FE curve: mesh + assemble + factorize + solves (s)."""
        return float(self.timings.get("fem_s", float("nan")))

    def rows(self) -> list[dict]:
        """One dict per load position (units in the keys)."""
        return [
            {
                "radius_mm": float(r),
                "roll_angle_deg": float(u),
                "hertz_half_width_um": float(a * 1e6),
                "fem_compliance_um_per_N_per_mm": float(c),
            }
            for r, u, a, c in zip(
                self.radius_mm, self.roll_angle_deg, self.half_width_m, self.fem_compliance_um_per_N_per_mm
            )
        ]


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


# -- geometry ------------------------------------------------------------------------


def gear_polygon(loaded, nominal, other) -> np.ndarray:
    """Closed CCW outline: tooth 0 with the ``loaded`` right and ``nominal`` left flank,
    teeth 1 .. z-1 from ``other`` (profiles or point arrays; quadratic chains stay
    quadratic chains)."""
    t0, rest = tooth_outline(loaded, nominal), tooth_outline(other)
    return ring_outline(lambda k: t0 if k == 0 else rest, nominal.gear.teeth)


def load_radii(pair: PairSpec, gear_index: int, positions: int, load_N: float) -> tuple[np.ndarray, np.ndarray]:
    """(radii m, roll angles rad) of the load positions: equal roll-angle (LOA) steps
    from the SAP to the contact whose Hertz patch ends one half-width below the tip.

    On the involute the arc length from the base circle is r_b u^2 / 2, so putting
    the patch centre m a_tip below the tip corner (m = TIP_MARGIN_HALF_WIDTHS) gives
    u_top = sqrt(u_a^2 - 2 m a_tip / r_b); the spare half-width keeps the patch off
    the corner of a worn flank too (the corner sinks by h sin(alpha_a) < a).
    """
    g = pair.gear(gear_index)
    mg = MeshGeometry(pair, pair.centre_distance_m)
    rb = g.base_radius_m
    u_sap = math.sqrt((mg.start_of_active_profile_m[gear_index] / rb) ** 2 - 1.0)
    u_a = math.sqrt((g.tip_radius_m / rb) ** 2 - 1.0)
    d_tip = rb * u_a if gear_index == 0 else mg.line_of_action_m - rb * u_a
    a_tip = float(hertz_half_width(mg, np.array([d_tip]), load_N / pair.face_width_m)[0])
    u_top = math.sqrt(u_a**2 - 2.0 * TIP_MARGIN_HALF_WIDTHS * a_tip / rb)
    u = np.linspace(u_sap, u_top, int(positions))
    return rb * np.sqrt(1.0 + u * u), u


# -- mesh helpers ------------------------------------------------------------------


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


def hertz_patch_forces(
    flank: np.ndarray,
    v_lo: int,
    v_hi: int,
    radius_m: np.ndarray,
    half_width_m: np.ndarray,
    force_dir: np.ndarray,
    load_N: float,
    n_points: int = PATCH_POINTS,
):
    """Quadrature points and point forces of the Hertz patches on the meshed flank.

    ``flank`` (m, root -> tip) is the meshed flank as a quadratic chain (its element
    edges, ``geometry.polyline``); the patches must lie between its vertices v_lo and
    v_hi (the involute). Arc length is measured on the edges at EDGE_SUBSTEPS sub-steps
    each. Returns (points (n, k, 2), forces (n, k, 2)): points on the edges' curves at
    arc distance a t_k from the contact point at radius R, moved 1e-9 m along the
    inward normal so the element search never misses; forces (2 F / pi) w_k e_F.
    """
    u_poly = np.arange((len(flank) - 1) // 2 * EDGE_SUBSTEPS + 1) / EDGE_SUBSTEPS
    xy_poly = quadratic_eval(flank, u_poly)[0]
    s_poly = cumulative_length(xy_poly)
    s_lo, s_hi = s_poly[v_lo * EDGE_SUBSTEPS], s_poly[v_hi * EDGE_SUBSTEPS]
    r_poly = np.hypot(xy_poly[:, 0], xy_poly[:, 1])
    sel = (s_poly >= s_lo - 1e-12) & (s_poly <= s_hi + 1e-12)
    if np.any(np.diff(r_poly[sel]) <= 0):
        raise ValueError("the meshed flank radius is not monotone on the involute (wear too deep?)")
    t, w = _patch_nodes(n_points)
    s_c = np.interp(radius_m, r_poly[sel], s_poly[sel])
    s_k = s_c[:, None] + half_width_m[:, None] * t[None, :]
    if np.any(s_k < s_lo) or np.any(s_k > s_hi):
        raise ValueError(
            "a Hertz patch leaves the involute part of the flank (load too close to the tip "
            "corner or below the form circle)"
        )
    xy, tan = quadratic_eval(flank, np.interp(s_k, s_poly, u_poly))
    pts = xy + 1e-9 * np.stack([-tan[..., 1], tan[..., 0]], axis=-1)  # inward = left of the root -> tip tangent
    mag = load_N * (2.0 / np.pi) * w[None, :] * np.ones_like(s_k)
    return pts, mag[..., None] * force_dir[:, None, :]


def patch_load(model, pts: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """Consistent nodal forces (N, n) of the point forces ``forces`` (n, k, 2) at
    ``pts`` (n, k, 2) of :func:`hertz_patch_forces`, one column per position, on the 2D
    ``model`` (``fem.elasticity.ElasticModel``)."""
    n, k = pts.shape[:2]
    P = model.probe(pts.reshape(-1, 2))  # rows 2 j, 2 j + 1: x, y at point j
    G = np.zeros((2 * n * k, n))
    col = np.repeat(np.arange(n), k)
    G[0::2][np.arange(n * k), col] = forces.reshape(-1, 2)[:, 0]
    G[1::2][np.arange(n * k), col] = forces.reshape(-1, 2)[:, 1]
    return np.asarray(P.T @ G)


def _patch_nodes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Chebyshev (2nd kind): int_-1^1 sqrt(1 - t^2) f(t) dt ~ sum_k w_k f(t_k)."""
    k = np.arange(1, n + 1)
    th = k * np.pi / (n + 1)
    return np.cos(th), np.pi / (n + 1) * np.sin(th) ** 2


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


# -- main ---------------------------------------------------------------------------


def single_tooth_compliance(
    pair: PairSpec,
    gear_index: int = 0,
    wear: WearSpec | None = None,
    positions: int = 21,
    order: int = 2,
    plane: str = "stress",
    mesh_scale: float = 1.0,
    load_N: float | None = None,
    worn_geometry: str = "morph",
    radii_m=None,
    read_at: str = "radius",
    crack: Crack | None = None,
    crack_tip_size_m: float | None = None,
) -> ToothFE:
    """FE compliance of tooth 0 of gear ``gear_index`` (0 pinion, 1 gear) on the full gear.

    wear           None / unworn: nominal tooth. Otherwise the loaded (right) flank of
                   tooth 0 is worn by ``geometry.wear.flank_depth`` on the nominal mesh
                   geometry; all other flanks stay nominal.
    positions      number of load positions, SAP to tip (>= 2).
    order          1 or 2 (Lagrange P1 / P2 triangles).
    plane          "stress" (default) or "strain".
    mesh_scale     multiplies every element size (1 = default level).
    load_N         normal load (N); default T / r_b1 at T = 40 N m. Only sets the Hertz
                   half-width (linear model).
    worn_geometry  "morph" (default: nominal mesh moved onto the worn flank) or
                   "remesh" (mesh the worn outline).
    radii_m        load radii (m) instead of ``positions`` equal roll steps (the pair
                   FE's consistency check reads the single tooth at its own contacts).
    read_at        "radius": the centre-line point (0, R) (default); "load_line": the
                   centre-line point where the load line crosses it, (0, y_c) of
                   geometry.loading (where Weber's h ends; fem.pair's c_1, c_2).
    crack          a straight root crack on tooth 0's loaded flank (``geometry.crack``),
                   meshed as a cut with free faces (:func:`tooth_mesh`); None: intact.
    crack_tip_size_m  element size at the crack tip (m; default
                   :func:`default_crack_tip_size_m`).

    With a crack, ``crack_mouth_opening_m_per_N`` is the mouth opening per unit load,
    (u_upper - u_lower) . n / F, n the unit normal of the crack line toward the tooth
    (upper) side, from the two coincident mouth nodes: > 0 means the faces separate.

    Returns a :class:`ToothFE`: compliance in um per (N/mm) at every position, the
    profiles the model was built from, dofs, elements and wall times (the analytic
    reference at the same radii: gearwear.stiffness.comparison.tooth_vs_analytic).
    """
    t_start = time.perf_counter()
    if radii_m is None and positions < 2:
        raise fail("positions", str(positions), "", "need at least 2")
    if read_at not in ("radius", "load_line"):
        raise fail("read_at", repr(read_at), "", "must be 'radius' or 'load_line'")
    g = pair.gear(gear_index)
    mg = MeshGeometry(pair, pair.centre_distance_m)
    b = pair.face_width_m
    if load_N is None:
        load_N = DEFAULT_TORQUE_NM / pair.gear(0).base_radius_m
    if not (math.isfinite(load_N) and load_N > 0):
        raise fail("load_N", repr(load_N), "", "must be finite and > 0")

    # -- load positions, Hertz half-widths, force directions (geometry.loading on the true flank)
    rb = g.base_radius_m
    if radii_m is None:
        R, u = load_radii(pair, gear_index, positions, load_N)
    else:
        R = np.atleast_1d(np.asarray(radii_m, dtype=float))
        u = np.sqrt(np.maximum((R / rb) ** 2 - 1.0, 0.0))
    d = rb * u if gear_index == 0 else mg.line_of_action_m - rb * u
    a = hertz_half_width(mg, d, load_N / b)

    tm = tooth_mesh(
        pair,
        gear_index,
        wear,
        order=order,
        mesh_scale=mesh_scale,
        load_radii_m=R,
        worn_geometry=worn_geometry,
        crack=crack,
        crack_tip_size_m=crack_tip_size_m,
    )
    mesh, gm = tm.mesh, tm.gear_mesh
    lp = load_points(tm.loaded, R)
    e_F = -np.column_stack([np.cos(lp.w_rad), np.sin(lp.w_rad)])

    model = assemble(mesh, g.material, b, gm.boundaries["bore"], plane=plane, order=order)

    # -- loads: Hertz patches on the meshed (curved) flank, all positions as right-hand sides
    t0 = time.perf_counter()
    flank, v_lo, v_hi = tm.flank_curve()
    pts, forces = hertz_patch_forces(flank, v_lo, v_hi, R, a, e_F, load_N)
    n, k = pts.shape[:2]
    F = patch_load(model, pts, forces)
    U = model.solve(F)
    yq = lp.y_axis_m if read_at == "load_line" else R
    Q = model.probe(np.column_stack([np.zeros_like(R), yq]))
    uc = np.asarray(Q @ U)  # (2 n, n): column i is position i's solution
    idx = np.arange(n)
    ui = np.column_stack([uc[2 * idx, idx], uc[2 * idx + 1, idx]])
    c_m_per_N = np.einsum("ij,ij->i", ui, e_F) / load_N
    cmod = None if crack is None else crack_mouth_opening(tm, model.basis, U) / load_N
    t_solve = time.perf_counter() - t0

    to_um_per_N_per_mm = 1e6 * b * 1e3
    timings = {
        "mesh_s": tm.mesh_s,
        "assemble_s": model.timings["assemble_s"] + tm.morph_s,
        "factorize_s": model.timings["factorize_s"],
        "solve_s": t_solve,
    }
    timings["fem_s"] = sum(timings.values())
    timings["total_s"] = time.perf_counter() - t_start
    return ToothFE(
        pair=pair,
        gear_index=gear_index,
        wear_label=wear.label if wear is not None else "unworn",
        order=order,
        plane=plane,
        mesh_scale=float(mesh_scale),
        load_N=float(load_N),
        radius_m=R,
        roll_rad=u,
        half_width_m=a,
        force_direction=e_F,
        fem_compliance_um_per_N_per_mm=c_m_per_N * to_um_per_N_per_mm,
        ndofs=int(model.ndofs),
        n_elements=int(gm.n_elements),
        worn_geometry=tm.worn_geometry,
        timings=timings,
        nominal=tm.nominal,
        loaded=tm.loaded,
        crack=crack,
        crack_tip_size_m=(
            None
            if crack is None
            else float(default_crack_tip_size_m(crack, mesh_scale) if crack_tip_size_m is None else crack_tip_size_m)
        ),
        crack_mouth_opening_m_per_N=cmod,
    )


def crack_mouth_pair(tm: ToothMesh) -> tuple[int, int, np.ndarray]:
    """(upper, lower, n): the two coincident mesh vertices at the crack mouth, the one
    of the elements on the tooth side of the crack line first, and that side's unit
    normal n of the crack line (m-free)."""
    mesh = tm.mesh
    assert tm.crack_xy is not None, "the tooth mesh has no crack"
    mouth, tip = tm.crack_xy
    d = (tip - mouth) / np.linalg.norm(tip - mouth)
    n = np.array([d[1], -d[0]])  # d turned by -90 deg: toward the tooth above the crack
    if n[1] < 0:
        n = -n
    p = mesh.p[:, : mesh.nvertices]
    at = np.flatnonzero(np.linalg.norm(p.T - mouth, axis=1) <= 1e-9 * np.linalg.norm(mouth))
    if len(at) != 2:
        raise RuntimeError(f"the crack mouth has {len(at)} mesh vertices, expected 2 (an open crack)")
    side = []
    for v in at:
        els = np.flatnonzero(np.any(mesh.t[:3] == v, axis=0))
        c = p[:, mesh.t[:3, els]].mean(axis=1).T  # element centroids
        side.append(float(np.mean((c - mouth) @ n)))
    up, lo = (at[0], at[1]) if side[0] > side[1] else (at[1], at[0])
    return int(up), int(lo), n


def crack_mouth_opening(tm: ToothMesh, basis, U: np.ndarray) -> np.ndarray:
    """Crack mouth opening displacement (u_upper - u_lower) . n (m) for every column
    of the solution matrix ``U`` (one per load case); see :func:`crack_mouth_pair`."""
    up, lo, n = crack_mouth_pair(tm)
    du = U[basis.nodal_dofs[:, up]] - U[basis.nodal_dofs[:, lo]]  # (2, n_cases)
    return n @ du
