"""Where a gear pair leaves an analytic stiffness model's own assumptions: one-line notes
shown with the model's curve (``gearwear stiffness``, the summary's ``warnings``).

The curve is computed all the same (it is what the published model gives); the notes say
which assumption the pair breaks, so a user reads the number knowing what it stands on:

* **Base-clamped teeth** (``yang_lin``, ``tian``, ``wu_zuo_parey``: the tooth is clamped at
  the base circle r_b). Where the root circle lies above the base circle (r_f > r_b: more
  than about 42 teeth at 20 deg, or a positive shift), the model's involute continues
  r_f - r_b below the root circle, through what is gear body, as tooth; where it lies below
  (r_f < r_b), the material between the two circles is not in the model. Over the atlas
  (docs/atlas.md) this height is what the base-clamped models' error follows most closely.
  Noted when |r_f - r_b| exceeds :data:`CLAMP_TOLERANCE_MODULE` modules. A base circle
  inside the bore (r_b <= r_bore) puts the clamped section in the hole.
* **Sainsot's foundation** (``energy``, ``chen_shao``, ``wu_zuo_parey``): its polynomials
  were fitted for h_fi = r_f / r_bore in [1.4, 7] and theta_f = S_f / (2 r_f) in
  [0.01, 0.12] rad (``analytic.energy.SAINSOT_H_FI_RANGE``); outside, the formula is
  extrapolated. r_f and S_f are each model's own clamped section: the root circle and the
  true root thickness for ``energy``, the clamped section of ``analytic.involute_beam``
  (for ``wu_zuo_parey`` the base circle and its chord).
"""

from __future__ import annotations

from gearwear.geometry.loading import root_section
from gearwear.geometry.profile import tooth_profile
from gearwear.geometry.spec import GearSpec, PairSpec

from . import involute_beam
from .energy import SAINSOT_H_FI_RANGE, SAINSOT_THETA_F_RANGE_RAD, sainsot_in_fit_range

#: |r_f - r_b| (in modules) below which a base-clamped model's clamp is taken as at the root
CLAMP_TOLERANCE_MODULE = 0.25


def _clamp_notes(method: str, g: GearSpec) -> list[str]:
    """The base-clamped models' notes for gear ``g`` (module docstring)."""
    mm = 1e3
    gap = g.root_radius_m - g.base_radius_m
    out = []
    if gap > CLAMP_TOLERANCE_MODULE * g.module_m:
        out.append(
            f"{g.name}: the root circle lies {gap * mm:.3g} mm above the base circle, and {method} clamps the tooth "
            f"at the base circle: {gap * mm:.3g} mm of gear body below the root circle count as an involute tooth "
            "neck there (what that costs: docs/atlas.md)"
        )
    elif -gap > CLAMP_TOLERANCE_MODULE * g.module_m:
        out.append(
            f"{g.name}: the base circle lies {-gap * mm:.3g} mm above the root circle, and {method} clamps the tooth "
            f"at the base circle: the material between the two circles is not in the model (docs/atlas.md)"
        )
    if g.base_radius_m <= g.hub_radius_m:
        out.append(
            f"{g.name}: the base circle (r_b = {g.base_radius_m * mm:.4g} mm) lies inside the bore "
            f"(r = {g.hub_radius_m * mm:.4g} mm): {method}'s clamped section is in the hole"
        )
    return out


def _sainsot_point(method: str, g: GearSpec) -> tuple[float, float]:
    """(h_fi, theta_f) of Sainsot's formula as ``method`` evaluates it for gear ``g``."""
    if method == "energy":
        _, x_M = root_section(tooth_profile(g))
        return g.root_radius_m / g.hub_radius_m, x_M / g.root_radius_m
    _, h_M, r = involute_beam.clamped_section_m(g, method)
    return r / g.hub_radius_m, h_M / r


def _uses_sainsot(method: str) -> bool:
    return method == "energy" or (method in involute_beam.MODELS and involute_beam.MODELS[method][2] == "sainsot")


def assumption_warnings(method: str, pair: PairSpec) -> list[str]:
    """One-line notes on where ``pair`` leaves ``method``'s assumptions (module
    docstring); empty for the methods without such notes and for pairs inside them."""
    out: list[str] = []
    for g in pair.gears:
        if method in involute_beam.MODELS and involute_beam.MODELS[method][0] == "base":
            out += _clamp_notes(method, g)
        if _uses_sainsot(method):
            h_fi, theta = _sainsot_point(method, g)
            if not sainsot_in_fit_range(h_fi, theta):
                (h0, h1), (t0, t1) = SAINSOT_H_FI_RANGE, SAINSOT_THETA_F_RANGE_RAD
                out.append(
                    f"{g.name}: Sainsot's foundation formula in {method} is extrapolated at h_fi = r_f / r_bore = "
                    f"{h_fi:.3g} and theta_f = {theta:.3g} rad "
                    f"(fitted for h_fi {h0:g}-{h1:g}, theta_f {t0:g}-{t1:g} rad)"
                )
    return out
