"""The contact state of ``analytic.tvms`` at any pinion angle: the candidate tooth pairs,
their compliance, their initial gaps and the Hertz law.

For every candidate pair k at position d_k on the line of action
(``geometry.kinematics.MeshGeometry.slots``):

* the linear compliance c_k = (delta_1 + delta_2)_pinion + (delta_1 + delta_2)_gear per
  unit load (m/N): Ishikawa slices (``analytic.ishikawa``) or the potential-energy method
  (``analytic.energy``) on the true worn profiles, the published closed-form involute
  models ``yang_lin``, ``tian``, ``wu_zuo_parey``, ``chen_shao``, ``chen_shao_weber``
  (``analytic.involute_beam``) or Kuang & Yang's regression ``kuang_yang``
  (``analytic.kuang_yang``) on the nominal involute, each tooth's term optionally times an FE
  correction factor interpolated at its contact radius; for ``energy`` and the involute
  models plus the linear Hertz compliance 4 (1 - nu^2) / (pi E b) (Yang & Lin), while for
  ``ishikawa`` the Hertz approach a F^0.9 (paper Eq. 5) is nonlinear and enters the load
  sharing (``kuang_yang``'s regression holds the contact flexibility: no Hertz term);
* the initial gap g_k (m) along the line of action: the depths removed from both flanks
  at the contact, h_1(d) + h_2(d) (wear, ``geometry.wear``; profile modifications and
  measured deviations, ``geometry.flank``), a spall on the faulty tooth's pair
  (``geometry.faults``), and outside the path a tip corner's separation
  (:func:`corner_gap_m`).

Tip-corner contact outside the path of contact: a pair approaching A (d < d_A) touches
first with the gear's tip corner, a receding pair (d > d_E) with the pinion's; the
corner's separation from the mating flank is computed exactly from the involute
functions (the two extended involutes touch at d; the corner lies on one of them at
the tip radius). Under load these pairs take load early / keep it late, which makes
the transmission error continuous at the zone changes. Their compliance is taken at
the path end (d_A or d_E) and their wear gap is that of the path end.

:class:`_Contact` holds what does not depend on the angle (made by :func:`_contact`);
:func:`_state` evaluates the candidates at any angles, :func:`_solve` shares the load
among them (``analytic.tvms_sharing``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.faults import FaultSpec, holds_fault, revolution_periods, spall_gap_m
from gearwear.geometry.flank import FlankSpec, modification_on_line_of_action
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import operating_geometry
from gearwear.geometry.profile import ToothProfile, tooth_profile
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec, flank_depth, key_roll_angles, wear_on_line_of_action

from . import involute_beam, ishikawa, kuang_yang
from .tvms_sharing import share_load

#: the per-tooth compliance models: the paper's slices, the potential energy on the true
#: profile, the published closed-form involute models (``analytic.involute_beam``) and
#: Kuang & Yang's regression (``analytic.kuang_yang``)
METHODS = ("ishikawa", "energy", *involute_beam.MODELS, "kuang_yang")
#: the models that take a root crack (reduced sections): the paper's slices, the potential
#: energy and Chen & Shao's root-clamped involute models (the crack model is theirs)
CRACKED = ("ishikawa", "energy", "chen_shao", "chen_shao_weber")
#: the models with the linear Hertz compliance of Yang & Lin in series (kuang_yang's
#: regression holds the contact flexibility; ishikawa's Hertz law is nonlinear)
LINEAR_HERTZ = ("energy", *involute_beam.MODELS)


# -- profiles and compliance ---------------------------------------------------------


@lru_cache(maxsize=64)
def _profiles(pair: PairSpec, wear: WearSpec | None, centre_distance_m: float):
    """(nominal, loaded) profiles of pinion and gear, cached: they depend only on the
    pair, the wear and the centre distance (which sets where the wear is)."""
    mesh = MeshGeometry(pair, centre_distance_m)
    nominal = tuple(tooth_profile(g, extra_roll=key_roll_angles(mesh, i, wear)) for i, g in enumerate(pair.gears))
    if wear is None or wear.is_unworn:
        return nominal, nominal
    loaded = []
    for i, p in enumerate(nominal):
        h = flank_depth(p, i, mesh, wear)
        loaded.append(p.worn(h))
    return nominal, tuple(loaded)


def _tooth_compliance(
    method: str,
    loaded: ToothProfile,
    nominal: ToothProfile,
    radius_m: np.ndarray,
    pair: PairSpec,
    n_slices: int,
    crack=None,
    plane: str = "stress",
) -> np.ndarray:
    """delta_1 + delta_2 per unit load (m/N) of one tooth at contact radii (``crack``: a
    geometry.crack.Crack at the root of this tooth, or None)."""
    if radius_m.size == 0:
        return np.zeros(0)
    if method == "ishikawa":
        try:
            c = ishikawa.tooth_compliance(
                loaded,
                radius_m,
                loaded.gear.material,
                pair.face_width_m,
                n_slices,
                opposite=nominal,
                crack=crack,
                plane=plane,
            )
        except ValueError as exc:
            if not loaded.is_worn:
                raise  # a nominal tooth with a non-positive slice is our bug, not the user's input
            raise fail(
                "wear depth",
                float(loaded.depth.max()) * 1e6,
                "um",
                f"makes a slice of the {loaded.gear.name} tooth non-positive ({exc})",
            ) from None
        return c.total_m_per_N
    if method == "kuang_yang" or (crack is not None and method not in CRACKED):
        if crack is not None:
            raise fail("method", repr(method), "", f"does not model a root crack (use {', '.join(CRACKED)})")
        return kuang_yang.tooth_compliance(loaded.gear, radius_m, pair.face_width_m)
    if method in involute_beam.MODELS:
        tip = None
        if crack is not None:
            from gearwear.geometry.crack import crack_line

            mouth, _ = crack_line(loaded, crack)  # the ISO 30-degree fillet point's height
            tip = involute_beam.crack_tip_m(loaded.gear, method, float(mouth[1]), crack.depth_m, crack.angle_rad)
        ci = involute_beam.tooth_compliance(method, loaded.gear, radius_m, pair.face_width_m, plane, crack_tip_m=tip)
        return ci.total_m_per_N
    from . import energy

    ce = energy.tooth_compliance(
        loaded, radius_m, loaded.gear.material, pair.face_width_m, opposite=nominal, crack=crack, plane=plane
    )
    return np.asarray(ce.total_m_per_N)


def _involute_fn(u):
    return u - np.arctan(u)


def corner_gap_m(mesh: MeshGeometry, d, side: str) -> np.ndarray:
    """Separation (m) of a tip corner from the mating flank for a pair whose extended
    involutes touch at LOA position d.

    side = "entry": gear tip corner vs pinion flank (d near or below d_A);
    side = "exit": pinion tip corner vs gear flank (d near or above d_E).

    LOA frame: T1 = (0, 0), T2 = (L, 0), O1 = (0, -r_b1), O2 = (L, r_b2). On the pinion
    flank touching the LOA at d, theta_1 - inv = pi/2 - d / r_b1 (polar angle about O1);
    on the gear flank, theta_2 - inv = -pi/2 - (L - d) / r_b2 (about O2). Two involutes of
    one base circle turned by dphi are r_b dphi apart along every common normal.
    """
    d = np.asarray(d, dtype=float)
    g1, g2 = mesh.pair.gear(0), mesh.pair.gear(1)
    rb1, rb2, L = g1.base_radius_m, g2.base_radius_m, mesh.line_of_action_m
    u1 = d / rb1
    u2 = (L - d) / rb2
    if side == "entry":
        ua2 = math.sqrt((g2.tip_radius_m / rb2) ** 2 - 1.0)
        th = -0.5 * math.pi - u2 + _involute_fn(ua2)  # gear tip corner, polar angle about O2
        qx = L + g2.tip_radius_m * np.cos(th)
        qy = rb2 + g2.tip_radius_m * np.sin(th)
        r = np.hypot(qx, qy + rb1)
        ur = np.sqrt(np.maximum((r / rb1) ** 2 - 1.0, 0.0))
        psi_q = np.arctan2(qy + rb1, qx) - _involute_fn(ur)
        psi_flank = 0.5 * math.pi - u1
        return rb1 * np.abs(psi_q - psi_flank)
    ua1 = math.sqrt((g1.tip_radius_m / rb1) ** 2 - 1.0)
    th = 0.5 * math.pi - u1 + _involute_fn(ua1)  # pinion tip corner, polar angle about O1
    qx = g1.tip_radius_m * np.cos(th)
    qy = -rb1 + g1.tip_radius_m * np.sin(th)
    r = np.hypot(qx - L, qy - rb2)
    ur = np.sqrt(np.maximum((r / rb2) ** 2 - 1.0, 0.0))
    psi_q = np.arctan2(qy - rb2, qx - L) - _involute_fn(ur)
    psi_flank = -0.5 * math.pi - u2
    return rb2 * np.abs(psi_q - psi_flank)


# -- the contact state at any pinion angle --------------------------------------------


@dataclass(frozen=True)
class _Contact:
    """Everything the load sharing needs that does not depend on the pinion angle: the
    operating geometry, the profiles, the compliance models and corrections, the gap
    sources and the Hertz law. :func:`_state` evaluates it at any angles."""

    method: str
    pair: PairSpec
    mesh: MeshGeometry
    nominal: tuple
    loaded: tuple
    n_slices: int
    corrections: tuple
    crack_correction: object
    wear: WearSpec | None
    flank: FlankSpec | None
    faults: FaultSpec | None
    corner_contact: bool
    form_limits_m: tuple[float, float]  # LOA range where a corner can touch the mating involute
    hertz: tuple[float, float]  # (a, expo) of delta_H = a F^expo (0, 1: linear, in c)
    c_hertz_m_per_N: float  # linear Hertz compliance (energy method), else 0
    total_N: float  # T / r_b1 along the LOA
    periods: int
    plane: str = "stress"  # 2D state of the tooth beam terms (analytic.plane)


def _contact(
    pair: PairSpec,
    method: str,
    torque_Nm: float,
    clearance_m: float,
    wear: WearSpec | None,
    bearing_stiffness_N_per_m: float,
    n_slices: int,
    corner_contact: bool,
    correction,
    flank,
    faults,
    crack_correction,
    plane: str = "stress",
) -> _Contact:
    if method not in METHODS:
        raise fail("method", repr(method), "", f"must be one of {', '.join(METHODS)} (iso6336 is a constant)")
    if not (torque_Nm > 0 and math.isfinite(torque_Nm)):
        raise fail("torque_Nm", torque_Nm, "N m", "must be in (0, 1e7] N m")
    og = operating_geometry(
        pair, clearance_m, torque_Nm if math.isfinite(bearing_stiffness_N_per_m) else 0.0, bearing_stiffness_N_per_m
    )
    mesh = og.mesh
    nominal, loaded = _profiles(pair, wear, mesh.centre_distance_m)
    rb1, rb2 = pair.gear(0).base_radius_m, pair.gear(1).base_radius_m
    L = mesh.line_of_action_m
    # extended (corner) contact is possible while the mating involute exists
    lo = max(rb1 * math.sqrt(max((nominal[0].form_radius_m / rb1) ** 2 - 1, 0)), 1e-9)
    hi = L - rb2 * math.sqrt(max((nominal[1].form_radius_m / rb2) ** 2 - 1, 0))
    c_hertz = 0.0
    if method == "ishikawa":
        hertz = (ishikawa.hertz_coefficient(pair.materials, pair.face_width_m), 0.9)
    elif method not in LINEAR_HERTZ:
        hertz = (0.0, 1.0)
    else:
        from . import energy

        c_hertz = energy.hertz_compliance_linear(pair.materials, pair.face_width_m)
        hertz = (0.0, 1.0)
    return _Contact(
        method,
        pair,
        mesh,
        nominal,
        loaded,
        n_slices,
        correction or (None, None),
        crack_correction,
        wear,
        flank,
        faults,
        corner_contact,
        (lo, hi),
        hertz,
        c_hertz,
        torque_Nm / rb1,
        revolution_periods(pair, faults),
        plane,
    )


def _compliance(s: _Contact, k: int, radius_m: np.ndarray, corr, crack=None) -> np.ndarray:
    """delta_1 + delta_2 per unit load (m/N) of gear k's tooth at contact radii, times the
    FE correction factor interpolated at the radius (``corr``: (radius_m, factor))."""
    cg = _tooth_compliance(s.method, s.loaded[k], s.nominal[k], radius_m, s.pair, s.n_slices, crack, s.plane)
    if corr is not None:
        grid, factor = (np.asarray(a, dtype=float) for a in corr)
        cg = cg * np.interp(radius_m, grid, factor)
    return cg


def _state(s: _Contact, theta_rad: np.ndarray, period: np.ndarray):
    """Candidate pairs at pinion angles ``theta_rad`` (rad, measured in mesh period
    ``period``; not wrapped, so slot j keeps its pair over the closed period [0, P]).

    Returns (c, gap, d, in_path, faulty), arrays (angles x slots): c the pair compliance
    (m/N, inf where the slot holds no candidate), gap the initial gap (m), d the LOA
    position (m), in_path inside [A, E], faulty the slot holds the faulty tooth (None
    without a fault). Compliances and gaps inside the path are taken at each distinct
    position once; the corners at the path ends (their depths are those of the tip and
    of the SAP), plus their separation from the mating flank (:func:`corner_gap_m`)."""
    mesh, pair = s.mesh, s.pair
    A, E = mesh.path_start_m, mesh.path_end_m
    rb1, rb2, L = pair.gear(0).base_radius_m, pair.gear(1).base_radius_m, mesh.line_of_action_m
    j, d = mesh.slots(theta_rad)
    in_path = mesh.in_path(d)
    lo, hi = s.form_limits_m
    entry = (d < A) & (d > lo) & s.corner_contact
    exit_ = (d > E) & (d < hi) & s.corner_contact
    cand = in_path | entry | exit_
    d_u, at = np.unique(np.clip(d[cand], A, E), return_inverse=True)
    radii = (np.sqrt(rb1**2 + d_u**2), np.sqrt(rb2**2 + (L - d_u) ** 2))
    c_g = [_compliance(s, k, radii[k], s.corrections[k]) for k in (0, 1)]
    c = np.full(d.shape, np.inf)
    c[cand] = (c_g[0] + c_g[1] + s.c_hertz_m_per_N)[at]
    gap_u = np.zeros(d_u.shape)
    if s.wear is not None and not s.wear.is_unworn:
        h1, h2 = wear_on_line_of_action(mesh, s.wear, d_u)
        gap_u = gap_u + h1 + h2
    if s.flank is not None and not s.flank.is_nominal:
        m1, m2 = modification_on_line_of_action(s.flank, mesh, d_u)
        gap_u = gap_u + m1 + m2
    gap = np.full(d.shape, np.inf)
    gap[cand] = gap_u[at]
    if np.any(entry):
        gap[entry] += corner_gap_m(mesh, d[entry], "entry")
    if np.any(exit_):
        gap[exit_] += corner_gap_m(mesh, d[exit_], "exit")
    faulty = None
    if s.faults is not None and s.periods > 1:
        # one revolution of the faulty gear: the faulty tooth's pair changed where it
        # sits (geometry.faults numbering: slot j of period n holds tooth (n - j) mod z)
        n = np.asarray(period)[:, None]
        faulty = np.zeros(d.shape, dtype=bool)
        crack = s.faults.crack
        if crack is not None:
            hit = holds_fault(pair, crack, n, j[None, :]) & cand
            g = crack.gear_index
            corr = s.crack_correction if s.crack_correction is not None else s.corrections[g]
            dh, ah = np.unique(np.clip(d[hit], A, E), return_inverse=True)
            rh = (np.sqrt(rb1**2 + dh**2), np.sqrt(rb2**2 + (L - dh) ** 2))
            healthy = [_compliance(s, k, rh[k], s.corrections[k]) for k in (0, 1)]
            healthy[g] = _compliance(s, g, rh[g], corr, crack.crack)
            c[hit] = (healthy[0] + healthy[1] + s.c_hertz_m_per_N)[ah]
            faulty |= hit
        spall = s.faults.spall
        if spall is not None:
            hit = holds_fault(pair, spall, n, j[None, :]) & cand
            gap[hit] += spall_gap_m(spall, mesh, np.clip(d[hit], A, E))
            faulty |= hit
    return c, gap, d, in_path, faulty


def _solve(s: _Contact, theta_rad: np.ndarray, period: np.ndarray, without: np.ndarray | None = None):
    """Load sharing at the angles: (F (angles x slots, N), Delta (angles, m), c, gap, d,
    in_path, faulty) (:func:`_state`, :func:`share_load`); ``without``: per angle a slot
    whose pair is left out of the load sharing (its gap is still returned)."""
    c, gap, d, in_path, faulty = _state(s, theta_rad, period)
    if without is not None:
        c = c.copy()
        c[np.arange(c.shape[0]), without] = np.inf
    F, delta = share_load(s.total_N, c, gap, *s.hertz)
    return F, delta, c, gap, d, in_path, faulty
