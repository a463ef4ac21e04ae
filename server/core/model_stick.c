/*
 * Sliding stick on a frictionless floor (docs/models.md). q = (x, phi):
 * x the horizontal position of the centre of mass, phi the angle between stick and floor.
 *   r_c = (x, (l/2) sin phi),  omega = phi_dot
 *   T = 1/2 m (x_dot^2 + (l^2/4) phi_dot^2 cos^2 phi) + 1/2 I phi_dot^2
 *   U = m g (l/2) sin phi
 * Hence M = diag(m, m l^2/4 cos^2 phi + I); only dM_11/dphi = -(m l^2/2) sin phi cos phi
 * is non-zero, so the only Christoffel symbol is c_111 = 1/2 dM_11/dphi and
 *   C = [[0, 0], [0, -(m l^2/4) sin phi cos phi phi_dot]],
 *   g = (0, m g (l/2) cos phi).
 * (Index 1 = phi.) This matches the course assignment's equation of motion for Problem 1 (d).
 */
#include <math.h>
#include "core_internal.h"

#define P_M p[LAG_STICK_M]
#define P_L p[LAG_STICK_L]
#define P_I p[LAG_STICK_I]
#define P_G p[LAG_STICK_G]

static void stick_mass(const double *p, const double *q, double *M)
{
    double c = cos(q[1]);
    M[0] = P_M; M[1] = 0.0;
    M[2] = 0.0; M[3] = 0.25 * P_M * P_L * P_L * c * c + P_I;
}

static void stick_mass_deriv(const double *p, const double *q, double *dM)
{
    for (int i = 0; i < 8; i++) dM[i] = 0.0;
    /* d/dphi (m l^2/4 cos^2 phi) = -(m l^2 / 2) sin phi cos phi; block k = 1 starts at 4 */
    dM[4 + 3] = -0.5 * P_M * P_L * P_L * sin(q[1]) * cos(q[1]);
}

static void stick_coriolis(const double *p, const double *q, const double *qd, double *C)
{
    C[0] = 0.0; C[1] = 0.0; C[2] = 0.0;
    C[3] = -0.25 * P_M * P_L * P_L * sin(q[1]) * cos(q[1]) * qd[1];
}

static void stick_gravity(const double *p, const double *q, double *g)
{
    g[0] = 0.0;
    g[1] = 0.5 * P_M * P_G * P_L * cos(q[1]);
}

static void stick_mass_bias(const double *p, const double *q, const double *qd, double *M,
                            double *h)
{
    double s = sin(q[1]), c = cos(q[1]);
    double a = 0.25 * P_M * P_L * P_L;
    M[0] = P_M; M[1] = 0.0;
    M[2] = 0.0; M[3] = a * c * c + P_I;
    h[0] = 0.0;
    h[1] = -a * s * c * qd[1] * qd[1] + 0.5 * P_M * P_G * P_L * c;
}

/* M is diagonal: x_ddot = F_x / m, phi_ddot = (tau_phi - h_phi) / M_11. */
static lag_result stick_forward(const double *p, const double *q, const double *qd,
                                const double *tau, double *qdd)
{
    double s, c;
    sincos(q[1], &s, &c);
    double a = 0.25 * P_M * P_L * P_L;
    double m11 = a * c * c + P_I;
    if (!(m11 > 0.0)) return LAG_ERR_SINGULAR;
    qdd[0] = tau[0] / P_M;
    qdd[1] = (tau[1] + a * s * c * qd[1] * qd[1] - 0.5 * P_M * P_G * P_L * c) / m11;
    return LAG_OK;
}

static double stick_kinetic(const double *p, const double *q, const double *qd)
{
    double c = cos(q[1]);
    return 0.5 * P_M * (qd[0] * qd[0] + 0.25 * P_L * P_L * qd[1] * qd[1] * c * c)
         + 0.5 * P_I * qd[1] * qd[1];
}

static double stick_potential(const double *p, const double *q)
{
    return P_M * P_G * 0.5 * P_L * sin(q[1]);
}

static const lag_model_info info = {
    .name = "stick",
    .nq = 2,
    LAG_STICK_PARAMS_INFO,
    .joint_names = {"x", "phi"},
    .actuated = {true, true},
    .angular = {false, true},
};

static const lag_model_doc doc = {
    .title = "sliding stick",
    .summary = "a stick sliding on a frictionless floor",
    LAG_STICK_PARAMS_DOC,
    .joints = {"horizontal position of the centre of mass", "angle between stick and floor"},
};

/* The model table's row (model.c). */
const lag_model_class lag_stick_model = {
    .info = &info,
    .doc = &doc,
    .mass = stick_mass,
    .mass_deriv = stick_mass_deriv,
    .coriolis = stick_coriolis,
    .gravity = stick_gravity,
    .mass_bias = stick_mass_bias,
    .forward = stick_forward,
    .kinetic = stick_kinetic,
    .potential = stick_potential,
};
