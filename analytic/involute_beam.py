"""The published potential-energy models of an involute tooth in closed angular form:
Yang & Lin (1987), Tian (2004), Wu, Zuo & Parey (2008) and Chen & Shao (2013).

All of them take the tooth as a cantilever whose flank is the ideal involute of the gear
(the fillet is not drawn) and integrate the strain energy of the mesh force F over the
tooth in the involute's own angle alpha (Tian's variable). For a tooth of base radius
r_b and base half angle

    alpha_2 = s_b / (2 r_b) = pi / (2 N) + inv(alpha_0) + 2 x tan(alpha_0) / N      [rad]

(N teeth, generating pressure angle alpha_0, profile shift coefficient x), the flank
point of parameter alpha (alpha_2 at the base circle, decreasing up the flank) has the
half thickness and height along the tooth axis

    h(alpha) = r_b [sin alpha + (alpha_2 - alpha) cos alpha]                        [m]
    y(alpha) = r_b [cos alpha - (alpha_2 - alpha) sin alpha],
    dy = -r_b (alpha_2 - alpha) cos alpha d alpha

and a contact at radius R has alpha = -alpha_1 with the load angle
alpha_1 = tan(arccos(r_b / R)) - alpha_2 (the angle between the force and the
perpendicular to the tooth axis). With E, G = E / (2 (1 + nu)) and the face width b
(Pa, Pa, m), the compliances per unit normal load (m/N) are (Tian 2004, Eqs. 2.22-2.24;
Wu, Zuo & Parey, Mech. Mach. Theory 43 (2008) Eqs. 8-10):

    1/k_b = int_{-alpha_1}^{alpha_c} 3 {1 + cos alpha_1 [(alpha_2 - alpha) sin alpha - cos alpha]}^2
                (alpha_2 - alpha) cos alpha / (2 E b [sin alpha + (alpha_2 - alpha) cos alpha]^3) d alpha
    1/k_s = int_{-alpha_1}^{alpha_c} 1.2 (1 + nu) (alpha_2 - alpha) cos alpha cos^2 alpha_1
                / (E b [sin alpha + (alpha_2 - alpha) cos alpha]) d alpha
    1/k_a = int_{-alpha_1}^{alpha_c} (alpha_2 - alpha) cos alpha sin^2 alpha_1
                / (2 E b [sin alpha + (alpha_2 - alpha) cos alpha]) d alpha

and the linear Hertz compliance of the pair 1/k_h = 4 (1 - nu^2) / (pi E b) (Yang & Lin
1987; ``energy.hertz_compliance_linear``). alpha_c is the clamped end of the involute:

* **Yang & Lin** (J. Mech. Transm. Autom. Des. 109:189-196, 1987): bending and axial
  compression, clamped at the base circle (alpha_c = alpha_2); no shear, no foundation.
* **Tian** (MSc thesis, University of Alberta, 2004): bending, shear and axial
  compression, clamped at the base circle; no foundation.
* **Wu, Zuo & Parey** (J. Sound Vib. 317:608-624, 2008): Tian's tooth (bending, shear and
  axial compression, clamped at the base circle) on the fillet foundation of Sainsot,
  Velex & Duverger (2004), linear Hertz. The foundation acts at the clamped section, as in
  the paper, which takes the root circle at the base circle: S_f = 2 r_b sin alpha_2 (the
  base chord), u_f measured from the base point y_b = r_b cos alpha_2, and Sainsot's
  h_fi = r_b / r_bore and theta_f = S_f / (2 r_b). (Where r_f differs from r_b this is the
  paper's approximation, kept as published; Chen & Shao's model below clamps at r_f.)
* **Chen & Shao** (Mech. Mach. Theory 62:63-74, 2013; after Chen & Shao, Eng. Fail.
  Anal. 18:2149, 2011): the tooth is clamped at the root circle r_f. When r_f < r_b the
  flank below the base circle is a straight segment of the base thickness
  h_b = r_b sin alpha_2, from the base circle down to the root circle at height
  y_M = sqrt(r_f^2 - h_b^2), added in closed form (a prismatic beam); with the lever
  p_0 = cos alpha_1 (y_F - y_b) - x_F sin alpha_1 at the base point y_b = r_b cos alpha_2
  and the segment length L = y_b - y_M:

      1/k_b += 3 / (2 E b h_b^3) [p_0^2 L + p_0 cos alpha_1 L^2 + cos^2 alpha_1 L^3 / 3]
      1/k_s += 1.2 cos^2 alpha_1 L / (2 G b h_b),   1/k_a += sin^2 alpha_1 L / (2 E b h_b)

  When r_f >= r_b the involute is cut at the root circle: alpha_c = alpha_2 - tan(arccos(r_b / r_f)).
  The gear body adds the fillet-foundation compliance of Sainsot, Velex & Duverger (J.
  Mech. Des. 126:748, 2004; ``energy.foundation_compliance``) with the root thickness
  S_f = 2 h(root) and u_f the distance from the root section to where the force line
  crosses the tooth axis; the variant ``chen_shao_weber`` takes Weber's (1949; Weber &
  Banaschek 1953) foundation instead (``ishikawa``'s Eqs. 3-4, the paper's).

Quadrature: the integrands are smooth in alpha over the whole span (no kinks: the profile
is an analytic curve), so an n-point Gauss-Legendre rule per contact converges
exponentially; all contacts and Gauss points are one array operation.

Plane state: the beam terms are plane stress as published; ``plane = "strain"`` puts
E / (1 - nu^2) in bending and axial compression (``analytic.plane``). The foundation and
Hertz terms are kept as published.

These models see the nominal involute of the gear spec: wear and flank deviations enter
the load sharing as gaps (``analytic.tvms``), not as a thinner tooth.

Root crack (Chen & Shao's models only; Chen & Shao, Eng. Fail. Anal. 18:2149, 2011, after
Tian 2004): a straight crack of depth q at angle nu to the tooth axis, its mouth on the
model's own flank at the height y_C of the ISO 30-degree fillet point (``geometry.crack``),
so its tip lies h_q = h(y_C) - q sin nu from the axis at y_q = y_C - q cos nu
(:func:`crack_tip_m`). Every section at or above the tip whose half thickness exceeds h_q
keeps only h_q on the cracked side: thickness h + h_q instead of 2 h in I and A (the
half thickness (h + h_q) / 2 in the integrals above; on the straight segment a prismatic
piece of its own). The integrals are cut at the tip height and where h = h_q (a jump and
kinks), so the Gauss rule keeps its exponential convergence. The foundation is unchanged
(the gear body's). Yang & Lin's and Tian's base-clamped teeth refuse a crack (their
clamp lies above the fillet where this crack starts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.spec import GearSpec, inv

from .energy import SHEAR_FACTOR, _gauss_legendre, foundation_compliance
from .plane import beam_modulus_Pa

#: the models of this module: (clamped at, shear term, foundation)
MODELS = {
    "yang_lin": ("base", False, "none"),
    "tian": ("base", True, "none"),
    "wu_zuo_parey": ("base", True, "sainsot"),
    "chen_shao": ("root", True, "sainsot"),
    "chen_shao_weber": ("root", True, "weber"),
}

#: Gauss-Legendre points per contact (the integrands are smooth: 24 points give the
#: integrals to ~1e-12 relative, tests/test_models_published.py)
N_GAUSS = 24


def base_half_angle_rad(gear: GearSpec) -> float:
    """alpha_2 (rad): half the angle the tooth subtends on the base circle,
    pi / (2 N) + inv(alpha_0) + 2 x tan(alpha_0) / N (the generated tooth thickness
    m (pi / 2 + 2 x tan alpha_0) at the reference circle carried to the base circle)."""
    a0, z = gear.pressure_angle_rad, gear.teeth
    return 0.5 * math.pi / z + inv(a0) + 2.0 * gear.profile_shift * math.tan(a0) / z


def load_angle_rad(gear: GearSpec, radius_m) -> np.ndarray:
    """alpha_1 (rad) at contact radii R (m): tan(arccos(r_b / R)) - alpha_2."""
    R = np.atleast_1d(np.asarray(radius_m, dtype=float))
    rb = gear.base_radius_m
    return np.sqrt(np.maximum((R / rb) ** 2 - 1.0, 0.0)) - base_half_angle_rad(gear)


@dataclass(frozen=True)
class InvoluteToothCompliance:
    """Compliance components (m/N) of one tooth at contact radii ``radius_m`` (m)."""

    model: str
    radius_m: np.ndarray
    load_angle_rad: np.ndarray
    bending_m_per_N: np.ndarray
    shear_m_per_N: np.ndarray
    axial_m_per_N: np.ndarray
    foundation_m_per_N: np.ndarray
    root_height_m: float  # y_M, where the tooth is clamped (m, along the tooth axis)
    root_half_thickness_m: float

    @property
    def total_m_per_N(self) -> np.ndarray:
        """Bending + shear + axial + foundation (the tooth's share, without Hertz)."""
        return self.bending_m_per_N + self.shear_m_per_N + self.axial_m_per_N + self.foundation_m_per_N


def _root(gear: GearSpec, clamp: str) -> tuple[float, float, float]:
    """(alpha_c, y_M, h_M): the clamped end of the involute integral (rad), the height
    (m) and half thickness (m) of the clamped section."""
    a2, rb, rf = base_half_angle_rad(gear), gear.base_radius_m, gear.root_radius_m
    if clamp == "base" or rf >= rb:
        ac = a2 if clamp == "base" else a2 - math.sqrt((rf / rb) ** 2 - 1.0)
        tan_c = a2 - ac
        return ac, rb * (math.cos(ac) - tan_c * math.sin(ac)), rb * (math.sin(ac) + tan_c * math.cos(ac))
    h_b = rb * math.sin(a2)
    return a2, math.sqrt(rf**2 - h_b**2), h_b


def _clamp_radius_m(gear: GearSpec, clamp: str) -> float:
    """The circle the foundation takes the clamped section on (m): the root circle, or the
    base circle of a base-clamped tooth (Wu, Zuo & Parey take the root circle there)."""
    return gear.root_radius_m if clamp == "root" else gear.base_radius_m


def clamped_section_m(gear: GearSpec, model: str) -> tuple[float, float, float]:
    """(y_M, h_M, r_c) (m) of ``model``'s clamped section: its height along the tooth axis,
    its half thickness, and the radius of the circle the foundation takes it on
    (:func:`_clamp_radius_m`)."""
    clamp = MODELS[model][0]
    _, y_M, h_M = _root(gear, clamp)
    return y_M, h_M, _clamp_radius_m(gear, clamp)


def _flank_y(rb: float, a2: float, al):
    """Height y (m) along the tooth axis of the flank point of parameter alpha."""
    return rb * (np.cos(al) - (a2 - al) * np.sin(al))


def _flank_h(rb: float, a2: float, al):
    """Half thickness h (m) of the flank point of parameter alpha."""
    return rb * (np.sin(al) + (a2 - al) * np.cos(al))


def _crack_breaks_rad(rb: float, a2: float, ac: float, h_q: float, y_q: float) -> np.ndarray:
    """The alpha (rad, increasing) in (-pi/2, alpha_c) where the cracked section is not
    smooth: the tip height y_q (a jump) and where h(alpha) = h_q above it (kinks). y is
    monotone in alpha; h is not (it peaks at alpha = 0), so its crossings are bracketed
    on a fine grid and refined by bisection."""
    from scipy.optimize import brentq

    lo = -0.5 * math.pi + 1e-9
    out = []
    if _flank_y(rb, a2, ac) < y_q < _flank_y(rb, a2, lo):
        out.append(brentq(lambda a: _flank_y(rb, a2, a) - y_q, lo, ac, xtol=1e-15))
    grid = np.linspace(lo, ac, 2049)
    d = _flank_h(rb, a2, grid) - h_q
    for k in np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0):
        a = brentq(lambda x: _flank_h(rb, a2, x) - h_q, grid[k], grid[k + 1], xtol=1e-15)
        if _flank_y(rb, a2, a) > y_q:
            out.append(a)
    return np.unique(np.asarray(out, dtype=float))


