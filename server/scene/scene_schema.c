/*
 * The scene schema: the merged YAML tree -> lag_scene, checked once.
 *
 * Every key is a row of a small table (k_top_keys, k_integrator_keys, ...) whose handler
 * reads its node; adding a key is one row and one handler. Every number has a range,
 * written next to its key as a `range` (with its unit and the reason for its bounds), and
 * relations between keys (1/publish_hz a multiple of dt, a stop inside explode_limit, a
 * force lasting at least one tick...) are checked where the second value is read. Errors
 * name the node: "file:line:column: key.path: what was expected" for the file, "--set
 * key: ..." for an override. Nothing is guessed: unknown keys, wrong types, missing
 * values, numbers written any other way than plain decimals, and values out of range
 * are errors.
 *
 * Order: `model` first (parameters, joint names and the length of q depend on it), then
 * the keys other values are measured against (integrator, publish_hz, explode_limit),
 * then every other key in file order. Models, their parameters and their joints come from
 * the core's lag_model_info; integrators from lag_method_from_name and lag_method_names.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_num.h"
#include "scene_keys.h"
#include "scene_schema.h"

/* ================================================================ ranges */

/* Fewest and most integrator ticks in one control period: one period is one call into
 * the core (fast mode runs periods back to back), so it must stay short. */
#define TICKS_MAX 100000
/* Control periods per wall second at most in real-time mode (publish_hz * rate). */
#define PERIODS_PER_S_MAX 10000.0

static const range R_DT = {1e-6, 1.0, false, "s"};           /* above: resolves no motion of these models; below: see T_MAX */
static const range R_RTOL = {1e-14, 0.1, false, NULL};      /* below ~50 eps no step can meet it */
static const range R_ATOL = {1e-14, 1.0, false, "m, rad, m/s or rad/s"};
static const range R_DT_MIN = {1e-15, 1.0, false, "s"};      /* and <= dt */
static const range R_NEWTON_TOL = {1e-15, 0.1, false, NULL}; /* scaled update: ~5 eps at best */
static const range R_ERROR = {1e-12, 0.1, false, "m or rad"}; /* below: the reference's own error */
static const range R_HORIZON = {1e-3, 100.0, false, "s"};      /* and >= one period, <= 1e6 periods */
static const range R_PUBLISH_HZ = {0.01, 10000.0, false, "Hz"}; /* and 1/publish_hz = k dt, k <= TICKS_MAX */
static const range R_EXPLODE = {1e-6, 1e9, false, "m, rad, m/s or rad/s"};
static const range R_RATE = {1e-3, 1e3, false, "sim s per wall s"};
static const range R_LOCKSTEP_TIMEOUT = {1e-3, 3600.0, false, "wall s"};
static const range R_LOCKSTEP_RETRY = {1e-3, 3600.0, false, "wall s"}; /* as the timeout */
static const range R_STATUS_HZ = {0.1, 100.0, false, "Hz"};

/* The magnitude of a physical parameter, by its unit in lag_model_info (a new model with
 * these units needs no code here): masses from a milligram to a thousand tonnes, lengths
 * from a micrometre to a thousand km, inertias spanning m l^2 / 12 of those, gravity up to
 * 100 g. A parameter may also be exactly 0. Which signs, and whether 0, a parameter may
 * take is the core's rule (lag_model_check: masses > 0, g >= 0, a height h0 any...).
 * Other units: magnitude at most F_MAX. */
static const struct {
    const char *unit;
    double lo, hi;
} k_param_windows[] = {
    {"kg", 1e-6, 1e6},
    {"m", 1e-6, 1e6},
    {"kg m^2", 1e-20, 1e18},
    {"m/s^2", 1e-6, 1e3},
};

/* Joins "parent.key" into buf. */
const char *sch_join(char *buf, size_t len, const char *parent, const char *key)
{
    if (parent && parent[0])
        snprintf(buf, len, "%s.%s", parent, key);
    else
        snprintf(buf, len, "%s", key);
    return buf;
}

/* Lists the names of a key table: "a, b, c". */
static void list_keys(char *buf, size_t len, const keyrow *rows)
{
    buf[0] = '\0';
    for (const keyrow *r = rows; r->name; r++) {
        size_t used = strlen(buf);
        snprintf(buf + used, len - used, "%s%s", r == rows ? "" : ", ", r->name);
    }
}

/* nd must be a mapping; `what` describes it ("a mapping (keys: a, b)"). */
int sch_need_map(conv *cv, const ynode *nd, const char *path, const char *what)
{
    if (nd->kind == YN_MAP)
        return 0;
    if (ynode_is_null(nd))
        return yfail(cv->err, nd, path, "missing value: expected %s", what);
    return yfail(cv->err, nd, path, "expected %s, got %s", what, ynode_kind_name(nd));
}

/* Walks a mapping's entries in file order and dispatches each to its table row, skipping
 * the keys listed in `skip` (read before). */
static int sch_convert_map_skip(conv *cv, const ynode *nd, const char *path,
                                const keyrow *rows, const char *what,
                                const char *const *skip)
{
    if (nd->kind != YN_MAP) {
        char allowed[512], expected[600];
        list_keys(allowed, sizeof allowed, rows);
        snprintf(expected, sizeof expected, "a mapping (keys: %s)", allowed);
        return sch_need_map(cv, nd, path, expected);
    }
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        bool skipped = false;
        for (int k = 0; skip && skip[k]; k++)
            skipped |= strcmp(skip[k], en->key) == 0;
        if (skipped)
            continue;
        const keyrow *r = rows;
        while (r->name && strcmp(r->name, en->key) != 0)
            r++;
        if (!r->name) {
            char allowed[512];
            list_keys(allowed, sizeof allowed, rows);
            return yfail_key(cv->err, en, "unknown %s '%s'%s%s; allowed: %s", what, en->key,
                             path[0] ? " in " : "", path, allowed);
        }
        char sub[256];
        if (r->fn(cv, en->val, sch_join(sub, sizeof sub, path, en->key)) < 0)
            return -1;
    }
    return 0;
}

int sch_convert_map(conv *cv, const ynode *nd, const char *path, const keyrow *rows,
                    const char *what)
{
    return sch_convert_map_skip(cv, nd, path, rows, what, NULL);
}

/* ================================================================ scalars */

