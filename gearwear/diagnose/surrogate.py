"""Surrogate of the 6-DOF forward model over the diagnosis unknowns, with its own error model.

**Unknowns** (scene keys they set; default prior ranges, uniform):

* ``wear_max_depth_um`` -> ``effects.wear.max_depth_um``: [0, 40] um (the paper's phases
  are mild 10 and severe 30 um); [0.1, 40] um when the scene names
  ``transmission_error``, which needs a worn flank;
* ``clearance_um`` -> ``effects.bearing_clearance.clearance_um``: [0, 50] um;
* ``torque_Nm`` -> ``operating.torque_Nm``: [0.5, 1.5] x the scene's torque.

**Features** are the complex mesh-harmonic coefficients 1..K of y_p, x_p, delta and F_m
(``dynamics.analysis.window_fourier``: exact window integrals, no aliasing) and the means
of y_p, x_p and F_m. The surrogate interpolates the real and imaginary parts, not the
amplitudes: a harmonic whose phasor passes near zero has a kinked amplitude but smooth
parts, and the amplitude of the interpolated phasor follows the kink.

**Design**: a scrambled Sobol sequence (scipy.stats.qmc, fixed seed) of 2^m points in the
unit cube plus its corners, mapped to the prior box; wear through u = sqrt(w / W), which
puts half the points below W/4: the response changes fastest at small wear, where the
wear gap of the entering pair is comparable to the elastic approach (1-3 um).
Each point is one short ``simulate`` (``TRAIN_DISCARD_S`` transient, ``TRAIN_PERIODS``
kept mesh periods, never more than the scene's own); the periodicity residual of each
run is recorded.

**Interpolation**: ``scipy.interpolate.RBFInterpolator``, thin-plate spline with a linear
polynomial, on the unit-cube coordinates. Chosen over a Gaussian process
(scikit-learn): it is exact at the design points, has no hyper-parameters to optimise
(deterministic, one linear solve, ~0.1 s for 500 points) and needs no new dependency.
The error model does what a GP's predictive variance would, from data instead of a
stationary-kernel assumption.

**Error model** (what enters the noise): the 32-fold cross-validation residuals of the
amplitudes at the design points, smoothed over the unknowns with a Gaussian kernel of
width one design spacing, give a local error s_i(theta) per feature. Held-out full
simulations (the scene's own solver settings, uniform random points of the prior)
calibrate it: per signal's harmonics and per mean, kappa = max(1, q95(|e| / s) / 1.96),
so that at least 95 % of the held-out errors lie inside kappa s's 95 % band. The
held-out errors are stated (``heldout`` in the cache sidecar and in diagnosis.json).
The errors of the features at one point are not independent: they come from the same
missing design information, and the harmonics of the four signals are one set of
mesh-force harmonics seen through fixed transfer functions while the bearings stay in
contact. :func:`error_multiplicity` therefore treats them as one common error.

**Cache**: like the stiffness tables (``gearwear.stiffness.tables``: same folder, SHA-256 key of
every input + the code fingerprint, checked on read, a bad entry is recomputed with one
line on stderr). An entry is ``<key>.npz`` + ``<key>.npz.json``.
"""

from __future__ import annotations

import copy
import functools
import hashlib
import io as _io
import math
import time
from concurrent.futures import Executor, Future, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gearwear import io
from gearwear.core.inputs import read_bounded
from gearwear.core.validation import InputError
from gearwear.diagnose.features import MEAN_SIGNALS, SIGNALS, Feature, all_features, feature_name
from gearwear.stiffness import tables

SURROGATE_VERSION = 1
TRAIN_DISCARD_S = 0.05  # > 6 time constants of the slowest bearing mode (2 % damping, ~1 kHz)
TRAIN_PERIODS = 10  # kept mesh periods of a training run
CV_FOLDS = 32
DESIGN_SEED = 20190415  # fixed: the same inputs give the same design, hence the same bytes
HOLDOUT_SEED = 7
FINGERPRINT_ROOT = "gearwear.diagnose.surrogate"
LABEL = "diagnose surrogate"  # how a cache line names an entry


