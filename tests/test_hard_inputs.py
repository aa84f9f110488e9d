"""Inputs that used to crash or pass silently, and now hold the promise.

Each test is one example from the audit of issue 12 that is not a plain bad input
(those are rows of tests/test_bad_inputs.py): a valid but unusual pair whose outputs
were NaN or a traceback, and plausible extremes that must be stated in the output.
JSON is parsed strictly (RFC 8259 has no NaN or Infinity).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gearwear.cli import main

ROOT = Path(__file__).resolve().parents[1]

# contact ratio 2.91: no single-contact zone at all
HIGH_CR = [
    "--set",
    "pair.teeth=[60,60]",
    "--set",
    "pair.pressure_angle_deg=14.5",
    "--set",
    "pair.addendum_coefficient=1.4",
    "--set",
    "pair.dedendum_coefficient=1.7",
    "--set",
    "pair.rack_tip_radius_coefficient=0.1",
    "--set",
    "pair.allow_undercut=true",
]


def strict(text: str):
    def refuse(token):
        raise ValueError(f"not JSON: {token}")

    return json.loads(text, parse_constant=refuse)


def run_json(argv, capsys):
    rc = main(argv)
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    return strict(cap.out)


def _fem_summary_coarse():
    """The pair FE curve of the HIGH_CR pair at twice the element sizes (the two 60-tooth
    bodies at the default level take 30 s; the zone bookkeeping under test is the same),
    through the summary and strict JSON the CLI prints."""
    from gearwear import io
    from gearwear.jobs.stiffness import Curve, fem_curve
    from gearwear.scene.files import builtin_scene_dict
    from gearwear.scene.model import scene_from_dict
    from gearwear.scene.overrides import apply_overrides

    sets = [HIGH_CR[i + 1] for i in range(0, len(HIGH_CR), 2)]
    pair = scene_from_dict(apply_overrides(builtin_scene_dict("paper-default"), sets)).pair
    r = fem_curve(pair, 8, 40.0, 0.0, None, mesh_scale=2.0, contact_scale=2.0, extended=False)
    return strict(io.json_text(Curve("fem", "fem", None, 0.0, r).summary()))


@pytest.mark.parametrize("method", ["ishikawa", "fem"])
def test_stiffness_json_above_contact_ratio_two(method, capsys):
    if method == "fem":
        s = _fem_summary_coarse()
    else:
        s = run_json(["stiffness", *HIGH_CR, "--method", method, "--points", "360", "--json"], capsys)
    # the textbook contact ratio of this pair, worked out in test_kinematics_operating's way:
    # eps = (sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin(alpha)) / p_b
    import math

    a, m, z = math.radians(14.5), 5e-3, 60
    r, rb = m * z / 2, m * z / 2 * math.cos(a)
    ra = r + 1.4 * m
    eps = (2 * math.sqrt(ra**2 - rb**2) - 2 * r * math.sin(a)) / (math.pi * m * math.cos(a))
    assert s["contact_ratio"] == pytest.approx(eps, rel=1e-9)
    assert s["single_zone_mean_N_per_m"] is None and s["zone_means_N_per_m"]["1"] is None
    assert s["zone_lengths_deg"]["1"] == 0.0
    assert s["zone_lengths_deg"]["2"] + s["zone_lengths_deg"]["3"] == pytest.approx(6.0, rel=1e-9)  # 360/60
    assert s["min_N_per_m"] > 0


def test_verify_json_above_contact_ratio_two(capsys):
    s = run_json(["verify", *HIGH_CR, "--wear", "unworn", "--positions", "5", "--no-convergence", "--json"], capsys)
    assert set(s["phases"]) == {"unworn"}


def test_committed_reports_are_strict_json():
    files = sorted(ROOT.glob("reports/**/*.json"))
    assert len(files) > 10
    for f in files:
        strict(f.read_text())


def test_contact_ratio_below_one_is_stated(capsys):
    # 4 mm of bearing clearance moves the centres apart: eps = 0.918 on the paper pair
    s = run_json(["geometry", "--no-mesh", "--clearance-um", "4000", "--json"], capsys)
    assert s["contact_ratio"] < 1
    assert any(f"contact ratio {s['contact_ratio']:.3f} < 1" in w for w in s["warnings"])
    main(["geometry", "--no-mesh", "--clearance-um", "4000"])
    assert f"warning: contact ratio {s['contact_ratio']:.3f} < 1" in capsys.readouterr().out


def test_running_hours_beyond_severe_are_flagged(capsys):
    s = run_json(["stiffness", "--wear", "500h", "--json"], capsys)
    assert any("beyond the 'severe' phase" in w for w in s["warnings"])
    s = run_json(["stiffness", "--wear", "severe", "--json"], capsys)
    assert s["warnings"] == []
