"""The atlas's designs: a scrambled Sobol sequence (scipy.stats.qmc) over the SPEC's axes,
each point mapped to a spur pair and a load, kept when the geometry accepts it
(geometry.design_space.rejection), counted by reason when not.

A point u in [0, 1)^8 maps to (axes of gearwear.jobs.atlas_spec):

* z1 = round(z_lo - 0.5 + (z_hi - z_lo + 1) u0) (every whole count equally likely), z2 = round(z1 i),
  i = i_lo + (i_hi - i_lo) u1;
* alpha = uniform u2, h_a* = uniform u3, h_f* = h_a* + dedendum margin, rack tip round
  rho* = min(rho*_spec, 0.8 rho*_max), rho*_max = (pi/4 - h_f* tan alpha) cos alpha / (1 - sin alpha)
  (the full round of the rack tooth, as geometry.spec.check_pair);
* x_i = x_lo,i + (x_hi - x_lo,i) u(4+i), x_lo,i = max(x_lo, x_min,i), x_min,i the undercut-free
  limit h_f* - rho* (1 - sin alpha) - z_i sin^2(alpha) / 2 (geometry.profile.undercut_limits);
* s_R / m log-uniform u6 in the rim range; bore_i = max(r_f,i - s_R, f_min r_f,i);
* line load w log-uniform u7 in its range; pinion torque T = w b r_b1.

The first ``designs`` feasible points of the sequence are the atlas; the rejects before
the last of them are counted by reason. The same SPEC gives the same designs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from gearwear.core.validation import fail
from gearwear.geometry.design_space import REASONS, rejection
from gearwear.geometry.spec import Material, PairSpec

#: the Sobol dimensions: z1, ratio, alpha, h_a*, x1, x2, rim, load
DIMENSIONS = 8


@dataclass(frozen=True)
class Design:
    """One atlas design: its index in the Sobol sequence, the pair and the pinion torque (SI)."""

    index: int
    pair: PairSpec
    torque_Nm: float
    line_load_N_per_mm: float
    rim_thickness_module: float

    def row(self) -> dict[str, Any]:
        """The design's inputs as table columns (units in the names)."""
        p = self.pair
        return {
            "design": self.index,
            "z1": p.teeth[0],
            "z2": p.teeth[1],
            "pressure_angle_deg": math.degrees(p.pressure_angle_rad),
            "addendum_coefficient": p.addendum_coefficient,
            "dedendum_coefficient": p.dedendum_coefficient,
            "rack_tip_radius_coefficient": p.rack_tip_radius_coefficient,
            "x1": p.profile_shift[0],
            "x2": p.profile_shift[1],
            "module_mm": p.module_m * 1e3,
            "face_width_mm": p.face_width_m * 1e3,
            "bore1_mm": p.hub_radius_m[0] * 1e3,
            "bore2_mm": p.hub_radius_m[1] * 1e3,
            "rim_thickness_module": self.rim_thickness_module,
            "line_load_N_per_mm": self.line_load_N_per_mm,
            "torque_Nm": self.torque_Nm,
        }


@dataclass
class DesignSpace:
    """The feasible designs and the rejects by reason (:data:`geometry.design_space.REASONS`)."""

    designs: list[Design]
    rejects: dict[str, int] = field(default_factory=lambda: {r: 0 for r in REASONS})
    drawn: int = 0


def _uniform(u: float, lo: float, hi: float) -> float:
    return lo + (hi - lo) * u


def _log_uniform(u: float, lo: float, hi: float) -> float:
    return lo * (hi / lo) ** u


def design_at(u, index: int, values: dict[str, Any]) -> Design:
    """The design of one Sobol point ``u`` (see the module docstring)."""
    u = [float(v) for v in u]
    z_lo, z_hi = values["axes.pinion_teeth"]
    z1 = int(min(z_hi, max(z_lo, round(z_lo - 0.5 + (z_hi - z_lo + 1) * u[0]))))
    z2 = max(1, int(round(z1 * _uniform(u[1], *values["axes.ratio"]))))
    alpha = math.radians(_uniform(u[2], *values["axes.pressure_angle_deg"]))
    ha = _uniform(u[3], *values["axes.addendum_coefficient"])
    hf = ha + values["pair.dedendum_margin"]
    rho_max = (0.25 * math.pi - hf * math.tan(alpha)) * math.cos(alpha) / (1.0 - math.sin(alpha))
    rho = max(0.0, min(values["pair.rack_tip_radius_coefficient"], 0.8 * rho_max))
    x_lo, x_hi = values["axes.profile_shift"]
    shifts = []
    for i, z in enumerate((z1, z2)):
        x_min = hf - rho * (1.0 - math.sin(alpha)) - 0.5 * z * math.sin(alpha) ** 2
        lo = min(max(x_lo, x_min), x_hi)
        shifts.append(_uniform(u[4 + i], lo, x_hi))
    m = values["pair.module_mm"] * 1e-3
    b = values["pair.face_width_mm"] * 1e-3
    rim = _log_uniform(u[6], *values["axes.rim_thickness_module"])
    roots = [0.5 * m * z - (hf - x) * m for z, x in zip((z1, z2), shifts)]
    f_min = values["pair.min_bore_fraction"]
    bores = tuple(max(r - rim * m, f_min * r) if r > 0 else 1e-9 for r in roots)
    w = _log_uniform(u[7], *values["axes.line_load_N_per_mm"])
    mat = Material(
        youngs_modulus_Pa=values["pair.youngs_modulus_GPa"] * 1e9, poisson_ratio=values["pair.poisson_ratio"]
    )
    pair = PairSpec(
        teeth=(z1, z2),
        module_m=m,
        pressure_angle_rad=alpha,
        face_width_m=b,
        addendum_coefficient=ha,
        dedendum_coefficient=hf,
        rack_tip_radius_coefficient=rho,
        profile_shift=(shifts[0], shifts[1]),
        hub_radius_m=bores,  # type: ignore[arg-type]
        materials=(mat, mat),
    )
    torque = w * 1e3 * b * pair.gear(0).base_radius_m
    return Design(index, pair, torque, w, rim)


def design_space(values: dict[str, Any]) -> DesignSpace:
    """The first ``designs`` feasible designs of the scrambled Sobol sequence of ``seed``,
    and the rejects by reason among the points drawn up to the last of them. Points are
    drawn in blocks of powers of two (the sequence's balanced sizes); a run that finds too
    few within limits.max_candidates is a one-line error."""
    from scipy.stats import qmc

    n = values["designs"]
    cap = values["limits.max_candidates"]
    limits = (values["limits.min_tip_thickness_module"], values["limits.min_contact_ratio"])
    sobol = qmc.Sobol(DIMENSIONS, scramble=True, seed=values["seed"])
    out = DesignSpace([])
    block = 1 << max(4, math.ceil(math.log2(max(n, 1))))
    while len(out.designs) < n:
        if out.drawn >= cap:
            raise fail(
                "limits.max_candidates",
                cap,
                "",
                f"only {len(out.designs)} of {n} designs feasible among {out.drawn} points drawn "
                f"(rejects: {', '.join(f'{k} {v}' for k, v in out.rejects.items() if v)}); widen the axes or "
                "draw more points",
            )
        take = min(block, cap - out.drawn)
        for u in sobol.random(take):
            d = design_at(u, out.drawn, values)
            out.drawn += 1
            why = rejection(d.pair, *limits)
            if why is None:
                out.designs.append(d)
                if len(out.designs) == n:
                    break
            else:
                out.rejects[why] += 1
        block = take
    return out
