"""Output folders: complete or absent, replaced as a whole, byte-identical for the same
inputs (timing.json aside), and traced to the content of the inputs (issue 12).

Every command runs in-process through ``gearwear.cli.app.main`` on small problems. The
paper report would take minutes; its test runs the real ``report paper`` command with
the expensive parts replaced (analytic instead of FE-calibrated tables, short
simulations), so everything from the computed results to the files is the real code.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
from pathlib import Path

import pytest

from gearwear import io
from gearwear.cli import main
from gearwear.core.atomic import atomic_folder, swap_in

SHORT = ["--set", "solver.duration_s=0.05", "--set", "solver.discard_s=0.02"]


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (relative path -> bytes), timing.json left out."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != io.TIMING
    }


def run_ok(*args: str) -> None:
    assert main(list(args)) == 0


def twice(tmp_path: Path, *args: str) -> dict[str, bytes]:
    """Run a command into two folders; both hold the same files with the same bytes,
    the manifest lists each with its SHA-256, and no temporary folder is left."""
    for k in ("a", "b"):
        run_ok(*args, "--out", str(tmp_path / k))
    a, b = snapshot(tmp_path / "a"), snapshot(tmp_path / "b")
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name] == b[name], f"{name} differs between two runs with the same inputs"
    m = json.loads(a[io.MANIFEST])
    assert set(m["files"]) == set(a) - {io.MANIFEST}
    for name, entry in m["files"].items():
        assert entry["sha256"] == hashlib.sha256(a[name]).hexdigest()
    assert (tmp_path / "a" / io.TIMING).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "b"]  # no .a.*.tmp / .old left
    for name, data in a.items():
        if name.endswith((".json", ".csv", ".md")):
            assert b"wall_s" not in data and b"Run time" not in data and b"Total wall time" not in data, name
    return a


# -- (a) the same inputs give the same bytes, every command ---------------------------------


def test_geometry_twice_same_bytes(tmp_path):
    files = twice(tmp_path, "geometry", "--wear", "mild", "--mesh-size-mm", "6")
    assert {"profile.csv", "profile.csv.json", "tooth.png", "pinion_mesh.vtu", "summary.json"} <= set(files)
    assert json.loads(files["summary.json"])["files"][0] == "profile.csv"  # names, not paths


def test_stiffness_twice_same_bytes(tmp_path):
    twice(tmp_path, "stiffness", "--wear", "unworn", "severe", "--clearance-um", "0", "50", "--points", "16")


def test_verify_twice_same_bytes(tmp_path):
    files = twice(tmp_path, "verify", "--wear", "severe", "--positions", "5", "--no-convergence")
    assert "provenance" in json.loads(files["verification.json"])


def test_calibrate_twice_same_bytes(tmp_path, monkeypatch):
    # the second run is a cache hit: what is compared is the copy into --out and the manifest
    # (that a cold and a cached table are bit-identical is tests/test_calibrate.py's business)
    monkeypatch.setenv("GEARWEAR_CACHE", str(tmp_path / "cache"))
    (tmp_path / "cache").mkdir()
    (tmp_path / "runs").mkdir()
    twice(tmp_path / "runs", "calibrate", "--wear", "unworn", "--points", "16")


def test_simulate_twice_same_bytes(tmp_path):
    files = twice(tmp_path, "simulate", *SHORT)
    import numpy as np

    with np.load(tmp_path / "a" / "signals.npz") as z:  # the fixed-date NPZ reads like np.savez's
        assert set(z.files) >= {"t_s", "F_m_N"} and z["t_s"].shape == z["F_m_N"].shape
        # every array carries its SI unit in its name (issue 24: SI values under bare keys)
        assert all(k.rsplit("_", 1)[-1] in ("s", "m", "N") for k in z.files), z.files
    assert "compile_s" not in json.loads(files["summary.json"])


def test_sweep_twice_same_bytes(tmp_path):
    files = twice(tmp_path, "sweep", *SHORT, "--set", "operating.torque_Nm=30,40", "--workers", "1")
    assert "wall_s" not in files["sweep.csv"].decode().splitlines()[0].split(",")


def test_report_paper_twice_same_bytes(tmp_path, monkeypatch):
    """The real `report paper` command with analytic tables (no FE) and 50 ms simulations."""
    from gearwear.analytic.tvms import mesh_stiffness
    from gearwear.reports import paper as report_paper
    from gearwear.stiffness import calibration as calibrate

    def table(pair, wear, clearance_m=0.0, torque_Nm=40.0, points=360, *args, **kwargs):
        return mesh_stiffness(
            pair, method="ishikawa", points=48, torque_Nm=torque_Nm, clearance_m=clearance_m, wear=wear
        )

    monkeypatch.setenv("GEARWEAR_CACHE", str(tmp_path / "cache"))  # compute() checks the cache folder
    (tmp_path / "runs").mkdir()
    real_scene = report_paper._scene
    monkeypatch.setattr(calibrate, "run_fe", lambda *a, **k: None)
    monkeypatch.setattr(calibrate, "calibrated_table", table)
    monkeypatch.setattr(
        report_paper,
        "_scene",
        lambda base, sets: real_scene(
            base, [s for s in sets if "mesh_stiffness" not in s] + ["solver.duration_s=0.05", "solver.discard_s=0.02"]
        ),
    )
    files = twice(tmp_path / "runs", "report", "paper")
    assert "README.md" in files and "trends.json" in files and "fig25_F_m_harmonics_clearance.png" in files


# -- (b) re-running replaces the folder: no stale files ------------------------------------------


def test_rerun_replaces_the_whole_folder(tmp_path):
    out = tmp_path / "st"
    run_ok("stiffness", "--wear", "unworn", "mild", "--points", "16", "--out", str(out))
    (out / "stiffness_ishikawa_worn_clearance9um.csv").write_text("from an earlier version\n")
    (out / "summary.json").write_text("{}\n")  # another command's output name
    (out / "fields_old").mkdir()
    (out / "fields_old" / "x.vtu").write_text("old")
    assert (out / "stiffness_ishikawa_unworn_clearance0um.csv").exists()
    run_ok("stiffness", "--wear", "severe", "--points", "16", "--out", str(out))
    names = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    assert names == sorted(
        [
            "manifest.json",
            "timing.json",
            "stiffness.png",
            "stiffness_summary.json",
            "stiffness_ishikawa_severe_clearance0um.csv",
            "stiffness_ishikawa_severe_clearance0um.csv.json",
        ]
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["st"]


def test_user_file_in_a_gearwear_folder_is_refused(tmp_path, capsys):
    """A file the user put into an output folder is never deleted by a re-run."""
    out = tmp_path / "st"
    run_ok("stiffness", "--points", "16", "--out", str(out))
    (out / "scene.toml").write_text("[operating]\n")
    before = snapshot(out)
    assert main(["stiffness", "--points", "16", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds scene.toml, which gearwear did not write" in err[0]
    assert snapshot(out) == before


def test_gearwear_folder_inside_a_gearwear_folder_is_replaced_with_it(tmp_path):
    out = tmp_path / "st"
    run_ok("stiffness", "--points", "16", "--out", str(out))
    run_ok("stiffness", "--points", "16", "--clearance-um", "20", "--out", str(out / "cl"))
    run_ok("stiffness", "--points", "16", "--out", str(out))
    assert not (out / "cl").exists()


def test_folder_without_manifest_holding_only_output_names_is_replaced(tmp_path):
    """Outputs committed before manifests existed (reports/): only the command's own names."""
    out = tmp_path / "cal"
    out.mkdir()
    (out / "stiffness.png").write_bytes(b"old png")
    (out / "stiffness_ishikawa_unworn_clearance0um.csv").write_text("old\n")
    run_ok("stiffness", "--points", "16", "--out", str(out))
    assert (out / io.MANIFEST).exists() and (out / "stiffness.png").read_bytes() != b"old png"


