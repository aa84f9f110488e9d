"""Trend classification and the trends table of the paper report (pure logic): every
row's "why" must follow from what that row measured, on synthetic inputs (both
directions of every quantity) and on the committed reports/paper/trends.json."""

import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from gearwear.reports.paper_study import CLEARANCES_UM, PHASES
from gearwear.reports.paper_trends import MECHANISMS, agrees, classify, describe_change, trends

ROOT = Path(__file__).resolve().parents[1]
CLASSES = ("increase", "decrease", "decrease-then-increase", "increase-then-decrease", "nonlinear", "flat")


@pytest.mark.parametrize(
    "values,expected",
    [
        ([150.0, 150.05, 150.1], "increase"),  # tiny relative change with a large offset
        ([24.4, 24.3, 24.2], "decrease"),
        ([3.0, 2.0, 2.5], "decrease-then-increase"),
        ([1.0, 2.0, 1.5], "increase-then-decrease"),
        ([1.0, 3.0, 2.0, 4.0], "nonlinear"),
        ([5.0, 5.0, 5.0], "flat"),
    ],
)
def test_classify(values, expected):
    assert classify(values) == expected


def test_agreement_rules():
    assert agrees("increase", "increase") == "agree"
    assert agrees("nonlinear", "decrease-then-increase") == "agree"
    assert agrees("increase", "flat") == "disagree (flat)"
    assert agrees("decrease", "increase") == "disagree"
    assert classify(np.linspace(0, 1, 21) ** 2) == "increase"


@pytest.mark.parametrize(
    "values,text",
    [
        ([0.6052, 0.5789, 0.5853], "falls by 4.35 % (unworn -> mild), then rises by 1.11 % (mild -> severe)"),
        ([754.5, 674.9, 664.8], "falls by 11.9 % (unworn -> severe)"),
        ([0.01688, 0.0632, 0.03927], "rises by 274 % (unworn -> mild), then falls by 37.9 % (mild -> severe)"),
        ([1.0, 1.0, 1.0], "stays flat (unworn -> severe)"),
        ([1.0, 3.0, 2.0], "rises by 200 % (unworn -> mild), then falls by 33.3 % (mild -> severe)"),
    ],
)
def test_describe_change(values, text):
    assert describe_change(values, PHASES) == text


# -- consistency of a row's "why" with its own measurement ---------------------------------

PHRASES = {
    "increase": (["rises by"], ["falls by"]),
    "decrease": (["falls by"], ["rises by"]),
    "decrease-then-increase": (["falls by", "then rises by"], []),
    "increase-then-decrease": (["rises by", "then falls by"], []),
    "nonlinear": (["changes direction"], ["rises by", "falls by"]),
    "flat": (["stays flat"], ["rises by", "falls by"]),
}


def _numbers(ours: str) -> list[float]:
    return [float(x) for x in ours.split(": ", 1)[1].split(" (")[0].split(" -> ")]


def check_row(row: dict) -> bool:
    """Asserts that the row's "why" says what its "ours" measured; returns whether the
    row was a classified trend (the few summary rows have their own checks)."""
    why = row["why"]
    assert why.startswith("Measured: "), row
    found = row["ours"].split(":", 1)[0]
    # the mechanism texts used must explain the measured direction
    for key, (direction, text) in MECHANISMS.items():
        if text.split("{")[0] in why:
            assert direction == found, (key, row)
    # the verdict in words
    if row["verdict"] == "agree":
        assert "as the paper says" in why and "does not find" not in why, row
    elif row["verdict"].startswith("disagree"):
        assert "does not find" in why and "as the paper says" not in why, row
    if found not in CLASSES:
        return False
    y = _numbers(row["ours"])
    assert classify(y) == found or len(set(y)) < len(y), row  # display rounding may tie neighbours
    measured = why.split(" Why: ")[0].split(" Context: ")[0]
    must, must_not = PHRASES[found]
    pos = [measured.find(p) for p in must]
    assert all(p >= 0 for p in pos) and pos == sorted(pos), (found, measured)
    assert not any(p in measured for p in must_not), (found, measured)
    if found in ("increase", "decrease"):
        pct = float(re.search(r"(?:rises|falls) by ([0-9.e+-]+) %", measured).group(1))
        assert pct == pytest.approx(100 * abs(y[-1] / y[0] - 1), rel=0.01, abs=0.02), (pct, y, row)
    return True


