"""Convergence of the stiffness table: F_m and k_h harmonics versus table length.

The analytic k_h(phi), e(phi) tables (analytic.tvms.mesh_stiffness) have N uniform nodes
per mesh period and, by default, the breakpoints of the load sharing on top (where a
pair enters or leaves the path or starts or stops carrying load, with graded nodes on
its loaded side). For N = 90 .. 5760, with and without the breakpoints, on three
scenes (the paper pair at the issue's 30.5 um bearing clearance; the paper pair with
severe wear at 10 um clearance; an unequal, profile-shifted 23/47 pair with mild wear and
20 um clearance): the full dynamics (gearwear.jobs.simulate.run, the scene's solver), the
F_m harmonics 1-10, and the k_h harmonics 1-10 of the table (exact Fourier coefficients
of the piecewise-linear table, geometry.curves.harmonic_amplitudes). Errors are against
the table with breakpoints at 2 x 5760 nodes per period: the largest over harmonics 1-10
of |H_m - H_m,ref| / H_m,ref (each harmonic relative to itself). Wall time: table and
dynamics of one run.

The default (analytic.TABLE_POINTS_PER_MESH_PERIOD) is the smallest N whose F_m error
with breakpoints is below TOLERANCE in every scene. Writes
reports/breakpoints/table_points.json and .png; prints the table."""

import json
import time
from pathlib import Path

import numpy as np

from gearwear.analytic import TABLE_POINTS_PER_MESH_PERIOD
from gearwear.geometry.curves import harmonic_amplitudes
from gearwear.jobs.simulate import run, stiffness_input
from gearwear.scene.files import builtin_scene_dict
from gearwear.scene.model import scene_from_dict
from gearwear.scene.overrides import apply_overrides

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "reports" / "breakpoints"
LENGTHS = (90, 180, 360, 720, 1440, 2880, 5760)
REFERENCE = 11520
TOLERANCE = 1e-3  # largest relative error of an F_m harmonic 1-10
HARMONICS = 10


def unequal_doc() -> dict:
    """23/47, x = +0.2/-0.1, m 3 mm, b 30 mm at 1500 rpm and 120 N m, masses and inertias
    from the blanks, mild wear and 20 um bearing clearance (static coupling)."""
    doc = builtin_scene_dict("paper-clearance")
    doc["name"] = "unequal-23-47"
    doc["pair"] = {
        "teeth": [23, 47],
        "module_mm": 3.0,
        "profile_shift": [0.2, -0.1],
        "face_width_mm": 30.0,
        "hub_radius_mm": [12.5, 25.0],
    }
    doc["operating"] = {"speed_rpm": 1500.0, "torque_Nm": 120.0}
    doc["bodies"] = {"bearing_stiffness_N_per_m": 2.6e8}
    doc["effects"]["wear"] = {"phase": "mild"}
    doc["effects"]["bearing_clearance"] = {"clearance_um": 20.0}
    return doc


SCENES = {
    "paper pair, 30.5 um clearance": (
        builtin_scene_dict("paper-clearance"),
        ["effects.bearing_clearance.clearance_um=30.5"],
    ),
    "paper pair, severe wear, 10 um clearance": (builtin_scene_dict("paper-wear-severe"), []),
    "23/47 shifted, mild wear, 20 um clearance": (unequal_doc(), []),
}


def one_run(doc: dict, sets: list[str], points: int, breakpoints: bool) -> dict:
    sc = scene_from_dict(
        apply_overrides(doc, sets + [f"effects.mesh_stiffness.points_per_mesh_period={points}"]), name=doc["name"]
    )
    t0 = time.perf_counter()
    stiff = stiffness_input(sc, breakpoints=breakpoints)
    t1 = time.perf_counter()
    r = run(sc, stiffness=stiff)
    t2 = time.perf_counter()
    span = stiff.periods * 2 * np.pi / sc.pair.teeth[0]
    return {
        "points": points,
        "breakpoints": breakpoints,
        "nodes": int(len(stiff.phi)),
        "F_m_N": r.result.harmonics("F_m", HARMONICS).tolist(),
        "k_h_N_per_m": harmonic_amplitudes(stiff.phi, stiff.k, span, HARMONICS, stiff.periods).tolist(),
        "table_s": t1 - t0,
        "dynamics_s": t2 - t1,
    }


