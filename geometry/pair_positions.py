"""Pair positions: where the teeth of a spur pair stand, and which of them can touch, as
the pinion turns (exact involute geometry and kinematics, no elasticity; SI units: m, rad).

Used by the resolved pair FE (fem.pair) to place its bodies and to find its contact
candidates; every function here is pure and works on arrays.

Tooth frame of a gear. Tooth 0 is centred on +y, its drive (right) flank at x > 0 is the
involute (geometry.profile)

    R = r_b sqrt(1 + u^2),   beta = psi_b - (u - atan u),   point (R sin beta, R cos beta)

with u the roll angle (rad) and psi_b = s / (2 r) + inv(alpha) the half angular thickness
on the base circle. The arc length of the involute from the base circle is
s = r_b u^2 / 2 (m).

Fixed frame of the pair (mesh at operating centre distance, geometry.kinematics). Pinion
centre O1 = 0, its base-circle tangency point T1 = (0, r_b1), line of action (LOA) along
+x to T2 = (L, r_b1), gear centre O2 = (L, r_b1 + r_b2), L = |T1 T2|. A tooth pair at LOA
position d (the slots of MeshGeometry.slots, shared with analytic.tvms) is placed rigidly
so that both nominal flanks pass through (d, r_b1): the pinion tooth frame is turned by

    gamma_1 = psi_b1 - d / r_b1 - dtheta,   gamma_2 = psi_b2 - (L - d) / r_b2 - pi

(dtheta: an extra turn of the pinion, the driven gear held). Pinion slot j sits on tooth
-j, gear slot j on tooth +j (slot j entered j mesh periods earlier); pairs one base pitch
apart are then exactly one tooth apart. A contact at d has the pinion roll d / r_b1 and
the gear roll (L - d) / r_b2.

Normal gap between involutes. Involutes of one base circle are parallel curves, so a point
Y (master tooth frame, radius r, angle beta from +y, u = sqrt(r^2 / r_b^2 - 1)) is at the
normal distance

    g = r_b (beta + u - atan u - psi_b)          (m; > 0 outside the master tooth)

from the master's nominal flank; the foot of the normal has the roll u_F = u - g / r_b,
the radius r_F = r_b sqrt(1 + u_F^2) and the outward normal (cos beta_T, -sin beta_T),
beta_T = psi_b - u_F (Litvin & Fuentes, Gear Geometry and Applied Theory, 2004, ch. 10:
the normal of an involute is tangent to its base circle).

Candidates. Besides the path of contact [A, E] a pair can carry load through its tip
corner a little before A and after E; a pair is a candidate within ``extension_pitches``
base pitches of the path.
"""

from __future__ import annotations

import math

import numpy as np

from .faults import FaultSpec, Spall, holds_fault
from .kinematics import MeshGeometry
from .spec import GearSpec, PairSpec

__all__ = [
    "NO_SPALL",
    "rot",
    "base_half_angle_rad",
    "involute_point",
    "involute_arc_m",
    "tip_roll_rad",
    "contact_arc_m",
    "tooth_frames",
    "involute_gap",
    "candidate_slots",
    "lowest_contact_radius_m",
    "fault_neighbours",
    "reach_ranges",
    "slot_faults",
    "spall_edge_radii_m",
]

#: no tooth of the slot is faulty (per gear: the slot's tooth carries the spall)
NO_SPALL = (False, False)


def rot(angle) -> np.ndarray:
    """Rotation matrices (..., 2, 2) by ``angle`` (rad, counter-clockwise)."""
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def base_half_angle_rad(g: GearSpec) -> float:
    """Half angular thickness of the tooth on the base circle (rad),
    psi_b = s / (2 r) + tan(alpha) - alpha (s: tooth thickness on the pitch circle of
    radius r, alpha the pressure angle)."""
    return g.pitch_thickness_m / (2 * g.pitch_radius_m) + math.tan(g.pressure_angle_rad) - g.pressure_angle_rad


