/*
 * YAML scene files -> lag_scene, with libyaml.
 *
 * Three stages:
 *   1. parse: libyaml events -> a small in-memory tree (ynode) that keeps every node's
 *      position (1-based line:column) and where it came from (the file or a --set);
 *      duplicate keys, aliases and syntax errors are caught here.
 *   2. graft: each --set "dotted.key.path=yaml value" is parsed the same way and its
 *      tree replaces (or adds) the node at that path.
 *   3. convert: the merged tree is checked against the schema and written into a
 *      lag_scene, once. Every check names the node: "file:line:column: ..." for the file,
 *      "--set key: ..." for an override. Nothing is guessed: unknown keys, wrong types,
 *      missing values, non-finite or out-of-range numbers are errors.
 *
 * The schema is a set of small key tables (k_top_keys, k_integrator_keys, ...): adding a
 * key is one table row and one handler. Effects (issue 4) get their own table, k_effects.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "scene.h"

#define MAX_DEPTH 32 /* deeper nesting than any scene needs: an error, not a stack overflow */

/* ================================================================ the tree */

/* Where nodes come from: the scene file or one --set. */
typedef struct ysrc {
    const char *name; /* file path, or the --set's dotted key path */
    bool is_set;
} ysrc;

typedef enum { YN_SCALAR, YN_MAP, YN_SEQ } ynode_kind;

struct ynode;
typedef struct yentry {
    char *key;
    int line, col;       /* the key's position */
    const ysrc *src;     /* the key's origin */
    struct ynode *val;
} yentry;

typedef struct ynode {
    ynode_kind kind;
    int line, col;       /* 1-based start of the node */
    const ysrc *src;
    /* scalar */
    char *text;
    bool quoted;         /* single/double quoted, literal or folded: a string, never a number */
    /* map (entries) or sequence (items) */
    int n, cap;
    yentry *entries;
    struct ynode **items;
} ynode;

static void ynode_free(ynode *nd)
{
    if (!nd)
        return;
    free(nd->text);
    for (int i = 0; i < nd->n; i++) {
        if (nd->kind == YN_MAP) {
            free(nd->entries[i].key);
            ynode_free(nd->entries[i].val);
        } else if (nd->kind == YN_SEQ) {
            ynode_free(nd->items[i]);
        }
    }
    free(nd->entries);
    free(nd->items);
    free(nd);
}

static ynode *ynode_new(ynode_kind kind, int line, int col, const ysrc *src)
{
    ynode *nd = calloc(1, sizeof *nd);
    if (!nd)
        return NULL;
    nd->kind = kind;
    nd->line = line;
    nd->col = col;
    nd->src = src;
    return nd;
}

/* Grows the entry/item array by one; returns false when out of memory. */
static bool ynode_grow(ynode *nd)
{
    if (nd->n < nd->cap)
        return true;
    int cap = nd->cap ? 2 * nd->cap : 8;
    if (nd->kind == YN_MAP) {
        yentry *e = realloc(nd->entries, (size_t)cap * sizeof *e);
        if (!e)
            return false;
        nd->entries = e;
    } else {
        ynode **it = realloc(nd->items, (size_t)cap * sizeof *it);
        if (!it)
            return false;
        nd->items = it;
    }
    nd->cap = cap;
    return true;
}

static yentry *ymap_find(const ynode *map, const char *key)
{
    for (int i = 0; i < map->n; i++)
        if (strcmp(map->entries[i].key, key) == 0)
            return &map->entries[i];
    return NULL;
}

/* A "null" scalar: empty plain scalar (`dt:` with nothing), `~` or `null`. */
static bool ynode_is_null(const ynode *nd)
{
    if (nd->kind != YN_SCALAR || nd->quoted)
        return false;
    const char *t = nd->text;
    return t[0] == '\0' || strcmp(t, "~") == 0 || strcmp(t, "null") == 0 ||
           strcmp(t, "Null") == 0 || strcmp(t, "NULL") == 0;
}

static const char *ynode_kind_name(const ynode *nd)
{
    switch (nd->kind) {
    case YN_MAP: return "a mapping";
    case YN_SEQ: return "a sequence";
    case YN_SCALAR: return ynode_is_null(nd) ? "nothing" : "a scalar";
    }
    return "?";
}

/* ================================================================ errors */

typedef struct errbuf {
    char *buf;
    size_t len;
} errbuf;

/* Writes "origin: [path: ]message" where origin is "file:line:column" or "--set key". */
static void verr(errbuf *e, const ysrc *src, int line, int col, const char *path,
                 const char *fmt, va_list ap)
{
    if (!e->buf || e->len == 0)
        return;
    char msg[768];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (!src) {
        snprintf(e->buf, e->len, "%s", msg);
    } else if (src->is_set) {
        if (path && path[0] && strcmp(path, src->name) != 0)
            snprintf(e->buf, e->len, "--set %s: %s: %s", src->name, path, msg);
        else
            snprintf(e->buf, e->len, "--set %s: %s", src->name, msg);
    } else if (path && path[0]) {
        snprintf(e->buf, e->len, "%s:%d:%d: %s: %s", src->name, line, col, path, msg);
    } else {
        snprintf(e->buf, e->len, "%s:%d:%d: %s", src->name, line, col, msg);
    }
}

/* Error at a node; returns -1 so that callers can `return fail(...)`. */
static int fail(errbuf *e, const ynode *nd, const char *path, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    verr(e, nd ? nd->src : NULL, nd ? nd->line : 0, nd ? nd->col : 0, path, fmt, ap);
    va_end(ap);
    return -1;
}

/* Error at a mapping key. */
static int fail_key(errbuf *e, const yentry *en, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    verr(e, en->src, en->line, en->col, NULL, fmt, ap);
    va_end(ap);
    return -1;
}

/* ================================================================ 1. parse */

typedef struct parser {
    yaml_parser_t yp;
    const ysrc *src;
    errbuf *err;
} parser;

static int syntax_error(parser *p)
{
    const yaml_parser_t *yp = &p->yp;
    const char *problem = yp->problem ? yp->problem : "unknown error";
    errbuf *e = p->err;
    if (yp->error == YAML_MEMORY_ERROR) {
        snprintf(e->buf, e->len, "%s: out of memory while reading YAML", p->src->name);
    } else if (yp->error == YAML_READER_ERROR) {
        /* the reader reports a byte offset, not a line */
        if (p->src->is_set)
            snprintf(e->buf, e->len, "--set %s: YAML error: %s at byte %zu", p->src->name,
                     problem, yp->problem_offset);
        else
            snprintf(e->buf, e->len, "%s: YAML error: %s at byte %zu", p->src->name,
                     problem, yp->problem_offset);
    } else {
        char ctx[256] = "";
        if (yp->context)
            snprintf(ctx, sizeof ctx, " (%s at %zu:%zu)", yp->context,
                     yp->context_mark.line + 1, yp->context_mark.column + 1);
        if (p->src->is_set)
            snprintf(e->buf, e->len, "--set %s: YAML syntax error: %s%s", p->src->name,
                     problem, ctx);
        else
            snprintf(e->buf, e->len, "%s:%zu:%zu: YAML syntax error: %s%s", p->src->name,
                     yp->problem_mark.line + 1, yp->problem_mark.column + 1, problem, ctx);
    }
    return -1;
}

static int next_event(parser *p, yaml_event_t *ev)
{
    if (!yaml_parser_parse(&p->yp, ev))
        return syntax_error(p);
    return 0;
}

