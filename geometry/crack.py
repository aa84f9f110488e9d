"""A straight tooth-root crack on the loaded flank of one tooth (SI units: m, rad).

Convention (Tian 2004; Wu, Zuo & Parey 2008; Chen & Shao 2011)
--------------------------------------------------------------
Tooth frame of ``geometry.profile``: the tooth centre line is +y, the loaded flank is
the right flank (x > 0). The crack is a straight line of length q = ``depth_m``

* from the crack *mouth* C = (x_C, y_C) on the loaded flank's root fillet, the ISO
  6336-3 critical-section point where the fillet tangent makes 30 deg with the centre
  line (:func:`critical_fillet_point`; there the bending stress of the tension side
  peaks and root cracks start),
* inward, toward the centre line and the opposite flank, and downward (toward the
  gear body), at the *crack angle* nu = ``angle_rad`` between the crack line and the
  tooth centre line:

      tip Q = C + q (-sin nu, -cos nu)

so the crack tip lies h_q = x_C - q sin nu from the centre line (Chen Z., Shao Y.,
"Dynamic simulation of spur gear with tooth root crack propagating along tooth width
and crack depth", Engineering Failure Analysis 18(8):2149-2164, 2011, Fig. 3 and
Eq. for h_q; after Tian X., "Dynamic simulation for system response of gearbox
including localized gear faults", MSc thesis, Univ. of Alberta, 2004). nu = 45 deg
is the value used in those papers; nu = 60 deg is perpendicular to the fillet at C.

Allowed range
-------------
* 0 < nu <= pi / 2: nu = 0 is a crack parallel to the centre line (no section is
  reduced in the reference model), nu > pi / 2 would run upward into the tooth.
* 0 < q <= x_C / sin nu: the tip stays on the loaded side of the centre line or on it
  (h_q >= 0), the range of the reference model (its first case; a crack beyond the
  centre line needs a different section model). Inside that range the crack stays in
  the material: left of C every point below the fillet and above the root circle is
  tooth, below the root circle rim, and x >= 0 keeps it off the opposite flank;
  additionally the tip must stay outside the bore, |Q| > r_hub (it only binds for
  nu below about 10 deg).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from gearwear.core.validation import fail

from .loading import flank_height_table
from .polyline import project_to_polyline
from .profile import RackGeometry, ToothProfile, _undercut_intersection, fillet_points

#: ISO 6336-3 critical section: the fillet tangent at 30 deg to the tooth centre line.
CRITICAL_TANGENT_ANGLE_RAD = math.radians(30.0)


@dataclass(frozen=True)
class Crack:
    """Straight root crack on tooth 0's loaded (right) flank.

    depth_m    crack length q (m) along the crack line, from the mouth at the ISO
               30-deg fillet point to the tip
    angle_rad  angle nu (rad) between the crack line and the tooth centre line; the
               crack runs inward and downward, tip = mouth + q (-sin nu, -cos nu)
    """

    depth_m: float
    angle_rad: float = math.radians(45.0)


def _tangent_angle(rack: RackGeometry, phi: float) -> float:
    """Angle (rad) between the fillet tangent at rack position phi and the +y axis,
    tangent taken root -> tip (unit normal n gives t = (-n_y, n_x))."""
    _, n = fillet_points(rack, np.array([phi]))
    tx, ty = -n[0, 1], n[0, 0]
    return math.atan2(abs(tx), ty)


def critical_fillet_point(profile: ToothProfile) -> tuple[float, float, np.ndarray]:
    """(x_m, y_m, tangent) of the ISO 6336-3 critical-section point on the loaded
    (right, x > 0) root fillet of ``profile``: where the fillet tangent makes 30 deg
    with the tooth centre line. ``tangent`` is the unit tangent there, root -> tip.

    The fillet is the exact trochoid of the rack tip round (``geometry.profile``,
    wear does not reach it), parameterised by the rack position phi; the tangent
    angle falls monotonically from 90 deg at the root land to the involute's angle
    at the form circle, and the 30-deg point is found by Brent's method to
    ~1e-15 rad in phi (far below 1e-9 m relative in position).
    """
    g = profile.gear
    rack = RackGeometry.of(g)
    phi0, phi1 = rack.phi_root, rack.phi_tangent
    if profile.undercut:  # the fillet ends where the trochoid meets the involute
        phi1 = _undercut_intersection(rack, g.base_radius_m, profile.psi_b)[0]

    def f(phi: float) -> float:
        return _tangent_angle(rack, phi) - CRITICAL_TANGENT_ANGLE_RAD

    lo, hi = f(phi0), f(phi1)
    if not (lo > 0.0 >= hi):
        raise fail(
            "pressure_angle_rad",
            g.pressure_angle_rad,
            "rad",
            f"the root fillet of {g.name} has no point with its tangent at 30 deg to the centre "
            f"line (tangent angle {math.degrees(lo + CRITICAL_TANGENT_ANGLE_RAD):.4g} to "
            f"{math.degrees(hi + CRITICAL_TANGENT_ANGLE_RAD):.4g} deg), so there is no ISO 6336-3 "
            "critical point for a root crack",
        )
    phi_c = brentq(f, phi0, phi1, xtol=1e-16, rtol=1e-15, maxiter=200)
    xy, n = fillet_points(rack, np.array([phi_c]))
    t = np.array([-n[0, 1], n[0, 0]])
    return float(xy[0, 0]), float(xy[0, 1]), t


def max_depth_m(profile: ToothProfile, angle_rad: float) -> float:
    """Largest crack depth q (m) allowed at crack angle ``angle_rad``: the tip on the
    centre line, q = x_C / sin nu, or less where the tip would reach the bore."""
    x_c, y_c, _ = critical_fillet_point(profile)
    q_axis = x_c / math.sin(angle_rad)
    # |C + q d| = r_hub, d = (-sin nu, -cos nu): q^2 + 2 q (C.d) + |C|^2 - r_hub^2 = 0
    r_hub = profile.gear.hub_radius_m
    cd = -(x_c * math.sin(angle_rad) + y_c * math.cos(angle_rad))
    disc = cd * cd - (x_c * x_c + y_c * y_c - r_hub * r_hub)
    q_bore = -cd - math.sqrt(disc) if disc > 0 else math.inf
    return min(q_axis, q_bore)


def check_crack(profile: ToothProfile, crack: Crack) -> None:
    """Raise an ``InputError`` naming ``angle_rad`` or ``depth_m`` when ``crack`` is
    outside the allowed range (module docstring)."""
    nu, q = crack.angle_rad, crack.depth_m
    if not (isinstance(nu, (int, float)) and math.isfinite(nu) and 0.0 < nu <= 0.5 * math.pi):
        raise fail(
            "angle_rad",
            nu,
            "rad",
            f"must be in (0, {0.5 * math.pi:.6g}] rad (inward and downward "
            "from the fillet, measured from the tooth centre line)",
        )
    q_max = max_depth_m(profile, nu)
    if not (isinstance(q, (int, float)) and math.isfinite(q) and 0.0 < q <= q_max):
        raise fail(
            "depth_m",
            q,
            "m",
            f"must be in (0, {q_max:.6g}] m at angle_rad = {nu:.6g} (crack tip on "
            "the loaded side of the tooth centre line, outside the bore)",
        )


def crack_line(profile: ToothProfile, crack: Crack) -> tuple[np.ndarray, np.ndarray]:
    """(mouth_xy, tip_xy) (m) of ``crack`` in the tooth frame (centre line +y, loaded
    flank x > 0): mouth C at the ISO 30-deg fillet point, tip C + q (-sin nu, -cos nu)."""
    check_crack(profile, crack)
    x_c, y_c, _ = critical_fillet_point(profile)
    mouth = np.array([x_c, y_c])
    d = np.array([-math.sin(crack.angle_rad), -math.cos(crack.angle_rad)])
    return mouth, mouth + crack.depth_m * d


def crack_mouth_arc(profile: ToothProfile, crack: Crack) -> tuple[np.ndarray, np.ndarray, float]:
    """(mouth_xy, tip_xy, s_m): ``crack_line`` and the mouth's arc position s_m (m) along
    the profile (its projection onto profile.xy, interpolated in profile.s), where a
    mesh of the cracked tooth puts the mouth vertex."""
    mouth, tip = crack_line(profile, crack)
    pr = project_to_polyline(mouth[None, :], profile.xy)
    k0 = int(pr.segment[0])
    s_m = float(profile.s[k0] + pr.t[0] * (profile.s[k0 + 1] - profile.s[k0]))
    return mouth, tip, s_m


def crack_tip_offset_m(profile: ToothProfile, crack: Crack) -> tuple[float, float]:
    """(h_q, y_q) (m): distance of the crack tip from the tooth centre line,
    h_q = x_C - q sin nu, and the tip's height y_q = y_C - q cos nu."""
    _, tip = crack_line(profile, crack)
    return float(tip[0]), float(tip[1])


