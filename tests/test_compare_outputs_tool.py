"""tools/compare_outputs.py's comparison rules, on made-up outputs (the tool itself runs every
command on two revisions: minutes, not a test)."""

import importlib.util
import json
import sys
from pathlib import Path

_spec = importlib.util.spec_from_file_location(
    "compare_outputs", Path(__file__).resolve().parents[1] / "tools" / "compare_outputs.py"
)
co = importlib.util.module_from_spec(_spec)
sys.modules["compare_outputs"] = co
_spec.loader.exec_module(co)


def test_wall_times_are_masked_and_nothing_else():
    a = (
        "method   wear      clear um    mean N/m  wall ms\n"
        "fem      unworn           0  3.4328e+08  16071.4\n"
        "scene x: 76800 steps (0 events), 3.49 s wall (integration 0.197 s, compile 3.10 s)\n"
        "wall time 1.9 s\n"
    )
    b = a.replace("3.4328e+08  16071.4", "3.4328e+08   7471.8").replace("3.49", "0.61").replace("1.9 s", "12.0 s")
    assert co.mask_text(a) == co.mask_text(b)
    assert co.mask_text(a.replace("3.4328e+08", "3.4329e+08")) != co.mask_text(b)  # a result digit counts
    assert co.strip_wall_keys({"wall_s": 1, "mesh": {"build_s": 2, "dofs": 3}, "duration_s": 0.5}) == {
        "mesh": {"dofs": 3},
        "duration_s": 0.5,
    }


def _table(code: str, extra: float) -> bytes:
    key = code * 8
    return json.dumps(
        {"inputs": {"code_sha256": code}, "input_sha256": key, "file": f"{key}.csv", "mean_N_per_m": extra}
    ).encode()


def test_code_fingerprint_is_reported_apart_and_a_result_is_not(tmp_path):
    for side, code in (("a", "1111"), ("b", "2222")):
        (tmp_path / side).mkdir()
        table = _table(code, 3.0e8)
        (tmp_path / side / "calibrated_x.csv.json").write_bytes(table)
        (tmp_path / side / "manifest.json").write_text(
            json.dumps(
                {"version": "0.1.0", "files": {"calibrated_x.csv.json": {"sha256": str(hash(table)), "bytes": 1}}}
            )
        )
    v = co.Verdict()
    co.compare_folders(tmp_path / "a", tmp_path / "b", v, set())
    assert not v.differs and v.line().startswith("differs only in code fingerprint")

    (tmp_path / "b" / "calibrated_x.csv.json").write_bytes(_table("2222", 3.1e8))
    v = co.Verdict()
    co.compare_folders(tmp_path / "a", tmp_path / "b", v, set())
    assert v.line().startswith("DIFFERS") and "mean_N_per_m" in v.line()


def test_first_difference():
    assert co.first_difference(b"abcdef", b"abcxef") == 3
    assert co.first_difference(b"abc", b"abcd") == 3
