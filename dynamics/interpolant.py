"""The periodic table interpolant: a table over one period read as a piecewise polynomial.

A table ``(phi_j, v_j)``, ``j = 0 .. n-1``, with ``0 <= phi_0 < ... < phi_{n-1} < P`` (``phi``
in rad of pinion rotation, ``P`` the table period in rad; ``v`` in the table's unit: N/m for
the mesh stiffness k, m for the excitation e) is read as a P-periodic function. On segment
j, ``[phi_j, phi_{j+1})`` (the last segment wraps to ``phi_0 + P``):

    v(phi) = c0 + c1 d + c2 d^2 + c3 d^3,        d = phi - phi_j  (rad)

``linear``: ``c0 = v_j``, ``c1 = (v_{j+1} - v_j) / (phi_{j+1} - phi_j)``, ``c2 = c3 = 0``
(positivity preserving, so zero-stiffness gaps stay zero; exact for piecewise-linear data).
``cubic``: scipy's periodic cubic spline (C2, 4th order for smooth data). The mean over a
period is the exact integral of the polynomials divided by P.

Pure functions of arrays (no model). The model (``dynamics.model``), its parameter vector
(``dynamics.params``) and the tables on the time axis (``dynamics.table_time``) build on
them.
"""

from __future__ import annotations

import numpy as np


def segment_coefficients(phi, v, P: float, kind: str = "linear") -> np.ndarray:
    """Per-segment polynomial coefficients (n, 4) of the periodic interpolant of the
    table (phi in [0, P), values v): on [phi_j, phi_j+1) (the last segment wraps to
    phi_0 + P) v(phi) = c0 + c1 d + c2 d^2 + c3 d^3 with d = phi - phi_j. ``linear``:
    the piecewise-linear interpolant (positivity preserving, exact for piecewise-linear
    data); ``cubic``: scipy's periodic cubic spline (C2, 4th order for smooth data)."""
    x = np.r_[phi, phi[0] + P]
    y = np.r_[v, v[0]]
    c = np.zeros((len(phi), 4))
    if kind == "cubic":
        from scipy.interpolate import CubicSpline

        cs = CubicSpline(x, y, bc_type="periodic")
        c[:] = cs.c[::-1].T
    else:
        c[:, 0] = y[:-1]
        c[:, 1] = np.diff(y) / np.diff(x)
    return c


def table_mean(phi, v, P: float, kind: str = "linear") -> float:
    """Mean of the periodic interpolant of a table over its period P (exact per segment;
    a plain average of the rows would misweight a non-uniform table)."""
    phi = np.asarray(phi, float)
    c = segment_coefficients(phi, np.asarray(v, float), P, kind)
    w = np.diff(np.r_[phi, phi[0] + P])
    return float(np.sum(c[:, 0] * w + c[:, 1] * w**2 / 2 + c[:, 2] * w**3 / 3 + c[:, 3] * w**4 / 4) / P)


def _eval_coefficients(phx, c, u):
    """Value and d/dphi of the extended-table interpolant at phases u in [0, P)."""
    i = np.clip(np.searchsorted(phx, u, side="right") - 1, 0, phx.size - 2)
    d = u - phx[i]
    c0, c1, c2, c3 = c[i, 0], c[i, 1], c[i, 2], c[i, 3]
    return c0 + d * (c1 + d * (c2 + d * c3)), c1 + d * (2 * c2 + 3 * d * c3)
