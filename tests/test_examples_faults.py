"""The example scenes of issue 13 (tip relief, measured deviation, root crack, spall)
through the command line: `stiffness --json` reports the loaded TE peak-to-peak, and
`simulate --json` runs each and reports the condition-monitoring indicators.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from gearwear.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCENES = ["tip_relief", "measured_deviation", "root_crack", "spall"]


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("name", SCENES)
def test_stiffness_json_reports_the_te_peak_to_peak(name, capsys):
    doc = _json(capsys, ["stiffness", str(EXAMPLES / f"{name}.toml"), "--json", "--points", "120"])
    assert math.isfinite(doc["ste_peak_to_peak_um"]) and doc["ste_peak_to_peak_um"] > 0
    if name in ("root_crack", "spall"):
        # 120 uniform nodes per mesh period over the revolution, and the breakpoints on top
        assert doc["mesh_periods"] == 30 and doc["points"] > 30 * 120
    if name == "tip_relief":
        # the relief is sized for this load: the map's modified TE is below the nominal one there
        row = min(doc["harris_map"], key=lambda r: abs(r["torque_Nm"] - doc["torque_Nm"]))
        assert row["ste_peak_to_peak_modified_um"] < 0.5 * row["ste_peak_to_peak_nominal_um"]


def test_a_spall_raises_the_te_above_the_healthy_pair(capsys):
    healthy = _json(capsys, ["stiffness", "--json", "--points", "120"])
    spall = _json(capsys, ["stiffness", str(EXAMPLES / "spall.toml"), "--json", "--points", "120"])
    assert spall["ste_peak_to_peak_um"] > 3 * healthy["ste_peak_to_peak_um"]


@pytest.fixture
def coarse_fe(monkeypatch):
    """The pair FE at the coarse sizes of tests/test_fem_faults.py (contact elements a / 1.25,
    the others x 1.5; the same bodies, so a worker that built them there reuses them), so
    the command line runs in seconds; everything else is the command's own path."""
    from gearwear.fem import pair_model as fe_model

    sizes = fe_model.body_sizes
    monkeypatch.setattr(
        fe_model,
        "body_sizes",
        lambda pair, torque_Nm=40.0, contact_scale=1.0, mesh_scale=1.0: sizes(
            pair, torque_Nm, 2.0 * contact_scale, 1.5 * mesh_scale
        ),
    )


def test_fem_takes_the_spall_over_one_revolution(capsys, coarse_fe):
    """`stiffness spall.toml --method fem --json`: the FE curve spans the pinion's revolution,
    reports the TE peak-to-peak, and the pit raises it by its bridged gap (about 9-10 um,
    as the analytic model) over the healthy FE pair's."""
    doc = _json(capsys, ["stiffness", str(EXAMPLES / "spall.toml"), "--method", "fem", "--json"])
    healthy = _json(capsys, ["stiffness", "--method", "fem", "--json"])
    analytic = _json(capsys, ["stiffness", str(EXAMPLES / "spall.toml"), "--json", "--points", "24"])
    assert doc["mesh_periods"] == 30 and doc["points"] == 30 * 24 and doc["faults"] == "spall20um@g0t0"
    rise = doc["ste_peak_to_peak_um"] - healthy["ste_peak_to_peak_um"]
    assert 8.0 < rise < 11.0
    assert doc["ste_peak_to_peak_um"] == pytest.approx(analytic["ste_peak_to_peak_um"], rel=0.03)


def test_fem_takes_the_root_crack_through_stiffness_and_simulate(capsys, coarse_fe, tmp_path):
    """The root crack example with the pair FE: `stiffness --method fem --json` reports the TE
    peak-to-peak over one revolution (the cracked tooth raises it above the healthy pair's),
    `--fields` writes the field of a position on the cracked tooth (the cracked body), and
    `simulate` with effects.mesh_stiffness.source = "fem" reports the condition indicators
    with shaft-order sidebands far above the healthy noise floor (below -150 dB,
    test_fault_sidebands_stand_far_above_the_healthy_noise_floor)."""
    doc = _json(
        capsys,
        [
            "stiffness",
            str(EXAMPLES / "root_crack.toml"),
            "--method",
            "fem",
            "--json",
            "--fields",
            "20",
            "--out",
            str(tmp_path / "st"),
        ],
    )
    healthy = _json(capsys, ["stiffness", "--method", "fem", "--json"])
    assert doc["mesh_periods"] == 30 and doc["faults"] == "crack2mm@g0t0"
    assert doc["ste_peak_to_peak_um"] > healthy["ste_peak_to_peak_um"] + 0.1
    assert doc["mean_N_per_m"] < healthy["mean_N_per_m"]
    assert any(f.endswith("fields_pos20.vtu") for f in doc["files"])
    fem = ["--set", 'effects.mesh_stiffness.source="fem"']
    crack = _json(capsys, ["simulate", str(EXAMPLES / "root_crack.toml"), *fem, "--json"])
    assert crack["stiffness_source"] == "fem" and crack["stiffness_table_mesh_periods"] == 30
    c = crack["condition_indicators"]["a_delta_m_per_s2"]
    for ind in ("ac_rms", "kurtosis", "crest_factor", "FM0", "sideband_ratio_dB"):
        assert c[ind] is not None and math.isfinite(c[ind]), ind
    assert c["sideband_ratio_dB"] > -60


def test_iso_method_refuses_modifications(capsys):
    assert main(["stiffness", str(EXAMPLES / "tip_relief.toml"), "--method", "iso6336"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gearwear: error: --method = 'iso6336'") and err.count("\n") == 1


@pytest.mark.parametrize("name", SCENES)
def test_simulate_runs_each_and_reports_the_indicators(name, capsys):
    doc = _json(capsys, ["simulate", str(EXAMPLES / f"{name}.toml"), "--json"])
    ci = doc["condition_indicators"]
    assert ci["revolutions"] >= 2
    for key in ("a_delta_m_per_s2", "a_y_p_m_per_s2"):
        a = ci[key]
        for ind in ("ac_rms", "kurtosis", "crest_factor", "FM0", "sideband_ratio_dB"):
            assert a[ind] is not None and math.isfinite(a[ind]), (key, ind)
        assert a["FM4"] is not None or "FM4" in a["undefined"]


def test_fault_sidebands_stand_far_above_the_healthy_noise_floor(capsys):
    """A fault on one tooth modulates the mesh once per revolution: sidebands at the shaft
    orders around the mesh harmonics. The healthy pair has none (numerical noise)."""
    healthy = _json(capsys, ["simulate", "--set", 'effects.mesh_stiffness.source="analytic"', "--json"])
    crack = _json(capsys, ["simulate", str(EXAMPLES / "root_crack.toml"), "--json"])
    h = healthy["condition_indicators"]["a_delta_m_per_s2"]["sideband_ratio_dB"]
    c = crack["condition_indicators"]["a_delta_m_per_s2"]["sideband_ratio_dB"]
    assert h < -150 and c > -60, (h, c)


def test_flank_with_a_constant_stiffness_is_refused(capsys):
    assert (
        main(
            [
                "simulate",
                "paper-default",
                "--set",
                "flank.tip_relief={amount_um=5, start_diameter_mm=152}",
                "--set",
                'effects.mesh_stiffness.source="constant"',
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert "[flank]" in err and "effects.mesh_stiffness.source" in err and err.count("\n") == 1
