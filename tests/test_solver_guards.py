"""Solver guards: RK4 beyond its stability limit is refused, the output is sized before
the run, the adaptive solver stops with a diagnosis (step budget, divergence)."""

import math
import subprocess
import sys

import pytest

from gearwear.core.validation import InputError
from gearwear.dynamics import linear_eigenfrequencies, paper_pair, simulate
from gearwear.dynamics.model import max_linear_rate
from gearwear.dynamics.simulate import SolverError, rk4_stability_number


def test_linear_rate_is_the_highest_eigenfrequency_when_undamped():
    m = paper_pair(zeta_m=0.0, zeta_b=0.0)
    w = max_linear_rate(m)
    assert abs(w - 2 * math.pi * linear_eigenfrequencies(m).max()) < 1e-9 * w


def test_rk4_beyond_stability_limit_is_refused_in_one_line():
    m = paper_pair().with_(k_b=1e13)
    hw, w = rk4_stability_number(m, 256)
    assert hw > 2.5
    with pytest.raises(InputError) as exc:
        simulate(m, 0.01, 0.0, method="rk4")
    msg = str(exc.value)
    assert "unstable" in msg and "2.5" in msg and "dopri5" in msg and "\n" not in msg
    n_min = int(msg.split(">= ")[1].split()[0])
    assert rk4_stability_number(m, n_min)[0] <= 2.5 < rk4_stability_number(m, n_min - 1)[0]


def test_output_too_large_is_refused_before_running():
    with pytest.raises(InputError, match="GiB"):
        simulate(paper_pair(), 100.0, 0.0, method="rk4")


def test_step_budget_stops_with_a_diagnosis():
    m = paper_pair(torque_Nm=5.0, speed_rpm=6000, backlash_total_m=100e-6, te_amplitude_m=2e-6)
    with pytest.raises(SolverError) as exc:
        simulate(m, 0.1, 0.05, method="dopri5", max_steps=3000)
    msg = str(exc.value)
    assert "budget of 3000 steps" in msg and "contact events" in msg and "t = " in msg


def test_divergence_is_diagnosed_not_nan():
    """Zero damping at a parametric resonance of the mesh mode: the amplitude grows
    without bound. The solver stops and says so instead of returning NaN."""
    m = paper_pair(speed_rpm=16320, zeta_m=0.0, zeta_b=0.0)
    with pytest.raises(SolverError, match="diverged"):
        simulate(m, 0.5, 0.4, method="dopri5")


@pytest.mark.parametrize(
    "sets, needle",
    [
        (["operating.speed_rpm=1e6"], "GiB"),
        (["solver.duration_s=100"], "GiB"),
        (["bodies.bearing_stiffness_N_per_m=1e13", "solver.method=\"rk4\""], "unstable"),
    ],
)
def test_cli_guards_exit_2_in_one_line(tmp_path, sets, needle):
    args = [sys.executable, "-m", "gearwear.cli", "simulate", "paper-default", "--out", str(tmp_path / "o")]
    for s in sets:
        args += ["--set", s]
    r = subprocess.run(args, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert needle in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("name", ["root_crack", "spall", "tip_relief", "shifted_pair", "your_pair", "runup_backlash"])
@pytest.mark.parametrize("source", ["calibrated", "fem"])
def test_the_check_before_an_fe_stiffness_accepts_every_valid_example(name, source):
    """The solver check made before an FE stiffness (simulate_job.check_before_stiffness)
    accepts every valid example, including the fault scenes whose table spans a whole
    revolution (its stand-in table had nodes in 7 of 8 eighths of the revolution only, so
    `simulate examples/root_crack.toml --set effects.mesh_stiffness.source=fem` was refused
    for a table it had built itself), and the shifted pair whose driver has more teeth."""
    from pathlib import Path

    from gearwear.jobs.simulate import check_before_stiffness
    from gearwear.scene.model import Scene

    path = Path(__file__).resolve().parents[1] / "examples" / f"{name}.toml"
    check_before_stiffness(Scene.load(str(path), {"effects.mesh_stiffness.source": source}))
