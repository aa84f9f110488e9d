"""Dynamics, linear truths: static deflection, eigenfrequencies (hand-assembled M, K),
free-vibration spectrum, spectrum scaling, effects at zero magnitude."""

import math

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.signal import find_peaks

from gearwear.core.validation import InputError
from gearwear.dynamics import (
    GearDynamics,
    harmonics,
    linear_eigenfrequencies,
    paper_pair,
    simulate,
    spectrum,
    static_equilibrium,
)

DEG20 = math.radians(20.0)


def test_settles_to_static_deflection_constant_stiffness():
    k = 4.0e8
    m = paper_pair(tvms=False, k_constant=k)
    F = 40.0 / m.R_p
    r = simulate(m, 0.3, 0.29, y0=np.zeros(10))  # start from rest, undeformed
    assert r.method == "rk4"
    tail = slice(-256, None)
    rel = lambda a, b: np.max(np.abs(np.asarray(a) - b)) / abs(b)  # noqa: E731
    assert rel(r.signals["delta"][tail], F / k) < 1e-6
    assert rel(r.signals["F_m"][tail], F) < 1e-6
    assert rel(r.signals["y_p"][tail], -F * math.cos(DEG20) / m.k_b) < 1e-6
    assert rel(r.signals["x_p"][tail], -F * math.sin(DEG20) / m.k_b) < 1e-6
    assert rel(r.signals["y_g"][tail], F * math.cos(DEG20) / m.k_b) < 1e-6
    assert rel(r.signals["x_g"][tail], F * math.sin(DEG20) / m.k_b) < 1e-6
    # the computed static equilibrium is the same point
    z = static_equilibrium(m)
    assert np.allclose(z[:5], r.states[-1, :5], rtol=1e-6, atol=1e-15)


def _hand_5x5(m_p, m_g, J_p, J_g, R_p, R_g, a, k, kb):
    """Reduced coordinates (y_p, x_p, y_g, x_g, q), written out element by element."""
    me = 1.0 / (R_p**2 / J_p + R_g**2 / J_g)
    c, s = math.cos(a), math.sin(a)
    K = np.array(
        [
            [kb + k * c * c, k * c * s, -k * c * c, -k * c * s, k * c],
            [k * c * s, kb + k * s * s, -k * c * s, -k * s * s, k * s],
            [-k * c * c, -k * c * s, kb + k * c * c, k * c * s, -k * c],
            [-k * c * s, -k * s * s, k * c * s, kb + k * s * s, -k * s],
            [k * c, k * s, -k * c, -k * s, k],
        ]
    )
    M = np.diag([m_p, m_p, m_g, m_g, me])
    return np.sqrt(eigh(K, M, eigvals_only=True)) / (2 * math.pi)


def _hand_6x6(m_p, m_g, J_p, J_g, R_p, R_g, a, k, kb):
    """Original paper coordinates (y_p, x_p, y_g, x_g, theta_p, theta_g): one rigid mode."""
    g = np.array([math.cos(a), math.sin(a), -math.cos(a), -math.sin(a), R_p, -R_g])
    K = np.diag([kb, kb, kb, kb, 0.0, 0.0]) + k * np.outer(g, g)
    M = np.diag([m_p, m_p, m_g, m_g, J_p, J_g])
    lam = eigh(K, M, eigvals_only=True)
    assert abs(lam[0]) < 1e-6 * lam[-1]  # rigid-body rotation
    return np.sqrt(lam[1:]) / (2 * math.pi)


@pytest.mark.parametrize("unequal", [False, True])
def test_eigenfrequencies_match_hand_assembled(unequal):
    m = paper_pair()
    if unequal:  # a 2:1-ish pair with different bodies (catches R_g / T_g typos)
        m = m.with_(m_g=6.0, J_g=0.03, R_g=0.1, T_p=40.0)
    f = linear_eigenfrequencies(m)
    args = (m.m_p, m.m_g, m.J_p, m.J_g, m.R_p, m.R_g, m.alpha, m.k_mean, m.k_b)
    assert np.allclose(f, _hand_5x5(*args), rtol=1e-10)
    assert np.allclose(f, _hand_6x6(*args), rtol=1e-8)


