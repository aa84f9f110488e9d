"""6-DOF bending-torsion spur-gear dynamics (paper Eqs. 7-10, 17-20), compiled kernels.

``dynamics`` receives the mesh stiffness as arrays (pinion angle over one mesh period
-> k_h, wear excitation e) and plain parameters; it never imports ``analytic``, ``fem``
or ``gearwear``. See ``dynamics.model`` for the equations and the paper corrections,
``dynamics.kernels`` for the effect specialisation and the integrators.
"""

from .analysis import energy_balance, harmonics, mechanical_energy, spectrum
from .equilibrium import static_equilibrium
from .linear import linear_eigenfrequencies
from .model import STATE_NAMES, GearDynamics, damping_from_ratios
from .presets import paper_pair, rectangular_stiffness
from .reference_rhs import rhs_python
from .simulate import SimResult, compute_signals, kernel_switches, simulate

__all__ = [
    "GearDynamics",
    "SimResult",
    "simulate",
    "harmonics",
    "spectrum",
    "linear_eigenfrequencies",
    "energy_balance",
    "mechanical_energy",
    "rhs_python",
    "static_equilibrium",
    "damping_from_ratios",
    "paper_pair",
    "rectangular_stiffness",
    "kernel_switches",
    "compute_signals",
    "STATE_NAMES",
]
