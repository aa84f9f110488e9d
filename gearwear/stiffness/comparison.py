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
* :func:`pair_consistency`: in single contact, the pair FE's centre-line readings
  (fem.pair_centre_line: c_1, c_2, the local approach c_local) against the single-tooth
  FE and against Weber's formula for the approach of a line contact
  (:func:`weber_approach_m`, Weber 1949, plane stress or plane strain).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from gearwear.analytic import energy, ishikawa
from gearwear.analytic.tvms import mesh_stiffness
from gearwear.core.validation import fail
from gearwear.geometry.curves import zone_means
from gearwear.geometry.spec import PairSpec

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
        return [
            {**row, "ishikawa_um_per_N_per_mm": float(i), "difference_percent": float(d)}
            for row, i, d in zip(self.fe.rows(), self.ishikawa_um_per_N_per_mm, self.difference_percent)
        ]


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
    ish = ishikawa.tooth_compliance(
        fe.loaded,
        fe.radius_m,
        fe.loaded.gear.material,
        pair.face_width_m,
        opposite=fe.nominal,
        crack=crack,
        plane=fe.plane,
    )
    t1 = time.perf_counter()
    en = energy.tooth_compliance(
        fe.loaded,
        fe.radius_m,
        fe.loaded.gear.material,
        pair.face_width_m,
        opposite=fe.nominal,
        crack=crack,
        plane=fe.plane,
    )
    t2 = time.perf_counter()
    return ToothComparison(
        fe, ish.total_m_per_N * to_um_per_N_per_mm, en.total_m_per_N * to_um_per_N_per_mm, t1 - t0, t2 - t1
    )


def pair_vs_analytic(fe: PairFE, corner_contact: bool = True, correction=None) -> dict:
    """The analytic Ishikawa curve at the angles, torque, clearance and wear of ``fe``
    (``correction``: the per-gear compliance factors of analytic.tvms.mesh_stiffness)
    and the comparison: "analytic" (the MeshStiffness), the means (N/m), their
    relative difference, the per-position k_FE / k_analytic - 1, the zone means over
    the FE curve's zones (N/m) and the mean STE (m). The analytic tooth beams are in the
    FE's 2D state (fe.meta["plane"])."""
    # at exactly the FE positions (not a table with breakpoints): compared position by position
    an = mesh_stiffness(
        fe.pair,
        method="ishikawa",
        torque_Nm=fe.torque_Nm,
        clearance_m=fe.meta.get("clearance_m", 0.0),
        wear=fe.wear,
        corner_contact=corner_contact,
        correction=correction,
        angles_rad=fe.angle_rad,
        plane=fe.meta.get("plane", "stress"),
    )
    zones = fe.zone_masks()
    z_fe, z_an = zone_means(fe.k_N_per_m, zones), zone_means(an.k_N_per_m, zones)
    return {
        "analytic": an,
        "mean_fe_N_per_m": fe.mean_N_per_m,
        "mean_analytic_N_per_m": an.mean_N_per_m,
        "mean_rel_diff": fe.mean_N_per_m / an.mean_N_per_m - 1.0,
        "per_position_rel_diff": fe.k_N_per_m / an.k_N_per_m - 1.0,
        "single_fe": z_fe["single"],
        "single_analytic": z_an["single"],
        "double_fe": z_fe["double"],
        "double_analytic": z_an["double"],
        "ste_mean_fe_m": float(np.mean(fe.ste_m)),
        "ste_mean_analytic_m": float(np.mean(an.ste_m)),
    }


# ---------------------------------------------------------------------------
# the pair FE's local approach against Weber (gearwear verify's pair consistency)
# ---------------------------------------------------------------------------


def _plane_constants(E: float, nu: float, plane: str) -> tuple[float, float]:
    """(E', nu') that turn the plane-strain formulas into the requested state."""
    if plane == "strain":
        return E, nu
    if plane == "stress":
        return E * (1 + 2 * nu) / (1 + nu) ** 2, nu / (1 + nu)
    raise fail("plane", repr(plane), "", "must be 'stress' or 'strain'")


