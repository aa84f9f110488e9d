"""Spur-pair mesh stiffness by resolved FE contact of the two gear bodies: loaded
static transmission error and mesh stiffness over one mesh period, any pair
(unequal teeth, profile shift, wear, clearance-shifted centre distance), and over one
revolution of the faulty gear with a spall or a root crack on one tooth.

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

The blank's torsion
-------------------
Each body is held at its bore, so delta (and k) holds the torsion of both blanks
between bore and teeth: moving the bores of the 23/47 pair (m 3, b 30 mm) from 12.5/25
to 24/55 mm moves the mean by +46 % while the analytic models have no such term. It is
reported as its own term. Reference circle of gear i: r_ref = r_f - 2 m, not below the
bore (pair_body.blank_reference_radius_m: there the tooth-pitch part of a tooth load's
field has decayed to ~exp(-4), so the circle turns as a rigid ring; with a thinner rim
r_ref is the bore, there is no blank term and the whole rim stays in the mesh
stiffness). Its rotation theta_ref,i (counter-clockwise) is the least-squares rigid
rotation of 16 z points on it, i.e. the mean tangential displacement over r_ref
(pair_body.blank_reading: a functional a_i of the body's displacement, exact for a
rigid rotation). By reciprocity theta_ref,i = a_i . K_i^-1 f_i = h_i . f_i with
h_i = (K_i^-1 a_i) on the condensed flank dofs: one more solve per body with the
factors of the condensation, nothing per position. Per position

    delta = delta_mesh + r_b1 theta_ref,1 + r_b2 theta_ref,2

(the pinion's contact moment turns its circle back against the drive, the gear's turns
its circle on with it: both widen the approach), and the mesh-only curve is the secant
above with delta_mesh: k_mesh = sum F_k / (delta_mesh - g_k); its tangent is
1 / (1 / k_tangent - (r_b1 theta_1 + r_b2 theta_2) / F). Each blank's torsional
stiffness is k_blank,i = T_i / theta_ref,i (N m/rad), T_i the contact loads' moment
about the gear's centre (T_1 = T; T_2 = T z2 / z1 to the off-line-of-action arms). The
mean (n = 0 Fourier part) of u_theta of a solid annulus held at the bore and loaded
outside r_ref obeys u'' + u'/r - u/r^2 = 0 with the torque through every circle, so
k_blank = 4 pi G b / (1 / r_bore^2 - 1 / r_ref^2) exactly (in-plane shear: plane
stress and plane strain alike), whatever the teeth do; the FE gives it to 1e-4
(tests/test_blank_torsion.py) and the identity STE / F = STE_mesh / F + r_b1^2 / k_1 +
r_b2^2 / k_2 with the closed-form k holds to 3e-4. What stays in the mesh-only term is
everything but the n = 0 part below r_ref: the blank's bending under the net tooth
force (n = 1, ~ ln(r_ref / r_bore)) and the teeth's foundation, which a bore close
below the root stiffens (bore study, benchmarks/bench_bore_study.py: the mesh-only mean
moves +23 % from 12.5/25 to 24/55 mm bores, against +46 % bore-fixed; between the thick
rims of 8/16 and 12.5/25 mm it moves ~4 %). Which to compare: Ishikawa (tooth clamped at
the root), the energy method (Sainsot's foundation is the body's local deformation
below the tooth, bore-dependent through h_fi = r_f / r_bore but without a rigid torsion
of the blank) and ISO 6336 (c' of solid blanks, no bore in it) with the mesh-only
curve; a 6-DOF model without shaft or blank torsion of its own with the bore-fixed one.

Faults on one tooth (geometry.faults)
-------------------------------------
Numbering as geometry.faults: in mesh period n of a revolution, slot j holds the pair
that entered n - j periods after tooth pair 0, so the faulty tooth tau of gear g sits
in slot j when (n - j) mod z_g = tau. The curve spans revolution_periods mesh periods
(z of the faulty gear; lcm with faults on both gears), ``positions`` per period. A
position is solved again only where a slot holding a faulty tooth is a candidate pair
(within EXTENSION_PITCHES p_b of the path, so the corner contact is included); every
other position is the healthy period's, copied (rotational periodicity), so those
periods are the healthy curve to the bit. The faulty solves use the healthy period's
angles, with ``period`` telling which slot holds the faulty tooth.

* Spall: the pit (through the face width, from its start diameter along the involute
  for its length, ``depth`` deep) is a flank depth of the faulty tooth only: the gap of
  a slave node inside it, or of a slave node whose foot on the master lies inside it,
  grows by the depth. Its two edges are corners of the spalled flank: exact points on
  the involute at the edge radii, candidates like the tip corner, loaded through the
  P2 edge weights, against the mating involute (flank nodes within h_c / 4 of an edge
  give way to it). Where the contact point lies within a window of the pit, the
  candidate window reaches past both edges. No bridging formula enters: at near-zero
  load the mating flank rests on the edges, and the TE is the rigid gap of the exact
  geometry (~ min(depth, x^2 / (2 R')), geometry.faults.spall_gap_m).
* Crack: a second body of the cracked gear (pair_body.build_cracked_body): the straight
  crack of geometry.crack cut into tooth 0 by Gmsh's Crack plugin (both faces free, no
  face contact), the tip refined to CRACK_TIP_FRACTION x min(fillet size, depth) as in
  fem.tooth (default_crack_tip_size_m, with the body's fillet size), and the drive
  flanks of the teeth that can be candidates together with the cracked one
  (fault_neighbours: floor(epsilon + 2 EXTENSION_PITCHES) each side) refined alike and
  condensed over the radius range they reach meanwhile. At a position where
  the cracked tooth is a candidate, that gear's flexibility comes from the cracked body,
  every candidate read and loaded on its own tooth relative to the cracked one (no
  periodic mapping); the mating gear keeps its healthy body. Elsewhere the healthy body
  serves (the crack's effect on its neighbours' compliance when it is not engaged is
  left out).

Measured (paper pair, 40 N m, 24 positions per period; wall times: make bench): spall
example (1 mm x 20 um at 150 mm on pinion tooth 0): 67 positions solved of 720, 38-268
candidates per position; root crack example (2 mm at 45 deg on pinion tooth 0): cracked
body 129k dofs, 3128 condensed dofs. Checks (tests/test_fem_faults.py):
near-zero-load TE over a short pit = spall_gap_m to 0.70 % of its peak; in single contact
on the cracked tooth c_1 read in the cracked pair = single-tooth FE of the cracked tooth
to 0.05-0.06 %, and the pair compliance = c_1,cracked + c_2 + c_local,healthy to
0.14-0.24 % (the crack also raises c_local by 0.3-0.7 %).

``pair_contact(executor=...)`` sends the positions in chunks to any
concurrent.futures.Executor (a process pool, Dask's ``Client.get_executor()``); the
workers rebuild the model from its arguments, each building a body once
(in-process cache), and the result is the serial one to the bit.

Measured (benchmarks/bench_fem_pair.py, 40 N m, plane stress, P2; wall times there)
-----------------------------------------------------------------------------------
Paper pair, 24 positions, h_c = 25.6 um: 96k dofs, 2172 condensed dofs, 38-77
candidates per position. Mean 3.3838e8 N/m; single-pair plateau 2.4686e8, double-pair
plateau 3.7784e8 N/m; loaded corner contact 0.298 deg before A and 0.296 deg after
E. Contact-zone refinement h_c = a/1.25 .. a/5: mean 3.38755, 3.38530, 3.38378,
3.38359, 3.38351 e8 (one more refinement of the default: -0.006 %; Richardson
estimate 3.38347e8). Single contact: c_1, c_2 equal the single-tooth FE to 0.1-0.15 %,
k_pair = 1 / (c_1 + c_2 + c_local) to 0.09 %, c_local = 1.50e-9 m/N is 4.5 % above
Weber in plane stress and 15 % above Weber in plane strain (gearwear.compare.pair_consistency).
Shifted 21/37 pair (x = +0.25/-0.10): two bodies, mean 3.2486e8,
plateaus 2.4752e8 / 3.7265e8 N/m, corner contact 0.461 / 0.463 deg.
"""

