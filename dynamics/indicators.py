"""Gear condition-monitoring indicators of a uniformly sampled signal (pure functions).

The signal ``x`` is a steady-state record (e.g. the relative acceleration ``a_delta`` of
:func:`dynamics.analysis.acceleration_signals`, a bearing acceleration, or the mesh force
``F_m``) sampled at ``fs_Hz`` over a **whole number of shaft revolutions** (a time-
synchronous record; with a simulation, round the duration with
:func:`dynamics.simulate.round_to_table_periods`). ``f_mesh_Hz`` must be a whole
multiple ``z`` of ``f_shaft_Hz`` (the shaft of the gear being monitored: ``z`` is its
number of teeth). Then every shaft order, every mesh harmonic ``k f_mesh`` and every
sideband ``k f_mesh +- n f_shaft`` falls exactly on a DFT bin (bin ``order * R`` for a
record of R revolutions): the spectral indicators below are exact bin sums with a
rectangular window, no leakage, no interpolation.

Definitions (x_ac = x - mean(x); amplitudes A(f) are single-sided, a sinusoid of
amplitude a on a bin has A = a):

* ``ac_rms`` = sqrt(mean(x_ac^2)); ``peak_to_peak`` = max(x) - min(x).
* ``kurtosis`` = mean(x_ac^4) / mean(x_ac^2)^2, the normalised 4th central moment
  (population form, = 3 for Gaussian noise, 1.5 for a sine; not the "excess" kurtosis).
* ``crest_factor`` = max|x_ac| / ac_rms (sqrt 2 for a sine).
* ``FM0`` (Stewart 1977; Samuel & Pines 2005, J. Sound Vib. 282:475-508, Sec. 3.1) =
  peak_to_peak / sum_{k=1..H} A(k f_mesh), the peak-to-peak of the signal over the sum
  of the mesh-harmonic amplitudes; H = every mesh harmonic up to the Nyquist
  frequency (inclusive) unless ``n_harmonics`` is given. A sine at f_mesh gives 2; a localised
  fault (a peak without a matching rise in the mesh harmonics) raises it.
* ``FM4`` (Stewart 1977; Zakrajsek, Townsend & Decker 1993, NASA TM-105950; Samuel &
  Pines 2005) = kurtosis of the *difference signal* d. Here d is x with these DFT bins
  set to zero (then transformed back): DC; the shaft orders 1..``n_shaft_orders``
  (default 2: once- and twice-per-revolution, eccentricity and misalignment); every mesh
  harmonic k f_mesh, k = 1..H (as for FM0); and the first-order sidebands
  k f_mesh +- f_shaft of each. What remains is what a healthy, uniformly loaded mesh
  does not produce: about 3 for Gaussian-like residuals, far above 3 when one tooth
  makes a peak once per revolution.
* ``sideband_energy`` = sum_{k=1..K} sum_{n=1..N_sb} [A(k f_mesh - n f_shaft)^2 +
  A(k f_mesh + n f_shaft)^2] (signal unit squared; "energy" as the sum of squared
  amplitudes, twice the mean power of those components); ``mesh_energy`` =
  sum_{k=1..K} A(k f_mesh)^2; ``sideband_ratio_dB`` = 10 log10(sideband_energy /
  mesh_energy) (defaults K = 3, N_sb = 3). An amplitude-modulated carrier
  (1 + m cos(2 pi f_shaft t)) cos(2 pi f_mesh t) has sidebands m/2 each: sideband
  energy m^2/2 of the carrier's.

Degenerate input: an indicator that is undefined (a signal constant to 1e-12 of its
magnitude: no kurtosis, no crest factor; no mesh-harmonic amplitude: no FM0; a
difference signal at the rounding level: no FM4; no mesh energy, or no sideband energy
at all: no finite dB ratio) is ``None`` with the reason in ``undefined``; no NaN or inf
ever reaches ``to_dict``. Arguments that break the requirements (not a whole number of
revolutions, f_mesh not a whole multiple of f_shaft, bands beyond the Nyquist
frequency, overlapping sidebands) raise ``InputError`` naming the argument.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from gearwear.core.validation import fail, fail_text

__all__ = [
    "GearIndicators",
    "SidebandLines",
    "gear_indicators",
    "result_indicators",
    "ac_rms",
    "kurtosis",
    "crest_factor",
    "fm0",
    "fm4",
    "difference_signal",
    "sideband_energy",
    "sideband_lines",
    "revolution_bins",
]

# an AC part below this fraction of the signal's magnitude is floating-point rounding
_FLAT = 1e-12


# ---------------------------------------------------------------------------------------
# validation and the exact bins
# ---------------------------------------------------------------------------------------
def _signal(x) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim != 1 or a.size < 4:
        raise fail_text("x", f"x: must be a 1-D signal of >= 4 samples, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise fail_text("x", "x: must be finite (no NaN or inf samples)")
    return a


def _positive(name: str, v) -> float:
    if (
        isinstance(v, bool)
        or not isinstance(v, (int, float, np.floating, np.integer))
        or not math.isfinite(v)
        or v <= 0
    ):
        raise fail_text(name, f"{name} = {v!r}: must be a finite number > 0", v)
    return float(v)


def _count(name: str, v, low: int) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer, float)) or int(v) != v or v < low:
        raise fail_text(name, f"{name} = {v!r}: must be a whole number >= {low}", v)
    return int(v)


def revolution_bins(n_samples: int, fs_Hz: float, f_mesh_Hz: float, f_shaft_Hz: float) -> tuple[int, int]:
    """(R, z): the record holds R whole shaft revolutions and f_mesh = z f_shaft, so shaft
    order r sits on DFT bin r R and mesh harmonic k on bin k z R. Raises InputError when
    the record is not a whole number (>= 1) of revolutions (to 1e-6 revolution) or
    f_mesh is not a whole multiple of f_shaft (to 1e-9)."""
    fs = _positive("fs_Hz", fs_Hz)
    fm = _positive("f_mesh_Hz", f_mesh_Hz)
    fsh = _positive("f_shaft_Hz", f_shaft_Hz)
    zr = fm / fsh
    z = int(round(zr))
    if z < 1 or abs(zr - z) > 1e-9 * zr:
        raise fail_text(
            "f_mesh_Hz",
            f"f_mesh_Hz = {fm:.9g}: must be a whole multiple of f_shaft_Hz = {fsh:.9g} "
            f"(the monitored shaft's tooth count), got the ratio {zr:.9g}",
            fm,
        )
    rev = n_samples * fsh / fs
    R = int(round(rev))
    if R < 1 or abs(rev - R) > 1e-6:
        raise fail_text(
            "x",
            f"x: {n_samples} samples at fs_Hz = {fs:.9g} are {rev:.9g} revolutions of "
            f"the shaft at f_shaft_Hz = {fsh:.9g}; the record must hold a whole number "
            f"(>= 1) of revolutions (with a simulation: round the duration with "
            f"round_to_table_periods)",
        )
    return R, z


def _amplitudes(x: np.ndarray, X: np.ndarray | None = None) -> np.ndarray:
    """Single-sided amplitudes of the DFT bins 0..N//2 (rectangular window); ``X``: the
    rfft of x if already computed."""
    N = x.size
    A = np.abs(np.fft.rfft(x) if X is None else X) / N
    A[1:] *= 2.0
    if N % 2 == 0:
        A[-1] /= 2.0
    return A


def _harmonic_count(N: int, R: int, z: int, n_harmonics) -> int:
    """Mesh harmonics up to the Nyquist frequency (bin k z R <= N // 2; with an even
    number of samples per mesh period the last one is on the Nyquist bin, which a
    mesh-periodic signal does fill), or the requested number if they fit."""
    H_max = (N // 2) // (z * R)
    if n_harmonics is None:
        if H_max < 1:
            raise fail_text(
                "fs_Hz",
                f"fs_Hz: the mesh frequency is not below the Nyquist frequency "
                f"({N} samples over {R} revolutions, {z} mesh periods each)",
            )
        return H_max
    H = _count("n_harmonics", n_harmonics, 1)
    if H > H_max:
        raise fail(
            "n_harmonics",
            H,
            "",
            f"only {H_max} mesh harmonics lie at or below the Nyquist frequency at this sample rate",
        )
    return H


# ---------------------------------------------------------------------------------------
# the indicators (each also available alone)
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Central:
    """The central moments every indicator reads, each taken once per signal: ``mean``,
    ``ac`` = x - mean, ``a2`` = ac^2 (ac * ac: numpy's power takes the same product for 2),
    ``m2`` = mean(a2), ``peak_ac`` = max|ac|, ``peak`` = max|x|, ``p2p`` = max - min.
    The same operations as each indicator on its own, so the same numbers to the bit."""

    mean: float
    ac: np.ndarray
    a2: np.ndarray
    m2: float
    peak_ac: float
    peak: float
    p2p: float

    @property
    def flat(self) -> bool:
        """The AC part is rounding (below _FLAT of the signal's magnitude)."""
        return self.peak_ac <= _FLAT * max(self.peak, 1e-300)

    @property
    def ac_rms(self) -> float:
        return float(np.sqrt(self.m2))


def _central(x: np.ndarray) -> _Central:
    mean = np.mean(x)
    ac = x - mean
    a2 = ac * ac
    return _Central(
        float(mean),
        ac,
        a2,
        float(np.mean(a2)),
        float(np.max(np.abs(ac))),
        float(np.max(np.abs(x))),
        float(np.ptp(x)),
    )


def ac_rms(x) -> float:
    """RMS of the AC part, sqrt(mean((x - mean x)^2)), in the signal's unit."""
    return _central(_signal(x)).ac_rms


def _kurtosis(c: _Central):
    if c.flat:
        return None, "the signal is constant (to 1e-12 of its magnitude): 4th moment over a zero variance"
    # (ac^2)^2, not ac**4: numpy's power takes pow() for 4, ~10x slower
    return float(np.mean(c.a2 * c.a2) / (c.m2 * c.m2)), None


def kurtosis(x) -> float | None:
    """Normalised 4th central moment mean(x_ac^4) / mean(x_ac^2)^2 (3 for Gaussian noise,
    1.5 for a sine); None for a constant signal."""
    return _kurtosis(_central(_signal(x)))[0]


def _crest(c: _Central):
    if c.flat:
        return None, "the signal is constant (to 1e-12 of its magnitude): peak over a zero RMS"
    return float(c.peak_ac / np.sqrt(c.m2)), None


def crest_factor(x) -> float | None:
    """max|x_ac| / ac_rms (sqrt 2 for a sine sampled at its peaks); None for a constant
    signal."""
    return _crest(_central(_signal(x)))[0]


def _fm0(c: _Central, A, R, z, H):
    s = float(np.sum(A[z * R * np.arange(1, H + 1)]))
    if s <= _FLAT * max(float(np.max(A)), 1e-300) or s == 0.0:
        return None, "no amplitude at the mesh harmonics (FM0's denominator is zero)"
    return c.p2p / s, None


def fm0(x, fs_Hz: float, f_mesh_Hz: float, f_shaft_Hz: float, n_harmonics: int | None = None) -> float | None:
    """FM0 = peak-to-peak of x / sum of the amplitudes of the mesh harmonics k f_mesh,
    k = 1..H (Stewart 1977, in Samuel & Pines 2005): H = all up to Nyquist by default.
    None when the mesh harmonics have no amplitude."""
    x = _signal(x)
    R, z = revolution_bins(x.size, fs_Hz, f_mesh_Hz, f_shaft_Hz)
    H = _harmonic_count(x.size, R, z, n_harmonics)
    return _fm0(_central(x), _amplitudes(x), R, z, H)[0]


def _removed_bins(N: int, R: int, z: int, H: int, n_shaft_orders: int) -> np.ndarray:
    top = N // 2
    orders = [0] + list(range(1, n_shaft_orders + 1))
    for k in range(1, H + 1):
        orders += [k * z - 1, k * z, k * z + 1]
    b = np.unique(np.array(orders, dtype=np.int64) * R)
    return b[(b >= 0) & (b <= top)]


def difference_signal(
    x, fs_Hz: float, f_mesh_Hz: float, f_shaft_Hz: float, n_shaft_orders: int = 2, n_harmonics: int | None = None
) -> np.ndarray:
    """The difference signal of FM4: x with the DFT bins of DC, the shaft orders
    1..n_shaft_orders, the mesh harmonics k f_mesh (k = 1..H, H as in :func:`fm0`) and
    their first-order sidebands k f_mesh +- f_shaft set to zero, transformed back (exact
    bins: the record is whole revolutions)."""
    x = _signal(x)
    R, z = revolution_bins(x.size, fs_Hz, f_mesh_Hz, f_shaft_Hz)
    H = _harmonic_count(x.size, R, z, n_harmonics)
    ns = _count("n_shaft_orders", n_shaft_orders, 0)
    return _difference(x, R, z, H, ns)


def _difference(x, R, z, H, ns, X: np.ndarray | None = None):
    """The difference signal; ``X``: the rfft of x if already computed (not modified)."""
    X = np.fft.rfft(x) if X is None else X.copy()
    X[_removed_bins(x.size, R, z, H, ns)] = 0.0
    return np.fft.irfft(X, n=x.size)


def _fm4(c: _Central, d):
    d2 = d * d
    rd = float(np.sqrt(np.mean(d2)))
    if rd <= _FLAT * max(c.ac_rms, c.peak, 1e-300):
        return None, (
            "the difference signal is at the rounding level: nothing is left after "
            "removing the shaft orders, mesh harmonics and first-order sidebands"
        )
    return float(np.mean(d2 * d2) / np.mean(d2) ** 2), None


def fm4(
    x, fs_Hz: float, f_mesh_Hz: float, f_shaft_Hz: float, n_shaft_orders: int = 2, n_harmonics: int | None = None
) -> float | None:
    """FM4 = kurtosis of the difference signal (:func:`difference_signal`; Stewart 1977,
    Zakrajsek et al. 1993, Samuel & Pines 2005). None when nothing is left of it."""
    x = _signal(x)
    return _fm4(_central(x), difference_signal(x, fs_Hz, f_mesh_Hz, f_shaft_Hz, n_shaft_orders, n_harmonics))[0]


def _sb_check(N, R, z, K, N_sb):
    K = _count("K", K, 1)
    N_sb = _count("N_sb", N_sb, 1)
    if 2 * N_sb >= z:
        raise fail(
            "N_sb",
            N_sb,
            "",
            f"sidebands must stay closer to their own mesh harmonic than to the next (2 N_sb < {z} = f_mesh / f_shaft)",
        )
    if 2 * (K * z + N_sb) * R >= N:
        raise fail(
            "K",
            K,
            "",
            "the sideband band K f_mesh + N_sb f_shaft reaches the Nyquist "
            "frequency; lower K or N_sb, or sample faster",
        )
    return K, N_sb


def _sidebands(A, R, z, K, N_sb):
    k = np.arange(1, K + 1)[:, None]
    n = np.r_[-np.arange(N_sb, 0, -1), np.arange(1, N_sb + 1)][None, :]
    sb = float(np.sum(A[(k * z + n) * R] ** 2))
    me = float(np.sum(A[k[:, 0] * z * R] ** 2))
    if me == 0.0:
        return sb, me, None, "no energy at the mesh harmonics (the ratio has no reference)"
    if sb == 0.0:
        return sb, me, None, "no sideband energy at all (the ratio is -inf dB)"
    return sb, me, 10.0 * math.log10(sb / me), None


def sideband_energy(x, fs_Hz: float, f_mesh_Hz: float, f_shaft_Hz: float, K: int = 3, N_sb: int = 3) -> dict:
    """Energy (sum of squared single-sided amplitudes) at k f_mesh +- n f_shaft, n = 1..N_sb,
    around the mesh harmonics k = 1..K, and at those harmonics: returns
    {"sideband_energy": ..., "mesh_energy": ... (signal unit^2), "sideband_ratio_dB":
    10 log10(sideband / mesh) or None}."""
    x = _signal(x)
    R, z = revolution_bins(x.size, fs_Hz, f_mesh_Hz, f_shaft_Hz)
    K, N_sb = _sb_check(x.size, R, z, K, N_sb)
    sb, me, db, _ = _sidebands(_amplitudes(x), R, z, K, N_sb)
    return {"sideband_energy": sb, "mesh_energy": me, "sideband_ratio_dB": db}


# ---------------------------------------------------------------------------------------
# all at once
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class GearIndicators:
    """Condition indicators of one record (see the module docstring for the definitions).

    Values in the signal's unit (``unit``): ``mean``, ``ac_rms``, ``peak_to_peak``; in
    unit squared: ``sideband_energy``, ``mesh_energy``; dimensionless: ``kurtosis``,
    ``crest_factor``, ``FM0``, ``FM4``; ``sideband_ratio_dB`` in dB. ``None`` = undefined,
    the reason in ``undefined`` (pairs of name and reason)."""

    unit: str
    n_samples: int
    n_revolutions: int
    fs_Hz: float
    f_mesh_Hz: float
    f_shaft_Hz: float
    mean: float
    ac_rms: float
    peak_to_peak: float
    kurtosis: float | None
    crest_factor: float | None
    FM0: float | None
    FM4: float | None
    sideband_energy: float
    mesh_energy: float
    sideband_ratio_dB: float | None
    K_mesh_harmonics: int
    N_sidebands: int
    FM0_FM4_mesh_harmonics: int
    FM4_shaft_orders_removed: int
    undefined: tuple = ()

    def to_dict(self) -> dict:
        """Plain JSON-ready dict (no NaN or inf: undefined values are None, with reasons)."""
        d = asdict(self)
        d["undefined"] = {name: why for name, why in self.undefined}
        return d


def gear_indicators(
    x,
    fs_Hz: float,
    f_mesh_Hz: float,
    f_shaft_Hz: float,
    K: int = 3,
    N_sb: int = 3,
    n_shaft_orders: int = 2,
    n_harmonics: int | None = None,
    unit: str = "",
) -> GearIndicators:
    """Every indicator of the module docstring for the record x (whole revolutions of the
    shaft at f_shaft_Hz, f_mesh_Hz a whole multiple of it). ``K``, ``N_sb``: mesh harmonics
    and sideband orders of the sideband energy; ``n_shaft_orders``, ``n_harmonics``: what
    FM4's difference signal removes and FM0 sums (H = all mesh harmonics up to Nyquist
    by default); ``unit`` names the signal's unit (e.g. "m/s^2", "N") in the result."""
    x = _signal(x)
    R, z = revolution_bins(x.size, fs_Hz, f_mesh_Hz, f_shaft_Hz)
    H = _harmonic_count(x.size, R, z, n_harmonics)
    ns = _count("n_shaft_orders", n_shaft_orders, 0)
    K, N_sb = _sb_check(x.size, R, z, K, N_sb)
    X = np.fft.rfft(x)  # one transform for the amplitudes and the difference signal
    A = _amplitudes(x, X)
    c = _central(x)  # one pass of the moments for all of them (each took its own: ~2x the time)
    why = []
    kur, r = _kurtosis(c)
    why += [("kurtosis", r)] if r else []
    cf, r = _crest(c)
    why += [("crest_factor", r)] if r else []
    f0, r = _fm0(c, A, R, z, H)
    why += [("FM0", r)] if r else []
    f4, r = _fm4(c, _difference(x, R, z, H, ns, X))
    why += [("FM4", r)] if r else []
    sb, me, db, r = _sidebands(A, R, z, K, N_sb)
    why += [("sideband_ratio_dB", r)] if r else []
    return GearIndicators(
        unit=str(unit),
        n_samples=int(x.size),
        n_revolutions=R,
        fs_Hz=float(fs_Hz),
        f_mesh_Hz=float(f_mesh_Hz),
        f_shaft_Hz=float(f_shaft_Hz),
        mean=c.mean,
        ac_rms=c.ac_rms,
        peak_to_peak=c.p2p,
        kurtosis=kur,
        crest_factor=cf,
        FM0=f0,
        FM4=f4,
        sideband_energy=sb,
        mesh_energy=me,
        sideband_ratio_dB=db,
        K_mesh_harmonics=K,
        N_sidebands=N_sb,
        FM0_FM4_mesh_harmonics=H,
        FM4_shaft_orders_removed=ns,
        undefined=tuple(why),
    )


_UNITS = {
    "F_m": "N",
    "a_delta": "m/s^2",
    "a_y_p": "m/s^2",
    "a_x_p": "m/s^2",
    "a_y_g": "m/s^2",
    "a_x_g": "m/s^2",
    "a_q": "m/s^2",
    "delta": "m",
    "s": "m",
    "q": "m",
    "y_p": "m",
    "x_p": "m",
    "y_g": "m",
    "x_g": "m",
}


def result_indicators(result, signal: str = "a_delta", f_shaft_Hz: float | None = None, **kw) -> GearIndicators:
    """:func:`gear_indicators` of a simulation signal (``result.signals`` or, for names
    starting ``a_``, :func:`dynamics.analysis.acceleration_signals`). ``f_shaft_Hz``
    defaults to the pinion's, omega_p / 2 pi (f_mesh = z_p f_shaft). The kept window must
    be whole revolutions of that shaft: simulate with a duration from
    :func:`dynamics.simulate.round_to_table_periods` and ``table_periods`` a multiple
    of the tooth count (``result.whole_table_periods``)."""
    if signal.startswith("a_"):
        from .analysis import acceleration_signals

        sigs = acceleration_signals(result)
    else:
        sigs = result.signals
    if signal not in sigs:
        raise fail("signal", repr(signal), "", f"not a signal of the result (one of {', '.join(sorted(sigs))})")
    m = result.model
    fsh = f_shaft_Hz if f_shaft_Hz is not None else m.omega_p / (2 * math.pi)
    kw.setdefault("unit", _UNITS.get(signal, ""))
    return gear_indicators(sigs[signal], result.fs_Hz, result.fm_Hz, fsh, **kw)


# ---------------------------------------------------------------------------------------
# what a spectrum plot should mark
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SidebandLines:
    """Frequencies to mark on a spectrum: ``mesh_Hz`` (K,) the mesh harmonics k f_mesh,
    k = 1..K; ``sideband_Hz`` (K, 2N) the sidebands k f_mesh + n f_shaft for the orders
    ``orders`` = -N..-1, 1..N (row k - 1). Lower sidebands at or below 0 Hz are kept
    (the caller clips to its axis)."""

    mesh_Hz: np.ndarray
    sideband_Hz: np.ndarray
    orders: np.ndarray

    def to_dict(self) -> dict:
        return {
            "mesh_Hz": self.mesh_Hz.tolist(),
            "sideband_Hz": self.sideband_Hz.tolist(),
            "orders": self.orders.tolist(),
        }


def sideband_lines(f_mesh_Hz: float, f_shaft_Hz: float, K: int = 3, N: int = 3) -> SidebandLines:
    """The mesh harmonics k f_mesh (k = 1..K) and their sidebands k f_mesh +- n f_shaft
    (n = 1..N): the lines a spectrum plot marks (the bands ``sideband_energy`` sums)."""
    fm = _positive("f_mesh_Hz", f_mesh_Hz)
    fsh = _positive("f_shaft_Hz", f_shaft_Hz)
    K = _count("K", K, 1)
    N = _count("N", N, 1)
    k = np.arange(1, K + 1, dtype=float)
    n = np.r_[-np.arange(N, 0, -1), np.arange(1, N + 1)]
    return SidebandLines(mesh_Hz=k * fm, sideband_Hz=k[:, None] * fm + n[None, :] * fsh, orders=n)