/* A finite number written as a plain decimal scalar. */
int sch_get_number(conv *cv, const ynode *nd, const char *path, double *out)
{
    if (ynode_is_null(nd))
        return yfail(cv->err, nd, path, "missing value: expected a number");
    if (nd->kind != YN_SCALAR)
        return yfail(cv->err, nd, path, "expected a number, got %s", ynode_kind_name(nd));
    if (nd->quoted)
        return yfail(cv->err, nd, path, "expected a number, got the quoted string \"%s\"",
                     nd->text);
    const char *t = nd->text;
    const char *u = (t[0] == '+' || t[0] == '-') ? t + 1 : t;
    /* YAML's own spellings of infinity and NaN */
    if (strcmp(u, ".inf") == 0 || strcmp(u, ".Inf") == 0 || strcmp(u, ".INF") == 0 ||
        strcmp(t, ".nan") == 0 || strcmp(t, ".NaN") == 0 || strcmp(t, ".NAN") == 0)
        return yfail(cv->err, nd, path, "expected a finite number, got %s", t);
    double v;
    lag_result r = lag_scene_read_decimal(t, &v);
    if (r == LAG_ERR_RANGE)
        return yfail(cv->err, nd, path, "expected a finite number, got %s", t); /* 1e999 */
    if (r != LAG_OK)
        return yfail(cv->err, nd, path, "expected a number, got '%s'", t);
    *out = v;
    return 0;
}

/* "from 1e-06 to 1 (s)" or "> 0 and <= 1e+12 (N)" */
static void describe_range(char *buf, size_t len, double lo, double hi, bool lo_open,
                           const char *unit)
{
    char u[64] = "";
    if (unit)
        snprintf(u, sizeof u, " (%s)", unit);
    if (lo_open)
        snprintf(buf, len, "> %.6g and <= %.6g%s", lo, hi, u);
    else
        snprintf(buf, len, "from %.6g to %.6g%s", lo, hi, u);
}

/* A number in [lo, hi] (or (lo, hi]). */
int sch_get_in(conv *cv, const ynode *nd, const char *path, double lo, double hi,
               bool lo_open, const char *unit, double *out)
{
    double v = 0.0;
    if (sch_get_number(cv, nd, path, &v) < 0)
        return -1;
    if (!(lo_open ? v > lo : v >= lo) || !(v <= hi)) {
        char r[160];
        describe_range(r, sizeof r, lo, hi, lo_open, unit);
        return yfail(cv->err, nd, path, "expected a number %s, got %s", r, nd->text);
    }
    *out = v;
    return 0;
}

int sch_get_range(conv *cv, const ynode *nd, const char *path, const range *r,
                  double *out)
{
    return sch_get_in(cv, nd, path, r->lo, r->hi, r->lo_open, r->unit, out);
}

/* A number whose sign (and whether it may be 0) is the core's rule: 0, or a magnitude in
 * r's window. The window keeps what the scene can say representable; lag_sim_def_check
 * refuses a wrong sign with its own message, which the loader reports at the key. */
int sch_get_magnitude(conv *cv, const ynode *nd, const char *path, const range *r,
                      double *out)
{
    double v = 0.0;
    if (sch_get_number(cv, nd, path, &v) < 0)
        return -1;
    double a = fabs(v);
    if (v != 0.0 && (!(r->lo_open ? a > r->lo : a >= r->lo) || !(a <= r->hi))) {
        char u[64] = "";
        if (r->unit)
            snprintf(u, sizeof u, " (%s)", r->unit);
        if (r->lo == 0.0)
            return yfail(cv->err, nd, path, "expected a magnitude of at most %.6g%s, got %s",
                         r->hi, u, nd->text);
        return yfail(cv->err, nd, path, "expected a magnitude from %.6g to %.6g%s, got %s",
                     r->lo, r->hi, u, nd->text);
    }
    *out = v;
    return 0;
}

/* An integer in [lo, hi], written as plain decimal digits. */
int sch_get_int(conv *cv, const ynode *nd, const char *path, long long lo, long long hi,
                long long *out)
{
    if (ynode_is_null(nd))
        return yfail(cv->err, nd, path, "missing value: expected an integer");
    if (nd->kind != YN_SCALAR)
        return yfail(cv->err, nd, path, "expected an integer, got %s", ynode_kind_name(nd));
    if (nd->quoted)
        return yfail(cv->err, nd, path, "expected an integer, got the quoted string \"%s\"",
                     nd->text);
    const char *t = nd->text, *d = (t[0] == '+' || t[0] == '-') ? t + 1 : t;
    bool digits = d[0] != '\0';
    for (const char *p = d; *p; p++)
        digits &= *p >= '0' && *p <= '9';
    if (!digits)
        return yfail(cv->err, nd, path, "expected an integer, got '%s'", t);
    errno = 0;
    long long v = strtoll(t, NULL, 10);
    if (errno == ERANGE || v < lo || v > hi)
        return yfail(cv->err, nd, path, "expected an integer from %lld to %lld, got %s", lo,
                     hi, t);
    *out = v;
    return 0;
}

/* A string scalar (quoted or plain). */
int sch_get_string(conv *cv, const ynode *nd, const char *path, const char *what,
                   const char **out)
{
    *out = NULL; /* set on every path: callers read it only on success, and an optimizer that
                  * cannot see yfail's -1 (another file) must not find it unset */
    if (ynode_is_null(nd))
        return yfail(cv->err, nd, path, "missing value: expected %s", what);
    if (nd->kind != YN_SCALAR)
        return yfail(cv->err, nd, path, "expected %s, got %s", what, ynode_kind_name(nd));
    *out = nd->text;
    return 0;
}

/* A YAML boolean: true/false (also yes/no, on/off as YAML 1.1 spells them), plain. */
int sch_get_bool(conv *cv, const ynode *nd, const char *path, bool *out)
{
    static const char *const yes[] = {"true", "True", "TRUE", "yes", "Yes", "on", "On", NULL};
    static const char *const no[] = {"false", "False", "FALSE", "no", "No", "off", "Off", NULL};
    if (ynode_is_null(nd))
        return yfail(cv->err, nd, path, "missing value: expected true or false");
    if (nd->kind != YN_SCALAR)
        return yfail(cv->err, nd, path, "expected true or false, got %s", ynode_kind_name(nd));
    if (nd->quoted)
        return yfail(cv->err, nd, path, "expected true or false, got the quoted string \"%s\"",
                     nd->text);
    for (int i = 0; yes[i]; i++)
        if (strcmp(nd->text, yes[i]) == 0) { *out = true; return 0; }
    for (int i = 0; no[i]; i++)
        if (strcmp(nd->text, no[i]) == 0) { *out = false; return 0; }
    return yfail(cv->err, nd, path, "expected true or false, got '%s'", nd->text);
}

