"""Run every benchmarks/bench_*.py in turn (``make bench``). Timings are printed,
never asserted. ``python benchmarks/run_all.py bench_a.py bench_b.py`` runs only those.

Each script runs in its own process, exactly as ``python benchmarks/bench_x.py`` would:
run in one process (runpy), a script's ``sys.exit`` ended the whole run, and the state one
script left behind changed the next one's results (the 200 random pairs of
bench_published_models came out different after the others had run). A script that exits
non-zero is named in the summary and the run goes on; the exit status is 1 if any failed."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def run_scripts(scripts: list[Path], python: str = sys.executable) -> list[str]:
    """Run ``scripts`` in turn, each in a new ``python`` process in its own folder's parent
    (the repository root), output passed through; returns the failures, one line each."""
    failed = []
    for script in scripts:
        print(f"== {script.name}", flush=True)
        code = subprocess.run([python, str(script)], cwd=script.resolve().parent.parent).returncode
        if code != 0:
            failed.append(f"{script.name}: exited with {code}")
    return failed


def main(argv: list[str]) -> int:
    here = Path(__file__).resolve().parent
    only = set(argv)
    scripts = [s for s in sorted(here.glob("bench_*.py")) if not only or s.name in only]
    failed = run_scripts(scripts)
    print(f"== {len(scripts) - len(failed)} of {len(scripts)} benchmarks ran to the end", flush=True)
    for line in failed:
        print(f"failed: {line}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
