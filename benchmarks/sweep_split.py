"""The cost of one sweep point, phase by phase, in-process (benchmarks/bench_sweep_scale.py).

A point of ``gearwear sweep`` (gearwear.jobs.sweep.run_point) is: scene validation (the
--set overrides applied, the scene built and checked), the stiffness table
(jobs.simulate.stiffness_input, or the worker's cached copy), the dynamic model
(build_model), the integration (the compiled kernel alone, ``SimResult.wall_s``), the
simulation's own sampling and statistics (the rest of dynamics.simulate.simulate), the
summary's exact harmonics and window means (the window integrals), its condition
indicators, the rest of the summary (warnings, notes), and the transport of the summary
back to the parent (pickling). Each phase is timed on its own, in the order the point
runs them, on warm kernels; the minimum over ``repeats`` passes of the grid is kept per
point (the machine is shared: the minimum is the least disturbed).
"""

from __future__ import annotations

import pickle
import time
from typing import Any

PHASES = (
    "validation",
    "stiffness",
    "model",
    "integration",
    "simulate_rest",
    "harmonics",
    "indicators",
    "summary_rest",
    "transport",
)


def point_split(raw: dict[str, Any], name: str, point: dict[str, Any], fixed: list[str]) -> dict[str, float]:
    """Seconds per phase of one grid point, run exactly as run_point runs it."""
    from gearwear.dynamics import simulate
    from gearwear.jobs import simulate as job
    from gearwear.jobs import sweep
    from gearwear.scene.model import scene_from_dict
    from gearwear.scene.overrides import apply_overrides

    out: dict[str, float] = {}
    t = time.perf_counter()
    scene = scene_from_dict(apply_overrides(raw, sweep.point_sets(point, fixed)), name=name)
    out["validation"] = time.perf_counter() - t
    t = time.perf_counter()
    stiff = sweep.point_stiffness(scene) if hasattr(sweep, "point_stiffness") else job.stiffness_input(scene)
    out["stiffness"] = time.perf_counter() - t
    t = time.perf_counter()
    model = job.build_model(scene, stiff)
    out["model"] = time.perf_counter() - t
    solver = dict(scene.solver)
    kw = {k: solver[k] for k in ("method", "steps_per_mesh_period", "rtol", "atol") if k in solver}
    t = time.perf_counter()
    res = simulate(model, solver["duration_s"], solver["discard_s"], **kw)
    whole = time.perf_counter() - t
    out["integration"] = res.wall_s
    out["simulate_rest"] = whole - res.wall_s
    run = job.SimulationRun(scene, model, stiff, res, solver, dict(scene.output), whole)
    t = time.perf_counter()
    res.harmonics_of(run.output["signals"], run.output["harmonics"])
    res.means_of(run.output["signals"], run.output["harmonics"])
    out["harmonics"] = time.perf_counter() - t
    t = time.perf_counter()
    job.condition_indicators(scene, res)
    out["indicators"] = time.perf_counter() - t
    t = time.perf_counter()
    summary = run.summary()  # harmonics memoised; its indicators again, taken off below
    summary["point"] = point
    out["summary_rest"] = max(time.perf_counter() - t - out["indicators"], 0.0)
    t = time.perf_counter()
    pickle.loads(pickle.dumps(summary))
    out["transport"] = time.perf_counter() - t
    return out


def grid_split(raw, name, points, fixed, repeats: int = 2) -> dict[str, Any]:
    """Per phase: the mean over the points of each point's minimum over ``repeats`` passes (ms)."""
    best: list[dict[str, float]] = []
    for r in range(repeats):
        for i, p in enumerate(points):
            s = point_split(raw, name, p, fixed)
            if r == 0:
                best.append(s)
            else:
                best[i] = {k: min(v, s[k]) for k, v in best[i].items()}
    ms = {k: 1e3 * sum(b[k] for b in best) / len(best) for k in PHASES}
    ms["overhead"] = sum(v for k, v in ms.items() if k != "integration")
    ms["total"] = ms["overhead"] + ms["integration"]
    return ms


