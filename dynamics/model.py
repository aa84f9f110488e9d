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
"""

from __future__ import annotations

import bisect
import functools
import math
from dataclasses import dataclass

import numpy as np

from gearwear.core.validation import InputError

__all__ = ["GearDynamics", "damping_from_ratios", "static_equilibrium",
           "linear_eigenfrequencies", "rhs_python", "STATE_NAMES"]

STATE_NAMES = ("y_p", "x_p", "y_g", "x_g", "q", "vy_p", "vx_p", "vy_g", "vx_g", "vq")


def _inv(a: float) -> float:
    return math.tan(a) - a


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
                raise InputError(f"{name} = {v!r}: must be a finite number > 0")
        for name in ("c_h", "T_p"):
            v = getattr(self, name)
            if not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
                raise InputError(f"{name} = {v!r}: must be a finite number")
        if self.c_h < 0:
            raise InputError(f"c_h = {self.c_h} N s/m: must be >= 0")
        cb = self.c_b if isinstance(self.c_b, (tuple, list)) else (self.c_b, self.c_b)
        if len(cb) != 2 or any((not math.isfinite(c)) or c < 0 for c in cb):
            raise InputError(f"c_b = {self.c_b!r} N s/m: must be >= 0 (one value or pinion, gear)")
        object.__setattr__(self, "c_b", (float(cb[0]), float(cb[1])))
        if not (0 < self.alpha < math.pi / 2):
            raise InputError(f"alpha = {self.alpha} rad: must be in (0, pi/2)")
        if int(self.z_p) != self.z_p or self.z_p < 3:
            raise InputError(f"z_p = {self.z_p}: must be a whole number >= 3")
        L = self.table_periods
        if (isinstance(L, bool) or not isinstance(L, (int, float, np.floating, np.integer))
                or not math.isfinite(L) or int(L) != L or L < 1):
            raise InputError(f"table_periods = {L!r}: must be a whole number >= 1 (mesh "
                             f"periods spanned by the stiffness tables)")
        object.__setattr__(self, "table_periods", int(L))
        P = self.table_period_rad
        phi = np.asarray(self.phi_table, dtype=float).ravel()
        k = np.asarray(self.k_table, dtype=float).ravel()
        if phi.size < 2 or k.shape != phi.shape:
            raise InputError(f"k_table: needs >= 2 points and the shape of phi_table "
                             f"({phi.size}), got {k.size}")
        if not (np.all(np.isfinite(phi)) and np.all(np.diff(phi) > 0) and phi[0] >= 0
                and phi[-1] < P * (1 + 1e-12)):
            span = ("one mesh period" if self.table_periods == 1 else
                    f"one table period of {self.table_periods} mesh periods (table_periods)")
            raise InputError(f"phi_table: must be strictly increasing inside {span} "
                             f"[0, {P:.6g}) rad")
        if self.table_periods > 1 and phi[-1] < (self.table_periods - 1) * self.mesh_period_rad * (1 - 1e-12):
            raise InputError(f"phi_table: ends at {phi[-1]:.6g} rad, but table_periods = "
                             f"{self.table_periods} needs a table over [0, {P:.6g}) rad (nodes in "
                             f"each of the {self.table_periods} mesh periods; tile a one-period "
                             f"table or set table_periods = 1)")
        if phi[-1] >= P:
            phi = phi.copy()
            phi[-1] = np.nextafter(P, 0.0)
        if not np.all(np.isfinite(k)) or np.any(k < 0):
            raise InputError("k_table N/m: must be finite and >= 0")
        e = np.zeros_like(phi) if self.e_table is None else np.asarray(self.e_table, float).ravel()
        if e.shape != phi.shape or not np.all(np.isfinite(e)):
            raise InputError(f"e_table m: must be finite with the shape of phi_table ({phi.size})")
        for name, arr in (("phi_table", phi), ("k_table", k), ("e_table", e)):
            arr = arr.copy()
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        for name in ("backlash_half_m", "bearing_half_clearance_m"):
            v = getattr(self, name)
            if v is not None and (not math.isfinite(v) or v < 0):
                raise InputError(f"{name} = {v} m: must be >= 0 (or None: effect absent)")
        if self.centre_distance not in ("static", "dynamic"):
            raise InputError(f"centre_distance = {self.centre_distance!r}: must be "
                             f"'static' or 'dynamic'")
        if self.mesh_damping not in ("off-when-separated", "paper"):
            raise InputError(f"mesh_damping = {self.mesh_damping!r}: must be "
                             f"'off-when-separated' or 'paper'")
        if self.interpolation not in ("linear", "cubic"):
            raise InputError(f"interpolation = {self.interpolation!r}: must be 'linear' or 'cubic'")
        if self.interpolation == "cubic":
            if phi.size < 4:
                raise InputError(f"k_table: cubic interpolation needs >= 4 points, got {phi.size}")
            kc = segment_coefficients(phi, k, P, "cubic")
            d = (np.diff(np.r_[phi, phi[0] + P]))[:, None] * np.linspace(0, 1, 9)[None, :]
            low = np.min(kc[:, 0, None] + d * (kc[:, 1, None] + d * (kc[:, 2, None] + d * kc[:, 3, None])))
            if low < 0:
                raise InputError(f"k_table: its periodic cubic spline goes negative "
                                 f"({low:.4g} N/m) between the rows; use linear interpolation")
        if self.k_constant is not None and (not math.isfinite(self.k_constant) or self.k_constant < 0):
            raise InputError(f"k_constant = {self.k_constant} N/m: must be >= 0")
        if self.centre_distance == "dynamic" and self.C0_m is not None:
            Cn = (self.R_p + self.R_g) / math.cos(self.alpha)
            if abs(self.C0_m - Cn) > 1e-9 * Cn:
                raise InputError(f"C0_m = {self.C0_m} m: must equal (R_p + R_g)/cos(alpha) "
                                 f"= {Cn:.9g} m (alpha is the pressure angle at C0)")

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
        return 1.0 / (self.R_p ** 2 / self.J_p + self.R_g ** 2 / self.J_g)

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


def segment_coefficients(phi, v, P: float, kind: str = "linear") -> np.ndarray:
    """Per-segment polynomial coefficients (n, 4) of the periodic interpolant of the
    table (phi in [0, P), values v): on [phi_j, phi_j+1) (the last segment wraps to
    phi_0 + P) v(phi) = c0 + c1 d + c2 d^2 + c3 d^3 with d = phi - phi_j. ``linear``:
    the piecewise-linear interpolant (positivity preserving, exact for piecewise-linear
    data); ``cubic``: scipy's periodic cubic spline (C2, 4th order for smooth data)."""
    x = np.r_[phi, phi[0] + P]
    y = np.r_[v, v[0]]
    c = np.zeros((len(phi), 4))
    if kind == "cubic":
        from scipy.interpolate import CubicSpline
        cs = CubicSpline(x, y, bc_type="periodic")
        c[:] = cs.c[::-1].T
    else:
        c[:, 0] = y[:-1]
        c[:, 1] = np.diff(y) / np.diff(x)
    return c


