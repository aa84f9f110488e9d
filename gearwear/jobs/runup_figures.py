"""The run-up's figures: K_v against speed with the steady states marked (periodic orders, quasi-periodic,
chaotic, unsettled) and the linear modes' speeds; the order map (mesh harmonics against speed) and the
Campbell diagram (the spectrum of each speed's window, peak-held on a frequency grid)."""

from __future__ import annotations

from typing import Any

import numpy as np

from gearwear.jobs.runup import N_HARMONICS, Chain, Point
from gearwear.jobs.sweep import Axis, point_label


def _label(p: Point, others: list[Axis]) -> str:
    return point_label(others, [p.values[a.key] for a in others]) or f"{p.scene.operating.torque_Nm:g} N m"


#: the marker of each steady state that is not plain periodic (period p > 1 cycles through PERIOD_MARKERS)
STATE_MARKERS = {"quasi-periodic": ("D", "tab:purple"), "chaotic": ("X", "red"), "unsettled": ("*", "0.35")}


PERIOD_MARKERS = (
    ("^", "gold"),
    ("s", "darkorange"),
    ("v", "saddlebrown"),
    ("p", "olive"),
    ("h", "teal"),
    ("<", "pink"),
    (">", "cyan"),
)


def steady_state_name(row: dict[str, Any], table_periods: int) -> str | None:
    """ "period 2" (periodic over p > 1 table periods), "quasi-periodic", "chaotic",
    "unsettled", or None for a period-1 response (the stiffness table's own period)."""
    if row["label"] != "periodic":
        return row["label"]
    p = row["period_mesh_periods"] // max(table_periods, 1)
    return f"period {p}" if p > 1 else None


def _state_style(name: str) -> tuple[str, str]:
    if name.startswith("period "):
        return PERIOD_MARKERS[(int(name.split()[1]) - 2) % len(PERIOD_MARKERS)]
    return STATE_MARKERS.get(name, ("o", "k"))


def _mark_states(ax, points: list[Point], chains: list[Chain]) -> None:
    """One marker per steady state that is not period 1 (period p > 1, quasi-periodic,
    chaotic, unsettled) on the K_v curves, one legend entry per kind."""
    found: dict[str, list[tuple[float, float]]] = {}
    for c in chains:
        L = points[c.point_index].model.table_periods
        for r in c.rows:
            name = steady_state_name(r, L)
            if name is not None:
                found.setdefault(name, []).append((r["speed_rpm"], r["K_v"]))
    runs = sum(len(c.rows) for c in chains)
    order = sorted(
        found, key=lambda n: (not n.startswith("period"), int(n.split()[1]) if n.startswith("period") else 0, n)
    )
    for name in order:
        mk, col = _state_style(name)
        xy = np.array(found[name])
        what = f"{name}, sub-harmonic f_m/{name.split()[1]}" if name.startswith("period") else name
        ax.plot(
            xy[:, 0],
            xy[:, 1],
            ls="none",
            marker=mk,
            ms=9,
            mfc=col,
            mec="k",
            mew=0.8,
            zorder=5,
            label=f"steady state {what}: {len(xy)} of {runs} speed runs",
        )


def _mode_speeds(ax, points: list[Point], summ: dict[str, Any]) -> int:
    """Dashed grey lines at the speeds where f_m meets a linear mode, each named above the
    axes by its frequency (staggered so close ones do not overprint); the rows of names."""
    from gearwear.plotting import labels_above

    marks: dict[float, float] = {}
    for i, p in enumerate(points):
        for n, f in zip(summ["points"][i]["mode_speeds_rpm"]["k1"], p.eigenfrequencies_Hz):
            if p.speeds[0] <= n <= p.speeds[-1]:
                marks.setdefault(round(n, 6), f)
    speeds = sorted(marks)
    for n in speeds:
        ax.axvline(
            n,
            color="0.45",
            lw=1.0,
            ls="--",
            zorder=1,
            label="f_m = a linear mode (frequency above)" if n == speeds[0] else None,
        )
    lo, hi = ax.get_xlim()
    return labels_above(ax, speeds, [f"{marks[n]:.0f} Hz" for n in speeds], 0.09 * (hi - lo), fontsize=8, color="0.25")


