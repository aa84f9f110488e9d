"""Operating geometry from bearing clearance (paper section 2.3, Eqs. 11-16).

Clearance convention. ``clearance_m`` (BC in paper Eq. 11) is the radial internal
clearance of one bearing in the ISO 5753 sense: the total radial play of the shaft
from one extreme position to the opposite one. In the dynamic model (paper Eqs.
7-10) each bearing is then a dead zone of half-width b = BC / 2 in x and in y.
Under the static mesh force both shaft centres move into the corner of their dead
zone and deflect their bearings, so the centres separate by 2 (b + F_x / k_b) along
the centre line and shift by 2 (b + F_y / k_b) across it; with 2 b = BC this is Eq. 11:

    C' = sqrt((C + 2 F_x / k_b + BC)^2 + (2 F_y / k_b + BC)^2)

F_x = F_n sin(alpha') (separating) and F_y = F_n cos(alpha') (tangential) are the
components of the static normal mesh force F_n = T_p / r_b1. Because alpha' depends
on C', the two are iterated to a fixed point (the paper uses the nominal alpha; the
difference is below 1e-6 um here). With no torque (or infinite bearing stiffness)
only the clearance moves the centres, and zero clearance gives the nominal geometry
exactly.

Backlash. The total normal backlash (along the line of action) at centre distance
C' is (the base-circle space widths left over by both teeth along the line of action,
ISO 21771; docs/models.md, "Backlash (Eqs. 13-15)")

    j_n = j_n0 + 2 (r_b1 + r_b2) (inv(alpha') - inv(alpha_w))          ("consistent")

where r_b1 + r_b2 = C_w cos(alpha_w) and alpha_w is the zero-backlash working
pressure angle (= alpha without profile shift). This equals paper Eq. 13,
(2 pi r_w1 / z_1 - s_w1 - s_w2) cos(alpha') + b_0, with s_w the thicknesses on the
operating pitch circles. The printed Eq. 15 has C' in place of C,
j_n = j_n0 + 2 C' cos(alpha) (inv(alpha') - inv(alpha)) ("printed"); it overstates the
change by the factor C'/C. In the dynamic model the backlash dead zone has half-width
j_n / 2 (paper Eq. 20 with b = j_n / 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gearwear.core.validation import Field, check_scalar, fail

from .kinematics import MeshGeometry
from .spec import PairSpec, inv

BACKLASH_FORMS = ("consistent", "printed")


@dataclass(frozen=True)
class OperatingGeometry:
    """Centre distance, pressure angle, backlash and contact path at a clearance."""

    pair: PairSpec
    clearance_m: float
    torque_Nm: float
    bearing_stiffness_N_per_m: float
    initial_backlash_m: float
    backlash_form: str
    mesh: MeshGeometry

    @property
    def centre_distance_m(self) -> float:
        return self.mesh.centre_distance_m

    @property
    def pressure_angle_rad(self) -> float:
        return self.mesh.pressure_angle_rad

    @property
    def contact_ratio(self) -> float:
        return self.mesh.contact_ratio

    @property
    def contact_line_length_m(self) -> float:
        return self.mesh.path_length_m

    @property
    def backlash_m(self) -> float:
        """Total normal backlash j_n (m), Eq. 13/15 in the chosen form."""
        return backlash(self.pair, self.centre_distance_m, self.initial_backlash_m, self.backlash_form)


def centre_distance(
    pair: PairSpec, clearance_m: float = 0.0, torque_Nm: float = 0.0, bearing_stiffness_N_per_m: float = math.inf
) -> float:
    """Operating centre distance C' (m) from paper Eq. 11, iterated on alpha'."""
    check_scalar("clearance_um", clearance_m * 1e6, Field("um", 0, 1e4))
    check_scalar("torque_Nm", torque_Nm, Field("N m", 0, 1e7))
    if not bearing_stiffness_N_per_m > 0:
        raise fail("bearing_stiffness_N_per_m", bearing_stiffness_N_per_m, "N/m", "must be in (0, inf] N/m")
    C = pair.centre_distance_m
    rb_sum = sum(g.base_radius_m for g in pair.gears)
    Fn = torque_Nm / pair.gear(0).base_radius_m
    compliance = 0.0 if math.isinf(bearing_stiffness_N_per_m) else 2.0 / bearing_stiffness_N_per_m
    Cp = C
    for _ in range(50):
        a = math.acos(min(1.0, rb_sum / Cp))
        Fx, Fy = Fn * math.sin(a), Fn * math.cos(a)
        new = math.hypot(C + compliance * Fx + clearance_m, compliance * Fy + clearance_m)
        if abs(new - Cp) <= 1e-15 * C:
            Cp = new
            break
        Cp = new
    return Cp


def max_clearance_m(pair: PairSpec) -> float:
    """The bearing clearance BC (m) at which the unloaded centre distance of Eq. 11,
    C' = sqrt((C + BC)^2 + BC^2), reaches a_max, where the tip circles stop overlapping on the
    line of action (sqrt(a_max^2 - (r_b1 + r_b2)^2) = sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 -
    r_b2^2)): BC = (sqrt(2 a_max^2 - C^2) - C) / 2. A larger clearance puts the gears out of mesh."""
    gears = pair.gears
    reach = sum(math.sqrt(max(g.tip_radius_m**2 - g.base_radius_m**2, 0.0)) for g in gears)
    a_max = math.hypot(reach, sum(g.base_radius_m for g in gears))
    C = pair.centre_distance_m
    return 0.5 * (math.sqrt(2.0 * a_max**2 - C**2) - C)


def backlash(
    pair: PairSpec, centre_distance_m: float, initial_backlash_m: float = 0.0, form: str = "consistent"
) -> float:
    """Total normal backlash (m) at centre distance C' (paper Eqs. 13-15, see module doc)."""
    if form not in BACKLASH_FORMS:
        raise fail("backlash form", repr(form), "", f"must be one of {', '.join(BACKLASH_FORMS)}")
    rb_sum = sum(g.base_radius_m for g in pair.gears)
    a_w = pair.working_pressure_angle_rad
    # at a_w itself the backlash is exactly j_n0 (acos of the rounded ratio would leave ~1e-13 m)
    a_op = a_w if centre_distance_m == pair.zero_backlash_centre_distance_m else math.acos(rb_sum / centre_distance_m)
    if form == "consistent":
        return initial_backlash_m + 2.0 * rb_sum * (inv(a_op) - inv(a_w))
    return initial_backlash_m + 2.0 * centre_distance_m * math.cos(a_w) * (inv(a_op) - inv(a_w))


def operating_geometry(
    pair: PairSpec,
    clearance_m: float = 0.0,
    torque_Nm: float = 0.0,
    bearing_stiffness_N_per_m: float = math.inf,
    initial_backlash_m: float = 0.0,
    backlash_form: str = "consistent",
) -> OperatingGeometry:
    """All operating quantities of paper Fig. 15 at one bearing clearance."""
    check_scalar("initial_backlash_um", initial_backlash_m * 1e6, Field("um", 0, 1e4))
    if backlash_form not in BACKLASH_FORMS:
        raise fail("backlash_form", repr(backlash_form), "", f"must be one of {', '.join(BACKLASH_FORMS)}")
    Cp = centre_distance(pair, clearance_m, torque_Nm, bearing_stiffness_N_per_m)
    return OperatingGeometry(
        pair,
        clearance_m,
        torque_Nm,
        bearing_stiffness_N_per_m,
        initial_backlash_m,
        backlash_form,
        MeshGeometry(pair, Cp),
    )
