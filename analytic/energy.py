"""Single-tooth compliance by the potential-energy method, on the true tooth profile.

The tooth is a cantilever of variable section along its axis (+y), clamped at the
root circle y_M = r_f and loaded at the contact point (x_F, y_F) by the mesh force
F along -(cos w, sin w) (see ``geometry.loading``). Equating the strain energy of
each mechanism to F^2 / (2 k) gives the compliances (Yang & Lin, J. Mech. Transm.
Autom. Des. 109, 1987; Tian, MSc thesis, Univ. of Alberta, 2004; Chaari, Fakhfakh &
Haddar, Eur. J. Mech. A/Solids 28, 2009):

    bending   1/k_b = int_{y_M}^{y_F} [cos w (y_F - y) - sin w x_F]^2 / (E I(y)) dy
    shear     1/k_s = int_{y_M}^{y_F} 1.2 cos^2 w / (G A(y)) dy
    axial     1/k_a = int_{y_M}^{y_F} sin^2 w / (E A(y)) dy

    I(y) = (2 x(y))^3 b / 12,  A(y) = 2 x(y) b,  G = E / (2 (1 + nu))      [m^4, m^2, Pa]

with the half thickness x(y) of the true (nominal or worn) profile,
``geometry.loading.half_thickness_at_height``, and b the face width (m). All
compliances are in m/N (deflection along the line of action per unit normal force).

Quadrature. x(y) is the linear interpolant of the profile polyline, so the
integrands have a kink at every polyline vertex, the fillet/involute junction among
them. A Gauss-Legendre rule over a span that contains kinks converges only
algebraically and its result jitters with the number of points at the size of the
polyline sag (~1e-5 relative here). The integrals are therefore split at every vertex
height: on each piece the integrand is a smooth rational function and an n-point
Gauss-Legendre rule converges exponentially. With eta = y - y_M the integrals need
only four position-independent cumulative moments,

    J_k(Y) = int_{y_M}^{Y} eta^k / x^3 dy  (k = 0, 1, 2),   K(Y) = int_{y_M}^{Y} dy / x,

since, with a = cos w, s = sin w, p = a (y_F - y_M) - s x_F,

    1/k_b = 3 / (2 E b) [p^2 J_0 - 2 p a J_1 + a^2 J_2](y_F)
    1/k_s = 1.2 a^2 / (2 G b) K(y_F),    1/k_a = s^2 / (2 E b) K(y_F).

They are accumulated once over the vertex pieces and completed for each contact by
one partial piece up to y_F: vectorized over positions and Gauss points, no loop
per position.

Fillet-foundation (gear body) compliance, Sainsot, Velex & Duverger (J. Mech. Des.
126:748, 2004), as used by Chaari et al. (2009):

    1/k_f = cos^2 w / (E b) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2 w)]   [m/N]

u_f: distance along the tooth axis from the root circle to where the force line
crosses the axis (m); S_f: tooth thickness at the root section, 2 x(y_M) (m);
X* = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f + E h_fi + F with
h_fi = r_f / r_int (r_int: hub/bore radius) and theta_f = S_f / (2 r_f) (rad).

Root crack (``crack=``, ``geometry.crack``): the reduced-section model of Chen, Z. &
Shao, Y., "Dynamic simulation of spur gear with tooth root crack propagating along
tooth width and crack depth", Engineering Failure Analysis 18(8):2149-2164 (2011),
after Tian (2004). With h_q = x_C - q sin nu the distance of the crack tip from the
centre line (x_C: the crack mouth's, q: depth, nu: crack angle) and h_x(y) the
loaded-side half thickness, a section at height y >= y_q (the tip height) with
h_x > h_q keeps only h_q on the cracked side:

    A(y) = (h_q + h_x'(y)) b,   I(y) = (h_q + h_x'(y))^3 b / 12      [m^2, m^4]

(h_x' the opposite half thickness); sections with h_x <= h_q, or below the tip, are
intact. The integrals above keep their form with x(y) = (h_q + h_x'(y)) / 2 there;
the tip height and the heights where h_x = h_q are added to the quadrature breaks
(a jump and a kink of x(y)), so the Gauss rule stays exponentially convergent. The
foundation term (Sainsot) is unchanged: it is the gear body's, whose root section
S_f the reference model leaves intact.

Hertz contact (linear, Yang & Lin 1987), identical materials:

    1/k_h = 4 (1 - nu^2) / (pi E b)                                            [m/N]

Plane state: the beam terms (E, G) are plane stress by derivation; with plane = "strain" (the
scene key fem.plane, resolved as for the FE) bending and axial take E / (1 - nu^2) and shear
keeps G (``analytic.plane``). The Hertz term is plane strain (line contact of long cylinders)
in both states, right at every face width since the contact zone (a ~ 64 um) is far narrower
than any face; Sainsot's foundation is a fit to 2D results at one Poisson ratio with only E in
it, so its state cannot be switched and it is kept as published.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from gearwear.core.validation import fail, fail_text
from gearwear.geometry.crack import Crack, reduced_section
from gearwear.geometry.loading import half_thickness_at_height, load_points, root_section, thickness_table
from gearwear.geometry.profile import FILLET, INVOLUTE, TIP_LAND, ToothProfile
from gearwear.geometry.spec import Material

from .plane import beam_modulus_Pa

#: Timoshenko shear coefficient of a rectangular section used by the energy method.
SHEAR_FACTOR = 1.2

#: Sainsot et al. (2004) coefficients (A, B, C, D, E, F) of L*, M*, P*, Q*, as
#: reproduced by Chaari et al. (2009) and later papers.
SAINSOT_COEFFICIENTS = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}

#: Parameter range over which the Sainsot polynomials were fitted, as quoted with
#: the formula by later implementations (h_fi = r_f / r_int >= 1 by definition).
#: Outside it the formula is extrapolated and the result is flagged.
SAINSOT_H_FI_RANGE = (1.4, 7.0)
SAINSOT_THETA_F_RANGE_RAD = (0.01, 0.12)


def sainsot_coefficients(h_fi, theta_f_rad) -> dict[str, np.ndarray]:
    """L*, M*, P*, Q* of Sainsot et al. (2004) (dimensionless):

        X*(h_fi, theta_f) = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f + E h_fi + F

    h_fi = r_f / r_int (root over bore radius), theta_f = tooth half angle at the
    root circle (rad). Broadcasts over array arguments.
    """
    h = np.asarray(h_fi, dtype=float)
    t = np.asarray(theta_f_rad, dtype=float)
    return {
        k: A / t**2 + B * h**2 + C * h / t + D / t + E * h + F for k, (A, B, C, D, E, F) in SAINSOT_COEFFICIENTS.items()
    }


def sainsot_in_fit_range(h_fi: float, theta_f_rad: float) -> bool:
    """True if (h_fi, theta_f) lie inside :data:`SAINSOT_H_FI_RANGE` and
    :data:`SAINSOT_THETA_F_RANGE_RAD`."""
    return bool(
        SAINSOT_H_FI_RANGE[0] <= h_fi <= SAINSOT_H_FI_RANGE[1]
        and SAINSOT_THETA_F_RANGE_RAD[0] <= theta_f_rad <= SAINSOT_THETA_F_RANGE_RAD[1]
    )


def foundation_compliance(
    w_rad, u_f_m, S_f_m: float, h_fi: float, theta_f_rad: float, material: Material, face_width_m: float
) -> np.ndarray:
    """Fillet-foundation compliance (m/N) of Sainsot, Velex & Duverger (2004):

        1/k_f = cos^2 w / (E b) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2 w)]

    w: load angle (rad); u_f: root circle to the force line's crossing of the tooth
    axis (m); S_f: root tooth thickness (m); E in Pa, b in m.
    """
    c = sainsot_coefficients(h_fi, theta_f_rad)
    w = np.asarray(w_rad, dtype=float)
    r = np.asarray(u_f_m, dtype=float) / S_f_m
    bracket = c["L"] * r**2 + c["M"] * r + c["P"] * (1.0 + c["Q"] * np.tan(w) ** 2)
    return np.cos(w) ** 2 / (material.youngs_modulus_Pa * face_width_m) * bracket


def hertz_compliance_linear(materials: Material | tuple[Material, Material], face_width_m: float) -> float:
    """Linearised Hertz contact compliance of a tooth pair (m/N), Yang & Lin (1987):

        1/k_h = 4 (1 - nu^2) / (pi E b)                          one material
        1/k_h = 2 / (pi b) [(1 - nu1^2) / E1 + (1 - nu2^2) / E2]   = 2 / (pi b E*)

    (the same expression: with E1 = E2 the bracket is 2 (1 - nu^2) / E). Independent of
    the load and of the contact radii (the load-independent linearisation of the line
    contact; a nonlinear law belongs elsewhere). ``materials``: one Material for both
    teeth or (pinion, gear).
    """
    m1, m2 = (materials, materials) if isinstance(materials, Material) else materials
    if m1 == m2:
        nu = m1.poisson_ratio
        return 4.0 * (1.0 - nu**2) / (math.pi * m1.youngs_modulus_Pa * face_width_m)
    s = sum((1.0 - m.poisson_ratio**2) / m.youngs_modulus_Pa for m in (m1, m2))
    return 2.0 * s / (math.pi * face_width_m)


@lru_cache(maxsize=8)
def _gauss_legendre(n_gauss: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the n-point Gauss-Legendre rule on [-1, 1] (read-only)."""
    xg, wg = np.polynomial.legendre.leggauss(n_gauss)
    xg.flags.writeable = wg.flags.writeable = False  # shared by every call
    return xg, wg


