"""Meshing kinematics of a spur pair: line of action, path of contact, contact ratio,
and which tooth pairs touch where as the pinion turns.

Positions on the line of action (LOA) are measured as the distance ``d`` from T1,
the point where the LOA touches the pinion's base circle, toward T2 (gear base
circle); |T1 T2| = C' sin(alpha') at operating centre distance C' and operating
pressure angle alpha' (C' cos(alpha') = r_b1 + r_b2). A contact at ``d`` is at pinion
radius sqrt(r_b1^2 + d^2) (pinion roll angle d / r_b1) and at gear radius
sqrt(r_b2^2 + (T1T2 - d)^2). Contact starts at A (gear tip circle),
d_A = T1T2 - sqrt(r_a2^2 - r_b2^2), and ends at E (pinion tip circle),
d_E = sqrt(r_a1^2 - r_b1^2). Neighbouring pairs are one base pitch p_b = pi m cos(alpha)
apart, and the pinion turning by theta moves every contact by r_b1 theta.
Transverse contact ratio epsilon = (d_E - d_A) / p_b (ISO 21771 / textbook formula).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearwear.core.validation import fail

from .spec import PairSpec


@dataclass(frozen=True)
class MeshGeometry:
    """Contact geometry of ``pair`` at centre distance ``centre_distance_m``."""

    pair: PairSpec
    centre_distance_m: float

    def __post_init__(self):
        rb_sum = sum(g.base_radius_m for g in self.pair.gears)
        if not self.centre_distance_m > rb_sum:
            raise fail(
                "centre distance",
                float(self.centre_distance_m * 1e3),
                "mm",
                f"must exceed the sum of base radii {rb_sum * 1e3:.6g} mm",
            )
        if self.path_length_m <= 0.0:
            raise fail(
                "centre distance",
                float(self.centre_distance_m * 1e3),
                "mm",
                f"the tip circles no longer overlap the line of action (path of contact "
                f"{self.path_length_m * 1e3:.4g} mm <= 0); the gears are out of mesh",
            )

    # -- scalars -----------------------------------------------------------------
    @property
    def pressure_angle_rad(self) -> float:
        """Operating pressure angle alpha' = arccos((r_b1 + r_b2) / C') (paper Eq. 14)."""
        if self.centre_distance_m == self.pair.centre_distance_m:
            return self.pair.operating_pressure_angle_rad  # bit-exact nominal value
        return math.acos(sum(g.base_radius_m for g in self.pair.gears) / self.centre_distance_m)

    @property
    def base_pitch_m(self) -> float:
        return self.pair.gear(0).base_pitch_m

    @property
    def line_of_action_m(self) -> float:
        """|T1 T2| = C' sin(alpha')."""
        return self.centre_distance_m * math.sin(self.pressure_angle_rad)

    @property
    def path_start_m(self) -> float:
        """d_A: contact starts where the gear's tip circle crosses the LOA."""
        g2 = self.pair.gear(1)
        return self.line_of_action_m - math.sqrt(g2.tip_radius_m**2 - g2.base_radius_m**2)

    @property
    def path_end_m(self) -> float:
        """d_E: contact ends where the pinion's tip circle crosses the LOA."""
        g1 = self.pair.gear(0)
        return math.sqrt(g1.tip_radius_m**2 - g1.base_radius_m**2)

    @property
    def path_length_m(self) -> float:
        """Length of the path of contact g_alpha (the 'contact line length' of paper Fig. 15c)."""
        return self.path_end_m - self.path_start_m

    @property
    def contact_ratio(self) -> float:
        return self.path_length_m / self.base_pitch_m

    @property
    def pitch_point_m(self) -> float:
        """d of the operating pitch point C: T1C = r_b1 tan(alpha')."""
        return self.pair.gear(0).base_radius_m * math.tan(self.pressure_angle_rad)

    @property
    def operating_pitch_radii_m(self) -> tuple[float, float]:
        c = math.cos(self.pressure_angle_rad)
        return tuple(g.base_radius_m / c for g in self.pair.gears)  # type: ignore[return-value]

    @property
    def mesh_angle_rad(self) -> float:
        """Pinion rotation per mesh period, 2 pi / z1."""
        return 2.0 * math.pi / self.pair.teeth[0]

    @property
    def single_contact_limits_m(self) -> tuple[float, float]:
        """(d_B, d_D): lowest and highest point of single tooth contact on the LOA.

        For contact ratio >= 1: B = E - p_b, D = A + p_b. For contact ratio < 1 there
        are gaps without contact; the pair returned is (d_A, d_E)."""
        if self.contact_ratio >= 1.0:
            return (self.path_end_m - self.base_pitch_m, self.path_start_m + self.base_pitch_m)
        return (self.path_start_m, self.path_end_m)

    def pinion_radius_at(self, d) -> np.ndarray:
        return np.sqrt(self.pair.gear(0).base_radius_m ** 2 + np.asarray(d) ** 2)

    def gear_radius_at(self, d) -> np.ndarray:
        return np.sqrt(self.pair.gear(1).base_radius_m ** 2 + (self.line_of_action_m - np.asarray(d)) ** 2)

    @property
    def start_of_active_profile_m(self) -> tuple[float, float]:
        """SAP radii (pinion, gear): lowest flank point that comes into contact."""
        return (float(self.pinion_radius_at(self.path_start_m)), float(self.gear_radius_at(self.path_end_m)))

    @property
    def end_of_active_profile_m(self) -> tuple[float, float]:
        """EAP radii (pinion, gear) = tip radii."""
        return (self.pair.gear(0).tip_radius_m, self.pair.gear(1).tip_radius_m)

    # -- which tooth pairs touch where ----------------------------------------------
    def slots(self, theta_rad) -> tuple[np.ndarray, np.ndarray]:
        """Tooth-pair slots and their LOA positions at pinion angles ``theta_rad`` (rad).

        theta = 0 when a pair enters the path at A. Slot j holds the pair that entered
        j mesh periods before that one; it sits at

            d_j(theta) = d_A + r_b1 theta + j p_b

        and, since p_b = r_b1 2 pi / z1, one mesh period later the same pair is in slot
        j + 1 at the same theta. Slots j = -1 .. ceil(epsilon) + 1 reach from one pitch
        before A to beyond E for theta in [0, 2 pi / z1) (tip-corner contact outside
        the path needs the neighbours of the path too). theta is not wrapped.

        Returns (j (m,), d_m (theta.shape + (m,)))."""
        theta = np.asarray(theta_rad, dtype=float)
        j = np.arange(-1, int(math.ceil(self.contact_ratio)) + 2)
        d = self.path_start_m + self.pair.gear(0).base_radius_m * theta[..., None] + j * self.base_pitch_m
        return j, d

    def in_path(self, d_m) -> np.ndarray:
        """True where LOA positions ``d_m`` lie on the path of contact [d_A, d_E]
        (to 1e-12 p_b, so a pair exactly at A or E counts)."""
        tol = 1e-12 * self.base_pitch_m
        return (d_m >= self.path_start_m - tol) & (d_m <= self.path_end_m + tol)

    @property
    def exit_angle_rad(self) -> float:
        """theta_E in [0, 2 pi / z1): the pinion angle of a mesh period at which a pair
        leaves the path at E. Slot j is at d_A + r_b1 theta + j p_b (theta = 0: a pair
        at A), so d_E is reached at theta_E = ((d_E - d_A) mod p_b) / r_b1; below it
        floor(epsilon) + 1 pairs are on the path, above it floor(epsilon)
        (:meth:`pairs_on_path`)."""
        return math.fmod(self.path_end_m - self.path_start_m, self.base_pitch_m) / self.pair.gear(0).base_radius_m

    @property
    def double_contact_share(self) -> float:
        """Fraction of a mesh period with two pairs on the path, epsilon - 1 clipped to [0, 1]."""
        return min(max(self.contact_ratio - 1.0, 0.0), 1.0)

    def contact_zones(self, theta_rad) -> dict[str, np.ndarray]:
        """Masks over pinion angles ``theta_rad`` in [0, 2 pi / z1) of the theoretical
        zones: "A" the first and "C" the second half of the double-contact interval
        0 <= r_b1 theta <= d_E - p_b - d_A (the pair that entered at theta = 0 is at
        d = d_A + r_b1 theta, the one ahead of it p_b further), "B" single contact.
        For epsilon < 1: A and C empty, B where the entering pair is on the path."""
        d_entry = self.path_start_m + self.pair.gear(0).base_radius_m * np.asarray(theta_rad, dtype=float)
        pb = self.base_pitch_m
        double = d_entry + pb <= self.path_end_m
        if self.contact_ratio < 1:
            return {"A": np.zeros_like(double), "B": d_entry <= self.path_end_m, "C": np.zeros_like(double)}
        half = d_entry < self.path_start_m + 0.5 * (self.path_end_m - pb - self.path_start_m) + 1e-300
        return {"A": double & half, "B": ~double, "C": double & ~half}

    def contact_ratio_warnings(self) -> list[str]:
        """A one-line note when the contact ratio is below 1: for 1 - epsilon of every
        mesh period no pair is on the path (the mesh stiffness is 0 there)."""
        eps = self.contact_ratio
        if eps >= 1.0:
            return []
        return [
            f"contact ratio {eps:.3f} < 1: no pair is in contact on the path of contact for "
            f"{100 * (1 - eps):.1f} % of each mesh period (only tip-corner contact, where a model has it, "
            "carries the load there; otherwise the mesh stiffness is 0)"
        ]

    def require_overlap(self, method: str) -> None:
        """Refuse ``method`` (a stiffness model that needs a pair on the path at every
        angle) when the contact ratio is below 1. Names the parameter ``method``."""
        eps = self.contact_ratio
        if eps >= 1.0:
            return
        raise fail(
            "method",
            repr(method),
            "",
            f"needs a contact ratio >= 1 (a tooth pair on the path of contact at every angle), but it is "
            f"{eps:.3f} at centre distance {self.centre_distance_m * 1e3:.6g} mm; the analytic methods "
            "(ishikawa, energy) model the gaps",
        )

    def pairs_on_path(self, theta_rad) -> np.ndarray:
        """Theoretical number of tooth pairs on the path of contact at pinion angles
        ``theta_rad`` in [0, 2 pi / z1): the pair that entered at theta = 0 is at
        d_A + r_b1 theta and the ones ahead of it one, two, ... base pitches further, so
        n = #{j >= 0 : d_A + r_b1 theta + j p_b <= d_E} (the inequality of
        :meth:`contact_zones`: n == 2 is A | C and n == 1 is B for 1 <= epsilon < 2).
        0 in the gaps of a contact ratio below 1."""
        d_entry = self.path_start_m + self.pair.gear(0).base_radius_m * np.asarray(theta_rad, dtype=float)
        pb = self.base_pitch_m
        n = (d_entry <= self.path_end_m).astype(np.int64)
        for j in range(1, int(math.ceil(self.contact_ratio)) + 1):
            n += d_entry + (pb if j == 1 else j * pb) <= self.path_end_m
        return n

    def zone_shares(self) -> dict[int, float]:
        """Fraction of a mesh period with n pairs on the path, n -> share: with
        n0 = floor(epsilon), n0 + 1 pairs for epsilon - n0 of the period and n0 pairs for
        the rest (n0 = 0: no pair, the gap of a contact ratio below 1)."""
        eps = self.contact_ratio
        n0 = int(math.floor(eps))
        if n0 == 1:
            share = self.double_contact_share  # the same float as the double zone
            return {1: 1.0 - share, 2: share}
        frac = eps - n0
        return {n0: 1.0 - frac, n0 + 1: frac}

    def contacts(self, theta_rad) -> "Contacts":
        """Tooth pairs in contact at pinion angles ``theta_rad`` (rad).

        theta = 0 when a pair enters contact at A. Returns, per angle, up to
        ceil(epsilon) + 1 slots (those of :meth:`slots` that can be on the path, at
        theta wrapped into one mesh period); slot j is the pair that entered j mesh
        periods earlier.
        """
        theta = np.atleast_1d(np.asarray(theta_rad, dtype=float))
        cycles = np.floor(theta / self.mesh_angle_rad)
        frac = theta - cycles * self.mesh_angle_rad
        j, d = self.slots(frac)
        on = (j >= 0) & (j <= math.ceil(self.contact_ratio))
        j, d = j[on], d[:, on]
        tooth = (cycles[:, None] - j[None, :]).astype(np.int64)
        return Contacts(theta=theta, d=d, active=self.in_path(d), tooth=tooth, mesh=self)


@dataclass(frozen=True)
class Contacts:
    """Contacts at a set of pinion angles (arrays of shape (n_angles, n_slots)).

    d       position on the LOA from T1 (m)
    active  True where that slot's pair is within the path of contact
    tooth   pinion tooth index (counts the mesh periods since the pair entered;
            the gear tooth in contact has the same count, with opposite sense)
    """

    theta: np.ndarray
    d: np.ndarray
    active: np.ndarray
    tooth: np.ndarray
    mesh: MeshGeometry

    @property
    def count(self) -> np.ndarray:
        """Number of pairs in contact at each angle."""
        return self.active.sum(axis=1)

    @property
    def pinion_radius_m(self) -> np.ndarray:
        return self.mesh.pinion_radius_at(self.d)

    @property
    def gear_radius_m(self) -> np.ndarray:
        return self.mesh.gear_radius_at(self.d)

    @property
    def pinion_roll_rad(self) -> np.ndarray:
        return self.d / self.mesh.pair.gear(0).base_radius_m

    @property
    def gear_roll_rad(self) -> np.ndarray:
        return (self.mesh.line_of_action_m - self.d) / self.mesh.pair.gear(1).base_radius_m
