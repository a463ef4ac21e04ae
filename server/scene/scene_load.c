/*
 * lag_scene_load: read the scene file (at most LAG_SCENE_MAX_BYTES), parse it and each
 * --set into YAML trees (scene_yaml.c), graft the --sets onto the file's tree in order,
 * and read the result through the schema (scene_schema.c), once.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scene.h"
#include "scene_schema.h"
#include "scene_yaml.h"

/* Reads at most LAG_SCENE_MAX_BYTES of `path` into a new buffer (plain files, pipes and
 * character devices alike: the bound is on what is read, not on what stat says). */
static int read_scene_file(const char *path, char **out, size_t *outlen, errbuf *e)
{
    *out = NULL;
    *outlen = 0;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return yfail(e, NULL, NULL, "%s: cannot open scene file: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) == 0 && S_ISDIR(st.st_mode)) {
        close(fd);
        return yfail(e, NULL, NULL, "%s: is a directory, not a scene file", path);
    }
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    for (;;) {
        if (!buf) {
            close(fd);
            return yfail(e, NULL, NULL, "%s: out of memory", path);
        }
        if (len == cap) {
            if (cap > LAG_SCENE_MAX_BYTES) {
                free(buf);
                close(fd);
                return yfail(e, NULL, NULL, "%s: larger than %d bytes, the limit for a scene "
                             "file", path, LAG_SCENE_MAX_BYTES);
            }
            size_t ncap = cap * 2 > (size_t)LAG_SCENE_MAX_BYTES + 1
                              ? (size_t)LAG_SCENE_MAX_BYTES + 1 : cap * 2;
            char *bigger = realloc(buf, ncap);
            if (!bigger) free(buf);
            buf = bigger;
            cap = ncap;
            continue;
        }
        ssize_t n = read(fd, buf + len, cap - len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            int en = errno;
            free(buf);
            close(fd);
            return yfail(e, NULL, NULL, "%s: cannot read scene file: %s", path, strerror(en));
        }
        if (n == 0)
            break;
        len += (size_t)n;
    }
    close(fd);
    *out = buf;
    *outlen = len;
    return 0;
}

/* Messages quote what the user wrote (a key, a value, a --set): control characters in it
 * are written as escapes (\n, \t, \r, \xHH), so that a message is always one line. */
static void one_line(char *buf, size_t len)
{
    if (!buf || len == 0)
        return;
    char out[2048];
    size_t o = 0;
    for (const unsigned char *p = (const unsigned char *)buf; *p && o + 5 < sizeof out; p++) {
        if (*p >= 0x20 && *p != 0x7F) {
            out[o++] = (char)*p;
        } else if (*p == '\n' || *p == '\t' || *p == '\r') {
            out[o++] = '\\';
            out[o++] = *p == '\n' ? 'n' : *p == '\t' ? 't' : 'r';
        } else {
            o += (size_t)snprintf(out + o, sizeof out - o, "\\x%02X", *p);
        }
    }
    out[o] = '\0';
    snprintf(buf, len, "%s", out);
}

static lag_result load_buffer(const char *name, const char *text, size_t len,
                              const char *const *sets, int nsets, lag_scene *sc, char *err,
                              size_t errlen);

lag_result lag_scene_load_buffer(const char *name, const char *text, size_t len,
                                 const char *const *sets, int nsets, lag_scene *sc, char *err,
                                 size_t errlen)
{
    lag_result rc = load_buffer(name, text, len, sets, nsets, sc, err, errlen);
    if (rc != 0)
        one_line(err, errlen);
    return rc;
}

/* A load in progress: the sources (the file, then one per --set) live until the tree
 * is freed. */
typedef struct load_state {
    errbuf e;
    ysrc *srcs;    /* [0] the file, [1 + i] --set i */
    char **names;  /* the --set sources' names (their key paths), owned */
    int nsets;
    ynode *root;   /* the merged tree */
} load_state;

/* One --set "key.path=value": its value parsed as YAML and grafted onto the tree at its
 * key path. */
