"""``gearwear report pair SCENE``: the one-page report of a user's own pair.

The real command runs once end to end (a subprocess on examples/shifted_pair.toml, the
command's own settings: the pair FE at 24 positions, 33 run-up speeds; ~20 s on a quiet
machine). A driver with more teeth than the driven gear runs in process on a coarse setting
(``report_pair.SETTINGS`` replaced). Bad inputs are refused before any work: exit 2, one
line, nothing written."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gearwear import io
from gearwear.cli import main
from gearwear.jobs import runup as runup_job
from gearwear.reports import pair as report_pair

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "shifted_pair.toml"
COARSE = report_pair.Settings(
    points=48,
    fe_positions=8,
    load_fractions=(0.5, 1.0, 2.0),
    speeds=5,
    runup=runup_job.Settings(max_periods=200, keep_periods=8),
)
#: the 47-tooth driver: the shifted pair's gears exchanged (teeth, bores and shifts)
BIG_DRIVER = [
    "--set",
    "pair.teeth=[47,23]",
    "--set",
    "pair.hub_radius_mm=[40,15]",
    "--set",
    "pair.profile_shift=[0.1,0.4]",
]

# a number as the page writes it; not a part of a name (z1, n_E1, m^2, a version 0.1.0)
NUMBER = re.compile(r"(?<![\w^.])[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?(?![\w.])")
# names, not data
NAMES = re.compile(r"ISO \d+(?:-\d+)?|6-DOF")


def _leaves(obj, numbers: list[float], words: set[str]) -> None:
    if isinstance(obj, dict):
        for v in obj.values():
            _leaves(v, numbers, words)
    elif isinstance(obj, list):
        for v in obj:
            _leaves(v, numbers, words)
    elif isinstance(obj, str):
        words.update(NUMBER.findall(NAMES.sub("", obj)))
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        numbers.append(float(obj))


def _half_step(token: str) -> float:
    """Half a unit of the token's last digit: how far the value may be from what it shows."""
    mantissa, _, exponent = token.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 0.5 * 10.0 ** (int(exponent or 0) - decimals)


def assert_page_numbers_in_json(readme: str, doc: dict) -> int:
    """Every number on the page is one of report.json's, to the digits the page shows."""
    numbers: list[float] = []
    words: set[str] = set()
    _leaves(doc, numbers, words)
    values = np.array(numbers)
    tokens = NUMBER.findall(NAMES.sub("", readme))
    for t in tokens:
        if t in words:
            continue
        x, tol = float(t), _half_step(t) * (1 + 1e-9)
        assert np.any(np.abs(values - x) <= tol), f"{t} on the page is not in report.json"
    return len(tokens)


def assert_iso_curve(doc: dict) -> None:
    """The ISO 6336 K_v on the page is analytic.iso6336.dynamic_factor of the inputs it lists,
    at the run-up's driver speeds converted to ISO's gear 1 (fewer teeth)."""
    from gearwear.analytic.iso6336 import dynamic_factor

    iso = doc["runup"]["iso6336"]
    i = iso["inputs"]
    z_driver = doc["geometry"]["gears"][0]["teeth"]
    assert i["z1"] == min(g["teeth"] for g in doc["geometry"]["gears"])
    n1 = np.asarray(doc["runup"]["speeds_rpm"]) * (z_driver / i["z1"])
    ref = dynamic_factor(
        n1,
        i["z1"],
        i["c_gamma_N_per_mm_um"],
        i["c_prime_N_per_mm_um"],
        i["m_red_kg_per_mm"],
        i["line_load_N_per_mm"],
        i["f_pb_um"] - i["y_p_um"],
        i["f_f_um"] - i["y_f_um"],
        i["C_a_um"],
        i["eps_gamma"],
    )
    np.testing.assert_allclose(iso["K_v"], ref.K_v, rtol=1e-12)
    assert iso["n_E1_rpm"] == pytest.approx(ref.n_E1_rpm, rel=1e-12)
    assert iso["n_E1_driver_rpm"] == pytest.approx(ref.n_E1_rpm * i["z1"] / z_driver, rel=1e-12)
    # the mean mesh stiffness ISO's c_gamma comes from is the dynamic model's
    b_mm = doc["geometry"]["face_width_mm"]
    assert i["c_gamma_N_per_mm_um"] * b_mm * 1e6 == pytest.approx(doc["runup"]["scene_mean_stiffness_N_per_m"])


