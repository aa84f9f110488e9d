"""Sweep scaling: 100 scenes of 1 s simulated each, on the local process pool and on a Dask
LocalCluster, with 1 and 2 workers (``make bench``; nothing asserted).

The scenes are the built-in ``paper-default`` (paper pair, analytic Ishikawa stiffness,
RK4 256 steps per mesh period) at 100 torques from 20 to 40 N m, ``solver.duration_s = 1``
(0.3 s discarded), run through ``gearwear.jobs.sweep.sweep`` exactly as ``gearwear sweep``
does (every point: scene validation, stiffness table, model, integration, summary with
exact harmonics and condition indicators). For each executor:

* start-up: creating the executor and one warm-up task per worker (import, numba kernels
  from the disk cache); a cluster's start-up is paid once per sweep;
* run: wall time of the 100 points after start-up;
* integration: the sum of the points' ``integration_wall_s`` (the compiled integrator alone);
* overhead per scene = (run wall x workers - integration) / 100: everything a scene costs
  beyond its integration (scene, stiffness table, summary, pickling, scheduling);
* scaling 1 -> 2 workers = run wall with 1 / run wall with 2.

The target is at most 20 s for the 100 scenes on this 2-core machine (start-up included).

Issue 27 (a sweep costs what its integrations cost) adds two measurements on the issue's own
sweep, ``gearwear sweep paper-default --set operating.speed_rpm=1000:3000:100`` (100 scenes
of 0.5 s simulated, 0.3 s discarded, RK4):

* split: the cost of one point phase by phase, in-process (benchmarks/sweep_split.py:
  scene validation, stiffness table, model build, integration, the rest of the
  simulation, exact harmonics and means, condition indicators, the rest of the summary,
  transport), each point's minimum over 2 passes, averaged over every 5th point; the
  target is overhead (everything but the integration) <= the integration;
* command: the wall time of the whole command (process start to exit, files written)
  with 1 and 2 workers, the minimum of 2 runs after a warm-up run (numba's disk cache
  warm); the target is <= 4 s with 2 workers.

``--only split,command`` skips the executor comparison above (minutes on a busy machine).
Writes benchmarks/results/bench_sweep_scale.json.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
for p in (str(ROOT), str(HERE)):
    if p not in sys.path:
        sys.path.insert(0, p)

from gearwear.jobs.sweep import make_executor, parse_axis, sweep  # noqa: E402
from gearwear.scene.files import load_scene_dict  # noqa: E402

N_SCENES = 100
FIXED = ["solver.duration_s=1.0", "solver.discard_s=0.3"]


def warm() -> float:
    """One short simulation in the worker: imports and kernels loaded before timing."""
    from gearwear.jobs.simulate import run
    from gearwear.scene.model import scene_from_dict

    data, name = load_scene_dict("paper-default")
    t0 = time.perf_counter()
    run(scene_from_dict({**data, "solver": {"duration_s": 0.01, "discard_s": 0.0}}, name=name))
    return time.perf_counter() - t0


def executor(kind: str, workers: int):
    """The executors ``gearwear sweep --workers N`` and ``--scheduler local:N`` use."""
    return make_executor(workers) if kind == "processes" else make_executor(scheduler=f"local:{workers}")


def measure(kind: str, workers: int) -> dict:
    data, name = load_scene_dict("paper-default")
    axes = [parse_axis(f"operating.torque_Nm=20:40:{N_SCENES}")]
    t0 = time.perf_counter()
    ex = executor(kind, workers)
    try:
        for f in [ex.submit(warm) for _ in range(2 * workers)]:
            f.result()
        t1 = time.perf_counter()
        rows = sweep(data, name, axes, FIXED, executor=ex, progress=False)
        t2 = time.perf_counter()
    finally:
        ex.shutdown()
    integ = sum(r["integration_wall_s"] for r in rows)
    run = t2 - t1
    return {
        "executor": kind,
        "workers": workers,
        "startup_s": t1 - t0,
        "run_s": run,
        "total_s": t2 - t0,
        "integration_s": integ,
        "overhead_per_scene_ms": 1e3 * (run * workers - integ) / N_SCENES,
        "scenes": len(rows),
    }


#: the sweep of issue 27
SPEEDS = "operating.speed_rpm=1000:3000:100"


def split() -> dict:
    """Per-point phases of the issue's sweep, in-process, with one BLAS thread as in a worker."""
    from sweep_split import grid_split
    from threadpoolctl import threadpool_limits

    from gearwear.jobs.sweep import grid

    threadpool_limits(limits=1, user_api="blas")
    warm()
    data, name = load_scene_dict("paper-default")
    points = grid([parse_axis(SPEEDS)])[::5]
    return grid_split(data, name, points, [], repeats=2)