static int mark_line(const yaml_event_t *ev) { return (int)ev->start_mark.line + 1; }
static int mark_col(const yaml_event_t *ev) { return (int)ev->start_mark.column + 1; }

static int parse_node(parser *p, yaml_event_t *ev, int depth, ynode **out);

/* Parses the node that starts with event `ev` (consumed) into *out. */
static int parse_node(parser *p, yaml_event_t *ev, int depth, ynode **out)
{
    *out = NULL;
    int line = mark_line(ev), col = mark_col(ev);
    ynode tmp = {.line = line, .col = col, .src = p->src};
    if (depth > MAX_DEPTH) {
        yaml_event_delete(ev);
        return fail(p->err, &tmp, NULL, "nesting deeper than %d levels", MAX_DEPTH);
    }
    switch (ev->type) {
    case YAML_ALIAS_EVENT:
        yaml_event_delete(ev);
        return fail(p->err, &tmp, NULL,
                    "aliases (*name) are not supported in scenes: write the value out");
    case YAML_SCALAR_EVENT: {
        ynode *nd = ynode_new(YN_SCALAR, line, col, p->src);
        if (!nd) {
            yaml_event_delete(ev);
            return fail(p->err, &tmp, NULL, "out of memory");
        }
        size_t len = ev->data.scalar.length;
        nd->text = malloc(len + 1);
        if (!nd->text) {
            yaml_event_delete(ev);
            ynode_free(nd);
            return fail(p->err, &tmp, NULL, "out of memory");
        }
        memcpy(nd->text, ev->data.scalar.value, len);
        nd->text[len] = '\0';
        nd->quoted = ev->data.scalar.style != YAML_PLAIN_SCALAR_STYLE &&
                     ev->data.scalar.style != YAML_ANY_SCALAR_STYLE;
        yaml_event_delete(ev);
        *out = nd;
        return 0;
    }
    case YAML_SEQUENCE_START_EVENT:
    case YAML_MAPPING_START_EVENT: {
        bool is_map = ev->type == YAML_MAPPING_START_EVENT;
        yaml_event_type_t end = is_map ? YAML_MAPPING_END_EVENT : YAML_SEQUENCE_END_EVENT;
        yaml_event_delete(ev);
        ynode *nd = ynode_new(is_map ? YN_MAP : YN_SEQ, line, col, p->src);
        if (!nd)
            return fail(p->err, &tmp, NULL, "out of memory");
        for (;;) {
            yaml_event_t kev;
            if (next_event(p, &kev) < 0) {
                ynode_free(nd);
                return -1;
            }
            if (kev.type == end) {
                yaml_event_delete(&kev);
                break;
            }
            if (!ynode_grow(nd)) {
                yaml_event_delete(&kev);
                ynode_free(nd);
                return fail(p->err, &tmp, NULL, "out of memory");
            }
            if (!is_map) {
                ynode *item;
                if (parse_node(p, &kev, depth + 1, &item) < 0) {
                    ynode_free(nd);
                    return -1;
                }
                nd->items[nd->n++] = item;
                continue;
            }
            /* mapping: a scalar key, then its value */
            ynode *key;
            if (parse_node(p, &kev, depth + 1, &key) < 0) {
                ynode_free(nd);
                return -1;
            }
            if (key->kind != YN_SCALAR) {
                fail(p->err, key, NULL, "expected a plain key, got %s", ynode_kind_name(key));
                ynode_free(key);
                ynode_free(nd);
                return -1;
            }
            const yentry *dup = ymap_find(nd, key->text);
            if (dup) {
                fail(p->err, key, NULL, "duplicate key '%s' (first at %d:%d)", key->text,
                     dup->line, dup->col);
                ynode_free(key);
                ynode_free(nd);
                return -1;
            }
            yaml_event_t vev;
            ynode *val;
            if (next_event(p, &vev) < 0 || parse_node(p, &vev, depth + 1, &val) < 0) {
                ynode_free(key);
                ynode_free(nd);
                return -1;
            }
            /* A missing value (`dt:` with nothing) has no position of its own worth
             * showing: point at its key instead. */
            if (ynode_is_null(val)) {
                val->line = key->line;
                val->col = key->col;
            }
            yentry *en = &nd->entries[nd->n++];
            en->key = key->text;
            key->text = NULL;
            en->line = key->line;
            en->col = key->col;
            en->src = p->src;
            en->val = val;
            ynode_free(key);
        }
        *out = nd;
        return 0;
    }
    default: {
        int type = (int)ev->type;
        yaml_event_delete(ev);
        return fail(p->err, &tmp, NULL, "unexpected YAML event %d", type);
    }
    }
}

/* Parses one YAML document from an initialized parser. An empty stream gives a null
 * scalar at 1:1. */
static int parse_document(parser *p, ynode **out)
{
    *out = NULL;
    yaml_event_t ev;
    if (next_event(p, &ev) < 0)
        return -1;
    yaml_event_delete(&ev); /* STREAM_START */
    if (next_event(p, &ev) < 0)
        return -1;
    if (ev.type == YAML_STREAM_END_EVENT) {
        yaml_event_delete(&ev);
        ynode *nd = ynode_new(YN_SCALAR, 1, 1, p->src);
        if (!nd || !(nd->text = calloc(1, 1))) {
            ynode_free(nd);
            return fail(p->err, NULL, NULL, "out of memory");
        }
        *out = nd;
        return 0;
    }
    yaml_event_delete(&ev); /* DOCUMENT_START */
    ynode *root;
    if (next_event(p, &ev) < 0 || parse_node(p, &ev, 0, &root) < 0)
        return -1;
    if (next_event(p, &ev) < 0) { /* DOCUMENT_END */
        ynode_free(root);
        return -1;
    }
    yaml_event_delete(&ev);
    if (next_event(p, &ev) < 0) {
        ynode_free(root);
        return -1;
    }
    if (ev.type != YAML_STREAM_END_EVENT) {
        ynode tmp = {.line = mark_line(&ev), .col = mark_col(&ev), .src = p->src};
        yaml_event_delete(&ev);
        ynode_free(root);
        return fail(p->err, &tmp, NULL, "a scene is one YAML document; found a second one");
    }
    yaml_event_delete(&ev);
    *out = root;
    return 0;
}

static int parse_file(const char *path, const ysrc *src, errbuf *err, ynode **out)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err->buf, err->len, "%s: cannot open scene file: %s", path, strerror(errno));
        return -1;
    }
    parser p = {.src = src, .err = err};
    if (!yaml_parser_initialize(&p.yp)) {
        fclose(f);
        snprintf(err->buf, err->len, "%s: cannot initialize the YAML parser", path);
        return -1;
    }
    yaml_parser_set_input_file(&p.yp, f);
    int rc = parse_document(&p, out);
    yaml_parser_delete(&p.yp);
    if (rc == 0 && ferror(f)) {
        ynode_free(*out);
        *out = NULL;
        snprintf(err->buf, err->len, "%s: read error", path);
        rc = -1;
    }
    fclose(f);
    return rc;
}

static int parse_string(const char *text, const ysrc *src, errbuf *err, ynode **out)
{
    parser p = {.src = src, .err = err};
    if (!yaml_parser_initialize(&p.yp)) {
        snprintf(err->buf, err->len, "--set %s: cannot initialize the YAML parser", src->name);
        return -1;
    }
    yaml_parser_set_input_string(&p.yp, (const unsigned char *)text, strlen(text));
    int rc = parse_document(&p, out);
    yaml_parser_delete(&p.yp);
    return rc;
}

/* ================================================================ 2. graft --set */

/* Replaces or adds the node at dotted path `src->name` in `root` by `val` (taken over).
 * Intermediate mappings that do not exist are created. */
