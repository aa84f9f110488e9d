"""A long user stiffness table on the RK4 step grid: cost per simulated second against the
plain C RK4 loop, and the F_m harmonic error against a converged reference.

Model: the user-table example (``examples/user_table``: the paper pair, a smooth closed-form
k and e sampled at 4096 rows per mesh period, explicit inertias and damping; 1200 rpm,
f_m = 600 Hz), RK4 at 256 steps per mesh period, 1 s simulated (153600 steps).

Timed in one run, interleaved rounds, minimum of the rounds (the machine is shared):

* ``schedule``: ``dynamics.table_time.rk4_schedule`` (one table period, built once per run);
* ``kernel``: ``dynamics.kernels.rk4`` with one output sample (the integration loop alone,
  as ``bench_rk4_vs_c.py`` times it);
* ``simulate``: ``dynamics.simulate(model, 1.0, 0.5, method="rk4")`` end to end (stability
  check, static equilibrium, schedule, the dense output at every table node in the kept
  window, signals), without and with ``dense`` output;
* ``kernel_all_effects``: the same table with 50 um backlash, 20 um bearing clearance and
  the dynamic centre distance (the model the C loop integrates; final states compared);
* ``C``: ``benchmarks/c_rk4/rk4.c`` (every effect's code on, ``gcc -O3 -march=native``) on
  the same parameters over a 256-sub-step-per-period schedule: the cost of 256 steps.

``dopri5``: ``simulate(..., method="dopri5", rtol=1e-8, dense=False)`` wall (kernel) for
the same second: its steps end on every table node (measured; not changed here).

``before``: the schedule that splits every step at every table node inside it (the old
contract; ``SPLIT_WEIGHT = -1``, no budget), timed in the same run.

Accuracy: F_m harmonics 1-10 (exact window integrals) of the 256-step run against RK4 at
2048 steps per mesh period with every break split, which agrees with dopri5 at rtol 1e-11;
relative error per harmonic (harmonics above 1 % of the largest). The stated kink defect
(``table_time.kink_defect``) of the breaks left inside steps, per mesh period, relative to
the mean mesh impulse F_s T_m.

Writes benchmarks/results/bench_user_table.json. Nothing is asserted."""

from __future__ import annotations

import datetime
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

import numpy as np  # noqa: E402
from bench_rk4_vs_c import Case, agreement, build_c  # noqa: E402

from gearwear.core.atomic import atomic_write_bytes  # noqa: E402
from gearwear.dynamics import simulate  # noqa: E402
from gearwear.dynamics import table_time as tt  # noqa: E402
from gearwear.jobs import simulate as sj  # noqa: E402
from gearwear.scene.files import load_scene_dict  # noqa: E402
from gearwear.scene.model import scene_from_dict  # noqa: E402

OUT_JSON = HERE / "results" / "bench_user_table.json"
STEPS = 256
DURATION = 1.0
ROUNDS = 5


def user_table_model():
    data, name = load_scene_dict(ROOT / "examples" / "user_table" / "scene.toml")
    sc = scene_from_dict(data, name=name)
    return sj.build_model(sc, sj.stiffness_input(sc))


class _AllSplit:
    """The old schedule: every break of the table a sub-step end."""

    def __enter__(self):
        self.saved = tt.SPLIT_WEIGHT, tt.SPLIT_MAX_PER_STEP
        tt.SPLIT_WEIGHT, tt.SPLIT_MAX_PER_STEP = -1.0, 10**9

    def __exit__(self, *exc):
        tt.SPLIT_WEIGHT, tt.SPLIT_MAX_PER_STEP = self.saved


