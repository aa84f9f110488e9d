"""Run every benchmarks/bench_*.py in turn (``make bench``). Timings are printed,
never asserted."""

import runpy
import sys
from pathlib import Path

here = Path(__file__).resolve().parent
sys.path.insert(0, str(here))  # for the shared _timing helper
for script in sorted(here.glob("bench_*.py")):
    print(f"== {script.name}", flush=True)
    runpy.run_path(str(script), run_name="__main__")
sys.exit(0)