def rel_error(h, ref) -> float:
    h, ref = np.asarray(h), np.asarray(ref)
    return float(np.max(np.abs(h - ref) / ref))


def study() -> dict:
    out = {"tolerance": TOLERANCE, "reference_points": REFERENCE, "lengths": list(LENGTHS), "scenes": {}}
    one_run(*SCENES[next(iter(SCENES))], 90, True)  # compile the kernels outside the timings
    for name, (doc, sets) in SCENES.items():
        ref = one_run(doc, sets, REFERENCE, True)
        rows = []
        for bp in (False, True):
            for n in LENGTHS:
                r = one_run(doc, sets, n, bp)
                r["F_m_error"] = rel_error(r["F_m_N"], ref["F_m_N"])
                r["k_h_error"] = rel_error(r["k_h_N_per_m"], ref["k_h_N_per_m"])
                rows.append(r)
        out["scenes"][name] = {"reference": ref, "rows": rows}
    with_bp = [[r["F_m_error"] for r in s["rows"] if r["breakpoints"]] for s in out["scenes"].values()]
    worst = np.max(with_bp, axis=0)
    ok = [n for n, e in zip(LENGTHS, worst) if e <= TOLERANCE]
    out["chosen"] = ok[0] if ok else None
    out["default"] = TABLE_POINTS_PER_MESH_PERIOD
    return out


def print_table(res: dict) -> None:
    for name, s in res["scenes"].items():
        ref = s["reference"]
        print(
            f"\n{name}: reference {ref['points']} points + breakpoints ({ref['nodes']} nodes), "
            f"F_m harmonics 1-10 (N) {', '.join(f'{x:.4g}' for x in ref['F_m_N'])}"
        )
        print(
            f"{'points':>7}{'nodes':>7}{'F_m err':>10}{'k_h err':>10}{'nodes':>7}{'F_m err':>10}{'k_h err':>10}"
            f"{'wall s':>8}{'wall s':>8}"
        )
        print(f"{'':>7}{'uniform only':^27}{'with breakpoints':^27}{'unif.':>8}{'bp':>8}")
        rows = {(r["points"], r["breakpoints"]): r for r in s["rows"]}
        for n in res["lengths"]:
            u, b = rows[n, False], rows[n, True]
            print(
                f"{n:>7}{u['nodes']:>7}{u['F_m_error']:>10.2e}{u['k_h_error']:>10.2e}{b['nodes']:>7}"
                f"{b['F_m_error']:>10.2e}{b['k_h_error']:>10.2e}{u['table_s'] + u['dynamics_s']:>8.2f}"
                f"{b['table_s'] + b['dynamics_s']:>8.2f}"
            )
    print(
        f"\nsmallest length with every F_m harmonic 1-10 within {100 * res['tolerance']:g} % of the reference "
        f"(with breakpoints, all scenes): {res['chosen']}; the default is {res['default']}"
    )


def figure(res: dict):
    from gearwear.plotting import subplots

    fig, axs = subplots(1, 2, figsize=(12, 4.6), sharey=True)
    for ax, what, label in (
        (axs[0], "F_m_error", "F_m harmonics 1-10 (full dynamics)"),
        (axs[1], "k_h_error", "k_h harmonics 1-10 (table)"),
    ):
        for i, (name, s) in enumerate(res["scenes"].items()):
            for bp, ls, mk in ((False, "--", "s"), (True, "-", "o")):
                rows = [r for r in s["rows"] if r["breakpoints"] == bp]
                ax.loglog(
                    [r["points"] for r in rows],
                    [max(r[what], 1e-12) for r in rows],
                    ls,
                    marker=mk,
                    color=f"C{i}",
                    label=f"{name}, {'with breakpoints' if bp else 'uniform only'}",
                )
        ax.axhline(res["tolerance"], color="grey", ls=":", label=f"tolerance {100 * res['tolerance']:g} %")
        ax.set_xlabel("uniform table nodes per mesh period")
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3, which="both")
    axs[0].set_ylabel(f"largest relative error of a harmonic\n(vs {res['reference_points']} nodes + breakpoints)")
    handles, labels = axs[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.2, 1, 1))
    return fig


if __name__ == "__main__":
    res = study()
    print_table(res)
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "table_points.json").write_text(json.dumps(res, indent=1) + "\n")
    figure(res).savefig(OUT / "table_points.png", dpi=120)
    print(f"wrote {OUT / 'table_points.json'} and {OUT / 'table_points.png'}")
