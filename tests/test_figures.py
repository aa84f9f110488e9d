"""Every figure the CLI writes is true, named for what it is, and readable.

The checks are small functions of a drawn matplotlib Figure, applied to every figure
function through one registry (``FIGURES``): a figure added later is checked by one line
there. Each figure is built from a small real run (analytic stiffness, one simulation, a
three-speed run-up) or from synthetic results of the right shape; nothing is written.

* every legend entry is visible: no labelled line lies exactly on another line (the
  same data, or within a pixel on the canvas) unless its label says so with "=";
* no legend box covers a plotted data point (the legend's window extent against the
  display coordinates of every line vertex, densified along the segments, and of every
  filled area or colour map);
* no two texts (titles, axis labels, annotations, legend boxes) overprint each other;
* axis labels are words with a unit in parentheses ("(dimensionless)" and "(ratio)"
  included), never a raw dotted scene key or a bare signal name;
* a log axis or a log colour scale spans at most 120 dB (10^6 in amplitude) below its
  largest value: the solver's 1e-12 rounding noise is not data;
* a spectrum spans the harmonics its run reports, up to (K + 0.5) f_m at least.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import re
from concurrent.futures import ThreadPoolExecutor
from functools import cache
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import LogNorm
from matplotlib.lines import Line2D
from matplotlib.transforms import Bbox

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: a log axis or colour scale may reach this far below its largest value (amplitude dB)
MAX_DEPTH_DB = 120.0
RAW_KEY = re.compile(r"^[A-Za-z_]\w*(\.\w+)+$")


# -- the checks ----------------------------------------------------------------------------


def drawn(fig):
    """The renderer of the figure drawn on an Agg canvas (layout done), drawn once."""
    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
        fig.canvas.draw()
    return fig.canvas.get_renderer()


def _lines(ax) -> list[Line2D]:
    return [ln for ln in ax.lines if ln.get_visible()]


def _display(line: Line2D) -> np.ndarray:
    xy = np.asarray(line.get_xydata(), float)
    return line.get_transform().transform(xy) if xy.size else xy.reshape(0, 2)


def _same_curve(a: Line2D, b: Line2D) -> bool:
    """b covers a: the same data, or the same number of points within a pixel on the canvas."""
    xa, xb = np.asarray(a.get_xydata(), float), np.asarray(b.get_xydata(), float)
    if xa.shape != xb.shape or xa.size == 0:
        return False
    if np.array_equal(xa, xb):
        return True
    da, db = _display(a), _display(b)
    ok = np.isfinite(da).all(axis=1) & np.isfinite(db).all(axis=1)
    return bool(ok.any()) and float(np.max(np.hypot(*(da[ok] - db[ok]).T))) < 1.0


def hidden_legend_entries(fig) -> list[str]:
    """Labels of legend lines another line covers, when neither label says "=" (drawn once
    and named "a = b" is the way to show two equal curves)."""
    drawn(fig)
    bad = []
    for ax in fig.axes:
        lines = _lines(ax)
        for a in lines:
            if a.get_label().startswith("_"):
                continue
            for b in lines:
                if b is not a and _same_curve(a, b) and "=" not in a.get_label() + b.get_label():
                    bad.append(f"{a.get_label()!r} under {b.get_label()!r}")
    return bad


def _legends(fig) -> list:
    return [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + list(fig.legends)


def _inside(points: np.ndarray, box) -> np.ndarray:
    return (points[:, 0] > box.x0) & (points[:, 0] < box.x1) & (points[:, 1] > box.y0) & (points[:, 1] < box.y1)


def _densified(line: Line2D, clip) -> np.ndarray:
    """A line's display vertices inside its axes and, for a drawn line of moderate length,
    points every ~2 px along its segments."""
    p = _display(line)
    p = p[np.isfinite(p).all(axis=1)]
    if line.get_linestyle() not in ("None", "none", "", " ") and 1 < len(p) < 5000:
        d = np.diff(p, axis=0)
        n = np.clip(np.ceil(np.hypot(d[:, 0], d[:, 1]) / 2.0), 1, 200).astype(int)
        seg = np.repeat(np.arange(len(d)), n)
        frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + 1) / np.repeat(n, n)
        p = np.vstack([p[:1], p[seg] + d[seg] * frac[:, None]])
    return p[_inside(p, clip)] if len(p) else p


def legends_over_data(fig) -> list[str]:
    """Legends whose box covers a data point of any axes: a line vertex (or a point along
    it), a filled area, a colour map or a shaded band."""
    renderer = drawn(fig)
    bad = []
    for leg in _legends(fig):
        box = leg.get_window_extent(renderer)
        for ax in fig.axes:
            if not ax.get_visible():
                continue
            clip = ax.bbox
            for ln in _lines(ax):
                if _inside(_densified(ln, clip), box).any():
                    bad.append(f"legend over {ln.get_label()!r}")
            for art in [*ax.collections, *ax.patches, *ax.images]:
                area = Bbox.intersection(art.get_window_extent(renderer), clip) if art.get_visible() else None
                if area is not None and area.width > 0 and area.height > 0 and box.overlaps(area):
                    bad.append(f"legend over a {type(art).__name__}")
    return bad


def _texts(fig) -> list:
    out = [t for t in fig.texts]
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        out += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
    return [t for t in out if t.get_visible() and t.get_text().strip()]


def overprinted_texts(fig) -> list[str]:
    """Pairs of texts (and legend boxes) whose boxes overlap by more than a pixel."""
    renderer = drawn(fig)
    boxes = [(repr(t.get_text()[:40]), t.get_window_extent(renderer)) for t in _texts(fig)]
    boxes += [(f"legend {i}", leg.get_window_extent(renderer)) for i, leg in enumerate(_legends(fig))]
    bad = []
    for i, (na, a) in enumerate(boxes):
        for nb, b in boxes[i + 1 :]:
            w = min(a.x1, b.x1) - max(a.x0, b.x0)
            h = min(a.y1, b.y1) - max(a.y0, b.y0)
            if w > 1 and h > 1:
                bad.append(f"{na} and {nb}")
    return bad


def bad_axis_labels(fig) -> list[str]:
    """Axis labels that are not words with a unit: a raw dotted scene key, a single token
    (a signal or column name), or no unit in parentheses (nor "ratio")."""
    bad = []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for text in (ax.get_xlabel(), ax.get_ylabel()):
            t = " ".join(text.split())
            if not t:
                continue
            if any(RAW_KEY.match(w.strip(",;:()")) for w in t.split()):
                bad.append(f"raw key in {t!r}")
            elif " " not in t:
                bad.append(f"not words: {t!r}")
            elif not (re.search(r"\([^()]+\)", t) or "ratio" in t):
                bad.append(f"no unit: {t!r}")
    return bad


def _ydata_in_view(ax) -> np.ndarray:
    lo, hi = sorted(ax.get_xlim())
    vals = []
    for ln in _lines(ax):
        xy = np.asarray(ln.get_xydata(), float)
        if xy.size and ln.get_transform().contains_branch_seperately(ax.transData)[1]:  # y in data units
            keep = (xy[:, 0] >= lo) & (xy[:, 0] <= hi) & np.isfinite(xy[:, 1]) & (xy[:, 1] > 0)
            vals.append(xy[keep, 1])
    return np.concatenate(vals) if vals else np.zeros(0)


def too_deep_log_scales(fig, depth_dB: float = MAX_DEPTH_DB) -> list[str]:
    """Log y axes whose lower limit, and log colour scales whose vmin, lie more than
    ``depth_dB`` below their largest value."""
    drawn(fig)
    ratio = 10 ** (-depth_dB / 20)
    bad = []
    for ax in fig.axes:
        if ax.get_yscale() == "log":
            y = _ydata_in_view(ax)
            if y.size and ax.get_ylim()[0] < float(y.max()) * ratio:
                bad.append(f"log axis from {ax.get_ylim()[0]:.3g} under a peak of {y.max():.3g}")
        for art in [*ax.collections, *ax.images]:
            norm = getattr(art, "norm", None)
            if isinstance(norm, LogNorm) and norm.vmin < norm.vmax * ratio:
                bad.append(f"log colours from {norm.vmin:.3g} to {norm.vmax:.3g}")
    return bad


def spectrum_short_of(ax, fm_Hz: float, K: int) -> str | None:
    """Why the spectrum on ``ax`` does not reach (K + 0.5) f_m, or None."""
    need = (K + 0.5) * fm_Hz
    line = max(_lines(ax), key=lambda ln: len(ln.get_xdata()))
    f = np.asarray(line.get_xdata(), float)
    df = float(np.median(np.diff(f)))
    if ax.get_xlim()[1] < need * (1 - 1e-9):
        return f"axis ends at {ax.get_xlim()[1]:g} Hz < {need:g} Hz"
    if f.max() < need - df:
        return f"data end at {f.max():g} Hz < {need:g} Hz"
    return None


def problems(fig) -> list[str]:
    """Every check that applies to any figure."""
    return (
        hidden_legend_entries(fig)
        + legends_over_data(fig)
        + overprinted_texts(fig)
        + bad_axis_labels(fig)
        + too_deep_log_scales(fig)
    )


# -- small real runs and synthetic results ----------------------------------------------------


@cache
def simulation():
    from gearwear.jobs.simulate import run
    from gearwear.scene.files import builtin_scene_dict
    from gearwear.scene.model import scene_from_dict

    return run(scene_from_dict(builtin_scene_dict("paper-wear-severe"), name="paper-wear-severe"))


def phases_of(doc: dict) -> list:
    from gearwear.jobs.verify import PhaseResult

    a = np.asarray
    return [
        PhaseResult(
            name,
            a(p["radius_mm"]),
            a(p["roll_angle_deg"]),
            a(p["fem_compliance_um_per_N_per_mm"]),
            a(p["ishikawa_compliance_um_per_N_per_mm"]),
            a(p["energy_compliance_um_per_N_per_mm"]),
            0.0,
            0.0,
            0.0,
            0,
            0,
        )
        for name, p in sorted(doc["phases"].items(), key=lambda kv: ("unworn", "mild", "severe").index(kv[0]))
    ]


def verification(equal: bool = False):
    """The committed verification's phases; with ``equal`` the mild phase a copy of the unworn."""
    from gearwear.jobs.verify import Verification

    phases = phases_of(json.loads((ROOT / "reports/verification/verification.json").read_text()))
    if equal:
        phases[1] = dataclasses.replace(phases[0], label="mild")
    return Verification(None, phases, None, None)