def kv_figure(points: list[Point], chains: list[Chain], others: list[Axis], summ: dict[str, Any]):
    """K_v against speed: up (solid) and down (dashed) per point, the jump bands shaded, ISO
    6336-1 method B (dotted) with its resonance speed n_E1, dashed grey lines (named by
    their frequency) at the speeds where the first mesh harmonic meets a linear mode, a
    marker on every speed whose steady state is not period 1. The legend is right of the
    axes, off the data."""
    from gearwear.plotting import legend_outside, subplots, title_pad

    fig, ax = subplots(1, 1, figsize=(12, 5.2))
    colors = ["C0", "C3", "C2", "C1", "C4", "C5", "C6", "C7"]
    for i, p in enumerate(points):
        col = colors[i % len(colors)]
        lab = _label(p, others)
        for c in (c for c in chains if c.point_index == i):
            rows = sorted(c.rows, key=lambda r: r["speed_rpm"])
            ax.plot(
                [r["speed_rpm"] for r in rows],
                [r["K_v"] for r in rows],
                "-" if c.direction == "up" else "--",
                color=col,
                lw=1.4,
                marker="." if c.direction == "up" else None,
                ms=4,
                label=f"{lab}, sweep {c.direction}",
            )
        nE1 = p.iso["n_E1_driver_rpm"]  # on the run-up's (driver) speed axis
        ax.plot(
            p.speeds, p.iso["K_v"], ":", color=col, lw=1.6, label=f"{lab}, ISO 6336-1 method B (n_E1 = {nE1:.0f} rpm)"
        )
        if p.speeds[0] <= nE1 <= p.speeds[-1]:
            ax.axvline(nE1, color=col, lw=0.8, ls="-.", alpha=0.7, label=f"{lab}, ISO resonance speed n_E1")
        for j, (lo, hi) in enumerate(summ["points"][i].get("jump_bands_rpm", [])):
            step = summ["speed_step_rpm"]
            ax.axvspan(
                lo - step / 2,
                hi + step / 2,
                color=col,
                alpha=0.15,
                lw=0,
                label=f"{lab}, jump band (up and down differ)" if j == 0 else None,
            )
    _mark_states(ax, points, chains)
    name_rows = _mode_speeds(ax, points, summ)
    ax.set_xlabel("pinion speed (rpm)")
    ax.set_ylabel("dynamic factor K_v = max F_m / static F (ratio)")
    ax.grid(alpha=0.3)
    legend_outside(ax, fontsize=8)
    ax.set_title("Dynamic factor against speed", fontsize=10, pad=title_pad(name_rows))
    fig.tight_layout()
    return fig


def _chain_panels(points: list[Point], chains: list[Chain], direction: str, size_in: tuple[float, float]):
    """A figure with one axes (``size_in`` inches) per chain of ``direction``, and per axes
    (axes, point, rows in speed order, speeds rpm)."""
    from gearwear.plotting import subplots

    mine = [c for c in chains if c.direction == direction]
    fig, axs = subplots(1, len(mine), figsize=(size_in[0] * len(mine), size_in[1]), squeeze=False)
    panels = []
    for ax, c in zip(axs[0], mine):
        rows = sorted(c.rows, key=lambda r: r["speed_rpm"])
        panels.append((ax, points[c.point_index], rows, np.array([r["speed_rpm"] for r in rows])))
    return fig, panels


def _modes(p: Point) -> list[float]:
    """The point's distinct linear eigenfrequencies (Hz), ascending."""
    return sorted(set(round(x, 6) for x in p.eigenfrequencies_Hz))


