"""Pure-Python right-hand side of the model (scalar ``math``), for scipy.integrate.solve_ivp.

``z' = f(t, z)`` for the 10 states (y_p, x_p, y_g, x_g, q in m, then their rates in m/s),
paper Eqs. 17-20 as corrected in ``dynamics.model``. Written independently of the
vectorised ``dynamics.equations`` and of the compiled ``dynamics.kernel_rhs``: three
implementations the tests compare. The table interpolant in ``phi = omega_p t`` is
evaluated from the same coefficients as the kernels (``dynamics.params``). No event
location: the contact modes (flank contact, bearing contact) follow the state.
"""

from __future__ import annotations

import bisect
import math
from typing import TYPE_CHECKING

import numpy as np

from .equations import has_flank_law
from .params import P_KC, P_PER, _inv

if TYPE_CHECKING:
    from .model import GearDynamics


def rhs_python(t: float, y, model: GearDynamics) -> np.ndarray:
    """Pure-Python right-hand side of the same model (for scipy.integrate.solve_ivp).

    Scalar ``math`` code written independently of the vectorised ``mesh_state`` and of
    the compiled kernel (a cross-check of both). The piecewise modes (flank contact,
    bearing contact) are evaluated from the state; no event location. ``y`` is the
    10-state vector (extra entries are ignored)."""
    par, phx, kc, ec = model._py_constants
    yp, xp, yg, xg, q, vyp, vxp, vyg, vxg, vq = (float(v) for v in y[:10])
    Rs = model.R_p + model.R_g
    Y = yp - yg
    if model.centre_distance == "dynamic":
        dx = model.C0 + xg - xp
        dy = yg - yp
        C = math.hypot(dx, dy)
        ca = min(Rs / C, 1.0)
        sa = math.sqrt(1.0 - ca * ca)
        b = (model.backlash_half_m or 0.0) + Rs * (sa / ca - math.atan2(sa, ca) - _inv(model.alpha))
        dC = (-dy / C, -dx / C, dy / C, dx / C)
        w = -Y * ca / C
        G = (ca + w * dC[0], w * dC[1], -ca + w * dC[2], w * dC[3])
        Gb = tuple(sa * c for c in dC)
        delta = q + Y * ca
    else:
        sa, ca = math.sin(model.alpha), math.cos(model.alpha)
        b = model.backlash_half_m or 0.0
        G = (ca, sa, -ca, -sa)
        Gb = (0.0, 0.0, 0.0, 0.0)
        delta = q + (xp - xg) * sa + Y * ca
    dd = vq + G[0] * vyp + G[1] * vxp + G[2] * vyg + G[3] * vxg
    P = par[P_PER]
    ph = model.omega_p * t
    u = ph - P * math.floor(ph / P)

    def interp(c):
        i = min(max(bisect.bisect_right(phx, u) - 1, 0), len(phx) - 2)
        d = u - phx[i]
        return c[i][0] + d * (c[i][1] + d * (c[i][2] + d * c[i][3]))

    k = interp(kc) if model.tvms else par[P_KC]
    e = interp(ec) if model.te_excitation else 0.0
    s = delta - e
    if has_flank_law(model):
        fdv = s - b if s > b else 0.0
        fbk = s + b if s < -b else 0.0
        on = fdv != 0.0 or fbk != 0.0 or s > b or s < -b or model.mesh_damping == "paper"
        fd = model.c_h * dd if on else 0.0
    else:
        fdv, fbk, fd = s, 0.0, model.c_h * dd
    F = fd + k * (fdv + fbk)
    kf = k * (fdv - fbk)
    Q = [-F * G[j] + kf * Gb[j] for j in range(4)]
    bb = model.bearing_half_clearance_m

    def fb(x):
        if bb is None:
            return x
        return x - bb if x > bb else (x + bb if x < -bb else 0.0)

    cbp, cbg = model.c_b_pair
    kb = model.k_b
    return np.array(
        [
            vyp,
            vxp,
            vyg,
            vxg,
            vq,
            (Q[0] - cbp * vyp - kb * fb(yp)) / model.m_p,
            (Q[1] - cbp * vxp - kb * fb(xp)) / model.m_p,
            (Q[2] - cbg * vyg - kb * fb(yg)) / model.m_g,
            (Q[3] - cbg * vxg - kb * fb(xg)) / model.m_g,
            (model.F_s - F) / model.m_e,
        ]
    )
