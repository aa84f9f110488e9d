"""numba's disk cache of the kernels is keyed on every kernel source (dynamics.kernel_cache).

numba stamps a cached function with its own file only; the kernels span several modules
(dynamics/kernel_*.py), so without the common stamp an edit of ``_rhs`` would leave the
cached ``rk4`` and ``dopri5`` running the old right-hand side."""

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DYN = ROOT / "dynamics"


def _defines_njit(tree: ast.Module) -> bool:
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            for d in node.decorator_list:
                f = d.func if isinstance(d, ast.Call) else d
                if isinstance(f, ast.Name) and f.id == "njit" or isinstance(f, ast.Attribute) and f.attr == "njit":
                    return True
    return False


def _package_imports(tree: ast.Module) -> set[str]:
    """This package's modules a module imports (relative imports), as file names."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            if node.module:
                out.add(node.module.split(".")[0] + ".py")
            else:
                out.update(a.name + ".py" for a in node.names)
    return out


def test_the_kernel_sources_list_holds_every_njit_module_and_what_it_imports():
    from gearwear.dynamics.kernel_cache import KERNEL_SOURCES

    need = set()
    for path in sorted(DYN.glob("*.py")):
        tree = ast.parse(path.read_text())
        if _defines_njit(tree):
            need |= {path.name} | _package_imports(tree)
    assert need, "no njit module found"
    missing = need - set(KERNEL_SOURCES)
    assert not missing, f"add to dynamics.kernel_cache.KERNEL_SOURCES: {sorted(missing)}"
    assert all((DYN / name).is_file() for name in KERNEL_SOURCES)


def test_every_kernel_is_stamped_with_the_digest_of_all_kernel_sources():
    import importlib

    from gearwear.dynamics import kernel_cache, kernels  # noqa: F401  (kernels keys the caches)

    assert kernel_cache.ACTIVE, "the kernels' caches are not keyed on the kernel sources (numba changed?)"
    digest = kernel_cache.sources_digest()
    assert digest is not None
    seen = []
    for name in kernel_cache.KERNEL_SOURCES:
        module = importlib.import_module(f"gearwear.dynamics.{name[:-3]}")
        for obj in vars(module).values():
            if getattr(getattr(obj, "py_func", None), "__module__", None) == module.__name__:
                stamp = obj._cache._impl.locator.get_source_stamp()
                assert stamp[1] == digest, f"{module.__name__}.{obj.py_func.__name__}"
                seen.append(obj.py_func.__name__)
    assert {"rk4", "dopri5", "rhs_at", "_rhs", "_dp_stages", "_illinois"} <= set(seen)


def test_the_digest_changes_with_any_kernel_source(tmp_path):
    from gearwear.dynamics.kernel_cache import KERNEL_SOURCES, sources_digest

    for name in KERNEL_SOURCES:
        shutil.copy(DYN / name, tmp_path / name)
    base = sources_digest(tmp_path)
    assert base == sources_digest()
    for name in KERNEL_SOURCES:
        text = (tmp_path / name).read_text()
        (tmp_path / name).write_text(text + "\n")
        assert sources_digest(tmp_path) != base, name
        (tmp_path / name).write_text(text)
    assert sources_digest(tmp_path) == base


_PROBE = """
import numpy as np
from gw_kernels_copy import kernels, params
p = np.zeros(params.N_PAR)
p[params.P_MP] = p[params.P_MG] = p[params.P_ME] = p[params.P_OM] = p[params.P_PER] = 1.0
p[params.P_FS] = 2.0
p[params.P_DPHI] = 0.5
phx = np.array([-0.5, 0.0, 0.5, 1.0])
kx = np.zeros((3, 4))
out = kernels.rhs_at(0.0, np.zeros(10), p, phx, kx, kx, None, None, None, None, None, None)
print(out[9], sum(kernels.rhs_at.stats.cache_hits.values()))
"""


@pytest.mark.slow
def test_an_edit_of_a_callee_module_recompiles_the_cached_caller(tmp_path):
    """A copy of the kernel modules: rhs_at (kernels.py) compiles, then loads from the disk
    cache; after an edit of _rhs (kernel_rhs.py, another file) it runs the new _rhs."""
    from gearwear.dynamics.kernel_cache import KERNEL_SOURCES

    pkg = tmp_path / "gw_kernels_copy"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    for name in (*KERNEL_SOURCES, "interpolant.py"):  # params imports the interpolant
        shutil.copy(DYN / name, pkg / name)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"), PYTHONPATH=str(tmp_path))

    def probe():
        out = subprocess.run(
            [sys.executable, "-c", _PROBE], env=env, cwd=tmp_path, capture_output=True, text=True, check=True
        ).stdout.split()
        return float(out[0]), int(out[1])

    assert probe() == (2.0, 0)  # (F_s - F_m) / m_e = 2, compiled
    assert probe() == (2.0, 1)  # loaded from the cache
    rhs = pkg / "kernel_rhs.py"
    old = "(p[P_FS] - F) / p[P_ME],"  # the torsional acceleration term of _rhs
    assert rhs.read_text().count(old) == 1
    rhs.write_text(rhs.read_text().replace(old, "(p[P_FS] - F) / p[P_ME] + 1.0,"))
    assert probe() == (3.0, 0)  # recompiled with the edited _rhs, not the cached one
