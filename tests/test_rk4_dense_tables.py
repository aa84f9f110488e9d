"""Long tables on the RK4 step grid: the cost is the step count's, the stage values are the
table's interpolant, and the error of the breaks the schedule leaves inside steps is the
stated one (``dynamics.table_time``: ``split_nodes``, ``kink_defect``).

Independent truths: np.interp of the raw rows at the stage times; the sub-step count of
the schedule and of the run (never wall time); the error of one RK4 step across a single
kink against the same step resolved by 64 sub-steps ending on the kink (Simpson's Peano
kernel, derived in ``table_time.peano``), and every step of a period on dense analytic
tables of an unequal profile-shifted pair (23/47, x = +0.2/-0.1) and of a pair whose
driver has more teeth (40/25) against the step resolved the same way; their F_m harmonics
against RK4 at 8x the steps with every break split (itself checked against dopri5 at
rtol 1e-11)."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from gearwear.dynamics import kernels, paper_pair, simulate
from gearwear.dynamics import table_time as tt
from gearwear.dynamics.equations import mesh_state
from gearwear.dynamics.params import derived
from gearwear.dynamics.simulate import kernel_switches
from gearwear.jobs import simulate as sj
from gearwear.scene.model import scene_from_dict

from scenes import with_paper

EX = Path(__file__).resolve().parents[1] / "examples" / "user_table"
sys.path.insert(0, str(EX))
from make_table import e_closed_um, k_closed  # noqa: E402


def smooth_pair(rows: int):
    """The paper pair with the user-table example's closed-form k and e sampled at ``rows``."""
    u = np.arange(rows) / rows
    P = 2 * math.pi / 30
    m = paper_pair(k_table=k_closed(u), phi_table=u * P, te_amplitude_m=1e-6)
    return m.with_(e_table=1e-6 * e_closed_um(u))


def dense_pair(teeth, shift, points: int = 4096):
    """A scene pair (paper bodies and operating point) with its analytic stiffness table at
    ``points`` nodes per mesh period plus the load-sharing breakpoints."""
    doc = with_paper(
        {
            "pair": {"teeth": teeth, "module_mm": 3.0, "profile_shift": shift, "hub_radius_mm": [12.0, 12.0]},
            "effects": {"mesh_stiffness": {"source": "analytic", "points_per_mesh_period": points}},
        }
    )
    sc = scene_from_dict(doc, name="dense")
    return sj.build_model(sc, sj.stiffness_input(sc))


@pytest.mark.parametrize("rows", [2048, 4096, 16384])
@pytest.mark.parametrize("N", [128, 256, 512])
def test_cost_is_the_step_count(rows, N):
    """A smooth curve sampled finer than the steps: one sub-step per step, whatever the rows
    (from 2048 rows per mesh period: at 1024 rows the signed Simpson sums of this curve's
    kinks, its interpolation error, reach 3.4e-6 of a step's impulse and the schedule
    splits them, SPLIT_WEIGHT = 1e-6)."""
    m = smooth_pair(rows)
    hs = tt.rk4_schedule(m, N)[0]
    assert hs.size == N
    split, unsplit = tt.split_nodes(m, N)
    assert split.size == 0 and unsplit.size > 0
    r = simulate(m, 8 / m.mesh_frequency_Hz, 4 / m.mesh_frequency_Hz, method="rk4", steps_per_mesh_period=N)
    assert r.rejected == r.steps == 8 * N  # sub-steps == steps


@pytest.mark.parametrize("which", ["smooth", "23/47"])
def test_stage_values_are_the_interpolant(which):
    """Every stage reads the table's linear interpolant at its own time, also across the
    breaks left inside a step."""
    m = smooth_pair(4096) if which == "smooth" else dense_pair([23, 47], [0.2, -0.1])
    N = 256
    hs, toff, kq, eq, dkq, deq, ends = tt.rk4_schedule(m, N)
    assert int(ends.sum()) == N * m.table_periods
    P = m.table_period_rad
    t0 = np.r_[0.0, toff[:-1]]
    assert abs(hs.sum() - P / m.omega_p) < 1e-12 * P / m.omega_p
    x = np.r_[m.phi_table, P]
    for j, frac in enumerate((0.0, 0.5, 1.0)):
        ph = ((t0 + frac * hs) * m.omega_p) % P
        k = np.interp(ph, x, np.r_[m.k_table, m.k_table[0]])
        # the analytic table has jumps over 1e-6 of a step: np.interp's rounding there
        assert np.max(np.abs(kq[j::3] - k)) < 1e-8 * m.k_mean
        if m.te_excitation:
            e = np.interp(ph, x, np.r_[m.e_table, m.e_table[0]])
            assert np.max(np.abs(eq[j::3] - e)) < 1e-12 * np.max(np.abs(e))


