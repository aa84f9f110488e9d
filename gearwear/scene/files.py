"""Reading what a scene refers to, bounded and checked: scene TOML files (with `extends`), the
built-in scenes, user stiffness tables and measured flank deviations (CSV), relative to the scene file."""

from __future__ import annotations

import os
import re
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

from gearwear.core.validation import InputError, fail
from gearwear.geometry.flank import Deviation

TABLE_MIN_ROWS = 8


#: the other columns of the stiffness tables the tool writes (stiffness_job.curve_csv,
#: tables.HEADER): accepted in a user table and not used
TOOL_TABLE_COLUMNS = r"pairs_in_contact|ste_um|load_pair_\d+_N"


def read_deviation_csv(path: str | Path, gear_index: int) -> Deviation:
    """A measured profile deviation: CSV with the header columns ``diameter_mm`` and
    ``deviation_um`` (positive = material removed), at least 2 rows, diameters strictly
    increasing (checked against the flank by geometry.flank.check_flank)."""
    key = f"flank.deviation_csv[{gear_index}]"
    _, data = _read_csv(path, key, ("diameter_mm", "deviation_um"), min_rows=2, what="deviation file")
    return Deviation(
        tuple(float(x) for x in data[:, 0] * 1e-3), tuple(float(x) for x in data[:, 1] * 1e-6), source=Path(path).name
    )


def _read_csv(
    path: str | Path,
    key: str,
    required: tuple[str, ...],
    optional: tuple[str, ...] = (),
    min_rows: int = 2,
    what: str = "table",
    also: str | None = None,
):
    """(header, rows as a float array) of a small numeric CSV a scene refers to: the header
    starts with the ``required`` columns, may add ``optional`` ones and columns whose names
    match the regular expression ``also`` (read, not used: the other columns of a file the
    tool wrote itself), '#' lines are comments; at least ``min_rows`` complete rows of
    finite numbers. Problems are one-line InputErrors under ``key``."""
    import csv

    import numpy as np

    from gearwear.core.inputs import read_input_text

    p = Path(path)
    text = read_input_text(p, key, what, TABLE_LIMIT_BYTES)
    rows = [r for r in csv.reader(text.splitlines()) if r and not r[0].lstrip().startswith("#")]
    want = ",".join(required) + "".join(f"[,{c}]" for c in optional)
    if not rows:
        raise fail(key, repr(str(p)), "", f"empty file; expected a header {want}")
    head = [c.strip() for c in rows[0]]
    allowed = required + optional
    other = re.compile(also) if also else None
    known = [c in allowed or (other is not None and other.fullmatch(c) is not None) for c in head]
    if head[: len(required)] != list(required) or not all(known) or len(set(head)) != len(head):
        extra = f" with an optional {', '.join(optional)} column" if optional else ""
        raise fail(key, repr(str(p)), "", f"header {','.join(head)!r}: must be {','.join(required)}{extra}")
    try:
        data = np.array([[float(c) for c in r] for r in rows[1:]], dtype=float)
    except ValueError as exc:
        raise fail(key, repr(str(p)), "", f"non-numeric value ({exc})") from None
    if data.ndim != 2 or data.shape[0] < min_rows or data.shape[1] != len(head):
        n = data.shape[0] if data.ndim == 2 else 0
        raise fail(key, repr(str(p)), "", f"needs >= {min_rows} complete rows of {len(head)} columns, got {n}")
    if not np.all(np.isfinite(data)):
        r = int(np.argwhere(~np.isfinite(data))[0, 0]) + 2
        raise fail(key, repr(str(p)), "", f"row {r} (line {r}): values must be finite numbers")
    return head, data


def read_stiffness_table(path: str | Path, z_pinion: int):
    """A user mesh-stiffness table: CSV with the header columns ``angle_deg`` (pinion
    angle over one mesh period, 0 <= angle < 360 / z1, strictly increasing, at least 8
    rows, not necessarily uniform), ``k_N_per_m`` (>= 0) and optionally ``excitation_um``
    (the transmission-error excitation e, material removed > 0). The rows must cover the
    period: the wrap-around gap (first row + period - last row) may not exceed the largest
    spacing between rows. Returns (angle_rad, k_N_per_m, excitation_m or None)."""
    import numpy as np

    key = "effects.mesh_stiffness.path"
    p = Path(path)
    # the tool's own stiffness CSVs (gearwear stiffness, calibrate) read back as they are
    head, data = _read_csv(
        p,
        key,
        ("angle_deg", "k_N_per_m"),
        ("excitation_um",),
        TABLE_MIN_ROWS,
        "stiffness table",
        also=TOOL_TABLE_COLUMNS,
    )
    period = 360.0 / z_pinion
    ang, k = data[:, 0], data[:, 1]
    if ang[0] < 0 or ang[-1] >= period:
        raise fail(
            key,
            repr(str(p)),
            "",
            f"angle_deg must lie in [0, {period:g}) deg (one mesh period "
            f"of the {z_pinion}-tooth pinion), got {ang.min():g} to {ang.max():g} deg",
        )
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
        raise fail(
            key,
            repr(str(p)),
            "",
            f"the rows do not cover one mesh period ({period:g} deg): "
            f"{ang[0]:g} to {ang[-1]:g} deg leaves a {wrap:g} deg gap",
        )
    e = data[:, head.index("excitation_um")] * 1e-6 if "excitation_um" in head else None
    return np.radians(ang), k, e