def table_mean(phi, v, P: float, kind: str = "linear") -> float:
    """Mean of the periodic interpolant of a table over its period P (exact per segment;
    a plain average of the rows would misweight a non-uniform table)."""
    phi = np.asarray(phi, float)
    c = segment_coefficients(phi, np.asarray(v, float), P, kind)
    w = np.diff(np.r_[phi, phi[0] + P])
    return float(np.sum(c[:, 0] * w + c[:, 1] * w ** 2 / 2 + c[:, 2] * w ** 3 / 3 + c[:, 3] * w ** 4 / 4) / P)


def _table_mean(model: GearDynamics, v: np.ndarray) -> float:
    return table_mean(model.phi_table, v, model.table_period_rad, model.interpolation)


def damping_from_ratios(zeta_m: float, zeta_b: float, k_mean: float, m_e: float, k_b: float,
                        m_p: float, m_g: float) -> tuple[float, tuple[float, float]]:
    """Viscous damping from damping ratios: ``c_h = 2 zeta_m sqrt(k_mean m_e)`` (mesh, on
    the reduced torsional mass m_e) and ``c_b = 2 zeta_b sqrt(k_b m)`` for the pinion's and
    the gear's bearing (m = m_p, m_g); c = 2 zeta sqrt(k m) is the damping that gives a
    single-DOF oscillator the ratio zeta of critical damping. Ratios dimensionless,
    stiffnesses N/m, masses kg; returns (c_h, (c_b_p, c_b_g)) in N s/m. The one home of
    this conversion (scenes and presets call it)."""
    return (2 * zeta_m * math.sqrt(k_mean * m_e),
            (2 * zeta_b * math.sqrt(k_b * m_p), 2 * zeta_b * math.sqrt(k_b * m_g)))


