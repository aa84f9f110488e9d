"""Ishikawa/Weber slice model of tooth compliance (paper Eqs. 2-6; Shi et al. 2013,
Weber & Banaschek 1953).

The tooth is a cantilever clamped at the root section (root circle, y = y_M) and cut
into n slices of height L along its axis; slice j has the true (nominal or worn)
thickness 2 Y_j at its mid-height, area A_j = 2 Y_j b and inertia I_j = (2 Y_j)^3 b / 12.
With S_j the distance from the top of slice j to the load point, x_F the offset of the
contact point from the axis and w the load angle (geometry.loading), Castigliano's
theorem on M(u) = F (cos w u - sin w x_F), u = y_F - y, gives per slice (paper Eq. 2,
whose printed form is garbled; this is its energy-consistent reading):

    delta_1 / F = sum_j 1/E [ cos^2 w (L^3 + 3 L^2 S_j + 3 L S_j^2) / (3 I_j)
                             - cos w sin w x_F (L^2 + 2 L S_j) / I_j
                             + sin^2 w x_F^2 L / I_j
                             + cos^2 w 12 (1 + nu) L / (5 A_j)      (shear, 1.2 / G)
                             + sin^2 w L / A_j ]                     (axial compression)

Weber's root (foundation) deflection, Eqs. 3-4, with L_f the lever arm of the force
line about the root section and 2 Y_M the root-section thickness:

    delta_2 / F = cos^2 w (1 - nu^2) / (E b) [ 5.306 (L_f / 2Y_M)^2
                  + 2 (1 - nu - 2 nu^2) / (1 - nu^2) (L_f / 2Y_M) + 1.534 (1 + 0.4167 tan^2 w / (1 + nu)) ]

    L_f = X_j - X_M - Y_j tan w   (= y_c - y_M, where the force line meets the axis)

and the nonlinear Hertzian approach of the pair, Eq. 5 (SI units: F in N, E in Pa,
b in m, delta in m):

    delta_3 = 1.275 F^0.9 / (E^0.9 b^0.8)

A pair's compliance (Eq. 6) is (delta_1 + delta_2)_pinion + delta_3 + (delta_1 + delta_2)_gear.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearwear.geometry.profile import ToothProfile
from gearwear.geometry.spec import Material

from gearwear.geometry.loading import half_thickness_at_height, load_points, root_section

DEFAULT_SLICES = 64


@dataclass(frozen=True)
class SliceCompliance:
    """Compliance components (m/N) at each contact radius, for face width b."""

    radius_m: np.ndarray
    bending_m_per_N: np.ndarray
    shear_m_per_N: np.ndarray
    axial_m_per_N: np.ndarray
    foundation_m_per_N: np.ndarray

    @property
    def delta1_m_per_N(self) -> np.ndarray:
        """Tooth deflection per unit load (bending + shear + axial), paper delta_1 / F."""
        return self.bending_m_per_N + self.shear_m_per_N + self.axial_m_per_N

    @property
    def total_m_per_N(self) -> np.ndarray:
        """delta_1 + delta_2 per unit load (no Hertz term)."""
        return self.delta1_m_per_N + self.foundation_m_per_N


def thickness_at_height(loaded: ToothProfile, y_m, opposite: ToothProfile | None = None) -> np.ndarray:
    """Full tooth thickness (m) at heights y: loaded flank plus the opposite flank
    (nominal by default), so one-flank wear thins the tooth by h, not 2 h."""
    other = opposite if opposite is not None else loaded
    return half_thickness_at_height(loaded, y_m) + half_thickness_at_height(other, y_m)


def slice_beam_compliance(thickness_fn, y_M, y_F, x_F, w, E: float, nu: float, b: float, n_slices: int):
    """Bending, shear and axial compliance (m/N) of a slice cantilever (Eq. 2 sums).

    thickness_fn(y) gives the full tooth thickness at heights y (array in, array out);
    y_M root-section height, y_F load height, x_F load offset, w load angle (arrays of
    equal shape, one entry per load position). Each slice has the thickness at its
    mid-height; within a slice the integrals are exact, so a prismatic beam is exact
    for any n (Timoshenko: L^3/(3EI) + 1.2 L/(GA) at w = 0).
    """
    y_M = np.asarray(y_M, dtype=float)
    y_F, x_F, w = (np.asarray(v, dtype=float) for v in (y_F, x_F, w))
    L = (y_F - y_M) / n_slices
    j = np.arange(n_slices)
    y_lo = y_M[..., None] + L[..., None] * j
    t = thickness_fn(y_lo + 0.5 * L[..., None])
    if np.any(~(t > 0)):
        raise ValueError("slice thickness <= 0: the tooth is consumed (wear deeper than the tooth)")
    A = t * b
    I = t ** 3 * b / 12.0
    Lc = L[..., None]
    S = (n_slices - 1 - j) * Lc  # distance from the top of slice j to the load point
    c, s = np.cos(w)[..., None], np.sin(w)[..., None]
    xF = x_F[..., None]
    bending = (c * c * (Lc ** 3 + 3 * Lc ** 2 * S + 3 * Lc * S ** 2) / (3 * I)
               - c * s * xF * (Lc ** 2 + 2 * Lc * S) / I
               + s * s * xF ** 2 * Lc / I).sum(axis=-1) / E
    shear = (c * c * 12.0 * (1 + nu) * Lc / (5.0 * A)).sum(axis=-1) / E
    axial = (s * s * Lc / A).sum(axis=-1) / E
    return bending, shear, axial


def tooth_compliance(loaded: ToothProfile, radius_m, material: Material, face_width_m: float,
                     n_slices: int = DEFAULT_SLICES, opposite: ToothProfile | None = None) -> SliceCompliance:
    """Slice-model compliance of one tooth loaded at contact radii ``radius_m`` (m).

    ``loaded`` is the loaded flank (worn or not); ``opposite`` the other flank
    (defaults to ``loaded`` mirrored; pass the nominal profile for one-flank wear).
    Vectorized over radii x slices.
    """
    if n_slices < 1:
        raise ValueError(f"n_slices = {n_slices}: must be >= 1")
    lp = load_points(loaded, radius_m)
    y_M, _ = root_section(loaded)
    if opposite is None:
        opposite = loaded
    bending, shear, axial = slice_beam_compliance(
        lambda y: thickness_at_height(loaded, y, opposite), np.full_like(lp.y_m, y_M), lp.y_m, lp.x_m, lp.w_rad,
        material.youngs_modulus_Pa, material.poisson_ratio, face_width_m, n_slices)
    foundation = weber_foundation(loaded, lp.y_axis_m, lp.w_rad, material, face_width_m, opposite)
    return SliceCompliance(lp.radius_m, bending, shear, axial, foundation)


def weber_foundation(loaded: ToothProfile, y_axis_m, w_rad, material: Material, face_width_m: float,
                     opposite: ToothProfile | None = None) -> np.ndarray:
    """Weber's root deflection per unit load, paper Eqs. 3-4 (m/N)."""
    E, nu = material.youngs_modulus_Pa, material.poisson_ratio
    y_M, _ = root_section(loaded)
    s_f = float(thickness_at_height(loaded, np.array([y_M]), opposite)[0])  # 2 Y_M
    ratio = (np.asarray(y_axis_m) - y_M) / s_f  # L_f / (2 Y_M)
    w = np.asarray(w_rad)
    bracket = (5.306 * ratio ** 2 + 2.0 * (1 - nu - 2 * nu ** 2) / (1 - nu ** 2) * ratio
               + 1.534 * (1 + 0.4167 * np.tan(w) ** 2 / (1 + nu)))
    return np.cos(w) ** 2 * (1 - nu ** 2) / (E * face_width_m) * bracket


def hertz_approach_m(force_N, material: Material, face_width_m: float) -> np.ndarray:
    """Nonlinear Hertzian approach of the pair, paper Eq. 5: 1.275 F^0.9 / (E^0.9 b^0.8) (m)."""
    F = np.maximum(np.asarray(force_N, dtype=float), 0.0)
    return hertz_coefficient(material, face_width_m) * F ** 0.9


def hertz_coefficient(material: Material, face_width_m: float) -> float:
    """a in delta_3 = a F^0.9 (SI)."""
    return 1.275 / (material.youngs_modulus_Pa ** 0.9 * face_width_m ** 0.8)
