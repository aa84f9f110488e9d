"""Mesh stiffness timings: one full 360-angle TVMS curve per method, against ROSS.

Times ``analytic.tvms.mesh_stiffness`` (methods ``ishikawa`` and ``energy``, 360 angle
points over one mesh period, 40 N m) on the built-in paper pair: the median of 21 runs
after one warm-up (the tooth profiles are then cached, as in a sweep), plus the cold
first call. Also times the ISO 6336-1 constant (``analytic.iso6336``) when importable.

In the same run it computes the TVMS of the same pair with ROSS
(``ross-rotordynamics``, ``GearElementTVMS`` + ``Mesh``, see ``ross_tvms.py``) in the
separate benchmark environment ``.venv-bench`` (ROSS is not a dependency of this
project)::

    python3 -m venv .venv-bench
    .venv-bench/bin/python -m pip install 'ross-rotordynamics==2.3.0' 'plotly<7'

If that environment is missing (or ROSS fails) the ROSS columns are left empty and a
note says why. ROSS's curve is load independent; ours is at 40 N m.

Prints a table (median wall, mean/min/max k, difference of the mean vs ROSS, speed
ratio ROSS/ours) and writes the same to benchmarks/results/bench_stiffness.json.
Timings are reported, never asserted; nothing here fails the run.
"""

from __future__ import annotations

import datetime
import inspect
import json
import math
import os
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT) not in sys.path:  # run as a plain script from anywhere
    sys.path.insert(0, str(ROOT))

POINTS = 360
TORQUE_NM = 40.0
RUNS = 21
METHODS = ("ishikawa", "energy")
ROSS_SCRIPT = HERE / "ross_tvms.py"
ROSS_PYTHON = Path(os.environ.get("GEARWEAR_BENCH_PYTHON", ROOT / ".venv-bench" / "bin" / "python"))
ROSS_REPEATS = 3
ROSS_TIMEOUT_S = 1800
OUT_JSON = HERE / "results" / "bench_stiffness.json"
BENCH_VENV_HELP = (
    "python3 -m venv .venv-bench && .venv-bench/bin/python -m pip install 'ross-rotordynamics==2.3.0' 'plotly<7'"
)


from _timing import median_time  # noqa: E402  (benchmarks/_timing.py)


