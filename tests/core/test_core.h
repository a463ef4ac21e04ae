/*
 * Shared helpers of the core's physics tests (tests/core/test_*.c).
 *
 * The point of these tests is independence: nothing here reads the core's closed forms.
 * Each model is written again from the body kinematics of docs/models.md (centre-of-mass
 * positions r_c(q), their velocities v_c(q, qd), body angular velocities omega), in complex
 * arithmetic so that derivatives can be taken by the complex step
 *
 *     f'(x) = Im f(x + i h) / h + O(h^2 f'''),   h = 1e-20,
 *
 * which has no subtractive cancellation: for h this small the truncation term is below
 * 1e-40 and the result is exact to a few ulps of the terms of f. T and U are then
 *     T = sum_b 1/2 m_b v_b . v_b + 1/2 I_b omega_b^2,   U = the row's potential
 * (sum_b m_b g y_b, plus what the model stores besides: tests/common/ref_models.h),
 * and M, dM/dq, g, dL/dq, dL/dqd follow from T and U by complex steps alone.
 *
 * Checks and cases: tests/common/lagsim_test.h.
 */
#ifndef LAGSIM_TEST_CORE_H
#define LAGSIM_TEST_CORE_H

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_test.h"
#include "ref_models.h" /* the models written again: kinematics, T, U */

#define TC_EPS DBL_EPSILON
/* complex-step size: any h with h^2 * |f'''| far below eps |f'| works; 1e-20 does. */
#define TC_CSTEP 1e-20

/* ------------------------------------------------------------------ random models */
static inline int tc_nq(lag_model_kind k) { return lag_model_info_get(k)->nq; }

/* Random but physical parameters, from the model's own table of units and rules: masses
 * 0.2..3 kg, lengths 0.2..2 m, inertias 0.01..1 kg m^2 (or, one model in two, every rod's
 * uniform-rod value m l^2 / 12), g 1..20 m/s^2, stiffnesses 0.5..20 N m/rad or N/m,
 * parameters that may take any value (h0) 0..1. A unit without a range stops the test:
 * give it one here. */
static inline void tc_random_model(lt_rng *r, lag_model_kind kind, lag_model *m)
{
    const lag_model_info *inf = lag_model_info_get(kind);
    lag_model_default(m, kind);
    bool rod = lt_uniform(r, 0, 1) < 0.5;
    for (int i = 0; i < inf->np; ++i) {
        const char *u = inf->param_units[i];
        if (inf->param_rules[i] == LAG_PARAM_ANY) m->p[i] = lt_uniform(r, 0, 1);
        else if (!strcmp(u, "kg")) m->p[i] = lt_uniform(r, 0.2, 3);
        else if (!strcmp(u, "m")) m->p[i] = lt_uniform(r, 0.2, 2);
        else if (!strcmp(u, "kg m^2")) m->p[i] = lt_uniform(r, 0.01, 1);
        else if (!strcmp(u, "m/s^2")) m->p[i] = lt_uniform(r, 1, 20);
        else if (!strcmp(u, "N m/rad") || !strcmp(u, "N/m")) m->p[i] = lt_uniform(r, 0.5, 20);
        else {
            fprintf(stderr, "test_core.h: no random range for unit '%s' (%s.%s)\n", u, inf->name,
                    inf->param_names[i]);
            abort();
        }
    }
    if (rod)
        for (int k = 0; k < inf->n_rods; ++k) {
            lag_rod rd = inf->rods[k];
            m->p[rd.inertia] = m->p[rd.mass] * m->p[rd.length] * m->p[rd.length] / 12;
        }
}

/* Random state: angles -pi..pi, positions -2..2, rates -5..5. */
static inline void tc_random_state(lt_rng *r, const lag_model *m, double *q, double *qd)
{
    const lag_model_info *inf = lag_model_info_get(m->kind);
    for (int i = 0; i < m->nq; ++i) {
        q[i] = inf->angular[i] ? lt_uniform(r, -TC_PI, TC_PI) : lt_uniform(r, -2, 2);
        qd[i] = lt_uniform(r, -5, 5);
    }
}

/* Random start of a motion for the structure tests: q_i in the reference's range. */
static inline void tc_motion_start(lt_rng *r, const lag_model *m, double *q)
{
    const tc_ref *ref = tc_ref_of(m->kind);
    for (int i = 0; i < m->nq; ++i) q[i] = lt_uniform(r, ref->qlo[i], ref->qhi[i]);
}

