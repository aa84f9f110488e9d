"""``gearwear report paper``: regenerate every numerical figure of Zhang et al. (2019)
with this tool, and compare each of the paper's trend claims with our result.

Stiffness comes from the FE-calibrated tables (gearwear.stiffness.calibration); the dynamic
responses from the built-in paper scenes with ``mesh_stiffness.source = "calibrated"``.
Figures are named after the paper's (fig06_..., fig25_...). The paper's trend claims are data,
``gearwear/data/claims/paper.toml``; trends() checks each against the quantity it names.
"""

from __future__ import annotations

import json
import math
import tomllib
import textwrap
import sys
import time
from importlib import resources
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gearwear.analytic import TABLE_POINTS_PER_MESH_PERIOD
from gearwear.geometry.curves import harmonic_amplitudes
from gearwear.geometry.operating import operating_geometry
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import PHASE_DEPTHS_M, WearSpec

from gearwear import io
from gearwear.plotting import from_zero, legend_outside, range_text, subplots
from gearwear.jobs.simulate import signal_label

PHASES = ("unworn", "mild", "severe")
CLEARANCES_UM = (0.0, 20.0, 40.0, 60.0, 80.0, 100.0)
SIGNALS = (("y_p", "um", 1e6, "Y displacement of the pinion"), ("x_p", "um", 1e6, "X displacement of the pinion"),
           ("delta", "um", 1e6, "relative displacement delta"), ("F_m", "N", 1.0, "mesh force F_m"))
WEAR_FIGS = {"y_p": (7, 8), "x_p": (9, 10), "delta": (11, 12), "F_m": (13, 14)}
CLEAR_FIGS = {"y_p": (18, 19), "x_p": (20, 21), "delta": (22, 23), "F_m": (24, 25)}


# -- trend classification -----------------------------------------------------------

def classify(y) -> str:
    """increase | decrease | decrease-then-increase | increase-then-decrease | nonlinear | flat."""
    y = np.asarray(y, dtype=float)
    scale = max(np.max(np.abs(y)), 1e-300)
    span = float(np.ptp(y))
    # "flat": the whole change is below 0.5 % of the mean level AND of no consequence;
    # quantities with a large offset (centre distance) are judged by their own span
    if span <= 1e-9 * scale:
        return "flat"
    d = np.diff(y)
    tol = 1e-3 * span
    if np.all(d > -tol):
        return "increase"
    if np.all(d < tol):
        return "decrease"
    k = int(np.argmin(y))
    if 0 < k < len(y) - 1 and np.all(d[:k] < tol) and np.all(d[k:] > -tol):
        return "decrease-then-increase"
    k = int(np.argmax(y))
    if 0 < k < len(y) - 1 and np.all(d[:k] > -tol) and np.all(d[k:] < tol):
        return "increase-then-decrease"
    return "nonlinear"


def agrees(claim: str, found: str) -> str:
    if claim == found:
        return "agree"
    if claim == "nonlinear" and found in ("decrease-then-increase", "increase-then-decrease", "nonlinear"):
        return "agree"
    if claim in ("increase", "decrease") and found == "flat":
        return "disagree (flat)"
    return "disagree"


def change_text(y) -> str:
    """The values of a row, 5 significant digits (enough that the percentages of its "why"
    follow from them to 0.01 %); long sweeps: the ends and a few points between."""
    y = np.asarray(y, dtype=float)
    if len(y) > 7:
        y = y[np.unique(np.linspace(0, len(y) - 1, 6).round().astype(int))]
    return " -> ".join(f"{v:.5g}" for v in y)


# -- computation -----------------------------------------------------------------------

def _scene(base: str, sets: list[str]):
    from gearwear.scene.model import apply_overrides, builtin_scene_dict, scene_from_dict
    return scene_from_dict(apply_overrides(builtin_scene_dict(base), sets), name=base)


