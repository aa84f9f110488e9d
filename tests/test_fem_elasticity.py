"""fem.elasticity against independent truths: patch tests, Timoshenko & Goodier's
cantilever, mirror symmetry, plane stress versus plane strain.

The reference values are written here from the equations (Hooke's law in E and nu,
the exact elasticity solution of the end-loaded cantilever), not from fem.elasticity.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla
import skfem

from gearwear.fem.elasticity import assemble, lame, traction_load
from gearwear.geometry.spec import Material

STEEL = Material(206e9, 0.3)
E, NU = STEEL.youngs_modulus_Pa, STEEL.poisson_ratio
G = E / (2 * (1 + NU))


def hooke(eps_xx, eps_yy, gam_xy, plane):
    """Stresses from engineering strains, written from E and nu directly."""
    if plane == "stress":
        f = E / (1 - NU**2)
        return f * (eps_xx + NU * eps_yy), f * (eps_yy + NU * eps_xx), G * gam_xy
    f = E / ((1 + NU) * (1 - 2 * NU))
    return f * ((1 - NU) * eps_xx + NU * eps_yy), f * ((1 - NU) * eps_yy + NU * eps_xx), G * gam_xy


def compliance_strains(sxx, syy, txy, plane):
    """Inverse Hooke: plane stress eps = [sxx - nu syy] / E; plane strain (sigma_zz =
    nu (sxx + syy)) eps_xx = [(1 - nu^2) sxx - nu (1 + nu) syy] / E."""
    if plane == "stress":
        return (sxx - NU * syy) / E, (syy - NU * sxx) / E, txy / G
    return (((1 - NU**2) * sxx - NU * (1 + NU) * syy) / E, ((1 - NU**2) * syy - NU * (1 + NU) * sxx) / E, txy / G)


def irregular_rectangle(L=0.02, H=0.01, n=(8, 5), seed=0, amp=0.3):
    """Tensor mesh of [0, L] x [0, H], refined once, interior vertices moved randomly
    by up to amp x the local spacing (orientation kept counter-clockwise)."""
    m = skfem.MeshTri.init_tensor(np.linspace(0, L, n[0] + 1), np.linspace(0, H, n[1] + 1)).refined(1)
    p = m.p.copy()
    interior = np.setdiff1d(np.arange(m.nvertices), m.boundary_nodes())
    h = min(L / n[0], H / n[1]) / 2
    rng = np.random.default_rng(seed)
    p[:, interior] += amp * h * rng.uniform(-1, 1, (2, interior.size))
    t = m.t.copy()
    cw = _signed_areas(p, t) < 0
    t[1:, cw] = t[2:0:-1, cw]
    out = skfem.MeshTri(p, t, sort_t=False)
    _assert_ccw(out)
    return out


def _signed_areas(p, t):
    a, b, c = (p[:, t[i]] for i in range(3))
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))


def _assert_ccw(m):
    assert np.all(_signed_areas(m.p, m.t) > 0)


def solve_with_prescribed(model, u_prescribed_fixed, F=None):
    """Solve K u = F with u given on the model's fixed dofs (nonzero Dirichlet),
    through the model's own factorization of K_ff."""
    U = np.zeros(model.ndofs)
    U[model.fixed] = u_prescribed_fixed
    rhs = -(model.K[model.free][:, model.fixed] @ u_prescribed_fixed)
    if F is not None:
        rhs = rhs + F[model.free]
    U[model.free] = model.lu.solve(rhs)
    return U


