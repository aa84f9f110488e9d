"""`--set KEY=VALUE` and the short flags that stand for scene keys: values parsed as TOML, keys set
or removed (`KEY=none`) by their dotted path, the wear shorthands (`--wear severe`, `25um`, `500h`)."""

from __future__ import annotations

import tomllib
from typing import Any

from gearwear.core.validation import InputError
from gearwear.geometry.wear import PHASE_DEPTHS_M

#: the command line's short flags (and the Python API's keywords of the same names): the
#: scene key each stands for
SHORT_KEYS = {
    "torque_Nm": "operating.torque_Nm",
    "clearance_um": "effects.bearing_clearance.clearance_um",
    "wear": "effects.wear",
}


def wear_table(text: str) -> dict[str, Any]:
    """The ``[effects] wear`` table of a ``--wear`` shorthand: a phase (``severe``), a
    maximum depth (``25um``) or running hours (``500h``)."""
    t = text.strip()
    if t in PHASE_DEPTHS_M:
        return {"phase": t}
    for suffix, key in (("um", "max_depth_um"), ("h", "hours")):
        if t.endswith(suffix):
            try:
                return {key: float(t[: -len(suffix)])}
            except ValueError:
                break
    raise InputError(
        f"--wear = {text!r}: must be one of {', '.join(PHASE_DEPTHS_M)}, a depth like 25um, or running hours like 500h"
    )


def wear_override(text: str) -> str:
    """The ``--wear`` shorthand as the ``--set`` it stands for."""
    ((key, value),) = wear_table(text).items()
    return f"effects.wear={{{key}={value!r}}}".replace("'", '"')


def parse_value(text: str) -> Any:
    """A --set value read as a TOML value (numbers, quoted strings, arrays, booleans,
    inline tables); anything else is taken as a bare string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(data: dict[str, Any], overrides: list[str]) -> dict[str, Any]:
    """Apply ``--set key.path=value`` overrides to a raw scene document (a copy).

    The value is read as a TOML value (numbers, strings in quotes, arrays, booleans,
    inline tables); a bare word is taken as a string. The bare word ``none`` removes the key
    (``--set effects.backlash=none`` drops the effect; a removed key takes its default). The
    result is validated like a file, so a bad override gets the same one-line error."""
    import copy

    out = copy.deepcopy(data)
    check_sets(overrides or [])
    for item in overrides or []:
        key, text = item.split("=", 1)
        if text.strip() == REMOVE:
            remove_key(out, key.strip())
        else:
            set_key(out, key.strip(), parse_value(text.strip()))
    return out


#: the --set value that removes a key
REMOVE = "none"


def check_sets(items: list[str]) -> None:
    """Each --set is one KEY=VALUE on one line (a newline would let a value inject TOML tables
    or keys), and each key is set once (which of two values wins would be a guess): one-line
    InputErrors otherwise. The short flags (--torque-Nm, --wear, ...) count as the keys they set."""
    seen: dict[str, str] = {}
    for item in items:
        if "=" not in item:
            raise InputError(f"--set {item!r}: must be KEY=VALUE with a dotted key, e.g. operating.speed_rpm=6000")
        if "\n" in item or "\r" in item:
            raise InputError(
                f"--set {item.splitlines()[0]!r}...: a value is one line (a newline could inject TOML "
                "tables); give one KEY=VALUE per --set"
            )
        key, value = (x.strip() for x in item.split("=", 1))
        if key in seen:
            raise InputError(
                f"--set {key}: given twice ({seen[key]!r} and {value!r}); give each key once "
                "(a short flag such as --torque-Nm sets its key too)"
            )
        seen[key] = value


def remove_key(data: dict[str, Any], key: str) -> None:
    """Remove a dotted key from a raw document (absent already: nothing to do, it is absent)."""
    *path, last = key.split(".")
    node: Any = data
    for part in path:
        node = node.get(part) if isinstance(node, dict) else None
        if node is None:
            return
    if isinstance(node, dict):
        node.pop(last, None)


def set_key(data: dict[str, Any], key: str, value: Any) -> None:
    """Set a dotted key (``operating.speed_rpm``) in a raw document, making tables on the way."""
    parts = key.split(".")
    node = data
    for part in parts[:-1]:
        nxt = node.setdefault(part, {})
        if not isinstance(nxt, dict):
            raise InputError(f"--set {key}: {part} is not a table")
        node = nxt
    node[parts[-1]] = value
