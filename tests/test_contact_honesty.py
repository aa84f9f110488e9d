"""A model that cannot separate never reports "separation 0 %".

Without a backlash effect the mesh is a two-sided spring: its separation fraction is
undefined (null, with the reason), the back-flank fraction is the share of time the mesh
force is negative (worked out here from the force signal itself), and a warning says what
that means and how to model separation. With backlash the same operating point separates.
Issue 22's case on the user's unequal, profile-shifted pair: 40 um wear at 6750 rpm."""

from __future__ import annotations

import numpy as np
import pytest

from gearwear.jobs.simulate import run
from gearwear.scene.model import scene_from_dict

HARD = {
    "pair": {
        "teeth": [23, 47],
        "module_mm": 3.0,
        "profile_shift": [0.2, -0.1],
        "face_width_mm": 30.0,
        "hub_radius_mm": [12.5, 25.0],
    },
    "bodies": {"bearing_stiffness_N_per_m": 5e8},
    "operating": {"speed_rpm": 6750, "torque_Nm": 40},
    "effects": {"mesh_stiffness": {"source": "analytic"}, "wear": {"max_depth_um": 40}, "transmission_error": {}},
    "solver": {"duration_s": 0.06, "discard_s": 0.03},
}


@pytest.fixture(scope="module")
def pulling():
    return run(scene_from_dict(HARD))


def test_a_two_sided_spring_reports_no_separation_and_its_back_flank_share(pulling):
    r = pulling.result
    s = pulling.summary()
    assert s["separation_fraction"] is None and "backlash" in s["separation_note"]
    f_neg = float(np.mean(r.signals["F_m"] < 0))
    assert f_neg > 0.05  # the mesh really pulls here
    assert s["backside_fraction"] == pytest.approx(f_neg, rel=1e-15)
    warn = [w for w in s["warnings"] if w.startswith("the mesh force is negative")]
    assert len(warn) == 1 and "[effects.backlash]" in warn[0] and f"{100 * f_neg:.2f} %" in warn[0]


def test_with_backlash_the_same_point_separates_and_the_warning_is_gone():
    doc = {**HARD, "effects": {**HARD["effects"], "backlash": {"initial_um": 50}}}
    s = run(scene_from_dict(doc)).summary()
    assert s["separation_fraction"] > 0.01
    assert not any(w.startswith("the mesh force is negative") for w in s["warnings"])
    assert "separation_note" not in s


def test_a_pair_that_never_pulls_gets_no_warning():
    doc = {
        **HARD,
        "operating": {"speed_rpm": 600, "torque_Nm": 120},
        "effects": {"mesh_stiffness": {"source": "analytic"}},
    }
    s = run(scene_from_dict(doc)).summary()
    assert s["separation_fraction"] is None and s["backside_fraction"] == 0.0
    assert not any(w.startswith("the mesh force is negative") for w in s["warnings"])
