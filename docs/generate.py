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
    lines = ["| method (paper pair, 360 angles, 40 N m) | wall (median) | mean k_h (N/m) | ROSS wall / ours |",
             "|---|---|---|---|"]
    for name, label in (("ishikawa", "Ishikawa, 64 slices"), ("energy", "potential energy, Gauss 16")):
        r = rows[name]
        lines.append(f"| {label} | {r['wall_s_median'] * 1e3:.2f} ms | {r['mean_N_per_m']:.4e} | "
                     f"{ross['wall_s_median'] / r['wall_s_median']:.0f} |")
    lines.append(f"| ROSS {ross['ross_version']} `GearElementTVMS` (peer) | {ross['wall_s_median'] * 1e3:.0f} ms | "
                 f"{ross['mean_N_per_m']:.4e} | 1 |")
    return "\n".join(lines)


def plane_study() -> str:
    """The 3D FE check of the 2D idealisation (reports/plane/plane.json, benchmarks/bench_plane.py):
    the face-averaged 3D tooth compliance over plane stress and over plane strain at the three
    load radii, finest mesh level, and which state has the smaller largest error."""
    rows = _json("reports/plane/plane.json")["rows"]
    widths = sorted({r["b_over_m"] for r in rows})
    lines = ["| b/m | 3D / plane stress (SAP, pitch, top) | 3D / plane strain (SAP, pitch, top) | closer |",
             "|---|---|---|---|"]
    for bm in widths:
        sel = [r for r in rows if r["b_over_m"] == bm]
        st = [r["average_3d"] / r["stress"] for r in sel]
        sn = [r["average_3d"] / r["strain"] for r in sel]
        closer = "stress" if max(abs(x - 1) for x in st) <= max(abs(x - 1) for x in sn) else "strain"
        lines.append(f"| {bm:g} | {', '.join(f'{x:.3f}' for x in st)} | {', '.join(f'{x:.3f}' for x in sn)} | "
                     f"{closer} |")
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
    lines = ["| measurement | wear_max_depth_um (truth 18) | clearance_um (truth 24) | verdict |",
             "|---|---|---|---|"]
    for case, what in DIAGNOSE_EXAMPLES:
        d = _json(f"reports/diagnose/{case}/diagnosis.json")
        e, ident = d["estimates"], d["identifiable"]
        notes = []
        for name, ok in ident.items():
            if ok:
                continue
            info = d["identifiability"][name]
            shown = _SHORT[name] if name in ("wear_max_depth_um", "clearance_um") else f"{name} {_interval(e[name])}"
            why = (f" (trades off with the {_SHORT[info['trades_off_with']]})" if info.get("reason") == "trade-off"
                   else "")
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
    blind = sorted({r["speed_rpm"] for r in harm if r["torque_Nm"] == low}
                   - {r["speed_rpm"] for r in harm if r["torque_Nm"] == low
                      and r["width_fraction"]["wear_max_depth_um"] < 0.995})
    text = (f"At every candidate speed and torque no harmonic table separates wear and clearance "
            f"(clearance {_span(clr)} of its prior range), while every displacement time "
            f"series {'does' if all(r['separable'] for r in disp) else 'mostly does'} "
            f"(clearance {_span(dc)}, wear {_span(dw)}); the narrowest is "
            f"all four signals at {b['speed_rpm']:g} rpm and {b['torque_Nm']:g} N m (wear "
            f"{100 * b['width_fraction']['wear_max_depth_um']:.0f} %, clearance "
            f"{100 * b['width_fraction']['clearance_um']:.0f} %).")
    if blind:
        text += (f" At {low:g} N m the harmonics alone say nothing about the wear at "
                 f"{' and '.join(f'{s:g}' for s in blind)} rpm (100 %).")
    return text


TABLES = {"stiffness-peer": stiffness_peer, "plane-study": plane_study, "diagnose-examples": diagnose_examples,
          "diagnose-plan": diagnose_plan}

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
