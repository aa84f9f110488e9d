"""Compiled right-hand side and integrators (numba, no Python per step).

Modules (one idea each; every name stays importable from here)
------------------------------------------------------------------
``kernel_state``   the state as tuples, stage sums, status codes (``ST_*``)
``kernel_rhs``     mesh kinematics, contact laws, the right-hand side, switching functions
``kernel_tables``  the table interpolant at a time (adaptive steps)
``kernel_rk4``     fixed-step RK4 on the precomputed schedule: ``rk4``
``kernel_dp_step`` one Dormand-Prince 5(4) step, its dense output, energy quadratures
``kernel_events``  event detection, location (Illinois) and record (``EV_*``)
``kernel_dopri5``  the adaptive driver: ``dopri5``
``kernel_cache``   numba's disk cache keyed on all of these files (an edit recompiles all)
``kernels``        this overview and ``rhs_at`` (the right-hand side at a time, for tests)

Specialisation mechanism
------------------------
Every effect switch is passed to the kernels as an argument that is either ``None``
(effect absent) or ``True`` (effect present): ``sw_tv`` (time-varying stiffness),
``sw_bl`` (backlash / two-flank law), ``sw_cl`` (bearing clearance), ``sw_te``
(transmission-error excitation), ``sw_dyn`` (dynamic centre distance), ``sw_en``
(energy accumulators). Numba compiles one specialisation per argument *type*
signature, so each effect set gets its own machine code; inside it every
``if sw is not None:`` test is on a ``NoneType`` or ``bool`` argument and numba's
dead-branch pruning removes the disabled branches before type inference (absent
effects cost nothing, not even a test). The specialisations are cached on disk
(``cache=True``), stamped with the content of every kernel source (``kernel_cache``).

Speed structure
---------------
The right-hand side works on scalars: the state is a 10-tuple, the parameters a
tuple of floats, and the result a tuple. Tuples are values in numba (no reference
counting, no heap). ``_rhs`` (``kernel_rhs``) is inlined at numba's IR level (``inline="always"``)
into RK4's four stages: left to LLVM it stayed a call that copied the 23-value parameter
tuple four times per step (1.33x a plain C loop; inlined 0.95x, ``benchmarks/bench_rk4_vs_c.py``).
Dormand-Prince calls it through ``_rhs_frozen``, one compiled copy for its 7 stages and
restarts: 8 inlined copies were most of a cold dopri5 compile, and its step is dominated by
error control, dense output and event checks.

Compile cost (issue 27)
-----------------------
A first run compiles every kernel function of its effect set (from an empty numba cache).
Most of that is numba's own typing and lowering, not LLVM's optimisation (``NUMBA_OPT=0``
saved a quarter of it: 13.5 -> 10.2 s CPU for dopri5 with every effect), so the cost
follows the amount of code numba processes: the functions only kernels call carry no
CPython or C wrapper (``kernel_state.INNER``), ``_rhs`` is compiled once for dopri5, and
numpy helpers that compile their own overloads on a first call (slice stores, ``np.zeros``,
``searchsorted``) are written as loops. ``benchmarks/bench_compile.py``
measures the cold compile per effect set in CPU seconds.

The stiffness contract
----------------------
The solver sees the periodic interpolant of the table (linear by default, or a periodic
cubic spline, ``GearDynamics.interpolation``), at the exact time of every stage:

* RK4 (fixed step ``h = T_m / N`` from t = 0): the step grid repeats every table
  period (``table_periods`` mesh periods; ``p[P_PER]`` is that period in rad, the mesh
  period for a one-period table), so ``table_time.rk4_schedule`` builds one table period's
  grid (``table_periods * N`` steps) once, before integrating. Every stage reads k and e,
  the interpolant, exactly at its own time (the loop reads them by index; no
  interpolation in the hot loop). Steps are split into sub-steps ending on the table's
  breaks only where the breaks' error would show (``table_time.split_nodes``): RK4
  integrates the explicit time dependence of the mesh force F = c_h delta' + k(t) (delta -
  e(t)) by Simpson's rule, so the breaks j inside a (sub-)step of h s make, to leading
  order in h omega_max, the error of a mesh-force impulse

      I = Sk (delta - e) - k Se,   Sk = sum_j h^2 E_1(theta_j) [dk/dt]_j  (N s/m),
      Se = sum_j h^2 E_1(theta_j) [de/dt]_j  (m s),   -1/72 <= E_1 <= 1/24

  (E_1 Simpson's Peano kernel for a slope jump [.] at theta_j h; cubic spline: h^4
  E_3 [d^3 k/dt^3], |E_3| <= 1/1152): q' is off by I / m_e, the bearing velocities by
  I cos a / m, I sin a / m (``table_time.kink_defect`` gives Sk and Se per sub-step;
  ``tests/test_rk4_dense_tables.py`` checks the term to 5 % against a resolved step).
  A step whose signed sums exceed SPLIT_WEIGHT = 1e-6 of its mean impulse
  (|Sk| / (h k_m) + |Se| / (h delta_s)) is split at its breaks, and so is a step that
  holds at most 2 breaks (the table as coarse as the steps there); the largest sums
  first, at most 8 splits per step on average over the period. So sharp edges and jumps
  are split and a coarse table at every kink (4th order, the schedule as before), not
  smooth stretches sampled finer than the steps, whose kinks' Simpson errors cancel to
  the table's own interpolation error. The cost is at most 9 sub-steps per step on
  average, and one per step for a smooth table with more than 2 rows per step and >= 2048
  rows per mesh period (a 4096-row user table at 256 steps: 256 sub-steps per period,
  was 4096).
* Dormand-Prince: every step ends on the next table node (the interpolant's kinks
  are at known times), so each step integrates a polynomial right-hand side; inside
  a step the table segment is fixed and evaluated at each stage time. Switching events
  (flank contact, bearing contact) are located and stepped to, and those inside the
  output window are returned with the state and both one-sided derivatives, so that the
  exact window integrals split there too (``analysis.event_pieces``).

State ``z``: y_p, x_p, y_g, x_g, q, then their velocities; with the energy switch four
quadrature states follow: input work int F_s q' dt, dissipated energy, parametric
stiffness work int 1/2 (dk/dt) f^2 dt and excitation work -int k f de/dt dt.

Status codes returned by the integrators: 0 finished, 1 step budget exhausted,
2 step size below the minimum, 3 diverged (non-finite or unbounded state).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import kernel_cache
from .kernel_dopri5 import dopri5
from .kernel_events import EV_COLS, EV_F0, EV_F1, EV_T, EV_Z
from .kernel_rhs import NG, _rhs
from .kernel_rk4 import rk4
from .kernel_state import ST_BUDGET, ST_DIVERGED, ST_HMIN, ST_OK, _put, _tup
from .kernel_tables import _segment, _table_at

__all__ = [
    "rk4",
    "dopri5",
    "rhs_at",
    "NG",
    "ST_OK",
    "ST_BUDGET",
    "ST_HMIN",
    "ST_DIVERGED",
    "EV_T",
    "EV_Z",
    "EV_F0",
    "EV_F1",
    "EV_COLS",
]


@njit(cache=True)
def rhs_at(t, z, p, phx, kx, ex, sw_tv, sw_bl, sw_cl, sw_te, sw_dyn, sw_en):
    """The compiled right-hand side at time t with the contact modes from the state
    (what RK4 integrates), as a 14-array (10 states, 4 energy rates): for tests."""
    i, m = _segment(t, p, phx)
    k, e, dk, de = _table_at(t, i, m, p, phx, kx, ex, sw_tv, sw_te)
    dz, F, w = _rhs(_tup(z), k, e, dk, de, p, None, sw_bl, sw_cl, sw_dyn, sw_en)
    out = np.zeros(14)
    _put(out, dz, w, sw_en)
    return out


# numba's disk cache keyed on every kernel source, not only each function's own file
# (dynamics.kernel_cache); before the first kernel call
kernel_cache.key_on_sources(__package__)
