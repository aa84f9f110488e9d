"""Input validation shared by every layer.

A bad input raises :class:`InputError` whose message is one line naming the key,
the value, the unit and the allowed range, e.g.::

    pair.module_mm = -5 mm: must be in (0, 100] mm

Scene documents (unknown keys, types, ranges) are validated by the pydantic schema in
gearwear.scene.schema; this module is the error contract every layer raises through.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping


class InputError(ValueError):
    """A user input is invalid; the message is a complete one-line diagnosis.

    Errors built by :func:`fail` (``key = value unit: why``), :func:`fail_range` (the same
    with a range that survives a rename with a unit change) or :func:`fail_text` (a message of
    another form, given as is) also carry ``key``, ``value``, ``unit`` and ``why`` so that a
    higher layer can rename a low layer's own parameter names to the user's keys
    (:func:`renamed`); every layer raises through them (tests/test_error_contract.py)."""

    key: str | None = None
    value: Any = None
    unit: str = ""
    why: str = ""
    field: "Field | None" = None  # set for range errors, so a rename can rescale the range
    note: str = ""


@dataclass(frozen=True)
class Field:
    """Schema entry for one scalar (or per-gear pair of scalars) input key.

    lo/hi bound the value; lo_open/hi_open make the bound exclusive. (Scene keys are
    validated by the pydantic schema, gearwear.scene.schema; the layers check their own
    arguments with :func:`check_scalar` and :func:`fail`.)
    """

    unit: str = ""
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False
    kind: type = float

    def range_text(self) -> str:
        left = "(" if self.lo_open or self.lo == -math.inf else "["
        right = ")" if self.hi_open or self.hi == math.inf else "]"
        lo = "-inf" if self.lo == -math.inf else _fmt(self.lo)
        hi = "inf" if self.hi == math.inf else _fmt(self.hi)
        unit = f" {self.unit}" if self.unit else ""
        return f"{left}{lo}, {hi}{right}{unit}"


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)


def fail(key: str, value: Any, unit: str, why: str) -> InputError:
    """Build the one-line error for ``key = value unit: why``."""
    u = f" {unit}" if unit else ""
    err = InputError(f"{key} = {_fmt(value)}{u}: {why}")
    err.key, err.value, err.unit, err.why = key, value, unit, why
    return err


def fail_range(key: str, value: float, field: Field, note: str = "") -> InputError:
    """``key = value unit: must be in <range>[, note]`` (the range survives a rename with
    a unit change, see :func:`renamed`)."""
    err = fail(key, value, field.unit, f"must be in {field.range_text()}" + (f", {note}" if note else ""))
    err.field, err.note = field, note
    return err


def fail_text(key: str | None, text: str, value: Any = None, unit: str = "", field: Field | None = None) -> InputError:
    """The contract's error for a one-line message that :func:`fail` cannot print byte for
    byte: a value printed with ``str``/``repr`` rather than ``%g``, no value at all
    (``k_table N/m: must be ...``), a range in words (``(0, pi/2)``). ``text`` is the message
    as given. It starts with ``key``, the layer's own name that :func:`renamed` swaps for the
    user's (None: the message names no input, e.g. ``WearSpec: exactly one of ...``), and
    ``why`` is what follows the first ``: `` after the key (or all that follows the key);
    ``value``, ``unit`` and ``field`` are set as :func:`fail` and :func:`fail_range` set them,
    so a rename with a unit change rescales the value (and the range) as it does for them."""
    if key is not None and not text.startswith(key):
        raise ValueError(f"fail_text: the message must start with its key {key!r}: {text!r}")
    rest = text if key is None else text[len(key) :]
    _, sep, after = rest.partition(": ")
    err = InputError(text)
    err.key, err.value, err.unit, err.field = key, value, unit, field
    err.why = after if sep else rest.strip()
    return err


def check_scalar(key: str, value: Any, field: Field) -> float | int:
    """Validate one scalar against ``field``; return it as ``field.kind``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise fail(key, repr(value), "", f"must be a number in {field.range_text()}")
    if field.kind is int:
        if isinstance(value, float) and not value.is_integer():
            raise fail(key, value, field.unit, f"must be a whole number in {field.range_text()}")
        value = int(value)
    else:
        value = float(value)
    if not math.isfinite(value):
        raise fail(key, value, field.unit, f"must be finite, in {field.range_text()}")
    below = value <= field.lo if field.lo_open else value < field.lo
    above = value >= field.hi if field.hi_open else value > field.hi
    if below or above:
        raise fail(key, value, field.unit, f"must be in {field.range_text()}")
    return value


def renamed(exc: InputError, names: Mapping[str, Any]) -> InputError:
    """The same error with its leading key replaced through ``names``, so a low layer
    can name its own parameters (``duration_s``, ``hub_radius_m``) and the app layer the
    user's key (``solver.duration_s``) or flag (``--method``).

    ``names[own] = new_key`` or ``(new_key, factor, unit)`` for a key whose user form
    has another unit (the value is multiplied by ``factor``). Indices survive:
    ``hub_radius_m[1]`` -> ``pair.hub_radius_mm[1]``."""
    msg = str(exc)
    head = exc.key if exc.key is not None else msg.split(" ", 1)[0].split(":", 1)[0]
    base, idx = (head.split("[", 1) + [""])[:2]
    if base not in names:
        return exc
    target = names[base]
    if isinstance(target, tuple):
        new_key, factor, unit = target
        if exc.key is not None and isinstance(exc.value, (int, float)) and not isinstance(exc.value, bool):
            key = new_key + (f"[{idx}" if idx else "")
            if exc.field is not None:
                f = exc.field
                scaled = Field(unit, f.lo * factor, f.hi * factor, f.lo_open, f.hi_open, f.kind)
                return fail_range(key, exc.value * factor, scaled, exc.note)
            return fail(key, exc.value * factor, unit, exc.why)
        target = new_key
    return type(exc)(target + msg[len(base) :])
