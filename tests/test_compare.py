"""FE against the analytic models in the app layer (gearwear.stiffness.comparison): the single-tooth
FE next to Ishikawa and the energy method at the same radii, the FE pair contact next
to the analytic curve. Coarse meshes, as in test_fem_tooth / test_fem_pair."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearwear.analytic import energy, ishikawa
from gearwear.fem.pair import pair_contact
from gearwear.fem.tooth import single_tooth_compliance
from gearwear.geometry.profile import tooth_profile
from gearwear.geometry.spec import default_pair
from gearwear.geometry.wear import WearSpec
from gearwear.stiffness.comparison import pair_vs_analytic, tooth_vs_analytic


@pytest.fixture(scope="module")
def pair():
    return default_pair()


@pytest.fixture(scope="module")
def nominal(pair):
    return tooth_vs_analytic(single_tooth_compliance(pair, mesh_scale=2.0))


def test_ishikawa_column_units(pair, nominal):
    """The reference column is analytic.ishikawa delta_1 + delta_2 (m/N) x 1e6 x b[mm]."""
    prof = tooth_profile(pair.gear(0))
    ref = ishikawa.tooth_compliance(prof, nominal.fe.radius_m, pair.materials[0], pair.face_width_m).total_m_per_N
    assert np.allclose(nominal.ishikawa_um_per_N_per_mm, ref * 1e6 * pair.face_width_m * 1e3, rtol=1e-3)
    ref_e = energy.tooth_compliance(prof, nominal.fe.radius_m, pair.materials[0], pair.face_width_m).total_m_per_N
    assert np.allclose(nominal.energy_um_per_N_per_mm, ref_e * 1e6 * pair.face_width_m * 1e3, rtol=1e-3)
    row = nominal.rows()[10]
    assert set(row) >= {
        "radius_mm",
        "roll_angle_deg",
        "fem_compliance_um_per_N_per_mm",
        "ishikawa_um_per_N_per_mm",
        "difference_percent",
    }
    assert row["difference_percent"] == pytest.approx(
        100 * (row["fem_compliance_um_per_N_per_mm"] / row["ishikawa_um_per_N_per_mm"] - 1), rel=1e-12
    )


def test_within_30_percent_of_ishikawa_at_pitch_point(pair, nominal):
    """At the pitch radius (75 mm) the FE compliance is within 30 % of Ishikawa's
    delta_1 + delta_2 (measured: FE +21 % in plane stress at the default level)."""
    r_pitch = pair.gear(0).pitch_radius_m
    fe = np.interp(r_pitch, nominal.fe.radius_m, nominal.fe.fem_compliance_um_per_N_per_mm)
    an = np.interp(r_pitch, nominal.fe.radius_m, nominal.ishikawa_um_per_N_per_mm)
    diff = fe / an - 1.0
    print(f"pitch point: FE {fe:.5f}, Ishikawa {an:.5f} um/(N/mm), difference {100 * diff:+.1f} %")
    assert abs(diff) < 0.30


def test_reference_is_on_the_worn_profile(pair, nominal):
    """One-flank wear thins the tooth, so the analytic reference on the FE's worn
    profile is more compliant than the nominal one at every radius."""
    worn = tooth_vs_analytic(single_tooth_compliance(pair, wear=WearSpec(phase="severe"), mesh_scale=2.0))
    assert np.array_equal(worn.fe.radius_m, nominal.fe.radius_m)
    assert np.all(worn.ishikawa_um_per_N_per_mm > nominal.ishikawa_um_per_N_per_mm)
    assert np.all(worn.energy_um_per_N_per_mm > nominal.energy_um_per_N_per_mm)


def test_pair_fe_against_the_analytic_curve(pair):
    """At the FE's angles theta_i = i 2 pi / (z1 n): the resolved FE pair is 10-35 %
    softer than the Ishikawa curve at every position (measured ~16-28 %: rim coupling
    and the resolved contact, which the slice model lacks), and in both two pairs are
    stiffer than one."""
    fe = pair_contact(pair, positions=12, contact_scale=2.0, extended=False)
    cmp = pair_vs_analytic(fe)
    an = cmp["analytic"]
    assert an.angle_rad == pytest.approx(np.arange(12) * 2 * math.pi / (30 * 12), rel=1e-12)
    assert np.all((cmp["per_position_rel_diff"] > -0.35) & (cmp["per_position_rel_diff"] < -0.10))
    assert cmp["double_fe"] > 1.3 * cmp["single_fe"]
    assert cmp["double_analytic"] > 1.3 * cmp["single_analytic"]
    assert cmp["ste_mean_fe_m"] > cmp["ste_mean_analytic_m"]  # softer: larger approach under the same load
