"""Load positions and Hertzian pressure patches of the FE single tooth (``fem.tooth``).

Units: SI (m, N, rad). :func:`load_radii` gives the contact radii (m) and roll angles
(rad); :func:`hertz_patch_forces` the quadrature points (m) and point forces (N) of each
patch; :func:`patch_load` their consistent nodal forces (N), one column per position.

Load positions
--------------
Contact radii R on the loaded (right) flank of tooth 0, equally spaced in roll
angle u (i.e. along the line of action, d = r_b u for the pinion) from the start of
active profile (SAP, ``MeshGeometry.start_of_active_profile_m``) to the contact
whose Hertz patch ends one half-width below the tip corner (see :func:`load_radii`).

Load: a Hertzian pressure patch, not a point force
--------------------------------------------------
A point force makes the 2D displacement log-singular at the load point (the local
solution never converges and pollutes the convergence elsewhere). Each load is the
Hertz line-contact pressure (Johnson, *Contact Mechanics*, 1985, Eqs. 4.43-4.45)

    p(s) = p0 sqrt(1 - s^2 / a^2),  |s| <= a,  p0 = 2 F / (pi a b),
    a = sqrt(4 w R_eq / (pi E*)),   w = F / b,   1 / R_eq = 1 / rho_1 + 1 / rho_2

(s = arc length along the flank from the contact point, rho_i the involute
curvature radii at the LOA position, ``geometry.wear.hertz_half_width``) with the
full normal load F (default T / r_b1 = 568 N at T = 40 N m; the model is linear,
F only sets a, about 56-64 um here). The traction is p e_F, e_F = -(cos w, sin w)
the mesh-force direction of ``geometry.loading`` (the line of action = the inward
nominal involute normal at the contact). On the nominal flank e_F equals the local
inward normal -n up to O(a / rho) ~ 1e-2 rad at the patch edges (symmetric, so the
resultant agrees to O((a / rho)^2)); on a worn flank the local normal tilts by
dh/ds (up to ~0.3 rad where the wear ramps in at the SAP), while the pair model
(``analytic.tvms``) measures compliance along the LOA, so the force is kept on it.

The patch is narrower than the flank elements, so the consistent load vector is
integrated with n-point Gauss-Chebyshev quadrature of the 2nd kind (exact for the
square-root weight; nodes t_k = cos(k pi / (n + 1)), weights
w_k = pi / (n + 1) sin^2(k pi / (n + 1)), sum w_k = pi / 2) through point
evaluation of the shape functions phi on the meshed flank polygon:

    f = (2 F / pi) sum_k w_k e_F phi(x(s_c + a t_k))

which has the exact resultant F e_F (partition of unity). The centre-line
measure (``fem.tooth_compliance``) is insensitive to the patch: changing a by a factor 4
(load x 1/4 .. x 16) changes the compliance by < 0.1 %.
"""

from __future__ import annotations

import math

import numpy as np

from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.polyline import cumulative_length, quadratic_eval
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import hertz_half_width

#: Default transmitted torque (N m) of the paper pair (section 3.1); the default
#: normal load is T / r_b1 (pinion base radius) for either gear.
DEFAULT_TORQUE_NM = 40.0

PATCH_POINTS = 48  # Gauss-Chebyshev points per Hertz patch
# sub-steps per flank edge when measuring arc length on it: a 0.4 mm edge at 14 mm
# curvature radius is 1e-8 relative longer than its 16 sub-chords
EDGE_SUBSTEPS = 16
TIP_MARGIN_HALF_WIDTHS = 2.0  # top load: patch centre 2 a (arc length) below the tip corner


