"""The stiffness-source registry (gearwear.stiffness.sources.SOURCES) is the one list of where a
mesh stiffness comes from: the command line, the API, the scene schema and the docs agree
with it, and every source returns the one curve type with the same contract.

Pairs: the unequal shifted 23/47 and the same gears with the larger one driving (tests/pairs.py).
"""

from __future__ import annotations

import dataclasses
import math
import re
import typing

import numpy as np
import pytest

import gearwear as gw
from gearwear.analytic.tvms import MeshStiffness, mesh_stiffness
from gearwear.cli import build_parser, main
from gearwear.core.validation import InputError
from gearwear.geometry.operating import operating_geometry
from gearwear.scene.reference import json_schema
from gearwear.scene.schema import MeshStiffnessDoc
from gearwear.stiffness.sources import METHODS, SCENE_SOURCES, SOURCES, Request, curve

from pairs import DRIVER_LARGER, UNEQUAL

PAIRS = {"unequal_23_47": UNEQUAL, "driver_larger_47_23": DRIVER_LARGER}
TORQUE_NM = 120.0


# -- one list, read by every front ------------------------------------------------------------------


def test_methods_and_scene_sources_are_the_registry():
    assert METHODS == tuple(n for n, s in SOURCES.items() if s.command)
    assert SCENE_SOURCES == tuple(n for n, s in SOURCES.items() if s.scene)
    assert gw.METHODS == METHODS


def test_the_schema_takes_exactly_the_scene_sources():
    assert typing.get_args(MeshStiffnessDoc.model_fields["source"].annotation) == SCENE_SOURCES
    schema = json_schema()
    ms = schema["$defs"]["MeshStiffnessDoc"]["properties"]["source"]
    assert tuple(ms["enum"]) == SCENE_SOURCES


def test_the_command_line_offers_every_method_and_refuses_others(capsys):
    stiffness = next(
        a
        for a in build_parser()._subparsers._group_actions[0].choices["stiffness"]._actions
        if "--method" in a.option_strings
    )
    for m in METHODS:
        assert f"{m}: {SOURCES[m].title}" in stiffness.help
    assert main(["stiffness", "--method", "nosuch", "--points", "16"]) == 2
    assert f"must be one or more of {', '.join(METHODS)}" in capsys.readouterr().err


def test_the_api_refuses_a_name_outside_the_registry():
    with pytest.raises(InputError, match=f"must be one of {', '.join(METHODS)}"):
        gw.mesh_stiffness(method="nosuch")


def test_a_method_that_cannot_show_a_flank_or_a_fault_is_refused_by_its_flags():
    """Each flag on its own: a flank deviation is refused by a method without ``flank``, a
    fault by one without ``faults`` (a method may show the one and not the other)."""
    from gearwear.geometry.faults import FaultSpec, Spall
    from gearwear.geometry.flank import FlankSpec
    from gearwear.jobs.stiffness import check_method

    given = {"flank": (FlankSpec(), None), "faults": (None, FaultSpec(spall=Spall(0, 0, 150e-3, 1e-3, 20e-6)))}
    for m in METHODS:
        for flag, (flank, faults) in given.items():
            if getattr(SOURCES[m], flag):
                check_method(m, flank, faults)
            else:
                with pytest.raises(InputError, match=re.escape(f"method = '{m}': is {SOURCES[m].title}")):
                    check_method(m, flank, faults)


# -- one curve type, one contract ---------------------------------------------------------------------


def _contract(r: MeshStiffness, pair) -> None:
    """What every source's curve satisfies, whatever the model: angles increasing within its span,
    a finite positive k_h, a finite excitation, arrays of one length."""
    assert isinstance(r, MeshStiffness)
    n = len(r.angle_rad)
    assert n >= 8 and np.all(np.diff(r.angle_rad) > 0)
    assert r.angle_rad[0] >= 0 and r.angle_rad[-1] < r.span_rad
    assert math.isclose(r.span_rad, r.periods * 2 * math.pi / pair.teeth[0], rel_tol=1e-12)
    assert np.all(np.isfinite(r.k_N_per_m)) and np.all(r.k_N_per_m > 0)
    assert r.excitation_m.shape == (n,) and np.all(np.isfinite(r.excitation_m))
    assert r.ste_m.shape == (n,) and r.pair_load_N.shape[0] == n


CHEAP = [n for n, s in SOURCES.items() if not s.fe and n != "table"]


