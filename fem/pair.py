"""Tooth-pair contact of a spur pair by FE influence coefficients: loaded static
transmission error and mesh stiffness over one mesh period, nominal and worn.

Model (SI units: m, N, rad, Pa)
-------------------------------
Both gears are full FE bodies (Gmsh P2 triangles, scikit-fem, plane stress by
default, thickness = face width b) with the bore fixed. The driver torque T gives
the total normal force F = T / r_b1 along the line of action (LOA). With the bores
fixed, the rigid-body unknown is the hub rotation: r_b1 theta_1 (driver turned, the
driven hub held) is the approach delta of the pair along the LOA = the loaded static
transmission error (STE), measured from the rigid, unworn position.

The deformation of a tooth pair k at LOA position d_k is split in three parts
(Weber 1949; Cornell 1981; the split used by the analytic single-tooth models):

(i)  body deflection: FE influence coefficients of each gear body. A unit load is
     applied on the loaded flank of tooth 0 as a Hertzian pressure patch (semi-
     ellipse of the static-share Hertz half-width a, 8-point Gauss-Chebyshev, each
     point's consistent P2 nodal load P^T f) at the contact point of radius R; the
     displacement is read at the point where the load line crosses the tooth centre
     line, y_c = y_F - x_F tan w (distance h = x_F / cos w from the contact,
     analytic.loading), and projected on the load direction. Read there the
     displacement stays finite under mesh refinement (the log-singular Hertz field
     is excluded) and includes bending, shear, rim/foundation and the rotation of
     the rim. It is the point where Weber's h in (ii) ends, so (i) + (ii) add up to
     the approach of the contact point; a rigid rotation of the tooth moves all
     points of the load line equally along it. fem.tooth reads at (0, R) instead
     (the centre line at the load radius): that point lies 0.7-1.3 mm off the load
     line and adds the tooth rotation times that offset plus part of the local
     field, +6 to +13 % compliance on the paper pinion (``read_at="radius"``
     reproduces it; the mean mesh stiffness drops by 6.7 %). Cross terms (a load on one
     tooth moves the neighbouring tooth through the rim) are read at the centre-line
     points of the neighbouring teeth. Rotational periodicity of the gear body makes
     one loaded tooth enough: the coefficient between a load on tooth t_j and the
     reading on tooth t_i equals that of a load on tooth 0 read on tooth t_i - t_j.
     So only tooth 0's active flank is refined, every load case sits on it, and one
     factorization per gear serves all positions (for identical unworn gears the
     pinion model is reused for the gear).
(ii) local contact approach between the two centre-line points, 2D Hertz/Weber
     (Weber 1949; Weber & Banaschek 1953), plane strain:

         delta_W(F) = 2 F (1 - nu^2) / (pi E b) [ln(2 h1 / a) + ln(2 h2 / a) - nu / (1 - nu)]
         a = sqrt(4 (F / b) R* / (pi E*)),   1/E* = 2 (1 - nu^2) / E,
         R* = rho1 rho2 / (rho1 + rho2),   rho1 = d, rho2 = |T1T2| - d.

     Nonlinear in F (log); it enters the contact solve as a secant compliance
     delta_W(F_k) / F_k, iterated to a fixed point (relative change < 1e-13).
     ``contact_plane="stress"`` uses the plane-stress form (E, nu replaced by
     E (1 + 2 nu) / (1 + nu)^2, nu / (1 + nu) in the plane-strain formula).
(iii) load sharing among the pairs by the complementarity solve of fem.contact
     (the solver verified on the Hertz cylinders): with C the sum of both gears'
     influence matrices (i) plus diag(delta_W(F_k) / F_k), initial gaps g_k from
     wear (geometry.wear.wear_on_line_of_action: h1 + h2 at d_k, along the involute
     normal = the LOA) and sum F_k = F:

         gap_k = g_k + (C F)_k - STE >= 0,  F_k >= 0,  F_k gap_k = 0.

Mesh stiffness, same definition as analytic.tvms: k = sum over loaded pairs of
F_k / (STE - g_k) (secant; F / STE when unworn), so F = k (STE - e) with the wear
excitation e = sum k_k g_k / k. The tangent stiffness dF/dSTE (central difference of
the whole solve at F (1 +- 1e-3)) is returned as well.

Why this method (and not a resolved Hertz zone at every position): a ~ 0.06-0.1 mm
at 40 N m needs elements of ~a/10 at each contact point, i.e. a new mesh and
factorization per position (24 positions x 2 gears), and the contact zone would have
to be re-meshed as the contact moves along the flank. The split (i)+(ii) needs one
factorization per gear: the Hertz near field enters through Weber's closed form,
which is the same local solution the Hertz-cylinder test of fem.contact verifies, and
the FE part is read where it converges (0.02 % from the extrapolated limit at the
default sizes, :func:`default_sizes`). The same complementarity solver that
reproduces the Hertz cylinders (fem.contact) shares the load. A full-gear mesh
(all z teeth) is used, so no sector cut conditions are needed. Tip-corner contact
outside the theoretical path of contact [A, E] is not modelled: the candidate pairs
are those inside the path, as analytic.tvms with corner_contact=False.

Wear: the loaded (right) flanks of all teeth of the FE bodies are the worn profiles
(geometry.wear.worn_profiles shape and depth), so each gear has its own mesh; the
contact point and centre-line point are those of the worn flank at the nominal
contact radius (as analytic.loading does).

Result for the paper pair (default_pair, 40 N m, 24 positions, defaults: plane
stress bodies, plane-strain Weber, P2, mesh_scale 1; 7-16 s wall on 2 cores)
--------------------------------------------------------------------------------
              mean k (N/m)  single    double    mean STE   Ishikawa mean (no corner / corner)
   unworn     3.482e8       2.589e8   3.928e8   1.69 um    4.319e8 (-19.4 %) / 4.400e8 (-20.9 %)
   mild       2.668e8       2.589e8   2.708e8   5.95 um    3.135e8 (-14.9 %) / 3.135e8
   severe     2.569e8       2.589e8   2.560e8   13.47 um   2.934e8 (-12.4 %) / 2.934e8

The FE mean is 19 % below Ishikawa for the unworn pair. Switching the FE model's
extra physics off one by one (``coupling``, ``local_contact``, ``plane``) accounts
for all of it: without the coupling of neighbouring teeth through the rim (which
the slice model does not have) -11.1 %; then with paper Eq. 5 instead of Weber's
2D contact approach -4.5 %; then plane strain instead of plane stress +1.0 % (single
contact +0.2 %, double +1.2 %). So the FE body compliance agrees with Ishikawa's
delta_1 + delta_2; the difference is the rim coupling (double contact only: -21.6 %
vs -12.0 % in single contact), Weber's contact law being ~25 % more compliant than
Eq. 5 at this load, and plane stress.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from geometry.kinematics import MeshGeometry
from geometry.mesh import MeshSizes, mesh_full_gear
from geometry.operating import operating_geometry
from geometry.profile import FILLET, INVOLUTE, ToothProfile, tooth_outline, tooth_profile
from geometry.spec import PairSpec
from geometry.wear import (WearSpec, flank_depth, hertz_half_width, key_roll_angles, load_share,
                           wear_on_line_of_action)
from analytic.ishikawa import hertz_approach_m
from analytic.loading import load_points
from analytic.tvms import CurveStats

from .contact import solve_contact
from .elasticity import assemble

__all__ = ["PairFE", "GearBody", "pair_contact", "compare_with_analytic", "weber_approach_m",
           "build_gear_body", "default_sizes"]

N_PATCH = 8  # Gauss-Chebyshev points of the Hertzian pressure patch


# ---------------------------------------------------------------------------
# result
# ---------------------------------------------------------------------------


@dataclass
class PairFE(CurveStats):
    """FE mesh stiffness over one mesh period (SI units).

    angle_rad          (n,) pinion angle, 0 when a pair enters at A (as analytic.tvms)
    k_N_per_m          (n,) secant mesh stiffness sum_k F_k / (STE - g_k)
    k_tangent_N_per_m  (n,) dF / dSTE
    ste_m              (n,) loaded static transmission error (approach along the LOA)
    excitation_m       (n,) e with F = k (STE - e) (0 when unworn)
    pair_load_N        (n, p) load of each candidate slot (columns as analytic.tvms)
    pair_d_m           (n, p) LOA position of each slot
    pair_in_path       (n, p) slot inside the path of contact [A, E]
    timings            wall times (s) of the stages
    meta               mesh sizes, element counts, options
    """

    pair: PairSpec
    mesh: MeshGeometry
    torque_Nm: float
    wear: WearSpec | None
    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    k_tangent_N_per_m: np.ndarray
    ste_m: np.ndarray
    excitation_m: np.ndarray
    pair_load_N: np.ndarray
    pair_d_m: np.ndarray
    pair_in_path: np.ndarray
    timings: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)

    def zone_means(self) -> dict[str, float]:
        z = self.zone_masks()
        dbl = z["A"] | z["C"]
        return {"single": float(np.mean(self.k_N_per_m[z["B"]])) if z["B"].any() else float("nan"),
                "double": float(np.mean(self.k_N_per_m[dbl])) if dbl.any() else float("nan")}


# ---------------------------------------------------------------------------
# local (Weber) contact approach
# ---------------------------------------------------------------------------


def _plane_constants(E: float, nu: float, plane: str) -> tuple[float, float]:
    """(E', nu') that turn the plane-strain formulas into the requested state."""
    if plane == "strain":
        return E, nu
    if plane == "stress":
        return E * (1 + 2 * nu) / (1 + nu) ** 2, nu / (1 + nu)
    raise ValueError(f"plane = {plane!r}: must be 'stress' or 'strain'")


def weber_approach_m(F_N, h1_m, h2_m, R_star_m, E_Pa: float, nu: float, b_m: float,
                     plane: str = "strain") -> np.ndarray:
    """Weber (1949) approach of the two centre-line points of a line contact (m):
    2 F (1 - nu^2)/(pi E b) [ln(2 h1/a) + ln(2 h2/a) - nu/(1 - nu)] with the Hertz
    half-width a = sqrt(4 (F/b) R* / (pi E*)), 1/E* = 2 (1 - nu^2)/E (plane strain;
    ``plane="stress"`` converts E, nu). Zero for F <= 0."""
    Ep, nup = _plane_constants(E_Pa, nu, plane)
    F = np.maximum(np.asarray(F_N, dtype=float), 0.0)
    E_star = Ep / (2.0 * (1.0 - nup ** 2))
    Fs = np.where(F > 0, F, 1.0)
    a = np.sqrt(4.0 * (Fs / b_m) * np.asarray(R_star_m) / (math.pi * E_star))
    br = np.log(2.0 * np.asarray(h1_m) / a) + np.log(2.0 * np.asarray(h2_m) / a) - nup / (1.0 - nup)
    return np.where(F > 0, 2.0 * F * (1.0 - nup ** 2) / (math.pi * Ep * b_m) * br, 0.0)


# ---------------------------------------------------------------------------
# gear body: outline, mesh, model
# ---------------------------------------------------------------------------


def default_sizes(module_m: float, mesh_scale: float = 1.0) -> dict:
    """Element sizes (m) of the gear bodies, proportional to the module m: global
    0.3 m, fillets of the loaded and the two neighbouring teeth on each side 0.05 m,
    the loaded flank of tooth 0 0.025 m (about 2 a at 40 N m: the patch need not be
    resolved, only the field at the centre line h ~ 3-4 mm away), outline spacing of
    the other teeth 0.125 m. Measured convergence of the mean stiffness of the paper
    pair (extrapolated limit 3.4812e8 N/m): mesh_scale 4 +1.9 %, 2 +0.24 %, 1 +0.02 %;
    the error falls roughly as h^3."""
    s = float(mesh_scale)
    if not (s > 0 and math.isfinite(s)):
        raise ValueError(f"mesh_scale = {mesh_scale!r}: must be finite and > 0")
    return {"global_m": 0.3 * module_m * s, "fillet_m": 0.05 * module_m * s,
            "load_m": 0.025 * module_m * s, "far_tooth_m": 0.125 * module_m * s}


def _resample(profile: ToothProfile, spacing: np.ndarray) -> ToothProfile:
    """Subset of the dense profile points with arc-length steps of about ``spacing``
    (per point). The ends, the start of the involute (form circle) and the tip corner
    are kept; a step shorter than half the spacing before a kept point is merged into
    the previous one (a very short outline edge would force slivers in the mesh)."""
    s = profile.s
    n = len(s)
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[-1] = True
    inv = np.flatnonzero(profile.region == INVOLUTE)
    if inv.size:
        keep[inv[0]] = keep[inv[-1]] = True
    out = [0]
    i = 0
    while i < n - 1:
        # farthest point within the local spacing, but never past a kept point
        j = int(np.searchsorted(s, s[i] + spacing[i], side="right")) - 1
        j = max(j, i + 1)
        nxt = np.flatnonzero(keep[i + 1: j + 1])
        if nxt.size:
            j = i + 1 + int(nxt[0])
            if len(out) > 1 and not keep[out[-1]] and s[j] - s[i] < 0.5 * spacing[i]:
                out.pop()
        out.append(j)
        i = j
    idx = np.asarray(out)
    kw = {k: getattr(profile, k)[idx] for k in ("xy", "normal", "s", "radius", "roll", "region")}
    if profile.depth is not None:
        kw["depth"] = profile.depth[idx]
    return replace(profile, **kw)


@dataclass
class GearBody:
    """One gear's FE model with its loaded profile (tooth 0 frame: tooth axis +y,
    loaded flank x > 0)."""

    index: int
    profile: ToothProfile          # loaded flank (worn or nominal), dense
    nominal: ToothProfile
    model: object                  # fem.elasticity.ElasticModel
    flank_xy: np.ndarray           # tooth-0 loaded flank polyline as meshed
    n_elements: int
    ndofs: int
    timings: dict


def build_gear_body(pair: PairSpec, index: int, loaded: ToothProfile, nominal: ToothProfile,
                    mesh: MeshGeometry, mesh_scale: float = 1.0, order: int = 2,
                    plane: str = "stress") -> GearBody:
    """Mesh a full gear (all loaded flanks = ``loaded``; tooth 0's active flank and the
    fillets of teeth -2..2 refined), fix the bore, assemble and factorize."""
    g = pair.gear(index)
    z = g.teeth
    sz = default_sizes(pair.module_m, mesh_scale)
    t0 = time.perf_counter()
    # active flank radii of this gear (plus a margin of two fine elements)
    r_sap = mesh.start_of_active_profile_m[index]
    in_active = (loaded.region == INVOLUTE) & (loaded.radius >= r_sap - 2 * sz["load_m"])
    fil = loaded.region == FILLET
    far = np.full(len(loaded.s), sz["far_tooth_m"])
    near = np.where(fil, sz["fillet_m"], sz["far_tooth_m"])
    loaded0 = np.where(in_active, sz["load_m"], near)
    near_n = np.where(nominal.region == FILLET, sz["fillet_m"], sz["far_tooth_m"])
    far_n = np.full(len(nominal.s), sz["far_tooth_m"])
    out_far = tooth_outline(_resample(loaded, far), _resample(nominal, far_n))
    out_near = tooth_outline(_resample(loaded, near), _resample(nominal, near_n))
    out_0 = tooth_outline(_resample(loaded, loaded0), _resample(nominal, near_n))
    pieces = []
    for k in range(z):
        kk = k if k <= z // 2 else k - z  # signed tooth index
        base = out_0 if kk == 0 else (out_near if abs(kk) <= 2 else out_far)
        ang = 2.0 * math.pi * k / z
        c, s = math.cos(ang), math.sin(ang)
        pts = base @ np.array([[c, -s], [s, c]]).T
        pieces.append(pts if not pieces else pts[1:])
    outline = np.vstack(pieces)[:-1]
    flank = _resample(loaded, loaded0)
    flank_xy = flank.xy[flank.region == INVOLUTE]
    refine = flank_xy[flank.radius[flank.region == INVOLUTE] >= r_sap - 2 * sz["load_m"]]
    fillets = []
    for kk in range(-2, 3):
        ang = 2.0 * math.pi * kk / z
        c, s = math.cos(ang), math.sin(ang)
        rot = np.array([[c, -s], [s, c]])
        for prof, sign in ((loaded, 1.0), (nominal, -1.0)):
            pts = prof.xy[prof.region == FILLET] * np.array([sign, 1.0])
            fillets.append(pts[:: max(1, len(pts) // 12)] @ rot.T)
    sizes = MeshSizes(global_m=sz["global_m"], fillet_m=sz["fillet_m"], load_m=sz["load_m"],
                      load_dist_m=2.0 * sz["load_m"], fillet_dist_m=2.0 * sz["fillet_m"], growth=0.25)
    gm = mesh_full_gear(outline, g.hub_radius_m, sizes, refine_points_xy=refine,
                        fillet_points_xy=np.vstack(fillets), order=order)
    t1 = time.perf_counter()
    model = assemble(gm.mesh, pair.material, pair.face_width_m, gm.boundaries["bore"], plane=plane, order=order)
    timings = {"mesh_s": t1 - t0, **model.timings}
    return GearBody(index, loaded, nominal, model, flank_xy, gm.n_elements, model.ndofs, timings)


def _rot(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _project_on_polyline(pts: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Nearest points of the polyline to ``pts``."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    L2 = np.einsum("ij,ij->i", ab, ab)
    out = np.empty_like(pts)
    for i, p in enumerate(pts):
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / L2, 0.0, 1.0)
        q = a + t[:, None] * ab
        k = int(np.argmin(np.einsum("ij,ij->i", q - p, q - p)))
        out[i] = q[k]
    return out


def _probe(model, pts: np.ndarray, chunk: int = 64):
    """model.probe in chunks (skfem's element finder falls back to a search over all
    elements for a whole call when one point is not among the nearest centroids)."""
    import scipy.sparse as sp

    blocks = [model.probe(pts[i: i + chunk]) for i in range(0, len(pts), chunk)]
    return sp.vstack(blocks).tocsr()


def _contact_data(body: GearBody, radius_m: np.ndarray, read_at: str = "load_line"):
    """Contact point, load direction (unit force on this gear) and centre-line reading
    point in the tooth-0 frame, and h (contact point to centre line along the load
    line). read_at "load_line": (0, y_c), where the load line crosses the centre line;
    "radius": (0, R), the centre-line point at the load radius (fem.tooth)."""
    lp = load_points(body.profile, radius_m)
    c = np.column_stack([lp.x_m, lp.y_m])
    e = -np.column_stack([np.cos(lp.w_rad), np.sin(lp.w_rad)])
    # (0, R) at a tip contact is the tip-land vertex: keep the probe 1 um inside
    yq = lp.y_axis_m if read_at == "load_line" else np.minimum(lp.radius_m, body.profile.gear.tip_radius_m - 1e-6)
    q = np.column_stack([np.zeros_like(yq), yq])
    h = lp.x_m / np.cos(lp.w_rad)
    return c, e, q, h


def _patch_loads(body: GearBody, c: np.ndarray, e: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Load vectors (N, n) of unit resultant Hertzian patches centred at c along e."""
    k = np.arange(1, N_PATCH + 1)
    xi = np.cos(k * math.pi / (N_PATCH + 1))
    wts = np.sin(k * math.pi / (N_PATCH + 1)) ** 2
    wts = wts / wts.sum()  # Gauss-Chebyshev (2nd kind) for the semi-ellipse, unit total
    t = np.column_stack([-e[:, 1], e[:, 0]])  # flank tangent (perpendicular to the load)
    n = len(c)
    pts = (c[:, None, :] + (a[:, None] * xi[None, :])[:, :, None] * t[:, None, :]).reshape(-1, 2)
    pts = _project_on_polyline(pts, body.flank_xy)
    # move the points 1 nm (1e-5 of the flank element size) into the body so that
    # the element finder sees them inside; the consistent load changes by ~1e-5
    pts = pts + 1e-9 * np.repeat(e, N_PATCH, axis=0)
    Pm = _probe(body.model, pts)
    f = np.zeros((2 * n * N_PATCH, n))
    rows = np.arange(n * N_PATCH)
    cols = np.repeat(np.arange(n), N_PATCH)
    w = np.tile(wts, n)
    f[2 * rows, cols] = w * np.repeat(e[:, 0], N_PATCH)
    f[2 * rows + 1, cols] = w * np.repeat(e[:, 1], N_PATCH)
    return np.asarray(Pm.T @ f)