def compute(progress: Callable[[str], None] | None = None,
            notify: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Every number of the paper report. ``notify`` receives the cache's one-line notes
    (a damaged entry being recomputed); the FE calibration of a wear phase runs only
    when one of its tables is not in the cache."""
    from gearwear.stiffness import tables
    from gearwear.stiffness.calibration import Calibration, calibrated_table, run_fe
    from gearwear.jobs.simulate import run

    tables.cache_dir()  # a bad GEARWEAR_CACHE stops here, before any FE run
    say = progress or (lambda msg: None)
    note = notify or tables.to_stderr
    pair = default_pair()
    T = 40.0
    wears = {p: (None if p == "unworn" else WearSpec(phase=p)) for p in PHASES}
    fe_runs: dict[str, Calibration] = {}

    def calibration(p: str) -> Callable[[], Calibration]:
        def get() -> Calibration:
            if p not in fe_runs:  # with the FE error estimate: it goes into the table sidecars
                fe_runs[p] = run_fe(pair, wears[p])
                say(f"FE single-tooth compliance ({p})")
            return fe_runs[p]
        return get

    cal = {p: calibration(p) for p in PHASES}
    # wear study: the built-in wear scenes (10 um clearance, static coupling)
    tabs_wear, sims_wear = {}, {}
    for p in PHASES:
        tabs_wear[p] = calibrated_table(pair, wears[p], 10e-6, T, TABLE_POINTS_PER_MESH_PERIOD, calibration=cal[p],
                                        notify=note)
        say(f"calibrated table + FE pair ({p})")
        sims_wear[p] = run(_scene(f"paper-wear-{p}", ['effects.mesh_stiffness={source = "calibrated"}']))
        say(f"simulation, wear {p}")
    tabs_cl, sims_cl = {}, {}
    for c in CLEARANCES_UM:
        tabs_cl[c] = calibrated_table(pair, None, c * 1e-6, T, TABLE_POINTS_PER_MESH_PERIOD, calibration=cal["unworn"],
                                      notify=note)
        say(f"calibrated table + FE pair (clearance {c:g} um)")
        sims_cl[c] = run(_scene("paper-clearance", ['effects.mesh_stiffness={source = "calibrated"}',
                                                    f"effects.bearing_clearance.clearance_um={c}"]))
        say(f"simulation, clearance {c:g} um")
    cl_fine = np.linspace(0.0, 100.0, 21)
    geo = [operating_geometry(pair, c * 1e-6, T, 2.6e8, 50e-6) for c in cl_fine]
    return {"pair": pair, "tabs_wear": tabs_wear, "sims_wear": sims_wear, "tabs_cl": tabs_cl,
            "sims_cl": sims_cl, "cl_fine": cl_fine, "geo": geo, "cal": cal}


# -- figures ---------------------------------------------------------------------------

def _stiffness_fig(tabs: dict, labeler, title: str, zoom: bool = False):
    fig, ax = subplots(figsize=(8.5, 4.2))
    for key, tab in tabs.items():
        ang = np.degrees(tab.angle_rad)
        per = 360.0 / 30
        a2 = np.concatenate([ang, ang + per])
        k2 = np.concatenate([tab.k_N_per_m, tab.k_N_per_m])
        ax.plot(a2, k2 / 1e8, label=labeler(key))
    ax.set_xlabel("pinion angle (deg), two mesh periods; 0 = a pair enters at A")
    ax.set_ylabel("mesh stiffness k_h (1e8 N/m)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    legend_outside(ax)
    fig.tight_layout()
    return fig


def _response_fig(sims: dict, name: str, unit: str, scale: float, labeler, title: str):
    fig, (ax, ax2) = subplots(1, 2, figsize=(12, 4))
    for key, run in sims.items():
        r = run.result
        n = int(round(3 * r.fs_Hz / r.fm_Hz))
        ax.plot((r.t[:n] - r.t[0]) * 1e3, r.signals[name][:n] * scale, lw=0.9, label=labeler(key))
        f, A = r.spectrum(name)
        keep = (f >= 0.5 * r.fm_Hz) & (f <= 10.5 * r.fm_Hz)
        ax2.plot(f[keep], A[keep] * scale, lw=0.8, label=labeler(key))
    ax.set_xlabel("time (ms), three mesh periods")
    ax.set_ylabel(signal_label(name))
    ax2.set_xlabel("frequency (Hz), mean removed")
    ax2.set_ylabel(f"amplitude of {name} ({unit})")
    ax2.set_ylim(bottom=0)
    for a in (ax, ax2):
        a.grid(alpha=0.3)
    legend_outside(ax2)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def _harmonics_fig(x, xlabel, H: np.ndarray, unit: str, name: str, title: str, xticklabels=None):
    """H: (n_points, n_harmonics)."""
    nh = H.shape[1]
    ncol = 5 if nh > 4 else 4
    nrow = math.ceil(nh / ncol)
    fig, axs = subplots(nrow, ncol, figsize=(3.1 * ncol, 3.0 * nrow), squeeze=False)
    for k in range(nh):
        a = axs[k // ncol][k % ncol]
        a.plot(x, H[:, k], "o-", ms=4)
        from_zero(a, H[:, k])
        a.set_title(f"k = {k + 1} at 40 N m: {range_text(H[:, k])}", fontsize=8)
        a.set_xlabel(xlabel, fontsize=8)
        a.set_ylabel(textwrap.fill(signal_label(name, "harmonic k"), 32), fontsize=8)
        if xticklabels is not None:
            a.set_xticks(x)
            a.set_xticklabels(xticklabels, fontsize=8)
        a.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def figures(res: dict[str, Any]) -> dict[str, Any]:
    figs: dict[str, Any] = {}
    figs["fig06_stiffness_wear.png"] = _stiffness_fig(
        res["tabs_wear"], lambda p: f"{p} ({PHASE_DEPTHS_M[p] * 1e6:g} um max depth)",
        "Fig. 6: mesh stiffness per wear phase (FE-calibrated, 40 N m, 10 um clearance)")
    xw = np.arange(3)
    for name, unit, scale, desc in SIGNALS:
        f1, f2 = WEAR_FIGS[name]
        figs[f"fig{f1:02d}_{name}_wear.png"] = _response_fig(
            res["sims_wear"], name, unit, scale, lambda p: p, f"Fig. {f1}: {desc} per wear phase")
        H = np.array([res["sims_wear"][p].result.harmonics(name, 4) * scale for p in PHASES])
        figs[f"fig{f2:02d}_{name}_harmonics_wear.png"] = _harmonics_fig(
            xw, "wear phase (category)", H, unit, name, f"Fig. {f2}: harmonics of {desc} versus wear phase",
            xticklabels=list(PHASES))
    # Fig. 15: operating geometry versus clearance
    geo, c = res["geo"], res["cl_fine"]
    fig, axs = subplots(1, 4, figsize=(15, 3.6))
    data = [("centre distance (mm)", [g.centre_distance_m * 1e3 for g in geo]),
            ("operating pressure angle (deg)", [math.degrees(g.pressure_angle_rad) for g in geo]),
            ("contact line length (mm)", [g.contact_line_length_m * 1e3 for g in geo]),
            ("contact ratio (dimensionless)", [g.contact_ratio for g in geo])]
    for a, (lab, y) in zip(axs, data):
        a.plot(c, y, "o-", ms=3)
        a.set_xlabel("bearing clearance (um)")
        a.set_ylabel(lab)
        a.grid(alpha=0.3)
    fig.suptitle("Fig. 15: operating geometry versus bearing clearance (Eq. 11 with 40 N m, k_b = 2.6e8 N/m)")
    fig.tight_layout()
    figs["fig15_geometry_clearance.png"] = fig
    cl = np.array(CLEARANCES_UM)
    fig, ax = subplots(figsize=(6, 4))
    ax.plot(cl, [res["tabs_cl"][x].mean_N_per_m / 1e8 for x in CLEARANCES_UM], "o-")
    ax.set_xlabel("bearing clearance (um)")
    ax.set_ylabel("mean mesh stiffness (1e8 N/m)")
    ax.set_title("Fig. 16: average mesh stiffness versus clearance")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    figs["fig16_mean_stiffness_clearance.png"] = fig
    figs["fig17_stiffness_clearance.png"] = _stiffness_fig(
        res["tabs_cl"], lambda x: f"clearance {x:g} um", "Fig. 17: mesh stiffness versus bearing clearance")
    sel = {x: res["sims_cl"][x] for x in (CLEARANCES_UM[0], CLEARANCES_UM[len(CLEARANCES_UM) // 2], CLEARANCES_UM[-1])}
    for name, unit, scale, desc in SIGNALS:
        f1, f2 = CLEAR_FIGS[name]
        figs[f"fig{f1:02d}_{name}_clearance.png"] = _response_fig(
            sel, name, unit, scale, lambda x: f"{x:g} um", f"Fig. {f1}: {desc} versus bearing clearance")
        nh = 10 if name == "F_m" else 4
        H = np.array([res["sims_cl"][x].result.harmonics(name, nh) * scale for x in CLEARANCES_UM])
        figs[f"fig{f2:02d}_{name}_harmonics_clearance.png"] = _harmonics_fig(
            cl, "bearing clearance (um)", H, unit, name, f"Fig. {f2}: harmonics of {desc} versus bearing clearance")
    return figs


# -- trends ------------------------------------------------------------------------------

# Every row's "why" is generated from what that row measured: a sentence on the
# measured change (direction words from classify(), percent change between the named
# ends), the verdict in words (for a disagreement: what this tool finds instead of the
# claim), and only then a mechanism, and only one that explains the measured direction
# (MECHANISMS: the direction each text explains; the tests check every row against it).
# "rises by" / "falls by" are reserved for the measured sentence.

#: mechanism texts by key: (the direction of change they explain, text or format string)
MECHANISMS: dict[str, tuple[str, str]] = {
    "wear_gaps": ("decrease", "thinner teeth and, above all, wear gaps: the entering and leaving pairs carry no "
                              "load until the elastic approach closes their gaps"),
    "tips_compliant": ("decrease", "with the larger centre distance the contacts move toward the tips, where the "
                                   "teeth are more compliant"),
    "double_zone_shorter": ("decrease", "the double-contact share of the period shortens ({a:.3f} -> {b:.3f})"),
    "contact_ratio": ("decrease", "the contact ratio falls ({a:.4f} -> {b:.4f})"),
    "eq11": ("increase", "Eq. 11: C' grows with the clearance, {slope:.3g} mm per mm of clearance"),
    "cos_alpha": ("increase", "cos a' = (r_b1 + r_b2) / C' and C' grows"),
    "tips_fixed": ("decrease", "the tip circles are fixed while C' grows"),
    "pitch_radius": ("increase", "r_w = r_b / cos a' grows with a'; base and tip radii are machined dimensions"),
    "backlash": ("increase", "2 (r_b1 + r_b2)(inv a' - inv a) grows with C'"),
    "dead_zone": ("increase", "the shaft crosses the dead zone BC/2 before the bearing carries: "
                              "{slope:.3g} um per um of clearance"),
    "half_backlash": ("increase", "in contact delta = j_n/2 + F/k, and half the backlash grows {db:.1f} um "
                                  "over the same range"),
}


def _mech(key: str, **kw) -> tuple[str, str]:
    direction, text = MECHANISMS[key]
    return direction, text.format(**kw)


def _pct(a: float, b: float) -> str:
    """|change| from a to b in percent, 3 significant digits (absolute change if a = 0)."""
    if a == 0:
        return f"{abs(b - a):.3g} (from 0)"
    return f"{abs(100.0 * (b / a - 1.0)):.3g} %"


def describe_change(values, labels) -> str:
    """What ``values`` did from the first to the last label, in the words of
    classify(): "rises by 12.3 % (0 um -> 100 um)", "falls by ...", "falls by ... (a ->
    b), then rises by ... (b -> c)", "changes direction 3 times, net ...", "stays flat"."""
    y = np.asarray(values, dtype=float)
    labels = [str(x) for x in labels]
    found = classify(y)
    ends = f"({labels[0]} -> {labels[-1]})"
    if found == "increase":
        return f"rises by {_pct(y[0], y[-1])} {ends}"
    if found == "decrease":
        return f"falls by {_pct(y[0], y[-1])} {ends}"
    if found in ("decrease-then-increase", "increase-then-decrease"):
        k = int(np.argmin(y)) if found == "decrease-then-increase" else int(np.argmax(y))
        first, second = ("falls", "rises") if found == "decrease-then-increase" else ("rises", "falls")
        return (f"{first} by {_pct(y[0], y[k])} ({labels[0]} -> {labels[k]}), then {second} by "
                f"{_pct(y[k], y[-1])} ({labels[k]} -> {labels[-1]})")
    if found == "flat":
        return f"stays flat {ends}"
    d = np.diff(y)
    s = np.sign(d[np.abs(d) > 1e-3 * np.ptp(y)])
    turns = int(np.sum(s[1:] != s[:-1]))
    net = "up" if y[-1] > y[0] else "down"
    return f"changes direction {turns} times, net {net} {_pct(y[0], y[-1])} {ends}"


