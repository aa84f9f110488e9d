"""Bookkeeping shared by every mesh-stiffness curve over one mesh period: the analytic
curves (analytic.tvms), the FE curves (fem.pair) and the constant ISO curve of the
app layer. Pure array work on top of the kinematics (geometry.kinematics); no model.

The theoretical zones of a period are those of ``MeshGeometry.contact_zones``: "A"
and "C" the halves of the double-contact interval, "B" single contact. Angles are
rad of pinion rotation, stiffness N/m, loads N.
"""

from __future__ import annotations

import math

import numpy as np

from .kinematics import MeshGeometry
from .spec import PairSpec


def zone_means(k_N_per_m, zones: dict[str, np.ndarray]) -> dict[str, float]:
    """Mean stiffness (N/m) over the double-contact zones A | C and over the
    single-contact zone B of ``zones`` (masks over the same angles as k); nan for an
    empty zone."""
    k = np.asarray(k_N_per_m, dtype=float)
    double, single = zones["A"] | zones["C"], zones["B"]
    return {"double": float(k[double].mean()) if double.any() else float("nan"),
            "single": float(k[single].mean()) if single.any() else float("nan")}


class CurveStats:
    """Statistics of a mesh-stiffness curve over one mesh period. Needs ``pair``,
    ``mesh`` (geometry.kinematics.MeshGeometry), ``torque_Nm``, ``angle_rad``,
    ``k_N_per_m`` and ``pair_load_N`` (angles x slots)."""

    # provided by the curve classes that mix this in (dataclass fields there)
    pair: PairSpec
    mesh: MeshGeometry
    torque_Nm: float
    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    pair_load_N: np.ndarray

    @property
    def mean_N_per_m(self) -> float:
        return float(np.mean(self.k_N_per_m))

    @property
    def min_N_per_m(self) -> float:
        return float(np.min(self.k_N_per_m))

    @property
    def max_N_per_m(self) -> float:
        return float(np.max(self.k_N_per_m))

    @property
    def pairs_in_contact(self) -> np.ndarray:
        """Number of pairs carrying load at each angle."""
        return (self.pair_load_N > 0).sum(axis=1)

    @property
    def contact_ratio(self) -> float:
        return self.mesh.contact_ratio

    @property
    def total_load_N(self) -> float:
        """Normal load on the line of action, T / r_b1 (N)."""
        return self.torque_Nm / self.pair.gear(0).base_radius_m

    def zone_masks(self) -> dict[str, np.ndarray]:
        """Masks of the theoretical zones A, B, C at ``angle_rad``
        (MeshGeometry.contact_zones)."""
        return self.mesh.contact_zones(self.angle_rad)

    def zone_means(self) -> dict[str, float]:
        """Mean stiffness over the double- ("double") and single-contact ("single")
        zones (N/m) and the zones' lengths per mesh period ("double_deg",
        "single_deg", pinion rotation in deg: (epsilon - 1) and (2 - epsilon) of the
        period)."""
        period_deg = math.degrees(self.mesh.mesh_angle_rad)
        share = self.mesh.double_contact_share
        return {**zone_means(self.k_N_per_m, self.zone_masks()),
                "double_deg": share * period_deg, "single_deg": (1.0 - share) * period_deg}
