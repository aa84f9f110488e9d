"""Gear bodies for resolved FE pair contact: mesh, Schur-complement flexibility of
the drive flank, and reading/loading vectors (SI units: m, N, rad, Pa).

One full gear per distinct gear of a pair (all z teeth, Gmsh's curved 6-node
triangles used as isoparametric P2 elements, plane stress by default, thickness =
face width b, bore fixed). Tooth 0 (centred on +y, drive flank x > 0) has its
drive flank sampled and refined to the contact element size h_c over the whole
candidate range (a margin below the start of active profile up to and including
the tip corner); Gmsh Distance + Threshold fields grade the size out
(``fem.mesh``). The neighbouring teeth +-1 .. +-n are sampled at the "near" size,
the others coarser. Every outline edge carries its arc mid-point (on the exact
involute there), so the mid-side nodes lie on the flank. The body only rotates
rigidly in the pair, so its stiffness in its own frame never changes and one
factorization serves every position and every wear state (wear enters the pair
solve as initial gaps, see fem.pair_candidates).

A cracked body (:func:`build_cracked_body`) has a root crack cut into tooth 0 and the
drive flanks of teeth -refined .. +refined sampled like tooth 0's; without rotational
periodicity its G covers all those flanks, each over the radius range a contact can
reach while the cracked tooth is engaged (about 3100 condensed dofs for the paper
pinion, against 2142 for the healthy body).

Flexibility by static condensation
----------------------------------
With the boundary set B = the dofs of (i) every node of tooth 0's refined drive
flank in the candidate range, (ii) the nodes of the drive-flank edges of the
neighbouring teeth in the same radius range and (iii) the nodes of the elements
that cross tooth 0's centre line (reading points of fem.pair_centre_line), the
flexibility of B is the inverse of the Schur complement

    S = K_BB - K_BI K_II^-1 K_IB,      G = S^-1 = (K^-1)_BB      (m/N)

(Maxwell-Betti: G is symmetric). fem.condensation computes it from one sparse LU
factorization (SuperLU, no pivoting) of the arrowhead [[K_II, 0], [K_BI, I]] with the
interior dofs I first (METIS nested dissection of the node graph) and B last: the border
of the factors is L_BI = K_BI L_II^-T D^-1, so S = K_BB - L_BI D L_BI^T (read in place from
SuperLU's supernodal store, fem.superlu_store), and G follows from one dense Cholesky
factorization and inversion (LAPACK dpotrf, dpotri). This replaces one sparse solve per
flank node (about 30 ms each for 117k dofs, i.e. ~25 s for 900 nodes), and gives the full
2 x 2 blocks (every force direction) at once. benchmarks/bench_fem_solvers.py compares
the sparse solvers that install here.

The blank's reference circle (r_ref = r_f - 2 m, not below the bore;
:func:`blank_reference_radius_m`) is read as a least-squares rigid motion of 16 z
points on it (:func:`blank_reading`): rotation = mean tangential displacement / r_ref,
translation = mean displacement. Its reading on the condensed dofs, h = (K^-1 a)_B,
costs one more solve with the same factors (reciprocity: a . U = h . f_B), so the pair
FE reads the circle's rotation under any contact load without a further solve
(fem.pair, "The blank's torsion").

Reading and loading at arbitrary flank points: on a boundary edge (v0, m, v1) the
isoparametric map and the trace of a P2 field are the same quadratics in the edge
parameter t, so the point x(t) has the weights (1 - t)(1 - 2 t), 4 t (1 - t),
t (2 t - 1) (also the consistent nodal load of a point force there); t is the
projection of the exact involute point onto the curved edge
(``geometry.polyline.quadratic_parameter``). Interior points (centre line) use the
P2 basis of their element (skfem probes, ``fem.mesh.CurvedMeshTri2``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from gearwear.fem.mesh import MeshSizes, mesh_full_gear
from gearwear.geometry.crack import Crack, crack_mouth_arc
from gearwear.geometry.pair_positions import involute_point, rot  # re-exported (the pair geometry's home)
from gearwear.geometry.polyline import cumulative_length, quadratic_parameter, with_midpoints
from gearwear.geometry.profile import (
    FILLET,
    INVOLUTE,
    ROOT_LAND,
    ToothProfile,
    polygon_area,
    ring_outline,
    tooth_outline,
)
from gearwear.geometry.sampling import profile_at, region_junctions
from gearwear.geometry.spec import GearSpec, Material

from .condensation import condensed_flexibility as _condensed_flexibility
from .condensation import interior_order as _interior_order  # noqa: F401 (the tests' and benchmarks' name)
from .elasticity import ElasticModel, assemble
from .memory import body_dofs

__all__ = [
    "BodySizes",
    "GearBody",
    "CrackedBody",
    "build_body",
    "body_builder",
    "build_cracked_body",
    "involute_point",
    "rot",
    "blank_reference_radius_m",
    "blank_reading",
]

GROWTH = 0.25  # size gradient of every refinement zone (m of size per m of distance)
BLANK_REFERENCE_MODULES = 2.0  # the blank's reference circle: r_ref = r_f - 2 m (not below the bore)
BLANK_READ_POINTS_PER_TOOTH = 16  # points of the reference circle read per tooth pitch


@dataclass(frozen=True)
class BodySizes:
    """Element sizes of a pair body (m).

    contact_m   drive flank of tooth 0 over the candidate range (~ a / 2.5)
    near_m      outline spacing of tooth 0's other parts and of the near teeth
    far_m       outline spacing of the other teeth
    fillet_m    fillets of the near teeth
    global_m    interior cap
    """

    contact_m: float
    near_m: float
    far_m: float
    fillet_m: float
    global_m: float


def _walk(a: float, b: float, spacing, keep: np.ndarray) -> list[float]:
    """Arc positions from a to b (either direction) with steps spacing(s); a kept
    position (region end) closer than 0.3 steps ahead is taken instead of the step."""
    sign = 1.0 if b >= a else -1.0
    pts = [a]
    while sign * (b - pts[-1]) > 1e-15:
        h = float(spacing(pts[-1]))
        nxt = pts[-1] + sign * h
        ahead = keep[(sign * (keep - pts[-1]) > 1e-15) & (sign * (b - keep) >= -1e-15)]
        if ahead.size:
            k = ahead[np.argmin(sign * (ahead - pts[-1]))]
            if sign * (nxt - k) >= -0.3 * h:
                nxt = float(k)
        if sign * (nxt - b) >= -0.3 * h:
            nxt = b
        pts.append(nxt)
    return pts


def _sample_flank(
    profile: ToothProfile, spacing, fine: tuple[float, float, float] | None = None, keep_s: tuple[float, ...] = ()
) -> np.ndarray:
    """One right flank (space centre -> tip axis) as a quadratic chain (vertex, arc
    mid-point, vertex, ...; ``geometry.polyline``) with arc steps spacing(s); region
    junctions and the arc positions ``keep_s`` (below the fine range: a crack mouth)
    are vertices, and involute points are put on the exact involute (the source
    polygon is off it by its chord sag). ``fine`` = (s_lo, s_hi, h): equal steps <= h
    on [s_lo, s_hi], so the edge at the tip corner (s_hi) is a full step at every
    refinement level (the corner contact is sensitive to it)."""
    s = profile.s
    junctions = s[region_junctions(profile)]
    # the fillet leaves the root circle tangentially, so a root land shorter than 1/20 step
    # (a nearly full-round root) is spanned by the first edge: as a vertex it would leave an
    # edge of that length, and a sliver element, at the space centre
    land = s[np.flatnonzero(profile.region == ROOT_LAND)[-1]]
    if 0.0 < land < 0.05 * float(spacing(0.0)):
        junctions = junctions[junctions != land]
    keep = np.sort(np.concatenate([junctions, np.asarray(keep_s, dtype=float)]))
    if fine is None:
        sn = np.array(_walk(0.0, float(s[-1]), spacing, keep))
    else:
        lo, hi, h = fine
        n = max(1, int(math.ceil((hi - lo) / h - 1e-9)))
        below = _walk(lo, 0.0, spacing, keep)[::-1]
        above = _walk(hi, float(s[-1]), spacing, keep)
        sn = np.concatenate([below[:-1], np.linspace(lo, hi, n + 1), above[1:]])
    sn = with_midpoints(sn)
    xy = profile_at(profile, sn).xy
    inv = np.flatnonzero(profile.region == INVOLUTE)
    on_inv = (sn >= s[inv[0]]) & (sn <= s[inv[-1]])
    r = np.hypot(xy[on_inv, 0], xy[on_inv, 1])
    xy[on_inv] = involute_point(profile.gear, r)
    return xy


@dataclass
class GearBody:
    """A gear body with the condensed flexibility of its drive-flank nodes.

    flank_r[t]   (n_t,) node radii along the drive flank of tooth t (t = 0 refined,
                 t != 0 the neighbours), sorted; flank_xy[t] their coordinates in
                 tooth t's own frame (tooth t turned back onto +y)
    flank_edges[t]  (e, 3) positions in flank_r[t] of each edge's (v0, mid, v1)
    flank_b[t]   (n_t,) position of each node's x dof in G (y dof = +1)
    G            (2 m, 2 m) flexibility of the condensed dofs (m/N)
    blank_reference_radius_m  r_ref of the blank's reference circle (:func:`blank_reference_radius_m`)
    blank_h      (3, 2 m) rigid motion of that circle per N on each condensed dof, rows
                 rotation (rad, counter-clockwise), translation x, y (m; body frame):
                 (theta_ref, v_x, v_y) = blank_h f_B (reciprocity, :func:`blank_reading`);
                 None when r_ref is the bore (no blank term)
    """

    gear: GearSpec
    sizes: BodySizes
    r_lo: float
    model: ElasticModel
    flank_r: dict
    flank_xy: dict
    flank_edges: dict
    flank_b: dict
    G: np.ndarray
    centre_b: np.ndarray  # B positions (x dofs) of the centre-line element nodes
    centre_dofs: np.ndarray  # their global x dofs
    dofs: np.ndarray  # (2 m,) global dof of each row of G
    n_elements: int
    timings: dict = field(default_factory=dict)
    blank_reference_radius_m: float = 0.0
    blank_h: np.ndarray | None = None

    @property
    def ndofs(self) -> int:
        return int(self.model.ndofs)

    def edge_weights(self, tooth: int, radius_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B positions (n, 3), weights (n, 3)) of points of tooth ``tooth``'s drive
        flank at radii R: P2 edge shape functions at the edge parameter of the
        involute point at R (its projection onto the curved edge)."""
        return self.edge_weights_many([(tooth, radius_m)])[0]

    def edge_weights_many(self, requests: list) -> list[tuple[np.ndarray, np.ndarray]]:
        """:meth:`edge_weights` of every (tooth, radii) of ``requests``, the projections
        onto the curved edges done together (they are independent per point: the same
        numbers as one call per request, for a fraction of the calls)."""
        parts = []
        for tooth, radius_m in requests:
            r = self.flank_r[tooth]
            e = self.flank_edges[tooth]
            R = np.atleast_1d(np.asarray(radius_m, dtype=float))
            lo, hi = r[e[:, 0]], r[e[:, 2]]
            k = np.clip(np.searchsorted(hi, R, side="left"), 0, len(e) - 1)
            if np.any(R < lo[0] - 1e-12) or np.any(R > hi[-1] + 1e-12):
                raise ValueError(
                    f"flank point outside the condensed range of tooth {tooth} "
                    f"({R.min() * 1e3:.4f}..{R.max() * 1e3:.4f} mm)"
                )
            parts.append((R, self.flank_xy[tooth][e[k]], self.flank_b[tooth][e[k]]))
        R = np.concatenate([p[0] for p in parts])
        ends = np.concatenate([p[1] for p in parts])  # (n, 3, 2): v0, mid, v1 of each point's edge
        t = quadratic_parameter(involute_point(self.gear, R), ends[:, 0], ends[:, 1], ends[:, 2])
        w = np.column_stack([(1 - t) * (1 - 2 * t), 4 * t * (1 - t), t * (2 * t - 1)])
        cut = np.cumsum([len(p[0]) for p in parts])[:-1]
        return [(p[2], wi) for p, wi in zip(parts, np.split(w, cut))]

    def node_index(self, radius_m: np.ndarray) -> np.ndarray:
        """Tooth-0 flank node positions (in flank_r[0]) nearest to the radii."""
        r = self.flank_r[0]
        k = np.clip(np.searchsorted(r, radius_m), 1, len(r) - 1)
        return np.where(np.abs(r[k - 1] - radius_m) <= np.abs(r[k] - radius_m), k - 1, k)


