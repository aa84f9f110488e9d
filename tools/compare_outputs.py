"""No behaviour change across a refactor: every gearwear command on two commits, each result file
compared byte for byte.

    .venv/bin/python tools/compare_outputs.py BEFORE_REV AFTER_REV [--work DIR] [--keep]

Revisions are commits (anything ``git rev-parse`` takes); commit a working tree's changes first.
For each revision, one at a time:

* a detached worktree, ``git worktree add --detach DIR/<before|after>-<sha>``, removed at the end
  unless --keep (DIR: --work, or a fresh temporary folder that is deleted with it);
* its own venv, ``DIR/<rev>/.venv``, with no third-party package reinstalled: the venv gets the
  build requirements of the worktree's pyproject.toml (setuptools >= 77 and wheel; the repository's
  .venv has an older setuptools, and the venv's bundled one cannot read the PEP 639 licence
  fields) from the configured package index, then ``pip install --no-deps --no-build-isolation -e``
  of the worktree (an editable install honours the package-dir mapping gearwear.fem -> fem/ ...),
  and only then a ``.pth`` file that appends the repository's .venv site-packages (numpy, scipy,
  gmsh, numba, ...). The .pth comes last so that pip never sees the repository's own editable
  gearwear as an installed copy to replace. ``gearwear`` and ``gearwear.fem`` must then import
  from the worktree;
* its own caches: GEARWEAR_CACHE (calibrated tables, surrogates), NUMBA_CACHE_DIR (compiled
  solver kernels) and MPLCONFIGDIR under DIR/<rev>/.cmp/, so that no result is read from a cache
  the other revision wrote;
* the commands of COMMANDS below, one at a time, through that venv's ``gearwear`` console script,
  in the scratch folder DIR/<rev>/.cmp/run, each with ``--out out/<name>`` where it writes files;
  stdout goes to DIR/<rev>/.cmp/stdout/<name>.txt. Input files (``{ex}``: examples/) are taken
  from BEFORE_REV for both runs (DIR/inputs/examples), so that only the code differs.

The commands cover every command and its main options on small problems, stdout as text and,
where a command offers it, as --json: about 4 min per revision on 2 cores (5-6 min on a machine
shared at load 6), most of it the FE and numba compiling the solver kernels into the empty cache.
``report paper`` is left out: it takes several minutes and has no quick mode.

Compared, per command: the set of files under its --out folder and each file's bytes, and its
stdout. Left out, and why:

* ``timing.json``: the run's wall times, the one file that differs between two identical runs
  (docs/commands.md: result files hold no wall time).
* stderr: progress bars (rates, ETAs), "compiling solver kernels" and cache notices; no results.
* wall-time figures in text stdout, replaced by ``<t>`` (WALL_TIME_PHRASES, WALL_TIME_COLUMNS):
  simulate's "<t> s wall (integration <t> s, compile <t> s)", runup's and report pair's
  "wall time <t> s", diagnose's "wall <t> s (surrogate ..., fit <t> s)", verify's convergence
  "dofs in <t> s", geometry's pinion mesh "built in <t> s", and the table columns "wall ms"
  (stiffness), "wall s" (report pair) and "FE s" (verify) in the rows under their header (with
  the padding before the figure, whose width varies with it). A row whose figure does not end
  under its header (an overflowing column) keeps it and so shows as a difference: never a
  silent pass.
* wall-time keys of ``--json`` stdout (WALL_TIME_KEYS, at any depth): wall_s, compile_s,
  build_s (geometry's mesh), *_wall_s and the diagnosis's timing object; the rest is compared
  as data.

Reported apart, as "differs only in code fingerprint (keys ...)", never as same: JSON that differs
only in what follows from the source code's fingerprint, which changes whenever a module moves
or changes: a calibrated table's ``inputs.code_sha256`` (SHA-256 of the calibration code's
source) and ``code_modules`` (the module names hashed), and then in the same document its
``input_sha256`` and ``file`` (the cache name, that hash); ``manifest.json``'s
``files[name].sha256`` and ``.bytes`` of a file that differs only so; a hash in ``--json`` stdout
whose before/after values are such an input_sha256 pair. manifest's ``version`` (the package's
version from pyproject.toml) is no fingerprint: a change there is a difference. Everything else
that differs is DIFFERS, with the file and the first differing byte offset, JSON path or line.

Output: a progress line per command and revision with its wall time, then one line per command
(``same``, ``differs only in code fingerprint (keys ...)`` or ``DIFFERS: ...``) and a summary.
Exit status 0 when nothing DIFFERS, 1 when something does (a command that fails on either
revision DIFFERS, with its stderr tail), 2 when a revision cannot be set up, 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import io
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tarfile
import tempfile
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
MAIN_PYTHON = REPO / ".venv" / "bin" / "python"

# ---------------------------------------------------------------------------------------------
# What runs. {out}: the command's output folder (out/<name>, relative to the run folder);
# {ex}: the examples/ folder of BEFORE_REV. Runs in this order: later commands reuse what earlier
# ones put in the (per-revision) caches, e.g. diagnose reads the surrogate diagnose --plan built.
# ---------------------------------------------------------------------------------------------
QUICK_SOLVE = ("--set", "solver.duration_s=0.06", "--set", "solver.discard_s=0.02")
COMMANDS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("geometry", ("geometry", "--out", "{out}")),
    (
        "geometry-worn",
        ("geometry", "--wear", "severe", "--clearance-um", "10", "--mesh-size-mm", "5", "--json", "--out", "{out}"),
    ),
    ("geometry-hours", ("geometry", "{ex}/shifted_pair.toml", "--wear", "8h", "--json")),
    ("stiffness", ("stiffness", "--out", "{out}")),
    (
        "stiffness-methods",
        (
            "stiffness",
            "--wear",
            "unworn",
            "mild",
            "severe",
            "--method",
            "ishikawa",
            "energy",
            "iso6336",
            "--json",
            "--out",
            "{out}",
        ),
    ),
    ("stiffness-clearance", ("stiffness", "--clearance-um", "0", "50", "--points", "90", "--out", "{out}")),
    ("stiffness-fem", ("stiffness", "--method", "fem", "--points", "8", "--fields", "0", "--out", "{out}")),
    ("stiffness-19-45", ("stiffness", "{ex}/your_pair.toml", "--out", "{out}")),
    ("stiffness-tip-relief", ("stiffness", "{ex}/tip_relief.toml", "--out", "{out}")),
    ("verify", ("verify", "--wear", "unworn", "severe", "--positions", "5", "--no-convergence", "--out", "{out}")),
    ("verify-json", ("verify", "--wear", "severe", "--positions", "5", "--no-convergence", "--json", "--out", "{out}")),
    ("calibrate", ("calibrate", "--points", "36", "--out", "{out}")),
    ("calibrate-cached", ("calibrate", "--points", "36", "--json", "--out", "{out}")),
    ("simulate", ("simulate", "--out", "{out}")),
    ("simulate-paper-default", ("simulate", "paper-default", "--json", "--out", "{out}")),
    ("simulate-root-crack", ("simulate", "{ex}/root_crack.toml", "--out", "{out}")),
    ("simulate-user-table", ("simulate", "{ex}/user_table/scene.toml", "--json", "--out", "{out}")),
    (
        "sweep",
        (
            "sweep",
            "--set",
            "effects.bearing_clearance.clearance_um=0:20:3",
            *QUICK_SOLVE,
            "--workers",
            "2",
            "--out",
            "{out}",
        ),
    ),
    (
        "sweep-wear",
        (
            "sweep",
            "paper-wear-severe",
            "--set",
            "effects.wear.phase=unworn,mild",
            *QUICK_SOLVE,
            "--workers",
            "1",
            "--json",
            "--out",
            "{out}",
        ),
    ),
    (
        "runup",
        (
            "runup",
            "--set",
            "operating.speed_rpm=1000:3000:3",
            "--max-periods",
            "40",
            "--keep-periods",
            "8",
            "--workers",
            "2",
            "--out",
            "{out}",
        ),
    ),
    (
        "runup-up",
        (
            "runup",
            "paper-wear-severe",
            "--set",
            "operating.speed_rpm=1000:3000:3",
            "--direction",
            "up",
            "--max-periods",
            "40",
            "--keep-periods",
            "8",
            "--workers",
            "1",
            "--json",
            "--out",
            "{out}",
        ),
    ),
    # one 32-point surrogate of short runs, built by the plan and read from the cache by the other two
    (
        "diagnose-plan",
        (
            "diagnose",
            "--plan",
            "{ex}/diagnose/scene.toml",
            "--speeds-rpm",
            "1200",
            "--torques-Nm",
            "40",
            "--design-points",
            "32",
            *QUICK_SOLVE,
            "--workers",
            "2",
            "--out",
            "{out}",
        ),
    ),
    (
        "diagnose",
        (
            "diagnose",
            "{ex}/diagnose/scene.toml",
            "--measured",
            "{ex}/diagnose/measured_timeseries.csv",
            "--design-points",
            "32",
            *QUICK_SOLVE,
            "--workers",
            "2",
            "--out",
            "{out}",
        ),
    ),
    (
        "diagnose-harmonics",
        (
            "diagnose",
            "{ex}/diagnose/scene.toml",
            "--measured",
            "{ex}/diagnose/measured_harmonics.csv",
            "--design-points",
            "32",
            *QUICK_SOLVE,
            "--workers",
            "2",
            "--json",
            "--out",
            "{out}",
        ),
    ),
    ("scene", ("scene", "paper-wear-severe")),
    ("scene-json", ("scene", "{ex}/your_pair.toml", "--set", "operating.speed_rpm=1500", "--json")),
    ("scene-schema", ("scene", "--schema")),
    ("scene-list", ("scene", "--list")),
    ("scene-reference", ("scene", "--reference")),
    ("report-pair", ("report", "pair", "{ex}/shifted_pair.toml", "--out", "{out}")),
)
COMMAND_TIMEOUT_S = 900

# ---------------------------------------------------------------------------------------------
# What is left out of the comparison (the module docstring says why).
# ---------------------------------------------------------------------------------------------
NOT_COMPARED = {"timing.json"}
TIME = r"(?:\d+(?:\.\d*)?(?:e[-+]?\d+)?|nan)"
#: wall-time figures in text stdout: each {t} is masked
WALL_TIME_PHRASES = (
    "{t} s wall (integration {t} s, compile {t} s)",  # simulate's summary line
    "wall time {t} s",  # runup, report pair
    "wall {t} s (surrogate",  # diagnose
    ", fit {t} s)",  # diagnose
    "dofs in {t} s",  # verify, the convergence line
    "built in {t} s",  # geometry, the pinion mesh line
)
#: text-table columns of wall times: the figure that ends under the header is masked
WALL_TIME_COLUMNS = ("wall ms", "wall s", "FE s")
#: --json stdout keys (at any depth) that hold wall times
WALL_TIME_KEYS = re.compile(r"^(wall_s|compile_s|build_s|timing|.*_wall_s)$")
#: the source code's fingerprint and what follows from it in the same JSON document
FINGERPRINT_KEYS = {"code_sha256", "code_modules"}
FINGERPRINT_DERIVED = {"input_sha256", "file"}
MASK = "<t>"


class SetupError(Exception):
    """A revision cannot be checked out, installed or imported: one line, exit status 2."""


@dataclass
class Revision:
    role: str  # before | after
    rev: str  # as given
    sha: str
    root: Path  # the worktree
    ex: Path  # the shared inputs' examples/ folder
    runs: dict[str, Run] = field(default_factory=dict)
    setup_s: float = 0.0

    @property
    def scratch(self) -> Path:
        return self.root / ".cmp"

    @property
    def venv(self) -> Path:
        return self.root / ".venv"


@dataclass
class Run:
    rc: int | None  # None: timed out
    wall_s: float
    stdout: Path
    stderr: Path
    out: Path | None  # the --out folder, if the command writes one


@dataclass
class Verdict:
    differs: list[str] = field(default_factory=list)
    fingerprint: list[str] = field(default_factory=list)  # "file: key path"

    def line(self) -> str:
        if self.differs:
            return "DIFFERS: " + "; ".join(self.differs)
        if self.fingerprint:
            return "differs only in code fingerprint (keys " + ", ".join(self.fingerprint) + ")"
        return "same"


# ---------------------------------------------------------------------------------------------
# Setting a revision up
# ---------------------------------------------------------------------------------------------
def sh(cmd: list[str], cwd: Path | None = None, env: dict[str, str] | None = None) -> str:
    """Run a setup command; its stdout, or SetupError with the tail of its stderr."""
    p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        raise SetupError(f"{' '.join(cmd[:4])} ... failed: {tail(p.stderr or p.stdout)}")
    return p.stdout


def git(*args: str) -> str:
    return sh(["git", "-C", str(REPO), *args]).strip()


def resolve(rev: str) -> str:
    try:
        return git("rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}")
    except SetupError:
        raise SetupError(f"{rev!r} is not a commit of {REPO} (commit the working tree's changes first)") from None


def extract_inputs(sha: str, dest: Path) -> Path:
    """examples/ of ``sha`` into dest/examples: the input files both revisions read."""
    p = subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", sha, "examples"], capture_output=True)
    if p.returncode != 0:
        raise SetupError(f"git archive {sha[:9]} examples failed: {tail(p.stderr.decode(errors='replace'))}")
    data = p.stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(dest, filter="data")
    return dest / "examples"


def purelib(python: Path) -> Path:
    return Path(sh([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).strip())


def build_requirements(src: Path) -> list[str]:
    with open(src / "pyproject.toml", "rb") as f:
        return list(tomllib.load(f).get("build-system", {}).get("requires", ["setuptools", "wheel"]))


def make_venv(r: Revision) -> Path:
    """The revision's venv: gearwear editable from the worktree, third-party packages read from
    the repository's .venv through a .pth. Returns its python."""
    sh([str(MAIN_PYTHON), "-m", "venv", str(r.venv)])
    py = r.venv / "bin" / "python"
    env = {**os.environ, "PIP_DISABLE_PIP_VERSION_CHECK": "1"}
    env.pop("PYTHONPATH", None)
    sh([str(py), "-m", "pip", "install", "--quiet", *build_requirements(r.root)], env=env)
    sh([str(py), "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation", "-e", str(r.root)], env=env)
    (purelib(py) / "_gearwear_compare_main_site.pth").write_text(f"{purelib(MAIN_PYTHON)}\n")
    return py


