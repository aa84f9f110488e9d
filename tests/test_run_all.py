"""``make bench`` (benchmarks/run_all.py) runs every script to the end, each as if alone: a
script that ends with ``sys.exit(0)`` used to end the whole run there (runpy in one
process), and one script's leftover state changed the next one's results. Checked on
throw-away scripts: one that exits 0, one that exits 3, one that raises, one that leaves
state behind, and one that writes a marker and whether it saw that state; all run, the
failures are named, no state crosses, and the run reports failure."""

from __future__ import annotations

import importlib.util
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
        "bench_c2.py": "import json\njson.LEFT_BEHIND = 1\n",
        "bench_d.py": (
            "import json\nfrom pathlib import Path\n"
            f"Path({str(marker)!r}).write_text(str(hasattr(json, 'LEFT_BEHIND')))\n"
        ),
    }
    for name, text in scripts.items():
        (tmp_path / name).write_text(text)
    failed = _run_all().run_scripts(sorted(tmp_path.glob("bench_*.py")))
    assert marker.read_text() == "False"  # ran, and in a fresh process
    assert failed == ["bench_b.py: exited with 3", "bench_c.py: exited with 1"]
    out = capsys.readouterr().out
    assert all(f"== {n}" in out for n in scripts)


def test_the_command_exits_1_and_names_the_failures(tmp_path, monkeypatch, capsys):
    mod = _run_all()
    monkeypatch.setattr(mod, "run_scripts", lambda scripts: ["bench_x.py: exited with 2"])
    assert mod.main([]) == 1
    assert "failed: bench_x.py: exited with 2" in capsys.readouterr().out
    monkeypatch.setattr(mod, "run_scripts", lambda scripts: [])
    assert mod.main(["bench_none.py"]) == 0