def stiffness_curves(example: str, wears=None, clearances_m=None, points: int = 180):
    from gearwear.jobs.stiffness import compute
    from gearwear.scene.model import load_scene

    sc = load_scene(str(EXAMPLES / example)) if example.endswith(".toml") else None
    if sc is None:
        from gearwear.scene.files import builtin_scene_dict
        from gearwear.scene.model import scene_from_dict

        sc = scene_from_dict(builtin_scene_dict(example), name=example)
    curves = compute(
        sc.pair,
        "ishikawa",
        wears if wears is not None else [sc.wear],
        clearances_m if clearances_m is not None else [sc.clearance_m],
        sc.operating.torque_Nm,
        points,
        flank=sc.flank,
        faults=sc.faults,
    )
    return sc, curves


def geometry(example: str | None, wear: str | None):
    from gearwear.jobs.geometry import compute
    from gearwear.scene.model import load_scene, parse_wear_arg

    sc = load_scene(None if example is None else str(EXAMPLES / example))
    return compute(sc, None if wear is None else parse_wear_arg(wear), 0.0, sc.operating.torque_Nm, build_mesh=False)


def sweep_results(values, others=None):
    """Harmonic amplitudes that change by a few percent over the sweep, per point."""
    from gearwear.jobs.sweep import Axis, grid

    axes = [Axis("effects.bearing_clearance.clearance_um", tuple(values))] + (others or [])
    results = []
    for i, p in enumerate(grid(axes)):
        x = i / max(len(values) - 1, 1)
        results.append(
            {
                "point": p,
                "harmonics": {
                    "F_m_N": [50 * (1 + 0.05 * x) / k for k in range(1, 11)],
                    "delta_um": [0.5 * (1 - 0.03 * x) / k for k in range(1, 11)],
                },
            }
        )
    return axes, results