from __future__ import annotations

import math
import threading
import time
from collections import OrderedDict
from concurrent.futures import Executor
from dataclasses import dataclass, field, replace
from typing import Any, Callable

import numpy as np

from gearwear.geometry.crack import check_crack
from gearwear.geometry.faults import FaultSpec, check_faults, faulty_slots, holds_fault, revolution_periods
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
from .pair_body import (BodySizes, GearBody, blank_reference_radius_m, build_body, build_cracked_body, involute_point,
                        rot)

__all__ = ["PairFE", "PairModel", "pair_contact", "pair_model", "solve_position", "blank_rotations", "body_sizes",
           "extended_contact_widths", "centre_line_compliance", "write_fields"]

ELEMENTS_PER_HALF_WIDTH = 2.5   # h_c = a_ref / 2.5 at contact_scale 1
WINDOW_HALF_WIDTHS = 3.0        # candidate window: +-3 a_ref of arc length (+ 2 h_c)
EXTENSION_PITCHES = 0.08        # pairs considered up to 0.08 p_b beyond A and E (corner contact)
DENSE_GAP_POINTS = 401          # samples of a pair's slave flank for its rigid gap g_k
ROTATION_STEP_RAD = 1e-7        # central difference of the gaps for the lever arms w_i
_BODY_CACHE: "OrderedDict[tuple, GearBody]" = OrderedDict()  # cracked bodies too
_BODY_CACHE_SIZE = 4
_BODY_LOCK = threading.RLock()


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
    meta               sizes, element counts, options, extended-contact widths, positions solved
    faults             the one-tooth faults (None: healthy); the curve then spans
                       ``periods`` mesh periods, one revolution of the faulty gear
    faulty_pair        (n, p) True where a candidate slot holds a faulty tooth (None: no fault)
    mesh_k_N_per_m, mesh_k_tangent_N_per_m, mesh_ste_m, mesh_excitation_m
                       (n,) the same with the blanks' torsion below r_ref taken out:
                       STE_mesh = STE - r_b1 theta_ref,1 - r_b2 theta_ref,2
    blank_rotation_rad (n, 2) rotation of each blank's reference circle (counter-clockwise)
    blank_torque_Nm    (n, 2) moment of the contact loads about each gear's centre
    meta also holds blank_reference_radius_m [2], blank_torsional_stiffness_Nm_per_rad [2]
    (sum T / sum theta over the positions; inf where r_ref is the bore) and
    mesh_only_mean_N_per_m.
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
    faults: FaultSpec | None = None
    periods: int = 1
    faulty_pair: np.ndarray | None = None
    mesh_k_N_per_m: np.ndarray | None = None
    mesh_k_tangent_N_per_m: np.ndarray | None = None
    mesh_ste_m: np.ndarray | None = None
    mesh_excitation_m: np.ndarray | None = None
    blank_rotation_rad: np.ndarray | None = None
    blank_torque_Nm: np.ndarray | None = None

    def without_blank_torsion(self) -> "PairFE":
        """The same result with the blanks' torsion below r_ref taken out: k, k_tangent,
        STE and e are the mesh-only ones (module docstring, "The blank's torsion")."""
        k, kt, ste, e = self.mesh_k_N_per_m, self.mesh_k_tangent_N_per_m, self.mesh_ste_m, self.mesh_excitation_m
        if k is None or kt is None or ste is None or e is None:
            raise ValueError("this result carries no mesh-only curve")
        return replace(self, k_N_per_m=k, k_tangent_N_per_m=kt, ste_m=ste, excitation_m=e)


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
    """Everything a position solve needs (built once per pair, torque and clearance).

    faults   the one-tooth faults (geometry.faults) or None; ``cracked`` per gear the
             body with the crack (pair_body.CrackedBody) or None."""

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
    faults: FaultSpec | None = None
    cracked: tuple = (None, None)

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
    return (replace(g, name=""), g.material, pair.face_width_m, sizes, round(r_lo, 9), nb,
            tuple(round(c, 9) for c in cy), plane)


def _cached(key: tuple, build):
    """The body under ``key`` from the in-process cache, or ``build()`` stored there;
    (body, built). One build at a time: threads of one worker process (a Dask worker)
    that need the same body wait for it instead of building it twice."""
    with _BODY_LOCK:
        if key in _BODY_CACHE:  # identical gears, another wear state or fault of the same pair
            _BODY_CACHE.move_to_end(key)
            return _BODY_CACHE[key], False
        body = build()
        _BODY_CACHE[key] = body
        while len(_BODY_CACHE) > _BODY_CACHE_SIZE:
            _BODY_CACHE.popitem(last=False)
        return body, True


def fault_neighbours(mesh: MeshGeometry) -> int:
    """Teeth on either side of a faulty tooth that can be candidates together with it:
    the candidate slots span (E - A) + 2 EXTENSION_PITCHES p_b of the LOA, so
    floor(epsilon + 2 EXTENSION_PITCHES) (at least 1)."""
    return max(1, int(math.floor(mesh.contact_ratio + 2 * EXTENSION_PITCHES + 1e-9)))


