"""``gearwear scene``: the resolved scene, the JSON Schema, the reference, the built-in names."""

from __future__ import annotations

import argparse
import json

from gearwear.cli.common import SET_HELP, load_scene
from gearwear.core.validation import InputError


def run(args: argparse.Namespace) -> int:
    from gearwear.scene.checks import resolved_dict
    from gearwear.scene.files import builtin_scene_names
    from gearwear.scene.reference import json_schema, reference_markdown, to_toml

    if (args.reference or args.schema or args.list) and (args.scene or args.set or args.json):
        given = [f for f, v in (("SCENE", args.scene), ("--set", args.set), ("--json", args.json)) if v]
        which = "--reference" if args.reference else "--schema" if args.schema else "--list"
        raise InputError(
            f"{', '.join(given)}: not used with {which} (it prints the same for every scene); drop "
            f"{'it' if len(given) == 1 else 'them'}"
        )
    if args.reference:
        print(reference_markdown(), end="")
        return 0
    if args.schema:
        print(json.dumps(json_schema(), indent=2))
        return 0
    if args.list:
        print("\n".join(builtin_scene_names()))
        return 0
    from gearwear.scene.assumptions import scene_assumptions

    scene = load_scene(args, loaded=False)
    assert scene.doc is not None
    data = resolved_dict(scene.doc)
    # what the run derives from the pair: the bore and the bodies where the scene gives none
    data["pair"].setdefault("hub_radius_mm", [round(r * 1e3, 6) for r in scene.pair.hub_radius_m])
    data["bodies"].setdefault("mass_kg", [float(f"{m:.9g}") for m in scene.bodies.mass_kg])
    data["bodies"].setdefault("inertia_kg_m2", [float(f"{j:.9g}") for j in scene.bodies.inertia_kg_m2])
    assumed = scene_assumptions(scene)
    if args.json:
        print(json.dumps({**data, "assumptions": [a.to_dict() for a in assumed]}, indent=2))
    else:
        print("".join(f"# {a.line}\n" for a in assumed) + to_toml(data), end="")
    return 0


def add_parser(sub) -> None:
    """The ``scene`` sub-command's arguments."""
    sc = sub.add_parser(
        "scene",
        help="print a fully resolved scene (every default), the JSON Schema, or the built-in scene names",
        description="gearwear scene NAME|FILE [--set ...]: the scene as the run sees it, every "
        "default filled in (TOML, or --json). gearwear scene --schema: the JSON Schema "
        "of a scene document, for completion and checking in editors. "
        "gearwear scene --list: the built-in scenes.",
    )
    sc.add_argument("scene", nargs="?", help="scene TOML file or built-in scene name (default: paper-default)")
    sc.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help=SET_HELP)
    sc.add_argument("--schema", action="store_true", help="print the JSON Schema of a scene document")
    sc.add_argument("--list", action="store_true", help="list the built-in scene names")
    sc.add_argument(
        "--reference", action="store_true", help="print the scene reference (Markdown, docs/scene-reference.md)"
    )
    sc.add_argument("--json", action="store_true", help="print JSON instead of TOML")
    sc.set_defaults(func=run)
