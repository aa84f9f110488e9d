"""Regression tests: pin the numbers README.md publishes; they are not independent
truths, see tests/test_*.py for those.

Each test recomputes figures the README prints, formats them to the README's digits
and asserts that the README contains exactly that text (whitespace-normalised), so a
drifted result and drifted prose both fail. A result changes only when the code does:
then rerun the command in the README, and update README.md and this file together.

What is recomputed here (about a minute on 2 cores): the analytic stiffness table,
ISO 6336, wear and clearance figures; the geometry figures; the FE checks (cantilever,
Hertz cylinders, single-tooth FE against Ishikawa and the energy method, wear effect,
plane strain); the resolved pair FE of the paper pair and of the shifted 21/37 pair;
the calibrated tables against the pair FE; the report model's modes; the cheap
dynamics accuracy figures. Too slow to recompute here (the FE convergence study, the
local-approach table, scipy's Python right-hand-side solvers, the paper report's 63
claims, ROSS) is pinned against the committed machine-written files instead
(reports/verification/verification.json, reports/paper/trends.json,
benchmarks/results/*.json), and each of those files is itself checked against a
cheap recomputation of some of its numbers. Wall times are benchmarks and not pinned.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import WearSpec

ROOT = Path(__file__).resolve().parents[1]
from scenes import published_text  # noqa: E402

README = published_text()  # README.md and docs/*.md: the published text
PHASES = ("unworn", "mild", "severe")


def say(text: str) -> None:
    """The README says exactly ``text`` (whitespace-normalised)."""
    text = " ".join(text.split())
    assert text in README, f"README.md does not say: {text!r}"


def e8(x: float, digits: int = 3) -> str:
    """4.389e8-style (the README's form for stiffness in N/m)."""
    return f"{x / 1e8:.{digits}f}e8"


def sci(x: float, digits: int = 1) -> str:
    """1.2e-3-style (no exponent padding, as the README writes small errors)."""
    m, e = f"{x:.{digits}e}".split("e")
    return f"{m}e{int(e)}"


def pct(x: float, digits: int = 1) -> str:
    """Relative change x (not in %) as '+12.8 %'."""
    return f"{100 * x:+.{digits}f} %"


def load_json(rel: str):
    return json.loads((ROOT / rel).read_text())


@pytest.fixture(scope="module")
def pair():
    return default_pair()


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """A private, empty calibrated-table cache: everything below is computed afresh."""
    old = os.environ.get("GEARWEAR_CACHE")
    os.environ["GEARWEAR_CACHE"] = str(tmp_path_factory.mktemp("gearwear-cache"))
    yield
    if old is None:
        os.environ.pop("GEARWEAR_CACHE", None)
    else:
        os.environ["GEARWEAR_CACHE"] = old


# -- analytic stiffness -------------------------------------------------------------------


@pytest.fixture(scope="module")
def analytic(pair):
    from gearwear.analytic.iso6336 import iso6336_stiffness
    from gearwear.analytic.tvms import mesh_stiffness

    out = {"iso": iso6336_stiffness(pair, torque_Nm=40.0)}
    for m in ("ishikawa", "energy"):
        out[m, False] = mesh_stiffness(pair, method=m, corner_contact=False)
        out[m, True] = mesh_stiffness(pair, method=m)
    for p in ("mild", "severe"):
        out[p] = mesh_stiffness(pair, wear=WearSpec(phase=p))
    out["cl200"] = mesh_stiffness(pair, clearance_m=200e-6)
    return out


def test_stiffness_table(analytic):
    iso = analytic["iso"]
    ref = iso.mesh_stiffness_N_per_m
    i0, e0, i1, e1 = (
        analytic[k] for k in (("ishikawa", False), ("energy", False), ("ishikawa", True), ("energy", True))
    )
    say(
        f"| mean k_h, theoretical path of contact (N/m) | {e8(i0.mean_N_per_m)} ({pct(i0.mean_N_per_m / ref - 1)}) "
        f"| {e8(e0.mean_N_per_m)} ({pct(e0.mean_N_per_m / ref - 1)}) | c_gamma_alpha b = {e8(ref)} |"
    )
    say(
        f"| mean k_h with tip-corner contact (N/m) | {e8(i1.mean_N_per_m)} ({pct(i1.mean_N_per_m / ref - 1)}) "
        f"| {e8(e1.mean_N_per_m)} ({pct(e1.mean_N_per_m / ref - 1)}) |"
    )
    zi, ze = i1.zone_means(), e1.zone_means()
    say(
        f"| double / single contact mean (N/m) | {e8(zi['double'])} / {e8(zi['single'])} "
        f"| {e8(ze['double'])} / {e8(ze['single'])} | c' b = {e8(iso.single_stiffness_N_per_m)} |"
    )
    # ISO without its C_M = 0.8, against both models with tip-corner contact (the means
    # the models give): 8.5 % and 7.2 %, "8 % above both"
    no_cm = ref / iso.C_M
    above = [no_cm / k.mean_N_per_m - 1 for k in (i1, e1)]
    assert all(0.07 < a < 0.09 for a in above), above
    say(f"without it ISO gives {no_cm / 1e8:.2f}e8 N/m, {100 * np.mean(above):.0f} % above both models")
    say(
        f"(line load {iso.line_load_N_per_mm:.1f} N/mm < 100 N/mm) would lower it further, to "
        f"{iso.mesh_stiffness_low_load_N_per_m / 1e8:.2f}e8 N/m"
    )


def test_wear_and_clearance_paragraphs(pair, analytic):
    from gearwear.geometry.kinematics import MeshGeometry
    from gearwear.geometry.wear import wear_on_line_of_action

    k0, km, ks = analytic["ishikawa", True], analytic["mild"], analytic["severe"]
    say(
        f"mean k_h falls from {e8(k0.mean_N_per_m)} (unworn) to {e8(km.mean_N_per_m)} (mild, 10 um) and "
        f"{e8(ks.mean_N_per_m)} N/m (severe, 30 um)"
    )
    mesh = MeshGeometry(pair, pair.centre_distance_m)
    h1, h2 = wear_on_line_of_action(mesh, WearSpec(phase="severe"), np.array([mesh.path_start_m]))
    say(f"gap of h_1(SAP) + h_2(tip) = {(h1[0] + h2[0]) * 1e6:.1f} um (severe)")
    assert 1e-6 < np.mean(k0.ste_m) < 2e-6  # "the 1-2 um elastic approach"
    say("far more than the 1-2 um elastic approach")
    drop = 1 - ks.k_N_per_m / k0.k_N_per_m
    single = k0.pairs_in_contact == 1
    assert drop[0] > 0.30 and np.max(np.abs(drop[single])) < 0.01
    say("falls to the single-pair value (drop > 30 %)")
    say("only the thinner teeth count (drop < 1 %)")
    c2 = analytic["cl200"]
    z0, z2 = k0.zone_means(), c2.zone_means()
    period = z0["double_deg"] + z0["single_deg"]
    say(
        f"the contact ratio falls ({k0.contact_ratio:.4f} -> {c2.contact_ratio:.4f} at 200 um), the double-contact "
        f"zone shortens ({z0['double_deg']:.2f} -> {z2['double_deg']:.2f} deg per {period:.0f} deg mesh period) and "
        f"the mean falls ({e8(k0.mean_N_per_m)} -> {e8(c2.mean_N_per_m)} N/m); the maximum falls too"
    )
    assert c2.max_N_per_m < k0.max_N_per_m


def test_geometry_and_assumption_figures(pair):
    from gearwear.fem.tooth import tooth_mesh
    from gearwear.geometry.profile import INVOLUTE, involute_points, tooth_profile

    g = pair.gear(0)
    body = tooth_mesh(pair).gear_mesh  # the FE default mesh of the whole gear
    area = body.area_m2
    mass = area * pair.face_width_m * pair.materials[0].density_kg_per_m3
    say(
        f"the gear body ({round(area * 1e6):,d} mm^2 from the mesh, x 20 mm, steel) weighs {mass:.2f} kg".replace(
            f"{round(area * 1e6):,d}", f"{round(area * 1e6):,d}".replace(",", " ")
        )
    )
    prof = tooth_profile(g)
    inv = np.flatnonzero(prof.region == INVOLUTE)
    exact, normal = involute_points(g.base_radius_m, prof.psi_b, 0.5 * (prof.roll[inv[:-1]] + prof.roll[inv[1:]]))
    chord = 0.5 * (prof.xy[inv[:-1]] + prof.xy[inv[1:]])
    sag = np.max(np.abs(np.sum((exact - chord) * normal, axis=1)))
    say(f"| tooth profile ({len(prof.s)} points) |")
    say(f"| chord sag {sag * 1e6:.2f} um |")
    say(f"the real fillet and the {(g.root_radius_m - g.hub_radius_m) * 1e3:.2f} mm rim down to the bore")


def test_full_gear_mesh_figures(pair):
    """Accuracy table, second row: triangle count and area error of the full P2 mesh at
    3 mm global, 0.4 mm fillets, 0.2 mm load point (benchmarks/bench_geometry.py)."""
    from gearwear.fem.mesh import MeshSizes, mesh_full_gear
    from gearwear.geometry.profile import fillet_midpoints, gear_outline, tooth_profile

    g = pair.gear(0)
    nom = tooth_profile(g, sag_m=1e-6)
    gm = mesh_full_gear(
        gear_outline(nom),
        g.hub_radius_m,
        MeshSizes(global_m=3e-3, fillet_m=0.4e-3, load_m=0.2e-3),
        refine_points_xy=np.array([nom.xy[-40]]),
        fillet_points_xy=fillet_midpoints(nom, g.teeth),
    )
    say(
        f"| full 30-tooth P2 mesh ({gm.n_elements / 1000:.0f}k triangles, 3 mm global, 0.4 mm fillets, 0.2 mm load "
        f"point) |"
    )
    assert gm.area_rel_error < 1e-8
    say("| area error 1e-8 |")


def test_slice_and_gauss_accuracy(pair):
    from gearwear.analytic import energy
    from gearwear.analytic.tvms import _profiles, mesh_stiffness

    ref = mesh_stiffness(pair, points=360, n_slices=1024).mean_N_per_m
    errs = {
        n: abs(mesh_stiffness(pair, points=360, n_slices=n).mean_N_per_m / ref - 1)
        for n in (4, 8, 16, 32, 64, 128, 256)
    }
    say("| rel. error | " + " | ".join(sci(errs[n]) for n in errs) + " |")
    say(f"| {sci(errs[64])} vs 1024 slices |")
    prof = _profiles(pair, None, pair.centre_distance_m)[0][0]
    R = np.linspace(71.8e-3, 79.9e-3, 200)
    c64 = energy.tooth_compliance(prof, R, pair.materials[0], pair.face_width_m, n_gauss=64).total_m_per_N
    c16 = energy.tooth_compliance(prof, R, pair.materials[0], pair.face_width_m, n_gauss=16).total_m_per_N
    assert np.max(np.abs(c16 / c64 - 1)) <= 1e-15  # round-off: the README's "1e-15"
    say("| Gauss 16 points: 1e-15 |")


def test_ross_comparison_against_bench_json(analytic):
    """ROSS runs only in .venv-bench: pinned to benchmarks/results/bench_stiffness.json,
    whose Ishikawa curve is checked against a fresh one."""
    d = load_json("benchmarks/results/bench_stiffness.json")
    row = next(r for r in d["rows"] if r["method"] == "ishikawa")
    assert row["mean_N_per_m"] == pytest.approx(analytic["ishikawa", True].mean_N_per_m, rel=1e-9)
    say(f"| mean {100 * (d['ross']['mean_N_per_m'] / row['mean_N_per_m'] - 1):.1f} % above our Ishikawa |")


# -- finite elements ------------------------------------------------------------------------


def test_cantilever_and_hertz_rows():
    import skfem

    from gearwear.fem.contact import hertz_cylinders
    from gearwear.fem.elasticity import assemble, traction_load
    from gearwear.geometry.spec import Material

    steel = Material(206e9, 0.3)
    E, G = steel.youngs_modulus_Pa, steel.youngs_modulus_Pa / 2.6
    L, c, P = 0.100, 0.005, 1000.0  # the beam of tests/test_fem_elasticity.py
    I = 2 * c**3 / 3
    m = skfem.MeshTri.init_tensor(np.linspace(0, L, 81), np.linspace(-c, c, 9))
    clamp = m.facets_satisfying(lambda x: np.isclose(x[0], L), boundaries_only=True)
    free = m.facets_satisfying(lambda x: np.isclose(x[0], 0.0), boundaries_only=True)
    model = assemble(m, steel, 1.0, clamp, plane="stress", order=2)
    U = model.solve(
        traction_load(model, free, lambda x, y: np.stack([np.zeros_like(x), P / (2 * I) * (c * c - y * y)]))
    )
    tip = float((model.probe(np.array([[0.0, 0.0]])) @ U)[1])
    timoshenko = P * L**3 / (3 * E * I) + P * L / (5 / 6 * G * 2 * c)
    say(f"| cantilever vs Timoshenko (clamped, kappa = 5/6) | {pct(tip / timoshenko - 1, 2)} |")
    h = hertz_cylinders(10e-3, 10e-3, order=1, elements_per_a=15)
    say(
        f"| 2D Hertz cylinders (a/15 elements) | half-width {pct(h.a_error, 2)}, peak pressure {pct(h.p0_error, 2)} "
        f"(P1) |"
    )


@pytest.fixture(scope="module")
def calibrations(pair, cache):
    """FE single-tooth stage of the calibration per wear phase (the default FE level);
    the same FE runs give the verification table's figures."""
    from gearwear.stiffness.calibration import run_fe

    return {p: run_fe(pair, None if p == "unworn" else WearSpec(phase=p), estimate_error=False) for p in PHASES}


def test_single_tooth_fe_against_analytic(calibrations):
    from gearwear.stiffness.comparison import tooth_vs_analytic

    fe = {p: calibrations[p].fe[0] for p in ("unworn", "severe")}
    cmp = {p: tooth_vs_analytic(f) for p, f in fe.items()}
    base = fe["unworn"]
    di = cmp["unworn"].ishikawa_um_per_N_per_mm / base.fem_compliance_um_per_N_per_mm - 1
    de = cmp["unworn"].energy_um_per_N_per_mm / base.fem_compliance_um_per_N_per_mm - 1
    r_pitch = base.pair.gear(0).pitch_radius_m
    d_pitch = np.interp(r_pitch, base.radius_m, di)
    say(
        f"| Ishikawa delta_1 + delta_2 vs FE | {pct(di[0])} (SAP) to {pct(di[-1])} (tip); {pct(d_pitch, 0)} at the "
        f"pitch point |"
    )
    say(f"| energy method vs FE | {pct(de[0])} (SAP) to {pct(de[-1])} (tip), {pct(de.min())} at its minimum |")
    wf = fe["severe"].fem_compliance_um_per_N_per_mm / base.fem_compliance_um_per_N_per_mm - 1
    wi = cmp["severe"].ishikawa_um_per_N_per_mm / cmp["unworn"].ishikawa_um_per_N_per_mm - 1
    say(
        f"| wear effect on the tooth compliance (severe) | FE +{100 * wf.min():.2f}..{100 * wf.max():.2f} %, "
        f"Ishikawa +{100 * wi.min():.2f}..{100 * wi.max():.2f} % |"
    )


def test_plane_strain_compliance(pair, calibrations):
    from gearwear.fem.tooth import single_tooth_compliance

    stress = calibrations["unworn"].fe[0].fem_compliance_um_per_N_per_mm
    strain = single_tooth_compliance(pair, plane="strain").fem_compliance_um_per_N_per_mm
    lower = 100 * (1 - strain / stress)
    say(f"in plane strain the FE compliance is {lower.min():.0f}-{lower.max():.0f} % lower")


def test_convergence_row_against_verification_json(calibrations):
    """The h/p study (~40 s) is pinned to reports/verification/verification.json; its
    default level is checked against the fresh default-level FE run."""
    d = load_json("reports/verification/verification.json")
    acc, conv = d["acceptance"], d["convergence"]
    default = next(r for r in conv if r["is_default"])
    fe = calibrations["unworn"].fe[0]
    assert default["dofs"] == fe.ndofs == acc["default_dofs"]
    assert np.allclose(default["compliance"], fe.fem_compliance_um_per_N_per_mm, rtol=1e-9, atol=0)
    p2 = [r for r in conv if r["order"] == 2]
    say(
        f"observed order {p2[-1]['observed_order_norm']:.2f}; default level ({acc['default_dofs'] / 1000:.1f}k dofs) "
        f"{acc['default_error_vs_extrapolation_pct']:.3f} % from the Richardson extrapolation; the two finest levels "
        f"differ by {acc['finest_p2_change_pct']:.3f} %"
    )
    ph = d["phases"]["unworn"]
    assert np.allclose(ph["fem_compliance_um_per_N_per_mm"], fe.fem_compliance_um_per_N_per_mm, rtol=1e-9, atol=0)


@pytest.fixture(scope="module")
def pair_fe(pair):
    from gearwear.fem.pair import pair_contact

    return pair_contact(pair, positions=24)


def _plateaus(r):
    loaded = r.pair_load_N > 0
    inside = ~np.any(loaded & ~r.pair_in_path, axis=1)
    n = loaded.sum(axis=1)
    return {k: float(np.mean(r.k_N_per_m[inside & (n == k)])) for k in (1, 2)}


def test_pair_fe_row(pair_fe):
    r = pair_fe
    p = _plateaus(r)
    dofs = set(r.meta["ndofs"])
    assert len(dofs) == 1
    n = f"{dofs.pop():,d}".replace(",", " ")
    say(
        f"{n} dofs per body; mean {e8(r.mean_N_per_m)} N/m, single-pair plateau {e8(p[1])}, double-pair "
        f"plateau {e8(p[2])} |"
    )
    ext = r.meta["extended_contact_deg"]
    assert f"{ext['entry']:.2f}" == f"{ext['exit']:.2f}"
    say(f"| extended (corner) contact | {ext['entry']:.2f} deg of pinion rotation beyond A and beyond E |")
    # the committed FE stiffness report holds the same curve
    rep = load_json("reports/stiffness_fem/stiffness_summary.json")
    assert rep[0]["wear"] == "unworn" and rep[0]["mean_N_per_m"] == pytest.approx(r.mean_N_per_m, rel=1e-9)


def test_local_approach_row_against_verification_json(pair_fe):
    """c_local against Weber (verify's pair_consistency, ~8 s more) is pinned to
    verification.json; its pair stiffnesses are checked against the fresh pair FE."""
    rows = load_json("reports/verification/verification.json")["pair_consistency"]
    fresh = pair_fe.k_N_per_m[pair_fe.pairs_in_contact == 1]
    assert len(rows) == len(fresh) >= 5
    # the same positions in the same order (solved once more, apart from the cycle: 2e-6)
    assert np.allclose(fresh, [r["k_pair_N_per_m"] for r in rows], rtol=1e-5, atol=0)
    ci = max(
        max(abs(r["c1_m_per_N"] / r["c1_tooth_m_per_N"] - 1), abs(r["c2_m_per_N"] / r["c2_tooth_m_per_N"] - 1))
        for r in rows
    )
    ident = max(abs(r["k_pair_N_per_m"] / r["k_identity_N_per_m"] - 1) for r in rows)
    cl = np.array([r["c_local_m_per_N"] for r in rows])
    ws = np.array([r["weber_stress_m_per_N"] for r in rows])
    we = np.array([r["weber_strain_m_per_N"] for r in rows])
    say(
        f"c_i agree to {100 * ci:.2f} %, the identity to {100 * ident:.3f} %; c_local = {cl.mean() * 1e9:.2f}e-9 m/N "
        f"is {pct(np.mean(cl / ws - 1))} above Weber in plane stress, {pct(np.mean(cl / we - 1), 0)} in plane strain"
    )


def test_shifted_pair_row():
    from gearwear.fem.pair import pair_contact

    from scenes import paper_pair_from

    sh = paper_pair_from({"pair": {"teeth": [21, 37], "profile_shift": [0.25, -0.10], "hub_radius_mm": [30.0, 40.0]}})
    r = pair_contact(sh, positions=24)
    p = _plateaus(r)
    say("| unequal shifted pair 21/37, x = +0.25/-0.10 |")
    say(f"mean {e8(r.mean_N_per_m)}, plateaus {e8(p[1])} / {e8(p[2])}, one more refinement")


@pytest.fixture(scope="module")
def calibrated(pair, calibrations, pair_fe, cache):
    from gearwear.stiffness.calibration import calibrated_table

    tabs = {
        p: calibrated_table(
            pair, None if p == "unworn" else WearSpec(phase=p), 0.0, 40.0, 360, calibration=calibrations[p], notify=None
        )
        for p in PHASES
    }
    # the wear study's unworn table (10 um clearance), for the report model below
    tabs["unworn10"] = calibrated_table(pair, None, 10e-6, 40.0, 360, calibration=calibrations["unworn"], notify=None)
    return tabs


def test_calibrated_tables_against_pair_fe(calibrated):
    t = {p: calibrated[p] for p in PHASES}
    fe = {p: t[p].meta["fe_pair_mean_N_per_m"] for p in PHASES}
    d = {p: t[p].mean_N_per_m / fe[p] - 1 for p in PHASES}
    rms = {p: t[p].meta["pair_check_rms"] for p in PHASES}
    say(
        f"| calibrated table vs FE pair (unworn / mild / severe) | means {100 * d['unworn']:+.2f} / "
        f"{100 * d['mild']:+.1f} / {100 * d['severe']:+.1f} %; held-out rms {100 * rms['unworn']:.1f} / "
        f"{100 * rms['mild']:.1f} / {100 * rms['severe']:.1f} % |"
    )
    dbl = [t[p].meta["pair_zone_factors"]["double"] for p in PHASES]
    sgl = [t[p].meta["pair_zone_factors"]["single"] for p in PHASES]
    assert {f"{x:.2f}" for x in dbl} == {"0.85"}
    say("(stage-2 factor 0.85)")
    say(f"(factor {min(sgl):.2f}-{max(sgl):.2f})")
    # the committed calibrated tables (reports/calibrated) are these tables
    for p in PHASES:
        side = load_json(f"reports/calibrated/calibrated_{p}_clearance0um.csv.json")
        assert side["mean_N_per_m"] == pytest.approx(t[p].mean_N_per_m, rel=1e-9), p
        assert side["fe_pair_mean_N_per_m"] == pytest.approx(fe[p], rel=1e-9), p


# -- the paper report ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def report_unworn(calibrated):
    """The wear study's unworn run of `gearwear report paper` (calibrated table from the
    fixture's cache, so no FE is rerun)."""
    from gearwear.jobs.simulate import run
    from gearwear.scene.files import builtin_scene_dict
    from gearwear.scene.model import scene_from_dict
    from gearwear.scene.overrides import apply_overrides

    sc = scene_from_dict(
        apply_overrides(builtin_scene_dict("paper-wear-unworn"), ['effects.mesh_stiffness={source = "calibrated"}']),
        name="paper-wear-unworn",
    )
    return run(sc)


def test_report_claims_and_modes(report_unworn):
    from gearwear.dynamics.model import linear_eigenfrequencies

    rows = load_json("reports/paper/trends.json")
    n, agree = len(rows), sum(r["verdict"] == "agree" for r in rows)
    say(f"checks each of the paper's {n} trend claims")
    say(f"{agree} agree and {n - agree} disagree")
    lin = next(r for r in rows if r["paper"].startswith("the first four F_m harmonics vary nonlinearly"))
    worst = max(float(x) for x in lin["ours"].split(":")[1].replace("%", "").split("of")[0].split(","))
    say(f"the exact ones stray at most {worst:.0f} %")
    # the report's model: modes with the calibrated table, and its largest F_m harmonics
    r = report_unworn.result
    f = np.unique(np.round(linear_eigenfrequencies(report_unworn.model), 6))
    say(f"the model's modes ({f[0]:.0f}, {f[1]:.0f} and {f[2]:.0f} Hz here)")
    top = sorted(np.argsort(-r.harmonics("F_m", 10))[:3] + 1)
    assert top == [5, 6, 7]
    say(f"Our largest mesh-force harmonics are the 5th-7th (near {f[2]:.0f} Hz)")
    # trends.json against this fresh run: the unworn point of the wear rows
    for row in rows:
        if row["where"] == "3.1.4, Fig. 13":
            assert row["ours"] == "largest: " + ", ".join(
                f"{k} x fm" for k in np.argsort(-r.harmonics("F_m", 10))[:3] + 1
            )
        if row["where"] == "3.1, Fig. 14" and "x fm of F_m" in row["paper"]:
            k = int(row["paper"].split(" x fm")[0])
            assert row["ours"].split(": ")[1].split(" -> ")[0] == f"{r.harmonics('F_m', 4)[k - 1]:.5g}"


# -- dynamics ---------------------------------------------------------------------------


def test_dynamics_eigenfrequencies_and_rk4_tables():
    from gearwear.dynamics import paper_pair, simulate
    from gearwear.dynamics.model import linear_eigenfrequencies

    f = np.unique(np.round(linear_eigenfrequencies(paper_pair()), 6))
    say(f"the linearised eigenfrequencies ({f[0]:.1f}, {f[1]:.1f}, {f[2]:.1f} Hz)")
    names = ("F_m", "delta")

    def err(h, ref):
        return max(
            float(np.max(np.abs(h[n] - ref[n])[ref[n] > 0.01 * ref[n].max()] / ref[n][ref[n] > 0.01 * ref[n].max()]))
            for n in names
        )

    worst = 0.0
    for L in (97, 256, 360, 1000):
        m = paper_pair(n_table=L)
        ref = simulate(m, 0.1, 0.05, method="dopri5", rtol=1e-10).harmonics_of(list(names))
        worst = max(
            worst, err(simulate(m, 0.1, 0.05, method="rk4", steps_per_mesh_period=256).harmonics_of(list(names)), ref)
        )
    assert 0.5 * 8.4e-5 < worst <= 8.4e-5, worst  # "to 8.4e-5 or better" (measured 8.35e-5)
    say(
        "RK4 at 256 steps agrees with the adaptive solver to 8.4e-5 or better for stiffness tables of 97, 256, 360 "
        "and 1000 nodes"
    )


def test_dynamics_accuracy_table():
    """The numba rows are recomputed (bench_dynamics.py's smooth and event cases); the
    scipy rows (Python right-hand side, ~60 s) are pinned to
    benchmarks/results/bench_dynamics.json, whose numba rows must equal the fresh ones."""
    from gearwear.dynamics import paper_pair, simulate

    bench = load_json("benchmarks/results/bench_dynamics.json")
    ms = paper_pair(torque_Nm=40.0, speed_rpm=1200.0)
    href = simulate(ms, 0.2, 0.1, method="dopri5", rtol=1e-12, samples_per_mesh_period=256).harmonics("F_m", 10)

    def err(r):
        h = r.harmonics("F_m", 10)
        keep = href >= 1e-6 * href.max()
        return float(np.max(np.abs(h[keep] - href[keep]) / href[keep]))

    rk4 = {
        N: err(simulate(ms, 0.2, 0.1, method="rk4", steps_per_mesh_period=N, samples_per_mesh_period=256))
        for N in (128, 256, 512, 1024)
    }
    dp = {
        rt: err(simulate(ms, 0.2, 0.1, method="dopri5", rtol=rt, samples_per_mesh_period=256)) for rt in (1e-8, 1e-10)
    }
    say("| RK4, 128 / 256 / 512 / 1024 steps per mesh period |")
    say(" / ".join(sci(rk4[N]) for N in rk4) + " |")
    say("| adaptive Dormand-Prince, rtol 1e-8 / 1e-10 |")
    say(f"| {sci(dp[1e-8])} / {sci(dp[1e-10])} |")
    rows = {(r["method"], r["setting"]): r["err_h1_10"] for r in bench["smooth"]["rows"]}
    for N, e in rk4.items():
        assert rows["RK4", f"{N} /period"] == pytest.approx(e, rel=1e-6)
    assert rows["dopri5", "rtol 1e-08"] == pytest.approx(dp[1e-8], rel=1e-6)
    say(f"| {sci(rows['scipy RK45', 'rtol 1e-07'])} / {sci(rows['scipy RK45', 'rtol 1e-08'])} |")
    say(f"| {sci(rows['scipy DOP853', 'rtol 1e-10'])} / {sci(rows['scipy DOP853', 'rtol 1e-12'])} |")
    say(f"(which agrees with scipy DOP853 at rtol 1e-12 to {sci(bench['smooth']['dop853_vs_reference'])})")
    say(f"(which is still {rows['scipy RK45', 'rtol 1e-07'] / rk4[256]:.0f} times less accurate)")
    say(f"Its observed order is {bench['smooth']['rk4_order_fit_table_multiples']:.2f}.")
    # event case: separation and located contact events, fresh
    me = paper_pair(torque_Nm=5.0, speed_rpm=6000.0, backlash_total_m=50e-6, te_amplitude_m=2e-6)
    P = 1.0 / me.mesh_frequency_Hz
    r = simulate(me, 20 * P, 4 * P, method="dopri5", rtol=1e-12, samples_per_mesh_period=256)
    say(f"{100 * r.separation_fraction:.0f} % of the time separated")
    say(f"({r.events} located contact events)")


def test_rk4_versus_c_agreement_against_bench_json():
    """The C comparison needs gcc and a timing run: pinned to bench_rk4_vs_c.json."""
    d = load_json("benchmarks/results/bench_rk4_vs_c.json")
    say(f"their final states agree to {sci(d['rk4_all_256']['agreement']['max_component_rel'])})")


def test_wear_depth_limit_of_the_paper_pinion(pair):
    """README, Geometry: the deepest wear accepted on the paper pinion."""
    from gearwear.geometry.operating import operating_geometry
    from gearwear.geometry.wear import depth_limits

    lim = depth_limits(operating_geometry(pair).mesh, WearSpec(phase="severe"))
    say(
        f"1/3 of the local half tooth thickness where the flank wears deepest is refused "
        f"({lim['max_depth_m'] * 1e6:.0f} um on the paper pinion)"
    )


def test_current_calibrated_means_in_the_history_paragraph():
    """README, FE section: the current calibrated table means, read from reports/calibrated
    (test_calibrated_tables_against_pair_fe checks those sidecars against fresh runs)."""
    means = [load_json(f"reports/calibrated/calibrated_{p}_clearance0um.csv.json")["mean_N_per_m"] for p in PHASES]
    say("0 um clearance) have means " + " / ".join(e8(m) for m in means) + " N/m.")


def test_your_own_pair_figures(capsys):
    """The README's "Your own gear pair in five minutes" (examples/your_pair.toml, 19/45 m 4):
    the blanks' masses, the analytic means and the pair FE (bore-fixed and mesh only),
    through the command line as the README runs them. Its analytic means were left at
    5.709e8 / 4.926e8 N/m after the breakpoint tables moved them to 5.707e8 / 4.923e8,
    because no test read them."""
    from gearwear.cli import main

    scene = str(ROOT / "examples" / "your_pair.toml")
    assert main(["stiffness", scene, "--method", "ishikawa", "energy", "iso6336", "fem", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    by = {c["method"]: c for c in d["curves"]}
    say(
        f"mean {e8(by['ishikawa']['mean_N_per_m'])}, {e8(by['energy']['mean_N_per_m'])} and "
        f"{e8(by['iso6336']['mean_N_per_m'])} N/m"
    )
    say(
        f"{e8(by['fem']['mean_N_per_m'])} N/m held at the bores and {e8(by['fem']['mesh_only_mean_N_per_m'])} N/m "
        "for the mesh alone"
    )
    assert main(["scene", scene]) == 0
    text = capsys.readouterr().out
    masses = [float(x) for x in text.split("mass_kg = [")[1].split("]")[0].split(",")]
    say(f"({masses[0]:.3f} and {masses[1]:.3g} kg:")
