"""The cycle of the resolved pair FE (fem.pair): every position of one mesh period, or of
one revolution of a faulty gear, solved and gathered into the mesh stiffness curve
(:func:`pair_contact`, result fem.pair_result.PairFE; SI units: m, N, rad).

Mesh stiffness, as analytic.tvms: k = sum over loaded pairs of F_k / (delta - g_k) with
F_k the load of pair k (the sum of its q_i) and g_k its rigid gap (fem.pair_candidates);
F = k (delta - e) with e = sum k_k g_k / k. The tangent dF / d delta is a central
difference of the whole solve at F (1 +- 1e-3). The mesh-only curve is the same secant
with the blanks' torsion taken out of delta (fem.pair, "The blank's torsion").

Faults: a position is solved again only where a slot holding a faulty tooth is a
candidate pair (within EXTENSION_PITCHES p_b of the path, so the corner contact is
included); every other position is the healthy period's, copied (rotational
periodicity), so those periods are the healthy curve to the bit.

Extended contact: :func:`extended_contact_widths` locates, by bisection on a pair's load,
the pinion rotation over which loaded corner contact reaches before A and after E.

``pair_contact(executor=...)`` sends the positions in chunks to any
concurrent.futures.Executor (a process pool, Dask's ``Client.get_executor()``); the
workers rebuild the model from its arguments, each building a body once (in-process
cache, fem.pair_model), and the result is the serial one to the bit.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import Executor
from typing import Callable

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.faults import FaultSpec, faulty_slots, revolution_periods
from gearwear.geometry.flank import FlankSpec
from gearwear.geometry.pair_positions import candidate_slots
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec

from .contact import solve_contact
from .pair_body import blank_reference_radius_m
from .pair_model import EXTENSION_PITCHES, PairModel, _check_inputs, _model_spec, _sizes, pair_model
from .pair_position import solve_position
from .pair_result import PairFE

__all__ = ["pair_contact", "extended_contact_widths"]


def _position_row(pm: PairModel, theta: float, total_N: float, period: int | None) -> tuple:
    """One position of the cycle: (slot loads, slot gaps, slot half-widths, STE, tangent
    stiffness, candidates, window hits, geometry wall s, tangent LCP wall s, blank
    rotations (2,), blank moments (2,))."""
    ta = time.perf_counter()
    ps = solve_position(pm, theta, total_N, period)
    tb = time.perf_counter()
    eps = 1e-3
    Cw, gw = ps.C / np.outer(ps.w, ps.w), ps.g / ps.w
    dp = solve_contact(Cw, gw, total_force_N=total_N * (1 + eps)).approach_m
    dm = solve_contact(Cw, gw, total_force_N=total_N * (1 - eps)).approach_m
    ktan = 2 * eps * total_N / (dp - dm)
    hits = sum(bool(c.get("window_hit")) for c in ps.cand)
    return (
        ps.loads_N,
        ps.gaps_m,
        ps.half_width_m,
        ps.ste_m,
        ktan,
        len(ps.g),
        hits,
        tb - ta,
        time.perf_counter() - tb,
        np.array(ps.blank_rotation_rad),
        np.array(ps.blank_torque_Nm),
    )


def _solve_chunk(spec: dict, items: list, total_N: float) -> list:
    """Worker task: the rows of the positions ``items`` ((theta, period) each). The
    model is rebuilt from its arguments; the in-process body cache makes each worker
    process build a body once."""
    pm = pair_model(**spec)
    return [_position_row(pm, th, total_N, n) for th, n in items]


def _body_meta(pm: PairModel) -> dict:
    """Sizes of the bodies (meta of the result)."""
    gc, cb = next(((gi, b) for gi, b in enumerate(pm.cracked) if b is not None), (None, None))
    return {
        "shared_body": pm.bodies[0] is pm.bodies[1],
        "n_elements": [bd.n_elements for bd in pm.bodies],
        "ndofs": [bd.ndofs for bd in pm.bodies],
        "condensed_dofs": [int(bd.G.shape[0]) for bd in pm.bodies],
        "cracked_body": None
        if cb is None
        else {
            "gear": gc,
            "n_elements": cb.n_elements,
            "ndofs": cb.ndofs,
            "condensed_dofs": int(cb.G.shape[0]),
            "refined_neighbours": cb.refined,
            "crack_tip_size_m": cb.crack_tip_size_m,
        },
    }


def _model_task(spec: dict, total_N: float, extended: bool) -> tuple:
    """Worker task: (extended-contact widths or None, body sizes, body-build timings)."""
    pm = pair_model(**spec)
    return (extended_contact_widths(pm, total_N) if extended else None), _body_meta(pm), dict(pm.timings)


def pair_contact(
    pair: PairSpec,
    wear: WearSpec | None = None,
    positions: int = 24,
    torque_Nm: float = 40.0,
    clearance_m: float = 0.0,
    contact_scale: float = 1.0,
    mesh_scale: float = 1.0,
    plane: str = "stress",
    extended: bool = True,
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
    executor: Executor | None = None,
    chunk_positions: int = 12,
    progress: Callable[[int, int], None] | None = None,
) -> PairFE:
    """FE static transmission error and mesh stiffness at ``positions`` pinion angles
    theta = i (2 pi / z1) / positions (theta = 0 when a pair enters at A), over one
    mesh period, or with ``faults`` over one revolution of the faulty gear
    (geometry.faults.revolution_periods mesh periods, ``positions`` each).

    The centre distance follows from the bearing clearance as in analytic.tvms (rigid
    bearings). ``contact_scale`` multiplies the contact element size h_c (the
    h-refinement of the contact zone), ``mesh_scale`` the other sizes. ``extended``:
    also locate where loaded corner contact begins and ends (bisection, meta
    "extended_contact_deg", on the healthy mesh). With faults only the positions where
    a faulty tooth is a candidate pair are solved again; every other position repeats
    the healthy period exactly (rotational periodicity; meta "positions_solved").
    ``executor``: any concurrent.futures.Executor (e.g. a ProcessPoolExecutor, or a Dask
    ``Client.get_executor()``); the positions go to it in chunks of
    ``chunk_positions``, each worker process building the bodies once, and the result is
    the same to the bit as the serial one. ``progress(done, total)`` is called as the
    positions are solved. See fem.pair for the method."""
    t_start = time.perf_counter()
    if isinstance(positions, bool) or not isinstance(positions, (int, np.integer)) or positions < 2:
        raise fail("positions", positions, "", "must be a whole number >= 2")
    faults = None if faults is None or faults.is_empty else faults
    F = torque_Nm / pair.gear(0).base_radius_m
    spec = _model_spec(pair, wear, torque_Nm, clearance_m, contact_scale, mesh_scale, plane, flank, faults)
    pm: PairModel | None = None
    if executor is None:
        pm = pair_model(**spec)
        mesh = pm.mesh
        sizes, a_ref, window = pm.sizes, pm.a_ref_m, pm.window_m
    else:  # the bodies are built in the workers; here only the inputs and the geometry
        mesh = _check_inputs(pair, torque_Nm, clearance_m, plane, faults).mesh
        sizes, a_ref, window = _sizes(pair, torque_Nm, contact_scale, mesh_scale)
    t_model = time.perf_counter()
    theta0 = np.arange(positions) * (mesh.mesh_angle_rad / positions)
    j, d0 = mesh.slots(theta0)
    periods = revolution_periods(pair, faults)
    # a position is solved again where a slot holding a faulty tooth is a candidate
    cand = np.tile(candidate_slots(mesh, d0, EXTENSION_PITCHES), (periods, 1))
    faulty = np.zeros(cand.shape, dtype=bool)
    for f in faults.faults() if faults is not None else []:
        faulty |= np.repeat(faulty_slots(pair, f, periods, j), positions, axis=0) & cand
    redo = np.flatnonzero(faulty.any(axis=1))
    items = [(float(th), None) for th in theta0] + [(float(theta0[r % positions]), int(r // positions)) for r in redo]
    tell = progress or (lambda done, total: None)
    tell(0, len(items))
    rows: list = []
    if executor is None:
        assert pm is not None
        for th, n in items:
            rows.append(_position_row(pm, th, F, n))
            tell(len(rows), len(items))
        t_cycle = time.perf_counter()
        widths = extended_contact_widths(pm, F) if extended else None
        body_meta, body_tim = _body_meta(pm), {k: v for k, v in pm.timings.items() if k != "model_s"}
    else:
        step = max(1, int(chunk_positions))
        futures = [executor.submit(_solve_chunk, spec, items[i : i + step], F) for i in range(0, len(items), step)]
        model_future = executor.submit(_model_task, spec, F, extended)
        for fu in futures:
            rows += fu.result()
            tell(len(rows), len(items))
        t_cycle = time.perf_counter()
        widths, body_meta, worker_tim = model_future.result()
        body_tim = {k: v for k, v in worker_tim.items() if k != "model_s"}
    t_end = time.perf_counter()
    # the healthy period, then (with faults) the revolution with its faulty rows replaced
    columns = (0, 1, 2, 3, 4, 9, 10)
    cols = [np.array([r[i] for r in rows[:positions]]) for i in columns]
    loads, gaps, hw, ste, ktan, rot_ref, torque = (
        np.tile(c, (periods, 1)) if c.ndim == 2 else np.tile(c, periods) for c in cols
    )
    for r, row in zip(redo, rows[positions:]):
        loads[r], gaps[r], hw[r], ste[r], ktan[r], rot_ref[r], torque[r] = (row[i] for i in columns)
    n_cand = [r[5] for r in rows]
    k, exc = _secant(loads, gaps, ste)
    # the blanks' torsion below r_ref taken out: delta_mesh = delta - r_b1 theta_1 - r_b2 theta_2
    rb = np.array([g.base_radius_m for g in pair.gears])
    blank_ste = rot_ref @ rb
    ste_mesh = ste - blank_ste
    k_mesh, exc_mesh = _secant(loads, gaps, ste_mesh)
    # theta_i is linear in the load (linear elasticity, n = 0 part: theta_i = T_i / k_blank,i), so
    # the blanks are a constant compliance in series also for the tangent dF / d delta
    ktan_mesh = 1.0 / (1.0 / ktan - blank_ste / F)
    k_blank = [
        float(torque[:, i].sum() / rot_ref[:, i].sum()) if np.any(rot_ref[:, i] != 0) else math.inf for i in (0, 1)
    ]
    theta = np.arange(positions * periods) * (mesh.mesh_angle_rad / positions)
    timings = {
        **body_tim,
        "model_s": t_model - t_start,
        "positions_s": t_cycle - t_model,
        "positions_geometry_s": float(sum(r[7] for r in rows)),
        "positions_lcp_s": float(sum(r[8] for r in rows)),
        "extended_s": t_end - t_cycle,
        "total_s": time.perf_counter() - t_start,
    }
    meta = {
        "sizes_m": {k2: getattr(sizes, k2) for k2 in ("contact_m", "near_m", "far_m", "fillet_m", "global_m")},
        "a_ref_m": a_ref,
        "window_m": window,
        "contact_scale": contact_scale,
        "mesh_scale": mesh_scale,
        "plane": plane,
        "order": 2,
        **body_meta,
        "clearance_m": clearance_m,
        "candidates_per_position": [int(min(n_cand)), int(max(n_cand))],
        "window_hits": int(sum(r[6] for r in rows)),
        "corner_contact": True,
        "local_contact": "resolved",
        "pair_gap_m": gaps,
        "extended_contact_deg": widths,
        "mesh_periods": periods,
        "positions_solved": len(items),
        "positions_total": positions * periods,
        "faults": None if faults is None else faults.label(),
        "blank_reference_radius_m": [float(bd_r) for bd_r in _reference_radii(pair)],
        "blank_torsional_stiffness_Nm_per_rad": k_blank,
        "mesh_only_mean_N_per_m": float(np.mean(k_mesh)),
    }
    return PairFE(
        pair,
        mesh,
        torque_Nm,
        wear,
        theta,
        k,
        ktan,
        ste,
        exc,
        loads,
        np.tile(d0, (periods, 1)),
        np.tile(mesh.in_path(d0), (periods, 1)),
        hw,
        timings,
        meta,
        faults,
        periods,
        faulty if faults is not None else None,
        k_mesh,
        ktan_mesh,
        ste_mesh,
        exc_mesh,
        rot_ref,
        torque,
    )


def _secant(loads: np.ndarray, gaps: np.ndarray, ste: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, e) per position, as analytic.tvms: k = sum over loaded pairs F_k / (ste - g_k)
    and e = sum k_k g_k / k, so F = k (ste - e) (N/m, m)."""
    on = loads > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        g_on = np.where(on, gaps, 0.0)
        k_pair = np.where(on, loads / np.maximum(ste[:, None] - g_on, 1e-300), 0.0)
    k = k_pair.sum(axis=1)
    return k, np.where(k > 0, (k_pair * g_on).sum(axis=1) / k, 0.0)


