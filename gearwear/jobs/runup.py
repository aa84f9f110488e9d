"""``gearwear runup``: speed run-ups with natural continuation, jump bands and ISO 6336 K_v.

``--set operating.speed_rpm=START:STOP:N`` gives the speeds; any other swept key
(``--set operating.torque_Nm=5,20``) gives independent parameter points, each run up (and/or
down) on its own. A run-up is a chain: each speed starts from the state the previous speed
ended in (``dynamics.steady.steady_state``: the kept window ends on whole table periods, so
the stiffness phase at the next run's t = 0 matches that state), so the up and down sweeps
can follow different branches of a nonlinear response. Chains are independent and run
concurrently on the executor (local processes or Dask, ``sweep_job.make_executor``); within
a chain the speeds follow each other, one task per speed, which is what the progress bar
counts.

Per speed (from the kept window of the steady state): the dynamic factor
K_v = max F_m / F_s (F_s = T_p / r_b1, the static normal mesh force), the dynamic
transmission error delta (RMS about its mean, peak-to-peak, mean; um), the fractions of
contact loss and back-side contact, exact window harmonics 1-10 of delta and F_m, the
Poincare-section residual and the label (periodic with its period, quasi-periodic, chaotic,
unsettled). A jump band is a run of speeds where the up and down K_v differ by more than
``jump_tol`` of the larger one.

Next to it, ISO 6336-1 method B K_v (``analytic.iso6336.dynamic_factor``) with its
resonance speed n_E1 from this tool's own mean mesh stiffness per face width c_gamma (the
scene's stiffness source) and the reduced mass m_red = m_e / b of the scene's inertias and
base radii; c', epsilon and the line load are ISO's (``iso6336_stiffness``, low-load factor
included), the deviations come from the scene's ``[iso6336]`` table. ISO's gear 1 is the
gear with fewer teeth, whichever drives: the run-up's (driver) speeds n enter ISO as that
gear's speeds n z_driver / z1, ``n_E1_rpm`` is a speed of that gear (z1 in the ISO
inputs) and ``n_E1_driver_rpm`` the same resonance as a driver speed (the run-up's axis);
m_red and the mesh stiffness do not depend on the order.
"""

from __future__ import annotations

import dataclasses
import math
from concurrent.futures import FIRST_COMPLETED, Executor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gearwear import io
from gearwear.core.validation import InputError
from gearwear.jobs.sweep import Axis, csv_cell, format_value, grid, point_label, point_sets
from gearwear.scene.model import Scene, scene_from_dict
from gearwear.scene.overrides import apply_overrides

SPEED_KEY = "operating.speed_rpm"
DIRECTIONS = ("up", "down", "both")
N_HARMONICS = 10


@dataclass(frozen=True)
class Settings:
    """Steady-state detection (dynamics.steady.steady_state) and the jump criterion."""

    tol: float = 1e-6  # Poincare-section residual (distance estimate) for "periodic"
    max_periods: int = 1500  # table periods integrated at most per speed before the kept window
    chunk_periods: int = 40  # table periods per convergence check
    keep_periods: int = 32  # table periods of the kept window (rounded up to a multiple of p)
    p_max: int = 8  # longest period looked for (table periods)
    jump_tol: float = 0.01  # up and down K_v differ by more than this fraction: a jump


@dataclass
class Chain:
    """One run-up: a parameter point, a direction and its speeds in sweep order."""

    point_index: int
    direction: str
    speeds: list[float]
    rows: list[dict[str, Any]] = field(default_factory=list)


@dataclass
class Point:
    """A parameter point: its scene (at the first speed), the dynamic model and the ISO curve."""

    values: dict[str, Any]
    scene: Scene
    model: Any  # GearDynamics at the first speed; other speeds change omega_p only
    solver: dict[str, Any]
    iso: dict[str, Any]  # ISO 6336 K_v at ``speeds`` and its inputs
    eigenfrequencies_Hz: list[float]
    speeds: tuple  # rpm, ascending
    mean_stiffness_N_per_m: float = math.nan  # of the scene's mesh stiffness: ISO's c_gamma

    def at_speeds(self, speeds_rpm) -> "Point":
        """The same point (model, modes) at other driver speeds (rpm, ascending): only the
        ISO 6336 curve depends on them."""
        speeds = tuple(float(v) for v in speeds_rpm)
        return dataclasses.replace(
            self, speeds=speeds, iso=iso_curve(self.scene, self.mean_stiffness_N_per_m, self.model.m_e, speeds)
        )


