"""Flank deviations from the nominal involute: profile modifications and measured
deviations, per gear, as material removed along the flank normal.

Wear (geometry.wear) already describes a flank as "material removed along the normal";
this module gives the same quantity for the other deviations a real gear has, so every
stiffness stage (analytic load sharing, resolved pair FE, calibrated tables) takes them
through one function, :func:`modification_on_line_of_action`. Sign: a positive depth
means material removed (the flank lies inside the nominal involute); a negative one,
material added (measured deviations only).

Profile modifications (ISO 21771:2007, 4.4; the linear and parabolic shapes of
ISO/TR 10064-1 and of Harris' relief studies) are defined along the roll length
L(R) = sqrt(R^2 - r_b^2) (m), the distance along the line of action: one unit of roll
length is one unit of travel of the contact point, so a relief that is linear in L is
linear in time at constant speed and the kinematic transmission error of a linear
relief is piecewise linear in the pinion angle (the "triangle" of the tests).

    tip relief:  C(R) = C_a ((L(R) - L_s) / (L_a - L_s))^p   for R >= R_s, else 0
    root relief: C(R) = C_f ((L_s - L(R)) / (L_s - L_N))^p   for R <= R_s, else 0

with p = 1 (linear) or 2 (parabolic), R_s the start radius, L_a the roll length at the
tip radius and L_N at the start of active profile (SAP, the active root diameter d_Nf
at the nominal centre distance). The root relief is held at C_f below the SAP (the
mating tip corner meets the flank there only in extended contact).

Measured deviations: (diameter, deviation) samples of one flank, positive = material
removed. Interpolated linearly in the diameter; outside the measured range the end
values are held (a profile trace usually stops short of the tip and of the SAP, ISO
1328-1 evaluation range) and :func:`flank_warnings` says so.

Assumption shared with the wear model: a deviation enters the load sharing as an
initial gap along the line of action (first order: tens of um against a 1-3 um elastic
approach) and leaves the tooth's body compliance at its nominal value (its effect on
the compliance is 1e-3 relative; the pair FE documents the same choice).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearwear.core.validation import Field, fail, fail_range

from .kinematics import MeshGeometry
from .spec import PairSpec
from .wear import MAX_DEPTH_FRACTION

SHAPES = ("linear", "parabolic")
#: the largest relief amount accepted: the tip relief of a gear rarely exceeds 0.02 m_n
#: (ISO/TR 10064-1 gives 0.01-0.03 m_n); beyond a millimetre it is no longer a modification
MAX_RELIEF_M = 1e-3


@dataclass(frozen=True)
class Relief:
    """A tip or root relief of one gear: ``amount_m`` (C_a or C_f, m) at the tip (tip
    relief) or at the SAP (root relief), starting at ``start_diameter_m``, shape linear or
    parabolic in the roll length."""

    amount_m: float
    start_diameter_m: float
    shape: str = "linear"


@dataclass(frozen=True)
class Deviation:
    """A measured profile deviation of one flank: diameters (m, increasing) and the
    material removed there (m). Tuples, so the spec is hashable (curves are cached)."""

    diameter_m: tuple[float, ...]
    depth_m: tuple[float, ...]
    source: str = ""


@dataclass(frozen=True)
class FlankSpec:
    """Per gear (pinion, gear): tip relief, root relief and measured deviation (None:
    absent). Every field applies to all teeth of its gear."""

    tip_relief: tuple[Relief | None, Relief | None] = (None, None)
    root_relief: tuple[Relief | None, Relief | None] = (None, None)
    deviation: tuple[Deviation | None, Deviation | None] = (None, None)

    @property
    def is_nominal(self) -> bool:
        return all(x is None for x in (*self.tip_relief, *self.root_relief, *self.deviation))

    def label(self) -> str:
        parts = []
        for name, rel in (("tip", self.tip_relief), ("root", self.root_relief)):
            for i, r in enumerate(rel):
                if r is not None:
                    parts.append(f"{name}{i}:{r.amount_m * 1e6:g}um")
        parts += [f"dev{i}" for i, d in enumerate(self.deviation) if d is not None]
        return "+".join(parts) or "nominal"


def roll_length_m(base_radius_m: float, radius_m) -> np.ndarray:
    """L(R) = sqrt(R^2 - r_b^2) (m), the involute's roll length; 0 below the base circle."""
    R = np.asarray(radius_m, dtype=float)
    return np.sqrt(np.maximum(R * R - base_radius_m**2, 0.0))


