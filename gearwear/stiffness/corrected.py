"""The atlas-corrected mesh stiffness: a surrogate of the pair FE over the atlas's design space,
applied to an analytic model's curve (issue 28, "a corrected model").

What it predicts
----------------
For a design d the atlas (gearwear.jobs.atlas) holds the pair FE with the blanks' torsion
taken out (``fem``) and every analytic model. With a *base* model B (an analytic model
that obeys the same similarity as the FE, see below) the surrogate interpolates the log ratios

    r_Z(d) = ln( K_Z,FE(d) / K_Z,B(d) ),   Z in {mean, lo, hi}

where ``lo`` and ``hi`` are the means over the kinematic zones with n0 = floor(epsilon)
and n0 + 1 pairs on the path (geometry.curves.CurveStats.zone_means; for 1 <= epsilon < 2
the single- and double-contact plateaus). The corrected curve is the base curve with each
angle's k_h multiplied by exp(r_hi) where n0 + 1 or more pairs carry load and by exp(r_lo)
where fewer do (the loaded count of the base curve, so the factors change where the base
curve already jumps); the loaded STE follows as F / k_h (unworn: Delta = F / k_h).

Descriptors (the surrogate's coordinates, :data:`DESCRIPTORS`)
--------------------------------------------------------------
z1, z2 / z1, alpha (deg), h_a*, x1, x2, ln(s_R1 / m), ln(s_R2 / m) with s_Ri = r_fi - bore_i,
and the load number ln(w / (E' m)), w = T / (r_b1 b) the line load (N/m), E' = E in plane
stress and E / (1 - nu^2) in plane strain. Similarity: in 2D linear elasticity with
frictionless contact, scaling every length by s at fixed w / (E' m) scales every
displacement by s and leaves k_h / (b E') unchanged (the Hertz half-width over the
module, a / m ~ sqrt(w / (E' m)), and the tip-corner gaps over the deflections are the
only load-dependent shapes). So the FE ratio is a function of these descriptors alone, for
any module and face width, as long as the base model obeys the same similarity: the
potential-energy family does (linear Hertz term 4 (1 - nu^2) / (pi E b), corner gaps that
scale with the teeth); Ishikawa's a F^0.9 does not and is never a base. Measured on the
23/47 pair at m 3 and 6 mm with the line load doubled: the pair FE's k_h / b agrees to
2.8e-6, the energy method's to 3.8e-5 (tests/test_corrected_model.py).

Interpolation and error
-----------------------
scipy.interpolate.RBFInterpolator, thin-plate spline with a linear polynomial, on the
descriptors scaled to the unit cube of the fitted designs, with a smoothing chosen from
:data:`SMOOTHINGS` by k-fold cross-validation (:func:`fit`). The out-of-sample error is
measured on designs held out of the fit (:func:`holdout_errors`), and published with the
atlas (reports/atlas).

Domain (:func:`check_domain`)
-----------------------------
A descriptor outside the range of the fitted designs is refused (one line: the key, the
value, the fitted range). Inside the box, a design farther (in unit-cube distance) from
every fitted design than the largest nearest-neighbour distance among them is in a gap of
the design (the atlas samples a rim shared by both gears, for example): a warning says by
how far. What the atlas held fixed (the tooth-root geometry h_f* - h_a* and rho*, equal
materials, Poisson's ratio, an unworn flank, no faults) is assumed and printed.
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from gearwear.core.validation import Field, fail_range

#: the surrogate's coordinates: (name, unit, what a refusal names); a name ``ln_*`` is the
#: logarithm of the quantity the refusal names and prints
#: ({s}, {l}: the index of the smaller and the larger gear in the pair, :func:`descriptors`)
DESCRIPTORS = (
    ("z1", "", "pair.teeth[{s}]"),
    ("ratio", "", "pair.teeth[{l}] / pair.teeth[{s}]"),
    ("pressure_angle_deg", "deg", "pair.pressure_angle_deg"),
    ("addendum_coefficient", "", "pair.addendum_coefficient"),
    ("x1", "", "pair.profile_shift[{s}]"),
    ("x2", "", "pair.profile_shift[{l}]"),
    ("ln_rim1_module", "", "gear {s} rim (r_f - bore) / m"),
    ("ln_rim2_module", "", "gear {l} rim (r_f - bore) / m"),
    ("ln_load_number", "", "load number w / (E' m), w = T / (r_b1 b)"),
)
#: the log ratios the surrogate interpolates (module docstring)
TARGETS = ("mean", "lo", "hi")
#: candidate smoothings of the thin-plate spline (0: interpolation), chosen by cross-validation
SMOOTHINGS = (0.0, 1e-4, 1e-3, 1e-2, 1e-1)
CV_FOLDS = 10
CV_SEED = 28
#: tolerance of the box check, as a fraction of each descriptor's fitted range
BOX_TOLERANCE = 1e-9
#: principal axes of the fitted designs with a singular value below this fraction of the
#: largest are directions the design does not span (Fit)
AXIS_TOLERANCE = 1e-6


def descriptors(pair, torque_Nm: float, plane: str = "stress") -> np.ndarray:
    """The :data:`DESCRIPTORS` of a pair at a driver torque (SI inputs, module docstring).

    "1" is the smaller gear whichever drives: the atlas samples a driving pinion (ratio
    >= 1), and the quantities the surrogate predicts, the mean and the zone means of k_h
    over a mesh period, are the same when the other gear drives (the same two flanks touch
    along the same path, run the other way; frictionless statics has no preferred sense).
    The line load w = T / (r_b b) is the same from either gear (the normal force over the
    face width)."""
    small, large = (0, 1) if pair.teeth[0] <= pair.teeth[1] else (1, 0)
    g1, g2 = pair.gear(small), pair.gear(large)
    m = pair.module_m
    mat = pair.materials[0]
    E = mat.youngs_modulus_Pa / (1.0 - mat.poisson_ratio**2) if plane == "strain" else mat.youngs_modulus_Pa
    w = torque_Nm / (pair.gear(0).base_radius_m * pair.face_width_m)
    return np.array(
        [
            float(g1.teeth),
            g2.teeth / g1.teeth,
            math.degrees(pair.pressure_angle_rad),
            pair.addendum_coefficient,
            pair.profile_shift[small],
            pair.profile_shift[large],
            math.log((g1.root_radius_m - g1.hub_radius_m) / m),
            math.log((g2.root_radius_m - g2.hub_radius_m) / m),
            math.log(w / (E * m)),
        ]
    )


def zone_values(mean: float, single: float, double: float, epsilon: float) -> tuple[float, float]:
    """(lo, hi): the zone means with n0 = floor(epsilon) and n0 + 1 pairs on the path from the
    atlas's columns. For 1 <= epsilon < 2 they are (single, double); for 2 <= epsilon < 3 the
    lo zone is the double one and hi (three pairs) follows from the mean,
    mean = (3 - epsilon) K_2 + (epsilon - 2) K_3 (zone lengths over a period: CurveStats)."""
    n0 = math.floor(epsilon)
    if n0 == 1:
        return single, double
    if n0 == 2:
        s_hi = epsilon - 2.0
        return double, (mean - (1.0 - s_hi) * double) / s_hi if s_hi > 0 else math.nan
    return math.nan, math.nan


@dataclass(frozen=True)
class Fit:
    """A fitted surrogate: the box of the fitted designs (``lo``, ``hi`` per descriptor), one
    interpolant per target (None where no design had the target), the chosen smoothings and
    the largest nearest-neighbour distance among the fitted designs (unit cube). A
    descriptor the designs hold fixed is not a coordinate (``active`` False): it only bounds
    the domain. The interpolants work in ``axes``: the principal axes of the fitted designs
    in the unit cube about their centre ``centre``, without the directions the designs do not
    span (two descriptors the design ties together, like one rim for both gears, would make
    the spline's linear part singular); a query's distance off those axes counts in the
    gap check."""

    lo: np.ndarray
    hi: np.ndarray
    active: np.ndarray
    centre: np.ndarray
    axes: np.ndarray
    models: Mapping[str, Any]
    smoothing: Mapping[str, float]
    U: np.ndarray
    gap: float

    def unit(self, X) -> np.ndarray:
        """Descriptors -> the unit cube of the fitted designs (active descriptors only)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        a = self.active
        return (X[:, a] - self.lo[a]) / (self.hi[a] - self.lo[a])

    def coordinates(self, X) -> np.ndarray:
        """Descriptors -> the interpolants' coordinates (the principal axes)."""
        return (self.unit(X) - self.centre) @ self.axes

    def predict(self, X) -> dict[str, np.ndarray]:
        """Predicted log ratios per target at the designs ``X`` (NaN: target not fitted)."""
        C = self.coordinates(X)
        return {t: (m(C) if m is not None else np.full(len(C), np.nan)) for t, m in self.models.items()}


def _rbf(U: np.ndarray, y: np.ndarray, smoothing: float):
    from scipy.interpolate import RBFInterpolator

    return RBFInterpolator(U, y, kernel="thin_plate_spline", degree=1, smoothing=smoothing)


def _cv_error(U: np.ndarray, y: np.ndarray, smoothing: float) -> float:
    """Root-mean-square k-fold cross-validation error of the log ratio."""
    rng = np.random.default_rng(CV_SEED)
    folds = np.array_split(rng.permutation(len(y)), min(CV_FOLDS, len(y)))
    err = []
    for f in folds:
        keep = np.setdiff1d(np.arange(len(y)), f)
        err.append(_rbf(U[keep], y[keep], smoothing)(U[f]) - y[f])
    return float(np.sqrt(np.mean(np.concatenate(err) ** 2)))


def fit(X, Y: Mapping[str, np.ndarray]) -> Fit:
    """Fit one thin-plate spline per target of ``Y`` (log ratios; NaN where a design lacks
    the target) over descriptors ``X`` (designs x :data:`DESCRIPTORS`), each with the
    smoothing of :data:`SMOOTHINGS` of least cross-validation error."""
    X = np.asarray(X, dtype=float)
    lo, hi = X.min(axis=0), X.max(axis=0)
    active = hi > lo
    U = (X[:, active] - lo[active]) / (hi[active] - lo[active])
    centre = U.mean(axis=0)
    _, sv, Vt = np.linalg.svd(U - centre, full_matrices=False)
    axes = Vt[sv > AXIS_TOLERANCE * sv[0]].T
    C = (U - centre) @ axes
    models: dict[str, Any] = {}
    chosen: dict[str, float] = {}
    for t, y in Y.items():
        y = np.asarray(y, dtype=float)
        ok = np.isfinite(y)
        if ok.sum() < C.shape[1] + 2:
            models[t], chosen[t] = None, math.nan
            continue
        s = min(SMOOTHINGS, key=lambda s: _cv_error(C[ok], y[ok], s))
        models[t], chosen[t] = _rbf(C[ok], y[ok], s), s
    from scipy.spatial import cKDTree

    d, _ = cKDTree(U).query(U, k=2)
    return Fit(lo, hi, active, centre, axes, models, chosen, U, float(d[:, 1].max()))


def holdout_errors(X, Y: Mapping[str, np.ndarray], held: np.ndarray) -> dict[str, np.ndarray]:
    """Relative errors exp(r_pred - r) - 1 of the surrogate fitted without the designs
    ``held`` (a boolean mask), at those designs, per target (finite targets only)."""
    X = np.asarray(X, dtype=float)
    f = fit(X[~held], {t: np.asarray(y, float)[~held] for t, y in Y.items()})
    pred = f.predict(X[held])
    out = {}
    for t, y in Y.items():
        y = np.asarray(y, float)[held]
        ok = np.isfinite(y) & np.isfinite(pred[t])
        out[t] = np.expm1(pred[t][ok] - y[ok])
    return out


def check_domain(
    f: Fit,
    x: np.ndarray,
    warn: Callable[[str], None] | None = None,
    box: tuple[Any, Any] | None = None,
    small: int = 0,
) -> None:
    """Refuse a design outside the box (one line naming the descriptor, its value and the
    range); warn through ``warn`` when it lies in a gap of the fitted designs (module
    docstring). The box is the fitted designs' range, widened to ``box`` (lo, hi per
    descriptor: the atlas's design space, of which the sampled designs fill the inside
    only; a standard h_a* = 1 is at the edge of an axis [1, 1.4] no sample hits exactly) where given.
    ``small``: the index of the smaller gear in the pair (the keys a refusal names)."""
    x = np.asarray(x, dtype=float)
    lo, hi = f.lo.copy(), f.hi.copy()
    if box is not None:
        lo, hi = np.minimum(lo, np.asarray(box[0], dtype=float)), np.maximum(hi, np.asarray(box[1], dtype=float))
    span = hi - lo
    for i, (name, unit, key) in enumerate(DESCRIPTORS):
        tol = BOX_TOLERANCE * (span[i] if span[i] > 0 else max(abs(lo[i]), 1.0))
        if not (lo[i] - tol <= x[i] <= hi[i] + tol):
            show = np.exp if name.startswith("ln_") else float  # what the key names
            raise fail_range(
                key.format(s=small, l=1 - small),
                float(show(x[i])),
                Field(unit, float(show(lo[i])), float(show(hi[i]))),
                f"the range of the atlas the corrected model was fitted on ({name})",
            )
    if warn is not None:
        from scipy.spatial import cKDTree

        d = float(cKDTree(f.U).query(f.unit(x)[0])[0])
        if d > f.gap:
            warn(
                f"warning: this pair is {d:.3g} from the nearest atlas design (unit-cube distance; the "
                f"largest spacing among the fitted designs is {f.gap:.3g}): the corrected model extrapolates"
            )


def design_box(inputs: Mapping[str, Any]) -> tuple[list[float], list[float]]:
    """(lo, hi) of each descriptor over an atlas SPEC's axes (gearwear.jobs.atlas_spec keys
    ``axes.*``, ``pair.module_mm``, ``pair.youngs_modulus_GPa``, ``pair.poisson_ratio``,
    ``fe.plane``): the design space the sampled designs fill."""
    a = {k[len("axes.") :]: v for k, v in inputs.items() if k.startswith("axes.")}
    E = inputs["pair.youngs_modulus_GPa"] * 1e9
    if inputs["fe.plane"] == "strain":
        E /= 1.0 - inputs["pair.poisson_ratio"] ** 2
    m = inputs["pair.module_mm"] * 1e-3
    rim = [math.log(v) for v in a["rim_thickness_module"]]
    load = [math.log(v * 1e3 / (E * m)) for v in a["line_load_N_per_mm"]]
    cols = [
        a["pinion_teeth"],
        a["ratio"],
        a["pressure_angle_deg"],
        a["addendum_coefficient"],
        a["profile_shift"],
        a["profile_shift"],
        rim,
        rim,
        load,
    ]
    return [float(c[0]) for c in cols], [float(c[1]) for c in cols]


# -- the committed surrogate ----------------------------------------------------------------

DATA = Path(__file__).resolve().parents[1] / "data" / "atlas_corrected.json"


@functools.lru_cache(maxsize=None)
def committed() -> tuple[Fit, dict[str, Any]]:
    """The surrogate fitted on the committed atlas (gearwear/data/atlas_corrected.json: the
    descriptors and log ratios of every atlas design, the base model, what the atlas held
    fixed); refitted on first use (deterministic, well under a second)."""
    doc = json.loads(DATA.read_text())
    X = np.asarray(doc["descriptors"], dtype=float)
    f = fit(X, {t: np.asarray(doc["log_ratio"][t], dtype=float) for t in TARGETS})
    return f, doc


def corrected_curve(rq, warn: Callable[[str], None] | None = None):
    """The atlas-corrected curve of a stiffness Request (gearwear.stiffness.sources): the
    base model's curve with its k_h multiplied by exp(r_hi) where n0 + 1 or more pairs carry
    load and by exp(r_lo) elsewhere (exp(r_mean) for a zone the surrogate has no ratio
    for), the loaded STE F / k_h (module docstring). Refuses a worn flank, unequal
    materials or another Poisson's ratio or 2D state than the atlas's (the ratios were not
    fitted there) and a design outside the fitted box; ``warn`` (default: stderr) hears a
    design in a gap of the atlas. A bearing clearance moves the base curve; the ratios are
    those of the nominal centre distance the atlas used."""
    import dataclasses
    import sys

    from gearwear.core.validation import fail
    from gearwear.stiffness.sources import SOURCES

    f, doc = committed()
    held = doc["fixed"]
    if rq.wear is not None and not rq.wear.is_unworn:
        raise fail("effects.wear", "set", "", "the corrected model is fitted on unworn flanks only")
    m1, m2 = rq.pair.materials
    if m1 != m2:
        raise fail("pair.materials", "unequal", "", "the corrected model is fitted on pairs of one material")
    if abs(m1.poisson_ratio - held["poisson_ratio"]) > 1e-9:
        raise fail_range(
            "pair.poisson_ratio",
            m1.poisson_ratio,
            Field("", held["poisson_ratio"], held["poisson_ratio"]),
            "the Poisson's ratio of the atlas the corrected model is fitted on",
        )
    if rq.plane != held["plane"]:
        why = (
            f"the corrected model is fitted in plane {held['plane']} only (the atlas's FE): set "
            f"fem.plane = \"{held['plane']}\", or use --method fem"
        )
        raise fail("fem.plane", repr(rq.plane), "", why)
    x = descriptors(rq.pair, rq.torque_Nm, held["plane"])
    box = (doc["domain"]["lo"], doc["domain"]["hi"]) if "domain" in doc else None
    small = 0 if rq.pair.teeth[0] <= rq.pair.teeth[1] else 1
    check_domain(f, x, warn=warn or (lambda s: print(s, file=sys.stderr)), box=box, small=small)
    r = {t: float(v[0]) for t, v in f.predict(x).items()}
    base = SOURCES[doc["base_model"]].curve(rq)
    n0 = math.floor(base.mesh.contact_ratio)
    hi = r["hi"] if math.isfinite(r["hi"]) else r["mean"]
    lo = r["lo"] if math.isfinite(r["lo"]) else r["mean"]
    loaded = (np.asarray(base.pair_load_N) > 0).sum(axis=1)
    k = np.asarray(base.k_N_per_m) * np.exp(np.where(loaded >= n0 + 1, hi, lo))
    F = rq.torque_Nm / rq.pair.gear(0).base_radius_m
    meta = {**base.meta, "corrected": {"base_model": doc["base_model"], "log_ratio": r, "atlas": doc["atlas"]}}
    return dataclasses.replace(base, method="corrected", k_N_per_m=k, ste_m=F / k, meta=meta)
