"""The model's equations on arrays of samples (vectorised numpy).

The reference the compiled kernels (``dynamics.kernel_rhs``) are tested against, and the
source of the derived signals (mesh force, contact modes, accelerations). SI units: m, m/s,
N, N/m, N s/m; see ``dynamics.model`` for the derivation and the paper corrections.

Mesh kinematics (paper Eq. 18, ``mesh_geometry``). Static centre-distance coupling:

    delta = q + (x_p - x_g) sin a + (y_p - y_g) cos a,
    G = d delta / d(y_p, x_p, y_g, x_g, q) = (cos a, sin a, -cos a, -sin a, 1),  b = b0

dynamic coupling: ``C = |O_g - O_p|``, ``cos a' = (R_p + R_g) / C``,
``delta = q + (y_p - y_g) cos a'``, ``b(C) = b0 + (R_p + R_g)(inv a' - inv a0)``; G and
``Gb = d b / d(y_p, x_p, y_g, x_g)`` are the exact gradients.

Contact law (Eqs. 19-20, ``mesh_state``): ``s = delta - e``; drive flank ``s > b``:
``f = s - b``, back flank ``s < -b``: ``f = s + b``;
``F_m = c_h delta' [in contact, or always with mesh_damping "paper"] + k_h f``. Without a
flank law (no backlash, static coupling) ``F_m = c_h delta' + k_h s``.

Bearings (Eqs. 7-10, ``bearing_f``): dead zone of half-width b_b.

Accelerations (Eq. 17 reduced, ``_accelerations``), with ``Q = -F_m G + k (f_drive -
f_back) Gb``:

    m_p y_p'' = Q_0 - c_bp y_p' - k_b f_b(y_p)   (x_p, and y_g, x_g with m_g, c_bg alike)
    m_e q''   = F_s + Q_4
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .params import _inv
from .table_time import _table_eval

if TYPE_CHECKING:
    from .model import GearDynamics


def mesh_geometry(model: GearDynamics, z):
    """Mesh kinematics for states z (..., >= 10), vectorised.

    Returns (delta, delta_dot, b, G, Gb, sin_a, cos_a): the relative mesh displacement,
    its rate, the backlash half-width, G = d delta / d(y_p, x_p, y_g, x_g, q) (..., 5) and
    Gb = d b / d(y_p, x_p, y_g, x_g) (..., 4; zero for the static coupling)."""
    z = np.asarray(z, float)
    shape = z.shape[:-1]
    Y = z[..., 0] - z[..., 2]
    if model.centre_distance == "dynamic":
        Rs = model.R_p + model.R_g
        dx = model.C0 + z[..., 3] - z[..., 1]
        dy = z[..., 2] - z[..., 0]
        C = np.hypot(dx, dy)
        ca = np.minimum(Rs / C, 1.0)
        sa = np.sqrt(1.0 - ca * ca)
        dC = np.stack([-dy / C, -dx / C, dy / C, dx / C], axis=-1)
        dca = -ca / C
        G = np.zeros(shape + (5,))
        G[..., :4] = (Y * dca)[..., None] * dC
        G[..., 0] += ca
        G[..., 2] -= ca
        G[..., 4] = 1.0
        b = (model.backlash_half_m or 0.0) + Rs * (sa / ca - np.arctan2(sa, ca) - _inv(model.alpha))
        Gb = sa[..., None] * dC
        delta = z[..., 4] + Y * ca
    else:
        s_, c_ = math.sin(model.alpha), math.cos(model.alpha)
        sa = np.full(shape, s_)
        ca = np.full(shape, c_)
        # G and Gb are constants here: read-only broadcast views, no (N, 5) arrays to fill
        G = np.broadcast_to(np.array([c_, s_, -c_, -s_, 1.0]), shape + (5,))
        Gb = np.broadcast_to(np.zeros(4), shape + (4,))
        b = np.full(shape, model.backlash_half_m or 0.0)
        delta = z[..., 4] + (z[..., 1] - z[..., 3]) * sa + Y * ca
        # G . z' added left to right as np.sum(G * z', axis=-1) adds a row of five (the same
        # numbers to the bit) without the (N, 5) product: ~2x faster on a sweep point's samples
        v = z[..., 5:10]
        ddelta = c_ * v[..., 0] + s_ * v[..., 1] + -c_ * v[..., 2] + -s_ * v[..., 3] + v[..., 4]
        return delta, ddelta, b, G, Gb, sa, ca
    ddelta = np.sum(G * z[..., 5:10], axis=-1)
    return delta, ddelta, b, G, Gb, sa, ca


def has_flank_law(model: GearDynamics) -> bool:
    """Backlash dead zone / two-flank contact law in use (backlash, or dynamic coupling)."""
    return model.backlash_half_m is not None or model.centre_distance == "dynamic"


def mesh_state(model: GearDynamics, t, z, k=None, e=None):
    """Vectorised mesh quantities for times t (N,) and states z (N, >=10).

    Contact law: drive flank in contact when s > b (spring k (s - b)), back flank when
    s < -b (spring k (s + b)); with b >= 0 at most one of them. Without backlash (static
    coupling) the mesh is a linear two-sided spring k s. Returns delta, delta_dot,
    s = delta - e, k_h, e, b, drive/back contact flags, mode (+1 drive, -1 back,
    0 separated, 2 both flanks), F_m (normal mesh force), F_damp, V_mesh and the force
    directions. ``k``/``e`` override the tables (static equilibrium)."""
    t = np.asarray(t, float)
    z = np.asarray(z, float)
    delta, ddelta, b, G, Gb, sa, ca = mesh_geometry(model, z)
    if k is not None:
        k, dk = np.full(delta.shape, float(k)), np.zeros(delta.shape)
    elif model.tvms:
        k, dk = _table_eval(model, t, "k")
    else:
        k, dk = np.full(delta.shape, model.k_mean), np.zeros(delta.shape)
    if e is not None:
        e, de = np.full(delta.shape, float(e)), np.zeros(delta.shape)
    elif model.te_excitation:
        e, de = _table_eval(model, t, "e")
    else:
        e, de = np.zeros(delta.shape), np.zeros(delta.shape)
    s = delta - e
    if has_flank_law(model):
        drive = s > b
        back = s < -b
        fd = np.where(drive, s - b, 0.0)
        fb = np.where(back, s + b, 0.0)
        damp_on = drive | back | (model.mesh_damping == "paper")
    else:
        drive = np.ones(s.shape, dtype=bool)
        back = np.zeros(s.shape, dtype=bool)
        fd = s
        fb = np.zeros(s.shape)
        damp_on = np.ones(s.shape, dtype=bool)
    mode = np.where(drive & back, 2, np.where(drive, 1, np.where(back, -1, 0)))
    Fd = np.where(damp_on, model.c_h * ddelta, 0.0)
    F = Fd + k * (fd + fb)
    return dict(
        delta=delta,
        delta_dot=ddelta,
        s=s,
        k_h=k,
        dk_dt=dk,
        e=e,
        de_dt=de,
        b=b,
        drive=drive,
        back=back,
        mode=mode,
        f_drive=fd,
        f_back=fb,
        F_damp=Fd,
        F_m=F,
        V_mesh=0.5 * k * (fd * fd + fb * fb),
        G=G,
        Gb=Gb,
        sin_a=sa,
        cos_a=ca,
    )


def bearing_f(model: GearDynamics, u):
    """Bearing dead-zone function f_b (paper Eqs. 7-10) of half-width b_b."""
    u = np.asarray(u, float)
    if model.bearing_half_clearance_m is None:
        return u
    bb = model.bearing_half_clearance_m
    return np.where(u > bb, u - bb, np.where(u < -bb, u + bb, 0.0))


def _accelerations(model: GearDynamics, t, z, k=None, e=None) -> np.ndarray:
    return accelerations_and_state(model, t, z, k, e)[0]


def accelerations_from_force(model: GearDynamics, z, F_m) -> tuple[np.ndarray, np.ndarray]:
    """(a, G): the accelerations of :func:`_accelerations` from the mesh force F_m already
    known at the states z, for the static (or no) centre-distance coupling, where G is
    constant and Gb = 0 (so Q = -F_m G): the same numbers without a second evaluation of
    the mesh state (the tables, the contact law). G is (5,)."""
    if model.centre_distance == "dynamic":
        raise ValueError("accelerations_from_force: the dynamic coupling's G depends on the state")
    sa, ca = math.sin(model.alpha), math.cos(model.alpha)
    G = np.array([ca, sa, -ca, -sa, 1.0])
    Q = -np.asarray(F_m, float)[..., None] * G
    return _bearing_accelerations(model, z, Q), G


def _bearing_accelerations(model: GearDynamics, z, Q) -> np.ndarray:
    """Eq. 17 reduced, from the generalised mesh forces Q (..., 5)."""
    cbp, cbg = model.c_b_pair
    fb = bearing_f(model, z[..., :4])
    a = np.empty(z.shape[:-1] + (5,))
    a[..., 0] = (Q[..., 0] - cbp * z[..., 5] - model.k_b * fb[..., 0]) / model.m_p
    a[..., 1] = (Q[..., 1] - cbp * z[..., 6] - model.k_b * fb[..., 1]) / model.m_p
    a[..., 2] = (Q[..., 2] - cbg * z[..., 7] - model.k_b * fb[..., 2]) / model.m_g
    a[..., 3] = (Q[..., 3] - cbg * z[..., 8] - model.k_b * fb[..., 3]) / model.m_g
    a[..., 4] = (model.F_s + Q[..., 4]) / model.m_e
    return a


def accelerations_and_state(model: GearDynamics, t, z, k=None, e=None) -> tuple[np.ndarray, dict]:
    """The accelerations (..., 5) of Eq. 17 and the :func:`mesh_state` they come from (one
    evaluation of the mesh state for callers that need both, e.g. a_delta = G . a)."""
    ms = mesh_state(model, t, z, k, e)
    # generalised mesh forces: -F G + k (f_drive - f_back) Gb
    Q = -ms["F_m"][..., None] * ms["G"]
    Q[..., :4] += (ms["k_h"] * (ms["f_drive"] - ms["f_back"]))[..., None] * ms["Gb"]
    return _bearing_accelerations(model, np.asarray(z, float), Q), ms
