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

Table nodes. A pair starts carrying load where Delta - g_k changes sign: with gaps (wear,
flank modifications, a corner's separation) that angle moves with the clearance, the
wear and the load. On a fixed grid the curve would snap when such an edge crosses a
node (a staircase in every sweep), so the table holds the breakpoints as exact nodes
(:func:`_table_nodes`): the uniform grid of ``points`` per mesh period, the kinematic
path ends A and E (:func:`kinematic_breaks_rad`), every angle where a pair starts or
stops carrying load (a root of Delta_k - g_k between neighbouring grid nodes where the
loaded set changes, :func:`_edge_roots`) with graded nodes on its loaded side (the
secant stiffness rises there like x^0.11: GRADED_WIDTH), and one-sided limits where a
pair is loaded at A or E (no corner contact). Every node holds the curve evaluated there,
the table is periodic over its span, and the harmonics of the piecewise-linear curve vary
continuously with the parameters (tests/test_table_breakpoints.py; the default grid:
benchmarks/bench_table_points.py).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from gearwear.core.validation import fail, fail_text
from gearwear.geometry.curves import CurveStats
from gearwear.geometry.faults import FaultSpec, holds_fault, revolution_periods, spall_gap_m
from gearwear.geometry.flank import FlankSpec, modification_on_line_of_action
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import operating_geometry
from gearwear.geometry.profile import ToothProfile, tooth_profile
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec, flank_depth, key_roll_angles, wear_on_line_of_action

from . import TABLE_POINTS_PER_MESH_PERIOD, ishikawa

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
    breakpoints_rad angles (also nodes of angle_rad) where a pair starts or stops carrying
                    load or enters or leaves the path of contact (empty: a uniform table)

    The angles need not be uniform (the breakpoints are nodes): statistics over the
    curve are integrals of its piecewise-linear interpolant (geometry.curves).
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
    breakpoints_rad: np.ndarray = field(default_factory=lambda: np.empty(0))


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


def _tooth_compliance(
    method: str,
    loaded: ToothProfile,
    nominal: ToothProfile,
    radius_m: np.ndarray,
    pair: PairSpec,
    n_slices: int,
    crack=None,
    plane: str = "stress",
) -> np.ndarray:
    """delta_1 + delta_2 per unit load (m/N) of one tooth at contact radii (``crack``: a
    geometry.crack.Crack at the root of this tooth, or None)."""
    if radius_m.size == 0:
        return np.zeros(0)
    if method == "ishikawa":
        try:
            c = ishikawa.tooth_compliance(
                loaded,
                radius_m,
                loaded.gear.material,
                pair.face_width_m,
                n_slices,
                opposite=nominal,
                crack=crack,
                plane=plane,
            )
        except ValueError as exc:
            if not loaded.is_worn:
                raise  # a nominal tooth with a non-positive slice is our bug, not the user's input
            raise fail(
                "wear depth",
                float(loaded.depth.max()) * 1e6,
                "um",
                f"makes a slice of the {loaded.gear.name} tooth non-positive ({exc})",
            ) from None
        return c.total_m_per_N
    from . import energy

    ce = energy.tooth_compliance(
        loaded, radius_m, loaded.gear.material, pair.face_width_m, opposite=nominal, crack=crack, plane=plane
    )
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
        raise fail_text(
            None,
            "no tooth pair can come into contact at some angles (contact ratio far below one): "
            "the static transmission error is undefined there",
        )
    rows = np.nonzero(cand)[0]
    cc, gg = c[cand], gap[cand]
    # upper start: the smallest-gap pair alone carries everything; the total load is
    # convex and increasing in Delta, so Newton from above converges monotonically
    gfull = np.where(cand, gap, np.inf)
    k0 = np.argmin(gfull, axis=1)
    r = np.arange(n)
    delta = gfull[r, k0] + c[r, k0] * total_N + a * total_N**expo
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


# -- the contact state at any pinion angle --------------------------------------------


@dataclass(frozen=True)
class _Contact:
    """Everything the load sharing needs that does not depend on the pinion angle: the
    operating geometry, the profiles, the compliance models and corrections, the gap
    sources and the Hertz law. :func:`_state` evaluates it at any angles."""

    method: str
    pair: PairSpec
    mesh: MeshGeometry
    nominal: tuple
    loaded: tuple
    n_slices: int
    corrections: tuple
    crack_correction: object
    wear: WearSpec | None
    flank: FlankSpec | None
    faults: FaultSpec | None
    corner_contact: bool
    form_limits_m: tuple[float, float]  # LOA range where a corner can touch the mating involute
    hertz: tuple[float, float]  # (a, expo) of delta_H = a F^expo (0, 1: linear, in c)
    c_hertz_m_per_N: float  # linear Hertz compliance (energy method), else 0
    total_N: float  # T / r_b1 along the LOA
    periods: int
    plane: str = "stress"  # 2D state of the tooth beam terms (analytic.plane)


def _contact(
    pair: PairSpec,
    method: str,
    torque_Nm: float,
    clearance_m: float,
    wear: WearSpec | None,
    bearing_stiffness_N_per_m: float,
    n_slices: int,
    corner_contact: bool,
    correction,
    flank,
    faults,
    crack_correction,
    plane: str = "stress",
) -> _Contact:
    if method not in METHODS:
        raise fail("method", repr(method), "", f"must be one of {', '.join(METHODS)} (iso6336 is a constant)")
    if not (torque_Nm > 0 and math.isfinite(torque_Nm)):
        raise fail("torque_Nm", torque_Nm, "N m", "must be in (0, 1e7] N m")
    og = operating_geometry(
        pair, clearance_m, torque_Nm if math.isfinite(bearing_stiffness_N_per_m) else 0.0, bearing_stiffness_N_per_m
    )
    mesh = og.mesh
    nominal, loaded = _profiles(pair, wear, mesh.centre_distance_m)
    rb1, rb2 = pair.gear(0).base_radius_m, pair.gear(1).base_radius_m
    L = mesh.line_of_action_m
    # extended (corner) contact is possible while the mating involute exists
    lo = max(rb1 * math.sqrt(max((nominal[0].form_radius_m / rb1) ** 2 - 1, 0)), 1e-9)
    hi = L - rb2 * math.sqrt(max((nominal[1].form_radius_m / rb2) ** 2 - 1, 0))
    c_hertz = 0.0
    if method == "ishikawa":
        hertz = (ishikawa.hertz_coefficient(pair.materials, pair.face_width_m), 0.9)
    else:
        from . import energy

        c_hertz = energy.hertz_compliance_linear(pair.materials, pair.face_width_m)
        hertz = (0.0, 1.0)
    return _Contact(
        method,
        pair,
        mesh,
        nominal,
        loaded,
        n_slices,
        correction or (None, None),
        crack_correction,
        wear,
        flank,
        faults,
        corner_contact,
        (lo, hi),
        hertz,
        c_hertz,
        torque_Nm / rb1,
        revolution_periods(pair, faults),
        plane,
    )


def _compliance(s: _Contact, k: int, radius_m: np.ndarray, corr, crack=None) -> np.ndarray:
    """delta_1 + delta_2 per unit load (m/N) of gear k's tooth at contact radii, times the
    FE correction factor interpolated at the radius (``corr``: (radius_m, factor))."""
    cg = _tooth_compliance(s.method, s.loaded[k], s.nominal[k], radius_m, s.pair, s.n_slices, crack, s.plane)
    if corr is not None:
        grid, factor = (np.asarray(a, dtype=float) for a in corr)
        cg = cg * np.interp(radius_m, grid, factor)
    return cg


def _state(s: _Contact, theta_rad: np.ndarray, period: np.ndarray):
    """Candidate pairs at pinion angles ``theta_rad`` (rad, measured in mesh period
    ``period``; not wrapped, so slot j keeps its pair over the closed period [0, P]).

    Returns (c, gap, d, in_path, faulty), arrays (angles x slots): c the pair compliance
    (m/N, inf where the slot holds no candidate), gap the initial gap (m), d the LOA
    position (m), in_path inside [A, E], faulty the slot holds the faulty tooth (None
    without a fault). Compliances and gaps inside the path are taken at each distinct
    position once; the corners at the path ends (their depths are those of the tip and
    of the SAP), plus their separation from the mating flank (:func:`corner_gap_m`)."""
    mesh, pair = s.mesh, s.pair
    A, E = mesh.path_start_m, mesh.path_end_m
    rb1, rb2, L = pair.gear(0).base_radius_m, pair.gear(1).base_radius_m, mesh.line_of_action_m
    j, d = mesh.slots(theta_rad)
    in_path = mesh.in_path(d)
    lo, hi = s.form_limits_m
    entry = (d < A) & (d > lo) & s.corner_contact
    exit_ = (d > E) & (d < hi) & s.corner_contact
    cand = in_path | entry | exit_
    d_u, at = np.unique(np.clip(d[cand], A, E), return_inverse=True)
    radii = (np.sqrt(rb1**2 + d_u**2), np.sqrt(rb2**2 + (L - d_u) ** 2))
    c_g = [_compliance(s, k, radii[k], s.corrections[k]) for k in (0, 1)]
    c = np.full(d.shape, np.inf)
    c[cand] = (c_g[0] + c_g[1] + s.c_hertz_m_per_N)[at]
    gap_u = np.zeros(d_u.shape)
    if s.wear is not None and not s.wear.is_unworn:
        h1, h2 = wear_on_line_of_action(mesh, s.wear, d_u)
        gap_u = gap_u + h1 + h2
    if s.flank is not None and not s.flank.is_nominal:
        m1, m2 = modification_on_line_of_action(s.flank, mesh, d_u)
        gap_u = gap_u + m1 + m2
    gap = np.full(d.shape, np.inf)
    gap[cand] = gap_u[at]
    if np.any(entry):
        gap[entry] += corner_gap_m(mesh, d[entry], "entry")
    if np.any(exit_):
        gap[exit_] += corner_gap_m(mesh, d[exit_], "exit")
    faulty = None
    if s.faults is not None and s.periods > 1:
        # one revolution of the faulty gear: the faulty tooth's pair changed where it
        # sits (geometry.faults numbering: slot j of period n holds tooth (n - j) mod z)
        n = np.asarray(period)[:, None]
        faulty = np.zeros(d.shape, dtype=bool)
        crack = s.faults.crack
        if crack is not None:
            hit = holds_fault(pair, crack, n, j[None, :]) & cand
            g = crack.gear_index
            corr = s.crack_correction if s.crack_correction is not None else s.corrections[g]
            dh, ah = np.unique(np.clip(d[hit], A, E), return_inverse=True)
            rh = (np.sqrt(rb1**2 + dh**2), np.sqrt(rb2**2 + (L - dh) ** 2))
            healthy = [_compliance(s, k, rh[k], s.corrections[k]) for k in (0, 1)]
            healthy[g] = _compliance(s, g, rh[g], corr, crack.crack)
            c[hit] = (healthy[0] + healthy[1] + s.c_hertz_m_per_N)[ah]
            faulty |= hit
        spall = s.faults.spall
        if spall is not None:
            hit = holds_fault(pair, spall, n, j[None, :]) & cand
            gap[hit] += spall_gap_m(spall, mesh, np.clip(d[hit], A, E))
            faulty |= hit
    return c, gap, d, in_path, faulty


def _solve(s: _Contact, theta_rad: np.ndarray, period: np.ndarray, without: np.ndarray | None = None):
    """Load sharing at the angles: (F (angles x slots, N), Delta (angles, m), c, gap, d,
    in_path, faulty) (:func:`_state`, :func:`share_load`); ``without``: per angle a slot
    whose pair is left out of the load sharing (its gap is still returned)."""
    c, gap, d, in_path, faulty = _state(s, theta_rad, period)
    if without is not None:
        c = c.copy()
        c[np.arange(c.shape[0]), without] = np.inf
    F, delta = share_load(s.total_N, c, gap, *s.hertz)
    return F, delta, c, gap, d, in_path, faulty


# -- table nodes: the breakpoints of the physics --------------------------------------

#: where a pair starts to carry load its secant stiffness rises from 0 to most of its
#: value over a vanishing load (energy: a jump to 1 / c; Ishikawa: F / (c F + a F^0.9),
#: which behaves like x^0.11 in the distance x from the breakpoint, so that its
#: piecewise-linear interpolant on a uniform grid converges only like h^1.1). Nodes at
#: x_i = W (i / N)^GRADED_POWER, i = 1 .. N = ceil(W / h), W = GRADED_WIDTH of a mesh
#: period, on the loaded side restore second order for x^p with p > 2 / GRADED_POWER - 1
#: (the standard graded mesh; cells grow from ~W (h / W)^3 to ~3 h)
GRADED_WIDTH, GRADED_POWER = 1.0 / 16, 3.0
#: a jump at a kinematic node (a pair loaded at A or E without corner contact) gets a
#: second node this far (fraction of a mesh period) on its other side: the one-sided limit
JUMP_OFFSET = 1e-9
#: a breakpoint is bracketed to this fraction of a mesh period
ROOT_TOL = 1e-14
#: nodes closer than this fraction of a mesh period are one node (the dynamics steps
#: over nodes within 1e-12 of a period of each other)
MERGE_TOL = 1e-11


def kinematic_breaks_rad(mesh: MeshGeometry) -> np.ndarray:
    """Pinion angles (rad) in [0, 2 pi / z1) where a pair enters or leaves the path of
    contact: at theta = 0 the entering pair is at A (slot 0, MeshGeometry.slots), at
    theta_E one leaves at E (MeshGeometry.exit_angle_rad; the images of A and E one base
    pitch away are the same angles one mesh period later)."""
    th_E = mesh.exit_angle_rad
    P = mesh.mesh_angle_rad
    if MERGE_TOL * P < th_E < P * (1 - MERGE_TOL):
        return np.array([0.0, th_E])
    return np.array([0.0])


def graded_offsets_rad(P: float, h: float) -> np.ndarray:
    """Distances (rad) of the graded nodes from a breakpoint (see GRADED_WIDTH): mesh
    period P, grid step h."""
    W = GRADED_WIDTH * P
    N = max(int(math.ceil(W / h)), 1)
    return W * (np.arange(1, N + 1) / N) ** GRADED_POWER


def _edge_roots(
    s: _Contact, a: np.ndarray, b: np.ndarray, period: np.ndarray, col: np.ndarray, tol: float
) -> np.ndarray:
    """Angles where the pair in slot ``col`` of mesh period ``period`` starts or stops
    carrying load, one per row, bracketed by a and b (loaded at one end only).

    The pair carries load exactly where Delta_k(theta) > g_k(theta), Delta_k the approach
    of the other pairs without it (with it unloaded the load sharing is theirs; the
    complementarity solution is unique), so the breakpoint is the root of the smooth
    f = Delta_k - g_k (the full Delta has a kink there). Illinois false position on every
    bracket at once (one load sharing per iteration for all of them), bisection if it has
    not converged in 40 steps. Returns the end of the final bracket (width <= tol) on the
    unloaded side: the table's node there holds the one-sided value without that pair."""
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)

    def f(x: np.ndarray, i: np.ndarray) -> np.ndarray:
        _, delta, _, gap, *_ = _solve(s, x, period[i], without=col[i])
        return delta - gap[np.arange(i.size), col[i]]

    rows = np.arange(a.size)
    fa, fb = f(a, rows), f(b, rows)
    kept_b = np.zeros(a.size, dtype=bool)  # the last step replaced a, keeping b
    for it in range(200):
        act = np.abs(b - a) > tol
        if not act.any():
            break
        i = rows[act]
        x = 0.5 * (a[i] + b[i])
        if it < 40:
            secant = (a[i] * fb[i] - b[i] * fa[i]) / np.where(fb[i] != fa[i], fb[i] - fa[i], 1.0)
            inside = (secant > np.minimum(a[i], b[i])) & (secant < np.maximum(a[i], b[i]))
            x = np.where(inside, secant, x)
        fx = f(x, i)
        same = (fx > 0) == (fa[i] > 0)
        # Illinois: an end kept twice in a row has its value halved, so it cannot stall
        ia, ib = i[same], i[~same]
        fb[ia[kept_b[ia]]] *= 0.5
        fa[ib[~kept_b[ib]]] *= 0.5
        a[ia], fa[ia] = x[same], fx[same]
        b[ib], fb[ib] = x[~same], fx[~same]
        kept_b[ia], kept_b[ib] = True, False
    return np.where(fa > 0, b, a)