def _resolve_table_path(data: dict[str, Any], base: Path) -> dict[str, Any]:
    """Relative paths of the files a scene refers to (the stiffness table, the measured
    deviations) are relative to the scene file's folder."""

    def resolve(p):
        return str(base / p) if isinstance(p, str) and p and not Path(p).is_absolute() else p

    ms = data.get("effects", {}).get("mesh_stiffness") if isinstance(data.get("effects"), dict) else None
    if isinstance(ms, dict) and "path" in ms:
        ms["path"] = resolve(ms["path"])
    fl = data.get("flank")
    if isinstance(fl, dict) and "deviation_csv" in fl:
        dev = fl["deviation_csv"]
        fl["deviation_csv"] = [resolve(p) for p in dev] if isinstance(dev, list) else resolve(dev)
    return data


def builtin_scene_dict(name: str) -> dict[str, Any]:
    """The raw TOML document of a built-in scene."""
    names = builtin_scene_names()
    if name not in names:
        raise InputError(f"built-in scene {name!r}: unknown (available: {', '.join(names)})")
    return tomllib.loads(resources.files("gearwear.data").joinpath(f"{name}.toml").read_text())


#: the largest scene file read (bytes): a scene is a few kB; more is not a scene
SCENE_LIMIT_BYTES = 1 << 20


#: the largest CSV a scene refers to (bytes): a 1e6-row stiffness table is ~40 MB
TABLE_LIMIT_BYTES = 64 << 20


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file (once, bounded, a regular file only: core.inputs.read_input),
    turning I/O and syntax problems into one-line InputErrors."""
    from gearwear.core.inputs import read_input

    p = Path(path)
    if not os.path.lexists(p):
        raise InputError(
            f"{p}: no such scene file, and not a built-in scene (built-in: {', '.join(builtin_scene_names())})"
        )
    data = read_input(p, "scene", "scene file", SCENE_LIMIT_BYTES)
    try:
        return tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(f"{p}: cannot read (not UTF-8 text: {type(exc).__name__})") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{p}: not valid TOML ({exc})") from None


def load_scene_dict(path: str | Path | None, default: str = "paper-default") -> tuple[dict[str, Any], str]:
    """(raw document, name) of a scene file or a built-in scene name; the built-in
    ``default`` when path is None. A file of that name wins over a built-in name. A file
    may start from another scene, ``extends = "paper-default"`` (a built-in name, or a
    file relative to it): that scene's keys, then the file's (tables merge key by key)."""
    if path is None:
        return builtin_scene_dict(default), default
    p = Path(path)
    if not p.exists() and str(path) in builtin_scene_names():
        return builtin_scene_dict(str(path)), str(path)
    return _extended(_resolve_table_path(load_toml(p), p.resolve().parent), p, 0), p.stem


def _extended(data: dict[str, Any], path: Path, depth: int) -> dict[str, Any]:
    """``data`` on top of the scene its ``extends`` key names (recursively, at most 8 deep)."""
    base_name = data.pop("extends", None)
    if base_name is None:
        return data
    if not isinstance(base_name, str) or not base_name:
        raise fail("extends", repr(base_name), "", "must be a built-in scene name or a scene file path")
    if depth >= 8:
        raise fail("extends", repr(base_name), "", "scenes extend each other more than 8 deep (a cycle?)")
    candidate = Path(base_name) if Path(base_name).is_absolute() else path.resolve().parent / base_name
    if candidate.exists():
        base = _extended(_resolve_table_path(load_toml(candidate), candidate.resolve().parent), candidate, depth + 1)
    elif base_name in builtin_scene_names():
        base = builtin_scene_dict(base_name)
    else:
        raise fail(
            "extends",
            repr(base_name),
            "",
            f"no such scene file, and not a built-in scene (built-in: {', '.join(builtin_scene_names())})",
        )
    base.pop("name", None)
    base.pop("description", None)
    return _merge(base, data)


def _merge(base: dict[str, Any], top: Mapping[str, Any]) -> dict[str, Any]:
    """``top`` over ``base``: tables merge key by key, any other value replaces."""
    out = dict(base)
    for k, v in top.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def builtin_scene_names() -> list[str]:
    return sorted(f.name[:-5] for f in resources.files("gearwear.data").iterdir() if f.name.endswith(".toml"))
