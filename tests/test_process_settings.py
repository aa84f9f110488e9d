"""fem.process_settings: a process-wide setting held by overlapping threads stays applied
until the last one leaves, then is restored (fem.pair_model builds two bodies at once).

The bug's class (a setting saved and restored by each thread's own block, undone under the
other thread) is forced on the real overlapped build in tests/test_fem_pair_condense.py.
The readings here are independent of the code under test: the rounding of a Cholesky
factorization (one and two OpenBLAS threads round differently), and NumPy's own switch of
the huge-page advice (it returns the setting)."""

from __future__ import annotations

import threading

import numpy as np
import pytest
import scipy.linalg as sla
from threadpoolctl import threadpool_limits

from gearwear.fem.process_settings import Held, huge_page_switch, one_blas_thread, small_pages

SWITCH = huge_page_switch()


_RNG = np.random.default_rng(3)
_A = _RNG.standard_normal((1500, 1500))
_SPD = _A @ _A.T + 1500 * np.eye(1500)


def _cholesky(threads: int | None = None) -> np.ndarray:
    """LAPACK dpotrf of a fixed SPD matrix (as fem.condensation._inverse), on ``threads`` BLAS
    threads or on what the process is set to."""
    if threads is None:
        return sla.lapack.dpotrf(_SPD, lower=1)[0]
    with threadpool_limits(limits=threads, user_api="blas"):
        return sla.lapack.dpotrf(_SPD, lower=1)[0]


ONE, TWO = _cholesky(1), _cholesky(2)


def _blas_threads() -> str:
    """How many BLAS threads the process computes on, read from the rounding of a Cholesky
    factorization: the effect the setting is for, whichever thread set it (threadpoolctl
    3.8 lets one thread at a time set OpenBLAS's count; the others' calls do nothing)."""
    c = _cholesky()
    return "one" if np.array_equal(c, ONE) else "two" if np.array_equal(c, TWO) else "other"


def _advice() -> bool:
    """NumPy's huge-page advice, read without changing it."""
    assert SWITCH is not None
    prev = bool(SWITCH(True))
    SWITCH(prev)
    return prev


def _overlap(hold, read) -> dict[str, object]:
    """Two threads in ``hold()`` at once; the first leaves while the second is inside: what
    the second sees after that, by ``read()``."""
    inside = threading.Barrier(2)
    first_left = threading.Event()
    seen: dict[str, object] = {}

    def short():
        with hold():
            inside.wait()
        first_left.set()

    def long():
        with hold():
            inside.wait()
            first_left.wait(10)
            seen["after the other left"] = read()

    threads = [threading.Thread(target=short), threading.Thread(target=long)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    return seen


needs_two = pytest.mark.skipif(
    np.array_equal(ONE, TWO) or _blas_threads() != "two", reason="one BLAS thread rounds as two here"
)


@needs_two
def test_one_blas_thread_holds_for_overlapping_threads_and_restores():
    """As fem.pair_model holds it: in the calling thread, around two worker threads whose own
    holds nest; each computes on one thread even after the other left."""
    with one_blas_thread():
        assert _overlap(one_blas_thread, _blas_threads) == {"after the other left": "one"}
        assert _blas_threads() == "one"
    assert _blas_threads() == "two"


@needs_two
def test_one_blas_thread_nested_and_on_an_exception():
    with pytest.raises(RuntimeError):
        with one_blas_thread():
            with one_blas_thread():
                assert _blas_threads() == "one"
            assert _blas_threads() == "one"
            raise RuntimeError("a failed build")
    assert _blas_threads() == "two"


def test_held_applies_once_and_undoes_once():
    log: list[str] = []

    def apply():
        log.append("apply")
        return lambda: log.append("undo")

    held = Held(apply)
    with held():
        with held():
            pass
        assert log == ["apply"]
    assert log == ["apply", "undo"]
    with held():
        pass
    assert log == ["apply", "undo", "apply", "undo"]


pages = pytest.mark.skipif(SWITCH is None, reason="this NumPy has no huge-page switch")


@pages
@pytest.mark.parametrize("before", [True, False])
def test_small_pages_off_inside_and_restored_after(before):
    assert SWITCH is not None
    SWITCH(before)
    try:
        with small_pages():
            assert _advice() is False
            a = np.ones((1024, 1024))  # 8 MB: an array NumPy would advise
            assert a.sum() == 1024 * 1024
        assert _advice() is before
        SWITCH(True)
        assert _overlap(small_pages, _advice) == {"after the other left": False}
        assert _advice() is True
    finally:
        SWITCH(True)