def check_imports(r: Revision, py: Path) -> None:
    """gearwear and gearwear.fem (a layer installed through the package-dir mapping) must import
    from the worktree, not from the repository's checkout; run as the commands are (in the run
    folder; -P: no script folder on sys.path, as for a console script)."""
    code = "import json, gearwear, gearwear.fem; print(json.dumps([gearwear.__file__, gearwear.fem.__file__]))"
    for f in json.loads(sh([str(py), "-P", "-c", code], cwd=r.scratch / "run", env=run_env(r))):
        if not Path(f).resolve().is_relative_to(r.root.resolve()):
            raise SetupError(f"{r.role} ({r.rev}): {f} imports from outside its worktree {r.root}")


def run_env(r: Revision) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env.update(
        GEARWEAR_CACHE=str(r.scratch / "gearwear-cache"),
        NUMBA_CACHE_DIR=str(r.scratch / "numba-cache"),
        MPLCONFIGDIR=str(r.scratch / "mplconfig"),
        PATH=f"{r.venv / 'bin'}{os.pathsep}{os.environ['PATH']}",
        PIP_DISABLE_PIP_VERSION_CHECK="1",
    )
    return env


def set_up(r: Revision) -> None:
    t0 = time.perf_counter()
    if r.root.exists():
        raise SetupError(
            f"{r.root} exists (an earlier --keep?): remove it with git worktree remove --force, "
            "or choose another --work"
        )
    git("worktree", "add", "--quiet", "--detach", str(r.root), r.sha)
    py = make_venv(r)
    for d in ("run", "stdout", "gearwear-cache", "numba-cache", "mplconfig"):
        (r.scratch / d).mkdir(parents=True, exist_ok=True)
    check_imports(r, py)
    r.setup_s = time.perf_counter() - t0
    progress(r, "set-up (worktree, venv, editable install)", r.setup_s, "")


