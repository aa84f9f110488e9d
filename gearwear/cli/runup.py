"""``gearwear runup``: speed run-up/down with natural continuation."""

from __future__ import annotations

import argparse
import math
import time

from gearwear import io
from gearwear.cli.common import (
    alias_sets,
    bounded_float,
    check_out,
    int_arg,
    output_options,
    pool_options,
    scene_options,
    worker_count,
    write_output,
)


def runup_directions() -> tuple[str, ...]:
    from gearwear.jobs import RUNUP_DIRECTIONS

    return RUNUP_DIRECTIONS


def run(args: argparse.Namespace) -> int:

    from gearwear.jobs import runup as runup_job
    from gearwear.jobs import sweep
    from gearwear.scene.files import load_scene_dict
    from gearwear.scene.model import require_dynamics, scene_from_dict
    from gearwear.scene.overrides import apply_overrides

    data, name = load_scene_dict(args.scene, default="paper-default")
    out = check_out(args.out, "runup")
    axes, fixed = sweep.split_sets(alias_sets(args))
    require_dynamics(scene_from_dict(apply_overrides(data, fixed), name=name))  # the fixed keys are checked first
    speed, others = runup_job.split_speed_axis(axes)
    sweep.check_size(
        len(speed.values) * math.prod(len(a.values) for a in others) * (2 if args.direction == "both" else 1),
        "runs (speeds x points x directions)",
        args.allow_large,
    )
    settings = runup_job.Settings(
        tol=bounded_float("--tolerance", args.tolerance, "", 1e-12, 1e-2),
        max_periods=int_arg("--max-periods", args.max_periods, 2, 1_000_000),
        keep_periods=int_arg("--keep-periods", args.keep_periods, 1, 100_000),
        jump_tol=bounded_float("--jump-tolerance", args.jump_tolerance, "", 1e-9, 1.0),
    )
    workers = worker_count(args)
    t0 = time.perf_counter()
    points, chains = runup_job.plan(data, name, speed, others, fixed, args.direction)
    with sweep.make_executor(workers, args.scheduler) as executor:
        runup_job.run(points, chains, settings, executor, progress=not args.json)
    wall = time.perf_counter() - t0
    summ = runup_job.summary(points, chains, speed, others, settings)
    base = points[0].scene
    inputs = {
        **io.scene_inputs(base),
        "speeds_rpm": list(speed.values),
        "axes": {a.key: list(a.values) for a in others},
        "direction": args.direction,
        "settings": settings.__dict__,
    }
    labels = {**io.scene_labels(base), "fixed": fixed}
    files = write_output(
        out,
        "runup",
        base,
        {**inputs, "fixed": fixed},
        lambda d: runup_job.write(points, chains, speed, others, summ, d, inputs, labels),
        {
            "total_s": wall,
            "chains": [
                {
                    "point": points[c.point_index].values,
                    "direction": c.direction,
                    "integration_s": sum(r["integration_wall_s"] for r in c.rows),
                }
                for c in chains
            ],
        },
    )
    summ["files"] = [str(f) for f in files]
    summ["wall_s"] = wall
    if args.json:
        print(io.json_text(summ, indent=None))
    else:
        for p in summ["points"]:
            iso = p["iso6336"]
            at_driver = (
                ""
                if iso["n_E1_driver_rpm"] == iso["n_E1_rpm"]
                else f" of ISO's gear 1 ({iso['inputs']['z1']} teeth), {iso['n_E1_driver_rpm']:.0f} rpm at the driver"
            )
            print(
                f"point {p['point'] or '-'}: ISO 6336 n_E1 = {iso['n_E1_rpm']:.0f} rpm{at_driver}; linear modes "
                f"{', '.join(f'{f:.1f}' for f in p['linear_eigenfrequencies_Hz'])} Hz"
            )
            for d, r in p["directions"].items():
                print(
                    f"  sweep {d}: K_v max {r['K_v_max']:.4f} at {r['K_v_max_speed_rpm']:g} rpm; "
                    f"{', '.join(f'{k} {v}' for k, v in sorted(r['labels'].items()))}"
                )
            if "jump_bands_rpm" in p:
                bands = "; ".join(f"{lo:g}-{hi:g} rpm" for lo, hi in p["jump_bands_rpm"]) or "none"
                print(f"  jump bands (up and down K_v differ by > {settings.jump_tol:g}): {bands}")
        print(f"wall time {wall:.1f} s")
        for f in files:
            print(f"wrote {f}")
    return 0


def add_parser(sub) -> None:
    """The ``runup`` sub-command's arguments."""
    ru = sub.add_parser(
        "runup",
        help="speed run-up/down with natural continuation: K_v, jumps, ISO 6336 K_v",
        description="Run a scene over a speed range, each speed starting from the steady state of "
        "the previous one: --set operating.speed_rpm=START:STOP:N (other swept keys give "
        "independent run-ups). Steady state is detected (Poincare-section residual) and "
        "labelled periodic, quasi-periodic or chaotic. Writes runup.csv (K_v, DTE, "
        "contact loss, harmonics 1-10 per speed), runup_summary.json (jump bands, ISO "
        "6336-1 n_E1), the K_v plot, the order maps and the Campbell diagrams.",
    )
    scene_options(ru, "paper-default")
    ru.add_argument(
        "--direction",
        default="both",
        choices=runup_directions(),
        help="sweep up, down or both (default both: the jump band is where they differ)",
    )
    ru.add_argument(
        "--tolerance",
        default="1e-6",
        help="periodicity tolerance of the steady state: estimated "
        "distance of the Poincare section from the periodic orbit, relative to the motion's range "
        "(default 1e-6)",
    )
    ru.add_argument(
        "--max-periods",
        default="1500",
        help="table periods integrated at most per speed before the "
        "kept window (default 1500); not settled by then: quasi-periodic, chaotic or unsettled",
    )
    ru.add_argument(
        "--keep-periods",
        default="32",
        help="table periods in the kept window the metrics come from "
        "(default 32, rounded up to a multiple of the period found)",
    )
    ru.add_argument(
        "--jump-tolerance",
        default="0.01",
        help="up and down K_v differing by more than this fraction mark a jump band (default 0.01)",
    )
    pool_options(ru)
    output_options(ru, "output folder", "print one JSON object (the summary)")
    ru.set_defaults(func=run)
