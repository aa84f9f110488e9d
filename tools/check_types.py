"""Static types of the installed package: build the wheel, install it into a scratch folder
and run mypy (default mode, the [tool.mypy] settings of pyproject.toml) over it.

The wheel, not the source tree, because the layers install under ``gearwear.<layer>`` from
top-level folders (the package-dir mapping): only the installed layout shows whether every
``gearwear.*`` import resolves. Run by ``make check`` (and so by CI); exit status 0 when mypy
reports no error.

    .venv/bin/python tools/check_types.py
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    # setuptools builds in ROOT/build/lib and never deletes a module that has since moved: a stale
    # copy would enter the wheel and be type-checked (a moved module's old imports fail)
    shutil.rmtree(ROOT / "build" / "lib", ignore_errors=True)
    with tempfile.TemporaryDirectory() as tmp:
        out, site = Path(tmp) / "wheel", Path(tmp) / "site"
        subprocess.run(
            [sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "-q", "-w", str(out)],
            check=True,
            capture_output=True,
            text=True,
        )
        (whl,) = out.glob("gearwear-*.whl")
        subprocess.run(
            [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(site), str(whl)],
            check=True,
            capture_output=True,
            text=True,
        )
        r = subprocess.run(
            [
                sys.executable,
                "-m",
                "mypy",
                "-p",
                "gearwear",
                "--config-file",
                str(ROOT / "pyproject.toml"),
                "--cache-dir",
                str(Path(tmp) / "cache"),
            ],
            cwd=site,
            env=dict(os.environ, MYPYPATH=str(site)),
            capture_output=True,
            text=True,
        )
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    return r.returncode


if __name__ == "__main__":
    sys.exit(main())
