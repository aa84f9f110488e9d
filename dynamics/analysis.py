"""Pure post-processing: spectra, mesh harmonics, energy balance."""

from __future__ import annotations

import numpy as np

from gearwear.core.validation import fail_text

from .equations import (
    _accelerations,
    accelerations_and_state,
    accelerations_from_force,
    bearing_f,
    has_flank_law,
    mesh_state,
)
from .model import GearDynamics

_trapezoid = getattr(np, "trapezoid", None) or getattr(np, "trapz")

__all__ = [
    "spectrum",
    "harmonics",
    "window_harmonics",
    "window_fourier",
    "fourier_amplitudes",
    "gauss_grid",
    "dense_derivatives",
    "event_pieces",
    "energy_balance",
    "mechanical_energy",
    "acceleration_signals",
]

#: pieces per pass of the window integrals and rows per block of the dense derivatives: the
#: temporaries of one pass (states at the Gauss nodes, the signals, the phasors) stay about
#: 1 MB each, in the cache and reused by the allocator, where one pass over a whole window
#: (180 000 pieces of a 0.5 s paper scene at 2400 rpm) allocated and page-faulted ~40 MB
#: arrays: the window integrals of that run took 180 ms that way and 85 ms in blocks of
#: 4096 (the same sums in a different order: 2e-14 relative)
BLOCK = 4096

# 3-point Gauss-Legendre on [0, 1]: exact for polynomials of degree 5
_GL_X = 0.5 + 0.5 * np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_GL_W = 0.5 * np.array([5.0, 8.0, 5.0]) / 9.0


def spectrum(signal, fs: float):
    """Single-sided amplitude spectrum (no window): a sinusoid of amplitude A on a bin
    shows A, the DC bin shows the mean. Use a whole number of periods of the
    frequencies of interest (the simulation window is whole mesh periods; for the shaft
    orders of a multi-period table, whole table periods: ``simulate.round_to_table_periods``)."""
    x = np.asarray(signal, float)
    N = x.size
    X = np.fft.rfft(x) / N
    amp = np.abs(X)
    amp[1:] *= 2.0
    if N % 2 == 0:
        amp[-1] /= 2.0
    return np.fft.rfftfreq(N, 1.0 / fs), amp


def harmonics(signal, fs: float, fm: float, n: int = 10) -> np.ndarray:
    """Amplitudes of the harmonics k fm, k = 1..n, by projection on exp(-i 2 pi k fm t).

    Equal to the FFT bin when the record holds a whole number of mesh periods."""
    x = np.asarray(signal, float)
    N = x.size
    t = np.arange(N) / fs
    k = np.arange(1, n + 1)[:, None]
    ph = np.exp(-2j * np.pi * fm * k * t[None, :])
    return 2.0 * np.abs(ph @ x) / N


