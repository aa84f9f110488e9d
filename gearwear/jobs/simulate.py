"""Scene -> dynamic model -> simulation: the composition of the ``simulate`` command.

Only what the scene's ``[effects]`` names is modelled:

* ``mesh_stiffness``: time-varying k_h(phi) from ``source`` = analytic (Ishikawa, load
  sharing at the scene torque), calibrated (FE-corrected, cached tables), fem (FE pair
  contact) or constant (``value_N_per_m``, else the analytic mean). Absent: a constant
  spring of the analytic mean stiffness. With fem and calibrated, ``blank_torsion``
  says whether both blanks' torsion between bore and teeth is in series with the mesh
  ("in_series", the default: the FE holds the gears at their bores; see
  :func:`blank_torsion`) or taken out ("excluded").
* ``wear``: changes the stiffness table (thinner teeth, wear gaps in the load sharing).
* ``transmission_error``: the wear excitation e(phi) enters the mesh force
  F = k_h f(delta - e). Absent: e = 0.
* ``backlash``: dead zone of half-width j_n / 2 (paper Eq. 20, typo fixed), j_n the
  total normal backlash (initial_um plus the change from the centre distance). In the
  gap no force acts; ``damping_in_gap = true`` keeps c_h delta' on there (paper Eq. 19
  read literally, which pulls the teeth together through the gap). Absent: a
  two-sided linear mesh spring.
* ``bearing_clearance``: dead zones of half-width BC / 2 in every bearing (Eqs. 7-10).
* ``centre_distance``: "static": the operating geometry (alpha', backlash, contact path
  and stiffness table) at C' from the bearing clearance (Eq. 11 clearance terms; the
  elastic bearing deflection is a state of the model itself, so it is not added
  twice); "dynamic": alpha' and the backlash follow the instantaneous centre distance.
  Absent: the nominal geometry.

Masses and inertias: ``bodies.mass_kg`` / ``inertia_kg_m2``, else each gear's own blank
(``gearwear.scene.model.resolve_bodies``, ``geometry.blank``). Damping:
``bodies.mesh_damping_N_s_per_m`` / ``bearing_damping_N_s_per_m``, else from the ratios
c_h = 2 zeta_m sqrt(k_mean m_e), c_b = 2 zeta_b sqrt(k_b m).

``mesh_stiffness.source = "table"`` takes k_h(phi) (and e(phi) from an
``excitation_um`` column) from the user's CSV (``scene.read_stiffness_table``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from gearwear.core.validation import InputError, renamed
from gearwear.dynamics import GearDynamics, damping_from_ratios, simulate
from gearwear.dynamics.model import table_mean
from gearwear.geometry.faults import revolution_periods
from gearwear.geometry.operating import backlash, centre_distance
from gearwear.geometry.spec import PairSpec
from gearwear.scene.assumptions import as_dicts, for_command
from gearwear.scene.checks import dynamics_fem_plane
from gearwear.scene.model import Scene, require_dynamics
from gearwear.scene.plausibility import body_warnings, pair_warnings, response_warnings, stiffness_warnings
from gearwear.stiffness.sources import SOURCES, Request, curve

#: SI unit of each signal of the dynamics layer (dynamics.simulate computes them in SI)
SI_UNITS = {"y_p": "m", "x_p": "m", "y_g": "m", "x_g": "m", "q": "m", "delta": "m", "F_m": "N"}
SIGNAL_UNITS = {
    "y_p": ("um", 1e6),
    "x_p": ("um", 1e6),
    "y_g": ("um", 1e6),
    "x_g": ("um", 1e6),
    "q": ("um", 1e6),
    "delta": ("um", 1e6),
    "F_m": ("N", 1.0),
}
#: what each signal is, in words (figure labels); dynamics.model: y along the line of action
#: (the common tangent of the base circles), x along the centre line
SIGNAL_WORDS = {
    "y_p": "pinion bearing displacement y_p, line of action",
    "x_p": "pinion bearing displacement x_p, centre line",
    "y_g": "gear bearing displacement y_g, line of action",
    "x_g": "gear bearing displacement x_g, centre line",
    "q": "relative torsional displacement q",
    "delta": "dynamic transmission error delta",
    "F_m": "mesh force F_m",
}


def signal_name(key: str) -> str:
    """The signal of a summary key: "F_m_N" -> "F_m", "delta_um" -> "delta", "delta" -> "delta"."""
    for name, (unit, _) in SIGNAL_UNITS.items():
        if key in (name, f"{name}_{unit}"):
            return name
    raise KeyError(key)


def signal_label(key: str, what: str = "") -> str:
    """An axis label in words with the unit: "mesh force F_m (N)"; ``what`` goes before the
    unit ("mesh force F_m, harmonic k (N)")."""
    name = signal_name(key)
    return f"{SIGNAL_WORDS[name]}{', ' + what if what else ''} ({SIGNAL_UNITS[name][0]})"


@dataclass
class StiffnessInput:
    phi: np.ndarray
    k: np.ndarray
    e: np.ndarray
    source: str
    mean_N_per_m: float
    wall_s: float
    periods: int = 1  # mesh periods the tables span (a fault: one revolution of its gear)


#: the dynamics layer's own parameter names -> scene keys
SOLVER_KEYS = {
    name: f"solver.{name}"
    for name in ("duration_s", "discard_s", "method", "steps_per_mesh_period", "rtol", "atol", "y0")
}
SOLVER_KEYS.update(
    {"k_table": "effects.mesh_stiffness", "e_table": "effects.mesh_stiffness", "phi_table": "effects.mesh_stiffness"}
)


def operating_centre_distance(scene: Scene) -> float:
    """C' used for the static geometry: nominal unless the static centre-distance coupling
    is modelled (the dynamic coupling starts from the nominal geometry and lets the
    instantaneous centre positions move it)."""
    pair = scene.pair
    cd = scene.effects.get("centre_distance")
    if cd is not None and cd["coupling"] == "static" and "bearing_clearance" in scene.effects:
        return centre_distance(pair, scene.clearance_m)
    return pair.centre_distance_m


def blank_torsion(ms: dict | None) -> str:
    """What the FE-based sources give the dynamics of the gear blanks
    (effects.mesh_stiffness.blank_torsion): "in_series" unless the scene says "excluded".
    The default because the FE holds each gear at its bore, so its k_h carries both blanks'
    torsion between bore and teeth in series with the mesh, and the 6-DOF model has no
    shaft or blank torsion of its own (the torque acts on the gear body directly): the
    blank compliance is physical there, and counted once. "excluded" is for a model that
    carries the blanks' torsion itself (it would count it twice)."""
    return (ms or {}).get("blank_torsion") or "in_series"


