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
    d.max_steps = 100000;
    d.newton_tol = 1e-13;
    return d;
}

/* y1 = y0 + h f(y0) */
lag_result lag_step_euler(lag_sim *s, double h, const double *y0, double *y1)
{
    int N = 2 * s->nq;
    double f[LAG_MAX_STATE];
    lag_result r = lag_sim_rhs(s, y0, f);
    if (r != LAG_OK) return r;
    for (int i = 0; i < N; i++) y1[i] = y0[i] + h * f[i];
    return LAG_OK;
}

/* qd1 = qd0 + h qdd(q0, qd0); q1 = q0 + h qd1 (velocity first). */
lag_result lag_step_semi_implicit_euler(lag_sim *s, double h, const double *y0, double *y1)
{
    int n = s->nq;
    double f[LAG_MAX_STATE];
    lag_result r = lag_sim_rhs(s, y0, f);
    if (r != LAG_OK) return r;
    for (int i = 0; i < n; i++) {
        y1[n + i] = y0[n + i] + h * f[n + i];
        y1[i] = y0[i] + h * y1[n + i];
    }
    return LAG_OK;
}

/* Classical fourth-order Runge-Kutta. */
lag_result lag_step_rk4(lag_sim *s, double h, const double *y0, double *y1)
{
    int N = 2 * s->nq;
    double yt[LAG_MAX_STATE];
    double k1[LAG_MAX_STATE], k2[LAG_MAX_STATE], k3[LAG_MAX_STATE], k4[LAG_MAX_STATE];
    lag_result r;
    if ((r = lag_sim_rhs(s, y0, k1)) != LAG_OK) return r;
    for (int i = 0; i < N; i++) yt[i] = y0[i] + 0.5 * h * k1[i];
    if ((r = lag_sim_rhs(s, yt, k2)) != LAG_OK) return r;
    for (int i = 0; i < N; i++) yt[i] = y0[i] + 0.5 * h * k2[i];
    if ((r = lag_sim_rhs(s, yt, k3)) != LAG_OK) return r;
    for (int i = 0; i < N; i++) yt[i] = y0[i] + h * k3[i];
    if ((r = lag_sim_rhs(s, yt, k4)) != LAG_OK) return r;
    for (int i = 0; i < N; i++)
        y1[i] = y0[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    return LAG_OK;
}

lag_result lag_step(lag_sim *s, double h, const double *y0, double *y1)
{
    switch (s->def.integrator.method) {
    case LAG_EULER: return lag_step_euler(s, h, y0, y1);
    case LAG_SEMI_IMPLICIT_EULER: return lag_step_semi_implicit_euler(s, h, y0, y1);
    case LAG_RK4: return lag_step_rk4(s, h, y0, y1);
    case LAG_DOPRI5: return lag_dopri5_span(s, h, y0, y1);
    case LAG_IMPLICIT_MIDPOINT: return lag_step_gauss(s, 1, h, y0, y1);
    case LAG_GAUSS4: return lag_step_gauss(s, 2, h, y0, y1);
    default: return LAG_ERR_ARG;
    }
}
