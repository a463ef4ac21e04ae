/*
 * Shared helpers of the effects and hard-case tests (tests/effects/test_*.c).
 *
 * Independence: the expectations of these tests come from the models' T and U written
 * again here (te_kinetic, te_potential), from closed-form solutions, conservation laws and
 * quadratures of our own; nothing here calls the core's energy or dynamics functions.
 * The generalized momentum p_i = dT/dqd_i is taken from our own T: T is quadratic in qd,
 * so (T(qd + e_i) - T(qd - e_i)) / 2 = (M qd)_i exactly, up to rounding.
 *
 * Checks and cases: tests/common/lagsim_test.h.
 */
#ifndef LAGSIM_EFFECTS_TEST_H
#define LAGSIM_EFFECTS_TEST_H

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_test.h"
#include "ref_models.h"

#define TE_PI TC_PI

/* ------------------------------------------------------------------ T and U, again */
/* The models of tests/common/ref_models.h (written from their body kinematics). */

static inline double te_kinetic(const lag_model *m, const double *q, const double *qd)
{
    return tc_T(m, q, qd);
}

/* The DIPC's includes the constant of h0. */
static inline double te_potential(const lag_model *m, const double *q) { return tc_U(m, q); }

static inline double te_energy(const lag_model *m, const double *q, const double *qd)
{
    return te_kinetic(m, q, qd) + te_potential(m, q);
}

/* Generalized momentum p_i = dT/dqd_i = (M qd)_i from our own T (exact for a quadratic). */
static inline double te_momentum(const lag_model *m, const double *q, const double *qd, int i)
{
    return tc_momentum(m, q, qd, i);
}

/* M = d2T/dqd2 from our own T, column by column of momenta. OUT: M */
static inline void te_mass(const lag_model *m, const double *q, double *M)
{
    int n = m->nq;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double e[LAG_MAX_DOF] = {0};
            e[j] = 1.0;
            M[i * n + j] = te_momentum(m, q, e, i);
        }
}

static inline double te_sim_energy(const lag_sim *s)
{
    lag_model m; /* the model integrated now (a flying stick: measured from its end) */
    lag_sim_dynamics(s, &m);
    return te_energy(&m, s->q, s->qd);
}

static inline bool te_finite_state(const lag_sim *s)
{
    for (int i = 0; i < s->nq; i++)
        if (!isfinite(s->q[i]) || !isfinite(s->qd[i])) return false;
    return true;
}

/* Initialises or aborts the test (a definition the test wrote must be valid). */
static inline void te_init(lag_sim *s, const lag_sim_def *d)
{
    char err[256];
    lag_result r = lag_sim_init(s, d, err, sizeof err);
    if (r != LAG_OK) {
        fprintf(stderr, "lag_sim_init: %s: %s\n", lag_result_string(r), err);
        exit(2);
    }
}

/* Counts the pending events of a kind (all kinds if kind == 0) and drains them. */
static inline int te_drain(lag_sim *s, int kind, int *n_total)
{
    lag_event ev;
    int c = 0;
    while (lag_sim_poll_event(s, &ev)) {
        if (kind == 0 || (int)ev.kind == kind) c++;
        if (n_total) (*n_total)++;
    }
    return c;
}

/* ------------------------------------------------------------------ quadrature */
/* Composite 5-point Gauss-Legendre of f on [a, b] with n panels. */
typedef double (*te_fn)(double x, const void *ctx);
static inline double te_gauss5(te_fn f, const void *ctx, double a, double b, int n)
{
    static const double x5[5] = {-0.90617984593866399280, -0.53846931010568309104, 0.0,
                                 0.53846931010568309104, 0.90617984593866399280};
    static const double w5[5] = {0.23692688505618908751, 0.47862867049936646804, 128.0 / 225.0,
                                 0.47862867049936646804, 0.23692688505618908751};
    double h = (b - a) / n, acc = 0.0;
    for (int k = 0; k < n; k++) {
        double c = a + (k + 0.5) * h, part = 0.0;
        for (int j = 0; j < 5; j++) part += w5[j] * f(c + 0.5 * h * x5[j], ctx);
        acc += 0.5 * h * part;
    }
    return acc;
}


