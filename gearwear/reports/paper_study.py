"""What ``gearwear report paper`` simulates: the paper's wear phases and clearances, the
signals it plots (name, unit, scale from SI, description) and the paper's figure numbers."""

from __future__ import annotations

PHASES = ("unworn", "mild", "severe")
CLEARANCES_UM = (0.0, 20.0, 40.0, 60.0, 80.0, 100.0)
SIGNALS = (
    ("y_p", "um", 1e6, "Y displacement of the pinion"),
    ("x_p", "um", 1e6, "X displacement of the pinion"),
    ("delta", "um", 1e6, "relative displacement delta"),
    ("F_m", "N", 1.0, "mesh force F_m"),
)
WEAR_FIGS = {"y_p": (7, 8), "x_p": (9, 10), "delta": (11, 12), "F_m": (13, 14)}
CLEAR_FIGS = {"y_p": (18, 19), "x_p": (20, 21), "delta": (22, 23), "F_m": (24, 25)}
