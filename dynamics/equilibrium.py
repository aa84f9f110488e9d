"""Static equilibrium under the mean mesh stiffness and the mean excitation.

The mesh carries ``F_m = F_s = T_p / R_p`` (N) along the line of action; each bearing is
deflected by the mesh force's component over k_b (N/m) plus the half clearance b_b (m),
and the mesh deflection takes up the rest (drive flank for F_s > 0, back flank for F_s < 0):

    y_p = -(F_s cos a / k_b + b_b),  x_p = -(F_s sin a / k_b + b_b),  y_g, x_g: opposite signs
    delta = e_mean + b sgn(F_s) + F_s / k_mean,   q = delta - (x_p - x_g) sin a - (y_p - y_g) cos a

(static centre-distance coupling; for F_s = 0 the bearings stay centred). With the dynamic
coupling this closed form starts a Newton solve (scipy ``root``) of zero accelerations
(``dynamics.equations``). Returns the 10 states (m, zero velocities).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from gearwear.core.validation import fail_text

from .equations import _accelerations, mesh_geometry

if TYPE_CHECKING:
    from .model import GearDynamics


def static_equilibrium(model: GearDynamics) -> np.ndarray:
    """Static equilibrium (10 states, zero velocities) under the mean stiffness and the mean
    excitation: F_m = F_s, bearings deflected by F_s cos/sin over k_b (plus the half
    clearance), delta = e_mean + b + F_s / k_mean (drive side; back side for F_s < 0).
    With the dynamic centre distance the closed form is the start of a Newton solve."""
    F = model.F_s
    k = model.k_mean
    if F != 0 and k <= 0:
        raise fail_text("k_table", "k_table: mean mesh stiffness is 0 N/m, no static equilibrium under load")
    sgn = 1.0 if F > 0 else (-1.0 if F < 0 else 0.0)
    bb = model.bearing_half_clearance_m or 0.0
    sa, ca, b = math.sin(model.alpha), math.cos(model.alpha), model.backlash_half_m or 0.0

    def bear(force):
        return 0.0 if force == 0 else force / model.k_b + math.copysign(bb, force)

    z = np.zeros(10)
    z[0], z[1], z[2], z[3] = bear(-F * ca), bear(-F * sa), bear(F * ca), bear(F * sa)
    delta = model.e_mean + sgn * b + (F / k if F != 0 else 0.0)
    z[4] = delta - (z[1] - z[3]) * sa - (z[0] - z[2]) * ca
    if model.centre_distance != "dynamic":
        return z
    from scipy.optimize import root

    xs = max(abs(F) / model.k_b, abs(F) / max(k, 1.0), 1e-9)  # scale to O(1) unknowns
    em = model.e_mean

    def resid(u):
        zz = np.zeros(10)
        zz[:5] = z[:5] + u * xs
        return (
            _accelerations(model, np.array(0.0), zz, k=k, e=em)
            * np.array([model.m_p, model.m_p, model.m_g, model.m_g, model.m_e])
            / max(abs(F), 1.0)
        )

    # start: delta of the dynamic form (no x-projection) on the drive flank
    z0 = z.copy()
    d0, _, b0, *_ = mesh_geometry(model, z0)
    z[4] += (em + sgn * float(b0) + (F / k if F != 0 else 0.0)) - float(d0)
    sol = root(resid, np.zeros(5), method="hybr", options=dict(xtol=1e-14))
    z[:5] = z[:5] + sol.x * xs
    return z
