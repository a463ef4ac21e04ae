/*
 * Scene defaults and names: the part of the scene that needs no YAML.
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"

/* Defaults for a model kind: the core's lag_default_sim_def (rk4 at 1 ms, at rest at
 * q = 0, the model's default parameters) plus the daemon's defaults documented in
 * scene.h and README.md ("Scenes"). OUT: sc */
void lag_scene_default(lag_scene *sc, lag_model_kind kind)
{
    memset(sc, 0, sizeof *sc);
    sc->sim = lag_default_sim_def(kind);
    sc->publish_hz = 100.0;
    sc->accuracy.horizon = 1.0;
    sc->accuracy.estimate_every = -1; /* not given: lag_scene_estimate_every */
    /* 1/100 s at dt = 1 ms; the loader recomputes it from the scene's values. */
    sc->ticks_per_period = 10;
    if (sc->sim.integrator.dt > 0.0) {
        double r = (1.0 / sc->publish_hz) / sc->sim.integrator.dt;
        sc->ticks_per_period = r >= 1.0 ? (int64_t)(r + 0.5) : 1;
    }
    sc->realtime.mode = LAG_RT_REALTIME;
    sc->realtime.rate = 1.0;
    sc->realtime.command_timeout = 0.5;
    sc->realtime.lockstep_timeout = 1.0;
    sc->realtime.lockstep_retry = 0.02;
    sc->realtime.status_hz = 5.0;
    const lag_model_info *mi = lag_model_info_get(kind);
    for (int i = 0; mi && i < mi->nq; i++)
        sc->realtime.effort_limit[i] = mi->actuated[i] ? LAG_SCENE_EFFORT_LIMIT : 0.0;
    sc->lcm.allow_lan = false;
    sc->lcm.ttl = 0;
    sc->lcm.url[0] = '\0';

    /* Channel prefix: the model name in capitals ("DIPC"). */
    const lag_model_info *info = lag_model_info_get(kind);
    const char *name = info && info->name ? info->name : "LAGSIM";
    size_t i = 0;
    for (; name[i] && i + 1 < sizeof sc->lcm.prefix; i++)
        sc->lcm.prefix[i] = (char)toupper((unsigned char)name[i]);
    sc->lcm.prefix[i] = '\0';
}

int lag_scene_read_decimal(const char *t, double *v)
{
    const char *p = t;
    if (*p == '+' || *p == '-')
        p++;
    int digits = 0;
    while (*p >= '0' && *p <= '9') { p++; digits++; }
    if (*p == '.') {
        p++;
        while (*p >= '0' && *p <= '9') { p++; digits++; }
    }
    if (digits == 0)
        return -1;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!(*p >= '0' && *p <= '9'))
            return -1;
        while (*p >= '0' && *p <= '9')
            p++;
    }
    if (*p != '\0')
        return -1;
    double x = strtod(t, NULL);
    if (!isfinite(x))
        return -2;
    *v = x;
    return 0;
}

const char *lag_rt_start_name(lag_rt_start s)
{
    switch (s) {
    case LAG_RT_START_RUNNING: return "running";
    case LAG_RT_START_PAUSED: return "paused";
    case LAG_RT_START_FIRST_COMMAND: return "first_command";
    }
    return "?";
}

const char *lag_rt_mode_name(lag_rt_mode m)
{
    switch (m) {
    case LAG_RT_REALTIME: return "realtime";
    case LAG_RT_FAST: return "fast";
    case LAG_RT_LOCKSTEP: return "lockstep";
    }
    return "?";
}

/* Reads a decimal integer of 1 to `maxdigits` digits without leading zeros (inet_aton
 * and strtol(.., 0) read those as octal) from *p, advanced past it. */
static bool read_uint(const char **p, int maxdigits, long *out)
{
    const char *s = *p;
    long v = 0;
    int n = 0;
    while (*s >= '0' && *s <= '9' && n < maxdigits) {
        v = v * 10 + (*s - '0');
        s++;
        n++;
    }
    if (n == 0 || (*s >= '0' && *s <= '9') || (n > 1 && **p == '0'))
        return false;
    *p = s;
    *out = v;
    return true;
}

/* See scene.h. The grammar is LCM's (lcm_udpm.c), made strict: LCM 1.3 only warns about
 * unknown options and accepts any provider it was built with. */