_CLAIM_WORDS = {"increase": "a rise", "decrease": "a fall", "decrease-then-increase": "a fall, then a rise",
                "increase-then-decrease": "a rise, then a fall", "nonlinear": "a nonlinear change", "flat": "no change"}


def _why(values, labels, claim: str, verdict: str, mechanisms=(), context: str = "") -> str:
    """The "why" of a trend row: the measured change, the verdict in words, the
    mechanisms that explain the measured direction, then neutral context."""
    found = classify(values)
    desc = describe_change(values, labels)
    if verdict == "agree":
        text = f"Measured: {desc}, as the paper says."
    else:
        text = f"Measured: {desc}; the paper claims {_CLAIM_WORDS.get(claim, claim)}, which this tool does not find."
    base = found.split("-")[0] if found in ("increase", "decrease") else found
    used = [t for d, t in mechanisms if d == base]
    if used:
        text += " Why: " + "; ".join(used) + "."
    if context:
        text += " " + context
    return text


def _modes_Hz(run) -> np.ndarray:
    """Distinct natural frequencies (Hz) of the linearised model of a run (its mean mesh stiffness)."""
    from gearwear.dynamics.model import linear_eigenfrequencies

    f = np.sort(linear_eigenfrequencies(run.model))
    keep = np.concatenate([[True], np.diff(f) > 1e-6 * f[-1]])
    return f[keep & (f > 0)]


