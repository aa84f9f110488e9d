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


def zone_means_by_count(k_N_per_m, pairs: np.ndarray) -> dict[int, float | None]:
    """Mean stiffness (N/m) over the angles with n pairs on the path, for every n from 1
    to max(3, the largest n present) (and n = 0 when there are gaps); None for a count
    that never occurs, never NaN. ``pairs``: the number of pairs at the angles of k
    (``MeshGeometry.pairs_on_path``)."""
    k = np.asarray(k_N_per_m, dtype=float)
    pairs = np.asarray(pairs)
    top = max(3, int(pairs.max()) if pairs.size else 0)
    out: dict[int, float | None] = {}
    for n in range(0 if np.any(pairs == 0) else 1, top + 1):
        sel = pairs == n
        out[n] = float(k[sel].mean()) if sel.any() else None
    return out


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

    @property
    def phase_rad(self) -> np.ndarray:
        """The angles wrapped into one mesh period (a curve over a revolution of a
        faulty gear spans several)."""
        P = self.mesh.mesh_angle_rad
        a = np.asarray(self.angle_rad, dtype=float)
        return a - P * np.floor(a / P)

    def zone_masks(self) -> dict[str, np.ndarray]:
        """Masks of the theoretical zones A, B, C at ``angle_rad``
        (MeshGeometry.contact_zones)."""
        return self.mesh.contact_zones(self.phase_rad)

    def zone_means(self) -> dict:
        """Zone statistics over one mesh period, by the number n of pairs on the path
        (``MeshGeometry.pairs_on_path``):

        * "by_count": n -> mean stiffness (N/m), None where n never occurs;
        * "deg_by_count": n -> the zone's length (pinion rotation, deg): with
          n0 = floor(epsilon), (epsilon - n0) of the period for n0 + 1 pairs and the
          rest for n0 pairs;
        * "double", "single": the means over n = 2 and n = 1 (NaN when absent; for
          1 <= epsilon < 2 these are the zones A | C and B), and "double_deg",
          "single_deg" their lengths ((epsilon - 1) and (2 - epsilon) of the period
          then)."""
        period_deg = math.degrees(self.mesh.mesh_angle_rad)
        by = zone_means_by_count(self.k_N_per_m, self.mesh.pairs_on_path(self.phase_rad))
        shares = self.mesh.zone_shares()
        deg = {n: shares.get(n, 0.0) * period_deg for n in by}
        nan = float("nan")
        return {"double": nan if by.get(2) is None else by[2], "single": nan if by.get(1) is None else by[1],
                "double_deg": deg.get(2, 0.0), "single_deg": deg.get(1, 0.0),
                "by_count": by, "deg_by_count": deg}
