"""The scene schema: one place for every key, options that would be ignored are errors,
the resolved scene is a fixed point, and the CLI's short flags are exact aliases of --set."""

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from gearwear.core.validation import InputError
from gearwear.scene.checks import resolved_dict
from gearwear.scene.files import builtin_scene_dict, builtin_scene_names
from gearwear.scene.model import scene_from_dict
from gearwear.scene.reference import json_schema, reference_markdown, to_toml
from gearwear.scene.validate import validate_document

from scenes import with_paper

ROOT = Path(__file__).resolve().parents[1]


def cli(*args):
    return subprocess.run([sys.executable, "-m", "gearwear.cli", *args], capture_output=True, text=True)


# Each of these was accepted and then silently ignored (or reported active and switched off).
IGNORED = [
    (
        {"effects": {"mesh_stiffness": {"source": "analytic", "value_N_per_m": 3e8}}},
        'effects.mesh_stiffness.value_N_per_m = 3e+08 N/m: only used with source = "constant"',
    ),
    (
        {"effects": {"mesh_stiffness": {"source": "constant", "interpolation": "cubic"}}},
        "effects.mesh_stiffness.interpolation = 'cubic': not used",
    ),
    (
        {"effects": {"mesh_stiffness": {"source": "analytic", "path": "k.csv"}}},
        "effects.mesh_stiffness.path = 'k.csv': only used with source = \"table\"",
    ),
    (
        {"effects": {"wear": {"phase": "mild", "archard_k_m2_per_N": 1e-16}}},
        "effects.wear.archard_k_m2_per_N = 1e-16 m^2/N: only used with hours",
    ),
    (
        {"effects": {"wear": {"hours": 100, "model": "archard", "wear_intensity": 1e-8}}},
        "effects.wear.wear_intensity = 1e-08: only used with hours and model = 'paper_eq1'",
    ),
    (
        {"effects": {"mesh_stiffness": {"source": "constant", "value_N_per_m": 3e8}, "wear": {"phase": "severe"}}},
        "effects.wear: ignored with a constant mesh_stiffness.value_N_per_m",
    ),
    (
        {"effects": {"centre_distance": {"coupling": "static"}}},
        'effects.centre_distance: coupling = "static" moves the centre distance by the bearing clearance only',
    ),
    ({"solver": {"rtol": 1e-6}}, "solver.rtol = 1e-06: only used by dopri5 (the solver is rk4 by auto"),
    ({"solver": {"method": "rk4", "atol": 1e-9}}, "solver.atol = 1e-09: only used by dopri5"),
    (
        {"effects": {"backlash": {}}, "solver": {"steps_per_mesh_period": 512}},
        "solver.steps_per_mesh_period = 512: only used by rk4 (the solver is dopri5 by auto",
    ),
    (
        {"bodies": {"bearing_damping_ratio": 0.02, "bearing_damping_N_s_per_m": 100.0}},
        "bodies.bearing_damping_N_s_per_m = [100.0, 100.0] N s/m: give either",
    ),
]


@pytest.mark.parametrize("doc,message", IGNORED)
def test_options_that_would_be_ignored_are_errors(doc, message):
    with pytest.raises(InputError) as err:
        scene_from_dict(with_paper(doc))
    assert str(err.value).startswith(message), str(err.value)
    assert "\n" not in str(err.value)


def test_the_same_options_are_accepted_where_they_act():
    for doc in (
        {"effects": {"mesh_stiffness": {"source": "constant", "value_N_per_m": 3e8}}},
        {"effects": {"wear": {"phase": "mild"}, "transmission_error": {}}},
        # the unworn baseline of a wear study: zero excitation, accepted (issue 24)
        {"effects": {"transmission_error": {}}},
        {"effects": {"wear": {"max_depth_um": 0}, "transmission_error": {}}},
        {"effects": {"wear": {"hours": 100, "archard_k_m2_per_N": 1e-16}}},
        {"effects": {"wear": {"hours": 100, "model": "paper_eq1", "wear_intensity": 1e-8}}},
        {"effects": {"centre_distance": {"coupling": "dynamic"}}},
        {"effects": {"bearing_clearance": {"clearance_um": 10}, "centre_distance": {}}, "solver": {"rtol": 1e-6}},
        {"solver": {"method": "rk4", "steps_per_mesh_period": 512}},
    ):
        scene_from_dict(with_paper(doc))


def test_typos_get_the_nearest_key_at_every_depth():
    for doc, hint in (
        ({"operatng": {}}, "did you mean operating?"),
        ({"bodies": {"mass_k": 3}}, "did you mean bodies.mass_kg?"),
        ({"effects": {"backlash": {"initial_mu": 3}}}, "did you mean effects.backlash.initial_um?"),
        ({"solver": {"duraton_s": 1}}, "did you mean solver.duration_s?"),
    ):
        with pytest.raises(InputError, match=hint.replace("?", r"\?").replace(".", r"\.")):
            validate_document(with_paper(doc))


def test_strings_are_not_read_as_numbers():
    with pytest.raises(InputError, match=r"operating.speed_rpm = '1200': must be a number in \(0, 1e\+06\] rpm"):
        validate_document(with_paper({"operating": {"speed_rpm": "1200"}}))


@pytest.mark.parametrize("name", builtin_scene_names())
def test_resolved_scene_is_a_fixed_point(name):
    """Printing a scene with every default and reading it back gives the same scene."""
    doc = validate_document(builtin_scene_dict(name), name=name)
    text = to_toml(resolved_dict(doc))
    again = validate_document(tomllib.loads(text))
    assert resolved_dict(again) == resolved_dict(doc)
    assert scene_from_dict(tomllib.loads(text)).pair == scene_from_dict(builtin_scene_dict(name)).pair


