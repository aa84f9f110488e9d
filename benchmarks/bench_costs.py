"""The cost table: the time a user waits for each job of issue 27, as whole processes, with
the limit or the peer beside it (``make bench`` runs this last; nothing is asserted).

Usage: ``python benchmarks/bench_costs.py [--checkout PATH] [--out JSON]``. Every command
runs from ``PATH/.venv`` (default: this checkout), so the same script measures another
revision (the committed ``benchmarks/results/bench_costs_before.json`` is this script run
on the checkout before issue 27, on the same machine). Rows:

* ``simulate`` of the built-in default scene (dopri5, every effect) and of
  ``paper-default`` (RK4, stiffness only), whole process, writing its files: *cold* with a
  fresh, empty ``NUMBA_CACHE_DIR`` (every kernel of that effect set compiled; the best of
  2 runs, each with its own empty folder) and *warm* (the same folder again; median of 3).
  Limit: 4 s cold.
* ``sweep paper-default --set operating.speed_rpm=1000:3000:100`` (100 scenes of 0.5 s)
  on 1 and 2 workers, whole process, numba cache warm (median of 2), writing its files
  (``--out``: the CSV and four figures); and on 2 workers as the issue states the command,
  without ``--out`` (the summary on stdout; median of 3). Limit: 4 s on 2.
* the pair-FE 24-position cycle of the paper pair, cold in one process (``fem.pair.
  pair_contact`` after ``_BODY_CACHE.clear()``: mesh, assembly, factorization and
  condensation of both bodies; imports excluded; the best of 2 fresh processes). Limit
  2.5 s; peer: a 2D CalculiX contact model of the same pair, 40-60 s per position
  (docs/verification.md).
* ``report paper`` and ``diagnose --plan``, whole process, numba warm: with an empty
  ``GEARWEAR_CACHE`` (stiffness tables, surrogates: what a first run costs once the kernels
  are compiled) and then warm (the same cache again). Limits 60 s and 20 s.

The in-process rows that need a peer in the same run (the 4096-row user table against the
C RK4 loop, the sweep's split per scene) come from their own benchmarks
(``bench_user_table.json``, ``bench_sweep_scale.json``) and are put beside these in
docs/accuracy-and-cost.md by docs/generate.py. Writes benchmarks/results/bench_costs.json.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

FE_SNIPPET = """
import time
from gearwear.fem import pair as fp
from gearwear.fem.pair_model import _BODY_CACHE
from gearwear.geometry.spec import default_pair
pair = default_pair()
_BODY_CACHE.clear()
t0 = time.perf_counter()
r = fp.pair_contact(pair, positions=24)
print(time.perf_counter() - t0, r.mean_N_per_m)
"""


def whole(cmd: list[str], env: dict, cwd: Path, timeout: float = 1800) -> float:
    """Wall time (s) of one whole process; raises on a non-zero exit."""
    t0 = time.perf_counter()
    r = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {r.returncode}: {r.stderr.strip()[-500:]}")
    return wall


def env_with(**kw) -> dict:
    env = dict(os.environ)
    env.update({k: str(v) for k, v in kw.items()})
    return env


def simulate_rows(gw: str, scene: list[str], tmp: Path, cwd: Path) -> dict:
    colds = []
    for i in range(2):
        cache = tmp / f"numba-{scene[0] if scene else 'default'}-{i}"
        shutil.rmtree(cache, ignore_errors=True)
        out = tmp / f"sim-{i}"
        colds.append(whole([gw, "simulate", *scene, "--out", str(out)], env_with(NUMBA_CACHE_DIR=cache), cwd))
        shutil.rmtree(out, ignore_errors=True)
    warm = []
    for i in range(3):
        out = tmp / f"simw-{i}"
        warm.append(whole([gw, "simulate", *scene, "--out", str(out)], env_with(NUMBA_CACHE_DIR=cache), cwd))
        shutil.rmtree(out, ignore_errors=True)
    return {"cold_s": min(colds), "cold_runs_s": colds, "warm_s": statistics.median(warm), "warm_runs_s": warm}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--checkout", type=Path, default=ROOT, help="the checkout whose .venv runs the commands")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "bench_costs.json")
    ap.add_argument("--skip", default="", help="comma-separated rows to skip (simulate, sweep, fe, report, plan)")
    args = ap.parse_args(argv)
    co = args.checkout.resolve()
    gw, py = str(co / ".venv" / "bin" / "gearwear"), str(co / ".venv" / "bin" / "python")
    skip = set(filter(None, args.skip.split(",")))
    commit = subprocess.run(["git", "-C", str(co), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    rows: dict = {}
    with tempfile.TemporaryDirectory(prefix="gearwear-costs-") as t:
        tmp = Path(t)
        warm_cache = tmp / "numba-warm"
        if "simulate" not in skip:
            rows["simulate_default"] = simulate_rows(gw, [], tmp, co)
            print(
                f"simulate (default scene): cold {rows['simulate_default']['cold_s']:.2f} s, warm "
                f"{rows['simulate_default']['warm_s']:.2f} s (limit 4 s cold)",
                flush=True,
            )
            rows["simulate_paper_default"] = simulate_rows(gw, ["paper-default"], tmp, co)
            print(
                f"simulate paper-default: cold {rows['simulate_paper_default']['cold_s']:.2f} s, warm "
                f"{rows['simulate_paper_default']['warm_s']:.2f} s (limit 4 s cold)",
                flush=True,
            )
        # one warm numba cache for the rest: every effect set they use compiled once
        env = env_with(NUMBA_CACHE_DIR=warm_cache)
        if "sweep" not in skip:
            cmd = [gw, "sweep", "paper-default", "--set", "operating.speed_rpm=1000:3000:100"]
            whole([*cmd, "--workers", "1", "--out", str(tmp / "sweep-warmup")], env, co)
            for w in (1, 2):
                runs = [
                    whole([*cmd, "--workers", str(w), "--out", str(tmp / f"sweep-{w}-{i}")], env, co) for i in range(2)
                ]
                rows[f"sweep_100_workers_{w}"] = {"wall_s": statistics.median(runs), "runs_s": runs}
                print(f"sweep 100 scenes, {w} worker(s): {statistics.median(runs):.2f} s (limit 4 s on 2)", flush=True)
            # the issue's own command: no --out (the summary table on stdout, no files, no figures)
            runs = [whole([*cmd, "--workers", "2"], env, co) for _ in range(3)]
            rows["sweep_100_workers_2_stdout"] = {"wall_s": statistics.median(runs), "runs_s": runs}
            print(f"sweep 100 scenes, 2 workers, no --out: {statistics.median(runs):.2f} s (limit 4 s)", flush=True)
        if "fe" not in skip:
            runs, mean = [], None
            for _ in range(2):
                r = subprocess.run([py, "-c", FE_SNIPPET], env=env, cwd=co, capture_output=True, text=True, check=True)
                wall, mean = (float(x) for x in r.stdout.split())
                runs.append(wall)
            rows["pair_fe_cycle_24"] = {"cold_s": min(runs), "runs_s": runs, "mean_k_N_per_m": mean}
            print(f"pair-FE cycle, 24 positions, cold: {min(runs):.2f} s (limit 2.5 s)", flush=True)
        for row, key, name, cmd, limit in (
            ("report", "report_paper", "report paper", ["report", "paper"], 60),
            ("plan", "diagnose_plan", "diagnose --plan", ["diagnose", "--plan"], 20),
        ):
            if row in skip:
                continue
            # cold: an empty stiffness-table and surrogate cache; warm: the same cache again
            cache_env = env_with(NUMBA_CACHE_DIR=warm_cache, GEARWEAR_CACHE=tmp / f"cache-{key}")
            cold = whole([gw, *cmd, "--out", str(tmp / f"{key}-cold")], cache_env, co, timeout=3600)
            warm = whole([gw, *cmd, "--out", str(tmp / f"{key}-warm")], cache_env, co, timeout=3600)
            rows[key] = {"cold_s": cold, "warm_s": warm}
            print(f"{name}: {cold:.1f} s with an empty cache, {warm:.1f} s warm (limit {limit} s)", flush=True)
    rec = {
        "benchmark": "bench_costs",
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "checkout_commit": commit.stdout.strip(),
        "machine": {
            "python": platform.python_version(),
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "load_1min_at_end": os.getloadavg()[0],
        },
        "limits_s": {
            "simulate_cold": 4.0,
            "sweep_100_workers_2": 4.0,
            "pair_fe_cycle_24": 2.5,
            "report_paper": 60.0,
            "diagnose_plan": 20.0,
        },
        "rows": rows,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(rec, indent=1) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    main()