int lag_scene_check_url(const char *url, bool allow_lan, int *ttl, char *err, size_t errlen)
{
    *ttl = 0;
    if (!url || url[0] == '\0')
        return 0;
    if (strncmp(url, "memq://", 7) == 0) {
        if (url[7] != '\0') {
            snprintf(err, errlen, "memq:// takes no address or options, got '%s'", url);
            return -1;
        }
        return 0;
    }
    if (strncmp(url, "udpm://", 7) != 0) {
        const char *sep = strstr(url, "://");
        int n = sep ? (int)(sep - url) : 0;
        if (sep && n < 16)
            snprintf(err, errlen, "LCM provider '%.*s://' is not accepted in a scene: "
                     "expected udpm://GROUP:PORT?ttl=0 (or memq:// for tests)", n, url);
        else
            snprintf(err, errlen, "expected an LCM URL udpm://GROUP:PORT?ttl=0 "
                     "(or memq:// for tests), got '%s'", url);
        return -1;
    }
    const char *p = url + 7;
    if (*p != '\0' && *p != '?') {
        /* GROUP: four decimal octets, a multicast address */
        long oct[4];
        for (int i = 0; i < 4; i++) {
            if ((i > 0 && *p++ != '.') || !read_uint(&p, 3, &oct[i]) || oct[i] > 255) {
                snprintf(err, errlen, "expected udpm://GROUP:PORT with GROUP a dotted IPv4 "
                         "multicast address (e.g. 239.255.76.67), got '%s'", url);
                return -1;
            }
        }
        if (oct[0] < 224 || oct[0] > 239) {
            snprintf(err, errlen, "%ld.%ld.%ld.%ld is not a multicast address "
                     "(224.0.0.0 to 239.255.255.255): udpm needs a multicast group",
                     oct[0], oct[1], oct[2], oct[3]);
            return -1;
        }
        if (*p == ':') {
            p++;
            long port;
            /* a plant's commands go to the next port (lagsim_bus.h) */
            if (!read_uint(&p, 5, &port) || port < 1 || port > 65534) {
                snprintf(err, errlen, "expected a port from 1 to 65534 (commands go to the "
                         "next port) after the group in "
                         "'%s'", url);
                return -1;
            }
        }
        if (*p != '\0' && *p != '?') {
            snprintf(err, errlen, "unexpected '%c' after the address in '%s' "
                     "(expected udpm://GROUP:PORT?option=value&...)", *p, url);
            return -1;
        }
    }
    if (*p == '?') {
        p++;
        bool seen_ttl = false, seen_buf = false;
        for (;;) {
            const char *eq = p;
            while (*eq && *eq != '=' && *eq != '&')
                eq++;
            int klen = (int)(eq - p);
            bool is_ttl = klen == 3 && strncmp(p, "ttl", 3) == 0;
            bool is_buf = klen == 13 && strncmp(p, "recv_buf_size", 13) == 0;
            if (!is_ttl && !is_buf) {
                snprintf(err, errlen, "unknown udpm option '%.*s' in '%s'; allowed: ttl, "
                         "recv_buf_size", klen > 32 ? 32 : klen, p, url);
                return -1;
            }
            if ((is_ttl && seen_ttl) || (is_buf && seen_buf)) {
                snprintf(err, errlen, "udpm option '%.*s' given twice in '%s'", klen, p, url);
                return -1;
            }
            const char *v = eq;
            long val;
            if (*v++ != '=' || !read_uint(&v, 10, &val) || (*v != '\0' && *v != '&')) {
                snprintf(err, errlen, "expected %.*s=<integer> in '%s'", klen, p, url);
                return -1;
            }
            if (is_ttl) {
                seen_ttl = true;
                if (val > 255) {
                    snprintf(err, errlen, "ttl must be 0 to 255, got %ld", val);
                    return -1;
                }
                if (val > 0 && !allow_lan) {
                    snprintf(err, errlen, "ttl=%ld sends every message beyond this host "
                             "(1: the local network, more: through routers); set "
                             "lcm.allow_lan: true if that is meant, or use ttl=0", val);
                    return -1;
                }
                *ttl = (int)val;
            } else {
                seen_buf = true;
                if (val < 4096 || val > 268435456) {
                    snprintf(err, errlen, "recv_buf_size must be 4096 to 268435456 bytes, "
                             "got %ld", val);
                    return -1;
                }
            }
            if (*v == '\0')
                break;
            p = v + 1; /* past '&' */
        }
    }
    return 0;
}

int lag_scene_estimate_every(const lag_scene *sc)
{
    if (sc->accuracy.estimate_every >= 0) return sc->accuracy.estimate_every;
    return sc->accuracy.error > 0 ? LAG_SCENE_ESTIMATE_EVERY : 0;
}

bool lag_scene_key_live(const char *key)
{
    static const char *const roots[] = {"parameters", "effects", "reference"};
    for (size_t i = 0; i < sizeof roots / sizeof roots[0]; i++) {
        size_t n = strlen(roots[i]);
        if (!strncmp(key, roots[i], n) && (key[n] == '\0' || key[n] == '.')) return true;
    }
    return false;
}