# ---------------------------------------------------------------------------------------------
# Running the commands
# ---------------------------------------------------------------------------------------------
def progress(r: Revision, what: str, wall_s: float, note: str) -> None:
    print(f"[{r.role} {r.sha[:9]}] {what:<44} {wall_s:7.1f} s  {note}".rstrip(), flush=True)


def run_command(r: Revision, name: str, argv: tuple[str, ...]) -> Run:
    out = Path("out") / name
    args = [a.format(out=out, ex=r.ex) for a in argv]
    stdout, stderr = r.scratch / "stdout" / f"{name}.txt", r.scratch / "stdout" / f"{name}.stderr.txt"
    t0 = time.perf_counter()
    with open(stdout, "wb") as fo, open(stderr, "wb") as fe:
        p = subprocess.Popen(
            [str(r.venv / "bin" / "gearwear"), *args],
            cwd=r.scratch / "run",
            env=run_env(r),
            stdin=subprocess.DEVNULL,
            stdout=fo,
            stderr=fe,
            start_new_session=True,
        )
        try:
            rc: int | None = p.wait(timeout=COMMAND_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGTERM)  # its own session: the command and its worker processes
            p.wait()
            rc = None
        except BaseException:
            os.killpg(p.pid, signal.SIGTERM)
            p.wait()
            raise
    wall = time.perf_counter() - t0
    progress(r, name, wall, "" if rc == 0 else f"FAILED ({status(rc)})")
    return Run(rc, wall, stdout, stderr, r.scratch / "run" / out if "{out}" in argv else None)


