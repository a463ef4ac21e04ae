/*
 * The generated blocks (lists.h): each a function of the core's tables (models with their
 * lag_model_doc, methods, effects), the bus's channel table, or the shipped scenes.
 */
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_internal.h"
#include "lagsim_bus.h"
#include "reference.h"
#include "lists.h"

/* ---------------------------------------------------------------- strings */

static void grow(lbuf *b, size_t more)
{
    if (b->n + more + 1 <= b->cap) return;
    size_t cap = b->cap ? b->cap : 256;
    while (cap < b->n + more + 1) cap *= 2;
    char *s = realloc(b->s, cap);
    if (!s) {
        fputs("lagsim_lists: out of memory\n", stderr);
        exit(1);
    }
    b->s = s;
    b->cap = cap;
}

void lb_putn(lbuf *b, const char *text, size_t n)
{
    grow(b, n);
    memcpy(b->s + b->n, text, n);
    b->n += n;
    b->s[b->n] = '\0';
}

void lb_put(lbuf *b, const char *text)
{
    lb_putn(b, text, strlen(text));
}

void lb_printf(lbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n <= 0) return;
    grow(b, (size_t)n);
    va_start(ap, fmt);
    vsnprintf(b->s + b->n, (size_t)n + 1, fmt, ap);
    va_end(ap);
    b->n += (size_t)n;
}

void lb_free(lbuf *b)
{
    free(b->s);
    *b = (lbuf){0};
}

/* "a, b, c or d" (conj "or"/"and") of n items, item k written by put(b, k). */
static void prose_list(lbuf *b, int n, const char *conj, void (*put)(lbuf *, int))
{
    for (int k = 0; k < n; k++) {
        if (k > 0) lb_printf(b, k == n - 1 ? " %s " : ", ", conj);
        put(b, k);
    }
}

static const lag_model_class *model(int k) { return lag_models[k]; }
static const char *model_name(int k) { return model(k)->info->name; }

/* ---------------------------------------------------------------- models */

/* README's first paragraph: "a **sliding stick**, ... and a **flying stick**" */
static void put_title(lbuf *b, int k)
{
    const char *t = model(k)->doc->title;
    lb_printf(b, "%s **%s**", strchr("aeiou", t[0]) ? "an" : "a", t);
}

static bool gen_model_titles(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    prose_list(out, LAG_MODEL_COUNT, "and", put_title);
    return true;
}

/* A name or a phrase in troff: a hyphen in a name is \- (not a break point), a backslash
 * is \e. */
static void troff_text(lbuf *b, const char *s, bool name)
{
    for (; *s; s++) {
        if (*s == '-' && name) lb_put(b, "\\-");
        else if (*s == '\\') lb_put(b, "\\e");
        else lb_putn(b, s, 1);
    }
}

/* lagsimd.1's DESCRIPTION: ".B stick" and "(a stick sliding on a frictionless floor)," */
static bool gen_man_models(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        lb_put(out, ".B ");
        troff_text(out, model_name(k), true);
        lb_put(out, "\n(");
        troff_text(out, model(k)->doc->summary, false);
        lb_put(out, k == LAG_MODEL_COUNT - 1 ? ")\n" : k == LAG_MODEL_COUNT - 2 ? ") or\n" : "),\n");
    }
    return true;
}

/* What a coordinate's unit and its input's are: m and N, or rad and N m. */
static const char *joint_unit(const lag_model_info *inf, int j) { return inf->angular[j] ? "rad" : "m"; }
static const char *effort_unit(const lag_model_info *inf, int j) { return inf->angular[j] ? "N m" : "N"; }

static const char *rule_text(lag_param_rule r)
{
    return r == LAG_PARAM_ANY ? "any" : r == LAG_PARAM_NONNEGATIVE ? ">= 0" : "> 0";
}

/* A parameter's default: its number, or a rod's m l^2/12 in the model's names. */
static void put_default(lbuf *b, const lag_model_info *inf, int i)
{
    for (int r = 0; r < inf->n_rods; r++)
        if (inf->rods[r].inertia == i) {
            lb_printf(b, "%s %s^2/12", inf->param_names[inf->rods[r].mass],
                      inf->param_names[inf->rods[r].length]);
            return;
        }
    lb_printf(b, "%g", inf->param_defaults[i]);
}

