"""The Dormand-Prince 5(4) tableau the kernels integrate with (dynamics.dormand_prince) is
scipy's RK45 (an independent transcription of Dormand & Prince 1980 and Shampine 1986), and
it has the order conditions of a 5(4) pair: row sums equal the nodes, the 5th-order weights
integrate t^q exactly for q <= 4, the error weights sum to zero."""

from __future__ import annotations

import numpy as np
from scipy.integrate import RK45

from gearwear.dynamics import dormand_prince as dp


def _a_matrix() -> np.ndarray:
    a = np.zeros((6, 5))
    for s, row in enumerate(dp.A, start=1):
        a[s, : len(row)] = row
    return a


def test_the_tableau_is_scipys():
    assert np.array_equal(np.asarray(dp.C[:6]), RK45.C)
    assert np.array_equal(_a_matrix(), RK45.A)
    assert np.array_equal(np.asarray(dp.B), RK45.B)
    assert np.array_equal(np.asarray(dp.E), RK45.E)
    assert np.array_equal(dp.P, RK45.P)


def test_order_conditions():
    a, b, c = _a_matrix(), np.asarray(dp.B), np.asarray(dp.C[:6])
    assert np.allclose(a.sum(axis=1), c, rtol=0, atol=1e-15)
    assert abs(b.sum() - 1) < 1e-15
    for q in range(5):  # quadrature order 5: sum b_s c_s^q = 1 / (q + 1)
        assert abs(b @ c**q - 1 / (q + 1)) < 1e-15
    assert abs(sum(dp.E)) < 1e-16
    # the dense output ends at z_new: sum over the powers of P equals B (with b_7 = 0)
    assert np.allclose(dp.P.sum(axis=1), np.append(b, 0.0), rtol=0, atol=1e-15)
