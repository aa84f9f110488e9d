"""Accuracy versus cost of the FE single-tooth compliance (fem.tooth).

h-refinement: every element size and the tooth-0 boundary sampling scale with
``mesh_scale`` (levels a factor r = sqrt(2) apart); p-refinement: Lagrange P1
versus P2 on the same meshes. For three consecutive levels of one order with
values f1 (coarse), f2, f3 (fine) at a load position, Richardson's analysis
(Roache, *Verification and Validation in Computational Science and Engineering*,
1998, ch. 5) gives the observed order and the extrapolated (h -> 0) value

    p = ln((f1 - f2) / (f2 - f3)) / ln(r),      f_ext = f3 + (f3 - f2) / (r^p - 1).

Per position p is undefined when the two differences change sign (non-monotone
convergence, e.g. where the difference is at the level of remeshing noise), so the
table reports the median of the defined per-position orders and a norm-based
order p_norm = ln(||f1 - f2|| / ||f2 - f3||) / ln(r) (max norm over positions),
and extrapolates every position with p_norm (one order for the whole curve is
more robust than 21 noisy ones). The error of a level is its largest relative
deviation from the reference extrapolation (the three finest P2 levels), over all
positions. The acceptance criteria of the default level are checked by
:func:`acceptance`.

Units: compliance in um per (N/mm), wall times in s (mesh + assemble + factorize
+ solves, the FE part of ``ToothFE.timings``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from gearwear.geometry.spec import PairSpec, default_pair
from gearwear.geometry.wear import WearSpec

from .tooth import LOAD_M, single_tooth_compliance

R_LEVEL = math.sqrt(2.0)
#: mesh_scale levels per order (coarse -> fine, ratio sqrt 2). P1 goes one level
#: further so that both orders span a similar range of cost.
LEVELS = {
    2: tuple(R_LEVEL**k for k in (3, 2, 1, 0, -1, -2)),
    1: tuple(R_LEVEL**k for k in (2, 1, 0, -1, -2, -3)),
}
DEFAULT_SCALE = 1.0


def observed_order(f1, f2, f3, r: float = R_LEVEL) -> tuple[np.ndarray, float]:
    """(per-position order (NaN where undefined), norm-based order) from three levels."""
    d12 = np.asarray(f1, float) - np.asarray(f2, float)
    d23 = np.asarray(f2, float) - np.asarray(f3, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = d12 / d23
        p = np.where((q > 0) & np.isfinite(q), np.log(np.abs(q)) / math.log(r), np.nan)
    n12, n23 = float(np.max(np.abs(d12))), float(np.max(np.abs(d23)))
    p_norm = math.log(n12 / n23) / math.log(r) if n12 > 0 and n23 > 0 else float("nan")
    return p, p_norm


def richardson(f2, f3, p: float, r: float = R_LEVEL) -> np.ndarray:
    """f_ext = f3 + (f3 - f2) / (r^p - 1) (the finer value f3 corrected)."""
    f2, f3 = np.asarray(f2, float), np.asarray(f3, float)
    if not (math.isfinite(p) and p > 0):
        return f3.copy()
    return f3 + (f3 - f2) / (r**p - 1.0)


def convergence_table(
    pair: PairSpec | None = None,
    wear: WearSpec | None = None,
    gear_index: int = 0,
    positions: int = 21,
    plane: str = "stress",
    levels: dict | None = None,
    progress=None,
) -> list[dict]:
    """Run every (order, mesh_scale) level and return one row (dict) per level.

    Row keys: order, mesh_scale, load_size_mm, dofs, elements, wall_s, timings,
    radius_mm, compliance (list, um per N/mm), max_change_pct (largest relative change
    from the next coarser level of the same order, %), observed_order_median,
    observed_order_norm (from this level and the two coarser ones), extrapolated
    (Richardson value from those three levels, list), error_pct (per position, vs the
    reference = extrapolation of the three finest P2 levels, or of the finest order
    present), error_pct_max, is_default.
    """
    pair = pair or default_pair()
    levels = levels or LEVELS
    rows: list[dict] = []
    for order in sorted(levels):
        prev: list[np.ndarray] = []
        for scale in levels[order]:
            r = single_tooth_compliance(
                pair, gear_index=gear_index, wear=wear, positions=positions, order=order, plane=plane, mesh_scale=scale
            )
            f = r.fem_compliance_um_per_N_per_mm
            row = {
                "order": order,
                "mesh_scale": float(scale),
                "load_size_mm": LOAD_M * 1e3 * scale,
                "dofs": r.ndofs,
                "elements": r.n_elements,
                "wall_s": r.wall_s,
                "timings": dict(r.timings),
                "radius_mm": r.radius_mm.tolist(),
                "compliance": f.tolist(),
                "max_change_pct": float("nan"),
                "observed_order_median": float("nan"),
                "observed_order_norm": float("nan"),
                "extrapolated": None,
                "is_default": bool(order == 2 and abs(scale - DEFAULT_SCALE) < 1e-12),
            }
            if prev:
                row["max_change_pct"] = float(np.max(np.abs(f / prev[-1] - 1.0)) * 100.0)
            if len(prev) >= 2:
                p, p_norm = observed_order(prev[-2], prev[-1], f)
                row["observed_order_median"] = float(np.nanmedian(p)) if np.any(np.isfinite(p)) else float("nan")
                row["observed_order_norm"] = p_norm
                row["observed_order_per_position"] = p.tolist()
                row["extrapolated"] = richardson(prev[-1], f, p_norm).tolist()
            prev.append(f)
            rows.append(row)
            if progress is not None:
                progress(row)
    ref = reference(rows)
    for row in rows:
        e = (np.asarray(row["compliance"]) / ref - 1.0) * 100.0
        row["error_pct"] = e.tolist()
        row["error_pct_max"] = float(np.max(np.abs(e)))
    return rows


def reference(rows: list[dict]) -> np.ndarray:
    """Richardson extrapolation of the finest level of the highest order with three levels."""
    for order in sorted({r["order"] for r in rows}, reverse=True):
        lev = [r for r in rows if r["order"] == order and r["extrapolated"] is not None]
        if lev:
            return np.asarray(min(lev, key=lambda r: r["mesh_scale"])["extrapolated"])
    finest = min(rows, key=lambda r: (-r["order"], r["mesh_scale"]))
    return np.asarray(finest["compliance"])


def acceptance(rows: list[dict], max_change_pct: float = 0.5) -> dict:
    """Accuracy checks of the default level: the two finest P2 levels differ by less
    than ``max_change_pct`` at every position, and the default level differs from the
    next finer P2 level by less than that. Its cost is reported (``default_dofs``,
    ``default_wall_s``) but not judged here: a verdict on wall time would make the same
    inputs give different results; benchmarks/bench_fem_targets.py times it."""
    p2 = sorted((r for r in rows if r["order"] == 2), key=lambda r: -r["mesh_scale"])
    default = next(r for r in p2 if r["is_default"])
    i = p2.index(default)
    finer = p2[i + 1] if i + 1 < len(p2) else None
    out = {
        "finest_p2_change_pct": p2[-1]["max_change_pct"],
        "default_vs_finer_change_pct": finer["max_change_pct"] if finer else float("nan"),
        "default_error_vs_extrapolation_pct": default["error_pct_max"],
        "default_wall_s": default["wall_s"],
        "default_dofs": default["dofs"],
    }
    out["ok"] = bool(
        out["finest_p2_change_pct"] < max_change_pct
        and (finer is None or out["default_vs_finer_change_pct"] < max_change_pct)
    )
    return out


def convergence_figure(rows: list[dict], wall_time: bool = True):
    """Largest relative error (vs the reference extrapolation, %) against dofs, and with
    ``wall_time`` also against wall time, log-log, one line per element order; the default
    level is circled. A result figure leaves the wall-time panel out, so the same inputs
    give the same bytes. No pyplot: the caller's backend is left alone."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullFormatter

    keys = ("dofs", "wall_s") if wall_time else ("dofs",)
    fig = Figure(figsize=(5 * len(keys) + (1 if len(keys) == 1 else 0), 4.2), layout="constrained")
    axes = fig.subplots(1, len(keys), squeeze=False)[0]
    for order, style in ((1, "s--"), (2, "o-")):
        # the reference level's own error is ~0 by construction; leave it out of the log plot
        lev = sorted((r for r in rows if r["order"] == order and r["error_pct_max"] > 0), key=lambda r: r["dofs"])
        for ax, key in zip(axes, keys):
            if not lev:
                continue
            ax.loglog([r[key] for r in lev], [r["error_pct_max"] for r in lev], style, label=f"P{order}")
            for r in lev:
                if r["is_default"]:
                    ax.loglog([r[key]], [r["error_pct_max"]], "o", ms=14, mfc="none", mec="k", label="default level")
    labels = {"dofs": "degrees of freedom (count)", "wall_s": "wall time, mesh + assemble + factorize + solves (s)"}
    for ax, key in zip(axes, keys):
        ax.set_xlabel(labels[key])
        ax.set_ylabel("max error over the positions vs Richardson (%)")
        ax.axhline(0.5, color="0.6", lw=0.8, ls=":")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)  # off the data
        ax.xaxis.set_minor_formatter(NullFormatter())
    fig.suptitle("FE single-tooth compliance: accuracy versus cost (full gear, bore fixed)", fontsize=10)
    return fig


