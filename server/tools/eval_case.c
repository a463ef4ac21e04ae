/* lagsim-eval's and lagsim-sweep's cases and runs (eval_case.h). */

#include "eval_case.h"
#include "lagsim_num.h"

#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <signal.h>
#include <stdalign.h>
#include <stddef.h>
#include <stdint.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "lagsim_bus.h"
#include "lagsim_clock.h"
#include "lagsim_log.h"
#include "lagsim/lagsim_control_t.h" /* the requests' constants */
#include "lagsim_out.h"
#include "lagsim_wire.h"
#include "scene.h"
#include "scene_yaml.h"

/* ---------------------------------------------------------------- the keys the tools own */
const eval_owned_key eval_owned_keys[EVAL_OWN_COUNT] = {
    [EVAL_OWN_MODE] = {"realtime.mode", "lockstep: a run's numbers do not depend on the "
                                        "controller's speed or the machine's load"},
    [EVAL_OWN_START] = {"realtime.start", "first_command (paused for a kept lagsim-sweep "
                                          "worker): a run starts with its controller"},
    [EVAL_OWN_LOCKSTEP_TIMEOUT] = {"realtime.lockstep_timeout",
                                   "0.1 s (3600 s for a kept worker): how often a waiting "
                                   "plant publishes its state again"},
    [EVAL_OWN_URL] = {"lcm.url", "ports of the run's own, with the group and options of "
                                 "--url or LCM_DEFAULT_URL: no crosstalk"},
    [EVAL_OWN_PREFIX] = {"lcm.prefix", "channels of the run's own ({prefix}, LAGSIM_PREFIX)"},
    [EVAL_OWN_ALLOW_LAN] = {"lcm.allow_lan", "false unless --allow-lan: nothing from or to "
                                             "the network"},
};

/* The length of the first segment of the dotted path p[0, end) */
static size_t segment(const char *p, const char *end)
{
    const char *dot = memchr(p, '.', (size_t)(end - p));
    return dot ? (size_t)(dot - p) : (size_t)(end - p);
}

bool eval_key_overlap(const char *a, size_t alen, const char *b, size_t blen)
{
    const char *ae = a + alen, *be = b + blen;
    /* a segment at a time while both agree; one path ending there is the other or holds
     * it */
    for (;;) {
        size_t al = segment(a, ae), bl = segment(b, be);
        if (al != bl || memcmp(a, b, al)) return false;
        if (a + al == ae || b + bl == be) return true;
        a += al + 1, b += bl + 1;
    }
}

int eval_owned_find(const char *key, size_t len)
{
    for (int r = 0; r < EVAL_OWN_COUNT; r++)
        if (eval_key_overlap(key, len, eval_owned_keys[r].key, strlen(eval_owned_keys[r].key)))
            return r;
    return -1;
}

int eval_owned_check(const char *key, size_t len, char *why, size_t n)
{
    int r = eval_owned_find(key, len);
    if (r < 0) return 0;
    const eval_owned_key *o = &eval_owned_keys[r];
    if (len < strlen(o->key))
        snprintf(why, n, "%.*s holds %s, which lagsim-eval and lagsim-sweep set themselves "
                 "(%s)", (int)len, key, o->key, o->why);
    else
        snprintf(why, n, "%s is set by lagsim-eval and lagsim-sweep themselves (%s)", o->key,
                 o->why);
    return -1;
}

void eval_owned_usage(FILE *f)
{
    enum { INDENT = 29, WIDTH = 80 };
    for (int r = 0; r < EVAL_OWN_COUNT; r++) {
        int col = fprintf(f, "  %-26s", eval_owned_keys[r].key);
        /* the reason's words, wrapped under each other */
        for (const char *w = eval_owned_keys[r].why; *w;) {
            int n = (int)strcspn(w, " ");
            if (col + 1 + n > WIDTH) col = fprintf(f, "\n%*s", INDENT - 1, "") - 1;
            col += fprintf(f, " %.*s", n, w);
            w += n + (w[n] == ' ');
        }
        fputc('\n', f);
    }
}

/* ---------------------------------------------------------------- cases */
static const char *const k_case_keys = "name, duration, set, bounds";

static int read_number(errbuf *e, const ynode *nd, const char *what, double lo, double hi,
                       double *v)
{
    if (nd->kind != YN_SCALAR || nd->quoted || lag_scene_read_decimal(nd->text, v) != 0 ||
        !(*v >= lo && *v <= hi))
        return yfail(e, nd, NULL, "%s: expected a number from %g to %g, got %s%s%s", what, lo,
                     hi, nd->kind == YN_SCALAR ? "'" : "",
                     nd->kind == YN_SCALAR ? nd->text : ynode_kind_name(nd),
                     nd->kind == YN_SCALAR ? "'" : "");
    return 0;
}

static int read_text(errbuf *e, const ynode *nd, const char *what, char *out, size_t len)
{
    if (nd->kind != YN_SCALAR || ynode_is_null(nd))
        return yfail(e, nd, NULL, "%s: expected text, got %s", what, ynode_kind_name(nd));
    if (strlen(nd->text) >= len)
        return yfail(e, nd, NULL, "%s: longer than %zu characters", what, len - 1);
    snprintf(out, len, "%s", nd->text);
    return 0;
}

/* A case's `set:`: "key=value" overrides, as lagsimd --set takes them, none of them on a
 * key the tools own (eval_owned_keys), each kept with its place in the file. */
static int read_sets(errbuf *e, const ynode *v, eval_case *c)
{
    if (v->kind != YN_SEQ)
        return yfail(e, v, NULL,
                     "set: expected a list of \"key=value\" overrides (as lagsimd --set), "
                     "got %s", ynode_kind_name(v));
    if (v->n > EVAL_SETS_MAX) return yfail(e, v, NULL, "set: at most %d overrides", EVAL_SETS_MAX);
    for (int i = 0; i < v->n; i++) {
        const ynode *it = v->items[i];
        if (read_text(e, it, "set", c->set[i], sizeof c->set[i])) return -1;
        c->set_line[i] = it->line;
        c->set_col[i] = it->col;
        if (!strchr(c->set[i], '=') || c->set[i][0] == '=')
            return yfail(e, it, NULL, "set: expected \"key=value\" (as lagsimd --set), got '%s'",
                         c->set[i]);
        char why[512];
        if (eval_owned_check(c->set[i], strcspn(c->set[i], "="), why, sizeof why))
            return yfail(e, it, NULL, "cases[%d].set[%d]: '%s': %s: a case cannot set it",
                         c->index, i, c->set[i], why);
    }
    c->nsets = v->n;
    return 0;
}

