"""Condition-monitoring indicators (dynamics.indicators) on signals with hand-worked values."""

import json
import math

import numpy as np
import pytest

from gearwear.core.validation import InputError
from gearwear.dynamics import indicators as ind

# a record of R = 4 revolutions of a shaft with z = 20 teeth, 64 samples per mesh period
Z, R, S = 20, 4, 64
F_SH = 25.0  # Hz
F_M = Z * F_SH  # 500 Hz
FS = S * F_M  # 32 kHz
N = R * Z * S
T = np.arange(N) / FS


def test_gaussian_noise_kurtosis_is_3():
    rng = np.random.default_rng(12345)
    x = rng.standard_normal(2**16) * 3.0 + 7.0
    se = math.sqrt(24.0 / x.size)  # standard error of the sample kurtosis
    k = ind.kurtosis(x)
    assert abs(k - 3.0) < 4 * se, (k, se)  # measured 2.9971 (se 0.019)
    assert ind.ac_rms(x) == pytest.approx(3.0, rel=0.02)


def test_pure_sine():
    A = 2.5
    x = A * np.cos(2 * np.pi * F_M * T)  # sampled at its peaks (even S)
    assert ind.crest_factor(x) == pytest.approx(math.sqrt(2), rel=1e-12)
    assert ind.kurtosis(x) == pytest.approx(1.5, rel=1e-12)
    assert ind.fm0(x, FS, F_M, F_SH) == pytest.approx(2.0, rel=1e-12)  # p-p 2A over A
    assert ind.ac_rms(x) == pytest.approx(A / math.sqrt(2), rel=1e-12)
    # nothing left after removing the mesh harmonics: FM4 undefined, with the reason
    g = ind.gear_indicators(x, FS, F_M, F_SH, unit="m/s^2")
    assert g.FM4 is None and "rounding level" in dict(g.undefined)["FM4"]
    assert g.sideband_energy < 1e-25 and g.sideband_ratio_dB < -250  # rounding level, finite


def test_fm4_impulses_versus_sidebands():
    rng = np.random.default_rng(7)
    carrier = np.cos(2 * np.pi * F_M * T)
    noise = 1e-3 * rng.standard_normal(N)
    # a tooth that hits once per revolution: one impulse per revolution
    imp = np.zeros(N)
    imp[np.arange(R) * Z * S + 37] = 0.5
    fm4_imp = ind.fm4(carrier + noise + imp, FS, F_M, F_SH)
    # a sine with first-order sidebands (removed) and a second-order one (kept): a sine residual
    sb = carrier + 0.2 * np.cos(2 * np.pi * (F_M + F_SH) * T) + 0.2 * np.cos(2 * np.pi * (F_M - F_SH) * T)
    fm4_sine_residual = ind.fm4(sb + 0.05 * np.cos(2 * np.pi * (F_M + 2 * F_SH) * T + 0.3), FS, F_M, F_SH)
    fm4_noise_residual = ind.fm4(sb + noise, FS, F_M, F_SH)
    se = math.sqrt(24.0 / N)
    # measured: impulses 919, sine residual 1.5 (to 4e-16), noise residual 2.977 (se 0.068)
    assert fm4_imp > 50, fm4_imp
    assert fm4_sine_residual == pytest.approx(1.5, rel=1e-9)
    assert abs(fm4_noise_residual - 3.0) < 5 * se, fm4_noise_residual
    # what is removed: DC, shaft orders 1-2, mesh harmonics and their first sidebands
    d = ind.difference_signal(sb + 4.0 + 0.3 * np.cos(2 * np.pi * 2 * F_SH * T), FS, F_M, F_SH)
    assert np.max(np.abs(d)) < 1e-12


def test_sideband_energy_of_an_am_carrier():
    for m in (0.05, 0.3, 1.0):
        x = (1 + m * np.cos(2 * np.pi * F_SH * T)) * np.cos(2 * np.pi * F_M * T)
        e = ind.sideband_energy(x, FS, F_M, F_SH)
        # hand-worked: each sideband has amplitude m/2, energy 2 (m/2)^2 = m^2/2; carrier 1
        assert e["mesh_energy"] == pytest.approx(1.0, rel=1e-12)
        assert e["sideband_energy"] == pytest.approx(m * m / 2, rel=1e-12)
        assert e["sideband_ratio_dB"] == pytest.approx(10 * math.log10(m * m / 2), abs=1e-10)
    # only the listed bands count: a sideband of order 4 is outside N_sb = 3
    x = np.cos(2 * np.pi * F_M * T) + 0.1 * np.cos(2 * np.pi * (F_M + 4 * F_SH) * T)
    assert ind.sideband_energy(x, FS, F_M, F_SH)["sideband_energy"] < 1e-25
    assert ind.sideband_energy(x, FS, F_M, F_SH, N_sb=4)["sideband_energy"] == pytest.approx(0.01)


def test_constant_signal_is_undefined_not_nan():
    g = ind.gear_indicators(np.full(N, 3.7), FS, F_M, F_SH, unit="N")
    assert g.kurtosis is None and g.crest_factor is None and g.FM0 is None and g.FM4 is None
    assert g.sideband_ratio_dB is None
    why = dict(g.undefined)
    assert set(why) == {"kurtosis", "crest_factor", "FM0", "FM4", "sideband_ratio_dB"}
    text = json.dumps(g.to_dict(), allow_nan=False)  # strict JSON
    assert '"unit": "N"' in text and g.to_dict()["undefined"]["kurtosis"].startswith("the signal is constant")
    assert g.mean == pytest.approx(3.7) and g.ac_rms < 1e-12 and ind.kurtosis(np.zeros(8)) is None