/* dT/dq_k (qd held) by complex step. OUT: out[n] */
static inline void tc_dT_dq(const lag_model *m, const double *q, const double *qd, double *out)
{
    for (int k = 0; k < m->nq; ++k) {
        cplx qc[3] = {0}, qdc[3] = {0};
        tc_to_c(m->nq, q, qc);
        tc_to_c(m->nq, qd, qdc);
        qc[k] += CMPLX(0, TC_CSTEP);
        out[k] = cimag(tc_T_c(m, qc, qdc)) / TC_CSTEP;
    }
}

/* dT/dqd_k (q held) by complex step: the generalized momentum p. OUT: out[n] */
static inline void tc_dT_dqd(const lag_model *m, const double *q, const double *qd, double *out)
{
    for (int k = 0; k < m->nq; ++k) {
        cplx qc[3] = {0}, qdc[3] = {0};
        tc_to_c(m->nq, q, qc);
        tc_to_c(m->nq, qd, qdc);
        qdc[k] += CMPLX(0, TC_CSTEP);
        out[k] = cimag(tc_T_c(m, qc, qdc)) / TC_CSTEP;
    }
}

/* dU/dq_k by complex step. OUT: out[n] */
static inline void tc_dU_dq(const lag_model *m, const double *q, double *out)
{
    for (int k = 0; k < m->nq; ++k) {
        cplx qc[3] = {0};
        tc_to_c(m->nq, q, qc);
        qc[k] += CMPLX(0, TC_CSTEP);
        out[k] = cimag(tc_U_c(m, qc)) / TC_CSTEP;
    }
}

/* M(q) as the Hessian of T in qd. T is exactly quadratic in qd, so polarization is exact:
 * M_ii = 2 T(q, e_i), M_ij = T(q, e_i + e_j) - T(q, e_i) - T(q, e_j). Complex q allowed
 * (for complex steps in q). OUT: M[n*n] */
static inline void tc_mass_c(const lag_model *m, const cplx *q, cplx *M)
{
    int n = m->nq;
    cplx Te[3];
    for (int i = 0; i < n; ++i) {
        cplx e[3] = {0, 0, 0};
        e[i] = 1;
        Te[i] = tc_T_c(m, q, e);
        M[i * n + i] = 2 * Te[i];
    }
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j) {
            cplx e[3] = {0, 0, 0};
            e[i] = 1;
            e[j] = 1;
            M[i * n + j] = M[j * n + i] = tc_T_c(m, q, e) - Te[i] - Te[j];
        }
}

static inline void tc_mass(const lag_model *m, const double *q, double *M)
{
    cplx qc[3] = {0}, Mc[9] = {0};
    tc_to_c(m->nq, q, qc);
    tc_mass_c(m, qc, Mc);
    for (int i = 0; i < m->nq * m->nq; ++i) M[i] = creal(Mc[i]);
}

/* dM_ij/dq_k by complex step on tc_mass_c, laid out as the core's: dM[k*n*n + i*n + j]. */
static inline void tc_mass_deriv(const lag_model *m, const double *q, double *dM)
{
    int n = m->nq;
    for (int k = 0; k < n; ++k) {
        cplx qc[3] = {0}, Mc[9] = {0};
        tc_to_c(n, q, qc);
        qc[k] += CMPLX(0, TC_CSTEP);
        tc_mass_c(m, qc, Mc);
        for (int i = 0; i < n * n; ++i) dM[k * n * n + i] = cimag(Mc[i]) / TC_CSTEP;
    }
}

/* C from the Christoffel formula with the dM above:
 * C_kj = sum_i c_ijk qd_i, c_ijk = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k). */
static inline void tc_christoffel(int n, const double *dM, const double *qd, double *C)
{
#define TC_DM(k, i, j) dM[(k) * n * n + (i) * n + (j)]
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j) {
            double s = 0;
            for (int i = 0; i < n; ++i)
                s += 0.5 * (TC_DM(i, k, j) + TC_DM(j, k, i) - TC_DM(k, i, j)) * qd[i];
            C[k * n + j] = s;
        }
#undef TC_DM
}

/* Generalized momentum p(q, v) = dT/dqd at qd = v, for complex q. T is exactly quadratic in
 * qd, so the central difference p_k = (T(q, v + c e_k) - T(q, v - c e_k)) / (2 c) is exact
 * for any c (no truncation term); c = max(1, |v|) keeps the rounding at a few eps |M| |v|.
 * Being linear in v, p(q, qdd) = M(q) qdd. OUT: out[n] */
