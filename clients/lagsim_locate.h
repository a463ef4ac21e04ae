/*
 * For the programs that take --prefix and --url (lagsimctl, the C controllers, lagsim-view):
 * whether a plant heard on LCM's default bus runs elsewhere. Where a plant named by its
 * prefix runs is the client library's lag_client_locate (a host's directory: its `plant`
 * events); a plant picked by lag_client_pick_plant carries the URL the directory named for
 * it, which this tells from the default bus's.
 */
#ifndef LAGSIM_LOCATE_H
#define LAGSIM_LOCATE_H

#include <stdbool.h>
#include <string.h>

#include "lagsim_client.h"

/* Whether `url` is another bus than LCM's default (LCM_DEFAULT_URL's). */
static inline bool lag_locate_elsewhere(const char *url)
{
    char here[LAG_CLIENT_URL_LEN], cmd[LAG_CLIENT_URL_LEN], err[64];
    return url && url[0] &&
           lag_client_plant_urls(NULL, here, sizeof here, cmd, sizeof cmd, err, sizeof err) ==
               LAG_CLIENT_OK &&
           strcmp(here, url) != 0;
}

#endif
