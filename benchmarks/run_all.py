"""Run every benchmarks/bench_*.py in turn (``make bench``). Timings are printed,
never asserted. ``python benchmarks/run_all.py bench_a.py bench_b.py`` runs only those."""

import runpy
import sys
from pathlib import Path

here = Path(__file__).resolve().parent
sys.path.insert(0, str(here))  # for the shared _timing helper
only = set(sys.argv[1:])
sys.argv = sys.argv[:1]  # the scripts parse their own (default) arguments
for script in sorted(here.glob("bench_*.py")):
    if only and script.name not in only:
        continue
    print(f"== {script.name}", flush=True)
    runpy.run_path(str(script), run_name="__main__")
sys.exit(0)
