"""Gear pairs other than the paper's 30/30 one, for tests that must know more than one pair.

Not a test file: a helper the ``test_any_pair_*`` files import. Everything around the paper
pair (z 30/30, m 5 mm, x 0/0) is symmetric in the pinion and the gear, so a formula that
swaps z1 and z2, r_b1 and r_b2 or the two tip radii passes every test on it. The named
pairs break that symmetry on purpose:

* ``UNEQUAL``: z 23/47, m 3 mm, x +0.2/-0.1, b 30 mm, bores 12.5/25 mm (ratio 2.04,
  shifted, net shift +0.1 so alpha_w != alpha and a tip shortening k != 0).
* ``DRIVER_LARGER``: the same two gears with the roles swapped, z 47/23 (index 0 is always
  the driver): everything that depends only on the geometry (centre distance, contact
  ratio, backlash) is the same as ``UNEQUAL``'s, everything that depends on which gear is
  which is mirrored.
* ``HIGH_CONTACT``: z 29/61, m 2 mm, addendum 1.25, dedendum 1.5, rack tip 0.25,
  x +0.1/0: a contact ratio just above 2 (two or three pairs in contact).
* ``ALPHA25``: z 17/31, m 4 mm, 25 deg pressure angle, rack tip 0.25, x +0.3/+0.1.

``valid_pairs()`` is a hypothesis strategy of random pairs that ``check_pair`` accepts.
"""

from __future__ import annotations

import math

from hypothesis import assume
from hypothesis import strategies as st

from gearwear.core.validation import InputError
from gearwear.geometry.spec import PairSpec, check_pair, default_pair, inv


def checked(**kw) -> PairSpec:
    """A PairSpec from keyword arguments, validated by check_pair (raises InputError)."""
    spec = PairSpec(**kw)
    check_pair(spec)
    return spec


UNEQUAL = checked(
    teeth=(23, 47), module_m=3e-3, profile_shift=(0.2, -0.1), face_width_m=30e-3, hub_radius_m=(12.5e-3, 25e-3)
)
DRIVER_LARGER = checked(
    teeth=(47, 23), module_m=3e-3, profile_shift=(-0.1, 0.2), face_width_m=30e-3, hub_radius_m=(25e-3, 12.5e-3)
)
HIGH_CONTACT = checked(
    teeth=(29, 61),
    module_m=2e-3,
    addendum_coefficient=1.25,
    dedendum_coefficient=1.5,
    rack_tip_radius_coefficient=0.25,
    profile_shift=(0.1, 0.0),
    face_width_m=16e-3,
    hub_radius_m=(15e-3, 25e-3),
)
ALPHA25 = checked(
    teeth=(17, 31),
    module_m=4e-3,
    pressure_angle_rad=math.radians(25.0),
    rack_tip_radius_coefficient=0.25,
    profile_shift=(0.3, 0.1),
    face_width_m=25e-3,
    hub_radius_m=(10e-3, 20e-3),
)

#: the named non-paper pairs, by name (pytest ids)
NAMED = {
    "unequal_23_47": UNEQUAL,
    "driver_larger_47_23": DRIVER_LARGER,
    "high_contact_29_61": HIGH_CONTACT,
    "alpha25_17_31": ALPHA25,
}
#: the same with the paper pair for reference
WITH_PAPER = {**NAMED, "paper_30_30": default_pair()}