@dataclass
class CrackedBody(GearBody):
    """A gear body with a root crack cut into tooth 0 (both faces free, no contact of
    the faces) and the drive flanks of teeth -refined .. +refined all refined like tooth
    0's. Rotational periodicity does not hold: G holds the flexibility of all those
    flanks (each over the radius range a contact can reach while the cracked tooth is
    engaged) and of tooth 0's centre line, read on the loaded teeth themselves."""

    crack_xy: np.ndarray | None = None  # (mouth, tip) in tooth 0's frame (m)
    crack_tip_size_m: float = 0.0
    refined: int = 0


def _flank_nodes(mesh, basis, outer: np.ndarray, g: GearSpec, tooth: int, r_lo: float, r_hi: float, tol_m: float):
    """Nodes of the drive-flank edges of tooth ``tooth`` overlapping [r_lo, r_hi]:
    (radii, coordinates in the tooth's own frame, global x dofs, edges). A vertex is
    on the flank within ``tol_m`` of the involute (Gmsh may split a long outline
    edge; the new vertices lie on the chord)."""
    z = g.teeth
    R0 = rot(-2.0 * math.pi * tooth / z)
    f = mesh.facets[:, outer]
    p0 = (mesh.p[:, f[0]].T) @ R0.T
    p1 = (mesh.p[:, f[1]].T) @ R0.T

    def on_flank(p):
        r = np.hypot(p[:, 0], p[:, 1])
        ok = (r >= g.base_radius_m) & (r <= g.tip_radius_m * (1 + 1e-12)) & (p[:, 0] > 0)
        ex = involute_point(g, np.minimum(np.maximum(r, g.base_radius_m), g.tip_radius_m))
        return ok & (np.hypot(*(p - ex).T) <= tol_m), r

    ok0, ra = on_flank(p0)
    ok1, rb = on_flank(p1)
    sel = ok0 & ok1 & (np.maximum(ra, rb) >= r_lo) & (np.minimum(ra, rb) <= r_hi)
    if not np.any(sel):
        raise RuntimeError(f"no drive-flank edges of tooth {tooth} found in the mesh")
    fac = np.asarray(outer)[sel]
    v0, v1 = mesh.facets[0, fac], mesh.facets[1, fac]
    swap = ra[sel] > rb[sel]
    v0, v1 = np.where(swap, v1, v0), np.where(swap, v0, v1)
    dx = np.concatenate([basis.nodal_dofs[0, v0], basis.facet_dofs[0, fac], basis.nodal_dofs[0, v1]])
    loc = basis.doflocs[:, dx].T @ R0.T
    rr = np.hypot(loc[:, 0], loc[:, 1])
    uniq, first, inv = np.unique(dx, return_index=True, return_inverse=True)
    order = np.argsort(rr[first], kind="stable")  # along the flank, root -> tip
    pos = np.empty(len(uniq), dtype=int)
    pos[order] = np.arange(len(uniq))
    node_of = pos[inv]
    ne = len(fac)
    edges = np.column_stack([node_of[:ne], node_of[ne : 2 * ne], node_of[2 * ne :]])
    edges = edges[np.argsort(np.hypot(*loc[:ne].T))]
    first = first[order]
    return rr[first], loc[first], uniq[order], edges


