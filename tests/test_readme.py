"""The README's Python API example runs as printed (from a neutral folder, so it uses
the installed package), and prints the figures the README quotes."""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_readme_python_api_example_runs(tmp_path):
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python API"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    first = r.stdout.splitlines()[0].split()
    # regression: the README quotes these two figures in a comment of the example
    assert f"{float(first[0]):.4g}" == "2.939e+08" and f"{float(first[1]):.5g}" == "1.6535"
