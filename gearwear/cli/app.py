"""The ``gearwear`` command line.

Every command works without a file (the built-in paper pair). A bad input prints
one line ``gearwear: error: <key> = <value> <unit>: <allowed range>`` and exits 2;
nothing is written before all inputs are validated, and files are written atomically.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gearwear.analytic import TABLE_POINTS_PER_MESH_PERIOD as TABLE_POINTS
from gearwear.core.validation import InputError, fail, renamed

from gearwear import __version__, io
from gearwear.stiffness.sources import METHODS, SOURCES

if TYPE_CHECKING:
    from gearwear.scene.model import Scene


#: --mesh-size-mm: the global element size of the whole-gear mesh; on the paper gear 0.25 mm
#: already means ~10^6 P2 triangles (minutes, GiBs), and 10 mm is coarser than a tooth
MESH_SIZE_RANGE_MM = (0.25, 10.0)


def _bounded_float(name: str, text: str, unit: str, lo: float, hi: float) -> float:
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{name} = {text!r}: must be a number in [{lo:g}, {hi:g}] {unit}") from None
    if not lo <= v <= hi:
        raise InputError(f"{name} = {v:g} {unit}: must be in [{lo:g}, {hi:g}] {unit}")
    return v


def _fem_plane(doc: Any, runs_fem: bool, what: str) -> str:
    """schema.fem_plane, imported when a command runs (the CLI imports nothing heavy
    before its signal handlers are installed)."""
    from gearwear.scene.schema import fem_plane

    return fem_plane(doc, runs_fem, what)


def _alias_sets(args: argparse.Namespace, skip: tuple[str, ...] = ()) -> list[str]:
    """The single-valued short flags as the --set overrides they stand for (``skip``: flags
    whose value the caller sets itself, one variant at a time)."""
    from gearwear.scene.model import wear_override

    sets = []
    if getattr(args, "torque_Nm", None) is not None:
        sets.append(f"operating.torque_Nm={args.torque_Nm}")
    for flag, make in (("wear", wear_override), ("clearance_um", _clearance_set)):
        values = _split_multi(getattr(args, flag, None))
        if len(values) == 1 and flag not in skip:
            sets.append(make(values[0]))
    return sets + list(args.set or [])


def _clearance_set(text: str) -> str:
    return f"effects.bearing_clearance.clearance_um={text}"


ALIAS_FLAGS = {"torque_Nm": "--torque-Nm", "clearance_um": "--clearance-um", "wear": "--wear"}


def _load(args: argparse.Namespace, default: str = "paper-default", extra: list[str] | None = None,
          loaded: bool = True, skip: tuple[str, ...] = ()) -> "Scene":
    """The command's scene: file or built-in name, short-flag aliases, then --set. A bad
    value given through a short flag is reported under the flag's name. ``loaded``: the
    command computes load sharing, so the torque must be > 0."""
    from gearwear.scene.model import SHORT_KEYS, apply_overrides, load_scene_dict, scene_from_dict

    data, name = load_scene_dict(args.scene, default=default)
    try:
        scene = scene_from_dict(apply_overrides(data, _alias_sets(args, skip) + list(extra or [])), name=name)
        if loaded and not scene.operating.torque_Nm > 0:
            raise fail("operating.torque_Nm", scene.operating.torque_Nm, "N m",
                       "must be in (0, 1e+07] N m: the load sharing of the mesh stiffness needs a load")
        return scene
    except InputError as exc:
        given = {SHORT_KEYS[attr]: flag for attr, flag in ALIAS_FLAGS.items() if getattr(args, attr, None) is not None}
        for key, flag in given.items():  # a sub-key of an alias (--wear=-5um sets effects.wear.max_depth_um)
            if str(exc).startswith(key + "."):
                raise type(exc)(f"{flag}: {exc}") from None
        raise renamed(exc, given) from None


def _variants(args: argparse.Namespace) -> "tuple[Scene, list, list[float]]":
    """(scene, wear specs, clearances in m) for commands that overlay several --wear and
    --clearance-um values: each value is the scene with that alias applied."""
    from gearwear.scene.model import wear_override

    scene = _load(args)
    wears = [_load(args, extra=[wear_override(w)], skip=("wear",)).wear
             for w in _split_multi(getattr(args, "wear", None))] or [scene.wear]
    clear = [_load(args, extra=[_clearance_set(c)], skip=("clearance_um",)).clearance_m
             for c in _split_multi(getattr(args, "clearance_um", None))]
    return scene, wears, clear or [scene.clearance_m]


def _cmd_geometry(args: argparse.Namespace) -> int:
    from gearwear.jobs import geometry as geometry_job

    scene = _load(args, loaded=False)
    _fem_plane(scene.doc, False, "gearwear geometry")
    torque, clearance_um, wear = scene.operating.torque_Nm, round(scene.clearance_m * 1e6, 9), scene.wear
    mesh_size = _bounded_float("--mesh-size-mm", args.mesh_size_mm, "mm", *MESH_SIZE_RANGE_MM)
    out = _check_out(args.out, "geometry")
    # the mesh is a file (pinion_mesh.vtu): built only when the folder is written, not for the table
    build_mesh = out is not None and not args.no_mesh
    res = geometry_job.compute(scene, wear, clearance_um * 1e-6, torque, build_mesh=build_mesh,
                               mesh_size_mm=mesh_size)
    inputs = {**io.scene_inputs(scene), "pair": _pair_inputs(scene), "wear": wear.label if wear else "unworn",
              "wear_spec": _wear_dict(wear), "clearance_um": clearance_um, "torque_Nm": torque,
              "bearing_stiffness_N_per_m": scene.bodies.bearing_stiffness_N_per_m,
              "bodies": {"mass_kg": list(scene.bodies.mass_kg), "inertia_kg_m2": list(scene.bodies.inertia_kg_m2)},
              "initial_backlash_um": scene.initial_backlash_m * 1e6, "mesh": build_mesh,
              "mesh_size_mm": mesh_size}
    files = _write(out, "geometry", scene, inputs,
                   lambda d: geometry_job.write(res, d, inputs, io.scene_labels(scene)),
                   {"total_s": res.wall_s, "mesh_build_s": res.mesh_build_s})
    summary = res.summary()
    summary["files"] = [str(f) for f in files]
    if args.json:
        print(io.json_text(summary, indent=None))
    else:
        _print_geometry(summary)
    return 0


def _check_out(out: str | None, command: str) -> Path | None:
    """--out is checked before any work: a new folder, an empty one, or one gearwear
    wrote (it has a manifest.json), since the command's output replaces it as a whole
    (gearwear.io.check_out; the parent must be writable, '' is refused)."""

    return io.check_out(out, command)


def _wear_dict(wear) -> dict | None:
    """Every field of a wear definition (not only its label): part of the hashed inputs."""
    import dataclasses

    return None if wear is None else dataclasses.asdict(wear)


#: which results each command's files hold, for the assumptions they list (gearwear.scene.assumptions.USES)
COMMAND_USES = {"geometry": "geometry", "stiffness": "stiffness", "verify": "verify", "calibrate": "calibrate",
                "simulate": "simulate", "sweep": "simulate", "runup": "runup", "diagnose": "simulate",
                "diagnose plan": "simulate", "report pair": "report pair"}


def _assumed(scene, uses: str) -> list[dict]:
    """The assumptions of ``scene`` a command's results rest on (gearwear.scene.assumptions), as
    dicts (``key``, ``value``, ``unit``, ``why``)."""
    from gearwear.scene.assumptions import as_dicts, for_command

    return as_dicts(for_command(scene, uses))


def print_assumed(assumed: list[dict]) -> None:
    """One ``assumed:`` line per value (with the results: a bad input stays one line)."""
    from gearwear.scene.assumptions import line_of

    for a in assumed:
        print(line_of(a))


def _write(out: Path | None, command: str, scene, inputs: dict, writer, timing: dict | None = None,
           uses: str | None = None) -> list[Path]:
    """Write a command's files into ``out`` as a whole (gearwear.io.write_folder): the
    manifest gets the inputs, the scene's name and referenced file paths, and every value
    the results assume that the scene did not give (``uses``: which results, default by
    command)."""

    if out is None:
        return []
    prov = {**inputs, **(io.scene_labels(scene) if scene is not None else {})}
    if scene is not None:
        prov["assumptions"] = _assumed(scene, uses or COMMAND_USES[command])
    return io.write_folder(out, command, prov, writer, timing)


def _split_multi(values: list[str] | str | None) -> list[str]:
    """Flag values given space- or comma-separated (one string for single-valued flags)."""
    out: list[str] = []
    for v in [values] if isinstance(values, str) else values or []:
        out += [x for x in v.split(",") if x.strip()]
    return out


def _cmd_stiffness(args: argparse.Namespace) -> int:

    from tqdm import tqdm

    from gearwear.geometry.faults import revolution_periods

    from gearwear.jobs import stiffness as stiffness_job

    methods = list(dict.fromkeys(_split_multi(args.method)))  # several methods: overlaid
    for m in methods:
        if m not in METHODS:
            raise InputError(f"--method = {m!r}: must be one or more of {', '.join(METHODS)}")
    scene, wears, clearances = _variants(args)
    uses = "stiffness-fem" if "fem" in methods else "stiffness-iso" if set(methods) == {"iso6336"} else "stiffness"
    plane = _fem_plane(scene.doc, any(m != "iso6336" for m in methods),
                       f"gearwear stiffness --method {' '.join(methods)}")
    assumed = _assumed(scene, uses)
    torque = scene.operating.torque_Nm
    # default angles per method: the FE's 24 positions take ~10 s, the analytic tables take ms
    points = {m: _int_arg("--points", args.points if args.points is not None else str(SOURCES[m].default_points),
                          8, 1_000_000) for m in methods}
    out = _check_out(args.out, "stiffness")
    fields = []
    if args.fields:
        if methods != ["fem"] or not args.out:
            raise InputError(f"--fields = {','.join(_split_multi(args.fields))}: needs --method fem (alone) and --out")
        # with a fault the FE curve spans one revolution of the faulty gear
        rows = points["fem"] * revolution_periods(scene.pair, scene.faults)
        fields = [_int_arg("--fields", f, 0, rows - 1) for f in _split_multi(args.fields)]
    for m in methods:
        stiffness_job.check_method(m, scene.flank, scene.faults)  # every method refused before any work
    curves = []
    with tqdm(desc="pair FE positions", unit="position", disable=args.json or "fem" not in methods or None,
              file=sys.stderr) as bar:
        def progress(done: int, total: int) -> None:  # only the pair FE reports progress
            bar.total = total
            bar.n = done
            bar.refresh()
        for m in methods:
            curves += stiffness_job.compute(scene.pair, m, wears, clearances, torque, points[m], scene.flank,
                                            scene.faults, plane=plane, **({"progress": progress} if m == "fem"
                                                                          else {}))
    harris = stiffness_job.harris(curves, scene.pair, scene.flank)
    inputs = {**io.scene_inputs(scene), "pair": _pair_inputs(scene),
              "method": methods[0] if len(methods) == 1 else methods, "torque_Nm": torque,
              "points": points[methods[0]] if len(methods) == 1 else points}

    def write_stiffness(folder: Path) -> list[Path]:
        written = stiffness_job.write(curves, folder, inputs, io.scene_labels(scene), harris, assumed)
        return written + (stiffness_job.write_fields(curves, folder, fields) if fields else [])
    files = _write(out, "stiffness", scene, {**inputs, "fields": fields}, write_stiffness,
                   {"curves": {c.slug: c.result.wall_s for c in curves}}, uses=uses)
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
        hdr = f"{'method':<9}{'wear':<9}{'clear um':>9}{'mean N/m':>12}{'min N/m':>12}{'max N/m':>12}" \
              f"{'eps':>8}{'double':>12}{'single':>12}{'wall ms':>9}"
        print(hdr)
        for s in summaries:
            print(f"{s['method']:<9}{s['wear']:<9}{s['clearance_um']:>9g}{s['mean_N_per_m']:>12.4e}"
                  f"{s['min_N_per_m']:>12.4e}{s['max_N_per_m']:>12.4e}{s['contact_ratio']:>8.4f}"
                  f"{_num_or_dash(s['double_zone_mean_N_per_m'])}{_num_or_dash(s['single_zone_mean_N_per_m'])}"
                  f"{s['wall_s'] * 1e3:>9.1f}")
        for s in summaries:
            if "mesh_only_mean_N_per_m" in s:  # the pair FE: what the bores add (compare analytic: mesh only)
                kb = ", ".join("-" if k is None else f"{k:.4e}" for k in s["blank_torsional_stiffness_Nm_per_rad"])
                rr = ", ".join(f"{r:.2f}" for r in s["blank_reference_radius_mm"])
                print(f"fem {s['wear']}, {s['clearance_um']:g} um: bore-fixed mean {s['bore_fixed_mean_N_per_m']:.4e} "
                      f"N/m, mesh only {s['mesh_only_mean_N_per_m']:.4e} N/m (blanks' torsion below r_ref = {rr} mm "
                      f"taken out; compare analytic methods with this); blank torsional stiffness {kb} N m/rad")
        print_assumed(assumed)
        for w in dict.fromkeys(w for s in summaries for w in s.get("warnings", [])):
            print(f"warning: {w}")
        for f in files:
            print(f"wrote {f}")
    return 0


def _num_or_dash(v: float | None, width: int = 12) -> str:
    """A zone mean in the text table; '-' for a zone the pair never has (contact ratio >= 2 has
    no single-contact zone)."""
    return f"{'-':>{width}}" if v is None else f"{v:>{width}.4e}"


def _unworn_as_none(wears: list) -> list:
    """verify and calibrate key an unworn flank as None (the nominal profile)."""
    return [None if w is None or w.is_unworn else w for w in wears]


def _cmd_verify(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from gearwear.jobs import verify as verify_job

    if not args.wear:
        args.wear = ["unworn", "mild", "severe"]
    scene, wears, _ = _variants(args)
    wears = _unworn_as_none(wears)
    assumed = _assumed(scene, "verify")
    positions = _int_arg("--positions", args.positions, 5, 201)
    out = _check_out(args.out, "verify")
    steps = len(wears) + (0 if args.no_convergence else 12)
    with tqdm(total=steps, desc="verify", unit="run", disable=args.json or None, file=sys.stderr) as bar:
        def progress(msg):
            bar.set_postfix_str(msg)
            bar.update(1)
        v = verify_job.run(scene.pair, wears, positions, convergence=not args.no_convergence, progress=progress,
                           plane=_fem_plane(scene.doc, True, "gearwear verify"))
    inputs = {**io.scene_inputs(scene), "pair": _pair_inputs(scene),
              "wear": [w.label if w else "unworn" for w in wears], "wear_spec": [_wear_dict(w) for w in wears],
              "positions": positions, "convergence": not args.no_convergence}
    timing = {"total_s": v.wall_s, "phases": {ph.label: {"fem_s": ph.fem_wall_s, "ishikawa_s": ph.ishikawa_wall_s,
                                                         "energy_s": ph.energy_wall_s} for ph in v.phases},
              "convergence": [{k: r.get(k) for k in ("order", "mesh_scale", "dofs", "wall_s")}
                              for r in v.convergence or []]}
    files = _write(out, "verify", scene, inputs, lambda d: verify_job.write(v, d, inputs, io.scene_labels(scene)),
                   timing)
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
            print(f"{ph.label:<9}{ph.fem_wall_s:>7.2f}{ph.dofs:>9}{di.min():>14.1f} .. {di.max():<11.1f}"
                  f"{de.min():>12.1f} .. {de.max():<11.1f}")
        print_assumed(assumed)
        if v.acceptance:
            a = v.acceptance
            print(f"FE convergence: two finest P2 levels differ by {a['finest_p2_change_pct']:.3f} %, default level "
                  f"{a['default_dofs']} dofs in {a['default_wall_s']:.2f} s")
        for f in files:
            print(f"wrote {f}")
    return 0


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from gearwear import io
    from gearwear.stiffness import calibration as calibrate
    from gearwear.stiffness import tables

    scene, wears, clearances = _variants(args)
    wears = _unworn_as_none(wears)
    assumed = _assumed(scene, "calibrate")
    torque = scene.operating.torque_Nm
    points = _int_arg("--points", args.points, 8, 1_000_000)
    out = _check_out(args.out, "calibrate")
    tables.cache_dir()  # a bad GEARWEAR_CACHE: exit 2 before any FE run
    for c in clearances:  # the FE pair contact needs overlap: refuse before any FE run
        try:
            calibrate.require_overlap(scene.pair, c)
        except InputError as exc:
            raise fail("--clearance-um", c * 1e6, "um", "the FE calibration " + str(exc).split(": ", 1)[1]) from None
    with _fe_executor(args) or contextlib.nullcontext() as executor:
        rows, copies, fe_s = _calibrate_tables(args, scene, wears, clearances, torque, points, out, executor)
    inputs = {**io.scene_inputs(scene), "wear": [w.label if w else "unworn" for w in wears],
              "wear_spec": [_wear_dict(w) for w in wears], "clearance_um": [c * 1e6 for c in clearances],
              "torque_Nm": torque, "points": points}
    files = _write(out, "calibrate", scene, inputs, lambda d: [io.write_bytes(d / n, b) for n, b in copies.items()],
                   {"fe_calibration_s": fe_s})
    if args.json:
        print(io.json_text({"tables": rows, "assumptions": assumed, "files": [str(f) for f in files]}, indent=None))
    else:
        # the table's own error against the pair FE it was calibrated to (per contact zone and
        # the maximum over the FE positions), next to the FE's discretisation estimate
        print(f"{'wear':<9}{'clear um':>9}{'mean N/m':>12}{'analytic':>12}{'vs pair FE max %':>17}"
              f"{'single %':>9}{'double %':>9}{'FE discr. %':>12}  cache")

        def pct(v: Any, width: int) -> str:
            return f"{'-':>{width}}" if v is None else f"{100 * v:>{width}.2f}"
        for r in rows:
            te: Any = r["table_vs_pair_fe"] or {}
            err: Any = r["fe_estimated_relative_error"]
            print(f"{r['wear']:<9}{r['clearance_um']:>9g}{r['mean_N_per_m']:>12.4e}"
                  f"{r['uncorrected_mean_N_per_m']:>12.4e}{pct(te.get('max'), 17)}{pct(te.get('single'), 9)}"
                  f"{pct(te.get('double'), 9)}{pct(err, 12)}  {'hit' if r['cache_hit'] else 'new'}")
        print_assumed(assumed)
        for f in files:
            print(f"wrote {f}")
    return 0


def _fe_executor(args: argparse.Namespace):
    """Where the FE runs of a calibration go: None (this process, the default: every body is
    built once and shared by the wear states), local processes (--workers N) or Dask
    (--scheduler). Each worker builds the bodies it needs once; the tables are the same to
    the bit on any executor."""
    from gearwear.jobs import sweep as sweep_job

    if not (args.workers or args.scheduler):
        return None
    return sweep_job.make_executor(_workers(args), args.scheduler)


def _workers(args: argparse.Namespace) -> int | None:
    """--workers N (1..1024), or None: the executor's default (all cores). With --scheduler the
    workers are the cluster's (local:N or the running one's): --workers would be ignored."""
    if args.workers and getattr(args, "scheduler", None):
        raise InputError(f"--workers = {args.workers}: not used with --scheduler {args.scheduler} (the cluster's "
                         "workers run the tasks; give their number as --scheduler local:N)")
    return _int_arg("--workers", args.workers, 1, 1024) if args.workers else None


def _calibrate_tables(args, scene, wears, clearances, torque, points, out, executor):
    """(rows, files to copy into --out, FE wall times) of every (wear, clearance) table."""
    from gearwear.stiffness import calibration as calibrate

    plane = _fem_plane(scene.doc, True, "gearwear calibrate")
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
            tab = calibrate.calibrated_table(scene.pair, w, c, torque, points, calibration=calibration,
                                             refresh=args.refresh, executor=executor,  # a damaged entry: recomputed
                                             plane=plane)
            hit = tab.from_cache
            label = f"{w.label if w else 'unworn'}_clearance{c * 1e6:g}um"
            if out:  # the bytes the cache holds, as checked (not read again)
                copies[f"calibrated_{label}.csv"] = tab.csv_bytes
                copies[f"calibrated_{label}.csv.json"] = tab.sidecar_bytes
            if not hit and fe:
                fe_s[label] = fe[0].wall_s
            m = tab.meta
            rows.append({"wear": w.label if w else "unworn", "clearance_um": c * 1e6, "cache_hit": hit,
                         "mean_N_per_m": tab.mean_N_per_m, "min_N_per_m": float(tab.k_N_per_m.min()),
                         "max_N_per_m": float(tab.k_N_per_m.max()),
                         "uncorrected_mean_N_per_m": m.get("uncorrected_mean_N_per_m"),
                         "check_residual": m.get("check_residual"), "fit_residual": m.get("fit_residual"),
                         "table_vs_pair_fe": m.get("table_vs_pair_fe"),
                         "fe_estimated_relative_error": m.get("fe_estimated_relative_error"),
                         "input_sha256": m.get("input_sha256"), "points": int(len(tab.k_N_per_m))})
    return rows, copies, fe_s


def _cmd_simulate(args: argparse.Namespace) -> int:
    from gearwear.jobs import simulate_io
    from gearwear.jobs import simulate as simulate_job

    from gearwear.scene.model import require_dynamics

    scene = _load(args, default="paper-wear-severe")
    require_dynamics(scene)
    out = _check_out(args.out, "simulate")
    run = simulate_job.run(scene, on_compile=lambda msg: print(msg, file=sys.stderr, flush=True))
    summary = run.summary()
    inputs = io.scene_inputs(scene)
    files = _write(out, "simulate", scene, inputs,
                   lambda d: simulate_io.write(run, d, inputs, io.scene_labels(scene)),
                   {"total_s": summary["wall_s"], "integration_s": summary["integration_wall_s"],
                    "compile_s": summary["compile_s"]})
    summary["files"] = [str(f) for f in files]
    if args.json:
        print(io.json_text(summary, indent=None))
    else:
        simulate_io.print_summary(summary)
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from gearwear.jobs import sweep
    from gearwear.scene.model import load_scene_dict, require_dynamics

    data, name = load_scene_dict(args.scene, default="paper-wear-severe")
    out = _check_out(args.out, "sweep")
    axes, fixed = sweep.split_sets(_alias_sets(args))
    from gearwear.scene.model import apply_overrides, scene_from_dict
    require_dynamics(scene_from_dict(apply_overrides(data, fixed), name=name))  # the fixed keys are checked first
    if not axes:
        raise InputError("--set: give at least one swept key, KEY=START:STOP:N or KEY=a,b,c")
    sweep.check_size(math.prod(len(a.values) for a in axes), "grid points", args.allow_large)
    with sweep.make_executor(_workers(args), args.scheduler) as executor:
        results = sweep.sweep(data, name, axes, fixed, executor=executor, progress=not args.json)
    base = scene_from_dict(apply_overrides(data, fixed), name=name)  # the scene every point starts from
    inputs = {**io.scene_inputs(base), "axes": {a.key: list(a.values) for a in axes}}
    labels = {**io.scene_labels(base), "fixed": fixed}
    files = _write(out, "sweep", base, {**inputs, "fixed": fixed},
                   lambda d: sweep.write(axes, results, d, inputs, labels),
                   {"points": [{"point": r["point"], "wall_s": r["wall_s"]} for r in results]})
    if args.json:
        print(io.json_text({"points": results, "files": [str(f) for f in files]}, indent=None))
    else:
        print(sweep.table_csv(axes, results).splitlines()[0][:200])
        for r in results:
            pt = ", ".join(f"{k}={v}" for k, v in r["point"].items())
            fm = r["harmonics"].get("F_m_N")
            extra = f"  F_m harmonics 1-4 (N): {', '.join(f'{x:.3g}' for x in fm[:4])}" if fm else ""
            sep = r["separation_fraction"]
            contact = ("no backlash: cannot separate, back flanks loaded "
                       f"{100 * r['backside_fraction']:.2f} %" if sep is None else f"separation {100 * sep:.2f} %")
            print(f"{pt}: {contact}{extra}")
        for f in files:
            print(f"wrote {f}")
    return 0


def _cmd_runup(args: argparse.Namespace) -> int:
    import time

    from gearwear.jobs import runup as runup_job
    from gearwear.jobs import sweep
    from gearwear.scene.model import apply_overrides, load_scene_dict, require_dynamics, scene_from_dict

    data, name = load_scene_dict(args.scene, default="paper-default")
    out = _check_out(args.out, "runup")
    axes, fixed = sweep.split_sets(_alias_sets(args))
    require_dynamics(scene_from_dict(apply_overrides(data, fixed), name=name))  # the fixed keys are checked first
    speed, others = runup_job.split_speed_axis(axes)
    sweep.check_size(len(speed.values) * math.prod(len(a.values) for a in others) * (2 if args.direction == "both"
                                                                                     else 1),
                     "runs (speeds x points x directions)", args.allow_large)
    settings = runup_job.Settings(
        tol=_bounded_float("--tolerance", args.tolerance, "", 1e-12, 1e-2),
        max_periods=_int_arg("--max-periods", args.max_periods, 2, 1_000_000),
        keep_periods=_int_arg("--keep-periods", args.keep_periods, 1, 100_000),
        jump_tol=_bounded_float("--jump-tolerance", args.jump_tolerance, "", 1e-9, 1.0))
    workers = _workers(args)
    t0 = time.perf_counter()
    points, chains = runup_job.plan(data, name, speed, others, fixed, args.direction)
    with sweep.make_executor(workers, args.scheduler) as executor:
        runup_job.run(points, chains, settings, executor, progress=not args.json)
    wall = time.perf_counter() - t0
    summ = runup_job.summary(points, chains, speed, others, settings)
    base = points[0].scene
    inputs = {**io.scene_inputs(base), "speeds_rpm": list(speed.values),
              "axes": {a.key: list(a.values) for a in others}, "direction": args.direction,
              "settings": settings.__dict__}
    labels = {**io.scene_labels(base), "fixed": fixed}
    files = _write(out, "runup", base, {**inputs, "fixed": fixed},
                   lambda d: runup_job.write(points, chains, speed, others, summ, d, inputs, labels),
                   {"total_s": wall, "chains": [{"point": points[c.point_index].values, "direction": c.direction,
                                                 "integration_s": sum(r["integration_wall_s"] for r in c.rows)}
                                                for c in chains]})
    summ["files"] = [str(f) for f in files]
    summ["wall_s"] = wall
    if args.json:
        print(io.json_text(summ, indent=None))
    else:
        for p in summ["points"]:
            iso = p["iso6336"]
            at_driver = ("" if iso["n_E1_driver_rpm"] == iso["n_E1_rpm"] else
                         f" of ISO's gear 1 ({iso['inputs']['z1']} teeth), "
                         f"{iso['n_E1_driver_rpm']:.0f} rpm at the driver")
            print(f"point {p['point'] or '-'}: ISO 6336 n_E1 = {iso['n_E1_rpm']:.0f} rpm{at_driver}; linear modes "
                  f"{', '.join(f'{f:.1f}' for f in p['linear_eigenfrequencies_Hz'])} Hz")
            for d, r in p["directions"].items():
                print(f"  sweep {d}: K_v max {r['K_v_max']:.4f} at {r['K_v_max_speed_rpm']:g} rpm; "
                      f"{', '.join(f'{k} {v}' for k, v in sorted(r['labels'].items()))}")
            if "jump_bands_rpm" in p:
                bands = "; ".join(f"{lo:g}-{hi:g} rpm" for lo, hi in p["jump_bands_rpm"]) or "none"
                print(f"  jump bands (up and down K_v differ by > {settings.jump_tol:g}): {bands}")
        print(f"wall time {wall:.1f} s")
        for f in files:
            print(f"wrote {f}")
    return 0


def _cmd_diagnose(args: argparse.Namespace) -> int:
    from gearwear.cli import diagnose as dc
    from gearwear.diagnose.surrogate import BuildSpec, validate_range
    from gearwear.scene.model import apply_overrides, load_scene_dict, require_dynamics, scene_from_dict

    data, name = load_scene_dict(args.scene, default="paper-wear-severe")
    unknowns = dc.parse_unknowns(args.unknowns)
    sets = _alias_sets(args)
    dc.check_sets(sets, unknowns)
    raw = apply_overrides(data, sets)
    scene = scene_from_dict(raw, name=name)  # the known part, checked first
    require_dynamics(scene)
    lo, hi = dc.prior_ranges(raw, unknowns, {"wear": args.wear_range_um, "clearance": args.clearance_range_um,
                                             "torque": args.torque_range_Nm})
    validate_range(raw, name, unknowns, lo, hi)
    rel = _bounded_float("--noise-pct", args.noise_pct, "%", 0.01, 100) / 100
    floor = _bounded_float("--noise-floor-pct", args.noise_floor_pct, "%", 0, 100) / 100
    workers = _workers(args)
    d, K = len(unknowns), int(scene.output["harmonics"])
    design = dc.design_size(args.design_points, "--design-points",
                            (dc.PLAN_DESIGN_POINTS if args.plan else dc.DESIGN_POINTS)[d])
    spec = BuildSpec(raw, name, unknowns, lo, hi, K, design, dc.HOLDOUT_POINTS[d])
    if args.plan:
        if args.measured:
            raise InputError(f"--measured {args.measured}: not used with --plan (the plan needs no measurement)")
        speeds, torques = dc.plan_candidates(raw, unknowns, dc.parse_list(args.speeds_rpm, "--speeds-rpm", "rpm", 1e6),
                                             dc.parse_list(args.torques_Nm, "--torques-Nm", "N m", 1e7))
        out = _check_out(args.out, "diagnose plan")
        doc, timing = dc.run_plan(spec, speeds, torques, rel, floor, workers, not args.json)
        inputs = dc.inputs(spec, rel, floor, {"plan_speeds_rpm": speeds, "plan_torques_Nm": torques})
        files = _write(out, "diagnose plan", scene, inputs,
                       lambda f: dc.write_plan(doc, f, inputs, io.scene_labels(scene)), timing)
        if args.json:
            print(io.json_text({**doc, "wall_s": timing["total_s"], "files": [str(f) for f in files]}, indent=None))
        else:
            from gearwear.diagnose.plan import print_table
            print_table(doc)
            for f in files:
                print(f"wrote {f}")
        return 0
    if not args.measured:
        raise InputError("--measured: missing; give the measured CSV (a time series or a harmonic table), "
                         "or --plan for a measurement plan")
    if args.speeds_rpm or args.torques_Nm:
        raise InputError("--speeds-rpm/--torques-Nm: only used with --plan")
    from gearwear.diagnose.features import read_measurement
    meas = read_measurement(args.measured, scene.mesh_frequency_Hz, K)  # a bad file: one line, before any work
    out = _check_out(args.out, "diagnose")
    res = dc.diagnose(spec, meas, rel, floor, workers, not args.json, refresh=args.refresh)
    inputs = dc.inputs(spec, rel, floor, {"measured_sha256": res.doc["measured"]["sha256"]})
    labels = {**io.scene_labels(scene), "measured_file": str(args.measured)}
    files = _write(out, "diagnose", scene, inputs, lambda f: dc.write_diagnosis(res, f, inputs, labels), res.timing)
    if args.json:
        print(io.json_text({**res.doc, "wall_s": res.timing["total_s"], "timing": res.timing,
                            "files": [str(f) for f in files]}, indent=None))
    else:
        dc.print_diagnosis(res.doc, res.timing, files)
    return 0


def _cmd_scene(args: argparse.Namespace) -> int:
    from gearwear.scene.schema import json_schema, reference_markdown, resolved_dict, to_toml
    from gearwear.scene.model import builtin_scene_names

    if (args.reference or args.schema or args.list) and (args.scene or args.set or args.json):
        given = [f for f, v in (("SCENE", args.scene), ("--set", args.set), ("--json", args.json)) if v]
        which = "--reference" if args.reference else "--schema" if args.schema else "--list"
        raise InputError(f"{', '.join(given)}: not used with {which} (it prints the same for every scene); drop "
                         f"{'it' if len(given) == 1 else 'them'}")
    if args.reference:
        print(reference_markdown(), end="")
        return 0
    if args.schema:
        print(json.dumps(json_schema(), indent=2))
        return 0
    if args.list:
        print("\n".join(builtin_scene_names()))
        return 0
    from gearwear.scene.assumptions import scene_assumptions

    scene = _load(args, loaded=False)
    assert scene.doc is not None
    data = resolved_dict(scene.doc)
    # what the run derives from the pair: the bore and the bodies where the scene gives none
    data["pair"].setdefault("hub_radius_mm", [round(r * 1e3, 6) for r in scene.pair.hub_radius_m])
    data["bodies"].setdefault("mass_kg", [float(f"{m:.9g}") for m in scene.bodies.mass_kg])
    data["bodies"].setdefault("inertia_kg_m2", [float(f"{j:.9g}") for j in scene.bodies.inertia_kg_m2])
    assumed = scene_assumptions(scene)
    if args.json:
        print(json.dumps({**data, "assumptions": [a.to_dict() for a in assumed]}, indent=2))
    else:
        print("".join(f"# {a.line}\n" for a in assumed) + to_toml(data), end="")
    return 0


def _cmd_report(args: argparse.Namespace) -> int:
    from gearwear.reports import paper as report_paper

    if args.which == "pair":
        return _cmd_report_pair(args)
    if args.which != "paper":
        raise InputError(f"report {args.which!r}: unknown (available: paper, pair)")
    if args.scene is not None or args.set:
        given = args.scene if args.scene is not None else f"--set {args.set[0]}"
        raise InputError(f"report paper: {given}: the paper report takes no scene or --set (it is the paper's "
                         "pair); gearwear report pair SCENE reports your own")
    out = _check_out(args.out, "report paper")
    assert out is not None
    files = report_paper.run_report(out, progress=True)
    for f in files:
        print(f"wrote {f}")
    return 0


def _cmd_report_pair(args: argparse.Namespace) -> int:
    """report pair SCENE: everything is validated (scene, --out, the bearing stiffness, the
    run-up's speeds) before any computation; then one progress bar over the parts."""
    import time

    from tqdm import tqdm

    from gearwear.reports import pair as report_pair
    from gearwear.jobs import sweep as sweep_job

    scene = _load(args)
    report_pair.check_scene(scene)
    out = _check_out(args.out, "report pair")
    t0 = time.perf_counter()
    settings = report_pair.SETTINGS
    prep = report_pair.prepare(scene, settings)
    steps = [*report_pair.PARTS, "figures"]
    with tqdm(total=len(steps), desc="report pair", unit="part", file=sys.stderr) as bar, \
            sweep_job.make_executor(1) as executor:
        def step(name: str) -> None:
            bar.n = steps.index(name)
            bar.set_postfix_str(name)

        def fe_progress(done: int, total: int) -> None:
            bar.set_postfix_str(f"pair FE position {done}/{total}")

        rep = report_pair.compute(prep, executor, step, fe_progress)
        doc = report_pair.document(rep)
        step("figures")
        inputs = {**io.scene_inputs(scene), "pair": _pair_inputs(scene), "settings": doc["settings"]}
        wall = report_pair.timing(rep)
        files = _write(out, "report pair", scene, inputs, lambda d: report_pair.write(doc, d),
                       {**wall, "total_s": time.perf_counter() - t0})
        bar.n = len(steps)
        bar.refresh()
    _print_report_pair(doc, wall)
    for f in files:
        print(f"wrote {f}")
    return 0


def _print_report_pair(doc: dict, wall: dict) -> None:
    from gearwear.reports import pair as report_pair

    print(f"{'method':<24}{'mean N/m':>12}{'vs FE %':>9}{'STE p-p um':>12}{'wall s':>9}")
    for r in doc["stiffness"]:
        vs = f"{'ref':>9}" if r["method"] == report_pair.REFERENCE else f"{r['mean_vs_fe_pct']:>+9.1f}"
        print(f"{r['label'].split(' (')[0]:<24}{r['mean_N_per_m']:>12.4e}{vs}"
              f"{r['ste_peak_to_peak_um']:>12.3f}{wall.get('stiffness ' + r['method'] + ' s', float('nan')):>9.2f}")
    ru = doc["runup"]
    print(f"run-up {ru['speeds_rpm'][0]:.0f}-{ru['speeds_rpm'][-1]:.0f} rpm ({len(ru['speeds_rpm'])} speeds, up): "
          f"K_v max {ru['K_v_max']:.4f} at {ru['K_v_max_speed_rpm']:.0f} rpm; ISO 6336 n_E1 "
          f"{ru['iso6336']['n_E1_driver_rpm']:.0f} rpm (driver), ISO K_v max {ru['K_v_iso_max']:.4f}")
    print(f"wall time {wall['computation s']:.1f} s (computation)")
    print_assumed(doc["assumptions"])
    for w in doc["warnings"]:
        print(f"warning: {w}")


def _int_arg(name: str, text, lo: int, hi: int) -> int:
    try:
        v = int(str(text))
    except ValueError:
        raise InputError(f"{name} = {text!r}: must be a whole number in [{lo}, {hi}]") from None
    if not lo <= v <= hi:
        raise InputError(f"{name} = {v}: must be a whole number in [{lo}, {hi}]")
    return v


def _pair_inputs(scene) -> dict:
    p = scene.pair
    return {"teeth": list(p.teeth), "module_mm": p.module_m * 1e3,
            "pressure_angle_deg": round(p.pressure_angle_rad * 180 / 3.141592653589793, 12),
            "face_width_mm": p.face_width_m * 1e3, "addendum_coefficient": p.addendum_coefficient,
            "dedendum_coefficient": p.dedendum_coefficient,
            "rack_tip_radius_coefficient": p.rack_tip_radius_coefficient,
            "profile_shift": list(p.profile_shift), "hub_radius_mm": [h * 1e3 for h in p.hub_radius_m],
            "allow_undercut": p.allow_undercut,
            "youngs_modulus_GPa": _one_or_two([m.youngs_modulus_Pa / 1e9 for m in p.materials]),
            "poisson_ratio": _one_or_two([m.poisson_ratio for m in p.materials]),
            **({"centre_distance_mm": p.installed_centre_distance_m * 1e3}
               if p.installed_centre_distance_m is not None else {})}


def _one_or_two(values: list) -> Any:
    """A per-gear value as the scene writes it: one value for both gears, else [pinion, gear]."""
    return values[0] if values[0] == values[1] else values


def _print_geometry(s: dict) -> None:
    g0, g1 = s["gears"]
    rows = [
        ("teeth (pinion, gear)", f"{g0['teeth']}, {g1['teeth']}"),
        ("base radius (mm)", f"{g0['base_radius_mm']:.4f}, {g1['base_radius_mm']:.4f}"),
        ("pitch radius (mm)", f"{g0['pitch_radius_mm']:.4f}, {g1['pitch_radius_mm']:.4f}"),
        ("tip radius (mm)", f"{g0['tip_radius_mm']:.4f}, {g1['tip_radius_mm']:.4f}"),
        ("root radius (mm)", f"{g0['root_radius_mm']:.4f}, {g1['root_radius_mm']:.4f}"),
        ("form radius / SAP (mm)", f"{g0['form_radius_mm']:.4f} / {g0['start_of_active_profile_mm']:.4f}, "
                                   f"{g1['form_radius_mm']:.4f} / {g1['start_of_active_profile_mm']:.4f}"),
        ("pitch thickness (mm)", f"{g0['pitch_thickness_mm']:.6f}, {g1['pitch_thickness_mm']:.6f}"),
        ("HPSTC diameter (mm)", ", ".join("-" if g["hpstc_diameter_mm"] is None else f"{g['hpstc_diameter_mm']:.4f}"
                                          for g in (g0, g1))),
        ("undercut", f"{g0['undercut']}, {g1['undercut']}"),
        ("body mass (kg)", f"{g0['mass_kg']:.4g}, {g1['mass_kg']:.4g}  ({s['bodies_from']['mass_kg']})"),
        ("body inertia (kg m^2)", f"{g0['inertia_kg_m2']:.4g}, {g1['inertia_kg_m2']:.4g}  "
                                  f"({s['bodies_from']['inertia_kg_m2']})"),
        ("bearing clearance (um)", f"{s['clearance_um']:g}"),
        ("centre distance (mm)", f"{s['centre_distance_mm']:.6f}  (nominal {s['nominal_centre_distance_mm']:.6f}; "
                                 "the stiffness and the dynamics run at it)"),
        ("loaded centre distance (mm)", "- (no bearing stiffness given)" if s["loaded_centre_distance_mm"] is None
         else f"{s['loaded_centre_distance_mm']:.6f}  (under {s['torque_Nm']:g} N m with the bearings' elastic "
              f"deflection, k_b {s['bearing_stiffness_N_per_m']:.3g} N/m: a state of the dynamic model)"),
        ("operating pressure angle (deg)", f"{s['operating_pressure_angle_deg']:.6f}"),
        ("contact ratio", f"{s['contact_ratio']:.6f}  (nominal {s['nominal_contact_ratio']:.6f})"),
        ("contact line length (mm)", f"{s['contact_line_length_mm']:.6f}"),
        ("normal backlash (um)", f"{s['backlash_um']:.4f}"),
        ("wear", f"{s['wear']}, max depth {s['max_wear_depth_um']:.3f} um"),
    ]
    if "mesh" in s:
        m = s["mesh"]
        rows.append(("pinion mesh", f"{m['elements']} P2 triangles, {m['nodes']} nodes, "
                                    f"{m['area_mm2']:.3f} mm^2, built in {m['build_s']:.2f} s"))
    w = max(len(r[0]) for r in rows)
    for k, v in rows:
        print(f"{k:<{w}}  {v}")
    print_assumed(s.get("assumptions", []))
    for note in s.get("warnings", []):
        print(f"warning: {note}")
    for f in s.get("files", []):
        print(f"wrote {f}")


SCHEDULER_HELP = ("run on Dask instead of local processes: local[:N] starts a LocalCluster of N worker processes "
                  "(default: all cores) on 127.0.0.1 for this run, ADDRESS (tcp://host:8786) connects to a running "
                  "scheduler, which must answer and have a worker within 10 s; needs the optional extra "
                  "gearwear[dask]")

ALLOW_LARGE_HELP = ("run more than 2000 grid points (run-up: speeds x points x directions), refused without it; "
                    "a run estimated to take over a minute states its estimate on stderr once its first point is done")

SET_HELP = ("override a scene key by its dotted path, e.g. --set operating.speed_rpm=6000 "
            "--set effects.backlash.initial_um=50; KEY=none removes a key or an effect, e.g. "
            "--set effects.backlash=none (repeatable; validated like the file; see gearwear scene --schema)")


def _scene_options(sp: argparse.ArgumentParser, default: str, multi: bool = False,
                   aliases: tuple[str, ...] = ("wear", "clearance", "torque")) -> None:
    """The scene argument, --set, and the short flags that are aliases of --set."""
    sp.add_argument("scene", nargs="?", help=f"scene TOML file or built-in scene name (default: {default}; "
                                             "list: gearwear scene --list)")
    sp.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help=SET_HELP)
    many = " (one or more: each is overlaid)" if multi else ""
    if "wear" in aliases:
        sp.add_argument("--wear", nargs="+" if multi else None, help="alias of --set effects.wear=...: unworn | "
                        f"mild | severe, a depth like 25um, or running hours like 500h{many}")
    if "clearance" in aliases:
        sp.add_argument("--clearance-um", nargs="+" if multi else None, help="alias of --set "
                        f"effects.bearing_clearance.clearance_um=X, bearing radial clearance in um{many}")
    if "torque" in aliases:
        sp.add_argument("--torque-Nm", help="alias of --set operating.torque_Nm=X, pinion torque in N m")