@cache
def runup():
    """A three-speed run-up both ways of the backlash example (real, ~2 s): 1500 rpm from rest
    settles period 2, and 2100 rpm is above f_m = 1036 Hz, a linear mode."""
    from gearwear.jobs import runup as runup_job
    from gearwear.jobs.sweep import parse_axis
    from gearwear.scene.files import load_scene_dict

    data, name = load_scene_dict(str(EXAMPLES / "runup_backlash.toml"))
    speed, others = runup_job.split_speed_axis([parse_axis("operating.speed_rpm=1500:2100:3")])
    points, chains = runup_job.plan(data, name, speed, others, [], "both")
    settings = runup_job.Settings()
    with ThreadPoolExecutor(1) as ex:
        runup_job.run(points, chains, settings, ex, progress=False)
    return points, chains, others, runup_job.summary(points, chains, speed, others, settings)


def runup_with_every_state():
    """The run-up with its rows relabelled: one of every steady state a run-up reports."""
    points, chains, others, summ = runup()
    chains = copy.deepcopy(chains)
    states = [
        ("periodic", 2),
        ("periodic", 3),
        ("quasi-periodic", 0),
        ("chaotic", 0),
        ("unsettled", 0),
        ("periodic", 1),
    ]
    for i, (r, (label, p)) in enumerate(zip((r for c in chains for r in c.rows), states)):
        r["label"], r["period_mesh_periods"] = label, p
        r["K_v"] += 0.3 * i  # apart: up and down share a K_v where they follow one branch
    return points, chains, others, summ