/* docs/scenes.md: every model's parameters, a row each */
static bool gen_model_params(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    lb_put(out, "| model | key | default | unit | sign | meaning |\n|---|---|---|---|---|---|\n");
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        const lag_model_info *inf = model(k)->info;
        for (int i = 0; i < inf->np; i++) {
            lb_printf(out, "|%s%s | `%s` | ", i == 0 ? " " : "", i == 0 ? inf->name : "",
                      inf->param_names[i]);
            put_default(out, inf, i);
            bool rod = isnan(inf->param_defaults[i]);
            lb_printf(out, " | %s | %s | %s%s |\n", inf->param_units[i],
                      rule_text(inf->param_rules[i]), model(k)->doc->params[i],
                      rod ? " (a uniform rod's if not given)" : "");
        }
    }
    return true;
}

/* docs/scenes.md: every model's coordinates, in the order of initial.q and the state */
static bool gen_model_joints(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    lb_put(out, "| model | coordinate | unit | input | meaning |\n|---|---|---|---|---|\n");
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        const lag_model_info *inf = model(k)->info;
        for (int j = 0; j < inf->nq; j++) {
            lb_printf(out, "|%s%s | `%s` | %s | ", j == 0 ? " " : "", j == 0 ? inf->name : "",
                      inf->joint_names[j], joint_unit(inf, j));
            if (inf->actuated[j]) lb_printf(out, "%s", effort_unit(inf, j));
            else lb_put(out, "none");
            lb_printf(out, " | %s |\n", model(k)->doc->joints[j]);
        }
    }
    return true;
}

/* The model's source file by the naming rule (server/core/model_<name, - as _>.c);
 * false if the tree has no such file. */
static bool model_file(lists_ctx *cx, int k, char *rel, size_t len)
{
    char base[64], path[1024];
    snprintf(base, sizeof base, "%s", model_name(k));
    for (char *c = base; *c; c++)
        if (*c == '-') *c = '_';
    snprintf(rel, len, "server/core/model_%s.c", base);
    snprintf(path, sizeof path, "%s/%s", cx->source, rel);
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(cx->err, sizeof cx->err, "model '%s': no file %s (a model is written in "
                 "server/core/model_<name>.c, a '-' of its name as '_')", model_name(k), rel);
        return false;
    }
    fclose(f);
    return true;
}

/* docs/models.md: the table of models, with the file that derives each */
static bool gen_models(lbuf *out, lists_ctx *cx)
{
    lb_put(out, "| model | what it is | coordinates | inputs on | written in |\n"
                "|---|---|---|---|---|\n");
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        const lag_model_info *inf = model(k)->info;
        char rel[256];
        if (!model_file(cx, k, rel, sizeof rel)) return false;
        lb_printf(out, "| `%s` | %s | ", inf->name, model(k)->doc->summary);
        for (int j = 0; j < inf->nq; j++)
            lb_printf(out, "%s`%s` (%s)", j ? ", " : "", inf->joint_names[j], joint_unit(inf, j));
        lb_put(out, " | ");
        for (int j = 0, n = 0; j < inf->nq; j++)
            if (inf->actuated[j]) lb_printf(out, "%s`%s` (%s)", n++ ? ", " : "", inf->joint_names[j],
                                            effort_unit(inf, j));
        lb_printf(out, " | `%s` |\n", rel);
    }
    return true;
}

/* "stick `x, phi`; manipulator `q1, q2`; ..." */
static void put_joints(lbuf *b, int k)
{
    const lag_model_info *inf = model(k)->info;
    lb_printf(b, "%s `", inf->name);
    for (int j = 0; j < inf->nq; j++) lb_printf(b, "%s%s", j ? ", " : "", inf->joint_names[j]);
    lb_put(b, "`");
}

static bool gen_joints(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        if (k) lb_put(out, "; ");
        put_joints(out, k);
    }
    return true;
}

/* ---------------------------------------------------------------- shipped scenes */

/* A scene file's model (its top-level `model:` line) and the first sentence of its
 * leading comment. False when it has no `model:` line. */
static bool scene_facts(const char *path, char *model_out, size_t mlen, lbuf *what)
{
    FILE *f = fopen(path, "r");
    if (!f) return false;
    char line[1024];
    bool head = true, said = false, found = false;
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        if (head && line[0] == '#' && !said) {
            const char *t = line + 1 + (line[1] == ' ');
            const char *stop = strstr(t, ". ");
            if (!stop && t[0] && t[strlen(t) - 1] == '.') stop = t + strlen(t) - 1;
            if (what->n) lb_put(what, " ");
            lb_putn(what, t, stop ? (size_t)(stop - t) + 1 : strlen(t));
            said = stop != NULL;
        } else if (line[0] != '#') {
            head = false;
        }
        if (strncmp(line, "model:", 6) == 0 && mlen >= 64)
            found = sscanf(line + 6, " %63[^ #\t]", model_out) == 1;
    }
    fclose(f);
    return found;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The names of the scenes in config/ (.yaml), sorted; their count, or -1 (cx->err). */
