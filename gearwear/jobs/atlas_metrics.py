"""The atlas's metrics of one mesh-stiffness curve (any source: analytic.tvms.MeshStiffness
or fem.pair.PairFE, both geometry.curves.CurveStats), over one mesh period, SI units:

* ``mean_N_per_m``: the mean of the piecewise-linear k_h (geometry.curves.curve_mean);
* ``single_N_per_m``, ``double_N_per_m``: the plateaus, the means over the zones with one
  and with two pairs on the path of contact (CurveStats.zone_means; NaN where the zone
  does not occur: no single contact at contact ratio >= 2, no double contact below... never
  for epsilon >= 1);
* ``p2p_N_per_m``: max k_h - min k_h at the curve's nodes;
* ``h1_N_per_m`` .. ``h3_N_per_m``: amplitudes 2 |c_m| of the mesh harmonics 1-3 of k_h,
  absolute in N/m (geometry.curves.harmonic_amplitudes: exact for the interpolant); divide
  by the mean for the relative ones;
* ``ste_p2p_um``: peak-to-peak of the loaded static transmission error (um; NaN for a
  source without an STE);
* ``entry_deg``, ``exit_deg``: the transition angles, where the number of loaded pairs
  changes, as pinion rotation (deg) from the kinematic ones: a pair starts carrying load
  ``entry_deg`` after it reaches A (negative: before A, loaded corner contact) and stops
  ``exit_deg`` after it passes E. From the nodes: the midpoint of the two nodes between
  which the count of loaded pairs changes (the analytic tables hold their breakpoints as
  nodes, so this is exact to their one-sided limits; the FE's positions resolve it to a
  position unless ``extended`` widths from fem.pair_cycle.extended_contact_widths are
  given, which are bisected to 1e-4 deg).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gearwear.geometry.curves import harmonic_amplitudes

#: the metric columns, in table order
METRICS = (
    "mean_N_per_m",
    "single_N_per_m",
    "double_N_per_m",
    "p2p_N_per_m",
    "h1_N_per_m",
    "h2_N_per_m",
    "h3_N_per_m",
    "ste_p2p_um",
    "entry_deg",
    "exit_deg",
)


def _wrap(x: float, period: float) -> float:
    """x into [-period / 2, period / 2)."""
    return (x + 0.5 * period) % period - 0.5 * period


def transitions_rad(angle_rad, loaded_count, period_rad: float) -> tuple[list[float], list[float]]:
    """(rises, falls): pinion angles (rad, in [0, period)) where the number of loaded pairs
    goes up and down between neighbouring nodes of a periodic curve, each at the midpoint
    of its two nodes."""
    a = np.asarray(angle_rad, dtype=float)
    n = np.asarray(loaded_count)
    nxt = np.r_[a[1:], a[0] + period_rad]
    n_next = np.r_[n[1:], n[0]]
    mid = 0.5 * (a + nxt) % period_rad
    return [float(x) for x in mid[n_next > n]], [float(x) for x in mid[n_next < n]]


def transition_offsets_deg(curve, extended: dict | None = None) -> tuple[float, float]:
    """(entry_deg, exit_deg) of the module docstring; NaN when the count never changes
    (a constant count: no transition to locate)."""
    mesh = curve.mesh
    P = mesh.mesh_angle_rad
    if extended is not None and all(math.isfinite(extended.get(k, math.nan)) for k in ("entry", "exit")):
        return -float(extended["entry"]), float(extended["exit"])
    loaded = (np.asarray(curve.pair_load_N) > 0).sum(axis=1)
    rises, falls = transitions_rad(curve.phase_rad, loaded, P)
    if not rises or not falls:
        return math.nan, math.nan
    entry = min((_wrap(r - 0.0, P) for r in rises), key=abs)
    exit_ = min((_wrap(f - mesh.exit_angle_rad, P) for f in falls), key=abs)
    return math.degrees(entry), math.degrees(exit_)


def curve_metrics(curve, extended: dict | None = None) -> dict[str, float]:
    """The :data:`METRICS` of one curve over one mesh period."""
    k = np.asarray(curve.k_N_per_m, dtype=float)
    zones = curve.zone_means()
    h = harmonic_amplitudes(curve.angle_rad, k, curve.span_rad, 3)
    ste = np.asarray(curve.ste_m, dtype=float)
    entry, exit_ = transition_offsets_deg(curve, extended)
    out: dict[str, Any] = {
        "mean_N_per_m": curve.mean_N_per_m,
        "single_N_per_m": zones["single"],
        "double_N_per_m": zones["double"],
        "p2p_N_per_m": float(k.max() - k.min()),
        "h1_N_per_m": float(h[0]),
        "h2_N_per_m": float(h[1]),
        "h3_N_per_m": float(h[2]),
        "ste_p2p_um": float(np.ptp(ste)) * 1e6 if np.all(np.isfinite(ste)) else math.nan,
        "entry_deg": entry,
        "exit_deg": exit_,
    }
    return {m: float(out[m]) for m in METRICS}
