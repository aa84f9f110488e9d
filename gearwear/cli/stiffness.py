"""``gearwear stiffness``: mesh stiffness curves of one or more sources (stiffness.sources)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from gearwear import io
from gearwear.analytic import TABLE_POINTS_PER_MESH_PERIOD as TABLE_POINTS
from gearwear.cli.common import (
    assumptions_of,
    check_out,
    fem_plane,
    int_arg,
    num_or_dash,
    pair_inputs,
    print_assumed,
    scene_options,
    split_multi,
    variants,
    write_output,
)
from gearwear.core.validation import InputError
from gearwear.stiffness.sources import METHODS, SOURCES


def run(args: argparse.Namespace) -> int:

    from tqdm import tqdm

    from gearwear.geometry.faults import revolution_periods
    from gearwear.jobs import stiffness as stiffness_job

    methods = list(dict.fromkeys(split_multi(args.method)))  # several methods: overlaid
    for m in methods:
        if m not in METHODS:
            raise InputError(f"--method = {m!r}: must be one or more of {', '.join(METHODS)}")
    scene, wears, clearances = variants(args)
    uses = "stiffness-fem" if "fem" in methods else "stiffness-iso" if set(methods) == {"iso6336"} else "stiffness"
    plane = fem_plane(
        scene.doc, any(m != "iso6336" for m in methods), f"gearwear stiffness --method {' '.join(methods)}"
    )
    assumed = assumptions_of(scene, uses)
    torque = scene.operating.torque_Nm
    # default angles per method: the FE's 24 positions take ~10 s, the analytic tables take ms
    points = {
        m: int_arg("--points", args.points if args.points is not None else str(SOURCES[m].default_points), 8, 1_000_000)
        for m in methods
    }
    out = check_out(args.out, "stiffness")
    fields = []
    if args.fields:
        if methods != ["fem"] or not args.out:
            raise InputError(f"--fields = {','.join(split_multi(args.fields))}: needs --method fem (alone) and --out")
        # with a fault the FE curve spans one revolution of the faulty gear
        rows = points["fem"] * revolution_periods(scene.pair, scene.faults)
        fields = [int_arg("--fields", f, 0, rows - 1) for f in split_multi(args.fields)]
    for m in methods:
        stiffness_job.check_method(m, scene.flank, scene.faults)  # every method refused before any work
    curves = []
    with tqdm(
        desc="pair FE positions", unit="position", disable=args.json or "fem" not in methods or None, file=sys.stderr
    ) as bar:

        def progress(done: int, total: int) -> None:  # only the pair FE reports progress
            bar.total = total
            bar.n = done
            bar.refresh()

        for m in methods:
            curves += stiffness_job.compute(
                scene.pair,
                m,
                wears,
                clearances,
                torque,
                points[m],
                scene.flank,
                scene.faults,
                plane=plane,
                **({"progress": progress} if m == "fem" else {}),
            )
    harris = stiffness_job.harris(curves, scene.pair, scene.flank)
    inputs = {
        **io.scene_inputs(scene),
        "pair": pair_inputs(scene),
        "method": methods[0] if len(methods) == 1 else methods,
        "torque_Nm": torque,
        "points": points[methods[0]] if len(methods) == 1 else points,
    }

    def write_stiffness(folder: Path) -> list[Path]:
        written = stiffness_job.write(curves, folder, inputs, io.scene_labels(scene), harris, assumed)
        return written + (stiffness_job.write_fields(curves, folder, fields) if fields else [])

    files = write_output(
        out,
        "stiffness",
        scene,
        {**inputs, "fields": fields},
        write_stiffness,
        {"curves": {c.slug: c.result.wall_s for c in curves}},
        uses=uses,
    )
    from gearwear.scene.plausibility import pair_warnings

    absurd = pair_warnings(scene)  # legal but no gear's: said, not refused
    summaries = [{**c.summary(), "assumptions": assumed} for c in curves]
    for s in summaries:
        s["warnings"] = list(s.get("warnings", [])) + absurd
    if args.json:
        doc = dict(summaries[0])
        doc["curves"] = summaries
        if harris is not None:
            doc["harris_map"] = harris.rows()
        doc["files"] = [str(f) for f in files]
        print(io.json_text(doc, indent=None))
    else:
        w = max(9, *(len(s["method"]) + 1 for s in summaries))  # a registered source may have a longer name
        hdr = (
            f"{'method':<{w}}{'wear':<9}{'clear um':>9}{'mean N/m':>12}{'min N/m':>12}{'max N/m':>12}"
            f"{'eps':>8}{'double':>12}{'single':>12}{'wall ms':>9}"
        )
        print(hdr)
        for s in summaries:
            print(
                f"{s['method']:<{w}}{s['wear']:<9}{s['clearance_um']:>9g}{s['mean_N_per_m']:>12.4e}"
                f"{s['min_N_per_m']:>12.4e}{s['max_N_per_m']:>12.4e}{s['contact_ratio']:>8.4f}"
                f"{num_or_dash(s['double_zone_mean_N_per_m'])}{num_or_dash(s['single_zone_mean_N_per_m'])}"
                f"{s['wall_s'] * 1e3:>9.1f}"
            )
        for s in summaries:
            if "mesh_only_mean_N_per_m" in s:  # the pair FE: what the bores add (compare analytic: mesh only)
                kb = ", ".join("-" if k is None else f"{k:.4e}" for k in s["blank_torsional_stiffness_Nm_per_rad"])
                rr = ", ".join(f"{r:.2f}" for r in s["blank_reference_radius_mm"])
                print(
                    f"fem {s['wear']}, {s['clearance_um']:g} um: bore-fixed mean {s['bore_fixed_mean_N_per_m']:.4e} "
                    f"N/m, mesh only {s['mesh_only_mean_N_per_m']:.4e} N/m (blanks' torsion below r_ref = {rr} mm "
                    f"taken out; compare analytic methods with this); blank torsional stiffness {kb} N m/rad"
                )
        print_assumed(assumed)
        for w in dict.fromkeys(w for s in summaries for w in s.get("warnings", [])):
            print(f"warning: {w}")
        for f in files:
            print(f"wrote {f}")
    return 0


def add_parser(sub) -> None:
    """The ``stiffness`` sub-command's arguments."""
    st = sub.add_parser(
        "stiffness",
        help="time-varying mesh stiffness curves (Ishikawa, energy, ISO 6336)",
        description="Mesh stiffness k_h over one mesh period with load sharing at the operating "
        "torque, wear gaps and tip-corner contact; loaded static transmission error. "
        "Several --wear or --clearance-um values overlay the curves (paper Figs. 6, "
        "16, 17).",
    )
    scene_options(st, "paper-default", multi=True)
    st.add_argument(
        "--method",
        nargs="+",
        default=["ishikawa"],
        help="one or more (overlaid; default ishikawa): " + " | ".join(f"{m}: {SOURCES[m].title}" for m in METHODS),
    )
    st.add_argument(
        "--points",
        help=f"uniform angles per mesh period for every method (>= 8; default {TABLE_POINTS}, "
        f"{SOURCES['fem'].default_points} for fem; the analytic methods add the "
        "breakpoints of the load sharing as nodes)",
    )
    st.add_argument("--out", help="output folder for CSV, JSON sidecars and PNGs")
    st.add_argument(
        "--fields",
        nargs="+",
        help="with --method fem: position indices (0 .. points-1, over the "
        "revolution with a fault) whose displacement and stress fields "
        "are written as .vtu for ParaView",
    )
    st.add_argument("--json", action="store_true", help="print one JSON object (first curve + 'curves')")
    st.set_defaults(func=run)
