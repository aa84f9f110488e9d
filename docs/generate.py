"""Fill the generated tables of docs/*.md from the committed results.

Published numbers come from the files a run wrote (benchmarks/results/*.json, reports/**),
not from prose typed after the run: each table sits between the markers

    <!-- generated: NAME -->
    ...
    <!-- end: NAME -->

and is rewritten from its source by ``python docs/generate.py`` (``--check``: exit 1 and name
the table if a document differs from what its source gives; tests/test_docs_generated.py
runs the check). Rerun the benchmark or the report, then this script.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _json(rel: str):
    return json.loads((ROOT / rel).read_text())


def stiffness_peer() -> str:
    """Mesh stiffness of the paper pair at 360 angles: ours against ROSS's GearElementTVMS in the
    same run (benchmarks/results/bench_stiffness.json, `make bench`)."""
    d = _json("benchmarks/results/bench_stiffness.json")
    rows = {r["method"]: r for r in d["rows"] if r.get("kind") == "curve"}
    ross = d["ross"]
    lines = [
        "| method (paper pair, 360 angles, 40 N m) | wall (median) | mean k_h (N/m) | ROSS wall / ours |",
        "|---|---|---|---|",
    ]
    for name, label in (("ishikawa", "Ishikawa, 64 slices"), ("energy", "potential energy, Gauss 16")):
        r = rows[name]
        lines.append(
            f"| {label} | {r['wall_s_median'] * 1e3:.2f} ms | {r['mean_N_per_m']:.4e} | "
            f"{ross['wall_s_median'] / r['wall_s_median']:.0f} |"
        )
    lines.append(
        f"| ROSS {ross['ross_version']} `GearElementTVMS` (peer) | {ross['wall_s_median'] * 1e3:.0f} ms | "
        f"{ross['mean_N_per_m']:.4e} | 1 |"
    )
    return "\n".join(lines)


def plane_study() -> str:
    """The 3D FE check of the 2D idealisation (reports/plane/plane.json, benchmarks/bench_plane.py):
    the face-averaged 3D tooth compliance over plane stress and over plane strain at the three
    load radii, finest mesh level, and which state has the smaller largest error."""
    rows = _json("reports/plane/plane.json")["rows"]
    widths = sorted({r["b_over_m"] for r in rows})
    lines = [
        "| b/m | 3D / plane stress (SAP, pitch, top) | 3D / plane strain (SAP, pitch, top) | closer |",
        "|---|---|---|---|",
    ]
    for bm in widths:
        sel = [r for r in rows if r["b_over_m"] == bm]
        st = [r["average_3d"] / r["stress"] for r in sel]
        sn = [r["average_3d"] / r["strain"] for r in sel]
        closer = "stress" if max(abs(x - 1) for x in st) <= max(abs(x - 1) for x in sn) else "strain"
        lines.append(
            f"| {bm:g} | {', '.join(f'{x:.3f}' for x in st)} | {', '.join(f'{x:.3f}' for x in sn)} | {closer} |"
        )
    return "\n".join(lines)


def _pct(a: float, b: float) -> str:
    return f"{100 * (b / a - 1):+.1f} %"


def bore_study() -> str:
    """The bore study (benchmarks/results/bench_bore_study.json, benchmarks/bench_bore_study.py):
    the pair FE held at its bores, the mesh only, the blanks' torsion (FE and closed form),
    the identity's residual and the analytic models beside them, then the decomposition of
    the bore dependence in words."""
    d = _json("benchmarks/results/bench_bore_study.json")
    rows = d["rows"]
    lines = [
        f"Pair FE in plane {d['plane']} (the command line's `auto` for b/m = 10), {d['positions']} positions, "
        f"{d['torque_Nm']:g} N m; means in 1e8 N/m, k_blank in 1e6 N m/rad:",
        "",
        "| bores (mm) | r_ref (mm) | FE bore-fixed | FE mesh only | - translation | k_blank FE (pinion / gear) | "
        "k_blank closed form | identity | Ishikawa | energy | ISO 6336 | FE wall (s) | 3 analytic (s) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        kf, kc = r["k_blank_fe_Nm_per_rad"], r["k_blank_closed_form_Nm_per_rad"]
        lines.append(
            f"| {r['bores_mm'][0]:g} / {r['bores_mm'][1]:g} | "
            f"{r['r_ref_mm'][0]:.2f} / {r['r_ref_mm'][1]:.2f} | "
            f"{r['bore_fixed_mean_N_per_m'] / 1e8:.4f} | {r['mesh_only_mean_N_per_m'] / 1e8:.4f} | "
            f"{r['mesh_only_without_translation_mean_N_per_m'] / 1e8:.4f} | "
            f"{kf[0] / 1e6:.3f} / {kf[1] / 1e6:.3f} | {kc[0] / 1e6:.3f} / {kc[1] / 1e6:.3f} | "
            f"{r['identity_residual_max']:.1e} | {r['ishikawa_mean_N_per_m'] / 1e8:.4f} | "
            f"{r['energy_mean_N_per_m'] / 1e8:.4f} | {r['iso6336_N_per_m'] / 1e8:.4f} | "
            f"{r['fe_wall_s']:.1f} | {r['analytic_wall_s']:.2f} |"
        )
    a, mid, b = rows[0], rows[1], rows[-1]
    fix = [1e10 / r["bore_fixed_mean_N_per_m"] for r in (a, b)]
    mesh = [1e10 / r["mesh_only_mean_N_per_m"] for r in (a, b)]
    blank = [1e10 * r["blank_compliance_closed_form_m_per_N"] for r in (a, b)]
    tr = [1e10 * r["translation_compliance_m_per_N"] for r in (a, b)]
    d_mesh, d_tr = mesh[0] - mesh[1], tr[0] - tr[1]
    module = 3.0
    rim = [[(rf - bo) / module for rf, bo in zip(r["root_radius_mm"], r["bores_mm"])] for r in rows]
    name = lambda r: f"{r['bores_mm'][0]:g}/{r['bores_mm'][1]:g}"  # noqa: E731
    ratio = lambda key, ref: " / ".join(f"{r[key] / r[ref]:.2f}" for r in rows)  # noqa: E731
    lines += [
        "",
        (
            f"From {name(a)} to {name(b)} mm the bore-fixed mean rises "
            f"{_pct(a['bore_fixed_mean_N_per_m'], b['bore_fixed_mean_N_per_m'])} "
            f"({a['bore_fixed_mean_N_per_m']:.3g} to {b['bore_fixed_mean_N_per_m']:.3g} N/m); its compliance 1/mean "
            f"falls by {fix[0] - fix[1]:.2f}e-10 m/N ({fix[0]:.3f} to {fix[1]:.3f}e-10). The blanks' torsion below "
            f"r_ref "
            f"(closed form, {blank[0]:.3f} to {blank[1]:.3f}e-10) is {blank[0] - blank[1]:.2f}e-10 of it. The "
            f"mesh-only "
            f"compliance falls by the other {d_mesh:.2f}e-10 ({mesh[0]:.3f} to {mesh[1]:.3f}e-10; the mean "
            f"{_pct(a['mesh_only_mean_N_per_m'], mid['mesh_only_mean_N_per_m'])} at {name(mid)}, "
            f"{_pct(a['mesh_only_mean_N_per_m'], b['mesh_only_mean_N_per_m'])} at {name(b)}): {d_tr:.2f}e-10 is the "
            f"reference circles' translation along the line of action ({tr[0]:.3f} to {tr[1]:.3f}e-10: the blanks' "
            f"bending under the net tooth force, the n = 1 part, which grows like ln(r_ref / r_bore)), and "
            f"{d_mesh - d_tr:.2f}e-10 the teeth's foundation, which a bore held close under the root stiffens (the rim "
            f"below the root, s_R = r_f - r_bore, is {' / '.join(f'{x[0]:.1f}' for x in rim)} modules on the pinion "
            f"and "
            f"{' / '.join(f'{x[1]:.1f}' for x in rim)} on the gear; at {b['bores_mm'][0]:g} mm the pinion's r_ref is "
            f"{b['r_ref_mm'][0] - b['bores_mm'][0]:.2f} mm above its bore). Without the translation the mesh-only mean "
            "moves "
            f"{_pct(a['mesh_only_without_translation_mean_N_per_m'], mid['mesh_only_without_translation_mean_N_per_m'])} "  # noqa: E501 (one expression)
            f"at {name(mid)} and "
            f"{_pct(a['mesh_only_without_translation_mean_N_per_m'], b['mesh_only_without_translation_mean_N_per_m'])} "
            f"at {name(b)}. The energy method moves with the bore too "
            f"({_pct(a['energy_mean_N_per_m'], mid['energy_mean_N_per_m'])} / "
            f"{_pct(a['energy_mean_N_per_m'], b['energy_mean_N_per_m'])}, through Sainsot's h_fi): its ratio to the "
            f"mesh-only mean is {ratio('energy_mean_N_per_m', 'mesh_only_mean_N_per_m')}, to the bore-fixed one "
            f"{ratio('energy_mean_N_per_m', 'bore_fixed_mean_N_per_m')}; ISO 6336's "
            f"{ratio('iso6336_N_per_m', 'mesh_only_mean_N_per_m')} against "
            f"{ratio('iso6336_N_per_m', 'bore_fixed_mean_N_per_m')}; Ishikawa's "
            f"{ratio('ishikawa_mean_N_per_m', 'mesh_only_mean_N_per_m')} against "
            f"{ratio('ishikawa_mean_N_per_m', 'bore_fixed_mean_N_per_m')}."
        ),
    ]
    return "\n".join(lines)


def _interval(e: dict) -> str:
    return f"{e['value']:.1f} (95 %: {e['lo95']:.1f}-{e['hi95']:.1f})"


#: the example diagnoses (reports/diagnose/<case>/diagnosis.json, `make report`) and how the
#: table describes their measurement
DIAGNOSE_EXAMPLES = (
    ("timeseries", "`measured_timeseries.csv`: y_p, x_p, delta, 8 mesh periods at 64 samples each, no noise"),
    ("harmonics", "`measured_harmonics.csv`: harmonics 1-10 of F_m and y_p, 2 % noise"),
    ("torque", "the time series, `--unknowns wear,clearance,torque` (torque truth 40 N m)"),
)
_SHORT = {"wear_max_depth_um": "wear", "clearance_um": "clearance", "torque_Nm": "torque_Nm"}


def diagnose_examples() -> str:
    """The example diagnoses: each unknown's estimate and 95 % interval, and the verdict in
    words (which unknowns the measurement does not resolve, why, and what would)."""
    lines = ["| measurement | wear_max_depth_um (truth 18) | clearance_um (truth 24) | verdict |", "|---|---|---|---|"]
    for case, what in DIAGNOSE_EXAMPLES:
        d = _json(f"reports/diagnose/{case}/diagnosis.json")
        e, ident = d["estimates"], d["identifiable"]
        notes = []
        for name, ok in ident.items():
            if ok:
                continue
            info = d["identifiability"][name]
            shown = _SHORT[name] if name in ("wear_max_depth_um", "clearance_um") else f"{name} {_interval(e[name])}"
            why = (
                f" (trades off with the {_SHORT[info['trades_off_with']]})" if info.get("reason") == "trade-off" else ""
            )
            fix = info.get("would_resolve", {}).get("measurement", "")
            fix = f"; {fix.split(' (')[0]} would resolve it" if fix else ""
            notes.append(f"{shown} not identifiable{why}{fix}")
        verdict = "; ".join(notes) if notes else "all resolved" if len(ident) > 2 else "both resolved"
        lines.append(f"| {what} | {_interval(e['wear_max_depth_um'])} | {_interval(e['clearance_um'])} | {verdict} |")
    return "\n".join(lines)


def _span(values: list[float], unit: str = " %") -> str:
    lo, hi = f"{min(values):.0f}", f"{max(values):.0f}"
    return f"{lo}{unit}" if lo == hi else f"{lo}-{hi}{unit}"


def diagnose_plan() -> str:
    """What the measurement plan (reports/diagnose/plan/plan.json) says, in one paragraph."""
    d = _json("reports/diagnose/plan/plan.json")
    rows = d["rows"]
    harm = [r for r in rows if r["measurement"].endswith("harmonics")]
    disp = [r for r in rows if r["measurement"] in ("y_p_um time series", "x_p_um time series")]
    clr = [100 * r["width_fraction"]["clearance_um"] for r in harm]
    dc = [100 * r["width_fraction"]["clearance_um"] for r in disp]
    dw = [100 * r["width_fraction"]["wear_max_depth_um"] for r in disp]
    b = d["best"]
    low = min(r["torque_Nm"] for r in rows)
    blind = sorted(
        {r["speed_rpm"] for r in harm if r["torque_Nm"] == low}
        - {r["speed_rpm"] for r in harm if r["torque_Nm"] == low and r["width_fraction"]["wear_max_depth_um"] < 0.995}
    )
    text = (
        f"At every candidate speed and torque no harmonic table separates wear and clearance "
        f"(clearance {_span(clr)} of its prior range), while every displacement time "
        f"series {'does' if all(r['separable'] for r in disp) else 'mostly does'} "
        f"(clearance {_span(dc)}, wear {_span(dw)}); the narrowest is "
        f"all four signals at {b['speed_rpm']:g} rpm and {b['torque_Nm']:g} N m (wear "
        f"{100 * b['width_fraction']['wear_max_depth_um']:.0f} %, clearance "
        f"{100 * b['width_fraction']['clearance_um']:.0f} %)."
    )
    if blind:
        text += (
            f" At {low:g} N m the harmonics alone say nothing about the wear at "
            f"{' and '.join(f'{s:g}' for s in blind)} rpm (100 %)."
        )
    return text


def stiffness_sources() -> str:
    """The stiffness sources and what each supports, from the registry (gearwear.stiffness.sources)."""
    from gearwear.stiffness.sources import SOURCES

    def yes(flag: bool) -> str:
        return "yes" if flag else "-"

    rows = [
        "| source | what it is | `--method` | scene `source` | default points per mesh period | flank, faults | "
        "fem.plane | runs the FE |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for s in SOURCES.values():
        rows.append(
            f"| `{s.name}` | {s.title} | {yes(s.command)} | {yes(s.scene)} | {s.default_points} | "
            f"{yes(s.flank and s.faults) if s.flank == s.faults else 'flank only'} | {yes(s.plane)} | {yes(s.fe)} |"
        )
    return "\n".join(rows)


#: the published models' rows: (reference, what the tooth compliance holds)
_PUBLISHED = {
    "yang_lin": ("Yang & Lin 1987", "involute from the base circle: bending, axial; linear Hertz"),
    "tian": ("Tian 2004", "involute from the base circle: bending, shear, axial; linear Hertz"),
    "wu_zuo_parey": (
        "Wu, Zuo & Parey 2008",
        "Tian's tooth from the base circle; Sainsot foundation at the base circle; linear Hertz",
    ),
    "chen_shao": (
        "Chen & Shao 2013",
        "clamped at the root circle (straight segment below r_b): bending, shear, axial; Sainsot foundation; "
        "linear Hertz",
    ),
    "chen_shao_weber": ("Chen & Shao 2013, Weber 1949", "as chen_shao with Weber's foundation"),
    "kuang_yang": ("Kuang & Yang 1992", "FE regression in N, x and r per tooth (all flexibilities; no Hertz term)"),
}


def published_models() -> str:
    """The published analytic models, their checks and costs
    (benchmarks/results/bench_published_models.json, benchmarks/bench_published_models.py)."""
    d = _json("benchmarks/results/bench_published_models.json")["methods"]
    rows = [
        "| method | reference | what it holds | checked against | figure | mean k_h 23/47 (N/m) | "
        "mean k_h 30/30 (N/m) | CPU / energy's |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for m, (ref, what) in _PUBLISHED.items():
        r = d[m]
        c = r["check"]
        if c["kind"] == "quad":
            from gearwear.analytic.involute_beam import MODELS

            found = ", the foundation by its formula from the hand geometry" if MODELS[m][2] != "none" else ""
            check = f"the height integrals by adaptive quadrature{found} (independent implementation)"
            fig = f"max rel. diff. {c['max_rel_diff']:.1e}"
        else:
            check = "ISO 6336-1 c'_th at the pitch point (second model)"
            fig = (
                f"ratio {c['ratio']['unequal_23_47']:.3f} (23/47), {c['ratio']['paper_30_30']:.3f} (30/30); "
                f"{c['sweep_min']:.2f}-{c['sweep_max']:.2f} over z 15-100"
            )
        mean = r["mean_N_per_m"]
        rows.append(
            f"| `{m}` | {ref} | {what} | {check} | {fig} | {mean['unequal_23_47']:.3e} | {mean['paper_30_30']:.3e} | "
            f"{r['cpu_over_energy']:.2f} |"
        )
    rob = _json("benchmarks/results/bench_published_models.json")["robustness"]
    n = sum(rob["energy"][k] for k in ("ok", "refused", "crash"))
    rows += [
        "",
        f"Over {n} random valid pairs (z 12-120, 14.5-25 deg, shifts up to 0.8, 100 N/mm), the curves that "
        "are finite and positive, refused in one line, or crash, and the mean k_h over `energy`'s:",
        "",
        "| method | finite, positive | refused | crash | mean k_h / energy's: median (min-max) |",
        "|---|---|---|---|---|",
    ]
    for m, r in rob.items():
        spread = f"{r['ratio_median']:.2f} ({r['ratio_min']:.2f}-{r['ratio_max']:.2f})" if "ratio_median" in r else "-"
        rows.append(f"| `{m}` | {r['ok']} | {r['refused']} | {r['crash']} | {spread} |")
    return "\n".join(rows)


def _s(x, fmt: str = ".1f") -> str:
    return "n/a" if x is None else f"{x:{fmt}} s"


def _dig(d: dict | None, *keys):
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return None
        d = d[k]
    return d


def cost_table() -> str:
    """What a user waits for, before and after issue 27, with the limit or the peer beside
    it: whole commands from benchmarks/results/bench_costs.json and bench_costs_before.json
    (benchmarks/bench_costs.py on this machine, the same script on the checkout before
    issue 27), the user table against the C loop from bench_user_table.json and the
    sweep's split per scene from bench_sweep_scale.json."""
    res = ROOT / "benchmarks" / "results"
    after = _json("benchmarks/results/bench_costs.json")
    before = (
        _json("benchmarks/results/bench_costs_before.json") if (res / "bench_costs_before.json").is_file() else None
    )
    ut = _json("benchmarks/results/bench_user_table.json")
    sw = _dig(_json("benchmarks/results/bench_sweep_scale.json"), "issue27", "split_ms") or {}
    b, a = (before or {}).get("rows", {}), after["rows"]

    def both(key: str, field: str, fmt: str = ".1f") -> tuple[str, str]:
        return _s(_dig(b, key, field), fmt), _s(_dig(a, key, field), fmt)

    rows = [
        "| what the user runs | before | after | limit or peer |",
        "|---|---|---|---|",
    ]
    for key, what in (
        (
            "simulate_default",
            "first `gearwear simulate` (built-in default scene: dopri5, every effect), "
            "whole process, empty numba cache (warm cache)",
        ),
        (
            "simulate_paper_default",
            "first `gearwear simulate paper-default` (RK4, stiffness only), whole "
            "process, empty numba cache (warm cache)",
        ),
    ):
        (bc, ac), (bw, aw) = both(key, "cold_s"), both(key, "warm_s")
        rows.append(f"| {what} | {bc} ({bw}) | {ac} ({aw}) | 4 s cold |")
    (b1, a1), (b2, a2) = both("sweep_100_workers_1", "wall_s"), both("sweep_100_workers_2", "wall_s")
    rows.append(
        "| `gearwear sweep paper-default --set operating.speed_rpm=1000:3000:100` (100 scenes of 0.5 s), "
        f"whole process, warm numba cache: 1 worker / 2 workers | {b1} / {b2} | {a1} / {a2} | 4 s on 2 workers |"
    )
    if _dig(a, "sweep_100_workers_2_stdout", "wall_s") is not None:
        rows.append(
            "| the same sweep on 2 workers without `--out` (the summary on stdout; no CSV, no figures) | | "
            f"{_s(_dig(a, 'sweep_100_workers_2_stdout', 'wall_s'), '.1f')} | 4 s on 2 workers |"
        )
    if sw:
        rows.append(
            "| one sweep point in-process (ms): integration / everything else (scene, table, rest of the run, "
            f"harmonics, indicators, transport) | | {sw['integration']:.0f} / {sw['overhead']:.0f} | "
            "everything else at most the integration |"
        )
    r = ut["ratio_to_c"]
    rows.append(
        "| 1 s simulated, 4096-row user table, RK4 256 steps per mesh period: the kernel on the C loop's "
        "model (every effect) / the whole `simulate` call, as multiples of the C loop in the same run | "
        f"{r['kernel_all_effects_before']:.1f}x / {r['sim_before']:.1f}x | {r['kernel_all_effects']:.2f}x / "
        f"{r['sim']:.2f}x | 3x the C loop (`benchmarks/c_rk4`); F_m harmonics "
        f"{ut['accuracy']['rel_error_vs_reference']:.1e} from the converged reference (limit 1e-3) |"
    )
    bf, af = both("pair_fe_cycle_24", "cold_s", ".2f")
    rows.append(
        f"| resolved pair-FE cycle, paper pair, 24 positions, cold in one process | {bf} | {af} | 2.5 s; "
        "a 2D CalculiX contact model of the same pair: 40-60 s per position |"
    )
    for key, what, limit in (
        ("report_paper", "`gearwear report paper`", 60),
        ("diagnose_plan", "`gearwear diagnose --plan`", 20),
    ):
        (bc, ac), (bw, aw) = both(key, "cold_s"), both(key, "warm_s")
        rows.append(
            f"| {what}, whole process, an empty `GEARWEAR_CACHE` (stiffness tables, surrogates; warm cache) "
            f"| {bc} ({bw}) | {ac} ({aw}) | {limit} s |"
        )
    when = f"after: {after['date']} at {after['checkout_commit']}"
    if before:
        when += f"; before: {before['date']} at {before['checkout_commit']}"
    rows.append("")
    rows.append(f"Measured on this machine (2 cores), {when}.")
    return "\n".join(rows)


