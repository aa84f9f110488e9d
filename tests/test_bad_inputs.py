"""Every bad input, on every command: one line naming the key and its value, exit 2, nothing written.

The contract (README, "Bad input"): ``gearwear: error: <key> = <value> <unit>: <allowed range or
reason>`` on stderr, exit status 2, and no file created anywhere (not in ``--out``, not in the
working folder, not in the table cache). Each row of ``CASES`` is one input a new user could
plausibly type, across all commands; the key and the value it must name are written out by
hand, from the scene reference (docs/scene-reference.md) and ``--help``, not read from the code.

The commands run in-process (``gearwear.cli.app.main``), which is what the console script calls;
an exception other than the one-line error would propagate here and fail the test. One test
runs the real console script to check that no traceback reaches the terminal.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from gearwear.cli import main

# A pair whose contact ratio is about 2.2: the zone statistics have no single-contact zone.
HIGH_CONTACT_RATIO = [
    "--set",
    "pair.teeth=[60,60]",
    "--set",
    "pair.pressure_angle_deg=14.5",
    "--set",
    "pair.addendum_coefficient=1.4",
    "--set",
    "pair.dedendum_coefficient=1.7",
    "--set",
    "pair.rack_tip_radius_coefficient=0.1",
    "--set",
    "pair.allow_undercut=true",
]


def _files(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*") if p.is_file())


def _setup(tmp: Path) -> None:
    """Files that some rows refer to (made before the run, so they are not counted as output)."""
    (tmp / "a_file.txt").write_text("not a folder\n")
    (tmp / "folder.toml").mkdir()
    (tmp / "latin1.toml").write_bytes(b"name = \"\xe9t\xe9\"\n")
    (tmp / "broken.toml").write_text("[pair\nteeth = [30, 30]\n")
    (tmp / "unknown_key.toml").write_text("[pair]\nteth = [30, 30]\n")
    (tmp / "string_number.toml").write_text("[operating]\nspeed_rpm = \"1200\"\n")
    (tmp / "garbage_table.csv").write_text("angle_deg,k_N_per_m\n0,4e8\nzero,abc\n")
    (tmp / "short_table.csv").write_text("angle_deg,k_N_per_m\n0,4e8\n")
    (tmp / "negative_table.csv").write_text(
        "angle_deg,k_N_per_m\n" + "".join(f"{a},{-1e8 if a == 5 else 4e8:g}\n" for a in range(12))
    )
    for name in ("garbage_table", "short_table", "negative_table", "missing_table"):
        (tmp / f"{name}.toml").write_text(
            f'extends = "paper-default"\n[effects]\nmesh_stiffness = {{ source = "table", path = "{name}.csv" }}\n'
        )
    (tmp / "wear_on_table.toml").write_text(
        'extends = "paper-default"\n[effects]\nmesh_stiffness = { source = "table", path = "short_table.csv" }\n'
        'wear = "severe"\n'
    )
    (tmp / "foreign_out").mkdir()
    (tmp / "foreign_out" / "my_notes.txt").write_text("keep me\n")
    (tmp / "cache_is_a_file").write_text("x\n")
    (tmp / "all_zero.csv").write_text("signal,harmonic,amplitude\nF_m_N,1,0\nF_m_N,2,0\n")
    (tmp / "diag.toml").write_text((Path(__file__).parents[1] / "examples" / "diagnose" / "scene.toml").read_text())
    (tmp / "huge_harmonics.csv").write_text("signal,harmonic,amplitude\nF_m_N,1,1e300\nF_m_N,2,3.5\n")
    (tmp / "huge_series.csv").write_text("time_s,y_p_um\n0,1\n0.001,-2e6\n0.002,1\n")
    (tmp / "user_manifest_out").mkdir()
    (tmp / "user_manifest_out" / "manifest.json").write_text('{"name": "my project", "files": ["a.txt"]}\n')


S = "--set"
# (id, argv, key the line must name, value it must name, environment overrides)
CASES: list[tuple[str, list[str], str, str | None, dict[str, str]]] = [
    # ---- scene files and the scene argument
    ("scene-missing", ["simulate", "no_such_scene.toml"], "no_such_scene.toml", None, {}),
    ("scene-unknown-builtin", ["simulate", "paper-defualt"], "paper-defualt", None, {}),
    ("scene-is-folder", ["geometry", "folder.toml"], "folder.toml", None, {}),
    ("scene-not-utf8", ["geometry", "latin1.toml"], "latin1.toml", None, {}),
    ("scene-toml-syntax", ["geometry", "broken.toml"], "broken.toml", None, {}),
    ("scene-unknown-key", ["geometry", "unknown_key.toml"], "pair.teth", "pair.teeth", {}),
    ("scene-string-for-number", ["simulate", "string_number.toml"], "operating.speed_rpm", "1200", {}),
    # ---- --set syntax and types
    ("set-no-equals", ["geometry", S, "pair.teeth"], "pair.teeth", None, {}),
    ("set-unknown-section", ["geometry", S, "gear.teeth=[30,30]"], "gear", None, {}),
    ("set-unknown-key", ["simulate", S, "operating.speed=1200"], "operating.speed", "speed_rpm", {}),
    ("set-bool-as-number", ["geometry", S, "pair.allow_undercut=2"], "pair.allow_undercut", "2", {}),
    ("set-list-length", ["geometry", S, "pair.teeth=[30,30,30]"], "pair.teeth", None, {}),
    # a newline would inject TOML tables; a key given twice would leave which value wins to a guess
    ("set-newline-table", ["scene", S, "pair.teeth=[30,30]\n[x]"], "--set", "pair.teeth", {}),
    (
        "set-newline-key",
        ["geometry", S, "operating.speed_rpm=1200\n[operating]\nspeed_rpm=99"],
        "--set",
        "operating.speed_rpm",
        {},
    ),
    (
        "set-repeated-sweep-key",
        ["sweep", S, "operating.speed_rpm=1000,1200", S, "operating.speed_rpm=1300"],
        "--set operating.speed_rpm",
        "given twice",
        {},
    ),
    (
        "set-repeated-by-flag",
        ["simulate", "--torque-Nm", "30", S, "operating.torque_Nm=40"],
        "--set operating.torque_Nm",
        "given twice",
        {},
    ),
    # ---- pair keys, one at a time
    ("teeth-too-few", ["geometry", S, "pair.teeth=[4,30]"], "pair.teeth[0]", "4", {}),
    ("teeth-fraction", ["geometry", S, "pair.teeth=[30.5,30]"], "pair.teeth[0]", "30.5", {}),
    ("module-zero", ["geometry", S, "pair.module_mm=0"], "pair.module_mm", "0", {}),
    ("module-negative", ["geometry", S, "pair.module_mm=-5"], "pair.module_mm", "-5", {}),
    ("module-nan", ["geometry", S, "pair.module_mm=nan"], "pair.module_mm", "nan", {}),
    ("pressure-angle-high", ["geometry", S, "pair.pressure_angle_deg=50"], "pair.pressure_angle_deg", "50", {}),
    ("face-width-inf", ["geometry", S, "pair.face_width_mm=inf"], "pair.face_width_mm", "inf", {}),
    ("shift-too-large", ["geometry", S, "pair.profile_shift=[3,0]"], "pair.profile_shift[0]", "3", {}),
    ("hub-above-root", ["geometry", S, "pair.hub_radius_mm=[80,40]"], "pair.hub_radius_mm[0]", "80", {}),
    (
        "dedendum-below-addendum",
        ["geometry", S, "pair.dedendum_coefficient=0.9"],
        "pair.dedendum_coefficient",
        "0.9",
        {},
    ),
    (
        "rack-round-too-big",
        ["geometry", S, "pair.rack_tip_radius_coefficient=0.9"],
        "pair.rack_tip_radius_coefficient",
        "0.9",
        {},
    ),
    (
        "pointed-tooth",
        ["geometry", S, "pair.teeth=[8,30]", S, "pair.profile_shift=[2,0]", S, "pair.hub_radius_mm=[5,40]"],
        "pair.profile_shift[0]",
        "2",
        {},
    ),
    (
        "tip-inside-base",
        [
            "geometry",
            S,
            "pair.teeth=[8,30]",
            S,
            "pair.profile_shift=[-1.5,0]",
            S,
            "pair.allow_undercut=true",
            S,
            "pair.hub_radius_mm=[5,40]",
        ],
        "pair.profile_shift[0]",
        "-1.5",
        {},
    ),
    (
        "undercut-not-allowed",
        ["geometry", S, "pair.teeth=[12,30]", S, "pair.hub_radius_mm=[10,40]"],
        "pair.teeth[0]",
        "12",
        {},
    ),
    (
        "tip-root-interference",
        ["stiffness", S, "pair.teeth=[5,5]", S, "pair.allow_undercut=true", S, "pair.hub_radius_mm=[3,3]"],
        "pair.",
        None,
        {},
    ),
    ("youngs-modulus-zero", ["geometry", S, "material.youngs_modulus_GPa=0"], "material.youngs_modulus_GPa", "0", {}),
    ("poisson-half", ["geometry", S, "material.poisson_ratio=0.5"], "material.poisson_ratio", "0.5", {}),
    # ---- wear
    ("wear-unknown-phase", ["geometry", "--wear", "worn-out"], "--wear", "worn-out", {}),
    ("wear-negative-depth", ["geometry", "--wear=-5um"], "--wear", "-5", {}),
    ("wear-deeper-than-tooth", ["stiffness", "--wear", "5000um"], "--wear", "5000", {}),
    (
        "wear-unknown-model",
        ["geometry", S, 'effects.wear={hours=500, model="magic"}'],
        "effects.wear.model",
        "magic",
        {},
    ),
    ("wear-negative-hours", ["geometry", "--wear=-10h"], "--wear", "-10", {}),
    # ---- operating point and the short aliases
    ("torque-huge", ["simulate", "--torque-Nm", "1e12"], "--torque-Nm", "1e+12", {}),
    ("torque-text", ["simulate", "--torque-Nm", "forty"], "--torque-Nm", "forty", {}),
    ("torque-zero-loaded", ["stiffness", "--torque-Nm", "0"], "--torque-Nm", "0", {}),
    ("speed-negative", ["simulate", S, "operating.speed_rpm=-100"], "operating.speed_rpm", "-100", {}),
    ("speed-absurd", ["simulate", S, "operating.speed_rpm=1e9"], "operating.speed_rpm", "1e+09", {}),
    ("clearance-negative", ["geometry", "--clearance-um", "-5"], "--clearance-um", "-5", {}),
    ("clearance-multi-one-bad", ["stiffness", "--clearance-um", "0", "-10"], "--clearance-um", "-10", {}),
    ("backlash-negative", ["simulate", S, "effects.backlash.initial_um=-1"], "effects.backlash.initial_um", "-1", {}),
    # ---- bodies
    ("mass-zero", ["simulate", S, "bodies.mass_kg=[0,3.75]"], "bodies.mass_kg[0]", "0", {}),
    (
        "bearing-stiffness-zero",
        ["simulate", S, "bodies.bearing_stiffness_N_per_m=0"],
        "bodies.bearing_stiffness_N_per_m",
        "0",
        {},
    ),
    ("damping-ratio-above-one", ["simulate", S, "bodies.mesh_damping_ratio=2"], "bodies.mesh_damping_ratio", "2", {}),
    (
        "damping-both-forms",
        ["simulate", S, "bodies.mesh_damping_ratio=0.05", S, "bodies.mesh_damping_N_s_per_m=2500"],
        "bodies.mesh_damping",
        None,
        {},
    ),
    # ---- solver
    ("solver-unknown-method", ["simulate", S, "solver.method=euler"], "solver.method", "euler", {}),
    ("solver-few-steps", ["simulate", S, "solver.steps_per_mesh_period=3"], "solver.steps_per_mesh_period", "3", {}),
    ("solver-zero-duration", ["simulate", S, "solver.duration_s=0"], "solver.duration_s", "0", {}),
    ("solver-rtol-one", ["simulate", S, "solver.method=dopri5", S, "solver.rtol=1"], "solver.rtol", "1", {}),
    (
        "solver-rk4-unstable",
        ["simulate", S, "operating.speed_rpm=20000", S, "solver.steps_per_mesh_period=8"],
        "solver.steps_per_mesh_period",
        "8",
        {},
    ),
    ("solver-output-too-large", ["simulate", S, "solver.duration_s=1000"], "solver.duration_s", "1000", {}),
    # ---- mesh-stiffness sources
    ("table-missing", ["simulate", "missing_table.toml"], "effects.mesh_stiffness.path", "missing_table.csv", {}),
    ("table-garbage", ["simulate", "garbage_table.toml"], "garbage_table.csv", None, {}),
    ("table-too-short", ["simulate", "short_table.toml"], "short_table.csv", None, {}),
    ("table-negative-k", ["simulate", "negative_table.toml"], "k_N_per_m", "-1e+08", {}),
    ("wear-on-user-table", ["simulate", "wear_on_table.toml"], "effects.wear", None, {}),
    (
        "constant-value-wrong-source",
        ["simulate", S, "effects.mesh_stiffness.value_N_per_m=4e8"],
        "effects.mesh_stiffness.value_N_per_m",
        None,
        {},
    ),
    # ---- command flags
    ("stiffness-method", ["stiffness", "--method", "magic"], "--method", "magic", {}),
    ("stiffness-points-few", ["stiffness", "--points", "3"], "--points", "3", {}),
    ("stiffness-points-text", ["stiffness", "--points", "many"], "--points", "many", {}),
    ("stiffness-fields-without-fem", ["stiffness", "--fields", "2", "--out", "o"], "--fields", "2", {}),
    (
        "stiffness-fields-out-of-range",
        ["stiffness", "--method", "fem", "--points", "8", "--fields", "9", "--out", "o"],
        "--fields",
        "9",
        {},
    ),
    ("geometry-mesh-size-small", ["geometry", "--mesh-size-mm", "0.1", "--out", "o"], "--mesh-size-mm", "0.1", {}),
    ("geometry-mesh-size-text", ["geometry", "--mesh-size-mm", "fine"], "--mesh-size-mm", "fine", {}),
    ("verify-positions-few", ["verify", "--positions", "2"], "--positions", "2", {}),
    ("verify-positions-many", ["verify", "--positions", "1000"], "--positions", "1000", {}),
    ("verify-bad-wear", ["verify", "--wear", "unworn", "25xx"], "--wear", "25xx", {}),
    (
        "fem-contact-ratio-below-one",
        ["stiffness", "--method", "fem", "--points", "8", "--clearance-um", "5000"],
        "--method",
        "'fem'",
        {},
    ),
    (
        "iso-contact-ratio-below-one",
        ["stiffness", "--method", "iso6336", "--clearance-um", "5000"],
        "--method",
        "'iso6336'",
        {},
    ),
    (
        "calibrate-contact-ratio-below-one",
        ["calibrate", "--points", "16", "--clearance-um", "0", "5000"],
        "--clearance-um",
        "5000",
        {},
    ),
    (
        "calibrated-source-contact-ratio-below-one",
        ["simulate", "--clearance-um", "5000", S, 'effects.mesh_stiffness={source="calibrated"}'],
        "effects.mesh_stiffness.source",
        "'calibrated'",
        {},
    ),
    ("calibrate-points-few", ["calibrate", "--points", "2"], "--points", "2", {}),
    (
        "calibrate-cache-is-file",
        ["calibrate", "--points", "16", "--wear", "unworn"],
        "GEARWEAR_CACHE",
        "cache_is_a_file",
        {"GEARWEAR_CACHE": "cache_is_a_file"},
    ),
    ("sweep-empty-list", ["sweep", S, "operating.speed_rpm=,"], "operating.speed_rpm", None, {}),
    ("sweep-zero-points", ["sweep", S, "operating.speed_rpm=1000:2000:0"], "operating.speed_rpm", "0", {}),
    ("sweep-bad-range", ["sweep", S, "operating.speed_rpm=1000:x:3"], "operating.speed_rpm", "x", {}),
    ("sweep-one-bad-value", ["sweep", S, "operating.speed_rpm=1200,-5"], "operating.speed_rpm", "-5", {}),
    ("sweep-nothing-swept", ["sweep", S, "operating.speed_rpm=1200"], "--set", None, {}),
    ("sweep-workers-zero", ["sweep", S, "operating.speed_rpm=1000,1200", "--workers", "0"], "--workers", "0", {}),
    ("calibrate-workers-zero", ["calibrate", "--refresh", "--workers", "0"], "--workers", "0", {}),
    ("scene-bad-set", ["scene", S, "pair.teeth=[1,2]"], "pair.teeth[0]", "1", {}),
    # ---- sizes and magnitudes, refused before any work (and before anything is cached)
    ("sweep-range-infinite", ["sweep", S, "operating.speed_rpm=inf:2000:2"], "operating.speed_rpm", "inf", {}),
    ("sweep-range-nan", ["sweep", S, "operating.speed_rpm=1000:nan:3"], "operating.speed_rpm", "nan", {}),
    ("sweep-too-many-points", ["sweep", S, "operating.speed_rpm=1000:2000:3000"], "--allow-large", "3000", {}),
    (
        "sweep-list-of-20000",
        ["sweep", S, "operating.speed_rpm=" + ",".join(f"{1000 + i / 100:g}" for i in range(20000))],
        "--allow-large",
        "20000",
        {},
    ),
    (
        "sweep-grid-too-large-even-allowed",
        ["sweep", S, "operating.speed_rpm=1000:2000:10000", S, "operating.torque_Nm=10:50:200", "--allow-large"],
        "--set",
        "2000000",
        {},
    ),
    ("runup-too-many-runs", ["runup", S, "operating.speed_rpm=1000:2000:1500"], "--allow-large", "3000", {}),
    (
        "mass-absurd-before-calibration",
        ["simulate", "paper-default", S, "bodies.mass_kg=1e-9", S, 'effects.mesh_stiffness.source="calibrated"'],
        "solver.steps_per_mesh_period",
        "256",
        {},
    ),
    # the same with dopri5 (paper-wear-severe has bearing clearance): refused by its step budget
    (
        "mass-absurd-before-calibration-dopri5",
        ["simulate", "paper-wear-severe", S, "bodies.mass_kg=1e-9", S, 'effects.mesh_stiffness.source="calibrated"'],
        "solver.duration_s",
        "0.5",
        {},
    ),
    ("measured-amplitude-absurd", ["diagnose", "--measured", "huge_harmonics.csv"], "--measured", "1e+300", {}),
    ("measured-sample-absurd", ["diagnose", "--measured", "huge_series.csv"], "--measured", "-2e+06", {}),
    # ---- flank modifications and faults (issue 13)
    (
        "relief-start-above-tip",
        ["stiffness", S, "flank.tip_relief={amount_um=5, start_diameter_mm=170}", "--out", "o"],
        "flank.tip_relief.start_diameter_mm[0]",
        "170",
        {},
    ),
    # a 1 mm relief on a module-1 tooth, thicker than the tooth's tip, was accepted
    (
        "relief-thicker-than-the-tip",
        [
            "stiffness",
            S,
            "pair.module_mm=1",
            S,
            "pair.hub_radius_mm=5",
            S,
            "flank.tip_relief={amount_um=1000, start_diameter_mm=31.5}",
        ],
        "flank.tip_relief.amount_um[0]",
        "1000",
        {},
    ),
    (
        "relief-shape",
        ["stiffness", S, 'flank.tip_relief={amount_um=5, start_diameter_mm=152, shape="cubic"}'],
        "flank.tip_relief.shape",
        "'cubic'",
        {},
    ),
    (
        "deviation-missing-file",
        ["stiffness", S, 'flank.deviation_csv=["nope.csv", ""]'],
        "flank.deviation_csv[0]",
        "nope.csv",
        {},
    ),
    ("crack-too-deep", ["simulate", S, "faults.crack={depth_mm=9}", "--out", "o"], "faults.crack.depth_mm", "9", {}),
    (
        "crack-too-deep-on-fem",
        ["stiffness", "--method", "fem", S, "faults.crack={depth_mm=9}", "--out", "o"],
        "faults.crack.depth_mm",
        "9",
        {},
    ),
    (
        "spall-tooth",
        ["stiffness", S, "faults.spall={tooth=30, start_diameter_mm=150, length_mm=1, depth_um=5}"],
        "faults.spall.tooth",
        "30",
        {},
    ),
    (
        "flank-on-constant-stiffness",
        [
            "simulate",
            "paper-default",
            S,
            "flank.tip_relief={amount_um=5, start_diameter_mm=152}",
            S,
            'effects.mesh_stiffness.source="constant"',
            "--out",
            "o",
        ],
        "[flank]",
        None,
        {},
    ),
    # ---- --out, checked before any work
    ("out-empty", ["geometry", "--no-mesh", "--out", ""], "--out", None, {}),
    ("out-is-file", ["simulate", "--out", "a_file.txt"], "--out", "a_file.txt", {}),
    ("out-under-file", ["stiffness", "--out", "a_file.txt/sub"], "--out", "a_file.txt/sub", {}),
    ("out-foreign-folder", ["geometry", "--no-mesh", "--out", "foreign_out"], "--out", "foreign_out", {}),
    (
        "out-users-manifest-json",
        ["geometry", "--no-mesh", "--out", "user_manifest_out"],
        "--out",
        "user_manifest_out",
        {},
    ),
    ("report-out-is-file", ["report", "paper", "--out", "a_file.txt"], "--out", "a_file.txt", {}),
    # ---- options that would do nothing, and a measurement with nothing in it (issue 25)
    ("scene-schema-with-set", ["scene", "--schema", S, "operating.speed_rpm=1"], "--set", None, {}),
    (
        "workers-with-scheduler",
        ["sweep", S, "operating.speed_rpm=1000,1200", "--workers", "2", "--scheduler", "local:1"],
        "--workers",
        "2",
        {},
    ),
    (
        "diagnose-torque-range-not-unknown",
        ["diagnose", "diag.toml", "--measured", "all_zero.csv", "--torque-range-Nm", "10:20"],
        "--torque-range-Nm",
        "10:20",
        {},
    ),
    (
        "diagnose-wear-range-not-unknown",
        ["diagnose", "diag.toml", "--unknowns", "clearance", "--measured", "all_zero.csv", "--wear-range-um", "0:20"],
        "--wear-range-um",
        "0:20",
        {},
    ),
    (
        "diagnose-all-zero-measurement",
        ["diagnose", "diag.toml", "--measured", "all_zero.csv"],
        "--measured",
        "every harmonic amplitude is 0",
        {},
    ),
    # ---- found by a fuzz of every key's edges: our bug (exit 1) or a message naming no key
    ("signals-empty", ["simulate", S, "output.signals=[]"], "output.signals", "[]", {}),
    ("signals-twice", ["simulate", S, 'output.signals=["F_m","F_m"]'], "output.signals", "F_m", {}),
    (
        "clearance-out-of-mesh",
        ["simulate", S, "effects.bearing_clearance.clearance_um=1e4"],
        "effects.bearing_clearance.clearance_um",
        "10000",
        {},
    ),
    # ---- argparse-level mistakes keep the one-line form too
    ("unknown-command", ["simulte"], "simulte", None, {}),
    ("unknown-flag", ["simulate", "--speed", "1200"], "--speed", None, {}),
    ("report-unknown", ["report", "book", "--out", "o"], "book", None, {}),
]


def test_the_table_is_broad():
    commands = {argv[0] for _, argv, *_ in CASES}
    assert len(CASES) >= 60
    assert {"geometry", "stiffness", "verify", "calibrate", "simulate", "sweep", "scene", "report"} <= commands
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_input_one_line_exit_2_nothing_written(case, tmp_path, monkeypatch, capsys):
    _, argv, key, value, env = case
    work = tmp_path / "work"
    work.mkdir()
    _setup(work)
    cache = tmp_path / "cache"
    monkeypatch.setenv("GEARWEAR_CACHE", str(cache))
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    monkeypatch.chdir(work)
    before = {p: p.stat().st_mtime_ns for p in _files(work)}
    rc = _run(argv)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2, err
    assert len(lines) == 1, err
    assert lines[0].startswith("gearwear: error: "), err
    assert key in lines[0], lines[0]
    if value is not None:
        assert value in lines[0], lines[0]
    assert "Traceback" not in err
    after = {p: p.stat().st_mtime_ns for p in _files(work)}
    assert after == before, f"files written or changed: {sorted(set(after) ^ set(before))}"
    assert not cache.exists() or not _files(cache)


def _run(argv: list[str]) -> int | str | None:
    """The exit status, whether the command returns it or argparse exits."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def test_console_script_never_shows_a_traceback(tmp_path):
    """The installed entry point, as a user runs it: an internal failure is one line, exit 1."""
    env = {**os.environ, "GEARWEAR_CACHE": str(tmp_path / "cache")}
    r = subprocess.run(
        [sys.executable, "-m", "gearwear.cli", "simulate", "--set", "pair.teeth=[4,30]"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
    )
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    r = subprocess.run(
        [sys.executable, "-m", "gearwear.cli", "--debug", "simulate", "--set", "pair.teeth=[4,30]"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
    )
    assert r.returncode != 0 and "Traceback" in r.stderr  # --debug shows where it came from


def test_ctrl_c_is_one_line_exit_130_and_writes_nothing(tmp_path, monkeypatch, capsys):
    """Ctrl-C in the middle of the computation: exit 130 (128 + SIGINT), one line, no --out folder."""
    from gearwear.jobs import simulate as simulate_job

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(simulate_job, "run", interrupted)
    monkeypatch.chdir(tmp_path)
    rc = main(["simulate", "--out", "sim"])
    err = capsys.readouterr().err
    assert rc == 130 and len(err.strip().splitlines()) == 1 and "interrupted" in err
    assert not list(tmp_path.iterdir())
