"""Spur-pair mesh stiffness by resolved FE contact of the two gear bodies: loaded
static transmission error and mesh stiffness over one mesh period, any pair
(unequal teeth, profile shift, wear, clearance-shifted centre distance).

Model (SI units: m, N, rad, Pa)
-------------------------------
Each distinct gear is one full FE body (fem.pair_body: all z teeth, P2 triangles,
plane stress by default, thickness = face width b, bore fixed) whose tooth 0 has
its drive flank refined to the contact element size h_c = a_ref / 2.5 (a_ref: Hertz
half-width of one pair at the pitch point under the full load, 64 um for the paper
pair at 40 N m) over the whole candidate range, from below the start of active
profile up to and including the tip corner. The flexibility G of those flank nodes
(and of the neighbouring teeth's drive flanks) comes from one sparse factorization
per body by static condensation; rotational periodicity maps every engaged tooth to
tooth 0 (a load on tooth t_l read on tooth t_k = a load on tooth 0 read on tooth
t_k - t_l). No analytic local (Hertz/Weber) term enters: the contact zone is
resolved by the mesh.

Kinematics. Fixed frame: pinion centre O1 = 0, its base-circle tangency point
T1 = (0, r_b1), line of action (LOA) along +x to T2 = (L, r_b1), gear centre
O2 = (L, r_b1 + r_b2). A tooth pair at LOA position d (the slots of
geometry.kinematics.MeshGeometry.slots, shared with analytic.tvms) is placed
rigidly so that both nominal flanks pass through (d, r_b1): pinion tooth frame
turned by gamma_1 = psi_b1 - d / r_b1, gear tooth frame by
gamma_2 = psi_b2 - (L - d) / r_b2 - pi (psi_b: half angular thickness on the base
circle; the involute is beta = psi_b - (u - atan u)). Pinion slot j sits on tooth
-j, gear slot j on tooth +j (slot j entered j mesh periods earlier); pairs one
base pitch apart are then exactly one tooth apart. The driven gear is held; the
pinion turns by the extra angle dtheta, and the loaded STE is delta = r_b1 dtheta.

Gaps from the exact profiles (node-to-surface). For each tooth pair the "slave" is
the gear whose tip is nearer the contact (the pinion for d past mid-path, else the
gear): its flank nodes within +-3 a_ref of arc length of the kinematic contact
point (the tip corner when d lies beyond the path) are the candidates; the
"master" is the mating flank as an exact involute. Involutes of one base circle
are parallel curves, so a point Y (master tooth frame, radius r, half-angle beta,
u = sqrt(r^2 / r_b^2 - 1)) is at the normal distance

    g = r_b (beta + u - atan u - psi_b)          (> 0 outside the master tooth)

from the master flank; the foot of the normal has roll u_F = u - g / r_b and
outward normal (cos beta_T, -sin beta_T), beta_T = psi_b - u_F. The slave point is
the exact flank point at the node's radius (the corner itself for the corner
node), so corner (extended) contact outside the kinematic path is included: a
slave's tip corner meets the master flank below its start of active profile.

Wear enters as initial gaps: g += h_slave(R_node) + h_master(R_foot), with h the
wear depth of geometry.wear.flank_depth along the nominal normal plus the profile
modifications and measured deviations of geometry.flank; the FE bodies
keep the nominal flanks. Why: the depths (<= 30 um) are 1e-3 of the tooth
thickness, so they change the body compliance by 0.01-0.1 % (fem.tooth, morph
study) while they change the gaps at first order (tens of um against a 1-2 um
elastic approach); a nominal body lets one factorization serve every wear state
and keeps mesh changes out of the wear effect. The gap g(s) keeps the worn
profile's shape along the flank (including its changed curvature), which is what
the contact zone sees.

Contact problem per position (frictionless; fem.contact's exact active-set
solver). Candidate i (force f_i >= 0 along the master normal e_i, +e_i on the slave
node, -e_i on the master at the foot point, with P2 edge weights):

    gap_i = g_i + (C f)_i - w_i delta >= 0,  f_i >= 0,  f_i gap_i = 0,
    sum_i w_i f_i = T / r_b1,                 C = sum over both bodies a_i^T G a_j

with w_i = -(d g_i / d dtheta) / r_b1 (the lever arm of e_i about O1 over r_b1;
1 on the LOA) from the exact gap function. With q = w f the problem is
fem.contact's form (C' = W^-1 C W^-1, g' = g / w, sum q = T / r_b1), so the loads
sum to T / r_b1 exactly and delta is the multiplier.

Mesh stiffness, as analytic.tvms: k = sum over loaded pairs of F_k / (delta - g_k)
with F_k = sum of q_i of the pair and g_k its rigid gap (the smallest g'_i over a
dense sampling of its slave flank: wear gap, corner clearance); F = k (delta - e)
with e = sum k_k g_k / k. The tangent dF / d delta is a central difference of the
whole solve at F (1 +- 1e-3).

Measured (benchmarks/bench_fem_pair.py, 2 cores, 40 N m, plane stress, P2)
----------------------------------------------------------------------------
Paper pair, 24 positions, h_c = 25.6 um: 96k dofs, 2172 condensed dofs, 38-77
candidates per position; cold cycle 8-10 s (mesh 1.4, assemble 1.9, ordering 0.9,
factorize 2.9, flexibility 1.8, 24 positions 0.26 + LCPs 0.10, extended-contact
bisection 0.3 s). Mean 3.3838e8 N/m; single-pair plateau 2.4686e8, double-pair
plateau 3.7784e8 N/m; loaded corner contact 0.298 deg before A and 0.296 deg after
E. Contact-zone refinement h_c = a/1.25 .. a/5: mean 3.38755, 3.38530, 3.38378,
3.38359, 3.38351 e8 (one more refinement of the default: -0.006 %; Richardson
estimate 3.38347e8). Single contact: c_1, c_2 equal the single-tooth FE to 0.1-0.15 %,
k_pair = 1 / (c_1 + c_2 + c_local) to 0.09 %, c_local = 1.50e-9 m/N is 4.5 % above
Weber in plane stress and 15 % above Weber in plane strain.
Shifted 21/37 pair (x = +0.25/-0.10): two bodies, cold cycle 14 s, mean 3.2486e8,
plateaus 2.4752e8 / 3.7265e8 N/m, corner contact 0.461 / 0.463 deg.
"""

