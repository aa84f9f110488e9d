"""The SPEC of ``gearwear atlas``: a TOML file of the design space's axes, the number of
designs, the seed, the fixed pair data, the feasibility limits, the FE settings and the
models. Every key has a unit in its name (or none), an allowed range and a default
(:data:`KEYS`, listed by ``gearwear atlas --help`` and written whole to the table's
sidecar). A bad key or value is one line naming the key, the value, the unit and the
range (core.validation), before anything is computed or written.

Layout (every key optional; ``[axes]`` entries are ``[low, high]``)::

    designs = 500
    seed = 2028
    models = ["all"]          # the analytic command sources of the registry, or names

    [axes]
    pinion_teeth = [14, 100]
    ratio = [1, 5]
    ...

    [pair]  / [limits]  / [fe]  / [analytic]
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gearwear.core.validation import Field, InputError, check_scalar, fail

#: the largest SPEC file read (bytes)
SPEC_LIMIT_BYTES = 1 << 20


@dataclass(frozen=True)
class Key:
    """One SPEC key: its default, allowed range (Field: unit, bounds, kind) and meaning.
    ``pair``: the value is a range [low, high] inside the field's bounds."""

    default: Any
    field: Field
    doc: str
    pair: bool = False


#: every key of a SPEC, by dotted name (section.key); the order is the order of --help
KEYS: dict[str, Key] = {
    "designs": Key(500, Field("", 1, 100_000, kind=int), "feasible designs in the atlas"),
    "seed": Key(2028, Field("", 0, 2**32 - 1, kind=int), "seed of the scrambled Sobol sequence"),
    "axes.pinion_teeth": Key([14, 100], Field("", 8, 400, kind=int), "pinion teeth z1 (uniform)", True),
    "axes.ratio": Key([1.0, 5.0], Field("", 1.0, 10.0), "gear ratio z2 / z1 (uniform; z2 rounded)", True),
    "axes.pressure_angle_deg": Key([14.5, 25.0], Field("deg", 10.0, 35.0), "pressure angle (uniform)", True),
    "axes.addendum_coefficient": Key(
        [1.0, 1.4], Field("", 0.5, 2.0), "addendum h_a* (uniform; 1.4 reaches contact ratios above 2)", True
    ),
    "axes.profile_shift": Key(
        [-0.5, 1.0],
        Field("", -2.0, 3.0),
        "each gear's profile shift x (uniform from max(low, the undercut-free limit of that gear) to high)",
        True,
    ),
    "axes.rim_thickness_module": Key(
        [1.5, 12.0],
        Field("", 0.5, 100.0),
        "rim s_R / m below the root circle of both gears (log-uniform; bore = r_f - s_R, "
        "solid where the bore would fall below pair.min_bore_fraction r_f)",
        True,
    ),
    "axes.line_load_N_per_mm": Key(
        [20.0, 1000.0], Field("N/mm", 0.1, 1e5), "load T / (r_b1 b) per face width (log-uniform)", True
    ),
    "pair.module_mm": Key(3.0, Field("mm", 0.1, 100.0), "module m of every design"),
    "pair.face_width_mm": Key(30.0, Field("mm", 0.1, 1000.0), "face width b of every design"),
    "pair.dedendum_margin": Key(
        0.25, Field("", 0.05, 1.0, lo_open=False), "dedendum h_f* = h_a* + this (bottom clearance, modules)"
    ),
    "pair.rack_tip_radius_coefficient": Key(
        0.38, Field("", 0.0, 0.5), "rack tip round rho*, capped at 0.8 of the largest round the rack tooth holds"
    ),
    "pair.min_bore_fraction": Key(0.2, Field("", 0.01, 0.9), "smallest bore radius / root radius (a shaft)"),
    "pair.youngs_modulus_GPa": Key(206.0, Field("GPa", 1.0, 1000.0), "Young's modulus of both gears"),
    "pair.poisson_ratio": Key(0.3, Field("", 0.0, 0.49), "Poisson's ratio of both gears"),
    "limits.min_tip_thickness_module": Key(
        0.2, Field("", 0.0, 1.0), "least tip thickness s_a / m (else rejected: pointed_tip)"
    ),
    "limits.min_contact_ratio": Key(1.0, Field("", 1.0, 3.0), "least contact ratio (else rejected: contact_ratio)"),
    "limits.max_candidates": Key(
        1_000_000, Field("", 1, 10_000_000, kind=int), "Sobol points drawn at most while looking for feasible designs"
    ),
    "fe.positions": Key(24, Field("", 2, 720, kind=int), "pair-FE positions per mesh period"),
    "fe.mesh_scale": Key(
        1.0,
        Field("", 0.25, 4.0),
        "pair-FE element sizes away from the contact, x the default (at 8 the FE fails on 14-20 teeth)",
    ),
    "fe.contact_scale": Key(1.0, Field("", 0.25, 8.0), "pair-FE contact element size h_c, x the default"),
    "fe.plane": Key("stress", Field(""), "2D state of the FE and the analytic tooth beams: stress | strain"),
    "fe.transitions": Key(
        True,
        Field(""),
        "locate the FE's loaded contact transitions by bisection (about 30 extra position solves); "
        "false: from the positions only (resolution one position)",
    ),
    "analytic.points": Key(
        360, Field("", 16, 100_000, kind=int), "analytic table nodes per mesh period (plus the breakpoints)"
    ),
    "models": Key(
        ["all"],
        Field(""),
        'analytic models compared with the FE: ["all"] (every analytic command source of the registry) or names',
    ),
}

