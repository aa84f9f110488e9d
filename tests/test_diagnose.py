"""gearwear diagnose: features, posterior, error model, surrogate cache, identifiability,
a coarse blind test and the command's contracts.

Independent truths: closed-form Fourier series; the linear-Gaussian posterior in closed
form (including a truncated normal at a prior bound); the common-error identity behind
``error_multiplicity``; the physics identity that, with the bearings pressed into their
clearance and no centre-distance coupling, the clearance shifts the mean bearing
displacements by exactly BC/2 and leaves every harmonic unchanged; full simulations the
surrogate never saw (held-out and blind). The surrogate in this file is tiny (32 Sobol
points, short runs), so the blind test checks the method's honesty (intervals cover the
truth), not its precision; `make report` runs the 20-trial blind test at the default size.
"""

import json
import math

import numpy as np
import pytest
from scipy import stats

from gearwear.cli import app as cli
from gearwear.core.validation import InputError
from gearwear.diagnose import job as dj
from gearwear.diagnose import posterior as dp
from gearwear.diagnose import surrogate as ds
from gearwear.diagnose.features import fourier_fit, read_measurement, time_series_features
from gearwear.scene.files import load_scene_dict

FM = 600.0
K = 10
#: the test scene: paper-wear-severe without the centre-distance coupling (the clearance then
#: acts only through the bearing dead zones) and a shorter run; 32 design + 32 held-out runs
SCENE_TOML = """
name = "diagnose-test"
extends = "paper-default"
[operating]
speed_rpm = 1200
torque_Nm = 40
[effects]
mesh_stiffness = { source = "analytic" }
wear = { max_depth_um = 10 }
backlash = { initial_um = 50 }
bearing_clearance = { clearance_um = 10 }
[solver]
duration_s = 0.15
discard_s = 0.1
"""
LO, HI = (0.0, 0.0), (40.0, 50.0)
DESIGN, HOLDOUT = 32, 32


# -- features --------------------------------------------------------------------------


def test_fourier_fit_recovers_a_closed_form_series_at_any_sampling():
    """Mean, amplitudes and phases of a band-limited series, sampled at a non-integer number of
    samples per period and unevenly: least squares is exact (1e-12)."""
    rng = np.random.default_rng(0)
    amp = rng.uniform(0.1, 2.0, K)
    ph = rng.uniform(-np.pi, np.pi, K)
    t = np.sort(rng.uniform(0, 7 / FM, 700))
    k = np.arange(1, K + 1)[:, None]
    x = 3.5 + np.sum(amp[:, None] * np.cos(2 * np.pi * k * FM * t + ph[:, None]), axis=0)
    mean, c = fourier_fit(t, x, FM, K)
    assert abs(mean - 3.5) < 1e-12
    np.testing.assert_allclose(np.abs(c), amp, rtol=1e-11)
    np.testing.assert_allclose(np.angle(c), ph, atol=1e-11)


def test_time_series_features_use_the_last_whole_periods():
    """A record of 12.3 mesh periods: the 12 last whole ones are used, so a disturbance in the
    leading 0.3 period is left out and the features are exact."""
    t = np.arange(0, 12.3 / FM, 1 / (FM * 50.0))
    x = 2.0 * np.cos(2 * np.pi * 3 * FM * t) - 0.5 + np.where(t < 0.25 / FM, 5.0, 0.0)
    vals, info = time_series_features(t, {"y_p_um": x}, FM, K)
    assert info["periods"] == 12 and vals[("y_p_um", 0)] == pytest.approx(-0.5, abs=1e-12)
    assert vals[("y_p_um", 3)] == pytest.approx(2.0, rel=1e-12)
    assert max(vals[("y_p_um", k)] for k in (1, 2, 4, 5, 6, 7, 8, 9, 10)) < 1e-12


