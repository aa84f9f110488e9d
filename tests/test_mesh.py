"""Tests for geometry.mesh (gmsh -> scikit-fem meshing of gear bodies).

Reference values are computed here independently of the module: polygon
areas by the shoelace formula, circle areas/lengths analytically, boundary
lengths by skfem facet quadrature, quality thresholds chosen a priori.
"""

from __future__ import annotations

import math
import os

import gmsh
import meshio
import numpy as np
import pytest
import skfem
from hypothesis import given, settings
from hypothesis import strategies as st
from skfem import BilinearForm, CellBasis, ElementTriP2, FacetBasis, Functional, condense, solve
from skfem.helpers import dot, grad

from gearwear.core.validation import InputError
from gearwear.fem.mesh import (
    GearMesh,
    MeshError,
    MeshInputError,
    MeshSizes,
    mesh_full_gear,
    mesh_sector,
    triangle_quality,
    write_mesh,
)

Q_MIN = 0.3  # a-priori acceptance threshold for the normalised radius ratio

# --------------------------------------------------------------------------
# synthetic geometry (independent of geometry/profile.py)
# --------------------------------------------------------------------------

Z, R_TIP, R_ROOT, R_HUB = 30, 0.080, 0.06875, 0.040


def gear_polar(z=Z, r_tip=R_TIP, r_root=R_ROOT, per_tooth=40):
    """Trapezoidal-tooth star: polar angles and radii of the polygon vertices.

    Per pitch: root land 30 %, rising flank 15 %, tip land 30 %, falling
    flank 25 %; ``per_tooth`` vertices per tooth, counter-clockwise.
    """
    pitch = 2 * np.pi / z
    n4 = per_tooth // 4
    th, rr = [], []
    for k in range(z):
        b = k * pitch
        for f in np.linspace(0, 1, n4, endpoint=False):
            th.append(b + 0.30 * f * pitch)
            rr.append(r_root)
        for f in np.linspace(0, 1, n4, endpoint=False):
            th.append(b + (0.30 + 0.15 * f) * pitch)
            rr.append(r_root + (r_tip - r_root) * f)
        for f in np.linspace(0, 1, n4, endpoint=False):
            th.append(b + (0.45 + 0.30 * f) * pitch)
            rr.append(r_tip)
        for f in np.linspace(0, 1, n4, endpoint=False):
            th.append(b + (0.75 + 0.25 * f) * pitch)
            rr.append(r_tip + (r_root - r_tip) * f)
    return np.array(th), np.array(rr)


def to_xy(th, rr):
    return np.c_[rr * np.cos(th), rr * np.sin(th)]


def shoelace(p):
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def fillet_points(z=Z, r_root=R_ROOT):
    """Both root/flank corners of every tooth space."""
    pitch = 2 * np.pi / z
    ang = np.array([k * pitch + f * pitch for k in range(z) for f in (0.30, 1.0)])
    return np.c_[r_root * np.cos(ang), r_root * np.sin(ang)]


def load_point(z=Z):
    th, rr = gear_polar(z=z)
    return to_xy(th, rr)[15]  # a vertex half-way up the first rising flank


def corner_xy(m):
    return m.p[:, m.t[:3]]  # (2, 3, nel)


def signed_corner_area(m):
    v = corner_xy(m)
    a = v[:, 1] - v[:, 0]
    b = v[:, 2] - v[:, 0]
    return 0.5 * (a[0] * b[1] - a[1] * b[0])


def mean_edge_length(m):
    v = corner_xy(m)
    e = [np.linalg.norm(v[:, i] - v[:, (i + 1) % 3], axis=0) for i in range(3)]
    return (e[0] + e[1] + e[2]) / 3


def skfem_area(m):
    basis = CellBasis(m, ElementTriP2(), intorder=4)
    return Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(basis)


def facet_length(m, facets):
    fb = FacetBasis(m, ElementTriP2(), facets=facets, intorder=4)
    return Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(fb)


FULL_SIZES = MeshSizes(global_m=3e-3, fillet_m=0.5e-3, load_m=0.2e-3)


