"""A realistic parameter set (the paper's pair, Table 2) and simple stiffness tables.

Choices (the paper does not give them): J = m r^2 / 2 of a solid disc of the gear mass
with r = 75 mm (the reference radius, z = 30, m = 5 mm); base radii 70.477 mm
(75 mm cos 20 deg); zeta_m = 0.05, zeta_b = 0.02 converted by
:func:`gearwear.dynamics.model.damping_from_ratios`; the mesh stiffness
is a smoothed rectangular wave between 2.9e8 (single pair) and 5.0e8 N/m (two pairs)
with a double-contact fraction 0.6535 of the mesh period (contact ratio 1.6535). At
40 N m the tooth deflection (~1.2 um) stays far above the dynamic fluctuation, so the
teeth never separate; light loads near the mesh resonance do separate.
"""

from __future__ import annotations

import math

import numpy as np

from .model import GearDynamics, damping_from_ratios

_trapezoid = getattr(np, "trapezoid", None) or getattr(np, "trapz")

__all__ = ["rectangular_stiffness", "paper_pair"]


def rectangular_stiffness(
    n: int = 256,
    z: int = 30,
    k_single: float = 2.9e8,
    k_double: float = 5.0e8,
    double_fraction: float = 0.6535,
    edge_fraction: float = 0.02,
    phase_fraction: float = 0.0,
):
    """Periodic smoothed rectangular wave over one mesh period on a uniform table.

    Double contact on [phase, phase + double_fraction) of the period; the edges are
    tanh ramps of width ~edge_fraction of the period. Returns (phi, k)."""
    P = 2 * math.pi / z
    phi = np.arange(n) * P / n
    u = phi / P
    w = max(edge_fraction, 1e-9) / 2
    ind = np.zeros(n)
    for shift in (-1.0, 0.0, 1.0):
        a = phase_fraction + shift
        ind += 0.5 * (np.tanh((u - a) / w) - np.tanh((u - a - double_fraction) / w))
    return phi, k_single + (k_double - k_single) * np.clip(ind, 0.0, 1.0)


def paper_pair(
    torque_Nm: float = 40.0,
    speed_rpm: float = 1200.0,
    *,
    n_table: int = 256,
    tvms: bool = True,
    backlash_total_m: float | None = None,
    clearance_total_m: float | None = None,
    te_amplitude_m: float | None = None,
    centre_distance: str = "static",
    zeta_m: float = 0.05,
    zeta_b: float = 0.02,
    mesh_damping: str = "off-when-separated",
    k_table=None,
    phi_table=None,
    k_constant: float | None = None,
) -> GearDynamics:
    """The paper's pair (Table 2): m = 3.75 kg, R_b = 70.477 mm, alpha = 20 deg,
    k_b = 2.6e8 N/m, z = 30. ``backlash_total_m`` / ``clearance_total_m`` are total
    plays (the model uses half of each); ``te_amplitude_m`` adds e(phi) = A (1 -
    cos(2 pi u)) / 2, a wear-like loss of material peaking mid-period."""
    z = 30
    m = 3.75
    r = 75e-3
    J = 0.5 * m * r * r
    Rb = r * math.cos(math.radians(20.0))
    kb = 2.6e8
    if k_table is None:
        phi, k = rectangular_stiffness(n_table, z)
    else:
        phi, k = np.asarray(phi_table, float), np.asarray(k_table, float)
    P = 2 * math.pi / z
    km = float(_trapezoid(np.append(k, k[0]), np.append(phi, phi[0] + P)) / P)
    if not tvms and k_constant is not None:
        km = k_constant
    me = 1.0 / (Rb * Rb / J * 2)
    c_h, c_b = damping_from_ratios(zeta_m, zeta_b, km, me, kb, m, m)
    e = None
    if te_amplitude_m is not None:
        e = te_amplitude_m * 0.5 * (1 - np.cos(2 * np.pi * phi / P))
    return GearDynamics(
        m_p=m,
        m_g=m,
        J_p=J,
        J_g=J,
        R_p=Rb,
        R_g=Rb,
        alpha=math.radians(20.0),
        k_b=kb,
        c_b=c_b,
        c_h=c_h,
        T_p=torque_Nm,
        omega_p=speed_rpm * 2 * math.pi / 60,
        z_p=z,
        phi_table=phi,
        k_table=k,
        e_table=e,
        tvms=tvms,
        backlash_half_m=None if backlash_total_m is None else backlash_total_m / 2,
        bearing_half_clearance_m=None if clearance_total_m is None else clearance_total_m / 2,
        te_excitation=te_amplitude_m is not None,
        centre_distance=centre_distance,
        mesh_damping=mesh_damping,
        k_constant=k_constant,
    )
