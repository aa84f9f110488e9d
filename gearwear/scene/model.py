"""Scenes: a TOML file naming the gear pair, bodies, operating point and the effects
to simulate (docs/scene-reference.md). An effect is modelled only if ``[effects]`` names it.

The schema (keys, types, units, ranges, defaults, cross-key checks) is
``gearwear.scene.schema``; this module loads documents (files, built-in names, ``--set``
overrides) and resolves a validated document into the SI specs the layers below use.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

from gearwear.core.validation import Field, InputError, fail, fail_range, renamed
from gearwear.geometry.faults import CrackFault, FaultSpec, Spall, check_faults
from gearwear.geometry.flank import Deviation, FlankSpec, Relief, check_flank
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import Material, PairSpec, Web, check_pair
from gearwear.geometry.wear import PHASE_DEPTHS_M, WearSpec, check_wear
from gearwear.scene.checks import (
    DEFAULT_BEARING_DAMPING_RATIO,
    DEFAULT_MESH_DAMPING_RATIO,
    dynamics_fem_plane,
    resolved_method,
)
from gearwear.scene.schema import FaultsDoc, FlankDoc, OperatingDoc, SceneDoc, WearDoc, validate_document

TABLE_MIN_ROWS = 8
#: the other columns of the stiffness tables the tool writes (stiffness_job.curve_csv,
#: tables.HEADER): accepted in a user table and not used
TOOL_TABLE_COLUMNS = r"pairs_in_contact|ste_um|load_pair_\d+_N"


@dataclass(frozen=True)
class Bodies:
    """Masses and polar moments of inertia (resolved: given in the scene, or from each
    gear's own blank, ``geometry.blank``), bearing stiffness (None: not given; the dynamics
    refuse to run without it) and damping: either ratios (c = 2 zeta sqrt(k m)) or explicit
    coefficients (the coefficients replace the ratios; a scene may give one form per
    damper). ``mass_from`` / ``inertia_from``: "scene" or "blank" per gear (inertia also
    "blank radius of gyration": J = m J_blank / m_blank for a given mass)."""

    mass_kg: tuple[float, float]
    inertia_kg_m2: tuple[float, float]
    bearing_stiffness_N_per_m: float | None
    bearing_damping_ratio: float = 0.02
    mesh_damping_ratio: float = 0.05
    bearing_damping_N_s_per_m: tuple[float, float] | None = None
    mesh_damping_N_s_per_m: float | None = None
    mass_from: str = "scene"
    inertia_from: str = "scene"


def resolve_bodies(b, pair: PairSpec) -> Bodies:
    """The 6-DOF bodies of a validated ``[bodies]`` table: masses and inertias not given
    come from each gear's blank (geometry.blank.body_properties: the generated section with
    its teeth, minus the bore, with its web, times the face width and that gear's density);
    a given mass without an inertia keeps the blank's radius of gyration."""
    from gearwear.geometry.blank import body_properties

    blank = [body_properties(g, pair.face_width_m) for g in pair.gears]
    if b.mass_kg is None:
        mass, mass_from = tuple(p.mass_kg for p in blank), "blank"
    else:
        mass, mass_from = tuple(b.mass_kg), "scene"
    if b.inertia_kg_m2 is not None:
        inertia, inertia_from = tuple(b.inertia_kg_m2), "scene"
    elif b.mass_kg is None:
        inertia, inertia_from = tuple(p.inertia_kg_m2 for p in blank), "blank"
    else:
        inertia = tuple(m * p.inertia_kg_m2 / p.mass_kg for m, p in zip(mass, blank))
        inertia_from = "blank radius of gyration"
    return Bodies(
        mass,
        inertia,
        b.bearing_stiffness_N_per_m,  # type: ignore[arg-type]
        DEFAULT_BEARING_DAMPING_RATIO if b.bearing_damping_ratio is None else b.bearing_damping_ratio,
        DEFAULT_MESH_DAMPING_RATIO if b.mesh_damping_ratio is None else b.mesh_damping_ratio,
        b.bearing_damping_N_s_per_m,
        b.mesh_damping_N_s_per_m,
        mass_from,
        inertia_from,
    )


def require_dynamics(scene: "Scene") -> None:
    """The inputs only the 6-DOF dynamics need, checked before any work of a dynamic
    command (simulate, sweep, runup, diagnose)."""
    if scene.bodies.bearing_stiffness_N_per_m is None:
        raise InputError(
            "bodies.bearing_stiffness_N_per_m: missing; the 6-DOF dynamics need the radial bearing "
            "stiffness (it sets the lateral modes the mesh excites and spans orders of magnitude, "
            "about 1e7 to 1e10 N/m, between designs, so no default would be right for your pair)"
        )
    if scene.doc is not None:
        dynamics_fem_plane(scene.doc)  # a given fem.plane only where the mesh stiffness has a 2D state