from __future__ import annotations

import math
import time
from collections import OrderedDict
from dataclasses import dataclass, field, replace

import numpy as np

from gearwear.geometry.loading import load_points
from gearwear.geometry.curves import CurveStats
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import operating_geometry
from gearwear.geometry.profile import INVOLUTE, tooth_profile
from gearwear.geometry.sampling import FINE_SAG_M
from gearwear.geometry.spec import PairSpec
from gearwear.core.validation import fail
from gearwear.geometry.flank import FlankSpec, is_nominal, modification_depth_m
from gearwear.geometry.wear import WearSpec, flank_depth, hertz_half_width, key_roll_angles

from .contact import solve_contact
from .pair_body import BodySizes, GearBody, build_body, involute_point, rot

__all__ = ["PairFE", "PairModel", "pair_contact", "pair_model", "solve_position", "weber_approach_m",
           "body_sizes", "extended_contact_widths", "consistency", "write_fields"]

ELEMENTS_PER_HALF_WIDTH = 2.5   # h_c = a_ref / 2.5 at contact_scale 1
WINDOW_HALF_WIDTHS = 3.0        # candidate window: +-3 a_ref of arc length (+ 2 h_c)
EXTENSION_PITCHES = 0.08        # pairs considered up to 0.08 p_b beyond A and E (corner contact)
DENSE_GAP_POINTS = 401          # samples of a pair's slave flank for its rigid gap g_k
ROTATION_STEP_RAD = 1e-7        # central difference of the gaps for the lever arms w_i
_BODY_CACHE: "OrderedDict[tuple, GearBody]" = OrderedDict()
_BODY_CACHE_SIZE = 4


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
    excitation_m       (n,) e with F = k (STE - e)
    pair_load_N        (n, p) load of each slot (torque-equivalent: sums to T / r_b1)
    pair_d_m           (n, p) LOA position of each slot
    pair_in_path       (n, p) slot inside the path of contact [A, E]
    half_width_m       (n, p) half the loaded arc length of each pair (resolved Hertz a)
    timings            wall times (s) of the stages
    meta               sizes, element counts, options, extended-contact widths
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
    half_width_m: np.ndarray
    timings: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)


# ---------------------------------------------------------------------------
# Weber's local approach (the analytic model being verified, not used in the solve)
# ---------------------------------------------------------------------------


def _plane_constants(E: float, nu: float, plane: str) -> tuple[float, float]:
    """(E', nu') that turn the plane-strain formulas into the requested state."""
    if plane == "strain":
        return E, nu
    if plane == "stress":
        return E * (1 + 2 * nu) / (1 + nu) ** 2, nu / (1 + nu)
    raise fail("plane", repr(plane), "", "must be 'stress' or 'strain'")


def weber_approach_m(F_N, h1_m, h2_m, R_star_m, E_Pa: float, nu: float, b_m: float,
                     plane: str = "strain") -> np.ndarray:
    """Weber (1949) approach of the two centre-line points of a line contact (m):
    2 F (1 - nu^2)/(pi E b) [ln(2 h1/a) + ln(2 h2/a) - nu/(1 - nu)] with the Hertz
    half-width a = sqrt(4 (F/b) R* / (pi E*)), 1/E* = 2 (1 - nu^2)/E (plane strain;
    ``plane="stress"`` converts E, nu). h1, h2: contact point to the centre-line
    points along the load line. Zero for F <= 0."""
    Ep, nup = _plane_constants(E_Pa, nu, plane)
    F = np.maximum(np.asarray(F_N, dtype=float), 0.0)
    E_star = Ep / (2.0 * (1.0 - nup ** 2))
    Fs = np.where(F > 0, F, 1.0)
    a = np.sqrt(4.0 * (Fs / b_m) * np.asarray(R_star_m) / (math.pi * E_star))
    br = np.log(2.0 * np.asarray(h1_m) / a) + np.log(2.0 * np.asarray(h2_m) / a) - nup / (1.0 - nup)
    return np.where(F > 0, 2.0 * F * (1.0 - nup ** 2) / (math.pi * Ep * b_m) * br, 0.0)


# ---------------------------------------------------------------------------
# the pair model: bodies + exact geometry
# ---------------------------------------------------------------------------


def _positive(key: str, value, unit: str = "") -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise fail(key, repr(value), unit, "must be a finite number > 0") from None
    if not (math.isfinite(v) and v > 0):
        raise fail(key, value, unit, "must be a finite number > 0")
    return v


