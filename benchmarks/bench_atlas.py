"""The atlas's cost per design over the design space (issue 28): the pair FE and the analytic
models of gearwear.jobs.atlas.run_design at the corners of the space, each in its own process
(CPU time, wall time and peak memory of that process), as ratios to a reference design
measured in the same run (the machine is shared: the ratios are the result, the absolute
times are loaded).

Corners (module 3 mm, face width 30 mm, 200 N/mm unless named): the reference 23/47
(x +0.2/-0.1, rim s_R/m = 4), 14 teeth (14/28), 100 teeth at ratio 5 (100/500) with rims
of 4 m and 12 m (the atlas's thickest) and with a solid blank (bores 0.2 r_f), a thin rim
(s_R/m = 1.5), 25 deg, and a high contact ratio (h_a* 1.3, epsilon > 2); FE settings as the
atlas's defaults (24 positions, mesh scale 1, transitions bisected) unless --coarse.

    .venv/bin/python benchmarks/bench_atlas.py [--coarse] [--only NAME ...]
    .venv/bin/python benchmarks/bench_atlas.py --overhead 500

writes benchmarks/results/bench_atlas.json (bench_atlas_overhead.json: the engine's own cost per
design, the curves replaced by a constant, cold cache and warm).
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import subprocess
import sys
import time
from pathlib import Path

RESULTS = Path(__file__).parent / "results" / "bench_atlas.json"


def corner(name: str):
    """(Design, note) of a named corner."""
    from gearwear.geometry.spec import PairSpec
    from gearwear.jobs.atlas_space import Design

    m, b, w = 3e-3, 30e-3, 200.0
    kw: dict = dict(module_m=m, face_width_m=b)
    rim = 4.0
    solid = False
    if name == "reference_23_47":
        kw.update(teeth=(23, 47), profile_shift=(0.2, -0.1))
    elif name == "z14":
        kw.update(teeth=(14, 28), profile_shift=(0.3, 0.0))
    elif name == "z100_ratio5_rim4":
        kw.update(teeth=(100, 500))
    elif name == "z100_ratio5_rim12":
        kw.update(teeth=(100, 500))
        rim = 12.0
    elif name == "z100_ratio5_solid":
        kw.update(teeth=(100, 500))
        solid = True
    elif name == "thin_rim_1.5":
        kw.update(teeth=(30, 60), profile_shift=(0.1, 0.0))
        rim = 1.5
    elif name == "alpha25":
        kw.update(
            teeth=(20, 40),
            pressure_angle_rad=math.radians(25),
            rack_tip_radius_coefficient=0.25,
            profile_shift=(0.2, 0),
        )
    elif name == "high_contact":
        kw.update(teeth=(40, 80), addendum_coefficient=1.3, dedendum_coefficient=1.55, rack_tip_radius_coefficient=0.25)
    else:
        raise SystemExit(f"unknown corner {name}")
    p = PairSpec(**kw)
    roots = [g.root_radius_m for g in p.gears]
    bores = tuple(0.2 * r if solid else max(r - rim * m, 0.2 * r) for r in roots)
    p = PairSpec(**{**kw, "hub_radius_m": bores})
    return Design(0, p, w * 1e3 * b * p.gear(0).base_radius_m, w, rim if not solid else math.nan)


CORNERS = (
    "reference_23_47",
    "z14",
    "thin_rim_1.5",
    "alpha25",
    "high_contact",
    "z100_ratio5_rim4",
    "z100_ratio5_rim12",
    "z100_ratio5_solid",
)


def one(name: str, coarse: bool) -> dict:
    """Run one corner in this process: run_design with the atlas's default models."""
    from gearwear.geometry.design_space import contact_ratio, rejection
    from gearwear.jobs.atlas import run_design
    from gearwear.jobs.atlas_spec import parse

    d = corner(name)
    why = rejection(d.pair)
    spec = parse({"fe": {"positions": 8, "mesh_scale": 2.0, "transitions": False}} if coarse else {})
    settings = {
        "positions": spec["fe.positions"],
        "mesh_scale": spec["fe.mesh_scale"],
        "contact_scale": spec["fe.contact_scale"],
        "plane": spec["fe.plane"],
        "transitions": spec["fe.transitions"],
        "points": spec["analytic.points"],
    }
    c0, t0 = time.process_time(), time.perf_counter()
    r = run_design(d, settings, spec.models, True)
    if not r["fe_info"]:  # the FE refused or failed on the corner: its one-line note is the result
        raise RuntimeError(f"the pair FE gave no curve ({r['metrics']['fem'].get('note', '?')})")
    return {
        "corner": name,
        "teeth": list(d.pair.teeth),
        "contact_ratio": contact_ratio(d.pair),
        "rejection": why,
        "cpu_s": time.process_time() - c0,
        "wall_s": time.perf_counter() - t0,
        "fe_cpu_s": r["times"]["fe"]["cpu_s"],
        "fe_wall_s": r["times"]["fe"]["wall_s"],
        "analytic_cpu_s": sum(v["cpu_s"] for k, v in r["times"].items() if k not in ("fe", "design")),
        "max_rss_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "ndofs": r["fe_info"]["ndofs"],
        "fem_mean_N_per_m": r["metrics"]["fem"]["mean_N_per_m"],
        "fem_bore_fixed_mean_N_per_m": r["metrics"]["fem_bore_fixed"]["mean_N_per_m"],
    }