@dataclass(frozen=True)
class Unknown:
    """One unknown of the diagnosis: its output name, the scene key it sets, its unit, the
    flag that sets its prior range and the coordinate the design is uniform in."""

    name: str
    short: str
    scene_key: str
    unit: str
    flag: str
    warp: str  # "sqrt" | "linear"

    def to_unit(self, value, lo: float, hi: float):
        """Physical value -> design coordinate in [0, 1]."""
        u = (np.asarray(value, float) - lo) / (hi - lo)
        return np.sqrt(np.clip(u, 0.0, None)) if self.warp == "sqrt" else u

    def from_unit(self, u, lo: float, hi: float):
        u = np.asarray(u, float)
        return lo + (hi - lo) * (u * u if self.warp == "sqrt" else u)


UNKNOWNS: dict[str, Unknown] = {
    "wear": Unknown("wear_max_depth_um", "wear", "effects.wear.max_depth_um", "um", "--wear-range-um", "sqrt"),
    "clearance": Unknown(
        "clearance_um", "clearance", "effects.bearing_clearance.clearance_um", "um", "--clearance-range-um", "linear"
    ),
    "torque": Unknown("torque_Nm", "torque", "operating.torque_Nm", "N m", "--torque-range-Nm", "linear"),
}


def default_range(u: Unknown, raw: dict[str, Any]) -> tuple[float, float]:
    """The documented prior range of ``u`` for the scene document ``raw``."""
    if u.short == "wear":
        return (0.1 if "transmission_error" in raw.get("effects", {}) else 0.0), 40.0
    if u.short == "clearance":
        return 0.0, 50.0
    T = float(raw.get("operating", {}).get("torque_Nm", 40.0))
    return 0.5 * T, 1.5 * T


def set_unknowns(raw: dict[str, Any], values: dict[str, float]) -> dict[str, Any]:
    """A copy of the scene document with the unknowns (short names) set. Wear becomes
    ``max_depth_um`` (keeping the scene's wear model and taper); an unknown clearance adds
    the bearing_clearance effect if the scene has none."""
    out = copy.deepcopy(raw)
    eff = out.setdefault("effects", {})
    for short, v in values.items():
        if short == "wear":
            old = eff.get("wear")
            keep = {k: old[k] for k in ("model", "taper_mm") if isinstance(old, dict) and k in old}
            eff["wear"] = {"max_depth_um": float(v), **keep}
        elif short == "clearance":
            eff["bearing_clearance"] = {"clearance_um": float(v)}
        else:
            out.setdefault("operating", {})["torque_Nm"] = float(v)
    return out


def scene_at(raw: dict[str, Any], name: str, values: dict[str, float], solver: dict[str, float] | None = None):
    from gearwear.scene.model import scene_from_dict

    doc = set_unknowns(raw, values)
    if solver:
        doc.setdefault("solver", {}).update(solver)
    return scene_from_dict(doc, name=name)


def training_solver(scene) -> dict[str, float]:
    """Short runs for the design: the transient of TRAIN_DISCARD_S and TRAIN_PERIODS kept
    mesh periods, never longer than the scene's own."""
    fm = scene.mesh_frequency_Hz
    discard = min(TRAIN_DISCARD_S, scene.solver["discard_s"])
    n_d = math.ceil(discard * fm - 1e-9)
    kept = min(TRAIN_PERIODS, max(int(math.floor((scene.solver["duration_s"] - n_d / fm) * fm + 1e-9)), 2))
    return {"discard_s": discard, "duration_s": (n_d + kept + 0.5) / fm}


def periodicity_residual(x: np.ndarray, S: int) -> float:
    """max |x(t) - x(t - T_m)| over the last mesh period, relative to the signal's range."""
    rng = float(np.ptp(x))
    if rng == 0.0 or x.size < 2 * S:
        return 0.0 if rng == 0.0 else math.inf
    return float(np.max(np.abs(x[-S:] - x[-2 * S : -S])) / rng)


