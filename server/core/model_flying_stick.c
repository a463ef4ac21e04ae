/*
 * The flying stick: the sliding stick's uniform stick (m, l, I, g), free in the plane. It
 * is a model of its own (a scene may name it: a stick thrown with no floor) and the one
 * the stick is simulated with when its floor lets it fly (the floor effect, flight on):
 * on the floor, its h is held at 0 (a resting stop), and then it is exactly the sliding
 * stick of model_stick.c.
 *
 * A free rigid body in the plane: centre of mass (x, y), angle phi,
 *   T = 1/2 m (x_dot^2 + y_dot^2) + 1/2 I phi_dot^2,   U = m g y,
 * with the stick's inputs as generalized forces (F_x on x, tau on phi). Its coordinates
 * are q = (x, phi, h), h the height of one end above the floor: end A at
 * r_c - a (cos phi, sin phi) (a = l/2; the end the sliding stick stands on, sigma = +1) or
 * end B at r_c + a (cos phi, sin phi) (sigma = -1), chosen by p[LAG_FSTICK_END] (0: A,
 * 1: B) for the model of the table; the floor, which switches ends while it runs, keeps
 * its end in the sim's state and integrates the two classes below (lag_flying_stick_ends),
 * the model's parameters untouched. So y = h + sigma a sin phi: the contact of that end with the floor is h = 0, a
 * coordinate at a stop, which the event engine holds, releases and hits; x and phi mean
 * what they mean for the sliding stick. The other end is at height h + sigma l sin phi.
 *   r_c = (x, h + sigma a s),  v_c = (x_dot, h_dot + sigma a c phi_dot),  omega = phi_dot
 *   T = 1/2 m x_dot^2 + 1/2 m (h_dot + sigma a c phi_dot)^2 + 1/2 I phi_dot^2
 *     = 1/2 m x_dot^2 + 1/2 (m a^2 c^2 + I) phi_dot^2 + sigma m a c phi_dot h_dot
 *       + 1/2 m h_dot^2
 *   U = m g (h + sigma a s)                           (c = cos phi, s = sin phi)
 * so, in the order (x, phi, h),
 *   M = [[m, 0, 0], [0, m a^2 c^2 + I, sigma m a c], [0, sigma m a c, m]].
 * Only derivatives in phi are non-zero: dM11/dphi = -2 m a^2 s c, dM12/dphi = dM21/dphi =
 * -sigma m a s. With D = dM/dphi the Christoffel form C_kj = sum_i c_ijk qd_i,
 * c_ijk = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k), reduces to
 * C_kj = 1/2 (D_kj phi_dot + [j = phi] sum_i D_ki qd_i - [k = phi] sum_i D_ij qd_i):
 *   C = [[0, 0, 0], [0, -m a^2 s c phi_dot, 0], [0, -sigma m a s phi_dot, 0]],
 *   g = dU/dq = (0, sigma m g a c, m g).
 * Lagrange's equations, M qdd + C qd + g = Q with Q = (F_x, tau, Q_h):
 *   m x_ddot = F_x
 *   (m a^2 c^2 + I) phi_ddot + sigma m a c h_ddot - m a^2 s c phi_dot^2 + sigma m g a c = tau
 *   sigma m a c phi_ddot + m h_ddot - sigma m a s phi_dot^2 + m g = Q_h
 * The last is m y_ddot = Q_h - m g (y_ddot = h_ddot + sigma a (c phi_ddot - s phi_dot^2));
 * taking sigma a c times it from the second leaves I phi_ddot = tau - sigma a c Q_h. In
 * closed form (the phi-h block has determinant m I, whatever phi):
 *   x_ddot = F_x / m,   phi_ddot = (tau - sigma a c Q_h) / I,
 *   h_ddot = Q_h / m - g + sigma a (s phi_dot^2 - c phi_ddot).
 * The first two are the free body's (the centre falls on a parabola, the angle turns at
 * tau / I), written without the terms that cancel, so that nothing of the centre's motion
 * leaks into phi through rounding.
 */
#include <math.h>
#include "core_internal.h"

#define P_M p[LAG_STICK_M]
#define P_L p[LAG_STICK_L]
#define P_I p[LAG_STICK_I]
#define P_G p[LAG_STICK_G]
/* sigma: +1 when h is end A's height, -1 for end B's (each function below takes it as
 * `sig`; the classes at the end fix it) */
#define SIG sig

static inline void fs_mass(double sig, const double *p, const double *q, double *M)
{
    double a = 0.5 * P_L, c = cos(q[1]);
    M[0] = P_M; M[1] = 0.0;                    M[2] = 0.0;
    M[3] = 0.0; M[4] = P_M * a * a * c * c + P_I; M[5] = SIG * P_M * a * c;
    M[6] = 0.0; M[7] = M[5];                   M[8] = P_M;
}

static inline void fs_mass_deriv(double sig, const double *p, const double *q, double *dM)
{
    double a = 0.5 * P_L, s = sin(q[1]), c = cos(q[1]);
    for (int i = 0; i < 27; i++) dM[i] = 0.0;
    /* block k = 1 (phi) starts at 9: entries (1,1), (1,2), (2,1) */
    dM[9 + 4] = -2.0 * P_M * a * a * s * c;
    dM[9 + 5] = dM[9 + 7] = -SIG * P_M * a * s;
}

static inline void fs_coriolis(double sig, const double *p, const double *q, const double *qd, double *C)
{
    double a = 0.5 * P_L, s = sin(q[1]), c = cos(q[1]);
    for (int i = 0; i < 9; i++) C[i] = 0.0;
    C[4] = -P_M * a * a * s * c * qd[1];
    C[7] = -SIG * P_M * a * s * qd[1];
}

