"""Tooth stiffness of ISO 6336-1:2019, method B (clause 9): a standard reference value.

All symbols and units follow the standard: stiffness per unit face width in
N/(mm um) (= 1e9 N/m per m of face width), module and face width in mm inside the
ISO formulas only; every input and every ``*_N_per_m`` output is SI.

Theoretical single stiffness (ISO 6336-1:2019, clause 9, method B; spur gears, so the virtual
tooth numbers are z_n = z / cos^3(beta) = z):

    q'    = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2
            + C8 x1^2 + C9 x2^2                                   [mm um / N]
    c'_th = 1 / q'                                                [N / (mm um)]

    C1..C9 = 0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188,
             0.00529, 0.00182

The constants are the published ISO 6336-1 table values for q', as given in this
project's brief; they agree with the values quoted in the gear literature, but
they were not re-checked against a copy of the standard. Equation numbers are
not quoted because they differ between the 2006 and 2019 editions.

Single stiffness of a tooth pair (ISO 6336-1:2019, clause 9):

    c' = c'_th C_M C_R C_B cos(beta)                              [N / (mm um)]

    C_M = 0.8                 theoretical-to-measured correction (solid spur gears)
    C_R = 1 + ln(b_s/b) / (5 exp(s_R / (5 m_n)))    gear blank factor; 1 for solid discs
    C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_n)]    basic rack factor
    cos(beta) = 1 (spur)

and, for materials other than steel/steel, the ISO material factor
E / E_st, E = 2 E1 E2 / (E1 + E2), E_st = 206000 N/mm^2 (1 for this project's
default steel; each gear has its own ``pair.materials[i]``). The q' fit covers
x1 >= x2 and -0.5 <= x1 + x2 <= 2; outside, :class:`IsoStiffness` flags it.

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
from dataclasses import dataclass
from typing import Any

from gearwear.core.validation import fail
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import PairSpec

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
    (ISO 6336-1:2019, method B, with z_n = z for spur gears). Index 1 is the
    pinion, 2 the wheel, in ISO's sense: the pinion is the gear with fewer teeth
    (z1 <= z2), whichever drives; x are the profile shift coefficients.
    """
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = ISO_Q_CONSTANTS
    return (c1 + c2 / z1 + c3 / z2 + c4 * x1 + c5 * x1 / z1 + c6 * x2 + c7 * x2 / z2
            + c8 * x1 ** 2 + c9 * x2 ** 2)


def single_stiffness_theoretical(z1: float, z2: float, x1: float, x2: float) -> float:
    """Theoretical single stiffness c'_th = 1 / q' in N/(mm um) (ISO 6336-1:2019, method B)."""
    return 1.0 / flexibility_theoretical(z1, z2, x1, x2)


def gear_blank_factor(face_width_m: float, module_m: float, web_thickness_m: float | None = None,
                      rim_thickness_m: float | None = None) -> float:
    """C_R of ISO 6336-1:2019: 1 for solid discs, else for webbed blanks

        C_R = 1 + ln(b_s / b) / (5 exp(s_R / (5 m_n)))

    with web thickness b_s, face width b, rim thickness s_R and normal module m_n
    (all in m; only ratios enter). As the standard prescribes, b_s/b is limited to
    [0.2, 1.2] and s_R/m_n to >= 1 (outside, the fit was not made).
    """
    if web_thickness_m is None:
        return 1.0
    if rim_thickness_m is None:
        raise ValueError("gear_blank_factor: a webbed blank needs rim_thickness_m as well")
    ratio = min(max(web_thickness_m / face_width_m, 0.2), 1.2)
    rim = max(rim_thickness_m / module_m, 1.0)
    return 1.0 + math.log(ratio) / (5.0 * math.exp(rim / 5.0))


def basic_rack_factor(dedendum_coefficient: float, pressure_angle_rad: float) -> float:
    """C_B of ISO 6336-1:2019 for pinion and wheel cut by the same rack:

        C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_n)]

    h_fP/m_n = ``dedendum_coefficient``; alpha_n in degrees inside the bracket.
    C_B = 1 for the ISO reference rack h_fP = 1.2 m_n, alpha_n = 20 deg.
    """
    return ((1.0 + 0.5 * (1.2 - dedendum_coefficient))
            * (1.0 - 0.02 * (20.0 - math.degrees(pressure_angle_rad))))


