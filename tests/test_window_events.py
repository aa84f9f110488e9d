"""Exact window harmonics across switching events (dopri5 with event location).

``window_fourier`` integrates, piece by piece between the dense output times, the cubic
Hermite interpolant of the states and their derivatives. That is exact to the
integrator's order only where the state is smooth. A switching event (contact loss, a
back-flank impact, a bearing lifting off) makes the acceleration jump (the mesh damper
c_h delta' switches on or off) or kink, and F_m = c_h delta' + k f(s) itself jumps, so no
piece may hold one: the solver's located events must be nodes of the dense output.

Truths used, none taken from the code's own output:
* the output sampling S only moves the piece ends (the dopri5 steps, hence the
  trajectory, do not depend on the output times), so the exact integrals of one
  trajectory cannot depend on S: any change is quadrature error;
* an independent reference: scipy's DOP853 on the pure-Python right-hand side, restarted
  at every table node and at every flank event that solve_ivp locates itself, its dense
  output integrated by 6-point Gauss-Legendre on every step, F_m written out here;
* the contact state is constant inside every piece (it can change only at an event node).
"""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gearwear.dynamics import paper_pair, rhs_python, simulate, static_equilibrium
from gearwear.dynamics.analysis import (
    _hermite_at_gauss,
    dense_derivatives,
    event_pieces,
    window_fourier,
    window_harmonics,
)
from gearwear.dynamics.model import mesh_state

NAMES = ["F_m", "delta"]
RTOL = 1e-10

CASES = {
    # 78 % separated, drive-flank contact lost and regained ~1.5 times per mesh period
    "contact loss": dict(torque_Nm=5.0, speed_rpm=6000, backlash_total_m=50e-6, te_amplitude_m=2e-6),
    # no flank law (the affine fold's domain): bearings in contact 34 % of the time
    "bearing lift-off": dict(torque_Nm=5.0, speed_rpm=6000, clearance_total_m=100e-6, te_amplitude_m=10e-6),
    # 90 % separated, back-flank impacts, bearings lifting off too
    "back-flank impacts": dict(
        torque_Nm=5.0, speed_rpm=6000, backlash_total_m=100e-6, te_amplitude_m=10e-6, clearance_total_m=20e-6
    ),
}


def _window(m, S, rtol=RTOL, periods=20, discard=4):
    P = 1.0 / m.mesh_frequency_Hz
    return simulate(
        m, (discard + periods + 0.5) * P, discard * P, method="dopri5", rtol=rtol, samples_per_mesh_period=S
    )


def _mode_changes(r, m):
    """Contact-state changes between consecutive samples (flank mode, bearing contact)."""
    n = int(np.sum(np.diff(r.signals["mode"]) != 0))
    if m.bearing_half_clearance_m is not None:
        on = np.abs(r.states[:, :4]) > m.bearing_half_clearance_m
        n += int(np.sum(np.any(np.diff(on, axis=0), axis=1)))
    return n


@pytest.mark.parametrize("case", list(CASES))
def test_event_harmonics_do_not_depend_on_the_output_sampling(case):
    """64 and 1024 samples per mesh period: the same trajectory (same steps and events),
    so the same exact integrals, to the solver's tolerance (measured 1.2e-9, 1.8e-9,
    1.6e-9 of the largest harmonic of F_m at rtol 1e-10). Before the dense output held
    the events, F_m changed by 2.0e-4 (contact loss) and 3.3e-4 (back-flank impacts);
    the bearing case changed by only 1.7e-9 already (the bearing force is continuous at
    lift-off: the acceleration kinks, it does not jump)."""
    m = paper_pair(**CASES[case])
    coarse, fine = _window(m, 64), _window(m, 1024)
    assert (coarse.steps, coarse.events) == (fine.steps, fine.events)
    assert _mode_changes(fine, m) >= 15  # the window is full of events
    a, b = window_fourier(coarse, NAMES, 10), window_fourier(fine, NAMES, 10)
    for name in NAMES:
        scale = np.abs(b[name]).max()
        assert np.abs(a[name] - b[name]).max() <= 200 * RTOL * scale, (
            case,
            name,
            np.abs(a[name] - b[name]).max() / scale,
        )


