"""The ``gearwear stiffness`` job: mesh stiffness curves per method, wear and clearance.

Writes one CSV (+ JSON sidecar) per curve, an overlay PNG in the style of paper
Fig. 6 (wear phases) / Fig. 17 (clearances) and, for several clearances, the
mean-stiffness-versus-clearance PNG of paper Fig. 16. A scene with a tip or root relief
adds the Harris map (loaded TE peak-to-peak against load, nominal and modified flank);
a scene with a fault gives curves over one revolution of the faulty gear, with the
faulty tooth's contact marked.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gearwear import io
from gearwear.analytic.model_warnings import assumption_warnings
from gearwear.analytic.tvms import DEFAULT_POINTS, MeshStiffness
from gearwear.core.validation import fail
from gearwear.geometry.faults import FaultSpec
from gearwear.geometry.flank import FlankSpec, flank_warnings
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec
from gearwear.stiffness.sources import BLANK_TORSION, METHODS, SOURCES, Request, curve, fem_curve, iso_curve

__all__ = [
    "BLANK_TORSION",
    "Curve",
    "check_method",
    "compute",
    "fem_curve",
    "figures",
    "harris",
    "iso_curve",
    "write",
    "write_fields",
]


@dataclass
class Curve:
    label: str
    method: str
    wear: WearSpec | None
    clearance_m: float
    result: MeshStiffness

    @property
    def slug(self) -> str:
        w = self.wear.label if self.wear else "unworn"
        return f"{self.method}_{w}_clearance{self.clearance_m * 1e6:g}um"

    def summary(self) -> dict[str, Any]:
        """Curve statistics. Zone means by the number of pairs on the path
        (``zone_means_N_per_m``: "1", "2", "3", ...; null where that count never occurs,
        e.g. no single-contact zone above a contact ratio of 2); the double/single keys
        are the "2" and "1" entries; means are integrals of the piecewise-linear curve
        (geometry.curves). ``points``: the table's nodes (the analytic tables add the
        breakpoints, ``breakpoints_deg``, to the uniform ones). ``warnings``: one-line
        notes (contact ratio below 1, wear beyond the severe phase, flank modifications,
        a pair outside the model's own assumptions: ``analytic.model_warnings``). The pair FE adds
        ``bore_fixed_mean_N_per_m`` (the bodies held at their bores: ``mean_N_per_m`` unless
        ``blank_torsion`` is "excluded"), ``mesh_only_mean_N_per_m`` (the blanks' torsion below
        their reference circles taken out: the one to compare with ishikawa, energy and
        iso6336, which have no blank torsion), ``blank_torsional_stiffness_Nm_per_rad``
        [pinion, gear] (null where the reference circle is the bore) and
        ``blank_reference_radius_mm``."""
        from gearwear.geometry.wear import wear_warnings

        r = self.result
        extra: dict[str, Any] = {}
        if r.flank is not None:
            extra["flank"] = r.flank.label()
        if r.faults is not None:
            extra["faults"] = r.faults.label()
        if "fe" in r.meta:  # the pair FE: both blanks' torsion, and the mesh without it
            fe = r.meta["fe"]
            extra["blank_torsion"] = fe["blank_torsion"]
            extra["bore_fixed_mean_N_per_m"] = fe["bore_fixed_mean_N_per_m"]
            extra["mesh_only_mean_N_per_m"] = fe["mesh_only_mean_N_per_m"]
            extra["blank_torsional_stiffness_Nm_per_rad"] = [
                None if math.isinf(k) else k for k in fe["blank_torsional_stiffness_Nm_per_rad"]
            ]
            extra["blank_reference_radius_mm"] = [r_m * 1e3 for r_m in fe["blank_reference_radius_m"]]
        if r.periods > 1:
            extra["mesh_periods"] = r.periods
            if "fe" in r.meta:  # the pair FE solves only the positions with the faulty tooth again
                extra["fe_positions_solved"] = r.meta["fe"]["positions_solved"]
                extra["fe_cracked_body"] = r.meta["fe"]["cracked_body"]
        z = r.zone_means()

        def null(v: float) -> float | None:
            return None if v is None or math.isnan(v) else v

        return {
            "method": self.method,
            "wear": self.wear.label if self.wear else "unworn",
            "clearance_um": self.clearance_m * 1e6,
            "torque_Nm": r.torque_Nm,
            "mean_N_per_m": r.mean_N_per_m,
            "min_N_per_m": r.min_N_per_m,
            "max_N_per_m": r.max_N_per_m,
            "contact_ratio": r.contact_ratio,
            "points": int(len(r.angle_rad)),
            "breakpoints_deg": [math.degrees(x) for x in r.breakpoints_rad],
            "wall_s": r.wall_s,
            "double_zone_mean_N_per_m": null(z["double"]),
            "single_zone_mean_N_per_m": null(z["single"]),
            "double_zone_length_deg": z["double_deg"],
            "single_zone_length_deg": z["single_deg"],
            "zone_means_N_per_m": {str(n): v for n, v in z["by_count"].items()},
            "zone_lengths_deg": {str(n): v for n, v in z["deg_by_count"].items()},
            "ste_mean_um": r.mean_of(r.ste_m) * 1e6,
            "ste_peak_to_peak_um": float(np.ptp(r.ste_m)) * 1e6,
            "centre_distance_mm": r.mesh.centre_distance_m * 1e3,
            "operating_pressure_angle_deg": math.degrees(r.mesh.pressure_angle_rad),
            "warnings": r.mesh.contact_ratio_warnings()
            + wear_warnings(r.mesh, self.wear)
            + flank_warnings(r.pair, r.flank)
            + assumption_warnings(self.method, r.pair),
            **extra,
        }


def write_fields(curves: list[Curve], out: Path, positions: list[int]) -> list[Path]:
    """Displacement and stress fields (.vtu) of the FE curves at the given position
    indices (over the revolution with a fault), one folder per curve
    (fem.pair.write_fields; the bodies are cached)."""
    from gearwear.fem.pair import pair_model
    from gearwear.fem.pair import write_fields as fe_fields

    files: list[Path] = []
    for c in curves:
        r = c.result
        pm = pair_model(r.pair, c.wear, r.torque_Nm, c.clearance_m, flank=r.flank, faults=r.faults)
        files += fe_fields(pm, positions, len(r.angle_rad) // r.periods, r.torque_Nm, out / f"fields_{c.slug}")
    return files


def check_method(method: str, flank: FlankSpec | None, faults: FaultSpec | None) -> None:
    """Refuse a method that cannot model the scene's flank deviations or faults (names
    ``method``; what each source supports: stiffness.sources.SOURCES)."""
    src = SOURCES[method]
    missing = [
        what
        for what, given, can in (("flank modifications", flank, src.flank), ("faults", faults, src.faults))
        if given is not None and not can
    ]
    if missing:
        able = [n for n in METHODS if (flank is None or SOURCES[n].flank) and (faults is None or SOURCES[n].faults)]
        raise fail(
            "method",
            repr(method),
            "",
            f"is {src.title} and cannot show {' or '.join(missing)}; use {', '.join(able[:-1])} or {able[-1]}",
        )


def compute(
    pair: PairSpec,
    method: str,
    wears: list[WearSpec | None],
    clearances_m: list[float],
    torque_Nm: float,
    points: int,
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
    plane: str = "stress",
    **fe_options,
) -> list[Curve]:
    """The curves of one method (a source of stiffness.sources.SOURCES) for every wear state
    and clearance (``plane``: the 2D state of the FE and of the analytic tooth beams, the
    scene's fem.plane resolved; ``fe_options``: the pair FE's other options, see
    stiffness.sources.fem_curve)."""
    check_method(method, flank, faults)
    curves = []
    for wear in wears:
        for c in clearances_m:
            r = curve(method, Request(pair, torque_Nm, c, wear, flank, faults, points, plane, options=fe_options))
            label = f"{wear.label if wear else 'unworn'}, clearance {c * 1e6:g} um"
            curves.append(Curve(label, method, wear, c, r))
    return curves


HARRIS_LOADS = np.linspace(0.1, 2.0, 20)  # fractions of the scene torque


def harris(curves: list[Curve], pair: PairSpec, flank: FlankSpec | None):
    """The Harris map of the scene's relief (analytic.harris) over 0.1-2 x the scene
    torque, for the first analytic curve's method, wear and clearance; None without a
    tip or root relief or without an analytic curve."""
    from gearwear.analytic.harris import harris_map

    if flank is None or all(r is None for r in (*flank.tip_relief, *flank.root_relief)):
        return None
    c = next((c for c in curves if c.method in ("ishikawa", "energy")), None)
    if c is None:
        return None
    return harris_map(
        pair,
        flank,
        HARRIS_LOADS * c.result.torque_Nm,
        c.method,
        c.result.meta.get("points_per_mesh_period", DEFAULT_POINTS),
        c.wear,
        c.clearance_m,
        plane=c.result.meta.get("plane", "stress"),
    )


def _relief(symbol: str, r) -> str:
    return f"{symbol} = {r.amount_m * 1e6:g} um, {r.shape}, from d = {r.start_diameter_m * 1e3:g} mm"


def relief_text(flank: FlankSpec | None) -> str:
    """The tip and root reliefs of a flank in words, per gear (one clause when both gears
    have the same): "tip relief on both gears: C_a = 8.5 um, linear, from d = 151.83 mm"."""
    if flank is None:
        return "no relief"
    parts = []
    for kind, symbol, rel in (("tip", "C_a", flank.tip_relief), ("root", "C_f", flank.root_relief)):
        if rel[0] is not None and rel[0] == rel[1]:
            parts.append(f"{kind} relief on both gears: {_relief(symbol, rel[0])}")
        else:
            parts += [
                f"{kind} relief on the {who}: {_relief(symbol, r)}"
                for who, r in zip(("pinion", "gear"), rel)
                if r is not None
            ]
    return "; ".join(parts) or "no relief"


def harris_figure(hm, torque_Nm: float, flank: FlankSpec | None = None):
    """Harris map: loaded TE peak-to-peak against torque, nominal and modified flank; the
    title states the relief the modified flank has."""
    import textwrap

    from gearwear.plotting import legend_outside, subplots

    fig, ax = subplots(1, 1, figsize=(8, 4.8))
    ax.plot(hm.torque_Nm, hm.nominal_ste_pp_m * 1e6, "o-", label="nominal flank")
    ax.plot(hm.torque_Nm, hm.modified_ste_pp_m * 1e6, "s-", label="modified flank (title)")
    ax.axvline(torque_Nm, color="grey", ls=":", label=f"scene torque {torque_Nm:g} N m")
    ax.set_xlabel("pinion torque (N m)")
    ax.set_ylabel("loaded static TE peak-to-peak (um)")
    ax.set_ylim(bottom=0)
    ax.set_title(textwrap.fill(f"Harris map; {relief_text(flank)}", 90), fontsize=9)
    ax.grid(alpha=0.3)
    legend_outside(ax, "below", ncol=3)
    fig.tight_layout()
    return fig


def curve_csv(c: Curve) -> str:
    r = c.result
    npair = r.pair_load_N.shape[1]
    cols = (
        ["angle_deg", "k_N_per_m", "pairs_in_contact"]
        + [f"load_pair_{j + 1}_N" for j in range(npair)]
        + ["ste_um", "excitation_um"]
    )
    rows = [",".join(cols)]
    n_in = r.pairs_in_contact
    for i in range(len(r.angle_rad)):
        loads = ",".join(f"{x:.9g}" for x in r.pair_load_N[i])
        rows.append(
            f"{math.degrees(r.angle_rad[i]):.9g},{r.k_N_per_m[i]:.9g},{n_in[i]},{loads},"
            f"{r.ste_m[i] * 1e6:.9g},{r.excitation_m[i] * 1e6:.9g}"
        )
    return "\n".join(rows) + "\n"


def figures(curves: list[Curve]):
    """stiffness.png (k_h and the loaded TE of every curve, the faulty tooth's contact
    shaded) and, for several clearances, mean_vs_clearance.png; legends off the data."""
    from gearwear.plotting import legend_outside, plot_merged, subplots

    figs = {}
    methods = list(dict.fromkeys(c.method for c in curves))

    def name(c: Curve) -> str:  # the method too when several are overlaid
        return c.label if len(methods) == 1 else f"{c.method}: {c.label}"

    fig, (ax, ax2) = subplots(2, 1, figsize=(9, 7), sharex=True)
    for c in curves:
        r = c.result
        ang = np.degrees(r.angle_rad)
        ax.plot(ang, r.k_N_per_m / 1e8, label=name(c))
        ax2.plot(ang, r.ste_m * 1e6, label=name(c))
    ax.set_ylabel("mesh stiffness k_h (1e8 N/m)")
    ax2.set_ylabel("loaded static TE (um)")
    ax2.set_xlabel("pinion angle from entry of a pair at A (deg), one mesh period")
    m0 = curves[0].result
    if m0.periods > 1:
        ax2.set_xlabel(
            f"pinion angle from entry of tooth pair 0 at A (deg), one revolution of the faulty gear "
            f"({m0.periods} mesh periods)"
        )
        if m0.faulty_pair is not None:
            on = np.any(m0.faulty_pair & (m0.pair_load_N > 0), axis=1)
            ang = np.degrees(m0.angle_rad)
            edges = np.flatnonzero(np.diff(np.r_[0, on.astype(int), 0]))
            for k, (i0, i1) in enumerate(zip(edges[::2], edges[1::2])):
                for a in (ax, ax2):
                    a.axvspan(
                        ang[i0],
                        ang[i1 - 1],
                        color="red",
                        alpha=0.12,
                        label="faulty tooth in contact" if k == 0 and a is ax else None,
                    )
    ax.set_title(
        f"Time-varying mesh stiffness ({', '.join(methods)}), T = {m0.torque_Nm:g} N m, "
        f"b = {m0.pair.face_width_m * 1e3:g} mm"
    )
    legend_outside(ax)
    ax.grid(alpha=0.3)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    figs["stiffness.png"] = fig
    clearances = sorted({c.clearance_m for c in curves})
    if len(clearances) > 1:
        fig2, axs = subplots(1, 3, figsize=(13, 4))

        def group(c: Curve) -> str:
            w = c.wear.label if c.wear else "unworn"
            return w if len(methods) == 1 else f"{c.method}, {w}"

        panels: list[list] = [[], [], []]  # (label, x, y, style) per panel; equal curves are drawn once
        for i, wl in enumerate(sorted({group(c) for c in curves})):
            sel = sorted((c for c in curves if group(c) == wl), key=lambda c: c.clearance_m)
            x = np.array([c.clearance_m * 1e6 for c in sel])
            zs = [c.result.zone_means() for c in sel]
            style = {"color": f"C{i}", "ms": 4}
            panels[0].append((wl, x, np.array([c.result.mean_N_per_m / 1e8 for c in sel]), {"marker": "o", **style}))
            panels[1].append((f"double: {wl}", x, np.array([z["double_deg"] for z in zs]), {"marker": "o", **style}))
            panels[1].append(
                (f"single: {wl}", x, np.array([z["single_deg"] for z in zs]), {"marker": "s", "ls": "--", **style})
            )
            panels[2].append((wl, x, np.array([c.result.contact_ratio for c in sel]), {"marker": "o", **style}))
        for a, curves_of in zip(axs, panels):
            span = float(np.ptp(np.concatenate([c[2] for c in curves_of])))
            plot_merged(
                a, curves_of, 0.01 * span, note=lambda y0, ys: f" (within {max(np.max(abs(y - y0)) for y in ys):.2g})"
            )
        axs[0].set_ylabel("mean mesh stiffness (1e8 N/m)")
        axs[1].set_ylabel("zone length per mesh period (deg)")
        axs[2].set_ylabel("contact ratio (dimensionless)")
        for a in axs:
            a.set_xlabel("bearing clearance (um)")
            a.grid(alpha=0.3)
            legend_outside(a, "below", fontsize=7)
        fig2.suptitle("Mesh stiffness versus bearing clearance (paper Fig. 16)")
        fig2.tight_layout()
        figs["mean_vs_clearance.png"] = fig2
    return figs


def write(
    curves: list[Curve],
    out: Path,
    inputs: dict[str, Any],
    labels: dict[str, Any] | None = None,
    harris_map=None,
    assumptions: list[dict] | None = None,
) -> list[Path]:
    """One CSV + sidecar per curve, the overlay PNGs and stiffness_summary.json into the
    folder ``out``. The sidecar's hashed inputs hold every field of the wear definition
    (not only its label); ``labels`` (the scene's name) are recorded, not hashed. No
    wall times: the same inputs give the same bytes (timing goes to timing.json)."""
    files = []
    for c in curves:
        p = io.write_text(out / f"stiffness_{c.slug}.csv", curve_csv(c))
        summary = io.without_timing(c.summary())
        wear = None if c.wear is None else dataclasses.asdict(c.wear)
        files += [
            p,
            io.sidecar(
                p,
                {
                    **inputs,
                    "wear": c.wear.label if c.wear else "unworn",
                    "wear_spec": wear,
                    "clearance_um": c.clearance_m * 1e6,
                },
                c.method,
                {**(labels or {}), "summary": summary},
            ),
        ]
    for name, fig in figures(curves).items():
        files.append(io.write_figure(fig, out / name))
    if harris_map is not None:
        r0 = curves[0].result
        files.append(io.write_figure(harris_figure(harris_map, r0.torque_Nm, r0.flank), out / "harris_map.png"))
        rows = harris_map.rows()
        text = ",".join(rows[0]) + "\n" + "".join(",".join(f"{v:.9g}" for v in r.values()) + "\n" for r in rows)
        files.append(io.write_text(out / "harris_map.csv", text))
    extra = {} if assumptions is None else {"assumptions": assumptions}
    files.append(
        io.write_json(out / "stiffness_summary.json", [{**io.without_timing(c.summary()), **extra} for c in curves])
    )
    return files
