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
