"""RK4 kernel versus a plain C loop of the same model, adaptive cost per stage, and the
whole-process time of ``gearwear simulate``.

1. All-effects model: ``paper_pair(backlash_total_m=50e-6, clearance_total_m=20e-6,
   te_amplitude_m=2e-6, centre_distance="dynamic", n_table=256)`` (40 N m, 1200 rpm,
   f_m = 600 Hz), 256 RK4 steps per mesh period, 1 s (600 periods, 153600 steps). The
   numba kernel ``dynamics.kernels.rk4`` (called as ``dynamics.simulate`` calls it, but
   with a single output sample at t = 0, so only the integration loop is timed) against
   ``benchmarks/c_rk4/rk4.c`` (the same model and RK4 scheme written in plain C from the
   model equations, ``gcc -O3 -march=native``, loaded with ctypes). Correctness first:
   the final states must agree to ~1e-9 relative. Then interleaved timing rounds
   (numba, C, numba, C, ...), medians. The same for a 360-point table at 256 steps
   per period (the schedule splits steps at the table nodes: ns per sub-step).
   Also the numba kernel with nothing but time-varying stiffness (``paper_pair()``).
   At 40 N m the teeth never separate and the bearings stay in contact (the dead-zone
   tests run, their branches do not switch); so the agreement is also checked in the
   separating regime (5 N m, 6000 rpm, the same effects, 84 % of the time apart):
   15 mesh periods, before the chaotic response amplifies rounding differences.
2. Adaptive cost per stage: ``dynamics.simulate(model, 1.0, 0.5, method="dopri5")`` on
   the all-effects model and on the smooth default model; wall per right-hand-side
   evaluation = wall_s / (6 (accepted + rejected)) (event location and dense output
   included), next to RK4's wall per stage (ns per step / 4) of the same effect set.
3. Whole process: ``gearwear simulate paper-default --json`` cold (a fresh, empty
   NUMBA_CACHE_DIR: every kernel compiled; the stiffness-table cache $GEARWEAR_CACHE
   and the OS file cache are left as they are) and warm (the same cache dir again, median
   of 3), and warm ``gearwear simulate paper-default --out DIR`` (writes the PNGs).

Nothing is asserted (timings are reported, never checked). Writes
benchmarks/results/bench_rk4_vs_c.json.
"""

from __future__ import annotations

import ctypes
import datetime
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT) not in sys.path:  # run as a plain script from anywhere
    sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from gearwear.core.atomic import atomic_write_bytes  # noqa: E402
from gearwear.dynamics import kernels, paper_pair, simulate, static_equilibrium  # noqa: E402
from gearwear.dynamics.model import derived, rk4_schedule  # noqa: E402
from gearwear.dynamics.simulate import kernel_switches  # noqa: E402

OUT_JSON = HERE / "results" / "bench_rk4_vs_c.json"
C_SRC = HERE / "c_rk4" / "rk4.c"
GEARWEAR = Path(sys.executable).parent / "gearwear"

ALL_EFFECTS = dict(backlash_total_m=50e-6, clearance_total_m=20e-6, te_amplitude_m=2e-6, centre_distance="dynamic")
STEPS = 256  # RK4 steps per mesh period
DURATION = 1.0  # s simulated (600 mesh periods)
ROUNDS = 7  # interleaved timing rounds (numba, C), medians
PROC_RUNS = 3  # warm whole-process runs, median
SWITCH_PERIODS = 15  # separating-regime agreement check


