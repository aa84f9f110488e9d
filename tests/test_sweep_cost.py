"""What makes a sweep cost what its integrations cost (issue 27) changes no number.

* the stiffness table memo (gearwear.jobs.table_memo) returns the table a fresh build gives,
  reuses it where only the dynamics change (the speed) and builds anew where the table's
  inputs change (the torque);
* the folded derivatives of an affine right-hand side (analysis._affine_fold_states) give
  the window integral of every piece (fold=False) and the closed-form mean;
* the merged output times equal numpy's union1d;
* the accelerations from the known mesh force equal the model's right-hand side;
* a sweep's points equal single ``simulate`` runs of the same scenes, and its figures
  rendered on the workers are the bytes rendered in-process;
* the reordered sums of a point's post-processing (the period sums read once, G . z' and
  G . a without the (N, 5) products, the indicators' moments taken once) are the
  straightforward numpy expressions to the bit, and the indicators are their definitions;
* the console script (which ends without the interpreter's teardown) prints and writes
  everything a sweep has.

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


@pytest.mark.parametrize("which", list(PAIRS))
@pytest.mark.parametrize("energy", [False, True])
def test_period_sums_are_the_reshaped_sums(which, energy):
    """The dense states summed over the periods (start and end of every piece) read once are
    the two reshape-sums to the bit, on the kernel's own output (with the energy
    accumulators the states are a strided view)."""
    from gearwear.dynamics.analysis import _period_pattern, period_sums
    from gearwear.dynamics.simulate import simulate

    sc = scene(which)
    s = dict(sc.solver)
    stiff = job.stiffness_input(sc)
    r = simulate(job.build_model(sc, stiff), s["duration_s"], s["discard_s"], track_energy=energy)
    Z, R = r.states_dense, r.n_periods
    Pt = _period_pattern(r.t_dense, R)
    assert Pt and R >= 2 and (Z.flags.c_contiguous != energy)
    S0, S1 = period_sums(Z, R, Pt)
    assert np.array_equal(S0, Z[:-1].reshape(R, Pt, 10).sum(axis=0))
    assert np.array_equal(S1, Z[1:].reshape(R, Pt, 10).sum(axis=0))


@pytest.mark.parametrize(
    "which, sets",
    [
        ("paper 30/30", []),
        ("shifted 20/45", ["effects.transmission_error={}"]),
        ("shifted 45/20 (driver larger)", ["effects.backlash={initial_um=40}"]),
        (
            "shifted 20/45",
            ["effects.centre_distance={coupling='dynamic'}", "effects.bearing_clearance={clearance_um=10}"],
        ),
    ],
)
def test_mesh_rates_and_a_delta_are_the_plain_sums(which, sets):
    """delta' = G . z' (mesh_geometry) and a_delta = G . a (analysis.accelerations_at) equal
    ``np.sum(G * x, axis=-1)`` to the bit, for the static coupling (G constant, a broadcast
    view) and the dynamic one (G per sample)."""
    from gearwear.dynamics.analysis import accelerations_at
    from gearwear.dynamics.equations import _accelerations, mesh_geometry

    r = job.run(scene(which, sets)).result
    Z = r.states
    _, ddelta, _, G, Gb, _, _ = mesh_geometry(r.model, Z)
    assert G.shape == (len(Z), 5) and Gb.shape == (len(Z), 4)
    assert np.array_equal(ddelta, np.sum(np.array(G) * Z[:, 5:10], axis=-1))
    a = _accelerations(r.model, r.t, Z)
    assert np.array_equal(accelerations_at(r.model, r.t, Z)["a_delta"], np.sum(np.array(G) * a, axis=1))


@pytest.mark.parametrize("which", list(PAIRS))
def test_indicators_are_their_definitions(which):
    """The indicators of a simulated point (moments taken once for all of them) are the
    definitions of dynamics.indicators written out with numpy, to the bit: mean, ac_rms =
    sqrt(mean(x_ac^2)), kurtosis = mean(x_ac^4) / mean(x_ac^2)^2, crest factor = max|x_ac| /
    ac_rms, peak-to-peak, and FM0 = peak-to-peak / the sum of the mesh-harmonic bins."""
    from gearwear.dynamics import indicators as ind
    from gearwear.dynamics.analysis import acceleration_signals

    path, base = PAIRS[which]
    raw, name = load_scene_dict(path)
    sc = scene_from_dict(apply_overrides(raw, base + ["solver.duration_s=0.2", "solver.discard_s=0.05"]), name=name)
    r = job.run(sc).result
    f_shaft, z = job.shaft_frequency_Hz(sc)
    n = (r.n_periods // z) * z * int(round(r.fs_Hz / r.fm_Hz))
    assert n > 0
    for x in (acceleration_signals(r)["a_delta"][-n:], r.signals["F_m"][-n:]):
        g = ind.gear_indicators(x, r.fs_Hz, r.fm_Hz, f_shaft)
        ac = x - np.mean(x)
        rms = np.sqrt(np.mean(ac**2))
        assert g.mean == float(np.mean(x)) and g.ac_rms == float(rms) == ind.ac_rms(x)
        assert g.kurtosis == float(np.mean(ac**2 * ac**2) / np.mean(ac**2) ** 2) == ind.kurtosis(x)
        assert g.crest_factor == float(np.max(np.abs(ac)) / rms) == ind.crest_factor(x)
        assert g.peak_to_peak == float(np.max(x) - np.min(x))
        A = 2 * np.abs(np.fft.rfft(x)) / x.size
        R = n // (z * int(round(r.fs_Hz / r.fm_Hz)))
        bins = z * R * np.arange(1, g.FM0_FM4_mesh_harmonics + 1)
        if bins[-1] == x.size // 2:  # the Nyquist bin is single-sided already
            A[-1] /= 2
        assert g.FM0 == pytest.approx(g.peak_to_peak / np.sum(A[bins]), rel=1e-13)
        assert g.FM0 == ind.fm0(x, r.fs_Hz, r.fm_Hz, f_shaft) and g.FM4 == ind.fm4(x, r.fs_Hz, r.fm_Hz, f_shaft)


def test_console_script_sweep_prints_and_writes_everything(tmp_path):
    """The ``gearwear`` console script ends with os._exit after its exit handlers
    (cli.app.quick_exit): its JSON (piped, so buffered) arrives whole, the status is 0, every
    file it names exists, the points are the in-process sweep's and the figures its bytes; a
    bad input still exits 2 with its one line."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    gw = str(Path(sys.executable).with_name("gearwear"))
    raw, name = load_scene_dict("examples/shifted_pair.toml")
    fixed = DRIVER_LARGER + SHORT
    axes = [sweep.parse_axis("operating.speed_rpm=1500:2500:2")]
    sets = [x for f in fixed for x in ("--set", f)]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}  # stdout buffered: flushed at exit
    cmd = [gw, "sweep", "examples/shifted_pair.toml", *sets, "--set", "operating.speed_rpm=1500:2500:2"]
    r = subprocess.run(
        [*cmd, "--workers", "2", "--json", "--out", str(tmp_path / "o")], capture_output=True, text=True, env=env
    )
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["files"] and all(Path(f).is_file() and Path(f).stat().st_size > 0 for f in out["files"])
    rows = [sweep.run_point(raw, name, p, fixed) for p in sweep.grid(axes)]
    for got, want in zip(out["points"], rows):
        for key in ("harmonics", "mean", "ac_rms", "peak_to_peak", "steps"):
            assert got[key] == json.loads(json.dumps(want[key])), key
    # its figures (rendered on its workers, the largest first) are the bytes rendered here
    (tmp_path / "here").mkdir()
    for f in sweep.write(axes, rows, tmp_path / "here", {}):
        if f.suffix == ".png":
            assert f.read_bytes() == (tmp_path / "o" / f.name).read_bytes(), f.name
    bad = subprocess.run([*cmd[:-2], "--set", "operating.speed_rpm=-5:10:2"], capture_output=True, text=True, env=env)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "speed_rpm" in bad.stderr