# ---------------------------------------------------------------------------
# the pair solve
# ---------------------------------------------------------------------------


def _profiles(pair: PairSpec, wear: WearSpec | None, mesh: MeshGeometry):
    """(nominal, loaded) profiles of both gears, as analytic.tvms builds them."""
    nominal = tuple(tooth_profile(g, extra_roll=key_roll_angles(mesh, i, wear)) for i, g in enumerate(pair.gears))
    if wear is None or wear.is_unworn:
        return nominal, nominal
    loaded = tuple(p.worn(flank_depth(p, i, mesh, wear)) for i, p in enumerate(nominal))
    return nominal, loaded


def _influence(body: GearBody, z: int, radii_load: np.ndarray, a_load: np.ndarray,
               reads: list[tuple[int, float]], read_at: str = "load_line") -> tuple[np.ndarray, dict]:
    """Influence coefficients (m/N): rows = reads (relative tooth, radius), columns =
    unit loads on tooth 0 at radii_load. One multi-RHS solve on the factorized body."""
    t0 = time.perf_counter()
    c, e, _, _ = _contact_data(body, radii_load)
    Fm = _patch_loads(body, c, e, a_load)
    t1 = time.perf_counter()
    U = body.model.solve(Fm)
    t2 = time.perf_counter()
    rel = np.array([r[0] for r in reads])
    rr = np.array([r[1] for r in reads])
    _, er, qr, _ = _contact_data(body, rr, read_at)
    pts = np.empty_like(qr)
    dirs = np.empty_like(er)
    for t in np.unique(rel):
        m = rel == t
        R = _rot(2.0 * math.pi * t / z)
        pts[m] = qr[m] @ R.T
        dirs[m] = er[m] @ R.T
    Pm = _probe(body.model, pts)
    uv = np.asarray(Pm @ U)  # (2 nread, nload)
    Cr = uv[0::2] * dirs[:, 0:1] + uv[1::2] * dirs[:, 1:2]
    return Cr, {"load_vectors_s": t1 - t0, "solve_s": t2 - t1, "read_s": time.perf_counter() - t2}