def half_thickness_m(gear: GearSpec, model: str, y_m: float) -> float:
    """Half thickness (m) of ``model``'s tooth at height ``y_m`` along the axis: Chen &
    Shao's straight segment (base thickness) below the base point when r_f < r_b, else
    the involute (the height solved for its alpha)."""
    from scipy.optimize import brentq

    rb, a2 = gear.base_radius_m, base_half_angle_rad(gear)
    clamp = MODELS[model][0]
    y_b = rb * math.cos(a2)
    if y_m <= y_b:
        if clamp == "root" and gear.root_radius_m < rb:
            return rb * math.sin(a2)
        if y_m < y_b:
            raise fail("height", y_m * 1e3, "mm", f"lies below the base point of the {model} tooth, which starts there")
    top = -0.5 * math.pi + 1e-9  # alpha -> -pi/2: far above any tip
    a = brentq(lambda x: float(_flank_y(rb, a2, x)) - y_m, top, a2, xtol=1e-15)
    return float(_flank_h(rb, a2, a))


def crack_tip_m(gear: GearSpec, model: str, mouth_height_m: float, depth_m: float, angle_rad: float):
    """(h_q, y_q) (m) of a root crack whose mouth is on ``model``'s own flank at the height
    of the ISO 30-degree fillet point (``geometry.crack``), running inward and down at
    ``angle_rad`` to the axis for ``depth_m``: h_q = h(y_C) - q sin nu, y_q = y_C - q cos nu
    (Chen & Shao 2011, Fig. 3). The mouth on the model's flank (not the true fillet's)
    makes the crack vanish continuously as q -> 0. Refused (one line) if the tip passes
    the tooth axis (h_q < 0: outside the reference model), or if the mouth lies below the
    clamped root section (the crack would be in the gear body, which the model holds
    rigid but for the foundation term)."""
    _, y_M, _ = _root(gear, MODELS[model][0])
    if mouth_height_m < y_M:
        why = f"its mouth lies below {model}'s clamped root section y_M = {y_M * 1e3:.6g} mm (use energy or ishikawa)"
        raise fail("crack depth", depth_m * 1e3, "mm", why)
    h_c = half_thickness_m(gear, model, mouth_height_m)
    h_q = h_c - depth_m * math.sin(angle_rad)
    if h_q < 0:
        why = f"its tip passes the tooth axis of the {model} tooth (<= {h_c / math.sin(angle_rad) * 1e3:.6g} mm)"
        raise fail("crack depth", depth_m * 1e3, "mm", why)
    return h_q, mouth_height_m - depth_m * math.cos(angle_rad)