def body_sizes(pair: PairSpec, torque_Nm: float = 40.0, contact_scale: float = 1.0,
               mesh_scale: float = 1.0) -> tuple[BodySizes, float]:
    """Element sizes of the pair bodies and a_ref (m). h_c = a_ref / 2.5 x
    contact_scale, a_ref the Hertz half-width (plane strain) of one pair at the pitch
    point under T / r_b1 on the nominal geometry; the rest scales with the module
    (near teeth 0.125 m, far teeth 0.3 m, fillets 0.05 m, interior 0.4 m) x mesh_scale."""
    cs = _positive("contact_scale", contact_scale)
    ms = _positive("mesh_scale", mesh_scale)
    mg = MeshGeometry(pair, pair.centre_distance_m)
    F = torque_Nm / pair.gear(0).base_radius_m
    a_ref = float(hertz_half_width(mg, np.array([mg.pitch_point_m]), F / pair.face_width_m)[0])
    m = pair.module_m
    return BodySizes(contact_m=a_ref / ELEMENTS_PER_HALF_WIDTH * cs, near_m=0.125 * m * ms, far_m=0.3 * m * ms,
                     fillet_m=0.05 * m * ms, global_m=0.4 * m * ms), a_ref


@dataclass
class PairModel:
    """Everything a position solve needs (built once per pair, torque and clearance)."""

    pair: PairSpec
    mesh: MeshGeometry
    bodies: tuple
    wear: WearSpec | None
    depth: tuple          # per gear: (radius, depth) arrays of the drive flank, or None
    window_m: float       # candidate half-window (arc length)
    a_ref_m: float
    sizes: BodySizes
    plane: str
    timings: dict

    @property
    def psi_b(self) -> tuple[float, float]:
        g1, g2 = (g.pitch_thickness_m / (2 * g.pitch_radius_m) + math.tan(g.pressure_angle_rad)
                  - g.pressure_angle_rad for g in self.pair.gears)
        return (g1, g2)


def _candidate_radius_range(mesh: MeshGeometry, gi: int, window_m: float) -> float:
    """Lowest flank radius a contact can reach on gear gi: its start of active profile
    moved EXTENSION_PITCHES p_b along the LOA plus the candidate window (arc length)."""
    g = mesh.pair.gear(gi)
    rb = g.base_radius_m
    ext = EXTENSION_PITCHES * mesh.base_pitch_m
    d = mesh.path_start_m - ext if gi == 0 else mesh.line_of_action_m - (mesh.path_end_m + ext)
    s = rb * (max(d, 0.0) / rb) ** 2 / 2.0 - window_m
    u = math.sqrt(max(2.0 * s / rb, 0.0))
    return max(rb * math.sqrt(1.0 + u * u), rb * 1.0001)


def _body_key(g, pair, sizes, r_lo, nb, cy, plane):
    return (replace(g, name=""), pair.material, pair.face_width_m, sizes, round(r_lo, 9), nb,
            tuple(round(c, 9) for c in cy), plane)


def pair_model(pair: PairSpec, wear: WearSpec | None = None, torque_Nm: float = 40.0, clearance_m: float = 0.0,
               contact_scale: float = 1.0, mesh_scale: float = 1.0, plane: str = "stress",
               flank: FlankSpec | None = None) -> PairModel:
    """Bodies (cached in-process: wear states share them) and exact geometry. ``flank``:
    profile modifications and measured deviations (geometry.flank), gaps like the wear."""
    t0 = time.perf_counter()
    _positive("torque_Nm", torque_Nm, "N m")
    if not (math.isfinite(clearance_m) and clearance_m >= 0):
        raise fail("clearance_m", clearance_m, "m", "must be finite and >= 0")
    if plane not in ("stress", "strain"):
        raise fail("plane", repr(plane), "", "must be 'stress' or 'strain'")
    og = operating_geometry(pair, clearance_m)
    mesh = og.mesh
    mesh.require_overlap("fem")  # the contact solve needs a pair that can touch at every angle
    sizes, a_ref = body_sizes(pair, torque_Nm, contact_scale, mesh_scale)
    window = WINDOW_HALF_WIDTHS * a_ref + 2.0 * sizes.contact_m
    nb = int(math.ceil(mesh.contact_ratio + 2 * EXTENSION_PITCHES)) + 1
    bodies: list[GearBody] = []
    depth: list[tuple[np.ndarray, np.ndarray] | None] = []
    tim: dict[str, float] = {}
    for gi, g in enumerate(pair.gears):
        # the body outline is interpolated on this polyline: 1 nm sag keeps it on the curve
        nominal = tooth_profile(g, sag_m=FINE_SAG_M, extra_roll=key_roll_angles(mesh, gi))
        r_lo = _candidate_radius_range(mesh, gi, window)
        lp = load_points(nominal, np.array([max(r_lo, nominal.form_radius_m), g.tip_radius_m * (1 - 1e-9)]))
        cy = (float(lp.y_axis_m.min()) - 1.0 * pair.module_m * 0.2, float(lp.y_axis_m.max()) + 0.2 * pair.module_m)
        key = _body_key(g, pair, sizes, r_lo, nb, cy, plane)
        if key in _BODY_CACHE:  # identical gears, or another wear state of the same pair
            body = _BODY_CACHE[key]
            _BODY_CACHE.move_to_end(key)
        else:
            body = build_body(g, pair.material, pair.face_width_m, nominal, sizes, r_lo, nb, cy, plane)
            _BODY_CACHE[key] = body
            while len(_BODY_CACHE) > _BODY_CACHE_SIZE:
                _BODY_CACHE.popitem(last=False)
            for k2, v in body.timings.items():
                tim[f"gear{gi}_{k2}"] = v
        bodies.append(body)
        worn = wear is not None and not wear.is_unworn
        if worn or not is_nominal(flank):
            inv = nominal.region == INVOLUTE
            h = flank_depth(nominal, gi, mesh, wear)[inv] if worn and wear is not None else 0.0
            h = h + modification_depth_m(flank, pair, gi, nominal.radius[inv])
            depth.append((nominal.radius[inv], h))
        else:
            depth.append(None)
    tim["model_s"] = time.perf_counter() - t0
    return PairModel(pair, mesh, tuple(bodies), wear, tuple(depth), window, a_ref, sizes, plane, tim)


