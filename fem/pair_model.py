"""The pair model of the resolved pair FE (fem.pair): everything a position solve needs,
built once per pair, torque and clearance (SI units: m, N, rad, Pa).

* the inputs, checked in this layer's names (torque_Nm, clearance_m, plane, the faults)
  and the operating geometry (geometry.operating, rigid bearings);
* the element sizes (:func:`body_sizes`): the contact element size h_c = a_ref / 2.5, a_ref
  the Hertz half-width of one pair at the pitch point under the full load; the candidate
  half-window WINDOW_HALF_WIDTHS a_ref + 2 h_c of arc length;
* one FE body per distinct gear (fem.pair_body.build_body), its refined flank covering
  every radius a contact can reach (geometry.pair_positions.lowest_contact_radius_m), and
  with a root crack the cracked body of that gear (fem.pair_body.build_cracked_body, the
  teeth that can be candidates together with the cracked one refined alike). Bodies are
  cached in-process (wear states, faults and worker chunks of one pair share them; one
  build at a time per process); two distinct bodies are built overlapped, the first one's
  assembly and condensation in a worker thread while the second is meshed
  (:func:`_healthy_bodies`);
* per gear the depth of the drive flank (wear, geometry.wear.flank_depth, plus the profile
  modifications and measured deviations of geometry.flank) along the nominal profile:
  the FE bodies keep the nominal flanks, the depths enter the contact as initial gaps
  (fem.pair_candidates).
"""

from __future__ import annotations

import math
import threading
import time
from collections import OrderedDict
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, replace
from functools import partial
from typing import Any

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.crack import check_crack
from gearwear.geometry.faults import FaultSpec, check_faults
from gearwear.geometry.flank import FlankSpec, is_nominal, modification_depth_m
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.loading import load_points
from gearwear.geometry.operating import operating_geometry
from gearwear.geometry.pair_positions import (
    base_half_angle_rad,
    fault_neighbours,
    lowest_contact_radius_m,
    reach_ranges,
)
from gearwear.geometry.profile import INVOLUTE, tooth_profile
from gearwear.geometry.sampling import FINE_SAG_M
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec, flank_depth, hertz_half_width, key_roll_angles

from .memory import check_bodies
from .pair_body import BodySizes, GearBody, body_builder, build_cracked_body, estimated_dofs
from .process_settings import one_blas_thread, small_pages

__all__ = [
    "PairModel",
    "pair_model",
    "body_sizes",
    "ELEMENTS_PER_HALF_WIDTH",
    "WINDOW_HALF_WIDTHS",
    "EXTENSION_PITCHES",
]

ELEMENTS_PER_HALF_WIDTH = 2.5  # h_c = a_ref / 2.5 at contact_scale 1
WINDOW_HALF_WIDTHS = 3.0  # candidate window: +-3 a_ref of arc length (+ 2 h_c)
EXTENSION_PITCHES = 0.08  # pairs considered up to 0.08 p_b beyond A and E (corner contact)
_BODY_CACHE: "OrderedDict[tuple, GearBody]" = OrderedDict()  # cracked bodies too
_BODY_CACHE_SIZE = 4
_BODY_LOCK = threading.RLock()


def _positive(key: str, value, unit: str = "") -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise fail(key, repr(value), unit, "must be a finite number > 0") from None
    if not (math.isfinite(v) and v > 0):
        raise fail(key, value, unit, "must be a finite number > 0")
    return v


def body_sizes(
    pair: PairSpec, torque_Nm: float = 40.0, contact_scale: float = 1.0, mesh_scale: float = 1.0
) -> tuple[BodySizes, float]:
    """Element sizes of the pair bodies and a_ref (m). h_c = a_ref / 2.5 x
    contact_scale, a_ref the Hertz half-width (plane strain) of one pair at the pitch
    point under T / r_b1 on the nominal geometry; the rest scales with the module
    (near teeth 0.125 m, far teeth 0.3 m, fillets 0.05 m, interior 0.4 m) x mesh_scale."""
    cs = _positive("contact_scale", contact_scale)
    ms = _positive("mesh_scale", mesh_scale)
    mg = MeshGeometry(pair, pair.centre_distance_m)
    F = torque_Nm / pair.gear(0).base_radius_m
    a_ref = float(hertz_half_width(mg, np.array([mg.pitch_point_m]), F / pair.face_width_m)[0])
    m = pair.module_m
    return BodySizes(
        contact_m=a_ref / ELEMENTS_PER_HALF_WIDTH * cs,
        near_m=0.125 * m * ms,
        far_m=0.3 * m * ms,
        fillet_m=0.05 * m * ms,
        global_m=0.4 * m * ms,
    ), a_ref