static inline void fs_gravity(double sig, const double *p, const double *q, double *g)
{
    g[0] = 0.0;
    g[1] = SIG * P_M * P_G * 0.5 * P_L * cos(q[1]);
    g[2] = P_M * P_G;
}

static inline void fs_mass_bias(double sig, const double *p, const double *q, const double *qd, double *M,
                         double *h)
{
    double a = 0.5 * P_L, s, c;
    sincos(q[1], &s, &c);
    double w2 = qd[1] * qd[1];
    M[0] = P_M; M[1] = 0.0;                    M[2] = 0.0;
    M[3] = 0.0; M[4] = P_M * a * a * c * c + P_I; M[5] = SIG * P_M * a * c;
    M[6] = 0.0; M[7] = M[5];                   M[8] = P_M;
    h[0] = 0.0;
    h[1] = -P_M * a * a * s * c * w2 + SIG * P_M * P_G * a * c;
    h[2] = -SIG * P_M * a * s * w2 + P_M * P_G;
}

/* The closed form of the header; M is positive definite exactly when m a^2 c^2 + I > 0
 * (its leading minors are m, m (m a^2 c^2 + I) and m^2 I), the pivot tested (a NaN angle
 * fails it, as for the other models). */
static inline lag_result fs_forward(double sig, const double *p, const double *q, const double *qd,
                             const double *tau, double *qdd)
{
    double a = 0.5 * P_L, s, c;
    sincos(q[1], &s, &c);
    if (!(P_M * a * a * c * c + P_I > 0.0)) return LAG_ERR_SINGULAR;
    qdd[0] = tau[0] / P_M;
    const double sa = SIG * a;
    qdd[1] = (tau[1] - sa * c * tau[2]) / P_I;
    qdd[2] = tau[2] / P_M - P_G + sa * (s * qd[1] * qd[1] - c * qdd[1]);
    return LAG_OK;
}

static inline double fs_kinetic(double sig, const double *p, const double *q, const double *qd)
{
    double vy = qd[2] + SIG * 0.5 * P_L * cos(q[1]) * qd[1];
    return 0.5 * P_M * (qd[0] * qd[0] + vy * vy) + 0.5 * P_I * qd[1] * qd[1];
}

static inline double fs_potential(double sig, const double *p, const double *q)
{
    return P_M * P_G * (q[2] + SIG * 0.5 * P_L * sin(q[1]));
}

/* The class's functions for one sigma expression S (of p): SUFFIX names them. */
#define FS_CLASS_FUNCS(SUFFIX, S)                                                          \
    static void mass##SUFFIX(const double *p, const double *q, double *M)                 \
    { fs_mass(S, p, q, M); }                                                               \
    static void mass_deriv##SUFFIX(const double *p, const double *q, double *dM)          \
    { fs_mass_deriv(S, p, q, dM); }                                                        \
    static void coriolis##SUFFIX(const double *p, const double *q, const double *qd,      \
                                 double *C)                                                \
    { fs_coriolis(S, p, q, qd, C); }                                                       \
    static void gravity##SUFFIX(const double *p, const double *q, double *g)              \
    { fs_gravity(S, p, q, g); }                                                            \
    static void mass_bias##SUFFIX(const double *p, const double *q, const double *qd,     \
                                  double *M, double *h)                                    \
    { fs_mass_bias(S, p, q, qd, M, h); }                                                   \
    static lag_result forward##SUFFIX(const double *p, const double *q, const double *qd, \
                                      const double *tau, double *qdd)                      \
    { return fs_forward(S, p, q, qd, tau, qdd); }                                          \
    static double kinetic##SUFFIX(const double *p, const double *q, const double *qd)     \
    { return fs_kinetic(S, p, q, qd); }                                                    \
    static double potential##SUFFIX(const double *p, const double *q)                     \
    { return fs_potential(S, p, q); }
#define FS_CLASS(SUFFIX)                                                                   \
    {.info = &info, .doc = &doc, .mass = mass##SUFFIX, .mass_deriv = mass_deriv##SUFFIX,  \
     .coriolis = coriolis##SUFFIX, .gravity = gravity##SUFFIX,                             \
     .mass_bias = mass_bias##SUFFIX, .forward = forward##SUFFIX,                           \
     .kinetic = kinetic##SUFFIX, .potential = potential##SUFFIX}

/* the table's model: the end p[LAG_FSTICK_END] names; the floor's: end A, end B */
FS_CLASS_FUNCS(_p, (p[LAG_FSTICK_END] != 0.0 ? -1.0 : 1.0))
FS_CLASS_FUNCS(_a, 1.0)
FS_CLASS_FUNCS(_b, -1.0)

static const lag_model_info info = {
    .name = "flying-stick",
    .nq = 3,
    LAG_STICK_PARAMS_INFO,
    .joint_names = {"x", "phi", "h"},
    .actuated = {true, true, false},
    .angular = {false, true, false},
};

static const lag_model_doc doc = {
    .title = "flying stick",
    .summary = "the stick free in the plane",
    LAG_STICK_PARAMS_DOC,
    .joints = {"horizontal position of the centre of mass", "angle between stick and floor",
               "height of end A above the floor (the stick's floor, flying it, switches ends)"},
};

/* The model table's row (model.c). */
const lag_model_class lag_flying_stick_model = FS_CLASS(_p);

/* The flying stick measured from end A and from end B, whatever p[LAG_FSTICK_END] says:
 * the floor's (effect_floor.c), indexed by the end h measures. */
const lag_model_class lag_flying_stick_ends[2] = {FS_CLASS(_a), FS_CLASS(_b)};
