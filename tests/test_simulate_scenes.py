"""Scenes drive the dynamics: only named effects are modelled, a zero-magnitude effect
reproduces the scene without it, hard cases separate and stay finite, CLI contracts."""

import json
import subprocess
import sys

import numpy as np
import pytest

from gearwear.jobs.simulate import run
from gearwear.scene.files import builtin_scene_dict
from gearwear.scene.model import scene_from_dict
from gearwear.scene.overrides import apply_overrides

SHORT = ["solver.duration_s=0.06", "solver.discard_s=0.03"]


def scene(*sets, base="paper-default"):
    """The built-in scene with the short run unless ``sets`` give their own solver times."""
    given = {s.split("=", 1)[0] for s in sets}
    short = [s for s in SHORT if s.split("=", 1)[0] not in given]
    return scene_from_dict(apply_overrides(builtin_scene_dict(base), [*short, *sets]), name=base)


@pytest.fixture(scope="module")
def plain():
    return run(scene("solver.method=\"rk4\""))


def _same(a, b, name):
    x, y = a.result.signals[name], b.result.signals[name]
    return np.max(np.abs(x - y)) / np.max(np.abs(y))


def test_zero_clearance_and_unworn_reproduce_the_scene_without_them(plain):
    with_clear = run(scene("solver.method=\"rk4\"", "effects.bearing_clearance={clearance_um = 0}"))
    unworn = run(scene("solver.method=\"rk4\"", "effects.wear={phase = \"unworn\"}"))
    for other in (with_clear, unworn):
        for name in ("F_m", "y_p", "x_p", "delta"):
            assert _same(other, plain, name) < 1e-9


def test_backlash_never_reached_reproduces_the_linear_mesh(plain):
    bl = run(scene("solver.method=\"rk4\"", "effects.backlash={initial_um = 50}"))
    assert bl.result.separation_fraction == 0.0
    for name in ("F_m", "y_p", "x_p"):
        assert _same(bl, plain, name) < 1e-9
    # delta carries the dead-zone offset b: the force balance is F = k (delta - b)
    assert np.max(np.abs(bl.result.signals["delta"] - plain.result.signals["delta"] - 25e-6)) < 1e-9


def test_only_named_effects_are_modelled(plain):
    m = plain.model
    assert m.backlash_half_m is None and m.bearing_half_clearance_m is None and not m.te_excitation
    full = run(
        scene(
            "effects.backlash={initial_um = 50}",
            "effects.bearing_clearance={clearance_um = 10}",
            "effects.centre_distance={coupling = \"dynamic\"}",
            "effects.wear={phase = \"severe\"}",
            "effects.transmission_error={}",
        )
    )
    fm = full.model
    # dynamic coupling starts from the nominal geometry: b = b0 / 2 there
    assert (
        fm.backlash_half_m == pytest.approx(25e-6)
        and fm.bearing_half_clearance_m == pytest.approx(5e-6)
        and fm.te_excitation
    )
    assert fm.centre_distance == "dynamic"


def test_light_load_with_backlash_separates_and_stays_finite():
    """5 N m, 100 um backlash, near the mesh resonance with severe-wear excitation: the
    teeth separate and hit the back flank; the result is finite."""
    r = run(
        scene(
            "operating.torque_Nm=5",
            "operating.speed_rpm=2000",
            "effects.backlash={initial_um = 100}",
            "effects.wear={phase = \"severe\"}",
            "effects.transmission_error={}",
            "solver.duration_s=0.1",
            "solver.discard_s=0.05",
        )
    )
    assert r.result.separation_fraction > 0.0
    for v in r.result.signals.values():
        assert np.all(np.isfinite(v))


def cli(*args):
    return subprocess.run([sys.executable, "-m", "gearwear.cli", *args], capture_output=True, text=True)


