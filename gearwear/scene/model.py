"""Scenes: a TOML file naming the gear pair, bodies, operating point and the effects
to simulate (docs/scene-reference.md). An effect is modelled only if ``[effects]`` names it.

The schema (keys, types, units, ranges, defaults, cross-key checks) is
``gearwear.scene.schema``; this module loads documents (files, built-in names, ``--set``
overrides) and resolves a validated document into the SI specs the layers below use.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping

from gearwear.core.validation import Field, InputError, fail, fail_range, renamed
from gearwear.geometry.faults import CrackFault, FaultSpec, Spall, check_faults
from gearwear.geometry.flank import FlankSpec, Relief, check_flank
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import Material, PairSpec, Web, check_pair
from gearwear.geometry.wear import WearSpec, check_wear
from gearwear.scene.checks import (
    DEFAULT_BEARING_DAMPING_RATIO,
    DEFAULT_MESH_DAMPING_RATIO,
    dynamics_fem_plane,
    resolved_method,
)
from gearwear.scene.files import builtin_scene_dict, load_scene_dict, read_deviation_csv, read_stiffness_table
from gearwear.scene.overrides import apply_overrides, set_key, wear_override
from gearwear.scene.schema import FaultsDoc, FlankDoc, OperatingDoc, SceneDoc, WearDoc
from gearwear.scene.validate import validate_document


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
        mass,  # type: ignore[arg-type]
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

    from gearwear.scene.validate import validate_tables

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
        "taper_m": w.taper_mm * 1e-3,
    }
    if w.max_depth_um is not None:
        kw["max_depth_m"] = w.max_depth_um * 1e-6
    if w.hours is not None:
        # the speed counts the contacts of the running time (geometry.wear.cycles); a depth
        # or a phase fixes the magnitude and the profile is the same at every speed, so the
        # spec leaves it at its default there: two scenes that differ only in the speed
        # then have equal specs and share one stiffness table (a speed sweep, the plan)
        kw["hours"] = w.hours
        kw["speed_rpm"] = operating.speed_rpm
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
    from gearwear.scene.validate import validate_tables

    t = validate_tables(
        {"effects": {"wear": table}, "operating": {"torque_Nm": torque_Nm, "speed_rpm": speed_rpm}},
        ("effects", "operating"),
    )
    assert t["effects"].wear is not None
    check_wear_table(t["effects"].wear)
    return wear_spec(t["effects"].wear, t["operating"], pair)


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
        deviation=devs,  # type: ignore[arg-type]
    )
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


def scene_from_dict(data: Mapping[str, Any], name: str = "scene") -> Scene:
    """Validate a parsed scene document (``gearwear.scene.schema``) and resolve it to SI."""
    return scene_from_doc(validate_document(data, name=name))


def load_scene(path: str | Path | None = None) -> Scene:
    """A scene from a TOML file or a built-in name, or the built-in default (the paper's
    pair) if None."""
    data, name = load_scene_dict(path)
    return scene_from_dict(data, name=name)


def builtin_scene(name: str) -> Scene:
    """A scene shipped with the package (``gearwear/data/<name>.toml``)."""
    return scene_from_dict(builtin_scene_dict(name), name=name)
