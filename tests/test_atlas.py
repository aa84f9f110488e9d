"""``gearwear atlas``: the metrics of a curve against independent routes (a dense FFT of the
interpolant, the unworn identity STE = F / k, the kinematic transitions at vanishing load), the
SPEC's one-line refusals, and the engine: a small atlas (8 designs, coarse FE) through a Dask
LocalCluster writes the bytes of the local process pool, and a rerun after losing a design's
cache entry computes only that design and writes the same bytes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from gearwear import io
from gearwear.cli.app import main
from gearwear.jobs.atlas_metrics import METRICS, curve_metrics, transitions_rad
from gearwear.stiffness.sources import Request, curve
from tests.pairs import DRIVER_LARGER, UNEQUAL

PAIRS = {"unequal_23_47": UNEQUAL, "driver_larger_47_23": DRIVER_LARGER}


def test_transitions_of_a_hand_made_staircase():
    """Loaded pairs 1 1 2 2 2 1 at angles 0..5 over a period of 6: the count rises between 1 and 2
    (at 1.5) and falls between 4 and 5 (at 4.5); the count wraps round the period."""
    rises, falls = transitions_rad([0, 1, 2, 3, 4, 5], [1, 1, 2, 2, 2, 1], 6.0)
    assert rises == [1.5] and falls == [4.5]
    rises, falls = transitions_rad([0, 1, 2, 3, 4, 5], [1, 2, 2, 1, 1, 2], 6.0)
    assert rises == [0.5, 4.5] and falls == [2.5, 5.5]  # 2 at the last node, 1 at the first
    rises, falls = transitions_rad([0.0, 1.0, 2.0], [1, 1, 2], 3.0)
    assert rises == [1.5] and falls == [2.5]  # 2 at the last node, back to 1 at 0 + period


def _dense_fourier(c, n: int = 1 << 18):
    """Mean and |harmonics 1-3| of the periodic piecewise-linear k_h, by the FFT of 2^18 uniform
    samples of np.interp (a second route to geometry.curves' exact integrals)."""
    P = c.span_rad
    x = np.arange(n) * (P / n)
    a = np.asarray(c.angle_rad)
    k = np.interp(x, np.r_[a, a[0] + P], np.r_[c.k_N_per_m, c.k_N_per_m[0]])
    f = np.fft.rfft(k) / n
    return f[0].real, 2 * np.abs(f[1:4])


@pytest.mark.parametrize("name", PAIRS)
@pytest.mark.parametrize("method", ["ishikawa", "energy"])
def test_metrics_of_an_analytic_curve_by_second_routes(name, method):
    pair = PAIRS[name]
    T = 150.0
    c = curve(method, Request(pair, T))
    m = curve_metrics(c)
    assert set(m) == set(METRICS)
    mean, h = _dense_fourier(c)
    assert m["mean_N_per_m"] == pytest.approx(mean, rel=2e-6)  # sampling the load-sharing jumps
    for j in range(3):
        assert m[f"h{j + 1}_N_per_m"] == pytest.approx(h[j], rel=2e-3, abs=1e-4 * mean)
    assert m["p2p_N_per_m"] == pytest.approx(np.ptp(c.k_N_per_m), rel=1e-12)
    # the plateaus: dense sample means over the kinematic zones (1 <= epsilon < 2 here)
    x = np.linspace(0, c.mesh.mesh_angle_rad, 20001)[:-1]
    a = np.asarray(c.angle_rad)
    k = np.interp(x, np.r_[a, a[0] + c.span_rad], np.r_[c.k_N_per_m, c.k_N_per_m[0]])
    two = x <= c.mesh.exit_angle_rad
    assert m["double_N_per_m"] == pytest.approx(k[two].mean(), rel=1e-3)
    assert m["single_N_per_m"] == pytest.approx(k[~two].mean(), rel=1e-3)
    # unworn: F = k STE, so the STE's peak-to-peak is F (1 / k_min - 1 / k_max)
    F = T / pair.gear(0).base_radius_m
    assert m["ste_p2p_um"] == pytest.approx(1e6 * F * (1 / c.k_N_per_m.min() - 1 / c.k_N_per_m.max()), rel=1e-9)


@pytest.mark.parametrize("name", PAIRS)
def test_transitions_tend_to_the_kinematic_ones_as_the_load_vanishes(name):
    """A pair starts carrying load before A and stops after E (corner contact, wider the more the
    teeth deflect): entry_deg < 0 < exit_deg, both shrinking with the load towards the kinematic
    transitions (0) at vanishing load."""
    pair = PAIRS[name]
    rows = [curve_metrics(curve("ishikawa", Request(pair, T))) for T in (400.0, 40.0, 0.04)]
    entries = [r["entry_deg"] for r in rows]
    exits = [r["exit_deg"] for r in rows]
    assert all(e < 0 for e in entries) and all(x > 0 for x in exits)
    assert abs(entries[0]) > abs(entries[1]) > abs(entries[2]) and exits[0] > exits[1] > exits[2]
    step = 360.0 / pair.teeth[0] / 360  # one node of the 360-point table (deg)
    assert abs(entries[2]) < step and abs(exits[2]) < step


# -- the SPEC -----------------------------------------------------------------------------------


BAD = [
    ("designs = 0\n", "designs"),
    ("designs = 2.5\n", "designs"),
    ("[axes]\npinion_teeth = [30, 20]\n", "axes.pinion_teeth"),
    ("[axes]\npressure_angle_deg = [5, 20]\n", "axes.pressure_angle_deg"),
    ("[axes]\nline_load_N_per_mm = 100\n", "axes.line_load_N_per_mm"),
    ("[axes]\nratio = [1, 20]\n", "axes.ratio"),
    ("[fe]\npositions = 1\n", "fe.positions"),
    ("[fe]\nplane = 'shell'\n", "fe.plane"),
    ("[fe]\nmesh_scal = 2\n", "fe.mesh_scal"),
    ("models = ['ishikawa', 'nonsense']\n", "models"),
    ("models = ['fem']\n", "models"),
    ("[pair]\nmodule_mm = -3\n", "pair.module_mm"),
    ("designs = \n", "SPEC"),
]


@pytest.mark.parametrize("text,key", BAD, ids=[k for _, k in BAD])
def test_a_bad_spec_is_one_line_exit_2_and_nothing_written(tmp_path, capsys, text, key):
    spec = tmp_path / "atlas.toml"
    spec.write_text(text)
    out = tmp_path / "out"
    assert main(["atlas", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("gearwear: error: ") and key in lines[0], err
    assert not out.exists()


def test_the_models_are_the_registrys_analytic_command_sources():
    from gearwear.jobs.atlas_spec import analytic_models, parse
    from gearwear.stiffness.sources import SOURCES

    # every analytic --method but the one fitted on the atlas itself
    want = tuple(n for n, s in SOURCES.items() if s.command and not s.fe and n != "corrected")
    assert "corrected" in SOURCES and analytic_models() == want and parse({}).models == want
    assert parse({"models": ["energy"]}).models == ("energy",)


# -- the engine ---------------------------------------------------------------------------------

TINY = """designs = 8
seed = 3
[axes]
pinion_teeth = [14, 20]
ratio = [1.0, 1.25]
line_load_N_per_mm = [400.0, 1000.0]
[fe]
positions = 4
mesh_scale = 4.0
contact_scale = 2.0
transitions = false
[analytic]
points = 64
"""


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.name != io.TIMING}


def _rows(folder: Path) -> list[dict[str, str]]:
    import csv

    with open(folder / "atlas.csv", newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.slow
def test_local_pool_and_dask_write_the_same_bytes_and_a_rerun_resumes(tmp_path, monkeypatch, capsys):
    spec = tmp_path / "tiny.toml"
    spec.write_text(TINY)
    monkeypatch.setenv("GEARWEAR_CACHE", str(tmp_path / "cache_local"))
    assert main(["atlas", str(spec), "--workers", "2", "--json", "--out", str(tmp_path / "local")]) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["from_cache"] == 0 and first["designs"] == 8
    monkeypatch.setenv("GEARWEAR_CACHE", str(tmp_path / "cache_dask"))
    assert main(["atlas", str(spec), "--scheduler", "local:2", "--json", "--out", str(tmp_path / "dask")]) == 0
    assert json.loads(capsys.readouterr().out)["from_cache"] == 0
    local = _snapshot(tmp_path / "local")
    assert set(local) == {"atlas.csv", "atlas.csv.json", "manifest.json"}
    assert local == _snapshot(tmp_path / "dask")

    # the table: every design with both FE rows and every model; the sidecar's bookkeeping
    from gearwear.jobs.atlas_spec import analytic_models

    rows = _rows(tmp_path / "local")
    side = json.loads(local["atlas.csv.json"])
    models = ["fem", "fem_bore_fixed", *analytic_models()]
    assert len(rows) == 8 * len(models)
    assert side["designs"] + sum(side["rejects"].values()) == side["points_drawn"]
    assert side["inputs"]["fe.positions"] == 4 and side["inputs"]["models"] == list(analytic_models())
    by = {(r["design"], r["model"]): r for r in rows}
    for d in {r["design"] for r in rows}:
        assert [m for (dd, m) in by if dd == d] == models
        fe, bore = by[(d, "fem")], by[(d, "fem_bore_fixed")]
        # taking the blanks' torsion (a compliance in series) out can only stiffen the mesh
        assert float(fe["mean_N_per_m"]) >= float(bore["mean_N_per_m"]) > 0
        for m in models:
            assert float(by[(d, m)]["mean_N_per_m"]) > 0

    # resume: one design's FE entry lost, the rerun computes that design only, same bytes
    monkeypatch.setenv("GEARWEAR_CACHE", str(tmp_path / "cache_local"))
    entries = sorted((tmp_path / "cache_local" / "atlas").glob("*.atlas.json"))
    fe_entries = [p for p in entries if set(json.loads(p.read_text())) == {"fem", "fem_bore_fixed"}]
    assert len(fe_entries) == 8
    fe_entries[0].unlink()
    assert main(["atlas", str(spec), "--workers", "1", "--json", "--out", str(tmp_path / "again")]) == 0
    assert json.loads(capsys.readouterr().out)["from_cache"] == 7
    assert _snapshot(tmp_path / "again") == local
    timing = json.loads((tmp_path / "again" / io.TIMING).read_text())["wall_s"]
    assert [k for k in timing if k.isdigit()] and len([k for k in timing if k.isdigit()]) == 1
    assert math.isfinite(timing["total_wall_s"])


def test_a_model_that_refuses_or_fails_leaves_its_rows_empty_and_says_why(monkeypatch):
    """One design must never end a long atlas: a model outside its validity (InputError) gets
    NaN metrics and "refused: <its line>", one that raises anything else "failed: <type>"; the
    other models of the design are computed as usual."""
    import dataclasses

    from gearwear.core.validation import fail
    from gearwear.jobs import atlas
    from gearwear.jobs.atlas_space import Design
    from gearwear.stiffness import sources

    def refuses(rq):
        raise fail("contact_ratio", 1.6, "", "must be below 1.5 for this model")

    def fails(rq):
        return 1 / 0

    monkeypatch.setitem(sources.SOURCES, "refuses", dataclasses.replace(sources.SOURCES["ishikawa"], curve=refuses))
    monkeypatch.setitem(sources.SOURCES, "fails", dataclasses.replace(sources.SOURCES["ishikawa"], curve=fails))
    d = Design(0, UNEQUAL, 100.0, 100.0, 4.0)
    settings = {"points": 64, "plane": "stress"}
    got = atlas.run_design(d, settings, ("refuses", "ishikawa", "fails"), False)["metrics"]
    assert got["refuses"]["note"] == "refused: contact_ratio = 1.6: must be below 1.5 for this model"
    assert got["fails"]["note"].startswith("failed: ZeroDivisionError")
    for m in ("refuses", "fails"):
        assert all(math.isnan(got[m][k]) for k in METRICS)
    assert got["ishikawa"]["mean_N_per_m"] > 0 and "note" not in got["ishikawa"]
