"""Frictionless contact by influence coefficients (fem.contact): hand-solved spring
cases, brute-force enumeration of the complementarity problem, and 2D Hertz line
contact of two elastic cylinders (FE, plane strain) against the closed form."""

import itertools
import math

import numpy as np
import pytest

from gearwear.fem.contact import (
    check_complementarity,
    fit_semi_ellipse,
    hertz_cylinders,
    hertz_line_contact,
    solve_contact,
)

# -- the solver on problems solved by hand ------------------------------------------


def test_two_springs_one_contact_by_hand():
    # spring 1 touches, spring 2 has a gap g2: small load -> spring 1 alone
    c1, c2, g2 = 1e-9, 2e-9, 1e-7
    C = np.diag([c1, c2])
    sol = solve_contact(C, [0.0, g2], total_force_N=50.0)
    assert sol.force_N == pytest.approx([50.0, 0.0], abs=1e-12)
    assert sol.approach_m == pytest.approx(c1 * 50.0, rel=1e-14)
    # the open spring keeps its gap minus the approach
    assert sol.gap_m[1] == pytest.approx(g2 - c1 * 50.0, rel=1e-13)
    assert list(sol.active) == [True, False]


def test_two_springs_both_in_contact_by_hand():
    c1, c2, g2, P = 1e-9, 2e-9, 1e-7, 500.0
    # both closed: delta = (P + g2/c2) / (1/c1 + 1/c2), p1 = delta/c1, p2 = (delta - g2)/c2
    delta = (P + g2 / c2) / (1 / c1 + 1 / c2)
    sol = solve_contact([np.diag([c1, 0.0]), np.diag([0.0, c2])], [0.0, g2], total_force_N=P)
    assert sol.approach_m == pytest.approx(delta, rel=1e-13)
    assert sol.force_N == pytest.approx([delta / c1, (delta - g2) / c2], rel=1e-13)
    assert sol.total_N == pytest.approx(P, rel=1e-15)
    # the same state under the prescribed approach
    sol2 = solve_contact(np.diag([c1, c2]), [0.0, g2], approach_m=delta)
    assert sol2.force_N == pytest.approx(sol.force_N, rel=1e-12)


def test_coupled_pair_by_hand():
    # influence matrix with cross terms (a load on one point moves the other)
    C = np.array([[3.0, 1.0], [1.0, 2.0]]) * 1e-9
    g = np.array([0.0, 0.2e-7])
    P = 100.0
    # both active: [C -1; 1 0] [p; delta] = [-g; P]  by Cramer's rule
    a, b, d = C[0, 0], C[0, 1], C[1, 1]
    # p1 + p2 = P and a p1 + b p2 - delta = -g1, b p1 + d p2 - delta = -g2
    # => (a - b) p1 + (b - d) p2 = g2 - g1
    p1 = (g[1] - g[0] - (b - d) * P) / ((a - b) - (b - d))
    p2 = P - p1
    delta = a * p1 + b * p2 + g[0]
    sol = solve_contact(C, g, total_force_N=P)
    assert p1 > 0 and p2 > 0
    assert sol.force_N == pytest.approx([p1, p2], rel=1e-12)
    assert sol.approach_m == pytest.approx(delta, rel=1e-13)


def _brute_force(C, g, P):
    """Enumerate all active sets; return the one meeting every condition."""
    n = len(g)
    found = []
    for r in range(1, n + 1):
        for S in itertools.combinations(range(n), r):
            S = list(S)
            A = np.zeros((r + 1, r + 1))
            A[:r, :r] = C[np.ix_(S, S)]
            A[:r, r] = -1.0
            A[r, :r] = 1.0
            sol = np.linalg.solve(A, np.concatenate([-g[S], [P]]))
            p = np.zeros(n)
            p[S] = sol[:r]
            gap = g + C @ p - sol[r]
            if np.all(p[S] > 0) and np.all(gap >= -1e-12 * np.max(np.abs(g))):
                found.append((p, sol[r]))
    return found


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_matches_enumeration_of_active_sets(seed):
    rng = np.random.default_rng(seed)
    n = 8
    M = rng.normal(size=(n, n))
    C = (M @ M.T + n * np.eye(n)) * 1e-10
    g = np.abs(rng.normal(size=n)) * 1e-7
    P = 200.0 * (1 + seed)
    ref = _brute_force(C, g, P)
    assert len(ref) == 1  # strictly convex QP: a unique solution
    sol = solve_contact(C, g, total_force_N=P)
    assert sol.force_N == pytest.approx(ref[0][0], rel=1e-10, abs=1e-10 * P)
    assert sol.approach_m == pytest.approx(ref[0][1], rel=1e-12)
    res = check_complementarity(sol, C, g, P)
    assert max(res.values()) < 1e-12


def test_prescribed_approach_without_contact_and_bad_inputs():
    C = np.eye(3) * 1e-9
    sol = solve_contact(C, [1e-6, 2e-6, 3e-6], approach_m=0.5e-6)
    assert np.all(sol.force_N == 0.0) and sol.gap_m == pytest.approx([0.5e-6, 1.5e-6, 2.5e-6])
    with pytest.raises(ValueError):
        solve_contact(C, [0, 0, 0])
    with pytest.raises(ValueError):
        solve_contact(C, [0, 0, 0], total_force_N=1.0, approach_m=0.0)
    with pytest.raises(ValueError):
        solve_contact(C, [0, 0], total_force_N=1.0)
    with pytest.raises(ValueError):
        solve_contact(C, [0, 0, 0], total_force_N=-1.0)


