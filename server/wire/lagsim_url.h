/*
 * lagsim's one reader of LCM URLs: memq:// and udpm://[GROUP[:PORT]][?OPTIONS], the
 * grammar of LCM's lcm_udpm.c made strict. The scene loader (lcm.url, LCM_DEFAULT_URL)
 * and the plant's URLs (lagsim_bus: daemon, client library, view, tools) both read a URL
 * here; nothing else in the project takes a URL apart (tests/structure checks it).
 *
 *   - memq:// takes nothing after it;
 *   - GROUP is a dotted IPv4 multicast address (224.0.0.0 to 239.255.255.255), each octet
 *     decimal without leading zeros (LCM reads the group with inet_aton and the port with
 *     strtol(.., 0): both take those as octal); absent: LCM's 239.255.76.67;
 *   - PORT is 1 to 65534 (a plant's commands go to PORT + 1), decimal, only after a
 *     GROUP; absent: LCM's 7667;
 *   - after the address only "?OPTIONS" or the end.
 * The options are kept as given (u->query) unless LAG_URL_SCENE_RULES asks for the rules
 * of a scene's lcm.url (docs/scenes.md): only ttl (0 to 255, above 0 only with
 * LAG_URL_ALLOW_LAN) and recv_buf_size (4096 to 268435456), each at most once, decimal.
 */
#ifndef LAGSIM_URL_H
#define LAGSIM_URL_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_URL_DEFAULT_GROUP "239.255.76.67" /* LCM's own defaults */
#define LAG_URL_DEFAULT_PORT 7667

typedef enum lag_url_flags {
    LAG_URL_SCENE_RULES = 1, /* check the options as a scene's lcm.url */
    LAG_URL_ALLOW_LAN = 2    /* with the above: a ttl above 0 is meant (lcm.allow_lan) */
} lag_url_flags;

typedef enum lag_url_provider { LAG_URL_MEMQ = 0, LAG_URL_UDPM } lag_url_provider;

/* A URL taken apart. */
typedef struct lag_url {
    lag_url_provider provider;
    bool has_group;        /* udpm: GROUP given */
    char group[16];        /* udpm: dotted, LCM's default when not given */
    bool has_port;         /* udpm: PORT given */
    int port;              /* udpm: LCM's default when not given */
    const char *query;     /* "" or "?OPTIONS" as given: points into the URL */
    int ttl;               /* LAG_URL_SCENE_RULES: the ttl option, 0 when absent */
    long recv_buf_size;    /* LAG_URL_SCENE_RULES: the option, 0 when absent */
} lag_url;

/* Reads url (not NULL) into *u under flags (lag_url_flags, or-ed). Returns 0, or -1
 * with what was expected in err. OUT: u */
int lag_url_parse(const char *url, int flags, lag_url *u, char *err, size_t errlen);

/* The URL of u (read by lag_url_parse, its URL still there: u->query points into it) on
 * another port: "udpm://GROUP:PORT" and u's options as given, or "memq://". Returns what
 * snprintf returns (>= len: cut short). OUT: out */
int lag_url_format(const lag_url *u, int port, char *out, size_t len);

#ifdef __cplusplus
}
#endif
#endif
