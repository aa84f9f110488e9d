"""Legal but absurd physics gets a warning (issue 25: a constant mesh stiffness of 1e-30 N/m,
Young's modulus 1e-9 GPa, a nearly zero user table ran without a word); a real pair gets none.

The references are the pair's own: the blank's mass and inertia (geometry.blank), ISO 6336's
mesh stiffness of the pair, its pitch radius and face width for the line load."""

from __future__ import annotations

import pytest

from gearwear.jobs.simulate import stiffness_input
from gearwear.scene.model import builtin_scene, scene_from_dict
from gearwear.scene.plausibility import body_warnings, pair_warnings, response_warnings, stiffness_warnings

USER = {
    "pair": {
        "teeth": [23, 47],
        "module_mm": 3.0,
        "profile_shift": [0.2, -0.1],
        "face_width_mm": 30.0,
        "hub_radius_mm": [12.5, 25.0],
    },
    "bodies": {"bearing_stiffness_N_per_m": 5e8},
    "operating": {"speed_rpm": 1500, "torque_Nm": 120},
    "effects": {"mesh_stiffness": {"source": "analytic"}},
}


def _all(sc):
    return pair_warnings(sc) + body_warnings(sc) + stiffness_warnings(sc, stiffness_input(sc).mean_N_per_m)


@pytest.mark.parametrize(
    "doc",
    [
        USER,
        {
            **USER,
            "pair": {**USER["pair"], "teeth": [47, 23], "profile_shift": [-0.1, 0.2], "hub_radius_mm": [25, 12.5]},
        },
    ],
    ids=["23-47", "driver-47"],
)
def test_a_real_pair_gets_no_warning(doc):
    assert _all(scene_from_dict(doc)) == []


@pytest.mark.parametrize("name", ["paper-default", "paper-wear-severe", "paper-clearance"])
def test_the_paper_scenes_get_no_warning(name):
    assert _all(builtin_scene(name)) == []


@pytest.mark.parametrize(
    "change,needle",
    [
        ({"material": {"youngs_modulus_GPa": 1e-9}}, "material.youngs_modulus_GPa = 1e-09 GPa"),
        ({"material": {"density_kg_per_m3": [20001, 7850]}}, "material.density_kg_per_m3 = 20001"),
        ({"bodies": {"mass_kg": [1e-9, 3.0]}}, "bodies.mass_kg = 1e-09 kg for the pinion"),
        ({"bodies": {"inertia_kg_m2": [1e-3, 1.0]}}, "bodies.inertia_kg_m2 = 1 kg m^2 for the gear"),
        ({"bodies": {"bearing_stiffness_N_per_m": 1e-9}}, "bodies.bearing_stiffness_N_per_m = 1e-09"),
        ({"operating": {"torque_Nm": 1e-9}}, "operating.torque_Nm = 1e-09 N m is a line load"),
        ({"operating": {"speed_rpm": 1e6}}, "pitch-line velocity"),
        (
            {"effects": {"mesh_stiffness": {"source": "constant", "value_N_per_m": 1e-30}}},
            "effects.mesh_stiffness.value_N_per_m (1e-30 N/m)",
        ),
    ],
)
def test_an_absurd_value_is_said(change, needle):
    doc = {k: dict(v) if isinstance(v, dict) else v for k, v in USER.items()}
    for table, keys in change.items():
        doc[table] = {**doc.get(table, {}), **keys}
    found = _all(scene_from_dict(doc))
    assert any(needle in w for w in found), found


def test_a_response_without_any_contact_is_said():
    class R:
        separation_fraction = 1.0

    assert response_warnings(R()) and not response_warnings(type("S", (), {"separation_fraction": 0.3})())


def test_the_cli_prints_the_warning_and_still_runs(tmp_path):
    import subprocess
    import sys

    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "gearwear.cli",
            "stiffness",
            "paper-default",
            "--set",
            "material.youngs_modulus_GPa=1e-9",
            "--points",
            "16",
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0 and "warning: material.youngs_modulus_GPa = 1e-09 GPa" in r.stdout
