"""An installed centre distance (``pair.centre_distance_mm``): one operating geometry for the
geometry, the stiffness and the dynamics, and the backlash it opens worked out by hand.

For gears cut for zero backlash at a_w, the normal backlash at a' is
2 (r_b1 + r_b2) (inv alpha' - inv alpha_w) with cos alpha' = (r_b1 + r_b2) / a' (the base
circles do not move). On the user's unequal, profile-shifted pair and on one whose driver has
more teeth."""

from __future__ import annotations

import math

import pytest

from gearwear.core.validation import InputError
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import backlash
from gearwear.scene.model import scene_from_dict

PAIRS = {
    "23-47": {
        "teeth": [23, 47],
        "module_mm": 3.0,
        "profile_shift": [0.2, -0.1],
        "face_width_mm": 30.0,
        "hub_radius_mm": [12.5, 25.0],
    },
    "driver-47": {
        "teeth": [47, 23],
        "module_mm": 3.0,
        "profile_shift": [-0.1, 0.2],
        "face_width_mm": 30.0,
        "hub_radius_mm": [25.0, 12.5],
    },
}


def _inv(a):
    return math.tan(a) - a


def _doc(pair, **extra):
    return {
        "pair": {**pair, **extra},
        "operating": {"speed_rpm": 1500, "torque_Nm": 120},
        "bodies": {"bearing_stiffness_N_per_m": 5e8},
    }


@pytest.mark.parametrize("name", PAIRS)
def test_the_backlash_it_opens_is_the_hand_formula(name):
    p = PAIRS[name]
    z1, z2 = p["teeth"]
    m, a = p["module_mm"] * 1e-3, math.radians(20)
    # zero-backlash working pressure angle of the shifts, by Newton on inv(alpha_w)
    target = _inv(a) + 2 * sum(p["profile_shift"]) * math.tan(a) / (z1 + z2)
    aw = a
    for _ in range(50):
        aw -= (_inv(aw) - target) / math.tan(aw) ** 2
    rb_sum = 0.5 * m * (z1 + z2) * math.cos(a)
    a_w = rb_sum / math.cos(aw)
    installed = a_w + 0.2e-3
    pair = scene_from_dict(_doc(p, centre_distance_mm=installed * 1e3)).pair
    alpha_p = math.acos(rb_sum / installed)
    assert pair.zero_backlash_centre_distance_m == pytest.approx(a_w, rel=1e-13)
    assert backlash(pair, pair.centre_distance_m) == pytest.approx(2 * rb_sum * (_inv(alpha_p) - _inv(aw)), rel=1e-9)
    # and the contact ratio shortens as the centres move apart
    assert (
        MeshGeometry(pair, pair.centre_distance_m).contact_ratio
        < MeshGeometry(pair, pair.zero_backlash_centre_distance_m).contact_ratio
    )


def test_geometry_stiffness_and_dynamics_run_at_the_same_centre_distance():
    from gearwear.jobs.geometry import compute
    from gearwear.jobs.simulate import build_model, stiffness_input

    sc = scene_from_dict(_doc(PAIRS["23-47"], centre_distance_mm=105.6))
    g = compute(sc, None, 0.0, 120.0, build_mesh=False).summary()
    st = stiffness_input(sc)
    model = build_model(sc, st)
    mesh = MeshGeometry(sc.pair, 0.1056)
    assert g["centre_distance_mm"] == pytest.approx(105.6, rel=1e-12)
    assert g["contact_ratio"] == pytest.approx(mesh.contact_ratio, rel=1e-12)
    assert model.C0_m == pytest.approx(0.1056, rel=1e-15)
    assert model.alpha == pytest.approx(mesh.pressure_angle_rad, rel=1e-15)
    from gearwear.analytic.tvms import mesh_stiffness

    k = mesh_stiffness(sc.pair, points=64, torque_Nm=120.0)
    assert k.mesh.centre_distance_m == pytest.approx(0.1056, rel=1e-15)
    assert k.contact_ratio == pytest.approx(mesh.contact_ratio, rel=1e-12)


def test_without_backlash_the_dynamics_warn_that_the_opened_backlash_is_not_modelled():
    from gearwear.jobs.simulate import operating_notes

    sc = scene_from_dict(
        {**_doc(PAIRS["23-47"], centre_distance_mm=105.6), "effects": {"mesh_stiffness": {"source": "analytic"}}}
    )
    notes = operating_notes(sc)["warnings"]
    assert any(n.startswith("pair.centre_distance_mm opens") and "[effects.backlash]" in n for n in notes)
    sc = scene_from_dict(
        {
            **_doc(PAIRS["23-47"], centre_distance_mm=105.6),
            "effects": {"mesh_stiffness": {"source": "analytic"}, "backlash": {"initial_um": 0}},
        }
    )
    assert not any(n.startswith("pair.centre_distance_mm opens") for n in operating_notes(sc)["warnings"])


@pytest.mark.parametrize("value", [105.0, 200.0])
def test_a_centre_distance_outside_the_meshing_range_is_refused_with_the_range(value):
    with pytest.raises(InputError) as e:
        scene_from_dict(_doc(PAIRS["23-47"], centre_distance_mm=value))
    msg = str(e.value)
    assert msg.startswith(f"pair.centre_distance_mm = {value:g} mm: must be in [105.297, ") and "\n" not in msg