static int graft(ynode *root, const ysrc *src, ynode *val, errbuf *err)
{
    ynode *map = root;
    const char *seg = src->name;
    char pathsofar[256] = "";
    for (;;) {
        const char *dot = strchr(seg, '.');
        size_t len = dot ? (size_t)(dot - seg) : strlen(seg);
        if (len == 0) {
            ynode_free(val);
            return fail(err, &(ynode){.src = src}, NULL,
                        "empty key in the dotted path (expected e.g. integrator.dt=0.001)");
        }
        char key[128];
        if (len >= sizeof key) {
            ynode_free(val);
            return fail(err, &(ynode){.src = src}, NULL, "key too long");
        }
        memcpy(key, seg, len);
        key[len] = '\0';
        if (map->kind != YN_MAP) {
            ynode_free(val);
            if (map->src->is_set)
                return fail(err, &(ynode){.src = src}, NULL,
                            "cannot set a key inside '%s', which is %s (from --set %s)",
                            pathsofar, ynode_kind_name(map), map->src->name);
            return fail(err, &(ynode){.src = src}, NULL,
                        "cannot set a key inside '%s', which is %s at %s:%d:%d", pathsofar,
                        ynode_kind_name(map), map->src->name, map->line, map->col);
        }
        yentry *en = ymap_find(map, key);
        if (!en) {
            if (!ynode_grow(map)) {
                ynode_free(val);
                return fail(err, &(ynode){.src = src}, NULL, "out of memory");
            }
            en = &map->entries[map->n];
            en->key = malloc(len + 1);
            if (!en->key) {
                ynode_free(val);
                return fail(err, &(ynode){.src = src}, NULL, "out of memory");
            }
            memcpy(en->key, key, len + 1);
            en->line = en->col = 1;
            en->src = src;
            en->val = NULL;
            map->n++;
        }
        if (!dot) {
            ynode_free(en->val);
            en->val = val;
            en->src = src; /* the key now comes from this --set */
            return 0;
        }
        if (!en->val) {
            en->val = ynode_new(YN_MAP, 1, 1, src);
            if (!en->val) {
                ynode_free(val);
                return fail(err, &(ynode){.src = src}, NULL, "out of memory");
            }
        }
        snprintf(pathsofar + strlen(pathsofar), sizeof pathsofar - strlen(pathsofar), "%s%s",
                 pathsofar[0] ? "." : "", key);
        map = en->val;
        seg = dot + 1;
    }
}

/* ================================================================ 3. convert */

typedef struct conv {
    errbuf *err;
    lag_scene *sc;
    const lag_model_info *info;
    /* nodes remembered for the final cross-checks (NULL if not given) */
    const ynode *root, *parameters, *publish_hz, *dt, *integrator, *initial, *dt_min;
    const ynode *explode_limit, *url;
    /* effects */
    const ynode *effects, *limits_node, *floor_node, *gravity_g_node;
    int gravity_enabled;  /* -1 not said, 0 off, 1 on */
    double gravity_g;
    int limit_seen;       /* bits: lower, upper given for the joint being read */
    int cur_joint;        /* the joint whose sub-mapping is being read */
    lag_disturbance *cur_dist; /* the disturbance being read */
    int cur_dist_kind;    /* bits: impulse, force given */
} conv;

/* Joins "parent.key" into buf. */
static const char *join(char *buf, size_t len, const char *parent, const char *key)
{
    if (parent && parent[0])
        snprintf(buf, len, "%s.%s", parent, key);
    else
        snprintf(buf, len, "%s", key);
    return buf;
}

/* Lists the names of a NULL-terminated key table: "a, b, c". */
typedef struct keyrow keyrow;
typedef int (*key_fn)(conv *cv, const ynode *val, const char *path);
struct keyrow {
    const char *name;
    key_fn fn;
};

static void list_keys(char *buf, size_t len, const keyrow *rows)
{
    buf[0] = '\0';
    for (const keyrow *r = rows; r->name; r++) {
        size_t used = strlen(buf);
        snprintf(buf + used, len - used, "%s%s", r == rows ? "" : ", ", r->name);
    }
}

/* nd must be a mapping; `what` describes it ("a mapping (keys: a, b)"). Returns 0, or
 * fails with "missing value: expected <what>" or "expected <what>, got <kind>". */
static int need_map(conv *cv, const ynode *nd, const char *path, const char *what)
{
    if (nd->kind == YN_MAP)
        return 0;
    if (ynode_is_null(nd))
        return fail(cv->err, nd, path, "missing value: expected %s", what);
    return fail(cv->err, nd, path, "expected %s, got %s", what, ynode_kind_name(nd));
}