def test_json_schema_describes_every_key_with_its_unit():
    s = json_schema()
    assert s["additionalProperties"] is False
    pair = s["$defs"]["PairDoc"]["properties"]
    assert pair["module_mm"]["unit"] == "mm" and pair["module_mm"]["minimum"] == 0.05
    assert pair["module_mm"]["maximum"] == 100
    # per-gear keys accept one value or a pair
    assert {"anyOf"} <= set(s["$defs"]["BodiesDoc"]["properties"]["mass_kg"]) or "anyOf" in json.dumps(
        s["$defs"]["BodiesDoc"]["properties"]["mass_kg"]
    )


def test_scene_reference_in_docs_is_generated_from_the_schema():
    """Regression: docs/scene-reference.md is the output of `gearwear scene --reference`."""
    assert (ROOT / "docs" / "scene-reference.md").read_text() == reference_markdown()


def test_cli_scene_schema_and_resolved_scene():
    r = cli("scene", "--schema")
    assert r.returncode == 0 and json.loads(r.stdout)["title"] == "gearwear scene"
    r = cli("scene", "paper-wear-severe")
    assert r.returncode == 0, r.stderr
    data = tomllib.loads(r.stdout)
    assert data["effects"]["bearing_clearance"]["clearance_um"] == 10
    assert data["bodies"]["mesh_damping_ratio"] == 0.05 and data["solver"]["method"] == "auto"
    r = cli("scene", "paper-default", "--set", "operating.speed_rpm=3000", "--json")
    assert json.loads(r.stdout)["operating"]["speed_rpm"] == 3000


def test_short_flags_are_aliases_of_set():
    a = cli("geometry", "paper-default", "--no-mesh", "--json", "--clearance-um", "25", "--torque-Nm", "60")
    b = cli(
        "geometry",
        "paper-default",
        "--no-mesh",
        "--json",
        "--set",
        "effects.bearing_clearance.clearance_um=25",
        "--set",
        "operating.torque_Nm=60",
    )
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    ja, jb = json.loads(a.stdout), json.loads(b.stdout)
    ja.pop("wall_s"), jb.pop("wall_s")
    assert ja == jb and ja["clearance_um"] == pytest.approx(25, rel=1e-12) and ja["torque_Nm"] == 60


@pytest.mark.parametrize("command", ["geometry", "stiffness", "verify", "calibrate", "simulate", "sweep", "scene"])
def test_every_command_takes_a_built_in_name_and_set(command):
    """A bad --set value is caught before any work, naming the key, for every command."""
    r = cli(command, "paper-wear-mild", "--set", "operating.speed_rpm=-1")
    assert r.returncode == 2
    assert r.stderr.strip() == "gearwear: error: operating.speed_rpm = -1 rpm: must be in (0, 1e+06] rpm"


def test_set_none_removes_an_effect_or_a_key():
    """Round trip (issue 24): there was no way to remove an effect with --set."""
    from gearwear.scene.overrides import apply_overrides

    base = builtin_scene_dict("paper-wear-severe")
    sc = scene_from_dict(
        apply_overrides(
            base, ["effects.backlash=none", "effects.bearing_clearance=none", "effects.centre_distance=none"]
        )
    )
    assert set(sc.effects) == {"mesh_stiffness", "wear"}
    sc = scene_from_dict(apply_overrides(base, ["bodies.inertia_kg_m2=none"]))
    assert sc.bodies.inertia_from == "blank radius of gyration"  # the key took its default
    assert (
        scene_from_dict(apply_overrides(base, ["effects.no_such_effect=none"])).effects == scene_from_dict(base).effects
    )  # removing what is absent changes nothing
    r = cli("scene", "paper-wear-severe", "--set", "effects.backlash=none", "--json")
    assert r.returncode == 0 and "backlash" not in json.loads(r.stdout)["effects"]


def test_stiffness_overlays_several_methods(tmp_path):
    r = cli("stiffness", "paper-default", "--method", "ishikawa", "energy", "iso6336", "--points", "32", "--json")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert [c["method"] for c in doc["curves"]] == ["ishikawa", "energy", "iso6336"]
    r = cli("stiffness", "paper-default", "--method", "ishikawa,nope")
    assert r.returncode == 2 and "--method = 'nope'" in r.stderr


def test_the_reference_names_keys_not_python_classes():
    """Regression (issue 24): the [flank] and [faults] sub-tables showed as
    `gearwear.scene.schema.ReliefDoc | None`. Every sub-table is a section of its own keys."""
    text = reference_markdown()
    assert "gearwear.scene.schema" not in text and "Doc |" not in text and "Doc " not in text
    for table in ("flank.tip_relief", "flank.root_relief", "faults.crack", "faults.spall", "blank.pinion"):
        assert f"### [{table}]" in text


def test_the_reference_states_every_default_in_toml_words():
    """A key without a default reads 'required', never a Python object's repr (the
    relief's start_diameter_mm showed `PydanticUndefined`); every row has its six cells
    (an optional key's type "str | None" split its row); every default cell is 'absent',
    'required' or a TOML value."""
    text = reference_markdown()
    assert "Undefined" not in text
    rows = [r for r in text.splitlines() if r.startswith("| `")]
    for row in rows:
        assert row.count(" | ") == 5, row  # six cells: a '|' in a type broke the row ("str | None")
        default = row.split(" | ")[4]
        assert default in ("absent", "required") or default.startswith("`"), row
    assert any(r.startswith("| `start_diameter_mm`") and " | required | " in r for r in rows)
