"""Wear depth: pure rolling at the pitch point, Archard/Hertz identities, offsets."""

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from gearwear.core.validation import InputError
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.profile import INVOLUTE, involute_points, tooth_profile
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import (
    WearSpec,
    hertz_half_width,
    hertz_load_integral,
    specific_sliding,
    wear_on_line_of_action,
    worn_profiles,
)
from gearwear.scene.model import parse_wear_arg, wear_from_dict


@pytest.fixture(scope="module")
def mesh():
    pair = default_pair()
    return MeshGeometry(pair, pair.centre_distance_m)


@pytest.mark.parametrize("model", ["archard", "paper_eq1"])
def test_zero_at_pitch_point_and_growing_toward_ends(mesh, model):
    spec = WearSpec(hours=100, model=model)
    h1, h2 = wear_on_line_of_action(mesh, spec, np.array([mesh.pitch_point_m]))
    assert h1[0] == 0.0 and h2[0] == 0.0
    B, D = mesh.single_contact_limits_m
    band = 0.3e-3  # the Hertz band (2 a < 0.15 mm here) smooths the load steps over this
    # within each load zone the depth grows with the distance from the pitch point
    for lo, hi in [(mesh.path_start_m + band, B - band), (B + band, mesh.pitch_point_m)]:
        d = np.linspace(lo, hi, 200)
        assert np.all(np.diff(wear_on_line_of_action(mesh, spec, d)[0]) < 0)
    for lo, hi in [(mesh.pitch_point_m, D - band), (D + band, mesh.path_end_m - band)]:
        d = np.linspace(lo, hi, 200)
        assert np.all(np.diff(wear_on_line_of_action(mesh, spec, d)[0]) > 0)
    # the deepest wear is at the ends of the path (root and tip of the flank)
    d = np.linspace(mesh.path_start_m, mesh.path_end_m, 20001)
    h = wear_on_line_of_action(mesh, spec, d)[0]
    assert min(d[np.argmax(h)] - d[0], d[-1] - d[np.argmax(h)]) < band


def test_specific_sliding_textbook(mesh):
    # at the tip of the pinion (E) zeta_1 = 1 - rho2/rho1 for equal gears
    zeta1, zeta2 = specific_sliding(mesh, np.array([mesh.path_end_m]))
    rho1 = mesh.path_end_m
    rho2 = mesh.line_of_action_m - rho1
    assert zeta1[0] == pytest.approx(1 - rho2 / rho1, rel=1e-14)
    assert zeta2[0] == pytest.approx(1 - rho1 / rho2, rel=1e-14)


def test_hertz_identities(mesh):
    """Hertz line contact: p0 = 2 w / (pi a) and the pressure integrates to w."""
    w = 28_000.0
    d = np.array([mesh.pitch_point_m])
    a = hertz_half_width(mesh, d, w)
    E = 206e9
    e_star = E / (2 * (1 - 0.3**2))
    R = mesh.pitch_point_m * (mesh.line_of_action_m - mesh.pitch_point_m) / mesh.line_of_action_m
    assert a[0] == pytest.approx(math.sqrt(4 * w * R / (math.pi * e_star)), rel=1e-14)
    p0 = 2 * w / (math.pi * a)
    assert hertz_load_integral(a, p0)[0] == pytest.approx(w, rel=1e-12)


def test_monotone_and_linear_in_running_time(mesh):
    d = np.linspace(mesh.path_start_m, mesh.path_end_m, 101)
    h10 = wear_on_line_of_action(mesh, WearSpec(hours=10), d)[0]
    h20 = wear_on_line_of_action(mesh, WearSpec(hours=20), d)[0]
    assert np.all(h20 >= h10)
    assert np.allclose(h20, 2 * h10, rtol=1e-12)
    # Archard per contact on a single-contact point: k |zeta| w
    spec = WearSpec(hours=1)
    B, D = mesh.single_contact_limits_m
    dd = 0.5 * (D + mesh.pitch_point_m)
    n = 1200 * 60
    w = 40.0 / default_pair().gear(0).base_radius_m / 0.02
    z1 = specific_sliding(mesh, np.array([dd]))[0][0]
    assert wear_on_line_of_action(mesh, spec, np.array([dd]))[0][0] == pytest.approx(
        5.3e-16 * abs(z1) * w * n, rel=1e-12
    )