@dataclass
class PairModel:
    """Everything a position solve needs (built once per pair, torque and clearance).

    faults   the one-tooth faults (geometry.faults) or None; ``cracked`` per gear the
             body with the crack (pair_body.CrackedBody) or None."""

    pair: PairSpec
    mesh: MeshGeometry
    bodies: tuple
    wear: WearSpec | None
    depth: tuple  # per gear: (radius, depth) arrays of the drive flank, or None
    window_m: float  # candidate half-window (arc length)
    a_ref_m: float
    sizes: BodySizes
    plane: str
    timings: dict
    faults: FaultSpec | None = None
    cracked: tuple = (None, None)

    @property
    def psi_b(self) -> tuple[float, float]:
        """Half angular thickness of each gear's tooth on its base circle (rad;
        geometry.pair_positions.base_half_angle_rad)."""
        return (base_half_angle_rad(self.pair.gear(0)), base_half_angle_rad(self.pair.gear(1)))


def _body_key(g, pair, sizes, r_lo, nb, cy, plane):
    return (
        replace(g, name=""),
        g.material,
        pair.face_width_m,
        sizes,
        round(r_lo, 9),
        nb,
        tuple(round(c, 9) for c in cy),
        plane,
    )


@contextmanager
def _building() -> Iterator[None]:
    """The process-wide settings of a body build, held by this (the calling) thread around
    it, so that a worker thread's holds only nest (fem.process_settings): one BLAS thread,
    the same rounding in overlapped and serial builds; no huge-page stalls on the bodies'
    fresh arrays. Held only while something is built."""
    with one_blas_thread(), small_pages():
        yield


def _cached(key: tuple, build):
    """The body under ``key`` from the in-process cache, or ``build()`` stored there;
    (body, built). One build at a time: threads of one worker process (a Dask worker)
    that need the same body wait for it instead of building it twice."""
    with _BODY_LOCK:
        if key in _BODY_CACHE:  # identical gears, another wear state or fault of the same pair
            _BODY_CACHE.move_to_end(key)
            return _BODY_CACHE[key], False
        with _building():
            body = build()
        _BODY_CACHE[key] = body
        while len(_BODY_CACHE) > _BODY_CACHE_SIZE:
            _BODY_CACHE.popitem(last=False)
        return body, True


def _healthy_bodies(keys: list, builders: list) -> list[tuple[GearBody, bool]]:
    """(body, built) per gear: the bodies under ``keys`` from the in-process cache, the
    missing ones built by ``builders`` (per gear: a function of no arguments that meshes
    the body and returns the rest of its build, pair_body.body_builder). A body two gears
    share is built once (``built`` True for the first gear only). With two distinct
    bodies missing, the first one's assembly and condensation run in a worker thread
    while this thread meshes the second: Gmsh and SuperLU's factorization, LAPACK and
    most of METIS's graph work release the GIL, so on two cores the two builds overlap
    (Gmsh itself stays in this thread; the result is the serial one to the bit, every
    body being built alone from its own inputs)."""
    with _BODY_LOCK:
        have: dict = {}
        missing: list = []
        for k in keys:
            if k in _BODY_CACHE:
                _BODY_CACHE.move_to_end(k)
                have[k] = _BODY_CACHE[k]
            elif k not in missing:
                missing.append(k)
        built: dict = {}
        if len(missing) == 2:
            with _building():
                finish_first = builders[keys.index(missing[0])]()
                with ThreadPoolExecutor(max_workers=1, thread_name_prefix="gearwear-body") as ex:
                    first = ex.submit(finish_first)
                    built[missing[1]] = builders[keys.index(missing[1])]()()
                    built[missing[0]] = first.result()
        elif missing:
            with _building():
                built[missing[0]] = builders[keys.index(missing[0])]()()
        for k, body in built.items():
            _BODY_CACHE[k] = body
        while len(_BODY_CACHE) > _BODY_CACHE_SIZE:
            _BODY_CACHE.popitem(last=False)
        out: list[tuple[GearBody, bool]] = []
        told: set = set()
        for k in keys:
            out.append((built[k] if k in built else have[k], k in built and k not in told))
            told.add(k)
        return out


