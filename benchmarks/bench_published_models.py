"""The published analytic mesh-stiffness models (issue 28): what each gives, how it was
checked, and what it costs, in one run.

For every analytic method of the registry (ishikawa, energy and the published models of
``analytic.involute_beam`` and ``analytic.kuang_yang``):

* the mean k_h (N/m) of the paper pair (40 N m) and of the unequal 23/47 pair and its
  driver-larger twin (120 N m), default tables (360 nodes per mesh period + breakpoints);
* the CPU time of one such curve (time.process_time, median of 15 warm runs alternating
  with the energy method's) and its ratio to the energy method's (the machine is shared:
  ratios, not seconds);
* the check of each published model against an independent truth
  (tests/test_models_published.py holds the same checks as tests):
  - yang_lin, tian, wu_zuo_parey, chen_shao, chen_shao_weber: the largest relative
    difference of the beam terms (bending, shear, axial) from the height integrals by
    adaptive quadrature (scipy.integrate.quad on the involute written from its polar form),
    and of the foundation term from the published formula at the clamped section of the
    hand geometry, over the four gears of the two test pairs at five contact radii each;
  - kuang_yang: the pitch-point pair stiffness (two teeth in series) over ISO 6336-1's
    c'_th (the q' polynomial) on the test pairs and a sweep of standard pairs;
* robustness over the geometry's space: 200 random valid pairs (tests/pairs.py
  ``valid_pairs``: z 12-120, m 1-10 mm, 14.5-25 deg, shifts up to 0.8; hypothesis,
  derandomized, so the same pairs every run) at a line load of 100 N/mm: how many curves
  are finite and positive, refused in one line (InputError) or crash, and each model's
  mean k_h over the energy method's (median, min, max).

    .venv/bin/python benchmarks/bench_published_models.py

Writes benchmarks/results/bench_published_models.json, from which docs/generate.py fills
the published-models table of docs/models.md.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from test_models_published import _by_quadrature, _hand_foundation, _iso_c_th, _radii  # noqa: E402

from gearwear.analytic import involute_beam, kuang_yang  # noqa: E402
from gearwear.analytic.tvms import METHODS, mesh_stiffness  # noqa: E402
from gearwear.geometry.spec import default_pair  # noqa: E402

from pairs import DRIVER_LARGER, UNEQUAL, checked  # noqa: E402

OUT = ROOT / "benchmarks" / "results" / "bench_published_models.json"
CASES = {
    "paper_30_30": (default_pair(), 40.0),
    "unequal_23_47": (UNEQUAL, 120.0),
    "driver_larger_47_23": (DRIVER_LARGER, 120.0),
}


def cpu_ab_s(fn, ref, repeat: int = 15) -> tuple[float, float]:
    """Median CPU times (s) of ``fn`` and of ``ref``, run alternately (A/B in the same
    stretch of a shared machine), after one warm run of each."""
    fn(), ref()
    a, b = [], []
    for _ in range(repeat):
        for f, out in ((fn, a), (ref, b)):
            t0 = time.process_time()
            f()
            out.append(time.process_time() - t0)
    return statistics.median(a), statistics.median(b)


def beam_check(model: str) -> float:
    """Largest relative difference of the closed angular integrals from quad, and of the
    foundation term from the published formula at the hand geometry's clamped section."""
    clamp, with_shear, kind = involute_beam.MODELS[model]
    worst = 0.0
    for p in (UNEQUAL, DRIVER_LARGER):
        for g in p.gears:
            R = _radii(g, 5)
            c = involute_beam.tooth_compliance(model, g, R, p.face_width_m)
            for i, r in enumerate(R):
                q = (
                    *_by_quadrature(g, float(r), clamp, p.face_width_m),
                    _hand_foundation(g, float(r), model, p.face_width_m),
                )
                ours = (c.bending_m_per_N[i], c.shear_m_per_N[i], c.axial_m_per_N[i], c.foundation_m_per_N[i])
                for a, b in zip(ours, q):
                    if b > 0 and (with_shear or a > 0):
                        worst = max(worst, abs(a / b - 1))
    return worst