def build_point(values: dict[str, Any], scene: Scene, speeds_rpm) -> Point:
    """A parameter point: the scene's mesh stiffness and dynamic model (built once), its
    linear modes and the ISO 6336 curve at the driver speeds ``speeds_rpm``."""
    from gearwear.dynamics.model import linear_eigenfrequencies
    from gearwear.jobs.simulate import build_model, stiffness_input

    stiff = stiffness_input(scene)
    model = build_model(scene, stiff)
    solver: dict[str, Any] = {
        k: scene.solver[k] for k in ("method", "steps_per_mesh_period", "rtol", "atol") if k in scene.solver
    }
    speeds = tuple(float(v) for v in speeds_rpm)
    return Point(
        values,
        scene,
        model,
        solver,
        iso_curve(scene, stiff.mean_N_per_m, model.m_e, speeds),
        [float(f) for f in linear_eigenfrequencies(model)],
        speeds,
        stiff.mean_N_per_m,
    )


def split_speed_axis(axes: list[Axis]) -> tuple[Axis, list[Axis]]:
    """The speed axis (required, a numeric sweep) and the other axes (parameter points)."""
    speed = [a for a in axes if a.key == SPEED_KEY]
    if not speed:
        raise InputError(f"--set: give the speeds as {SPEED_KEY}=START:STOP:N (or a list a,b,c)")
    ax = speed[0]
    if any(isinstance(v, str) or isinstance(v, bool) for v in ax.values):
        raise InputError(f"--set {SPEED_KEY}: the speeds must be numbers in rpm")
    if len(set(ax.values)) != len(ax.values):
        raise InputError(f"--set {SPEED_KEY}: the speeds must be distinct")
    if len(ax.values) < 2:
        raise InputError(f"--set {SPEED_KEY}: a run-up needs at least 2 speeds, got {len(ax.values)}")
    return Axis(ax.key, tuple(sorted(float(v) for v in ax.values))), [a for a in axes if a.key != SPEED_KEY]


def iso_curve(scene: Scene, k_mean_N_per_m: float, m_e_kg: float, speeds_rpm) -> dict[str, Any]:
    """ISO 6336-1 method B K_v at the driver speeds ``speeds_rpm`` and its inputs (module
    docstring): ISO's gear 1 is the gear with fewer teeth, turning at n z_driver / z1."""
    import numpy as np

    from gearwear.analytic.iso6336 import (
        dynamic_factor,
        iso1328_deviations_um,
        iso6336_stiffness,
        running_in_case_hardened_um,
    )
    from gearwear.scene.schema import Iso6336Doc

    doc = (scene.doc.iso6336 if scene.doc is not None else None) or Iso6336Doc()
    pair = scene.pair
    b_mm = pair.face_width_m * 1e3
    K_A = doc.application_factor
    T = scene.operating.torque_Nm
    iso = iso6336_stiffness(pair, torque_Nm=T, K_A=K_A)  # T: the driver's torque
    # ISO 6336-1 takes the larger deviation of the pair (the larger gear's ISO 1328 value)
    f_pt, f_f = (
        max(v)
        for v in zip(
            *(iso1328_deviations_um(pair.module_m, 2 * g.pitch_radius_m, doc.accuracy_grade) for g in pair.gears)
        )
    )
    f_pb = doc.f_pb_um if doc.f_pb_um is not None else round(f_pt * math.cos(pair.pressure_angle_rad), 3)
    f_fa = doc.f_f_um if doc.f_f_um is not None else f_f
    y_p = doc.y_p_um if doc.y_p_um is not None else running_in_case_hardened_um(f_pb)
    y_f = doc.y_f_um if doc.y_f_um is not None else running_in_case_hardened_um(f_fa)
    C_a = doc.C_a_um
    if C_a is None:
        tips = [r for r in (scene.flank.tip_relief if scene.flank is not None else ()) if r is not None]
        C_a = max(r.amount_m for r in tips) * 1e6 if tips else 0.0
    c_gamma = k_mean_N_per_m / (b_mm * 1e6)  # N/m -> N/(mm um) per mm of face width
    m_red = m_e_kg / b_mm
    # the driver's speed n turns ISO's gear 1 at n z_driver / z1 (the ratio first: exactly 1
    # when the driver is gear 1)
    speed_ratio = pair.teeth[0] / iso.z1
    r = dynamic_factor(
        np.asarray(speeds_rpm, float) * speed_ratio,
        iso.z1,
        c_gamma,
        iso.c_prime_low_load,
        m_red,
        iso.line_load_N_per_mm or 0.0,
        f_pb - y_p,
        f_fa - y_f,
        C_a,
        iso.eps_alpha,
    )
    return {
        "K_v": [float(v) for v in r.K_v],
        "range": list(r.range_name),
        "n_E1_rpm": r.n_E1_rpm,
        "n_E1_driver_rpm": r.n_E1_rpm / speed_ratio,
        "N_S": r.N_S,
        "B_p": r.B_p,
        "B_f": r.B_f,
        "B_k": r.B_k,
        "inputs": {
            "z1": iso.z1,
            "c_gamma_N_per_mm_um": c_gamma,
            "c_prime_N_per_mm_um": iso.c_prime_low_load,
            "m_red_kg_per_mm": m_red,
            "line_load_N_per_mm": iso.line_load_N_per_mm,
            "eps_gamma": iso.eps_alpha,
            "accuracy_grade": doc.accuracy_grade,
            "f_pb_um": f_pb,
            "f_f_um": f_fa,
            "y_p_um": y_p,
            "y_f_um": y_f,
            "C_a_um": C_a,
            "application_factor": K_A,
        },
    }


