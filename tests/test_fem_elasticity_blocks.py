"""The block assembly of isotropic elasticity (fem.elasticity_blocks) against scikit-fem's
own vector form (skfem.models.elasticity.linear_elasticity) on straight and curved meshes."""

import numpy as np
import pytest
import skfem
from skfem.models.elasticity import linear_elasticity

from gearwear.fem.elasticity_blocks import isotropic_stiffness


@pytest.mark.parametrize(
    "mesh, elem",
    [
        (skfem.MeshTri.init_sqsymmetric().refined(2), skfem.ElementTriP1()),
        (skfem.MeshTri.init_sqsymmetric().refined(2), skfem.ElementTriP2()),
        (skfem.MeshTri2.init_circle(2), skfem.ElementTriP2()),  # isoparametric, curved edges
    ],
)
def test_blocks_equal_skfems_vector_form(mesh, elem):
    lam, mu = 1.3e11, 0.8e11
    order = 2 if isinstance(elem, skfem.ElementTriP2) else 1
    vector = skfem.Basis(mesh, skfem.ElementVector(elem), intorder=2 * order)
    K_ref = skfem.asm(linear_elasticity(lam, mu), vector).toarray()
    K = isotropic_stiffness(skfem.Basis(mesh, elem, intorder=2 * order), lam, mu).toarray()
    assert K.shape == K_ref.shape
    assert np.max(np.abs(K - K_ref)) <= 1e-13 * np.max(np.abs(K_ref))
