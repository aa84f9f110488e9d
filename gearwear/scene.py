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

from geometry.spec import PairSpec, load_toml, pair_from_dict
from geometry.validation import Field, InputError, check_value, fail, parse_table, reject_unknown
from geometry.wear import WearSpec, wear_from_dict

BODIES_SCHEMA = {
    "mass_kg": Field("kg", 0, 1e6, lo_open=True, per_gear=True),
    "bearing_stiffness_N_per_m": Field("N/m", 0, 1e13, lo_open=True),
    "bearing_damping_ratio": Field("", 0, 1),
    "mesh_damping_ratio": Field("", 0, 1),
}
BODIES_DEFAULTS = {"mass_kg": [3.75, 3.75], "bearing_stiffness_N_per_m": 2.6e8,
                   "bearing_damping_ratio": 0.02, "mesh_damping_ratio": 0.05}
OPERATING_SCHEMA = {
    "speed_rpm": Field("rpm", 0, 1e6, lo_open=True),
    "torque_Nm": Field("N m", 0, 1e7, lo_open=True),
}
OPERATING_DEFAULTS = {"speed_rpm": 1200.0, "torque_Nm": 40.0}

EFFECT_KEYS: dict[str, tuple[str, ...]] = {
    "mesh_stiffness": ("source", "value_N_per_m"),
    "wear": ("phase", "max_depth_um", "hours", "model", "archard_k_m2_per_N", "wear_intensity", "taper_mm"),
    "backlash": ("initial_um", "form", "damping_in_gap"),
    "bearing_clearance": ("clearance_um",),
    "centre_distance": ("coupling",),
    "transmission_error": (),
}
STIFFNESS_SOURCES = ("constant", "analytic", "calibrated", "fem")
SOLVER_KEYS = ("method", "steps_per_mesh_period", "duration_s", "discard_s", "rtol", "atol")
OUTPUT_KEYS = ("signals", "harmonics")


@dataclass(frozen=True)
class Bodies:
    mass_kg: tuple[float, float] = (3.75, 3.75)
    bearing_stiffness_N_per_m: float = 2.6e8
    bearing_damping_ratio: float = 0.02
    mesh_damping_ratio: float = 0.05


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
                o["value_N_per_m"] = check_value("effects.mesh_stiffness.value_N_per_m", opts["value_N_per_m"],
                                                 Field("N/m", 0, 1e13, lo_open=True))
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
    b = parse_table("bodies", data.get("bodies", {}), BODIES_SCHEMA, BODIES_DEFAULTS)
    o = parse_table("operating", data.get("operating", {}), OPERATING_SCHEMA, OPERATING_DEFAULTS)
    bodies = Bodies(b["mass_kg"], b["bearing_stiffness_N_per_m"], b["bearing_damping_ratio"], b["mesh_damping_ratio"])
    operating = Operating(o["speed_rpm"], o["torque_Nm"])
    effects = _effects(data.get("effects", {}))
    solver = dict(data.get("solver", {}))
    reject_unknown("solver", solver.keys(), SOLVER_KEYS)
    output = dict(data.get("output", {}))
    reject_unknown("output", output.keys(), OUTPUT_KEYS)
    wear = None
    if "wear" in effects:
        wear = wear_from_dict(effects["wear"], operating.torque_Nm, operating.speed_rpm)
    nm = data.get("name", name)
    if not isinstance(nm, str):
        raise fail("name", repr(nm), "", "must be a string")
    return Scene(nm, pair, bodies, operating, effects, solver, output, wear)


def load_scene(path: str | Path | None = None) -> Scene:
    """A scene from a TOML file, or the built-in default (the paper's pair) if None."""
    if path is None:
        return builtin_scene("paper-default")
    p = Path(path)
    return scene_from_dict(load_toml(p), name=p.stem)


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
    return load_toml(p), p.stem


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

