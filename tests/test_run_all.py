"""``make bench`` (benchmarks/run_all.py) runs every script to the end, whatever one of them
does: a script that ends with ``sys.exit(0)`` used to end the whole run there (runpy in one
process), so the scripts after it never ran. Checked on throw-away scripts: one that exits
0, one that exits 3, one that raises, and one that writes a marker; all four run, the
failures are named, and the run reports failure."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run_all():
    spec = importlib.util.spec_from_file_location("run_all", ROOT / "benchmarks" / "run_all.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_every_script_runs_after_an_exit_or_an_error(tmp_path, capsys):
    marker = tmp_path / "ran"
    scripts = {
        "bench_a.py": "import sys\nsys.exit(0)\n",
        "bench_b.py": "import sys\nsys.exit(3)\n",
        "bench_c.py": "raise ValueError('boom')\n",
        "bench_d.py": f"from pathlib import Path\nPath({str(marker)!r}).write_text('yes')\n",
    }
    for name, text in scripts.items():
        (tmp_path / name).write_text(text)
    argv = list(sys.argv)
    failed = _run_all().run_scripts(sorted(tmp_path.glob("bench_*.py")))
    assert sys.argv == argv  # restored for the caller
    assert marker.read_text() == "yes"
    assert failed == ["bench_b.py: exited with 3", "bench_c.py: ValueError: boom"]
    out = capsys.readouterr().out
    assert all(f"== {n}" in out for n in scripts)


def test_the_command_exits_1_and_names_the_failures(tmp_path, monkeypatch, capsys):
    mod = _run_all()
    monkeypatch.setattr(mod, "run_scripts", lambda scripts: ["bench_x.py: exited with 2"])
    assert mod.main([]) == 1
    assert "failed: bench_x.py: exited with 2" in capsys.readouterr().out
    monkeypatch.setattr(mod, "run_scripts", lambda scripts: [])
    assert mod.main(["bench_none.py"]) == 0
