"""``gearwear report pair SCENE``: a one-page report of a user's own gear pair.

Five parts, each from the job that computes it elsewhere in gearwear:

1. the geometry of both gears and the mesh (``jobs.geometry``);
2. the mesh stiffness k_h over one mesh period by every method (``jobs.stiffness``:
   Ishikawa, potential energy, ISO 6336-1 method B as a constant, and the resolved pair FE),
   each method's statistics and its mean's difference from the FE mean;
3. the peak-to-peak loaded static transmission error (STE) against the pinion torque (a
   Harris map; with a tip or root relief the nominal and the modified flank, otherwise the
   scene's flank only);
4. a run-up (one sweep up on a local process, natural continuation, ``jobs.runup``) over a
   speed range around ISO 6336-1's resonance speed n_E1, with ISO's K_v on the same speeds;
5. every value the results assume that the scene did not give (``assumptions``).

:func:`prepare` validates everything and lays out the run-up before any heavy work;
:func:`compute` computes; :func:`document` turns the results into the dict written as
``report.json``; the page (:func:`markdown`) and the figures are drawn from that dict only,
so every number on the page is one of report.json's. SI inside; names carry units (the
page shows mm, um, rpm and N m where it says so).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from gearwear import __version__, io
from gearwear.core.validation import InputError
from gearwear.jobs import runup as runup_job
from gearwear.jobs import stiffness as stiffness_job
from gearwear.jobs.sweep import Axis
from gearwear.scene.model import Scene, require_dynamics

#: the methods of the page, in its order (a subset of the registry's METHODS: the paper's
#: models, ISO and the FE); the FE is the reference of the differences
METHOD_LABELS = {
    "ishikawa": "Ishikawa (analytic)",
    "energy": "potential energy (analytic, Sainsot foundation)",
    "iso6336": "ISO 6336-1 method B (one constant)",
    "fem": "pair FE (resolved contact of both bodies)",
}
REFERENCE = "fem"
#: the parts :func:`compute` announces through its ``step`` callback, in order
PARTS = ("geometry", *(label.split(" (")[0] for label in METHOD_LABELS.values()), "STE against load", "run-up")


@dataclass(frozen=True)
class Settings:
    """How finely the report computes (the command uses :data:`SETTINGS`)."""

    points: int = 360  # angles per mesh period of the analytic and ISO curves
    fe_positions: int = 24  # pair-FE positions per mesh period (~0.5 s each)
    load_fractions: tuple[float, ...] = tuple(float(f) for f in stiffness_job.HARRIS_LOADS)  # x scene torque
    speed_fractions: tuple[float, float] = (0.2, 1.6)  # run-up range, x ISO's n_E1 at the driver
    speeds: int = 33  # run-up speeds (sweep up)
    runup: runup_job.Settings = field(default_factory=runup_job.Settings)


SETTINGS = Settings()


@dataclass
class Prepared:
    """A validated report: the scene, the run-up's point (model, ISO curve) and its chain."""

    scene: Scene
    settings: Settings
    point: runup_job.Point
    chain: runup_job.Chain


@dataclass
class Report:
    """The computed report (SI; ``wall_s`` per part in s)."""

    scene: Scene
    settings: Settings
    geometry: dict[str, Any]
    curves: list[stiffness_job.Curve]
    load_map: dict[str, Any]
    point: runup_job.Point
    chain: runup_job.Chain
    runup_summary: dict[str, Any]
    assumptions: list[dict[str, Any]]
    wall_s: dict[str, float]


def check_scene(scene: Scene) -> None:
    """Refuse what the report cannot show, before any work: no bearing stiffness (the
    dynamics need it), faults (their curves span a revolution, not a mesh period)."""
    require_dynamics(scene)
    if scene.faults is not None:
        raise InputError(
            "[faults]: report pair shows a healthy pair over one mesh period; a fault needs curves "
            "over a revolution: use gearwear stiffness and gearwear simulate for it"
        )