/* ================================================================ joints */

/* "x, phi" for messages */
void sch_joint_list(const conv *cv, char *buf, size_t len)
{
    buf[0] = '\0';
    for (int i = 0; i < cv->info->nq; i++) {
        size_t used = strlen(buf);
        snprintf(buf + used, len - used, "%s%s", i ? ", " : "", cv->info->joint_names[i]);
    }
}

int sch_joint_index(const conv *cv, const char *name)
{
    for (int i = 0; i < cv->info->nq; i++)
        if (strcmp(name, cv->info->joint_names[i]) == 0) return i;
    return -1;
}

/* Walks a mapping {joint name: value} and calls fn for each joint. */
int sch_per_joint(conv *cv, const ynode *nd, const char *path, joint_fn fn)
{
    char names[128], what[160];
    sch_joint_list(cv, names, sizeof names);
    snprintf(what, sizeof what, "a mapping of joints (%s)", names);
    if (sch_need_map(cv, nd, path, what) < 0)
        return -1;
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        int j = sch_joint_index(cv, en->key);
        if (j < 0)
            return yfail_key(cv->err, en, "unknown joint '%s' in %s for model %s; allowed: %s",
                             en->key, path, cv->info->name, names);
        char sub[256];
        if (fn(cv, j, en->val, sch_join(sub, sizeof sub, path, en->key)) < 0)
            return -1;
    }
    return 0;
}

/* Joint j takes an input (a command, an actuator). */
int sch_need_actuated(conv *cv, int j, const ynode *nd, const char *path)
{
    if (!cv->info->actuated[j])
        return yfail(cv->err, nd, path, "joint %s of model %s takes no input",
                     cv->info->joint_names[j], cv->info->name);
    return 0;
}

/* The scene's explode_limit (read in the first pass), as a bound on the magnitude of a
 * position, velocity or noise amplitude: a value beyond it can never be part of a valid
 * state. A sign the value must have is the core's rule. */
int sch_get_within_explode(conv *cv, const ynode *nd, const char *path, double *out)
{
    double lim = fabs(cv->sc->sim.explode_limit); /* its own sign: the core's check */
    double v = 0.0;
    if (sch_get_number(cv, nd, path, &v) < 0)
        return -1;
    if (!(fabs(v) <= lim))
        return yfail(cv->err, nd, path, "expected a number from %.6g to %.6g (explode_limit%s), "
                     "got %s", -lim, lim, cv->explode_limit ? "" : ", default", nd->text);
    *out = v;
    return 0;
}

/* ================================================================ model, parameters */

static int key_model(conv *cv, const ynode *val, const char *path)
{
    (void)cv; (void)val; (void)path; /* read first: see scene_schema_convert */
    return 0;
}

static int key_parameters(conv *cv, const ynode *nd, const char *path)
{
    const lag_model_info *info = cv->info;
    lag_model *m = &cv->sc->sim.model;
    char allowed[256] = "";
    for (int i = 0; i < info->np; i++) {
        size_t used = strlen(allowed);
        snprintf(allowed + used, sizeof allowed - used, "%s%s", i ? ", " : "",
                 info->param_names[i]);
    }
    char what[300];
    snprintf(what, sizeof what, "a mapping (keys: %s)", allowed);
    if (sch_need_map(cv, nd, path, what) < 0)
        return -1;
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        int k = lag_model_param_index(m->kind, en->key);
        if (k < 0)
            return yfail_key(cv->err, en, "unknown parameter '%s' for model %s; allowed: %s",
                             en->key, info->name, allowed);
        char sub[256];
        sch_join(sub, sizeof sub, path, en->key);
        const char *unit = info->param_units[k] ? info->param_units[k] : "SI";
        double lo = 0.0, hi = F_MAX, v = 0.0;
        for (size_t w = 0; w < sizeof k_param_windows / sizeof k_param_windows[0]; w++) {
            if (strcmp(unit, k_param_windows[w].unit) == 0) {
                lo = k_param_windows[w].lo;
                hi = k_param_windows[w].hi;
            }
        }
        if (sch_get_number(cv, en->val, sub, &v) < 0)
            return -1;
        if (v != 0.0 && !(fabs(v) >= lo && fabs(v) <= hi))
            return yfail(cv->err, en->val, sub,
                         "expected a magnitude from %.6g to %.6g (%s), got %s", lo, hi, unit,
                         en->val->text);
        m->p[k] = v; /* sign and zero: the core's check */
    }
    return 0;
}

/* ================================================================ initial */

static int get_vector(conv *cv, const ynode *nd, const char *path, double *out)
{
    const lag_model_info *info = cv->info;
    int nq = info->nq;
    char names[128];
    sch_joint_list(cv, names, sizeof names);
    if (ynode_is_null(nd))
        return yfail(cv->err, nd, path, "missing value: expected a sequence of %d numbers (%s)",
                     nq, names);
    if (nd->kind != YN_SEQ)
        return yfail(cv->err, nd, path, "expected a sequence of %d numbers (%s), got %s", nq,
                     names, ynode_kind_name(nd));
    if (nd->n != nq)
        return yfail(cv->err, nd, path,
                     "expected a sequence of %d numbers (%s) for model %s, got %d", nq, names,
                     info->name, nd->n);
    for (int i = 0; i < nq; i++) {
        char sub[256];
        snprintf(sub, sizeof sub, "%s[%d]", path, i);
        if (sch_get_number(cv, nd->items[i], sub, &out[i]) < 0) /* within explode_limit: the core's check */
            return -1;
    }
    return 0;
}

static int key_q(conv *cv, const ynode *nd, const char *path)
{
    return get_vector(cv, nd, path, cv->sc->sim.q0);
}

static int key_qd(conv *cv, const ynode *nd, const char *path)
{
    return get_vector(cv, nd, path, cv->sc->sim.qd0);
}

