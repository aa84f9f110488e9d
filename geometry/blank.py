"""Mass and polar moment of inertia of a gear body from its own blank.

The body is the generated transverse section (every tooth with its rack-cut fillet,
``geometry.profile.gear_outline``) minus the bore, extruded over the face width b, of
the gear's own density rho. For a webbed blank (``geometry.spec.Web``) the section is
split into three annuli-like parts of different axial thickness:

    rim   r_i <= r (to the teeth)   thickness b      r_i = r_f - s_R
    web   r_h <= r <= r_i           thickness b_s
    hub   r_bore <= r <= r_h        thickness b

so that

    m = rho [b (A_outline - pi r_i^2) + b_s pi (r_i^2 - r_h^2) + b pi (r_h^2 - r_bore^2)]
    J = rho [b (I_outline - pi r_i^4 / 2) + b_s pi (r_i^4 - r_h^4) / 2 + b pi (r_h^4 - r_bore^4) / 2]

(a solid blank is the case b_s = b). A_outline and the polar second moment of area
I_outline = int (x^2 + y^2) dA of the closed outline polygon follow from Green's theorem
over its edges (exact for the polygon; the outline is sampled to 0.2 um sag):

    A = 1/2 sum (x_i y_{i+1} - x_{i+1} y_i)
    I = 1/12 sum (x_i y_{i+1} - x_{i+1} y_i) (x_i^2 + x_i x_{i+1} + x_{i+1}^2 + y_i^2 + y_i y_{i+1} + y_{i+1}^2)

Units: m, m^2, m^4, kg, kg m^2. Assumptions: the hub has the face width; shaft, keys,
bolt holes and lightening holes are not part of the body (give ``bodies.mass_kg`` and
``bodies.inertia_kg_m2`` to override).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .profile import gear_outline, polygon_area, tooth_profile
from .spec import GearSpec


@dataclass(frozen=True)
class BodyProperties:
    """Mass (kg) and polar moment of inertia about the gear axis (kg m^2) of one gear
    body, with the section area (m^2) and the polar second moment of area of the
    section (m^4) of the full-width part they come from."""

    mass_kg: float
    inertia_kg_m2: float
    section_area_m2: float
    section_polar_moment_m4: float


def polygon_polar_moment(xy: np.ndarray) -> float:
    """Polar second moment of area int (x^2 + y^2) dA (m^4) of a closed polygon about the
    origin (Green's theorem, see the module docstring; positive for counter-clockwise)."""
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    return float(np.sum(cross * (x * x + x * xn + xn * xn + y * y + y * yn + yn * yn)) / 12.0)


@lru_cache(maxsize=64)
def body_properties(g: GearSpec, face_width_m: float) -> BodyProperties:
    """Mass and polar moment of inertia of gear ``g`` (its generated outline, its bore,
    its web if any, its material's density) over the face width (m)."""
    outline = gear_outline(tooth_profile(g))
    A_out = polygon_area(outline)
    I_out = polygon_polar_moment(outline)
    rho, b = g.material.density_kg_per_m3, face_width_m
    r_bore = g.hub_radius_m
    if g.web is None:
        r_i = r_h = r_bore
        b_s = b
    else:
        r_i, r_h, b_s = g.root_radius_m - g.web.rim_thickness_m, g.web.hub_radius_m, g.web.thickness_m
    pi = math.pi
    area = (A_out - pi * r_i**2) * b + pi * (r_i**2 - r_h**2) * b_s + pi * (r_h**2 - r_bore**2) * b
    polar = (I_out - 0.5 * pi * r_i**4) * b + 0.5 * pi * (r_i**4 - r_h**4) * b_s + 0.5 * pi * (r_h**4 - r_bore**4) * b
    return BodyProperties(rho * area, rho * polar, A_out - pi * r_bore**2, I_out - 0.5 * pi * r_bore**4)
