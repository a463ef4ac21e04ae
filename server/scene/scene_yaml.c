/*
 * The YAML tree of a scene: parse (libyaml events -> ynode, within the limits of
 * scene.h), graft (--set overrides) and positions (errors as file:line:column). See
 * scene_yaml.h for what is refused and why.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "scene.h"
#include "scene_yaml.h"

/* ================================================================ the tree */

void ynode_free(ynode *nd)
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

const yentry *ymap_find(const ynode *map, const char *key)
{
    for (int i = 0; i < map->n; i++)
        if (strcmp(map->entries[i].key, key) == 0)
            return &map->entries[i];
    return NULL;
}

const ynode *ytree_lookup(const ynode *root, const char *path)
{
    const ynode *nd = root;
    const char *p = path;
    while (*p) {
        if (*p == '[') { /* [i] */
            char *end;
            long i = strtol(p + 1, &end, 10);
            if (end == p + 1 || *end != ']' || nd->kind != YN_SEQ || i < 0 || i >= nd->n)
                return nd;
            nd = nd->items[i];
            p = end + 1;
        } else { /* key, up to '.', '[' or the end */
            size_t len = strcspn(p, ".[");
            const yentry *en = NULL;
            for (int i = 0; nd->kind == YN_MAP && i < nd->n && !en; i++)
                if (strlen(nd->entries[i].key) == len && strncmp(nd->entries[i].key, p, len) == 0)
                    en = &nd->entries[i];
            if (!en)
                return nd;
            nd = en->val;
            p += len;
        }
        if (*p == '.')
            p++;
    }
    return nd;
}

bool ynode_is_null(const ynode *nd)
{
    if (nd->kind != YN_SCALAR || nd->quoted)
        return false;
    const char *t = nd->text;
    return t[0] == '\0' || strcmp(t, "~") == 0 || strcmp(t, "null") == 0 ||
           strcmp(t, "Null") == 0 || strcmp(t, "NULL") == 0;
}

const char *ynode_kind_name(const ynode *nd)
{
    switch (nd->kind) {
    case YN_MAP: return "a mapping";
    case YN_SEQ: return "a sequence";
    case YN_SCALAR: return ynode_is_null(nd) ? "nothing" : "a scalar";
    }
    return "?";
}

/* ================================================================ errors */

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

int yfail(errbuf *e, const ynode *nd, const char *path, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    verr(e, nd ? nd->src : NULL, nd ? nd->line : 0, nd ? nd->col : 0, path, fmt, ap);
    va_end(ap);
    return -1;
}

int yfail_key(errbuf *e, const yentry *en, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    verr(e, en->src, en->line, en->col, NULL, fmt, ap);
    va_end(ap);
    return -1;
}

/* ================================================================ parse */

typedef struct parser {
    yaml_parser_t yp;
    const char *text;  /* the whole input, for positions of reader errors */
    size_t len;
    const ysrc *src;
    errbuf *err;
    int nodes;         /* built so far, against LAG_SCENE_MAX_NODES */
} parser;

/* 1-based line:column of byte `off`, counted as libyaml counts marks: lines end at \n,
 * \r\n, \r and the Unicode breaks NEL, LS, PS; columns count characters. */
static void offset_position(const char *text, size_t len, size_t off, int *line, int *col)
{
    const unsigned char *s = (const unsigned char *)text;
    if (off > len)
        off = len;
    int l = 1, c = 1;
    for (size_t i = 0; i < off; i++) {
        if (s[i] == '\n' || (s[i] == '\r' && !(i + 1 < len && s[i + 1] == '\n'))) {
            l++;
            c = 1;
        } else if (s[i] == 0xC2 && i + 1 < off && s[i + 1] == 0x85) { /* NEL */
            l++;
            c = 1;
            i++;
        } else if (s[i] == 0xE2 && i + 2 < off && s[i + 1] == 0x80 &&
                   (s[i + 2] == 0xA8 || s[i + 2] == 0xA9)) { /* LS, PS */
            l++;
            c = 1;
            i += 2;
        } else if ((s[i] & 0xC0) != 0x80 && s[i] != '\r') {
            c++; /* a character starts here (continuation bytes do not count) */
        }
    }
    *line = l;
    *col = c;
}