@pytest.mark.parametrize(
    "text, where",
    [
        ("time_s,y_p_um\n0,1\n0.001,abc\n", "row 3, column y_p_um: 'abc' is not a number"),
        ("time_s,y_p_um,z_um\n0,1,2\n", "row 1, column z_um: unknown column"),
        ("time_s,y_p_um\n0,1\n0,2\n", "row 3, column time_s: 0 does not increase"),
        ("time_s,y_p_um\n0,1\n0.0001,2\n", "column time_s: the record spans 0.0001 s, less than one mesh period"),
        ("time_s,y_p_um\n" + "".join(f"{i / 6000},{i}\n" for i in range(40)), "cannot resolve 10 mesh harmonics"),
        ("signal,harmonic,amplitude\nF_m_N,11,1\n", "row 2, column harmonic: 11 must be a whole number in [1, 10]"),
        ("signal,harmonic,amplitude\nF_m_N,2,-1\n", "row 2, column amplitude: -1 must be >= 0"),
        ("signal,harmonic,amplitude\nq_um,2,1\n", "row 2, column signal: 'q_um' is not a measurable signal"),
        ("signal,harmonic,amplitude\nF_m_N,2,1\nF_m_N,2,3\n", "row 3: repeats F_m_N harmonic 2"),
        ("", "is empty"),
    ],
)
def test_bad_measurement_files_name_file_row_and_column(tmp_path, text, where):
    p = tmp_path / "m.csv"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        read_measurement(p, FM, K)
    assert str(e.value).startswith(f"--measured {p}") and where in str(e.value) and "\n" not in str(e.value)


# -- posterior, Fisher information, error model: closed forms ----------------------------


def _linear_gaussian(A, b, y, sd):
    return lambda th: -0.5 * np.sum(((th @ A.T + b) - y) ** 2 / sd**2, axis=1)


@pytest.mark.parametrize("scale", [1.0, 1e-3])
def test_grid_posterior_equals_the_linear_gaussian_closed_form(scale):
    """A linear model with Gaussian noise and a wide uniform prior: the posterior is the
    Gaussian N(mu, (A^T S^-1 A)^-1). Medians and 95 % limits within 0.5 % of a standard
    deviation, also when the posterior is 1000x narrower than the prior (zoomed grids)."""
    A = np.array([[1.0, 0.6], [0.3, -1.2], [2.0, 0.5]])
    truth = np.array([4.0, 6.0])
    sd = np.array([0.5, 0.8, 0.4]) * scale
    y = A @ truth + np.array([0.3, -0.2, 0.1]) * scale
    cov = np.linalg.inv(A.T @ (A / sd[:, None] ** 2))
    mu = cov @ (A.T @ (y / sd**2))
    post = dp.grid_posterior(_linear_gaussian(A, 0.0, y, sd), [0, 0], [10, 10], 101)
    s = dp.summarise(post, ["a", "b"], [0, 0], [10, 10])
    for j, n in enumerate("ab"):
        e, sj = s["estimates"][n], math.sqrt(cov[j, j])
        assert abs(e["value"] - mu[j]) < 5e-3 * sj
        assert abs(e["lo95"] - (mu[j] - 1.959964 * sj)) < 5e-3 * sj
        assert abs(e["hi95"] - (mu[j] + 1.959964 * sj)) < 5e-3 * sj
    assert s["correlation"][0, 1] == pytest.approx(cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1]), abs=2e-3)
    if scale < 1:
        assert len(post.stages) > 1  # the zoom found the narrow posterior


def test_interval_at_a_prior_bound_is_the_truncated_normal():
    """A posterior cut by the prior's lower bound: quantiles of scipy's truncated normal."""
    sd = 2.0
    post = dp.grid_posterior(lambda th: -0.5 * ((th[:, 0] - 1.0) / sd) ** 2, [0.0], [50.0], 401)
    tn = stats.truncnorm((0 - 1.0) / sd, (50 - 1.0) / sd, loc=1.0, scale=sd)
    for q in (0.025, 0.5, 0.975):
        assert post.quantile(0, q) == pytest.approx(tn.ppf(q), abs=2e-3 * sd)