@pytest.mark.parametrize("theta", [0.2, 0.5, 0.8])
def test_one_step_across_a_kink_makes_the_peano_error(theta, monkeypatch):
    """A table with one strong kink inside the first step (k flat, then rising by 40 % over
    half a period): RK4 across it (the split switched off) minus the same step resolved by
    64 sub-steps per side of the kink is, in q', the stated leading term I / m_e with
    I = Sk (delta - e) (``kink_defect``), to 5 %, and within the bound."""
    N = 1024  # h omega_max = 0.04: the leading term dominates
    P = 2 * math.pi / 30
    dph = P / N
    phi = np.array([0.0, theta * dph, 0.5 * P])
    k = np.array([3.0e8, 3.0e8, 4.2e8])
    m = paper_pair(k_table=k, phi_table=phi)
    p = tuple(derived(m)[0].tolist())
    sw = kernel_switches(m)
    h = 1.0 / (m.mesh_frequency_Hz * N)
    z0 = np.zeros(10)
    z0[4] = m.F_s / 3.0e8  # static deflection, at rest
    monkeypatch.setattr(tt, "SPLIT_WEIGHT", math.inf)
    s0 = tt.rk4_schedule(m, N)
    assert s0[0].size == N  # not split
    Sk, _ = tt.kink_defect(m, N)
    monkeypatch.setattr(tt, "SPLIT_WEIGHT", -1.0)
    s1 = tt.rk4_schedule(m, 64 * N)  # the kink on a sub-step end of 64x finer steps
    assert np.min(np.abs(np.r_[0.0, s1[1]] * m.omega_p - theta * dph)) < 1e-9 * dph
    _, _, z_one = kernels.rk4(z0, h, 1, np.array([0.0]), 1.0, p, *s0, *sw)
    _, _, z_ref = kernels.rk4(z0, h / 64, 64, np.array([0.0]), 1.0, p, *s1, *sw)
    delta = mesh_state(m, np.array([0.5 * h]), z0[None, :])["delta"][0]
    I = Sk[0] * delta
    err = z_one[9] - z_ref[9]
    assert abs(I) > 0 and abs(err - I / m.m_e) < 0.05 * abs(I / m.m_e), (err, I / m.m_e)
    bound = abs(Sk[0]) * delta / m.m_e
    assert abs(err) <= 1.05 * bound
    # and the worst case |E_1| <= 1/24 of the derivation
    jump = abs(np.diff(k)[1] / np.diff(phi)[1]) * m.omega_p
    assert abs(Sk[0]) <= h**2 * jump / 24 * (1 + 1e-12)


def _rel(h, ref):
    keep = ref > 0.01 * ref.max()
    return float(np.max(np.abs(h[keep] - ref[keep]) / ref[keep]))


