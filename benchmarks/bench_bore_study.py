"""The bore study: what the bore does to the pair FE's mesh stiffness, and why.

The 23/47 pair (m 3 mm, b 30 mm, x = +0.2/-0.1, 120 N m), three bore pairs. For each:
the pair FE (fem.pair, default settings as ``gearwear stiffness --method fem``, 24
positions, bodies built cold) with the bodies held at their bores ("bore-fixed", what
it reports as k) and with both blanks' torsion below their reference circles r_ref
taken out ("mesh only"); each blank's torsional stiffness T / theta_ref measured in the
FE and by the closed form of a solid annulus in torsion (in-plane shear, the same in
plane stress and plane strain; the n = 0 Fourier part of u_theta of the bore-fixed
body, exact for any load outside r_ref):

    k_blank = 4 pi G b / (1 / r_bore^2 - 1 / r_ref^2)      (N m/rad)

the residual of the identity STE / F = STE_mesh / F + r_b1^2 / k_1 + r_b2^2 / k_2 with
the closed-form k (max over the positions), the least-squares translation of the
reference circles along the line of action (the n = 1 part: what of the remaining bore
dependence is the blanks' bending under the net tooth force), and Ishikawa, the energy
method (Sainsot's foundation, which depends on the bore through h_fi = r_f / r_bore)
and ISO 6336 (method B c_gamma_alpha b) beside them. Wall times are printed, never
asserted.

    .venv/bin/python benchmarks/bench_bore_study.py

The FE and the analytic tooth beams run in the 2D state the command line takes for this
pair (fem.plane = "auto": plane strain at b/m = 10). Writes benchmarks/results/bench_bore_study.json, from which
docs/generate.py fills the bore-study table of docs/models.md.
"""

import json
import math
import time
from pathlib import Path

import numpy as np

from gearwear.analytic.iso6336 import iso6336_stiffness
from gearwear.analytic.tvms import mesh_stiffness
from gearwear.fem import pair as fp
from gearwear.fem.pair_cycle import _secant
from gearwear.fem.pair_model import _BODY_CACHE
from gearwear.fem.pair_position import _reps_memo
from gearwear.geometry.pair_positions import rot, tooth_frames
from gearwear.scene.checks import resolved_plane
from gearwear.scene.model import scene_from_dict

BORES_MM = ([12.5, 25.0], [18.0, 40.0], [24.0, 55.0])
#: the 2D state `gearwear stiffness --method fem` takes for this pair (fem.plane = "auto", b/m = 10)
PLANE = resolved_plane("auto", 30.0, 3.0)
RESULT = Path(__file__).resolve().parent / "results" / "bench_bore_study.json"
TORQUE_NM = 120.0
POSITIONS = 24


def the_pair(bores_mm):
    return scene_from_dict(
        {
            "pair": {
                "teeth": [23, 47],
                "module_mm": 3.0,
                "profile_shift": [0.2, -0.1],
                "face_width_mm": 30.0,
                "hub_radius_mm": list(bores_mm),
            },
            "operating": {"speed_rpm": 1500, "torque_Nm": TORQUE_NM},
        }
    ).pair


def annulus_k(g, r_ref: float) -> float:
    """Closed-form torsional stiffness (N m/rad) of the solid annulus bore..r_ref."""
    if r_ref <= g.hub_radius_m:
        return math.inf
    return 4 * math.pi * g.material.shear_modulus_Pa * g.face_width_m / (1 / g.hub_radius_m**2 - 1 / r_ref**2)


def ring_translation_m(pm, ps) -> float:
    """Approach along the line of action (m) from the reference circles' least-squares
    translation (GearBody.blank_h rows 1, 2; body frame turned into the fixed frame by
    each candidate's tooth frame): the pinion pushed along -x, the gear along +x."""
    v = [0.0, 0.0]
    for gi, body in enumerate(pm.bodies):
        rep = _reps_memo(body, ps.cand, gi, None)
        for k, c in enumerate(ps.cand):
            idx, coef = rep(k, 0)
            local = [float(np.sum(body.blank_h[r][idx] * coef * c["force_N"][:, None])) for r in (1, 2)]
            v[gi] += float((rot(tooth_frames(pm.mesh, c["d"])[gi]) @ np.array(local))[0])
    return v[1] - v[0]


