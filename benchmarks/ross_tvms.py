"""Time-varying mesh stiffness (TVMS) of a spur pair computed by ROSS, for benchmarks.

Standalone: run it with the python of the separate benchmark environment, never with
the project's one, and it imports nothing from this project::

    .venv-bench/bin/python benchmarks/ross_tvms.py [--pair JSON] [--points 360] [--repeats 3]

Tested with ross-rotordynamics 2.3.0 and plotly 6.9.0 (Python 3.11). pip resolves
ross-rotordynamics 2.3.0 to plotly 7.1.0, with which ``import ross`` fails (plotly 7
dropped ``scattermapbox``), so plotly < 7 is pinned::

    python3 -m venv .venv-bench
    .venv-bench/bin/python -m pip install 'ross-rotordynamics==2.3.0' 'plotly<7'

What ROSS computes (ross/gear_element.py, read from the 2.3.0 source):

* ``GearElementTVMS(n, material, width, bore_diameter, module, n_teeth, pr_angle,
  helix_angle=0, addendum_coeff=1, tip_clearance_coeff=0.25)``: one gear, SI units.
  Tooth: involute plus the rack-generated fillet; rack tip radius is fixed at
  c m / (1 - sin alpha) (c = tip_clearance_coeff); dedendum = addendum_coeff + c.
  Tooth compliance by the potential-energy method (bending, shear with factor 1.2,
  axial; Ma et al. 2014), each term one ``scipy.integrate.quad`` over the fillet and
  one over the involute, per contact point; fillet-foundation compliance by the
  Sainsot et al. (2004) formula with h = r_f / (bore_diameter / 2).
* ``Mesh(driving, driven)``: contact ratio, a constant Hertzian stiffness
  pi E b / (4 (1 - nu^2)) (driving gear's E, nu; load independent), and, in the
  constructor, the curve over one mesh period at 1000 points
  (``get_stiffness_for_mesh_period()``, stored as ``theta_range`` / ``stiffness_range``).
* ``Mesh.get_variable_stiffness(theta)``: the mesh stiffness (N/m, along the line of
  action) at pinion angle theta (rad): 1 / (1/k_H + 1/k_1 + 1/k_2) per tooth pair,
  summed over the pairs in contact. Nothing is cached: each call re-runs the quads.
  ``get_stiffness_for_mesh_period(n_mesh_period, n_points)`` is a list comprehension
  over it on ``linspace(0, 2 pi / z1, n_points)`` (endpoint included).
* Kinematics (a property of ROSS, not of this script): the contact point is moved
  linearly in the *pressure angle* with rotation (the roll angle tan(alpha) is what is
  linear), and each tooth's contact runs from its involute start ``alpha_c`` (end of
  the fillet; 8.90 deg for the paper pair) to its tip (28.24 deg), not from the start
  of the active profile (10.80 deg). The double/single contact durations follow the
  contact ratio and are right; the contact positions inside them are approximate.

Timing: the gears and the Mesh are built once (reported as ``construct_s``; that
includes ROSS's own 1000-point curve), then the full ``points``-point curve is
evaluated ``repeats`` times; the median wall time is reported. With ``--grid periodic``
(default) the angles are ``arange(points) * (2 pi / z1) / points`` (one period, end
point excluded, like analytic.tvms, so the mean is a proper period mean); with
``--grid ross`` the curve is ``get_stiffness_for_mesh_period(1, points)`` verbatim.
Both cost ``points`` calls of ``get_variable_stiffness``.

Prints one JSON line on stdout (the last line; import-time chatter of ROSS's
dependencies is sent to stderr).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import statistics
import sys
import time
import warnings

#: The paper gear pair (Zhang et al. 2019 plus the project's documented assumptions).
DEFAULT_PAIR = {
    "teeth": [30, 30],
    "module_mm": 5.0,
    "pressure_angle_deg": 20.0,
    "face_width_mm": 20.0,
    "youngs_modulus_GPa": 206.0,
    "poisson_ratio": 0.3,
    "density_kg_per_m3": 7850.0,
    "hub_radius_mm": [40.0, 40.0],
    "addendum_coefficient": 1.0,
    "dedendum_coefficient": 1.25,
    "rack_tip_radius_coefficient": 0.38,
    "profile_shift": [0.0, 0.0],
}


@contextlib.contextmanager
def stdout_to_stderr():
    """Send everything written to fd 1 (also by C extensions) to fd 2 meanwhile."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def per_gear(value, name):
    if isinstance(value, (list, tuple)):
        if len(value) != 2:
            raise SystemExit(f"ross_tvms: {name} must be one value or two (pinion, gear)")
        return list(value)
    return [value, value]


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pair", default="{}", help="JSON object overriding keys of the default pair (or @file.json)")
    ap.add_argument("--points", type=int, default=360, help="angle points over one mesh period")
    ap.add_argument("--repeats", type=int, default=3, help="timed evaluations of the full curve")
    ap.add_argument("--grid", choices=("periodic", "ross"), default="periodic")
    ap.add_argument("--plot", default=None, help="also save a PNG of the curve here")
    args = ap.parse_args(argv)
    text = args.pair
    if text.startswith("@"):
        with open(text[1:], encoding="utf-8") as fh:
            text = fh.read()
    user = json.loads(text)
    unknown = sorted(set(user) - set(DEFAULT_PAIR))
    if unknown:
        raise SystemExit(f"ross_tvms: unknown pair keys {unknown}; known: {sorted(DEFAULT_PAIR)}")
    pair = {**DEFAULT_PAIR, **user}
    if args.points < 2 or args.repeats < 1:
        raise SystemExit("ross_tvms: --points must be >= 2 and --repeats >= 1")
    return args, pair