def _cumulative_moments(
    half_thickness: Callable[[np.ndarray], np.ndarray], breaks: np.ndarray, upper: np.ndarray, n_gauss: int
) -> np.ndarray:
    """(4, n_pos) array of [J_0, J_1, J_2, K] from breaks[0] to ``upper`` (see module doc).

    Full pieces between consecutive breaks are integrated once; each position adds
    the partial piece from the last break below it.
    """
    xg, wg = _gauss_legendre(n_gauss)
    y0 = breaks[0]

    def moments(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        half = 0.5 * (b - a)
        y = (0.5 * (a + b))[:, None] + half[:, None] * xg[None, :]
        x = np.asarray(half_thickness(y.ravel()), dtype=float).reshape(y.shape)
        eta = y - y0
        inv = 1.0 / x
        inv3 = inv * inv * inv
        eta_inv3 = eta * inv3
        return np.stack([inv3 @ wg, eta_inv3 @ wg, (eta * eta_inv3) @ wg, inv @ wg]) * half  # (4, n_pieces)

    full = moments(breaks[:-1], breaks[1:])
    cum = np.concatenate([np.zeros((4, 1)), np.cumsum(full, axis=1)], axis=1)
    k = np.clip(np.searchsorted(breaks, upper, side="right") - 1, 0, len(breaks) - 2)
    return cum[:, k] + moments(breaks[k], upper)


def beam_compliance(
    half_thickness: Callable[[np.ndarray], np.ndarray],
    breaks_m,
    x_load_m,
    y_load_m,
    w_rad,
    material: Material,
    face_width_m: float,
    n_gauss: int = 16,
    plane: str = "stress",
):
    """Bending, shear and axial compliance (m/N) of a cantilever tooth, each an array
    over the load positions (equations in the module docstring).

    ``half_thickness(y)``: half thickness x (m) at heights y (m), vectorized.
    ``breaks_m``: increasing heights (m) where x(y) may be non-smooth; the first is
    the clamped root section y_M, the last must reach the highest load.
    ``x_load_m``, ``y_load_m``, ``w_rad``: contact point (m) and load angle (rad).
    ``plane``: the 2D state; plane strain puts E / (1 - nu^2) in the bending and axial
    terms and keeps G in the shear term (``analytic.plane``).
    """
    if n_gauss < 1:
        raise fail_text("n_gauss", f"n_gauss = {n_gauss}: must be >= 1", n_gauss)
    breaks = np.asarray(breaks_m, dtype=float)
    if breaks.ndim != 1 or len(breaks) < 2 or np.any(np.diff(breaks) <= 0):
        raise ValueError("breaks_m must be a strictly increasing sequence of at least two heights")
    x_F, y_F, w = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=float)) for v in (x_load_m, y_load_m, w_rad)))
    y_M = breaks[0]
    if np.any(y_F <= y_M) or np.any(y_F > breaks[-1] * (1 + 1e-12)):
        raise ValueError(
            f"load heights must lie in ({y_M:.6g}, {breaks[-1]:.6g}] m (above the root section, within the profile)"
        )
    J0, J1, J2, K = _cumulative_moments(half_thickness, breaks, y_F, n_gauss)
    E, G, b = (
        beam_modulus_Pa(material.youngs_modulus_Pa, material.poisson_ratio, plane),
        material.shear_modulus_Pa,
        face_width_m,
    )
    a, s = np.cos(w), np.sin(w)
    # expanding [a (y_F - y) - s x_F]^2 about y_M keeps the moments position-free;
    # with eta measured from y_M the terms stay of the lever's size (no cancellation)
    p = a * (y_F - y_M) - s * x_F
    bending = 3.0 / (2.0 * E * b) * (p**2 * J0 - 2.0 * p * a * J1 + a**2 * J2)
    shear = SHEAR_FACTOR * a**2 / (2.0 * G * b) * K
    axial = s**2 / (2.0 * E * b) * K
    return bending, shear, axial


