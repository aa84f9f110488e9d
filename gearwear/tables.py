"""Mesh-stiffness tables: CSV + JSON sidecar, cached by the hash of their inputs.

A table is k_h and the wear excitation over one mesh period. Its sidecar records
the inputs, their SHA-256 (inputs + software version), the method, the FE mesh size,
the estimated error and the version. The cache key is that hash, so a changed input
(or a new software version) never reuses a stale table; files are written atomically
(temporary name + rename), so an interrupted run leaves no half-written table.

Cache folder: $GEARWEAR_CACHE, else ~/.cache/gearwear/tables.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from . import io


def cache_dir() -> Path:
    root = os.environ.get("GEARWEAR_CACHE")
    return Path(root) if root else Path.home() / ".cache" / "gearwear" / "tables"


@dataclass
class StiffnessTable:
    """k_h(phi) and e(phi) over one mesh period, with provenance."""

    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    excitation_m: np.ndarray
    ste_m: np.ndarray
    pairs_in_contact: np.ndarray
    meta: dict[str, Any]

    @property
    def mean_N_per_m(self) -> float:
        return float(np.mean(self.k_N_per_m))

    def to_csv(self) -> str:
        rows = ["angle_deg,k_N_per_m,ste_um,excitation_um,pairs_in_contact"]
        for a, k, s, e, n in zip(self.angle_rad, self.k_N_per_m, self.ste_m, self.excitation_m,
                                 self.pairs_in_contact):
            rows.append(f"{math.degrees(a):.12g},{k:.12g},{s * 1e6:.12g},{e * 1e6:.12g},{int(n)}")
        return "\n".join(rows) + "\n"

    @classmethod
    def from_files(cls, csv_path: Path) -> "StiffnessTable":
        data = np.loadtxt(csv_path, delimiter=",", skiprows=1, ndmin=2)
        meta = json.loads(Path(str(csv_path) + ".json").read_text())
        return cls(np.radians(data[:, 0]), data[:, 1], data[:, 3] * 1e-6, data[:, 2] * 1e-6,
                   data[:, 4].astype(int), meta)


def table_key(inputs: dict[str, Any]) -> str:
    return io.input_hash(inputs)


def cached(inputs: dict[str, Any], folder: Path | None = None) -> StiffnessTable | None:
    """The cached table for exactly these inputs, or None."""
    folder = folder or cache_dir()
    key = table_key(inputs)
    csv = folder / f"{key}.csv"
    side = Path(str(csv) + ".json")
    if not (csv.exists() and side.exists()):
        return None
    try:
        meta = json.loads(side.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    if meta.get("input_sha256") != key:
        return None
    return StiffnessTable.from_files(csv)


def store(table: StiffnessTable, inputs: dict[str, Any], method: str, folder: Path | None = None,
          extra: dict[str, Any] | None = None) -> Path:
    """Write the table and its sidecar into the cache (atomic); returns the CSV path."""
    folder = folder or cache_dir()
    key = table_key(inputs)
    csv = folder / f"{key}.csv"
    # sidecar first would let a reader see metadata without data; write data first
    io.write_text(csv, table.to_csv())
    io.sidecar(csv, inputs, method, {**(extra or {}), **{"mean_N_per_m": table.mean_N_per_m}})
    table.meta = json.loads(Path(str(csv) + ".json").read_text())
    return csv