def _table_nodes(s: _Contact, points: int) -> tuple[np.ndarray, ...]:
    """Table nodes with the breakpoints of the physics: (angle over the ``periods`` mesh
    periods, ascending in [0, span); the same as an angle in its mesh period and that
    period, the pair (local, period) at which the node is evaluated; the breakpoints).

    The uniform grid of ``points`` per mesh period, plus per period: the kinematic
    breaks (a pair at A or E, :func:`kinematic_breaks_rad`); the angles where a pair
    starts or stops carrying load (Delta = g_k, :func:`_edge_roots`, searched between
    neighbouring nodes where a pair's loaded state changes while it stays a candidate),
    each with a graded cluster on its loaded side; and at a kinematic break where the
    loaded set jumps, the one-sided limit JUMP_OFFSET away."""
    P = s.mesh.mesh_angle_rad
    h = P / points
    kin = kinematic_breaks_rad(s.mesh)
    local = np.union1d(np.arange(points) * h, np.r_[kin, P])  # closed period [0, P]
    n_loc = local.size
    per = np.repeat(np.arange(s.periods), n_loc)
    th = np.tile(local, s.periods)
    F, _, c, *_ = _solve(s, th, per)
    cand = np.isfinite(c)
    on = F > 0
    # neighbours inside one period where a slot's pair changes its loaded state
    i, k = np.nonzero((on[:-1] != on[1:]) & cand[:-1] & cand[1:])
    keep = (i + 1) % n_loc != 0
    i, k = i[keep], k[keep]
    roots = _edge_roots(s, th[i], th[i + 1], per[i], k, ROOT_TOL * P) if i.size else th[:0]
    side = np.where(on[i + 1, k], 1.0, -1.0)  # towards the loaded side
    offsets = graded_offsets_rad(P, h)
    graded = (roots[:, None] + side[:, None] * offsets).ravel()
    # one-sided limits at a kinematic break where the loaded set jumps
    eps = JUMP_OFFSET * P
    kin_th, kin_per = np.tile(kin, s.periods), np.repeat(np.arange(s.periods), kin.size)
    jumps = []
    F0 = _solve(s, kin_th, kin_per)[0]
    for sign in (-1.0, 1.0):
        Fs = _solve(s, kin_th + sign * eps, kin_per)[0]
        jump = np.any((Fs > 0) != (F0 > 0), axis=1)
        jumps.append((kin_th[jump] + sign * eps, kin_per[jump]))
    uni = (np.tile(np.arange(points) * h, s.periods), np.repeat(np.arange(s.periods), points))
    breaks = (np.r_[roots, kin_th], np.r_[per[i], kin_per])
    # priority: breakpoints, one-sided limits, graded clusters, the uniform grid
    groups = [
        breaks,
        (np.concatenate([x for x, _ in jumps]), np.concatenate([n for _, n in jumps])),
        (graded, np.repeat(per[i], offsets.size)),
        uni,
    ]
    local = np.concatenate([g[0] for g in groups])
    period = np.concatenate([g[1] for g in groups])
    prio = np.concatenate([np.full(g[0].size, q) for q, g in enumerate(groups)])
    span = s.periods * P
    ang = np.mod(local + period * P, span)
    keep = merge_nodes(ang, prio, span, MERGE_TOL * P)
    return ang[keep], local[keep], period[keep], np.sort(np.mod(breaks[0] + breaks[1] * P, span))