def load_radii(pair: PairSpec, gear_index: int, positions: int, load_N: float) -> tuple[np.ndarray, np.ndarray]:
    """(radii m, roll angles rad) of the load positions: equal roll-angle (LOA) steps
    from the SAP to the contact whose Hertz patch ends one half-width below the tip.

    On the involute the arc length from the base circle is r_b u^2 / 2, so putting
    the patch centre m a_tip below the tip corner (m = TIP_MARGIN_HALF_WIDTHS) gives
    u_top = sqrt(u_a^2 - 2 m a_tip / r_b); the spare half-width keeps the patch off
    the corner of a worn flank too (the corner sinks by h sin(alpha_a) < a).
    """
    g = pair.gear(gear_index)
    mg = MeshGeometry(pair, pair.centre_distance_m)
    rb = g.base_radius_m
    u_sap = math.sqrt((mg.start_of_active_profile_m[gear_index] / rb) ** 2 - 1.0)
    u_a = math.sqrt((g.tip_radius_m / rb) ** 2 - 1.0)
    d_tip = rb * u_a if gear_index == 0 else mg.line_of_action_m - rb * u_a
    a_tip = float(hertz_half_width(mg, np.array([d_tip]), load_N / pair.face_width_m)[0])
    u_top = math.sqrt(u_a**2 - 2.0 * TIP_MARGIN_HALF_WIDTHS * a_tip / rb)
    u = np.linspace(u_sap, u_top, int(positions))
    return rb * np.sqrt(1.0 + u * u), u


def hertz_patch_forces(
    flank: np.ndarray,
    v_lo: int,
    v_hi: int,
    radius_m: np.ndarray,
    half_width_m: np.ndarray,
    force_dir: np.ndarray,
    load_N: float,
    n_points: int = PATCH_POINTS,
):
    """Quadrature points and point forces of the Hertz patches on the meshed flank.

    ``flank`` (m, root -> tip) is the meshed flank as a quadratic chain (its element
    edges, ``geometry.polyline``); the patches must lie between its vertices v_lo and
    v_hi (the involute). Arc length is measured on the edges at EDGE_SUBSTEPS sub-steps
    each. Returns (points (n, k, 2), forces (n, k, 2)): points on the edges' curves at
    arc distance a t_k from the contact point at radius R, moved 1e-9 m along the
    inward normal so the element search never misses; forces (2 F / pi) w_k e_F.
    """
    u_poly = np.arange((len(flank) - 1) // 2 * EDGE_SUBSTEPS + 1) / EDGE_SUBSTEPS
    xy_poly = quadratic_eval(flank, u_poly)[0]
    s_poly = cumulative_length(xy_poly)
    s_lo, s_hi = s_poly[v_lo * EDGE_SUBSTEPS], s_poly[v_hi * EDGE_SUBSTEPS]
    r_poly = np.hypot(xy_poly[:, 0], xy_poly[:, 1])
    sel = (s_poly >= s_lo - 1e-12) & (s_poly <= s_hi + 1e-12)
    if np.any(np.diff(r_poly[sel]) <= 0):
        raise ValueError("the meshed flank radius is not monotone on the involute (wear too deep?)")
    t, w = _patch_nodes(n_points)
    s_c = np.interp(radius_m, r_poly[sel], s_poly[sel])
    s_k = s_c[:, None] + half_width_m[:, None] * t[None, :]
    if np.any(s_k < s_lo) or np.any(s_k > s_hi):
        raise ValueError(
            "a Hertz patch leaves the involute part of the flank (load too close to the tip "
            "corner or below the form circle)"
        )
    xy, tan = quadratic_eval(flank, np.interp(s_k, s_poly, u_poly))
    pts = xy + 1e-9 * np.stack([-tan[..., 1], tan[..., 0]], axis=-1)  # inward = left of the root -> tip tangent
    mag = load_N * (2.0 / np.pi) * w[None, :] * np.ones_like(s_k)
    return pts, mag[..., None] * force_dir[:, None, :]


def patch_load(model, pts: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """Consistent nodal forces (N, n) of the point forces ``forces`` (n, k, 2) at
    ``pts`` (n, k, 2) of :func:`hertz_patch_forces`, one column per position, on the 2D
    ``model`` (``fem.elasticity.ElasticModel``)."""
    n, k = pts.shape[:2]
    P = model.probe(pts.reshape(-1, 2))  # rows 2 j, 2 j + 1: x, y at point j
    G = np.zeros((2 * n * k, n))
    col = np.repeat(np.arange(n), k)
    G[0::2][np.arange(n * k), col] = forces.reshape(-1, 2)[:, 0]
    G[1::2][np.arange(n * k), col] = forces.reshape(-1, 2)[:, 1]
    return np.asarray(P.T @ G)


def _patch_nodes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Chebyshev (2nd kind): int_-1^1 sqrt(1 - t^2) f(t) dt ~ sum_k w_k f(t_k)."""
    k = np.arange(1, n + 1)
    th = k * np.pi / (n + 1)
    return np.cos(th), np.pi / (n + 1) * np.sin(th) ** 2