static int syntax_error(parser *p)
{
    const yaml_parser_t *yp = &p->yp;
    const char *problem = yp->problem ? yp->problem : "unknown error";
    errbuf *e = p->err;
    ynode at = {.src = p->src};
    if (yp->error == YAML_MEMORY_ERROR)
        return yfail(e, NULL, NULL, "%s: out of memory while reading YAML", p->src->name);
    if (yp->error == YAML_READER_ERROR) {
        /* the reader reports a byte offset: turned into line:column here */
        offset_position(p->text, p->len, yp->problem_offset, &at.line, &at.col);
        if (yp->problem_value >= 0 && yp->problem_value <= 0xFF &&
            strstr(problem, "UTF-8"))
            return yfail(e, &at, NULL, "YAML error: %s (byte 0x%02X): a scene is UTF-8 text",
                         problem, (unsigned)yp->problem_value);
        if (yp->problem_value >= 0)
            return yfail(e, &at, NULL, "YAML error: %s (character U+%04X)", problem,
                         (unsigned)yp->problem_value);
        return yfail(e, &at, NULL, "YAML error: %s", problem);
    }
    char ctx[256] = "";
    if (yp->context)
        snprintf(ctx, sizeof ctx, " (%s at %zu:%zu)", yp->context,
                 yp->context_mark.line + 1, yp->context_mark.column + 1);
    at.line = (int)yp->problem_mark.line + 1;
    at.col = (int)yp->problem_mark.column + 1;
    return yfail(e, &at, NULL, "YAML syntax error: %s%s", problem, ctx);
}

static int next_event(parser *p, yaml_event_t *ev)
{
    if (!yaml_parser_parse(&p->yp, ev))
        return syntax_error(p);
    return 0;
}

static int mark_line(const yaml_event_t *ev) { return (int)ev->start_mark.line + 1; }
static int mark_col(const yaml_event_t *ev) { return (int)ev->start_mark.column + 1; }

/* Anchors and tags are refused (see scene_yaml.h); the event is deleted on error. */
static int check_plain_node(parser *p, yaml_event_t *ev, const ynode *at)
{
    const yaml_char_t *anchor = NULL, *tag = NULL;
    switch (ev->type) {
    case YAML_SCALAR_EVENT:
        anchor = ev->data.scalar.anchor;
        tag = ev->data.scalar.tag;
        break;
    case YAML_SEQUENCE_START_EVENT:
        anchor = ev->data.sequence_start.anchor;
        tag = ev->data.sequence_start.tag;
        break;
    case YAML_MAPPING_START_EVENT:
        anchor = ev->data.mapping_start.anchor;
        tag = ev->data.mapping_start.tag;
        break;
    default:
        break;
    }
    if (tag) {
        char t[64];
        const char *tg = (const char *)tag;
        if (strncmp(tg, "tag:yaml.org,2002:", 18) == 0) /* as written: !!str */
            snprintf(t, sizeof t, "!!%s", tg + 18);
        else
            snprintf(t, sizeof t, "%s", tg);
        yaml_event_delete(ev);
        return yfail(p->err, at, NULL,
                     "YAML tags (%s) are not supported in scenes: write a number plainly, "
                     "a string plainly or in quotes", t);
    }
    if (anchor) {
        yaml_event_delete(ev);
        return yfail(p->err, at, NULL,
                     "anchors (&name) are not supported in scenes: write each value out");
    }
    return 0;
}

/* Counts one more node against LAG_SCENE_MAX_NODES. */
static int count_node(parser *p, const ynode *at)
{
    if (++p->nodes > LAG_SCENE_MAX_NODES)
        return yfail(p->err, at, NULL,
                     "more than %d YAML nodes (scalars, mappings, sequences): a scene has "
                     "far fewer; this is the limit", LAG_SCENE_MAX_NODES);
    return 0;
}

