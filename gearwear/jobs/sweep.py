"""Parameter sweeps of a scene: a grid of --set overrides run on any executor.

``--set KEY=START:STOP:N`` sweeps a number linearly (N points), ``--set KEY=a,b,c``
sweeps listed values (e.g. ``effects.wear.phase=unworn,mild,severe``); several
--set give the Cartesian grid. Points run on a ``concurrent.futures``-style executor:
local processes by default, a Dask LocalCluster started for the run (``--scheduler
local[:N]``) or an existing Dask cluster (``--scheduler ADDRESS``; optional extra
``dask[distributed]``), see :func:`make_executor`. Each point is validated like a scene file.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import math
import os
import sys
import textwrap
import threading
import time
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gearwear import io
from gearwear.core import interrupts
from gearwear.core.validation import InputError
from gearwear.jobs.table_memo import TableMemo
from gearwear.scene.model import scene_from_dict
from gearwear.scene.overrides import apply_overrides, parse_value


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
            if not (math.isfinite(start) and math.isfinite(stop)):
                raise ValueError
        except ValueError:
            raise InputError(
                f"--set {key}={spec}: START and STOP must be finite numbers and N a whole number"
            ) from None
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
    from gearwear.scene.overrides import check_sets

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
    words and units, :func:`gearwear.scene.reference.key_words`); empty without axes."""
    from gearwear.scene.reference import key_words

    def one(a: Axis, v) -> str:
        words, unit = key_words(a.key)
        shown = unit if unit not in ("", "dimensionless", "category") else ""
        return f"{words} = {v}{' ' + shown if shown else ''}"

    return ", ".join(one(a, v) for a, v in zip(axes, values))


def point_sets(point: dict[str, Any], fixed: list[str]) -> list[str]:
    """The --set overrides of one grid point (fixed ones first)."""
    return list(fixed) + [
        f"{k}={format_value(v) if not isinstance(v, str) else json.dumps(v)}" for k, v in point.items()
    ]


#: this process's stiffness tables of sweep points (a worker keeps them from point to point)
TABLES = TableMemo()


def point_stiffness(scene):
    """The stiffness tables of a point's scene, through this process's :data:`TABLES`: a
    point whose stiffness inputs equal an earlier one's (a speed sweep: all of them) reuses
    its curve (gearwear.jobs.table_memo)."""
    from gearwear.jobs.simulate import stiffness_input

    return stiffness_input(scene, tables=TABLES)


_BLAS_LIMITED = False


def single_thread_blas() -> None:
    """One BLAS thread in a worker process, set once (the parent process is left alone).
    A point's BLAS work is small matrix-vector products (the exact harmonics' phasors, 11
    x ~2000 complex): a second thread only adds its wake-up and, on a busy machine, its
    spinning: the window integrals of a 0.5 s paper scene took 60-150 ms with two BLAS
    threads and 9 ms with one (measured on 2 shared cores)."""
    global _BLAS_LIMITED
    import multiprocessing

    if _BLAS_LIMITED or multiprocessing.parent_process() is None:
        return
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")
    _BLAS_LIMITED = True


def run_point(raw: dict[str, Any], name: str, point: dict[str, Any], fixed: list[str]) -> dict[str, Any]:
    """One grid point (top-level function so process and Dask executors can pickle it)."""
    from gearwear.jobs.simulate import run

    single_thread_blas()
    scene = scene_from_dict(apply_overrides(raw, point_sets(point, fixed)), name=name)
    summary = run(scene, stiffness=point_stiffness(scene)).summary()
    summary["point"] = point
    return summary


#: seconds an interrupted pool gets to end its workers before they are killed
STOP_TIMEOUT_S = 5.0
#: seconds to wait for a Dask scheduler (--scheduler ADDRESS) to answer, and for it to have a worker
CONNECT_TIMEOUT_S = 10.0


class _StopsOnError:
    """``with executor:`` that waits for its tasks on a normal exit, but on an exception
    (KeyboardInterrupt and core.interrupts.Terminated included) calls ``stop``: pending
    tasks cancelled, workers ended now, within a bounded time."""

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.shutdown(wait=True)  # type: ignore[attr-defined]
        else:
            self.stop()  # type: ignore[attr-defined]
        return False