def sap_radius_m(pair: PairSpec, gear_index: int) -> float:
    """Start of active profile of gear ``gear_index`` at the nominal centre distance (m)."""
    return MeshGeometry(pair, pair.centre_distance_m).start_of_active_profile_m[gear_index]


def relief_depth_m(relief: Relief, pair: PairSpec, gear_index: int, kind: str, radius_m) -> np.ndarray:
    """Depth (m) of a tip (``kind`` = "tip") or root ("root") relief at radii ``radius_m``."""
    g = pair.gear(gear_index)
    rb = g.base_radius_m
    L = roll_length_m(rb, radius_m)
    Ls = float(roll_length_m(rb, 0.5 * relief.start_diameter_m))
    p = 1.0 if relief.shape == "linear" else 2.0
    if kind == "tip":
        La = float(roll_length_m(rb, g.tip_radius_m))
        t = np.clip((L - Ls) / (La - Ls), 0.0, None)
    else:
        LN = float(roll_length_m(rb, sap_radius_m(pair, gear_index)))
        t = np.clip((Ls - L) / (Ls - LN), 0.0, 1.0)
    return relief.amount_m * t**p


def deviation_depth_m(dev: Deviation, radius_m) -> np.ndarray:
    """Measured deviation (m, + = removed) at radii ``radius_m``: linear in the diameter,
    end values held outside the measured range."""
    return np.interp(2.0 * np.asarray(radius_m, dtype=float), dev.diameter_m, dev.depth_m)


def modification_depth_m(flank: FlankSpec | None, pair: PairSpec, gear_index: int, radius_m) -> np.ndarray:
    """Total depth (m, + = material removed) of the modifications and measured deviation
    of gear ``gear_index`` at radii ``radius_m``: their sum (they add, as the issue of a
    relieved flank that was then measured)."""
    R = np.asarray(radius_m, dtype=float)
    out = np.zeros_like(R)
    if flank is None:
        return out
    tip, root, dev = flank.tip_relief[gear_index], flank.root_relief[gear_index], flank.deviation[gear_index]
    if tip is not None:
        out = out + relief_depth_m(tip, pair, gear_index, "tip", R)
    if root is not None:
        out = out + relief_depth_m(root, pair, gear_index, "root", R)
    if dev is not None:
        out = out + deviation_depth_m(dev, R)
    return out


def modification_on_line_of_action(flank: FlankSpec | None, mesh: MeshGeometry, d_m) -> tuple[np.ndarray, np.ndarray]:
    """(pinion, gear) depths (m) at LOA positions ``d_m``: each flank at its own contact
    radius, r_1 = sqrt(r_b1^2 + d^2), r_2 = sqrt(r_b2^2 + (T1T2 - d)^2). Their sum is the
    initial gap of a pair at d (both measured along the common normal, the LOA)."""
    d = np.asarray(d_m, dtype=float)
    return (
        modification_depth_m(flank, mesh.pair, 0, mesh.pinion_radius_at(d)),
        modification_depth_m(flank, mesh.pair, 1, mesh.gear_radius_at(d)),
    )


# -- checks --------------------------------------------------------------------------


