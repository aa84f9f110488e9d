"""``gearwear simulate``: the 6-DOF dynamics of a scene."""

from __future__ import annotations

import argparse
import sys

from gearwear import io
from gearwear.cli.common import check_out, load_scene, output_options, scene_options, write_output


def run(args: argparse.Namespace) -> int:
    from gearwear.jobs import simulate as simulate_job
    from gearwear.jobs import simulate_io
    from gearwear.scene.model import require_dynamics

    scene = load_scene(args, default="paper-wear-severe")
    require_dynamics(scene)
    out = check_out(args.out, "simulate")
    run = simulate_job.run(scene, on_compile=lambda msg: print(msg, file=sys.stderr, flush=True))
    summary = run.summary()
    inputs = io.scene_inputs(scene)
    files = write_output(
        out,
        "simulate",
        scene,
        inputs,
        lambda d: simulate_io.write(run, d, inputs, io.scene_labels(scene)),
        {
            "total_s": summary["wall_s"],
            "integration_s": summary["integration_wall_s"],
            "compile_s": summary["compile_s"],
        },
    )
    summary["files"] = [str(f) for f in files]
    if args.json:
        print(io.json_text(summary, indent=None))
    else:
        simulate_io.print_summary(summary)
    return 0


def add_parser(sub) -> None:
    """The ``simulate`` sub-command's arguments."""
    sm = sub.add_parser(
        "simulate",
        help="6-DOF gear-pair dynamics of a scene (only the effects it names)",
        description="Simulate the bending-torsion gear-pair model (paper Eqs. 17-20, typos fixed) "
        "with the effects the scene names. Without a scene: the paper's severe-wear "
        "case with 10 um bearing clearance (built-in scene paper-wear-severe). Writes "
        "signals (NPZ + CSV), time-trace and spectrum PNGs and summary.json.",
    )
    scene_options(sm, "paper-wear-severe")
    output_options(sm)
    sm.set_defaults(func=run)