static const keyrow k_initial_keys[] = {
    {"q", key_q, K_VECTOR},   /* rad or m, per coordinate, within explode_limit */
    {"qd", key_qd, K_VECTOR}, /* rad/s or m/s, within explode_limit */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_initial(conv *cv, const ynode *nd, const char *path)
{
    return sch_convert_map(cv, nd, path, k_initial_keys, "key");
}

/* ================================================================ integrator */

static int key_method(conv *cv, const ynode *nd, const char *path)
{
    char allowed[256];
    lag_method_names(allowed, sizeof allowed);
    char what[300];
    snprintf(what, sizeof what, "a method (%s)", allowed);
    const char *s;
    if (sch_get_string(cv, nd, path, what, &s) < 0)
        return -1;
    int m = lag_method_from_name(s);
    if (m < 0)
        return yfail(cv->err, nd, path, "unknown method '%s'; allowed: %s", s, allowed);
    cv->sc->sim.integrator.method = (lag_method)m;
    return 0;
}

static int key_dt(conv *cv, const ynode *nd, const char *path)
{
    cv->dt = nd;
    return sch_get_magnitude(cv, nd, path, &R_DT, &cv->sc->sim.integrator.dt);
}

static int key_rtol(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_RTOL, &cv->sc->sim.integrator.rtol);
}

static int key_atol(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_ATOL, &cv->sc->sim.integrator.atol);
}

static int key_dt_min(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_DT_MIN, &cv->sc->sim.integrator.dt_min);
}

static int key_max_iter(conv *cv, const ynode *nd, const char *path)
{
    long long v = 0;
    if (sch_get_int(cv, nd, path, INT_MIN, INT_MAX, &v) < 0) /* 1..1000: the core's check */
        return -1;
    cv->sc->sim.integrator.max_iter = (int)v;
    return 0;
}

/* dopri5's work per tick is bounded by max_steps: at most 1e6 (about a second of CPU) */
static int key_max_steps(conv *cv, const ynode *nd, const char *path)
{
    long long v = 0;
    if (sch_get_int(cv, nd, path, INT_MIN, INT_MAX, &v) < 0) /* >= 1: the core's check */
        return -1;
    if (v > 1000000)
        return yfail(cv->err, nd, path, "expected an integer of at most 1000000 (steps per "
                     "tick), got %s", nd->text);
    cv->sc->sim.integrator.max_steps = (int)v;
    return 0;
}

static int key_newton_tol(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_magnitude(cv, nd, path, &R_NEWTON_TOL, &cv->sc->sim.integrator.newton_tol);
}

/* integrator.error: the largest difference from the exact q over integrator.horizon that
 * the run may have; the daemon then chooses method and dt itself (lagsimd's calibration) */
static int key_error(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_range(cv, nd, path, &R_ERROR, &cv->sc->accuracy.error);
}

static int key_horizon(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_range(cv, nd, path, &R_HORIZON, &cv->sc->accuracy.horizon);
}

/* integrator.estimate_every: the live error estimate's shadow run every N periods (0: off) */
static int key_estimate_every(conv *cv, const ynode *nd, const char *path)
{
    long long v = 0;
    if (sch_get_int(cv, nd, path, 0, 1000000, &v) < 0)
        return -1;
    cv->sc->accuracy.estimate_every = (int)v;
    return 0;
}

static const keyrow k_integrator_keys[] = {
    {"method", key_method, K_OTHER},         /* euler | semi-implicit-euler | rk4 | dopri5 | ... */
    {"dt", key_dt, K_NUMBER},                 /* s */
    {"rtol", key_rtol, K_NUMBER},             /* dopri5 */
    {"atol", key_atol, K_NUMBER},             /* dopri5 */
    {"dt_min", key_dt_min, K_NUMBER},         /* dopri5, s, <= dt */
    {"max_iter", key_max_iter, K_INTEGER},     /* implicit methods, 1..1000 */
    {"max_steps", key_max_steps, K_INTEGER},   /* dopri5, steps per tick, 1..1e6 */
    {"newton_tol", key_newton_tol, K_NUMBER}, /* implicit methods */
    {"error", key_error, K_NUMBER},           /* m or rad over horizon: chooses method, dt */
    {"horizon", key_horizon, K_NUMBER},       /* s, the error's horizon (1) */
    {"estimate_every", key_estimate_every, K_INTEGER}, /* periods between live error estimates */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_integrator(conv *cv, const ynode *nd, const char *path)
{
    cv->integrator = nd;
    return sch_convert_map(cv, nd, path, k_integrator_keys, "key");
}

/* ================================================================ rates, limits */

static int key_publish_hz(conv *cv, const ynode *nd, const char *path)
{
    cv->publish_hz = nd;
    return sch_get_range(cv, nd, path, &R_PUBLISH_HZ, &cv->sc->publish_hz);
}

static int key_explode_limit(conv *cv, const ynode *nd, const char *path)
{
    cv->explode_limit = nd;
    return sch_get_magnitude(cv, nd, path, &R_EXPLODE, &cv->sc->sim.explode_limit);
}

/* ================================================================ realtime */

static int key_mode(conv *cv, const ynode *nd, const char *path)
{
    const char *s;
    if (sch_get_string(cv, nd, path, "a mode (realtime, fast, lockstep)", &s) < 0)
        return -1;
    for (int m = LAG_RT_REALTIME; m <= LAG_RT_LOCKSTEP; m++) {
        if (strcmp(s, lag_rt_mode_name((lag_rt_mode)m)) == 0) {
            cv->sc->realtime.mode = (lag_rt_mode)m;
            return 0;
        }
    }
    return yfail(cv->err, nd, path, "unknown mode '%s'; allowed: realtime, fast, lockstep", s);
}

static int key_rate(conv *cv, const ynode *nd, const char *path)
{
    cv->rate = nd;
    return sch_get_range(cv, nd, path, &R_RATE, &cv->sc->realtime.rate);
}

/* At least one control period: a shorter timeout would zero the command of a controller
 * that answers every period before its next answer can arrive. */
static int key_command_timeout(conv *cv, const ynode *nd, const char *path)
{
    double period = (double)cv->sc->ticks_per_period * cv->sc->sim.integrator.dt;
    if (sch_get_number(cv, nd, path, &cv->sc->realtime.command_timeout) < 0)
        return -1;
    double v = cv->sc->realtime.command_timeout;
    if (!(v >= period * (1.0 - 1e-9)) || !(v <= T_MAX))
        return yfail(cv->err, nd, path, "expected a number from %.6g (one control period, "
                     "1/publish_hz) to %.6g (sim s), got %s", period, T_MAX, nd->text);
    return 0;
}

static int key_lockstep_timeout(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_range(cv, nd, path, &R_LOCKSTEP_TIMEOUT, &cv->sc->realtime.lockstep_timeout);
}

static int key_lockstep_retry(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_range(cv, nd, path, &R_LOCKSTEP_RETRY, &cv->sc->realtime.lockstep_retry);
}

static int key_status_hz(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_range(cv, nd, path, &R_STATUS_HZ, &cv->sc->realtime.status_hz);
}

/* effort_limit: {actuated joint: bound} */
static int effort_limit_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    if (sch_need_actuated(cv, j, nd, path) < 0)
        return -1;
    return sch_get_range(cv, nd, path, &R_EFFORT, &cv->sc->realtime.effort_limit[j]);
}