def low_load_factor(line_load_N_per_mm: float | None) -> float:
    """(F_t K_A / b / 100)^0.25 below 100 N/mm, else 1 (ISO 6336-1:2019).

    ``None`` (load unknown) gives 1: the standard value without the reduction.
    """
    if line_load_N_per_mm is None or line_load_N_per_mm >= LOW_LOAD_LIMIT_N_PER_MM:
        return 1.0
    if line_load_N_per_mm <= 0.0:
        raise ValueError(f"line load = {line_load_N_per_mm:g} N/mm: must be > 0")
    return (line_load_N_per_mm / LOW_LOAD_LIMIT_N_PER_MM) ** 0.25


@dataclass(frozen=True)
class IsoStiffness:
    """ISO 6336-1 method B stiffness of a spur pair.

    Stiffness values per unit face width in N/(mm um) (ISO units); the
    ``*_N_per_m`` properties give the spring of the whole face width in N/m.
    ``line_load_N_per_mm`` = F_t K_A / b (None when no torque was given, then the
    low-load factor is 1).
    """

    c_th_prime: float          # theoretical single stiffness c'_th, N/(mm um)
    C_M: float
    C_R: float
    C_B: float
    cos_beta: float
    material_factor: float     # E / E_st, 1 for steel/steel
    c_prime: float             # c' without the low-load factor, N/(mm um)
    eps_alpha: float           # transverse contact ratio used
    c_gamma_alpha: float       # mesh stiffness without the low-load factor, N/(mm um)
    low_load_factor: float
    c_prime_low_load: float    # c' with the low-load factor, N/(mm um)
    c_gamma_alpha_low_load: float
    face_width_mm: float
    line_load_N_per_mm: float | None
    in_fit_range: bool         # profile shifts inside the range of the q' fit

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


def iso6336_stiffness(pair: PairSpec, torque_Nm: float | None = None,
                      contact_ratio: float | None = None, K_A: float = 1.0,
                      web_thickness_m: float | None = None,
                      rim_thickness_m: float | None = None) -> IsoStiffness:
    """ISO 6336-1:2019 method B single and mesh stiffness of ``pair`` (spur gears).

    ``torque_Nm``: pinion torque (N m); the nominal tangential load at the reference
    circle is F_t = 2 T / d_1 (N, d_1 = m z_1 in m), and the line load F_t K_A / b
    (N/mm) decides the low-load factor. ``contact_ratio`` defaults to the transverse
    contact ratio eps_alpha at the nominal centre distance (geometry.kinematics).
    ``web_thickness_m`` / ``rim_thickness_m`` describe a webbed blank (C_R); by
    default the blank is a solid disc (C_R = 1). Both gears share the basic rack, so
    one C_B applies (the mean of the two when a given root diameter changes a gear's
    tool dedendum), and one material (material factor E / E_st). See the module
    docstring for the equations.

    ISO 6336's index 1 is the pinion in its sense, the gear with fewer teeth (u = z2 / z1
    >= 1), not the driver: q' and the fit range take the smaller gear's z and x as z_n1, x1
    whichever gear drives (index 0 of ``pair`` is the driver), so a pair has one ISO
    stiffness in either direction of power flow. The line load is the driver's torque over
    the driver's reference radius (the same tangential force on both gears).
    """
    if K_A <= 0:
        raise ValueError(f"K_A = {K_A:g}: must be > 0")
    z1, z2 = pair.teeth
    x1, x2 = pair.profile_shift
    if z1 > z2:  # ISO's pinion is the smaller gear
        (z1, x1), (z2, x2) = (z2, x2), (z1, x1)
    c_th = single_stiffness_theoretical(z1, z2, x1, x2)
    C_R = gear_blank_factor(pair.face_width_m, pair.module_m, web_thickness_m, rim_thickness_m)
    # ISO 6336-1: racks that differ (a given root diameter sets each gear's tool
    # dedendum) give C_B = (C_B1 + C_B2) / 2
    C_B = 0.5 * (basic_rack_factor(pair.gear(0).dedendum_coefficient, pair.pressure_angle_rad)
                 + basic_rack_factor(pair.gear(1).dedendum_coefficient, pair.pressure_angle_rad))
    cos_beta = 1.0  # spur gears
    # the equivalent modulus E = 2 E1 E2 / (E1 + E2) of the two gears' own materials
    material_factor = pair.equivalent_youngs_modulus_Pa / E_STEEL_ISO_Pa
    c_prime = c_th * C_M_SOLID * C_R * C_B * cos_beta * material_factor
    eps = (MeshGeometry(pair, pair.centre_distance_m).contact_ratio
           if contact_ratio is None else float(contact_ratio))
    if eps < 1.0:
        # c_gamma_alpha = c' (0.75 eps + 0.25) is a mean over overlapping pairs (ISO 6336-1
        # states it for eps >= 1.2); with gaps in the contact there is no such mean
        raise fail("method", "'iso6336'", "", f"ISO 6336-1 method B needs a contact ratio >= 1 (overlapping "
                   f"tooth pairs), but it is {eps:.3f}; the analytic methods (ishikawa, energy) model the gaps")
    b_mm = pair.face_width_m * 1e3
    line_load = None
    if torque_Nm is not None:
        if torque_Nm <= 0:
            raise ValueError(f"torque = {torque_Nm:g} N m: must be > 0")
        d1_m = pair.module_m * pair.teeth[0]  # the driver's reference diameter: T is its torque
        F_t = 2.0 * torque_Nm / d1_m
        line_load = F_t * K_A / b_mm
    f_low = low_load_factor(line_load)
    mesh_factor = 0.75 * eps + 0.25
    return IsoStiffness(
        c_th_prime=c_th, C_M=C_M_SOLID, C_R=C_R, C_B=C_B, cos_beta=cos_beta,
        material_factor=material_factor, c_prime=c_prime,
        eps_alpha=eps, c_gamma_alpha=c_prime * mesh_factor, low_load_factor=f_low,
        c_prime_low_load=c_prime * f_low, c_gamma_alpha_low_load=c_prime * f_low * mesh_factor,
        face_width_mm=b_mm, line_load_N_per_mm=line_load,
        in_fit_range=bool(x1 >= x2 and -0.5 <= x1 + x2 <= 2.0),
    )