/* Walks a mapping's entries in file order and dispatches each to its table row. */
static int convert_map(conv *cv, const ynode *nd, const char *path, const keyrow *rows,
                       const char *what)
{
    if (nd->kind != YN_MAP) {
        char allowed[512], expected[600];
        list_keys(allowed, sizeof allowed, rows);
        snprintf(expected, sizeof expected, "a mapping (keys: %s)", allowed);
        return need_map(cv, nd, path, expected);
    }
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        const keyrow *r = rows;
        while (r->name && strcmp(r->name, en->key) != 0)
            r++;
        if (!r->name) {
            char allowed[512];
            list_keys(allowed, sizeof allowed, rows);
            if (!rows->name)
                return fail_key(cv->err, en, "unknown %s '%s'%s%s: none are available yet",
                                what, en->key, path[0] ? " in " : "", path);
            return fail_key(cv->err, en, "unknown %s '%s'%s%s; allowed: %s", what, en->key,
                            path[0] ? " in " : "", path, allowed);
        }
        char sub[256];
        if (r->fn(cv, en->val, join(sub, sizeof sub, path, en->key)) < 0)
            return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------- scalars */

/* A finite number: strtod on the whole plain scalar, nothing left over. */
static int get_number(conv *cv, const ynode *nd, const char *path, double *out)
{
    if (ynode_is_null(nd))
        return fail(cv->err, nd, path, "missing value: expected a number");
    if (nd->kind != YN_SCALAR)
        return fail(cv->err, nd, path, "expected a number, got %s", ynode_kind_name(nd));
    if (nd->quoted)
        return fail(cv->err, nd, path, "expected a number, got the quoted string \"%s\"",
                    nd->text);
    const char *t = nd->text;
    const char *u = (t[0] == '+' || t[0] == '-') ? t + 1 : t;
    /* YAML's own spellings of infinity and NaN */
    if (strcmp(u, ".inf") == 0 || strcmp(u, ".Inf") == 0 || strcmp(u, ".INF") == 0 ||
        strcmp(t, ".nan") == 0 || strcmp(t, ".NaN") == 0 || strcmp(t, ".NAN") == 0)
        return fail(cv->err, nd, path, "expected a finite number, got %s", t);
    errno = 0;
    char *end;
    double v = strtod(t, &end);
    if (end == t || *end != '\0')
        return fail(cv->err, nd, path, "expected a number, got '%s'", t);
    if (!isfinite(v))
        return fail(cv->err, nd, path, "expected a finite number, got %s", t);
    *out = v;
    return 0;
}

static int get_positive(conv *cv, const ynode *nd, const char *path, double *out)
{
    double v = 0.0;
    if (get_number(cv, nd, path, &v) < 0)
        return -1;
    if (!(v > 0.0))
        return fail(cv->err, nd, path, "expected a positive number, got %s", nd->text);
    *out = v;
    return 0;
}

/* An integer in [lo, hi]: strtoll on the whole plain scalar. */
static int get_int(conv *cv, const ynode *nd, const char *path, long long lo, long long hi,
                   long long *out)
{
    if (ynode_is_null(nd))
        return fail(cv->err, nd, path, "missing value: expected an integer");
    if (nd->kind != YN_SCALAR)
        return fail(cv->err, nd, path, "expected an integer, got %s", ynode_kind_name(nd));
    if (nd->quoted)
        return fail(cv->err, nd, path, "expected an integer, got the quoted string \"%s\"",
                    nd->text);
    errno = 0;
    char *end;
    long long v = strtoll(nd->text, &end, 10);
    if (end == nd->text || *end != '\0')
        return fail(cv->err, nd, path, "expected an integer, got '%s'", nd->text);
    if (errno == ERANGE || v < lo || v > hi)
        return fail(cv->err, nd, path, "expected an integer from %lld to %lld, got %s", lo,
                    hi, nd->text);
    *out = v;
    return 0;
}

/* A non-empty string scalar (quoted or plain). */
static int get_string(conv *cv, const ynode *nd, const char *path, const char *what,
                      const char **out)
{
    if (ynode_is_null(nd))
        return fail(cv->err, nd, path, "missing value: expected %s", what);
    if (nd->kind != YN_SCALAR)
        return fail(cv->err, nd, path, "expected %s, got %s", what, ynode_kind_name(nd));
    *out = nd->text;
    return 0;
}

/* ---------------------------------------------------------------- model, parameters */

static int key_model(conv *cv, const ynode *val, const char *path)
{
    (void)cv; (void)val; (void)path; /* read first, by lag_scene_load; see convert_scene */
    return 0;
}

static int key_parameters(conv *cv, const ynode *nd, const char *path)
{
    const lag_model_info *info = cv->info;
    lag_model *m = &cv->sc->sim.model;
    cv->parameters = nd;
    char allowed[256] = "";
    for (int i = 0; i < info->np; i++) {
        size_t used = strlen(allowed);
        snprintf(allowed + used, sizeof allowed - used, "%s%s", i ? ", " : "",
                 info->param_names[i]);
    }
    char what[300];
    snprintf(what, sizeof what, "a mapping (keys: %s)", allowed);
    if (need_map(cv, nd, path, what) < 0)
        return -1;
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        int k = lag_model_param_index(m->kind, en->key);
        if (k < 0)
            return fail_key(cv->err, en, "unknown parameter '%s' for model %s; allowed: %s",
                            en->key, info->name, allowed);
        char sub[256];
        join(sub, sizeof sub, path, en->key);
        double v = 0.0;
        if (get_number(cv, en->val, sub, &v) < 0)
            return -1;
        /* g >= 0 (0 switches gravity off); h0 is a height, any sign; masses, lengths and
         * inertias must be positive. */
        if (strcmp(en->key, "g") == 0) {
            if (v < 0.0)
                return fail(cv->err, en->val, sub, "expected a number >= 0, got %s",
                            en->val->text);
        } else if (strcmp(en->key, "h0") != 0) {
            if (!(v > 0.0))
                return fail(cv->err, en->val, sub, "expected a positive number (%s), got %s",
                            info->param_units[k] ? info->param_units[k] : "SI",
                            en->val->text);
        }
        m->p[k] = v;
    }
    return 0;
}

/* ---------------------------------------------------------------- initial */

static int get_vector(conv *cv, const ynode *nd, const char *path, double *out)
{
    const lag_model_info *info = cv->info;
    int nq = info->nq;
    char names[128] = "";
    for (int i = 0; i < nq; i++) {
        size_t used = strlen(names);
        snprintf(names + used, sizeof names - used, "%s%s", i ? ", " : "",
                 info->joint_names[i]);
    }
    if (ynode_is_null(nd))
        return fail(cv->err, nd, path, "missing value: expected a sequence of %d numbers (%s)",
                    nq, names);
    if (nd->kind != YN_SEQ)
        return fail(cv->err, nd, path, "expected a sequence of %d numbers (%s), got %s", nq,
                    names, ynode_kind_name(nd));
    if (nd->n != nq)
        return fail(cv->err, nd, path,
                    "expected a sequence of %d numbers (%s) for model %s, got %d", nq, names,
                    info->name, nd->n);
    for (int i = 0; i < nq; i++) {
        char sub[256];
        snprintf(sub, sizeof sub, "%s[%d]", path, i);
        if (get_number(cv, nd->items[i], sub, &out[i]) < 0)
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
    {"q", key_q},   /* rad or m, per coordinate */
    {"qd", key_qd}, /* rad/s or m/s */
    {NULL, NULL},
};

static int key_initial(conv *cv, const ynode *nd, const char *path)
{
    cv->initial = nd;
    return convert_map(cv, nd, path, k_initial_keys, "key");
}

/* ---------------------------------------------------------------- integrator */

static int key_method(conv *cv, const ynode *nd, const char *path)
{
    char allowed[256] = "";
    for (int i = 0; i < LAG_METHOD_COUNT; i++) {
        size_t used = strlen(allowed);
        snprintf(allowed + used, sizeof allowed - used, "%s%s", i ? ", " : "",
                 lag_method_name((lag_method)i));
    }
    char what[300];
    snprintf(what, sizeof what, "a method (%s)", allowed);
    const char *s;
    if (get_string(cv, nd, path, what, &s) < 0)
        return -1;
    int m = lag_method_from_name(s);
    if (m < 0)
        return fail(cv->err, nd, path, "unknown method '%s'; allowed: %s", s, allowed);
    cv->sc->sim.integrator.method = (lag_method)m;
    return 0;
}

static int key_dt(conv *cv, const ynode *nd, const char *path)
{
    cv->dt = nd;
    return get_positive(cv, nd, path, &cv->sc->sim.integrator.dt);
}

static int key_rtol(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &cv->sc->sim.integrator.rtol);
}

static int key_atol(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &cv->sc->sim.integrator.atol);
}

static int key_dt_min(conv *cv, const ynode *nd, const char *path)
{
    cv->dt_min = nd;
    return get_positive(cv, nd, path, &cv->sc->sim.integrator.dt_min);
}

static int key_max_iter(conv *cv, const ynode *nd, const char *path)
{
    long long v = 0;
    if (get_int(cv, nd, path, 1, 1000, &v) < 0)
        return -1;
    cv->sc->sim.integrator.max_iter = (int)v;
    return 0;
}

static int key_newton_tol(conv *cv, const ynode *nd, const char *path)
{
    double v = 0.0;
    if (get_positive(cv, nd, path, &v) < 0)
        return -1;
    if (!(v < 1.0))
        return fail(cv->err, nd, path, "expected a number in (0, 1), got %s", nd->text);
    cv->sc->sim.integrator.newton_tol = v;
    return 0;
}

static const keyrow k_integrator_keys[] = {
    {"method", key_method},         /* euler | semi-implicit-euler | rk4 | dopri5 | ... */
    {"dt", key_dt},                 /* s */
    {"rtol", key_rtol},             /* dopri5 */
    {"atol", key_atol},             /* dopri5 */
    {"dt_min", key_dt_min},         /* dopri5, s */
    {"max_iter", key_max_iter},     /* implicit methods */
    {"newton_tol", key_newton_tol}, /* implicit methods */
    {NULL, NULL},
};

static int key_integrator(conv *cv, const ynode *nd, const char *path)
{
    cv->integrator = nd;
    return convert_map(cv, nd, path, k_integrator_keys, "key");
}

/* ---------------------------------------------------------------- rates, limits */

