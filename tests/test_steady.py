"""Steady-state detection and classification (dynamics.steady) against independent truths:
sequences whose nature is known in closed form (a periodic orbit, two incommensurate
frequencies, the logistic map), the uniqueness of a linear system's periodic response
(up and down sweeps must agree), the linearised modes (resonance speeds), and the
classic jump of a gear pair with backlash (Kahraman & Singh 1990)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearwear.dynamics import linear_eigenfrequencies, paper_pair
from gearwear.dynamics.steady import classify_sequence, section_residuals, steady_state, zero_one_test


def logistic(r: float, n: int, x0: float = 0.3, burn: int = 500) -> np.ndarray:
    x = x0
    out = np.empty(n)
    for i in range(burn + n):
        x = r * x * (1 - x)
        if i >= burn:
            out[i - burn] = x
    return out


# -- the 0-1 test for chaos on sequences of known nature ----------------------------------


def test_zero_one_test_logistic_map_chaotic_and_periodic():
    # r = 4: fully chaotic (Lyapunov exponent ln 2); r = 3.2: a stable 2-cycle
    assert zero_one_test(logistic(4.0, 1000)) > 0.9
    assert abs(zero_one_test(logistic(3.2, 1000))) < 0.1


def test_zero_one_test_quasi_periodic_is_regular():
    n = np.arange(1, 1001)
    q = np.cos(n) + 0.7 * np.cos(math.sqrt(2) * n)  # two incommensurate frequencies
    assert abs(zero_one_test(q)) < 0.2


def test_zero_one_test_noise_free_periodic_is_regular():
    n = np.arange(1000)
    assert abs(zero_one_test(np.sin(2 * np.pi * n / 3))) < 0.1


def _embed(x: np.ndarray) -> np.ndarray:
    """A 10-component 'state' sequence built from a scalar one (delay coordinates)."""
    X = np.zeros((x.size - 10, 10))
    for i in range(10):
        X[:, i] = x[i : x.size - 10 + i]
    return X


def test_classify_periodic_quasi_and_chaotic():
    scale = np.ones(10)
    per3 = np.tile([0.1, 0.5, 0.9], 200) + 1e-9 * np.sin(np.arange(600))
    label, p, r, k = classify_sequence(_embed(per3), per3[:-10], scale, 1e-6)
    assert (label, p) == ("periodic", 3) and r < 1e-6 and k is None
    n = np.arange(1, 700)
    q = np.cos(n) + 0.7 * np.cos(math.sqrt(2) * n)
    label, p, r, k = classify_sequence(_embed(q), q[:-10], scale, 1e-6)
    assert label == "quasi-periodic" and p == 0 and r > 0.1 and abs(k) < 0.2
    c = logistic(4.0, 700)
    label, p, r, k = classify_sequence(_embed(c), c[:-10], scale, 1e-6)
    assert label == "chaotic" and k > 0.9


def test_section_residuals_by_hand():
    X = np.array([[0.0] * 10, [1.0] * 10, [0.0] * 10, [1.0] * 10])
    assert np.allclose(section_residuals(X, 1, np.full(10, 2.0)), 0.5)
    assert np.allclose(section_residuals(X, 2, np.ones(10)), 0.0)


# -- natural continuation -------------------------------------------------------------------


def test_continuation_from_a_converged_state_is_periodic_from_the_first_period():
    """The kept window ends on a whole mesh period, so its end state belongs to stiffness
    phase 0, which is where the next run starts: restarting from it at the same speed
    repeats the orbit from the first section. A state taken half a period into the window
    (the wrong phase) does not: the negative control shows the check can fail."""
    m = paper_pair(40.0, 3000.0)
    s = steady_state(m, tol=1e-9, chunk_periods=20)
    again = steady_state(m, s.z_end, tol=1e-9, chunk_periods=20)
    assert again.periods_integrated == 20  # converged in the first chunk
    assert again.residual < 1e-10
    F0, F1 = s.result.signals["F_m"], again.result.signals["F_m"]
    n = min(F0.size, F1.size)
    assert np.max(np.abs(F1[:n] - F0[:n])) < 1e-8 * np.ptp(F0)
    S = int(round(s.result.fs_Hz / s.result.fm_Hz))
    wrong = steady_state(m, s.result.states[S // 2], tol=1e-9, chunk_periods=20)
    assert wrong.periods_integrated > 20


# -- linear system: a unique periodic response, peaks at the modes ---------------------------


def _sweep(model, speeds, **kw):
    z = None
    out = []
    for rpm in speeds:
        mm = model.with_(omega_p=rpm * 2 * math.pi / 60)
        s = steady_state(mm, z, **kw)
        z = s.z_end
        out.append(s)
    return out


def test_linear_system_up_and_down_coincide_and_peak_at_the_modes():
    m = paper_pair(40.0, 2000.0)
    f_mode = linear_eigenfrequencies(m)[0]  # 1037 Hz, the first coupled torsion-bearing mode
    n_res = 60 * f_mode / m.z_p  # first mesh harmonic on it: 2074 rpm
    step = 25.0
    speeds = np.arange(1900.0, 2250.0 + 1, step)
    up = _sweep(m, speeds, tol=1e-9)
    down = _sweep(m, speeds[::-1], tol=1e-9)[::-1]
    for a, b in zip(up, down):
        assert a.label == b.label == "periodic" and a.period_mesh_periods == 1
        for key in ("F_m", "delta"):
            x, y = a.result.signals[key], b.result.signals[key]
            assert abs(x.max() - y.max()) <= 1e-6 * abs(x.max())
            assert abs(np.ptp(x) - np.ptp(y)) <= 1e-6 * np.ptp(x)
    h1 = np.array([s.result.harmonics("delta", 1)[0] for s in up])
    assert abs(speeds[np.argmax(h1)] - n_res) <= step


def _frf_delta(m, f_Hz: float) -> complex:
    """delta per unit excitation e at f_Hz from the hand-assembled linear 5-DOF model:
    M z'' + C z' + K z = g k e(t) with g = d delta / dz (independent of the solver)."""
    ca, sa = math.cos(m.alpha), math.sin(m.alpha)
    g = np.array([ca, sa, -ca, -sa, 1.0])
    cbp, cbg = m.c_b_pair
    M = np.diag([m.m_p, m.m_p, m.m_g, m.m_g, m.m_e])
    K = np.diag([m.k_b] * 4 + [0.0]) + m.k_mean * np.outer(g, g)
    C = np.diag([cbp, cbp, cbg, cbg, 0.0]) + m.c_h * np.outer(g, g)
    w = 2 * math.pi * f_Hz
    z = np.linalg.solve(K - w * w * M + 1j * w * C, g * m.k_mean)
    return complex(g @ z)