# ---------------------------------------------------------------------------------------
# Derived constants shared by the compiled kernels and the Python reference right-hand side
# ---------------------------------------------------------------------------------------
# parameter vector layout
(P_MP, P_MG, P_ME, P_FS, P_KB, P_CBP, P_CBG, P_CH, P_SA, P_CA, P_KC, P_B, P_BB, P_OM,
 P_PER, P_C0, P_RS, P_INV0, P_PAPER, P_UNI, P_DPHI, P_PHI0, P_N) = range(23)
N_PAR = 23


def derived(model: GearDynamics):
    """Parameter vector (``par[P_PER]`` is the table period in rad, ``table_period_rad``),
    the table nodes, the periodic-extended nodes phx (n + 2) and the
    k and e interpolants' coefficients per extended segment (n + 1, 4), see
    :func:`segment_coefficients` (computed once per model instance, read-only arrays)."""
    return model._derived


def _compute_derived(model: GearDynamics):
    P = model.table_period_rad          # par[P_PER]: the period of the tables
    phi = np.asarray(model.phi_table, float)
    n = phi.size
    par = np.zeros(N_PAR)
    par[P_MP], par[P_MG], par[P_ME] = model.m_p, model.m_g, model.m_e
    par[P_FS] = model.F_s
    par[P_KB] = model.k_b
    par[P_CBP], par[P_CBG] = model.c_b_pair
    par[P_CH] = model.c_h
    par[P_SA], par[P_CA] = math.sin(model.alpha), math.cos(model.alpha)
    par[P_KC] = model.k_mean
    par[P_B] = model.backlash_half_m or 0.0
    par[P_BB] = model.bearing_half_clearance_m or 0.0
    par[P_OM] = model.omega_p
    par[P_PER] = P
    par[P_C0] = model.C0
    par[P_RS] = model.R_p + model.R_g
    par[P_INV0] = _inv(math.acos(min(1.0, par[P_RS] / par[P_C0])))
    par[P_PAPER] = 1.0 if model.mesh_damping == "paper" else 0.0
    d = P / n
    uniform = np.allclose(np.diff(phi), d, rtol=1e-9, atol=0) and abs(phi[0]) < d * (1 - 1e-9)
    par[P_UNI] = 1.0 if uniform else 0.0
    par[P_DPHI] = d
    par[P_PHI0] = phi[0]
    par[P_N] = n
    phx = np.concatenate(([phi[-1] - P], phi, [phi[0] + P]))
    out = [par, phi, phx]
    for tab in (model.k_table, model.e_table):
        c = segment_coefficients(phi, np.asarray(tab, float), P, model.interpolation)
        # extended segments: [phi_-1 - P, phi_0) is the wrap segment, then the n table segments
        out.append(np.ascontiguousarray(np.vstack([c[-1:], c])))
    for a in out:
        a.setflags(write=False)
    return tuple(out)


def _eval_coefficients(phx, c, u):
    """Value and d/dphi of the extended-table interpolant at phases u in [0, P)."""
    i = np.clip(np.searchsorted(phx, u, side="right") - 1, 0, phx.size - 2)
    d = u - phx[i]
    c0, c1, c2, c3 = c[i, 0], c[i, 1], c[i, 2], c[i, 3]
    return c0 + d * (c1 + d * (c2 + d * c3)), c1 + d * (2 * c2 + 3 * d * c3)


def _table_eval(model: GearDynamics, t, which: str):
    """The periodic table interpolant (``model.interpolation``) and its time derivative at t."""
    par, phi, phx, kc, ec = derived(model)
    P = par[P_PER]
    ph = model.omega_p * np.asarray(t, float)
    u = ph - P * np.floor(ph / P)
    val, dv = _eval_coefficients(phx, kc if which == "k" else ec, u)
    return val, dv * model.omega_p


def _breaks(model: GearDynamics, c: np.ndarray, rel: float = 1e-12) -> np.ndarray:
    """Per table node: is it a break of the interpolant (extended coefficients c)? Linear:
    where the slope jumps (collinear nodes are not); cubic spline: every node (its third
    derivative jumps)."""
    if model.interpolation == "cubic":
        return np.ones(c.shape[0] - 1, dtype=bool)
    scale = float(np.max(np.abs(c[:, 1]))) or 1.0
    return np.abs(np.diff(c[:, 1])) > rel * scale