def merge_nodes(angle: np.ndarray, priority: np.ndarray, span: float, tol: float) -> np.ndarray:
    """Indices of the nodes to keep, in ascending angle: of nodes closer than ``tol`` to
    each other (also across the wrap from ``span`` to 0) only one of the lowest priority
    number is kept."""
    order = np.argsort(angle, kind="stable")
    ang, prio = angle[order], priority[order]
    cluster = np.r_[0, np.cumsum(np.diff(ang) > tol)]
    if ang.size > 1 and ang[0] + span - ang[-1] <= tol:
        cluster[cluster == cluster[-1]] = 0  # the last nodes are the first ones, one span on
    best = np.lexsort((prio, cluster))  # by cluster, then priority
    first = np.r_[True, np.diff(cluster[best]) > 0]
    return order[np.sort(best[first])]


# -- the curve -----------------------------------------------------------------------

#: uniform table nodes per mesh period (the breakpoints come on top); the convergence
#: study benchmarks/bench_table_points.py sets it
DEFAULT_POINTS = TABLE_POINTS_PER_MESH_PERIOD


def mesh_stiffness(
    pair: PairSpec,
    method: str = "ishikawa",
    points: int = DEFAULT_POINTS,
    torque_Nm: float = 40.0,
    clearance_m: float = 0.0,
    wear: WearSpec | None = None,
    bearing_stiffness_N_per_m: float = math.inf,
    n_slices: int = ishikawa.DEFAULT_SLICES,
    corner_contact: bool = True,
    correction=None,
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
    crack_correction=None,
    breakpoints: bool = True,
    angles_rad=None,
    plane: str = "stress",
) -> MeshStiffness:
    """k_h(theta), pair loads and loaded STE over one mesh period at the operating point
    (over one revolution of the faulty gear when ``faults`` has a fault: ``periods`` mesh
    periods).

    Table nodes: ``points`` uniform angles per mesh period, and with ``breakpoints`` (the
    default) the breakpoints of the physics on top (:func:`_table_nodes`): where a pair
    enters or leaves the path (A, E) and where a pair starts or stops carrying load
    (Delta = g_k: wear, flank modifications, corner contact and the bearing-clearance
    geometry move it), each resolved by nodes on its loaded side. The table is then
    non-uniform; every node holds the curve evaluated there (a breakpoint node the
    one-sided value without the pair), and the piecewise-linear curve between nodes is
    what the dynamics interpolate. ``breakpoints = False``: the uniform grid only (the
    convergence study's comparison). ``angles_rad``: evaluate at exactly these pinion
    angles instead of a table (the curve's angles are then these).

    The centre distance follows from the bearing clearance (and the static load if a
    finite bearing stiffness is given), paper Eq. 11; the contact path, contact ratio and
    wear pattern are those at that centre distance.

    ``correction``: optional ((radius_m, factor), (radius_m, factor)) per gear: the
    tooth compliance delta_1 + delta_2 at contact radius R is multiplied by the factor
    interpolated at R (the FE calibration; see gearwear.stiffness.calibration). Plain arrays, so
    this module never depends on the FE stage. ``crack_correction``: (radius_m, factor)
    of the cracked tooth (FE of the cracked tooth over the reduced-section model); absent,
    the cracked tooth takes its gear's ``correction``. ``plane``: the 2D state of the tooth
    beam terms, "stress" (the published models) or "strain" (``analytic.plane``); the app
    passes the scene's fem.plane resolved as for the FE.
    """
    t0 = time.perf_counter()
    if not isinstance(points, (int, np.integer)) or points < 8:
        raise fail("points", points, "", "must be a whole number >= 8")
    s = _contact(
        pair,
        method,
        torque_Nm,
        clearance_m,
        wear,
        bearing_stiffness_N_per_m,
        n_slices,
        corner_contact,
        correction,
        flank,
        faults,
        crack_correction,
        plane,
    )
    P = s.mesh.mesh_angle_rad
    breaks = np.empty(0)
    if angles_rad is not None:
        theta = np.asarray(angles_rad, dtype=float).ravel()
        # each angle in its mesh period (a node a rounding error below a period's start is
        # taken at a tiny negative angle of that period: the slots are not wrapped)
        whole = np.floor(theta / P + 1e-12)
        local, period = theta - whole * P, np.mod(whole, s.periods).astype(np.int64)
    elif breakpoints:
        theta, local, period, breaks = _table_nodes(s, int(points))
    else:
        local = np.tile(np.arange(points) * (P / points), s.periods)
        period = np.repeat(np.arange(s.periods), points)
        theta = np.arange(points * s.periods) * (P / points)
    F, delta, c, gap, d, in_path, faulty = _solve(s, local, period)
    loaded_mask = F > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        k_pair = np.where(loaded_mask, F / np.maximum(delta[:, None] - gap, 1e-300), 0.0)
    k = k_pair.sum(axis=1)
    excitation = np.where(k > 0, (k_pair * np.where(loaded_mask, gap, 0.0)).sum(axis=1) / k, 0.0)
    wall = time.perf_counter() - t0
    return MeshStiffness(
        method,
        pair,
        s.mesh,
        torque_Nm,
        wear,
        theta,
        k,
        delta,
        excitation,
        F,
        d,
        in_path,
        wall,
        n_slices,
        {
            "clearance_m": clearance_m,
            "corner_contact": corner_contact,
            "corrected": correction is not None,
            "points_per_mesh_period": int(points),
            "breakpoints": bool(breakpoints),
            "plane": plane,
        },
        flank,
        faults,
        s.periods,
        faulty,
        breaks,
    )
