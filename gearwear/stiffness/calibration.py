"""Calibrated mesh-stiffness tables: the analytic (Ishikawa) model corrected to FE.

Two stages, each fitted on some FE positions and checked on the others:

1. Tooth compliance. For each gear the FE single-tooth compliance c_FE(R) (full
   gear, bore fixed, Hertz patch load, centre-line deflection; fem.tooth) and the
   Ishikawa delta_1 + delta_2 c_A(R) at the same load radii from SAP to tip give
   r(R) = c_FE / c_A, fitted by a quadratic in the normalised radius on the even
   positions and checked on the odd ones. The analytic TVMS (load sharing, Hertz
   Eq. 5, wear gaps, tip-corner contact) is evaluated with every tooth compliance
   multiplied by r(R).
2. Pair level. What a per-tooth model cannot hold -- the coupling of neighbouring
   teeth through the rim and the true local contact approach of the finite teeth --
   comes from the FE pair contact (fem.pair: both gear bodies with the contact zone
   resolved, no analytic local term) at ``PAIR_POSITIONS`` angles: s = k_FE / k_stage1
   is the median, taken separately where one and where two or more pairs carry load
   (stage 1), over the even FE positions, and checked on the odd ones; the table is
   k_stage1(theta) s(theta).

Calibration version 3 (this one): as version 2, with the FE models on Gmsh's curved
6-node meshes (single-tooth compliance +0.10..+0.14 %, pair cycle mean -0.14 %).
Version 2: stage 2 is fitted to the resolved pair contact.
Version 1 fitted it to the earlier pair FE, which added Weber's half-plane approach
in plane strain between the tooth centre lines (3.9 % stiffer on the cycle mean, no
corner contact). The stage-1 correction is unchanged; see README for the new
numbers. CALIBRATION_VERSION is part of the cache key, so a version-1 table is never
reused.

Tables are cached by the SHA-256 of all inputs (gearwear.stiffness.tables). The inputs include
CALIBRATION_VERSION and :func:`code_fingerprint`, the SHA-256 over the source of every
gearwear module a calibrated table depends on: this module and the modules it imports,
followed transitively through their gearwear imports (also those inside functions),
i.e. the geometry, analytic and fem modules it uses, gearwear.stiffness.comparison, gearwear.stiffness.tables,
gearwear.io and gearwear.core (:func:`code_modules`). Each module enters as its dotted
name and its bytes (line endings normalised), sorted by name, so the fingerprint is the
same in a fresh clone, an editable install and a wheel, and any edit of that code gives
a new key instead of a stale table. A cache entry that fails its checks on read
(gearwear.stiffness.tables.lookup: truncated, unreadable, non-finite, bytes not matching the
sidecar) is recomputed, and :func:`calibrated_table` says so through ``notify`` (one
line on stderr by default).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import importlib.util
import math
import re
import time
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from gearwear.analytic.tvms import DEFAULT_POINTS, mesh_stiffness
from gearwear.geometry.faults import FaultSpec
from gearwear.geometry.flank import FlankSpec
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec
from gearwear.stiffness import tables
from gearwear.stiffness.comparison import pair_vs_analytic, tooth_vs_analytic

FIT_DEGREE = 2
PAIR_POSITIONS = 24
#: Bumped whenever the calibration's FE models change (part of the cache key):
#: 1 = pair FE with Weber's local term, 2 = resolved pair contact (fem.pair),
#: 3 = both FE models on Gmsh's curved 6-node meshes (isoparametric P2).
CALIBRATION_VERSION = 3

#: the code fingerprint starts here and follows every gearwear import
FINGERPRINT_ROOT = "gearwear.stiffness.calibration"
#: not followed: the app package's __init__ (its __version__ is in every key already, and
#: its lazy API import would pull in the whole app)
FINGERPRINT_SKIP = frozenset({"gearwear"})


# -- code fingerprint ------------------------------------------------------------------


@functools.lru_cache(maxsize=None)
def _spec(name: str):
    """The import spec of a gearwear module, or None if ``name`` is not a module."""
    parent = name.rpartition(".")[0]
    if parent and parent != "gearwear":  # only a package's attribute can be a submodule
        ps = _spec(parent)
        if ps is None or ps.submodule_search_locations is None:
            return None
    try:
        return importlib.util.find_spec(name)
    except (ImportError, ValueError):
        return None


def _source_bytes(name: str) -> bytes:
    """The source of module ``name`` (line endings normalised, so a checkout with CRLF hashes alike)."""
    spec = _spec(name)
    if spec is None or not spec.origin or not spec.has_location:
        return b"<no source>"
    return Path(spec.origin).read_bytes().replace(b"\r\n", b"\n")


#: ``from X import a, (b, c)`` and ``import X, Y as Z`` at any indentation (imports inside
#: functions count); a match inside a docstring only adds a module, never drops one
_FROM = re.compile(rb"^[ \t]*from[ \t]+(\.*[\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#;]*)", re.M)
_IMPORT = re.compile(rb"^[ \t]*import[ \t]+([\w., \t]+)", re.M)


def _imports(name: str, source: bytes) -> set[str]:
    """The gearwear modules ``name`` imports anywhere in its source, with their parent packages."""
    spec = _spec(name)
    package = name if spec is not None and spec.submodule_search_locations is not None else name.rpartition(".")[0]
    found: set[str] = set()
    for m in _IMPORT.finditer(source):
        found.update(part.split()[0] for part in m.group(1).decode().split(",") if part.strip())
    for m in _FROM.finditer(source):
        mod = m.group(1).decode()
        level = len(mod) - len(mod.lstrip("."))
        if level:
            parts = package.split(".")
            base = ".".join(parts[: len(parts) - level + 1] + ([mod[level:]] if mod[level:] else []))
        else:
            base = mod
        found.add(base)
        names = m.group(2).decode().strip("() \t\n").replace("\n", " ")
        for part in names.split(","):
            word = part.split()[0] if part.split() else ""
            if word.isidentifier() and _spec(f"{base}.{word}") is not None:
                found.add(f"{base}.{word}")
    out: set[str] = set()
    for mod in found:
        parts = mod.split(".")
        out.update(".".join(parts[:i]) for i in range(1, len(parts) + 1))
    return {m for m in out if (m == "gearwear" or m.startswith("gearwear.")) and _spec(m) is not None}


def dependencies(
    root: str, read: Callable[[str], bytes] = _source_bytes, skip: Iterable[str] = FINGERPRINT_SKIP
) -> tuple[str, ...]:
    """``root`` and every gearwear module reachable from it through imports, sorted."""
    skip = frozenset(skip)
    seen: set[str] = set()
    todo = [root]
    while todo:
        mod = todo.pop()
        if mod in seen or mod in skip:
            continue
        seen.add(mod)
        todo.extend(_imports(mod, read(mod)))
    return tuple(sorted(seen))


def fingerprint(modules: Iterable[str], read: Callable[[str], bytes] = _source_bytes) -> str:
    """SHA-256 over (dotted name, source bytes) of each module, in sorted order."""
    h = hashlib.sha256()
    for mod in sorted(modules):
        src = read(mod)
        h.update(f"{mod}\0{len(src)}\0".encode())
        h.update(src)
    return h.hexdigest()


@functools.lru_cache(maxsize=None)
def code_modules() -> tuple[str, ...]:
    """The modules whose source can change a calibrated table (computed once per process)."""
    return dependencies(FINGERPRINT_ROOT)


@functools.lru_cache(maxsize=None)
def code_fingerprint() -> str:
    """SHA-256 of the calibration code (:func:`code_modules`); part of every table's inputs."""
    return fingerprint(code_modules())


