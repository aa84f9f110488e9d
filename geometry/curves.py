"""Bookkeeping shared by every mesh-stiffness curve over one mesh period: the analytic
curves (analytic.tvms), the FE curves (fem.pair) and the constant ISO curve of the
app layer. Pure array work on top of the kinematics (geometry.kinematics); no model.

The theoretical zones of a period are those of ``MeshGeometry.contact_zones``: "A"
and "C" the halves of the double-contact interval, "B" single contact. Angles are
rad of pinion rotation, stiffness N/m, loads N.
"""

from __future__ import annotations

import math

import numpy as np

from .kinematics import MeshGeometry
from .spec import PairSpec


def zone_means(k_N_per_m, zones: dict[str, np.ndarray]) -> dict[str, float]:
    """Mean stiffness (N/m) over the double-contact zones A | C and over the
    single-contact zone B of ``zones`` (masks over the same angles as k); nan for an
    empty zone. Sample means: for curves compared position by position at the same
    uniform angles (gearwear.stiffness.comparison); a curve's own zone means are the integrals of
    :meth:`CurveStats.zone_means`."""
    k = np.asarray(k_N_per_m, dtype=float)
    double, single = zones["A"] | zones["C"], zones["B"]
    return {
        "double": float(k[double].mean()) if double.any() else float("nan"),
        "single": float(k[single].mean()) if single.any() else float("nan"),
    }


# -- integrals of a periodic piecewise-linear curve (non-uniform nodes) -----------------