#: the driver of :func:`command_timeline`: the console script's main() with the sweep's steps
#: wrapped, each logging (pid, step, start, end) in seconds since the launch
TIMELINE_DRIVER = """
import functools, json, os, sys, time
T0, LOG = float(os.environ["SPLIT_T0"]), os.environ["SPLIT_LOG"]
def rec(name, t0, t1):
    with open(LOG, "a") as f:
        f.write(json.dumps([os.getpid(), name, t0 - T0, t1 - T0]) + "\\n")
def wrap(mod, attr):
    f = getattr(mod, attr)
    @functools.wraps(f)
    def g(*a, **k):
        t0 = time.time()
        try:
            return f(*a, **k)
        finally:
            rec(attr, t0, time.time())
    setattr(mod, attr, g)
import gearwear.cli.sweep as cli_sweep
import gearwear.jobs.sweep as sw
for attr in ("run_point", "warm_figures", "figure_png", "sweep", "write"):
    wrap(sw, attr)
wrap(cli_sweep, "run")
from gearwear.cli import main
sys.argv = ["gearwear", *sys.argv[1:]]
main()
"""


def command_timeline(args: list[str], workers: int, out: str, python: str | None = None) -> dict[str, float]:
    """Where the whole ``gearwear sweep ARGS --workers N --out OUT`` command's wall time goes
    (s), from one run through the console script's ``main`` (numba's disk cache as it is;
    ``python``: the interpreter of another checkout's venv, default this one):

    * ``startup``: process start to the command's ``run`` (interpreter, imports, parser);
    * ``before_points``: to the first point's start (scene validation, forking the workers);
    * ``first_point``: the first point of each worker, mean (kernels from numba's cache, the
      stiffness table, first-call imports);
    * ``points``: the rest of the points, to the last one's end;
    * ``figures``: from there to the files written (figure rendering, its warm-up where it is
      not overlapped, writing);
    * ``exit``: to the process's end; ``total``: the whole wall time."""
    import json
    import os
    import subprocess
    import sys
    import tempfile
    from collections import defaultdict
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "log")
        env = {**os.environ, "SPLIT_LOG": log}
        cmd = [python or sys.executable, "-c", TIMELINE_DRIVER, "sweep", *args, "--workers", str(workers), "--out", out]
        env["SPLIT_T0"] = repr(time.time())
        t0 = time.perf_counter()
        # run in the interpreter's checkout: with -c the current folder comes first on sys.path,
        # and another checkout's gearwear/ there would be imported instead of the venv's own
        cwd = Path(python).absolute().parents[2] if python else Path(__file__).resolve().parents[1]
        subprocess.run(cmd, env=env, cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        total = time.perf_counter() - t0
        rows = [json.loads(x) for x in open(log)]
    by: dict[str, list] = defaultdict(list)
    for pid, name, a, b in rows:
        by[name].append((pid, a, b))
    run = by["run"][0]
    points = sorted(by["run_point"], key=lambda r: r[1])
    firsts = [min((r for r in points if r[0] == pid), key=lambda r: r[1]) for pid in {r[0] for r in points}]
    first_start = points[0][1]
    last_end = max(r[2] for r in points)
    first_mean = sum(r[2] - r[1] for r in firsts) / len(firsts)
    return {
        "startup": run[1],
        "before_points": first_start - run[1],
        "first_point": first_mean,
        "points": last_end - first_start - first_mean,
        "figures": run[2] - last_end,
        "exit": total - run[2],
        "total": total,
        "points_run": len(points),
    }


if __name__ == "__main__":
    import argparse
    import shutil
    import statistics
    import sys
    import tempfile

    ap = argparse.ArgumentParser(description="where the issue-27 sweep command's time goes (command_timeline)")
    ap.add_argument("--python", help="another checkout's venv python (default: this one)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--runs", type=int, default=3, help="runs after one warm-up; the median of each phase")
    a = ap.parse_args()
    sweep_args = ["paper-default", "--set", "operating.speed_rpm=1000:3000:100"]
    with tempfile.TemporaryDirectory() as tmp:
        runs = []
        for i in range(a.runs + 1):
            runs.append(command_timeline(sweep_args, a.workers, f"{tmp}/o{i}", a.python))
            shutil.rmtree(f"{tmp}/o{i}", ignore_errors=True)
    print(f"gearwear sweep {' '.join(sweep_args)} --workers {a.workers}: median of {a.runs} runs (s)")
    for k in runs[1]:
        print(f"  {k:<24}{statistics.median(r[k] for r in runs[1:]):8.3f}")
    sys.exit(0)