static int read_case(errbuf *e, const ynode *nd, int index, eval_case *c)
{
    memset(c, 0, sizeof *c);
    c->index = index;
    if (nd->kind != YN_MAP)
        return yfail(e, nd, NULL, "cases[%d]: expected a mapping (%s), got %s", index,
                     k_case_keys, ynode_kind_name(nd));
    bool has_duration = false;
    for (int k = 0; k < nd->n; k++) {
        const yentry *en = &nd->entries[k];
        const ynode *v = en->val;
        if (!strcmp(en->key, "name")) {
            if (read_text(e, v, "name", c->name, sizeof c->name)) return -1;
            for (const char *p = c->name; *p; p++)
                if (!(*p == '_' || *p == '-' || *p == '.' || (*p >= '0' && *p <= '9') ||
                      (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z')))
                    return yfail(e, v, NULL,
                                 "name: letters, digits, '_', '-' and '.' only (it names "
                                 "files), got '%s'", c->name);
        } else if (!strcmp(en->key, "duration")) {
            if (read_number(e, v, "duration", 1e-3, 1e6, &c->duration)) return -1;
            has_duration = true;
        } else if (!strcmp(en->key, "set")) {
            if (read_sets(e, v, c)) return -1;
        } else if (!strcmp(en->key, "bounds")) {
            if (v->kind != YN_MAP)
                return yfail(e, v, NULL,
                             "bounds: expected a mapping joint: largest |q| (e.g. "
                             "{theta: 0.5}), got %s", ynode_kind_name(v));
            if (v->n > EVAL_JOINTS_MAX)
                return yfail(e, v, NULL, "bounds: at most %d joints", EVAL_JOINTS_MAX);
            for (int i = 0; i < v->n; i++) {
                if (strlen(v->entries[i].key) >= EVAL_NAME_LEN)
                    return yfail_key(e, &v->entries[i], "bounds: joint name too long");
                snprintf(c->bound_joint[i], EVAL_NAME_LEN, "%s", v->entries[i].key);
                if (read_number(e, v->entries[i].val, "bounds", 0, 1e9, &c->bound[i]))
                    return -1;
            }
            c->nbounds = v->n;
        } else {
            return yfail_key(e, en, "cases[%d]: unknown key '%s' (expected %s)", index,
                             en->key, k_case_keys);
        }
    }
    if (!c->name[0]) return yfail(e, nd, NULL, "cases[%d]: missing 'name'", index);
    if (!has_duration) return yfail(e, nd, NULL, "cases[%d]: missing 'duration' (s)", index);
    return 0;
}

int eval_cases_load(const char *path, eval_case **cases, int *n, char *err, size_t errlen)
{
    *cases = NULL;
    *n = 0;
    char *text = NULL;
    size_t len = 0;
    if (lag_scene_read(path, &text, &len, err, errlen) != 0) return -1;
    ysrc src = {.name = path, .is_set = false};
    errbuf e = {err, errlen};
    ynode *root = NULL;
    int rc = ytree_parse(text, len, &src, &e, &root);
    free(text);
    if (rc != 0) return -1;
    rc = -1;
    const yentry *ce = root->kind == YN_MAP ? ymap_find(root, "cases") : NULL;
    if (root->kind != YN_MAP) {
        yfail(&e, root, NULL, "expected a mapping with a 'cases:' list, got %s",
              ynode_kind_name(root));
        goto out;
    }
    if (!ce) {
        rc = 0;
        goto out;
    }
    const ynode *list = ce->val;
    if (list->kind != YN_SEQ || list->n == 0) {
        yfail(&e, list, NULL, "cases: expected a list of cases (each with %s), got %s",
              k_case_keys, list->kind == YN_SEQ ? "an empty list" : ynode_kind_name(list));
        goto out;
    }
    if (list->n > EVAL_CASES_MAX) {
        yfail(&e, list, NULL, "cases: at most %d", EVAL_CASES_MAX);
        goto out;
    }
    eval_case *cs = calloc((size_t)list->n, sizeof *cs);
    if (!cs) {
        snprintf(err, errlen, "%s: out of memory", path);
        goto out;
    }
    for (int i = 0; i < list->n; i++) {
        if (read_case(&e, list->items[i], i, &cs[i])) {
            free(cs);
            goto out;
        }
        for (int j = 0; j < i; j++)
            if (!strcmp(cs[j].name, cs[i].name)) {
                yfail(&e, list->items[i], NULL, "cases[%d]: a second case named '%s'", i,
                      cs[i].name);
                free(cs);
                goto out;
            }
    }
    *cases = cs;
    *n = list->n;
    rc = 0;
out:
    ynode_free(root);
    return rc;
}

/* ---------------------------------------------------------------- scene */
int eval_scene_load(const char *config, const char *const *sets, int nsets, eval_scene *out,
                    char *err, size_t errlen)
{
    lag_scene *sc = calloc(1, sizeof *sc);
    if (!sc) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int rc = lag_scene_load(config, sets, nsets, sc, err, errlen);
    if (rc == 0) {
        memset(out, 0, sizeof *out);
        const lag_model_info *info = lag_model_info_get(sc->sim.model.kind);
        snprintf(out->model, sizeof out->model, "%s", info->name);
        out->nj = sc->sim.model.nq < EVAL_JOINTS_MAX ? sc->sim.model.nq : EVAL_JOINTS_MAX;
        for (int j = 0; j < out->nj; j++) {
            snprintf(out->joint[j], EVAL_NAME_LEN, "%s", info->joint_names[j]);
            out->angular[j] = info->angular[j];
            out->actuated[j] = info->actuated[j];
            out->q0[j] = sc->sim.q0[j];
            out->qd0[j] = sc->sim.qd0[j];
        }
        out->has_reference = sc->reference.n > 0;
        for (int j = 0; j < out->nj; j++) out->reference[j] = sc->reference.on[j];
        out->period = 1.0 / sc->publish_hz;
    }
    free(sc);
    return rc ? -1 : 0;
}

bool eval_scene_unreferenced(const eval_scene *sc, char *buf, size_t len)
{
    int none = 0, k = 0;
    buf[0] = '\0';
    for (int j = 0; j < sc->nj; j++) none += !sc->reference[j];
    if (!sc->has_reference || none == 0) return false;
    size_t u = 0;
    for (int j = 0; j < sc->nj && u < len; j++) {
        if (sc->reference[j]) continue;
        k++;
        u += (size_t)snprintf(buf + u, len - u, "%s%s", k == 1 ? "" : k == none ? " and " : ", ",
                              sc->joint[j]);
    }
    return true;
}

int eval_case_scene_load(const char *config, const char *from, const eval_case *c,
                         const char *const *extra, int nextra, eval_scene *sc, char *err,
                         size_t errlen)
{
    const char *sets[EVAL_SETS_MAX * 2];
    int n = 0;
    for (int i = 0; i < c->nsets; i++) sets[n++] = c->set[i];
    for (int i = 0; i < nextra && n < EVAL_SETS_MAX * 2; i++) sets[n++] = extra[i];
    if (eval_scene_load(config, sets, n, sc, err, errlen) == 0) return 0;
    /* the first of the case's own overrides with which the scene no longer loads (the
     * loader applies them in order) is the one to point at */
    char msg[2048];
    eval_scene tmp;
    for (int j = 0; j < c->nsets && from && c->set_line[j] > 0; j++)
        if (eval_scene_load(config, sets, j + 1, &tmp, msg, sizeof msg) != 0) {
            snprintf(err, errlen, "%s:%d:%d: cases[%d].set[%d]: %s", from, c->set_line[j],
                     c->set_col[j], c->index, j, msg);
            return -1;
        }
    char whole[2048];
    snprintf(whole, sizeof whole, "%s", err);
    snprintf(err, errlen, "case %s: %s", c->name, whole);
    return -1;
}

void eval_owned_sets(const eval_env *env, bool kept, char out[EVAL_OWN_COUNT][EVAL_SET_LEN])
{
    for (int r = 0; r < EVAL_OWN_COUNT; r++) {
        const char *key = eval_owned_keys[r].key;
        char *o = out[r];
        switch ((eval_owned_row)r) {
        case EVAL_OWN_MODE: snprintf(o, EVAL_SET_LEN, "%s=lockstep", key); break;
        /* lockstep waits at t = 0 for the controller's first command (a kept daemon
         * waits paused for the worker's STEP) */
        case EVAL_OWN_START:
            snprintf(o, EVAL_SET_LEN, "%s=%s", key, kept ? "paused" : "first_command");
            break;
        /* a waiting plant publishes its state again every lockstep_timeout: a controller
         * that finds the plant after the first one (by discovery) waits at most this
         * long. A kept daemon's STEP takes a period without a command once it passed (as
         * asked): the longest one there, so that a period never goes without its answer
         * (a lost answer costs a retry, docs/server.md). The results depend on neither. */
        case EVAL_OWN_LOCKSTEP_TIMEOUT:
            snprintf(o, EVAL_SET_LEN, "%s=%s", key, kept ? "3600" : "0.1");
            break;
        case EVAL_OWN_URL: snprintf(o, EVAL_SET_LEN, "%s=%s", key, env->url); break;
        case EVAL_OWN_PREFIX: snprintf(o, EVAL_SET_LEN, "%s=%s", key, env->prefix); break;
        case EVAL_OWN_ALLOW_LAN:
            snprintf(o, EVAL_SET_LEN, "%s=%s", key, env->allow_lan ? "true" : "false");
            break;
        case EVAL_OWN_COUNT: break;
        }
    }
}

/* ---------------------------------------------------------------- processes */
int eval_bus_init(eval_bus *b, const char *url, bool allow_lan, char *err, size_t errlen)
{
    memset(b, 0, sizeof *b);
    const char *env = getenv("LCM_DEFAULT_URL");
    b->from = url ? "--url" : env && env[0] ? "LCM_DEFAULT_URL" : "the default URL";
    if (!url) url = env && env[0] ? env : EVAL_DEFAULT_URL;
    if (strlen(url) >= sizeof b->base) {
        snprintf(err, errlen, "%s: an LCM URL of at most %zu characters expected", b->from,
                 sizeof b->base - 1);
        return -1;
    }
    snprintf(b->base, sizeof b->base, "%s", url);
    char why[512];
    /* a plant's URL first (the provider), then the options under a scene's rules, as the
     * daemon reads its lcm.url */
    if (lag_url_parse(b->base, 0, &b->u, why, sizeof why) != 0 ||
        (b->u.provider == LAG_URL_UDPM &&
         lag_url_parse(b->base, LAG_URL_SCENE_RULES | LAG_URL_ALLOW_LAN, &b->u, why,
                       sizeof why) != 0)) {
        snprintf(err, errlen, "%s %s: %s", b->from, url, why);
        return -1;
    }
    if (b->u.provider != LAG_URL_UDPM) {
        snprintf(err, errlen, "%s %s: the daemon and the controller are processes of their "
                 "own, which an in-process memq:// bus cannot join: give a udpm:// URL",
                 b->from, url);
        return -1;
    }
    if (b->u.ttl > 0 && !allow_lan) {
        snprintf(err, errlen, "%s %s: ttl=%d sends every message of the runs beyond this host "
                 "and lets the network command their plants (docs/network.md): give "
                 "--allow-lan if that is meant, or use ttl=0", b->from, url, b->u.ttl);
        return -1;
    }
    return 0;
}

bool eval_text_plain(const char *s)
{
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ||
              strchr("_-.:/?=&", *s)))
            return false;
    return true;
}

int eval_bus_take(const eval_bus *b, lag_port_lease *l, char *url, size_t len, char *err,
                  size_t errlen)
{
    if (lag_port_take(l, err, errlen) != 0) return -1;
    int n = lag_url_format(&b->u, l->port, url, len);
    if (n < 0 || (size_t)n >= len || !eval_text_plain(url)) {
        snprintf(err, errlen, "%s %s: the run's URL '%.*s' is too long or has a character "
                 "that a quote would change", b->from, b->base, (int)len, url);
        lag_port_release(l);
        return -1;
    }
    return 0;
}

double eval_now(void) { return lag_clock_mono_s(); }

double eval_now_wall(void) { return 1e-6 * (double)lag_clock_wall_us(); }

void eval_sleep(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - floor(s)) * 1e9)};
    nanosleep(&ts, NULL);
}