def test_semi_ellipse_fit_recovers_exact_profile():
    x = np.linspace(-3, 3, 121) * 1e-4
    a, p0 = 1.1e-4, 2e9
    p = p0 * np.sqrt(np.maximum(0, 1 - (x / a) ** 2))
    af, pf = fit_semi_ellipse(x, p, 1.3e-4, 1.5e9)
    assert af == pytest.approx(a, rel=1e-6) and pf == pytest.approx(p0, rel=1e-6)


def test_hertz_closed_form_identities():
    # a^2 = 4 w R* / (pi E*), p0 = 2 w / (pi a): load = pi a p0 / 2
    w, R1, R2, E, nu = 1e6, 0.01, 0.03, 206e9, 0.3
    a, p0 = hertz_line_contact(w, R1, R2, E, nu)
    Rs = 1 / (1 / R1 + 1 / R2)
    Es = E / (2 * (1 - nu**2))
    assert a == pytest.approx(math.sqrt(4 * w * Rs / (math.pi * Es)), rel=1e-15)
    assert math.pi * a * p0 / 2 == pytest.approx(w, rel=1e-15)


# -- Hertz line contact of two elastic cylinders (FE) -------------------------------


@pytest.fixture(scope="module")
def cylinders_p1():
    # R1 = R2 = 10 mm, a = 3.5 % of R (0.35 mm), elements a/15 over +-3.5 a, P1
    return hertz_cylinders(10e-3, 10e-3, order=1, elements_per_a=15)


def test_hertz_cylinders_half_width_and_peak_pressure(cylinders_p1):
    r = cylinders_p1
    assert r.element_size_m == pytest.approx(r.a_theory_m / 15)
    assert abs(r.a_error) < 0.02, r.a_error
    assert abs(r.p0_error) < 0.02, r.p0_error
    # the largest nodal pressure itself (no fit) is also within 2 % of p0
    assert abs(r.p_max_node_Pa / r.p0_theory_Pa - 1) < 0.02
    # the contact is inside the candidate zone with open nodes on both sides
    loaded = r.x_m[r.force_N > 0]
    assert loaded.min() > -1.2 * r.a_theory_m and loaded.max() < 1.2 * r.a_theory_m
    assert (r.force_N == 0).sum() > 20


def test_hertz_cylinders_complementarity_and_equilibrium(cylinders_p1):
    r = cylinders_p1
    res = check_complementarity(r.solution, r.flexibility, r.gap0_m, r.load_N_per_m)
    assert res["equilibrium"] < 1e-12
    assert res["neg_force"] == 0.0
    assert res["neg_gap"] < 1e-12
    assert res["complementarity"] < 1e-12
    # identical cylinders: the resultant acts on the line of centres (the unstructured
    # meshes are not mirror-symmetric node by node, so only the moment is checked)
    assert abs(np.sum(r.force_N * r.x_m)) < 1e-3 * r.load_N_per_m * r.a_theory_m


def test_hertz_cylinders_quadratic_elements():
    # P2, node-to-node on corner and mid-side nodes: the nodal pressures alternate by
    # a few per cent between corner and mid-side nodes; the fitted a and p0 do not.
    # Candidates within +-2a (the contact is within +-a) keep the 2 x 121 solves cheap.
    r = hertz_cylinders(10e-3, 10e-3, order=2, elements_per_a=15, candidate_half_width=2.0)
    assert r.x_m.min() < -1.9 * r.a_theory_m and r.solution.force_N[0] == 0.0
    assert abs(r.a_error) < 0.02 and abs(r.p0_error) < 0.02
    assert check_complementarity(r.solution, r.flexibility, r.gap0_m, r.load_N_per_m)["neg_gap"] < 1e-12


def test_hertz_cylinders_unequal_radii():
    # two different meshes (R1 = 10 mm, R2 = 20 mm) paired node-to-node at equal x
    r = hertz_cylinders(10e-3, 20e-3, order=1, elements_per_a=15)
    assert r.flexibility[0].shape == r.flexibility[1].shape
    assert not np.allclose(r.flexibility[0], r.flexibility[1], rtol=1e-2, atol=0.0)
    assert abs(r.a_error) < 0.02 and abs(r.p0_error) < 0.02


@pytest.mark.slow
def test_hertz_cylinders_unequal_radii_p2_and_refinement():
    r = hertz_cylinders(10e-3, 20e-3, order=2, elements_per_a=15, candidate_half_width=2.0)
    assert abs(r.a_error) < 0.02 and abs(r.p0_error) < 0.02
    # refining from a/8 to a/30 brings a closer to theory
    coarse = hertz_cylinders(10e-3, 10e-3, order=1, elements_per_a=8)
    fine = hertz_cylinders(10e-3, 10e-3, order=1, elements_per_a=30)
    assert abs(fine.a_error) < abs(coarse.a_error) < 0.02