def test_bad_arguments_name_themselves():
    x = np.cos(2 * np.pi * F_M * T)
    cases = [
        (lambda: ind.gear_indicators(x[:-5], FS, F_M, F_SH), "x: .*whole number"),
        (lambda: ind.gear_indicators(x, FS, F_M, 23.0), "f_mesh_Hz"),
        (lambda: ind.gear_indicators(x, -FS, F_M, F_SH), "fs_Hz"),
        (lambda: ind.gear_indicators(x, FS, F_M, F_SH, N_sb=10), "N_sb"),
        (lambda: ind.gear_indicators(x, FS, F_M, F_SH, K=40), "K = 40"),
        (lambda: ind.gear_indicators(x, FS, F_M, F_SH, K=0), "K = 0"),
        (lambda: ind.gear_indicators(x, FS, F_M, F_SH, n_harmonics=99), "n_harmonics"),
        (lambda: ind.gear_indicators(np.r_[x[:-1], np.nan], FS, F_M, F_SH), "x: must be finite"),
        (lambda: ind.kurtosis(np.ones((3, 3))), "x: must be a 1-D"),
    ]
    for f, msg in cases:
        with pytest.raises(InputError, match=msg) as ei:
            f()
        assert "\n" not in str(ei.value)


def test_gear_indicators_dict_and_sideband_lines():
    x = (1 + 0.2 * np.cos(2 * np.pi * F_SH * T)) * np.cos(2 * np.pi * F_M * T)
    d = ind.gear_indicators(x, FS, F_M, F_SH, unit="m/s^2").to_dict()
    assert d["n_revolutions"] == R and d["K_mesh_harmonics"] == 3 and d["N_sidebands"] == 3
    assert d["FM0_FM4_mesh_harmonics"] == S // 2 and d["FM4_shaft_orders_removed"] == 2
    assert d["sideband_ratio_dB"] == pytest.approx(10 * math.log10(0.02))
    json.dumps(d, allow_nan=False)
    lines = ind.sideband_lines(F_M, F_SH, K=2, N=3)
    assert lines.mesh_Hz.tolist() == [500.0, 1000.0]
    assert lines.orders.tolist() == [-3, -2, -1, 1, 2, 3]
    assert lines.sideband_Hz[1].tolist() == [925.0, 950.0, 975.0, 1025.0, 1050.0, 1075.0]
    json.dumps(lines.to_dict())


def test_indicators_of_a_simulated_tooth_fault():
    """One mesh period of a 30-period table 10 % softer: the sideband ratio of the relative
    acceleration rises from the numerical floor to about -37 dB, and FM4 goes from
    undefined (the healthy difference signal is rounding noise) to about 41."""
    from gearwear.dynamics import paper_pair, simulate
    from gearwear.dynamics.simulate import round_to_table_periods

    m1 = paper_pair(n_table=128)
    P = m1.mesh_period_rad
    phi = (m1.phi_table[None, :] + P * np.arange(30)[:, None]).ravel()
    out = {}
    for fault in (0.0, 0.1):
        k = np.tile(m1.k_table, 30)
        k[:128] *= 1 - fault
        m = m1.with_(phi_table=phi, k_table=k, e_table=np.tile(m1.e_table, 30), table_periods=30)
        r = simulate(m, round_to_table_periods(m, 0.4, 0.3), 0.3, method="rk4", steps_per_mesh_period=128)
        out[fault] = ind.result_indicators(r, "a_delta")
        assert out[fault].unit == "m/s^2" and out[fault].n_revolutions == 2
    # measured: healthy -256 dB, FM4 None; faulty -36.7 dB, FM4 41.3, crest 2.20 -> 3.59
    assert out[0.0].sideband_ratio_dB < -200 and out[0.1].sideband_ratio_dB > -50
    assert out[0.0].FM4 is None and "FM4" in dict(out[0.0].undefined) and out[0.1].FM4 > 10
    assert out[0.1].crest_factor > 1.3 * out[0.0].crest_factor
    json.dumps(out[0.1].to_dict(), allow_nan=False)


def test_periodicity_mismatch_finds_the_period_and_flags_none():
    """The indicators' periodicity verdict (issue 24: a chaotic healthy pair looked like a fault):
    a period-2 signal repeats exactly at p = 2, noise at no p."""
    from gearwear.dynamics.simulate import periodicity_mismatch

    S = 64
    t = np.arange(40 * S) / S  # 40 mesh periods
    x = np.sin(2 * np.pi * t) + 0.3 * np.sin(np.pi * t)  # period 2 mesh periods
    p, m = periodicity_mismatch(x, S)
    assert p == 2 and m < 1e-12
    noise = np.random.default_rng(1).standard_normal(40 * S)
    assert periodicity_mismatch(noise, S)[1] > 0.3


def test_a_non_periodic_healthy_response_is_flagged():
    """The light-load backlash example is healthy but not periodic (its kurtosis of ~20 and
    sideband ratio near 0 dB look like a fault): the indicators say so, and a warning too; the
    paper's severe-wear scene is periodic and carries no such warning."""
    from gearwear.jobs.simulate import run
    from gearwear.scene.model import load_scene

    s = run(load_scene("examples/light_load_backlash.toml")).summary()
    assert s["condition_indicators"]["periodic"] is False
    assert any(w.startswith("condition indicators: not periodic") for w in s["warnings"])
    s = run(load_scene("paper-wear-severe")).summary()
    assert s["condition_indicators"]["periodic"] is True
    assert not any(w.startswith("condition indicators") for w in s["warnings"])
