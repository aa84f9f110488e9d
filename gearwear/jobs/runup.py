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
from gearwear.jobs import RUNUP_DIRECTIONS as DIRECTIONS
from gearwear.jobs.sweep import Axis, csv_cell, format_value, grid, point_sets
from gearwear.scene.model import Scene, scene_from_dict
from gearwear.scene.overrides import apply_overrides

SPEED_KEY = "operating.speed_rpm"
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
    from gearwear.jobs.runup_figures import campbell_figure, kv_figure, order_map_figure  # matplotlib: when writing

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
