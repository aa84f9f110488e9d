"""The stiffness atlas, read: every analytic model's error against the pair FE over the design
space, where each model can be trusted, and the atlas-corrected model (issue 28).

Input: a ``gearwear atlas`` folder (atlas.csv, one row per design and model, and its sidecar;
gearwear.jobs.atlas). The reference is the pair FE with the blanks' torsion taken out
(model ``fem``: the mesh stiffness the analytic models describe, fem.pair "The blank's
torsion"); the bore-fixed FE (``fem_bore_fixed``) is reported beside it as one more row.

Errors per design (:func:`errors`): for the mean, the plateaus and the loaded STE
peak-to-peak the relative error model / FE - 1; for the fluctuation (the peak-to-peak and
the harmonics 1-3 of k_h) the difference over the FE *mean*, (model - FE) / FE mean: near an
integer contact ratio the FE's own fluctuation tends to zero and an error relative to it
says nothing (hundreds of % on a harmonic of 1 % of the mean), while the fluctuation over
the mean is the parametric excitation depth the dynamics see; for the transition angles the
difference model - FE in degrees of pinion rotation. A metric a model does not give is left
out, never zero: a zone the pair does not have, and every fluctuation metric of a model
whose curve is a constant over the whole atlas (ISO 6336's c_gamma: its peak-to-peak is
zero on every design, :func:`constant_models`). Summaries: median, 95th percentile and
maximum of |error|, and the signed median (the bias).

Which model where (:func:`which_model_where`): the designs split by contact ratio
(below 1.6, 1.6-2, 2 and above), rim (s_R / m below 3: thin; 3 and above) and load (line load
below and above 200 N/mm); in each cell the model of least median |error| of the mean.

The corrected model (gearwear.stiffness.corrected): fitted on a seeded 80 % of the designs and
checked on the other 20 % (:func:`corrected_holdout`), beside every analytic model's error on
the same held-out designs; then fitted on every design and exported
(:func:`corrected_data`, gearwear/data/atlas_corrected.json).
"""

from __future__ import annotations

import csv
import io as _io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from gearwear.jobs.atlas_metrics import METRICS

REFERENCE = "fem"
BORE_FIXED = "fem_bore_fixed"
#: the atlas's metrics (gearwear.jobs.atlas_metrics) compared as differences (the transition
#: angles, deg) and as ratios (relative error: every other one)
ANGLES = tuple(m for m in METRICS if m.endswith("_deg"))
RELATIVE = tuple(m for m in METRICS if m not in ANGLES)
#: the fluctuation of k_h: compared over the FE mean (module docstring)
BY_MEAN = ("p2p_N_per_m", "h1_N_per_m", "h2_N_per_m", "h3_N_per_m")
#: what a constant curve does not give (module docstring)
FLUCTUATION = (*BY_MEAN, "ste_p2p_um", *ANGLES)
#: the design axes the maps show: (column, label, log axis)
AXES = (
    ("z1", "pinion teeth z1", False),
    ("ratio", "ratio z2 / z1", False),
    ("pressure_angle_deg", "pressure angle (deg)", False),
    ("addendum_coefficient", "addendum h_a*", False),
    ("x1", "pinion shift x1", False),
    ("x2", "gear shift x2", False),
    ("rim_thickness_module", "rim s_R / m", True),
    ("line_load_N_per_mm", "line load (N/mm)", True),
    ("contact_ratio", "contact ratio", False),
)
#: the base model of the corrected one: the potential-energy method obeys the similarity the
#: corrected model's coordinates rest on (gearwear.stiffness.corrected)
BASE_MODEL = "energy"
HOLDOUT_FRACTION = 0.2
HOLDOUT_SEED = 28
CONTACT_BANDS = ((0.0, 1.6, "eps < 1.6"), (1.6, 2.0, "1.6 <= eps < 2"), (2.0, math.inf, "eps >= 2"))
RIM_BANDS = ((0.0, 3.0, "thin rim (s_R/m < 3)"), (3.0, math.inf, "rim s_R/m >= 3"))
LOAD_BANDS = ((0.0, 200.0, "w < 200 N/mm"), (200.0, math.inf, "w >= 200 N/mm"))


