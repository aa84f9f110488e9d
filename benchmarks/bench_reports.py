"""Whole-command wall times of ``gearwear report paper`` and ``gearwear diagnose --plan``.

Each command runs as a process of its own (``subprocess``, the installed ``gearwear``
script next to this interpreter), as a user runs it, so start-up imports, the worker
pools and the figure files count. Two cache states per command (``GEARWEAR_CACHE``, the
folder of the calibrated tables and the diagnosis surrogates):

* ``cold``: an empty cache folder, i.e. a user's first run: report paper runs the FE of
  its nine calibrated tables, diagnose --plan simulates its nine surrogates (9 x 164
  runs);
* ``warm``: the same folder again right after, i.e. every later run.

The numba cache (``NUMBA_CACHE_DIR``) is whatever the environment has; warm it by one run
before timing: the first-run compile is not what this measures. Each timing is the
minimum of ``--repeat`` runs (the machine is shared: the minimum is the least disturbed).
Nothing is asserted.

Usage::

    python benchmarks/bench_reports.py --label after [--repeat 2] [--skip-cold-plan]

merges ``{label: {command: {cache state: seconds}}}`` into
benchmarks/results/bench_reports.json (run once with ``--label before`` on the code
before a change to keep both).
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULT = ROOT / "benchmarks" / "results" / "bench_reports.json"
GEARWEAR = str(Path(sys.executable).parent / "gearwear")
COMMANDS = {
    "report paper": ["report", "paper"],
    "diagnose --plan": ["diagnose", "--plan"],
}


def timed_run(args: list[str], cache: Path, out: Path) -> float:
    """Wall time (s) of one whole ``gearwear`` process with ``GEARWEAR_CACHE = cache``."""
    env = {**os.environ, "GEARWEAR_CACHE": str(cache)}
    t0 = time.perf_counter()
    subprocess.run([GEARWEAR, *args, "--out", str(out)], env=env, check=True, capture_output=True)
    return time.perf_counter() - t0


def measure(name: str, args: list[str], repeat: int, cold: bool) -> dict[str, float]:
    """{"cold": min s, "warm": min s} of ``repeat`` runs each (cold: each run on a new,
    empty cache folder; warm: on the folder a cold run filled)."""
    res: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix="gearwear-bench-reports-") as tmp:
        base = Path(tmp)
        cache = base / "cache"
        if cold:
            times = []
            for i in range(repeat):
                shutil.rmtree(cache, ignore_errors=True)
                times.append(timed_run(args, cache, base / f"out-cold-{i}"))
                print(f"{name}, cold cache: {times[-1]:.1f} s", flush=True)
            res["cold"] = min(times)
        elif not cache.exists():  # warm needs a filled cache: one untimed run fills it
            timed_run(args, cache, base / "out-fill")
        times = []
        for i in range(repeat):
            times.append(timed_run(args, cache, base / f"out-warm-{i}"))
            print(f"{name}, warm cache: {times[-1]:.1f} s", flush=True)
        res["warm"] = min(times)
    return res


def main() -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--label", default="after", help="key in the results file (before, after, ...)")
    ap.add_argument("--repeat", type=int, default=2, help="runs per cache state; the minimum is kept")
    ap.add_argument("--skip-cold-plan", action="store_true", help="diagnose --plan on a warm cache only")
    ap.add_argument("--only", choices=list(COMMANDS), help="one command only")
    a = ap.parse_args()
    doc = json.loads(RESULT.read_text()) if RESULT.exists() else {"benchmark": "bench_reports"}
    entry = doc.setdefault(a.label, {})
    for name, args in COMMANDS.items():
        if a.only and name != a.only:
            continue
        cold = not (a.skip_cold_plan and name == "diagnose --plan")
        entry[name] = {f"{k}_s": v for k, v in measure(name, args, a.repeat, cold).items()}
    entry["date"] = time.strftime("%Y-%m-%d %H:%M")
    entry["machine"] = f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the end (shared)"
    entry["repeat"] = a.repeat
    doc["cache_states"] = (
        "cold: an empty GEARWEAR_CACHE (first run: the report's FE, the plan's surrogates); "
        "warm: the same folder right after; numba cache warm in both"
    )
    RESULT.parent.mkdir(parents=True, exist_ok=True)
    RESULT.write_text(json.dumps(doc, indent=2, sort_keys=True) + "\n")
    print(f"wrote {RESULT}")
    return doc


if __name__ == "__main__":
    main()
