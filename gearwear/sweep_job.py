"""Parameter sweeps of a scene: a grid of --set overrides run on any executor.

``--set KEY=START:STOP:N`` sweeps a number linearly (N points), ``--set KEY=a,b,c``
sweeps listed values (e.g. ``effects.wear.phase=unworn,mild,severe``); several
--set give the Cartesian grid. Points run on a ``concurrent.futures``-style executor:
local processes by default, or a Dask cluster's executor (``--scheduler ADDRESS``,
optional extra ``dask[distributed]``). Each point is validated like a scene file.
"""

from __future__ import annotations

import itertools
import json
import math
import os
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gearwear.core.validation import InputError

from . import io
from .scene import apply_overrides, parse_value, scene_from_dict


@dataclass(frozen=True)
class Axis:
    key: str
    values: tuple


def parse_axis(item: str) -> Axis:
    """KEY=START:STOP:N (linear) or KEY=a,b,c (listed values)."""
    if "=" not in item:
        raise InputError(f"--set {item!r}: must be KEY=START:STOP:N or KEY=a,b,c")
    key, spec = (x.strip() for x in item.split("=", 1))
    if spec.count(":") == 2:
        a, b, n = spec.split(":")
        try:
            start, stop, count = float(a), float(b), int(n)
        except ValueError:
            raise InputError(f"--set {key}={spec}: START and STOP must be numbers and N a whole number") from None
        if count < 1 or count > 10000:
            raise InputError(f"--set {key}={spec}: N = {count} must be in [1, 10000]")
        vals = np.linspace(start, stop, count)
        return Axis(key, tuple(float(v) for v in vals))
    values = tuple(parse_value(v.strip()) for v in spec.split(",") if v.strip())
    if not values:
        raise InputError(f"--set {key}={spec}: no values to sweep; give KEY=START:STOP:N or KEY=a,b,c")
    return Axis(key, values)


def grid(axes: list[Axis]) -> list[dict[str, Any]]:
    return [dict(zip([a.key for a in axes], combo)) for combo in itertools.product(*[a.values for a in axes])]


def _fmt(v) -> str:
    return repr(v) if isinstance(v, str) else (f"{v:.12g}" if isinstance(v, float) else str(v))


def point_sets(point: dict[str, Any], fixed: list[str]) -> list[str]:
    """The --set overrides of one grid point (fixed ones first)."""
    return list(fixed) + [f"{k}={_fmt(v) if not isinstance(v, str) else json.dumps(v)}" for k, v in point.items()]


def run_point(raw: dict[str, Any], name: str, point: dict[str, Any], fixed: list[str]) -> dict[str, Any]:
    """One grid point (top-level function so process and Dask executors can pickle it)."""
    from .simulate_job import run

    scene = scene_from_dict(apply_overrides(raw, point_sets(point, fixed)), name=name)
    summary = run(scene).summary()
    summary["point"] = point
    return summary


def make_executor(workers: int | None = None, scheduler: str | None = None) -> Executor:
    if scheduler:
        try:
            from dask.distributed import Client
        except ImportError:
            raise InputError(f"--scheduler {scheduler}: Dask is not installed; pip install 'gearwear[dask]'") from None
        return Client(scheduler).get_executor()
    return ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1)


def sweep(raw: dict[str, Any], name: str, axes: list[Axis], fixed: list[str] | None = None,
          executor: Executor | None = None, progress: bool = True) -> list[dict[str, Any]]:
    """Run every grid point; results in grid order (deterministic whatever the executor)."""
    from tqdm import tqdm

    points = grid(axes)
    # validate every point before starting any work: a bad value fails fast, in one line
    for p in points:
        scene_from_dict(apply_overrides(raw, point_sets(p, list(fixed or []))), name=name)
    own = executor is None
    ex = executor or make_executor()
    results: list[dict[str, Any] | None] = [None] * len(points)
    try:
        futures = {ex.submit(run_point, raw, name, p, list(fixed or [])): i for i, p in enumerate(points)}
        with tqdm(total=len(points), desc="sweep", unit="point", disable=not progress) as bar:
            for fut in as_completed(futures):
                results[futures[fut]] = fut.result()
                bar.update(1)
    finally:
        if own:
            ex.shutdown()
    return results  # type: ignore[return-value]