@dataclass(frozen=True)
class Operating:
    speed_rpm: float = 1200.0
    torque_Nm: float = 40.0


@dataclass(frozen=True)
class Scene:
    """A validated scene resolved to SI. ``effects`` maps effect name -> its options (SI);
    ``doc`` is the validated document it came from (``gearwear.scene.schema.SceneDoc``)."""

    name: str
    pair: PairSpec
    bodies: Bodies
    operating: Operating
    effects: dict[str, dict[str, Any]] = field(default_factory=dict)
    solver: dict[str, Any] = field(default_factory=dict)
    output: dict[str, Any] = field(default_factory=dict)
    wear: WearSpec | None = None
    doc: SceneDoc | None = None
    flank: FlankSpec | None = None
    faults: FaultSpec | None = None

    @classmethod
    def load(cls, source: str | Path | None = None, overrides: Mapping[str, Any] | None = None) -> "Scene":
        """A scene from a built-in name or a TOML file (None: ``paper-default``), with
        dotted-key overrides, e.g. ``Scene.load("paper-wear-severe",
        {"operating.speed_rpm": 6000})``. Validated like a file."""
        data, name = load_scene_dict(source)
        for key, value in (overrides or {}).items():
            set_key(data, key, value)
        return scene_from_dict(data, name=name)

    @property
    def clearance_m(self) -> float:
        return self.effects.get("bearing_clearance", {}).get("clearance_m", 0.0)

    @property
    def initial_backlash_m(self) -> float:
        return self.effects.get("backlash", {}).get("initial_m", 0.0)

    @property
    def backlash_form(self) -> str:
        return self.effects.get("backlash", {}).get("form", "consistent")

    @property
    def mesh_frequency_Hz(self) -> float:
        return self.operating.speed_rpm / 60.0 * self.pair.teeth[0]


#: geometry's own parameter names -> scene keys (with unit conversion)
PAIR_KEYS = {
    "teeth": "pair.teeth",
    "addendum_coefficient": "pair.addendum_coefficient",
    "dedendum_coefficient": "pair.dedendum_coefficient",
    "rack_tip_radius_coefficient": "pair.rack_tip_radius_coefficient",
    "profile_shift": "pair.profile_shift",
    "hub_radius_m": ("pair.hub_radius_mm", 1e3, "mm"),
    "tip_diameter_m": ("pair.tip_diameter_mm", 1e3, "mm"),
    "root_diameter_m": ("pair.root_diameter_mm", 1e3, "mm"),
    "installed_centre_distance_m": ("pair.centre_distance_mm", 1e3, "mm"),
}

#: unitless own names that a geometry message may mention after its key ("profile_shift[0] >= 0.3")
_PAIR_WORDS = re.compile(
    r"(?<![\w.])(profile_shift|allow_undercut|addendum_coefficient|teeth)"
    r"(?=\[\d\]|\s*(?:>=|<=|=))"
)


def renamed_pair_error(exc: InputError) -> InputError:
    """A geometry error with its key and the unitless own names in its text renamed to
    scene keys (``teeth[0] = 12: ...; allow_undercut = true ...`` ->
    ``pair.teeth[0] = 12: ...; pair.allow_undercut = true ...``)."""
    if exc.key is not None and exc.key in WEB_KEYS:
        web_key, factor, unit = WEB_KEYS[exc.key]
        f = exc.field
        if f is not None:
            return fail_range(
                web_key, exc.value * factor, Field(unit, f.lo * factor, f.hi * factor, f.lo_open, f.hi_open), exc.note
            )
        return fail(web_key, exc.value * factor, unit, exc.why)
    out = renamed(exc, PAIR_KEYS)
    text = str(out)
    head, sep, body = text.partition(": ")
    body = _PAIR_WORDS.sub(lambda m: "pair." + m.group(1), body)
    if sep and body != text.partition(": ")[2]:
        new = type(out)(head + sep + body)
        for attr in ("key", "value", "unit", "why", "field", "note"):
            if attr in vars(out):
                setattr(new, attr, getattr(out, attr))
        return new
    return out


#: the bore radius of a scene without pair.hub_radius_mm, as a fraction of the root radius (assumed)
DEFAULT_BORE_FRACTION = 0.5


