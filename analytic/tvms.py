"""Time-varying mesh stiffness with load sharing, wear gaps and tip-corner contact.

For each pinion angle theta over one mesh period (theta = 0 when a pair enters the
path of contact at A) every candidate tooth pair k has

* a position d_k on the line of action (geometry.kinematics.MeshGeometry.slots),
* a linear compliance c_k = (delta_1 + delta_2)_pinion + (delta_1 + delta_2)_gear per
  unit load (Ishikawa slices or the potential-energy method, true worn profiles),
* a Hertzian approach: nonlinear a F^0.9 (paper Eq. 5) for ``ishikawa``, linear
  4 (1 - nu^2) / (pi E b) F (Yang & Lin) for ``energy``,
* an initial gap g_k along the line of action: the depths removed from both flanks at
  the contact, h_1(d) + h_2(d) (both measured along the involute normal = the LOA): wear
  (geometry.wear) plus profile modifications and measured deviations
  (geometry.flank), and on the faulty tooth's pair a spall (geometry.faults).

A fault on one tooth (a root crack: the cracked tooth's compliance; a spall: its gap)
makes the curve periodic over one revolution of the faulty gear: it then spans
``periods`` = z_g mesh periods (geometry.faults.revolution_periods) and the pair in slot
j of period n holds the teeth (n - j) mod z.

The static transmission error Delta (the approach of the gears along the LOA beyond
the rigid, unworn position) follows from compatibility and equilibrium
(complementarity: a pair with g_k >= Delta carries nothing):

    c_k F_k + delta_H(F_k) = Delta - g_k  if Delta > g_k, else F_k = 0;   sum_k F_k = F = T / r_b1

Sum F_k(Delta) is convex and increasing in Delta, so Newton's method from above
converges monotonically; loads sum to F to ~1e-13 relative.

Mesh stiffness: k_h = sum over loaded pairs of F_k / (Delta - g_k), the secant pair
stiffness of paper Eq. 6 summed over the pairs that carry load, so the mesh force is
F = k_h (Delta - e) with the wear excitation e = sum k_k g_k / k_h.

The method in four modules; their public names are re-exported here, so
``gearwear.analytic.tvms`` stays the place to import them from:

* ``analytic.tvms_curve``: the curve type, :class:`MeshStiffness` (k_h in N/m, STE and e in
  m, pair loads in N at pinion angles in rad);
* ``analytic.tvms_contact``: the contact state at any pinion angle: the candidate pairs,
  their compliance c_k (m/N, :data:`METHODS`), their gaps g_k (m) with the tip-corner
  separation outside the path (:func:`corner_gap_m`), and the Hertz law;
* ``analytic.tvms_sharing``: the load sharing, Newton on Delta (:func:`share_load`);
* ``analytic.tvms_nodes``: the table nodes with the breakpoints as exact nodes
  (:func:`kinematic_breaks_rad`, :func:`graded_offsets_rad`, :func:`merge_nodes`).

:func:`mesh_stiffness` puts them together at the operating point.
"""

from __future__ import annotations

import math
import time

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.faults import FaultSpec
from gearwear.geometry.flank import FlankSpec
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec

from . import TABLE_POINTS_PER_MESH_PERIOD, ishikawa
from .tvms_contact import METHODS, _contact, _solve, corner_gap_m
from .tvms_contact import _profiles as _profiles
from .tvms_curve import MeshStiffness
from .tvms_nodes import (
    GRADED_POWER,
    GRADED_WIDTH,
    JUMP_OFFSET,
    MERGE_TOL,
    ROOT_TOL,
    _table_nodes,
    graded_offsets_rad,
    kinematic_breaks_rad,
    merge_nodes,
)
from .tvms_sharing import share_load

__all__ = [
    "METHODS",
    "DEFAULT_POINTS",
    "MeshStiffness",
    "mesh_stiffness",
    "corner_gap_m",
    "share_load",
    "kinematic_breaks_rad",
    "graded_offsets_rad",
    "merge_nodes",
    "GRADED_WIDTH",
    "GRADED_POWER",
    "JUMP_OFFSET",
    "ROOT_TOL",
    "MERGE_TOL",
]


#: uniform table nodes per mesh period (the breakpoints come on top); the convergence
#: study benchmarks/bench_table_points.py sets it
DEFAULT_POINTS = TABLE_POINTS_PER_MESH_PERIOD