def stresses_at_quadrature(model, U):
    """(sxx, syy, txy) at the quadrature points from the FE strains and hooke()."""
    du = model.basis.interpolate(U).grad  # (2, 2, nel, nqp): du[i, j] = d u_i / d x_j
    exx, eyy, gxy = du[0, 0], du[1, 1], du[0, 1] + du[1, 0]
    return hooke(exx, eyy, gxy, model.plane)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_displacement_patch_test(order, plane):
    """Linear displacement of a uniform stress state imposed on the whole boundary
    of an irregular mesh: the FE solution is that field at every dof and the stress
    is uniform (Irons' patch test)."""
    m = irregular_rectangle(seed=1 + order)
    sig = (120e6, -45e6, 35e6)
    exx, eyy, gxy = compliance_strains(*sig, plane)
    model = assemble(m, STEEL, 0.02, m.boundary_facets(), plane=plane, order=order)
    x = model.basis.doflocs  # (2, N): location of every dof (x and y dofs interleaved)
    # exact field plus a rigid-body motion (must not produce stress)
    ux = exx * x[0] + 0.5 * gxy * x[1] + 1e-5 - 2e-4 * x[1]
    uy = 0.5 * gxy * x[0] + eyy * x[1] - 3e-5 + 2e-4 * x[0]
    ix, iy = model.basis.split_indices()  # skfem interleaves the components: x at even, y at odd dofs
    assert np.array_equal(ix, np.arange(0, model.ndofs, 2)) and np.array_equal(iy, np.arange(1, model.ndofs, 2))
    U_exact = np.empty(model.ndofs)
    U_exact[0::2], U_exact[1::2] = ux[0::2], uy[1::2]
    U = solve_with_prescribed(model, U_exact[model.fixed])
    assert model.free.size > 50  # a real patch: many interior dofs
    assert np.max(np.abs(U - U_exact)) <= 1e-10 * np.max(np.abs(U_exact))
    sxx, syy, txy = stresses_at_quadrature(model, U)
    scale = max(abs(s) for s in sig)
    for got, want in zip((sxx, syy, txy), sig):
        assert np.max(np.abs(got - want)) <= 1e-10 * scale  # measured ~1e-13


@pytest.mark.parametrize("order", [1, 2])
def test_traction_patch_test_plane_stress_vs_strain(order):
    """Uniaxial tension by a traction on x = L, symmetry supports (u_x = 0 on x = 0,
    u_y = 0 on y = 0): the stress is uniform sigma_xx = T, and the strains follow
    plane stress eps_xx = T / E, eps_yy = -nu T / E, or plane strain
    eps_xx = (1 - nu^2) T / E, eps_yy = -nu (1 + nu) T / E."""
    L, H, b, T = 0.02, 0.01, 0.015, 80e6
    m = irregular_rectangle(L, H, seed=7)
    right = m.facets_satisfying(lambda x: np.isclose(x[0], L), boundaries_only=True)
    left = m.facets_satisfying(lambda x: np.isclose(x[0], 0.0), boundaries_only=True)
    bottom = m.facets_satisfying(lambda x: np.isclose(x[1], 0.0), boundaries_only=True)
    for plane, (exx_want, eyy_want) in {
        "stress": (T / E, -NU * T / E),
        "strain": ((1 - NU**2) * T / E, -NU * (1 + NU) * T / E),
    }.items():
        model = assemble(m, STEEL, b, left, plane=plane, order=order)
        F = traction_load(model, right, lambda x, y: np.stack([np.full_like(x, T), np.zeros_like(x)]))
        # resultant of the consistent load = b T H
        assert F[0::2].sum() == pytest.approx(b * T * H, rel=1e-12)
        assert abs(F[1::2].sum()) < 1e-9 * b * T * H
        fix = np.concatenate(
            [model.basis.get_dofs(facets=left).all("u^1"), model.basis.get_dofs(facets=bottom).all("u^2")]
        )
        free = np.setdiff1d(np.arange(model.ndofs), fix)
        U = np.zeros(model.ndofs)
        U[free] = spla.spsolve(model.K[free][:, free].tocsc(), F[free])
        x = model.basis.doflocs
        assert np.allclose(U[0::2], exx_want * x[0, 0::2], rtol=0, atol=1e-10 * exx_want * L)
        assert np.allclose(U[1::2], eyy_want * x[1, 1::2], rtol=0, atol=1e-10 * abs(eyy_want) * H)
        sxx, syy, txy = stresses_at_quadrature(model, U)
        assert np.allclose(sxx, T, rtol=1e-9) and np.max(np.abs(syy)) < 1e-9 * T and np.max(np.abs(txy)) < 1e-9 * T