def pair_report_doc() -> dict:
    ang = np.linspace(0, 12, 49)
    k = {
        "ishikawa": 4.4e8 + 0.8e8 * np.cos(ang),
        "energy": 4.1e8 + 0.7e8 * np.cos(ang),
        "iso6336": np.full_like(ang, 4.6e8),
        "fem": 4.0e8 + 0.9e8 * np.cos(ang),
    }
    speeds = np.linspace(2000, 8000, 9)
    return {
        "operating": {"torque_Nm": 60.0},
        "stiffness": [
            {
                "method": m,
                "label": m,
                "angle_deg": ang.tolist(),
                "k_N_per_m": v.tolist(),
                "mean_N_per_m": float(v.mean()),
            }
            for m, v in k.items()
        ],
        "load_map": {
            "torque_Nm": [30.0, 60.0, 120.0],
            "scene_torque_Nm": 60.0,
            "ste_peak_to_peak_um": {"nominal flank": [0.4, 0.8, 1.6]},
        },
        "runup": {
            "speeds_rpm": speeds.tolist(),
            "K_v": (1 + 0.1 * np.sin(speeds / 900)).tolist(),
            "iso6336": {"K_v": (1 + speeds / 1e4).tolist(), "n_E1_driver_rpm": 6000.0},
        },
    }


class _Run:
    """A simulation result of the shape the paper report draws: sinusoids at k f_m."""

    def __init__(self, scale: float):
        from gearwear.dynamics.analysis import spectrum

        fm, S, M = 600.0, 64, 40
        t = np.arange(S * M) / (S * fm)
        sig = {
            n: scale * sum(np.cos(2 * np.pi * k * fm * t) / k for k in range(1, 11)) * u
            for n, u in (("y_p", 1e-7), ("x_p", 5e-8), ("delta", 3e-7), ("F_m", 50.0))
        }
        self.result = SimpleNamespace(
            t=t,
            signals=sig,
            fs_Hz=S * fm,
            fm_Hz=fm,
            spectrum=lambda n: spectrum(sig[n] - sig[n].mean(), S * fm),
            harmonics=lambda n, K: np.array([scale / k for k in range(1, K + 1)]),
        )


def paper_report_results() -> dict:
    from gearwear.geometry.operating import operating_geometry
    from gearwear.geometry.spec import default_pair
    from gearwear.reports.paper_study import CLEARANCES_UM, PHASES

    pair = default_pair()
    ang = np.linspace(0, 2 * np.pi / 30, 60, endpoint=False)

    def tab(s):
        return SimpleNamespace(angle_rad=ang, k_N_per_m=s * (4e8 + 1e8 * np.cos(30 * ang)), mean_N_per_m=s * 4e8)

    cl = np.linspace(0, 100, 5)
    return {
        "tabs_wear": {p: tab(1 - 0.05 * i) for i, p in enumerate(PHASES)},
        "sims_wear": {p: _Run(1 + 0.2 * i) for i, p in enumerate(PHASES)},
        "tabs_cl": {c: tab(1 - 0.001 * c) for c in CLEARANCES_UM},
        "sims_cl": {c: _Run(1 + 0.004 * c) for c in CLEARANCES_UM},
        "cl_fine": cl,
        "geo": [operating_geometry(pair, c * 1e-6, 40.0, 2.6e8, 50e-6) for c in cl],
    }


