"""``gearwear sweep``: a scene over a parameter grid, in parallel."""

from __future__ import annotations

import argparse
import math

from gearwear import io
from gearwear.cli.common import (
    alias_sets,
    check_out,
    output_options,
    pool_options,
    scene_options,
    worker_count,
    write_output,
)
from gearwear.core.validation import InputError


def run(args: argparse.Namespace) -> int:
    from gearwear.jobs import sweep
    from gearwear.scene.files import load_scene_dict
    from gearwear.scene.model import require_dynamics

    data, name = load_scene_dict(args.scene, default="paper-wear-severe")
    out = check_out(args.out, "sweep")
    axes, fixed = sweep.split_sets(alias_sets(args))
    from gearwear.scene.model import scene_from_dict
    from gearwear.scene.overrides import apply_overrides

    require_dynamics(scene_from_dict(apply_overrides(data, fixed), name=name))  # the fixed keys are checked first
    if not axes:
        raise InputError("--set: give at least one swept key, KEY=START:STOP:N or KEY=a,b,c")
    sweep.check_size(math.prod(len(a.values) for a in axes), "grid points", args.allow_large)
    base = scene_from_dict(apply_overrides(data, fixed), name=name)  # the scene every point starts from
    inputs = {**io.scene_inputs(base), "axes": {a.key: list(a.values) for a in axes}}
    labels = {**io.scene_labels(base), "fixed": fixed}
    # the files are written while the workers are still up: they render the figures
    with sweep.make_executor(worker_count(args), args.scheduler) as executor:
        results = sweep.sweep(
            data, name, axes, fixed, executor=executor, progress=not args.json, warm_figures_after=out is not None
        )
        files = write_output(
            out,
            "sweep",
            base,
            {**inputs, "fixed": fixed},
            lambda d: sweep.write(axes, results, d, inputs, labels, executor=executor),
            {"points": [{"point": r["point"], "wall_s": r["wall_s"]} for r in results]},
        )
    if args.json:
        print(io.json_text({"points": results, "files": [str(f) for f in files]}, indent=None))
    else:
        print(sweep.table_csv(axes, results).splitlines()[0][:200])
        for r in results:
            pt = ", ".join(f"{k}={v}" for k, v in r["point"].items())
            fm = r["harmonics"].get("F_m_N")
            extra = f"  F_m harmonics 1-4 (N): {', '.join(f'{x:.3g}' for x in fm[:4])}" if fm else ""
            sep = r["separation_fraction"]
            contact = (
                f"no backlash: cannot separate, back flanks loaded {100 * r['backside_fraction']:.2f} %"
                if sep is None
                else f"separation {100 * sep:.2f} %"
            )
            print(f"{pt}: {contact}{extra}")
        for f in files:
            print(f"wrote {f}")
    return 0


def add_parser(sub) -> None:
    """The ``sweep`` sub-command's arguments."""
    sw = sub.add_parser(
        "sweep",
        help="run a scene over a parameter grid in parallel (harmonics vs parameter)",
        description="Sweep scene keys: --set KEY=START:STOP:N (linear) or KEY=a,b,c (values); "
        "KEY=VALUE fixes a key. Runs the grid on local cores (or a Dask cluster) with "
        "a progress bar and writes sweep.csv (metrics and harmonic amplitudes per "
        "point) and harmonics-versus-parameter PNGs (paper Figs. 8-14, 19-25).",
    )
    scene_options(sw, "paper-wear-severe")
    pool_options(sw)
    output_options(sw)
    sw.set_defaults(func=run)
