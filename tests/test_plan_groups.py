"""The measurement plan's runs grouped across speeds (gearwear.diagnose.plan.SpeedGroups,
gearwear.diagnose.surrogate.simulate_runs) and the window integrals in blocks
(dynamics.analysis.BLOCK).

Independent truths: a run's result is a function of its own scene, so a run whose stiffness
table comes from a shared memo equals the run that computes its own table, to the bit; the
table depends on the torque, the wear and the pair but not on the speed, so three speeds at
one torque need one table (counted at its source), and two torques two. The window
integrals are sums of independent pieces, so evaluating them in blocks changes only the
order of the additions (roundoff), and the derivatives at the dense times are row by row
the same numbers in any blocks. Pairs: 23/47 shifted (x +0.2/-0.1) and its mirror 47/23,
whose driver has more teeth, with wear, backlash and bearing clearance (the plan's
unknowns), not the paper's 30/30.
"""

from __future__ import annotations

import copy
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from gearwear.core.validation import InputError
from gearwear.diagnose import plan as dplan
from gearwear.diagnose import surrogate as ds
from gearwear.jobs import simulate as job_simulate
from gearwear.stiffness import sources

K = 6


def _raw(teeth, shifts, bores_mm, speed_rpm=1500.0, torque_Nm=60.0):
    return {
        "pair": {
            "teeth": list(teeth),
            "module_mm": 3.0,
            "face_width_mm": 30.0,
            "profile_shift": list(shifts),
            "hub_radius_mm": list(bores_mm),
        },
        "operating": {"speed_rpm": speed_rpm, "torque_Nm": torque_Nm},
        "bodies": {"bearing_stiffness_N_per_m": 4e8},
        "effects": {
            "mesh_stiffness": {"source": "analytic"},
            "wear": {"max_depth_um": 10.0},
            "backlash": {"initial_um": 50.0},
            "bearing_clearance": {"clearance_um": 10.0},
        },
        "solver": {"duration_s": 0.03, "discard_s": 0.02},
    }


PAIRS = {
    "23/47 shifted": ((23, 47), (0.2, -0.1), (12.5, 25.0)),
    "47/23 driver larger": ((47, 23), (-0.1, 0.2), (25.0, 12.5)),
}


def _at(raw, speed_rpm=None, torque_Nm=None):
    doc = copy.deepcopy(raw)
    if speed_rpm is not None:
        doc["operating"]["speed_rpm"] = speed_rpm
    if torque_Nm is not None:
        doc["operating"]["torque_Nm"] = torque_Nm
    return doc


@pytest.fixture
def counted(monkeypatch):
    """Calls of the stiffness source (the table's computation), counted."""
    calls = []
    real = sources.curve

    def curve(source, request):
        calls.append(source)
        return real(source, request)

    # the memo looks the source up at each call, simulate's default path holds its own name
    monkeypatch.setattr(sources, "curve", curve)
    monkeypatch.setattr(job_simulate, "curve", curve)
    return calls


@pytest.mark.parametrize("pair", PAIRS)
def test_runs_sharing_a_table_equal_their_own_runs(pair, counted):
    """Three speeds (one of them with a shorter window) and one design point: one table,
    and every result equal to its own simulate_point's, to the bit."""
    raw = _raw(*PAIRS[pair])
    values = {"wear": 7.5, "clearance": 20.0}
    runs = [
        (_at(raw, 900.0), "grouped", values, None),
        (_at(raw, 1800.0), "grouped", values, {"duration_s": 0.025, "discard_s": 0.015}),
        (_at(raw, 3600.0), "grouped", values, None),
    ]
    grouped = ds.simulate_runs(runs, K)
    assert len(counted) == 1
    counted.clear()
    for (r, name, v, sol), (y, resid) in zip(runs, grouped):
        y0, resid0 = ds.simulate_point(r, name, v, sol, K)
        assert np.array_equal(y, y0) and resid == resid0
    assert len(counted) == 3  # on their own: one table each


@pytest.mark.parametrize("pair", PAIRS)
@pytest.mark.parametrize("wear", [{"max_depth_um": 10.0}, {"phase": "mild"}, {"hours": 200.0}])
def test_the_speed_enters_the_table_request_only_through_running_hours(pair, wear):
    """The stiffness table's request (everything the curve depends on) is the same at two
    speeds for a wear depth or phase, and differs for running hours, whose depth counts the
    contacts (speed x time): the case the plan's and a speed sweep's shared tables rest on."""
    from gearwear.jobs.simulate import stiffness_input

    reqs = []

    def record(source, request):
        reqs.append(request)
        return sources.curve(source, request)

    for n in (900.0, 2700.0):
        raw = _at(_raw(*PAIRS[pair]), n)
        raw["effects"]["wear"] = dict(wear)
        stiffness_input(ds.scene_at(raw, "req", {}), tables=record)
    assert (reqs[0] == reqs[1]) is ("hours" not in wear)