static int key_effort_limit(conv *cv, const ynode *nd, const char *path)
{
    return sch_per_joint(cv, nd, path, effort_limit_joint);
}

static int key_start(conv *cv, const ynode *nd, const char *path);

static const keyrow k_realtime_keys[] = {
    {"mode", key_mode, K_OTHER},                         /* realtime | fast | lockstep */
    {"start", key_start, K_OTHER},                       /* running | paused | first_command */
    {"rate", key_rate, K_NUMBER},                         /* sim s per wall s */
    {"command_timeout", key_command_timeout, K_NUMBER},   /* sim s */
    {"lockstep_timeout", key_lockstep_timeout, K_NUMBER}, /* wall s */
    {"lockstep_retry", key_lockstep_retry, K_NUMBER},     /* wall s */
    {"status_hz", key_status_hz, K_NUMBER},               /* wall Hz */
    {"effort_limit", key_effort_limit, K_JOINTS},         /* N or N m per actuated joint */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_start(conv *cv, const ynode *nd, const char *path)
{
    const char *s;
    if (sch_get_string(cv, nd, path, "a start (running, paused, first_command)", &s) < 0)
        return -1;
    for (int k = LAG_RT_START_RUNNING; k <= LAG_RT_START_FIRST_COMMAND; k++) {
        if (strcmp(s, lag_rt_start_name((lag_rt_start)k)) == 0) {
            cv->sc->realtime.start = (lag_rt_start)k;
            cv->start = nd;
            return 0;
        }
    }
    return yfail(cv->err, nd, path, "unknown start '%s'; allowed: running, paused, first_command", s);
}

static int key_realtime(conv *cv, const ynode *nd, const char *path)
{
    return sch_convert_map(cv, nd, path, k_realtime_keys, "key");
}

/* ================================================================ lcm */

static int key_url(conv *cv, const ynode *nd, const char *path)
{
    cv->url = nd;
    /* "" (quoted) is allowed: LCM's default URL */
    if (nd->kind == YN_SCALAR && nd->quoted && nd->text[0] == '\0') {
        cv->sc->lcm.url[0] = '\0';
        return 0;
    }
    const char *s;
    if (sch_get_string(cv, nd, path, "an LCM URL (e.g. udpm://239.255.76.67:7667?ttl=0)", &s) < 0)
        return -1;
    if (strlen(s) >= sizeof cv->sc->lcm.url)
        return yfail(cv->err, nd, path, "URL longer than %zu characters",
                     sizeof cv->sc->lcm.url - 1);
    snprintf(cv->sc->lcm.url, sizeof cv->sc->lcm.url, "%s", s);
    return 0; /* checked with lcm.allow_lan once both are read (scene_schema_convert) */
}

static int key_prefix(conv *cv, const ynode *nd, const char *path)
{
    const char *s;
    if (sch_get_string(cv, nd, path, "a channel prefix of [A-Za-z0-9_]", &s) < 0)
        return -1;
    size_t n = strlen(s);
    lag_diag d; /* the rule is the scene's (lag_scene_check), on the length as given */
    if (lag_scene_check_prefix_len(n, &d) != LAG_OK)
        return yfail(cv->err, nd, path, "%s", d.message);
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                  (c >= '0' && c <= '9') || c == '_';
        if (!ok)
            return yfail(cv->err, nd, path,
                         "expected a channel prefix of [A-Za-z0-9_], got '%s' "
                         "(character %zu is '%c')", s, i + 1, c);
    }
    memcpy(cv->sc->lcm.prefix, s, n + 1);
    return 0;
}

static int key_allow_lan(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_bool(cv, nd, path, &cv->sc->lcm.allow_lan);
}

