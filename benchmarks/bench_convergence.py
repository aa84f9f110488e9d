"""Accuracy versus cost of the analytic stiffness models (paper pair, 40 N m).

Ishikawa: mean mesh stiffness versus the number of slices, error against a
1024-slice reference; energy method: versus Gauss points per profile piece, error
against 64 points. Wall time is the median of repeated full 360-angle curves."""

import statistics
import time

from gearwear.analytic.tvms import mesh_stiffness
from gearwear.geometry.spec import default_pair


def timed(fn, n=9):
    out, ts = None, []
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return out, statistics.median(ts)


pair = default_pair()
ref = mesh_stiffness(pair, points=360, n_slices=1024).mean_N_per_m
print(f"Ishikawa slices (reference: 1024 slices, mean k = {ref:.6e} N/m)")
print(f"{'slices':>8}{'mean k (N/m)':>16}{'rel. error':>12}{'wall (ms)':>11}")
for n in (4, 8, 16, 32, 64, 128, 256):
    r, t = timed(lambda: mesh_stiffness(pair, points=360, n_slices=n))
    print(f"{n:>8}{r.mean_N_per_m:>16.6e}{abs(r.mean_N_per_m / ref - 1):>12.2e}{t * 1e3:>11.2f}")

from gearwear.analytic import energy  # noqa: E402
from gearwear.analytic.tvms import _profiles  # noqa: E402
import numpy as np  # noqa: E402

prof = _profiles(pair, None, pair.centre_distance_m)[0][0]
R = np.linspace(71.8e-3, 79.9e-3, 200)
ref_e = energy.tooth_compliance(prof, R, pair.material, pair.face_width_m, n_gauss=64).total_m_per_N
print("\nEnergy method Gauss points per profile piece (reference: 64), single-tooth compliance, 200 radii")
print(f"{'points':>8}{'max rel. error':>16}{'wall (ms)':>11}")
for n in (1, 2, 4, 8, 16):
    c, t = timed(lambda: energy.tooth_compliance(prof, R, pair.material, pair.face_width_m, n_gauss=n))
    print(f"{n:>8}{np.max(np.abs(c.total_m_per_N / ref_e - 1)):>16.2e}{t * 1e3:>11.2f}")
