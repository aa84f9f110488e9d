"""Flank wear depth and worn profiles.

Both models give the depth h removed along the flank normal at each point of the
active involute, for a gear turning N contacts (each tooth meets the mating gear once
per revolution). Sliding at a flank point follows from the specific sliding

    zeta_1 = 1 - (rho_2 / rho_1) (z_1 / z_2),   zeta_2 = 1 - (rho_1 / rho_2) (z_2 / z_1)

with rho_1 = d and rho_2 = |T1T2| - d the involute curvature radii at the contact
point d on the line of action (kinematics module). zeta = 0 at the pitch point
(pure rolling) and |zeta| grows toward tip and root. While the Hertz band (half-width
a) passes a flank point, the surfaces slide past each other by 2 a |zeta|.

(a) Archard (default; Flodin & Andersson, Wear 207, 1997, "single point"):
    dh = k p ds with ds = |zeta| dx. Integrating the Hertz pressure p(x) =
    p0 sqrt(1 - x^2 / a^2) over one passage of the band gives h per contact =
    k |zeta| int p dx; the integral is taken with the load sharing at the band's
    position (Gauss-Chebyshev), so it equals k |zeta| w inside a load zone and ramps
    over the band width 2 a where single and double contact alternate.
    k in m^2/N (Pa^-1).

(b) Paper Eq. 1 (Zhang et al. 2019, after Wang et al. 2013). Read with consistent
    units, the square root is a / 2 with a the Hertz half-width
    a = sqrt(4 w R / (pi E')), w = 2 T / (psi m^2 z cos(alpha)) the normal load per
    width (T = 9.55e6 P / n is the torque in N mm from power P in kW and speed n in
    rpm, psi m = b the face width), 1/E' = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 and
    R = 1 / (1/rho1 + 1/rho2). Eq. 1 is then h = 4 I_h mu (n t) (a / 2) = I_h (2 a |zeta|) N:
    I_h (dimensionless "wear characteristic") is the depth removed per unit sliding
    distance, mu the slide coefficient (= specific sliding zeta) and n t = N the
    number of contacts (n in rpm, t in minutes).

The load per pair w follows the static load sharing of the path of contact: the
whole load in single contact, half of it in double contact, a third in the triple
contact of a contact ratio above 2 (equal sharing; the stiffness-based sharing is the
analytic stage's business). The models are linear in
N: the profile change does not feed back into the pressure (documented limit).

Named phases are defined by the maximum depth on the pinion flank (the shape comes
from the chosen model): unworn 0, mild 10 um, severe 30 um (assumed: the paper gives
no depths; 30 um is about 0.4 % of the 7.85 mm pitch thickness, well inside the
"mild to moderate" range reported by Flodin & Andersson).
The worn profile is the nominal one moved inward along the normal by h(s); h is
tapered to zero over ``taper_m`` beyond the ends of the active profile so the worn
flank stays continuous (a step of h at the SAP otherwise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import numpy as np

from gearwear.core.validation import Field, fail, fail_range, fail_text

from .kinematics import MeshGeometry
from .profile import INVOLUTE, ToothProfile, tooth_profile
from .spec import PairSpec

PHASE_DEPTHS_M = {"unworn": 0.0, "mild": 10e-6, "severe": 30e-6}
WEAR_MODELS = ("archard", "paper_eq1")

#: Largest accepted wear depth, as a fraction of the tooth's half thickness at the radius of
#: the deepest wear. Beyond a third of the local half thickness the tooth has lost a third
#: of its section there and the flank's shape is no longer a small offset of the involute:
#: the wear laws here do not feed the profile change back into the pressure (module doc),
#: the worn flank no longer meshes near its nominal path, and the slice/FE stiffness models
#: would describe a different tooth. The named phases are far below it (severe 30 um is
#: about 1/40 of the paper pair's half thickness near the tip).
MAX_DEPTH_FRACTION = 1.0 / 3.0


@dataclass(frozen=True)
class WearSpec:
    """How much wear: a named phase, an explicit maximum depth, or running hours.

    Exactly one of phase / max_depth_m / hours is set. The model gives the shape
    (and, for ``hours``, the magnitude). Loads use torque_Nm (N m) of the pinion
    (driver); speed_rpm (rpm) counts the contacts of ``hours`` only (:func:`cycles`): a
    phase or a depth fixes the magnitude, and the profile is the same at any speed.
    """

    phase: str | None = None
    max_depth_m: float | None = None
    hours: float | None = None
    model: str = "archard"
    archard_k_m2_per_N: float = 5.3e-16  # Flodin & Andersson (1997), boundary-lubricated steel
    wear_intensity: float = 1e-8  # I_h of Eq. 1 (dimensionless), assumed
    torque_Nm: float = 40.0
    speed_rpm: float = 1200.0
    taper_m: float = 0.2e-3

    @property
    def is_unworn(self) -> bool:
        if self.phase is not None:
            return PHASE_DEPTHS_M[self.phase] == 0.0
        if self.max_depth_m is not None:
            return self.max_depth_m == 0.0
        return self.hours == 0.0

    @property
    def label(self) -> str:
        if self.phase is not None:
            return self.phase
        if self.max_depth_m is not None:
            return f"{self.max_depth_m * 1e6:g}um"
        return f"{self.hours:g}h"


# -- sliding and contact mechanics on the line of action --------------------------


def specific_sliding(mesh: MeshGeometry, d) -> tuple[np.ndarray, np.ndarray]:
    """(zeta_1, zeta_2) at LOA positions d (m); zero at the pitch point."""
    d = np.asarray(d, dtype=float)
    z1, z2 = mesh.pair.teeth
    rho1 = d
    rho2 = mesh.line_of_action_m - d
    with np.errstate(divide="ignore", invalid="ignore"):
        zeta1 = 1.0 - (rho2 / rho1) * (z1 / z2)
        zeta2 = 1.0 - (rho1 / rho2) * (z2 / z1)
    return zeta1, zeta2


def load_share(mesh: MeshGeometry, d) -> np.ndarray:
    """Fraction of the normal load carried by a pair at d: 1 / n with n the number of
    pairs on the path of contact (equal sharing: 1 in single, 1/2 in double, 1/3 in
    triple contact of a contact ratio above 2), 0 outside the path of contact."""
    d = np.asarray(d, dtype=float)
    A, E, pb = mesh.path_start_m, mesh.path_end_m, mesh.base_pitch_m
    inside = (d >= A) & (d <= E)
    # the other pairs sit k base pitches ahead and behind; every one on the path shares
    others = np.zeros(d.shape)
    k = 1
    while k * pb <= E - A:
        for dk in (d - k * pb, d + k * pb):
            others += (dk >= A) & (dk <= E)
        k += 1
    return np.where(inside, 1.0 / (1.0 + others), 0.0)


def hertz_half_width(mesh: MeshGeometry, d, load_per_width_N_per_m) -> np.ndarray:
    """Hertz line-contact half-width a = sqrt(4 w R / (pi E')) (m) at LOA position d."""
    m1, m2 = mesh.pair.materials
    if m1 == m2:  # E* = E / (2 (1 - nu^2)), bit for bit as before per-gear materials
        e_star = m1.youngs_modulus_Pa / (2.0 * (1.0 - m1.poisson_ratio**2))
    else:
        e_star = mesh.pair.contact_modulus_Pa
    d = np.asarray(d, dtype=float)
    R = d * (mesh.line_of_action_m - d) / mesh.line_of_action_m
    return np.sqrt(4.0 * np.asarray(load_per_width_N_per_m) * np.maximum(R, 0.0) / (math.pi * e_star))


def hertz_load_integral(a, p0) -> np.ndarray:
    """int_{-a}^{a} p0 sqrt(1 - x^2/a^2) dx = pi a p0 / 2 (N/m)."""
    return 0.5 * np.pi * np.asarray(a) * np.asarray(p0)


def _semicircle_cdf(t):
    """Fraction of a semi-elliptical (Hertz) pressure distribution on [-1, t]:
    1/2 + (t sqrt(1 - t^2) + asin t) / pi."""
    t = np.clip(t, -1.0, 1.0)
    return 0.5 + (t * np.sqrt(1.0 - t * t) + np.arcsin(t)) / np.pi


def load_share_breaks(mesh: MeshGeometry) -> np.ndarray:
    """LOA positions where the static load sharing changes (A, E and their images
    one or more base pitches away inside the path)."""
    A, E, pb = mesh.path_start_m, mesh.path_end_m, mesh.base_pitch_m
    pts = [A, E]
    k = 1
    while A + k * pb < E:
        pts += [A + k * pb, E - k * pb]
        k += 1
    return np.unique(np.array(pts))


def band_load_per_width(mesh: MeshGeometry, d, spec: WearSpec) -> tuple[np.ndarray, np.ndarray]:
    """(w_bar, a): load per width that a flank point at d effectively sees while the
    Hertz band passes over it, and the band half-width a.

    While the band (half-width a, semi-elliptical pressure) travels over the point, the
    pair's load follows the load sharing at the band's position:

        int p dx = (2 / pi) int_{-1}^{1} sqrt(1 - t^2) w(d + a t) dt = w_bar.

    The load sharing w is piecewise constant, so the integral is exact with the
    semicircle CDF. This smears the single/double-contact steps over the band width
    instead of printing them as steps into the worn profile. The band width is that of
    the full load (it only sets the smoothing length), so w_bar is continuous in d.
    """
    d = np.asarray(d, dtype=float)
    b = mesh.pair.face_width_m
    Fn = spec.torque_Nm / mesh.pair.gear(0).base_radius_m
    a = hertz_half_width(mesh, d, Fn / b)
    a_safe = np.where(a > 0, a, 1e-300)
    br = load_share_breaks(mesh)
    w_bar = np.zeros_like(d)
    for lo, hi in zip(br[:-1], br[1:]):
        share = float(load_share(mesh, np.array([0.5 * (lo + hi)]))[0])
        w_bar += share * (_semicircle_cdf((hi - d) / a_safe) - _semicircle_cdf((lo - d) / a_safe))
    return Fn / b * w_bar, a


def depth_per_contact(mesh: MeshGeometry, d, spec: WearSpec) -> tuple[np.ndarray, np.ndarray]:
    """Wear depth (m) per contact on pinion and gear flank at LOA positions d."""
    d = np.asarray(d, dtype=float)
    w_bar, a = band_load_per_width(mesh, d, spec)
    zeta1, zeta2 = specific_sliding(mesh, d)
    inside = (d >= mesh.path_start_m) & (d <= mesh.path_end_m)
    if spec.model == "archard":
        # dh = k p ds with ds = |zeta| dx: h = k |zeta| int p dx = k |zeta| w_bar
        h1 = spec.archard_k_m2_per_N * np.abs(zeta1) * w_bar
        h2 = spec.archard_k_m2_per_N * np.abs(zeta2) * w_bar
    else:
        # Eq. 1: I_h times the sliding distance 2 a |zeta| per contact, a at the band load
        a = hertz_half_width(mesh, d, w_bar)
        h1 = spec.wear_intensity * 2.0 * a * np.abs(zeta1)
        h2 = spec.wear_intensity * 2.0 * a * np.abs(zeta2)
    h1 = np.where(inside, np.nan_to_num(h1), 0.0)
    h2 = np.where(inside, np.nan_to_num(h2), 0.0)
    return h1, h2


def cycles(spec: WearSpec, mesh: MeshGeometry) -> tuple[float, float]:
    """Contacts per tooth (pinion, gear) after spec.hours at spec.speed_rpm."""
    n1 = spec.speed_rpm * 60.0 * (spec.hours or 0.0)
    z1, z2 = mesh.pair.teeth
    return n1, n1 * z1 / z2


def wear_on_line_of_action(mesh: MeshGeometry, spec: WearSpec, d) -> tuple[np.ndarray, np.ndarray]:
    """Wear depth (m) of pinion and gear flank at LOA positions d (m) for ``spec``."""
    d = np.asarray(d, dtype=float)
    h1c, h2c = depth_per_contact(mesh, d, spec)
    if spec.hours is not None:
        n1, n2 = cycles(spec, mesh)
        return h1c * n1, h2c * n2
    target = PHASE_DEPTHS_M[spec.phase] if spec.phase is not None else spec.max_depth_m
    if target is None:
        raise fail_text(None, "WearSpec: exactly one of phase, max_depth_m, hours must be set")
    if target == 0.0:
        return np.zeros_like(d), np.zeros_like(d)
    # scale so the pinion's maximum over its whole active flank equals the target
    z1, z2 = mesh.pair.teeth
    scale = target / _flank_reference(mesh, spec)[0]
    return h1c * scale, h2c * scale * z1 / z2


def flank_depth(profile: ToothProfile, gear_index: int, mesh: MeshGeometry, spec: WearSpec) -> np.ndarray:
    """Wear depth (m) at every point of ``profile`` (pinion: gear_index 0, gear: 1).

    Non-zero on the active involute only, tapered linearly to zero over
    ``spec.taper_m`` of arc length beyond its ends.
    """
    if spec.is_unworn:
        return np.zeros_like(profile.s)
    rb = profile.gear.base_radius_m
    u = np.where(profile.region == INVOLUTE, profile.roll, np.nan)
    d = rb * u if gear_index == 0 else mesh.line_of_action_m - rb * u
    h1, h2 = wear_on_line_of_action(mesh, spec, np.nan_to_num(d, nan=-1.0))
    h = h1 if gear_index == 0 else h2
    h = np.where(np.isfinite(u), h, 0.0)
    if spec.taper_m > 0 and np.any(h > 0):
        active = np.flatnonzero(h > 0)
        i0, i1 = active[0], active[-1]
        s = profile.s
        below = np.arange(len(s)) < i0
        above = np.arange(len(s)) > i1
        ramp_lo = np.clip(1.0 - (s[i0] - s) / spec.taper_m, 0.0, 1.0) * h[i0]
        ramp_hi = np.clip(1.0 - (s - s[i1]) / spec.taper_m, 0.0, 1.0) * h[i1]
        h = np.where(below, ramp_lo, np.where(above, ramp_hi, h))
    return h


# Value memoisation, not identity: MeshGeometry (PairSpec, float) and WearSpec are frozen
# dataclasses hashed and compared by field values, and the result is a tuple of floats, so
# equal inputs share an entry and no caller can change a cached value.
@lru_cache(maxsize=64)
def _flank_reference(mesh: MeshGeometry, spec: WearSpec) -> tuple[float, float, float]:
    """(largest pinion depth per contact, LOA position of the pinion's and of the gear's
    deepest wear) on a dense grid over the path of contact. Cached: it depends only on
    the (hashable, frozen) mesh and wear spec, and every worn stiffness curve needs it."""
    d = np.linspace(mesh.path_start_m, mesh.path_end_m, 40001)
    h1, h2 = depth_per_contact(mesh, d, spec)
    return float(np.max(h1)), float(d[np.argmax(h1)]), float(d[np.argmax(h2)])


@lru_cache(maxsize=64)
def _flank_extremes(mesh: MeshGeometry, spec: WearSpec) -> tuple[float, float, float, float]:
    """(largest pinion depth per contact, its LOA position, largest gear depth per
    contact, its LOA position) on the grid of :func:`_flank_reference`."""
    d = np.linspace(mesh.path_start_m, mesh.path_end_m, 40001)
    h1, h2 = depth_per_contact(mesh, d, spec)
    i1, i2 = int(np.argmax(h1)), int(np.argmax(h2))
    return float(h1[i1]), float(d[i1]), float(h2[i2]), float(d[i2])


def max_depths_m(mesh: MeshGeometry, spec: WearSpec) -> tuple[float, float]:
    """Largest wear depth (m) on the pinion and on the gear flank for ``spec`` (the
    maxima of :func:`wear_on_line_of_action` over the path of contact)."""
    if spec.is_unworn:
        return 0.0, 0.0
    h1, _, h2, _ = _flank_extremes(mesh, spec)
    z1, z2 = mesh.pair.teeth
    if spec.hours is not None:
        n1, n2 = cycles(spec, mesh)
        return h1 * n1, h2 * n2
    target = PHASE_DEPTHS_M[spec.phase] if spec.phase is not None else spec.max_depth_m
    assert target is not None
    return target, h2 * (target / h1) * z1 / z2


def half_thickness_at_contact_m(mesh: MeshGeometry, gear_index: int, d: float) -> tuple[float, float]:
    """(radius R, half arc tooth thickness s_R / 2) (m) of the nominal involute flank of
    gear ``gear_index`` where it touches LOA position d: roll u = d / r_b1 (pinion) or
    (T1T2 - d) / r_b2 (gear), R = r_b sqrt(1 + u^2), s_R / 2 = R (psi_b - inv(alpha_R))
    with inv(alpha_R) = u - atan(u) and psi_b = s / (2 r) + inv(alpha) (ISO 21771)."""
    g = mesh.pair.gear(gear_index)
    rb = g.base_radius_m
    u = (d if gear_index == 0 else mesh.line_of_action_m - d) / rb
    psi_b = g.pitch_thickness_m / (2.0 * g.pitch_radius_m) + math.tan(g.pressure_angle_rad) - g.pressure_angle_rad
    R = rb * math.sqrt(1.0 + u * u)
    return R, R * (psi_b - (u - math.atan(u)))


def depth_limits(mesh: MeshGeometry, spec: WearSpec) -> dict[str, float]:
    """The deepest wear accepted for this pair: MAX_DEPTH_FRACTION of the local half
    thickness (:func:`half_thickness_at_contact_m`) where each flank wears deepest.

    Returns "pinion_m" and "gear_m" (each flank's own limit, m), "max_depth_m" (the
    largest pinion depth that keeps both flanks within their limits, the quantity a
    phase or ``max_depth_m`` sets), "radius_m" and "half_thickness_m" of the flank that
    sets it, "gear_index", and for ``hours`` "hours" (the running time that reaches it;
    the depth is linear in the time)."""
    h1, d1, h2, d2 = _flank_extremes(mesh, spec)
    z1, z2 = mesh.pair.teeth
    R1, t1 = half_thickness_at_contact_m(mesh, 0, d1)
    R2, t2 = half_thickness_at_contact_m(mesh, 1, d2)
    lim1, lim2 = MAX_DEPTH_FRACTION * t1, MAX_DEPTH_FRACTION * t2
    # the pinion depth that brings the gear flank to its limit
    via_gear = lim2 * h1 / (h2 * z1 / z2) if h2 > 0 else math.inf
    i = 0 if lim1 <= via_gear else 1
    out = {
        "pinion_m": lim1,
        "gear_m": lim2,
        "max_depth_m": min(lim1, via_gear),
        "gear_index": float(i),
        "radius_m": (R1, R2)[i],
        "half_thickness_m": (t1, t2)[i],
    }
    per_hour1 = h1 * spec.speed_rpm * 60.0
    per_hour2 = h2 * spec.speed_rpm * 60.0 * z1 / z2
    out["hours"] = min(lim1 / per_hour1 if per_hour1 > 0 else math.inf, lim2 / per_hour2 if per_hour2 > 0 else math.inf)
    return out


def check_wear(mesh: MeshGeometry, spec: WearSpec) -> None:
    """Refuse wear deeper than MAX_DEPTH_FRACTION (1/3) of the tooth's half thickness at
    the radius of the deepest wear, on either flank. Names this layer's parameters:
    ``max_depth_m`` (m), ``hours`` (h) or ``phase``."""
    if spec.is_unworn:
        return
    depth1, depth2 = max_depths_m(mesh, spec)
    lim = depth_limits(mesh, spec)
    if depth1 <= lim["pinion_m"] and depth2 <= lim["gear_m"]:
        return
    name = ("pinion", "gear")[int(lim["gear_index"])]
    frac = Fraction(MAX_DEPTH_FRACTION).limit_denominator(100)
    where = (
        f"{frac} of the {name}'s half tooth thickness ({lim['half_thickness_m'] * 1e3:.3f} mm) at "
        f"r = {lim['radius_m'] * 1e3:.3f} mm, where its flank wears deepest"
    )
    if spec.hours is not None:
        hi = math.floor(lim["hours"] * 1e3) / 1e3
        raise fail_range(
            "hours",
            spec.hours,
            Field("h", 0.0, hi),
            f"the wear would reach {depth1 * 1e6:.4g} um on the pinion and {depth2 * 1e6:.4g} um on "
            f"the gear, beyond {where}",
        )
    hi_m = math.floor(lim["max_depth_m"] * 1e7) / 1e7  # 0.1 um below the limit, so the quoted value is allowed
    if spec.phase is not None:
        raise fail(
            "phase",
            repr(spec.phase),
            "",
            f"its {depth1 * 1e6:g} um exceed {where} (at most {hi_m * 1e6:.4g} um for this pair)",
        )
    raise fail_range("max_depth_m", depth1, Field("m", 0.0, hi_m), "the deepest wear accepted is " + where)


def wear_warnings(mesh: MeshGeometry, spec: WearSpec | None) -> list[str]:
    """One-line warnings about a wear spec that is accepted but outside the documented
    range: running hours whose depth exceeds the 'severe' phase (30 um)."""
    if spec is None or spec.hours is None or spec.is_unworn:
        return []
    d1, d2 = max_depths_m(mesh, spec)
    severe = PHASE_DEPTHS_M["severe"]
    if max(d1, d2) <= severe:
        return []
    return [
        f"wear after {spec.hours:g} h reaches {d1 * 1e6:.4g} um on the pinion and {d2 * 1e6:.4g} um on the gear, "
        f"beyond the 'severe' phase ({severe * 1e6:g} um): the wear model has no profile feedback, so "
        "this depth is an extrapolation"
    ]


def wear_peaks(mesh: MeshGeometry, spec: WearSpec) -> np.ndarray:
    """LOA positions (m) of the deepest wear on the pinion and on the gear flank."""
    return np.array(_flank_reference(mesh, spec)[1:])


def key_roll_angles(mesh: MeshGeometry, gear_index: int, spec: WearSpec | None = None) -> np.ndarray:
    """Roll angles (rad) of the path ends, single-contact limits and pitch point on a
    flank (and the wear peaks), so profiles sample where the wear pattern has its
    extremes and ramps."""
    d = np.array([mesh.path_start_m, *mesh.single_contact_limits_m, mesh.pitch_point_m, mesh.path_end_m])
    if spec is not None and not spec.is_unworn:
        d = np.concatenate([d, wear_peaks(mesh, spec)])
    if gear_index == 0:
        return d / mesh.pair.gear(0).base_radius_m
    return (mesh.line_of_action_m - d) / mesh.pair.gear(1).base_radius_m


def worn_profiles(
    pair: PairSpec, spec: WearSpec, mesh: MeshGeometry | None = None, sag_m: float = 0.2e-6
) -> tuple[tuple[ToothProfile, ToothProfile], tuple[ToothProfile, ToothProfile]]:
    """((nominal pinion, nominal gear), (worn pinion, worn gear)) loaded flanks.

    The wear pattern is computed on the nominal mesh geometry unless ``mesh`` is given.
    """
    mesh = mesh or MeshGeometry(pair, pair.centre_distance_m)
    check_wear(mesh, spec)
    nominal = tuple(
        tooth_profile(g, sag_m=sag_m, extra_roll=key_roll_angles(mesh, i, spec)) for i, g in enumerate(pair.gears)
    )
    worn = tuple(p.worn(flank_depth(p, i, mesh, spec)) for i, p in enumerate(nominal))
    return nominal, worn  # type: ignore[return-value]
