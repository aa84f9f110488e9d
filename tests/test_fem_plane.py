"""The scene key fem.plane: validated, honoured by every FE path and by the analytic tooth
beams, refused where no model with a 2D state runs, listed as assumed where a result uses its
default."""

import pytest

from gearwear.cli import main
from gearwear.core.validation import InputError
from gearwear.scene.assumptions import for_command
from gearwear.scene.checks import dynamics_fem_plane, fem_plane, resolved_dict
from gearwear.scene.model import scene_from_dict

from scenes import with_paper

BEARING = {"bodies": {"bearing_stiffness_N_per_m": 1e9}}


def scene(**tables):
    return scene_from_dict(with_paper({**BEARING, **tables}))


def test_default_and_given():
    """The default is "auto": plane stress below b/m = 4.3 (the paper pair, b/m 4), plane strain
    from there on (the 3D check's crossover, reports/plane); a given state is taken as given."""
    from gearwear.scene.checks import PLANE_STRAIN_FROM_B_OVER_M

    assert resolved_dict(scene().doc)["fem"] == {"plane": "auto"}
    assert fem_plane(scene().doc, True, "gearwear verify") == "stress"  # b/m = 4
    wide = scene(pair={"face_width_mm": 5.0 * PLANE_STRAIN_FROM_B_OVER_M})  # b/m = 4.3
    assert fem_plane(wide.doc, True, "gearwear verify") == "strain"
    s = scene(fem={"plane": "strain"})
    assert fem_plane(s.doc, True, "gearwear verify") == "strain"
    assert fem_plane(scene(fem={"plane": "stress"}, pair={"face_width_mm": 100.0}).doc, True, "x") == "stress"
    assert fem_plane(None, True, "x") == "stress"


def test_bad_value_is_one_line_naming_key_and_choices():
    with pytest.raises(InputError) as e:
        scene(fem={"plane": "plain"})
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("fem.plane") and "stress" in msg and "strain" in msg
    with pytest.raises(InputError, match="fem.plan"):
        scene(fem={"plan": "strain"})


def test_refused_where_no_fe_model_runs():
    s = scene(fem={"plane": "strain"})
    with pytest.raises(InputError, match="fem.plane = 'strain': not used: gearwear geometry"):
        fem_plane(s.doc, False, "gearwear geometry")
    # the dynamics use it with an analytic or FE mesh-stiffness source, and with a constant
    # taken from the analytic mean; not with a user table or a given constant
    with pytest.raises(InputError, match="not used"):
        dynamics_fem_plane(
            scene(fem={"plane": "strain"}, effects={"mesh_stiffness": {"source": "constant", "value_N_per_m": 3e8}}).doc
        )
    for src in ("fem", "calibrated", "analytic"):
        assert (
            dynamics_fem_plane(scene(fem={"plane": "strain"}, effects={"mesh_stiffness": {"source": src}}).doc)
            == "strain"
        )
    assert dynamics_fem_plane(s.doc) == "strain"  # no [effects] mesh_stiffness: the analytic mean
    assert dynamics_fem_plane(scene(effects={"mesh_stiffness": {"source": "calibrated"}}).doc) == "stress"
    # absent, nothing to refuse
    assert dynamics_fem_plane(scene().doc) == "stress"


def test_cli_refuses_it_without_fe(capsys):
    assert main(["geometry", "--no-mesh", "--set", "fem.plane=strain"]) != 0
    assert "fem.plane = 'strain': not used: gearwear geometry" in capsys.readouterr().err
    assert main(["stiffness", "--method", "iso6336", "--set", "fem.plane=strain"]) != 0
    assert "gearwear stiffness --method iso6336" in capsys.readouterr().err
    # the analytic tooth beams take it (tests/test_analytic_plane.py checks what it changes)
    assert main(["stiffness", "--method", "ishikawa", "--set", "fem.plane=strain"]) == 0


def test_the_dynamics_pass_it_to_the_pair_fe(monkeypatch):
    import gearwear.fem.pair as fp
    from gearwear.jobs import simulate as simulate_job

    seen = {}

    class Stop(Exception):
        pass

    def fake(*a, **k):
        seen.update(k)
        raise Stop

    monkeypatch.setattr(fp, "pair_contact", fake)
    with pytest.raises(Stop):
        simulate_job.stiffness_input(scene(fem={"plane": "strain"}, effects={"mesh_stiffness": {"source": "fem"}}))
    assert seen["plane"] == "strain"


def test_calibrated_tables_are_keyed_by_it():
    from gearwear.stiffness.calibration import table_inputs

    p = scene().pair
    a, b = (table_inputs(p, None, 0.0, 40.0, 360, 21, plane=x) for x in ("stress", "strain"))
    assert a["fe"]["plane"] == a["fe_pair"]["plane"] == "stress"
    assert b["fe"]["plane"] == b["fe_pair"]["plane"] == "strain"


def test_assumed_where_an_fe_result_uses_the_default():
    keys = lambda s, cmd: [a.key for a in for_command(s, cmd)]  # noqa: E731
    assert "fem.plane" in keys(scene(), "verify")
    assert "fem.plane" in keys(scene(), "stiffness-fem")
    assert "fem.plane" in keys(scene(), "stiffness")  # the analytic tooth beams use it
    assert "fem.plane" not in keys(scene(), "stiffness-iso")  # ISO 6336 alone has no 2D state
    assert "fem.plane" not in keys(scene(fem={"plane": "stress"}), "verify")
    assert "fem.plane" in keys(scene(), "simulate")  # a constant from the analytic mean
    assert "fem.plane" not in keys(
        scene(effects={"mesh_stiffness": {"source": "constant", "value_N_per_m": 3e8}}), "simulate"
    )
    assert "fem.plane" in keys(scene(effects={"mesh_stiffness": {"source": "calibrated"}}), "simulate")
