"""What makes a sweep cost what its integrations cost (issue 27) changes no number.

* the stiffness table memo (gearwear.jobs.table_memo) returns the table a fresh build gives,
  reuses it where only the dynamics change (the speed) and builds anew where the table's
  inputs change (the torque);
* the folded derivatives of an affine right-hand side (analysis._affine_fold_states) give
  the window integral of every piece (fold=False) and the closed-form mean;
* the merged output times equal numpy's union1d;
* the accelerations from the known mesh force equal the model's right-hand side;
* a sweep's points equal single ``simulate`` runs of the same scenes, and its figures
  rendered on the workers are the bytes rendered in-process.

On the paper pair and on unequal profile-shifted pairs (20/45, x +0.4/+0.1; and the same
gears with the 45-tooth gear driving).
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from gearwear.jobs import simulate as job
from gearwear.jobs import sweep
from gearwear.jobs.table_memo import TableMemo
from gearwear.scene.files import load_scene_dict
from gearwear.scene.model import scene_from_dict
from gearwear.scene.overrides import apply_overrides

SHORT = ["solver.duration_s=0.06", "solver.discard_s=0.02"]
#: the shifted example's gears with the larger one driving
DRIVER_LARGER = ["pair.teeth=[45, 20]", "pair.profile_shift=[0.1, 0.4]", "pair.hub_radius_mm=[40.0, 15.0]"]
PAIRS = {
    "paper 30/30": ("paper-default", []),
    "shifted 20/45": ("examples/shifted_pair.toml", []),
    "shifted 45/20 (driver larger)": ("examples/shifted_pair.toml", DRIVER_LARGER),
}


def scene(which: str, sets: list[str] = ()):
    path, base = PAIRS[which]
    raw, name = load_scene_dict(path)
    return scene_from_dict(apply_overrides(raw, base + SHORT + list(sets)), name=name)


@pytest.mark.parametrize("which", list(PAIRS))
def test_memoised_table_is_the_fresh_table(which):
    memo = TableMemo()
    a = job.stiffness_input(scene(which), tables=memo)
    fresh = job.stiffness_input(scene(which, ["operating.speed_rpm=2345"]))
    b = job.stiffness_input(scene(which, ["operating.speed_rpm=2345"]), tables=memo)  # only the speed differs
    assert (memo.hits, memo.misses) == (1, 1)
    for x in (a, b):
        assert np.array_equal(x.phi, fresh.phi) and np.array_equal(x.k, fresh.k) and np.array_equal(x.e, fresh.e)
        assert x.mean_N_per_m == fresh.mean_N_per_m and x.periods == fresh.periods
    assert not b.k.flags.writeable  # shared with later points: nobody may write into it
    c = job.stiffness_input(scene(which, ["operating.torque_Nm=17"]), tables=memo)  # the load sharing changes
    assert memo.misses == 2 and not np.array_equal(c.k, a.k)


@pytest.mark.parametrize("which", list(PAIRS))
@pytest.mark.parametrize("te", [False, True])
def test_folded_derivatives_equal_every_piece(which, te):
    """The affine fold with the derivatives folded too equals the unfolded window integral
    (each piece's own right-hand side) to rounding, complex coefficients and means."""
    from gearwear.dynamics.analysis import _affine_rhs, window_integrals

    sets = ["effects.transmission_error={}"] if te else []
    r = job.run(scene(which, sets)).result
    assert _affine_rhs(r.model) and r.n_periods >= 2
    names = ["y_p", "x_p", "delta", "F_m"]
    (cf, mf), (cr, mr) = window_integrals(r, names, 10), window_integrals(r, names, 10, fold=False)
    for name in names:
        scale = np.max(np.abs(cr[name]))
        assert np.max(np.abs(cf[name] - cr[name])) <= 1e-12 * scale, name
        assert mf[name] == pytest.approx(mr[name], rel=1e-12, abs=1e-12 * scale)


def test_folded_mean_of_a_constant_stiffness_is_the_static_deflection():
    """A constant mesh spring at rest in its static equilibrium: the exact window mean of F_m
    is the transmitted force T_p / R_p (closed form), of delta F / k."""
    import math

    from gearwear.dynamics.analysis import window_integrals

    sc = scene("shifted 20/45", ["effects.mesh_stiffness={source='constant'}"])
    r = job.run(sc).result
    coeffs, means = window_integrals(r, ["F_m", "delta"], 4)
    F = sc.operating.torque_Nm / sc.pair.gears[0].base_radius_m
    assert means["F_m"] == pytest.approx(F, rel=1e-9)
    assert means["delta"] == pytest.approx(F / r.model.k_mean, rel=1e-9)
    assert np.max(np.abs(coeffs["F_m"])) <= 1e-9 * F and math.isfinite(means["F_m"])


def test_merged_times_are_union1d():
    from gearwear.dynamics.simulate import merge_times

    rng = np.random.default_rng(7)
    for _ in range(100):
        t_uni = 0.3 + 1e-4 * np.arange(rng.integers(2, 2000))
        nodes = np.sort(rng.uniform(t_uni[0], t_uni[-1], rng.integers(0, 400)))
        nodes = np.sort(np.r_[nodes, nodes[:2]])  # a node twice (both ends of a table period)
        t_out, uni = merge_times(t_uni, nodes)
        want = np.union1d(t_uni, nodes)
        assert np.array_equal(t_out, want) and np.array_equal(uni, np.searchsorted(want, t_uni))


@pytest.mark.parametrize(
    "which, sets",
    [
        ("shifted 20/45", []),
        ("shifted 45/20 (driver larger)", ["effects.transmission_error={}"]),
        ("paper 30/30", ["effects.backlash={initial_um=40}", "effects.bearing_clearance={clearance_um=10}"]),
    ],
)
def test_accelerations_from_the_force_are_the_right_hand_side(which, sets):
    from gearwear.dynamics.analysis import accelerations_at
    from gearwear.dynamics.equations import _accelerations

    r = job.run(scene(which, sets)).result
    fast = accelerations_at(r.model, r.t, r.states, r.signals["F_m"])
    a = _accelerations(r.model, r.t, r.states)
    assert np.array_equal(fast["a_y_p"], a[:, 0]) and np.array_equal(fast["a_q"], a[:, 4])
    assert np.array_equal(fast["a_delta"], accelerations_at(r.model, r.t, r.states)["a_delta"])


def test_sweep_points_are_single_runs_and_figures_the_same_bytes(tmp_path):
    """A sweep on two worker processes (memoised tables, single-thread BLAS, figures on the
    workers) gives each point's summary exactly as a single run of its scene, and the PNGs
    rendered in-process."""
    raw, name = load_scene_dict("examples/shifted_pair.toml")
    fixed = DRIVER_LARGER + SHORT
    axes = [sweep.parse_axis("operating.speed_rpm=1200:2400:3")]
    (tmp_path / "pool").mkdir()
    with sweep.make_executor(2) as ex:
        rows = sweep.sweep(raw, name, axes, fixed, executor=ex, progress=False, warm_figures_after=True)
        files = sweep.write(axes, rows, tmp_path / "pool", {}, executor=ex)
    for point, row in zip(sweep.grid(axes), rows):
        one = job.run(scene_from_dict(apply_overrides(raw, sweep.point_sets(point, fixed)), name=name)).summary()
        for key in ("harmonics", "mean", "ac_rms", "peak_to_peak", "condition_indicators", "steps"):
            assert row[key] == one[key], key
    (tmp_path / "here").mkdir()
    here = sweep.write(axes, rows, tmp_path / "here", {})
    assert [p.name for p in files] == [p.name for p in here]
    for a, b in zip(files, here):
        if a.suffix == ".png":
            assert a.read_bytes() == b.read_bytes(), a.name
    assert len(pickle.dumps(rows[0])) < 20_000  # a summary, not arrays, comes back
