"""Tooth-root crack (geometry.crack, the analytic reduced-section model, the FE crack).

Independent truths: the ISO 30-deg point against a finite-difference tangent of a
densely sampled trochoid; the analytic bending compliance against a trapezoid-rule
integration of the reduced-section beam written out here; the FE crack against its
own refinement, the intact tooth (depth -> 0) and the physics of a free crack
(duplicated nodes, faces that open under load).
"""

import math

import numpy as np
import pytest

from gearwear.analytic import energy, ishikawa
from gearwear.core.validation import InputError
from gearwear.geometry.crack import Crack, crack_line, critical_fillet_point, max_depth_m, reduced_section
from gearwear.geometry.loading import load_points
from gearwear.geometry.polyline import project_to_polyline
from gearwear.geometry.profile import FILLET, INVOLUTE, TIP_LAND, RackGeometry, fillet_points, tooth_profile

from scenes import paper_pair_from

NU_45 = math.radians(45.0)


@pytest.fixture(scope="module")
def paper():
    pair = paper_pair_from({})  # the paper pair: module 5 mm, pinion 30 teeth
    prof = tooth_profile(pair.gear(0))
    return pair, prof


# -- geometry -------------------------------------------------------------------------


def test_critical_point_tangent_is_30_deg_by_finite_differences(paper):
    _, prof = paper
    x, y, t = critical_fillet_point(prof)
    assert x > 0
    assert math.degrees(math.atan2(abs(t[0]), t[1])) == pytest.approx(30.0, abs=1e-9)
    # independent: sample the trochoid densely, central-difference tangent, find 30 deg
    rack = RackGeometry.of(prof.gear)
    phi = np.linspace(rack.phi_root, rack.phi_tangent, 400_001)
    xy, _ = fillet_points(rack, phi)
    d = np.gradient(xy, axis=0)  # root -> tip
    ang = np.arctan2(np.abs(d[:, 0]), d[:, 1]) - math.radians(30.0)
    k = int(np.flatnonzero((ang[:-1] > 0) & (ang[1:] <= 0))[0])
    f = ang[k] / (ang[k] - ang[k + 1])
    ref = xy[k] + f * (xy[k + 1] - xy[k])
    assert np.hypot(x - ref[0], y - ref[1]) <= 1e-9 * math.hypot(*ref)


def test_critical_point_lies_on_the_fillet(paper):
    _, prof = paper
    x, y, _ = critical_fillet_point(prof)
    pr = project_to_polyline(np.array([[x, y]]), prof.xy)
    assert pr.distance[0] <= 0.2e-6 + 1e-12  # the profile polyline's chord sag
    seg = int(pr.segment[0])
    assert prof.region[seg] == FILLET and prof.region[seg + 1] == FILLET
    assert prof.gear.root_radius_m < math.hypot(x, y) < prof.form_radius_m


def test_crack_line_convention_and_limits(paper):
    _, prof = paper
    mouth, tip = crack_line(prof, Crack(1e-3, NU_45))
    x, y, _ = critical_fillet_point(prof)
    assert np.allclose(mouth, [x, y], rtol=0, atol=1e-15)
    d = tip - mouth
    assert np.hypot(*d) == pytest.approx(1e-3, rel=1e-12)
    assert d[0] < 0 and d[1] < 0  # inward and downward
    assert math.atan2(-d[0], -d[1]) == pytest.approx(NU_45, rel=1e-12)  # angle to the centre line
    q_max = max_depth_m(prof, NU_45)
    assert q_max == pytest.approx(x / math.sin(NU_45), rel=1e-12)  # tip on the centre line
    assert crack_line(prof, Crack(q_max, NU_45))[1][0] == pytest.approx(0.0, abs=1e-15)
    for bad, key in (
        (Crack(0.0, NU_45), "depth_m"),
        (Crack(-1e-3, NU_45), "depth_m"),
        (Crack(1.001 * q_max, NU_45), "depth_m"),
        (Crack(float("nan"), NU_45), "depth_m"),
        (Crack(1e-3, 0.0), "angle_rad"),
        (Crack(1e-3, 1.6), "angle_rad"),
    ):
        with pytest.raises(InputError, match=key) as exc:
            crack_line(prof, bad)
        assert "\n" not in str(exc.value) and "must be in" in str(exc.value)