def _centre_line_nodes(mesh, basis, y_lo: float, y_hi: float) -> np.ndarray:
    """Global x dofs of all nodes of the elements that cross the centre line x = 0 of
    tooth 0 between heights y_lo and y_hi."""
    pt = mesh.p[:, mesh.t]  # (2, 3, nel)
    xmin, xmax = pt[0].min(axis=0), pt[0].max(axis=0)
    ymin, ymax = pt[1].min(axis=0), pt[1].max(axis=0)
    el = np.flatnonzero((xmin <= 0) & (xmax >= 0) & (ymax >= y_lo) & (ymin <= y_hi))
    return np.unique(basis.element_dofs[0::2, el])


def estimated_dofs(gear: GearSpec, nominal: ToothProfile, sizes: BodySizes, r_lo: float) -> float:
    """The dofs :func:`build_body` would give ``gear``'s body, estimated before meshing from
    its outline (every tooth sampled at the far size), the length of tooth 0's refined
    flank (``r_lo`` to the tip) and the element sizes (fem.memory)."""
    far = _sample_flank(nominal, lambda s: sizes.far_m)
    outline = ring_outline(lambda k: tooth_outline(far), gear.teeth)
    inv = np.flatnonzero(nominal.region == INVOLUTE)
    s_inv = nominal.s[inv]
    flank = float(s_inv[-1] - np.interp(r_lo, nominal.radius[inv], s_inv))
    return body_dofs(
        polygon_area(outline[0::2]),
        gear.root_radius_m,
        gear.hub_radius_m,
        sizes.global_m,
        sizes.far_m,
        flank_m=flank,
        contact_m=sizes.contact_m,
        growth=GROWTH,
    )