def run_up_speeds_rpm(n_E1_driver_rpm: float, settings: Settings) -> tuple[float, ...]:
    """The run-up's driver speeds (rpm, ascending): ``settings.speeds`` evenly spaced over
    ``settings.speed_fractions`` of ISO's resonance speed, to 6 significant digits."""
    lo, hi = settings.speed_fractions
    return tuple(float(f"{v:.6g}") for v in np.linspace(lo * n_E1_driver_rpm, hi * n_E1_driver_rpm, settings.speeds))


def prepare(scene: Scene, settings: Settings = SETTINGS) -> Prepared:
    """Validate the scene and lay out the run-up (the scene's mesh stiffness and dynamic
    model, ISO's n_E1, the speeds around it); cheap unless the scene's stiffness source is
    the FE."""
    check_scene(scene)
    p0 = runup_job.build_point({}, scene, (scene.operating.speed_rpm,))
    speeds = run_up_speeds_rpm(p0.iso["n_E1_driver_rpm"], settings)
    if not speeds[-1] <= 1e6:
        raise InputError(
            f"operating.speed_rpm = {speeds[-1]:g} rpm: the run-up around ISO's resonance "
            f"({p0.iso['n_E1_driver_rpm']:.6g} rpm) needs speeds above the scene range (0, 1e+06] rpm"
        )
    return Prepared(scene, settings, p0.at_speeds(speeds), runup_job.Chain(0, "up", list(speeds)))


def geometry(scene: Scene) -> dict[str, Any]:
    """The geometry table's data (``jobs.geometry`` summary plus the pair's module, pressure
    angle and installed centre distance; lengths in mm, angles in deg)."""
    from gearwear.jobs import geometry as geometry_job

    s = geometry_job.compute(
        scene, scene.wear, scene.clearance_m, scene.operating.torque_Nm, build_mesh=False
    ).summary()
    pair = scene.pair
    for key in ("assumptions", "wall_s"):
        s.pop(key)
    installed = pair.installed_centre_distance_m
    return {
        **s,
        "module_mm": pair.module_m * 1e3,
        "pressure_angle_deg": math.degrees(pair.pressure_angle_rad),
        "installed_centre_distance_mm": None if installed is None else installed * 1e3,
    }


def stiffness(
    scene: Scene,
    settings: Settings,
    fe_progress: Callable[[int, int], None] | None = None,
    step: Callable[[str], None] = lambda msg: None,
) -> list[stiffness_job.Curve]:
    """k_h over one mesh period by every method of the page (METHOD_LABELS) at the scene's
    torque, wear, clearance and flank; ISO 6336 is one constant of the nominal flank."""
    from gearwear.scene.checks import fem_plane

    curves = []
    # the scene's fem.plane (auto: by b/m), for the FE and the analytic tooth beams alike
    plane = fem_plane(scene.doc, True, "gearwear report pair")
    for i, method in enumerate(METHOD_LABELS):
        step(PARTS[1 + i])
        fem = method == "fem"
        args = (
            scene.pair,
            method,
            [scene.wear],
            [scene.clearance_m],
            scene.operating.torque_Nm,
            settings.fe_positions if fem else settings.points,
            None if method == "iso6336" else scene.flank,
        )
        curves += (
            stiffness_job.compute(*args, progress=fe_progress, plane=plane)
            if fem
            else stiffness_job.compute(*args, plane=plane)
        )
    return curves


