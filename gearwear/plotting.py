"""Figures through matplotlib's object API only, and the few rules every figure follows.

``subplots`` is ``pyplot.subplots`` without pyplot: the Figure is not registered in
pyplot's global figure manager (nothing to close, no leak), no backend is selected
or switched (a notebook user's backend stays as it was) and rcParams are not
touched. Save the figure with :func:`gearwear.io.write_figure` (atomic PNG); PNG
rendering needs no backend, ``Figure.savefig`` picks the Agg canvas itself.

The rules (``tests/test_figures.py`` checks them on every figure the CLI writes):

* a legend never covers data: :func:`legend_outside` puts it right of or below its axes;
* two curves that would be drawn on top of each other are drawn once, and the label
  says so (:func:`merge_coincident`: "unworn = mild = severe");
* a spectrum covers the harmonics the run reports, (K + 0.5) f_m (:func:`spectrum_band_Hz`),
  and a log spectrum's axis stops :data:`FLOOR_DB` below its largest line
  (:func:`log_floor`), not at the solver's rounding noise;
* labels placed at nearby positions are staggered so they do not overprint
  (:func:`stagger_levels`).
"""

from __future__ import annotations

from typing import Literal, Sequence

import numpy as np
from matplotlib.figure import Figure

#: dots per inch of every figure drawn here, and so of its PNG (gearwear.io.write_figure
#: saves a figure at its own dpi unless told otherwise)
FIGURE_DPI = 130

#: a log spectrum's axis ends this far below its largest line (amplitude dB, 20 log10)
FLOOR_DB = 100.0


def subplots(
    nrows: int = 1,
    ncols: int = 1,
    *,
    figsize: tuple[float, float] | None = None,
    layout: Literal["constrained", "compressed", "tight"] | None = None,
    **subplot_kw,
):
    """(Figure, axes) like ``pyplot.subplots``; ``figsize`` in inches, ``subplot_kw``
    (sharex, squeeze, ...) go to :meth:`Figure.subplots`. The figure's dpi is the one
    :func:`gearwear.io.write_figure` saves at (:data:`FIGURE_DPI`): matplotlib keeps each
    text's layout per dpi, so a layout engine's pass (``tight_layout``) and the saving
    passes then measure the tick labels once instead of twice (a sweep's ten-panel figure:
    1.13 -> 0.86 s)."""
    fig = Figure(figsize=figsize, layout=layout, dpi=FIGURE_DPI)
    return fig, fig.subplots(nrows, ncols, **subplot_kw)


def legend_outside(ax, where: Literal["right", "below"] = "right", fontsize: float = 8, ncol: int = 1, **kw):
    """The legend of ``ax`` outside its axes, so it never covers data: to the right (top
    aligned) or under the tick labels and the x label (centred; the offset is in points,
    so it holds for any axes height). Layout engines (tight, constrained) and
    ``bbox_inches="tight"`` make room for it. None when nothing has a label."""
    from matplotlib.transforms import offset_copy

    if not ax.get_legend_handles_labels()[0]:
        return None
    if where == "right":
        return ax.legend(
            loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=fontsize, ncol=ncol, **kw
        )
    # tick marks, tick labels and their pads ~ 2.2 font sizes, the x label ~ 1.8 more
    size = ax.xaxis.get_label().get_fontsize()
    drop = size * (2.4 + (1.8 if ax.get_xlabel() else 0.0))
    under = offset_copy(ax.transAxes, fig=ax.figure, y=-drop, units="points")
    return ax.legend(
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        bbox_transform=under,
        borderaxespad=0.0,
        fontsize=fontsize,
        ncol=ncol,
        **kw,
    )


def spectrum_band_Hz(fm_Hz: float, harmonics: int) -> float:
    """Upper end of a spectrum plot: the K mesh harmonics the run reports and half a mesh
    order beyond, (K + 0.5) f_m."""
    return (harmonics + 0.5) * fm_Hz


def log_floor(values, depth_dB: float = FLOOR_DB) -> float:
    """The lower end of a log amplitude axis: ``depth_dB`` below the largest value (a
    tiny positive number for an all-zero signal)."""
    peak = float(np.max(values)) if np.size(values) else 0.0
    return peak * 10.0 ** (-depth_dB / 20.0) if peak > 0 else 1e-300


