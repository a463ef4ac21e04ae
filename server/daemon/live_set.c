/*
 * Changes made while running (control_t SET): validated by the scene loader on the
 * scene's own bytes; see live_set.h.
 */
#include "live_set.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int live_set_parse(const char *key, const char *value, char *kv, char *why, size_t whylen)
{
    size_t root = !strncmp(key, "parameters", 10) ? 10 : !strncmp(key, "effects", 7) ? 7 : 0;
    if (root == 0 || (key[root] != '\0' && key[root] != '.') || strchr(key, '=')) {
        snprintf(why, whylen, "set: only keys under parameters and effects change while "
                              "running (e.g. parameters.m2, effects.friction.q2.kinetic)");
        return -1;
    }
    if (!value[0] || snprintf(kv, LIVE_SET_LEN, "%s=%s", key, value) >= LIVE_SET_LEN) {
        snprintf(why, whylen, "set: the value is empty, or key=value is longer than %d bytes",
                 LIVE_SET_LEN - 1);
        return -1;
    }
    return 0;
}

/* Does s start with "name:L:C" (L, C decimal)? Returns its length, else 0. */
static size_t location_at(const char *s, const char *name)
{
    size_t n = strlen(name);
    if (n == 0 || strncmp(s, name, n) != 0) return 0;
    for (int part = 0; part < 2; part++) {
        if (s[n] != ':' || s[n + 1] < '0' || s[n + 1] > '9') return 0;
        n++;
        while (s[n] >= '0' && s[n] <= '9') n++;
    }
    return n;
}

/* The loader's message for the bus: the change's own "--set key: " goes (the answer names
 * the change already); a leading "file:line:column: " (a rule that a setting of the file
 * breaks with the change, e.g. the initial state outside a new stop) becomes words, and
 * so does any other mention of a place in the file. */
static void shape(const char *msg, const char *name, const char *kv, char *out, size_t outlen)
{
    char own[LIVE_SET_LEN + 8];
    size_t klen = strcspn(kv, "=");
    snprintf(own, sizeof own, "--set %.*s: ", (int)klen, kv);
    size_t o = 0;
    const char *p = msg;
    if (!strncmp(p, own, strlen(own))) {
        p += strlen(own);
    } else {
        size_t loc = location_at(p, name);
        if (loc && p[loc] == ':' && p[loc + 1] == ' ') {
            o += (size_t)snprintf(out, outlen, "with the rest of the scene: ");
            p += loc + 2;
        }
    }
    while (*p && o + 1 < outlen) {
        size_t loc = location_at(p, name);
        if (loc) {
            int w = snprintf(out + o, outlen - o, "the scene file");
            o += w < 0 ? 0 : (size_t)w;
            if (o >= outlen) o = outlen - 1;
            p += loc;
        } else {
            out[o++] = *p++;
        }
    }
    if (outlen) out[o < outlen ? o : outlen - 1] = '\0';
}

/* Is entry e overridden by a change of the key that kv sets (the same key, or one below)? */
static bool overrides(const char *kv, const char *e)
{
    size_t klen = strcspn(kv, "=");
    return !strncmp(e, kv, klen) && (e[klen] == '=' || e[klen] == '.');
}

int live_set_load(const lagsimd_opts *o, const live_sets *ls, const char *kv, lag_scene *out,
                  char *why, size_t whylen)
{
    if (!o || !o->scene_text) {
        snprintf(why, whylen, "set: no scene source to validate a change against");
        return -1;
    }
    bool room = ls->n < LIVE_SET_MAX;
    for (int i = 0; !room && i < ls->n; i++) room = overrides(kv, ls->kv[i]);
    if (!room) {
        snprintf(why, whylen, "set %s: %d distinct keys have been changed while running, the "
                              "most: set a whole group instead (e.g. effects.friction)",
                 kv, LIVE_SET_MAX);
        return -1;
    }
    /* the scene's --set overrides, the changes so far, this one */
    int nbase = o->nsets, n = nbase + ls->n + 1;
    const char **all = malloc(sizeof *all * (size_t)n);
    if (!all) {
        snprintf(why, whylen, "set: out of memory");
        return -1;
    }
    for (int i = 0; i < nbase; i++) all[i] = o->sets[i];
    for (int i = 0; i < ls->n; i++) all[nbase + i] = ls->kv[i];
    all[n - 1] = kv;
    char err[512];
    int rc = lag_scene_load_buffer(o->scene_name, o->scene_text, o->scene_len, all, n, out, err,
                                   sizeof err);
    free(all);
    if (rc != 0) {
        char msg[512];
        shape(err, o->scene_name ? o->scene_name : "", kv, msg, sizeof msg);
        snprintf(why, whylen, "set %s: %s", kv, msg);
        return -1;
    }
    return 0;
}

void live_set_keep(live_sets *ls, const char *kv)
{
    int k = 0;
    for (int i = 0; i < ls->n; i++) {
        if (overrides(kv, ls->kv[i])) continue;
        if (k != i) memcpy(ls->kv[k], ls->kv[i], sizeof ls->kv[k]);
        k++;
    }
    ls->n = k;
    if (ls->n < LIVE_SET_MAX) /* live_set_load made room sure */
        snprintf(ls->kv[ls->n++], sizeof ls->kv[0], "%s", kv);
}