def _cracked_ranges(mesh: MeshGeometry, gi: int, refined: int, r_lo: float, margin_m: float) -> dict:
    """Flank radius range (r_lo, r_hi) (m) of each tooth t = -refined .. refined of a
    cracked body (tooth 0 cracked) that a contact can reach while the cracked tooth is a
    candidate. In the FE's numbering a pinion slot j is body tooth -j and a gear slot
    body tooth +j, so tooth t sits at d* - t p_b (pinion) or d* + t p_b (gear) when the
    cracked tooth is at d*; both lie in [A - ext, E + ext]. The contact's arc position
    on the flank, s = r_b u^2 / 2, widened by ``margin_m`` both ways."""
    g = mesh.pair.gear(gi)
    rb, r_top = g.base_radius_m, g.tip_radius_m
    L, pb = mesh.line_of_action_m, mesh.base_pitch_m
    ext = EXTENSION_PITCHES * pb
    lo, hi = mesh.path_start_m - ext, mesh.path_end_m + ext
    sign = -1.0 if gi == 0 else 1.0
    u_tip = math.sqrt((r_top / rb) ** 2 - 1.0)
    out = {}
    for t in range(-refined, refined + 1):
        d = np.array([max(lo, lo + sign * t * pb), min(hi, hi + sign * t * pb)])
        u = np.clip((d if gi == 0 else L - d) / rb, 0.0, u_tip)
        s = rb * u * u / 2.0
        s_lo, s_hi = max(float(s.min()) - margin_m, 0.0), float(s.max()) + margin_m
        r_a, r_b = (rb * math.sqrt(1.0 + 2.0 * x / rb) for x in (s_lo, s_hi))
        out[t] = (r_lo, r_top) if t == 0 else (max(r_lo, r_a), min(r_top, r_b))
    return out


def _cracked_body(pair: PairSpec, mesh: MeshGeometry, faults: FaultSpec, nominal, sizes: BodySizes, r_lo: float,
                  nb: int, cy: tuple[float, float], window: float, plane: str):
    """The body of the cracked gear (cached in-process like the healthy ones; the key
    holds the crack, its tip size and the refined teeth)."""
    from .tooth import default_crack_tip_size_m

    cf = faults.crack
    assert cf is not None
    gi = cf.gear_index
    g = pair.gear(gi)
    crack = cf.crack
    check_crack(nominal, crack)
    tip_m = default_crack_tip_size_m(crack, fillet_m=sizes.fillet_m)
    refined = fault_neighbours(mesh)
    sp = faults.spall
    # a spall on the same gear widens the candidate window by up to its length
    margin = 2.0 * window + (sp.length_m if sp is not None and sp.gear_index == gi else 0.0)
    ranges = _cracked_ranges(mesh, gi, refined, r_lo, margin)
    key = ("cracked", _body_key(g, pair, sizes, r_lo, nb, cy, plane), crack, round(tip_m, 12), refined,
           tuple((t, round(a, 9), round(b, 9)) for t, (a, b) in sorted(ranges.items())))
    return _cached(key, lambda: build_cracked_body(g, g.material, pair.face_width_m, nominal, sizes, ranges, nb,
                                                   refined, cy, crack, tip_m, plane))


def _check_inputs(pair: PairSpec, torque_Nm: float, clearance_m: float, plane: str, faults: FaultSpec | None):
    """Bad inputs of the pair model, in this layer's names; the operating geometry."""
    _positive("torque_Nm", torque_Nm, "N m")
    if not (math.isfinite(clearance_m) and clearance_m >= 0):
        raise fail("clearance_m", clearance_m, "m", "must be finite and >= 0")
    if plane not in ("stress", "strain"):
        raise fail("plane", repr(plane), "", "must be 'stress' or 'strain'")
    if faults is not None:
        check_faults(pair, faults)
    og = operating_geometry(pair, clearance_m)
    og.mesh.require_overlap("fem")  # the contact solve needs a pair that can touch at every angle
    return og


def _sizes(pair: PairSpec, torque_Nm: float, contact_scale: float, mesh_scale: float):
    """(body sizes, a_ref, candidate half-window) (m): body_sizes and the window of
    WINDOW_HALF_WIDTHS a_ref + 2 h_c of arc length."""
    sizes, a_ref = body_sizes(pair, torque_Nm, contact_scale, mesh_scale)
    return sizes, a_ref, WINDOW_HALF_WIDTHS * a_ref + 2.0 * sizes.contact_m


def _model_spec(pair: PairSpec, wear: WearSpec | None, torque_Nm: float, clearance_m: float, contact_scale: float,
                mesh_scale: float, plane: str, flank: FlankSpec | None, faults: FaultSpec | None) -> dict[str, Any]:
    """The pair_model arguments by name (what a worker process needs to rebuild the model)."""
    return {"pair": pair, "wear": wear, "torque_Nm": torque_Nm, "clearance_m": clearance_m,
            "contact_scale": contact_scale, "mesh_scale": mesh_scale, "plane": plane, "flank": flank, "faults": faults}


def pair_model(pair: PairSpec, wear: WearSpec | None = None, torque_Nm: float = 40.0, clearance_m: float = 0.0,
               contact_scale: float = 1.0, mesh_scale: float = 1.0, plane: str = "stress",
               flank: FlankSpec | None = None, faults: FaultSpec | None = None) -> PairModel:
    """Bodies (cached in-process: wear states and faults share them) and exact geometry.
    ``flank``: profile modifications and measured deviations (geometry.flank), gaps like
    the wear. ``faults`` (geometry.faults): a spall is a gap of its tooth only; a crack
    adds the cracked body of its gear (pair_body.build_cracked_body)."""
    t0 = time.perf_counter()
    faults = None if faults is None or faults.is_empty else faults
    mesh = _check_inputs(pair, torque_Nm, clearance_m, plane, faults).mesh
    sizes, a_ref, window = _sizes(pair, torque_Nm, contact_scale, mesh_scale)
    nb = int(math.ceil(mesh.contact_ratio + 2 * EXTENSION_PITCHES)) + 1
    bodies: list[GearBody] = []
    depth: list[tuple[np.ndarray, np.ndarray] | None] = []
    cracked: list = [None, None]
    tim: dict[str, float] = {}
    for gi, g in enumerate(pair.gears):
        # the body outline is interpolated on this polyline: 1 nm sag keeps it on the curve
        nominal = tooth_profile(g, sag_m=FINE_SAG_M, extra_roll=key_roll_angles(mesh, gi))
        r_lo = _candidate_radius_range(mesh, gi, window)
        lp = load_points(nominal, np.array([max(r_lo, nominal.form_radius_m), g.tip_radius_m * (1 - 1e-9)]))
        cy = (float(lp.y_axis_m.min()) - 1.0 * pair.module_m * 0.2, float(lp.y_axis_m.max()) + 0.2 * pair.module_m)
        body, built = _cached(_body_key(g, pair, sizes, r_lo, nb, cy, plane),
                              lambda: build_body(g, g.material, pair.face_width_m, nominal, sizes, r_lo, nb, cy,
                                                 plane))
        if built:
            for k2, v in body.timings.items():
                tim[f"gear{gi}_{k2}"] = v
        bodies.append(body)
        if faults is not None and faults.crack is not None and faults.crack.gear_index == gi:
            cracked[gi], built = _cracked_body(pair, mesh, faults, nominal, sizes, r_lo, nb, cy, window, plane)
            if built:
                for k2, v in cracked[gi].timings.items():
                    tim[f"cracked{gi}_{k2}"] = v
        worn = wear is not None and not wear.is_unworn
        if worn or not is_nominal(flank):
            inv = nominal.region == INVOLUTE
            h = flank_depth(nominal, gi, mesh, wear)[inv] if worn and wear is not None else 0.0
            h = h + modification_depth_m(flank, pair, gi, nominal.radius[inv])
            depth.append((nominal.radius[inv], h))
        else:
            depth.append(None)
    tim["model_s"] = time.perf_counter() - t0
    return PairModel(pair, mesh, tuple(bodies), wear, tuple(depth), window, a_ref, sizes, plane, tim, faults,
                     tuple(cracked))