@pytest.mark.parametrize("name", CHEAP)
@pytest.mark.parametrize("pair_id", PAIRS)
def test_every_cheap_source_meets_the_contract(name, pair_id):
    pair = PAIRS[pair_id]
    if name == "corrected":  # fitted on rims of 1.5-12 m (the test pairs' larger gear has 13.8 m)
        pair = _with_rims(pair, 6.0)
    _contract(curve(name, Request(pair, TORQUE_NM, points=48)), pair)


def _with_rims(pair, rim_modules: float):
    """``pair`` with both bores moved so that r_f - bore = rim_modules m on each gear."""
    m = pair.module_m
    return dataclasses.replace(pair, hub_radius_m=tuple(g.root_radius_m - rim_modules * m for g in pair.gears))


@pytest.mark.parametrize("pair_id", PAIRS)
def test_the_loads_of_a_load_sharing_source_carry_the_torque(pair_id):
    """Equilibrium (independent of the compliance model): at every angle the pair loads sum to
    F = T / r_b1 (r_b1 the driver's base radius, m)."""
    pair = PAIRS[pair_id]
    F = TORQUE_NM / pair.gear(0).base_radius_m
    for name in ("ishikawa", "energy", "iso6336", "analytic"):
        r = curve(name, Request(pair, TORQUE_NM, points=48))
        np.testing.assert_allclose(r.pair_load_N.sum(axis=1), F, rtol=1e-9)


def test_the_scene_analytic_source_is_ishikawa():
    rq = Request(UNEQUAL, TORQUE_NM, points=48, plane="strain")
    a, i = curve("analytic", rq), curve("ishikawa", rq)
    np.testing.assert_array_equal(a.k_N_per_m, i.k_N_per_m)
    np.testing.assert_array_equal(a.angle_rad, i.angle_rad)


def test_a_constant_is_the_value_or_the_analytic_mean():
    rq = Request(DRIVER_LARGER, TORQUE_NM, points=48)
    mean = mesh_stiffness(DRIVER_LARGER, points=48, torque_Nm=TORQUE_NM).mean_N_per_m
    assert np.all(curve("constant", rq).k_N_per_m == mean)
    given = Request(DRIVER_LARGER, TORQUE_NM, points=48, options={"value_N_per_m": 3.5e8})
    assert np.all(curve("constant", given).k_N_per_m == 3.5e8)


def test_iso6336_is_c_gamma_alpha_times_the_face_width():
    """ISO 6336-1 method B: k = c_gamma_alpha b with c_gamma_alpha = c' (0.75 eps_alpha + 0.25)
    (eq. 33-34; the operating contact ratio), constant over the angle."""
    from gearwear.analytic.iso6336 import iso6336_stiffness

    eps = operating_geometry(UNEQUAL, 0.0).contact_ratio
    iso = iso6336_stiffness(UNEQUAL, torque_Nm=TORQUE_NM, contact_ratio=eps)
    r = curve("iso6336", Request(UNEQUAL, TORQUE_NM, points=16))
    c_gamma = iso.c_prime * (0.75 * eps + 0.25)
    np.testing.assert_allclose(r.k_N_per_m, c_gamma * 1e6 * UNEQUAL.face_width_m * 1e3, rtol=1e-9)


def test_a_user_table_comes_back_as_given_and_claims_no_loads():
    phi = np.linspace(0, 2 * math.pi / UNEQUAL.teeth[0], 40, endpoint=False)
    k = 4e8 + 1e8 * np.cos(UNEQUAL.teeth[0] * phi)
    r = curve("table", Request(UNEQUAL, TORQUE_NM, options={"angle_rad": phi, "k_N_per_m": k, "excitation_m": None}))
    _contract(r, UNEQUAL)
    np.testing.assert_array_equal(r.k_N_per_m, k)
    assert np.all(r.excitation_m == 0) and r.pair_load_N.shape == (40, 0)
    assert np.all(np.isnan(r.ste_m))  # a table has no loaded STE: said, not made up


@pytest.mark.slow
def test_the_fem_source_meets_the_contract():
    pair = DRIVER_LARGER
    r = curve("fem", Request(pair, TORQUE_NM, points=8, options={"mesh_scale": 2.0}))
    _contract(r, pair)
    np.testing.assert_allclose(r.pair_load_N.sum(axis=1), TORQUE_NM / pair.gear(0).base_radius_m, rtol=1e-9)
