"""Writes k.csv: a smooth closed-form mesh stiffness and excitation over one mesh period
of a 30-tooth pinion (12 deg), sampled at 4096 rows. The same closed form is the
independent reference in tests/test_user_table.py:

    k(u) = 3.5e8 (1 + 0.25 cos 2 pi u + 0.08 sin 4 pi u)   N/m
    e(u) = 0.5 sin 2 pi u + 0.2 cos 4 pi u                  um
    u = angle / 12 deg

The dynamics integrates the periodic *linear* interpolant of the rows. Linear
interpolation scales a table harmonic of order n by sinc^2(n / 4096), i.e. by
1 - n^2 1.96e-7, so this table holds the closed form's harmonics to 8e-7; richer
content (a 3rd harmonic) would differ from its closed form by n^2 2e-7 in the
response harmonic n: the table's own resolution, not the solver's error.
"""

from pathlib import Path

import numpy as np

N = 4096
PERIOD_DEG = 12.0


def k_closed(u):
    return 3.5e8 * (1 + 0.25 * np.cos(2 * np.pi * u) + 0.08 * np.sin(4 * np.pi * u))


def e_closed_um(u):
    return 0.5 * np.sin(2 * np.pi * u) + 0.2 * np.cos(4 * np.pi * u)


if __name__ == "__main__":
    u = np.arange(N) / N
    rows = np.column_stack([u * PERIOD_DEG, k_closed(u), e_closed_um(u)])
    out = Path(__file__).with_name("k.csv")
    np.savetxt(
        out,
        rows,
        delimiter=",",
        header="angle_deg,k_N_per_m,excitation_um",
        comments="",
        fmt=["%.12g", "%.12g", "%.12g"],
    )
    print(f"wrote {out}")