static inline void tc_momentum_c(const lag_model *m, const cplx *q, const double *v, cplx *out)
{
    int n = m->nq;
    double c = 1;
    for (int i = 0; i < n; ++i) c = fmax(c, fabs(v[i]));
    for (int k = 0; k < n; ++k) {
        cplx vp[3] = {0}, vm[3] = {0};
        for (int i = 0; i < n; ++i) vp[i] = vm[i] = v[i];
        vp[k] += c;
        vm[k] -= c;
        out[k] = (tc_T_c(m, q, vp) - tc_T_c(m, q, vm)) / (2 * c);
    }
}

/* Lagrange's left side d/dt(dL/dqd) - dL/dq at (q, qd) for a given qdd, from T and U only.
 * Along a motion, d/dt p(q, qd) = (dp/dq) qd + p(q, qdd) (p is linear in its second
 * argument); the first term is a complex step of p in q along qd, the second is exact.
 * dL/dq = dT/dq - dU/dq by complex steps. No truncation error anywhere: the result is
 * exact to the rounding of a few dozen terms of the size of M qdd, |dM| |qd|^2 and g. OUT: out[n] */
static inline void tc_lagrange_lhs(const lag_model *m, const double *q, const double *qd,
                                   const double *qdd, double *out)
{
    int n = m->nq;
    cplx qs[3] = {0}, qr[3] = {0}, pq[3] = {0}, pa[3] = {0};
    for (int i = 0; i < n; ++i) {
        qs[i] = CMPLX(q[i], TC_CSTEP * qd[i]);
        qr[i] = q[i];
    }
    tc_momentum_c(m, qs, qd, pq);  /* Im / h = (dp/dq) qd */
    tc_momentum_c(m, qr, qdd, pa); /* = M(q) qdd */
    double dTq[3], dUq[3];
    tc_dT_dq(m, q, qd, dTq);
    tc_dU_dq(m, q, dUq);
    for (int i = 0; i < n; ++i)
        out[i] = cimag(pq[i]) / TC_CSTEP + creal(pa[i]) - (dTq[i] - dUq[i]);
}

/* Forward dynamics of our own, from T and U only: Lagrange's equations read
 * M(q) qdd = tau - (dp/dq) qd + dT/dq - dU/dq, with M from tc_mass and the rest from
 * tc_lagrange_lhs at qdd = 0; solved by Gaussian elimination with partial pivoting.
 * Used for reference trajectories that share no code with the core. OUT: qdd[n] */
static inline void tc_forward_own(const lag_model *m, const double *q, const double *qd,
                                  const double *tau, double *qdd)
{
    int n = m->nq;
    double A[3][4] = {{0}}, zero[3] = {0, 0, 0}, h[3];
    double M[9];
    tc_mass(m, q, M);
    tc_lagrange_lhs(m, q, qd, zero, h);
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) A[i][j] = M[i * n + j];
        A[i][n] = (tau ? tau[i] : 0) - h[i];
    }
    for (int c = 0; c < n; ++c) {
        int piv = c;
        for (int r = c + 1; r < n; ++r)
            if (fabs(A[r][c]) > fabs(A[piv][c])) piv = r;
        for (int j = 0; j <= n; ++j) {
            double t = A[c][j];
            A[c][j] = A[piv][j];
            A[piv][j] = t;
        }
        for (int r = c + 1; r < n; ++r) {
            double f = A[r][c] / A[c][c];
            for (int j = c; j <= n; ++j) A[r][j] -= f * A[c][j];
        }
    }
    for (int i = n - 1; i >= 0; --i) {
        double s = A[i][n];
        for (int j = i + 1; j < n; ++j) s -= A[i][j] * qdd[j];
        qdd[i] = s / A[i][i];
    }
}

/* Classical RK4 with our own forward dynamics, unforced, from (q0, qd0) over nsteps of h;
 * if rec is given, stores y = (q, qd) every `every` steps (rec[0] = initial). OUT: y[2n] */