def diagnosis(monkeypatch):
    """A Fit of two unknowns (a Gaussian posterior on a grid) and its feature rows."""
    from gearwear.diagnose import plots as diagnose_plots
    from gearwear.diagnose.posterior import GridPosterior
    from gearwear.diagnose.surrogate import UNKNOWNS

    ax = [np.linspace(0, 40, 41), np.linspace(0, 50, 51)]
    X, Y = np.meshgrid(*ax, indexing="ij")
    p = np.exp(-0.5 * (((X - 17) / 2) ** 2 + ((Y - 28) / 9) ** 2))
    unknowns = [UNKNOWNS["wear"], UNKNOWNS["clearance"]]
    est = {u.name: {"value": v, "lo95": v - 5, "hi95": v + 5} for u, v in zip(unknowns, (17.0, 28.0))}
    ft = SimpleNamespace(
        names=[u.name for u in unknowns],
        sur=SimpleNamespace(unknowns=unknowns),
        post=GridPosterior(ax, p / p.sum(), []),
        summary={"estimates": est},
    )
    rows = [
        {
            "signal": s,
            "harmonic": k,
            "measured": a / max(k, 0.5),
            "fitted": 1.02 * a / max(k, 0.5),
            "sigma_noise": 0.01 * a,
            "sigma_surrogate": 0.01 * a,
        }
        for s, a in (("y_p_um", 0.1), ("F_m_N", 100.0))
        for k in range(0, 11)
    ]
    monkeypatch.setattr(diagnose_plots, "feature_rows", lambda _: rows)
    return ft


# -- the registry: every figure function the CLI writes ----------------------------------------


def _simulate(name):
    from gearwear.jobs import simulate_io

    return {"response.png": simulate_io.figure, "spectrum.png": simulate_io.spectrum_figure}[name](simulation())


def _verify(equal=False):
    from gearwear.jobs.verify import figures

    return figures(verification(equal))["compliance.png"]


def _convergence():
    from gearwear.fem.convergence import convergence_figure

    rows = [
        dict(order=o, dofs=d, wall_s=w, error_pct_max=e, is_default=(o == 2 and d == 4000))
        for o, d, w, e in ((1, 1000, 0.1, 4.0), (1, 4000, 0.3, 1.0), (2, 1000, 0.2, 0.4), (2, 4000, 0.6, 0.05))
    ]
    return convergence_figure(rows, wall_time=False)


def _stiffness(name, example="spall.toml", overlay=False):
    from gearwear.geometry.wear import WearSpec
    from gearwear.jobs.stiffness import figures

    kw = {"wears": [None, WearSpec(phase="severe")], "clearances_m": [0.0, 50e-6]} if overlay else {}
    return figures(stiffness_curves(example, **kw)[1])[name]


def _harris():
    from gearwear.jobs.stiffness import harris, harris_figure

    sc, curves = stiffness_curves("tip_relief.toml")
    return harris_figure(harris(curves, sc.pair, sc.flank), sc.operating.torque_Nm, sc.flank)


def _tooth(example, wear):
    from gearwear.jobs.geometry import tooth_figure

    return tooth_figure(geometry(example, wear))


def _sweep(name, two_torques=False):
    from gearwear.jobs.sweep import Axis, figures

    if two_torques:
        return figures(*sweep_results(np.linspace(0, 100, 6), [Axis("operating.torque_Nm", (10.0, 40.0))]))[name]
    return figures(*sweep_results(np.linspace(0, 100, 11)))[name]


def _runup(kind, direction="up", every_state=False):
    from gearwear.jobs import runup_figures

    points, chains, others, summ = runup_with_every_state() if every_state else runup()
    if kind == "kv":
        return runup_figures.kv_figure(points, chains, others, summ)
    return getattr(runup_figures, f"{kind}_figure")(points, chains, others, direction)


def _pair_report(name):
    from gearwear.reports import pair as report_pair

    return report_pair.FIGURES[name](pair_report_doc())


def _paper_report():
    from gearwear.reports.paper import figures

    return list(figures(paper_report_results()).items())


def _diagnose(name, monkeypatch):
    from gearwear.diagnose import plots as diagnose_plots

    return getattr(diagnose_plots, name)(diagnosis(monkeypatch))