# ---------------------------------------------------------------------------
# one position
# ---------------------------------------------------------------------------


def _frames(pm: PairModel, d: float, dtheta: float = 0.0):
    """(gamma_1, gamma_2, O2): rotations of the pinion and gear tooth frames of the pair
    at LOA position d (pinion turned by the extra angle dtheta) and the gear centre."""
    rb1, rb2 = (g.base_radius_m for g in pm.pair.gears)
    L = pm.mesh.line_of_action_m
    p1, p2 = pm.psi_b
    return p1 - d / rb1 - dtheta, p2 - (L - d) / rb2 - math.pi, np.array([L, rb1 + rb2])


def _depth(pm: PairModel, gi: int, R: np.ndarray) -> np.ndarray:
    dd = pm.depth[gi]
    if dd is None:
        return np.zeros_like(R)
    return np.interp(R, dd[0], dd[1], left=0.0, right=0.0)


def _gap(pm: PairModel, slave: int, R: np.ndarray, d: float, dtheta: float = 0.0):
    """Initial normal gap of the exact slave flank points at radii R against the exact
    master involute (+ wear of both flanks): (gap, foot radius, master outward normal in
    the master tooth frame, the same in the fixed frame)."""
    g1, g2, O2 = _frames(pm, d, dtheta)
    master = 1 - slave
    gs, gm = pm.pair.gear(slave), pm.pair.gear(master)
    X = involute_point(gs, R)
    if slave == 0:
        Y = (X @ rot(g1).T - O2) @ rot(-g2).T
        gam_m = g2
    else:
        Y = (X @ rot(g2).T + O2) @ rot(-g1).T
        gam_m = g1
    rbm = gm.base_radius_m
    r = np.hypot(Y[:, 0], Y[:, 1])
    u = np.sqrt(np.maximum((r / rbm) ** 2 - 1.0, 0.0))
    kappa = np.arctan2(Y[:, 0], Y[:, 1]) + u - np.arctan(u)
    gap = rbm * (kappa - pm.psi_b[master])
    uF = u - gap / rbm
    rF = rbm * np.sqrt(1.0 + uF * uF)
    bT = pm.psi_b[master] - uF
    n_loc = np.column_stack([np.cos(bT), -np.sin(bT)])
    gap = gap + _depth(pm, slave, R) + _depth(pm, master, rF)
    # a foot past the master's tip or below its condensed flank: that slave point faces
    # the master's corner or fillet, not its flank; it cannot be loaded here
    out = (rF > gm.tip_radius_m) | (rF < pm.bodies[master].flank_r[0][0]) | (r <= rbm)
    gap = np.where(out, np.inf, gap)
    return gap, rF, n_loc, n_loc @ rot(gam_m).T


@dataclass
class PositionSolution:
    """Resolved contact at one pinion angle (SI).

    d_m, teeth (slots in contact candidates), loads_N per slot (torque-equivalent),
    ste_m, gaps_m per slot (rigid gap g_k), cand (per slot: dict with slave, node
    radii, foot radii, forces, reps), half_width_m per slot."""

    theta_rad: float
    d_m: np.ndarray
    slots: np.ndarray
    loads_N: np.ndarray
    ste_m: float
    gaps_m: np.ndarray
    half_width_m: np.ndarray
    cand: list
    C: np.ndarray
    g: np.ndarray
    w: np.ndarray


