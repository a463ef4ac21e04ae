/*
 * A plant's LCM URLs and channels: see lagsim_bus.h.
 */
#include "lagsim_bus.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const suffix[LAG_BUS_CHANNEL_COUNT] = {
    [LAG_BUS_STATE] = "_STATE",     [LAG_BUS_STATUS] = "_STATUS",
    [LAG_BUS_EVENT] = "_EVENT",     [LAG_BUS_SCENE] = "_SCENE",
    [LAG_BUS_COMMAND] = "_COMMAND", [LAG_BUS_CONTROL] = "_CONTROL",
    [LAG_BUS_REFERENCE] = "_REFERENCE",
};
_Static_assert(sizeof suffix / sizeof suffix[0] == LAG_BUS_CHANNEL_COUNT, "one suffix per channel");

const char *lag_bus_suffix(lag_bus_channel ch)
{
    return (unsigned)ch < LAG_BUS_CHANNEL_COUNT ? suffix[ch] : "";
}

bool lag_bus_is_input(lag_bus_channel ch)
{
    return ch == LAG_BUS_COMMAND || ch == LAG_BUS_CONTROL;
}

/* Reads 1 to maxdigits decimal digits at *p into *v, without leading zeros (LCM reads
 * the group with inet_aton and the port with strtol(.., 0): both take those as octal);
 * advances *p. */
static bool read_digits(const char **p, int maxdigits, long *v)
{
    const char *s = *p;
    long x = 0;
    int n = 0;
    while (*s >= '0' && *s <= '9' && n < maxdigits) {
        x = 10 * x + (*s++ - '0');
        n++;
    }
    if (n == 0 || (*s >= '0' && *s <= '9') || (n > 1 && **p == '0')) return false;
    *p = s;
    *v = x;
    return true;
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
    if (strcmp(url, "memq://") == 0) {
        snprintf(b->state_url, sizeof b->state_url, "%s", url);
        snprintf(b->command_url, sizeof b->command_url, "%s", url);
        return 0;
    }
    if (strncmp(url, "udpm://", 7) != 0)
        return fail(err, errlen, "a lagsim plant speaks udpm://GROUP:PORT (or memq:// in one "
                    "process), not '%s'", url);
    const char *p = url + 7;
    /* GROUP: four decimal octets (LCM's default when absent) */
    if (*p == '\0' || *p == '?') {
        snprintf(b->group, sizeof b->group, "%s", LAG_BUS_DEFAULT_GROUP);
    } else {
        long oct[4];
        for (int i = 0; i < 4; i++)
            if ((i > 0 && *p++ != '.') || !read_digits(&p, 3, &oct[i]) || oct[i] > 255)
                return fail(err, errlen, "expected udpm://GROUP:PORT with GROUP a dotted IPv4 "
                            "multicast address, got '%s'", url);
        if (oct[0] < 224 || oct[0] > 239)
            return fail(err, errlen, "the group of '%s' is not a multicast address", url);
        snprintf(b->group, sizeof b->group, "%ld.%ld.%ld.%ld", oct[0], oct[1], oct[2], oct[3]);
    }
    long port = LAG_BUS_DEFAULT_PORT;
    if (*p == ':') {
        p++;
        if (!read_digits(&p, 5, &port) || port < 1 || port > 65534)
            return fail(err, errlen, "expected a port from 1 to 65534 in '%s' (commands go to "
                        "the next port)", url);
    }
    if (*p != '\0' && *p != '?')
        return fail(err, errlen, "unexpected characters after the address in '%s'", url);
    const char *query = p; /* "" or "?options", kept as given */
    b->udpm = true;
    b->state_port = (int)port;
    b->command_port = (int)port + 1;
    snprintf(b->state_url, sizeof b->state_url, "udpm://%s:%d%s", b->group, b->state_port, query);
    snprintf(b->command_url, sizeof b->command_url, "udpm://%s:%d%s", b->group, b->command_port,
             query);
    return 0;
}