def weber_approach_m(F_N, h1_m, h2_m, R_star_m, E_Pa, nu, b_m: float, plane: str = "strain") -> np.ndarray:
    """Weber (1949) approach of the two centre-line points of a line contact (m), the sum
    of each body's own term

        w_i = 2 F (1 - nu_i^2) / (pi E_i b) [ln(2 h_i / a) - nu_i / (2 (1 - nu_i))]

    (one material: 2 F (1 - nu^2)/(pi E b) [ln(2 h1/a) + ln(2 h2/a) - nu/(1 - nu)]) with the
    Hertz half-width a = sqrt(4 (F/b) R* / (pi E*)), 1/E* = sum (1 - nu_i^2)/E_i (plane
    strain; ``plane="stress"`` converts E, nu). ``E_Pa``, ``nu``: one value or (body 1,
    body 2). h1, h2: contact point to the centre-line points along the load line. Zero for
    F <= 0."""
    F = np.maximum(np.asarray(F_N, dtype=float), 0.0)
    Fs = np.where(F > 0, F, 1.0)
    if np.ndim(E_Pa) == 0 and np.ndim(nu) == 0:
        Ep, nup = _plane_constants(float(E_Pa), float(nu), plane)
        E_star = Ep / (2.0 * (1.0 - nup**2))
        a = np.sqrt(4.0 * (Fs / b_m) * np.asarray(R_star_m) / (math.pi * E_star))
        br = np.log(2.0 * np.asarray(h1_m) / a) + np.log(2.0 * np.asarray(h2_m) / a) - nup / (1.0 - nup)
        return np.where(F > 0, 2.0 * F * (1.0 - nup**2) / (math.pi * Ep * b_m) * br, 0.0)
    Es = np.broadcast_to(np.asarray(E_Pa, dtype=float), (2,))
    nus = np.broadcast_to(np.asarray(nu, dtype=float), (2,))
    consts = [_plane_constants(float(e), float(n), plane) for e, n in zip(Es, nus)]
    E_star = 1.0 / sum((1.0 - n**2) / e for e, n in consts)
    a = np.sqrt(4.0 * (Fs / b_m) * np.asarray(R_star_m) / (math.pi * E_star))
    out = 0.0
    for (e, n), h in zip(consts, (h1_m, h2_m)):
        out = out + 2.0 * F * (1.0 - n**2) / (math.pi * e * b_m) * (
            np.log(2.0 * np.asarray(h) / a) - n / (2.0 * (1.0 - n))
        )
    return np.where(F > 0, out, 0.0)


def pair_consistency(
    pair: PairSpec, torque_Nm: float = 40.0, positions: int = 24, contact_scale: float = 1.0, plane: str = "stress"
) -> list[dict]:
    """At every single-contact position of the cycle: c_1, c_2 read in the pair FE and
    by the single-tooth FE (fem.tooth on its own mesh, Hertz patch, read at the same
    centre-line points), c_local (fem.pair_centre_line), Weber's approach
    (:func:`weber_approach_m`) in plane stress and plane strain, and the pair stiffness
    against 1 / (c_1 + c_2 + c_local) with the single-tooth c."""
    from gearwear.fem.pair import centre_line_compliance, pair_model, solve_position
    from gearwear.fem.tooth import single_tooth_compliance

    pm = pair_model(pair, None, torque_Nm, 0.0, contact_scale, 1.0, plane)
    F = torque_Nm / pair.gear(0).base_radius_m
    theta = np.arange(positions) * (pm.mesh.mesh_angle_rad / positions)
    rows = []
    for th in theta:
        ps = solve_position(pm, float(th), F)
        if int(np.sum(ps.loads_N > 0)) != 1:
            continue
        rows.append(centre_line_compliance(pm, ps))
    if not rows:
        return rows
    mats = pair.materials
    for gi in (0, 1):
        R = np.array([r[f"R{gi + 1}_m"] for r in rows])
        fe = single_tooth_compliance(pair, gear_index=gi, radii_m=R, load_N=F, plane=plane, read_at="load_line")
        c = fe.fem_compliance_um_per_N_per_mm / (1e6 * pair.face_width_m * 1e3)
        for r, ci in zip(rows, c):
            r[f"c{gi + 1}_tooth_m_per_N"] = float(ci)
    for r in rows:
        for pl in ("stress", "strain"):
            r[f"weber_{pl}_m_per_N"] = (
                float(
                    weber_approach_m(
                        r["load_N"],
                        r["h1_m"],
                        r["h2_m"],
                        r["R_star_m"],
                        tuple(m.youngs_modulus_Pa for m in mats),
                        tuple(m.poisson_ratio for m in mats),
                        pair.face_width_m,
                        pl,
                    )
                )
                / r["load_N"]
            )
        r["k_pair_N_per_m"] = 1.0 / r["c_pair_m_per_N"]
        r["k_identity_N_per_m"] = 1.0 / (r["c1_tooth_m_per_N"] + r["c2_tooth_m_per_N"] + r["c_local_m_per_N"])
    return rows