def plan(
    raw: dict[str, Any], name: str, speed: Axis, others: list[Axis], fixed: list[str], direction: str
) -> tuple[list[Point], list[Chain]]:
    """Validate every (point, speed) scene before any work, build each point's stiffness
    and model once, and lay out the chains."""
    if direction not in DIRECTIONS:
        raise InputError(f"--direction = {direction!r}: must be one of {', '.join(DIRECTIONS)}")
    scenes = []
    for values in grid(others) if others else [{}]:  # every (point, speed) is a valid scene, before any work
        sets = point_sets(values, list(fixed))
        for v in speed.values[1:]:
            scene_from_dict(apply_overrides(raw, sets + [f"{SPEED_KEY}={format_value(v)}"]), name=name)
        scene = scene_from_dict(
            apply_overrides(raw, sets + [f"{SPEED_KEY}={format_value(speed.values[0])}"]), name=name
        )
        if not scene.operating.torque_Nm > 0:
            raise InputError("operating.torque_Nm = 0 N m: a run-up needs a load (K_v = max F_m / static F)")
        scenes.append((values, scene))
    points = [build_point(values, scene, speed.values) for values, scene in scenes]
    dirs = ("up", "down") if direction == "both" else (direction,)
    chains = [
        Chain(i, d, list(speed.values) if d == "up" else list(speed.values[::-1]))
        for i in range(len(points))
        for d in dirs
    ]
    return points, chains


def run_speed(model, speed_rpm: float, y0, solver: dict[str, Any], settings: Settings) -> dict[str, Any]:
    """One speed of a chain (top level, so process and Dask executors can pickle it): the
    steady state from ``y0`` and its per-speed metrics; ``z_end`` continues the chain."""
    from gearwear.dynamics.steady import steady_state

    m = model.with_(omega_p=speed_rpm * 2 * math.pi / 60)
    s = steady_state(
        m,
        y0,
        tol=settings.tol,
        max_periods=settings.max_periods,
        chunk_periods=settings.chunk_periods,
        keep_periods=settings.keep_periods,
        p_max=settings.p_max,
        **solver,
    )
    r = s.result
    F_max = float(r.signals["F_m"].max())
    d = r.stats["delta"]  # np.std / np.ptp / np.mean of r.signals["delta"] (simulate)
    h = r.harmonics_of(["delta", "F_m"], N_HARMONICS)
    f, A = r.spectrum("delta")  # the kept window: whole multiples of the period, so f_m / p is a bin
    band = (f > 0) & (f <= (N_HARMONICS + 0.5) * r.fm_Hz)
    return {
        "speed_rpm": float(speed_rpm),
        "fm_Hz": r.fm_Hz,
        "label": s.label,
        "period_mesh_periods": s.period_mesh_periods,
        "residual": s.residual,
        "zero_one_K": s.zero_one_K,
        "periods_integrated": s.periods_integrated * m.table_periods,
        "K_v": float(F_max / m.F_s),
        "F_m_max_N": F_max,
        "delta_ac_rms_um": d["ac_rms"] * 1e6,
        "delta_p2p_um": d["p2p"] * 1e6,
        "delta_mean_um": d["mean"] * 1e6,
        "separation_fraction": r.separation_fraction,
        "backside_fraction": r.backside_fraction,
        "delta_harmonics_um": (h["delta"] * 1e6).tolist(),
        "F_m_harmonics_N": h["F_m"].tolist(),
        "integration_wall_s": s.integration_wall_s,
        "z_end": s.z_end.tolist(),
        # for the Campbell diagram only (not in runup.csv): delta's amplitude spectrum, bins 1, 2, ...
        "spectrum_df_Hz": float(f[1]),
        "delta_spectrum_um": (A[band] * 1e6).tolist(),
    }


