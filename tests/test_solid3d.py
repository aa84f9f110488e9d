"""fem.solid3d: the 3D elasticity against independent truths, and one coarse tooth.

A prismatic cantilever (length L along x, height h along y, width b along z), clamped
at x = 0, a uniform shear traction on the end face x = L (resultant w per unit width),
deflection = u_y of the centre line (L, h/2) averaged over the width:

* thin (b = h/5): Timoshenko beam theory, P L^3 / (3 E I) + P L / (kappa G A), kappa
  = 5/6 (the clamp's warping restraint and the load's spreading are O((h/L)^2) of it);
  and the 2D plane-stress FE of the same section.
* wide (b = 20 h): at the mid-plane eps_zz -> 0, so the mid-plane deflection is the
  2D plane-strain one; the width average lies between plane strain and plane stress.
* the bending compliance of plane strain is (1 - nu^2) times that of plane stress (E' =
  E / (1 - nu^2)).
"""

import numpy as np
import pytest
import skfem
from skfem import ElementTetP2, FacetBasis, LinearForm, asm

from gearwear.fem.elasticity import assemble, traction_load
from gearwear.fem.solid3d import face_planes, plane_check, rigid_body_modes, solid_stiffness, solve_spd, z_rule
from gearwear.geometry.spec import Material, default_pair

E, NU = 206e9, 0.3
MAT = Material(E, NU, 7850.0)
H = 0.01  # m, the beam's height (y)
NY = 4


def cantilever(length_m: float, nx: int, planes: np.ndarray) -> dict:
    """Centre-line tip deflection per unit line load (m^2/N): 3D half model (u_z = 0 at
    z = 0, free end face at z = planes[-1]) averaged over the width ("avg") and at the
    mid-plane ("mid"), and 2D plane stress / plane strain on the z = 0 face of the same
    tetrahedral mesh (the same triangles)."""
    mesh = skfem.MeshTet.init_tensor(np.linspace(0, length_m, nx + 1), np.linspace(0, H, NY + 1), planes)
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    K, sb = solid_stiffness(mesh, lam, mu)
    clamp = sb.get_dofs(lambda x: np.isclose(x[0], 0.0)).all()
    sym = sb.get_dofs(lambda x: np.isclose(x[2], 0.0)).all()
    fixed = np.union1d((3 * clamp[:, None] + np.arange(3)).ravel(), 3 * sym + 2)
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    fb = FacetBasis(mesh, ElementTetP2(), facets=mesh.facets_satisfying(lambda x: np.isclose(x[0], length_m)))
    F = np.zeros(K.shape[0])
    F[1::3] = asm(LinearForm(lambda v, w: v / H), fb)  # 1 N/m along z, spread over the end face
    U = np.zeros_like(F)
    U[free] = solve_spd(K[free][:, free].tocsr(), F[free, None], rigid_body_modes(sb.doflocs)[free])[:, 0]
    zs, ws = z_rule(planes)
    line = np.vstack([np.full(len(zs) + 1, length_m), np.full(len(zs) + 1, H / 2), np.concatenate([[0.0], zs])])
    uy = sb.probes(line).tocsr() @ U[1::3]
    out = {"avg": float(uy[1:] @ ws) / planes[-1], "mid": float(uy[0])}
    bottom = mesh.facets[:, mesh.facets_satisfying(lambda x: np.isclose(x[2], 0.0))]
    used = np.unique(bottom)
    new = np.full(mesh.p.shape[1], -1)
    new[used] = np.arange(len(used))
    sec = skfem.MeshTri(mesh.p[:2, used], new[bottom])
    for plane in ("stress", "strain"):
        model = assemble(sec, MAT, 1.0, sec.facets_satisfying(lambda x: np.isclose(x[0], 0.0)), plane=plane, order=2)
        F2 = traction_load(
            model,
            sec.facets_satisfying(lambda x: np.isclose(x[0], length_m)),
            lambda x, y: np.stack([0.0 * x, 0.0 * x + 1.0 / H]),
        )
        out[plane] = float((model.probe(np.array([[length_m, H / 2]])) @ model.solve(F2))[1])
    return out


