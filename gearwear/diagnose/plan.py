"""``gearwear diagnose --plan``: which signals, speeds and torques make the unknowns separable.

For every candidate operating point (speed x torque) the surrogate of that point is built
(or read from the cache, gearwear.diagnose.surrogate), and for every candidate
measurement (one signal's harmonic table, one signal's time series with its mean, all
four signals as time series) the Fisher information of the stated noise model (the
surrogate's sensitivities, measurement noise on the predicted features, the surrogate's
own error) gives Cramer-Rao 95 % interval widths at reference points spread over the
prior (a Sobol set). A width is a fraction of the prior range, capped at 1 (the prior
itself bounds the interval). The table gives the median over the reference points and the
median |correlation| between wear and clearance: a measurement separates them when both
widths stay below gearwear.diagnose.posterior.RESOLVED_FRACTION.
"""

from __future__ import annotations

import functools
import math
from concurrent.futures import Executor, Future
from typing import Any, Callable

import numpy as np

from gearwear.diagnose import posterior as dp
from gearwear.diagnose.features import MEAN_SIGNALS, SIGNALS, Feature, all_features
from gearwear.diagnose.job import expected_widths
from gearwear.diagnose.surrogate import BuildSpec, Pending, Surrogate, finish, simulate_point, simulate_runs, start

REFERENCE_POINTS = 16
REFERENCE_SEED = 11


def candidates(harmonics: int) -> list[tuple[str, list[Feature]]]:
    """(label, features) of every candidate measurement."""
    out: list[tuple[str, list[Feature]]] = []
    for s in SIGNALS:
        out.append((f"{s} harmonics", [(s, k) for k in range(1, harmonics + 1)]))
    for s in MEAN_SIGNALS:
        out.append((f"{s} time series", [(s, k) for k in range(1, harmonics + 1)] + [(s, 0)]))
    out.append(("all four, time series", all_features(harmonics)))
    return out


def reference_points(sur: Surrogate) -> np.ndarray:
    from scipy.stats import qmc

    d = len(sur.unknowns)
    u = qmc.Sobol(d, scramble=True, seed=np.random.default_rng(REFERENCE_SEED)).random_base2(
        int(math.log2(REFERENCE_POINTS))
    )
    return sur.lo + (sur.hi - sur.lo) * u


def assess(sur: Surrogate, rel: float, floor_frac: float) -> list[dict[str, Any]]:
    """One row per candidate measurement at this surrogate's operating point."""
    refs = reference_points(sur)
    names = [u.name for u in sur.unknowns]
    pair = [names.index(n) for n in ("wear_max_depth_um", "clearance_um") if n in names]
    rows = []
    for label, feats in candidates(sur.harmonics):
        widths, corr = [], []
        for th in refs:
            w = expected_widths(sur, th, feats, rel, floor_frac)
            widths.append(np.minimum(w["marginal"], 1.0))
            if len(pair) == 2:
                corr.append(abs(w["correlation"][pair[0], pair[1]]))
        med = np.median(widths, axis=0)
        row: dict[str, Any] = {
            "measurement": label,
            "width_fraction": {n: float(v) for n, v in zip(names, med)},
            "resolves": {n: bool(v <= dp.RESOLVED_FRACTION) for n, v in zip(names, med)},
        }
        if corr:
            row["wear_clearance_correlation"] = float(np.median(corr))
        row["separable"] = all(row["resolves"].values())
        rows.append(row)
    return rows


def _table_key(raw: dict[str, Any]) -> str:
    """The scene document without its speed: runs whose documents agree here (and in the
    unknowns' values) have the same stiffness tables."""
    import json

    doc = {k: v for k, v in raw.items() if k != "operating"}
    doc["operating"] = {k: v for k, v in raw.get("operating", {}).items() if k != "speed_rpm"}
    return json.dumps(doc, sort_keys=True, default=repr)


class SpeedGroups(Executor):
    """The plan's runs, one task per design point and torque for all candidate speeds.

    The plan's surrogates share their design and held-out points (fixed seeds, the same
    prior), and the stiffness tables depend on the torque and the unknowns' values, not on
    the speed or the solver's window. :func:`plan` hands
    this front to :func:`gearwear.diagnose.surrogate.start` in place of the executor: it
    records each :func:`simulate_point` as a future of its own, and :meth:`flush` submits
    the runs that differ only in the speed as one :func:`simulate_runs` task, which
    computes their table once (3 speeds: 2 of every 3 tables saved, about a third of a
    training run's cost) and sets each run's future from its own result. Every result is
    the one its own task would give, to the bit; only the grouping of work changes. Without
    a real executor (one worker) the groups run in this process at :meth:`flush`.
    ``progress(1)`` is called as each run's result arrives."""

    def __init__(self, executor: Executor | Callable[[], Executor | None] | None, progress=None):
        self.inner = executor
        self.progress = progress
        self.groups: dict[tuple, list[tuple[tuple, Future]]] = {}

    def submit(self, fn, /, *args, **kwargs):  # type: ignore[override]
        if fn is not simulate_point or kwargs or len(args) != 5:
            raise TypeError("SpeedGroups runs simulate_point(raw, name, values, solver, harmonics) only")
        raw, name, values, solver, harmonics = args
        key = (name, harmonics, tuple(sorted(values.items())), _table_key(raw))
        fut: Future = Future()
        self.groups.setdefault(key, []).append(((raw, name, values, solver), fut))
        return fut

    def _deliver(self, members: list[tuple[tuple, Future]], task: Future) -> None:
        try:
            results = task.result()
        except BaseException as exc:  # the group failed or was cancelled: so did each of its runs
            for _, fut in members:
                fut.set_exception(exc)
            return
        for (_, fut), res in zip(members, results):
            fut.set_result(res)
            if self.progress:
                self.progress(1)

    def flush(self) -> None:
        """Submit every group recorded so far (in the order of their first run)."""
        groups, self.groups = self.groups, {}
        ex = self.inner if self.inner is None or isinstance(self.inner, Executor) else self.inner()
        for (_, harmonics, _, _), members in groups.items():
            runs = [m for m, _ in members]
            if ex is None:
                task: Future = Future()
                task.set_result(simulate_runs(runs, harmonics))
            else:
                task = ex.submit(simulate_runs, runs, harmonics)
            task.add_done_callback(functools.partial(self._deliver, members))


