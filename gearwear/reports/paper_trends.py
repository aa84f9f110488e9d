"""The paper's trend claims checked against this tool's results.

The claims are data (``gearwear/data/claims/paper.toml``): what the paper says, the direction
it claims, the measured quantity that checks it and the mechanism that explains it. Here are
the words for a measured change (:func:`classify`, :func:`agrees`, :func:`change_text`), the
named quantities, mechanisms, contexts and computed rows the data refers to, and
:func:`trends`, which evaluates every claim on the results of ``reports.paper.compute``.
"""

from __future__ import annotations

import math
import tomllib
from importlib import resources
from typing import Any, Callable

import numpy as np

from gearwear.geometry.curves import harmonic_amplitudes
from gearwear.reports.paper_study import CLEARANCES_UM, PHASES, SIGNALS

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


# -- trends ------------------------------------------------------------------------------

# Every row's "why" is generated from what that row measured: a sentence on the
# measured change (direction words from classify(), percent change between the named
# ends), the verdict in words (for a disagreement: what this tool finds instead of the
# claim), and only then a mechanism, and only one that explains the measured direction
# (MECHANISMS: the direction each text explains; the tests check every row against it).
# "rises by" / "falls by" are reserved for the measured sentence.

#: mechanism texts by key: (the direction of change they explain, text or format string)
MECHANISMS: dict[str, tuple[str, str]] = {
    "wear_gaps": (
        "decrease",
        "thinner teeth and, above all, wear gaps: the entering and leaving pairs carry no "
        "load until the elastic approach closes their gaps",
    ),
    "tips_compliant": (
        "decrease",
        "with the larger centre distance the contacts move toward the tips, where the teeth are more compliant",
    ),
    "double_zone_shorter": ("decrease", "the double-contact share of the period shortens ({a:.3f} -> {b:.3f})"),
    "contact_ratio": ("decrease", "the contact ratio falls ({a:.4f} -> {b:.4f})"),
    "eq11": ("increase", "Eq. 11: C' grows with the clearance, {slope:.3g} mm per mm of clearance"),
    "cos_alpha": ("increase", "cos a' = (r_b1 + r_b2) / C' and C' grows"),
    "tips_fixed": ("decrease", "the tip circles are fixed while C' grows"),
    "pitch_radius": ("increase", "r_w = r_b / cos a' grows with a'; base and tip radii are machined dimensions"),
    "backlash": ("increase", "2 (r_b1 + r_b2)(inv a' - inv a) grows with C'"),
    "dead_zone": (
        "increase",
        "the shaft crosses the dead zone BC/2 before the bearing carries: {slope:.3g} um per um of clearance",
    ),
    "half_backlash": (
        "increase",
        "in contact delta = j_n/2 + F/k, and half the backlash grows {db:.1f} um over the same range",
    ),
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
        return (
            f"{first} by {_pct(y[0], y[k])} ({labels[0]} -> {labels[k]}), then {second} by "
            f"{_pct(y[k], y[-1])} ({labels[k]} -> {labels[-1]})"
        )
    if found == "flat":
        return f"stays flat {ends}"
    d = np.diff(y)
    s = np.sign(d[np.abs(d) > 1e-3 * np.ptp(y)])
    turns = int(np.sum(s[1:] != s[:-1]))
    net = "up" if y[-1] > y[0] else "down"
    return f"changes direction {turns} times, net {net} {_pct(y[0], y[-1])} {ends}"


_CLAIM_WORDS = {
    "increase": "a rise",
    "decrease": "a fall",
    "decrease-then-increase": "a fall, then a rise",
    "increase-then-decrease": "a rise, then a fall",
    "nonlinear": "a nonlinear change",
    "flat": "no change",
}


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
    drop = 1 - (
        np.interp(x, worn.angle_rad, worn.k_N_per_m, period=P) / np.interp(x, base.angle_rad, base.k_N_per_m, period=P)
    )
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
        parts.append(
            f"{lab}: modes {', '.join(f'{m:.0f}' for m in modes)} Hz, {k} x fm = {f:.0f} Hz is {where} "
            f"(nearest {near:.0f} Hz, {100 * abs(f / near - 1):.0f} % away)"
        )
        if len(runs) == 1 or np.allclose(_modes_Hz(runs[0]), _modes_Hz(runs[-1]), rtol=0.02):
            parts[-1] = parts[-1].replace(f"{lab}: ", "")
            break
    a0, a1 = (_harmonic_amplitude(t, k) for t in (tables[0], tables[-1]))
    change = f"{100 * (a1 / a0 - 1):+.3g} %" if a0 > 0 else "n/a"
    return (
        "Context: " + "; ".join(parts) + f". Harmonic {k} of the stiffness table changes by {change} "
        f"({labels[0]} -> {labels[-1]}). Which response harmonic grows depends on that excitation and on the "
        "mode placement, which the paper's unstated inertias and damping set."
    )


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
            claims.append(
                {
                    **entry,
                    "k": int(k),
                    "claim": direction,
                    "paper": entry["paper"].format(k=int(k), direction=direction.replace("-", " ")),
                }
            )
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
    return (
        "Context: the peak-to-peak of the stiffness table changes by "
        f"{100 * (p2p_k[-1] / p2p_k[0] - 1):+.3g} % ({PHASES[0]} -> {PHASES[-1]}); the response also depends "
        "on the mode placement."
    )


def _context_bearings(res, c):
    sc = res["sims_cl"]
    bcf = [
        min(sc[x].result.bearing_contact_fraction.values())
        for x in CLEARANCES_UM
        if sc[x].result.bearing_contact_fraction
    ]
    if not bcf:
        return ""
    if min(bcf) >= 0.999:
        return (
            f"Context: the bearings stay pressed into their clearance in every run (lowest bearing contact "
            f"fraction {min(bcf):.3g}), so the clearance shifts the shafts and changes the dynamics only "
            "through the mesh geometry."
        )
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
    why = f"Measured: where the unworn pair shares the load with a second pair k_h {double} on average, {single}" + (
        ", as the paper says."
        if ok
        else "; the paper claims the larger change in the double zone, which this tool does not find."
    )
    if ok:
        why += (
            " Why: wear is deepest near root and tip (large sliding), which are in contact only in the "
            "double zone; at the pitch point (single zone) it is zero."
        )
    return {
        "ours": f"mean drop double zone {dd:.1f} %, single zone {ds:.2f} %",
        "verdict": "agree" if ok else "disagree",
        "why": why,
    }


def _row_nonlinearity(res, c):
    """How far the first four F_m harmonics bend away from a straight line over the clearances."""
    H4 = np.array([res["sims_cl"][x].result.harmonics("F_m", 4) for x in CLEARANCES_UM])
    lin = []
    for k in range(4):
        fit = np.polyval(np.polyfit(CLEARANCES_UM, H4[:, k], 1), CLEARANCES_UM)
        lin.append(float(np.max(np.abs(H4[:, k] - fit)) / max(np.ptp(H4[:, k]), 1e-300)))
    verdict = "agree" if min(lin) > 0.1 else "partly" if max(lin) > 0.1 else "disagree"
    bent = [k + 1 for k, v in enumerate(lin) if v > 0.1]
    why = (
        f"Measured: the largest deviation of a harmonic from its straight-line fit is {100 * max(lin):.0f} % of its "
        f"range (harmonic {int(np.argmax(lin)) + 1}); "
        + (
            "every one of the four bends by more than 10 %, as the paper says."
            if verdict == "agree"
            else f"harmonics {', '.join(map(str, bent))} bend by more than 10 %, the others are nearly straight."
            if verdict == "partly"
            else "all four are nearly straight lines (within 10 %); the paper claims a nonlinear change, which this "
            "tool does not find."
        )
    )
    return {
        "ours": "largest deviation from a straight line, per harmonic: "
        + ", ".join(f"{100 * v:.0f} %" for v in lin)
        + " of its range",
        "verdict": verdict,
        "why": why,
    }


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
    return {
        "ours": f"largest: {', '.join(f'{k + 1} x fm' for k in top)}",
        "verdict": "agree" if ok else "disagree",
        "why": (
            f"Measured: the largest harmonics are {', '.join(str(k + 1) for k in top)} x fm "
            f"({top_f} Hz at f_m = {r.fm_Hz:.0f} Hz)"
            + (", as the paper says" if ok else "; the paper claims the 8th-10th, which this tool does not find")
            + f"; the model's modes are {', '.join(f'{m:.0f}' for m in modes)} Hz (first run of the "
            f"{lab} study); the mode nearest the largest harmonic is "
            f"{modes[int(np.argmin(np.abs(modes - (top[0] + 1) * r.fm_Hz)))]:.0f} Hz. The paper's "
            "resonance depends on its unstated masses, inertias and damping."
        ),
    }


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
        context = " ".join(
            t for t in (c.get("context", ""), CONTEXTS[c["context_from"]](res, c) if "context_from" in c else "") if t
        )
        note = c.get("note", "")
        rows.append(
            {
                **head,
                "ours": f"{found}: {change_text(values)}" + (f" {note}" if note else ""),
                "verdict": verdict,
                "why": _why(values, _labels(res, study), c["claim"], verdict, mechanisms, context),
            }
        )
    return rows
