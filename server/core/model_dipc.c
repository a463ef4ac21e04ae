/*
 * Double inverted pendulum on a cart (docs/models.md). q = (theta0, theta1, theta2):
 * cart position, and the two rods' absolute angles from the upward vertical.
 *   r_1 = (theta0 + a1 s1, h0 + a1 c1),  a1 = l1/2
 *   r_2 = (theta0 + l1 s1 + a2 s2, h0 + l1 c1 + a2 c2),  a2 = l2/2
 *   T = 1/2 m0 th0d^2 + sum_i (1/2 m_i |v_i|^2 + 1/2 I_i th_id^2),  U = m1 g y1 + m2 g y2
 * Expanding |v_i|^2 gives T = 1/2 qd^T M qd with
 *   M00 = m0 + m1 + m2          M01 = k1 c1           M02 = k2 c2
 *   M11 = m1 a1^2 + m2 l1^2 + I1                      M12 = k3 cos(th1 - th2)
 *   M22 = m2 a2^2 + I2
 *   k1 = m1 a1 + m2 l1,  k2 = m2 a2,  k3 = m2 l1 a2.
 * The non-zero derivatives are dM01/dth1 = -k1 s1, dM02/dth2 = -k2 s2,
 * dM12/dth1 = -k3 s12, dM12/dth2 = +k3 s12 (s12 = sin(th1 - th2)), so the Christoffel
 * symbols c_ijk = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k) give
 *   C = [[0, -k1 s1 th1d, -k2 s2 th2d],
 *        [0,  0,           k3 s12 th2d],
 *        [0, -k3 s12 th1d, 0         ]]
 *   g = dU/dq = (0, -k1 g s1, -k2 g s2).
 */
#include <math.h>
#include "core_internal.h"

typedef struct dipc_k {
    double mt, k1, k2, k3, J1, J2;
} dipc_k;

/* The constant coefficients of M from the parameters. */
static inline dipc_k dipc_coeffs(const double *p)
{
    double m1 = p[LAG_DIPC_M1], m2 = p[LAG_DIPC_M2];
    double l1 = p[LAG_DIPC_L1], a1 = 0.5 * l1, a2 = 0.5 * p[LAG_DIPC_L2];
    dipc_k k;
    k.mt = p[LAG_DIPC_M0] + m1 + m2;
    k.k1 = m1 * a1 + m2 * l1;
    k.k2 = m2 * a2;
    k.k3 = m2 * l1 * a2;
    k.J1 = m1 * a1 * a1 + m2 * l1 * l1 + p[LAG_DIPC_I1];
    k.J2 = m2 * a2 * a2 + p[LAG_DIPC_I2];
    return k;
}

static void dipc_mass(const double *p, const double *q, double *M)
{
    dipc_k k = dipc_coeffs(p);
    double c1 = cos(q[1]), c2 = cos(q[2]), c12 = cos(q[1] - q[2]);
    M[0] = k.mt;      M[1] = k.k1 * c1;   M[2] = k.k2 * c2;
    M[3] = M[1];      M[4] = k.J1;        M[5] = k.k3 * c12;
    M[6] = M[2];      M[7] = M[5];        M[8] = k.J2;
}

static void dipc_mass_deriv(const double *p, const double *q, double *dM)
{
    dipc_k k = dipc_coeffs(p);
    double s1 = sin(q[1]), s2 = sin(q[2]), s12 = sin(q[1] - q[2]);
    for (int i = 0; i < 27; i++) dM[i] = 0.0;
    /* k = 1 (theta1): block at 9 */
    dM[9 + 1] = dM[9 + 3] = -k.k1 * s1;
    dM[9 + 5] = dM[9 + 7] = -k.k3 * s12;
    /* k = 2 (theta2): block at 18 */
    dM[18 + 2] = dM[18 + 6] = -k.k2 * s2;
    dM[18 + 5] = dM[18 + 7] = k.k3 * s12;
}

static void dipc_coriolis(const double *p, const double *q, const double *qd, double *C)
{
    dipc_k k = dipc_coeffs(p);
    double s1 = sin(q[1]), s2 = sin(q[2]), s12 = sin(q[1] - q[2]);
    C[0] = 0.0; C[1] = -k.k1 * s1 * qd[1];  C[2] = -k.k2 * s2 * qd[2];
    C[3] = 0.0; C[4] = 0.0;                 C[5] = k.k3 * s12 * qd[2];
    C[6] = 0.0; C[7] = -k.k3 * s12 * qd[1]; C[8] = 0.0;
}

static void dipc_gravity(const double *p, const double *q, double *g)
{
    dipc_k k = dipc_coeffs(p);
    double gr = p[LAG_DIPC_G];
    g[0] = 0.0;
    g[1] = -k.k1 * gr * sin(q[1]);
    g[2] = -k.k2 * gr * sin(q[2]);
}