def plan(
    spec: BuildSpec,
    speeds: list[float],
    torques: list[float] | None,
    rel: float,
    floor_frac: float,
    executor: Executor | Callable[[], Executor | None] | None = None,
    progress: Callable[[int], None] | None = None,
) -> dict[str, Any]:
    """The plan document: rows per operating point and candidate measurement, and the
    measurements that separate the unknowns. ``spec``: the surrogate at the scene's own
    operating point, which each candidate point replaces. ``torques`` None: the torque is
    an unknown."""
    import copy
    from dataclasses import replace

    rows = []
    builds = []
    levels: list[float | None] = list(torques) if torques else [None]
    started = []
    groups = SpeedGroups(executor, progress)
    for n in speeds:
        for T in levels:
            doc = copy.deepcopy(spec.raw)
            doc.setdefault("operating", {})["speed_rpm"] = float(n)
            if T is not None:
                doc["operating"]["torque_Nm"] = float(T)
            # every missing surrogate's runs are submitted before the first is fitted: the
            # workers simulate the next operating points while this process fits
            started.append((n, T, start(replace(spec, raw=doc), groups, None)))
    groups.flush()
    for n, T, got in started:
        sur = finish(got) if isinstance(got, Pending) else got
        builds.append(
            {
                "speed_rpm": n,
                "torque_Nm": T,
                "from_cache": sur.from_cache,
                "heldout_harmonic_relative_error_median": sur.heldout.get("harmonic_relative_error_median"),
                **{k: v for k, v in sur.meta.items() if k.endswith("wall_s")},
            }
        )
        for r in assess(sur, rel, floor_frac):
            rows.append({"speed_rpm": n, "torque_Nm": T, **r})
    separable = [r for r in rows if r["separable"]]
    best = min(separable, key=lambda r: max(r["width_fraction"].values()), default=None)
    return {
        "unknowns": [u.name for u in spec.unknowns],
        "prior": {
            u.name: {"lo": float(a), "hi": float(b), "unit": u.unit} for u, a, b in zip(spec.unknowns, spec.lo, spec.hi)
        },
        "noise_model": {"relative": rel, "floor_fraction_of_largest_harmonic": floor_frac},
        "resolved_fraction": dp.RESOLVED_FRACTION,
        "rows": rows,
        "surrogates": builds,
        "separable": [{k: r[k] for k in ("speed_rpm", "torque_Nm", "measurement")} for r in separable],
        "best": None
        if best is None
        else {k: best[k] for k in ("speed_rpm", "torque_Nm", "measurement", "width_fraction")},
    }


def table_csv(doc: dict[str, Any]) -> str:
    names = doc["unknowns"]
    cols = (
        ["speed_rpm", "torque_Nm", "measurement"]
        + [f"width_fraction_{n}" for n in names]
        + ["wear_clearance_correlation", "separable"]
    )
    lines = [",".join(cols)]
    for r in doc["rows"]:
        vals = (
            [
                f"{r['speed_rpm']:.6g}",
                "unknown" if r["torque_Nm"] is None else f"{r['torque_Nm']:.6g}",
                r["measurement"],
            ]
            + [f"{r['width_fraction'][n]:.4f}" for n in names]
            + [
                f"{r['wear_clearance_correlation']:.4f}" if "wear_clearance_correlation" in r else "",
                str(r["separable"]).lower(),
            ]
        )
        lines.append(",".join(vals))
    return "\n".join(lines) + "\n"


def print_table(doc: dict[str, Any]) -> None:
    names = doc["unknowns"]
    head = (
        f"{'speed rpm':>9} {'torque N m':>10}  {'measurement':<24}"
        + "".join(f"{n[:16] + ' %':>19}" for n in names)
        + f"{'|corr|':>8}  separable"
    )
    print("95 % interval width as % of the prior range (Cramer-Rao, median over the prior):")
    print(head)
    for r in doc["rows"]:
        T = "unknown" if r["torque_Nm"] is None else f"{r['torque_Nm']:g}"
        corr = f"{r['wear_clearance_correlation']:8.2f}" if "wear_clearance_correlation" in r else f"{'-':>8}"
        print(
            f"{r['speed_rpm']:>9g} {T:>10}  {r['measurement']:<24}"
            + "".join(f"{100 * r['width_fraction'][n]:>19.0f}" for n in names)
            + corr
            + f"  {'yes' if r['separable'] else 'no'}"
        )
    b = doc["best"]
    if b is None:
        print("no candidate separates the unknowns; widen the candidate speeds and torques")
    else:
        T = "the unknown torque" if b["torque_Nm"] is None else f"{b['torque_Nm']:g} N m"
        print(f"best: {b['measurement']} at {b['speed_rpm']:g} rpm and {T}")