def default_bore_radii_m(spec: PairSpec) -> tuple[float, float]:
    """The assumed bore radius of each gear: DEFAULT_BORE_FRACTION of its root radius (m;
    a tiny positive value where the root circle is not above the centre, which check_pair
    then refuses by the profile shift)."""
    return tuple(max(DEFAULT_BORE_FRACTION * g.root_radius_m, 1e-9) for g in spec.gears)  # type: ignore[return-value]


def _web(doc) -> Web | None:
    return (
        None
        if doc is None
        else Web(doc.web_thickness_mm * 1e-3, doc.rim_thickness_mm * 1e-3, doc.hub_outer_radius_mm * 1e-3)
    )


#: geometry's web keys -> scene keys, per gear index
WEB_KEYS = {
    f"web.{own}[{i}]": (f"blank.{gear}.{key}", 1e3, "mm")
    for i, gear in enumerate(("pinion", "gear"))
    for own, key in (
        ("thickness_m", "web_thickness_mm"),
        ("rim_thickness_m", "rim_thickness_mm"),
        ("hub_radius_m", "hub_outer_radius_mm"),
    )
}


def pair_spec(doc: SceneDoc) -> PairSpec:
    """The SI pair spec of a validated document, checked for geometric consistency."""
    p, m = doc.pair, doc.material

    def mm(v):
        return None if v is None else (v[0] * 1e-3, v[1] * 1e-3)

    webs = (None, None) if doc.blank is None else (_web(doc.blank.pinion), _web(doc.blank.gear))
    spec = PairSpec(
        teeth=p.teeth,
        module_m=p.module_mm * 1e-3,
        pressure_angle_rad=math.radians(p.pressure_angle_deg),
        face_width_m=p.face_width_mm * 1e-3,
        addendum_coefficient=p.addendum_coefficient,
        dedendum_coefficient=p.dedendum_coefficient,
        rack_tip_radius_coefficient=p.rack_tip_radius_coefficient,
        profile_shift=p.profile_shift,
        hub_radius_m=(1e-9, 1e-9)
        if p.hub_radius_mm is None
        else (p.hub_radius_mm[0] * 1e-3, p.hub_radius_mm[1] * 1e-3),
        webs=webs,
        allow_undercut=p.allow_undercut,
        materials=tuple(
            Material(m.youngs_modulus_GPa[i] * 1e9, m.poisson_ratio[i], m.density_kg_per_m3[i]) for i in (0, 1)
        ),  # type: ignore[arg-type]
        tip_diameter_m=mm(p.tip_diameter_mm),
        root_diameter_m=mm(p.root_diameter_mm),
        installed_centre_distance_m=None if p.centre_distance_mm is None else p.centre_distance_mm * 1e-3,
    )
    if p.hub_radius_mm is None:
        spec = replace(spec, hub_radius_m=default_bore_radii_m(spec))
    try:
        check_pair(spec)
    except InputError as exc:
        raise renamed_pair_error(exc) from None
    return spec


def pair_from_dict(data: Mapping[str, Any]) -> PairSpec:
    """A pair spec from a scene document (only [pair], [material] and [blank] are read),
    validated."""
    from types import SimpleNamespace

    from gearwear.scene.schema import validate_tables

    return pair_spec(SimpleNamespace(**validate_tables(data, ("pair", "material", "blank"))))  # type: ignore[arg-type]


#: geometry.wear's own parameter names -> scene keys
WEAR_KEYS = {
    "max_depth_m": ("effects.wear.max_depth_um", 1e6, "um"),
    "hours": "effects.wear.hours",
    "phase": "effects.wear.phase",
}


def wear_spec(w: WearDoc, operating: OperatingDoc, pair: PairSpec | None = None) -> WearSpec:
    """The SI wear spec of a validated ``[effects] wear`` table at the operating point.

    With ``pair``, wear deeper than ``geometry.wear.MAX_DEPTH_FRACTION`` (1/3) of the
    tooth's half thickness where it is deepest is refused (``geometry.wear.check_wear``,
    on the nominal mesh), naming ``effects.wear.max_depth_um`` / ``hours`` / ``phase``."""
    kw: dict[str, Any] = {
        "phase": w.phase,
        "model": w.model,
        "torque_Nm": operating.torque_Nm,
        "speed_rpm": operating.speed_rpm,
        "taper_m": w.taper_mm * 1e-3,
    }
    if w.max_depth_um is not None:
        kw["max_depth_m"] = w.max_depth_um * 1e-6
    if w.hours is not None:
        kw["hours"] = w.hours
    if w.archard_k_m2_per_N is not None:
        kw["archard_k_m2_per_N"] = w.archard_k_m2_per_N
    if w.wear_intensity is not None:
        kw["wear_intensity"] = w.wear_intensity
    spec = WearSpec(**kw)
    if pair is not None:
        try:
            check_wear(MeshGeometry(pair, pair.centre_distance_m), spec)
        except InputError as exc:
            raise renamed(exc, WEAR_KEYS) from None
    return spec


