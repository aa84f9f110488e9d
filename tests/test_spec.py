"""Spec parsing: every bad input is one clear line naming key, value, unit and range."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gearwear.core.validation import InputError
from gearwear.geometry.spec import default_pair

from scenes import paper_pair_from


def test_default_is_paper_pair():
    p = default_pair()
    assert p.teeth == (30, 30) and p.module_m == 5e-3
    assert p.pressure_angle_rad == math.radians(20)
    assert p.centre_distance_m == pytest.approx(0.150, rel=1e-15)
    assert all(m.youngs_modulus_Pa == 206e9 and m.poisson_ratio == 0.3 for m in p.materials)


@pytest.mark.parametrize(
    "table,key,value,pattern",
    [
        ("pair", "module_mm", -5, r"pair.module_mm = -5 mm: must be in \[0.05, 100\] mm"),
        ("pair", "pressure_angle_deg", 0, r"pair.pressure_angle_deg = 0 deg: must be in \[10, 35\] deg"),
        ("pair", "pressure_angle_deg", 45, r"pair.pressure_angle_deg = 45 deg: must be in \[10, 35\] deg"),
        ("pair", "teeth", [4, 30], r"pair.teeth\[0\] = 4: must be in \[5, 1000\]"),
        ("pair", "teeth", 3.5, r"pair.teeth = 3.5: must be a whole number"),
        ("pair", "face_width_mm", "wide", r"pair.face_width_mm = 'wide': must be a number"),
        ("material", "poisson_ratio", 0.5, r"material.poisson_ratio = 0.5: must be in \[0, 0.5\)"),
        ("pair", "hub_radius_mm", 70, r"pair.hub_radius_mm\[0\] = 70 mm: must be in \(0, 68.75\) mm"),
        ("pair", "dedendum_coefficient", 0.9, r"pair.dedendum_coefficient = 0.9: must exceed"),
    ],
)
def test_bad_values(table, key, value, pattern):
    with pytest.raises(InputError, match=pattern) as err:
        paper_pair_from({table: {key: value}})
    assert "\n" not in str(err.value)


def test_unknown_keys_suggest_nearest():
    with pytest.raises(InputError, match="pair.modul_mm: unknown key; did you mean pair.module_mm"):
        paper_pair_from({"pair": {"modul_mm": 5}})
    with pytest.raises(InputError, match="materail: unknown key; did you mean material"):
        paper_pair_from({"materail": {}})


@given(st.floats(allow_nan=True, allow_infinity=True) | st.integers(-(10**6), 10**6))
def test_module_validation_never_passes_garbage(v):
    try:
        p = paper_pair_from({"pair": {"module_mm": v, "hub_radius_mm": 1e-3}})
    except InputError as e:
        assert str(e).startswith("pair.")
        return
    assert 0 < p.module_m <= 0.1 and math.isfinite(p.module_m)