# -- dynamic factor K_v, method B (ISO 6336-1:2006 clause 6.5) --------------------------------
#
# Resonance speed and ratio:
#     n_E1 = 30000 / (pi z1) sqrt(c_gamma / m_red)      [min^-1]; c_gamma N/(mm um), m_red kg/mm
#     N    = n1 / n_E1
# m_red is the mass of the pair per unit face width reduced to the line of action,
# m1* m2* / (m1* + m2*) with m* = J* / r_b^2 (J* the polar moment of inertia per face width).
# Lower limit of the main resonance range (w = F_t K_A / b in N/mm):
#     N_S = 0.5 + 0.35 sqrt(w / 100) for w < 100 N/mm, else 0.85
# With B_p = c' f_pb,eff / w, B_f = c' f_f,eff / w, B_k = |1 - c' C_a / w|,
# f_pb,eff = f_pb - y_p and f_f,eff = f_f - y_f (after running-in):
#     subcritical      N <= N_S:        K_v = N K + 1,  K = C_v1 B_p + C_v2 B_f + C_v3 B_k
#     main resonance   N_S < N <= 1.15: K_v = C_v1 B_p + C_v2 B_f + C_v4 B_k + 1
#     supercritical    N >= 1.5:        K_v = C_v5 B_p + C_v6 B_f + C_v7
#     intermediate     1.15 < N < 1.5:  K_v = K_v(1.5) + (K_v(1.15) - K_v(1.5)) (1.5 - N) / 0.35
# C_v1..C_v7 depend on the total contact ratio eps_gamma (eps_alpha for spur gears), see
# :func:`cv_coefficients`. The equations and coefficients here agree with two independent
# implementations of the 2006 edition read for this module; no copy of the standard was at
# hand, and no worked example with every input and its printed K_v was found (tests check
# each range by hand and the continuity at the range boundaries instead).

#: ISO 6336-1 speed ranges, by resonance ratio N
KV_RANGES = ("subcritical", "main resonance", "intermediate", "supercritical")


def resonance_speed_rpm(z1: int, c_gamma_N_per_mm_um: float, m_red_kg_per_mm: float) -> float:
    """n_E1 = 30000 / (pi z1) sqrt(c_gamma / m_red) in min^-1 (ISO 6336-1 method B): the
    pinion speed whose mesh frequency is the natural frequency sqrt(k / m_e) / (2 pi) of
    the pair's relative torsional vibration on rigid bearings."""
    if not (c_gamma_N_per_mm_um > 0 and m_red_kg_per_mm > 0 and z1 > 0):
        raise ValueError("resonance_speed_rpm: z1, c_gamma and m_red must be > 0")
    return 30000.0 / (math.pi * z1) * math.sqrt(c_gamma_N_per_mm_um / m_red_kg_per_mm)