def load_map(scene: Scene, curves: list[stiffness_job.Curve], settings: Settings) -> dict[str, Any]:
    """Peak-to-peak loaded STE (um) against pinion torque (N m), Ishikawa. With a tip or
    root relief: ``stiffness_job.harris`` (nominal and modified flank, its own loads);
    otherwise the scene's flank at ``settings.load_fractions`` of the scene's torque."""
    from gearwear.analytic.tvms import mesh_stiffness

    T = scene.operating.torque_Nm
    flank = "nominal" if scene.flank is None else scene.flank.label()
    hm = stiffness_job.harris(curves, scene.pair, scene.flank)
    if hm is not None:
        torques = hm.torque_Nm.tolist()
        pp = {
            "nominal flank": (hm.nominal_ste_pp_m * 1e6).tolist(),
            f"modified flank ({flank})": (hm.modified_ste_pp_m * 1e6).tolist(),
        }
    else:
        torques = [f * T for f in settings.load_fractions]
        pp = {
            "nominal flank" if scene.flank is None else f"scene's flank ({flank})": [
                float(
                    np.ptp(
                        mesh_stiffness(
                            scene.pair, "ishikawa", settings.points, t, scene.clearance_m, scene.wear, flank=scene.flank
                        ).ste_m
                    )
                )
                * 1e6
                for t in torques
            ]
        }
    return {
        "method": "ishikawa",
        "torque_Nm": torques,
        "loads": len(torques),
        "scene_torque_Nm": T,
        "ste_peak_to_peak_um": pp,
    }


def compute(
    prep: Prepared,
    executor,
    step: Callable[[str], None] = lambda msg: None,
    fe_progress: Callable[[int, int], None] | None = None,
    runup_progress: bool = False,
) -> Report:
    """Every part of the report (``executor`` runs the run-up's chain, e.g.
    ``sweep_job.make_executor(1)``); ``step`` is called before each part with its name."""
    from gearwear.scene.assumptions import as_dicts, for_command

    scene, settings = prep.scene, prep.settings
    wall: dict[str, float] = {}
    t = time.perf_counter()
    step("geometry")
    geo = geometry(scene)
    wall["geometry"] = time.perf_counter() - t
    curves = stiffness(scene, settings, fe_progress, step)
    for c in curves:
        wall[f"stiffness {c.method}"] = c.result.wall_s
    t = time.perf_counter()
    step("STE against load")
    lm = load_map(scene, curves, settings)
    wall["STE against load"] = time.perf_counter() - t
    t = time.perf_counter()
    step("run-up")
    chain = runup_job.Chain(0, "up", list(prep.chain.speeds))
    runup_job.run([prep.point], [chain], settings.runup, executor, progress=runup_progress)
    speed_axis = Axis(runup_job.SPEED_KEY, prep.point.speeds)
    summ = runup_job.summary([prep.point], [chain], speed_axis, [], settings.runup)
    wall["run-up"] = time.perf_counter() - t
    return Report(
        scene, settings, geo, curves, lm, prep.point, chain, summ, as_dicts(for_command(scene, "report pair")), wall
    )


# -- the document (report.json) ------------------------------------------------------------


def _null(v: float | None) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


def stiffness_rows(curves: list[stiffness_job.Curve]) -> list[dict[str, Any]]:
    """One row per method: the curve's statistics (N/m, um, s), the difference of its mean
    from the FE mean (%) and the curve itself (pinion angle in deg, k_h in N/m)."""
    ref = next(c for c in curves if c.method == REFERENCE).result.mean_N_per_m
    rows = []
    for c in curves:
        s = c.summary()
        r = c.result
        rows.append(
            {
                "method": c.method,
                "label": METHOD_LABELS[c.method],
                "points": s["points"],
                "mean_N_per_m": s["mean_N_per_m"],
                "min_N_per_m": s["min_N_per_m"],
                "max_N_per_m": s["max_N_per_m"],
                "double_zone_mean_N_per_m": s["double_zone_mean_N_per_m"],
                "single_zone_mean_N_per_m": s["single_zone_mean_N_per_m"],
                "ste_peak_to_peak_um": s["ste_peak_to_peak_um"],
                "mean_vs_fe_pct": 100.0 * (s["mean_N_per_m"] / ref - 1.0),
                "angle_deg": np.degrees(r.angle_rad).tolist(),
                "k_N_per_m": r.k_N_per_m.tolist(),
                "warnings": s["warnings"],
            }
        )
    return rows


def stiffness_source(scene: Scene) -> str:
    """The dynamic model's mesh stiffness in words (simulate_job.stiffness_input's source)."""
    ms = scene.effects.get("mesh_stiffness")
    source = ms["source"] if ms else "constant"
    return "analytic, Ishikawa" if source == "analytic" else source