@dataclass
class Correction:
    """FE / analytic tooth-compliance ratio r(R) for one gear."""

    radius_m: np.ndarray  # FE load radii
    ratio: np.ndarray  # c_FE / c_A at those radii
    coeffs: np.ndarray  # polynomial in t = (R - R0) / (R1 - R0)
    r0: float
    r1: float
    fit_residual: float  # max |fit / ratio - 1| on the fitting (even) positions
    check_residual: float  # the same on the held-out (odd) positions

    def factor(self, R) -> np.ndarray:
        t = (np.asarray(R, dtype=float) - self.r0) / (self.r1 - self.r0)
        return np.polyval(self.coeffs, np.clip(t, 0.0, 1.0))

    def grid(self, n: int = 200) -> tuple[np.ndarray, np.ndarray]:
        """(radius, factor) arrays for analytic.tvms (clamped beyond the FE range)."""
        R = np.linspace(self.r0, self.r1, n)
        return R, self.factor(R)


def fit_correction(radius_m: np.ndarray, fem: np.ndarray, analytic: np.ndarray) -> Correction:
    """Fit r = fem / analytic on the even positions, check on the odd ones."""
    ratio = np.asarray(fem, dtype=float) / np.asarray(analytic, dtype=float)
    r0, r1 = float(radius_m.min()), float(radius_m.max())
    t = (radius_m - r0) / (r1 - r0)
    fit, check = slice(0, None, 2), slice(1, None, 2)
    coeffs = np.polyfit(t[fit], ratio[fit], FIT_DEGREE)
    res = np.abs(np.polyval(coeffs, t) / ratio - 1.0)
    return Correction(np.asarray(radius_m), ratio, coeffs, r0, r1, float(res[fit].max()), float(res[check].max()))