def _sci(x: float) -> str:
    """1.2e-3-style (no exponent padding)."""
    m, e = f"{x:.1e}".split("e")
    return f"{m}e{int(e)}"


def dynamics_smooth() -> str:
    """The smooth case of benchmarks/results/bench_dynamics.json: the reference's
    cross-check, the table of wall time against error, and the ratios the text quotes."""
    d = _json("benchmarks/results/bench_dynamics.json")
    s, summ = d["smooth"], d["summary"]
    rows = {(r["method"], r["setting"]): r for r in s["rows"]}

    def cells(method: str, settings: list[str], unit: float, fmt: str, suffix: str) -> str:
        got = [rows[method, x] for x in settings]
        walls = " / ".join(f"{r['wall_s'] * unit:{fmt}}" for r in got)
        return f"{walls} {suffix} | " + " / ".join(_sci(r["err_h1_10"]) for r in got)

    rk4 = [f"{n} /period" for n in (128, 256, 512, 1024)]
    r256, r45 = rows["RK4", "256 /period"], rows["scipy RK45", "rtol 1e-07"]
    return "\n".join(
        [
            "Dynamics (`benchmarks/bench_dynamics.py`, one run): error = max relative error of the",
            "F_m harmonics 1-10 against dopri5 at rtol 1e-12 (which agrees with scipy DOP853 at",
            f"rtol 1e-12 to {_sci(s['dop853_vs_reference'])}). All harmonics are exact window integrals",
            "(`dynamics.analysis.window_harmonics`), scipy's included, so no method is judged on",
            "aliased samples.",
            "",
            "| smooth case (40 N m, 0.2 s) | wall | error |",
            "|---|---|---|",
            "| RK4, 128 / 256 / 512 / 1024 steps per mesh period | " + cells("RK4", rk4, 1e3, ".1f", "ms") + " |",
            "| adaptive Dormand-Prince, rtol 1e-8 / 1e-10 | "
            + cells("dopri5", ["rtol 1e-08", "rtol 1e-10"], 1e3, ".1f", "ms")
            + " |",
            "| scipy RK45 (Python right-hand side), rtol 1e-7 / 1e-8 | "
            + cells("scipy RK45", ["rtol 1e-07", "rtol 1e-08"], 1.0, ".2f", "s")
            + " |",
            "| scipy DOP853 (Python right-hand side), rtol 1e-10 / 1e-12 | "
            + cells("scipy DOP853", ["rtol 1e-10", "rtol 1e-12"], 1.0, ".1f", "s")
            + " |",
            "",
            f"RK4 at 256 steps per period is {r45['wall_s'] / r256['wall_s']:.0f} times faster than RK45 at "
            f"rtol 1e-7 (which is still {r45['err_h1_10'] / r256['err_h1_10']:.0f} times less accurate) and "
            f"{summ['ratio_rk45_interpolated']:.0f} times faster at equal error (interpolated). Its observed "
            f"order is {s['rk4_order_fit_table_multiples']:.2f}. The scipy rows are adaptive runs on a "
            "right-hand side whose linear table kinks they step across: at loose tolerances their error "
            "depends on where the steps fall: between the runs of 2026-11-28 and 2026-12-08 (the same code and "
            "numpy and scipy versions; solve_ivp took 14564 and 14555 steps at rtol 1e-7) the RK45 error at "
            "rtol 1e-8 moved from 3.6e-5 to 1.1e-4, while the numba rows stayed the same to the bit.",
        ]
    )


