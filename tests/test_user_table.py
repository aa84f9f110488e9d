"""A user stiffness table (examples/user_table: a smooth closed-form k and e sampled at
4096 rows, explicit inertias and damping coefficients) drives the scene; its mesh
harmonics must equal an independent solution of the same model with the closed-form
k(t), e(t) (paper Eqs. 17-20 written out here, scipy DOP853 at rtol 1e-11)."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gearwear.core.validation import InputError
from gearwear.jobs import simulate as simulate_job
from gearwear.scene.files import load_scene_dict
from gearwear.scene.model import scene_from_dict
from gearwear.scene.overrides import apply_overrides

from scenes import with_paper

EX = Path(__file__).resolve().parents[1] / "examples" / "user_table"
sys.path.insert(0, str(EX))
from make_table import PERIOD_DEG, e_closed_um, k_closed  # noqa: E402

SHORT = ["solver.duration_s=0.4", "solver.discard_s=0.3"]


def _scene(*sets):
    data, name = load_scene_dict(EX / "scene.toml")
    return scene_from_dict(apply_overrides(data, [*SHORT, *sets]), name=name)


@pytest.fixture(scope="module")
def reference():
    """Independent reference: 5-DOF model of the paper pair written out by hand."""
    z, m_mm, a0 = 30, 5.0, math.radians(20.0)
    Rb = 0.5 * m_mm * 1e-3 * z * math.cos(a0)  # base radius, both gears
    alpha = a0  # standard pair at nominal centre distance
    m, kb, cb, ch = 3.75, 2.6e8, 1250.0, 2500.0
    Jp, Jg = 0.0105, 0.0125
    me = 1.0 / (Rb**2 / Jp + Rb**2 / Jg)
    Fs = 40.0 / Rb
    om = 1200 * 2 * math.pi / 60
    fm = z * om / (2 * math.pi)
    ca, sa = math.cos(alpha), math.sin(alpha)

    def ke(t):
        u = (om * t / math.radians(PERIOD_DEG)) % 1.0
        return k_closed(u), 1e-6 * e_closed_um(u)

    def rhs(t, y):
        yp, xp, yg, xg, q, vyp, vxp, vyg, vxg, vq = y
        d = q + (xp - xg) * sa + (yp - yg) * ca
        dd = vq + (vxp - vxg) * sa + (vyp - vyg) * ca
        k, e = ke(t)
        F = ch * dd + k * (d - e)
        return [
            vyp,
            vxp,
            vyg,
            vxg,
            vq,
            (-F * ca - cb * vyp - kb * yp) / m,
            (-F * sa - cb * vxp - kb * xp) / m,
            (F * ca - cb * vyg - kb * yg) / m,
            (F * sa - cb * vxg - kb * xg) / m,
            (Fs - F) / me,
        ]

    y0 = np.zeros(10)
    y0[4] = Fs / 3.5e8
    t0, M = 0.3, 60
    sol = solve_ivp(rhs, (0.0, t0 + M / fm), y0, method="DOP853", rtol=1e-11, atol=1e-16, dense_output=True)
    S = 2048
    t = t0 + np.arange(M * S) / (S * fm)
    Y = sol.sol(t)
    d = Y[4] + (Y[1] - Y[3]) * sa + (Y[0] - Y[2]) * ca
    dd = Y[9] + (Y[6] - Y[8]) * sa + (Y[5] - Y[7]) * ca
    k, e = ke(t)
    F = ch * dd + k * (d - e)
    kk = np.arange(1, 11)[:, None]
    ph = np.exp(-2j * np.pi * fm * kk * t[None, :])
    return {name: 2 * np.abs(ph @ x) / x.size for name, x in (("F_m", F), ("delta", d))}


def _worst(run, ref):
    h = run.result.harmonics_of(["F_m", "delta"])
    worst = 0.0
    for name in ("F_m", "delta"):
        big = ref[name].max()
        keep = ref[name] > 0.01 * big
        worst = max(worst, float(np.max(np.abs(h[name][keep] - ref[name][keep]) / ref[name][keep])))
    return worst


def test_user_table_default_rk4_matches_independent_reference(reference):
    run = simulate_job.run(_scene())
    assert run.result.method == "rk4" and run.stiffness.source == "table"
    assert run.model.J_p == 0.0105 and run.model.c_h == 2500.0 and run.model.c_b == (1250.0, 1250.0)
    assert _worst(run, reference) < 1e-3


def test_user_table_cubic_tight_settings_match_to_1e6(reference):
    """The same 4096-row table read as a periodic cubic spline (interpolation = "cubic"),
    RK4 at 1024 steps per period: the spline holds the smooth closed form to ~1e-13, so
    what remains is the solver's error."""
    run = simulate_job.run(_scene('effects.mesh_stiffness.interpolation="cubic"', "solver.steps_per_mesh_period=1024"))
    assert run.model.interpolation == "cubic"
    assert _worst(run, reference) < 1e-6