# ---------------------------------------------------------------------------
# one position
# ---------------------------------------------------------------------------

#: no tooth of the slot is faulty (per gear: the slot's tooth carries the spall)
NO_SPALL = (False, False)


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


def _spall_radii(pm: PairModel) -> tuple[float, float]:
    """Radii (m) of the spall's edges on its flank."""
    assert pm.faults is not None and pm.faults.spall is not None
    sp = pm.faults.spall
    return 0.5 * sp.start_diameter_m, 0.5 * sp.end_diameter_m(pm.pair)


def _spall_depth(pm: PairModel, gi: int, R: np.ndarray, spalled: tuple) -> np.ndarray | float:
    """Depth (m) of the spall at radii R of gear gi's flank when the slot's tooth of
    gear gi carries it (``spalled``): the pit floor between its edges, 0 elsewhere."""
    if not spalled[gi]:
        return 0.0
    assert pm.faults is not None and pm.faults.spall is not None
    ra, rb = _spall_radii(pm)
    return np.where((R > ra) & (R < rb), pm.faults.spall.depth_m, 0.0)


def _gap(pm: PairModel, slave: int, R: np.ndarray, d: float, dtheta: float = 0.0, spalled: tuple = NO_SPALL):
    """Initial normal gap of the exact slave flank points at radii R against the exact
    master involute (+ wear and flank deviations of both flanks, + the spall where the
    slot's tooth carries it): (gap, foot radius, master outward normal in the master
    tooth frame, the same in the fixed frame)."""
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
    if spalled != NO_SPALL:
        gap = gap + _spall_depth(pm, slave, R, spalled) + _spall_depth(pm, master, rF, spalled)
    # a foot past the master's tip or below its condensed flank: that slave point faces
    # the master's corner or fillet, not its flank; it cannot be loaded here
    out = (rF > gm.tip_radius_m) | (rF < pm.bodies[master].flank_r[0][0]) | (r <= rbm)
    gap = np.where(out, np.inf, gap)
    return gap, rF, n_loc, n_loc @ rot(gam_m).T


@dataclass
class PositionSolution:
    """Resolved contact at one pinion angle (SI).

    d_m, teeth (slots in contact candidates), loads_N per slot (torque-equivalent),
    ste_m, gaps_m per slot (rigid gap g_k), cand (per slot one dict, two with a spall's
    edges: slave, node radii, foot radii, forces, reps), half_width_m per slot;
    cracked per gear (body tooth, LOA position) of the cracked tooth when the cracked
    body served, else None; per gear the rotation theta_ref (rad) of the blank's
    reference circle and the contact loads' moment T about the gear's centre (N m), both
    counter-clockwise (:func:`blank_rotations`)."""

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
    cracked: tuple = (None, None)
    blank_rotation_rad: tuple = (0.0, 0.0)
    blank_torque_Nm: tuple = (0.0, 0.0)


def _lever_arms(pm: PairModel, slave: int, R: np.ndarray, d: float, spalled: tuple = NO_SPALL):
    """(gap, foot radius, local normal, fixed normal, w) of slave points at radii R, w the
    lever arm -(d gap / d dtheta) / r_b1 by a central difference of the exact gaps."""
    gap, rF, n_loc, e_fix = _gap(pm, slave, R, d, spalled=spalled)
    gp, _, _, _ = _gap(pm, slave, R, d, ROTATION_STEP_RAD, spalled)
    gm_, _, _, _ = _gap(pm, slave, R, d, -ROTATION_STEP_RAD, spalled)
    ok = np.isfinite(gap) & np.isfinite(gp) & np.isfinite(gm_)
    with np.errstate(invalid="ignore"):  # inf - inf where a point cannot touch (not ok)
        w = -(gp - gm_) / (2 * ROTATION_STEP_RAD) / pm.pair.gear(0).base_radius_m
    return gap, rF, n_loc, e_fix, w, ok


def _arc(rb: float, R) -> np.ndarray:
    """Arc length along the involute from the base circle, s = r_b u^2 / 2 (m)."""
    return rb * ((np.asarray(R, dtype=float) / rb) ** 2 - 1.0) / 2.0


def _tip_roll(g) -> float:
    """Roll angle u_a (rad) of gear g's tip circle."""
    return math.sqrt((g.tip_radius_m / g.base_radius_m) ** 2 - 1.0)


def _contact_arc(pm: PairModel, gi: int, d: float) -> float:
    """Arc position s_c = r_b u^2 / 2 (m) on gear gi's flank of the kinematic contact at
    LOA position d, the roll u clamped to [0, u_a]."""
    g = pm.pair.gear(gi)
    rb = g.base_radius_m
    u = (d if gi == 0 else pm.mesh.line_of_action_m - d) / rb
    return rb * min(max(u, 0.0), _tip_roll(g)) ** 2 / 2.0


def _spall_edges(pm: PairModel, d: float, spalled: tuple):
    """(gear, edge radii (2,), edge arc positions (2,), widened window) when the slot's
    spalled flank can touch the mating flank near its pit at LOA position d, else None.

    The mating flank bridges a short pit on its edges (geometry.faults): the two edges are
    corners of the spalled flank, loaded like the tip corner by an exact point on the
    flank, and the candidate window reaches past both of them."""
    if not any(spalled):
        return None
    assert pm.faults is not None and pm.faults.spall is not None
    gs = 0 if spalled[0] else 1
    g = pm.pair.gear(gs)
    rb = g.base_radius_m
    radii = np.array(_spall_radii(pm))
    s_edges = _arc(rb, radii)
    s_c = _contact_arc(pm, gs, d)
    w = pm.window_m
    if not (s_edges[0] - w <= s_c <= s_edges[1] + w):
        return None
    return gs, radii, s_edges, w + float(np.max(np.abs(s_edges - s_c)))