@pytest.fixture(scope="module")
def full_gear():
    """The 30-tooth module-5 gear at production sizes (its meshing time is a benchmark:
    benchmarks/bench_fem_targets.py)."""
    outline = to_xy(*gear_polar())
    gm = mesh_full_gear(
        outline,
        R_HUB,
        FULL_SIZES,
        refine_points_xy=load_point(),
        fillet_points_xy=fillet_points(),
    )
    return outline, gm, None


@pytest.fixture(scope="module")
def small_gear_input():
    th, rr = gear_polar(z=12, r_tip=0.040, r_root=0.034, per_tooth=24)
    return to_xy(th, rr), 0.015, MeshSizes(global_m=3e-3, load_m=0.5e-3)


# --------------------------------------------------------------------------
# full gear at production sizes
# --------------------------------------------------------------------------


def test_full_gear_is_a_quadratic_mesh(full_gear):
    outline, gm, _ = full_gear
    print(
        f"\n[mesh] full 30-tooth gear: {gm.n_elements} P2 triangles, "
        f"{gm.mesh.doflocs.shape[1]} nodes, area rel error {gm.area_rel_error:.2e}"
    )
    assert isinstance(gm, GearMesh)
    assert isinstance(gm.mesh, skfem.MeshTri2)
    assert gm.n_elements > 0


def test_full_gear_orientation_and_quality(full_gear):
    _, gm, _ = full_gear
    assert np.all(signed_corner_area(gm.mesh) > 0)
    q = triangle_quality(gm.mesh)
    assert q.shape == (gm.n_elements,)
    assert np.all(q <= 1 + 1e-12)
    assert q.min() > Q_MIN


def test_full_gear_area_exact(full_gear):
    outline, gm, _ = full_gear
    exact = shoelace(outline) - math.pi * R_HUB**2
    assert gm.area_m2 == pytest.approx(exact, rel=1e-6)
    assert gm.exact_area_m2 == pytest.approx(exact, rel=1e-12)
    # skfem's own isoparametric quadrature agrees
    assert skfem_area(gm.mesh) == pytest.approx(exact, rel=1e-6)


def test_full_gear_boundaries(full_gear):
    outline, gm, _ = full_gear
    m = gm.mesh
    assert set(gm.boundaries) >= {"bore", "outer"}
    bf = set(m.boundary_facets().tolist())
    allb = np.concatenate([gm.boundaries["bore"], gm.boundaries["outer"]])
    assert len(allb) == len(bf) and set(allb.tolist()) == bf  # partition of the boundary
    for name, f in gm.boundaries.items():
        assert f.size > 0
        np.testing.assert_array_equal(m.boundaries[name], f)
    # bore facets: both vertices on the hub circle
    rb = np.hypot(*m.p[:, m.facets[:, gm.boundaries["bore"]]])
    np.testing.assert_allclose(rb, R_HUB, rtol=1e-9)
    # outer facets: vertices at least at root radius, and on the polygon
    ro = np.hypot(*m.p[:, m.facets[:, gm.boundaries["outer"]]])
    assert ro.min() > R_ROOT * (1 - 1e-9) and ro.max() < R_TIP * (1 + 1e-9)
    # curved-bore length (P2 mapping) = 2 pi r; outer length = polygon perimeter
    assert facet_length(m, gm.boundaries["bore"]) == pytest.approx(2 * math.pi * R_HUB, rel=1e-6)
    perim = float(np.sum(np.linalg.norm(np.roll(outline, -1, 0) - outline, axis=1)))
    assert facet_length(m, gm.boundaries["outer"]) == pytest.approx(perim, rel=1e-10)


def test_refinement_near_points(full_gear):
    _, gm, _ = full_gear
    m = gm.mesh
    c = m.p[:, m.t[:3]].mean(axis=1).T
    h = mean_edge_length(m)
    d_load = np.linalg.norm(c - load_point(), axis=1)
    d_fil = np.min(np.linalg.norm(c[:, None, :] - fillet_points()[None], axis=2), axis=1)
    near_load = h[d_load < 0.5e-3]
    near_fil = h[d_fil < 1.0e-3]
    far = h[(d_load > 30e-3) & (d_fil > 15e-3)]
    assert near_load.size and near_fil.size and far.size
    assert np.median(near_load) < 2 * FULL_SIZES.load_m
    assert np.median(near_fil) < 2 * FULL_SIZES.fillet_m
    assert np.median(far) > 0.5 * FULL_SIZES.global_m
    assert np.median(near_load) < np.median(near_fil) < np.median(far)


