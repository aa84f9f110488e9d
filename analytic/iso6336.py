"""Tooth stiffness of ISO 6336-1:2019, method B (clause 9): a standard reference value.

All symbols and units follow the standard: stiffness per unit face width in
N/(mm um) (= 1e9 N/m per m of face width), module and face width in mm inside the
ISO formulas only; every input and every ``*_N_per_m`` output is SI.

Gear order. ISO 6336 (like every rating code) calls gear 1 the gear with FEWER teeth
(its "pinion"), whichever of the two drives; gear 2 has more. This project's pairs put
the driver at index 0 (``geometry.spec.PairSpec``), so every function here that takes a
pair first puts it in ISO's order (:func:`iso_ordered`: the per-gear values swapped when
the driver has more teeth; equal tooth counts keep the driver as gear 1). What follows
the order: z1, x1 and z2, x2 in q' below (and the fit range x1 >= x2), z1 and the gear-1
speed n1 in the resonance speed n_E1 and the ratio N = n1 / n_E1, and the reference
diameter d1 = m z1 with the gear-1 torque T1 = T_driver z1 / z_driver in F_t = 2 T1 / d1.
C_B, C_R, the equivalent modulus, eps_alpha and m_red do not depend on the order. A
KISSsoft report shows the order at work (``tests/test_iso6336_kisssoft.py``): in the
NREL 5 MW gearbox's first planetary stage the 19-tooth sun is KISSsoft's "gear 1", yet its
c' = 12.362 N/(mm um) is the one with the 17-tooth planet as ISO's gear 1 (the sun as
gear 1 gives 12.665, 2.4 % high).

Theoretical single stiffness (ISO 6336-1:2019, clause 9, method B; the pairs of this
project are spur gears, so the virtual tooth numbers z_n are z):

    q'    = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2
            + C8 x1^2 + C9 x2^2                                   [mm um / N]
            (index 1: the gear with fewer teeth, see "Gear order")
    c'_th = 1 / q'                                                [N / (mm um)]

    C1..C9 = 0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188,
             0.00529, 0.00182

The constants are the published ISO 6336-1 table values for q', as given in this
project's brief; they agree with the values quoted in the gear literature, but
they were not re-checked against a copy of the standard. Equation numbers are
not quoted because they differ between the 2006 and 2019 editions. With them the
stiffness below reproduces every c' and c_gamma_alpha of KISSsoft's ISO 6336:2006
reports read for this module to the printed digits (``tests/test_iso6336_kisssoft.py``).

Single stiffness of a tooth pair (ISO 6336-1:2019, clause 9):

    c' = c'_th C_M C_R C_B cos(beta)                              [N / (mm um)]

    C_M = 0.8                 theoretical-to-measured correction (solid spur gears)
    C_R = 1 + ln(b_s/b) / (5 exp(s_R / (5 m_n)))    gear blank factor; 1 for solid discs
          (per gear from its own web, the pair's C_R the mean of the two; see below)
    C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_n)]    basic rack factor
    cos(beta) = 1 (spur)

and, for materials other than steel/steel, the ISO material factor
E / E_st, E = 2 E1 E2 / (E1 + E2), E_st = 206000 N/mm^2 (1 for this project's
default steel; each gear has its own ``pair.materials[i]``). The q' fit covers
x1 >= x2 and -0.5 <= x1 + x2 <= 2; outside, :class:`IsoStiffness` flags it.

Helical gears (pure functions of numbers below; the pair model itself is spur): q' takes
the virtual tooth numbers z_n = z / (cos^2(beta_b) cos(beta)), sin(beta_b) = sin(beta)
cos(alpha_n) (ISO 21771; z / cos^3(beta) is its approximation), c' the factor cos(beta),
eps_alpha is the transverse contact ratio and the dynamic factor's C_v coefficients take the
total contact ratio eps_gamma = eps_alpha + eps_beta, eps_beta = b sin(beta) / (pi m_n).
KISSsoft's helical stage 3 of the NREL 5 MW gearbox (beta = 10 deg) prints z_n = 25.037 /
99.104 and c' = 13.832 N/(mm um): the exact z_n gives 13.832, z / cos^3(beta) 13.837.

Gear blank factor of two gears. ISO 6336-1 writes C_R with one web thickness b_s and
one rim thickness s_R (web b_s wide in the middle of the face, rim s_R deep below the
root), that is for a pair whose two blanks are alike. Here each gear has its own blank
(``pair.gear(i).web``, a ``geometry.spec.Web``, or None for a solid disc, C_R,i = 1), and
the pair takes the mean

    C_R = (C_R,1 + C_R,2) / 2

the same averaging ISO 6336-1 prescribes for the basic rack factor of two different
racks, C_B = (C_B1 + C_B2) / 2. It gives the standard's C_R when the blanks are alike. The
standard's own wording for unlike blanks could not be checked here (no copy at hand):
the KISSsoft reports reproduced in ``tests/test_iso6336_kisssoft.py`` print one b_s / b
per mesh (0.25), and both gears' inner diameters give the same s_R (3.5 m_n in the
planetary stages, 5 m_n in stage 3), so they confirm the formula, not the averaging.

At low line load (F_t K_A / b < 100 N/mm) the standard reduces c' by the factor
(F_t K_A / b / 100)^0.25 (ISO 6336-1, clause 9): the contact is not yet fully
established along the face. Mesh stiffness (mean of the total mesh stiffness over
the path of contact, ISO 6336-1:2019 clause 9):

    c_gamma_alpha = c' (0.75 eps_alpha + 0.25)                    [N / (mm um)]

Conversion to a spring of face width b: c [N/(mm um)] * b [mm] = c b N/um
= c b 1e6 N/m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from gearwear.core.validation import fail, fail_text
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import GearSpec, PairSpec

#: ISO 6336-1:2019 constants C1..C9 of q' (mm um / N).
ISO_Q_CONSTANTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)

#: C_M of ISO 6336-1: measured stiffness of solid steel spur gears is 0.8 of the theory.
C_M_SOLID = 0.8

#: Line load (N/mm) below which ISO 6336-1 reduces the stiffness.
LOW_LOAD_LIMIT_N_PER_MM = 100.0

#: Young's modulus of steel that the ISO stiffness values refer to (Pa).
E_STEEL_ISO_Pa = 206e9


def flexibility_theoretical(z1: float, z2: float, x1: float, x2: float) -> float:
    """Minimum theoretical flexibility q' (mm um / N) of a solid spur tooth pair.

    q' = C1 + C2/z1 + C3/z2 + C4 x1 + C5 x1/z1 + C6 x2 + C7 x2/z2 + C8 x1^2 + C9 x2^2
    (ISO 6336-1:2019, method B; z_n = z for spur gears, :func:`virtual_teeth` for
    helical gears: the arguments are then the virtual numbers). Index 1 is ISO's gear 1,
    the gear with fewer teeth (whichever drives), 2 the other; x are the profile shift
    coefficients. Not symmetric in the two gears: :func:`iso_ordered` puts a pair in
    this order.
    """
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = ISO_Q_CONSTANTS
    return c1 + c2 / z1 + c3 / z2 + c4 * x1 + c5 * x1 / z1 + c6 * x2 + c7 * x2 / z2 + c8 * x1**2 + c9 * x2**2


def iso_ordered(pair: PairSpec) -> PairSpec:
    """``pair`` in ISO 6336's gear order: index 0 is ISO's gear 1, the gear with fewer teeth.

    ``pair`` itself when its driver (index 0) has no more teeth than the driven gear;
    otherwise the same pair with every per-gear value (each tuple field of ``PairSpec``:
    teeth, profile shifts, bores, materials, webs, given tip and root diameters) swapped,
    so that ``iso_ordered(pair).gear(0)`` is the driven gear. Shared values (module,
    rack, face width, centre distance) stay. The driver is then index 1: a driver torque
    is converted with the tooth ratio by the caller.
    """
    if pair.teeth[0] <= pair.teeth[1]:
        return pair
    # every tuple field of PairSpec holds one value per gear (index 0 = pinion/driver)
    return replace(
        pair, **{f.name: getattr(pair, f.name)[::-1] for f in fields(pair) if isinstance(getattr(pair, f.name), tuple)}
    )


def single_stiffness_theoretical(z1: float, z2: float, x1: float, x2: float) -> float:
    """Theoretical single stiffness c'_th = 1 / q' in N/(mm um) (ISO 6336-1:2019, method B)."""
    return 1.0 / flexibility_theoretical(z1, z2, x1, x2)


def gear_blank_factor(
    face_width_m: float, module_m: float, web_thickness_m: float | None = None, rim_thickness_m: float | None = None
) -> float:
    """C_R of ISO 6336-1:2019: 1 for solid discs, else for webbed blanks

        C_R = 1 + ln(b_s / b) / (5 exp(s_R / (5 m_n)))

    with web thickness b_s, face width b, rim thickness s_R and normal module m_n
    (all in m; only ratios enter). As the standard prescribes, b_s/b is limited to
    [0.2, 1.2] and s_R/m_n to >= 1 (outside, the fit was not made).
    """
    if web_thickness_m is None:
        return 1.0
    if rim_thickness_m is None:
        raise fail_text(None, "gear_blank_factor: a webbed blank needs rim_thickness_m as well")
    ratio = min(max(web_thickness_m / face_width_m, 0.2), 1.2)
    rim = max(rim_thickness_m / module_m, 1.0)
    return 1.0 + math.log(ratio) / (5.0 * math.exp(rim / 5.0))


def gear_blank_factor_of(gear: GearSpec) -> float:
    """C_R of one gear from its own blank: 1 for a solid disc (``gear.web`` None), else
    :func:`gear_blank_factor` of its web thickness b_s and rim thickness s_R."""
    if gear.web is None:
        return 1.0
    return gear_blank_factor(gear.face_width_m, gear.module_m, gear.web.thickness_m, gear.web.rim_thickness_m)


def pair_blank_factor(pair: PairSpec) -> float:
    """C_R of a pair whose gears have their own blanks: (C_R,1 + C_R,2) / 2 (module
    docstring, "Gear blank factor of two gears"); C_R of the standard when both are alike."""
    return 0.5 * (gear_blank_factor_of(pair.gear(0)) + gear_blank_factor_of(pair.gear(1)))


def basic_rack_factor(dedendum_coefficient: float, pressure_angle_rad: float) -> float:
    """C_B of ISO 6336-1:2019 for pinion and wheel cut by the same rack:

        C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_n)]

    h_fP/m_n = ``dedendum_coefficient``; alpha_n in degrees inside the bracket.
    C_B = 1 for the ISO reference rack h_fP = 1.2 m_n, alpha_n = 20 deg.
    """
    return (1.0 + 0.5 * (1.2 - dedendum_coefficient)) * (1.0 - 0.02 * (20.0 - math.degrees(pressure_angle_rad)))


def single_stiffness(
    c_th_prime: float, C_R: float, C_B: float, material_factor: float, helix_angle_rad: float = 0.0
) -> float:
    """c' = c'_th C_M C_R C_B cos(beta) E / E_st in N/(mm um), C_M = 0.8 (ISO 6336-1 method B,
    module docstring), without the low-load factor."""
    return c_th_prime * C_M_SOLID * C_R * C_B * math.cos(helix_angle_rad) * material_factor


def mesh_stiffness(c_prime: float, eps_alpha: float) -> float:
    """c_gamma_alpha = c' (0.75 eps_alpha + 0.25) in the units of c' (ISO 6336-1 method B; the
    mean of the total mesh stiffness over the path of contact)."""
    return c_prime * (0.75 * eps_alpha + 0.25)


def base_helix_angle_rad(helix_angle_rad: float, normal_pressure_angle_rad: float) -> float:
    """beta_b: sin(beta_b) = sin(beta) cos(alpha_n) (ISO 21771), rad."""
    return math.asin(math.sin(helix_angle_rad) * math.cos(normal_pressure_angle_rad))


def virtual_teeth(teeth: float, helix_angle_rad: float, normal_pressure_angle_rad: float) -> float:
    """Virtual number of teeth z_n = z / (cos^2(beta_b) cos(beta)) of a helical gear (ISO 21771),
    the z_n of q'; z itself for spur gears."""
    c = math.cos(base_helix_angle_rad(helix_angle_rad, normal_pressure_angle_rad))
    return teeth / (c * c * math.cos(helix_angle_rad))


