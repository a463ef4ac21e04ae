/*
 * A scene: everything a YAML scene file says. The core part (lag_sim_def) plus the
 * daemon's settings (output rate, real-time pacing, LCM). Pure C: scene_yaml.c fills it
 * with libyaml; nothing else here depends on libyaml.
 */
#ifndef LAGSIM_SCENE_H
#define LAGSIM_SCENE_H

#include "lagsim/lagsim.h"

typedef enum lag_rt_mode {
    LAG_RT_REALTIME = 0, /* paced against CLOCK_MONOTONIC at realtime.rate */
    LAG_RT_FAST,         /* as fast as possible, still serving LCM */
    LAG_RT_LOCKSTEP      /* one control period per answering command */
} lag_rt_mode;

typedef struct lag_scene {
    char path[512];          /* file it was read from ("" if built in code) */
    lag_sim_def sim;         /* model, parameters, integrator, initial state */
    double publish_hz;       /* state output rate = control rate, Hz; default 100 */
    int64_t ticks_per_period;/* (1/publish_hz) / dt, an integer (validated) */
    struct {
        lag_rt_mode mode;        /* default realtime */
        double rate;             /* sim seconds per wall second, default 1.0 */
        double command_timeout;  /* sim s; a command older than this is zeroed; default 0.5 */
        double lockstep_timeout; /* wall s; lockstep waits this long for a command; 1.0 */
        double status_hz;        /* status publication rate, Hz; default 5 */
    } realtime;
    struct {
        char url[256];           /* "" = LCM's default (honours LCM_DEFAULT_URL) */
        char prefix[64];         /* channel prefix; default the model name in capitals */
    } lcm;
} lag_scene;

/* Defaults for a model kind: lag_default_sim_def plus the daemon defaults above. */
void lag_scene_default(lag_scene *sc, lag_model_kind kind);

/* Loads a YAML scene file, then applies `nsets` overrides "dotted.key.path=yaml value"
 * (same validation as the file). On failure returns non-zero and writes
 * "file:line:column: what was expected" (or "--set key: ...") into err. OUT: sc */
int lag_scene_load(const char *path, const char *const *sets, int nsets, lag_scene *sc,
                   char *err, size_t errlen);

const char *lag_rt_mode_name(lag_rt_mode m);

#endif
