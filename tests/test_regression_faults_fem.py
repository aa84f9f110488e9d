"""Regression tests (not independent truths, see tests/test_fem_faults.py for those): the
pair-FE fault figures README.md publishes in "Real flanks and faults".

Recomputing them takes about a minute (two revolutions of the pair FE at the default
sizes, a cracked body, two simulations), so they are read from the committed
machine-written reports (reports/examples/{spall,root_crack}/{stiffness,simulate}_fem,
`make report`), and each report is cross-checked cheaply against the current code:
its healthy mesh periods are, row for row, the committed healthy pair FE curve
(reports/stiffness_fem, which tests/test_regression_published.py pins to a fresh FE
run); its summary matches its own CSV; the simulation ran on that FE table; the scene
it was made from is today's example file; and the analytic rows beside it are
recomputed. The README must print exactly the digits formatted here.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from gearwear import io
from gearwear.analytic.tvms import mesh_stiffness
from gearwear.scene.files import load_scene_dict
from gearwear.scene.model import scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
from scenes import published_text  # noqa: E402

README = published_text()  # README.md and docs/*.md: the published text
REPORTS = ROOT / "reports"
EXAMPLES = ("spall", "root_crack")


def say(text: str) -> None:
    text = " ".join(text.split())
    assert text in README, f"README.md does not say: {text!r}"


def e8(x: float) -> str:
    return f"{x / 1e8:.3f}e8"


def _json(rel: str):
    return json.loads((REPORTS / rel).read_text())


def _rows(rel: str) -> list[list[str]]:
    with open(REPORTS / rel, newline="") as f:
        return list(csv.reader(f))


def _scene(name: str):
    data, label = load_scene_dict(str(ROOT / "examples" / f"{name}.toml"))
    return scene_from_dict(data, name=label)


@pytest.fixture(scope="module")
def reports():
    out = {}
    for name in EXAMPLES:
        out[name] = {
            kind: _json(f"examples/{name}/{kind}/{'summary' if 'simulate' in kind else 'stiffness_summary'}.json")
            for kind in ("stiffness", "stiffness_fem", "simulate", "simulate_fem")
        }
        for k in ("stiffness", "stiffness_fem"):
            out[name][k] = out[name][k][0]
    out["healthy_fem"] = _json("stiffness_fem/stiffness_summary.json")[0]
    return out


def _indicators(summary: dict) -> str:
    a = summary["condition_indicators"]["a_delta_m_per_s2"]
    return f"{a['kurtosis']:.3f}, {a['crest_factor']:.3f}, {a['FM4']:.3f}, {a['sideband_ratio_dB']:+.1f} dB"


def test_fault_examples_table(reports):
    for name in EXAMPLES:
        r = reports[name]
        for label, st, sim in (
            ("pair FE", r["stiffness_fem"], r["simulate_fem"]),
            ("analytic", r["stiffness"], r["simulate"]),
        ):
            say(
                f"| {name} | {label} | {st['ste_peak_to_peak_um']:.3f} um | {e8(st['mean_N_per_m'])} N/m | "
                f"{_indicators(sim)} |"
            )
    h = reports["healthy_fem"]
    assert h["wear"] == "unworn" and h["clearance_um"] == 0.0
    say(f"| healthy (paper pair) | pair FE | {h['ste_peak_to_peak_um']:.3f} um | {e8(h['mean_N_per_m'])} N/m | |")


def test_fault_examples_paragraph(reports):
    fe = [reports[n]["stiffness_fem"] for n in EXAMPLES]
    assert len({(s["fe_positions_solved"], s["points"]) for s in fe}) == 1
    say(f"({fe[0]['fe_positions_solved']} of {fe[0]['points']} for both examples)")
    sp = reports["spall"]
    say(f"({sp['stiffness_fem']['ste_peak_to_peak_um']:.3f} against {sp['stiffness']['ste_peak_to_peak_um']:.3f} um)")
    # the analytic healthy pair is recomputed (1 ms); the crack's analytic TE is checked below
    healthy_an = float(np.ptp(mesh_stiffness(_scene("root_crack").pair).ste_m)) * 1e6
    cr = reports["root_crack"]
    rise_fe = cr["stiffness_fem"]["ste_peak_to_peak_um"] - reports["healthy_fem"]["ste_peak_to_peak_um"]
    rise_an = cr["stiffness"]["ste_peak_to_peak_um"] - healthy_an
    say(
        f"raises the FE TE peak-to-peak by {rise_fe:.3f} um over the healthy FE pair, {rise_fe / rise_an:.1f} times "
        f"the analytic model's rise ({rise_an:.3f} um over its {healthy_an:.3f} um)"
    )
    below = {
        round(100 * (1 - reports[n]["stiffness_fem"]["mean_N_per_m"] / reports[n]["stiffness"]["mean_N_per_m"]))
        for n in EXAMPLES
    }
    assert len(below) == 1
    say(f"The FE means are {below.pop()} % below Ishikawa's")
    body = cr["stiffness_fem"]["fe_cracked_body"]
    dofs = f"{body['ndofs']:,d}".replace(",", " ")
    say(f"(the cracked body, {dofs} dofs with {body['condensed_dofs']} condensed")


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_committed_fe_reports_are_todays(name, reports):
    r = reports[name]
    fe = _rows(f"examples/{name}/stiffness_fem/stiffness_fem_unworn_clearance0um.csv")
    healthy = _rows("stiffness_fem/stiffness_fem_unworn_clearance0um.csv")
    header, rows, h_rows = fe[0], fe[1:], healthy[1:]
    assert header == healthy[0] and len(rows) == 30 * len(h_rows) == r["stiffness_fem"]["points"]
    # mesh periods 2..28 hold no faulty tooth: the healthy curve, every value but the angle
    n = len(h_rows)
    for period in range(2, 29):
        assert [row[1:] for row in rows[period * n : (period + 1) * n]] == [row[1:] for row in h_rows], period
    ste = np.array([float(row[header.index("ste_um")]) for row in rows])
    assert float(np.ptp(ste)) == pytest.approx(r["stiffness_fem"]["ste_peak_to_peak_um"], rel=1e-8)
    # the simulation ran on that table
    sim = r["simulate_fem"]
    assert sim["stiffness_source"] == "fem" and sim["stiffness_table_mesh_periods"] == 30
    assert sim["mean_mesh_stiffness_N_per_m"] == pytest.approx(r["stiffness_fem"]["mean_N_per_m"], rel=1e-9)
    # made from today's example scene
    scene = _scene(name)
    digest = io.scene_inputs(scene)["scene_sha256"]
    for kind in ("stiffness_fem", "stiffness", "simulate"):
        assert _json(f"examples/{name}/{kind}/manifest.json")["provenance"]["scene_sha256"] == digest, kind
    assert r["stiffness_fem"]["faults"] == scene.faults.label()
    # the analytic rows beside it, recomputed
    an = mesh_stiffness(scene.pair, points=360, faults=scene.faults)
    assert float(np.ptp(an.ste_m)) * 1e6 == pytest.approx(r["stiffness"]["ste_peak_to_peak_um"], rel=1e-9)
    assert an.mean_N_per_m == pytest.approx(r["stiffness"]["mean_N_per_m"], rel=1e-9)
