"""Dynamics (paper Eqs. 7-10, 17-20) of a pair whose driver has MORE teeth: the 47/23 pair
of tests/pairs.py with its own bodies (geometry.blank.body_properties: mass and polar
moment of each generated gear), its own base radii and working pressure angle, and its
analytic mesh stiffness, built into GearDynamics directly.

With z_p = z_g (the paper pair) R_p = R_g and J_p = J_g, so a model that swaps the two
radii or inertias, or uses T_p for the gear's torque, is right by accident; here
R_p / R_g = 47/23 and J_p / J_g ~ 17.

Independent truths: static equilibrium of the paper's 6-DOF equations (J_p theta_p'' =
T_p - R_p F_m, J_g theta_g'' = R_g F_m - T_g: over a steady periodic response the mean
mesh force is T_p / R_p and the gear's torque balance is T_g = R_g F_m = T_p z_g / z_p;
the bearings carry the mean mesh force's components); the linear modes of the 6x6 system
(y_p, x_p, y_g, x_g, theta_p, theta_g) assembled here from those equations and solved
with scipy.linalg.eigh (one rigid rotation, five modes), against the model's eigenvalues
and the peaks of a free-vibration spectrum; and energy, written out here from the same
M and K: conserved (with the torque's potential -F_s q) without damping, and balancing
the input work F_s (q_end - q_start) with damping and a varying stiffness.
"""

import math

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.signal import find_peaks

from gearwear.analytic.tvms import mesh_stiffness
from gearwear.dynamics import GearDynamics, linear_eigenfrequencies, simulate, spectrum
from gearwear.geometry.blank import body_properties

from pairs import DRIVER_LARGER, by_hand_radii, by_hand_working_pressure_angle

PAIR = DRIVER_LARGER
K_B = 2.6e8  # bearing stiffness, N/m (the paper's)
TORQUE = 40.0  # on the 47-tooth driver, N m


def _bodies():
    """(m_p, m_g, J_p, J_g) of the generated 47- and 23-tooth bodies (kg, kg m^2)."""
    bp = [body_properties(g, PAIR.face_width_m) for g in PAIR.gears]
    return bp[0].mass_kg, bp[1].mass_kg, bp[0].inertia_kg_m2, bp[1].inertia_kg_m2


def _model(*, torque=TORQUE, tvms=True, k_constant=None, zeta_m=0.05, zeta_b=0.02, speed_rpm=1200.0):
    m_p, m_g, J_p, J_g = _bodies()
    R_p, R_g = (by_hand_radii(PAIR, i)["base"] for i in (0, 1))
    r = mesh_stiffness(PAIR, points=64, torque_Nm=TORQUE)
    k_mean = k_constant if k_constant is not None else r.mean_N_per_m
    m_e = 1.0 / (R_p**2 / J_p + R_g**2 / J_g)
    c_h = 2 * zeta_m * math.sqrt(k_mean * m_e)
    c_b = (2 * zeta_b * math.sqrt(K_B * m_p), 2 * zeta_b * math.sqrt(K_B * m_g))
    return GearDynamics(
        m_p=m_p,
        m_g=m_g,
        J_p=J_p,
        J_g=J_g,
        R_p=R_p,
        R_g=R_g,
        alpha=by_hand_working_pressure_angle(PAIR),
        k_b=K_B,
        c_b=c_b,
        c_h=c_h,
        T_p=torque,
        omega_p=speed_rpm * 2 * math.pi / 60,
        z_p=PAIR.teeth[0],
        phi_table=r.angle_rad,
        k_table=r.k_N_per_m,
        tvms=tvms,
        k_constant=k_constant,
    )


def _hand_6x6(model, k):
    """M, K in the paper's coordinates (y_p, x_p, y_g, x_g, theta_p, theta_g): the mesh
    spring k acts on delta = (y_p - y_g) cos(a) + (x_p - x_g) sin(a) + R_p theta_p - R_g theta_g."""
    a = model.alpha
    g = np.array([math.cos(a), math.sin(a), -math.cos(a), -math.sin(a), model.R_p, -model.R_g])
    K = np.diag([K_B] * 4 + [0.0, 0.0]) + k * np.outer(g, g)
    M = np.diag([model.m_p, model.m_p, model.m_g, model.m_g, model.J_p, model.J_g])
    return M, K, g