def _candidates(pm: PairModel, d: float, j: int) -> dict | None:
    """Candidate nodes, gaps, lever arms and load/read representations of the pair in
    slot j at LOA position d, or None when no node can reach the mating flank."""
    mid = 0.5 * (pm.mesh.path_start_m + pm.mesh.path_end_m)
    slave = 0 if d >= mid else 1
    gs = pm.pair.gear(slave)
    rb = gs.base_radius_m
    L = pm.mesh.line_of_action_m
    u_kin = d / rb if slave == 0 else (L - d) / rb
    u_a = math.sqrt((gs.tip_radius_m / rb) ** 2 - 1.0)
    s_c = rb * min(max(u_kin, 0.0), u_a) ** 2 / 2.0
    body = pm.bodies[slave]
    r_nodes = body.flank_r[0]
    s_nodes = rb * ((r_nodes / rb) ** 2 - 1.0) / 2.0
    sel = np.flatnonzero(np.abs(s_nodes - s_c) <= pm.window_m)
    if sel.size == 0:
        return None
    R = r_nodes[sel]
    gap, rF, n_loc, e_fix = _gap(pm, slave, R, d)
    gp, _, _, _ = _gap(pm, slave, R, d, ROTATION_STEP_RAD)
    gm_, _, _, _ = _gap(pm, slave, R, d, -ROTATION_STEP_RAD)
    ok = np.isfinite(gap) & np.isfinite(gp) & np.isfinite(gm_)
    if not ok.any():
        return None
    sel, R, gap, rF, n_loc, e_fix, gp, gm_ = (x[ok] for x in (sel, R, gap, rF, n_loc, e_fix, gp, gm_))
    w = -(gp - gm_) / (2 * ROTATION_STEP_RAD) / pm.pair.gear(0).base_radius_m
    # rigid gap of the pair: dense sampling of the slave flank over the window
    u_lo = math.sqrt(max(2 * (s_c - pm.window_m) / rb, 0.0))
    u_hi = math.sqrt(2 * min(s_c + pm.window_m, rb * u_a ** 2 / 2) / rb)
    Rd = rb * np.sqrt(1.0 + np.linspace(u_lo, u_hi, DENSE_GAP_POINTS) ** 2)
    gd, _, _, _ = _gap(pm, slave, Rd, d)
    gd_p, _, _, _ = _gap(pm, slave, Rd, d, ROTATION_STEP_RAD)
    gd_m, _, _, _ = _gap(pm, slave, Rd, d, -ROTATION_STEP_RAD)
    wd = -(gd_p - gd_m) / (2 * ROTATION_STEP_RAD) / pm.pair.gear(0).base_radius_m
    with np.errstate(invalid="ignore"):
        g_pair = float(np.nanmin(np.where(np.isfinite(gd) & (wd > 0), gd / wd, np.inf)))
    g1, g2, _ = _frames(pm, d)
    gam = (g1, g2)
    master = 1 - slave
    # directions in each body's tooth frame: +e on the slave node, -e on the master foot
    dir_s = e_fix @ rot(-gam[slave]).T
    dir_m = -n_loc
    return {"slave": slave, "nodes": sel, "R": R, "rF": rF, "gap": gap, "w": w, "g_pair": g_pair,
            "dirs": {slave: dir_s, master: dir_m}, "j": j, "d": d,
            "teeth": (-j, j)}


def _reps(body: GearBody, c: dict, gi: int, delta_tooth: int):
    """(B positions (n, 6), coefficients (n, 6)) of the candidates of c on body gi,
    read or loaded on the body's tooth ``delta_tooth`` (relative to the load tooth)."""
    z = body.gear.teeth
    ang = 2.0 * math.pi * delta_tooth / z
    dirs = c["dirs"][gi] @ rot(ang).T
    if gi == c["slave"] and delta_tooth == 0:
        b = body.flank_b[0][c["nodes"]]
        idx = np.column_stack([b, b, b])
        wts = np.zeros((len(b), 3))
        wts[:, 0] = 1.0
    else:
        R = c["R"] if gi == c["slave"] else c["rF"]
        idx, wts = body.edge_weights(delta_tooth, R)
    idx6 = np.concatenate([idx, idx + 1], axis=1)
    coef6 = np.concatenate([wts * dirs[:, :1], wts * dirs[:, 1:]], axis=1)
    return idx6, coef6


def _flexibility(pm: PairModel, cands: list) -> np.ndarray:
    """C (n, n) of all candidates: sum over both bodies of a_i^T G a_j, with the read
    on the tooth t_i - t_j relative to the load (rotational periodicity)."""
    sizes = [len(c["R"]) for c in cands]
    off = np.concatenate([[0], np.cumsum(sizes)])
    C = np.zeros((off[-1], off[-1]))
    for gi, body in enumerate(pm.bodies):
        for a, ca in enumerate(cands):
            for b, cb in enumerate(cands):
                dt = ca["teeth"][gi] - cb["teeth"][gi]
                ia, wa = _reps(body, ca, gi, dt)
                ib, wb = _reps(body, cb, gi, 0)
                Gs = body.G[np.ix_(ia.ravel(), ib.ravel())].reshape(ia.shape[0], 6, ib.shape[0], 6)
                C[off[a]:off[a + 1], off[b]:off[b + 1]] += np.einsum("ia,iajb,jb->ij", wa, Gs, wb)
    return 0.5 * (C + C.T)


def solve_position(pm: PairModel, theta: float, total_N: float) -> PositionSolution:
    """Resolved contact at pinion angle theta (rad from the entry of a pair at A; any
    value, also outside one mesh period) under the torque-equivalent load total_N."""
    j, d = pm.mesh.slots(theta)
    A, E = pm.mesh.path_start_m, pm.mesh.path_end_m
    ext = EXTENSION_PITCHES * pm.mesh.base_pitch_m
    cands, slots = [], []
    for k in np.flatnonzero((d >= A - ext) & (d <= E + ext)):
        c = _candidates(pm, float(d[k]), int(j[k]))
        if c is not None:
            cands.append(c)
            slots.append(k)
    if not cands:
        raise RuntimeError(f"no tooth pair can touch at theta = {theta!r} rad")
    C = _flexibility(pm, cands)
    g = np.concatenate([c["gap"] for c in cands])
    w = np.concatenate([c["w"] for c in cands])
    if np.any(w <= 0):
        raise RuntimeError("a candidate's lever arm about the pinion centre is not positive")
    sol = solve_contact(C / np.outer(w, w), g / w, total_force_N=total_N)
    q = sol.force_N
    loads = np.zeros(len(d))
    hw = np.zeros(len(d))
    gaps = np.full(len(d), np.inf)
    off = 0
    for k, c in zip(slots, cands):
        n = len(c["R"])
        qc = q[off:off + n]
        c["force_N"] = qc / c["w"]
        loads[k] = qc.sum()
        gaps[k] = c["g_pair"]
        on = np.flatnonzero(qc > 0)
        if on.size:
            rb = pm.pair.gear(c["slave"]).base_radius_m
            s = rb * ((c["R"] / rb) ** 2 - 1.0) / 2.0
            ds = np.diff(s).mean() if len(s) > 1 else 0.0
            hw[k] = 0.5 * (s[on].max() - s[on].min() + ds)
            c["window_hit"] = bool(on[0] == 0 and s[0] > s.min() - 1) and (on[0] == 0 or on[-1] == n - 1)
        off += n
    return PositionSolution(float(theta), d, np.asarray(slots), loads, float(sol.approach_m), gaps, hw, cands,
                            C, g, w)