@pytest.fixture(scope="module")
def slender():
    """L / h = 10, b = h / 5: a thin beam."""
    return cantilever(10 * H, 20, np.array([0.0, H / 10]))


def test_thin_cantilever_is_timoshenko_and_plane_stress(slender):
    L, I, A, G = 10 * H, H**3 / 12, H, E / (2 * (1 + NU))  # per unit width
    timoshenko = L**3 / (3 * E * I) + L / (5 / 6 * G * A)
    assert abs(slender["avg"] / timoshenko - 1) < 0.02
    assert abs(slender["stress"] / timoshenko - 1) < 0.02
    # the thin limit: 3D = generalised plane stress. The P2 tetrahedra keep a gap to the P2
    # triangles of the same face (about 0.4 % here, the same for b = h/10 .. h/40: the
    # discretisation, not the width) that closes under refinement
    gap = abs(slender["avg"] / slender["stress"] - 1)
    assert gap < 0.006 and abs(slender["mid"] / slender["avg"] - 1) < 1e-4
    global NY
    NY, ny = 8, NY
    try:
        fine = cantilever(10 * H, 40, np.array([0.0, H / 10]))
    finally:
        NY = ny
    assert abs(fine["avg"] / fine["stress"] - 1) < 0.65 * gap


def test_plane_strain_bending_scales_by_one_minus_nu_squared(slender):
    # bending dominates at L/h = 10: E' = E / (1 - nu^2) (shear ~1 %, the clamp's Poisson restraint)
    assert abs(slender["strain"] / slender["stress"] / (1 - NU**2) - 1) < 0.01


def test_wide_plate_mid_plane_is_plane_strain():
    # a stubby cantilever (L = 2 h, like a tooth) on a face 40 times its length: the free
    # edges' zone spans about the length, so the middle of the face is plane strain
    L = 2 * H
    wide = cantilever(L, 8, face_planes(20 * L, H / 4, 2 * H, growth=0.5))
    assert abs(wide["mid"] / wide["strain"] - 1) < 0.002
    assert wide["strain"] < wide["avg"] < wide["stress"]
    assert (wide["avg"] - wide["strain"]) / (wide["stress"] - wide["strain"]) < 0.15


def test_face_planes_refine_by_the_scale():
    a = face_planes(0.05, 0.8e-3, 7.5e-3, 0.3)
    b = face_planes(0.05, 0.4e-3, 3.75e-3, 0.15)
    assert a[0] == 0 and a[-1] == 0.05 and np.all(np.diff(a) > 0)
    assert abs((len(b) - 1) / (len(a) - 1) - 2) < 0.1
    assert np.diff(a)[-1] < np.diff(a)[0]  # finest at the free end face
    assert len(face_planes(1e-4, 0.8e-3, 7.5e-3)) == 2


def test_coarse_tooth_lies_between_the_2d_idealisations():
    pair = default_pair()
    r = plane_check(pair, face_width_m=4 * pair.module_m, mesh_scale=2.5)
    s, e, a, m = (r.stress_um_per_N_per_mm, r.strain_um_per_N_per_mm, r.average_um_per_N_per_mm, r.mid_um_per_N_per_mm)
    assert np.all(e < a) and np.all(a < s) and np.all(e < m) and np.all(m < s)
    assert np.all(np.diff(s) > 0) and np.all(np.diff(a) > 0)  # softer toward the tip
    # the 2D states differ by a factor between 1 - nu^2 (pure bending) and 1 (pure shear)
    assert np.all((e / s > 1 - NU**2 - 1e-9) & (e / s < 1))
    # a thin face is plane stress
    thin = plane_check(pair, face_width_m=0.05 * pair.module_m, mesh_scale=2.5, radii_m=r.radius_m[1:2])
    assert abs(thin.average_um_per_N_per_mm[0] / thin.stress_um_per_N_per_mm[0] - 1) < 0.003