def wear_from_dict(
    table: Mapping[str, Any] | str, torque_Nm: float = 40.0, speed_rpm: float = 1200.0, pair: PairSpec | None = None
) -> WearSpec:
    """A wear spec from an ``[effects] wear`` table (or a phase name), validated (with
    ``pair``: also against the depth limit of that pair, see :func:`wear_spec`)."""
    from gearwear.scene.checks import check_wear_table
    from gearwear.scene.schema import validate_tables

    t = validate_tables(
        {"effects": {"wear": table}, "operating": {"torque_Nm": torque_Nm, "speed_rpm": speed_rpm}},
        ("effects", "operating"),
    )
    assert t["effects"].wear is not None
    check_wear_table(t["effects"].wear)
    return wear_spec(t["effects"].wear, t["operating"], pair)


#: the command line's short flags (and the Python API's keywords of the same names): the
#: scene key each stands for
SHORT_KEYS = {
    "torque_Nm": "operating.torque_Nm",
    "clearance_um": "effects.bearing_clearance.clearance_um",
    "wear": "effects.wear",
}


def wear_table(text: str) -> dict[str, Any]:
    """The ``[effects] wear`` table of a ``--wear`` shorthand: a phase (``severe``), a
    maximum depth (``25um``) or running hours (``500h``)."""
    t = text.strip()
    if t in PHASE_DEPTHS_M:
        return {"phase": t}
    for suffix, key in (("um", "max_depth_um"), ("h", "hours")):
        if t.endswith(suffix):
            try:
                return {key: float(t[: -len(suffix)])}
            except ValueError:
                break
    raise InputError(
        f"--wear = {text!r}: must be one of {', '.join(PHASE_DEPTHS_M)}, a depth like 25um, or running hours like 500h"
    )


def wear_override(text: str) -> str:
    """The ``--wear`` shorthand as the ``--set`` it stands for."""
    ((key, value),) = wear_table(text).items()
    return f"effects.wear={{{key}={value!r}}}".replace("'", '"')


def parse_wear_arg(text: str, torque_Nm: float = 40.0, speed_rpm: float = 1200.0) -> WearSpec:
    """The wear spec of a ``--wear`` shorthand."""
    data = apply_overrides({"operating": {"torque_Nm": torque_Nm, "speed_rpm": speed_rpm}}, [wear_override(text)])
    return wear_from_dict(data["effects"]["wear"], torque_Nm, speed_rpm)


def scene_from_doc(doc: SceneDoc) -> Scene:
    """The runtime (SI) scene of a validated document."""
    pair = pair_spec(doc)
    b, e = doc.bodies, doc.effects
    bodies = resolve_bodies(b, pair)
    operating = Operating(doc.operating.speed_rpm, doc.operating.torque_Nm)
    effects: dict[str, dict[str, Any]] = {}
    if e.mesh_stiffness is not None:
        effects["mesh_stiffness"] = e.mesh_stiffness.model_dump(exclude_none=True)
    if e.wear is not None:
        effects["wear"] = e.wear.model_dump(exclude_none=True)
    if e.backlash is not None:
        effects["backlash"] = {
            "initial_m": e.backlash.initial_um * 1e-6,
            "form": e.backlash.form,
            "damping_in_gap": e.backlash.damping_in_gap,
        }
    if e.bearing_clearance is not None:
        from gearwear.geometry.operating import max_clearance_m

        bc_max = max_clearance_m(pair)
        if not e.bearing_clearance.clearance_um * 1e-6 < bc_max:
            raise fail_range(
                "effects.bearing_clearance.clearance_um",
                e.bearing_clearance.clearance_um,
                Field("um", 0.0, math.floor(bc_max * 1e7) / 10, hi_open=True),
                "below the clearance that moves the centres apart until the tip circles no longer "
                "overlap on the line of action (out of mesh)",
            )
        effects["bearing_clearance"] = {"clearance_m": e.bearing_clearance.clearance_um * 1e-6}
    if e.centre_distance is not None:
        effects["centre_distance"] = {"coupling": e.centre_distance.coupling}
    if e.transmission_error is not None:
        effects["transmission_error"] = {}
    wear = wear_spec(e.wear, doc.operating, pair) if e.wear is not None else None
    ms = effects.get("mesh_stiffness", {})
    if ms.get("source") == "table":
        tab = read_stiffness_table(ms["path"], pair.teeth[0])
        ms["angle_rad"], ms["k_N_per_m"], ms["excitation_m"] = tab
        if "transmission_error" in effects and tab[2] is None:
            raise InputError(
                f"effects.transmission_error: the table {ms['path']} has no excitation_um column, "
                f"so there is no excitation to apply; add the column or drop the effect"
            )
    solver = doc.solver.model_dump(exclude_none=True)
    solver["method"] = resolved_method(doc)
    flank = flank_spec(doc.flank, pair) if doc.flank is not None else None
    faults = fault_spec(doc.faults, pair) if doc.faults is not None else None
    return Scene(doc.name, pair, bodies, operating, effects, solver, doc.output.model_dump(), wear, doc, flank, faults)


