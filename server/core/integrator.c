/* Integrator names and defaults, and the explicit fixed-step methods on y = (q, qd). */
#include <stdio.h>
#include <string.h>
#include "core_internal.h"

/* The method table: one row per lag_method (designated initializers; the size is checked
 * against LAG_METHOD_COUNT, so a method without its row does not build). */
typedef struct method_class {
    lag_method_info info;
    /* one step of h from y0 (an adaptive method: sub-steps landing on h) */
    lag_result (*step)(lag_sim *s, double h, const double *y0, double *y1);
    /* adaptive methods: n ticks of the public state without stopping at each tick
     * (lag_sim_advance's path when no effect needs the tick boundaries) */
    lag_result (*advance)(lag_sim *s, int64_t n, int64_t stop);
} method_class;

static lag_result step_midpoint(lag_sim *s, double h, const double *y0, double *y1)
{
    return lag_step_gauss(s, 1, h, y0, y1);
}
static lag_result step_gauss4(lag_sim *s, double h, const double *y0, double *y1)
{
    return lag_step_gauss(s, 2, h, y0, y1);
}

static const method_class methods[] = {
    [LAG_EULER] = {{"euler", 1, false, false, false}, lag_step_euler},
    [LAG_SEMI_IMPLICIT_EULER] = {{"semi-implicit-euler", 1, false, false, false},
                                 lag_step_semi_implicit_euler},
    [LAG_RK4] = {{"rk4", 4, false, false, false}, lag_step_rk4},
    [LAG_DOPRI5] = {{"dopri5", 5, true, false, false}, lag_dopri5_span, lag_dopri5_advance},
    [LAG_IMPLICIT_MIDPOINT] = {{"implicit-midpoint", 2, false, true, true}, step_midpoint},
    [LAG_GAUSS4] = {{"gauss4", 4, false, true, true}, step_gauss4},
};
_Static_assert(sizeof methods / sizeof methods[0] == LAG_METHOD_COUNT,
               "the method table needs one row per lag_method");

const lag_method_info *lag_method_info_get(lag_method m)
{
    return ((int)m >= 0 && m < LAG_METHOD_COUNT) ? &methods[m].info : NULL;
}

const char *lag_method_name(lag_method m)
{
    return ((int)m >= 0 && m < LAG_METHOD_COUNT) ? methods[m].info.name : "unknown";
}

int lag_method_from_name(const char *name)
{
    for (int i = 0; i < LAG_METHOD_COUNT; i++)
        if (name && strcmp(name, methods[i].info.name) == 0) return i;
    return -1;
}

int lag_method_order(lag_method m)
{
    return ((int)m >= 0 && m < LAG_METHOD_COUNT) ? methods[m].info.order : 0;
}

const char *lag_method_names(char *buf, size_t len)
{
    size_t used = 0;
    if (!buf || len == 0) return buf;
    buf[0] = '\0';
    for (int i = 0; i < LAG_METHOD_COUNT && used < len; i++) {
        int w = snprintf(buf + used, len - used, "%s%s", i ? ", " : "", methods[i].info.name);
        if (w < 0) break;
        used += (size_t)w;
    }
    return buf;
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
    lag_result r = lag_rhs(s, y0, f);
    if (r != LAG_OK) return lag_stage_fault(s, y0, r);
    for (int i = 0; i < N; i++) y1[i] = y0[i] + h * f[i];
    return LAG_OK;
}

/* qd1 = qd0 + h qdd(q0, qd0); q1 = q0 + h qd1 (velocity first). */
lag_result lag_step_semi_implicit_euler(lag_sim *s, double h, const double *y0, double *y1)
{
    int n = s->nq;
    double f[LAG_MAX_STATE];
    lag_result r = lag_rhs(s, y0, f);
    if (r != LAG_OK) return lag_stage_fault(s, y0, r);
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
    if ((r = lag_rhs(s, y0, k1)) != LAG_OK) return lag_stage_fault(s, y0, r);
    for (int i = 0; i < N; i++) yt[i] = y0[i] + 0.5 * h * k1[i];
    if ((r = lag_rhs(s, yt, k2)) != LAG_OK) return lag_stage_fault(s, yt, r);
    for (int i = 0; i < N; i++) yt[i] = y0[i] + 0.5 * h * k2[i];
    if ((r = lag_rhs(s, yt, k3)) != LAG_OK) return lag_stage_fault(s, yt, r);
    for (int i = 0; i < N; i++) yt[i] = y0[i] + h * k3[i];
    if ((r = lag_rhs(s, yt, k4)) != LAG_OK) return lag_stage_fault(s, yt, r);
    for (int i = 0; i < N; i++)
        y1[i] = y0[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    return LAG_OK;
}

lag_result lag_step(lag_sim *s, double h, const double *y0, double *y1)
{
    return methods[s->def.integrator.method].step(s, h, y0, y1);
}

lag_result lag_adaptive_advance(lag_sim *s, int64_t n, int64_t stop)
{
    return methods[s->def.integrator.method].advance(s, n, stop);
}

bool lag_method_table_ok(void)
{
    for (int i = 0; i < LAG_METHOD_COUNT; i++) {
        const method_class *c = &methods[i];
        if (!c->info.name || !c->step || c->info.order < 1) return false;
        if (c->info.adaptive != (c->advance != NULL)) return false;
        for (int j = 0; j < i; j++)
            if (strcmp(methods[j].info.name, c->info.name) == 0) return false;
    }
    return true;
}