def test_fisher_widths_of_a_linear_model():
    """Cramer-Rao widths equal the closed-form posterior widths of the linear-Gaussian model;
    an unknown no feature depends on has an infinite width."""
    J = np.array([[1.0, 0.6], [0.3, -1.2], [2.0, 0.5]])
    var = np.array([0.25, 0.64, 0.16])
    cov = np.linalg.inv(J.T @ (J / var[:, None]))
    w = dp.fisher_widths(J, var, [10.0, 20.0])
    np.testing.assert_allclose(w["marginal"], 2 * 1.959964 * np.sqrt(np.diag(cov)) / [10.0, 20.0], rtol=1e-12)
    np.testing.assert_allclose(
        w["conditional"], 2 * 1.959964 / np.sqrt(np.diag(J.T @ (J / var[:, None]))) / [10.0, 20.0], rtol=1e-12
    )
    flat = dp.fisher_widths(np.column_stack([J[:, 0], np.zeros(3)]), var, [1.0, 1.0])
    assert np.isinf(flat["marginal"]).all() and np.isinf(flat["conditional"][1])


def test_error_multiplicity_is_exact_for_one_common_error():
    """n features y_i = theta + e + n_i with one common surrogate error e ~ N(0, s^2) and
    independent noise n_i ~ N(0, sigma^2): the exact posterior variance of theta is
    s^2 + sigma^2 / n; independent terms of variance sigma^2 + m s^2 give the same."""
    n, s, sigma = 7, 0.3, 0.5
    m = ds.error_multiplicity(n)
    y = np.linspace(9.0, 11.0, n)
    post = dp.grid_posterior(
        lambda th: -0.5 * np.sum((th[:, :1] - y) ** 2, axis=1) / (sigma**2 + m * s**2), [0.0], [20.0], 2001
    )
    sd = (post.quantile(0, 0.975) - post.quantile(0, 0.025)) / (2 * 1.959964)
    assert sd == pytest.approx(math.sqrt(s**2 + sigma**2 / n), rel=1e-3)


def test_local_error_and_calibration():
    """Constant residuals are their own kernel average; kappa makes 95 % of the z-scores fall
    inside 1.96 kappa (and is never below 1)."""
    rng = np.random.default_rng(1)
    Ud = rng.random((50, 2))
    r2 = np.full((50, 3), 4.0)
    np.testing.assert_allclose(ds.local_rms(rng.random((5, 2)), Ud, r2, 0.1), 2.0, rtol=1e-12)
    z = np.column_stack([rng.standard_normal(4000) * 3.0, rng.standard_normal(4000) * 0.5])
    kappa = ds.calibrate(z, np.array(["a", "b"]))
    assert kappa[0] == pytest.approx(3.0, rel=0.05) and kappa[1] == 1.0
    assert np.mean(np.abs(z[:, 0]) <= 1.959964 * kappa[0]) == pytest.approx(0.95, abs=1e-3)


def test_design_coordinates_invert():
    u = ds.UNKNOWNS["wear"]
    x = np.array([0.0, 0.3, 10.0, 39.9, 40.0])
    np.testing.assert_allclose(u.from_unit(u.to_unit(x, 0.0, 40.0), 0.0, 40.0), x, rtol=1e-14, atol=1e-14)
    assert u.to_unit(10.0, 0.0, 40.0) == pytest.approx(0.5)  # half the design below a quarter of the range


# -- the forward model and a tiny surrogate --------------------------------------------


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    """The test scene file, its document and the tiny surrogate (built once, cached in a
    private folder; the command-line tests below hit the same cache entry)."""
    folder = tmp_path_factory.mktemp("diagnose")
    scene = folder / "scene.toml"
    scene.write_text(SCENE_TOML)
    cache = folder / "cache"
    mp = pytest.MonkeyPatch()
    mp.setenv("GEARWEAR_CACHE", str(cache))
    raw, name = load_scene_dict(str(scene))
    unknowns = [ds.UNKNOWNS["wear"], ds.UNKNOWNS["clearance"]]
    spec = ds.BuildSpec(raw, name, unknowns, LO, HI, K, DESIGN, HOLDOUT)
    sur = ds.build(spec)
    yield {"scene": scene, "raw": raw, "name": name, "spec": spec, "sur": sur, "cache": cache, "folder": folder}
    mp.undo()


