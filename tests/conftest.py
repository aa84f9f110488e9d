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