def _hand_energy(model, k, Z):
    """Kinetic + bearing + mesh strain energy (J) of reduced states Z (n, 10), with the
    relative coordinate q = R_p theta_p - R_g theta_g: the rigid rotation carries no strain
    and its kinetic energy is constant without a net torque, so the relative motion's
    kinetic energy is m_e q'^2 / 2 with m_e = 1 / (R_p^2 / J_p + R_g^2 / J_g) (written out)."""
    m_e = 1.0 / (model.R_p**2 / model.J_p + model.R_g**2 / model.J_g)
    a = model.alpha
    y_p, x_p, y_g, x_g, q = Z[:, :5].T
    v = Z[:, 5:10]
    delta = q + (x_p - x_g) * math.sin(a) + (y_p - y_g) * math.cos(a)
    kin = 0.5 * (
        model.m_p * (v[:, 0] ** 2 + v[:, 1] ** 2) + model.m_g * (v[:, 2] ** 2 + v[:, 3] ** 2) + m_e * v[:, 4] ** 2
    )
    return kin + 0.5 * K_B * np.sum(Z[:, :4] ** 2, axis=1) + 0.5 * k * delta**2


def test_the_driver_has_more_teeth_and_the_bodies_differ():
    """The premise: a 47-tooth driver on a 23-tooth gear, R_p / R_g = z_p / z_g, and bodies
    of different mass and inertia (so swapped indices show)."""
    m = _model()
    assert m.z_p == 47 and PAIR.teeth[1] == 23
    assert m.R_p / m.R_g == pytest.approx(47 / 23, rel=1e-12)
    assert m.J_p > 10 * m.J_g and m.m_p > 3 * m.m_g


def test_static_equilibrium_mean_mesh_force_and_gear_torque():
    """With the analytic stiffness curve of this pair and damping, after the transient the
    response repeats every mesh period, so the mean accelerations over whole periods vanish:
    mean F_m = T_p / R_p from the pinion's torsion, the gear's torsion then needs
    T_g = R_g mean F_m = T_p z_g / z_p (output torque of a 47:23 speed increaser, less than
    T_p), and each bearing carries the mean mesh force's components, k_b mean(y) = -+F cos(a),
    k_b mean(x) = -+F sin(a)."""
    m = _model()
    r = simulate(m, 0.3, 0.25, method="rk4")
    F = TORQUE / by_hand_radii(PAIR, 0)["base"]
    # the exact window mean (dynamics means_of): a sample mean of F_m, which jumps where a
    # pair enters or leaves at the table's exact contact edges, is off by ~ a jump / samples
    Fm = r.means_of(["F_m"])["F_m"]
    assert Fm == pytest.approx(F, rel=1e-4)
    assert m.T_g == pytest.approx(TORQUE * 23 / 47, rel=1e-12)
    assert by_hand_radii(PAIR, 1)["base"] * Fm == pytest.approx(TORQUE * 23 / 47, rel=1e-4)
    a = m.alpha
    for name, sign, comp in (
        ("y_p", -1, math.cos(a)),
        ("x_p", -1, math.sin(a)),
        ("y_g", 1, math.cos(a)),
        ("x_g", 1, math.sin(a)),
    ):
        assert K_B * r.means_of([name])[name] == pytest.approx(sign * F * comp, rel=1e-4)
    assert np.ptp(r.signals["F_m"]) > 0.01 * F  # the varying stiffness does excite the mesh