# ---------------------------------------------------------------------------
# the cycle
# ---------------------------------------------------------------------------


def pair_contact(pair: PairSpec, wear: WearSpec | None = None, positions: int = 24, torque_Nm: float = 40.0,
                 clearance_m: float = 0.0, contact_scale: float = 1.0, mesh_scale: float = 1.0,
                 plane: str = "stress", extended: bool = True, flank: FlankSpec | None = None) -> PairFE:
    """FE static transmission error and mesh stiffness at ``positions`` pinion angles
    theta = i (2 pi / z1) / positions (theta = 0 when a pair enters at A).

    The centre distance follows from the bearing clearance as in analytic.tvms (rigid
    bearings). ``contact_scale`` multiplies the contact element size h_c (the
    h-refinement of the contact zone), ``mesh_scale`` the other sizes. ``extended``:
    also locate where loaded corner contact begins and ends (bisection, meta
    "extended_contact_deg"). See the module docstring for the method."""
    t_start = time.perf_counter()
    if isinstance(positions, bool) or not isinstance(positions, (int, np.integer)) or positions < 2:
        raise fail("positions", positions, "", "must be a whole number >= 2")
    pm = pair_model(pair, wear, torque_Nm, clearance_m, contact_scale, mesh_scale, plane, flank)
    t_model = time.perf_counter()
    mesh = pm.mesh
    F = torque_Nm / pair.gear(0).base_radius_m
    theta = np.arange(positions) * (mesh.mesh_angle_rad / positions)
    _, d = mesh.slots(theta)
    in_path = mesh.in_path(d)
    loads = np.zeros(d.shape)
    gaps = np.full(d.shape, np.inf)
    hw = np.zeros(d.shape)
    ste = np.zeros(positions)
    ktan = np.zeros(positions)
    n_cand, hits, iters = [], 0, 0
    t_lcp = 0.0
    t_asm = 0.0
    for p, th in enumerate(theta):
        ta = time.perf_counter()
        ps = solve_position(pm, float(th), F)
        tb = time.perf_counter()
        loads[p], gaps[p], hw[p], ste[p] = ps.loads_N, ps.gaps_m, ps.half_width_m, ps.ste_m
        n_cand.append(len(ps.g))
        hits += sum(bool(c.get("window_hit")) for c in ps.cand)
        eps = 1e-3
        Cw, gw = ps.C / np.outer(ps.w, ps.w), ps.g / ps.w
        dp = solve_contact(Cw, gw, total_force_N=F * (1 + eps)).approach_m
        dm = solve_contact(Cw, gw, total_force_N=F * (1 - eps)).approach_m
        ktan[p] = 2 * eps * F / (dp - dm)
        t_asm += tb - ta
        t_lcp += time.perf_counter() - tb
    on = loads > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        g_on = np.where(on, gaps, 0.0)
        k_pair = np.where(on, loads / np.maximum(ste[:, None] - g_on, 1e-300), 0.0)
    k = k_pair.sum(axis=1)
    exc = np.where(k > 0, (k_pair * g_on).sum(axis=1) / k, 0.0)
    t_cycle = time.perf_counter()
    widths = extended_contact_widths(pm, F) if extended else None
    t_end = time.perf_counter()
    timings = {**pm.timings, "model_s": t_model - t_start, "positions_s": t_cycle - t_model,
               "positions_geometry_s": t_asm, "positions_lcp_s": t_lcp, "extended_s": t_end - t_cycle,
               "total_s": t_end - t_start}
    meta = {"sizes_m": {k2: getattr(pm.sizes, k2) for k2 in ("contact_m", "near_m", "far_m", "fillet_m",
                                                              "global_m")},
            "a_ref_m": pm.a_ref_m, "window_m": pm.window_m, "contact_scale": contact_scale,
            "mesh_scale": mesh_scale, "plane": plane, "order": 2, "shared_body": pm.bodies[0] is pm.bodies[1],
            "n_elements": [bd.n_elements for bd in pm.bodies], "ndofs": [bd.ndofs for bd in pm.bodies],
            "condensed_dofs": [int(bd.G.shape[0]) for bd in pm.bodies], "clearance_m": clearance_m,
            "candidates_per_position": [int(min(n_cand)), int(max(n_cand))], "window_hits": int(hits),
            "corner_contact": True, "local_contact": "resolved", "pair_gap_m": gaps,
            "extended_contact_deg": widths}
    return PairFE(pair, mesh, torque_Nm, wear, theta, k, ktan, ste, exc, loads, d, in_path, hw, timings, meta)