/* The index of the first entry (in file order) whose key repeats an earlier key of the
 * mapping, with that earlier entry in *first; -1 if none, -2 out of memory.
 * O(n log n): keys sorted, equal keys by index. */
typedef struct keyix {
    const char *key;
    int i;
} keyix;

static int by_key_then_index(const void *a, const void *b)
{
    const keyix *x = a, *y = b;
    int c = strcmp(x->key, y->key);
    return c ? c : (x->i > y->i) - (x->i < y->i);
}

static int find_duplicate(const ynode *map, int *first)
{
    if (map->n < 2)
        return -1;
    keyix *ix = malloc((size_t)map->n * sizeof *ix);
    if (!ix)
        return -2;
    for (int i = 0; i < map->n; i++)
        ix[i] = (keyix){map->entries[i].key, i};
    qsort(ix, (size_t)map->n, sizeof *ix, by_key_then_index);
    int dup = -1, run = 0; /* run: start of the current run of equal keys */
    for (int i = 1; i < map->n; i++) {
        if (strcmp(ix[i].key, ix[run].key) != 0) {
            run = i;
            continue;
        }
        if (i == run + 1 && (dup < 0 || ix[i].i < dup)) { /* the run's second occurrence */
            dup = ix[i].i;
            *first = ix[run].i;
        }
    }
    free(ix);
    return dup;
}

static int parse_node(parser *p, yaml_event_t *ev, int depth, ynode **out);

