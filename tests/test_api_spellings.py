"""Every spelling the command line takes for a value is taken by the Python API, and means
the same: the API's result equals the CLI's ``--json`` for the same spelling.

Run on the paper pair and on the unequal, profile-shifted pair whose driver has more
teeth (examples/shifted_pair.toml), so a spelling that only works for 30/30 shows up."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import gearwear as gw
from gearwear.cli import main

ROOT = Path(__file__).resolve().parents[1]
SCENES = ["paper-default", str(ROOT / "examples" / "shifted_pair.toml")]
# the --wear spellings of the README: a phase, a maximum depth, running hours
WEARS = ["mild", "25um", "8h"]


def _cli(argv, capsys):
    rc = main(argv)
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    return json.loads(cap.out)


@pytest.mark.parametrize("scene", SCENES, ids=["paper", "shifted_driver_more_teeth"])
@pytest.mark.parametrize("wear", WEARS)
def test_simulate_takes_every_wear_spelling_of_the_cli(scene, wear, capsys):
    cli = _cli(
        [
            "simulate",
            scene,
            "--wear",
            wear,
            "--set",
            "solver.duration_s=0.1",
            "--set",
            "solver.discard_s=0.05",
            "--json",
        ],
        capsys,
    )
    api = gw.simulate(scene, wear=wear, solver__duration_s=0.1, solver__discard_s=0.05).summary()
    for k in (1, 2, 3):
        assert api["harmonics"]["F_m_N"][k - 1] == pytest.approx(cli["harmonics"]["F_m_N"][k - 1], rel=1e-12)
    # and the spelling is not ignored: unworn gives other harmonics
    unworn = gw.simulate(scene, solver__duration_s=0.1, solver__discard_s=0.05).summary()
    assert unworn["harmonics"]["F_m_N"][0] != pytest.approx(api["harmonics"]["F_m_N"][0], rel=1e-6)


@pytest.mark.parametrize("wear", WEARS)
def test_mesh_stiffness_takes_every_wear_spelling_of_the_cli(wear, capsys):
    cli = _cli(["stiffness", "paper-default", "--wear", wear, "--json"], capsys)
    api = gw.mesh_stiffness(gw.paper_pair(), wear=wear, torque_Nm=40.0)
    assert api.mean_N_per_m == pytest.approx(cli["mean_N_per_m"], rel=1e-12)


def test_simulate_short_flags_are_keywords(capsys):
    cli = _cli(
        [
            "simulate",
            SCENES[1],
            "--torque-Nm",
            "90",
            "--clearance-um",
            "20",
            "--set",
            "solver.duration_s=0.1",
            "--set",
            "solver.discard_s=0.05",
            "--json",
        ],
        capsys,
    )
    api = gw.simulate(
        SCENES[1], torque_Nm=90, clearance_um=20, solver__duration_s=0.1, solver__discard_s=0.05
    ).summary()
    assert api["harmonics"]["F_m_N"][:3] == pytest.approx(cli["harmonics"]["F_m_N"][:3], rel=1e-12)


def test_a_bad_wear_spelling_names_the_flag():
    with pytest.raises(gw.InputError, match="--wear = '25 mm'"):
        gw.simulate("paper-default", wear="25 mm")