def _wear_inputs(wear: WearSpec | None) -> dict[str, Any] | None:
    return None if wear is None or wear.is_unworn else dataclasses.asdict(wear)


@dataclass
class Calibration:
    """FE runs and fitted corrections for one pair and wear state."""

    pair: PairSpec
    wear: WearSpec | None
    fe: tuple  # fem.tooth.ToothFE per gear
    corrections: tuple  # Correction per gear
    error_estimate: float  # relative FE discretisation error estimate (max over positions)
    wall_s: float


@dataclass
class PairCorrection:
    """Stage 2: zone factors k_FE / k_stage1 from the FE pair contact."""

    double: float
    single: float
    check_residual: float  # max |k_stage1 s / k_FE - 1| on the odd (held-out) FE positions
    check_rms: float  # rms of the same
    fit_residual: float  # the same on the even (fitting) positions
    fe_mean_N_per_m: float
    stage1_mean_at_fe_N_per_m: float
    fe_wall_s: float
    #: the calibrated table against the pair FE at every FE position: max |k_table / k_FE - 1|
    #: per contact zone ("single", "double"; None where the pair has no such zone), over all
    #: positions ("max"), and the rms
    table_error: dict = dataclasses.field(default_factory=dict)
    #: both blanks' torsional compliance below their reference circles along the line of
    #: action, r_b1^2 / k_blank,1 + r_b2^2 / k_blank,2 (m/N), and the pair FE's mean without it
    blank_compliance_m_per_N: float = 0.0
    fe_mesh_only_mean_N_per_m: float = float("nan")


def pair_correction(
    pair: PairSpec,
    wear: WearSpec | None,
    clearance_m: float,
    torque_Nm: float,
    corr: tuple,
    positions: int = 24,
    executor: Executor | None = None,
    plane: str = "stress",
) -> PairCorrection:
    """Fit the per-zone pair factor on the even FE positions, check on the odd ones
    (``executor``: where the FE positions are solved, fem.pair.pair_contact; the same
    result to the bit)."""
    from gearwear.fem.pair import pair_contact

    fe = pair_contact(
        pair,
        wear=wear,
        positions=positions,
        torque_Nm=torque_Nm,
        clearance_m=clearance_m,
        executor=executor,
        plane=plane,
    )
    st1 = pair_vs_analytic(fe, correction=corr)["analytic"]
    ratio = fe.k_N_per_m / st1.k_N_per_m
    # two or more loaded pairs: only there can the rim couple them
    dbl = st1.pairs_in_contact >= 2
    even = np.arange(positions) % 2 == 0
    factors = {}
    for name, zone in (("double", dbl), ("single", ~dbl)):
        sel = zone & even
        # median: the few positions at a zone change (where the analytic tip-corner contact
        # and the FE differ most) must not drag the factor of the whole zone
        factors[name] = (
            float(np.median(ratio[sel])) if sel.any() else float(np.median(ratio[zone])) if zone.any() else 1.0
        )
    s = np.where(dbl, factors["double"], factors["single"])
    res = np.abs(s / ratio - 1.0)
    table_error = {
        "max": float(res.max()),
        "rms": float(np.sqrt(np.mean(res**2))),
        **{name: float(res[zone].max()) if zone.any() else None for name, zone in (("single", ~dbl), ("double", dbl))},
    }
    rb = [g.base_radius_m for g in pair.gears]
    blank = sum(r * r / k for r, k in zip(rb, fe.meta["blank_torsional_stiffness_Nm_per_rad"]))
    return PairCorrection(
        factors["double"],
        factors["single"],
        float(res[~even].max()),
        float(np.sqrt(np.mean(res[~even] ** 2))),
        float(res[even].max()),
        fe.mean_N_per_m,
        st1.mean_N_per_m,
        float(fe.timings.get("total_s", float("nan"))),
        table_error,
        float(blank),
        fe.meta["mesh_only_mean_N_per_m"],
    )


