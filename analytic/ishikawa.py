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

Plane state: delta_1 is a beam with free sides (E, G = E / (2 (1 + nu))): plane stress, the
paper's model; with plane = "strain" (the scene key fem.plane, resolved as for the FE) its
bending and axial terms take E / (1 - nu^2) and the shear term keeps G (``analytic.plane``).
Weber's delta_2 is a half-plane foundation derived in plane strain ((1 - nu^2) / E) and
delta_3 is Palmgren's empirical law for real (3D) line contacts; both are kept as published
in either state.

Root crack (``crack=``, ``geometry.crack``): the reduced-section model of Chen & Shao
(Engineering Failure Analysis 18(8):2149-2164, 2011) after Tian (MSc thesis, Univ. of
Alberta, 2004). With h_q the distance of the crack tip from the centre line and h_x(y)
the loaded-side half thickness, a slice at mid-height y >= y_q (the tip height) with
h_x > h_q keeps only h_q on the cracked side:

    2 Y_j -> h_q + h_x'(y_j),   A_j = 2 Y_j b,   I_j = (2 Y_j)^3 b / 12     [m, m^2, m^4]

(h_x' the opposite half thickness); other slices are intact. Weber's foundation term
delta_2 is unchanged: it belongs to the gear body below the root section, which the
reference model leaves intact (the root-section thickness 2 Y_M stays the nominal one).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from gearwear.core.validation import fail_text
from gearwear.geometry.crack import Crack, reduced_section
from gearwear.geometry.loading import load_points, root_height_m, root_section, thickness_table
from gearwear.geometry.profile import ToothProfile
from gearwear.geometry.spec import Material

from .plane import beam_modulus_Pa

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
    ys, ts = thickness_table(loaded, opposite)
    return np.interp(np.asarray(y_m, dtype=float), ys, ts)


def slice_beam_compliance(
    thickness_fn, y_M, y_F, x_F, w, E: float, nu: float, b: float, n_slices: int, plane: str = "stress"
):
    """Bending, shear and axial compliance (m/N) of a slice cantilever (Eq. 2 sums).

    thickness_fn(y) gives the full tooth thickness at heights y (array in, array out);
    y_M root-section height, y_F load height, x_F load offset, w load angle (arrays of
    equal shape, one entry per load position). Each slice has the thickness at its
    mid-height; within a slice the integrals are exact, so a prismatic beam is exact
    for any n (Timoshenko: L^3/(3EI) + 1.2 L/(GA) at w = 0).

    With S_j = k_j L (k_j = n - 1 - j slices above slice j), 1/I_j = 12 / (b t_j^3) and
    1/A_j = 1 / (b t_j), the sums over j factor into three fixed weight vectors on
    1/t_j^3 and one on 1/t_j:

        bending = 12 / (E b) [cos^2 w L^3 sum (1 + 3 k_j + 3 k_j^2) / (3 t_j^3)
                              - cos w sin w x_F L^2 sum (1 + 2 k_j) / t_j^3 + sin^2 w x_F^2 L sum 1 / t_j^3]
        shear   = 12 (1 + nu) / (5 E b) cos^2 w L sum 1 / t_j,   axial = sin^2 w L / (E b) sum 1 / t_j

    so all slices x positions are one interpolation, two reciprocals and one matrix
    product (no powers, no per-term temporaries). ``plane``: the 2D state of the bending
    and axial terms, whose E becomes E / (1 - nu^2) in plane strain (``analytic.plane``;
    the shear term's G is the same in both).
    """
    Eb = beam_modulus_Pa(E, nu, plane)
    y_M = np.asarray(y_M, dtype=float)
    y_F, x_F, w = (np.asarray(v, dtype=float) for v in (y_F, x_F, w))
    L = (y_F - y_M) / n_slices
    # slices x positions: along each row the heights are sorted when the positions are,
    # which np.interp's search exploits. Two arrays of that size, y and t, and no other:
    # every further temporary that large makes the allocator hand memory back to the
    # system and fault it in again on the next call, which costs more than the arithmetic
    y = np.multiply.outer(np.arange(n_slices) + 0.5, L)
    y += y_M
    t = np.asarray(thickness_fn(y), dtype=float)
    if np.may_share_memory(t, y):  # y is overwritten below
        t = t.copy()
    if t.size and not np.min(t) > 0:  # also catches NaN
        raise fail_text(None, "slice thickness <= 0: the tooth is consumed (wear deeper than the tooth)")
    inv_sum = np.divide(1.0, t, out=y).sum(axis=0)
    cube = np.multiply(t, t, out=y)
    cube *= t
    sums = np.tensordot(_slice_weights(n_slices), np.divide(1.0, cube, out=cube), axes=(0, 0))
    c, s = np.cos(w), np.sin(w)
    bending = 12.0 / (Eb * b) * (c * c * L**3 * sums[0] - c * s * x_F * L**2 * sums[1] + s * s * x_F**2 * L * sums[2])
    shear = 12.0 * (1 + nu) / (5.0 * E * b) * c * c * L * inv_sum
    axial = s * s * L / (Eb * b) * inv_sum
    return bending, shear, axial


@lru_cache(maxsize=8)
def _slice_weights(n_slices: int) -> np.ndarray:
    """(n, 3) weights of 1/t_j^3 in the bending sums of :func:`slice_beam_compliance`."""
    k = np.arange(n_slices - 1, -1, -1, dtype=float)
    W = np.column_stack([(1.0 + 3.0 * k + 3.0 * k * k) / 3.0, 1.0 + 2.0 * k, np.ones(n_slices)])
    W.flags.writeable = False  # shared by every call
    return W


def tooth_compliance(
    loaded: ToothProfile,
    radius_m,
    material: Material,
    face_width_m: float,
    n_slices: int = DEFAULT_SLICES,
    opposite: ToothProfile | None = None,
    crack: Crack | None = None,
    plane: str = "stress",
) -> SliceCompliance:
    """Slice-model compliance of one tooth loaded at contact radii ``radius_m`` (m).

    ``loaded`` is the loaded flank (worn or not); ``opposite`` the other flank
    (defaults to ``loaded`` mirrored; pass the nominal profile for one-flank wear).
    ``crack``: a root crack on the loaded flank (``geometry.crack.Crack``), reduced
    sections as in the module docstring; the foundation term is unchanged. None (the
    default) is the intact tooth, computed exactly as without the argument.
    ``plane``: "stress" (the paper's delta_1) or "strain" (E / (1 - nu^2) in its bending and
    axial terms); delta_2 is Weber's plane-strain foundation in both (module docstring).
    Vectorized over radii x slices.
    """
    if n_slices < 1:
        raise fail_text("n_slices", f"n_slices = {n_slices}: must be >= 1", n_slices)
    lp = load_points(loaded, radius_m)
    y_M = root_height_m(loaded)
    ys, ts = thickness_table(loaded, opposite)  # one table for the slices and the root section
    if crack is None:

        def thickness(y):
            return np.interp(y, ys, ts)
    else:
        red = reduced_section(loaded, crack)

        def thickness(y):
            return np.interp(y, ys, ts) - red.loss_m(y)

    bending, shear, axial = slice_beam_compliance(
        thickness,
        np.full_like(lp.y_m, y_M),
        lp.y_m,
        lp.x_m,
        lp.w_rad,
        material.youngs_modulus_Pa,
        material.poisson_ratio,
        face_width_m,
        n_slices,
        plane,
    )
    foundation = _weber(lp.y_axis_m, lp.w_rad, y_M, float(np.interp(y_M, ys, ts)), material, face_width_m)
    return SliceCompliance(lp.radius_m, bending, shear, axial, foundation)


def weber_foundation(
    loaded: ToothProfile, y_axis_m, w_rad, material: Material, face_width_m: float, opposite: ToothProfile | None = None
) -> np.ndarray:
    """Weber's root deflection per unit load, paper Eqs. 3-4 (m/N)."""
    y_M, _ = root_section(loaded)
    s_f = float(thickness_at_height(loaded, np.array([y_M]), opposite)[0])  # 2 Y_M
    return _weber(y_axis_m, w_rad, y_M, s_f, material, face_width_m)


def _weber(y_axis_m, w_rad, y_M: float, s_f: float, material: Material, face_width_m: float) -> np.ndarray:
    """Eqs. 3-4 from the root section height y_M and thickness s_f = 2 Y_M (m)."""
    E, nu = material.youngs_modulus_Pa, material.poisson_ratio
    ratio = (np.asarray(y_axis_m) - y_M) / s_f  # L_f / (2 Y_M)
    w = np.asarray(w_rad)
    bracket = (
        5.306 * ratio**2
        + 2.0 * (1 - nu - 2 * nu**2) / (1 - nu**2) * ratio
        + 1.534 * (1 + 0.4167 * np.tan(w) ** 2 / (1 + nu))
    )
    return np.cos(w) ** 2 * (1 - nu**2) / (E * face_width_m) * bracket


def hertz_approach_m(force_N, materials: Material | tuple[Material, Material], face_width_m: float) -> np.ndarray:
    """Nonlinear Hertzian approach of the pair, paper Eq. 5: 1.275 F^0.9 / (E^0.9 b^0.8) (m)."""
    F = np.maximum(np.asarray(force_N, dtype=float), 0.0)
    return hertz_coefficient(materials, face_width_m) * F**0.9


def hertz_coefficient(materials: Material | tuple[Material, Material], face_width_m: float) -> float:
    """a in delta_3 = a F^0.9 (SI). Palmgren's empirical law is written for one steel
    (nu = 0.3 built in); for two materials E is the equivalent modulus 2 E1 E2 / (E1 + E2),
    as ISO 6336-1 takes it, which is exact for the Hertz E* when nu1 = nu2."""
    m1, m2 = (materials, materials) if isinstance(materials, Material) else materials
    E1, E2 = m1.youngs_modulus_Pa, m2.youngs_modulus_Pa
    E = E1 if E1 == E2 else 2.0 * E1 * E2 / (E1 + E2)
    return 1.275 / (E**0.9 * face_width_m**0.8)