def test_lame_constants():
    lam, mu = lame(STEEL, "strain")
    assert lam == pytest.approx(E * NU / ((1 + NU) * (1 - 2 * NU)), rel=1e-14) and mu == pytest.approx(G, rel=1e-14)
    lam_s, mu_s = lame(STEEL, "stress")
    assert lam_s == pytest.approx(E * NU / (1 - NU**2), rel=1e-14) and mu_s == pytest.approx(G, rel=1e-14)
    with pytest.raises(ValueError):
        lame(STEEL, "axisymmetric")


# -- cantilever ----------------------------------------------------------------------

L_B, C_B, P_B = 0.100, 0.005, 1000.0  # length, half-depth (h = 10 mm), end load (N per m thickness)
I_B = 2 * C_B**3 / 3  # second moment per unit thickness, m^4 / m


def tg_displacement(x, y):
    """Timoshenko & Goodier, Theory of Elasticity (1970), Art. 21: cantilever
    0 <= x <= l, |y| <= c, loaded at x = 0 by the shear traction
    tau = P (c^2 - y^2) / (2 I) (resultant P), built in at x = l with
    u = v = dv/dx = 0 at (l, 0). Exact plane-stress solution."""
    P, l, c, I = P_B, L_B, C_B, I_B
    u = (
        -P * x**2 * y / (2 * E * I)
        - NU * P * y**3 / (6 * E * I)
        + P * y**3 / (6 * I * G)
        + (P * l**2 / (2 * E * I) - P * c**2 / (2 * I * G)) * y
    )
    v = NU * P * x * y**2 / (2 * E * I) + P * x**3 / (6 * E * I) - P * l**2 * x / (2 * E * I) + P * l**3 / (3 * E * I)
    return u, v


@pytest.fixture(scope="module")
def beam_mesh():
    # 80 x 8 squares of 1.25 mm (2 triangles each); P2
    return skfem.MeshTri.init_tensor(np.linspace(0, L_B, 81), np.linspace(-C_B, C_B, 9))


def _end_traction(x, y):
    return np.stack([np.zeros_like(x), P_B / (2 * I_B) * (C_B**2 - y**2)])


def test_cantilever_exact_elasticity_solution(beam_mesh):
    """With T&G's exact displacements imposed on the built-in end and the parabolic
    shear on the free end, P2 reproduces the elasticity solution: the free-end
    deflection v(0, 0) = P l^3 / (3 E I) to 1e-5 (measured -5e-7; the field is cubic,
    so P2 is close but not exact)."""
    m = beam_mesh
    clamp = m.facets_satisfying(lambda x: np.isclose(x[0], L_B), boundaries_only=True)
    free_end = m.facets_satisfying(lambda x: np.isclose(x[0], 0.0), boundaries_only=True)
    model = assemble(m, STEEL, 1.0, clamp, plane="stress", order=2)
    F = traction_load(model, free_end, _end_traction)
    assert F[1::2].sum() == pytest.approx(P_B, rel=1e-12)
    x = model.basis.doflocs
    u_ex, v_ex = tg_displacement(x[0], x[1])
    U_ex = np.where(np.arange(model.ndofs) % 2 == 0, u_ex, v_ex)
    U = solve_with_prescribed(model, U_ex[model.fixed], F)
    tip = np.asarray(model.probe(np.array([[0.0, 0.0]])) @ U)
    assert tip[1] == pytest.approx(P_B * L_B**3 / (3 * E * I_B), rel=1e-5)
    assert np.max(np.abs(U - U_ex)) < 1e-5 * np.max(np.abs(U_ex))


