/*
 * Where a plant's messages go: the two LCM URLs and the six channels of a lagsimd daemon,
 * derived from its LCM URL and channel prefix. The daemon, the C client library, the
 * view and the tests all take them from here; the Python, Lua and Java helpers
 * (clients/python/lagsim_lcm.py plant_urls, clients/lua/lagsim_lcm.lua plant_urls,
 * clients/java/lagsim/examples/PlantUrls.java) follow the same rule and are checked
 * against the same table of cases (tests/net/plant_urls.txt).
 *
 * The rule (docs/network.md):
 *   - the base URL is the scene's lcm.url, or LCM_DEFAULT_URL, or LCM's default
 *     udpm://239.255.76.67:7667?ttl=0;
 *   - the STATE URL is the base URL: the daemon publishes <PREFIX>_STATE, _STATUS,
 *     _EVENT and _SCENE there, and controllers, the view and lcm-logger listen there;
 *   - the COMMAND URL is the same group and options on the next port (PORT + 1):
 *     controllers publish <PREFIX>_COMMAND and _CONTROL there, and only the daemon
 *     listens;
 *   - memq:// (one in-process bus, for tests) is both.
 * Two ports, not two groups: a Linux socket bound to a port receives every group joined
 * on that port by any socket of the host, so only the port keeps a flood of commands out
 * of the sockets of those who only want states.
 */
#ifndef LAGSIM_BUS_H
#define LAGSIM_BUS_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_BUS_URL_LEN 320       /* a derived URL: the scene's (< 256) and a longer port */
#define LAG_BUS_CHANNEL_LEN 76    /* prefix (< 64) + "_REFERENCE" */
#define LAG_BUS_PREFIX_MAX 53     /* a channel name has at most 63 bytes; _REFERENCE has 10 */
#define LAG_BUS_DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0" /* LCM's own default */

/* The channels of one plant; all but COMMAND and CONTROL are the daemon's output. */
typedef enum lag_bus_channel {
    LAG_BUS_STATE = 0,
    LAG_BUS_STATUS,
    LAG_BUS_EVENT,
    LAG_BUS_SCENE,
    LAG_BUS_COMMAND,  /* input: on the command URL */
    LAG_BUS_CONTROL,  /* input: on the command URL */
    LAG_BUS_REFERENCE,/* output, on the state URL: only when the scene has a reference */
    LAG_BUS_CHANNEL_COUNT,
    /* Not on the bus: in the daemon's --log only, the commanded input of a period. */
    LAG_BUS_INPUT = LAG_BUS_CHANNEL_COUNT,
    LAG_BUS_SUFFIX_COUNT
} lag_bus_channel;

typedef struct lag_bus {
    char state_url[LAG_BUS_URL_LEN];   /* _STATE, _STATUS, _EVENT, _SCENE */
    char command_url[LAG_BUS_URL_LEN]; /* _COMMAND, _CONTROL */
    bool udpm;                         /* false: memq:// (one bus for both) */
    char group[16];                    /* udpm: the multicast group, dotted */
    int state_port, command_port;      /* udpm */
    char channel[LAG_BUS_CHANNEL_COUNT][LAG_BUS_CHANNEL_LEN];
} lag_bus;

/* Derives the URLs and channels of the plant with LCM URL `url` (NULL or "": the
 * environment's LCM_DEFAULT_URL, else LCM's default) and channel prefix `prefix`.
 * Accepts memq:// and udpm://[GROUP[:PORT]][?OPTIONS] as lag_url_parse reads them
 * (lagsim_url.h; the options kept as given; the command port is PORT + 1); anything else,
 * a URL of 256 characters or more, or a prefix of 0 or more than 53 characters, is refused
 * with a message in err. Returns 0 or -1. OUT: b */
int lag_bus_init(lag_bus *b, const char *url, const char *prefix, char *err, size_t errlen);

/* The suffix of a channel ("_STATE", ...; "_INPUT"): the one table of them. */
const char *lag_bus_suffix(lag_bus_channel ch);

/* Writes the name of channel ch of the plant with prefix `prefix` ("<PREFIX>_STATE") to
 * dst; returns what snprintf returns (>= cap: cut short). OUT: dst */
int lag_bus_channel_name(char *dst, size_t cap, const char *prefix, lag_bus_channel ch);

/* Whether the channel goes to the daemon (command URL) rather than from it. */
bool lag_bus_is_input(lag_bus_channel ch);

#ifdef __cplusplus
}
#endif
#endif
