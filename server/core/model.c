/* Model kinds: the info table, parameter defaults and validation, public dispatch, and
 * forward dynamics (M qdd = tau - C qd - g solved by Cholesky). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "core_internal.h"

/* The model table: one row per lag_model_kind, defined in the model's own file. A kind
 * added to the enum without its row breaks the build here; a row whose kind is missing
 * from the enum does not compile. */
extern const lag_model_class lag_stick_model, lag_manipulator_model, lag_dipc_model, lag_cartpole_model,
    lag_flying_stick_model;
const lag_model_class *const lag_models[] = {
    [LAG_MODEL_STICK] = &lag_stick_model,
    [LAG_MODEL_MANIPULATOR] = &lag_manipulator_model,
    [LAG_MODEL_DIPC] = &lag_dipc_model,
    [LAG_MODEL_CARTPOLE] = &lag_cartpole_model,
    [LAG_MODEL_FLYING_STICK] = &lag_flying_stick_model,
};
_Static_assert(sizeof lag_models / sizeof lag_models[0] == LAG_MODEL_COUNT,
               "the model table needs one row per lag_model_kind");

const lag_model_info *lag_model_info_get(lag_model_kind kind)
{
    if ((int)kind < 0 || kind >= LAG_MODEL_COUNT) return NULL;
    return lag_models[kind]->info;
}

const lag_model_info *lag_model_info_by_joints(const char *const *names, int n)
{
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        const lag_model_info *info = lag_models[k]->info;
        bool same = info->nq == n;
        for (int i = 0; same && i < n; i++) same = names[i] && strcmp(info->joint_names[i], names[i]) == 0;
        if (same) return info;
    }
    return NULL;
}

int lag_model_kind_from_name(const char *name)
{
    for (int k = 0; k < LAG_MODEL_COUNT; k++)
        if (name && strcmp(name, lag_models[k]->info->name) == 0) return k;
    return -1;
}

const char *lag_model_names(char *buf, size_t len)
{
    size_t used = 0;
    if (!buf || len == 0) return buf;
    buf[0] = '\0';
    for (int k = 0; k < LAG_MODEL_COUNT && used < len; k++) {
        int w = snprintf(buf + used, len - used, "%s%s", k ? ", " : "", lag_models[k]->info->name);
        if (w < 0) break;
        used += (size_t)w;
    }
    return buf;
}

int lag_model_param_index(lag_model_kind kind, const char *name)
{
    const lag_model_info *info = lag_model_info_get(kind);
    if (!info || !name) return -1;
    for (int i = 0; i < info->np; i++)
        if (strcmp(name, info->param_names[i]) == 0) return i;
    return -1;
}


void lag_model_default_unfinished(lag_model *m, lag_model_kind kind)
{
    const lag_model_info *info = lag_models[kind]->info;
    memset(m, 0, sizeof *m);
    m->kind = kind;
    m->nq = info->nq;
    for (int i = 0; i < info->np; i++) m->p[i] = info->param_defaults[i];
}

/* Uniform rod inertia about its centre, m l^2 / 12, for each rod's inertia still NaN. */
void lag_model_finish(lag_model *m)
{
    const lag_model_info *info = lag_model_info_get(m->kind);
    if (!info) return;
    double *p = m->p;
    for (int r = 0; r < info->n_rods; r++) {
        const lag_rod *rod = &info->rods[r];
        if (isnan(p[rod->inertia])) p[rod->inertia] = p[rod->mass] * p[rod->length] * p[rod->length] / 12.0;
    }
}

void lag_model_default(lag_model *m, lag_model_kind kind)
{
    lag_model_default_unfinished(m, kind);
    lag_model_finish(m);
}

lag_result lag_diag_fail(lag_diag *d, const char *field, const char *fmt, ...)
{
    if (!d) return LAG_ERR_ARG;
    snprintf(d->field, sizeof d->field, "%s", field ? field : "");
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->message, sizeof d->message, fmt, ap);
    va_end(ap);
    return LAG_ERR_ARG;
}

void lag_diag_format(const lag_diag *d, char *err, size_t errlen)
{
    if (!err || errlen == 0) return;
    if (d->field[0]) snprintf(err, errlen, "%s: %s", d->field, d->message);
    else snprintf(err, errlen, "%s", d->message);
}

lag_result lag_model_check(const lag_model *m, lag_diag *d)
{
    const lag_model_info *info = lag_model_info_get(m->kind);
    if (!info) return lag_diag_fail(d, "model", "unknown model kind %d", (int)m->kind);
    if (m->nq != info->nq)
        return lag_diag_fail(d, "model", "%s has %d coordinates, not %d", info->name,
                             info->nq, m->nq);
    for (int i = 0; i < info->np; i++) {
        double v = m->p[i];
        char field[LAG_FIELD_MAX];
        snprintf(field, sizeof field, "parameters.%s", info->param_names[i]);
        if (!isfinite(v)) return lag_diag_fail(d, field, "expected a finite number, got %g", v);
        switch (info->param_rules[i]) {
        case LAG_PARAM_POSITIVE:
            if (!(v > 0))
                return lag_diag_fail(d, field, "expected a number > 0 (%s), got %g",
                                     info->param_units[i], v);
            break;
        case LAG_PARAM_NONNEGATIVE:
            if (!(v >= 0))
                return lag_diag_fail(d, field, "expected a number >= 0 (%s), got %g",
                                     info->param_units[i], v);
            break;
        case LAG_PARAM_ANY:
            break;
        }
    }
    return LAG_OK;
}