def gauss_grid(breaks) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature nodes and weights (3-point Gauss-Legendre per interval) over the sorted
    breakpoints: exact for integrands that are polynomials of degree <= 5 between breaks."""
    b = np.asarray(breaks, float)
    return _gauss_nodes(b[:-1], np.diff(b))


def _gauss_nodes(a: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """3-point Gauss-Legendre nodes and weights of the intervals [a_j, a_j + w_j], in time
    order (3 per interval)."""
    tq = (a[:, None] + w[:, None] * _GL_X[None, :]).ravel()
    wq = (w[:, None] * _GL_W[None, :]).ravel()
    return tq, wq


def fourier_amplitudes(x, tq, wq, f0: float, n: int, span: float) -> np.ndarray:
    """Amplitudes |c_k|, k = 1..n, of x(t) = sum c_k cos(2 pi k f0 t + phi_k) over a window of
    length ``span`` (a whole number of periods 1/f0): c_k = (2 / span) |int x e^{-i 2 pi k f0 t} dt|,
    by the quadrature (tq, wq)."""
    return 2.0 * np.abs(_phasors(tq, f0, n) @ (np.asarray(wq) * np.asarray(x))) / span


def _phasors(tq, f0: float, n: int, k0: int = 1) -> np.ndarray:
    """e^{-i 2 pi k f0 t} for k = k0..n (rows; k0 = 0 adds the row of ones that integrates the
    mean) by repeated products: one complex exp per point."""
    tq = np.asarray(tq, float)
    ph = np.empty((n, tq.size), complex)
    ph[0] = np.exp(-2j * np.pi * f0 * tq)
    for j in range(1, n):
        np.multiply(ph[j - 1], ph[0], out=ph[j])
    return np.vstack([np.ones((1, tq.size), complex), ph]) if k0 == 0 else ph


def window_harmonics(result, names, n: int = 10, chunk: int = BLOCK) -> dict:
    """Amplitudes of the mesh harmonics k f_m (k = 1..n): ``|window_fourier|``."""
    return {name: np.abs(c) for name, c in window_fourier(result, names, n, chunk).items()}


def window_fourier(result, names, n: int = 10, chunk: int = BLOCK, fold: bool = True) -> dict:
    """Complex mesh-harmonic coefficients c_k, k = 1..n (:func:`window_integrals`)."""
    return window_integrals(result, names, n, chunk, fold)[0]


def window_integrals(result, names, n: int = 10, chunk: int = BLOCK, fold: bool = True) -> tuple[dict, dict]:
    """Complex mesh-harmonic coefficients c_k = (2 / T) int x(t) e^{-i 2 pi k f_m t} dt,
    k = 1..n, of signals over the whole sampled window (length T, whole mesh periods, so
    the phase is referred to the mesh angle phi = 0 at t = 0), as exact Fourier
    integrals of the continuous signal rather than a DFT of its samples.

    Why: F_m = c_h delta' + k_h(phi) f(s) contains the linear table k_h(phi), whose kinks
    put energy at all harmonics up to the table's resolution; a DFT of S samples per mesh
    period folds harmonic S +- k onto k (aliasing), which for a worn table is larger
    than the harmonic itself. ``simulate`` therefore also samples the state at every
    table node inside the window [t_0, t_0 + M T_m] (``result.t_dense``), and the adaptive
    solver returns every switching event it located there (``result.window_events``): at
    contact loss and flank impacts the acceleration jumps (and F_m with the mesh damper),
    at bearing contacts it kinks, so the pieces between output times that hold events are
    split there (:func:`event_pieces`). Inside every piece the state is smooth and is taken
    as the cubic Hermite interpolant of the states and their exact derivatives (the model's
    right-hand side; the solver's one-sided derivatives at events), the tables are linear,
    and 3-point Gauss-Legendre integrates each piece of the signal to the interpolation
    error of the integrator's own output (O(h^4)). The signals are evaluated by
    ``compute_signals`` (the same definitions as the samples; inside a piece the contact
    mode of the interpolated state is the piece's own). RK4 locates no events: its
    harmonics with backlash or clearance keep the error of pieces across them (and RK4's
    own, first order there).

    Cost (``fold``; the same integral, reordered): the output times repeat every period,
    so e^{-i k w t} repeats too, and the weighted signal is summed over the periods
    before one period's phasors are applied. Without a flank law (no backlash, static or
    no centre-distance coupling) every signal is affine in the state with coefficients
    that repeat every table period, s(t, z) = A(t) z + b(t); then the sum over the R
    table periods of s(t_q + r T, z_r) is s(t_q, sum_r z_r) + (R - 1) s(t_q, 0), and the
    Hermite interpolant is linear in its end values, so the states are summed first and
    the signals are evaluated on one table period only (a 1 s run: ~0.3 s -> ~0.02 s).
    Both folds leave out the pieces that hold events (zero weight; in the affine sums
    piece q counts the c_q periods where it is whole: s(t_q, sum z) + (c_q - 1) s(t_q, 0))
    and add those pieces' sub-pieces one by one. ``fold=False`` evaluates every piece
    (the reference the tests compare with). Returns (coefficients, means): the means are the
    exact window means (1 / T) int x dt, the k = 0 row of the same pass."""
    from .simulate import compute_signals

    model = result.model
    t = result.t_dense
    Z = result.states_dense
    span = t[-1] - t[0]
    L = model.table_periods
    R = result.n_periods // L if result.n_periods % L == 0 else 0
    # row 0 is k = 0 (the mean), rows 1..n the harmonics: one pass integrates both
    acc = {name: np.zeros(n + 1, complex) for name in names}
    if fold and R >= 2 and _affine_rhs(model) and _event_sides(result) is None:
        Pt = _period_pattern(t, R)
        if Pt:
            _affine_fold_states(acc, model, t, Z, R, Pt, names, n, result.fm_Hz, compute_signals)
            return (
                {name: 2.0 * v[1:] / span for name, v in acc.items()},
                {name: float(v[0].real) / span for name, v in acc.items()},
            )
    F = dense_derivatives(result)
    broken, sub = event_pieces(result, F)
    if sub is not None:
        _add_pieces(acc, model, *sub, names, n, result.fm_Hz, chunk, compute_signals, k0=0)
    Pt = _period_pattern(t, R) if fold and R >= 2 and not has_flank_law(model) else 0
    P = _period_pattern(t, result.n_periods) if fold and not Pt else 0
    if Pt:
        _affine_fold(acc, model, t, Z, F, broken, R, Pt, names, n, result.fm_Hz, compute_signals, k0=0)
    elif P:
        # the sample times repeat every mesh period (uniform grid + table nodes), so
        # e^{-i k w t} does too (k w T_m = 2 pi k): sum the weighted signal over the periods
        # first and apply the phasors of one period (n x 3P products instead of n x 3MP)
        chunk = max(1, chunk // P) * P
        ph = None
        for c0 in range(0, t.size - 1, chunk):
            sel = np.arange(c0, min(c0 + chunk, t.size - 1))
            tq, wq, sig = _signals_at_quadrature(model, t, Z, F, sel, names, compute_signals)
            if sub is not None:
                wq = wq * np.repeat(~broken[sel], 3)
            if ph is None:
                ph = _phasors(tq[: 3 * P], result.fm_Hz, n, k0=0)
            for name in names:
                acc[name] += ph @ (wq * sig[name]).reshape(-1, 3 * P).sum(axis=0)
    else:
        _add_pieces(acc, model, t, Z, F, np.nonzero(~broken)[0], names, n, result.fm_Hz, chunk, compute_signals, k0=0)
    return (
        {name: 2.0 * v[1:] / span for name, v in acc.items()},
        {name: float(v[0].real) / span for name, v in acc.items()},
    )


def _add_pieces(acc, model, t, Z, F, pieces, names, n: int, fm_Hz: float, chunk: int, compute_signals, k0: int = 1):
    """acc[name] += int x e^{-i k w t} dt, k = k0..n, over the pieces [t_j, t_j+1] listed (in chunks)."""
    for c0 in range(0, pieces.size, chunk):
        tq, wq, sig = _signals_at_quadrature(model, t, Z, F, pieces[c0 : c0 + chunk], names, compute_signals)
        ph = _phasors(tq, fm_Hz, n, k0)
        for name in names:
            acc[name] += ph @ (wq * sig[name])


#: an output time this close to an event (in mesh periods) is the event's instant: its state
#: is the event's and its side, which the state alone cannot tell, is ambiguous
EVENT_SNAP_PERIODS = 1e-9


def _event_sides(result):
    """The window's events and where they meet the output times t_dense: (rows, lo, hi,
    first, last); output times lo..hi-1 are within EVENT_SNAP_PERIODS of the event, first /
    last mark events at the window's start / end. None without events."""
    from .kernels import EV_T

    ev = getattr(result, "window_events", None)
    if ev is None or ev.shape[0] == 0:
        return None
    t = result.t_dense
    tol = EVENT_SNAP_PERIODS / result.fm_Hz
    te = ev[:, EV_T]
    lo = np.searchsorted(t, te - tol, side="left")
    hi = np.searchsorted(t, te + tol, side="right")
    first = (hi > lo) & (lo == 0)
    last = (hi > lo) & (hi == t.size) & ~first
    return ev, lo, hi, first, last


