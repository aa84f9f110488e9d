"""Dynamics, hard cases: each stays finite and bounded, and the nonlinear branch it is
about really happens; every trajectory converges under refinement over a fixed short
window (which holds for periodic and non-periodic runs alike)."""

import numpy as np
import pytest

from gearwear.dynamics import kernels, paper_pair, simulate
from gearwear.dynamics.analysis import energy_balance, mechanical_energy


def _refined_table(m, factor):
    """The same model with its stiffness (and excitation) table subdivided ``factor``
    times: the linear interpolant is the same function, but the adaptive solver, whose
    steps end on every table node, takes an independent, finer step sequence."""
    P = 2 * np.pi / m.z_p
    n = len(m.phi_table) * factor
    phi = np.arange(n) * P / n
    assert np.allclose(m.phi_table, np.arange(len(m.phi_table)) * P / len(m.phi_table))  # uniform tables only

    def lin(v):
        return None if v is None else np.interp(phi, np.append(m.phi_table, P), np.append(v, v[0]))

    return m.with_(phi_table=phi, k_table=lin(m.k_table), e_table=lin(m.e_table))


def _trajectory_error(a, ref):
    """Largest difference over the window of delta, F_m, y_p and x_g, each relative to
    the largest |value| of the reference."""
    assert np.array_equal(a.t, ref.t)
    return max(
        float(np.max(np.abs(a.signals[n] - ref.signals[n])) / np.max(np.abs(ref.signals[n])))
        for n in ("delta", "F_m", "y_p", "x_g")
    )


def _converges(m, periods, tol):
    """Over the first ``periods`` mesh periods from the static state, the default run
    (RK4 256 steps per period, or dopri5 rtol 1e-8 with event location) is within
    ``tol`` of a tight reference (dopri5, rtol 1e-12, table subdivided 8 times), and one
    refinement (RK4 512 steps, or dopri5 on the table subdivided twice) is closer still
    (or both are at round-off, < 1e-9). A fixed short window converges whether or not
    the run settles to a periodic state. Returns the two errors."""
    P = 1.0 / m.mesh_frequency_Hz
    kw = dict(samples_per_mesh_period=64)
    ref = simulate(_refined_table(m, 8), periods * P, 0.0, method="dopri5", rtol=1e-12, **kw)
    a = simulate(m, periods * P, 0.0, **kw)
    if a.method == "rk4":
        b = simulate(m, periods * P, 0.0, method="rk4", steps_per_mesh_period=512, **kw)
    else:
        b = simulate(_refined_table(m, 2), periods * P, 0.0, method="dopri5", **kw)
    ea, eb = _trajectory_error(a, ref), _trajectory_error(b, ref)
    assert ea < tol, (ea, tol)
    assert eb < 0.5 * ea or eb < 1e-9, (ea, eb)
    return ea, eb


def _finite_bounded(r, bound_m=1e-3):
    for name in ("y_p", "x_p", "y_g", "x_g", "delta", "F_m"):
        assert np.all(np.isfinite(r.signals[name])), name
    for name in ("y_p", "x_p", "y_g", "x_g", "delta"):
        assert np.max(np.abs(r.signals[name])) < bound_m, name


def test_light_load_near_resonance_separates_and_hits_the_back_flank():
    # 5 N m, 100 um total backlash, f_m = 3 kHz (between the 1.3 kHz bearing and the 4.1 kHz
    # mesh mode), 10 um wear excitation (severe wear): tooth separation and back-flank impacts
    m = paper_pair(torque_Nm=5.0, speed_rpm=6000, backlash_total_m=100e-6, te_amplitude_m=10e-6)
    _converges(m, 10, 1e-6)  # measured 1.4e-9 (2x table: 1.0e-10)
    r = simulate(m, 0.05, 0.02)
    _finite_bounded(r)
    assert r.method == "dopri5" and r.events > 50
    assert r.separation_fraction > 0.1
    assert r.backside_fraction > 0.0
    assert r.signals["s"].min() < -m.backlash_half_m  # the back flank was reached
    # the same pair without wear excitation and at the design load never separates
    r40 = simulate(paper_pair(torque_Nm=40.0, backlash_total_m=100e-6), 0.05, 0.02)
    assert r40.separation_fraction == 0.0 and r40.events == 0


