"""ISO 6336-1 method B stiffness: the standard's polynomial evaluated by hand, its
quoted typical range, and the identities between its factors."""

import math
from dataclasses import replace

import pytest

from gearwear.analytic.iso6336 import (
    basic_rack_factor,
    gear_blank_factor,
    iso6336_stiffness,
    iso_ordered,
    low_load_factor,
    pair_blank_factor,
    single_stiffness_theoretical,
)
from gearwear.geometry.kinematics import MeshGeometry
from gearwear.geometry.spec import Web, default_pair, replace_checked


def test_theoretical_stiffness_by_hand_z30_x0():
    # q' = C1 + C2/z1 + C3/z2 with x1 = x2 = 0 (ISO 6336-1 constants), mm um / N
    q = 0.04723 + 0.15551 / 30 + 0.25791 / 30
    assert single_stiffness_theoretical(30, 30, 0.0, 0.0) == pytest.approx(1.0 / q, rel=1e-12)


def test_theoretical_stiffness_by_hand_with_profile_shift():
    z1, z2, x1, x2 = 20, 45, 0.3, -0.1
    q = (
        0.04723
        + 0.15551 / z1
        + 0.25791 / z2
        - 0.00635 * x1
        - 0.11654 * x1 / z1
        - 0.00193 * x2
        - 0.24188 * x2 / z2
        + 0.00529 * x1**2
        + 0.00182 * x2**2
    )
    assert single_stiffness_theoretical(z1, z2, x1, x2) == pytest.approx(1.0 / q, rel=1e-12)


def test_standard_steel_pair_in_iso_typical_range():
    """ISO 6336-1: c' is about 14 N/(mm um) for solid steel spur gears of standard
    proportions; without the low-load factor it must lie within 12..16."""
    r = iso6336_stiffness(default_pair())
    assert 12.0 < r.c_prime < 16.0
    assert r.low_load_factor == 1.0 and r.c_prime_low_load == r.c_prime


def test_paper_pair_factors():
    pair = default_pair()  # h_fP = 1.25 m, alpha = 20 deg, solid, steel 206 GPa
    r = iso6336_stiffness(pair)
    assert r.C_M == 0.8 and r.C_R == 1.0 and r.cos_beta == 1.0 and r.material_factor == 1.0
    assert r.C_B == pytest.approx(1.0 + 0.5 * (1.2 - 1.25), rel=1e-15)
    assert r.c_prime == pytest.approx(r.c_th_prime * 0.8 * r.C_B, rel=1e-15)
    assert r.eps_alpha == MeshGeometry(pair, pair.centre_distance_m).contact_ratio
    assert r.in_fit_range


def test_basic_rack_factor_is_one_for_iso_reference_rack():
    assert basic_rack_factor(1.2, math.radians(20.0)) == pytest.approx(1.0, abs=1e-15)
    # each bracket on its own
    assert basic_rack_factor(1.0, math.radians(20.0)) == pytest.approx(1.1, rel=1e-15)
    assert basic_rack_factor(1.2, math.radians(25.0)) == pytest.approx(1.1, rel=1e-14)


def test_gear_blank_factor():
    assert gear_blank_factor(20e-3, 5e-3) == 1.0
    # b_s/b = 0.5, s_R/m_n = 2: 1 + ln 0.5 / (5 e^0.4)
    assert gear_blank_factor(20e-3, 5e-3, 10e-3, 10e-3) == pytest.approx(
        1.0 + math.log(0.5) / (5.0 * math.exp(0.4)), rel=1e-14
    )
    # ratios beyond the standard's limits are clamped to them
    assert gear_blank_factor(20e-3, 5e-3, 1e-3, 1e-3) == pytest.approx(1.0 + math.log(0.2) / (5.0 * math.exp(0.2)))


def test_mesh_stiffness_identity():
    for eps in (1.2, 1.65, 1.9):
        r = iso6336_stiffness(default_pair(), contact_ratio=eps)
        assert r.eps_alpha == eps
        assert r.c_gamma_alpha == pytest.approx(r.c_prime * (0.75 * eps + 0.25), rel=1e-15)


