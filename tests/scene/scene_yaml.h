/*
 * Flow YAML for one scene key, for the scene tests (test_ranges.c, test_checks.c):
 * yaml_for(out, len, "effects.disturbance[0].t", "V", nq) writes
 * "effects: {disturbance: [{t: V}]}"; a trailing "name[i]" is a vector of nq numbers with
 * V at i, 0 elsewhere ("initial.q[1]" -> "initial: {q: [0, V, 0]}" for nq = 3).
 */
#ifndef LAGSIM_TEST_SCENE_YAML_H
#define LAGSIM_TEST_SCENE_YAML_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static inline void yaml_for(char *out, size_t len, const char *path, const char *value, int nq)
{
    const char *dot = strchr(path, '.');
    size_t seg = dot ? (size_t)(dot - path) : strlen(path);
    const char *br = memchr(path, '[', seg);
    size_t name = br ? (size_t)(br - path) : seg;
    char inner[512];
    if (!dot && br) { /* a vector element */
        int at = atoi(br + 1);
        size_t u = (size_t)snprintf(inner, sizeof inner, "[");
        for (int i = 0; i < nq; i++)
            u += (size_t)snprintf(inner + u, sizeof inner - u, "%s%s", i ? ", " : "",
                                  i == at ? value : "0");
        snprintf(inner + u, sizeof inner - u, "]");
    } else if (dot) {
        char rest[512];
        yaml_for(rest, sizeof rest, dot + 1, value, nq);
        if (snprintf(inner, sizeof inner, br ? "[{%s}]" : "{%s}", rest) < 0) inner[0] = '\0';
    } else {
        snprintf(inner, sizeof inner, "%s", value);
    }
    /* cut short when it does not fit (a test's key, far below the size): said by the
     * result, which gcc's format-truncation wants looked at */
    if (snprintf(out, len, "%.*s: %s", (int)name, path, inner) < 0 && len) out[0] = '\0';
}

#endif