class Table:
    """atlas.csv by design: ``design`` (the designs' columns, one value per design) and
    ``metric[model][metric]`` (one value per design, NaN where empty)."""

    def __init__(self, text: str):
        rows = list(csv.DictReader(_io.StringIO(text)))
        if not rows:
            raise ValueError("atlas.csv has no rows")
        first_metric = list(rows[0]).index("model") + 1
        self.metrics = list(rows[0])[first_metric:]
        self.design_columns = list(rows[0])[: first_metric - 1]
        order = sorted({int(r["design"]) for r in rows})
        at = {d: i for i, d in enumerate(order)}
        self.models = list(dict.fromkeys(r["model"] for r in rows))
        n = len(order)
        self.design: dict[str, np.ndarray] = {c: np.full(n, np.nan) for c in self.design_columns}
        self.metric = {m: {k: np.full(n, np.nan) for k in self.metrics} for m in self.models}
        for r in rows:
            i = at[int(r["design"])]
            for c in self.design_columns:
                self.design[c][i] = float(r[c])
            for k in self.metrics:
                self.metric[r["model"]][k][i] = float(r[k]) if r[k] != "" else math.nan
        self.design["ratio"] = self.design["z2"] / self.design["z1"]
        self.n = n

    @property
    def analytic(self) -> list[str]:
        return [m for m in self.models if m not in (REFERENCE, BORE_FIXED)]


def constant_models(t: Table) -> list[str]:
    """The models whose k_h peak-to-peak is zero on every design they give (a constant)."""
    out = []
    for m in t.models:
        p2p = t.metric[m]["p2p_N_per_m"]
        p2p = p2p[np.isfinite(p2p)]
        if p2p.size and not np.any(p2p):
            out.append(m)
    return out


def errors(t: Table) -> dict[str, dict[str, np.ndarray]]:
    """model -> metric -> error per design against ``fem`` (module docstring; NaN: not given)."""
    ref = t.metric[REFERENCE]
    constant = constant_models(t)
    out: dict[str, dict[str, np.ndarray]] = {}
    for m in [*t.analytic, BORE_FIXED]:
        out[m] = {}
        for k in RELATIVE:
            with np.errstate(divide="ignore", invalid="ignore"):
                if k in BY_MEAN:
                    out[m][k] = (t.metric[m][k] - ref[k]) / ref["mean_N_per_m"]
                else:
                    out[m][k] = t.metric[m][k] / ref[k] - 1.0
        for k in ANGLES:
            out[m][k] = t.metric[m][k] - ref[k]
        if m in constant:
            for k in FLUCTUATION:
                out[m][k] = np.full(t.n, np.nan)
    return out


def stats(e: np.ndarray) -> dict[str, float]:
    """median, p95 and max of |e|, the signed median and the count (finite values)."""
    e = e[np.isfinite(e)]
    if e.size == 0:
        return {"n": 0}
    a = np.abs(e)
    return {
        "n": int(e.size),
        "median_abs": float(np.median(a)),
        "p95_abs": float(np.percentile(a, 95)),
        "max_abs": float(a.max()),
        "median_signed": float(np.median(e)),
    }


def summary(errs: dict[str, dict[str, np.ndarray]]) -> dict[str, dict[str, dict[str, float]]]:
    return {m: {k: stats(v) for k, v in per.items()} for m, per in errs.items()}


def _bands(values: np.ndarray, bands) -> list[tuple[str, np.ndarray]]:
    return [(label, (values >= lo) & (values < hi)) for lo, hi, label in bands]


