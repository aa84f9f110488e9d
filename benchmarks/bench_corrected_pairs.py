"""The corrected model out of sample (issue 28): pairs that are not atlas designs, each with its
own module, face width, shifts and load, the pair FE (blanks' torsion taken out, plane stress
as the atlas) against the corrected model and the analytic models it is meant to beat. Their
means are compared as the atlas compares them (gearwear.jobs.atlas_metrics.curve_metrics).

    .venv/bin/python benchmarks/bench_corrected_pairs.py

writes benchmarks/results/bench_corrected_pairs.json (nothing asserted; the FE takes seconds
per pair, the models milliseconds: both are reported).
"""

from __future__ import annotations

import dataclasses
import datetime
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
RESULTS = ROOT / "benchmarks" / "results" / "bench_corrected_pairs.json"
MODELS = ("corrected", "energy", "ishikawa", "chen_shao", "iso6336")


def _rims(pair, rim_modules: float):
    """``pair`` with r_f - bore = rim_modules m on both gears."""
    return dataclasses.replace(
        pair, hub_radius_m=tuple(g.root_radius_m - rim_modules * pair.module_m for g in pair.gears)
    )


def pairs():
    """(name, pair, driver torque N m): unequal shifted, driver larger, other modules and widths."""
    from gearwear.geometry.spec import Material, PairSpec
    from tests.pairs import DRIVER_LARGER, UNEQUAL

    steel = Material(youngs_modulus_Pa=206e9, poisson_ratio=0.3)
    p19 = PairSpec(
        teeth=(19, 45),
        module_m=2e-3,
        pressure_angle_rad=math.radians(20.0),
        face_width_m=20e-3,
        profile_shift=(0.4, 0.0),
        hub_radius_m=(5e-3, 10e-3),
        materials=(steel, steel),
    )
    p28 = PairSpec(
        teeth=(28, 70),
        module_m=4e-3,
        pressure_angle_rad=math.radians(18.0),
        face_width_m=40e-3,
        addendum_coefficient=1.2,
        dedendum_coefficient=1.45,
        profile_shift=(0.3, 0.1),
        hub_radius_m=(10e-3, 20e-3),
        materials=(steel, steel),
    )
    return [
        ("23/47, m 3, x +0.2/-0.1, rims 6 m, 120 N m", _rims(UNEQUAL, 6.0), 120.0),
        ("47/23 (driver larger), rims 4 m, 250 N m", _rims(DRIVER_LARGER, 4.0), 250.0),
        ("19/45, m 2, b 20 mm, x +0.4/0, rims 3 m, 60 N m", _rims(p19, 3.0), 60.0),
        ("28/70, m 4, b 40 mm, 18 deg, h_a* 1.2, x +0.3/+0.1, rims 8 m, 900 N m", _rims(p28, 8.0), 900.0),
    ]


def main() -> int:
    from gearwear.fem.pair import pair_contact
    from gearwear.jobs.atlas_metrics import curve_metrics
    from gearwear.stiffness.corrected import committed
    from gearwear.stiffness.sources import Request, curve

    committed()  # the surrogate is refitted once per process (timed apart from the curves)
    rows = []
    for name, p, T in pairs():
        t = time.perf_counter()
        r = pair_contact(p, positions=24, torque_Nm=T, plane="stress", extended=True)
        fe = curve_metrics(r.without_blank_torsion(), r.meta.get("extended_contact_deg"))["mean_N_per_m"]
        row = {"pair": name, "fem_mean_N_per_m": fe, "fem_wall_s": time.perf_counter() - t, "models": {}}
        for m in MODELS:
            t = time.perf_counter()
            k = curve_metrics(curve(m, Request(p, T, plane="stress")))["mean_N_per_m"]
            row["models"][m] = {"mean_N_per_m": k, "error": k / fe - 1.0, "wall_s": time.perf_counter() - t}
        rows.append(row)
        print(name, {m: f"{100 * v['error']:+.1f} %" for m, v in row["models"].items()}, flush=True)
    doc = {"when": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"), "rows": rows}
    RESULTS.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n")
    print(f"wrote {RESULTS}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
