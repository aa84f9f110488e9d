"""Gmsh meshes of the real (rack-generated, worn) gear: area, orientation, quality,
determinism, boundaries."""

import math

import numpy as np
import pytest

from gearwear.fem.mesh import MeshSizes, mesh_full_gear, mesh_sector, triangle_quality
from gearwear.geometry.profile import FILLET, gear_outline, polygon_area, tooth_profile
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import WearSpec, flank_depth
from gearwear.geometry.kinematics import MeshGeometry


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
    gm = mesh_full_gear(outline, g.hub_radius_m, sizes, refine_points_xy=load,
                        fillet_points_xy=nom.xy[nom.region == FILLET][::10])
    exact = polygon_area(outline) - math.pi * g.hub_radius_m ** 2
    assert gm.area_m2 == pytest.approx(exact, rel=1e-6)
    assert np.all(_signed_corner_areas(gm.mesh) > 0)
    assert triangle_quality(gm.mesh).min() > 0.3
    bore = gm.mesh.p[:, gm.mesh.facets[:, gm.boundaries["bore"]].ravel()]
    assert np.allclose(np.hypot(*bore), g.hub_radius_m, rtol=1e-9)
    again = mesh_full_gear(outline, g.hub_radius_m, sizes, refine_points_xy=load,
                           fillet_points_xy=nom.xy[nom.region == FILLET][::10])
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
    segment = 0.5 * r ** 2 * ((a1 - a0) - math.sin(a1 - a0))
    assert gm.area_m2 == pytest.approx(polygon_area(closed) - segment, rel=1e-6)
    assert np.all(_signed_corner_areas(gm.mesh) > 0)
    for key in ("outer", "hub_arc", "cut_left", "cut_right"):
        assert len(gm.boundaries[key]) > 0
