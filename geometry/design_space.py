"""The spur-gear design space of the stiffness atlas: which pairs are feasible, and why not.

Pure functions of a :class:`~gearwear.geometry.spec.PairSpec` (SI units) that say whether
a generated pair can run, and the reason when it cannot (:func:`rejection`), in the order

1. ``undercut``: the basic rack undercuts a gear (its straight flank ends below the line
   of action's start, u_F < 0: geometry.profile.involute_start);
2. ``pointed_tip``: the arc tooth thickness on the tip circle (:func:`tip_thickness_m`) is
   below ``min_tip_thickness_module`` modules (0.2 by default; 0 is the pointed tooth of
   geometry.spec.check_pair), or the tip circle lies inside the base circle;
3. ``interference``: a mate's tip reaches a flank below its involute start (form radius
   r_Nf), i.e. into the fillet (:func:`interference_margins_m` < 0);
4. ``contact_ratio``: the transverse contact ratio (:func:`contact_ratio`) is below
   ``min_contact_ratio`` (1: one pair would have to carry the load across a gap);
5. ``other``: anything else geometry.spec.check_pair refuses (rack tip round too large
   for the rack tooth, a bore at or above the root circle, no working pressure angle).

The formulas are the textbook ones (ISO 21771; Litvin & Fuentes, *Gear Geometry and
Applied Theory*, ch. 10), written out here so that the atlas can count rejects by reason
without parsing the one-line errors of check_pair, which stops at the first problem.
"""

from __future__ import annotations

import math

from .profile import involute_start
from .spec import GearSpec, PairSpec, check_pair, tip_half_angle_rad

#: the reasons a design is rejected, in the order they are tested (:func:`rejection`)
REASONS = ("undercut", "pointed_tip", "interference", "contact_ratio", "other")

#: least arc tooth thickness on the tip circle, in modules (a common design limit: 0.2 m
#: to 0.4 m for hardened gears; below it the tip is too thin to carry load)
MIN_TIP_THICKNESS_MODULE = 0.2
#: least transverse contact ratio
MIN_CONTACT_RATIO = 1.0


def tip_thickness_m(g: GearSpec) -> float:
    """Arc tooth thickness on the tip circle (m), s_a = 2 r_a (s / (2 r) + inv(alpha) -
    inv(alpha_a)), cos(alpha_a) = r_b / r_a (ISO 21771); -inf when the tip circle is not
    above the base circle (no involute flank at all)."""
    if not g.tip_radius_m > g.base_radius_m:
        return -math.inf
    return 2.0 * g.tip_radius_m * tip_half_angle_rad(g)


def path_of_contact_m(spec: PairSpec, centre_distance_m: float | None = None) -> tuple[float, float, float]:
    """(d_A, d_E, L) on the line of action from T1 (m), at centre distance C (default: the
    pair's :attr:`~PairSpec.centre_distance_m`): L = T1T2 = C sin(alpha'), cos(alpha') =
    (r_b1 + r_b2) / C; the gear's tip circle enters at d_A = L - sqrt(r_a2^2 - r_b2^2), the
    pinion's leaves at d_E = sqrt(r_a1^2 - r_b1^2)."""
    g1, g2 = spec.gears
    C = spec.centre_distance_m if centre_distance_m is None else centre_distance_m
    L = C * math.sin(math.acos(min(1.0, (g1.base_radius_m + g2.base_radius_m) / C)))
    d_A = L - math.sqrt(max(g2.tip_radius_m**2 - g2.base_radius_m**2, 0.0))
    d_E = math.sqrt(max(g1.tip_radius_m**2 - g1.base_radius_m**2, 0.0))
    return d_A, d_E, L


def contact_ratio(spec: PairSpec, centre_distance_m: float | None = None) -> float:
    """Transverse contact ratio epsilon = (d_E - d_A) / p_b, p_b = pi m cos(alpha)
    (:func:`path_of_contact_m`; negative when the tip circles do not overlap on the line
    of action)."""
    d_A, d_E, _ = path_of_contact_m(spec, centre_distance_m)
    return (d_E - d_A) / spec.gear(0).base_pitch_m


def interference_margins_m(spec: PairSpec, centre_distance_m: float | None = None) -> tuple[float, float]:
    """Roll lengths (m) by which the mate's tip meets each flank above its involute start:
    (pinion, gear). Contact on the pinion flank starts at roll length d_A from T1, on the
    gear flank at L - d_E from T2 (:func:`path_of_contact_m`); the involute of gear i starts
    at roll length r_bi u_Nf,i (geometry.profile.involute_start). A negative margin is
    tip/root interference: the mate's tip sweeps below the form circle into the fillet."""
    d_A, d_E, L = path_of_contact_m(spec, centre_distance_m)
    g1, g2 = spec.gears
    return (
        d_A - g1.base_radius_m * involute_start(g1)[0],
        (L - d_E) - g2.base_radius_m * involute_start(g2)[0],
    )


def rejection(
    spec: PairSpec,
    min_tip_thickness_module: float = MIN_TIP_THICKNESS_MODULE,
    min_contact_ratio: float = MIN_CONTACT_RATIO,
) -> str | None:
    """Why ``spec`` is not a feasible design (one of :data:`REASONS`), or None when it is.
    The reasons are tested in the order of :data:`REASONS`; a feasible design also passes
    geometry.spec.check_pair (the model's own acceptance), else it is ``other``."""
    try:
        gears = spec.gears
        if not spec.allow_undercut and any(involute_start(g)[1] for g in gears):
            return "undercut"
        if any(tip_thickness_m(g) < min_tip_thickness_module * spec.module_m for g in gears):
            return "pointed_tip"
        if min(interference_margins_m(spec)) < 0.0:
            return "interference"
        if contact_ratio(spec) < min_contact_ratio:
            return "contact_ratio"
        check_pair(spec)
    except (ValueError, ZeroDivisionError):  # InputError is a ValueError: check_pair's refusals
        # (and no working pressure angle when x1 + x2 is too negative: inverse_involute)
        return "other"
    return None
