"""Parameter sweeps of a scene: a grid of --set overrides run on any executor.

``--set KEY=START:STOP:N`` sweeps a number linearly (N points), ``--set KEY=a,b,c``
sweeps listed values (e.g. ``effects.wear.phase=unworn,mild,severe``); several
--set give the Cartesian grid. Points run on a ``concurrent.futures``-style executor:
local processes by default, a Dask LocalCluster started for the run (``--scheduler
local[:N]``) or an existing Dask cluster (``--scheduler ADDRESS``; optional extra
``dask[distributed]``), see :func:`make_executor`. Each point is validated like a scene file.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import textwrap
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


def split_sets(items: list[str]) -> tuple[list[Axis], list[str]]:
    """--set items as swept axes (KEY=START:STOP:N, KEY=a,b,c) and fixed overrides (the rest,
    and any value that is a TOML array, table or string)."""
    from .scene import check_sets

    check_sets(items)  # one line per --set, each key once (a swept key too)
    axes: list[Axis] = []
    fixed: list[str] = []
    for item in items:
        spec = item.split("=", 1)[1].strip() if "=" in item else ""
        if spec[:1] in "[{\"'" or ("," not in spec and spec.count(":") != 2):
            fixed.append(item)
        else:
            axes.append(parse_axis(item))
    return axes, fixed


def grid(axes: list[Axis]) -> list[dict[str, Any]]:
    return [dict(zip([a.key for a in axes], combo)) for combo in itertools.product(*[a.values for a in axes])]


def format_value(v) -> str:
    """A swept value as text: a float to 12 significant digits, a string as its repr."""
    return repr(v) if isinstance(v, str) else (f"{v:.12g}" if isinstance(v, float) else str(v))


def csv_cell(v) -> str:
    """A swept value as a CSV cell: a string as is, a number by :func:`format_value`."""
    return str(v) if isinstance(v, str) else format_value(v)


def point_label(axes: list[Axis], values) -> str:
    """A point's values on ``axes`` in words, "pinion torque = 10 N m, ..." (the schema's
    words and units, :func:`gearwear.schema.key_words`); empty without axes."""
    from .schema import key_words

    def one(a: Axis, v) -> str:
        words, unit = key_words(a.key)
        shown = unit if unit not in ("", "dimensionless", "category") else ""
        return f"{words} = {v}{' ' + shown if shown else ''}"

    return ", ".join(one(a, v) for a, v in zip(axes, values))


def point_sets(point: dict[str, Any], fixed: list[str]) -> list[str]:
    """The --set overrides of one grid point (fixed ones first)."""
    return list(fixed) + [f"{k}={format_value(v) if not isinstance(v, str) else json.dumps(v)}"
                          for k, v in point.items()]


def run_point(raw: dict[str, Any], name: str, point: dict[str, Any], fixed: list[str]) -> dict[str, Any]:
    """One grid point (top-level function so process and Dask executors can pickle it)."""
    from .simulate_job import run

    scene = scene_from_dict(apply_overrides(raw, point_sets(point, fixed)), name=name)
    summary = run(scene).summary()
    summary["point"] = point
    return summary


class DaskExecutor(Executor):
    """A Dask cluster as a plain ``concurrent.futures.Executor`` (its futures are
    ``concurrent.futures.Future``), so every caller that takes an executor (sweeps, run-ups,
    FE positions) runs on it unchanged. ``shutdown`` closes the client and, for a cluster
    this process started (``--scheduler local``), the cluster and its workers."""

    def __init__(self, client, cluster=None):
        self.client = client
        self.cluster = cluster
        self._executor = client.get_executor()

    def submit(self, fn, /, *args, **kwargs):  # type: ignore[override]
        return self._executor.submit(fn, *args, **kwargs)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        try:
            self._executor.shutdown(wait=wait)
        finally:
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()


#: --scheduler local:N accepts 1 .. this many worker processes
MAX_LOCAL_WORKERS = 256


def _local_workers(scheduler: str) -> int | None:
    """N of ``local`` / ``local:N`` (None: the machine's cores); not a local spec -> -1."""
    if scheduler == "local":
        return None
    if not scheduler.startswith("local:"):
        return -1
    text = scheduler.split(":", 1)[1]
    try:
        n = int(text)
    except ValueError:
        raise InputError(f"--scheduler = {scheduler!r}: local:N needs a whole number of workers N in "
                         f"[1, {MAX_LOCAL_WORKERS}]") from None
    if not 1 <= n <= MAX_LOCAL_WORKERS:
        raise InputError(f"--scheduler = {scheduler!r}: N = {n} workers must be in [1, {MAX_LOCAL_WORKERS}]")
    return n


def _share_cores(workers: int) -> None:
    """Worker initializer: the BLAS thread pool gets this worker's share of the cores. A
    forked worker inherits a pool sized for the whole machine, so N workers ran N x cores
    BLAS threads: 100 scenes on 2 workers took 15.0 s, and 11.7 s with one thread each
    (benchmarks/bench_sweep_scale.py). Dask sets the same limit in its workers' environment."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=max(1, (os.cpu_count() or 1) // workers), user_api="blas")


def make_executor(workers: int | None = None, scheduler: str | None = None) -> Executor:
    """The executor that runs independent tasks (grid points, run-up chains, FE positions):

    * no scheduler: local processes (``workers``, default all cores);
    * ``local`` or ``local:N``: a ``dask.distributed.LocalCluster`` started here (N worker
      processes, default the machine's cores, one thread each, on the loopback interface,
      no dashboard), closed again by ``shutdown``;
    * anything else: the address of a running Dask scheduler (``tcp://host:8786``).

    Dask needs the optional extra ``gearwear[dask]`` (it is in the ``test`` extra too)."""
    if not scheduler:
        procs = workers or os.cpu_count() or 1
        return ProcessPoolExecutor(max_workers=procs, initializer=_share_cores, initargs=(procs,))
    n = _local_workers(scheduler)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError(f"--scheduler {scheduler}: Dask is not installed; pip install 'gearwear[dask]'") from None
    if n != -1:
        import logging

        import dask

        # one thread per worker: the kernels are single-threaded numba code, and two threads
        # in one process would share one GIL between their Python parts. Dask starts its
        # workers with MALLOC_TRIM_THRESHOLD_=65536, which also switches off glibc's dynamic
        # mmap threshold: every array above 128 KiB is then a fresh mmap whose pages fault in
        # zeroed, and a 1 s simulation with its summary ran 2x slower than in a plain process
        # (0.36 s against 0.18 s per scene, measured); the workers keep glibc's defaults.
        with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
            cluster = LocalCluster(n_workers=n or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR)
        try:
            return DaskExecutor(Client(cluster), cluster)
        except BaseException:
            cluster.close()
            raise
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"--scheduler = {scheduler}: cannot connect to a Dask scheduler there "
                         f"({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})") from None
    return DaskExecutor(client)


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
        cols += [f"mean_{k}", f"ac_rms_{k}", f"p2p_{k}"] + [f"h{j}_{k}" for j in range(1, n + 1)]
    rows = [",".join(cols)]
    for r in results:
        vals = [csv_cell(r["point"][a.key]) for a in axes]
        bc = r["bearing_contact_fraction"]
        sep = r["separation_fraction"]  # None (empty cell): no backlash dead zone, the mesh cannot separate
        vals += ["" if sep is None else f"{sep:.6g}", f"{r['backside_fraction']:.6g}",
                 f"{bc.get('pinion', float('nan')):.6g}", f"{bc.get('gear', float('nan')):.6g}",
                 str(r["steps"])]
        for k in sig_keys:
            vals += [f"{r[q][k]:.8g}" for q in ("mean", "ac_rms", "peak_to_peak")] \
                + [f"{x:.8g}" for x in r["harmonics"][k]]
        rows.append(",".join(vals))
    return "\n".join(rows) + "\n"


def figures(axes: list[Axis], results: list[dict[str, Any]]):
    """Harmonic amplitudes versus the first swept parameter, one figure per signal
    (paper Figs. 8, 10, 12, 14, 19, 21, 23: k = 1..4; Fig. 25: F_m, k = 1..10). Labels
    in words with units from the schema (any swept key) and the signal table; every
    y axis starts at 0 and each panel's title gives the range in % of its mean, so a
    5 % change looks like 5 %."""
    from .plotting import from_zero, legend_outside, range_text, subplots
    from .schema import key_label
    from .simulate_job import SIGNAL_WORDS, signal_label, signal_name

    ax0 = axes[0]
    others = axes[1:]
    figs = {}
    sig_keys = list(results[0]["harmonics"])
    xlabel = key_label(ax0.key)
    for key in sig_keys:
        nh = min(10 if key.startswith("F_m") else 4, len(results[0]["harmonics"][key]))
        ncol = 5 if nh > 4 else max(nh, 1)
        nrow = math.ceil(nh / ncol)
        fig, axs = subplots(nrow, ncol, figsize=(3.2 * ncol, 2.9 * nrow), squeeze=False)
        groups: dict[tuple, list[dict]] = {}
        for r in results:
            groups.setdefault(tuple(r["point"][a.key] for a in others), []).append(r)
        xs_str = any(isinstance(v, str) for v in ax0.values)
        for gkey, rs in groups.items():
            label = point_label(others, gkey) or None
            x = list(range(len(rs))) if xs_str else [r["point"][ax0.key] for r in rs]
            for k in range(nh):
                a = axs[k // ncol][k % ncol]
                a.plot(x, [r["harmonics"][key][k] for r in rs], "o-", ms=4, label=label)
                if xs_str:
                    a.set_xticks(range(len(rs)))
                    a.set_xticklabels([str(r["point"][ax0.key]) for r in rs], fontsize=8)
        for k in range(nh):
            a = axs[k // ncol][k % ncol]
            y = np.array([r["harmonics"][key][k] for r in results], float)
            from_zero(a, y)
            a.set_title(f"k = {k + 1}: {range_text(y)}", fontsize=8)
            a.set_xlabel(xlabel, fontsize=8)
            a.set_ylabel(textwrap.fill(signal_label(key, "harmonic k"), 32), fontsize=8)
            a.grid(alpha=0.3)
        for k in range(nh, nrow * ncol):
            axs[k // ncol][k % ncol].set_visible(False)
        if others:
            legend_outside(axs[0][ncol - 1], fontsize=7)
        fig.suptitle(f"Mesh harmonics k f_m of the {SIGNAL_WORDS[signal_name(key)]} versus the "
                     f"{xlabel}; y axes from 0", fontsize=10)
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
