"""The ``gearwear diagnose`` command: option checks, the run, its files and its printout.

gearwear.cli.app parses the line and checks the generic flags; this module checks what is
particular to the diagnosis (unknowns, prior ranges, --set of an unknown's key) before
any simulation, runs the diagnosis or the plan, and writes:

* diagnose: ``diagnosis.json`` (estimates, intervals, identifiable, verdict, the
  surrogate's held-out error, the noise model), ``features.csv`` (+ sidecar: measured,
  fitted, sigmas per feature), ``corner.png``, ``features.png``;
* plan: ``plan.json``, ``plan.csv`` (+ sidecar).

Wall times go to timing.json and --json only.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gearwear import io
from gearwear.cli.common import (
    alias_sets,
    bounded_float,
    check_out,
    output_options,
    scene_options,
    worker_count,
    write_output,
)
from gearwear.core.validation import InputError
from gearwear.diagnose import job as dj
from gearwear.diagnose import surrogate as ds
from gearwear.diagnose.features import Measurement

#: default design sizes (Sobol points; the 2^d corners come on top) and held-out runs
DESIGN_POINTS = {1: 64, 2: 256, 3: 512}
PLAN_DESIGN_POINTS = {1: 32, 2: 128, 3: 256}
HOLDOUT_POINTS = {1: 16, 2: 32, 3: 64}
PLAN_SPEED_FACTORS = (0.5, 1.0, 2.0)
PLAN_TORQUE_FACTORS = (0.5, 1.0, 2.0)


def parse_unknowns(text: str) -> list[ds.Unknown]:
    names = [x.strip() for x in text.split(",") if x.strip()]
    bad = [n for n in names if n not in ds.UNKNOWNS]
    if not names or bad:
        raise InputError(
            f"--unknowns = {text}: {'no unknown given' if not names else repr(bad[0]) + ' is not one'}; "
            f"choose from {', '.join(ds.UNKNOWNS)} (comma-separated)"
        )
    if len(set(names)) != len(names):
        raise InputError(f"--unknowns = {text}: names an unknown twice")
    return [ds.UNKNOWNS[n] for n in ds.UNKNOWNS if n in names]  # a fixed order: the same inputs, the same key


#: the scene key (or table) each unknown replaces
OWNED_KEYS = {"wear": "effects.wear", "clearance": "effects.bearing_clearance", "torque": "operating.torque_Nm"}


def check_sets(sets: list[str], unknowns: list[ds.Unknown]) -> None:
    """An override of an unknown's scene key would be ignored: refuse it."""
    for item in sets:
        key = item.split("=", 1)[0].strip()
        for u in unknowns:
            own = OWNED_KEYS[u.short]
            if key == own or key.startswith(own + "."):
                raise InputError(
                    f"--set {key}: sets {u.name}, an unknown of the diagnosis (--unknowns); give its "
                    f"prior range with {u.flag} LO:HI instead"
                )


