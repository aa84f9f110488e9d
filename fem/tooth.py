"""Single-tooth compliance of a spur gear by the finite element method.

Reference model
---------------
The whole gear body with all z teeth (``fem.mesh.mesh_full_gear``), bore
clamped (u = 0 on r = r_hub), 2D linear elasticity, plane stress by default with
thickness = face width b (``fem.elasticity``). Only tooth 0 (centred on +y) is
loaded. The rim under the loaded tooth is part of the tooth's "foundation" (Weber's
delta_2), so a sector model needs cut conditions that the full gear does not; the
full gear is the reference and no sector is used.

The method in four modules; their public names are re-exported here, so
``gearwear.fem.tooth`` stays the place to import them from:

* ``fem.tooth_load``: the load positions, equal roll-angle steps from the SAP to the
  contact whose Hertz patch ends below the tip corner (:func:`load_radii`, m and rad), and
  the Hertzian pressure patch that loads each one (Johnson 1985, Eqs. 4.43-4.45;
  :func:`hertz_patch_forces`, :func:`patch_load`, N);
* ``fem.tooth_mesh``: the meshed full gear (:func:`tooth_mesh`, :class:`ToothMesh`): element
  sizes (:func:`mesh_sizes`, m), curved P2 edges, the worn flank and the root-crack cut;
* ``fem.tooth_flank``: the mesh nodes on the loaded flank and the morph of the nominal
  mesh onto the worn flank (:func:`morph_to_worn`, harmonic extension, m);
* ``fem.tooth_compliance``: the solve and the centre-line compliance
  c = u(0, R) . e_F / F (:func:`single_tooth_compliance`, :class:`ToothFE`, um per (N/mm)),
  and the crack mouth opening per unit load (:func:`crack_mouth_opening`, m/N).
"""

from __future__ import annotations

from .tooth_compliance import ToothFE, crack_mouth_opening, crack_mouth_pair, single_tooth_compliance
from .tooth_flank import morph_to_worn
from .tooth_load import (
    DEFAULT_TORQUE_NM,
    EDGE_SUBSTEPS,
    PATCH_POINTS,
    TIP_MARGIN_HALF_WIDTHS,
    hertz_patch_forces,
    load_radii,
    patch_load,
)
from .tooth_mesh import (
    CRACK_TIP_FRACTION,
    FILLET_DIST_M,
    FILLET_M,
    GLOBAL_M,
    GROWTH,
    LOAD_DIST_M,
    LOAD_M,
    OTHER_SPACING,
    WORN_GEOMETRIES,
    ToothMesh,
    default_crack_tip_size_m,
    gear_polygon,
    mesh_sizes,
    tooth_mesh,
)

__all__ = [
    "ToothFE",
    "single_tooth_compliance",
    "crack_mouth_pair",
    "crack_mouth_opening",
    "ToothMesh",
    "tooth_mesh",
    "mesh_sizes",
    "gear_polygon",
    "default_crack_tip_size_m",
    "morph_to_worn",
    "load_radii",
    "hertz_patch_forces",
    "patch_load",
    "GLOBAL_M",
    "LOAD_M",
    "FILLET_M",
    "GROWTH",
    "FILLET_DIST_M",
    "LOAD_DIST_M",
    "DEFAULT_TORQUE_NM",
    "OTHER_SPACING",
    "PATCH_POINTS",
    "EDGE_SUBSTEPS",
    "TIP_MARGIN_HALF_WIDTHS",
    "WORN_GEOMETRIES",
    "CRACK_TIP_FRACTION",
]