def _cracked_body(
    pair: PairSpec,
    mesh: MeshGeometry,
    faults: FaultSpec,
    nominal,
    sizes: BodySizes,
    r_lo: float,
    nb: int,
    cy: tuple[float, float],
    window: float,
    plane: str,
):
    """The body of the cracked gear (cached in-process like the healthy ones; the key
    holds the crack, its tip size and the refined teeth)."""
    from .tooth import default_crack_tip_size_m

    cf = faults.crack
    assert cf is not None
    gi = cf.gear_index
    g = pair.gear(gi)
    crack = cf.crack
    check_crack(nominal, crack)
    tip_m = default_crack_tip_size_m(crack, fillet_m=sizes.fillet_m)
    refined = fault_neighbours(mesh, EXTENSION_PITCHES)
    sp = faults.spall
    # a spall on the same gear widens the candidate window by up to its length
    margin = 2.0 * window + (sp.length_m if sp is not None and sp.gear_index == gi else 0.0)
    ranges = reach_ranges(mesh, gi, refined, r_lo, margin, EXTENSION_PITCHES)
    key = (
        "cracked",
        _body_key(g, pair, sizes, r_lo, nb, cy, plane),
        crack,
        round(tip_m, 12),
        refined,
        tuple((t, round(a, 9), round(b, 9)) for t, (a, b) in sorted(ranges.items())),
    )
    return _cached(
        key,
        lambda: build_cracked_body(
            g, g.material, pair.face_width_m, nominal, sizes, ranges, nb, refined, cy, crack, tip_m, plane
        ),
    )


def _check_inputs(pair: PairSpec, torque_Nm: float, clearance_m: float, plane: str, faults: FaultSpec | None):
    """Bad inputs of the pair model, in this layer's names; the operating geometry."""
    _positive("torque_Nm", torque_Nm, "N m")
    if not (math.isfinite(clearance_m) and clearance_m >= 0):
        raise fail("clearance_m", clearance_m, "m", "must be finite and >= 0")
    if plane not in ("stress", "strain"):
        raise fail("plane", repr(plane), "", "must be 'stress' or 'strain'")
    if faults is not None:
        check_faults(pair, faults)
    og = operating_geometry(pair, clearance_m)
    og.mesh.require_overlap("fem")  # the contact solve needs a pair that can touch at every angle
    return og


def _sizes(pair: PairSpec, torque_Nm: float, contact_scale: float, mesh_scale: float):
    """(body sizes, a_ref, candidate half-window) (m): body_sizes and the window of
    WINDOW_HALF_WIDTHS a_ref + 2 h_c of arc length."""
    sizes, a_ref = body_sizes(pair, torque_Nm, contact_scale, mesh_scale)
    return sizes, a_ref, WINDOW_HALF_WIDTHS * a_ref + 2.0 * sizes.contact_m


def _model_spec(
    pair: PairSpec,
    wear: WearSpec | None,
    torque_Nm: float,
    clearance_m: float,
    contact_scale: float,
    mesh_scale: float,
    plane: str,
    flank: FlankSpec | None,
    faults: FaultSpec | None,
) -> dict[str, Any]:
    """The pair_model arguments by name (what a worker process needs to rebuild the model)."""
    return {
        "pair": pair,
        "wear": wear,
        "torque_Nm": torque_Nm,
        "clearance_m": clearance_m,
        "contact_scale": contact_scale,
        "mesh_scale": mesh_scale,
        "plane": plane,
        "flank": flank,
        "faults": faults,
    }