def runup_doc(rep: Report) -> dict[str, Any]:
    """The run-up's rows (driver speed rpm, K_v, steady-state label, DTE p-p um), ISO's
    curve on the same speeds and what the run-up found (runup_job.summary)."""
    p, c = rep.point, rep.chain
    rows = sorted(c.rows, key=lambda r: r["speed_rpm"])
    entry = rep.runup_summary["points"][0]
    up = entry["directions"]["up"]
    iso = p.iso
    i_max = int(np.argmax([r["K_v"] for r in rows]))
    return {
        "direction": "up",
        "speeds_rpm": [r["speed_rpm"] for r in rows],
        "K_v": [r["K_v"] for r in rows],
        "labels": [r["label"] for r in rows],
        "delta_p2p_um": [r["delta_p2p_um"] for r in rows],
        "K_v_max": up["K_v_max"],
        "K_v_max_speed_rpm": up["K_v_max_speed_rpm"],
        "K_v_iso_at_K_v_max_speed": iso["K_v"][i_max],
        "K_v_iso_max": max(iso["K_v"]),
        "label_counts": up["labels"],
        "contact_loss_speeds": up["contact_loss_speeds"],
        "linear_eigenfrequencies_Hz": entry["linear_eigenfrequencies_Hz"],
        "mesh_frequency_meets_mode_rpm": entry["mode_speeds_rpm"]["k1"],
        "scene_mean_stiffness_N_per_m": p.mean_stiffness_N_per_m,
        "stiffness_source": stiffness_source(rep.scene),
        "iso6336": {
            "K_v": iso["K_v"],
            "range": iso["range"],
            "n_E1_rpm": iso["n_E1_rpm"],
            "n_E1_driver_rpm": iso["n_E1_driver_rpm"],
            "N_S": iso["N_S"],
            "inputs": iso["inputs"],
        },
        "settings": asdict(rep.settings.runup),
    }


def document(rep: Report) -> dict[str, Any]:
    """report.json: every number the page shows (and the curves the figures draw)."""
    scene = rep.scene
    settings = asdict(rep.settings)
    settings.pop("runup")
    return {
        "software": "gearwear",
        "version": __version__,
        "scene_name": scene.name,
        "operating": {
            "torque_Nm": scene.operating.torque_Nm,
            "speed_rpm": scene.operating.speed_rpm,
            "wear": scene.wear.label if scene.wear else "unworn",
            "clearance_um": scene.clearance_m * 1e6,
            "flank": scene.flank.label() if scene.flank is not None else "nominal",
        },
        "settings": settings,
        "geometry": rep.geometry,
        "stiffness": stiffness_rows(rep.curves),
        "load_map": rep.load_map,
        "runup": runup_doc(rep),
        "assumptions": rep.assumptions,
        "warnings": list(
            dict.fromkeys(rep.geometry["warnings"] + [w for c in rep.curves for w in c.summary()["warnings"]])
        ),
    }


def timing(rep: Report) -> dict[str, float]:
    """Wall time of each part (s) for timing.json: the page and report.json hold none, so two runs
    with the same inputs give the same bytes."""
    return {**{f"{k} s": v for k, v in rep.wall_s.items()}, "computation s": sum(rep.wall_s.values())}


# -- the page ----------------------------------------------------------------------------


def _f(v: float | None, spec: str) -> str:
    """A number as the page shows it ('-' for none)."""
    return "-" if v is None else format(v, spec)


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    return out + ["| " + " | ".join(r) + " |" for r in rows]


