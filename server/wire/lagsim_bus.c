/*
 * A plant's LCM URLs and channels: see lagsim_bus.h.
 */
#include "lagsim_bus.h"
#include "lagsim_url.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const suffix[LAG_BUS_SUFFIX_COUNT] = {
    [LAG_BUS_STATE] = "_STATE",     [LAG_BUS_STATUS] = "_STATUS",
    [LAG_BUS_EVENT] = "_EVENT",     [LAG_BUS_SCENE] = "_SCENE",
    [LAG_BUS_COMMAND] = "_COMMAND", [LAG_BUS_CONTROL] = "_CONTROL",
    [LAG_BUS_REFERENCE] = "_REFERENCE", [LAG_BUS_INPUT] = "_INPUT",
};
_Static_assert(sizeof suffix / sizeof suffix[0] == LAG_BUS_SUFFIX_COUNT, "one suffix per channel");

const char *lag_bus_suffix(lag_bus_channel ch)
{
    return (unsigned)ch < LAG_BUS_SUFFIX_COUNT ? suffix[ch] : "";
}

int lag_bus_channel_name(char *dst, size_t cap, const char *prefix, lag_bus_channel ch)
{
    return snprintf(dst, cap, "%s%s", prefix ? prefix : "", lag_bus_suffix(ch));
}

bool lag_bus_is_input(lag_bus_channel ch)
{
    return ch == LAG_BUS_COMMAND || ch == LAG_BUS_CONTROL;
}

static int fail(char *err, size_t errlen, const char *fmt, const char *url)
{
    if (err && errlen) snprintf(err, errlen, fmt, url);
    return -1;
}

_Static_assert(LAG_BUS_PREFIX_MAX == 53, "the message below says 53");

int lag_bus_init(lag_bus *b, const char *url, const char *prefix, char *err, size_t errlen)
{
    memset(b, 0, sizeof *b);
    if (err && errlen) err[0] = '\0';
    if (!prefix || prefix[0] == '\0' || strlen(prefix) > LAG_BUS_PREFIX_MAX)
        return fail(err, errlen, "a channel prefix has 1 to 53 characters (LCM channel names "
                    "have at most 63 bytes, and _REFERENCE 10)%s", "");
    for (int k = 0; k < LAG_BUS_CHANNEL_COUNT; k++)
        snprintf(b->channel[k], LAG_BUS_CHANNEL_LEN, "%s%s", prefix, suffix[k]);

    if (!url || url[0] == '\0') {
        const char *env = getenv("LCM_DEFAULT_URL");
        url = env && env[0] ? env : LAG_BUS_DEFAULT_URL;
    }
    if (strlen(url) >= 256)
        return fail(err, errlen, "LCM URL longer than 255 characters: '%.40s...'", url);
    lag_url u;
    if (lag_url_parse(url, 0, &u, err, errlen) != 0) return -1;
    if (u.provider == LAG_URL_MEMQ) {
        snprintf(b->state_url, sizeof b->state_url, "%s", url);
        snprintf(b->command_url, sizeof b->command_url, "%s", url);
        return 0;
    }
    b->udpm = true;
    snprintf(b->group, sizeof b->group, "%s", u.group);
    b->state_port = u.port;
    b->command_port = u.port + 1;
    /* the options, kept as given */
    snprintf(b->state_url, sizeof b->state_url, "udpm://%s:%d%s", b->group, b->state_port,
             u.query);
    snprintf(b->command_url, sizeof b->command_url, "udpm://%s:%d%s", b->group,
             b->command_port, u.query);
    return 0;
}