/* Reads the items of a sequence or the entries of a mapping up to its end event. */
static int parse_children(parser *p, ynode *nd, int depth)
{
    bool is_map = nd->kind == YN_MAP;
    yaml_event_type_t end = is_map ? YAML_MAPPING_END_EVENT : YAML_SEQUENCE_END_EVENT;
    for (;;) {
        yaml_event_t kev;
        if (next_event(p, &kev) < 0)
            return -1;
        if (kev.type == end) {
            yaml_event_delete(&kev);
            break;
        }
        if (nd->n >= LAG_SCENE_MAX_ITEMS) {
            ynode at = {.line = mark_line(&kev), .col = mark_col(&kev), .src = p->src};
            yaml_event_delete(&kev);
            return yfail(p->err, &at, NULL, "more than %d %s in one %s: this is the limit",
                         LAG_SCENE_MAX_ITEMS, is_map ? "keys" : "items",
                         is_map ? "mapping" : "sequence");
        }
        if (!ynode_grow(nd)) {
            yaml_event_delete(&kev);
            return yfail(p->err, nd, NULL, "out of memory");
        }
        if (!is_map) {
            ynode *item;
            if (parse_node(p, &kev, depth + 1, &item) < 0)
                return -1;
            nd->items[nd->n++] = item;
            continue;
        }
        /* mapping: a scalar key, then its value */
        ynode *key;
        if (parse_node(p, &kev, depth + 1, &key) < 0)
            return -1;
        if (key->kind != YN_SCALAR) {
            yfail(p->err, key, NULL, "expected a plain key, got %s", ynode_kind_name(key));
            ynode_free(key);
            return -1;
        }
        yaml_event_t vev;
        ynode *val;
        if (next_event(p, &vev) < 0 || parse_node(p, &vev, depth + 1, &val) < 0) {
            ynode_free(key);
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
    if (is_map) {
        int first = -1, dup = find_duplicate(nd, &first);
        if (dup == -2)
            return yfail(p->err, nd, NULL, "out of memory");
        if (dup >= 0)
            return yfail_key(p->err, &nd->entries[dup], "duplicate key '%s' (first at %d:%d)",
                             nd->entries[dup].key, nd->entries[first].line,
                             nd->entries[first].col);
    }
    return 0;
}

/* Parses the node that starts with event `ev` (consumed) into *out. */
static int parse_node(parser *p, yaml_event_t *ev, int depth, ynode **out)
{
    *out = NULL;
    int line = mark_line(ev), col = mark_col(ev);
    ynode at = {.line = line, .col = col, .src = p->src};
    if (ev->type == YAML_ALIAS_EVENT) {
        yaml_event_delete(ev);
        return yfail(p->err, &at, NULL,
                     "aliases (*name) are not supported in scenes: write the value out");
    }
    if (ev->type != YAML_SCALAR_EVENT && ev->type != YAML_SEQUENCE_START_EVENT &&
        ev->type != YAML_MAPPING_START_EVENT) {
        int type = (int)ev->type;
        yaml_event_delete(ev);
        return yfail(p->err, &at, NULL, "unexpected YAML event %d", type);
    }
    if (check_plain_node(p, ev, &at) < 0)
        return -1;
    if (count_node(p, &at) < 0) {
        yaml_event_delete(ev);
        return -1;
    }
    if (ev->type == YAML_SCALAR_EVENT) {
        size_t len = ev->data.scalar.length;
        if (len > LAG_SCENE_MAX_SCALAR) {
            yaml_event_delete(ev);
            return yfail(p->err, &at, NULL,
                         "a scalar of %zu bytes: at most %d is the limit", len,
                         LAG_SCENE_MAX_SCALAR);
        }
        ynode *nd = ynode_new(YN_SCALAR, line, col, p->src);
        if (nd)
            nd->text = malloc(len + 1);
        if (!nd || !nd->text) {
            yaml_event_delete(ev);
            ynode_free(nd);
            return yfail(p->err, &at, NULL, "out of memory");
        }
        memcpy(nd->text, ev->data.scalar.value, len);
        nd->text[len] = '\0';
        nd->quoted = ev->data.scalar.style != YAML_PLAIN_SCALAR_STYLE &&
                     ev->data.scalar.style != YAML_ANY_SCALAR_STYLE;
        yaml_event_delete(ev);
        /* a NUL inside a quoted scalar ("\0") would cut the text short unseen */
        if (memchr(nd->text, '\0', len)) {
            ynode_free(nd);
            return yfail(p->err, &at, NULL, "a scalar with a NUL character");
        }
        *out = nd;
        return 0;
    }
    bool is_map = ev->type == YAML_MAPPING_START_EVENT;
    yaml_event_delete(ev);
    if (depth >= LAG_SCENE_MAX_DEPTH)
        return yfail(p->err, &at, NULL, "nesting deeper than %d levels: this is the limit",
                     LAG_SCENE_MAX_DEPTH);
    ynode *nd = ynode_new(is_map ? YN_MAP : YN_SEQ, line, col, p->src);
    if (!nd)
        return yfail(p->err, &at, NULL, "out of memory");
    if (parse_children(p, nd, depth) < 0) {
        ynode_free(nd);
        return -1;
    }
    *out = nd;
    return 0;
}

/* Parses one YAML document from an initialized parser. */
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
            return yfail(p->err, NULL, NULL, "out of memory");
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
        ynode at = {.line = mark_line(&ev), .col = mark_col(&ev), .src = p->src};
        yaml_event_delete(&ev);
        ynode_free(root);
        return yfail(p->err, &at, NULL, "a scene is one YAML document; found a second one");
    }
    yaml_event_delete(&ev);
    *out = root;
    return 0;
}

int ytree_parse(const char *text, size_t len, const ysrc *src, errbuf *e, ynode **out)
{
    *out = NULL;
    ynode at = {.line = 1, .col = 1, .src = src};
    if (len > LAG_SCENE_MAX_BYTES) {
        if (src->is_set)
            return yfail(e, &at, NULL, "a value of %zu bytes: at most %d is the limit", len,
                         LAG_SCENE_MAX_BYTES);
        return yfail(e, NULL, NULL, "%s: %zu bytes: a scene file has at most %d (the limit)",
                     src->name, len, LAG_SCENE_MAX_BYTES);
    }
    /* Scenes are UTF-8; libyaml would also take UTF-16 after a byte order mark, and then
     * its byte offsets would no longer be ours. */
    if (len >= 2 && (((unsigned char)text[0] == 0xFF && (unsigned char)text[1] == 0xFE) ||
                     ((unsigned char)text[0] == 0xFE && (unsigned char)text[1] == 0xFF)))
        return yfail(e, &at, NULL, "a UTF-16 byte order mark: a scene is UTF-8 text");
    parser p = {.text = text, .len = len, .src = src, .err = e};
    if (!yaml_parser_initialize(&p.yp))
        return yfail(e, &at, NULL, "cannot initialize the YAML parser");
    yaml_parser_set_encoding(&p.yp, YAML_UTF8_ENCODING);
    yaml_parser_set_input_string(&p.yp, (const unsigned char *)text, len);
    int rc = parse_document(&p, out);
    yaml_parser_delete(&p.yp);
    return rc;
}

