"""Exact window harmonics: the period fold is the same integral reordered.

window_fourier sums over periods before applying the phasors (every signal), and for a
mesh without a flank law it sums the states first and evaluates the signals on one table
period (s(t, z) affine in z with periodic coefficients). Both must give the integral
that evaluates every piece of the window (fold=False) to rounding, for every kind of
model the fold accepts or refuses: complex coefficients, not only amplitudes, since the
diagnosis uses their phases."""

import numpy as np
import pytest

from gearwear.dynamics import paper_pair, simulate
from gearwear.dynamics.analysis import window_fourier, window_harmonics
from gearwear.dynamics.model import has_flank_law

NAMES = ["y_p", "x_p", "delta", "F_m", "k_h", "s"]


def _tiled_fault_model():
    """A 30-period table (a one-tooth fault): one period softened by 20 %."""
    base = paper_pair(n_table=64)
    phi = np.concatenate([base.phi_table + j * base.mesh_period_rad for j in range(30)])
    k = np.tile(base.k_table, 30)
    k[:64] *= 0.8
    return base.with_(phi_table=phi, k_table=k, e_table=np.tile(base.e_table, 30), table_periods=30)


CASES = {
    "smooth table, RK4": (lambda: paper_pair(n_table=97), "rk4", 24),
    "excitation and bearing clearance, dopri5": (
        lambda: paper_pair(torque_Nm=20.0, speed_rpm=3000, te_amplitude_m=3e-6, clearance_total_m=20e-6),
        "dopri5",
        24,
    ),
    "30-period table": (_tiled_fault_model, "rk4", 60),
    "backlash (no affine fold)": (
        lambda: paper_pair(torque_Nm=5.0, speed_rpm=4000, backlash_total_m=50e-6),
        "dopri5",
        24,
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_folded_integral_equals_the_piece_by_piece_integral(case):
    make, method, periods = CASES[case]
    m = make()
    P = 1.0 / m.mesh_frequency_Hz
    r = simulate(m, (periods + 2) * P, 2 * P, method=method, rtol=1e-9, steps_per_mesh_period=128)
    assert r.n_periods == periods
    folded = window_fourier(r, NAMES, 10)
    direct = window_fourier(r, NAMES, 10, fold=False)
    for name in NAMES:
        c, ref = folded[name], direct[name]
        assert np.iscomplexobj(c) and c.shape == (10,)
        scale = max(np.abs(ref).max(), 1e-300)
        assert np.abs(c - ref).max() <= 1e-9 * scale, (case, name, np.abs(c - ref).max() / scale)
    amps = window_harmonics(r, ["F_m"], 10)["F_m"]
    assert np.allclose(amps, np.abs(direct["F_m"]), rtol=1e-9, atol=0)
    if not has_flank_law(m) and m.table_periods > 1:
        assert np.abs(direct["F_m"]).max() > 0  # the fault's table really varies


def test_fold_gives_the_phase_of_a_shifted_window():
    """The coefficients refer to t = 0 (mesh angle 0): discarding one more mesh period
    leaves every coefficient of a periodic steady state unchanged, in phase too."""
    m = paper_pair(n_table=64)
    P = 1.0 / m.mesh_frequency_Hz
    a = simulate(m, 432 * P, 400 * P, method="rk4")  # 400 periods: the transient is gone
    b = simulate(m, 433 * P, 401 * P, method="rk4")
    ca, cb = window_fourier(a, ["F_m"], 5)["F_m"], window_fourier(b, ["F_m"], 5)["F_m"]
    assert np.abs(ca - cb).max() < 1e-6 * np.abs(ca).max()