def user_table() -> str:
    """The long user table against the C loop (benchmarks/results/bench_user_table.json): the
    run's load, the ratios now and before issue 27, and dopri5's."""
    ut = _json("benchmarks/results/bench_user_table.json")
    r, d = ut["ratio_to_c"], ut["dopri5"]
    agree = ut["all_effects_agreement_numba_vs_c"]["max_component_rel"]
    rows = [
        f"Long user tables (`benchmarks/bench_user_table.py`, one run, {ut['date'][:10]}, load average "
        f"{ut['load_avg'][0]:.1f} at its start; minimum of {len(ut['rounds_s']['c'])} interleaved rounds, so "
        "the in-run ratios are what to read): the user-table example (4096 rows of a smooth closed-form k and e "
        "per mesh period), 256 RK4 steps per mesh period, 1 s simulated. The schedule now holds "
        f"{ut['substeps_per_period']['now']} sub-steps per period ({ut['substeps_per_period']['before']} before: "
        "every step split at its 16 nodes); the C loop (`c_rk4/rk4.c`, all effects) over 256 sub-steps per "
        "period is the unit:",
        "",
        "| 1 s simulated, 4096-row table, 256 steps per period | now, x C | before, x C |",
        "|---|---|---|",
        f"| RK4 kernel, the table's own model (TVMS and TE) | {r['kernel']:.2f} | {r['kernel_before']:.1f} |",
        "| RK4 kernel, the same table with every effect of the C loop (its model; final states agree to "
        f"{agree:.0e}) | {r['kernel_all_effects']:.2f} | {r['kernel_all_effects_before']:.1f} |",
        f"| `simulate(..., dense=False)`, end to end | {r['sim']:.2f} | {r['sim_before']:.1f} |",
        "| `simulate(...)` with the dense output at every table node of the kept window (for the exact window "
        f"harmonics) | {r['sim_dense']:.1f} | {r['sim_dense_before']:.1f} |",
        f"| dopri5, rtol {d['rtol']:g} (kernel; steps end on every table node: {d['steps_per_mesh_period']:.0f} "
        f"steps per mesh period) | {d['ratio_to_c']:.1f} | - |",
    ]
    return "\n".join(rows)


