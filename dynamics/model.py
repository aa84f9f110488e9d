"""Plain-parameter description of the bending-torsion gear model (paper Eqs. 7-10, 17-20).

Coordinates (SI): bearing translations ``y_p, x_p, y_g, x_g`` (x along the centre line
from the pinion to the gear, y along the common tangent) and the relative torsional
coordinate ``q = R_p theta_p - R_g theta_g``. The rigid-body rotation is reduced away:

    m_e q''  = F_s - F_m,              m_e = 1 / (R_p^2/J_p + R_g^2/J_g),  F_s = T_p / R_p
    m_p y_p'' + c_b y_p' + k_b f_b(y_p) = -F_m cos(a)     m_g y_g'' + ... = +F_m cos(a)
    m_p x_p'' + c_b x_p' + k_b f_b(x_p) = -F_m sin(a)     m_g x_g'' + ... = +F_m sin(a)
    delta = q + (x_p - x_g) sin(a) + (y_p - y_g) cos(a)                        (Eq. 18)
    s = delta - e(phi),  F_m = c_h delta' + k_h(phi) f(s)                       (Eq. 19)

(static centre-distance coupling; see below for the dynamic form).

This is paper Eq. 17 with its typo fixed (docs/models.md, "Dynamics"): the gear torsion equation
uses the output torque ``T_g = T_p R_g / R_p`` and ``R_g``; only then does the
relative coordinate reduce exactly to the equation for ``q`` above (the paper's
``J_g theta_g'' = -T_p + R_p F_m`` is dimensionally right only for a 1:1 pair).
``f`` is the backlash dead zone of Eq. 20 with the third branch read as ``s < -b``.

Contact law (``mesh_damping``):
  * ``"off-when-separated"`` (default): while ``|s| <= b`` the teeth are apart and the
    mesh transmits no force at all, neither spring nor damper (a gap carries no
    tension); in drive-side (``s > b``) or back-side (``s < -b``) contact
    ``F_m = c_h delta' + k_h f(s)``.
  * ``"paper"``: literal Eq. 19, ``c_h delta'`` always on, also across the gap. Then the
    mesh force is continuous at contact/separation (it only has a kink) but a
    "damper through the gap" pulls the separated teeth together.

Bearings: ``f_b`` is the dead zone of half-width ``b_b = BC / 2`` (BC = total radial play,
paper Eqs. 7-10). The bearing damping ``c_b y'`` is always on, as printed in Eq. 17
(lubricant film / housing damping acts in the gap too).

Centre-distance coupling:
  * ``"static"``: the pressure angle ``alpha`` and the backlash half-width are fixed (the
    caller computes them from the static operating geometry, e.g. paper Eq. 11). This is
    the paper's single-line-of-action model: a radial separation of the centres opens
    the drive flank through the ``(x_p - x_g) sin(a)`` term of Eq. 18 but closes the
    back flank by the same amount (an inherent first-order limitation of Eq. 17/18).
  * ``"dynamic"``: O_g - O_p = (C0 + x_g - x_p, y_g - y_p), C(t) = |O_g - O_p|,
    ``alpha'(t) = arccos((R_p + R_g) / C(t))``, half backlash
    ``b(t) = b0 + (R_p + R_g)(inv alpha'(t) - inv alpha0)`` on each flank (the total
    normal backlash changes by ``2 (R_p+R_g)(inv a' - inv a0)``; ``R_p, R_g`` are base
    radii). Since b(C) already *is* the effect of the centre distance on the flank
    gaps (d b / d C = sin alpha' exactly), the x-projection of Eq. 18 must not be added
    on top of it (it would open the drive flank twice and leave the back flank
    unchanged). So here ``delta = q + (y_p - y_g) cos alpha'(t)`` with the symmetric dead
    zone ``[-b(C), b(C)]``, and the generalised forces are the exact gradients of the
    flank potentials ``1/2 k (s -+ b(C))^2`` and of the Rayleigh function
    ``1/2 c_h delta'^2``. To first order this reproduces the paper's radial force
    ``F sin alpha`` on drive contact, gives the physically right (separating) radial
    force on back contact, and it is exactly energy-consistent (``energy_balance``
    closes). The two-flank law is always used in this mode (no backlash given means
    b0 = 0: a tight mesh at C0; if b(C) < 0 both flanks are compressed).
    ``alpha`` is the pressure angle at ``C0_m`` (``C0_m`` defaults to
    ``(R_p + R_g)/cos(alpha)``; a given ``C0_m`` must agree).

Stiffness / excitation tables: ``phi_table`` (rad of pinion rotation, strictly increasing
inside one table period ``[0, table_periods 2 pi / z_p)``), ``k_table`` (N/m), ``e_table``
(m); the nominal pinion angle is ``phi = omega_p t``. ``table_periods`` (default 1) is the
number of mesh periods the tables span: 1 for a healthy pair (k is mesh-periodic); a fault
on one tooth makes k periodic over a revolution of that gear (``z_p`` for a pinion tooth,
``z_g`` for a gear tooth, ``lcm(z_p, z_g)`` for both). Everything that repeats with the
table (interpolant, means, node times, the RK4 schedule, the adaptive solver's node
stepping) uses the table period ``table_period_rad``; what is physically the mesh period
(``mesh_frequency_Hz``, samples per mesh period, harmonic bins) stays. Interpolation is periodic *linear*
(positivity preserving, so zero-stiffness gaps stay zero; exact for tabulated
piecewise-linear data). The tables' kinks are at known times, so the adaptive
integrator ends its steps on them (each step sees a polynomial right-hand side) and
the RK4 integrator is kink-free when ``steps_per_mesh_period`` is a multiple of the
table length (uniform table starting at a node).

This module holds the parameters (``GearDynamics``, validated in ``__post_init__``) and the
damping conversion. The rest of the model lives in one module per idea: the table
interpolant (``dynamics.interpolant``), the kernels' parameter vector (``dynamics.params``),
the tables on the time axis and the RK4 schedule (``dynamics.table_time``), the equations
on arrays (``dynamics.equations``), the pure-Python right-hand side
(``dynamics.reference_rhs``), the static equilibrium (``dynamics.equilibrium``) and the
linearised model (``dynamics.linear``). Their names stay importable from here.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from gearwear.core.validation import Field, fail, fail_text

# names that lived here before the split, still importable from this module
from .equations import _accelerations, bearing_f, has_flank_law, mesh_geometry, mesh_state  # noqa: F401
from .equilibrium import static_equilibrium
from .interpolant import _eval_coefficients, segment_coefficients, table_mean  # noqa: F401
from .linear import _linear_matrices, linear_eigenfrequencies, max_linear_rate  # noqa: F401
from .params import (  # noqa: F401
    N_PAR,
    P_B,
    P_BB,
    P_C0,
    P_CA,
    P_CBG,
    P_CBP,
    P_CH,
    P_DPHI,
    P_FS,
    P_INV0,
    P_KB,
    P_KC,
    P_ME,
    P_MG,
    P_MP,
    P_N,
    P_OM,
    P_PAPER,
    P_PER,
    P_PHI0,
    P_RS,
    P_SA,
    P_UNI,
    _compute_derived,
    _inv,
    derived,
)
from .reference_rhs import rhs_python
from .table_time import _breaks, _table_eval, rk4_schedule, table_node_times  # noqa: F401

__all__ = [
    "GearDynamics",
    "damping_from_ratios",
    "static_equilibrium",
    "linear_eigenfrequencies",
    "rhs_python",
    "STATE_NAMES",
]

STATE_NAMES = ("y_p", "x_p", "y_g", "x_g", "q", "vy_p", "vx_p", "vy_g", "vx_g", "vq")


@dataclass(frozen=True, eq=False)
class GearDynamics:
    """Plain SI parameters of the 6-DOF (5 after reduction) spur-gear model.

    ``c_b`` is a scalar (both bearings) or a (pinion, gear) pair. Effect switches:
    ``tvms`` (else constant ``k_constant`` or the table mean), ``backlash_half_m``
    (None = no backlash: linear two-sided mesh spring), ``bearing_half_clearance_m``
    (None = linear bearings), ``te_excitation`` (else e = 0), ``centre_distance``.
    ``table_periods``: the tables span this many mesh periods (a whole number >= 1;
    ``z_p`` for a one-tooth pinion fault, see the module docstring).
    """

    m_p: float
    m_g: float
    J_p: float
    J_g: float
    R_p: float
    R_g: float
    alpha: float
    k_b: float
    c_b: float | tuple[float, float]
    c_h: float
    T_p: float
    omega_p: float
    z_p: int
    phi_table: np.ndarray
    k_table: np.ndarray
    e_table: np.ndarray | None = None
    tvms: bool = True
    backlash_half_m: float | None = None
    bearing_half_clearance_m: float | None = None
    te_excitation: bool = False
    centre_distance: str = "static"
    C0_m: float | None = None
    mesh_damping: str = "off-when-separated"
    k_constant: float | None = None
    interpolation: str = "linear"
    table_periods: int = 1

    def __post_init__(self):
        pos = ("m_p", "m_g", "J_p", "J_g", "R_p", "R_g", "k_b", "omega_p")
        for name in pos:
            v = getattr(self, name)
            if not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v) or v <= 0:
                raise fail_text(name, f"{name} = {v!r}: must be a finite number > 0", v)
        for name in ("c_h", "T_p"):
            v = getattr(self, name)
            if not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
                raise fail_text(name, f"{name} = {v!r}: must be a finite number", v)
        if self.c_h < 0:
            raise fail_text("c_h", f"c_h = {self.c_h} N s/m: must be >= 0", self.c_h, unit="N s/m")
        cb = self.c_b if isinstance(self.c_b, (tuple, list)) else (self.c_b, self.c_b)
        if len(cb) != 2 or any((not math.isfinite(c)) or c < 0 for c in cb):
            raise fail_text(
                "c_b", f"c_b = {self.c_b!r} N s/m: must be >= 0 (one value or pinion, gear)", self.c_b, unit="N s/m"
            )
        object.__setattr__(self, "c_b", (float(cb[0]), float(cb[1])))
        if not (0 < self.alpha < math.pi / 2):
            raise fail_text(
                "alpha",
                f"alpha = {self.alpha} rad: must be in (0, pi/2)",
                self.alpha,
                unit="rad",
                field=Field("rad", 0.0, math.pi / 2, lo_open=True, hi_open=True),
            )
        if int(self.z_p) != self.z_p or self.z_p < 3:
            raise fail_text("z_p", f"z_p = {self.z_p}: must be a whole number >= 3", self.z_p)
        L = self.table_periods
        if (
            isinstance(L, bool)
            or not isinstance(L, (int, float, np.floating, np.integer))
            or not math.isfinite(L)
            or int(L) != L
            or L < 1
        ):
            raise fail_text(
                "table_periods",
                f"table_periods = {L!r}: must be a whole number >= 1 (mesh periods spanned by the stiffness tables)",
                L,
            )
        object.__setattr__(self, "table_periods", int(L))
        P = self.table_period_rad
        phi = np.asarray(self.phi_table, dtype=float).ravel()
        k = np.asarray(self.k_table, dtype=float).ravel()
        if phi.size < 2 or k.shape != phi.shape:
            raise fail_text(
                "k_table", f"k_table: needs >= 2 points and the shape of phi_table ({phi.size}), got {k.size}"
            )
        if not (np.all(np.isfinite(phi)) and np.all(np.diff(phi) > 0) and phi[0] >= 0 and phi[-1] < P * (1 + 1e-12)):
            span = (
                "one mesh period"
                if self.table_periods == 1
                else f"one table period of {self.table_periods} mesh periods (table_periods)"
            )
            raise fail_text("phi_table", f"phi_table: must be strictly increasing inside {span} [0, {P:.6g}) rad")
        if self.table_periods > 1 and phi[-1] < (self.table_periods - 1) * self.mesh_period_rad * (1 - 1e-12):
            raise fail_text(
                "phi_table",
                f"phi_table: ends at {phi[-1]:.6g} rad, but table_periods = "
                f"{self.table_periods} needs a table over [0, {P:.6g}) rad (nodes in "
                f"each of the {self.table_periods} mesh periods; tile a one-period "
                f"table or set table_periods = 1)",
            )
        if phi[-1] >= P:
            phi = phi.copy()
            phi[-1] = np.nextafter(P, 0.0)
        if not np.all(np.isfinite(k)) or np.any(k < 0):
            raise fail_text("k_table", "k_table N/m: must be finite and >= 0", unit="N/m")
        e = np.zeros_like(phi) if self.e_table is None else np.asarray(self.e_table, float).ravel()
        if e.shape != phi.shape or not np.all(np.isfinite(e)):
            raise fail_text("e_table", f"e_table m: must be finite with the shape of phi_table ({phi.size})", unit="m")
        for name, arr in (("phi_table", phi), ("k_table", k), ("e_table", e)):
            arr = arr.copy()
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        for name in ("backlash_half_m", "bearing_half_clearance_m"):
            v = getattr(self, name)
            if v is not None and (not math.isfinite(v) or v < 0):
                raise fail_text(name, f"{name} = {v} m: must be >= 0 (or None: effect absent)", v, unit="m")
        if self.centre_distance not in ("static", "dynamic"):
            raise fail("centre_distance", repr(self.centre_distance), "", "must be 'static' or 'dynamic'")
        if self.mesh_damping not in ("off-when-separated", "paper"):
            raise fail("mesh_damping", repr(self.mesh_damping), "", "must be 'off-when-separated' or 'paper'")
        if self.interpolation not in ("linear", "cubic"):
            raise fail("interpolation", repr(self.interpolation), "", "must be 'linear' or 'cubic'")
        if self.interpolation == "cubic":
            if phi.size < 4:
                raise fail_text("k_table", f"k_table: cubic interpolation needs >= 4 points, got {phi.size}")
            kc = segment_coefficients(phi, k, P, "cubic")
            d = (np.diff(np.r_[phi, phi[0] + P]))[:, None] * np.linspace(0, 1, 9)[None, :]
            low = np.min(kc[:, 0, None] + d * (kc[:, 1, None] + d * (kc[:, 2, None] + d * kc[:, 3, None])))
            if low < 0:
                raise fail_text(
                    "k_table",
                    f"k_table: its periodic cubic spline goes negative "
                    f"({low:.4g} N/m) between the rows; use linear interpolation",
                )
        if self.k_constant is not None and (not math.isfinite(self.k_constant) or self.k_constant < 0):
            raise fail_text(
                "k_constant", f"k_constant = {self.k_constant} N/m: must be >= 0", self.k_constant, unit="N/m"
            )
        if self.centre_distance == "dynamic" and self.C0_m is not None:
            Cn = (self.R_p + self.R_g) / math.cos(self.alpha)
            if abs(self.C0_m - Cn) > 1e-9 * Cn:
                raise fail_text(
                    "C0_m",
                    f"C0_m = {self.C0_m} m: must equal (R_p + R_g)/cos(alpha) "
                    f"= {Cn:.9g} m (alpha is the pressure angle at C0)",
                    self.C0_m,
                    unit="m",
                )

    # ---- derived quantities (pure) ----
    @property
    def C0(self) -> float:
        """Centre distance at zero bearing displacement: C0_m or (R_p + R_g)/cos(alpha)."""
        return self.C0_m if self.C0_m is not None else (self.R_p + self.R_g) / math.cos(self.alpha)

    @property
    def mesh_period_rad(self) -> float:
        return 2 * math.pi / self.z_p

    @property
    def table_period_rad(self) -> float:
        """Pinion rotation (rad) spanned by the tables: ``table_periods * 2 pi / z_p``
        (the period of k and e; the mesh period when ``table_periods = 1``)."""
        if self.table_periods == 1:
            return 2 * math.pi / self.z_p
        return self.table_periods * (2 * math.pi / self.z_p)

    @property
    def table_period_s(self) -> float:
        """Duration (s) of one table period at the nominal speed."""
        return self.table_period_rad / self.omega_p

    @property
    def mesh_frequency_Hz(self) -> float:
        return self.z_p * self.omega_p / (2 * math.pi)

    @property
    def m_e(self) -> float:
        return 1.0 / (self.R_p**2 / self.J_p + self.R_g**2 / self.J_g)

    @property
    def F_s(self) -> float:
        return self.T_p / self.R_p

    @property
    def T_g(self) -> float:
        return self.T_p * self.R_g / self.R_p

    @property
    def k_mean(self) -> float:
        """Mean mesh stiffness: table-period mean of the interpolated table (or the constant)."""
        if not self.tvms:
            return self.k_constant if self.k_constant is not None else _table_mean(self, self.k_table)
        return _table_mean(self, self.k_table)

    @property
    def e_mean(self) -> float:
        return _table_mean(self, self.e_table) if self.te_excitation and self.e_table is not None else 0.0

    @property
    def c_b_pair(self) -> tuple[float, float]:
        """(pinion, gear) bearing damping in N s/m (``c_b`` is normalised to this pair)."""
        cb = self.c_b
        return (cb, cb) if isinstance(cb, (int, float)) else (float(cb[0]), float(cb[1]))

    # Computed once per instance (the fields and the read-only tables never change after
    # __post_init__) and dropped with it. A module-level lru_cache would key on identity
    # (eq=False), keep up to 64 models and their tables alive and share state between
    # unrelated callers. cached_property writes the instance __dict__, so frozen is fine.
    @functools.cached_property
    def _derived(self) -> tuple:
        return _compute_derived(self)

    @functools.cached_property
    def _py_constants(self) -> tuple:
        par, phi, phx, kc, ec = self._derived
        return (par.tolist(), phx.tolist(), kc.tolist(), ec.tolist())

    def with_(self, **changes) -> "GearDynamics":
        """A copy with some fields replaced (dataclasses.replace)."""
        import dataclasses

        return dataclasses.replace(self, **changes)


def _table_mean(model: GearDynamics, v: np.ndarray) -> float:
    return table_mean(model.phi_table, v, model.table_period_rad, model.interpolation)


def damping_from_ratios(
    zeta_m: float, zeta_b: float, k_mean: float, m_e: float, k_b: float, m_p: float, m_g: float
) -> tuple[float, tuple[float, float]]:
    """Viscous damping from damping ratios: ``c_h = 2 zeta_m sqrt(k_mean m_e)`` (mesh, on
    the reduced torsional mass m_e) and ``c_b = 2 zeta_b sqrt(k_b m)`` for the pinion's and
    the gear's bearing (m = m_p, m_g); c = 2 zeta sqrt(k m) is the damping that gives a
    single-DOF oscillator the ratio zeta of critical damping. Ratios dimensionless,
    stiffnesses N/m, masses kg; returns (c_h, (c_b_p, c_b_g)) in N s/m. The one home of
    this conversion (scenes and presets call it)."""
    return (
        2 * zeta_m * math.sqrt(k_mean * m_e),
        (2 * zeta_b * math.sqrt(k_b * m_p), 2 * zeta_b * math.sqrt(k_b * m_g)),
    )
