"""Regression tests: pin the numbers the README's "Diagnosis" section publishes; they are
not independent truths (tests/test_diagnose.py holds those).

The blind test and the surrogate figures take minutes (`make bench`), the example
diagnoses a surrogate build (`make report`), so they are read from the committed
machine-written files (benchmarks/results/bench_diagnose.json,
reports/diagnose/*/diagnosis.json, reports/diagnose/plan/plan.json), and each file is
checked against a cheap recomputation: the blind truths from their seed, the counts and
widths from the per-trial rows, the example reports against the committed example files.
The clearance identity (4.7e-12) is recomputed. Wall times are benchmarks, not pinned.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
from scenes import published_text  # noqa: E402

README = published_text()  # README.md and docs/*.md: the published text
TRUTH = {"wear_max_depth_um": 18.0, "clearance_um": 24.0, "torque_Nm": 40.0}


def say(text: str) -> None:
    text = " ".join(text.split())
    assert text in README, f"README.md does not say: {text!r}"


def load(rel: str):
    return json.loads((ROOT / rel).read_text())


def sci(x: float, digits: int = 1) -> str:
    """7.7e-4-style (no exponent padding, as the README writes small numbers)."""
    m, e = f"{x:.{digits}e}".split("e")
    return f"{m}e{int(e)}"


def iv(e: dict, digits: int = 1) -> str:
    return f"{e['value']:.{digits}f} (95 %: {e['lo95']:.{digits}f}-{e['hi95']:.{digits}f})"


def test_blind_test_rows_against_bench_json():
    d = load("benchmarks/results/bench_diagnose.json")
    rng = np.random.default_rng(2019)  # the truths are the seed's, the counts and widths the rows'
    truths = np.column_stack([rng.uniform(0, 40, 20), rng.uniform(0, 50, 20)])
    ts = d["blind"]["time series, y_p x_p delta F_m, with means"]
    ht = d["blind"]["harmonic table, F_m_N and y_p_um"]
    for case in (ts, ht):
        rows = case["rows"]
        np.testing.assert_allclose(
            [[r["truth"]["wear_max_depth_um"], r["truth"]["clearance_um"]] for r in rows], truths, rtol=1e-15
        )
        inside = [{n: e["lo95"] <= r["truth"][n] <= e["hi95"] for n, e in r["estimates"].items()} for r in rows]
        assert case["inside_both"] == sum(all(i.values()) for i in inside)
        for n in ("wear_max_depth_um", "clearance_um"):
            assert case["inside"][n] == sum(i[n] for i in inside)
            w = [r["estimates"][n]["hi95"] - r["estimates"][n]["lo95"] for r in rows]
            assert case["width_median"][n] == pytest.approx(float(np.median(w)), rel=1e-12)
    say(
        f"| time series of y_p, x_p, delta, F_m (harmonics and means) | {ts['inside_both']} of 20 | "
        f"{ts['inside']['wear_max_depth_um']} / {ts['inside']['clearance_um']} | "
        f"{ts['width_median']['wear_max_depth_um']:.2f} um / {ts['width_median']['clearance_um']:.2f} um | "
        f"{ts['identifiable_count']['wear_max_depth_um']} / {ts['identifiable_count']['clearance_um']} |"
    )
    say(
        f"| harmonic table of F_m and y_p | {ht['inside_both']} of 20 | "
        f"{ht['inside']['wear_max_depth_um']} / {ht['inside']['clearance_um']} | "
        f"{ht['width_median']['wear_max_depth_um']:.2f} um / {ht['width_median']['clearance_um']:.2f} um | "
        f"{ht['identifiable_count']['wear_max_depth_um']} / {ht['identifiable_count']['clearance_um']} |"
    )
    s = d["surrogate"]
    h = s["heldout"]
    say(
        f"its held-out error of the harmonic amplitudes is {100 * h['harmonic_relative_error_median']:.2f} % median, "
        f"{100 * h['harmonic_relative_error_p90']:.1f} % at the 90th and "
        f"{100 * h['harmonic_relative_error_p95']:.1f} % "
        "at the 95th percentile"
    )
    by = s["heldout_median_by_wear"]
    say(f"(median {100 * by['below_8_um']:.1f} % below 8 um of wear, {100 * by['from_8_um']:.2f} % above")
    say(f"the training runs are periodic to {sci(s['periodicity_residual_max'])}")
    dev = [100 * x for st in s["wear_steps"] for x in st["rms_deviation_F_m_harmonics_1_10"]]
    say(f"by {min(dev):.2f}-{sorted(dev)[-2]:.2f} % rms ({max(dev):.1f} % for")


@pytest.mark.parametrize("case", ["timeseries", "harmonics", "torque"])
def test_example_rows_against_reports(case):
    d = load(f"reports/diagnose/{case}/diagnosis.json")
    measured = "measured_harmonics.csv" if case == "harmonics" else "measured_timeseries.csv"
    data = (ROOT / "examples" / "diagnose" / measured).read_bytes()
    assert d["measured"]["file"] == measured and d["measured"]["sha256"] == hashlib.sha256(data).hexdigest()
    e = d["estimates"]
    for n, ok in d["identifiable"].items():  # a resolved unknown holds its truth
        if ok:
            assert e[n]["lo95"] <= TRUTH[n] <= e[n]["hi95"], n
    # the docs' table of these rows is generated from this file (docs/generate.py,
    # tests/test_docs_generated.py); here: the resolved unknowns hold the truth


def test_plan_sentences_against_plan_json():
    d = load("reports/diagnose/plan/plan.json")
    rows = d["rows"]
    harm = [r for r in rows if r["measurement"].endswith("harmonics")]
    disp = [r for r in rows if r["measurement"] in ("y_p_um time series", "x_p_um time series")]
    assert not any(r["separable"] for r in harm) and all(r["separable"] for r in disp)
    # the docs' paragraph on the plan is generated from plan.json (docs/generate.py); here:
    # no harmonic table resolves the clearance, every displacement series resolves both
    assert all(r["width_fraction"]["clearance_um"] > 0.5 for r in harm)
    assert all(max(r["width_fraction"].values()) < 0.5 for r in disp)


def test_clearance_identity_figure():
    """Recomputed: the paper pair without centre-distance coupling, two clearances."""
    from gearwear.diagnose.surrogate import simulate_point
    from gearwear.scene.files import load_scene_dict

    raw, name = load_scene_dict("paper-wear-severe")
    del raw["effects"]["centre_distance"]
    raw["solver"] = {"duration_s": 0.15, "discard_s": 0.1}
    a, _ = simulate_point(raw, name, {"wear": 12.0, "clearance": 0.0}, None, 10)
    b, _ = simulate_point(raw, name, {"wear": 12.0, "clearance": 30.0}, None, 10)
    rel = np.max(np.abs(a[:80] - b[:80])) / np.max(np.abs(a[:80]))
    say(f"unchanged (to {sci(rel)};")
