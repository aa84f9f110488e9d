"""gearwear runup and the Dask executor: outputs, contracts and a real LocalCluster.

The physics of the run-up (continuation, steady-state detection, linear modes, the jump)
is tested on the dynamics layer in tests/test_steady.py; here the command that wraps it:
the files it writes (byte-identical on repeat), the jump-band bookkeeping, the ISO 6336
curve's inputs, one-line errors, and the same bytes whether the tasks run on local
processes or on a Dask cluster listening on 127.0.0.1.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
from pathlib import Path

import pytest

from gearwear import io
from gearwear.cli import main

SPEEDS = ["--set", "operating.speed_rpm=1900:2200:4"]
FAST = ["--keep-periods", "8", "--tolerance", "1e-7"]


def snapshot(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != io.TIMING
    }


def test_runup_writes_its_files_the_same_bytes_twice(tmp_path, capsys):
    for k in ("a", "b"):
        assert main(["runup", "paper-default", *SPEEDS, *FAST, "--workers", "1", "--out", str(tmp_path / k)]) == 0
    a, b = snapshot(tmp_path / "a"), snapshot(tmp_path / "b")
    assert set(a) == {
        "runup.csv",
        "runup.csv.json",
        "runup_summary.json",
        "kv.png",
        "order_map_up.png",
        "order_map_down.png",
        "campbell_up.png",
        "campbell_down.png",
        "manifest.json",
    }
    assert a == b
    m = json.loads(a["manifest.json"])
    for name, entry in m["files"].items():
        assert entry["sha256"] == hashlib.sha256(a[name]).hexdigest()
    rows = list(csv.DictReader(a["runup.csv"].decode().splitlines()))
    assert [r["direction"] for r in rows] == ["up"] * 4 + ["down"] * 4
    assert [float(r["speed_rpm"]) for r in rows[:4]] == [1900, 2000, 2100, 2200]
    for r in rows:
        assert r["label"] == "periodic" and r["period_mesh_periods"] == "1"
        assert float(r["residual"]) < 1e-7
        assert float(r["K_v"]) > 1 and float(r["K_v_iso6336"]) > 1
        # K_v is max F_m over the static normal force T / r_b1 (40 N m / 70.477 mm)
        assert float(r["F_m_max_N"]) / float(r["K_v"]) == pytest.approx(
            40 / (0.075 * math.cos(math.radians(20))), rel=1e-6
        )
    for k in ("wall_s", "integration_wall_s"):
        assert k.encode() not in a["runup.csv"] and k.encode() not in a["runup_summary.json"]
    s = json.loads(a["runup_summary.json"])
    pt = s["points"][0]
    assert pt["jump_bands_rpm"] == []  # no backlash: one response, whatever the direction
    # ISO's resonance speed is the rigid-bearing torsional frequency of the tool's own mean
    # stiffness and m_e: n_E1 = 60 sqrt(k / m_e) / (2 pi z1)
    inp = pt["iso6336"]["inputs"]
    k = inp["c_gamma_N_per_mm_um"] * 20 * 1e6
    m_e = inp["m_red_kg_per_mm"] * 20
    assert pt["iso6336"]["n_E1_rpm"] == pytest.approx(60 * math.sqrt(k / m_e) / (2 * math.pi * 30), rel=1e-12)
    assert m_e == pytest.approx(0.5 * 3.75 * 0.075**2 / (2 * (0.075 * math.cos(math.radians(20))) ** 2), rel=1e-12)
    assert (inp["f_pb_um"], inp["f_f_um"]) == (pytest.approx(10.0 * math.cos(math.radians(20)), abs=1e-3), 12.0)
    assert pt["mode_speeds_rpm"]["k1"][0] == pytest.approx(60 * pt["linear_eigenfrequencies_Hz"][0] / 30)


def test_jump_bands_by_hand():
    from gearwear.jobs.runup import jump_bands

    up = [{"speed_rpm": v, "K_v": k} for v, k in zip((1, 2, 3, 4, 5, 6), (1.0, 1.0, 2.0, 2.0, 1.0, 3.0))]
    down = [{"speed_rpm": v, "K_v": k} for v, k in zip((6, 5, 4, 3, 2, 1), (3.0, 1.5, 2.0, 1.0, 1.0, 1.005))]
    assert jump_bands(up, down, 0.01) == [[3, 3], [5, 5]]
    assert jump_bands(up, down, 0.001) == [[1, 1], [3, 3], [5, 5]]


def test_iso_table_changes_the_iso_curve_only(tmp_path):
    for extra in ([], ["--set", "iso6336={accuracy_grade=8, C_a_um=3}"]):
        assert (
            main(
                [
                    "runup",
                    "paper-default",
                    "--set",
                    "operating.speed_rpm=1900,2000",
                    *FAST,
                    "--direction",
                    "up",
                    "--workers",
                    "1",
                    "--json",
                ]
            )
            == 0
            if not extra
            else main(
                [
                    "runup",
                    "paper-default",
                    "--set",
                    "operating.speed_rpm=1900,2000",
                    *FAST,
                    "--direction",
                    "up",
                    "--workers",
                    "1",
                    "--out",
                    str(tmp_path / "iso"),
                    *extra,
                ]
            )
            == 0
        )
    rows = list(csv.DictReader((tmp_path / "iso" / "runup.csv").read_text().splitlines()))
    s = json.loads((tmp_path / "iso" / "runup_summary.json").read_text())["points"][0]["iso6336"]["inputs"]
    assert s["accuracy_grade"] == 8 and s["C_a_um"] == 3
    assert s["f_pb_um"] == pytest.approx(20.0 * math.cos(math.radians(20)), abs=1e-3)  # grade 8 = 2 x grade 6
    assert all(float(r["K_v_iso6336"]) > 1 for r in rows)


BAD = [
    (["runup", "paper-default", "--set", "operating.torque_Nm=5,20"], "operating.speed_rpm"),
    (["runup", "paper-default", "--set", "operating.speed_rpm=1000,-3"], "operating.speed_rpm"),
    (["runup", "paper-default", "--set", "operating.speed_rpm=1000"], "--set"),
    (["runup", "paper-default", "--set", "operating.speed_rpm=1000:2000:3", "--direction", "sideways"], "--direction"),
    (["runup", "paper-default", "--set", "operating.speed_rpm=1000:2000:3", "--tolerance", "0"], "--tolerance"),
    (["runup", "paper-default", "--set", "operating.speed_rpm=1000:2000:3", "--max-periods", "x"], "--max-periods"),
    (["runup", "paper-default", "--set", "operating.speed_rpm=1000:2000:3", "--scheduler", "local:0"], "--scheduler"),
    (
        ["runup", "paper-default", "--set", "operating.speed_rpm=1000:2000:3", "--set", "iso6336.C_a_um=-1"],
        "iso6336.C_a_um",
    ),
    (
        ["runup", "paper-default", "--set", "operating.speed_rpm=1000:2000:3", "--set", "operating.torque_Nm=0"],
        "operating.torque_Nm",
    ),
    (["sweep", "paper-default", "--set", "operating.torque_Nm=5,20", "--scheduler", "local:x"], "--scheduler"),
]


@pytest.mark.parametrize("argv,key", BAD, ids=[f"{i}-{b[1]}" for i, b in enumerate(BAD)])
def test_bad_input_one_line_exit_2_nothing_written(argv, key, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    try:
        rc = main([*argv, "--out", "o"])
    except SystemExit as exc:  # argparse mistakes exit from inside the parser
        rc = exc.code
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("gearwear: error: ") and key in lines[0], err
    assert not any(tmp_path.iterdir())


# -- Dask for real ------------------------------------------------------------------------------


def test_dask_local_cluster_gives_the_bytes_of_the_local_processes(tmp_path):
    """A LocalCluster on the loopback interface (two worker processes, as --scheduler
    local:2 starts it), reached by its address: a sweep and a run-up through it write the
    same bytes as the local process pool, and an FE calibration's runs (the pair FE
    positions in chunks, the single-tooth FE; each worker builds its own gear bodies) give
    every array of the run in this process to the bit."""
    import logging

    import numpy as np
    from dask.distributed import Client, LocalCluster

    from gearwear.fem.pair import pair_contact
    from gearwear.geometry.spec import default_pair
    from gearwear.jobs.sweep import DaskExecutor, make_executor
    from gearwear.stiffness import calibration as calibrate

    sweep = [
        "sweep",
        "paper-default",
        "--set",
        "operating.torque_Nm=20,30,40",
        "--set",
        "solver.duration_s=0.04",
        "--set",
        "solver.discard_s=0.02",
    ]
    runup = ["runup", "paper-default", "--set", "operating.speed_rpm=1900,2100", *FAST]
    with LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=logging.ERROR,
    ) as cluster:
        addr = cluster.scheduler_address
        assert addr.startswith("tcp://127.0.0.1:")
        for name, argv in (("sweep", sweep), ("runup", runup)):
            assert main([*argv, "--scheduler", addr, "--out", str(tmp_path / f"{name}_dask")]) == 0
            assert main([*argv, "--workers", "2", "--out", str(tmp_path / f"{name}_local")]) == 0
            assert snapshot(tmp_path / f"{name}_dask") == snapshot(tmp_path / f"{name}_local")
        ex = DaskExecutor(Client(addr))
        try:
            fe = {"positions": 8, "extended": False, "contact_scale": 2.0, "mesh_scale": 1.5}
            on_dask = pair_contact(default_pair(), executor=ex, chunk_positions=3, **fe)
            cal_dask = calibrate.run_fe(default_pair(), None, positions=9, estimate_error=False, executor=ex)
        finally:
            ex.shutdown()
        here = pair_contact(default_pair(), **fe)
        for key in ("k_N_per_m", "k_tangent_N_per_m", "ste_m", "excitation_m", "pair_load_N", "half_width_m"):
            assert getattr(on_dask, key).tobytes() == getattr(here, key).tobytes(), key
        cal_here = calibrate.run_fe(default_pair(), None, positions=9, estimate_error=False)
        for a, b in zip(cal_dask.fe, cal_here.fe):
            assert a.fem_compliance_um_per_N_per_mm.tobytes() == b.fem_compliance_um_per_N_per_mm.tobytes()
        assert np.array_equal(cal_dask.corrections[0].coeffs, cal_here.corrections[0].coeffs)
    ex = make_executor(scheduler="local:1")  # the factory's own LocalCluster: a plain Executor
    try:
        assert isinstance(ex, DaskExecutor)
        assert ex.submit(math.hypot, 3.0, 4.0).result() == 5.0
        assert ex.cluster is not None and ex.cluster.scheduler_address.startswith("tcp://127.0.0.1:")
    finally:
        ex.shutdown()
    assert ex.client.status == "closed"


def test_iso_curve_takes_the_gear_with_fewer_teeth_as_gear_1():
    """ISO 6336's gear 1 has fewer teeth whichever drives: a run-up of a pair whose driver has
    47 teeth (driven: 23) gives the ISO K_v curve of the exchanged pair (driver 23 teeth) at
    the corresponding speeds n_23 = n_47 47 / 23 and torque T 23 / 47, exactly. n_E1 is a speed
    of the 23-tooth gear, 30000 / (pi 23) sqrt(c_gamma / m_red) with c_gamma = k / b and
    m_red = m_e / b (here k = 4e8 N/m, m_e = 1 kg, b = 20 mm: sqrt(20 / 0.05) = 20), and the
    deviations are the larger gear's (grade 6 at d = 235 mm: f_pt = 10 um, f_pb = 9.397 um)."""
    import copy

    import numpy as np

    from gearwear.jobs import runup as runup_job
    from gearwear.scene.files import load_scene_dict
    from gearwear.scene.model import scene_from_dict

    data, _ = load_scene_dict("paper-default")
    big_drives, small_drives = copy.deepcopy(data), copy.deepcopy(data)
    big_drives["pair"].update(teeth=[47, 23], profile_shift=[0.1, 0.3], hub_radius_mm=[40.0, 30.0])
    small_drives["pair"].update(teeth=[23, 47], profile_shift=[0.3, 0.1], hub_radius_mm=[30.0, 40.0])
    small_drives["operating"]["torque_Nm"] = data["operating"]["torque_Nm"] * (23 / 47)
    n = np.array([1000.0, 3000.0, 6000.0, 9000.0, 12000.0])
    a = runup_job.iso_curve(scene_from_dict(big_drives, "a"), 4e8, 1.0, n)
    b = runup_job.iso_curve(scene_from_dict(small_drives, "b"), 4e8, 1.0, n * (47 / 23))
    assert a["K_v"] == b["K_v"] and a["inputs"] == b["inputs"] and a["n_E1_rpm"] == b["n_E1_rpm"]
    assert a["range"] == ["subcritical", "main resonance", "intermediate", "supercritical", "supercritical"]
    assert a["inputs"]["z1"] == 23
    assert a["n_E1_rpm"] == pytest.approx(30000 / (math.pi * 23) * 20, rel=1e-12)
    assert a["n_E1_driver_rpm"] == pytest.approx(a["n_E1_rpm"] * 23 / 47, rel=1e-15)
    assert a["inputs"]["f_pb_um"] == pytest.approx(10 * math.cos(math.radians(20)), abs=1e-3)