def test_linear_modes_hand_6x6_and_free_vibration_spectrum():
    """Constant stiffness (the curve's mean), no damping, no torque. The hand 6x6 system has
    one rigid rotation (eigenvalue 0) and five modes; the model's eigenfrequencies are those
    five, and a free vibration from a mixed initial displacement shows a spectral peak at
    each distinct one (0.5 %, 1 s record: 1 Hz bins, parabolic peak refinement) and none
    elsewhere above 1 % of the largest."""
    k = mesh_stiffness(PAIR, points=64, torque_Nm=TORQUE).mean_N_per_m
    m = _model(torque=0.0, tvms=False, k_constant=k, zeta_m=0.0, zeta_b=0.0)
    M, K, _ = _hand_6x6(m, k)
    lam = eigh(K, M, eigvals_only=True)
    assert abs(lam[0]) < 1e-9 * lam[-1]
    f_hand = np.sqrt(lam[1:]) / (2 * math.pi)
    assert np.allclose(linear_eigenfrequencies(m), f_hand, rtol=1e-9, atol=0)
    y0 = np.zeros(10)
    y0[:5] = np.array([1.0, -0.6, 0.3, 0.8, 1.3]) * 1e-6
    r = simulate(m, 1.0, 0.0, y0=y0, method="rk4")
    total = np.zeros(r.t.size // 2 + 1)
    for name in ("y_p", "x_p", "y_g", "x_g", "q"):
        x = r.signals[name] - r.signals[name].mean()
        total += spectrum(x * np.hanning(x.size), r.fs_Hz)[1]
    f = np.fft.rfftfreq(r.t.size, 1 / r.fs_Hz)
    for fk in f_hand:
        win = (f > 0.97 * fk) & (f < 1.03 * fk)
        i = int(np.argmax(np.where(win, total, 0)))
        lo, mid, hi = np.log(total[i - 1 : i + 2])
        f_peak = f[i] + 0.5 * (lo - hi) / (lo - 2 * mid + hi) * (f[1] - f[0])
        assert f_peak == pytest.approx(fk, rel=5e-3)
    peaks, _ = find_peaks(total, height=0.01 * total.max())
    for p in peaks:
        assert np.min(np.abs(f[p] / f_hand - 1)) < 5e-3, f[p]


def test_energy_conserved_without_damping_and_balanced_with_it():
    """Undamped, constant stiffness, torque T_p on the driver: the hand energy (module
    docstring) minus the torque's potential F_s q, F_s = T_p / R_p, stays constant (adaptive
    solver, rtol 1e-10) to 1e-6 of the largest strain and kinetic energy. Damped, with the varying
    stiffness: the model's tracked input work is F_s (q_end - q_start) (by hand), the
    dissipation is positive, and the hand energy changes by input - dissipation +
    parametric work (the tracked terms) to 1e-6 of the largest of them (adaptive solver,
    rtol 1e-10; measured 3e-8)."""
    k = mesh_stiffness(PAIR, points=64, torque_Nm=TORQUE).mean_N_per_m
    m = _model(tvms=False, k_constant=k, zeta_m=0.0, zeta_b=0.0)
    F_s = TORQUE / by_hand_radii(PAIR, 0)["base"]
    y0 = np.zeros(10)
    y0[:5] = np.array([1.0, -0.6, 0.3, 0.8, 1.3]) * 1e-6
    r = simulate(m, 0.02, 0.0, y0=y0, method="dopri5", rtol=1e-10)
    E = _hand_energy(m, k, r.states)
    H = E - F_s * r.states[:, 4]
    assert np.ptp(E) > 0.1 * E.max()  # energy really moves between the terms
    assert np.ptp(H) < 1e-6 * E.max()
    md = _model()
    rd = simulate(md, 0.02, 0.0, method="dopri5", rtol=1e-10, track_energy=True)
    W = {name: float(v[-1] - v[0]) for name, v in rd.energy.items()}
    q = rd.states[:, 4]
    assert W["W_in"] == pytest.approx(F_s * (q[-1] - q[0]), rel=1e-6, abs=0)
    assert W["D"] > 0
    P = 2 * math.pi / md.z_p
    k_of_t = np.interp(np.mod(md.omega_p * rd.t[[0, -1]], P), md.phi_table, md.k_table, period=P)
    E0, E1 = (_hand_energy(md, kk, rd.states[[i]])[0] for kk, i in zip(k_of_t, (0, -1)))
    scale = max(abs(W["W_in"]), W["D"], abs(W["W_k"]))
    assert E1 - E0 == pytest.approx(W["W_in"] - W["D"] + W["W_k"], abs=1e-6 * scale)
