"""F_m harmonics versus bearing clearance, before and after the breakpoint tables.

The acceptance measurement of the staircase issue: the full dynamics of paper-clearance
at 0.5 um steps from 20 to 40 um bearing clearance,

    gearwear sweep paper-clearance --set effects.bearing_clearance.clearance_um=20:40:41 --out DIR

run on commit 74b2d9b (uniform 360-point tables; reports/breakpoints/clearance_sweep_before)
and on this version (reports/breakpoints/clearance_sweep; ``make report`` reruns it). For
each F_m harmonic: the largest departure of a step from its neighbours' trend,
|s_i - (s_i-1 + s_i+1) / 2| / H_i+1 (s the step between neighbouring clearances, H the
harmonic after the step), and the 30 -> 31 um step of the issue: H(31) against the trend
H(30) + s(29.5 -> 30) + s(31 -> 31.5). Writes reports/breakpoints/clearance_sweep.png and
clearance_sweep.json; prints the table. Usage: python benchmarks/clearance_sweep_report.py"""

import csv
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "reports" / "breakpoints"
RUNS = {
    "before (74b2d9b, uniform 360-point table)": OUT / "clearance_sweep_before" / "sweep.csv",
    "after (360 points + breakpoints)": OUT / "clearance_sweep" / "sweep.csv",
}
KEY = "effects.bearing_clearance.clearance_um"
PLOTTED = (3, 4, 7, 9)  # the third harmonic of the issue and the others that jumped most


def load(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(clearance um, F_m harmonics 1-10 N (n, 10)) of a sweep.csv, by clearance."""
    rows = list(csv.DictReader(path.open()))
    x = np.array([float(r[KEY]) for r in rows])
    H = np.array([[float(r[f"h{k}_F_m_N"]) for k in range(1, 11)] for r in rows])
    order = np.argsort(x)
    return x[order], H[order]


def step_departures(H: np.ndarray) -> np.ndarray:
    """|s_i - (s_i-1 + s_i+1) / 2| / H_i+1 for the interior steps i (rows) per harmonic."""
    s = np.diff(H, axis=0)
    return np.abs(s[1:-1] - 0.5 * (s[:-2] + s[2:])) / np.abs(H[2:-1])


def issue_step(x: np.ndarray, H: np.ndarray, a: float = 30.0, b: float = 31.0) -> dict:
    """H(b) against the trend of its neighbours' steps, H(a) + s(a - 0.5 -> a) + s(b -> b + 0.5)
    (two 0.5 um steps from a to b), per harmonic."""
    i, j = int(np.flatnonzero(np.isclose(x, a))[0]), int(np.flatnonzero(np.isclose(x, b))[0])
    trend = H[i] + (H[i] - H[i - 1]) + (H[j + 1] - H[j])
    return {
        "H_a_N": H[i].tolist(),
        "H_b_N": H[j].tolist(),
        "trend_b_N": trend.tolist(),
        "departure": (np.abs(H[j] - trend) / np.abs(H[j])).tolist(),
    }


def figure(data: dict):
    from gearwear.plotting import subplots

    fig, axs = subplots(2, 2, figsize=(11, 7.5), sharex=True)
    for ax, k in zip(axs.ravel(), PLOTTED):
        for (label, (x, H)), style in zip(
            data.items(), (dict(ls="--", marker="s", ms=3, color="C3"), dict(ls="-", marker="o", ms=3, color="C0"))
        ):
            ax.plot(x, H[:, k - 1], label=label, **style)
        ax.set_title(f"harmonic {k} of the mesh force F_m ({k} x f_m)", fontsize=10)
        ax.set_ylabel("amplitude (N)")
        ax.grid(alpha=0.3)
    for ax in axs[-1]:
        ax.set_xlabel("bearing clearance (um)")
    handles, labels = axs[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, frameon=False)
    fig.suptitle("paper-clearance, full dynamics: mesh-force harmonics versus bearing clearance (0.5 um steps)")
    fig.tight_layout(rect=(0, 0.05, 1, 0.97))
    return fig


def main() -> None:
    data = {label: load(path) for label, path in RUNS.items()}
    out = {}
    for label, (x, H) in data.items():
        d = step_departures(H)
        worst = d.argmax(axis=0)
        out[label] = {
            "largest_step_departure": d.max(axis=0).tolist(),
            "at_step_um": [[float(x[w + 1]), float(x[w + 2])] for w in worst],
            "step_30_31": issue_step(x, H),
        }
    print("largest departure of a clearance step from its neighbours' trend, per F_m harmonic (% of the harmonic)")
    print(f"{'harmonic':>9}" + "".join(f"{k:>9}" for k in range(1, 11)))
    for label, r in out.items():
        print(label)
        print(f"{'':>9}" + "".join(f"{100 * v:>9.3f}" for v in r["largest_step_departure"]))
        print(f"{'at (um)':>9}" + "".join(f"{a:>5g}-{b:<3g}" for a, b in r["at_step_um"]))
    print("\nthe 30 -> 31 um step, third harmonic:")
    for label, r in out.items():
        s = r["step_30_31"]
        print(
            f"  {label}: H3(30) = {s['H_a_N'][2]:.4f} N, H3(31) = {s['H_b_N'][2]:.4f} N, neighbours' trend "
            f"{s['trend_b_N'][2]:.4f} N, departure {100 * s['departure'][2]:.3f} %"
        )
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "clearance_sweep.json").write_text(json.dumps(out, indent=1) + "\n")
    figure(data).savefig(OUT / "clearance_sweep.png", dpi=110)
    print(f"wrote {OUT / 'clearance_sweep.json'} and {OUT / 'clearance_sweep.png'}")


if __name__ == "__main__":
    main()
