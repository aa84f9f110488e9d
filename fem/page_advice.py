"""NumPy's huge-page advice switched off while the pair FE builds its bodies (Linux).

NumPy asks the kernel to back every array of 4 MB or more with transparent huge pages
(``madvise(MADV_HUGEPAGE)``; NumPy's ``NUMPY_MADVISE_HUGEPAGE``). Where the kernel's THP
``defrag`` setting is ``madvise`` (a common default; this machine's), that advice makes the
first touch of such an array compact memory synchronously until 2 MB pages are free. A
body build touches a few hundred MB of fresh arrays once each (the assembly's triplets, the
condensation's dense border and Schur complement, the flexibility), so those stalls were a
large and erratic part of it: the first touch of a 288 MB array took 1.99 s with the advice
and 0.13-0.17 s without, and the paper pair's cold 24-position cycle took 4.07 s (median of
11 fresh processes, alternating) with it against 3.67 s without, on this 2-core machine. Small pages change no
number (the same bytes: arrays are values, not addresses); they cost some TLB misses in the
dense products, which were smaller than the stalls here. Where the advice is not available
(another NumPy, another OS) this does nothing.

``small_pages()`` is a context manager: the advice is off while any thread is inside one
(they nest and overlap: fem.pair_model builds two bodies at once) and is restored to what
it was when the last one leaves.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

__all__ = ["small_pages"]

_LOCK = threading.Lock()
_DEPTH = 0
_SAVED: bool | None = None


def _setter():
    """NumPy's switch of the advice (it returns the previous setting), or None."""
    for mod in ("_core", "core"):
        f = getattr(getattr(getattr(np, mod, None), "multiarray", None), "_set_madvise_hugepage", None)
        if callable(f):
            return f
    return None


@contextmanager
def small_pages() -> Iterator[None]:
    """Arrays allocated inside the block get no huge-page advice (see the module docstring)."""
    global _DEPTH, _SAVED
    setter = _setter()
    if setter is None:
        yield
        return
    with _LOCK:
        if _DEPTH == 0:
            _SAVED = bool(setter(False))
        _DEPTH += 1
    try:
        yield
    finally:
        with _LOCK:
            _DEPTH -= 1
            if _DEPTH == 0 and _SAVED is not None:
                setter(_SAVED)
                _SAVED = None
