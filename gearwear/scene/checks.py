"""Checks across the keys of a scene document (an option that would be silently ignored, or
that contradicts another, is an error) and what a document resolves to: the 2D state of the
FE models (fem.plane), the solver, the damping defaults, the resolved dictionary."""

from typing import Any

from pydantic import BaseModel

from gearwear.core.validation import InputError, fail
from gearwear.scene.schema import SIGNALS, SceneDoc, WearDoc
from gearwear.stiffness.sources import SCENE_SOURCES, SOURCES

# -- checks across keys ---------------------------------------------------------------


def _given(model: BaseModel | None, key: str) -> bool:
    return model is not None and key in model.model_fields_set


def cross_check(doc: SceneDoc) -> None:
    """Every option that would be silently ignored, or that contradicts another, is an error."""
    e, b, s = doc.effects, doc.bodies, doc.solver
    ms = e.mesh_stiffness
    src = ms.source if ms is not None else None
    if ms is not None:
        if ms.value_N_per_m is not None and src != "constant":
            raise fail(
                "effects.mesh_stiffness.value_N_per_m",
                ms.value_N_per_m,
                "N/m",
                f'only used with source = "constant" (source is {src!r})',
            )
        if _given(ms, "interpolation") and src == "constant":
            raise fail(
                "effects.mesh_stiffness.interpolation", repr(ms.interpolation), "", 'not used with source = "constant"'
            )
        if src == "table" and not ms.path:
            raise InputError(
                'effects.mesh_stiffness.path: missing (a CSV file with columns angle_deg, '
                'k_N_per_m and optionally excitation_um, needed by source = "table")'
            )
        if _given(ms, "points_per_mesh_period") and (src in ("fem", "table") or ms.value_N_per_m is not None):
            why = (
                f"source is {src!r}"
                if src in ("fem", "table")
                else "the constant is value_N_per_m, not an analytic mean"
            )
            raise fail(
                "effects.mesh_stiffness.points_per_mesh_period",
                ms.points_per_mesh_period,
                "",
                f'only used with an analytic table (source "analytic", "calibrated" or a "constant" '
                f"without value_N_per_m; {why})",
            )
        if ms.path is not None and src != "table":
            raise fail(
                "effects.mesh_stiffness.path", repr(ms.path), "", f'only used with source = "table" (source is {src!r})'
            )
        if ms.blank_torsion is not None and src not in ("fem", "calibrated"):
            raise fail(
                "effects.mesh_stiffness.blank_torsion",
                repr(ms.blank_torsion),
                "",
                f'only used with source = "fem" or "calibrated" (source is {src!r}, which has no blank torsion term)',
            )
    w = e.wear
    if w is not None:
        check_wear_table(w)
        if src == "table":
            raise InputError(
                'effects.wear: cannot be applied to a user stiffness table (mesh_stiffness.source = '
                '"table"): the table already is the stiffness; drop [effects] wear'
            )
        if src == "constant" and ms is not None and ms.value_N_per_m is not None and e.transmission_error is None:
            raise InputError(
                "effects.wear: ignored with a constant mesh_stiffness.value_N_per_m and no "
                "transmission_error (the wear would change nothing); drop one of them"
            )
    # transmission_error on a nominal flank is accepted: a wear study needs its unworn baseline,
    # and the nominal flank's excitation is not zero (the tip-corner contact outside the path)
    if e.centre_distance is not None and e.centre_distance.coupling == "static" and e.bearing_clearance is None:
        raise InputError(
            'effects.centre_distance: coupling = "static" moves the centre distance by the bearing '
            "clearance only; without [effects] bearing_clearance it is the nominal one. Add the "
            'clearance, use coupling = "dynamic", or drop the effect'
        )
    if _given(doc.material, "density_kg_per_m3") and b.mass_kg is not None and b.inertia_kg_m2 is not None:
        v = doc.material.density_kg_per_m3
        raise fail(
            "material.density_kg_per_m3",
            v[0] if v[0] == v[1] else list(v),
            "kg/m^3",
            "not used: bodies.mass_kg and bodies.inertia_kg_m2 are both given (the density only sets the "
            "masses and inertias computed from the blanks); drop one of them",
        )
    for ratio, coeff in (
        ("bearing_damping_ratio", "bearing_damping_N_s_per_m"),
        ("mesh_damping_ratio", "mesh_damping_N_s_per_m"),
    ):
        if getattr(b, ratio) is not None and getattr(b, coeff) is not None:
            v = getattr(b, coeff)
            raise fail(
                f"bodies.{coeff}",
                list(v) if isinstance(v, tuple) else v,
                "N s/m",
                f"give either bodies.{ratio} or bodies.{coeff}, not both",
            )
    sig = doc.output.signals
    if not sig or len(set(sig)) != len(sig):
        raise fail(
            "output.signals", repr(list(sig)), "", f"must name at least one signal, each once (of {', '.join(SIGNALS)})"
        )
    if s.discard_s >= s.duration_s:
        raise fail("solver.discard_s", s.discard_s, "s", f"must be below solver.duration_s = {s.duration_s:g} s")
    method = resolved_method(doc)
    if method == "rk4":
        for key in ("rtol", "atol"):
            if _given(s, key):
                raise fail(
                    f"solver.{key}",
                    getattr(s, key),
                    "",
                    f"only used by dopri5 (the solver is rk4"
                    f"{' by auto: no backlash or bearing clearance' if s.method == 'auto' else ''})",
                )
    elif _given(s, "steps_per_mesh_period"):
        raise fail(
            "solver.steps_per_mesh_period",
            s.steps_per_mesh_period,
            "",
            f"only used by rk4 (the solver is dopri5"
            f"{' by auto: backlash or bearing clearance is modelled' if s.method == 'auto' else ''})",
        )