# -- the atlas (issue 28): reports/atlas, written by make atlas ------------------------------

ATLAS = ROOT / "reports" / "atlas"


def _atlas_md(name: str) -> str:
    """A table python -m gearwear.reports.atlas wrote into reports/atlas/analysis."""
    return (ATLAS / "analysis" / name).read_text().rstrip("\n")


def atlas_facts() -> str:
    """What the committed atlas holds: designs, Sobol points drawn, rejects, the axes and what
    was held fixed (reports/atlas/atlas.csv.json, the sidecar gearwear atlas wrote)."""
    side = json.loads((ATLAS / "atlas.csv.json").read_text())
    inp = side["inputs"]
    rejects = ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in side["rejects"].items())
    axes = "; ".join(
        f"{k[len('axes.') :].replace('_', ' ')} {v[0]:g}-{v[1]:g}"
        for k, v in sorted(inp.items())
        if k.startswith("axes.")
    )
    return (
        f"{side['designs']} feasible designs of {side['points_drawn']} scrambled Sobol points (seed {inp['seed']}; "
        f"rejected: {rejects}). Axes: {axes}. Held fixed: module {inp['pair.module_mm']:g} mm, face width "
        f"{inp['pair.face_width_mm']:g} mm, E {inp['pair.youngs_modulus_GPa']:g} GPa, "
        f"nu {inp['pair.poisson_ratio']:g}, "
        f"plane {inp['fe.plane']}, rack tip radius {inp['pair.rack_tip_radius_coefficient']:g} m_n, dedendum h_a* + "
        f"{inp['pair.dedendum_margin']:g}, solid blanks held at their bores (no webs); the pair FE at "
        f"{inp['fe.positions']} positions per mesh period, mesh scale {inp['fe.mesh_scale']:g}, the transitions "
        f"bisected: {'yes' if inp['fe.transitions'] else 'no'}. Models: {', '.join(f'`{m}`' for m in side['models'])}."
    )