def which_model_where(t: Table, errs: dict[str, dict[str, np.ndarray]], metric: str = "mean_N_per_m") -> list[dict]:
    """One row per cell of (contact ratio, rim, load) bands with designs: the best and the
    second model by median |error| of ``metric``, their median and p95."""
    rows = []
    for c_label, c in _bands(t.design["contact_ratio"], CONTACT_BANDS):
        for r_label, r in _bands(t.design["rim_thickness_module"], RIM_BANDS):
            for w_label, w in _bands(t.design["line_load_N_per_mm"], LOAD_BANDS):
                cell = c & r & w
                if not cell.any():
                    continue
                ranked = []
                for m in t.analytic:
                    s = stats(errs[m][metric][cell])
                    if s["n"]:
                        ranked.append((s["median_abs"], m, s))
                ranked.sort()
                rows.append(
                    {
                        "contact": c_label,
                        "rim": r_label,
                        "load": w_label,
                        "designs": int(cell.sum()),
                        "best": ranked[0][1],
                        "best_median_abs": ranked[0][0],
                        "best_p95_abs": ranked[0][2]["p95_abs"],
                        "second": ranked[1][1] if len(ranked) > 1 else "",
                        "second_median_abs": ranked[1][0] if len(ranked) > 1 else math.nan,
                    }
                )
    return rows


