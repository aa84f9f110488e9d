"""Packaging: the wheel installs one top-level name, and static analysis resolves every
import of the installed package (mypy, default mode, over the wheel's files)."""

import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "-q", "-w", str(out)],
                   check=True, capture_output=True, text=True)
    (whl,) = out.glob("gearwear-*.whl")
    return whl


def test_wheel_installs_only_the_gearwear_package(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert top == {"gearwear"}
    # every layer is inside it, with the built-in scenes
    for sub in ("core", "geometry", "analytic", "fem", "dynamics", "data"):
        assert f"gearwear/{sub}/__init__.py" in names
    assert "gearwear/data/paper-default.toml" in names


def test_mypy_resolves_every_import_of_the_installed_package(wheel, tmp_path):
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(site), str(wheel)],
                   check=True, capture_output=True)
    env = dict(os.environ, MYPYPATH=str(site))
    r = subprocess.run([sys.executable, "-m", "mypy", "-p", "gearwear", "--config-file", str(ROOT / "pyproject.toml"),
                        "--cache-dir", str(tmp_path / "cache"), "--no-error-summary"],
                       cwd=site, env=env, capture_output=True, text=True)
    lines = [ln for ln in r.stdout.splitlines() if ": error:" in ln]
    unresolved = [ln for ln in lines if re.search(r"\[(import-not-found|import-untyped|import)\]", ln)
                  or re.search(r'Module "gearwear[.\w]*" has no attribute', ln)]
    assert not unresolved, "\n".join(unresolved)
    assert r.returncode in (0, 1) and "Traceback" not in r.stderr, r.stderr
    assert not lines, "\n".join(lines)