def _harmonic_amplitude(tab, k: int) -> float:
    """Amplitude of the k-th mesh harmonic of a stiffness table over one mesh period (its
    piecewise-linear interpolant on its not necessarily uniform nodes, exact)."""
    return float(harmonic_amplitudes(tab.angle_rad, tab.k_N_per_m, tab.span_rad, k)[k - 1])


def _segments(tab) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(start, end, loaded pairs inside) of every segment of a periodic table. A
    breakpoint node holds the one-sided value without the pair that enters or leaves
    there (analytic.tvms), so inside a segment the count is the larger of its ends'."""
    x = np.r_[tab.angle_rad, tab.angle_rad[0] + tab.span_rad]
    n = np.r_[tab.pairs_in_contact, tab.pairs_in_contact[:1]]
    return x[:-1], x[1:], np.maximum(n[:-1], n[1:])


def _loaded_share(tab, pairs: int) -> float:
    """Fraction of the table's span with at least ``pairs`` loaded pairs."""
    a, b, n = _segments(tab)
    return float(np.sum((b - a)[n >= pairs]) / tab.span_rad)


def _zone_drops(base, worn) -> tuple[float, float]:
    """Mean of 1 - k_worn / k_base (%) over the angles where ``base`` has two or more
    loaded pairs and over the rest: both tables interpolated (periodic, linear) on the
    union of their nodes, the trapezoid rule on it."""
    P = base.span_rad
    x = np.union1d(base.angle_rad, worn.angle_rad)
    drop = 1 - (np.interp(x, worn.angle_rad, worn.k_N_per_m, period=P)
                / np.interp(x, base.angle_rad, base.k_N_per_m, period=P))
    xs, ds = np.r_[x, x[0] + P], np.r_[drop, drop[:1]]
    area, length = 0.5 * (ds[1:] + ds[:-1]) * np.diff(xs), np.diff(xs)
    a, _, n = _segments(base)
    dbl = n[np.clip(np.searchsorted(a, 0.5 * (xs[1:] + xs[:-1]), side="right") - 1, 0, n.size - 1)] >= 2
    return 100 * float(area[dbl].sum() / length[dbl].sum()), 100 * float(area[~dbl].sum() / length[~dbl].sum())


