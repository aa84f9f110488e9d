"""Geometry stage timings: profile generation, worn profiles, full-gear P2 mesh.

Reports the median of repeated runs; compares profile cost at two sag tolerances
(accuracy of the polyline versus time)."""

import numpy as np
from _timing import median_time  # noqa: E402  (benchmarks/_timing.py)

from gearwear.fem.mesh import MeshSizes, mesh_full_gear
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.profile import INVOLUTE, fillet_midpoints, gear_outline, involute_points, tooth_profile
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import WearSpec, worn_profiles


def polyline_error(prof):
    """Max chord sag (m): normal distance from involute chord midpoints to the curve."""
    g = prof.gear
    inv = np.flatnonzero(prof.region == INVOLUTE)
    u_mid = 0.5 * (prof.roll[inv[:-1]] + prof.roll[inv[1:]])
    exact, normal = involute_points(g.base_radius_m, prof.psi_b, u_mid)
    chord = 0.5 * (prof.xy[inv[:-1]] + prof.xy[inv[1:]])
    return float(np.max(np.abs(np.sum((exact - chord) * normal, axis=1))))


pair = default_pair()
g = pair.gear(0)
print(f"{'what':<38}{'median wall':>14}{'points':>9}{'max chord sag':>18}")
for sag in (5e-6, 1e-6, 0.2e-6):
    prof = tooth_profile(g, sag_m=sag)
    t = median_time(lambda: tooth_profile(g, sag_m=sag))
    print(
        f"{'tooth profile, sag ' + format(sag * 1e6, 'g') + ' um':<38}{t * 1e3:>11.2f} ms{len(prof.s):>9}"
        f"{polyline_error(prof) * 1e9:>15.1f} nm"
    )
mesh = MeshGeometry(pair, pair.centre_distance_m)
t = median_time(lambda: worn_profiles(pair, WearSpec(phase="severe"), mesh))
print(f"{'worn profiles (both gears, severe)':<38}{t * 1e3:>11.2f} ms")
nom = tooth_profile(g, sag_m=1e-6)
outline = gear_outline(nom)
pts = fillet_midpoints(nom, g.teeth)
load = np.array([[nom.xy[-40, 0], nom.xy[-40, 1]]])
for size in (3e-3, 1.5e-3):
    sizes = MeshSizes(global_m=size, fillet_m=0.4e-3, load_m=0.2e-3)
    gm = mesh_full_gear(outline, g.hub_radius_m, sizes, refine_points_xy=load, fillet_points_xy=pts)
    t = median_time(
        lambda: mesh_full_gear(outline, g.hub_radius_m, sizes, refine_points_xy=load, fillet_points_xy=pts), n=3
    )
    print(
        f"{'full 30-tooth P2 mesh, global ' + format(size * 1e3, 'g') + ' mm':<38}{t:>12.2f} s"
        f"{gm.n_elements:>9} tri, area error {gm.area_rel_error:.1e}"
    )