#: mesh-stiffness sources that run the FE models
FE_SOURCES = tuple(n for n in SCENE_SOURCES if SOURCES[n].fe)
#: the mesh-stiffness sources whose models have a 2D state (fem.plane): the FE ones and the
#: analytic tooth beams (a constant has one only as the analytic mean: dynamics_uses_plane)
PLANE_SOURCES = tuple(n for n in SCENE_SOURCES if SOURCES[n].plane)

#: fem.plane = "auto": plane strain from this face width over module on (the 3D check's crossover of
#: the largest compliance error of plane stress and plane strain, reports/plane)
PLANE_STRAIN_FROM_B_OVER_M = 4.3


def resolved_plane(plane: str, face_width_mm: float, module_mm: float) -> str:
    """The 2D state an FE model runs in: ``plane`` itself, or for "auto" stress below
    b/m = PLANE_STRAIN_FROM_B_OVER_M and strain from there on."""
    if plane != "auto":
        return plane
    return "strain" if face_width_mm / module_mm >= PLANE_STRAIN_FROM_B_OVER_M else "stress"


def fem_plane(doc: SceneDoc | None, runs_fem: bool, what: str) -> str:
    """The 2D idealisation (fem.plane) of the FE models a command runs (the default for a
    scene without a document). ``runs_fem``: whether ``what`` (the command and its options,
    for the message) runs an FE model at all; a fem.plane the scene gives is refused when
    it does not (an ignored option is an error)."""
    if doc is None:
        return "stress"
    if not runs_fem and _given(doc.fem, "plane"):
        raise fail(
            "fem.plane",
            repr(doc.fem.plane),
            "",
            f"not used: {what} runs no model with a 2D state "
            f"(only gearwear stiffness --method fem, ishikawa or energy, verify, calibrate, report pair "
            f"and the dynamics with effects.mesh_stiffness.source = \"analytic\", \"fem\" or "
            f"\"calibrated\" do); drop [fem] plane",
        )
    return resolved_plane(doc.fem.plane, doc.pair.face_width_mm, doc.pair.module_mm)


def dynamics_uses_plane(doc: SceneDoc) -> bool:
    """Whether the dynamics' mesh stiffness comes from a model with a 2D state: an analytic or
    FE source, or a constant without value_N_per_m (the analytic mean)."""
    ms = doc.effects.mesh_stiffness
    if ms is None:
        return True
    return ms.source in PLANE_SOURCES or (ms.source == "constant" and ms.value_N_per_m is None)


def dynamics_fem_plane(doc: SceneDoc) -> str:
    """fem.plane for the dynamic commands (refused where :func:`dynamics_uses_plane` is false)."""
    ms = doc.effects.mesh_stiffness
    src = ms.source if ms is not None else None
    return fem_plane(
        doc,
        dynamics_uses_plane(doc),
        f"the dynamics with effects.mesh_stiffness.source = {src!r}"
        if src is not None
        else "the dynamics without [effects] mesh_stiffness",
    )


def check_wear_table(w: WearDoc) -> None:
    """``[effects] wear``: exactly one of phase, max_depth_um, hours; a model's coefficient
    only with hours and that model."""
    given = [k for k in ("phase", "max_depth_um", "hours") if getattr(w, k) is not None]
    if len(given) != 1:
        raise InputError(
            f"effects.wear: give exactly one of phase, max_depth_um, hours (got {', '.join(given) or 'none'})"
        )
    for key, model in (("archard_k_m2_per_N", "archard"), ("wear_intensity", "paper_eq1")):
        if getattr(w, key) is not None and (w.hours is None or w.model != model):
            raise fail(
                f"effects.wear.{key}",
                getattr(w, key),
                "m^2/N" if key.startswith("archard") else "",
                f"only used with hours and model = {model!r} (a phase or max_depth_um fixes the "
                f"depth, so the coefficient cancels)",
            )


def resolved_method(doc: SceneDoc) -> str:
    """auto -> rk4 for smooth models, dopri5 (event location) with backlash, clearance or
    dynamic centre distance (the same rule as ``gearwear.dynamics.simulate``)."""
    if doc.solver.method != "auto":
        return doc.solver.method
    e = doc.effects
    nonsmooth = (
        e.backlash is not None
        or e.bearing_clearance is not None
        or (e.centre_distance is not None and e.centre_distance.coupling == "dynamic")
    )
    return "dopri5" if nonsmooth else "rk4"


def resolved_dict(doc: SceneDoc) -> dict[str, Any]:
    """The document with every default filled in, absent effects and unset optional keys
    left out, damping ratios resolved: what the run uses."""
    out = doc.model_dump(mode="json", exclude_none=True)
    b = out["bodies"]
    if "mass_kg" in b and "inertia_kg_m2" in b:
        out["material"].pop("density_kg_per_m3", None)  # unused: both are given (cross_check)
    if "bearing_damping_N_s_per_m" not in b:
        b.setdefault("bearing_damping_ratio", DEFAULT_BEARING_DAMPING_RATIO)
    if "mesh_damping_N_s_per_m" not in b:
        b.setdefault("mesh_damping_ratio", DEFAULT_MESH_DAMPING_RATIO)
    ms = out.get("effects", {}).get("mesh_stiffness")
    if ms is not None and (ms.get("source") in ("fem", "table") or "value_N_per_m" in ms):
        ms.pop("points_per_mesh_period", None)  # no analytic table (cross_check)
    if resolved_method(doc) == "rk4":
        out["solver"].pop("rtol", None)
    else:
        out["solver"].pop("steps_per_mesh_period", None)
    return out


DEFAULT_BEARING_DAMPING_RATIO = 0.02
DEFAULT_MESH_DAMPING_RATIO = 0.05