def _clock(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _rel(h, ref) -> float:
    keep = ref > 0.01 * ref.max()
    return float(np.max(np.abs(h[keep] - ref[keep]) / ref[keep]))


def main() -> dict:
    model = user_table_model()
    fm = model.mesh_frequency_Hz
    tmp = Path(tempfile.mkdtemp(prefix="bench_user_table_"))
    try:
        lib, build = build_c(tmp)
        new = Case(model, STEPS, DURATION)
        with _AllSplit():
            old = Case(model, STEPS, DURATION)
        # the C loop on the new schedule: 256 sub-steps per period, the cost of the step count
        assert new.Q == STEPS, new.Q
        c_case = new
        new.numba(), old.numba()
        # the same table with every effect of the C loop on (its own model): same-model ratio
        model_all = model.with_(backlash_half_m=25e-6, bearing_half_clearance_m=10e-6, centre_distance="dynamic")
        all_new = Case(model_all, STEPS, DURATION)
        with _AllSplit():
            all_old = Case(model_all, STEPS, DURATION)
        z_all, _ = all_new.numba()
        all_old.numba()
        agree = agreement(z_all, all_new.c(lib)[0]) if lib is not None else None
        sim = lambda dense: simulate(model, DURATION, 0.5, method="rk4", steps_per_mesh_period=STEPS, dense=dense)  # noqa: E731

        def sim_old(dense):
            with _AllSplit():
                return sim(dense)

        sim(True), sim_old(True)
        t = {
            k: []
            for k in (
                "c",
                "kernel",
                "kernel_before",
                "kernel_all_effects",
                "kernel_all_effects_before",
                "schedule",
                "schedule_before",
                "sim",
                "sim_dense",
                "sim_before",
                "sim_dense_before",
            )
        }
        for _ in range(ROUNDS):
            if lib is not None:
                t["c"].append(_clock(lambda: c_case.c(lib)))
            t["kernel"].append(_clock(new.numba))
            t["kernel_before"].append(_clock(old.numba))
            t["kernel_all_effects"].append(_clock(all_new.numba))
            t["kernel_all_effects_before"].append(_clock(all_old.numba))
            t["schedule"].append(_clock(lambda: tt.rk4_schedule(model, STEPS)))
            with _AllSplit():
                t["schedule_before"].append(_clock(lambda: tt.rk4_schedule(model, STEPS)))
            t["sim"].append(_clock(lambda: sim(False)))
            t["sim_dense"].append(_clock(lambda: sim(True)))
            t["sim_before"].append(_clock(lambda: sim_old(False)))
            t["sim_dense_before"].append(_clock(lambda: sim_old(True)))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    best = {k: (min(v) if v else None) for k, v in t.items()}
    c = best["c"]
    ratio = {k: (v / c if (c and v) else None) for k, v in best.items()}

    # accuracy
    D, Dd = 0.2, 0.1
    r = simulate(model, D, Dd, method="rk4", steps_per_mesh_period=STEPS)
    h = r.harmonics("F_m")
    with _AllSplit():
        ref = simulate(model, D, Dd, method="rk4", steps_per_mesh_period=8 * STEPS).harmonics("F_m")
        h_old = simulate(model, D, Dd, method="rk4", steps_per_mesh_period=STEPS).harmonics("F_m")
    dp = simulate(model, D, Dd, method="dopri5", rtol=1e-11).harmonics("F_m")
    # dopri5 on the same table (its steps end on every table node: measured, not changed)
    simulate(model, 4 / fm, 0.0, method="dopri5")
    d_walls, d_res = [], None
    for _ in range(2):
        d_res = simulate(model, DURATION, 0.5, method="dopri5", rtol=1e-8, dense=False)
        d_walls.append(d_res.wall_s)
    dopri = dict(
        rtol=1e-8,
        kernel_wall_s=min(d_walls),
        ratio_to_c=(min(d_walls) / c) if c else None,
        accepted_steps=d_res.steps,
        rejected=d_res.rejected,
        steps_per_mesh_period=d_res.steps / (DURATION * fm),
    )
    Sk, Se = tt.kink_defect(model, STEPS)
    dmax = float(np.max(np.abs(r.signals["delta"])) + np.max(np.abs(model.e_table)))  # >= max|delta - e|
    defect = float(np.sum(np.abs(Sk)) * dmax + np.max(model.k_table) * np.sum(np.abs(Se)))
    acc = dict(
        F_m_harmonics_N=h.tolist(),
        reference_F_m_harmonics_N=ref.tolist(),
        rel_error_vs_reference=_rel(h, ref),
        rel_error_before_vs_reference=_rel(h_old, ref),
        reference_vs_dopri5_rtol_1e11=_rel(ref, dp),
        kink_defect_per_period_Ns=defect,
        kink_defect_rel_to_mean_impulse=defect / (abs(model.F_s) / fm),
    )
    res = dict(
        date=datetime.datetime.now().isoformat(timespec="seconds"),
        load_avg=list(os.getloadavg()),
        c_build=build,
        model="examples/user_table (4096 rows, k and e), 1200 rpm",
        steps_per_mesh_period=STEPS,
        simulated_s=DURATION,
        substeps_per_period=dict(now=new.Q, before=old.Q),
        all_effects_model="the same table with 50 um backlash, 20 um bearing clearance, dynamic centre distance "
        "(the C loop's model)",
        all_effects_agreement_numba_vs_c=agree,
        seconds_per_simulated_second_min_of_rounds=best,
        ratio_to_c=ratio,
        rounds_s=t,
        accuracy=acc,
        dopri5=dopri,
    )
    print(f"user table, 4096 rows, {STEPS} steps per mesh period, 1 s simulated; min of {ROUNDS} rounds")
    print(f"  sub-steps per period: now {new.Q}, before {old.Q}")
    for k in (
        "c",
        "kernel",
        "kernel_before",
        "kernel_all_effects",
        "kernel_all_effects_before",
        "schedule",
        "schedule_before",
        "sim",
        "sim_before",
        "sim_dense",
        "sim_dense_before",
    ):
        v = best[k]
        rk = ratio[k]
        print(f"  {k:18s} {'-' if v is None else f'{v:.4f} s':>10s}   x C {'-' if rk is None else f'{rk:.2f}'}")
    print(
        f"  F_m harmonics 1-10 vs converged: {acc['rel_error_vs_reference']:.2e} "
        f"(before {acc['rel_error_before_vs_reference']:.2e}); "
        f"reference vs dopri5 {acc['reference_vs_dopri5_rtol_1e11']:.1e}; stated kink defect "
        f"{acc['kink_defect_rel_to_mean_impulse']:.1e} of the mean impulse per period"
    )
    print(
        f"  dopri5 rtol 1e-8 (kernel, 1 s): {dopri['kernel_wall_s']:.3f} s, x C "
        f"{'-' if dopri['ratio_to_c'] is None else format(dopri['ratio_to_c'], '.1f')}, "
        f"{dopri['steps_per_mesh_period']:.0f} steps per mesh period (one per table node)"
    )
    atomic_write_bytes(OUT_JSON, (json.dumps(res, indent=1) + "\n").encode())
    print(f"wrote {OUT_JSON.relative_to(ROOT)}")
    return res


if __name__ == "__main__":
    main()
