"""``gearwear atlas``: every analytic mesh-stiffness model of the registry against the pair FE
over a space-filling design of spur pairs (issue 28's engine).

Per design (gearwear.jobs.atlas_space: Sobol points the geometry accepts) the engine computes

* the curve of every analytic model the SPEC names (gearwear.stiffness.sources: every
  ``command`` source that does not run the FE, so a model added to the registry appears
  here by itself), at the design's torque;
* the resolved pair FE (fem.pair.pair_contact), **one solve**: its result holds the
  bore-fixed curve (both blanks' torsion in series, ``blank_torsion = "in_series"``) and
  the mesh-only curve (the blanks' torsion below r_ref taken out, ``"excluded"``, which
  the analytic models are compared with: fem.pair, "The blank's torsion"); both enter the
  table, as models ``fem`` (excluded) and ``fem_bore_fixed`` (in_series);

and the metrics of each curve (gearwear.jobs.atlas_metrics). The designs run on any
executor of gearwear.jobs.sweep.make_executor (local processes, a Dask LocalCluster, a
running Dask scheduler), one task per design, with a progress bar.

Resumable: each design's FE metrics and each model's metrics are a cache entry
(gearwear.stiffness.tables' folder and rules: data + sidecar, atomic, checked on read)
keyed by the SHA-256 of their content: the design, the FE settings (or the model's
points and plane), the fingerprint of the code that computes them and the library
versions. An interrupted atlas keeps the designs it finished; a rerun computes only the
rest, and a model added to the registry costs only its own curves.

Outputs (written whole, gearwear.io.write_folder): ``atlas.csv``, one row per design and
model, and its sidecar ``atlas.csv.json`` (the SPEC with every default, the rejects by
reason, the models, the library versions); wall and CPU times per design go to
``timing.json`` only, so the same SPEC gives the same bytes on every executor.
"""

from __future__ import annotations

import contextlib
import functools
import json
import math
import resource
import sys
import time
from concurrent.futures import Executor, as_completed
from dataclasses import asdict
from pathlib import Path
from typing import Any

from gearwear import io
from gearwear.jobs.atlas_metrics import METRICS, curve_metrics
from gearwear.jobs.atlas_space import Design, DesignSpace, design_space
from gearwear.jobs.atlas_spec import AtlasSpec

#: bump when the meaning of a cached entry changes without a code change the fingerprint sees
ATLAS_VERSION = 1
#: the two FE rows of a design: mesh only (blanks' torsion excluded) and bore-fixed (in series)
FE_MODELS = ("fem", "fem_bore_fixed")
#: modules whose source changes the FE entries / the analytic entries (their imports follow)
FE_ROOTS = ("gearwear.fem.pair", "gearwear.jobs.atlas_metrics")
MODEL_ROOTS = ("gearwear.stiffness.sources", "gearwear.jobs.atlas_metrics")
LABEL = "atlas design"


def fe_settings(spec: AtlasSpec) -> dict[str, Any]:
    return {
        "positions": spec["fe.positions"],
        "mesh_scale": spec["fe.mesh_scale"],
        "contact_scale": spec["fe.contact_scale"],
        "plane": spec["fe.plane"],
        "transitions": spec["fe.transitions"],
    }


@functools.lru_cache(maxsize=None)
def _fingerprint(roots: tuple[str, ...]) -> str:
    from gearwear.stiffness.calibration import dependencies, fingerprint

    mods: set[str] = set()
    for r in roots:
        mods.update(dependencies(r))
    return fingerprint(mods)


def cache_inputs(spec: AtlasSpec, design: Design) -> dict[str, dict[str, Any]]:
    """The hashed inputs of each cache entry of ``design``: "fe" and one per model."""
    from gearwear.stiffness.calibration import library_versions

    pair = asdict(design.pair)
    common = {"atlas_version": ATLAS_VERSION, "pair": pair, "torque_Nm": design.torque_Nm}
    libs = library_versions()
    out = {"fe": {**common, "fe": fe_settings(spec), "code_sha256": _fingerprint(FE_ROOTS), "libraries": libs}}
    code = _fingerprint(MODEL_ROOTS)
    for m in spec.models:
        out[m] = {
            **common,
            "model": m,
            "points": spec["analytic.points"],
            "plane": spec["fe.plane"],
            "code_sha256": code,
            "libraries": libs,
        }
    return out


# -- one design (a worker's task) ----------------------------------------------------------


def _guarded(compute_rows):
    """``compute_rows()`` (a dict model -> metrics), or, when it raises, None and one line: a
    model that refuses the design ("refused: " + its one-line InputError: outside the model's
    validity) or fails on it ("failed: " + the exception; a bug to report). One design never
    ends a long atlas; its rows are empty and the sidecar lists why (``notes``)."""
    from gearwear.core.validation import InputError

    try:
        return compute_rows(), None
    except InputError as exc:
        return None, f"refused: {exc}"
    except Exception as exc:  # recorded per design: the run goes on
        first = str(exc).splitlines()[0] if str(exc) else ""
        return None, f"failed: {type(exc).__name__}: {first}"


