"""The ``gearwear`` command line.

Every command works without a file (the built-in paper pair). A bad input prints
one line ``gearwear: error: <key> = <value> <unit>: <allowed range>`` and exits 2;
nothing is written before all inputs are validated, and files are written atomically.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import importlib
import os
import sys
from pathlib import Path
from typing import NoReturn

from gearwear import __version__, io
from gearwear.core.validation import InputError, renamed

#: the commands, in the order of ``gearwear --help``: each is the module gearwear.cli.NAME with
#: ``add_parser(sub)`` (its arguments; ``set_defaults(func=run)``) and ``run(args) -> int``
COMMANDS = (
    "geometry",
    "stiffness",
    "verify",
    "calibrate",
    "simulate",
    "sweep",
    "runup",
    "diagnose",
    "atlas",
    "scene",
    "report",
)


class _Parser(argparse.ArgumentParser):
    """argparse with the one-line error of every other bad input (no usage block)."""

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"gearwear: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="gearwear",
        description=(
            "FE-verified mesh stiffness and dynamics of spur gears with wear, backlash and bearing "
            "clearance. Without a file every command uses the built-in paper pair (Zhang et al. 2019, Table 2)."
        ),
    )
    p.add_argument("--version", action="version", version=f"gearwear {__version__}")
    p.add_argument("--debug", action="store_true", help="show Python tracebacks instead of one-line errors")
    sub = p.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        importlib.import_module(f"gearwear.cli.{command}").add_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run one command. Exit status: 0 done, 2 bad input (one line naming the key, value,
    unit and allowed range; nothing written), 1 an internal failure (one line; the
    traceback only with --debug), 130 interrupted by SIGINT (Ctrl-C) and 143 by SIGTERM
    (one line; nothing half-written, worker processes stopped).

    The signal handlers come first (core.interrupts.handled): a signal during the imports
    of a command is handled like one during its computation. Called without ``argv`` (the
    console script, ``python -m gearwear.cli``) the process ends here (:func:`quick_exit`);
    with ``argv`` (tests, other programs) it returns the status."""
    status = _main(argv)
    if argv is None:
        quick_exit(status)
    return status


def quick_exit(status: int) -> NoReturn:
    """End the process with ``status`` once the command is done, as the interpreter would
    but without its teardown: the non-daemon threads are waited for and the exit handlers
    run (threading's and atexit's: executors, Dask, multiprocessing), the standard streams
    are flushed, then ``os._exit``. Freeing every module and object of numpy, scipy,
    numba, pydantic and matplotlib one by one took 0.2-0.4 s after every command
    (``gearwear sweep``: 0.21-0.28 s after its last line; an import of the sweep's modules
    alone: 0.43 s to exit normally, 0.02 s this way; measured on 2 shared cores). Every
    file a command writes is closed (and renamed into place) before it returns."""
    import threading

    with contextlib.suppress(Exception):
        threading._shutdown()  # type: ignore[attr-defined]  # what Py_Finalize does first
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a closed pipe (| head): nothing more to say
            stream.flush()
    os._exit(status)


def _main(argv: list[str] | None) -> int:
    from gearwear.core import interrupts

    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv  # accepted anywhere on the line, not only before the command
    with interrupts.handled():
        written = len(io.SWAPPED_IN)
        try:
            _safe_streams()
            return _run(argv, debug)
        except KeyboardInterrupt as exc:  # also one that arrives while another error is reported
            if debug:
                raise
            sig = interrupts.signal_of(exc)
            done = io.SWAPPED_IN[written:]
            what = f"after writing {', '.join(map(str, done))}" if done else "nothing was written or replaced"
            _say(f"gearwear: interrupted by {sig.name}{' (Ctrl-C)' if sig.name == 'SIGINT' else ''}; {what}")
            return interrupts.EXIT_STATUS[sig]
        finally:
            if isinstance(sys.stderr, _LineStart):
                sys.stderr = sys.stderr._stream


def _say(line: str) -> None:
    """One line on stderr, on a line of its own."""
    if isinstance(sys.stderr, _LineStart):
        sys.stderr.say(line)
    else:
        print(line, file=sys.stderr, flush=True)


class _LineStart:
    """sys.stderr, remembering whether the last character written ended a line, so that a
    final message starts on a line of its own even if a progress bar the signal hit was
    left unfinished (:meth:`say`)."""

    def __init__(self, stream):
        self._stream = stream
        self._last = "\n"

    def write(self, text: str) -> int:
        if text:
            self._last = text[-1]
        return self._stream.write(text)

    def say(self, line: str) -> None:
        self.write(("" if self._last == "\n" else "\n") + line + "\n")
        self.flush()

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _safe_streams() -> None:
    """Printing never fails on a character the terminal's encoding lacks (an --out named
    "résultats" under LC_ALL=C or PYTHONIOENCODING=ascii): it is written escaped instead of
    ending the command after its files were written."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None and stream.errors in ("strict", None):
            with contextlib.suppress(ValueError, OSError):
                reconfigure(errors="backslashreplace")
    if not isinstance(sys.stderr, _LineStart):
        sys.stderr = _LineStart(sys.stderr)


def _run(argv: list[str], debug: bool) -> int:
    parser = build_parser()
    args = parser.parse_args([a for a in argv if a != "--debug"])
    args.debug = debug
    try:
        return args.func(args)
    except InputError as exc:
        if args.debug:
            raise
        _say(f"gearwear: error: {renamed(exc, FLAG_NAMES)}")
        return 2
    except BrokenPipeError:  # output piped into head & co.: not an error of ours
        sys.stderr.close()
        return 0
    except Exception as exc:
        # a mesher failure is ours too: every shape reaching the FE passed the geometry's
        # checks, so a shape Gmsh cannot mesh is a bug, never the user's input
        if args.debug:
            raise
        where = exc.__traceback__
        while where is not None and where.tb_next is not None:
            where = where.tb_next
        at = f" at {Path(where.tb_frame.f_code.co_filename).name}:{where.tb_lineno}" if where else ""
        msg = str(exc).splitlines()[0] if str(exc) else ""
        _say(
            f"gearwear: internal error: {type(exc).__name__}{at}: {msg} (this is a bug; rerun with --debug "
            "for the traceback and report it)"
        )
        return 1


#: the lower layers' own parameter names -> the command-line flags that set them
FLAG_NAMES = {"method": "--method", "fields": "--fields", "points": "--points", "positions": "--positions"}


if __name__ == "__main__":
    sys.exit(main())
