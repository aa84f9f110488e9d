"""Reading a user's input file: once, bounded, and only if it is a regular file.

Every file a command reads (a scene, a stiffness table, a flank deviation, a measured
vibration) goes through :func:`read_input`:

* it is opened without blocking (``O_NONBLOCK``) and checked with ``fstat`` on the open
  descriptor, so a FIFO, a device or a socket is refused in one line instead of hanging
  the command (or reading /dev/zero until the machine runs out of memory), and the check
  and the read concern the same file (no race with a rename in between);
* its size is bounded before it is read (``limit_bytes``: more than any input of its kind
  the tool could use), and at most ``limit_bytes + 1`` bytes are read, so a file growing
  while it is read is caught too;
* it is read once: the bytes parsed are the bytes whose SHA-256 is recorded
  (:func:`recorded_sha256`, used by the manifests), never a second read of a file that may
  have changed in between.
"""

from __future__ import annotations

import hashlib
import os
import stat
import threading
from pathlib import Path

from .validation import fail

#: SHA-256 of the bytes each input was parsed from, by resolved path (this process)
_DIGESTS: dict[str, str] = {}
_LOCK = threading.Lock()

MiB = 1 << 20


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a pipe (FIFO)"),
        (stat.S_ISCHR, "a device"),
        (stat.S_ISBLK, "a device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a regular file"


class _Refused(Exception):
    """Why a file is not read (``stream``: it is not a regular file)."""

    def __init__(self, why: str, stream: bool = False):
        super().__init__(why)
        self.stream = stream


def _read(p: Path, what: str, limit_bytes: int) -> bytes:
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise _Refused(f"no such {what}") from None
    except IsADirectoryError:
        raise _Refused(f"is a folder, not a {what}") from None
    except OSError as exc:
        raise _Refused(f"cannot be read ({exc.strerror or type(exc).__name__})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise _Refused(f"is {_kind(st.st_mode)}, not a {what}", stream=True)
        if st.st_size > limit_bytes:
            raise _Refused(
                f"is {st.st_size} bytes, more than any {what} the tool can use (at most {limit_bytes} bytes)"
            )
        chunks, n = [], 0
        while n <= limit_bytes:
            block = os.read(fd, min(MiB, limit_bytes + 1 - n))
            if not block:
                break
            chunks.append(block)
            n += len(block)
        data = b"".join(chunks)
    except OSError as exc:
        raise _Refused(f"cannot be read ({exc.strerror or type(exc).__name__})") from None
    finally:
        os.close(fd)
    if len(data) > limit_bytes:
        raise _Refused(f"grew past {limit_bytes} bytes while it was read, more than any {what} the tool can use")
    return data


def read_input(path: str | Path, key: str, what: str, limit_bytes: int) -> bytes:
    """The bytes of the input file ``path``, or a one-line
    :class:`~gearwear.core.validation.InputError` under ``key`` ("KEY = 'path': why") if it
    is missing, not a regular file, unreadable or larger than ``limit_bytes``. The SHA-256 of
    the bytes is recorded for :func:`recorded_sha256`."""
    p = Path(path)
    try:
        data = _read(p, what, limit_bytes)
    except _Refused as exc:
        hint = ": inputs are read from regular files (save a stream to a file first)" if exc.stream else ""
        raise fail(key, repr(str(p)), "", f"{exc}{hint}") from None
    with _LOCK:
        _DIGESTS[str(p.resolve())] = hashlib.sha256(data).hexdigest()
    return data


def read_bounded(path: str | Path, what: str, limit_bytes: int) -> tuple[bytes | None, str | None]:
    """(bytes, None), or (None, why) for a file that is missing, not a regular file (a
    folder, a FIFO, a device, a link to one), unreadable or larger than ``limit_bytes``:
    the same checks as :func:`read_input`, for files the tool reads to check them (cache
    entries, an old manifest), which are not inputs of a result (nothing is recorded)."""
    try:
        return _read(Path(path), what, limit_bytes), None
    except _Refused as exc:
        return None, str(exc)


def read_input_text(path: str | Path, key: str, what: str, limit_bytes: int) -> str:
    """:func:`read_input` decoded as UTF-8 (one line naming the file if it is not)."""
    data = read_input(path, key, what, limit_bytes)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise fail(key, repr(str(path)), "", f"is not UTF-8 text (byte {exc.start})") from None


def recorded_sha256(path: str | Path) -> str | None:
    """The SHA-256 of the bytes ``path`` was parsed from in this process, or None if it was
    not read through :func:`read_input`."""
    with _LOCK:
        return _DIGESTS.get(str(Path(path).resolve()))