/* ------------------------------------------------------------------ the stick, by hand */
/* J(phi) = m l^2/4 cos^2 phi + I: the stick's M_phiphi from T (M is diagonal). */
static inline double te_stick_J(const double *p, double phi)
{
    double c = cos(phi), l = p[LAG_STICK_L];
    return 0.25 * p[LAG_STICK_M] * l * l * c * c + p[LAG_STICK_I];
}

/* phi_dot^2 at phi on the free stick's energy curve through (phi0, phid0):
 *   1/2 J(phi) phid^2 + m g l/2 sin phi = 1/2 J(phi0) phid0^2 + m g l/2 sin phi0.
 * sin phi0 - sin phi = 2 cos((phi0 + phi)/2) sin((phi0 - phi)/2): no cancellation. */
static inline double te_stick_phid2(const double *p, double phi0, double phid0, double phi)
{
    double m = p[LAG_STICK_M], l = p[LAG_STICK_L], g = p[LAG_STICK_G];
    double ds = 2.0 * cos(0.5 * (phi0 + phi)) * sin(0.5 * (phi0 - phi));
    return (te_stick_J(p, phi0) * phid0 * phid0 + m * g * l * ds) / te_stick_J(p, phi);
}

/* Normal force over m at (phi, phid^2) with no inputs: N/m = g + d2/dt2 ((l/2) sin phi),
 * phidd from Lagrange's equation of T and U:
 *   J phidd + 1/2 J'(phi) phid^2 + m g l/2 cos phi = 0,  J' = -m l^2/2 cos phi sin phi. */
static inline double te_stick_normal(const double *p, double phi, double phid2)
{
    double m = p[LAG_STICK_M], l = p[LAG_STICK_L], g = p[LAG_STICK_G];
    double c = cos(phi), s = sin(phi);
    double phidd = (0.25 * m * l * l * c * s * phid2 - 0.5 * m * g * l * c) / te_stick_J(p, phi);
    return g + 0.5 * l * (c * phidd - s * phid2);
}

/* Time for a stick released at rest from theta0 = pi/2 - phi0 off the vertical (small) to
 * reach the floor phi = 0: t = int dphi / |phid(phi)|. With theta = pi/2 - phi the
 * integrand is singular like 1/sqrt(theta - theta0) at the start; the substitution
 * theta = theta0 cosh(s) makes it smooth (~ sqrt(2 J / (m g l)) near s = 0):
 *   t = int_0^S theta0 sinh(s) / sqrt(m g l (cos theta0 - cos theta) / J(theta)) ds,
 *   cos theta0 - cos theta = 2 sin((theta + theta0)/2) sin((theta - theta0)/2),
 *   theta - theta0 = 2 theta0 sinh^2(s/2),  S = acosh((pi/2) / theta0). */
typedef struct { const double *p; double th0; } te_fall_ctx;
static inline double te_fall_integrand(double s, const void *vctx)
{
    const te_fall_ctx *c = (const te_fall_ctx *)vctx;
    const double *p = c->p;
    double m = p[LAG_STICK_M], l = p[LAG_STICK_L], g = p[LAG_STICK_G];
    double sh = sinh(0.5 * s);
    double dth = 2.0 * c->th0 * sh * sh; /* theta - theta0 */
    double th = c->th0 + dth;
    double dc = 2.0 * sin(0.5 * (th + c->th0)) * sin(0.5 * dth);
    double sl = sin(th); /* cos phi */
    double J = 0.25 * m * l * l * sl * sl + p[LAG_STICK_I];
    if (s == 0.0) return sqrt(2.0 * J / (m * g * l * cos(c->th0))); /* limit s -> 0 */
    return c->th0 * sinh(s) / sqrt(m * g * l * dc / J);
}

/* Fall time from theta0 off the vertical to the floor; panels doubled until two
 * successive values agree to 1e-13 s. OUT: *quad_err (last change) */
static inline double te_stick_fall_time(const double *p, double theta0, double *quad_err)
{
    te_fall_ctx c = {p, theta0};
    double S = acosh((TE_PI / 2) / theta0);
    double prev = te_gauss5(te_fall_integrand, &c, 0.0, S, 64), cur = prev;
    for (int n = 128; n <= 65536; n *= 2) {
        cur = te_gauss5(te_fall_integrand, &c, 0.0, S, n);
        if (fabs(cur - prev) < 1e-13) break;
        prev = cur;
    }
    if (quad_err) *quad_err = fabs(cur - prev);
    return cur;
}

static inline const char *te_method(lag_method m) { return lag_method_name(m); }

#endif
