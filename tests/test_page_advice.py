"""fem.page_advice.small_pages: NumPy's huge-page advice is off inside the block, for
overlapping threads too, and restored to what it was when the last one leaves. The advice is
read back through NumPy's own switch (it returns the previous setting)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from gearwear.fem import page_advice
from gearwear.fem.page_advice import small_pages

SETTER = page_advice._setter()
pytestmark = pytest.mark.skipif(SETTER is None, reason="this NumPy has no huge-page switch")


def _advice() -> bool:
    """The current setting, read without changing it."""
    prev = bool(SETTER(True))
    SETTER(prev)
    return prev


@pytest.mark.parametrize("before", [True, False])
def test_off_inside_and_restored_after(before):
    SETTER(before)
    try:
        with small_pages():
            assert _advice() is False
            a = np.ones((1024, 1024))  # 8 MB: an array NumPy would advise
            assert a.sum() == 1024 * 1024
            with small_pages():  # nested
                assert _advice() is False
            assert _advice() is False
        assert _advice() is before
    finally:
        SETTER(True)


def test_overlapping_threads_restore_once_the_last_one_leaves():
    """Two bodies built at once (fem.pair_model): the first to leave must not switch the
    advice back on under the other."""
    SETTER(True)
    inside = threading.Barrier(2)
    first_left = threading.Event()
    seen: dict[str, bool] = {}

    def short():
        with small_pages():
            inside.wait()
        first_left.set()

    def long():
        with small_pages():
            inside.wait()
            first_left.wait(10)
            seen["after the other left"] = _advice()

    threads = [threading.Thread(target=short), threading.Thread(target=long)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    assert seen == {"after the other left": False}
    assert _advice() is True


def test_an_exception_restores_the_advice():
    SETTER(True)
    with pytest.raises(RuntimeError):
        with small_pages():
            raise RuntimeError("a failed build")
    assert _advice() is True
