"""Accuracy versus cost of the stiffness models (paper pair, 40 N m).

Ishikawa: mean mesh stiffness versus the number of slices, error against a
1024-slice reference; energy method: versus Gauss points per profile piece, error
against 64 points. Wall time is the median of repeated full 360-angle curves.
FE single-tooth compliance (fem.tooth, P2 on Gmsh's curved 6-node mesh, 21
positions): the default level and two finer ones (mesh_scale 1, 1/sqrt 2, 1/2),
the error of each against the Richardson extrapolation of the three, and the wall
time of every stage; Gmsh meshing time of order 1 versus order 2."""

from _timing import timed  # noqa: E402  (benchmarks/_timing.py)

from gearwear.analytic.tvms import mesh_stiffness
from gearwear.geometry.spec import default_pair

pair = default_pair()
ref = mesh_stiffness(pair, points=360, n_slices=1024).mean_N_per_m
print(f"Ishikawa slices (reference: 1024 slices, mean k = {ref:.6e} N/m)")
print(f"{'slices':>8}{'mean k (N/m)':>16}{'rel. error':>12}{'wall (ms)':>11}")
for n in (4, 8, 16, 32, 64, 128, 256):
    r, t = timed(lambda: mesh_stiffness(pair, points=360, n_slices=n))
    print(f"{n:>8}{r.mean_N_per_m:>16.6e}{abs(r.mean_N_per_m / ref - 1):>12.2e}{t * 1e3:>11.2f}")

import numpy as np  # noqa: E402

from gearwear.analytic import energy  # noqa: E402
from gearwear.analytic.tvms import _profiles  # noqa: E402

prof = _profiles(pair, None, pair.centre_distance_m)[0][0]
R = np.linspace(71.8e-3, 79.9e-3, 200)
ref_e = energy.tooth_compliance(prof, R, pair.materials[0], pair.face_width_m, n_gauss=64).total_m_per_N
print("\nEnergy method Gauss points per profile piece (reference: 64), single-tooth compliance, 200 radii")
print(f"{'points':>8}{'max rel. error':>16}{'wall (ms)':>11}")
for n in (1, 2, 4, 8, 16):
    c, t = timed(lambda: energy.tooth_compliance(prof, R, pair.materials[0], pair.face_width_m, n_gauss=n))
    print(f"{n:>8}{np.max(np.abs(c.total_m_per_N / ref_e - 1)):>16.2e}{t * 1e3:>11.2f}")

from gearwear.fem.convergence import observed_order, richardson  # noqa: E402
from gearwear.fem.tooth import single_tooth_compliance, tooth_mesh  # noqa: E402

print("\nFE single-tooth compliance, P2 on Gmsh's curved 6-node mesh, 21 positions (SAP to tip)")
scales = (1.0, 2**-0.5, 0.5)
fe = [single_tooth_compliance(pair, mesh_scale=s) for s in scales]
c = [r.fem_compliance_um_per_N_per_mm for r in fe]
_, p_norm = observed_order(*c)
ref_fe = richardson(c[1], c[2], p_norm)
print(
    f"observed order {p_norm:.2f}; extrapolated compliance at the first / middle / last position "
    f"{ref_fe[0]:.6f} / {ref_fe[10]:.6f} / {ref_fe[-1]:.6f} um/(N/mm)"
)
print(f"{'scale':>7}{'dofs':>9}{'max err %':>11}{'mesh s':>8}{'assemble s':>11}{'factorize s':>12}{'solve s':>9}")
for s, r, ci in zip(scales, fe, c):
    t = r.timings
    print(
        f"{s:>7.3f}{r.ndofs:>9}{100 * np.max(np.abs(ci / ref_fe - 1)):>11.4f}{t['mesh_s']:>8.2f}"
        f"{t['assemble_s']:>11.2f}{t['factorize_s']:>12.2f}{t['solve_s']:>9.2f}"
    )
for order in (1, 2):
    _, t = timed(lambda: tooth_mesh(pair, order=order), n=5)
    print(f"Gmsh mesh of the default level, order {order}: {t:.2f} s (median of 5, incl. profiles and morph lookup)")
