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


TABLES = {"stiffness-peer": stiffness_peer, "plane-study": plane_study}

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