def order_map_figure(points: list[Point], chains: list[Chain], others: list[Axis], direction: str):
    """Order map of one sweep direction: the amplitude of delta's mesh harmonics k = 1..10
    over speed and order (log colour), with the curves k = 60 f_mode / (z1 n) of the linear
    modes. Integer orders only: a sub-harmonic is in the Campbell diagram
    (:func:`campbell_figure`)."""
    from matplotlib.colors import LogNorm

    from gearwear.plotting import legend_outside

    fig, panels = _chain_panels(points, chains, direction, (6.5, 4.8))
    for ax, p, rows, n in panels:
        A = np.array([r["delta_harmonics_um"] for r in rows]).T
        pos = A[A > 0]
        lo = max(float(pos.max()) * 1e-5, float(pos.min())) if pos.size else 1e-12
        im = ax.pcolormesh(
            n,
            np.arange(1, N_HARMONICS + 1),
            np.maximum(A, lo),
            shading="nearest",
            norm=LogNorm(vmin=lo, vmax=max(float(A.max()), lo * 10)),
            cmap="viridis",
        )
        z1 = p.scene.pair.teeth[0]
        for j, f in enumerate(_modes(p)):
            ax.plot(
                n,
                60 * f / (z1 * n),
                color="w",
                lw=0.9,
                ls=("--", ":", "-.")[j % 3],
                label=f"k f_m = linear mode {f:.0f} Hz",
            )
        ax.set_ylim(0.5, N_HARMONICS + 0.5)
        ax.set_xlabel("pinion speed (rpm)")
        ax.set_ylabel("mesh harmonic order k (dimensionless)")
        ax.set_title(f"{_label(p, others)}, sweep {direction}", fontsize=9)
        fig.colorbar(im, ax=ax, label="amplitude of delta at k f_m (um)")
        legend_outside(ax, "below", fontsize=7, ncol=2, facecolor="0.5")
    fig.suptitle(
        "Order map of the dynamic transmission error delta\n(integer orders only; sub-harmonics: "
        f"campbell_{direction}.png)",
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def campbell_spectrum(row: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """(frequency Hz, amplitude um) of delta over the kept window of one speed: bins 1, 2,
    ... up to (N_HARMONICS + 0.5) f_m (the DC bin, delta's mean, left out)."""
    A = np.asarray(row["delta_spectrum_um"], float)
    return row["spectrum_df_Hz"] * np.arange(1, A.size + 1), A


def peak_hold(f: np.ndarray, A: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """``A`` (on bins ``f``, uniform) resampled on the rows between ``edges``: each row the
    largest bin inside it, a row holding no bin the nearest bin, NaN beyond the bins. A
    line one bin wide so stays visible whatever the rows' height."""
    df = f[1] - f[0] if f.size > 1 else 1.0
    out = np.full(edges.size - 1, -np.inf)
    row = np.searchsorted(edges, f, side="right") - 1
    ok = (row >= 0) & (row < out.size)
    np.maximum.at(out, row[ok], A[ok])
    centre = 0.5 * (edges[1:] + edges[:-1])
    empty = ~np.isfinite(out)
    nearest = np.clip(np.rint((centre - f[0]) / df).astype(int), 0, f.size - 1)
    out[empty] = A[nearest[empty]]
    out[(centre < f[0] - df / 2) | (centre > f[-1] + df / 2)] = np.nan
    return out


def campbell_grid(rows: list[dict[str, Any]], f_max_Hz: float, n_rows: int = 300):
    """(speed edges rpm, frequency edges Hz, amplitude um (frequency rows x speeds)) of the
    Campbell diagram: each speed's kept-window spectrum of delta (:func:`campbell_spectrum`)
    on common frequency rows (:func:`peak_hold`), each row the largest of itself and its
    two neighbours (a line one row high would be thinner than a pixel line on a
    300-row map: it shows three rows, +-f_max / n_rows); NaN above a speed's spectrum."""
    n = np.array([r["speed_rpm"] for r in rows], float)
    mid = 0.5 * (n[1:] + n[:-1])
    x_edges = np.r_[
        n[0] - (mid[0] - n[0]) if n.size > 1 else n[0] - 1, mid, n[-1] + (n[-1] - mid[-1]) if n.size > 1 else n[-1] + 1
    ]
    y_edges = np.linspace(0.0, f_max_Hz, n_rows + 1)
    Z = np.column_stack([peak_hold(*campbell_spectrum(r), y_edges) for r in rows])
    padded = np.pad(Z, ((1, 1), (0, 0)), constant_values=np.nan)
    with np.errstate(invalid="ignore"):
        wide = np.fmax(np.fmax(padded[:-2], padded[2:]), padded[1:-1])
    return x_edges, y_edges, np.where(np.isnan(Z), np.nan, wide)


def campbell_figure(points: list[Point], chains: list[Chain], others: list[Axis], direction: str):
    """Campbell diagram of one sweep direction: the amplitude spectrum of delta over the
    kept window of each speed (log colour, FLOOR_DB deep) against response frequency and
    speed, the order lines k f_m (k = 1..N_HARMONICS) and f_m / 2, and the model's linear
    eigenfrequencies as horizontal lines. A period-2 response shows its line at f_m / 2,
    any response whatever it holds between the orders."""
    from matplotlib import colormaps
    from matplotlib.colors import LogNorm

    from gearwear.plotting import FLOOR_DB, legend_outside, log_floor

    fig, panels = _chain_panels(points, chains, direction, (7.5, 5.6))
    for ax, p, rows, n in panels:
        z1 = p.scene.pair.teeth[0]
        f_max = (N_HARMONICS + 0.5) * z1 * float(n.max()) / 60
        x_edges, y_edges, Z = campbell_grid(rows, f_max)
        peak = float(np.nanmax(Z)) if np.isfinite(Z).any() else 1.0
        floor = log_floor([peak])
        cmap = colormaps["viridis"].with_extremes(bad="0.92")
        im = ax.pcolormesh(
            x_edges,
            y_edges,
            np.ma.masked_invalid(np.maximum(Z, floor)),
            shading="flat",
            norm=LogNorm(vmin=floor, vmax=peak),
            cmap=cmap,
        )
        for k in range(1, N_HARMONICS + 1):
            ax.plot(
                n,
                k * z1 * n / 60,
                color="w",
                lw=0.5,
                ls=(0, (1, 3)),
                alpha=0.7,
                label=f"order lines k f_m, k = 1..{N_HARMONICS}" if k == 1 else None,
            )
        ax.plot(
            n,
            0.5 * z1 * n / 60,
            color="w",
            lw=0.7,
            ls=(0, (4, 6)),
            alpha=0.8,
            label="f_m / 2 (the line of a period-2 response)",
        )
        for j, f in enumerate(_modes(p)):
            ax.axhline(
                f,
                color="red",
                lw=1.0,
                ls=":",
                label="linear eigenfrequencies: " + ", ".join(f"{v:.0f}" for v in _modes(p)) + " Hz"
                if j == 0
                else None,
            )
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_ylim(0, f_max)
        ax.set_xlabel("pinion speed (rpm)")
        ax.set_ylabel("response frequency (Hz)")
        ax.set_title(f"{_label(p, others)}, sweep {direction}", fontsize=9)
        fig.colorbar(im, ax=ax, label=f"amplitude of delta (um), {FLOOR_DB:g} dB deep")
        legend_outside(ax, "below", fontsize=7, ncol=2, facecolor="0.6")
    fig.suptitle(
        "Campbell diagram of the dynamic transmission error delta\n(the spectrum of the kept window at "
        "each speed; grey: above the computed band)",
        fontsize=10,
    )
    fig.tight_layout()
    return fig
