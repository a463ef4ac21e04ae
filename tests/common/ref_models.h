/*
 * The tests' own models: each written again from its body kinematics, with no code of the
 * core (only its parameter values, looked up by name, and its names for the models).
 *
 * For each model: the bodies' centres of mass r_c(q), their velocities v_c = d r_c / dt
 * written out by the chain rule, the bodies' angular velocities omega, masses and
 * inertias, and its potential energy U as a function of q and those bodies. From these
 * alone
 *     T = sum_b 1/2 m_b v_b . v_b + 1/2 I_b omega_b^2,   U = the row's potential,
 * in complex arithmetic, so that tests/core/test_core.h can take derivatives by complex
 * steps, and tests/effects can read energies and momenta. A model whose only potential is
 * gravity names tc_U_gravity (sum_b m_b g y_b); one with more (a spring in a joint, a
 * magnet...) writes its own, e.g. tc_U_gravity plus 1/2 k q_i^2, and its parameters (a
 * stiffness in N m/rad or N/m) get random values as masses do (test_core.h).
 *
 * One row per model of the core's table (tc_refs, indexed by kind): a model without its
 * row does not build, and a kind asked for that has none, or whose row lacks its
 * kinematics or its potential, stops the test (abort), never falls back on another
 * model's. A row also gives a smooth unforced motion (the conservation and convergence
 * tests run it) and the positions where the structure tests start their random motions.
 */
#ifndef LAGSIM_REF_MODELS_H
#define LAGSIM_REF_MODELS_H

#include <complex.h>
/* glibc defines CMPLX only where the compiler has __builtin_complex (not clang 14). C11
 * lays a double complex out as double[2], which this fallback fills exactly (x + I*y
 * would not be exact for infinite or NaN parts). */
#ifndef CMPLX
static inline double complex lag_test_cmplx(double re, double im)
{
    union { double complex z; double d[2]; } u = {.d = {re, im}};
    return u.z;
}
#define CMPLX(x, y) lag_test_cmplx((x), (y))
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"

/* complex.h defines I; the inertias are called I, so the macro must go. */
#undef I
typedef double complex cplx;

#define TC_PI 3.14159265358979323846
#define TC_MAX_BODIES 4

/* The bodies of a model at (q, qd): centre of mass (x, y), its velocity (vx, vy), angular
 * velocity w, mass, inertia about the centre of mass. */
typedef struct tc_bodies {
    int nb;
    double mass[TC_MAX_BODIES], inertia[TC_MAX_BODIES];
    cplx x[TC_MAX_BODIES], y[TC_MAX_BODIES], vx[TC_MAX_BODIES], vy[TC_MAX_BODIES], w[TC_MAX_BODIES];
} tc_bodies;

/* Parameter `name` of m (by the core's name for it; a missing one stops the test). */
static inline double tc_p(const lag_model *m, const char *name)
{
    int i = lag_model_param_index(m->kind, name);
    if (i < 0) {
        fprintf(stderr, "model %s has no parameter %s\n", lag_model_info_get(m->kind)->name, name);
        abort();
    }
    return m->p[i];
}

/* ------------------------------------------------------------------ the models */

/* Sliding stick: r_c = (x, (l/2) sin phi), omega = phi_dot. */
static inline void tc_kin_stick(const lag_model *m, const cplx *q, const cplx *qd, tc_bodies *b)
{
    double l = tc_p(m, "l");
    b->nb = 1;
    b->mass[0] = tc_p(m, "m");
    b->inertia[0] = tc_p(m, "I");
    b->x[0] = q[0];
    b->y[0] = 0.5 * l * csin(q[1]);
    b->vx[0] = qd[0];
    b->vy[0] = 0.5 * l * ccos(q[1]) * qd[1];
    b->w[0] = qd[1];
}

/* Manipulator: r_c1 = l1 (cos q1, sin q1), r_c2 = q2 (cos q1, sin q1), omega = q1_dot for
 * both arms. */