def transverse_pressure_angle_rad(normal_pressure_angle_rad: float, helix_angle_rad: float) -> float:
    """alpha_t: tan(alpha_t) = tan(alpha_n) / cos(beta) (ISO 21771), rad."""
    return math.atan(math.tan(normal_pressure_angle_rad) / math.cos(helix_angle_rad))


def transverse_contact_ratio(
    tip_radii_m: tuple[float, float],
    base_radii_m: tuple[float, float],
    centre_distance_m: float,
    transverse_base_pitch_m: float,
) -> float:
    """eps_alpha = (sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin(alpha_wt)) / p_bt of an
    external pair, cos(alpha_wt) = (r_b1 + r_b2) / a (ISO 21771); radii, a and the transverse
    base pitch p_bt = pi m_t cos(alpha_t) in m."""
    (ra1, ra2), (rb1, rb2) = tip_radii_m, base_radii_m
    alpha_wt = math.acos((rb1 + rb2) / centre_distance_m)
    approach = math.sqrt(ra1**2 - rb1**2) + math.sqrt(ra2**2 - rb2**2)
    return (approach - centre_distance_m * math.sin(alpha_wt)) / transverse_base_pitch_m


def overlap_ratio(face_width_m: float, helix_angle_rad: float, normal_module_m: float) -> float:
    """eps_beta = b sin(beta) / (pi m_n) (ISO 21771); 0 for spur gears. The dynamic factor's
    C_v take eps_gamma = eps_alpha + eps_beta."""
    return face_width_m * math.sin(helix_angle_rad) / (math.pi * normal_module_m)


