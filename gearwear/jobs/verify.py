"""The ``gearwear verify`` job: analytic (Ishikawa, energy) versus FE tooth compliance.

Per wear phase: FE single-tooth compliance on the full gear (fem.tooth) at the load
positions from SAP to tip, the Ishikawa delta_1 + delta_2 and the energy-method
bending + shear + axial + foundation compliance at the same radii, their differences,
and the wall time of each method. Plus (with the convergence study) the FE h/p
convergence with Richardson extrapolation (fem.convergence) and, in single contact,
the local approach c_local that the resolved pair FE (fem.pair) finds between the
tooth centre lines against Weber's half-plane formula in plane stress and plane
strain, with the identity k_pair = 1 / (c_1 + c_2 + c_local) (c_1, c_2 single-tooth
FE). Writes verification.md, PNGs and verification.json.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gearwear import io
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec
from gearwear.stiffness.comparison import tooth_vs_analytic


@dataclass
class PhaseResult:
    label: str
    radius_mm: np.ndarray
    roll_angle_deg: np.ndarray
    fem: np.ndarray
    ishikawa: np.ndarray
    energy: np.ndarray
    fem_wall_s: float
    ishikawa_wall_s: float
    energy_wall_s: float
    dofs: int
    elements: int

    def to_json(self) -> dict[str, Any]:
        return {
            "radius_mm": self.radius_mm.tolist(),
            "roll_angle_deg": self.roll_angle_deg.tolist(),
            "fem_compliance_um_per_N_per_mm": self.fem.tolist(),
            "ishikawa_compliance_um_per_N_per_mm": self.ishikawa.tolist(),
            "energy_compliance_um_per_N_per_mm": self.energy.tolist(),
            "ishikawa_difference_percent": (100 * (self.ishikawa / self.fem - 1)).tolist(),
            "energy_difference_percent": (100 * (self.energy / self.fem - 1)).tolist(),
            "wall_s": self.fem_wall_s,
            "ishikawa_wall_s": self.ishikawa_wall_s,
            "energy_wall_s": self.energy_wall_s,
            "fem_dofs": self.dofs,
            "fem_elements": self.elements,
        }


@dataclass
class Verification:
    pair: PairSpec
    phases: list[PhaseResult]
    convergence: list[dict] | None
    acceptance: dict | None
    wall_s: float = 0.0
    pair_consistency: list | None = None
    meta: dict = field(default_factory=dict)


def run_phase(pair: PairSpec, wear: WearSpec | None, positions: int = 21, plane: str = "stress") -> PhaseResult:
    from gearwear.fem.tooth import single_tooth_compliance

    fe = single_tooth_compliance(pair, gear_index=0, wear=wear, positions=positions, plane=plane)
    cmp = tooth_vs_analytic(fe)
    return PhaseResult(
        wear.label if wear else "unworn",
        fe.radius_mm,
        fe.roll_angle_deg,
        fe.fem_compliance_um_per_N_per_mm,
        cmp.ishikawa_um_per_N_per_mm,
        cmp.energy_um_per_N_per_mm,
        fe.wall_s,
        cmp.ishikawa_wall_s,
        cmp.energy_wall_s,
        int(fe.ndofs),
        int(fe.n_elements),
    )


def run(
    pair: PairSpec,
    wears: list[WearSpec | None],
    positions: int = 21,
    convergence: bool = True,
    progress=None,
    plane: str = "stress",
) -> Verification:
    """The FE (2D idealisation ``plane``, the scene's fem.plane) against the analytic
    models for every wear state, and with ``convergence`` the h/p convergence and the pair
    consistency check."""
    t0 = time.perf_counter()
    phases = []
    for w in wears:
        phases.append(run_phase(pair, w, positions, plane))
        if progress:
            progress(f"FE compliance, wear {phases[-1].label}")
    conv = acc = None
    if convergence:
        from gearwear.fem.convergence import acceptance, convergence_table

        conv = convergence_table(
            pair,
            None,
            positions=positions,
            plane=plane,
            progress=(lambda row: progress(f"convergence P{row['order']} scale {row['mesh_scale']:.3f}"))
            if progress
            else None,
        )
        acc = acceptance(conv)
        from gearwear.stiffness.comparison import pair_consistency

        cons = pair_consistency(pair, plane=plane)  # ~8 s: the pair model and two single-tooth runs
        return Verification(
            pair, phases, conv, acc, time.perf_counter() - t0, pair_consistency=cons, meta={"plane": plane}
        )
    return Verification(pair, phases, conv, acc, time.perf_counter() - t0, meta={"plane": plane})


#: curves closer than this fraction of their panel's range are drawn once ("unworn = mild")
COINCIDE = 0.01
METHOD_STYLES = (
    ("FE", "fem", {"marker": "o", "ms": 4, "ls": "-"}),
    ("Ishikawa", "ishikawa", {"ls": "--"}),
    ("energy", "energy", {"ls": ":"}),
)


def _panel(ax, curves, note) -> None:
    """Draw (label, x, y, style) curves, coinciding ones once (:data:`COINCIDE` of the
    range; ``note`` says by how much they differ), with the legend right of the axes."""
    from gearwear.plotting import legend_outside, plot_merged

    if not curves:
        return
    span = float(np.ptp(np.concatenate([np.ravel(c[2]) for c in curves])))
    plot_merged(ax, curves, COINCIDE * span, note=note)
    legend_outside(ax, fontsize=7)


def _relative(y0: np.ndarray, others: list[np.ndarray]) -> str:
    return f" (within {max(float(np.max(np.abs(o / y0 - 1))) for o in others) * 100:.2g} %)"


def _points(y0: np.ndarray, others: list[np.ndarray]) -> str:
    return f" (within {max(float(np.max(np.abs(o - y0))) for o in others):.2g} % points)"


def figures(v: Verification):
    """compliance.png: FE and analytic compliance per wear phase, their differences, and
    the change by wear. Wear changes the compliance by far less than the methods differ,
    so the phases of one method coincide in the top panels: each is drawn once, its label
    naming every phase it stands for ("FE: unworn = mild = severe")."""
    from gearwear.plotting import subplots

    figs = {}
    fig, (ax, ax2, ax3) = subplots(3, 1, figsize=(11, 11), sharex=True)
    colours = {ph.label: f"C{i}" for i, ph in enumerate(v.phases)}

    def curves(y_of, phases, methods=METHOD_STYLES):
        return [
            (f"{name}: {ph.label}", ph.radius_mm, y_of(ph, attr), {"color": colours[ph.label], **style})
            for name, attr, style in methods
            for ph in phases
        ]

    _panel(ax, curves(lambda ph, a: getattr(ph, a), v.phases), _relative)
    _panel(ax2, curves(lambda ph, a: 100 * (getattr(ph, a) / ph.fem - 1), v.phases, METHOD_STYLES[1:]), _points)
    base = next((ph for ph in v.phases if ph.label == "unworn"), None)
    if base is not None:
        _panel(
            ax3,
            curves(
                lambda ph, a: 100 * (getattr(ph, a) / getattr(base, a) - 1), [ph for ph in v.phases if ph is not base]
            ),
            _points,
        )
    ax.set_ylabel("tooth compliance (um per N/mm)")
    ax.set_title("Single-tooth compliance: FE (full gear, bore fixed) vs analytic bending+shear+foundation")
    ax.grid(alpha=0.3)
    ax2.axhline(0, color="k", lw=0.6)
    ax2.set_ylabel("analytic - FE (% of FE)")
    ax2.grid(alpha=0.3)
    ax3.set_ylabel("compliance change by wear (% of unworn)")
    ax3.set_xlabel("load radius (mm), start of active profile to tip")
    ax3.grid(alpha=0.3)
    fig.tight_layout()
    figs["compliance.png"] = fig
    return figs


def _per_gear(values) -> str:
    """'206' for one value of both gears, '206/103' for pinion/gear."""
    a, b = values
    return f"{a:g}" if a == b else f"{a:g}/{b:g}"


def markdown(v: Verification, files: dict[str, str]) -> str:
    p = v.pair
    lines = [
        "# Verification: analytic tooth compliance against FE",
        "",
        f"Pair: z = {p.teeth[0]}/{p.teeth[1]}, m = {p.module_m * 1e3:g} mm, alpha = "
        f"{np.degrees(p.pressure_angle_rad):g} deg, b = {p.face_width_m * 1e3:g} mm, E = "
        f"{_per_gear(m.youngs_modulus_Pa / 1e9 for m in p.materials)} GPa, nu = "
        f"{_per_gear(m.poisson_ratio for m in p.materials)}, bore radius "
        f"{p.hub_radius_m[0] * 1e3:g} mm. FE: full gear (all teeth), bore fixed, "
        f"plane {v.meta.get('plane', 'stress')}, P2 "
        "triangles, load along the line of action as a Hertzian pressure patch; the deflection is the "
        "displacement of the tooth centre line at the load radius projected on the load direction. "
        "Compliance = deflection per load per unit face width (um per N/mm). Analytic: Ishikawa/Weber "
        "delta_1 + delta_2 (paper Eqs. 2-4) and the potential-energy method (bending + shear + axial + "
        "Sainsot foundation), without the Hertz term.",
        "",
    ]
    if "compliance.png" in files:
        lines += [f"![compliance]({files['compliance.png']})", ""]
    for ph in v.phases:
        lines += [
            f"## Wear: {ph.label}",
            "",
            f"FE: {ph.dofs} dofs, {ph.elements} elements, {len(ph.radius_mm)} positions (wall times: timing.json).",
            "",
            "| radius (mm) | roll (deg) | FE | Ishikawa | diff % | energy | diff % |",
            "|---|---|---|---|---|---|---|",
        ]
        for k in range(len(ph.radius_mm)):
            lines.append(
                f"| {ph.radius_mm[k]:.3f} | {ph.roll_angle_deg[k]:.2f} | {ph.fem[k]:.5f} | "
                f"{ph.ishikawa[k]:.5f} | {100 * (ph.ishikawa[k] / ph.fem[k] - 1):+.1f} | "
                f"{ph.energy[k]:.5f} | {100 * (ph.energy[k] / ph.fem[k] - 1):+.1f} |"
            )
        lines.append("")
    if v.convergence:
        lines += [
            "## FE convergence (unworn, h- and p-refinement, Richardson extrapolation)",
            "",
            "```",
            _table(v.convergence),
            "```",
            "",
        ]
        if "convergence.png" in files:
            lines += [f"![convergence]({files['convergence.png']})", ""]
        a = v.acceptance or {}
        lines += [
            f"Default level: {a.get('default_dofs')} dofs; "
            f"change to the next finer P2 level {a.get('default_vs_finer_change_pct', float('nan')):.3f} %; "
            f"two finest P2 levels differ by {a.get('finest_p2_change_pct', float('nan')):.3f} %; "
            f"error vs extrapolation {a.get('default_error_vs_extrapolation_pct', float('nan')):.3f} %.",
            "",
        ]
    if v.pair_consistency:
        lines += [
            "## Pair FE in single contact: local approach c_local against Weber",
            "",
            "c_1, c_2: deflection of the tooth centre-line points where the load line crosses them, per N, "
            "read in the resolved pair FE and by the single-tooth FE (own mesh, Hertz patch); c_local = "
            "STE / F - c_1 - c_2 (pair FE). Units 1e-9 m/N.",
            "",
            "| d (mm) | c_1 pair | c_1 tooth | c_2 pair | c_2 tooth | c_local | Weber stress | Weber strain "
            "| k pair (N/m) | 1/(c_1+c_2+c_local) |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in v.pair_consistency:
            f = 1e9
            lines.append(
                f"| {r['d_m'] * 1e3:.3f} | {r['c1_m_per_N'] * f:.4f} | {r['c1_tooth_m_per_N'] * f:.4f} | "
                f"{r['c2_m_per_N'] * f:.4f} | {r['c2_tooth_m_per_N'] * f:.4f} | "
                f"{r['c_local_m_per_N'] * f:.4f} | {r['weber_stress_m_per_N'] * f:.4f} | "
                f"{r['weber_strain_m_per_N'] * f:.4f} | {r['k_pair_N_per_m']:.5e} | "
                f"{r['k_identity_N_per_m']:.5e} |"
            )
        lines.append("")
    return "\n".join(lines)


def _table(rows: list[dict]) -> str:
    from gearwear.fem.convergence import format_table

    return format_table(rows, wall_time=False)  # a result file: wall times go to timing.json


def write(v: Verification, out: Path, inputs: dict[str, Any], labels: dict[str, Any] | None = None) -> list[Path]:
    """verification.md, the PNGs and verification.json (with its provenance inside)
    into the folder ``out``; no wall times (timing.json)."""
    files: list[Path] = []
    names: dict[str, str] = {}
    for name, fig in figures(v).items():
        files.append(io.write_figure(fig, out / name))
        names[name] = name
    if v.convergence:
        from gearwear.fem.convergence import convergence_figure

        files.append(
            io.write_figure(convergence_figure(v.convergence, wall_time=False), out / "convergence.png", dpi=120)
        )
        names["convergence.png"] = "convergence.png"
    files.append(io.write_text(out / "verification.md", markdown(v, names)))
    js = io.without_timing(to_json(v))
    # a JSON result carries its provenance inside instead of a .json.json sidecar
    from gearwear import __version__

    js["provenance"] = {
        "software": "gearwear",
        "version": __version__,
        "inputs": inputs,
        "input_sha256": io.input_hash(inputs),
        "method": "fem.tooth vs analytic.ishikawa / analytic.energy",
        **(labels or {}),
    }
    files.append(io.write_json(out / "verification.json", js, indent=1))
    return files


def to_json(v: Verification) -> dict[str, Any]:
    out: dict[str, Any] = {"phases": {ph.label: ph.to_json() for ph in v.phases}, "wall_s": v.wall_s}
    if v.convergence is not None:
        out["convergence"] = [{k: val for k, val in r.items() if k != "timings"} for r in v.convergence]
        out["acceptance"] = v.acceptance
    if v.pair_consistency is not None:
        out["pair_consistency"] = v.pair_consistency
    return out
