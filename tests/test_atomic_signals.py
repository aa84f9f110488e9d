"""A signal at *any* line of core/atomic.py leaves the target old or new, never mixed, and no
hidden temporary file or folder next to it.

The CI run of 2026-11-28 left ``.out.*.tmp`` behind when a SIGTERM reached ``gearwear
runup`` just after the temporary folder was created and before the cleanup that removes it
was armed (tests/test_signals.py, ``runup-write-SIGTERM``, about one run in a few hundred).
That is a whole class: any point between creating a temporary and registering its removal.
Here the signal is sent at each line event of core/atomic.py in turn (sys.settrace), for a
whole folder and for a single file, so every such window is hit deterministically.

Python's own SIGINT handler (KeyboardInterrupt) is used, as the handler gearwear installs
raises the same exception (core.interrupts)."""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

import pytest

from gearwear.core import atomic

ATOMIC_FILE = os.path.realpath(atomic.__file__)


def _signal_at_line(k: int):
    """A trace function that sends SIGINT to this process at the k-th line event in
    core/atomic.py (counted over every frame of that file) and returns whether it fired."""
    seen = [0]
    fired = [False]

    def local(frame, event, arg):
        if event == "line":
            seen[0] += 1
            if seen[0] == k and not fired[0]:
                fired[0] = True
                os.kill(os.getpid(), signal.SIGINT)
        return local

    def tracer(frame, event, arg):
        if os.path.realpath(frame.f_code.co_filename) == ATOMIC_FILE:
            return local(frame, event, arg)
        return None

    return tracer, fired


def _hidden(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith("."))


def _write_folder(target: Path) -> None:
    with atomic.atomic_folder(target) as tmp:
        (tmp / "new.txt").write_text("new")
        (tmp / "sub").mkdir()
        (tmp / "sub" / "b.txt").write_text("b")


def _write_file(target: Path) -> None:
    atomic.atomic_write_bytes(target, b"new")


@pytest.fixture(autouse=True)
def python_sigint_handler():
    """Python's own SIGINT handler, SIGINT unblocked, for the test: an earlier in-process test of
    the same pytest worker may have left another handler or mask (gearwear's command line keeps
    its handlers after a signal, as the process is ending; CI's make test saw 0 of the signals
    land in three of these cases under pytest-xdist)."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    mask = signal.pthread_sigmask(signal.SIG_UNBLOCK, [signal.SIGINT])
    yield
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    signal.signal(signal.SIGINT, old)


@pytest.mark.parametrize("kind", ["folder", "file"])
@pytest.mark.parametrize("existing", [True, False], ids=["replace", "create"])
def test_a_signal_at_any_line_leaves_old_or_new_and_nothing_hidden(tmp_path, kind, existing):
    write = _write_folder if kind == "folder" else _write_file
    k, interrupted_runs = 0, 0
    while True:
        k += 1
        case = tmp_path / f"case{k}"
        case.mkdir()
        target = case / "out"
        if existing and kind == "folder":
            target.mkdir()
            (target / "old.txt").write_text("old")
        elif existing:
            target.write_bytes(b"old")
        tracer, fired = _signal_at_line(k)
        interrupted = False
        sys.settrace(tracer)
        try:
            write(target)
            sys.settrace(None)
            os.sched_yield()  # a pending handler runs at the latest here
        except KeyboardInterrupt:
            interrupted = True
        finally:
            sys.settrace(None)
        if not fired[0]:  # k is past the last line of the write: every line was hit
            assert not interrupted
            break
        interrupted_runs += interrupted
        assert _hidden(case) == [], f"signal at line event {k}: left {_hidden(case)}"
        if kind == "folder":
            content = sorted(p.relative_to(target).as_posix() for p in target.rglob("*")) if target.exists() else None
            allowed = [["new.txt", "sub", "sub/b.txt"], ["old.txt"] if existing else None]
        else:
            content = target.read_bytes() if target.exists() else None
            allowed = [b"new", b"old" if existing else None]
        assert content in allowed, f"signal at line event {k}: {content}"
        if not interrupted:
            assert content == allowed[0]
    assert k > 10 and interrupted_runs > 5  # the trace reached the code and the signals landed
