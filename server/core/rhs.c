/*
 * The right-hand side: the model's forward dynamics with the effects' forces and holds,
 * in (q, qd) and in canonical (q, p) coordinates, and what a failed evaluation means
 * (lag_stage_fault). What the integrators call; below the sim (sim.c) and the
 * integrators (integrator*.c), which do not call each other for it.
 */
#include <math.h>
#include <string.h>
#include "core_internal.h"

/* Solves A x = b on the free joints of `locked` (a reduced SPD system); x is 0 on the
 * locked joints. With nothing locked this is the full solve. OUT: x */
static lag_result solve_free(int n, uint32_t locked, const double *A, const double *b,
                             double *x)
{
    LAG_ASSERT(n >= 1 && n <= LAG_MAX_DOF && (locked >> n) == 0); /* locks only on joints */
    if (!locked) return lag_spd_solve(n, A, b, x);
    int free_idx[LAG_MAX_DOF], nf = 0;
    for (int i = 0; i < n; i++)
        if (!(locked & (1u << i))) free_idx[nf++] = i;
    double Aff[LAG_MAX_DOF * LAG_MAX_DOF], bf[LAG_MAX_DOF], xf[LAG_MAX_DOF];
    for (int a = 0; a < nf; a++) {
        bf[a] = b[free_idx[a]];
        for (int c = 0; c < nf; c++) Aff[a * nf + c] = A[free_idx[a] * n + free_idx[c]];
    }
    for (int i = 0; i < n; i++) x[i] = 0.0;
    if (nf == 0) return LAG_OK;
    lag_result r = lag_spd_solve(nf, Aff, bf, xf);
    if (r != LAG_OK) return r;
    for (int a = 0; a < nf; a++) x[free_idx[a]] = xf[a];
    return LAG_OK;
}

lag_result lag_forward_locked(const lag_sim *s, const double *q, const double *qd,
                              const double *Q, double *qdd, double *lambda)
{
    const int n = s->nq;
    const uint32_t locked = s->mode.locked;
    if (!locked) {
        if (lambda)
            for (int i = 0; i < n; i++) lambda[i] = 0.0;
        return s->dyn->forward(s->model.p, q, qd, Q, qdd);
    }
    double M[LAG_MAX_DOF * LAG_MAX_DOF], h[LAG_MAX_DOF], r[LAG_MAX_DOF];
    s->dyn->mass_bias(s->model.p, q, qd, M, h);
    for (int i = 0; i < n; i++) r[i] = Q[i] - h[i];
    /* M_ff qdd_f = r_f on the free joints; qdd_L = 0 */
    lag_result res = solve_free(n, locked, M, r, qdd);
    if (res != LAG_OK) return res;
    if (lambda) /* lambda = M qdd - r, the force each lock must supply */
        for (int i = 0; i < n; i++) {
            double acc = -r[i];
            for (int j = 0; j < n; j++) acc += M[i * n + j] * qdd[j];
            lambda[i] = (locked & (1u << i)) ? acc : 0.0;
        }
    return LAG_OK;
}

lag_result lag_stage_fault(const lag_sim *s, const double *y, lag_result r)
{
    return (r == LAG_ERR_SINGULAR && !lag_state_ok(2 * s->nq, y, INFINITY)) ? LAG_ERR_NONFINITE : r;
}

lag_result lag_sim_rhs(lag_sim *s, const double *y, double *ydot)
{
    lag_result r = lag_rhs(s, y, ydot);
    return r == LAG_OK ? r : lag_stage_fault(s, y, r);
}

lag_result lag_qd_from_p(const lag_sim *s, const double *q, const double *p, double *qd)
{
    double M[LAG_MAX_DOF * LAG_MAX_DOF];
    s->dyn->mass(s->model.p, q, M);
    return solve_free(s->nq, s->mode.locked, M, p, qd);
}

/* Canonical form y = (q, p), p = M(q) qd, H = T + U:
 *   q_dot = M^-1 p,  p_dot = dT/dq |_(qd fixed) - g(q) + Q,  dT/dq_k = 1/2 qd^T dM/dq_k qd.
 * (dH/dq at fixed p equals -dT/dq at fixed qd.) Locked joints: qd_i = 0 and p_i is
 * not evolved (the reduced system on the free joints is Hamiltonian in (q_f, p_f)). */
lag_result lag_sim_rhs_qp(lag_sim *s, const double *y, double *ydot)
{
    int n = s->nq;
    const lag_model *m = &s->model;
    const lag_model_class *vt = s->dyn;
    double dM[LAG_MAX_DOF * LAG_MAX_DOF * LAG_MAX_DOF];
    double g[LAG_MAX_DOF], Q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
    s->stats.rhs_evals++;
    lag_result r = lag_qd_from_p(s, y, y + n, qd);
    if (r != LAG_OK) return lag_stage_fault(s, y, r);
    vt->mass_deriv(m->p, y, dM);
    vt->gravity(m->p, y, g);
    lag_effects_force(s, y, qd, Q);
    for (int k = 0; k < n; k++) {
        double t = 0.0;
        const double *dMk = dM + k * n * n;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) t += qd[i] * dMk[i * n + j] * qd[j];
        ydot[k] = qd[k];
        ydot[n + k] = (s->mode.locked & (1u << k)) ? 0.0 : 0.5 * t - g[k] + Q[k];
    }
    return LAG_OK;
}