def test_simulate_cli_json_and_files(tmp_path):
    r = cli(
        "simulate",
        "--set",
        "solver.duration_s=0.05",
        "--set",
        "solver.discard_s=0.02",
        "--json",
        "--out",
        str(tmp_path),
    )
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    for key in (
        "fm_Hz",
        "harmonics",
        "mean",
        "ac_rms",
        "peak_to_peak",
        "separation_fraction",
        "backside_fraction",
        "steps",
        "wall_s",
    ):
        assert key in s
    assert s["fm_Hz"] == pytest.approx(600.0)
    for sig in ("F_m_N", "delta_um", "y_p_um"):
        assert len(s["harmonics"][sig]) == 10
    names = {p.name for p in tmp_path.iterdir()}
    assert {"signals.npz", "signals.csv", "signals.csv.json", "response.png", "summary.json"} <= names


@pytest.mark.parametrize(
    "setting,message",
    [
        ("operating.speed_rpm=-5", "operating.speed_rpm = -5 rpm"),
        ("effects.backlash.initial_um=-1", "effects.backlash.initial_um = -1 um"),
        ("effects.bearing_clearence.clearance_um=5", "did you mean effects.bearing_clearance"),
        ("solver.method=\"euler\"", "solver.method = 'euler'"),
        ("operating.speed", "--set 'operating.speed'"),
    ],
)
def test_simulate_bad_overrides(tmp_path, setting, message):
    r = cli("simulate", "--set", setting, "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and message in r.stderr, r.stderr
    assert not (tmp_path / "o").exists()


def test_sweep_grid_and_outputs(tmp_path):
    r = cli(
        "sweep",
        "paper-wear-severe",
        "--set",
        "effects.bearing_clearance.clearance_um=0:40:2",
        "--set",
        "solver.duration_s=0.05",
        "--set",
        "solver.discard_s=0.02",
        "--workers",
        "2",
        "--out",
        str(tmp_path),
        "--json",
    )
    assert r.returncode == 0, r.stderr
    pts = json.loads(r.stdout)["points"]
    assert [p["point"]["effects.bearing_clearance.clearance_um"] for p in pts] == [0.0, 40.0]
    rows = (tmp_path / "sweep.csv").read_text().splitlines()
    assert len(rows) == 3 and rows[0].startswith("effects.bearing_clearance.clearance_um,separation_fraction")
    assert (tmp_path / "harmonics_F_m_N.png").exists()


def test_summary_statistics_of_a_known_signal():
    """Regression class: ``rms`` included the mean (y_p: rms 7.05 um, peak-to-peak 0.62 um). On
    c + A sin(2 pi k t / T) sampled over whole periods: mean c, AC RMS A / sqrt(2), p-p 2 A
    (sampled at the peaks)."""
    import math

    import numpy as np

    from gearwear.dynamics.simulate import signal_stats

    t = np.arange(400) / 400.0
    x = 7.05 + 0.31 * np.sin(2 * math.pi * 4 * t)
    s = signal_stats(x)
    assert s["mean"] == pytest.approx(7.05, rel=1e-12)
    assert s["ac_rms"] == pytest.approx(0.31 / math.sqrt(2), rel=1e-12)
    assert s["p2p"] == pytest.approx(0.62, rel=1e-12)
    assert set(s) == {"mean", "ac_rms", "p2p"}


def test_a_wear_study_includes_its_unworn_baseline():
    """Round trip (issue 24): transmission_error with zero wear was refused ("no excitation on a
    nominal flank"), so a wear study could not include its own baseline. It is accepted: zero
    wear equals no wear effect bit for bit, and the nominal flank's excitation is not zero but
    the tip-corner contact outside the path (analytic.tvms corner gaps), which the refusal hid."""
    base = builtin_scene_dict("paper-default")
    short = ["solver.duration_s=0.03", "solver.discard_s=0.02", "effects.transmission_error={}"]
    zero = run(scene_from_dict(apply_overrides(base, short + ["effects.wear={max_depth_um=0}"])))
    none = run(scene_from_dict(apply_overrides(base, short)))
    assert np.array_equal(zero.result.signals["F_m"], none.result.signals["F_m"])
    assert zero.model.te_excitation and np.any(zero.stiffness.e > 0)