@dataclass(frozen=True)
class ReducedSection:
    """The reduced-section crack model of Chen & Shao (2011) after Tian (2004), as a
    loss of tooth thickness per height y along the centre line (m).

    With h_x(y) the loaded-side half thickness (``geometry.loading.flank_height_table``)
    and h_q the crack tip's distance from the centre line, a section at height y keeps
    only h_q on the cracked side where h_x > h_q: the material beyond the line
    x = h_q through the crack tip is taken as carrying no load. Its thickness,
    area and second moment become

        t_c(y) = h_q + h_x'(y),   A = t_c b,   I = t_c^3 b / 12      (h_x > h_q)

    (h_x' the opposite half thickness, = h_x for a symmetric tooth), and the
    sections with h_x <= h_q are intact. The references clamp the cantilever at the
    base circle, above the crack tip, so every section there lies above the tip. Here
    the cantilever is clamped at the root circle y_M, which can lie above or below
    the tip: the reduction is applied to sections at or above the tip height y_q only,
    since below it no section is cut (this is the reference model on the reference's
    sections and tends continuously to the intact tooth as q -> 0, where y_q -> y_C
    and h_q -> x_C). The centroid shift of the reduced section is ignored, as in the
    references.

    h_q_m, y_q_m  crack-tip offset from the centre line and height (m)
    y_m, x_m      knots of the loaded flank's half thickness h_x(y) (m)
    """

    h_q_m: float
    y_q_m: float
    y_m: np.ndarray
    x_m: np.ndarray

    def loss_m(self, y_m) -> np.ndarray:
        """Thickness removed by the crack at heights ``y_m`` (m):
        max(h_x(y) - h_q, 0) for y >= y_q, else 0; same shape as ``y_m``."""
        y = np.asarray(y_m, dtype=float)
        over = np.interp(y, self.y_m, self.x_m) - self.h_q_m
        return np.where((y >= self.y_q_m) & (over > 0.0), over, 0.0)

    def breaks_m(self) -> np.ndarray:
        """Heights (m) where the loss is not smooth: the tip height y_q (a jump) and
        every height above it where h_x(y) crosses h_q (a kink), increasing."""
        d = self.x_m - self.h_q_m
        k = np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)
        # h_x is linear on each knot interval, so the crossing is exact
        yc = self.y_m[k] + d[k] / (d[k] - d[k + 1]) * (self.y_m[k + 1] - self.y_m[k])
        return np.unique(np.concatenate([[self.y_q_m], yc[yc > self.y_q_m]]))


def reduced_section(loaded: ToothProfile, crack: Crack) -> ReducedSection:
    """:class:`ReducedSection` of ``crack`` on the loaded flank ``loaded`` (its crack
    geometry from :func:`crack_line`, its h_x(y) from the loaded flank polyline)."""
    h_q, y_q = crack_tip_offset_m(loaded, crack)
    ys, xs = flank_height_table(loaded)
    return ReducedSection(h_q, y_q, ys, xs)