def by_hand_working_pressure_angle(pair: PairSpec) -> float:
    """alpha_w from inv(alpha_w) = inv(alpha) + 2 (x1 + x2) tan(alpha) / (z1 + z2) (ISO 21771),
    solved here by bisection (not the library's Newton): inv is increasing on [0, pi/2)."""
    a = pair.pressure_angle_rad
    target = inv(a) + 2.0 * sum(pair.profile_shift) * math.tan(a) / sum(pair.teeth)
    lo, hi = 0.0, 1.5
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if inv(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def by_hand_radii(pair: PairSpec, i: int) -> dict[str, float]:
    """Radii of gear i written out from the ISO 21771 definitions (m): pitch m z / 2, base
    r cos(alpha), root r - (h_f* - x) m, tip r + (h_a* + x + k) m with
    k = (a_w - a) / m - (x1 + x2) and a_w = a cos(alpha) / cos(alpha_w)."""
    m, z, x = pair.module_m, pair.teeth[i], pair.profile_shift[i]
    r = 0.5 * m * z
    a_ref = 0.5 * m * sum(pair.teeth)
    a_w = a_ref * math.cos(pair.pressure_angle_rad) / math.cos(by_hand_working_pressure_angle(pair))
    k = (a_w - a_ref) / m - sum(pair.profile_shift)
    return {
        "pitch": r,
        "base": r * math.cos(pair.pressure_angle_rad),
        "root": r - (pair.dedendum_coefficient - x) * m,
        "tip": r + (pair.addendum_coefficient + x + k) * m,
        "a_w": a_w,
    }


def _undercut_free_shift(z: int, alpha: float, dedendum: float, rho: float) -> float:
    """Least profile shift without undercut by a rounded rack (textbook limit),
    x_min = h_f* - rho* (1 - sin alpha) - z sin^2(alpha) / 2, plus a small margin."""
    return dedendum - rho * (1.0 - math.sin(alpha)) - 0.5 * z * math.sin(alpha) ** 2 + 0.02


@st.composite
def valid_pairs(draw, max_shift: float = 0.8) -> PairSpec:
    """Random pairs that check_pair accepts: teeth 12..120 each (either gear may be the
    larger), module 1..10 mm, pressure angle 14.5..25 deg, addendum 0.9..1.3 with a
    dedendum 0.25 deeper, a rack tip round that fits the rack, shifts from the undercut
    limit up to ``max_shift``, face width 4..20 modules, bores 20..70 % of the root
    radius. Refusals (pointed tips, interference, no path of contact) are filtered with
    ``assume``; the shifts start above the undercut limit so that few draws are refused."""
    z = (draw(st.integers(12, 120)), draw(st.integers(12, 120)))
    m = draw(st.floats(1e-3, 10e-3))
    alpha = math.radians(draw(st.floats(14.5, 25.0)))
    ha = draw(st.floats(0.9, 1.3))
    hf = ha + 0.25
    rho_max = (0.25 * math.pi - hf * math.tan(alpha)) * math.cos(alpha) / (1.0 - math.sin(alpha))
    assume(rho_max > 0.05)
    rho = draw(st.floats(0.05, min(0.38, 0.95 * rho_max)))
    shifts = []
    for zi in z:
        lo = max(-0.5, _undercut_free_shift(zi, alpha, hf, rho))
        assume(lo < max_shift)
        shifts.append(draw(st.floats(lo, max_shift)))
    root = [0.5 * m * zi - (hf - xi) * m for zi, xi in zip(z, shifts)]
    assume(min(root) > 0)
    bores = tuple(draw(st.floats(0.2, 0.7)) * r for r in root)
    b = draw(st.floats(4.0, 20.0)) * m
    spec = PairSpec(
        teeth=z,
        module_m=m,
        pressure_angle_rad=alpha,
        face_width_m=b,
        addendum_coefficient=ha,
        dedendum_coefficient=hf,
        rack_tip_radius_coefficient=rho,
        profile_shift=tuple(shifts),
        hub_radius_m=bores,
    )
    try:
        check_pair(spec)
    except InputError:
        assume(False)
    return spec


__all__ = [
    "ALPHA25",
    "DRIVER_LARGER",
    "HIGH_CONTACT",
    "NAMED",
    "UNEQUAL",
    "WITH_PAPER",
    "by_hand_radii",
    "by_hand_working_pressure_angle",
    "checked",
    "valid_pairs",
]