def stiffness_input(scene: Scene, breakpoints: bool = True, tables: Callable | None = None) -> StiffnessInput:
    """The k_h(phi), e(phi) tables the scene asks for (arrays over the table's mesh
    periods; the analytic and calibrated tables have
    ``effects.mesh_stiffness.points_per_mesh_period`` uniform nodes per mesh period and
    the breakpoints of the load sharing on top, analytic.tvms.mesh_stiffness).
    ``breakpoints = False``: the analytic table on the uniform nodes only (for the
    convergence study, benchmarks/bench_table_points.py). ``tables(source, request)``: where
    the curve comes from (default :func:`gearwear.stiffness.sources.curve`; a sweep passes
    its per-process :class:`gearwear.jobs.table_memo.TableMemo`)."""
    t0 = time.perf_counter()
    pair, T = scene.pair, scene.operating.torque_Nm
    Cp = operating_centre_distance(scene)
    clearance_geo = scene.clearance_m if Cp != pair.centre_distance_m else 0.0
    ms = scene.effects.get("mesh_stiffness")
    source = ms["source"] if ms else "constant"
    points = (ms or {}).get("points_per_mesh_period")  # None: the source's default (SOURCES)
    wear, flank, faults = scene.wear, scene.flank, scene.faults
    ignored = source == "table" or (source == "constant" and "transmission_error" not in scene.effects)
    if (flank is not None or faults is not None) and ignored:
        what = "[flank]" if flank is not None else "[faults]"
        raise InputError(
            f"{what}: the simulation's mesh stiffness is "
            f"{'a user table' if source == 'table' else 'a constant without transmission_error'}, "
            'which cannot show it; set effects.mesh_stiffness.source = "analytic", "calibrated" or '
            '"fem" (or add [effects] transmission_error to a constant stiffness)'
        )
    periods = revolution_periods(pair, faults)
    plane = dynamics_fem_plane(scene.doc) if scene.doc is not None else "stress"
    if SOURCES[source].fe:
        check_before_stiffness(scene)
    options = {}
    if source == "table":
        assert ms is not None
        options = {"angle_rad": ms["angle_rad"], "k_N_per_m": ms["k_N_per_m"], "excitation_m": ms["excitation_m"]}
    elif source == "constant":
        options = {"value_N_per_m": (ms or {}).get("value_N_per_m")}
    r = (tables or curve)(
        source,
        Request(pair, T, clearance_geo, wear, flank, faults, points, plane, breakpoints, blank_torsion(ms), options),
    )
    phi, k, e = r.angle_rad, r.k_N_per_m, r.excitation_m
    return StiffnessInput(
        np.asarray(phi),
        np.asarray(k),
        np.asarray(e),
        source,
        table_mean(phi, k, periods * 2 * math.pi / pair.teeth[0], (ms or {}).get("interpolation", "linear")),
        time.perf_counter() - t0,
        periods,
    )


