"""Stiffness tables over several mesh periods (``GearDynamics.table_periods``): a fault on
one pinion tooth makes k periodic over a pinion revolution (z_p mesh periods).

* tiling identity: a z_p-period table that repeats the one-period table gives the
  one-period response (RK4 and dopri5);
* RK4 keeps its 4th order on a multi-period table whose length does not divide the
  step count (97 nodes per mesh period, z_p periods, one period faulted);
* a faulted period puts sidebands f_m +- n f_shaft (n = 1, 2, 3) around the first mesh
  harmonics; without it they are at the numerical noise floor.

Figures measured on this machine (paper pair, 1200 rpm, 40 N m): tiling identity RK4
1.1e-13, dopri5 (rtol 1e-10) 1.5e-12 of max |x| (F_m, delta, vq, y_p samples; mesh
harmonics 3e-14 / 1.1e-13); RK4 order 3.88 / 3.96 (128 -> 256 -> 512 steps); sidebands
without the fault <= 1.7e-13 (F_m) and <= 1.2e-13 (a_delta) of their mesh harmonic, with
a 10 % stiffness loss on one mesh period 3e-3 ... 2.8e-2."""

import math

import numpy as np
import pytest

from gearwear.core.validation import InputError
from gearwear.dynamics import paper_pair, simulate
from gearwear.dynamics.analysis import acceleration_signals
from gearwear.dynamics.model import rk4_schedule, table_node_times
from gearwear.dynamics.simulate import _periodic_with, round_to_table_periods


def tiled(m, L, fault=None):
    """The one-period model m with its tables repeated L times (table_periods = L); with
    ``fault`` the stiffness of the first mesh period is scaled by (1 - fault)."""
    P = m.mesh_period_rad
    phi = (m.phi_table[None, :] + P * np.arange(L)[:, None]).ravel()
    k = np.tile(m.k_table, L)
    if fault is not None:
        k[: m.k_table.size] *= 1.0 - fault
    return m.with_(phi_table=phi, k_table=k, e_table=np.tile(m.e_table, L), table_periods=L)


def _rel(a, b, names=("F_m", "delta", "vq", "y_p")):
    return max(float(np.max(np.abs(a.signals[n] - b.signals[n])) / np.max(np.abs(b.signals[n]))) for n in names)


# ---- the model ------------------------------------------------------------------------
def test_table_period_and_its_uses():
    m1 = paper_pair(n_table=97, te_amplitude_m=2e-6)
    mL = tiled(m1, m1.z_p)
    assert m1.table_periods == 1 and m1.table_period_rad == m1.mesh_period_rad
    assert mL.table_period_rad == pytest.approx(2 * math.pi, rel=1e-15)
    assert mL.table_period_s == pytest.approx(2 * math.pi / m1.omega_p, rel=1e-15)
    assert mL.mesh_frequency_Hz == m1.mesh_frequency_Hz  # physical, unchanged
    assert mL.k_mean == pytest.approx(m1.k_mean, rel=1e-14)
    assert mL.e_mean == pytest.approx(m1.e_mean, rel=1e-14)
    # node times: the same set as the one-period table's
    a, b = table_node_times(m1, 0.001, 0.2), table_node_times(mL, 0.001, 0.2)
    assert a.size == b.size and np.max(np.abs(a - b)) < 1e-15 * 0.2 * 10
    # the RK4 schedule spans one table period: L N steps
    N = 128
    hs, toff, kq, eq, dkq, deq, ends = rk4_schedule(mL, N)
    T = mL.table_period_s
    assert int(ends.sum()) == mL.z_p * N and abs(hs.sum() - T) < 1e-12 * T
    h1 = rk4_schedule(m1, N)
    assert hs.size == mL.z_p * h1[0].size
    assert np.allclose(kq, np.tile(h1[2], mL.z_p), rtol=1e-12, atol=0)


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, float("nan"), "2"])
def test_table_periods_is_validated(bad):
    m = paper_pair(n_table=64)
    with pytest.raises(InputError, match="table_periods") as ei:
        m.with_(table_periods=bad)
    assert "\n" not in str(ei.value)


def test_one_period_table_with_several_table_periods_is_refused():
    m = paper_pair(n_table=64)
    with pytest.raises(InputError, match="phi_table.*table_periods = 30"):
        m.with_(table_periods=30)  # a one-mesh-period table: forgot to tile
    with pytest.raises(InputError, match="phi_table"):  # beyond the table period
        tiled(m, 3).with_(table_periods=2)
    assert tiled(m, 3).table_periods == 3 and m.with_(table_periods=1.0).table_periods == 1


def test_round_to_table_periods():
    m = tiled(paper_pair(n_table=64), 30)
    fm = m.mesh_frequency_Hz
    for dur, disc in ((0.1, 0.05), (0.051, 0.0), (0.2, 0.0123), (0.05 + 59.9 / fm, 0.05)):
        d = round_to_table_periods(m, dur, disc)
        n_d = math.ceil(disc * fm - 1e-9)
        M = math.floor((d - n_d / fm) * fm + 1e-9)
        assert M % 30 == 0 and M >= math.floor((dur - n_d / fm) * fm + 1e-9), (dur, disc, M)
        assert M - 30 < max(math.floor((dur - n_d / fm) * fm + 1e-9), 1)
    assert round_to_table_periods(m, 0.01, 0.0, min_table_periods=3) * fm == pytest.approx(90.5)
    m1 = paper_pair(n_table=64)
    assert round_to_table_periods(m1, 0.1, 0.05) * fm == pytest.approx(60.5)  # L = 1: same window