def test_clearance_with_bearings_in_contact_shifts_the_means_by_half_and_leaves_the_harmonics(world):
    """Physics identity (no centre-distance coupling, bearings pressed into their clearance):
    y_p and x_p move by exactly BC/2 and no harmonic changes (1e-9)."""
    a, _ = ds.simulate_point(world["raw"], world["name"], {"wear": 12.0, "clearance": 0.0}, None, K)
    b, _ = ds.simulate_point(world["raw"], world["name"], {"wear": 12.0, "clearance": 30.0}, None, K)
    n = 8 * K
    assert np.max(np.abs(a[:n] - b[:n])) < 1e-9 * np.max(np.abs(a[:n]))
    np.testing.assert_allclose(b[n : n + 2] - a[n : n + 2], -15.0, atol=1e-9)
    assert b[n + 2] == pytest.approx(a[n + 2], rel=1e-12)  # the mean mesh force is the torque's


def test_bearing_harmonics_are_the_mesh_force_through_a_fixed_transfer_function(world):
    """With the bearings pressed into their clearance, m_p y'' + c_b y' + k_b y = -F_m cos(a)
    is linear: harmonic k of y_p (x_p) is F_m's times -cos(a) (-sin(a)) / (k_b - m_p w^2 +
    i c_b w), w = 2 pi k f_m, whatever the wear and clearance (closed form, 1e-5)."""
    from gearwear.dynamics.analysis import window_fourier
    from gearwear.jobs.simulate import run

    r = run(ds.scene_at(world["raw"], world["name"], {"wear": 25.0, "clearance": 40.0})).result
    m = r.model
    c = window_fourier(r, ["y_p", "x_p", "F_m"], K)
    w = 2 * np.pi * r.fm_Hz * np.arange(1, K + 1)
    H = 1 / (m.k_b - m.m_p * w**2 + 1j * m.c_b_pair[0] * w)
    np.testing.assert_allclose(c["y_p"], -math.cos(m.alpha) * H * c["F_m"], rtol=1e-5)
    np.testing.assert_allclose(c["x_p"], -math.sin(m.alpha) * H * c["F_m"], rtol=1e-5)


def test_window_fourier_agrees_with_a_fit_of_the_samples(world):
    """The exact complex harmonics (quadrature of the dense solution) equal the least-squares
    Fourier coefficients of the sampled displacements (smooth signals, no aliasing: 1024
    samples per mesh period; the stiffness table resolves the steep rise where a pair starts
    to carry load, whose harmonics above ~250 alias into a 256-sample fit by ~2e-6)."""
    from gearwear.dynamics import simulate
    from gearwear.dynamics.analysis import window_fourier
    from gearwear.jobs.simulate import build_model, stiffness_input

    sc = ds.scene_at(world["raw"], world["name"], {"wear": 20.0, "clearance": 5.0})
    r = simulate(
        build_model(sc, stiffness_input(sc)),
        sc.solver["duration_s"],
        sc.solver["discard_s"],
        rtol=sc.solver["rtol"],
        samples_per_mesh_period=1024,
    )
    c = window_fourier(r, ["y_p", "delta"], K)
    for name in ("y_p", "delta"):
        _, fit = fourier_fit(r.t - r.t[0], r.signals[name], r.fm_Hz, K)
        np.testing.assert_allclose(fit, c[name], rtol=0, atol=1e-6 * np.max(np.abs(c[name])))


def test_surrogate_error_model_covers_unseen_full_simulations(world):
    """Eight full simulations that neither the design nor the held-out set contains: the
    error model's 95 % band holds at least 85 % of their feature errors (the calibration used
    other points), and the held-out error is stated."""
    sur = world["sur"]
    X = np.random.default_rng(99).uniform(LO, HI, (8, 2))
    Y, _ = ds.run_points(world["raw"], world["name"], [{"wear": w, "clearance": c} for w, c in X], None, K)
    err = np.abs(sur.predict(X) - ds.amplitudes(Y, K))
    assert np.mean(err <= 1.959964 * sur.error(X)) >= 0.85
    h = sur.heldout
    assert h["points"] == HOLDOUT and 0 < h["harmonic_relative_error_median"] < h["harmonic_relative_error_p95"]