def plot_convergence(rows: list[dict], path: str | Path, wall_time: bool = True) -> Path:
    """:func:`convergence_figure` written atomically as a PNG."""
    from gearwear.core.atomic import atomic_write

    fig = convergence_figure(rows, wall_time)
    return atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=120, metadata={"Software": None}))


def format_table(rows: list[dict], wall_time: bool = True) -> str:
    """Plain-text summary table (one line per level); a result file leaves the wall-time
    column out (``wall_time=False``) so the same inputs give the same bytes."""
    wall_head = f" {'wall s':>7}" if wall_time else ""
    head = (
        f"{'order':>5} {'scale':>7} {'h_load mm':>9} {'dofs':>8}{wall_head} {'max chg %':>9} "
        f"{'p median':>8} {'p norm':>7} {'err % (max)':>11}"
    )
    lines = [head]
    for r in rows:
        wall = f" {r['wall_s']:7.2f}" if wall_time else ""
        lines.append(
            f"{'P%d' % r['order']:>5} {r['mesh_scale']:7.3f} {r['load_size_mm']:9.3f} {r['dofs']:8d}"
            f"{wall} {r['max_change_pct']:9.3f} {r['observed_order_median']:8.2f} "
            f"{r['observed_order_norm']:7.2f} {r['error_pct_max']:11.3f}" + ("  <- default" if r["is_default"] else "")
        )
    return "\n".join(lines)