def assert_page(out: Path, scene_args: list[str]) -> dict:
    """What every report page holds: the files, every method and the FE, the numbers of
    report.json, ISO's curve, the assumptions of the scene."""
    from gearwear.scene.assumptions import for_command
    from gearwear.scene.files import load_scene_dict
    from gearwear.scene.model import scene_from_dict
    from gearwear.scene.overrides import apply_overrides

    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(io.OUTPUT_NAMES["report pair"] + (io.MANIFEST, io.TIMING))
    readme = (out / "README.md").read_text()
    doc = json.loads((out / "report.json").read_text())
    # result files hold no wall time (two runs, the same bytes): timing.json holds them
    assert "wall" not in json.dumps(doc) and "wall" not in readme.replace("wall time of each part", "")
    for label in report_pair.METHOD_LABELS.values():
        assert label in readme
    assert "pair FE" in readme and [r["method"] for r in doc["stiffness"]] == ["ishikawa", "energy", "iso6336", "fem"]
    for png in report_pair.FIGURES:
        assert f"]({png})" in readme
    assert assert_page_numbers_in_json(readme, doc) > 100
    assert_iso_curve(doc)
    fe = next(r for r in doc["stiffness"] if r["method"] == "fem")
    assert fe["points"] == doc["settings"]["fe_positions"] and fe["mean_vs_fe_pct"] == 0.0
    ru = doc["runup"]
    lo, hi = doc["settings"]["speed_fractions"]
    n_E1 = ru["iso6336"]["n_E1_driver_rpm"]
    assert ru["speeds_rpm"][0] == pytest.approx(lo * n_E1, rel=1e-5)
    assert ru["speeds_rpm"][-1] == pytest.approx(hi * n_E1, rel=1e-5)
    assert all(k >= 1.0 for k in ru["K_v"]) and len(ru["K_v"]) == doc["settings"]["speeds"]
    data, name = load_scene_dict(scene_args[0])
    sets = [scene_args[i + 1] for i, a in enumerate(scene_args) if a == "--set"]
    lines = [a.line for a in for_command(scene_from_dict(apply_overrides(data, sets), name=name), "report pair")]
    assert lines and all(f"- `{line}`" in readme for line in lines)
    assert [a["key"] for a in doc["assumptions"]] == [line.split()[1] for line in lines]
    return doc, lines


def test_the_command_on_the_example(tmp_path):
    """The real command, as a user runs it."""
    out = tmp_path / "rp"
    r = subprocess.run(
        [sys.executable, "-m", "gearwear.cli", "report", "pair", str(EXAMPLE), "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    assert "report pair" in r.stderr and "Traceback" not in r.stderr  # the progress bar
    doc, lines = assert_page(out, [str(EXAMPLE)])
    assert [ln for ln in r.stdout.splitlines() if ln.startswith("assumed: ")] == lines
    assert doc["settings"]["fe_positions"] == 24 and doc["settings"]["speeds"] == 33
    assert doc["geometry"]["bodies_from"] == {"mass_kg": "blank", "inertia_kg_m2": "blank"}
    manifest = json.loads((out / io.MANIFEST).read_text())
    assert manifest["command"] == "report pair" and set(manifest["files"]) == set(io.OUTPUT_NAMES["report pair"])


def test_a_driver_with_more_teeth(tmp_path, monkeypatch, capsys):
    """47 teeth drive 23: ISO's gear 1 is the driven gear, the run-up's speeds are the
    driver's around ISO's resonance on that axis (coarse setting)."""
    monkeypatch.setattr(report_pair, "SETTINGS", COARSE)
    out = tmp_path / "rp47"
    assert main(["report", "pair", str(EXAMPLE), *BIG_DRIVER, "--out", str(out)]) == 0
    doc, lines = assert_page(out, [str(EXAMPLE), *BIG_DRIVER])
    iso = doc["runup"]["iso6336"]
    assert [g["teeth"] for g in doc["geometry"]["gears"]] == [47, 23] and iso["inputs"]["z1"] == 23
    assert iso["n_E1_driver_rpm"] == pytest.approx(iso["n_E1_rpm"] * 23 / 47)
    assert "ISO's gear 1 is the 23-tooth gear" in (out / "README.md").read_text()
    assert [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("assumed: ")] == lines


def _refused(argv: list[str], tmp_path: Path, monkeypatch, capsys) -> str:
    """Run ``argv`` in ``tmp_path``: exit 2, one line, nothing written, and no work started."""

    def no_work(*args, **kwargs):
        raise AssertionError("the report started computing before refusing the input")

    monkeypatch.setattr(report_pair, "prepare", no_work)
    monkeypatch.chdir(tmp_path)
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert rc == 2 and len(err) == 1 and err[0].startswith("gearwear: error: "), err
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == before
    return err[0]


def test_a_scene_without_bearing_stiffness_is_refused(tmp_path, monkeypatch, capsys):
    text = EXAMPLE.read_text().replace("bearing_stiffness_N_per_m = 5e8", "")
    assert "bearing_stiffness" not in text
    (tmp_path / "no_bearings.toml").write_text(text)
    err = _refused(["report", "pair", "no_bearings.toml", "--out", "rp"], tmp_path, monkeypatch, capsys)
    assert "bodies.bearing_stiffness_N_per_m" in err and "N/m" in err


@pytest.mark.parametrize(
    "argv, key",
    [
        (["report", "pair", str(EXAMPLE), "--out", "a_file.txt"], "--out"),
        (["report", "pair", str(EXAMPLE), "--set", "operating.torque_Nm=-3", "--out", "rp"], "operating.torque_Nm"),
        (
            [
                "report",
                "pair",
                str(EXAMPLE),
                "--set",
                "faults.spall={tooth=0, start_diameter_mm=62, length_mm=1, depth_um=5}",
                "--out",
                "rp",
            ],
            "[faults]",
        ),
        (["report", "paper", str(EXAMPLE), "--out", "rp"], "report paper"),
    ],
)
def test_bad_inputs_are_refused_before_any_work(argv, key, tmp_path, monkeypatch, capsys):
    (tmp_path / "a_file.txt").write_text("mine\n")
    assert key in _refused(argv, tmp_path, monkeypatch, capsys)