def prior_ranges(
    raw: dict[str, Any], unknowns: list[ds.Unknown], given: dict[str, str | None]
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(lo, hi) per unknown: LO:HI from its flag, else the documented default. A range flag of
    a quantity that is not an unknown would be ignored: an error."""
    shorts = {u.short for u in unknowns}
    for short, text in given.items():
        if text is not None and short not in shorts:
            flag = next(u.flag for u in ds.UNKNOWNS.values() if u.short == short)
            raise InputError(
                f"{flag} = {text}: not used, {short} is not an unknown (--unknowns "
                f"{','.join(u.short for u in unknowns)}); add it to --unknowns or drop the flag"
            )
    lo, hi = [], []
    for u in unknowns:
        text = given.get(u.short)
        if text is None:
            a, b = ds.default_range(u, raw)
        else:
            parts = text.split(":")
            try:
                if len(parts) != 2:
                    raise ValueError
                a, b = float(parts[0]), float(parts[1])
            except ValueError:
                raise InputError(f"{u.flag} = {text}: must be LO:HI in {u.unit}, e.g. 0:40") from None
            if not (math.isfinite(a) and math.isfinite(b) and 0.0 <= a < b):
                raise InputError(
                    f"{u.flag} = {text} {u.unit}: must be LO:HI with "
                    f"{'0 < LO' if u.short == 'torque' else '0 <= LO'} < HI"
                )
            if u.short == "torque" and a <= 0:
                raise InputError(f"{u.flag} = {text} {u.unit}: LO must be > 0 (the mesh stiffness needs a load)")
        lo.append(float(a))
        hi.append(float(b))
    return tuple(lo), tuple(hi)


def design_size(text: str | None, flag: str, default: int) -> int:
    if text is None:
        return default
    try:
        n = int(text)
    except ValueError:
        n = -1
    if n < 8 or n > 65536 or n & (n - 1):
        raise InputError(f"{flag} = {text}: must be a power of two in [8, 65536] (a Sobol design)")
    return n


class LazyExecutor:
    """Local processes (sweep_job.make_executor), started on the first call, i.e. only if a
    surrogate must be built, and reused by every later build; one worker: this process."""

    def __init__(self, workers: int | None):
        self.workers = workers
        self.executor: Any = None

    def __call__(self):
        if self.executor is None and self.workers != 1:
            from gearwear.jobs.sweep import make_executor

            self.executor = make_executor(self.workers)
        return self.executor

    def __enter__(self) -> "LazyExecutor":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        """Shut the executor down if one was started; on an exception (Ctrl-C included) it
        stops its workers at once (sweep_job.LocalPool)."""
        if self.executor is not None:
            executor, self.executor = self.executor, None
            executor.__exit__(exc_type, exc, tb)


def _bar(total: int, enabled: bool):
    import sys

    from tqdm import tqdm

    return tqdm(total=total, desc="diagnose surrogate", unit="run", disable=not enabled or None, file=sys.stderr)


@dataclass
class Diagnosis:
    doc: dict[str, Any]
    fit: dj.Fit
    measurement: Measurement
    timing: dict[str, Any]


def diagnose(
    spec: ds.BuildSpec,
    meas: Measurement,
    rel: float,
    floor_frac: float,
    workers: int | None,
    progress: bool,
    refresh: bool = False,
) -> Diagnosis:
    """The diagnosis of ``meas`` (read_measurement of the file, at the scene's mesh
    frequency and ``spec.harmonics``) over the surrogate of ``spec``."""
    t0 = time.perf_counter()
    with (
        LazyExecutor(workers) as ex,
        _bar(spec.design_points + 2 ** len(spec.unknowns) + spec.holdout_points, progress) as bar,
    ):
        sur = ds.build(spec, ex, bar.update, refresh=refresh)
    t1 = time.perf_counter()
    ft = dj.fit(sur, meas.values, rel, floor_frac)
    ver = dj.verdict(ft, rel, floor_frac)
    info = {
        "file": Path(meas.source).name,
        "sha256": io.file_sha256(meas.source),
        "kind": meas.kind,
        "features": len(ft.features),
        "signals": meas.signals,
        **meas.info,
    }
    doc = dj.document(ft, ver, info, rel, floor_frac, spec.name)
    timing = {
        "total_s": time.perf_counter() - t0,
        "fit_s": time.perf_counter() - t1,
        "surrogate_from_cache": sur.from_cache,
        **({} if sur.from_cache else {"surrogate_build_s": sur.meta.get("build_wall_s")}),
    }
    return Diagnosis(doc, ft, meas, timing)


def inputs(spec: ds.BuildSpec, rel: float, floor_frac: float, extra: dict[str, Any]) -> dict[str, Any]:
    return {
        **io.scene_inputs(spec.base_scene()),
        "unknowns": [u.name for u in spec.unknowns],
        "prior_lo": list(spec.lo),
        "prior_hi": list(spec.hi),
        "noise_relative": rel,
        "noise_floor_fraction": floor_frac,
        "design_points": spec.design_points,
        "holdout_points": spec.holdout_points,
        "harmonics": spec.harmonics,
        **extra,
    }


def write_diagnosis(d: Diagnosis, folder: Path, inp: dict[str, Any], labels: dict[str, Any]) -> list[Path]:
    from gearwear.diagnose import plots as diagnose_plots

    files = [io.write_json(folder / "diagnosis.json", d.doc)]
    rows = d.doc["features"]
    cols = [
        "feature",
        "signal",
        "harmonic",
        "measured",
        "fitted",
        "sigma_noise",
        "sigma_surrogate",
        "residual_over_sigma",
    ]
    lines = [",".join(cols)] + [
        ",".join(str(r[c]) if isinstance(r[c], (str, int)) else f"{r[c]:.8g}" for c in cols) for r in rows
    ]
    csv = io.write_text(folder / "features.csv", "\n".join(lines) + "\n")
    files += [csv, io.sidecar(csv, inp, "gearwear diagnose (grid posterior over the surrogate)", labels)]
    files.append(io.write_figure(diagnose_plots.corner(d.fit), folder / "corner.png"))
    files.append(io.write_figure(diagnose_plots.features(d.fit), folder / "features.png"))
    return files


def print_diagnosis(doc: dict[str, Any], timing: dict[str, Any], files: list[Path]) -> None:
    m = doc["measured"]
    print(
        f"measured: {m['file']} ({m['kind'].replace('_', ' ')}, {m['features']} features of {', '.join(m['signals'])})"
    )
    print(f"{'unknown':<20}{'estimate':>10}{'lo95':>10}{'hi95':>10}  {'prior':<14}{'identifiable':>13}")
    for n, e in doc["estimates"].items():
        p = doc["prior"][n]
        print(
            f"{n:<20}{e['value']:>10.4g}{e['lo95']:>10.4g}{e['hi95']:>10.4g}  "
            f"{p['lo']:g}-{p['hi']:g} {p['unit']:<6}{'yes' if doc['identifiable'][n] else 'no':>9}"
        )
    print(doc["verdict"])
    h = doc["surrogate"]["heldout"]
    print(
        f"surrogate: {doc['surrogate']['design_points']} runs, held-out error of the harmonic amplitudes "
        f"{100 * h['harmonic_relative_error_median']:.2f} % median, {100 * h['harmonic_relative_error_p95']:.1f} % "
        f"95th percentile ({h['points']} full simulations; enters the noise model)"
    )
    built = (
        "read from the cache"
        if timing["surrogate_from_cache"]
        else f"built in {timing.get('surrogate_build_s', 0.0):.1f} s"
    )
    print(f"wall {timing['total_s']:.1f} s (surrogate {built}, fit {timing['fit_s']:.1f} s)")
    for f in files:
        print(f"wrote {f}")


def plan_candidates(
    raw: dict[str, Any], unknowns: list[ds.Unknown], speeds: list[float] | None, torques: list[float] | None
) -> tuple[list[float], list[float] | None]:
    op = raw.get("operating", {})
    n0, T0 = float(op.get("speed_rpm", 1200.0)), float(op.get("torque_Nm", 40.0))
    sp = speeds or [f * n0 for f in PLAN_SPEED_FACTORS]
    if any(u.short == "torque" for u in unknowns):
        if torques:
            raise InputError(
                "--torques-Nm: the torque is an unknown (--unknowns), so the plan cannot choose it; "
                "drop --torques-Nm or the torque unknown"
            )
        return sp, None
    return sp, torques or [f * T0 for f in PLAN_TORQUE_FACTORS]


def parse_list(text: str | None, flag: str, unit: str, hi: float) -> list[float] | None:
    if text is None:
        return None
    out = []
    for part in text.split(","):
        try:
            v = float(part)
        except ValueError:
            raise InputError(f"{flag} = {text}: must be numbers separated by commas, in (0, {hi:g}] {unit}") from None
        if not (math.isfinite(v) and 0 < v <= hi):
            raise InputError(f"{flag} = {v:g} {unit}: must be in (0, {hi:g}] {unit}")
        out.append(v)
    return out


def run_plan(
    spec: ds.BuildSpec,
    speeds: list[float],
    torques: list[float] | None,
    rel: float,
    floor_frac: float,
    workers: int | None,
    progress: bool,
) -> tuple[dict[str, Any], dict[str, Any]]:
    from gearwear.diagnose import plan as diagnose_plan

    t0 = time.perf_counter()
    total = len(speeds) * len(torques or [None]) * (spec.design_points + 2 ** len(spec.unknowns) + spec.holdout_points)
    with LazyExecutor(workers) as ex, _bar(total, progress) as bar:
        doc = diagnose_plan.plan(spec, speeds, torques, rel, floor_frac, ex, bar.update)
    timing = {"total_s": time.perf_counter() - t0, "surrogates": doc.pop("surrogates")}
    return doc, timing


def write_plan(doc: dict[str, Any], folder: Path, inp: dict[str, Any], labels: dict[str, Any]) -> list[Path]:
    from gearwear.diagnose import plan as diagnose_plan

    files = [io.write_json(folder / "plan.json", doc)]
    csv = io.write_text(folder / "plan.csv", diagnose_plan.table_csv(doc))
    files += [csv, io.sidecar(csv, inp, "gearwear diagnose --plan (Fisher information of the surrogates)", labels)]
    return files


def run(args: argparse.Namespace) -> int:
    from gearwear.cli import diagnose as dc
    from gearwear.diagnose.surrogate import BuildSpec, validate_range
    from gearwear.scene.files import load_scene_dict
    from gearwear.scene.model import require_dynamics, scene_from_dict
    from gearwear.scene.overrides import apply_overrides

    data, name = load_scene_dict(args.scene, default="paper-wear-severe")
    unknowns = dc.parse_unknowns(args.unknowns)
    sets = alias_sets(args)
    dc.check_sets(sets, unknowns)
    raw = apply_overrides(data, sets)
    scene = scene_from_dict(raw, name=name)  # the known part, checked first
    require_dynamics(scene)
    lo, hi = dc.prior_ranges(
        raw,
        unknowns,
        {"wear": args.wear_range_um, "clearance": args.clearance_range_um, "torque": args.torque_range_Nm},
    )
    validate_range(raw, name, unknowns, lo, hi)
    rel = bounded_float("--noise-pct", args.noise_pct, "%", 0.01, 100) / 100
    floor = bounded_float("--noise-floor-pct", args.noise_floor_pct, "%", 0, 100) / 100
    workers = worker_count(args)
    d, K = len(unknowns), int(scene.output["harmonics"])
    design = dc.design_size(
        args.design_points, "--design-points", (dc.PLAN_DESIGN_POINTS if args.plan else dc.DESIGN_POINTS)[d]
    )
    spec = BuildSpec(raw, name, unknowns, lo, hi, K, design, dc.HOLDOUT_POINTS[d])
    if args.plan:
        if args.measured:
            raise InputError(f"--measured {args.measured}: not used with --plan (the plan needs no measurement)")
        speeds, torques = dc.plan_candidates(
            raw,
            unknowns,
            dc.parse_list(args.speeds_rpm, "--speeds-rpm", "rpm", 1e6),
            dc.parse_list(args.torques_Nm, "--torques-Nm", "N m", 1e7),
        )
        out = check_out(args.out, "diagnose plan")
        doc, timing = dc.run_plan(spec, speeds, torques, rel, floor, workers, not args.json)
        inputs = dc.inputs(spec, rel, floor, {"plan_speeds_rpm": speeds, "plan_torques_Nm": torques})
        files = write_output(
            out, "diagnose plan", scene, inputs, lambda f: dc.write_plan(doc, f, inputs, io.scene_labels(scene)), timing
        )
        if args.json:
            print(io.json_text({**doc, "wall_s": timing["total_s"], "files": [str(f) for f in files]}, indent=None))
        else:
            from gearwear.diagnose.plan import print_table

            print_table(doc)
            for f in files:
                print(f"wrote {f}")
        return 0
    if not args.measured:
        raise InputError(
            "--measured: missing; give the measured CSV (a time series or a harmonic table), "
            "or --plan for a measurement plan"
        )
    if args.speeds_rpm or args.torques_Nm:
        raise InputError("--speeds-rpm/--torques-Nm: only used with --plan")
    from gearwear.diagnose.features import read_measurement

    meas = read_measurement(args.measured, scene.mesh_frequency_Hz, K)  # a bad file: one line, before any work
    out = check_out(args.out, "diagnose")
    res = dc.diagnose(spec, meas, rel, floor, workers, not args.json, refresh=args.refresh)
    inputs = dc.inputs(spec, rel, floor, {"measured_sha256": res.doc["measured"]["sha256"]})
    labels = {**io.scene_labels(scene), "measured_file": str(args.measured)}
    files = write_output(
        out, "diagnose", scene, inputs, lambda f: dc.write_diagnosis(res, f, inputs, labels), res.timing
    )
    if args.json:
        print(
            io.json_text(
                {**res.doc, "wall_s": res.timing["total_s"], "timing": res.timing, "files": [str(f) for f in files]},
                indent=None,
            )
        )
    else:
        dc.print_diagnosis(res.doc, res.timing, files)
    return 0


def add_parser(sub) -> None:
    """The ``diagnose`` sub-command's arguments."""
    # argparse %-formats help texts: a literal percent sign is written %%
    dg = sub.add_parser(
        "diagnose",
        help="estimate wear depth and bearing clearance (and torque) from a measured "
        "vibration, with 95 %% intervals and an identifiability verdict",
        description="Fit the 6-DOF model to measured mesh harmonics (and mean values) through a "
        "cached surrogate of the model over the unknowns; print estimates, 95 % "
        "intervals and which unknown the measurement cannot resolve. --plan: which "
        "signals, speeds and torques would separate the unknowns. The scene fixes "
        "everything known (default: paper-wear-severe). Writes diagnosis.json, "
        "features.csv, corner.png, features.png (plan: plan.json, plan.csv).",
    )
    scene_options(dg, "paper-wear-severe", aliases=("torque",))
    dg.add_argument(
        "--measured",
        help="CSV: a time series (time_s plus any of y_p_um, x_p_um, delta_um, F_m_N; "
        "displacements, so integrate a housing accelerometer upstream) or a "
        "harmonic table (signal,harmonic,amplitude)",
    )
    dg.add_argument(
        "--plan",
        action="store_true",
        help="no measurement: rank signals, speeds and torques by how "
        "well they would separate the unknowns (Fisher information)",
    )
    dg.add_argument(
        "--unknowns",
        default="wear,clearance",
        help="comma-separated, of wear (wear_max_depth_um), "
        "clearance (clearance_um), torque (torque_Nm); "
        "default wear,clearance",
    )
    dg.add_argument(
        "--wear-range-um",
        help="prior range LO:HI of the maximum wear depth (default 0:40; 0.1:40 with transmission_error)",
    )
    dg.add_argument("--clearance-range-um", help="prior range LO:HI of the bearing clearance (default 0:50)")
    dg.add_argument("--torque-range-Nm", help="prior range LO:HI of the torque (default 0.5 to 1.5 x the scene's)")
    dg.add_argument("--noise-pct", default="2", help="relative measurement noise of each feature, %% (default 2)")
    dg.add_argument(
        "--noise-floor-pct",
        default="0.5",
        help="absolute noise floor, %% of the largest measured harmonic of the same signal (default 0.5)",
    )
    dg.add_argument(
        "--design-points",
        help="surrogate design size, a power of two (default 256 for two unknowns, 512 for three; --plan 128 / 256)",
    )
    dg.add_argument("--workers", help="local worker processes for building a surrogate (default: all cores)")
    dg.add_argument(
        "--speeds-rpm", help="--plan: candidate pinion speeds, comma-separated (default 0.5, 1, 2 x the scene's)"
    )
    dg.add_argument("--torques-Nm", help="--plan: candidate torques, comma-separated (default 0.5, 1, 2 x the scene's)")
    dg.add_argument("--refresh", action="store_true", help="rebuild the surrogate even if it is cached")
    output_options(dg)
    dg.set_defaults(func=run)
