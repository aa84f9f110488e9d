"""The paper report's FE-calibrated stiffness tables: from the cache, or their FE on the local cores.

A table (gearwear.stiffness.calibration.calibrated_table) needs two FE stages on a cache
miss: the single-tooth compliance of its wear phase (run_fe: a fine and a sqrt(2)-coarse
run, ~7 s) and the pair contact at its clearance (pair_correction: the two gear bodies,
~15 s, then 24 positions, ~3 s). The report asks for nine tables (three wear phases at
10 um, six clearances unworn), so a cold report is ~2 min of FE in one process.

On a miss the work goes to local worker processes (gearwear.jobs.sweep.make_executor):

* the single-tooth runs of every phase that has a missing table, each run a task of its
  own (run_fe with the executor; the result is the same to the bit);
* then one task per clearance with a missing table, holding every missing table at that
  clearance: the pair FE's bodies depend on the clearance (through the lowest contact
  radius), not on the wear, and are cached inside a process (fem.pair_model), so the
  three wear phases at 10 um build their bodies once, in one worker. A clearance's task
  is submitted as soon as the single-tooth runs of its phases are done.

Each task calls calibrated_table itself, which stores the table in the cache; the parent
reads nothing twice. Every table is the function of its inputs that calibrated_table
computes serially (the same calls, in another process).
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Callable

from gearwear.stiffness import tables

#: a table the report needs: (its key in the report, wear phase, clearance in m)
Request = tuple[Any, str, float]


class _Miss(Exception):
    """Raised by the calibration stand-in: the table is not in the cache."""


def _miss():
    raise _Miss


def cached(pair, wear, clearance_m: float, torque_Nm: float, points: int, notify) -> tables.StiffnessTable | None:
    """The table from the cache, or None: calibrated_table calls its ``calibration`` only
    on a miss (after checking the inputs), and this one raises instead of running the FE."""
    from gearwear.stiffness.calibration import calibrated_table

    try:
        return calibrated_table(pair, wear, clearance_m, torque_Nm, points, calibration=_miss, notify=notify)
    except _Miss:
        return None


def _tables_at(pair, items: list, torque_Nm: float, points: int) -> list:
    """Worker task: the calibrated tables of ``items`` [(wear, clearance_m, calibration)],
    one clearance, in order (the pair FE's bodies built once for all of them)."""
    from gearwear.stiffness.calibration import calibrated_table

    return [calibrated_table(pair, w, c, torque_Nm, points, calibration=cal) for w, c, cal in items]


def calibrated_tables(
    pair,
    requests: list[Request],
    wears: dict[str, Any],
    torque_Nm: float,
    points: int,
    notify,
    say: Callable[[str], None],
    workers: int | None = None,
) -> dict[Any, tables.StiffnessTable]:
    """Every table of ``requests`` by its key: from the cache, the missing ones computed
    on ``workers`` local processes (default: the cores). ``say`` gets one line per FE
    stage done and per table."""
    found = {key: cached(pair, wears[p], c, torque_Nm, points, notify) for key, p, c in requests}
    out = {key: tab for key, tab in found.items() if tab is not None}
    missing = [r for r in requests if r[0] not in out]
    for key in out:
        say(f"calibrated table from the cache ({key})")
    if not missing:
        return out
    from gearwear.jobs.sweep import make_executor
    from gearwear.stiffness.calibration import run_fe

    phases = list(dict.fromkeys(p for _, p, _ in missing))
    by_clearance: dict[float, list[Request]] = {}
    for r in missing:
        by_clearance.setdefault(r[2], []).append(r)
    with make_executor(workers) as pool, ThreadPoolExecutor(len(phases) + len(by_clearance)) as threads:
        # threads only wait: each hands its FE tasks to the pool and blocks on them
        cals: dict[str, Future] = {p: threads.submit(run_fe, pair, wears[p], executor=pool) for p in phases}

        def at(c: float, group: list[Request]) -> list:
            items = [(wears[p], c, cals[p].result()) for _, p, _ in group]
            return pool.submit(_tables_at, pair, items, torque_Nm, points).result()

        groups = {c: threads.submit(at, c, g) for c, g in by_clearance.items()}
        for p, f in cals.items():
            f.result()
            say(f"FE single-tooth compliance ({p})")
        for c, f in groups.items():
            for (key, _, _), tab in zip(by_clearance[c], f.result()):
                out[key] = tab
                say(f"calibrated table + FE pair ({key})")
    return out