def run(
    points: list[Point], chains: list[Chain], settings: Settings, executor: Executor, progress: bool = True
) -> list[Chain]:
    """Run every chain: the first speed of each is submitted at once, and each finished speed
    submits the next speed of its chain from its end state. Results land in sweep order
    whatever the executor or the order of completion (the same inputs give the same rows)."""
    import sys

    from tqdm import tqdm

    from gearwear.jobs.sweep import Estimate, workers_of

    total = sum(len(c.speeds) for c in chains)
    futures: dict[Any, tuple[int, int]] = {}
    parallel = min(workers_of(executor), len(chains))
    estimate = Estimate(
        f"run-up of {total} speeds", parallel, math.ceil(len(chains) / parallel) * max(len(c.speeds) for c in chains)
    )

    def submit(ci: int, k: int, y0) -> None:
        c = chains[ci]
        p = points[c.point_index]
        futures[executor.submit(run_speed, p.model, c.speeds[k], y0, p.solver, settings)] = (ci, k)

    try:
        for ci in range(len(chains)):
            submit(ci, 0, None)
        with tqdm(total=total, desc="runup", unit="speed", disable=not progress, file=sys.stderr) as bar:
            while futures:
                done, _ = wait(list(futures), return_when=FIRST_COMPLETED)
                for f in sorted(done, key=lambda f: futures[f]):
                    ci, k = futures.pop(f)
                    row = f.result()
                    chains[ci].rows.append(row)
                    bar.update(1)
                    estimate.first_done(bar.write)
                    if k + 1 < len(chains[ci].speeds):
                        submit(ci, k + 1, np.asarray(row["z_end"]))
    finally:
        for f in futures:
            f.cancel()
    return chains


def jump_bands(up: list[dict], down: list[dict], rel: float) -> list[list[float]]:
    """Contiguous runs of speeds where the up and down K_v differ by more than ``rel`` of the
    larger: [[first, last], ...] in rpm (the edges are known to one speed step)."""
    by_speed = {r["speed_rpm"]: r["K_v"] for r in down}
    bands: list[list[float]] = []
    prev = False
    for r in sorted(up, key=lambda r: r["speed_rpm"]):
        a, b = r["K_v"], by_speed[r["speed_rpm"]]
        differ = abs(a - b) > rel * max(abs(a), abs(b))
        if differ and prev:
            bands[-1][1] = r["speed_rpm"]
        elif differ:
            bands.append([r["speed_rpm"], r["speed_rpm"]])
        prev = differ
    return bands


def summary(
    points: list[Point], chains: list[Chain], speed: Axis, others: list[Axis], settings: Settings
) -> dict[str, Any]:
    """What a run-up found, per parameter point: jump bands, ISO 6336 curve and n_E1, the
    linear modes and the speeds where the first two mesh harmonics meet them, peak K_v per
    direction, label counts and the largest residual (no wall times: timing.json has them)."""
    out = []
    for i, p in enumerate(points):
        mine = {c.direction: c for c in chains if c.point_index == i}
        z1 = p.scene.pair.teeth[0]
        entry: dict[str, Any] = {
            "point": p.values,
            "torque_Nm": p.scene.operating.torque_Nm,
            "linear_eigenfrequencies_Hz": p.eigenfrequencies_Hz,
            "mode_speeds_rpm": {f"k{k}": [60 * f / (k * z1) for f in p.eigenfrequencies_Hz] for k in (1, 2)},
            "iso6336": {k: p.iso[k] for k in ("n_E1_rpm", "n_E1_driver_rpm", "N_S", "B_p", "B_f", "B_k", "inputs")},
            "directions": {},
        }
        for d, c in mine.items():
            best = max(c.rows, key=lambda r: r["K_v"])
            labels: dict[str, int] = {}
            for r in c.rows:
                labels[r["label"]] = labels.get(r["label"], 0) + 1
            per = [r["residual"] for r in c.rows if r["label"] == "periodic"]
            entry["directions"][d] = {
                "K_v_max": best["K_v"],
                "K_v_max_speed_rpm": best["speed_rpm"],
                "labels": labels,
                "max_residual_periodic": max(per) if per else None,
                "contact_loss_speeds": sum((r["separation_fraction"] or 0.0) > 0 for r in c.rows),
            }
        if "up" in mine and "down" in mine:
            entry["jump_bands_rpm"] = jump_bands(mine["up"].rows, mine["down"].rows, settings.jump_tol)
        out.append(entry)
    step = (speed.values[-1] - speed.values[0]) / (len(speed.values) - 1)
    return {
        "speeds_rpm": [speed.values[0], speed.values[-1], len(speed.values)],
        "speed_step_rpm": step,
        "swept": [a.key for a in others],
        "settings": settings.__dict__,
        "points": out,
    }


