"""The README's Python API example runs as printed (from a neutral folder, so it uses
the installed package), and prints the figures the README quotes."""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_readme_python_api_example_runs(tmp_path):
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python API") :]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    first = r.stdout.splitlines()[0].split()
    # regression (see tests/test_regression_published.py): the comment on the first
    # print() quotes the two figures it prints, in the README's digits
    quoted = re.search(r"print\(k\.mean_N_per_m, k\.contact_ratio\)\s*#\s*(\d\.\d{3})e(\d) N/m, (\d\.\d{4})", code)
    assert quoted, "the README example no longer quotes the mean stiffness and contact ratio"
    mantissa, exponent, ratio = quoted.groups()
    k, eps = float(first[0]), float(first[1])
    assert f"{k / 10 ** int(exponent):.3f}" == mantissa and f"{eps:.4f}" == ratio, (first, quoted.groups())