def low_load_factor(line_load_N_per_mm: float | None) -> float:
    """(F_t K_A / b / 100)^0.25 below 100 N/mm, else 1 (ISO 6336-1:2019).

    ``None`` (load unknown) gives 1: the standard value without the reduction.
    """
    if line_load_N_per_mm is None or line_load_N_per_mm >= LOW_LOAD_LIMIT_N_PER_MM:
        return 1.0
    if line_load_N_per_mm <= 0.0:
        raise fail("line load", float(line_load_N_per_mm), "N/mm", "must be > 0")
    return (line_load_N_per_mm / LOW_LOAD_LIMIT_N_PER_MM) ** 0.25


@dataclass(frozen=True)
class IsoStiffness:
    """ISO 6336-1 method B stiffness of a spur pair.

    Stiffness values per unit face width in N/(mm um) (ISO units); the
    ``*_N_per_m`` properties give the spring of the whole face width in N/m.
    ``line_load_N_per_mm`` = F_t K_A / b (None when no torque was given, then the
    low-load factor is 1). ``z1``, ``z2``: the tooth counts in ISO's order (z1 <= z2,
    gear 1 = the gear with fewer teeth, whichever drives).
    """

    z1: int  # teeth of ISO's gear 1 (the fewer)
    z2: int
    c_th_prime: float  # theoretical single stiffness c'_th, N/(mm um)
    C_M: float
    C_R: float
    C_B: float
    cos_beta: float
    material_factor: float  # E / E_st, 1 for steel/steel
    c_prime: float  # c' without the low-load factor, N/(mm um)
    eps_alpha: float  # transverse contact ratio used
    c_gamma_alpha: float  # mesh stiffness without the low-load factor, N/(mm um)
    low_load_factor: float
    c_prime_low_load: float  # c' with the low-load factor, N/(mm um)
    c_gamma_alpha_low_load: float
    face_width_mm: float
    line_load_N_per_mm: float | None
    in_fit_range: bool  # profile shifts inside the range of the q' fit

    @property
    def single_stiffness_N_per_m(self) -> float:
        """c' b: N/(mm um) * mm = N/um = 1e6 N/m."""
        return self.c_prime * self.face_width_mm * 1e6

    @property
    def mesh_stiffness_N_per_m(self) -> float:
        """c_gamma_alpha b in N/m."""
        return self.c_gamma_alpha * self.face_width_mm * 1e6

    @property
    def single_stiffness_low_load_N_per_m(self) -> float:
        return self.c_prime_low_load * self.face_width_mm * 1e6

    @property
    def mesh_stiffness_low_load_N_per_m(self) -> float:
        return self.c_gamma_alpha_low_load * self.face_width_mm * 1e6