def _candidates(pm: PairModel, d: float, j: int, spalled: tuple = NO_SPALL) -> list:
    """Candidate points of the pair in slot j at LOA position d: one dict (slave nodes,
    gaps, lever arms, directions), and a second with the two edges of a spall on the
    slot's tooth (geometry.faults) where the mating flank can reach them; empty when no
    point can reach the mating flank."""
    mid = 0.5 * (pm.mesh.path_start_m + pm.mesh.path_end_m)
    slave = 0 if d >= mid else 1
    gs = pm.pair.gear(slave)
    rb = gs.base_radius_m
    u_a = _tip_roll(gs)
    s_c = _contact_arc(pm, slave, d)
    body = pm.bodies[slave]
    r_nodes = body.flank_r[0]
    s_nodes = _arc(rb, r_nodes)
    edges = _spall_edges(pm, d, spalled)
    window = pm.window_m if edges is None else edges[3]
    sel = np.flatnonzero(np.abs(s_nodes - s_c) <= window)
    g1, g2, _ = _frames(pm, d)
    gam = (g1, g2)
    master = 1 - slave
    out = []
    if sel.size:
        R = r_nodes[sel]
        gap, rF, n_loc, e_fix, w, ok = _lever_arms(pm, slave, R, d, spalled)
        if edges is not None:
            # the edge points replace the flank nodes at them (two candidates at one point
            # would make C singular): nodes within h_c / 4 of an edge on the spalled flank
            ge, _, s_e, _ = edges
            s_pit = _arc(rb, R) if ge == slave else _arc(pm.pair.gear(ge).base_radius_m, rF)
            ok &= np.min(np.abs(s_pit[:, None] - s_e[None, :]), axis=1) > 0.25 * pm.sizes.contact_m
        if ok.any():
            sel, R, gap, rF, n_loc, e_fix, w = (x[ok] for x in (sel, R, gap, rF, n_loc, e_fix, w))
            # rigid gap of the pair: dense sampling of the slave flank over the window
            u_lo = math.sqrt(max(2 * (s_c - window) / rb, 0.0))
            u_hi = math.sqrt(2 * min(s_c + window, rb * u_a ** 2 / 2) / rb)
            Rd = rb * np.sqrt(1.0 + np.linspace(u_lo, u_hi, DENSE_GAP_POINTS) ** 2)
            gd, _, _, _, wd, _ = _lever_arms(pm, slave, Rd, d, spalled)
            with np.errstate(invalid="ignore"):
                g_pair = float(np.nanmin(np.where(np.isfinite(gd) & (wd > 0), gd / wd, np.inf)))
            # directions in each body's tooth frame: +e on the slave node, -e on the master foot
            out.append({"slave": slave, "nodes": sel, "R": R, "rF": rF, "gap": gap, "w": w, "g_pair": g_pair,
                        "dirs": {slave: e_fix @ rot(-gam[slave]).T, master: -n_loc}, "j": j, "d": d,
                        "teeth": (-j, j)})
    if edges is not None:
        ge, Re, _, _ = edges
        gap, rF, n_loc, e_fix, w, ok = _lever_arms(pm, ge, Re, d)  # the edge itself is not in the pit
        ok &= w > 0
        if ok.any():
            Re, gap, rF, n_loc, e_fix, w = (x[ok] for x in (Re, gap, rF, n_loc, e_fix, w))
            out.append({"slave": ge, "nodes": None, "R": Re, "rF": rF, "gap": gap, "w": w,
                        "g_pair": float(np.min(gap / w)), "dirs": {ge: e_fix @ rot(-gam[ge]).T, 1 - ge: -n_loc},
                        "j": j, "d": d, "teeth": (-j, j), "corner": True})
    return out


def _reps(body: GearBody, c: dict, gi: int, delta_tooth: int, at_nodes: bool = True):
    """(positions (n, 6), coefficients (n, 6)) of the candidates of c on body gi,
    read or loaded on the body's tooth ``delta_tooth`` (relative to the load tooth).
    Slave points on the load tooth are its nodes (``at_nodes``, the healthy body whose
    tooth 0 they were taken from); otherwise P2 edge weights at the point's radius."""
    z = body.gear.teeth
    ang = 2.0 * math.pi * delta_tooth / z
    dirs = c["dirs"][gi] @ rot(ang).T
    if at_nodes and gi == c["slave"] and delta_tooth == 0 and c["nodes"] is not None:
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


def _reps_memo(body: GearBody, cands: list, gi: int, cracked_tooth: int | None) -> Callable[[int, int], tuple]:
    """rep(k, dt): _reps of candidate k on body gi, each computed once. Healthy body
    (``cracked_tooth`` None): read dt teeth from the load tooth; cracked body: on the
    candidate's own tooth relative to the cracked one, whatever dt."""
    memo: dict = {}

    def rep(k: int, dt: int) -> tuple:
        key = (k, dt) if cracked_tooth is None else k
        if key not in memo:
            c = cands[k]
            memo[key] = (_reps(body, c, gi, dt) if cracked_tooth is None
                         else _reps(body, c, gi, c["teeth"][gi] - cracked_tooth, at_nodes=False))
        return memo[key]

    return rep


def _body_reps(pm: PairModel, cands: list, cracked: tuple):
    """(gear index, body, rep) per gear: the cracked body where ``cracked[gi]`` names its
    cracked tooth, else the healthy one, with :func:`_reps_memo` of the candidates on it."""
    for gi, body in enumerate(pm.bodies):
        ct = cracked[gi]
        if ct is not None:
            body = pm.cracked[gi]
        yield gi, body, _reps_memo(body, cands, gi, None if ct is None else ct[0])


def _flexibility(pm: PairModel, cands: list, cracked: tuple = (None, None)) -> np.ndarray:
    """C (n, n) of all candidates: sum over both bodies of a_i^T G a_j. On a healthy body
    the read is on tooth t_i - t_j relative to the load (rotational periodicity); on a
    cracked body (``cracked[gi]``: the body tooth of the cracked slot) each candidate sits
    on its own tooth relative to the cracked one, and G is read there directly."""
    sizes = [len(c["R"]) for c in cands]
    off = np.concatenate([[0], np.cumsum(sizes)])
    C = np.zeros((off[-1], off[-1]))
    for gi, body, rep in _body_reps(pm, cands, cracked):
        for a, ca in enumerate(cands):
            for b, cb in enumerate(cands):
                ia, wa = rep(a, ca["teeth"][gi] - cb["teeth"][gi])
                ib, wb = rep(b, 0)
                Gs = body.G[np.ix_(ia.ravel(), ib.ravel())].reshape(ia.shape[0], 6, ib.shape[0], 6)
                C[off[a]:off[a + 1], off[b]:off[b + 1]] += np.einsum("ia,iajb,jb->ij", wa, Gs, wb)
    return 0.5 * (C + C.T)


def _slot_faults(pm: PairModel, period: int | None, j: int) -> tuple[tuple, bool]:
    """(spalled per gear, cracked) for slot j in mesh period ``period`` of a revolution:
    the slot holds the pair that entered period - j periods after tooth pair 0, so the
    faulty tooth of gear g is there when (period - j) mod z_g == tooth
    (geometry.faults.holds_fault). ``period`` None: the healthy mesh."""
    f = pm.faults
    if period is None or f is None:
        return NO_SPALL, False
    sp, cr = f.spall, f.crack
    spalled = tuple(sp is not None and sp.gear_index == gi and holds_fault(pm.pair, sp, period, j) for gi in (0, 1))
    return spalled, cr is not None and holds_fault(pm.pair, cr, period, j)


