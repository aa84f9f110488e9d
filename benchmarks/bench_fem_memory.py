"""The pair FE's memory estimate (fem.memory), fitted and checked on the atlas corners.

For every body of benchmarks/bench_atlas.py's corners: the dofs fem.memory estimates before
meshing (fem.pair_body.estimated_dofs), and for every corner whose bodies this machine can
mesh, the element count and dofs of the real mesh (fem.pair_body, meshed and assembled in a
process of its own, the condensation skipped). The element model's coefficients are fitted
by least squares over those bodies; the memory model M = M0 + c sum_b n_b log2 n_b by least
squares on its relative error against the peak resident memory of the whole FE run that
bench_atlas.py recorded per corner (its max_rss_MB, against the dofs n_b of the corner's
distinct bodies: fem.pair_model builds two at the same time). Writes
benchmarks/results/bench_fem_memory.json; fem.memory's constants are these fits, rounded
(tests/test_fem_memory.py checks they agree).

    .venv/bin/python benchmarks/bench_fem_memory.py
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results" / "bench_fem_memory.json"
#: corners too large to mesh here (fem.memory refuses them: the estimate only)
ESTIMATE_ONLY = ("z100_ratio5_solid",)
#: light loads (a finer contact zone, h_c = a_ref / 2.5) besides the corners' 200 N/mm
LIGHT = ("paper_40Nm", "reference_23_47_20Nmm")


def case(name: str):
    """(pair, torque N m) of a corner of bench_atlas.py or of a light-load case."""
    from bench_atlas import corner

    from gearwear.geometry.spec import default_pair

    if name == "paper_40Nm":
        return default_pair(), 40.0
    if name == "reference_23_47_20Nmm":
        d = corner("reference_23_47")
        return d.pair, 20e3 * d.pair.face_width_m * d.pair.gear(0).base_radius_m
    d = corner(name)
    return d.pair, d.torque_Nm


def measure(name: str) -> list[dict]:
    """Per body of corner ``name``: the estimate, and the real mesh's elements and dofs (the
    FE stopped at its first condensation), in this process."""

    import gearwear.fem.pair_body as pb
    import gearwear.fem.pair_model as pmod
    from gearwear.fem.pair import pair_contact
    from gearwear.geometry.profile import polygon_area

    rows: list[dict] = []
    meshes: list[dict] = []
    orig_mesh, orig_check, orig_dofs = pb.mesh_full_gear, pmod.check_bodies, pb.body_dofs
    terms: list[dict] = []

    def spy_dofs(area, rf, bore, global_m, far_m, flank_m=0.0, contact_m=1.0, growth=0.25):
        terms.append({"flank_m": flank_m, "contact_m": contact_m, "growth": growth})
        return orig_dofs(area, rf, bore, global_m, far_m, flank_m, contact_m, growth)

    def spy_check(bodies):
        # body_dofs runs once per gear, in gear order; two equal gears check one body
        for gi, _, teeth, bore, dofs in bodies:
            row = {"corner": name, "gear": gi, "teeth": teeth, "bore_m": bore, "dofs_estimate": dofs}
            rows.append({**row, **terms[gi]})
        orig_check(bodies)

    def spy_mesh(outline, hub, msz, **kw):
        gm = orig_mesh(outline, hub, msz, **kw)
        meshes.append({"bore_m": hub, "elements": int(gm.n_elements), "outline_area_m2": float(polygon_area(outline))})
        return gm

    def stop(cls, gear, sizes, r_lo, gm, model, *a, **k):
        for m in meshes:
            if m["elements"] == gm.n_elements:
                m.update(dofs=int(model.basis.N), root_m=gear.root_radius_m, global_m=sizes.global_m, far_m=sizes.far_m)
        if all("dofs" in m for m in meshes) and len(meshes) == len({(r["teeth"], r["bore_m"]) for r in rows}):
            raise _Done  # every distinct body meshed (two equal gears share one)
        return None

    pmod.check_bodies, pb.mesh_full_gear, pb._condensed, pb.body_dofs = spy_check, spy_mesh, stop, spy_dofs
    pair, torque = case(name)
    try:
        pair_contact(pair, torque_Nm=torque, positions=4)
    except _Done:
        pass
    for r in rows:
        for m in meshes:
            if abs(m["bore_m"] - r["bore_m"]) < 1e-12 and "dofs" in m and not m.get("used"):
                r.update(m)
                m["used"] = True
    for r in rows:
        r.pop("used", None)
    return rows


class _Done(Exception):
    pass


class _Stop(Exception):
    pass


def main() -> None:
    if len(sys.argv) > 2 and sys.argv[1] == "--one":
        name = sys.argv[2]
        if name in ESTIMATE_ONLY:
            import gearwear.fem.pair_model as pmod

            sys.path.insert(0, str(HERE))
            from bench_atlas import corner

            rows = []

            def spy_check(bodies):
                for gi, _, teeth, bore, dofs in bodies:
                    rows.append({"corner": name, "gear": gi, "teeth": teeth, "bore_m": bore, "dofs_estimate": dofs})
                raise _Stop

            pmod.check_bodies = spy_check
            d = corner(name)
            try:
                pmod.pair_model(d.pair, None, d.torque_Nm, 0.0)
            except _Stop:
                pass
            print(json.dumps(rows))
        else:
            sys.path.insert(0, str(HERE))
            print(json.dumps(measure(name)))
        return
    sys.path.insert(0, str(HERE))
    from bench_atlas import CORNERS

    from gearwear.fem import memory

    bodies = []
    for name in (*CORNERS, *LIGHT):
        p = subprocess.run([sys.executable, __file__, "--one", name], capture_output=True, text=True)
        if p.returncode != 0:
            raise SystemExit(f"{name}: {p.stderr.strip().splitlines()[-1]}")
        got = json.loads(p.stdout.strip().splitlines()[-1])
        bodies += got
        for b in got:
            print(
                f"{name:20s} gear {b['gear']} z {b['teeth']:4d}: estimate {b['dofs_estimate'] / 1e6:6.3f} M dofs"
                + (
                    f", mesh {b['dofs'] / 1e6:6.3f} M ({b['dofs_estimate'] / b['dofs'] - 1:+.1%})"
                    if "dofs" in b
                    else ""
                ),
                flush=True,
            )
    meshed = [b for b in bodies if "dofs" in b]
    a = math.sqrt(3) / 4
    X = np.array(
        [
            [
                math.pi * (b["root_m"] ** 2 - b["bore_m"] ** 2) / (a * b["global_m"] ** 2),
                max(b["outline_area_m2"] - math.pi * b["root_m"] ** 2, 0.0) / (a * b["far_m"] ** 2),
                b["flank_m"] / (a * b["growth"] * b["contact_m"]),
                1.0,
            ]
            for b in meshed
        ]
    )
    el = np.array([b["elements"] for b in meshed], float)
    coef = np.linalg.lstsq(X, el, rcond=None)[0]
    dpe = [b["dofs"] / b["elements"] for b in meshed]
    # the peak memory of the whole FE run per corner (bench_atlas.py), against its distinct
    # bodies (both built at the same time; fem.memory)
    atlas = json.loads((HERE / "results" / "bench_atlas.json").read_text())
    peaks = []
    for row in atlas["rows"]:
        if "max_rss_MB" not in row:
            continue
        dofs = [b["dofs"] for b in meshed if b["corner"] == row["corner"]]
        if dofs:
            peaks.append({"corner": row["corner"], "dofs": dofs, "peak_MB": row["max_rss_MB"]})
    fill = np.array([sum(n * math.log2(n) for n in p["dofs"]) for p in peaks])
    A = np.column_stack([np.ones_like(fill), fill])
    # least squares on the relative error, every corner alike: on the absolute error the
    # GB-sized corners decide alone and M0 moved from 224 to 190 MiB between two runs
    # (peaks moving by a few %), on the relative one from 235 to 216 MiB
    y = np.array([p["peak_MB"] for p in peaks]) * 2**20
    mem = np.linalg.lstsq(A / y[:, None], np.ones_like(y), rcond=None)[0]
    for p in peaks:
        p["model_MB"] = memory.peak_bytes(p["dofs"]) / 2**20
    out = {
        "bodies": bodies,
        "elements_fit": {"body": coef[0], "teeth": coef[1], "contact": coef[2], "tooth0": coef[3]},
        "elements_fit_max_rel_error": float(np.max(np.abs(X @ coef / el - 1))),
        "dofs_per_element": [min(dpe), max(dpe)],
        "estimate_max_rel_error": max(abs(b["dofs_estimate"] / b["dofs"] - 1) for b in meshed),
        "peaks": peaks,
        "memory_fit": {"M0_MiB": mem[0] / 2**20, "c_bytes": mem[1]},
        "memory_model_max_rel_error": max(abs(p["model_MB"] / p["peak_MB"] - 1) for p in peaks),
    }
    RESULTS.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({k: v for k, v in out.items() if k not in ("bodies", "peaks")}, indent=1))


if __name__ == "__main__":
    main()