def run_fe(
    pair: PairSpec,
    wear: WearSpec | None,
    positions: int = 21,
    estimate_error: bool = True,
    executor: Executor | None = None,
    plane: str = "stress",
) -> Calibration:
    """FE single-tooth compliance of both gears and the fitted corrections.

    Identical gears (same spec apart from the name) carry identical worn flanks, so
    the pinion's FE run serves both. The discretisation error is estimated from a
    second run with all mesh sizes x sqrt(2): |c_h - c_2h| / (sqrt(2)^p - 1), p = 2.
    ``executor`` (any concurrent.futures.Executor): the independent single-tooth FE runs
    go to it as separate tasks; the result is the same to the bit. ``plane``: the 2D
    idealisation of the FE (the scene's fem.plane)."""
    from gearwear.fem.tooth import single_tooth_compliance

    t0 = time.perf_counter()
    same = dataclasses.replace(pair.gear(0), name="") == dataclasses.replace(pair.gear(1), name="")
    runs = (
        [{"gear_index": 0}]
        + ([] if same else [{"gear_index": 1}])
        + ([{"gear_index": 0, "mesh_scale": math.sqrt(2)}] if estimate_error else [])
    )
    if executor is None:
        done = [single_tooth_compliance(pair, wear=wear, positions=positions, plane=plane, **kw) for kw in runs]
    else:
        futures = [
            executor.submit(single_tooth_compliance, pair, wear=wear, positions=positions, plane=plane, **kw)
            for kw in runs
        ]
        done = [f.result() for f in futures]
    fe0 = done[0]
    fe1 = fe0 if same else done[1]
    err = float("nan")
    if estimate_error:
        coarse = done[-1]
        diff = np.abs(coarse.fem_compliance_um_per_N_per_mm / fe0.fem_compliance_um_per_N_per_mm - 1.0)
        err = float(diff.max() / (math.sqrt(2) ** 2 - 1.0))
    corr = tuple(
        fit_correction(f.radius_m, f.fem_compliance_um_per_N_per_mm, tooth_vs_analytic(f).ishikawa_um_per_N_per_mm)
        for f in (fe0, fe1)
    )
    return Calibration(pair, wear, (fe0, fe1), corr, err, time.perf_counter() - t0)


def crack_correction(pair: PairSpec, faults: FaultSpec, positions: int = 21, plane: str = "stress") -> Correction:
    """FE / reduced-section ratio of the cracked tooth (fem.tooth with ``crack``: the crack
    as a cut in the mesh), fitted like the healthy corrections. The FE crack model takes a
    nominal flank, so the ratio is that of the unworn cracked tooth (wear changes a tooth's
    compliance by 0.01-0.1 %, fem.tooth). The FE raises the compliance 1.8-6 times more
    than the reduced-section model (tests/test_crack.py): the correction carries that."""
    from gearwear.fem.tooth import single_tooth_compliance

    assert faults.crack is not None
    fe = single_tooth_compliance(
        pair, gear_index=faults.crack.gear_index, positions=positions, crack=faults.crack.crack, plane=plane
    )
    return fit_correction(
        fe.radius_m, fe.fem_compliance_um_per_N_per_mm, tooth_vs_analytic(fe).ishikawa_um_per_N_per_mm
    )


@functools.lru_cache(maxsize=1)
def library_versions() -> dict[str, str]:
    """Versions of the libraries that shape a calibrated table (a Gmsh upgrade can move
    mesh nodes, a scikit-fem or SciPy upgrade the assembly or the factorisation), so a
    table cached under other versions is recomputed rather than reused."""
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for dist in ("gmsh", "scikit-fem", "numpy", "scipy", "meshio"):
        try:
            out[dist] = version(dist)
        except PackageNotFoundError:
            out[dist] = "absent"
    return out