# --------------------------------------------------------------------------
# simple shapes with known areas
# --------------------------------------------------------------------------


def test_square_with_bore_area_and_laplace():
    a, r = 0.05, 0.02
    sq = np.array([[-a, -a], [a, -a], [a, a], [-a, a]])
    gm = mesh_full_gear(sq, r, MeshSizes(global_m=5e-3))
    exact = (2 * a) ** 2 - math.pi * r**2
    assert gm.area_m2 == pytest.approx(exact, rel=1e-6)
    assert skfem_area(gm.mesh) == pytest.approx(exact, rel=1e-6)
    assert np.all(signed_corner_area(gm.mesh) > 0)
    assert triangle_quality(gm).min() > Q_MIN
    # P2 Laplace solve reproduces a linear field exactly (it lies in the
    # isoparametric space) -> mesh, DOF ordering and orientation are usable
    m = gm.mesh
    basis = CellBasis(m, ElementTriP2())
    K = BilinearForm(lambda u, v, w: dot(grad(u), grad(v))).assemble(basis)
    exact_u = basis.project(lambda x: 1.0 + 2.0 * x[0] - 3.0 * x[1])
    D = basis.get_dofs().all()
    u = solve(*condense(K, np.zeros(K.shape[0]), x=exact_u, D=D))
    np.testing.assert_allclose(u, exact_u, atol=1e-10)


def test_order1_mesh():
    a, r = 0.05, 0.02
    sq = np.array([[-a, -a], [a, -a], [a, a], [-a, a]])
    gm = mesh_full_gear(sq, r, MeshSizes(global_m=5e-3), order=1)
    m = gm.mesh
    assert type(m) is skfem.MeshTri1
    assert m.t.shape[0] == 3
    assert np.all(signed_corner_area(m) > 0)
    # polygonal bore: area = square minus the polygon through the bore nodes
    e = m.facets[:, gm.boundaries["bore"]]
    pa, pb = m.p[:, e[0]], m.p[:, e[1]]
    chord_tri = 0.5 * np.abs(pa[0] * pb[1] - pa[1] * pb[0])
    assert gm.area_m2 == pytest.approx((2 * a) ** 2 - chord_tri.sum(), rel=1e-10)
    assert float(np.sum(signed_corner_area(m))) == pytest.approx(gm.area_m2, rel=1e-12)


