"""Mesh-stiffness tables: CSV + JSON sidecar, cached by the hash of their inputs.

A table is k_h and the wear excitation over one mesh period (over a revolution of the
faulty gear with a fault), at nodes that need not be uniform (the breakpoints of the
load sharing are nodes, analytic.tvms); its span is recorded (``span_rad``) so that its
mean is the integral of the piecewise-linear table. Its sidecar records
the inputs, their SHA-256 (inputs + software version), the SHA-256 of the CSV bytes
(``csv_sha256``), the method, the FE mesh size, the estimated error and the version.
The cache key is the input hash. For calibrated tables the inputs include the
fingerprint of the calibration code (gearwear.stiffness.calibration.code_fingerprint), so a
changed input, a changed calibration code or a new software version never reuses a
stale table. Files are written atomically (temporary name + rename), data before
sidecar, so an interrupted run leaves no half-written table.

Reading an entry checks it (:func:`lookup`, a pure function that returns the table or
the reason it is not used): the sidecar belongs to these inputs, the CSV parses with
the expected header, it has exactly the rows its sidecar records, every value is finite, angles
increase, k > 0 wherever a pair is in contact (k = 0 only where none is), and the
CSV bytes match ``csv_sha256``. A bad entry is not used; the caller recomputes it
and reports the reason through its ``notify`` callback (:func:`to_stderr` by default
in gearwear.stiffness.calibration), e.g.::

    gearwear: cache entry 3fa2c1d0... (unworn, 0 um) is truncated (99 of 360 rows); recomputing

Cache folder: $GEARWEAR_CACHE, else ~/.cache/gearwear/tables. :func:`cache_dir`
creates it and raises a one-line InputError if it is a file or cannot be created or
written, so a bad setting stops a run before any computation.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gearwear import io
from gearwear.core.inputs import read_bounded
from gearwear.core.validation import fail
from gearwear.geometry.curves import curve_mean

#: the largest cache file read (a table of 10^6 rows is ~80 MB; a surrogate of 65536 runs ~0.5 GB)
ENTRY_LIMIT_BYTES = 1 << 30
SIDECAR_LIMIT_BYTES = 16 << 20

HEADER = "angle_deg,k_N_per_m,ste_um,excitation_um,pairs_in_contact"
_COLUMNS = HEADER.split(",")

#: receives one line, e.g. "cache entry 3fa2c1d0... (unworn, 0 um) is truncated (...); recomputing"
Notify = Callable[[str], None]


def to_stderr(message: str) -> None:
    """The default ``notify``: one line on stderr, prefixed like every CLI message."""
    print(f"gearwear: {message}", file=sys.stderr, flush=True)


def cache_dir() -> Path:
    """The cache folder ($GEARWEAR_CACHE, else ~/.cache/gearwear/tables), created if missing.

    Raises a one-line InputError if it is a file, or cannot be created or written."""
    root = os.environ.get("GEARWEAR_CACHE")
    path = Path(root).expanduser() if root else Path.home() / ".cache" / "gearwear" / "tables"
    key = "GEARWEAR_CACHE" if root else "cache folder"
    hint = "" if root else "; set GEARWEAR_CACHE to a writable folder"
    if path.exists() and not path.is_dir():
        raise fail(key, path, "", "is a file, not a folder" + hint)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise fail(key, path, "", f"cannot be created ({exc.strerror or exc})" + hint) from None
    try:  # a real probe: os.access says yes to root even on a read-only file system
        with tempfile.TemporaryFile(dir=path, prefix=".probe-"):
            pass
    except OSError as exc:
        raise fail(key, path, "", f"is not writable ({exc.strerror or exc})" + hint) from None
    return path


@dataclass
class StiffnessTable:
    """k_h(phi) and e(phi) over one mesh period, with provenance.

    ``from_cache`` is True when the table was read from an existing cache entry (not
    stored; only for the caller to report a cache hit). ``span_rad``: the pinion rotation
    the table spans (its period)."""

    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    excitation_m: np.ndarray
    ste_m: np.ndarray
    pairs_in_contact: np.ndarray
    meta: dict[str, Any]
    from_cache: bool = False
    span_rad: float = math.nan
    csv_bytes: bytes = field(default=b"", repr=False)  # the checked CSV bytes (cache or store)

    @property
    def sidecar_bytes(self) -> bytes:
        """The sidecar as the cache holds it (``meta`` in the sidecar's JSON form)."""
        return (io.json_text(self.meta) + "\n").encode("utf-8")

    @property
    def mean_N_per_m(self) -> float:
        """Mean of the piecewise-linear k_h over the span (geometry.curves.curve_mean)."""
        return curve_mean(self.angle_rad, self.k_N_per_m, self.span_rad)

    def to_csv(self) -> str:
        rows = [HEADER]
        for a, k, s, e, n in zip(self.angle_rad, self.k_N_per_m, self.ste_m, self.excitation_m, self.pairs_in_contact):
            rows.append(f"{math.degrees(a):.12g},{k:.12g},{s * 1e6:.12g},{e * 1e6:.12g},{int(n)}")
        return "\n".join(rows) + "\n"

    @classmethod
    def from_files(cls, csv_path: Path) -> "StiffnessTable":
        """Read a stored table (checked as by :func:`read`); ValueError if it is not valid."""
        meta = json.loads(Path(str(csv_path) + ".json").read_text())
        tab, reason = read(Path(csv_path), meta)
        if tab is None:
            raise ValueError(f"{csv_path}: {reason}")
        return tab


def table_key(inputs: dict[str, Any]) -> str:
    return io.input_hash(inputs)


def _parse(text: str, points: int | None) -> tuple[np.ndarray | None, str | None]:
    """The data rows of a table CSV as an (n, 5) array, or the reason they are not valid."""
    lines = text.split("\n")
    complete = lines[-1] == ""  # every row written ends with a newline
    if complete:
        lines.pop()
    if not lines or lines[0].strip() != HEADER:
        return None, "has no valid header line"
    body = lines[1:]
    rows = []
    for i, line in enumerate(body):
        fields = line.split(",")
        try:
            if len(fields) != len(_COLUMNS):
                raise ValueError
            rows.append([float(f) for f in fields])
        except ValueError:
            if i == len(body) - 1 and not complete:
                n = len(rows)
                return None, (
                    f"is truncated ({n} of {points} rows, the last one cut)"
                    if points
                    else f"is truncated (row {n + 1} cut)"
                )
            shown = line if len(line) <= 40 else line[:37] + "..."
            return None, f"has an unreadable line {i + 2} ({shown!r})"
    n = len(rows)
    if not complete:  # the last row parsed but has no newline: it may be cut inside its last number
        return None, (
            f"is truncated ({n} of {points} rows, the last one cut)"
            if points
            else "is truncated (no newline at the end)"
        )
    if points is not None and n != points:
        return None, (f"is truncated ({n} of {points} rows)" if n < points else f"has {n} rows, expected {points}")
    if n == 0:
        return None, "has no rows"
    data = np.array(rows, dtype=float)
    angle, k, ste, _, pairs = data.T
    # ste = e + F / k is infinite only where no pair is in contact (k = 0)
    finite = np.isfinite(data)
    finite[:, 2] |= (pairs == 0) & np.isinf(ste)
    if not finite.all():
        r, c = np.argwhere(~finite)[0]
        return None, f"has a non-finite {_COLUMNS[c]} ({data[r, c]:g}) on line {r + 2}"
    bad = np.nonzero((pairs < 0) | (pairs != np.round(pairs)))[0]
    if bad.size:
        return None, f"has an invalid pairs_in_contact ({pairs[bad[0]]:g}) on line {bad[0] + 2}"
    bad = np.nonzero(((pairs > 0) & ~(k > 0)) | (k < 0))[0]
    if bad.size:
        return None, (
            f"has k_N_per_m = {k[bad[0]]:g} on line {bad[0] + 2} with {int(pairs[bad[0]])} pair(s) in contact"
        )
    bad = np.nonzero(np.diff(angle) <= 0)[0]
    if bad.size:
        return None, f"has angles that do not increase (line {bad[0] + 3})"
    return data, None


def read(csv_path: Path, meta: dict[str, Any], points: int | None = None) -> tuple[StiffnessTable | None, str | None]:
    """Check and read one table CSV against its sidecar ``meta``: (table, None) or (None, reason).

    ``points``: the expected number of rows (default: ``meta["rows"]``, written by
    :func:`store`). The file is read bounded and only if it is a regular file
    (core.inputs.read_bounded: a folder, a FIFO or a link to a device is a reason, not a
    hang)."""
    raw, why = read_bounded(csv_path, "file", ENTRY_LIMIT_BYTES)
    if raw is None:
        return None, why
    return check(raw, meta, points)


def check(raw: bytes, meta: dict[str, Any], points: int | None = None) -> tuple[StiffnessTable | None, str | None]:
    """:func:`read` on the bytes of a table CSV."""
    if points is None:
        # the breakpoints of the load sharing add nodes: the sidecar records the rows written
        points = meta.get("rows")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        return None, "is not a text file"
    data, reason = _parse(text, points)
    if data is None:
        return None, reason
    want = meta.get("csv_sha256")
    if not want:
        return None, "has no csv_sha256 in its sidecar"
    if hashlib.sha256(raw).hexdigest() != want:
        return None, "does not match the csv_sha256 of its sidecar (changed after it was stored)"
    span = meta.get("span_rad")
    if not isinstance(span, (int, float)) or not span > data[-1, 0] * math.pi / 180:
        return None, "has no valid span_rad in its sidecar (the table's period, beyond its last angle)"
    tab = StiffnessTable(
        np.radians(data[:, 0]),
        data[:, 1],
        data[:, 3] * 1e-6,
        data[:, 2] * 1e-6,
        data[:, 4].astype(int),
        meta,
        from_cache=True,
        span_rad=float(span),
        csv_bytes=raw,
    )
    return tab, None


def lookup(inputs: dict[str, Any], folder: Path | None = None) -> tuple[StiffnessTable | None, str | None]:
    """The cache entry for exactly these inputs: (table, None) on a valid hit, (None, None)
    if there is none, (None, reason) if there is one that must not be used.

    Pure apart from reading the files (and :func:`cache_dir` creating the folder):
    it prints nothing; the caller reports the reason (:func:`entry_message`)."""
    csv, meta, reason = entry(folder or cache_dir(), table_key(inputs), ".csv")
    return (None, reason) if meta is None else read(csv, meta)


def entry(folder: Path, key: str, suffix: str) -> tuple[Path, dict[str, Any] | None, str | None]:
    """(data file ``<key><suffix>``, its sidecar's metadata, None) for an entry whose sidecar
    belongs to ``key``; (path, None, None) if there is no entry; (path, None, reason) if
    there is one that must not be used. Shared by every kind of cache entry (stiffness
    tables, diagnosis surrogates); the caller then checks the data itself (read with
    core.inputs.read_bounded). Both files are read only if they are regular files, within a
    size bound: a folder, a FIFO, a link to /dev/zero or an unreadable file in their place
    is a reason to recompute, never a hang or a crash."""
    path = folder / f"{key}{suffix}"
    side = Path(str(path) + ".json")
    has_data, has_side = os.path.lexists(path), os.path.lexists(side)
    if not (has_data or has_side):
        return path, None, None
    if not has_side:
        return path, None, "has no sidecar"
    if not has_data:
        return path, None, "has a sidecar but no data"
    raw, why = read_bounded(side, "file", SIDECAR_LIMIT_BYTES)
    if raw is None:
        return path, None, f"has an unusable sidecar ({why})"
    try:
        meta = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        return path, None, f"has an unreadable sidecar ({type(exc).__name__})"
    if not isinstance(meta, dict) or meta.get("input_sha256") != key:
        return path, None, "has a sidecar that belongs to other inputs"
    return path, meta, None


def write_entry(key: str, label: str, files: dict[Path, bytes], notify: Notify | None = to_stderr) -> bool:
    """Write the files of a cache entry, in order (data first, then its sidecar), each
    atomically and over whatever damaged entry is there (a folder in its place is removed:
    the cache's names are its own). If that fails (OSError) ``notify`` gets one line and the
    caller uses its result without caching it; returns whether the entry was stored."""
    try:
        for path, data in files.items():
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            io.write_bytes(path, data)
        return True
    except OSError as exc:
        if notify is not None:
            notify(
                f"cache entry {key[:8]}... ({label}) could not be stored ({exc.strerror or exc}); the result "
                "is used without caching it"
            )
        return False


def entry_message(key: str, label: str, reason: str) -> str:
    """One line for ``notify``: ``cache entry 3fa2c1d0... (unworn, 0 um) <reason>; recomputing``."""
    return f"cache entry {key[:8]}... ({label}) {reason}; recomputing"


def cached(
    inputs: dict[str, Any], folder: Path | None = None, notify: Notify | None = None, label: str = ""
) -> StiffnessTable | None:
    """The valid cached table for exactly these inputs, or None (a bad entry is reported
    to ``notify``, if given, as one line)."""
    tab, reason = lookup(inputs, folder)
    if reason is not None and notify is not None:
        notify(entry_message(table_key(inputs), label or "table", reason))
    return tab


def store(
    table: StiffnessTable,
    inputs: dict[str, Any],
    method: str,
    folder: Path | None = None,
    extra: dict[str, Any] | None = None,
    label: str = "table",
    notify: Notify | None = to_stderr,
) -> Path:
    """Write the table and its sidecar into the cache (atomic; if that fails, ``notify``
    gets one line and the table is used uncached, :func:`write_entry`); returns the CSV path.

    The sidecar records ``csv_sha256``, the SHA-256 of the CSV bytes, which a read checks.
    Afterwards ``table`` holds exactly what a later read of the entry returns (the
    values as written, the sidecar as ``meta``), so cold and cached results are
    bit-identical; ValueError if the table fails the checks of a read."""
    folder = folder or cache_dir()
    key = table_key(inputs)
    csv = folder / f"{key}.csv"
    data = table.to_csv().encode("utf-8")
    side = io.sidecar_bytes(
        csv,
        inputs,
        method,
        {
            **(extra or {}),
            "mean_N_per_m": table.mean_N_per_m,
            "rows": int(len(table.angle_rad)),
            "span_rad": table.span_rad,
            "csv_sha256": hashlib.sha256(data).hexdigest(),
        },
    )
    # sidecar first would let a reader see metadata without data; write data first
    write_entry(key, label, {csv: data, Path(str(csv) + ".json"): side}, notify)
    meta = json.loads(side)
    # from the bytes written, not from the file: a concurrent writer of the same key cannot interfere
    back, reason = check(data, meta)
    if back is None:
        raise ValueError(f"{csv}: the computed table {reason}")
    table.angle_rad, table.k_N_per_m, table.excitation_m = back.angle_rad, back.k_N_per_m, back.excitation_m
    table.ste_m, table.pairs_in_contact, table.meta, table.from_cache = (back.ste_m, back.pairs_in_contact, meta, False)
    table.csv_bytes = data
    return csv