#: geometry.flank's own keys -> scene keys (diameters in m -> mm, depths in m -> um)
FLANK_KEYS: dict[str, Any] = {
    f"{t}.{k}": (
        f"flank.{t}.{k.replace('_m', '_um' if 'amount' in k else '_mm')}",
        1e6 if "amount" in k else 1e3,
        "um" if "amount" in k else "mm",
    )
    for t in ("tip_relief", "root_relief")
    for k in ("amount_m", "start_diameter_m")
}
FLANK_KEYS.update(
    {
        "tip_relief.shape": "flank.tip_relief.shape",
        "root_relief.shape": "flank.root_relief.shape",
        "deviation.diameter_m": "flank.deviation_csv",
    }
)
FAULT_KEYS: dict[str, Any] = {
    "crack.tooth": "faults.crack.tooth",
    "spall.tooth": "faults.spall.tooth",
    "spall.start_diameter_m": ("faults.spall.start_diameter_mm", 1e3, "mm"),
    "spall.length_m": ("faults.spall.length_mm", 1e3, "mm"),
    "spall.depth_m": ("faults.spall.depth_um", 1e6, "um"),
    "depth_m": ("faults.crack.depth_mm", 1e3, "mm"),
    "angle_rad": ("faults.crack.angle_deg", 180 / math.pi, "deg"),
}


def flank_spec(f: FlankDoc, pair: PairSpec) -> FlankSpec | None:
    """The SI flank spec of a validated ``[flank]`` table (deviation CSVs read), checked
    against the pair (geometry.flank.check_flank, errors renamed to scene keys)."""

    def relief(doc, i):
        return None if doc is None else Relief(doc.amount_um[i] * 1e-6, doc.start_diameter_mm[i] * 1e-3, doc.shape)

    csv = f.deviation_csv or ("", "")
    devs = tuple(read_deviation_csv(path, i) if path else None for i, path in enumerate(csv))
    spec = FlankSpec(
        tip_relief=(relief(f.tip_relief, 0), relief(f.tip_relief, 1)),
        root_relief=(relief(f.root_relief, 0), relief(f.root_relief, 1)),
        deviation=devs,
    )  # type: ignore[arg-type]
    try:
        check_flank(pair, spec)
    except InputError as exc:
        raise renamed(exc, FLANK_KEYS) from None
    return None if spec.is_nominal else spec


def fault_spec(f: FaultsDoc, pair: PairSpec) -> FaultSpec | None:
    """The SI faults of a validated ``[faults]`` table, checked against the pair."""
    crack = spall = None
    if f.crack is not None:
        c = f.crack
        crack = CrackFault(c.gear, c.tooth, c.depth_mm * 1e-3, math.radians(c.angle_deg))
    if f.spall is not None:
        s = f.spall
        spall = Spall(s.gear, s.tooth, s.start_diameter_mm * 1e-3, s.length_mm * 1e-3, s.depth_um * 1e-6)
    spec = FaultSpec(crack, spall)
    try:
        check_faults(pair, spec)
    except InputError as exc:
        raise renamed(exc, FAULT_KEYS) from None
    if crack is not None and f.crack is not None:
        from gearwear.geometry.crack import max_depth_m
        from gearwear.geometry.profile import tooth_profile

        q_max = max_depth_m(tooth_profile(pair.gear(crack.gear_index)), crack.angle_rad)
        if crack.depth_m > q_max:
            raise fail_range(
                "faults.crack.depth_mm",
                f.crack.depth_mm,
                Field("mm", 0.0, math.floor(q_max * 1e7) / 1e4, lo_open=True),
                f"at angle_deg = {f.crack.angle_deg:g} the crack tip must stay on the loaded side of "
                "the tooth centre line and outside the bore (Chen & Shao's reduced-section range)",
            )
    return None if spec.is_empty else spec


