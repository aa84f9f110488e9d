"""Dynamics, model consistency: three independent right-hand sides agree (compiled
kernel, scalar pure-Python, vectorised numpy), table interpolation paths, flank law,
dynamic centre-distance geometry against finite differences of the flank potential."""

import math

import numpy as np
import pytest

from gearwear.dynamics import kernel_switches, kernels, paper_pair, rhs_python, simulate, static_equilibrium
from gearwear.dynamics.model import _accelerations, derived, mesh_state

CASES = {
    "tvms": dict(),
    "all-static": dict(backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=5e-6),
    "all-dynamic": dict(
        backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=5e-6, centre_distance="dynamic"
    ),
    "paper-damping": dict(backlash_total_m=50e-6, mesh_damping="paper"),
    "dynamic-no-backlash": dict(centre_distance="dynamic"),
}


def _random_states(m, n, rng):
    z0 = static_equilibrium(m)
    b = (m.backlash_half_m or 0.0) + 2e-6
    Z = np.empty((n, 10))
    Z[:, :4] = z0[:4] + rng.uniform(-1, 1, (n, 4)) * 20e-6  # across the bearing dead zones
    Z[:, 4] = z0[4] + rng.uniform(-2.5, 0.5, n) * b  # drive, gap and back flank
    Z[:, 5:] = rng.normal(0, 0.05, (n, 5))
    return Z


@pytest.mark.parametrize("name", sorted(CASES))
def test_three_right_hand_sides_agree(name):
    m = paper_pair(**CASES[name])
    rng = np.random.default_rng(1)
    Z = _random_states(m, 200, rng)
    T = rng.uniform(0, 0.01, 200)
    par, phi, phx, kx, ex = derived(m)
    sw = kernel_switches(m, track_energy=True)
    p = tuple(par.tolist())
    A = _accelerations(m, T, Z)
    seen = set()
    for t, z, a in zip(T, Z, A):
        dz = kernels.rhs_at(t, z, p, phx, kx, ex, *sw)
        dp = rhs_python(t, z, m)
        scale = np.abs(dp[5:]).max()
        assert np.allclose(dz[:10], dp, rtol=1e-9, atol=1e-9 * scale)
        assert np.allclose(a, dp[5:], rtol=1e-9, atol=1e-9 * scale)
        seen.add(int(mesh_state(m, np.array([t]), z[None])["mode"][0]))
    if m.backlash_half_m is not None:
        assert {-1, 0, 1} <= seen  # all three flank modes hit


def _with_collinear_nodes(m, phi, k):
    """The same piecewise-linear function with extra collinear nodes (non-uniform table)."""
    mid = 0.5 * (phi[:-1:3] + phi[1::3])
    kmid = 0.5 * (k[:-1:3] + k[1::3])
    order = np.argsort(np.r_[phi, mid])
    return m.with_(phi_table=np.r_[phi, mid][order], k_table=np.r_[k, kmid][order], e_table=None)


@pytest.mark.parametrize("offset", [0.0, 0.4])
def test_uniform_fast_path_equals_searchsorted_path(offset):
    """O(1) uniform-table lookup (also for a table not starting at 0) against binary search."""
    base = paper_pair()
    d = base.mesh_period_rad / 256
    phi = (np.arange(256) + offset) * d
    P = base.mesh_period_rad
    k = np.interp(phi, np.r_[base.phi_table, P], np.r_[base.k_table, base.k_table[0]])
    m = base.with_(phi_table=phi, k_table=k)
    m2 = _with_collinear_nodes(m, phi, k)
    assert derived(m)[0][19] == 1.0 and derived(m2)[0][19] == 0.0  # uniform / searchsorted
    r = simulate(m, 0.02, 0.01, method="rk4", steps_per_mesh_period=512)
    r2 = simulate(m2, 0.02, 0.01, method="rk4", steps_per_mesh_period=512)
    assert np.max(np.abs(r2.signals["F_m"] - r.signals["F_m"])) < 1e-9 * np.ptp(r.signals["F_m"])
    assert np.allclose(r.signals["k_h"], r2.signals["k_h"], rtol=1e-12)