def geometry_lines(g: dict[str, Any]) -> list[str]:
    p, q = g["gears"]

    def row(label: str, key: str, spec: str) -> list[str]:
        return [label, _f(p[key], spec), _f(q[key], spec)]

    both = [
        ("module (mm)", "module_mm", ".4g"),
        ("pressure angle (deg)", "pressure_angle_deg", ".4g"),
        ("face width (mm)", "face_width_mm", ".4g"),
    ]
    rows = [row("teeth", "teeth", "d")] + [[lab, _f(g[k], s), _f(g[k], s)] for lab, k, s in both]
    rows += [
        row(lab, k, s)
        for lab, k, s in (
            ("profile shift coefficient", "profile_shift", ".4g"),
            ("base radius (mm)", "base_radius_mm", ".4f"),
            ("pitch radius (mm)", "pitch_radius_mm", ".4f"),
            ("tip radius (mm)", "tip_radius_mm", ".4f"),
            ("root radius (mm)", "root_radius_mm", ".4f"),
            ("form radius (mm)", "form_radius_mm", ".4f"),
            ("start of active profile, SAP radius (mm)", "start_of_active_profile_mm", ".4f"),
            ("LPSTC diameter (mm)", "lpstc_diameter_mm", ".4f"),
            ("HPSTC diameter (mm)", "hpstc_diameter_mm", ".4f"),
            ("bore radius (mm)", "hub_radius_mm", ".4g"),
            (f"body mass (kg), from the {g['bodies_from']['mass_kg']}", "mass_kg", ".5g"),
            (f"body inertia (kg m^2), from the {g['bodies_from']['inertia_kg_m2']}", "inertia_kg_m2", ".5g"),
        )
    ]
    installed = g["installed_centre_distance_mm"]
    mesh = [
        [
            "installed centre distance (mm)",
            "none given: the zero-backlash one" if installed is None else _f(installed, ".4f"),
        ],
        ["zero-backlash centre distance (mm)", _f(g["zero_backlash_centre_distance_mm"], ".4f")],
        [
            f"operating centre distance (mm), bearing clearance {_f(g['clearance_um'], 'g')} um",
            _f(g["centre_distance_mm"], ".4f"),
        ],
        ["operating pressure angle (deg)", _f(g["operating_pressure_angle_deg"], ".4f")],
        ["contact ratio (operating)", _f(g["contact_ratio"], ".4f")],
        ["normal backlash (um)", _f(g["backlash_um"], ".2f")],
        ["bearing stiffness (N/m)", _f(g["bearing_stiffness_N_per_m"], ".4g")],
    ]
    return (
        _table(["quantity", f"pinion (driver, {p['teeth']} teeth)", f"gear ({q['teeth']} teeth)"], rows)
        + [""]
        + _table(["mesh", "value"], mesh)
    )


def stiffness_lines(rows: list[dict[str, Any]]) -> list[str]:
    head = [
        "method",
        "mean (N/m)",
        "min (N/m)",
        "max (N/m)",
        "double-contact mean (N/m)",
        "single-contact mean (N/m)",
        "STE peak-to-peak (um)",
        "mean vs FE (%)",
    ]
    body = [
        [
            r["label"],
            _f(r["mean_N_per_m"], ".4e"),
            _f(r["min_N_per_m"], ".4e"),
            _f(r["max_N_per_m"], ".4e"),
            _f(r["double_zone_mean_N_per_m"], ".4e"),
            _f(r["single_zone_mean_N_per_m"], ".4e"),
            _f(r["ste_peak_to_peak_um"], ".3f"),
            "reference" if r["method"] == REFERENCE else _f(r["mean_vs_fe_pct"], "+.1f"),
        ]
        for r in rows
    ]
    return _table(head, body)