static inline void tc_kin_manipulator(const lag_model *m, const cplx *q, const cplx *qd, tc_bodies *b)
{
    double l1 = tc_p(m, "l1");
    cplx c = ccos(q[0]), s = csin(q[0]);
    b->nb = 2;
    b->mass[0] = tc_p(m, "m1");
    b->mass[1] = tc_p(m, "m2");
    b->inertia[0] = tc_p(m, "I1");
    b->inertia[1] = tc_p(m, "I2");
    b->x[0] = l1 * c;
    b->y[0] = l1 * s;
    b->vx[0] = -l1 * s * qd[0];
    b->vy[0] = l1 * c * qd[0];
    b->w[0] = qd[0];
    b->x[1] = q[1] * c;
    b->y[1] = q[1] * s;
    b->vx[1] = qd[1] * c - q[1] * s * qd[0];
    b->vy[1] = qd[1] * s + q[1] * c * qd[0];
    b->w[1] = qd[0];
}

/* DIPC: r_0 = (theta0, 0); r_1 = (theta0 + l1/2 sin th1, h0 + l1/2 cos th1);
 * r_2 = (theta0 + l1 sin th1 + l2/2 sin th2, h0 + l1 cos th1 + l2/2 cos th2);
 * the cart does not rotate, rod i turns at theta_i_dot. */
static inline void tc_kin_dipc(const lag_model *m, const cplx *q, const cplx *qd, tc_bodies *b)
{
    double l1 = tc_p(m, "l1"), l2 = tc_p(m, "l2"), h0 = tc_p(m, "h0");
    cplx s1 = csin(q[1]), c1 = ccos(q[1]), s2 = csin(q[2]), c2 = ccos(q[2]);
    b->nb = 3;
    b->mass[0] = tc_p(m, "m0");
    b->mass[1] = tc_p(m, "m1");
    b->mass[2] = tc_p(m, "m2");
    b->inertia[0] = 0;
    b->inertia[1] = tc_p(m, "I1");
    b->inertia[2] = tc_p(m, "I2");
    b->x[0] = q[0];
    b->y[0] = 0;
    b->vx[0] = qd[0];
    b->vy[0] = 0;
    b->w[0] = 0;
    b->x[1] = q[0] + 0.5 * l1 * s1;
    b->y[1] = h0 + 0.5 * l1 * c1;
    b->vx[1] = qd[0] + 0.5 * l1 * c1 * qd[1];
    b->vy[1] = -0.5 * l1 * s1 * qd[1];
    b->w[1] = qd[1];
    b->x[2] = q[0] + l1 * s1 + 0.5 * l2 * s2;
    b->y[2] = h0 + l1 * c1 + 0.5 * l2 * c2;
    b->vx[2] = qd[0] + l1 * c1 * qd[1] + 0.5 * l2 * c2 * qd[2];
    b->vy[2] = -l1 * s1 * qd[1] - 0.5 * l2 * s2 * qd[2];
    b->w[2] = qd[2];
}

/* Cart-pole: r_0 = (x, 0), the cart does not rotate; r_1 = (x + l1/2 sin th,
 * l1/2 cos th), the rod turns at theta_dot. */
static inline void tc_kin_cartpole(const lag_model *m, const cplx *q, const cplx *qd, tc_bodies *b)
{
    double a = 0.5 * tc_p(m, "l1");
    cplx s = csin(q[1]), c = ccos(q[1]);
    b->nb = 2;
    b->mass[0] = tc_p(m, "m0");
    b->mass[1] = tc_p(m, "m1");
    b->inertia[0] = 0;
    b->inertia[1] = tc_p(m, "I1");
    b->x[0] = q[0];
    b->y[0] = 0;
    b->vx[0] = qd[0];
    b->vy[0] = 0;
    b->w[0] = 0;
    b->x[1] = q[0] + a * s;
    b->y[1] = a * c;
    b->vx[1] = qd[0] + a * c * qd[1];
    b->vy[1] = -a * s * qd[1];
    b->w[1] = qd[1];
}