def test_flank_law_and_paper_damping_difference():
    m = paper_pair(backlash_total_m=50e-6)
    b = m.backlash_half_m
    z = static_equilibrium(m)
    t = np.zeros(3)
    Z = np.tile(z, (3, 1))
    G = np.array([math.cos(m.alpha), math.sin(m.alpha), -math.cos(m.alpha), -math.sin(m.alpha), 1.0])
    # put s in the gap, on the drive flank and on the back flank; approaching velocity
    d0 = mesh_state(m, t[:1], z[None])["delta"][0]
    Z[:, 4] += np.array([0.0, -b - (d0 - b), -2 * b - (d0 - b) - 1e-6]) - 0.0
    Z[:, 9] = 0.1
    ms = mesh_state(m, t, Z)
    s = ms["s"]
    assert s[0] > b and abs(s[1]) <= b and s[2] < -b
    assert list(ms["mode"]) == [1, 0, -1]
    assert ms["F_m"][1] == 0.0  # no force through the gap
    dd = ms["delta_dot"]
    assert np.allclose(dd, 0.1 * G[4])
    mp = m.with_(mesh_damping="paper")
    msp = mesh_state(mp, t, Z)
    assert msp["F_m"][1] == pytest.approx(m.c_h * dd[1])  # literal Eq. 19: damper across the gap
    assert np.allclose(msp["F_m"][[0, 2]], ms["F_m"][[0, 2]])
    k = ms["k_h"]
    assert ms["F_m"][0] == pytest.approx(m.c_h * dd[0] + k[0] * (s[0] - b))
    assert ms["F_m"][2] == pytest.approx(m.c_h * dd[2] + k[2] * (s[2] + b))


def test_dynamic_centre_distance_geometry():
    m = paper_pair(backlash_total_m=50e-6, centre_distance="dynamic")
    Rs = m.R_p + m.R_g
    inv = lambda a: math.tan(a) - a  # noqa: E731
    z = np.zeros(10)
    z[3] = 30e-6  # gear pushed away along the centre line
    ms = mesh_state(m, np.zeros(1), z[None])
    C = m.C0 + 30e-6
    a = math.acos(Rs / C)
    assert ms["b"][0] == pytest.approx(m.backlash_half_m + Rs * (inv(a) - inv(m.alpha)), rel=1e-10)
    # d b / d C = sin(alpha'): per side the backlash grows by ~ dC sin(alpha)
    assert (ms["b"][0] - m.backlash_half_m) / 30e-6 == pytest.approx(math.sin(m.alpha), rel=1e-3)
    # generalised forces are minus the gradient of the flank potential 1/2 k f^2
    rng = np.random.default_rng(3)
    for _ in range(5):
        zz = static_equilibrium(m)
        zz[:4] += rng.normal(0, 3e-6, 4)
        zz[4] += rng.choice([1, -1]) * rng.uniform(0, 3e-6) - (0 if rng.random() < 0.5 else 2 * 25e-6)
        zz[5:] = 0.0
        V = lambda x: mesh_state(m.with_(T_p=0.0), np.zeros(1), x[None])["V_mesh"][0]  # noqa: E731
        acc = _accelerations(m.with_(T_p=0.0, k_b=1e-30, c_b=0.0), np.zeros(1), zz[None])[0]
        M = np.array([m.m_p, m.m_p, m.m_g, m.m_g, m.m_e])
        for j in range(5):
            h = 1e-11
            zp, zm = zz.copy(), zz.copy()
            zp[j] += h
            zm[j] -= h
            grad = (V(zp) - V(zm)) / (2 * h)
            assert acc[j] * M[j] == pytest.approx(-grad, rel=1e-5, abs=1e-6)
