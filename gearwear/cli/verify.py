"""``gearwear verify``: FE single-tooth compliance against the analytic models, FE convergence."""

from __future__ import annotations

import argparse
import sys

from gearwear import io
from gearwear.cli.common import (
    assumptions_of,
    check_out,
    fem_plane,
    int_arg,
    output_options,
    pair_inputs,
    print_assumed,
    scene_options,
    unworn_as_none,
    variants,
    wear_dict,
    write_output,
)


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from gearwear.jobs import verify as verify_job

    if not args.wear:
        args.wear = ["unworn", "mild", "severe"]
    scene, wears, _ = variants(args)
    wears = unworn_as_none(wears)
    assumed = assumptions_of(scene, "verify")
    positions = int_arg("--positions", args.positions, 5, 201)
    out = check_out(args.out, "verify")
    steps = len(wears) + (0 if args.no_convergence else 12)
    with tqdm(total=steps, desc="verify", unit="run", disable=args.json or None, file=sys.stderr) as bar:

        def progress(msg):
            bar.set_postfix_str(msg)
            bar.update(1)

        v = verify_job.run(
            scene.pair,
            wears,
            positions,
            convergence=not args.no_convergence,
            progress=progress,
            plane=fem_plane(scene.doc, True, "gearwear verify"),
        )
    inputs = {
        **io.scene_inputs(scene),
        "pair": pair_inputs(scene),
        "wear": [w.label if w else "unworn" for w in wears],
        "wear_spec": [wear_dict(w) for w in wears],
        "positions": positions,
        "convergence": not args.no_convergence,
    }
    timing = {
        "total_s": v.wall_s,
        "phases": {
            ph.label: {"fem_s": ph.fem_wall_s, "ishikawa_s": ph.ishikawa_wall_s, "energy_s": ph.energy_wall_s}
            for ph in v.phases
        },
        "convergence": [{k: r.get(k) for k in ("order", "mesh_scale", "dofs", "wall_s")} for r in v.convergence or []],
    }
    files = write_output(
        out, "verify", scene, inputs, lambda d: verify_job.write(v, d, inputs, io.scene_labels(scene)), timing
    )
    js = verify_job.to_json(v)
    js["assumptions"] = assumed
    js["files"] = [str(f) for f in files]
    if args.json:
        print(io.json_text(js, indent=None))
    else:
        print(f"{'wear':<9}{'FE s':>7}{'dofs':>9}{'Ishikawa-FE % (min..max)':>28}{'energy-FE % (min..max)':>26}")
        for ph in v.phases:
            di = 100 * (ph.ishikawa / ph.fem - 1)
            de = 100 * (ph.energy / ph.fem - 1)
            print(
                f"{ph.label:<9}{ph.fem_wall_s:>7.2f}{ph.dofs:>9}{di.min():>14.1f} .. {di.max():<11.1f}"
                f"{de.min():>12.1f} .. {de.max():<11.1f}"
            )
        print_assumed(assumed)
        if v.acceptance:
            a = v.acceptance
            print(
                f"FE convergence: two finest P2 levels differ by {a['finest_p2_change_pct']:.3f} %, default level "
                f"{a['default_dofs']} dofs in {a['default_wall_s']:.2f} s"
            )
        for f in files:
            print(f"wrote {f}")
    return 0


def add_parser(sub) -> None:
    """The ``verify`` sub-command's arguments."""
    v = sub.add_parser(
        "verify",
        help="analytic (Ishikawa, energy) vs FE tooth compliance, FE convergence",
        description="FE single-tooth compliance on the full gear (bore fixed, plane stress, P2) "
        "at load positions from SAP to tip, against Ishikawa delta_1 + delta_2 and the "
        "energy method, per wear phase; h/p convergence with Richardson extrapolation. "
        "Writes verification.md, compliance.png, convergence.png, verification.json.",
    )
    scene_options(v, "paper-default", multi=True, aliases=("wear", "torque"))
    v.add_argument("--positions", default="21", help="load positions from SAP to tip (default 21)")
    v.add_argument("--no-convergence", action="store_true", help="skip the h/p convergence study (~1-3 min)")
    output_options(v)
    v.set_defaults(func=run)
