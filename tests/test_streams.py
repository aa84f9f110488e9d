"""Every input stream is bounded and read once: a FIFO, a device or an oversized file given
where a file is expected gets one line and exit 2, within seconds (no hang, no reading
/dev/zero until the memory runs out), and nothing is written; the SHA-256 recorded in the
manifest is that of the bytes parsed (a file changed after it was read does not change it)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from gearwear.core.inputs import read_input
from gearwear.core.validation import InputError

SHORT = ["--set", "solver.duration_s=0.02", "--set", "solver.discard_s=0.01"]


def run(*args, cwd=None, timeout=60):
    return subprocess.run([sys.executable, "-m", "gearwear.cli", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=timeout)


@pytest.fixture
def fifo(tmp_path):
    p = tmp_path / "pipe.csv"
    os.mkfifo(p)
    return p


def _table_scene(tmp_path, table: str) -> Path:
    s = tmp_path / "t.toml"
    s.write_text(f'extends = "paper-default"\n[effects]\nmesh_stiffness = {{ source = "table", path = "{table}" }}\n')
    return s


def _one_line_exit_2(r, *needles, out=None):
    assert r.returncode == 2, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and all(n in lines[0] for n in needles), r.stderr
    assert out is None or not out.exists()


def test_a_fifo_is_refused_not_waited_on(tmp_path, fifo):
    out = tmp_path / "o"
    _one_line_exit_2(run("simulate", str(_table_scene(tmp_path, fifo.name)), "--out", str(out), timeout=30),
                     "effects.mesh_stiffness.path", "pipe (FIFO)", out=out)
    scene = tmp_path / "s.fifo"
    os.mkfifo(scene)
    _one_line_exit_2(run("geometry", str(scene), timeout=30), "pipe (FIFO)")
    dev = tmp_path / "dev.toml"
    dev.write_text('extends = "paper-default"\n[flank]\ndeviation_csv = ["pipe.csv", ""]\n')
    _one_line_exit_2(run("stiffness", str(dev), timeout=30), "flank.deviation_csv[0]", "pipe (FIFO)")
    _one_line_exit_2(run("diagnose", "examples/diagnose/scene.toml", "--measured", str(fifo), "--out", str(out),
                         cwd=Path(__file__).parents[1], timeout=30), "--measured", "pipe (FIFO)", out=out)


def test_a_device_is_refused_not_read_to_the_end(tmp_path):
    _one_line_exit_2(run("simulate", str(_table_scene(tmp_path, "/dev/zero")), timeout=30),
                     "effects.mesh_stiffness.path", "a device")
    _one_line_exit_2(run("geometry", "/dev/zero", timeout=30), "a device")


def test_an_oversized_input_is_refused_with_the_limit(tmp_path):
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:
        fh.truncate((64 << 20) + 1)   # sparse: no disk used
    _one_line_exit_2(run("simulate", str(_table_scene(tmp_path, "big.csv")), timeout=30),
                     "effects.mesh_stiffness.path", f"at most {64 << 20} bytes")


def test_read_input_reads_once_and_records_what_it_parsed(tmp_path):
    from gearwear.core.inputs import recorded_sha256
    import hashlib

    p = tmp_path / "a.txt"
    p.write_bytes(b"first")
    assert read_input(p, "k", "file", 100) == b"first"
    p.write_bytes(b"second")                   # changed after it was read
    assert recorded_sha256(p) == hashlib.sha256(b"first").hexdigest()
    with pytest.raises(InputError, match=r"^k = '.*a.txt': is 6 bytes, more than any file the tool can use"):
        read_input(p, "k", "file", 5)


def test_the_manifest_hashes_the_bytes_that_were_used(tmp_path):
    """A table read from the scene's folder: the manifest's SHA-256 is that of its bytes."""
    import hashlib

    rows = "angle_deg,k_N_per_m\n" + "".join(f"{12 * i / 16:g},{3e8 + 1e7 * (i % 2):.6g}\n" for i in range(16))
    (tmp_path / "k.csv").write_text(rows)
    out = tmp_path / "o"
    r = run("simulate", str(_table_scene(tmp_path, "k.csv")), *SHORT, "--out", str(out))
    assert r.returncode == 0, r.stderr
    man = json.loads((out / "manifest.json").read_text())
    ref = man["provenance"]["referenced_files"]["effects.mesh_stiffness.path"]
    assert ref["sha256"] == hashlib.sha256(rows.encode()).hexdigest()
