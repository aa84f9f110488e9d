"""The Python API in one place: ``import gearwear as gw``.

    import gearwear as gw
    pair = gw.paper_pair()                                   # Zhang et al. (2019), Table 2
    k = gw.mesh_stiffness(pair, method="ishikawa", wear="severe")
    k.angle_rad, k.k_N_per_m, k.mean_N_per_m                 # arrays/values, unit in the name
    run = gw.simulate(gw.Scene.load("paper-wear-severe"))
    run.summary()["harmonics"]["F_m_N"]                      # mesh-force harmonics, N
    rows = gw.sweep("paper-wear-severe", {"operating.speed_rpm": [600, 1200, 2400]})

Every function validates its inputs like the command line does (one-line
:class:`InputError`). Units: SI inside; a keyword's unit is in its name.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

from gearwear.core.validation import InputError
from gearwear.geometry.spec import PairSpec, default_pair
from gearwear.geometry.wear import WearSpec
from gearwear.scene.model import Scene, pair_from_dict, parse_wear_arg, wear_from_dict
from gearwear.scene.overrides import SHORT_KEYS, wear_table
from gearwear.stiffness.sources import METHODS, SOURCES


def paper_pair() -> PairSpec:
    """The paper's pair: z = 30/30, m = 5 mm, alpha = 20 deg, with this project's
    assumptions (face width 20 mm, E = 206 GPa, nu = 0.3, ISO 53 rack, bore 40 mm)."""
    return default_pair()


def pair(**keys: Any) -> PairSpec:
    """A pair from ``[pair]`` scene keys (units in the names), e.g.
    ``gw.pair(teeth=[21, 37], module_mm=3, face_width_mm=30, profile_shift=[0.25, -0.1])``
    (teeth, module_mm and face_width_mm are required); ``material={...}`` too."""
    material = keys.pop("material", {})
    return pair_from_dict({"pair": keys, "material": material})


def wear_spec(
    spec: str | Mapping[str, Any] | WearSpec | None, torque_Nm: float = 40.0, speed_rpm: float = 1200.0
) -> WearSpec | None:
    """A wear spec from every spelling the command line's ``--wear`` takes: a phase name
    (``"severe"``), a depth (``"25um"``), running hours (``"500h"``), an ``[effects] wear``
    table (``{"max_depth_um": 25}``, ``{"hours": 500}``), a WearSpec, or None (unworn).
    Running hours wear at the operating point ``torque_Nm`` (N m) and ``speed_rpm``."""
    if spec is None or isinstance(spec, WearSpec):
        return spec
    if isinstance(spec, str):
        return parse_wear_arg(spec, torque_Nm, speed_rpm)
    return wear_from_dict(spec, torque_Nm, speed_rpm)


wear = wear_spec  # gw.wear("severe"); functions below take a ``wear`` argument, so they call wear_spec


def mesh_stiffness(
    pair: PairSpec | None = None,
    method: str = "ishikawa",
    wear: Any = None,
    torque_Nm: float | None = None,
    clearance_um: float = 0.0,
    points: int | None = None,
):
    """k_h over one mesh period: ``method`` ishikawa (paper Eqs. 2-6), energy, iso6336
    (constant, ISO 6336-1 method B), fem (resolved FE pair contact, ~10 s for 24
    positions) or a published analytic model (yang_lin, tian, wu_zuo_parey, chen_shao,
    chen_shao_weber, kuang_yang: docs/models.md); ``gearwear.METHODS`` lists them all. ``torque_Nm``: the
    pinion torque, required with your own pair (without a pair: the paper pair at its
    40 N m). Returns an object with ``angle_rad``,
    ``k_N_per_m``, ``excitation_m``, ``mean_N_per_m``, ``contact_ratio`` and more
    (``gearwear.analytic.tvms.MeshStiffness``)."""
    from gearwear.jobs import stiffness as stiffness_job

    if method not in METHODS:
        raise InputError(f"method = {method!r}: must be one of {', '.join(METHODS)}")
    if torque_Nm is None:
        if pair is not None:
            raise InputError("torque_Nm: missing; the load sharing needs the pinion torque of your pair (N m)")
        torque_Nm = 40.0  # the paper's operating point, with the paper's pair
    from gearwear.scene.checks import resolved_plane

    n = points if points is not None else SOURCES[method].default_points
    p = pair or default_pair()
    # the 2D state of the FE and of the analytic tooth beams as a scene's default fem.plane =
    # "auto" picks it (stress below b/m = PLANE_STRAIN_FROM_B_OVER_M, strain from there on)
    wears, clearances = [wear_spec(wear, torque_Nm)], [clearance_um * 1e-6]
    curves = stiffness_job.compute(
        p, method, wears, clearances, torque_Nm, n, plane=resolved_plane("auto", p.face_width_m, p.module_m)
    )
    return curves[0].result


def verify(
    pair: PairSpec | None = None,
    wear: Sequence[Any] = ("unworn", "mild", "severe"),
    positions: int = 21,
    convergence: bool = False,
):
    """FE single-tooth compliance against Ishikawa and the energy method, per wear phase
    (``gearwear.jobs.verify.Verification``; ``.phases[i].fem`` etc. in um/(N/mm))."""
    from gearwear.jobs import verify as verify_job

    wears = [wear_spec(w) for w in wear]
    return verify_job.run(
        pair or default_pair(),
        [None if w is None or w.is_unworn else w for w in wears],
        positions,
        convergence=convergence,
    )


def simulate(scene: Scene | str | None = None, **overrides: Any):
    """Simulate a scene (a Scene, a built-in name or a TOML path). Keyword overrides use
    the dotted keys with ``__`` for the dots: ``simulate("paper-default",
    operating__speed_rpm=6000)``; the command line's short flags are keywords too, with
    the same spellings: ``wear="25um"`` (a phase, a depth in um or running hours, like
    ``--wear``), ``torque_Nm=120`` and ``clearance_um=30``. Returns ``SimulationRun``
    (``.summary()``, ``.result.t``, ``.result.signals``)."""
    from gearwear.jobs.simulate import run

    return run(_scene(scene, overrides))  # run() already names errors by scene key


def sweep(
    scene: Scene | str | None, axes: Mapping[str, Sequence[Any]], workers: int | None = None, progress: bool = False
) -> list[dict[str, Any]]:
    """Run a scene over the Cartesian grid of ``axes`` ({dotted key: values}) on local
    processes; one summary dict per point, in grid order."""
    from gearwear.jobs import sweep as sw
    from gearwear.scene.files import load_scene_dict

    if isinstance(scene, Scene):
        raise InputError("sweep: give the scene as a built-in name or a file path (a sweep re-reads it per point)")
    data, name = load_scene_dict(scene, default="paper-wear-severe")
    ax = [sw.Axis(k, tuple(v)) for k, v in axes.items()]
    with sw.make_executor(workers) as ex:  # an exception or Ctrl-C stops the workers at once
        return sw.sweep(data, name, ax, executor=ex, progress=progress)


def _scene(scene: Scene | str | None, overrides: Mapping[str, Any]) -> Scene:
    if isinstance(scene, Scene):
        if overrides:
            raise InputError("overrides: give them with Scene.load(name, {...}) or pass the scene by name")
        return scene
    dotted: dict[str, Any] = {}
    for k, v in overrides.items():
        # the --wear spellings stand for an [effects] wear table (scene.wear_table)
        dotted[SHORT_KEYS.get(k, k.replace("__", "."))] = wear_table(v) if k == "wear" and isinstance(v, str) else v
    return Scene.load(scene, dotted)


__all__ = [
    "paper_pair",
    "pair",
    "wear",
    "mesh_stiffness",
    "verify",
    "simulate",
    "sweep",
    "Scene",
    "PairSpec",
    "WearSpec",
    "InputError",
    "METHODS",
]