def test_free_vibration_spectral_peaks_match_eigenfrequencies():
    m = paper_pair(tvms=False, zeta_m=0.0, zeta_b=0.0, torque_Nm=0.0)
    assert m.c_h == 0 and m.c_b == (0.0, 0.0)
    fn = linear_eigenfrequencies(m)
    y0 = np.zeros(10)
    y0[:5] = np.array([1.0, -0.6, 0.3, 0.8, 1.3]) * 1e-6
    r = simulate(m, 1.0, 0.0, y0=y0)
    df = 1.0 / (r.t[-1] - r.t[0] + 1 / r.fs_Hz)
    assert df <= 1.01
    total = np.zeros(r.t.size // 2 + 1)
    for name in ("y_p", "x_p", "y_g", "x_g", "q"):
        x = r.signals[name] - r.signals[name].mean()
        total += spectrum(x * np.hanning(x.size), r.fs_Hz)[1]
    f = np.fft.rfftfreq(r.t.size, 1 / r.fs_Hz)
    distinct = np.unique(np.round(fn, 3))
    distinct = distinct[np.r_[True, np.diff(distinct) > 1e-3 * distinct[1:]]]
    for fk in distinct:
        w = (f > 0.97 * fk) & (f < 1.03 * fk)
        i = np.argmax(np.where(w, total, 0))
        # parabolic refinement on the log spectrum
        a, b, c = np.log(total[i - 1 : i + 2])
        fpk = f[i] + 0.5 * (a - c) / (a - 2 * b + c) * (f[1] - f[0])
        assert abs(fpk - fk) / fk < 0.005, (fk, fpk)
        assert total[i] > 100 * np.median(total)
    peaks, _ = find_peaks(total, height=0.01 * total.max())
    for p in peaks:
        assert np.min(np.abs(f[p] - distinct) / distinct) < 0.005, f[p]
    # undamped, no excitation: the energy is conserved (adaptive solver; RK4 at 256 steps
    # per mesh period has its own numerical damping, (w h)^6 / 144 per step)
    from gearwear.dynamics import mechanical_energy

    ra = simulate(m, 0.05, 0.0, y0=y0, method="dopri5", rtol=1e-10)
    E = mechanical_energy(m, ra.t, ra.states)
    assert np.ptp(E) / E.mean() < 1e-6


def test_spectrum_and_harmonics_scaling():
    fs, fm = 25600.0, 600.0
    t = np.arange(2560) / fs  # 60 mesh periods
    x = 0.3 + 2.0 * np.sin(2 * np.pi * fm * t + 0.4) + 0.5 * np.cos(2 * np.pi * 3 * fm * t)
    f, A = spectrum(x, fs)
    assert A[0] == pytest.approx(0.3, abs=1e-12)
    assert A[np.argmin(np.abs(f - fm))] == pytest.approx(2.0, rel=1e-12)
    assert A[np.argmin(np.abs(f - 3 * fm))] == pytest.approx(0.5, rel=1e-12)
    h = harmonics(x, fs, fm, 4)
    assert np.allclose(h, [2.0, 0.0, 0.5, 0.0], atol=1e-12)


def _max_rel(a, b):
    return np.max(np.abs(a - b)) / max(np.ptp(b), np.max(np.abs(b)))


def test_zero_magnitude_effects_reproduce_the_plain_scene():
    base = paper_pair()  # TVMS only
    rb = simulate(base, 0.05, 0.02, method="rk4")
    names = ("y_p", "x_p", "y_g", "x_g", "F_m", "delta")
    # bearing clearance of zero
    r = simulate(paper_pair(clearance_total_m=0.0), 0.05, 0.02, method="rk4")
    for n in names:
        assert _max_rel(r.signals[n], rb.signals[n]) < 1e-9, n
    # transmission-error excitation switched on with e = 0
    r = simulate(base.with_(te_excitation=True, e_table=np.zeros(256)), 0.05, 0.02, method="rk4")
    for n in names:
        assert _max_rel(r.signals[n], rb.signals[n]) < 1e-9, n
    # a backlash that is never reached (the back flank stays 1 mm away): only delta shifts by b
    b = 0.5e-3
    r = simulate(paper_pair(backlash_total_m=2 * b), 0.05, 0.02, method="rk4")
    assert r.separation_fraction == 0 and r.backside_fraction == 0
    for n in names[:-1]:
        assert _max_rel(r.signals[n], rb.signals[n]) < 1e-9, n
    assert _max_rel(r.signals["delta"] - b, rb.signals["delta"]) < 1e-9
    # adaptive solver: zero clearance never triggers an event, identical steps
    ra = simulate(base, 0.05, 0.02, method="dopri5")
    r = simulate(paper_pair(clearance_total_m=0.0), 0.05, 0.02, method="dopri5")
    assert r.events == 0 and r.steps == ra.steps
    for n in names:
        assert _max_rel(r.signals[n], ra.signals[n]) < 1e-9, n


def test_auto_method_and_bad_inputs():
    assert simulate(paper_pair(), 0.01, 0.0).method == "rk4"
    assert simulate(paper_pair(backlash_total_m=50e-6), 0.01, 0.0).method == "dopri5"
    with pytest.raises(InputError, match="discard_s"):
        simulate(paper_pair(), 0.01, 0.02)
    with pytest.raises(InputError, match="method"):
        simulate(paper_pair(), 0.01, 0.0, method="euler")
    with pytest.raises(InputError, match="k_table"):
        paper_pair().with_(k_table=np.ones(5))
    with pytest.raises(InputError, match="backlash_half_m"):
        paper_pair().with_(backlash_half_m=-1e-6)
    with pytest.raises(InputError, match="C0_m"):
        paper_pair(centre_distance="dynamic").with_(C0_m=0.2)
    with pytest.raises(InputError, match="phi_table"):
        paper_pair().with_(phi_table=np.linspace(0, 1, 256))


def test_gear_torsion_uses_output_torque_for_unequal_pair():
    """Eq. 17 fixed: with T_g = T_p R_g / R_p the static mesh force is T_p / R_p and the
    reduced model settles there (no drift of q) for an unequal pair."""
    m = paper_pair(tvms=False, k_constant=4e8).with_(m_g=6.0, J_g=0.03, R_g=0.1)
    assert isinstance(m, GearDynamics)
    r = simulate(m, 0.3, 0.29, y0=np.zeros(10))
    assert np.allclose(r.signals["F_m"], 40.0 / m.R_p, rtol=1e-6)
    assert np.ptp(r.signals["q"]) < 1e-6 * np.mean(np.abs(r.signals["q"]))