def iso6336_stiffness(
    pair: PairSpec, torque_Nm: float | None = None, contact_ratio: float | None = None, K_A: float = 1.0
) -> IsoStiffness:
    """ISO 6336-1:2019 method B single and mesh stiffness of ``pair`` (spur gears).

    ISO's gear 1 is the gear with fewer teeth whatever drives (module docstring, "Gear
    order"): the pair is taken in that order (:func:`iso_ordered`), so a pair and the same
    pair with driver and driven gear exchanged give the same result.
    ``torque_Nm``: torque of the pair's driver, index 0 (N m); ISO's gear 1 carries
    T1 = T z1 / z_driver (no losses), and the nominal tangential load at its reference
    circle is F_t = 2 T1 / d1 (N, d1 = m z1 in m; the same force at either reference
    circle). The line load F_t K_A / b (N/mm) decides the low-load factor.
    ``contact_ratio`` defaults to the transverse contact ratio eps_alpha at the nominal
    centre distance (geometry.kinematics).
    Each gear's own blank gives its C_R (``pair.gear(i).web``; None: a solid disc, C_R = 1),
    the pair takes the mean of the two (:func:`pair_blank_factor`). Both gears share the
    basic rack, so one C_B applies (the mean of the two when a given root diameter changes
    a gear's tool dedendum); the material factor is E / E_st with the equivalent modulus
    E = 2 E1 E2 / (E1 + E2). See the module docstring for the equations.
    """
    if K_A <= 0:
        raise fail("K_A", float(K_A), "", "must be > 0")
    z_driver = pair.teeth[0]
    pair = iso_ordered(pair)  # from here on index 0 is ISO's gear 1 (fewer teeth)
    z1, z2 = pair.teeth
    x1, x2 = pair.profile_shift
    c_th = single_stiffness_theoretical(z1, z2, x1, x2)
    C_R = pair_blank_factor(pair)
    # ISO 6336-1: racks that differ (a given root diameter sets each gear's tool
    # dedendum) give C_B = (C_B1 + C_B2) / 2
    C_B = 0.5 * (
        basic_rack_factor(pair.gear(0).dedendum_coefficient, pair.pressure_angle_rad)
        + basic_rack_factor(pair.gear(1).dedendum_coefficient, pair.pressure_angle_rad)
    )
    # the equivalent modulus E = 2 E1 E2 / (E1 + E2) of the two gears' own materials
    material_factor = pair.equivalent_youngs_modulus_Pa / E_STEEL_ISO_Pa
    c_prime = single_stiffness(c_th, C_R, C_B, material_factor)
    eps = MeshGeometry(pair, pair.centre_distance_m).contact_ratio if contact_ratio is None else float(contact_ratio)
    if eps < 1.0:
        # c_gamma_alpha = c' (0.75 eps + 0.25) is a mean over overlapping pairs (ISO 6336-1
        # states it for eps >= 1.2); with gaps in the contact there is no such mean
        raise fail(
            "method",
            "'iso6336'",
            "",
            f"ISO 6336-1 method B needs a contact ratio >= 1 (overlapping "
            f"tooth pairs), but it is {eps:.3f}; the analytic methods (ishikawa, energy) model the gaps",
        )
    b_mm = pair.face_width_m * 1e3
    line_load = None
    if torque_Nm is not None:
        if torque_Nm <= 0:
            raise fail("torque", float(torque_Nm), "N m", "must be > 0")
        # T1 = T z1 / z_driver: the ratio first, so that it is exactly 1 without a swap
        torque_1_Nm = torque_Nm * (z1 / z_driver)
        d1_m = pair.module_m * z1
        F_t = 2.0 * torque_1_Nm / d1_m
        line_load = F_t * K_A / b_mm
    f_low = low_load_factor(line_load)
    return IsoStiffness(
        z1=z1,
        z2=z2,
        c_th_prime=c_th,
        C_M=C_M_SOLID,
        C_R=C_R,
        C_B=C_B,
        cos_beta=1.0,  # spur gears
        material_factor=material_factor,
        c_prime=c_prime,
        eps_alpha=eps,
        c_gamma_alpha=mesh_stiffness(c_prime, eps),
        low_load_factor=f_low,
        c_prime_low_load=c_prime * f_low,
        c_gamma_alpha_low_load=mesh_stiffness(c_prime * f_low, eps),
        face_width_mm=b_mm,
        line_load_N_per_mm=line_load,
        in_fit_range=bool(x1 >= x2 and -0.5 <= x1 + x2 <= 2.0),
    )