def ross_inputs(pair):
    """Map the pair onto ROSS's arguments; list what ROSS cannot take."""
    notes = []
    teeth = per_gear(pair["teeth"], "teeth")
    hub = per_gear(pair["hub_radius_mm"], "hub_radius_mm")
    shift = per_gear(pair["profile_shift"], "profile_shift")
    alpha = math.radians(pair["pressure_angle_deg"])
    ha = float(pair["addendum_coefficient"])
    c = float(pair["dedendum_coefficient"]) - ha  # ROSS: dedendum = addendum + tip clearance
    rho_ross = c / (1.0 - math.sin(alpha))  # ROSS's rack tip radius (in modules), not an input
    if abs(rho_ross - pair["rack_tip_radius_coefficient"]) > 1e-3:
        notes.append(
            f"rack tip radius: ROSS fixes it at c/(1 - sin alpha) = {rho_ross:.4f} m "
            f"(asked {pair['rack_tip_radius_coefficient']:g} m)"
        )
    if any(x != 0 for x in shift):
        notes.append(f"profile shift {shift} ignored: ROSS has no profile shift (x = 0)")
    notes.append(
        "load independent: ROSS's TVMS is linear (no torque input; constant Hertzian stiffness pi E b / (4 (1 - nu^2)))"
    )
    gears = [
        dict(
            n=i,
            width=pair["face_width_mm"] * 1e-3,
            bore_diameter=2.0 * hub[i] * 1e-3,
            module=pair["module_mm"] * 1e-3,
            n_teeth=int(teeth[i]),
            pr_angle=alpha,
            addendum_coeff=ha,
            tip_clearance_coeff=c,
        )
        for i in (0, 1)
    ]
    return gears, notes


def main(argv=None):
    args, pair = parse_args(sys.argv[1:] if argv is None else argv)
    gear_kw, notes = ross_inputs(pair)
    seen_warnings = []

    def keep(ws):
        for w in ws:
            msg = f"{w.category.__name__}: {w.message}"
            if msg not in seen_warnings:
                seen_warnings.append(msg)

    with stdout_to_stderr():
        t0 = time.perf_counter()
        import numpy as np
        import ross
        from ross.gear_element import GearElementTVMS, Mesh
        from ross.materials import Material

        import_s = time.perf_counter() - t0

        material = Material(
            name="bench_steel",
            rho=pair["density_kg_per_m3"],
            E=pair["youngs_modulus_GPa"] * 1e9,
            Poisson=pair["poisson_ratio"],
        )
        # "default": each warning once per location (ROSS warns on every quad call)
        with warnings.catch_warnings(record=True) as ws:
            warnings.simplefilter("default")
            t0 = time.perf_counter()
            gears = [GearElementTVMS(material=material, **kw) for kw in gear_kw]
            mesh = Mesh(gears[0], gears[1])
            construct_s = time.perf_counter() - t0
        keep(ws)

        period = 2.0 * math.pi / gears[0].n_teeth
        if args.grid == "periodic":
            theta = np.arange(args.points) * (period / args.points)

            def curve():
                return theta, [mesh.get_variable_stiffness(t) for t in theta]
        else:

            def curve():
                return mesh.get_stiffness_for_mesh_period(1, args.points)

        walls = []
        for _ in range(args.repeats):
            with warnings.catch_warnings(record=True) as ws:
                warnings.simplefilter("default")
                t0 = time.perf_counter()
                th, k = curve()
                walls.append(time.perf_counter() - t0)
            keep(ws)
        th = np.asarray(th, dtype=float)
        k = np.asarray(k, dtype=float)
        fig_path = None
        if args.plot:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=(7, 4))
            ax.plot(np.degrees(th), k / 1e8, "k-")
            ax.set_xlabel("pinion angle (deg) over one mesh period")
            ax.set_ylabel("mesh stiffness (1e8 N/m)")
            ax.set_title(f"ROSS {ross.__version__} GearElementTVMS, {args.points} points, mean {k.mean():.3e} N/m")
            ax.grid(True)
            fig.tight_layout()
            fig.savefig(args.plot, dpi=110)
            fig_path = args.plot

    try:
        import plotly

        plotly_version = plotly.__version__
    except Exception:  # noqa: BLE001 - only informational
        plotly_version = None
    out = {
        "ross_version": ross.__version__,
        "plotly_version": plotly_version,
        "python": sys.version.split()[0],
        "points": int(args.points),
        "repeats": int(args.repeats),
        "grid": args.grid,
        "wall_s_median": statistics.median(walls),
        "wall_s_all": walls,
        "construct_s": construct_s,
        "import_s": import_s,
        "mean_N_per_m": float(k.mean()),
        "min_N_per_m": float(k.min()),
        "max_N_per_m": float(k.max()),
        "contact_ratio": float(mesh.contact_ratio),
        "hertzian_stiffness_N_per_m": float(mesh.hertzian_stiffness),
        "ross_inputs": [{key: (float(v) if isinstance(v, float) else v) for key, v in kw.items()} for kw in gear_kw],
        "pair": pair,
        "notes": notes,
        "warnings": seen_warnings,
        "plot": fig_path,
        "angle_rad": [float(x) for x in th],
        "k_N_per_m": [float(x) for x in k],
    }
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
