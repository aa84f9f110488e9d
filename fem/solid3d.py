"""Which 2D idealisation fits a spur tooth of face width b: a 3D FE check.

A 2D model of a tooth is plane stress (sigma_zz = 0: the thin limit b -> 0) or plane
strain (eps_zz = 0: the long limit b -> oo). The real tooth lies between; this module
computes the 3D linear-elastic compliance of one tooth on its rim for a given face width
and the 2D plane-stress and plane-strain compliances of the same section, with the same
boundary conditions, load and in-plane mesh, so the three can be compared.

Body and boundary conditions (SI: m, N, Pa)
--------------------------------------------
The sector of gear ``gear_index`` that holds tooth 0 (centred on +y): the toothed outline
of ``geometry.profile.tooth_outline`` from the middle of the space on the right to the
middle of the space on the left (polar angles pi/2 -+ pi/z), two radial cuts down to the
bore circle r = r_hub (``PairSpec.hub_radius_m``), the bore arc. The cuts and the bore
arc are held, u = 0 (the rest of the gear taken as rigid); the toothed outline is free.
The 2D models get exactly these conditions on the section; the 3D model on the swept
cut faces, and its two end faces z = +-b/2 are free. Holding the cuts makes the body
stiffer than the whole gear of ``fem.tooth`` (whose neighbouring teeth and rim give way):
the sector's plane-stress compliance of the paper pinion is 40 % (SAP) to 75 % (top) of
the full gear's. The check compares 2D with 3D on one body, so the conditions need only
be the same in both; the foundation's share of the compliance is smaller here than in
the whole gear.

The 3D body is the section swept over the face width, z in [-b/2, b/2]. Geometry, load
and conditions are symmetric about z = 0, so only z in [0, b/2] is meshed, with
u_z = 0 on z = 0 (exact for the symmetric solution of a linear problem).

Load
----
A line load of intensity w (N/m) uniform along the face, along the mesh-force direction
e_F = -(cos w_L, sin w_L) of ``geometry.loading`` at load radius R on the right flank,
spread over the Hertz patch p(s) = p0 sqrt(1 - s^2 / a^2) as in ``fem.tooth`` (Gauss-
Chebyshev points on the meshed flank, ``fem.tooth.hertz_patch_forces``), a the Hertz
half-width of the paper's load per width (``fem.tooth``: the centre-line reading is
insensitive to a). In 3D every patch point is a line along z, integrated per element
layer with ``Z_POINTS`` Gauss-Legendre points (weights = length / b/2).

Compliance (the reading of ``fem.tooth.single_tooth_compliance``, read_at="radius")
-------------------------------------------------------------------------------
The displacement of the tooth centre-line point (0, R) along e_F per unit line load:

    2D:               c = u(0, R) . e_F / w
    3D face average:  c_avg = (2 / b) int_0^{b/2} u(0, R, z) . e_F dz / w
    3D mid-plane:     c_mid = u(0, R, 0) . e_F / w

all in m^2/N, reported as um per (N/mm) (x 1e9), the unit of ``fem.tooth``. Elements:
P2 Lagrange on straight-sided triangles (2D) and tetrahedra (3D, Gmsh's extrusion of
the same section mesh, ``fem.mesh.mesh_sector_solid``, every prism cut into three
tetrahedra): every layer plane of the 3D mesh carries the 2D mesh, and the P2
tetrahedron restricted to a face is the P2 triangle, so the 2D and 3D spaces agree on
those planes. The straight edges' sag (h^2 / (8 rho)) is common to both and goes with h.

Limits (the independent truths the tests check)
-----------------------------------------------
* b -> 0: the 3D solution tends to generalised plane stress, c_avg -> c_stress.
* b -> oo: away from the end faces eps_zz -> 0, c_mid -> c_strain; the end zones
  (a few tooth thicknesses wide) stay softer, so c_strain < c_avg < c_stress.
* In plane strain the constants are E' = E / (1 - nu^2), nu' = nu / (1 - nu) of plane
  stress; G is the same, so a shear-free bending compliance scales by 1 - nu^2.

Solver: the 2D models use ``fem.elasticity.assemble``; the 3D matrix is assembled by
:func:`solid_stiffness` (lambda, mu of E, nu; identical to scikit-fem's
``linear_elasticity`` form, ~10 times faster for P2 tetrahedra), the held dofs
eliminated and the reduced system solved by :func:`solve_spd` (SuperLU for small
systems, else conjugate gradients with smoothed-aggregation multigrid, pyamg, to a
relative residual of 1e-10).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementTetP2
from skfem.models.elasticity import lame_parameters

from gearwear.core.validation import fail
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.loading import load_points
from gearwear.geometry.profile import FILLET, INVOLUTE, ROOT_LAND, TIP_LAND, tooth_outline, tooth_profile
from gearwear.geometry.sampling import FINE_SAG_M, resample_profile
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import hertz_half_width

from .elasticity import assemble
from .mesh import MeshSizes, SolidMesh, mesh_sector_solid
from .tooth import DEFAULT_TORQUE_NM, hertz_patch_forces, load_radii, patch_load

#: element sizes at mesh_scale = 1 as fractions of the module: the tooth flank and
#: fillets, the far field, the first layer at the free end face and the largest layer
FLANK_FRACTION = 0.16
GLOBAL_FRACTION = 0.8
FACE_LAYER_FRACTION = 0.16
MAX_LAYER_FRACTION = 1.5
#: growth of the element sizes away from the refined zones (in-plane and along z)
GROWTH = 0.3
Z_POINTS = 4  # Gauss-Legendre points per element layer (load and average)
M2_PER_N_TO_UM_PER_N_PER_MM = 1e9


@dataclass
class PlaneCheck:
    """Tooth compliance in 2D plane stress, 2D plane strain and 3D at load radii.

    Compliances in um per (N/mm) (deflection per line load), arrays over ``radius_m``.
    ``timings`` (s): mesh_s, stress_s, strain_s (assemble + factorize + solve of one 2D
    model), solid_s (3D assemble + factorize + solve), total_s.
    """

    pair: PairSpec
    gear_index: int
    face_width_m: float
    mesh_scale: float
    radius_m: np.ndarray
    stress_um_per_N_per_mm: np.ndarray
    strain_um_per_N_per_mm: np.ndarray
    average_um_per_N_per_mm: np.ndarray  # 3D, averaged over the face width
    mid_um_per_N_per_mm: np.ndarray  # 3D, at the mid-plane z = 0
    ndofs_2d: int
    ndofs_3d: int
    n_triangles: int
    n_tetrahedra: int
    n_layers: int
    timings: dict = field(default_factory=dict)

    @property
    def b_over_m(self) -> float:
        return self.face_width_m / self.pair.module_m

    def rows(self) -> list[dict]:
        return [
            {
                "radius_mm": float(r) * 1e3,
                "stress": float(s),
                "strain": float(e),
                "average_3d": float(a),
                "mid_3d": float(c),
            }
            for r, s, e, a, c in zip(
                self.radius_m,
                self.stress_um_per_N_per_mm,
                self.strain_um_per_N_per_mm,
                self.average_um_per_N_per_mm,
                self.mid_um_per_N_per_mm,
            )
        ]


def check_radii(pair: PairSpec, gear_index: int = 0) -> np.ndarray:
    """The three load radii of the check (m): the start of active profile, the pitch
    circle and the top load of ``fem.tooth.load_radii`` (its Hertz patch ends one
    half-width below the tip corner)."""
    R, _ = load_radii(pair, gear_index, 2, DEFAULT_TORQUE_NM / pair.gear(0).base_radius_m)
    return np.array([R[0], pair.gear(gear_index).pitch_radius_m, R[-1]])


def face_planes(half_width_m: float, first_m: float, largest_m: float, growth: float = GROWTH) -> np.ndarray:
    """Layer planes z (m) from the mid-plane 0 to the free end face ``half_width_m``.

    The layer size follows h(d) = min(first_m + growth d, largest_m) at the distance d
    from the end face (the form of Gmsh's threshold fields in ``fem.mesh``):
    N = ceil(int_0^D dd / h) layers, the planes equidistributing int dd / h, so scaling
    every size by s refines the layers by 1 / s (up to the rounding of N)."""
    if not (half_width_m > 0 and first_m > 0 and largest_m >= first_m and growth > 0):
        raise ValueError(
            f"face_planes: need half_width_m > 0, 0 < first_m <= largest_m, growth > 0, got "
            f"{half_width_m!r}, {first_m!r}, {largest_m!r}, {growth!r}"
        )
    d = np.linspace(0.0, half_width_m, 4001)
    inv_h = 1.0 / np.minimum(first_m + growth * d, largest_m)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (inv_h[1:] + inv_h[:-1]) * np.diff(d))])
    n = max(1, int(math.ceil(cum[-1] - 1e-9)))
    d_planes = np.interp(np.linspace(0.0, cum[-1], n + 1), cum, d)
    z = half_width_m - d_planes[::-1]
    z[0], z[-1] = 0.0, half_width_m
    return z


def sector_solid(pair: PairSpec, gear_index: int, face_width_m: float, mesh_scale: float = 1.0):
    """(SolidMesh, flank chain, first and last involute vertex of the flank) of the
    half-width sector model (module docstring), element sizes x ``mesh_scale``."""
    g = pair.gear(gear_index)
    m, s = pair.module_m, float(mesh_scale)
    flank_m, global_m = FLANK_FRACTION * m * s, GLOBAL_FRACTION * m * s
    sizes = MeshSizes(
        global_m=global_m,
        fillet_m=flank_m,
        load_m=flank_m,
        fillet_dist_m=0.3 * m,
        load_dist_m=0.3 * m,
        growth=GROWTH * s,
    )
    base = tooth_profile(g, sag_m=FINE_SAG_M)
    poly = resample_profile(base, {ROOT_LAND: flank_m, FILLET: flank_m, INVOLUTE: flank_m, TIP_LAND: flank_m})
    outline = tooth_outline(poly)
    half = math.pi / g.teeth
    # the whole tooth and its fillets are refined: its flanks' vertices as refinement points
    refine = np.vstack([poly.xy, poly.xy * np.array([-1.0, 1.0])])
    planes = face_planes(0.5 * face_width_m, FACE_LAYER_FRACTION * m * s, MAX_LAYER_FRACTION * m * s, GROWTH * s)
    solid = mesh_sector_solid(
        outline, g.hub_radius_m, 0.5 * math.pi - half, 0.5 * math.pi + half, sizes, planes, refine_points_xy=refine
    )
    inv = np.flatnonzero(poly.region == INVOLUTE)
    chain = np.empty((2 * len(poly.xy) - 1, 2))
    chain[0::2], chain[1::2] = poly.xy, 0.5 * (poly.xy[:-1] + poly.xy[1:])
    return solid, chain, int(inv[0]), int(inv[-1])


def z_rule(planes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points z and weights (sum = depth) over the element layers."""
    t, w = np.polynomial.legendre.leggauss(Z_POINTS)
    lo, hi = planes[:-1, None], planes[1:, None]
    return (0.5 * (lo + hi) + 0.5 * (hi - lo) * t).ravel(), (0.5 * (hi - lo) * w).ravel()


def plane_check(
    pair: PairSpec, face_width_m: float | None = None, gear_index: int = 0, radii_m=None, mesh_scale: float = 1.0
) -> PlaneCheck:
    """3D and 2D (plane stress, plane strain) compliance of tooth 0 of gear ``gear_index``
    on its sector (module docstring) at ``radii_m`` (default :func:`check_radii`) for face
    width ``face_width_m`` (default the pair's). Element sizes scale with the module and
    with ``mesh_scale``."""
    t_start = time.perf_counter()
    b = pair.face_width_m if face_width_m is None else float(face_width_m)
    if not (math.isfinite(b) and b > 0):
        raise fail("face_width_m", repr(face_width_m), "", "must be finite and > 0")
    g = pair.gear(gear_index)
    R = check_radii(pair, gear_index) if radii_m is None else np.atleast_1d(np.asarray(radii_m, dtype=float))
    mg = MeshGeometry(pair, pair.centre_distance_m)
    rb = g.base_radius_m
    u = np.sqrt(np.maximum((R / rb) ** 2 - 1.0, 0.0))
    d = rb * u if gear_index == 0 else mg.line_of_action_m - rb * u
    load_N = DEFAULT_TORQUE_NM / pair.gear(0).base_radius_m
    a = hertz_half_width(mg, d, load_N / pair.face_width_m)  # the paper's load per width at every b
    lp = load_points(tooth_profile(g, sag_m=FINE_SAG_M), R)
    e_F = -np.column_stack([np.cos(lp.w_rad), np.sin(lp.w_rad)])

    t0 = time.perf_counter()
    solid, chain, v_lo, v_hi = sector_solid(pair, gear_index, b, mesh_scale)
    t_mesh = time.perf_counter() - t0
    # one unit line load per radius: forces (n, k, 2) at patch points (n, k, 2), sum = e_F
    pts, forces = hertz_patch_forces(chain, v_lo, v_hi, R, a, e_F, 1.0)
    n, k = pts.shape[:2]
    read = np.column_stack([np.zeros_like(R), R])

    sec = solid.section
    held = np.concatenate([sec.boundaries[key] for key in ("hub_arc", "cut_left", "cut_right")])
    out2, t2 = {}, {}
    for plane in ("stress", "strain"):
        t0 = time.perf_counter()
        model = assemble(sec.mesh, g.material, 1.0, held, plane=plane, order=2)
        F = patch_load(model, pts, forces)
        U = model.solve(F)
        Q = model.probe(read)
        uc = np.asarray(Q @ U)
        idx = np.arange(n)
        out2[plane] = uc[2 * idx, idx] * e_F[:, 0] + uc[2 * idx + 1, idx] * e_F[:, 1]
        t2[plane] = time.perf_counter() - t0
        ndofs_2d = model.ndofs

    t0 = time.perf_counter()
    avg, mid, ndofs_3d = _solve_solid(solid, g.material, pts, forces, read, e_F)
    t_solid = time.perf_counter() - t0
    c = M2_PER_N_TO_UM_PER_N_PER_MM
    return PlaneCheck(
        pair=pair,
        gear_index=gear_index,
        face_width_m=b,
        mesh_scale=float(mesh_scale),
        radius_m=R,
        stress_um_per_N_per_mm=out2["stress"] * c,
        strain_um_per_N_per_mm=out2["strain"] * c,
        average_um_per_N_per_mm=avg * c,
        mid_um_per_N_per_mm=mid * c,
        ndofs_2d=int(ndofs_2d),
        ndofs_3d=int(ndofs_3d),
        n_triangles=int(sec.n_elements),
        n_tetrahedra=solid.n_elements,
        n_layers=len(solid.planes_z_m) - 1,
        timings={
            "mesh_s": t_mesh,
            "stress_s": t2["stress"],
            "strain_s": t2["strain"],
            "solid_s": t_solid,
            "total_s": time.perf_counter() - t_start,
        },
    )


def solid_stiffness(mesh, lam: float, mu: float, chunk: int = 20000) -> tuple[sp.csr_matrix, Basis]:
    """Stiffness matrix of 3D linear elasticity with P2 tetrahedra and the scalar P2 basis
    whose dof d carries the displacement components at rows 3 d, 3 d + 1, 3 d + 2.

        K_ab^ij = int lambda d_i phi_a d_j phi_b + mu (delta_ij grad phi_a . grad phi_b
                  + d_j phi_a d_i phi_b) dV

    On straight tetrahedra the integrand is quadratic, so the 4-point rule (order 2) is
    exact. Element matrices are formed in chunks of elements by one contraction each
    (scikit-fem's generic form is ~10 times slower for this element)."""
    sb = Basis(mesh, ElementTetP2(), intorder=2)
    nloc = sb.Nbfun
    rows, cols, vals = [], [], []
    dofs = sb.element_dofs  # (10, nel)
    eye = np.eye(3)
    for e0 in range(0, mesh.t.shape[1], chunk):
        sl = slice(e0, min(e0 + chunk, mesh.t.shape[1]))
        G = np.stack([sb.basis[a][0].grad[:, sl] for a in range(nloc)])  # (a, i, e, q)
        A = np.einsum("aieq,bjeq,eq->eaibj", G, G, sb.dx[sl], optimize=True)
        D = np.einsum("eaibi->eab", A)
        Ke = lam * A + mu * (A.transpose(0, 1, 4, 3, 2) + D[:, :, None, :, None] * eye[None, None, :, None, :])
        gd = (3 * dofs[:, sl].T[:, :, None] + np.arange(3)[None, None, :]).reshape(-1, 3 * nloc)  # (e, 3 a + i)
        rows.append(np.repeat(gd, 3 * nloc, axis=1).ravel())
        cols.append(np.tile(gd, (1, 3 * nloc)).ravel())
        vals.append(Ke.reshape(-1, 3 * nloc * 3 * nloc).ravel())
    n = 3 * sb.N
    K = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)).tocsr()
    return K, sb