def check_before_stiffness(scene: Scene) -> None:
    """The solver's stability check, made before an expensive mesh stiffness (the FE
    calibration, which also writes the table cache, or the pair FE: minutes), so a run the
    solver would refuse anyway is refused first, with nothing computed or cached. The
    stiffness is not known yet: the check runs on the scene's model without its mesh spring
    and damper (k = 0, c_h = 0). Its fastest mode (the bearings', sqrt(k_b / m)) is a lower
    bound of the one RK4 must resolve, or that limits dopri5's stable step, with any mesh
    stiffness, so what fails here fails later too (e.g. bodies.mass_kg = 1e-9 kg: omega_max
    >= 5e8 rad/s)."""
    from gearwear.dynamics.simulate import check_dopri5_budget, check_rk4_stable, resolve_method

    require_dynamics(scene)
    periods = revolution_periods(scene.pair, scene.faults)
    # nodes in every mesh period of the table (a table over a revolution needs them in each)
    phi = np.linspace(0.0, periods * 2 * math.pi / scene.pair.teeth[0], 8 * periods, endpoint=False)
    none = StiffnessInput(phi, np.zeros_like(phi), np.zeros_like(phi), "constant", 0.0, 0.0, periods)
    try:
        model = build_model(scene, none).with_(c_h=0.0)
        if resolve_method(model, scene.solver.get("method", "auto")) == "rk4":
            check_rk4_stable(model, scene.solver.get("steps_per_mesh_period", 256), k=0.0, bound=True)
        else:
            check_dopri5_budget(model, scene.solver.get("duration_s", 0.5), k=0.0, bound=True)
    except InputError as exc:
        raise renamed(exc, SOLVER_KEYS) from None


