/*
 * Scene defaults and names: the part of the scene that needs no YAML.
 */
#include <ctype.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"
#include "lagsim_url.h"

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
    int64_t k;
    if (lag_ticks_exact(1.0 / sc->publish_hz, sc->sim.integrator.dt, &k) && k >= 1)
        sc->ticks_per_period = k;
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

/* d's field and message (what is expected, what was found): a rule broken. */
static lag_result fault(lag_diag *d, const char *field, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static lag_result fault(lag_diag *d, const char *field, const char *fmt, ...)
{
    snprintf(d->field, sizeof d->field, "%s", field);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->message, sizeof d->message, fmt, ap);
    va_end(ap);
    return LAG_ERR_ARG;
}

lag_result lag_scene_check_prefix_len(size_t n, lag_diag *d)
{
    if (n >= 1 && n <= LAG_SCENE_PREFIX_MAX) return LAG_OK;
    return fault(d, "lcm.prefix", "expected a channel prefix of 1 to %d characters, got %zu "
                 "(LCM channel names have at most 63 bytes, and the longest suffix, "
                 "_REFERENCE, has 10)", LAG_SCENE_PREFIX_MAX, n);
}

lag_result lag_scene_check(const lag_scene *sc, lag_diag *d)
{
    const double hz = sc->publish_hz;
    if (!(hz > 0) || !isfinite(hz) || sc->ticks_per_period < 1 ||
        sc->ticks_per_period > LAG_SCENE_PERIOD_TICKS_MAX)
        return fault(d, "publish_hz", "expected > 0 and finite, 1/publish_hz a whole number "
                     "of ticks (1 to 2^53), got %g Hz (%lld ticks)", hz,
                     (long long)sc->ticks_per_period);
    const double rate = sc->realtime.rate, shz = sc->realtime.status_hz;
    if (!(rate > 0) || !isfinite(rate))
        return fault(d, "realtime.rate", "expected > 0 and finite (sim s per wall s), got %g",
                     rate);
    if (!(shz > 0) || !isfinite(shz))
        return fault(d, "realtime.status_hz", "expected > 0 and finite (Hz), got %g", shz);
    const double retry = sc->realtime.lockstep_retry, wait = sc->realtime.lockstep_timeout;
    if (!(retry >= 0) || !isfinite(retry))
        return fault(d, "realtime.lockstep_retry", "expected >= 0 and finite (wall s), got %g",
                     retry);
    if (!(wait >= 0) || !isfinite(wait))
        return fault(d, "realtime.lockstep_timeout", "expected >= 0 and finite (wall s), got %g",
                     wait);
    if (!(sc->realtime.command_timeout >= 0))
        return fault(d, "realtime.command_timeout", "expected >= 0 (sim s; inf: never), got %g",
                     sc->realtime.command_timeout);
    return lag_scene_check_prefix_len(strnlen(sc->lcm.prefix, sizeof sc->lcm.prefix), d);
}

lag_result lag_scene_read_decimal(const char *t, double *v)
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
        return LAG_ERR_SYNTAX;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!(*p >= '0' && *p <= '9'))
            return LAG_ERR_SYNTAX;
        while (*p >= '0' && *p <= '9')
            p++;
    }
    if (*p != '\0')
        return LAG_ERR_SYNTAX;
    double x = strtod(t, NULL);
    if (!isfinite(x))
        return LAG_ERR_RANGE;
    *v = x;
    return LAG_OK;
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

/* See scene.h: the wire layer's one URL reader, under a scene's rules. */
lag_result lag_scene_check_url(const char *url, bool allow_lan, int *ttl, char *err,
                               size_t errlen)
{
    *ttl = 0;
    if (!url || url[0] == '\0')
        return LAG_OK;
    lag_url u;
    int flags = LAG_URL_SCENE_RULES | (allow_lan ? LAG_URL_ALLOW_LAN : 0);
    if (lag_url_parse(url, flags, &u, err, errlen) != 0)
        return LAG_ERR_SCENE;
    *ttl = u.ttl;
    return LAG_OK;
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