/* ================================================================ graft --set */

/* The mapping a --set walks into at `pathsofar`: nothing (`effects:`, `effects=null`) is
 * an empty mapping, as the schema reads it: a key set inside it starts one, so that a null
 * set earlier never makes later sets below it fail. Anything else but a mapping is an
 * error at `at`. */
static int graft_into(ynode *map, const ynode *at, const char *pathsofar, errbuf *err)
{
    if (map->kind == YN_SCALAR && ynode_is_null(map)) {
        free(map->text);
        map->text = NULL;
        map->quoted = false;
        map->kind = YN_MAP;
    }
    if (map->kind == YN_MAP)
        return 0;
    if (map->src->is_set)
        return yfail(err, at, NULL,
                     "cannot set a key inside '%s': it was set to %s by %s=..., not a "
                     "mapping (set '%s' to a mapping, e.g. %s={}, first)",
                     pathsofar, ynode_kind_name(map), map->src->name, pathsofar, pathsofar);
    return yfail(err, at, NULL,
                 "cannot set a key inside '%s', which is %s at %s:%d:%d, not a mapping",
                 pathsofar, ynode_kind_name(map), map->src->name, map->line, map->col);
}

/* map's entry `key` (of len bytes), added (empty, from src) if the mapping has none;
 * NULL with the error at `at`. */
static yentry *graft_entry(ynode *map, const char *key, size_t len, const ysrc *src,
                           const ynode *at, errbuf *err)
{
    yentry *en = (yentry *)ymap_find(map, key);
    if (en)
        return en;
    if (map->n >= LAG_SCENE_MAX_ITEMS || !ynode_grow(map)) {
        yfail(err, at, NULL, map->n >= LAG_SCENE_MAX_ITEMS
              ? "the mapping has the most keys a mapping may have" : "out of memory");
        return NULL;
    }
    en = &map->entries[map->n];
    en->key = malloc(len + 1);
    if (!en->key) {
        yfail(err, at, NULL, "out of memory");
        return NULL;
    }
    memcpy(en->key, key, len + 1);
    en->line = en->col = 1;
    en->src = src;
    en->val = NULL;
    map->n++;
    return en;
}

int ytree_graft(ynode *root, const ysrc *src, ynode *val, errbuf *err)
{
    ynode at = {.src = src};
    ynode *map = root;
    const char *seg = src->name;
    char pathsofar[512] = "";
    if (strlen(src->name) > 255) {
        ynode_free(val);
        return yfail(err, &at, NULL, "key path longer than 255 characters");
    }
    for (;;) {
        const char *dot = strchr(seg, '.');
        size_t len = dot ? (size_t)(dot - seg) : strlen(seg);
        if (len == 0) {
            ynode_free(val);
            return yfail(err, &at, NULL,
                         "empty key in the dotted path (expected e.g. integrator.dt=0.001)");
        }
        char key[256];
        memcpy(key, seg, len);
        key[len] = '\0';
        yentry *en = NULL;
        if (graft_into(map, &at, pathsofar, err) < 0 ||
            !(en = graft_entry(map, key, len, src, &at, err))) {
            ynode_free(val);
            return -1;
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
                return yfail(err, &at, NULL, "out of memory");
            }
        }
        snprintf(pathsofar + strlen(pathsofar), sizeof pathsofar - strlen(pathsofar), "%s%s",
                 pathsofar[0] ? "." : "", key);
        map = en->val;
        seg = dot + 1;
    }
}
