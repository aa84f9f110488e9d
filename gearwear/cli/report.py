"""``gearwear report``: one page of a user's pair (``report pair``) or the paper's (``report paper``)."""

from __future__ import annotations

import argparse
import sys
import time

from gearwear import io
from gearwear.cli.common import check_out, load_scene, pair_inputs, print_assumed, scene_options, write_output
from gearwear.core.validation import InputError


def run(args: argparse.Namespace) -> int:
    from gearwear.reports import paper as report_paper

    if args.which == "pair":
        return run_pair(args)
    if args.which != "paper":
        raise InputError(f"report {args.which!r}: unknown (available: paper, pair)")
    if args.scene is not None or args.set:
        given = args.scene if args.scene is not None else f"--set {args.set[0]}"
        raise InputError(
            f"report paper: {given}: the paper report takes no scene or --set (it is the paper's "
            "pair); gearwear report pair SCENE reports your own"
        )
    out = check_out(args.out, "report paper")
    assert out is not None
    files = report_paper.run_report(out, progress=True)
    for f in files:
        print(f"wrote {f}")
    return 0


def run_pair(args: argparse.Namespace) -> int:
    """report pair SCENE: everything is validated (scene, --out, the bearing stiffness, the
    run-up's speeds) before any computation; then one progress bar over the parts."""

    from tqdm import tqdm

    from gearwear.jobs import sweep as sweep_job
    from gearwear.reports import pair as report_pair

    scene = load_scene(args)
    report_pair.check_scene(scene)
    out = check_out(args.out, "report pair")
    t0 = time.perf_counter()
    settings = report_pair.SETTINGS
    prep = report_pair.prepare(scene, settings)
    steps = [*report_pair.PARTS, "figures"]
    with (
        tqdm(total=len(steps), desc="report pair", unit="part", file=sys.stderr) as bar,
        sweep_job.make_executor(1) as executor,
    ):

        def step(name: str) -> None:
            bar.n = steps.index(name)
            bar.set_postfix_str(name)

        def fe_progress(done: int, total: int) -> None:
            bar.set_postfix_str(f"pair FE position {done}/{total}")

        rep = report_pair.compute(prep, executor, step, fe_progress)
        doc = report_pair.document(rep)
        step("figures")
        inputs = {**io.scene_inputs(scene), "pair": pair_inputs(scene), "settings": doc["settings"]}
        wall = report_pair.timing(rep)
        files = write_output(
            out,
            "report pair",
            scene,
            inputs,
            lambda d: report_pair.write(doc, d),
            {**wall, "total_s": time.perf_counter() - t0},
        )
        bar.n = len(steps)
        bar.refresh()
    print_pair(doc, wall)
    for f in files:
        print(f"wrote {f}")
    return 0


def print_pair(doc: dict, wall: dict) -> None:
    from gearwear.reports import pair as report_pair

    print(f"{'method':<24}{'mean N/m':>12}{'vs FE %':>9}{'STE p-p um':>12}{'wall s':>9}")
    for r in doc["stiffness"]:
        vs = f"{'ref':>9}" if r["method"] == report_pair.REFERENCE else f"{r['mean_vs_fe_pct']:>+9.1f}"
        print(
            f"{r['label'].split(' (')[0]:<24}{r['mean_N_per_m']:>12.4e}{vs}"
            f"{r['ste_peak_to_peak_um']:>12.3f}{wall.get('stiffness ' + r['method'] + ' s', float('nan')):>9.2f}"
        )
    ru = doc["runup"]
    print(
        f"run-up {ru['speeds_rpm'][0]:.0f}-{ru['speeds_rpm'][-1]:.0f} rpm ({len(ru['speeds_rpm'])} speeds, up): "
        f"K_v max {ru['K_v_max']:.4f} at {ru['K_v_max_speed_rpm']:.0f} rpm; ISO 6336 n_E1 "
        f"{ru['iso6336']['n_E1_driver_rpm']:.0f} rpm (driver), ISO K_v max {ru['K_v_iso_max']:.4f}"
    )
    print(f"wall time {wall['computation s']:.1f} s (computation)")
    print_assumed(doc["assumptions"])
    for w in doc["warnings"]:
        print(f"warning: {w}")


def add_parser(sub) -> None:
    """The ``report`` sub-command's arguments."""
    rp = sub.add_parser(
        "report",
        help="a one-page report of your gear pair (report pair SCENE), or the paper's "
        "figures with a trends table (report paper)",
        description="report pair SCENE: a one-page report of your own pair (README.md, report.json "
        "and PNGs): the geometry of both gears and the mesh, the mesh stiffness by every "
        "method including the pair FE, the loaded transmission error against load, a "
        "run-up around ISO 6336's resonance with ISO's K_v next to it, and every value "
        "assumed (~30 s; needs bodies.bearing_stiffness_N_per_m). "
        "report paper: every numerical figure of Zhang et al. (2019) regenerated with "
        "FE-calibrated stiffness and the 6-DOF model, with a table comparing each of the "
        "paper's trend claims with this tool's result (a few minutes).",
    )
    rp.add_argument("which", choices=["paper", "pair"], help="which report")
    scene_options(rp, "paper-default; report pair only", aliases=())
    rp.add_argument(
        "--out", required=True, help="output folder (the repository's copy of report paper is reports/paper)"
    )
    rp.set_defaults(func=run)