static const keyrow k_lcm_keys[] = {
    {"url", key_url, K_OTHER},             /* "" = LCM's default; udpm:// or memq:// */
    {"prefix", key_prefix, K_OTHER},       /* channel prefix */
    {"allow_lan", key_allow_lan, K_OTHER}, /* bool: traffic may leave this host (ttl > 0) */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int key_lcm(conv *cv, const ynode *nd, const char *path)
{
    return sch_convert_map(cv, nd, path, k_lcm_keys, "key");
}

/* ================================================================ reference */

/* A reference's times and frequencies, as lag_reference_check takes them. */
static const range R_REF_START = {0.0, T_MAX, false, "s"};
static const range R_REF_FREQUENCY = {0.0, 1e6, true, "Hz"};
static const range R_REF_DURATION = {0.0, T_MAX, true, "s"};

/* The keys some kinds take, with their bit of lag_ref_kind_info.keys: which kind takes
 * which key is the reference library's table (lag_ref_kind_table), not written here. */
static const struct {
    const char *name;
    unsigned bit;
} k_ref_key_bits[] = {
    {"frequency", LAG_REF_KEY_FREQUENCY},
    {"frequency_end", LAG_REF_KEY_FREQUENCY_END},
    {"duration", LAG_REF_KEY_DURATION},
    {"points", LAG_REF_KEY_POINTS},
};
#define N_REF_KEY_BITS (sizeof k_ref_key_bits / sizeof k_ref_key_bits[0])

/* "step, ramp, sine, chirp, square, waypoints" */
static void ref_kind_list(char *buf, size_t len)
{
    buf[0] = '\0';
    for (int k = 0; k < LAG_REF_KIND_COUNT; k++) {
        size_t used = strlen(buf);
        snprintf(buf + used, len - used, "%s%s", k ? ", " : "", lag_ref_kind_table[k].name);
    }
}

/* "type, start, amplitude, offset, frequency" : the keys a kind takes */
static void ref_key_list(int kind, char *buf, size_t len)
{
    snprintf(buf, len, "type, start, amplitude, offset");
    for (size_t b = 0; b < N_REF_KEY_BITS; b++)
        if (lag_ref_kind_table[kind].keys & k_ref_key_bits[b].bit) {
            size_t used = strlen(buf);
            snprintf(buf + used, len - used, ", %s", k_ref_key_bits[b].name);
        }
}

/* A key some kinds take: refused for a kind that does not. */
static int ref_key_allowed(conv *cv, const ynode *nd, const char *path, const char *key)
{
    unsigned bit = 0;
    for (size_t b = 0; b < N_REF_KEY_BITS; b++)
        if (strcmp(k_ref_key_bits[b].name, key) == 0) bit = k_ref_key_bits[b].bit;
    cv->cur_ref_seen |= bit;
    int kind = cv->cur_ref_kind;
    if (kind < 0 || (lag_ref_kind_table[kind].keys & bit))
        return 0;
    char keys[256];
    ref_key_list(kind, keys, sizeof keys);
    return yfail(cv->err, nd, path, "a %s reference takes no %s; its keys: %s",
                 lag_ref_kind_table[kind].name, key, keys);
}

static int ref_type(conv *cv, const ynode *nd, const char *path)
{
    (void)cv; (void)nd; (void)path; /* read first: see ref_joint */
    return 0;
}

static int ref_start(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_range(cv, nd, path, &R_REF_START, &cv->cur_ref->start);
}

/* amplitude and offset: a position, within explode_limit */
static int ref_amplitude(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_within_explode(cv, nd, path, &cv->cur_ref->amplitude);
}

static int ref_offset(conv *cv, const ynode *nd, const char *path)
{
    return sch_get_within_explode(cv, nd, path, &cv->cur_ref->offset);
}

static int ref_frequency(conv *cv, const ynode *nd, const char *path)
{
    if (ref_key_allowed(cv, nd, path, "frequency") < 0) return -1;
    return sch_get_range(cv, nd, path, &R_REF_FREQUENCY, &cv->cur_ref->frequency);
}

static int ref_frequency_end(conv *cv, const ynode *nd, const char *path)
{
    if (ref_key_allowed(cv, nd, path, "frequency_end") < 0) return -1;
    return sch_get_range(cv, nd, path, &R_REF_FREQUENCY, &cv->cur_ref->frequency_end);
}

static int ref_duration(conv *cv, const ynode *nd, const char *path)
{
    if (ref_key_allowed(cv, nd, path, "duration") < 0) return -1;
    return sch_get_range(cv, nd, path, &R_REF_DURATION, &cv->cur_ref->duration);
}

/* points: [[t, w], ...], t in s from start (strictly increasing), w a position within
 * explode_limit (r = offset + amplitude w) */
static int ref_points(conv *cv, const ynode *nd, const char *path)
{
    if (ref_key_allowed(cv, nd, path, "points") < 0) return -1;
    lag_reference *ref = cv->cur_ref;
    if (nd->kind != YN_SEQ || nd->n < 1 || nd->n > LAG_REF_MAX_POINTS)
        return yfail(cv->err, nd, path, "expected a sequence of 1 to %d points [t, w] (s from "
                     "start, and the value), got %s", LAG_REF_MAX_POINTS,
                     nd->kind == YN_SEQ ? "more or none" : ynode_kind_name(nd));
    for (int k = 0; k < nd->n; k++) {
        const ynode *it = nd->items[k];
        char sub[256], el[280];
        snprintf(sub, sizeof sub, "%s[%d]", path, k);
        if (it->kind != YN_SEQ || it->n != 2)
            return yfail(cv->err, it, sub, "expected a point [t, w] (two numbers)");
        snprintf(el, sizeof el, "%s[0]", sub);
        if (sch_get_range(cv, it->items[0], el, &R_REF_START, &ref->point_t[k]) < 0) return -1;
        char a[LAG_NUM_LEN], b[LAG_NUM_LEN];
        if (k > 0 && !(ref->point_t[k] > ref->point_t[k - 1]))
            return yfail(cv->err, it->items[0], el, "the points' times must increase strictly "
                         "(%s after %s)", lag_num(ref->point_t[k], a),
                         lag_num(ref->point_t[k - 1], b));
        snprintf(el, sizeof el, "%s[1]", sub);
        if (sch_get_within_explode(cv, it->items[1], el, &ref->point_w[k]) < 0) return -1;
    }
    ref->n_points = nd->n;
    return 0;
}

static const keyrow k_ref_keys[] = {
    {"type", ref_type, K_OTHER},                   /* a kind of lag_ref_kind_table */
    {"start", ref_start, K_NUMBER},                /* s */
    {"amplitude", ref_amplitude, K_NUMBER},        /* m or rad, within explode_limit */
    {"offset", ref_offset, K_NUMBER},              /* m or rad, within explode_limit */
    {"frequency", ref_frequency, K_NUMBER},        /* Hz: sine, square, chirp */
    {"frequency_end", ref_frequency_end, K_NUMBER},/* Hz: chirp */
    {"duration", ref_duration, K_NUMBER},          /* s: ramp, chirp */
    {"points", ref_points, K_OTHER},               /* waypoints: [[t, w], ...] (numbers
                                                      range-checked in ref_points) */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

static int ref_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    lag_scene_reference *sr = &cv->sc->reference;
    char kinds[128], what[256];
    ref_kind_list(kinds, sizeof kinds);
    snprintf(what, sizeof what, "a reference mapping (type: %s; start, amplitude, offset...)",
             kinds);
    if (sch_need_map(cv, nd, path, what) < 0)
        return -1;
    /* the type first: it decides the other keys and their defaults */
    const yentry *te = ymap_find(nd, "type");
    int kind = -1;
    if (te) {
        char tpath[300];
        const char *name;
        sch_join(tpath, sizeof tpath, path, "type");
        snprintf(what, sizeof what, "a reference type (%s)", kinds);
        if (sch_get_string(cv, te->val, tpath, what, &name) < 0)
            return -1;
        kind = lag_ref_kind_from_name(name);
        if (kind < 0)
            return yfail(cv->err, te->val, tpath, "unknown reference type '%s'; allowed: %s",
                         name, kinds);
    }
    lag_reference *ref = &sr->joint[j];
    *ref = lag_reference_default(kind < 0 ? LAG_REF_STEP : (lag_ref_kind)kind);
    cv->cur_ref = ref;
    cv->cur_ref_kind = kind;
    cv->cur_ref_seen = 0;
    if (sch_convert_map(cv, nd, path, k_ref_keys, "reference key") < 0)
        return -1;
    if (kind < 0)
        return yfail(cv->err, nd, path, "a reference needs a type (%s)", kinds);
    unsigned missing = lag_ref_kind_table[kind].needs & ~cv->cur_ref_seen;
    for (size_t b = 0; b < N_REF_KEY_BITS; b++)
        if (missing & k_ref_key_bits[b].bit)
            return yfail(cv->err, nd, path, "a %s reference needs %s", lag_ref_kind_table[kind].name,
                         k_ref_key_bits[b].name);
    /* the library's own check, last (the relations between keys it knows of) */
    char key[64], msg[256];
    if (lag_reference_check(ref, key, sizeof key, msg, sizeof msg) != 0) {
        char kpath[340];
        size_t base = strcspn(key, "[");
        char head[64];
        snprintf(head, sizeof head, "%.*s", (int)base, key);
        const yentry *ke = ymap_find(nd, head);
        sch_join(kpath, sizeof kpath, path, key);
        return yfail(cv->err, ke ? ke->val : nd, kpath, "%s", msg);
    }
    if (!sr->on[j]) sr->n++;
    sr->on[j] = true;
    return 0;
}

static int key_reference(conv *cv, const ynode *nd, const char *path)
{
    /* `reference:` with nothing = no reference; a --set replaces what it names */
    memset(&cv->sc->reference, 0, sizeof cv->sc->reference);
    if (ynode_is_null(nd))
        return 0;
    return sch_per_joint(cv, nd, path, ref_joint);
}

/* `cases:` are lagsim-eval's (server/tools/eval_case.c reads and checks them); a scene
 * that carries its evaluation cases runs as it would without them. */
static int key_cases(conv *cv, const ynode *nd, const char *path)
{
    (void)cv, (void)nd, (void)path;
    return 0;
}

/* ================================================================ the scene */

static const keyrow k_top_keys[] = {
    {"model", key_model, K_OTHER},                 /* from lag_model_info (required) */
    {"parameters", key_parameters, K_PARAMS},       /* named as in lag_model_info */
    {"initial", key_initial, K_MAP, k_initial_keys},             /* q, qd */
    {"integrator", key_integrator, K_MAP, k_integrator_keys},       /* method, dt, tolerances */
    {"publish_hz", key_publish_hz, K_NUMBER},       /* Hz */
    {"explode_limit", key_explode_limit, K_NUMBER}, /* |q_i|, |qd_i| bound */
    {"realtime", key_realtime, K_MAP, k_realtime_keys},           /* pacing of the real-time server */
    {"lcm", key_lcm, K_MAP, k_lcm_keys},                     /* transport */
    {"effects", key_effects, K_MAP, k_effects},             /* per-scene effects */
    {"reference", key_reference, K_JOINTS, k_ref_keys},     /* per joint: what to follow */
    {"cases", key_cases, K_OTHER},                  /* lagsim-eval's, not the daemon's */
    {NULL, NULL, K_OTHER, NULL, NULL},
};

/* Read before the others, in this order: what other values are measured against. */
static const char *const k_first_keys[] = {"model", "integrator", "publish_hz",
                                           "explode_limit", NULL};

/* "stick, manipulator, dipc" from the core's table */
static void model_list(char *buf, size_t len)
{
    buf[0] = '\0';
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        const lag_model_info *info = lag_model_info_get((lag_model_kind)k);
        size_t used = strlen(buf);
        snprintf(buf + used, len - used, "%s%s", k ? ", " : "", info ? info->name : "?");
    }
}