# -- analytic reduced-section model ----------------------------------------------------

MODELS = [pytest.param(ishikawa, id="ishikawa"), pytest.param(energy, id="energy")]


@pytest.fixture(scope="module")
def radii(paper):
    pair, prof = paper
    g = pair.gear(0)
    return np.linspace(1.02 * g.base_radius_m, g.tip_radius_m, 5)


@pytest.mark.parametrize("model", MODELS)
def test_crack_none_is_bit_identical(paper, radii, model):
    pair, prof = paper
    a = model.tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m)
    b = model.tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m, crack=None)
    assert np.array_equal(a.total_m_per_N, b.total_m_per_N)


@pytest.mark.parametrize("model", MODELS)
def test_depth_to_zero_gives_intact_tooth(paper, radii, model):
    pair, prof = paper
    c0 = model.tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m).total_m_per_N
    rel = []
    for q in (1e-6, 1e-8, 1e-10):
        c = model.tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m, crack=Crack(q, NU_45))
        rel.append(float(np.max(np.abs(c.total_m_per_N / c0 - 1.0))))
    # the residual at q -> 0 is the 0.2 um chord sag of the profile polyline at the mouth
    assert rel[-1] <= 1e-9
    assert rel[0] >= rel[-1]


@pytest.mark.parametrize("model", MODELS)
def test_compliance_rises_monotonically_with_depth(paper, radii, model):
    pair, prof = paper
    depths = np.array([0.25, 0.5, 1.0, 2.0, 4.0, 6.0]) * 1e-3
    c = np.array(
        [
            model.tooth_compliance(
                prof, radii, pair.materials[0], pair.face_width_m, crack=Crack(q, NU_45)
            ).total_m_per_N
            for q in depths
        ]
    )
    c0 = model.tooth_compliance(prof, radii, pair.materials[0], pair.face_width_m).total_m_per_N
    assert np.all(c[0] > c0)
    assert np.all(np.diff(c, axis=0) > 0)


def test_bending_at_tip_matches_hand_integration(paper):
    """1/k_b = int_{y_M}^{y_F} [cos w (y_F - y) - sin w x_F]^2 / (E I(y)) dy with
    I = t_c^3 b / 12, t_c = min(h_x, h_q) + h_x above the tip height: trapezoid rule on
    a fine uniform grid, thickness read from the profile points directly."""
    pair, prof = paper
    g, E, b = pair.gear(0), pair.materials[0].youngs_modulus_Pa, pair.face_width_m
    crack = Crack(1.5e-3, NU_45)
    _, tip = crack_line(prof, crack)
    h_q, y_q = tip
    sel = np.isin(prof.region, (FILLET, INVOLUTE, TIP_LAND))
    xf, yf = prof.xy[sel, 0], prof.xy[sel, 1]
    o = np.argsort(yf)
    R = np.array([g.tip_radius_m])
    lp = load_points(prof, R)
    y_M = g.root_radius_m
    y = np.linspace(y_M, lp.y_m[0], 400_001)
    hx = np.interp(y, yf[o], xf[o])
    t = np.where((y >= y_q) & (hx > h_q), h_q + hx, 2 * hx)
    w, xF, yF = lp.w_rad[0], lp.x_m[0], lp.y_m[0]
    f = (math.cos(w) * (yF - y) - math.sin(w) * xF) ** 2 / (E * t**3 * b / 12)
    hand = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(y)))
    intact = np.sum(0.5 * ((f * t**3 / (2 * hx) ** 3)[1:] + (f * t**3 / (2 * hx) ** 3)[:-1]) * np.diff(y))
    assert hand > 1.01 * intact  # the crack matters in this case
    en = energy.tooth_compliance(prof, R, pair.materials[0], b, crack=crack).bending_m_per_N[0]
    ish = ishikawa.tooth_compliance(prof, R, pair.materials[0], b, n_slices=20_000, crack=crack).bending_m_per_N[0]
    assert en == pytest.approx(hand, rel=1e-4)
    assert ish == pytest.approx(hand, rel=1e-4)