def _solve_solid(
    solid: SolidMesh, material, pts: np.ndarray, forces: np.ndarray, read: np.ndarray, e_F: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int]:
    """(face-averaged, mid-plane compliance (m^2/N) per radius, dofs) of the 3D half model."""
    lam, mu = lame_parameters(material.youngs_modulus_Pa, material.poisson_ratio)
    K, sb = solid_stiffness(solid.mesh, lam, mu)
    bd = solid.boundaries
    held = sb.get_dofs(facets=np.concatenate([bd["hub_arc"], bd["cut_left"], bd["cut_right"]])).all()
    sym = sb.get_dofs(facets=bd["bottom"]).all()
    fixed = np.union1d((3 * held[:, None] + np.arange(3)).ravel(), 3 * sym + 2)
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    depth = solid.depth_m
    zq, wq = z_rule(solid.planes_z_m)
    n, k = pts.shape[:2]
    F = np.zeros((K.shape[0], n))
    for i in range(n):
        # patch point j on the line z: force f_j w_q (1 N/m along the face)
        xyz = np.vstack([np.repeat(pts[i, :, 0], len(zq)), np.repeat(pts[i, :, 1], len(zq)), np.tile(zq, k)])
        P = sb.probes(xyz).tocsr()  # (npts, N) scalar values
        wt = np.tile(wq, k)
        for c in (0, 1):
            F[c::3, i] = P.T @ (np.repeat(forces[i, :, c], len(zq)) * wt)
    U = np.zeros_like(F)
    U[free] = solve_spd(K[free][:, free].tocsr(), F[free], rigid_body_modes(sb.doflocs)[free])
    avg, mid = np.zeros(n), np.zeros(n)
    for i in range(n):
        line = np.vstack(
            [np.full(len(zq) + 1, read[i, 0]), np.full(len(zq) + 1, read[i, 1]), np.concatenate([[0.0], zq])]
        )
        Q = sb.probes(line).tocsr()
        uF = (Q @ U[0::3, i]) * e_F[i, 0] + (Q @ U[1::3, i]) * e_F[i, 1]
        mid[i] = uF[0]
        avg[i] = float(uF[1:] @ wq) / depth
    return avg, mid, int(K.shape[0])


