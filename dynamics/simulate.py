"""Time integration driver: builds the specialised kernel call, samples on a uniform grid.

Output grid: the discarded transient is rounded *up* to a whole number of mesh periods
and the kept window is a whole number ``M`` of mesh periods (``M = floor((duration -
discard) f_m)``), sampled at ``samples_per_mesh_period`` points per period (default
``steps_per_mesh_period``), so the mesh harmonics fall exactly on FFT bins. The RK4
output is the integrator state at the grid points (cubic Hermite between steps when the
grid is not a subset of the steps); the adaptive output is its dense output.

Tables over several mesh periods (``GearDynamics.table_periods = L > 1``, a tooth fault):
the excitation repeats every L mesh periods, so a spectrum that resolves the shaft
orders (sidebands ``f_m +- n f_m / L``) needs a kept window of a whole number of *table*
periods. ``simulate`` keeps whole mesh periods as always; pass the duration through
:func:`round_to_table_periods` (rounds it up so that the kept window is whole table
periods) and check ``SimResult.whole_table_periods``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from gearwear.core.validation import Field, InputError, fail, fail_text

from . import kernels
from .equations import has_flank_law, mesh_state
from .equilibrium import static_equilibrium
from .linear import max_linear_rate
from .model import STATE_NAMES, GearDynamics
from .params import derived
from .table_time import rk4_schedule, table_node_times

__all__ = ["SimResult", "simulate", "kernel_switches", "compute_signals", "round_to_table_periods"]

ENERGY_NAMES = ("W_in", "D", "W_k", "W_e")


@dataclass
class SimResult:
    t: np.ndarray  # sample times (s), uniform, whole mesh periods
    signals: dict  # name -> array on t
    fm_Hz: float
    fs_Hz: float
    steps: int  # accepted steps
    rejected: int  # dopri5: rejected steps; rk4: sub-steps at table nodes
    events: int  # located switching events (adaptive only)
    wall_s: float  # integration wall time (compilation excluded)
    compile_s: float  # compilation / cache load in this call (0 if warm)
    separation_fraction: float | None  # fraction of samples with |s| <= b; None: the model has no
    # backlash dead zone (a two-sided spring cannot separate)
    backside_fraction: float  # back-flank contact: fraction of samples with s < -b (backlash),
    # or with a negative mesh force (two-sided spring)
    bearing_contact_fraction: dict  # "pinion"/"gear": fraction with |y| > b_b or |x| > b_b
    method: str
    states: np.ndarray  # (N, 10) sampled states
    energy: dict | None  # accumulated W_in, D, W_k, W_e on t (track_energy)
    n_periods: int
    stats: dict  # name -> dict(mean, ac_rms, p2p): mean, RMS about the mean, peak-to-peak
    periodic_with: int  # smallest p (mesh periods) with a p-periodic tail, 0 if none;
    # with table_periods L > 1 only multiples of L are tried
    z_end: np.ndarray  # final state
    switches: tuple = field(default=())
    model: GearDynamics | None = None  # the model that produced it (exact harmonics)
    t_dense: np.ndarray | None = None  # the sample times plus the table nodes and the window end
    states_dense: np.ndarray | None = None  # (len(t_dense), 10) states there
    window_events: np.ndarray | None = None  # (E, kernels.EV_COLS) the switching events dopri5
    # located in the window: time, state, derivative
    # before and after (analysis.event_pieces)
    _harmonics_memo: dict = field(default_factory=dict, repr=False)
    table_periods: int = 1  # mesh periods per table period (model.table_periods)

    @property
    def event_times(self) -> np.ndarray:
        """Times (s) of the switching events located inside the window (dopri5; none for RK4)."""
        if self.window_events is None:
            return np.empty(0)
        return self.window_events[:, kernels.EV_T].copy()

    @property
    def whole_table_periods(self) -> bool:
        """The kept window holds a whole number of table periods (``n_periods`` is a
        multiple of ``table_periods``): a DFT of it resolves the table's (shaft) orders
        on exact bins. Always true for ``table_periods = 1``."""
        return self.n_periods % self.table_periods == 0

    def harmonics(self, name: str = "F_m", n: int = 10) -> np.ndarray:
        """Amplitudes of the mesh harmonics k f_m, k = 1..n, of signal ``name``: exact
        Fourier integrals over the whole window (:func:`dynamics.analysis.window_harmonics`),
        free of the aliasing that sampling a linear stiffness table's kinks causes."""
        return self.harmonics_of([name], n)[name]

    def harmonics_of(self, names, n: int = 10) -> dict:
        """``harmonics`` for several signals in one pass over the window."""
        from .analysis import harmonics

        if self.model is None or self.t_dense is None:
            return {name: harmonics(self.signals[name], self.fs_Hz, self.fm_Hz, n) for name in names}
        self._window_pass(names, n)
        return {name: self._harmonics_memo[(name, n)].copy() for name in names}

    def means_of(self, names, n: int = 10) -> dict:
        """Exact window means (1 / T) int x dt of signals: the k = 0 term of the harmonics' pass
        (sample means of a signal with jumps, such as F_m across a table's contact edges, are
        off by about a jump over the samples per period); sample means without dense output."""
        if self.model is None or self.t_dense is None:
            return {name: float(np.mean(self.signals[name])) for name in names}
        self._window_pass(names, n)
        return {name: self._harmonics_memo[(name, "mean")] for name in names}

    def _window_pass(self, names, n: int) -> None:
        """Harmonics 1..n and the mean of ``names`` from one window integral, memoised."""
        from .analysis import window_integrals

        missing = [
            name
            for name in names
            if (name, n) not in self._harmonics_memo or (name, "mean") not in self._harmonics_memo
        ]
        if missing:
            coeffs, means = window_integrals(self, missing, n)
            for name in missing:
                self._harmonics_memo[(name, n)] = np.abs(coeffs[name])
                self._harmonics_memo[(name, "mean")] = means[name]

    def spectrum(self, name: str = "F_m"):
        """Single-sided amplitude spectrum (f, A) of signal ``name``."""
        from .analysis import spectrum

        return spectrum(self.signals[name], self.fs_Hz)