def main() -> None:
    print(
        f"23/47, m 3 mm, b 30 mm, x +0.2/-0.1, {TORQUE_NM:g} N m, {POSITIONS} positions, plane {PLANE}; "
        "means in 1e8 N/m, k_blank in 1e6 N m/rad"
    )
    rows = []
    hdr = (
        "bores mm",
        "r_ref mm",
        "FE bore-fixed",
        "FE mesh only",
        "mesh - transl.",
        "k_blank FE",
        "k_blank closed",
        "identity",
        "Ishikawa",
        "energy",
        "ISO 6336",
        "FE s",
        "analytic s",
    )
    print(" | ".join(hdr))
    for bores in BORES_MM:
        pair = the_pair(bores)
        _BODY_CACHE.clear()  # cold: both bodies built
        t0 = time.perf_counter()
        fe = fp.pair_contact(pair, positions=POSITIONS, torque_Nm=TORQUE_NM, plane=PLANE)
        t_fe = time.perf_counter() - t0
        F = TORQUE_NM / pair.gear(0).base_radius_m
        rb = [g.base_radius_m for g in pair.gears]
        r_ref = fe.meta["blank_reference_radius_m"]
        kc = [annulus_k(g, r) for g, r in zip(pair.gears, r_ref)]
        ident = np.abs(fe.ste_m / (fe.mesh_ste_m + F * sum(r * r / k for r, k in zip(rb, kc))) - 1).max()
        # the n = 1 part: the circles' translation, from the same model (cached bodies)
        pm = fp.pair_model(pair, torque_Nm=TORQUE_NM, plane=PLANE)
        tr = np.array([ring_translation_m(pm, fp.solve_position(pm, float(th), F)) for th in fe.angle_rad])
        k_mt = _secant(fe.pair_load_N, fe.meta["pair_gap_m"], fe.mesh_ste_m - tr)[0]
        t0 = time.perf_counter()
        ish, en = (
            mesh_stiffness(pair, m, torque_Nm=TORQUE_NM, plane=PLANE).mean_N_per_m for m in ("ishikawa", "energy")
        )
        iso = iso6336_stiffness(pair, torque_Nm=TORQUE_NM).mesh_stiffness_N_per_m
        t_an = time.perf_counter() - t0
        kf = fe.meta["blank_torsional_stiffness_Nm_per_rad"]
        print(
            f"{bores[0]:g}/{bores[1]:g} | {r_ref[0] * 1e3:.2f}/{r_ref[1] * 1e3:.2f} | "
            f"{fe.mean_N_per_m / 1e8:.4f} | {fe.meta['mesh_only_mean_N_per_m'] / 1e8:.4f} | "
            f"{np.mean(k_mt) / 1e8:.4f} | {kf[0] / 1e6:.3f}/{kf[1] / 1e6:.3f} | "
            f"{kc[0] / 1e6:.3f}/{kc[1] / 1e6:.3f} | "
            f"{ident:.1e} | {ish / 1e8:.4f} | {en / 1e8:.4f} | {iso / 1e8:.4f} | {t_fe:.1f} | {t_an:.2f}",
            flush=True,
        )
        c_fix, c_mesh = 1 / fe.mean_N_per_m, 1 / fe.meta["mesh_only_mean_N_per_m"]
        print(
            f"    compliances 1e-10 m/N: bore-fixed {c_fix * 1e10:.3f}, mesh only {c_mesh * 1e10:.3f}, blanks "
            f"(closed form) {sum(r * r / k for r, k in zip(rb, kc)) * 1e10:.3f}, circles' translation "
            f"{np.mean(tr) / F * 1e10:.3f}; rim below the root r_f - r_bore = "
            f"{(pair.gear(0).root_radius_m - bores[0] * 1e-3) * 1e3:.2f}/"
            f"{(pair.gear(1).root_radius_m - bores[1] * 1e-3) * 1e3:.2f} mm",
            flush=True,
        )
        rows.append(
            {
                "bores_mm": list(bores),
                "r_ref_mm": [r * 1e3 for r in r_ref],
                "root_radius_mm": [g.root_radius_m * 1e3 for g in pair.gears],
                "bore_fixed_mean_N_per_m": fe.mean_N_per_m,
                "mesh_only_mean_N_per_m": fe.meta["mesh_only_mean_N_per_m"],
                "mesh_only_without_translation_mean_N_per_m": float(np.mean(k_mt)),
                "k_blank_fe_Nm_per_rad": list(kf),
                "k_blank_closed_form_Nm_per_rad": kc,
                "identity_residual_max": float(ident),
                "blank_compliance_closed_form_m_per_N": sum(r * r / k for r, k in zip(rb, kc)),
                "translation_compliance_m_per_N": float(np.mean(tr) / F),
                "ishikawa_mean_N_per_m": ish,
                "energy_mean_N_per_m": en,
                "iso6336_N_per_m": iso,
                "fe_wall_s": t_fe,
                "analytic_wall_s": t_an,
            }
        )
    RESULT.write_text(
        json.dumps(
            {
                "pair": "23/47, m 3 mm, b 30 mm, x +0.2/-0.1",
                "torque_Nm": TORQUE_NM,
                "positions": POSITIONS,
                "plane": PLANE,
                "rows": rows,
            },
            indent=1,
        )
        + "\n"
    )
    print(f"wrote {RESULT}")


if __name__ == "__main__":
    main()
