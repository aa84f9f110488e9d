"""Dynamics, accuracy: an independent reference solver (scipy DOP853 on a pure-Python
right-hand side), energy balance with the parametric work, event location vs RK4."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gearwear.dynamics import (
    compute_signals,
    energy_balance,
    harmonics,
    paper_pair,
    rhs_python,
    simulate,
    static_equilibrium,
)


def _rel(h, href):
    return np.abs(h - href) / href


def test_harmonics_match_scipy_dop853_smooth_case():
    m = paper_pair(n_table=64)  # TVMS (smoothed rectangular wave), no clearances
    P = 1.0 / m.mesh_frequency_Hz
    rk = simulate(m, 10 * P, 2 * P, method="rk4", steps_per_mesh_period=256)
    dp = simulate(m, 10 * P, 2 * P, method="dopri5", rtol=1e-9)
    x = m.F_s / m.k_mean
    atol = np.r_[np.full(5, 1e-12 * x), np.full(5, 1e-12 * x * 2e4)]
    sol = solve_ivp(
        lambda t, y: rhs_python(t, y, m),
        (0.0, rk.t[-1]),
        static_equilibrium(m),
        method="DOP853",
        rtol=1e-10,
        atol=atol,
        t_eval=rk.t,
    )
    assert sol.success
    ref = compute_signals(m, rk.t, sol.y.T)
    for name in ("F_m", "delta"):
        href = harmonics(ref[name], rk.fs_Hz, rk.fm_Hz, 10)
        assert np.all(href > 1e-3 * href.max())  # all ten harmonics are present
        for r in (rk, dp):
            err = _rel(harmonics(r.signals[name], r.fs_Hz, r.fm_Hz, 10), href)
            assert err.max() < 0.005, (name, r.method, err)
        # and much better than required
        assert _rel(harmonics(dp.signals[name], dp.fs_Hz, dp.fm_Hz, 10), href).max() < 1e-5


@pytest.mark.parametrize(
    "case",
    [
        dict(torque_Nm=5.0, speed_rpm=4000, backlash_total_m=50e-6),
        dict(torque_Nm=5.0, speed_rpm=6000, backlash_total_m=100e-6, te_amplitude_m=10e-6, clearance_total_m=20e-6),
        dict(
            torque_Nm=5.0,
            speed_rpm=6000,
            backlash_total_m=100e-6,
            te_amplitude_m=10e-6,
            clearance_total_m=20e-6,
            centre_distance="dynamic",
        ),
    ],
)
@pytest.mark.parametrize("method", ["rk4", "dopri5"])
def test_energy_balance_closes_with_parametric_work(case, method):
    m = paper_pair(**case)
    r = simulate(m, 0.03, 0.0, method=method, rtol=1e-9, track_energy=True)
    assert r.separation_fraction > 0.05  # the gap really opens
    eb = energy_balance(r, m)
    assert eb["relative_residual"] < 1e-3, eb
    # the parametric work of the time-varying stiffness is a real part of the balance
    assert abs(eb["parametric_work"]) > 0.01 * eb["dissipated"]
    assert eb["dissipated"] > 0
    if "te_amplitude_m" in case:
        assert abs(eb["excitation_work"]) > 0.1 * eb["dissipated"]
    # without the parametric term the balance would not close
    miss = abs(eb["residual"] + eb["parametric_work"]) / max(abs(eb["dissipated"]), 1e-300)
    assert miss > 10 * eb["relative_residual"]


def _event_case():
    # 6000 rpm, 50 um total backlash, light load with a 2 um wear excitation: the teeth
    # separate in most mesh periods (frequent impacts)
    return paper_pair(torque_Nm=5.0, speed_rpm=6000, backlash_total_m=50e-6, te_amplitude_m=2e-6)


def test_event_location_reaches_1e6_on_mesh_force_harmonics():
    m = _event_case()
    P = 1.0 / m.mesh_frequency_Hz
    ref = simulate(m, 20 * P, 4 * P, method="dopri5", rtol=1e-12)
    assert ref.separation_fraction > 0.3 and ref.events >= 10
    href = harmonics(ref.signals["F_m"], ref.fs_Hz, ref.fm_Hz, 4)
    for rtol in (1e-8, 1e-9):
        r = simulate(m, 20 * P, 4 * P, method="dopri5", rtol=rtol)
        assert r.events == ref.events
        assert _rel(harmonics(r.signals["F_m"], r.fs_Hz, r.fm_Hz, 4), href).max() < 1e-6
    # fixed-step RK4 at the same (and 4x the) resolution is far from it
    for N in (256, 1024):
        r = simulate(m, 20 * P, 4 * P, method="rk4", steps_per_mesh_period=N, samples_per_mesh_period=256)
        assert _rel(harmonics(r.signals["F_m"], r.fs_Hz, r.fm_Hz, 4), href).max() > 1e-4


def _observed_order(m, Ns, ref_h):
    P = 1.0 / m.mesh_frequency_Hz
    errs = []
    for N in Ns:
        r = simulate(m, 20 * P, 4 * P, method="rk4", steps_per_mesh_period=N, samples_per_mesh_period=64)
        errs.append(_rel(harmonics(r.signals["F_m"], r.fs_Hz, r.fm_Hz, 4), ref_h).max())
    slope = -np.polyfit(np.log(Ns), np.log(errs), 1)[0]
    return slope, errs


def test_rk4_loses_its_order_at_contact_events():
    Ns = np.array([256, 512, 1024, 2048])
    smooth = paper_pair(torque_Nm=5.0, speed_rpm=4000, n_table=64)
    nonsmooth = paper_pair(torque_Nm=5.0, speed_rpm=4000, n_table=64, backlash_total_m=50e-6)
    orders = {}
    for name, m in (("smooth", smooth), ("events", nonsmooth)):
        P = 1.0 / m.mesh_frequency_Hz
        ref = simulate(m, 20 * P, 4 * P, method="dopri5", rtol=1e-12, samples_per_mesh_period=64)
        href = harmonics(ref.signals["F_m"], ref.fs_Hz, ref.fm_Hz, 4)
        if name == "events":
            assert ref.separation_fraction > 0.1
        Nsm = Ns // 4 if name == "smooth" else Ns  # stay above round-off when smooth
        orders[name], errs = _observed_order(m, Nsm, href)
    assert orders["smooth"] > 3.5
    assert orders["events"] < 2.5, orders


def test_step_halving_converges_smooth_and_event_cases():
    m = paper_pair(torque_Nm=40.0, speed_rpm=1200)
    # same output grid for both (F_m carries the images of the linear table at n +- k,
    # which alias differently on different grids)
    a = simulate(m, 0.1, 0.05, steps_per_mesh_period=256)
    b = simulate(m, 0.1, 0.05, steps_per_mesh_period=512, samples_per_mesh_period=256)
    ha, hb = (harmonics(r.signals["F_m"], r.fs_Hz, r.fm_Hz) for r in (a, b))
    assert _rel(ha, hb).max() < 1e-3
    m = paper_pair(torque_Nm=5.0, speed_rpm=4000, backlash_total_m=50e-6)
    a = simulate(m, 0.05, 0.03, rtol=1e-8)
    b = simulate(m, 0.05, 0.03, rtol=1e-10)
    assert a.method == "dopri5" and a.separation_fraction > 0.1
    ha, hb = (harmonics(r.signals["F_m"], r.fs_Hz, r.fm_Hz) for r in (a, b))
    assert a.periodic_with == 0 or _rel(ha, hb).max() < 1e-4


def test_first_contact_time_is_located_exactly():
    """Free flight across the gap has a closed-form contact time t* = b / v0 (no force
    acts while separated, F_s = 0). The run through the event must equal a run started
    at the contact state (the model is time-invariant with constant stiffness)."""
    m = paper_pair(tvms=False, torque_Nm=0.0, backlash_total_m=100e-6)
    b = m.backlash_half_m
    P = 1.0 / m.mesh_frequency_Hz
    dt = P / 256
    shift = 40
    v0 = b / (shift * dt)
    y0 = np.zeros(10)
    y0[9] = v0
    r1 = simulate(m, 6 * P, 0.0, method="dopri5", rtol=1e-12, y0=y0)
    y1 = y0.copy()
    y1[4] = b
    r2 = simulate(m, 6 * P, 0.0, method="dopri5", rtol=1e-12, y0=y1)
    assert r1.events >= 10 and r1.separation_fraction > 0.05 and r1.backside_fraction > 0
    # before contact: exact straight-line flight
    assert np.allclose(r1.signals["q"][: shift + 1], v0 * r1.t[: shift + 1], rtol=1e-12, atol=1e-18)
    n = r1.t.size - shift
    # end of the first contact (the teeth leave each other again)
    leave = int(np.nonzero(np.diff(r2.signals["mode"][:n]))[0][1])
    for name in ("q", "F_m", "y_p", "x_g"):
        # (sample 0 is the contact instant itself, where the damper force jumps)
        a, c = r1.signals[name][shift + 1 :], r2.signals[name][1:n]
        scale = np.max(np.abs(c))
        assert np.max(np.abs(a - c)[:leave]) < 1e-10 * scale, name
        assert np.max(np.abs(a - c)) < 1e-7 * scale, name  # after ~20 impacts
