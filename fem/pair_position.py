"""One position of the resolved pair FE (fem.pair): the frictionless contact of all
candidate pairs at one pinion angle, solved exactly (SI units: m, N, rad).

Contact problem per position (fem.contact's exact active-set solver). Candidate i (the
points of fem.pair_candidates; force f_i >= 0 along the master normal e_i, +e_i on the
slave node, -e_i on the master at the foot point, with P2 edge weights):

    gap_i = g_i + (C f)_i - w_i delta >= 0,  f_i >= 0,  f_i gap_i = 0,
    sum_i w_i f_i = T / r_b1,                 C = sum over both bodies a_i^T G a_j

with w_i the lever arms of fem.pair_candidates. With q = w f the problem is
fem.contact's form (C' = W^-1 C W^-1, g' = g / w, sum q = T / r_b1), so the loads sum to
T / r_b1 exactly and delta (the loaded STE, r_b1 times the pinion's extra turn) is the
multiplier.

Flexibility C. G of each body (fem.pair_body) holds its refined tooth 0 and the drive
flanks of the neighbouring teeth; rotational periodicity maps every engaged tooth to tooth
0 (a load on tooth t_l read on tooth t_k = a load on tooth 0 read on tooth t_k - t_l). Where
the cracked body serves (its cracked tooth is a candidate), every candidate is read and
loaded on its own tooth relative to the cracked one (no periodic mapping).

The blanks' reference circles turn by theta_ref,i = h_i . f_i (fem.pair_body.blank_reading,
by reciprocity; fem.pair, "The blank's torsion"): :func:`blank_rotations`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from gearwear.geometry.pair_positions import candidate_slots, involute_arc_m, involute_point, rot, slot_faults

from .contact import solve_contact
from .pair_body import GearBody
from .pair_candidates import _candidates
from .pair_model import EXTENSION_PITCHES, PairModel

__all__ = ["PositionSolution", "solve_position", "blank_rotations"]


@dataclass
class PositionSolution:
    """Resolved contact at one pinion angle (SI).

    d_m, teeth (slots in contact candidates), loads_N per slot (torque-equivalent),
    ste_m, gaps_m per slot (rigid gap g_k), cand (per slot one dict, two with a spall's
    edges: slave, node radii, foot radii, forces, reps), half_width_m per slot;
    cracked per gear (body tooth, LOA position) of the cracked tooth when the cracked
    body served, else None; per gear the rotation theta_ref (rad) of the blank's
    reference circle and the contact loads' moment T about the gear's centre (N m), both
    counter-clockwise (:func:`blank_rotations`)."""

    theta_rad: float
    d_m: np.ndarray
    slots: np.ndarray
    loads_N: np.ndarray
    ste_m: float
    gaps_m: np.ndarray
    half_width_m: np.ndarray
    cand: list
    C: np.ndarray
    g: np.ndarray
    w: np.ndarray
    cracked: tuple = (None, None)
    blank_rotation_rad: tuple = (0.0, 0.0)
    blank_torque_Nm: tuple = (0.0, 0.0)


def _rep_request(c: dict, gi: int, delta_tooth: int, at_nodes: bool = True):
    """Where candidate c is read on body gi, tooth ``delta_tooth`` (relative to the load
    tooth): None for the slave's own nodes (``at_nodes``: the healthy body whose tooth 0
    they were taken from), else (tooth, radii) for P2 edge weights."""
    if at_nodes and gi == c["slave"] and delta_tooth == 0 and c["nodes"] is not None:
        return None
    return delta_tooth, (c["R"] if gi == c["slave"] else c["rF"])


def _rep_of(body: GearBody, c: dict, gi: int, delta_tooth: int, weights) -> tuple:
    """(positions (n, 6), coefficients (n, 6)) of candidate c on body gi, tooth
    ``delta_tooth``, from its edge weights ``weights`` ((positions, weights) (n, 3) each)
    or at its nodes (None)."""
    z = body.gear.teeth
    dirs = c["dirs"][gi] @ rot(2.0 * math.pi * delta_tooth / z).T
    if weights is None:
        b = body.flank_b[0][c["nodes"]]
        idx = np.column_stack([b, b, b])
        wts = np.zeros((len(b), 3))
        wts[:, 0] = 1.0
    else:
        idx, wts = weights
    idx6 = np.concatenate([idx, idx + 1], axis=1)
    coef6 = np.concatenate([wts * dirs[:, :1], wts * dirs[:, 1:]], axis=1)
    return idx6, coef6


def _reps(body: GearBody, c: dict, gi: int, delta_tooth: int, at_nodes: bool = True):
    """(positions (n, 6), coefficients (n, 6)) of the candidates of c on body gi,
    read or loaded on the body's tooth ``delta_tooth`` (relative to the load tooth).
    Slave points on the load tooth are its nodes (``at_nodes``, the healthy body whose
    tooth 0 they were taken from); otherwise P2 edge weights at the point's radius."""
    req = _rep_request(c, gi, delta_tooth, at_nodes)
    return _rep_of(body, c, gi, delta_tooth, None if req is None else body.edge_weights(*req))


