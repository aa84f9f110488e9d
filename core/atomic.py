"""Atomic file writing, shared by every layer (geometry is the bottom of the import graph).

A file is written to a temporary name in its destination folder and renamed over
the target, so an error never leaves a half-written file."""

from __future__ import annotations

import os
import secrets
from pathlib import Path
from typing import Callable


def _create_temp(p: Path) -> str:
    """Create an empty, new file next to ``p`` with the target's extension.

    ``os.open(..., 0o666)`` lets the kernel apply the process umask, so the file gets
    the mode an ordinary ``open(p, "w")`` would give (tempfile.mkstemp makes 0600, and
    learning the umask with os.umask would change it process-wide, racing other threads).
    O_EXCL makes the name ours alone."""
    for _ in range(100):
        tmp = str(p.parent / f".{p.name}.{secrets.token_hex(6)}.tmp{p.suffix}")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise FileExistsError(f"{p}: no free temporary name in {p.parent}")


def atomic_write(path: str | os.PathLike, writer: Callable[[str], None]) -> Path:
    """Call ``writer(tmp_path)`` and rename the result to ``path``.

    The temporary file keeps the target's extension (some writers pick the format
    from it) and has the mode 0o666 & ~umask of an ordinary new file."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = _create_temp(p)
    try:
        writer(tmp)
        os.replace(tmp, p)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return p


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)
    return atomic_write(path, write)
