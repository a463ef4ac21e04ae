/*
 * Rotary/prismatic manipulator (docs/models.md). q = (q1, q2): q1 the angle of arm 1
 * from the horizontal, q2 the distance of arm 2's centre of mass from the axis.
 *   r_c1 = l1 (cos q1, sin q1), r_c2 = q2 (cos q1, sin q1), omega = q1_dot for both
 *   T = 1/2 m1 l1^2 q1d^2 + 1/2 m2 (q2^2 q1d^2 + q2d^2) + 1/2 (I1 + I2) q1d^2
 *   U = (m1 l1 + m2 q2) g sin q1
 * Hence M = diag(m1 l1^2 + I1 + I2 + m2 q2^2, m2), dM_00/dq2 = 2 m2 q2 the only
 * derivative, and the Christoffel form (the course assignment's (5)):
 *   C = [[m2 q2 q2d, m2 q2 q1d], [-m2 q2 q1d, 0]],
 *   g = ((m1 l1 + m2 q2) g cos q1, m2 g sin q1).
 */
#include <math.h>
#include "core_internal.h"

#define P_M1 p[LAG_MANIP_M1]
#define P_M2 p[LAG_MANIP_M2]
#define P_L1 p[LAG_MANIP_L1]
#define P_I1 p[LAG_MANIP_I1]
#define P_I2 p[LAG_MANIP_I2]
#define P_G p[LAG_MANIP_G]

static void manip_mass(const double *p, const double *q, double *M)
{
    M[0] = P_M1 * P_L1 * P_L1 + P_I1 + P_I2 + P_M2 * q[1] * q[1]; M[1] = 0.0;
    M[2] = 0.0;                                                  M[3] = P_M2;
}

static void manip_mass_deriv(const double *p, const double *q, double *dM)
{
    for (int i = 0; i < 8; i++) dM[i] = 0.0;
    dM[4 + 0] = 2.0 * P_M2 * q[1]; /* d M_00 / d q2 */
}

static void manip_coriolis(const double *p, const double *q, const double *qd, double *C)
{
    double a = P_M2 * q[1];
    C[0] = a * qd[1];  C[1] = a * qd[0];
    C[2] = -a * qd[0]; C[3] = 0.0;
}

static void manip_gravity(const double *p, const double *q, double *g)
{
    g[0] = (P_M1 * P_L1 + P_M2 * q[1]) * P_G * cos(q[0]);
    g[1] = P_M2 * P_G * sin(q[0]);
}

static void manip_mass_bias(const double *p, const double *q, const double *qd, double *M,
                            double *h)
{
    double s = sin(q[0]), c = cos(q[0]);
    double a = P_M2 * q[1];
    manip_mass(p, q, M);
    /* C qd = (2 m2 q2 q1d q2d, -m2 q2 q1d^2) */
    h[0] = 2.0 * a * qd[0] * qd[1] + (P_M1 * P_L1 + a) * P_G * c;
    h[1] = -a * qd[0] * qd[0] + P_M2 * P_G * s;
}

/* M is diagonal: the two equations decouple given q, qd. */
static lag_result manip_forward(const double *p, const double *q, const double *qd,
                                const double *tau, double *qdd)
{
    double s, c;
    sincos(q[0], &s, &c);
    double a = P_M2 * q[1];
    double m00 = P_M1 * P_L1 * P_L1 + P_I1 + P_I2 + a * q[1];
    if (!(m00 > 0.0)) return LAG_ERR_SINGULAR;
    qdd[0] = (tau[0] - 2.0 * a * qd[0] * qd[1] - (P_M1 * P_L1 + a) * P_G * c) / m00;
    qdd[1] = (tau[1] + a * qd[0] * qd[0] - P_M2 * P_G * s) / P_M2;
    return LAG_OK;
}

static double manip_kinetic(const double *p, const double *q, const double *qd)
{
    return 0.5 * P_M1 * P_L1 * P_L1 * qd[0] * qd[0]
         + 0.5 * P_M2 * (q[1] * q[1] * qd[0] * qd[0] + qd[1] * qd[1])
         + 0.5 * (P_I1 + P_I2) * qd[0] * qd[0];
}

static double manip_potential(const double *p, const double *q)
{
    return (P_M1 * P_L1 + P_M2 * q[1]) * P_G * sin(q[0]);
}

static const lag_model_info info = {
    .name = "manipulator",
    .nq = 2,
    .np = LAG_MANIP_NP,
    .param_names = {"m1", "m2", "l1", "I1", "I2", "g"},
    .param_defaults = {2.0, 1.0, 0.3, 0.02, 0.05, 9.81},
    .param_units = {"kg", "kg", "m", "kg m^2", "kg m^2", "m/s^2"},
    .param_rules = {[LAG_MANIP_G] = LAG_PARAM_NONNEGATIVE},
    .joint_names = {"q1", "q2"},
    .actuated = {true, true},
    .angular = {true, false},
};

static const lag_model_doc doc = {
    .title = "rotary/prismatic manipulator",
    .summary = "a revolute arm with a prismatic arm along it",
    .params = {"arm 1 mass", "arm 2 mass", "axis to arm 1's centre of mass",
               "arm 1 inertia about its centre of mass", "arm 2 inertia about its centre of mass",
               "gravity"},
    .joints = {"arm 1 angle from the horizontal",
               "distance of arm 2's centre of mass from the axis"},
};

/* The model table's row (model.c). */
const lag_model_class lag_manipulator_model = {
    .info = &info,
    .doc = &doc,
    .mass = manip_mass,
    .mass_deriv = manip_mass_deriv,
    .coriolis = manip_coriolis,
    .gravity = manip_gravity,
    .mass_bias = manip_mass_bias,
    .forward = manip_forward,
    .kinetic = manip_kinetic,
    .potential = manip_potential,
};
