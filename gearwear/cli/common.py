"""The skeleton every command shares: its scene (file or built-in name, the short flags that
are aliases of --set, then --set), the --out check before any work, the assumptions a
result rests on, the atomic write with provenance, and the argument checks of one line."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gearwear import io
from gearwear.core.validation import InputError, fail, renamed

if TYPE_CHECKING:
    from gearwear.scene.model import Scene


def bounded_float(name: str, text: str, unit: str, lo: float, hi: float) -> float:
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{name} = {text!r}: must be a number in [{lo:g}, {hi:g}] {unit}") from None
    if not lo <= v <= hi:
        raise InputError(f"{name} = {v:g} {unit}: must be in [{lo:g}, {hi:g}] {unit}")
    return v


def int_arg(name: str, text, lo: int, hi: int) -> int:
    try:
        v = int(str(text))
    except ValueError:
        raise InputError(f"{name} = {text!r}: must be a whole number in [{lo}, {hi}]") from None
    if not lo <= v <= hi:
        raise InputError(f"{name} = {v}: must be a whole number in [{lo}, {hi}]")
    return v


def fem_plane(doc: Any, runs_fem: bool, what: str) -> str:
    """schema.fem_plane, imported when a command runs (the CLI imports nothing heavy
    before its signal handlers are installed)."""
    from gearwear.scene.checks import fem_plane

    return fem_plane(doc, runs_fem, what)


def alias_sets(args: argparse.Namespace, skip: tuple[str, ...] = ()) -> list[str]:
    """The single-valued short flags as the --set overrides they stand for (``skip``: flags
    whose value the caller sets itself, one variant at a time)."""
    from gearwear.scene.overrides import wear_override

    sets = []
    if getattr(args, "torque_Nm", None) is not None:
        sets.append(f"operating.torque_Nm={args.torque_Nm}")
    for flag, make in (("wear", wear_override), ("clearance_um", clearance_set)):
        values = split_multi(getattr(args, flag, None))
        if len(values) == 1 and flag not in skip:
            sets.append(make(values[0]))
    return sets + list(args.set or [])


def clearance_set(text: str) -> str:
    return f"effects.bearing_clearance.clearance_um={text}"


ALIAS_FLAGS = {"torque_Nm": "--torque-Nm", "clearance_um": "--clearance-um", "wear": "--wear"}


def load_scene(
    args: argparse.Namespace,
    default: str = "paper-default",
    extra: list[str] | None = None,
    loaded: bool = True,
    skip: tuple[str, ...] = (),
) -> "Scene":
    """The command's scene: file or built-in name, short-flag aliases, then --set. A bad
    value given through a short flag is reported under the flag's name. ``loaded``: the
    command computes load sharing, so the torque must be > 0."""
    from gearwear.scene.files import load_scene_dict
    from gearwear.scene.model import scene_from_dict
    from gearwear.scene.overrides import SHORT_KEYS, apply_overrides

    data, name = load_scene_dict(args.scene, default=default)
    try:
        scene = scene_from_dict(apply_overrides(data, alias_sets(args, skip) + list(extra or [])), name=name)
        if loaded and not scene.operating.torque_Nm > 0:
            raise fail(
                "operating.torque_Nm",
                scene.operating.torque_Nm,
                "N m",
                "must be in (0, 1e+07] N m: the load sharing of the mesh stiffness needs a load",
            )
        return scene
    except InputError as exc:
        given = {SHORT_KEYS[attr]: flag for attr, flag in ALIAS_FLAGS.items() if getattr(args, attr, None) is not None}
        for key, flag in given.items():  # a sub-key of an alias (--wear=-5um sets effects.wear.max_depth_um)
            if str(exc).startswith(key + "."):
                raise type(exc)(f"{flag}: {exc}") from None
        raise renamed(exc, given) from None


def variants(args: argparse.Namespace) -> "tuple[Scene, list, list[float]]":
    """(scene, wear specs, clearances in m) for commands that overlay several --wear and
    --clearance-um values: each value is the scene with that alias applied."""
    from gearwear.scene.overrides import wear_override

    scene = load_scene(args)
    wears = [
        load_scene(args, extra=[wear_override(w)], skip=("wear",)).wear
        for w in split_multi(getattr(args, "wear", None))
    ] or [scene.wear]
    clear = [
        load_scene(args, extra=[clearance_set(c)], skip=("clearance_um",)).clearance_m
        for c in split_multi(getattr(args, "clearance_um", None))
    ]
    return scene, wears, clear or [scene.clearance_m]


def check_out(out: str | None, command: str) -> Path | None:
    """--out is checked before any work: a new folder, an empty one, or one gearwear
    wrote (it has a manifest.json), since the command's output replaces it as a whole
    (gearwear.io.check_out; the parent must be writable, '' is refused)."""

    return io.check_out(out, command)


def wear_dict(wear) -> dict | None:
    """Every field of a wear definition (not only its label): part of the hashed inputs."""
    import dataclasses

    return None if wear is None else dataclasses.asdict(wear)


#: which results each command's files hold, for the assumptions they list (gearwear.scene.assumptions.USES)
COMMAND_USES = {
    "geometry": "geometry",
    "stiffness": "stiffness",
    "verify": "verify",
    "calibrate": "calibrate",
    "simulate": "simulate",
    "sweep": "simulate",
    "runup": "runup",
    "diagnose": "simulate",
    "diagnose plan": "simulate",
    "report pair": "report pair",
}


def assumptions_of(scene, uses: str) -> list[dict]:
    """The assumptions of ``scene`` a command's results rest on (gearwear.scene.assumptions), as
    dicts (``key``, ``value``, ``unit``, ``why``)."""
    from gearwear.scene.assumptions import as_dicts, for_command

    return as_dicts(for_command(scene, uses))


def print_assumed(assumed: list[dict]) -> None:
    """One ``assumed:`` line per value (with the results: a bad input stays one line)."""
    from gearwear.scene.assumptions import line_of

    for a in assumed:
        print(line_of(a))


def write_output(
    out: Path | None, command: str, scene, inputs: dict, writer, timing: dict | None = None, uses: str | None = None
) -> list[Path]:
    """Write a command's files into ``out`` as a whole (gearwear.io.write_folder): the
    manifest gets the inputs, the scene's name and referenced file paths, and every value
    the results assume that the scene did not give (``uses``: which results, default by
    command)."""

    if out is None:
        return []
    prov = {**inputs, **(io.scene_labels(scene) if scene is not None else {})}
    if scene is not None:
        prov["assumptions"] = assumptions_of(scene, uses or COMMAND_USES[command])
    return io.write_folder(out, command, prov, writer, timing)


def split_multi(values: list[str] | str | None) -> list[str]:
    """Flag values given space- or comma-separated (one string for single-valued flags)."""
    out: list[str] = []
    for v in [values] if isinstance(values, str) else values or []:
        out += [x for x in v.split(",") if x.strip()]
    return out


def num_or_dash(v: float | None, width: int = 12) -> str:
    """A zone mean in the text table; '-' for a zone the pair never has (contact ratio >= 2 has
    no single-contact zone)."""
    return f"{'-':>{width}}" if v is None else f"{v:>{width}.4e}"


def unworn_as_none(wears: list) -> list:
    """verify and calibrate key an unworn flank as None (the nominal profile)."""
    return [None if w is None or w.is_unworn else w for w in wears]


def fe_executor(args: argparse.Namespace):
    """Where the FE runs of a calibration go: None (this process, the default: every body is
    built once and shared by the wear states), local processes (--workers N) or Dask
    (--scheduler). Each worker builds the bodies it needs once; the tables are the same to
    the bit on any executor."""
    from gearwear.jobs import sweep as sweep_job

    if not (args.workers or args.scheduler):
        return None
    return sweep_job.make_executor(worker_count(args), args.scheduler)


def worker_count(args: argparse.Namespace) -> int | None:
    """--workers N (1..1024), or None: the executor's default (all cores). With --scheduler the
    workers are the cluster's (local:N or the running one's): --workers would be ignored."""
    if args.workers and getattr(args, "scheduler", None):
        raise InputError(
            f"--workers = {args.workers}: not used with --scheduler {args.scheduler} (the cluster's "
            "workers run the tasks; give their number as --scheduler local:N)"
        )
    return int_arg("--workers", args.workers, 1, 1024) if args.workers else None


def pair_inputs(scene) -> dict:
    p = scene.pair
    return {
        "teeth": list(p.teeth),
        "module_mm": p.module_m * 1e3,
        "pressure_angle_deg": round(p.pressure_angle_rad * 180 / 3.141592653589793, 12),
        "face_width_mm": p.face_width_m * 1e3,
        "addendum_coefficient": p.addendum_coefficient,
        "dedendum_coefficient": p.dedendum_coefficient,
        "rack_tip_radius_coefficient": p.rack_tip_radius_coefficient,
        "profile_shift": list(p.profile_shift),
        "hub_radius_mm": [h * 1e3 for h in p.hub_radius_m],
        "allow_undercut": p.allow_undercut,
        "youngs_modulus_GPa": one_or_two([m.youngs_modulus_Pa / 1e9 for m in p.materials]),
        "poisson_ratio": one_or_two([m.poisson_ratio for m in p.materials]),
        **(
            {"centre_distance_mm": p.installed_centre_distance_m * 1e3}
            if p.installed_centre_distance_m is not None
            else {}
        ),
    }


def one_or_two(values: list) -> Any:
    """A per-gear value as the scene writes it: one value for both gears, else [pinion, gear]."""
    return values[0] if values[0] == values[1] else values


SCHEDULER_HELP = (
    "run on Dask instead of local processes: local[:N] starts a LocalCluster of N worker processes "
    "(default: all cores) on 127.0.0.1 for this run, ADDRESS (tcp://host:8786) connects to a running "
    "scheduler, which must answer and have a worker within 10 s; needs the optional extra "
    "gearwear[dask]"
)


ALLOW_LARGE_HELP = (
    "run more than 2000 grid points (run-up: speeds x points x directions), refused without it; "
    "a run estimated to take over a minute states its estimate on stderr once its first point is done"
)


SET_HELP = (
    "override a scene key by its dotted path, e.g. --set operating.speed_rpm=6000 "
    "--set effects.backlash.initial_um=50; KEY=none removes a key or an effect, e.g. "
    "--set effects.backlash=none (repeatable; validated like the file; see gearwear scene --schema)"
)


def scene_options(
    sp: argparse.ArgumentParser,
    default: str,
    multi: bool = False,
    aliases: tuple[str, ...] = ("wear", "clearance", "torque"),
) -> None:
    """The scene argument, --set, and the short flags that are aliases of --set."""
    sp.add_argument(
        "scene",
        nargs="?",
        help=f"scene TOML file or built-in scene name (default: {default}; list: gearwear scene --list)",
    )
    sp.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help=SET_HELP)
    many = " (one or more: each is overlaid)" if multi else ""
    if "wear" in aliases:
        sp.add_argument(
            "--wear",
            nargs="+" if multi else None,
            help="alias of --set effects.wear=...: unworn | "
            f"mild | severe, a depth like 25um, or running hours like 500h{many}",
        )
    if "clearance" in aliases:
        sp.add_argument(
            "--clearance-um",
            nargs="+" if multi else None,
            help=f"alias of --set effects.bearing_clearance.clearance_um=X, bearing radial clearance in um{many}",
        )
    if "torque" in aliases:
        sp.add_argument("--torque-Nm", help="alias of --set operating.torque_Nm=X, pinion torque in N m")


def output_options(
    sp: argparse.ArgumentParser, out_help: str = "output folder", json_help: str = "print one JSON object"
) -> None:
    """--out FOLDER and --json, which every command that writes results takes."""
    sp.add_argument("--out", help=out_help)
    sp.add_argument("--json", action="store_true", help=json_help)


def pool_options(sp: argparse.ArgumentParser) -> None:
    """--workers, --scheduler and --allow-large of the commands that run a grid of scenes."""
    sp.add_argument("--workers", help="local worker processes (default: all cores)")
    sp.add_argument("--scheduler", help=SCHEDULER_HELP)
    sp.add_argument("--allow-large", action="store_true", help=ALLOW_LARGE_HELP)