def dense_derivatives(result) -> np.ndarray:
    """Time derivatives (len(t_dense), 10) of the dense states ``result.states_dense``:
    the model's right-hand side at each state (velocities, then ``_accelerations``). An
    event at the window's first (last) output time gives it the solver's derivative after
    (before) the event, the side inside the window."""
    from .kernels import EV_F0, EV_F1

    Z, t = result.states_dense, result.t_dense
    F = np.empty((Z.shape[0], 10))
    F[:, :5] = Z[:, 5:10]
    # row by row the same numbers; in blocks, the temporaries stay small (BLOCK)
    for a in range(0, Z.shape[0], BLOCK):
        F[a : a + BLOCK, 5:] = _accelerations(result.model, t[a : a + BLOCK], Z[a : a + BLOCK])
    sides = _event_sides(result)
    if sides is not None:
        ev, lo, hi, first, last = sides
        if first.any():
            F[0] = ev[np.nonzero(first)[0][-1], EV_F1 : EV_F1 + 10]
        if last.any():
            F[-1] = ev[np.nonzero(last)[0][0], EV_F0 : EV_F0 + 10]
    return F


def event_pieces(result, F) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None]:
    """The pieces of the window integral that switching events split.

    Returns (broken, sub): broken[j] marks the piece [t_j, t_j+1] of ``result.t_dense``
    that holds an event (or ends on an output time within EVENT_SNAP_PERIODS of one, which
    the event replaces); sub = (t, Z, F, pieces) are the nodes of those pieces with every
    event inside them twice, the first copy with the solver's derivative before the event,
    the second with the one after (the kernel's rows, ``result.window_events``), and the
    indices of their sub-pieces (a zero-length one between the copies has zero weight).
    ``F`` are the output times' derivatives (:func:`dense_derivatives`). sub is None
    without events inside the window."""
    from .kernels import EV_F0, EV_F1, EV_T, EV_Z

    t = result.t_dense
    n = t.size
    broken = np.zeros(n - 1, dtype=bool)
    sides = _event_sides(result)
    if sides is None:
        return broken, None
    ev, lo, hi, first, last = sides
    inner = ~(first | last)
    if not inner.any():
        return broken, None
    ev, lo, hi = ev[inner], lo[inner], hi[inner]
    # pieces lo-1 .. hi-1 touch the event (one piece, or the two around a replaced time)
    d = np.zeros(n, dtype=np.int64)
    np.add.at(d, lo - 1, 1)
    np.add.at(d, np.maximum(hi, lo), -1)
    broken = np.cumsum(d)[:-1] > 0
    dropped = np.zeros(n, dtype=bool)
    for e in np.nonzero(hi > lo)[0]:
        dropped[lo[e] : hi[e]] = True
    ends = np.zeros(n, dtype=bool)
    ends[:-1] |= broken
    ends[1:] |= broken
    keep = np.nonzero(ends & ~dropped)[0]
    k = ev.shape[0]
    m = keep.size + 2 * k
    # rows are in time order and no kept output time is an event's: the copies of event e
    # follow the kept times before it and the copies of the events before it
    before = np.searchsorted(t[keep], ev[:, EV_T]) + 2 * np.arange(k)
    copy = np.zeros(m, dtype=bool)
    copy[before] = copy[before + 1] = True
    ts, Zs, Fs = np.empty(m), np.empty((m, 10)), np.empty((m, 10))
    ts[~copy], Zs[~copy], Fs[~copy] = t[keep], result.states_dense[keep, :10], F[keep]
    for c, f0 in ((before, EV_F0), (before + 1, EV_F1)):
        ts[c], Zs[c], Fs[c] = ev[:, EV_T], ev[:, EV_Z : EV_Z + 10], ev[:, f0 : f0 + 10]
    # a piece between two output times is either whole (integrated with the rest) or the
    # gap between two runs of broken pieces: only pieces with an event end are new
    pieces = np.nonzero(copy[:-1] | copy[1:])[0]
    return broken, (ts, Zs, Fs, pieces)


