"""The flat parameter vector the compiled kernels read, and the model's derived tables.

The kernels (``dynamics.kernels``) take the model as one float64 array ``par`` of ``N_PAR``
entries, indexed by the ``P_*`` constants (module globals: numba freezes them as
compile-time constants). SI units:

    P_MP, P_MG    masses m_p, m_g (kg)              P_ME   m_e = 1/(R_p^2/J_p + R_g^2/J_g) (kg)
    P_FS          F_s = T_p / R_p (N)               P_KB   bearing stiffness k_b (N/m)
    P_CBP, P_CBG  bearing damping c_b (N s/m)       P_CH   mesh damping c_h (N s/m)
    P_SA, P_CA    sin a, cos a (a: pressure angle)  P_KC   mean (or constant) mesh stiffness (N/m)
    P_B           backlash half-width b0 (m)        P_BB   bearing half-clearance b_b (m)
    P_OM          pinion speed omega_p (rad/s)      P_PER  table period (rad)
    P_C0          centre distance C0 (m)            P_RS   R_p + R_g, base radii (m)
    P_INV0        inv a0 at C0                      P_PAPER  1: mesh_damping "paper"
    P_UNI         1: uniform table (P_DPHI spacing in rad, P_PHI0 first node in rad)
    P_N           number of table nodes

``derived(model)`` returns ``(par, phi, phx, kc, ec)``: the vector, the table nodes (rad),
the periodic-extended nodes ``phx`` (n + 2: ``phi_{n-1} - P``, the nodes, ``phi_0 + P``) and
the k and e interpolants' coefficients per extended segment ((n + 1, 4), see
``dynamics.interpolant``); computed once per model instance (``GearDynamics._derived``),
read-only arrays.

``_inv`` is the involute function ``inv a = tan a - a``: the dynamic centre-distance
coupling's half backlash is ``b(C) = b0 + (R_p + R_g)(inv a'(C) - inv a0)``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .interpolant import segment_coefficients

if TYPE_CHECKING:
    from .model import GearDynamics


def _inv(a: float) -> float:
    """The involute function inv a = tan a - a (a in rad)."""
    return math.tan(a) - a


# parameter vector layout
(
    P_MP,
    P_MG,
    P_ME,
    P_FS,
    P_KB,
    P_CBP,
    P_CBG,
    P_CH,
    P_SA,
    P_CA,
    P_KC,
    P_B,
    P_BB,
    P_OM,
    P_PER,
    P_C0,
    P_RS,
    P_INV0,
    P_PAPER,
    P_UNI,
    P_DPHI,
    P_PHI0,
    P_N,
) = range(23)
N_PAR = 23


def derived(model: GearDynamics):
    """Parameter vector (``par[P_PER]`` is the table period in rad, ``table_period_rad``),
    the table nodes, the periodic-extended nodes phx (n + 2) and the
    k and e interpolants' coefficients per extended segment (n + 1, 4), see
    :func:`segment_coefficients` (computed once per model instance, read-only arrays)."""
    return model._derived


def _compute_derived(model: GearDynamics):
    P = model.table_period_rad  # par[P_PER]: the period of the tables
    phi = np.asarray(model.phi_table, float)
    n = phi.size
    par = np.zeros(N_PAR)
    par[P_MP], par[P_MG], par[P_ME] = model.m_p, model.m_g, model.m_e
    par[P_FS] = model.F_s
    par[P_KB] = model.k_b
    par[P_CBP], par[P_CBG] = model.c_b_pair
    par[P_CH] = model.c_h
    par[P_SA], par[P_CA] = math.sin(model.alpha), math.cos(model.alpha)
    par[P_KC] = model.k_mean
    par[P_B] = model.backlash_half_m or 0.0
    par[P_BB] = model.bearing_half_clearance_m or 0.0
    par[P_OM] = model.omega_p
    par[P_PER] = P
    par[P_C0] = model.C0
    par[P_RS] = model.R_p + model.R_g
    par[P_INV0] = _inv(math.acos(min(1.0, par[P_RS] / par[P_C0])))
    par[P_PAPER] = 1.0 if model.mesh_damping == "paper" else 0.0
    d = P / n
    uniform = np.allclose(np.diff(phi), d, rtol=1e-9, atol=0) and abs(phi[0]) < d * (1 - 1e-9)
    par[P_UNI] = 1.0 if uniform else 0.0
    par[P_DPHI] = d
    par[P_PHI0] = phi[0]
    par[P_N] = n
    phx = np.concatenate(([phi[-1] - P], phi, [phi[0] + P]))
    out = [par, phi, phx]
    for tab in (model.k_table, model.e_table):
        c = segment_coefficients(phi, np.asarray(tab, float), P, model.interpolation)
        # extended segments: [phi_-1 - P, phi_0) is the wrap segment, then the n table segments
        out.append(np.ascontiguousarray(np.vstack([c[-1:], c])))
    for a in out:
        a.setflags(write=False)
    return tuple(out)