def _prismatic(p0, c, u1: float, u2: float, h: float):
    """int_{u1}^{u2} (p0 + c u)^2 du / h^3 and (u2 - u1) / h for a piece of constant half
    thickness h (m) at distances u (m) below the base point (the lever grows by c u)."""
    lever2 = p0**2 * (u2 - u1) + p0 * c * (u2**2 - u1**2) + c**2 * (u2**3 - u1**3) / 3.0
    return lever2 / h**3, (u2 - u1) / h


def tooth_compliance(
    model: str,
    gear: GearSpec,
    radius_m,
    face_width_m: float,
    plane: str = "stress",
    n_gauss: int = N_GAUSS,
    crack_tip_m: tuple[float, float] | None = None,
) -> InvoluteToothCompliance:
    """Compliance (m/N) of ``gear``'s tooth by ``model`` (:data:`MODELS`) at contact
    radii ``radius_m`` (m); equations in the module docstring. E, nu from the gear's
    material; ``plane``: the beam terms' 2D state. ``crack_tip_m``: (h_q, y_q), the tip of
    a root crack on the loaded flank (its distance from the tooth axis and its height, m;
    ``geometry.crack.crack_tip_offset_m``): the reduced sections of Tian (2004) and Chen &
    Shao (2011) (module docstring); None: the intact tooth."""
    if model not in MODELS:
        raise fail("model", repr(model), "", f"must be one of {', '.join(MODELS)}")
    clamp, with_shear, foundation = MODELS[model]
    R = np.atleast_1d(np.asarray(radius_m, dtype=float))
    rb = gear.base_radius_m
    if np.any(R < rb * (1 - 1e-12)):
        why = f"must be on the involute (>= r_b = {rb * 1e3:.6g} mm)"
        raise fail("contact radius", float(R.min()) * 1e3, "mm", why)
    mat = gear.material
    E = beam_modulus_Pa(mat.youngs_modulus_Pa, mat.poisson_ratio, plane)
    G, b = mat.shear_modulus_Pa, face_width_m
    a2 = base_half_angle_rad(gear)
    a1 = load_angle_rad(gear, R)
    ac, y_M, h_M = _root(gear, clamp)
    if np.any(-a1 >= ac):
        raise fail("contact radius", float(R.min()) * 1e3, "mm", "must lie above the clamped root section")
    # the involute from the contact (alpha = -alpha_1) to the clamp (alpha_c), cut at the
    # crack's breaks into pieces (none without a crack), each with n Gauss points:
    # (n_pos, n_pieces, n_gauss); a piece outside a contact's span has zero width
    breaks = np.empty(0) if crack_tip_m is None else _crack_breaks_rad(rb, a2, ac, *crack_tip_m)
    lo = -a1[:, None]
    edges = np.concatenate([lo, np.clip(breaks[None, :], lo, ac), np.full_like(lo, ac)], axis=1)
    xg, wg = _gauss_legendre(n_gauss)
    half = 0.5 * np.diff(edges, axis=1)[:, :, None]
    al = 0.5 * (edges[:, 1:] + edges[:, :-1])[:, :, None] + half * xg
    t = a2 - al
    ca, sa = np.cos(al), np.sin(al)
    jac = t * ca  # dy / (r_b d alpha), up to the sign absorbed by the limits
    hx = sa + t * ca  # h / r_b
    if crack_tip_m is not None:
        # Chen & Shao / Tian: at or above the tip the cracked side keeps h_q (where h > h_q)
        h_q, y_q = crack_tip_m
        cut = (rb * (ca - t * sa) >= y_q) & (hx > h_q / rb)
        hx = np.where(cut, 0.5 * (hx + h_q / rb), hx)
    c1 = np.cos(a1)[:, None, None]
    lever = 1.0 + c1 * (t * sa - ca)  # [cos a1 (y_F - y) - x_F sin a1] / r_b
    w = half * wg
    bending = (3.0 * lever**2 * jac / hx**3 * w).sum(axis=(1, 2)) / (2.0 * E * b)
    inv_h = (jac / hx * w).sum(axis=(1, 2))  # int dy / h, over r_b ... r_b cancels
    # the force point and where the force line crosses the tooth axis (for the foundation)
    y_F = rb * (np.cos(a1) + (a1 + a2) * np.sin(a1))
    x_F = rb * ((a1 + a2) * np.cos(a1) - np.sin(a1))
    y_b = rb * math.cos(a2)
    c, s = np.cos(a1), np.sin(a1)
    lever2_h3 = np.zeros_like(R)  # the straight segment's int lever^2 / h^3 dy and int dy / h
    len_h = np.zeros_like(R)
    if clamp == "root" and y_M < y_b * (1 - 1e-15) and ac == a2:
        # Chen & Shao's straight segment of the base thickness h_M from the base circle down to
        # the root circle (u = y_b - y from 0 to L); with a crack, the part above the tip keeps
        # h_q on the cracked side: half thickness (h_M + h_q) / 2 there
        L = y_b - y_M
        p0 = c * (y_F - y_b) - s * x_F
        pieces = [(0.0, L, h_M)]
        if crack_tip_m is not None and crack_tip_m[0] < h_M and crack_tip_m[1] < y_b:
            u_q = min(y_b - crack_tip_m[1], L)
            pieces = [(0.0, u_q, 0.5 * (h_M + crack_tip_m[0])), (u_q, L, h_M)]
        for u1, u2, hh in pieces:
            if u2 > u1:
                a, bb = _prismatic(p0, c, u1, u2, hh)
                lever2_h3, len_h = lever2_h3 + a, len_h + bb
    bending = bending + 3.0 / (2.0 * E * b) * lever2_h3
    shear = SHEAR_FACTOR * c**2 * (inv_h + len_h) / (2.0 * G * b) if with_shear else np.zeros_like(R)
    axial = s**2 * (inv_h + len_h) / (2.0 * E * b)
    y_c = y_F - x_F * np.tan(a1)
    if foundation == "sainsot":
        S_f = 2.0 * h_M
        rf = _clamp_radius_m(gear, clamp)
        found = foundation_compliance(a1, y_c - y_M, S_f, rf / gear.hub_radius_m, S_f / (2.0 * rf), mat, b)
    elif foundation == "weber":
        from .ishikawa import _weber

        found = _weber(y_c, a1, y_M, 2.0 * h_M, mat, b)
    else:
        found = np.zeros_like(R)
    return InvoluteToothCompliance(
        model, R, a1, bending, shear, axial, np.asarray(found, dtype=float), float(y_M), float(h_M)
    )