def _reps_memo(body: GearBody, cands: list, gi: int, cracked_tooth: int | None) -> Callable[[int, int], tuple]:
    """rep(k, dt): _reps of candidate k on body gi, each computed once. Healthy body
    (``cracked_tooth`` None): read dt teeth from the load tooth; cracked body: on the
    candidate's own tooth relative to the cracked one, whatever dt. On a healthy body
    every (k, dt) a position needs (each candidate read on the tooth of every load, and
    on its own) is computed up front, the edge weights in one batch
    (GearBody.edge_weights_many)."""
    memo: dict = {}
    if cracked_tooth is None:
        keys = sorted(
            {(a, ca["teeth"][gi] - cb["teeth"][gi]) for a, ca in enumerate(cands) for cb in cands}
            | {(b, 0) for b in range(len(cands))}
        )
        reqs = {key: _rep_request(cands[key[0]], gi, key[1]) for key in keys}
        edge = [key for key in keys if reqs[key] is not None]
        weights = dict(zip(edge, body.edge_weights_many([reqs[key] for key in edge]))) if edge else {}
        for key in keys:
            memo[key] = _rep_of(body, cands[key[0]], gi, key[1], weights.get(key))

    def rep(k: int, dt: int) -> tuple:
        key = (k, dt) if cracked_tooth is None else k
        if key not in memo:
            c = cands[k]
            memo[key] = (
                _reps(body, c, gi, dt)
                if cracked_tooth is None
                else _reps(body, c, gi, c["teeth"][gi] - cracked_tooth, at_nodes=False)
            )
        return memo[key]

    return rep


def _body_reps(pm: PairModel, cands: list, cracked: tuple) -> list:
    """[(gear index, body, rep)] per gear: the cracked body where ``cracked[gi]`` names its
    cracked tooth, else the healthy one, with :func:`_reps_memo` of the candidates on it
    (one list serves :func:`_flexibility` and :func:`blank_rotations` of a position, so
    each representation is computed once)."""
    out = []
    for gi, body in enumerate(pm.bodies):
        ct = cracked[gi]
        if ct is not None:
            body = pm.cracked[gi]
        out.append((gi, body, _reps_memo(body, cands, gi, None if ct is None else ct[0])))
    return out


def _flexibility(pm: PairModel, cands: list, cracked: tuple = (None, None), reps: list | None = None) -> np.ndarray:
    """C (n, n) of all candidates: sum over both bodies of a_i^T G a_j. On a healthy body
    the read is on tooth t_i - t_j relative to the load (rotational periodicity); on a
    cracked body (``cracked[gi]``: the body tooth of the cracked slot) each candidate sits
    on its own tooth relative to the cracked one, and G is read there directly."""
    sizes = [len(c["R"]) for c in cands]
    off = np.concatenate([[0], np.cumsum(sizes)])
    C = np.zeros((off[-1], off[-1]))
    for gi, body, rep in reps if reps is not None else _body_reps(pm, cands, cracked):
        for b, cb in enumerate(cands):
            # the loads of candidate b read at every candidate a: one gather from G per b
            ras = [rep(a, ca["teeth"][gi] - cb["teeth"][gi]) for a, ca in enumerate(cands)]
            ia, wa = np.concatenate([r[0] for r in ras]), np.concatenate([r[1] for r in ras])
            ib, wb = rep(b, 0)
            Gs = body.G[np.ix_(ia.ravel(), ib.ravel())].reshape(ia.shape[0], 6, ib.shape[0], 6)
            C[:, off[b] : off[b + 1]] += np.einsum("ia,iajb,jb->ij", wa, Gs, wb)
    return 0.5 * (C + C.T)