static inline void tc_reference_run(const lag_model *m, const double *q0, const double *qd0,
                                    double h, int nsteps, double *y, double (*rec)[6], int every)
{
    int n = m->nq, ny = 2 * n;
    double k[4][6], yt[6];
    memcpy(y, q0, n * sizeof *y);
    memcpy(y + n, qd0, n * sizeof *y);
    if (rec) memcpy(rec[0], y, ny * sizeof *y);
    static const double c[4] = {0, 0.5, 0.5, 1};
    for (int s = 0; s < nsteps; ++s) {
        for (int st = 0; st < 4; ++st) {
            for (int i = 0; i < ny; ++i) yt[i] = y[i] + (st ? c[st] * h * k[st - 1][i] : 0);
            for (int i = 0; i < n; ++i) k[st][i] = yt[n + i];
            tc_forward_own(m, yt, yt + n, NULL, k[st] + n);
        }
        for (int i = 0; i < ny; ++i) y[i] += h / 6 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
        if (rec && (s + 1) % every == 0) memcpy(rec[(s + 1) / every], y, ny * sizeof *y);
    }
}

/* ------------------------------------------------------------------ small linear algebra */
static inline double tc_maxabs(int n, const double *x)
{
    double a = 0;
    for (int i = 0; i < n; ++i) a = fmax(a, fabs(x[i]));
    return a;
}

static inline void tc_matvec(int n, const double *A, const double *x, double *y)
{
    for (int i = 0; i < n; ++i) {
        double s = 0;
        for (int j = 0; j < n; ++j) s += A[i * n + j] * x[j];
        y[i] = s;
    }
}

/* Cholesky of a symmetric n x n matrix; returns the smallest pivot d_i of A = L D L^T
 * (all > 0 iff A is positive definite), or -1 at the first non-positive one. */
static inline double tc_min_pivot(int n, const double *A)
{
    double L[9] = {0};
    double minp = INFINITY;
    for (int j = 0; j < n; ++j) {
        double d = A[j * n + j];
        for (int k = 0; k < j; ++k) d -= L[j * n + k] * L[j * n + k];
        if (!(d > 0)) return -1;
        minp = fmin(minp, d);
        double ljj = sqrt(d);
        L[j * n + j] = ljj;
        for (int i = j + 1; i < n; ++i) {
            double s = A[i * n + j];
            for (int k = 0; k < j; ++k) s -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = s / ljj;
        }
    }
    return minp;
}

/* Least-squares slope of log(err) against log(h). */
static inline double tc_slope(int k, const double *h, const double *err)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < k; ++i) {
        double x = log(h[i]), y = log(err[i]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

/* ------------------------------------------------------------------ simulations */
/* A sim definition for a model, method and tick dt, starting from (q0, qd0). */
static inline lag_sim_def tc_sim_def(const lag_model *m, lag_method method, double dt,
                                     const double *q0, const double *qd0)
{
    lag_sim_def d = lag_default_sim_def(m->kind);
    d.model = *m;
    d.integrator.method = method;
    d.integrator.dt = dt;
    for (int i = 0; i < m->nq; ++i) {
        d.q0[i] = q0[i];
        d.qd0[i] = qd0[i];
    }
    return d;
}

/* Initializes s from d; reports and counts a failure if the core refuses. */
static inline int tc_sim_init(lag_sim *s, const lag_sim_def *d)
{
    char err[256] = "";
    lag_result r = lag_sim_init(s, d, err, sizeof err);
    if (r != LAG_OK) {
        lt_failures++;
        fprintf(stderr, "lag_sim_init(%s, %s, dt %g) failed: %s (%s)\n",
                lag_model_info_get(d->model.kind)->name, lag_method_name(d->integrator.method),
                d->integrator.dt, lag_result_string(r), err);
        return -1;
    }
    return 0;
}

/* Advances n ticks; reports and counts a failure on any error. */
static inline int tc_advance(lag_sim *s, int64_t n, bool continuous)
{
    lag_result r = lag_sim_advance(s, n, continuous);
    if (r != LAG_OK) {
        lt_failures++;
        fprintf(stderr, "lag_sim_advance(%s, %s) failed at tick %lld: %s\n",
                lag_model_info_get(s->def.model.kind)->name,
                lag_method_name(s->def.integrator.method), (long long)s->tick,
                lag_result_string(r));
        return -1;
    }
    return 0;
}

/* Facts of method m from the core's table (tests iterate 0..LAG_METHOD_COUNT-1). */
static inline const lag_method_info *tc_method(int m)
{
    const lag_method_info *mi = lag_method_info_get((lag_method)m);
    if (!mi) {
        fprintf(stderr, "no method %d in the core's table\n", m);
        abort();
    }
    return mi;
}

#endif