def atlas_headline() -> str:
    """The atlas in three lines, from reports/atlas/analysis/summary.json."""
    d = json.loads((ATLAS / "analysis" / "summary.json").read_text())
    mean = {m: v["mean_N_per_m"] for m, v in d["summary"].items() if m != "fem_bore_fixed" and v["mean_N_per_m"]["n"]}
    ranked = sorted(mean, key=lambda m: mean[m]["median_abs"])
    c = d["corrected"]
    cm, best = c["corrected"]["mean"], c["analytic_mean_error_on_held_out"][c["best_analytic"]]
    bf = d["summary"]["fem_bore_fixed"]["mean_N_per_m"]

    def pct(x: float) -> str:
        return f"{100 * x:.1f} %"

    return "\n".join(
        [
            f"- **Over {d['designs']} designs the best analytic model's mean k_h is off the FE by "
            f"{pct(mean[ranked[0]]['median_abs'])} on the median.** The closest: "
            + ", ".join(
                f"`{m}` {pct(mean[m]['median_abs'])} (p95 {pct(mean[m]['p95_abs'])}, on {mean[m]['n']} designs)"
                for m in ranked[:3]
            )
            + "; the farthest: "
            + ", ".join(f"`{m}` {pct(mean[m]['median_abs'])} (p95 {pct(mean[m]['p95_abs'])})" for m in ranked[-2:])
            + ".",
            f"- **The corrected model** (the energy method times a surrogate of the FE ratio) is off by "
            f"{pct(cm['median_abs'])} on the median and {pct(cm['p95_abs'])} at p95 on {c['held_out_designs']} designs "
            f"held out of its fit, against {pct(best['median_abs'])} and {pct(best['p95_abs'])} for the best analytic "
            f"model on the same designs (`{c['best_analytic']}`).",
            f"- **The definition moves the number too:** the bore-fixed FE differs from the mesh-only one by "
            f"{pct(bf['median_abs'])} on the median, {pct(bf['p95_abs'])} at p95 and up to {pct(bf['max_abs'])} "
            "(the blanks' torsion, largest for a small bore under a thick rim).",
        ]
    )


