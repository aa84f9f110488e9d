"""Figures of ``gearwear diagnose``: the posterior corner plot and measured against fitted
features (matplotlib object API, gearwear.plotting)."""

from __future__ import annotations

import numpy as np

from gearwear.diagnose.job import Fit, feature_rows
from gearwear.plotting import legend_outside, subplots


def _hpd_levels(p: np.ndarray, masses=(0.95, 0.68)) -> list[float]:
    """Density levels enclosing the given posterior masses (highest density first)."""
    flat = np.sort(p.ravel())[::-1]
    cum = np.cumsum(flat) / flat.sum()
    return sorted({float(flat[min(int(np.searchsorted(cum, m)), flat.size - 1)]) for m in masses})


def corner(ft: Fit):
    """Marginals on the diagonal (95 % interval shaded, median dashed), joint densities
    below it (68 and 95 % highest-density contours), on the final grid of the posterior."""
    from gearwear.scene.reference import key_label, key_words

    names = ft.names
    d = len(names)
    units = [u.unit for u in ft.sur.unknowns]
    words = [key_words(u.scene_key)[0] for u in ft.sur.unknowns]
    labels = [key_label(u.scene_key) for u in ft.sur.unknowns]
    fig, axs = subplots(d, d, figsize=(3.2 * d, 3.0 * d), squeeze=False)
    post = ft.post
    for i in range(d):
        for j in range(d):
            ax = axs[i][j]
            if j > i:
                ax.set_visible(False)
                continue
            if i == j:
                x, p = post.axes[i], post.marginal(i)
                e = ft.summary["estimates"][names[i]]
                area = float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(x))) if x.size > 1 else 1.0
                dens = p / max(area, 1e-300)
                ax.plot(x, dens, color="k", lw=1.2)
                band = (x >= e["lo95"]) & (x <= e["hi95"])
                ax.fill_between(x[band], dens[band], color="tab:blue", alpha=0.3, label="95 % interval")
                ax.axvline(e["value"], color="tab:blue", ls="--", lw=1.0, label="median")
                ax.set_yticks([])
                ax.set_title(f"{words[i]} = {e['value']:.3g} [{e['lo95']:.3g}, {e['hi95']:.3g}] {units[i]}", fontsize=8)
                if i == 0:
                    legend_outside(ax, fontsize=7)
            else:
                p = post.joint(j, i)  # axes (j, i): x = unknown j, y = unknown i
                X, Y = np.meshgrid(post.axes[j], post.axes[i], indexing="ij")
                if min(p.shape) > 1:
                    ax.contourf(
                        X, Y, p, levels=[*_hpd_levels(p), p.max() * 1.0001], colors=["tab:blue", "navy"], alpha=0.6
                    )
                ax.plot(*[ft.summary["estimates"][names[k]]["value"] for k in (j, i)], "w+", ms=8)
            if i == d - 1:
                ax.set_xlabel(labels[j], fontsize=8)
            if j == 0 and i > 0:
                ax.set_ylabel(labels[i], fontsize=8)
            ax.tick_params(labelsize=7)
    fig.suptitle("Posterior (uniform prior; zoomed grid box shown)", fontsize=9)
    fig.tight_layout()
    return fig


def features(ft: Fit):
    """Per signal: measured harmonic amplitudes with their total 95 % band (noise and
    surrogate error) and the surrogate at the estimate; the means in the titles."""
    from gearwear.jobs.simulate import SIGNAL_UNITS, SIGNAL_WORDS, signal_name

    rows = feature_rows(ft)
    sigs = list(dict.fromkeys(r["signal"] for r in rows))
    fig, axs = subplots(len(sigs), 1, figsize=(7.5, 2.4 * len(sigs)), squeeze=False)
    for ax, s in zip(axs[:, 0], sigs):
        h = [r for r in rows if r["signal"] == s and r["harmonic"] > 0]
        m = [r for r in rows if r["signal"] == s and r["harmonic"] == 0]
        if h:
            k = np.array([r["harmonic"] for r in h])
            y = np.array([r["measured"] for r in h])
            sd = np.array([np.hypot(r["sigma_noise"], r["sigma_surrogate"]) for r in h])
            ax.errorbar(k - 0.08, y, yerr=1.96 * sd, fmt="o", ms=4, capsize=2, label="measured, 95 % band")
            ax.plot(k + 0.08, [r["fitted"] for r in h], "s", ms=4, mfc="none", label="surrogate at the estimate")
            ax.set_yscale("log")
            ax.set_xticks(k)
        title = SIGNAL_WORDS[signal_name(s)] + (
            "; mean measured "
            + ", ".join(f"{r['measured']:.4g}" for r in m)
            + ", fitted "
            + ", ".join(f"{r['fitted']:.4g}" for r in m)
            if m
            else ""
        )
        ax.set_title(title, fontsize=8)
        ax.set_ylabel(f"harmonic amplitude ({SIGNAL_UNITS[signal_name(s)][0]})", fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.tick_params(labelsize=7, which="both")
    legend_outside(axs[0, 0], fontsize=7)
    axs[-1, 0].set_xlabel("mesh harmonic order k (dimensionless)", fontsize=8)
    fig.tight_layout()
    return fig
