/*
 * Scene defaults and names: the part of the scene that needs no YAML.
 */
#include <ctype.h>
#include <stdio.h>
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
    sc->realtime.status_hz = 5.0;
    sc->lcm.url[0] = '\0';

    /* Channel prefix: the model name in capitals ("DIPC"). */
    const lag_model_info *info = lag_model_info_get(kind);
    const char *name = info && info->name ? info->name : "LAGSIM";
    size_t i = 0;
    for (; name[i] && i + 1 < sizeof sc->lcm.prefix; i++)
        sc->lcm.prefix[i] = (char)toupper((unsigned char)name[i]);
    sc->lcm.prefix[i] = '\0';
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
