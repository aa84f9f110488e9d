"""Gmsh meshes of the real (rack-generated, worn) gear: area, orientation, quality,
determinism, boundaries."""

import math

import numpy as np
import pytest

from gearwear.fem.mesh import MeshSizes, mesh_full_gear, mesh_sector, triangle_quality
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.profile import FILLET, gear_outline, polygon_area, tooth_profile
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import WearSpec, flank_depth


@pytest.fixture(scope="module")
def profiles():
    pair = default_pair()
    g = pair.gear(0)
    nom = tooth_profile(g, sag_m=2e-6)
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    worn = nom.worn(flank_depth(nom, 0, mesh, WearSpec(phase="severe")))
    return g, nom, worn


def _signed_corner_areas(m):
    p, t = m.p, m.t[:3]
    a, b, c = p[:, t[0]], p[:, t[1]], p[:, t[2]]
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))


def test_full_worn_gear_mesh(profiles):
    g, nom, worn = profiles
    outline = gear_outline(nom, worn, worn_teeth=[0])
    sizes = MeshSizes(global_m=3e-3, fillet_m=0.5e-3, load_m=0.2e-3)
    load = np.array([[nom.xy[len(nom.s) // 2 + 20, 0], nom.xy[len(nom.s) // 2 + 20, 1]]])
    gm = mesh_full_gear(
        outline, g.hub_radius_m, sizes, refine_points_xy=load, fillet_points_xy=nom.xy[nom.region == FILLET][::10]
    )
    exact = polygon_area(outline) - math.pi * g.hub_radius_m**2
    assert gm.area_m2 == pytest.approx(exact, rel=1e-6)
    assert np.all(_signed_corner_areas(gm.mesh) > 0)
    assert triangle_quality(gm.mesh).min() > 0.3
    bore = gm.mesh.p[:, gm.mesh.facets[:, gm.boundaries["bore"]].ravel()]
    assert np.allclose(np.hypot(*bore), g.hub_radius_m, rtol=1e-9)
    again = mesh_full_gear(
        outline, g.hub_radius_m, sizes, refine_points_xy=load, fillet_points_xy=nom.xy[nom.region == FILLET][::10]
    )
    assert np.array_equal(gm.mesh.p, again.mesh.p) and np.array_equal(gm.mesh.t, again.mesh.t)


def test_three_tooth_sector_area(profiles):
    g, nom, worn = profiles
    z = g.teeth
    line = gear_outline(nom, worn, teeth=[-1, 0, 1], worn_teeth=[0])
    a0, a1 = math.pi / 2 - 3 * math.pi / z, math.pi / 2 + 3 * math.pi / z
    gm = mesh_sector(line, g.hub_radius_m, a0, a1, MeshSizes(global_m=2e-3, fillet_m=0.4e-3))
    # exact: polygon (outline + both cut ends at the hub) minus the hub circular segment
    r = g.hub_radius_m
    closed = np.vstack([line, [r * math.cos(a1), r * math.sin(a1)], [r * math.cos(a0), r * math.sin(a0)]])
    segment = 0.5 * r**2 * ((a1 - a0) - math.sin(a1 - a0))
    assert gm.area_m2 == pytest.approx(polygon_area(closed) - segment, rel=1e-6)
    assert np.all(_signed_corner_areas(gm.mesh) > 0)
    for key in ("outer", "hub_arc", "cut_left", "cut_right"):
        assert len(gm.boundaries[key]) > 0


def test_tooth_fe_mesh_carries_gmsh_mid_side_nodes_on_the_flank():
    """The single-tooth FE (P2) runs on Gmsh's 6-node mesh with its mid-side nodes:
    on tooth 0's loaded flank they lie on the exact involute (polar form
    beta = psi_b - inv(alpha_R)) and on the exact trochoidal fillet (dense
    geometry.profile.fillet_points) to < 1e-2 of each edge's chord sag (measured
    ~1e-4: the 1 nm source polyline), where straight edges would put them on the
    chord; the order-1 model has 3-node elements and no mid-side nodes."""
    import skfem

    from gearwear.fem.elasticity import assemble
    from gearwear.fem.tooth import tooth_mesh
    from gearwear.geometry.polyline import project_to_polyline
    from gearwear.geometry.profile import RackGeometry, fillet_points

    pair = default_pair()
    g = pair.gear(0)
    tm = tooth_mesh(pair, mesh_scale=2.0)
    m = tm.mesh
    assert isinstance(m, skfem.MeshTri2)
    model = assemble(m, pair.materials[0], pair.face_width_m, tm.gear_mesh.boundaries["bore"], order=2)
    assert np.array_equal(model.basis.doflocs[:, 0::2], m.doflocs)  # the P2 nodes are Gmsh's nodes
    nodes = tm.flank_nodes
    assert np.all(nodes[0::2] < m.nvertices) and np.all(nodes[1::2] >= m.nvertices)  # vertex, mid, vertex, ...
    a, mid, b = (m.doflocs[:, nodes[k : -1 if k < 2 else None : 2]].T for k in (0, 1, 2))
    a, b = a[: len(mid)], b[: len(mid)]
    ab, am = b - a, mid - a
    sag = np.abs(ab[:, 0] * am[:, 1] - ab[:, 1] * am[:, 0]) / np.hypot(*ab.T)  # node's distance from the chord
    R = np.hypot(*mid.T)
    rb = g.base_radius_m
    alpha = g.pressure_angle_rad
    psi_b = g.pitch_thickness_m / (2 * g.pitch_radius_m) + np.tan(alpha) - alpha
    on_inv = R > tm.nominal.form_radius_m * (1 + 1e-6)
    on_inv &= R < g.tip_radius_m * (1 - 1e-6)
    alpha_R = np.arccos(rb / R[on_inv])
    beta_exact = psi_b - (np.tan(alpha_R) - alpha_R)
    dev = R[on_inv] * np.abs(np.arctan2(mid[on_inv, 0], mid[on_inv, 1]) - beta_exact)  # >= distance to the curve
    assert on_inv.sum() >= 8 and np.all(dev < 1e-2 * sag[on_inv]), (dev / sag[on_inv]).max()
    rack = RackGeometry.of(g)
    fil, _ = fillet_points(rack, np.linspace(rack.phi_root, rack.phi_tangent, 20001))
    on_fil = (R < tm.nominal.form_radius_m * (1 - 1e-6)) & (R > g.root_radius_m * (1 + 1e-6))
    d_fil = project_to_polyline(mid[on_fil], fil).distance
    assert on_fil.sum() >= 3 and np.all(d_fil < 1e-2 * sag[on_fil]), (d_fil / sag[on_fil]).max()
    p1 = tooth_mesh(pair, mesh_scale=2.0, order=1)
    assert type(p1.mesh) is skfem.MeshTri1 and p1.mesh.doflocs.shape[1] == p1.mesh.nvertices