@settings(max_examples=12, deadline=None)
@given(
    n=st.integers(min_value=5, max_value=40),
    seed=st.integers(min_value=0, max_value=2**31 - 1),
    r_hub=st.floats(min_value=0.005, max_value=0.07),
)
def test_random_star_polygons(n, seed, r_hub):
    rng = np.random.default_rng(seed)
    th = np.sort(rng.uniform(0, 2 * np.pi, n))
    th = th[np.diff(np.r_[th, th[0] + 2 * np.pi]) > 0.15]  # no needle spikes
    if th.size < 3 or np.max(np.diff(np.r_[th, th[0] + 2 * np.pi])) > 2.5:
        return  # not star-shaped around the origin with margin
    rr = rng.uniform(0.07, 0.1, th.size)
    poly = to_xy(th, rr)
    # distance from the origin to the closest point of any edge
    a, b = poly, np.roll(poly, -1, 0)
    t = np.clip(np.einsum("ij,ij->i", -a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
    d = float(np.min(np.linalg.norm(a + t[:, None] * (b - a), axis=1)))
    if r_hub >= d:
        with pytest.raises(MeshError, match="not strictly inside"):
            mesh_full_gear(poly, r_hub, MeshSizes(global_m=8e-3))
        return
    if r_hub > 0.8 * d:
        return  # legal, but a gap below the element size may be rejected
    gm = mesh_full_gear(poly, r_hub, MeshSizes(global_m=8e-3))
    assert gm.area_m2 == pytest.approx(shoelace(poly) - math.pi * r_hub**2, rel=1e-6)
    assert np.all(signed_corner_area(gm.mesh) > 0)


# --------------------------------------------------------------------------
# sector
# --------------------------------------------------------------------------


def test_sector_area_boundaries_orientation():
    th, rr = gear_polar()
    # from the 3rd root-land vertex of tooth 1 to the same vertex of tooth 4
    i0, i1 = 40 + 2, 4 * 40 + 2
    poly = to_xy(th, rr)[i0 : i1 + 1]
    a0, a1 = th[i0], th[i1]
    sizes = MeshSizes(global_m=3e-3, fillet_m=0.5e-3)
    gm = mesh_sector(poly, R_HUB, a0, a1, sizes, fillet_points_xy=fillet_points())
    m = gm.mesh
    assert isinstance(m, skfem.MeshTri2)
    # P0 and Pn lie on the cut rays, so the polygon [O, P0..Pn] has the cuts
    # as edges: region = that polygon minus the hub's circular sector
    closed = np.vstack([[0.0, 0.0], poly])
    exact = shoelace(closed) - 0.5 * R_HUB**2 * (a1 - a0)
    assert gm.area_m2 == pytest.approx(exact, rel=1e-6)
    assert skfem_area(m) == pytest.approx(exact, rel=1e-6)
    assert np.all(signed_corner_area(m) > 0)
    assert triangle_quality(m).min() > Q_MIN
    assert set(gm.boundaries) >= {"hub_arc", "outer", "cut_left", "cut_right"}
    for name, f in gm.boundaries.items():
        assert f.size > 0, name
    p = lambda name: m.p[:, m.facets[:, gm.boundaries[name]]]  # noqa: E731
    np.testing.assert_allclose(np.hypot(*p("hub_arc")), R_HUB, rtol=1e-9)
    for name, ang in (("cut_right", a0), ("cut_left", a1)):
        q = p(name)
        np.testing.assert_allclose(np.arctan2(q[1], q[0]), ang, atol=1e-9)
        rq = np.hypot(*q)
        assert rq.min() == pytest.approx(R_HUB, rel=1e-9)
        assert rq.max() == pytest.approx(R_ROOT, rel=1e-9)
    assert facet_length(m, gm.boundaries["hub_arc"]) == pytest.approx(R_HUB * (a1 - a0), rel=1e-6)
    assert facet_length(m, gm.boundaries["cut_left"]) == pytest.approx(R_ROOT - R_HUB, rel=1e-10)


def test_sector_errors():
    th, rr = gear_polar()
    poly = to_xy(th, rr)[42:163]
    a0, a1 = th[42], th[162]
    s = MeshSizes(global_m=3e-3)
    with pytest.raises(MeshError, match="out of order"):
        mesh_sector(poly, R_HUB, a1, a0, s)
    with pytest.raises(MeshError, match="not on the ray"):
        mesh_sector(poly, R_HUB, a0 + 0.01, a1, s)
    with pytest.raises(MeshError, match="hub_radius_m"):
        mesh_sector(poly, R_ROOT, a0, a1, s)


# --------------------------------------------------------------------------
# determinism and gmsh session handling
# --------------------------------------------------------------------------


def test_deterministic_and_repeatable(small_gear_input):
    outline, r, sizes = small_gear_input
    lp = outline[5]
    g1 = mesh_full_gear(outline, r, sizes, refine_points_xy=lp)
    g2 = mesh_full_gear(outline, r, sizes, refine_points_xy=lp)
    assert np.array_equal(g1.mesh.doflocs, g2.mesh.doflocs)
    assert np.array_equal(g1.mesh.t, g2.mesh.t)
    for k in g1.boundaries:
        assert np.array_equal(g1.boundaries[k], g2.boundaries[k])
    assert not gmsh.isInitialized()


def test_exception_inside_meshing_finalises(small_gear_input, monkeypatch):
    outline, r, sizes = small_gear_input

    def boom(*a, **k):
        raise RuntimeError("synthetic failure\nsecond line")

    monkeypatch.setattr(gmsh.model.mesh, "generate", boom)
    with pytest.raises(MeshError, match="synthetic failure") as ei:
        mesh_full_gear(outline, r, sizes)
    assert "\n" not in str(ei.value)
    assert not isinstance(ei.value, InputError)  # a Gmsh failure is ours, not the input's
    assert not gmsh.isInitialized()
    monkeypatch.undo()
    assert mesh_full_gear(outline, r, sizes).n_elements > 0  # still usable
    assert not gmsh.isInitialized()


def test_caller_gmsh_session_untouched(small_gear_input):
    outline, r, sizes = small_gear_input
    ref = mesh_full_gear(outline, r, sizes)
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("callers_model")
        gmsh.option.setNumber("Mesh.Algorithm", 5)
        gm = mesh_full_gear(outline, r, sizes)
        assert gmsh.isInitialized()
        assert gmsh.model.getCurrent() == "callers_model"
        assert gmsh.option.getNumber("Mesh.Algorithm") == 5
        assert "callers_model" in gmsh.model.list()
        assert len(gmsh.model.list()) == 2  # default "" + theirs; ours removed
        assert np.array_equal(gm.mesh.doflocs, ref.mesh.doflocs)
    finally:
        gmsh.finalize()


# --------------------------------------------------------------------------
# invalid input
# --------------------------------------------------------------------------


def test_invalid_geometry_errors():
    s = MeshSizes(global_m=5e-3)
    sq = np.array([[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, 0.05]])
    bowtie = np.array([[-0.05, -0.05], [0.05, 0.05], [0.05, -0.05], [-0.05, 0.05]])
    with pytest.raises(MeshInputError, match="self-intersecting"):
        mesh_full_gear(bowtie, 0.01, s)
    with pytest.raises(MeshInputError, match="counter-clockwise"):
        mesh_full_gear(sq[::-1], 0.01, s)
    with pytest.raises(MeshInputError, match=r"hub_radius_m=0\.05 is not strictly inside"):
        mesh_full_gear(sq, 0.05, s)
    with pytest.raises(MeshInputError, match="hub_radius_m"):
        mesh_full_gear(sq, -1.0, s)
    with pytest.raises(MeshInputError, match="duplicate"):
        mesh_full_gear(np.vstack([sq, sq[:1]]), 0.01, s)
    with pytest.raises(MeshInputError, match="shape"):
        mesh_full_gear(sq[:, :1], 0.01, s)
    with pytest.raises(MeshInputError, match="enclose the origin"):
        mesh_full_gear(sq + 0.2, 0.01, s)
    with pytest.raises(MeshInputError, match="fillet_m is None"):
        mesh_full_gear(sq, 0.01, s, fillet_points_xy=[[0.03, 0.0]])
    with pytest.raises(MeshInputError, match="global_m"):
        MeshSizes(global_m=-1.0)
    with pytest.raises(MeshInputError, match="larger than global_m"):
        MeshSizes(global_m=1e-3, load_m=2e-3)
    # toothed outline with one tooth tip folded across its neighbour
    th, rr = gear_polar(z=12, r_tip=0.040, r_root=0.034, per_tooth=24)
    bad = to_xy(th, rr)
    bad[8] = bad[20] * 1.0001
    with pytest.raises(MeshInputError, match="self-intersecting"):
        mesh_full_gear(bad, 0.015, s)
    assert issubclass(MeshError, ValueError)
    # an impossible input is the caller's error, through the contract (exit 2 in the CLI)
    assert issubclass(MeshInputError, InputError) and issubclass(MeshInputError, MeshError)
    assert not gmsh.isInitialized()


def test_curved_outline_edges():
    """Square with its top edge bulged into the parabola y = a + c (1 - x^2 / a^2)
    (given by its mid-point (0, a + c)): exact area (2 a)^2 + (2/3)(2 a) c - pi r^2,
    every node Gmsh puts on that edge on the parabola with one at its apex, its
    length the parabola's arc length; the sector takes curved edges too. Bad
    mid-points are rejected."""
    a, r, c = 0.05, 0.02, 0.01
    sq = np.array([[-a, -a], [a, -a], [a, a], [-a, a]])
    mids = np.full((4, 2), np.nan)
    mids[2] = [0.0, a + c]
    gm = mesh_full_gear(sq, r, MeshSizes(global_m=8e-3), outline_mid_xy=mids)
    exact = (2 * a) ** 2 + 2 / 3 * 2 * a * c - math.pi * r**2
    assert gm.exact_area_m2 == pytest.approx(exact, rel=1e-14)
    assert gm.area_m2 == pytest.approx(exact, rel=1e-6) and skfem_area(gm.mesh) == pytest.approx(exact, rel=1e-6)
    m = gm.mesh
    top = np.array([f for f in gm.boundaries["outer"] if np.all(m.p[1, m.facets[:, f]] > a - 1e-12)])
    nodes = np.hstack([m.p[:, m.facets[:, top].ravel()], m.doflocs[:, m.nvertices + top]])
    assert len(top) > 5 and np.allclose(nodes[1], a + c * (1 - nodes[0] ** 2 / a**2), rtol=0, atol=1e-15)
    assert np.min(np.hypot(nodes[0], nodes[1] - a - c)) < 1e-8  # by symmetry, to gmsh's arc-length integration
    # arc length of the parabola: int sqrt(1 + (2 c x / a^2)^2) dx over [-a, a]
    k = 2 * c / a**2
    L = a * math.sqrt(1 + (k * a) ** 2) + math.asinh(k * a) / k
    assert facet_length(m, top) == pytest.approx(L, rel=1e-7)
    # sector: the upper half of the square's outline, its top edge curved
    line = np.array([[a, 0.0], [a, a], [-a, a], [-a, 0.0]])
    gs = mesh_sector(line, r, 0.0, math.pi, MeshSizes(global_m=8e-3), outline_mid_xy=mids[1:4])
    assert gs.area_m2 == pytest.approx(2 * a * a + 2 / 3 * 2 * a * c - 0.5 * math.pi * r**2, rel=1e-6)
    s = MeshSizes(global_m=5e-3)
    with pytest.raises(MeshError, match="order 2"):
        mesh_full_gear(sq, r, s, order=1, outline_mid_xy=mids)
    with pytest.raises(MeshError, match="shape"):
        mesh_full_gear(sq, r, s, outline_mid_xy=mids[:3])
    far = mids.copy()
    far[2] = [0.0, a + 0.03]
    with pytest.raises(MeshError, match="quarter"):
        mesh_full_gear(sq, r, s, outline_mid_xy=far)
    half = mids.copy()
    half[0] = [0.0, np.nan]
    with pytest.raises(MeshError, match="two NaNs"):
        mesh_full_gear(sq, r, s, outline_mid_xy=half)


# --------------------------------------------------------------------------
# output
# --------------------------------------------------------------------------


def test_write_mesh_roundtrip(tmp_path, small_gear_input):
    outline, r, sizes = small_gear_input
    gm = mesh_full_gear(outline, r, sizes)
    pm, pv = tmp_path / "g.msh", tmp_path / "g.vtu"
    write_mesh(gm, str(pm), str(pv))
    assert sorted(os.listdir(tmp_path)) == ["g.msh", "g.vtu"]  # no temp leftovers
    for path in (pm, pv):
        mm = meshio.read(path)
        tri = mm.get_cells_type("triangle6")
        assert tri.shape == (gm.n_elements, 6)
        np.testing.assert_allclose(mm.points[:, :2], gm.mesh.doflocs.T)
        # re-imported P2 geometry has the same area (orientation + node order kept)
        m2 = skfem.MeshTri2(np.ascontiguousarray(mm.points[:, :2].T), np.ascontiguousarray(tri.T))
        assert skfem_area(m2) == pytest.approx(gm.area_m2, rel=1e-12)
    mm = meshio.read(pm)
    assert {"bore", "outer"} <= set(mm.field_data)
    assert mm.get_cells_type("line3").shape[0] == sum(v.size for v in gm.boundaries.values())