SECTIONS = ("axes", "pair", "limits", "fe", "analytic")


@dataclass(frozen=True)
class AtlasSpec:
    """A validated SPEC: ``values`` maps every key of :data:`KEYS` to its value (defaults
    filled in); ``models`` the analytic source names, resolved against the registry."""

    values: dict[str, Any]
    models: tuple[str, ...]

    def __getitem__(self, key: str) -> Any:
        return self.values[key]

    def as_dict(self) -> dict[str, Any]:
        """The whole spec (every default filled in, models resolved), as written to the sidecar."""
        return {**self.values, "models": list(self.models)}


def analytic_models() -> tuple[str, ...]:
    """The registry's analytic models: command sources that do not run the FE (the ones a
    user can ask ``gearwear stiffness --method`` for whose curve is a model, not a table), without
    the atlas-corrected model (gearwear.stiffness.corrected), which is fitted on the atlas itself."""
    from gearwear.stiffness.sources import SOURCES

    fitted_on_the_atlas = ("corrected",)
    return tuple(
        n for n, s in SOURCES.items() if s.command and not s.fe and n not in ("table", "constant", *fitted_on_the_atlas)
    )


def _flatten(doc: dict[str, Any]) -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for k, v in doc.items():
        if k in SECTIONS:
            if not isinstance(v, dict):
                raise fail(k, repr(v), "", f"must be a table [{k}] of keys")
            for kk, vv in v.items():
                flat[f"{k}.{kk}"] = vv
        else:
            flat[k] = v
    return flat


def _nearest(key: str) -> str:
    import difflib

    close = difflib.get_close_matches(key, list(KEYS), n=1)
    return f" (did you mean {close[0]}?)" if close else ""


def _check(key: str, value: Any) -> Any:
    spec = KEYS[key]
    f = spec.field
    if key == "fe.plane":
        if value not in ("stress", "strain"):
            raise fail(key, repr(value), "", "must be stress or strain")
        return value
    if key == "fe.transitions":
        if not isinstance(value, bool):
            raise fail(key, repr(value), "", "must be true or false")
        return value
    if key == "models":
        return value  # resolved against the registry in parse()
    if spec.pair:
        if not (isinstance(value, list) and len(value) == 2):
            raise fail(key, repr(value), f.unit, f"must be a range [low, high] within {f.range_text()}")
        lo, hi = (check_scalar(key, v, f) for v in value)
        if lo > hi:
            raise fail(key, repr(value), f.unit, f"low must not exceed high, within {f.range_text()}")
        return [lo, hi]
    return check_scalar(key, value, f)


def parse(doc: dict[str, Any]) -> AtlasSpec:
    """A SPEC document (parsed TOML) validated, every default filled in. One-line
    InputError (key, value, unit, range) on the first bad key."""
    flat = _flatten(doc)
    for key in flat:
        if key not in KEYS:
            raise InputError(f"{key}: not a key of an atlas SPEC{_nearest(key)}; see gearwear atlas --help")
    values = {k: _check(k, flat[k]) if k in flat else KEYS[k].default for k in KEYS}
    teeth_hi = values["axes.pinion_teeth"][1] * values["axes.ratio"][1]
    if teeth_hi > 1000:
        raise fail(
            "axes.ratio",
            repr(values["axes.ratio"]),
            "",
            f"gives gears of up to {teeth_hi:.0f} teeth with axes.pinion_teeth up to "
            f"{values['axes.pinion_teeth'][1]}: at most 1000 (the FE meshes the whole body)",
        )
    return AtlasSpec(values, _models(values["models"]))


def _models(value: Any) -> tuple[str, ...]:
    known = analytic_models()
    if not (isinstance(value, list) and value and all(isinstance(v, str) for v in value)):
        raise fail("models", repr(value), "", f'must be ["all"] or a list of names from {", ".join(known)}')
    if value == ["all"]:
        return known
    for name in value:
        if name not in known:
            raise fail("models", repr(name), "", f"must be one of {', '.join(known)} (or all)")
    if len(set(value)) != len(value):
        raise fail("models", repr(value), "", "names a model twice")
    return tuple(value)


def load(path: str | Path) -> AtlasSpec:
    """Read and validate a SPEC file (bounded, a regular file only: core.inputs.read_input)."""
    from gearwear.core.inputs import read_input_text

    text = read_input_text(path, "SPEC", "atlas spec", SPEC_LIMIT_BYTES)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise fail("SPEC", repr(str(path)), "", f"is not valid TOML ({exc})") from None
    return parse(doc)


def defaults_text() -> str:
    """Every key with its default, unit, range and meaning (for ``--help``)."""
    lines = []
    for key, k in KEYS.items():
        unit = f" {k.field.unit}" if k.field.unit else ""
        rng = "" if k.field.lo == -math.inf else f" in {k.field.range_text()}"
        default = str(k.default).replace("'", '"') if not isinstance(k.default, bool) else str(k.default).lower()
        lines.append(f"  {key} = {default}{unit}{rng}: {k.doc}")
    return "\n".join(lines)