ROW_KEYS = (
    "fm_Hz",
    "label",
    "period_mesh_periods",
    "residual",
    "zero_one_K",
    "periods_integrated",
    "K_v",
    "F_m_max_N",
    "delta_ac_rms_um",
    "delta_p2p_um",
    "delta_mean_um",
    "separation_fraction",
    "backside_fraction",
)


def table_csv(points: list[Point], chains: list[Chain], others: list[Axis]) -> str:
    """runup.csv: one row per (point, direction, speed) in sweep order."""
    cols = [a.key for a in others] + ["direction", "speed_rpm", *ROW_KEYS, "K_v_iso6336"]
    cols += [f"delta_h{k}_um" for k in range(1, N_HARMONICS + 1)] + [f"F_m_h{k}_N" for k in range(1, N_HARMONICS + 1)]
    lines = [",".join(cols)]
    for c in chains:
        p = points[c.point_index]
        iso_by_speed = dict(zip(p.speeds, p.iso["K_v"]))
        for r in c.rows:
            vals = [csv_cell(p.values[a.key]) for a in others]
            vals += [c.direction, format_value(r["speed_rpm"])]
            for k in ROW_KEYS:
                v = r[k]
                vals.append(
                    "" if v is None else (v if isinstance(v, str) else (str(v) if isinstance(v, int) else f"{v:.8g}"))
                )
            vals.append(f"{iso_by_speed.get(r['speed_rpm'], float('nan')):.8g}")
            vals += [f"{x:.8g}" for x in r["delta_harmonics_um"]] + [f"{x:.8g}" for x in r["F_m_harmonics_N"]]
            lines.append(",".join(vals))
    return "\n".join(lines) + "\n"


def _label(p: Point, others: list[Axis]) -> str:
    return point_label(others, [p.values[a.key] for a in others]) or f"{p.scene.operating.torque_Nm:g} N m"


#: the marker of each steady state that is not plain periodic (period p > 1 cycles through PERIOD_MARKERS)
STATE_MARKERS = {"quasi-periodic": ("D", "tab:purple"), "chaotic": ("X", "red"), "unsettled": ("*", "0.35")}
PERIOD_MARKERS = (
    ("^", "gold"),
    ("s", "darkorange"),
    ("v", "saddlebrown"),
    ("p", "olive"),
    ("h", "teal"),
    ("<", "pink"),
    (">", "cyan"),
)


def steady_state_name(row: dict[str, Any], table_periods: int) -> str | None:
    """ "period 2" (periodic over p > 1 table periods), "quasi-periodic", "chaotic",
    "unsettled", or None for a period-1 response (the stiffness table's own period)."""
    if row["label"] != "periodic":
        return row["label"]
    p = row["period_mesh_periods"] // max(table_periods, 1)
    return f"period {p}" if p > 1 else None


def _state_style(name: str) -> tuple[str, str]:
    if name.startswith("period "):
        return PERIOD_MARKERS[(int(name.split()[1]) - 2) % len(PERIOD_MARKERS)]
    return STATE_MARKERS.get(name, ("o", "k"))


def _mark_states(ax, points: list[Point], chains: list[Chain]) -> None:
    """One marker per steady state that is not period 1 (period p > 1, quasi-periodic,
    chaotic, unsettled) on the K_v curves, one legend entry per kind."""
    found: dict[str, list[tuple[float, float]]] = {}
    for c in chains:
        L = points[c.point_index].model.table_periods
        for r in c.rows:
            name = steady_state_name(r, L)
            if name is not None:
                found.setdefault(name, []).append((r["speed_rpm"], r["K_v"]))
    runs = sum(len(c.rows) for c in chains)
    order = sorted(
        found, key=lambda n: (not n.startswith("period"), int(n.split()[1]) if n.startswith("period") else 0, n)
    )
    for name in order:
        mk, col = _state_style(name)
        xy = np.array(found[name])
        what = f"{name}, sub-harmonic f_m/{name.split()[1]}" if name.startswith("period") else name
        ax.plot(
            xy[:, 0],
            xy[:, 1],
            ls="none",
            marker=mk,
            ms=9,
            mfc=col,
            mec="k",
            mew=0.8,
            zorder=5,
            label=f"steady state {what}: {len(xy)} of {runs} speed runs",
        )


