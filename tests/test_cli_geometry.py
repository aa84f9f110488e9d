"""`gearwear geometry`: JSON summary, files, and one-line errors for bad input."""

import json
import math
import subprocess
import sys

import pytest


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "gearwear.cli", *args], capture_output=True, text=True, cwd=cwd)


def test_geometry_json_without_file_is_the_paper_pair():
    r = run("geometry", "--no-mesh", "--json", "--torque-Nm", "0")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    for key in (
        "contact_ratio",
        "base_radius_mm",
        "pitch_radius_mm",
        "tip_radius_mm",
        "root_radius_mm",
        "centre_distance_mm",
        "operating_pressure_angle_deg",
        "backlash_um",
        "contact_line_length_mm",
        "max_wear_depth_um",
    ):
        assert key in s
    assert s["base_radius_mm"] == pytest.approx(75 * math.cos(math.radians(20)), rel=1e-12)
    assert s["centre_distance_mm"] == 150.0 and s["backlash_um"] == 0.0
    assert s["operating_pressure_angle_deg"] == pytest.approx(20.0, rel=1e-14)


def test_geometry_writes_files_atomically(tmp_path):
    out = tmp_path / "geo"
    r = run("geometry", "--wear", "severe", "--clearance-um", "10", "--out", str(out), "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["max_wear_depth_um"] == pytest.approx(30.0, rel=1e-9)
    names = {p.name for p in out.iterdir()}
    assert {"profile.csv", "profile.csv.json", "tooth.png", "pinion_mesh.vtu", "summary.json"} <= names
    assert not [n for n in names if n.endswith(".tmp")]
    meta = json.loads((out / "profile.csv.json").read_text())
    assert len(meta["input_sha256"]) == 64 and meta["inputs"]["wear"] == "severe"
    header = (out / "profile.csv").read_text().splitlines()[0]
    assert "wear_depth_um" in header and "roll_angle_deg" in header


BAD = [
    ("[pair]\nmodule_mm = -5\n", "pair.module_mm = -5 mm"),
    ("[pair]\npressure_angle_deg = 0\n", "pair.pressure_angle_deg = 0 deg"),
    ("[pair]\npressure_angle_deg = 45\n", "pair.pressure_angle_deg = 45 deg"),
    ("[pair]\nteeth = [4, 30]\n", "pair.teeth[0] = 4"),
    ("[pair]\nmodule = 5\n", "did you mean pair.module_mm"),
    ("[effects]\nbearing_clearence = { clearance_um = 10 }\n", "did you mean effects.bearing_clearance"),
    ("[effects]\nbearing_clearance = { clearance_um = -10 }\n", "effects.bearing_clearance.clearance_um = -10 um"),
]


@pytest.mark.parametrize("toml,message", BAD)
def test_bad_input_files_give_one_line_and_write_nothing(tmp_path, toml, message):
    f = tmp_path / "bad.toml"
    f.write_text(toml)
    out = tmp_path / "out"
    r = run("geometry", str(f), "--no-mesh", "--out", str(out))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], r.stderr
    assert not out.exists()


@pytest.mark.parametrize(
    "args,message",
    [
        (["--clearance-um", "-5"], "--clearance-um = -5 um: must be in [0, 10000] um"),
        (["--wear", "12000um"], "effects.wear.max_depth_um = 12000 um: must be in [0, "),
        (["--wear", "heavy"], "--wear = 'heavy'"),
    ],
)
def test_bad_cli_options(tmp_path, args, message):
    out = tmp_path / "out"
    r = run("geometry", "--no-mesh", "--out", str(out), *args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], r.stderr
    assert not out.exists()


def test_stiffness_cli_overlays_and_json(tmp_path):
    out = tmp_path / "st"
    r = run("stiffness", "--wear", "unworn", "mild", "severe", "--points", "120", "--out", str(out), "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    for key in ("mean_N_per_m", "min_N_per_m", "max_N_per_m", "contact_ratio", "points", "wall_s"):
        assert key in s
    means = [c["mean_N_per_m"] for c in s["curves"]]
    assert means[0] > means[1] > means[2]
    names = {p.name for p in out.iterdir()}
    assert "stiffness.png" in names and "stiffness_ishikawa_severe_clearance0um.csv.json" in names
    header = (out / "stiffness_ishikawa_mild_clearance0um.csv").read_text().splitlines()[0]
    assert header.startswith("angle_deg,k_N_per_m,pairs_in_contact,load_pair_1_N") and "ste_um" in header
    r = run("stiffness", "--clearance-um", "0,50,100", "--points", "60", "--out", str(out / "cl"))
    assert r.returncode == 0, r.stderr
    assert (out / "cl" / "mean_vs_clearance.png").exists()


@pytest.mark.parametrize(
    "args,message",
    [
        (["--points", "4"], "--points = 4"),
        (["--torque-Nm", "0"], "--torque-Nm = 0 N m"),
        (["--wear", "12000um"], "effects.wear.max_depth_um = 12000 um: must be in [0, "),
        (["--method", "magic"], "--method = 'magic'"),
    ],
)
def test_stiffness_bad_input(tmp_path, args, message):
    r = run("stiffness", "--out", str(tmp_path / "o"), *args)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and message in r.stderr, r.stderr
    assert not (tmp_path / "o").exists()


def test_same_inputs_give_the_same_bytes(tmp_path):
    for k in (1, 2):
        r = run("stiffness", "--wear", "mild", "--points", "64", "--out", str(tmp_path / f"r{k}"))
        assert r.returncode == 0, r.stderr
    for name in (
        "stiffness_ishikawa_mild_clearance0um.csv",
        "stiffness_ishikawa_mild_clearance0um.csv.json",
        "stiffness.png",
    ):
        assert (tmp_path / "r1" / name).read_bytes() == (tmp_path / "r2" / name).read_bytes(), name


def test_the_table_builds_no_mesh():
    """Issue 24: `gearwear geometry` built a 47k-triangle mesh (3.3 s) just to print its table; the
    mesh is a file, built only when --out writes the folder."""
    import json as _json

    r = run("geometry", "--json")
    assert r.returncode == 0 and "mesh" not in _json.loads(r.stdout)
