"""Figures through matplotlib's object API only.

``subplots`` is ``pyplot.subplots`` without pyplot: the Figure is not registered in
pyplot's global figure manager (nothing to close, no leak), no backend is selected
or switched (a notebook user's backend stays as it was) and rcParams are not
touched. Save the figure with :func:`gearwear.io.write_figure` (atomic PNG); PNG
rendering needs no backend, ``Figure.savefig`` picks the Agg canvas itself.
"""

from __future__ import annotations

from typing import Literal

from matplotlib.figure import Figure


def subplots(nrows: int = 1, ncols: int = 1, *, figsize: tuple[float, float] | None = None,
             layout: Literal["constrained", "compressed", "tight"] | None = None, **subplot_kw):
    """(Figure, axes) like ``pyplot.subplots``; ``figsize`` in inches, ``subplot_kw``
    (sharex, squeeze, ...) go to :meth:`Figure.subplots`."""
    fig = Figure(figsize=figsize, layout=layout)
    return fig, fig.subplots(nrows, ncols, **subplot_kw)