def half_thickness_m(g, radius_m: float) -> float:
    """Half the nominal arc tooth thickness (m) at a radius on the involute (ISO 21771):
    r (s / (2 r_p) + inv(alpha) - inv(alpha_r)), cos(alpha_r) = r_b / r."""
    from .spec import inv

    a_r = math.acos(min(1.0, g.base_radius_m / radius_m))
    return radius_m * (g.pitch_thickness_m / (2.0 * g.pitch_radius_m) + inv(g.pressure_angle_rad) - inv(a_r))


def check_flank(pair: PairSpec, flank: FlankSpec) -> None:
    """Refuse modifications that do not fit the flank, naming this layer's keys
    (``tip_relief.start_diameter_m[i]``, ``root_relief.start_diameter_m[i]``,
    ``tip_relief.amount_m[i]``, ``deviation.diameter_m[i]``; the app renames them):

    * a tip relief starts between the SAP and the tip diameter (exclusive);
    * a root relief starts between the SAP and the tip, below the tip relief's start;
    * amounts in [0, 1] mm;
    * measured diameters strictly increasing, finite, and overlapping the active flank.
    """
    for i in (0, 1):
        g = pair.gear(i)
        d_sap, d_tip = 2.0 * sap_radius_m(pair, i), 2.0 * g.tip_radius_m
        active = Field("m", d_sap, d_tip, lo_open=True, hi_open=True)
        tip, root, dev = flank.tip_relief[i], flank.root_relief[i], flank.deviation[i]
        for name, rel in (("tip_relief", tip), ("root_relief", root)):
            if rel is None:
                continue
            if rel.shape not in SHAPES:
                raise fail(f"{name}.shape[{i}]", repr(rel.shape), "", f"must be one of {', '.join(SHAPES)}")
            if not (0.0 <= rel.amount_m <= MAX_RELIEF_M):
                raise fail_range(f"{name}.amount_m[{i}]", rel.amount_m, Field("m", 0.0, MAX_RELIEF_M))
            if not (d_sap < rel.start_diameter_m < d_tip):
                raise fail_range(
                    f"{name}.start_diameter_m[{i}]",
                    rel.start_diameter_m,
                    active,
                    f"the active flank of the {g.name} from its SAP to its tip",
                )
            # the relief is largest at the tip (tip relief) or the SAP (root relief): it may take
            # at most the share of the half tooth thickness there that wear may (geometry.wear)
            r_end = g.tip_radius_m if name == "tip_relief" else 0.5 * d_sap
            limit = MAX_DEPTH_FRACTION * half_thickness_m(g, r_end)
            if rel.amount_m > limit:
                raise fail_range(
                    f"{name}.amount_m[{i}]",
                    rel.amount_m,
                    Field("m", 0.0, limit),
                    f"at most {MAX_DEPTH_FRACTION:.3g} of the {g.name}'s half tooth thickness "
                    f"({half_thickness_m(g, r_end) * 1e3:.4g} mm) at the "
                    f"{'tip' if name == 'tip_relief' else 'start of active profile'}, where the "
                    "relief is largest (more would cut through the tooth)",
                )
        if tip is not None and root is not None and not root.start_diameter_m < tip.start_diameter_m:
            raise fail_range(
                f"root_relief.start_diameter_m[{i}]",
                root.start_diameter_m,
                Field("m", d_sap, tip.start_diameter_m, True, True),
                "below the start of the tip relief",
            )
        if dev is not None:
            _check_deviation(dev, i, g.name, d_sap, d_tip)


