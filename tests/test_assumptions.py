"""Nothing silently assumed: every value a result uses that the scene did not give is listed
(console ``assumed:`` lines, ``assumptions`` in --json, the summaries and the manifest), and
the listed value is the one the run used: writing it into the scene changes no result.

Run on a user's own unequal, profile-shifted pair from an (almost) empty scene file."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from gearwear.scene.assumptions import for_command, scene_assumptions
from gearwear.scene.model import scene_from_dict
from gearwear.scene.overrides import set_key

#: the least a scene gives: its pair and its operating point
MINIMAL = {
    "pair": {"teeth": [23, 47], "module_mm": 3.0, "face_width_mm": 30.0},
    "operating": {"speed_rpm": 1500, "torque_Nm": 120},
}


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "gearwear.cli", *args], capture_output=True, text=True, cwd=cwd)


def _keys(items):
    return {a.key for a in items}


def test_a_minimal_scene_lists_every_default_it_rests_on():
    sc = scene_from_dict({**MINIMAL, "effects": {"wear": {"hours": 100}}})
    keys = _keys(scene_assumptions(sc))
    assert {
        "pair.pressure_angle_deg",
        "pair.addendum_coefficient",
        "pair.dedendum_coefficient",
        "pair.rack_tip_radius_coefficient",
        "pair.profile_shift",
        "pair.hub_radius_mm",
        "pair.centre_distance_mm",
        "material.youngs_modulus_GPa",
        "material.poisson_ratio",
        "material.density_kg_per_m3",
        "bodies.mass_kg",
        "bodies.inertia_kg_m2",
        "bodies.bearing_damping_ratio",
        "bodies.mesh_damping_ratio",
        "effects.mesh_stiffness",
        "effects.wear.model",
        "effects.wear.archard_k_m2_per_N",
        "effects.wear.taper_mm",
    } <= keys
    # what a command does not use, it does not list: the stiffness uses no bodies or damping
    stiff = _keys(for_command(sc, "stiffness"))
    assert "bodies.mass_kg" not in stiff and "bodies.mesh_damping_ratio" not in stiff
    assert "material.youngs_modulus_GPa" in stiff and "material.youngs_modulus_GPa" not in _keys(
        for_command(sc, "geometry")
    )


def test_the_built_in_paper_scenes_state_their_bodies_and_pair():
    """The paper's values are stated in the built-in scenes, not assumed: no pair, material or
    body line (the ISO K_v inputs of a run-up remain)."""
    from gearwear.scene.model import builtin_scene

    for name in ("paper-default", "paper-wear-severe", "paper-clearance"):
        keys = _keys(scene_assumptions(builtin_scene(name)))
        assert not {k for k in keys if k.startswith(("pair.", "material.", "bodies."))} - {"pair.centre_distance_mm"}


@pytest.mark.parametrize("command", ["geometry", "stiffness", "simulate"])
def test_each_listed_value_is_what_the_run_used(command):
    """Give every assumed value explicitly: the assumption list empties (for those keys) and the
    results are the same numbers."""
    from gearwear.jobs.geometry import compute
    from gearwear.jobs.simulate import run, stiffness_input

    doc = {
        **MINIMAL,
        "bodies": {"bearing_stiffness_N_per_m": 5e8},
        "effects": {"mesh_stiffness": {"source": "analytic"}},
        "solver": {"duration_s": 0.04, "discard_s": 0.02},
    }
    sc = scene_from_dict(doc)
    given = json.loads(json.dumps(doc))
    for a in for_command(sc, command):
        # the density only makes the masses, which are then given too (giving both is refused)
        if a.key.startswith(("pair.", "material.", "bodies.")) and a.key != "material.density_kg_per_m3":
            set_key(given, a.key, a.value)
    sc2 = scene_from_dict(given)
    left = {a.key for a in for_command(sc2, command)} & {a.key for a in for_command(sc, command)}
    assert not {k for k in left if k.startswith(("pair.", "material.", "bodies."))} - {"pair.centre_distance_mm"}
    if command == "geometry":
        a, b = (compute(s, None, 0.0, 120.0, build_mesh=False).summary() for s in (sc, sc2))
        for key in ("contact_ratio", "centre_distance_mm", "backlash_um", "base_radius_mm"):
            assert a[key] == pytest.approx(b[key], rel=1e-12)
    elif command == "stiffness":
        assert stiffness_input(sc).mean_N_per_m == pytest.approx(stiffness_input(sc2).mean_N_per_m, rel=1e-12)
    else:
        h1, h2 = (run(s).summary()["harmonics"]["F_m_N"] for s in (sc, sc2))
        # the inertias are listed to 6 digits: the harmonics agree to that
        assert h1 == pytest.approx(h2, rel=1e-5)


def test_cli_prints_lists_and_records_the_assumptions(tmp_path):
    scene = tmp_path / "mine.toml"
    scene.write_text(
        '[pair]\nteeth = [23, 47]\nmodule_mm = 3.0\nface_width_mm = 30.0\n'
        '[operating]\nspeed_rpm = 1500\ntorque_Nm = 120\n'
    )
    r = cli("geometry", str(scene), "--no-mesh", "--out", str(tmp_path / "g"))
    assert r.returncode == 0, r.stderr
    lines = [ln for ln in r.stdout.splitlines() if ln.startswith("assumed: ")]
    assert any(ln.startswith("assumed: bodies.mass_kg = [") for ln in lines)
    assert any(ln.startswith("assumed: pair.hub_radius_mm = [") for ln in lines)
    man = json.loads((tmp_path / "g" / "manifest.json").read_text())
    summary = json.loads((tmp_path / "g" / "summary.json").read_text())
    assert [a["key"] for a in man["provenance"]["assumptions"]] == [a["key"] for a in summary["assumptions"]]
    assert len(lines) == len(summary["assumptions"])
    r = cli("stiffness", str(scene), "--points", "16", "--json")
    doc = json.loads(r.stdout)
    assert r.returncode == 0 and "material.youngs_modulus_GPa" in {a["key"] for a in doc["assumptions"]}
    assert not any(ln.startswith("assumed:") for ln in r.stdout.splitlines())  # --json: one JSON object


def test_dynamics_without_bearing_stiffness_is_refused_before_any_work(tmp_path):
    """The bearing stiffness sets the lateral modes and spans 1e7-1e10 N/m between designs: the
    dynamic commands require it (one line, exit 2, nothing written); geometry and stiffness do not."""
    scene = tmp_path / "mine.toml"
    scene.write_text(
        '[pair]\nteeth = [23, 47]\nmodule_mm = 3.0\nface_width_mm = 30.0\n'
        '[operating]\nspeed_rpm = 1500\ntorque_Nm = 120\n'
    )
    for args in (
        ["simulate", str(scene)],
        ["sweep", str(scene), "--set", "operating.speed_rpm=1000,2000"],
        ["runup", str(scene), "--set", "operating.speed_rpm=1000:2000:3"],
    ):
        r = cli(*args, "--out", str(tmp_path / "o"))
        assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
        assert r.stderr.startswith("gearwear: error: bodies.bearing_stiffness_N_per_m: missing")
        assert not (tmp_path / "o").exists()
    assert cli("stiffness", str(scene), "--points", "16").returncode == 0


def test_a_scene_without_its_pair_says_what_a_scene_needs(tmp_path):
    scene = tmp_path / "empty.toml"
    scene.write_text("")
    r = cli("geometry", str(scene))
    assert r.returncode == 2 and r.stderr.startswith("gearwear: error: pair: missing; a scene names its own gear pair")
    scene.write_text("[pair]\nteeth = [23, 47]\nmodul_mm = 3\n")
    r = cli("geometry", str(scene))
    assert "pair.modul_mm: unknown key; did you mean pair.module_mm?" in r.stderr  # the typo before "missing"
