"""The 2D state of the analytic tooth models' beam terms: plane stress or plane strain.

A tooth is a plate of thickness b (the face width) loaded in its plane. Its two limits:

* plane stress (sigma_zz = 0): free faces, the thin-face limit (b/m -> 0);
* plane strain (eps_zz = 0): a wide face whose mid-plane cannot contract.

In plane strain the in-plane normal stiffness of an isotropic solid is E' = E / (1 - nu^2)
(sigma_xx = E' eps_xx at sigma_yy = 0 and eps_zz = 0), so the beam's bending and axial terms
take E'; the shear modulus G = E / (2 (1 + nu)) is the same in both states (in-plane shear does
not couple to the normal strains). Which state fits which face width is settled by the 3D FE
check (reports/plane, docs/models.md "Plane stress or plane strain"); the scene key fem.plane
chooses it for the FE and these beam terms alike.
"""

from __future__ import annotations

from gearwear.core.validation import fail

PLANES = ("stress", "strain")


def beam_modulus_Pa(youngs_modulus_Pa: float, poisson_ratio: float, plane: str) -> float:
    """E of the beam's bending and axial terms (Pa): E in plane stress, E / (1 - nu^2) in
    plane strain."""
    if plane == "stress":
        return youngs_modulus_Pa
    if plane == "strain":
        return youngs_modulus_Pa / (1.0 - poisson_ratio**2)
    raise fail("plane", repr(plane), "", f"must be one of {', '.join(PLANES)}")
