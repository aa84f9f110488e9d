"""The stated range of every numeric scene key is exactly the enforced one.

For each key the JSON Schema publishes with a range (``gearwear scene --schema``), the
nearest representable value outside each finite bound (the bound itself when the bound is
open) must be refused, in one line that names the key, the value and that same published
range. The keys and bounds are read from the schema, so a key added later is covered.
"""

from __future__ import annotations

import math

import pytest

from gearwear.core.validation import InputError
from gearwear.scene.model import scene_from_dict
from gearwear.scene.reference import json_schema

from scenes import paper_doc


def _ranged_keys():
    schema = json_schema()
    defs = schema["$defs"]

    def walk(node, path):
        if "$ref" in node:
            node = defs[node["$ref"].split("/")[-1]]
        for option in node.get("anyOf", []):
            yield from walk(option, path)
        for key, prop in node.get("properties", {}).items():
            if "range" in prop:
                yield ".".join(path + [key]), prop
            else:
                yield from walk(prop, path + [key])

    return sorted(dict(walk(schema, [])).items())


def _bounds(prop):
    """(lower, lower_open, upper, upper_open, integer) from the schema's keywords; per-gear keys
    keep them on their items."""
    if "anyOf" in prop:
        item = next(o for o in prop["anyOf"] if o.get("type") in ("number", "integer"))
    else:
        item = prop
    lo, lo_open = (item["exclusiveMinimum"], True) if "exclusiveMinimum" in item else (item.get("minimum"), False)
    hi, hi_open = (item["exclusiveMaximum"], True) if "exclusiveMaximum" in item else (item.get("maximum"), False)
    return lo, lo_open, hi, hi_open, item.get("type") == "integer"


def _outside(bound, is_open, integer, direction):
    if is_open:
        return bound
    if integer:
        return bound + direction
    return math.nextafter(float(bound), direction * math.inf)


#: valid siblings for tables with required keys (only the key under test is changed)
REQUIRED = {
    "faults.crack": {"depth_mm": 1.0},
    "faults.spall": {"start_diameter_mm": 150.0, "length_mm": 0.5, "depth_um": 20.0},
    "flank.tip_relief": {"amount_um": 10.0, "start_diameter_mm": 155.0},
    "flank.root_relief": {"amount_um": 10.0, "start_diameter_mm": 148.0},
    "blank.pinion": {"web_thickness_mm": 10.0, "rim_thickness_mm": 10.0, "hub_outer_radius_mm": 50.0},
    "blank.gear": {"web_thickness_mm": 10.0, "rim_thickness_mm": 10.0, "hub_outer_radius_mm": 50.0},
}


def _doc_with(key, value):
    """The paper scene (a complete document: a scene must name its pair and operating point)
    with ``key`` set to ``value``."""
    doc = paper_doc()
    node = doc
    parts = key.split(".")
    for i, p in enumerate(parts[:-1]):
        node = node.setdefault(p, dict(REQUIRED.get(".".join(parts[: i + 1]), {})))
    node[parts[-1]] = value
    return doc


CASES = []
for key, prop in _ranged_keys():
    lo, lo_open, hi, hi_open, integer = _bounds(prop)
    for bound, is_open, direction in ((lo, lo_open, -1), (hi, hi_open, +1)):
        if bound is not None:
            CASES.append((key, prop, _outside(bound, is_open, integer, direction)))


def test_every_ranged_key_is_covered():
    keys = {c[0] for c in CASES}
    assert len(keys) >= 30
    assert {"pair.module_mm", "operating.torque_Nm", "pair.teeth", "solver.duration_s"} <= keys


@pytest.mark.parametrize("key,prop,value", CASES, ids=[f"{c[0]}={c[2]!r}" for c in CASES])
def test_just_outside_the_published_range_is_refused_with_that_range(key, prop, value):
    if prop.get("per_gear"):  # the pinion out of range, the gear at its default (or the same value)
        value = [value, prop["default"][1] if prop.get("default") else value]
    with pytest.raises(InputError) as exc:
        scene_from_dict(_doc_with(key, value))
    msg = str(exc.value)
    assert "\n" not in msg
    assert msg.startswith(key + ("[0]" if prop.get("per_gear") else "")), msg
    assert prop["range"] in msg, msg


def _inside(bound, is_open, integer, direction):
    """The extreme accepted value at a bound: the bound itself when closed, else the nearest
    representable value inside it (5e-324 above an open zero)."""
    if not is_open:
        return bound
    if integer:
        return bound - direction
    return math.nextafter(float(bound), -direction * math.inf)


EDGE_CASES = []
for key, prop in _ranged_keys():
    lo, lo_open, hi, hi_open, integer = _bounds(prop)
    for bound, is_open, direction in ((lo, lo_open, -1), (hi, hi_open, +1)):
        if bound is not None:
            EDGE_CASES.append((key, prop, _inside(bound, is_open, integer, direction)))


@pytest.mark.parametrize("key,prop,value", EDGE_CASES, ids=[f"{c[0]}={c[2]!r}" for c in EDGE_CASES])
def test_the_extreme_accepted_value_builds_a_scene_or_is_refused_in_one_line(key, prop, value):
    """Regression class: module_mm = 5e-324 passed the schema and divided by zero in the pair
    geometry. At each edge of a published range the scene (pair geometry, wear limits, solver
    settings) is either built with finite derived quantities or refused as bad input."""
    try:
        scene = scene_from_dict(_doc_with(key, [value, value] if prop.get("per_gear") else value))
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    pair = scene.pair
    for q in (pair.centre_distance_m, pair.tip_alteration_coefficient, pair.working_pressure_angle_rad):
        assert math.isfinite(q)
    for g in pair.gears:
        assert 0 < g.base_radius_m < g.tip_radius_m and math.isfinite(g.tip_radius_m)