def markdown(doc: dict[str, Any]) -> str:
    """README.md of the report, from report.json's dict only."""
    from gearwear.scene.assumptions import line_of

    g, op, ru, lm = doc["geometry"], doc["operating"], doc["runup"], doc["load_map"]
    iso = ru["iso6336"]
    fe = next(r for r in doc["stiffness"] if r["method"] == REFERENCE)
    L = [
        f"# Gear pair report: {doc['scene_name']}",
        "",
        f"Pinion (driver) torque {_f(op['torque_Nm'], 'g')} N m, speed {_f(op['speed_rpm'], 'g')} rpm; "
        f"wear: {op['wear']}; bearing clearance {_f(op['clearance_um'], 'g')} um; flank: {op['flank']}. "
        f"Written by gearwear {doc['version']} (`gearwear report pair`); every number on this page is in "
        "`report.json`, every value the scene did not give is listed at the end.",
        "",
        "## Geometry",
        "",
    ]
    L += geometry_lines(g)
    L += [
        "",
        "## Mesh stiffness by every method",
        "",
        f"At {_f(op['torque_Nm'], 'g')} N m over one mesh period: the analytic curves and ISO at "
        f"{doc['settings']['points']} angles, the pair FE at {fe['points']} positions. ISO 6336-1 method B "
        "gives one constant (c_gamma_alpha b): no angle dependence, no wear, no flank modification.",
        "",
        "![Mesh stiffness by method](stiffness.png)",
        "",
    ]
    L += stiffness_lines(doc["stiffness"])
    L += [
        "",
        "## Loaded transmission error against load (Harris map)",
        "",
        f"Peak-to-peak loaded static transmission error (Ishikawa) at {lm['loads']} pinion torques from "
        f"{_f(lm['torque_Nm'][0], '.4g')} to {_f(lm['torque_Nm'][-1], '.4g')} N m; the scene's torque is "
        f"{_f(lm['scene_torque_Nm'], 'g')} N m. "
        + (
            "A tip or root relief flattens the TE near one load (its design load) only."
            if len(lm["ste_peak_to_peak_um"]) > 1
            else "Without a tip or root relief the TE grows with the load, about in proportion to it; a relief "
            "would flatten it near one load."
        ),
        "",
        "![STE against load](ste_load.png)",
        "",
    ]
    L += _table(
        ["pinion torque (N m)"] + [_f(t, ".4g") for t in lm["torque_Nm"]],
        [[f"STE p-p, {n} (um)"] + [_f(v, ".3f") for v in pp] for n, pp in lm["ste_peak_to_peak_um"].items()],
    )
    speeds = ru["speeds_rpm"]
    lo, hi = doc["settings"]["speed_fractions"]
    at_driver = (
        ""
        if iso["n_E1_driver_rpm"] == iso["n_E1_rpm"]
        else (f" (ISO's gear 1 is the {iso['inputs']['z1']}-tooth gear: n_E1 = {_f(iso['n_E1_rpm'], '.0f')} rpm of it)")
    )
    L += [
        "",
        "## Run-up: dynamic factor K_v next to ISO 6336",
        "",
        f"The 6-DOF model swept up over {doc['settings']['speeds']} driver speeds from {_f(speeds[0], '.0f')} to "
        f"{_f(speeds[-1], '.0f')} rpm ({_f(lo, 'g')} to {_f(hi, 'g')} x ISO's n_E1), each speed starting from "
        "the previous steady state (K_v = max F_m / static F). ISO 6336-1 method B on the same speeds, from the "
        f"model's mean mesh stiffness ({ru['stiffness_source']}: {_f(ru['scene_mean_stiffness_N_per_m'], '.4e')} "
        "N/m) and reduced mass.",
        "",
        "![K_v against speed](kv.png)",
        "",
    ]
    L += _table(
        ["quantity", "value"],
        [
            ["ISO 6336 resonance speed n_E1, driver (rpm)" + at_driver, _f(iso["n_E1_driver_rpm"], ".0f")],
            ["K_v max of the run-up", _f(ru["K_v_max"], ".4f")],
            ["at driver speed (rpm)", _f(ru["K_v_max_speed_rpm"], ".0f")],
            ["ISO 6336 K_v at that speed", _f(ru["K_v_iso_at_K_v_max_speed"], ".4f")],
            ["ISO 6336 K_v max on the range", _f(ru["K_v_iso_max"], ".4f")],
            [
                "linear eigenfrequencies of the model (Hz)",
                ", ".join(_f(f, ".1f") for f in ru["linear_eigenfrequencies_Hz"]),
            ],
            ["steady states", ", ".join(f"{k} {v}" for k, v in sorted(ru["label_counts"].items()))],
            ["speeds with contact loss", str(ru["contact_loss_speeds"])],
        ],
    )
    L += ["", "## Assumptions", "", "Values the results use that the scene did not give:", ""]
    L += [f"- `{line_of(a)}`" for a in doc["assumptions"]] or ["- none"]
    if doc["warnings"]:
        L += ["", "## Warnings", ""] + [f"- {w}" for w in doc["warnings"]]
    L += [
        "",
        "The wall time of each part (the pair FE is most of it) is in `timing.json`: the page and "
        "`report.json` hold none, so two runs with the same inputs give the same bytes.",
        "",
    ]
    return "\n".join(L)


