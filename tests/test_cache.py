"""Calibrated-table cache: code fingerprint in the key, entries checked on read, bad entries
recomputed with a one-line message, a bad $GEARWEAR_CACHE rejected before any computation.

The FE stages (run_fe, pair_correction) are replaced by fixed corrections, so each table
costs one analytic TVMS (milliseconds); tests/test_calibrate.py runs the real FE and checks
that a real table passes the same checks on a cache hit.
"""

import json
import os
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from gearwear.core.validation import InputError
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import WearSpec
from gearwear.stiffness import calibration as calibrate
from gearwear.stiffness import tables

POINTS = 120


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("GEARWEAR_CACHE", str(folder))
    return folder


@pytest.fixture
def fe_runs(monkeypatch):
    """Replace both FE stages; the list records each (wear) for which the FE would have run."""
    runs = []
    corr = calibrate.fit_correction(np.linspace(0.040, 0.050, 9), np.linspace(1.25, 1.10, 9), np.ones(9))
    fe = SimpleNamespace(ndofs=1, n_elements=1, order=2, plane="stress")

    def run_fe(pair, wear, positions=21, estimate_error=True, executor=None, plane="stress"):
        runs.append(wear)
        return calibrate.Calibration(pair, wear, (fe, fe), (corr, corr), 0.0, 0.0)

    monkeypatch.setattr(calibrate, "run_fe", run_fe)
    monkeypatch.setattr(
        calibrate,
        "pair_correction",
        lambda *a, **k: calibrate.PairCorrection(1.0, 0.97, 0.0, 0.0, 0.0, 3.4e8, 3.4e8, 0.0),
    )
    return runs


def table(wear=None, clearance_m=0.0, **kw):
    return calibrate.calibrated_table(default_pair(), wear, clearance_m, 40.0, POINTS, **kw)


def entry(folder, wear=None, clearance_m=0.0):
    key = tables.table_key(calibrate.table_inputs(default_pair(), wear, clearance_m, 40.0, POINTS, 21))
    return key, folder / f"{key}.csv"


def test_cold_then_hit(cache, fe_runs, capsys):
    a = table()
    b = table()
    assert fe_runs == [None] and not a.from_cache and b.from_cache
    assert np.array_equal(a.k_N_per_m, b.k_N_per_m) and a.meta == b.meta
    # the uniform nodes and the breakpoints of the load sharing (analytic.tvms) on top
    assert len(a.k_N_per_m) == a.meta["rows"] > POINTS and np.all(a.k_N_per_m > 0)
    assert np.all(np.isin(np.round(np.arange(POINTS) * (a.span_rad / POINTS), 12), np.round(a.angle_rad, 12)))
    key, csv = entry(cache)
    meta = json.loads((cache / f"{key}.csv.json").read_text())
    assert meta["inputs"]["code_sha256"] == calibrate.code_fingerprint()
    assert meta["inputs"]["calibration_version"] == calibrate.CALIBRATION_VERSION
    assert "gearwear.fem.pair" in meta["code_modules"]
    assert len(meta["csv_sha256"]) == 64
    assert capsys.readouterr().err == ""


def test_stale_code_is_not_reused(cache, fe_runs, monkeypatch, capsys):
    monkeypatch.setattr(calibrate, "code_fingerprint", lambda: "1" * 64)  # the code the table was made with
    old = table()
    monkeypatch.setattr(calibrate, "code_fingerprint", lambda: "2" * 64)  # the calibration code changed
    new = table()
    assert len(fe_runs) == 2 and not new.from_cache
    assert old.meta["input_sha256"] != new.meta["input_sha256"]
    assert new.meta["inputs"]["code_sha256"] == "2" * 64
    assert len(list(cache.glob("*.csv"))) == 2
    assert capsys.readouterr().err == ""  # another key: a plain miss, nothing to report


def _damage(csv, edit):
    lines = csv.read_text().split("\n")
    csv.write_text(edit(lines))


