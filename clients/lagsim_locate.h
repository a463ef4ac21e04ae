/*
 * Where a plant named by its prefix runs when no URL was given: a host of plants
 * (lagsimd --plants) keeps a directory on LCM's default bus, where each of its plants says
 * every 0.5 s on which URL it runs (a `plant` event, lag_client_discover follows it); the
 * plant takes its commands there, not on the directory. The programs that take --prefix
 * without --url (lagsimctl, the C controllers, lagsim-view) ask here first.
 *
 * Header only (static functions over lag_client_discover): the client library's ABI is not
 * changed by it.
 */
#ifndef LAGSIM_LOCATE_H
#define LAGSIM_LOCATE_H

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_bus.h"
#include "lagsim_client.h"

#define LAG_LOCATE_WAIT_S 1.0 /* a host's directory names each plant every 0.5 s */

/* Whether `url` is another bus than LCM's default (LCM_DEFAULT_URL's). */
static inline bool lag_locate_elsewhere(const char *url)
{
    lag_bus b;
    char err[64];
    return url && url[0] && lag_bus_init(&b, NULL, "X", err, sizeof err) == 0 &&
           strcmp(b.state_url, url) != 0;
}

/* The URL the directory on LCM's default bus names for `prefix`, into url (len bytes):
 * true when it is another bus than the default; false when the prefix is a plant of that
 * bus itself, or nothing names it within LAG_LOCATE_WAIT_S. */
static inline bool lag_locate_plant(const char *prefix, char *url, size_t len)
{
    lag_client_plant *all = calloc(LAG_CLIENT_MAX_PLANTS, sizeof *all);
    char err[256];
    int n = 0;
    bool found = false;
    if (all && lag_client_discover(NULL, LAG_LOCATE_WAIT_S, 0.3, all, LAG_CLIENT_MAX_PLANTS,
                                   sizeof all[0], &n, err, sizeof err) == LAG_CLIENT_OK)
        for (int i = 0; i < n && !found; i++)
            if (!strcmp(all[i].prefix, prefix) && lag_locate_elsewhere(all[i].url)) {
                snprintf(url, len, "%s", all[i].url);
                found = true;
            }
    free(all);
    return found;
}

#endif