def _affine_rhs(model: GearDynamics) -> bool:
    """The whole right-hand side is affine in the state, dz/dt = A(t) z + b(t), with A and b
    repeating every table period: no flank law (a two-sided linear mesh spring, static or
    no centre-distance coupling) and no bearing dead zone. Then no switching event exists
    and the derivatives fold over the periods like the signals (:func:`_affine_fold_states`)."""
    return not has_flank_law(model) and model.bearing_half_clearance_m is None


def _affine_fold_states(acc, model, t, Z, R: int, Pt: int, names, n: int, fm_Hz: float, compute_signals):
    """acc[name] += the whole window integral (k = 0..n) when the right-hand side is affine
    (:func:`_affine_rhs`): the fold of :func:`_affine_fold` with the derivatives folded too.
    The sum over the R table periods of f(t_j + r T, z_r) = A(t_j) z_r + b(t_j) is
    f(t_j, sum_r z_r) + (R - 1) f(t_j, 0), so the derivatives are evaluated at the Pt + 1
    times of one period instead of at every dense time (dense_derivatives): the same
    integral, its terms summed in another order (a 0.5 s run of the paper pair: 131 000
    accelerations -> 2 x 658)."""
    Zs0, Zs1 = period_sums(Z, R, Pt)
    tb = t[: Pt + 1]

    def folded(tj, Zs):
        a = _accelerations(model, tj, Zs) + (R - 1) * _accelerations(model, tj, np.zeros_like(Zs))
        return np.hstack([Zs[:, 5:10], a])

    _affine_apply(
        acc, model, tb, Zs0, Zs1, folded(tb[:-1], Zs0), folded(tb[1:], Zs1), np.full(Pt, float(R)),
        names, n, fm_Hz, compute_signals, 0,
    )  # fmt: skip