def rk4_schedule(model: GearDynamics, steps_per_period: int, snap: float = 1e-9):
    """The fixed-step RK4 grid of one table period, split at the table's breaks.

    Steps are h = T_m / N from t = 0 (``steps_per_period`` = N per *mesh* period), so the
    grid repeats every table period of L = ``table_periods`` mesh periods: the schedule
    holds L N steps (for L = 1 one mesh period, as before). The
    periodic linear interpolant has a kink at every table node; RK4 across a kink is
    only second-order accurate (Simpson's rule on a function with a slope jump), so a
    step that contains nodes is split into sub-steps that end on them. Each sub-step
    then sees a polynomial k(t) and e(t), sampled exactly at its three stage times
    (start, middle, end), and RK4 keeps its 4th order for any table length and any N.
    A node within ``snap`` steps of a step boundary is taken as on it (its error is
    O(snap h^2)).

    Returns (hs, toff, kq, eq, dkq, deq, ends): sub-step lengths in s (Q,), the time of
    each sub-step's end from the start of the table period (Q,), k and e at the 3Q stage
    times (start, middle, end of each sub-step), dk/dt and de/dt at each sub-step's
    middle (Q,; the energy accumulators) and a 0/1 flag per sub-step that ends on a
    step boundary."""
    par, phi, phx, kc, ec = derived(model)
    P = par[P_PER]
    N = int(steps_per_period) * model.table_periods     # steps per table period
    dph = P / N
    bounds = np.arange(N + 1) * dph
    nodes = np.asarray(phi, float)[_breaks(model, kc) | _breaks(model, ec)]
    rel = nodes / dph
    off = np.abs(rel - np.rint(rel)) < snap
    pts = np.union1d(bounds, nodes[~off])
    a, b = pts[:-1], pts[1:]
    mid = 0.5 * (a + b)
    # each stage on the segment that holds the sub-step (a sub-step never crosses a break)
    seg = np.clip(np.searchsorted(phx, mid, side="right") - 1, 0, phx.size - 2)
    w = model.omega_p
    out = [np.diff(pts) / w, b / w]
    d = np.column_stack([a, mid, b]) - phx[seg][:, None]
    for c in (kc, ec):
        cs = c[seg]
        out.append((cs[:, 0, None] + d * (cs[:, 1, None] + d * (cs[:, 2, None] + d * cs[:, 3, None]))).ravel())
    for c in (kc, ec):
        cs = c[seg]
        dm = d[:, 1]
        out.append((cs[:, 1] + dm * (2 * cs[:, 2] + 3 * dm * cs[:, 3])) * w)
    on_bound = np.abs(b / dph - np.rint(b / dph)) < 1e-12 * N
    out.append(on_bound.astype(np.int64))
    return tuple(out)


def table_node_times(model: GearDynamics, t0: float, t1: float) -> np.ndarray:
    """Times in (t0, t1) at which the pinion angle passes a table node (the breaks of the
    k and e interpolants; the table repeats every table period); empty when neither
    table varies."""
    if not (model.tvms or model.te_excitation):
        return np.empty(0)
    P = model.table_period_rad
    w = model.omega_p
    phi = derived(model)[1]
    m = np.arange(np.floor(w * t0 / P) - 1, np.ceil(w * t1 / P) + 1)
    t = ((phi[None, :] + P * m[:, None]) / w).ravel()
    return np.sort(t[(t > t0) & (t < t1)])