# -- dynamic factor K_v, method B (ISO 6336-1:2006 clause 6.5) --------------------------------
#
# Resonance speed and ratio (z1, n1: teeth and speed of ISO's gear 1, the gear with fewer
# teeth whichever drives; in a planetary stage n1 is the speed relative to the carrier):
#     n_E1 = 30000 / (pi z1) sqrt(c_gamma / m_red)      [min^-1]; c_gamma N/(mm um), m_red kg/mm
#     N    = n1 / n_E1
# (n1 z1 is the mesh frequency times 60, so N is the same whichever gear it is written
# for; n_E1 itself is a speed of gear 1.)
# m_red is the mass of the pair per unit face width reduced to the line of action,
# m1* m2* / (m1* + m2*) with m* = J* / r_b^2 (J* the polar moment of inertia per face width),
# :func:`reduced_mass_kg_per_mm`; a planetary stage has its own rule,
# :func:`reduced_mass_sun_planet_kg_per_mm` (and m_red = m_planet* for the planet-annulus mesh).
# Lower limit of the main resonance range (w = F_t K_A / b in N/mm):
#     N_S = 0.5 + 0.35 sqrt(w / 100) for w < 100 N/mm, else 0.85
# With B_p = c' f_pb,eff / w, B_f = c' f_f,eff / w, B_k = |1 - c' C_a / w|,
# f_pb,eff = f_pb - y_p and f_f,eff = f_f - y_f (after running-in):
#     subcritical      N <= N_S:        K_v = N K + 1,  K = C_v1 B_p + C_v2 B_f + C_v3 B_k
#     main resonance   N_S < N <= 1.15: K_v = C_v1 B_p + C_v2 B_f + C_v4 B_k + 1
#     supercritical    N >= 1.5:        K_v = C_v5 B_p + C_v6 B_f + C_v7
#     intermediate     1.15 < N < 1.5:  K_v = K_v(1.5) + (K_v(1.15) - K_v(1.5)) (1.5 - N) / 0.35
# C_v1..C_v7 depend on the total contact ratio eps_gamma (eps_alpha for spur gears), see
# :func:`cv_coefficients`.
# Inputs as KISSsoft's ISO 6336:2006 reports of the NREL 5 MW gearbox use them
# (tests/test_iso6336_kisssoft.py): f_pb and f_f are the larger of the two gears' values
# (its running-in y_p = 1.342 um of the sun-planet mesh is 0.075 x 17.9 um, the planet's
# f_pb, not the sun's 16.9), from ISO 1328-1:1995 (:func:`iso1328_deviations_um`, f_pb =
# f_pt cos(alpha_t) printed to 0.1 um); running-in of case-hardened steel y_p = 0.075 f_pb,
# y_f = 0.075 f_f (:func:`running_in_case_hardened_um`); w = F_t K_A / b with F_t per mesh
# (a planetary stage: the sun torque over p planets, 2 T_sun / (p d_sun)); C_a = 0 when no
# tip relief is specified ("only running-in"), so B_k = 1: the helical stage's printed
# K_v = 1.092 needs B_k = 1 (with C_a = C_ay = 2.0 um, the running-in tip relief it prints,
# B_k = 0.967 and K_v = 1.091). One open implementation reads ISO 6336-1:2006 as setting
# B_k = 1 for accuracy grades 6 and coarser, which the grade-6 reports cannot tell apart.
# Edition: the reports name "ISO 6336:2006 Method B", and these equations reproduce their
# printed n_E1, N and K_v; whether the 2019 edition changes any of them could not be
# checked here (no copy of either edition at hand), so they are the 2006 method.