/* Whether cmd has the placeholder ph outside every quote, as sh reads it: '...' quotes
 * everything, "..." all but \\ before " \\ $ `, and a \\ outside quotes the next byte. */
static bool bare_placeholder(const char *cmd, const char *ph)
{
    size_t n = strlen(ph);
    char quote = 0;
    for (const char *p = cmd; *p; p++) {
        if (quote == '\'') {
            if (*p == '\'') quote = 0;
        } else if (*p == '\\' && p[1]) {
            if (!quote || strchr("\"\\$`", p[1])) p++;
        } else if (*p == '"') {
            quote = quote ? 0 : '"';
        } else if (*p == '\'' && !quote) {
            quote = '\'';
        } else if (!quote && !strncmp(p, ph, n)) {
            return true;
        }
    }
    return false;
}

void eval_url_hint(const char *cmd, const char *url, char *buf, size_t len)
{
    buf[0] = '\0';
    bool amp = strchr(url, '&') != NULL, glob = strchr(url, '?') != NULL;
    if ((!amp && !glob) || !bare_placeholder(cmd, "{url}")) return;
    snprintf(buf, len, "; {url} stands outside quotes in the command and the run's URL has %s%s%s "
             "(%s%s%s): write '{url}'", amp ? "'&'" : "", amp && glob ? " and " : "",
             glob ? "'?'" : "", amp ? "the shell ends the command at '&'" : "",
             amp && glob ? ", " : "", glob ? "'?' is a file pattern" : "");
}

