"""Write the synthetic measurements of examples/diagnose (run from the repository root):

    .venv/bin/python examples/diagnose/make_measurements.py

SYNTHETIC: made by gearwear's full model (``gearwear simulate`` of scene.toml), not
measured on a test rig. Truth: maximum wear depth 18 um, bearing clearance 24 um.

* measured_timeseries.csv: y_p_um, x_p_um, delta_um over the last 8 mesh periods of the
  simulation, every 4th sample (64 per mesh period, 38.4 kHz), no noise added;
* measured_harmonics.csv: the harmonic table (signal,harmonic,amplitude) of F_m_N and
  y_p_um, harmonics 1-10 from the same run, each multiplied by 1 + 0.02 eps,
  eps ~ N(0, 1) (numpy default_rng(2019)): 2 % measurement noise.
"""

from pathlib import Path

import numpy as np

from gearwear.diagnose.features import SIGNALS, time_series_features
from gearwear.diagnose.job import perturb
from gearwear.diagnose.surrogate import scene_at
from gearwear.jobs.simulate import run
from gearwear.scene.files import load_scene_dict

HERE = Path(__file__).resolve().parent
TRUTH = {"wear": 18.0, "clearance": 24.0}

raw, name = load_scene_dict(str(HERE / "scene.toml"))
r = run(scene_at(raw, name, TRUTH)).result
S = int(round(r.fs_Hz / r.fm_Hz))
keep = slice(-8 * S, None, 4)
cols = ["y_p_um", "x_p_um", "delta_um"]
data = np.column_stack([r.t[keep]] + [r.signals[SIGNALS[c][0]][keep] * SIGNALS[c][1] for c in cols])
header = (
    "# SYNTHETIC measurement from gearwear simulate (examples/diagnose/make_measurements.py): "
    "wear_max_depth_um = 18, clearance_um = 24\ntime_s," + ",".join(cols)
)
np.savetxt(HERE / "measured_timeseries.csv", data, delimiter=",", header=header, comments="", fmt="%.10g")

vals, _ = time_series_features(
    r.t, {c: r.signals[SIGNALS[c][0]] * SIGNALS[c][1] for c in ("F_m_N", "y_p_um")}, r.fm_Hz, 10
)
noisy = perturb({f: v for f, v in vals.items() if f[1] > 0}, 0.02, 0.0, np.random.default_rng(2019))
lines = [
    "# SYNTHETIC measurement from gearwear simulate with 2 % noise (examples/diagnose/make_measurements.py): "
    "wear_max_depth_um = 18, clearance_um = 24",
    "signal,harmonic,amplitude",
]
lines += [f"{s},{k},{v:.6g}" for (s, k), v in noisy.items()]
(HERE / "measured_harmonics.csv").write_text("\n".join(lines) + "\n")
print("wrote", HERE / "measured_timeseries.csv", HERE / "measured_harmonics.csv")
