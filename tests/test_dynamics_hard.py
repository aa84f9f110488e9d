"""Dynamics, hard cases: each stays finite and bounded, and the nonlinear branch it is
about really happens; results converge under refinement or are reported non-periodic."""

import numpy as np
import pytest

from gearwear.dynamics import harmonics, paper_pair, simulate
from gearwear.dynamics import kernels


def _converged_or_nonperiodic(m, duration, discard, tol=1e-3):
    """Refine (RK4 256 -> 512 steps, or dopri5 rtol 1e-8 -> 1e-10) and compare F_m harmonics."""
    a = simulate(m, duration, discard, rtol=1e-8, steps_per_mesh_period=256)
    if a.method == "rk4":
        b = simulate(m, duration, discard, steps_per_mesh_period=512, samples_per_mesh_period=256)
    else:
        b = simulate(m, duration, discard, rtol=1e-10)
    ha, hb = (harmonics(r.signals["F_m"], r.fs_Hz, r.fm_Hz, 10) for r in (a, b))
    err = np.max(np.abs(ha - hb)) / np.max(hb)
    assert a.periodic_with == 0 or err < tol, (a.periodic_with, err)
    return a, err


def _finite_bounded(r, bound_m=1e-3):
    for name in ("y_p", "x_p", "y_g", "x_g", "delta", "F_m"):
        assert np.all(np.isfinite(r.signals[name])), name
    for name in ("y_p", "x_p", "y_g", "x_g", "delta"):
        assert np.max(np.abs(r.signals[name])) < bound_m, name


def test_light_load_near_resonance_separates_and_hits_the_back_flank():
    # 5 N m, 100 um total backlash, f_m = 3 kHz (between the 1.3 kHz bearing and the 4.1 kHz
    # mesh mode), 10 um wear excitation (severe wear): tooth separation and back-flank impacts
    m = paper_pair(torque_Nm=5.0, speed_rpm=6000, backlash_total_m=100e-6, te_amplitude_m=10e-6)
    r, _ = _converged_or_nonperiodic(m, 0.05, 0.02)
    _finite_bounded(r)
    assert r.method == "dopri5" and r.events > 50
    assert r.separation_fraction > 0.1
    assert r.backside_fraction > 0.0
    assert r.signals["s"].min() < -m.backlash_half_m       # the back flank was reached
    # the same pair without wear excitation and at the design load never separates
    r40 = simulate(paper_pair(torque_Nm=40.0, backlash_total_m=100e-6), 0.05, 0.02)
    assert r40.separation_fraction == 0.0 and r40.events == 0


def test_bearing_clearance_100um_rattles():
    m = paper_pair(torque_Nm=5.0, speed_rpm=6000, clearance_total_m=100e-6, te_amplitude_m=10e-6)
    r, _ = _converged_or_nonperiodic(m, 0.05, 0.02)
    _finite_bounded(r)
    assert r.events > 50
    for side in ("pinion", "gear"):
        assert 0.0 < r.bearing_contact_fraction[side] < 1.0      # crosses its dead zone
    # at the design load the centres stay pressed into the clearance (Eq. 11 corner)
    r40 = simulate(paper_pair(clearance_total_m=100e-6), 0.05, 0.02)
    assert r40.bearing_contact_fraction == {"pinion": 1.0, "gear": 1.0}
    assert np.min(np.abs(r40.signals["y_p"])) > 50e-6


def test_zero_damping_one_second_stays_bounded():
    m = paper_pair(backlash_total_m=50e-6, clearance_total_m=10e-6, zeta_m=0.0, zeta_b=0.0)
    assert m.c_h == 0.0 and m.c_b == (0.0, 0.0)
    r = simulate(m, 1.0, 0.5)
    _finite_bounded(r, bound_m=200e-6)
    dyn = r.signals["delta"] - np.mean(r.signals["delta"])
    assert np.max(np.abs(dyn)) < 20 * (m.F_s / m.k_mean)        # bounded oscillation
    # undamped: nothing to settle, and it says so or is converged
    assert r.periodic_with in (0, 1, 2, 3, 4, 5, 6, 7, 8)


@pytest.mark.parametrize("backlash", [None, 50e-6])
def test_contact_ratio_below_one_with_zero_stiffness_gaps(backlash):
    # single pair for 90 % of the mesh period, no pair at all (k = 0) for 10 %
    phi = np.arange(256) * (2 * np.pi / 30) / 256
    u = phi / phi[1] / 256
    k = 2.9e8 * np.clip(np.minimum(u / 0.02, (0.9 - u) / 0.02), 0.0, 1.0)   # linear ramps
    assert np.sum(k == 0.0) >= 20
    m = paper_pair(k_table=k, phi_table=phi, backlash_total_m=backlash)
    r, _ = _converged_or_nonperiodic(m, 0.1, 0.05)
    _finite_bounded(r)
    assert np.min(r.signals["k_h"]) == 0.0
    if backlash is not None:
        assert r.separation_fraction > 0.05         # the teeth fly across the gap


def test_20000_rpm_all_effects_finite():
    m = paper_pair(speed_rpm=20000, backlash_total_m=50e-6, clearance_total_m=20e-6,
                   te_amplitude_m=5e-6, centre_distance="dynamic")
    assert m.mesh_frequency_Hz == pytest.approx(10000.0)
    r, _ = _converged_or_nonperiodic(m, 0.02, 0.01)
    _finite_bounded(r)


def test_rk4_all_effects_and_specialisation():
    """Step count and one compiled specialisation per effect set (speed is measured in
    benchmarks/bench_dynamics.py, never asserted)."""
    m = paper_pair(backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=5e-6,
                   centre_distance="dynamic")
    r = simulate(m, 1.0, 0.5, method="rk4")
    assert r.steps == 153600 - 1 or r.steps == 153600
    plain = simulate(paper_pair(tvms=False), 0.01, 0.0, method="rk4")
    # one compiled specialisation per effect set: absent effects are NoneType arguments
    assert r.switches == (True,) * 5 + (None,)
    assert plain.switches == (None,) * 6
    sigs = [tuple(str(a) for a in s) for s in kernels.rk4.signatures]
    assert any(s[-6:] == ("none",) * 6 for s in sigs)
    assert any(s[-6:] == ("bool",) * 5 + ("none",) for s in sigs)
