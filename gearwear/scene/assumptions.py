"""Every value a result uses that the user's scene did not give: one ``assumed:`` line each.

A scene names its pair (teeth, module, face width) and its operating point; everything
else has a stated default or is derived from the user's own geometry. Nothing of the
paper's pair is a silent default for another pair: each value that is not in the scene
but changes a result is listed here, with the reason, on the console (``assumed: KEY =
VALUE UNIT (why)``), in ``--json`` (``assumptions``), in the summary files and in the
manifest.

What a command uses decides what it lists (``uses``):

* ``geometry``  the basic rack, pressure angle, profile shifts, centre distance
* ``elastic``   Young's modulus and Poisson's ratio (stiffness models, FE)
* ``bore``      the bore radius (the FE holds the bodies there; the body masses)
* ``bodies``    density, masses and inertias of the 6-DOF bodies
* ``dynamics``  damping ratios and the mesh-stiffness model of a scene without one
* ``wear``      the depth of a named wear phase, the wear model's coefficients
* ``iso``       the ISO 6336 K_v inputs a run-up draws next to its own
* ``fem``       the 2D idealisation (fem.plane) of the FE models and the analytic tooth beams;
                a dynamic command uses it with an analytic or FE mesh-stiffness source
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable

from gearwear.geometry.wear import PHASE_DEPTHS_M, WearSpec
from gearwear.scene.checks import (
    DEFAULT_BEARING_DAMPING_RATIO,
    DEFAULT_MESH_DAMPING_RATIO,
    PLANE_STRAIN_FROM_B_OVER_M,
    dynamics_uses_plane,
    resolved_plane,
)
from gearwear.scene.schema import Iso6336Doc, SceneDoc

#: what each command's results use (see the module docstring)
USES = {
    "geometry": frozenset({"geometry", "wear", "bore", "bodies"}),
    "stiffness": frozenset({"geometry", "elastic", "wear", "fem"}),
    "stiffness-iso": frozenset({"geometry", "elastic", "wear"}),
    "stiffness-fem": frozenset({"geometry", "elastic", "wear", "bore", "fem"}),
    "verify": frozenset({"geometry", "elastic", "wear", "bore", "fem"}),
    "calibrate": frozenset({"geometry", "elastic", "wear", "bore", "fem"}),
    "simulate": frozenset({"geometry", "elastic", "wear", "bore", "bodies", "dynamics"}),
    "runup": frozenset({"geometry", "elastic", "wear", "bore", "bodies", "dynamics", "iso"}),
    "report pair": frozenset({"geometry", "elastic", "wear", "bore", "bodies", "dynamics", "iso", "fem"}),
}


@dataclass(frozen=True)
class Assumption:
    """One value not in the scene: its scene key, the value used (scene units), the unit,
    why this value, and which kind of result uses it."""

    key: str
    value: Any
    unit: str
    why: str
    use: str

    @property
    def line(self) -> str:
        return line_of(self.to_dict())

    def to_dict(self) -> dict[str, Any]:
        return {"key": self.key, "value": self.value, "unit": self.unit, "why": self.why}


def line_of(a: dict[str, Any]) -> str:
    """``assumed: KEY = VALUE UNIT (why)`` of an assumption's dict."""
    unit = f" {a['unit']}" if a["unit"] else ""
    return f"assumed: {a['key']} = {_text(a['value'])}{unit} ({a['why']})"


