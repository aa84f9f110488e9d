"""FE against the analytic models: the app layer wires fem and analytic, which never
import each other.

* :func:`tooth_vs_analytic`: the single-tooth FE compliance (fem.tooth, centre-line
  deflection of the full gear, um per N/mm) next to Ishikawa's delta_1 + delta_2
  (analytic.ishikawa, paper Eqs. 2-4) and the potential-energy bending + shear +
  axial + foundation compliance (analytic.energy) at the same load radii on the same
  (worn) profiles the FE model was built from.
* :func:`pair_vs_analytic`: the resolved FE pair contact (fem.pair) against the
  analytic Ishikawa mesh stiffness (analytic.tvms) at the same angles, torque,
  clearance and wear: means, zone means (geometry.curves) and the per-position
  relative difference k_FE / k_analytic - 1.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from gearwear.analytic import energy, ishikawa
from gearwear.analytic.tvms import mesh_stiffness
from gearwear.geometry.curves import zone_means

if TYPE_CHECKING:  # the FE stack (Gmsh, scikit-fem) loads only where an FE result exists
    from gearwear.fem.pair import PairFE
    from gearwear.fem.tooth import ToothFE


@dataclass(frozen=True)
class ToothComparison:
    """FE and analytic single-tooth compliance at the FE load radii (um per N/mm:
    deflection per load per unit face width, [m/N] x 1e6 x b[mm])."""

    fe: ToothFE
    ishikawa_um_per_N_per_mm: np.ndarray
    energy_um_per_N_per_mm: np.ndarray
    ishikawa_wall_s: float
    energy_wall_s: float

    @property
    def difference_percent(self) -> np.ndarray:
        """100 (FE - Ishikawa) / Ishikawa."""
        return 100.0 * (self.fe.fem_compliance_um_per_N_per_mm / self.ishikawa_um_per_N_per_mm - 1.0)

    def rows(self) -> list[dict]:
        """The FE rows (fem.tooth.ToothFE.rows) with the Ishikawa column and the difference."""
        return [{**row, "ishikawa_um_per_N_per_mm": float(i), "difference_percent": float(d)}
                for row, i, d in zip(self.fe.rows(), self.ishikawa_um_per_N_per_mm, self.difference_percent)]


def tooth_vs_analytic(fe: ToothFE) -> ToothComparison:
    """Ishikawa's delta_1 + delta_2 and the energy-method compliance of the tooth of
    ``fe`` at its load radii, on the profiles its FE model was built from (the worn
    loaded flank and the nominal opposite flank), with its root crack if it has one, and
    in its 2D state (fem.plane)."""
    if fe.loaded is None or fe.nominal is None:
        raise ValueError("the FE result carries no profiles (made by an older fem.tooth?)")
    pair = fe.pair
    to_um_per_N_per_mm = 1e6 * pair.face_width_m * 1e3
    t0 = time.perf_counter()
    crack = getattr(fe, "crack", None)  # the same root crack in the analytic models (reduced section)
    # like with like: the analytic beams in the FE's 2D state (analytic.plane)
    ish = ishikawa.tooth_compliance(fe.loaded, fe.radius_m, fe.loaded.gear.material, pair.face_width_m,
                                    opposite=fe.nominal,
                                    crack=crack, plane=fe.plane)
    t1 = time.perf_counter()
    en = energy.tooth_compliance(fe.loaded, fe.radius_m, fe.loaded.gear.material, pair.face_width_m,
                                 opposite=fe.nominal,
                                 crack=crack, plane=fe.plane)
    t2 = time.perf_counter()
    return ToothComparison(fe, ish.total_m_per_N * to_um_per_N_per_mm, en.total_m_per_N * to_um_per_N_per_mm,
                           t1 - t0, t2 - t1)


def pair_vs_analytic(fe: PairFE, corner_contact: bool = True, correction=None) -> dict:
    """The analytic Ishikawa curve at the angles, torque, clearance and wear of ``fe``
    (``correction``: the per-gear compliance factors of analytic.tvms.mesh_stiffness)
    and the comparison: "analytic" (the MeshStiffness), the means (N/m), their
    relative difference, the per-position k_FE / k_analytic - 1, the zone means over
    the FE curve's zones (N/m) and the mean STE (m). The analytic tooth beams are in the
    FE's 2D state (fe.meta["plane"])."""
    # at exactly the FE positions (not a table with breakpoints): compared position by position
    an = mesh_stiffness(fe.pair, method="ishikawa", torque_Nm=fe.torque_Nm,
                        clearance_m=fe.meta.get("clearance_m", 0.0), wear=fe.wear, corner_contact=corner_contact,
                        correction=correction, angles_rad=fe.angle_rad, plane=fe.meta.get("plane", "stress"))
    zones = fe.zone_masks()
    z_fe, z_an = zone_means(fe.k_N_per_m, zones), zone_means(an.k_N_per_m, zones)
    return {
        "analytic": an,
        "mean_fe_N_per_m": fe.mean_N_per_m,
        "mean_analytic_N_per_m": an.mean_N_per_m,
        "mean_rel_diff": fe.mean_N_per_m / an.mean_N_per_m - 1.0,
        "per_position_rel_diff": fe.k_N_per_m / an.k_N_per_m - 1.0,
        "single_fe": z_fe["single"], "single_analytic": z_an["single"],
        "double_fe": z_fe["double"], "double_analytic": z_an["double"],
        "ste_mean_fe_m": float(np.mean(fe.ste_m)), "ste_mean_analytic_m": float(np.mean(an.ste_m)),
    }