def test_bearing_clearance_100um_rattles():
    m = paper_pair(torque_Nm=5.0, speed_rpm=6000, clearance_total_m=100e-6, te_amplitude_m=10e-6)
    _converges(m, 20, 1e-6)  # measured 9.8e-11 (2x table: 3.0e-12)
    r = simulate(m, 0.05, 0.02)
    _finite_bounded(r)
    assert r.events > 50
    for side in ("pinion", "gear"):
        assert 0.0 < r.bearing_contact_fraction[side] < 1.0  # crosses its dead zone
    # at the design load the centres stay pressed into the clearance (Eq. 11 corner)
    r40 = simulate(paper_pair(clearance_total_m=100e-6), 0.05, 0.02)
    assert r40.bearing_contact_fraction == {"pinion": 1.0, "gear": 1.0}
    assert np.min(np.abs(r40.signals["y_p"])) > 50e-6


def test_zero_damping_one_second_stays_bounded():
    """No damping anywhere: nothing is dissipated, the energy balance closes with the
    torque work and the parametric work of the stiffness alone, and the energy does not
    grow over 1 s (600 mesh periods, no parametric instability at this operating point):
    the largest energy in each 0.1 s block and the delta swing per block stay within
    2 % of the first block's (measured 0.6 % and 0.4 %)."""
    m = paper_pair(backlash_total_m=50e-6, clearance_total_m=10e-6, zeta_m=0.0, zeta_b=0.0)
    assert m.c_h == 0.0 and m.c_b == (0.0, 0.0)
    r = simulate(m, 1.0, 0.0, track_energy=True)
    _finite_bounded(r, bound_m=200e-6)
    eb = energy_balance(r, m)
    assert eb["dissipated"] == 0.0
    assert eb["relative_residual"] < 1e-3, eb  # measured 1.9e-4
    assert abs(eb["parametric_work"]) > 1e-3 * abs(eb["input_work"])  # the stiffness does work
    E = mechanical_energy(m, r.t, r.states)
    blocks = np.array_split(np.arange(len(E)), 10)
    e_max = np.array([E[b].max() for b in blocks])
    swing = np.array([np.ptp(r.signals["delta"][b]) for b in blocks])
    assert np.all(np.abs(e_max / e_max[0] - 1) < 0.02), e_max
    assert np.all(np.abs(swing / swing[0] - 1) < 0.02), swing
    # the swing is the stiffness fluctuation's: a few times F/k_min - F/k_max, not more
    static_range = m.F_s / m.k_table.min() - m.F_s / m.k_table.max()
    assert static_range < swing[0] < 5 * static_range


@pytest.mark.parametrize("backlash", [None, 50e-6])
def test_contact_ratio_below_one_with_zero_stiffness_gaps(backlash):
    # single pair for 90 % of the mesh period, no pair at all (k = 0) for 10 %
    phi = np.arange(256) * (2 * np.pi / 30) / 256
    u = phi / phi[1] / 256
    k = 2.9e8 * np.clip(np.minimum(u / 0.02, (0.9 - u) / 0.02), 0.0, 1.0)  # linear ramps
    assert np.sum(k == 0.0) >= 20
    m = paper_pair(k_table=k, phi_table=phi, backlash_total_m=backlash)
    # RK4 256 -> 512: 3.9e-5 -> 2.5e-6 (4th order); with backlash the flights across the
    # k = 0 gaps make the trajectory sensitive, so the window is 4 periods: 2.2e-5 -> 7.5e-7
    _converges(m, 10 if backlash is None else 4, 1e-4)
    r = simulate(m, 0.1, 0.05)
    _finite_bounded(r)
    assert np.min(r.signals["k_h"]) == 0.0
    if backlash is not None:
        assert r.separation_fraction > 0.05  # the teeth fly across the gap


def test_20000_rpm_all_effects_finite():
    m = paper_pair(
        speed_rpm=20000, backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=5e-6, centre_distance="dynamic"
    )
    assert m.mesh_frequency_Hz == pytest.approx(10000.0)
    _converges(m, 10, 1e-8)  # measured 8.1e-11, 2x table the same (round-off)
    r = simulate(m, 0.02, 0.01)
    _finite_bounded(r)


def test_rk4_all_effects_and_specialisation():
    """Step count and one compiled specialisation per effect set (speed is measured in
    benchmarks/bench_dynamics.py, never asserted)."""
    m = paper_pair(backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=5e-6, centre_distance="dynamic")
    r = simulate(m, 1.0, 0.5, method="rk4")
    assert r.steps == 153600 - 1 or r.steps == 153600
    plain = simulate(paper_pair(tvms=False), 0.01, 0.0, method="rk4")
    # one compiled specialisation per effect set: absent effects are NoneType arguments
    assert r.switches == (True,) * 5 + (None,)
    assert plain.switches == (None,) * 6
    sigs = [tuple(str(a) for a in s) for s in kernels.rk4.signatures]
    assert any(s[-6:] == ("none",) * 6 for s in sigs)
    assert any(s[-6:] == ("bool",) * 5 + ("none",) for s in sigs)