def atlas_errors() -> str:
    return _atlas_md("errors.md")


def atlas_where() -> str:
    return _atlas_md("where.md")


def atlas_failures() -> str:
    return _atlas_md("failures.md")


def atlas_corrected() -> str:
    return _atlas_md("corrected.md")


def atlas_corrected_pairs() -> str:
    """The corrected model on pairs that are not atlas designs
    (benchmarks/results/bench_corrected_pairs.json, benchmarks/bench_corrected_pairs.py)."""
    d = _json("benchmarks/results/bench_corrected_pairs.json")
    given = d["rows"][0]["models"]
    models = ["corrected", *sorted(m for m in given if m != "corrected")] if "corrected" in given else sorted(given)
    rows = [
        "| pair | FE mean k_h (N/m) | FE wall (s) | " + " | ".join(f"`{m}`" for m in models) + " |",
        "|---" * (len(models) + 3) + "|",
    ]
    for r in d["rows"]:
        cells = [f"{100 * r['models'][m]['error']:+.1f} %" for m in models]
        rows.append(
            f"| {r['pair']} | {r['fem_mean_N_per_m']:.3e} | {r['fem_wall_s']:.1f} | " + " | ".join(cells) + " |"
        )
    rows += [
        "",
        f"Error of each model's mean k_h against the pair FE (blanks' torsion taken out, plane stress), {d['when']}.",
    ]
    return "\n".join(rows)