def build_model(scene: Scene, stiff: StiffnessInput) -> GearDynamics:
    pair: PairSpec = scene.pair
    b = scene.bodies
    require_dynamics(scene)
    assert b.bearing_stiffness_N_per_m is not None
    m_p, m_g = b.mass_kg
    J_p, J_g = b.inertia_kg_m2
    g1, g2 = pair.gears
    R_p, R_g = g1.base_radius_m, g2.base_radius_m
    Cp = operating_centre_distance(scene)
    alpha = math.acos((R_p + R_g) / Cp) if Cp != pair.centre_distance_m else pair.operating_pressure_angle_rad
    m_e = 1.0 / (R_p**2 / J_p + R_g**2 / J_g)
    c_h, c_b = damping_from_ratios(
        b.mesh_damping_ratio, b.bearing_damping_ratio, stiff.mean_N_per_m, m_e, b.bearing_stiffness_N_per_m, m_p, m_g
    )
    if b.mesh_damping_N_s_per_m is not None:
        c_h = b.mesh_damping_N_s_per_m
    if b.bearing_damping_N_s_per_m is not None:
        c_b = b.bearing_damping_N_s_per_m
    eff = scene.effects
    half_backlash = None
    if "backlash" in eff:
        jn = backlash(pair, Cp, scene.initial_backlash_m, scene.backlash_form)
        half_backlash = 0.5 * jn
    half_clear = 0.5 * scene.clearance_m if "bearing_clearance" in eff else None
    tvms = "mesh_stiffness" in eff and eff["mesh_stiffness"]["source"] != "constant"
    coupling = eff.get("centre_distance", {}).get("coupling", "static")
    te = "transmission_error" in eff and bool(np.any(stiff.e != 0))
    return GearDynamics(
        m_p=m_p,
        m_g=m_g,
        J_p=J_p,
        J_g=J_g,
        R_p=R_p,
        R_g=R_g,
        alpha=alpha,
        k_b=b.bearing_stiffness_N_per_m,
        c_b=c_b,
        c_h=c_h,
        T_p=scene.operating.torque_Nm,
        omega_p=scene.operating.speed_rpm * 2 * math.pi / 60,
        z_p=pair.teeth[0],
        phi_table=stiff.phi,
        k_table=stiff.k,
        e_table=stiff.e if te else None,
        tvms=tvms,
        backlash_half_m=half_backlash,
        bearing_half_clearance_m=half_clear,
        te_excitation=te,
        centre_distance=coupling if "centre_distance" in eff else "static",
        C0_m=pair.centre_distance_m,
        mesh_damping="paper" if eff.get("backlash", {}).get("damping_in_gap") else "off-when-separated",
        k_constant=None if tvms else stiff.mean_N_per_m,
        interpolation=eff.get("mesh_stiffness", {}).get("interpolation", "linear"),
        table_periods=stiff.periods,
    )


@dataclass
class SimulationRun:
    scene: Scene
    model: GearDynamics
    stiffness: StiffnessInput
    result: Any
    solver: dict
    output: dict
    wall_s: float

    @property
    def signals(self) -> dict[str, np.ndarray]:
        """The kept signals in SI with the unit in each key (``t_s``, ``y_p_m``, ``F_m_N``, ...),
        on the uniform sample times of the kept window; ``result.signals`` is the dynamics
        layer's own dict (SI, the paper's symbol names without units)."""
        r = self.result
        return {"t_s": r.t, **{f"{n}_{SI_UNITS[n]}": r.signals[n] for n in self.output["signals"]}}

    def summary(self) -> dict[str, Any]:
        r = self.result
        n = self.output["harmonics"]
        harm, mean, ac_rms, p2p = {}, {}, {}, {}
        amps = r.harmonics_of(self.output["signals"], n)
        means = r.means_of(self.output["signals"], n)  # exact window integrals, like the harmonics
        for name in self.output["signals"]:
            unit, scale = SIGNAL_UNITS[name]
            key = f"{name}_{unit}"
            harm[key] = (amps[name] * scale).tolist()
            st = r.stats[name]
            mean[key] = means[name] * scale
            ac_rms[key] = st["ac_rms"] * scale
            p2p[key] = st["p2p"] * scale
        ci = condition_indicators(self.scene, r)
        # the indicators assume a periodic response: say so where it is not
        ci_warn = [f"condition indicators: {ci['periodicity']}"] if ci.get("periodic") is False else []
        return {
            "scene": self.scene.name,
            "fm_Hz": r.fm_Hz,
            "harmonics": harm,
            "mean": mean,
            "ac_rms": ac_rms,
            "peak_to_peak": p2p,
            "separation_fraction": r.separation_fraction,
            "backside_fraction": r.backside_fraction,
            "bearing_contact_fraction": r.bearing_contact_fraction,
            "steps": int(r.steps),
            # dopri5 rejects steps; RK4 rejects none: its second counter is the steps split
            # where a table node falls inside them (the stage values stay the table's function)
            **(
                {"rk4_substeps_at_table_nodes": int(r.rejected)}
                if r.method == "rk4"
                else {"rejected_steps": int(r.rejected)}
            ),
            "events": int(r.events),
            "method": r.method,
            "periodic_with_mesh_periods": int(r.periodic_with),
            "wall_s": self.wall_s,
            "integration_wall_s": r.wall_s,
            "compile_s": r.compile_s,
            "stiffness_source": self.stiffness.source,
            "mean_mesh_stiffness_N_per_m": self.stiffness.mean_N_per_m,
            "effects": sorted(self.scene.effects),
            "duration_s": self.solver["duration_s"],
            "stiffness_table_mesh_periods": self.stiffness.periods,
            "condition_indicators": ci,
            **({"flank": self.scene.flank.label()} if self.scene.flank is not None else {}),
            **({"faults": self.scene.faults.label()} if self.scene.faults is not None else {}),
            **contact_notes(self.scene, r),
            "assumptions": as_dicts(for_command(self.scene, "simulate")),
            **operating_notes(
                self.scene,
                contact_warnings(self.scene, r)
                + ci_warn
                + pair_warnings(self.scene)
                + body_warnings(self.scene)
                + stiffness_warnings(self.scene, self.stiffness.mean_N_per_m)
                + response_warnings(r),
            ),
        }