@pytest.mark.parametrize(
    "edit, reason",
    [
        (lambda ls: "\n".join(ls[:41]) + "\n", "is truncated (40 of {rows} rows)"),
        (lambda ls: "\n".join(ls[:41]) + "\n" + ls[41][:9], "is truncated (40 of {rows} rows, the last one cut)"),
        (lambda ls: "\n".join(ls[:9] + ["garbage"] + ls[10:]), "has an unreadable line 10 ('garbage')"),
        (
            lambda ls: "\n".join(ls[:5] + [ls[5].replace(ls[5].split(",")[1], "nan")] + ls[6:]),
            "has a non-finite k_N_per_m (nan) on line 6",
        ),
        (
            lambda ls: "\n".join(ls[:5] + [ls[5].replace(ls[5].split(",")[1], "0")] + ls[6:]),
            "has k_N_per_m = 0 on line 6 with",
        ),
        (lambda ls: "\n".join(ls[:-1] + ls[1:]), "has {twice} rows, expected {rows}"),
        (lambda ls: "\n".join(["angle,k"] + ls[1:]), "has no valid header line"),
    ],
)
def test_bad_entry_is_recomputed_with_one_line(cache, fe_runs, capsys, edit, reason):
    good = table()
    key, csv = entry(cache)
    reason = reason.format(rows=len(good.k_N_per_m), twice=2 * len(good.k_N_per_m))  # the rows its sidecar records
    _damage(csv, edit)
    assert tables.lookup(calibrate.table_inputs(default_pair(), None, 0.0, 40.0, POINTS, 21))[0] is None
    again = table()
    err = capsys.readouterr().err
    assert err.startswith(f"gearwear: cache entry {key[:8]}... (unworn, 0 um) {reason}")
    assert err.endswith("; recomputing\n") and err.count("\n") == 1
    assert len(fe_runs) == 2 and not again.from_cache
    assert np.array_equal(again.k_N_per_m, good.k_N_per_m)
    hit = table()  # the entry was rewritten and is valid again
    assert hit.from_cache and len(fe_runs) == 2 and capsys.readouterr().err == ""


def test_bytes_not_matching_the_sidecar(cache, fe_runs, capsys):
    table()
    key, csv = entry(cache)
    lines = csv.read_text().split("\n")
    k = lines[3].split(",")
    k[1] = repr(float(k[1]) * 1.1)  # still a valid table, but not the one stored
    lines[3] = ",".join(k)
    csv.write_text("\n".join(lines))
    messages = []
    again = table(notify=messages.append)
    assert messages == [
        f"cache entry {key[:8]}... (unworn, 0 um) does not match the csv_sha256 of its "
        "sidecar (changed after it was stored); recomputing"
    ]
    assert not again.from_cache and len(fe_runs) == 2 and capsys.readouterr().err == ""


def test_sidecar_problems(cache, fe_runs):
    table(WearSpec(phase="mild"), 10e-6)
    inputs = calibrate.table_inputs(default_pair(), WearSpec(phase="mild"), 10e-6, 40.0, POINTS, 21)
    key, csv = entry(cache, WearSpec(phase="mild"), 10e-6)
    side = cache / f"{key}.csv.json"
    meta = json.loads(side.read_text())
    del meta["csv_sha256"]
    side.write_text(json.dumps(meta))
    assert tables.lookup(inputs) == (None, "has no csv_sha256 in its sidecar")
    side.write_text("{")
    assert tables.lookup(inputs) == (None, "has an unreadable sidecar (JSONDecodeError)")
    side.unlink()
    assert tables.lookup(inputs) == (None, "has no sidecar")
    messages = []
    table(WearSpec(phase="mild"), 10e-6, notify=messages.append)
    assert messages == [f"cache entry {key[:8]}... (mild, 10 um) has no sidecar; recomputing"]
    csv.unlink()
    assert tables.lookup(inputs) == (None, "has a sidecar but no data")
    (cache / f"{key}.csv.json").unlink()
    assert tables.lookup(inputs) == (None, None)  # no entry at all: a plain miss


def test_refresh_and_lazy_calibration(cache, fe_runs):
    made = []

    def lazy():
        made.append(1)
        return calibrate.run_fe(default_pair(), None)

    table(calibration=lazy)
    table(calibration=lazy)  # a hit: the FE stage is never asked for
    assert made == [1] and len(fe_runs) == 1
    assert not table(refresh=True).from_cache and len(fe_runs) == 2


def test_cache_folder_that_is_a_file(tmp_path, monkeypatch, fe_runs):
    f = tmp_path / "not-a-folder"
    f.write_text("x")
    monkeypatch.setenv("GEARWEAR_CACHE", str(f))
    with pytest.raises(InputError) as exc:
        table()
    assert str(exc.value) == f"GEARWEAR_CACHE = {f}: is a file, not a folder"
    monkeypatch.setenv("GEARWEAR_CACHE", str(f / "sub"))
    with pytest.raises(InputError, match=r"^GEARWEAR_CACHE = .*/not-a-folder/sub: cannot be created \(") as exc:
        table()
    assert "\n" not in str(exc.value)
    assert fe_runs == []  # raised before any computation


