"""numba's disk cache for the kernels, keyed on every kernel source file.

numba (``cache=True``) stamps the cached machine code of a function with the content of
*its own* source file only (numba issue #1833, "Cache invalidation" in numba's notes on
caching). A kernel inlines functions from the other kernel modules and reads the parameter
layout (``dynamics.params``) and the Dormand-Prince tableau (``dynamics.dormand_prince``)
as compile-time constants, so an edit there would leave its callers' cached code stale:
``rk4`` would go on running the old ``_rhs``. ``key_on_sources`` gives every njit function
of ``KERNEL_SOURCES`` a cache whose source stamp is (numba's stamp of its file, the SHA-256
of all of ``KERNEL_SOURCES``): an edit in any of them recompiles every kernel once, as an
edit of the single kernels.py did before it was split. Nothing else changes: the cache
folder, the file names, the index key and the specialisations per effect set.

It relies on numba's cache classes (``numba.core.caching.FunctionCache``, the ``locator``
of its implementation) and on the dispatcher's ``_cache`` attribute. Where they are
missing (another numba), the kernels keep numba's per-file stamps and ``ACTIVE`` stays
False; tests/test_kernel_cache.py fails then, so an upgrade that breaks this is noticed.
"""

from __future__ import annotations

import hashlib
import importlib
from pathlib import Path

#: the files whose content the compiled kernels depend on: the modules that define njit
#: functions and every module of this package they import (tests/test_kernel_cache.py
#: checks that the list is complete)
KERNEL_SOURCES = (
    "dormand_prince.py",
    "params.py",
    "kernel_state.py",
    "kernel_rhs.py",
    "kernel_tables.py",
    "kernel_rk4.py",
    "kernel_dp_step.py",
    "kernel_events.py",
    "kernel_dopri5.py",
    "kernels.py",
    "kernel_cache.py",
)

#: True once the kernels' caches are keyed on ``sources_digest()``
ACTIVE = False


def sources_digest(folder: Path | None = None) -> str | None:
    """SHA-256 (hex) of the names and contents of ``KERNEL_SOURCES`` in ``folder`` (this
    package's folder by default); None when one of them cannot be read."""
    folder = Path(__file__).parent if folder is None else folder
    h = hashlib.sha256()
    try:
        for name in KERNEL_SOURCES:
            h.update(name.encode() + b"\0" + (folder / name).read_bytes() + b"\0")
    except OSError:
        return None
    return h.hexdigest()


class _StampedLocator:
    """numba's cache locator of one function, with the kernel sources' digest added to its
    source stamp (everything else is the wrapped locator's)."""

    def __init__(self, inner, digest: str):
        self._inner = inner
        self._digest = digest

    def __getattr__(self, name):
        return getattr(self._inner, name)

    def get_source_stamp(self):
        return (self._inner.get_source_stamp(), self._digest)


def key_on_sources(package: str) -> bool:
    """Give every cached njit function defined in ``package``'s ``KERNEL_SOURCES`` modules
    a cache stamped with ``sources_digest()``. Call it before the first kernel call (at the
    end of ``dynamics.kernels``). Returns ``ACTIVE``."""
    global ACTIVE
    digest = sources_digest()
    try:
        from numba.core.caching import FunctionCache
    except ImportError:
        return ACTIVE
    impl_base = getattr(FunctionCache, "_impl_class", None)
    if digest is None or impl_base is None or not isinstance(getattr(impl_base, "locator", None), property):
        return ACTIVE

    class _Impl(impl_base):  # type: ignore[misc, valid-type]
        @property
        def locator(self):
            return _StampedLocator(super().locator, digest)

    class _KernelCache(FunctionCache):  # type: ignore[misc, valid-type]
        _impl_class = _Impl

    n = 0
    for name in KERNEL_SOURCES:
        module = importlib.import_module(f"{package}.{name[:-3]}")
        for obj in list(vars(module).values()):
            py_func = getattr(obj, "py_func", None)
            if (
                isinstance(getattr(obj, "_cache", None), FunctionCache)
                and getattr(py_func, "__module__", None) == module.__name__
            ):
                obj._cache = _KernelCache(py_func)
                n += 1
    ACTIVE = n > 0
    return ACTIVE
