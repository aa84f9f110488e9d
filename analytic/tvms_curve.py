"""The mesh stiffness curve of ``analytic.tvms`` (:class:`MeshStiffness`): k_h, the loaded
static transmission error, the excitation and the pair loads at the table's pinion angles.

Over one mesh period, or over one revolution of the faulty gear with a fault (``periods``
mesh periods). At each pinion angle theta (rad), from the pair loads F_k (N) and the gaps
g_k (m) of the load sharing (``analytic.tvms_sharing``):

    k_h = sum over loaded pairs of F_k / (Delta - g_k)    [N/m]   (paper Eq. 6, summed)
    F = k_h (Delta - e),   e = sum k_k g_k / k_h          [m]

Delta the loaded static transmission error along the line of action (m), k_k the secant
stiffness of pair k. The angles need not be uniform (the breakpoints are nodes,
``analytic.tvms_nodes``): statistics over the curve are integrals of its piecewise-linear
interpolant (``geometry.curves.CurveStats``). SI units throughout.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gearwear.geometry.curves import CurveStats
from gearwear.geometry.faults import FaultSpec
from gearwear.geometry.flank import FlankSpec
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec

from . import ishikawa


@dataclass(frozen=True)
class MeshStiffness(CurveStats):
    """A mesh stiffness curve over one mesh period (SI units).

    angle_rad       (n,) pinion angle from the entry of a pair at A
    k_N_per_m       (n,) mesh stiffness (sum of loaded pairs' secant stiffness)
    ste_m           (n,) loaded static transmission error along the LOA
    excitation_m    (n,) e with F = k_h (ste - e) (zero when unworn)
    pair_load_N     (n, p) load of each candidate pair (zero when not in contact)
    pair_d_m        (n, p) position of each candidate pair on the LOA
    pair_in_path    (n, p) True inside the theoretical path of contact [A, E]
    faulty_pair     (n, p) True where the slot holds the faulty tooth (None: no fault)
    periods         mesh periods the curve spans (1; z of the faulty gear with a fault)
    breakpoints_rad angles (also nodes of angle_rad) where a pair starts or stops carrying
                    load or enters or leaves the path of contact (empty: a uniform table)

    The angles need not be uniform (the breakpoints are nodes): statistics over the
    curve are integrals of its piecewise-linear interpolant (geometry.curves).
    """

    method: str
    pair: PairSpec
    mesh: MeshGeometry
    torque_Nm: float
    wear: WearSpec | None
    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    ste_m: np.ndarray
    excitation_m: np.ndarray
    pair_load_N: np.ndarray
    pair_d_m: np.ndarray
    pair_in_path: np.ndarray
    wall_s: float = 0.0
    n_slices: int = ishikawa.DEFAULT_SLICES
    meta: dict = field(default_factory=dict)
    flank: FlankSpec | None = None
    faults: FaultSpec | None = None
    periods: int = 1
    faulty_pair: np.ndarray | None = None
    breakpoints_rad: np.ndarray = field(default_factory=lambda: np.empty(0))