# ------------------------------------------------------------------------------------
# the plain C loop
# ------------------------------------------------------------------------------------
def build_c(tmp: Path):
    """Compile rk4.c into tmp and load it; None (with a printed reason) if impossible."""
    gcc = shutil.which("gcc")
    if gcc is None:
        print("gcc not found: skipping the C comparison")
        return None, "gcc not found"
    so = tmp / "librk4.so"
    cmd = [gcc, "-O3", "-march=native", "-shared", "-fPIC", str(C_SRC), "-o", str(so), "-lm"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print(f"gcc failed, skipping the C comparison:\n{r.stderr}")
        return None, "gcc failed"
    lib = ctypes.CDLL(str(so))
    dp = ctypes.POINTER(ctypes.c_double)
    lib.rk4_run.argtypes = [dp, ctypes.c_int, dp, dp, dp, ctypes.c_long, ctypes.c_double, dp]
    lib.rk4_run.restype = ctypes.c_int
    ver = subprocess.run([gcc, "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    return lib, " ".join(cmd[:-4] + ["rk4.c"]) + f"  ({ver})"


def _ptr(a: np.ndarray):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


class Case:
    """One model at STEPS steps per period: the numba kernel call and the C call."""

    def __init__(self, model, steps: int = STEPS, duration: float = DURATION):
        self.model = model
        par = derived(model)[0]
        self.par = np.ascontiguousarray(par, dtype=float)
        self.p = tuple(par.tolist())
        self.sched = rk4_schedule(model, steps)
        hs, toff, kq, eq, dkq, deq, ends = self.sched
        self.hs = np.ascontiguousarray(hs, float)
        self.kq = np.ascontiguousarray(kq, float)
        self.eq = np.ascontiguousarray(eq, float)
        self.Q = int(hs.shape[0])
        Pt = 1.0 / model.mesh_frequency_Hz
        self.h = Pt / steps
        self.periods = int(round(duration * model.mesh_frequency_Hz))
        self.n_steps = self.periods * steps
        self.n_sub = self.periods * self.Q
        self.z0 = static_equilibrium(model)
        self.zlim = 1.0  # m: far beyond every displacement of this model
        self.sw = kernel_switches(model)
        self.t_out = np.array([0.0])

    def numba(self):
        out, counters, z = kernels.rk4(
            self.z0, self.h, self.n_steps, self.t_out, self.zlim, self.p, *self.sched, *self.sw
        )
        return z, counters

    def c(self, lib):
        z = self.z0.copy()
        st = lib.rk4_run(
            _ptr(self.par), self.Q, _ptr(self.hs), _ptr(self.kq), _ptr(self.eq), self.n_sub, self.zlim, _ptr(z)
        )
        return z, st


def agreement(zn: np.ndarray, zc: np.ndarray) -> dict:
    """Relative differences of the final states: per component (|dz_i| / |z_i|, max) and
    norm-wise for the displacements and the velocities."""
    d = np.abs(zc - zn)
    comp = d / np.maximum(np.abs(zn), 1e-300)
    return dict(
        max_component_rel=float(np.max(comp)),
        displacements_rel=float(np.linalg.norm(d[:5]) / np.linalg.norm(zn[:5])),
        velocities_rel=float(np.linalg.norm(d[5:10]) / max(np.linalg.norm(zn[5:10]), 1e-300)),
        worst_state=int(np.argmax(comp)),
    )


def switching_check(lib) -> dict | None:
    """Final-state agreement in the separating regime (the flank and bearing dead zones
    switch every period), over SWITCH_PERIODS mesh periods."""
    if lib is None:
        return None
    model = paper_pair(5.0, 6000.0, n_table=256, **ALL_EFFECTS)
    case = Case(model, duration=SWITCH_PERIODS / model.mesh_frequency_Hz)
    zn, _ = case.numba()
    zc, st = case.c(lib)
    return dict(
        model="all effects, 5 N m, 6000 rpm (separating)",
        periods=case.periods,
        c_status=int(st),
        agreement=agreement(zn, zc),
    )


def _clock(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def time_pair(case: Case, lib, rounds: int = ROUNDS):
    """Interleaved rounds (numba, C); medians in ns per sub-step."""
    tn, tc = [], []
    for _ in range(rounds):
        tn.append(_clock(case.numba))
        if lib is not None:
            tc.append(_clock(lambda: case.c(lib)))
    ns_n = statistics.median(tn) / case.n_sub * 1e9
    ns_c = statistics.median(tc) / case.n_sub * 1e9 if tc else None
    return ns_n, ns_c, tn, tc


def rk4_block(name: str, model, lib) -> dict:
    case = Case(model)
    zn, counters = case.numba()  # compiles (or loads the cache), and checks
    rec = dict(
        model=name,
        steps_per_period=STEPS,
        periods=case.periods,
        steps=case.n_steps,
        substeps_per_period=case.Q,
        substeps=case.n_sub,
        switches=str(case.sw),
        numba_counters=[int(c) for c in counters],
    )
    if lib is not None:
        zc, st = case.c(lib)
        rec["c_status"] = int(st)
        rec["agreement"] = agreement(zn, zc)
    ns_n, ns_c, tn, tc = time_pair(case, lib)
    rec.update(
        numba_ns_per_substep=ns_n,
        c_ns_per_substep=ns_c,
        ratio_numba_over_c=(ns_n / ns_c) if ns_c else None,
        numba_ns_per_step=ns_n * case.n_sub / case.n_steps,
        c_ns_per_step=(ns_c * case.n_sub / case.n_steps) if ns_c else None,
        numba_round_s=tn,
        c_round_s=tc,
    )
    return rec


def numba_only(name: str, model) -> dict:
    case = Case(model)
    case.numba()
    ts = [_clock(case.numba) for _ in range(ROUNDS)]
    ns = statistics.median(ts) / case.n_sub * 1e9
    return dict(
        model=name,
        switches=str(case.sw),
        substeps_per_period=case.Q,
        numba_ns_per_substep=ns,
        numba_ns_per_step=ns * case.n_sub / case.n_steps,
        numba_round_s=ts,
    )


def dopri_block(name: str, model, rk4_ns_per_step: float, runs: int = 3) -> dict:
    simulate(model, 4.0 / model.mesh_frequency_Hz, 0.0, method="dopri5")  # compile / load
    walls, res = [], None
    for _ in range(runs):
        res = simulate(model, DURATION, 0.5, method="dopri5")
        walls.append(res.wall_s)
    wall = statistics.median(walls)
    evals = 6 * (res.steps + res.rejected)
    ns_stage = wall / evals * 1e9
    rk4_stage = rk4_ns_per_step / 4.0
    return dict(
        model=name,
        wall_s=wall,
        wall_runs_s=walls,
        accepted=res.steps,
        rejected=res.rejected,
        events=res.events,
        rhs_evals=evals,
        ns_per_stage=ns_stage,
        rk4_ns_per_stage=rk4_stage,
        ratio_to_rk4_stage=ns_stage / rk4_stage,
    )


# ------------------------------------------------------------------------------------
# whole process
# ------------------------------------------------------------------------------------
def _proc(args, env) -> tuple[float, int, str]:
    t0 = time.perf_counter()
    r = subprocess.run([str(GEARWEAR), *args], capture_output=True, text=True, env=env, cwd=ROOT)
    return time.perf_counter() - t0, r.returncode, (r.stderr or "").strip()[-300:]


def process_block(tmp: Path) -> dict:
    if not GEARWEAR.exists():
        print(f"{GEARWEAR} not found: skipping the whole-process timing")
        return dict(skipped=f"{GEARWEAR} not found")
    cache = tmp / "numba-cache"
    cache.mkdir()
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    scene = "paper-default"
    wall, rc, err = _proc(["simulate", scene, "--json"], env)
    if rc != 0:  # the bare scene name may not be accepted: use the file
        shutil.rmtree(cache)
        cache.mkdir()
        scene = str(ROOT / "gearwear" / "data" / "paper-default.toml")
        wall, rc, err = _proc(["simulate", scene, "--json"], env)
    rec = dict(scene=scene, cold_s=wall, cold_rc=rc)
    if rc != 0:
        rec["error"] = err
        print(f"gearwear simulate failed (exit {rc}): {err}")
        return rec
    warm = [_proc(["simulate", scene, "--json"], env) for _ in range(PROC_RUNS)]
    rec.update(
        warm_s=statistics.median(w[0] for w in warm), warm_runs_s=[w[0] for w in warm], warm_rc=[w[1] for w in warm]
    )
    outs = []
    for i in range(PROC_RUNS):
        outs.append(_proc(["simulate", scene, "--out", str(tmp / f"out{i}")], env))
    rec.update(
        warm_out_s=statistics.median(w[0] for w in outs),
        warm_out_runs_s=[w[0] for w in outs],
        warm_out_rc=[w[1] for w in outs],
    )
    return rec


# ------------------------------------------------------------------------------------
def _f(x, fmt="{:.1f}"):
    return "-" if x is None else fmt.format(x)


def main() -> dict:
    tmp = Path(tempfile.mkdtemp(prefix="bench_rk4_c_"))
    try:
        lib, build = build_c(tmp)
        all256 = paper_pair(n_table=256, **ALL_EFFECTS)
        all360 = paper_pair(n_table=360, **ALL_EFFECTS)
        smooth = paper_pair()
        r256 = rk4_block("all effects, 256-point table", all256, lib)
        r360 = rk4_block("all effects, 360-point table", all360, lib)
        rsw = switching_check(lib)
        rstiff = numba_only("stiffness only (paper_pair())", smooth)
        d_all = dopri_block("all effects, 256-point table", all256, r256["numba_ns_per_step"])
        d_smooth = dopri_block("smooth default (paper_pair())", smooth, rstiff["numba_ns_per_step"])
        proc = process_block(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    print(f"C build: {build if lib is not None else 'skipped'}")
    print(
        f"RK4, {STEPS} steps per mesh period, {DURATION:g} s ({r256['periods']} periods), "
        f"interleaved medians of {ROUNDS} rounds:"
    )
    print(
        f"  {'case':34s} {'sub/per':>7s} {'numba ns':>9s} {'C ns':>7s} {'numba/C':>7s} "
        f"{'final-state agreement (max rel, per component)':s}"
    )
    for r in (r256, r360):
        ag = r.get("agreement")
        print(
            f"  {r['model']:34s} {r['substeps_per_period']:7d} {r['numba_ns_per_substep']:9.1f} "
            f"{_f(r['c_ns_per_substep']):>7s} {_f(r['ratio_numba_over_c'], '{:.2f}'):>7s} "
            f"{'-' if ag is None else format(ag['max_component_rel'], '.2e')}"
            + (
                ""
                if ag is None
                else f" (displacements {ag['displacements_rel']:.1e}, velocities {ag['velocities_rel']:.1e})"
            )
        )
    print(
        f"  {rstiff['model']:34s} {rstiff['substeps_per_period']:7d} "
        f"{rstiff['numba_ns_per_substep']:9.1f} {'-':>7s} {'-':>7s}"
    )
    print("  (ns per sub-step; with the 256-point table a sub-step is a step)")
    if rsw is not None:
        ag = rsw["agreement"]
        print(
            f"  agreement, {rsw['model']}, {rsw['periods']} periods: max rel "
            f"{ag['max_component_rel']:.2e} (displacements {ag['displacements_rel']:.1e}, "
            f"velocities {ag['velocities_rel']:.1e})"
        )
    print("dopri5 (1 s, 0.5 s discarded, rtol 1e-8): wall per right-hand-side evaluation")
    print(
        f"  {'case':34s} {'steps':>7s} {'rej':>5s} {'events':>6s} {'ns/stage':>8s} {'RK4 ns/stage':>12s} {'ratio':>6s}"
    )
    for d in (d_all, d_smooth):
        print(
            f"  {d['model']:34s} {d['accepted']:7d} {d['rejected']:5d} {d['events']:6d} "
            f"{d['ns_per_stage']:8.1f} {d['rk4_ns_per_stage']:12.1f} {d['ratio_to_rk4_stage']:6.2f}"
        )
    if "cold_s" in proc and "warm_s" in proc:
        print(
            f"gearwear simulate {Path(proc['scene']).name} --json: cold {proc['cold_s']:.2f} s "
            f"(empty NUMBA_CACHE_DIR), warm {proc['warm_s']:.2f} s (median of {PROC_RUNS}); "
            f"--out DIR (PNGs) warm {proc['warm_out_s']:.2f} s"
        )

    res = dict(
        date=datetime.datetime.now().isoformat(timespec="seconds"),
        machine=dict(
            platform=platform.platform(),
            processor=_cpu_name(),
            cpus=os.cpu_count(),
            python=platform.python_version(),
            numpy=np.__version__,
            numba=_numba_version(),
            load_avg=list(os.getloadavg()),
        ),
        c_build=build,
        rk4_all_256=r256,
        rk4_all_360=r360,
        switching_agreement=rsw,
        rk4_stiffness_only=rstiff,
        dopri5_all=d_all,
        dopri5_smooth=d_smooth,
        process=proc,
    )
    atomic_write_bytes(OUT_JSON, (json.dumps(res, indent=1) + "\n").encode())
    print(f"wrote {OUT_JSON.relative_to(ROOT)}")
    return res


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def _numba_version() -> str:
    import numba

    return numba.__version__


if __name__ == "__main__":
    main()
