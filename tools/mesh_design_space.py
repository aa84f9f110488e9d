"""Mesh (without solving) the pair FE's bodies of the design-space study's designs, fast:
the mesher's checks (exact region, quality) and folded elements, per design, in a pool.

    .venv/bin/python tools/mesh_design_space.py [FIRST LAST [WORKERS]]

FIRST..LAST are positions in tests/test_fe_design_space.py's accepted designs (default all
223); one line per design: its element counts and folded elements, or the error. The full
check (meshing and solving) is ``make fe-design-space``.
"""

from __future__ import annotations

import math
import sys
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import test_fe_design_space as space  # noqa: E402

from gearwear.fem import pair_model as fe_model  # noqa: E402
from gearwear.fem.mesh import inverted_elements  # noqa: E402
from gearwear.fem.pair_body import _mesh_body  # noqa: E402
from gearwear.geometry.pair_positions import lowest_contact_radius_m  # noqa: E402
from gearwear.geometry.profile import tooth_profile  # noqa: E402
from gearwear.geometry.sampling import FINE_SAG_M  # noqa: E402
from gearwear.geometry.wear import key_roll_angles  # noqa: E402


def mesh_one(item) -> str:
    """Both bodies of one design at the test's load (200 N/mm), as the pair FE meshes them."""
    pos, (i, pair) = item
    t0 = time.time()
    try:
        T = 200e3 * pair.face_width_m * pair.gear(0).base_radius_m
        mesh = fe_model._check_inputs(pair, T, 0.0, "stress", None).mesh
        sizes, _, window = fe_model._sizes(pair, T, 1.0, 1.0)
        nb = int(math.ceil(mesh.contact_ratio + 2 * fe_model.EXTENSION_PITCHES)) + 1
        out = []
        for gi, g in enumerate(pair.gears):
            nominal = tooth_profile(g, sag_m=FINE_SAG_M, extra_roll=key_roll_angles(mesh, gi))
            r_lo = lowest_contact_radius_m(mesh, gi, window, fe_model.EXTENSION_PITCHES)
            _, model, _, _, _ = _mesh_body(g, g.material, pair.face_width_m, nominal, sizes, r_lo, nb, "stress")
            out.append((model.mesh.t.shape[1], int(np.sum(inverted_elements(model.mesh)))))
        return f"{pos:3d} design{i}: ok {out} {time.time() - t0:.1f}s z={pair.teeth}"
    except Exception as e:  # report and go on: the point is to see every failure
        return f"{pos:3d} design{i}: FAIL {type(e).__name__}: {str(e)[:300]} z={pair.teeth}"


if __name__ == "__main__":
    lo = int(sys.argv[1]) if len(sys.argv) > 1 else 0
    hi = int(sys.argv[2]) if len(sys.argv) > 2 else len(space.DESIGNS)
    with Pool(int(sys.argv[3]) if len(sys.argv) > 3 else 2) as pool:
        for line in pool.imap(mesh_one, list(enumerate(space.DESIGNS))[lo:hi]):
            print(line, flush=True)
