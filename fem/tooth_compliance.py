"""FE single-tooth compliance (``fem.tooth``): the solve at all load positions, the
centre-line compliance measure and, with a root crack, the crack mouth opening.

:func:`single_tooth_compliance` meshes the full gear (``fem.tooth_mesh``), loads tooth 0
by Hertzian pressure patches at the load positions (``fem.tooth_load``), assembles 2D
linear elasticity (``fem.elasticity``, bore clamped) and solves. The stiffness matrix is
factorized once and all positions are solved as right-hand sides.

Compliance measure
------------------
The displacement of the tooth centre-line point (0, R) (x = 0 in the tooth frame,
the load radius) projected on e_F:

    c = u(0, R) . e_F / F    [m/N for face width b]
    c [um / (N/mm)] = c [m/N] * 1e6 * b [mm]

It excludes the local contact flattening (the pair model adds it as the Hertzian
delta_3) and is the FE counterpart of Ishikawa's delta_1 + delta_2; the app layer
(``gearwear.stiffness.comparison``) evaluates that and the energy method at the same radii on
the same (worn) profiles, which :class:`ToothFE` carries for it.

Crack mouth opening: with a root crack the two faces meet at the mouth in two coincident
vertices (``fem.tooth_mesh``); per unit load

    CMOD / F = (u_upper - u_lower) . n / F    [m/N]

n the unit normal of the crack line toward the tooth (upper) side, so > 0 means the
faces separate (:func:`crack_mouth_opening`, :func:`crack_mouth_pair`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.crack import Crack
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.loading import load_points
from gearwear.geometry.profile import ToothProfile
from gearwear.geometry.spec import PairSpec
from gearwear.geometry.wear import WearSpec, hertz_half_width

from .elasticity import assemble
from .tooth_load import DEFAULT_TORQUE_NM, hertz_patch_forces, load_radii, patch_load
from .tooth_mesh import ToothMesh, default_crack_tip_size_m, tooth_mesh


@dataclass
class ToothFE:
    """FE single-tooth compliance at load positions from SAP to tip.

    Arrays have one entry per load position (SI unless the name says otherwise).
    Compliances are in um per (N/mm): deflection per load per unit face width.
    ``timings`` (s): mesh_s, assemble_s (incl. the morph), factorize_s, solve_s
    (load vectors, solves, probes), fem_s (their sum) and total_s (whole call,
    incl. profiles). ``nominal`` and ``loaded`` are the fine source profiles of the
    tooth the model was built from (loaded: its worn right flank, else nominal).
    """

    pair: PairSpec
    gear_index: int
    wear_label: str
    order: int
    plane: str
    mesh_scale: float
    load_N: float
    radius_m: np.ndarray
    roll_rad: np.ndarray
    half_width_m: np.ndarray
    force_direction: np.ndarray  # (n, 2) unit vectors e_F of the applied force
    fem_compliance_um_per_N_per_mm: np.ndarray
    ndofs: int
    n_elements: int
    worn_geometry: str = "morph"
    timings: dict = field(default_factory=dict)
    nominal: ToothProfile | None = None
    loaded: ToothProfile | None = None
    crack: Crack | None = None
    crack_tip_size_m: float | None = None
    crack_mouth_opening_m_per_N: np.ndarray | None = None  # (n,) CMOD per unit load, > 0: open

    @property
    def radius_mm(self) -> np.ndarray:
        return self.radius_m * 1e3

    @property
    def roll_angle_deg(self) -> np.ndarray:
        return np.degrees(self.roll_rad)

    @property
    def wall_s(self) -> float:
        """Wall time of the FE curve: mesh + assemble + factorize + solves (s)."""
        return float(self.timings.get("fem_s", float("nan")))

    def rows(self) -> list[dict]:
        """One dict per load position (units in the keys)."""
        return [
            {
                "radius_mm": float(r),
                "roll_angle_deg": float(u),
                "hertz_half_width_um": float(a * 1e6),
                "fem_compliance_um_per_N_per_mm": float(c),
            }
            for r, u, a, c in zip(
                self.radius_mm, self.roll_angle_deg, self.half_width_m, self.fem_compliance_um_per_N_per_mm
            )
        ]


def single_tooth_compliance(
    pair: PairSpec,
    gear_index: int = 0,
    wear: WearSpec | None = None,
    positions: int = 21,
    order: int = 2,
    plane: str = "stress",
    mesh_scale: float = 1.0,
    load_N: float | None = None,
    worn_geometry: str = "morph",
    radii_m=None,
    read_at: str = "radius",
    crack: Crack | None = None,
    crack_tip_size_m: float | None = None,
) -> ToothFE:
    """FE compliance of tooth 0 of gear ``gear_index`` (0 pinion, 1 gear) on the full gear.

    wear           None / unworn: nominal tooth. Otherwise the loaded (right) flank of
                   tooth 0 is worn by ``geometry.wear.flank_depth`` on the nominal mesh
                   geometry; all other flanks stay nominal.
    positions      number of load positions, SAP to tip (>= 2).
    order          1 or 2 (Lagrange P1 / P2 triangles).
    plane          "stress" (default) or "strain".
    mesh_scale     multiplies every element size (1 = default level).
    load_N         normal load (N); default T / r_b1 at T = 40 N m. Only sets the Hertz
                   half-width (linear model).
    worn_geometry  "morph" (default: nominal mesh moved onto the worn flank) or
                   "remesh" (mesh the worn outline).
    radii_m        load radii (m) instead of ``positions`` equal roll steps (the pair
                   FE's consistency check reads the single tooth at its own contacts).
    read_at        "radius": the centre-line point (0, R) (default); "load_line": the
                   centre-line point where the load line crosses it, (0, y_c) of
                   geometry.loading (where Weber's h ends; fem.pair's c_1, c_2).
    crack          a straight root crack on tooth 0's loaded flank (``geometry.crack``),
                   meshed as a cut with free faces (:func:`tooth_mesh`); None: intact.
    crack_tip_size_m  element size at the crack tip (m; default
                   :func:`default_crack_tip_size_m`).

    With a crack, ``crack_mouth_opening_m_per_N`` is the mouth opening per unit load,
    (u_upper - u_lower) . n / F, n the unit normal of the crack line toward the tooth
    (upper) side, from the two coincident mouth nodes: > 0 means the faces separate.

    Returns a :class:`ToothFE`: compliance in um per (N/mm) at every position, the
    profiles the model was built from, dofs, elements and wall times (the analytic
    reference at the same radii: gearwear.stiffness.comparison.tooth_vs_analytic).
    """
    t_start = time.perf_counter()
    if radii_m is None and positions < 2:
        raise fail("positions", str(positions), "", "need at least 2")
    if read_at not in ("radius", "load_line"):
        raise fail("read_at", repr(read_at), "", "must be 'radius' or 'load_line'")
    g = pair.gear(gear_index)
    mg = MeshGeometry(pair, pair.centre_distance_m)
    b = pair.face_width_m
    if load_N is None:
        load_N = DEFAULT_TORQUE_NM / pair.gear(0).base_radius_m
    if not (math.isfinite(load_N) and load_N > 0):
        raise fail("load_N", repr(load_N), "", "must be finite and > 0")

    # -- load positions, Hertz half-widths, force directions (geometry.loading on the true flank)
    rb = g.base_radius_m
    if radii_m is None:
        R, u = load_radii(pair, gear_index, positions, load_N)
    else:
        R = np.atleast_1d(np.asarray(radii_m, dtype=float))
        u = np.sqrt(np.maximum((R / rb) ** 2 - 1.0, 0.0))
    d = rb * u if gear_index == 0 else mg.line_of_action_m - rb * u
    a = hertz_half_width(mg, d, load_N / b)

    tm = tooth_mesh(
        pair,
        gear_index,
        wear,
        order=order,
        mesh_scale=mesh_scale,
        load_radii_m=R,
        worn_geometry=worn_geometry,
        crack=crack,
        crack_tip_size_m=crack_tip_size_m,
    )
    mesh, gm = tm.mesh, tm.gear_mesh
    lp = load_points(tm.loaded, R)
    e_F = -np.column_stack([np.cos(lp.w_rad), np.sin(lp.w_rad)])

    model = assemble(mesh, g.material, b, gm.boundaries["bore"], plane=plane, order=order)

    # -- loads: Hertz patches on the meshed (curved) flank, all positions as right-hand sides
    t0 = time.perf_counter()
    flank, v_lo, v_hi = tm.flank_curve()
    pts, forces = hertz_patch_forces(flank, v_lo, v_hi, R, a, e_F, load_N)
    n, k = pts.shape[:2]
    F = patch_load(model, pts, forces)
    U = model.solve(F)
    yq = lp.y_axis_m if read_at == "load_line" else R
    Q = model.probe(np.column_stack([np.zeros_like(R), yq]))
    uc = np.asarray(Q @ U)  # (2 n, n): column i is position i's solution
    idx = np.arange(n)
    ui = np.column_stack([uc[2 * idx, idx], uc[2 * idx + 1, idx]])
    c_m_per_N = np.einsum("ij,ij->i", ui, e_F) / load_N
    cmod = None if crack is None else crack_mouth_opening(tm, model.basis, U) / load_N
    t_solve = time.perf_counter() - t0

    to_um_per_N_per_mm = 1e6 * b * 1e3
    timings = {
        "mesh_s": tm.mesh_s,
        "assemble_s": model.timings["assemble_s"] + tm.morph_s,
        "factorize_s": model.timings["factorize_s"],
        "solve_s": t_solve,
    }
    timings["fem_s"] = sum(timings.values())
    timings["total_s"] = time.perf_counter() - t_start
    return ToothFE(
        pair=pair,
        gear_index=gear_index,
        wear_label=wear.label if wear is not None else "unworn",
        order=order,
        plane=plane,
        mesh_scale=float(mesh_scale),
        load_N=float(load_N),
        radius_m=R,
        roll_rad=u,
        half_width_m=a,
        force_direction=e_F,
        fem_compliance_um_per_N_per_mm=c_m_per_N * to_um_per_N_per_mm,
        ndofs=int(model.ndofs),
        n_elements=int(gm.n_elements),
        worn_geometry=tm.worn_geometry,
        timings=timings,
        nominal=tm.nominal,
        loaded=tm.loaded,
        crack=crack,
        crack_tip_size_m=(
            None
            if crack is None
            else float(default_crack_tip_size_m(crack, mesh_scale) if crack_tip_size_m is None else crack_tip_size_m)
        ),
        crack_mouth_opening_m_per_N=cmod,
    )


def crack_mouth_pair(tm: ToothMesh) -> tuple[int, int, np.ndarray]:
    """(upper, lower, n): the two coincident mesh vertices at the crack mouth, the one
    of the elements on the tooth side of the crack line first, and that side's unit
    normal n of the crack line (m-free)."""
    mesh = tm.mesh
    assert tm.crack_xy is not None, "the tooth mesh has no crack"
    mouth, tip = tm.crack_xy
    d = (tip - mouth) / np.linalg.norm(tip - mouth)
    n = np.array([d[1], -d[0]])  # d turned by -90 deg: toward the tooth above the crack
    if n[1] < 0:
        n = -n
    p = mesh.p[:, : mesh.nvertices]
    at = np.flatnonzero(np.linalg.norm(p.T - mouth, axis=1) <= 1e-9 * np.linalg.norm(mouth))
    if len(at) != 2:
        raise RuntimeError(f"the crack mouth has {len(at)} mesh vertices, expected 2 (an open crack)")
    side = []
    for v in at:
        els = np.flatnonzero(np.any(mesh.t[:3] == v, axis=0))
        c = p[:, mesh.t[:3, els]].mean(axis=1).T  # element centroids
        side.append(float(np.mean((c - mouth) @ n)))
    up, lo = (at[0], at[1]) if side[0] > side[1] else (at[1], at[0])
    return int(up), int(lo), n


def crack_mouth_opening(tm: ToothMesh, basis, U: np.ndarray) -> np.ndarray:
    """Crack mouth opening displacement (u_upper - u_lower) . n (m) for every column
    of the solution matrix ``U`` (one per load case); see :func:`crack_mouth_pair`."""
    up, lo, n = crack_mouth_pair(tm)
    du = U[basis.nodal_dofs[:, up]] - U[basis.nodal_dofs[:, lo]]  # (2, n_cases)
    return n @ du