def read_deviation_csv(path: str | Path, gear_index: int) -> Deviation:
    """A measured profile deviation: CSV with the header columns ``diameter_mm`` and
    ``deviation_um`` (positive = material removed), at least 2 rows, diameters strictly
    increasing (checked against the flank by geometry.flank.check_flank)."""
    key = f"flank.deviation_csv[{gear_index}]"
    _, data = _read_csv(path, key, ("diameter_mm", "deviation_um"), min_rows=2, what="deviation file")
    return Deviation(
        tuple(float(x) for x in data[:, 0] * 1e-3), tuple(float(x) for x in data[:, 1] * 1e-6), source=Path(path).name
    )


def scene_from_dict(data: Mapping[str, Any], name: str = "scene") -> Scene:
    """Validate a parsed scene document (``gearwear.scene.schema``) and resolve it to SI."""
    return scene_from_doc(validate_document(data, name=name))


def _read_csv(
    path: str | Path,
    key: str,
    required: tuple[str, ...],
    optional: tuple[str, ...] = (),
    min_rows: int = 2,
    what: str = "table",
    also: str | None = None,
):
    """(header, rows as a float array) of a small numeric CSV a scene refers to: the header
    starts with the ``required`` columns, may add ``optional`` ones and columns whose names
    match the regular expression ``also`` (read, not used: the other columns of a file the
    tool wrote itself), '#' lines are comments; at least ``min_rows`` complete rows of
    finite numbers. Problems are one-line InputErrors under ``key``."""
    import csv

    import numpy as np

    from gearwear.core.inputs import read_input_text

    p = Path(path)
    text = read_input_text(p, key, what, TABLE_LIMIT_BYTES)
    rows = [r for r in csv.reader(text.splitlines()) if r and not r[0].lstrip().startswith("#")]
    want = ",".join(required) + "".join(f"[,{c}]" for c in optional)
    if not rows:
        raise fail(key, repr(str(p)), "", f"empty file; expected a header {want}")
    head = [c.strip() for c in rows[0]]
    allowed = required + optional
    other = re.compile(also) if also else None
    known = [c in allowed or (other is not None and other.fullmatch(c) is not None) for c in head]
    if head[: len(required)] != list(required) or not all(known) or len(set(head)) != len(head):
        extra = f" with an optional {', '.join(optional)} column" if optional else ""
        raise fail(key, repr(str(p)), "", f"header {','.join(head)!r}: must be {','.join(required)}{extra}")
    try:
        data = np.array([[float(c) for c in r] for r in rows[1:]], dtype=float)
    except ValueError as exc:
        raise fail(key, repr(str(p)), "", f"non-numeric value ({exc})") from None
    if data.ndim != 2 or data.shape[0] < min_rows or data.shape[1] != len(head):
        n = data.shape[0] if data.ndim == 2 else 0
        raise fail(key, repr(str(p)), "", f"needs >= {min_rows} complete rows of {len(head)} columns, got {n}")
    if not np.all(np.isfinite(data)):
        r = int(np.argwhere(~np.isfinite(data))[0, 0]) + 2
        raise fail(key, repr(str(p)), "", f"row {r} (line {r}): values must be finite numbers")
    return head, data