@pytest.mark.parametrize("teeth, shift", [([23, 47], [0.2, -0.1]), ([40, 25], [0.0, 0.0])])
def test_dense_analytic_tables_meet_the_accuracy_contract(teeth, shift, monkeypatch):
    """4096 nodes per mesh period plus the breakpoints (jumps where pairs enter, leave and
    share load), 256 steps per mesh period: F_m harmonics 1-10 within 1e-3 of RK4 at 2048
    steps with every break split (converged: agrees with dopri5 at rtol 1e-11 to 1e-7).
    The schedule splits the steps at the jumps (a handful of graded clusters), not the
    smooth stretches, and the stated kink error of what it leaves is below 1e-6 of the
    mean mesh impulse per period."""
    m = dense_pair(teeth, shift)
    fm = m.mesh_frequency_Hz
    D, Dd = 40 / fm, 20 / fm
    N = 256
    r = simulate(m, D, Dd, method="rk4", steps_per_mesh_period=N)
    hs = tt.rk4_schedule(m, N)[0]
    split, unsplit = tt.split_nodes(m, N)
    assert hs.size == N + split.size < 3 * N  # the breaks are 4000+ nodes, the sub-steps < 3 N
    assert unsplit.size > 10 * split.size
    Sk, _ = tt.kink_defect(m, N)
    delta = float(np.max(np.abs(r.signals["delta"])))
    rho = np.sum(np.abs(Sk)) * delta / (abs(m.F_s) / fm)
    assert rho < 1e-6, rho
    monkeypatch.setattr(tt, "SPLIT_WEIGHT", -1.0)
    monkeypatch.setattr(tt, "SPLIT_MAX_PER_STEP", 10**9)
    ref = simulate(m, D, Dd, method="rk4", steps_per_mesh_period=8 * N).harmonics("F_m")
    monkeypatch.undo()
    dp = simulate(m, D, Dd, method="dopri5", rtol=1e-11).harmonics("F_m")
    assert _rel(ref, dp) < 1e-7
    assert _rel(r.harmonics("F_m"), ref) < 1e-3


@pytest.mark.parametrize("teeth, shift", [([23, 47], [0.2, -0.1]), ([40, 25], [0.0, 0.0])])
def test_stated_kink_error_holds_step_by_step_on_dense_tables(teeth, shift, monkeypatch):
    """The dense analytic tables above, every step of a mesh period from the static
    deflection: RK4's step on the schedule (thousands of kinks left inside steps) minus
    the same step resolved by 64 sub-steps ending on every break is, in q', the stated
    I_q / m_e = Sk_q delta / m_e (``kink_defect``) to 5 % of the largest, and within the
    bound |Sk_q| |delta| / m_e plus that margin. The bodies are 1e4 times heavier, so
    RK4's own O(h^5) error is far below the kinks' (the kink term does not depend on it)."""
    m0 = dense_pair(teeth, shift)
    s = 1e4
    m = m0.with_(m_p=m0.m_p * s, m_g=m0.m_g * s, J_p=m0.J_p * s, J_g=m0.J_g * s)
    N = 256
    h = 1.0 / (m.mesh_frequency_Hz * N)
    p = tuple(derived(m)[0].tolist())
    sw = kernel_switches(m)
    pol = tt.rk4_schedule(m, N)
    Sk, _ = tt.kink_defect(m, N)
    monkeypatch.setattr(tt, "SPLIT_WEIGHT", -1.0)
    monkeypatch.setattr(tt, "SPLIT_MAX_PER_STEP", 10**9)
    fine = tt.rk4_schedule(m, 64 * N)
    monkeypatch.undo()

    def part(sched, sel):
        return tuple(np.ascontiguousarray(a[np.repeat(sel, 3)] if a.size == 3 * sel.size else a[sel]) for a in sched)

    step_pol = np.r_[0, np.cumsum(pol[6])[:-1]]
    step_fine = np.r_[0, np.cumsum(fine[6])[:-1]] // 64
    z0 = np.zeros(10)
    z0[4] = m.F_s / m.k_mean  # delta = q at rest, e = 0
    err, pred = np.empty(N), np.empty(N)
    for j in range(N):
        _, _, a = kernels.rk4(z0.copy(), h, 1, np.array([0.0]), 1.0, p, *part(pol, step_pol == j), *sw)
        _, _, b = kernels.rk4(z0.copy(), h / 64, 64, np.array([0.0]), 1.0, p, *part(fine, step_fine == j), *sw)
        err[j] = a[9] - b[9]
        pred[j] = np.sum(Sk[step_pol == j]) * z0[4] / m.m_e
    assert np.count_nonzero(pred) > N // 2  # most steps hold kinks
    margin = 0.05 * np.max(np.abs(pred))
    assert np.max(np.abs(err - pred)) < margin
    bound = np.array([np.sum(np.abs(Sk[step_pol == j])) for j in range(N)]) * z0[4] / m.m_e
    assert np.all(np.abs(err) <= bound + margin)