def mesh_geometry(model: GearDynamics, z):
    """Mesh kinematics for states z (..., >= 10), vectorised.

    Returns (delta, delta_dot, b, G, Gb, sin_a, cos_a): the relative mesh displacement,
    its rate, the backlash half-width, G = d delta / d(y_p, x_p, y_g, x_g, q) (..., 5) and
    Gb = d b / d(y_p, x_p, y_g, x_g) (..., 4; zero for the static coupling)."""
    z = np.asarray(z, float)
    shape = z.shape[:-1]
    Y = z[..., 0] - z[..., 2]
    if model.centre_distance == "dynamic":
        Rs = model.R_p + model.R_g
        dx = model.C0 + z[..., 3] - z[..., 1]
        dy = z[..., 2] - z[..., 0]
        C = np.hypot(dx, dy)
        ca = np.minimum(Rs / C, 1.0)
        sa = np.sqrt(1.0 - ca * ca)
        dC = np.stack([-dy / C, -dx / C, dy / C, dx / C], axis=-1)
        dca = -ca / C
        G = np.zeros(shape + (5,))
        G[..., :4] = (Y * dca)[..., None] * dC
        G[..., 0] += ca
        G[..., 2] -= ca
        G[..., 4] = 1.0
        b = (model.backlash_half_m or 0.0) + Rs * (sa / ca - np.arctan2(sa, ca) - _inv(model.alpha))
        Gb = sa[..., None] * dC
        delta = z[..., 4] + Y * ca
    else:
        sa = np.full(shape, math.sin(model.alpha))
        ca = np.full(shape, math.cos(model.alpha))
        G = np.zeros(shape + (5,))
        G[..., 0], G[..., 1], G[..., 2], G[..., 3], G[..., 4] = ca, sa, -ca, -sa, 1.0
        Gb = np.zeros(shape + (4,))
        b = np.full(shape, model.backlash_half_m or 0.0)
        delta = z[..., 4] + (z[..., 1] - z[..., 3]) * sa + Y * ca
    ddelta = np.sum(G * z[..., 5:10], axis=-1)
    return delta, ddelta, b, G, Gb, sa, ca


def has_flank_law(model: GearDynamics) -> bool:
    """Backlash dead zone / two-flank contact law in use (backlash, or dynamic coupling)."""
    return model.backlash_half_m is not None or model.centre_distance == "dynamic"


def mesh_state(model: GearDynamics, t, z, k=None, e=None):
    """Vectorised mesh quantities for times t (N,) and states z (N, >=10).

    Contact law: drive flank in contact when s > b (spring k (s - b)), back flank when
    s < -b (spring k (s + b)); with b >= 0 at most one of them. Without backlash (static
    coupling) the mesh is a linear two-sided spring k s. Returns delta, delta_dot,
    s = delta - e, k_h, e, b, drive/back contact flags, mode (+1 drive, -1 back,
    0 separated, 2 both flanks), F_m (normal mesh force), F_damp, V_mesh and the force
    directions. ``k``/``e`` override the tables (static equilibrium)."""
    t = np.asarray(t, float)
    z = np.asarray(z, float)
    delta, ddelta, b, G, Gb, sa, ca = mesh_geometry(model, z)
    if k is not None:
        k, dk = np.full(delta.shape, float(k)), np.zeros(delta.shape)
    elif model.tvms:
        k, dk = _table_eval(model, t, "k")
    else:
        k, dk = np.full(delta.shape, model.k_mean), np.zeros(delta.shape)
    if e is not None:
        e, de = np.full(delta.shape, float(e)), np.zeros(delta.shape)
    elif model.te_excitation:
        e, de = _table_eval(model, t, "e")
    else:
        e, de = np.zeros(delta.shape), np.zeros(delta.shape)
    s = delta - e
    if has_flank_law(model):
        drive = s > b
        back = s < -b
        fd = np.where(drive, s - b, 0.0)
        fb = np.where(back, s + b, 0.0)
        damp_on = drive | back | (model.mesh_damping == "paper")
    else:
        drive = np.ones(s.shape, dtype=bool)
        back = np.zeros(s.shape, dtype=bool)
        fd = s
        fb = np.zeros(s.shape)
        damp_on = np.ones(s.shape, dtype=bool)
    mode = np.where(drive & back, 2, np.where(drive, 1, np.where(back, -1, 0)))
    Fd = np.where(damp_on, model.c_h * ddelta, 0.0)
    F = Fd + k * (fd + fb)
    return dict(delta=delta, delta_dot=ddelta, s=s, k_h=k, dk_dt=dk, e=e, de_dt=de, b=b,
                drive=drive, back=back, mode=mode, f_drive=fd, f_back=fb, F_damp=Fd, F_m=F,
                V_mesh=0.5 * k * (fd * fd + fb * fb), G=G, Gb=Gb, sin_a=sa, cos_a=ca)


def bearing_f(model: GearDynamics, u):
    """Bearing dead-zone function f_b (paper Eqs. 7-10) of half-width b_b."""
    u = np.asarray(u, float)
    if model.bearing_half_clearance_m is None:
        return u
    bb = model.bearing_half_clearance_m
    return np.where(u > bb, u - bb, np.where(u < -bb, u + bb, 0.0))