#: every figure function the CLI writes, by command and file: (monkeypatch) -> figure or [(name, figure)]
FIGURES = {
    "simulate response.png": lambda mp: _simulate("response.png"),
    "simulate spectrum.png": lambda mp: _simulate("spectrum.png"),
    "verify compliance.png": lambda mp: _verify(),
    "verify compliance.png, two equal phases": lambda mp: _verify(equal=True),
    "verify convergence.png": lambda mp: _convergence(),
    "stiffness stiffness.png, spall": lambda mp: _stiffness("stiffness.png"),
    "stiffness stiffness.png, wear and clearances": lambda mp: _stiffness("stiffness.png", "paper-default", True),
    "stiffness mean_vs_clearance.png": lambda mp: _stiffness("mean_vs_clearance.png", "paper-default", True),
    "stiffness harris_map.png": lambda mp: _harris(),
    "geometry tooth.png, severe": lambda mp: _tooth(None, "severe"),
    "geometry tooth.png, unworn": lambda mp: _tooth(None, None),
    "geometry tooth.png, 19/45 teeth": lambda mp: _tooth("your_pair.toml", "severe"),
    "sweep harmonics_F_m_N.png": lambda mp: _sweep("harmonics_F_m_N.png"),
    "sweep harmonics_delta_um.png, two torques": lambda mp: _sweep("harmonics_delta_um.png", two_torques=True),
    "runup kv.png": lambda mp: _runup("kv"),
    "runup kv.png, every steady state": lambda mp: _runup("kv", every_state=True),
    "runup order_map_up.png": lambda mp: _runup("order_map"),
    "runup campbell_up.png": lambda mp: _runup("campbell"),
    "runup campbell_down.png": lambda mp: _runup("campbell", "down"),
    "report pair stiffness.png": lambda mp: _pair_report("stiffness.png"),
    "report pair ste_load.png": lambda mp: _pair_report("ste_load.png"),
    "report pair kv.png": lambda mp: _pair_report("kv.png"),
    "report paper fig*.png": lambda mp: _paper_report(),
    "diagnose corner.png": lambda mp: _diagnose("corner", mp),
    "diagnose features.png": lambda mp: _diagnose("features", mp),
}


@pytest.mark.parametrize("name", sorted(FIGURES))
def test_every_figure_shows_every_legend_entry_off_the_data_with_labels_in_words(name, monkeypatch):
    made = FIGURES[name](monkeypatch)
    for sub, fig in made if isinstance(made, list) else [(name, made)]:
        assert problems(fig) == [], sub


# -- the checks see what they are for ---------------------------------------------------------


def test_the_checks_catch_a_bad_figure():
    from gearwear.plotting import subplots

    x = np.linspace(0, 1, 50)
    fig, ax = subplots(1, 1, figsize=(5, 3))
    ax.plot(x, x, label="unworn")
    ax.plot(x, x.copy(), label="mild")  # the same curve again, not said
    ax.semilogy(x, np.r_[1.0, np.full(49, 1e-12)])  # rounding noise on a log axis
    ax.legend(loc="upper left")  # on the curve's start
    ax.set_xlabel("effects.bearing_clearance.clearance_um")
    ax.set_ylabel("F_m_N")
    assert hidden_legend_entries(fig) == ["'unworn' under 'mild'", "'mild' under 'unworn'"]
    assert legends_over_data(fig)
    assert [b.split(":")[0].split(" in ")[0] for b in bad_axis_labels(fig)] == ["raw key", "not words"]
    assert too_deep_log_scales(fig)
    fig2, ax2 = subplots(1, 1)
    ax2.set_title("Harris map")
    ax2.text(0.5, 1.01, "SAP", transform=ax2.transAxes)
    ax2.text(0.5, 1.01, "LPSTC", transform=ax2.transAxes)
    assert overprinted_texts(fig2)


# -- 1. spectra ----------------------------------------------------------------------------


def test_spectra_cover_the_reported_harmonics_above_a_floor_tied_to_the_signal():
    from gearwear.jobs import simulate_io
    from gearwear.plotting import FLOOR_DB

    run = simulation()
    K, fm = int(run.output["harmonics"]), run.result.fm_Hz
    assert K == 10 and fm == 600.0
    spec = simulate_io.spectrum_figure(run)
    ax = spec.axes[0]
    assert spectrum_short_of(ax, fm, K) is None
    lo, _ = ax.get_ylim()
    peak = float(_ydata_in_view(ax).max())
    assert lo == pytest.approx(peak * 10 ** (-FLOOR_DB / 20), rel=1e-9)
    # the demo's largest lines (k = 5, 6 at 3-3.6 kHz) are on the plot, far above the floor
    f, A = (np.asarray(v, float) for v in max(_lines(ax), key=lambda ln: len(ln.get_xdata())).get_data())
    for k in (5, 6):
        assert A[np.argmin(abs(f - k * fm))] > 1e4 * lo
    response = simulate_io.figure(run)
    for row in np.asarray(response.axes).reshape(-1, 2):
        assert spectrum_short_of(row[1], fm, K) is None


# -- 2. coinciding curves --------------------------------------------------------------------


def test_equal_curves_are_drawn_once_and_named_with_equals():
    from gearwear.jobs.verify import figures

    fig = figures(verification(equal=True))["compliance.png"]
    top = fig.axes[0]
    labels = [ln.get_label() for ln in _lines(top)]
    # three methods, each one line: unworn = mild exactly, severe within a fraction of a percent
    assert len(labels) == 3 and all(lab.split(" (")[0].endswith("unworn = mild = severe") for lab in labels)
    assert all("within" in lab for lab in labels)  # severe differs a little from the unworn: the label says so
    assert len(fig.axes[0].get_legend().get_texts()) == 3


