"""What a gear mesh is asked for and what it gives back: the element sizes (``MeshSizes``), the
result (``GearMesh``) and the errors of the meshing steps (``MeshError``; ``MeshInputError`` for
an input the mesher refuses as impossible). Lengths in m. The meshing itself: ``fem.mesh``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import skfem

from gearwear.core.validation import InputError


class MeshError(ValueError):
    """A meshing failure (one-line message): Gmsh could not mesh the region, or its mesh
    failed a check. Every shape a design sends to the mesher passed the geometry's checks,
    so from a design this is an internal error (the CLI reports it as a bug, exit 1).
    Inputs the mesher refuses as impossible raise the subclass :class:`MeshInputError`."""


class MeshInputError(MeshError, InputError):
    """An input the mesher refuses because it is impossible: an outline that is not a
    simple counter-clockwise polygon around the origin, a bore not strictly inside it,
    sizes or sector angles out of range, a crack that does not start on the outline or
    ends outside the region. An InputError of the contract (gearwear.core.validation;
    the CLI reports it as the caller's error, exit 2) and a MeshError for the callers of
    ``fem.mesh``; the message is the same one-line diagnosis."""


def _positive(name: str, value: float | None, allow_none: bool = False) -> float | None:
    """``value`` as a finite float > 0 (or None if allowed); MeshInputError naming ``name``."""
    if value is None:
        if allow_none:
            return None
        raise MeshInputError(f"{name} must be given, got None")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise MeshInputError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(v) and v > 0.0):
        raise MeshInputError(f"{name} must be finite and > 0, got {value!r}")
    return v


@dataclass(frozen=True)
class MeshSizes:
    """Target element sizes (edge lengths, metres) and refinement extents.

    Refinement is a Distance+Threshold field per feature, combined with a Min
    field: within ``*_dist_m`` of a refinement point the size is the fine
    size; beyond it the size grows linearly with slope ``growth`` (metres of
    size per metre of distance) until it reaches ``global_m``.

    global_m     size far from all features (also the upper size cap).
    fillet_m     size near the points passed as ``fillet_points_xy`` (tooth
                 root fillets, where bending stress peaks); None = no fillet
                 refinement.
    load_m       size near ``refine_points_xy`` (load / contact points, where
                 Hertzian contact stresses need resolving); None = none.
    fillet_dist_m, load_dist_m
                 radius of the uniformly fine zone; None = 4 x the fine size.
    growth       size gradient outside the fine zone (dimensionless, > 0);
                 0.25 keeps neighbouring elements within ~25 % of each other.
    """

    global_m: float
    fillet_m: float | None = None
    load_m: float | None = None
    fillet_dist_m: float | None = None
    load_dist_m: float | None = None
    growth: float = 0.25

    def __post_init__(self) -> None:
        _positive("MeshSizes.global_m", self.global_m)
        _positive("MeshSizes.fillet_m", self.fillet_m, allow_none=True)
        _positive("MeshSizes.load_m", self.load_m, allow_none=True)
        _positive("MeshSizes.fillet_dist_m", self.fillet_dist_m, allow_none=True)
        _positive("MeshSizes.load_dist_m", self.load_dist_m, allow_none=True)
        _positive("MeshSizes.growth", self.growth)
        for name in ("fillet_m", "load_m"):
            v = getattr(self, name)
            if v is not None and v > self.global_m:
                raise MeshInputError(f"MeshSizes.{name}={v!r} is larger than global_m={self.global_m!r}")


@dataclass(frozen=True, eq=False)
class GearMesh:
    """A meshed gear body.

    mesh           CurvedMeshTri2 (order 2) or skfem.MeshTri (order 1);
                   coordinates in metres, all elements counter-clockwise.
                   ``mesh.boundaries`` holds the same facet groups.
    boundaries     facet-index arrays (indices into ``mesh.facets``):
                   full gear: "bore" (hub circle), "outer" (toothed polygon);
                   sector: "hub_arc", "outer", "cut_right" (radial cut at
                   angle_from, on the right when looking outward from the
                   centre), "cut_left" (radial cut at angle_to).
    area_m2        area of the meshed region, by exact quadrature of the
                   isoparametric (P2) or affine (P1) element geometry.
    exact_area_m2  exact area of the intended region (true circular bore; see
                   module docstring).
    order          geometric order (1 or 2).
    n_elements     number of triangles.
    build_time_s   wall time spent in gmsh + conversion (informational).
    """

    mesh: "skfem.MeshTri2"
    boundaries: dict[str, np.ndarray]
    area_m2: float
    exact_area_m2: float
    hub_radius_m: float
    order: int
    build_time_s: float = field(default=0.0)

    @property
    def n_elements(self) -> int:
        return int(self.mesh.t.shape[1])

    @property
    def area_rel_error(self) -> float:
        return abs(self.area_m2 - self.exact_area_m2) / self.exact_area_m2