def kernel_switches(model: GearDynamics, track_energy: bool = False) -> tuple:
    """The effect switches as kernel arguments: ``True`` (present) or ``None`` (absent)."""
    on = lambda b: True if b else None  # noqa: E731
    return (
        on(model.tvms),
        on(has_flank_law(model)),
        on(model.bearing_half_clearance_m is not None),
        on(model.te_excitation),
        on(model.centre_distance == "dynamic"),
        on(track_energy),
    )


def _gidx(model: GearDynamics) -> np.ndarray:
    idx = []
    if has_flank_law(model):
        idx += [0, 1]
    if model.bearing_half_clearance_m is not None:
        idx += list(range(2, 10))
    return np.array(idx, dtype=np.int64)


_WARM: set = set()
OUTPUT_BYTES_PER_SAMPLE_STATE = 8 * 40  # states plus the ~25 derived signal arrays, float64


class SolverError(InputError):
    """The integration could not finish; the message says what was happening."""


def rk4_stability_number(
    model: GearDynamics, steps_per_mesh_period: int, k: float | None = None
) -> tuple[float, float]:
    """(h * omega_max, omega_max): omega_max is the largest |eigenvalue| (rad/s) of the
    linearised first-order system at the largest table stiffness (mesh and bearing
    springs engaged, both dampers on; ``k``: at this mesh stiffness instead); RK4's
    stability region reaches about 2.8 on the imaginary axis and 2.8 on the negative real
    axis, so h omega_max <= 2.5 leaves a margin."""
    if k is None:
        k = float(np.max(model.k_table)) if model.tvms else model.k_mean
    w = max_linear_rate(model, k)
    return w / (model.mesh_frequency_Hz * steps_per_mesh_period), w


def resolve_method(model: GearDynamics, method: str) -> str:
    """The integrator "auto" stands for: RK4 when there is neither backlash (a flank law)
    nor bearing clearance, else dopri5."""
    if method != "auto":
        return method
    nonsmooth = has_flank_law(model) or model.bearing_half_clearance_m is not None
    return "dopri5" if nonsmooth else "rk4"


