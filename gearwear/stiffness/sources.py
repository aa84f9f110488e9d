"""Where a mesh stiffness comes from: one registry, :data:`SOURCES`.

Every source is a function ``Request -> MeshStiffness`` (analytic.tvms: k_h(phi), the
wear excitation e(phi), the loaded STE and, where the source knows them, the pair loads
and positions; SI units) with what it supports. Two audiences read the same registry:

* ``gearwear stiffness --method NAME`` and ``gw.mesh_stiffness(method=NAME)`` take the
  sources marked ``command`` (:data:`METHODS`): the models whose curve is the result;
* ``effects.mesh_stiffness.source = NAME`` in a scene takes the sources marked ``scene``
  (:data:`SCENE_SOURCES`): what drives the dynamics. Its ``analytic`` is Ishikawa's
  slice model (the paper's), ``calibrated`` the FE-calibrated tables, ``table`` a user's
  CSV and ``constant`` one value (default: the analytic mean).

The command line's choices, the API's check, the schema's Literal and the generated
source table in docs/models.md come from here or are tested equal to it
(tests/test_sources.py). To add a source, add one :class:`Source` entry with its curve
function, and its tests (CONTRIBUTING.md, "Adding a stiffness source").

Heavy modules (the models, the FE) are imported inside the curve functions: this module
is read by the command line before its signal handlers are installed.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Mapping

from gearwear.analytic import TABLE_POINTS_PER_MESH_PERIOD

if TYPE_CHECKING:
    from gearwear.analytic.tvms import MeshStiffness
    from gearwear.geometry.faults import FaultSpec
    from gearwear.geometry.flank import FlankSpec
    from gearwear.geometry.spec import PairSpec
    from gearwear.geometry.wear import WearSpec

#: pair-FE positions per mesh period unless a command says otherwise (the 24-position cycle of the
#: paper pair: docs/accuracy-and-cost.md)
FE_POSITIONS = 24

#: what the FE-based stiffness holds of the gear blanks (effects.mesh_stiffness.blank_torsion)
BLANK_TORSION = ("in_series", "excluded")


@dataclass(frozen=True)
class Request:
    """What a stiffness curve is asked for (SI units).

    ``points``: nodes per mesh period (None: the source's ``default_points``); ``plane``:
    the 2D state of the FE and of the analytic tooth beams (the scene's fem.plane
    resolved); ``breakpoints``: the analytic table's exact load-sharing breakpoints on top
    of the uniform nodes; ``blank_torsion``: the FE sources' blanks in series with the mesh
    or taken out; ``options``: a source's own inputs (the FE's mesh_scale, executor,
    progress; a table's ``angle_rad``, ``k_N_per_m``, ``excitation_m``; a constant's
    ``value_N_per_m``)."""

    pair: PairSpec
    torque_Nm: float
    clearance_m: float = 0.0
    wear: WearSpec | None = None
    flank: FlankSpec | None = None
    faults: FaultSpec | None = None
    points: int | None = None
    plane: str = "stress"
    breakpoints: bool = True
    blank_torsion: str = "in_series"
    options: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Source:
    """One stiffness source: ``curve(request)`` and what it supports.

    ``command``: a ``--method`` of gearwear stiffness and the API; ``scene``: a value of
    effects.mesh_stiffness.source. ``flank``/``faults``: the curve can show flank
    deviations and single-tooth faults (the load sharing); ``plane``: it honours fem.plane;
    ``fe``: it runs the FE (seconds to minutes; the dynamics check the solver first). A
    constant shows flank deviations and faults only through the analytic wear excitation
    (with the transmission_error effect), and has a 2D state only as the analytic mean."""

    name: str
    title: str
    curve: Callable[[Request], "MeshStiffness"]
    default_points: int = TABLE_POINTS_PER_MESH_PERIOD
    command: bool = False
    scene: bool = False
    flank: bool = True
    faults: bool = True
    plane: bool = True
    fe: bool = False

    def points(self, request: Request) -> int:
        return self.default_points if request.points is None else request.points


# -- the curve functions -------------------------------------------------------------------


def _corrected(rq: Request) -> "MeshStiffness":
    """gearwear.stiffness.corrected.corrected_curve: the energy method's curve times the FE /
    energy ratios the atlas surrogate predicts for the pair (refuses outside the atlas)."""
    from gearwear.stiffness.corrected import corrected_curve

    return corrected_curve(rq)


def _analytic(method: str, name: str | None = None) -> Callable[[Request], "MeshStiffness"]:
    """The curve of analytic.tvms.mesh_stiffness (load sharing over the slice or energy
    compliances) with ``method``, at the default points of source ``name`` (default: the method's)."""

    def curve(rq: Request) -> "MeshStiffness":
        from gearwear.analytic.tvms import mesh_stiffness

        return mesh_stiffness(
            rq.pair,
            method=method,
            points=SOURCES[name or method].points(rq),
            torque_Nm=rq.torque_Nm,
            clearance_m=rq.clearance_m,
            wear=rq.wear,
            flank=rq.flank,
            faults=rq.faults,
            breakpoints=rq.breakpoints,
            plane=rq.plane,
        )

    return curve


#: the dynamics' ``analytic`` source: Ishikawa's slice model (the paper's)
_scene_analytic = _analytic("ishikawa", "analytic")


def iso_curve(pair: PairSpec, points: int, torque_Nm: float, clearance_m: float) -> "MeshStiffness":
    """ISO 6336-1 method B as a constant curve k = c_gamma_alpha b at the operating
    contact ratio (the standard gives no angle dependence)."""
    import numpy as np

    from gearwear.analytic.iso6336 import iso6336_stiffness
    from gearwear.analytic.tvms import MeshStiffness
    from gearwear.geometry.operating import operating_geometry

    t0 = time.perf_counter()
    og = operating_geometry(pair, clearance_m)
    iso = iso6336_stiffness(pair, torque_Nm=torque_Nm, contact_ratio=og.contact_ratio)
    k = np.full(points, iso.mesh_stiffness_N_per_m)
    theta = np.arange(points) * (og.mesh.mesh_angle_rad / points)
    F = torque_Nm / pair.gear(0).base_radius_m
    contacts = og.mesh.contacts(theta)
    share = np.where(contacts.active, F / np.maximum(contacts.count, 1)[:, None], 0.0)
    return MeshStiffness(
        "iso6336",
        pair,
        og.mesh,
        torque_Nm,
        None,
        theta,
        k,
        F / k,
        np.zeros(points),
        share,
        contacts.d,
        contacts.active,
        time.perf_counter() - t0,
        meta={"iso": dataclasses.asdict(iso)},
    )


def fem_curve(
    pair: PairSpec,
    points: int,
    torque_Nm: float,
    clearance_m: float,
    wear: WearSpec | None,
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
    blank_torsion: str = "in_series",
    **fe_options,
) -> "MeshStiffness":
    """Resolved FE contact of both gear bodies (fem.pair) as a MeshStiffness curve, over
    one revolution of the faulty gear with ``faults`` (``fe_options``: pair_contact's
    mesh_scale, contact_scale, plane, extended, executor, progress). ``blank_torsion``:
    "in_series" (the bodies held at their bores: both blanks' torsion in series with the
    mesh) or "excluded" (the mesh only: the blanks' torsion below their reference
    circles taken out, fem.pair "The blank's torsion"); meta["fe"] holds both means and
    the blanks' torsional stiffnesses either way."""
    from gearwear.analytic.tvms import MeshStiffness
    from gearwear.core.validation import InputError, fail, renamed
    from gearwear.fem.pair import pair_contact

    if blank_torsion not in BLANK_TORSION:
        raise fail("blank_torsion", repr(blank_torsion), "", f"must be one of {', '.join(BLANK_TORSION)}")
    try:
        fe = pair_contact(
            pair,
            wear=wear,
            positions=points,
            torque_Nm=torque_Nm,
            clearance_m=clearance_m,
            flank=flank,
            faults=faults,
            **fe_options,
        )
    except InputError as exc:  # a body too large for this machine names its bore (fem.memory)
        raise renamed(exc, {"hub_radius_m": ("pair.hub_radius_mm", 1e3, "mm")}) from None
    meta = {
        **{k: v for k, v in fe.meta.items() if k != "pair_gap_m"},
        "blank_torsion": blank_torsion,
        "bore_fixed_mean_N_per_m": fe.mean_N_per_m,
    }
    if blank_torsion == "excluded":
        fe = fe.without_blank_torsion()
    return MeshStiffness(
        "fem",
        pair,
        fe.mesh,
        torque_Nm,
        wear,
        fe.angle_rad,
        fe.k_N_per_m,
        fe.ste_m,
        fe.excitation_m,
        fe.pair_load_N,
        fe.pair_d_m,
        fe.pair_in_path,
        float(fe.timings.get("total_s", float("nan"))),
        meta={"fe": meta},
        flank=flank,
        faults=fe.faults,
        periods=fe.periods,
        faulty_pair=fe.faulty_pair,
    )


def _iso(rq: Request) -> "MeshStiffness":
    return iso_curve(rq.pair, SOURCES["iso6336"].points(rq), rq.torque_Nm, rq.clearance_m)


def _fem(rq: Request) -> "MeshStiffness":
    return fem_curve(
        rq.pair,
        SOURCES["fem"].points(rq),
        rq.torque_Nm,
        rq.clearance_m,
        rq.wear,
        rq.flank,
        rq.faults,
        blank_torsion=rq.blank_torsion,
        plane=rq.plane,
        **rq.options,
    )


def table_curve(
    name: str,
    rq: Request,
    angle_rad,
    k_N_per_m,
    excitation_m,
    ste_m=None,
    wall_s: float = 0.0,
    meta: Mapping[str, Any] | None = None,
    periods: int = 1,
) -> "MeshStiffness":
    """A k_h(phi), e(phi) table as the common curve type. A table carries no pair loads or
    contact positions: those arrays have no columns (shape (n, 0)), and an unknown loaded
    STE is NaN, never a made-up number."""
    import numpy as np

    from gearwear.analytic.tvms import MeshStiffness
    from gearwear.geometry.operating import operating_geometry

    phi = np.asarray(angle_rad, dtype=float)
    n = len(phi)
    ste = np.full(n, np.nan) if ste_m is None else np.asarray(ste_m, dtype=float)
    return MeshStiffness(
        name,
        rq.pair,
        operating_geometry(rq.pair, rq.clearance_m).mesh,
        rq.torque_Nm,
        rq.wear,
        phi,
        np.asarray(k_N_per_m, dtype=float),
        ste,
        np.asarray(excitation_m, dtype=float),
        np.zeros((n, 0)),
        np.zeros((n, 0)),
        np.zeros((n, 0), dtype=bool),
        wall_s,
        meta=dict(meta or {}),
        flank=rq.flank,
        faults=rq.faults,
        periods=periods,
    )


def _calibrated(rq: Request) -> "MeshStiffness":
    """The FE-calibrated table (stiffness.calibration, cached by its inputs), with both
    blanks' torsion taken out when the request says "excluded"."""
    from gearwear.geometry.faults import revolution_periods
    from gearwear.stiffness.calibration import calibrated_table, without_blank_torsion

    t0 = time.perf_counter()
    tab = calibrated_table(
        rq.pair,
        rq.wear,
        rq.clearance_m,
        rq.torque_Nm,
        SOURCES["calibrated"].points(rq),
        flank=rq.flank,
        faults=rq.faults,
        plane=rq.plane,
    )
    if rq.blank_torsion == "excluded":
        tab = without_blank_torsion(tab)
    return table_curve(
        "calibrated",
        rq,
        tab.angle_rad,
        tab.k_N_per_m,
        tab.excitation_m,
        tab.ste_m,
        time.perf_counter() - t0,
        {"table": tab.meta},
        revolution_periods(rq.pair, rq.faults),
    )


def _user_table(rq: Request) -> "MeshStiffness":
    """A user's k_h(phi) CSV, read and checked by the scene (scene.model.read_stiffness_table):
    ``options`` holds its ``angle_rad``, ``k_N_per_m`` and ``excitation_m`` (None: zero)."""
    import numpy as np

    o = rq.options
    k = np.asarray(o["k_N_per_m"])
    e = o.get("excitation_m")
    return table_curve("table", rq, o["angle_rad"], k, np.zeros_like(k) if e is None else e)


def _constant(rq: Request) -> "MeshStiffness":
    """One value at the analytic table's nodes: ``options["value_N_per_m"]``, else the
    analytic curve's mean. The analytic wear excitation is kept (it acts with the
    transmission_error effect)."""
    import numpy as np

    r = _scene_analytic(rq)
    value = rq.options.get("value_N_per_m")
    k = np.full_like(r.k_N_per_m, r.mean_N_per_m if value is None else value)
    return dataclasses.replace(r, method="constant", k_N_per_m=k)


#: every stiffness source, by name (the order is the order of the command line's choices)
SOURCES: dict[str, Source] = {
    s.name: s
    for s in (
        Source("ishikawa", "Ishikawa/Weber slice model (paper Eqs. 2-6)", _analytic("ishikawa"), command=True),
        Source("energy", "potential-energy method (Yang & Lin, Sainsot foundation)", _analytic("energy"), command=True),
        Source(
            "yang_lin",
            "Yang & Lin 1987: involute from the base circle, bending + axial + linear Hertz",
            _analytic("yang_lin"),
            command=True,
            faults=False,
        ),
        Source(
            "tian",
            "Tian 2004: involute from the base circle, bending + shear + axial + linear Hertz",
            _analytic("tian"),
            command=True,
            faults=False,
        ),
        Source(
            "wu_zuo_parey",
            "Wu, Zuo & Parey 2008: Tian's tooth from the base circle, Sainsot foundation, linear Hertz",
            _analytic("wu_zuo_parey"),
            command=True,
            faults=False,
        ),
        Source(
            "chen_shao",
            "Chen & Shao 2013: clamped at the root circle, Sainsot foundation, linear Hertz",
            _analytic("chen_shao"),
            command=True,
        ),
        Source(
            "chen_shao_weber",
            "Chen & Shao 2013 with Weber's foundation (Weber & Banaschek)",
            _analytic("chen_shao_weber"),
            command=True,
        ),
        Source(
            "kuang_yang",
            "Kuang & Yang 1992: empirical tooth stiffness in N, x and the contact radius",
            _analytic("kuang_yang"),
            command=True,
            faults=False,
            plane=False,
        ),
        Source(
            "iso6336", "one constant (ISO 6336-1 method B)", _iso, command=True, flank=False, faults=False, plane=False
        ),
        Source(
            "corrected",
            "atlas-corrected energy method: a surrogate of the pair FE over the atlas's design space",
            _corrected,
            command=True,
            flank=False,
            faults=False,
        ),
        Source("constant", "one value (default: the analytic mean)", _constant, scene=True, plane=False),
        Source("analytic", "Ishikawa/Weber slice model, as a table for the dynamics", _scene_analytic, scene=True),
        Source("calibrated", "FE-calibrated analytic tables (cached by input hash)", _calibrated, scene=True, fe=True),
        Source(
            "fem",
            "resolved pair FE of both gear bodies",
            _fem,
            default_points=FE_POSITIONS,
            command=True,
            scene=True,
            fe=True,
        ),
        Source("table", "a user's k_h(phi) CSV", _user_table, scene=True, flank=False, faults=False, plane=False),
    )
}

#: ``gearwear stiffness --method`` and ``gw.mesh_stiffness(method=...)``
METHODS = tuple(n for n, s in SOURCES.items() if s.command)
#: ``effects.mesh_stiffness.source`` (the schema's Literal is tested equal to it)
SCENE_SOURCES = tuple(n for n, s in SOURCES.items() if s.scene)


def curve(name: str, request: Request) -> "MeshStiffness":
    """The curve of source ``name`` for ``request``."""
    return SOURCES[name].curve(request)
