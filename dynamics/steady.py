"""Steady state of the periodically excited gear pair: detected, not assumed.

The excitation (k_h, e) repeats every table period T (one mesh period, or L of them with
a tooth fault), so the steady states are the attractors of the Poincare map P: z(t) ->
z(t + T) of the 10-dimensional state, sampled once per table period (the Poincare
section). This module integrates in chunks of whole table periods until the section
sequence X_0, X_1, ... repeats, and labels what it found:

* **periodic with period p** (p table periods; p > 1 is a subharmonic response): the
  residual ``r_p = max_k |X_{k+p} - X_k|`` (each state component divided by the
  peak-to-peak of its group, displacements or velocities, over the chunk: a dimensionless
  number) is below ``tol``. Near a fixed point the residual shrinks geometrically, by
  rho^p per p sections; the distance to the fixed point is then about r_p / (1 - rho^p)
  (a geometric series), so a run counts as converged when that estimate is below ``tol``
  (rho is measured over the last chunk and 1 - rho^p is floored at 0.01, which makes a
  residual below tol / 100 always converged: the floor of rounding and solver error).
* **quasi-periodic** or **chaotic** when no p <= ``p_max`` converges within the budget of
  periods: the Gottwald-Melbourne 0-1 test for chaos (:func:`zero_one_test`) on the
  relative mesh displacement delta at the sections separates regular (K ~ 0) from
  chaotic (K ~ 1) motion; K >= 0.5 is chaotic.
* **unsettled** when the p = 1 residual is still falling steadily at the end of the budget
  (its maximum falls from each quarter of the second half to the next, by more than half in
  all: a lightly damped transient that needs more periods), rather than calling a slow
  decay quasi-periodic.

Natural continuation: the state handed to the next speed is the end of the kept window,
a whole number of table periods after t = 0, so the stiffness phase omega t at the new
run's t = 0 is the phase that state was computed at (``simulate`` starts every run at
phase 0).

References: G. A. Gottwald, I. Melbourne, A new test for chaos in deterministic systems,
Proc. R. Soc. Lond. A 460 (2004) 603-611; On the implementation of the 0-1 test for
chaos, SIAM J. Appl. Dyn. Syst. 8 (2009) 129-145 (correlation method, modified mean
square displacement, median over c).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearwear.core.validation import Field, fail_text

from .equations import mesh_geometry
from .model import GearDynamics
from .simulate import SimResult, simulate

__all__ = ["SteadyState", "steady_state", "section_residuals", "zero_one_test", "classify_sequence", "LABELS"]

LABELS = ("periodic", "quasi-periodic", "chaotic", "unsettled")

#: 0-1 test: K at or above this is chaotic (K ~ 1), below it regular (K ~ 0)
CHAOS_THRESHOLD = 0.5
#: floor of 1 - rho^p in the distance estimate r / (1 - rho^p)
CONTRACTION_FLOOR = 0.01
#: a period p > 1 is accepted only while every shorter period's residual is above this
#: many tol: a transient decaying at a frequency near a fraction of the excitation's also
#: nearly repeats after p periods, while a true subharmonic keeps r_1 of order 1
SUBHARMONIC_MARGIN = 1e3
#: a p = 1 residual that fell in each quarter of the second half of the budget, and by more
#: than this factor over it, is a transient still decaying ("unsettled"), not a
#: quasi-periodic motion (whose residual does not trend)
UNSETTLED_DROP = 0.5


def _group_scale(states: np.ndarray) -> np.ndarray:
    """Per-component scale (10,): the largest peak-to-peak of the displacement group
    (y_p, x_p, y_g, x_g, q) for each displacement and of the velocity group for each
    velocity, floored at 1e-15 m and 1e-12 m/s (a state at rest)."""
    ptp = np.ptp(states, axis=0)
    d = max(float(np.max(ptp[:5])), 1e-15)
    v = max(float(np.max(ptp[5:10])), 1e-12)
    return np.r_[np.full(5, d), np.full(5, v)]


def section_residuals(X: np.ndarray, p: int, scale: np.ndarray) -> np.ndarray:
    """d_k = max_i |X[k+p, i] - X[k, i]| / scale_i for k = 0 .. K-p-1 (dimensionless):
    how far the section sequence X (K, 10) is from repeating with period p."""
    X = np.asarray(X, float)
    if X.shape[0] <= p:
        return np.empty(0)
    return np.max(np.abs(X[p:] - X[:-p]) / scale, axis=1)


def zero_one_test(phi, n_c: int = 100, n_cut: int | None = None) -> float:
    """Gottwald-Melbourne 0-1 test for chaos (2009, correlation method): K in [-1, 1],
    ~0 for regular (periodic or quasi-periodic) and ~1 for chaotic sequences.

    For each c in (pi/5, 4 pi/5) (``n_c`` evenly spaced values; the median over c removes
    the resonant ones): p_c(n) = sum_{j<=n} phi_j cos(j c), q_c(n) = sum phi_j sin(j c);
    the mean square displacement M_c(n) = <(p(j+n) - p(j))^2 + (q(j+n) - q(j))^2>_j for
    n = 1 .. n_cut (default N/10), minus its oscillatory part
    V_osc = <phi>^2 (1 - cos n c) / (1 - cos c); K_c = corr(n, D_c(n)); K = median K_c.
    A bounded (regular) motion keeps D_c bounded, a chaotic one makes it grow ~ n."""
    x = np.asarray(phi, float).ravel()
    N = x.size
    if N < 50:
        raise fail_text(None, f"zero_one_test: needs at least 50 samples, got {N}")
    n_cut = int(n_cut or N // 10)
    cs = np.linspace(math.pi / 5, 4 * math.pi / 5, n_c + 2)[1:-1]
    j = np.arange(1, N + 1)
    n = np.arange(1, n_cut + 1)
    mean2 = float(np.mean(x)) ** 2
    K = np.empty(cs.size)
    for i, c in enumerate(cs):
        pc = np.cumsum(x * np.cos(j * c))
        qc = np.cumsum(x * np.sin(j * c))
        M = np.array([np.mean((pc[k:] - pc[:-k]) ** 2 + (qc[k:] - qc[:-k]) ** 2) for k in n])
        D = M - mean2 * (1 - np.cos(n * c)) / (1 - math.cos(c))
        if np.ptp(D) == 0.0:
            K[i] = 0.0
            continue
        K[i] = np.corrcoef(n, D)[0, 1]
    return float(np.median(K))


def classify_sequence(
    X: np.ndarray, observable: np.ndarray, scale: np.ndarray, tol: float, p_max: int = 8
) -> tuple[str, int, float, float | None]:
    """(label, p, residual, K) of a settled section sequence X (K, 10): periodic with the
    smallest p <= p_max whose residual max_k d_k (:func:`section_residuals`) is <= tol
    (residual = that value); otherwise the 0-1 test on ``observable`` (one value per
    section) gives chaotic (K >= 0.5) or quasi-periodic, with the p = 1 residual."""
    for p in range(1, p_max + 1):
        d = section_residuals(X, p, scale)
        if d.size and float(np.max(d)) <= tol:
            return "periodic", p, float(np.max(d)), None
    d1 = section_residuals(X, 1, scale)
    r1 = float(np.max(d1)) if d1.size else math.inf
    k = zero_one_test(observable) if np.size(observable) >= 50 else None
    if k is None:
        return "quasi-periodic", 0, r1, None
    return ("chaotic" if k >= CHAOS_THRESHOLD else "quasi-periodic"), 0, r1, k


@dataclass
class SteadyState:
    """A steady state found by :func:`steady_state`."""

    result: SimResult  # the kept window: whole multiples of p table periods
    label: str  # periodic | quasi-periodic | chaotic | unsettled
    period_table_periods: int  # p (0 unless periodic)
    period_mesh_periods: int  # p * table_periods
    residual: float  # section residual of the kept window (period p, else p = 1)
    distance_estimate: float  # residual / max(1 - rho^p, 0.01) at convergence (inf if none)
    zero_one_K: float | None  # 0-1 test K (None when periodic)
    periods_integrated: int  # table periods integrated before the kept window
    converged: bool
    z_end: np.ndarray  # state at the end of the kept window (whole table periods)
    integration_wall_s: float = 0.0  # integration wall time of every chunk and the kept window


def _chunk(model: GearDynamics, z, n_table: int, sim: dict, samples: int, dense: bool = True) -> SimResult:
    L = model.table_periods
    fm = model.mesh_frequency_Hz
    # +0.5 mesh period: simulate floors the kept window to whole mesh periods
    return simulate(model, (n_table * L + 0.5) / fm, 0.0, y0=z, samples_per_mesh_period=samples, dense=dense, **sim)


def _sections(res: SimResult, L: int, start: bool = False) -> np.ndarray:
    """The section states of a chunk: every table period after t = 0 (from t = 0 with
    ``start``), and the end state."""
    S = int(round(res.fs_Hz / res.fm_Hz))
    return np.vstack([res.states[0 if start else S * L :: S * L], res.z_end[None, :]])


def steady_state(
    model: GearDynamics,
    y0=None,
    *,
    tol: float = 1e-6,
    max_periods: int = 1500,
    chunk_periods: int = 40,
    keep_periods: int = 32,
    p_max: int = 8,
    method: str = "auto",
    steps_per_mesh_period: int = 256,
    rtol: float = 1e-8,
    atol=None,
    samples_per_mesh_period: int | None = None,
) -> SteadyState:
    """Integrate from ``y0`` (default: the static equilibrium) in chunks of
    ``chunk_periods`` table periods until the section sequence is periodic with some
    p <= ``p_max`` to ``tol`` (module docstring) or ``max_periods`` table periods are
    spent, then integrate the kept window: ``keep_periods`` table periods rounded up to a
    multiple of p, sampled at ``samples_per_mesh_period`` (default: the RK4 step count),
    whose result carries the response metrics. Returns a :class:`SteadyState`; its
    ``residual`` is measured on the kept window itself."""
    for name, v, lo in (
        ("max_periods", max_periods, 1),
        ("chunk_periods", chunk_periods, 2),
        ("keep_periods", keep_periods, 1),
        ("p_max", p_max, 1),
    ):
        if int(v) != v or v < lo:
            raise fail_text(name, f"{name} = {v}: must be a whole number >= {lo}", v)
    if not (0 < tol < 1):
        raise fail_text(
            "tol", f"tol = {tol}: must be in (0, 1)", tol, field=Field("", 0.0, 1.0, lo_open=True, hi_open=True)
        )
    L = model.table_periods
    sim = {"method": method, "steps_per_mesh_period": steps_per_mesh_period, "rtol": rtol, "atol": atol}
    z = None if y0 is None else np.asarray(y0, float).ravel().copy()
    X: list[np.ndarray] = []
    spent = 0
    converged = False
    p_found = 0
    dist = math.inf
    scale: np.ndarray  # set by every chunk; the loop runs at least once (max_periods >= 1)
    wall = 0.0
    while spent < max_periods:
        n = int(min(chunk_periods, max_periods - spent))
        # detection reads only the sections and the end state: no table-node output
        res = _chunk(model, z, n, sim, 8, dense=False)
        wall += res.wall_s
        if not X:
            X.append(res.states[0].copy())
        X.extend(_sections(res, L))
        scale = _group_scale(res.states)
        z = res.z_end.copy()
        spent += n
        seq = np.asarray(X)
        lower: list[float] = []  # r_q of the periods q < p tried so far
        for p in range(1, p_max + 1):
            d = section_residuals(seq, p, scale)
            if d.size < 2 * p + 1:
                break
            r_now = float(np.max(d[-p:]))
            lower.append(r_now)
            if r_now > tol:
                continue
            if p > 1 and min(lower[:-1]) <= SUBHARMONIC_MARGIN * tol:
                break  # a decaying transient that nearly repeats after p periods, not a subharmonic
            m = int(min(n, d.size - p))
            r_then = float(np.max(d[-p - m : -m])) if m > 0 else r_now
            rho_p = (r_now / r_then) ** (p / m) if (m > 0 and r_then > 0 and r_now > 0) else 0.0
            est = r_now / max(1.0 - rho_p, CONTRACTION_FLOOR)
            if est <= tol:
                converged, p_found, dist = True, p, est
                break
        if converged:
            break
    keep = int(keep_periods)
    if converged:
        keep = -(-keep // p_found) * p_found
    S = int(samples_per_mesh_period or steps_per_mesh_period)
    res = _chunk(model, z, keep, sim, S)
    wall += res.wall_s
    Xk = _sections(res, L, start=True)
    kscale = _group_scale(res.states)
    if converged:
        d = section_residuals(Xk, p_found, kscale)
        return SteadyState(
            res, "periodic", p_found, p_found * L, float(np.max(d)), dist, None, spent, True, res.z_end.copy(), wall
        )
    # not periodic within the budget: the second half of the sections, settled as far as it goes
    seq = np.asarray(X)
    tail = seq[seq.shape[0] // 2 :]
    obs = mesh_geometry(model, tail)[0]
    label, p, r, k = classify_sequence(tail, obs, scale, tol, p_max)
    d1 = section_residuals(tail, 1, scale)
    if label == "quasi-periodic" and d1.size >= 8:  # a decaying transient is regular (K ~ 0)
        q = [float(np.max(part)) for part in np.array_split(d1, 4)]
        if all(b < a for a, b in zip(q, q[1:])) and q[-1] < UNSETTLED_DROP * q[0]:
            label = "unsettled"
    d = section_residuals(Xk, max(p, 1), kscale)
    return SteadyState(
        res,
        label,
        p,
        p * L,
        float(np.max(d)) if d.size else math.inf,
        math.inf,
        k,
        spent,
        label == "periodic",
        res.z_end.copy(),
        wall,
    )