def blank_rotations(pm: PairModel, cands: list, cracked: tuple = (None, None)) -> tuple[tuple, tuple]:
    """((theta_ref,1, theta_ref,2), (T_1, T_2)) under the solved candidate forces: per gear
    the rotation (rad) of the blank's reference circle, theta_ref = sum h . f over the
    loads on that body (h = GearBody.blank_h[0], the circle's reading by reciprocity), and
    the loads' moment T (N m) about the gear's centre, from each force at its exact
    involute point; both counter-clockwise in the body's frame, the same sense in the
    fixed frame (and both > 0 under a driving load: the pinion's contact moment opposes
    its clockwise drive, the gear's drives it counter-clockwise). Loads are taken as in
    :func:`_flexibility` (tooth 0 of a healthy body by rotational periodicity, the
    circle's reading being the same in every tooth pitch; on a cracked body each on its
    own tooth)."""
    theta, torque = [0.0, 0.0], [0.0, 0.0]
    for gi, body, rep in _body_reps(pm, cands, cracked):
        for k, c in enumerate(cands):
            f = c["force_N"]
            X = involute_point(body.gear, c["R"] if gi == c["slave"] else c["rF"])
            fv = f[:, None] * c["dirs"][gi]
            torque[gi] += float(np.sum(X[:, 0] * fv[:, 1] - X[:, 1] * fv[:, 0]))
            if body.blank_h is not None:
                idx, coef = rep(k, 0)
                theta[gi] += float(np.sum(body.blank_h[0][idx] * coef * f[:, None]))
    return (theta[0], theta[1]), (torque[0], torque[1])


def _candidate_slots(mesh: MeshGeometry, d: np.ndarray) -> np.ndarray:
    """Slots whose pair can touch: within EXTENSION_PITCHES p_b of the path of contact."""
    ext = EXTENSION_PITCHES * mesh.base_pitch_m
    return (d >= mesh.path_start_m - ext) & (d <= mesh.path_end_m + ext)


def solve_position(pm: PairModel, theta: float, total_N: float, period: int | None = None) -> PositionSolution:
    """Resolved contact at pinion angle theta (rad from the entry of a pair at A; any
    value, also outside one mesh period) under the torque-equivalent load total_N.
    ``period``: the mesh period of a revolution with the model's faults (which slot holds
    the faulty tooth); None: the healthy mesh."""
    j, d = pm.mesh.slots(theta)
    cands, slots = [], []
    cracked: list = [None, None]
    for k in np.flatnonzero(_candidate_slots(pm.mesh, d)):
        spalled, crack_here = _slot_faults(pm, period, int(j[k]))
        if crack_here:
            assert pm.faults is not None and pm.faults.crack is not None
            gc = pm.faults.crack.gear_index
            cracked[gc] = ((-int(j[k]), int(j[k]))[gc], float(d[k]))
        for c in _candidates(pm, float(d[k]), int(j[k]), spalled):
            cands.append(c)
            slots.append(k)
    if not cands:
        raise RuntimeError(f"no tooth pair can touch at theta = {theta!r} rad")
    C = _flexibility(pm, cands, tuple(cracked))
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
        loads[k] += qc.sum()
        gaps[k] = min(gaps[k], c["g_pair"])
        on = np.flatnonzero(qc > 0)
        if on.size and not c.get("corner"):
            rb = pm.pair.gear(c["slave"]).base_radius_m
            s = _arc(rb, c["R"])
            ds = np.diff(s).mean() if len(s) > 1 else 0.0
            hw[k] = 0.5 * (s[on].max() - s[on].min() + ds)
            c["window_hit"] = bool(on[0] == 0 and s[0] > s.min() - 1) and (on[0] == 0 or on[-1] == n - 1)
        off += n
    rot_ref, torque = blank_rotations(pm, cands, tuple(cracked))
    return PositionSolution(float(theta), d, np.asarray(slots), loads, float(sol.approach_m), gaps, hw, cands,
                            C, g, w, tuple(cracked), rot_ref, torque)


# ---------------------------------------------------------------------------
# the cycle
# ---------------------------------------------------------------------------


def _position_row(pm: PairModel, theta: float, total_N: float, period: int | None) -> tuple:
    """One position of the cycle: (slot loads, slot gaps, slot half-widths, STE, tangent
    stiffness, candidates, window hits, geometry wall s, tangent LCP wall s, blank
    rotations (2,), blank moments (2,))."""
    ta = time.perf_counter()
    ps = solve_position(pm, theta, total_N, period)
    tb = time.perf_counter()
    eps = 1e-3
    Cw, gw = ps.C / np.outer(ps.w, ps.w), ps.g / ps.w
    dp = solve_contact(Cw, gw, total_force_N=total_N * (1 + eps)).approach_m
    dm = solve_contact(Cw, gw, total_force_N=total_N * (1 - eps)).approach_m
    ktan = 2 * eps * total_N / (dp - dm)
    hits = sum(bool(c.get("window_hit")) for c in ps.cand)
    return (ps.loads_N, ps.gaps_m, ps.half_width_m, ps.ste_m, ktan, len(ps.g), hits, tb - ta,
            time.perf_counter() - tb, np.array(ps.blank_rotation_rad), np.array(ps.blank_torque_Nm))


def _solve_chunk(spec: dict, items: list, total_N: float) -> list:
    """Worker task: the rows of the positions ``items`` ((theta, period) each). The
    model is rebuilt from its arguments; the in-process body cache makes each worker
    process build a body once."""
    pm = pair_model(**spec)
    return [_position_row(pm, th, total_N, n) for th, n in items]


def _body_meta(pm: PairModel) -> dict:
    """Sizes of the bodies (meta of the result)."""
    gc, cb = next(((gi, b) for gi, b in enumerate(pm.cracked) if b is not None), (None, None))
    return {"shared_body": pm.bodies[0] is pm.bodies[1], "n_elements": [bd.n_elements for bd in pm.bodies],
            "ndofs": [bd.ndofs for bd in pm.bodies], "condensed_dofs": [int(bd.G.shape[0]) for bd in pm.bodies],
            "cracked_body": None if cb is None else
            {"gear": gc, "n_elements": cb.n_elements, "ndofs": cb.ndofs,
             "condensed_dofs": int(cb.G.shape[0]), "refined_neighbours": cb.refined,
             "crack_tip_size_m": cb.crack_tip_size_m}}


def _model_task(spec: dict, total_N: float, extended: bool) -> tuple:
    """Worker task: (extended-contact widths or None, body sizes, body-build timings)."""
    pm = pair_model(**spec)
    return (extended_contact_widths(pm, total_N) if extended else None), _body_meta(pm), dict(pm.timings)


