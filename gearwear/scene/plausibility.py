"""Warnings for physics that is legal but absurd for a gear: a value the schema accepts
(its ranges bound what can be computed, not what is sensible) but that no gear pair has.

Each check compares a scene's value with what the pair itself implies, so the bounds hold for
any size of gear, and says by how much it is off. A warning never stops a run: it is one
``warning:`` line and an entry in the summaries. The bounds (stated, not fitted):

* Young's modulus 0.5-700 GPa: from soft engineering plastics (POM, PA: 1-3 GPa) to cemented
  carbide (about 600 GPa);
* density 500-20 000 kg/m^3: from plastics and foams to tungsten alloys;
* a given body mass or inertia within a factor of 10 of the blank's own (gearwear.geometry.blank):
  a hub and a shaft add mass, a web removes some, but not a factor of ten;
* a bearing stiffness 1e6-1e11 N/m: from soft rubber mounts to very stiff rolling bearings;
* a constant or user-table mesh stiffness within a factor of 10 of ISO 6336's c_gamma b for the
  pair (whose accuracy is tens of percent, not a factor of ten);
* a line load F_t / b of 0.1-5000 N/mm: below, the load is within the model's round-off; above,
  the teeth of any steel pair would break;
* a pitch-line velocity below 200 m/s (the fastest turbo gears run at about 150 m/s).
"""

from __future__ import annotations

import math
from typing import Any

from gearwear.scene.model import Scene

E_RANGE_GPA = (0.5, 700.0)
DENSITY_RANGE = (500.0, 20000.0)
BODY_FACTOR = 10.0
BEARING_RANGE_N_PER_M = (1e6, 1e11)
STIFFNESS_FACTOR = 10.0
LINE_LOAD_RANGE_N_PER_MM = (0.1, 5000.0)
MAX_PITCH_LINE_SPEED_M_PER_S = 200.0


def _outside(value: float, lo: float, hi: float) -> bool:
    return not lo <= value <= hi


def pair_warnings(scene: Scene) -> list[str]:
    """Materials, load and speed of a scene against what any gear has (every command)."""
    out: list[str] = []
    pair = scene.pair
    for i, m in enumerate(pair.materials):
        name = ("pinion", "gear")[i]
        e = m.youngs_modulus_Pa / 1e9
        if _outside(e, *E_RANGE_GPA):
            out.append(
                f"material.youngs_modulus_GPa = {e:g} GPa for the {name} is outside "
                f"{E_RANGE_GPA[0]:g}-{E_RANGE_GPA[1]:g} GPa, "
                "the range of gear materials from plastics to carbide"
            )
    T = scene.operating.torque_Nm
    if T > 0:
        w = T / pair.gear(0).pitch_radius_m / (pair.face_width_m * 1e3)
        if _outside(w, *LINE_LOAD_RANGE_N_PER_MM):
            out.append(
                f"operating.torque_Nm = {T:g} N m is a line load of {w:.3g} N/mm on the face, outside "
                f"{LINE_LOAD_RANGE_N_PER_MM[0]:g}-{LINE_LOAD_RANGE_N_PER_MM[1]:g} N/mm (below: lost in "
                "round-off; above: the teeth of any steel pair would break)"
            )
    v = scene.operating.speed_rpm * 2 * math.pi / 60 * pair.gear(0).pitch_radius_m
    if v > MAX_PITCH_LINE_SPEED_M_PER_S:
        out.append(
            f"operating.speed_rpm = {scene.operating.speed_rpm:g} rpm is a pitch-line velocity of {v:.4g} "
            f"m/s, above the {MAX_PITCH_LINE_SPEED_M_PER_S:g} m/s of the fastest turbo gears"
        )
    return out


def body_warnings(scene: Scene) -> list[str]:
    """Densities, given masses and inertias, bearing stiffness (the commands that use bodies)."""
    from gearwear.geometry.blank import body_properties

    out: list[str] = []
    pair, b = scene.pair, scene.bodies
    for i, g in enumerate(pair.gears):
        name = ("pinion", "gear")[i]
        rho = g.material.density_kg_per_m3
        if b.mass_from == "blank" and _outside(rho, *DENSITY_RANGE):
            out.append(
                f"material.density_kg_per_m3 = {rho:g} kg/m^3 for the {name} is outside "
                f"{DENSITY_RANGE[0]:g}-{DENSITY_RANGE[1]:g} kg/m^3 (plastics to tungsten)"
            )
        blank = body_properties(g, pair.face_width_m)
        for key, value, own, unit in (
            ("mass_kg", b.mass_kg[i], blank.mass_kg, "kg"),
            ("inertia_kg_m2", b.inertia_kg_m2[i], blank.inertia_kg_m2, "kg m^2"),
        ):
            from_scene = (b.mass_from if key == "mass_kg" else b.inertia_from) == "scene"
            if from_scene and _outside(value / own, 1.0 / BODY_FACTOR, BODY_FACTOR):
                out.append(
                    f"bodies.{key} = {value:g} {unit} for the {name} is {value / own:.3g} times its blank's "
                    f"({own:.4g} {unit}: its section over the face width at its density): more than a factor "
                    f"of {BODY_FACTOR:g} from the body the geometry describes"
                )
    k_b = b.bearing_stiffness_N_per_m
    if k_b is not None and _outside(k_b, *BEARING_RANGE_N_PER_M):
        out.append(
            f"bodies.bearing_stiffness_N_per_m = {k_b:g} N/m is outside {BEARING_RANGE_N_PER_M[0]:g}-"
            f"{BEARING_RANGE_N_PER_M[1]:g} N/m, the range of gear bearings"
        )
    return out


def stiffness_warnings(scene: Scene, mean_N_per_m: float) -> list[str]:
    """A constant or user-table mesh stiffness against ISO 6336's estimate for the pair."""
    from gearwear.analytic.iso6336 import iso6336_stiffness

    ms = scene.effects.get("mesh_stiffness", {})
    source = ms.get("source", "constant")
    given = source == "table" or (source == "constant" and "value_N_per_m" in ms)
    if not given or not mean_N_per_m > 0:
        return []
    try:
        iso = iso6336_stiffness(scene.pair).mesh_stiffness_N_per_m
    except Exception:  # ISO needs a contact ratio >= 1: no reference, no warning
        return []
    ratio = mean_N_per_m / iso
    if _outside(ratio, 1.0 / STIFFNESS_FACTOR, STIFFNESS_FACTOR):
        what = "the user table's mean" if source == "table" else "effects.mesh_stiffness.value_N_per_m"
        return [
            f"{what} ({mean_N_per_m:.4g} N/m) is {ratio:.3g} times ISO 6336's mesh stiffness of this pair "
            f"({iso:.4g} N/m): more than a factor of {STIFFNESS_FACTOR:g} from any steel tooth pair of this size"
        ]
    return []


def response_warnings(result: Any) -> list[str]:
    """A response with no tooth contact at all (the teeth never touch in the kept window)."""
    if result.separation_fraction is not None and result.separation_fraction >= 1.0:
        return [
            "the teeth never touch in the kept window (separation 100 % of the time): the mesh carries no load; "
            "check the backlash, the torque and the speed"
        ]
    return []