def table_inputs(
    pair: PairSpec,
    wear: WearSpec | None,
    clearance_m: float,
    torque_Nm: float,
    points: int,
    positions: int,
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
    plane: str = "stress",
) -> dict[str, Any]:
    from gearwear.fem import pair as fe_pair
    from gearwear.fem import tooth

    # flank and faults enter the key only when present, so the keys of plain tables stay valid
    extra: dict[str, Any] = {
        k: dataclasses.asdict(v) for k, v in (("flank", flank), ("faults", faults)) if v is not None
    }
    return {
        **extra,
        "kind": "calibrated mesh stiffness",
        "pair": dataclasses.asdict(pair),
        "wear": _wear_inputs(wear),
        "clearance_m": clearance_m,
        "torque_Nm": torque_Nm,
        "points": points,
        "fe": {
            "positions": positions,
            "order": 2,
            "plane": plane,
            "mesh_scale": 1.0,
            "sizes": dataclasses.asdict(tooth.mesh_sizes(1.0)),
            "fit_degree": FIT_DEGREE,
        },
        "calibration_version": CALIBRATION_VERSION,
        "code_sha256": code_fingerprint(),
        "libraries": library_versions(),
        "fe_pair": {
            "positions": PAIR_POSITIONS,
            "order": 2,
            "plane": plane,
            "local_contact": "resolved",
            "contact_elements_per_half_width": fe_pair.ELEMENTS_PER_HALF_WIDTH,
            "candidate_half_widths": fe_pair.WINDOW_HALF_WIDTHS,
            "corner_contact": True,
            "zone_factors": "median",
        },
    }


def without_blank_torsion(tab: tables.StiffnessTable) -> tables.StiffnessTable:
    """The calibrated table with both blanks' torsion taken out. The table follows the
    pair FE with the bodies held at their bores, so it holds the blanks' compliance
    c_b = r_b1^2 / k_blank,1 + r_b2^2 / k_blank,2 (fem.pair, stored with the table) in
    series; with F = k (STE - e) and STE_mesh = STE - F c_b:

        1 / k_mesh = 1 / k - c_b,   STE_mesh = STE - F c_b,   e unchanged."""
    c_b = float(tab.meta["blank_compliance_m_per_N"])
    k = 1.0 / (1.0 / tab.k_N_per_m - c_b)
    F = tab.k_N_per_m * (tab.ste_m - tab.excitation_m)
    return dataclasses.replace(tab, k_N_per_m=k, ste_m=tab.ste_m - F * c_b)


def table_label(wear: WearSpec | None, clearance_m: float) -> str:
    """How a table is named in messages: ``unworn, 0 um``, ``severe, 10 um``."""
    return f"{'unworn' if wear is None or wear.is_unworn else wear.label}, {clearance_m * 1e6:g} um"


def require_overlap(pair: PairSpec, clearance_m: float) -> None:
    """A calibrated table needs the FE pair contact, which needs a tooth pair on the path
    of contact at every angle (contact ratio >= 1); refused otherwise, in scene terms."""
    from gearwear.core.validation import InputError, renamed
    from gearwear.geometry.operating import operating_geometry

    try:
        operating_geometry(pair, clearance_m).mesh.require_overlap("calibrated")
    except InputError as exc:
        raise renamed(exc, {"method": "effects.mesh_stiffness.source"}) from None