def test_blind_coarse(world):
    """Blind test, coarse: measurements from the full model (simulate) at random wear and
    clearance values the design does not contain, the time series of y_p, x_p and F_m
    (harmonics and means), 2 % noise (each feature x (1 + 0.02 eps)). The truth lies inside
    both 95 % intervals in at least 5 of 6 trials, and the means resolve the clearance
    (interval below 10 % of the prior range)."""
    sur, rng = world["sur"], np.random.default_rng(2024)
    inside, widths = 0, []
    for i in range(6):
        truth = {
            "wear": float(rng.uniform(*ds.default_range(ds.UNKNOWNS["wear"], world["raw"]))),
            "clearance": float(rng.uniform(0, 50)),
        }
        vals = dj.synthetic_features(
            world["raw"],
            world["name"],
            truth,
            K,
            ["y_p_um", "x_p_um", "F_m_N"],
            True,
            0.02,
            np.random.default_rng(100 + i),
        )
        ft = dj.fit(sur, vals, 0.02, 0.005)
        e = ft.summary["estimates"]
        inside += all(e[u.name]["lo95"] <= truth[u.short] <= e[u.name]["hi95"] for u in sur.unknowns)
        widths.append(e["clearance_um"]["interval_fraction_of_prior"])
    assert inside >= 5
    assert max(widths) < 0.10


def test_unidentifiable_clearance_is_reported_so_and_a_time_series_resolves_it(world):
    """Harmonics only, bearings always in contact: no feature depends on the clearance, so it
    is reported as not identifiable with an interval over most of the prior, and the advice
    is a mean value (a time series). The same truth from a time series with means: resolved,
    truth inside."""
    sur = world["sur"]
    truth = {"wear": 22.0, "clearance": 31.0}
    harm = dj.synthetic_features(
        world["raw"], world["name"], truth, K, ["y_p_um", "F_m_N"], False, 0.02, np.random.default_rng(5)
    )
    ft = dj.fit(sur, harm, 0.02, 0.005)
    v = dj.verdict(ft, 0.02, 0.005)
    e = ft.summary["estimates"]["clearance_um"]
    assert v["identifiable"]["clearance_um"] is False and e["interval_fraction_of_prior"] > 0.85
    assert "clearance_um cannot be resolved" in v["verdict"]
    assert "mean of" in v["details"]["clearance_um"]["would_resolve"]["measurement"]
    ts = dj.synthetic_features(
        world["raw"], world["name"], truth, K, ["y_p_um", "F_m_N"], True, 0.02, np.random.default_rng(5)
    )
    ft2 = dj.fit(sur, ts, 0.02, 0.005)
    e2 = ft2.summary["estimates"]["clearance_um"]
    assert dj.verdict(ft2, 0.02, 0.005)["identifiable"]["clearance_um"] is True
    assert e2["lo95"] <= 31.0 <= e2["hi95"]


