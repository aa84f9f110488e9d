"""Packaging: the wheel installs one top-level name with every layer and the built-in scenes.
(Static types of the installed package: tools/check_types.py, run by ``make check`` and CI.)"""

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "-q", "-w", str(out)],
        check=True,
        capture_output=True,
        text=True,
    )
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
