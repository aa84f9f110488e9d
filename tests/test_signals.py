"""SIGINT and SIGTERM at any moment end a command cleanly (README, "A bad input prints one line").

Each case runs the real command line in a subprocess in its own process group, as a shell
runs a job, waits for a moment of the run and sends a real signal: SIGINT to the whole
process group (what Ctrl-C in a terminal does) or SIGTERM to the command's process (what
``kill`` or a job manager does). Then:

* the exit status is 130 (SIGINT) or 143 (SIGTERM) and stderr is one line (apart from the
  progress bar's own text), with no traceback;
* no process of the group is left a few seconds later (the local pool's workers, the Dask
  LocalCluster's workers, multiprocessing's helpers);
* no temporary folder (``.NAME.*.tmp``, ``.NAME.*.old``) is left next to ``--out``;
* the previous ``--out`` content (written first by a short successful run) is unchanged, or,
  if the signal came after the new folder was swapped in (the line then says "after
  writing"), the folder is the new run's complete set.

The moments, detected by polling (never a fixed sleep): *start* (gearwear's handlers are
installed, /proc/PID/status, and the command is still importing), *compute* (the progress
bar is on stderr), *write* (the temporary folder next to ``--out`` exists) and, for a
LocalCluster, *dask* (its first worker process exists).
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import termios
import threading
import time
from pathlib import Path

import pytest

psutil = pytest.importorskip("psutil")

pytestmark = pytest.mark.slow

SHORT = ["--set", "solver.duration_s=0.06", "--set", "solver.discard_s=0.02"]
SWEEP = ["sweep", "--set", "operating.speed_rpm=1000:1250:6", *SHORT]
RUNUP = [
    "runup",
    "--set",
    "operating.speed_rpm=1000,1100,1200",
    "--max-periods",
    "60",
    "--keep-periods",
    "8",
    "--workers",
    "2",
]

# command -> (the short run that writes the previous --out, the run that is interrupted, its moments)
COMMANDS = {
    "stiffness": (
        ["stiffness", "--points", "16"],
        ["stiffness", "--method", "fem", "--points", "8"],
        ("start", "compute", "write"),
    ),
    "sweep-local": (
        ["sweep", "--set", "operating.speed_rpm=1000,1100", *SHORT, "--workers", "1"],
        [*SWEEP, "--workers", "2"],
        ("start", "compute", "write"),
    ),
    "sweep-dask": (
        ["sweep", "--set", "operating.speed_rpm=1000,1100", *SHORT, "--workers", "1"],
        [*SWEEP, "--scheduler", "local:1"],
        ("start", "dask", "compute"),
    ),
    "runup": (
        [
            "runup",
            "--set",
            "operating.speed_rpm=1000,1100",
            "--max-periods",
            "40",
            "--keep-periods",
            "8",
            "--direction",
            "up",
            "--workers",
            "1",
        ],
        RUNUP,
        ("start", "compute", "write"),
    ),
}
BAR = {"stiffness": "pair FE positions", "sweep-local": "sweep:", "sweep-dask": "sweep:", "runup": "runup:"}
CASES = [(c, m, s) for c, (_, _, moments) in COMMANDS.items() for m in moments for s in ("SIGINT", "SIGTERM")]
SIGTERM_BIT = 1 << (signal.SIGTERM - 1)


def _env(cache: Path) -> dict[str, str]:
    return {**os.environ, "GEARWEAR_CACHE": str(cache), "PYTHONUNBUFFERED": "1"}


def _snapshot(folder: Path) -> dict[str, str]:
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.fixture(scope="module")
def previous(tmp_path_factory):
    """Per command, a folder written by a short successful run (copied into each case)."""
    root = tmp_path_factory.mktemp("previous")
    made: dict[str, Path] = {}

    def get(command: str) -> Path:
        if command not in made:
            out = root / command
            r = subprocess.run(
                [sys.executable, "-m", "gearwear.cli", *COMMANDS[command][0], "--out", str(out)],
                capture_output=True,
                text=True,
                env=_env(root / "cache"),
                timeout=300,
            )
            assert r.returncode == 0, r.stderr[-2000:]
            made[command] = out
        return made[command]

    return get


def _group(pgid: int) -> list[int]:
    """Live (not zombie) processes of the process group ``pgid``."""
    left = []
    for p in psutil.process_iter(["status"]):
        try:
            if os.getpgid(p.pid) == pgid and p.info["status"] != psutil.STATUS_ZOMBIE:
                left.append(p.pid)
        except (ProcessLookupError, psutil.Error):
            continue
    return left


def _handlers_installed(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    caught = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("SigCgt:")), 16)
    return bool(caught & SIGTERM_BIT)  # Python itself catches SIGINT only; SIGTERM is gearwear's


def _reached(moment: str, command: str, proc, err: "Terminal", out: Path) -> bool:
    if moment == "start":
        return _handlers_installed(proc.pid)
    if moment == "compute":
        return BAR[command] in err.text()
    if moment == "write":
        return any(out.parent.glob(f".{out.name}.*.tmp"))
    # dask: the LocalCluster's first worker process (spawned by multiprocessing) exists
    try:
        kids = psutil.Process(proc.pid).children(recursive=True)
    except psutil.Error:
        return False
    return any(
        "spawn_main" in " ".join(k.cmdline()) and "resource_tracker" not in " ".join(k.cmdline())
        for k in kids
        if k.is_running()
    )


class Terminal:
    """A pseudo-terminal for a child's stderr, drained by a thread (``text()``: so far)."""

    def __init__(self):
        self.master, self.slave = os.openpty()
        # 24 x 120 characters: a pty starts at 0 x 0, where tqdm draws nothing
        fcntl.ioctl(self.slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 120, 0, 0))
        self.buf = bytearray()
        self.reader = threading.Thread(target=self._drain, daemon=True)

    def started(self) -> None:
        os.close(self.slave)  # the child has it; reading ends (EIO) when every holder is gone
        self.reader.start()

    def _drain(self) -> None:
        while True:
            try:
                data = os.read(self.master, 65536)
            except OSError:
                break
            if not data:
                break
            self.buf += data

    def text(self) -> str:
        return bytes(self.buf).decode("utf-8", errors="replace")

    def drained(self, timeout_s: float = 10.0) -> str:
        """Everything the child wrote: the reader ends when the last holder of the terminal
        has exited. Read right after the child's exit, the last lines could still be in the
        terminal (the console script exits within a millisecond of its last line, without the
        interpreter's teardown; a loaded machine had not run the reader yet)."""
        self.reader.join(timeout_s)
        return self.text()


