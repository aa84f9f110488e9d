/* Plain C reference for benchmarks/bench_rk4_vs_c.py: the reduced 5-DOF spur-gear
 * model of dynamics/model.py with every effect on (time-varying mesh stiffness k and
 * transmission-error excitation e from the one-period RK4 schedule, backlash dead
 * zone with drive and back flank, bearing clearance dead zones on y_p, x_p, y_g, x_g,
 * dynamic centre distance, mesh damping only in contact), integrated by classical
 * RK4 over the schedule's sub-steps. No output sampling, no energy accumulators.
 *
 * Written from the model equations (dynamics/model.py docstring), not from the numba
 * kernel: state z = (y_p, x_p, y_g, x_g, q, their velocities);
 *   O_g - O_p = (C0 + x_g - x_p, y_g - y_p), C = |O_g - O_p|, cos a' = (R_p+R_g)/C,
 *   b(C) = b0 + (R_p+R_g) (inv a' - inv a0),   delta = q + (y_p - y_g) cos a',
 *   s = delta - e,  drive flank f_d = s - b if s > b,  back flank f_b = s + b if s < -b,
 *   F = c_h delta' (in contact) + k (f_d + f_b),
 *   generalised mesh force Q = -F d delta/dx + k (f_d - f_b) d b/dx,
 *   m x'' = Q - c_b x' - k_b f_bb(x) (bearings, dead zone half-width b_b),
 *   m_e q'' = F_s - F.
 * The parameter vector p uses the layout of dynamics.model (P_MP = 0, ... P_PAPER = 18).
 *
 * Build: gcc -O3 -march=native -shared -fPIC rk4.c -o librk4.so -lm
 */
#include <math.h>

enum { MP, MG, ME, FS, KB, CBP, CBG, CH, SA, CA, KC, B0, BB, OM, PER, C0, RS, INV0, PAPER };

static inline double dead(double u, double bb)
{
    if (u > bb) return u - bb;
    if (u < -bb) return u + bb;
    return 0.0;
}

/* dz = f(z) at mesh stiffness k and excitation e */
static inline void rhs(const double *restrict p, const double *restrict z, double k, double e,
                       double *restrict dz)
{
    const double rs = p[RS];
    /* centre line and the operating pressure angle */
    double dx = p[C0] + z[3] - z[1];
    double dy = z[2] - z[0];
    double C = sqrt(dx * dx + dy * dy);
    double ca = rs / C;
    if (ca > 1.0) ca = 1.0;
    double sa = sqrt(1.0 - ca * ca);
    double b = p[B0] + rs * (sa / ca - atan2(sa, ca) - p[INV0]);
    /* dC/d(y_p, x_p, y_g, x_g) = (-dy, -dx, dy, dx) / C */
    double cy = -dy / C, cx = -dx / C;
    double Y = z[0] - z[2];
    double w = -Y * ca / C;             /* Y d(cos a')/dC */
    double g0 = ca + w * cy, g1 = w * cx, g2 = -ca - w * cy, g3 = -w * cx;
    double delta = z[4] + Y * ca;
    double ddelta = z[9] + g0 * z[5] + g1 * z[6] + g2 * z[7] + g3 * z[8];
    /* two-flank contact law */
    double s = delta - e;
    double fdr = 0.0, fbk = 0.0, fdamp = 0.0;
    if (s > b) fdr = s - b;
    if (s < -b) fbk = s + b;
    if (s > b || s < -b || p[PAPER] > 0.5) fdamp = p[CH] * ddelta;
    double F = fdamp + k * (fdr + fbk);
    double kf = k * (fdr - fbk);        /* times d b/dx = sin a' dC/dx */
    double q0 = -F * g0 + kf * sa * cy;
    double q1 = -F * g1 + kf * sa * cx;
    double q2 = -F * g2 - kf * sa * cy;
    double q3 = -F * g3 - kf * sa * cx;
    double bb = p[BB], kb = p[KB];
    dz[0] = z[5];
    dz[1] = z[6];
    dz[2] = z[7];
    dz[3] = z[8];
    dz[4] = z[9];
    dz[5] = (q0 - p[CBP] * z[5] - kb * dead(z[0], bb)) / p[MP];
    dz[6] = (q1 - p[CBP] * z[6] - kb * dead(z[1], bb)) / p[MP];
    dz[7] = (q2 - p[CBG] * z[7] - kb * dead(z[2], bb)) / p[MG];
    dz[8] = (q3 - p[CBG] * z[8] - kb * dead(z[3], bb)) / p[MG];
    dz[9] = (p[FS] - F) / p[ME];
}

/* n_substeps RK4 sub-steps of the periodic schedule (hs[Q]; kq, eq: k and e at each
 * sub-step's start, middle and end), starting at sub-step 0, z[10] updated in place.
 * Returns 0, or 3 when |y_p|, |y_g| or |q| reaches zlim or turns non-finite. */
int rk4_run(const double *p, int Q, const double *hs, const double *kq, const double *eq,
            long n_substeps, double zlim, double *z)
{
    double d1[10], d2[10], d3[10], d4[10], zt[10];
    int q = 0;
    for (long n = 0; n < n_substeps; n++) {
        double h = hs[q];
        rhs(p, z, kq[3 * q], eq[3 * q], d1);
        for (int i = 0; i < 10; i++) zt[i] = z[i] + 0.5 * h * d1[i];
        rhs(p, zt, kq[3 * q + 1], eq[3 * q + 1], d2);
        for (int i = 0; i < 10; i++) zt[i] = z[i] + 0.5 * h * d2[i];
        rhs(p, zt, kq[3 * q + 1], eq[3 * q + 1], d3);
        for (int i = 0; i < 10; i++) zt[i] = z[i] + h * d3[i];
        rhs(p, zt, kq[3 * q + 2], eq[3 * q + 2], d4);
        double h6 = h / 6.0;
        for (int i = 0; i < 10; i++) z[i] += h6 * (d1[i] + 2.0 * (d2[i] + d3[i]) + d4[i]);
        if (!(fabs(z[4]) < zlim && fabs(z[0]) < zlim && fabs(z[2]) < zlim)) return 3;
        if (++q == Q) q = 0;
    }
    return 0;
}