def short_error(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".strip().splitlines()[0][:300]


def pair_for_ross(pair) -> dict:
    """The pair in ross_tvms.py's JSON keys (the same gear pair, not a copy of defaults)."""
    return {
        "teeth": list(pair.teeth),
        "module_mm": pair.module_m * 1e3,
        "pressure_angle_deg": math.degrees(pair.pressure_angle_rad),
        "face_width_mm": pair.face_width_m * 1e3,
        "youngs_modulus_GPa": pair.materials[0].youngs_modulus_Pa / 1e9,
        "poisson_ratio": pair.materials[0].poisson_ratio,
        "density_kg_per_m3": pair.materials[0].density_kg_per_m3,
        "hub_radius_mm": [h * 1e3 for h in pair.hub_radius_m],
        "addendum_coefficient": pair.addendum_coefficient,
        "dedendum_coefficient": pair.dedendum_coefficient,
        "rack_tip_radius_coefficient": pair.rack_tip_radius_coefficient,
        "profile_shift": list(pair.profile_shift),
    }


def ours(pair, notes):
    """Rows for analytic.tvms methods (curves)."""
    rows = []
    try:
        from gearwear.analytic import tvms
        from gearwear.analytic.tvms import mesh_stiffness
    except Exception as exc:  # noqa: BLE001 - report, never fail
        notes.append(f"analytic.tvms not importable ({short_error(exc)}): our TVMS rows skipped")
        return rows
    for method in METHODS:
        row = {"method": method, "kind": "curve", "points": POINTS, "torque_Nm": TORQUE_NM}
        try:
            cache = getattr(getattr(tvms, "_profiles", None), "cache_clear", None)
            if cache is not None:
                cache()
            t0 = time.perf_counter()
            res = mesh_stiffness(pair, method=method, points=POINTS, torque_Nm=TORQUE_NM)  # warm-up
            row["cold_wall_s"] = time.perf_counter() - t0
            row["wall_s_median"] = median_time(
                lambda: mesh_stiffness(pair, method=method, points=POINTS, torque_Nm=TORQUE_NM), RUNS
            )
            row["runs"] = RUNS
            row["mean_N_per_m"] = float(res.mean_N_per_m)
            row["min_N_per_m"] = float(min(res.k_N_per_m))
            row["max_N_per_m"] = float(max(res.k_N_per_m))
            row["angle_rad"] = [float(x) for x in res.angle_rad]
            row["k_N_per_m"] = [float(x) for x in res.k_N_per_m]
        except Exception as exc:  # noqa: BLE001
            row["error"] = short_error(exc)
            notes.append(f"{method}: failed ({row['error']})")
        rows.append(row)
    return rows


def iso(pair, notes):
    """Rows for the ISO 6336-1 method B constant (no curve)."""
    try:
        from gearwear.analytic.iso6336 import iso6336_stiffness
    except Exception as exc:  # noqa: BLE001
        notes.append(f"analytic.iso6336 not importable ({short_error(exc)}): ISO 6336 row skipped")
        return []
    try:
        kw = {"torque_Nm": TORQUE_NM} if "torque_Nm" in inspect.signature(iso6336_stiffness).parameters else {}
        res = iso6336_stiffness(pair, **kw)
        wall = median_time(lambda: iso6336_stiffness(pair, **kw), RUNS)
        rows = [
            {
                "method": "iso6336",
                "kind": "constant c_gamma_alpha b",
                "wall_s_median": wall,
                "runs": RUNS,
                "mean_N_per_m": float(res.mesh_stiffness_N_per_m),
                "torque_Nm": kw.get("torque_Nm"),
            }
        ]
        low = getattr(res, "mesh_stiffness_low_load_N_per_m", None)
        if low is not None and kw and low != res.mesh_stiffness_N_per_m:
            rows.append(
                {
                    "method": "iso6336 low-load",
                    "kind": "constant, low-load factor at 40 N m",
                    "wall_s_median": wall,
                    "runs": RUNS,
                    "mean_N_per_m": float(low),
                    "torque_Nm": TORQUE_NM,
                }
            )
        return rows
    except Exception as exc:  # noqa: BLE001
        notes.append(f"iso6336: failed ({short_error(exc)})")
        return [{"method": "iso6336", "error": short_error(exc)}]


def ross(pair, notes):
    """ROSS's TVMS from the separate benchmark environment, or None."""
    if not ROSS_PYTHON.exists():
        notes.append(
            f"ROSS skipped: no benchmark environment at {ROSS_PYTHON}. Create it (from the "
            f"project root) with:  {BENCH_VENV_HELP}"
        )
        return None
    cmd = [
        str(ROSS_PYTHON),
        str(ROSS_SCRIPT),
        "--pair",
        json.dumps(pair_for_ross(pair)),
        "--points",
        str(POINTS),
        "--repeats",
        str(ROSS_REPEATS),
    ]
    try:
        # cwd: a scratch dir, since ROSS's dependencies probe the cwd for shared libraries
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=ROSS_TIMEOUT_S, cwd=tempfile.gettempdir())
    except Exception as exc:  # noqa: BLE001 - includes TimeoutExpired
        notes.append(f"ROSS skipped: {short_error(exc)}")
        return None
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        tail = " | ".join((proc.stderr or proc.stdout).strip().splitlines()[-3:])
        notes.append(f"ROSS skipped: ross_tvms.py exited {proc.returncode}: {tail[:500]}")
        return None
    try:
        out = json.loads(lines[-1])
    except ValueError as exc:
        notes.append(f"ROSS skipped: unreadable output ({short_error(exc)})")
        return None
    notes.extend(f"ROSS: {n}" for n in out.get("notes", []))
    notes.extend(f"ROSS warned: {w}" for w in out.get("warnings", []))
    return out


def compare(rows, ross_out):
    if ross_out is None:
        return
    k_ross, t_ross = ross_out["mean_N_per_m"], ross_out["wall_s_median"]
    for r in rows:
        if "mean_N_per_m" in r:
            r["mean_diff_vs_ross_pct"] = 100.0 * (r["mean_N_per_m"] - k_ross) / k_ross
        if r.get("wall_s_median"):
            r["speed_ratio_ross_over_ours"] = t_ross / r["wall_s_median"]