def involute_point(g: GearSpec, radius_m) -> np.ndarray:
    """Exact points (n, 2) (m) of the nominal drive (right) flank of tooth 0 at radii
    R >= r_b: beta = psi_b - (u - atan u), u = sqrt(R^2 / r_b^2 - 1) (geometry.profile).

    psi_b is summed as s / (2 r) + (tan alpha - alpha) here, as geometry.profile does (the
    same value as :func:`base_half_angle_rad` to the last bit or two; each is kept as it
    was so the FE results stay bit-identical)."""
    R = np.asarray(radius_m, dtype=float)
    rb = g.base_radius_m
    u = np.sqrt(np.maximum((R / rb) ** 2 - 1.0, 0.0))
    psi_b = g.pitch_thickness_m / (2.0 * g.pitch_radius_m) + (math.tan(g.pressure_angle_rad) - g.pressure_angle_rad)
    beta = psi_b - (u - np.arctan(u))
    return np.stack([R * np.sin(beta), R * np.cos(beta)], -1)


def involute_arc_m(rb: float, R) -> np.ndarray:
    """Arc length (m) along the involute of base radius ``rb`` from the base circle to
    radius R: s = r_b u^2 / 2 = r_b (R^2 / r_b^2 - 1) / 2."""
    return rb * ((np.asarray(R, dtype=float) / rb) ** 2 - 1.0) / 2.0


def tip_roll_rad(g: GearSpec) -> float:
    """Roll angle u_a (rad) of gear g's tip circle, u_a = sqrt(r_a^2 / r_b^2 - 1)."""
    return math.sqrt((g.tip_radius_m / g.base_radius_m) ** 2 - 1.0)


def contact_arc_m(mesh: MeshGeometry, gi: int, d: float) -> float:
    """Arc position s_c = r_b u^2 / 2 (m) on gear gi's flank of the kinematic contact at
    LOA position d (m): u = d / r_b1 (pinion) or (L - d) / r_b2 (gear), clamped to
    [0, u_a]."""
    g = mesh.pair.gear(gi)
    rb = g.base_radius_m
    u = (d if gi == 0 else mesh.line_of_action_m - d) / rb
    return rb * min(max(u, 0.0), tip_roll_rad(g)) ** 2 / 2.0


def tooth_frames(mesh: MeshGeometry, d: float, dtheta: float = 0.0) -> tuple[float, float, np.ndarray]:
    """(gamma_1, gamma_2, O2): rotations (rad, counter-clockwise) of the pinion and gear
    tooth frames of the pair at LOA position d (m), the pinion turned on by the extra angle
    dtheta (rad), and the gear centre O2 = (L, r_b1 + r_b2) (m) in the fixed frame
    (module docstring)."""
    rb1, rb2 = (g.base_radius_m for g in mesh.pair.gears)
    L = mesh.line_of_action_m
    p1, p2 = (base_half_angle_rad(g) for g in mesh.pair.gears)
    return p1 - d / rb1 - dtheta, p2 - (L - d) / rb2 - math.pi, np.array([L, rb1 + rb2])


def involute_gap(mesh: MeshGeometry, slave: int, R: np.ndarray, d: float, dtheta: float = 0.0):
    """Normal gap of the exact points of gear ``slave``'s drive flank at radii R (m)
    against the exact involute of the mating ("master") flank, the pair at LOA position
    d (m) with the pinion turned on by dtheta (rad) (module docstring, "Normal gap").

    Returns (gap (n,) m, foot radius r_F (n,) m, master outward normal (n, 2) in the master
    tooth frame, the same in the fixed frame, off (n,) bool): ``off`` where the foot lies
    past the master's tip circle or the point inside its base circle (the point faces the
    master's corner or fillet, not its flank)."""
    g1, g2, O2 = tooth_frames(mesh, d, dtheta)
    master = 1 - slave
    gs, gm = mesh.pair.gear(slave), mesh.pair.gear(master)
    X = involute_point(gs, R)
    if slave == 0:
        Y = (X @ rot(g1).T - O2) @ rot(-g2).T
        gam_m = g2
    else:
        Y = (X @ rot(g2).T + O2) @ rot(-g1).T
        gam_m = g1
    psi_m = base_half_angle_rad(gm)
    rbm = gm.base_radius_m
    r = np.hypot(Y[:, 0], Y[:, 1])
    u = np.sqrt(np.maximum((r / rbm) ** 2 - 1.0, 0.0))
    kappa = np.arctan2(Y[:, 0], Y[:, 1]) + u - np.arctan(u)
    gap = rbm * (kappa - psi_m)
    uF = u - gap / rbm
    rF = rbm * np.sqrt(1.0 + uF * uF)
    bT = psi_m - uF
    n_loc = np.column_stack([np.cos(bT), -np.sin(bT)])
    off = (rF > gm.tip_radius_m) | (r <= rbm)
    return gap, rF, n_loc, n_loc @ rot(gam_m).T, off