def test_user_table_tight_settings_match_to_1e6(reference, tmp_path):
    """Tight settings: RK4 at 1024 steps per period on a 16384-row table of the same closed
    form. The table resolution is part of the setting: the solver integrates the rows'
    linear interpolant, which scales a harmonic n of the closed form by sinc^2(n / rows)
    (1 - n^2 2e-7 at 4096 rows: 2.9e-6 on the response harmonics 3-10, whatever the
    solver; 1.2e-8 n^2 at 16384 rows)."""
    u = np.arange(16384) / 16384
    rows = np.column_stack([u * PERIOD_DEG, k_closed(u), e_closed_um(u)])
    np.savetxt(
        tmp_path / "k.csv", rows, delimiter=",", header="angle_deg,k_N_per_m,excitation_um", comments="", fmt="%.15g"
    )
    data, name = load_scene_dict(EX / "scene.toml")
    data["effects"]["mesh_stiffness"]["path"] = str(tmp_path / "k.csv")
    sc = scene_from_dict(apply_overrides(data, [*SHORT, "solver.steps_per_mesh_period=1024"]), name=name)
    assert _worst(simulate_job.run(sc), reference) < 1e-6


@pytest.mark.parametrize(
    "csv, needle",
    [
        ("angle_deg,k_N_per_m\n" + "".join(f"{a},{3e8}\n" for a in (0, 2, 1, 3, 4, 5, 6, 7)), "strictly increasing"),
        ("angle_deg,k_N_per_m\n" + "".join(f"{a},{3e8}\n" for a in range(7)), ">= 8"),
        ("angle_deg,k_N_per_m\n" + "".join(f"{a},{'nan' if a == 3 else 3e8}\n" for a in range(8)), "finite"),
        ("angle_deg,k_N_per_m\n" + "".join(f"{a},{-1 if a == 3 else 3e8}\n" for a in range(8)), ">= 0"),
        ("angle_deg,k_N_per_m\n" + "".join(f"{a * 0.5},{3e8}\n" for a in range(8)), "cover one mesh period"),
        ("angle_deg,k_N_per_m\n" + "".join(f"{a * 1.5},{3e8}\n" for a in range(9)), "[0, 12)"),
        ("angle,k\n" + "".join(f"{a},{3e8}\n" for a in range(8)), "header"),
        ("angle_deg,k_N_per_m\n" + "".join(f"{a},x\n" for a in range(8)), "non-numeric"),
    ],
)
def test_bad_tables_get_one_line(tmp_path, csv, needle):
    (tmp_path / "k.csv").write_text(csv)
    doc = {"effects": {"mesh_stiffness": {"source": "table", "path": str(tmp_path / "k.csv")}}}
    with pytest.raises(InputError) as exc:
        scene_from_dict(with_paper(doc))
    msg = str(exc.value)
    assert needle in msg and "effects.mesh_stiffness.path" in msg and "\n" not in msg


def test_relative_path_is_from_the_scene_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # not the scene's folder
    sc = _scene()
    assert sc.effects["mesh_stiffness"]["k_N_per_m"].size == 4096


def test_damping_given_twice_and_ignored_options_are_errors():
    with pytest.raises(InputError, match="not both"):
        _scene("bodies.mesh_damping_ratio=0.05")
    with pytest.raises(InputError, match="not both"):
        _scene("bodies.bearing_damping_ratio=0.02")
    with pytest.raises(InputError, match="effects.wear"):
        _scene('effects.wear={phase="severe"}')
    with pytest.raises(InputError, match="value_N_per_m"):
        scene_from_dict(with_paper({"effects": {"mesh_stiffness": {"source": "analytic", "value_N_per_m": 3e8}}}))


@pytest.mark.parametrize("method", ["ishikawa", "fem"])
def test_the_tools_own_stiffness_csv_is_a_user_table(tmp_path, method):
    """Round trip (issue 24): a stiffness CSV written by `gearwear stiffness` is accepted back as a
    user table (its other columns are read, not used), and the simulation of the table equals
    the simulation of the analytic source it came from at the table's nodes (same k_h and e)."""
    import subprocess
    import sys

    import numpy as np

    from gearwear.scene.files import read_stiffness_table

    out = tmp_path / "st"
    points = "24" if method == "fem" else "90"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "gearwear.cli",
            "stiffness",
            "paper-wear-severe",
            "--method",
            method,
            "--points",
            points,
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    csv = next(out.glob("stiffness_*.csv"))
    ang, k, e = read_stiffness_table(csv, 30)
    raw = np.genfromtxt(csv, delimiter=",", names=True)
    assert np.array_equal(k, raw["k_N_per_m"]) and np.allclose(e * 1e6, raw["excitation_um"], rtol=1e-14, atol=0)
    doc = with_paper({"effects": {"mesh_stiffness": {"source": "table", "path": str(csv)}, "transmission_error": {}}})
    sc = scene_from_dict(doc)
    # every row of the file is a node of the table (the analytic CSV holds its breakpoints too)
    assert sc.effects["mesh_stiffness"]["k_N_per_m"].size == raw.size