def _mode_speeds(ax, points: list[Point], summ: dict[str, Any]) -> int:
    """Dashed grey lines at the speeds where f_m meets a linear mode, each named above the
    axes by its frequency (staggered so close ones do not overprint); the rows of names."""
    from gearwear.plotting import labels_above

    marks: dict[float, float] = {}
    for i, p in enumerate(points):
        for n, f in zip(summ["points"][i]["mode_speeds_rpm"]["k1"], p.eigenfrequencies_Hz):
            if p.speeds[0] <= n <= p.speeds[-1]:
                marks.setdefault(round(n, 6), f)
    speeds = sorted(marks)
    for n in speeds:
        ax.axvline(
            n,
            color="0.45",
            lw=1.0,
            ls="--",
            zorder=1,
            label="f_m = a linear mode (frequency above)" if n == speeds[0] else None,
        )
    lo, hi = ax.get_xlim()
    return labels_above(ax, speeds, [f"{marks[n]:.0f} Hz" for n in speeds], 0.09 * (hi - lo), fontsize=8, color="0.25")


def kv_figure(points: list[Point], chains: list[Chain], others: list[Axis], summ: dict[str, Any]):
    """K_v against speed: up (solid) and down (dashed) per point, the jump bands shaded, ISO
    6336-1 method B (dotted) with its resonance speed n_E1, dashed grey lines (named by
    their frequency) at the speeds where the first mesh harmonic meets a linear mode, a
    marker on every speed whose steady state is not period 1. The legend is right of the
    axes, off the data."""
    from gearwear.plotting import legend_outside, subplots, title_pad

    fig, ax = subplots(1, 1, figsize=(12, 5.2))
    colors = ["C0", "C3", "C2", "C1", "C4", "C5", "C6", "C7"]
    for i, p in enumerate(points):
        col = colors[i % len(colors)]
        lab = _label(p, others)
        for c in (c for c in chains if c.point_index == i):
            rows = sorted(c.rows, key=lambda r: r["speed_rpm"])
            ax.plot(
                [r["speed_rpm"] for r in rows],
                [r["K_v"] for r in rows],
                "-" if c.direction == "up" else "--",
                color=col,
                lw=1.4,
                marker="." if c.direction == "up" else None,
                ms=4,
                label=f"{lab}, sweep {c.direction}",
            )
        nE1 = p.iso["n_E1_driver_rpm"]  # on the run-up's (driver) speed axis
        ax.plot(
            p.speeds, p.iso["K_v"], ":", color=col, lw=1.6, label=f"{lab}, ISO 6336-1 method B (n_E1 = {nE1:.0f} rpm)"
        )
        if p.speeds[0] <= nE1 <= p.speeds[-1]:
            ax.axvline(nE1, color=col, lw=0.8, ls="-.", alpha=0.7, label=f"{lab}, ISO resonance speed n_E1")
        for j, (lo, hi) in enumerate(summ["points"][i].get("jump_bands_rpm", [])):
            step = summ["speed_step_rpm"]
            ax.axvspan(
                lo - step / 2,
                hi + step / 2,
                color=col,
                alpha=0.15,
                lw=0,
                label=f"{lab}, jump band (up and down differ)" if j == 0 else None,
            )
    _mark_states(ax, points, chains)
    name_rows = _mode_speeds(ax, points, summ)
    ax.set_xlabel("pinion speed (rpm)")
    ax.set_ylabel("dynamic factor K_v = max F_m / static F (ratio)")
    ax.grid(alpha=0.3)
    legend_outside(ax, fontsize=8)
    ax.set_title("Dynamic factor against speed", fontsize=10, pad=title_pad(name_rows))
    fig.tight_layout()
    return fig


def _chain_panels(points: list[Point], chains: list[Chain], direction: str, size_in: tuple[float, float]):
    """A figure with one axes (``size_in`` inches) per chain of ``direction``, and per axes
    (axes, point, rows in speed order, speeds rpm)."""
    from gearwear.plotting import subplots

    mine = [c for c in chains if c.direction == direction]
    fig, axs = subplots(1, len(mine), figsize=(size_in[0] * len(mine), size_in[1]), squeeze=False)
    panels = []
    for ax, c in zip(axs[0], mine):
        rows = sorted(c.rows, key=lambda r: r["speed_rpm"])
        panels.append((ax, points[c.point_index], rows, np.array([r["speed_rpm"] for r in rows])))
    return fig, panels


