"""Draw and save the paper report's figures on the local cores.

Twenty figures take ~20 s to lay out and rasterise in one process (matplotlib, Agg), about
as long as the rest of a report whose tables are cached. The figures are independent, so
they are drawn in forked worker processes (gearwear.jobs.sweep.LocalPool), one task per
figure, the slowest first (the 10-panel harmonic grids). The workers are forked after the
results exist and inherit them (``_RESULTS``): nothing is pickled but the file names, and
each worker draws with the same code, fonts and settings as this process, so every PNG
has the same bytes as one drawn here.
"""

from __future__ import annotations

import multiprocessing
import os
from pathlib import Path
from typing import Any

from gearwear import io

#: the results the forked workers draw from (set before they are forked, read in them)
_RESULTS: dict[str, Any] | None = None


def _draw(name: str, folder: Path, dpi: int) -> Path:
    """Worker task: draw figure ``name`` from the inherited results and save it."""
    from gearwear.reports.paper import figure_builders

    assert _RESULTS is not None, "paper_render._draw runs in a worker forked by render()"
    return io.write_figure(figure_builders(_RESULTS)[name](), folder / name, dpi=dpi)


def _cost(name: str) -> int:
    """Drawing order: the harmonic grids (up to 10 panels, most text to lay out) first,
    so that no large figure is left for one worker at the end."""
    return 0 if "harmonics" in name else 1


def render(res: dict[str, Any], names: list[str], folder: Path, dpi: int, workers: int | None = None) -> list[Path]:
    """Every figure of ``names`` drawn from ``res`` into ``folder`` (PNG, ``dpi``), on
    ``workers`` processes (default: the cores; one: in this process). Returns the paths
    in the order of ``names``."""
    global _RESULTS
    workers = workers or os.cpu_count() or 1
    # the workers must inherit the results: only a forked worker does
    if workers == 1 or len(names) < 2 or multiprocessing.get_start_method() != "fork":
        from gearwear.reports.paper import figure_builders

        builders = figure_builders(res)
        return [io.write_figure(builders[n](), folder / n, dpi=dpi) for n in names]
    from gearwear.jobs.sweep import make_executor

    _RESULTS = res
    try:
        with make_executor(min(workers, len(names))) as pool:
            futures = {n: pool.submit(_draw, n, folder, dpi) for n in sorted(names, key=_cost)}
            return [futures[n].result() for n in names]
    finally:
        _RESULTS = None