def _accelerations(model: GearDynamics, t, z, k=None, e=None) -> np.ndarray:
    ms = mesh_state(model, t, z, k, e)
    # generalised mesh forces: -F G + k (f_drive - f_back) Gb
    Q = -ms["F_m"][..., None] * ms["G"]
    Q[..., :4] += (ms["k_h"] * (ms["f_drive"] - ms["f_back"]))[..., None] * ms["Gb"]
    cbp, cbg = model.c_b_pair
    fb = bearing_f(model, z[..., :4])
    a = np.empty(z.shape[:-1] + (5,))
    a[..., 0] = (Q[..., 0] - cbp * z[..., 5] - model.k_b * fb[..., 0]) / model.m_p
    a[..., 1] = (Q[..., 1] - cbp * z[..., 6] - model.k_b * fb[..., 1]) / model.m_p
    a[..., 2] = (Q[..., 2] - cbg * z[..., 7] - model.k_b * fb[..., 2]) / model.m_g
    a[..., 3] = (Q[..., 3] - cbg * z[..., 8] - model.k_b * fb[..., 3]) / model.m_g
    a[..., 4] = (model.F_s + Q[..., 4]) / model.m_e
    return a


def rhs_python(t: float, y, model: GearDynamics) -> np.ndarray:
    """Pure-Python right-hand side of the same model (for scipy.integrate.solve_ivp).

    Scalar ``math`` code written independently of the vectorised ``mesh_state`` and of
    the compiled kernel (a cross-check of both). The piecewise modes (flank contact,
    bearing contact) are evaluated from the state; no event location. ``y`` is the
    10-state vector (extra entries are ignored)."""
    par, phx, kc, ec = model._py_constants
    yp, xp, yg, xg, q, vyp, vxp, vyg, vxg, vq = (float(v) for v in y[:10])
    Rs = model.R_p + model.R_g
    Y = yp - yg
    if model.centre_distance == "dynamic":
        dx = model.C0 + xg - xp
        dy = yg - yp
        C = math.hypot(dx, dy)
        ca = min(Rs / C, 1.0)
        sa = math.sqrt(1.0 - ca * ca)
        b = (model.backlash_half_m or 0.0) + Rs * (sa / ca - math.atan2(sa, ca) - _inv(model.alpha))
        dC = (-dy / C, -dx / C, dy / C, dx / C)
        w = -Y * ca / C
        G = (ca + w * dC[0], w * dC[1], -ca + w * dC[2], w * dC[3])
        Gb = tuple(sa * c for c in dC)
        delta = q + Y * ca
    else:
        sa, ca = math.sin(model.alpha), math.cos(model.alpha)
        b = model.backlash_half_m or 0.0
        G = (ca, sa, -ca, -sa)
        Gb = (0.0, 0.0, 0.0, 0.0)
        delta = q + (xp - xg) * sa + Y * ca
    dd = vq + G[0] * vyp + G[1] * vxp + G[2] * vyg + G[3] * vxg
    P = par[P_PER]
    ph = model.omega_p * t
    u = ph - P * math.floor(ph / P)

    def interp(c):
        i = min(max(bisect.bisect_right(phx, u) - 1, 0), len(phx) - 2)
        d = u - phx[i]
        return c[i][0] + d * (c[i][1] + d * (c[i][2] + d * c[i][3]))

    k = interp(kc) if model.tvms else par[P_KC]
    e = interp(ec) if model.te_excitation else 0.0
    s = delta - e
    if has_flank_law(model):
        fdv = s - b if s > b else 0.0
        fbk = s + b if s < -b else 0.0
        on = fdv != 0.0 or fbk != 0.0 or s > b or s < -b or model.mesh_damping == "paper"
        fd = model.c_h * dd if on else 0.0
    else:
        fdv, fbk, fd = s, 0.0, model.c_h * dd
    F = fd + k * (fdv + fbk)
    kf = k * (fdv - fbk)
    Q = [-F * G[j] + kf * Gb[j] for j in range(4)]
    bb = model.bearing_half_clearance_m

    def fb(x):
        if bb is None:
            return x
        return x - bb if x > bb else (x + bb if x < -bb else 0.0)

    cbp, cbg = model.c_b_pair
    kb = model.k_b
    return np.array([vyp, vxp, vyg, vxg, vq,
                     (Q[0] - cbp * vyp - kb * fb(yp)) / model.m_p,
                     (Q[1] - cbp * vxp - kb * fb(xp)) / model.m_p,
                     (Q[2] - cbg * vyg - kb * fb(yg)) / model.m_g,
                     (Q[3] - cbg * vxg - kb * fb(xg)) / model.m_g,
                     (model.F_s - F) / model.m_e])


