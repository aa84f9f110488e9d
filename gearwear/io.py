"""Atomic, traceable output files.

Every file is written to a temporary name in the destination folder and renamed
over the target, so a crash or an error never leaves a half-written file. Result
files get a JSON sidecar (``<file>.json``) with the inputs, their SHA-256 hash,
the method and the software version.
"""

from __future__ import annotations

import hashlib
import io
import json
from pathlib import Path
from typing import Any

from gearwear.core.atomic import atomic_write_bytes

from . import __version__


def write_bytes(path: str | Path, data: bytes) -> Path:
    return atomic_write_bytes(path, data)


def write_text(path: str | Path, text: str) -> Path:
    return write_bytes(path, text.encode("utf-8"))


def write_figure(fig, path: str | Path, dpi: int = 130) -> Path:
    """Save a matplotlib figure atomically (PNG, deterministic metadata)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, metadata={"Software": None}, bbox_inches="tight")
    return write_bytes(path, buf.getvalue())


def canonical_json(obj: Any) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=_default)


def _default(o: Any):
    if hasattr(o, "tolist"):
        return o.tolist()
    if isinstance(o, (set, tuple)):
        return list(o)
    return str(o)


def input_hash(inputs: Any) -> str:
    """SHA-256 of the canonical JSON of ``inputs`` and the software version."""
    return hashlib.sha256((canonical_json(inputs) + __version__).encode()).hexdigest()


def sidecar(path: str | Path, inputs: Any, method: str, extra: dict | None = None) -> Path:
    """Write ``<path>.json`` describing how ``path`` was made."""
    meta = {"file": Path(path).name, "software": "gearwear", "version": __version__,
            "method": method, "inputs": inputs, "input_sha256": input_hash(inputs)}
    if extra:
        meta.update(extra)
    return write_text(str(path) + ".json", json.dumps(meta, indent=2, sort_keys=True, default=_default) + "\n")