def test_linear_forced_response_equals_the_frequency_response_and_peaks_at_the_modes():
    """Constant stiffness with the excitation e = A (1 - cos phi_m) / 2: a linear
    time-invariant system forced at f_m only. Its steady delta harmonic is |H(f_m)| e_1,
    e_1 the first harmonic of the excitation, with H the frequency response of the hand-assembled matrices,
    at every speed of the
    run-up (1e-6), and the run-up's maximum sits within one speed step of each mode that
    delta sees (1037 and 4080 Hz; the 1325 Hz bearing modes do not move delta)."""
    A = 2e-6
    m = paper_pair(40.0, 2000.0, tvms=False, te_amplitude_m=A)
    modes = linear_eigenfrequencies(m)
    for f_mode, step in ((modes[0], 25.0), (modes[-1], 100.0)):
        n_res = 60 * f_mode / m.z_p
        speeds = n_res + step * np.arange(-4, 5) + step / 3  # not centred on the answer
        runs = _sweep(m, speeds, tol=1e-9)
        h1 = np.array([s.result.harmonics("delta", 1)[0] for s in runs])
        # the solver sees the linear interpolant of e's 256-row table, whose first harmonic
        # is that of the cosine times sinc^2(pi / 256) (1 - 5.0e-5)
        e1 = A / 2 * np.sinc(1 / m.phi_table.size) ** 2
        frf = np.array([abs(_frf_delta(m, rpm * m.z_p / 60)) * e1 for rpm in speeds])
        assert np.max(np.abs(h1 / frf - 1)) < 1e-6
        assert abs(speeds[np.argmax(h1)] - n_res) <= step


# -- backlash: the jump ----------------------------------------------------------------------


def _band(model, speeds, rel=0.01):
    up = _sweep(model, speeds, tol=1e-6)
    down = _sweep(model, speeds[::-1], tol=1e-6)[::-1]
    kv = lambda s: float(s.result.signals["F_m"].max() / model.F_s)  # noqa: E731
    differ = [abs(kv(a) - kv(b)) > rel * max(kv(a), kv(b)) for a, b in zip(up, down)]
    return speeds[np.array(differ)], up, down


def test_backlash_jump_band_is_located_and_stays_put_when_the_grid_is_halved():
    """Light load (5 N m), 100 um backlash, 2 % mesh damping: the softening contact loss
    near the main resonance (the first mode at 2074 rpm) gives an upper branch that the
    down-sweep follows and the up-sweep misses: they differ inside a band below the
    resonance and agree outside it. Halving the speed step moves each edge by less than
    the coarse step."""
    m = paper_pair(5.0, 2000.0, backlash_total_m=100e-6, zeta_m=0.02)
    coarse = np.arange(1650.0, 2100.0 + 1, 50.0)
    fine = np.arange(1650.0, 2100.0 + 1, 25.0)
    b1, up, down = _band(m, coarse)
    b2, _, _ = _band(m, fine)
    assert b1.size >= 3 and b2.size >= 5
    assert coarse[0] < b1.min() and b1.max() < coarse[-1]  # it agrees outside the band
    # the fold is approached more closely with smaller steps (a large step can leave the upper
    # branch's shrinking basin early), so an edge may move by up to one coarse step
    assert abs(b2.min() - b1.min()) <= 50.0 and abs(b2.max() - b1.max()) <= 50.0
    inside = np.isin(coarse, b1)
    # the upper branch (down-sweep) loses contact, the lower one (up-sweep) does not
    assert all(d.result.separation_fraction > 0.05 for d, i in zip(down, inside) if i)
    assert all(u.result.separation_fraction == 0.0 for u, i in zip(up, inside) if i)


def test_a_slowly_decaying_transient_is_unsettled_not_quasi_periodic():
    """A linear pair has one periodic response; with 0.2 % damping at 12 000 rpm (a decay
    time of ~300 mesh periods) 400 periods do not reach it, and the steadily falling
    residual must say so rather than pass for quasi-periodic motion."""
    m = paper_pair(40.0, 12000.0, zeta_m=0.002, zeta_b=0.002)
    s = steady_state(m, tol=1e-9, max_periods=400)
    assert s.label == "unsettled" and not s.converged and s.period_mesh_periods == 0


@pytest.mark.parametrize("bad", [dict(tol=0.0), dict(max_periods=0), dict(chunk_periods=1), dict(p_max=0)])
def test_bad_settings_are_one_line_errors(bad):
    from gearwear.core.validation import InputError

    with pytest.raises(InputError):
        steady_state(paper_pair(40.0, 1200.0), **bad)
