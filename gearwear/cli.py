"""The ``gearwear`` command line.

Every command works without a file (the built-in paper pair). A bad input prints
one line ``gearwear: error: <key> = <value> <unit>: <allowed range>`` and exits 2;
nothing is written before all inputs are validated, and files are written atomically.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from gearwear.core.validation import InputError

from . import __version__


def _float_arg(name: str, unit: str, lo: float = 0.0):
    def parse(text: str) -> float:
        try:
            v = float(text)
        except ValueError:
            raise InputError(f"{name} = {text!r}: must be a number in [{lo:g}, inf) {unit}".rstrip()) from None
        if not v >= lo or v != v:
            raise InputError(f"{name} = {v:g} {unit}: must be in [{lo:g}, inf) {unit}")
        return v
    return parse


def _cmd_geometry(args: argparse.Namespace) -> int:
    from gearwear.geometry.wear import parse_wear_arg

    from . import geometry_job
    from .scene import load_scene

    scene = load_scene(args.pair)
    torque = scene.operating.torque_Nm if args.torque_Nm is None else _float_arg("--torque-Nm", "N m")(args.torque_Nm)
    clearance_um = (scene.clearance_m * 1e6 if args.clearance_um is None
                    else _float_arg("--clearance-um", "um")(args.clearance_um))
    wear = scene.wear
    if args.wear is not None:
        wear = parse_wear_arg(args.wear, torque, scene.operating.speed_rpm)
    mesh_size = _float_arg("--mesh-size-mm", "mm", 1e-3)(args.mesh_size_mm)
    res = geometry_job.compute(scene, wear, clearance_um * 1e-6, torque, build_mesh=not args.no_mesh,
                               mesh_size_mm=mesh_size)
    inputs = {"scene": scene.name, "pair": _pair_inputs(scene), "wear": wear.label if wear else "unworn",
              "wear_model": wear.model if wear else None, "clearance_um": clearance_um, "torque_Nm": torque,
              "bearing_stiffness_N_per_m": scene.bodies.bearing_stiffness_N_per_m,
              "initial_backlash_um": scene.initial_backlash_m * 1e6, "mesh_size_mm": mesh_size}
    files = geometry_job.write(res, Path(args.out), inputs) if args.out else []
    summary = res.summary()
    summary["files"] = [str(f) for f in files]
    if args.json:
        print(json.dumps(summary, sort_keys=True))
    else:
        _print_geometry(summary)
    return 0


def _split_multi(values: list[str] | None) -> list[str]:
    out: list[str] = []
    for v in values or []:
        out += [x for x in v.split(",") if x.strip()]
    return out


def _cmd_stiffness(args: argparse.Namespace) -> int:
    import math

    from gearwear.geometry.wear import parse_wear_arg

    from . import stiffness_job
    from .scene import load_scene

    scene = load_scene(args.pair)
    if args.method not in stiffness_job.METHODS:
        raise InputError(f"--method = {args.method!r}: must be one of {', '.join(stiffness_job.METHODS)}")
    torque = scene.operating.torque_Nm if args.torque_Nm is None else _float_arg("--torque-Nm", "N m")(args.torque_Nm)
    if not torque > 0:
        raise InputError(f"--torque-Nm = {torque:g} N m: must be in (0, 1e7] N m")
    if args.points is None:
        args.points = "24" if args.method == "fem" else "360"  # FE: 24 positions take ~10 s
    points = _int_arg("--points", args.points, 8, 1_000_000)
    wear_args = _split_multi(args.wear)
    wears = [parse_wear_arg(w, torque, scene.operating.speed_rpm) for w in wear_args] or [scene.wear]
    cl_args = _split_multi(args.clearance_um)
    clearances = ([_float_arg("--clearance-um", "um")(c) * 1e-6 for c in cl_args] or [scene.clearance_m])
    fields = [_int_arg("--fields", f, 0, points - 1) for f in _split_multi(args.fields)]
    if fields and (args.method != "fem" or not args.out):
        raise InputError(f"--fields = {','.join(map(str, fields))}: needs --method fem and --out")
    curves = stiffness_job.compute(scene.pair, args.method, wears, clearances, torque, points)
    inputs = {"scene": scene.name, "pair": _pair_inputs(scene), "method": args.method, "torque_Nm": torque,
              "points": points}
    files = stiffness_job.write(curves, Path(args.out), inputs) if args.out else []
    if fields:
        files += stiffness_job.write_fields(curves, Path(args.out), fields)
    summaries = [c.summary() for c in curves]
    if args.json:
        out = dict(summaries[0])
        out["curves"] = summaries
        out["files"] = [str(f) for f in files]
        print(json.dumps(out, sort_keys=True, allow_nan=False, default=lambda o: None))
    else:
        hdr = f"{'method':<9}{'wear':<9}{'clear um':>9}{'mean N/m':>12}{'min N/m':>12}{'max N/m':>12}" \
              f"{'eps':>8}{'double':>12}{'single':>12}{'wall ms':>9}"
        print(hdr)
        for s in summaries:
            dz = s["double_zone_mean_N_per_m"]
            print(f"{s['method']:<9}{s['wear']:<9}{s['clearance_um']:>9g}{s['mean_N_per_m']:>12.4e}"
                  f"{s['min_N_per_m']:>12.4e}{s['max_N_per_m']:>12.4e}{s['contact_ratio']:>8.4f}"
                  f"{(dz if math.isfinite(dz) else float('nan')):>12.4e}{s['single_zone_mean_N_per_m']:>12.4e}"
                  f"{s['wall_s'] * 1e3:>9.1f}")
        for f in files:
            print(f"wrote {f}")
    return 0


def _wear_list(args, scene, torque):
    from gearwear.geometry.wear import parse_wear_arg
    names = _split_multi(args.wear)
    return [None if w == "unworn" else parse_wear_arg(w, torque, scene.operating.speed_rpm) for w in names]


def _cmd_verify(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from . import verify_job
    from .scene import load_scene

    scene = load_scene(args.pair)
    from gearwear.geometry.wear import WearSpec
    wears = _wear_list(args, scene, scene.operating.torque_Nm) or [None, WearSpec(phase="mild"),
                                                                   WearSpec(phase="severe")]
    positions = _int_arg("--positions", args.positions, 5, 201)
    steps = len(wears) + (0 if args.no_convergence else 12)
    with tqdm(total=steps, desc="verify", unit="run", disable=args.json or None, file=sys.stderr) as bar:
        def progress(msg):
            bar.set_postfix_str(msg)
            bar.update(1)
        v = verify_job.run(scene.pair, wears, positions, convergence=not args.no_convergence, progress=progress)
    inputs = {"scene": scene.name, "pair": _pair_inputs(scene), "wear": [w.label if w else "unworn" for w in wears],
              "positions": positions, "convergence": not args.no_convergence}
    files = verify_job.write(v, Path(args.out), inputs) if args.out else []
    js = verify_job.to_json(v)
    js["files"] = [str(f) for f in files]
    if args.json:
        print(json.dumps(js, sort_keys=True, allow_nan=False, default=lambda o: None))
    else:
        print(f"{'wear':<9}{'FE s':>7}{'dofs':>9}{'Ishikawa-FE % (min..max)':>28}{'energy-FE % (min..max)':>26}")
        for ph in v.phases:
            di = 100 * (ph.ishikawa / ph.fem - 1)
            de = 100 * (ph.energy / ph.fem - 1)
            print(f"{ph.label:<9}{ph.fem_wall_s:>7.2f}{ph.dofs:>9}{di.min():>14.1f} .. {di.max():<11.1f}"
                  f"{de.min():>12.1f} .. {de.max():<11.1f}")
        if v.acceptance:
            a = v.acceptance
            print(f"FE convergence: two finest P2 levels differ by {a['finest_p2_change_pct']:.3f} %, default level "
                  f"{a['default_dofs']} dofs in {a['default_wall_s']:.2f} s")
        for f in files:
            print(f"wrote {f}")
    return 0


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from . import calibrate, io, tables
    from .scene import load_scene

    scene = load_scene(args.pair)
    torque = scene.operating.torque_Nm if args.torque_Nm is None else _float_arg("--torque-Nm", "N m")(args.torque_Nm)
    if not torque > 0:
        raise InputError(f"--torque-Nm = {torque:g} N m: must be in (0, 1e7] N m")
    points = _int_arg("--points", args.points, 8, 1_000_000)
    wears = _wear_list(args, scene, torque) or [scene.wear]
    cl_args = _split_multi(args.clearance_um)
    clearances = [_float_arg("--clearance-um", "um")(c) * 1e-6 for c in cl_args] or [scene.clearance_m]
    out = Path(args.out) if args.out else None
    rows, files = [], []
    for w in wears:
        cal = None
        for c in clearances:
            inputs = calibrate.table_inputs(scene.pair, w, c, torque, points, 21)
            hit = None if args.refresh else tables.cached(inputs)
            if hit is None and cal is None:
                cal = calibrate.run_fe(scene.pair, w)
            tab = hit or calibrate.calibrated_table(scene.pair, w, c, torque, points, calibration=cal,
                                                    refresh=args.refresh)
            key = tables.table_key(inputs)
            label = f"{w.label if w else 'unworn'}_clearance{c * 1e6:g}um"
            if out:
                src = tables.cache_dir() / f"{key}.csv"
                files.append(io.write_bytes(out / f"calibrated_{label}.csv", src.read_bytes()))
                files.append(io.write_bytes(out / f"calibrated_{label}.csv.json",
                                            Path(str(src) + ".json").read_bytes()))
            m = tab.meta
            rows.append({"wear": w.label if w else "unworn", "clearance_um": c * 1e6, "cache_hit": hit is not None,
                         "mean_N_per_m": tab.mean_N_per_m, "min_N_per_m": float(tab.k_N_per_m.min()),
                         "max_N_per_m": float(tab.k_N_per_m.max()),
                         "uncorrected_mean_N_per_m": m.get("uncorrected_mean_N_per_m"),
                         "check_residual": m.get("check_residual"), "fit_residual": m.get("fit_residual"),
                         "fe_estimated_relative_error": m.get("fe_estimated_relative_error"),
                         "input_sha256": m.get("input_sha256"), "points": int(len(tab.k_N_per_m))})
    if args.json:
        print(json.dumps({"tables": rows, "files": [str(f) for f in files]}, sort_keys=True,
                         allow_nan=False, default=lambda o: None))
    else:
        print(f"{'wear':<9}{'clear um':>9}{'mean N/m':>12}{'analytic':>12}{'check res %':>12}{'FE err %':>9}  cache")
        for r in rows:
            print(f"{r['wear']:<9}{r['clearance_um']:>9g}{r['mean_N_per_m']:>12.4e}"
                  f"{r['uncorrected_mean_N_per_m']:>12.4e}{100 * max(r['check_residual']):>12.2f}"
                  f"{100 * r['fe_estimated_relative_error']:>9.2f}  {'hit' if r['cache_hit'] else 'new'}")
        for f in files:
            print(f"wrote {f}")
    return 0


def _cmd_simulate(args: argparse.Namespace) -> int:
    from . import simulate_io, simulate_job
    from .scene import apply_overrides, load_scene_dict, scene_from_dict

    data, name = load_scene_dict(args.scene, default="paper-wear-severe")
    scene = scene_from_dict(apply_overrides(data, args.set), name=name)
    run = simulate_job.run(scene, on_compile=lambda msg: print(msg, file=sys.stderr, flush=True))
    summary = run.summary()
    files = simulate_io.write(run, Path(args.out), {"scene": name, "overrides": args.set or []}) if args.out else []
    summary["files"] = [str(f) for f in files]
    if args.json:
        print(json.dumps(summary, sort_keys=True, allow_nan=False, default=lambda o: None))
    else:
        simulate_io.print_summary(summary)
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from . import sweep
    from .scene import builtin_scene_names, load_scene_dict

    if args.scene and not Path(args.scene).exists() and args.scene in builtin_scene_names():
        data, name = load_scene_dict(None, default=args.scene)
    else:
        data, name = load_scene_dict(args.scene, default="paper-wear-severe")
    axes, fixed = [], []
    for item in args.set or []:
        spec = item.split("=", 1)[1].strip() if "=" in item else ""
        if spec[:1] in "[{\"'" or ("," not in spec and spec.count(":") != 2):
            fixed.append(item)
        else:
            axes.append(sweep.parse_axis(item))
    if not axes:
        raise InputError("--set: give at least one swept key, KEY=START:STOP:N or KEY=a,b,c")
    workers = _int_arg("--workers", args.workers, 1, 1024) if args.workers else None
    executor = sweep.make_executor(workers, args.scheduler)
    results = sweep.sweep(data, name, axes, fixed, executor=executor, progress=not args.json)
    executor.shutdown()
    inputs = {"scene": name, "axes": {a.key: list(a.values) for a in axes}, "fixed": fixed}
    files = sweep.write(axes, results, Path(args.out), inputs) if args.out else []
    if args.json:
        print(json.dumps({"points": results, "files": [str(f) for f in files]}, sort_keys=True,
                         allow_nan=False, default=lambda o: None))
    else:
        print(sweep.table_csv(axes, results).splitlines()[0][:200])
        for r in results:
            pt = ", ".join(f"{k}={v}" for k, v in r["point"].items())
            fm = r["harmonics"].get("F_m_N")
            extra = f"  F_m harmonics 1-4 (N): {', '.join(f'{x:.3g}' for x in fm[:4])}" if fm else ""
            print(f"{pt}: separation {100 * r['separation_fraction']:.2f} %{extra}")
        for f in files:
            print(f"wrote {f}")
    return 0


def _cmd_report(args: argparse.Namespace) -> int:
    from . import report_paper

    if args.which != "paper":
        raise InputError(f"report {args.which!r}: unknown (available: paper)")
    files = report_paper.run_report(Path(args.out), progress=True)
    for f in files:
        print(f"wrote {f}")
    return 0


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
            "allow_undercut": p.allow_undercut, "youngs_modulus_GPa": p.material.youngs_modulus_Pa / 1e9,
            "poisson_ratio": p.material.poisson_ratio}


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
        ("undercut", f"{g0['undercut']}, {g1['undercut']}"),
        ("bearing clearance (um)", f"{s['clearance_um']:g}  (torque {s['torque_Nm']:g} N m, "
                                   f"bearing stiffness {s['bearing_stiffness_N_per_m']:.3g} N/m)"),
        ("centre distance (mm)", f"{s['centre_distance_mm']:.6f}  (nominal {s['nominal_centre_distance_mm']:.6f})"),
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
    for f in s.get("files", []):
        print(f"wrote {f}")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="gearwear", description=(
        "FE-verified mesh stiffness and dynamics of spur gears with wear, backlash and bearing "
        "clearance. Without a file every command uses the built-in paper pair (Zhang et al. 2019, Table 2)."))
    p.add_argument("--version", action="version", version=f"gearwear {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    g = sub.add_parser("geometry", help="tooth profile, operating geometry, wear and gear mesh",
                       description="Generate the rack-cut tooth profile (involute + trochoidal fillet), the "
                                   "operating geometry at a bearing clearance (paper Eqs. 11-16), the worn "
                                   "flank, and a P2 Gmsh mesh of the whole pinion.")
    g.add_argument("pair", nargs="?", help="scene or pair TOML file (default: built-in paper pair)")
    g.add_argument("--wear", help="unworn | mild | severe, a depth like 25um, or running hours like 500h")
    g.add_argument("--clearance-um", help="bearing radial clearance BC in um (default: scene value or 0)")
    g.add_argument("--torque-Nm", help="static pinion torque for Eq. 11 and wear loads (default: scene, 40)")
    g.add_argument("--mesh-size-mm", default="2.5", help="element size far from fillets/load point (default 2.5)")
    g.add_argument("--no-mesh", action="store_true", help="skip the Gmsh mesh")
    g.add_argument("--out", help="output folder for profile.csv, tooth.png, pinion_mesh.vtu, summary.json")
    g.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    g.set_defaults(func=_cmd_geometry)

    st = sub.add_parser("stiffness", help="time-varying mesh stiffness curves (Ishikawa, energy, ISO 6336)",
                        description="Mesh stiffness k_h over one mesh period with load sharing at the operating "
                                    "torque, wear gaps and tip-corner contact; loaded static transmission error. "
                                    "Several --wear or --clearance-um values overlay the curves (paper Figs. 6, "
                                    "16, 17).")
    st.add_argument("pair", nargs="?", help="scene or pair TOML file (default: built-in paper pair)")
    st.add_argument("--method", default="ishikawa", help="ishikawa (paper Eqs. 2-6, default) | energy "
                                                         "(potential energy + Sainsot foundation) | iso6336 | fem "
                                                         "(resolved FE contact of both gear bodies, ~10 s)")
    st.add_argument("--wear", nargs="+", help="one or more of unworn, mild, severe, 25um, 500h (or comma-separated)")
    st.add_argument("--clearance-um", nargs="+", help="one or more bearing clearances in um")
    st.add_argument("--torque-Nm", help="pinion torque (default: scene, 40)")
    st.add_argument("--points", help="angles per mesh period (>= 8; default 360, 24 for fem)")
    st.add_argument("--out", help="output folder for CSV, JSON sidecars and PNGs")
    st.add_argument("--fields", nargs="+", help="with --method fem: position indices (0 .. points-1) whose "
                                                "displacement and stress fields are written as .vtu for ParaView")
    st.add_argument("--json", action="store_true", help="print one JSON object (first curve + 'curves')")
    st.set_defaults(func=_cmd_stiffness)

    v = sub.add_parser("verify", help="analytic (Ishikawa, energy) vs FE tooth compliance, FE convergence",
                       description="FE single-tooth compliance on the full gear (bore fixed, plane stress, P2) "
                                   "at load positions from SAP to tip, against Ishikawa delta_1 + delta_2 and the "
                                   "energy method, per wear phase; h/p convergence with Richardson extrapolation. "
                                   "Writes verification.md, compliance.png, convergence.png, verification.json.")
    v.add_argument("pair", nargs="?", help="scene or pair TOML file (default: built-in paper pair)")
    v.add_argument("--wear", nargs="+", help="phases to verify (default: unworn,mild,severe)")
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
    c.add_argument("pair", nargs="?", help="scene or pair TOML file (default: built-in paper pair)")
    c.add_argument("--wear", nargs="+", help="wear phases / depths / hours (default: the scene's)")
    c.add_argument("--clearance-um", nargs="+", help="bearing clearances in um (default: the scene's)")
    c.add_argument("--torque-Nm", help="pinion torque (default: scene, 40)")
    c.add_argument("--points", default="360", help="angles per mesh period (default 360)")
    c.add_argument("--refresh", action="store_true", help="recompute even if a cached table exists")
    c.add_argument("--out", help="copy the tables (CSV + JSON sidecar) here")
    c.add_argument("--json", action="store_true", help="print one JSON object")
    c.set_defaults(func=_cmd_calibrate)

    sm = sub.add_parser("simulate", help="6-DOF gear-pair dynamics of a scene (only the effects it names)",
                        description="Simulate the bending-torsion gear-pair model (paper Eqs. 17-20, typos fixed) "
                                    "with the effects the scene names. Without a scene: the paper's severe-wear "
                                    "case with 10 um bearing clearance (built-in scene paper-wear-severe). Writes "
                                    "signals (NPZ + CSV), time-trace and spectrum PNGs and summary.json.")
    sm.add_argument("scene", nargs="?", help="scene TOML file (default: built-in paper-wear-severe)")
    sm.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a scene key by its dotted path, e.g. --set operating.speed_rpm=6000 "
                         "--set effects.backlash.initial_um=50 (repeatable; validated like the file)")
    sm.add_argument("--out", help="output folder")
    sm.add_argument("--json", action="store_true", help="print one JSON object")
    sm.set_defaults(func=_cmd_simulate)

    sw = sub.add_parser("sweep", help="run a scene over a parameter grid in parallel (harmonics vs parameter)",
                        description="Sweep scene keys: --set KEY=START:STOP:N (linear) or KEY=a,b,c (values); "
                                    "KEY=VALUE fixes a key. Runs the grid on local cores (or a Dask cluster) with "
                                    "a progress bar and writes sweep.csv (metrics and harmonic amplitudes per "
                                    "point) and harmonics-versus-parameter PNGs (paper Figs. 8-14, 19-25).")
    sw.add_argument("scene", nargs="?", help="scene TOML file or built-in scene name (default: paper-wear-severe)")
    sw.add_argument("--set", action="append", metavar="KEY=SPEC", help="swept or fixed key (repeatable)")
    sw.add_argument("--workers", help="local worker processes (default: all cores)")
    sw.add_argument("--scheduler", help="Dask scheduler ADDRESS (needs the optional extra gearwear[dask])")
    sw.add_argument("--out", help="output folder")
    sw.add_argument("--json", action="store_true", help="print one JSON object")
    sw.set_defaults(func=_cmd_sweep)

    rp = sub.add_parser("report", help="regenerate the paper's figures with a trends table (report paper)",
                        description="report paper: every numerical figure of Zhang et al. (2019) regenerated with "
                                    "FE-calibrated stiffness and the 6-DOF model, with a table comparing each of the "
                                    "paper's trend claims with this tool's result (a few minutes).")
    rp.add_argument("which", choices=["paper"], help="which report")
    rp.add_argument("--out", default="reports/paper", help="output folder (default reports/paper)")
    rp.set_defaults(func=_cmd_report)
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except InputError as exc:
        print(f"gearwear: error: {exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # mesh failures etc. carry their own one-line message
        from gearwear.geometry import mesh as _mesh
        if isinstance(exc, getattr(_mesh, "MeshError", ())):
            print(f"gearwear: error: {exc}", file=sys.stderr)
            return 2
        raise


if __name__ == "__main__":
    sys.exit(main())