/* "{prefix}" and "{url}" in cmd replaced by the run's prefix and URL as they are, nothing
 * added: each is checked to be plain text (eval_text_plain), which means itself inside
 * the user's own quotes, so the rule is one a user can predict (docs/evaluation.md). */
int eval_expand(const char *cmd, const eval_env *env, char *out, size_t len, char *err,
                size_t errlen)
{
    if (!eval_text_plain(env->prefix) || !eval_text_plain(env->url)) {
        snprintf(err, errlen, "the run's prefix '%s' or URL '%s' has a character that a quote "
                 "would change", env->prefix, env->url);
        return -1;
    }
    size_t o = 0;
    for (const char *p = cmd; *p;) {
        const char *rep = NULL;
        size_t skip = 0;
        if (!strncmp(p, "{prefix}", 8)) rep = env->prefix, skip = 8;
        else if (!strncmp(p, "{url}", 5)) rep = env->url, skip = 5;
        size_t n = rep ? strlen(rep) : 1;
        if (o + n >= len) {
            snprintf(err, errlen, "the controller's command, {prefix} and {url} replaced, is "
                     "longer than %zu characters", len - 1);
            return -1;
        }
        memcpy(out + o, rep ? rep : p, n);
        o += n;
        p += rep ? skip : 1;
    }
    out[o] = '\0';
    return 0;
}

void eval_series_free(eval_series *s)
{
    free(s->t);
    for (int j = 0; j < EVAL_JOINTS_MAX; j++) {
        free(s->q[j]);
        free(s->r[j]);
        free(s->u[j]);
    }
    memset(s, 0, sizeof *s);
}

int eval_series_grow(eval_series *s, int nj)
{
    if (s->n < s->cap) return 0;
    size_t cap = s->cap ? 2 * s->cap : 1024;
    double *t = realloc(s->t, cap * sizeof *t);
    if (!t) return -1;
    s->t = t;
    for (int j = 0; j < nj; j++) {
        double **arr[3] = {&s->q[j], &s->r[j], &s->u[j]};
        for (int a = 0; a < 3; a++) {
            double *p = realloc(*arr[a], cap * sizeof *p);
            if (!p) return -1;
            *arr[a] = p;
        }
    }
    s->cap = cap;
    return 0;
}

void eval_fail(eval_result *res, const char *fmt, ...)
{
    if (res->failed) return; /* the first reason stays */
    res->failed = true;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(res->reason, sizeof res->reason, fmt, ap);
    va_end(ap);
}

/* The wire module's type for <PREFIX>_REFERENCE ("reference_t"), or -1 while it has none:
 * found by name in the wire's table, its fields read through the wire's field table, so
 * that this file follows the message's definition instead of copying it. */
static int reference_type(void)
{
    for (int t = 0; t < LAG_WIRE_TYPE_COUNT; t++) {
        const char *name = lag_wire_type_name((lag_wire_type)t);
        if (name && !strcmp(name, "reference_t")) return t;
    }
    return -1;
}

static const lag_wire_field *field(const lag_wire_field *f, int n, const char *name,
                                   lag_wire_kind kind)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(f[i].name, name) && f[i].kind == kind) return &f[i];
    return NULL;
}

/* The reference of a logged <PREFIX>_REFERENCE record (published just before the state
 * of the same sim_time): its time and r of each joint it lists (the others keep 0).
 * Returns 1 when the record was read. */