static int key_publish_hz(conv *cv, const ynode *nd, const char *path)
{
    cv->publish_hz = nd;
    return get_positive(cv, nd, path, &cv->sc->publish_hz);
}

static int key_explode_limit(conv *cv, const ynode *nd, const char *path)
{
    cv->explode_limit = nd;
    return get_positive(cv, nd, path, &cv->sc->sim.explode_limit);
}

/* ---------------------------------------------------------------- realtime */

static int key_mode(conv *cv, const ynode *nd, const char *path)
{
    const char *s;
    if (get_string(cv, nd, path, "a mode (realtime, fast, lockstep)", &s) < 0)
        return -1;
    for (int m = LAG_RT_REALTIME; m <= LAG_RT_LOCKSTEP; m++) {
        if (strcmp(s, lag_rt_mode_name((lag_rt_mode)m)) == 0) {
            cv->sc->realtime.mode = (lag_rt_mode)m;
            return 0;
        }
    }
    return fail(cv->err, nd, path, "unknown mode '%s'; allowed: realtime, fast, lockstep", s);
}

static int key_rate(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &cv->sc->realtime.rate);
}

static int key_command_timeout(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &cv->sc->realtime.command_timeout);
}

static int key_lockstep_timeout(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &cv->sc->realtime.lockstep_timeout);
}

static int key_status_hz(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &cv->sc->realtime.status_hz);
}

typedef int (*joint_fn)(conv *cv, int joint, const ynode *val, const char *path);
static int per_joint(conv *cv, const ynode *nd, const char *path, joint_fn fn);
static int get_bool(conv *cv, const ynode *nd, const char *path, bool *out);

/* effort_limit: {actuated joint: bound} */
static int effort_limit_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    if (!cv->info->actuated[j])
        return fail(cv->err, nd, path, "joint %s of model %s takes no input",
                    cv->info->joint_names[j], cv->info->name);
    return get_positive(cv, nd, path, &cv->sc->realtime.effort_limit[j]);
}

static int key_effort_limit(conv *cv, const ynode *nd, const char *path)
{
    return per_joint(cv, nd, path, effort_limit_joint);
}

static const keyrow k_realtime_keys[] = {
    {"mode", key_mode},                         /* realtime | fast | lockstep */
    {"rate", key_rate},                         /* sim s per wall s */
    {"command_timeout", key_command_timeout},   /* sim s */
    {"lockstep_timeout", key_lockstep_timeout}, /* wall s */
    {"status_hz", key_status_hz},               /* Hz */
    {"effort_limit", key_effort_limit},         /* N or N m per actuated joint */
    {NULL, NULL},
};

static int key_realtime(conv *cv, const ynode *nd, const char *path)
{
    return convert_map(cv, nd, path, k_realtime_keys, "key");
}

/* ---------------------------------------------------------------- lcm */

static int key_url(conv *cv, const ynode *nd, const char *path)
{
    cv->url = nd;
    /* "" (quoted) is allowed: LCM's default URL */
    if (nd->kind == YN_SCALAR && nd->quoted && nd->text[0] == '\0') {
        cv->sc->lcm.url[0] = '\0';
        return 0;
    }
    const char *s;
    if (get_string(cv, nd, path, "an LCM URL (e.g. udpm://239.255.76.67:7667?ttl=0)", &s) < 0)
        return -1;
    if (strlen(s) >= sizeof cv->sc->lcm.url)
        return fail(cv->err, nd, path, "URL longer than %zu characters",
                    sizeof cv->sc->lcm.url - 1);
    snprintf(cv->sc->lcm.url, sizeof cv->sc->lcm.url, "%s", s);
    return 0; /* checked with lcm.allow_lan once both are read (convert_scene) */
}

static int key_allow_lan(conv *cv, const ynode *nd, const char *path)
{
    return get_bool(cv, nd, path, &cv->sc->lcm.allow_lan);
}

static int key_prefix(conv *cv, const ynode *nd, const char *path)
{
    const char *s;
    if (get_string(cv, nd, path, "a channel prefix of [A-Za-z0-9_]", &s) < 0)
        return -1;
    size_t n = strlen(s);
    if (n == 0 || n >= sizeof cv->sc->lcm.prefix)
        return fail(cv->err, nd, path, "expected a channel prefix of 1 to %zu characters",
                    sizeof cv->sc->lcm.prefix - 1);
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                  (c >= '0' && c <= '9') || c == '_';
        if (!ok)
            return fail(cv->err, nd, path,
                        "expected a channel prefix of [A-Za-z0-9_], got '%s' "
                        "(character %zu is '%c')", s, i + 1, c);
    }
    memcpy(cv->sc->lcm.prefix, s, n + 1);
    return 0;
}

static const keyrow k_lcm_keys[] = {
    {"url", key_url},       /* "" = LCM's default */
    {"prefix", key_prefix}, /* channel prefix */
    {"allow_lan", key_allow_lan}, /* bool: traffic may leave this host (ttl > 0) */
    {NULL, NULL},
};

static int key_lcm(conv *cv, const ynode *nd, const char *path)
{
    return convert_map(cv, nd, path, k_lcm_keys, "key");
}

/* ---------------------------------------------------------------- effects */

/* Effects (issue 4): each section present switches its effect on (lag_effects_def.enabled);
 * per-joint sections are mappings from joint names to values. Values are checked where
 * they are read, so errors point at the offending node. */

static lag_effects_def *fx(conv *cv) { return &cv->sc->sim.effects; }

/* A YAML boolean: true/false (also yes/no, on/off as YAML 1.1 spells them). */
static int get_bool(conv *cv, const ynode *nd, const char *path, bool *out)
{
    static const char *const yes[] = {"true", "True", "TRUE", "yes", "Yes", "on", "On", NULL};
    static const char *const no[] = {"false", "False", "FALSE", "no", "No", "off", "Off", NULL};
    if (ynode_is_null(nd))
        return fail(cv->err, nd, path, "missing value: expected true or false");
    if (nd->kind != YN_SCALAR || nd->quoted)
        return fail(cv->err, nd, path, "expected true or false, got %s", ynode_kind_name(nd));
    for (int i = 0; yes[i]; i++)
        if (strcmp(nd->text, yes[i]) == 0) { *out = true; return 0; }
    for (int i = 0; no[i]; i++)
        if (strcmp(nd->text, no[i]) == 0) { *out = false; return 0; }
    return fail(cv->err, nd, path, "expected true or false, got '%s'", nd->text);
}

static int get_nonneg(conv *cv, const ynode *nd, const char *path, double *out)
{
    double v = 0.0;
    if (get_number(cv, nd, path, &v) < 0)
        return -1;
    if (!(v >= 0.0))
        return fail(cv->err, nd, path, "expected a number >= 0, got %s", nd->text);
    *out = v;
    return 0;
}

static int get_unit(conv *cv, const ynode *nd, const char *path, double *out)
{
    double v = 0.0;
    if (get_number(cv, nd, path, &v) < 0)
        return -1;
    if (!(v >= 0.0 && v <= 1.0))
        return fail(cv->err, nd, path, "expected a restitution coefficient in [0, 1], got %s",
                    nd->text);
    *out = v;
    return 0;
}

/* "x, phi" for messages */
static void joint_list(const conv *cv, char *buf, size_t len)
{
    buf[0] = '\0';
    for (int i = 0; i < cv->info->nq; i++) {
        size_t used = strlen(buf);
        snprintf(buf + used, len - used, "%s%s", i ? ", " : "", cv->info->joint_names[i]);
    }
}