def _text(v: Any) -> str:
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_text(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _per_gear(values: Iterable[float]) -> Any:
    """One value when both gears share it (as a scene writes it), else [pinion, gear]."""
    a, b = values
    return a if a == b else [a, b]


def _given(model: Any, key: str) -> bool:
    return model is not None and key in model.model_fields_set


def scene_assumptions(scene) -> list[Assumption]:
    """Every assumption of a resolved ``gearwear.scene.model.Scene`` (all uses)."""
    doc: SceneDoc = scene.doc
    pair = scene.pair
    p, mat, b, e = doc.pair, doc.material, doc.bodies, doc.effects
    out: list[Assumption] = []

    def add(key: str, value: Any, unit: str, why: str, use: str) -> None:
        out.append(Assumption(key, value, unit, why, use))

    rack = "ISO 53 profile A basic rack"
    if not _given(p, "pressure_angle_deg"):
        add("pair.pressure_angle_deg", p.pressure_angle_deg, "deg", "the standard pressure angle", "geometry")
    for key, why in (
        ("addendum_coefficient", f"{rack}, h_a* = 1"),
        ("dedendum_coefficient", f"{rack}, h_f* = 1.25"),
        ("rack_tip_radius_coefficient", f"{rack}, rho_fP* = 0.38"),
    ):
        if not _given(p, key) and not (key == "dedendum_coefficient" and p.root_diameter_mm is not None):
            add(f"pair.{key}", getattr(p, key), "", why, "geometry")
    if not _given(p, "profile_shift"):
        add("pair.profile_shift", _per_gear(p.profile_shift), "", "no profile shift", "geometry")
    if p.centre_distance_mm is None:
        add(
            "pair.centre_distance_mm",
            round(pair.centre_distance_m * 1e3, 6),
            "mm",
            "the zero-backlash working centre distance of the profile shifts",
            "geometry",
        )
    if p.hub_radius_mm is None:
        add(
            "pair.hub_radius_mm",
            _per_gear(round(r * 1e3, 4) for r in pair.hub_radius_m),
            "mm",
            "bore radius: half of each root radius; the FE holds the bodies there and the masses exclude it",
            "bore",
        )
    if not _given(mat, "youngs_modulus_GPa"):
        add("material.youngs_modulus_GPa", _per_gear(mat.youngs_modulus_GPa), "GPa", "steel", "elastic")
    if not _given(mat, "poisson_ratio"):
        add("material.poisson_ratio", _per_gear(mat.poisson_ratio), "", "steel", "elastic")
    bodies = scene.bodies
    blank = (
        "each gear's blank: its generated section with the teeth, minus the bore, "
        + ("solid" if doc.blank is None else "with the [blank] web where given")
        + " over the face width, times the density"
    )
    if bodies.mass_from == "blank" or bodies.inertia_from != "scene":
        if not _given(mat, "density_kg_per_m3"):
            add("material.density_kg_per_m3", _per_gear(mat.density_kg_per_m3), "kg/m^3", "steel", "bodies")
    if bodies.mass_from == "blank":
        add("bodies.mass_kg", _per_gear(round(m, 6) for m in bodies.mass_kg), "kg", f"from {blank}", "bodies")
    if bodies.inertia_from == "blank":
        add(
            "bodies.inertia_kg_m2",
            _per_gear(float(f"{j:.6g}") for j in bodies.inertia_kg_m2),
            "kg m^2",
            f"from {blank}",
            "bodies",
        )
    elif bodies.inertia_from != "scene":
        add(
            "bodies.inertia_kg_m2",
            _per_gear(float(f"{j:.6g}") for j in bodies.inertia_kg_m2),
            "kg m^2",
            "the given mass at the radius of gyration of each gear's blank, J = m J_blank / m_blank",
            "bodies",
        )
    if b.bearing_damping_ratio is None and b.bearing_damping_N_s_per_m is None:
        add(
            "bodies.bearing_damping_ratio",
            DEFAULT_BEARING_DAMPING_RATIO,
            "",
            "a typical rolling-bearing support; c_b = 2 zeta_b sqrt(k_b m)",
            "dynamics",
        )
    if b.mesh_damping_ratio is None and b.mesh_damping_N_s_per_m is None:
        add(
            "bodies.mesh_damping_ratio",
            DEFAULT_MESH_DAMPING_RATIO,
            "",
            "mid-range of the 0.03-0.1 usual for spur meshes; c_h = 2 zeta_m sqrt(k_mean m_e)",
            "dynamics",
        )
    if e.mesh_stiffness is None:
        add(
            "effects.mesh_stiffness",
            "absent",
            "",
            "a constant mesh stiffness, the mean of the analytic "
            "(Ishikawa) curve; add [effects] mesh_stiffness for the time-varying one",
            "dynamics",
        )
    w = e.wear
    if w is not None:
        if w.phase is not None and w.phase != "unworn":
            depth = round(PHASE_DEPTHS_M[w.phase] * 1e6, 9)
            add(
                f"effects.wear.phase = \"{w.phase}\": max_depth_um",
                depth,
                "um",
                "this project's reading of the paper's phases (it gives no depths); give max_depth_um for your own",
                "wear",
            )
        if w.hours is not None:
            if not _given(w, "model"):
                add("effects.wear.model", w.model, "", "Archard's law (Flodin & Andersson 1997)", "wear")
            if w.model == "archard" and w.archard_k_m2_per_N is None:
                add(
                    "effects.wear.archard_k_m2_per_N",
                    WearSpec.archard_k_m2_per_N,
                    "m^2/N",
                    "boundary-lubricated steel (Flodin & Andersson 1997); the depth scales with it",
                    "wear",
                )
            if w.model == "paper_eq1" and w.wear_intensity is None:
                add(
                    "effects.wear.wear_intensity",
                    WearSpec.wear_intensity,
                    "",
                    "I_h of the paper's Eq. 1 (assumed; the paper gives none)",
                    "wear",
                )
        if not _given(w, "taper_mm") and not (w.phase == "unworn"):
            add("effects.wear.taper_mm", w.taper_mm, "mm", "run-out of the depth beyond the active profile", "wear")
    if not _given(doc.fem, "plane"):
        b_m = doc.pair.face_width_mm / doc.pair.module_mm
        state = resolved_plane("auto", doc.pair.face_width_mm, doc.pair.module_mm)
        add(
            "fem.plane",
            state,
            "",
            f"auto: b/m = {b_m:.3g} is {'at or above' if state == 'strain' else 'below'} "
            f"{PLANE_STRAIN_FROM_B_OVER_M:g}, where the 3D check (reports/plane) finds plane {state} the closer 2D "
            "state of a tooth's compliance",
            "fem",
        )
    iso = doc.iso6336 or Iso6336Doc()
    for key, why in (
        ("accuracy_grade", "ISO 1328-1 grade of the deviations not given"),
        ("application_factor", "K_A = 1, a uniform drive"),
    ):
        if not _given(doc.iso6336, key):
            add(f"iso6336.{key}", getattr(iso, key), "", why, "iso")
    return out


def for_command(scene, command: str, extra: Iterable[str] = ()) -> list[Assumption]:
    """The assumptions a command's results rest on (``USES[command]`` plus ``extra``)."""
    uses = USES[command] | frozenset(extra)
    if "dynamics" in uses and scene.doc is not None and dynamics_uses_plane(scene.doc):
        uses |= {"fem"}
    return [a for a in scene_assumptions(scene) if a.use in uses]


def as_dicts(items: Iterable[Assumption]) -> list[dict[str, Any]]:
    return [a.to_dict() for a in items]


def print_lines(items: Iterable[Assumption]) -> None:
    for a in items:
        print(a.line)