# -- 3. run-up: legend, mode lines, steady states -----------------------------------------------


def test_runup_marks_every_steady_state_and_names_the_mode_speeds():
    from gearwear.jobs import runup_figures

    fig = _runup("kv", every_state=True)
    drawn(fig)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    for state in ("period 2", "period 3", "quasi-periodic", "chaotic", "unsettled"):
        assert sum(f"steady state {state}" in t for t in texts) == 1, state
    markers = [ln for ln in _lines(ax) if ln.get_label().startswith("steady state")]
    assert len({(ln.get_marker(), ln.get_markerfacecolor()) for ln in markers}) == len(markers) == 5
    assert not any("period 1" in t for t in texts)
    # the speeds where f_m meets a linear mode: full-height lines, each named by its frequency
    points, _, _, summ = runup()
    inside = [
        f
        for n, f in zip(summ["points"][0]["mode_speeds_rpm"]["k1"], points[0].eigenfrequencies_Hz)
        if 1500 <= n <= 2100
    ]
    names = [t.get_text() for t in ax.texts]
    assert sorted(names) == sorted({f"{f:.0f} Hz" for f in inside})
    assert runup_figures.steady_state_name({"label": "periodic", "period_mesh_periods": 30}, 30) is None


# -- 4. sweep labels from the schema ------------------------------------------------------------


def test_every_scene_key_has_an_axis_label_in_words_with_its_unit():
    from gearwear.scene.reference import json_schema, key_label

    def keys(node, path, defs):
        node = defs[node["$ref"].split("/")[-1]] if "$ref" in node else node
        for sub in node.get("anyOf", []):
            if "$ref" in sub:
                yield from keys(sub, path, defs)
        for name, p in node.get("properties", {}).items():
            ref = p if "$ref" in p else next((x for x in p.get("anyOf", []) if "$ref" in x), None)
            if ref is not None:
                yield from keys(ref, path + [name], defs)
            elif "unit" in p:
                yield ".".join(path + [name]), p["unit"]

    s = json_schema()
    found = list(keys(s, [], s["$defs"]))
    assert len(found) > 50
    for key, unit in found:
        label = key_label(key)
        assert label.endswith(f"({unit or 'dimensionless'})"), (key, label)
        leaf = key.split(".")[-1]
        assert not RAW_KEY.match(label) and not ("_" in leaf and leaf in label), (key, label)
    assert key_label("effects.bearing_clearance.clearance_um") == "radial bearing clearance BC (um)"
    assert key_label("operating.speed_rpm") == "pinion speed (rpm)"
    assert key_label("flank.tip_relief.amount_um") == "tip relief: relief amount (um)"


def test_sweep_axes_start_at_zero_and_state_the_relative_range():
    from gearwear.jobs.sweep import Axis, figures
    from gearwear.scene.reference import key_label

    axes, results = sweep_results(np.linspace(0, 100, 11))
    fig = figures(axes, results)["harmonics_F_m_N.png"]
    for k, ax in enumerate(fig.axes[:10]):
        assert ax.get_ylim()[0] == 0
        assert ax.get_xlabel() == key_label("effects.bearing_clearance.clearance_um")
        assert ax.get_ylabel() == "mesh force F_m, harmonic k (N)"
        assert ax.get_title() == f"k = {k + 1}: range 4.9 % of the mean"  # 0.05 / 1.025 of the mean
    # any swept key gets its words: a damping ratio
    other = [Axis("bodies.mesh_damping_ratio", (0.02, 0.05))]
    res = [{"point": {"bodies.mesh_damping_ratio": v}, "harmonics": {"F_m_N": [1.0] * 10}} for v in (0.02, 0.05)]
    assert (
        figures(other, res)["harmonics_F_m_N.png"].axes[0].get_xlabel() == "bodies: mesh damping ratio (dimensionless)"
    )


# -- 5. tooth.png -------------------------------------------------------------------------------


