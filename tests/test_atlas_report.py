"""The atlas report (gearwear.reports.atlas) on a hand-made atlas.csv whose errors are known
by construction: each model is the FE times a factor chosen per design, so every summary,
the cell table and the held-out check can be worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearwear.reports import atlas as A

HEAD = (
    "design,z1,z2,pressure_angle_deg,addendum_coefficient,dedendum_coefficient,rack_tip_radius_coefficient,"
    "x1,x2,module_mm,face_width_mm,bore1_mm,bore2_mm,rim_thickness_module,line_load_N_per_mm,torque_Nm,"
    "contact_ratio,model,mean_N_per_m,single_N_per_m,double_N_per_m,p2p_N_per_m,h1_N_per_m,h2_N_per_m,"
    "h3_N_per_m,ste_p2p_um,entry_deg,exit_deg"
)


def _csv(factors: dict[str, list[float]], eps: list[float], rims: list[float]) -> str:
    rows = [HEAD]
    for i, (e, r) in enumerate(zip(eps, rims)):
        design = f"{i},23,47,20,1,1.25,0.38,0.2,-0.1,3,30,12.5,25,{r},100,120,{e}"
        for m, f in {"fem": [1.0] * len(eps), "fem_bore_fixed": [0.9] * len(eps), **factors}.items():
            k = 1e9 * f[i]
            single = "" if e >= 2 else f"{0.8 * k}"
            rows.append(
                f"{design},{m},{k},{single},{1.2 * k},{0.3 * k},{0.1 * k},{0.05 * k},{0.02 * k},1.5,{0.1 * f[i]},0.2"
            )
    return "\n".join(rows) + "\n"


def test_errors_summaries_and_cells_are_the_known_factors():
    eps = [1.5, 1.7, 1.9, 2.1, 1.5, 1.8]
    rims = [2.0, 2.5, 5.0, 6.0, 8.0, 2.2]
    a = [1.10, 1.20, 1.05, 1.30, 1.02, 0.90]
    b = [0.95, 0.97, 1.40, 1.01, 1.50, 0.99]
    t = A.Table(_csv({"a": a, "b": b}, eps, rims))
    assert t.n == 6 and t.analytic == ["a", "b"]
    e = A.errors(t)
    assert np.allclose(e["a"]["mean_N_per_m"], np.array(a) - 1, atol=1e-12)
    # the fluctuation is compared over the FE mean: (0.9 - 1) 0.3 k / k
    assert np.allclose(e["fem_bore_fixed"]["p2p_N_per_m"], -0.03, atol=1e-12)
    assert np.allclose(e["a"]["h1_N_per_m"], 0.1 * (np.array(a) - 1), atol=1e-12)
    # a zone the pair does not have is left out, never an error of 0 or -100 %
    assert np.isnan(e["a"]["single_N_per_m"][3]) and A.stats(e["a"]["single_N_per_m"])["n"] == 5
    # the angle metrics are differences in degrees
    assert e["b"]["entry_deg"][2] == pytest.approx(0.1 * 1.40 - 0.1)
    s = A.stats(e["a"]["mean_N_per_m"])
    assert s["max_abs"] == pytest.approx(0.30) and s["median_abs"] == pytest.approx(np.median(np.abs(np.array(a) - 1)))
    assert s["p95_abs"] == pytest.approx(np.percentile(np.abs(np.array(a) - 1), 95))
    cells = {(r["contact"], r["rim"]): r for r in A.which_model_where(t, e)}
    # thin rims (2.0, 2.5, 2.2) at eps < 2: b is within 5 %, a is off by 10-20 %
    thin = [r for k, r in cells.items() if k[1].startswith("thin")]
    assert all(r["best"] == "b" for r in thin)
    # designs 2 (eps 1.9, rim 5) and 4 (eps 1.5, rim 8): a is best there
    solid = [r for k, r in cells.items() if not k[1].startswith("thin") and k[0] != "eps >= 2"]
    assert solid and all(r["best"] == "a" for r in solid)
    assert sum(r["designs"] for r in cells.values()) == 6


def test_binned_median_and_the_held_out_split():
    x = np.arange(100.0)
    e = np.where(x < 50, 1.0, 3.0)
    m = A.binned_error(x, e, np.array([0.0, 50.0, 99.0]))
    assert m.tolist() == [1.0, 3.0]
    h = A.held_out(500)
    assert h.sum() == 100 and (A.held_out(500) == h).all()


@pytest.mark.parametrize("eps", [1.4, 1.75, 2.3])
def test_log_ratios_take_the_zone_means_of_both_curves(eps):
    t = A.Table(_csv({"energy": [1.25, 1.25]}, [eps, eps], [3.0, 3.0]))
    r = A.log_ratios(t, "energy")
    assert np.allclose(r["mean"], math.log(1 / 1.25))
    assert np.allclose(r["lo"], math.log(1 / 1.25)) and np.allclose(r["hi"], math.log(1 / 1.25))


def test_a_constant_model_gives_no_fluctuation_and_refusals_are_counted():
    eps, rims = [1.5, 1.7, 2.2], [2.0, 4.0, 8.0]
    text = _csv({"iso": [1.1, 1.2, 0.9]}, eps, rims)
    # make "iso" a constant: zero peak-to-peak and harmonics on every design
    rows = [r.split(",") for r in text.splitlines()]
    col = {c: i for i, c in enumerate(rows[0])}
    for r in rows[1:]:
        if r[col["model"]] == "iso":
            for c in ("p2p_N_per_m", "h1_N_per_m", "h2_N_per_m", "h3_N_per_m"):
                r[col[c]] = "0"
    t = A.Table("\n".join(",".join(r) for r in rows) + "\n")
    assert A.constant_models(t) == ["iso"]
    e = A.errors(t)
    for k in A.FLUCTUATION:
        assert np.isnan(e["iso"][k]).all(), k  # not given, never -100 %
    assert np.allclose(e["iso"]["mean_N_per_m"], [0.1, 0.2, -0.1])
    side = {"notes": {"iso": {"3": "refused: teeth = 153: ...", "4": "failed: ValueError"}, "b": {}}}
    assert A.refusals(side) == {"iso": {"refused": 1, "failed": 1}, "b": {"refused": 0, "failed": 0}}


def test_failure_modes_find_the_axis_the_error_follows(monkeypatch):
    # model "a" is off by a factor that grows with the rim, "b" by one that grows with the load
    n = 16
    rims = list(np.linspace(1.5, 12.0, n))
    eps = [1.5 + 0.05 * (i % 7) for i in range(n)]
    a = [1.0 + 0.02 * r for r in rims]
    rng = np.random.default_rng(3)
    b = list(1.0 + 0.1 * rng.random(n))
    t = A.Table(_csv({"a": a, "b": b}, eps, rims))
    # the derived base/root axis needs pairs; here it is a constant so it never wins
    monkeypatch.setattr(A, "pairs_of", lambda t, inputs: [_Pair()] * t.n)
    f = {r["model"]: r for r in A.failure_modes(t, {}, A.errors(t))}
    assert f["a"]["axis"] == "rim_thickness_module" and f["a"]["spearman"] == pytest.approx(1.0)
    q1, q3 = np.percentile(rims, [25, 75])
    assert f["a"]["median_low"] == pytest.approx(np.median([0.02 * r for r in rims if r <= q1]))
    assert f["a"]["median_high"] == pytest.approx(np.median([0.02 * r for r in rims if r >= q3]))
    assert f["a"]["median_signed"] == pytest.approx(np.median(np.array(a) - 1))
    assert f["a"]["mechanism"] == "" and "fem_bore_fixed" in f


class _Gear:
    base_radius_m, root_radius_m = 0.05, 0.049


class _Pair:
    module_m, gears = 0.003, (_Gear(), _Gear())


def test_the_clamp_axes_are_the_largest_gaps_of_either_sign(monkeypatch):
    """explanatory_axes' two derived axes, per design: the largest (r_b - r_f) / m over the two
    gears (material a base-clamped model leaves out) and the largest (r_f - r_b) / m (body it
    counts as tooth), from radii set by hand: a pinion 1 m base-above-root with a wheel 2 m
    root-above-base gives 1 and 2; two gears 0.5 m and 0.25 m base-above-root give 0.5 and -0.25."""
    m = 0.003

    class G:
        def __init__(self, rb_minus_rf_modules):
            self.base_radius_m, self.root_radius_m = 0.05 + rb_minus_rf_modules * m, 0.05

    class P:
        def __init__(self, *gaps):
            self.module_m, self.gears = m, tuple(G(x) for x in gaps)

    t = A.Table(_csv({"a": [1.0, 1.1]}, [1.5, 1.6], [3.0, 4.0]))
    monkeypatch.setattr(A, "pairs_of", lambda t, inputs: [P(1.0, -2.0), P(0.5, 0.25)])
    ax = A.explanatory_axes(t, {})
    np.testing.assert_allclose(ax["base_above_root_module"][1], [1.0, 0.5], rtol=1e-12)
    np.testing.assert_allclose(ax["root_above_base_module"][1], [2.0, -0.25], rtol=1e-12)
