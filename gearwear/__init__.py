"""gearwear: FE-verified mesh stiffness and dynamics of worn spur gears.

This package is the composition root: scenes, stiffness tables, sweeps, reports
and the ``gearwear`` command line. It wires ``geometry``, ``analytic``, ``fem`` and
``dynamics`` together (see DESIGN.md for the one-way dependency direction).
"""

__version__ = "0.1.0"
