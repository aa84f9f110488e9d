"""The published tables are generated from the committed results, never typed: every
`<!-- generated: NAME -->` block of docs/*.md equals what docs/generate.py makes of its source
file (benchmarks/results/*.json, reports/**) today."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_generated_tables_are_up_to_date():
    r = subprocess.run([sys.executable, str(ROOT / "docs" / "generate.py"), "--check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def test_every_block_has_a_source():
    sys.path.insert(0, str(ROOT / "docs"))
    import generate

    names = {m.group("name") for doc in (ROOT / "docs").glob("*.md") for m in generate.BLOCK.finditer(doc.read_text())}
    assert names and names <= set(generate.TABLES)