def _message_lines(text: str) -> list[str]:
    """stderr without the progress bars' own text (tqdm redraws its line with \\r)."""
    parts = re.split(r"[\r\n]", text)
    return [p for p in parts if p.strip() and not p.startswith(tuple(BAR.values()))]


@pytest.mark.parametrize("command,moment,sig", CASES, ids=[f"{c}-{m}-{s}" for c, m, s in CASES])
def test_a_signal_ends_the_command_cleanly(command, moment, sig, tmp_path, previous):
    out = tmp_path / "out"
    shutil.copytree(previous(command), out)
    before = _snapshot(out)
    err = Terminal()  # stderr is a terminal, as for a user: the progress bars are drawn
    proc = subprocess.Popen(
        [sys.executable, "-m", "gearwear.cli", *COMMANDS[command][1], "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=err.slave,
        env=_env(tmp_path / "cache"),
        cwd=tmp_path,
        start_new_session=True,
    )
    err.started()
    try:
        deadline = time.monotonic() + 120
        while not _reached(moment, command, proc, err, out):
            assert proc.poll() is None, f"the run ended before the {moment} moment:\n{err.text()[-2000:]}"
            assert time.monotonic() < deadline, f"no {moment} moment within 120 s"
            time.sleep(0.005)
        if sig == "SIGINT":
            os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C: the terminal signals the whole group
        else:
            os.kill(proc.pid, signal.SIGTERM)  # kill PID, a job manager
        rc = proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    text = err.drained()
    lines = _message_lines(text)
    assert rc == (130 if sig == "SIGINT" else 143), text[-3000:]
    assert len(lines) == 1 and lines[0].startswith(f"gearwear: interrupted by {sig}"), text[-3000:]
    assert "Traceback" not in text
    deadline = time.monotonic() + 15
    while _group(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _group(proc.pid), f"processes left: {[psutil.Process(p).cmdline() for p in _group(proc.pid)]}"
    assert not list(tmp_path.glob(".out.*")), sorted(p.name for p in tmp_path.iterdir())
    err.reader.join(5)
    if "after writing" in lines[0]:  # the signal came after the swap: the new folder, complete
        man = json.loads((out / "manifest.json").read_text())
        assert set(man["files"]) | {"manifest.json", "timing.json"} == set(_snapshot(out))
    else:
        assert "nothing was written or replaced" in lines[0]
        assert _snapshot(out) == before


def test_worker_processes_ignore_ctrl_c_and_end_on_sigterm():
    """The local pool's workers: SIGINT ignored, SIGTERM at its default action (they are
    ended by their parent), so a Ctrl-C to the group is handled once, by the parent."""
    from gearwear.jobs.sweep import LocalPool

    with LocalPool(1) as pool:
        pid = pool.submit(os.getpid).result(timeout=60)
        status = Path(f"/proc/{pid}/status").read_text()
    fields = {
        ln.split(":")[0]: int(ln.split()[1], 16)
        for ln in status.splitlines()
        if ln.startswith(("SigIgn", "SigCgt", "SigBlk"))
    }
    assert fields["SigIgn"] & (1 << (signal.SIGINT - 1))
    assert not (fields["SigCgt"] | fields["SigBlk"] | fields["SigIgn"]) & SIGTERM_BIT