@pytest.mark.parametrize("case", list(CASES))
def test_no_quadrature_piece_holds_a_contact_change(case):
    """At the Gauss points of every piece (the interpolated states window_fourier
    evaluates: the whole pieces between output times and the sub-pieces of those that hold
    events) the contact state (flank mode, the four bearing contacts) is that of the whole
    piece, and it changes from piece to piece only at a located event."""
    m = paper_pair(**CASES[case])
    r = _window(m, 64)
    F = dense_derivatives(r)
    broken, (ts, Zs, Fs, sub) = event_pieces(r, F)
    starts, ends, states = [], [], []
    for t, Z, Fd, pieces in ((r.t_dense, r.states_dense, F, np.nonzero(~broken)[0]), (ts, Zs, Fs, sub)):
        dt = (t[pieces + 1] - t[pieces])[:, None]
        pieces = pieces[dt[:, 0] > 0]
        dt = dt[dt[:, 0] > 0]
        Zq = _hermite_at_gauss(Z[pieces], Z[pieces + 1], Fd[pieces] * dt, Fd[pieces + 1] * dt)
        tq = (t[pieces][:, None] + dt * np.array([0.11, 0.5, 0.89])).ravel()  # only the time of k, e
        state = mesh_state(m, tq, Zq)["mode"].astype(np.int64)
        if m.bearing_half_clearance_m is not None:
            on = np.abs(Zq[:, :4]) > m.bearing_half_clearance_m
            state = 10 * state + on @ np.array([1, 2, 4, 8])
        state = state.reshape(-1, 3)
        assert np.all(state == state[:, :1]), "a piece holds a contact change"
        starts.append(t[pieces])
        ends.append(t[pieces + 1])
        states.append(state[:, 0])
    order = np.argsort(np.concatenate(starts), kind="stable")
    end, s = np.concatenate(ends)[order], np.concatenate(states)[order]
    assert np.array_equal(np.concatenate(starts)[order][1:], end[:-1])  # the pieces tile the window
    changed = end[:-1][s[1:] != s[:-1]]
    assert changed.size >= 15
    assert np.all(np.isin(changed, r.event_times))


def _reference(m, t0, t1, n, rtol=1e-12):
    """Coefficients c_k = (2 / (t1 - t0)) int_t0^t1 x e^{-i k w_m t} dt of F_m and delta,
    from scipy DOP853 on ``rhs_python`` with the flank events located by solve_ivp."""
    P = 1.0 / m.mesh_frequency_Hz
    w, Pr, b = m.omega_p, m.table_period_rad, m.backlash_half_m
    sa, ca = math.sin(m.alpha), math.cos(m.alpha)
    nodes = np.concatenate([(m.phi_table + Pr * j) / w for j in range(int(t1 * w / Pr) + 2)] + [[t0, t1]])
    nodes = np.unique(nodes[(nodes > 1e-9 * P) & (nodes <= t1)])

    def delta(y):
        return y[4] + (y[1] - y[3]) * sa + (y[0] - y[2]) * ca

    def drive(t, y):
        return delta(y) - b

    def back(t, y):
        return -delta(y) - b

    drive.terminal = back.terminal = True
    x = m.F_s / m.k_mean
    atol = np.r_[np.full(5, 1e-3 * rtol * x), np.full(5, 20.0 * rtol * x)]
    f = lambda t, y: rhs_python(t, y, m)  # noqa: E731
    t, y, segments = 0.0, static_equilibrium(m), []
    for tn in nodes:  # restart at every table node: a smooth rhs per segment
        while t < tn:
            sol = solve_ivp(
                f, (t, tn), y, method="DOP853", rtol=rtol, atol=atol, events=[drive, back], dense_output=True
            )
            segments.append((sol.sol, sol.t))
            t, y = sol.t[-1], sol.y[:, -1]
            if sol.status == 1 and t < tn:
                # across the event by a step of 1e-9 mesh periods without event functions (the
                # state sits on the switching surface, solve_ivp would find the event again)
                t2 = min(t + 1e-9 * P, tn)
                sol = solve_ivp(
                    f, (t, t2), y, method="DOP853", rtol=rtol, atol=atol, first_step=t2 - t, dense_output=True
                )
                segments.append((sol.sol, sol.t))
                t, y = sol.t[-1], sol.y[:, -1]
    xg, wg = np.polynomial.legendre.leggauss(6)
    phx, kx = np.append(m.phi_table, Pr), np.append(m.k_table, m.k_table[0])
    k = np.arange(1, n + 1)[:, None]
    c = {name: np.zeros(n, complex) for name in NAMES}
    for sol, ts in segments:
        if ts[0] < t0 - 1e-12 * P or ts.size < 2:
            continue
        a, e = ts[:-1, None], ts[1:, None]
        tq = (0.5 * (a + e) + 0.5 * (e - a) * xg).ravel()
        wq = (0.5 * (e - a) * wg).ravel()
        Y = sol(tq)
        d = delta(Y)
        dd = Y[9] + (Y[6] - Y[8]) * sa + (Y[5] - Y[7]) * ca
        dm = delta(sol(0.5 * (ts[0] + ts[-1])))  # the segment's contact state
        kk = np.interp(np.mod(w * tq, Pr), phx, kx)
        F = m.c_h * dd + kk * (d - b) if dm > b else (m.c_h * dd + kk * (d + b) if dm < -b else 0.0 * d)
        ph = np.exp(-2j * np.pi * m.mesh_frequency_Hz * k * tq[None, :])
        c["F_m"] += ph @ (wq * F)
        c["delta"] += ph @ (wq * d)
    return {name: 2.0 * v / (t1 - t0) for name, v in c.items()}


