/* Integrator names and defaults, and the explicit fixed-step methods on y = (q, qd). */
#include <string.h>
#include "core_internal.h"

static const char *const method_names[LAG_METHOD_COUNT] = {
    "euler", "semi-implicit-euler", "rk4", "dopri5", "implicit-midpoint", "gauss4",
};
static const int method_orders[LAG_METHOD_COUNT] = {1, 1, 4, 5, 2, 4};

const char *lag_method_name(lag_method m)
{
    return ((int)m >= 0 && m < LAG_METHOD_COUNT) ? method_names[m] : "unknown";
}

int lag_method_from_name(const char *name)
{
    for (int i = 0; i < LAG_METHOD_COUNT; i++)
        if (name && strcmp(name, method_names[i]) == 0) return i;
    return -1;
}

int lag_method_order(lag_method m)
{
    return ((int)m >= 0 && m < LAG_METHOD_COUNT) ? method_orders[m] : 0;
}

lag_integrator_def lag_default_integrator_def(void)
{
    lag_integrator_def d;
    d.method = LAG_RK4;
    d.dt = 1e-3;
    d.rtol = 1e-8;
    d.atol = 1e-10;
    d.dt_min = 1e-12;
    d.max_iter = 20;
    d.newton_tol = 1e-13;
    return d;
}

/* Packs the public state into y = (q, qd). */
static inline void load_y(const lag_sim *s, double *y)
{
    int n = s->nq;
    memcpy(y, s->q, sizeof(double) * n);
    memcpy(y + n, s->qd, sizeof(double) * n);
}

/* y1 = y0 + h f(y0) */
lag_result lag_step_euler(lag_sim *s, double *q1, double *qd1)
{
    int n = s->nq, N = 2 * n;
    double h = s->def.integrator.dt, y[LAG_MAX_STATE], f[LAG_MAX_STATE];
    load_y(s, y);
    lag_result r = lag_sim_rhs(s, y, f);
    if (r != LAG_OK) return r;
    for (int i = 0; i < N; i++) y[i] += h * f[i];
    memcpy(q1, y, sizeof(double) * n);
    memcpy(qd1, y + n, sizeof(double) * n);
    return LAG_OK;
}

/* qd1 = qd0 + h qdd(q0, qd0); q1 = q0 + h qd1 (velocity first). */
lag_result lag_step_semi_implicit_euler(lag_sim *s, double *q1, double *qd1)
{
    int n = s->nq;
    double h = s->def.integrator.dt, y[LAG_MAX_STATE], f[LAG_MAX_STATE];
    load_y(s, y);
    lag_result r = lag_sim_rhs(s, y, f);
    if (r != LAG_OK) return r;
    for (int i = 0; i < n; i++) {
        qd1[i] = y[n + i] + h * f[n + i];
        q1[i] = y[i] + h * qd1[i];
    }
    return LAG_OK;
}

/* Classical fourth-order Runge-Kutta. */
lag_result lag_step_rk4(lag_sim *s, double *q1, double *qd1)
{
    int n = s->nq, N = 2 * n;
    double h = s->def.integrator.dt;
    double y[LAG_MAX_STATE], yt[LAG_MAX_STATE];
    double k1[LAG_MAX_STATE], k2[LAG_MAX_STATE], k3[LAG_MAX_STATE], k4[LAG_MAX_STATE];
    lag_result r;
    load_y(s, y);
    if ((r = lag_sim_rhs(s, y, k1)) != LAG_OK) return r;
    for (int i = 0; i < N; i++) yt[i] = y[i] + 0.5 * h * k1[i];
    if ((r = lag_sim_rhs(s, yt, k2)) != LAG_OK) return r;
    for (int i = 0; i < N; i++) yt[i] = y[i] + 0.5 * h * k2[i];
    if ((r = lag_sim_rhs(s, yt, k3)) != LAG_OK) return r;
    for (int i = 0; i < N; i++) yt[i] = y[i] + h * k3[i];
    if ((r = lag_sim_rhs(s, yt, k4)) != LAG_OK) return r;
    for (int i = 0; i < N; i++)
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    memcpy(q1, y, sizeof(double) * n);
    memcpy(qd1, y + n, sizeof(double) * n);
    return LAG_OK;
}
