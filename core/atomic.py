"""Atomic file and folder writing, shared by every layer (core is the bottom of the
import graph).

A file is written to a temporary name in its destination folder and renamed over
the target, so an error never leaves a half-written file. A whole folder
(:func:`atomic_folder`) is written into a temporary folder next to it and swapped in
as a whole, so a set of files is complete or absent, never mixed with an earlier set."""

from __future__ import annotations

import os
import secrets
import shutil
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator

from . import interrupts


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
    tmp: str | None = None
    try:
        # a signal between creating the temporary and the assignment would leave it
        # behind: it is delivered once ``tmp`` is set, inside this try
        with interrupts.deferred():
            tmp = _create_temp(p)
        writer(tmp)
        os.replace(tmp, p)
    except BaseException:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return p


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)

    return atomic_write(path, write)


# -- whole folders ----------------------------------------------------------------------


def _new_sibling_dir(p: Path, tag: str) -> Path:
    """Create a new, empty folder next to ``p`` (same filesystem, so renames are atomic),
    hidden and named after it. ``os.mkdir(..., 0o777)`` lets the umask set the mode, as
    for an ordinary folder (tempfile.mkdtemp would make it 0700)."""
    for _ in range(100):
        d = p.parent / f".{p.name}.{secrets.token_hex(6)}.{tag}"
        try:
            os.mkdir(d, 0o777)
        except FileExistsError:
            continue
        return d
    raise FileExistsError(f"{p}: no free temporary folder name in {p.parent}")


def swap_in(new: Path, target: Path, may_replace: Callable[[Path], None] | None = None) -> None:
    """Put the folder ``new`` at ``target`` as a whole: rename the old ``target`` aside,
    rename ``new`` in, delete the old one. SIGINT or SIGTERM during the two renames undoes
    them (the old folder is back, ``new`` is removed) and is then delivered
    (core.interrupts.deferred: KeyboardInterrupt under the command line's handlers); one
    while the old folder is deleted is delivered after it (the swap is done).

    ``may_replace(folder)`` raises if the folder at ``target`` must not be replaced. It is
    called on ``target`` just before the swap and again on the folder renamed aside, which
    nothing can add a file to by its old name any more: a file that appeared in ``target``
    during the run, up to the rename, is never deleted (the swap is undone and the
    exception raised)."""
    old: Path | None = None
    undone = False
    with interrupts.deferred() as hits:
        try:
            if target.exists():
                if may_replace is not None:
                    may_replace(target)
                old = _new_sibling_dir(target, "old")
                os.rmdir(old)  # only the free name is wanted: rename(dir, dir) needs no target
                os.rename(target, old)
                if may_replace is not None:
                    may_replace(old)
            os.rename(new, target)
        except BaseException:
            if old is not None and old.exists() and not target.exists():
                os.rename(old, target)
            raise
        if hits:  # a signal during the renames: put the old folder back (delivered on leaving)
            os.rename(target, new)
            if old is not None:
                os.rename(old, target)
            shutil.rmtree(new, ignore_errors=True)
            undone = True
        elif old is not None:
            shutil.rmtree(old, ignore_errors=True)
    if undone:  # the signal was delivered on leaving; if its handler did not raise, the caller still must know
        raise interrupts.exception_for(hits[0])


@contextmanager
def atomic_folder(path: str | os.PathLike, may_replace: Callable[[Path], None] | None = None) -> Iterator[Path]:
    """Write a whole folder atomically: yields a fresh, empty temporary folder next to
    ``path``; when the block ends normally, that folder replaces ``path`` as a whole
    (:func:`swap_in`), so ``path`` afterwards holds exactly what the block wrote -- no
    file of an earlier content survives. On any exception, KeyboardInterrupt included,
    the temporary folder is removed and ``path`` is left as it was.

    A symlink at ``path`` is followed: the folder it points to is replaced. The caller
    decides whether ``path`` may be replaced at all (gearwear.io checks that it is
    empty or written by gearwear, and passes that check as ``may_replace``, see
    :func:`swap_in`)."""
    p = Path(path)
    if p.is_symlink():
        p = p.resolve()
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp: Path | None = None
    try:
        # as in atomic_write: a signal right after the mkdir is delivered inside this try
        with interrupts.deferred():
            tmp = _new_sibling_dir(p, "tmp")
        yield tmp
        swap_in(tmp, p, may_replace)
    except BaseException:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        raise