def test_phases_scale_to_their_maximum_depth(mesh):
    pair = default_pair()
    for phase, depth in [("mild", 10e-6), ("severe", 30e-6)]:
        (_, _), (w1, w2) = worn_profiles(pair, WearSpec(phase=phase))
        assert w1.depth.max() == pytest.approx(depth, rel=1e-12)
        d = np.linspace(mesh.path_start_m, mesh.path_end_m, 40001)
        assert wear_on_line_of_action(mesh, WearSpec(phase=phase), d)[0].max() == pytest.approx(depth, rel=1e-12)
    (_, _), (w1, _) = worn_profiles(pair, WearSpec(phase="unworn"))
    assert not w1.is_worn


def test_uniform_depth_turns_the_involute_by_h_over_rb():
    """An involute moved along its normal by a constant h is the involute turned by
    h / r_b: the arc thickness at every radius falls by h R / r_b, i.e. exactly h on
    the base circle."""
    pair = default_pair()
    g = pair.gear(0)
    nom = tooth_profile(g)
    h = 20e-6
    depth = np.where(nom.region == INVOLUTE, h, 0.0)
    worn = nom.worn(depth)
    inv = nom.region == INVOLUTE
    R = worn.radius[inv]
    beta_w = np.arctan2(worn.xy[inv, 0], worn.xy[inv, 1])
    # nominal half-angle at the same radius from the exact involute equation
    u = np.sqrt((R / g.base_radius_m) ** 2 - 1)
    beta_n = nom.psi_b - (u - np.arctan(u))
    # worn thickness = nominal thickness - depth (one flank worn), measured on the base circle
    thickness_loss_on_base_circle = (beta_n - beta_w) * g.base_radius_m
    assert np.max(np.abs(thickness_loss_on_base_circle - h)) < 1e-9
    assert np.max(np.abs((beta_n - beta_w) * R - h * R / g.base_radius_m)) < 1e-9


