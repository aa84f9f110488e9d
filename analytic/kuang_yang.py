"""Kuang & Yang's empirical single-tooth stiffness (J. H. Kuang and Y. T. Yang, "An
estimate of mesh stiffness and load sharing ratio of a spur gear pair", Proc. ASME 1992
Int. Power Transm. Gearing Conf., DE-Vol. 43-1, 1-9; as restated by Kuang & Lin, J. Vib.
Acoust. 123:311, 2001).

(The coefficients below are the restated ones; no copy of the 1992 paper could be reached
from this machine to compare them digit by digit. What checks them here is a second
regression, ISO 6336-1's c'_th: tests/test_models_published.py.)

A regression of finite-element results for a tooth of a steel gear with N teeth and
addendum modification (profile shift) coefficient X, loaded at contact radius r:

    K(r) = (A_0 + A_1 X) + (A_2 + A_3 X) (r - R) / ((1 + X) m)      [N / (mm um) per unit face width]

    A_0 =  3.867 + 1.612 N - 0.02916 N^2 + 0.0001553 N^3
    A_1 = 17.060 + 0.7289 N - 0.01728 N^2 + 0.0000993 N^3
    A_2 =  2.637 - 1.222 N + 0.02217 N^2 - 0.0001179 N^3
    A_3 = -6.330 - 1.033 N + 0.02068 N^2 - 0.0001130 N^3

with R the reference (pitch) radius and m the module. The paper gives K as 10^8 N/m for
a face width of 1 cm, which is the same number in N / (mm um) = 10^9 N/m per metre of
face; the tooth stiffness is therefore K 10^9 b (N/m) for a face width b (m). The
regression holds the bending, shear, fillet-foundation and local contact flexibility of
the FE tooth together: the pair compliance is the two teeth in series, with no separate
Hertz term (1/k_pair = 1/K_1 + 1/K_2).

The fit is for steel; another material is scaled by E / :data:`E_REF_PA` (the stiffness
of a linear elastic body at fixed nu is proportional to E). The cubics in N are used for
:data:`TEETH_RANGE` only: above 100 teeth they turn up steeply (A_0 = 28.8 at N = 100,
45.8 at 120, 114 at 150, where a tooth should tend to the rack's), so a gear outside it is
refused (one line, exit 2), as is any K <= 0.
"""

from __future__ import annotations

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.spec import GearSpec

#: Young's modulus of the steel of the regression (Pa)
E_REF_PA = 206e9

#: the tooth counts the cubic fits are used for (a gear outside is refused)
TEETH_RANGE = (12, 100)

#: coefficients (c_0, c_1, c_2, c_3) of A_i = c_0 + c_1 N + c_2 N^2 + c_3 N^3
COEFFICIENTS = (
    (3.867, 1.612, -0.02916, 0.0001553),
    (17.060, 0.7289, -0.01728, 0.0000993),
    (2.637, -1.222, 0.02217, -0.0001179),
    (-6.330, -1.033, 0.02068, -0.0001130),
)

#: N / (mm um) per unit face width, in N/m per metre of face width
UNIT_N_PER_M2 = 1e9


def coefficients(teeth: int) -> tuple[float, float, float, float]:
    """(A_0, A_1, A_2, A_3) for N = ``teeth`` (N / (mm um) per unit face width)."""
    return tuple(sum(c * teeth**k for k, c in enumerate(row)) for row in COEFFICIENTS)  # type: ignore[return-value]


def tooth_stiffness_N_per_m(gear: GearSpec, radius_m, face_width_m: float) -> np.ndarray:
    """Single-tooth stiffness K(r) 10^9 b E / E_ref (N/m) of ``gear`` at contact radii
    ``radius_m`` (m) for face width ``face_width_m`` (m)."""
    lo, hi = TEETH_RANGE
    if not lo <= gear.teeth <= hi:
        raise fail(
            "teeth",
            gear.teeth,
            "",
            f"the Kuang & Yang regression is used for {lo} to {hi} teeth (the {gear.name}'s cubic fits diverge beyond)",
        )
    a0, a1, a2, a3 = coefficients(gear.teeth)
    X, m = gear.profile_shift, gear.module_m
    r = np.atleast_1d(np.asarray(radius_m, dtype=float))
    K = (a0 + a1 * X) + (a2 + a3 * X) * (r - gear.pitch_radius_m) / ((1.0 + X) * m)
    if np.any(K <= 0):
        raise fail(
            "teeth",
            gear.teeth,
            "",
            f"with x = {X:g}: the Kuang & Yang regression gives a stiffness <= 0 on the {gear.name}'s "
            "flank (outside its fitted range)",
        )
    return K * UNIT_N_PER_M2 * face_width_m * (gear.material.youngs_modulus_Pa / E_REF_PA)


def tooth_compliance(gear: GearSpec, radius_m, face_width_m: float) -> np.ndarray:
    """1 / K(r) (m/N), the tooth's share of the pair compliance."""
    return 1.0 / tooth_stiffness_N_per_m(gear, radius_m, face_width_m)
