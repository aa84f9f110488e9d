"""Displacement and stress fields of the resolved pair FE (fem.pair) at chosen positions,
written as VTU files for ParaView (SI units: m, Pa).

Each gear body is solved once more at the position under the contact forces of its
solution (fem.pair_position.solve_position: a sparse LU of the body's stiffness, kept on
the body), its element-mean stress computed in its 2D state (plane stress: sigma_zz = 0;
plane strain: sigma_zz = nu (sigma_xx + sigma_yy)), and both bodies are placed in the
fixed frame of geometry.pair_positions by their tooth frames.
"""

from __future__ import annotations

import numpy as np

from gearwear.core.validation import fail
from gearwear.geometry.faults import revolution_periods
from gearwear.geometry.pair_positions import rot, tooth_frames

from .pair_body import GearBody
from .pair_model import PairModel
from .pair_position import _reps, solve_position

__all__ = ["write_fields"]


def _stress(body: GearBody, U: np.ndarray, material) -> np.ndarray:
    """Element-mean stress (nel, 3): sigma_xx, sigma_yy, sigma_xy (Pa) of the field U."""
    from skfem.helpers import sym_grad

    from .elasticity import lame

    basis = body.model.basis
    eps = sym_grad(basis.interpolate(U))  # (2, 2, nel, nqp)
    lam, mu = lame(material, body.model.plane)
    tr = eps[0, 0] + eps[1, 1]
    sxx, syy, sxy = lam * tr + 2 * mu * eps[0, 0], lam * tr + 2 * mu * eps[1, 1], 2 * mu * eps[0, 1]
    return np.column_stack([sxx.mean(axis=1), syy.mean(axis=1), sxy.mean(axis=1)])


def write_fields(pm: PairModel, positions: list[int], points: int, torque_Nm: float, out_dir) -> list:
    """Displacement and stress fields of both gears at the given position indices i of a
    curve with ``points`` positions per mesh period (theta = i 2 pi / (z1 points); with the
    model's faults i runs over the revolution, and period i // points says which slot holds
    the faulty tooth) as ``fields_pos<i>.vtu`` (meshio, P2 triangles in the fixed frame of
    geometry.pair_positions; point data displacement_m, cell data sigma_xx/yy/xy_Pa,
    von_mises_Pa, gear). The loaded tooth with the largest load is each body's refined
    tooth 0; the other loaded teeth take their load on their own (coarser) flanks. Where
    the cracked body served, it is drawn with its cracked tooth as tooth 0."""
    from pathlib import Path

    import meshio
    import scipy.sparse.linalg as spla

    from gearwear.core.atomic import atomic_write

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    F = torque_Nm / pm.pair.gear(0).base_radius_m
    total = points * revolution_periods(pm.pair, pm.faults)
    files = []
    for i in positions:
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < total:
            raise fail("fields", i, "", f"must be a position index in [0, {total - 1}]")
        theta = (i % points) * pm.mesh.mesh_angle_rad / points
        ps = solve_position(pm, theta, F, None if pm.faults is None else int(i // points))
        ref = max(ps.cand, key=lambda c: float(c["force_N"].sum()))
        _, _, O2 = tooth_frames(pm.mesh, ref["d"])
        pts, cells, disp, cdata, gear_id = [], [], [], [], []
        offset = 0
        for gi, body in enumerate(pm.bodies):
            ct = ps.cracked[gi]
            tooth0, d0 = (ref["teeth"][gi], ref["d"]) if ct is None else ct
            body = body if ct is None else pm.cracked[gi]
            model = body.model
            if getattr(body, "_lu", None) is None:
                Kff = model.K[model.free][:, model.free].tocsc()
                body._lu = spla.splu(
                    Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
                )
            f = np.zeros(model.ndofs)
            for c in ps.cand:
                idx, coef = _reps(body, c, gi, c["teeth"][gi] - tooth0, at_nodes=ct is None)
                np.add.at(f, body.dofs[idx], coef * c["force_N"][:, None])
            U = np.zeros(model.ndofs)
            U[model.free] = body._lu.solve(f[model.free])
            S = _stress(body, U, pm.pair.materials[gi])
            Rm = rot(tooth_frames(pm.mesh, d0)[gi])
            loc = model.basis.doflocs[:, 0::2].T
            p = loc @ Rm.T + (0.0 if gi == 0 else O2)
            u = U.reshape(-1, 2) @ Rm.T
            # stress tensor to the fixed frame: R sigma R^T
            sig = np.stack([np.stack([S[:, 0], S[:, 2]], -1), np.stack([S[:, 2], S[:, 1]], -1)], -2)
            sig = Rm @ sig @ Rm.T
            sxx, syy, sxy = sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1]
            szz = (pm.pair.materials[gi].poisson_ratio * (sxx + syy)) if pm.plane == "strain" else 0.0 * sxx
            vm = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * sxy**2)
            pts.append(np.column_stack([p, np.zeros(len(p))]))
            disp.append(np.column_stack([u, np.zeros(len(u))]))
            cells.append(model.basis.element_dofs[0::2].T // 2 + offset)
            cdata.append(np.column_stack([sxx, syy, sxy, vm]))
            gear_id.append(np.full(len(sxx), gi))
            offset += len(p)
        cd = np.vstack(cdata)
        mesh = meshio.Mesh(
            np.vstack(pts),
            [("triangle6", np.vstack(cells).astype(np.int64))],
            point_data={"displacement_m": np.vstack(disp)},
            cell_data={
                "sigma_xx_Pa": [cd[:, 0]],
                "sigma_yy_Pa": [cd[:, 1]],
                "sigma_xy_Pa": [cd[:, 2]],
                "von_mises_Pa": [cd[:, 3]],
                "gear": [np.concatenate(gear_id)],
            },
        )
        path = out_dir / f"fields_pos{i}.vtu"
        atomic_write(str(path), lambda tmp: meshio.write(tmp, mesh, file_format="vtu"))
        files.append(path)
    return files