#: ISO 6336-1 speed ranges, by resonance ratio N
KV_RANGES = ("subcritical", "main resonance", "intermediate", "supercritical")


def resonance_speed_rpm(z1: int, c_gamma_N_per_mm_um: float, m_red_kg_per_mm: float) -> float:
    """n_E1 = 30000 / (pi z1) sqrt(c_gamma / m_red) in min^-1 (ISO 6336-1 method B): the
    speed of ISO's gear 1 (``z1`` teeth, the fewer of the pair) whose mesh frequency is the
    natural frequency sqrt(k / m_e) / (2 pi) of the pair's relative torsional vibration on
    rigid bearings."""
    if not (c_gamma_N_per_mm_um > 0 and m_red_kg_per_mm > 0 and z1 > 0):
        raise fail_text(None, "resonance_speed_rpm: z1, c_gamma and m_red must be > 0")
    return 30000.0 / (math.pi * z1) * math.sqrt(c_gamma_N_per_mm_um / m_red_kg_per_mm)


def mass_per_face_width_kg_per_mm(inertia_kg_m2: float, base_radius_m: float, face_width_m: float) -> float:
    """m* = J / (r_b^2 b) in kg/mm: a gear's polar moment of inertia J (kg m^2) as a mass on
    its line of action (base radius r_b, m), per mm of face width b (m) (ISO 6336-1 method B)."""
    return inertia_kg_m2 / base_radius_m**2 / (face_width_m * 1e3)


def reduced_mass_kg_per_mm(m1_kg_per_mm: float, m2_kg_per_mm: float) -> float:
    """m_red = m1* m2* / (m1* + m2*) in kg/mm of a gear pair (ISO 6336-1 method B); symmetric
    in the two gears."""
    return m1_kg_per_mm * m2_kg_per_mm / (m1_kg_per_mm + m2_kg_per_mm)