class LocalPool(_StopsOnError, ProcessPoolExecutor):
    """Local worker processes that end with the command.

    Each worker ignores SIGINT (a Ctrl-C in the terminal reaches the whole process group;
    the parent handles it once) and ends on SIGTERM without a word
    (core.interrupts.worker_init); it is forked with both signals blocked, so neither can
    reach it before that (:meth:`submit`). Leaving a ``with`` block on an exception,
    KeyboardInterrupt included, :meth:`stop` cancels what has not started and ends the
    workers at once instead of waiting for every submitted task."""

    def __init__(self, workers: int):
        super().__init__(max_workers=workers, initializer=_worker_start, initargs=(workers,))

    def submit(self, fn, /, *args, **kwargs):  # type: ignore[override]
        # with the fork start method the workers are forked here, inheriting the signal mask
        with interrupts.deferred(children=True):
            return super().submit(fn, *args, **kwargs)

    def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> None:
        """Cancel the pending tasks and end the workers: SIGTERM, then SIGKILL for any still
        running after ``timeout_s``."""
        procs = list((getattr(self, "_processes", None) or {}).values())
        manager = getattr(self, "_executor_manager_thread", None)
        self.shutdown(wait=False, cancel_futures=True)
        for proc in procs:
            with contextlib.suppress(OSError, ValueError):
                proc.terminate()
        deadline = time.monotonic() + timeout_s
        for proc in procs:
            with contextlib.suppress(OSError, ValueError, AssertionError):
                proc.join(max(0.0, deadline - time.monotonic()))
                if proc.is_alive():
                    proc.kill()
                    proc.join(1.0)
        # let the pool's manager thread finish closing its wakeup pipe now: left to wind down
        # while the interpreter exits, it races CPython 3.11's exit hook, which writes to
        # that pipe as it closes ("Exception ignored ... Bad file descriptor" on stderr
        # after the one line of an interrupted command)
        if manager is not None:
            manager.join(max(0.1, deadline - time.monotonic()))


def _worker_start(workers: int) -> None:
    """Initializer of a LocalPool worker: its signal dispositions, then its share of the cores."""
    interrupts.worker_init()
    _share_cores(workers)