def runup_directions() -> tuple[str, ...]:
    from gearwear.jobs.runup import DIRECTIONS

    return DIRECTIONS


class _Parser(argparse.ArgumentParser):
    """argparse with the one-line error of every other bad input (no usage block)."""

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"gearwear: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="gearwear", description=(
        "FE-verified mesh stiffness and dynamics of spur gears with wear, backlash and bearing "
        "clearance. Without a file every command uses the built-in paper pair (Zhang et al. 2019, Table 2)."))
    p.add_argument("--version", action="version", version=f"gearwear {__version__}")
    p.add_argument("--debug", action="store_true", help="show Python tracebacks instead of one-line errors")
    sub = p.add_subparsers(dest="command", required=True)

    g = sub.add_parser("geometry", help="tooth profile, operating geometry, wear and gear mesh",
                       description="Generate the rack-cut tooth profile (involute + trochoidal fillet), the "
                                   "operating geometry at a bearing clearance (paper Eqs. 11-16), the worn "
                                   "flank, and a P2 Gmsh mesh of the whole pinion.")
    _scene_options(g, "paper-default")
    g.add_argument("--mesh-size-mm", default="2.5", help="global element size of the pinion mesh, in [0.25, 10] mm "
                   "(default 2.5); fillets 0.4 mm, load point 0.2 mm")
    g.add_argument("--no-mesh", action="store_true", help="with --out: skip the Gmsh mesh (without --out none is "
                                                          "built: the table needs none)")
    g.add_argument("--out", help="output folder for profile.csv, tooth.png, pinion_mesh.vtu, summary.json")
    g.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    g.set_defaults(func=_cmd_geometry)

    st = sub.add_parser("stiffness", help="time-varying mesh stiffness curves (Ishikawa, energy, ISO 6336)",
                        description="Mesh stiffness k_h over one mesh period with load sharing at the operating "
                                    "torque, wear gaps and tip-corner contact; loaded static transmission error. "
                                    "Several --wear or --clearance-um values overlay the curves (paper Figs. 6, "
                                    "16, 17).")
    _scene_options(st, "paper-default", multi=True)
    st.add_argument("--method", nargs="+", default=["ishikawa"],
                    help="one or more (overlaid; default ishikawa): " + " | ".join(
                        f"{m}: {SOURCES[m].title}" for m in METHODS))
    st.add_argument("--points", help=f"uniform angles per mesh period for every method (>= 8; default {TABLE_POINTS}, "
                                     f"{SOURCES['fem'].default_points} for fem; the analytic methods add the "
                                     "breakpoints of the load sharing as nodes)")
    st.add_argument("--out", help="output folder for CSV, JSON sidecars and PNGs")
    st.add_argument("--fields", nargs="+", help="with --method fem: position indices (0 .. points-1, over the "
                                                "revolution with a fault) whose displacement and stress fields "
                                                "are written as .vtu for ParaView")
    st.add_argument("--json", action="store_true", help="print one JSON object (first curve + 'curves')")
    st.set_defaults(func=_cmd_stiffness)

    v = sub.add_parser("verify", help="analytic (Ishikawa, energy) vs FE tooth compliance, FE convergence",
                       description="FE single-tooth compliance on the full gear (bore fixed, plane stress, P2) "
                                   "at load positions from SAP to tip, against Ishikawa delta_1 + delta_2 and the "
                                   "energy method, per wear phase; h/p convergence with Richardson extrapolation. "
                                   "Writes verification.md, compliance.png, convergence.png, verification.json.")
    _scene_options(v, "paper-default", multi=True, aliases=("wear", "torque"))
    v.add_argument("--positions", default="21", help="load positions from SAP to tip (default 21)")
    v.add_argument("--no-convergence", action="store_true", help="skip the h/p convergence study (~1-3 min)")
    v.add_argument("--out", help="output folder")
    v.add_argument("--json", action="store_true", help="print one JSON object")
    v.set_defaults(func=_cmd_verify)

    c = sub.add_parser("calibrate", help="FE-calibrated mesh stiffness tables (cached by input hash)",
                       description="Mesh stiffness tables from the Ishikawa model with the tooth compliance "
                                   "corrected to FE (fitted on the even load positions, checked on the odd ones). "
                                   "Tables are cached by the SHA-256 of their inputs ($GEARWEAR_CACHE or "
                                   "~/.cache/gearwear/tables); these are what scenes with "
                                   "mesh_stiffness.source = \"calibrated\" use.")
    _scene_options(c, "paper-default", multi=True)
    c.add_argument("--points", default=str(TABLE_POINTS), help=f"uniform angles per mesh period (default "
                                                                 f"{TABLE_POINTS}; the breakpoints come on top)")
    c.add_argument("--refresh", action="store_true", help="recompute even if a cached table exists")
    c.add_argument("--workers", help="solve the FE runs and pair positions on N local worker processes (default: "
                                     "in this process, where every gear body is built once for all wear states)")
    c.add_argument("--scheduler", help=SCHEDULER_HELP)
    c.add_argument("--out", help="copy the tables (CSV + JSON sidecar) here")
    c.add_argument("--json", action="store_true", help="print one JSON object")
    c.set_defaults(func=_cmd_calibrate)

    sm = sub.add_parser("simulate", help="6-DOF gear-pair dynamics of a scene (only the effects it names)",
                        description="Simulate the bending-torsion gear-pair model (paper Eqs. 17-20, typos fixed) "
                                    "with the effects the scene names. Without a scene: the paper's severe-wear "
                                    "case with 10 um bearing clearance (built-in scene paper-wear-severe). Writes "
                                    "signals (NPZ + CSV), time-trace and spectrum PNGs and summary.json.")
    _scene_options(sm, "paper-wear-severe")
    sm.add_argument("--out", help="output folder")
    sm.add_argument("--json", action="store_true", help="print one JSON object")
    sm.set_defaults(func=_cmd_simulate)

    sw = sub.add_parser("sweep", help="run a scene over a parameter grid in parallel (harmonics vs parameter)",
                        description="Sweep scene keys: --set KEY=START:STOP:N (linear) or KEY=a,b,c (values); "
                                    "KEY=VALUE fixes a key. Runs the grid on local cores (or a Dask cluster) with "
                                    "a progress bar and writes sweep.csv (metrics and harmonic amplitudes per "
                                    "point) and harmonics-versus-parameter PNGs (paper Figs. 8-14, 19-25).")
    _scene_options(sw, "paper-wear-severe")
    sw.add_argument("--workers", help="local worker processes (default: all cores)")
    sw.add_argument("--scheduler", help=SCHEDULER_HELP)
    sw.add_argument("--allow-large", action="store_true", help=ALLOW_LARGE_HELP)
    sw.add_argument("--out", help="output folder")
    sw.add_argument("--json", action="store_true", help="print one JSON object")
    sw.set_defaults(func=_cmd_sweep)

    ru = sub.add_parser("runup", help="speed run-up/down with natural continuation: K_v, jumps, ISO 6336 K_v",
                        description="Run a scene over a speed range, each speed starting from the steady state of "
                                    "the previous one: --set operating.speed_rpm=START:STOP:N (other swept keys give "
                                    "independent run-ups). Steady state is detected (Poincare-section residual) and "
                                    "labelled periodic, quasi-periodic or chaotic. Writes runup.csv (K_v, DTE, "
                                    "contact loss, harmonics 1-10 per speed), runup_summary.json (jump bands, ISO "
                                    "6336-1 n_E1), the K_v plot, the order maps and the Campbell diagrams.")
    _scene_options(ru, "paper-default")
    ru.add_argument("--direction", default="both", choices=runup_directions(),
                    help="sweep up, down or both (default both: the jump band is where they differ)")
    ru.add_argument("--tolerance", default="1e-6", help="periodicity tolerance of the steady state: estimated "
                    "distance of the Poincare section from the periodic orbit, relative to the motion's range "
                    "(default 1e-6)")
    ru.add_argument("--max-periods", default="1500", help="table periods integrated at most per speed before the "
                    "kept window (default 1500); not settled by then: quasi-periodic, chaotic or unsettled")
    ru.add_argument("--keep-periods", default="32", help="table periods in the kept window the metrics come from "
                    "(default 32, rounded up to a multiple of the period found)")
    ru.add_argument("--jump-tolerance", default="0.01", help="up and down K_v differing by more than this fraction "
                    "mark a jump band (default 0.01)")
    ru.add_argument("--workers", help="local worker processes (default: all cores)")
    ru.add_argument("--scheduler", help=SCHEDULER_HELP)
    ru.add_argument("--allow-large", action="store_true", help=ALLOW_LARGE_HELP)
    ru.add_argument("--out", help="output folder")
    ru.add_argument("--json", action="store_true", help="print one JSON object (the summary)")
    ru.set_defaults(func=_cmd_runup)

    # argparse %-formats help texts: a literal percent sign is written %%
    dg = sub.add_parser("diagnose", help="estimate wear depth and bearing clearance (and torque) from a measured "
                                         "vibration, with 95 %% intervals and an identifiability verdict",
                        description="Fit the 6-DOF model to measured mesh harmonics (and mean values) through a "
                                    "cached surrogate of the model over the unknowns; print estimates, 95 % "
                                    "intervals and which unknown the measurement cannot resolve. --plan: which "
                                    "signals, speeds and torques would separate the unknowns. The scene fixes "
                                    "everything known (default: paper-wear-severe). Writes diagnosis.json, "
                                    "features.csv, corner.png, features.png (plan: plan.json, plan.csv).")
    _scene_options(dg, "paper-wear-severe", aliases=("torque",))
    dg.add_argument("--measured", help="CSV: a time series (time_s plus any of y_p_um, x_p_um, delta_um, F_m_N; "
                                       "displacements, so integrate a housing accelerometer upstream) or a "
                                       "harmonic table (signal,harmonic,amplitude)")
    dg.add_argument("--plan", action="store_true", help="no measurement: rank signals, speeds and torques by how "
                                                        "well they would separate the unknowns (Fisher information)")
    dg.add_argument("--unknowns", default="wear,clearance", help="comma-separated, of wear (wear_max_depth_um), "
                                                                 "clearance (clearance_um), torque (torque_Nm); "
                                                                 "default wear,clearance")
    dg.add_argument("--wear-range-um", help="prior range LO:HI of the maximum wear depth (default 0:40; 0.1:40 "
                                            "with transmission_error)")
    dg.add_argument("--clearance-range-um", help="prior range LO:HI of the bearing clearance (default 0:50)")
    dg.add_argument("--torque-range-Nm", help="prior range LO:HI of the torque (default 0.5 to 1.5 x the scene's)")
    dg.add_argument("--noise-pct", default="2", help="relative measurement noise of each feature, %% (default 2)")
    dg.add_argument("--noise-floor-pct", default="0.5", help="absolute noise floor, %% of the largest measured "
                                                             "harmonic of the same signal (default 0.5)")
    dg.add_argument("--design-points", help="surrogate design size, a power of two (default 256 for two unknowns, "
                                            "512 for three; --plan 128 / 256)")
    dg.add_argument("--workers", help="local worker processes for building a surrogate (default: all cores)")
    dg.add_argument("--speeds-rpm", help="--plan: candidate pinion speeds, comma-separated (default 0.5, 1, 2 x "
                                         "the scene's)")
    dg.add_argument("--torques-Nm", help="--plan: candidate torques, comma-separated (default 0.5, 1, 2 x the "
                                         "scene's)")
    dg.add_argument("--refresh", action="store_true", help="rebuild the surrogate even if it is cached")
    dg.add_argument("--out", help="output folder")
    dg.add_argument("--json", action="store_true", help="print one JSON object")
    dg.set_defaults(func=_cmd_diagnose)

    sc = sub.add_parser("scene", help="print a fully resolved scene (every default), the JSON Schema, or the "
                                      "built-in scene names",
                        description="gearwear scene NAME|FILE [--set ...]: the scene as the run sees it, every "
                                    "default filled in (TOML, or --json). gearwear scene --schema: the JSON Schema "
                                    "of a scene document, for completion and checking in editors. "
                                    "gearwear scene --list: the built-in scenes.")
    sc.add_argument("scene", nargs="?", help="scene TOML file or built-in scene name (default: paper-default)")
    sc.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help=SET_HELP)
    sc.add_argument("--schema", action="store_true", help="print the JSON Schema of a scene document")
    sc.add_argument("--list", action="store_true", help="list the built-in scene names")
    sc.add_argument("--reference", action="store_true", help="print the scene reference (Markdown, "
                                                                  "docs/scene-reference.md)")
    sc.add_argument("--json", action="store_true", help="print JSON instead of TOML")
    sc.set_defaults(func=_cmd_scene)

    rp = sub.add_parser("report", help="a one-page report of your gear pair (report pair SCENE), or the paper's "
                                       "figures with a trends table (report paper)",
                        description="report pair SCENE: a one-page report of your own pair (README.md, report.json "
                                    "and PNGs): the geometry of both gears and the mesh, the mesh stiffness by every "
                                    "method including the pair FE, the loaded transmission error against load, a "
                                    "run-up around ISO 6336's resonance with ISO's K_v next to it, and every value "
                                    "assumed (~30 s; needs bodies.bearing_stiffness_N_per_m). "
                                    "report paper: every numerical figure of Zhang et al. (2019) regenerated with "
                                    "FE-calibrated stiffness and the 6-DOF model, with a table comparing each of the "
                                    "paper's trend claims with this tool's result (a few minutes).")
    rp.add_argument("which", choices=["paper", "pair"], help="which report")
    _scene_options(rp, "paper-default; report pair only", aliases=())
    rp.add_argument("--out", required=True, help="output folder (the repository's copy of report paper is "
                                                 "reports/paper)")
    rp.set_defaults(func=_cmd_report)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run one command. Exit status: 0 done, 2 bad input (one line naming the key, value,
    unit and allowed range; nothing written), 1 an internal failure (one line; the
    traceback only with --debug), 130 interrupted by SIGINT (Ctrl-C) and 143 by SIGTERM
    (one line; nothing half-written, worker processes stopped).

    The signal handlers come first (core.interrupts.handled): a signal during the imports
    of a command is handled like one during its computation."""
    from gearwear.core import interrupts

    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv  # accepted anywhere on the line, not only before the command
    with interrupts.handled():
        written = len(io.SWAPPED_IN)
        try:
            _safe_streams()
            return _run(argv, debug)
        except KeyboardInterrupt as exc:  # also one that arrives while another error is reported
            if debug:
                raise
            sig = interrupts.signal_of(exc)
            done = io.SWAPPED_IN[written:]
            what = f"after writing {', '.join(map(str, done))}" if done else "nothing was written or replaced"
            _say(f"gearwear: interrupted by {sig.name}{' (Ctrl-C)' if sig.name == 'SIGINT' else ''}; {what}")
            return interrupts.EXIT_STATUS[sig]
        finally:
            if isinstance(sys.stderr, _LineStart):
                sys.stderr = sys.stderr._stream


def _say(line: str) -> None:
    """One line on stderr, on a line of its own."""
    if isinstance(sys.stderr, _LineStart):
        sys.stderr.say(line)
    else:
        print(line, file=sys.stderr, flush=True)


class _LineStart:
    """sys.stderr, remembering whether the last character written ended a line, so that a
    final message starts on a line of its own even if a progress bar the signal hit was
    left unfinished (:meth:`say`)."""

    def __init__(self, stream):
        self._stream = stream
        self._last = "\n"

    def write(self, text: str) -> int:
        if text:
            self._last = text[-1]
        return self._stream.write(text)

    def say(self, line: str) -> None:
        self.write(("" if self._last == "\n" else "\n") + line + "\n")
        self.flush()

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _safe_streams() -> None:
    """Printing never fails on a character the terminal's encoding lacks (an --out named
    "résultats" under LC_ALL=C or PYTHONIOENCODING=ascii): it is written escaped instead of
    ending the command after its files were written."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None and stream.errors in ("strict", None):
            with contextlib.suppress(ValueError, OSError):
                reconfigure(errors="backslashreplace")
    if not isinstance(sys.stderr, _LineStart):
        sys.stderr = _LineStart(sys.stderr)


