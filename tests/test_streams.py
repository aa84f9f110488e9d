"""Every input stream is bounded and read once: a FIFO, a device or an oversized file given
where a file is expected gets one line and exit 2, within seconds (no hang, no reading
/dev/zero until the memory runs out), and nothing is written; the SHA-256 recorded in the
manifest is that of the bytes parsed (a file changed after it was read does not change it)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gearwear.core.inputs import read_input
from gearwear.core.validation import InputError

SHORT = ["--set", "solver.duration_s=0.02", "--set", "solver.discard_s=0.01"]


def run(*args, cwd=None, timeout=60):
    return subprocess.run(
        [sys.executable, "-m", "gearwear.cli", *args], capture_output=True, text=True, cwd=cwd, timeout=timeout
    )


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
    _one_line_exit_2(
        run("simulate", str(_table_scene(tmp_path, fifo.name)), "--out", str(out), timeout=30),
        "effects.mesh_stiffness.path",
        "pipe (FIFO)",
        out=out,
    )
    scene = tmp_path / "s.fifo"
    os.mkfifo(scene)
    _one_line_exit_2(run("geometry", str(scene), timeout=30), "pipe (FIFO)")
    dev = tmp_path / "dev.toml"
    dev.write_text('extends = "paper-default"\n[flank]\ndeviation_csv = ["pipe.csv", ""]\n')
    _one_line_exit_2(run("stiffness", str(dev), timeout=30), "flank.deviation_csv[0]", "pipe (FIFO)")
    _one_line_exit_2(
        run(
            "diagnose",
            "examples/diagnose/scene.toml",
            "--measured",
            str(fifo),
            "--out",
            str(out),
            cwd=Path(__file__).parents[1],
            timeout=30,
        ),
        "--measured",
        "pipe (FIFO)",
        out=out,
    )


def test_a_device_is_refused_not_read_to_the_end(tmp_path):
    _one_line_exit_2(
        run("simulate", str(_table_scene(tmp_path, "/dev/zero")), timeout=30), "effects.mesh_stiffness.path", "a device"
    )
    _one_line_exit_2(run("geometry", "/dev/zero", timeout=30), "a device")


def test_an_oversized_input_is_refused_with_the_limit(tmp_path):
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:
        fh.truncate((64 << 20) + 1)  # sparse: no disk used
    _one_line_exit_2(
        run("simulate", str(_table_scene(tmp_path, "big.csv")), timeout=30),
        "effects.mesh_stiffness.path",
        f"at most {64 << 20} bytes",
    )


def test_read_input_reads_once_and_records_what_it_parsed(tmp_path):
    import hashlib

    from gearwear.core.inputs import recorded_sha256

    p = tmp_path / "a.txt"
    p.write_bytes(b"first")
    assert read_input(p, "k", "file", 100) == b"first"
    p.write_bytes(b"second")  # changed after it was read
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


# -- every wait is bounded: a Dask scheduler address -----------------------------------------


@pytest.fixture
def silent_server():
    """A TCP server that accepts connections and never answers (a port of something that is
    not a Dask scheduler, or a hung one): its address."""
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    held = []
    stop = threading.Event()

    def serve():
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(srv.accept()[0])
            except OSError:
                continue

    t = threading.Thread(target=serve, daemon=True)
    t.start()
    yield f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    stop.set()
    t.join(2)
    for c in held:
        c.close()
    srv.close()


def _nobody_listens() -> str:
    import socket

    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()  # nothing listens there now
    return f"tcp://127.0.0.1:{port}"


@pytest.mark.parametrize(
    "command",
    [
        ["sweep", "--set", "operating.speed_rpm=1000,1100", *SHORT],
        ["runup", "--set", "operating.speed_rpm=1000,1100", "--max-periods", "40"],
    ],
    ids=["sweep", "runup"],
)
@pytest.mark.parametrize("where", ["silent", "nobody"])
def test_a_scheduler_address_that_does_not_answer_is_refused_in_bounded_time(tmp_path, silent_server, command, where):
    from gearwear.jobs.sweep import CONNECT_TIMEOUT_S

    address = silent_server if where == "silent" else _nobody_listens()
    out = tmp_path / "o"
    t0 = time.monotonic()
    r = run(*command, "--scheduler", address, "--out", str(out), cwd=tmp_path, timeout=90)
    took = time.monotonic() - t0
    _one_line_exit_2(
        r, f"--scheduler = {address}", f"{CONNECT_TIMEOUT_S:g} s" if where == "silent" else "connect", out=out
    )
    assert took < CONNECT_TIMEOUT_S + 15, took  # the stated wait, plus the start of the command
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_scheduler_without_workers_is_refused():
    pytest.importorskip("distributed")
    from dask.distributed import LocalCluster

    from gearwear.jobs.sweep import connect

    with LocalCluster(n_workers=0, processes=True, host="127.0.0.1", dashboard_address="127.0.0.1:0") as cluster:
        t0 = time.monotonic()
        with pytest.raises(
            InputError,
            match=r"^--scheduler = tcp://127\.0\.0\.1:\d+: the scheduler there has no "
            r"worker \(waited 2 s\)",
        ):
            connect(cluster.scheduler_address, timeout_s=2)
        assert time.monotonic() - t0 < 10


# -- a long run states its estimate ----------------------------------------------------------


def test_a_long_sweep_states_its_estimated_time_once(tmp_path, monkeypatch, capsys):
    from gearwear.cli import main
    from gearwear.jobs import sweep as sweep_job

    monkeypatch.setattr(sweep_job, "LONG_RUN_S", 0.0)  # every run counts as long here
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", "--set", "operating.speed_rpm=1000,1100,1200", *SHORT, "--workers", "1", "--json"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and re.match(
        r"^gearwear: sweep of 3 points on 1 worker: about \d+ s in all \(the first "
        r"took \d+\.\d s\)$",
        err[0],
    ), err


# -- odd paths: an --out name the terminal's encoding cannot show -------------------------------


@pytest.mark.parametrize(
    "env",
    [{"LC_ALL": "C", "PYTHONUTF8": "0"}, {"LC_ALL": "C"}, {"PYTHONIOENCODING": "ascii"}],
    ids=["C-locale-no-utf8-mode", "C-locale", "ascii-stdout"],
)
def test_a_non_ascii_out_works_under_an_ascii_locale(tmp_path, env):
    base = {k: v for k, v in os.environ.items() if k not in ("PYTHONIOENCODING", "PYTHONUTF8", "LANG", "LC_ALL")}
    r = subprocess.run(
        [sys.executable, "-m", "gearwear.cli", "geometry", "--no-mesh", "--out", "résultats"],
        capture_output=True,
        cwd=tmp_path,
        env={**base, **env},
        timeout=120,
    )
    assert r.returncode == 0, r.stderr.decode(errors="replace")
    assert r.stderr == b""
    out = tmp_path / "résultats"
    assert (out / "manifest.json").is_file() and (out / "profile.csv").is_file()
    assert [p.name for p in tmp_path.iterdir()] == ["résultats"]
    assert r.stdout.count(b"wrote ") == len(list(out.iterdir()))