def _fake_res(seed: int, flip: bool):
    """A report's result dictionary with synthetic numbers: each quantity gets a random
    shape (monotone up or down, V, inverted V, zigzag); ``flip`` reverses them all."""
    from gearwear.dynamics import paper_pair

    rng = np.random.default_rng(seed)
    model = paper_pair()

    def shape(n, level=1.0):
        kind = rng.integers(5)
        x = np.linspace(0, 1, n)
        y = {0: x, 1: -x, 2: (x - 0.5) ** 2, 3: -((x - 0.5) ** 2), 4: np.sin(7 * x)}[int(kind)]
        y = level * (1 + 0.3 * y)
        return y[::-1] if flip else y

    def sims(keys):
        nk = len(keys)
        H = {name: np.array([shape(nk, 0.1 * (k + 1)) for k in range(10)]).T for name in ("y_p", "x_p", "delta", "F_m")}
        st = {name: np.array([shape(nk, 2.0), shape(nk, 5.0)]).T for name in H}
        out = {}
        for i, key in enumerate(keys):
            res = SimpleNamespace(
                fm_Hz=600.0,
                bearing_contact_fraction={"pinion": 1.0, "gear": 1.0},
                harmonics=(lambda name, n, i=i: H[name][i, :n]),
                stats={name: {"p2p": st[name][i, 0], "mean": st[name][i, 1]} for name in H},
            )
            out[key] = SimpleNamespace(result=res, model=model)
        return out

    def tables(keys):
        phi = np.linspace(0, 1, 360, endpoint=False)
        mean = shape(len(keys), 3e8)
        out = {}
        for i, key in enumerate(keys):
            k = mean[i] * (1 + 0.2 * np.cos(2 * np.pi * phi) + 0.05 * rng.standard_normal(360))
            out[key] = SimpleNamespace(
                k_N_per_m=k,
                mean_N_per_m=float(k.mean()),
                angle_rad=phi,
                span_rad=1.0,
                pairs_in_contact=np.where(phi < 0.6, 2, 1),
            )
        return out

    cl_fine = np.linspace(0.0, 100.0, 21)
    cols = {
        a: shape(21, lv)
        for a, lv in (("C", 0.15), ("alpha", 0.35), ("L", 0.024), ("eps", 1.65), ("rw", 0.075), ("b", 60e-6))
    }
    geo = [
        SimpleNamespace(
            centre_distance_m=cols["C"][i],
            pressure_angle_rad=cols["alpha"][i],
            contact_line_length_m=cols["L"][i],
            contact_ratio=cols["eps"][i],
            mesh=SimpleNamespace(operating_pitch_radii_m=(cols["rw"][i], cols["rw"][i])),
            backlash_m=cols["b"][i],
        )
        for i in range(21)
    ]
    return {
        "tabs_wear": tables(PHASES),
        "sims_wear": sims(PHASES),
        "tabs_cl": tables(CLEARANCES_UM),
        "sims_cl": sims(CLEARANCES_UM),
        "cl_fine": cl_fine,
        "geo": geo,
    }


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("flip", [False, True])
def test_every_why_follows_its_measurement_synthetic(seed, flip):
    rows = trends(_fake_res(seed, flip))
    assert len(rows) == 63
    assert sum(check_row(r) for r in rows) >= 55
    found = {r["ours"].split(":", 1)[0] for r in rows}
    assert {"increase", "decrease"} <= found


def test_flipping_the_measurement_flips_the_words():
    """The same synthetic report with every sequence reversed: each monotone row's
    measured words swap (rises <-> falls); the explanation never stays put."""
    a, b = trends(_fake_res(7, False)), trends(_fake_res(7, True))
    swapped = 0
    for ra, rb in zip(a, b):
        fa, fb = ra["ours"].split(":", 1)[0], rb["ours"].split(":", 1)[0]
        if {fa, fb} == {"increase", "decrease"}:
            assert ra["why"] != rb["why"]
            ma, mb = (r["why"].split(" Why: ")[0] for r in (ra, rb))
            assert ("rises by" in ma) == ("falls by" in mb), (ra, rb)
            swapped += 1
    assert swapped >= 20


def test_every_why_follows_its_measurement_committed_report():
    """reports/paper/trends.json as committed (regenerate it with `make report` when
    report_paper.trends changes)."""
    rows = json.loads((ROOT / "reports" / "paper" / "trends.json").read_text())
    assert len(rows) == 63
    assert sum(check_row(r) for r in rows) >= 55
