/*
 * The daemon's LCM instances (lagsim_bus.h gives the URLs):
 *   s->lcm        the state URL, publishing only: it never subscribes, so LCM never
 *                 opens a receive socket for it and the daemon never reads back its own
 *                 states (in fast mode, tens of thousands a second);
 *   s->lcm_in     the command URL: _COMMAND and _CONTROL. Its receive socket gets a
 *                 filter (lagsim_net.h): only this plant's two channels, and unless
 *                 lcm.allow_lan only datagrams sent from this host;
 * For memq:// (tests, one process) one lcm_t is both.
 *
 * One plant per prefix: the state URL's lcm_t subscribes to _SCENE (its receive socket
 * filtered to that channel and _COMMAND, so the kernel drops the daemon's own states
 * instead of handing them back; a command sent there, to the wrong port, is counted). Before it publishes anything, the daemon asks its prefix for a
 * scene (DESCRIBE) and listens RT_LOOK_MS (look_for_other_plant); another plant's scene
 * (rt_handle_scene: one that decodes, names this prefix and is not one of the daemon's
 * own) makes it refuse to start, and later makes it stop. Whom it hears follows the
 * command URL's rule: this host only unless lcm.allow_lan.
 */
#include <stdio.h>
#include <string.h>

#include "lagsim_net.h"
#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"

/* Filters the receive socket of the command URL's lcm_t, then reads until a marker sent
 * after the filter comes back, discarding whatever came before it (it may have come in
 * before the filter did). Returns 0, or an exit code with a message in err. */
static int filter_input(rt_server *s, char *err, size_t errlen)
{
    const lag_bus *b = &s->bus;
    bool host_only = !s->sc->lcm.allow_lan;
    const char *with_marker[] = {s->ch_command, s->ch_control, LAG_NET_MARKER_CHANNEL};
    char ferr[256];
    int n = lag_net_filter(b->command_port, host_only, with_marker, 3, ferr, sizeof ferr);
    if (n <= 0) {
        snprintf(err, errlen, "%s%s: cannot restrict the command URL %s to %s", n < 0 ? ferr :
                 "LCM's receive socket for the command port was not found",
                 host_only ? "" : " (lcm.allow_lan: true)", b->command_url,
                 host_only ? "this host (lcm.allow_lan: false)" : "this plant's channels");
        return LAGSIMD_EXIT_RUNTIME;
    }
    if (lag_net_sync(s->lcm_in, 3000) != 0) {
        snprintf(err, errlen, "LCM on %s does not hear its own messages (is there a multicast "
                 "route? docs/network.md)", b->command_url);
        return LAGSIMD_EXIT_RUNTIME;
    }
    n = lag_net_filter(b->command_port, host_only, with_marker, 2, ferr, sizeof ferr);
    if (n <= 0) {
        snprintf(err, errlen, "%s", n < 0 ? ferr : "LCM's receive socket went away");
        return LAGSIMD_EXIT_RUNTIME;
    }
    return LAGSIMD_EXIT_OK;
}

#define RT_LOOK_MS 200 /* how long a starting daemon listens for another plant */

/* Before the daemon publishes anything: filters the state URL's receive socket to _SCENE
 * (the plant watch), asks the prefix for its scene (DESCRIBE on the command URL; a daemon
 * there answers on the state URL) and listens RT_LOOK_MS for another plant's. Returns 0,
 * or an exit code with a message. */
static int look_for_other_plant(rt_server *s, char *err, size_t errlen)
{
    const lag_bus *b = &s->bus;
    bool host_only = !s->sc->lcm.allow_lan;
    /* and _COMMAND: a command sent to the state port is counted (rt_wait.c says so) */
    const char *out[] = {s->ch_scene, s->ch_command};
    char ferr[256];
    int n = lag_net_filter(b->state_port, host_only, out, 2, ferr, sizeof ferr);
    if (n <= 0) {
        snprintf(err, errlen, "%s: cannot filter the state URL %s for the plant watch",
                 n < 0 ? ferr : "LCM's receive socket for the state port was not found",
                 b->state_url);
        return LAGSIMD_EXIT_RUNTIME;
    }
    lag_wire_control c;
    memset(&c, 0, sizeof c);
    c.utime = rt_wall_us();
    c.request = LAGSIM_CONTROL_T_DESCRIBE;
    int len = lag_wire_encode(LAG_WIRE_CONTROL, &c, s->buf, RT_BUF_SIZE);
    if (len > 0) lcm_publish(s->lcm_in, s->ch_control, s->buf, (unsigned)len);
    int64_t end = rt_mono_ns() + RT_LOOK_MS * 1000000LL;
    for (int64_t left; !s->other_plant[0] && (left = end - rt_mono_ns()) > 0;)
        lcm_handle_timeout(s->lcm, (int)(left / 1000000) + 1);
    if (s->other_plant[0]) {
        snprintf(err, errlen, "another plant publishes on prefix %s (%s): refusing to start; "
                 "one plant per prefix (give this one another lcm.prefix, or stop the other)",
                 s->sc->lcm.prefix, s->other_plant);
        return LAGSIMD_EXIT_RUNTIME;
    }
    return LAGSIMD_EXIT_OK;
}

int rt_bus_open(rt_server *s, char *err, size_t errlen)
{
    const lag_bus *b = &s->bus;
    lag_net_note_inherited(); /* a parent's sockets are not filtered */
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
    rc = look_for_other_plant(s, err, errlen);
    if (rc == LAGSIMD_EXIT_OK) rc = filter_input(s, err, errlen);
    if (rc != LAGSIMD_EXIT_OK) {
        rt_bus_close(s);
        return rc;
    }
    /* where the daemon listens, and who can reach it */
    char ifname[64];
    if (lag_net_group_iface(b->group, ifname, sizeof ifname) != 0)
        snprintf(ifname, sizeof ifname, "no interface (no route to %s)", b->group);
    int ttl = s->sc->lcm.ttl; /* the loader's reading of the URL (LCM_DEFAULT_URL included) */
    if (ttl > 0)
        fprintf(stderr, "lagsimd: warning: LCM url '%s' has ttl=%d: states, status and events "
                "leave this host (multicast to the local network%s)\n", b->state_url, ttl,
                ttl > 1 ? " and beyond routers" : "");
    if (s->sc->lcm.allow_lan)
        fprintf(stderr, "lagsimd: %s: listening on %s for commands and control from the "
                "network (lcm.allow_lan: true: any host that reaches %s can command this "
                "plant) on %s; states on %s\n", s->sc->lcm.prefix, ifname, ifname,
                b->command_url, b->state_url);
    else
        fprintf(stderr, "lagsimd: %s: listening on %s for commands and control from this "
                "host only (lcm.allow_lan: false) on %s; states on %s%s\n", s->sc->lcm.prefix,
                ifname, b->command_url, b->state_url,
                ttl == 0 ? ", which stay on this host (ttl=0)" : "");
    return LAGSIMD_EXIT_OK;
}

void rt_bus_close(rt_server *s)
{
    rt_close(s);
    if (s->lcm_in && s->lcm_in != s->lcm) lcm_destroy(s->lcm_in);
    if (s->lcm) lcm_destroy(s->lcm);
    s->lcm = s->lcm_in = NULL;
}
