"""Plane polylines: arc length, stitching, point projection and quadratic chains.

Pure numpy; points are (n, 2) arrays in any length unit (m throughout gearwear).

Quadratic chains
----------------
A quadratic chain stores a piecewise-quadratic curve as its nodes in order,
vertex, mid-point, vertex, ..., vertex (odd length 2 n + 1 for n edges). Edge i,
(a, m, b) = nodes (2 i, 2 i + 1, 2 i + 2), is the quadratic Lagrange interpolant

    x(t) = a (1 - t)(1 - 2 t) + 4 t (1 - t) m + b t (2 t - 1),   0 <= t <= 1,

the trace of an isoparametric 6-node triangle on that edge (Zienkiewicz & Taylor,
*The Finite Element Method*, vol. 1, ch. 6 and 8). Rotation, mirroring, reversal
and stitching at vertices keep the layout, so tooth outlines with mid-points are
assembled by the same code as plain ones.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

__all__ = [
    "cumulative_length",
    "stitch",
    "project_to_segments",
    "PolylineProjection",
    "project_to_polyline",
    "with_midpoints",
    "quadratic_eval",
    "quadratic_points",
    "quadratic_parameter",
]


def cumulative_length(xy: np.ndarray) -> np.ndarray:
    """Arc length along the polyline at each of its points, starting at 0."""
    xy = np.asarray(xy, dtype=float)
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])


def stitch(pieces: Sequence[np.ndarray], closed: bool = False, rtol: float = 1e-9) -> np.ndarray:
    """Join polylines end to start into one: every piece must start where the previous
    one ends (within ``rtol`` x the largest coordinate), and the shared point is kept
    once. ``closed``: the last point must coincide with the first and is dropped (a
    closed polygon without a repeated point)."""
    parts = [np.asarray(p, dtype=float).reshape(-1, 2) for p in pieces]
    if not parts:
        raise ValueError("stitch: no pieces")
    tol = rtol * max(float(np.max(np.abs(p))) if p.size else 0.0 for p in parts)
    out = [parts[0]]
    for k, p in enumerate(parts[1:], start=1):
        if np.hypot(*(p[0] - out[-1][-1])) > tol:
            raise ValueError(
                f"stitch: piece {k} starts at {p[0].tolist()}, not at the end {out[-1][-1].tolist()} of piece {k - 1}"
            )
        out.append(p[1:])
    xy = np.vstack(out)
    if closed:
        if len(xy) < 2 or np.hypot(*(xy[-1] - xy[0])) > tol:
            raise ValueError("stitch: the pieces do not close (last point != first point)")
        xy = xy[:-1]
    return xy


def project_to_segments(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closest points of segments a -> b to points p (broadcasting over leading axes):
    (parameter t in [0, 1] with the closest point a + t (b - a), distance)."""
    ab = b - a
    L2 = np.einsum("...i,...i->...", ab, ab)
    t = np.einsum("...i,...i->...", p - a, ab) / np.where(L2 > 0, L2, 1.0)
    t = np.clip(t, 0.0, 1.0)
    d = p - (a + t[..., None] * ab)
    return t, np.sqrt(np.einsum("...i,...i->...", d, d))


@dataclass(frozen=True)
class PolylineProjection:
    """Closest points of a polyline to given points (one entry per point).

    segment   index i of the closest segment (points i, i + 1 of the polyline)
    t         parameter on that segment, 0 .. 1
    distance  distance to the closest point
    s         arc length of the closest point along the polyline
    """

    segment: np.ndarray
    t: np.ndarray
    distance: np.ndarray
    s: np.ndarray