def pair_contact(pair: PairSpec, wear: WearSpec | None = None, positions: int = 24, torque_Nm: float = 40.0,
                 clearance_m: float = 0.0, contact_scale: float = 1.0, mesh_scale: float = 1.0,
                 plane: str = "stress", extended: bool = True, flank: FlankSpec | None = None,
                 faults: FaultSpec | None = None, executor: Executor | None = None,
                 chunk_positions: int = 12, progress: Callable[[int, int], None] | None = None) -> PairFE:
    """FE static transmission error and mesh stiffness at ``positions`` pinion angles
    theta = i (2 pi / z1) / positions (theta = 0 when a pair enters at A), over one
    mesh period, or with ``faults`` over one revolution of the faulty gear
    (geometry.faults.revolution_periods mesh periods, ``positions`` each).

    The centre distance follows from the bearing clearance as in analytic.tvms (rigid
    bearings). ``contact_scale`` multiplies the contact element size h_c (the
    h-refinement of the contact zone), ``mesh_scale`` the other sizes. ``extended``:
    also locate where loaded corner contact begins and ends (bisection, meta
    "extended_contact_deg", on the healthy mesh). With faults only the positions where
    a faulty tooth is a candidate pair are solved again; every other position repeats
    the healthy period exactly (rotational periodicity; meta "positions_solved").
    ``executor``: any concurrent.futures.Executor (e.g. a ProcessPoolExecutor, or a Dask
    ``Client.get_executor()``); the positions go to it in chunks of
    ``chunk_positions``, each worker process building the bodies once, and the result is
    the same to the bit as the serial one. ``progress(done, total)`` is called as the
    positions are solved. See the module docstring for the method."""
    t_start = time.perf_counter()
    if isinstance(positions, bool) or not isinstance(positions, (int, np.integer)) or positions < 2:
        raise fail("positions", positions, "", "must be a whole number >= 2")
    faults = None if faults is None or faults.is_empty else faults
    F = torque_Nm / pair.gear(0).base_radius_m
    spec = _model_spec(pair, wear, torque_Nm, clearance_m, contact_scale, mesh_scale, plane, flank, faults)
    pm: PairModel | None = None
    if executor is None:
        pm = pair_model(**spec)
        mesh = pm.mesh
        sizes, a_ref, window = pm.sizes, pm.a_ref_m, pm.window_m
    else:  # the bodies are built in the workers; here only the inputs and the geometry
        mesh = _check_inputs(pair, torque_Nm, clearance_m, plane, faults).mesh
        sizes, a_ref, window = _sizes(pair, torque_Nm, contact_scale, mesh_scale)
    t_model = time.perf_counter()
    theta0 = np.arange(positions) * (mesh.mesh_angle_rad / positions)
    j, d0 = mesh.slots(theta0)
    periods = revolution_periods(pair, faults)
    # a position is solved again where a slot holding a faulty tooth is a candidate
    cand = np.tile(_candidate_slots(mesh, d0), (periods, 1))
    faulty = np.zeros(cand.shape, dtype=bool)
    for f in (faults.faults() if faults is not None else []):
        faulty |= np.repeat(faulty_slots(pair, f, periods, j), positions, axis=0) & cand
    redo = np.flatnonzero(faulty.any(axis=1))
    items = [(float(th), None) for th in theta0] + [(float(theta0[r % positions]), int(r // positions)) for r in redo]
    tell = progress or (lambda done, total: None)
    tell(0, len(items))
    rows: list = []
    if executor is None:
        assert pm is not None
        for th, n in items:
            rows.append(_position_row(pm, th, F, n))
            tell(len(rows), len(items))
        t_cycle = time.perf_counter()
        widths = extended_contact_widths(pm, F) if extended else None
        body_meta, body_tim = _body_meta(pm), {k: v for k, v in pm.timings.items() if k != "model_s"}
    else:
        step = max(1, int(chunk_positions))
        futures = [executor.submit(_solve_chunk, spec, items[i:i + step], F) for i in range(0, len(items), step)]
        model_future = executor.submit(_model_task, spec, F, extended)
        for fu in futures:
            rows += fu.result()
            tell(len(rows), len(items))
        t_cycle = time.perf_counter()
        widths, body_meta, worker_tim = model_future.result()
        body_tim = {k: v for k, v in worker_tim.items() if k != "model_s"}
    t_end = time.perf_counter()
    # the healthy period, then (with faults) the revolution with its faulty rows replaced
    columns = (0, 1, 2, 3, 4, 9, 10)
    cols = [np.array([r[i] for r in rows[:positions]]) for i in columns]
    loads, gaps, hw, ste, ktan, rot_ref, torque = (np.tile(c, (periods, 1)) if c.ndim == 2 else np.tile(c, periods)
                                                   for c in cols)
    for r, row in zip(redo, rows[positions:]):
        loads[r], gaps[r], hw[r], ste[r], ktan[r], rot_ref[r], torque[r] = (row[i] for i in columns)
    n_cand = [r[5] for r in rows]
    k, exc = _secant(loads, gaps, ste)
    # the blanks' torsion below r_ref taken out: delta_mesh = delta - r_b1 theta_1 - r_b2 theta_2
    rb = np.array([g.base_radius_m for g in pair.gears])
    blank_ste = rot_ref @ rb
    ste_mesh = ste - blank_ste
    k_mesh, exc_mesh = _secant(loads, gaps, ste_mesh)
    # theta_i is linear in the load (linear elasticity, n = 0 part: theta_i = T_i / k_blank,i), so
    # the blanks are a constant compliance in series also for the tangent dF / d delta
    ktan_mesh = 1.0 / (1.0 / ktan - blank_ste / F)
    k_blank = [float(torque[:, i].sum() / rot_ref[:, i].sum()) if np.any(rot_ref[:, i] != 0) else math.inf
               for i in (0, 1)]
    theta = np.arange(positions * periods) * (mesh.mesh_angle_rad / positions)
    timings = {**body_tim, "model_s": t_model - t_start, "positions_s": t_cycle - t_model,
               "positions_geometry_s": float(sum(r[7] for r in rows)),
               "positions_lcp_s": float(sum(r[8] for r in rows)),
               "extended_s": t_end - t_cycle, "total_s": time.perf_counter() - t_start}
    meta = {"sizes_m": {k2: getattr(sizes, k2) for k2 in ("contact_m", "near_m", "far_m", "fillet_m", "global_m")},
            "a_ref_m": a_ref, "window_m": window, "contact_scale": contact_scale,
            "mesh_scale": mesh_scale, "plane": plane, "order": 2, **body_meta, "clearance_m": clearance_m,
            "candidates_per_position": [int(min(n_cand)), int(max(n_cand))],
            "window_hits": int(sum(r[6] for r in rows)), "corner_contact": True, "local_contact": "resolved",
            "pair_gap_m": gaps, "extended_contact_deg": widths, "mesh_periods": periods,
            "positions_solved": len(items), "positions_total": positions * periods,
            "faults": None if faults is None else faults.label(),
            "blank_reference_radius_m": [float(bd_r) for bd_r in _reference_radii(pair)],
            "blank_torsional_stiffness_Nm_per_rad": k_blank,
            "mesh_only_mean_N_per_m": float(np.mean(k_mesh))}
    return PairFE(pair, mesh, torque_Nm, wear, theta, k, ktan, ste, exc, loads, np.tile(d0, (periods, 1)),
                  np.tile(mesh.in_path(d0), (periods, 1)), hw, timings, meta, faults, periods,
                  faulty if faults is not None else None, k_mesh, ktan_mesh, ste_mesh, exc_mesh, rot_ref, torque)


def _secant(loads: np.ndarray, gaps: np.ndarray, ste: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, e) per position, as analytic.tvms: k = sum over loaded pairs F_k / (ste - g_k)
    and e = sum k_k g_k / k, so F = k (ste - e) (N/m, m)."""
    on = loads > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        g_on = np.where(on, gaps, 0.0)
        k_pair = np.where(on, loads / np.maximum(ste[:, None] - g_on, 1e-300), 0.0)
    k = k_pair.sum(axis=1)
    return k, np.where(k > 0, (k_pair * g_on).sum(axis=1) / k, 0.0)


def _reference_radii(pair: PairSpec) -> tuple[float, float]:
    """r_ref (m) of both blanks (pair_body.blank_reference_radius_m)."""
    return blank_reference_radius_m(pair.gear(0)), blank_reference_radius_m(pair.gear(1))


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
# centre-line readings in single contact and the local approach c_local (compared with
# the single-tooth FE and Weber's formula by gearwear.compare.pair_consistency)
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
    the pair load, and c_local = delta / F - c_1 - c_2 (m/N). At a position the cracked
    body served, the cracked gear's reading is on its cracked tooth (which must then be
    the loaded one)."""
    loaded = [c for c, k in zip(ps.cand, ps.slots) if ps.loads_N[k] > 0]
    if len({c["j"] for c in loaded}) != 1:
        raise ValueError("centre_line_compliance needs exactly one loaded pair")
    F = float(ps.loads_N.sum())
    d = loaded[0]["d"]
    L = pm.mesh.line_of_action_m
    out = {"d_m": d}
    for gi, body in enumerate(pm.bodies):
        g = pm.pair.gear(gi)
        R = math.hypot(g.base_radius_m, d if gi == 0 else L - d)
        prof = tooth_profile(g)
        lp = load_points(prof, np.array([R]))
        e = -np.array([math.cos(lp.w_rad[0]), math.sin(lp.w_rad[0])])
        ct = ps.cracked[gi]
        if ct is not None and ct[0] != loaded[0]["teeth"][gi]:
            raise ValueError("centre_line_compliance: the loaded pair is not on the cracked tooth")
        body = body if ct is None else pm.cracked[gi]
        qb, qw = _probe_rep(body, np.array([0.0, lp.y_axis_m[0]]))
        rows = np.concatenate([qb, qb + 1])
        coef = np.concatenate([qw * e[0], qw * e[1]])
        u = 0.0
        for c in loaded:  # the pair's flank nodes, and a spall's edges
            ia, wa = _reps(body, c, gi, 0, at_nodes=ct is None)
            Gs = body.G[np.ix_(rows, ia.ravel())].reshape(len(rows), ia.shape[0], 6)
            u += float(np.einsum("r,rjb,jb,j->", coef, Gs, wa, c["force_N"]))
        out[f"c{gi + 1}_m_per_N"] = u / F
        out[f"R{gi + 1}_m"] = R
        out[f"h{gi + 1}_m"] = float(lp.x_m[0] / math.cos(lp.w_rad[0]))
    out["c_pair_m_per_N"] = ps.ste_m / F
    out["c_local_m_per_N"] = ps.ste_m / F - out["c1_m_per_N"] - out["c2_m_per_N"]
    out["load_N"] = F
    out["R_star_m"] = d * (L - d) / L
    return out


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


def write_fields(pm: PairModel, positions: list[int], points: int, torque_Nm: float, out_dir) -> list:
    """Displacement and stress fields of both gears at the given position indices i of a
    curve with ``points`` positions per mesh period (theta = i 2 pi / (z1 points); with the
    model's faults i runs over the revolution, and period i // points says which slot holds
    the faulty tooth) as ``fields_pos<i>.vtu`` (meshio, P2 triangles in the fixed frame of
    the module docstring; point data displacement_m, cell data sigma_xx/yy/xy_Pa,
    von_mises_Pa, gear). The loaded tooth with the largest load is each body's refined
    tooth 0; the other loaded teeth take their load on their own (coarser) flanks. Where
    the cracked body served, it is drawn with its cracked tooth as tooth 0."""
    import meshio
    import scipy.sparse.linalg as spla
    from pathlib import Path

    from gearwear.core.atomic import atomic_write

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    F = torque_Nm / pm.pair.gear(0).base_radius_m
    total = points * revolution_periods(pm.pair, pm.faults)
    files = []
    for i in positions:
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < total:
            raise fail("fields", i, "", f"must be a position index in [0, {total - 1}]")
        theta = (i % points) * pm.mesh.mesh_angle_rad / points
        ps = solve_position(pm, theta, F, None if pm.faults is None else int(i // points))
        ref = max(ps.cand, key=lambda c: float(c["force_N"].sum()))
        _, _, O2 = _frames(pm, ref["d"])
        pts, cells, disp, cdata, gear_id = [], [], [], [], []
        offset = 0
        for gi, body in enumerate(pm.bodies):
            ct = ps.cracked[gi]
            tooth0, d0 = (ref["teeth"][gi], ref["d"]) if ct is None else ct
            body = body if ct is None else pm.cracked[gi]
            model = body.model
            if getattr(body, "_lu", None) is None:
                Kff = model.K[model.free][:, model.free].tocsc()
                body._lu = spla.splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                     options={"SymmetricMode": True})
            f = np.zeros(model.ndofs)
            for c in ps.cand:
                idx, coef = _reps(body, c, gi, c["teeth"][gi] - tooth0, at_nodes=ct is None)
                np.add.at(f, body.dofs[idx], coef * c["force_N"][:, None])
            U = np.zeros(model.ndofs)
            U[model.free] = body._lu.solve(f[model.free])
            S = _stress(body, U, pm.pair.materials[gi])
            Rm = rot(_frames(pm, d0)[gi])
            loc = model.basis.doflocs[:, 0::2].T
            p = loc @ Rm.T + (0.0 if gi == 0 else O2)
            u = U.reshape(-1, 2) @ Rm.T
            # stress tensor to the fixed frame: R sigma R^T
            sig = np.stack([np.stack([S[:, 0], S[:, 2]], -1), np.stack([S[:, 2], S[:, 1]], -1)], -2)
            sig = Rm @ sig @ Rm.T
            sxx, syy, sxy = sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1]
            szz = (pm.pair.materials[gi].poisson_ratio * (sxx + syy)) if pm.plane == "strain" else 0.0 * sxx
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