def _closed(angle_rad, values, span_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and values closed over one span: the first node repeated one span later."""
    x = np.asarray(angle_rad, dtype=float)
    v = np.asarray(values, dtype=float)
    return np.r_[x, x[0] + span_rad], np.concatenate([v, v[:1]], axis=0)


def curve_mean(angle_rad, values, span_rad: float) -> float:
    """Mean over one span of the periodic piecewise-linear interpolant of ``values`` at
    the (not necessarily uniform, ascending) nodes ``angle_rad``, the period being
    ``span_rad``: the trapezoid rule, (1 / span) sum (v_i + v_i+1) / 2 (x_i+1 - x_i),
    exact for the interpolant (a plain average of the nodes would weigh a clustered
    region more). On a uniform grid it is the plain average."""
    x, v = _closed(angle_rad, values, span_rad)
    return float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(x)) / span_rad)


def interval_integral(angle_rad, values, span_rad: float, a_rad: float, b_rad: float) -> float:
    """Integral over [a, b] (a <= b within one span of the nodes' start) of the periodic
    piecewise-linear interpolant: each segment clipped to [a, b], its linear values at
    the clipped ends, trapezoid (exact)."""
    x, v = _closed(angle_rad, values, span_rad)
    x0 = x[0]
    a = x0 + (a_rad - x0) % span_rad
    b = a + (b_rad - a_rad)
    # two laps of segments cover [a, b] for any start inside the first one
    x2 = np.r_[x[:-1], x + span_rad]
    v2 = np.r_[v[:-1], v]
    lo, hi = np.maximum(x2[:-1], a), np.minimum(x2[1:], b)
    use = hi > lo
    slope = np.diff(v2) / np.diff(x2)
    va = v2[:-1][use] + slope[use] * (lo[use] - x2[:-1][use])
    vb = v2[:-1][use] + slope[use] * (hi[use] - x2[:-1][use])
    return float(np.sum(0.5 * (va + vb) * (hi[use] - lo[use])))


def fourier_coefficients(angle_rad, values, span_rad: float, n: int, periods: int = 1) -> np.ndarray:
    """Complex Fourier coefficients c_m, m = 1 .. n harmonics of the mesh frequency, of the
    periodic piecewise-linear interpolant of ``values`` at the (not necessarily uniform,
    ascending) nodes ``angle_rad`` over a span of ``periods`` mesh periods (harmonic m is
    order m periods of the span), v(x) = c_0 + sum 2 Re(c_q exp(i w_q x)). Exact: with
    slopes s_i on [x_i, x_i+1] the interpolant is continuous and periodic, so integration
    by parts twice gives c_q = 1 / (L w_q^2) sum_i (s_i-1 - s_i) exp(-i w_q x_i),
    w_q = 2 pi q / L: only the slope jumps at the nodes count."""
    x, v = _closed(angle_rad, values, span_rad)
    s = np.diff(v) / np.diff(x)
    jump = np.r_[s[-1], s[:-1]] - s  # s_(i-1) - s_i at x_i
    w = 2 * np.pi * periods * np.arange(1, n + 1) / span_rad
    return (np.exp(-1j * np.outer(w, x[:-1])) @ jump) / (span_rad * w**2)


def harmonic_amplitudes(angle_rad, values, span_rad: float, n: int, periods: int = 1) -> np.ndarray:
    """Amplitudes 2 |c_m| of the mesh harmonics m = 1 .. n of the periodic piecewise-linear
    interpolant (:func:`fourier_coefficients`)."""
    return 2 * np.abs(fourier_coefficients(angle_rad, values, span_rad, n, periods))


class CurveStats:
    """Statistics of a mesh-stiffness curve over one mesh period. Needs ``pair``,
    ``mesh`` (geometry.kinematics.MeshGeometry), ``torque_Nm``, ``angle_rad``,
    ``k_N_per_m`` and ``pair_load_N`` (angles x slots)."""

    # provided by the curve classes that mix this in (dataclass fields there)
    pair: PairSpec
    mesh: MeshGeometry
    torque_Nm: float
    angle_rad: np.ndarray
    k_N_per_m: np.ndarray
    pair_load_N: np.ndarray

    @property
    def span_rad(self) -> float:
        """Pinion rotation the curve spans: its mesh periods (``periods``, 1 unless set)."""
        return getattr(self, "periods", 1) * self.mesh.mesh_angle_rad

    @property
    def mean_N_per_m(self) -> float:
        """Mean of the piecewise-linear k_h over the span (:func:`curve_mean`)."""
        return curve_mean(self.angle_rad, self.k_N_per_m, self.span_rad)

    def mean_of(self, values) -> float:
        """Mean over the span of another quantity at the curve's angles (e.g. ste_m)."""
        return curve_mean(self.angle_rad, values, self.span_rad)

    def harmonics_N_per_m(self, n: int = 10) -> np.ndarray:
        """Amplitudes of the mesh harmonics 1 .. n of k_h (N/m, :func:`harmonic_amplitudes`)."""
        return harmonic_amplitudes(self.angle_rad, self.k_N_per_m, self.span_rad, n, getattr(self, "periods", 1))

    @property
    def min_N_per_m(self) -> float:
        return float(np.min(self.k_N_per_m))

    @property
    def max_N_per_m(self) -> float:
        return float(np.max(self.k_N_per_m))

    @property
    def pairs_in_contact(self) -> np.ndarray:
        """Number of pairs carrying load at each angle."""
        return (self.pair_load_N > 0).sum(axis=1)

    @property
    def contact_ratio(self) -> float:
        return self.mesh.contact_ratio

    @property
    def total_load_N(self) -> float:
        """Normal load on the line of action, T / r_b1 (N)."""
        return self.torque_Nm / self.pair.gear(0).base_radius_m

    @property
    def phase_rad(self) -> np.ndarray:
        """The angles wrapped into one mesh period (a curve over a revolution of a
        faulty gear spans several)."""
        P = self.mesh.mesh_angle_rad
        a = np.asarray(self.angle_rad, dtype=float)
        return a - P * np.floor(a / P)

    def zone_masks(self) -> dict[str, np.ndarray]:
        """Masks of the theoretical zones A, B, C at ``angle_rad``
        (MeshGeometry.contact_zones)."""
        return self.mesh.contact_zones(self.phase_rad)

    def zone_means(self) -> dict:
        """Zone statistics over one mesh period, by the number n of pairs on the path
        (``MeshGeometry.pairs_on_path``):

        * "by_count": n -> mean stiffness (N/m), None where n never occurs: the integral
          of the piecewise-linear k_h over the zone divided by its length. With
          n0 = floor(epsilon), n0 + 1 pairs are on the path for 0 <= theta <= theta_E and
          n0 for theta_E < theta < P in every mesh period
          (``MeshGeometry.exit_angle_rad``);
        * "deg_by_count": n -> the zone's length (pinion rotation, deg): with
          n0 = floor(epsilon), (epsilon - n0) of the period for n0 + 1 pairs and the
          rest for n0 pairs;
        * "double", "single": the means over n = 2 and n = 1 (NaN when absent; for
          1 <= epsilon < 2 these are the zones A | C and B), and "double_deg",
          "single_deg" their lengths ((epsilon - 1) and (2 - epsilon) of the period
          then)."""
        P = self.mesh.mesh_angle_rad
        period_deg = math.degrees(P)
        periods = getattr(self, "periods", 1)
        n0 = int(math.floor(self.mesh.contact_ratio))
        th_E = self.mesh.exit_angle_rad
        by: dict[int, float | None] = {n: None for n in range(0 if n0 == 0 else 1, max(3, n0 + 1) + 1)}
        for n, (a, b) in ((n0 + 1, (0.0, th_E)), (n0, (th_E, P))):
            if b - a > 0:
                total = sum(
                    interval_integral(self.angle_rad, self.k_N_per_m, self.span_rad, a + m * P, b + m * P)
                    for m in range(periods)
                )
                by[n] = total / (periods * (b - a))
        shares = self.mesh.zone_shares()
        deg = {n: shares.get(n, 0.0) * period_deg for n in by}
        nan = float("nan")
        return {
            "double": nan if by.get(2) is None else by[2],
            "single": nan if by.get(1) is None else by[1],
            "double_deg": deg.get(2, 0.0),
            "single_deg": deg.get(1, 0.0),
            "by_count": by,
            "deg_by_count": deg,
        }
