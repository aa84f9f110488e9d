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

import math
from concurrent.futures import Executor
from typing import Any, Callable

import numpy as np

from gearwear.diagnose import posterior as dp
from gearwear.diagnose.features import MEAN_SIGNALS, SIGNALS, Feature, all_features
from gearwear.diagnose.job import expected_widths
from gearwear.diagnose.surrogate import BuildSpec, Pending, Surrogate, finish, start

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
    for n in speeds:
        for T in levels:
            doc = copy.deepcopy(spec.raw)
            doc.setdefault("operating", {})["speed_rpm"] = float(n)
            if T is not None:
                doc["operating"]["torque_Nm"] = float(T)
            # every missing surrogate's runs are submitted before the first is fitted: the
            # workers simulate the next operating points while this process fits
            started.append((n, T, start(replace(spec, raw=doc), executor, progress)))
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