def simulate_point(
    raw: dict[str, Any],
    name: str,
    values: dict[str, float],
    solver: dict[str, float] | None,
    harmonics: int,
    tables: Callable | None = None,
) -> tuple[np.ndarray, float]:
    """One forward run: ([Re c, Im c, means], periodicity residual). c: the complex
    harmonics 1..K of every signal of SIGNALS in its unit; means of MEAN_SIGNALS.
    ``tables``: where the stiffness curve comes from (a :class:`gearwear.jobs.table_memo.TableMemo`
    shared by runs whose tables are equal, :func:`simulate_runs`; default: computed here).
    Top-level, so process and Dask executors can pickle it."""
    from gearwear.dynamics.analysis import window_fourier
    from gearwear.jobs.simulate import run, stiffness_input

    scene = scene_at(raw, name, values, solver)
    r = run(scene, stiffness=stiffness_input(scene, tables=tables)).result
    models = [m for m, _ in SIGNALS.values()]
    c = window_fourier(r, models, harmonics)
    harm = np.concatenate([c[m] * f for m, f in SIGNALS.values()])
    means = [r.stats[SIGNALS[s][0]]["mean"] * SIGNALS[s][1] for s in MEAN_SIGNALS]
    S = int(round(r.fs_Hz / r.fm_Hz))
    resid = max(periodicity_residual(r.signals[m], S) for m in models)
    return np.concatenate([harm.real, harm.imag, means]), resid


def simulate_runs(
    runs: list[tuple[dict[str, Any], str, dict[str, float], dict[str, float] | None]], harmonics: int
) -> list[tuple[np.ndarray, float]]:
    """:func:`simulate_point` of every (raw, name, values, solver) of ``runs``, in order, with
    one :class:`gearwear.jobs.table_memo.TableMemo` for them all: runs that differ only in
    what the stiffness tables do not depend on (the speed, the solver's window; the
    bearing clearance unless it moves the centre distance) compute their tables once. Each result equals its own
    :func:`simulate_point` to the bit (the memo hands on the curve the same request gives).
    Top-level, so process and Dask executors can pickle it."""
    from gearwear.jobs.table_memo import TableMemo

    memo = TableMemo()
    return [simulate_point(raw, name, values, solver, harmonics, tables=memo) for raw, name, values, solver in runs]