def binned_error(x: np.ndarray, e: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Median of ``e`` in each bin of ``x`` (NaN for a bin with fewer than 5 designs)."""
    out = np.full(len(edges) - 1, np.nan)
    for i in range(len(edges) - 1):
        s = (x >= edges[i]) & (x <= edges[i + 1] if i == len(edges) - 2 else x < edges[i + 1]) & np.isfinite(e)
        if s.sum() >= 5:
            out[i] = np.median(e[s])
    return out


def refusals(side: dict[str, Any]) -> dict[str, dict[str, int]]:
    """Per model, how many designs it refused (outside its stated validity) and failed on,
    from the sidecar's notes (gearwear.jobs.atlas: "refused: ..." / "failed: ...")."""
    out: dict[str, dict[str, int]] = {}
    for model, per in (side.get("notes") or {}).items():
        lines = list(per.values()) if isinstance(per, dict) else list(per)
        out[model] = {
            "refused": sum(str(x).startswith("refused") for x in lines),
            "failed": sum(str(x).startswith("failed") for x in lines),
        }
    return out


# -- failure modes ---------------------------------------------------------------------------

#: what each model leaves out or assumes, from its definition (docs/models.md); the atlas
#: measures what that costs (:func:`failure_modes`)
MECHANISMS = {
    "ishikawa": "a sliced cantilever of the true tooth clamped at the root circle, Weber's foundation, "
    "Weber's Hertz term; the bore and rim are not seen",
    "energy": "the potential energy of the true tooth (fillet included) clamped at the root circle, Sainsot's "
    "foundation (which sees the bore only through r_f / r_bore), linear Hertz",
    "yang_lin": "the involute alone, clamped at the base circle, no shear, no foundation: where r_b > r_f "
    "(few teeth) the material between the circles is missing and the tooth is short and stiff; where r_f > r_b "
    "(many teeth) it hangs on a slender involute neck reaching r_f - r_b into the body",
    "tian": "as Yang & Lin with shear: clamped at the base circle (too short where r_b > r_f, on an involute "
    "neck through the body where r_f > r_b), no foundation",
    "wu_zuo_parey": "Tian's tooth clamped at the base circle on Sainsot's foundation, taken there (the paper "
    "puts the root circle on the base circle): where r_f > r_b (many teeth: the wheels of high ratios) the "
    "tooth hangs on a slender involute neck reaching r_f - r_b into the body, and the foundation acts below it",
    "chen_shao": "the involute clamped at the root circle (a straight segment below the base circle, no "
    "fillet), Sainsot's foundation, linear Hertz",
    "chen_shao_weber": "as Chen & Shao with Weber's foundation instead of Sainsot's (Weber's ignores the bore)",
    "kuang_yang": "a regression of FE teeth in the tooth count, the shift and the contact radius, for "
    "12-100 teeth (it refuses a gear outside); no pressure angle, addendum, rim or load term",
    "iso6336": "one constant: c_gamma of ISO 6336-1 method B (the basic rack and webs enter through C_B and "
    "C_R; a solid disc with a bore has C_R = 1); no fluctuation",
    BORE_FIXED: "not a model: the same FE with the bores held fixed, so the blanks' torsion between "
    "bore and teeth adds in series (the value a test rig with rigid shafts would measure)",
}


def explanatory_axes(t: Table, inputs: dict[str, Any]) -> dict[str, tuple[str, np.ndarray]]:
    """The design axes a failure mode is sought along: the atlas's axes (:data:`AXES`), the
    height of the base circle above the root circle, max over both gears of (r_b - r_f) / m
    (the material a base-clamped model leaves out; negative where r_f > r_b), and the height
    of the root circle above the base circle, max over both gears of (r_f - r_b) / m (the
    gear body a base-clamped model counts as an involute neck of the tooth: the wheel's,
    in most pairs)."""
    out = {col: (label, t.design[col]) for col, label, _ in AXES}
    gaps = np.array([[(g.base_radius_m - g.root_radius_m) / p.module_m for g in p.gears] for p in pairs_of(t, inputs)])
    out["base_above_root_module"] = ("base circle above root circle (r_b - r_f) / m, max of both gears", gaps.max(1))
    out["root_above_base_module"] = ("root circle above base circle (r_f - r_b) / m, max of both gears", -gaps.min(1))
    return out


def failure_modes(
    t: Table, inputs: dict[str, Any], errs: dict[str, dict[str, np.ndarray]], metric: str = "mean_N_per_m"
) -> list[dict[str, Any]]:
    """Per model: its bias (signed median of ``metric``'s error), the design axis its error
    follows most closely (largest |Spearman rank correlation|), and the median error in the
    lowest and highest quarter of that axis. The numbers only: the mechanism is
    :data:`MECHANISMS`, written from each model's definition, not fitted."""
    from scipy.stats import spearmanr

    axes = explanatory_axes(t, inputs)
    out = []
    for m in [*t.analytic, BORE_FIXED]:
        e = errs[m][metric]
        ok = np.isfinite(e)
        if ok.sum() < 8:
            continue
        ranked = []
        for col, (label, x) in axes.items():
            if np.ptp(x[ok]) > 0 and np.ptp(e[ok]) > 0:  # a constant has no rank correlation
                rho = float(spearmanr(x[ok], e[ok]).statistic)
                ranked.append((abs(rho), col, label, rho))
        row = {
            "model": m,
            "designs": int(ok.sum()),
            "median_signed": float(np.median(e[ok])),
            "p95_abs": float(np.percentile(np.abs(e[ok]), 95)),
            "mechanism": MECHANISMS.get(m, ""),
        }
        if not ranked:
            out.append({**row, "axis": None})
            continue
        ranked.sort(reverse=True)
        _, col, label, rho = ranked[0]
        x = axes[col][1][ok]
        q1, q3 = np.percentile(x, [25, 75])
        out.append(
            {
                **row,
                "axis": col,
                "axis_label": label,
                "spearman": rho,
                "q1": float(q1),
                "q3": float(q3),
                "median_low": float(np.median(e[ok][x <= q1])),
                "median_high": float(np.median(e[ok][x >= q3])),
            }
        )
    return out


# -- the corrected model -------------------------------------------------------------------


def pairs_of(t: Table, inputs: dict[str, Any]):
    """The PairSpec of every design (from its columns and the atlas SPEC's material)."""
    from gearwear.geometry.spec import Material, PairSpec

    mat = Material(
        youngs_modulus_Pa=inputs["pair.youngs_modulus_GPa"] * 1e9, poisson_ratio=inputs["pair.poisson_ratio"]
    )
    d = t.design
    out = []
    for i in range(t.n):
        out.append(
            PairSpec(
                teeth=(int(d["z1"][i]), int(d["z2"][i])),
                module_m=d["module_mm"][i] * 1e-3,
                pressure_angle_rad=math.radians(d["pressure_angle_deg"][i]),
                face_width_m=d["face_width_mm"][i] * 1e-3,
                addendum_coefficient=d["addendum_coefficient"][i],
                dedendum_coefficient=d["dedendum_coefficient"][i],
                rack_tip_radius_coefficient=d["rack_tip_radius_coefficient"][i],
                profile_shift=(d["x1"][i], d["x2"][i]),
                hub_radius_m=(d["bore1_mm"][i] * 1e-3, d["bore2_mm"][i] * 1e-3),
                materials=(mat, mat),
            )
        )
    return out


def log_ratios(t: Table, model: str) -> dict[str, np.ndarray]:
    """ln(FE / model) of the mean and of the lo and hi zone means (corrected.zone_values)."""
    from gearwear.stiffness.corrected import zone_values

    out = {"mean": np.log(t.metric[REFERENCE]["mean_N_per_m"] / t.metric[model]["mean_N_per_m"])}
    lo, hi = np.full(t.n, np.nan), np.full(t.n, np.nan)
    for i in range(t.n):
        eps = t.design["contact_ratio"][i]
        f, b = t.metric[REFERENCE], t.metric[model]
        zf = zone_values(f["mean_N_per_m"][i], f["single_N_per_m"][i], f["double_N_per_m"][i], eps)
        zm = zone_values(b["mean_N_per_m"][i], b["single_N_per_m"][i], b["double_N_per_m"][i], eps)
        with np.errstate(divide="ignore", invalid="ignore"):
            lo[i], hi[i] = np.log(zf[0] / zm[0]), np.log(zf[1] / zm[1])
    out["lo"], out["hi"] = lo, hi
    return out


def descriptors_of(t: Table, inputs: dict[str, Any]) -> np.ndarray:
    from gearwear.stiffness.corrected import descriptors

    return np.array([descriptors(p, T, inputs["fe.plane"]) for p, T in zip(pairs_of(t, inputs), t.design["torque_Nm"])])


def held_out(n: int) -> np.ndarray:
    rng = np.random.default_rng(HOLDOUT_SEED)
    mask = np.zeros(n, bool)
    mask[rng.permutation(n)[: int(round(HOLDOUT_FRACTION * n))]] = True
    return mask


def corrected_holdout(t: Table, inputs: dict[str, Any], errs: dict[str, dict[str, np.ndarray]]) -> dict[str, Any]:
    """The corrected model fitted without the held-out designs: its relative error of the
    mean and of the zone means there, beside each analytic model's on the same designs."""
    from gearwear.stiffness.corrected import holdout_errors

    X = descriptors_of(t, inputs)
    Y = log_ratios(t, BASE_MODEL)
    ok = np.isfinite(Y["mean"])
    held = held_out(t.n) & ok
    e = holdout_errors(X[ok], {k: v[ok] for k, v in Y.items()}, held[ok])
    analytic = {m: stats(errs[m]["mean_N_per_m"][held]) for m in t.analytic}
    best = min(analytic, key=lambda m: analytic[m].get("median_abs", math.inf))
    return {
        "base_model": BASE_MODEL,
        "fitted_designs": int((ok & ~held).sum()),
        "held_out_designs": int(held.sum()),
        "corrected": {k: stats(v) for k, v in e.items()},
        "analytic_mean_error_on_held_out": analytic,
        "best_analytic": best,
    }


def corrected_data(t: Table, inputs: dict[str, Any], atlas_name: str) -> dict[str, Any]:
    """gearwear/data/atlas_corrected.json: the descriptors and log ratios of every design
    with a finite FE mean, the base model, what the atlas held fixed."""
    from gearwear.stiffness.corrected import DESCRIPTORS, design_box

    X = descriptors_of(t, inputs)
    Y = log_ratios(t, BASE_MODEL)
    ok = np.isfinite(Y["mean"])
    return {
        "atlas": atlas_name,
        "base_model": BASE_MODEL,
        "descriptors_names": [d[0] for d in DESCRIPTORS],
        "descriptors": X[ok].tolist(),
        "domain": dict(zip(("lo", "hi"), design_box(inputs))),
        "log_ratio": {k: [None if not math.isfinite(x) else float(x) for x in v[ok]] for k, v in Y.items()},
        "fixed": {
            "plane": inputs["fe.plane"],
            "poisson_ratio": inputs["pair.poisson_ratio"],
            "dedendum_margin": inputs.get("pair.dedendum_margin"),
            "rack_tip_radius_coefficient": inputs.get("pair.rack_tip_radius_coefficient"),
        },
    }


# -- the figures -----------------------------------------------------------------------------


def _error_label(metric: str) -> str:
    if metric in ANGLES:
        return "model - FE (deg)"
    return "(model - FE) / FE mean (%)" if metric in BY_MEAN else "model / FE - 1 (%)"


def error_figure(t: Table, errs: dict[str, dict[str, np.ndarray]]):
    """Box plots of the signed error per model, one panel per metric."""
    from gearwear.plotting import subplots

    metrics = [*RELATIVE, *ANGLES]
    models = [*t.analytic, BORE_FIXED]
    fig, axes = subplots(2, 5, figsize=(17, 7.5), layout="constrained", squeeze=False)
    for ax, k in zip(axes.ravel(), metrics):
        scale = 100.0 if k in RELATIVE else 1.0
        data, names = [], []
        for m in models:
            v = errs[m][k][np.isfinite(errs[m][k])] * scale
            if v.size:
                data.append(v)
                names.append(m)
        if data:
            # vertical boxes: matplotlib >= 3.11 deprecates vert=, < 3.10 has no orientation=
            ax.boxplot(data, whis=(5, 95), showfliers=True, flierprops={"markersize": 2})
            ax.set_xticks(range(1, len(names) + 1), names, fontsize=7, rotation=60, ha="right")
        ax.axhline(0.0, color="k", lw=0.6)
        if k in RELATIVE:  # errors of a few % next to several hundred %: linear within 10 %
            ax.set_yscale("symlog", linthresh=10.0)
        ax.set_title(k.replace("_N_per_m", "").replace("_um", "").replace("_deg", ""), fontsize=9)
        ax.set_ylabel(_error_label(k), fontsize=8)
        ax.tick_params(labelsize=7)
    fig.suptitle(
        f"Error against the pair FE (blanks' torsion excluded), {t.n} designs: box 25-75 %, whiskers 5-95 %",
        fontsize=10,
    )
    return fig


def map_figure(t: Table, errs: dict[str, dict[str, np.ndarray]], metric: str = "mean_N_per_m"):
    """The signed error of ``metric`` over each design axis: every design (points) and the
    binned median (line) of each model."""
    from gearwear.plotting import legend_outside, subplots

    models = [*t.analytic, BORE_FIXED]
    fig, axes = subplots(3, 3, figsize=(15, 11), layout="constrained", squeeze=False)
    colors = {m: f"C{i % 10}" for i, m in enumerate(models)}
    for ax, (col, label, log) in zip(axes.ravel(), AXES):
        x = t.design[col]
        edges = np.geomspace(x.min(), x.max(), 9) if log else np.linspace(x.min(), x.max(), 9)
        mid = np.sqrt(edges[1:] * edges[:-1]) if log else 0.5 * (edges[1:] + edges[:-1])
        for m in models:
            e = 100.0 * errs[m][metric]
            ax.plot(x, e, ".", ms=1.5, color=colors[m], alpha=0.25)
            ax.plot(mid, binned_error(x, e, edges), "-", lw=1.4, color=colors[m], label=m)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_yscale("symlog", linthresh=10.0)  # a few % next to several hundred %
        if log:
            from matplotlib.ticker import NullFormatter, ScalarFormatter

            ax.set_xscale("log")
            ax.xaxis.set_major_formatter(ScalarFormatter())
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(label, fontsize=8)
        ax.set_ylabel(_error_label(metric), fontsize=8)
        ax.tick_params(labelsize=7)
    legend_outside(axes[0, 2], fontsize=7)
    fig.suptitle(f"{metric}: error over the design axes (points: designs; lines: median in 8 bins)", fontsize=10)
    return fig


# -- the document --------------------------------------------------------------------------


def analyse(folder: Path) -> dict[str, Any]:
    """Everything the atlas report holds, from an atlas folder."""
    t = Table((folder / "atlas.csv").read_text())
    side = json.loads((folder / "atlas.csv.json").read_text())
    errs = errors(t)
    return {
        "table": t,
        "errors": errs,
        "inputs": side["inputs"],
        "sidecar": side,
        "summary": summary(errs),
        "where": which_model_where(t, errs),
        "corrected": corrected_holdout(t, side["inputs"], errs),
        "failures": failure_modes(t, side["inputs"], errs),
        "refusals": refusals(side),
        "constant": constant_models(t),
    }


def _pct(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{100 * x:.1f}"


def summary_markdown(doc: dict[str, Any]) -> str:
    """The table of model errors: one row per model, median / p95 / max |error| (%) per metric."""
    lines = [
        "| model | "
        + " | ".join(k.replace("_N_per_m", "").replace("_um", "") + ("\\*" if k in BY_MEAN else "") for k in RELATIVE)
        + " | entry, exit (deg) |",
        "|---" * (len(RELATIVE) + 2) + "|",
    ]
    for m, per in doc["summary"].items():
        cells = []
        for k in RELATIVE:
            s = per[k]
            cells.append(
                "-" if not s["n"] else f"{_pct(s['median_abs'])} / {_pct(s['p95_abs'])} / {_pct(s['max_abs'])}"
            )
        ang = [per[k] for k in ANGLES]
        cells.append(
            "-"
            if not all(a["n"] for a in ang)
            else ", ".join(f"{a['median_abs']:.2f} / {a['p95_abs']:.2f}" for a in ang)
        )
        lines.append(f"| `{m}` | " + " | ".join(cells) + " |")
    n = doc["table"].n
    lines += [
        "",
        f"Median / p95 / max of |error| in % over the {n} designs (entry, exit: median / p95 of |model - FE| in "
        "degrees of pinion rotation). \\* the peak-to-peak and the harmonics of k_h as (model - FE) / FE mean. "
        "The reference is the pair FE with the blanks' torsion taken out; `fem_bore_fixed` is the same FE with "
        "the bores fixed, for scale. \"-\": not given"
        + (f" (`{'`, `'.join(doc['constant'])}` is a constant: no fluctuation)" if doc["constant"] else "")
        + ".",
    ]
    ref = doc.get("refusals") or {}
    said = [
        f"`{m}` refused {r['refused']} and failed on {r['failed']}"
        for m, r in ref.items()
        if r["refused"] or r["failed"]
    ]
    if said:
        lines += ["", "Designs a model did not give (outside its stated validity): " + "; ".join(said) + "."]
    return "\n".join(lines) + "\n"


def failures_markdown(doc: dict[str, Any]) -> str:
    """The failure modes in words: each model's mechanism and what the atlas measures it costs."""
    lines = []
    for f in doc["failures"]:
        if f["axis"] is None:
            lines.append(
                f"- **`{f['model']}`** ({f['mechanism']}). Over {f['designs']} designs its mean k_h is off by "
                f"{_pct(f['median_signed'])} % on every design alike."
            )
            continue
        trend = "rises" if f["median_high"] > f["median_low"] else "falls"
        lines.append(
            f"- **`{f['model']}`** ({f['mechanism']}). Over {f['designs']} designs its mean k_h is "
            f"{'too stiff' if f['median_signed'] > 0 else 'too soft'} by {_pct(abs(f['median_signed']))} % "
            f"(median; p95 of |error| {_pct(f['p95_abs'])} %). The error follows {f['axis_label']} most closely "
            f"(Spearman {f['spearman']:+.2f}): it {trend} from {_pct(f['median_low'])} % where that axis is at or "
            f"below {f['q1']:.3g} to {_pct(f['median_high'])} % at or above {f['q3']:.3g} (medians of the lowest "
            "and highest quarter)."
        )
    return "\n".join(lines) + "\n"


def corrected_markdown(doc: dict[str, Any]) -> str:
    """The corrected model's held-out error beside every analytic model's on the same designs."""
    c = doc["corrected"]
    rows = [
        f"Fitted on {c['fitted_designs']} designs, checked on the {c['held_out_designs']} held out of the fit "
        f"(a seeded {round(100 * HOLDOUT_FRACTION)} %); |error| of the mean k_h against the FE, in %:",
        "",
        "| model | median | p95 | max | bias (signed median) |",
        "|---|---|---|---|---|",
    ]
    s = c["corrected"]["mean"]
    rows.append(
        f"| **corrected** (on `{c['base_model']}`) | {_pct(s['median_abs'])} | {_pct(s['p95_abs'])} | "
        f"{_pct(s['max_abs'])} | {_pct(s['median_signed'])} |"
    )
    for m, s in sorted(c["analytic_mean_error_on_held_out"].items(), key=lambda kv: kv[1].get("median_abs", 9e9)):
        if not s["n"]:
            continue
        best = " (best analytic)" if m == c["best_analytic"] else ""
        few = "" if s["n"] == c["held_out_designs"] else f" (on the {s['n']} it gives)"
        rows.append(
            f"| `{m}`{best}{few} | {_pct(s['median_abs'])} | {_pct(s['p95_abs'])} | {_pct(s['max_abs'])} | "
            f"{_pct(s['median_signed'])} |"
        )
    z = c["corrected"]
    rows += [
        "",
        f"The zone means on the same held-out designs: fewer pairs (lo) {_pct(z['lo']['median_abs'])} / "
        f"{_pct(z['lo']['p95_abs'])} %, more pairs (hi) {_pct(z['hi']['median_abs'])} / {_pct(z['hi']['p95_abs'])} % "
        "(median / p95 of |error|).",
    ]
    return "\n".join(rows) + "\n"


def where_markdown(doc: dict[str, Any]) -> str:
    lines = [
        "| contact ratio | rim | load | designs | best model (median / p95 of mean error, %) | next |",
        "|---|---|---|---|---|---|",
    ]
    for r in doc["where"]:
        lines.append(
            f"| {r['contact']} | {r['rim']} | {r['load']} | {r['designs']} | `{r['best']}` "
            f"({_pct(r['best_median_abs'])} / {_pct(r['best_p95_abs'])}) | "
            f"`{r['second']}` ({_pct(r['second_median_abs'])}) |"
        )
    return "\n".join(lines) + "\n"


def write(doc: dict[str, Any], out: Path) -> list[Path]:
    """summary.json, errors.md, where.md, errors.png, map_mean.png, map_p2p.png in ``out``."""
    from gearwear import io

    out.mkdir(parents=True, exist_ok=True)
    t, errs = doc["table"], doc["errors"]
    files = [
        io.write_json(
            out / "summary.json",
            {
                "designs": t.n,
                "summary": doc["summary"],
                "where": doc["where"],
                "corrected": doc["corrected"],
                "failures": doc["failures"],
                "refusals": doc["refusals"],
                "constant_models": doc["constant"],
            },
        ),
        io.write_text(out / "errors.md", summary_markdown(doc)),
        io.write_text(out / "where.md", where_markdown(doc)),
        io.write_text(out / "failures.md", failures_markdown(doc)),
        io.write_text(out / "corrected.md", corrected_markdown(doc)),
        io.write_figure(error_figure(t, errs), out / "errors.png"),
        io.write_figure(map_figure(t, errs, "mean_N_per_m"), out / "map_mean.png"),
        io.write_figure(map_figure(t, errs, "p2p_N_per_m"), out / "map_p2p.png"),
    ]
    return files


def main(argv: list[str] | None = None) -> int:
    """``python -m gearwear.reports.atlas ATLAS_DIR [--data PATH]``: the analysis of an atlas
    folder into ATLAS_DIR/analysis, and the corrected model's data (default:
    gearwear/data/atlas_corrected.json). make atlas runs it after gearwear atlas."""
    import argparse

    from gearwear import io
    from gearwear.stiffness.corrected import DATA

    ap = argparse.ArgumentParser(prog="python -m gearwear.reports.atlas", description=main.__doc__)
    ap.add_argument("atlas", type=Path, help="a gearwear atlas output folder (atlas.csv and its sidecar)")
    ap.add_argument("--data", type=Path, default=DATA, help=f"where the corrected model's data go (default: {DATA})")
    args = ap.parse_args(argv)
    doc = analyse(args.atlas)
    for f in write(doc, args.atlas / "analysis"):
        print(f"wrote {f}")
    name = args.atlas.resolve().name
    print(f"wrote {io.write_json(args.data, corrected_data(doc['table'], doc['inputs'], name))}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
