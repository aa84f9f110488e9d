"""Contact candidates of one tooth pair at one position of the resolved pair FE
(fem.pair): which flank points can touch, their initial gaps and lever arms (SI units:
m, N, rad).

Gaps from the exact profiles (node-to-surface). For each tooth pair the "slave" is the
gear whose tip is nearer the contact (the pinion for d past mid-path, else the gear): its
flank nodes within +-3 a_ref of arc length of the kinematic contact point (the tip corner
when d lies beyond the path) are the candidates; the "master" is the mating flank as an
exact involute, and the gap is the normal distance to it
(geometry.pair_positions.involute_gap, the pair placed by its tooth frames). The slave
point is the exact flank point at the node's radius (the corner itself for the corner
node), so corner (extended) contact outside the kinematic path is included: a slave's tip
corner meets the master flank below its start of active profile. A point whose foot lies
past the master's tip, below its condensed flank or whose radius is inside its base
circle cannot be loaded (gap inf).

Wear enters as initial gaps: g += h_slave(R_node) + h_master(R_foot), with h the wear
depth of geometry.wear.flank_depth along the nominal normal plus the profile
modifications and measured deviations of geometry.flank (fem.pair_model); the FE bodies
keep the nominal flanks. Why: the depths (<= 30 um) are 1e-3 of the tooth thickness, so
they change the body compliance by 0.01-0.1 % (fem.tooth, morph study) while they change
the gaps at first order (tens of um against a 1-2 um elastic approach); a nominal body
lets one factorization serve every wear state and keeps mesh changes out of the wear
effect. The gap g(s) keeps the worn profile's shape along the flank (including its
changed curvature), which is what the contact zone sees.

Lever arms. w_i = -(d g_i / d dtheta) / r_b1 (the lever arm of the master normal e_i
about O1 over r_b1; 1 on the line of action) by a central difference of the exact gaps
with the pinion turned by +-ROTATION_STEP_RAD. The rigid gap g_k of a pair is the
smallest g / w over DENSE_GAP_POINTS samples of its slave flank in the window.

A spall (geometry.faults) is a flank depth of its tooth only: the gap of a slave node
inside the pit, or of a slave node whose foot on the master lies inside it, grows by the
depth; its two edges are extra candidates (corners of the spalled flank, exact points on
the involute at the edge radii, loaded through the P2 edge weights); flank nodes within
h_c / 4 of an edge give way to it, and the candidate window reaches past both edges where
the contact lies within a window of the pit.
"""

from __future__ import annotations

import math

import numpy as np

from gearwear.geometry.pair_positions import (
    NO_SPALL,
    contact_arc_m,
    involute_arc_m,
    involute_gap,
    rot,
    spall_edge_radii_m,
    tip_roll_rad,
    tooth_frames,
)

from .pair_model import PairModel

DENSE_GAP_POINTS = 401  # samples of a pair's slave flank for its rigid gap g_k
ROTATION_STEP_RAD = 1e-7  # central difference of the gaps for the lever arms w_i


def _depth(pm: PairModel, gi: int, R: np.ndarray) -> np.ndarray:
    dd = pm.depth[gi]
    if dd is None:
        return np.zeros_like(R)
    return np.interp(R, dd[0], dd[1], left=0.0, right=0.0)


def _spall_depth(pm: PairModel, gi: int, R: np.ndarray, spalled: tuple) -> np.ndarray | float:
    """Depth (m) of the spall at radii R of gear gi's flank when the slot's tooth of
    gear gi carries it (``spalled``): the pit floor between its edges, 0 elsewhere."""
    if not spalled[gi]:
        return 0.0
    assert pm.faults is not None and pm.faults.spall is not None
    ra, rb = spall_edge_radii_m(pm.pair, pm.faults.spall)
    return np.where((R > ra) & (R < rb), pm.faults.spall.depth_m, 0.0)


def _gap(pm: PairModel, slave: int, R: np.ndarray, d: float, dtheta: float = 0.0, spalled: tuple = NO_SPALL):
    """Initial normal gap of the exact slave flank points at radii R against the exact
    master involute (geometry.pair_positions.involute_gap; + wear and flank deviations of
    both flanks, + the spall where the slot's tooth carries it): (gap, foot radius, master
    outward normal in the master tooth frame, the same in the fixed frame)."""
    gap, rF, n_loc, n_fix, off = involute_gap(pm.mesh, slave, R, d, dtheta)
    master = 1 - slave
    gap = gap + _depth(pm, slave, R) + _depth(pm, master, rF)
    if spalled != NO_SPALL:
        gap = gap + _spall_depth(pm, slave, R, spalled) + _spall_depth(pm, master, rF, spalled)
    # a foot past the master's tip or below its condensed flank: that slave point faces
    # the master's corner or fillet, not its flank; it cannot be loaded here
    gap = np.where(off | (rF < pm.bodies[master].flank_r[0][0]), np.inf, gap)
    return gap, rF, n_loc, n_fix


def _lever_arms(pm: PairModel, slave: int, R: np.ndarray, d: float, spalled: tuple = NO_SPALL):
    """(gap, foot radius, local normal, fixed normal, w) of slave points at radii R, w the
    lever arm -(d gap / d dtheta) / r_b1 by a central difference of the exact gaps."""
    gap, rF, n_loc, e_fix = _gap(pm, slave, R, d, spalled=spalled)
    gp, _, _, _ = _gap(pm, slave, R, d, ROTATION_STEP_RAD, spalled)
    gm_, _, _, _ = _gap(pm, slave, R, d, -ROTATION_STEP_RAD, spalled)
    ok = np.isfinite(gap) & np.isfinite(gp) & np.isfinite(gm_)
    with np.errstate(invalid="ignore"):  # inf - inf where a point cannot touch (not ok)
        w = -(gp - gm_) / (2 * ROTATION_STEP_RAD) / pm.pair.gear(0).base_radius_m
    return gap, rF, n_loc, e_fix, w, ok