def _reference_radii(pair: PairSpec) -> tuple[float, float]:
    """r_ref (m) of both blanks (pair_body.blank_reference_radius_m)."""
    return blank_reference_radius_m(pair.gear(0)), blank_reference_radius_m(pair.gear(1))


def extended_contact_widths(pm: PairModel, total_N: float, tol_deg: float = 1e-4) -> dict:
    """Pinion rotation (deg) over which a pair carries load before it reaches A
    (gear tip corner on the pinion flank) and after it passes E (pinion tip corner),
    by bisection on the pair's load (positive inside, zero outside)."""
    rb1 = pm.pair.gear(0).base_radius_m
    A, E = pm.mesh.path_start_m, pm.mesh.path_end_m
    span = EXTENSION_PITCHES * pm.mesh.base_pitch_m / rb1

    def load_at(theta, target_d):
        ps = solve_position(pm, theta, total_N)
        k = int(np.argmin(np.abs(ps.d_m - target_d)))
        return ps.loads_N[k]

    out = {}
    for name, d_kin, sign in (("entry", A, -1.0), ("exit", E, 1.0)):
        theta_kin = (d_kin - A) / rb1
        lo, hi = 0.0, span  # distance beyond the kinematic transition (rad)
        if load_at(theta_kin + sign * hi, d_kin + sign * hi * rb1) > 0:
            out[name] = float("nan")  # beyond the candidate range: not resolved
            continue
        if load_at(theta_kin, d_kin) <= 0:
            out[name] = 0.0
            continue
        while math.degrees(hi - lo) > tol_deg:
            mid = 0.5 * (lo + hi)
            if load_at(theta_kin + sign * mid, d_kin + sign * mid * rb1) > 0:
                lo = mid
            else:
                hi = mid
        out[name] = math.degrees(0.5 * (lo + hi))
    return out
