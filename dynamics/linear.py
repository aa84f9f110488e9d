"""The linearised 5-DOF model: M, C, K, natural frequencies, the fastest rate.

Linearised about the operating point with the mean mesh stiffness k (N/m) and the mesh
damper c_h (N s/m) on the line of action ``g = d delta / d(y_p, x_p, y_g, x_g, q) =
(cos a, sin a, -cos a, -sin a, 1)``, bearings k_b (N/m) and c_b (N s/m), no dead zones (no
backlash, no bearing clearance):

    M = diag(m_p, m_p, m_g, m_g, m_e)
    K = diag(k_b, k_b, k_b, k_b, 0) + k g g^T
    C = diag(c_bp, c_bp, c_bg, c_bg, 0) + c_h g g^T

Natural frequencies ``f_i = sqrt(lambda_i) / (2 pi)`` (Hz) from ``K v = lambda M v``; the
largest |eigenvalue| (rad/s) of the first-order system ``z' = [[0, I], [-M^-1 K, -M^-1 C]] z``
sets the step an explicit integrator can take (RK4: ``h |lambda|`` up to ~2.8).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .model import GearDynamics


def linear_eigenfrequencies(model: GearDynamics) -> np.ndarray:
    """Natural frequencies (Hz, ascending) of the linearised, undamped 5-DOF model: mean
    mesh stiffness, no backlash, no bearing clearance, operating pressure angle alpha."""
    from scipy.linalg import eigh

    M, _, K = _linear_matrices(model, model.k_mean)
    lam = eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(lam, 0, None)) / (2 * math.pi)


def _linear_matrices(model: GearDynamics, k: float):
    """M, C, K of the linearised 5-DOF model (mesh spring k and damper c_h on the line of
    action g = d delta / d(y_p, x_p, y_g, x_g, q), bearings k_b and c_b, no dead zones)."""
    ca, sa = math.cos(model.alpha), math.sin(model.alpha)
    g = np.array([ca, sa, -ca, -sa, 1.0])
    cbp, cbg = model.c_b_pair
    K = np.diag([model.k_b] * 4 + [0.0]) + k * np.outer(g, g)
    C = np.diag([cbp, cbp, cbg, cbg, 0.0]) + model.c_h * np.outer(g, g)
    M = np.diag([model.m_p, model.m_p, model.m_g, model.m_g, model.m_e])
    return M, C, K


def max_linear_rate(model: GearDynamics, k: float | None = None) -> float:
    """Largest |eigenvalue| (rad/s) of the linearised first-order system
    z' = [[0, I], [-M^-1 K, -M^-1 C]] z at mesh stiffness k (default: the mean). It sets
    the step an explicit integrator can take: RK4 is stable for h |lambda| up to ~2.8."""
    M, C, K = _linear_matrices(model, model.k_mean if k is None else k)
    Mi = np.diag(1.0 / np.diag(M))
    A = np.block([[np.zeros((5, 5)), np.eye(5)], [-Mi @ K, -Mi @ C]])
    return float(np.max(np.abs(np.linalg.eigvals(A))))