def extended_contact_widths(pm: PairModel, total_N: float, tol_deg: float = 1e-4) -> dict:
    """Pinion rotation (deg) over which a pair carries load before it reaches A
    (gear tip corner on the pinion flank) and after it passes E (pinion tip corner),
    by bisection on the pair's load (positive inside, zero outside)."""
    rb1 = pm.pair.gear(0).base_radius_m
    A, E = pm.mesh.path_start_m, pm.mesh.path_end_m
    span = EXTENSION_PITCHES * pm.mesh.base_pitch_m / rb1

    def load_at(theta, target_d):
        ps = solve_position(pm, theta, total_N)
        k = int(np.argmin(np.abs(ps.d_m - target_d)))
        return ps.loads_N[k]

    out = {}
    for name, d_kin, sign in (("entry", A, -1.0), ("exit", E, 1.0)):
        theta_kin = (d_kin - A) / rb1
        lo, hi = 0.0, span  # distance beyond the kinematic transition (rad)
        if load_at(theta_kin + sign * hi, d_kin + sign * hi * rb1) > 0:
            out[name] = float("nan")  # beyond the candidate range: not resolved
            continue
        if load_at(theta_kin, d_kin) <= 0:
            out[name] = 0.0
            continue
        while math.degrees(hi - lo) > tol_deg:
            mid = 0.5 * (lo + hi)
            if load_at(theta_kin + sign * mid, d_kin + sign * mid * rb1) > 0:
                lo = mid
            else:
                hi = mid
        out[name] = math.degrees(0.5 * (lo + hi))
    return out


# ---------------------------------------------------------------------------
# consistency with the single-tooth FE and the local approach c_local
# ---------------------------------------------------------------------------


