"""Process-wide settings the pair FE holds while it builds bodies, safe for overlapping
threads: a setting is applied when the first thread enters, kept while any thread is inside
(fem.pair_model builds two bodies at once, one in a worker thread) and restored when the
last one leaves (:class:`Held`). fem.pair_model holds both in its calling thread around the
builds, so the worker thread's own holds (fem.condensation) only nest.

Why: a process-wide setting saved and restored by each thread's own ``with`` is undone under
the other thread. With ``with threadpool_limits(1)`` in each body's condensation, the body
in the worker thread could leave its block (setting the BLAS back to two threads) while the
other body was inside its own, whose Cholesky factorization then ran on two threads and
rounded differently (dpotrf on one and on two OpenBLAS threads differ in the last bits):
the overlapped build then differed from the serial one, seen once in a full test run
(tests/test_fem_pair_condense.py). threadpoolctl 3.8 also lets only one thread at a time
set OpenBLAS's thread count (the others' calls do nothing), so the limit is set, and
restored, by the thread that holds it first: the caller of fem.pair_model.

The settings:

* :data:`one_blas_thread`: one BLAS thread (threadpoolctl). The thread count of a threaded
  BLAS routine sets its rounding, so the condensation's dense products (fem.condensation)
  are the same to the bit in every process, worker and overlap; and OpenBLAS's threaded
  dpotri took 6.2 s against 0.39 s on one thread for m = 2142 on this 2-core machine.
* :data:`small_pages`: no huge-page advice from NumPy. NumPy asks the kernel to back every
  array of 4 MB or more with transparent huge pages (``madvise(MADV_HUGEPAGE)``;
  ``NUMPY_MADVISE_HUGEPAGE``). Where the kernel's THP ``defrag`` setting is ``madvise`` (a
  common default; this machine's), that advice makes the first touch of such an array
  compact memory synchronously until 2 MB pages are free. A body build touches a few
  hundred MB of fresh arrays once each (the assembly's triplets, the condensation's dense
  border and Schur complement, the flexibility): the first touch of a 288 MB array took
  1.99 s with the advice (0.02-0.03 s for the next two in the same process: the stalls are
  erratic) and 0.13-0.17 s without, and the paper pair's cold 24-position
  cycle took 4.07 s (median of 11 fresh processes, alternating) with it against 3.67 s
  without, on this machine. Small pages change no number (arrays are values, not
  addresses); they cost some TLB misses in the dense products, fewer than the stalls here.
  Where NumPy has no such switch this does nothing.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np

__all__ = ["Held", "one_blas_thread", "small_pages"]


class Held:
    """A process-wide setting held by any number of threads at once: ``apply()`` sets it and
    returns the function that undoes it; ``with held():`` applies it when the first thread
    enters and undoes it when the last one leaves (nested and overlapping blocks alike)."""

    def __init__(self, apply: Callable[[], Callable[[], None]]):
        self._apply = apply
        self._lock = threading.Lock()
        self._depth = 0
        self._undo: Callable[[], None] | None = None

    @contextmanager
    def __call__(self) -> Iterator[None]:
        with self._lock:
            if self._depth == 0:
                self._undo = self._apply()
            self._depth += 1
        try:
            yield
        finally:
            with self._lock:
                self._depth -= 1
                if self._depth == 0 and self._undo is not None:
                    undo, self._undo = self._undo, None
                    undo()


def huge_page_switch() -> Callable[[bool], bool] | None:
    """NumPy's switch of the huge-page advice (it returns the previous setting), or None."""
    for mod in ("_core", "core"):
        f = getattr(getattr(getattr(np, mod, None), "multiarray", None), "_set_madvise_hugepage", None)
        if callable(f):
            return f
    return None


def _no_huge_pages() -> Callable[[], None]:
    switch = huge_page_switch()
    if switch is None:
        return lambda: None
    before = bool(switch(False))

    def undo() -> None:
        switch(before)

    return undo


def _one_thread() -> Callable[[], None]:
    from threadpoolctl import threadpool_limits

    # entered and left like a ``with`` block (threadpoolctl counts its holders to hand the
    # control of OpenBLAS back when the last one leaves)
    limiter = threadpool_limits(limits=1, user_api="blas")
    limiter.__enter__()
    return lambda: limiter.__exit__(None, None, None)


#: no huge-page advice from NumPy while held (see the module docstring)
small_pages = Held(_no_huge_pages)
#: one BLAS thread while held (see the module docstring)
one_blas_thread = Held(_one_thread)