def period_sums(Z: np.ndarray, R: int, Pt: int) -> tuple[np.ndarray, np.ndarray]:
    """(S0, S1): the states at the starts (Z[:-1]) and at the ends (Z[1:]) of the pieces,
    each summed over the R periods of Pt pieces, S0[j] = sum_r Z[r Pt + j] and S1[j] =
    sum_r Z[r Pt + j + 1]. S1[j] = S0[j + 1] but for the last piece (the same rows added in
    the same order), so the window's states are read once for both: the second pass over
    them (10 MB for a 0.5 s paper scene) cost ~1.5 ms a point. Equal to the bit to
    ``Z[1:].reshape(R, Pt, nz).sum(axis=0)`` (tests/test_sweep_cost.py)."""
    nz = Z.shape[1]
    S0 = Z[:-1].reshape(R, Pt, nz).sum(axis=0)
    S1 = np.empty_like(S0)
    S1[:-1] = S0[1:]
    # the period ends Z[Pt], Z[2 Pt], ..., Z[R Pt], added in that order like the rest
    S1[-1] = Z[Pt::Pt][:R].sum(axis=0)
    return S0, S1


def _affine_fold(
    acc, model, t, Z, F, broken, R: int, Pt: int, names, n: int, fm_Hz: float, compute_signals, k0: int = 1
):
    """acc[name] += the window integral over the whole pieces for signals affine in the
    state (window_fourier): the end values of every piece summed over the R table periods
    (Pt pieces each) with the pieces that hold events left out, the signals on one period."""
    nz = Z.shape[1]
    Zs0, Zs1, Fs0, Fs1 = (X.reshape(R, Pt, nz).sum(axis=0) for X in (Z[:-1], Z[1:], F[:-1], F[1:]))
    count = np.full(Pt, float(R))
    out = np.nonzero(broken)[0]
    if out.size:
        # few pieces (two per event at most): take them out of the sums again
        q = out % Pt
        for Xs, X in ((Zs0, Z[out]), (Zs1, Z[out + 1]), (Fs0, F[out]), (Fs1, F[out + 1])):
            np.subtract.at(Xs, q, X)
        np.subtract.at(count, q, 1.0)
    _affine_apply(acc, model, t[: Pt + 1], Zs0, Zs1, Fs0, Fs1, count, names, n, fm_Hz, compute_signals, k0)


def _affine_apply(acc, model, tb, Zs0, Zs1, Fs0, Fs1, count, names, n: int, fm_Hz: float, compute_signals, k0: int):
    """acc[name] += the folded integral: the Hermite interpolant of the period-summed piece
    ends (Zs0, Zs1, slopes Fs0, Fs1) at the Gauss nodes of one period's pieces (times tb),
    the signals there, plus (count - 1) times the signals of the zero state."""
    w = np.diff(tb)
    tq, wq = _gauss_nodes(tb[:-1], w)
    dt = w[:, None]
    Zq = _hermite_at_gauss(Zs0, Zs1, Fs0 * dt, Fs1 * dt)
    summed = compute_signals(model, tq, Zq)
    zero = compute_signals(model, tq, np.zeros_like(Zq))
    ph = _phasors(tq, fm_Hz, n, k0)
    c = np.repeat(count - 1.0, 3)
    for name in names:
        acc[name] += ph @ (wq * (summed[name] + c * zero[name]))


