"""Load sharing among the candidate tooth pairs of ``analytic.tvms``: the pair loads and the
static transmission error at every pinion angle.

Compatibility and equilibrium, a complementarity problem at each angle (a pair with
g_k >= Delta carries nothing):

    c_k F_k + a F_k^expo = Delta - g_k  if Delta > g_k, else F_k = 0;   sum_k F_k = F

c_k the pair's linear compliance (m/N), g_k its initial gap (m), a F^expo the Hertzian
approach (m; a F^0.9, paper Eq. 5, for ``ishikawa``; a = 0 for ``energy``, whose linear
Hertz term is in c_k), F = T / r_b1 the total normal load along the line of action (N),
Delta the approach of the gears along the line of action (m). Sum F_k(Delta) is convex and
increasing in Delta, so Newton's method from above converges monotonically
(:func:`share_load`); each pair's load at a given Delta is a Newton solve of its own
(:func:`_pair_load`). The loads sum to F to ~1e-13 relative, then exactly (a final
rescaling).
"""

from __future__ import annotations

import numpy as np

from gearwear.core.validation import fail_text


def _pair_load(e, c, a, expo, warm=None):
    """Solve c F + a F^expo = e for F >= 0 (F = 0 where e <= 0) by Newton's method.

    Returns (F, dF/de) with dF/de = 1 / (c + a expo F^(expo - 1)) where F > 0, else 0.

    The left side is increasing and concave in F, so F(e) is convex: from above (the
    bound e / c), one step lands below the root; from below the iterates rise
    monotonically to it. ``warm`` = (F0, dF0, e0), the solution at an earlier e0 > e:
    its tangent F0 + dF0 (e - e0) starts below the root, off by O((e - e0)^2), and
    needs 1-2 steps. Only the pairs with e > 0 are iterated."""
    pos = e > 0
    F = np.where(pos, e / c, 0.0)
    if a == 0.0:
        return F, np.where(pos, 1.0 / c, 0.0)
    if warm is not None:
        F0, dF0, e0 = warm
        tangent = F0 + dF0 * (e - e0)
        F = np.where(pos & (tangent > 0), np.minimum(tangent, F), F)
    idx = np.flatnonzero(pos)
    ep, cp, Fk = e[idx], c[idx], F[idx]
    a_expo = a * expo
    for _ in range(60):
        Fp = np.maximum(Fk, 1e-300)  # F^(expo - 1) is infinite at 0
        Fe = Fp ** (expo - 1.0)
        slope = cp + a_expo * Fe
        step = ((cp + a * Fe) * Fp - ep) / slope
        Fk = np.maximum(Fk - step, 0.0)
        if np.all(np.abs(step) <= 1e-14 * Fk):
            break
    F[idx] = Fk
    dF = np.zeros(F.shape)
    # the slope before the last step, 1e-14 from the converged one: it only steers Newton
    dF[idx] = np.where(Fk > 0, 1.0 / slope, 0.0)
    return F, dF


def share_load(total_N: float, c: np.ndarray, gap: np.ndarray, a: float, expo: float):
    """Load sharing among candidate pairs (rows = angles, columns = pairs).

    c: linear compliance (m/N), inf where the slot has no candidate; gap (m); Hertz
    a F^expo. Returns (F (n, p), Delta (n,)). Works on the flattened candidates of all
    angles at once: Newton on every angle's Delta together, each step solving every
    pair's load.
    """
    cand = np.isfinite(c) & np.isfinite(gap)
    n = c.shape[0]
    if not np.all(cand.any(axis=1)):
        raise fail_text(
            None,
            "no tooth pair can come into contact at some angles (contact ratio far below one): "
            "the static transmission error is undefined there",
        )
    rows = np.nonzero(cand)[0]
    cc, gg = c[cand], gap[cand]
    # upper start: the smallest-gap pair alone carries everything; the total load is
    # convex and increasing in Delta, so Newton from above converges monotonically
    gfull = np.where(cand, gap, np.inf)
    k0 = np.argmin(gfull, axis=1)
    r = np.arange(n)
    delta = gfull[r, k0] + c[r, k0] * total_N + a * total_N**expo
    warm = None
    for _ in range(100):
        e = delta[rows] - gg
        F, dF = _pair_load(e, cc, a, expo, warm)
        resid = np.bincount(rows, F, n) - total_N
        if np.all(np.abs(resid) <= 1e-13 * total_N):
            break  # F belongs to this delta
        slope = np.bincount(rows, dF, n)
        delta = delta - np.where(slope > 0, resid / np.where(slope > 0, slope, 1.0), 0.0)
        warm = (F, dF, e)
    # remove the last tiny Newton residual so the loads sum to the total exactly
    T = np.bincount(rows, F, n)
    F = F * (total_N / np.where(T > 0, T, 1.0))[rows]
    out = np.zeros(c.shape)
    out[cand] = F
    return out, delta