def read_stiffness_table(path: str | Path, z_pinion: int):
    """A user mesh-stiffness table: CSV with the header columns ``angle_deg`` (pinion
    angle over one mesh period, 0 <= angle < 360 / z1, strictly increasing, at least 8
    rows, not necessarily uniform), ``k_N_per_m`` (>= 0) and optionally ``excitation_um``
    (the transmission-error excitation e, material removed > 0). The rows must cover the
    period: the wrap-around gap (first row + period - last row) may not exceed the largest
    spacing between rows. Returns (angle_rad, k_N_per_m, excitation_m or None)."""
    import numpy as np

    key = "effects.mesh_stiffness.path"
    p = Path(path)
    # the tool's own stiffness CSVs (gearwear stiffness, calibrate) read back as they are
    head, data = _read_csv(
        p,
        key,
        ("angle_deg", "k_N_per_m"),
        ("excitation_um",),
        TABLE_MIN_ROWS,
        "stiffness table",
        also=TOOL_TABLE_COLUMNS,
    )
    period = 360.0 / z_pinion
    ang, k = data[:, 0], data[:, 1]
    if ang[0] < 0 or ang[-1] >= period:
        raise fail(
            key,
            repr(str(p)),
            "",
            f"angle_deg must lie in [0, {period:g}) deg (one mesh period "
            f"of the {z_pinion}-tooth pinion), got {ang.min():g} to {ang.max():g} deg",
        )
    if np.any(np.diff(ang) <= 0):
        r = int(np.argmax(np.diff(ang) <= 0)) + 3
        raise fail(key, repr(str(p)), "", f"angle_deg must be strictly increasing (line {r})")
    if np.any(k < 0):
        r = int(np.argmax(k < 0)) + 2
        raise fail(key, repr(str(p)), "", f"k_N_per_m must be >= 0 N/m (line {r}: {k[r - 2]:g})")
    if not np.any(k > 0):
        raise fail(key, repr(str(p)), "", "k_N_per_m is 0 everywhere: no mesh stiffness")
    wrap = ang[0] + period - ang[-1]
    if wrap > np.max(np.diff(ang)) * (1 + 1e-9):
        raise fail(
            key,
            repr(str(p)),
            "",
            f"the rows do not cover one mesh period ({period:g} deg): "
            f"{ang[0]:g} to {ang[-1]:g} deg leaves a {wrap:g} deg gap",
        )
    e = data[:, head.index("excitation_um")] * 1e-6 if "excitation_um" in head else None
    return np.radians(ang), k, e


def _resolve_table_path(data: dict[str, Any], base: Path) -> dict[str, Any]:
    """Relative paths of the files a scene refers to (the stiffness table, the measured
    deviations) are relative to the scene file's folder."""

    def resolve(p):
        return str(base / p) if isinstance(p, str) and p and not Path(p).is_absolute() else p

    ms = data.get("effects", {}).get("mesh_stiffness") if isinstance(data.get("effects"), dict) else None
    if isinstance(ms, dict) and "path" in ms:
        ms["path"] = resolve(ms["path"])
    fl = data.get("flank")
    if isinstance(fl, dict) and "deviation_csv" in fl:
        dev = fl["deviation_csv"]
        fl["deviation_csv"] = [resolve(p) for p in dev] if isinstance(dev, list) else resolve(dev)
    return data


def load_scene(path: str | Path | None = None) -> Scene:
    """A scene from a TOML file or a built-in name, or the built-in default (the paper's
    pair) if None."""
    data, name = load_scene_dict(path)
    return scene_from_dict(data, name=name)


def builtin_scene_dict(name: str) -> dict[str, Any]:
    """The raw TOML document of a built-in scene."""
    names = builtin_scene_names()
    if name not in names:
        raise InputError(f"built-in scene {name!r}: unknown (available: {', '.join(names)})")
    return tomllib.loads(resources.files("gearwear.data").joinpath(f"{name}.toml").read_text())