def reduced_mass_sun_planet_kg_per_mm(m_sun_kg_per_mm: float, m_planet_kg_per_mm: float, planets: int) -> float:
    """m_red of the sun-planet mesh of a planetary stage with ``planets`` planets (kg/mm):

        m_red = m_sun* m_pla* / (m_sun* + p m_pla*)

    with m* = J / (r_b^2 b) of each gear (:func:`mass_per_face_width_kg_per_mm`). The sun
    meshes with all p planets, so each mesh sees m_sun* / p in series with one planet:
    (m_sun*/p) m_pla* / (m_sun*/p + m_pla*). The planet-annulus mesh takes m_red = m_pla*
    (the annulus as an infinitely heavy, fixed body). This is ISO 6336-1's planetary rule
    as KISSsoft applies it: its NREL 5 MW stage 2 (p = 3) prints m_red = 0.1534 kg/mm for the
    sun-planet mesh and 1.4684 kg/mm (= m_pla*) for the planet-annulus mesh, both from its
    printed moments of inertia (tests/test_iso6336_kisssoft.py); the wording of the
    standard itself could not be checked here.
    """
    if planets < 1:
        raise fail_text("planets", f"planets = {planets}: must be >= 1", planets)
    return m_sun_kg_per_mm * m_planet_kg_per_mm / (m_sun_kg_per_mm + planets * m_planet_kg_per_mm)


def running_in_case_hardened_um(deviation_um: float) -> float:
    """Running-in allowance of case-hardened or nitrided steel, y = 0.075 of the deviation
    (f_pb for y_p, f_f_alpha for y_f), at most 3 um (ISO 6336-1 method B), in um."""
    return min(0.075 * deviation_um, 3.0)


def cv_coefficients(eps_gamma: float) -> tuple[float, float, float, float, float, float, float]:
    """(C_v1, ..., C_v7) of ISO 6336-1 method B for the total contact ratio eps_gamma > 1:
    constants 0.32, 0.34, 0.23, 0.90, 0.47, 0.47 up to eps_gamma = 2; beyond it
    C_v2 = 0.57/(eps - 0.3), C_v3 = 0.096/(eps - 1.56), C_v4 = (0.57 - 0.05 eps)/(eps - 1.44),
    C_v6 = 0.12/(eps - 1.74); C_v7 = 0.75 up to 1.5, 0.125 sin(pi (eps - 2)) + 0.875 up to
    2.5, then 1."""
    e = float(eps_gamma)
    if not e > 1.0:
        raise fail("eps_gamma", e, "", "ISO 6336-1 method B needs a contact ratio > 1")
    if e <= 2.0:
        c2, c3, c4, c6 = 0.34, 0.23, 0.90, 0.47
    else:
        c2, c3, c4, c6 = 0.57 / (e - 0.3), 0.096 / (e - 1.56), (0.57 - 0.05 * e) / (e - 1.44), 0.12 / (e - 1.74)
    c7 = 0.75 if e <= 1.5 else (0.125 * math.sin(math.pi * (e - 2.0)) + 0.875 if e <= 2.5 else 1.0)
    return 0.32, c2, c3, c4, 0.47, c6, c7


@dataclass(frozen=True)
class IsoDynamicFactor:
    """ISO 6336-1 method B dynamic factor over the speeds of ISO's gear 1 (the gear with fewer
    teeth; arrays follow ``speed_rpm``)."""

    speed_rpm: Any  # numpy array (min^-1)
    K_v: Any  # numpy array
    N: Any  # numpy array, resonance ratio n1 / n_E1
    range_name: tuple  # per speed: one of KV_RANGES
    n_E1_rpm: float
    N_S: float
    B_p: float
    B_f: float
    B_k: float
    C_v: tuple
    line_load_N_per_mm: float  # w = F_t K_A / b


def dynamic_factor(
    speed_rpm,
    z1: int,
    c_gamma_N_per_mm_um: float,
    c_prime_N_per_mm_um: float,
    m_red_kg_per_mm: float,
    line_load_N_per_mm: float,
    f_pb_eff_um: float,
    f_f_eff_um: float,
    C_a_um: float,
    eps_gamma: float,
) -> IsoDynamicFactor:
    """K_v of ISO 6336-1 method B at each speed ``speed_rpm`` of ISO's gear 1 (equations above
    the function).

    ``z1`` and ``speed_rpm`` belong to ISO's gear 1, the gear with FEWER teeth whichever
    drives (a driver speed n converts to n z_driver / z1; relative to the carrier in a
    planetary stage). ``line_load_N_per_mm`` = F_t K_A / b with F_t the nominal tangential
    load at the reference circle; stiffnesses per unit face width in N/(mm um); deviations
    in um."""
    import numpy as np

    if not line_load_N_per_mm > 0:
        raise fail("line load", float(line_load_N_per_mm), "N/mm", "must be > 0")
    n = np.atleast_1d(np.asarray(speed_rpm, float))
    w = float(line_load_N_per_mm)
    nE1 = resonance_speed_rpm(z1, c_gamma_N_per_mm_um, m_red_kg_per_mm)
    N = n / nE1
    NS = 0.5 + 0.35 * math.sqrt(w / 100.0) if w < 100.0 else 0.85
    cv = cv_coefficients(eps_gamma)
    c1, c2, c3, c4, c5, c6, c7 = cv
    cp = float(c_prime_N_per_mm_um)
    Bp = cp * max(f_pb_eff_um, 0.0) / w
    Bf = cp * max(f_f_eff_um, 0.0) / w
    Bk = abs(1.0 - cp * C_a_um / w)
    k_sub = c1 * Bp + c2 * Bf + c3 * Bk
    kv_main = c1 * Bp + c2 * Bf + c4 * Bk + 1.0
    kv_super = c5 * Bp + c6 * Bf + c7
    kv_inter = kv_super + (kv_main - kv_super) * (1.5 - N) / 0.35
    conds = [N <= NS, N <= 1.15, N < 1.5]
    K_v = np.select(conds, [N * k_sub + 1.0, np.full_like(N, kv_main), kv_inter], kv_super)
    names = tuple(np.select(conds, list(KV_RANGES[:3]), KV_RANGES[3]).tolist())
    return IsoDynamicFactor(n, K_v, N, names, nE1, NS, Bp, Bf, Bk, cv, w)


