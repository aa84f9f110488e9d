"""The pair FE meshes the extremes of the geometry it accepts (the slow design-space study's
failures, reduced to quick cases).

Regression class, found by ``make fe-design-space``:

* a rack tip round at its full-round limit leaves a root land of nanometres between the
  fillets of one space (design103: 0.05 um on z 47/150); as an outline vertex it made a
  sliver element (radius ratio 0.0009) and the FE refused the pair;
* a coarse outline edge spanning a tightly curved fillet that gmsh splits (design113: z 22/61,
  m 8.19 mm, rack tip 0.217 m) puts its mid-side nodes at arc-length middles, so the P2 edges
  are other parabolas through the same curve points; the mesh was refused by a fixed 1e-6
  relative area bound (it was off by 1.01e-6), although it is the intended region.

Independent truths: det J > 0 at every element's corners, edge mid-points and centroid
(``inverted_elements``); the P2 mesh's area (quadrature over the elements) equals the gear
section computed from the exact tooth profile (a polygon at 0.1 nm chord sag, minus the bore)
to within the P2 outline's own representation error; the pair FE's contact loads carry the
torque (sum F = T / r_b1)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from skfem import Basis, ElementTriP2, Functional

from gearwear.fem.mesh import inverted_elements
from gearwear.fem.pair import pair_contact, pair_model
from gearwear.geometry.profile import ROOT_LAND, gear_outline, polygon_area, tooth_profile
from gearwear.geometry.spec import PairSpec, check_pair

_AREA = Functional(lambda w: 1.0 + 0.0 * w.x[0])


def _section_error(g, mesh) -> float:
    """Relative difference of the P2 mesh's area from the exact section (m^2)."""
    exact = polygon_area(gear_outline(tooth_profile(g, sag_m=1e-10))) - math.pi * g.hub_radius_m**2
    return abs(_AREA.assemble(Basis(mesh, ElementTriP2())) / exact - 1.0)


def _full_round(teeth, x, alpha_deg) -> PairSpec:
    """A pair cut by a rack whose tip round is the full round (1 - 1e-9 of it)."""
    a = math.radians(alpha_deg)
    rho_max = (0.25 * math.pi - 1.25 * math.tan(a)) * math.cos(a) / (1.0 - math.sin(a))
    p = PairSpec(
        teeth=teeth,
        module_m=2e-3,
        pressure_angle_rad=a,
        face_width_m=16e-3,
        profile_shift=x,
        rack_tip_radius_coefficient=rho_max * (1 - 1e-9),
        hub_radius_m=(10e-3, 12e-3),
    )
    check_pair(p)
    return p


@pytest.mark.parametrize(
    "teeth,x,alpha_deg",
    [((19, 32), (0.25, -0.1), 20.0), ((34, 21), (0.0, 0.3), 23.7)],
    ids=["shifted-unequal", "driver-more-teeth"],
)
def test_a_full_round_root_meshes_and_solves(teeth, x, alpha_deg):
    p = _full_round(teeth, x, alpha_deg)
    for g in p.gears:  # the hard case: the root land is (almost) gone
        prof = tooth_profile(g)
        assert prof.s[np.flatnonzero(prof.region == ROOT_LAND)[-1]] < 1e-3 * p.module_m
    T = 200e3 * p.face_width_m * p.gear(0).base_radius_m
    r = pair_contact(p, positions=2, torque_Nm=T, extended=False)
    assert np.all(np.abs(r.pair_load_N.sum(axis=1) * p.gear(0).base_radius_m / T - 1.0) < 1e-12)
    assert np.all(np.isfinite(r.k_N_per_m)) and np.all(r.k_N_per_m > 0)
    for g, body in zip(p.gears, pair_model(p, torque_Nm=T).bodies):
        assert not np.any(inverted_elements(body.model.mesh))
        assert _section_error(g, body.model.mesh) < 5e-5


def test_split_coarse_fillet_edges_keep_the_region():
    """design113's pinion (z 22, m 8.19 mm, x +0.487, alpha 24.26 deg, rack tip 0.217) with a
    small mate, its bore as large (61.9 mm): the far teeth's 2.5 mm outline edges span most of a 1.8 mm
    fillet round."""
    p = PairSpec(
        teeth=(22, 24),
        module_m=8.19e-3,
        pressure_angle_rad=math.radians(24.26),
        face_width_m=0.1127,
        profile_shift=(0.487, -0.487),
        rack_tip_radius_coefficient=0.217,
        hub_radius_m=(61.9e-3, 62e-3),
    )
    check_pair(p)
    T = 200e3 * p.face_width_m * p.gear(0).base_radius_m
    for g, body in zip(p.gears, pair_model(p, torque_Nm=T).bodies):
        assert not np.any(inverted_elements(body.model.mesh))
        # measured 1.6e-5 on the z 22 / 61 pair: coarse P2 edges on the far teeth's fillets
        assert _section_error(g, body.model.mesh) < 5e-5
