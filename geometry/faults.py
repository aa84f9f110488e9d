"""Faults on one tooth: a root crack and a spall (pit), and which tooth pair is where.

A fault on one tooth makes the mesh periodic over one revolution of its gear, not over
one mesh period. Numbering: tooth 0 of each gear is the one of the pair that enters
contact at A at pinion angle theta = 0; teeth count in meshing order, so the pair that
entered m mesh periods after it has pinion tooth m mod z_1 and gear tooth m mod z_2.
A curve over ``periods`` mesh periods (row block n = 0 .. periods - 1 of one mesh
period each) holds in slot j (geometry.kinematics.MeshGeometry.slots: the pair that
entered j periods before) the pair m = n - j. With faults on one gear the curve spans
z of that gear; on both, lcm(z_1, z_2) mesh periods.

Spall (2D: through the whole face width, assumed; the issue's keys give no width). The
flank of the faulty tooth is removed to ``depth_m`` between the start radius and the
point ``length_m`` further along the involute (arc length s = r_b u^2 / 2 from the base
circle, u the roll angle). A mating flank whose contact point lies inside the spall
does not reach its bottom when the spall is short: the two surfaces separate as
x^2 / (2 R') at a distance x from the contact point (R' = rho_1 rho_2 / (rho_1 + rho_2)
the relative radius of curvature, rho = the involute radii, d and T1T2 - d), so the
mating flank bridges the pit on its edges. The initial gap of the pair is then

    g_spall(d) = min(depth, min(x_a, x_b)^2 / (2 R'(d)))

with x_a, x_b the arc lengths from the contact point to the spall's edges (zero at the
edges, so the gap is continuous). This is the kinematic part of the classic spall
models (e.g. Chaari, Baccar, Abbes, Haddar 2008, Eur. J. Mech. A/Solids 27:691-705,
who remove the spalled width from the contact): here the whole width is lost and the
load moves to the edges and to the neighbouring pairs. The tooth body compliance is
unchanged (a pit of tens of um).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearwear.core.validation import Field, fail_range

from .kinematics import MeshGeometry
from .spec import PairSpec

#: deepest accepted spall (m): deeper pits are tooth breakage, not a surface fault
MAX_SPALL_DEPTH_M = 1e-3


@dataclass(frozen=True)
class Spall:
    """A through-width spall on one tooth of one gear (SI): from ``start_diameter_m``
    along the involute toward the tip for ``length_m`` of arc length, ``depth_m`` deep."""

    gear_index: int
    tooth: int
    start_diameter_m: float
    length_m: float
    depth_m: float

    def roll_range(self, pair: PairSpec) -> tuple[float, float]:
        """(u_a, u_b): roll angles (rad) of the spall's edges on its gear's involute."""
        rb = pair.gear(self.gear_index).base_radius_m
        ua = math.sqrt(max((0.5 * self.start_diameter_m / rb) ** 2 - 1.0, 0.0))
        s_b = 0.5 * rb * ua * ua + self.length_m
        return ua, math.sqrt(2.0 * s_b / rb)

    def end_diameter_m(self, pair: PairSpec) -> float:
        rb = pair.gear(self.gear_index).base_radius_m
        return 2.0 * rb * math.hypot(1.0, self.roll_range(pair)[1])


@dataclass(frozen=True)
class CrackFault:
    """A straight root crack on one tooth (geometry.crack.Crack: depth, angle)."""

    gear_index: int
    tooth: int
    depth_m: float
    angle_rad: float

    @property
    def crack(self):
        from .crack import Crack

        return Crack(self.depth_m, self.angle_rad)


@dataclass(frozen=True)
class FaultSpec:
    crack: CrackFault | None = None
    spall: Spall | None = None

    @property
    def is_empty(self) -> bool:
        return self.crack is None and self.spall is None

    def faults(self) -> list:
        return [f for f in (self.crack, self.spall) if f is not None]

    def label(self) -> str:
        parts = []
        if self.crack is not None:
            parts.append(f"crack{self.crack.depth_m * 1e3:g}mm@g{self.crack.gear_index}t{self.crack.tooth}")
        if self.spall is not None:
            parts.append(f"spall{self.spall.depth_m * 1e6:g}um@g{self.spall.gear_index}t{self.spall.tooth}")
        return "+".join(parts) or "none"


def revolution_periods(pair: PairSpec, faults: FaultSpec | None) -> int:
    """Mesh periods after which the faulted mesh repeats: z of the faulty gear, the lcm of
    both when both gears have a fault, 1 without faults."""
    if faults is None or faults.is_empty:
        return 1
    zs = {pair.teeth[f.gear_index] for f in faults.faults()}
    return math.lcm(*zs)


def holds_fault(pair: PairSpec, fault, period, j):
    """Whether slot j of mesh period ``period`` holds the fault's tooth: the pair there
    entered period - j periods after pair 0, so (period - j) mod z_g == tooth (module
    docstring). Integers give a bool; integer arrays (broadcast) a bool mask."""
    return (period - j) % pair.teeth[fault.gear_index] == fault.tooth


def faulty_slots(pair: PairSpec, fault, periods: int, n_slots_j: np.ndarray) -> np.ndarray:
    """(periods, slots) mask: True where slot j of mesh period n holds the fault's tooth,
    holds_fault over n = 0 .. periods - 1 and the slot numbers j ``n_slots_j``."""
    return holds_fault(pair, fault, np.arange(periods)[:, None], np.asarray(n_slots_j)[None, :])


def spall_gap_m(spall: Spall, mesh: MeshGeometry, d_m) -> np.ndarray:
    """Initial gap (m) of the pair holding the spalled tooth, contact at LOA positions d
    (module docstring: depth, limited by the bridging of the mating flank)."""
    d = np.asarray(d_m, dtype=float)
    pair = mesh.pair
    g = pair.gear(spall.gear_index)
    rb = g.base_radius_m
    L = mesh.line_of_action_m
    u = (d if spall.gear_index == 0 else L - d) / rb
    ua, ub = spall.roll_range(pair)
    inside = (u > ua) & (u < ub)
    s = 0.5 * rb * u * u
    xa, xb = s - 0.5 * rb * ua * ua, 0.5 * rb * ub * ub - s
    rho1, rho2 = np.maximum(d, 1e-12), np.maximum(L - d, 1e-12)
    R_rel = rho1 * rho2 / (rho1 + rho2)
    bridge = np.minimum(xa, xb) ** 2 / (2.0 * R_rel)
    return np.where(inside, np.minimum(spall.depth_m, bridge), 0.0)


def check_faults(pair: PairSpec, faults: FaultSpec) -> None:
    """Refuse faults that do not fit the pair, naming this layer's keys (``spall.tooth``,
    ``spall.start_diameter_m``, ``spall.length_m``, ``spall.depth_m``, ``crack.tooth``;
    the app renames them): the tooth index within the gear; the spall on the active
    flank (SAP to tip) and ending below the tip; depth in (0, 1] mm."""
    for name, f in (("crack", faults.crack), ("spall", faults.spall)):
        if f is None:
            continue
        z = pair.teeth[f.gear_index]
        if not 0 <= f.tooth < z:
            raise fail_range(
                f"{name}.tooth",
                f.tooth,
                Field("", 0, z - 1, kind=int),
                f"a tooth of the {pair.gear(f.gear_index).name} ({z} teeth)",
            )
    s = faults.spall
    if s is None:
        return
    g = pair.gear(s.gear_index)
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    d_sap, d_tip = 2.0 * mesh.start_of_active_profile_m[s.gear_index], 2.0 * g.tip_radius_m
    if not (d_sap <= s.start_diameter_m < d_tip):
        raise fail_range(
            "spall.start_diameter_m",
            s.start_diameter_m,
            Field("m", d_sap, d_tip, hi_open=True),
            f"the active flank of the {g.name} (SAP to tip)",
        )
    if not (0.0 < s.depth_m <= MAX_SPALL_DEPTH_M):
        raise fail_range("spall.depth_m", s.depth_m, Field("m", 0.0, MAX_SPALL_DEPTH_M, lo_open=True))
    rb = g.base_radius_m
    ua = math.sqrt((0.5 * s.start_diameter_m / rb) ** 2 - 1.0)
    u_tip = math.sqrt((g.tip_radius_m / rb) ** 2 - 1.0)
    room = 0.5 * rb * (u_tip * u_tip - ua * ua)
    if not (0.0 < s.length_m <= room):
        raise fail_range(
            "spall.length_m",
            s.length_m,
            Field("m", 0.0, room, lo_open=True),
            f"the flank from the start diameter to the tip is {room * 1e3:.4g} mm long",
        )