def table_csv(axes: list[Axis], results: list[dict[str, Any]]) -> str:
    first = results[0]
    sig_keys = list(first["harmonics"])
    n = len(first["harmonics"][sig_keys[0]])
    cols = [a.key for a in axes] + ["separation_fraction", "backside_fraction", "bearing_contact_pinion",
                                    "bearing_contact_gear", "steps"]
    for k in sig_keys:
        cols += [f"rms_{k}", f"p2p_{k}"] + [f"h{j}_{k}" for j in range(1, n + 1)]
    rows = [",".join(cols)]
    for r in results:
        vals = [str(r["point"][a.key]) if isinstance(r["point"][a.key], str) else _fmt(r["point"][a.key])
                for a in axes]
        bc = r["bearing_contact_fraction"]
        vals += [f"{r['separation_fraction']:.6g}", f"{r['backside_fraction']:.6g}",
                 f"{bc.get('pinion', float('nan')):.6g}", f"{bc.get('gear', float('nan')):.6g}",
                 str(r["steps"])]
        for k in sig_keys:
            vals += [f"{r['rms'][k]:.8g}", f"{r['peak_to_peak'][k]:.8g}"] + [f"{x:.8g}" for x in r["harmonics"][k]]
        rows.append(",".join(vals))
    return "\n".join(rows) + "\n"


def figures(axes: list[Axis], results: list[dict[str, Any]]):
    """Harmonic amplitudes versus the first swept parameter, one figure per signal
    (paper Figs. 8, 10, 12, 14, 19, 21, 23: k = 1..4; Fig. 25: F_m, k = 1..10)."""
    from .plotting import subplots

    ax0 = axes[0]
    others = axes[1:]
    figs = {}
    sig_keys = list(results[0]["harmonics"])
    for key in sig_keys:
        nh = 10 if key.startswith("F_m") else 4
        ncol = 5 if nh == 10 else 4
        nrow = math.ceil(nh / ncol)
        fig, axs = subplots(nrow, ncol, figsize=(3.2 * ncol, 2.8 * nrow), squeeze=False)
        groups: dict[tuple, list[dict]] = {}
        for r in results:
            groups.setdefault(tuple(r["point"][a.key] for a in others), []).append(r)
        xs_str = any(isinstance(v, str) for v in ax0.values)
        for gkey, rs in groups.items():
            label = ", ".join(f"{a.key.split('.')[-1]}={v}" for a, v in zip(others, gkey)) or None
            x = list(range(len(rs))) if xs_str else [r["point"][ax0.key] for r in rs]
            for k in range(nh):
                a = axs[k // ncol][k % ncol]
                a.plot(x, [r["harmonics"][key][k] for r in rs], "o-", ms=4, label=label)
                a.set_title(f"{k + 1} x fm", fontsize=9)
                if xs_str:
                    a.set_xticks(range(len(rs)))
                    a.set_xticklabels([str(r["point"][ax0.key]) for r in rs], fontsize=8)
                a.grid(alpha=0.3)
        for k in range(nh):
            a = axs[k // ncol][k % ncol]
            a.set_xlabel(ax0.key.split(".")[-1], fontsize=8)
            a.set_ylabel(key, fontsize=8)
        if others:
            axs[0][0].legend(fontsize=7)
        fig.suptitle(f"Harmonics of {key} versus {ax0.key}", fontsize=10)
        fig.tight_layout()
        figs[f"harmonics_{key}.png"] = fig
    return figs


def write(axes: list[Axis], results: list[dict[str, Any]], out: Path, inputs: dict[str, Any],
          labels: dict[str, Any] | None = None) -> list[Path]:
    """sweep.csv (+ sidecar; no wall times, they go to timing.json) and the
    harmonics-versus-parameter PNGs into the folder ``out``."""
    files = []
    csv = io.write_text(out / "sweep.csv", table_csv(axes, results))
    files += [csv, io.sidecar(csv, inputs, "gearwear sweep (dynamics.simulate per point)", labels)]
    for name, fig in figures(axes, results).items():
        files.append(io.write_figure(fig, out / name))
    return files