def blank_rotations(
    pm: PairModel, cands: list, cracked: tuple = (None, None), reps: list | None = None
) -> tuple[tuple, tuple]:
    """((theta_ref,1, theta_ref,2), (T_1, T_2)) under the solved candidate forces: per gear
    the rotation (rad) of the blank's reference circle, theta_ref = sum h . f over the
    loads on that body (h = GearBody.blank_h[0], the circle's reading by reciprocity), and
    the loads' moment T (N m) about the gear's centre, from each force at its exact
    involute point; both counter-clockwise in the body's frame, the same sense in the
    fixed frame (and both > 0 under a driving load: the pinion's contact moment opposes
    its clockwise drive, the gear's drives it counter-clockwise). Loads are taken as in
    :func:`_flexibility` (tooth 0 of a healthy body by rotational periodicity, the
    circle's reading being the same in every tooth pitch; on a cracked body each on its
    own tooth)."""
    theta, torque = [0.0, 0.0], [0.0, 0.0]
    for gi, body, rep in reps if reps is not None else _body_reps(pm, cands, cracked):
        for k, c in enumerate(cands):
            f = c["force_N"]
            X = involute_point(body.gear, c["R"] if gi == c["slave"] else c["rF"])
            fv = f[:, None] * c["dirs"][gi]
            torque[gi] += float(np.sum(X[:, 0] * fv[:, 1] - X[:, 1] * fv[:, 0]))
            if body.blank_h is not None:
                idx, coef = rep(k, 0)
                theta[gi] += float(np.sum(body.blank_h[0][idx] * coef * f[:, None]))
    return (theta[0], theta[1]), (torque[0], torque[1])


def solve_position(pm: PairModel, theta: float, total_N: float, period: int | None = None) -> PositionSolution:
    """Resolved contact at pinion angle theta (rad from the entry of a pair at A; any
    value, also outside one mesh period) under the torque-equivalent load total_N.
    ``period``: the mesh period of a revolution with the model's faults (which slot holds
    the faulty tooth); None: the healthy mesh."""
    j, d = pm.mesh.slots(theta)
    cands, slots = [], []
    cracked: list = [None, None]
    for k in np.flatnonzero(candidate_slots(pm.mesh, d, EXTENSION_PITCHES)):
        spalled, crack_here = slot_faults(pm.pair, pm.faults, period, int(j[k]))
        if crack_here:
            assert pm.faults is not None and pm.faults.crack is not None
            gc = pm.faults.crack.gear_index
            cracked[gc] = ((-int(j[k]), int(j[k]))[gc], float(d[k]))
        for c in _candidates(pm, float(d[k]), int(j[k]), spalled):
            cands.append(c)
            slots.append(k)
    if not cands:
        raise RuntimeError(f"no tooth pair can touch at theta = {theta!r} rad")
    reps = _body_reps(pm, cands, tuple(cracked))
    C = _flexibility(pm, cands, tuple(cracked), reps)
    g = np.concatenate([c["gap"] for c in cands])
    w = np.concatenate([c["w"] for c in cands])
    if np.any(w <= 0):
        raise RuntimeError("a candidate's lever arm about the pinion centre is not positive")
    sol = solve_contact(C / np.outer(w, w), g / w, total_force_N=total_N)
    q = sol.force_N
    loads = np.zeros(len(d))
    hw = np.zeros(len(d))
    gaps = np.full(len(d), np.inf)
    off = 0
    for k, c in zip(slots, cands):
        n = len(c["R"])
        qc = q[off : off + n]
        c["force_N"] = qc / c["w"]
        loads[k] += qc.sum()
        gaps[k] = min(gaps[k], c["g_pair"])
        on = np.flatnonzero(qc > 0)
        if on.size and not c.get("corner"):
            rb = pm.pair.gear(c["slave"]).base_radius_m
            s = involute_arc_m(rb, c["R"])
            ds = np.diff(s).mean() if len(s) > 1 else 0.0
            hw[k] = 0.5 * (s[on].max() - s[on].min() + ds)
            c["window_hit"] = bool(on[0] == 0 and s[0] > s.min() - 1) and (on[0] == 0 or on[-1] == n - 1)
        off += n
    rot_ref, torque = blank_rotations(pm, cands, tuple(cracked), reps)
    return PositionSolution(
        float(theta),
        d,
        np.asarray(slots),
        loads,
        float(sol.approach_m),
        gaps,
        hw,
        cands,
        C,
        g,
        w,
        tuple(cracked),
        rot_ref,
        torque,
    )
