"""Time-varying mesh stiffness with load sharing, wear gaps and tip-corner contact.

For each pinion angle theta over one mesh period (theta = 0 when a pair enters the
path of contact at A) every candidate tooth pair k has

* a position d_k on the line of action (geometry.kinematics.MeshGeometry.slots),
* a linear compliance c_k = (delta_1 + delta_2)_pinion + (delta_1 + delta_2)_gear per
  unit load (Ishikawa slices or the potential-energy method, true worn profiles),
* a Hertzian approach: nonlinear a F^0.9 (paper Eq. 5) for ``ishikawa``, linear
  4 (1 - nu^2) / (pi E b) F (Yang & Lin) for ``energy``,
* an initial gap g_k along the line of action: the depths removed from both flanks at
  the contact, h_1(d) + h_2(d) (both measured along the involute normal = the LOA): wear
  (geometry.wear) plus profile modifications and measured deviations
  (geometry.flank), and on the faulty tooth's pair a spall (geometry.faults).

A fault on one tooth (a root crack: the cracked tooth's compliance; a spall: its gap)
makes the curve periodic over one revolution of the faulty gear: it then spans
``periods`` = z_g mesh periods (geometry.faults.revolution_periods) and the pair in slot
j of period n holds the teeth (n - j) mod z.

The static transmission error Delta (the approach of the gears along the LOA beyond
the rigid, unworn position) follows from compatibility and equilibrium
(complementarity: a pair with g_k >= Delta carries nothing):

    c_k F_k + delta_H(F_k) = Delta - g_k  if Delta > g_k, else F_k = 0;   sum_k F_k = F = T / r_b1

Sum F_k(Delta) is convex and increasing in Delta, so Newton's method from above
converges monotonically; loads sum to F to ~1e-13 relative.

Mesh stiffness: k_h = sum over loaded pairs of F_k / (Delta - g_k), the secant pair
stiffness of paper Eq. 6 summed over the pairs that carry load, so the mesh force is
F = k_h (Delta - e) with the wear excitation e = sum k_k g_k / k_h.

Tip-corner contact outside the path of contact: a pair approaching A (d < d_A) touches
first with the gear's tip corner, a receding pair (d > d_E) with the pinion's; the
corner's separation from the mating flank is computed exactly from the involute
functions (the two extended involutes touch at d; the corner lies on one of them at
the tip radius). Under load these pairs take load early / keep it late, which makes
the transmission error continuous at the zone changes. Their compliance is taken at
the path end (d_A or d_E) and their wear gap is that of the path end.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from gearwear.geometry.curves import CurveStats
from gearwear.geometry.faults import FaultSpec, faulty_slots, revolution_periods, spall_gap_m
from gearwear.geometry.flank import FlankSpec, modification_on_line_of_action
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import operating_geometry
from gearwear.geometry.profile import ToothProfile, tooth_profile
from gearwear.geometry.spec import PairSpec
from gearwear.core.validation import InputError, fail
from gearwear.geometry.wear import WearSpec, flank_depth, key_roll_angles, wear_on_line_of_action

from . import ishikawa

METHODS = ("ishikawa", "energy")


@dataclass(frozen=True)
class MeshStiffness(CurveStats):
    """A mesh stiffness curve over one mesh period (SI units).

    angle_rad       (n,) pinion angle from the entry of a pair at A
    k_N_per_m       (n,) mesh stiffness (sum of loaded pairs' secant stiffness)
    ste_m           (n,) loaded static transmission error along the LOA
    excitation_m    (n,) e with F = k_h (ste - e) (zero when unworn)
    pair_load_N     (n, p) load of each candidate pair (zero when not in contact)
    pair_d_m        (n, p) position of each candidate pair on the LOA
    pair_in_path    (n, p) True inside the theoretical path of contact [A, E]
    faulty_pair     (n, p) True where the slot holds the faulty tooth (None: no fault)
    periods         mesh periods the curve spans (1; z of the faulty gear with a fault)
    """

    method: str
    pair: PairSpec
    mesh: MeshGeometry
    torque_Nm: float
    wear: WearSpec | None
    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    ste_m: np.ndarray
    excitation_m: np.ndarray
    pair_load_N: np.ndarray
    pair_d_m: np.ndarray
    pair_in_path: np.ndarray
    wall_s: float = 0.0
    n_slices: int = ishikawa.DEFAULT_SLICES
    meta: dict = field(default_factory=dict)
    flank: FlankSpec | None = None
    faults: FaultSpec | None = None
    periods: int = 1
    faulty_pair: np.ndarray | None = None


# -- profiles and compliance ---------------------------------------------------------

@lru_cache(maxsize=64)
def _profiles(pair: PairSpec, wear: WearSpec | None, centre_distance_m: float):
    """(nominal, loaded) profiles of pinion and gear, cached: they depend only on the
    pair, the wear and the centre distance (which sets where the wear is)."""
    mesh = MeshGeometry(pair, centre_distance_m)
    nominal = tuple(tooth_profile(g, extra_roll=key_roll_angles(mesh, i, wear)) for i, g in enumerate(pair.gears))
    if wear is None or wear.is_unworn:
        return nominal, nominal
    loaded = []
    for i, p in enumerate(nominal):
        h = flank_depth(p, i, mesh, wear)
        loaded.append(p.worn(h))
    return nominal, tuple(loaded)


def _tooth_compliance(method: str, loaded: ToothProfile, nominal: ToothProfile, radius_m: np.ndarray,
                      pair: PairSpec, n_slices: int, crack=None) -> np.ndarray:
    """delta_1 + delta_2 per unit load (m/N) of one tooth at contact radii (``crack``: a
    geometry.crack.Crack at the root of this tooth, or None)."""
    if radius_m.size == 0:
        return np.zeros(0)
    if method == "ishikawa":
        try:
            c = ishikawa.tooth_compliance(loaded, radius_m, loaded.gear.material, pair.face_width_m, n_slices,
                                          opposite=nominal, crack=crack)
        except ValueError as exc:
            if not loaded.is_worn:
                raise  # a nominal tooth with a non-positive slice is our bug, not the user's input
            raise fail("wear depth", float(loaded.depth.max()) * 1e6, "um",
                       f"makes a slice of the {loaded.gear.name} tooth non-positive ({exc})") from None
        return c.total_m_per_N
    from . import energy
    ce = energy.tooth_compliance(loaded, radius_m, loaded.gear.material, pair.face_width_m, opposite=nominal,
                                 crack=crack)
    return np.asarray(ce.total_m_per_N)


def _involute_fn(u):
    return u - np.arctan(u)


def corner_gap_m(mesh: MeshGeometry, d, side: str) -> np.ndarray:
    """Separation (m) of a tip corner from the mating flank for a pair whose extended
    involutes touch at LOA position d.

    side = "entry": gear tip corner vs pinion flank (d near or below d_A);
    side = "exit": pinion tip corner vs gear flank (d near or above d_E).

    LOA frame: T1 = (0, 0), T2 = (L, 0), O1 = (0, -r_b1), O2 = (L, r_b2). On the pinion
    flank touching the LOA at d, theta_1 - inv = pi/2 - d / r_b1 (polar angle about O1);
    on the gear flank, theta_2 - inv = -pi/2 - (L - d) / r_b2 (about O2). Two involutes of
    one base circle turned by dphi are r_b dphi apart along every common normal.
    """
    d = np.asarray(d, dtype=float)
    g1, g2 = mesh.pair.gear(0), mesh.pair.gear(1)
    rb1, rb2, L = g1.base_radius_m, g2.base_radius_m, mesh.line_of_action_m
    u1 = d / rb1
    u2 = (L - d) / rb2
    if side == "entry":
        ua2 = math.sqrt((g2.tip_radius_m / rb2) ** 2 - 1.0)
        th = -0.5 * math.pi - u2 + _involute_fn(ua2)  # gear tip corner, polar angle about O2
        qx = L + g2.tip_radius_m * np.cos(th)
        qy = rb2 + g2.tip_radius_m * np.sin(th)
        r = np.hypot(qx, qy + rb1)
        ur = np.sqrt(np.maximum((r / rb1) ** 2 - 1.0, 0.0))
        psi_q = np.arctan2(qy + rb1, qx) - _involute_fn(ur)
        psi_flank = 0.5 * math.pi - u1
        return rb1 * np.abs(psi_q - psi_flank)
    ua1 = math.sqrt((g1.tip_radius_m / rb1) ** 2 - 1.0)
    th = 0.5 * math.pi - u1 + _involute_fn(ua1)  # pinion tip corner, polar angle about O1
    qx = g1.tip_radius_m * np.cos(th)
    qy = -rb1 + g1.tip_radius_m * np.sin(th)
    r = np.hypot(qx - L, qy - rb2)
    ur = np.sqrt(np.maximum((r / rb2) ** 2 - 1.0, 0.0))
    psi_q = np.arctan2(qy - rb2, qx - L) - _involute_fn(ur)
    psi_flank = -0.5 * math.pi - u2
    return rb2 * np.abs(psi_q - psi_flank)


# -- load sharing --------------------------------------------------------------------

def _pair_load(e, c, a, expo, warm=None):
    """Solve c F + a F^expo = e for F >= 0 (F = 0 where e <= 0) by Newton's method.

    Returns (F, dF/de) with dF/de = 1 / (c + a expo F^(expo - 1)) where F > 0, else 0.

    The left side is increasing and concave in F, so F(e) is convex: from above (the
    bound e / c), one step lands below the root; from below the iterates rise
    monotonically to it. ``warm`` = (F0, dF0, e0), the solution at an earlier e0 > e:
    its tangent F0 + dF0 (e - e0) starts below the root, off by O((e - e0)^2), and
    needs 1-2 steps. Only the pairs with e > 0 are iterated."""
    pos = e > 0
    F = np.where(pos, e / c, 0.0)
    if a == 0.0:
        return F, np.where(pos, 1.0 / c, 0.0)
    if warm is not None:
        F0, dF0, e0 = warm
        tangent = F0 + dF0 * (e - e0)
        F = np.where(pos & (tangent > 0), np.minimum(tangent, F), F)
    idx = np.flatnonzero(pos)
    ep, cp, Fk = e[idx], c[idx], F[idx]
    a_expo = a * expo
    for _ in range(60):
        Fp = np.maximum(Fk, 1e-300)  # F^(expo - 1) is infinite at 0
        Fe = Fp ** (expo - 1.0)
        slope = cp + a_expo * Fe
        step = ((cp + a * Fe) * Fp - ep) / slope
        Fk = np.maximum(Fk - step, 0.0)
        if np.all(np.abs(step) <= 1e-14 * Fk):
            break
    F[idx] = Fk
    dF = np.zeros(F.shape)
    # the slope before the last step, 1e-14 from the converged one: it only steers Newton
    dF[idx] = np.where(Fk > 0, 1.0 / slope, 0.0)
    return F, dF


def share_load(total_N: float, c: np.ndarray, gap: np.ndarray, a: float, expo: float):
    """Load sharing among candidate pairs (rows = angles, columns = pairs).

    c: linear compliance (m/N), inf where the slot has no candidate; gap (m); Hertz
    a F^expo. Returns (F (n, p), Delta (n,)). Works on the flattened candidates of all
    angles at once: Newton on every angle's Delta together, each step solving every
    pair's load.
    """
    cand = np.isfinite(c) & np.isfinite(gap)
    n = c.shape[0]
    if not np.all(cand.any(axis=1)):
        raise InputError("no tooth pair can come into contact at some angles (contact ratio far below one): "
                         "the static transmission error is undefined there")
    rows = np.nonzero(cand)[0]
    cc, gg = c[cand], gap[cand]
    # upper start: the smallest-gap pair alone carries everything; the total load is
    # convex and increasing in Delta, so Newton from above converges monotonically
    gfull = np.where(cand, gap, np.inf)
    k0 = np.argmin(gfull, axis=1)
    r = np.arange(n)
    delta = gfull[r, k0] + c[r, k0] * total_N + a * total_N ** expo
    warm = None
    for _ in range(100):
        e = delta[rows] - gg
        F, dF = _pair_load(e, cc, a, expo, warm)
        resid = np.bincount(rows, F, n) - total_N
        if np.all(np.abs(resid) <= 1e-13 * total_N):
            break  # F belongs to this delta
        slope = np.bincount(rows, dF, n)
        delta = delta - np.where(slope > 0, resid / np.where(slope > 0, slope, 1.0), 0.0)
        warm = (F, dF, e)
    # remove the last tiny Newton residual so the loads sum to the total exactly
    T = np.bincount(rows, F, n)
    F = F * (total_N / np.where(T > 0, T, 1.0))[rows]
    out = np.zeros(c.shape)
    out[cand] = F
    return out, delta


# -- the curve -----------------------------------------------------------------------

def mesh_stiffness(pair: PairSpec, method: str = "ishikawa", points: int = 360, torque_Nm: float = 40.0,
                   clearance_m: float = 0.0, wear: WearSpec | None = None,
                   bearing_stiffness_N_per_m: float = math.inf, n_slices: int = ishikawa.DEFAULT_SLICES,
                   corner_contact: bool = True, correction=None, flank: FlankSpec | None = None,
                   faults: FaultSpec | None = None, crack_correction=None) -> MeshStiffness:
    """k_h(theta), pair loads and loaded STE over one mesh period at the operating point
    (over one revolution of the faulty gear when ``faults`` has a fault: ``points`` per
    mesh period, ``periods`` mesh periods).

    The centre distance follows from the bearing clearance (and the static load if a
    finite bearing stiffness is given), paper Eq. 11; the contact path, contact ratio and
    wear pattern are those at that centre distance.

    ``correction``: optional ((radius_m, factor), (radius_m, factor)) per gear: the
    tooth compliance delta_1 + delta_2 at contact radius R is multiplied by the factor
    interpolated at R (the FE calibration; see gearwear.calibrate). Plain arrays, so
    this module never depends on the FE stage. ``crack_correction``: (radius_m, factor)
    of the cracked tooth (FE of the cracked tooth over the reduced-section model); absent,
    the cracked tooth takes its gear's ``correction``.
    """
    t0 = time.perf_counter()
    if method not in METHODS:
        raise fail("method", repr(method), "", f"must be one of {', '.join(METHODS)} (iso6336 is a constant)")
    if not isinstance(points, (int, np.integer)) or points < 8:
        raise fail("points", points, "", "must be a whole number >= 8")
    if not (torque_Nm > 0 and math.isfinite(torque_Nm)):
        raise fail("torque_Nm", torque_Nm, "N m", "must be in (0, 1e7] N m")
    og = operating_geometry(pair, clearance_m, torque_Nm if math.isfinite(bearing_stiffness_N_per_m) else 0.0,
                            bearing_stiffness_N_per_m)
    mesh = og.mesh
    nominal, loaded = _profiles(pair, wear, mesh.centre_distance_m)
    theta = np.arange(points) * (mesh.mesh_angle_rad / points)
    rb1, rb2 = pair.gear(0).base_radius_m, pair.gear(1).base_radius_m
    L = mesh.line_of_action_m
    A, E = mesh.path_start_m, mesh.path_end_m
    # candidate slots: from one pitch before entry to beyond the exit
    _, d = mesh.slots(theta)
    in_path = mesh.in_path(d)
    # extended (corner) contact is possible while the mating involute exists
    lo = max(rb1 * math.sqrt(max((nominal[0].form_radius_m / rb1) ** 2 - 1, 0)), 1e-9)
    hi = L - rb2 * math.sqrt(max((nominal[1].form_radius_m / rb2) ** 2 - 1, 0))
    entry = (d < A) & (d > lo) & corner_contact
    exit_ = (d > E) & (d < hi) & corner_contact
    cand = in_path | entry | exit_
    # compliances: inside the path at the contact radii; corners at the path ends. All
    # candidates of all angles in one pass per gear, each distinct position once. Taken
    # slot by slot (columns; slot j covers [d_A + j p_b, d_A + (j + 1) p_b)) the clipped
    # positions never decrease, so equal ones (the corner candidates at d_A and d_E)
    # are runs, and the slice heights come sorted, which the interpolation exploits
    cand_t = cand.T
    dc = np.clip(d, A, E).T[cand_t]
    first = np.empty(dc.shape, dtype=bool)
    first[:1] = True
    np.not_equal(dc[1:], dc[:-1], out=first[1:])
    d_u, at = dc[first], np.cumsum(first) - 1
    r1 = np.sqrt(rb1 ** 2 + d_u ** 2)
    r2 = np.sqrt(rb2 ** 2 + (L - d_u) ** 2)
    crack = faults.crack if faults is not None else None
    base_shape = d.shape

    def spread(values_u: np.ndarray) -> np.ndarray:
        """Per-candidate values (angles x slots of one period) from per-position ones; inf
        elsewhere."""
        out = np.full(base_shape, np.inf)
        out.T[cand_t] = values_u[at]
        return out

    def compliance(k: int, gear_r: np.ndarray, corr, fault=None) -> np.ndarray:
        cg = _tooth_compliance(method, loaded[k], nominal[k], gear_r, pair, n_slices,
                               None if fault is None else fault.crack)
        if corr is not None:
            grid, factor = (np.asarray(a, dtype=float) for a in corr)
            cg = cg * np.interp(gear_r, grid, factor)
        return cg

    corrections = correction or (None, None)
    c_g = [compliance(k, gear_r, corrections[k]) for k, gear_r in enumerate((r1, r2))]
    c_u = c_g[0] + c_g[1]
    c_hertz = 0.0
    if method == "ishikawa":
        a, expo = ishikawa.hertz_coefficient(pair.materials, pair.face_width_m), 0.9
    else:
        from . import energy
        c_hertz = energy.hertz_compliance_linear(pair.materials, pair.face_width_m)
        a, expo = 0.0, 1.0
    c = spread(c_u + c_hertz)
    # gaps: wear and flank modifications inside the path (at the path end for the
    # corners: their depths are those of the tip and of the SAP), plus the corner separation
    gap_u = np.zeros(d_u.shape)
    if wear is not None and not wear.is_unworn:
        h1, h2 = wear_on_line_of_action(mesh, wear, d_u)
        gap_u = gap_u + h1 + h2
    if flank is not None and not flank.is_nominal:
        m1, m2 = modification_on_line_of_action(flank, mesh, d_u)
        gap_u = gap_u + m1 + m2
    gap = spread(gap_u)
    if np.any(entry):
        gap[entry] += corner_gap_m(mesh, d[entry], "entry")
    if np.any(exit_):
        gap[exit_] += corner_gap_m(mesh, d[exit_], "exit")
    periods = revolution_periods(pair, faults)
    faulty = None
    if periods > 1:
        # one revolution of the faulty gear: the healthy period repeated, then the
        # faulty tooth's pair changed where it sits (geometry.faults numbering)
        j, _ = mesh.slots(theta[:1])
        theta = np.arange(points * periods) * (mesh.mesh_angle_rad / points)
        c, gap, d, in_path, cand = (np.tile(x, (periods, 1)) for x in (c, gap, d, in_path, cand))
        d_clip = np.clip(d, A, E)
        faulty = np.zeros(d.shape, dtype=bool)
        if crack is not None:
            hit = np.repeat(faulty_slots(pair, crack, periods, j), points, axis=0) & cand
            g = crack.gear_index
            corr_crack = crack_correction if crack_correction is not None else corrections[g]
            c_cracked = c_u - c_g[g] + compliance(g, (r1, r2)[g], corr_crack, crack)
            c[hit] = np.tile(spread(c_cracked + c_hertz), (periods, 1))[hit]
            faulty |= hit
        spall = faults.spall if faults is not None else None
        if spall is not None:
            hit = np.repeat(faulty_slots(pair, spall, periods, j), points, axis=0) & cand
            gap[hit] += spall_gap_m(spall, mesh, d_clip[hit])
            faulty |= hit
    total = torque_Nm / rb1
    F, delta = share_load(total, c, gap, a, expo)
    loaded_mask = F > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        k_pair = np.where(loaded_mask, F / np.maximum(delta[:, None] - gap, 1e-300), 0.0)
    k = k_pair.sum(axis=1)
    excitation = np.where(k > 0, (k_pair * np.where(loaded_mask, gap, 0.0)).sum(axis=1) / k, 0.0)
    wall = time.perf_counter() - t0
    return MeshStiffness(method, pair, mesh, torque_Nm, wear, theta, k, delta, excitation, F, d, in_path,
                         wall, n_slices, {"clearance_m": clearance_m, "corner_contact": corner_contact,
                                          "corrected": correction is not None},
                         flank, faults, periods, faulty)