def profile_breaks(profile: ToothProfile, y_root_m: float) -> np.ndarray:
    """Heights (m) of the flank polyline vertices from the root section up: the
    kinks of x(y) (fillet/involute junction included), with y_root_m first."""
    sel = (profile.region == FILLET) | (profile.region == INVOLUTE) | (profile.region == TIP_LAND)
    ys = profile.xy[sel, 1]
    ys = ys[ys > y_root_m]
    return np.unique(np.concatenate([[y_root_m], ys]))


@dataclass(frozen=True)
class ToothCompliance:
    """Compliance components (m/N) of one tooth at contact radii ``radius_m`` (m).

    Arrays have the length of ``radius_m``. ``foundation_in_fit_range`` is False when
    (h_fi, theta_f) lie outside the range of the Sainsot fit (the value is then an
    extrapolation, not an error).
    """

    radius_m: np.ndarray
    w_rad: np.ndarray
    bending_m_per_N: np.ndarray
    shear_m_per_N: np.ndarray
    axial_m_per_N: np.ndarray
    foundation_m_per_N: np.ndarray
    h_fi: float
    theta_f_rad: float
    foundation_coefficients: dict
    foundation_in_fit_range: bool
    face_width_m: float
    n_gauss: int

    @property
    def total_m_per_N(self) -> np.ndarray:
        """Bending + shear + axial + foundation (the tooth's share, without Hertz)."""
        return self.bending_m_per_N + self.shear_m_per_N + self.axial_m_per_N + self.foundation_m_per_N

    @property
    def stiffness_N_per_m(self) -> np.ndarray:
        return 1.0 / self.total_m_per_N


