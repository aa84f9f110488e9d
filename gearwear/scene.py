"""Scenes: a TOML file naming the gear pair, bodies, operating point and the effects
to simulate (DESIGN.md, "Scenes"). An effect is modelled only if ``[effects]`` names it.

This module validates the whole file (unknown keys are rejected with the nearest
valid key suggested) and turns it into immutable specs. Units are in the key names;
everything inside is SI.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

from gearwear.geometry.spec import PairSpec, load_toml, pair_from_dict
from gearwear.core.validation import Field, InputError, check_value, fail, parse_table, reject_unknown
from gearwear.geometry.wear import WearSpec, wear_from_dict

BODIES_SCHEMA = {
    "mass_kg": Field("kg", 0, 1e6, lo_open=True, per_gear=True),
    "inertia_kg_m2": Field("kg m^2", 0, 1e6, lo_open=True, per_gear=True),
    "bearing_stiffness_N_per_m": Field("N/m", 0, 1e13, lo_open=True),
    "bearing_damping_ratio": Field("", 0, 1),
    "mesh_damping_ratio": Field("", 0, 1),
    "bearing_damping_N_s_per_m": Field("N s/m", 0, 1e9, per_gear=True),
    "mesh_damping_N_s_per_m": Field("N s/m", 0, 1e9),
}
# optional: without them J = m r^2 / 2 at the pitch radius and c from the damping ratios
BODIES_OPTIONAL = ("inertia_kg_m2", "bearing_damping_N_s_per_m", "mesh_damping_N_s_per_m")
TABLE_MIN_ROWS = 8
BODIES_DEFAULTS = {"mass_kg": [3.75, 3.75], "bearing_stiffness_N_per_m": 2.6e8,
                   "bearing_damping_ratio": 0.02, "mesh_damping_ratio": 0.05}
OPERATING_SCHEMA = {
    "speed_rpm": Field("rpm", 0, 1e6, lo_open=True),
    "torque_Nm": Field("N m", 0, 1e7, lo_open=True),
}
OPERATING_DEFAULTS = {"speed_rpm": 1200.0, "torque_Nm": 40.0}

EFFECT_KEYS: dict[str, tuple[str, ...]] = {
    "mesh_stiffness": ("source", "value_N_per_m", "path", "interpolation"),
    "wear": ("phase", "max_depth_um", "hours", "model", "archard_k_m2_per_N", "wear_intensity", "taper_mm"),
    "backlash": ("initial_um", "form", "damping_in_gap"),
    "bearing_clearance": ("clearance_um",),
    "centre_distance": ("coupling",),
    "transmission_error": (),
}
STIFFNESS_SOURCES = ("constant", "analytic", "calibrated", "fem", "table")
SOLVER_KEYS = ("method", "steps_per_mesh_period", "duration_s", "discard_s", "rtol", "atol")
OUTPUT_KEYS = ("signals", "harmonics")


@dataclass(frozen=True)
class Bodies:
    """Masses, inertias (None: J = m r^2 / 2 of a disc at the pitch radius), bearing
    stiffness and damping: either ratios (c = 2 zeta sqrt(k m)) or explicit coefficients
    (the coefficients replace the ratios; a scene may give one form per damper)."""
    mass_kg: tuple[float, float] = (3.75, 3.75)
    bearing_stiffness_N_per_m: float = 2.6e8
    bearing_damping_ratio: float = 0.02
    mesh_damping_ratio: float = 0.05
    inertia_kg_m2: tuple[float, float] | None = None
    bearing_damping_N_s_per_m: tuple[float, float] | None = None
    mesh_damping_N_s_per_m: float | None = None


@dataclass(frozen=True)
class Operating:
    speed_rpm: float = 1200.0
    torque_Nm: float = 40.0


@dataclass(frozen=True)
class Scene:
    """A validated scene. ``effects`` maps effect name -> its validated options."""

    name: str
    pair: PairSpec
    bodies: Bodies
    operating: Operating
    effects: dict[str, dict[str, Any]] = field(default_factory=dict)
    solver: dict[str, Any] = field(default_factory=dict)
    output: dict[str, Any] = field(default_factory=dict)
    wear: WearSpec | None = None

    @property
    def clearance_m(self) -> float:
        return self.effects.get("bearing_clearance", {}).get("clearance_m", 0.0)

    @property
    def initial_backlash_m(self) -> float:
        return self.effects.get("backlash", {}).get("initial_m", 0.0)

    @property
    def backlash_form(self) -> str:
        return self.effects.get("backlash", {}).get("form", "consistent")

    @property
    def mesh_frequency_Hz(self) -> float:
        return self.operating.speed_rpm / 60.0 * self.pair.teeth[0]


def _effects(raw: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    if not isinstance(raw, Mapping):
        raise InputError("effects: must be a table of effects")
    reject_unknown("effects", raw.keys(), EFFECT_KEYS.keys())
    out: dict[str, dict[str, Any]] = {}
    for name, opts in raw.items():
        if not isinstance(opts, Mapping):
            raise InputError(f"effects.{name}: must be an inline table, e.g. {name} = {{}}")
        reject_unknown(f"effects.{name}", opts.keys(), EFFECT_KEYS[name])
        o: dict[str, Any] = {}
        if name == "mesh_stiffness":
            src = opts.get("source", "analytic")
            if src not in STIFFNESS_SOURCES:
                raise fail("effects.mesh_stiffness.source", repr(src), "", f"must be one of {', '.join(STIFFNESS_SOURCES)}")
            o["source"] = src
            if "value_N_per_m" in opts:
                if src != "constant":
                    raise fail("effects.mesh_stiffness.value_N_per_m", opts["value_N_per_m"], "N/m",
                               f"only used with source = \"constant\" (source is {src!r})")
                o["value_N_per_m"] = check_value("effects.mesh_stiffness.value_N_per_m", opts["value_N_per_m"],
                                                 Field("N/m", 0, 1e13, lo_open=True))
            interp = opts.get("interpolation", "linear")
            if interp not in ("linear", "cubic"):
                raise fail("effects.mesh_stiffness.interpolation", repr(interp), "",
                           "must be linear (positivity preserving, for sharp tables) or cubic "
                           "(periodic cubic spline, for smooth tables)")
            if interp != "linear" and src == "constant":
                raise fail("effects.mesh_stiffness.interpolation", repr(interp), "",
                           'not used with source = "constant"')
            o["interpolation"] = interp
            if src == "table" and "path" not in opts:
                raise InputError('effects.mesh_stiffness.path: missing (a CSV file with columns angle_deg, '
                                 'k_N_per_m and optionally excitation_um, needed by source = "table")')
            if "path" in opts:
                if src != "table":
                    raise fail("effects.mesh_stiffness.path", repr(opts["path"]), "",
                               f'only used with source = "table" (source is {src!r})')
                if not isinstance(opts["path"], str) or not opts["path"]:
                    raise fail("effects.mesh_stiffness.path", repr(opts["path"]), "", "must be a file path")
                o["path"] = opts["path"]
        elif name == "backlash":
            o["initial_m"] = check_value("effects.backlash.initial_um", opts.get("initial_um", 0.0),
                                         Field("um", 0, 1e4)) * 1e-6
            form = opts.get("form", "consistent")
            if form not in ("consistent", "printed"):
                raise fail("effects.backlash.form", repr(form), "", "must be one of consistent, printed")
            o["form"] = form
            gap_damping = opts.get("damping_in_gap", False)
            if not isinstance(gap_damping, bool):
                raise fail("effects.backlash.damping_in_gap", repr(gap_damping), "",
                           "must be true (paper Eq. 19 literally: c_h delta' acts in the gap) or false (default)")
            o["damping_in_gap"] = gap_damping
        elif name == "bearing_clearance":
            o["clearance_m"] = check_value("effects.bearing_clearance.clearance_um", opts.get("clearance_um", 0.0),
                                           Field("um", 0, 1e4)) * 1e-6
        elif name == "centre_distance":
            coupling = opts.get("coupling", "static")
            if coupling not in ("static", "dynamic"):
                raise fail("effects.centre_distance.coupling", repr(coupling), "", "must be one of static, dynamic")
            o["coupling"] = coupling
        elif name == "wear":
            o = dict(opts)  # parsed into a WearSpec once the operating point is known
        out[name] = o
    return out


def scene_from_dict(data: Mapping[str, Any], name: str = "scene") -> Scene:
    """Validate a parsed scene document (see DESIGN.md for the format)."""
    pair = pair_from_dict(data)  # also rejects unknown top-level tables
    raw_b = data.get("bodies", {})
    b = parse_table("bodies", raw_b, BODIES_SCHEMA, BODIES_DEFAULTS, optional=BODIES_OPTIONAL)
    for ratio, coeff in (("bearing_damping_ratio", "bearing_damping_N_s_per_m"),
                         ("mesh_damping_ratio", "mesh_damping_N_s_per_m")):
        if isinstance(raw_b, Mapping) and ratio in raw_b and coeff in raw_b:
            raise fail(f"bodies.{coeff}", raw_b[coeff], "N s/m",
                       f"give either bodies.{ratio} or bodies.{coeff}, not both")
    o = parse_table("operating", data.get("operating", {}), OPERATING_SCHEMA, OPERATING_DEFAULTS)
    bodies = Bodies(b["mass_kg"], b["bearing_stiffness_N_per_m"], b["bearing_damping_ratio"], b["mesh_damping_ratio"],
                    b.get("inertia_kg_m2"), b.get("bearing_damping_N_s_per_m"), b.get("mesh_damping_N_s_per_m"))
    operating = Operating(o["speed_rpm"], o["torque_Nm"])
    effects = _effects(data.get("effects", {}))
    solver = dict(data.get("solver", {}))
    reject_unknown("solver", solver.keys(), SOLVER_KEYS)
    output = dict(data.get("output", {}))
    reject_unknown("output", output.keys(), OUTPUT_KEYS)
    wear = None
    if "wear" in effects:
        wear = wear_from_dict(effects["wear"], operating.torque_Nm, operating.speed_rpm)
    ms = effects.get("mesh_stiffness", {})
    if ms.get("source") == "table":
        tab = read_stiffness_table(ms["path"], pair.teeth[0])
        ms["angle_rad"], ms["k_N_per_m"], ms["excitation_m"] = tab
        if "wear" in effects:
            raise InputError('effects.wear: cannot be applied to a user stiffness table (mesh_stiffness.source = '
                             '"table"): the table already is the stiffness; drop [effects] wear')
        if "transmission_error" in effects and tab[2] is None:
            raise InputError(f"effects.transmission_error: the table {ms['path']} has no excitation_um column, "
                             f"so there is no excitation to apply; add the column or drop the effect")
    nm = data.get("name", name)
    if not isinstance(nm, str):
        raise fail("name", repr(nm), "", "must be a string")
    return Scene(nm, pair, bodies, operating, effects, solver, output, wear)


def read_stiffness_table(path: str | Path, z_pinion: int):
    """A user mesh-stiffness table: CSV with the header columns ``angle_deg`` (pinion
    angle over one mesh period, 0 <= angle < 360 / z1, strictly increasing, at least 8
    rows, not necessarily uniform), ``k_N_per_m`` (>= 0) and optionally ``excitation_um``
    (the transmission-error excitation e, material removed > 0). The rows must cover the
    period: the wrap-around gap (first row + period - last row) may not exceed the largest
    spacing between rows. Returns (angle_rad, k_N_per_m, excitation_m or None)."""
    import csv
    import math

    import numpy as np

    key = "effects.mesh_stiffness.path"
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else type(exc).__name__
        raise fail(key, repr(str(p)), "", f"cannot read the stiffness table ({why})") from None
    rows = [r for r in csv.reader(text.splitlines()) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise fail(key, repr(str(p)), "", "empty file; expected a header angle_deg,k_N_per_m[,excitation_um]")
    head = [c.strip() for c in rows[0]]
    allowed = ("angle_deg", "k_N_per_m", "excitation_um")
    if head[:2] != ["angle_deg", "k_N_per_m"] or any(c not in allowed for c in head) or len(set(head)) != len(head):
        raise fail(key, repr(str(p)), "", f"header {','.join(head)!r}: must be angle_deg,k_N_per_m "
                   f"with an optional excitation_um column")
    try:
        data = np.array([[float(c) for c in r] for r in rows[1:]], dtype=float)
    except ValueError as exc:
        raise fail(key, repr(str(p)), "", f"non-numeric value ({exc})") from None
    if data.ndim != 2 or data.shape[0] < TABLE_MIN_ROWS or data.shape[1] != len(head):
        n = data.shape[0] if data.ndim == 2 else 0
        raise fail(key, repr(str(p)), "", f"needs >= {TABLE_MIN_ROWS} complete rows of {len(head)} "
                   f"columns, got {n}")
    if not np.all(np.isfinite(data)):
        r = int(np.argwhere(~np.isfinite(data))[0, 0]) + 2
        raise fail(key, repr(str(p)), "", f"row {r} (line {r}): values must be finite numbers")
    period = 360.0 / z_pinion
    ang, k = data[:, 0], data[:, 1]
    if ang[0] < 0 or ang[-1] >= period:
        raise fail(key, repr(str(p)), "", f"angle_deg must lie in [0, {period:g}) deg (one mesh period "
                   f"of the {z_pinion}-tooth pinion), got {ang.min():g} to {ang.max():g} deg")
    if np.any(np.diff(ang) <= 0):
        r = int(np.argmax(np.diff(ang) <= 0)) + 3
        raise fail(key, repr(str(p)), "", f"angle_deg must be strictly increasing (line {r})")
    if np.any(k < 0):
        r = int(np.argmax(k < 0)) + 2
        raise fail(key, repr(str(p)), "", f"k_N_per_m must be >= 0 N/m (line {r}: {k[r - 2]:g})")
    if not np.any(k > 0):
        raise fail(key, repr(str(p)), "", "k_N_per_m is 0 everywhere: no mesh stiffness")
    wrap = ang[0] + period - ang[-1]
    if wrap > np.max(np.diff(ang)) * (1 + 1e-9):
        raise fail(key, repr(str(p)), "", f"the rows do not cover one mesh period ({period:g} deg): "
                   f"{ang[0]:g} to {ang[-1]:g} deg leaves a {wrap:g} deg gap")
    e = data[:, 2] * 1e-6 if "excitation_um" in head else None
    return np.radians(ang), k, e


def _resolve_table_path(data: dict[str, Any], base: Path) -> dict[str, Any]:
    """Relative table paths are relative to the scene file's folder."""
    ms = data.get("effects", {}).get("mesh_stiffness") if isinstance(data.get("effects"), dict) else None
    if isinstance(ms, dict) and isinstance(ms.get("path"), str) and ms["path"] and not Path(ms["path"]).is_absolute():
        ms["path"] = str(base / ms["path"])
    return data