def _solve_position(Cb: np.ndarray, gaps: np.ndarray, F: float, weber) -> tuple[np.ndarray, float]:
    """Contact solve with the nonlinear Weber term as a secant compliance, iterated."""
    n = len(gaps)
    Fk = np.full(n, F / n)
    s = weber(Fk) / Fk
    for _ in range(200):
        sol = solve_contact(Cb + np.diag(s), gaps, total_force_N=F)
        Fnew = sol.force_N
        # unloaded pairs keep a secant at the mean load: it only steers the active set
        s_new = np.where(Fnew > 0, weber(np.where(Fnew > 0, Fnew, 1.0)) / np.where(Fnew > 0, Fnew, 1.0), s)
        if np.max(np.abs(Fnew - Fk)) <= 1e-13 * F and np.all(np.abs(s_new - s) <= 1e-13 * np.abs(s)):
            return Fnew, sol.approach_m
        Fk, s = Fnew, s_new
    raise RuntimeError("Weber secant iteration did not converge")


def pair_contact(pair: PairSpec, wear: WearSpec | None = None, positions: int = 24, torque_Nm: float = 40.0,
                 clearance_m: float = 0.0, order: int = 2, mesh_scale: float = 1.0,
                 plane: str = "stress", contact_plane: str = "strain", coupling: bool = True,
                 local_contact: str = "weber", read_at: str = "load_line") -> PairFE:
    """FE static transmission error and mesh stiffness at ``positions`` pinion angles
    theta = i (2 pi / z1) / positions (theta = 0 when a pair enters at A).

    The centre distance follows from the bearing clearance as in analytic.tvms
    (rigid bearings). ``plane``: state of the FE gear bodies; ``contact_plane``: state
    of the local Weber term (plane strain: the Hertz zone, a << b, is constrained
    along the face width). See the module docstring for the method.

    Diagnostics (to attribute differences to the analytic model, not for use):
    ``coupling=False`` drops the cross terms between teeth (each pair sees only its
    own teeth, as the analytic model assumes); ``local_contact="eq5"`` replaces
    Weber's centre-line approach by the analytic Hertz law 1.275 F^0.9 / (E^0.9 b^0.8)
    (paper Eq. 5; a surface approach, so it is not consistent with the centre-line
    reading); ``read_at="radius"`` reads the body displacement at the centre-line
    point (0, R) at the load radius (the fem.tooth extraction) instead of where the
    load line crosses the centre line (Weber's h ends there, so only "load_line"
    makes (i) + (ii) additive).
    """
    t_start = time.perf_counter()
    if not isinstance(positions, (int, np.integer)) or positions < 2:
        raise ValueError(f"positions = {positions!r}: must be a whole number >= 2")
    if not (torque_Nm > 0 and math.isfinite(torque_Nm)):
        raise ValueError(f"torque_Nm = {torque_Nm!r}: must be finite and > 0")
    if local_contact not in ("weber", "eq5"):
        raise ValueError(f"local_contact = {local_contact!r}: must be 'weber' or 'eq5'")
    if read_at not in ("load_line", "radius"):
        raise ValueError(f"read_at = {read_at!r}: must be 'load_line' or 'radius'")
    og = operating_geometry(pair, clearance_m)
    mesh = og.mesh
    worn = wear is not None and not wear.is_unworn
    nominal, loaded = _profiles(pair, wear, mesh)
    rb1, rb2 = pair.gear(0).base_radius_m, pair.gear(1).base_radius_m
    L, pb = mesh.line_of_action_m, mesh.base_pitch_m
    A, E = mesh.path_start_m, mesh.path_end_m
    theta = np.arange(positions) * (mesh.mesh_angle_rad / positions)
    nslots = int(math.ceil(mesh.contact_ratio)) + 3
    j = np.arange(-1, nslots - 1)  # the slot layout of analytic.tvms
    d = A + rb1 * theta[:, None] + j[None, :] * pb
    in_path = (d >= A - 1e-12 * pb) & (d <= E + 1e-12 * pb)
    F = torque_Nm / rb1
    mat = pair.material
    b = pair.face_width_m
    t_prof = time.perf_counter()

    # -- bodies (identical unworn gears share one model)
    same = (not worn) and pair.gear(0).teeth == pair.gear(1).teeth and \
        replace(pair.gear(0), name="") == replace(pair.gear(1), name="")
    bodies = [build_gear_body(pair, 0, loaded[0], nominal[0], mesh, mesh_scale, order, plane)]
    bodies.append(bodies[0] if same else build_gear_body(pair, 1, loaded[1], nominal[1], mesh, mesh_scale,
                                                         order, plane))
    t_bodies = time.perf_counter()

    # -- contact geometry of every candidate (position, slot)
    pos_idx, slot_idx = np.nonzero(in_path)
    dc = d[pos_idx, slot_idx]
    R = [np.sqrt(rb1 ** 2 + dc ** 2), np.sqrt(rb2 ** 2 + (L - dc) ** 2)]
    # pinion slot j sits on tooth -j, gear slot j on tooth +j (tooth 0 frame of each
    # gear, loaded flank x > 0): then all simultaneous loads share one LOA direction
    tooth = [-j[slot_idx], j[slot_idx]]
    Rstar = dc * (L - dc) / L
    a_patch = hertz_half_width(mesh, dc, F * load_share(mesh, dc) / b)
    h, dirs = [], []
    for gi in (0, 1):
        _, ee, _, hh = _contact_data(bodies[gi], R[gi])
        h.append(hh)
        # load direction in the gear's fixed frame (tooth t = tooth 0 turned by 2 pi t / z)
        ang = 2.0 * math.pi * tooth[gi] / pair.gear(gi).teeth
        c_, s_ = np.cos(ang), np.sin(ang)
        dirs.append(np.column_stack([c_ * ee[:, 0] - s_ * ee[:, 1], s_ * ee[:, 0] + c_ * ee[:, 1]]))
    # self-check of the slot -> tooth mapping: simultaneous loads share one LOA direction
    mismatch = 0.0
    for gi in (0, 1):
        for p_ in range(positions):
            m_ = pos_idx == p_
            if m_.sum() > 1:
                dd = dirs[gi][m_]
                mismatch = max(mismatch, float(np.max(np.abs(np.arctan2(
                    dd[:, 1] * dd[0, 0] - dd[:, 0] * dd[0, 1], dd @ dd[0])))))
    if worn:
        h1w, h2w = wear_on_line_of_action(mesh, wear, dc)
        gap_all = h1w + h2w
    else:
        gap_all = np.zeros(len(dc))

    # -- influence coefficients per gear: loads on tooth 0 at every candidate radius,
    # reads at (relative tooth, radius) of every other candidate of the same position
    C_pos = [np.zeros((positions, len(j), len(j))) for _ in (0, 1)]
    tim_inf = {}
    groups = [np.flatnonzero(pos_idx == p) for p in range(positions)]
    work = {}
    for gi in (0, 1):
        body = bodies[gi]
        work.setdefault(id(body), []).append(gi)
    for key, gis in work.items():
        body = bodies[gis[0]]
        loads_R, loads_a, reads, entries = [], [], [], []
        for gi in gis:
            base = len(loads_R)
            loads_R.extend(R[gi])
            loads_a.extend(a_patch)
            for p, grp in enumerate(groups):
                for ii in grp:
                    for jj in grp:
                        reads.append((int(tooth[gi][ii] - tooth[gi][jj]), float(R[gi][ii])))
                        entries.append((gi, p, slot_idx[ii], slot_idx[jj], base + jj))
        Cr, tinf = _influence(body, pair.gear(gis[0]).teeth, np.asarray(loads_R), np.asarray(loads_a), reads,
                              read_at)
        for (gi, p, si, sj, col), row in zip(entries, range(len(reads))):
            C_pos[gi][p, si, sj] = Cr[row, col]
        for k2, v in tinf.items():
            tim_inf[k2] = tim_inf.get(k2, 0.0) + v
    t_inf = time.perf_counter()

    # -- contact solve per position
    loads = np.zeros(d.shape)
    ste = np.zeros(positions)
    ktan = np.zeros(positions)
    asym = 0.0
    for p, grp in enumerate(groups):
        sl = slot_idx[grp]
        Cb = C_pos[0][p][np.ix_(sl, sl)] + C_pos[1][p][np.ix_(sl, sl)]
        asym = max(asym, float(np.max(np.abs(Cb - Cb.T)) / np.max(np.abs(Cb))))
        # loads act on the flank, displacements are read on the centre line, so C is
        # not exactly reciprocal (asymmetry ~1e-3 of the largest entry, in meta);
        # its symmetric part is used (the solver's QP form needs a symmetric C)
        Cb = 0.5 * (Cb + Cb.T)
        if not coupling:
            Cb = np.diag(np.diag(Cb))

        if local_contact == "weber":
            def weber(Fk, grp=grp):
                return weber_approach_m(Fk, h[0][grp], h[1][grp], Rstar[grp], mat.youngs_modulus_Pa,
                                        mat.poisson_ratio, b, contact_plane)
        else:
            def weber(Fk):
                return hertz_approach_m(Fk, mat, b)

        Fk, delta = _solve_position(Cb, gap_all[grp], F, weber)
        loads[p, sl] = Fk
        ste[p] = delta
        eps = 1e-3
        _, dp = _solve_position(Cb, gap_all[grp], F * (1 + eps), weber)
        _, dm = _solve_position(Cb, gap_all[grp], F * (1 - eps), weber)
        ktan[p] = 2 * eps * F / (dp - dm)
    gaps = np.full(d.shape, np.inf)
    gaps[pos_idx, slot_idx] = gap_all
    on = loads > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        k_pair = np.where(on, loads / np.maximum(ste[:, None] - np.where(on, gaps, 0.0), 1e-300), 0.0)
    k = k_pair.sum(axis=1)
    exc = np.where(k > 0, (k_pair * np.where(on, gaps, 0.0)).sum(axis=1) / k, 0.0)
    t_end = time.perf_counter()
    timings = {"profiles_s": t_prof - t_start, "bodies_s": t_bodies - t_prof,
               "influence_s": t_inf - t_bodies, "contact_s": t_end - t_inf, "total_s": t_end - t_start,
               **{f"influence_{k2}": v for k2, v in tim_inf.items()}}
    for gi, body in enumerate(bodies):
        for k2, v in body.timings.items():
            timings[f"gear{gi}_{k2}"] = v
    meta = {"sizes_m": default_sizes(pair.module_m, mesh_scale), "mesh_scale": mesh_scale, "order": order,
            "plane": plane, "contact_plane": contact_plane, "shared_body": same,
            "n_elements": [bd.n_elements for bd in bodies], "ndofs": [bd.ndofs for bd in bodies],
            "flexibility_asymmetry": asym, "direction_mismatch_rad": mismatch, "coupling": coupling,
            "local_contact": local_contact, "read_at": read_at, "clearance_m": clearance_m, "corner_contact": False,
            "pair_gap_m": gaps}
    return PairFE(pair, mesh, torque_Nm, wear, theta, k, ktan, ste, exc, loads, d, in_path, timings, meta)