#: why a model without a backlash dead zone reports no separation fraction
NO_SEPARATION = (
    "no [effects] backlash: the mesh is a two-sided spring, which cannot separate; "
    "add [effects.backlash] to model separation"
)


def contact_notes(scene: Scene, r) -> dict[str, Any]:
    """``separation_note``: why ``separation_fraction`` is null (a model that cannot separate)."""
    return {"separation_note": NO_SEPARATION} if r.separation_fraction is None else {}


def contact_warnings(scene: Scene, r) -> list[str]:
    """A warning when a model without backlash pulls: its mesh force goes negative, so the back
    flanks carry load that a real pair with backlash would lose by separating."""
    if r.separation_fraction is not None or r.backside_fraction <= 0.0:
        return []
    f_min = float(np.min(r.signals["F_m"]))
    return [
        f"the mesh force is negative {100 * r.backside_fraction:.2f} % of the time (down to {f_min:.4g} N): "
        "without [effects] backlash the mesh is a two-sided spring, so the back flanks carry that load; a real "
        "pair separates instead. Add [effects.backlash] (initial_um = the pair's normal backlash) to model "
        "separation and back-flank impacts"
    ]


def operating_notes(scene: Scene, extra: list[str] | None = None) -> dict[str, Any]:
    """The contact ratio of the static operating geometry, and one-line warnings where a
    result rests on it (below 1, part of every mesh period has no pair in contact) or on
    an extrapolated input (running hours beyond the 'severe' wear phase)."""
    from gearwear.geometry.flank import flank_warnings
    from gearwear.geometry.operating import backlash, operating_geometry
    from gearwear.geometry.wear import wear_warnings

    pair = scene.pair
    Cp = operating_centre_distance(scene)
    mesh = operating_geometry(pair, scene.clearance_m if Cp != pair.centre_distance_m else 0.0).mesh
    opened = backlash(pair, pair.centre_distance_m)
    if "backlash" not in scene.effects and opened > 0.0:
        extra = [
            f"pair.centre_distance_mm opens {opened * 1e6:.4g} um of normal backlash, which the dynamics model "
            "only with [effects.backlash] (add it to let the teeth separate)"
        ] + list(extra or [])
    return {
        "contact_ratio": mesh.contact_ratio,
        "warnings": mesh.contact_ratio_warnings()
        + wear_warnings(mesh, scene.wear)
        + flank_warnings(pair, scene.flank)
        + list(extra or []),
    }


#: signals the condition indicators are computed on: the relative acceleration along the line
#: of action (the transmission-error acceleration) and the pinion bearing's transverse
#: acceleration (what an accelerometer on a stiff housing sees)
INDICATOR_SIGNALS = {"a_delta": "a_delta_m_per_s2", "a_y_p": "a_y_p_m_per_s2"}


def shaft_frequency_Hz(scene: Scene) -> tuple[float, int]:
    """(f_shaft, z): the shaft frequency of the faulty gear (the pinion's without a fault, or
    with faults on both gears) and its tooth count; sidebands sit at k f_m +- n f_shaft."""
    pair, f_p = scene.pair, scene.operating.speed_rpm / 60.0
    gears = {f.gear_index for f in scene.faults.faults()} if scene.faults is not None else set()
    if gears == {1}:
        return f_p * pair.teeth[0] / pair.teeth[1], pair.teeth[1]
    return f_p, pair.teeth[0]