def test_low_load_factor_below_and_above_100_N_per_mm():
    pair = default_pair()  # d1 = 150 mm, b = 20 mm: F_t / b = 2000 T / (150 * 20) = T / 1.5 N/mm
    low = iso6336_stiffness(pair, torque_Nm=40.0)
    assert low.line_load_N_per_mm == pytest.approx(40.0 / 1.5, rel=1e-14)
    f = (40.0 / 1.5 / 100.0) ** 0.25
    assert low.low_load_factor == pytest.approx(f, rel=1e-14)
    assert low.c_prime_low_load == pytest.approx(low.c_prime * f, rel=1e-14)
    assert low.c_gamma_alpha_low_load == pytest.approx(low.c_gamma_alpha * f, rel=1e-14)
    assert low.c_prime == iso6336_stiffness(pair).c_prime  # c' itself stays unreduced
    # K_A scales the line load
    assert iso6336_stiffness(pair, torque_Nm=40.0, K_A=2.0).low_load_factor == pytest.approx(
        (80.0 / 1.5 / 100.0) ** 0.25, rel=1e-14
    )
    for torque in (150.0, 300.0):  # 100 and 200 N/mm: no reduction
        high = iso6336_stiffness(pair, torque_Nm=torque)
        assert high.low_load_factor == 1.0
        assert high.c_prime_low_load == high.c_prime
    assert low_load_factor(None) == 1.0


def test_N_per_m_conversion():
    r = iso6336_stiffness(default_pair(), torque_Nm=40.0)
    # N/(mm um) * 20 mm = N/um; 1 N/um = 1e6 N/m
    assert r.single_stiffness_N_per_m == pytest.approx(r.c_prime * 20.0 * 1e6, rel=1e-15)
    assert r.mesh_stiffness_N_per_m == pytest.approx(r.c_gamma_alpha * 20.0 * 1e6, rel=1e-15)
    assert r.mesh_stiffness_low_load_N_per_m == pytest.approx(r.c_gamma_alpha_low_load * 20e6, rel=1e-15)


def test_more_teeth_stiffer():
    zs = [12, 17, 25, 30, 50, 100, 200]
    c = [single_stiffness_theoretical(z, z, 0.0, 0.0) for z in zs]
    assert all(b > a for a, b in zip(c, c[1:]))
    c2 = [single_stiffness_theoretical(20, z, 0.0, 0.0) for z in zs]
    assert all(b > a for a, b in zip(c2, c2[1:]))


def test_softer_material_scales_stiffness():
    pair = default_pair()
    alu = replace(pair, materials=(replace(pair.materials[0], youngs_modulus_Pa=103e9),) * 2)
    assert iso6336_stiffness(alu).c_prime == pytest.approx(0.5 * iso6336_stiffness(pair).c_prime, rel=1e-14)


def test_profile_shift_enters_and_range_flag():
    pair = replace_checked(default_pair(), profile_shift=(0.4, 0.0))
    r = iso6336_stiffness(pair)
    assert r.c_th_prime == pytest.approx(single_stiffness_theoretical(30, 30, 0.4, 0.0), rel=1e-15)
    assert r.in_fit_range
    assert not iso6336_stiffness(replace_checked(default_pair(), profile_shift=(0.0, 0.3))).in_fit_range


def test_bad_inputs():
    with pytest.raises(ValueError):
        iso6336_stiffness(default_pair(), torque_Nm=-1.0)
    with pytest.raises(ValueError):
        iso6336_stiffness(default_pair(), K_A=0.0)


def driver_with_more_teeth():
    """A pair whose driver (index 0) has more teeth than the driven gear, with every
    per-gear value different, and the same pair with driver and driven gear exchanged."""
    pair = replace_checked(
        default_pair(),
        teeth=(47, 23),
        profile_shift=(0.1, 0.3),
        hub_radius_m=(60e-3, 30e-3),
        materials=(replace(default_pair().materials[0], youngs_modulus_Pa=200e9), default_pair().materials[1]),
    )
    swapped = replace_checked(
        pair, teeth=(23, 47), profile_shift=(0.3, 0.1), hub_radius_m=(30e-3, 60e-3), materials=pair.materials[::-1]
    )
    return pair, swapped


def test_iso_order_puts_the_gear_with_fewer_teeth_first():
    pair, swapped = driver_with_more_teeth()
    assert iso_ordered(pair) == swapped
    assert iso_ordered(pair).gear(0) == replace(pair.gear(1), name="pinion")
    assert iso_ordered(swapped) is swapped
    same = default_pair()  # equal tooth counts: the driver stays gear 1
    assert iso_ordered(same) is same