static int joint_index(const conv *cv, const char *name)
{
    for (int i = 0; i < cv->info->nq; i++)
        if (strcmp(name, cv->info->joint_names[i]) == 0) return i;
    return -1;
}

/* Walks a mapping {joint name: value} and calls fn for each joint. */
static int per_joint(conv *cv, const ynode *nd, const char *path, joint_fn fn)
{
    char names[128], what[160];
    joint_list(cv, names, sizeof names);
    snprintf(what, sizeof what, "a mapping of joints (%s)", names);
    if (need_map(cv, nd, path, what) < 0)
        return -1;
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        int j = joint_index(cv, en->key);
        if (j < 0)
            return fail_key(cv->err, en, "unknown joint '%s' in %s for model %s; allowed: %s",
                            en->key, path, cv->info->name, names);
        char sub[256];
        if (fn(cv, j, en->val, join(sub, sizeof sub, path, en->key)) < 0)
            return -1;
    }
    return 0;
}

/* gravity: {enabled: bool, g: m/s^2} -- applied after parameters (see convert_scene) */
static int key_gravity_enabled(conv *cv, const ynode *nd, const char *path)
{
    bool b = true;
    if (get_bool(cv, nd, path, &b) < 0)
        return -1;
    cv->gravity_enabled = b ? 1 : 0;
    return 0;
}

static int key_gravity_g(conv *cv, const ynode *nd, const char *path)
{
    if (get_nonneg(cv, nd, path, &cv->gravity_g) < 0)
        return -1;
    cv->gravity_g_node = nd;
    return 0;
}

static const keyrow k_gravity_keys[] = {
    {"enabled", key_gravity_enabled}, /* false: g = 0 */
    {"g", key_gravity_g},             /* m/s^2, replaces parameters.g */
    {NULL, NULL},
};

static int key_effect_gravity(conv *cv, const ynode *nd, const char *path)
{
    if (nd->kind == YN_SCALAR && !ynode_is_null(nd))
        return key_gravity_enabled(cv, nd, path); /* gravity: false */
    return convert_map(cv, nd, path, k_gravity_keys, "key");
}

/* damping: {joint: b} */
static int damping_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &fx(cv)->damping[j]);
}

static int key_effect_damping(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_DAMPING;
    return per_joint(cv, nd, path, damping_joint);
}

/* friction: {joint: {static: mu_s, kinetic: mu_k}} */
static int fr_static(conv *cv, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &fx(cv)->friction_static[cv->cur_joint]);
}

static int fr_kinetic(conv *cv, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &fx(cv)->friction_kinetic[cv->cur_joint]);
}

static const keyrow k_friction_keys[] = {
    {"static", fr_static},   /* largest holding force, N or N m */
    {"kinetic", fr_kinetic}, /* sliding force, N or N m */
    {NULL, NULL},
};

static int friction_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    cv->cur_joint = j;
    fx(cv)->friction_static[j] = NAN; /* "not given": defaults to kinetic below */
    if (convert_map(cv, nd, path, k_friction_keys, "key") < 0)
        return -1;
    lag_effects_def *e = fx(cv);
    if (isnan(e->friction_static[j])) e->friction_static[j] = e->friction_kinetic[j];
    if (e->friction_static[j] < e->friction_kinetic[j])
        return fail(cv->err, nd, path, "expected static (%g) >= kinetic (%g)",
                    e->friction_static[j], e->friction_kinetic[j]);
    return 0;
}

static int key_effect_friction(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_FRICTION;
    return per_joint(cv, nd, path, friction_joint);
}

/* limits: {joint: {lower, upper, restitution}}, plus rest_velocity for all */
static int lim_lower(conv *cv, const ynode *nd, const char *path)
{
    cv->limit_seen |= 1;
    return get_number(cv, nd, path, &fx(cv)->limit_lower[cv->cur_joint]);
}

static int lim_upper(conv *cv, const ynode *nd, const char *path)
{
    cv->limit_seen |= 2;
    return get_number(cv, nd, path, &fx(cv)->limit_upper[cv->cur_joint]);
}

static int lim_restitution(conv *cv, const ynode *nd, const char *path)
{
    return get_unit(cv, nd, path, &fx(cv)->restitution[cv->cur_joint]);
}

static const keyrow k_limit_keys[] = {
    {"lower", lim_lower},             /* m or rad */
    {"upper", lim_upper},             /* m or rad */
    {"restitution", lim_restitution}, /* [0, 1], default 0 */
    {NULL, NULL},
};

static int key_rest_velocity(conv *cv, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &fx(cv)->rest_velocity);
}

static int key_effect_limits(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_LIMITS;
    if (need_map(cv, nd, path, "a mapping of joints and rest_velocity") < 0)
        return -1;
    for (int i = 0; i < nd->n; i++) {
        const yentry *en = &nd->entries[i];
        char sub[256];
        join(sub, sizeof sub, path, en->key);
        if (strcmp(en->key, "rest_velocity") == 0) {
            if (key_rest_velocity(cv, en->val, sub) < 0) return -1;
            continue;
        }
        int j = joint_index(cv, en->key);
        if (j < 0) {
            char names[128];
            joint_list(cv, names, sizeof names);
            return fail_key(cv->err, en, "unknown joint '%s' in %s for model %s; allowed: %s, "
                            "rest_velocity", en->key, path, cv->info->name, names);
        }
        cv->cur_joint = j;
        cv->limit_seen = 0;
        if (convert_map(cv, en->val, sub, k_limit_keys, "key") < 0)
            return -1;
        if (cv->limit_seen != 3)
            return fail(cv->err, en->val, sub, "expected both lower and upper");
        lag_effects_def *e = fx(cv);
        if (!(e->limit_lower[j] < e->limit_upper[j]))
            return fail(cv->err, en->val, sub, "expected lower (%g) < upper (%g)",
                        e->limit_lower[j], e->limit_upper[j]);
        e->limit_on[j] = true;
        cv->limits_node = nd;
    }
    return 0;
}

/* floor (stick): {restitution, rest_velocity} */
static int floor_restitution(conv *cv, const ynode *nd, const char *path)
{
    return get_unit(cv, nd, path, &fx(cv)->floor_restitution);
}

static const keyrow k_floor_keys[] = {
    {"restitution", floor_restitution}, /* [0, 1], default 0 */
    {"rest_velocity", key_rest_velocity}, /* rad/s, default 1e-3 */
    {NULL, NULL},
};

static int key_effect_floor(conv *cv, const ynode *nd, const char *path)
{
    if (cv->sc->sim.model.kind != LAG_MODEL_STICK)
        return fail(cv->err, nd, path, "the floor effect is for model stick only, not %s",
                    cv->info->name);
    fx(cv)->enabled |= LAG_EFF_FLOOR;
    cv->floor_node = nd;
    if (ynode_is_null(nd))
        return 0; /* floor: with defaults */
    return convert_map(cv, nd, path, k_floor_keys, "key");
}

/* actuator: {joint: {max, lag}} on actuated joints */
static int act_max(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &fx(cv)->actuator_max[cv->cur_joint]);
}

static int act_lag(conv *cv, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &fx(cv)->actuator_tau[cv->cur_joint]);
}

static const keyrow k_actuator_keys[] = {
    {"max", act_max}, /* |effort| bound, N or N m */
    {"lag", act_lag}, /* first-order time constant, s */
    {NULL, NULL},
};

static int actuator_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    if (!cv->info->actuated[j])
        return fail(cv->err, nd, path, "joint %s of model %s takes no input",
                    cv->info->joint_names[j], cv->info->name);
    cv->cur_joint = j;
    return convert_map(cv, nd, path, k_actuator_keys, "key");
}