def test_periodic_with_reports_multiples_of_the_table_period():
    S, L = 16, 5
    t = np.arange(40 * S) / S
    one = np.sin(2 * np.pi * t)  # 1-periodic
    slow = one + 1e-3 * np.sin(2 * np.pi * t / L)  # L-periodic
    assert _periodic_with(one, S, 40) == 1 and _periodic_with(slow, S, 40) == L  # L = 1: as before
    assert _periodic_with(one, S, 40, table_periods=L) == L  # never fewer than L
    assert _periodic_with(slow, S, 40, table_periods=L) == L
    assert _periodic_with(slow[: (2 * L - 1) * S], S, 2 * L - 1, table_periods=L) == 0  # too short
    assert _periodic_with(np.ones(10 * S), S, 10, table_periods=L) == L


# ---- tiling identity ------------------------------------------------------------------
@pytest.mark.parametrize("method, kw", [("rk4", {}), ("dopri5", {"rtol": 1e-10})])
def test_tiled_table_gives_the_one_period_response(method, kw):
    m1 = paper_pair(n_table=97, te_amplitude_m=2e-6)
    mL = tiled(m1, m1.z_p)
    a = simulate(m1, 0.1, 0.05, method=method, **kw)
    b = simulate(mL, 0.1, 0.05, method=method, **kw)
    assert a.steps == b.steps
    err = _rel(b, a)
    # measured: rk4 1.1e-13, dopri5 1.5e-12 (of max |x|); rounding of the node times only
    assert err < 1e-11, err
    ha, hb = a.harmonics_of(["F_m", "delta"]), b.harmonics_of(["F_m", "delta"])
    for n in ha:
        assert np.max(np.abs(ha[n] - hb[n])) < 1e-10 * ha[n].max()


# ---- RK4 order on a multi-period table -------------------------------------------------
def test_rk4_fourth_order_on_a_faulted_multi_period_table():
    m = tiled(paper_pair(n_table=97), 30, fault=0.1)  # 97 nodes per period: no step divides it
    S = 16
    ref = simulate(m, 0.1, 0.05, method="dopri5", rtol=1e-11, samples_per_mesh_period=S)

    def err(N):
        r = simulate(m, 0.1, 0.05, method="rk4", steps_per_mesh_period=N, samples_per_mesh_period=S)
        return max(
            float(np.max(np.abs(r.signals[n] - ref.signals[n])) / np.ptp(ref.signals[n])) for n in ("F_m", "delta")
        )

    e = [err(N) for N in (128, 256, 512)]
    orders = [math.log2(e[i] / e[i + 1]) for i in range(2)]
    # measured: 4.5e-4, 3.1e-5, 2.0e-6; orders 3.88, 3.96
    assert e[1] < 1e-4 and all(3.5 < o < 4.5 for o in orders), (e, orders)


# ---- sidebands of a one-tooth fault ---------------------------------------------------
def _sidebands(m):
    """Steady state over two pinion revolutions: the F_m and a_delta amplitudes at
    f_m k +- n f_shaft (n = 1..3) over the amplitude at k f_m, k = 1..3."""
    disc = 0.3  # 180 mesh periods of transient
    r = simulate(m, round_to_table_periods(m, disc + 0.1, disc), disc, method="rk4")
    assert r.whole_table_periods and r.n_periods == 60
    assert r.periodic_with == m.table_periods  # settled, honest periodicity
    f_sh = m.omega_p / (2 * math.pi)
    out = {}
    sig = dict(F_m=r.signals["F_m"], a_delta=acceleration_signals(r)["a_delta"])
    for name, x in sig.items():
        A = np.abs(np.fft.rfft(x)) / x.size * 2  # rectangular window
        df = r.fs_Hz / x.size
        assert abs(f_sh / df - round(f_sh / df)) < 1e-9  # shaft orders on bins
        b = lambda f: A[int(round(f / df))]  # noqa: E731
        out[name] = np.array(
            [
                [max(b(k * r.fm_Hz + n * f_sh), b(k * r.fm_Hz - n * f_sh)) / b(k * r.fm_Hz) for n in (1, 2, 3)]
                for k in (1, 2, 3)
            ]
        )
    return out


def test_a_one_tooth_fault_makes_shaft_order_sidebands():
    m1 = paper_pair(n_table=256)
    healthy = _sidebands(tiled(m1, m1.z_p))
    faulty = _sidebands(tiled(m1, m1.z_p, fault=0.1))
    for name in ("F_m", "a_delta"):
        # measured: healthy <= 1.7e-13 (F_m), 1.2e-13 (a_delta); faulty 3e-3 ... 2.8e-2
        assert healthy[name].max() < 1e-10, (name, healthy[name])
        assert faulty[name].min() > 1e-3, (name, faulty[name])
        assert faulty[name].min() > 1e6 * healthy[name].max()
