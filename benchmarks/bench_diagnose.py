"""Diagnosis (issue 15): surrogate build time, the blind test, one cached diagnosis.

Scene: examples/diagnose/scene.toml (paper pair, 40 N m, 1200 rpm, Archard wear, 50 um
backlash, bearing clearance with the static centre-distance coupling; face width 20 mm,
E 206 GPa, damping 5 % mesh / 2 % bearings). Unknowns wear_max_depth_um in [0, 40] um and
clearance_um in [0, 50] um, uniform prior; the default surrogate (256 Sobol points + 4
corners, 32 held-out full simulations), built cold into a temporary cache on 2 processes.

Blind test: 20 truths drawn uniformly from the prior (numpy default_rng(2019)); none is a
design point. Each "measurement" comes from the full model (``simulate`` with the scene's
own solver, 0.5 s, 0.3 s discarded), its features computed from the sampled record as
for a measured CSV, then 2 % noise: every feature multiplied by 1 + 0.02 eps,
eps ~ N(0, 1) independent (default_rng(1000 + trial)). The fit assumes that noise
(--noise-pct 2, --noise-floor-pct 0.5). Two measurements of the same truths:

* time series of y_p_um, x_p_um, delta_um, F_m_N (harmonics 1-10 and the means);
* harmonic table of F_m_N and y_p_um (harmonics 1-10, no means).

Reported: how often the truth lies inside both 95 % intervals (and each), the interval
widths, the identifiability verdicts, the fit time. Then one whole diagnosis through the
command line with the cached surrogate (examples/diagnose/measured_timeseries.csv, with
--out: figures included). Nothing is asserted; results go to
benchmarks/results/bench_diagnose.json (README section "Diagnosis").
"""

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "examples" / "diagnose" / "scene.toml"
TRIALS = 20
SMALL_WEAR_UM = 8.0
CASES = {
    "time series, y_p x_p delta F_m, with means": (["y_p_um", "x_p_um", "delta_um", "F_m_N"], True),
    "harmonic table, F_m_N and y_p_um": (["F_m_N", "y_p_um"], False),
}


def wear_steps(raw, name, ds) -> list[dict]:
    """How much the F_m harmonics scatter about a smooth curve in the wear (the 360-node
    stiffness table moves the start of contact by whole nodes): 41 training-length runs over
    2 um of wear at 24 um clearance, rms deviation from a quadratic fit, relative to the
    mean amplitude, per harmonic."""
    sol = ds.training_solver(ds.scene_at(raw, name, {"wear": 20.0, "clearance": 24.0}))
    out = []
    for a in (14.0, 20.0, 30.0):
        w = np.linspace(a, a + 2.0, 41)
        F = np.array(
            [
                ds.amplitudes(
                    ds.simulate_point(raw, name, {"wear": float(x), "clearance": 24.0}, sol, 10)[0][None], 10
                )[0, 30:40]
                for x in w
            ]
        )
        dev = [
            float(np.sqrt(np.mean((F[:, k] - np.polyval(np.polyfit(w, F[:, k], 2), w)) ** 2)) / np.mean(F[:, k]))
            for k in range(10)
        ]
        out.append({"wear_um": [a, a + 2.0], "rms_deviation_F_m_harmonics_1_10": dev})
        print(
            f"F_m harmonics about a quadratic over {a:g}-{a + 2:g} um of wear: rms deviation "
            + " ".join(f"{100 * d:.2f}" for d in dev)
            + " %"
        )
    return out


