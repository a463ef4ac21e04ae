/*
 * The model's dynamics for controllers (lagsim_client.h, "the model's dynamics"): the
 * scene's model and parameters made into the core's lag_model, then the core's own closed
 * forms (server/core/model_*.c, compiled into this library as the core is compiled), so
 * that a controller computes M(q) and h(q, qd) exactly as the daemon's step does. The
 * core's structs stay inside: the interface is the scene handle and plain arrays.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_client.h"

static lag_result fail(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static lag_result fail(char *err, size_t errlen, const char *fmt, ...)
{
    if (err && errlen > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return LAG_ERR_ARG;
}

/* The model whose coordinates the scene's joints are: the scene's model, or (a stick whose
 * floor lets it fly publishes x, phi, h) the model of the core's table with those joints. */
static const lag_model_info *scene_info(const lag_client_scene *sc, char *err, size_t errlen)
{
    const char *name = lag_client_scene_model(sc);
    int kind = lag_model_kind_from_name(name);
    if (kind < 0) {
        char known[256];
        fail(err, errlen, "scene model '%s' is not one this library knows (%s)", name,
             lag_model_names(known, sizeof known));
        return NULL;
    }
    const lag_model_info *info = lag_model_info_get((lag_model_kind)kind);
    int n = lag_client_scene_num_joints(sc);
    const char *names[LAG_CLIENT_MAX_JOINTS];
    bool same = n == info->nq;
    for (int i = 0; i < n && i < LAG_CLIENT_MAX_JOINTS; i++) {
        names[i] = lag_client_scene_joint_name(sc, i);
        same = same && strcmp(names[i], info->joint_names[i]) == 0;
    }
    if (same) return info;
    const lag_model_info *by = n <= LAG_CLIENT_MAX_JOINTS ? lag_model_info_by_joints(names, n) : NULL;
    if (by && by->np == info->np) return by; /* the same parameters: the stick in flight */
    fail(err, errlen, "scene model %s: its %d joints are not those of a model this library knows",
         name, n);
    return NULL;
}

/* The scene's model with its parameters, checked; n must be its number of coordinates. */
static lag_result scene_model(const lag_client_scene *sc, int n, lag_model *m, char *err,
                              size_t errlen)
{
    if (err && errlen > 0) err[0] = '\0';
    if (!sc) return fail(err, errlen, "no scene");
    const lag_model_info *info = scene_info(sc, err, errlen);
    if (!info) return LAG_ERR_ARG;
    if (n != info->nq)
        return fail(err, errlen, "scene model %s has %d coordinates (%s%s%s%s%s), not %d", info->name,
                    info->nq, info->joint_names[0], info->nq > 1 ? ", " : "",
                    info->nq > 1 ? info->joint_names[1] : "", info->nq > 2 ? ", " : "",
                    info->nq > 2 ? info->joint_names[2] : "", n);
    lag_model_default_unfinished(m, (lag_model_kind)lag_model_kind_from_name(info->name));
    for (int i = 0; i < info->np; i++) {
        double v = lag_client_scene_param(sc, info->param_names[i]);
        if (isnan(v))
            return fail(err, errlen, "scene model %s has no parameter %s", info->name,
                        info->param_names[i]);
        m->p[i] = v;
    }
    lag_model_finish(m);
    char why[200];
    if (lag_model_validate(m, why, sizeof why) != LAG_OK)
        return fail(err, errlen, "scene model %s: %s", info->name, why);
    return LAG_OK;
}

static lag_result finite_in(int n, const double *x, const char *what, char *err, size_t errlen)
{
    if (!x) return fail(err, errlen, "%s is NULL", what);
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i])) return fail(err, errlen, "%s[%d] is not finite", what, i);
    return LAG_OK;
}

lag_result lag_client_model_mass(const lag_client_scene *sc, int n, const double *q, double *M,
                                 char *err, size_t errlen)
{
    lag_model m;
    lag_result rc = scene_model(sc, n, &m, err, errlen);
    if (rc == LAG_OK) rc = finite_in(n, q, "q", err, errlen);
    if (rc == LAG_OK && !M) rc = fail(err, errlen, "M is NULL");
    if (rc != LAG_OK) return rc;
    lag_model_mass(&m, q, M);
    return LAG_OK;
}

lag_result lag_client_model_bias(const lag_client_scene *sc, int n, const double *q,
                                 const double *qd, double *h, char *err, size_t errlen)
{
    lag_model m;
    lag_result rc = scene_model(sc, n, &m, err, errlen);
    if (rc == LAG_OK) rc = finite_in(n, q, "q", err, errlen);
    if (rc == LAG_OK) rc = finite_in(n, qd, "qd", err, errlen);
    if (rc == LAG_OK && !h) rc = fail(err, errlen, "h is NULL");
    if (rc != LAG_OK) return rc;
    lag_model_bias(&m, q, qd, h);
    return LAG_OK;
}