def _no_work(design, settings, models, fe):
    """run_design's result shape without the curves (the engine's own cost alone)."""
    from gearwear.jobs.atlas_metrics import METRICS

    zero = {m: 1.0 for m in METRICS}
    names = list(models) + (["fem", "fem_bore_fixed"] if fe else [])
    return {"metrics": {n: zero for n in names}, "times": {"design": {"wall_s": 0.0}}, "fe_info": {}}


def overhead(designs: int) -> dict:
    """The engine's own cost per design: the default SPEC's designs through compute() on a local
    pool of 2 with run_design replaced by :func:`_no_work` (forked workers inherit the
    replacement), into an empty cache (cold: every entry written) and again (warm: every design
    read from the cache, nothing submitted)."""
    import tempfile

    from gearwear.jobs import atlas
    from gearwear.jobs.atlas_space import design_space
    from gearwear.jobs.atlas_spec import parse
    from gearwear.jobs.sweep import make_executor

    spec = parse({"designs": designs})
    t0 = time.perf_counter()
    space = design_space(spec.values)
    t_space = time.perf_counter() - t0
    atlas.run_design = _no_work  # type: ignore[assignment]
    out = {"designs": designs, "points_drawn": space.drawn, "design_space_s": t_space}
    with tempfile.TemporaryDirectory() as tmp:
        for phase in ("cold", "warm"):
            with make_executor(2) as ex:
                t0 = time.perf_counter()
                atlas.compute(spec, space, ex, progress=False, cache=Path(tmp))
                out[f"{phase}_s"] = time.perf_counter() - t0
            out[f"{phase}_ms_per_design"] = 1e3 * out[f"{phase}_s"] / designs
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--coarse", action="store_true", help="8 positions, mesh scale 2, no bisection")
    ap.add_argument("--only", nargs="+", default=list(CORNERS))
    ap.add_argument("--one", help=argparse.SUPPRESS)
    ap.add_argument("--overhead", type=int, metavar="N", help="only the engine's cost per design on N designs")
    args = ap.parse_args()
    if args.overhead:
        res = overhead(args.overhead)
        print(json.dumps(res))
        RESULTS.parent.mkdir(exist_ok=True)
        RESULTS.with_name("bench_atlas_overhead.json").write_text(json.dumps(res, indent=1) + "\n")
        return
    if args.one:
        print(json.dumps(one(args.one, args.coarse)))
        return
    rows = []
    for name in args.only:
        t0 = time.perf_counter()
        cmd = [sys.executable, __file__, "--one", name] + (["--coarse"] if args.coarse else [])
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            row = {"corner": name, "error": (p.stderr.strip().splitlines() or ["?"])[-1]}
        else:
            row = json.loads(p.stdout.strip().splitlines()[-1])
        row["process_wall_s"] = time.perf_counter() - t0
        rows.append(row)
        print(json.dumps(row), flush=True)
    ref = next((r for r in rows if r["corner"] == "reference_23_47" and "cpu_s" in r), None)
    for r in rows:
        if ref is not None and "cpu_s" in r:
            r["fe_cpu_ratio_to_reference"] = r["fe_cpu_s"] / ref["fe_cpu_s"]
    out = {"coarse": args.coarse, "rows": rows}
    RESULTS.parent.mkdir(exist_ok=True)
    name = RESULTS if not args.coarse else RESULTS.with_name("bench_atlas_coarse.json")
    name.write_text(json.dumps(out, indent=1) + "\n")
    print(
        f"{'corner':22s} {'teeth':>9s} {'eps':>5s} {'FE cpu s':>9s} {'ratio':>6s} {'an. cpu s':>9s} {'RSS MB':>7s} dofs"
    )
    for r in rows:
        if "cpu_s" not in r:
            print(f"{r['corner']:22s} error: {r['error']}")
            continue
        print(
            f"{r['corner']:22s} {str(r['teeth']):>9s} {r['contact_ratio']:5.2f} {r['fe_cpu_s']:9.1f} "
            f"{r.get('fe_cpu_ratio_to_reference', math.nan):6.2f} {r['analytic_cpu_s']:9.2f} {r['max_rss_MB']:7.0f} "
            f"{r['ndofs']}"
        )


if __name__ == "__main__":
    main()
