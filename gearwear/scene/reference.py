"""The scene document described for people and editors: the JSON Schema, the generated scene
reference (docs/scene-reference.md), the words and units of every key, TOML output."""

import inspect
import types
import typing
from typing import Any, Mapping

from pydantic import BaseModel

from gearwear.scene.checks import cross_check
from gearwear.scene.schema import SceneDoc
from gearwear.scene.validate import _literal_names, _model_in


def json_schema() -> dict[str, Any]:
    """JSON Schema (draft 2020-12) of a scene document, for editor completion."""
    s = SceneDoc.model_json_schema(mode="validation")
    s["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    s["title"] = "gearwear scene"
    return s


def reference_markdown() -> str:
    """The scene reference (docs/scene-reference.md), generated from the models: every
    table, key, type, unit, allowed range, default and description."""
    lines = [
        "# Scene reference",
        "",
        "Generated from `gearwear/scene/schema.py` by `gearwear scene --reference`; do not edit by hand.",
        "A scene is a TOML document; units are in the key names. `gearwear scene NAME|FILE` prints a",
        "scene with every default filled in, `gearwear scene --schema` the JSON Schema.",
        "",
    ]
    for name, info in SceneDoc.model_fields.items():
        model = _model_in(info.annotation)
        if model is None:
            lines += [f"- `{name}` (string): {'the scene name' if name == 'name' else 'free text'}", ""]
    for name, info in SceneDoc.model_fields.items():
        model = _model_in(info.annotation)
        if model is None:
            continue
        lines += [f"## [{name}]", "", inspect.cleandoc(model.__doc__ or ""), ""]
        if name == "effects":
            for ename, einfo in model.model_fields.items():
                emodel = _model_in(einfo.annotation)
                lines += [f"### effects.{ename}", "", inspect.cleandoc(emodel.__doc__ or ""), ""]
                lines += _key_table(emodel) if emodel.model_fields else ["No options: `" + ename + " = {}`.", ""]
            continue
        lines += _key_table(model)
        for sname, sinfo in model.model_fields.items():  # sub-tables: [flank.tip_relief], [faults.crack], ...
            smodel = _model_in(sinfo.annotation)
            if smodel is not None:
                lines += [f"### [{name}.{sname}]", "", inspect.cleandoc(smodel.__doc__ or ""), ""]
                lines += _key_table(smodel)
    lines += ["## Checks across keys", "", (cross_check.__doc__ or "").strip() + " The checks:", ""]
    lines += [f"- {c}" for c in CROSS_CHECKS] + [""]
    return "\n".join(lines)


#: what :func:`cross_check` enforces, for the reference
CROSS_CHECKS = (
    '`mesh_stiffness.value_N_per_m` only with `source = "constant"`; `interpolation` not with it',
    '`mesh_stiffness.path` needed by, and only used with, `source = "table"`',
    '`mesh_stiffness.blank_torsion` only with `source = "fem"` or `"calibrated"` (the others have no blank term)',
    '`mesh_stiffness.points_per_mesh_period` only with an analytic table (`source` analytic, calibrated, or '
    'constant without `value_N_per_m`)',
    "`wear`: exactly one of `phase`, `max_depth_um`, `hours`; `archard_k_m2_per_N` / `wear_intensity` "
    "only with `hours` and their model",
    '`wear` not with a user table, nor with a constant `value_N_per_m` and no `transmission_error`',
    "`transmission_error` with a user table needs its `excitation_um` column (a nominal flank is "
    "accepted: the unworn baseline of a wear study, whose excitation is the tip-corner contact)",
    '`centre_distance` with `coupling = "static"` needs `bearing_clearance`',
    "a damper is given as a ratio or as a coefficient, not both",
    "`material.density_kg_per_m3` not with both `bodies.mass_kg` and `bodies.inertia_kg_m2` (it would change nothing)",
    "`solver.discard_s` < `solver.duration_s`; `rtol`/`atol` only for dopri5, "
    "`steps_per_mesh_period` only for rk4 (after `auto` is resolved)",
    "`fem.plane` only where a model with a 2D state runs: `stiffness --method fem|ishikawa|energy`, `verify`, "
    '`calibrate`, `report pair`, and the dynamics with `mesh_stiffness.source = "analytic"`, `"fem"` or '
    '`"calibrated"` (checked by the command)',
)


def _key_table(model: type[BaseModel]) -> list[str]:
    rows = ["| key | type | unit | range | default | meaning |", "|---|---|---|---|---|---|"]
    for key, info in model.model_fields.items():
        extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
        names = _literal_names(info.annotation)
        sub = _model_in(info.annotation)
        kind = (
            "one of " + ", ".join(f"`{n}`" for n in names)
            if names
            else "per gear"
            if extra.get("per_gear")
            else f"table, see [{model_table_name(model, key)}] below"
            if sub is not None
            else _type_name(info.annotation)
        )
        default = None if info.is_required() else info.get_default(call_default_factory=True)
        shown = (
            "required"
            if info.is_required()
            else "absent"
            if default is None
            else f"`{to_toml({'v': default}).split(' = ', 1)[1].strip()}`"
        )
        rows.append(
            f"| `{key}` | {kind} | {extra.get('unit', '') or ''} | {extra.get('range', '')} | {shown} | "
            f"{(info.description or '').replace('|', '/')} |"
        )
    return rows + [""]


def key_words(key: str) -> tuple[str, str]:
    """(what a scene key is, in words; its unit) from this schema, so any key has them:
    the first phrase of the key's description, after the name of its sub-table when the
    phrase does not say it, and the unit ("dimensionless" without one, "category" for a
    named choice): ``operating.speed_rpm`` -> ("pinion speed", "rpm"),
    ``effects.bearing_clearance.clearance_um`` -> ("radial bearing clearance BC", "um"),
    ``flank.tip_relief.amount_um`` -> ("tip relief: relief amount", "um"). A key outside
    the schema: its last part in words, no unit."""
    parts = key.split(".")
    model: Any = SceneDoc
    info = None
    for part in parts:
        fields = getattr(model, "model_fields", None)
        if fields is None or part not in fields:
            return parts[-1].replace("_", " "), ""
        info = fields[part]
        model = _model_in(info.annotation)
    extra = info.json_schema_extra if info is not None and isinstance(info.json_schema_extra, dict) else {}
    unit = str(extra.get("unit", "") or "")
    phrase = _first_phrase(info.description or "") if info is not None else ""
    choices = _literal_names(info.annotation) if info is not None else []
    named = _reads_as_words(phrase) and phrase not in choices  # "analytic (Ishikawa), ...": a choice, not a name
    if not named:
        phrase = _name_words(parts[-1], unit)
    # the sub-table ("tip relief"); a top-level key named by its key name gets its table ("solver: method")
    context = " ".join(parts[1:-1] if len(parts) > 2 or named else parts[:-1]).replace("_", " ")
    if context and not set(context.lower().split()) <= set(phrase.lower().split()):
        phrase = f"{context}: {phrase}"
    return phrase, unit or ("category" if choices else "dimensionless")


def key_label(key: str) -> str:
    """An axis label for a scene key: its :func:`key_words` and the unit in parentheses,
    "pinion speed (rpm)"."""
    phrase, unit = key_words(key)
    return f"{phrase} ({unit})" if unit else phrase


def _first_phrase(description: str) -> str:
    """The description up to its first sentence end, semicolon, colon, bracket or comma,
    with a lower-case first letter (an acronym and a name's possessive stay)."""
    text = description.split(". ")[0].rstrip(".")
    for sep in (";", ": ", " (", ","):
        text = text.split(sep)[0]
    text = text.strip()
    first = text.split(" ")[0]
    return text[:1].lower() + text[1:] if text[1:2].islower() and not first.endswith("'s") else text


def _reads_as_words(phrase: str) -> bool:
    """A phrase of words ("pinion speed"), not a symbol ("zeta_b"), a condition ("With
    source = ...") or a code list ("0 pinion")."""
    words = phrase.split()
    return (
        bool(words)
        and phrase[:1].isalpha()
        and words[0].lower() != "with"
        and any(len(w) >= 3 and w.isalpha() for w in words)
    )


def _name_words(name: str, unit: str) -> str:
    """A key's name without its unit suffix, in words: bearing_damping_N_s_per_m ->
    "bearing damping"."""
    for suffix in (unit.replace("^", "").replace("/", "_per_").replace(" ", "_"), unit.replace(" ", "")):
        if suffix and name.endswith("_" + suffix):
            name = name[: -len(suffix) - 1]
            break
    return name.replace("_", " ")


def model_table_name(model: type[BaseModel], key: str) -> str:
    """The dotted name of sub-table ``key`` of ``model`` as a scene writes it (flank.tip_relief)."""
    parent = next((n for n, i in SceneDoc.model_fields.items() if _model_in(i.annotation) is model), "")
    return f"{parent}.{key}" if parent else key


def _type_name(annotation: Any) -> str:
    """The TOML type of a key in words (an optional key's None is its absence, shown in the
    default column; a ``|`` would break the Markdown table)."""
    args = [a for a in typing.get_args(annotation) if a is not type(None)]
    if typing.get_origin(annotation) in (typing.Union, types.UnionType) and len(args) == 1:
        annotation = args[0]
    if typing.get_origin(annotation) is tuple:
        inner = typing.get_args(annotation)
        return f"[{', '.join(_type_name(a) for a in inner)}]"
    text = getattr(annotation, "__name__", None) or str(annotation)
    return {"float": "number", "int": "whole number", "bool": "true/false", "str": "string"}.get(
        text, "list" if "list" in text else text.replace("|", "or")
    )


def to_toml(data: Mapping[str, Any]) -> str:
    """A resolved document as TOML (scalars, arrays and one level of effect tables)."""

    def val(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(val(x) for x in v) + "]"
        if isinstance(v, Mapping):
            return "{ " + ", ".join(f"{k} = {val(x)}" for k, x in v.items()) + " }" if v else "{}"
        return repr(v)

    lines = [f"{k} = {val(v)}" for k, v in data.items() if not isinstance(v, Mapping)]
    for k, v in data.items():
        if isinstance(v, Mapping):
            lines += ["", f"[{k}]"] + [f"{kk} = {val(vv)}" for kk, vv in v.items()]
    return "\n".join(lines) + "\n"


__all__ = ["CROSS_CHECKS", "json_schema", "key_label", "key_words", "model_table_name", "reference_markdown", "to_toml"]