def candidate_slots(mesh: MeshGeometry, d: np.ndarray, extension_pitches: float) -> np.ndarray:
    """Slots whose pair can touch: LOA positions d (m) within ``extension_pitches`` base
    pitches of the path of contact, A - e p_b <= d <= E + e p_b."""
    ext = extension_pitches * mesh.base_pitch_m
    return (d >= mesh.path_start_m - ext) & (d <= mesh.path_end_m + ext)


def lowest_contact_radius_m(mesh: MeshGeometry, gi: int, window_m: float, extension_pitches: float) -> float:
    """Lowest flank radius (m) a contact can reach on gear gi: its start of active profile
    moved ``extension_pitches`` p_b along the LOA (roll u = d / r_b, arc s = r_b u^2 / 2),
    minus ``window_m`` of arc length; not below 1.0001 r_b."""
    g = mesh.pair.gear(gi)
    rb = g.base_radius_m
    ext = extension_pitches * mesh.base_pitch_m
    d = mesh.path_start_m - ext if gi == 0 else mesh.line_of_action_m - (mesh.path_end_m + ext)
    s = rb * (max(d, 0.0) / rb) ** 2 / 2.0 - window_m
    u = math.sqrt(max(2.0 * s / rb, 0.0))
    return max(rb * math.sqrt(1.0 + u * u), rb * 1.0001)


def fault_neighbours(mesh: MeshGeometry, extension_pitches: float) -> int:
    """Teeth on either side of one tooth that can be candidates together with it: the
    candidate slots span (E - A) + 2 e p_b of the LOA (e = ``extension_pitches``), so
    floor(epsilon + 2 e) (at least 1)."""
    return max(1, int(math.floor(mesh.contact_ratio + 2 * extension_pitches + 1e-9)))


def reach_ranges(
    mesh: MeshGeometry, gi: int, refined: int, r_lo: float, margin_m: float, extension_pitches: float
) -> dict:
    """Flank radius range (r_a, r_b) (m) of each tooth t = -refined .. refined of gear gi
    that a contact can reach while tooth 0 is a candidate (within ``extension_pitches``
    p_b of the path). A pinion slot j is tooth -j and a gear slot tooth +j, so tooth t
    sits at d* - t p_b (pinion) or d* + t p_b (gear) when tooth 0 is at d*; both lie in
    [A - ext, E + ext]. The contact's arc position on the flank, s = r_b u^2 / 2, is
    widened by ``margin_m`` both ways; tooth 0's range is (r_lo, r_a,tip)."""
    g = mesh.pair.gear(gi)
    rb, r_top = g.base_radius_m, g.tip_radius_m
    L, pb = mesh.line_of_action_m, mesh.base_pitch_m
    ext = extension_pitches * pb
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


def slot_faults(pair: PairSpec, faults: FaultSpec | None, period: int | None, j: int) -> tuple[tuple, bool]:
    """(spalled per gear, cracked) for slot j in mesh period ``period`` of a revolution
    with ``faults`` (None: healthy): the slot holds the pair that
    entered period - j periods after tooth pair 0, so the faulty tooth of gear g is there
    when (period - j) mod z_g == tooth (geometry.faults.holds_fault). ``period`` None:
    the healthy mesh."""
    if period is None or faults is None:
        return NO_SPALL, False
    sp, cr = faults.spall, faults.crack
    spalled = tuple(sp is not None and sp.gear_index == gi and holds_fault(pair, sp, period, j) for gi in (0, 1))
    return spalled, cr is not None and holds_fault(pair, cr, period, j)


def spall_edge_radii_m(pair: PairSpec, spall: Spall) -> tuple[float, float]:
    """Radii (m) of a spall's edges on its flank: half its start and end diameters."""
    return 0.5 * spall.start_diameter_m, 0.5 * spall.end_diameter_m(pair)