def main() -> dict:
    cache = tempfile.mkdtemp(prefix="gearwear-bench-diagnose-")
    os.environ["GEARWEAR_CACHE"] = cache
    from gearwear.cli.diagnose import DESIGN_POINTS, HOLDOUT_POINTS
    from gearwear.diagnose import job as dj
    from gearwear.diagnose import surrogate as ds
    from gearwear.jobs.sweep import make_executor
    from gearwear.scene.files import load_scene_dict

    raw, name = load_scene_dict(str(SCENE))
    unknowns = [ds.UNKNOWNS["wear"], ds.UNKNOWNS["clearance"]]
    lo, hi = (0.0, 0.0), (40.0, 50.0)
    spec = ds.BuildSpec(raw, name, unknowns, lo, hi, 10, DESIGN_POINTS[2], HOLDOUT_POINTS[2])
    ex = make_executor(2)
    t0 = time.perf_counter()
    sur = ds.build(spec, ex)
    build_s = time.perf_counter() - t0
    ex.shutdown()
    print(
        f"surrogate: {len(sur.X)} training runs + {HOLDOUT_POINTS[2]} held-out full simulations, built in "
        f"{build_s:.1f} s on 2 processes; held-out error of the harmonic amplitudes "
        f"{100 * sur.heldout['harmonic_relative_error_median']:.2f} % median, "
        f"{100 * sur.heldout['harmonic_relative_error_p95']:.1f} % 95th percentile; periodicity residual of "
        f"the training runs <= {sur.meta['periodicity_residual_max']:.1e}"
    )
    Fh, Ph = ds.amplitudes(sur.Yh, 10), sur.predict(sur.Xh)
    harm = np.array([k > 0 for _, k in sur.features])
    rel = np.abs(Ph - Fh)[:, harm] / np.where(Fh[:, harm] > 1e-3 * Fh[:, harm].max(axis=0), Fh[:, harm], np.nan)
    small = sur.Xh[:, 0] < SMALL_WEAR_UM
    by_wear = {
        f"below_{SMALL_WEAR_UM:g}_um": float(np.nanmedian(rel[small])),
        f"from_{SMALL_WEAR_UM:g}_um": float(np.nanmedian(rel[~small])),
        "points_below": int(small.sum()),
    }
    print(
        f"held-out error median below {SMALL_WEAR_UM:g} um of wear "
        f"{100 * by_wear[f'below_{SMALL_WEAR_UM:g}_um']:.2f} %"
        f" ({by_wear['points_below']} points), from {SMALL_WEAR_UM:g} um "
        f"{100 * by_wear[f'from_{SMALL_WEAR_UM:g}_um']:.2f} %"
    )
    steps = wear_steps(raw, name, ds)
    rng = np.random.default_rng(2019)
    truths = np.column_stack([rng.uniform(a, b, TRIALS) for a, b in zip(lo, hi)])
    gap = float(np.min(np.abs(truths[:, None, :] - sur.X[None, :, :]).max(axis=2)))
    results = {}
    for label, (cols, means) in CASES.items():
        rows = []
        for i, th in enumerate(truths):
            truth = {"wear": float(th[0]), "clearance": float(th[1])}
            vals = dj.synthetic_features(raw, name, truth, 10, cols, means, 0.02, np.random.default_rng(1000 + i))
            t1 = time.perf_counter()
            ft = dj.fit(sur, vals, 0.02, 0.005)
            ver = dj.verdict(ft, 0.02, 0.005)
            wall = time.perf_counter() - t1
            est = ft.summary["estimates"]
            rows.append(
                {
                    "truth": {u.name: truth[u.short] for u in unknowns},
                    "estimates": {u.name: {k: est[u.name][k] for k in ("value", "lo95", "hi95")} for u in unknowns},
                    "inside": {
                        u.name: bool(est[u.name]["lo95"] <= truth[u.short] <= est[u.name]["hi95"]) for u in unknowns
                    },
                    "identifiable": ver["identifiable"],
                    "fit_and_verdict_s": wall,
                }
            )
        inside = {u.name: sum(r["inside"][u.name] for r in rows) for u in unknowns}
        widths = {
            u.name: [r["estimates"][u.name]["hi95"] - r["estimates"][u.name]["lo95"] for r in rows] for u in unknowns
        }
        results[label] = {
            "trials": TRIALS,
            "inside_both": sum(all(r["inside"].values()) for r in rows),
            "inside": inside,
            "width_median": {n: float(np.median(w)) for n, w in widths.items()},
            "width_max": {n: float(np.max(w)) for n, w in widths.items()},
            "width_min": {n: float(np.min(w)) for n, w in widths.items()},
            "identifiable_count": {u.name: sum(r["identifiable"][u.name] for r in rows) for u in unknowns},
            "fit_and_verdict_s_median": float(np.median([r["fit_and_verdict_s"] for r in rows])),
            "rows": rows,
        }
        s = results[label]
        print(
            f"{label}: truth inside both 95 % intervals in {s['inside_both']} of {TRIALS} "
            f"(wear {inside['wear_max_depth_um']}, clearance {inside['clearance_um']}); median widths "
            f"{s['width_median']['wear_max_depth_um']:.2f} um and {s['width_median']['clearance_um']:.2f} um; "
            f"identifiable {s['identifiable_count']}; fit {s['fit_and_verdict_s_median']:.2f} s"
        )
    out = Path(cache) / "run"
    t2 = time.perf_counter()
    proc = subprocess.run(
        [
            str(Path(sys.executable).parent / "gearwear"),
            "diagnose",
            str(SCENE),
            "--measured",
            str(ROOT / "examples" / "diagnose" / "measured_timeseries.csv"),
            "--out",
            str(out),
            "--json",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    process_s = time.perf_counter() - t2
    doc = json.loads(proc.stdout)
    print(
        f"one diagnosis with the cached surrogate (command line, --out with figures): {process_s:.1f} s whole "
        f"process, {doc['wall_s']:.2f} s inside gearwear"
    )
    return {
        "benchmark": "bench_diagnose",
        "date": time.strftime("%Y-%m-%d"),
        "machine": f"{os.cpu_count()} cores",
        "scene": "examples/diagnose/scene.toml",
        "prior": {"wear_max_depth_um": [lo[0], hi[0]], "clearance_um": [lo[1], hi[1]]},
        "noise": "each feature x (1 + 0.02 eps), eps ~ N(0, 1); fit: --noise-pct 2 --noise-floor-pct 0.5",
        "surrogate": {
            "training_runs": int(len(sur.X)),
            "holdout_runs": HOLDOUT_POINTS[2],
            "build_s": build_s,
            "heldout": sur.heldout,
            "heldout_median_by_wear": by_wear,
            "wear_steps": steps,
            "periodicity_residual_max": sur.meta["periodicity_residual_max"],
        },
        "truth_min_distance_to_design": gap,
        "blind": results,
        "cached_diagnosis": {
            "process_s": process_s,
            "wall_s": doc["wall_s"],
            "estimates": doc["estimates"],
            "identifiable": doc["identifiable"],
        },
    }


if __name__ == "__main__":
    res = main()
    path = ROOT / "benchmarks" / "results" / "bench_diagnose.json"
    path.write_text(json.dumps(res, indent=2, sort_keys=True) + "\n")
    print(f"wrote {path}")
