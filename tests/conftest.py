"""Test-session settings.

Hypothesis runs derandomized by default so that ``make test`` on CI explores the same
examples as on a developer's machine; a CI run must not be the first to meet a new case.
``HYPOTHESIS_PROFILE=explore`` searches with fresh random seeds (and more examples) when
hunting for new failures; anything it finds becomes an explicit test.
"""

import os

from hypothesis import settings

settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


def pytest_collection_modifyitems(config, items):
    """Mark ``slow`` the tests listed in tests/slow_tests.txt (measured, tools/slow_tests.py),
    so that ``make check`` (-m "not slow") is the fast tier; ``make test`` runs them all."""
    from pathlib import Path

    import pytest

    listed = Path(__file__).with_name("slow_tests.txt")
    slow = {ln.strip() for ln in listed.read_text().splitlines() if ln.strip() and not ln.startswith("#")}
    for item in items:
        if item.nodeid in slow:
            item.add_marker(pytest.mark.slow)
