/*
 * Where a plant named by its prefix runs when no URL was given: a host of plants
 * (lagsimd --plants) keeps a directory on LCM's default bus, where each of its plants says
 * every 0.5 s on which URL it runs (a `plant` event, lag_client_discover follows it too); the
 * plant takes its commands there, not on the directory. The programs that take --prefix
 * without --url (lagsimctl, the C controllers, lagsim-view) ask here first.
 *
 * It only listens (to <PREFIX>_EVENT, _STATE, _STATUS and _SCENE on the default bus, at
 * most LAG_LOCATE_WAIT_S): a plant of that bus itself is asked nothing (a lockstep plant
 * asked for its scene publishes its state again). Header only: the client library's ABI
 * is not changed by it.
 */
#ifndef LAGSIM_LOCATE_H
#define LAGSIM_LOCATE_H

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/lcm.h>

#include "lagsim_bus.h"
#include "lagsim_client.h"
#include "lagsim_wire.h"

#define LAG_LOCATE_WAIT_S 1.0 /* a host's directory names each plant every 0.5 s */

/* Whether `url` is another bus than LCM's default (LCM_DEFAULT_URL's). */
static inline bool lag_locate_elsewhere(const char *url)
{
    lag_bus b;
    char err[64];
    return url && url[0] && lag_bus_init(&b, NULL, "X", err, sizeof err) == 0 &&
           strcmp(b.state_url, url) != 0;
}

/* What lag_locate_plant heard. */
typedef struct lag_locate {
    const char *prefix;
    char *url;
    size_t len;
    int found;  /* 0 nothing yet; 1 a `plant` event named another URL; -1 the plant is here */
} lag_locate;

static inline void lag_locate_on(const lcm_recv_buf_t *rb, const char *channel, void *user)
{
    lag_locate *l = user;
    static lag_wire_event ev; /* large: not on the stack */
    size_t n = strlen(l->prefix);
    bool event = !strcmp(channel + n, lag_bus_suffix(LAG_BUS_EVENT));
    if (!event) {
        l->found = -1; /* its state, status or scene: a plant of this bus */
        return;
    }
    if (lag_wire_decode(LAG_WIRE_EVENT, rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &ev) != LAG_WIRE_OK)
        return;
    if (strcmp(ev.kind, "plant") != 0) {
        l->found = -1;
        return;
    }
    lag_bus b;
    char err[64];
    if (lag_bus_init(&b, ev.detail, l->prefix, err, sizeof err) == 0 &&
        lag_locate_elsewhere(b.state_url)) {
        snprintf(l->url, l->len, "%s", b.state_url);
        l->found = 1;
    }
}

/* The URL the directory on LCM's default bus names for `prefix`, into url (len bytes):
 * true when it is another bus than the default; false when the prefix is a plant of that
 * bus itself (its state, status, scene or an event of its own heard first), or nothing
 * names it within LAG_LOCATE_WAIT_S. Listens only: asks nothing of any plant. */
static inline bool lag_locate_plant(const char *prefix, char *url, size_t len)
{
    lag_locate l = {prefix, url, len, 0};
    char pattern[160];
    if (strlen(prefix) > 64) return false;
    snprintf(pattern, sizeof pattern, "%s_(EVENT|STATE|STATUS|SCENE)", prefix);
    lcm_t *lcm = lcm_create(NULL);
    lcm_subscription_t *sub = lcm ? lcm_subscribe(lcm, pattern, lag_locate_on, &l) : NULL;
    if (sub) lcm_subscription_set_queue_capacity(sub, 64);
    double end = lag_client_now() + LAG_LOCATE_WAIT_S;
    for (double left; sub && l.found == 0 && (left = end - lag_client_now()) > 0;)
        if (lcm_handle_timeout(lcm, (int)(left * 1000.0) + 1) < 0) break;
    if (sub) lcm_unsubscribe(lcm, sub);
    if (lcm) lcm_destroy(lcm);
    return l.found == 1;
}

#endif