#: ISO 1328-1:1995 range limits (mm) of the reference diameter d and of the normal module m:
#: the tolerance formulae take the geometric mean of the limits of the range holding the
#: gear's value (5 <= d <= 20, 20 < d <= 50, ...; 0.5 <= m <= 2, 2 < m <= 3.5, ...)
ISO1328_DIAMETER_LIMITS_MM = (
    5.0,
    20.0,
    50.0,
    125.0,
    280.0,
    560.0,
    1000.0,
    1600.0,
    2500.0,
    4000.0,
    6000.0,
    8000.0,
    10000.0,
)
ISO1328_MODULE_LIMITS_MM = (0.5, 2.0, 3.5, 6.0, 10.0, 16.0, 25.0, 40.0, 70.0)


def iso1328_range_mean(value_mm: float, limits_mm: tuple[float, ...]) -> float:
    """sqrt(lo hi) (mm) of the ISO 1328-1:1995 range lo < value <= hi of ``limits_mm`` that holds
    ``value_mm`` (the first range includes its lower limit)."""
    if not limits_mm[0] <= value_mm <= limits_mm[-1]:
        raise fail_text(
            None,
            f"{value_mm:g} mm: outside the ISO 1328-1 ranges [{limits_mm[0]:g}, {limits_mm[-1]:g}] mm",
            value_mm,
            unit="mm",
        )
    hi_index = next(i for i, hi in enumerate(limits_mm[1:], 1) if value_mm <= hi)
    return math.sqrt(limits_mm[hi_index - 1] * limits_mm[hi_index])


def iso1328_deviations_um(module_m: float, reference_diameter_m: float, grade: int) -> tuple[float, float]:
    """(f_pt, f_f_alpha) in um of ISO 1328-1:1995 accuracy ``grade`` (1-12): the grade-5
    values f_pt = 0.3 (m + 0.4 sqrt(d)) + 4 and f_f_alpha = 2.5 sqrt(m) + 0.17 sqrt(d) + 0.5
    with m and d (mm) the geometric means of their ISO 1328-1 ranges
    (:func:`iso1328_range_mean`), times 2^((Q - 5) / 2), rounded as ISO 1328-1 prescribes
    (above 10 um to whole um, 5-10 um to 0.5 um, below 5 um to 0.1 um). The range means are
    what KISSsoft's tolerance tables show: its NREL 5 MW reports print, at grade 6,
    f_pt / f_f_alpha = 18 / 21 um for m = 21 mm, d = 378 mm (the gear's own m and d would
    give 18 / 22) and 33 / 33 um for m = 45 mm, d = 855 mm (own m and d: 30 / 31)."""
    m = iso1328_range_mean(module_m * 1e3, ISO1328_MODULE_LIMITS_MM)
    d = iso1328_range_mean(reference_diameter_m * 1e3, ISO1328_DIAMETER_LIMITS_MM)
    step = 2.0 ** ((grade - 5) / 2.0)

    def rnd(x: float) -> float:
        q = 1.0 if x > 10 else (0.5 if x >= 5 else 0.1)
        return round(round(x / q) * q, 1)

    return rnd((0.3 * (m + 0.4 * math.sqrt(d)) + 4.0) * step), rnd(
        (2.5 * math.sqrt(m) + 0.17 * math.sqrt(d) + 0.5) * step
    )