def _why_harmonic(name: str, k: int, runs: list, tables: list, labels: list) -> str:
    """Context of a harmonic row, from the runs it measured: k fm against the model's
    modes (first and last run) and the change of the same harmonic of the stiffness
    tables that drive the runs."""
    fm = runs[0].result.fm_Hz
    f = k * fm
    parts = []
    for lab, run in ((labels[0], runs[0]), (labels[-1], runs[-1])):
        modes = _modes_Hz(run)
        near = modes[int(np.argmin(np.abs(modes - f)))]
        if f < modes[0]:
            where = f"below the lowest mode {modes[0]:.0f} Hz"
        elif f > modes[-1]:
            where = f"above the highest mode {modes[-1]:.0f} Hz"
        else:
            j = int(np.searchsorted(modes, f))
            where = f"between the {modes[j - 1]:.0f} and {modes[j]:.0f} Hz modes"
        parts.append(f"{lab}: modes {', '.join(f'{m:.0f}' for m in modes)} Hz, {k} x fm = {f:.0f} Hz is {where} "
                     f"(nearest {near:.0f} Hz, {100 * abs(f / near - 1):.0f} % away)")
        if len(runs) == 1 or np.allclose(_modes_Hz(runs[0]), _modes_Hz(runs[-1]), rtol=0.02):
            parts[-1] = parts[-1].replace(f"{lab}: ", "")
            break
    a0, a1 = (_harmonic_amplitude(t, k) for t in (tables[0], tables[-1]))
    change = f"{100 * (a1 / a0 - 1):+.3g} %" if a0 > 0 else "n/a"
    return ("Context: " + "; ".join(parts) + f". Harmonic {k} of the stiffness table changes by {change} "
            f"({labels[0]} -> {labels[-1]}). Which response harmonic grows depends on that excitation and on the "
            "mode placement, which the paper's unstated inertias and damping set.")


# -- the claims (gearwear/data/claims/paper.toml) and what they are checked against ------

#: the directions a claim can name: the words of classify()
DIRECTIONS = ("increase", "decrease", "decrease-then-increase", "increase-then-decrease", "nonlinear", "flat")
_SIGNAL = {s[0]: s for s in SIGNALS}  # name -> (name, unit, scale, description)


def load_claims() -> list[dict[str, Any]]:
    """The paper's trend claims (``gearwear/data/claims/paper.toml``), one dict per row of
    the trends table, in its order: a harmonic family (``harmonics = {k = direction}``)
    becomes one claim per harmonic with its ``k``, ``claim`` and ``paper`` filled in."""
    text = resources.files("gearwear.data.claims").joinpath("paper.toml").read_text(encoding="utf-8")
    claims = []
    for entry in tomllib.loads(text)["claim"]:
        family = entry.pop("harmonics", None)
        if family is None:
            claims.append(entry)
            continue
        for k, direction in family.items():
            claims.append({**entry, "k": int(k), "claim": direction,
                           "paper": entry["paper"].format(k=int(k), direction=direction.replace("-", " "))})
    return claims


def _labels(res: dict[str, Any], study: str) -> list[str]:
    """The points of a study: wear phases, the simulated clearances, the fine clearance grid of Fig. 15."""
    if study == "wear":
        return list(PHASES)
    return [f"{x:g} um" for x in (CLEARANCES_UM if study == "clearance" else res["cl_fine"])]


def _runs_tables(res: dict[str, Any], study: str) -> tuple[list, list]:
    if study == "wear":
        return [res["sims_wear"][p] for p in PHASES], [res["tabs_wear"][p] for p in PHASES]
    return [res["sims_cl"][x] for x in CLEARANCES_UM], [res["tabs_cl"][x] for x in CLEARANCES_UM]


#: quantity name -> (study, values(res, claim)): what a claim's direction is checked against
QUANTITIES: dict[str, tuple[str, Callable[[dict[str, Any], dict[str, Any]], list[float]]]] = {}


def _quantity(name: str, study: str):
    def register(fn):
        QUANTITIES[name] = (study, fn)
        return fn
    return register


@_quantity("mean_stiffness_vs_wear", "wear")
def _mean_stiffness_wear(res, c):
    return [res["tabs_wear"][p].mean_N_per_m for p in PHASES]


@_quantity("harmonic_vs_wear", "wear")
def _harmonic_wear(res, c):
    scale = _SIGNAL[c["signal"]][2]
    return [res["sims_wear"][p].result.harmonics(c["signal"], 4)[c["k"] - 1] * scale for p in PHASES]


@_quantity("p2p_vs_wear", "wear")
def _p2p_wear(res, c):
    return [res["sims_wear"][p].result.stats[c["signal"]]["p2p"] * _SIGNAL[c["signal"]][2] for p in PHASES]


def _geometry(attr: str, fn: Callable[[Any], float]):
    @_quantity(f"{attr}_vs_clearance", "clearance_fine")
    def values(res, c):
        return [fn(g) for g in res["geo"]]
    return values


_geometry("centre_distance", lambda g: g.centre_distance_m * 1e3)
_geometry("pressure_angle", lambda g: math.degrees(g.pressure_angle_rad))
_geometry("contact_line_length", lambda g: g.contact_line_length_m * 1e3)
_geometry("contact_ratio", lambda g: g.contact_ratio)
_geometry("pitch_radius", lambda g: g.mesh.operating_pitch_radii_m[0] * 1e3)
_geometry("backlash", lambda g: g.backlash_m * 1e6)