static int scene_files(lists_ctx *cx, char ***names)
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/config", cx->source);
    DIR *d = opendir(dir);
    if (!d) {
        snprintf(cx->err, sizeof cx->err, "cannot read %.400s", dir);
        return -1;
    }
    int n = 0, cap = 16;
    char **v = malloc((size_t)cap * sizeof *v);
    for (struct dirent *e; v && (e = readdir(d)) != NULL;) {
        size_t len = strlen(e->d_name);
        if (len < 6 || strcmp(e->d_name + len - 5, ".yaml") != 0 || e->d_name[0] == '.') continue;
        if (n == cap) v = realloc(v, (size_t)(cap *= 2) * sizeof *v);
        if (v) v[n++] = strdup(e->d_name);
    }
    closedir(d);
    if (!v) {
        snprintf(cx->err, sizeof cx->err, "out of memory");
        return -1;
    }
    qsort(v, (size_t)n, sizeof *v, by_name);
    *names = v;
    return n;
}

static void free_names(char **v, int n)
{
    for (int i = 0; i < n; i++) free(v[i]);
    free(v);
}

/* One row of the table of shipped scenes; false if the file names no model of the
 * table. has[k]: a scene of model k was seen. */
static bool scene_row(lbuf *out, lists_ctx *cx, const char *file, bool *has)
{
    char path[1024], mname[64] = "";
    lbuf what = {0};
    snprintf(path, sizeof path, "%s/config/%s", cx->source, file);
    bool ok = scene_facts(path, mname, sizeof mname, &what);
    int k = ok ? lag_model_kind_from_name(mname) : -1;
    if (k < 0)
        snprintf(cx->err, sizeof cx->err, "config/%s: %s", file,
                 ok ? "its model is not one of the core's table" : "no top-level `model:` line");
    else
        lb_printf(out, "| `config/%s` | %s | %s |\n", file, mname, what.n ? what.s : "");
    if (k >= 0) has[k] = true;
    lb_free(&what);
    return k >= 0;
}

/* docs/scenes.md: the shipped scenes, each described by its own first comment; every
 * model of the table must have one (a model without a scene to run is not done). */
static bool gen_configs(lbuf *out, lists_ctx *cx)
{
    char **files = NULL;
    int n = scene_files(cx, &files);
    if (n < 0) return false;
    bool has[LAG_MODEL_COUNT] = {false}, ok = true;
    lb_put(out, "| file | model | what it is |\n|---|---|---|\n");
    for (int i = 0; i < n && ok; i++) ok = scene_row(out, cx, files[i], has);
    free_names(files, n);
    for (int k = 0; k < LAG_MODEL_COUNT && ok; k++)
        if (!has[k]) {
            snprintf(cx->err, sizeof cx->err, "model '%s' has no shipped scene: add config/%s.yaml "
                     "(docs/extending.md, a model)", model_name(k), model_name(k));
            ok = false;
        }
    return ok;
}

/* ---------------------------------------------------------------- methods, effects, channels */

static bool gen_methods(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    lb_put(out, "| `integrator.method` | order | step | stage equations | over long runs |\n"
                "|---|---|---|---|---|\n");
    for (int m = 0; m < LAG_METHOD_COUNT; m++) {
        const lag_method_info *mi = lag_method_info_get((lag_method)m);
        lb_printf(out, "| `%s` | %d | %s | %s | %s |\n", mi->name, mi->order,
                  mi->adaptive ? "adaptive (`rtol`, `atol`, `dt_min`, `max_steps`), "
                                 "landing on every tick of `dt`" : "fixed, `dt`",
                  mi->implicit ? "implicit: Newton (`max_iter`, `newton_tol`)" : "explicit",
                  mi->canonical ? "symplectic in (q, p): the energy error stays bounded, a "
                                  "cyclic coordinate's momentum is kept to `newton_tol`"
                                : "the energy error grows with time");
    }
    return true;
}

static bool gen_method_count(lbuf *out, lists_ctx *cx)
{
    static const char *const words[] = {"no", "one", "two", "three", "four", "five", "six",
                                        "seven", "eight", "nine", "ten", "eleven", "twelve"};
    (void)cx;
    if (LAG_METHOD_COUNT < (int)(sizeof words / sizeof words[0])) lb_put(out, words[LAG_METHOD_COUNT]);
    else lb_printf(out, "%d", LAG_METHOD_COUNT);
    return true;
}