def test_cantilever_full_clamp_vs_timoshenko_beam(beam_mesh):
    """Full clamp (u = v = 0 on x = l), parabolic shear P at x = 0. Compared: the
    centroid deflection at the loaded end against Timoshenko beam theory
    P l^3 / (3 E I) + P l / (kappa G A), kappa = 5/6, A = 2 c (unit thickness),
    within 1 % (measured -0.19 %); the shear term (0.78 % of the total) must show:
    the FE deflection exceeds pure bending P l^3 / (3 E I) (measured +0.58 %)."""
    m = beam_mesh
    clamp = m.facets_satisfying(lambda x: np.isclose(x[0], L_B), boundaries_only=True)
    free_end = m.facets_satisfying(lambda x: np.isclose(x[0], 0.0), boundaries_only=True)
    model = assemble(m, STEEL, 1.0, clamp, plane="stress", order=2)
    U = model.solve(traction_load(model, free_end, _end_traction))
    tip = float((model.probe(np.array([[0.0, 0.0]])) @ U)[1])
    bending = P_B * L_B**3 / (3 * E * I_B)
    timoshenko = bending + P_B * L_B / (5 / 6 * G * 2 * C_B)
    assert tip == pytest.approx(timoshenko, rel=0.01)
    assert tip > bending * 1.004


# -- symmetry ------------------------------------------------------------------------


def mirrored_mesh(seed=3):
    """Irregular mesh of [-L, L] x [0, H]: an irregular half mesh and its mirror
    image (x -> -x), joined on x = 0 (exactly mirror-symmetric)."""
    half = irregular_rectangle(0.01, 0.01, n=(5, 5), seed=seed)
    p, t = half.p, half.t
    on_axis = np.isclose(p[0], 0.0)
    mirror_index = np.arange(p.shape[1]) + p.shape[1]
    mirror_index[on_axis] = np.flatnonzero(on_axis)
    pm = np.hstack([p, p * np.array([[-1.0], [1.0]])])
    tm = np.hstack([t, mirror_index[t][[0, 2, 1]]])  # mirrored triangles, re-oriented CCW
    used = np.unique(tm)
    renum = np.full(pm.shape[1], -1)
    renum[used] = np.arange(used.size)
    m = skfem.MeshTri(pm[:, used], renum[tm], sort_t=False)
    _assert_ccw(m)
    return m


@pytest.mark.parametrize("order", [1, 2])
def test_mirror_symmetry_rectangle(order):
    """Mirror-symmetric body, clamped base, load symmetric about x = 0 (a pressure
    bump on the top edge): u_x(-x, y) = -u_x(x, y), u_y(-x, y) = u_y(x, y) to round-off."""
    m = mirrored_mesh()
    base = m.facets_satisfying(lambda x: np.isclose(x[1], 0.0), boundaries_only=True)
    top = m.facets_satisfying(lambda x: np.isclose(x[1], 0.01), boundaries_only=True)
    model = assemble(m, STEEL, 0.01, base, order=order)
    F = traction_load(model, top, lambda x, y: np.stack([2e6 * x / 0.01, -50e6 * np.exp(-((x / 0.004) ** 2))]))
    U = model.solve(F)
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(0.0005, 0.0095, 30), rng.uniform(0.0005, 0.0095, 30)])
    a = model.probe(pts) @ U
    b = model.probe(pts * np.array([-1.0, 1.0])) @ U
    scale = np.max(np.abs(a))
    assert scale > 0
    assert np.max(np.abs(a[0::2] + b[0::2])) < 1e-10 * scale
    assert np.max(np.abs(a[1::2] - b[1::2])) < 1e-10 * scale