def fmt(value, spec, width):
    return f"{'-' if value is None else format(value, spec):>{width}}"


def print_table(rows, ross_out):
    print(
        f"{'method':<18}{'median wall':>14}{'mean k':>13}{'min k':>12}{'max k':>12}"
        f"{'mean vs ROSS':>14}{'ROSS/ours':>11}"
    )
    print(f"{'':<18}{'(ms)':>14}{'(N/m)':>13}{'(N/m)':>12}{'(N/m)':>12}{'(%)':>14}{'(speed)':>11}")
    allrows = list(rows)
    if ross_out is not None:
        allrows.append(
            {
                "method": f"ROSS {ross_out['ross_version']}",
                "wall_s_median": ross_out["wall_s_median"],
                "mean_N_per_m": ross_out["mean_N_per_m"],
                "min_N_per_m": ross_out["min_N_per_m"],
                "max_N_per_m": ross_out["max_N_per_m"],
                "mean_diff_vs_ross_pct": 0.0,
                "speed_ratio_ross_over_ours": 1.0,
            }
        )
    for r in allrows:
        if "error" in r:
            print(f"{r['method']:<18}  failed: {r['error']}")
            continue
        wall = r.get("wall_s_median")
        print(
            f"{r['method']:<18}{fmt(None if wall is None else wall * 1e3, '.3f', 14)}"
            f"{fmt(r.get('mean_N_per_m'), '.4e', 13)}{fmt(r.get('min_N_per_m'), '.3e', 12)}"
            f"{fmt(r.get('max_N_per_m'), '.3e', 12)}{fmt(r.get('mean_diff_vs_ross_pct'), '+.2f', 14)}"
            f"{fmt(r.get('speed_ratio_ross_over_ours'), '.1f', 11)}"
        )


def write_json(path: Path, data: dict) -> None:
    """Atomic write (temp file + rename) through the project's shared writer."""
    from gearwear.core.atomic import atomic_write_bytes

    atomic_write_bytes(path, (json.dumps(data, indent=1) + "\n").encode())


def main():
    notes: list[str] = []
    rows: list[dict] = []
    ross_out = None
    pair = None
    try:
        from gearwear.geometry.spec import default_pair

        pair = default_pair()
    except Exception as exc:  # noqa: BLE001
        notes.append(f"geometry.spec.default_pair failed ({short_error(exc)}): nothing to time")
    if pair is not None:
        for section in (ours, iso):
            try:
                rows += section(pair, notes)
            except Exception as exc:  # noqa: BLE001
                notes.append(f"{section.__name__}: {short_error(exc)}")
        try:
            ross_out = ross(pair, notes)
        except Exception as exc:  # noqa: BLE001
            notes.append(f"ROSS skipped: {short_error(exc)}")
        compare(rows, ross_out)
    print(
        f"{POINTS}-angle TVMS over one mesh period, paper pair, ours at {TORQUE_NM:g} N m "
        f"(median of {RUNS} after a warm-up); ROSS median of {ROSS_REPEATS}"
    )
    print_table(rows, ross_out)
    for r in rows:
        if "cold_wall_s" in r:
            print(f"  {r['method']}: first (cold) call {r['cold_wall_s'] * 1e3:.1f} ms incl. tooth profiles")
    if ross_out is not None:
        print(
            f"  ROSS: construction {ross_out['construct_s']:.2f} s (Mesh() computes its own 1000-point "
            f"curve), import {ross_out['import_s']:.1f} s; grid {ross_out['grid']}"
        )
    for n in notes:
        print(f"  note: {n}")
    result = {
        "benchmark": "bench_stiffness",
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "python": sys.version.split()[0],
        "points": POINTS,
        "torque_Nm": TORQUE_NM,
        "pair": pair_for_ross(pair) if pair is not None else None,
        "rows": rows,
        "ross": ross_out,
        "notes": notes,
    }
    try:
        write_json(OUT_JSON, result)
        print(f"  wrote {OUT_JSON.relative_to(ROOT)}")
    except Exception as exc:  # noqa: BLE001
        print(f"  note: could not write {OUT_JSON} ({short_error(exc)})")


if __name__ == "__main__":
    try:
        main()
    except Exception:  # noqa: BLE001 - a benchmark must never stop make bench
        traceback.print_exc()
        print("bench_stiffness: failed (see above); continuing")