def _empty(note: str) -> dict[str, Any]:
    return {**{m: math.nan for m in METRICS}, "note": note}


def run_design(design: Design, settings: dict[str, Any], models: tuple[str, ...], fe: bool) -> dict[str, Any]:
    """The metrics of ``design``: each of ``models`` (analytic sources) and, with ``fe``,
    both FE rows from one pair-FE solve. Top-level so process pools and Dask can pickle it.
    Returns {"metrics": {model: {metric: value}}, "fe_info": ..., "times": ...}; a model
    that refuses or fails on the design gets NaN metrics and a ``note`` (:func:`_guarded`)."""
    from gearwear.jobs.sweep import single_thread_blas
    from gearwear.stiffness.sources import Request, curve

    single_thread_blas()
    t0, c0 = time.perf_counter(), time.process_time()
    out: dict[str, Any] = {"metrics": {}, "times": {}, "fe_info": {}}
    rq = Request(design.pair, design.torque_Nm, points=settings["points"], plane=settings["plane"])
    for name in models:
        t, c = time.perf_counter(), time.process_time()
        rows, note = _guarded(lambda: {name: curve_metrics(curve(name, rq))})  # called at once
        out["metrics"].update(rows or {name: _empty(note or "")})
        out["times"][name] = {"wall_s": time.perf_counter() - t, "cpu_s": time.process_time() - c}
    if fe:
        from gearwear.fem.pair import pair_contact

        t, c = time.perf_counter(), time.process_time()

        def both() -> dict[str, Any]:
            r = pair_contact(
                design.pair,
                positions=settings["positions"],
                torque_Nm=design.torque_Nm,
                mesh_scale=settings["mesh_scale"],
                contact_scale=settings["contact_scale"],
                plane=settings["plane"],
                extended=settings["transitions"],
            )
            ext = r.meta.get("extended_contact_deg")
            out["fe_info"] = {
                "ndofs": r.meta.get("ndofs"),
                "n_elements": r.meta.get("n_elements"),
                "condensed_dofs": r.meta.get("condensed_dofs"),
                "blank_torsional_stiffness_Nm_per_rad": r.meta.get("blank_torsional_stiffness_Nm_per_rad"),
            }
            # one solve: the bore-fixed curve and the mesh-only one are both in r
            return {"fem": curve_metrics(r.without_blank_torsion(), ext), "fem_bore_fixed": curve_metrics(r, ext)}

        rows, note = _guarded(both)
        out["metrics"].update(rows or {m: _empty(note or "") for m in FE_MODELS})
        out["times"]["fe"] = {"wall_s": time.perf_counter() - t, "cpu_s": time.process_time() - c}
    out["times"]["design"] = {
        "wall_s": time.perf_counter() - t0,
        "cpu_s": time.process_time() - c0,
        "max_rss_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }
    return out


# -- the cache -----------------------------------------------------------------------------


def _entry_bytes(metrics: dict[str, Any]) -> bytes:
    return (io.json_text(metrics) + "\n").encode("utf-8")


def read_entry(folder: Path, inputs: dict[str, Any]) -> dict[str, Any] | None:
    """A valid cache entry for ``inputs`` (its metrics), else None (missing or damaged:
    recomputed)."""
    import hashlib

    from gearwear.core.inputs import read_bounded
    from gearwear.stiffness.tables import ENTRY_LIMIT_BYTES, entry

    key = io.input_hash(inputs)
    path, meta, _ = entry(folder, key, ".atlas.json")
    if meta is None:
        return None
    raw, _ = read_bounded(path, "file", ENTRY_LIMIT_BYTES)
    if raw is None or hashlib.sha256(raw).hexdigest() != meta.get("data_sha256"):
        return None
    try:
        data = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError):
        return None
    return data if isinstance(data, dict) else None


def write_entry(folder: Path, inputs: dict[str, Any], data: dict[str, Any]) -> None:
    """Store ``data`` for ``inputs`` (data first, then the sidecar; atomic)."""
    import hashlib

    from gearwear.stiffness.tables import write_entry as write_files

    key = io.input_hash(inputs)
    raw = _entry_bytes(data)
    path = folder / f"{key}.atlas.json"
    side = {"input_sha256": key, "data_sha256": hashlib.sha256(raw).hexdigest(), "inputs": inputs}
    write_files(key, LABEL, {path: raw, Path(str(path) + ".json"): (io.json_text(side) + "\n").encode()})


def _round_trip(data: dict[str, Any]) -> dict[str, Any]:
    """``data`` as a cache read returns it (so a cold run and a resumed one give the same bytes)."""
    return json.loads(_entry_bytes(data).decode("utf-8"))


# -- the run -------------------------------------------------------------------------------