# -- (c) a foreign folder is refused and untouched ---------------------------------------------


@pytest.mark.parametrize("with_output_name", [True, False])
def test_foreign_folder_is_refused(tmp_path, capsys, with_output_name):
    out = tmp_path / "results"
    out.mkdir()
    (out / "thesis.tex").write_text("mine\n")
    if with_output_name:  # a gearwear-looking name next to a foreign file is still a foreign folder
        (out / "stiffness.png").write_bytes(b"png")
    before = snapshot(out)
    rc = main(["stiffness", "--points", "16", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert "exists, is not empty and was not written by gearwear" in err[0]
    assert snapshot(out) == before and sorted(p.name for p in tmp_path.iterdir()) == ["results"]


@pytest.mark.parametrize("out", ["", "."])
def test_out_empty_or_current_folder_is_refused(tmp_path, monkeypatch, capsys, out):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "keep.txt").write_text("x")
    assert main(["geometry", "--no-mesh", "--out", out]) == 2
    assert "--out" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]


# -- (d) Ctrl-C while writing leaves the previous output as it was -------------------------------


def test_ctrl_c_while_writing_keeps_the_previous_output(tmp_path, monkeypatch, capsys):
    from gearwear.jobs import stiffness as stiffness_job

    out = tmp_path / "st"
    run_ok("stiffness", "--wear", "mild", "--points", "16", "--out", str(out))
    before = snapshot(out)

    def interrupted(curves):  # called after the CSVs and sidecars are written
        assert any(tmp_path.glob(".st.*.tmp/stiffness_*.csv"))
        raise KeyboardInterrupt

    monkeypatch.setattr(stiffness_job, "figures", interrupted)
    assert main(["stiffness", "--wear", "severe", "--points", "16", "--out", str(out)]) == 130
    assert "interrupted" in capsys.readouterr().err
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["st"]  # no temporary folder left


