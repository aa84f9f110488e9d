"""Posterior of the diagnosis unknowns on a grid, Fisher information, identifiability.

Noise model (per measured feature i, Gaussian, independent):

    y_i = f_i(theta) + e_i,  var(e_i) = (r y_i)^2 + (q A_s)^2 + m s_i(theta)^2

r: relative measurement noise (``--noise-pct``, default 2 %); q A_s: an absolute floor,
q (``--noise-floor-pct``, default 0.5 %) times the largest measured harmonic amplitude
A_s of the same signal (small harmonics are not known better than the sensor's noise
floor; it also covers the aliasing of a sampled record); s_i(theta): the surrogate's own
error (gearwear.diagnose.surrogate), counted m times (``error_multiplicity``) because
the surrogate errors of related features are correlated.

The prior is uniform on the box of the prior ranges. The log-likelihood is
-1/2 sum (f_i - y_i)^2 / var_i. Its normalisation (-1/2 sum log var_i) is left out: it
depends on theta only through the surrogate error and would favour the parts of the box
where the surrogate happens to be more accurate, which is a property of the design, not
evidence from the measurement. (The blind test shows intervals that cover the truth at
their stated rate this way; with the term they do not.)

The posterior is evaluated exactly on a grid (deterministic; no sampler to converge):
first over the whole prior box, then on boxes zoomed onto the region where
log p > max - 25 (everything outside carries < 1e-10 of the mass), until the box stops
shrinking. Marginals by summation, 95 % intervals equal-tailed (2.5 and 97.5 %
quantiles of the marginal), the point estimate is the marginal median.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

LOG_TAIL = 25.0  # zoom onto log p > max - LOG_TAIL
RESOLVED_FRACTION = 0.5  # resolved: the 95 % interval spans at most this fraction of the prior range
Z95 = 1.959964


def noise_variance(features: list[tuple[str, int]], values: np.ndarray, rel: float, floor_frac: float) -> np.ndarray:
    """(r y_i)^2 + (q A_s)^2, A_s the largest harmonic amplitude of signal s among ``values``."""
    values = np.asarray(values, float)
    top: dict[str, float] = {}
    for (s, k), v in zip(features, values):
        if k > 0:
            top[s] = max(top.get(s, 0.0), abs(v))
    floor = np.array([floor_frac * top.get(s, 0.0) for s, _ in features])
    return (rel * values) ** 2 + floor**2


@dataclass
class GridPosterior:
    """Normalised posterior on the final (zoomed) grid."""

    axes: list[np.ndarray]
    density: np.ndarray  # p on the grid, sums to 1
    stages: list[tuple[list[float], list[float]]]  # (lo, hi) of every grid box evaluated

    def marginal(self, j: int) -> np.ndarray:
        other = tuple(i for i in range(self.density.ndim) if i != j)
        return self.density.sum(axis=other)

    def joint(self, i: int, j: int) -> np.ndarray:
        other = tuple(k for k in range(self.density.ndim) if k not in (i, j))
        return self.density.sum(axis=other) if other else self.density

    def quantile(self, j: int, q: float) -> float:
        """Quantile of marginal j, the grid values taken as the density at the nodes
        (piecewise linear between them, so the CDF is piecewise quadratic; solved exactly)."""
        x, p = self.axes[j], self.marginal(j)
        if x.size == 1:
            return float(x[0])
        cell = 0.5 * (p[:-1] + p[1:]) * np.diff(x)
        cdf = np.concatenate([[0.0], np.cumsum(cell)])
        total = cdf[-1]
        target = q * total
        i = int(np.clip(np.searchsorted(cdf, target, side="right") - 1, 0, x.size - 2))
        h, a, b = x[i + 1] - x[i], p[i], p[i + 1]
        need = target - cdf[i]
        # int_0^t (a + (b - a) s / h) ds = need
        if abs(b - a) < 1e-14 * max(a, b, 1e-300):
            t = need / a if a > 0 else 0.0
        else:
            disc = max(a * a + 2 * (b - a) * need / h, 0.0)
            t = (math.sqrt(disc) - a) * h / (b - a)
        return float(x[i] + min(max(t, 0.0), h))

    def mean_cov(self) -> tuple[np.ndarray, np.ndarray]:
        mesh = np.meshgrid(*self.axes, indexing="ij")
        pts = np.stack([m.ravel() for m in mesh], axis=1)
        w = self.density.ravel()
        mu = w @ pts
        d = pts - mu
        return mu, (d * w[:, None]).T @ d

    def map_point(self) -> np.ndarray:
        idx = np.unravel_index(int(np.argmax(self.density)), self.density.shape)
        return np.array([a[i] for a, i in zip(self.axes, idx)])


def grid_posterior(logpost: Callable[[np.ndarray], np.ndarray], lo, hi, n: int, zooms: int = 4) -> GridPosterior:
    """Evaluate ``logpost`` (m, d) -> (m,) on n^d grids: the prior box, then boxes zoomed
    onto log p > max - LOG_TAIL (one grid cell of margin, clipped to the prior)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    blo, bhi = lo.copy(), hi.copy()
    stages = []
    while True:
        axes = [np.linspace(a, b, n) if b > a else np.array([a]) for a, b in zip(blo, bhi)]
        mesh = np.meshgrid(*axes, indexing="ij")
        L = logpost(np.stack([m.ravel() for m in mesh], axis=1)).reshape(mesh[0].shape)
        stages.append((blo.tolist(), bhi.tolist()))
        keep = L >= np.max(L) - LOG_TAIL
        nlo, nhi = blo.copy(), bhi.copy()
        for j, ax in enumerate(axes):
            if ax.size == 1:
                continue
            hit = np.nonzero(np.any(keep, axis=tuple(i for i in range(L.ndim) if i != j)))[0]
            step = ax[1] - ax[0]
            nlo[j] = max(lo[j], ax[hit[0]] - step)
            nhi[j] = min(hi[j], ax[hit[-1]] + step)
        shrink = np.min((nhi - nlo) / np.where(bhi > blo, bhi - blo, 1.0))
        if len(stages) > zooms or shrink > 0.7:  # no axis shrank by 30 %: this grid resolves the region
            break
        blo, bhi = nlo, nhi
    p = np.exp(L - np.max(L))
    return GridPosterior(axes, p / p.sum(), stages)