static void put_effect(lbuf *b, int k) { lb_put(b, lag_effect_info_get(k).name); }

/* "damping, limits, ... and spring": the effects of the table, in its order */
static bool gen_effects(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    prose_list(out, LAG_EFF_COUNT, "and", put_effect);
    return true;
}

/* "step, ramp, ...": the kinds of reference a scene's reference.<joint>.type takes */
static bool gen_reference_kinds(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    for (int k = 0; k < LAG_REF_KIND_COUNT; k++)
        lb_printf(out, "%s%s", k ? ", " : "", lag_ref_kind_table[k].name);
    return true;
}

/* The effects whose row may keep state of its own (what a replay restart cannot redo),
 * in the table's order: "limits, floor, friction, actuator" */
static bool gen_keeps_state(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    int n = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        lag_effect_info e = lag_effect_info_get(k);
        if (e.keeps_state) lb_printf(out, "%s%s", n++ ? ", " : "", e.name);
    }
    return true;
}

/* The channels a plant publishes (the state URL) or takes (the command URL):
 * "`<PREFIX>_STATE`, `_STATUS`, ..." */
static void channels(lbuf *out, bool input)
{
    int n = 0;
    for (int c = 0; c < LAG_BUS_CHANNEL_COUNT; c++)
        if (lag_bus_is_input((lag_bus_channel)c) == input)
            lb_printf(out, n++ ? ", `%s`" : "`<PREFIX>%s`", lag_bus_suffix((lag_bus_channel)c));
}

static bool gen_channels_state(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    channels(out, false);
    return true;
}

static bool gen_channels_command(lbuf *out, lists_ctx *cx)
{
    (void)cx;
    channels(out, true);
    return true;
}

/* ---------------------------------------------------------------- the tables */

const lists_block lists_blocks[] = {
    {"model-titles", false, gen_model_titles, "the models' titles in a sentence (README.md)"},
    {"man-models", true, gen_man_models, "troff: each model's name and summary (lagsimd.1)"},
    {"model-params", true, gen_model_params, "every model's parameters (docs/scenes.md)"},
    {"model-joints", true, gen_model_joints, "every model's coordinates (docs/scenes.md)"},
    {"models", true, gen_models, "the table of models and their files (docs/models.md)"},
    {"joints", false, gen_joints, "each model's coordinates in a sentence"},
    {"configs", true, gen_configs, "the shipped scenes, a row per config/ file (every model has one)"},
    {"methods", true, gen_methods, "the integrators and their properties"},
    {"method-count", false, gen_method_count, "how many integrators, in words"},
    {"effects", false, gen_effects, "the effects in a sentence"},
    {"reference-kinds", false, gen_reference_kinds, "the kinds of reference (reference.<joint>.type)"},
    {"keeps-state", false, gen_keeps_state, "the effects that may keep state of their own"},
    {"channels-state", false, gen_channels_state, "the channels on a plant's state URL"},
    {"channels-command", false, gen_channels_command, "the channels on a plant's command URL"},
};
const int lists_block_count = (int)(sizeof lists_blocks / sizeof lists_blocks[0]);

const lists_block *lists_block_find(const char *name, size_t len)
{
    for (int i = 0; i < lists_block_count; i++)
        if (strlen(lists_blocks[i].name) == len && strncmp(lists_blocks[i].name, name, len) == 0)
            return &lists_blocks[i];
    return NULL;
}

bool lists_tail(lbuf *out, const char *what, size_t len)
{
    char buf[1024];
    const char *text = NULL;
    if (len == 6 && strncmp(what, "models", 6) == 0) {
        text = lag_model_names(buf, sizeof buf);
    } else if (len == 7 && strncmp(what, "methods", 7) == 0) {
        text = lag_method_names(buf, sizeof buf);
    } else if (len == 7 && strncmp(what, "effects", 7) == 0) {
        buf[0] = '\0';
        for (int k = 0; k < LAG_EFF_COUNT; k++)
            snprintf(buf + strlen(buf), sizeof buf - strlen(buf), "%s%s", k ? ", " : "",
                     lag_effect_info_get(k).name);
        text = buf;
    }
    if (!text) return false;
    for (const char *p = text; *p; p++) { /* "a, b" -> "a | b" */
        if (p[0] == ',' && p[1] == ' ') {
            lb_put(out, " | ");
            p++;
        } else {
            lb_putn(out, p, 1);
        }
    }
    return true;
}
