"""Measured features for ``gearwear diagnose``: mesh-harmonic amplitudes and mean values.

A feature is ``(signal, k)``: the amplitude of mesh harmonic k (k >= 1) of a signal, or
its mean (k = 0). Signals carry their unit in the name, as in ``gearwear simulate``'s
CSV: ``y_p_um``, ``x_p_um`` (pinion bearing displacement in the line-of-action and
off-line directions, relative to the bearing centre), ``delta_um`` (relative
displacement along the line of action) and ``F_m_N`` (mesh force).

Two file kinds (:func:`read_measurement`):

* a **time series** CSV: ``time_s`` (``t_s``, as ``gearwear simulate`` writes it, is
  accepted too) and any of the four signals. A housing accelerometer must be integrated
  twice to displacement upstream (band-pass first, so the integration does not drift);
  the diagnosis compares displacements. The harmonics are the least-squares Fourier
  coefficients of the last whole mesh periods of the record (the scene gives the speed,
  so f_m = n z_p / 60), which equal the DFT bins for uniform sampling and need no
  whole number of samples per period. The means of ``y_p_um`` and ``x_p_um`` (a bearing
  pressed into its clearance shifts the mean by about BC/2) and of ``F_m_N`` (T / R_b)
  are features too. The mean of ``delta_um`` is not: a transmission-error measurement
  (encoders) has no absolute zero, while the model's delta includes the backlash.
* a **harmonic table** CSV: ``signal,harmonic,amplitude`` rows, e.g. ``F_m_N,3,12.5``.
  It carries no mean values.

A bad file is one line naming the file, the row and the column.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gearwear.core.validation import InputError

#: measurable signals: file column -> (model signal, factor from SI to the column's unit)
SIGNALS: dict[str, tuple[str, float]] = {
    "y_p_um": ("y_p", 1e6),
    "x_p_um": ("x_p", 1e6),
    "delta_um": ("delta", 1e6),
    "F_m_N": ("F_m", 1.0),
}
#: signals whose mean value is a feature (see the module docstring for delta)
MEAN_SIGNALS = ("y_p_um", "x_p_um", "F_m_N")
TIME_COLUMNS = ("time_s", "t_s")

Feature = tuple[str, int]  # (signal column, harmonic k >= 1; 0 = the mean)


def feature_name(f: Feature) -> str:
    """``F_m_N h3`` for harmonic 3, ``y_p_um mean`` for the mean."""
    return f"{f[0]} mean" if f[1] == 0 else f"{f[0]} h{f[1]}"


def all_features(harmonics: int) -> list[Feature]:
    """Every feature a surrogate predicts: harmonics 1..K of each signal, then the means."""
    return [(s, k) for s in SIGNALS for k in range(1, harmonics + 1)] + [(s, 0) for s in MEAN_SIGNALS]


@dataclass
class Measurement:
    """Measured feature values (in the signals' units) and where they came from."""

    source: str
    kind: str  # "time_series" | "harmonics"
    values: dict[Feature, float]
    info: dict = field(default_factory=dict)  # time series: periods, samples per period

    @property
    def features(self) -> list[Feature]:
        return list(self.values)

    @property
    def signals(self) -> list[str]:
        return list(dict.fromkeys(s for s, _ in self.values))


def _bad(path: Path, row: int | None, column: str | None, why: str) -> InputError:
    where = "".join(
        x for x in (f", row {row}" if row is not None else "", f", column {column}" if column is not None else "")
    )
    return InputError(f"--measured {path}{where}: {why}")


def fourier_fit(t: np.ndarray, x: np.ndarray, f0: float, n: int) -> tuple[float, np.ndarray]:
    """(mean, complex c_k, k = 1..n) of x(t) ~ mean + sum Re(c_k e^{i 2 pi k f0 t}) by least
    squares; |c_k| is the amplitude of harmonic k (x = a cos + b sin gives c = a - i b)."""
    w = 2 * math.pi * f0 * np.asarray(t, float)[:, None] * np.arange(1, n + 1)[None, :]
    A = np.hstack([np.ones((w.shape[0], 1)), np.cos(w), np.sin(w)])
    coef = np.linalg.lstsq(A, np.asarray(x, float), rcond=None)[0]
    return float(coef[0]), coef[1 : n + 1] - 1j * coef[n + 1 :]


def time_series_features(
    t: np.ndarray, columns: dict[str, np.ndarray], fm_Hz: float, harmonics: int
) -> tuple[dict[Feature, float], dict]:
    """Harmonic amplitudes 1..K (and the means of MEAN_SIGNALS) over the last whole mesh
    periods of a record; ValueError naming what is missing if the record is too short or
    too coarse for K harmonics."""
    span = float(t[-1] - t[0])
    periods = int(math.floor(span * fm_Hz + 1e-9))
    if periods < 1:
        raise ValueError(
            f"the record spans {span:.6g} s, less than one mesh period ({1 / fm_Hz:.6g} s at the scene's speed)"
        )
    keep = t >= t[-1] - periods / fm_Hz - 1e-12 / fm_Hz
    per_period = (int(np.count_nonzero(keep)) - 1) / periods
    if per_period < 2 * harmonics + 1:
        raise ValueError(
            f"{per_period:.1f} samples per mesh period cannot resolve {harmonics} mesh harmonics "
            f"(at least {2 * harmonics + 1} are needed)"
        )
    values: dict[Feature, float] = {}
    for col, x in columns.items():
        mean, c = fourier_fit(t[keep], x[keep], fm_Hz, harmonics)
        values.update({(col, k + 1): float(abs(ck)) for k, ck in enumerate(c)})
        if col in MEAN_SIGNALS:
            values[(col, 0)] = mean
    return values, {"periods": periods, "samples_per_period": per_period}


def _number(path: Path, row: int, col: str, text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise _bad(path, row, col, f"{text.strip()!r} is not a number") from None
    if not math.isfinite(v):
        raise _bad(path, row, col, f"{text.strip()} is not a finite number")
    return v


#: the largest magnitude a measured value (a sample or an amplitude) may have, per signal, in
#: its unit: 0.1 m of bearing or mesh displacement, 1e10 N of mesh force. Far beyond any gear
#: pair (the teeth leave the mesh at a fraction of the module, at most 100 mm), so a larger
#: value is a wrong unit or a corrupt file; refused when the file is read, before any run.
MAX_MAGNITUDE = {"y_p_um": 1e5, "x_p_um": 1e5, "delta_um": 1e5, "F_m_N": 1e10}


def _plausible(path: Path, row: int, col: str, v: float, signal: str | None = None) -> float:
    """``v`` (of ``signal``, default the column's) if it is within MAX_MAGNITUDE."""
    sig = signal or col
    if abs(v) > MAX_MAGNITUDE[sig]:
        raise _bad(
            path,
            row,
            col,
            f"{v:g} is beyond any physical value of {sig} (|value| <= "
            f"{MAX_MAGNITUDE[sig]:g} in its unit); check the unit and the file",
        )
    return v


#: the largest measurement file read (bytes): 1e6 samples of five signals is ~60 MB
MEASUREMENT_LIMIT_BYTES = 256 << 20


def read_measurement(path: str | Path, fm_Hz: float, harmonics: int) -> Measurement:
    """Read a time-series or harmonic-table CSV (see the module docstring) into features.
    ``harmonics``: the largest harmonic the diagnosis uses (the scene's output.harmonics)."""
    from gearwear.core.inputs import read_input_text

    p = Path(path)
    try:  # once, bounded, a regular file only (a FIFO or /dev/zero is refused, not waited on)
        text = read_input_text(p, "--measured", "file", MEASUREMENT_LIMIT_BYTES)
    except InputError as exc:
        raise _bad(p, None, None, str(exc).split(": ", 1)[1]) from None
    rows = list(csv.reader(line for line in text.splitlines() if line.strip() and not line.startswith("#")))
    if not rows:
        raise _bad(
            p,
            None,
            None,
            "is empty; give a time series (time_s, "
            + ", ".join(SIGNALS)
            + ") or a harmonic table (signal,harmonic,amplitude)",
        )
    header = [h.strip() for h in rows[0]]
    if header == ["signal", "harmonic", "amplitude"]:
        meas = _harmonic_table(p, rows[1:], harmonics)
    else:
        meas = _time_series(p, header, rows[1:], fm_Hz, harmonics)
    if not any(v != 0.0 for (_, k), v in meas.values.items() if k >= 1):
        # a running gear pair always shows mesh harmonics: all zero is a dead sensor or an
        # empty export, and fitting it would report a confident estimate of nothing
        raise _bad(
            p,
            None,
            None,
            "every harmonic amplitude is 0: a running gear pair always has mesh "
            "harmonics (was the sensor connected, the record exported?)",
        )
    return meas


def _harmonic_table(p: Path, rows: list[list[str]], harmonics: int) -> Measurement:
    values: dict[Feature, float] = {}
    for i, r in enumerate(rows, start=2):
        if len(r) != 3:
            raise _bad(p, i, None, f"has {len(r)} fields, expected 3 (signal,harmonic,amplitude)")
        sig = r[0].strip()
        if sig not in SIGNALS:
            raise _bad(p, i, "signal", f"{sig!r} is not a measurable signal ({', '.join(SIGNALS)})")
        kf = _number(p, i, "harmonic", r[1])
        if kf != int(kf) or not 1 <= kf <= harmonics:
            raise _bad(
                p,
                i,
                "harmonic",
                f"{r[1].strip()} must be a whole number in [1, {harmonics}] (the scene's output.harmonics)",
            )
        amp = _number(p, i, "amplitude", r[2])
        if amp < 0:
            raise _bad(p, i, "amplitude", f"{amp:g} must be >= 0 (an amplitude)")
        _plausible(p, i, "amplitude", amp, sig)
        if (sig, int(kf)) in values:
            raise _bad(p, i, None, f"repeats {sig} harmonic {int(kf)}")
        values[(sig, int(kf))] = amp
    if not values:
        raise _bad(p, None, None, "has a header but no rows")
    return Measurement(str(p), "harmonics", values)


def _time_series(p: Path, header: list[str], rows: list[list[str]], fm_Hz: float, harmonics: int) -> Measurement:
    tcol = next((h for h in TIME_COLUMNS if h in header), None)
    if tcol is None:
        raise _bad(
            p, 1, None, "the header has neither time_s (a time series) nor signal,harmonic,amplitude (a harmonic table)"
        )
    for h in header:
        if h != tcol and h not in SIGNALS:
            raise _bad(p, 1, h, f"unknown column (a time series has {tcol} and any of {', '.join(SIGNALS)})")
    if len(set(header)) != len(header):
        raise _bad(p, 1, None, "repeats a column")
    cols = [h for h in header if h != tcol]
    if not cols:
        raise _bad(p, 1, None, f"has only {tcol}; add at least one of {', '.join(SIGNALS)}")
    data = np.empty((len(rows), len(header)))
    for i, r in enumerate(rows):
        if len(r) != len(header):
            raise _bad(p, i + 2, None, f"has {len(r)} fields, the header {len(header)}")
        for j, h in enumerate(header):
            data[i, j] = (
                _number(p, i + 2, h, r[j]) if h == tcol else _plausible(p, i + 2, h, _number(p, i + 2, h, r[j]))
            )
    t = data[:, header.index(tcol)]
    if t.size < 2:
        raise _bad(p, None, None, "has fewer than two samples")
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if bad.size:
        raise _bad(p, int(bad[0]) + 3, tcol, f"{t[bad[0] + 1]:g} does not increase")
    columns = {h: data[:, header.index(h)] for h in cols}
    try:
        values, info = time_series_features(t, columns, fm_Hz, harmonics)
    except ValueError as exc:
        raise _bad(p, None, tcol, str(exc)) from None
    return Measurement(str(p), "time_series", values, info)