static int key_effect_actuator(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_ACTUATOR;
    return per_joint(cv, nd, path, actuator_joint);
}

/* disturbance: [{t, joint, impulse | force + duration}, ...] */
static int dist_t(conv *cv, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &cv->cur_dist->t);
}

static int dist_joint(conv *cv, const ynode *nd, const char *path)
{
    const char *name;
    char names[128];
    joint_list(cv, names, sizeof names);
    char what[160];
    snprintf(what, sizeof what, "a joint name (%s)", names);
    if (get_string(cv, nd, path, what, &name) < 0)
        return -1;
    int j = joint_index(cv, name);
    if (j < 0)
        return fail(cv->err, nd, path, "unknown joint '%s'; allowed: %s", name, names);
    cv->cur_dist->joint = j;
    return 0;
}

static int dist_impulse(conv *cv, const ynode *nd, const char *path)
{
    cv->cur_dist_kind |= 1;
    cv->cur_dist->impulse = true;
    return get_number(cv, nd, path, &cv->cur_dist->value);
}

static int dist_force(conv *cv, const ynode *nd, const char *path)
{
    cv->cur_dist_kind |= 2;
    cv->cur_dist->impulse = false;
    return get_number(cv, nd, path, &cv->cur_dist->value);
}

static int dist_duration(conv *cv, const ynode *nd, const char *path)
{
    return get_positive(cv, nd, path, &cv->cur_dist->duration);
}

static const keyrow k_dist_keys[] = {
    {"t", dist_t},               /* s */
    {"joint", dist_joint},       /* joint name */
    {"impulse", dist_impulse},   /* N s or N m s */
    {"force", dist_force},       /* N or N m */
    {"duration", dist_duration}, /* s, with force */
    {NULL, NULL},
};

static int key_effect_disturbance(conv *cv, const ynode *nd, const char *path)
{
    lag_effects_def *e = fx(cv);
    e->enabled |= LAG_EFF_DISTURBANCE;
    if (nd->kind != YN_SEQ)
        return fail(cv->err, nd, path,
                    "expected a sequence of {t, joint, impulse} or {t, joint, force, duration}");
    if (nd->n > LAG_MAX_DISTURBANCES)
        return fail(cv->err, nd, path, "at most %d disturbances, got %d", LAG_MAX_DISTURBANCES,
                    nd->n);
    e->n_disturbances = nd->n;
    for (int k = 0; k < nd->n; k++) {
        char sub[256];
        snprintf(sub, sizeof sub, "%s[%d]", path, k);
        cv->cur_dist = &e->disturbances[k];
        memset(cv->cur_dist, 0, sizeof *cv->cur_dist);
        cv->cur_dist->joint = -1;
        cv->cur_dist->t = NAN;
        cv->cur_dist_kind = 0;
        if (convert_map(cv, nd->items[k], sub, k_dist_keys, "key") < 0)
            return -1;
        const ynode *it = nd->items[k];
        if (isnan(cv->cur_dist->t) || cv->cur_dist->joint < 0)
            return fail(cv->err, it, sub, "expected both t and joint");
        if (cv->cur_dist_kind != 1 && cv->cur_dist_kind != 2)
            return fail(cv->err, it, sub, "expected exactly one of impulse or force");
        if (cv->cur_dist_kind == 2 && !(cv->cur_dist->duration > 0))
            return fail(cv->err, it, sub, "a force needs a duration > 0 (s)");
        if (cv->cur_dist_kind == 1 && cv->cur_dist->duration != 0)
            return fail(cv->err, it, sub, "an impulse takes no duration");
    }
    return 0;
}

/* noise: {seed, q: {joint: std}, qd: {joint: std}} */
static int noise_q_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &fx(cv)->noise_q[j]);
}

static int noise_qd_joint(conv *cv, int j, const ynode *nd, const char *path)
{
    return get_nonneg(cv, nd, path, &fx(cv)->noise_qd[j]);
}

static int noise_q(conv *cv, const ynode *nd, const char *path)
{
    return per_joint(cv, nd, path, noise_q_joint);
}

static int noise_qd(conv *cv, const ynode *nd, const char *path)
{
    return per_joint(cv, nd, path, noise_qd_joint);
}

static int noise_seed(conv *cv, const ynode *nd, const char *path)
{
    long long v = 0;
    if (get_int(cv, nd, path, 0, 9007199254740991LL, &v) < 0)
        return -1;
    fx(cv)->noise_seed = (uint64_t)v;
    return 0;
}

static const keyrow k_noise_keys[] = {
    {"seed", noise_seed}, /* integer, default 1 */
    {"q", noise_q},       /* std dev per joint, m or rad */
    {"qd", noise_qd},     /* std dev per joint, m/s or rad/s */
    {NULL, NULL},
};

static int key_effect_noise(conv *cv, const ynode *nd, const char *path)
{
    fx(cv)->enabled |= LAG_EFF_NOISE;
    return convert_map(cv, nd, path, k_noise_keys, "key");
}

static const keyrow k_effects[] = {
    {"gravity", key_effect_gravity},
    {"damping", key_effect_damping},
    {"friction", key_effect_friction},
    {"limits", key_effect_limits},
    {"floor", key_effect_floor},
    {"actuator", key_effect_actuator},
    {"disturbance", key_effect_disturbance},
    {"noise", key_effect_noise},
    {NULL, NULL},
};

static int key_effects(conv *cv, const ynode *nd, const char *path)
{
    /* `effects:` with nothing = no effects */
    if (ynode_is_null(nd))
        return 0;
    cv->effects = nd;
    return convert_map(cv, nd, path, k_effects, "effect");
}

/* ---------------------------------------------------------------- the scene */

static const keyrow k_top_keys[] = {
    {"model", key_model},                 /* stick | manipulator | dipc (required) */
    {"parameters", key_parameters},       /* named as in lag_model_info */
    {"initial", key_initial},             /* q, qd */
    {"integrator", key_integrator},       /* method, dt, tolerances */
    {"publish_hz", key_publish_hz},       /* Hz */
    {"explode_limit", key_explode_limit}, /* |q_i|, |qd_i| bound */
    {"realtime", key_realtime},           /* pacing of the real-time server */
    {"lcm", key_lcm},                     /* transport */
    {"effects", key_effects},             /* issue 4 */
    {NULL, NULL},
};

