"""``gearwear geometry``: tooth profile, operating geometry, wear and the pinion mesh."""

from __future__ import annotations

import argparse

from gearwear import io
from gearwear.cli.common import (
    bounded_float,
    check_out,
    fem_plane,
    load_scene,
    output_options,
    pair_inputs,
    print_assumed,
    scene_options,
    wear_dict,
    write_output,
)

#: --mesh-size-mm: the global element size of the whole-gear mesh; on the paper gear 0.25 mm
#: already means ~10^6 P2 triangles (minutes, GiBs), and 10 mm is coarser than a tooth
MESH_SIZE_RANGE_MM = (0.25, 10.0)


def run(args: argparse.Namespace) -> int:
    from gearwear.jobs import geometry as geometry_job

    scene = load_scene(args, loaded=False)
    fem_plane(scene.doc, False, "gearwear geometry")
    torque, clearance_um, wear = scene.operating.torque_Nm, round(scene.clearance_m * 1e6, 9), scene.wear
    mesh_size = bounded_float("--mesh-size-mm", args.mesh_size_mm, "mm", *MESH_SIZE_RANGE_MM)
    out = check_out(args.out, "geometry")
    # the mesh is a file (pinion_mesh.vtu): built only when the folder is written, not for the table
    build_mesh = out is not None and not args.no_mesh
    res = geometry_job.compute(scene, wear, clearance_um * 1e-6, torque, build_mesh=build_mesh, mesh_size_mm=mesh_size)
    inputs = {
        **io.scene_inputs(scene),
        "pair": pair_inputs(scene),
        "wear": wear.label if wear else "unworn",
        "wear_spec": wear_dict(wear),
        "clearance_um": clearance_um,
        "torque_Nm": torque,
        "bearing_stiffness_N_per_m": scene.bodies.bearing_stiffness_N_per_m,
        "bodies": {"mass_kg": list(scene.bodies.mass_kg), "inertia_kg_m2": list(scene.bodies.inertia_kg_m2)},
        "initial_backlash_um": scene.initial_backlash_m * 1e6,
        "mesh": build_mesh,
        "mesh_size_mm": mesh_size,
    }
    files = write_output(
        out,
        "geometry",
        scene,
        inputs,
        lambda d: geometry_job.write(res, d, inputs, io.scene_labels(scene)),
        {"total_s": res.wall_s, "mesh_build_s": res.mesh_build_s},
    )
    summary = res.summary()
    summary["files"] = [str(f) for f in files]
    if args.json:
        print(io.json_text(summary, indent=None))
    else:
        print_summary(summary)
    return 0


def print_summary(s: dict) -> None:
    g0, g1 = s["gears"]
    rows = [
        ("teeth (pinion, gear)", f"{g0['teeth']}, {g1['teeth']}"),
        ("base radius (mm)", f"{g0['base_radius_mm']:.4f}, {g1['base_radius_mm']:.4f}"),
        ("pitch radius (mm)", f"{g0['pitch_radius_mm']:.4f}, {g1['pitch_radius_mm']:.4f}"),
        ("tip radius (mm)", f"{g0['tip_radius_mm']:.4f}, {g1['tip_radius_mm']:.4f}"),
        ("root radius (mm)", f"{g0['root_radius_mm']:.4f}, {g1['root_radius_mm']:.4f}"),
        (
            "form radius / SAP (mm)",
            f"{g0['form_radius_mm']:.4f} / {g0['start_of_active_profile_mm']:.4f}, "
            f"{g1['form_radius_mm']:.4f} / {g1['start_of_active_profile_mm']:.4f}",
        ),
        ("pitch thickness (mm)", f"{g0['pitch_thickness_mm']:.6f}, {g1['pitch_thickness_mm']:.6f}"),
        (
            "HPSTC diameter (mm)",
            ", ".join("-" if g["hpstc_diameter_mm"] is None else f"{g['hpstc_diameter_mm']:.4f}" for g in (g0, g1)),
        ),
        ("undercut", f"{g0['undercut']}, {g1['undercut']}"),
        ("body mass (kg)", f"{g0['mass_kg']:.4g}, {g1['mass_kg']:.4g}  ({s['bodies_from']['mass_kg']})"),
        (
            "body inertia (kg m^2)",
            f"{g0['inertia_kg_m2']:.4g}, {g1['inertia_kg_m2']:.4g}  ({s['bodies_from']['inertia_kg_m2']})",
        ),
        ("bearing clearance (um)", f"{s['clearance_um']:g}"),
        (
            "centre distance (mm)",
            f"{s['centre_distance_mm']:.6f}  (nominal {s['nominal_centre_distance_mm']:.6f}; "
            "the stiffness and the dynamics run at it)",
        ),
        (
            "loaded centre distance (mm)",
            "- (no bearing stiffness given)"
            if s["loaded_centre_distance_mm"] is None
            else f"{s['loaded_centre_distance_mm']:.6f}  (under {s['torque_Nm']:g} N m with the bearings' elastic "
            f"deflection, k_b {s['bearing_stiffness_N_per_m']:.3g} N/m: a state of the dynamic model)",
        ),
        ("operating pressure angle (deg)", f"{s['operating_pressure_angle_deg']:.6f}"),
        ("contact ratio", f"{s['contact_ratio']:.6f}  (nominal {s['nominal_contact_ratio']:.6f})"),
        ("contact line length (mm)", f"{s['contact_line_length_mm']:.6f}"),
        ("normal backlash (um)", f"{s['backlash_um']:.4f}"),
        ("wear", f"{s['wear']}, max depth {s['max_wear_depth_um']:.3f} um"),
    ]
    if "mesh" in s:
        m = s["mesh"]
        rows.append(
            (
                "pinion mesh",
                f"{m['elements']} P2 triangles, {m['nodes']} nodes, "
                f"{m['area_mm2']:.3f} mm^2, built in {m['build_s']:.2f} s",
            )
        )
    w = max(len(r[0]) for r in rows)
    for k, v in rows:
        print(f"{k:<{w}}  {v}")
    print_assumed(s.get("assumptions", []))
    for note in s.get("warnings", []):
        print(f"warning: {note}")
    for f in s.get("files", []):
        print(f"wrote {f}")


def add_parser(sub) -> None:
    """The ``geometry`` sub-command's arguments."""
    g = sub.add_parser(
        "geometry",
        help="tooth profile, operating geometry, wear and gear mesh",
        description="Generate the rack-cut tooth profile (involute + trochoidal fillet), the "
        "operating geometry at a bearing clearance (paper Eqs. 11-16), the worn "
        "flank, and a P2 Gmsh mesh of the whole pinion.",
    )
    scene_options(g, "paper-default")
    g.add_argument(
        "--mesh-size-mm",
        default="2.5",
        help="global element size of the pinion mesh, in [0.25, 10] mm "
        "(default 2.5); fillets 0.4 mm, load point 0.2 mm",
    )
    g.add_argument(
        "--no-mesh",
        action="store_true",
        help="with --out: skip the Gmsh mesh (without --out none is built: the table needs none)",
    )
    output_options(
        g,
        "output folder for profile.csv, tooth.png, pinion_mesh.vtu, summary.json",
        "print one JSON object instead of the table",
    )
    g.set_defaults(func=run)