def calibrated_table(
    pair: PairSpec,
    wear: WearSpec | None,
    clearance_m: float = 0.0,
    torque_Nm: float = 40.0,
    points: int = DEFAULT_POINTS,
    positions: int = 21,
    calibration: Calibration | Callable[[], Calibration] | None = None,
    refresh: bool = False,
    notify: tables.Notify | None = tables.to_stderr,
    flank: FlankSpec | None = None,
    faults: FaultSpec | None = None,
    executor: Executor | None = None,
    plane: str = "stress",
) -> tables.StiffnessTable:
    """The calibrated k_h table, from the cache when these exact inputs were run before.

    ``flank`` (modifications, measured deviations) and ``faults`` enter the load sharing of
    the corrected analytic stage (analytic.tvms): gaps, and for a crack the cracked tooth's
    reduced-section compliance corrected to the FE of the cracked tooth
    (:func:`crack_correction`). With a fault the table spans one revolution of the faulty
    gear.

    ``calibration``: the FE stage (run_fe) to use on a cache miss, or a function that
    returns it (called only on a miss, so a caller can share one FE run between tables
    without running it when every table is cached); None runs it here.
    ``executor`` (any concurrent.futures.Executor, e.g. a Dask ``Client.get_executor()``):
    the FE runs of a cache miss (run_fe's single-tooth runs, the pair FE positions) are
    solved there; the table is the same to the bit, so it is not part of the key.
    ``plane``: the 2D idealisation of both FE stages (the scene's fem.plane; part of the
    key); a given ``calibration`` must have been run with it.
    ``notify``: gets one line when a cache entry exists but fails its checks and is
    recomputed (default: printed to stderr; None: silent). The returned table's
    ``from_cache`` tells whether it came from the cache. A bad $GEARWEAR_CACHE raises
    InputError before anything is computed.
    """
    folder = tables.cache_dir()
    inputs = table_inputs(pair, wear, clearance_m, torque_Nm, points, positions, flank, faults, plane)
    if not refresh:
        hit = tables.cached(inputs, folder, notify, table_label(wear, clearance_m))
        if hit is not None:
            return hit
    require_overlap(pair, clearance_m)  # before the FE runs, which cannot model a gap
    if callable(calibration):
        calibration = calibration()
    cal = calibration or run_fe(pair, wear, positions, executor=executor, plane=plane)
    if cal.fe[0].plane != plane:
        raise ValueError(f"calibration run in plane {cal.fe[0].plane}, table asked for plane {plane}")
    corr = tuple(c.grid() for c in cal.corrections)
    cc = crack_correction(pair, faults, positions, plane) if faults is not None and faults.crack is not None else None
    r = mesh_stiffness(
        pair,
        method="ishikawa",
        points=points,
        torque_Nm=torque_Nm,
        clearance_m=clearance_m,
        wear=wear,
        correction=corr,
        flank=flank,
        faults=faults,
        crack_correction=None if cc is None else cc.grid(),
        plane=plane,
    )
    pc = pair_correction(pair, wear, clearance_m, torque_Nm, corr, PAIR_POSITIONS, executor, plane)
    s = np.where(r.pairs_in_contact >= 2, pc.double, pc.single)
    k = r.k_N_per_m * s
    F = torque_Nm / pair.gear(0).base_radius_m
    # F = k (ste - e): keep the wear excitation, rescale the elastic part
    ste = r.excitation_m + F / k
    tab = tables.StiffnessTable(r.angle_rad, k, r.excitation_m, ste, r.pairs_in_contact, {}, span_rad=r.span_rad)
    fe0 = cal.fe[0]
    method = "ishikawa slices corrected to FE single-tooth compliance (fem.tooth)"
    tables.store(
        tab,
        inputs,
        method,
        folder,
        label=table_label(wear, clearance_m),
        notify=notify,
        extra={
            "code_modules": list(code_modules()),
            "fe_mesh": {
                "dofs": int(fe0.ndofs),
                "elements": int(fe0.n_elements),
                "order": fe0.order,
                "plane": fe0.plane,
            },
            "fe_estimated_relative_error": cal.error_estimate,
            "fit_residual": [c.fit_residual for c in cal.corrections],
            "check_residual": [c.check_residual for c in cal.corrections],
            "correction_ratio_range": [[float(c.ratio.min()), float(c.ratio.max())] for c in cal.corrections],
            "stage1_mean_N_per_m": r.mean_N_per_m,
            "pair_zone_factors": {"double": pc.double, "single": pc.single},
            "pair_check_residual": pc.check_residual,
            "pair_check_rms": pc.check_rms,
            "pair_fit_residual": pc.fit_residual,
            # what a user of the table needs: its error against the pair FE it was calibrated to
            "table_vs_pair_fe": pc.table_error,
            **(
                {}
                if cc is None
                else {
                    "crack_correction_ratio_range": [float(cc.ratio.min()), float(cc.ratio.max())],
                    "crack_check_residual": cc.check_residual,
                }
            ),
            "fe_pair_mean_N_per_m": pc.fe_mean_N_per_m,
            # the blanks' torsion (fem.pair) the table holds in series, for without_blank_torsion
            "blank_compliance_m_per_N": pc.blank_compliance_m_per_N,
            "fe_pair_mesh_only_mean_N_per_m": pc.fe_mesh_only_mean_N_per_m,
            "uncorrected_mean_N_per_m": mesh_stiffness(
                pair,
                points=points,
                torque_Nm=torque_Nm,
                clearance_m=clearance_m,
                wear=wear,
                flank=flank,
                faults=faults,
                plane=plane,
            ).mean_N_per_m,
        },
    )
    # store() leaves in tab what a later cache hit returns: cold and cached calls are bit-identical
    return tab
