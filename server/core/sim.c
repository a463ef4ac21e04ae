/* The simulation: definition, state, held input, and advancing by ticks of dt.
 * Sim time is tick * dt, always computed from the integer tick count. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "core_internal.h"

lag_sim_def lag_default_sim_def(lag_model_kind kind)
{
    lag_sim_def d;
    memset(&d, 0, sizeof d);
    lag_model_default(&d.model, kind);
    d.integrator = lag_default_integrator_def();
    d.explode_limit = 1e6;
    return d;
}

lag_result lag_sim_def_validate(const lag_sim_def *def, char *err, size_t errlen)
{
    lag_result r = lag_model_validate(&def->model, err, errlen);
    if (r != LAG_OK) return r;
    const lag_integrator_def *in = &def->integrator;
    if ((int)in->method < 0 || in->method >= LAG_METHOD_COUNT) {
        snprintf(err, errlen, "unknown integrator method %d", (int)in->method);
        return LAG_ERR_ARG;
    }
    if (!(isfinite(in->dt) && in->dt > 0)) {
        snprintf(err, errlen, "integrator.dt must be a finite number > 0 (s), got %g", in->dt);
        return LAG_ERR_ARG;
    }
    if (!(isfinite(in->rtol) && in->rtol > 0) || !(isfinite(in->atol) && in->atol > 0)) {
        snprintf(err, errlen, "integrator.rtol and atol must be finite numbers > 0");
        return LAG_ERR_ARG;
    }
    if (!(isfinite(in->dt_min) && in->dt_min > 0 && in->dt_min <= in->dt)) {
        snprintf(err, errlen, "integrator.dt_min must be > 0 and <= dt, got %g", in->dt_min);
        return LAG_ERR_ARG;
    }
    if (in->max_iter < 1 || in->max_iter > 1000) {
        snprintf(err, errlen, "integrator.max_iter must be in 1..1000, got %d", in->max_iter);
        return LAG_ERR_ARG;
    }
    if (!(isfinite(in->newton_tol) && in->newton_tol > 0 && in->newton_tol < 1)) {
        snprintf(err, errlen, "integrator.newton_tol must be in (0, 1), got %g", in->newton_tol);
        return LAG_ERR_ARG;
    }
    if (!(isfinite(def->explode_limit) && def->explode_limit > 0)) {
        snprintf(err, errlen, "explode_limit must be a finite number > 0, got %g",
                 def->explode_limit);
        return LAG_ERR_ARG;
    }
    int n = def->model.nq;
    for (int i = 0; i < n; i++) {
        if (!isfinite(def->q0[i]) || !isfinite(def->qd0[i])) {
            snprintf(err, errlen, "initial q and qd must be finite");
            return LAG_ERR_ARG;
        }
        if (fabs(def->q0[i]) > def->explode_limit || fabs(def->qd0[i]) > def->explode_limit) {
            snprintf(err, errlen, "initial state exceeds explode_limit %g", def->explode_limit);
            return LAG_ERR_ARG;
        }
    }
    double M[LAG_MAX_DOF * LAG_MAX_DOF], b[LAG_MAX_DOF] = {0}, x[LAG_MAX_DOF];
    lag_model_mass(&def->model, def->q0, M);
    if (lag_spd_solve(n, M, b, x) != LAG_OK) {
        snprintf(err, errlen, "mass matrix is not positive definite at the initial q");
        return LAG_ERR_ARG;
    }
    return LAG_OK;
}

lag_result lag_sim_init(lag_sim *s, const lag_sim_def *def, char *err, size_t errlen)
{
    lag_result r = lag_sim_def_validate(def, err, errlen);
    if (r != LAG_OK) return r;
    memset(s, 0, sizeof *s);
    s->def = *def;
    s->nq = def->model.nq;
    lag_sim_reset(s, NULL, NULL);
    return LAG_OK;
}

void lag_sim_reset(lag_sim *s, const double *q, const double *qd)
{
    int n = s->nq;
    for (int i = 0; i < n; i++) {
        s->q[i] = q ? q[i] : s->def.q0[i];
        s->qd[i] = qd ? qd[i] : s->def.qd0[i];
        s->tau[i] = 0.0;
    }
    s->tick = 0;
    s->dp.valid = false;
    s->dp.h = 0.0;
}

void lag_sim_set_input(lag_sim *s, const double *tau)
{
    const lag_model_info *info = lag_model_info_get(s->def.model.kind);
    bool changed = false;
    for (int i = 0; i < s->nq; i++) {
        double v = info->actuated[i] ? tau[i] : 0.0;
        if (memcmp(&v, &s->tau[i], sizeof v) != 0) changed = true;
        s->tau[i] = v;
    }
    /* dopri5 may have run ahead of the public state with the old input: restart it. */
    if (changed) s->dp.valid = false;
}