@_quantity("max_stiffness_vs_clearance", "clearance")
def _max_stiffness_clearance(res, c):
    return [res["tabs_cl"][x].k_N_per_m.max() for x in CLEARANCES_UM]


@_quantity("mean_stiffness_vs_clearance", "clearance")
def _mean_stiffness_clearance(res, c):
    return [res["tabs_cl"][x].mean_N_per_m for x in CLEARANCES_UM]


@_quantity("double_zone_share_vs_clearance", "clearance")
def _double_zone_share(res, c=None):  # also the numbers of the mechanism double_zone_shorter
    return [_loaded_share(res["tabs_cl"][x], 2) for x in CLEARANCES_UM]


@_quantity("y_shift_vs_clearance", "clearance")
def _y_shift(res, c=None):
    return [abs(res["sims_cl"][x].result.stats["y_p"]["mean"]) * 1e6 for x in CLEARANCES_UM]


@_quantity("mean_delta_vs_clearance", "clearance")
def _mean_delta(res, c):
    return [res["sims_cl"][x].result.stats["delta"]["mean"] * 1e6 for x in CLEARANCES_UM]


@_quantity("harmonic_vs_clearance", "clearance")
def _harmonic_clearance(res, c):
    scale = _SIGNAL[c["signal"]][2]
    return [res["sims_cl"][x].result.harmonics(c["signal"], 10)[c["k"] - 1] * scale for x in CLEARANCES_UM]


@_quantity("p2p_vs_clearance", "clearance")
def _p2p_clearance(res, c):
    return [res["sims_cl"][x].result.stats[c["signal"]]["p2p"] * _SIGNAL[c["signal"]][2] for x in CLEARANCES_UM]


def _centre_distance_slope(res):
    C, c = QUANTITIES["centre_distance_vs_clearance"][1](res, {}), res["cl_fine"]
    return {"slope": (C[-1] - C[0]) / ((c[-1] - c[0]) * 1e-3) if c[-1] != c[0] else float("nan")}


def _double_zone_ends(res):
    dz = _double_zone_share(res)
    return {"a": dz[0], "b": dz[-1]}


def _dead_zone_slope(res):
    y = _y_shift(res)
    return {"slope": (y[-1] - y[0]) / (CLEARANCES_UM[-1] - CLEARANCES_UM[0])}


def _half_backlash(res):
    bl = np.interp(CLEARANCES_UM, res["cl_fine"], QUANTITIES["backlash_vs_clearance"][1](res, {}))
    return {"db": (bl[-1] - bl[0]) / 2}


#: mechanism key -> the numbers its text quotes, from the results (a key not here quotes none)
MECHANISM_PARAMS: dict[str, Callable[[dict[str, Any]], dict[str, float]]] = {
    "eq11": _centre_distance_slope,
    "double_zone_shorter": _double_zone_ends,
    "contact_ratio": lambda res: {"a": res["geo"][0].contact_ratio, "b": res["geo"][-1].contact_ratio},
    "dead_zone": _dead_zone_slope,
    "half_backlash": _half_backlash,
}


def _context_harmonic(res, c):
    study = QUANTITIES[c["quantity"]][0]
    runs, tabs = _runs_tables(res, study)
    return _why_harmonic(c["signal"], c["k"], runs, tabs, _labels(res, study))


def _context_stiffness_p2p(res, c):
    p2p_k = [float(np.ptp(res["tabs_wear"][p].k_N_per_m)) for p in PHASES]
    return ("Context: the peak-to-peak of the stiffness table changes by "
            f"{100 * (p2p_k[-1] / p2p_k[0] - 1):+.3g} % ({PHASES[0]} -> {PHASES[-1]}); the response also depends "
            "on the mode placement.")


def _context_bearings(res, c):
    sc = res["sims_cl"]
    bcf = [min(sc[x].result.bearing_contact_fraction.values()) for x in CLEARANCES_UM
           if sc[x].result.bearing_contact_fraction]
    if not bcf:
        return ""
    if min(bcf) >= 0.999:
        return (f"Context: the bearings stay pressed into their clearance in every run (lowest bearing contact "
                f"fraction {min(bcf):.3g}), so the clearance shifts the shafts and changes the dynamics only "
                "through the mesh geometry.")
    return f"Context: the bearings leave their contact (lowest bearing contact fraction {min(bcf):.3g})."


#: context name -> text computed from the results (after a claim's own context)
CONTEXTS: dict[str, Callable[[dict[str, Any], dict[str, Any]], str]] = {
    "harmonic_modes": _context_harmonic,
    "stiffness_p2p_wear": _context_stiffness_p2p,
    "bearings_pressed": _context_bearings,
}


def _row_zone_drops(res, c):
    """Where wear lowers the stiffness most: the double-tooth zone against the single."""
    dd, ds = _zone_drops(res["tabs_wear"]["unworn"], res["tabs_wear"][c["phase"]])
    ok = dd > ds
    double = f"{'loses' if dd >= 0 else 'gains'} {abs(dd):.1f} %"
    single = f"the single zone {'loses' if ds >= 0 else 'gains'} {abs(ds):.2f} %"
    why = (f"Measured: where the unworn pair shares the load with a second pair k_h {double} on average, "
           f"{single}" + (", as the paper says." if ok else "; the paper claims the larger change in the "
                                                             "double zone, which this tool does not find."))
    if ok:
        why += (" Why: wear is deepest near root and tip (large sliding), which are in contact only in the "
                "double zone; at the pitch point (single zone) it is zero.")
    return {"ours": f"mean drop double zone {dd:.1f} %, single zone {ds:.2f} %",
            "verdict": "agree" if ok else "disagree", "why": why}