static int read_reference(const lag_log_record *rec, const eval_scene *sc, double *t,
                          double r[EVAL_JOINTS_MAX])
{
    int type = reference_type();
    if (type < 0) return 0; /* no reference type: every case regulates to r = 0 */
    int nf = 0;
    const lag_wire_field *fs = lag_wire_fields((lag_wire_type)type, &nf);
    const lag_wire_field *f_t = field(fs, nf, "sim_time", LAG_WIRE_DOUBLE);
    const lag_wire_field *f_n = field(fs, nf, "num_joints", LAG_WIRE_INT16);
    const lag_wire_field *f_name = field(fs, nf, "name", LAG_WIRE_STRING);
    const lag_wire_field *f_r = field(fs, nf, "r", LAG_WIRE_DOUBLE);
    size_t size = lag_wire_struct_size((lag_wire_type)type);
    if (!f_t || !f_n || !f_name || !f_r || f_r->count_field < 0 || f_name->count_field < 0)
        return 0;
    static _Alignas(max_align_t) unsigned char buf[1 << 16];
    if (size > sizeof buf ||
        lag_wire_decode_any((lag_wire_type)type, rec->data, rec->size, EVAL_JOINTS_MAX, buf,
                            NULL) != 0)
        return 0;
    memcpy(t, buf + f_t->offset, sizeof *t);
    int16_t n;
    memcpy(&n, buf + f_n->offset, sizeof n);
    for (int j = 0; j < EVAL_JOINTS_MAX; j++) r[j] = 0;
    for (int i = 0; i < n && i < f_r->capacity && i < f_name->capacity; i++) {
        const char *name = (const char *)(buf + f_name->offset + (size_t)i * f_name->size);
        double v;
        memcpy(&v, buf + f_r->offset + (size_t)i * sizeof v, sizeof v);
        for (int j = 0; j < sc->nj; j++)
            if (!strncmp(name, sc->joint[j], f_name->size) && isfinite(v)) r[j] = v;
    }
    return isfinite(*t);
}

void eval_take_init(eval_take *tk, const char *prefix, const eval_scene *sc, eval_series *s,
                    eval_result *res)
{
    memset(tk, 0, sizeof *tk);
    lag_bus_channel_name(tk->ch_state, sizeof tk->ch_state, prefix, LAG_BUS_STATE);
    lag_bus_channel_name(tk->ch_event, sizeof tk->ch_event, prefix, LAG_BUS_EVENT);
    lag_bus_channel_name(tk->ch_ref, sizeof tk->ch_ref, prefix, LAG_BUS_REFERENCE);
    lag_bus_channel_name(tk->ch_control, sizeof tk->ch_control, prefix, LAG_BUS_CONTROL);
    tk->sc = sc;
    tk->s = s;
    tk->res = res;
    tk->ref_time = NAN;
    tk->t_stop = INFINITY;
    tk->started = true;
}

/* A daemon kept for many runs: the run's records follow the last RESET_TO the records
 * hold (everything before it, earlier runs' tails included, is dropped at each one). */
void eval_take_from_last_reset(eval_take *tk)
{
    tk->per_reset = true;
    tk->started = false;
}

static void take_state(eval_take *tk, const lag_log_record *rec)
{
    const eval_scene *sc = tk->sc;
    eval_series *s = tk->s;
    lag_wire_joint_state st;
    if (lag_wire_decode_any(LAG_WIRE_JOINT_STATE, rec->data, rec->size, sc->nj, &st, NULL) != 0 ||
        st.num_joints != sc->nj)
        return;
    /* a state published again (a lockstep retry, a status request) is one sample; a
     * kept daemon may step past the duration */
    if ((s->n && st.sim_time <= s->t[s->n - 1]) || st.sim_time > tk->t_stop) return;
    if (eval_series_grow(s, sc->nj)) {
        tk->oom = true;
        return;
    }
    size_t k = s->n++;
    s->t[k] = st.sim_time;
    bool ref = tk->ref_time == st.sim_time;
    if (ref) s->has_reference = true;
    for (int j = 0; j < sc->nj; j++) {
        s->q[j][k] = st.position[j];
        s->r[j][k] = ref ? tk->ref_r[j] : 0;
        /* the state's effort was held over the period that ended at it; the last state's
         * is repeated as the held effort after it */
        if (k) s->u[j][k - 1] = st.effort[j];
        s->u[j][k] = st.effort[j];
    }
}

static void take_event(eval_take *tk, const lag_log_record *rec)
{
    lag_wire_event ev;
    if (lag_wire_decode_event(rec->data, rec->size, &ev) != 0) return;
    if (!strcmp(ev.kind, "numeric_fault")) {
        eval_fail(tk->res, "fault at t = %.6g s: %s", ev.sim_time, ev.detail);
        tk->fault = true;
    }
    /* a lockstep_timeout only delays a lockstep run: its states stay those of a run
     * without it, bit for bit (docs/server.md); a controller that never answers ends in
     * the wall timeout */
    else if (!strcmp(ev.kind, "stop")) {
        if (strstr(ev.detail, "duration reached")) tk->stopped_at_duration = true;
        else eval_fail(tk->res, "stopped at t = %.6g s: %s", ev.sim_time, ev.detail);
    }
}

/* A RESET_TO the daemon took (the log holds what it received with its fate: an input
 * record is in the log only when accepted: docs/server.md, "Record, replay, watch") */
static bool is_reset_to(const eval_take *tk, const lag_log_record *rec)
{
    if (strcmp(rec->channel, tk->ch_control)) return false;
    lag_wire_control m;
    return lag_wire_decode_control(rec->data, rec->size, tk->sc->nj, &m) == 0 &&
           m.request == LAGSIM_CONTROL_T_RESET_TO;
}

/* A kept daemon's RESET_TO: what came before belonged to earlier runs */
static void take_restart(eval_take *tk)
{
    tk->s->n = 0;
    tk->s->has_reference = false;
    tk->res->failed = false;
    tk->res->reason[0] = '\0';
    tk->ref_time = NAN;
    tk->fault = tk->stopped_at_duration = false;
    tk->started = true;
}