def check_rk4_stable(
    model: GearDynamics, steps_per_mesh_period: int, k: float | None = None, bound: bool = False
) -> None:
    """One-line InputError if RK4 is unstable at this step (h omega_max > 2.5,
    :func:`rk4_stability_number`). ``k``: the mesh stiffness of the linearisation instead of
    the table's largest; ``bound``: omega_max is a lower bound (a model without its mesh
    spring), so the step count named is a lower bound too."""
    hw, w = rk4_stability_number(model, steps_per_mesh_period, k)
    if hw > 2.5:
        n_min = int(math.ceil(w / (2.5 * model.mesh_frequency_Hz)))
        eq = ">=" if bound else "="
        raise fail_text(
            "steps_per_mesh_period",
            f"steps_per_mesh_period = {steps_per_mesh_period}: RK4 is unstable "
            f"here (h omega_max {eq} {hw:.3g} > 2.5, omega_max {eq} {w:.4g} rad/s of the "
            f"linearised model); use >= {n_min} steps per mesh period or "
            f"method = dopri5",
            steps_per_mesh_period,
        )


#: |h lambda| at which Dormand-Prince 5(4) leaves its stability region (about 3.3 on the
#: negative real axis, less along the imaginary one): no accepted step is longer than
#: DOPRI5_STABLE_H_OMEGA / omega_max once the fastest mode is excited
DOPRI5_STABLE_H_OMEGA = 3.5


def dopri5_step_budget(t_end_s: float, mesh_frequency_Hz: float) -> int:
    """dopri5's default budget of steps (accepted + rejected) for a run to ``t_end_s``:
    20 000 per mesh period plus 100 000."""
    return int(20_000 * (t_end_s * mesh_frequency_Hz + 1)) + 100_000


def check_dopri5_budget(
    model: GearDynamics, duration_s: float, k: float | None = None, bound: bool = False, max_steps: int | None = None
) -> None:
    """One-line InputError if dopri5 cannot reach ``duration_s`` within its step budget:
    an explicit method's steps stay below DOPRI5_STABLE_H_OMEGA / omega_max, so it needs
    at least duration_s omega_max / 3.5 steps (omega_max: :func:`rk4_stability_number`'s
    linearisation, at mesh stiffness ``k``; ``bound``: a lower bound). Checked before any
    work, so a scene whose bodies are absurdly light is refused in a second rather than
    after minutes of integration (or an FE calibration) that would end the same way."""
    if k is None:
        k = float(np.max(model.k_table)) if model.tvms else model.k_mean
    w = max_linear_rate(model, k)
    budget = max_steps if max_steps is not None else dopri5_step_budget(duration_s, model.mesh_frequency_Hz)
    need = duration_s * w / DOPRI5_STABLE_H_OMEGA
    if need > budget:
        eq = ">=" if bound else "="
        raise fail(
            "duration_s",
            float(duration_s),
            "s",
            f"dopri5 cannot reach it within its budget of "
            f"{budget} steps: the fastest mode of the linearised model (omega_max {eq} "
            f"{w:.4g} rad/s) limits a stable step to {DOPRI5_STABLE_H_OMEGA / w:.3g} s, "
            f"so it needs >= {need:.3g} steps (check the bodies' masses and the bearing "
            f"stiffness, or shorten duration_s)",
        )


def _run(method, model, z0, t_end, t_out, steps_per_period, rtol, atol_vec, sw, max_steps, zlim):
    par, phi, phx, kx, ex = derived(model)
    p = tuple(par.tolist())
    Pt = 1.0 / model.mesh_frequency_Hz
    if method == "rk4":
        h = Pt / steps_per_period
        n_steps = max(int(math.ceil(t_end / h - 1e-9)), 0)
        sched = rk4_schedule(model, steps_per_period)
        out, counters, z = kernels.rk4(z0, h, n_steps, t_out, zlim, p, *sched, *sw)
        return out, counters, z, counters[0] * h, np.empty((0, kernels.EV_COLS))
    h0 = Pt / 256.0
    hmax = Pt / 4.0
    hmin = 1e-9 * Pt
    return kernels.dopri5(
        z0, t_end, t_out, rtol, atol_vec, h0, hmax, hmin, max_steps, zlim, _gidx(model), p, phi, phx, kx, ex, *sw
    )