def _row_nonlinearity(res, c):
    """How far the first four F_m harmonics bend away from a straight line over the clearances."""
    H4 = np.array([res["sims_cl"][x].result.harmonics("F_m", 4) for x in CLEARANCES_UM])
    lin = []
    for k in range(4):
        fit = np.polyval(np.polyfit(CLEARANCES_UM, H4[:, k], 1), CLEARANCES_UM)
        lin.append(float(np.max(np.abs(H4[:, k] - fit)) / max(np.ptp(H4[:, k]), 1e-300)))
    verdict = "agree" if min(lin) > 0.1 else "partly" if max(lin) > 0.1 else "disagree"
    bent = [k + 1 for k, v in enumerate(lin) if v > 0.1]
    why = (f"Measured: the largest deviation of a harmonic from its straight-line fit is {100 * max(lin):.0f} % of its "
           f"range (harmonic {int(np.argmax(lin)) + 1}); " + (
               "every one of the four bends by more than 10 %, as the paper says." if verdict == "agree" else
               f"harmonics {', '.join(map(str, bent))} bend by more than 10 %, the others are nearly straight."
               if verdict == "partly" else
               "all four are nearly straight lines (within 10 %); the paper claims a nonlinear change, which this "
               "tool does not find."))
    return {"ours": "largest deviation from a straight line, per harmonic: "
            + ", ".join(f"{100 * v:.0f} %" for v in lin) + " of its range", "verdict": verdict, "why": why}


def _row_top_harmonics(res, c):
    """Which three of the first ten F_m harmonics are largest (first run of a study)."""
    lab = c["study"]
    run = next(iter(res["sims_wear" if lab == "wear" else "sims_cl"].values()))
    r = run.result
    h = r.harmonics("F_m", 10)
    top = sorted(range(10), key=lambda k: -h[k])[:3]
    ok = bool(set(top) & {7, 8, 9})
    modes = _modes_Hz(run)
    top_f = ", ".join(f"{(k + 1) * r.fm_Hz:.0f}" for k in top)
    return {"ours": f"largest: {', '.join(f'{k + 1} x fm' for k in top)}", "verdict": "agree" if ok else "disagree",
            "why": (f"Measured: the largest harmonics are {', '.join(str(k + 1) for k in top)} x fm "
                    f"({top_f} Hz at f_m = {r.fm_Hz:.0f} Hz)" + (", as the paper says" if ok else
                                                                 "; the paper claims the 8th-10th, "
                                                                 "which this tool does not find")
                    + f"; the model's modes are {', '.join(f'{m:.0f}' for m in modes)} Hz (first run of the "
                      f"{lab} study); the mode nearest the largest harmonic is "
                      f"{modes[int(np.argmin(np.abs(modes - (top[0] + 1) * r.fm_Hz)))]:.0f} Hz. The paper's "
                      "resonance depends on its unstated masses, inertias and damping.")}


#: row name -> (the claim it evaluates, row(res, claim) -> ours, verdict, why): rows whose
#: test is their own computation rather than classify() of one quantity
ROWS: dict[str, tuple[str, Callable[[dict[str, Any], dict[str, Any]], dict[str, str]]]] = {
    "zone_drops": ("double > single", _row_zone_drops),
    "fm_harmonics_nonlinearity": ("nonlinear", _row_nonlinearity),
    "fm_top_harmonics": ("8-10 highest", _row_top_harmonics),
}


def trends(res: dict[str, Any]) -> list[dict[str, str]]:
    """The trends table: every claim of load_claims() against this tool's result."""
    rows: list[dict[str, str]] = []
    for c in load_claims():
        head = {"where": c["where"], "paper": c["paper"], "claim": c["claim"]}
        if "row" in c:
            rows.append({**head, **ROWS[c["row"]][1](res, c)})
            continue
        study, extract = QUANTITIES[c["quantity"]]
        values = extract(res, c)
        found = classify(values)
        verdict = agrees(c["claim"], found)
        mechanisms = [_mech(key, **MECHANISM_PARAMS.get(key, lambda res: {})(res)) for key in c.get("mechanisms", ())]
        context = " ".join(t for t in (c.get("context", ""),
                                       CONTEXTS[c["context_from"]](res, c) if "context_from" in c else "") if t)
        note = c.get("note", "")
        rows.append({**head, "ours": f"{found}: {change_text(values)}" + (f" {note}" if note else ""),
                     "verdict": verdict, "why": _why(values, _labels(res, study), c["claim"], verdict, mechanisms,
                                                     context)})
    return rows


# -- markdown ---------------------------------------------------------------------------