def test_reduced_section_breaks_are_where_the_loss_is_not_smooth(paper):
    _, prof = paper
    red = reduced_section(prof, Crack(1e-3, NU_45))
    br = red.breaks_m()
    assert br[0] == red.y_q_m
    # at each kink above the tip the loaded half thickness equals h_q
    assert np.allclose(np.interp(br[1:], red.y_m, red.x_m), red.h_q_m, rtol=0, atol=1e-12)
    assert red.loss_m(np.array([red.y_q_m - 1e-9]))[0] == 0.0
    assert red.loss_m(np.array([red.y_q_m + 1e-9]))[0] > 0.0


# -- FE: the crack as a cut with free faces --------------------------------------------

FE_DEPTHS_MM = (0.05, 0.5, 1.0, 2.0)
TIP_SIZES_M = (0.2e-3, 0.05e-3, 0.0125e-3)  # refinement ratio 4


@pytest.fixture(scope="module")
def fe_runs(paper):
    """Single-tooth FE of the paper pinion at the default level, 3 load positions (SAP,
    mid, top): intact, the depths of FE_DEPTHS_MM, and the 1 mm crack at TIP_SIZES_M."""
    from gearwear.fem.tooth import single_tooth_compliance

    pair, _ = paper
    run = dict(positions=3, mesh_scale=1.0)
    out = {"intact": single_tooth_compliance(pair, **run)}
    for q in FE_DEPTHS_MM:
        out[q] = single_tooth_compliance(pair, crack=Crack(q * 1e-3, NU_45), **run)
    out["tip"] = [
        single_tooth_compliance(pair, crack=Crack(1e-3, NU_45), crack_tip_size_m=h, **run) for h in TIP_SIZES_M
    ]
    return out


def test_fe_crack_none_keeps_the_intact_model(paper, fe_runs):
    from gearwear.fem.tooth import single_tooth_compliance

    pair, _ = paper
    r = single_tooth_compliance(pair, positions=3, mesh_scale=1.0, crack=None)
    assert np.array_equal(r.fem_compliance_um_per_N_per_mm, fe_runs["intact"].fem_compliance_um_per_N_per_mm)
    assert r.crack is None and r.crack_mouth_opening_m_per_N is None


def test_fe_converges_under_crack_tip_refinement(fe_runs):
    c = np.array([r.fem_compliance_um_per_N_per_mm for r in fe_runs["tip"]])
    d1, d2 = np.abs(c[1] - c[0]), np.abs(c[2] - c[1])
    order = np.log(d1 / d2) / np.log(4.0)
    print(
        f"\ncrack-tip refinement (1 mm crack; tip {[h * 1e3 for h in TIP_SIZES_M]} mm): "
        f"relative differences {(d1 / c[2]).tolist()} then {(d2 / c[2]).tolist()}, observed order {order.tolist()}"
    )
    assert np.all(d2 < d1)
    assert np.all(d2 / c[2] < 1e-3)


def test_fe_tends_to_intact_as_depth_goes_to_zero(fe_runs):
    c0 = fe_runs["intact"].fem_compliance_um_per_N_per_mm
    c = fe_runs[0.05].fem_compliance_um_per_N_per_mm
    print(f"\n0.05 mm crack vs intact: {(c / c0 - 1).tolist()}")
    assert np.all(np.abs(c / c0 - 1) < 0.01)


def test_fe_compliance_rises_with_depth(fe_runs):
    c = np.array(
        [fe_runs["intact"].fem_compliance_um_per_N_per_mm]
        + [fe_runs[q].fem_compliance_um_per_N_per_mm for q in (0.5, 1.0, 2.0)]
    )
    print(f"\nFE compliance um/(N/mm), intact, 0.5, 1, 2 mm (rows) x SAP, mid, top:\n{c}")
    assert np.all(np.diff(c, axis=0) > 0)