/* Flying stick: the stick free in the plane; h is the height of one end E (end A at
 * r_c - l/2 (cos phi, sin phi), sigma = +1, or end B at r_c + l/2 (cos phi, sin phi),
 * sigma = -1, chosen by p[LAG_FSTICK_END]), so r_c = (x, h + sigma (l/2) sin phi):
 * E's height plus the rise from E to the centre. omega = phi_dot. */
static inline void tc_kin_flying_stick(const lag_model *m, const cplx *q, const cplx *qd, tc_bodies *b)
{
    double l = tc_p(m, "l"), sigma = m->p[LAG_FSTICK_END] != 0.0 ? -1.0 : 1.0;
    b->nb = 1;
    b->mass[0] = tc_p(m, "m");
    b->inertia[0] = tc_p(m, "I");
    b->x[0] = q[0];
    b->y[0] = q[2] + sigma * 0.5 * l * csin(q[1]);
    b->vx[0] = qd[0];
    b->vy[0] = qd[2] + sigma * 0.5 * l * ccos(q[1]) * qd[1];
    b->w[0] = qd[1];
}

/* ------------------------------------------------------------------ potentials */

/* U = sum_b m_b g y_b: gravity on the bodies (at q: b holds them there). */
static inline cplx tc_U_gravity(const lag_model *m, const cplx *q, const tc_bodies *b)
{
    (void)q;
    cplx U = 0;
    double g = tc_p(m, "g");
    for (int i = 0; i < b->nb; ++i) U += b->mass[i] * g * b->y[i];
    return U;
}

/* ------------------------------------------------------------------ the table */
typedef struct tc_ref {
    void (*kinematics)(const lag_model *m, const cplx *q, const cplx *qd, tc_bodies *b);
    /* U(q), written from the bodies at q (b) and the model's own stored energies */
    cplx (*potential)(const lag_model *m, const cplx *q, const tc_bodies *b);
    /* A smooth unforced motion with the model's default parameters: start, horizon T (s,
     * a multiple of 1 ms; short enough that the tests' coarsest steps resolve it). */
    double q0[LAG_MAX_DOF], qd0[LAG_MAX_DOF], T;
    /* Where the structure tests' random motions start: q_i in [qlo_i, qhi_i]. */
    double qlo[LAG_MAX_DOF], qhi[LAG_MAX_DOF];
} tc_ref;

static const tc_ref tc_refs[] = {
    /* the stick falls from 1.2 rad to near the floor (0.4 s) while sliding at 0.5 m/s */
    [LAG_MODEL_STICK] = {.kinematics = tc_kin_stick, .potential = tc_U_gravity,
                         .q0 = {0.0, 1.2}, .qd0 = {0.5, 0.0}, .T = 0.4,
                         .qlo = {-2, 0.3}, .qhi = {2, 1.3}},
    /* the arm swings below the horizontal with the slider moving in */
    [LAG_MODEL_MANIPULATOR] = {.kinematics = tc_kin_manipulator, .potential = tc_U_gravity,
                               .q0 = {-TC_PI / 2 + 0.4, 0.5}, .qd0 = {0.0, -0.3}, .T = 1.0,
                               .qlo = {-TC_PI, 0.3}, .qhi = {TC_PI, 1.0}},
    /* both rods hanging and swinging, the cart free */
    [LAG_MODEL_DIPC] = {.kinematics = tc_kin_dipc, .potential = tc_U_gravity,
                        .q0 = {0.0, TC_PI + 0.3, TC_PI - 0.2}, .qd0 = {0.0, 0.0, 0.0}, .T = 1.0,
                        .qlo = {-2, -TC_PI, -TC_PI}, .qhi = {2, TC_PI, TC_PI}},
    /* the pole hanging and swinging, the cart free */
    [LAG_MODEL_CARTPOLE] = {.kinematics = tc_kin_cartpole, .potential = tc_U_gravity,
                            .q0 = {0.0, TC_PI + 0.5}, .qd0 = {0.2, 0.0}, .T = 1.0,
                            .qlo = {-2, -TC_PI}, .qhi = {2, TC_PI}},
    /* thrown up spinning, no floor: the centre on its parabola, the angle turning */
    [LAG_MODEL_FLYING_STICK] = {.kinematics = tc_kin_flying_stick, .potential = tc_U_gravity,
                                .q0 = {0.0, 0.3, 1.0}, .qd0 = {0.5, 3.0, 2.0}, .T = 1.0,
                                .qlo = {-2, -TC_PI, 0.0}, .qhi = {2, TC_PI, 2.0}},
};
_Static_assert(sizeof tc_refs / sizeof tc_refs[0] == LAG_MODEL_COUNT,
               "tests/common/ref_models.h needs a reference row for every model of the core");