def command(workers: int, runs: int = 2) -> float:
    """Minimum wall time (s) of the whole ``gearwear sweep`` command over ``runs``."""
    exe = Path(sys.executable).with_name("gearwear")
    best = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(runs):
            out = Path(tmp) / f"run{i}"
            cmd = [str(exe), "sweep", "paper-default", "--set", SPEEDS, "--out", str(out), "--workers", str(workers)]
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            best = min(best, time.perf_counter() - t0)
            shutil.rmtree(out, ignore_errors=True)
    return best


def issue27() -> dict:
    """The split per scene and the whole command's time (1 and 2 workers), printed."""
    exe = Path(sys.executable).with_name("gearwear")
    with tempfile.TemporaryDirectory() as tmp:  # the kernels into numba's disk cache first
        subprocess.run(
            [str(exe), "sweep", "paper-default", "--set", "operating.speed_rpm=1000:3000:3", "--out", f"{tmp}/w"],
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    ms = split()
    print(f"gearwear sweep paper-default --set {SPEEDS}: one point in-process (ms, mean over every 5th point)")
    for k, v in ms.items():
        print(f"  {k:<14}{v:>9.2f}")
    print(f"  overhead / integration = {ms['overhead'] / ms['integration']:.2f} (target <= 1)")
    cmd = {str(w): command(w) for w in (1, 2)}
    for w, t in cmd.items():
        print(f"  whole command, {w} worker(s), numba cache warm: {t:.2f} s (target <= 4 s with 2)")
    return {"sweep": f"paper-default --set {SPEEDS}", "split_ms": ms, "command_s": cmd, "numba_cache": "warm"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="executors,split,command", help="comma-separated: executors, split, command")
    only = set(ap.parse_args().only.split(","))
    out = HERE / "results" / "bench_sweep_scale.json"
    old = json.loads(out.read_text()) if out.exists() else {}
    record: dict = {
        **old,
        "date": datetime.date.today().isoformat(),
        "machine": platform.platform(),
        "cores": os.cpu_count(),
        "load_average_at_start": os.getloadavg()[0],
    }
    if only & {"split", "command"}:
        record["issue27"] = issue27()
    if "executors" in only:
        record.update(executors())
        record["executors_measured"] = record["date"]
    else:  # the executor comparison kept from its own run, with its own date
        record["executors_measured"] = old.get("executors_measured", old.get("date"))
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(record, indent=2) + "\n")
    print(f"wrote {out.relative_to(ROOT)}")


def executors() -> dict:
    """The executor comparison (start-up, run, overhead per scene) of the module docstring."""
    try:
        import dask.distributed  # noqa: F401

        kinds = ["processes", "dask"]
    except ImportError:
        print("dask.distributed not installed: only the process pool is measured (pip install 'gearwear[dask]')")
        kinds = ["processes"]
    res = [measure(k, w) for k in kinds for w in (1, 2)]
    print(
        f"{N_SCENES} scenes of 1 s simulated (paper-default, RK4 256 steps/period), this machine "
        f"({os.cpu_count()} cores)"
    )
    print(
        f"{'executor':<10}{'workers':>8}{'start-up s':>12}{'run s':>8}{'total s':>9}{'integration s':>15}"
        f"{'overhead/scene ms':>19}"
    )
    for r in res:
        print(
            f"{r['executor']:<10}{r['workers']:>8}{r['startup_s']:>12.2f}{r['run_s']:>8.2f}{r['total_s']:>9.2f}"
            f"{r['integration_s']:>15.2f}{r['overhead_per_scene_ms']:>19.1f}"
        )
    for k in kinds:
        one, two = (next(r for r in res if r["executor"] == k and r["workers"] == w) for w in (1, 2))
        print(
            f"{k}: 1 -> 2 workers speed-up {one['run_s'] / two['run_s']:.2f} (run), "
            f"{one['total_s'] / two['total_s']:.2f} (with start-up)"
        )
    return {"scenes": N_SCENES, "results": res}


if __name__ == "__main__":
    main()