static int load_set(load_state *ls, int i, const char *s)
{
    errbuf *e = &ls->e;
    const char *eq = s ? strchr(s, '=') : NULL;
    if (!eq) {
        snprintf(e->buf, e->len, "--set %.200s: expected key.path=value", s ? s : "(null)");
        return -1;
    }
    size_t klen = (size_t)(eq - s);
    if (klen == 0) {
        snprintf(e->buf, e->len, "--set %.200s: expected key.path=value, the key is empty", s);
        return -1;
    }
    if (klen > 255) {
        snprintf(e->buf, e->len, "--set %.40s...: a key path of %zu characters: at most 255", s,
                 klen);
        return -1;
    }
    char *key = ls->names[i + 1] = malloc(klen + 1);
    if (!key) {
        snprintf(e->buf, e->len, "--set: out of memory");
        return -1;
    }
    memcpy(key, s, klen);
    key[klen] = '\0';
    ysrc *src = &ls->srcs[i + 1];
    src->name = key;
    src->is_set = true;
    ynode *val;
    if (ytree_parse(eq + 1, strlen(eq + 1), src, e, &val) < 0)
        return -1;
    /* a root that is not a mapping (e.g. an empty file) is reported by the schema */
    if (ls->root->kind != YN_MAP && ynode_is_null(ls->root)) {
        ynode *m = calloc(1, sizeof *m);
        if (!m) {
            ynode_free(val);
            snprintf(e->buf, e->len, "--set: out of memory");
            return -1;
        }
        m->kind = YN_MAP;
        m->line = m->col = 1;
        m->src = &ls->srcs[0];
        ynode_free(ls->root);
        ls->root = m;
    }
    return ytree_graft(ls->root, src, val, e);
}

/* The file's tree, each --set grafted on in order, then the schema. */
static int load_tree(load_state *ls, const char *name, const char *text, size_t len,
                     const char *const *sets, lag_scene *sc)
{
    ls->srcs = calloc((size_t)ls->nsets + 1, sizeof *ls->srcs);
    ls->names = calloc((size_t)ls->nsets + 1, sizeof *ls->names);
    if (!ls->srcs || !ls->names) {
        snprintf(ls->e.buf, ls->e.len, "%s: out of memory", name);
        return -1;
    }
    ls->srcs[0].name = name;
    ls->srcs[0].is_set = false;
    if (ytree_parse(text ? text : "", len, &ls->srcs[0], &ls->e, &ls->root) < 0)
        return -1;
    for (int i = 0; i < ls->nsets; i++)
        if (load_set(ls, i, sets[i]) < 0)
            return -1;
    return scene_schema_convert(ls->root, name, sc, &ls->e) < 0 ? -1 : 0;
}

static lag_result load_buffer(const char *name, const char *text, size_t len,
                              const char *const *sets, int nsets, lag_scene *sc, char *err,
                              size_t errlen)
{
    char dummy[8];
    load_state ls = {.e = {.buf = err ? err : dummy, .len = err ? errlen : sizeof dummy},
                     .nsets = nsets};
    if (ls.e.len)
        ls.e.buf[0] = '\0';
    if (!name || (!text && len) || !sc || nsets < 0 || (nsets > 0 && !sets)) {
        snprintf(ls.e.buf, ls.e.len, "lag_scene_load: invalid arguments");
        return LAG_ERR_ARG;
    }
    memset(sc, 0, sizeof *sc);
    lag_result rc = load_tree(&ls, name, text, len, sets, sc) < 0 ? LAG_ERR_SCENE : LAG_OK;
    ynode_free(ls.root);
    if (ls.names)
        for (int i = 0; i <= nsets; i++)
            free(ls.names[i]);
    free(ls.names);
    free(ls.srcs);
    return rc;
}

lag_result lag_scene_read(const char *path, char **text, size_t *len, char *err, size_t errlen)
{
    char dummy[8];
    errbuf e = {.buf = err ? err : dummy, .len = err ? errlen : sizeof dummy};
    if (e.len)
        e.buf[0] = '\0';
    if (!path || !text || !len) {
        snprintf(e.buf, e.len, "lag_scene_read: invalid arguments");
        return LAG_ERR_ARG;
    }
    if (read_scene_file(path, text, len, &e) < 0) {
        one_line(err, errlen);
        return LAG_ERR_SCENE;
    }
    return LAG_OK;
}

lag_result lag_scene_load(const char *path, const char *const *sets, int nsets, lag_scene *sc,
                          char *err, size_t errlen)
{
    char dummy[8];
    errbuf e = {.buf = err ? err : dummy, .len = err ? errlen : sizeof dummy};
    if (e.len)
        e.buf[0] = '\0';
    if (!path || !sc) {
        snprintf(e.buf, e.len, "lag_scene_load: invalid arguments");
        return LAG_ERR_ARG;
    }
    memset(sc, 0, sizeof *sc);
    char *text;
    size_t len;
    if (read_scene_file(path, &text, &len, &e) < 0) {
        one_line(err, errlen);
        return LAG_ERR_SCENE;
    }
    lag_result rc = lag_scene_load_buffer(path, text, len, sets, nsets, sc, err, errlen);
    free(text);
    return rc;
}