def test_gear_tooth_radial_load_is_symmetric():
    """The real gear (all teeth, gmsh mesh, not mirror-symmetric) with a radial
    pressure on the tip land of tooth 0 (symmetric about the tooth axis, x = 0):
    the displacement field is mirror-symmetric to within the discretisation error
    (0.5 % of the largest displacement), and the axis points move radially."""
    from gearwear.fem.mesh import mesh_full_gear
    from gearwear.fem.tooth import gear_polygon, mesh_sizes
    from gearwear.geometry.profile import FILLET, INVOLUTE, ROOT_LAND, TIP_LAND, tooth_profile
    from gearwear.geometry.sampling import resample_profile
    from gearwear.geometry.spec import default_pair

    pair = default_pair()
    g = pair.gear(0)
    sizes = mesh_sizes(2.0)
    prof = tooth_profile(g, sag_m=1e-9)
    poly = resample_profile(
        prof,
        {ROOT_LAND: sizes.fillet_m, FILLET: sizes.fillet_m, INVOLUTE: sizes.load_m, TIP_LAND: sizes.load_m},
        midpoints=True,
    )
    other = resample_profile(
        prof, {r: 0.2 * sizes.global_m for r in (ROOT_LAND, FILLET, INVOLUTE, TIP_LAND)}, midpoints=True
    )
    outline = gear_polygon(poly, poly, other)  # vertex, edge mid-point, vertex, ...
    gm = mesh_full_gear(outline[0::2], g.hub_radius_m, sizes, order=2, outline_mid_xy=outline[1::2])
    mesh = gm.mesh
    model = assemble(gm.mesh, pair.materials[0], pair.face_width_m, gm.boundaries["bore"], order=2)
    # the FE runs on Gmsh's curved 6-node mesh itself: its P2 dofs sit on Gmsh's nodes
    assert np.array_equal(model.basis.doflocs[:, 0::2], gm.mesh.doflocs)
    mid = mesh.p[:, mesh.facets[:, gm.boundaries["outer"]]].mean(axis=1)
    # tip-land chords of tooth 0 (midpoints sag ~1 um below the tip circle)
    tip = gm.boundaries["outer"][(np.hypot(*mid) > g.tip_radius_m - 10e-6) & (np.abs(mid[0]) < 5e-3) & (mid[1] > 0)]
    assert tip.size >= 4

    def radial_pressure(x, y):
        r = np.hypot(x, y)
        return -20e6 * np.stack([x / r, y / r])

    U = model.solve(traction_load(model, tip, radial_pressure))
    ys = np.linspace(g.root_radius_m - 10e-3, g.tip_radius_m - 0.5e-3, 12)
    pts = np.vstack([np.column_stack([np.full_like(ys, dx), ys]) for dx in (0.6e-3, 1.2e-3)])
    a = model.probe(pts) @ U
    b = model.probe(pts * np.array([-1.0, 1.0])) @ U
    scale = np.max(np.abs(a))
    assert np.max(np.abs(a[0::2] + b[0::2])) < 5e-3 * scale
    assert np.max(np.abs(a[1::2] - b[1::2])) < 5e-3 * scale
    axis = model.probe(np.column_stack([np.zeros_like(ys), ys])) @ U
    assert np.max(np.abs(axis[0::2])) < 5e-3 * np.max(np.abs(axis[1::2]))
    assert np.all(axis[1::2] < 0)  # pushed toward the centre


# -- probes -------------------------------------------------------------------------


@pytest.mark.parametrize("order", [1, 2])
def test_probe_interleaves_components(order):
    """P @ U = [ux0, uy0, ux1, uy1, ...] for a field the element represents exactly."""
    m = irregular_rectangle(seed=11)
    model = assemble(m, STEEL, 0.01, m.boundary_facets(), order=order)
    x = model.basis.doflocs
    U = np.where(np.arange(model.ndofs) % 2 == 0, 1 + 2 * x[0] - 3 * x[1], -4 + 5 * x[0] + 7 * x[1])
    pts = np.array([[0.003, 0.004], [0.017, 0.002], [0.011, 0.0093]])
    got = model.probe(pts) @ U
    want = np.column_stack([1 + 2 * pts[:, 0] - 3 * pts[:, 1], -4 + 5 * pts[:, 0] + 7 * pts[:, 1]]).ravel()
    assert np.allclose(got, want, rtol=0, atol=1e-13)