class DaskExecutor(_StopsOnError, Executor):
    """A Dask cluster as a plain ``concurrent.futures.Executor`` (its futures are
    ``concurrent.futures.Future``), so every caller that takes an executor (sweeps, run-ups,
    FE positions) runs on it unchanged. ``shutdown`` closes the client and, for a cluster
    this process started (``--scheduler local``), the cluster and its workers; leaving a
    ``with`` block on an exception (Ctrl-C included) :meth:`stop` cancels the futures and
    closes both within a bounded time."""

    def __init__(self, client, cluster=None):
        self.client = client
        self.cluster = cluster
        self._executor = client.get_executor()

    def submit(self, fn, /, *args, **kwargs):  # type: ignore[override]
        return self._executor.submit(fn, *args, **kwargs)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        try:
            self._executor.shutdown(wait=wait and not cancel_futures)
        finally:
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()

    def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> None:
        """Cancel every future and close the client and a cluster started here, each
        bounded by ``timeout_s``; a worker process of that cluster still running then is
        killed."""
        import psutil  # type: ignore[import-untyped]  # installed with distributed (no stubs)

        procs = []
        for nanny in getattr(self.cluster, "workers", {}).values():
            with contextlib.suppress(Exception):
                procs.append(psutil.Process(nanny.pid))
        with contextlib.suppress(Exception):
            self._executor.shutdown(wait=False)  # cancels the futures
        with contextlib.suppress(Exception):
            self.client.close(timeout=timeout_s)
        # a worker still inside a task would get seconds of grace from the cluster's close;
        # its tasks are cancelled, so it ends now (psutil checks that the process is still
        # the one it was, not a new one with a reused pid)
        for proc in procs:
            with contextlib.suppress(psutil.Error):
                proc.terminate()
        if self.cluster is not None:
            with contextlib.suppress(Exception):
                self.cluster.close(timeout=timeout_s)
        for proc in procs:
            with contextlib.suppress(psutil.Error):
                proc.kill()


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
        raise InputError(
            f"--scheduler = {scheduler!r}: local:N needs a whole number of workers N in [1, {MAX_LOCAL_WORKERS}]"
        ) from None
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

    * no scheduler: local processes (:class:`LocalPool`, ``workers``, default all cores);
    * ``local`` or ``local:N``: a ``dask.distributed.LocalCluster`` started here (N worker
      processes, default the machine's cores, one thread each, on the loopback interface;
      its HTTP server on a free port: with None Dask still takes 8787 and warns on stderr
      when another cluster has it), closed again by ``shutdown``; its workers are started with SIGINT
      blocked (core.interrupts.blocked_sigint), so a Ctrl-C reaches only this process;
    * anything else: the address of a running Dask scheduler (``tcp://host:8786``), which
      must answer and have a worker within CONNECT_TIMEOUT_S (:func:`connect`).

    Use it in a ``with`` block: leaving it on an exception (Ctrl-C included) stops the
    workers at once. Dask needs the optional extra ``gearwear[dask]`` (it is in the
    ``test`` extra too)."""
    if not scheduler:
        return LocalPool(workers or os.cpu_count() or 1)
    n = _local_workers(scheduler)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError(f"--scheduler {scheduler}: Dask is not installed; pip install 'gearwear[dask]'") from None
    if n == -1:
        return DaskExecutor(connect(scheduler))
    import logging

    import dask

    # one thread per worker: the kernels are single-threaded numba code, and two threads
    # in one process would share one GIL between their Python parts. Dask starts its
    # workers with MALLOC_TRIM_THRESHOLD_=65536, which also switches off glibc's dynamic
    # mmap threshold: every array above 128 KiB is then a fresh mmap whose pages fault in
    # zeroed, and a 1 s simulation with its summary ran 2x slower than in a plain process
    # (0.36 s against 0.18 s per scene, measured); the workers keep glibc's defaults.
    with (
        dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}),
        interrupts.blocked_sigint(),
    ):
        cluster = LocalCluster(
            n_workers=n or os.cpu_count() or 1,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
            silence_logs=logging.ERROR,
        )
    try:
        return DaskExecutor(Client(cluster), cluster)
    except BaseException:
        cluster.close(timeout=STOP_TIMEOUT_S)
        raise


def connect(address: str, timeout_s: float = CONNECT_TIMEOUT_S):
    """A ``dask.distributed.Client`` of the scheduler at ``address``, or a one-line
    InputError naming the address if nothing there answers as a Dask scheduler within
    ``timeout_s`` (nobody listening, a server that accepts the connection and never
    answers) or the scheduler has no worker within another ``timeout_s``. The connection is
    made in a thread waited on with a deadline: Dask's own timeout covers opening the
    connection, not a peer that accepts it and stays silent."""
    from dask.distributed import Client

    box: dict[str, Any] = {}

    def attempt() -> None:
        try:
            box["client"] = Client(address, timeout=f"{timeout_s}s")
        except BaseException as exc:  # reported by the waiting thread
            box["error"] = exc

    def bad(why: str) -> InputError:
        return InputError(
            f"--scheduler = {address}: {why}; give the address of a running Dask scheduler with "
            "workers, e.g. tcp://host:8786, or local[:N]"
        )

    thread = threading.Thread(target=attempt, name="gearwear dask connect", daemon=True)
    thread.start()
    thread.join(timeout_s + 1.0)
    if thread.is_alive():
        raise bad(f"no answer from a Dask scheduler there within {timeout_s:g} s")
    if "error" in box:
        exc = box["error"]
        first = str(exc).splitlines()[0] if str(exc) else ""
        raise bad(f"cannot connect to a Dask scheduler there ({type(exc).__name__}: {first})")
    client = box["client"]
    try:
        client.wait_for_workers(1, timeout=timeout_s)
    except (OSError, TimeoutError):  # asyncio and Dask time-outs are TimeoutError or OSError
        with contextlib.suppress(Exception):
            client.close(timeout=1)
        raise bad(f"the scheduler there has no worker (waited {timeout_s:g} s)") from None
    return client


def sweep(
    raw: dict[str, Any],
    name: str,
    axes: list[Axis],
    fixed: list[str] | None = None,
    executor: Executor | None = None,
    progress: bool = True,
    warm_figures_after: bool = False,
) -> list[dict[str, Any]]:
    """Run every grid point; results in grid order (deterministic whatever the executor).
    A run estimated to take longer than LONG_RUN_S says so on stderr once its first point
    is done (:class:`Estimate`). ``warm_figures_after``: queue one :func:`warm_figures`
    per worker behind the points (the caller renders the figures on the same executor)."""
    from tqdm import tqdm

    points = grid(axes)
    # validate every point before starting any work: a bad value fails fast, in one line
    for p in points:
        scene_from_dict(apply_overrides(raw, point_sets(p, list(fixed or []))), name=name)
    results: list[dict[str, Any] | None] = [None] * len(points)
    with contextlib.ExitStack() as stack:
        ex = executor or stack.enter_context(make_executor())
        parallel = min(workers_of(ex), len(points))
        estimate = Estimate(f"sweep of {len(points)} points", parallel, math.ceil(len(points) / parallel))
        futures = {ex.submit(run_point, raw, name, p, list(fixed or [])): i for i, p in enumerate(points)}
        if warm_figures_after:
            for _ in range(parallel):
                ex.submit(warm_figures)
        with tqdm(total=len(points), desc="sweep", unit="point", disable=not progress, file=sys.stderr) as bar:
            for fut in as_completed(futures):
                results[futures[fut]] = fut.result()
                bar.update(1)
                estimate.first_done(bar.write)
    return results  # type: ignore[return-value]


#: a sweep or run-up estimated to take longer than this states its estimate (stderr, once)
LONG_RUN_S = 60.0
#: a sweep or run-up of more evaluations than this is refused unless --allow-large is given
MAX_POINTS = 2000
#: ... and of more than this even with --allow-large (the grid is held in memory)
HARD_MAX_POINTS = 1_000_000


def check_size(count: int, what: str, allow_large: bool) -> None:
    """A one-line InputError if a sweep or run-up of ``count`` evaluations (``what`` names
    them: "grid points", "runs (speeds x points x directions)") is larger than MAX_POINTS
    without ``allow_large``, or than HARD_MAX_POINTS at all."""
    if count > HARD_MAX_POINTS:
        raise InputError(
            f"--set: {count} {what}, more than {HARD_MAX_POINTS} (the grid is held in memory); split the sweep"
        )
    if count > MAX_POINTS and not allow_large:
        raise InputError(
            f"--set: {count} {what}, more than {MAX_POINTS} (hours of computation); give "
            "--allow-large to run them anyway (the estimated time is printed once the first is done)"
        )


def workers_of(executor: Executor) -> int:
    """How many tasks ``executor`` runs at once (worker processes, or Dask worker threads)."""
    n = getattr(executor, "_max_workers", None)
    if isinstance(n, int):
        return n
    client = getattr(executor, "client", None)
    if client is not None:
        with contextlib.suppress(Exception):
            return max(1, sum(int(w.get("nthreads", 1)) for w in client.scheduler_info()["workers"].values()))
    return os.cpu_count() or 1


class Estimate:
    """The estimated time of a long run, stated once: when the first task is done, its wall
    time (from the start, so it includes starting the workers) times the ``rounds`` of
    tasks that follow each other on ``parallel`` workers. Printed (one line through
    ``write``, above the progress bar) only if that exceeds LONG_RUN_S."""

    def __init__(self, what: str, parallel: int, rounds: int):
        self.what, self.parallel, self.rounds = what, max(1, parallel), rounds
        self.t0 = time.perf_counter()
        self.said = False

    def first_done(self, write) -> None:
        if self.said:
            return
        self.said = True
        first = time.perf_counter() - self.t0
        total = first * self.rounds
        if total > LONG_RUN_S:
            write(
                f"gearwear: {self.what} on {self.parallel} worker{'s' if self.parallel > 1 else ''}: about "
                f"{duration_text(total)} in all (the first took {first:.1f} s)",
                file=sys.stderr,
            )


def duration_text(seconds: float) -> str:
    """``45 s``, ``12 min``, ``3 h 20 min``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{int(seconds // 3600)} h {int(seconds % 3600 // 60)} min"


def table_csv(axes: list[Axis], results: list[dict[str, Any]]) -> str:
    first = results[0]
    sig_keys = list(first["harmonics"])
    n = len(first["harmonics"][sig_keys[0]])
    cols = [a.key for a in axes] + [
        "separation_fraction",
        "backside_fraction",
        "bearing_contact_pinion",
        "bearing_contact_gear",
        "steps",
    ]
    for k in sig_keys:
        cols += [f"mean_{k}", f"ac_rms_{k}", f"p2p_{k}"] + [f"h{j}_{k}" for j in range(1, n + 1)]
    rows = [",".join(cols)]
    for r in results:
        vals = [csv_cell(r["point"][a.key]) for a in axes]
        bc = r["bearing_contact_fraction"]
        sep = r["separation_fraction"]  # None (empty cell): no backlash dead zone, the mesh cannot separate
        vals += [
            "" if sep is None else f"{sep:.6g}",
            f"{r['backside_fraction']:.6g}",
            f"{bc.get('pinion', float('nan')):.6g}",
            f"{bc.get('gear', float('nan')):.6g}",
            str(r["steps"]),
        ]
        for k in sig_keys:
            vals += [f"{r[q][k]:.8g}" for q in ("mean", "ac_rms", "peak_to_peak")] + [
                f"{x:.8g}" for x in r["harmonics"][k]
            ]
        rows.append(",".join(vals))
    return "\n".join(rows) + "\n"


def figures(axes: list[Axis], results: list[dict[str, Any]]):
    """Harmonic amplitudes versus the first swept parameter, one figure per signal
    (paper Figs. 8, 10, 12, 14, 19, 21, 23: k = 1..4; Fig. 25: F_m, k = 1..10). Labels
    in words with units from the schema (any swept key) and the signal table; every
    y axis starts at 0 and each panel's title gives the range in % of its mean, so a
    5 % change looks like 5 %."""
    return {f"harmonics_{key}.png": figure(axes, results, key) for key in results[0]["harmonics"]}


def figure_png(axes: list[Axis], results: list[dict[str, Any]], key: str) -> bytes:
    """The PNG of :func:`figure` (a task for a worker: the figures of a sweep render in
    parallel, and only the bytes come back)."""
    return io.figure_bytes(figure(axes, results, key))


def warm_figures() -> None:
    """Import the plotting stack in a worker and draw a small figure (the first drawing
    loads the fonts: ~1 s more than the next one), queued behind a sweep's points: a worker
    with no point left does it while the others finish their last ones."""
    from gearwear.plotting import subplots
    from gearwear.scene.reference import key_label  # noqa: F401

    fig, ax = subplots(figsize=(1.0, 1.0))
    ax.set_title("k = 1", fontsize=8)
    io.figure_bytes(fig, dpi=20)


def panel_count(results: list[dict[str, Any]], key: str) -> int:
    """Panels of the figure of signal ``key``: one per harmonic shown (F_m: k = 1..10, the
    others k = 1..4, fewer if the summaries have fewer)."""
    return min(10 if key.startswith("F_m") else 4, len(results[0]["harmonics"][key]))


def figure(axes: list[Axis], results: list[dict[str, Any]], key: str):
    """The harmonics-versus-parameter figure of signal ``key`` (:func:`figures`); reads
    each result's ``point`` and ``harmonics`` only."""
    from gearwear.jobs.simulate import SIGNAL_WORDS, signal_label, signal_name
    from gearwear.plotting import from_zero, legend_outside, range_text, subplots
    from gearwear.scene.reference import key_label

    ax0 = axes[0]
    others = axes[1:]
    xlabel = key_label(ax0.key)
    nh = panel_count(results, key)
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
    fig.suptitle(
        f"Mesh harmonics k f_m of the {SIGNAL_WORDS[signal_name(key)]} versus the {xlabel}; y axes from 0",
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def write(
    axes: list[Axis],
    results: list[dict[str, Any]],
    out: Path,
    inputs: dict[str, Any],
    labels: dict[str, Any] | None = None,
    executor: Executor | None = None,
) -> list[Path]:
    """sweep.csv (+ sidecar; no wall times, they go to timing.json) and the
    harmonics-versus-parameter PNGs into the folder ``out``. With an ``executor`` (the
    sweep's own workers) the figures render there, one task each, in parallel (a second
    or more each: the parent's largest cost after the points), and come back as PNG bytes,
    the same bytes :func:`gearwear.io.write_figure` writes."""
    keys = list(results[0]["harmonics"])
    pngs: dict[str, Any] = {}
    if executor is not None:
        slim = [{"point": r["point"], "harmonics": r["harmonics"]} for r in results]
        # the largest figure first (F_m's ten panels take as long as two of four panels):
        # queued in file order, two workers ended 0.6 s apart, one idle (the longest
        # processing time first rule; the files are written in file order all the same)
        for key in sorted(keys, key=lambda k: -panel_count(results, k)):
            pngs[key] = executor.submit(figure_png, axes, slim, key)
    files = []
    csv = io.write_text(out / "sweep.csv", table_csv(axes, results))
    files += [csv, io.sidecar(csv, inputs, "gearwear sweep (dynamics.simulate per point)", labels)]
    for key in keys:
        name = f"harmonics_{key}.png"
        if pngs:
            files.append(io.write_bytes(out / name, pngs[key].result()))
        else:
            files.append(io.write_figure(figure(axes, results, key), out / name))
    return files
