"""The atlas at scale (issue 28): ``gearwear atlas`` on the first N designs of atlas.toml with
an empty cache, on a local process pool of 2 workers (``--workers 2``) and on a 2-worker Dask
LocalCluster (``--scheduler local:2``), whole processes, in one run; the bytes of the two
atlas.csv files compared; the per-design cost and the engine's overhead; a projection of
the full atlas to N workers.

    .venv/bin/python benchmarks/bench_atlas_scale.py [--designs 16] [--full reports/atlas]

Per run: the whole-process wall time, the designs' wall and CPU times (timing.json: each
design's FE and analytic models, measured in the worker), and the overhead

    overhead = wall - (sum of the designs' wall times) / workers

(start-up, imports, scheduling, transport, writing; what the engine adds to the designs'
own cost on a perfectly balanced pool). Projection of an atlas of D designs on N workers
(the designs are independent; a worker holds one design at a time):

    T(N) ~ overhead + max(sum_d cpu_d / N, max_d cpu_d)

with cpu_d the per-design CPU times of ``--full`` (the committed atlas's timing.json: the
designs computed in the run that wrote it) scaled to D designs by their mean. Writes
benchmarks/results/bench_atlas_scale.json. Nothing is asserted: the machine is shared.
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "bench_atlas_scale.json"
EXECUTORS = {"local pool, 2 workers": ["--workers", "2"], "Dask LocalCluster, 2 workers": ["--scheduler", "local:2"]}


def _spec(designs: int, folder: Path) -> Path:
    text = (ROOT / "atlas.toml").read_text().replace("designs = 500", f"designs = {designs}")
    assert f"designs = {designs}" in text
    p = folder / "atlas.toml"
    p.write_text(text)
    return p


def _designs(timing: dict) -> dict[str, dict]:
    """Design index -> its own wall and CPU time in the worker (timing.json: ``design``)."""
    return {k: v["design"] for k, v in timing.items() if isinstance(v, dict) and "design" in v}


def run_one(label: str, flags: list[str], spec: Path, folder: Path) -> dict:
    """One whole ``gearwear atlas`` process with its own empty cache."""
    out, cache = folder / f"out-{len(flags)}-{flags[-1].replace(':', '')}", folder / f"cache-{flags[-1]}"
    env = {**os.environ, "GEARWEAR_CACHE": str(cache)}
    cmd = [str(ROOT / ".venv" / "bin" / "gearwear"), "atlas", str(spec), *flags, "--out", str(out), "--json"]
    t = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t
    timing = json.loads((out / "timing.json").read_text())["wall_s"]
    per = _designs(timing)
    d_wall = sum(v["wall_s"] for v in per.values())
    d_cpu = sum(v["cpu_s"] for v in per.values())
    return {
        "executor": label,
        "command": " ".join(["gearwear", "atlas", "SPEC", *flags, "--out", "DIR", "--json"]),
        "wall_s": wall,
        "designs": len(per),
        "designs_wall_s_sum": d_wall,
        "designs_cpu_s_sum": d_cpu,
        "design_cpu_s_median": statistics.median(v["cpu_s"] for v in per.values()),
        "overhead_s": wall - d_wall / 2,
        "atlas_csv_sha256": hashlib.sha256((out / "atlas.csv").read_bytes()).hexdigest(),
    }


def projection(full: Path, designs: int, overhead_s: float) -> dict:
    """T(N) for the full atlas from the per-design CPU times of its own run (module docstring)."""
    timing = json.loads((full / "timing.json").read_text())["wall_s"]
    cpu = [v["cpu_s"] for v in _designs(timing).values()]
    mean = statistics.fmean(cpu)
    total = mean * designs
    return {
        "from": str(full / "timing.json"),
        "designs_timed": len(cpu),
        "design_cpu_s": {
            "mean": mean,
            "median": statistics.median(cpu),
            "p95": sorted(cpu)[int(0.95 * (len(cpu) - 1))],
            "max": max(cpu),
        },
        "designs": designs,
        "cpu_s_total": total,
        "wall_s_by_workers": {str(n): overhead_s + max(total / n, max(cpu)) for n in (1, 2, 4, 8, 16, 32, 64)},
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--designs", type=int, default=16)
    ap.add_argument("--full", type=Path, default=ROOT / "reports" / "atlas", help="the full atlas folder")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        spec = _spec(args.designs, folder)
        runs = [run_one(label, flags, spec, folder) for label, flags in EXECUTORS.items()]
    for r in runs:
        print(
            f"{r['executor']}: {r['wall_s']:.1f} s wall for {r['designs']} designs "
            f"(designs' CPU {r['designs_cpu_s_sum']:.1f} s, overhead {r['overhead_s']:.1f} s)"
        )
    same = len({r["atlas_csv_sha256"] for r in runs}) == 1
    print(f"atlas.csv bytes equal on both executors: {same}")
    doc = {
        "when": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "load_average_start": os.getloadavg(),
        "designs": args.designs,
        "runs": runs,
        "same_bytes": same,
    }
    full_designs = 500
    if (args.full / "timing.json").exists():
        doc["projection"] = projection(args.full, full_designs, max(r["overhead_s"] for r in runs))
        for n, t in doc["projection"]["wall_s_by_workers"].items():
            print(f"projected {full_designs}-design atlas on {n} workers: {t / 60:.0f} min")
    RESULTS.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n")
    print(f"wrote {RESULTS}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