lag_result lag_model_validate(const lag_model *m, char *err, size_t errlen)
{
    lag_diag d;
    lag_result r = lag_model_check(m, &d);
    if (r != LAG_OK) lag_diag_format(&d, err, errlen);
    return r;
}

void lag_model_mass(const lag_model *m, const double *q, double *M)
{
    lag_models[m->kind]->mass(m->p, q, M);
}

void lag_model_mass_deriv(const lag_model *m, const double *q, double *dM)
{
    lag_models[m->kind]->mass_deriv(m->p, q, dM);
}

void lag_model_coriolis(const lag_model *m, const double *q, const double *qd, double *C)
{
    lag_models[m->kind]->coriolis(m->p, q, qd, C);
}

void lag_model_gravity(const lag_model *m, const double *q, double *g)
{
    lag_models[m->kind]->gravity(m->p, q, g);
}

void lag_model_bias(const lag_model *m, const double *q, const double *qd, double *h)
{
    double M[LAG_MAX_DOF * LAG_MAX_DOF];
    lag_models[m->kind]->mass_bias(m->p, q, qd, M, h);
}

double lag_model_kinetic(const lag_model *m, const double *q, const double *qd)
{
    return lag_models[m->kind]->kinetic(m->p, q, qd);
}

double lag_model_potential(const lag_model *m, const double *q)
{
    return lag_models[m->kind]->potential(m->p, q);
}

lag_result lag_spd_solve(int n, const double *A, const double *b, double *x)
{
    LAG_ASSERT(n >= 1 && n <= LAG_MAX_STATE);
    if (n == 3) return lag_spd_solve3(A, b, x);
    if (n == 2) return lag_spd_solve2(A, b, x);
    double L[LAG_MAX_STATE * LAG_MAX_STATE];
    /* Cholesky A = L L^T, lower triangle only. */
    for (int j = 0; j < n; j++) {
        double d = A[j * n + j];
        for (int k = 0; k < j; k++) d -= L[j * n + k] * L[j * n + k];
        if (!(d > 0.0)) return LAG_ERR_SINGULAR; /* also catches NaN */
        double ljj = sqrt(d);
        L[j * n + j] = ljj;
        for (int i = j + 1; i < n; i++) {
            double s = A[i * n + j];
            for (int k = 0; k < j; k++) s -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = s / ljj;
        }
    }
    double y[LAG_MAX_STATE];
    for (int i = 0; i < n; i++) {
        double s = b[i];
        for (int k = 0; k < i; k++) s -= L[i * n + k] * y[k];
        y[i] = s / L[i * n + i];
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = y[i];
        for (int k = i + 1; k < n; k++) s -= L[k * n + i] * x[k];
        x[i] = s / L[i * n + i];
    }
    return LAG_OK;
}

lag_result lag_lu_solve_inplace(int n, double *A, double *b)
{
    LAG_ASSERT(n >= 1 && n <= 4 * LAG_MAX_STATE);
    for (int k = 0; k < n; k++) {
        int piv = k;
        double best = fabs(A[k * n + k]);
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > best) { best = fabs(A[i * n + k]); piv = i; }
        if (!(best > 0.0)) return LAG_ERR_SINGULAR;
        if (piv != k) {
            for (int j = 0; j < n; j++) {
                double t = A[k * n + j]; A[k * n + j] = A[piv * n + j]; A[piv * n + j] = t;
            }
            double t = b[k]; b[k] = b[piv]; b[piv] = t;
        }
        for (int i = k + 1; i < n; i++) {
            double f = A[i * n + k] / A[k * n + k];
            A[i * n + k] = f;
            for (int j = k + 1; j < n; j++) A[i * n + j] -= f * A[k * n + j];
            b[i] -= f * b[k];
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = b[i];
        for (int j = i + 1; j < n; j++) s -= A[i * n + j] * b[j];
        b[i] = s / A[i * n + i];
    }
    return LAG_OK;
}

lag_result lag_model_forward(const lag_model *m, const double *q, const double *qd,
                             const double *tau, double *qdd)
{
    static const double zero[LAG_MAX_DOF] = {0};
    if (!tau) tau = zero;
    lag_result r = lag_models[m->kind]->forward(m->p, q, qd, tau, qdd);
    /* a NaN or Inf argument also fails the pivot test: say which it was */
    if (r == LAG_ERR_SINGULAR && !(lag_state_ok(m->nq, q, INFINITY) &&
                                   lag_state_ok(m->nq, qd, INFINITY) &&
                                   lag_state_ok(m->nq, tau, INFINITY)))
        r = LAG_ERR_NONFINITE;
    return r;
}

bool lag_state_ok(int n, const double *x, double limit)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i]) || fabs(x[i]) > limit) return false;
    return true;
}

lag_result lag_state_check(int n, const double *x, double limit)
{
    if (lag_state_ok(n, x, limit)) return LAG_OK;
    return lag_state_ok(n, x, INFINITY) ? LAG_ERR_EXPLODE : LAG_ERR_NONFINITE;
}
