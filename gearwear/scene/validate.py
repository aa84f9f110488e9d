"""A scene document validated against the schema, with pydantic's structured errors turned into the
one-line contract of the command line: the key, the value, the unit, the allowed range, and the
nearest key for a typo (``modul_mm`` -> ``module_mm``)."""

import difflib
from typing import Any, Literal, Mapping

from pydantic import BaseModel, ValidationError

from gearwear.core.validation import InputError, fail
from gearwear.scene.schema import SceneDoc

# -- field helpers -------------------------------------------------------------------


def _field_info(model: type[BaseModel], loc: tuple) -> tuple[type[BaseModel] | None, Any]:
    """(model holding the last named key, its FieldInfo) along an error location."""
    cur: Any = model
    info = None
    owner = None
    for part in loc:
        if isinstance(part, int) or cur is None:
            continue
        fields = getattr(cur, "model_fields", None)
        if fields is None or part not in fields:
            continue
        owner, info = cur, fields[part]
        cur = _model_in(info.annotation)
    return owner, info


def _model_in(annotation: Any) -> Any:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()) or ():
        m = _model_in(arg)
        if m is not None:
            return m
    return None


def _key(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif isinstance(part, str) and (part.startswith(("function-", "tuple[", "nullable[")) or "Doc" in part):
            continue  # pydantic's names for union members and validators, not keys
        else:
            out += ("." if out else "") + part
    return out


def _raw_at(data: Any, loc: tuple) -> Any:
    for part in loc:
        try:
            data = data[part]
        except (KeyError, IndexError, TypeError):
            return None
    return data


def _translate(err: Mapping[str, Any], data: Mapping[str, Any]) -> InputError:
    loc = tuple(err["loc"])
    kind, value = err["type"], err.get("input")
    if loc and isinstance(loc[-1], int) and not isinstance(_raw_at(data, loc[:-1]), (list, tuple)):
        loc = loc[:-1]  # a per-gear key given as one value: name the key, not an index
    key = _key(loc)
    owner, info = _field_info(SceneDoc, loc)
    extra = info.json_schema_extra if info is not None and isinstance(info.json_schema_extra, dict) else {}
    unit, rng = extra.get("unit", ""), extra.get("range", "")
    if kind == "extra_forbidden":
        table, _, name = key.rpartition(".")
        holder = _model_in(_field_info(SceneDoc, loc[:-1])[1].annotation) if len(loc) > 1 else SceneDoc
        allowed = sorted((holder or SceneDoc).model_fields)
        near = difflib.get_close_matches(name, allowed, n=1, cutoff=0.5)
        hint = f"; did you mean {table + '.' if table else ''}{near[0]}?" if near else ""
        return InputError(f"{key}: unknown key{hint} (allowed: {', '.join(allowed)})")
    if kind == "missing":
        if key in MISSING_TABLES:
            return InputError(f"{key}: missing; {MISSING_TABLES[key]}")
        doc = (info.description or "").split(". ")[0].rstrip(".") if info is not None else ""
        what = f"{doc}, {rng}" if doc and rng else doc or rng
        return InputError(f"{key}: missing ({what})" if what else f"{key}: missing")
    if kind == "per_gear":
        return fail(key, list(value) if isinstance(value, (list, tuple)) else value, "", err["msg"])
    if kind in ("model_type", "dict_type", "model_attributes_type"):
        return InputError(f"{key}: must be a table of keys, got {type(value).__name__}")
    if kind == "literal_error":
        expected = info.annotation if info is not None else None
        names = _literal_names(expected) or [err.get("ctx", {}).get("expected", "")]
        return fail(key, repr(value), "", f"must be one of {', '.join(names)}")
    if kind == "bool_type":
        return fail(key, repr(value), "", "must be true or false")
    if kind in ("string_type",):
        return fail(key, repr(value), "", "must be a string")
    if kind in ("list_type", "tuple_type"):
        return fail(key, repr(value), "", "must be a list")
    if kind == "int_from_float":
        return fail(key, value, unit, f"must be a whole number in {rng}")
    if kind == "finite_number":
        return fail(key, value, unit, f"must be finite, in {rng}")
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return fail(key, value, unit, f"must be in {rng}")
    if kind in ("float_type", "int_type", "int_parsing", "float_parsing"):
        what = "a whole number" if kind.startswith("int") else "a number"
        return fail(key, repr(value), "", f"must be {what} in {rng}" if rng else f"must be {what}")
    return InputError(f"{key}: {err['msg']}")


#: what a required table holds, for the one-line error when it is absent
MISSING_TABLES = {
    "pair": "a scene names its own gear pair: [pair] teeth = [z1, z2], module_mm, face_width_mm (the other pair "
    "keys have stated defaults; gearwear scene --reference lists them)",
    "operating": "a scene names its operating point: [operating] speed_rpm (pinion) and torque_Nm (pinion)",
}


def _literal_names(annotation: Any) -> list[str]:
    if annotation is None:
        return []
    if getattr(annotation, "__origin__", None) is Literal:
        return [str(a) for a in annotation.__args__]
    for arg in getattr(annotation, "__args__", ()) or ():
        names = _literal_names(arg)
        if names:
            return names
    return []


def validate_document(data: Mapping[str, Any], name: str | None = None) -> SceneDoc:
    """Validate a parsed scene document against the schema and the cross-key checks.

    Raises :class:`InputError` with a one-line message for the first problem."""
    if not isinstance(data, Mapping):
        raise InputError(f"scene: must be a table of keys, got {type(data).__name__}")
    doc_in = dict(data)
    if name is not None and "name" not in doc_in:
        doc_in["name"] = name
    try:
        doc = SceneDoc.model_validate(doc_in)
    except ValidationError as exc:
        raise _translate(_first(exc.errors()), doc_in) from None
    from gearwear.scene.checks import cross_check  # the checks read the models defined here

    cross_check(doc)
    return doc


def _first(errors: list) -> Any:
    """The error to report: an unknown key first (its nearest-key hint also explains a
    'missing' one: ``modul_mm`` for ``module_mm``), then a bad value, then a missing key."""
    rank = {"extra_forbidden": 0, "missing": 2}
    return min(errors, key=lambda e: rank.get(e["type"], 1))


def validate_tables(data: Mapping[str, Any], names: tuple[str, ...]) -> dict[str, Any]:
    """Validate some top-level tables of a scene document on their own (the Python API's
    ``gw.pair(...)`` needs [pair] and [material], not an operating point), with the same
    one-line errors as :func:`validate_document`. Returns {name: validated table or None}."""
    if not isinstance(data, Mapping):
        raise InputError(f"scene: must be a table of keys, got {type(data).__name__}")
    for key in data:
        if key not in SceneDoc.model_fields:
            raise _translate({"loc": (key,), "type": "extra_forbidden", "msg": ""}, data)
    out: dict[str, Any] = {}
    for name in names:
        info = SceneDoc.model_fields[name]
        model = _model_in(info.annotation)
        raw = data.get(name)
        if raw is None and not info.is_required():
            out[name] = info.get_default(call_default_factory=True)
            continue
        try:
            out[name] = model.model_validate({} if raw is None else raw)
        except ValidationError as exc:
            err = dict(_first(exc.errors()))
            err["loc"] = (name, *err["loc"])
            raise _translate(err, data) from None
    return out