def atlas_scale() -> str:
    """The atlas's wall time and cost per design (benchmarks/results/bench_atlas_scale.json,
    benchmarks/bench_atlas_scale.py) and the committed run's own timing."""
    d = _json("benchmarks/results/bench_atlas_scale.json")
    rows = [
        f"`gearwear atlas` on the first {d['designs']} designs of atlas.toml, empty cache, whole process "
        f"({d['when']}, load average at the start {d['load_average_start'][0]:.1f}; "
        "`python benchmarks/bench_atlas_scale.py`):",
        "",
        "| executor | wall (s) | designs' CPU, sum (s) | per design, median CPU (s) | overhead (s) | atlas.csv |",
        "|---|---|---|---|---|---|",
    ]
    first = d["runs"][0]["atlas_csv_sha256"]
    for r in d["runs"]:
        same = "the same bytes" if r["atlas_csv_sha256"] == first else "DIFFERENT bytes"
        rows.append(
            f"| {r['executor']} (`{' '.join(r['command'].split()[3:-3])}`) | {r['wall_s']:.1f} | "
            f"{r['designs_cpu_s_sum']:.1f} | {r['design_cpu_s_median']:.1f} | {r['overhead_s']:.1f} | {same} |"
        )
    run = json.loads((ATLAS / "timing.json").read_text())["wall_s"]
    timed = sum(1 for v in run.values() if isinstance(v, dict) and "design" in v)
    rows += [
        "",
        f"The committed atlas itself: {timed} designs computed in one run of {run['total_wall_s'] / 60:.1f} min "
        f"(`make atlas`: a 2-worker Dask LocalCluster, with other jobs sharing the 2 cores), and "
        f"{run['designs_from_cache']} read from the content-hash cache, computed by an earlier, interrupted run of "
        "the same code (the FE's code fingerprint is in each cache key). The 500 designs were therefore not timed "
        "in one piece on either executor; the projection below is from the designs' own CPU times.",
    ]
    pr = d.get("projection")
    if pr:
        c = pr["design_cpu_s"]
        workers = sorted(int(n) for n in pr["wall_s_by_workers"])
        rows += [
            "",
            f"Per design over the committed atlas ({pr['designs_timed']} designs timed in the run that computed "
            f"them): CPU mean {c['mean']:.1f} s, median {c['median']:.1f} s, p95 {c['p95']:.1f} s, "
            f"max {c['max']:.1f} s. "
            f"Projected wall time of {pr['designs']} designs, overhead + max(sum of CPU / N, the longest design):",
            "",
            "| workers | " + " | ".join(str(n) for n in workers) + " |",
            "|---" * (len(workers) + 1) + "|",
            "| wall (min) | " + " | ".join(f"{pr['wall_s_by_workers'][str(n)] / 60:.0f}" for n in workers) + " |",
        ]
    return "\n".join(rows)