def compare_with_analytic(fe: PairFE, corner_contact: bool = False) -> dict:
    """Ishikawa mesh stiffness (analytic.tvms) at the same angles, torque, clearance and
    wear: means, zone means and the per-position relative difference (FE / analytic - 1)."""
    from analytic.tvms import mesh_stiffness

    an = mesh_stiffness(fe.pair, method="ishikawa", points=len(fe.angle_rad), torque_Nm=fe.torque_Nm,
                        clearance_m=fe.meta.get("clearance_m", 0.0), wear=fe.wear,
                        corner_contact=corner_contact)
    if not np.allclose(an.angle_rad, fe.angle_rad, rtol=0, atol=1e-15):
        raise RuntimeError("analytic and FE angles differ")
    z = fe.zone_masks()
    dbl = z["A"] | z["C"]
    return {
        "analytic": an,
        "mean_fe_N_per_m": fe.mean_N_per_m,
        "mean_analytic_N_per_m": an.mean_N_per_m,
        "mean_rel_diff": fe.mean_N_per_m / an.mean_N_per_m - 1.0,
        "per_position_rel_diff": fe.k_N_per_m / an.k_N_per_m - 1.0,
        "single_fe": float(np.mean(fe.k_N_per_m[z["B"]])), "single_analytic": float(np.mean(an.k_N_per_m[z["B"]])),
        "double_fe": float(np.mean(fe.k_N_per_m[dbl])), "double_analytic": float(np.mean(an.k_N_per_m[dbl])),
        "ste_mean_fe_m": float(np.mean(fe.ste_m)), "ste_mean_analytic_m": float(np.mean(an.ste_m)),
    }
