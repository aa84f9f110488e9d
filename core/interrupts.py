"""SIGINT (Ctrl-C) and SIGTERM: a command ends cleanly at any moment.

* :func:`handled` (the command line, around a whole command): SIGINT raises
  KeyboardInterrupt and SIGTERM raises :class:`Terminated` (a KeyboardInterrupt), so every
  ``finally`` and ``except BaseException`` cleanup runs for both: temporary folders are
  removed, worker processes stopped. Only the first signal raises; later ones (a second
  Ctrl-C, a SIGTERM on top) are ignored, so the cleanup is not cut short.
* :func:`deferred` (short critical sections): a signal is recorded and delivered when the
  section ends; with ``children=True`` it is also blocked in this thread's signal mask,
  which threads and processes started inside inherit (a worker process then never sees
  the Ctrl-C that the terminal sends to the whole process group: the parent handles it
  once and stops its workers).
* :func:`worker_init` (first thing in a worker process of a local pool): SIGINT ignored,
  SIGTERM back to its default action (the parent ends its workers with SIGTERM).

Python runs signal handlers in the main thread only; elsewhere these do nothing.
"""

from __future__ import annotations

import _thread
import signal
import sys
import threading
import time
from contextlib import contextmanager
from typing import Any, Iterator

SIGNALS = (signal.SIGINT, signal.SIGTERM)
#: the exit status of a command ended by a signal (128 + its number, as a shell reports it)
EXIT_STATUS = {signal.SIGINT: 130, signal.SIGTERM: 143}


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that the same cleanups run (exit status 143)."""

    signum = signal.SIGTERM


def exception_for(signum: int) -> KeyboardInterrupt:
    """The exception that stands for ``signum``: Terminated for SIGTERM, else KeyboardInterrupt."""
    return Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def signal_of(exc: BaseException) -> signal.Signals:
    """The signal an interrupt exception stands for."""
    return signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT


class _State:
    received: int | None = None  # the first signal while handled() is active
    lost: bool = False  # its exception was swallowed ("Exception ignored in ...")


_STATE = _State()


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def _raise_once(signum: int, frame: Any) -> None:
    if _STATE.received is not None and not _STATE.lost:  # cleaning up after the first signal: ignored
        return
    _STATE.received, _STATE.lost = signum if _STATE.received is None else _STATE.received, False
    raise exception_for(_STATE.received)


def _unraisable(hook):
    """sys.unraisablehook while :func:`handled` is active. Python runs a signal handler at
    any point of the main thread, also inside a weakref callback or a ``__del__`` method,
    where an exception cannot propagate: it is printed ("Exception ignored in ...") and
    dropped, and the command would run on to the end. Such a lost interrupt is delivered
    again (``_thread.interrupt_main``: the handler runs at the next point of the main
    thread, where it can propagate) instead of being printed; anything else goes to
    ``hook``."""

    def unraisable(info) -> None:
        if isinstance(info.exc_value, KeyboardInterrupt) and _STATE.received is not None:
            _STATE.lost = True
            # from another thread, a moment later: here the handler would run (and be
            # swallowed) at once
            threading.Thread(target=_deliver_later, args=(_STATE.received,), daemon=True).start()
            return
        hook(info)

    return unraisable


def _deliver_later(signum: int) -> None:
    """Send ``signum`` to the main thread again, a moment later."""
    time.sleep(0.02)
    _thread.interrupt_main(signal.Signals(signum))


@contextmanager
def handled() -> Iterator[_State]:
    """Inside: SIGINT -> KeyboardInterrupt, SIGTERM -> Terminated, the first one only. On
    exit the previous handlers come back, unless a signal was received: the process is
    ending because of it, and a second Ctrl-C must not interrupt what remains (the
    interpreter's exit, which joins the pools' threads)."""
    if not _main_thread():
        yield _STATE
        return
    old = {s: signal.getsignal(s) for s in SIGNALS}
    old_hook = sys.unraisablehook
    _STATE.received, _STATE.lost = None, False
    sys.unraisablehook = _unraisable(old_hook)
    for s in SIGNALS:
        signal.signal(s, _raise_once)
    try:
        yield _STATE
    finally:
        if _STATE.received is None:
            sys.unraisablehook = old_hook
            for s, h in old.items():
                signal.signal(s, h if h is not None else signal.SIG_DFL)


@contextmanager
def deferred(children: bool = False) -> Iterator[list[int]]:
    """While inside, SIGINT and SIGTERM are recorded (the yielded list) instead of handled;
    on exit the handlers come back and each recorded signal is delivered to them (so under
    :func:`handled` the first raises). ``children``: also block both in this thread's
    signal mask while inside, so threads and processes started inside inherit the block.
    A caller may clear the list to drop what it has dealt with itself."""
    hits: list[int] = []
    if not _main_thread():
        yield hits
        return
    old = {s: signal.getsignal(s) for s in SIGNALS}
    for s in SIGNALS:
        signal.signal(s, lambda signum, frame: hits.append(signum))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS) if children else None
    try:
        yield hits
    finally:
        if mask is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        for s, h in old.items():
            signal.signal(s, h if h is not None else signal.SIG_DFL)
        for hit in dict.fromkeys(hits):
            signal.raise_signal(hit)


@contextmanager
def blocked_sigint() -> Iterator[None]:
    """SIGINT blocked in this thread's mask while inside (the handler is deferred as by
    :func:`deferred`): threads and processes started inside inherit the block and so never
    see a Ctrl-C. For pools whose workers cannot run :func:`worker_init` first (a Dask
    LocalCluster spawns them from its own thread): SIGTERM stays deliverable to them, which
    is how their nanny ends them.

    multiprocessing's resource tracker, started on first use, unblocks SIGINT in the thread
    that starts it (which would then spawn the workers unprotected): it is started here,
    before the block."""
    if not _main_thread():
        yield
        return
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    with deferred():
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, (signal.SIGINT,))
        try:
            yield
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def rearm() -> None:
    """Install the current Python handlers of SIGINT and SIGTERM again (main thread only).
    For after a C library that sets the process's signal actions behind Python's back:
    Gmsh's initialize() resets both to the default action (terminate, leaving temporary
    folders and workers behind) while Python still reports its own handlers."""
    if not _main_thread():
        return
    for s in SIGNALS:
        h = signal.getsignal(s)
        if h is not None:
            signal.signal(s, h)


def worker_init() -> None:
    """In a worker process: ignore SIGINT, SIGTERM to its default action, both unblocked
    (a forked worker starts with its parent's handlers and, from a pool that forks inside
    :func:`deferred` with ``children=True``, with both blocked)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)