void eval_take_record(eval_take *tk, const lag_log_record *rec)
{
    if (!rec->data) return;
    if (tk->per_reset && is_reset_to(tk, rec)) take_restart(tk);
    if (!tk->started) return;
    if (!strcmp(rec->channel, tk->ch_state)) take_state(tk, rec);
    else if (!strcmp(rec->channel, tk->ch_ref)) {
        if (!read_reference(rec, tk->sc, &tk->ref_time, tk->ref_r)) tk->ref_time = NAN;
    } else if (!strcmp(rec->channel, tk->ch_event)) take_event(tk, rec);
}

/* The run's end as the fresh daemon's log says it: an early stop or no state fail it */
static void take_end(const eval_take *tk, double duration)
{
    const eval_series *s = tk->s;
    eval_result *res = tk->res;
    res->states = s->n;
    res->t_end = s->n ? s->t[s->n - 1] : 0;
    if (!s->n) eval_fail(res, "no state logged");
    else if (res->t_end < duration - 0.5 * tk->sc->period)
        eval_fail(res, "stopped at t = %.6g s before the duration %.6g s", res->t_end, duration);
}

int eval_read_log(const char *path, const char *prefix, const eval_scene *sc, double duration,
                  eval_series *s, eval_result *res, char *err, size_t errlen)
{
    lag_log *lg = lag_log_open(path, 1 << 20, err, errlen);
    if (!lg) return -1;
    eval_take tk;
    eval_take_init(&tk, prefix, sc, s, res);
    int rc;
    lag_log_record rec;
    while ((rc = lag_log_next(lg, &rec)) == LAG_LOG_OK && !tk.oom) eval_take_record(&tk, &rec);
    if (rc == LAG_LOG_ERROR || tk.oom) {
        snprintf(err, errlen, "%s: %s", path, tk.oom ? "out of memory" : lag_log_errmsg(lg));
        lag_log_close(lg);
        return -1;
    }
    lag_log_close(lg);
    take_end(&tk, duration);
    if (s->n && !res->failed && !tk.stopped_at_duration)
        eval_fail(res, "the daemon did not stop on its duration");
    return 0;
}

int eval_score(const eval_series *s, const eval_case *c, const eval_scene *sc,
               eval_result *res, char *err, size_t errlen)
{
    res->nj = sc->nj;
    lag_metric_opts o = lag_metric_opts_default();
    for (int j = 0; j < sc->nj; j++) {
        for (int m = 0; m < LAG_METRIC_COUNT; m++) res->m[j].v[m] = NAN;
        res->m[j].step = NAN;
        double mx = 0;
        for (size_t k = 0; k < s->n; k++)
            if (fabs(s->q[j][k]) > mx || !isfinite(s->q[j][k])) mx = fabs(s->q[j][k]);
        res->max_abs_q[j] = s->n ? mx : NAN;
        if (s->n < 2) continue;
        char merr[256];
        if (lag_metrics_compute(s->t, s->q[j], s->r[j], s->u[j], s->n, &o, &res->m[j], merr,
                                sizeof merr) != 0) {
            snprintf(err, errlen, "%s: %s", sc->joint[j], merr);
            return -1;
        }
    }
    for (int b = 0; b < c->nbounds; b++)
        for (int j = 0; j < sc->nj; j++)
            if (!strcmp(c->bound_joint[b], sc->joint[j]) && !(res->max_abs_q[j] <= c->bound[b]))
                eval_fail(res, "%s reached %.6g, past its bound %.6g", sc->joint[j],
                     res->max_abs_q[j], c->bound[b]);
    return 0;
}

/* ---------------------------------------------------------------- one run */
/* lagsimd --config S --set ... : argv, its strings built in one arena */
enum { ARGS_MAX = 2 * (EVAL_SETS_MAX * 2 + 16) };
typedef struct daemon_args {
    char *argv[ARGS_MAX];
    char owned[8][600];
    char owned_sets[EVAL_OWN_COUNT][EVAL_SET_LEN];
    int na, no;
} daemon_args;

static void arg(daemon_args *d, const char *a) { d->argv[d->na++] = (char *)a; }

/* A buffer of d's own for an argument (filled by the caller, then arg()). */
static char *own(daemon_args *d) { return d->owned[d->no++]; }
#define OWN_CAP sizeof ((daemon_args *)0)->owned[0]

static void daemon_argv(daemon_args *d, const eval_env *env, const eval_case *c,
                        const char *const *extra, int nextra, const char *log)
{
    d->na = d->no = 0;
    arg(d, env->lagsimd);
    arg(d, "--config");
    arg(d, env->config);
    eval_owned_sets(env, false, d->owned_sets);
    for (int i = 0; i < EVAL_OWN_COUNT; i++) {
        arg(d, "--set");
        arg(d, d->owned_sets[i]);
    }
    for (int i = 0; i < c->nsets && d->na + 2 < ARGS_MAX - 8; i++) {
        arg(d, "--set");
        arg(d, c->set[i]);
    }
    for (int i = 0; i < nextra && d->na + 2 < ARGS_MAX - 8; i++) {
        arg(d, "--set");
        arg(d, extra[i]);
    }
    char *o = own(d);
    char num[LAG_NUM_LEN];
    snprintf(o, OWN_CAP, "%s", lag_num(c->duration, num));
    arg(d, "--duration");
    arg(d, o);
    arg(d, "--log");
    arg(d, log);
    arg(d, "-q");
    d->argv[d->na] = NULL;
}

/* The controller has ended: whether the daemon ends by itself within 5 s (a controller
 * ends on the daemon's stop event, a moment before the daemon exits). A daemon whose
 * status says it waits for a command never will (nothing else answers it): false at
 * once. OUT: dst */
static bool daemon_after(eval_watch *watch, pid_t dpid, int *dst)
{
    double since = eval_now_wall(), end = eval_now() + 5.0;
    while (eval_now() < end) {
        if (eval_wait_until(dpid, eval_now() + 0.05, dst)) return true;
        if (eval_watch_stuck(watch, since)) return false;
    }
    return false;
}

