"""Run every benchmarks/bench_*.py in turn (``make bench``). Timings are printed,
never asserted. ``python benchmarks/run_all.py bench_a.py bench_b.py`` runs only those.

Each script runs in this one process (runpy), so a script that ends with ``sys.exit(...)``
or fails must not end the run: its SystemExit or exception is caught, the script is
counted as failed unless it exited with 0 (or None), and the next one runs. The summary
names every failed script; the exit status is 1 if any failed."""

from __future__ import annotations

import runpy
import sys
import traceback
from pathlib import Path


def run_scripts(scripts: list[Path]) -> list[str]:
    """Run ``scripts`` in turn as ``__main__``; returns the failures, one line each."""
    failed = []
    for script in scripts:
        print(f"== {script.name}", flush=True)
        argv = sys.argv
        sys.argv = [str(script)]  # the scripts parse their own (default) arguments
        try:
            runpy.run_path(str(script), run_name="__main__")
        except SystemExit as exc:  # a script's own exit: fine when 0 / None
            if exc.code not in (0, None):
                failed.append(f"{script.name}: exited with {exc.code!r}")
        except Exception as exc:  # noqa: BLE001 - reported and counted; the next script runs
            traceback.print_exc()
            failed.append(f"{script.name}: {type(exc).__name__}: {exc}")
        finally:
            sys.argv = argv
    return failed


def main(argv: list[str]) -> int:
    here = Path(__file__).resolve().parent
    sys.path.insert(0, str(here))  # for the shared _timing helper
    only = set(argv)
    scripts = [s for s in sorted(here.glob("bench_*.py")) if not only or s.name in only]
    failed = run_scripts(scripts)
    print(f"== {len(scripts) - len(failed)} of {len(scripts)} benchmarks ran to the end", flush=True)
    for line in failed:
        print(f"failed: {line}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
