"""The pair FE meshes and solves every design the geometry accepts: at least 200 accepted Sobol designs
(of 256 drawn) over
tooth counts, ratio, module, pressure angle, both profile shifts, bores and rack tip radii.

Not part of ``make test`` (each design builds two gear bodies: about 20 s to 5 min here, an
hour or more in all); run with ``make fe-design-space``. A design the geometry refuses
(check_pair: undercut, interference, pointed tip) or whose contact ratio is below 1 (the FE
cannot load overlapping pairs it does not have) is counted, not meshed. For every accepted
design: both bodies mesh with no folded element and the exact area (fem.mesh's own checks),
and at every solved position the contact loads sum to T / r_b1 (the load sum, to 1e-12) and
the mesh stiffness is finite and positive. Gear tooth counts are kept <= 150 to bound the run
time (a 270-tooth gear alone takes 5 min to mesh and factorise)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import qmc

from gearwear.core.validation import InputError
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import PairSpec, check_pair

N_DESIGNS = 256
pytestmark = pytest.mark.design_space


def design(u) -> PairSpec:
    """One design from a point u in [0, 1)^8."""
    z1 = int(round(12 + 68 * u[0]))
    z2 = min(int(round(z1 * (1 + 3 * u[1]))), 150)
    m = 1e-3 * (1 + 9 * u[2])
    spec = PairSpec(
        teeth=(z1, z2),
        module_m=m,
        pressure_angle_rad=math.radians(14.5 + 10.5 * u[3]),
        face_width_m=m * (3 + 12 * u[6]),
        profile_shift=(-0.5 + 1.5 * u[4], -0.5 + 1.5 * u[5]),
        rack_tip_radius_coefficient=0.2 + 0.18 * u[7],
        hub_radius_m=(1e-9, 1e-9),
    )
    frac = 0.2 + 0.6 * u[6]
    return PairSpec(**{**spec.__dict__, "hub_radius_m": tuple(frac * g.root_radius_m for g in spec.gears)})


def accepted() -> list[tuple[int, PairSpec]]:
    out = []
    for i, u in enumerate(qmc.Sobol(8, scramble=True, seed=2026).random(N_DESIGNS)):
        p = design(u)
        try:
            check_pair(p)
        except InputError:
            continue
        if MeshGeometry(p, p.centre_distance_m).contact_ratio >= 1.0:
            out.append((i, p))
    return out


DESIGNS = accepted()


@pytest.mark.parametrize("index,pair", DESIGNS, ids=[f"design{i}" for i, _ in DESIGNS])
def test_the_pair_fe_meshes_and_solves(index, pair):
    from gearwear.fem.mesh import inverted_elements
    from gearwear.fem.pair import pair_contact, pair_model

    rb1 = pair.gear(0).base_radius_m
    T = 200e3 * pair.face_width_m * rb1  # 200 N/mm line load
    r = pair_contact(pair, positions=4, torque_Nm=T, extended=False)
    F = T / rb1
    assert np.all(np.abs(r.pair_load_N.sum(axis=1) / F - 1.0) < 1e-12)
    assert np.all(np.isfinite(r.k_N_per_m)) and np.all(r.k_N_per_m > 0)
    for body in pair_model(pair, torque_Nm=T).bodies:  # the cached bodies: no second meshing
        assert not np.any(inverted_elements(body.model.mesh))