def test_worn_points_lie_at_depth_from_nominal_flank():
    pair = default_pair()
    (nom, _), (worn, _) = worn_profiles(pair, WearSpec(phase="severe"))
    g = pair.gear(0)
    inv = np.flatnonzero((nom.region == INVOLUTE) & (worn.depth > 0))
    for i in inv[:: max(1, len(inv) // 25)]:
        p = worn.xy[i]

        def dist(u):
            q, _ = involute_points(g.base_radius_m, nom.psi_b, np.array([u]))
            return float(np.linalg.norm(q[0] - p))

        u0 = nom.roll[i]
        res = minimize_scalar(dist, bounds=(u0 - 0.05, u0 + 0.05), method="bounded", options={"xatol": 1e-12})
        assert res.fun == pytest.approx(worn.depth[i], abs=1e-9)


def test_wear_that_consumes_the_tooth_is_a_clear_error():
    pair = default_pair()
    prof = tooth_profile(pair.gear(0))
    depth = np.where(prof.region == INVOLUTE, 12e-3, 0.0)
    with pytest.raises(InputError, match=r"wear depth = .* um: consumes the tooth"):
        prof.worn(depth)
    # through the wear models it never gets that far: the depth limit refuses it first
    with pytest.raises(InputError, match=r"^max_depth_m = 0.012 m: must be in \[0, "):
        worn_profiles(pair, WearSpec(max_depth_m=12e-3))


def _half_thickness_iso(g, R):
    """ISO 21771 half arc thickness at radius R on the involute:
    s_R / 2 = R (s / (2 r) + inv(alpha) - inv(alpha_R)), cos(alpha_R) = r_b / R."""
    aR = math.acos(g.base_radius_m / R)
    a = g.pressure_angle_rad
    return R * (g.pitch_thickness_m / (2 * g.pitch_radius_m) + math.tan(a) - a - (math.tan(aR) - aR))


def test_absurd_wear_depth_is_refused_with_the_allowed_maximum(mesh):
    """5 mm of wear on a 5 mm module tooth: one line naming effects.wear.max_depth_um, the
    value, the unit and the maximum for this pair, 1/3 of the local half thickness where
    the flank wears deepest (the radius it names lies on the active flank)."""
    import re

    from gearwear.cli import main

    with pytest.raises(InputError) as err:
        wear_from_dict({"max_depth_um": 5000.0}, pair=default_pair())
    msg = str(err.value)
    m = re.fullmatch(
        r"effects\.wear\.max_depth_um = 5000 um: must be in \[0, ([\d.]+)\] um, the deepest wear "
        r"accepted is 1/3 of the pinion's half tooth thickness \(([\d.]+) mm\) at r = ([\d.]+) mm, "
        r"where its flank wears deepest",
        msg,
    )
    assert m, msg
    limit_um, half_mm, R_mm = (float(v) for v in m.groups())
    g = default_pair().gear(0)
    sap, tip = mesh.start_of_active_profile_m[0], g.tip_radius_m
    assert sap - 0.2e-3 <= R_mm * 1e-3 <= tip  # within the Hertz band of the active flank
    half = _half_thickness_iso(g, R_mm * 1e-3)
    assert half_mm == pytest.approx(half * 1e3, abs=1e-3)
    assert limit_um == pytest.approx(half / 3 * 1e6, abs=2.0)
    assert 1000 < limit_um < 2000  # a third of a ~4.7 mm half thickness
    from gearwear.scene.schema import WearDoc

    assert f"{limit_um:g} um for the paper pair" in (WearDoc.model_fields["max_depth_um"].description or "")
    assert wear_from_dict({"max_depth_um": limit_um}, pair=default_pair()).max_depth_m == pytest.approx(limit_um * 1e-6)
    # the command line: one line, the alias named, exit 2
    assert main(["geometry", "--no-mesh", "--wear", "5000um"]) == 2


def test_running_hours_beyond_severe_are_flagged_and_absurd_ones_refused(mesh):
    from gearwear.jobs import geometry as geometry_job
    from gearwear.scene.model import Scene

    spec = wear_from_dict({"hours": 500.0}, pair=default_pair())
    h1, _ = wear_on_line_of_action(mesh, spec, np.linspace(mesh.path_start_m, mesh.path_end_m, 4001))
    assert 30e-6 < h1.max() < 1e-3  # beyond the severe phase, far below the tooth
    scene = Scene.load(None, {"effects.wear": {"hours": 500.0}})
    res = geometry_job.compute(scene, scene.wear, 0.0, 40.0, build_mesh=False)
    warn = res.summary()["warnings"]
    assert len(warn) == 1 and "beyond the 'severe' phase (30 um)" in warn[0] and "500 h" in warn[0]
    assert (
        geometry_job.compute(scene, wear_from_dict("severe"), 0.0, 40.0, build_mesh=False).summary()["warnings"] == []
    )
    with pytest.raises(InputError, match=r"^effects\.wear\.hours = 5e\+06 h: must be in \[0, [\d.]+\] h"):
        Scene.load(None, {"effects.wear": {"hours": 5e6}})


def test_wear_inputs():
    assert parse_wear_arg("severe").phase == "severe"
    assert parse_wear_arg("25um").max_depth_m == pytest.approx(25e-6)
    assert parse_wear_arg("100h").hours == 100
    with pytest.raises(InputError, match="--wear"):
        parse_wear_arg("heavy")
    with pytest.raises(InputError, match="did you mean effects.wear.phase"):
        wear_from_dict({"phas": "mild"})
    with pytest.raises(InputError, match=r"max_depth_um = -3 um: must be in \[0, 20000\] um"):
        wear_from_dict({"max_depth_um": -3})