def _hermite_at_gauss(Z0, Z1, F0, F1) -> np.ndarray:
    """Cubic Hermite interpolant of every piece (end values Z0, Z1 and end slopes times the
    piece length F0, F1) at the 3 Gauss nodes, rows in time order. At a Gauss node the
    Hermite basis is a constant of the node, so every piece is interpolated at once."""
    nodes = []
    for th in _GL_X:
        h00, h10 = 2 * th**3 - 3 * th**2 + 1, th**3 - 2 * th**2 + th
        h01, h11 = -2 * th**3 + 3 * th**2, th**3 - th**2
        nodes.append(h00 * Z0 + h10 * F0 + h01 * Z1 + h11 * F1)
    return np.stack(nodes, axis=1).reshape(-1, Z0.shape[1])


def _period_pattern(t: np.ndarray, M: int) -> int:
    """Intervals per mesh period P when the dense times t (M P + 1 of them) repeat the same
    offsets in every one of the M mesh periods of the window (to 1e-9 of a period), else 0."""
    if M < 2 or (t.size - 1) % M:
        return 0
    P = (t.size - 1) // M
    T = (t[-1] - t[0]) / M
    tt = t[:-1].reshape(M, P)
    start = t[0] + T * np.arange(M)
    if np.max(np.abs(tt[:, 0] - start)) > 1e-9 * T:
        return 0
    tau = tt - start[:, None]
    return P if np.max(np.abs(tau - tau[0])) <= 1e-9 * T else 0


def _signals_at_quadrature(model, t, Z, F, pieces, names, compute_signals):
    """Gauss points and weights of the pieces [t_j, t_j+1] (j in ``pieces``, increasing),
    and the signals there from the cubic Hermite interpolant of the states Z and
    derivatives F."""
    if pieces.size and pieces[-1] - pieces[0] + 1 == pieces.size:
        # a run of pieces: slices are views, where an index array would copy Z and F
        j0, j1 = slice(pieces[0], pieces[-1] + 1), slice(pieces[0] + 1, pieces[-1] + 2)
    else:
        j0, j1 = pieces, pieces + 1
    a = t[j0]
    dt = t[j1] - a
    tq, wq = _gauss_nodes(a, dt)
    dt = dt[:, None]
    Zq = _hermite_at_gauss(Z[j0], Z[j1], F[j0] * dt, F[j1] * dt)
    return tq, wq, compute_signals(model, tq, Zq)


def mechanical_energy(model: GearDynamics, t, Z) -> np.ndarray:
    """Kinetic + bearing strain + mesh strain energy (reduced model) at states Z (N, 10)."""
    Z = np.atleast_2d(np.asarray(Z, float))
    t = np.atleast_1d(np.asarray(t, float))
    T = 0.5 * (
        model.m_p * (Z[:, 5] ** 2 + Z[:, 6] ** 2) + model.m_g * (Z[:, 7] ** 2 + Z[:, 8] ** 2) + model.m_e * Z[:, 9] ** 2
    )
    Vb = 0.5 * model.k_b * np.sum(bearing_f(model, Z[:, :4]) ** 2, axis=1)
    return T + Vb + mesh_state(model, t, Z)["V_mesh"]