double lag_sim_time(const lag_sim *s) { return (double)s->tick * s->def.integrator.dt; }

double lag_sim_energy(const lag_sim *s)
{
    return lag_model_kinetic(&s->def.model, s->q, s->qd)
         + lag_model_potential(&s->def.model, s->q);
}

/* The generalized forces acting besides gravity and inertia: the held input. */
static inline void applied_forces(const lag_sim *s, const double *q, const double *qd,
                                  double *Q)
{
    (void)q; (void)qd;
    for (int i = 0; i < s->nq; i++) Q[i] = s->tau[i];
}

lag_result lag_sim_rhs(lag_sim *s, const double *y, double *ydot)
{
    int n = s->nq;
    double Q[LAG_MAX_DOF];
    applied_forces(s, y, y + n, Q);
    s->stats.rhs_evals++;
    for (int i = 0; i < n; i++) ydot[i] = y[n + i];
    return lag_model_forward(&s->def.model, y, y + n, Q, ydot + n);
}

/* Canonical form y = (q, p), p = M(q) qd, H = T + U:
 *   q_dot = M^-1 p,  p_dot = dT/dq |_(qd fixed) - g(q) + Q,  dT/dq_k = 1/2 qd^T dM/dq_k qd.
 * (dH/dq at fixed p equals -dT/dq at fixed qd.) */
lag_result lag_sim_rhs_qp(lag_sim *s, const double *y, double *ydot)
{
    int n = s->nq;
    const lag_model *m = &s->def.model;
    const lag_model_vtable *vt = lag_model_vt(m);
    double M[LAG_MAX_DOF * LAG_MAX_DOF], dM[LAG_MAX_DOF * LAG_MAX_DOF * LAG_MAX_DOF];
    double g[LAG_MAX_DOF], Q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
    s->stats.rhs_evals++;
    vt->mass(m->p, y, M);
    lag_result r = lag_spd_solve(n, M, y + n, qd);
    if (r != LAG_OK) return r;
    vt->mass_deriv(m->p, y, dM);
    vt->gravity(m->p, y, g);
    applied_forces(s, y, qd, Q);
    for (int k = 0; k < n; k++) {
        double t = 0.0;
        const double *dMk = dM + k * n * n;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) t += qd[i] * dMk[i * n + j] * qd[j];
        ydot[k] = qd[k];
        ydot[n + k] = 0.5 * t - g[k] + Q[k];
    }
    return LAG_OK;
}

lag_result lag_sim_advance(lag_sim *s, int64_t nticks, bool continuous)
{
    if (nticks <= 0) return LAG_OK;
    lag_method method = s->def.integrator.method;
    if (method == LAG_DOPRI5) {
        lag_result r = lag_dopri5_advance(s, nticks, continuous);
        if (r != LAG_OK) s->stats.faults++;
        return r;
    }
    int n = s->nq;
    double limit = s->def.explode_limit;
    for (int64_t k = 0; k < nticks; k++) {
        double q1[LAG_MAX_DOF], qd1[LAG_MAX_DOF];
        lag_result r;
        switch (method) {
        case LAG_EULER: r = lag_step_euler(s, q1, qd1); break;
        case LAG_SEMI_IMPLICIT_EULER: r = lag_step_semi_implicit_euler(s, q1, qd1); break;
        case LAG_RK4: r = lag_step_rk4(s, q1, qd1); break;
        case LAG_IMPLICIT_MIDPOINT: r = lag_step_gauss(s, 1, q1, qd1); break;
        case LAG_GAUSS4: r = lag_step_gauss(s, 2, q1, qd1); break;
        default: r = LAG_ERR_ARG; break;
        }
        if (r == LAG_OK) {
            bool finite = lag_state_ok(n, q1, INFINITY) && lag_state_ok(n, qd1, INFINITY);
            if (!finite) r = LAG_ERR_NONFINITE;
            else if (!lag_state_ok(n, q1, limit) || !lag_state_ok(n, qd1, limit)) r = LAG_ERR_EXPLODE;
        }
        if (r != LAG_OK) {
            s->stats.faults++;
            return r; /* public state is still that of the last good tick */
        }
        memcpy(s->q, q1, sizeof(double) * n);
        memcpy(s->qd, qd1, sizeof(double) * n);
        s->tick++;
        s->stats.steps_accepted++;
    }
    return LAG_OK;
}