def _probe_rep(body: GearBody, pt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(B positions of x dofs, P2 weights) of an interior point of tooth 0."""
    P = body.model.basis.probes(np.asarray(pt, dtype=float).reshape(2, 1)).tocsr()
    nz = np.abs(P[0].data) > 1e-14  # explicit zeros (the other component, a shared edge)
    dofs, wts = P[0].indices[nz], P[0].data[nz]
    b_of = {int(x): int(b) for x, b in zip(body.centre_dofs, body.centre_b)}
    missing = [int(x) for x in dofs if int(x) not in b_of]
    if missing:
        raise RuntimeError("a centre-line reading point lies in an element that is not condensed")
    return np.array([b_of[int(x)] for x in dofs]), np.asarray(wts)


def centre_line_compliance(pm: PairModel, ps: PositionSolution) -> dict:
    """In single contact: displacement of each tooth's centre-line point where the load
    line crosses it (y_c of geometry.loading), along the force on that tooth, per N of
    the pair load, and c_local = delta / F - c_1 - c_2 (m/N)."""
    loaded = [c for c, k in zip(ps.cand, ps.slots) if ps.loads_N[k] > 0]
    if len(loaded) != 1:
        raise ValueError("centre_line_compliance needs exactly one loaded pair")
    c = loaded[0]
    F = float(ps.loads_N.sum())
    d = c["d"]
    L = pm.mesh.line_of_action_m
    out = {"d_m": d}
    for gi, body in enumerate(pm.bodies):
        g = pm.pair.gear(gi)
        R = math.hypot(g.base_radius_m, d if gi == 0 else L - d)
        prof = tooth_profile(g)
        lp = load_points(prof, np.array([R]))
        e = -np.array([math.cos(lp.w_rad[0]), math.sin(lp.w_rad[0])])
        qb, qw = _probe_rep(body, np.array([0.0, lp.y_axis_m[0]]))
        ia, wa = _reps(body, c, gi, 0)
        rows = np.concatenate([qb, qb + 1])
        coef = np.concatenate([qw * e[0], qw * e[1]])
        Gs = body.G[np.ix_(rows, ia.ravel())].reshape(len(rows), ia.shape[0], 6)
        u = float(np.einsum("r,rjb,jb,j->", coef, Gs, wa, c["force_N"]))
        out[f"c{gi + 1}_m_per_N"] = u / F
        out[f"R{gi + 1}_m"] = R
        out[f"h{gi + 1}_m"] = float(lp.x_m[0] / math.cos(lp.w_rad[0]))
    out["c_pair_m_per_N"] = ps.ste_m / F
    out["c_local_m_per_N"] = ps.ste_m / F - out["c1_m_per_N"] - out["c2_m_per_N"]
    out["load_N"] = F
    out["R_star_m"] = d * (L - d) / L
    return out


def consistency(pair: PairSpec, torque_Nm: float = 40.0, positions: int = 24, contact_scale: float = 1.0,
                plane: str = "stress") -> list[dict]:
    """At every single-contact position of the cycle: c_1, c_2 read in the pair FE and
    by the single-tooth FE (fem.tooth on its own mesh, Hertz patch, read at the same
    centre-line points), c_local, Weber's approach in plane stress and plane strain,
    and the pair stiffness against 1 / (c_1 + c_2 + c_local) with the single-tooth c."""
    from .tooth import single_tooth_compliance

    pm = pair_model(pair, None, torque_Nm, 0.0, contact_scale, 1.0, plane)
    F = torque_Nm / pair.gear(0).base_radius_m
    theta = np.arange(positions) * (pm.mesh.mesh_angle_rad / positions)
    rows = []
    for th in theta:
        ps = solve_position(pm, float(th), F)
        if int(np.sum(ps.loads_N > 0)) != 1:
            continue
        rows.append(centre_line_compliance(pm, ps))
    if not rows:
        return rows
    mat = pair.material
    for gi in (0, 1):
        R = np.array([r[f"R{gi + 1}_m"] for r in rows])
        fe = single_tooth_compliance(pair, gear_index=gi, radii_m=R, load_N=F, plane=plane, read_at="load_line")
        c = fe.fem_compliance_um_per_N_per_mm / (1e6 * pair.face_width_m * 1e3)
        for r, ci in zip(rows, c):
            r[f"c{gi + 1}_tooth_m_per_N"] = float(ci)
    for r in rows:
        for pl in ("stress", "strain"):
            r[f"weber_{pl}_m_per_N"] = float(weber_approach_m(r["load_N"], r["h1_m"], r["h2_m"], r["R_star_m"],
                                                              mat.youngs_modulus_Pa, mat.poisson_ratio,
                                                              pair.face_width_m, pl)) / r["load_N"]
        r["k_pair_N_per_m"] = 1.0 / r["c_pair_m_per_N"]
        r["k_identity_N_per_m"] = 1.0 / (r["c1_tooth_m_per_N"] + r["c2_tooth_m_per_N"] + r["c_local_m_per_N"])
    return rows


# ---------------------------------------------------------------------------
# fields
# ---------------------------------------------------------------------------


def _stress(body: GearBody, U: np.ndarray, material) -> np.ndarray:
    """Element-mean stress (nel, 3): sigma_xx, sigma_yy, sigma_xy (Pa) of the field U."""
    from skfem.helpers import sym_grad

    from .elasticity import lame

    basis = body.model.basis
    eps = sym_grad(basis.interpolate(U))  # (2, 2, nel, nqp)
    lam, mu = lame(material, body.model.plane)
    tr = eps[0, 0] + eps[1, 1]
    sxx, syy, sxy = lam * tr + 2 * mu * eps[0, 0], lam * tr + 2 * mu * eps[1, 1], 2 * mu * eps[0, 1]
    return np.column_stack([sxx.mean(axis=1), syy.mean(axis=1), sxy.mean(axis=1)])


def write_fields(pm: PairModel, positions: list[int], n_positions: int, torque_Nm: float, out_dir) -> list:
    """Displacement and stress fields of both gears at the given position indices
    (theta = i 2 pi / (z1 n_positions)) as ``fields_pos<i>.vtu`` (meshio, P2 triangles
    in the fixed frame of the module docstring; point data displacement_m, cell data
    sigma_xx/yy/xy_Pa, von_mises_Pa, gear). The loaded tooth with the largest load is
    each body's refined tooth 0; the other loaded teeth take their load on their own
    (coarser) flanks."""
    import meshio
    import scipy.sparse.linalg as spla
    from pathlib import Path

    from gearwear.core.atomic import atomic_write

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    F = torque_Nm / pm.pair.gear(0).base_radius_m
    files = []
    for i in positions:
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < n_positions:
            raise fail("fields", i, "", f"must be a position index in [0, {n_positions - 1}]")
        theta = i * pm.mesh.mesh_angle_rad / n_positions
        ps = solve_position(pm, theta, F)
        ref = max(ps.cand, key=lambda c: float(c["force_N"].sum()))
        g1, g2, O2 = _frames(pm, ref["d"])
        pts, cells, disp, cdata, gear_id = [], [], [], [], []
        offset = 0
        for gi, body in enumerate(pm.bodies):
            model = body.model
            if getattr(body, "_lu", None) is None:
                Kff = model.K[model.free][:, model.free].tocsc()
                body._lu = spla.splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                     options={"SymmetricMode": True})
            f = np.zeros(model.ndofs)
            for c in ps.cand:
                idx, coef = _reps(body, c, gi, c["teeth"][gi] - ref["teeth"][gi])
                np.add.at(f, body.dofs[idx], coef * c["force_N"][:, None])
            U = np.zeros(model.ndofs)
            U[model.free] = body._lu.solve(f[model.free])
            S = _stress(body, U, pm.pair.material)
            Rm = rot(g1 if gi == 0 else g2)
            loc = model.basis.doflocs[:, 0::2].T
            p = loc @ Rm.T + (0.0 if gi == 0 else O2)
            u = U.reshape(-1, 2) @ Rm.T
            # stress tensor to the fixed frame: R sigma R^T
            sig = np.stack([np.stack([S[:, 0], S[:, 2]], -1), np.stack([S[:, 2], S[:, 1]], -1)], -2)
            sig = Rm @ sig @ Rm.T
            sxx, syy, sxy = sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1]
            szz = (pm.pair.material.poisson_ratio * (sxx + syy)) if pm.plane == "strain" else 0.0 * sxx
            vm = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * sxy ** 2)
            pts.append(np.column_stack([p, np.zeros(len(p))]))
            disp.append(np.column_stack([u, np.zeros(len(u))]))
            cells.append(model.basis.element_dofs[0::2].T // 2 + offset)
            cdata.append(np.column_stack([sxx, syy, sxy, vm]))
            gear_id.append(np.full(len(sxx), gi))
            offset += len(p)
        cd = np.vstack(cdata)
        mesh = meshio.Mesh(np.vstack(pts), [("triangle6", np.vstack(cells).astype(np.int64))],
                           point_data={"displacement_m": np.vstack(disp)},
                           cell_data={"sigma_xx_Pa": [cd[:, 0]], "sigma_yy_Pa": [cd[:, 1]], "sigma_xy_Pa": [cd[:, 2]],
                                      "von_mises_Pa": [cd[:, 3]], "gear": [np.concatenate(gear_id)]})
        path = out_dir / f"fields_pos{i}.vtu"
        atomic_write(str(path), lambda tmp: meshio.write(tmp, mesh, file_format="vtu"))
        files.append(path)
    return files