def test_ctrl_c_during_the_swap_rolls_back(tmp_path, monkeypatch):
    """SIGINT between the two renames of the swap: the old folder is back, the new one gone."""
    import gearwear.core.atomic as atomic

    target = tmp_path / "out"
    target.mkdir()
    (target / "old.txt").write_text("old")
    real_rename = os.rename
    calls = []

    def rename(a, b):
        real_rename(a, b)
        calls.append((a, b))
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(atomic.os, "rename", rename)
    with pytest.raises(KeyboardInterrupt):
        with atomic_folder(target) as tmp:
            (tmp / "new.txt").write_text("new")
    assert [p.name for p in tmp_path.iterdir()] == ["out"] and (target / "old.txt").read_text() == "old"
    assert not (target / "new.txt").exists()
    monkeypatch.setattr(atomic.os, "rename", real_rename)
    new = tmp_path / ".fresh"
    new.mkdir()
    swap_in(new, target)  # without a signal the swap completes
    assert list(target.iterdir()) == [] and sorted(p.name for p in tmp_path.iterdir()) == ["out"]


# -- (d') the swap never deletes a file gearwear did not write ----------------------------------


def test_a_file_that_appears_during_the_run_is_never_deleted(tmp_path, monkeypatch, capsys):
    """A file put into --out while the command runs (after the check before any work): the
    swap stops with one line and exit 2, the folder and that file stay as they are."""
    from gearwear.jobs import stiffness as stiffness_job

    out = tmp_path / "st"
    run_ok("stiffness", "--points", "16", "--out", str(out))
    capsys.readouterr()
    before = snapshot(out)
    figures = stiffness_job.figures

    def while_writing(curves):
        (out / "notes.txt").write_text("written by the user during the run\n")
        return figures(curves)

    monkeypatch.setattr(stiffness_job, "figures", while_writing)
    assert main(["stiffness", "--points", "16", "--wear", "mild", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "notes.txt appeared in it during the run" in err[0] and "--out = " in err[0]
    assert (out / "notes.txt").read_text() == "written by the user during the run\n"
    assert {k: v for k, v in snapshot(out).items() if k != "notes.txt"} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["st"]  # no .st.*.tmp / .old left


def test_a_file_that_appears_between_the_check_and_the_rename_is_never_deleted(tmp_path):
    """The swap checks the folder again once it is renamed aside, when nothing can be added
    to it by its name any more: a file that arrived just before the rename is kept."""
    import gearwear.core.atomic as atomic

    target = tmp_path / "out"
    target.mkdir()
    (target / "mine.txt").write_text("x")
    seen = []

    def may_replace(folder):
        seen.append(folder.name)
        if folder != target and any(folder.iterdir()):
            raise io.InputError(f"--out = {target}: mine.txt appeared")

    new = tmp_path / ".fresh"
    new.mkdir()
    with pytest.raises(io.InputError):
        atomic.swap_in(new, target, may_replace)
    assert seen[0] == "out" and seen[1].startswith(".out.") and seen[1].endswith(".old")
    assert (target / "mine.txt").read_text() == "x" and sorted(p.name for p in tmp_path.iterdir()) == [".fresh", "out"]


def _make_read_only(folder: Path):
    """chmod 555 (or, as root, for whom permissions do not stop a deletion, the immutable
    attribute); returns the undo, or skips if neither is possible here."""
    import shutil
    import subprocess

    if os.geteuid() != 0:
        folder.chmod(0o555)
        return lambda: folder.chmod(0o755)
    if shutil.which("chattr") is None or subprocess.run(["chattr", "+i", str(folder)], capture_output=True).returncode:
        pytest.skip("running as root without chattr +i: no folder here is read-only to this process")
    return lambda: subprocess.run(["chattr", "-i", str(folder)], check=True)


@pytest.mark.parametrize("where", [".", "sub"])
def test_a_read_only_out_is_refused_before_any_work(tmp_path, capsys, where):
    """Its old content could not be deleted: the command stops before any work (exit 2,
    one line), so no hidden .NAME.*.old folder is left holding it."""
    out = tmp_path / "st"
    run_ok("stiffness", "--points", "16", "--out", str(out))
    (out / "fields_0").mkdir()
    (out / "fields_0" / "u.vtu").write_text("old field\n")
    capsys.readouterr()
    locked = out if where == "." else out / "fields_0"
    undo = _make_read_only(locked)
    try:
        before = snapshot(out)
        assert main(["stiffness", "--points", "16", "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        name = "." if where == "." else "fields_0/"
        assert len(err) == 1 and f"{name} is read-only" in err[0], err
        assert snapshot(out) == before
        assert sorted(p.name for p in tmp_path.iterdir()) == ["st"]
    finally:
        undo()


def test_a_users_manifest_json_does_not_make_a_folder_gearwears(tmp_path, capsys):
    """A folder holding only a file of the user's called manifest.json, or one that claims to
    be gearwear's without a command and a file list, is not replaced."""
    for doc in (
        {"name": "my project", "files": ["a", "b"]},
        {"software": "gearwear", "files": {}},
        {"software": "gearwear", "command": "stiffness", "files": {"x.csv": "not a hash"}},
    ):
        out = tmp_path / "mine"
        out.mkdir(exist_ok=True)
        (out / "manifest.json").write_text(json.dumps(doc))
        assert main(["stiffness", "--points", "16", "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "manifest.json" in err[0], err
        assert json.loads((out / "manifest.json").read_text()) == doc
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"]


# -- (e) provenance is the content of the inputs ----------------------------------------------

SCENE = """
extends = "paper-default"

[operating]
torque_Nm = {torque}

[effects]
wear = {{ hours = 500, archard_k_m2_per_N = {k} }}
"""


def sidecar(out: Path) -> dict:
    return json.loads(next(out.glob("stiffness_*.csv.json")).read_text())


def test_provenance_hashes_content_not_names(tmp_path):
    (tmp_path / "a.toml").write_text(SCENE.format(torque=5, k=5.3e-16))
    (tmp_path / "b.toml").write_text(SCENE.format(torque=5, k=5.3e-16))  # same content, other name
    (tmp_path / "c.toml").write_text(SCENE.format(torque=30, k=5.3e-16))  # the scene file edited
    (tmp_path / "d.toml").write_text(SCENE.format(torque=5, k=1e-15))  # same wear label "500h"
    meta = {}
    for name in "abcd":
        run_ok("stiffness", str(tmp_path / f"{name}.toml"), "--points", "16", "--out", str(tmp_path / f"o{name}"))
        meta[name] = sidecar(tmp_path / f"o{name}")
        man = json.loads((tmp_path / f"o{name}" / io.MANIFEST).read_text())
        assert man["provenance"]["scene_sha256"] == meta[name]["inputs"]["scene_sha256"]
        assert man["provenance"]["scene_name"] == name and meta[name]["scene_name"] == name
    h = {n: (m["inputs"]["scene_sha256"], m["input_sha256"]) for n, m in meta.items()}
    assert h["a"] == h["b"]  # the name labels the run; it is not an input
    assert h["c"][0] != h["a"][0] and h["c"][1] != h["a"][1]  # torque 5 -> 30 N m
    assert meta["d"]["inputs"]["wear"] == meta["a"]["inputs"]["wear"] == "500h"
    assert h["d"][1] != h["a"][1]  # the full wear definition is hashed, not its label
    assert meta["d"]["inputs"]["wear_spec"]["archard_k_m2_per_N"] == 1e-15


def test_referenced_table_enters_by_content(tmp_path):
    from gearwear.scene.model import Scene

    rows = "\n".join(f"{12 * i / 16:g},{2.5e8 + 1e7 * (i % 2):.6g}" for i in range(16))
    scene = 'extends = "paper-default"\n[effects]\nmesh_stiffness = { source = "table", path = "k.csv" }\n'
    for sub in ("x", "y"):
        (tmp_path / sub).mkdir()
        (tmp_path / sub / "s.toml").write_text(scene)
        (tmp_path / sub / "k.csv").write_text("angle_deg,k_N_per_m\n" + rows + "\n")
    hx = io.scene_inputs(Scene.load(tmp_path / "x" / "s.toml"))
    hy = io.scene_inputs(Scene.load(tmp_path / "y" / "s.toml"))
    assert hx == hy  # the same table in another folder: the same inputs
    assert hx["scene"]["effects"]["mesh_stiffness"]["path"].startswith("sha256:")
    (tmp_path / "y" / "k.csv").write_text("angle_deg,k_N_per_m\n" + rows.replace("2.5e+08", "2.4e+08") + "\n")
    assert io.scene_inputs(Scene.load(tmp_path / "y" / "s.toml"))["scene_sha256"] != hx["scene_sha256"]
    labels = io.scene_labels(Scene.load(tmp_path / "x" / "s.toml"))
    assert labels["referenced_files"]["effects.mesh_stiffness.path"]["path"].endswith("k.csv")


def test_simulate_sidecar_hashes_the_resolved_scene(tmp_path):
    """--set and the scene file reach the hash through the resolved scene."""
    (tmp_path / "s.toml").write_text(
        (Path(__file__).parents[1] / "gearwear" / "data" / "paper-wear-severe.toml").read_text()
    )
    run_ok("simulate", str(tmp_path / "s.toml"), *SHORT, "--out", str(tmp_path / "f"))
    run_ok("simulate", *SHORT, "--out", str(tmp_path / "b"))  # the built-in of the same content
    run_ok("simulate", *SHORT, "--torque-Nm", "30", "--out", str(tmp_path / "t"))
    h = {k: json.loads((tmp_path / k / "signals.csv.json").read_text())["input_sha256"] for k in "fbt"}
    assert h["f"] == h["b"] != h["t"]