def ky_over_iso(p) -> float:
    g = sorted(p.gears, key=lambda g: g.teeth)
    K = [kuang_yang.tooth_stiffness_N_per_m(gi, gi.pitch_radius_m, 1e-3)[0] / 1e6 for gi in g]
    return (1.0 / (1.0 / K[0] + 1.0 / K[1])) / _iso_c_th(g[0].teeth, g[1].teeth, g[0].profile_shift, g[1].profile_shift)


def robustness(n: int = 200) -> dict:
    """Counts per model (ok / refused / crash) and the mean k_h over energy's on ``n``
    random valid pairs (hypothesis, derandomized)."""
    from hypothesis import HealthCheck, given, settings

    from gearwear.core.validation import InputError

    from pairs import valid_pairs

    counts = {m: {"ok": 0, "refused": 0, "crash": 0} for m in METHODS}
    ratio: dict[str, list[float]] = {m: [] for m in METHODS}

    @settings(max_examples=n, deadline=None, derandomize=True, database=None, suppress_health_check=list(HealthCheck))
    @given(p=valid_pairs(max_shift=0.8))
    def run(p):
        torque = 100e3 * p.face_width_m * p.gear(0).base_radius_m  # 100 N/mm of face along the LOA
        means = {}
        for m in METHODS:
            try:
                r = mesh_stiffness(p, method=m, points=32, torque_Nm=torque)
            except InputError:
                counts[m]["refused"] += 1
                continue
            except Exception:  # noqa: BLE001 - counted, never raised: the benchmark reports it
                counts[m]["crash"] += 1
                continue
            good = bool(np.all(np.isfinite(r.k_N_per_m)) and np.all(r.k_N_per_m > 0))
            counts[m]["ok" if good else "crash"] += 1
            means[m] = r.mean_N_per_m
        for m, v in means.items():
            if "energy" in means:
                ratio[m].append(v / means["energy"])

    run()
    return {
        m: {
            **counts[m],
            **({"ratio_median": float(np.median(r)), "ratio_min": min(r), "ratio_max": max(r)} if r else {}),
        }
        for m, r in ratio.items()
    }


def main() -> None:
    rows = {}

    def energy():
        return mesh_stiffness(UNEQUAL, method="energy", torque_Nm=120.0)

    for m in METHODS:
        row = {
            "mean_N_per_m": {k: mesh_stiffness(p, method=m, torque_Nm=T).mean_N_per_m for k, (p, T) in CASES.items()}
        }
        c, e = cpu_ab_s(lambda m=m: mesh_stiffness(UNEQUAL, method=m, torque_Nm=120.0), energy)
        row["cpu_s_unequal"] = c
        row["cpu_over_energy"] = c / e
        if m in involute_beam.MODELS:
            row["check"] = {"kind": "quad", "max_rel_diff": beam_check(m)}
        elif m == "kuang_yang":
            sweep = [
                checked(teeth=z, module_m=3e-3, profile_shift=x, face_width_m=30e-3, hub_radius_m=(10e-3, 10e-3))
                for z, x in [((15, 15), (0.3, 0.3)), ((20, 20), (0, 0)), ((17, 40), (0.3, 0)), ((30, 30), (0, 0)),
                             ((25, 75), (0.2, -0.2)), ((40, 80), (0, 0)), ((60, 90), (0.1, 0.1)), ((100, 100), (0, 0))]
            ]  # fmt: skip
            ratios = [ky_over_iso(p) for p in sweep]
            row["check"] = {
                "kind": "iso_c_th",
                "ratio": {k: ky_over_iso(p) for k, (p, _) in CASES.items()},
                "sweep_min": min(ratios),
                "sweep_max": max(ratios),
                "sweep_pairs": [
                    f"{p.teeth[0]}/{p.teeth[1]} x {p.profile_shift[0]:g}/{p.profile_shift[1]:g}" for p in sweep
                ],
            }
        rows[m] = row
        print(
            m,
            {k: f"{v:.4g}" for k, v in row["mean_N_per_m"].items()},
            f"cpu x{row['cpu_over_energy']:.2f}",
            row.get("check"),
        )
    rob = robustness()
    for m, r in rob.items():
        print(m, r)
    cpu = "time.process_time, median of 15 warm runs alternating with energy's"
    doc = {"methods": rows, "robustness": rob, "cpu": cpu}
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
