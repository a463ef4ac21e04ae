/*
 * The scene as a run uses it (scene_run.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_run.h"

/* A scene without lcm.url leaves the choice to LCM, which reads LCM_DEFAULT_URL: that
 * URL gets the scene's checks too (no file:// logs, no ttl above 0 without
 * lcm.allow_lan) and becomes the scene's, so what runs is what was checked. */
lag_result scene_run_default_url(lag_scene *sc)
{
    const char *env = getenv("LCM_DEFAULT_URL");
    if (sc->lcm.url[0] != '\0' || !env || env[0] == '\0')
        return LAG_OK;
    char err[512];
    if (strlen(env) >= sizeof sc->lcm.url) {
        fprintf(stderr, "lagsimd: LCM_DEFAULT_URL: longer than %zu characters\n",
                sizeof sc->lcm.url - 1);
        return LAG_ERR_SCENE;
    }
    if (lag_scene_check_url(env, sc->lcm.allow_lan, &sc->lcm.ttl, err, sizeof err) != 0) {
        fprintf(stderr, "lagsimd: LCM_DEFAULT_URL: %s\n", err);
        return LAG_ERR_SCENE;
    }
    snprintf(sc->lcm.url, sizeof sc->lcm.url, "%s", env);
    return LAG_OK;
}

/* Whether the --set overrides give integrator.method (a scene's integrator.error then
 * chooses nothing: the run is told). */
static bool integrator_given(const char *const *sets, int nsets)
{
    for (int i = 0; i < nsets; i++)
        if (strncmp(sets[i], "integrator.method=", 18) == 0) return true;
    return false;
}

/* integrator.error: the integrator the calibration chooses, or the one the command line
 * names with --set integrator.method=... (a rerun of a choice, or the user's own): then
 * said, and not measured. OUT: ch */
static lag_result choose(const lag_scene *sc, const char *const *sets, int nsets, bool offline,
                         bool quiet, lagsimd_choice *ch)
{
    ch->n = 0;
    if (sc->accuracy.error > 0 && integrator_given(sets, nsets)) {
        fprintf(stderr, "lagsimd: integrator.error %g: the integrator given by --set (%s, dt %g "
                "s) is used, not measured\n", sc->accuracy.error,
                lag_method_name(sc->sim.integrator.method), sc->sim.integrator.dt);
        return LAGSIMD_EXIT_OK;
    }
    return lagsimd_choose_integrator(sc, offline, quiet, ch);
}

/* Appends the calibration's choice to the overrides (main made room for its 4) and
 * loads the scene again with it. */
static lag_result reload_with(const char *config, const char *text, size_t len,
                              const char **sets, int *nsets, const lagsimd_choice *ch,
                              lag_scene *sc)
{
    char err[1024];
    for (int i = 0; i < ch->n; i++) sets[(*nsets)++] = ch->kv[i];
    if (lag_scene_load_buffer(config, text, len, sets, *nsets, sc, err, sizeof err) != 0) {
        fprintf(stderr, "lagsimd: the integrator chosen for integrator.error: %s\n", err);
        return LAG_ERR_SCENE;
    }
    return LAG_OK;
}

lag_result scene_run_load(const char *name, const char *text, size_t len, const char **sets,
                          int *nsets, scene_run_how how, lagsimd_choice *choice, lag_scene *sc)
{
    char err[1024];
    choice->n = 0;
    if (lag_scene_load_buffer(name, text, len, sets, *nsets, sc, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "%s\n", err);
        return LAG_ERR_SCENE;
    }
    if (how.cost) return LAG_OK;
    if (how.replay && sc->accuracy.error > 0 && !integrator_given(sets, *nsets)) {
        fprintf(stderr, "lagsimd: %s: integrator.error: the recorded run chose its integrator "
                "when it started; give the same with --set integrator.method=... --set "
                "integrator.dt=... (and rtol, atol for dopri5), as the run printed them\n",
                name);
        return LAG_ERR_USAGE;
    }
    if (!how.replay && choose(sc, sets, *nsets, how.offline, how.quiet, choice) != LAG_OK)
        return LAG_ERR_USAGE; /* said why */
    if (choice->n > 0) return reload_with(name, text, len, sets, nsets, choice, sc);
    return LAG_OK;
}