def status(rc: int | None) -> str:
    return f"timed out after {COMMAND_TIMEOUT_S} s" if rc is None else f"exit status {rc}"


def tail(text: str, n: int = 3) -> str:
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    return " | ".join(ln.strip()[-200:] for ln in lines[-n:]) or "(nothing on stderr)"


# ---------------------------------------------------------------------------------------------
# Comparing
# ---------------------------------------------------------------------------------------------
def first_difference(a: bytes, b: bytes) -> int:
    """Offset of the first differing byte (the shorter length if one is a prefix of the other)."""
    n = min(len(a), len(b))
    step = 1 << 16
    for i in range(0, n, step):
        hi = min(i + step, n)
        if a[i:hi] != b[i:hi]:
            return next(j for j in range(i, hi) if a[j] != b[j])
    return n


def show_path(path: tuple) -> str:
    s = ""
    for k in path:
        s += f"[{k}]" if isinstance(k, int) else (f".{k}" if re.fullmatch(r"\w+", k) else f"[{json.dumps(k)}]")
    return s.lstrip(".") or "(top)"


def json_diff(a: Any, b: Any, path: tuple = ()) -> list[tuple[tuple, Any, Any]]:
    """(path, before, after) of every leaf that differs; lists of different lengths and
    values of different types differ as a whole."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for k in sorted(set(a) | set(b)):
            out += json_diff(a.get(k, "<absent>"), b.get(k, "<absent>"), (*path, k))
        return out
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in json_diff(x, y, (*path, i))]
    same = (
        a == b
        and type(a) is type(b)
        or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))
    )
    return [] if same else [(path, a, b)]


def is_fingerprint(path: tuple) -> bool:
    return any(k in FINGERPRINT_KEYS for k in path)


def split_fingerprint(diffs: list, renamed: set) -> tuple[list, list]:
    """(fingerprint diffs, other diffs) of one JSON document. A derived key (input_sha256, file)
    counts only in a document whose fingerprint itself differs; its before/after pair goes into
    ``renamed`` so that the same hash elsewhere (--json stdout) is recognised."""
    has_fp = any(is_fingerprint(p) for p, _, _ in diffs)
    fp, other = [], []
    for p, x, y in diffs:
        derived = has_fp and p and p[-1] in FINGERPRINT_DERIVED and isinstance(x, str) and isinstance(y, str)
        if is_fingerprint(p) or derived or (isinstance(x, str) and isinstance(y, str) and (x, y) in renamed):
            fp.append((p, x, y))
            if derived:
                renamed.add((x, y))
                renamed.add((x.removesuffix(".csv"), y.removesuffix(".csv")))
        else:
            other.append((p, x, y))
    return fp, other


def describe(diffs: list, n: int = 3) -> str:
    shown = [f"{show_path(p)}: {json.dumps(x)[:60]} -> {json.dumps(y)[:60]}" for p, x, y in diffs[:n]]
    more = f" (+{len(diffs) - n} more)" if len(diffs) > n else ""
    return ", ".join(shown) + more


def compare_json_file(name: str, a: bytes, b: bytes, renamed: set, fp_files: set, v: Verdict) -> None:
    try:
        da, db = json.loads(a), json.loads(b)
    except ValueError:
        v.differs.append(f"{name} differs at byte {first_difference(a, b)} (not JSON on one side)")
        return
    diffs = json_diff(da, db)
    if not diffs:
        v.differs.append(f"{name} differs at byte {first_difference(a, b)} (same JSON data, other bytes)")
        return
    if Path(name).name == "manifest.json":
        folder = str(Path(name).parent).removeprefix(".").lstrip("/")
        follows = {str(Path(folder) / f) if folder else f for f in fp_files}
        fp = [
            d
            for d in diffs
            if len(d[0]) == 3 and d[0][0] == "files" and d[0][2] in ("sha256", "bytes") and d[0][1] in follows
        ]
        other = [d for d in diffs if d not in fp]
    else:
        fp, other = split_fingerprint(diffs, renamed)
    if other:
        v.differs.append(f"{name} differs at byte {first_difference(a, b)}: {describe(other)}")
    elif fp:
        fp_files.add(name)
        v.fingerprint.append(f"{name}: " + " ".join(sorted({show_path(p) for p, _, _ in fp})))


def files_of(folder: Path | None) -> dict[str, Path]:
    if folder is None or not folder.is_dir():
        return {}
    return {
        p.relative_to(folder).as_posix(): p
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name not in NOT_COMPARED
    }


def compare_folders(a: Path | None, b: Path | None, v: Verdict, renamed: set) -> None:
    fa, fb = files_of(a), files_of(b)
    if set(fa) != set(fb):
        v.differs.append(
            f"files only before: {sorted(set(fa) - set(fb)) or '-'}, only after: {sorted(set(fb) - set(fa)) or '-'}"
        )
    fp_files: set[str] = set()
    common = sorted(set(fa) & set(fb), key=lambda n: (Path(n).name == "manifest.json", n))  # manifests last
    for name in common:
        x, y = fa[name].read_bytes(), fb[name].read_bytes()
        if x == y:
            continue
        if name.endswith(".json"):
            compare_json_file(name, x, y, renamed, fp_files, v)
        else:
            v.differs.append(f"{name} differs at byte {first_difference(x, y)} (sizes {len(x)}, {len(y)})")


def mask_phrase(line: str, rx: re.Pattern) -> str:
    def blank(m: re.Match) -> str:
        s, base = m.group(0), m.start()
        for g in range(m.re.groups, 0, -1):
            lo, hi = m.span(g)
            s = s[: lo - base] + MASK + s[hi - base :]
        return s

    return rx.sub(blank, line)


PHRASE_RX = tuple(re.compile(re.escape(p).replace(re.escape("{t}"), f"({TIME})")) for p in WALL_TIME_PHRASES)
COLUMN_RX = tuple(re.compile(rf"(?<!\S){re.escape(c)}(?!\S)") for c in WALL_TIME_COLUMNS)
NUMBER_RX = re.compile(rf"-?{TIME}")


def mask_text(text: str) -> list[str]:
    """The lines of a text stdout with its wall-time figures replaced by <t>."""
    out, end = [], None
    for line in text.splitlines():
        if end is not None:  # a row of a table with a wall-time column ending at `end`
            tok = next(
                (m for m in re.finditer(r"\S+", line) if m.end() == end and NUMBER_RX.fullmatch(m.group())), None
            )
            if tok is not None:
                out.append(f"{line[: tok.start()].rstrip()} {MASK}{line[tok.end() :]}")  # the padding varies too
                continue
            end = None
        for rx in COLUMN_RX:
            m = rx.search(line)
            if m:
                end = m.end()
        for rx in PHRASE_RX:
            line = mask_phrase(line, rx)
        out.append(line)
    return out


def strip_wall_keys(o: Any) -> Any:
    if isinstance(o, dict):
        return {k: strip_wall_keys(v) for k, v in o.items() if not WALL_TIME_KEYS.match(k)}
    if isinstance(o, list):
        return [strip_wall_keys(v) for v in o]
    return o


def compare_stdout(argv: tuple[str, ...], a: Path, b: Path, v: Verdict, renamed: set) -> None:
    x, y = a.read_text(errors="replace"), b.read_text(errors="replace")
    if "--json" in argv:
        try:
            dx, dy = strip_wall_keys(json.loads(x)), strip_wall_keys(json.loads(y))
        except ValueError:
            pass  # not one JSON object: compared as text
        else:
            fp, other = split_fingerprint(json_diff(dx, dy), renamed)
            if other:
                v.differs.append(f"stdout (--json, wall-time keys dropped): {describe(other)}")
            elif fp:
                v.fingerprint.append("stdout: " + " ".join(sorted({show_path(p) for p, _, _ in fp})))
            return
    lx, ly = mask_text(x), mask_text(y)
    if lx != ly:
        i = next((i for i, (p, q) in enumerate(zip(lx, ly)) if p != q), min(len(lx), len(ly)))
        p, q = (lx[i] if i < len(lx) else "<end>"), (ly[i] if i < len(ly) else "<end>")
        c = first_difference(p.encode(), q.encode())
        v.differs.append(f"stdout line {i + 1} column {c + 1}: {excerpt(p, c)!r} -> {excerpt(q, c)!r}")


def excerpt(line: str, col: int, before: int = 30, after: int = 40) -> str:
    """The part of ``line`` around the column where it first differs."""
    lo = max(0, col - before)
    return ("..." if lo else "") + line[lo : col + after] + ("..." if len(line) > col + after else "")


def compare_command(name: str, argv: tuple[str, ...], a: Run, b: Run) -> Verdict:
    v = Verdict()
    for role, r in (("before", a), ("after", b)):
        if r.rc != 0:
            v.differs.append(f"{role}: {status(r.rc)}: {tail(r.stderr.read_text(errors='replace'))}")
    if v.differs:
        return v
    renamed: set = set()
    compare_folders(a.out, b.out, v, renamed)
    compare_stdout(argv, a.stdout, b.stdout, v, renamed)
    return v


# ---------------------------------------------------------------------------------------------
# Main
# ---------------------------------------------------------------------------------------------
def remove(revs: list[Revision], work: Path, own_work: bool) -> None:
    for r in revs:
        if r.root.exists():
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(r.root)], capture_output=True)
            shutil.rmtree(r.root, ignore_errors=True)
    subprocess.run(["git", "-C", str(REPO), "worktree", "prune"], capture_output=True)
    shutil.rmtree(work / "inputs", ignore_errors=True)
    if own_work:
        shutil.rmtree(work, ignore_errors=True)


def report(revs: list[Revision], t0: float) -> int:
    before, after = revs
    counts = {"same": 0, "fingerprint": 0, "DIFFERS": 0}
    print(
        f"\ncomparison of {before.rev} ({before.sha[:9]}) and {after.rev} ({after.sha[:9]}); "
        f"not compared: {', '.join(sorted(NOT_COMPARED))}, stderr, wall-time figures of stdout"
    )
    for name, argv in COMMANDS:
        v = compare_command(name, argv, before.runs[name], after.runs[name])
        counts["DIFFERS" if v.differs else "fingerprint" if v.fingerprint else "same"] += 1
        print(f"  {name:<24} {v.line()}")
    wall = {r.role: r.setup_s + sum(x.wall_s for x in r.runs.values()) for r in revs}
    print(
        f"summary: {len(COMMANDS)} commands: {counts['same']} same, {counts['fingerprint']} differ only in "
        f"code fingerprint, {counts['DIFFERS']} DIFFER; wall time before {wall['before']:.0f} s, "
        f"after {wall['after']:.0f} s, total {time.perf_counter() - t0:.0f} s"
    )
    return 1 if counts["DIFFERS"] else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("before", help="the revision before the change (a commit)")
    ap.add_argument("after", help="the revision after the change (a commit)")
    ap.add_argument(
        "--work",
        type=Path,
        help="folder for the worktrees, venvs, caches and outputs "
        "(default: a temporary folder, deleted at the end unless --keep)",
    )
    ap.add_argument("--keep", action="store_true", help="keep the worktrees, venvs and outputs")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    own_work = args.work is None
    work = Path(tempfile.mkdtemp(prefix="gearwear-compare-")) if own_work else args.work.resolve()
    revs: list[Revision] = []
    try:
        if not MAIN_PYTHON.exists():
            raise SetupError(f"{MAIN_PYTHON} missing: make venv first (its packages are shared)")
        work.mkdir(parents=True, exist_ok=True)
        shas = [resolve(args.before), resolve(args.after)]
        ex = extract_inputs(shas[0], work / "inputs")
        revs = [
            Revision(role, rev, sha, work / f"{role}-{sha[:12]}", ex)
            for role, rev, sha in zip(("before", "after"), (args.before, args.after), shas)
        ]
        for r in revs:
            set_up(r)
            for name, cmd in COMMANDS:
                r.runs[name] = run_command(r, name, cmd)
        return report(revs, t0)
    except SetupError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    finally:
        if args.keep:
            print(f"kept: {work}", file=sys.stderr)
        else:
            remove(revs, work, own_work)


if __name__ == "__main__":
    sys.exit(main())