def test_cli_cache_folder_that_is_a_file(tmp_path):
    f = tmp_path / "not-a-folder"
    f.write_text("x")
    env = {**os.environ, "GEARWEAR_CACHE": str(f)}
    r = subprocess.run(
        [sys.executable, "-m", "gearwear.cli", "calibrate", "--points", "48"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr == f"gearwear: error: GEARWEAR_CACHE = {f}: is a file, not a folder\n"


def test_fingerprint_follows_the_source():
    mods = calibrate.code_modules()
    for m in (
        "gearwear.stiffness.calibration",
        "gearwear.stiffness.tables",
        "gearwear.stiffness.comparison",
        "gearwear.io",
        "gearwear.fem.pair",
        "gearwear.fem.tooth",
        "gearwear.fem.pair_body",
        "gearwear.fem.contact",
        "gearwear.fem.elasticity",
        "gearwear.fem.mesh",
        "gearwear.analytic.tvms",
        "gearwear.analytic.ishikawa",
        "gearwear.geometry.wear",
        "gearwear.geometry.profile",
        "gearwear.geometry.kinematics",
        "gearwear.core.validation",
    ):
        assert m in mods
    assert list(mods) == sorted(mods)
    assert not [m for m in mods if m == "gearwear" or m.startswith(("gearwear.dynamics", "gearwear.cli.app"))]
    base = calibrate.fingerprint(mods)
    assert base == calibrate.code_fingerprint() and len(base) == 64
    assert calibrate.fingerprint(reversed(mods)) == base  # order-independent
    read = calibrate._source_bytes
    # one changed byte in any one file changes the fingerprint
    for changed in ("gearwear.fem.pair", "gearwear.stiffness.tables", "gearwear.geometry.wear"):
        edited = calibrate.fingerprint(mods, read=lambda m: read(m) + (b"#" if m == changed else b""))
        assert edited != base


def test_fingerprint_does_not_depend_on_where_the_files_are(tmp_path):
    """A fresh clone elsewhere (or a wheel in site-packages) has the same names and bytes."""
    mods = calibrate.code_modules()
    for m in mods:
        (tmp_path / f"{m}.py").write_bytes(calibrate._source_bytes(m).replace(b"\n", b"\r\n"))
    elsewhere = calibrate.fingerprint(mods, read=lambda m: (tmp_path / f"{m}.py").read_bytes().replace(b"\r\n", b"\n"))
    assert elsewhere == calibrate.code_fingerprint()


def test_dependencies_follow_imports_inside_functions():
    """Relative imports at one and two levels, and an import inside a function, are followed."""
    src = {
        "gearwear.stiffness.calibration": b"from . import tables\ndef f():\n    from gearwear.fem import pair\n",
        "gearwear.stiffness.tables": b"from .. import io\n",
        "gearwear.io": b"from . import __version__\n",
    }
    deps = calibrate.dependencies("gearwear.stiffness.calibration", read=lambda m: src.get(m, b""))
    assert deps == (
        "gearwear.fem",
        "gearwear.fem.pair",
        "gearwear.io",
        "gearwear.stiffness",
        "gearwear.stiffness.calibration",
        "gearwear.stiffness.tables",
    )


def test_a_computed_table_that_fails_the_checks_is_not_stored_silently(cache):
    tab = tables.StiffnessTable(
        np.linspace(0, 0.1, 8), np.full(8, np.nan), np.zeros(8), np.zeros(8), np.ones(8, dtype=int), {}
    )
    with pytest.raises(ValueError, match="the computed table has a non-finite k_N_per_m"):
        tables.store(tab, {"kind": "test", "points": 8}, "test")


# -- an entry that is not a regular file ------------------------------------------------------


def _within(seconds, fn):
    """fn() run in a thread that must finish within ``seconds``: a read that waited on a FIFO
    would fail the test instead of hanging it."""
    import threading

    box = {}
    t = threading.Thread(target=lambda: box.setdefault("result", fn()), daemon=True)
    t.start()
    t.join(seconds)
    assert not t.is_alive(), f"still running after {seconds} s (waiting on the damaged entry?)"
    return box["result"]


def _break(path, damage):
    """Put something that is not a cache file at ``path``."""
    if damage == "unreadable" and os.geteuid() == 0:
        pytest.skip("root reads a chmod 000 file")
    path.unlink()
    if damage == "folder":
        path.mkdir()
        (path / "x").write_text("x")
    elif damage == "fifo":
        os.mkfifo(path)
    elif damage == "dev-zero":
        path.symlink_to("/dev/zero")
    else:
        path.write_bytes(b"x")
        path.chmod(0)


DAMAGES = ["folder", "fifo", "dev-zero", "unreadable"]


@pytest.mark.parametrize("which", ["data", "sidecar"])
@pytest.mark.parametrize("damage", DAMAGES)
def test_a_table_entry_that_is_not_a_regular_file_is_recomputed(cache, fe_runs, capsys, damage, which):
    good = table()
    key, csv = entry(cache)
    _break(csv if which == "data" else csv.with_name(csv.name + ".json"), damage)
    again = _within(60, table)
    err = capsys.readouterr().err
    assert err.startswith(f"gearwear: cache entry {key[:8]}... (unworn, 0 um) ") and err.count("\n") == 1, err
    assert err.endswith("; recomputing\n") and ("is a" in err or "cannot be read" in err), err
    assert not again.from_cache and np.array_equal(again.k_N_per_m, good.k_N_per_m)
    assert table().from_cache and csv.is_file() and not csv.is_symlink()  # stored again, over the damage


@pytest.fixture(scope="module")
def surrogate(tmp_path_factory):
    """A small diagnosis surrogate (8 design points) of the example scene, built once in
    this process: (its BuildSpec, the cache folder)."""
    from pathlib import Path

    from gearwear.cli import diagnose as dc
    from gearwear.diagnose import surrogate as ds
    from gearwear.scene.files import load_scene_dict
    from gearwear.scene.model import scene_from_dict

    folder = tmp_path_factory.mktemp("surrogate-cache")
    old = os.environ.get("GEARWEAR_CACHE")
    os.environ["GEARWEAR_CACHE"] = str(folder)
    try:
        raw, name = load_scene_dict(str(Path(__file__).parents[1] / "examples" / "diagnose" / "scene.toml"))
        unknowns = dc.parse_unknowns("wear,clearance")
        lo, hi = dc.prior_ranges(raw, unknowns, {})
        K = int(scene_from_dict(raw, name=name).output["harmonics"])
        spec = ds.BuildSpec(raw, name, unknowns, lo, hi, K, 8, dc.HOLDOUT_POINTS[2])
        ds.build(spec, notify=None)
    finally:
        if old is None:
            os.environ.pop("GEARWEAR_CACHE")
        else:
            os.environ["GEARWEAR_CACHE"] = old
    return spec, folder


@pytest.mark.parametrize("which", ["data", "sidecar"])
@pytest.mark.parametrize("damage", DAMAGES)
def test_a_surrogate_entry_that_is_not_a_regular_file_is_refused_on_read(surrogate, tmp_path, damage, which):
    import shutil

    from gearwear.diagnose import surrogate as ds

    spec, built = surrogate
    folder = tmp_path / "cache"
    shutil.copytree(built, folder)
    inputs = spec.inputs()
    npz = folder / f"{tables.table_key(inputs)}.npz"
    assert _within(60, lambda: ds.lookup(inputs, spec.unknowns, folder))[0] is not None
    _break(npz if which == "data" else npz.with_name(npz.name + ".json"), damage)
    sur, reason = _within(60, lambda: ds.lookup(inputs, spec.unknowns, folder))
    assert sur is None and ("is a" in reason or "cannot be read" in reason), reason


def test_a_surrogate_entry_replaced_by_a_folder_is_rebuilt_and_stored(surrogate, tmp_path, monkeypatch):
    import shutil

    from gearwear.diagnose import surrogate as ds

    spec, built = surrogate
    folder = tmp_path / "cache"
    shutil.copytree(built, folder)
    monkeypatch.setenv("GEARWEAR_CACHE", str(folder))
    key = tables.table_key(spec.inputs())
    _break(folder / f"{key}.npz", "folder")
    lines = []
    sur = _within(300, lambda: ds.build(spec, notify=lines.append))
    assert lines == [f"cache entry {key[:8]}... (diagnose surrogate) is a folder, not a file; recomputing"]
    assert not sur.from_cache and (folder / f"{key}.npz").is_file()
    assert ds.build(spec, notify=lines.append).from_cache and len(lines) == 1