/* After the first keys: 1/publish_hz = k dt with 1 <= k <= TICKS_MAX. */
static int check_period(conv *cv)
{
    lag_scene *sc = cv->sc;
    /* integrator.error chooses dt later (lagsimd); one that divides the period until then */
    if (sc->accuracy.error > 0 && !cv->dt) sc->sim.integrator.dt = 1.0 / sc->publish_hz;
    double dt = sc->sim.integrator.dt;
    double period = 1.0 / sc->publish_hz;
    double r = period / dt;
    const ynode *at = cv->publish_hz ? cv->publish_hz
                    : cv->dt ? cv->dt
                    : cv->integrator ? cv->integrator : cv->root;
    const char *atpath = cv->publish_hz ? "publish_hz"
                       : cv->dt ? "integrator.dt"
                       : cv->integrator ? "integrator" : NULL;
    char p_s[LAG_NUM_LEN], dt_s[LAG_NUM_LEN];
    lag_num(period, p_s);
    lag_num(dt, dt_s);
    if (!(r >= 1.0 - 1e-9))
        return yfail(cv->err, at, atpath,
                     "1/publish_hz = %s s must be an integer multiple (>= 1) of "
                     "integrator.dt = %s s", p_s, dt_s);
    double ticks = floor(r + 0.5);
    if (fabs(r - ticks) > 1e-9 * r)
        return yfail(cv->err, at, atpath,
                     "1/publish_hz = %s s must be an integer multiple of integrator.dt = "
                     "%s s (it is %.6g dt)", p_s, dt_s, r);
    if (ticks > TICKS_MAX)
        return yfail(cv->err, at, atpath,
                     "1/publish_hz = %s s is %.0f ticks of integrator.dt = %s s: at most "
                     "%d ticks per control period (one period is one uninterrupted call)",
                     p_s, ticks, dt_s, TICKS_MAX);
    sc->ticks_per_period = (int64_t)ticks;
    return 0; /* dt_min <= dt: the core's check */
}

/* The core's own checks of def (parameters, the integrator's settings against each other,
 * the effects' values against each other and the initial state, which models have a
 * floor...), made by the core alone: its diagnosis names the field in the scene's own
 * terms, and the field's node gives the position. */
static int core_check(conv *cv, const lag_sim_def *def)
{
    lag_diag d;
    if (lag_sim_def_check(def, &d) == LAG_OK)
        return 0;
    return yfail(cv->err, ytree_lookup(cv->root, d.field), d.field[0] ? d.field : NULL, "%s",
                 d.message);
}

/* Step 1: the model comes first (parameters, the length of q and the defaults depend on
 * it); sc gets the model's defaults. */
static int convert_model(conv *cv, const char *path)
{
    const ynode *root = cv->root;
    if (root->kind != YN_MAP) {
        if (ynode_is_null(root))
            return yfail(cv->err, root, NULL,
                         "expected a mapping with the scene's keys (at least 'model'), "
                         "got an empty document");
        return yfail(cv->err, root, NULL,
                     "expected a mapping with the scene's keys (at least 'model'), got %s",
                     ynode_kind_name(root));
    }
    char models[256];
    model_list(models, sizeof models);
    const yentry *me = ymap_find(root, "model");
    if (!me)
        return yfail(cv->err, root, NULL, "missing required key 'model' (%s)", models);
    const char *mname;
    char what[300];
    snprintf(what, sizeof what, "a model (%s)", models);
    if (sch_get_string(cv, me->val, "model", what, &mname) < 0)
        return -1;
    int kind = lag_model_kind_from_name(mname);
    if (kind < 0)
        return yfail(cv->err, me->val, "model", "unknown model '%s'; allowed: %s", mname, models);
    lag_scene_default(cv->sc, (lag_model_kind)kind);
    snprintf(cv->sc->path, sizeof cv->sc->path, "%s", path ? path : "");
    lag_model_default_unfinished(&cv->sc->sim.model, (lag_model_kind)kind);
    cv->info = lag_model_info_get((lag_model_kind)kind);
    return 0;
}