def merge_coincident(curves: Sequence[tuple[str, np.ndarray, np.ndarray]], tol: float) -> list[list[int]]:
    """Groups of curves (label, x, y): curves on the same x whose y lie within ``tol``
    (absolute, in y's unit) of the group's first curve everywhere, as lists of indices
    into ``curves``, in first-seen order. Draw each group once, labelled with
    :func:`joined`."""
    groups: list[list[int]] = []
    for i, (_, x, y) in enumerate(curves):
        for g in groups:
            _, x0, y0 = curves[g[0]]
            if (
                np.shape(x0) == np.shape(x)
                and np.array_equal(x0, x)
                and np.all(np.abs(np.asarray(y, float) - np.asarray(y0, float)) <= tol)
            ):
                g.append(i)
                break
        else:
            groups.append([i])
    return groups


def joined(names: Sequence[str]) -> str:
    """ "a = b = c" for curves drawn once because they coincide; a prefix up to ": " that
    all share is written once ("FE: unworn = mild")."""
    heads = {n.split(": ", 1)[0] for n in names}
    if len(names) > 1 and len(heads) == 1 and all(": " in n for n in names):
        return f"{heads.pop()}: " + " = ".join(n.split(": ", 1)[1] for n in names)
    return " = ".join(names)


def stagger_levels(positions: Sequence[float], min_gap: float) -> list[int]:
    """A level (0, 1, 2, ...) per position such that two positions closer than
    ``min_gap`` never share a level: labels drawn at ``base + level * step`` do not
    overprint. Positions in any order; the smallest free level is taken, left to right."""
    order = np.argsort(positions, kind="stable")
    last: dict[int, float] = {}
    out = [0] * len(positions)
    for i in order:
        x = float(positions[i])
        level = 0
        while level in last and x - last[level] < min_gap:
            level += 1
        last[level] = x
        out[i] = level
    return out


def plot_merged(ax, curves: Sequence[tuple[str, np.ndarray, np.ndarray, dict]], tol: float, note=None):
    """Draw curves (label, x, y, plot keywords) on ``ax``, each group that
    :func:`merge_coincident` finds within ``tol`` once, in the style of its first member
    and labelled "a = b" (+ ``note(y of the first, [y of the others])`` when they are not
    equal to the last bit), so no legend entry names a curve hidden under another.
    Returns the lines drawn."""
    lines = []
    for g in merge_coincident([c[:3] for c in curves], tol):
        _, x, y, kw = curves[g[0]]
        others = [np.asarray(curves[i][2], float) for i in g[1:]]
        differ = any(not np.array_equal(y, o) for o in others)
        label = joined([curves[i][0] for i in g]) + (note(np.asarray(y, float), others) if note and differ else "")
        lines += ax.plot(x, y, label=label, **kw)
    return lines


def range_text(y) -> str:
    """ "range 5.4 % of the mean" of the values a panel shows (beside a y axis from 0, it
    says how large a change is)."""
    y = np.asarray(y, float)
    mean = float(np.mean(y)) if y.size else 0.0
    if not mean > 0:
        return "all zero" if not np.any(y) else "mean not positive"
    pct = 100 * float(np.ptp(y)) / mean
    return f"range {pct:.0f} % of the mean" if pct >= 10 else f"range {pct:.2g} % of the mean"


def from_zero(ax, y) -> None:
    """A y axis from 0 to a little above the largest value, so a 5 % change looks like 5 %."""
    top = float(np.max(y)) if np.size(y) else 0.0
    ax.set_ylim(0, 1.08 * top if top > 0 else 1.0)


def labels_above(ax, xs: Sequence[float], texts: Sequence[str], min_gap: float, **text_kw) -> int:
    """Name x positions of ``ax`` above its axes, off the data: positions closer than
    ``min_gap`` (x units) go to different rows (:func:`stagger_levels`). Returns the
    number of rows, for the title's pad (:func:`title_pad`)."""
    levels = stagger_levels(xs, min_gap)
    for x, text, level in zip(xs, texts, levels):
        ax.annotate(
            text,
            (x, 1.0),
            xycoords=ax.get_xaxis_transform(),
            xytext=(0, 3 + LABEL_ROW_PT * level),
            textcoords="offset points",
            ha="center",
            va="bottom",
            **{"fontsize": 7, **text_kw},
        )
    return 1 + max(levels, default=-1)


#: height of a row of :func:`labels_above` (points)
LABEL_ROW_PT = 10.0


def title_pad(rows: int) -> float:
    """The title pad (points) that clears ``rows`` rows of :func:`labels_above`."""
    return 6.0 + LABEL_ROW_PT * rows
