"""The published potential-energy models of an involute tooth in closed angular form:
Yang & Lin (1987), Tian (2004) and Chen & Shao (2013).

All three take the tooth as a cantilever whose flank is the ideal involute of the gear
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
the load sharing as gaps (``analytic.tvms``), not as a thinner tooth, and a root crack is
not modelled (the ``energy`` and ``ishikawa`` methods have it).
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


def tooth_compliance(
    model: str, gear: GearSpec, radius_m, face_width_m: float, plane: str = "stress", n_gauss: int = N_GAUSS
) -> InvoluteToothCompliance:
    """Compliance (m/N) of ``gear``'s tooth by ``model`` (:data:`MODELS`) at contact
    radii ``radius_m`` (m); equations in the module docstring. E, nu from the gear's
    material; ``plane``: the beam terms' 2D state."""
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
    # Gauss points of [-alpha_1, alpha_c] per contact: (n_pos, n_gauss)
    xg, wg = _gauss_legendre(n_gauss)
    half = 0.5 * (ac + a1)
    al = (0.5 * (ac - a1))[:, None] + half[:, None] * xg[None, :]
    t = a2 - al
    ca, sa = np.cos(al), np.sin(al)
    jac = t * ca  # dy / (r_b d alpha), up to the sign absorbed by the limits
    hx = sa + t * ca  # h / r_b
    c1 = np.cos(a1)[:, None]
    lever = 1.0 + c1 * (t * sa - ca)  # [cos a1 (y_F - y) - x_F sin a1] / r_b
    w = half[:, None] * wg[None, :]
    bending = (3.0 * lever**2 * jac / hx**3 * w).sum(axis=1) / (2.0 * E * b)
    inv_h = (jac / hx * w).sum(axis=1)  # int dy / h, over r_b ... r_b cancels
    shear = SHEAR_FACTOR * np.cos(a1) ** 2 * inv_h / (2.0 * G * b) if with_shear else np.zeros_like(R)
    axial = np.sin(a1) ** 2 * inv_h / (2.0 * E * b)
    # the force point and where the force line crosses the tooth axis (for the foundation)
    y_F = rb * (np.cos(a1) + (a1 + a2) * np.sin(a1))
    x_F = rb * ((a1 + a2) * np.cos(a1) - np.sin(a1))
    y_b = rb * math.cos(a2)
    if clamp == "root" and y_M < y_b * (1 - 1e-15) and ac == a2:
        # Chen & Shao's straight segment of the base thickness from the base circle down to the root circle
        L = y_b - y_M
        c, s = np.cos(a1), np.sin(a1)
        p0 = c * (y_F - y_b) - s * x_F
        bending = bending + 3.0 / (2.0 * E * b * h_M**3) * (p0**2 * L + p0 * c * L**2 + c**2 * L**3 / 3.0)
        if with_shear:
            shear = shear + SHEAR_FACTOR * c**2 * L / (2.0 * G * b * h_M)
        axial = axial + s**2 * L / (2.0 * E * b * h_M)
    y_c = y_F - x_F * np.tan(a1)
    if foundation == "sainsot":
        S_f = 2.0 * h_M
        rf = gear.root_radius_m
        found = foundation_compliance(a1, y_c - y_M, S_f, rf / gear.hub_radius_m, S_f / (2.0 * rf), mat, b)
    elif foundation == "weber":
        from .ishikawa import _weber

        found = _weber(y_c, a1, y_M, 2.0 * h_M, mat, b)
    else:
        found = np.zeros_like(R)
    return InvoluteToothCompliance(
        model, R, a1, bending, shear, axial, np.asarray(found, dtype=float), float(y_M), float(h_M)
    )
