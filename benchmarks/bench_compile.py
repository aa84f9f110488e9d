"""Cold compile of the dynamics kernels per effect set, in CPU seconds, A/B across checkouts.

Issue 27 asks for any effect set's first whole-process ``simulate`` within 4 s from an empty
numba cache. Each case runs in a fresh process with a fresh, empty ``NUMBA_CACHE_DIR``:

* ``first_cpu_s``: CPU time (``time.process_time``) of the first ``dynamics.simulate``
  call (compiling every kernel of that effect set, then the run);
* ``run_cpu_s``: the same call again in the same process (warm: the run alone);
  ``compile_cpu_s = first_cpu_s - run_cpu_s``;
* ``numba_compile_cpu_s`` and ``events``: CPU time inside numba's outermost
  ``numba:compile`` events and the number of compile events (one per function and
  signature numba compiles, overloads of numpy functions included);
* ``process_cpu_s``: user + sys CPU of the whole cold process (imports included), and
  ``process_warm_cpu_s`` the same process again on the now-filled cache.

CPU time, not wall time: on a loaded machine a cold compile's wall time says more about the
other processes than about the compiler. Checkouts (``--checkout PATH``, repeatable; each
runs from ``PATH/.venv``) alternate within each repeat, so a before/after pair shares the
machine's state. The models are ``dynamics.paper_pair`` (40 N m, 1200 rpm) with every effect
(50 um backlash, 20 um bearing play, 2 um TE excitation, dynamic centre distance: the
built-in default scene's effect set plus TE) or stiffness only (``paper-default``'s), 0.02 s
simulated. Nothing is asserted. Writes benchmarks/results/bench_compile.json.

Usage: ``python benchmarks/bench_compile.py [--checkout PATH ...] [--repeats N] [--cases ...]``
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT_JSON = HERE / "results" / "bench_compile.json"
SUMMARY_KEYS = ("compile_cpu_s", "process_cpu_s", "process_warm_cpu_s")

#: the cases: (method, paper_pair keywords)
CASES = {
    "dopri5-all": (
        "dopri5",
        dict(backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=2e-6, centre_distance="dynamic"),
    ),
    "rk4-stiffness": ("rk4", {}),
    "rk4-all": (
        "rk4",
        dict(backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=2e-6, centre_distance="dynamic"),
    ),
    "dopri5-stiffness": ("dopri5", {}),
}

SNIPPET = """
import json, resource, sys, time
from numba.core import event
acc = {"cpu": 0.0, "n": 0, "depth": 0, "t0": 0.0}
class L(event.Listener):
    def on_start(self, e):
        if acc["depth"] == 0:
            acc["t0"] = time.process_time()
        acc["depth"] += 1
        acc["n"] += 1
    def on_end(self, e):
        acc["depth"] -= 1
        if acc["depth"] == 0:
            acc["cpu"] += time.process_time() - acc["t0"]
event.register("numba:compile", L())
from gearwear.dynamics import paper_pair, simulate
method, kw = sys.argv[1], json.loads(sys.argv[2])
m = paper_pair(**kw)
c0 = time.process_time()
r = simulate(m, 0.02, 0.01, method=method)
c1 = time.process_time()
r2 = simulate(m, 0.02, 0.01, method=method)
c2 = time.process_time()
same = bool((r.signals["F_m"] == r2.signals["F_m"]).all())
print(json.dumps(dict(first_cpu_s=c1 - c0, run_cpu_s=c2 - c1, numba_compile_cpu_s=acc["cpu"], events=acc["n"],
                      steps=int(r.steps), F_m_last=float(r.signals["F_m"][-1]), repeatable=same)))
"""


def one(python: str, method: str, kw: dict, cache: Path, cwd: Path) -> dict:
    """One process on ``cache``: the snippet's figures plus the process's user + sys CPU."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(
        [python, "-c", SNIPPET, method, json.dumps(kw)], env=env, cwd=cwd, capture_output=True, text=True, timeout=3600
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise RuntimeError(r.stderr[-2000:])
    out = json.loads(r.stdout.strip().splitlines()[-1])
    out["process_cpu_s"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--checkout", type=Path, action="append", help="checkout(s) to compare (default: this one)")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--cases", default=",".join(CASES), help="comma-separated: " + ", ".join(CASES))
    ap.add_argument("--out", type=Path, default=OUT_JSON)
    a = ap.parse_args(argv)
    checkouts = [c.resolve() for c in (a.checkout or [ROOT])]
    cases = [c for c in a.cases.split(",") if c]
    rows: dict = {str(c): {k: [] for k in cases} for c in checkouts}
    with tempfile.TemporaryDirectory(prefix="bench-compile-") as tmp:
        for rep in range(a.repeats):
            for case in cases:
                method, kw = CASES[case]
                for c in checkouts:  # alternating: before, after, before, after ...
                    cache = Path(tmp) / f"nc-{rep}-{case}-{checkouts.index(c)}"
                    cold = one(str(c / ".venv" / "bin" / "python"), method, kw, cache, c)
                    warm = one(str(c / ".venv" / "bin" / "python"), method, kw, cache, c)
                    shutil.rmtree(cache, ignore_errors=True)
                    cold["compile_cpu_s"] = cold["first_cpu_s"] - cold["run_cpu_s"]
                    cold["process_warm_cpu_s"] = warm["process_cpu_s"]
                    cold["warm_events"] = warm["events"]
                    rows[str(c)][case].append(cold)
                    print(
                        f"{c.name:>16} {case:<17} compile {cold['compile_cpu_s']:6.2f} s CPU "
                        f"(numba {cold['numba_compile_cpu_s']:5.2f} s, {cold['events']} events; warm "
                        f"{warm['events']}), process cold {cold['process_cpu_s']:5.2f} / warm "
                        f"{warm['process_cpu_s']:5.2f} s CPU, F_m(end) {cold['F_m_last']!r}",
                        flush=True,
                    )
    summary = {
        c: {
            case: {
                k: statistics.median(r[k] for r in runs)
                for k in ("compile_cpu_s", "process_cpu_s", "process_warm_cpu_s")
            }
            for case, runs in per.items()
        }
        for c, per in rows.items()
    }
    res = dict(
        benchmark="bench_compile",
        date=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        machine=f"{platform.machine()} {os.cpu_count()} cores, {platform.python_version()}",
        load_1min=os.getloadavg()[0],
        command=" ".join([Path(sys.executable).name, *sys.argv]),
        rows=rows,
        summary=summary,
    )
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(res, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
