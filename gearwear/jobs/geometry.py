"""The ``gearwear geometry`` job: profile, operating geometry, wear and mesh of a pair.

Pure computation (:func:`compute`) is separated from writing (:func:`write`) so a
bad input fails before any file is touched.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gearwear import io
from gearwear.geometry.flank import hpstc_diameters_m, lpstc_diameters_m
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.operating import OperatingGeometry, centre_distance, operating_geometry
from gearwear.geometry.profile import REGION_NAMES, ToothProfile, gear_outline
from gearwear.geometry.wear import WearSpec, key_roll_angles, wear_warnings, worn_profiles
from gearwear.scene.assumptions import as_dicts, for_command
from gearwear.scene.model import Scene
from gearwear.scene.plausibility import body_warnings, pair_warnings


@dataclass
class GeometryResult:
    scene: Scene
    wear: WearSpec | None
    operating: OperatingGeometry
    nominal: tuple[ToothProfile, ToothProfile]
    worn: tuple[ToothProfile, ToothProfile]
    mesh: Any = None  # gearwear.fem.mesh.GearMesh of the pinion, if built
    mesh_build_s: float = 0.0
    wall_s: float = 0.0
    loaded_centre_distance_m: float | None = None  # with the bearings' elastic deflection (Eq. 11)

    def summary(self) -> dict[str, Any]:
        og = self.operating
        pair = self.scene.pair
        nominal = MeshGeometry(pair, pair.centre_distance_m)
        per_gear = []
        single = og.mesh.contact_ratio >= 1
        hpstc = hpstc_diameters_m(og.mesh) if single else (math.nan, math.nan)
        lpstc = lpstc_diameters_m(og.mesh) if single else (math.nan, math.nan)
        for i, g in enumerate(pair.gears):
            prof = self.nominal[i]
            # the reference circle may lie below the root (large shifts): then the ISO value
            # s = m (pi/2 + 2 x tan alpha) of the extended involute
            on_profile = prof.radius.min() <= g.pitch_radius_m <= prof.radius.max()
            s_pitch = float(prof.thickness_at_radius(g.pitch_radius_m)) if on_profile else g.pitch_thickness_m
            per_gear.append(
                {
                    "name": g.name,
                    "teeth": g.teeth,
                    "profile_shift": g.profile_shift,
                    "base_radius_mm": g.base_radius_m * 1e3,
                    "pitch_radius_mm": g.pitch_radius_m * 1e3,
                    "tip_radius_mm": g.tip_radius_m * 1e3,
                    "root_radius_mm": g.root_radius_m * 1e3,
                    "form_radius_mm": prof.form_radius_m * 1e3,
                    "start_of_active_profile_mm": og.mesh.start_of_active_profile_m[i] * 1e3,
                    "hpstc_diameter_mm": None if math.isnan(hpstc[i]) else hpstc[i] * 1e3,
                    "lpstc_diameter_mm": None if math.isnan(lpstc[i]) else lpstc[i] * 1e3,
                    "pitch_thickness_mm": s_pitch * 1e3,
                    "undercut": prof.undercut,
                    "max_wear_depth_um": float(self.worn[i].depth.max()) * 1e6,
                    "hub_radius_mm": g.hub_radius_m * 1e3,
                    "mass_kg": self.scene.bodies.mass_kg[i],
                    "inertia_kg_m2": self.scene.bodies.inertia_kg_m2[i],
                }
            )
        p0 = per_gear[0]
        out = {
            "contact_ratio": og.contact_ratio,
            "nominal_contact_ratio": nominal.contact_ratio,
            "base_radius_mm": p0["base_radius_mm"],
            "pitch_radius_mm": p0["pitch_radius_mm"],
            "tip_radius_mm": p0["tip_radius_mm"],
            "root_radius_mm": p0["root_radius_mm"],
            "centre_distance_mm": og.centre_distance_m * 1e3,
            "nominal_centre_distance_mm": pair.centre_distance_m * 1e3,
            "zero_backlash_centre_distance_mm": pair.zero_backlash_centre_distance_m * 1e3,
            "operating_pressure_angle_deg": math.degrees(og.pressure_angle_rad),
            "backlash_um": og.backlash_m * 1e6,
            "contact_line_length_mm": og.contact_line_length_m * 1e3,
            "base_pitch_mm": og.mesh.base_pitch_m * 1e3,
            "max_wear_depth_um": max(float(g["max_wear_depth_um"]) for g in per_gear),  # type: ignore[arg-type]
            "wear": self.wear.label if self.wear else "unworn",
            "clearance_um": og.clearance_m * 1e6,
            "torque_Nm": og.torque_Nm,
            "bearing_stiffness_N_per_m": self.scene.bodies.bearing_stiffness_N_per_m,
            "loaded_centre_distance_mm": None
            if self.loaded_centre_distance_m is None
            else self.loaded_centre_distance_m * 1e3,
            "bodies_from": {"mass_kg": self.scene.bodies.mass_from, "inertia_kg_m2": self.scene.bodies.inertia_from},
            "face_width_mm": pair.face_width_m * 1e3,
            "gears": per_gear,
            "assumptions": as_dicts(for_command(self.scene, "geometry")),
            "warnings": og.mesh.contact_ratio_warnings()
            + wear_warnings(og.mesh, self.wear)
            + pair_warnings(self.scene)
            + body_warnings(self.scene),
            "wall_s": self.wall_s,
        }
        if self.mesh is not None:
            m = self.mesh.mesh
            out["mesh"] = {
                "elements": int(m.t.shape[1]),
                "nodes": int(m.p.shape[1]),
                "area_mm2": float(self.mesh.area_m2) * 1e6,
                "build_s": self.mesh_build_s,
            }
        return out


def compute(
    scene: Scene,
    wear: WearSpec | None,
    clearance_m: float,
    torque_Nm: float,
    build_mesh: bool = True,
    mesh_size_mm: float = 2.5,
) -> GeometryResult:
    t0 = time.perf_counter()
    pair = scene.pair
    # the operating geometry the stiffness and the dynamics use: the installed centre distance
    # moved by the bearing clearance (Eq. 11's clearance terms). The elastic bearing deflection
    # under the static load is a state of the dynamic model, not part of this geometry; it is
    # reported on its own (GeometryResult.loaded_centre_distance_m)
    og = operating_geometry(pair, clearance_m, torque_Nm, math.inf, scene.initial_backlash_m, scene.backlash_form)
    spec = wear or WearSpec(phase="unworn")
    # the wear pattern follows the contact path at the operating centre distance
    nominal, worn = worn_profiles(pair, spec, og.mesh)
    res = GeometryResult(scene, wear, og, nominal, worn)
    k_b = scene.bodies.bearing_stiffness_N_per_m
    if k_b is not None and torque_Nm > 0:
        res.loaded_centre_distance_m = centre_distance(pair, clearance_m, torque_Nm, k_b)
    if build_mesh:
        t1 = time.perf_counter()
        res.mesh = pinion_mesh(res, mesh_size_mm * 1e-3)
        res.mesh_build_s = time.perf_counter() - t1
    res.wall_s = time.perf_counter() - t0
    return res


def pinion_mesh(res: GeometryResult, global_size_m: float):
    """P2 mesh of the whole pinion (worn flanks on every tooth if worn), refined at
    every fillet and at the highest point of single tooth contact of tooth 0."""
    from gearwear.fem.mesh import MeshSizes, mesh_full_gear
    from gearwear.geometry.profile import fillet_midpoints, tooth_profile

    pair = res.scene.pair
    g = pair.gear(0)
    # The mesher takes straight segments: a coarser sampling (1 um sag) keeps the
    # boundary from forcing tiny elements while the geometry error stays < 1 um.
    nominal = tooth_profile(g, sag_m=1e-6, extra_roll=key_roll_angles(res.operating.mesh, 0, res.wear))
    worn = None
    if res.worn[0].is_worn:
        from gearwear.geometry.wear import flank_depth

        spec = res.wear or WearSpec(phase="unworn")
        worn = nominal.worn(flank_depth(nominal, 0, res.operating.mesh, spec))
    outline = gear_outline(nominal, worn)
    # load point: highest point of single tooth contact (HPSTC) on tooth 0's right flank
    d_hp = res.operating.mesh.single_contact_limits_m[1]
    r_hp = float(res.operating.mesh.pinion_radius_at(d_hp))
    beta = float(nominal.half_angle_at_radius(r_hp)[0])
    load = np.array([[r_hp * math.sin(beta), r_hp * math.cos(beta)]])
    # the refinements never ask for coarser elements than the global size
    sizes = MeshSizes(global_m=global_size_m, fillet_m=min(0.4e-3, global_size_m), load_m=min(0.2e-3, global_size_m))
    return mesh_full_gear(
        outline, g.hub_radius_m, sizes, refine_points_xy=load, fillet_points_xy=fillet_midpoints(nominal, g.teeth)
    )


def profile_table(res: GeometryResult) -> str:
    """CSV of both loaded flanks (nominal and worn), one row per profile point."""
    cols = [
        "gear",
        "region",
        "s_mm",
        "x_mm",
        "y_mm",
        "normal_x",
        "normal_y",
        "radius_mm",
        "roll_angle_deg",
        "wear_depth_um",
        "x_worn_mm",
        "y_worn_mm",
    ]
    lines = [",".join(cols)]
    for i, (nom, worn) in enumerate(zip(res.nominal, res.worn)):
        name = ("pinion", "gear")[i]
        roll = np.where(np.isfinite(nom.roll), np.degrees(nom.roll), np.nan)
        for k in range(len(nom.s)):
            r = "" if not np.isfinite(roll[k]) else f"{roll[k]:.9g}"
            lines.append(
                f"{name},{REGION_NAMES[int(nom.region[k])]},{nom.s[k] * 1e3:.9f},{nom.xy[k, 0] * 1e3:.9f},"
                f"{nom.xy[k, 1] * 1e3:.9f},{nom.normal[k, 0]:.12f},{nom.normal[k, 1]:.12f},"
                f"{nom.radius[k] * 1e3:.9f},{r},{worn.depth[k] * 1e6:.6f},"
                f"{worn.xy[k, 0] * 1e3:.9f},{worn.xy[k, 1] * 1e3:.9f}"
            )
    return "\n".join(lines) + "\n"


def key_radii_mm(res: GeometryResult, i: int) -> dict[str, float]:
    """The points of gear ``i``'s active flank at the operating centre distance (mm):
    SAP, LPSTC, operating pitch circle, HPSTC (the single-contact limits only with a
    contact ratio of at least 1)."""
    mesh = res.operating.mesh
    out = {"SAP": mesh.start_of_active_profile_m[i] * 1e3}
    if mesh.contact_ratio >= 1:
        out["LPSTC"] = lpstc_diameters_m(mesh)[i] * 0.5e3
    out["pitch"] = mesh.operating_pitch_radii_m[i] * 1e3
    if mesh.contact_ratio >= 1:
        out["HPSTC"] = hpstc_diameters_m(mesh)[i] * 0.5e3
    return out


def _outline_panel(ax, res: GeometryResult, i: int) -> None:
    """One gear's tooth: nominal, worn and the wear depth x50, with its base, form and
    pitch circles named at alternate ends (close radii never share an end)."""
    from gearwear.geometry.profile import tooth_outline
    from gearwear.plotting import legend_outside, stagger_levels

    nom, worn = res.nominal[i], res.worn[i]
    g = res.scene.pair.gear(i)
    o = tooth_outline(nom)
    name = f"worn ({res.wear.label if res.wear else 'unworn'})"
    depth_um = float(np.max(worn.depth)) * 1e6 if worn.is_worn else 0.0
    # a wear depth below 1/200 of the tooth height is within a line width: one outline, said so
    same = worn.is_worn and depth_um * 1e-6 < 0.005 * float(np.ptp(o[:, 1]))
    ax.plot(
        o[:, 0] * 1e3,
        o[:, 1] * 1e3,
        "k-",
        lw=1.2,
        label=f"nominal = {name} at this scale (depth <= {depth_um:.3g} um)" if same else "nominal",
    )
    if worn.is_worn:
        if not same:
            w = tooth_outline(worn, nom)
            ax.plot(w[:, 0] * 1e3, w[:, 1] * 1e3, "r-", lw=1.0, label=name)
        exaggeration = 50.0
        ex = nom.xy - exaggeration * worn.depth[:, None] * nom.normal
        ax.plot(ex[:, 0] * 1e3, ex[:, 1] * 1e3, "r--", lw=0.8, label=f"worn, depth x{exaggeration:g}")
    th = np.linspace(-math.pi / g.teeth, math.pi / g.teeth, 200)
    circles = [(g.base_radius_m, "base"), (g.pitch_radius_m, "pitch"), (nom.form_radius_m, "form")]
    levels = stagger_levels([r for r, _ in circles], 0.06 * float(np.ptp(o[:, 1])))  # m, as the radii
    for (rad, lab), level in zip(circles, levels):
        ax.plot(rad * np.sin(th) * 1e3, rad * np.cos(th) * 1e3, ":", lw=0.7)
        end = th[0] if level % 2 == 0 else th[-1]  # inward from the left or the right end, above the circle
        ax.annotate(
            lab,
            (rad * math.sin(end) * 1e3, rad * math.cos(end) * 1e3),
            xytext=(0, 2),
            textcoords="offset points",
            fontsize=7,
            ha="left" if level % 2 == 0 else "right",
            va="bottom",
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(
        f"{('Pinion', 'Gear')[i]} tooth: z = {g.teeth}, m = {g.module_m * 1e3:g} mm, x = {g.profile_shift:g}",
        fontsize=10,
    )
    legend_outside(ax, "below", ncol=2)


def _wear_panel(ax, res: GeometryResult, i: int) -> None:
    """One gear's wear depth against its own flank radius, its SAP, LPSTC, pitch and HPSTC
    marked by dashed lines and named above the axes (staggered: no overprint); an
    unworn flank says so instead of drawing a zero line."""
    from gearwear.plotting import labels_above, title_pad

    nm, wp = res.nominal[i], res.worn[i]
    mask = np.isfinite(nm.roll)
    if wp.is_worn:
        ax.plot(nm.radius[mask] * 1e3, wp.depth[mask] * 1e6, ("C0-", "C1-")[i])
        ax.set_ylim(bottom=0)
    else:
        ax.set_xlim(nm.radius[mask].min() * 1e3, nm.radius[mask].max() * 1e3)
        ax.set_ylim(0, 1)
        ax.set_yticks([0])
        ax.text(
            0.5,
            0.5,
            "unworn: no wear",
            transform=ax.transAxes,
            ha="center",
            va="center",
            fontsize=11,
            color="0.3",
            bbox={"fc": "w", "ec": "none"},
        )
    marks = key_radii_mm(res, i)
    for r in marks.values():
        ax.axvline(r, color="0.5", lw=0.7, ls="--")
    lo, hi = ax.get_xlim()
    rows = labels_above(ax, list(marks.values()), list(marks), 0.12 * (hi - lo))
    ax.set_xlabel(f"radius on the {('pinion', 'gear')[i]} flank (mm)")
    ax.set_ylabel("wear depth along the normal (um)")
    ax.set_title(
        f"{('Pinion', 'Gear')[i]} wear depth ({res.wear.label if res.wear else 'unworn'}"
        f"{', ' + res.wear.model if res.wear and wp.is_worn else ''})",
        fontsize=10,
        pad=title_pad(rows),
    )
    ax.grid(alpha=0.3)


def tooth_figure(res: GeometryResult):
    """tooth.png: per gear (columns: pinion, gear) its tooth outline and its wear depth,
    each on its own axes and scale."""
    from gearwear.plotting import subplots

    fig, axs = subplots(2, 2, figsize=(12, 10.5), gridspec_kw={"height_ratios": [1.25, 1]})
    for i in range(2):
        _outline_panel(axs[0][i], res, i)
        _wear_panel(axs[1][i], res, i)
    fig.tight_layout()
    return fig


def write(res: GeometryResult, out: Path, inputs: dict[str, Any], labels: dict[str, Any] | None = None) -> list[Path]:
    """Write profile CSV (+ sidecar), tooth PNG, mesh .vtu (+ sidecar) and summary JSON
    into the folder ``out``. No wall times (they go to timing.json); ``labels`` (the
    scene's name) are recorded in the sidecars but not hashed."""
    files = []
    csv = io.write_text(out / "profile.csv", profile_table(res))
    files += [
        csv,
        io.sidecar(
            csv, inputs, "rack-generated involute + trochoid; wear " + (res.wear.model if res.wear else "none"), labels
        ),
    ]
    files.append(io.write_figure(tooth_figure(res), out / "tooth.png"))
    if res.mesh is not None:
        from gearwear.fem.mesh import write_mesh

        vtu = out / "pinion_mesh.vtu"
        write_mesh(res.mesh, path_vtu=str(vtu))
        files += [
            vtu,
            io.sidecar(
                vtu,
                inputs,
                "gmsh P2 triangles, full pinion",
                {**(labels or {}), "elements": int(res.mesh.mesh.t.shape[1])},
            ),
        ]
    summ = io.without_timing(res.summary())
    # names relative to the folder: the bytes do not depend on where the folder is
    summ["files"] = [f.name for f in files] + ["summary.json"]
    files.append(io.write_json(out / "summary.json", summ))
    return files