def load_scene(path: str | Path | None = None) -> Scene:
    """A scene from a TOML file or a built-in name, or the built-in default (the paper's
    pair) if None."""
    data, name = load_scene_dict(path)
    return scene_from_dict(data, name=name)


def builtin_scene_dict(name: str) -> dict[str, Any]:
    """The raw TOML document of a built-in scene."""
    import tomllib
    names = builtin_scene_names()
    if name not in names:
        raise InputError(f"built-in scene {name!r}: unknown (available: {', '.join(names)})")
    return tomllib.loads(resources.files("gearwear.data").joinpath(f"{name}.toml").read_text())


def apply_overrides(data: dict[str, Any], overrides: list[str]) -> dict[str, Any]:
    """Apply ``--set key.path=value`` overrides to a raw scene document (a copy).

    The value is read as a TOML value (numbers, strings in quotes, arrays, booleans,
    inline tables); a bare word is taken as a string. The result is validated like a
    file, so a bad override gets the same one-line error."""
    import copy
    import tomllib
    out = copy.deepcopy(data)
    for item in overrides or []:
        if "=" not in item:
            raise InputError(f"--set {item!r}: must be KEY=VALUE with a dotted key, e.g. operating.speed_rpm=6000")
        key, text = item.split("=", 1)
        key = key.strip()
        try:
            value = tomllib.loads(f"v = {text.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            value = text.strip()
        parts = key.split(".")
        node = out
        for part in parts[:-1]:
            nxt = node.setdefault(part, {})
            if not isinstance(nxt, dict):
                raise InputError(f"--set {key}: {part} is not a table")
            node = nxt
        node[parts[-1]] = value
    return out


def load_scene_dict(path: str | Path | None, default: str = "paper-default") -> tuple[dict[str, Any], str]:
    """(raw document, name) of a scene file, or of a built-in scene when path is None."""
    if path is None:
        return builtin_scene_dict(default), default
    p = Path(path)
    if not p.exists() and str(path) in builtin_scene_names():
        return builtin_scene_dict(str(path)), str(path)
    return _resolve_table_path(load_toml(p), p.resolve().parent), p.stem


def builtin_scene_names() -> list[str]:
    return sorted(f.name[:-5] for f in resources.files("gearwear.data").iterdir() if f.name.endswith(".toml"))


def builtin_scene(name: str) -> Scene:
    """A scene shipped with the package (``gearwear/data/<name>.toml``)."""
    names = builtin_scene_names()
    if name not in names:
        raise InputError(f"built-in scene {name!r}: unknown (available: {', '.join(names)})")
    import tomllib
    text = resources.files("gearwear.data").joinpath(f"{name}.toml").read_text()
    return scene_from_dict(tomllib.loads(text), name=name)

