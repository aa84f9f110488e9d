"""gearwear: FE-verified mesh stiffness and dynamics of worn spur gears.

``import gearwear as gw`` gives the Python API (``gearwear.api``): ``gw.paper_pair()``,
``gw.Scene.load(...)``, ``gw.mesh_stiffness(...)``, ``gw.verify(...)``,
``gw.simulate(...)``, ``gw.sweep(...)``. The layers install as sub-packages:
``gearwear.core`` (errors, validation, atomic I/O), ``gearwear.geometry``,
``gearwear.analytic``, ``gearwear.fem``, ``gearwear.dynamics``; the rest of this
package is the app that wires them (docs/architecture.md).

The API names load on first use, so importing a sub-package stays cheap.
"""

from importlib.metadata import PackageNotFoundError as _NotInstalled
from importlib.metadata import version as _version
from typing import Any

try:  # one source of the version: pyproject.toml, through the installed metadata
    __version__ = _version("gearwear")
except _NotInstalled:  # a source tree used without installing it
    __version__ = "0+unknown"

_API = (
    "paper_pair",
    "pair",
    "wear",
    "mesh_stiffness",
    "verify",
    "simulate",
    "sweep",
    "Scene",
    "PairSpec",
    "WearSpec",
    "InputError",
    "METHODS",
)


def __getattr__(name: str) -> Any:
    if name in _API:
        from gearwear import api

        return getattr(api, name)
    raise AttributeError(f"module 'gearwear' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_API))


__all__ = ["__version__", *_API]
