"""Trend classification used by the paper report (pure logic)."""

import numpy as np
import pytest

from gearwear.report_paper import agrees, classify


@pytest.mark.parametrize("values,expected", [
    ([150.0, 150.05, 150.1], "increase"),            # tiny relative change with a large offset
    ([24.4, 24.3, 24.2], "decrease"),
    ([3.0, 2.0, 2.5], "decrease-then-increase"),
    ([1.0, 2.0, 1.5], "increase-then-decrease"),
    ([1.0, 3.0, 2.0, 4.0], "nonlinear"),
    ([5.0, 5.0, 5.0], "flat"),
])
def test_classify(values, expected):
    assert classify(values) == expected


def test_agreement_rules():
    assert agrees("increase", "increase") == "agree"
    assert agrees("nonlinear", "decrease-then-increase") == "agree"
    assert agrees("increase", "flat") == "disagree (flat)"
    assert agrees("decrease", "increase") == "disagree"
    assert classify(np.linspace(0, 1, 21) ** 2) == "increase"