def jacobian(f: Callable[[np.ndarray], np.ndarray], theta, lo, hi, rel_step: float = 0.01) -> np.ndarray:
    """d f / d theta (F, d) by central differences of step rel_step x the prior range
    (one-sided at the bounds)."""
    theta, lo, hi = (np.asarray(v, float) for v in (theta, lo, hi))
    d = theta.size
    pts = []
    steps = []
    for j in range(d):
        h = rel_step * (hi[j] - lo[j])
        a, b = theta.copy(), theta.copy()
        a[j] = max(lo[j], theta[j] - h)
        b[j] = min(hi[j], theta[j] + h)
        pts += [a, b]
        steps.append(b[j] - a[j])
    vals = f(np.array(pts))
    return np.column_stack([(vals[2 * j + 1] - vals[2 * j]) / steps[j] for j in range(d)])


def fisher_widths(J: np.ndarray, var: np.ndarray, ranges) -> dict[str, np.ndarray]:
    """From the sensitivities J (F, d) and the feature variances: the Fisher information in
    prior-range units, the Cramer-Rao 95 % interval widths as fractions of the prior range
    (``marginal``: the other unknowns free; ``conditional``: the others known) and the
    correlation the information implies."""
    Jn = J * np.asarray(ranges, float)[None, :]
    Fi = Jn.T @ (Jn / np.asarray(var, float)[:, None])
    d = Fi.shape[0]
    diag = np.diag(Fi)
    cond = np.where(diag > 0, 2 * Z95 / np.sqrt(np.where(diag > 0, diag, 1.0)), np.inf)
    cov = np.linalg.pinv(Fi, hermitian=True)
    rank = np.linalg.matrix_rank(Fi, hermitian=True, tol=1e-10 * max(float(np.max(np.abs(Fi))), 1e-300))
    marg = 2 * Z95 * np.sqrt(np.clip(np.diag(cov), 0.0, None))
    if rank < d:
        marg = np.full(d, np.inf)
    sd = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    corr = cov / np.outer(sd, sd)
    return {"fisher": Fi, "marginal": marg, "conditional": cond, "correlation": corr}


def summarise(post: GridPosterior, names: list[str], lo, hi) -> dict[str, Any]:
    """estimates (value = marginal median, lo95, hi95, map), fraction of the prior range,
    posterior correlation."""
    mu, cov = post.mean_cov()
    sd = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    corr = cov / np.outer(sd, sd)
    mp = post.map_point()
    est = {}
    for j, n in enumerate(names):
        a, b = post.quantile(j, 0.025), post.quantile(j, 0.975)
        est[n] = {
            "value": post.quantile(j, 0.5),
            "lo95": a,
            "hi95": b,
            "map": float(mp[j]),
            "mean": float(mu[j]),
            "std": float(sd[j]),
            "interval_fraction_of_prior": (b - a) / (hi[j] - lo[j]),
        }
    return {"estimates": est, "correlation": corr}