def tooth_compliance(
    profile: ToothProfile,
    radius_m,
    material: Material,
    face_width_m: float,
    n_gauss: int = 16,
    opposite: ToothProfile | None = None,
    crack: Crack | None = None,
    plane: str = "stress",
) -> ToothCompliance:
    """Potential-energy compliance of the tooth ``profile`` loaded at contact radii
    ``radius_m`` (m) on its (nominal or worn) right flank.

    Bending, shear and axial terms integrate the true half thickness from the root
    circle y_M = r_f to the contact height (``n_gauss`` Gauss-Legendre points per
    profile piece); the foundation term is Sainsot et al. (2004) with
    S_f = 2 x(y_M), theta_f = S_f / (2 r_f), h_fi = r_f / r_hub and
    u_f = y_axis - y_M. Equations: module docstring. E, G in Pa; b in m.
    ``opposite``: the other flank (default: symmetric tooth); with one-flank wear pass
    the nominal profile so the thickness is x_worn + x_nominal.
    ``crack``: a root crack on the loaded flank (``geometry.crack.Crack``): reduced
    sections in the bending, shear and axial integrals (module docstring), foundation
    unchanged. None (the default) is the intact tooth, computed exactly as without it.
    ``plane``: "stress" or "strain", the beam terms' 2D state (:func:`beam_compliance`); the
    foundation and Hertz terms are the same in both (module docstring).
    """
    lp = load_points(profile, radius_m)
    y_M, x_M = root_section(profile)
    if np.any(lp.y_m <= y_M):
        bad = float(lp.radius_m[lp.y_m <= y_M][0])
        raise fail(
            "contact radius",
            bad * 1e3,
            "mm",
            f"its contact point lies below the root section y_M = {y_M * 1e3:.6g} mm (use radii on the active flank)",
        )
    breaks = profile_breaks(profile, y_M)
    if opposite is not None:
        breaks = np.unique(np.concatenate([breaks, profile_breaks(opposite, y_M)]))
        x_M = 0.5 * (x_M + float(half_thickness_at_height(opposite, np.array([y_M]))[0]))
    ys, ts = thickness_table(profile, opposite)
    if crack is None:

        def half(y):
            return 0.5 * np.interp(y, ys, ts)
    else:
        red = reduced_section(profile, crack)
        cb = red.breaks_m()
        breaks = np.unique(np.concatenate([breaks, cb[(cb > y_M) & (cb < breaks[-1])]]))

        def half(y):
            return 0.5 * (np.interp(y, ys, ts) - red.loss_m(y))

    bending, shear, axial = beam_compliance(
        half, breaks, lp.x_m, lp.y_m, lp.w_rad, material, face_width_m, n_gauss, plane
    )
    r_f = profile.gear.root_radius_m
    S_f = 2.0 * x_M
    theta_f = S_f / (2.0 * r_f)
    h_fi = r_f / profile.gear.hub_radius_m
    foundation = foundation_compliance(lp.w_rad, lp.y_axis_m - y_M, S_f, h_fi, theta_f, material, face_width_m)
    coeffs = {k: float(v) for k, v in sainsot_coefficients(h_fi, theta_f).items()}
    return ToothCompliance(
        radius_m=lp.radius_m,
        w_rad=lp.w_rad,
        bending_m_per_N=bending,
        shear_m_per_N=shear,
        axial_m_per_N=axial,
        foundation_m_per_N=foundation,
        h_fi=h_fi,
        theta_f_rad=theta_f,
        foundation_coefficients=coeffs,
        foundation_in_fit_range=sainsot_in_fit_range(h_fi, theta_f),
        face_width_m=face_width_m,
        n_gauss=n_gauss,
    )