def compute(
    spec: AtlasSpec,
    space: DesignSpace | None = None,
    executor: Executor | None = None,
    progress: bool = True,
    cache: Path | None = None,
) -> dict[str, Any]:
    """Run the atlas: {"space": DesignSpace, "results": {design index: {model: metrics}},
    "timing": {...}, "cached": number of designs read whole from the cache}. Designs whose
    entries are all cached are not submitted; each finished design is stored at once."""
    from tqdm import tqdm

    from gearwear.jobs.sweep import Estimate, make_executor, workers_of
    from gearwear.stiffness.tables import cache_dir

    t_start = time.perf_counter()
    space = space or design_space(spec.values)
    folder = cache or (cache_dir() / "atlas")
    folder.mkdir(parents=True, exist_ok=True)
    settings = {**fe_settings(spec), "points": spec["analytic.points"]}
    results: dict[int, dict[str, Any]] = {}
    timing: dict[str, Any] = {}
    todo = []
    for d in space.designs:
        inputs = cache_inputs(spec, d)
        have = {k: read_entry(folder, v) for k, v in inputs.items()}
        results[d.index] = {}
        for k, v in have.items():
            if v is not None:
                results[d.index].update(v)
        missing_models = tuple(m for m in spec.models if have[m] is None)
        if missing_models or have["fe"] is None:
            todo.append((d, inputs, missing_models, have["fe"] is None))
    cached = len(space.designs) - len(todo)
    if todo:
        with contextlib.ExitStack() as stack:
            ex = executor or stack.enter_context(make_executor())
            parallel = min(workers_of(ex), len(todo))
            estimate = Estimate(f"atlas of {len(todo)} designs", parallel, math.ceil(len(todo) / parallel))
            futures = {ex.submit(run_design, d, settings, mm, fe): (d, inputs, mm, fe) for d, inputs, mm, fe in todo}
            with tqdm(total=len(todo), desc="atlas", unit="design", disable=not progress, file=sys.stderr) as bar:
                for fut in as_completed(futures):
                    d, inputs, mm, fe = futures[fut]
                    got = fut.result()
                    for m in mm:
                        data = _round_trip({m: got["metrics"][m]})
                        write_entry(folder, inputs[m], data)
                        results[d.index].update(data)
                    if fe:
                        data = _round_trip({k: got["metrics"][k] for k in FE_MODELS})
                        write_entry(folder, inputs["fe"], data)
                        results[d.index].update(data)
                    timing[str(d.index)] = {**got["times"], **({"fe_info": got["fe_info"]} if got["fe_info"] else {})}
                    bar.update(1)
                    estimate.first_done(bar.write)
    timing["total_wall_s"] = time.perf_counter() - t_start
    timing["designs_from_cache"] = cached
    return {"space": space, "results": results, "timing": timing, "cached": cached}


def _cell(v: Any) -> str:
    if v is None:  # NaN, as the strict JSON of a cache entry holds it
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.10g}"
    return str(v)


def table_csv(spec: AtlasSpec, space: DesignSpace, results: dict[int, dict[str, Any]]) -> str:
    """atlas.csv: one row per design and model (the FE rows first), the design's inputs, then
    the metrics (gearwear.jobs.atlas_metrics; an empty cell is NaN: a zone the pair never has,
    an STE the model does not give)."""
    from gearwear.geometry.design_space import contact_ratio

    models = FE_MODELS + spec.models
    rows = []
    header = None
    for d in space.designs:
        base = {**d.row(), "contact_ratio": contact_ratio(d.pair)}
        if header is None:
            header = list(base) + ["model"] + list(METRICS)
            rows.append(",".join(header))
        for m in models:
            met = results[d.index][m]
            rows.append(",".join([_cell(v) for v in base.values()] + [m] + [_cell(met[k]) for k in METRICS]))
    return "\n".join(rows) + "\n"


def notes(spec: AtlasSpec, space: DesignSpace, results: dict[int, dict[str, Any]]) -> dict[str, dict[str, str]]:
    """model -> {design index: why its row is empty} (a model that refused or failed)."""
    out: dict[str, dict[str, str]] = {}
    for d in space.designs:
        for m in FE_MODELS + spec.models:
            note = results[d.index][m].get("note")
            if note:
                out.setdefault(m, {})[str(d.index)] = note
    return out


def sidecar_extra(spec: AtlasSpec, space: DesignSpace, results: dict[int, dict[str, Any]]) -> dict[str, Any]:
    from gearwear.stiffness.calibration import library_versions

    return {
        "notes": notes(spec, space, results),
        "designs": len(space.designs),
        "points_drawn": space.drawn,
        "rejects": dict(space.rejects),
        "models": {"fem": "pair FE, blanks' torsion excluded", "fem_bore_fixed": "pair FE, bores fixed"}
        | {m: m for m in spec.models},
        "metrics": "gearwear.jobs.atlas_metrics (units in the column names; harmonics h1-h3 are absolute "
        "amplitudes 2 |c_m| of k_h in N/m; entry_deg, exit_deg pinion rotation from A and E)",
        "libraries": library_versions(),
    }


def write(spec: AtlasSpec, run: dict[str, Any], out: Path) -> list[Path]:
    """atlas.csv and its sidecar into the folder ``out``."""
    csv = io.write_text(out / "atlas.csv", table_csv(spec, run["space"], run["results"]))
    extra = sidecar_extra(spec, run["space"], run["results"])
    return [csv, io.sidecar(csv, spec.as_dict(), "gearwear atlas (analytic models and pair FE per design)", extra)]