def _diagnose(method, counters, t_stop, t_end, max_steps, zlim) -> str:
    """One line on why an integration stopped early."""
    status = int(counters[4])
    where = f"t = {t_stop:.6g} s of {t_end:.6g} s"
    if status == kernels.ST_DIVERGED:
        return (
            f"dynamics: {method} diverged at {where}: a displacement exceeded {zlim:.3g} m "
            f"(non-finite or unbounded state); the model is unstable for these parameters "
            f"(check damping, stiffness and speed), or the step is too large"
        )
    rate = int(counters[5]) if counters.shape[0] > 5 else 0
    chatter = (
        f"chattering contact: {rate} contact events per 1000 steps just before the stop "
        f"(impacts with vanishing rebound; more mesh or bearing damping ends them)"
    )
    if status == kernels.ST_HMIN:
        why = chatter if rate >= 50 else "the response is too stiff or is diverging"
        return f"dynamics: {method} step size fell below 1e-9 mesh periods at {where}: {why}"
    why = chatter if rate >= 50 else f"{int(counters[2])} contact events so far"
    return (
        f"dynamics: {method} used its whole budget of {max_steps} steps by {where} ({why}); "
        f"raise max_steps or shorten duration_s"
    )


def _all_finite(a: np.ndarray) -> bool:
    """Every value of ``a`` is finite. A finite sum says so in one pass without a boolean
    array (a NaN or an infinity anywhere makes the sum NaN or infinite); only a non-finite
    sum, which finite values give on overflow alone, is checked value by value."""
    return math.isfinite(float(np.sum(a))) or bool(np.all(np.isfinite(a)))


def compute_signals(model: GearDynamics, t: np.ndarray, Z: np.ndarray) -> dict:
    """Signals from sampled states: displacements, velocities, delta, delta', s, k_h, F_m."""
    ms = mesh_state(model, t, Z[:, :10])
    # the state columns as the rows of one transposed copy: one pass over Z instead of ten
    # strided ones (each column copy reads every cache line of Z)
    cols = np.ascontiguousarray(Z[:, :10].T)
    sig = {name: cols[i] for i, name in enumerate(STATE_NAMES)}
    sig.update(
        delta=ms["delta"],
        delta_dot=ms["delta_dot"],
        s=ms["s"],
        k_h=ms["k_h"],
        F_m=ms["F_m"],
        mode=ms["mode"],
        b=ms["b"],
    )
    if model.centre_distance == "dynamic":
        sig["alpha_op"] = np.arctan2(ms["sin_a"], ms["cos_a"])
    return sig


def _periodic_with(x: np.ndarray, S: int, M: int, max_p: int = 8, tol: float = 1e-6, table_periods: int = 1) -> int:
    """Smallest p in L, 2L, ..., max_p L (L = ``table_periods``, mesh periods per table
    period) with x(t + p T_m) = x(t) over the last max(p, 2) mesh periods to ``tol`` of
    the signal range; 0 if none (non-periodic, not yet settled, or a window shorter than
    2 p mesh periods). With L = 1 that is the smallest p <= max_p. With L > 1 the
    excitation itself has period L T_m: a response that looks periodic with fewer mesh
    periods (a small fault under the tolerance) is reported as L, never as less, and a
    constant signal as L."""
    L = int(table_periods)
    rng = float(np.ptp(x)) if x.size else 0.0
    if rng == 0.0:
        return L
    for p in range(L, L * max_p + 1, L):
        span = max(p, 2) * S
        if (p + max(p, 2)) * S > x.size:
            break
        a = x[-span:]
        b = x[-span - p * S : -p * S]
        if np.max(np.abs(a - b)) <= tol * rng:
            return p
    return 0