def _check_deviation(dev: Deviation, i: int, name: str, d_sap: float, d_tip: float) -> None:
    """One measured trace: >= 2 rows, finite, diameters strictly increasing, overlapping
    the active flank (SAP to tip), |deviation| <= 1 mm. Errors name the file."""
    key, what = f"deviation.diameter_m[{i}]", repr(dev.source or "deviation")
    dia = np.asarray(dev.diameter_m, float)
    dep = np.asarray(dev.depth_m, float)
    if dia.size < 2 or dia.shape != dep.shape:
        raise fail(key, what, "", f"needs at least 2 rows of diameter_mm and deviation_um, got {dia.size}")
    if not (np.all(np.isfinite(dia)) and np.all(np.isfinite(dep))):
        raise fail(key, what, "", "every value must be a finite number")
    if np.any(np.diff(dia) <= 0):
        k = int(np.flatnonzero(np.diff(dia) <= 0)[0]) + 1
        raise fail(
            key,
            what,
            "",
            f"diameter_mm must be strictly increasing (row {k + 1}: {dia[k] * 1e3:g} mm after {dia[k - 1] * 1e3:g} mm)",
        )
    if dia[-1] <= d_sap or dia[0] >= d_tip:
        raise fail(
            key,
            what,
            "",
            f"diameters {dia[0] * 1e3:.6g}-{dia[-1] * 1e3:.6g} mm must overlap the active "
            f"flank of the {name}, {d_sap * 1e3:.6g}-{d_tip * 1e3:.6g} mm",
        )
    if np.max(np.abs(dep)) > MAX_RELIEF_M:
        k = int(np.argmax(np.abs(dep)))
        raise fail(
            key,
            what,
            "",
            f"deviation_um = {dep[k] * 1e6:g} um in row {k + 1}: must be in "
            f"[{-MAX_RELIEF_M * 1e6:g}, {MAX_RELIEF_M * 1e6:g}] um",
        )


def flank_warnings(pair: PairSpec, flank: FlankSpec | None) -> list[str]:
    """One-line notes: a measured deviation that does not cover the active flank (the
    end values are held beyond it)."""
    if flank is None:
        return []
    out = []
    for i, dev in enumerate(flank.deviation):
        if dev is None:
            continue
        g = pair.gear(i)
        d_sap, d_tip = 2.0 * sap_radius_m(pair, i), 2.0 * g.tip_radius_m
        lo, hi = dev.diameter_m[0], dev.diameter_m[-1]
        if lo > d_sap or hi < d_tip:
            out.append(
                f"the measured deviation of the {g.name}{' (' + dev.source + ')' if dev.source else ''} "
                f"covers diameters {lo * 1e3:.4g}-{hi * 1e3:.4g} mm of the active flank "
                f"{d_sap * 1e3:.4g}-{d_tip * 1e3:.4g} mm; its end values are held beyond"
            )
    return out


def hpstc_diameters_m(mesh: MeshGeometry) -> tuple[float, float]:
    """Diameters (m) of the highest point of single tooth contact (HPSTC) of the pinion
    (at d_D = d_A + p_b) and of the gear (at d_B = d_E - p_b): where a long tip relief
    starts (contact ratio >= 1)."""
    dB, dD = mesh.single_contact_limits_m
    return 2.0 * float(mesh.pinion_radius_at(dD)), 2.0 * float(mesh.gear_radius_at(dB))


def lpstc_diameters_m(mesh: MeshGeometry) -> tuple[float, float]:
    """Diameters (m) of the lowest point of single tooth contact (LPSTC) of the pinion
    (at d_B = d_E - p_b) and of the gear (at d_D = d_A + p_b), contact ratio >= 1."""
    dB, dD = mesh.single_contact_limits_m
    return 2.0 * float(mesh.pinion_radius_at(dB)), 2.0 * float(mesh.gear_radius_at(dD))


def is_nominal(flank: FlankSpec | None) -> bool:
    return flank is None or flank.is_nominal


__all__ = [
    "Relief",
    "Deviation",
    "FlankSpec",
    "SHAPES",
    "MAX_RELIEF_M",
    "roll_length_m",
    "relief_depth_m",
    "deviation_depth_m",
    "modification_depth_m",
    "modification_on_line_of_action",
    "check_flank",
    "flank_warnings",
    "hpstc_diameters_m",
    "lpstc_diameters_m",
    "is_nominal",
    "sap_radius_m",
]