def test_event_harmonics_match_scipy_dop853_with_located_events():
    """10 mesh periods after 2, 4000 rpm, 50 um backlash: 40 contact events. Measured
    7.5e-10 (F_m) and 8.5e-10 (delta) of the largest harmonic at rtol 1e-11 and 1024 samples
    per period (7.5e-8 at rtol 1e-9; the reference moves by 4e-12 from rtol 1e-12 to
    1e-13); 1.4e-5 for F_m before the pieces were split at the events."""
    m = paper_pair(torque_Nm=5.0, speed_rpm=4000, backlash_total_m=50e-6, n_table=64)
    r = _window(m, 1024, rtol=1e-11, periods=10, discard=2)
    assert _mode_changes(r, m) >= 20
    ref = _reference(m, r.t_dense[0], r.t_dense[-1], 10)
    c = window_fourier(r, NAMES, 10)
    for name in NAMES:
        scale = np.abs(ref[name]).max()
        assert np.abs(c[name] - ref[name]).max() <= 5e-9 * scale, (name, np.abs(c[name] - ref[name]).max() / scale)


def test_event_pieces_split_the_pieces_that_hold_events():
    """Hand-made kernel rows on the output times 0..6 (mesh periods): an event at the window
    start (that time takes the derivative after it), one inside a piece, two at one time
    (kernel order kept), one 1e-12 after an output time (that time's state is the event's,
    its side ambiguous: the event replaces it) and one at the window end (derivative
    before)."""
    from gearwear.dynamics import kernels

    m = paper_pair()
    fm = m.mesh_frequency_Hz
    Z = np.arange(70.0).reshape(7, 10)
    times = np.array([0.0, 1.5, 2.5, 2.5, 5.0 + 1e-12, 6.0]) / fm
    ev = np.zeros((times.size, kernels.EV_COLS))
    for i, te in enumerate(times):
        ev[i, kernels.EV_T] = te
        ev[i, kernels.EV_Z : kernels.EV_Z + 10] = 100 + i
        ev[i, kernels.EV_F0 : kernels.EV_F0 + 10] = -(i + 1)  # before: -1, -2, ...
        ev[i, kernels.EV_F1 : kernels.EV_F1 + 10] = i + 1  # after: 1, 2, ...
    r = SimpleNamespace(model=m, t_dense=np.arange(7.0) / fm, states_dense=Z, window_events=ev, fm_Hz=fm)
    F = dense_derivatives(r)
    assert F[0, 0] == 1 and F[-1, 0] == -6  # the sides inside the window
    broken, (ts, Zs, Fs, pieces) = event_pieces(r, F)
    assert broken.tolist() == [False, True, True, False, True, True]
    assert np.allclose(ts * fm, [1, 1.5, 1.5, 2, 2.5, 2.5, 2.5, 2.5, 3, 4, 5, 5, 6], rtol=0, atol=1e-9)
    assert Zs[:, 0].tolist() == [10, 101, 101, 20, 102, 102, 103, 103, 30, 40, 104, 104, 60]
    assert Fs[:, 0].tolist() == [F[1, 0], -2, 2, F[2, 0], -3, 3, -4, 4, F[3, 0], F[4, 0], -5, 5, -6]
    # the sub-pieces all have an event end: 3 -> 4 is whole (integrated with the rest)
    assert pieces.tolist() == [0, 1, 2, 3, 4, 5, 6, 7, 9, 10, 11]


def test_folds_with_events_equal_the_piece_by_piece_integral():
    """The period folds leave out the pieces that hold events and add their sub-pieces:
    the same integral as evaluating every piece (fold=False), to rounding, for the affine
    fold (bearing clearance alone) and the phasor fold (a flank law)."""
    for case in ("bearing lift-off", "contact loss"):
        r = _window(paper_pair(**CASES[case]), 64)
        assert r.event_times.size >= 15
        folded, direct = window_fourier(r, NAMES, 10), window_fourier(r, NAMES, 10, fold=False)
        for name in NAMES:
            scale = np.abs(direct[name]).max()
            assert np.abs(folded[name] - direct[name]).max() <= 1e-12 * scale, (case, name)
        assert np.allclose(window_harmonics(r, NAMES, 10)["F_m"], np.abs(direct["F_m"]), rtol=1e-12, atol=0)
