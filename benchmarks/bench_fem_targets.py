"""Wall-time targets of the FE stages, measured here instead of asserted in the tests.

tests/test_fem_tooth.py used to assert that the default FE single-tooth level takes
<= 10 s for its 21-position curve and that the coarse convergence study's default
level takes <= 60 s; tests/test_mesh.py timed the full 30-tooth P2 mesh at production
sizes. Wall time depends on the machine and on its load (the test suite shares two
cores), so those numbers are benchmarks: this script reports each as the median of a
few runs and its ratio to the target (below 1 meets it). The tests keep their
accuracy assertions. Timings are printed, never asserted; nothing here fails the run.
"""

import math
import statistics

import numpy as np
from _timing import timed  # noqa: E402  (benchmarks/_timing.py)

from gearwear.fem.convergence import acceptance, convergence_table
from gearwear.fem.mesh import MeshSizes, mesh_full_gear
from gearwear.fem.tooth import single_tooth_compliance
from gearwear.geometry.profile import fillet_midpoints, gear_outline, tooth_profile
from gearwear.geometry.spec import default_pair

RUNS = 3


def line(what, wall, target=None, note=""):
    ratio = f"{wall / target:>8.2f}" if target else f"{'-':>8}"
    tgt = f"{target:>9.1f}" if target else f"{'-':>9}"
    print(f"  {what:<58}{wall:>9.2f}{tgt}{ratio}  {note}")


pair = default_pair()
print(f"FE wall-time targets ({RUNS} runs each, median; ratio = wall / target, below 1 meets it)")
print(f"  {'stage':<58}{'wall s':>9}{'target':>9}{'ratio':>8}")

# 1. default single-tooth level, 21 positions (was: tests/test_fem_tooth.py, d.wall_s <= 10 s)
runs = [single_tooth_compliance(pair) for _ in range(RUNS)]
line(
    "single-tooth FE, default P2 level, 21 positions (wall_s)",
    statistics.median(r.wall_s for r in runs),
    10.0,
    f"{runs[0].ndofs} dofs",
)

# 2. the coarse convergence study of the tests (was: acceptance(..., max_wall_s=60))
sq = math.sqrt(2.0)
study, wall = timed(lambda: convergence_table(pair, levels={1: (2.0, sq, 1.0), 2: (2 * sq, 2.0, sq)}), n=1)
rows = [dict(x) for x in study]
for x in rows:
    x["is_default"] = x["order"] == 2 and x is rows[-1]
acc = acceptance(rows, max_change_pct=1.0)
line("coarse convergence study: its 'default' level (wall_s)", acc["default_wall_s"], 60.0, f"whole study {wall:.1f} s")

# 3. the full 30-tooth P2 mesh at the sizes of tests/test_mesh.py (3 mm, 0.5 mm fillets,
#    0.2 mm load point), on the real gear outline (was: printed by test_full_gear_timing)
g = pair.gear(0)
nom = tooth_profile(g, sag_m=1e-6)
outline = gear_outline(nom)
pts = fillet_midpoints(nom, g.teeth)
load = np.array([[nom.xy[-40, 0], nom.xy[-40, 1]]])
sizes = MeshSizes(global_m=3e-3, fillet_m=0.5e-3, load_m=0.2e-3)
gm, wall = timed(lambda: mesh_full_gear(outline, g.hub_radius_m, sizes, refine_points_xy=load, fillet_points_xy=pts))
line("full 30-tooth P2 mesh, 3 / 0.5 / 0.2 mm", wall, None, f"{gm.n_elements} triangles")