@pytest.mark.parametrize("inner", ["threads", "this process"])
def test_speed_groups_one_task_per_design_point_and_torque(inner, counted):
    """2 torques x 3 speeds x 2 design points, submitted in the plan's order (speed outer):
    4 tasks and 4 tables; each run's future holds its own simulate_point result, and the
    progress counts every run once."""
    raw = _raw(*PAIRS["47/23 driver larger"])
    points = [{"wear": 3.0, "clearance": 5.0}, {"wear": 15.0, "clearance": 40.0}]
    tasks = []

    class Recording(ThreadPoolExecutor):
        def submit(self, fn, /, *args, **kwargs):
            tasks.append(fn)
            return super().submit(fn, *args, **kwargs)

    ticks = []
    with Recording(2) as pool:
        groups = dplan.SpeedGroups(pool if inner == "threads" else (lambda: None), ticks.append)
        futures = {}
        for n in (600.0, 1200.0, 2400.0):
            for T in (30.0, 90.0):
                for i, p in enumerate(points):
                    futures[(n, T, i)] = groups.submit(ds.simulate_point, _at(raw, n, T), "g", p, None, K)
        assert not tasks and not any(f.done() for f in futures.values())
        groups.flush()
        got = {key: f.result(timeout=300) for key, f in futures.items()}
    assert len(tasks) == (4 if inner == "threads" else 0)
    assert all(fn is ds.simulate_runs for fn in tasks)
    assert len(counted) == 4 and sum(ticks) == 12
    for (n, T, i), (y, resid) in got.items():
        y0, resid0 = ds.simulate_point(_at(raw, n, T), "g", points[i], None, K)
        assert np.array_equal(y, y0) and resid == resid0


def test_a_failed_group_fails_each_of_its_runs():
    """A run that raises fails every future of its group with its error; another group is
    not touched. In this process (one worker) the error leaves flush itself."""
    raw = _raw(*PAIRS["23/47 shifted"])
    with ThreadPoolExecutor(1) as pool:
        groups = dplan.SpeedGroups(pool)
        bad = [groups.submit(ds.simulate_point, _at(raw, n), "g", {"wear": -5.0}, None, K) for n in (600.0, 1200.0)]
        good = groups.submit(ds.simulate_point, _at(raw, 600.0), "g", {"wear": 5.0}, None, K)
        groups.flush()
        for f in bad:
            with pytest.raises(InputError, match="wear"):
                f.result(timeout=300)
        assert good.result(timeout=300)[0].size > 0
    groups = dplan.SpeedGroups(lambda: None)
    groups.submit(ds.simulate_point, _at(raw, 600.0), "g", {"wear": -5.0}, None, K)
    with pytest.raises(InputError, match="wear"):
        groups.flush()


def test_speed_groups_refuse_what_they_cannot_group():
    groups = dplan.SpeedGroups(None)
    with pytest.raises(TypeError):
        groups.submit(print, "not a run")


@pytest.mark.parametrize("pair", PAIRS)
def test_window_integrals_in_blocks_are_the_whole_sums(pair):
    """The exact window harmonics of a run with backlash and bearing clearance (no fold: every
    piece evaluated, the events' pieces split) in blocks of 257 and 1000 pieces against one pass over
    the whole window: the same integrals to roundoff; the dense derivatives in blocks are the
    same numbers as in one pass, to the bit."""
    from gearwear.dynamics import analysis as A
    from gearwear.dynamics.equations import _accelerations
    from gearwear.jobs.simulate import run

    raw = _raw(*PAIRS[pair])
    raw["solver"] = {"method": "dopri5", "duration_s": 0.05, "discard_s": 0.02}
    r = run(ds.scene_at(raw, "blocks", {"wear": 12.0, "clearance": 20.0})).result
    names = ["y_p", "F_m", "delta"]
    assert r.t_dense.size > 4 * 257
    whole, whole_mean = A.window_integrals(r, names, K, chunk=10**9)
    for chunk in (257, 1000):
        c, mean = A.window_integrals(r, names, K, chunk=chunk)
        for name in names:
            np.testing.assert_allclose(c[name], whole[name], rtol=1e-12, atol=1e-12 * np.max(np.abs(whole[name])))
            assert mean[name] == pytest.approx(whole_mean[name], rel=1e-12, abs=1e-15)
    F = A.dense_derivatives(r)
    Z = r.states_dense
    # the first and last rows may be an event's one-sided derivative instead (dense_derivatives)
    inner = slice(1, -1)
    assert np.array_equal(F[inner, 5:], _accelerations(r.model, r.t_dense, Z)[inner])
    assert np.array_equal(F[:, :5], Z[:, 5:10])