static int convert_scene(const ynode *root, const char *path, lag_scene *sc, errbuf *err)
{
    conv cv = {.err = err, .sc = sc, .root = root, .gravity_enabled = -1};
    if (root->kind != YN_MAP) {
        if (ynode_is_null(root))
            return fail(err, root, NULL,
                        "expected a mapping with the scene's keys (at least 'model'), "
                        "got an empty document");
        return fail(err, root, NULL,
                    "expected a mapping with the scene's keys (at least 'model'), got %s",
                    ynode_kind_name(root));
    }

    /* The model comes first: parameters, the length of q and the defaults depend on it. */
    static const char models[] = "stick, manipulator, dipc";
    const yentry *me = ymap_find(root, "model");
    if (!me)
        return fail(err, root, NULL, "missing required key 'model' (%s)", models);
    const char *mname;
    char what[64];
    snprintf(what, sizeof what, "a model (%s)", models);
    if (get_string(&cv, me->val, "model", what, &mname) < 0)
        return -1;
    int kind = lag_model_kind_from_name(mname);
    if (kind < 0)
        return fail(err, me->val, "model", "unknown model '%s'; allowed: %s", mname, models);

    lag_scene_default(sc, (lag_model_kind)kind);
    snprintf(sc->path, sizeof sc->path, "%s", path ? path : "");
    lag_model_default_unfinished(&sc->sim.model, (lag_model_kind)kind);
    cv.info = lag_model_info_get((lag_model_kind)kind);

    if (convert_map(&cv, root, "", k_top_keys, "key") < 0)
        return -1;

    /* effects.gravity overrides parameters.g (after both are read, whatever their order) */
    if (cv.gravity_g_node) sc->sim.model.p[lag_model_param_index(sc->sim.model.kind, "g")] = cv.gravity_g;
    if (cv.gravity_enabled == 0) sc->sim.model.p[lag_model_param_index(sc->sim.model.kind, "g")] = 0.0;

    /* Parameters: uniform-rod inertias not given -> m l^2 / 12; then the core's check. */
    char msg[256];
    lag_model_finish(&sc->sim.model);
    if (lag_model_validate(&sc->sim.model, msg, sizeof msg) != LAG_OK)
        return fail(err, cv.parameters ? cv.parameters : me->val,
                    cv.parameters ? "parameters" : NULL, "%s", msg);

    /* Output period: an integer number of integrator ticks. */
    double dt = sc->sim.integrator.dt;
    double period = 1.0 / sc->publish_hz;
    double r = period / dt;
    const ynode *at = cv.publish_hz ? cv.publish_hz
                    : cv.dt ? cv.dt
                    : cv.integrator ? cv.integrator : root;
    const char *atpath = cv.publish_hz ? "publish_hz"
                       : cv.dt ? "integrator.dt"
                       : cv.integrator ? "integrator" : NULL;
    if (!(r >= 1.0 - 1e-9) || r > 1e12)
        return fail(err, at, atpath,
                    "1/publish_hz = %.17g s must be an integer multiple (>= 1) of "
                    "integrator.dt = %.17g s", period, dt);
    double ticks = floor(r + 0.5);
    if (fabs(r - ticks) > 1e-9 * r)
        return fail(err, at, atpath,
                    "1/publish_hz = %.17g s must be an integer multiple of integrator.dt = "
                    "%.17g s (it is %.6g dt)", period, dt, r);
    sc->ticks_per_period = (int64_t)ticks;

    /* dopri5's smallest step cannot exceed the tick. */
    if (sc->sim.integrator.dt_min > dt)
        return fail(err, cv.dt_min ? cv.dt_min : at, cv.dt_min ? "integrator.dt_min" : atpath,
                    "expected a number <= integrator.dt = %.17g s, got %.17g",
                    dt, sc->sim.integrator.dt_min);

    /* The initial state must lie inside explode_limit. */
    for (int i = 0; i < sc->sim.model.nq; i++) {
        double lim = sc->sim.explode_limit;
        if (fabs(sc->sim.q0[i]) > lim || fabs(sc->sim.qd0[i]) > lim) {
            const ynode *bad = cv.initial ? cv.initial : cv.explode_limit;
            return fail(err, bad, cv.initial ? "initial" : "explode_limit",
                        "initial state exceeds explode_limit = %g", lim);
        }
    }

    /* The initial state must lie within the stops and above the floor. */
    const lag_effects_def *e = &sc->sim.effects;
    for (int i = 0; i < sc->sim.model.nq; i++) {
        if (!((e->enabled & LAG_EFF_LIMITS) && e->limit_on[i])) continue;
        if (sc->sim.q0[i] < e->limit_lower[i] || sc->sim.q0[i] > e->limit_upper[i])
            return fail(err, cv.initial ? cv.initial : cv.limits_node,
                        cv.initial ? "initial" : "effects.limits",
                        "initial %s = %g is outside its limits [%g, %g]",
                        cv.info->joint_names[i], sc->sim.q0[i], e->limit_lower[i],
                        e->limit_upper[i]);
    }
    if ((e->enabled & LAG_EFF_FLOOR) && (sc->sim.q0[1] < 0 || sc->sim.q0[1] > M_PI))
        return fail(err, cv.initial ? cv.initial : cv.floor_node,
                    cv.initial ? "initial" : "effects.floor",
                    "initial phi = %g must be in [0, pi] with a floor", sc->sim.q0[1]);

    /* lcm.url, with lcm.allow_lan wherever it was given */
    if (lag_scene_check_url(sc->lcm.url, sc->lcm.allow_lan, &sc->lcm.ttl, msg, sizeof msg) < 0)
        return fail(err, cv.url, "lcm.url", "%s", msg);

    /* Final check by the core (integrator settings, initial state). */
    if (lag_sim_def_validate(&sc->sim, msg, sizeof msg) != LAG_OK)
        return fail(err, root, NULL, "invalid scene: %s", msg);
    return 0;
}

/* ================================================================ entry point */

int lag_scene_load(const char *path, const char *const *sets, int nsets, lag_scene *sc,
                   char *err, size_t errlen)
{
    char dummy[8];
    errbuf e = {.buf = err ? err : dummy, .len = err ? errlen : sizeof dummy};
    if (e.len)
        e.buf[0] = '\0';
    if (!path || !sc || nsets < 0 || (nsets > 0 && !sets)) {
        snprintf(e.buf, e.len, "lag_scene_load: invalid arguments");
        return -1;
    }
    memset(sc, 0, sizeof *sc);

    /* Sources live until the tree is freed: the file, then one per --set. */
    ysrc *srcs = calloc((size_t)nsets + 1, sizeof *srcs);
    char **names = calloc((size_t)nsets + 1, sizeof *names);
    ynode *root = NULL;
    int rc = -1;
    if (!srcs || !names) {
        snprintf(e.buf, e.len, "%s: out of memory", path);
        goto done;
    }
    srcs[0].name = path;
    srcs[0].is_set = false;
    if (parse_file(path, &srcs[0], &e, &root) < 0)
        goto done;

    for (int i = 0; i < nsets; i++) {
        const char *s = sets[i];
        const char *eq = s ? strchr(s, '=') : NULL;
        if (!eq) {
            snprintf(e.buf, e.len, "--set %s: expected key.path=value", s ? s : "(null)");
            goto done;
        }
        size_t klen = (size_t)(eq - s);
        names[i + 1] = malloc(klen + 1);
        if (!names[i + 1]) {
            snprintf(e.buf, e.len, "--set: out of memory");
            goto done;
        }
        memcpy(names[i + 1], s, klen);
        names[i + 1][klen] = '\0';
        srcs[i + 1].name = names[i + 1];
        srcs[i + 1].is_set = true;
        if (klen == 0) {
            snprintf(e.buf, e.len, "--set %s: expected key.path=value, the key is empty", s);
            goto done;
        }
        ynode *val;
        if (parse_string(eq + 1, &srcs[i + 1], &e, &val) < 0)
            goto done;
        /* a root that is not a mapping (e.g. an empty file) is reported by convert */
        if (root->kind != YN_MAP && ynode_is_null(root)) {
            ynode *m = ynode_new(YN_MAP, 1, 1, &srcs[0]);
            if (!m) {
                ynode_free(val);
                snprintf(e.buf, e.len, "--set: out of memory");
                goto done;
            }
            ynode_free(root);
            root = m;
        }
        if (graft(root, &srcs[i + 1], val, &e) < 0)
            goto done;
    }

    rc = convert_scene(root, path, sc, &e) < 0 ? -1 : 0;
done:
    ynode_free(root);
    if (names)
        for (int i = 0; i <= nsets; i++)
            free(names[i]);
    free(names);
    free(srcs);
    return rc;
}