TABLES = {
    "atlas-facts": atlas_facts,
    "atlas-headline": atlas_headline,
    "atlas-errors": atlas_errors,
    "atlas-where": atlas_where,
    "atlas-failures": atlas_failures,
    "atlas-corrected": atlas_corrected,
    "atlas-corrected-pairs": atlas_corrected_pairs,
    "atlas-scale": atlas_scale,
    "stiffness-sources": stiffness_sources,
    "published-models": published_models,
    "stiffness-peer": stiffness_peer,
    "plane-study": plane_study,
    "diagnose-examples": diagnose_examples,
    "diagnose-plan": diagnose_plan,
    "bore-study": bore_study,
    "cost-table": cost_table,
    "user-table": user_table,
    "dynamics-smooth": dynamics_smooth,
}

BLOCK = re.compile(r"(<!-- generated: (?P<name>[\w-]+) -->\n)(?P<body>.*?)(<!-- end: (?P=name) -->)", re.S)


def render(text: str) -> str:
    """``text`` with every generated block rewritten from its source."""
    return BLOCK.sub(lambda m: m.group(1) + TABLES[m.group("name")]() + "\n" + m.group(4), text)


def main(argv: list[str]) -> int:
    check = "--check" in argv
    stale = []
    for doc in sorted((ROOT / "docs").glob("*.md")):
        text = doc.read_text()
        new = render(text)
        if new != text:
            stale.append(doc.name)
            if not check:
                doc.write_text(new)
    if check and stale:
        print(f"generated tables out of date in {', '.join(stale)}: run python docs/generate.py")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