def _spall_edges(pm: PairModel, d: float, spalled: tuple):
    """(gear, edge radii (2,), edge arc positions (2,), widened window) when the slot's
    spalled flank can touch the mating flank near its pit at LOA position d, else None.

    The mating flank bridges a short pit on its edges (geometry.faults): the two edges are
    corners of the spalled flank, loaded like the tip corner by an exact point on the
    flank, and the candidate window reaches past both of them."""
    if not any(spalled):
        return None
    assert pm.faults is not None and pm.faults.spall is not None
    gs = 0 if spalled[0] else 1
    g = pm.pair.gear(gs)
    rb = g.base_radius_m
    radii = np.array(spall_edge_radii_m(pm.pair, pm.faults.spall))
    s_edges = involute_arc_m(rb, radii)
    s_c = contact_arc_m(pm.mesh, gs, d)
    w = pm.window_m
    if not (s_edges[0] - w <= s_c <= s_edges[1] + w):
        return None
    return gs, radii, s_edges, w + float(np.max(np.abs(s_edges - s_c)))


def _candidates(pm: PairModel, d: float, j: int, spalled: tuple = NO_SPALL) -> list:
    """Candidate points of the pair in slot j at LOA position d: one dict (slave nodes,
    gaps, lever arms, directions), and a second with the two edges of a spall on the
    slot's tooth (geometry.faults) where the mating flank can reach them; empty when no
    point can reach the mating flank."""
    mid = 0.5 * (pm.mesh.path_start_m + pm.mesh.path_end_m)
    slave = 0 if d >= mid else 1
    gs = pm.pair.gear(slave)
    rb = gs.base_radius_m
    u_a = tip_roll_rad(gs)
    s_c = contact_arc_m(pm.mesh, slave, d)
    body = pm.bodies[slave]
    r_nodes = body.flank_r[0]
    s_nodes = involute_arc_m(rb, r_nodes)
    edges = _spall_edges(pm, d, spalled)
    window = pm.window_m if edges is None else edges[3]
    sel = np.flatnonzero(np.abs(s_nodes - s_c) <= window)
    g1, g2, _ = tooth_frames(pm.mesh, d)
    gam = (g1, g2)
    master = 1 - slave
    out = []
    if sel.size:
        R = r_nodes[sel]
        gap, rF, n_loc, e_fix, w, ok = _lever_arms(pm, slave, R, d, spalled)
        if edges is not None:
            # the edge points replace the flank nodes at them (two candidates at one point
            # would make C singular): nodes within h_c / 4 of an edge on the spalled flank
            ge, _, s_e, _ = edges
            s_pit = involute_arc_m(rb, R) if ge == slave else involute_arc_m(pm.pair.gear(ge).base_radius_m, rF)
            ok &= np.min(np.abs(s_pit[:, None] - s_e[None, :]), axis=1) > 0.25 * pm.sizes.contact_m
        if ok.any():
            sel, R, gap, rF, n_loc, e_fix, w = (x[ok] for x in (sel, R, gap, rF, n_loc, e_fix, w))
            # rigid gap of the pair: dense sampling of the slave flank over the window
            u_lo = math.sqrt(max(2 * (s_c - window) / rb, 0.0))
            u_hi = math.sqrt(2 * min(s_c + window, rb * u_a**2 / 2) / rb)
            Rd = rb * np.sqrt(1.0 + np.linspace(u_lo, u_hi, DENSE_GAP_POINTS) ** 2)
            gd, _, _, _, wd, _ = _lever_arms(pm, slave, Rd, d, spalled)
            with np.errstate(invalid="ignore"):
                g_pair = float(np.nanmin(np.where(np.isfinite(gd) & (wd > 0), gd / wd, np.inf)))
            # directions in each body's tooth frame: +e on the slave node, -e on the master foot
            out.append(
                {
                    "slave": slave,
                    "nodes": sel,
                    "R": R,
                    "rF": rF,
                    "gap": gap,
                    "w": w,
                    "g_pair": g_pair,
                    "dirs": {slave: e_fix @ rot(-gam[slave]).T, master: -n_loc},
                    "j": j,
                    "d": d,
                    "teeth": (-j, j),
                }
            )
    if edges is not None:
        ge, Re, _, _ = edges
        gap, rF, n_loc, e_fix, w, ok = _lever_arms(pm, ge, Re, d)  # the edge itself is not in the pit
        ok &= w > 0
        if ok.any():
            Re, gap, rF, n_loc, e_fix, w = (x[ok] for x in (Re, gap, rF, n_loc, e_fix, w))
            out.append(
                {
                    "slave": ge,
                    "nodes": None,
                    "R": Re,
                    "rF": rF,
                    "gap": gap,
                    "w": w,
                    "g_pair": float(np.min(gap / w)),
                    "dirs": {ge: e_fix @ rot(-gam[ge]).T, 1 - ge: -n_loc},
                    "j": j,
                    "d": d,
                    "teeth": (-j, j),
                    "corner": True,
                }
            )
    return out