def test_cache_hit_and_damaged_entries(world, tmp_path):
    """A second build reads the entry (same predictions); a changed byte, a missing sidecar
    or a sidecar of other inputs is refused with its reason."""
    spec, sur = world["spec"], world["sur"]
    again = ds.build(spec, notify=None)
    assert again.from_cache
    X = np.array([[5.0, 5.0], [33.0, 41.0]])
    np.testing.assert_array_equal(again.predict(X), sur.predict(X))
    inputs = spec.inputs()
    key = ds.tables.table_key(inputs)
    src = world["cache"] / f"{key}.npz"
    for damage, reason in (
        ("byte", "does not match the npz_sha256"),
        ("sidecar", "has no sidecar"),
        ("other", "belongs to other inputs"),
    ):
        folder = tmp_path / damage
        folder.mkdir()
        data = bytearray(src.read_bytes())
        side = json.loads((world["cache"] / f"{key}.npz.json").read_text())
        if damage == "byte":
            data[len(data) // 2] ^= 0xFF
        if damage == "other":
            side["input_sha256"] = "0" * 64
        (folder / f"{key}.npz").write_bytes(bytes(data))
        if damage != "sidecar":
            (folder / f"{key}.npz.json").write_text(json.dumps(side))
        got, why = ds.lookup(inputs, spec.unknowns, folder)
        assert got is None and reason in why


# -- the command -------------------------------------------------------------------------


def _run(capsys, *argv):
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _measurement(world, path):
    vals = dj.synthetic_features(
        world["raw"],
        world["name"],
        {"wear": 15.0, "clearance": 20.0},
        K,
        ["y_p_um"],
        False,
        0.02,
        np.random.default_rng(3),
    )
    path.write_text("signal,harmonic,amplitude\n" + "".join(f"{s},{k},{v!r}\n" for (s, k), v in vals.items()))
    return path


def test_command_twice_same_bytes_and_json_keys(world, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("GEARWEAR_CACHE", str(world["cache"]))
    m = _measurement(world, tmp_path / "m.csv")
    base = ["diagnose", str(world["scene"]), "--measured", str(m), "--design-points", str(DESIGN), "--workers", "1"]
    code, out, err = _run(capsys, *base, "--out", str(tmp_path / "a"), "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc["estimates"]["wear_max_depth_um"]) == {"value", "lo95", "hi95"}
    assert set(doc["identifiable"]) == {"wear_max_depth_um", "clearance_um"} and isinstance(doc["verdict"], str)
    assert doc["surrogate"]["heldout"]["points"] == HOLDOUT and doc["wall_s"] > 0
    assert _run(capsys, *base, "--out", str(tmp_path / "b"))[0] == 0
    for f in ("diagnosis.json", "features.csv", "features.csv.json", "corner.png", "features.png", "manifest.json"):
        assert (tmp_path / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes(), f
    assert "wall" not in (tmp_path / "a" / "diagnosis.json").read_text()


def test_plan_ranks_measurements(world, tmp_path, capsys, monkeypatch):
    """At the scene's own operating point (the cached surrogate): harmonics alone cannot
    separate the clearance, a displacement time series (its mean) can."""
    monkeypatch.setenv("GEARWEAR_CACHE", str(world["cache"]))
    code, out, err = _run(
        capsys,
        "diagnose",
        "--plan",
        str(world["scene"]),
        "--design-points",
        str(DESIGN),
        "--speeds-rpm",
        "1200",
        "--torques-Nm",
        "40",
        "--workers",
        "1",
        "--json",
        "--out",
        str(tmp_path / "p"),
    )
    assert code == 0, err
    rows = {r["measurement"]: r for r in json.loads(out)["rows"]}
    assert not rows["F_m_N harmonics"]["resolves"]["clearance_um"]
    assert rows["y_p_um time series"]["resolves"]["clearance_um"]
    assert (tmp_path / "p" / "plan.csv").exists()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--unknowns", "wear,foo"], "--unknowns = wear,foo: 'foo' is not one"),
        (["--wear-range-um", "5:1"], "--wear-range-um = 5:1 um: must be LO:HI"),
        (["--clearance-range-um", "abc"], "--clearance-range-um = abc: must be LO:HI in um"),
        (["--wear-range-um", "0:5000"], "--wear-range-um = 0:5000 um: at 5000 um the scene is refused"),
        (
            ["--set", "effects.wear.max_depth_um=3"],
            "--set effects.wear.max_depth_um: sets wear_max_depth_um, an unknown",
        ),
        (["--noise-pct", "0"], "--noise-pct = 0 %: must be in [0.01, 100] %"),
        (["--design-points", "100"], "--design-points = 100: must be a power of two"),
        (["--plan", "--measured", "x.csv"], "--measured x.csv: not used with --plan"),
        ([], "--measured: missing"),
        (["--measured", "nope.csv"], "--measured nope.csv: no such file"),
    ],
)
def test_bad_inputs_one_line_exit_2_nothing_written(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("GEARWEAR_CACHE", str(tmp_path / "cache"))
    code, out, err = _run(capsys, "diagnose", *args, "--out", "res")
    assert code == 2 and err.count("\n") == 1 and err.startswith("gearwear: error: ") and message in err, err
    assert not (tmp_path / "res").exists() and not (tmp_path / "cache").exists()