def cv_coefficients(eps_gamma: float) -> tuple[float, float, float, float, float, float, float]:
    """(C_v1, ..., C_v7) of ISO 6336-1 method B for the total contact ratio eps_gamma > 1:
    constants 0.32, 0.34, 0.23, 0.90, 0.47, 0.47 up to eps_gamma = 2; beyond it
    C_v2 = 0.57/(eps - 0.3), C_v3 = 0.096/(eps - 1.56), C_v4 = (0.57 - 0.05 eps)/(eps - 1.44),
    C_v6 = 0.12/(eps - 1.74); C_v7 = 0.75 up to 1.5, 0.125 sin(pi (eps - 2)) + 0.875 up to
    2.5, then 1."""
    e = float(eps_gamma)
    if not e > 1.0:
        raise ValueError(f"eps_gamma = {e:g}: ISO 6336-1 method B needs a contact ratio > 1")
    if e <= 2.0:
        c2, c3, c4, c6 = 0.34, 0.23, 0.90, 0.47
    else:
        c2, c3, c4, c6 = 0.57 / (e - 0.3), 0.096 / (e - 1.56), (0.57 - 0.05 * e) / (e - 1.44), 0.12 / (e - 1.74)
    c7 = 0.75 if e <= 1.5 else (0.125 * math.sin(math.pi * (e - 2.0)) + 0.875 if e <= 2.5 else 1.0)
    return 0.32, c2, c3, c4, 0.47, c6, c7


@dataclass(frozen=True)
class IsoDynamicFactor:
    """ISO 6336-1 method B dynamic factor over pinion speeds (arrays follow ``speed_rpm``)."""
    speed_rpm: Any             # numpy array (min^-1)
    K_v: Any                   # numpy array
    N: Any                     # numpy array, resonance ratio n1 / n_E1
    range_name: tuple          # per speed: one of KV_RANGES
    n_E1_rpm: float
    N_S: float
    B_p: float
    B_f: float
    B_k: float
    C_v: tuple
    line_load_N_per_mm: float  # w = F_t K_A / b


def dynamic_factor(speed_rpm, z1: int, c_gamma_N_per_mm_um: float, c_prime_N_per_mm_um: float,
                   m_red_kg_per_mm: float, line_load_N_per_mm: float, f_pb_eff_um: float,
                   f_f_eff_um: float, C_a_um: float, eps_gamma: float) -> IsoDynamicFactor:
    """K_v of ISO 6336-1 method B at each pinion speed (equations above the function).

    ``line_load_N_per_mm`` = F_t K_A / b with F_t the nominal tangential load at the
    reference circle; stiffnesses per unit face width in N/(mm um); deviations in um."""
    import numpy as np

    if not line_load_N_per_mm > 0:
        raise ValueError(f"line load = {line_load_N_per_mm:g} N/mm: must be > 0")
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


def iso1328_deviations_um(module_m: float, reference_diameter_m: float, grade: int) -> tuple[float, float]:
    """(f_pt, f_f_alpha) in um of ISO 1328-1:1995 accuracy ``grade`` (1-12): the grade-5
    values f_pt = 0.3 (m + 0.4 sqrt(d)) + 4 and f_f_alpha = 2.5 sqrt(m) + 0.17 sqrt(d) + 0.5
    (m, d in mm) times 2^((Q - 5) / 2), rounded as ISO 1328-1 prescribes (above 10 um to
    whole um, 5-10 um to 0.5 um, below 5 um to 0.1 um)."""
    m, d = module_m * 1e3, reference_diameter_m * 1e3
    step = 2.0 ** ((grade - 5) / 2.0)

    def rnd(x: float) -> float:
        q = 1.0 if x > 10 else (0.5 if x >= 5 else 0.1)
        return round(round(x / q) * q, 1)
    return rnd((0.3 * (m + 0.4 * math.sqrt(d)) + 4.0) * step), rnd((2.5 * math.sqrt(m) + 0.17 * math.sqrt(d) + 0.5) * step)