def periodicity_mismatch(x: np.ndarray, S: int, max_p: int = 8, table_periods: int = 1) -> tuple[int, float]:
    """(p, m): the period p in L, 2L, ..., max_p L mesh periods (L = ``table_periods``) that
    repeats best over the end of the window, and its mismatch m = max |x(t + p T_m) - x(t)| /
    range(x) over the last max(p, 2) mesh periods (0: exactly periodic; about 1: no period).
    (0, inf) when the window is shorter than 2 L + 2 mesh periods. ``S``: samples per mesh
    period."""
    L = int(table_periods)
    rng = float(np.ptp(x)) if x.size else 0.0
    if rng == 0.0:
        return L, 0.0
    found: list[tuple[int, float]] = []
    for p in range(L, L * max_p + 1, L):
        span = max(p, 2) * S
        if (p + max(p, 2)) * S > x.size:
            break
        found.append((p, float(np.max(np.abs(x[-span:] - x[-span - p * S : -p * S]))) / rng))
    if not found:
        return 0, math.inf
    # the smallest period that repeats as well as the best one (multiples of it repeat too)
    m_min = min(m for _, m in found)
    return next((p, m) for p, m in found if m <= max(2.0 * m_min, 1e-12))


def round_to_table_periods(
    model: GearDynamics, duration_s: float, discard_s: float = 0.0, min_table_periods: int = 1
) -> float:
    """A duration for which ``simulate(model, duration, discard_s)`` keeps a whole number
    (at least ``min_table_periods``) of table periods: the smallest such window that is
    not shorter than the one ``duration_s`` gives.

    ``simulate`` rounds the discarded transient up to whole mesh periods (t0) and keeps
    ``M = floor((duration - t0) f_m)`` mesh periods; this rounds M up to a multiple of
    ``model.table_periods`` (L) and returns t0 + M T_m plus half a mesh period of margin
    (``simulate`` floors, so the margin cannot add a period and keeps rounding error away
    from the boundary). With a table over one pinion revolution (L = z_p) that is whole
    pinion revolutions: the DFT of the kept window has the shaft orders, hence the
    sidebands f_m +- n f_shaft, on exact bins. For L = 1 (and any duration that already
    gives whole mesh periods) it returns a duration that keeps the same window."""
    if not (isinstance(duration_s, (int, float)) and math.isfinite(duration_s) and duration_s > 0):
        raise fail_text("duration_s", f"duration_s = {duration_s} s: must be > 0", duration_s, unit="s")
    if not (math.isfinite(discard_s) and 0 <= discard_s):
        raise fail_text("discard_s", f"discard_s = {discard_s} s: must be >= 0", discard_s, unit="s")
    if int(min_table_periods) != min_table_periods or min_table_periods < 1:
        raise fail_text(
            "min_table_periods",
            f"min_table_periods = {min_table_periods}: must be a whole number >= 1",
            min_table_periods,
        )
    fm = model.mesh_frequency_Hz
    L = model.table_periods
    n_d = int(math.ceil(discard_s * fm - 1e-9))
    M = max(int(math.floor((duration_s - n_d / fm) * fm + 1e-9)), 1)
    M = max(-(-M // L), int(min_table_periods)) * L
    return (n_d + M + 0.5) / fm


def merge_times(t_uni: np.ndarray, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t_out, uni): ``np.union1d(t_uni, nodes)`` and where the t_uni are in it, for an
    increasing t_uni and sorted nodes none of which equals a t_uni (simulate drops the
    nodes on the grid): a merge in O(N) instead of union1d's sort of both. Equal nodes
    (a node at both ends of the table period) are kept once, as union1d keeps them."""
    if not nodes.size:
        return t_uni, np.arange(t_uni.size)
    nodes = nodes[np.r_[True, np.diff(nodes) > 0]]
    before = np.searchsorted(t_uni, nodes)  # grid times before each node
    t_out = np.empty(t_uni.size + nodes.size)
    t_out[before + np.arange(nodes.size)] = nodes
    # nodes before grid time k: those with before <= k (a count, no second search)
    uni = np.arange(t_uni.size) + np.cumsum(np.bincount(before, minlength=t_uni.size + 1))[: t_uni.size]
    t_out[uni] = t_uni
    return t_out, uni


def signal_stats(x) -> dict[str, float]:
    """Summary statistics of a signal sampled uniformly over whole periods, in its unit:
    ``mean``, ``ac_rms`` = sqrt(mean((x - mean)^2)) (the RMS of the fluctuation about the mean,
    never an RMS that mixes the mean in: a 7 um static deflection would hide a 0.6 um
    vibration) and ``p2p`` = max - min."""
    x = np.asarray(x, dtype=float)
    return dict(mean=float(np.mean(x)), ac_rms=float(np.std(x)), p2p=float(np.ptp(x)))


def simulate(
    model: GearDynamics,
    duration_s: float,
    discard_s: float = 0.0,
    method: str = "auto",
    steps_per_mesh_period: int = 256,
    rtol: float = 1e-8,
    atol=None,
    y0=None,
    samples_per_mesh_period: int | None = None,
    track_energy: bool = False,
    max_steps: int | None = None,
    max_output_bytes: float = 2 * 2**30,
    on_compile=None,
    dense: bool = True,
) -> SimResult:
    """Integrate the model over [0, duration_s] and sample the kept window.

    method: "rk4" (fixed step, ``steps_per_mesh_period``), "dopri5" (adaptive, rtol/atol,
    event location), "auto" (RK4 when there is neither backlash nor bearing clearance,
    else dopri5). atol: None -> rtol times the static-deflection scale for displacements
    (and times that scale times the mesh natural angular frequency for velocities); a
    scalar is the displacement atol (velocities scaled the same way); or 10 values.
    y0: initial state (10 values); default the static equilibrium under the mean stiffness.

    Guards (each raises one-line errors): RK4 is refused beyond its stability limit
    (h omega_max > 2.5, :func:`rk4_stability_number`); the output is sized before the
    run and refused above ``max_output_bytes``; dopri5 has a step budget (``max_steps``,
    default 20 000 per mesh period) and a minimum step (1e-9 mesh periods) and stops
    with a diagnosis (chattering contact, collapse, divergence) instead of running on.
    ``on_compile(message)`` is called once if compiling the kernels for this effect set
    takes noticeable time (first run only; numba caches them on disk).
    ``dense=False`` outputs the uniform samples only, without the table nodes (no
    ``t_dense``/``states_dense``, so ``harmonics`` falls back to the samples): for runs
    that read only ``states`` and ``z_end``. Neither kernel takes its steps from the
    output times, so the samples and the end state are the same as with ``dense=True``.
    """
    if not (isinstance(duration_s, (int, float)) and math.isfinite(duration_s) and duration_s > 0):
        raise fail_text("duration_s", f"duration_s = {duration_s} s: must be > 0", duration_s, unit="s")
    if not (math.isfinite(discard_s) and 0 <= discard_s < duration_s):
        raise fail_text("discard_s", f"discard_s = {discard_s} s: must be in [0, duration_s)", discard_s, unit="s")
    if method not in ("auto", "rk4", "dopri5"):
        raise fail("method", repr(method), "", "must be 'rk4', 'dopri5' or 'auto'")
    if int(steps_per_mesh_period) != steps_per_mesh_period or steps_per_mesh_period < 4:
        raise fail_text(
            "steps_per_mesh_period",
            f"steps_per_mesh_period = {steps_per_mesh_period}: must be a whole number >= 4",
            steps_per_mesh_period,
        )
    if not (0 < rtol < 1):
        raise fail_text(
            "rtol", f"rtol = {rtol}: must be in (0, 1)", rtol, field=Field("", 0.0, 1.0, lo_open=True, hi_open=True)
        )
    method = resolve_method(model, method)
    fm = model.mesh_frequency_Hz
    Pt = 1.0 / fm
    n_d = int(math.ceil(discard_s * fm - 1e-9))
    t0 = n_d * Pt
    M = int(math.floor((duration_s - t0) * fm + 1e-9))
    if M < 1:
        raise fail_text(
            "duration_s",
            f"duration_s = {duration_s} s: must exceed discard_s rounded up "
            f"to whole mesh periods ({t0:.6g} s) by at least one mesh period "
            f"({Pt:.6g} s)",
            duration_s,
            unit="s",
        )
    S = int(samples_per_mesh_period or steps_per_mesh_period)
    dt = Pt / S
    # output: the uniform grid of the kept window (M periods, S per period, plus its end
    # point) and (dense) every table node inside it, so the signals between output points
    # are free of table kinks (exact harmonics, analysis.window_harmonics)
    t_uni = t0 + dt * np.arange(M * S + 1)
    nodes = table_node_times(model, t_uni[0], t_uni[-1]) if dense else np.empty(0)
    if nodes.size:
        r = (nodes - t0) / dt
        nodes = nodes[np.abs(r - np.rint(r)) > 1e-9]
    n_out = t_uni.size + nodes.size
    need = n_out * OUTPUT_BYTES_PER_SAMPLE_STATE
    if need > max_output_bytes:
        raise fail(
            "duration_s",
            float(duration_s),
            "s",
            f"the kept window of {M} mesh periods "
            f"x {S} samples needs about {need / 2**30:.3g} GiB of output (limit "
            f"{max_output_bytes / 2**30:.3g} GiB); shorten duration_s - discard_s or "
            f"lower the speed",
        )
    t_out, uni = merge_times(t_uni, nodes)
    t_end = float(t_uni[-1])
    if method == "rk4":
        check_rk4_stable(model, steps_per_mesh_period)
        # the schedule holds one table period: table_periods x steps sub-steps plus the
        # table's nodes, 11 float64 each
        sched = 88 * (model.table_periods * steps_per_mesh_period + model.phi_table.size)
        if sched > max_output_bytes:
            raise fail(
                "table_periods",
                model.table_periods,
                "",
                f"the RK4 schedule of one "
                f"table period needs about {sched / 2**30:.3g} GiB (limit "
                f"{max_output_bytes / 2**30:.3g} GiB); use fewer steps per mesh "
                f"period or method = dopri5",
            )
    if max_steps is None:
        max_steps = dopri5_step_budget(t_end, fm)
    if method == "dopri5":
        check_dopri5_budget(model, t_end, max_steps=max_steps)

    z0 = static_equilibrium(model) if y0 is None else np.asarray(y0, float).ravel()
    if z0.shape != (10,) or not np.all(np.isfinite(z0)):
        raise fail_text("y0", "y0: must be 10 finite values (y_p, x_p, y_g, x_g, q and velocities)")
    nz = 14 if track_energy else 10
    z0 = np.concatenate([z0, np.zeros(nz - 10)])

    k_ref = max(model.k_mean, 1e-300)
    x_ref = abs(model.F_s) / k_ref + 2 * abs(model.F_s) / model.k_b
    if x_ref == 0:
        x_ref = float(np.max(np.abs(z0[:5]))) or 1e-6
    w_ref = math.sqrt((k_ref + model.k_b) / min(model.m_e, model.m_p, model.m_g))
    if atol is None:
        atol_vec = np.r_[np.full(5, rtol * x_ref), np.full(5, rtol * x_ref * w_ref)]
    elif np.ndim(atol) == 0:
        atol_vec = np.r_[np.full(5, float(atol)), np.full(5, float(atol) * w_ref)]
    else:
        atol_vec = np.asarray(atol, float).ravel()
        if atol_vec.shape != (10,):
            raise fail_text("atol", "atol: must be None, a scalar or 10 values")
    if np.any(atol_vec <= 0):
        raise fail_text("atol", "atol: must be > 0")
    # a displacement this far beyond every physical scale means divergence, not dynamics
    zlim = 1e4 * (
        x_ref + (model.backlash_half_m or 0.0) + (model.bearing_half_clearance_m or 0.0) + float(np.max(np.abs(z0[:5])))
    )

    sw = kernel_switches(model, track_energy)
    key = (method, sw)
    compile_s = 0.0
    if key not in _WARM:
        # compile (or load from numba's disk cache) on a tiny problem, so wall_s is pure run
        timer = None
        if on_compile is not None:
            import threading

            timer = threading.Timer(1.0, on_compile, ("compiling solver kernels for this effect set, first run only",))
            timer.daemon = True
            timer.start()
        tc = time.perf_counter()
        try:
            _run(
                method,
                model,
                z0.copy(),
                4 * Pt / steps_per_mesh_period,
                np.array([0.0]),
                steps_per_mesh_period,
                rtol,
                atol_vec,
                sw,
                1000,
                zlim,
            )
        finally:
            if timer is not None:
                timer.cancel()
        compile_s = time.perf_counter() - tc
        _WARM.add(key)
    tw = time.perf_counter()
    out, counters, z_end, t_stop, ev = _run(
        method, model, z0, t_end, t_out, steps_per_mesh_period, rtol, atol_vec, sw, max_steps, zlim
    )
    wall = time.perf_counter() - tw
    ko = int(counters[3])
    if int(counters[4]) != kernels.ST_OK or ko < n_out or not _all_finite(out):
        if int(counters[4]) == kernels.ST_OK:
            if np.all(np.isfinite(out[:ko])):
                raise RuntimeError(
                    f"dynamics: {method} finished with {ko} of {n_out} output samples "
                    f"(output grid not reached: a bug, please report)"
                )
            counters[4] = kernels.ST_DIVERGED
        raise SolverError(_diagnose(method, counters, t_stop, t_end, max_steps, zlim))
    # np.take gathers whole rows (memcpy each); out[index] took ~3x as long for the 51 200
    # rows of a 0.5 s scene (the same rows either way)
    t_win, Z_win = t_uni[:-1], np.take(out, uni[:-1], axis=0)
    sig = compute_signals(model, t_win, Z_win)
    mode = sig["mode"]
    sep: float | None
    if has_flank_law(model):
        sep = float(np.mean(mode == 0))
        back = float(np.mean((mode == -1) | (mode == 2)))
    else:
        # a two-sided linear mesh spring cannot separate: the fraction is undefined, not 0;
        # a negative mesh force is the back flanks carrying load
        sep = None
        back = float(np.mean(sig["F_m"] < 0.0))
    if model.bearing_half_clearance_m is not None:
        bb = model.bearing_half_clearance_m
        bc = {
            "pinion": float(np.mean((np.abs(Z_win[:, 0]) > bb) | (np.abs(Z_win[:, 1]) > bb))),
            "gear": float(np.mean((np.abs(Z_win[:, 2]) > bb) | (np.abs(Z_win[:, 3]) > bb))),
        }
    else:
        bc = {"pinion": 1.0, "gear": 1.0}
    stats = {name: signal_stats(sig[name]) for name in ("y_p", "x_p", "y_g", "x_g", "q", "delta", "F_m")}
    energy = None
    if track_energy:
        energy = {name: Z_win[:, 10 + i].copy() for i, name in enumerate(ENERGY_NAMES)}
    return SimResult(
        t=t_win,
        signals=sig,
        fm_Hz=fm,
        fs_Hz=S * fm,
        steps=int(counters[0]),
        rejected=int(counters[1]),
        events=int(counters[2]),
        wall_s=wall,
        compile_s=compile_s,
        separation_fraction=sep,
        backside_fraction=back,
        bearing_contact_fraction=bc,
        method=method,
        states=Z_win if nz == 10 else Z_win[:, :10].copy(),  # Z_win is a fresh array (np.take)
        energy=energy,
        n_periods=M,
        stats=stats,
        periodic_with=_periodic_with(sig["delta"], S, M, table_periods=model.table_periods),
        z_end=z_end[:10].copy(),
        switches=sw,
        model=model,
        t_dense=t_out if dense else None,
        states_dense=out[:, :10] if dense else None,
        window_events=ev,
        table_periods=model.table_periods,
    )
