/*
 * Cart-pole: a single uniform rod on a cart. q = (x, theta): the cart's position on its
 * horizontal track, and the rod's angle from the upward vertical (as the DIPC's angles).
 * Cart of mass m0; rod of mass m1, length l1, inertia I1 about its centre (a uniform rod,
 * m1 l1^2 / 12, unless given), pivoted on the cart; a = l1 / 2.
 *   r_0 = (x, 0),  r_1 = (x + a sin th, a cos th),  omega_1 = th_dot
 *   T = 1/2 m0 xd^2 + 1/2 m1 |v_1|^2 + 1/2 I1 thd^2,  U = m1 g a cos th
 * With v_1 = (xd + a cos th thd, -a sin th thd), |v_1|^2 = xd^2 + 2 a cos th xd thd +
 * a^2 thd^2, so T = 1/2 qd^T M qd with
 *   M00 = m0 + m1,  M01 = k c,  M11 = m1 a^2 + I1,   k = m1 a, c = cos th, s = sin th.
 * The only non-zero derivative is dM01/dth = -k s, so the Christoffel symbols
 * c_ijk = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k) give
 *   C = [[0, -k s thd], [0, 0]],   g = dU/dq = (0, -k g s),
 * and Lagrange's equations read
 *   (m0 + m1) xdd + k c thdd - k s thd^2 = F
 *   k c xdd + (m1 a^2 + I1) thdd - k g s = 0
 * (the DIPC's with the upper rod taken away). Input: a horizontal force F on the cart.
 */
#include <math.h>
#include "core_internal.h"

enum { P_M0, P_M1, P_L1, P_I1, P_G, P_COUNT };

typedef struct cp_k {
    double mt, k, J;
} cp_k;

static inline cp_k cp_coeffs(const double *p)
{
    double a = 0.5 * p[P_L1];
    return (cp_k){p[P_M0] + p[P_M1], p[P_M1] * a, p[P_M1] * a * a + p[P_I1]};
}

static void cp_mass(const double *p, const double *q, double *M)
{
    cp_k k = cp_coeffs(p);
    M[0] = k.mt;            M[1] = k.k * cos(q[1]);
    M[2] = M[1];            M[3] = k.J;
}

static void cp_mass_deriv(const double *p, const double *q, double *dM)
{
    cp_k k = cp_coeffs(p);
    for (int i = 0; i < 8; i++) dM[i] = 0.0;
    dM[4 + 1] = dM[4 + 2] = -k.k * sin(q[1]); /* block k = 1 (theta) starts at 4 */
}

static void cp_coriolis(const double *p, const double *q, const double *qd, double *C)
{
    cp_k k = cp_coeffs(p);
    C[0] = 0.0; C[1] = -k.k * sin(q[1]) * qd[1];
    C[2] = 0.0; C[3] = 0.0;
}

static void cp_gravity(const double *p, const double *q, double *g)
{
    g[0] = 0.0;
    g[1] = -cp_coeffs(p).k * p[P_G] * sin(q[1]);
}

/* M and h = C qd + g with one sincos. */
static void cp_mass_bias(const double *p, const double *q, const double *qd, double *M, double *h)
{
    cp_k k = cp_coeffs(p);
    double s, c;
    sincos(q[1], &s, &c);
    M[0] = k.mt;      M[1] = k.k * c;
    M[2] = M[1];      M[3] = k.J;
    h[0] = -k.k * s * qd[1] * qd[1];
    h[1] = -k.k * p[P_G] * s;
}

/* M qdd = tau - h, by the 2 x 2 LDL^T solve. */
static lag_result cp_forward(const double *p, const double *q, const double *qd,
                             const double *tau, double *qdd)
{
    double M[4], h[2];
    cp_mass_bias(p, q, qd, M, h);
    double r[2] = {tau[0] - h[0], tau[1] - h[1]};
    return lag_spd_solve2(M, r, qdd);
}

static double cp_kinetic(const double *p, const double *q, const double *qd)
{
    cp_k k = cp_coeffs(p);
    return 0.5 * k.mt * qd[0] * qd[0] + k.k * cos(q[1]) * qd[0] * qd[1] + 0.5 * k.J * qd[1] * qd[1];
}

static double cp_potential(const double *p, const double *q)
{
    return cp_coeffs(p).k * p[P_G] * cos(q[1]);
}

/* Defaults: the classic cart-pole (Barto, Sutton & Anderson 1983): a 1 kg cart and a
 * 0.1 kg pole 1 m long. */
static const lag_model_info info = {
    .name = "cartpole",
    .nq = 2,
    .np = P_COUNT,
    .param_names = {"m0", "m1", "l1", "I1", "g"},
    .param_defaults = {1.0, 0.1, 1.0, NAN, 9.81},
    .param_units = {"kg", "kg", "m", "kg m^2", "m/s^2"},
    .param_rules = {[P_G] = LAG_PARAM_NONNEGATIVE},
    .n_rods = 1,
    .rods = {{P_I1, P_M1, P_L1}},
    .joint_names = {"x", "theta"},
    .actuated = {true, false},
    .angular = {false, true},
};

static const lag_model_doc doc = {
    .title = "cart-pole",
    .summary = "a pendulum on a cart",
    .params = {"cart mass", "pole mass", "pole length", "pole inertia about its centre", "gravity"},
    .joints = {"cart position", "pole angle from the upward vertical"},
};

/* The model table's row (model.c). */
const lag_model_class lag_cartpole_model = {
    .info = &info,
    .doc = &doc,
    .mass = cp_mass,
    .mass_deriv = cp_mass_deriv,
    .coriolis = cp_coriolis,
    .gravity = cp_gravity,
    .mass_bias = cp_mass_bias,
    .forward = cp_forward,
    .kinetic = cp_kinetic,
    .potential = cp_potential,
};