def parse_value(text: str) -> Any:
    """A --set value read as a TOML value (numbers, quoted strings, arrays, booleans,
    inline tables); anything else is taken as a bare string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(data: dict[str, Any], overrides: list[str]) -> dict[str, Any]:
    """Apply ``--set key.path=value`` overrides to a raw scene document (a copy).

    The value is read as a TOML value (numbers, strings in quotes, arrays, booleans,
    inline tables); a bare word is taken as a string. The bare word ``none`` removes the key
    (``--set effects.backlash=none`` drops the effect; a removed key takes its default). The
    result is validated like a file, so a bad override gets the same one-line error."""
    import copy

    out = copy.deepcopy(data)
    check_sets(overrides or [])
    for item in overrides or []:
        key, text = item.split("=", 1)
        if text.strip() == REMOVE:
            remove_key(out, key.strip())
        else:
            set_key(out, key.strip(), parse_value(text.strip()))
    return out


#: the --set value that removes a key
REMOVE = "none"


def check_sets(items: list[str]) -> None:
    """Each --set is one KEY=VALUE on one line (a newline would let a value inject TOML tables
    or keys), and each key is set once (which of two values wins would be a guess): one-line
    InputErrors otherwise. The short flags (--torque-Nm, --wear, ...) count as the keys they set."""
    seen: dict[str, str] = {}
    for item in items:
        if "=" not in item:
            raise InputError(f"--set {item!r}: must be KEY=VALUE with a dotted key, e.g. operating.speed_rpm=6000")
        if "\n" in item or "\r" in item:
            raise InputError(
                f"--set {item.splitlines()[0]!r}...: a value is one line (a newline could inject TOML "
                "tables); give one KEY=VALUE per --set"
            )
        key, value = (x.strip() for x in item.split("=", 1))
        if key in seen:
            raise InputError(
                f"--set {key}: given twice ({seen[key]!r} and {value!r}); give each key once "
                "(a short flag such as --torque-Nm sets its key too)"
            )
        seen[key] = value


def remove_key(data: dict[str, Any], key: str) -> None:
    """Remove a dotted key from a raw document (absent already: nothing to do, it is absent)."""
    *path, last = key.split(".")
    node: Any = data
    for part in path:
        node = node.get(part) if isinstance(node, dict) else None
        if node is None:
            return
    if isinstance(node, dict):
        node.pop(last, None)


def set_key(data: dict[str, Any], key: str, value: Any) -> None:
    """Set a dotted key (``operating.speed_rpm``) in a raw document, making tables on the way."""
    parts = key.split(".")
    node = data
    for part in parts[:-1]:
        nxt = node.setdefault(part, {})
        if not isinstance(nxt, dict):
            raise InputError(f"--set {key}: {part} is not a table")
        node = nxt
    node[parts[-1]] = value


#: the largest scene file read (bytes): a scene is a few kB; more is not a scene
SCENE_LIMIT_BYTES = 1 << 20
#: the largest CSV a scene refers to (bytes): a 1e6-row stiffness table is ~40 MB
TABLE_LIMIT_BYTES = 64 << 20


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file (once, bounded, a regular file only: core.inputs.read_input),
    turning I/O and syntax problems into one-line InputErrors."""
    from gearwear.core.inputs import read_input

    p = Path(path)
    if not os.path.lexists(p):
        raise InputError(
            f"{p}: no such scene file, and not a built-in scene (built-in: {', '.join(builtin_scene_names())})"
        )
    data = read_input(p, "scene", "scene file", SCENE_LIMIT_BYTES)
    try:
        return tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(f"{p}: cannot read (not UTF-8 text: {type(exc).__name__})") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{p}: not valid TOML ({exc})") from None


def load_scene_dict(path: str | Path | None, default: str = "paper-default") -> tuple[dict[str, Any], str]:
    """(raw document, name) of a scene file or a built-in scene name; the built-in
    ``default`` when path is None. A file of that name wins over a built-in name. A file
    may start from another scene, ``extends = "paper-default"`` (a built-in name, or a
    file relative to it): that scene's keys, then the file's (tables merge key by key)."""
    if path is None:
        return builtin_scene_dict(default), default
    p = Path(path)
    if not p.exists() and str(path) in builtin_scene_names():
        return builtin_scene_dict(str(path)), str(path)
    return _extended(_resolve_table_path(load_toml(p), p.resolve().parent), p, 0), p.stem


def _extended(data: dict[str, Any], path: Path, depth: int) -> dict[str, Any]:
    """``data`` on top of the scene its ``extends`` key names (recursively, at most 8 deep)."""
    base_name = data.pop("extends", None)
    if base_name is None:
        return data
    if not isinstance(base_name, str) or not base_name:
        raise fail("extends", repr(base_name), "", "must be a built-in scene name or a scene file path")
    if depth >= 8:
        raise fail("extends", repr(base_name), "", "scenes extend each other more than 8 deep (a cycle?)")
    candidate = Path(base_name) if Path(base_name).is_absolute() else path.resolve().parent / base_name
    if candidate.exists():
        base = _extended(_resolve_table_path(load_toml(candidate), candidate.resolve().parent), candidate, depth + 1)
    elif base_name in builtin_scene_names():
        base = builtin_scene_dict(base_name)
    else:
        raise fail(
            "extends",
            repr(base_name),
            "",
            f"no such scene file, and not a built-in scene (built-in: {', '.join(builtin_scene_names())})",
        )
    base.pop("name", None)
    base.pop("description", None)
    return _merge(base, data)


def _merge(base: dict[str, Any], top: Mapping[str, Any]) -> dict[str, Any]:
    """``top`` over ``base``: tables merge key by key, any other value replaces."""
    out = dict(base)
    for k, v in top.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def builtin_scene_names() -> list[str]:
    return sorted(f.name[:-5] for f in resources.files("gearwear.data").iterdir() if f.name.endswith(".toml"))


def builtin_scene(name: str) -> Scene:
    """A scene shipped with the package (``gearwear/data/<name>.toml``)."""
    return scene_from_dict(builtin_scene_dict(name), name=name)
