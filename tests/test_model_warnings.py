"""The notes on a pair outside an analytic model's own assumptions (analytic.model_warnings):
the clamp height of the base-clamped models and the fit range of Sainsot's foundation.

Independent truths: the root and base radii by hand from ISO 21771 (r_f = m (z/2 + x - h_f*),
r_b = m z cos(alpha) / 2), Sainsot's h_fi = r_f / r_bore and theta_f = S_f / (2 r_f) from the
clamped section's thickness computed here (the base chord 2 r_b sin alpha_2 with alpha_2
from the reference-circle arc thickness), and the fit range as Sainsot et al. published
it (h_fi 1.4-7, theta_f 0.01-0.12 rad). Pairs: the unequal shifted 23/47, its driver-larger
twin, a 30/90 wheel whose root circle is well above its base circle, and random valid
pairs (hypothesis).
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import pytest
from hypothesis import given, settings

from gearwear.analytic.model_warnings import CLAMP_TOLERANCE_MODULE, assumption_warnings
from gearwear.cli import main
from gearwear.geometry.spec import GearSpec

from pairs import DRIVER_LARGER, UNEQUAL, checked, valid_pairs

BASE_CLAMPED = ("yang_lin", "tian", "wu_zuo_parey")
ROOT_CLAMPED = ("chen_shao", "chen_shao_weber", "energy", "ishikawa", "kuang_yang")


def _radii(g: GearSpec) -> tuple[float, float]:
    """(r_f, r_b) (m) by hand (ISO 21771, the gear's own dedendum coefficient)."""
    m, z, x = g.module_m, g.teeth, g.profile_shift
    return m * (z / 2 + x - g.dedendum_coefficient), m * z * math.cos(g.pressure_angle_rad) / 2


def _clamp_gap_mm(g: GearSpec) -> float:
    rf, rb = _radii(g)
    return (rf - rb) * 1e3


WHEEL = checked(
    teeth=(30, 90), module_m=3e-3, profile_shift=(0.0, 0.0), face_width_m=30e-3, hub_radius_m=(20e-3, 60e-3)
)


def test_the_unequal_pair_notes_only_the_pinions_missing_material():
    """23/47, m 3: the pinion's base circle lies 1.069 mm above its root circle (> 0.25 m =
    0.75 mm), the gear's root circle 0.20 mm above its base circle (< 0.75 mm): tian notes
    the pinion only, with the height by hand; the root-clamped models note nothing (both
    gears inside Sainsot's fit range)."""
    p, g = UNEQUAL.gear(0), UNEQUAL.gear(1)
    assert _clamp_gap_mm(p) == pytest.approx(3 * (11.5 + 0.2 - 1.25) - 34.5 * math.cos(math.radians(20)), rel=1e-12)
    assert 0 < _clamp_gap_mm(g) < CLAMP_TOLERANCE_MODULE * 3.0
    notes = assumption_warnings("tian", UNEQUAL)
    assert len(notes) == 1 and notes[0].startswith("pinion:")
    assert f"{-_clamp_gap_mm(p):.3g} mm above the root circle" in notes[0]
    for m in ROOT_CLAMPED:
        assert assumption_warnings(m, UNEQUAL) == [], m


def test_the_driver_larger_twin_names_the_same_gear_by_its_role():
    """47/23: the same 23-tooth gear, now index 1 ("gear"), gets the same note."""
    notes = assumption_warnings("yang_lin", DRIVER_LARGER)
    assert len(notes) == 1 and notes[0].startswith("gear:")
    assert (
        notes[0].replace("gear:", "pinion:", 1).replace("yang_lin", "tian") == assumption_warnings("tian", UNEQUAL)[0]
    )


def test_a_wheel_whose_root_circle_is_above_its_base_circle_gets_the_neck_note():
    """z = 90, m 3, 20 deg: r_f - r_b = 3 (45 - 1.25) - 135 cos 20 deg = 4.39 mm, counted as an
    involute neck by every base-clamped model; the 30-tooth pinion (r_b - r_f = 1.04 mm) gets
    the missing-material note."""
    gap = _clamp_gap_mm(WHEEL.gear(1))
    assert gap == pytest.approx(3 * 43.75 - 135 * math.cos(math.radians(20)), rel=1e-12)
    for m in BASE_CLAMPED:
        notes = assumption_warnings(m, WHEEL)
        neck = [n for n in notes if n.startswith("gear:") and "neck" in n]
        assert len(neck) == 1 and f"{gap:.3g} mm above the base circle" in neck[0]
        assert any(n.startswith("pinion:") and "not in the model" in n for n in notes)


def test_a_base_circle_inside_the_bore_is_named():
    """The 90-tooth wheel with its bore between the base circle (126.86 mm) and the root
    circle (131.25 mm): the base-clamped models say their clamped section is in the hole."""
    rf, rb = _radii(WHEEL.gear(1))
    bore = 0.5 * (rf + rb)
    pair = dataclasses.replace(WHEEL, hub_radius_m=(20e-3, bore))
    notes = assumption_warnings("tian", pair)
    assert any("inside the bore" in n and f"{rb * 1e3:.4g} mm" in n for n in notes)
    assert not any("inside the bore" in n for n in assumption_warnings("tian", WHEEL))


@pytest.mark.parametrize("bore_mm", [60.0, 80.0, 100.0, 120.0])
def test_sainsots_range_is_flagged_where_h_fi_leaves_it(bore_mm):
    """The 90-tooth gear of WHEEL (r_f = 131.25 mm by hand) on bores of 60-120 mm: h_fi =
    r_f / r_bore = 2.19, 1.64, 1.31, 1.09; chen_shao and energy flag the gear exactly where
    h_fi < 1.4 (theta_f stays inside its range), with h_fi by hand; the pinion (20 mm
    bore, h_fi 2.06) never."""
    rf = _radii(WHEEL.gear(1))[0]
    bore = bore_mm * 1e-3
    pair = dataclasses.replace(WHEEL, hub_radius_m=(20e-3, bore))
    for m in ("chen_shao", "energy"):
        notes = [n for n in assumption_warnings(m, pair) if "Sainsot" in n]
        assert len(notes) == (1 if rf / bore < 1.4 else 0), (m, rf / bore)
        if notes:
            assert notes[0].startswith("gear:") and f"h_fi = r_f / r_bore = {rf / bore:.3g}" in notes[0]


def test_wu_zuo_parey_evaluates_sainsot_at_the_base_chord():
    """wu_zuo_parey's theta_f is the base chord over 2 r_b = sin(alpha_2), alpha_2 by hand
    from the arc thickness m (pi/2 + 2 x tan alpha) at the reference circle: on a bore
    that puts h_fi = r_b / r_bore = 1.2 (out of range) the note carries both values."""
    g = WHEEL.gear(1)
    rb = _radii(g)[1]
    pair = dataclasses.replace(WHEEL, hub_radius_m=(20e-3, rb / 1.2))
    a = g.pressure_angle_rad
    a2 = (0.5 * math.pi + 2 * g.profile_shift * math.tan(a)) / g.teeth + math.tan(a) - a
    notes = [n for n in assumption_warnings("wu_zuo_parey", pair) if "Sainsot" in n]
    assert len(notes) == 1
    assert f"h_fi = r_f / r_bore = {1.2:.3g} and theta_f = {math.sin(a2):.3g} rad" in notes[0]


@settings(max_examples=40, deadline=None)
@given(p=valid_pairs(max_shift=0.5))
def test_any_pair_clamp_notes_follow_the_hand_radii(p):
    """For any valid pair: a base-clamped model notes a gear's clamp exactly when
    |r_f - r_b| (by hand) exceeds 0.25 m, in the direction of the sign; a root-clamped model
    never notes a clamp."""
    for m in BASE_CLAMPED:
        notes = assumption_warnings(m, p)
        for g in p.gears:
            gap = _clamp_gap_mm(g) / (g.module_m * 1e3)
            mine = [n for n in notes if n.startswith(f"{g.name}:") and "clamps the tooth" in n]
            if abs(gap) <= CLAMP_TOLERANCE_MODULE - 1e-9:
                assert mine == []
            elif abs(gap) > CLAMP_TOLERANCE_MODULE + 1e-9:
                assert len(mine) == 1 and (("neck" in mine[0]) == (gap > 0))
    for m in ROOT_CLAMPED:
        assert not any("clamps the tooth" in n for n in assumption_warnings(m, p))


def test_the_stiffness_command_prints_and_returns_the_notes(capsys, tmp_path):
    """`gearwear stiffness --json` carries the notes in each curve's warnings; the text
    output prints them as warning lines."""
    scene = tmp_path / "wheel.toml"
    scene.write_text(
        "[pair]\nteeth = [30, 90]\nmodule_mm = 3\nface_width_mm = 30\nprofile_shift = [0.0, 0.0]\n"
        "hub_radius_mm = [20, 60]\n\n[operating]\ntorque_Nm = 200\nspeed_rpm = 1000\n"
    )
    assert main(["stiffness", str(scene), "--method", "tian", "chen_shao", "--points", "16", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    by = {c["method"]: c["warnings"] for c in doc["curves"]}
    assert any("neck" in w for w in by["tian"]) and not any("clamps the tooth" in w for w in by["chen_shao"])
    out = tmp_path / "out"
    assert main(["stiffness", str(scene), "--method", "tian", "--points", "16", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "warning: gear: the root circle lies" in text
    assert Path(out / "manifest.json").exists()