/* Waits for the daemon's end, or the controller's (true when --timeout ended it): a controller that ends first (it could
 * not start, it crashed) leaves a lockstep plant waiting for ever, so the daemon gets a
 * few seconds to end on its own (a controller ends on the daemon's stop event, a moment
 * before the daemon exits) and is then stopped. OUT: dst (the daemon's wait status) */
static bool wait_run(const eval_env *env, pid_t dpid, pid_t cpid, eval_result *res, int *dst)
{
    int cst = 0;
    double t0 = eval_now();
    bool daemon_done = false, controller_done = false;
    eval_watch *watch = eval_watch_start(env->url, env->prefix, env->wall_timeout,
                                         env->who[0] ? env->who : NULL);
    while (!daemon_done && eval_now() < t0 + env->wall_timeout) {
        daemon_done = eval_wait_until(dpid, eval_now() + 0.05, dst);
        eval_watch_poll(watch);
        if (!daemon_done && !controller_done && eval_wait_until(cpid, 0, &cst)) {
            controller_done = true;
            if (!daemon_after(watch, dpid, dst)) {
                eval_stop_group(dpid, dst);
                char hint[200];
                eval_url_hint(env->controller, env->url, hint, sizeof hint);
                eval_fail(res, "the controller ended (%s %d) before the run did%s",
                     WIFEXITED(cst) ? "exit status" : "signal",
                     WIFEXITED(cst) ? WEXITSTATUS(cst) : WTERMSIG(cst), hint);
            }
            daemon_done = true;
        }
    }
    eval_watch_stop(watch);
    bool timed_out = !daemon_done;
    if (timed_out) {
        eval_stop_group(dpid, dst);
        eval_fail(res, "no end after %.3g wall s (--timeout)", env->wall_timeout);
    }
    /* a controller ends on the daemon's stop event; one that does not is stopped */
    if (!controller_done && !eval_wait_until(cpid, eval_now() + 3.0, &cst)) eval_stop_group(cpid, &cst);
    return timed_out;
}

void eval_stderr_paths(const eval_env *env, char *controller, char *daemon, size_t len)
{
    snprintf(controller, len, "%s/%s.controller.stderr", env->workdir, env->prefix);
    snprintf(daemon, len, "%s/%s.lagsimd.stderr", env->workdir, env->prefix);
}

#define TAIL_LINES 8
#define TAIL_LINE_MAX 200

void eval_stderr_tail(const char *path, const char *who, char *out, size_t cap)
{
    FILE *f = fopen(path, "r");
    if (!f) return;
    char buf[4096];
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    long from = size > (long)sizeof buf - 1 ? size - (long)sizeof buf + 1 : 0;
    size_t n = size > 0 && fseek(f, from, SEEK_SET) == 0 ? fread(buf, 1, sizeof buf - 1, f) : 0;
    fclose(f);
    while (n > 0 && (buf[n - 1] == '\n' || buf[n - 1] == '\r')) n--;
    if (n == 0) return;
    buf[n] = '\0';
    /* the start of the last TAIL_LINES lines (a line cut by the read's start counts) */
    size_t start = n;
    int lines = 1;
    for (; start > 0; start--)
        if (buf[start - 1] == '\n' && lines++ == TAIL_LINES) {
            lines = TAIL_LINES;
            break;
        }
    size_t u = strlen(out);
    int w = snprintf(out + u, cap - u, "%s's stderr, its last %d line%s:\n", who, lines,
                     lines > 1 ? "s" : "");
    for (char *line = buf + start; w >= 0 && (u = strlen(out)) + 4 < cap;) {
        char *nl = strchr(line, '\n');
        size_t len = nl ? (size_t)(nl - line) : strlen(line);
        char one[TAIL_LINE_MAX + 1];
        size_t k = 0;
        for (; k < len && k < TAIL_LINE_MAX; k++) {
            unsigned char ch = (unsigned char)line[k];
            one[k] = ch < 0x20 || ch == 0x7f ? ' ' : (char)ch;
        }
        one[k] = '\0';
        w = snprintf(out + u, cap - u, "| %s\n", one);
        if (!nl) break;
        line = nl + 1;
    }
}

/* Without -v: a failed run keeps the last lines of what its processes said; the files go. */
static void stderr_done(const eval_env *env, const char *cerr, const char *derr,
                        eval_result *res, bool keep)
{
    if (env->verbose) return;
    if (keep) {
        eval_stderr_tail(cerr, "the controller", res->output, sizeof res->output);
        eval_stderr_tail(derr, "lagsimd", res->output, sizeof res->output);
    }
    unlink(cerr);
    unlink(derr);
}

