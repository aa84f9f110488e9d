"""Write tests/slow_tests.txt, the tests ``make check`` leaves out, from a measured run:

    .venv/bin/python -m pytest -q -n 2 --durations=0 > durations.log
    .venv/bin/python tools/slow_tests.py durations.log [more.log ...] [THRESHOLD_S]

A test is slow when its setup + call + teardown took THRESHOLD_S (default 2 s) or more in any of
the runs. Leaving slow tests out moves their module fixtures' setup onto the fast tests that
share them, so the list is made from the full run and then from a run of the fast tier
(-m "not slow"); the committed list: both runs, 1.0 s. tests/conftest.py marks the listed
node ids ``slow``; ``make test`` still runs them all.
"""

from __future__ import annotations

import re
import sys
from collections import Counter
from pathlib import Path

LIST = Path(__file__).resolve().parents[1] / "tests" / "slow_tests.txt"


def durations(log: str) -> Counter[str]:
    """Setup + call + teardown (s) per test node id of a pytest --durations=0 log."""
    total: Counter[str] = Counter()
    for line in Path(log).read_text().splitlines():
        m = re.match(r"([\d.]+)s (?:call|setup|teardown)\s+(\S+)", line)
        if m:
            total[m.group(2)] += float(m.group(1))
    return total


def main(logs: list[str], threshold_s: float = 2.0) -> None:
    runs = [durations(log) for log in logs]
    total = runs[0]
    slow = sorted({n for run in runs for n, t in run.items() if t >= threshold_s})
    kept = sum(t for n, t in total.items() if n not in slow)
    LIST.write_text(
        f"# tests make check leaves out: >= {threshold_s:g} s each in a measured run "
        "(tools/slow_tests.py);\n"
        f"# {len(slow)} tests, {sum(total[n] for n in slow):.0f} s of {sum(total.values()):.0f} s; "
        f"the rest took {kept:.0f} s (in the first run)\n" + "".join(f"{n}\n" for n in slow)
    )
    print(f"wrote {LIST}: {len(slow)} slow tests")


if __name__ == "__main__":
    args = sys.argv[1:]
    threshold = float(args.pop()) if args and not Path(args[-1]).exists() else 2.0
    main(args, threshold)
