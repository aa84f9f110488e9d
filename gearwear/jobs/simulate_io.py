"""Files and text of the ``simulate`` command: signals (NPZ + CSV), PNGs in the style
of paper Figs. 7, 9, 11, 13 (time trace and spectrum), summary JSON."""

from __future__ import annotations

import io as _io
import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from gearwear import io
from gearwear.jobs.simulate import SIGNAL_UNITS, SimulationRun, signal_label
from gearwear.scene.assumptions import line_of


def signals_csv(run: SimulationRun) -> str:
    r = run.result
    names = run.output["signals"]
    cols = ["t_s"] + [f"{n}_{SIGNAL_UNITS[n][0]}" for n in names]
    data = np.column_stack([r.t] + [r.signals[n] * SIGNAL_UNITS[n][1] for n in names])
    buf = _io.StringIO()
    np.savetxt(buf, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
    return buf.getvalue()


def figure(run: SimulationRun):
    """Per signal: five mesh periods of the time trace and the amplitude spectrum of the
    kept window up to (K + 0.5) f_m, K = the harmonics the run reports."""
    from gearwear.plotting import spectrum_band_Hz, subplots

    r = run.result
    names = run.output["signals"]
    K = int(run.output["harmonics"])
    fig, axes = subplots(len(names), 2, figsize=(12, 2.4 * len(names)), squeeze=False)
    n_show = max(1, int(round(5 * r.fs_Hz / r.fm_Hz)))  # five mesh periods
    f_hi = spectrum_band_Hz(r.fm_Hz, K)
    for i, n in enumerate(names):
        unit, scale = SIGNAL_UNITS[n]
        ax, ax2 = axes[i]
        ax.plot(r.t[:n_show] * 1e3, r.signals[n][:n_show] * scale, lw=0.9)
        ax.set_ylabel(textwrap.fill(signal_label(n), 30), fontsize=8)
        ax.grid(alpha=0.3)
        f, A = r.spectrum(n)
        keep = (f >= 0.5 * r.fm_Hz) & (f <= f_hi)  # the mean (DC) would dwarf the harmonics
        ax2.plot(f[keep], A[keep] * scale, lw=0.8)
        for k in range(1, K + 1):
            ax2.axvline(k * r.fm_Hz, color="0.85", lw=0.5, zorder=0)
        ax2.set_xlim(0.5 * r.fm_Hz, f_hi)
        ax2.set_ylim(bottom=0)
        ax2.set_ylabel(f"amplitude of {n} ({unit})", fontsize=8)
        ax2.grid(alpha=0.3)
    axes[-1][0].set_xlabel("time (ms), five mesh periods after the discarded transient")
    axes[-1][1].set_xlabel(f"frequency (Hz), mean removed; grey lines: k f_m, k = 1..{K}")
    sc = run.scene
    fig.suptitle(
        f"{sc.name}: {sc.operating.speed_rpm:g} rpm, {sc.operating.torque_Nm:g} N m, f_m = "
        f"{r.fm_Hz:g} Hz, effects: {', '.join(sorted(sc.effects)) or 'none'}",
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def spectrum_figure(run: SimulationRun):
    """Amplitude spectrum (log scale) of the relative acceleration along the line of action
    over the last whole revolutions of the kept window (rectangular window: shaft orders on
    exact bins) up to (K + 0.5) f_m (K: the harmonics the run reports), the axis ending
    FLOOR_DB below the largest line (below it the solver's rounding noise, ~1e-12), with the
    mesh harmonics (solid) and the sidebands k f_m +- n f_shaft, n = 1..3, of the first three
    (dashed: the lines the sideband ratio sums). None when the window is shorter than one
    revolution."""
    from gearwear.dynamics.analysis import acceleration_signals, spectrum
    from gearwear.dynamics.indicators import sideband_lines
    from gearwear.jobs.simulate import shaft_frequency_Hz
    from gearwear.plotting import FLOOR_DB, legend_outside, log_floor, spectrum_band_Hz, subplots

    r = run.result
    f_shaft, z = shaft_frequency_Hz(run.scene)
    revs = r.n_periods // z
    if revs < 1:
        return None
    S = int(round(r.fs_Hz / r.fm_Hz))
    K = int(run.output["harmonics"])
    x = acceleration_signals(r)["a_delta"][-revs * z * S :]
    f, A = spectrum(x - np.mean(x), r.fs_Hz)
    lines = sideband_lines(r.fm_Hz, f_shaft)
    f_hi = spectrum_band_Hz(r.fm_Hz, K)
    keep = (f > 0) & (f <= f_hi)
    floor = log_floor(A[keep])
    fig, ax = subplots(1, 1, figsize=(10, 4.5))
    ax.semilogy(f[keep], A[keep], lw=0.8, color="k")
    for k in range(1, K + 1):
        ax.axvline(
            k * r.fm_Hz,
            color="tab:blue",
            lw=1.0,
            alpha=0.6,
            zorder=1,
            label=f"mesh harmonics k f_m, k = 1..{K}" if k == 1 else None,
        )
    for k, sides in enumerate(lines.sideband_Hz):
        for j, fs in enumerate(sides):
            ax.axvline(
                fs,
                color="tab:red",
                lw=0.8,
                ls="--",
                alpha=0.5,
                zorder=1,
                label=f"sidebands k f_m +- n f_shaft, k <= {len(lines.mesh_Hz)}, n <= {len(sides) // 2} "
                f"(f_shaft = {f_shaft:.4g} Hz)"
                if k == j == 0
                else None,
            )
    ci = run.summary()["condition_indicators"].get("a_delta_m_per_s2", {})
    ratio = ci.get("sideband_ratio_dB")
    ax.set_xlim(0, f_hi)
    peak = float(np.max(A[keep]))
    ax.set_ylim(floor, 3 * peak if peak > 0 else 1.0)
    ax.set_xlabel(f"frequency (Hz), mean removed; f_m = {r.fm_Hz:g} Hz")
    ax.set_ylabel("acceleration a_delta, line of action (m/s^2)")
    ax.set_title(
        f"{run.scene.name}: relative acceleration on the line of action, {revs} whole revolutions, "
        f"rectangular window; axis floor {FLOOR_DB:g} dB below the largest line; sideband/mesh energy "
        f"{'n/a' if ratio is None else f'{ratio:.1f} dB'}",
        fontsize=9,
    )
    ax.grid(alpha=0.3, which="both")
    legend_outside(ax, "below", ncol=2)
    fig.tight_layout()
    return fig


def write(run: SimulationRun, out: Path, inputs: dict[str, Any], labels: dict[str, Any] | None = None) -> list[Path]:
    """signals.npz, signals.csv (+ sidecar), response.png and summary.json into the
    folder ``out``. The NPZ has fixed zip timestamps and summary.json no wall times, so
    the same inputs give the same bytes (timing goes to timing.json)."""
    files = []
    r = run.result
    files.append(io.write_bytes(out / "signals.npz", io.npz_bytes(run.signals)))  # SI, units in the keys
    csv = io.write_text(out / "signals.csv", signals_csv(run))
    files += [csv, io.sidecar(csv, inputs, f"dynamics.simulate ({r.method})", labels)]
    files.append(io.write_figure(figure(run), out / "response.png"))
    spec = spectrum_figure(run)
    if spec is not None:
        files.append(io.write_figure(spec, out / "spectrum.png"))
    files.append(io.write_json(out / "summary.json", io.without_timing(run.summary())))
    return files


def print_summary(s: dict[str, Any]) -> None:
    print(
        f"scene {s['scene']}: f_m = {s['fm_Hz']:g} Hz, method {s['method']}, {s['steps']} steps "
        f"({s['events']} events), {s['wall_s']:.2f} s wall (integration {s['integration_wall_s']:.3f} s, "
        f"compile {s['compile_s']:.2f} s)"
    )
    print(
        f"effects: {', '.join(s['effects']) or 'none'}; mesh stiffness {s['stiffness_source']}, mean "
        f"{s['mean_mesh_stiffness_N_per_m']:.4e} N/m"
    )
    if s["separation_fraction"] is None:
        print(
            f"tooth separation: not modelled ({s['separation_note']}); back-flank contact "
            f"{100 * s['backside_fraction']:.2f} % of the time (negative mesh force)"
        )
    else:
        print(
            f"tooth separation {100 * s['separation_fraction']:.2f} % of the time, back-side contact "
            f"{100 * s['backside_fraction']:.2f} %"
        )
    print(
        f"{'signal':<12}{'mean':>12}{'AC rms':>12}{'p-p':>12}   harmonics k f_m, k = 1.."
        f"{len(next(iter(s['harmonics'].values())))}"
    )
    for key, h in s["harmonics"].items():
        print(
            f"{key:<12}{s['mean'][key]:>12.4g}{s['ac_rms'][key]:>12.4g}{s['peak_to_peak'][key]:>12.4g}   "
            + " ".join(f"{x:.3g}" for x in h)
        )
    ci = s.get("condition_indicators", {})
    a = ci.get("a_delta_m_per_s2")
    if a is not None:

        def num(v, fmt):
            return "n/a" if v is None else format(v, fmt)

        print(
            f"indicators (a_delta, {ci['revolutions']} revolutions at f_shaft = {ci['shaft_frequency_Hz']:.4g} Hz, "
            f"{'periodic' if ci.get('periodic') else 'NOT periodic: see the warning'}): "
            f"rms {num(a['ac_rms'], '.4g')} m/s^2, kurtosis {num(a['kurtosis'], '.3f')}, crest "
            f"{num(a['crest_factor'], '.3f')}, FM0 {num(a['FM0'], '.3f')}, FM4 {num(a['FM4'], '.3f')}, "
            f"sidebands {num(a['sideband_ratio_dB'], '.1f')} dB"
        )
    elif ci.get("why_none"):
        print(f"indicators: none, {ci['why_none']}")
    for a in s.get("assumptions", []):
        print(line_of(a))
    for note in s.get("warnings", []):
        print(f"warning: {note}")
    for f in s.get("files", []):
        print(f"wrote {f}")