def _mesh_body(
    gear: GearSpec,
    material: Material,
    face_width_m: float,
    nominal: ToothProfile,
    sizes: BodySizes,
    r_lo: float,
    neighbours: int,
    plane: str,
    refined: int = 0,
    crack: Crack | None = None,
    crack_tip_size_m: float | None = None,
    staged: bool = False,
):
    """Mesh and assemble a gear body: tooth 0's drive flank (and those of teeth
    -refined .. +refined) refined to h_c over the candidate range, teeth up to
    +-neighbours at the near size, the rest at the far size; ``crack`` cut into tooth 0.
    Returns (gmsh mesh, model, the drive-flank node sets as a function of
    {tooth: radius range}, crack (mouth, tip) or None, timings); ``staged``: meshes
    (Gmsh, in the calling thread) and returns the rest (the assembly) as a function of
    no arguments that returns the same tuple and may run in any thread."""
    t0 = time.perf_counter()
    g = gear
    z = g.teeth
    hc = sizes.contact_m
    inv = np.flatnonzero(nominal.region == INVOLUTE)
    s_inv = nominal.s[inv]
    # the fine range starts a fixed arc length below r_lo (the same at every level)
    s_lo = max(float(np.interp(r_lo, nominal.radius[inv], s_inv)) - 0.01 * g.module_m, float(s_inv[0]))
    s_hi = float(s_inv[-1])

    def fine(s):
        dist = max(s_lo - s, s - s_hi, 0.0)
        return min(sizes.near_m, hc + GROWTH * dist)

    near = lambda s: sizes.near_m  # noqa: E731
    far = lambda s: sizes.far_m  # noqa: E731
    right0 = _sample_flank(nominal, fine, (s_lo, s_hi, hc))
    side_near = _sample_flank(nominal, near)
    crack_xy = None
    right_c = right0
    if crack is not None:
        # the crack mouth (ISO 30-deg fillet point, far below the fine range) becomes a
        # vertex of tooth 0's outline; the flank above it keeps tooth 0's sampling
        mouth, tip, s_m = crack_mouth_arc(nominal, crack)
        right_c = _sample_flank(nominal, fine, (s_lo, s_hi, hc), keep_s=(s_m,))
        v = right_c[0::2]
        crack_xy = np.array([v[int(np.argmin(np.hypot(*(v - mouth).T)))], tip])
    # tooth 0, the refined neighbours, the near ones, the others
    kinds = (
        tooth_outline(right_c, side_near),
        tooth_outline(right0, side_near),
        tooth_outline(side_near),
        tooth_outline(_sample_flank(nominal, far)),
    )

    def tooth(k: int) -> np.ndarray:
        away = min(k, z - k)  # teeth between tooth k and tooth 0
        return kinds[0 if away == 0 else 1 if away <= refined else 2 if away <= neighbours else 3]

    # a quadratic chain: even points are the vertices, odd ones the edge mid-points
    outline = ring_outline(tooth, z)
    mirror = np.array([-1.0, 1.0])
    v0 = right0[::2]
    s_r0 = cumulative_length(v0)
    refine = v0[(s_r0 >= s_lo - 1e-12) & (s_r0 <= s_hi + 1e-12)]
    if refined:
        refine = np.vstack([refine @ rot(2.0 * math.pi * kk / z).T for kk in range(-refined, refined + 1)])
    fil = nominal.xy[nominal.region == FILLET]
    fil = fil[:: max(1, len(fil) // 10)]
    fillets = np.vstack(
        [np.vstack([fil, fil * mirror]) @ rot(2.0 * math.pi * kk / z).T for kk in range(-neighbours, neighbours + 1)]
    )
    msz = MeshSizes(
        global_m=sizes.global_m,
        fillet_m=sizes.fillet_m,
        load_m=hc,
        load_dist_m=hc,
        fillet_dist_m=2 * sizes.fillet_m,
        growth=GROWTH,
    )
    gm = mesh_full_gear(
        outline[0::2],
        g.hub_radius_m,
        msz,
        refine_points_xy=refine,
        fillet_points_xy=fillets,
        order=2,
        outline_mid_xy=outline[1::2],
        crack_xy=crack_xy,
        crack_tip_size_m=crack_tip_size_m if crack is not None else None,
    )
    t1 = time.perf_counter()
    rest = lambda: _assembled(gm, material, face_width_m, plane, g, sizes, refined, crack_xy, t1 - t0)  # noqa: E731
    return rest if staged else rest()


def _assembled(
    gm, material: Material, face_width_m: float, plane: str, g: GearSpec, sizes, refined: int, crack_xy, mesh_s
):
    """The second half of :func:`_mesh_body`: the assembly of the meshed body ``gm`` and
    its drive-flank node sets."""
    t1 = time.perf_counter()
    model = assemble(gm.mesh, material, face_width_m, gm.boundaries["bore"], plane=plane, order=2, factorize=False)
    t2 = time.perf_counter()
    if not np.all(model.basis.nodal_dofs[1].take(0) == model.basis.nodal_dofs[0].take(0) + 1):
        raise RuntimeError("unexpected dof numbering of the vector P2 basis")
    outer = np.asarray(gm.boundaries["outer"])
    r_top = g.tip_radius_m

    def flanks(ranges: dict) -> tuple[dict, dict, dict, dict]:
        """Node sets of the drive flanks of the teeth t in ``ranges`` over their radius
        ranges (r_a, r_b)."""
        flank_r, flank_xy, flank_dofs, flank_edges = {}, {}, {}, {}
        for t, (r_a, r_b) in sorted(ranges.items()):
            # refined flanks lie on the involute; the near teeth's outline edges sag by
            # h^2 / (8 rho), rho >= 0.1 r_b here
            tol = 1e-9 * r_top if abs(t) <= refined else sizes.near_m**2 / (0.8 * g.base_radius_m)
            flank_r[t], flank_xy[t], flank_dofs[t], flank_edges[t] = _flank_nodes(
                model.mesh, model.basis, outer, g, t, r_a, r_b, tol
            )
        return flank_r, flank_xy, flank_dofs, flank_edges

    return gm, model, flanks, crack_xy, {"mesh_s": mesh_s, "assemble_s": t2 - t1}


def blank_reference_radius_m(gear: GearSpec) -> float:
    """Radius r_ref (m) of the blank's reference circle: BLANK_REFERENCE_MODULES modules
    below the root circle, r_ref = r_f - 2 m, but not below the bore.

    Why there: a tooth load's field about the mean (n = 0) rotation varies around the
    circle with the tooth pitch; its n-th Fourier mode decays inwards like (r / r_f)^n,
    and at r_f - 2 m the tooth-pitch mode (n = z) is down to (1 - 2 m / r_f)^z
    ~ exp(-2 z m / r_f) = exp(-4) ~ 2 % (r_f ~ m z / 2): the circle turns nearly as a rigid
    ring, so its rotation does not depend on how it is read. Where the rim is thinner
    (r_f - 2 m <= bore), r_ref is the bore: no blank term, the whole rim stays in the mesh
    stiffness."""
    return max(gear.root_radius_m - BLANK_REFERENCE_MODULES * gear.module_m, gear.hub_radius_m)


def blank_reading(model: ElasticModel, gear: GearSpec) -> tuple[float, np.ndarray | None]:
    """(r_ref, A): the reading functionals of the reference circle's least-squares rigid
    motion, (theta_ref, v_x, v_y) = A U (rad counter-clockwise, m, m; body frame): over
    n = BLANK_READ_POINTS_PER_TOOTH z points x_k = r_ref (cos phi_k, sin phi_k),
    phi_k = pi / 2 + 2 pi (k + 1/2) / n (the same number, mirror-symmetric, in every tooth
    pitch), with t_k = (-sin phi_k, cos phi_k),

        theta_ref = 1 / (n r_ref) sum_k t_k . u(x_k),   v = 1 / n sum_k u(x_k)

    (on a uniformly sampled circle the rotation and the translation of the least-squares
    fit decouple). u(x_k) by the P2 basis of the element holding x_k
    (fem.mesh.CurvedMeshTri2). theta_ref is exact for a rigid rotation and reads only the
    axisymmetric (n = 0) part of u_theta; v only the n = 1 part. A (3, ndofs) is None when
    r_ref is the bore."""
    r_ref = blank_reference_radius_m(gear)
    if r_ref <= gear.hub_radius_m:
        return r_ref, None
    n = BLANK_READ_POINTS_PER_TOOTH * gear.teeth
    phi = 0.5 * math.pi + 2.0 * math.pi * (np.arange(n) + 0.5) / n
    P = model.probe(r_ref * np.column_stack([np.cos(phi), np.sin(phi)]))
    Px, Py = P[0::2].T, P[1::2].T
    rows = [(Px @ -np.sin(phi) + Py @ np.cos(phi)) / r_ref, Px @ np.ones(n), Py @ np.ones(n)]
    return r_ref, np.vstack([np.asarray(r).ravel() for r in rows]) / n


def _condensed(
    cls,
    gear: GearSpec,
    sizes: BodySizes,
    r_lo: float,
    gm,
    model: ElasticModel,
    flank_sets: tuple,
    centre_y: tuple[float, float],
    timings: dict,
    **extra,
):
    """The body ``cls`` with G over the flank node sets (radii, coordinates, x dofs,
    edges per tooth) and the nodes of the elements crossing tooth 0's centre line, and
    the blank's reading h = (K^-1 a)_B (:func:`blank_reading`) from the same factorization."""
    flank_r, flank_xy, flank_dofs, flank_edges = flank_sets
    centre = _centre_line_nodes(model.mesh, model.basis, *centre_y)
    # B: x dofs of all condensed nodes (y dof = x dof + 1 in skfem's vector P2 numbering)
    xd = np.unique(np.concatenate([*flank_dofs.values(), centre]))
    r_ref, a = blank_reading(model, gear)
    G, h, tim = _condensed_flexibility(model, xd, a)
    where = {int(d): i for i, d in enumerate(xd)}
    flank_b = {t: 2 * np.array([where[int(d)] for d in flank_dofs[t]]) for t in flank_dofs}
    return cls(
        gear=gear,
        flank_r=flank_r,
        flank_xy=flank_xy,
        flank_edges=flank_edges,
        flank_b=flank_b,
        dofs=np.column_stack([xd, xd + 1]).ravel(),
        sizes=sizes,
        r_lo=r_lo,
        model=model,
        G=G,
        centre_b=2 * np.array([where[int(d)] for d in centre]),
        centre_dofs=centre,
        n_elements=gm.n_elements,
        timings={**timings, **tim},
        blank_reference_radius_m=r_ref,
        blank_h=h,
        **extra,
    )


def body_builder(
    gear: GearSpec,
    material: Material,
    face_width_m: float,
    nominal: ToothProfile,
    sizes: BodySizes,
    r_lo: float,
    neighbours: int,
    centre_y: tuple[float, float],
    plane: str = "stress",
) -> Callable[[], GearBody]:
    """:func:`build_body` in two stages: mesh the body now (Gmsh, in the calling thread:
    Gmsh is one per process and resets the signal handlers when it starts) and return the
    rest (assembly and condensation) as a function of no arguments, which may run in
    another thread (fem.pair_model overlaps it with the meshing of the other gear)."""
    rest = _mesh_body(gear, material, face_width_m, nominal, sizes, r_lo, neighbours, plane, staged=True)

    def finish() -> GearBody:
        gm, model, flanks, _, timings = rest()
        ranges = {t: (r_lo, gear.tip_radius_m) for t in range(-neighbours, neighbours + 1)}
        return _condensed(GearBody, gear, sizes, r_lo, gm, model, flanks(ranges), centre_y, timings)

    return finish


def build_body(
    gear: GearSpec,
    material: Material,
    face_width_m: float,
    nominal: ToothProfile,
    sizes: BodySizes,
    r_lo: float,
    neighbours: int,
    centre_y: tuple[float, float],
    plane: str = "stress",
) -> GearBody:
    """Mesh, assemble and condense one gear body (see the module docstring).

    nominal     dense nominal profile of the gear (right flank of tooth 0)
    r_lo        lowest radius of the candidate range (the tip corner is the top)
    neighbours  teeth +-1 .. +-neighbours are condensed too (cross-tooth coupling)
    centre_y    (y_lo, y_hi) heights of tooth 0's centre line to be readable
    """
    return body_builder(gear, material, face_width_m, nominal, sizes, r_lo, neighbours, centre_y, plane)()


def build_cracked_body(
    gear: GearSpec,
    material: Material,
    face_width_m: float,
    nominal: ToothProfile,
    sizes: BodySizes,
    ranges: dict,
    neighbours: int,
    refined: int,
    centre_y: tuple[float, float],
    crack: Crack,
    crack_tip_size_m: float,
    plane: str = "stress",
) -> CrackedBody:
    """Mesh, assemble and condense a gear body with ``crack`` (geometry.crack) cut into
    tooth 0's loaded fillet, as :func:`build_body` but with the drive flanks of teeth
    -refined .. +refined all sampled like tooth 0's (a contact on any of them is resolved
    alike), the crack tip refined to ``crack_tip_size_m`` (fem.mesh: Gmsh's Crack plugin,
    both faces free) and G over those flanks, tooth t over ``ranges[t]`` = (r_a, r_b)
    (m; tooth 0's lower end is the candidate range's r_lo), and tooth 0's centre line."""
    r_lo = ranges[0][0]
    gm, model, flanks, crack_xy, timings = _mesh_body(
        gear, material, face_width_m, nominal, sizes, r_lo, neighbours, plane, refined, crack, crack_tip_size_m
    )
    return _condensed(
        CrackedBody,
        gear,
        sizes,
        r_lo,
        gm,
        model,
        flanks(ranges),
        centre_y,
        timings,
        crack_xy=crack_xy,
        crack_tip_size_m=crack_tip_size_m,
        refined=refined,
    )