def test_solve_many_right_hand_sides_matches_single():
    m = irregular_rectangle(seed=5)
    left = m.facets_satisfying(lambda x: np.isclose(x[0], 0.0), boundaries_only=True)
    model = assemble(m, STEEL, 0.01, left, order=2)
    rng = np.random.default_rng(2)
    F = rng.normal(size=(model.ndofs, 3))
    Um = model.solve(F)
    for k in range(3):
        assert np.allclose(Um[:, k], model.solve(F[:, k]), rtol=1e-12, atol=0)
    assert np.all(Um[model.fixed] == 0)
    r = model.K @ Um[:, 0] - F[:, 0]
    assert np.max(np.abs(r[model.free])) < 1e-8 * np.max(np.abs(F))


# -- isoparametric P2 on Gmsh's curved 6-node mesh ------------------------------------

R_DISC, R_BORE, N_DISC = 0.010, 0.004, 48


@pytest.fixture(scope="module")
def curved_disc():
    """A disc with a bore, its outer circle given as N_DISC points plus the exact
    circle point at the middle of every edge (Gmsh meshes each edge as the parabola
    through the three), mesh size 1.5 mm (> the 1.3 mm edges, so none is split):
    curved 6-node triangles."""
    from gearwear.fem.mesh import MeshSizes, mesh_full_gear

    th = np.linspace(0.0, 2 * np.pi, N_DISC, endpoint=False)
    mid = th + np.pi / N_DISC
    gm = mesh_full_gear(
        R_DISC * np.column_stack([np.cos(th), np.sin(th)]),
        R_BORE,
        MeshSizes(global_m=1.5e-3),
        outline_mid_xy=R_DISC * np.column_stack([np.cos(mid), np.sin(mid)]),
    )
    assert isinstance(gm.mesh, skfem.MeshTri2)
    return gm


def _linear_field(x, plane):
    sig = (120e6, -45e6, 35e6)
    exx, eyy, gxy = compliance_strains(*sig, plane)
    ux = exx * x[0] + 0.5 * gxy * x[1] + 1e-5 - 2e-4 * x[1]
    uy = 0.5 * gxy * x[0] + eyy * x[1] - 3e-5 + 2e-4 * x[0]
    return sig, ux, uy


def test_curved_mesh_mid_side_nodes_are_on_the_circle(curved_disc):
    """Gmsh's mid-side nodes on the outer boundary are the given circle points, where
    a straight edge's mid-point sags by R (1 - cos(pi / 48)) = 21 um; the mesh fills
    the region of the parabolic edges: polygon + 48 x (2/3) chord x sag."""
    m = curved_disc.mesh
    f = curved_disc.boundaries["outer"]
    assert len(f) == N_DISC
    mids = m.doflocs[:, m.nvertices + f]
    sag = R_DISC * (1 - np.cos(np.pi / N_DISC))
    assert np.max(np.abs(np.hypot(*mids) - R_DISC)) < 1e-12 * R_DISC
    chord = m.p[:, m.facets[:, f]].mean(axis=1)
    assert np.allclose(R_DISC - np.hypot(*chord), sag, rtol=1e-9)  # the chord centres are not the nodes
    polygon = 0.5 * N_DISC * R_DISC**2 * np.sin(2 * np.pi / N_DISC)
    bulges = N_DISC * 2 / 3 * (2 * R_DISC * np.sin(np.pi / N_DISC)) * sag
    exact = polygon + bulges - np.pi * R_BORE**2
    assert curved_disc.exact_area_m2 == pytest.approx(exact, rel=1e-12)
    assert curved_disc.area_m2 == pytest.approx(exact, rel=1e-8)  # the bore's P2 chords: 1e-8 by design


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_isoparametric_displacement_patch_test(curved_disc, plane):
    """Irons' patch test on the curved mesh: a linear displacement (uniform stress +
    rigid motion) imposed on every boundary node, corner and mid-side, is reproduced
    at every interior node to round-off, and the stress is uniform at every
    quadrature point (isoparametric elements contain the linear fields exactly)."""
    m = curved_disc.mesh
    model = assemble(m, STEEL, 0.01, m.boundary_facets(), plane=plane, order=2)
    sig, ux, uy = _linear_field(model.basis.doflocs, plane)
    U_exact = np.where(np.arange(model.ndofs) % 2 == 0, ux, uy)
    U = solve_with_prescribed(model, U_exact[model.fixed])
    assert model.free.size > 100
    assert np.max(np.abs(U - U_exact)) <= 1e-10 * np.max(np.abs(U_exact))
    got = stresses_at_quadrature(model, U)
    for g, want in zip(got, sig):
        assert np.max(np.abs(g - want)) <= 1e-9 * max(abs(s) for s in sig)