/* The reference of a kind; stops the test if it has none. */
static inline const tc_ref *tc_ref_of(lag_model_kind kind)
{
    if ((int)kind < 0 || kind >= LAG_MODEL_COUNT || !tc_refs[kind].kinematics ||
        !tc_refs[kind].potential) {
        fprintf(stderr, "no reference kinematics and potential for model kind %d: add a row "
                        "with both to tests/common/ref_models.h\n", (int)kind);
        abort();
    }
    return &tc_refs[kind];
}

static inline void tc_kinematics(const lag_model *m, const cplx *q, const cplx *qd, tc_bodies *b)
{
    memset(b, 0, sizeof *b);
    tc_ref_of(m->kind)->kinematics(m, q, qd, b);
}

/* T = sum 1/2 m v.v + 1/2 I w^2 (no conjugates: analytic in q and qd). */
static inline cplx tc_T_c(const lag_model *m, const cplx *q, const cplx *qd)
{
    tc_bodies b;
    tc_kinematics(m, q, qd, &b);
    cplx T = 0;
    for (int i = 0; i < b.nb; ++i)
        T += 0.5 * b.mass[i] * (b.vx[i] * b.vx[i] + b.vy[i] * b.vy[i]) +
             0.5 * b.inertia[i] * b.w[i] * b.w[i];
    return T;
}

/* U(q): the row's potential, from the bodies at q. */
static inline cplx tc_U_c(const lag_model *m, const cplx *q)
{
    cplx zero[LAG_MAX_DOF] = {0};
    tc_bodies b;
    tc_kinematics(m, q, zero, &b);
    return tc_ref_of(m->kind)->potential(m, q, &b);
}

static inline void tc_to_c(int n, const double *x, cplx *z)
{
    for (int i = 0; i < n; ++i) z[i] = x[i];
}

static inline double tc_T(const lag_model *m, const double *q, const double *qd)
{
    cplx qc[LAG_MAX_DOF] = {0}, qdc[LAG_MAX_DOF] = {0};
    tc_to_c(m->nq, q, qc);
    tc_to_c(m->nq, qd, qdc);
    return creal(tc_T_c(m, qc, qdc));
}

static inline double tc_U(const lag_model *m, const double *q)
{
    cplx qc[LAG_MAX_DOF] = {0};
    tc_to_c(m->nq, q, qc);
    return creal(tc_U_c(m, qc));
}

/* Generalized momentum p_i = dT/dqd_i from T alone: T is quadratic in qd, so
 * (T(qd + e_i) - T(qd - e_i)) / 2 = (M qd)_i exactly, up to rounding. */
static inline double tc_momentum(const lag_model *m, const double *q, const double *qd, int i)
{
    double a[LAG_MAX_DOF] = {0}, b[LAG_MAX_DOF] = {0};
    for (int k = 0; k < m->nq; k++) { a[k] = qd[k]; b[k] = qd[k]; }
    a[i] += 1.0;
    b[i] -= 1.0;
    return 0.5 * (tc_T(m, q, a) - tc_T(m, q, b));
}

#endif
