"""Frictionless 2D contact by FE influence coefficients and an active-set
complementarity solve, verified on Hertz line contact of two cylinders.

Contact problem (influence-coefficient form, Johnson, *Contact Mechanics*, 1985,
ch. 5 and Kalker, *Three-dimensional elastic bodies in rolling contact*, 1990)
-------------------------------------------------------------------------------
n candidate contact points i (node pairs, or tooth pairs) carry compressive normal
forces p_i >= 0 (N; forces, not pressures). Each body B has a flexibility
(influence) matrix C^B (m/N): C^B_ij = displacement of point i of body B along the
inward normal (away from the other body) caused by a unit compressive force at point
j. It is symmetric by Maxwell-Betti reciprocity. With C = sum_B C^B, the initial
(undeformed, rigid) gaps g_i (m) and the rigid approach delta (m) of the two bodies
along the common normal, the deformed gap is

    gap_i = g_i + (C p)_i - delta                                      (1)

(surfaces pushed inward open the gap, the rigid approach closes it) and the
frictionless contact conditions are the linear complementarity problem

    p_i >= 0,   gap_i >= 0,   p_i gap_i = 0,   and either sum_i p_i = P   (2)
                                               (force control, delta unknown)
                                               or delta given (approach control).

Because C is symmetric positive definite, (1)-(2) are exactly the KKT conditions of
the strictly convex quadratic programme

    min  1/2 p^T C p + g^T p     s.t.  p >= 0,  1^T p = P              (3)

with delta the multiplier of the equality (for approach control: min 1/2 p^T C p +
(g - delta 1)^T p s.t. p >= 0). Its solution is unique.

Solver: primal active-set method (Lawson & Hanson, *Solving Least Squares
Problems*, 1974, ch. 23, the NNLS algorithm, with the extra equality row): solve the
equality system on the active set S,

    [ C_SS  -1 ] [ p_S   ]   [ -g_S ]
    [ 1^T    0 ] [ delta ] = [  P   ],

if a force comes out <= 0, step from the previous feasible point toward the new one
only as far as feasibility allows and drop the point(s) that reach zero (Kalker's
"drop tensile nodes", done without losing feasibility); once all forces are positive,
add the point with the most negative gap (most penetrating) and repeat. Every step
lowers the objective of (3) and no active set repeats, so the method terminates in a
finite number of steps at the exact solution (the dense solves are direct, the
result is exact up to round-off). Convergence test: min gap >= -tol * scale with
tol = 1e-12 and scale = max(|g|, |delta|, max(C) P). scipy.optimize.nnls solves
min |A x - b|, x >= 0 only; the equality sum p = P (unknown delta) would need a
penalty row, which is not exact, so the algorithm is implemented here directly.

Hertz line contact (verification, ``hertz_cylinders``)
-------------------------------------------------------
Two cylinders of radii R1, R2 (plane strain) pressed together by a load w per unit
length (N/m): contact half-width and peak pressure (Johnson 1985, Eq. 4.43-4.45)

    a = sqrt(4 w R* / (pi E*)),   p0 = 2 w / (pi a),   p(x) = p0 sqrt(1 - x^2/a^2)
    1/R* = 1/R1 + 1/R2,   1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2.

FE model: each cylinder is a disc on a rigid shaft (bore of radius ``bore_frac`` R
fixed; this removes the rigid-body motion far from the contact, where it does not
change the contact stresses, St Venant). The circle polygon is sampled at equal
x-spacing h (the element size, h << a) within +-x_fine around the contact pole and
graded outside; the mesh is refined to h there. Candidate points are the boundary
nodes (corner and, for P2, mid-side nodes) with |x| <= 3a; both bodies use the same
x-sampling, so nodes pair one-to-one at equal x (node-to-node). The common normal is
the line of centres (y); the gap of a pair is measured along it from the actual node
positions (mid-side nodes sit on the chords). Influence columns: one unit normal
nodal force per candidate node, all solved against one factorization.

Nodal force -> pressure: p_i = f_i / L_i with the tributary length L_i = int N_i ds
(the boundary integral of the node's shape function: (l_left + l_right)/2 for P1,
l/6 per adjacent edge for P2 corners and 2 l/3 for P2 mid-side nodes). a and p0 are
estimated by a least-squares fit of the semi-ellipse p0 sqrt(max(0, 1 - x^2/a^2)) to
all candidate-node pressures (two parameters; robust against the node-level
discreteness of the contact edge).

Verification (R1 = R2 = 10 mm, E = 206 GPa, nu = 0.3, w = 2.18 MN/m so that
a = 0.35 mm = 3.5 % R, p0 = 3.96 GPa; element size h = a/15 = 23 um, candidates
|x| <= 3a, ~8 000 triangles per cylinder, ~1 s):
P1: a +0.12 %, p0 +0.16 %, largest nodal pressure +0.27 %; h = a/8: +0.30 / +0.24 %,
h = a/30: +0.04 / +0.12 %. P2 (corner and mid-side nodes paired): a +0.09 %, p0
+0.84 %; the nodal pressures alternate by ~3 % between corner and mid-side nodes
(the node-to-node P2 oscillation), the fit averages it out. R2 = 20 mm (two
different meshes): a +0.14 %, p0 +0.13 % (P1).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from gearwear.core.validation import fail
from gearwear.geometry.polyline import stitch

__all__ = [
    "ContactSolution",
    "solve_contact",
    "check_complementarity",
    "HertzCylinderResult",
    "hertz_line_contact",
    "hertz_cylinders",
    "fit_semi_ellipse",
]


# ---------------------------------------------------------------------------
# the complementarity solver
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class ContactSolution:
    """Solution of the contact LCP (1)-(2); SI units.

    force_N      (n,) compressive contact forces p_i >= 0
    approach_m   rigid approach delta (prescribed or solved for)
    gap_m        (n,) deformed gaps g + C p - delta (>= 0; exactly 0 where loaded,
                 up to round-off)
    active       (n,) True where p_i > 0
    iterations   number of active-set changes
    """

    force_N: np.ndarray
    approach_m: float
    gap_m: np.ndarray
    active: np.ndarray
    iterations: int

    @property
    def total_N(self) -> float:
        return float(self.force_N.sum())


def _as_flexibility(C) -> np.ndarray:
    if isinstance(C, (list, tuple)):
        mats = [np.asarray(c, dtype=float) for c in C]
        if not mats:
            raise ValueError("flexibility: empty list of body matrices")
        Ct = np.sum(mats, axis=0)
    else:
        Ct = np.asarray(C, dtype=float)
    if Ct.ndim != 2 or Ct.shape[0] != Ct.shape[1]:
        raise ValueError(f"flexibility must be a square matrix, got shape {Ct.shape}")
    if not np.all(np.isfinite(Ct)):
        raise ValueError("flexibility has non-finite entries")
    return Ct


def solve_contact(
    flexibility,
    gap0_m,
    total_force_N: float | None = None,
    approach_m: float | None = None,
    tol: float = 1e-12,
    max_iter: int | None = None,
) -> ContactSolution:
    """Solve the frictionless contact LCP by the primal active-set method.

    flexibility   (n, n) m/N, or a list of per-body matrices that are summed
                  (C = sum_B C^B; symmetric positive definite).
    gap0_m        (n,) initial gaps g_i (m) at zero approach; may be negative
                  (initial interference) when the approach is prescribed.
    total_force_N prescribed total compressive force P > 0 (force control) ...
    approach_m    ... or the prescribed rigid approach delta (exactly one of them).

    Sign convention: gap_i = g_i + (C p)_i - delta, p_i >= 0 compressive.
    Returns a :class:`ContactSolution`; raises RuntimeError if the active set does not
    converge within ``max_iter`` (default 10 n + 20) changes (it cannot for SPD C).
    """
    C = _as_flexibility(flexibility)
    g = np.asarray(gap0_m, dtype=float).ravel()
    n = g.size
    if C.shape[0] != n:
        raise ValueError(f"flexibility is {C.shape}, gaps have {n} entries")
    if (total_force_N is None) == (approach_m is None):
        raise ValueError("give exactly one of total_force_N and approach_m")
    if n == 0:
        raise ValueError("no candidate contact points")
    if max_iter is None:
        max_iter = 10 * n + 20
    force_control = total_force_N is not None
    P = delta = math.nan  # the one of them not given stays NaN and is never used
    if total_force_N is not None:
        P = float(total_force_N)
        if not (P > 0 and math.isfinite(P)):
            raise fail("total_force_N", repr(total_force_N), "", "must be finite and > 0")
    elif approach_m is not None:
        delta = float(approach_m)
        if not math.isfinite(delta):
            raise fail("approach_m", repr(approach_m), "", "must be finite")
    cmax = float(np.max(np.abs(np.diag(C))))
    p = np.zeros(n)
    if force_control:
        # feasible start: the point of smallest gap carries everything
        k0 = int(np.argmin(g))
        S = [k0]
        p[k0] = P
        scale = max(float(np.max(np.abs(g))), cmax * P)
    else:
        S = []
        scale = max(float(np.max(np.abs(g))), abs(delta), 1e-300)

    def equality_solve(S):
        idx = np.asarray(S, dtype=int)
        if force_control:
            m = len(idx)
            A = np.zeros((m + 1, m + 1))
            A[:m, :m] = C[np.ix_(idx, idx)]
            A[:m, m] = -1.0
            A[m, :m] = 1.0
            rhs = np.concatenate([-g[idx], [P]])
            sol = sla.solve(A, rhs)
            return sol[:m], float(sol[m])
        if len(idx) == 0:
            return np.zeros(0), delta
        return sla.solve(C[np.ix_(idx, idx)], delta - g[idx], assume_a="pos"), delta

    it = 0
    d_cur = delta if not force_control else math.nan
    while True:
        # inner loop: equality solve on S, back off to feasibility while a force is <= 0
        while S:
            z, d_new = equality_solve(S)
            if np.all(z > 0.0):
                p[:] = 0.0
                p[np.asarray(S)] = z
                d_cur = d_new
                break
            it += 1
            if it > max_iter:
                raise RuntimeError("contact active set did not converge")
            idx = np.asarray(S)
            ps = p[idx]
            neg = z <= 0.0
            alpha = float(np.min(ps[neg] / (ps[neg] - z[neg])))
            p[idx] = ps + alpha * (z - ps)
            # the blocking point(s) reach zero: leave the active set
            keep = p[idx] > 1e-14 * max(float(np.max(ps)), 1e-300)
            p[idx[~keep]] = 0.0
            S = [int(i) for i in idx[keep]]
        gap = g + C @ p - d_cur
        free = np.ones(n, dtype=bool)
        free[np.asarray(S, dtype=int)] = False
        if force_control:
            scale = max(scale, abs(d_cur))
        if not np.any(free) or float(np.min(gap[free])) >= -tol * scale:
            break
        it += 1
        if it > max_iter:
            raise RuntimeError("contact active set did not converge")
        cand = np.flatnonzero(free)
        S.append(int(cand[np.argmin(gap[cand])]))
    active = p > 0.0
    return ContactSolution(p.copy(), float(d_cur), gap, active, it)


def check_complementarity(sol: ContactSolution, flexibility, gap0_m, total_force_N: float | None = None) -> dict:
    """Residuals of (1)-(2) at a solution, each scaled to be ~1e-15 when exact:
    min force / max force, min gap / gap scale, max |p_i gap_i| / (P * gap scale),
    and |sum p - P| / P."""
    C = _as_flexibility(flexibility)
    g = np.asarray(gap0_m, dtype=float)
    p = sol.force_N
    gap = g + C @ p - sol.approach_m
    P = float(total_force_N) if total_force_N is not None else max(float(p.sum()), 1e-300)
    gscale = max(float(np.max(np.abs(g))), abs(sol.approach_m), float(np.max(np.abs(C @ p))), 1e-300)
    return {
        "neg_force": float(max(0.0, -p.min()) / max(p.max(), 1e-300)),
        "neg_gap": float(max(0.0, -gap.min()) / gscale),
        "complementarity": float(np.max(np.abs(p * gap)) / (P * gscale)),
        "equilibrium": float(abs(p.sum() - P) / P),
    }


# ---------------------------------------------------------------------------
# Hertz line contact: theory and FE verification
# ---------------------------------------------------------------------------


def hertz_line_contact(
    w_N_per_m: float,
    R1_m: float,
    R2_m: float,
    E1_Pa: float,
    nu1: float,
    E2_Pa: float | None = None,
    nu2: float | None = None,
) -> tuple[float, float]:
    """(a, p0): Hertz half-width (m) and peak pressure (Pa) of two cylinders (plane
    strain), a = sqrt(4 w R* / (pi E*)), p0 = 2 w / (pi a). R2 = inf gives a flat."""
    E2 = E1_Pa if E2_Pa is None else E2_Pa
    n2 = nu1 if nu2 is None else nu2
    inv_R = 1.0 / R1_m + (0.0 if math.isinf(R2_m) else 1.0 / R2_m)
    E_star = 1.0 / ((1 - nu1**2) / E1_Pa + (1 - n2**2) / E2)
    a = math.sqrt(4.0 * w_N_per_m / (math.pi * E_star * inv_R))
    return a, 2.0 * w_N_per_m / (math.pi * a)


def fit_semi_ellipse(x_m: np.ndarray, p_Pa: np.ndarray, a0: float, p00: float) -> tuple[float, float]:
    """Least-squares fit of p0 sqrt(max(0, 1 - x^2/a^2)) to nodal pressures: (a, p0)."""
    from scipy.optimize import least_squares

    x = np.asarray(x_m, dtype=float)
    p = np.asarray(p_Pa, dtype=float)

    def res(q):
        a, p0 = q
        return p0 * np.sqrt(np.maximum(0.0, 1.0 - (x / a) ** 2)) - p

    sol = least_squares(res, [a0, p00], x_scale=[a0, p00], xtol=1e-14, ftol=1e-14, gtol=1e-14)
    return float(sol.x[0]), float(sol.x[1])


@dataclass
class HertzCylinderResult:
    """FE Hertz line contact versus theory (SI units)."""

    a_theory_m: float
    p0_theory_Pa: float
    a_fit_m: float
    p0_fit_Pa: float
    p_max_node_Pa: float
    x_m: np.ndarray  # candidate node positions along the contact
    pressure_Pa: np.ndarray  # nodal force / tributary length
    force_N: np.ndarray  # nodal forces (per unit length: thickness 1 m)
    solution: ContactSolution
    flexibility: list
    gap0_m: np.ndarray
    load_N_per_m: float
    element_size_m: float
    n_elements: tuple
    timings: dict = field(default_factory=dict)

    @property
    def a_error(self) -> float:
        return self.a_fit_m / self.a_theory_m - 1.0

    @property
    def p0_error(self) -> float:
        return self.p0_fit_Pa / self.p0_theory_Pa - 1.0


def _cylinder_outline(R: float, x_fine: float, h: float, h_max: float, growth: float = 1.15) -> np.ndarray:
    """CCW circle polygon (centre at the origin, contact pole at (0, R)): equal
    x-spacing h for |x| <= x_fine, then arc steps growing by ``growth`` up to h_max
    down to the bottom (0, -R), the same on both sides."""
    n = int(math.ceil(x_fine / h))
    xs = h * np.arange(n, -n - 1, -1)  # over the pole, counter-clockwise
    fine = np.column_stack([xs, np.sqrt(R * R - xs * xs)])
    # polar angle phi from +y, counter-clockwise: (x, y) = R (-sin phi, cos phi)
    phi = [math.asin(n * h / R)]
    s = h
    while True:
        s = min(s * growth, h_max)
        if phi[-1] + s / R >= math.pi - 0.5 * s / R:
            break
        phi.append(phi[-1] + s / R)
    if len(phi) > 1 and math.pi - phi[-1] < 0.3 * s / R:
        phi.pop()
    ang = np.array(phi[1:] + [math.pi])
    side = np.vstack([fine[-1:], np.column_stack([-R * np.sin(ang), R * np.cos(ang)])])
    return stitch([fine, side, (side * np.array([-1.0, 1.0]))[::-1]], closed=True)


def _cylinder_body(
    R: float,
    E: float,
    nu: float,
    x_fine: float,
    h: float,
    x_cand: float,
    order: int,
    bore_frac: float,
    global_m: float | None = None,
):
    """Mesh one cylinder, assemble (plane strain, thickness 1 m, bore fixed) and return
    (model, candidate y-dofs sorted by x, their x, their y, tributary lengths, n_elem)."""
    import skfem
    from skfem import FacetBasis, asm

    from gearwear.fem.mesh import MeshSizes, mesh_full_gear
    from gearwear.geometry.spec import Material

    from .elasticity import assemble

    h_max = global_m if global_m is not None else R / 12.0
    outline = _cylinder_outline(R, x_fine, h, h_max)
    fine = outline[np.abs(outline[:, 0]) <= x_fine + 1e-12]
    fine = fine[fine[:, 1] > 0]
    sizes = MeshSizes(global_m=h_max, load_m=h, load_dist_m=0.25 * x_fine, growth=0.2)
    gm = mesh_full_gear(outline, bore_frac * R, sizes, refine_points_xy=fine, order=order)
    mat = Material(youngs_modulus_Pa=E, poisson_ratio=nu)
    model = assemble(gm.mesh, mat, 1.0, gm.boundaries["bore"], plane="strain", order=order)
    m = model.mesh
    outer = np.asarray(gm.boundaries["outer"])
    basis = model.basis
    verts = np.unique(m.facets[:, outer])
    ydof_list = list(basis.nodal_dofs[1, verts])
    if order == 2:
        ydof_list += list(basis.facet_dofs[1, outer])
    ydofs = np.asarray(ydof_list, dtype=int)
    loc = basis.doflocs[:, ydofs]
    sel = (np.abs(loc[0]) <= x_cand * (1 + 1e-9)) & (loc[1] > 0)
    ydofs, loc = ydofs[sel], loc[:, sel]
    o = np.argsort(loc[0])
    ydofs, loc = ydofs[o], loc[:, o]
    fb = FacetBasis(m, basis.elem, facets=outer, intorder=2 * order + 2)

    @skfem.LinearForm
    def ey(v, w):
        return v[1]

    trib = asm(ey, fb)[ydofs]
    return model, ydofs, loc[0], loc[1], trib, int(m.t.shape[1])


def hertz_cylinders(
    R1_m: float = 10e-3,
    R2_m: float = 10e-3,
    E_Pa: float = 206e9,
    nu: float = 0.3,
    a_over_R: float = 0.035,
    elements_per_a: float = 15.0,
    order: int = 2,
    bore_frac: float = 0.25,
    candidate_half_width: float = 3.0,
) -> HertzCylinderResult:
    """FE Hertz line contact of two cylinders (plane strain, thickness 1 m).

    The load per unit length w is chosen so that the theoretical half-width is
    ``a_over_R`` * min(R1, R2); the element size at the contact is a / elements_per_a
    over |x| <= (candidate_half_width + 0.5) a; candidate node pairs within
    |x| <= candidate_half_width * a. Both bodies are meshed and assembled (when R1 = R2
    the second is the mirror image of the first: its flexibility is the same matrix,
    so it is reused).
    """
    t0 = time.perf_counter()
    Rmin = min(R1_m, R2_m)
    a_t = a_over_R * Rmin
    R_star = 1.0 / (1.0 / R1_m + 1.0 / R2_m)
    E_star = E_Pa / (2.0 * (1.0 - nu**2))
    w = a_t**2 * math.pi * E_star / (4.0 * R_star)
    a_th, p0_th = hertz_line_contact(w, R1_m, R2_m, E_Pa, nu)
    h = a_th / elements_per_a
    x_fine = (candidate_half_width + 0.5) * a_th
    x_cand = candidate_half_width * a_th
    bodies = []
    timings = {}
    radii = [R1_m] if R1_m == R2_m else [R1_m, R2_m]
    for R in radii:
        tb = time.perf_counter()
        model, dofs, x, y, trib, nel = _cylinder_body(R, E_Pa, nu, x_fine, h, x_cand, order, bore_frac)
        tm = time.perf_counter()
        F = np.zeros((model.ndofs, dofs.size))
        F[dofs, np.arange(dofs.size)] = -1.0  # unit compressive force (toward the centre)
        U = model.solve(F)
        Cb = -U[dofs, :]  # inward (away from the contact) normal displacement
        Cb = 0.5 * (Cb + Cb.T)  # Maxwell-Betti: symmetric up to round-off
        bodies.append(dict(C=Cb, x=x, y=y, R=R, trib=trib, nel=nel))
        timings[f"body_R{R * 1e3:g}mm_s"] = time.perf_counter() - tb
        timings[f"influence_R{R * 1e3:g}mm_s"] = time.perf_counter() - tm
    if len(bodies) == 1:
        bodies.append(bodies[0])
    b1, b2 = bodies
    if b1["x"].size != b2["x"].size or not np.allclose(b1["x"], b2["x"], atol=1e-6 * h):
        raise RuntimeError("candidate nodes of the two cylinders do not pair up at equal x")
    x = b1["x"]
    # initial gap along the line of centres, from the actual node positions
    g = (b1["R"] - b1["y"]) + (b2["R"] - b2["y"])
    tc = time.perf_counter()
    sol = solve_contact([b1["C"], b2["C"]], g, total_force_N=w)
    timings["contact_s"] = time.perf_counter() - tc
    trib = 0.5 * (b1["trib"] + b2["trib"])
    pres = sol.force_N / trib
    a_fit, p0_fit = fit_semi_ellipse(x, pres, a_th, p0_th)
    timings["total_s"] = time.perf_counter() - t0
    return HertzCylinderResult(
        a_th,
        p0_th,
        a_fit,
        p0_fit,
        float(pres.max()),
        x,
        pres,
        sol.force_N,
        sol,
        [b1["C"], b2["C"]],
        g,
        w,
        h,
        (b1["nel"], b2["nel"]),
        timings,
    )
