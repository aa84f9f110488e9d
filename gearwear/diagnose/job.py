"""``gearwear diagnose``: wear depth, bearing clearance (and torque) from a measured vibration.

The composition: the scene fixes everything known; the unknowns
(gearwear.diagnose.surrogate.UNKNOWNS) get a prior range; a cached surrogate of the
6-DOF model over them predicts the measured features (gearwear.diagnose.features); the
posterior on a grid gives estimates and 95 % intervals under the stated noise model
(gearwear.diagnose.posterior); the identifiability verdict says which unknown the
measurement cannot resolve and which measurement would.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gearwear.diagnose import posterior as dp
from gearwear.diagnose.features import MEAN_SIGNALS, SIGNALS, Feature, all_features, feature_name, time_series_features
from gearwear.diagnose.surrogate import Surrogate, error_multiplicity

GRID_POINTS = {1: 401, 2: 101, 3: 41}  # per axis and zoom stage


@dataclass
class Fit:
    """A measurement fitted against a surrogate."""

    sur: Surrogate
    features: list[Feature]
    idx: np.ndarray  # their columns in the surrogate's features
    y: np.ndarray  # measured values
    var_noise: np.ndarray  # measurement-noise variances
    multiplicity: float
    post: dp.GridPosterior
    summary: dict[str, Any]

    @property
    def names(self) -> list[str]:
        return [u.name for u in self.sur.unknowns]

    def variance(self, theta) -> np.ndarray:
        """Total variance of the measured features at theta (m, F_measured)."""
        return self.var_noise + self.multiplicity * self.sur.error(theta, columns=self.idx) ** 2

    def estimate(self) -> np.ndarray:
        return np.array([self.summary["estimates"][n]["value"] for n in self.names])


def log_likelihood(sur: Surrogate, idx: np.ndarray, y: np.ndarray, var_noise: np.ndarray, mult: float):
    """theta (m, d) -> -1/2 sum (f_i(theta) - y_i)^2 / (var_noise_i + mult s_i(theta)^2)."""

    def logpost(theta: np.ndarray) -> np.ndarray:
        out = np.empty(len(theta))
        for a in range(0, len(theta), 8192):
            th = theta[a : a + 8192]
            v = var_noise + mult * sur.error(th, columns=idx) ** 2
            out[a : a + 8192] = -0.5 * np.sum((sur.predict(th)[:, idx] - y) ** 2 / v, axis=1)
        return out

    return logpost


def fit(sur: Surrogate, values: dict[Feature, float], rel: float, floor_frac: float) -> Fit:
    """The posterior of the unknowns given the measured feature values."""
    all_f = sur.features
    feats = [f for f in all_f if f in values]
    idx = np.array([all_f.index(f) for f in feats])
    y = np.array([values[f] for f in feats])
    var_noise = dp.noise_variance(feats, y, rel, floor_frac)
    mult = error_multiplicity(len(feats))
    post = dp.grid_posterior(
        log_likelihood(sur, idx, y, var_noise, mult), sur.lo, sur.hi, GRID_POINTS[len(sur.unknowns)]
    )
    return Fit(
        sur, feats, idx, y, var_noise, mult, post, dp.summarise(post, [u.name for u in sur.unknowns], sur.lo, sur.hi)
    )


# -- identifiability ----------------------------------------------------------------------


def candidate_groups(measured: list[Feature], harmonics: int) -> list[tuple[str, list[Feature]]]:
    """Measurements one could add: the mean of a displacement or force (a time series instead
    of a harmonic table), the harmonics of another signal, and all four signals as time series."""
    have = set(measured)
    groups: list[tuple[str, list[Feature]]] = []
    for s in MEAN_SIGNALS:
        if (s, 0) not in have:
            how = "the same record as a time series" if any(f[0] == s for f in have) else f"a time series of {s}"
            groups.append((f"the mean of {s} ({how})", [(s, 0)]))
    for s in SIGNALS:
        if not any(f[0] == s and f[1] > 0 for f in have):
            groups.append((f"the harmonics of {s}", [(s, k) for k in range(1, harmonics + 1)]))
    every = all_features(harmonics)
    if any(f not in have for f in every):
        groups.append(("time series of all four signals (y_p_um, x_p_um, delta_um, F_m_N)", every))
    return groups


def expected_widths(
    sur: Surrogate,
    theta: np.ndarray,
    feats: list[Feature],
    rel: float,
    floor_frac: float,
    measured_var: dict[Feature, float] | None = None,
) -> dict[str, np.ndarray]:
    """Cramer-Rao widths (fractions of the prior) at theta for measuring ``feats``: the
    surrogate's sensitivities, the noise model on the predicted values (or the given
    variances of features already measured) and the surrogate error."""
    all_f = sur.features
    idx = np.array([all_f.index(f) for f in feats])
    pred = sur.predict(theta[None, :])[0, idx]
    var = dp.noise_variance(feats, pred, rel, floor_frac)
    if measured_var:
        var = np.array([measured_var.get(f, v) for f, v in zip(feats, var)])
    var = var + error_multiplicity(len(feats)) * sur.error(theta[None, :], columns=idx)[0] ** 2
    J = dp.jacobian(lambda th: sur.predict(th)[:, idx], theta, sur.lo, sur.hi)
    return dp.fisher_widths(J, var, sur.hi - sur.lo)


def verdict(ft: Fit, rel: float, floor_frac: float) -> dict[str, Any]:
    """identifiable (each unknown -> bool), per-unknown reasons and advice, and one text."""
    sur, names = ft.sur, ft.names
    est = ft.estimate()
    here = expected_widths(sur, est, ft.features, rel, floor_frac, dict(zip(ft.features, ft.var_noise)))
    corr = ft.summary["correlation"]
    ident: dict[str, bool] = {}
    details: dict[str, Any] = {}
    lines = []
    for j, u in enumerate(sur.unknowns):
        e = ft.summary["estimates"][u.name]
        frac = e["interval_fraction_of_prior"]
        ok = frac <= dp.RESOLVED_FRACTION
        ident[u.name] = bool(ok)
        d: dict[str, Any] = {
            "interval_fraction_of_prior": frac,
            "cramer_rao_fraction": float(here["marginal"][j]),
            "cramer_rao_fraction_others_known": float(here["conditional"][j]),
        }
        span = f"{e['lo95']:.3g}-{e['hi95']:.3g} {u.unit}, {100 * frac:.0f} % of the prior range"
        if ok:
            lines.append(f"{u.name} = {e['value']:.3g} {u.unit} (95 %: {span}): resolved.")
        else:
            others = [k for k in range(len(names)) if k != j]
            partner = max(others, key=lambda k: abs(corr[j, k])) if others else None
            if partner is not None and here["conditional"][j] <= dp.RESOLVED_FRACTION:
                d["reason"] = "trade-off"
                d["trades_off_with"] = names[partner]
                known = names[partner] if len(others) == 1 else "the other unknowns"
                why = (
                    f"it trades off with {names[partner]} (posterior correlation {corr[j, partner]:+.2f}); "
                    f"with {known} known it would span {100 * here['conditional'][j]:.0f} % (Cramer-Rao)"
                )
            else:
                d["reason"] = "insensitive"
                c = here["conditional"][j]
                extent = f"spans {100 * c:.0f} % of" if c <= 1 else "is wider than"
                why = (
                    "the measured features hardly respond to it "
                    f"(even with the other unknowns known, the Cramer-Rao 95 % interval {extent} the prior range)"
                )
            advice = resolving_measurement(sur, est, ft, j, rel, floor_frac)
            d["would_resolve"] = advice
            lines.append(
                f"{u.name} cannot be resolved from this measurement (95 %: {span}): {why}. "
                + (
                    f"Measuring {advice['measurement']} would resolve it (expected 95 % interval "
                    f"{100 * advice['expected_fraction_of_prior']:.0f} % of the prior range, Cramer-Rao "
                    "at the estimate)."
                    if advice.get("measurement")
                    else "No other signal at this speed and torque would resolve it; measure at another "
                    "operating point (gearwear diagnose --plan SCENE ranks speeds and torques)."
                )
            )
        details[u.name] = d
    return {"identifiable": ident, "details": details, "verdict": " ".join(lines)}


def resolving_measurement(
    sur: Surrogate, est: np.ndarray, ft: Fit, j: int, rel: float, floor_frac: float
) -> dict[str, Any]:
    """The smallest added measurement (of :func:`candidate_groups`; fewest new features,
    then one of a signal already measured, then the narrowest interval) whose Cramer-Rao
    interval for unknown j reaches RESOLVED_FRACTION; {} if none does."""
    measured_var = dict(zip(ft.features, ft.var_noise))
    have = {s for s, _ in ft.features}
    found = []
    for label, group in candidate_groups(ft.features, sur.harmonics):
        new = [f for f in group if f not in measured_var]
        w = float(expected_widths(sur, est, ft.features + new, rel, floor_frac, measured_var)["marginal"][j])
        if w <= dp.RESOLVED_FRACTION:
            found.append((len(new), not all(s in have for s, _ in new), w, label))
    if not found:
        return {}
    _, _, w, label = min(found)
    return {"measurement": label, "expected_fraction_of_prior": w}


# -- synthetic measurements (blind tests, the example) -----------------------------------


def synthetic_features(
    raw: dict[str, Any],
    name: str,
    truth: dict[str, float],
    harmonics: int,
    columns: list[str],
    means: bool,
    rel: float,
    rng: np.random.Generator,
    floor_frac: float = 0.0,
) -> dict[Feature, float]:
    """A "measurement" from the full model (``simulate`` with the scene's own solver) at the
    truth (unknown short name -> value): the harmonics (and, with ``means``, the mean
    values) of the sampled signals ``columns`` over the kept window, computed as for a
    measured CSV, then each multiplied by (1 + rel eps), eps ~ N(0, 1) independent, plus
    floor_frac times the signal's largest harmonic times another N(0, 1)."""
    from gearwear.diagnose.surrogate import scene_at
    from gearwear.jobs.simulate import run

    r = run(scene_at(raw, name, truth)).result
    cols = {c: r.signals[SIGNALS[c][0]] * SIGNALS[c][1] for c in columns}
    vals, _ = time_series_features(r.t, cols, r.fm_Hz, harmonics)
    if not means:
        vals = {f: v for f, v in vals.items() if f[1] > 0}
    return perturb(vals, rel, floor_frac, rng)


def perturb(
    values: dict[Feature, float], rel: float, floor_frac: float, rng: np.random.Generator
) -> dict[Feature, float]:
    """The noise model's measurement noise applied to exact features (in their order)."""
    feats = list(values)
    y = np.array([values[f] for f in feats])
    sd = np.sqrt(dp.noise_variance(feats, y, 0.0, floor_frac))
    out = y * (1 + rel * rng.standard_normal(y.size)) + sd * rng.standard_normal(y.size)
    out = np.where([k > 0 for _, k in feats], np.abs(out), out)  # an amplitude stays >= 0
    return dict(zip(feats, out.tolist()))


# -- the result document ------------------------------------------------------------------


def feature_rows(ft: Fit) -> list[dict[str, Any]]:
    est = ft.estimate()
    fitted = ft.sur.predict(est[None, :])[0, ft.idx]
    s = ft.sur.error(est[None, :], columns=ft.idx)[0]
    tot = np.sqrt(ft.variance(est[None, :])[0])
    return [
        {
            "feature": feature_name(f),
            "signal": f[0],
            "harmonic": f[1],
            "measured": float(y),
            "fitted": float(fv),
            "sigma_noise": float(np.sqrt(vn)),
            "sigma_surrogate": float(np.sqrt(ft.multiplicity) * si),
            "residual_over_sigma": float((y - fv) / t),
        }
        for f, y, fv, vn, si, t in zip(ft.features, ft.y, fitted, ft.var_noise, s, tot)
    ]


def document(
    ft: Fit, ver: dict[str, Any], meas_info: dict[str, Any], rel: float, floor_frac: float, scene_name: str
) -> dict[str, Any]:
    """diagnosis.json (no wall times: those go to timing.json and --json)."""
    sur = ft.sur
    rows = feature_rows(ft)
    return {
        "scene": scene_name,
        "measured": meas_info,
        "unknowns": ft.names,
        "prior": {
            u.name: {"lo": float(a), "hi": float(b), "unit": u.unit, "distribution": "uniform"}
            for u, a, b in zip(sur.unknowns, sur.lo, sur.hi)
        },
        "estimates": {n: {k: ft.summary["estimates"][n][k] for k in ("value", "lo95", "hi95")} for n in ft.names},
        "posterior": {
            n: {k: v for k, v in ft.summary["estimates"][n].items() if k not in ("value", "lo95", "hi95")}
            for n in ft.names
        },
        "posterior_correlation": ft.summary["correlation"].tolist(),
        "identifiable": ver["identifiable"],
        "verdict": ver["verdict"],
        "identifiability": ver["details"],
        "noise_model": {
            "relative": rel,
            "floor_fraction_of_largest_harmonic": floor_frac,
            "surrogate_error_multiplicity": ft.multiplicity,
            "variance": "(relative * measured)^2 + (floor * largest harmonic of the signal)^2 "
            "+ multiplicity * surrogate_error(theta)^2",
            "distribution": "Gaussian, independent features",
        },
        "surrogate": {
            "design_points": int(len(sur.X)),
            "heldout": sur.heldout,
            "periodicity_residual_max": sur.meta.get("periodicity_residual_max"),
            "interpolation": "scipy RBFInterpolator, thin-plate spline + linear",
        },
        "grid": {"stages": ft.post.stages, "points_per_axis": int(ft.post.axes[0].size)},
        "chi2_per_feature": float(np.mean([r["residual_over_sigma"] ** 2 for r in rows])),
        "features": rows,
    }