def rigid_body_modes(points: np.ndarray) -> np.ndarray:
    """(3 N, 6) the three translations and three rotations at ``points`` (3, N), rows
    3 d + i as in :func:`solid_stiffness`: the near-null space of elasticity."""
    x, y, z = points
    n = points.shape[1]
    B = np.zeros((n, 3, 6))
    B[:, 0, 0] = B[:, 1, 1] = B[:, 2, 2] = 1.0
    B[:, 0, 3], B[:, 1, 3] = -y, x
    B[:, 1, 4], B[:, 2, 4] = -z, y
    B[:, 0, 5], B[:, 2, 5] = z, -x
    return B.reshape(3 * n, 6)


#: relative residual of the conjugate-gradient solves of the 3D model
CG_RTOL = 1e-10
#: below this many unknowns the 3D system is factorized (SuperLU) instead
DIRECT_MAX_DOFS = 40000


def solve_spd(A: sp.csr_matrix, F: np.ndarray, modes: np.ndarray) -> np.ndarray:
    """Solutions of A X = F (A symmetric positive definite, one column per load) by a
    direct factorization up to DIRECT_MAX_DOFS unknowns, else by conjugate gradients
    preconditioned with smoothed-aggregation algebraic multigrid (pyamg; ``modes``: the
    near-null space, rigid-body modes) to a relative residual of CG_RTOL. SuperLU's
    orderings fill 3D P2 matrices badly (144k unknowns: 10 min, 2 cores); the multigrid
    solve takes seconds."""
    if A.shape[0] <= DIRECT_MAX_DOFS:
        lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        return lu.solve(np.ascontiguousarray(F))
    import pyamg

    ml = pyamg.smoothed_aggregation_solver(A, B=modes, symmetry="hermitian", max_coarse=2000)
    X = np.zeros_like(F)
    for j in range(F.shape[1]):
        res: list[float] = []
        X[:, j] = ml.solve(F[:, j], tol=CG_RTOL, accel="cg", maxiter=2000, residuals=res)
        if res[-1] > CG_RTOL * 10 * res[0]:
            raise RuntimeError(
                f"3D solve did not converge: relative residual {res[-1] / res[0]:.2e} after {len(res)} iterations"
            )
    return X