def _run(argv: list[str], debug: bool) -> int:
    parser = build_parser()
    args = parser.parse_args([a for a in argv if a != "--debug"])
    args.debug = debug
    try:
        return args.func(args)
    except InputError as exc:
        if args.debug:
            raise
        _say(f"gearwear: error: {renamed(exc, FLAG_NAMES)}")
        return 2
    except BrokenPipeError:  # output piped into head & co.: not an error of ours
        sys.stderr.close()
        return 0
    except Exception as exc:
        # a mesher failure is ours too: every shape reaching the FE passed the geometry's
        # checks, so a shape Gmsh cannot mesh is a bug, never the user's input
        if args.debug:
            raise
        where = exc.__traceback__
        while where is not None and where.tb_next is not None:
            where = where.tb_next
        at = f" at {Path(where.tb_frame.f_code.co_filename).name}:{where.tb_lineno}" if where else ""
        msg = str(exc).splitlines()[0] if str(exc) else ""
        _say(f"gearwear: internal error: {type(exc).__name__}{at}: {msg} (this is a bug; rerun with --debug "
             "for the traceback and report it)")
        return 1


#: the lower layers' own parameter names -> the command-line flags that set them
FLAG_NAMES = {"method": "--method", "fields": "--fields", "points": "--points", "positions": "--positions"}


if __name__ == "__main__":
    sys.exit(main())