def test_gear_1_is_the_gear_with_fewer_teeth_whichever_drives():
    """ISO 6336's gear 1 has fewer teeth: a pair whose driver has more teeth gives exactly
    the stiffness of the same pair with driver and driven gear exchanged, and that is the
    q' polynomial with z1 = 23 (x1 = 0.3), z2 = 47 (x2 = 0.1) by hand. Read with the driver
    as gear 1 the polynomial is 2.6 % softer (the error this guards against)."""
    pair, swapped = driver_with_more_teeth()
    a, b = iso6336_stiffness(pair), iso6336_stiffness(swapped)
    assert a == b
    assert (a.z1, a.z2) == (23, 47)
    q = (
        0.04723
        + 0.15551 / 23
        + 0.25791 / 47
        - 0.00635 * 0.3
        - 0.11654 * 0.3 / 23
        - 0.00193 * 0.1
        - 0.24188 * 0.1 / 47
        + 0.00529 * 0.3**2
        + 0.00182 * 0.1**2
    )
    assert a.c_th_prime == pytest.approx(1.0 / q, rel=1e-12)
    assert 1 - single_stiffness_theoretical(47, 23, 0.1, 0.3) / a.c_th_prime > 0.025  # the driver-first reading
    # the driver's torque T is T z1 / z_driver on gear 1: the swapped pair's driver carries T 23 / 47
    T = 350.0
    assert iso6336_stiffness(pair, torque_Nm=T) == iso6336_stiffness(swapped, torque_Nm=T * (23 / 47))
    # F_t = 2 T1 / d1 = 2 (T 23 / 47) / (5 mm * 23): the same force as 2 T / d_driver
    assert iso6336_stiffness(pair, torque_Nm=T).line_load_N_per_mm == pytest.approx(
        2 * T / (5e-3 * 47) / 20.0, rel=1e-14
    )


def test_each_gear_has_its_own_web_and_the_pair_takes_the_mean_blank_factor():
    """C_R per gear from its own web, the pair's the mean (C_R,1 + C_R,2) / 2; by hand with
    b = 20 mm, m = 5 mm: b_s = 10 mm, s_R = 10 mm gives 1 + ln 0.5 / (5 e^0.4); b_s = 6 mm,
    s_R = 5 mm gives 1 + ln 0.3 / (5 e^0.2); a solid disc 1."""
    cr_a = 1.0 + math.log(0.5) / (5.0 * math.exp(0.4))
    cr_b = 1.0 + math.log(0.3) / (5.0 * math.exp(0.2))
    solid = iso6336_stiffness(default_pair())
    for webs, expected in (
        ((Web(10e-3, 10e-3, 50e-3), None), 0.5 * (cr_a + 1.0)),
        ((None, Web(6e-3, 5e-3, 50e-3)), 0.5 * (1.0 + cr_b)),
        ((Web(10e-3, 10e-3, 50e-3), Web(6e-3, 5e-3, 50e-3)), 0.5 * (cr_a + cr_b)),
        ((Web(10e-3, 10e-3, 50e-3),) * 2, cr_a),
    ):  # alike blanks: the standard's C_R
        pair = replace_checked(default_pair(), webs=webs)
        assert pair_blank_factor(pair) == pytest.approx(expected, rel=1e-14)
        r = iso6336_stiffness(pair)
        assert r.C_R == pair_blank_factor(pair)
        assert r.c_prime == pytest.approx(solid.c_prime * expected, rel=1e-14)
        assert r.c_gamma_alpha == pytest.approx(solid.c_gamma_alpha * expected, rel=1e-14)
    assert pair_blank_factor(default_pair()) == 1.0


def test_two_materials_scale_by_the_equivalent_modulus():
    """E1 = 206 GPa, E2 = 103 GPa: c' and c_gamma_alpha are the steel/steel values times
    E / E_st with E = 2 E1 E2 / (E1 + E2) (ISO 6336-1), whichever gear is the softer."""
    pair = default_pair()
    steel = iso6336_stiffness(pair)
    factor = 2 * 206 * 103 / (206 + 103) / 206
    for materials in (
        (pair.materials[0], replace(pair.materials[1], youngs_modulus_Pa=103e9)),
        (replace(pair.materials[0], youngs_modulus_Pa=103e9), pair.materials[1]),
    ):
        r = iso6336_stiffness(replace_checked(pair, materials=materials))
        assert r.material_factor == pytest.approx(factor, rel=1e-15)
        assert r.c_prime == pytest.approx(steel.c_prime * factor, rel=1e-15)
        assert r.c_gamma_alpha == pytest.approx(steel.c_gamma_alpha * factor, rel=1e-15)