def mesh_stiffness(
    pair: PairSpec,
    method: str = "ishikawa",
    points: int = DEFAULT_POINTS,
    torque_Nm: float = 40.0,
    clearance_m: float = 0.0,
    wear: WearSpec | None = None,
    bearing_stiffness_N_per_m: float = math.inf,
    n_slices: int = ishikawa.DEFAULT_SLICES,
    corner_contact: bool = True,
    correction=None,
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
    crack_correction=None,
    breakpoints: bool = True,
    angles_rad=None,
    plane: str = "stress",
) -> MeshStiffness:
    """k_h(theta), pair loads and loaded STE over one mesh period at the operating point
    (over one revolution of the faulty gear when ``faults`` has a fault: ``periods`` mesh
    periods).

    Table nodes: ``points`` uniform angles per mesh period, and with ``breakpoints`` (the
    default) the breakpoints of the physics on top (:func:`_table_nodes`): where a pair
    enters or leaves the path (A, E) and where a pair starts or stops carrying load
    (Delta = g_k: wear, flank modifications, corner contact and the bearing-clearance
    geometry move it), each resolved by nodes on its loaded side. The table is then
    non-uniform; every node holds the curve evaluated there (a breakpoint node the
    one-sided value without the pair), and the piecewise-linear curve between nodes is
    what the dynamics interpolate. ``breakpoints = False``: the uniform grid only (the
    convergence study's comparison). ``angles_rad``: evaluate at exactly these pinion
    angles instead of a table (the curve's angles are then these).

    The centre distance follows from the bearing clearance (and the static load if a
    finite bearing stiffness is given), paper Eq. 11; the contact path, contact ratio and
    wear pattern are those at that centre distance.

    ``correction``: optional ((radius_m, factor), (radius_m, factor)) per gear: the
    tooth compliance delta_1 + delta_2 at contact radius R is multiplied by the factor
    interpolated at R (the FE calibration; see gearwear.stiffness.calibration). Plain arrays, so
    this module never depends on the FE stage. ``crack_correction``: (radius_m, factor)
    of the cracked tooth (FE of the cracked tooth over the reduced-section model); absent,
    the cracked tooth takes its gear's ``correction``. ``plane``: the 2D state of the tooth
    beam terms, "stress" (the published models) or "strain" (``analytic.plane``); the app
    passes the scene's fem.plane resolved as for the FE.
    """
    t0 = time.perf_counter()
    if not isinstance(points, (int, np.integer)) or points < 8:
        raise fail("points", points, "", "must be a whole number >= 8")
    s = _contact(
        pair,
        method,
        torque_Nm,
        clearance_m,
        wear,
        bearing_stiffness_N_per_m,
        n_slices,
        corner_contact,
        correction,
        flank,
        faults,
        crack_correction,
        plane,
    )
    P = s.mesh.mesh_angle_rad
    breaks = np.empty(0)
    if angles_rad is not None:
        theta = np.asarray(angles_rad, dtype=float).ravel()
        # each angle in its mesh period (a node a rounding error below a period's start is
        # taken at a tiny negative angle of that period: the slots are not wrapped)
        whole = np.floor(theta / P + 1e-12)
        local, period = theta - whole * P, np.mod(whole, s.periods).astype(np.int64)
    elif breakpoints:
        theta, local, period, breaks = _table_nodes(s, int(points))
    else:
        local = np.tile(np.arange(points) * (P / points), s.periods)
        period = np.repeat(np.arange(s.periods), points)
        theta = np.arange(points * s.periods) * (P / points)
    F, delta, c, gap, d, in_path, faulty = _solve(s, local, period)
    loaded_mask = F > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        k_pair = np.where(loaded_mask, F / np.maximum(delta[:, None] - gap, 1e-300), 0.0)
    k = k_pair.sum(axis=1)
    excitation = np.where(k > 0, (k_pair * np.where(loaded_mask, gap, 0.0)).sum(axis=1) / k, 0.0)
    wall = time.perf_counter() - t0
    return MeshStiffness(
        method,
        pair,
        s.mesh,
        torque_Nm,
        wear,
        theta,
        k,
        delta,
        excitation,
        F,
        d,
        in_path,
        wall,
        n_slices,
        {
            "clearance_m": clearance_m,
            "corner_contact": corner_contact,
            "corrected": correction is not None,
            "points_per_mesh_period": int(points),
            "breakpoints": bool(breakpoints),
            "plane": plane,
        },
        flank,
        faults,
        s.periods,
        faulty,
        breaks,
    )