/* Step 2: what the other values are measured against (integrator, publish_hz,
 * explode_limit), checked by the core at once (a later key's range must not be measured
 * against a value the core refuses), then the period they make. */
static int convert_first_keys(conv *cv)
{
    lag_scene *sc = cv->sc;
    for (int k = 1; k_first_keys[k]; k++) {
        const yentry *en = ymap_find(cv->root, k_first_keys[k]);
        if (!en)
            continue;
        const keyrow *r = k_top_keys;
        while (strcmp(r->name, en->key) != 0)
            r++;
        if (r->fn(cv, en->val, en->key) < 0)
            return -1;
    }
    lag_sim_def first = sc->sim; /* the model's defaults, with their rods' inertias */
    lag_model_finish(&first.model);
    if (core_check(cv, &first) < 0 || check_period(cv) < 0)
        return -1;
    /* the watchdog default: 0.5 s, but never shorter than two control periods */
    double period = (double)sc->ticks_per_period * sc->sim.integrator.dt;
    if (sc->realtime.command_timeout < 2.0 * period)
        sc->realtime.command_timeout = 2.0 * period;
    return 0;
}

/* Step 4: what follows from several keys once all are read, then the core's checks. */
static int convert_finish(conv *cv)
{
    lag_scene *sc = cv->sc;
    /* effects.gravity overrides parameters.g (after both are read, whatever their order) */
    int gi = lag_model_param_index(sc->sim.model.kind, "g");
    if (gi >= 0 && cv->gravity_g_node) sc->sim.model.p[gi] = cv->gravity_g;
    if (gi >= 0 && cv->gravity_enabled == 0) sc->sim.model.p[gi] = 0.0;

    /* realtime.start not given: a lockstep run waits for its controller's first command
     * (it cannot advance without one anyway, and then no start order can lose the first
     * state); realtime and fast run from the start, like a plant switched on */
    if (!cv->start)
        sc->realtime.start = sc->realtime.mode == LAG_RT_LOCKSTEP ? LAG_RT_START_FIRST_COMMAND
                                                                  : LAG_RT_START_RUNNING;

    /* Parameters: uniform-rod inertias not given -> m l^2 / 12 */
    lag_model_finish(&sc->sim.model);

    /* Real time: at most PERIODS_PER_S_MAX control periods per wall second. */
    if (sc->realtime.mode == LAG_RT_REALTIME &&
        sc->publish_hz * sc->realtime.rate > PERIODS_PER_S_MAX * (1.0 + 1e-12)) {
        const ynode *at = cv->rate ? cv->rate : cv->publish_hz;
        return yfail(cv->err, at, cv->rate ? "realtime.rate" : "publish_hz",
                     "publish_hz * realtime.rate = %.6g control periods per wall second: at "
                     "most %.0f in realtime mode (mode: fast runs as fast as it can)",
                     sc->publish_hz * sc->realtime.rate, PERIODS_PER_S_MAX);
    }

    /* lcm.url, with lcm.allow_lan wherever it was given */
    char msg[256];
    if (lag_scene_check_url(sc->lcm.url, sc->lcm.allow_lan, &sc->lcm.ttl, msg, sizeof msg) < 0)
        return yfail(cv->err, cv->url, "lcm.url", "%s", msg);
    if (core_check(cv, &sc->sim) < 0) return -1;
    /* the scene-level rules, as for a scene built in code (the keys' ranges above are
     * narrower: a file's scene meets them) */
    lag_diag d;
    if (lag_scene_check(sc, &d) == LAG_OK) return 0;
    return yfail(cv->err, ytree_lookup(cv->root, d.field), d.field, "%s", d.message);
}

int scene_schema_convert(const ynode *root, const char *path, lag_scene *sc, errbuf *err)
{
    conv cv = {.err = err, .sc = sc, .root = root, .gravity_enabled = -1};
    if (convert_model(&cv, path) < 0 || convert_first_keys(&cv) < 0)
        return -1;
    /* Step 3: every other key, in file order */
    if (sch_convert_map_skip(&cv, root, "", k_top_keys, "key", k_first_keys) < 0)
        return -1;
    return convert_finish(&cv);
}

/* ================================================================ every numeric key */

/* snprintf for key paths (at most 255 characters; longer ones are cut) */
static void pathf(char *buf, size_t len, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void pathf(char *buf, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, len, fmt, ap);
    va_end(ap);
}

static void walk(const lag_model_info *info, const keyrow *rows, const char *prefix,
                 scene_number_fn fn, void *ctx)
{
    for (const keyrow *r = rows; r->name; r++) {
        char p[256], q[256];
        pathf(p, sizeof p, "%s%s%s", prefix, prefix[0] ? "." : "", r->name);
        switch (r->type) {
        case K_OTHER:
            break;
        case K_NUMBER:
        case K_INTEGER:
            fn(ctx, p, r->type == K_INTEGER);
            break;
        case K_MAP:
            walk(info, r->sub, p, fn, ctx);
            break;
        case K_PARAMS:
            for (int i = 0; i < info->np; i++)
            {
                pathf(q, sizeof q, "%s.%s", p, info->param_names[i]);
                fn(ctx, q, false);
            }
            break;
        case K_VECTOR:
            for (int i = 0; i < info->nq; i++) {
                pathf(q, sizeof q, "%s[%d]", p, i);
                fn(ctx, q, false);
            }
            break;
        case K_JOINTS:
            for (int i = 0; i < info->nq; i++) {
                pathf(q, sizeof q, "%s.%s", p, info->joint_names[i]);
                if (r->sub)
                    walk(info, r->sub, q, fn, ctx);
                else
                    fn(ctx, q, false);
            }
            if (r->extra)
                walk(info, r->extra, p, fn, ctx);
            break;
        case K_LIST:
            pathf(q, sizeof q, "%s[0]", p);
            walk(info, r->sub, q, fn, ctx);
            break;
        }
    }
}

void scene_schema_each_number(lag_model_kind kind, scene_number_fn fn, void *ctx)
{
    const lag_model_info *info = lag_model_info_get(kind);
    if (info)
        walk(info, k_top_keys, "", fn, ctx);
}