/* The step's hot path: M and h = C qd + g with one sincos per angle. */
static inline __attribute__((always_inline)) void
dipc_mass_bias_inl(const double *p, const double *q, const double *qd, double *M, double *h)
{
    dipc_k k = dipc_coeffs(p);
    double s1, c1, s2, c2;
    sincos(q[1], &s1, &c1);
    sincos(q[2], &s2, &c2);
    double c12 = c1 * c2 + s1 * s2, s12 = s1 * c2 - c1 * s2;
    double gr = p[LAG_DIPC_G];
    M[0] = k.mt;      M[1] = k.k1 * c1;   M[2] = k.k2 * c2;
    M[3] = M[1];      M[4] = k.J1;        M[5] = k.k3 * c12;
    M[6] = M[2];      M[7] = M[5];        M[8] = k.J2;
    double w1 = qd[1] * qd[1], w2 = qd[2] * qd[2];
    h[0] = -k.k1 * s1 * w1 - k.k2 * s2 * w2;
    h[1] = k.k3 * s12 * w2 - k.k1 * gr * s1;
    h[2] = -k.k3 * s12 * w1 - k.k2 * gr * s2;
}

/* M qdd = tau - h with M and h as in dipc_mass_bias, solved by LDL^T written out for
 * this M (M00 is constant). */
static lag_result dipc_forward(const double *p, const double *q, const double *qd,
                               const double *tau, double *qdd)
{
    double M[9], h[3];
    dipc_mass_bias_inl(p, q, qd, M, h);
    double r[3] = {tau[0] - h[0], tau[1] - h[1], tau[2] - h[2]};
    return lag_spd_solve3(M, r, qdd);
}

static void dipc_mass_bias(const double *p, const double *q, const double *qd, double *M,
                           double *h)
{
    dipc_mass_bias_inl(p, q, qd, M, h);
}

static double dipc_kinetic(const double *p, const double *q, const double *qd)
{
    double M[9];
    dipc_mass(p, q, M);
    double T = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) T += qd[i] * M[3 * i + j] * qd[j];
    return 0.5 * T;
}

static double dipc_potential(const double *p, const double *q)
{
    double m1 = p[LAG_DIPC_M1], m2 = p[LAG_DIPC_M2], l1 = p[LAG_DIPC_L1];
    double h0 = p[LAG_DIPC_H0], gr = p[LAG_DIPC_G];
    double y1 = h0 + 0.5 * l1 * cos(q[1]);
    double y2 = h0 + l1 * cos(q[1]) + 0.5 * p[LAG_DIPC_L2] * cos(q[2]);
    return m1 * gr * y1 + m2 * gr * y2;
}

static const lag_model_info info = {
    .name = "dipc",
    .nq = 3,
    .np = LAG_DIPC_NP,
    .param_names = {"m0", "m1", "m2", "l1", "l2", "I1", "I2", "g", "h0"},
    .param_defaults = {1.5, 0.5, 0.75, 0.5, 0.75, NAN, NAN, 9.81, 0.0},
    .param_units = {"kg", "kg", "kg", "m", "m", "kg m^2", "kg m^2", "m/s^2", "m"},
    .param_rules = {[LAG_DIPC_G] = LAG_PARAM_NONNEGATIVE, [LAG_DIPC_H0] = LAG_PARAM_ANY},
    .n_rods = 2,
    .rods = {{LAG_DIPC_I1, LAG_DIPC_M1, LAG_DIPC_L1}, {LAG_DIPC_I2, LAG_DIPC_M2, LAG_DIPC_L2}},
    .joint_names = {"theta0", "theta1", "theta2"},
    .actuated = {true, false, false},
    .angular = {false, true, true},
};

static const lag_model_doc doc = {
    .title = "double inverted pendulum on a cart (DIPC)",
    .summary = "a double inverted pendulum on a cart",
    .params = {"cart mass", "lower rod mass", "upper rod mass", "lower rod length",
               "upper rod length", "lower rod inertia about its centre",
               "upper rod inertia about its centre", "gravity",
               "height of the lower pivot above the track"},
    .joints = {"cart position", "lower rod angle from the upward vertical",
               "upper rod angle from the upward vertical (absolute, not from the lower rod)"},
};

/* The model table's row (model.c). */
const lag_model_class lag_dipc_model = {
    .info = &info,
    .doc = &doc,
    .mass = dipc_mass,
    .mass_deriv = dipc_mass_deriv,
    .coriolis = dipc_coriolis,
    .gravity = dipc_gravity,
    .mass_bias = dipc_mass_bias,
    .forward = dipc_forward,
    .kinetic = dipc_kinetic,
    .potential = dipc_potential,
};
