"""ISO 6336-1 method B dynamic factor K_v (analytic.iso6336.dynamic_factor).

Each speed range is checked against values worked out by hand below from the equations,
plus the continuity ISO builds in at N = 1.15 and 1.5, the resonance speed against the
natural frequency it stands for, and the C_v table. Published examples with every input
and the printed K_v (KISSsoft's reports of the NREL 5 MW gearbox, subcritical range) are
reproduced in tests/test_iso6336_kisssoft.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearwear.analytic.iso6336 import (
    ISO1328_MODULE_LIMITS_MM,
    cv_coefficients,
    dynamic_factor,
    iso1328_deviations_um,
    iso1328_range_mean,
    resonance_speed_rpm,
)

# hand-worked case: z1 = 30, c_gamma = 15, c' = 12 N/(mm um), m_red = 0.05 kg/mm,
# w = F_t K_A / b = 50 N/mm, f_pb,eff = 8 um, f_f,eff = 10 um, C_a = 2 um, eps = 1.6
#   n_E1 = 30000 / (30 pi) sqrt(15 / 0.05) = 318.30989 * 17.320508 = 5513.289 min^-1
#   N_S  = 0.5 + 0.35 sqrt(0.5) = 0.7474874
#   B_p  = 12 * 8 / 50 = 1.92;  B_f = 12 * 10 / 50 = 2.4;  B_k = |1 - 12 * 2 / 50| = 0.52
#   K    = 0.32 * 1.92 + 0.34 * 2.4 + 0.23 * 0.52 = 1.55
#   subcritical, N = 0.5:  K_v = 1 + 0.5 * 1.55 = 1.775
#   main resonance:        K_v = 0.6144 + 0.816 + 0.9 * 0.52 + 1 = 2.8984
#   C_v7 (eps 1.6) = 0.125 sin(-0.4 pi) + 0.875 = 0.7561178
#   supercritical:         K_v = 0.47 * 1.92 + 0.47 * 2.4 + 0.7561178 = 2.7865178
#   intermediate, N = 1.3: K_v = 2.7865178 + (2.8984 - 2.7865178) * 0.2 / 0.35 = 2.8504505
CASE = dict(
    z1=30,
    c_gamma_N_per_mm_um=15.0,
    c_prime_N_per_mm_um=12.0,
    m_red_kg_per_mm=0.05,
    line_load_N_per_mm=50.0,
    f_pb_eff_um=8.0,
    f_f_eff_um=10.0,
    C_a_um=2.0,
    eps_gamma=1.6,
)
N_E1 = 5513.289


def kv_at(N):
    r = dynamic_factor(np.asarray(N, float) * N_E1, **CASE)
    return r


def test_each_range_against_hand_worked_values():
    r = kv_at([0.5, 1.0, 1.3, 2.0])
    assert r.n_E1_rpm == pytest.approx(N_E1, rel=1e-6)
    assert r.N_S == pytest.approx(0.7474874, rel=1e-6)
    assert (r.B_p, r.B_f, r.B_k) == pytest.approx((1.92, 2.4, 0.52), rel=1e-12)
    assert r.range_name == ("subcritical", "main resonance", "intermediate", "supercritical")
    assert r.K_v == pytest.approx([1.775, 2.8984, 2.8504505, 2.7865178], rel=1e-6)


def test_continuity_at_the_intermediate_boundaries_and_the_jump_at_N_S():
    eps = 1e-9
    lo, hi = kv_at([1.15 - eps, 1.15 + eps]).K_v
    assert abs(hi - lo) < 1e-6
    lo, hi = kv_at([1.5 - eps, 1.5 + eps]).K_v
    assert abs(hi - lo) < 1e-6
    # at N_S the standard steps from the subcritical line up to the resonance plateau
    r = kv_at([0.7474874 - 1e-6, 0.7474874 + 1e-6])
    assert r.range_name == ("subcritical", "main resonance")
    assert r.K_v[0] == pytest.approx(1 + 0.7474874 * 1.55, rel=1e-5)


def test_low_speed_limit_and_full_line_load_resonance_limit():
    assert kv_at([1e-6]).K_v[0] == pytest.approx(1.0, abs=1e-5)
    heavy = dynamic_factor([0.84 * N_E1, 0.86 * N_E1], **{**CASE, "line_load_N_per_mm": 150.0})
    assert heavy.N_S == 0.85 and heavy.range_name == ("subcritical", "main resonance")


def test_resonance_speed_is_the_rigid_bearing_torsional_natural_frequency():
    """c_gamma b = k (N/m per 1e6) and m_red b = m_e: n_E1 is the pinion speed whose mesh
    frequency z1 n / 60 equals sqrt(k / m_e) / (2 pi)."""
    k, m_e, b_mm, z1 = 4.3e8, 1.06, 20.0, 30
    f = math.sqrt(k / m_e) / (2 * math.pi)
    assert resonance_speed_rpm(z1, k / (b_mm * 1e6), m_e / b_mm) == pytest.approx(60 * f / z1, rel=1e-12)


def test_cv_coefficients_table():
    assert cv_coefficients(1.4) == pytest.approx((0.32, 0.34, 0.23, 0.90, 0.47, 0.47, 0.75))
    # eps = 2.2: 0.57/1.9, 0.096/0.64, 0.46/0.76, 0.12/0.46, 0.125 sin(0.2 pi) + 0.875
    assert cv_coefficients(2.2) == pytest.approx((0.32, 0.3, 0.15, 0.6052632, 0.47, 0.2608696, 0.9484732), rel=1e-6)
    assert cv_coefficients(3.0)[6] == 1.0
    with pytest.raises(ValueError):
        cv_coefficients(1.0)


def test_iso1328_grade_deviations_by_hand():
    # m = 5 mm in the range (3.5, 6] -> sqrt(3.5 * 6) = 4.5826 mm, d = 150 mm in (125, 280]
    # -> sqrt(125 * 280) = 187.08 mm; grade 5: f_pt = 0.3 (4.5826 + 0.4 sqrt 187.08) + 4
    # = 7.016 -> 7.0; f_f_alpha = 2.5 sqrt 4.5826 + 0.17 sqrt 187.08 + 0.5 = 8.177 -> 8.0;
    # grade 6 (x sqrt 2): 9.922 -> 10.0, 11.564 -> 12.0
    assert iso1328_deviations_um(5e-3, 150e-3, 5) == (7.0, 8.0)
    assert iso1328_deviations_um(5e-3, 150e-3, 6) == (10.0, 12.0)
    assert iso1328_range_mean(2.0, ISO1328_MODULE_LIMITS_MM) == 1.0  # 0.5 <= m <= 2: sqrt(0.5 * 2)
    assert iso1328_range_mean(2.000001, ISO1328_MODULE_LIMITS_MM) == math.sqrt(7.0)
    with pytest.raises(ValueError):
        iso1328_deviations_um(5e-3, 4e-3, 6)  # d < 5 mm: no ISO 1328-1 range


def test_iso1328_grade_6_tolerances_as_kisssoft_prints_them():
    """Published: KISSsoft's ISO 1328-1:1995 tables ([fptT], [ffaT], grade 6) in its reports of
    the NREL 5 MW gearbox (GitHub gfsReboucas/Drivetrain, @NREL_5MW/stage_0{1,2,3}.rtf): every
    gear, annuli included. Evaluated at the gear's own m and d, (21 mm, 378 mm) would give
    f_f_alpha = 22 um and (45 mm, 855 mm) f_pt = 30 um."""
    printed = {
        (21, 378.000): (18, 21),
        (21, 756.000): (19, 23),
        (21, 1953.000): (22, 27),
        (45, 855.000): (33, 33),
        (45, 765.000): (33, 33),
        (45, 2520.000): (38, 40),
        (14, 341.183): (14, 18),
        (14, 1350.517): (17, 22),
    }
    for (m_mm, d_mm), f in printed.items():
        assert iso1328_deviations_um(m_mm * 1e-3, d_mm * 1e-3, 6) == f