def _modes(p: Point) -> list[float]:
    """The point's distinct linear eigenfrequencies (Hz), ascending."""
    return sorted(set(round(x, 6) for x in p.eigenfrequencies_Hz))


def order_map_figure(points: list[Point], chains: list[Chain], others: list[Axis], direction: str):
    """Order map of one sweep direction: the amplitude of delta's mesh harmonics k = 1..10
    over speed and order (log colour), with the curves k = 60 f_mode / (z1 n) of the linear
    modes. Integer orders only: a sub-harmonic is in the Campbell diagram
    (:func:`campbell_figure`)."""
    from matplotlib.colors import LogNorm

    from gearwear.plotting import legend_outside

    fig, panels = _chain_panels(points, chains, direction, (6.5, 4.8))
    for ax, p, rows, n in panels:
        A = np.array([r["delta_harmonics_um"] for r in rows]).T
        pos = A[A > 0]
        lo = max(float(pos.max()) * 1e-5, float(pos.min())) if pos.size else 1e-12
        im = ax.pcolormesh(
            n,
            np.arange(1, N_HARMONICS + 1),
            np.maximum(A, lo),
            shading="nearest",
            norm=LogNorm(vmin=lo, vmax=max(float(A.max()), lo * 10)),
            cmap="viridis",
        )
        z1 = p.scene.pair.teeth[0]
        for j, f in enumerate(_modes(p)):
            ax.plot(
                n,
                60 * f / (z1 * n),
                color="w",
                lw=0.9,
                ls=("--", ":", "-.")[j % 3],
                label=f"k f_m = linear mode {f:.0f} Hz",
            )
        ax.set_ylim(0.5, N_HARMONICS + 0.5)
        ax.set_xlabel("pinion speed (rpm)")
        ax.set_ylabel("mesh harmonic order k (dimensionless)")
        ax.set_title(f"{_label(p, others)}, sweep {direction}", fontsize=9)
        fig.colorbar(im, ax=ax, label="amplitude of delta at k f_m (um)")
        legend_outside(ax, "below", fontsize=7, ncol=2, facecolor="0.5")
    fig.suptitle(
        "Order map of the dynamic transmission error delta\n(integer orders only; sub-harmonics: "
        f"campbell_{direction}.png)",
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def campbell_spectrum(row: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """(frequency Hz, amplitude um) of delta over the kept window of one speed: bins 1, 2,
    ... up to (N_HARMONICS + 0.5) f_m (the DC bin, delta's mean, left out)."""
    A = np.asarray(row["delta_spectrum_um"], float)
    return row["spectrum_df_Hz"] * np.arange(1, A.size + 1), A


def peak_hold(f: np.ndarray, A: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """``A`` (on bins ``f``, uniform) resampled on the rows between ``edges``: each row the
    largest bin inside it, a row holding no bin the nearest bin, NaN beyond the bins. A
    line one bin wide so stays visible whatever the rows' height."""
    df = f[1] - f[0] if f.size > 1 else 1.0
    out = np.full(edges.size - 1, -np.inf)
    row = np.searchsorted(edges, f, side="right") - 1
    ok = (row >= 0) & (row < out.size)
    np.maximum.at(out, row[ok], A[ok])
    centre = 0.5 * (edges[1:] + edges[:-1])
    empty = ~np.isfinite(out)
    nearest = np.clip(np.rint((centre - f[0]) / df).astype(int), 0, f.size - 1)
    out[empty] = A[nearest[empty]]
    out[(centre < f[0] - df / 2) | (centre > f[-1] + df / 2)] = np.nan
    return out


def campbell_grid(rows: list[dict[str, Any]], f_max_Hz: float, n_rows: int = 300):
    """(speed edges rpm, frequency edges Hz, amplitude um (frequency rows x speeds)) of the
    Campbell diagram: each speed's kept-window spectrum of delta (:func:`campbell_spectrum`)
    on common frequency rows (:func:`peak_hold`), each row the largest of itself and its
    two neighbours (a line one row high would be thinner than a pixel line on a
    300-row map: it shows three rows, +-f_max / n_rows); NaN above a speed's spectrum."""
    n = np.array([r["speed_rpm"] for r in rows], float)
    mid = 0.5 * (n[1:] + n[:-1])
    x_edges = np.r_[
        n[0] - (mid[0] - n[0]) if n.size > 1 else n[0] - 1, mid, n[-1] + (n[-1] - mid[-1]) if n.size > 1 else n[-1] + 1
    ]
    y_edges = np.linspace(0.0, f_max_Hz, n_rows + 1)
    Z = np.column_stack([peak_hold(*campbell_spectrum(r), y_edges) for r in rows])
    padded = np.pad(Z, ((1, 1), (0, 0)), constant_values=np.nan)
    with np.errstate(invalid="ignore"):
        wide = np.fmax(np.fmax(padded[:-2], padded[2:]), padded[1:-1])
    return x_edges, y_edges, np.where(np.isnan(Z), np.nan, wide)


def campbell_figure(points: list[Point], chains: list[Chain], others: list[Axis], direction: str):
    """Campbell diagram of one sweep direction: the amplitude spectrum of delta over the
    kept window of each speed (log colour, FLOOR_DB deep) against response frequency and
    speed, the order lines k f_m (k = 1..N_HARMONICS) and f_m / 2, and the model's linear
    eigenfrequencies as horizontal lines. A period-2 response shows its line at f_m / 2,
    any response whatever it holds between the orders."""
    from matplotlib import colormaps
    from matplotlib.colors import LogNorm

    from gearwear.plotting import FLOOR_DB, legend_outside, log_floor

    fig, panels = _chain_panels(points, chains, direction, (7.5, 5.6))
    for ax, p, rows, n in panels:
        z1 = p.scene.pair.teeth[0]
        f_max = (N_HARMONICS + 0.5) * z1 * float(n.max()) / 60
        x_edges, y_edges, Z = campbell_grid(rows, f_max)
        peak = float(np.nanmax(Z)) if np.isfinite(Z).any() else 1.0
        floor = log_floor([peak])
        cmap = colormaps["viridis"].with_extremes(bad="0.92")
        im = ax.pcolormesh(
            x_edges,
            y_edges,
            np.ma.masked_invalid(np.maximum(Z, floor)),
            shading="flat",
            norm=LogNorm(vmin=floor, vmax=peak),
            cmap=cmap,
        )
        for k in range(1, N_HARMONICS + 1):
            ax.plot(
                n,
                k * z1 * n / 60,
                color="w",
                lw=0.5,
                ls=(0, (1, 3)),
                alpha=0.7,
                label=f"order lines k f_m, k = 1..{N_HARMONICS}" if k == 1 else None,
            )
        ax.plot(
            n,
            0.5 * z1 * n / 60,
            color="w",
            lw=0.7,
            ls=(0, (4, 6)),
            alpha=0.8,
            label="f_m / 2 (the line of a period-2 response)",
        )
        for j, f in enumerate(_modes(p)):
            ax.axhline(
                f,
                color="red",
                lw=1.0,
                ls=":",
                label="linear eigenfrequencies: " + ", ".join(f"{v:.0f}" for v in _modes(p)) + " Hz"
                if j == 0
                else None,
            )
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_ylim(0, f_max)
        ax.set_xlabel("pinion speed (rpm)")
        ax.set_ylabel("response frequency (Hz)")
        ax.set_title(f"{_label(p, others)}, sweep {direction}", fontsize=9)
        fig.colorbar(im, ax=ax, label=f"amplitude of delta (um), {FLOOR_DB:g} dB deep")
        legend_outside(ax, "below", fontsize=7, ncol=2, facecolor="0.6")
    fig.suptitle(
        "Campbell diagram of the dynamic transmission error delta\n(the spectrum of the kept window at "
        "each speed; grey: above the computed band)",
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def write(
    points: list[Point],
    chains: list[Chain],
    speed: Axis,
    others: list[Axis],
    summ: dict[str, Any],
    out: Path,
    inputs: dict[str, Any],
    labels: dict[str, Any],
) -> list[Path]:
    """runup.csv (+ sidecar), runup_summary.json, kv.png, order_map_<direction>.png and
    campbell_<direction>.png into ``out`` (no wall times in any of them)."""
    files = []
    csv = io.write_text(out / "runup.csv", table_csv(points, chains, others))
    files += [
        csv,
        io.sidecar(
            csv, inputs, "gearwear runup (dynamics.steady.steady_state per speed, natural continuation)", labels
        ),
    ]
    files.append(io.write_json(out / "runup_summary.json", io.without_timing(summ)))
    files.append(io.write_figure(kv_figure(points, chains, others, summ), out / "kv.png"))
    for d in dict.fromkeys(c.direction for c in chains):
        files.append(io.write_figure(order_map_figure(points, chains, others, d), out / f"order_map_{d}.png"))
        files.append(io.write_figure(campbell_figure(points, chains, others, d), out / f"campbell_{d}.png"))
    return files