def static_equilibrium(model: GearDynamics) -> np.ndarray:
    """Static equilibrium (10 states, zero velocities) under the mean stiffness and the mean
    excitation: F_m = F_s, bearings deflected by F_s cos/sin over k_b (plus the half
    clearance), delta = e_mean + b + F_s / k_mean (drive side; back side for F_s < 0).
    With the dynamic centre distance the closed form is the start of a Newton solve."""
    F = model.F_s
    k = model.k_mean
    if F != 0 and k <= 0:
        raise InputError("k_table: mean mesh stiffness is 0 N/m, no static "
                         "equilibrium under load")
    sgn = 1.0 if F > 0 else (-1.0 if F < 0 else 0.0)
    bb = model.bearing_half_clearance_m or 0.0
    sa, ca, b = math.sin(model.alpha), math.cos(model.alpha), model.backlash_half_m or 0.0

    def bear(force):
        return 0.0 if force == 0 else force / model.k_b + math.copysign(bb, force)

    z = np.zeros(10)
    z[0], z[1], z[2], z[3] = bear(-F * ca), bear(-F * sa), bear(F * ca), bear(F * sa)
    delta = model.e_mean + sgn * b + (F / k if F != 0 else 0.0)
    z[4] = delta - (z[1] - z[3]) * sa - (z[0] - z[2]) * ca
    if model.centre_distance != "dynamic":
        return z
    from scipy.optimize import root

    xs = max(abs(F) / model.k_b, abs(F) / max(k, 1.0), 1e-9)   # scale to O(1) unknowns
    em = model.e_mean

    def resid(u):
        zz = np.zeros(10)
        zz[:5] = z[:5] + u * xs
        return _accelerations(model, np.array(0.0), zz, k=k, e=em) * np.array(
            [model.m_p, model.m_p, model.m_g, model.m_g, model.m_e]) / max(abs(F), 1.0)

    # start: delta of the dynamic form (no x-projection) on the drive flank
    z0 = z.copy()
    d0, _, b0, *_ = mesh_geometry(model, z0)
    z[4] += (em + sgn * float(b0) + (F / k if F != 0 else 0.0)) - float(d0)
    sol = root(resid, np.zeros(5), method="hybr", options=dict(xtol=1e-14))
    z[:5] = z[:5] + sol.x * xs
    return z


def linear_eigenfrequencies(model: GearDynamics) -> np.ndarray:
    """Natural frequencies (Hz, ascending) of the linearised, undamped 5-DOF model: mean
    mesh stiffness, no backlash, no bearing clearance, operating pressure angle alpha."""
    from scipy.linalg import eigh

    M, _, K = _linear_matrices(model, model.k_mean)
    lam = eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(lam, 0, None)) / (2 * math.pi)


def _linear_matrices(model: GearDynamics, k: float):
    """M, C, K of the linearised 5-DOF model (mesh spring k and damper c_h on the line of
    action g = d delta / d(y_p, x_p, y_g, x_g, q), bearings k_b and c_b, no dead zones)."""
    ca, sa = math.cos(model.alpha), math.sin(model.alpha)
    g = np.array([ca, sa, -ca, -sa, 1.0])
    cbp, cbg = model.c_b_pair
    K = np.diag([model.k_b] * 4 + [0.0]) + k * np.outer(g, g)
    C = np.diag([cbp, cbp, cbg, cbg, 0.0]) + model.c_h * np.outer(g, g)
    M = np.diag([model.m_p, model.m_p, model.m_g, model.m_g, model.m_e])
    return M, C, K


def max_linear_rate(model: GearDynamics, k: float | None = None) -> float:
    """Largest |eigenvalue| (rad/s) of the linearised first-order system
    z' = [[0, I], [-M^-1 K, -M^-1 C]] z at mesh stiffness k (default: the mean). It sets
    the step an explicit integrator can take: RK4 is stable for h |lambda| up to ~2.8."""
    M, C, K = _linear_matrices(model, model.k_mean if k is None else k)
    Mi = np.diag(1.0 / np.diag(M))
    A = np.block([[np.zeros((5, 5)), np.eye(5)], [-Mi @ K, -Mi @ C]])
    return float(np.max(np.abs(np.linalg.eigvals(A))))