def test_fe_crack_faces_are_free(paper, fe_runs):
    from gearwear.fem.tooth import tooth_mesh

    pair, _ = paper
    for order, scale in ((2, 1.0), (1, 2.0)):
        tm = tooth_mesh(pair, crack=Crack(1e-3, NU_45), order=order, mesh_scale=scale)
        m = tm.mesh
        f = tm.gear_mesh.boundaries["crack"]
        assert set(f.tolist()) <= set(m.boundary_facets().tolist())
        # every crack node but the tip appears twice (both faces), P2 mid-side nodes too
        nodes = np.unique(m.facets[:, f])
        if order == 2:
            nodes = np.concatenate([nodes, m.nvertices + f])
        xy = np.round(m.doflocs[:, nodes].T / 1e-12).astype(np.int64)
        _, counts = np.unique(xy, axis=0, return_counts=True)
        assert np.sum(counts == 1) == 1 and np.all(counts[counts != 1] == 2)
        assert len(f) % 2 == 0 and len(f) >= 4
        mouth, tip = tm.crack_xy
        assert np.sum(np.linalg.norm(m.p.T - tip, axis=1) < 1e-12) == 1
        assert np.sum(np.linalg.norm(m.p.T - mouth, axis=1) < 1e-12) == 2
    # the tension-side crack opens under every load position, more for deeper cracks
    cmod = np.array([fe_runs[q].crack_mouth_opening_m_per_N for q in (0.5, 1.0, 2.0)])
    assert np.all(cmod > 0) and np.all(np.diff(cmod, axis=0) > 0)


def test_fe_over_analytic_increase_is_reported(paper, fe_runs):
    """Not a calibration: the ratio of the FE compliance increase to the analytic one
    (reduced-section model, same radii, same profile), printed for the record; only
    its sign is asserted (both models stiffen nothing)."""
    pair, prof = paper
    R = fe_runs["intact"].radius_m
    fe0 = fe_runs["intact"].fem_compliance_um_per_N_per_mm
    lines = []
    for model in (energy, ishikawa):
        a0 = model.tooth_compliance(prof, R, pair.materials[0], pair.face_width_m).total_m_per_N
        for q in (0.5, 1.0, 2.0):
            a = model.tooth_compliance(
                prof, R, pair.materials[0], pair.face_width_m, crack=Crack(q * 1e-3, NU_45)
            ).total_m_per_N
            d_an = (a - a0) * 1e9 * pair.face_width_m  # m/N -> um/(N/mm)
            d_fe = fe_runs[q].fem_compliance_um_per_N_per_mm - fe0
            ratio = d_fe / d_an
            lines.append(
                f"{model.__name__.rsplit('.', 1)[-1]:9s} q = {q} mm: FE/analytic increase {ratio.round(3).tolist()}"
            )
            assert np.all(ratio > 0)
    print("\nradii mm " + str((R * 1e3).round(3).tolist()) + "\n" + "\n".join(lines))


def test_mesher_rejects_bad_crack_input_and_is_deterministic(paper):
    from gearwear.fem.mesh import MeshError, MeshSizes, mesh_full_gear
    from gearwear.fem.tooth import tooth_mesh

    pair, _ = paper
    n = 64
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    square = np.column_stack([np.cos(ang), np.sin(ang)]) * 0.05  # a polygon "gear"
    sizes = MeshSizes(global_m=5e-3)
    for crack_xy, match in (
        ([[0.049, 0.0], [0.04, 0.0]], "not an outline point"),
        ([square[0], [0.06, 0.0]], "not inside"),
        ([square[0], [0.005, 0.0]], "not inside"),
    ):  # in the bore
        with pytest.raises(MeshError, match=match):
            mesh_full_gear(square, 0.01, sizes, order=1, crack_xy=np.array(crack_xy))
    with pytest.raises(MeshError, match="crack_tip_size_m"):
        mesh_full_gear(square, 0.01, sizes, order=1, crack_tip_size_m=1e-4)
    a, b = (tooth_mesh(pair, crack=Crack(1e-3, NU_45), mesh_scale=2.0) for _ in range(2))
    assert np.array_equal(a.mesh.doflocs, b.mesh.doflocs) and np.array_equal(a.mesh.t, b.mesh.t)