def pair_model(
    pair: PairSpec,
    wear: WearSpec | None = None,
    torque_Nm: float = 40.0,
    clearance_m: float = 0.0,
    contact_scale: float = 1.0,
    mesh_scale: float = 1.0,
    plane: str = "stress",
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
) -> PairModel:
    """Bodies (cached in-process: wear states and faults share them) and exact geometry.
    ``flank``: profile modifications and measured deviations (geometry.flank), gaps like
    the wear. ``faults`` (geometry.faults): a spall is a gap of its tooth only; a crack
    adds the cracked body of its gear (pair_body.build_cracked_body)."""
    t0 = time.perf_counter()
    faults = None if faults is None or faults.is_empty else faults
    mesh = _check_inputs(pair, torque_Nm, clearance_m, plane, faults).mesh
    sizes, a_ref, window = _sizes(pair, torque_Nm, contact_scale, mesh_scale)
    nb = int(math.ceil(mesh.contact_ratio + 2 * EXTENSION_PITCHES)) + 1
    bodies: list[GearBody] = []
    depth: list[tuple[np.ndarray, np.ndarray] | None] = []
    cracked: list = [None, None]
    tim: dict[str, float] = {}
    per_gear = []
    for gi, g in enumerate(pair.gears):
        # the body outline is interpolated on this polyline: 1 nm sag keeps it on the curve
        nominal = tooth_profile(g, sag_m=FINE_SAG_M, extra_roll=key_roll_angles(mesh, gi))
        r_lo = lowest_contact_radius_m(mesh, gi, window, EXTENSION_PITCHES)
        lp = load_points(nominal, np.array([max(r_lo, nominal.form_radius_m), g.tip_radius_m * (1 - 1e-9)]))
        cy = (float(lp.y_axis_m.min()) - 1.0 * pair.module_m * 0.2, float(lp.y_axis_m.max()) + 0.2 * pair.module_m)
        per_gear.append((g, nominal, r_lo, cy))
    keys = [_body_key(g, pair, sizes, r_lo, nb, cy, plane) for g, _, r_lo, cy in per_gear]
    # bodies too large for this machine together are refused before any is meshed
    # (fem.memory); two equal gears build one body
    check_bodies(
        [
            (gi, g.name, g.teeth, g.hub_radius_m, estimated_dofs(g, nominal, sizes, r_lo))
            for gi, (g, nominal, r_lo, _) in enumerate(per_gear)
            if keys[gi] not in keys[:gi]
        ]
    )
    healthy = _healthy_bodies(
        keys,
        [
            partial(body_builder, g, g.material, pair.face_width_m, nominal, sizes, r_lo, nb, cy, plane)
            for g, nominal, r_lo, cy in per_gear
        ],
    )
    for gi, ((g, nominal, r_lo, cy), (body, built)) in enumerate(zip(per_gear, healthy)):
        if built:
            for k2, v in body.timings.items():
                tim[f"gear{gi}_{k2}"] = v
        bodies.append(body)
        if faults is not None and faults.crack is not None and faults.crack.gear_index == gi:
            cracked[gi], built = _cracked_body(pair, mesh, faults, nominal, sizes, r_lo, nb, cy, window, plane)
            if built:
                for k2, v in cracked[gi].timings.items():
                    tim[f"cracked{gi}_{k2}"] = v
        worn = wear is not None and not wear.is_unworn
        if worn or not is_nominal(flank):
            inv = nominal.region == INVOLUTE
            h = flank_depth(nominal, gi, mesh, wear)[inv] if worn and wear is not None else 0.0
            h = h + modification_depth_m(flank, pair, gi, nominal.radius[inv])
            depth.append((nominal.radius[inv], h))
        else:
            depth.append(None)
    tim["model_s"] = time.perf_counter() - t0
    return PairModel(
        pair, mesh, tuple(bodies), wear, tuple(depth), window, a_ref, sizes, plane, tim, faults, tuple(cracked)
    )