def test_isoparametric_traction_patch_test_on_the_curved_boundary(curved_disc):
    """The same uniform stress sigma carried by the traction sigma n on the curved
    outer boundary (n the normal of the curved element edges), the exact linear
    displacement prescribed on the bore only: the FE solution is that field at every
    node to round-off (consistent load on the curved edges, exact quadrature of the
    isoparametric P2 stiffness for a linear field)."""
    from skfem import FacetBasis, LinearForm

    m = curved_disc.mesh
    plane = "stress"
    model = assemble(m, STEEL, 0.01, curved_disc.boundaries["bore"], plane=plane, order=2)
    sig, ux, uy = _linear_field(model.basis.doflocs, plane)
    S = np.array([[sig[0], sig[2]], [sig[2], sig[1]]])
    fb = FacetBasis(m, model.basis.elem, facets=curved_disc.boundaries["outer"], intorder=8)

    @LinearForm
    def traction(v, w):
        t = np.einsum("ij,j...->i...", S, w.n)
        return t[0] * v[0] + t[1] * v[1]

    F = traction.assemble(fb) * model.thickness_m
    U_exact = np.where(np.arange(model.ndofs) % 2 == 0, ux, uy)
    U = solve_with_prescribed(model, U_exact[model.fixed], F)
    assert np.max(np.abs(U - U_exact)) <= 1e-9 * np.max(np.abs(U_exact))


def test_probe_finds_points_in_the_curved_boundary_elements(curved_disc):
    """Points between a boundary edge's chord and the circle lie outside every corner
    triangle but inside the curved elements: the probe finds them and interpolates a
    linear field exactly; a point outside the disc is rejected."""
    m = curved_disc.mesh
    model = assemble(m, STEEL, 0.01, curved_disc.boundaries["bore"], order=2)
    x = model.basis.doflocs
    U = np.where(np.arange(model.ndofs) % 2 == 0, 1 + 2e3 * x[0] - 3e3 * x[1], -4 + 5e3 * x[0] + 7e3 * x[1])
    ang = np.linspace(0.01, 2 * np.pi - 0.01, 40)
    r = R_DISC - 0.2 * R_DISC * (1 - np.cos(np.pi / 24))  # inside the circle, outside most chords
    pts = r * np.column_stack([np.cos(ang), np.sin(ang)])
    got = model.probe(pts) @ U
    want = np.column_stack([1 + 2e3 * pts[:, 0] - 3e3 * pts[:, 1], -4 + 5e3 * pts[:, 0] + 7e3 * pts[:, 1]]).ravel()
    assert np.allclose(got, want, rtol=0, atol=1e-11)
    with pytest.raises(ValueError, match="outside"):
        model.probe(np.array([[R_DISC * 1.001, 0.0]]))


def test_plain_skfem_quadratic_mesh_can_be_probed():
    """A MeshTri2 from skfem itself (no Gmsh) is assembled as it is and probed."""
    m = skfem.MeshTri2.init_circle(2)
    model = assemble(m, STEEL, 0.01, m.boundary_facets(), order=2)
    x = model.basis.doflocs
    U = np.where(np.arange(model.ndofs) % 2 == 0, 2 * x[0] + x[1], x[0] - x[1])
    got = model.probe(np.array([[0.3, -0.2], [0.0, 0.99]])) @ U
    assert np.allclose(got, [0.4, 0.5, 0.99, -0.99], rtol=0, atol=1e-13)
