"""The result of the resolved pair FE (fem.pair): PairFE, the loaded static transmission
error and mesh stiffness over one mesh period (or one revolution of a faulty gear), with
the blanks' torsion also taken out (SI units: m, N, rad)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from gearwear.geometry.curves import CurveStats
from gearwear.geometry.faults import FaultSpec
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec

__all__ = ["PairFE"]


@dataclass
class PairFE(CurveStats):
    """FE mesh stiffness over one mesh period (SI units).

    angle_rad          (n,) pinion angle, 0 when a pair enters at A (as analytic.tvms)
    k_N_per_m          (n,) secant mesh stiffness sum_k F_k / (STE - g_k)
    k_tangent_N_per_m  (n,) dF / dSTE
    ste_m              (n,) loaded static transmission error (approach along the LOA)
    excitation_m       (n,) e with F = k (STE - e)
    pair_load_N        (n, p) load of each slot (torque-equivalent: sums to T / r_b1)
    pair_d_m           (n, p) LOA position of each slot
    pair_in_path       (n, p) slot inside the path of contact [A, E]
    half_width_m       (n, p) half the loaded arc length of each pair (resolved Hertz a)
    timings            wall times (s) of the stages
    meta               sizes, element counts, options, extended-contact widths, positions solved
    faults             the one-tooth faults (None: healthy); the curve then spans
                       ``periods`` mesh periods, one revolution of the faulty gear
    faulty_pair        (n, p) True where a candidate slot holds a faulty tooth (None: no fault)
    mesh_k_N_per_m, mesh_k_tangent_N_per_m, mesh_ste_m, mesh_excitation_m
                       (n,) the same with the blanks' torsion below r_ref taken out:
                       STE_mesh = STE - r_b1 theta_ref,1 - r_b2 theta_ref,2
    blank_rotation_rad (n, 2) rotation of each blank's reference circle (counter-clockwise)
    blank_torque_Nm    (n, 2) moment of the contact loads about each gear's centre
    meta also holds blank_reference_radius_m [2], blank_torsional_stiffness_Nm_per_rad [2]
    (sum T / sum theta over the positions; inf where r_ref is the bore) and
    mesh_only_mean_N_per_m.
    """

    pair: PairSpec
    mesh: MeshGeometry
    torque_Nm: float
    wear: WearSpec | None
    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    k_tangent_N_per_m: np.ndarray
    ste_m: np.ndarray
    excitation_m: np.ndarray
    pair_load_N: np.ndarray
    pair_d_m: np.ndarray
    pair_in_path: np.ndarray
    half_width_m: np.ndarray
    timings: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)
    faults: FaultSpec | None = None
    periods: int = 1
    faulty_pair: np.ndarray | None = None
    mesh_k_N_per_m: np.ndarray | None = None
    mesh_k_tangent_N_per_m: np.ndarray | None = None
    mesh_ste_m: np.ndarray | None = None
    mesh_excitation_m: np.ndarray | None = None
    blank_rotation_rad: np.ndarray | None = None
    blank_torque_Nm: np.ndarray | None = None

    def without_blank_torsion(self) -> "PairFE":
        """The same result with the blanks' torsion below r_ref taken out: k, k_tangent,
        STE and e are the mesh-only ones (fem.pair, "The blank's torsion")."""
        k, kt, ste, e = self.mesh_k_N_per_m, self.mesh_k_tangent_N_per_m, self.mesh_ste_m, self.mesh_excitation_m
        if k is None or kt is None or ste is None or e is None:
            raise ValueError("this result carries no mesh-only curve")
        return replace(self, k_N_per_m=k, k_tangent_N_per_m=kt, ste_m=ste, excitation_m=e)
