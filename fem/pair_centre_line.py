"""Centre-line readings of the resolved pair FE (fem.pair) in single contact: how far each
tooth's centre-line point moves under the pair's load, and the local approach c_local
that the resolved contact zone adds between the two centre lines (SI units: m, N).

The reading point of each tooth is where the load line crosses its centre line (y_c of
geometry.loading), read by the P2 basis of its element (the nodes of the elements that
cross tooth 0's centre line are condensed, fem.pair_body); c_1 and c_2 are its
displacement along the force on that tooth per N of the pair load, and
c_local = delta / F - c_1 - c_2. The app compares them with the single-tooth FE and with
Weber's formula (gearwear.stiffness.comparison.pair_consistency).
"""

from __future__ import annotations

import math

import numpy as np

from gearwear.geometry.loading import load_points
from gearwear.geometry.profile import tooth_profile

from .pair_body import GearBody
from .pair_model import PairModel
from .pair_position import PositionSolution, _reps

__all__ = ["centre_line_compliance"]


def _probe_rep(body: GearBody, pt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(B positions of x dofs, P2 weights) of an interior point of tooth 0."""
    P = body.model.basis.probes(np.asarray(pt, dtype=float).reshape(2, 1)).tocsr()
    nz = np.abs(P[0].data) > 1e-14  # explicit zeros (the other component, a shared edge)
    dofs, wts = P[0].indices[nz], P[0].data[nz]
    b_of = {int(x): int(b) for x, b in zip(body.centre_dofs, body.centre_b)}
    missing = [int(x) for x in dofs if int(x) not in b_of]
    if missing:
        raise RuntimeError("a centre-line reading point lies in an element that is not condensed")
    return np.array([b_of[int(x)] for x in dofs]), np.asarray(wts)


def centre_line_compliance(pm: PairModel, ps: PositionSolution) -> dict:
    """In single contact: displacement of each tooth's centre-line point where the load
    line crosses it (y_c of geometry.loading), along the force on that tooth, per N of
    the pair load, and c_local = delta / F - c_1 - c_2 (m/N). At a position the cracked
    body served, the cracked gear's reading is on its cracked tooth (which must then be
    the loaded one)."""
    loaded = [c for c, k in zip(ps.cand, ps.slots) if ps.loads_N[k] > 0]
    if len({c["j"] for c in loaded}) != 1:
        raise ValueError("centre_line_compliance needs exactly one loaded pair")
    F = float(ps.loads_N.sum())
    d = loaded[0]["d"]
    L = pm.mesh.line_of_action_m
    out = {"d_m": d}
    for gi, body in enumerate(pm.bodies):
        g = pm.pair.gear(gi)
        R = math.hypot(g.base_radius_m, d if gi == 0 else L - d)
        prof = tooth_profile(g)
        lp = load_points(prof, np.array([R]))
        e = -np.array([math.cos(lp.w_rad[0]), math.sin(lp.w_rad[0])])
        ct = ps.cracked[gi]
        if ct is not None and ct[0] != loaded[0]["teeth"][gi]:
            raise ValueError("centre_line_compliance: the loaded pair is not on the cracked tooth")
        body = body if ct is None else pm.cracked[gi]
        qb, qw = _probe_rep(body, np.array([0.0, lp.y_axis_m[0]]))
        rows = np.concatenate([qb, qb + 1])
        coef = np.concatenate([qw * e[0], qw * e[1]])
        u = 0.0
        for c in loaded:  # the pair's flank nodes, and a spall's edges
            ia, wa = _reps(body, c, gi, 0, at_nodes=ct is None)
            Gs = body.G[np.ix_(rows, ia.ravel())].reshape(len(rows), ia.shape[0], 6)
            u += float(np.einsum("r,rjb,jb,j->", coef, Gs, wa, c["force_N"]))
        out[f"c{gi + 1}_m_per_N"] = u / F
        out[f"R{gi + 1}_m"] = R
        out[f"h{gi + 1}_m"] = float(lp.x_m[0] / math.cos(lp.w_rad[0]))
    out["c_pair_m_per_N"] = ps.ste_m / F
    out["c_local_m_per_N"] = ps.ste_m / F - out["c1_m_per_N"] - out["c2_m_per_N"]
    out["load_N"] = F
    out["R_star_m"] = d * (L - d) / L
    return out