def markdown(res: dict[str, Any], rows: list[dict[str, str]], figs: list[str]) -> str:
    pair = res["pair"]
    n_agree = sum(r["verdict"] == "agree" for r in rows)
    L = ["# Reproduction of Zhang et al. (2019) with gearwear", "",
         "Every numerical figure of the paper regenerated with this tool (`gearwear report paper`). Stiffness: "
         "FE-calibrated tables (Ishikawa model with the tooth compliance corrected to the full-gear FE and a "
         "per-contact-state factor from the FE tooth-pair contact); dynamics: the 6-DOF model with the paper's "
         "typos fixed. Wear study: built-in scenes `paper-wear-unworn|mild|severe` (40 N m, 1200 rpm, 10 um "
         "clearance, 50 um initial backlash, static centre distance); clearance study: `paper-clearance` "
         f"(unworn) at {', '.join(f'{c:g}' for c in CLEARANCES_UM)} um.", "",
         f"Trend claims: {len(rows)}, of which {n_agree} agree with this tool.", "",
         "## Trends: the paper versus this tool", "",
         "| where | paper says | this tool finds | verdict | why |", "|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r['where']} | {r['paper']} | {r['ours']} | {r['verdict']} | {r['why']} |")
    L += ["", "## Assumed parameters (not given in the paper)", "",
          "| quantity | value |", "|---|---|",
          f"| face width | {pair.face_width_m * 1e3:g} mm |",
          f"| Young's modulus, Poisson, density | {pair.materials[0].youngs_modulus_Pa / 1e9:g} GPa, "
          f"{pair.materials[0].poisson_ratio:g}, {pair.materials[0].density_kg_per_m3:g} kg/m^3 |",
          f"| basic rack | h_a* {pair.addendum_coefficient:g}, h_f* {pair.dedendum_coefficient:g}, "
          f"rho_f* {pair.rack_tip_radius_coefficient:g} |",
          f"| hub (bore) radius | {pair.hub_radius_m[0] * 1e3:g} mm |",
          "| wear phases (max depth on the pinion flank, Archard shape) | unworn 0, mild 10 um, severe 30 um |",
          "| damping ratios | mesh 0.05, bearings 0.02 |",
          "| inertia | J = m r^2 / 2 (solid disc at the pitch radius) |",
          "| initial backlash | 50 um (total normal) |",
          "| bearing clearance in the wear study | 10 um (total radial play BC) |", "",
          "## Corrections to the paper's equations", "",
          "* Eq. 2 (garbled): read as Castigliano on the slice cantilever, including the sin^2 w x_F^2 term.",
          "* Eq. 1: the square root is half the Hertz contact width; Eq. 1 = I_h (2 a |zeta|) N.",
          "* Eq. 11: BC is the total radial play of each bearing (dead zones of half-width BC/2 in Eqs. 7-10).",
          "* Eq. 15: normal backlash 2 C cos(a)(inv a' - inv a); the printed form uses C' "
          "(switch `form = \"printed\"`).",
          "* Eq. 17: the gear's torsion uses the output torque T_g = T_p R_g / R_p and R_g.",
          "* Eq. 19: no damping force through a backlash gap (switch `damping_in_gap = true` for the literal form).",
          "* Eq. 20: the third branch is delta < -b.", "", "## Figures", ""]
    for f in figs:
        L += [f"![{f}]({f})", ""]
    return "\n".join(L) + "\n"


def provenance(res: dict[str, Any]) -> dict[str, Any]:
    """What the report was made from: the resolved scene of every simulation (by its
    SHA-256, see gearwear.io.scene_inputs) and the fixed study parameters."""
    scenes = {f"wear {p}": io.scene_inputs(res["sims_wear"][p].scene)["scene_sha256"] for p in PHASES}
    scenes.update({f"clearance {c:g} um": io.scene_inputs(res["sims_cl"][c].scene)["scene_sha256"]
                   for c in CLEARANCES_UM})
    return {"report": "paper", "phases": list(PHASES), "clearances_um": list(CLEARANCES_UM),
            "table_points": 360, "torque_Nm": 40.0, "scene_sha256": scenes}


def write(res: dict[str, Any], out: Path) -> list[Path]:
    """The figures, README.md and trends.json into the folder ``out`` (no wall times)."""
    figs = figures(res)
    rows = trends(res)
    files = []
    for name, fig in figs.items():
        files.append(io.write_figure(fig, out / name, dpi=110))
    files.append(io.write_text(out / "README.md", markdown(res, rows, list(figs))))
    files.append(io.write_text(out / "trends.json", json.dumps(rows, indent=1) + "\n"))
    return files


def run_report(out: Path, progress: bool = True) -> list[Path]:
    """Compute the report and write it into ``out`` as a whole (gearwear.io.write_folder:
    complete or absent, replacing an earlier report; the run time goes to timing.json)."""
    from tqdm import tqdm

    t0 = time.perf_counter()
    steps = 3 + 2 * len(PHASES) + 2 * len(CLEARANCES_UM)
    with tqdm(total=steps, desc="report paper", unit="step", disable=not progress) as bar:
        def say(msg):
            bar.set_postfix_str(msg[:40])
            bar.update(1)
        res = compute(say, notify=lambda m: tqdm.write(f"gearwear: {m}", file=sys.stderr))
    return io.write_folder(out, "report paper", provenance(res), lambda d: write(res, d),
                           {"total_s": time.perf_counter() - t0})