def condition_indicators(scene: Scene, result) -> dict[str, Any]:
    """RMS, kurtosis, crest factor, FM0, FM4 and sideband energy (dynamics.indicators) of
    the indicator signals over the last whole revolutions of the kept window (of the faulty
    gear's shaft), or the reason there are none."""
    from gearwear.dynamics.analysis import accelerations_at
    from gearwear.dynamics.indicators import gear_indicators

    f_shaft, z = shaft_frequency_Hz(scene)
    S = int(round(result.fs_Hz / result.fm_Hz))
    revs = result.n_periods // z
    if revs < 1:
        return {
            "shaft_frequency_Hz": f_shaft,
            "revolutions": 0,
            "why_none": f"the kept window ({result.n_periods} mesh periods) is shorter than one revolution "
            f"({z} mesh periods); lengthen solver.duration_s",
        }
    n = revs * z * S
    # the accelerations of the last n samples only (each sample's depends on its own state)
    acc = accelerations_at(result.model, result.t[-n:], result.states[-n:], result.signals["F_m"][-n:])
    out: dict[str, Any] = {"shaft_frequency_Hz": f_shaft, "revolutions": revs, **periodicity_verdict(result)}
    for name, key in INDICATOR_SIGNALS.items():
        out[key] = gear_indicators(acc[name], result.fs_Hz, result.fm_Hz, f_shaft, unit="m/s^2").to_dict()
    return out


#: the largest period-to-period mismatch (relative to the range of delta) for which the response
#: counts as periodic: the indicators are stated to 3 digits
PERIODIC_MISMATCH = 1e-3


def periodicity_verdict(result) -> dict[str, Any]:
    """Whether the kept window is a periodic steady response, which the condition indicators
    assume: a tooth fault shows as a change from revolution to revolution of a periodic
    response, while a quasi-periodic or chaotic healthy pair has kurtosis, crest factor and
    sidebands of its own (dynamics.simulate.periodicity_mismatch on delta)."""
    from gearwear.dynamics.simulate import periodicity_mismatch

    S = int(round(result.fs_Hz / result.fm_Hz))
    p, m = periodicity_mismatch(result.signals["delta"], S, table_periods=result.table_periods)
    periodic = m <= PERIODIC_MISMATCH
    verdict = (
        f"periodic with {p} mesh period{'s' if p > 1 else ''} (period-to-period mismatch {m:.1e} of the range)"
        if periodic
        else f"not periodic over the kept window (best period {p} mesh periods repeats to only {m:.2g} of the "
        "range): kurtosis, crest factor, FM4 and the sidebands measure the quasi-periodic or chaotic "
        "response itself, not a tooth fault; check the steady state (gearwear runup) or lengthen "
        "solver.duration_s"
    )
    return {"periodic": periodic, "periodic_mismatch": m if math.isfinite(m) else None, "periodicity": verdict}


def run(scene: Scene, on_compile=None, stiffness: StiffnessInput | None = None) -> SimulationRun:
    """Simulate a scene. ``on_compile(message)`` is called once when the solver kernels
    for this effect set must be compiled (first run only). With a tooth fault the
    duration is rounded up so that the kept window is whole revolutions of the faulty
    gear (dynamics.simulate.round_to_table_periods): its shaft orders fall on exact bins.
    ``stiffness``: the tables to use (default: :func:`stiffness_input` of the scene)."""
    from gearwear.dynamics.simulate import round_to_table_periods

    t0 = time.perf_counter()
    solver, output = dict(scene.solver), dict(scene.output)
    stiff = stiffness_input(scene) if stiffness is None else stiffness
    try:
        model = build_model(scene, stiff)
        if model.table_periods > 1:
            solver["duration_s"] = round_to_table_periods(model, solver["duration_s"], solver["discard_s"])
        kw = {k: solver[k] for k in ("method", "steps_per_mesh_period", "rtol", "atol") if k in solver}
        res = simulate(model, solver["duration_s"], solver["discard_s"], on_compile=on_compile, **kw)
    except InputError as exc:
        raise renamed(exc, SOLVER_KEYS) from None
    return SimulationRun(scene, model, stiff, res, solver, output, time.perf_counter() - t0)