def run_points(
    raw: dict[str, Any],
    name: str,
    points: list[dict[str, float]],
    solver: dict[str, float] | None,
    harmonics: int,
    executor: Executor | None = None,
    progress: Callable[[int], None] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """simulate_point at every point, in order (deterministic whatever the executor; no
    executor: in this process)."""
    out: list[Any] = [None] * len(points)
    if executor is None:
        for i, p in enumerate(points):
            out[i] = simulate_point(raw, name, p, solver, harmonics)
            if progress:
                progress(1)
    else:
        futures = {executor.submit(simulate_point, raw, name, p, solver, harmonics): i for i, p in enumerate(points)}
        for fut in as_completed(futures):
            out[futures[fut]] = fut.result()
            if progress:
                progress(1)
    return np.array([o[0] for o in out]), np.array([o[1] for o in out])


def amplitudes(Y: np.ndarray, harmonics: int) -> np.ndarray:
    """[Re c, Im c, means] rows -> feature rows (all_features order): |c| then the means."""
    n = len(SIGNALS) * harmonics
    return np.hstack([np.abs(Y[:, :n] + 1j * Y[:, n : 2 * n]), Y[:, 2 * n :]])


def _rbf(U: np.ndarray, Y: np.ndarray):
    from scipy.interpolate import RBFInterpolator

    return RBFInterpolator(U, Y, kernel="thin_plate_spline", degree=1)


@dataclass
class Surrogate:
    """The fitted surrogate; build with :func:`fit` or :func:`build`, predict with
    :meth:`predict` (features, all_features order) and :meth:`error` (local error s)."""

    unknowns: list[Unknown]
    lo: np.ndarray
    hi: np.ndarray
    harmonics: int
    X: np.ndarray  # design (n, d), physical units
    Y: np.ndarray  # [Re c, Im c, means] at the design
    cv: np.ndarray  # cross-validation residuals of the features at the design (n, F)
    kappa: np.ndarray  # calibration factor per feature (F,)
    heldout: dict[str, Any]  # the stated errors against the held-out full simulations
    meta: dict[str, Any] = field(default_factory=dict)
    from_cache: bool = False
    Xh: np.ndarray | None = None  # the held-out points and their [Re c, Im c, means]
    Yh: np.ndarray | None = None

    def __post_init__(self):
        self._U = self.unit(self.X)
        self._scale = feature_scale(self.Y)
        self._rbf = _rbf(self._U, self.Y / self._scale)
        self.h = bandwidth(len(self.X), len(self.unknowns))

    @property
    def features(self) -> list[Feature]:
        return all_features(self.harmonics)

    def unit(self, theta) -> np.ndarray:
        th = np.atleast_2d(np.asarray(theta, float))
        return np.column_stack([u.to_unit(th[:, j], self.lo[j], self.hi[j]) for j, u in enumerate(self.unknowns)])

    def predict(self, theta) -> np.ndarray:
        """Features (m, F) at physical points theta (m, d)."""
        return amplitudes(self._rbf(self.unit(theta)) * self._scale, self.harmonics)

    def error(self, theta, columns=None, chunk: int = 4096) -> np.ndarray:
        """Local error s_i(theta) (m, F), or of the feature ``columns`` only: kappa times
        the kernel-smoothed CV residuals."""
        U = self.unit(theta)
        cols = slice(None) if columns is None else np.asarray(columns)
        cv2 = self.cv[:, cols] ** 2
        out = np.empty((U.shape[0], cv2.shape[1]))
        for a in range(0, U.shape[0], chunk):
            out[a : a + chunk] = local_rms(U[a : a + chunk], self._U, cv2, self.h)
        return out * self.kappa[cols]


def bandwidth(n: int, d: int) -> float:
    """One design spacing in the unit cube: n^(-1/d)."""
    return float(n) ** (-1.0 / d)


def local_rms(U: np.ndarray, Ud: np.ndarray, r2: np.ndarray, h: float) -> np.ndarray:
    """Nadaraya-Watson kernel average of squared residuals r2 (n, F) at the design Ud,
    Gaussian kernel of width h, evaluated at U (m, d); returns its square root."""
    d2 = np.sum((U[:, None, :] - Ud[None, :, :]) ** 2, axis=-1)
    w = np.exp(-0.5 * (d2 - d2.min(axis=1, keepdims=True)) / h**2)
    return np.sqrt((w @ r2) / w.sum(axis=1, keepdims=True))


def feature_scale(Y: np.ndarray) -> np.ndarray:
    """Per-column standard deviation of the design outputs (1 for a constant column): the
    RBF interpolates Y / scale, so every output weighs alike in the shared kernel."""
    return np.where(np.std(Y, axis=0) > 0, np.std(Y, axis=0), 1.0)


def corners(d: int) -> np.ndarray:
    """The 2^d corners of the unit box (2^d, d), in meshgrid order."""
    return np.array(np.meshgrid(*[[0.0, 1.0]] * d, indexing="ij")).reshape(d, -1).T


def cross_validation(U: np.ndarray, Y: np.ndarray, harmonics: int, folds: int = CV_FOLDS) -> np.ndarray:
    """Feature residuals at every design point of the surrogate fitted without its fold
    (fold = index mod folds: each fold is spread over the Sobol design)."""
    scale = feature_scale(Y)
    F = amplitudes(Y, harmonics)
    res = np.empty_like(F)
    idx = np.arange(len(U)) % min(folds, len(U))
    for f in np.unique(idx):
        m = idx == f
        res[m] = amplitudes(_rbf(U[~m], Y[~m] / scale)(U[m]) * scale, harmonics) - F[m]
    return res


def calibrate(z: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """kappa per feature: max(1, q95(|z|) / 1.96) over the held-out z = e / s of each group."""
    kappa = np.ones(z.shape[1])
    for g in np.unique(groups):
        m = groups == g
        kappa[m] = max(1.0, float(np.percentile(np.abs(z[:, m]), 95)) / 1.959964)
    return kappa


def feature_groups(harmonics: int) -> np.ndarray:
    """Calibration groups: the harmonics of one signal, or one mean."""
    return np.array([f"{s}:{'mean' if k == 0 else 'h'}" for s, k in all_features(harmonics)])


def error_multiplicity(n_features: int) -> float:
    """How many times each measured feature's surrogate variance is counted: n, the number
    of measured features, i.e. their surrogate errors are taken as one common error. That
    is exact for one common error (n features with independent noise sigma and a common
    error s carry sigma^2 / n + s^2, and so do n terms of variance sigma^2 + n s^2) and
    conservative for partly independent errors. The blind test justifies it: counting the
    errors as partly independent (the participation ratio of their cross-validation
    correlation) gave intervals that missed the truth more often than stated."""
    return float(max(1, n_features))


def fit(
    unknowns: list[Unknown],
    lo,
    hi,
    harmonics: int,
    X: np.ndarray,
    Y: np.ndarray,
    Xh: np.ndarray,
    Yh: np.ndarray,
    meta: dict[str, Any] | None = None,
) -> Surrogate:
    """The surrogate from the design (X, Y) and the held-out full simulations (Xh, Yh)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    F = len(all_features(harmonics))
    probe = Surrogate(unknowns, lo, hi, harmonics, X, Y, np.zeros((len(X), F)), np.ones(F), {}, meta or {})
    probe.cv = cross_validation(probe._U, Y, harmonics)
    Fh, Ph = amplitudes(Yh, harmonics), probe.predict(Xh)
    s_h = probe.error(Xh)
    probe.kappa = calibrate((Ph - Fh) / np.where(s_h > 0, s_h, np.inf), feature_groups(harmonics))
    probe.heldout = heldout_summary(Xh, Fh, Ph, s_h * probe.kappa, harmonics)
    probe.Xh, probe.Yh = Xh, Yh
    return probe


def heldout_summary(Xh, Fh, Ph, Sh, harmonics: int) -> dict[str, Any]:
    """The stated surrogate error against the held-out full simulations."""
    feats = all_features(harmonics)
    harm = np.array([k > 0 for _, k in feats])
    err = Ph - Fh
    big = Fh[:, harm] > 1e-3 * np.max(Fh[:, harm], axis=0)  # a relative error of a vanishing amplitude says nothing
    rel = np.abs(err[:, harm])[big] / Fh[:, harm][big]
    per = {feature_name(f): float(np.sqrt(np.mean(err[:, i] ** 2))) for i, f in enumerate(feats)}
    inside = np.abs(err) <= 1.959964 * Sh
    return {
        "points": int(len(Xh)),
        "harmonic_relative_error_median": float(np.median(rel)),
        "harmonic_relative_error_p90": float(np.percentile(rel, 90)),
        "harmonic_relative_error_p95": float(np.percentile(rel, 95)),
        "mean_abs_error": {f"{s}": float(np.sqrt(np.mean(err[:, i] ** 2))) for i, (s, k) in enumerate(feats) if k == 0},
        "rms_error_per_feature": per,
        "fraction_inside_error_model_95": float(np.mean(inside)),
    }


# -- building, with the cache -------------------------------------------------------------


@dataclass
class BuildSpec:
    """Everything a surrogate depends on (its cache key is the hash of :meth:`inputs`)."""

    raw: dict[str, Any]  # the scene document (after --set), unknowns not yet set
    name: str
    unknowns: list[Unknown]
    lo: tuple[float, ...]
    hi: tuple[float, ...]
    harmonics: int
    design_points: int  # 2^m Sobol points (the corners come on top)
    holdout_points: int

    def base_scene(self):
        return scene_at(self.raw, self.name, {u.short: l for u, l in zip(self.unknowns, self.lo)})

    def inputs(self) -> dict[str, Any]:
        import numba
        import scipy

        scene = self.base_scene()
        return {
            "kind": "diagnose surrogate",
            "surrogate_version": SURROGATE_VERSION,
            **io.scene_inputs(scene),
            "unknowns": [u.name for u in self.unknowns],
            "lo": list(self.lo),
            "hi": list(self.hi),
            "harmonics": self.harmonics,
            "design_points": self.design_points,
            "holdout_points": self.holdout_points,
            "training_solver": training_solver(scene),
            "design_seed": DESIGN_SEED,
            "holdout_seed": HOLDOUT_SEED,
            "cv_folds": CV_FOLDS,
            "code_sha256": code_fingerprint(),
            "versions": {"numpy": np.__version__, "scipy": scipy.__version__, "numba": numba.__version__},
        }


@functools.lru_cache(maxsize=None)
def code_fingerprint() -> str:
    """SHA-256 of the source of every gearwear module the surrogate's numbers depend on."""
    from gearwear.stiffness.calibration import dependencies, fingerprint

    return fingerprint(dependencies(FINGERPRINT_ROOT))


def design(spec: BuildSpec) -> tuple[np.ndarray, np.ndarray]:
    """(training points, held-out points) in physical units. Training: Sobol in the design
    coordinates plus the corners of the box; held-out: uniform in the prior."""
    from scipy.stats import qmc

    d = len(spec.unknowns)
    m = int(round(math.log2(spec.design_points)))
    u = qmc.Sobol(d, scramble=True, seed=np.random.default_rng(DESIGN_SEED)).random_base2(m)
    u = np.vstack([corners(d), u])
    X = np.column_stack([un.from_unit(u[:, j], spec.lo[j], spec.hi[j]) for j, un in enumerate(spec.unknowns)])
    rng = np.random.default_rng(HOLDOUT_SEED)
    Xh = np.asarray(spec.lo) + (np.asarray(spec.hi) - np.asarray(spec.lo)) * rng.random((spec.holdout_points, d))
    return X, Xh


def _points(spec: BuildSpec, X: np.ndarray) -> list[dict[str, float]]:
    return [{u.short: float(x[j]) for j, u in enumerate(spec.unknowns)} for x in X]


@dataclass
class Pending:
    """A surrogate whose runs are submitted (:func:`start`) and not yet fitted
    (:func:`finish`): the design's and the held-out points' futures, in design order."""

    spec: BuildSpec
    inputs: dict[str, Any]
    folder: Path
    X: np.ndarray
    Xh: np.ndarray
    design: list[Future]
    holdout: list[Future]
    t0: float
    notify: tables.Notify | None
    progress: Callable[[int], None] | None


def start(
    spec: BuildSpec,
    executor: Executor | Callable[[], Executor | None] | None = None,
    progress: Callable[[int], None] | None = None,
    notify: tables.Notify | None = tables.to_stderr,
    refresh: bool = False,
) -> Surrogate | Pending:
    """The cached surrogate for ``spec``; else, with an executor, every run of its design
    and held-out points submitted at once (a :class:`Pending` for :func:`finish`), so a
    caller with several surrogates to build keeps the workers busy while this process fits
    the ones whose runs are done (diagnose.plan); without one, the whole build here."""
    folder = tables.cache_dir()
    inputs = spec.inputs()
    if not refresh:
        sur, reason = lookup(inputs, spec.unknowns, folder)
        if sur is not None:
            return sur
        if reason is not None and notify is not None:
            notify(tables.entry_message(tables.table_key(inputs), LABEL, reason))
    t0 = time.perf_counter()
    X, Xh = design(spec)
    ex = executor if executor is None or isinstance(executor, Executor) else executor()
    if ex is None:
        Y, resid = run_points(
            spec.raw, spec.name, _points(spec, X), training_solver(spec.base_scene()), spec.harmonics, None, progress
        )
        t1 = time.perf_counter()
        Yh, _ = run_points(spec.raw, spec.name, _points(spec, Xh), None, spec.harmonics, None, progress)
        return _fit_and_store(spec, inputs, folder, notify, X, Y, resid, Xh, Yh, t0, t1)
    solver = training_solver(spec.base_scene())
    submit = lambda p, sol: ex.submit(simulate_point, spec.raw, spec.name, p, sol, spec.harmonics)  # noqa: E731
    return Pending(
        spec,
        inputs,
        folder,
        X,
        Xh,
        [submit(p, solver) for p in _points(spec, X)],
        [submit(p, None) for p in _points(spec, Xh)],
        t0,
        notify,
        progress,
    )


def _collect(futures: list[Future], progress: Callable[[int], None] | None) -> tuple[np.ndarray, np.ndarray]:
    """simulate_point's results in submission order (as run_points returns them)."""
    for fut in as_completed(futures):
        fut.result()
        if progress:
            progress(1)
    out = [f.result() for f in futures]
    return np.array([o[0] for o in out]), np.array([o[1] for o in out])


def finish(pending: Pending) -> Surrogate:
    """The surrogate of a :func:`start` that submitted its runs: wait for them, fit, store."""
    pe = pending
    Y, resid = _collect(pe.design, pe.progress)
    t1 = time.perf_counter()
    Yh, _ = _collect(pe.holdout, pe.progress)
    return _fit_and_store(pe.spec, pe.inputs, pe.folder, pe.notify, pe.X, Y, resid, pe.Xh, Yh, pe.t0, t1)


def _fit_and_store(spec, inputs, folder, notify, X, Y, resid, Xh, Yh, t0: float, t1: float) -> Surrogate:
    """Fit, store, and the wall times in ``meta`` (timing.json only). They run from
    :func:`start`: for a surrogate whose runs queued behind another's (diagnose.plan),
    design_wall_s includes that wait."""
    t2 = time.perf_counter()
    meta = {
        "periodicity_residual_max": float(np.max(resid)),
        "training_runs": int(len(X)),
        "design_wall_s": t1 - t0,
        "holdout_wall_s": t2 - t1,
    }
    sur = fit(spec.unknowns, spec.lo, spec.hi, spec.harmonics, X, Y, Xh, Yh, meta)
    sur.meta["fit_wall_s"] = time.perf_counter() - t2
    store(sur, inputs, folder, notify)
    sur.meta["build_wall_s"] = time.perf_counter() - t0
    return sur


def build(
    spec: BuildSpec,
    executor: Executor | Callable[[], Executor | None] | None = None,
    progress: Callable[[int], None] | None = None,
    notify: tables.Notify | None = tables.to_stderr,
    refresh: bool = False,
) -> Surrogate:
    """The cached surrogate for ``spec``, or a new one (then stored). A damaged or stale
    entry is reported to ``notify`` in one line and rebuilt. ``executor``: runs the
    design (None: this process); a callable is called only when a build is needed (the
    caller shuts down what it returns). The design's and the held-out runs go to the
    executor together (:func:`start`), so its workers do not wait for the design's last
    run before the held-out runs start."""
    got = start(spec, executor, progress, notify, refresh)
    return finish(got) if isinstance(got, Pending) else got


def store(
    sur: Surrogate, inputs: dict[str, Any], folder: Path, notify: tables.Notify | None = tables.to_stderr
) -> Path:
    """Write ``<key>.npz`` then its sidecar (atomic; data first; if that fails, ``notify``
    gets one line and the surrogate is used uncached, tables.write_entry)."""
    key = tables.table_key(inputs)
    path = folder / f"{key}.npz"
    data = io.npz_bytes({"X": sur.X, "Y": sur.Y, "cv": sur.cv, "kappa": sur.kappa, "Xh": sur.Xh, "Yh": sur.Yh})
    side = io.sidecar_bytes(
        path,
        inputs,
        "gearwear diagnose surrogate (RBF thin-plate spline over a Sobol design of dynamics.simulate runs)",
        {
            "npz_sha256": hashlib.sha256(data).hexdigest(),
            "heldout": sur.heldout,
            "periodicity_residual_max": sur.meta.get("periodicity_residual_max"),
            "training_runs": sur.meta.get("training_runs"),
        },
    )
    tables.write_entry(key, LABEL, {path: data, Path(str(path) + ".json"): side}, notify)
    return path


def lookup(inputs: dict[str, Any], unknowns: list[Unknown], folder: Path) -> tuple[Surrogate | None, str | None]:
    """(surrogate, None) on a valid entry, (None, None) without one, (None, reason) for an
    entry that must not be used (checked: sidecar of these inputs, the npz's SHA-256,
    array shapes, finite values)."""
    path, meta, reason = tables.entry(folder, tables.table_key(inputs), ".npz")
    if meta is None:
        return None, reason
    raw, why = read_bounded(path, "file", tables.ENTRY_LIMIT_BYTES)
    if raw is None:
        return None, why
    if hashlib.sha256(raw).hexdigest() != meta.get("npz_sha256"):
        return None, "does not match the npz_sha256 of its sidecar (changed after it was stored)"
    try:
        with np.load(_io.BytesIO(raw), allow_pickle=False) as z:
            arrays = {k: z[k] for k in ("X", "Y", "cv", "kappa", "Xh", "Yh")}
    except (OSError, ValueError, KeyError) as exc:
        return None, f"is not a valid surrogate ({type(exc).__name__})"
    K, d = inputs["harmonics"], len(unknowns)
    F = len(all_features(K))
    n = inputs["design_points"] + 2**d
    shapes = {
        "X": (n, d),
        "Y": (n, 2 * len(SIGNALS) * K + len(MEAN_SIGNALS)),
        "cv": (n, F),
        "kappa": (F,),
        "Xh": (inputs["holdout_points"], d),
        "Yh": (inputs["holdout_points"], 2 * len(SIGNALS) * K + len(MEAN_SIGNALS)),
    }
    for k, shape in shapes.items():
        if arrays[k].shape != shape:
            return None, f"has {k} of shape {arrays[k].shape}, expected {shape}"
        if not np.all(np.isfinite(arrays[k])):
            return None, f"has non-finite values in {k}"
    sur = Surrogate(
        unknowns,
        np.array(inputs["lo"]),
        np.array(inputs["hi"]),
        K,
        arrays["X"],
        arrays["Y"],
        arrays["cv"],
        arrays["kappa"],
        meta.get("heldout", {}),
        {"periodicity_residual_max": meta.get("periodicity_residual_max"), "training_runs": meta.get("training_runs")},
        from_cache=True,
        Xh=arrays["Xh"],
        Yh=arrays["Yh"],
    )
    return sur, None


def validate_range(raw: dict[str, Any], name: str, unknowns: list[Unknown], lo, hi) -> None:
    """Every corner of the prior box is a valid scene (one-line error naming the range flag
    otherwise), so a bad range stops before any simulation."""
    d = len(unknowns)
    for corner in corners(d):
        values = {u.short: (hi[j] if corner[j] else lo[j]) for j, u in enumerate(unknowns)}
        try:
            scene_at(raw, name, values)
        except InputError as exc:
            bad = next(
                (
                    u
                    for u in unknowns
                    if str(exc).startswith(u.scene_key.rsplit(".", 1)[0]) or str(exc).startswith(u.scene_key)
                ),
                None,
            )
            if bad is None:
                raise
            j = unknowns.index(bad)
            raise InputError(
                f"{bad.flag} = {lo[j]:g}:{hi[j]:g} {bad.unit}: at {values[bad.short]:g} {bad.unit} "
                f"the scene is refused ({exc})"
            ) from None
