"""The Harris map: peak-to-peak of the loaded static transmission error against load,
for the nominal and for a modified flank (Harris 1958, "Dynamic loads on the teeth of
spur gears", Proc. IMechE 172:87-112; the "Harris map" of Smith, "Gear Noise and
Vibration", 2003, ch. 3).

A tip relief removes the transmission error at one load only: at that design load the
relieved teeth enter and leave contact at the deflection of the loaded pair, so the TE
is nearly flat; below it the relief dominates (TE from the kinematics of the relief),
above it the deflection does. The map makes that trade visible. Loads in N m of pinion
torque, TE in m along the line of action (analytic.tvms).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearwear.geometry.flank import FlankSpec
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec

from .tvms import DEFAULT_POINTS, mesh_stiffness


@dataclass(frozen=True)
class HarrisMap:
    torque_Nm: np.ndarray
    nominal_ste_pp_m: np.ndarray
    modified_ste_pp_m: np.ndarray

    def rows(self) -> list[dict]:
        return [
            {
                "torque_Nm": float(t),
                "ste_peak_to_peak_nominal_um": float(a * 1e6),
                "ste_peak_to_peak_modified_um": float(b * 1e6),
            }
            for t, a, b in zip(self.torque_Nm, self.nominal_ste_pp_m, self.modified_ste_pp_m)
        ]


def harris_map(
    pair: PairSpec,
    flank: FlankSpec,
    torques_Nm,
    method: str = "ishikawa",
    points: int = DEFAULT_POINTS,
    wear: WearSpec | None = None,
    clearance_m: float = 0.0,
    plane: str = "stress",
) -> HarrisMap:
    """TE peak-to-peak (m) over one mesh period at each torque, without and with ``flank``
    (``plane``: the tooth beams' 2D state, analytic.plane)."""
    T = np.asarray(torques_Nm, dtype=float)
    nominal: list[float] = []
    modified: list[float] = []
    for t in T:
        for fl, out in ((None, nominal), (flank, modified)):
            r = mesh_stiffness(
                pair,
                method=method,
                points=points,
                torque_Nm=float(t),
                clearance_m=clearance_m,
                wear=wear,
                flank=fl,
                plane=plane,
            )
            out.append(float(np.ptp(r.ste_m)))
    return HarrisMap(T, np.array(nominal), np.array(modified))