def project_to_polyline(
    points: np.ndarray, poly: np.ndarray, max_distance: float = np.inf, chunk: int = 256
) -> PolylineProjection:
    """Orthogonal projection of ``points`` (k, 2) onto the open polyline ``poly`` (n, 2),
    n >= 2 (the first closest segment wins ties). Points farther than ``max_distance``
    from the polyline's bounding box are not projected (distance inf, segment 0, t 0).
    Brute force over all segments in chunks of points (memory: chunk x n)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    poly = np.asarray(poly, dtype=float)
    if poly.ndim != 2 or poly.shape[0] < 2:
        raise ValueError("project_to_polyline: the polyline needs at least 2 points")
    a, b = poly[:-1], poly[1:]
    seg = np.zeros(len(pts), dtype=int)
    t = np.zeros(len(pts))
    dist = np.full(len(pts), np.inf)
    near = np.flatnonzero(
        np.all((pts >= poly.min(axis=0) - max_distance) & (pts <= poly.max(axis=0) + max_distance), axis=1)
    )
    for i0 in range(0, len(near), chunk):
        idx = near[i0 : i0 + chunk]
        tt, dd = project_to_segments(pts[idx, None, :], a[None], b[None])
        k = np.argmin(dd, axis=1)
        rows = np.arange(len(k))
        seg[idx], t[idx], dist[idx] = k, tt[rows, k], dd[rows, k]
    s_poly = cumulative_length(poly)
    return PolylineProjection(seg, t, dist, s_poly[seg] + t * (s_poly[seg + 1] - s_poly[seg]))


def with_midpoints(s: np.ndarray) -> np.ndarray:
    """Positions s_0, (s_0 + s_1) / 2, s_1, ... : the nodes of a quadratic chain whose
    vertices are at ``s`` and whose mid-points halve each interval."""
    s = np.asarray(s, dtype=float)
    out = np.empty(2 * len(s) - 1)
    out[0::2] = s
    out[1::2] = 0.5 * (s[:-1] + s[1:])
    return out


def _quadratic(a, m, b, t):
    t = t[..., None]
    return a * (1 - t) * (1 - 2 * t) + 4 * t * (1 - t) * m + b * t * (2 * t - 1)


def _edges(chain: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    chain = np.asarray(chain, dtype=float)
    if chain.ndim != 2 or len(chain) < 3 or len(chain) % 2 == 0:
        raise ValueError(f"a quadratic chain needs an odd number >= 3 of points, got {len(chain)}")
    return chain[0:-1:2], chain[1::2], chain[2::2]


def quadratic_eval(chain: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points and unit tangents (direction of increasing u) of the chain at chain
    parameters u in [0, n_edges]: edge i = min(floor(u), n_edges - 1) at t = u - i."""
    a, m, b = _edges(chain)
    u = np.asarray(u, dtype=float)
    i = np.clip(np.floor(u).astype(int), 0, len(a) - 1)
    t = u - i
    xy = _quadratic(a[i], m[i], b[i], t)
    d = (b[i] - a[i]) + (4 - 8 * t)[..., None] * (m[i] - 0.5 * (a[i] + b[i]))
    return xy, d / np.linalg.norm(d, axis=-1)[..., None]


def quadratic_points(chain: np.ndarray, n_sub: int) -> np.ndarray:
    """The chain's curve as a polyline: every edge at t = k / n_sub, k = 0 .. n_sub
    (shared vertices once), i.e. at chain parameters arange(n_edges n_sub + 1) / n_sub.
    A circle arc of angle phi per sub-step is off its chord by R phi^2 / 8."""
    n_edges = (len(chain) - 1) // 2
    return quadratic_eval(chain, np.arange(n_edges * n_sub + 1) / n_sub)[0]


def quadratic_parameter(p: np.ndarray, a: np.ndarray, m: np.ndarray, b: np.ndarray, iterations: int = 8) -> np.ndarray:
    """Parameter t in [0, 1] of the point of each quadratic edge (a, m, b) closest to p
    (all (k, 2)): Newton on d/dt |x(t) - p|^2 = 0 from the chord projection."""
    p, a, m, b = (np.asarray(v, dtype=float) for v in (p, a, m, b))
    t, _ = project_to_segments(p, a, b)
    # x(t) = a + t (b - a) + 4 t (1 - t) e with e = m - (a + b) / 2
    e = m - 0.5 * (a + b)
    for _ in range(iterations):
        x = _quadratic(a, m, b, t)
        d1 = (b - a) + (4 - 8 * t)[:, None] * e
        d2 = -8 * e
        f = np.einsum("ij,ij->i", x - p, d1)
        df = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", x - p, d2)
        # df <= 0 only far off a strongly curved edge (no unique closest point): stay
        t = np.clip(t - np.where(df > 0, f / np.where(df > 0, df, 1.0), 0.0), 0.0, 1.0)
    return t