int eval_run(const eval_env *env, const eval_case *c, const char *const *extra, int nextra,
             const eval_scene *sc, eval_result *res, eval_series *out, char *err,
             size_t errlen)
{
    memset(res, 0, sizeof *res);
    res->nj = sc->nj;
    char log[1024];
    snprintf(log, sizeof log, "%s/%s.lcm", env->workdir, env->prefix);
    unlink(log);
    daemon_args d;
    daemon_argv(&d, env, c, extra, nextra, log);

    char cmd[4096], cerr[1100], derr[1100];
    if (eval_expand(env->controller, env, cmd, sizeof cmd, err, errlen)) return -1;
    eval_stderr_paths(env, cerr, derr, sizeof cerr);
    /* the controller first: in lockstep it then answers the first state (clients.md) */
    pid_t cpid = eval_spawn(NULL, cmd, env, cerr);
    if (cpid < 0) {
        snprintf(err, errlen, "cannot start the controller: %s", strerror(errno));
        return -1;
    }
    pid_t dpid = eval_spawn(d.argv, NULL, env, derr);
    if (dpid < 0) {
        snprintf(err, errlen, "cannot start %s: %s", env->lagsimd, strerror(errno));
        int st;
        eval_stop_group(cpid, &st);
        stderr_done(env, cerr, derr, res, false);
        return -1;
    }
    int dst = 0;
    bool timed_out = wait_run(env, dpid, cpid, res, &dst);

    if (WIFEXITED(dst) && WEXITSTATUS(dst) == 2) {
        stderr_done(env, cerr, derr, res, true); /* lagsimd says why */
        snprintf(err, errlen, "lagsimd refused the case '%s' (exit 2)%s%.*s", c->name,
                 res->output[0] ? ":\n" : "; rerun with -v", (int)(errlen > 64 ? errlen - 64 : 0),
                 res->output);
        unlink(log);
        return -1;
    }
    if (WIFEXITED(dst) && WEXITSTATUS(dst) == 127) {
        stderr_done(env, cerr, derr, res, false);
        snprintf(err, errlen, "cannot run %s", env->lagsimd);
        return -1;
    }
    eval_series local = {0};
    eval_series *s = out ? out : &local;
    memset(s, 0, sizeof *s);
    int rc = eval_read_log(log, env->prefix, sc, c->duration, s, res, err, errlen);
    if (rc == 0 && timed_out && !(s->n && s->t[s->n - 1] > 0)) {
        /* lockstep waits at t = 0 for the first command: nothing answered it */
        res->failed = false;
        eval_fail(res, "no end after %.3g wall s (--timeout): no command answered the first "
                       "state (is the controller on the run's prefix: {prefix} or "
                       "LAGSIM_PREFIX?)", env->wall_timeout);
    }
    if (rc == 0) {
        if (!(WIFEXITED(dst) && WEXITSTATUS(dst) == 0))
            eval_fail(res, "lagsimd ended with %s %d",
                 WIFEXITED(dst) ? "exit status" : "signal",
                 WIFEXITED(dst) ? WEXITSTATUS(dst) : WTERMSIG(dst));
        rc = eval_score(s, c, sc, res, err, errlen);
    }
    if (!out) eval_series_free(&local);
    if (!env->verbose) unlink(log);
    stderr_done(env, cerr, derr, res, rc != 0 || res->failed);
    return rc;
}

/* ---------------------------------------------------------------- requirements */
static int joint_index(const eval_scene *sc, const char *name)
{
    for (int j = 0; j < sc->nj; j++)
        if (!strcmp(sc->joint[j], name)) return j;
    return -1;
}

int eval_require_check(const lag_require *req, const eval_scene *sc, char *err, size_t len)
{
    for (int i = 0; i < req->n; i++)
        if (joint_index(sc, req->term[i].joint) < 0) {
            char names[256] = "";
            for (int j = 0; j < sc->nj; j++) {
                size_t u = strlen(names);
                snprintf(names + u, sizeof names - u, "%s%s", j ? ", " : "", sc->joint[j]);
            }
            snprintf(err, len, "the %s has no joint '%s' (it has %s)", sc->model,
                     req->term[i].joint, names);
            return -1;
        }
    return 0;
}

bool eval_require_holds(const lag_require *req, const eval_scene *sc, const eval_result *res,
                        char *why, size_t len)
{
    size_t n = 0;
    int failed = 0, said = 0;
    if (len) why[0] = '\0';
    for (int i = 0; i < req->n; i++) {
        int j = joint_index(sc, req->term[i].joint);
        if (j >= 0 && lag_require_term_holds(&req->term[i], &res->m[j])) continue;
        failed++;
        char t[160], v[32], one[220];
        lag_require_term_format(&req->term[i], t, sizeof t);
        eval_fmt(j < 0 ? NAN : res->m[j].v[req->term[i].metric], v, sizeof v);
        int w = snprintf(one, sizeof one, "%s%s fails (%s)", said ? "; " : "", t, v);
        /* every failing term, as long as the caller's buffer keeps room to say how many
         * more there are */
        if (w > 0 && n + (size_t)w + 40 < len) {
            memcpy(why + n, one, (size_t)w + 1);
            n += (size_t)w;
            said++;
        }
    }
    if (failed > said && n + 40 <= len)
        snprintf(why + n, len - n, "%sand %d more term%s fail", said ? "; " : "", failed - said,
                 failed - said > 1 ? "s" : "");
    return failed == 0;
}

void eval_fmt(double v, char *buf, size_t len)
{
    if (isnan(v)) snprintf(buf, len, "nan");
    else snprintf(buf, len, "%.6g", v);
}

void eval_default_lagsimd(char *buf, size_t len)
{
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n > 0) {
        self[n] = '\0';
        snprintf(buf, len, "%s/lagsimd", dirname(self));
        if (access(buf, X_OK) == 0) return;
    }
    snprintf(buf, len, "lagsimd");
}

FILE *eval_open_out(const char *prog, const char *what, const char *path, bool force,
                    const char *const *in, int nin)
{
    char err[512];
    int fd = lag_out_open(what, path, force, in, nin, 0, err, sizeof err);
    if (fd < 0) {
        fprintf(stderr, "%s: %s\n", prog, err);
        return NULL;
    }
    return fdopen(fd, "w");
}

/* The next word of a shell command at *p into w (of 1024 bytes): quotes removed, a word
 * cut at 1023 bytes. false at the command's end. */
static bool shell_word(const char **p, char *w)
{
    const char *s = *p;
    while (*s && (strchr(" \t\n;&|<>()", *s))) s++;
    if (!*s) return false;
    size_t n = 0;
    char quote = 0;
    for (; *s && (quote || !strchr(" \t\n;&|<>()", *s)); s++) {
        char c = *s;
        if (quote == '\'') {
            if (c == '\'') { quote = 0; continue; }
        } else if (c == '\\' && s[1] && (!quote || strchr("\"\\$`", s[1]))) {
            c = *++s;
        } else if (c == '"' || (c == '\'' && !quote)) {
            quote = quote ? 0 : c;
            continue;
        }
        if (n < 1023) w[n++] = c;
    }
    w[n] = '\0';
    *p = s;
    return true;
}

int eval_command_files(const char *cmd, char (*out)[1024], int max)
{
    char w[1024];
    int n = 0;
    struct stat st;
    while (n < max && shell_word(&cmd, w))
        if (stat(w, &st) == 0 && S_ISREG(st.st_mode)) snprintf(out[n++], 1024, "%s", w);
    return n;
}
