"""``gearwear atlas SPEC --out DIR``: every analytic mesh-stiffness model of the registry
against the pair FE over a Sobol design of spur pairs (gearwear.jobs.atlas)."""

from __future__ import annotations

import argparse

from gearwear import io
from gearwear.cli.common import SCHEDULER_HELP, check_out, output_options, worker_count, write_output


def run(args: argparse.Namespace) -> int:
    from gearwear.jobs import atlas, atlas_spec
    from gearwear.jobs.atlas_space import design_space
    from gearwear.jobs.sweep import make_executor
    from gearwear.stiffness.tables import cache_dir

    spec = atlas_spec.load(args.spec)
    out = check_out(args.out, "atlas")
    workers = worker_count(args)
    space = design_space(spec.values)  # the rejects are counted before any FE work
    folder = cache_dir() / "atlas"  # a bad GEARWEAR_CACHE fails here, in one line
    with make_executor(workers, args.scheduler) as executor:
        result = atlas.compute(spec, space, executor, progress=not args.json, cache=folder)
    files = write_output(
        out,
        "atlas",
        None,
        {"spec": spec.as_dict()},
        lambda d: atlas.write(spec, result, d),
        result["timing"],
    )
    summary = {
        "designs": len(space.designs),
        "points_drawn": space.drawn,
        "rejects": space.rejects,
        "from_cache": result["cached"],
        "models": list(atlas.FE_MODELS + spec.models),
        "wall_s": result["timing"]["total_wall_s"],
        "files": [str(f) for f in files],
    }
    if args.json:
        print(io.json_text(summary, indent=None))
    else:
        rejects = ", ".join(f"{k} {v}" for k, v in space.rejects.items())
        print(f"{len(space.designs)} designs of {space.drawn} Sobol points (rejected: {rejects})")
        print(f"{result['cached']} designs from the cache; {summary['wall_s']:.1f} s")
        for f in files:
            print(f"wrote {f}")
    return 0


def add_parser(sub) -> None:
    """The ``atlas`` sub-command's arguments."""
    from gearwear.jobs.atlas_spec import defaults_text

    ap = sub.add_parser(
        "atlas",
        help="every analytic mesh-stiffness model against the pair FE over a Sobol design of spur pairs",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Draw a scrambled Sobol design of feasible spur pairs (rejects counted by reason: "
        "undercut, pointed tip, interference, contact ratio), compute every analytic model of the "
        "stiffness registry and the pair FE (one solve: blanks' torsion excluded and bore-fixed) per "
        "design, and write atlas.csv (one row per design and model: mean, plateaus, peak-to-peak, "
        "harmonics 1-3, loaded STE peak-to-peak, transition angles) with its sidecar. Each design is "
        "cached by its content ($GEARWEAR_CACHE/atlas): an interrupted atlas resumes where it stopped.\n\n"
        "SPEC keys (TOML; [section] key = value; every key optional, its default written to the sidecar):\n"
        + defaults_text(),
    )
    ap.add_argument("spec", help="atlas SPEC, a TOML file (see the keys above)")
    ap.add_argument("--workers", help="local worker processes (default: all cores)")
    ap.add_argument("--scheduler", help=SCHEDULER_HELP)
    output_options(ap)
    ap.set_defaults(func=run)