def test_each_gear_has_its_own_axes_and_an_unworn_flank_says_so():
    from gearwear.jobs.geometry import key_radii_mm, tooth_figure

    res = geometry("your_pair.toml", "severe")
    fig = tooth_figure(res)
    drawn(fig)
    outline_p, outline_g, wear_p, wear_g = fig.axes
    for i, ax in ((0, wear_p), (1, wear_g)):
        lo, hi = ax.get_xlim()
        assert lo <= min(key_radii_mm(res, i).values()) and max(key_radii_mm(res, i).values()) <= hi
        assert sorted(t.get_text() for t in ax.texts) == sorted(key_radii_mm(res, i))
    assert wear_p.get_xlim()[1] < wear_g.get_xlim()[0]  # 19 and 45 teeth: radii apart, each on its own axis
    assert outline_p.get_ylim()[1] < outline_g.get_ylim()[0]
    unworn = tooth_figure(geometry(None, None))
    for ax in unworn.axes[2:]:
        assert "unworn: no wear" in [t.get_text() for t in ax.texts]
        assert all(np.ptp(ln.get_xdata()) == 0 for ln in _lines(ax))  # no wear curve: the marked radii only


# -- 6. Harris map ------------------------------------------------------------------------------


def test_the_harris_title_states_the_relief():
    from gearwear.geometry.flank import FlankSpec, Relief
    from gearwear.jobs.stiffness import relief_text

    title = _harris().axes[0].get_title().replace("\n", " ")
    assert "tip relief on both gears: C_a = 8.5 um, linear, from d = 151.83 mm" in title
    per_gear = FlankSpec(
        tip_relief=(Relief(5e-6, 0.15, "parabolic"), None), root_relief=(Relief(4e-6, 0.145), Relief(6e-6, 0.146))
    )
    assert relief_text(per_gear) == (
        "tip relief on the pinion: C_a = 5 um, parabolic, from d = 150 mm; "
        "root relief on the pinion: C_f = 4 um, linear, from d = 145 mm; "
        "root relief on the gear: C_f = 6 um, linear, from d = 146 mm"
    )


# -- 7. Campbell diagram ---------------------------------------------------------------------------


def test_the_campbell_diagram_shows_the_subharmonic_of_a_period_2_response():
    from gearwear.jobs import runup as runup_job
    from gearwear.jobs import runup_figures

    points, chains, others, _ = runup()
    up = next(c for c in chains if c.direction == "up")
    row = up.rows[0]
    assert (row["speed_rpm"], row["label"], row["period_mesh_periods"]) == (1500.0, "periodic", 2)
    fm = row["fm_Hz"]
    f, A = runup_figures.campbell_spectrum(row)
    i = int(np.argmin(abs(f - fm / 2)))
    assert f[i] == pytest.approx(fm / 2, rel=1e-12)  # an exact bin: the kept window is whole periods
    assert f.max() >= (runup_job.N_HARMONICS + 0.5) * fm - row["spectrum_df_Hz"]
    between = A[(f > 0.1 * fm) & (f < 0.4 * fm)]  # below f_m / 2: nothing but noise
    assert A[i] > 1e-3 * A.max() and A[i] > 1e4 * between.max()
    # the figure's colour map holds that line at f_m / 2 in the 1500 rpm column
    fig = runup_figures.campbell_figure(points, chains, others, "up")
    mesh = next(c for c in fig.axes[0].collections if hasattr(c, "get_coordinates"))
    y = mesh.get_coordinates()[:, 0, 1]
    col = np.ma.filled(mesh.get_array(), np.nan).reshape(len(y) - 1, -1)[:, 0]
    mid = 0.5 * (y[1:] + y[:-1])
    assert col[int(np.searchsorted(y, fm / 2)) - 1] == pytest.approx(A[i], rel=1e-12)
    assert col[int(np.searchsorted(y, fm / 2)) - 1] > 1e3 * np.nanmax(col[(mid > 0.1 * fm) & (mid < 0.4 * fm)])
    # a period-1 response has nothing there
    one = next(r for r in up.rows if r["period_mesh_periods"] == 1)
    f1, A1 = runup_figures.campbell_spectrum(one)
    assert A1[np.argmin(abs(f1 - one["fm_Hz"] / 2))] < 1e-6 * A1.max()


def test_peak_hold_keeps_a_one_bin_line_on_coarse_rows():
    from gearwear.jobs.runup_figures import peak_hold

    f = np.arange(1, 1001) * 10.0  # bins of 10 Hz
    A = np.full(f.size, 1e-9)
    A[499] = 1.0  # one line at 5 kHz
    rows = peak_hold(f, A, np.linspace(0, 20000, 41))  # 500 Hz rows, the upper half beyond the bins
    assert rows[10] == 1.0 and np.sum(rows == 1.0) == 1
    assert np.all(np.isnan(rows[21:])) and np.all(rows[:20][np.arange(20) != 10] == 1e-9)
