/*
 * The YAML tree of a scene (private to the scene loader): libyaml events -> small nodes
 * that keep their 1-based line:column and where they came from (the file or a --set),
 * the graft of --set overrides, and the error helpers that print those positions.
 * Nothing here knows a scene key; the schema (scene_schema.c) does.
 *
 * The subset of YAML a scene may use: one document of mappings, sequences and scalars.
 * Refused while parsing, each with its position: aliases, anchors and tags (a scene has no
 * use for them, and honouring some while ignoring others reads values differently from
 * what they say), duplicate keys, keys that are not scalars, and anything beyond the
 * limits in scene.h (bytes, nodes, items, nesting, scalar length), which bound the time
 * and memory a hostile file can take.
 */
#ifndef LAGSIM_SCENE_YAML_H
#define LAGSIM_SCENE_YAML_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>

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

void ynode_free(ynode *nd);
/* The entry with this key, or NULL. */
const yentry *ymap_find(const ynode *map, const char *key);
/* A "null" scalar: empty plain scalar (`dt:` with nothing), `~` or `null`. */
bool ynode_is_null(const ynode *nd);
/* "a mapping", "a sequence", "a scalar", "nothing" */
const char *ynode_kind_name(const ynode *nd);

/* The node at `path` ("effects.limits.q2.lower", "initial.q[1]": keys joined by '.',
 * sequence items as [i]), or the deepest node on the way to it when the tree does not
 * hold all of it (root if none). */
const ynode *ytree_lookup(const ynode *root, const char *path);

/* ---------------------------------------------------------------- errors */

/* The caller's message buffer. */
typedef struct errbuf {
    char *buf;
    size_t len;
} errbuf;

/* Writes "file:line:column: [path: ]message" for a node of the file, "--set key: [path:
 * ]message" for a node of a --set (path left out when it is the --set's own). Returns -1
 * so that callers can `return yfail(...)`. nd may be NULL: the message alone. */
int yfail(errbuf *e, const ynode *nd, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* The same at a mapping key's position. */
int yfail_key(errbuf *e, const yentry *en, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* ---------------------------------------------------------------- parse, graft */

/* Parses one YAML document of `len` bytes (at most LAG_SCENE_MAX_BYTES; NUL bytes are
 * refused like any control character) into *out. An empty document gives a null scalar
 * at 1:1. On error returns -1 with "origin:line:column: what" in e. OUT: out */
int ytree_parse(const char *text, size_t len, const ysrc *src, errbuf *e, ynode **out);

/* Replaces or adds the node at dotted path src->name in the mapping root by val (taken
 * over, freed on error); intermediate mappings that do not exist are created. */
int ytree_graft(ynode *root, const ysrc *src, ynode *val, errbuf *e);

#endif