def energy_balance(result, model: GearDynamics) -> dict:
    """Energy balance over the sampled window [t_0, t_end]:

        dE = W_in - D + W_k + W_e
        W_in = int F_s q' dt (torques' work, reduced), D = int c_b |v|^2 + F_damp delta' dt,
        W_k = int 1/2 (dk/dt) f(s)^2 dt (parametric work of the time-varying stiffness),
        W_e = -int k f(s) (de/dt) dt (work of the transmission-error excitation).

    Uses the quadrature states integrated with the solution (``simulate(...,
    track_energy=True)``); otherwise the trapezoidal rule on the sampled power (less
    accurate across contact events). relative_residual = |residual| / max |term|.
    The dynamic centre-distance coupling is derived from the flank potentials, so it
    closes too."""
    Z = result.states
    t = result.t
    E = mechanical_energy(model, t, Z)
    dE = float(E[-1] - E[0])
    if result.energy is not None:
        W = {k: float(v[-1] - v[0]) for k, v in result.energy.items()}
        how = "quadrature states"
    else:
        ms = mesh_state(model, t, Z)
        cbp, cbg = model.c_b_pair
        p_in = model.F_s * Z[:, 9]
        p_d = cbp * (Z[:, 5] ** 2 + Z[:, 6] ** 2) + cbg * (Z[:, 7] ** 2 + Z[:, 8] ** 2) + ms["F_damp"] * ms["delta_dot"]
        p_k = 0.5 * ms["dk_dt"] * (ms["f_drive"] ** 2 + ms["f_back"] ** 2)
        p_e = -ms["k_h"] * (ms["f_drive"] + ms["f_back"]) * ms["de_dt"]
        W = {k: float(_trapezoid(p, t)) for k, p in (("W_in", p_in), ("D", p_d), ("W_k", p_k), ("W_e", p_e))}
        how = "grid trapezoid"
    res = dE - (W["W_in"] - W["D"] + W["W_k"] + W["W_e"])
    scale = max(abs(dE), abs(W["W_in"]), abs(W["D"]), abs(W["W_k"]), abs(W["W_e"]), 1e-300)
    return dict(
        input_work=W["W_in"],
        dissipated=W["D"],
        parametric_work=W["W_k"],
        excitation_work=W["W_e"],
        energy_change=dE,
        E_start=float(E[0]),
        E_end=float(E[-1]),
        residual=res,
        relative_residual=abs(res) / scale,
        method=how,
    )


def acceleration_signals(result) -> dict:
    """Accelerations (m/s^2) at the samples ``result.t``, from the model's right-hand side
    at the sampled states (exact, no differentiation of samples): ``a_y_p, a_x_p, a_y_g,
    a_x_g`` (bearing translations), ``a_q`` (relative torsional coordinate) and
    ``a_delta``, the relative acceleration along the line of action, G . a with G = d delta /
    d(y_p, x_p, y_g, x_g, q). With the static centre-distance coupling G is constant and
    a_delta = delta'' exactly; with the dynamic coupling G depends on the state and the
    term dG/dt . v (second order in the bearing velocities) is left out.

    Like F_m, these carry the stiffness table's kinks: a DFT of S samples per mesh
    period aliases the high harmonics onto the low ones (onto mesh harmonics and, with
    a multi-period table, onto shaft orders; never onto other frequencies when the
    window is whole table periods)."""
    model = result.model
    if model is None:
        raise fail_text(None, "acceleration_signals: the result carries no model")
    return accelerations_at(model, result.t, result.states)


def accelerations_at(model: GearDynamics, t, Z, F_m=None) -> dict:
    """:func:`acceleration_signals` at the times t and states Z (a part of the samples: the
    same numbers there, each sample's acceleration depends on its own state only).
    ``F_m``: the mesh force at those states if known (the result's signal); with the
    static coupling the accelerations then follow from it without evaluating the mesh
    state again (equations.accelerations_from_force)."""
    if F_m is not None and model.centre_distance != "dynamic":
        a, G = accelerations_from_force(model, Z, F_m)
    else:
        a, ms = accelerations_and_state(model, t, Z)
        G = ms["G"]
    out = {name: a[:, i].copy() for i, name in enumerate(("a_y_p", "a_x_p", "a_y_g", "a_x_g", "a_q"))}
    out["a_delta"] = _dot5(G, a)
    return out


def _dot5(G: np.ndarray, a: np.ndarray) -> np.ndarray:
    """sum_i G_i a_i over the last axis of a (N, 5) (G: (5,) or (N, 5)), added left to right
    as ``np.sum(G * a, axis=1)`` adds a row of five (the same numbers to the bit, checked in
    tests/test_sweep_cost.py), without the (N, 5) product and numpy's reduction over short
    rows (~4x the time for the 46 000 samples of a sweep point's indicators)."""
    g = G.T if G.ndim == 2 else G
    out = g[0] * a[:, 0]
    for i in range(1, a.shape[1]):
        out += g[i] * a[:, i]
    return out
