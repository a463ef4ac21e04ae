/*
 * The daemon's LCM instances (lagsim_bus.h gives the URLs):
 *   s->lcm        the state URL, publishing only: it never subscribes, so LCM never
 *                 opens a receive socket for it and the daemon never reads back its own
 *                 states (in fast mode, tens of thousands a second);
 *   s->lcm_in     the command URL: _COMMAND and _CONTROL;
 * For memq:// (tests, one process) one lcm_t is both.
 */
#include <stdio.h>
#include <string.h>

#include "rt_server.h"

int rt_bus_open(rt_server *s, char *err, size_t errlen)
{
    const lag_bus *b = &s->bus;
    lcm_t *out = lcm_create(b->state_url);
    lcm_t *in = !b->udpm ? out : out ? lcm_create(b->command_url) : NULL;
    if (!out || !in) {
        snprintf(err, errlen, "cannot create LCM on %s", out ? b->command_url : b->state_url);
        if (out) lcm_destroy(out);
        return LAGSIMD_EXIT_RUNTIME;
    }
    s->discard = true; /* until rt_begin: nothing that arrives before the start counts */
    int rc = rt_attach(s, out, in, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) {
        if (in != out) lcm_destroy(in);
        lcm_destroy(out);
        s->lcm = s->lcm_in = NULL;
        return rc;
    }
    if (!b->udpm) {
        fprintf(stderr, "lagsimd: %s: on %s (this process only)\n", s->sc->lcm.prefix,
                b->state_url);
        return LAGSIMD_EXIT_OK;
    }
    int ttl = s->sc->lcm.ttl; /* the loader's reading of the URL (LCM_DEFAULT_URL included) */
    if (ttl > 0)
        fprintf(stderr, "lagsimd: warning: LCM url '%s' has ttl=%d: states, status and events "
                "leave this host (multicast to the local network%s)\n", b->state_url, ttl,
                ttl > 1 ? " and beyond routers" : "");
    fprintf(stderr, "lagsimd: %s: states on %s, commands and control on %s\n",
            s->sc->lcm.prefix, b->state_url, b->command_url);
    return LAGSIMD_EXIT_OK;
}

void rt_bus_close(rt_server *s)
{
    rt_close(s);
    if (s->lcm_in && s->lcm_in != s->lcm) lcm_destroy(s->lcm_in);
    if (s->lcm) lcm_destroy(s->lcm);
    s->lcm = s->lcm_in = NULL;
}
