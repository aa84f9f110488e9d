"""``gearwear calibrate``: FE-calibrated mesh stiffness tables (cached by input hash)."""

from __future__ import annotations

import argparse
import contextlib
from typing import Any

from gearwear import io
from gearwear.analytic import TABLE_POINTS_PER_MESH_PERIOD as TABLE_POINTS
from gearwear.cli.common import (
    SCHEDULER_HELP,
    assumptions_of,
    check_out,
    fe_executor,
    fem_plane,
    int_arg,
    output_options,
    print_assumed,
    scene_options,
    unworn_as_none,
    variants,
    wear_dict,
    write_output,
)
from gearwear.core.validation import InputError, fail


def run(args: argparse.Namespace) -> int:
    from gearwear.stiffness import calibration as calibrate
    from gearwear.stiffness import tables

    scene, wears, clearances = variants(args)
    wears = unworn_as_none(wears)
    assumed = assumptions_of(scene, "calibrate")
    torque = scene.operating.torque_Nm
    points = int_arg("--points", args.points, 8, 1_000_000)
    out = check_out(args.out, "calibrate")
    tables.cache_dir()  # a bad GEARWEAR_CACHE: exit 2 before any FE run
    for c in clearances:  # the FE pair contact needs overlap: refuse before any FE run
        try:
            calibrate.require_overlap(scene.pair, c)
        except InputError as exc:
            raise fail("--clearance-um", c * 1e6, "um", "the FE calibration " + str(exc).split(": ", 1)[1]) from None
    with fe_executor(args) or contextlib.nullcontext() as executor:
        rows, copies, fe_s = _calibrate_tables(args, scene, wears, clearances, torque, points, out, executor)
    inputs = {
        **io.scene_inputs(scene),
        "wear": [w.label if w else "unworn" for w in wears],
        "wear_spec": [wear_dict(w) for w in wears],
        "clearance_um": [c * 1e6 for c in clearances],
        "torque_Nm": torque,
        "points": points,
    }
    files = write_output(
        out,
        "calibrate",
        scene,
        inputs,
        lambda d: [io.write_bytes(d / n, b) for n, b in copies.items()],
        {"fe_calibration_s": fe_s},
    )
    if args.json:
        print(io.json_text({"tables": rows, "assumptions": assumed, "files": [str(f) for f in files]}, indent=None))
    else:
        # the table's own error against the pair FE it was calibrated to (per contact zone and
        # the maximum over the FE positions), next to the FE's discretisation estimate
        print(
            f"{'wear':<9}{'clear um':>9}{'mean N/m':>12}{'analytic':>12}{'vs pair FE max %':>17}"
            f"{'single %':>9}{'double %':>9}{'FE discr. %':>12}  cache"
        )

        def pct(v: Any, width: int) -> str:
            return f"{'-':>{width}}" if v is None else f"{100 * v:>{width}.2f}"

        for r in rows:
            te: Any = r["table_vs_pair_fe"] or {}
            err: Any = r["fe_estimated_relative_error"]
            print(
                f"{r['wear']:<9}{r['clearance_um']:>9g}{r['mean_N_per_m']:>12.4e}"
                f"{r['uncorrected_mean_N_per_m']:>12.4e}{pct(te.get('max'), 17)}{pct(te.get('single'), 9)}"
                f"{pct(te.get('double'), 9)}{pct(err, 12)}  {'hit' if r['cache_hit'] else 'new'}"
            )
        print_assumed(assumed)
        for f in files:
            print(f"wrote {f}")
    return 0


def _calibrate_tables(args, scene, wears, clearances, torque, points, out, executor):
    """(rows, files to copy into --out, FE wall times) of every (wear, clearance) table."""
    from gearwear.stiffness import calibration as calibrate

    plane = fem_plane(scene.doc, True, "gearwear calibrate")
    rows: list[dict] = []
    copies: dict[str, bytes] = {}  # the cached tables, copied into --out as a whole at the end
    fe_s: dict[str, float] = {}
    for w in wears:
        fe: list = []

        def calibration(w=w, fe=fe):  # one FE run per wear, and only on a cache miss
            if not fe:
                fe.append(calibrate.run_fe(scene.pair, w, executor=executor, plane=plane))
            return fe[0]

        for c in clearances:
            tab = calibrate.calibrated_table(
                scene.pair,
                w,
                c,
                torque,
                points,
                calibration=calibration,
                refresh=args.refresh,
                executor=executor,  # a damaged entry: recomputed
                plane=plane,
            )
            hit = tab.from_cache
            label = f"{w.label if w else 'unworn'}_clearance{c * 1e6:g}um"
            if out:  # the bytes the cache holds, as checked (not read again)
                copies[f"calibrated_{label}.csv"] = tab.csv_bytes
                copies[f"calibrated_{label}.csv.json"] = tab.sidecar_bytes
            if not hit and fe:
                fe_s[label] = fe[0].wall_s
            m = tab.meta
            rows.append(
                {
                    "wear": w.label if w else "unworn",
                    "clearance_um": c * 1e6,
                    "cache_hit": hit,
                    "mean_N_per_m": tab.mean_N_per_m,
                    "min_N_per_m": float(tab.k_N_per_m.min()),
                    "max_N_per_m": float(tab.k_N_per_m.max()),
                    "uncorrected_mean_N_per_m": m.get("uncorrected_mean_N_per_m"),
                    "check_residual": m.get("check_residual"),
                    "fit_residual": m.get("fit_residual"),
                    "table_vs_pair_fe": m.get("table_vs_pair_fe"),
                    "fe_estimated_relative_error": m.get("fe_estimated_relative_error"),
                    "input_sha256": m.get("input_sha256"),
                    "points": int(len(tab.k_N_per_m)),
                }
            )
    return rows, copies, fe_s


def add_parser(sub) -> None:
    """The ``calibrate`` sub-command's arguments."""
    c = sub.add_parser(
        "calibrate",
        help="FE-calibrated mesh stiffness tables (cached by input hash)",
        description="Mesh stiffness tables from the Ishikawa model with the tooth compliance "
        "corrected to FE (fitted on the even load positions, checked on the odd ones). "
        "Tables are cached by the SHA-256 of their inputs ($GEARWEAR_CACHE or "
        "~/.cache/gearwear/tables); these are what scenes with "
        "mesh_stiffness.source = \"calibrated\" use.",
    )
    scene_options(c, "paper-default", multi=True)
    c.add_argument(
        "--points",
        default=str(TABLE_POINTS),
        help=f"uniform angles per mesh period (default {TABLE_POINTS}; the breakpoints come on top)",
    )
    c.add_argument("--refresh", action="store_true", help="recompute even if a cached table exists")
    c.add_argument(
        "--workers",
        help="solve the FE runs and pair positions on N local worker processes (default: "
        "in this process, where every gear body is built once for all wear states)",
    )
    c.add_argument("--scheduler", help=SCHEDULER_HELP)
    output_options(c, "copy the tables (CSV + JSON sidecar) here")
    c.set_defaults(func=run)