# -- the figures -------------------------------------------------------------------------


def _finish(fig, ax, xlabel: str, ylabel: str, title: str):
    """Labels, a grid and the legend below the axes (off the data)."""
    from gearwear.plotting import legend_outside

    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    legend_outside(ax, "below", ncol=2, frameon=False)
    fig.tight_layout()
    return fig


def stiffness_figure(doc: dict[str, Any]):
    from gearwear.plotting import subplots

    fig, ax = subplots(1, 1, figsize=(10, 4.6))
    styles = {
        "ishikawa": ("C0", "-", None),
        "energy": ("C2", "--", None),
        "iso6336": ("C3", ":", None),
        "fem": ("k", "-", "o"),
    }
    for r in doc["stiffness"]:
        col, ls, mk = styles[r["method"]]
        ax.plot(
            r["angle_deg"],
            np.asarray(r["k_N_per_m"]) / 1e8,
            color=col,
            ls=ls,
            marker=mk,
            ms=4,
            lw=2.0 if r["method"] == "iso6336" else 1.3,
            zorder=3 if mk else 2,
            label=f"{r['label']}, mean {r['mean_N_per_m']:.3e} N/m",
        )
    return _finish(
        fig,
        ax,
        "pinion angle from the entry of a tooth pair (deg), one mesh period",
        "mesh stiffness k_h (1e8 N/m)",
        f"Mesh stiffness at {doc['operating']['torque_Nm']:g} N m",
    )


def load_figure(doc: dict[str, Any]):
    from gearwear.plotting import subplots

    lm = doc["load_map"]
    fig, ax = subplots(1, 1, figsize=(9, 4.4))
    for (name, pp), mk in zip(lm["ste_peak_to_peak_um"].items(), "os^"):
        ax.plot(lm["torque_Nm"], pp, marker=mk, ms=4, label=name)
    ax.axvline(lm["scene_torque_Nm"], color="grey", ls=":", label=f"scene torque {lm['scene_torque_Nm']:g} N m")
    ax.set_ylim(bottom=0)
    return _finish(
        fig,
        ax,
        "pinion torque (N m)",
        "loaded static TE peak-to-peak (um)",
        "Loaded transmission error against load (Harris map, Ishikawa)",
    )


def kv_figure(doc: dict[str, Any]):
    from gearwear.plotting import subplots

    ru = doc["runup"]
    iso = ru["iso6336"]
    fig, ax = subplots(1, 1, figsize=(10, 4.6))
    ax.plot(ru["speeds_rpm"], ru["K_v"], ".-", color="C0", lw=1.4, label="6-DOF model, sweep up")
    ax.plot(ru["speeds_rpm"], iso["K_v"], ":", color="C3", lw=2.0, label="ISO 6336-1 method B")
    n = iso["n_E1_driver_rpm"]
    ax.axvline(n, color="C3", lw=0.8, ls="-.", label=f"ISO resonance n_E1 = {n:.0f} rpm (driver)")
    return _finish(
        fig,
        ax,
        "driver (pinion) speed (rpm)",
        "dynamic factor K_v = max F_m / static F (ratio)",
        "Run-up: dynamic factor against speed",
    )


FIGURES = {"stiffness.png": stiffness_figure, "ste_load.png": load_figure, "kv.png": kv_figure}


def write(doc: dict[str, Any], out: Path) -> list[Path]:
    """README.md, report.json and the figures into the folder ``out``."""
    files = [io.write_text(out / "README.md", markdown(doc)), io.write_json(out / "report.json", doc)]
    return files + [io.write_figure(make(doc), out / name) for name, make in FIGURES.items()]
