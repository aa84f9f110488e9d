"""Where and how the mesh force loads a tooth, from the true (nominal or worn) profile.

Tooth frame: the tooth axis is +y (the gear frame of ``geometry.profile``), the loaded
flank is the right flank (x > 0). A contact at radius R on the flank is at
(x_F, y_F) = R (sin beta(R), cos beta(R)) with beta the flank half-angle there. The
mesh force acts along the line of action, i.e. along the inward involute normal:

    F = -F (cos w, sin w),   w = alpha_R - beta(R),   cos(alpha_R) = r_b / R

so F cos w bends the tooth (perpendicular to the axis) and F sin w compresses it.
The force line crosses the tooth axis at y_c = y_F - x_F tan(w); the bending moment
on the section at height y is M(y) = F cos(w) (y_c - y) (Weber; Cornell 1981).
On a worn flank the contact point moves inward (beta from the worn profile); the
force direction stays that of the nominal involute (first order in h / R).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .profile import FILLET, INVOLUTE, TIP_LAND, ToothProfile


@dataclass(frozen=True)
class LoadPoints:
    """Load application data for a set of contact radii (arrays of equal length, SI)."""

    radius_m: np.ndarray
    x_m: np.ndarray  # half-thickness offset of the contact point from the tooth axis
    y_m: np.ndarray  # height of the contact point along the tooth axis
    w_rad: np.ndarray  # load angle between the force and the perpendicular to the axis
    y_axis_m: np.ndarray  # where the force line crosses the tooth axis


def load_points(profile: ToothProfile, radius_m) -> LoadPoints:
    """Contact point, load angle and force-line data at contact radii ``radius_m`` (m)."""
    R = np.atleast_1d(np.asarray(radius_m, dtype=float))
    beta = profile.half_angle_at_radius(R)
    rb = profile.gear.base_radius_m
    alpha_R = np.arccos(np.clip(rb / R, -1.0, 1.0))
    w = alpha_R - beta
    x = R * np.sin(beta)  # contact point on the (possibly worn) flank
    y = R * np.cos(beta)
    return LoadPoints(R, x, y, w, y - x * np.tan(w))


def root_height_m(profile: ToothProfile) -> float:
    """y_M (m): the root section of the tooth cantilever is taken at the root circle on
    the tooth axis, y_M = r_f (Sainsot et al. 2004; Weber)."""
    return profile.gear.root_radius_m


def root_section(profile: ToothProfile) -> tuple[float, float]:
    """(y_M, half thickness at y_M) (m) of the root section (:func:`root_height_m`)."""
    y_M = root_height_m(profile)
    return y_M, float(half_thickness_at_height(profile, np.array([y_M]))[0])


def flank_height_table(profile: ToothProfile) -> tuple[np.ndarray, np.ndarray]:
    """Knots (y_m, x_m) of the loaded flank's half thickness x(y) along the tooth axis:
    the profile polyline from the root up to the tip, strictly increasing in y."""
    sel = (profile.region == FILLET) | (profile.region == INVOLUTE) | (profile.region == TIP_LAND)
    xs, ys = profile.xy[sel, 0], profile.xy[sel, 1]
    # along the flank from root to tip the height grows; keep the monotone part
    keep = np.concatenate([[True], np.diff(np.maximum.accumulate(ys)) > 0])
    return ys[keep], xs[keep]


def half_thickness_at_height(profile: ToothProfile, y_m) -> np.ndarray:
    """Half tooth thickness x(y) of the loaded flank at heights y (m) along the tooth
    axis (sections perpendicular to the axis), interpolated on the profile polyline
    between the root section and the tip."""
    ys, xs = flank_height_table(profile)
    return np.interp(np.asarray(y_m, dtype=float), ys, xs)


def thickness_table(loaded: ToothProfile, opposite: ToothProfile | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Knots (y_m, t_m) of the full tooth thickness t(y) = x_loaded(y) + x_opposite(y)
    (``opposite`` defaults to ``loaded``: a symmetric tooth).

    Both half thicknesses are piecewise linear in y (np.interp, constant beyond their
    ends), so their sum is piecewise linear on the union of the knots: one
    interpolation in this table equals the sum of the two (to round-off)."""
    yl, xl = flank_height_table(loaded)
    if opposite is None or opposite is loaded:
        return yl, 2.0 * xl  # doubling is exact: bit-identical to x + x
    yo, xo = flank_height_table(opposite)
    y = np.union1d(yl, yo)
    return y, np.interp(y, yl, xl) + np.interp(y, yo, xo)
