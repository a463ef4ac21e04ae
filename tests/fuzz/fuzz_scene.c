/*
 * Fuzz target: the scene loader, from a scene file and --set overrides made of arbitrary
 * bytes, then the core on what the loader accepted.
 *
 * Input: the scene file's bytes, then, after each NUL byte, one --set "key.path=value"
 * (at most 8; a NUL cannot occur inside a command-line argument). What must hold:
 *   - the loader never crashes, leaks or takes long (the limits of scene.h bound a
 *     hostile file's cost; libFuzzer's -timeout and -rss_limit_mb watch them);
 *   - a refused scene has exactly one line of message, naming the file or the --set;
 *   - an accepted scene is one the core accepts too (lag_sim_init), with every value
 *     inside the loader's documented ranges, and a few control periods of it (with an
 *     input on every actuated joint) give finite states whenever the core says they are
 *     good. A step refused with an error code is a correct outcome.
 * The integrator's per-tick work is capped here (max_steps, ticks per advance) so that
 * the target stays fast; the loader's own bounds are the ones checked above.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"

#define MAX_SETS 8
#define NAME "scene.yaml"

static void die(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_scene: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

static void check_finite(const char *what, int n, const double *x)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i]))
            die("non-finite value reported as good", what);
}

static void check_in(const char *what, double v, double lo, double hi)
{
    if (!(v >= lo && v <= hi)) {
        char buf[128];
        snprintf(buf, sizeof buf, "%s = %g outside [%g, %g]", what, v, lo, hi);
        die("accepted scene out of range", buf);
    }
}

/* The loader's documented ranges (docs/scenes.md), for what it accepted. */
static void check_scene(const lag_scene *sc)
{
    const lag_sim_def *d = &sc->sim;
    check_in("integrator.dt", d->integrator.dt, 1e-6, 1.0);
    check_in("publish_hz", sc->publish_hz, 0.01, 1e4);
    check_in("ticks_per_period", (double)sc->ticks_per_period, 1, 100000);
    check_in("explode_limit", d->explode_limit, 1e-6, 1e9);
    check_in("realtime.rate", sc->realtime.rate, 1e-3, 1e3);
    check_in("realtime.status_hz", sc->realtime.status_hz, 0.1, 100);
    check_in("realtime.lockstep_timeout", sc->realtime.lockstep_timeout, 1e-3, 3600);
    check_in("realtime.command_timeout", sc->realtime.command_timeout,
             (double)sc->ticks_per_period * d->integrator.dt * (1 - 1e-9), LAG_SCENE_MAX_TIME);
    const lag_model_info *info = lag_model_info_get(d->model.kind);
    for (int i = 0; i < d->model.nq; i++)
        if (info->actuated[i])
            check_in("realtime.effort_limit", sc->realtime.effort_limit[i], 1e-300, 1e12);
    const lag_effects_def *e = &d->effects;
    for (int k = 0; k < e->n_disturbances; k++) {
        check_in("disturbance t", e->disturbances[k].t, 0, LAG_SCENE_MAX_TIME);
        check_in("disturbance value", e->disturbances[k].value, -1e12, 1e12);
    }
    /* the reference: as the library checks it, finite everywhere, its joints counted */
    int nref = 0;
    for (int i = 0; i < d->model.nq; i++) {
        if (!sc->reference.on[i]) continue;
        nref++;
        const lag_reference *rf = &sc->reference.joint[i];
        char key[64], msg[128];
        if (lag_reference_check(rf, key, sizeof key, msg, sizeof msg) != 0)
            die("accepted reference fails the library's check", key);
        check_in("reference amplitude", rf->amplitude, -d->explode_limit, d->explode_limit);
        check_in("reference offset", rf->offset, -d->explode_limit, d->explode_limit);
        double r, rdot, rddot;
        lag_reference_eval(rf, rf->start + 0.5, &r, &rdot, &rddot);
        if (!isfinite(r) || !isfinite(rdot) || !isfinite(rddot))
            die("accepted reference not finite", NULL);
    }
    if (nref != sc->reference.n) die("reference joints miscounted", NULL);
    int ttl = -1;
    char err[256];
    if (lag_scene_check_url(sc->lcm.url, sc->lcm.allow_lan, &ttl, err, sizeof err) != 0 ||
        ttl != sc->lcm.ttl || (ttl > 0 && !sc->lcm.allow_lan))
        die("accepted lcm.url fails its own check", sc->lcm.url);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* split: file, then NUL-separated --sets */
    char *buf = malloc(size + 1);
    if (!buf)
        return 0;
    memcpy(buf, data, size);
    buf[size] = '\0';
    size_t flen = strnlen(buf, size);
    const char *sets[MAX_SETS];
    int nsets = 0;
    for (size_t at = flen; at < size && nsets < MAX_SETS;) {
        sets[nsets++] = buf + at + 1; /* NUL-terminated by the next NUL or buf[size] */
        at += 1 + strlen(buf + at + 1);
    }

    static lag_scene sc; /* large: not on the stack */
    char err[1024];
    int rc = lag_scene_load_buffer(NAME, buf, flen, sets, nsets, &sc, err, sizeof err);
    if (rc != 0) {
        if (err[0] == '\0')
            die("refused without a message", NULL);
        if (strchr(err, '\n'))
            die("message of more than one line", err);
        if (strncmp(err, NAME, strlen(NAME)) != 0 && strncmp(err, "--set ", 6) != 0)
            die("message names neither the file nor a --set", err);
        free(buf);
        return 0;
    }
    check_scene(&sc);

    /* the core accepts what the loader accepted */
    sc.sim.integrator.max_steps = sc.sim.integrator.max_steps > 2000 ? 2000
                                                                      : sc.sim.integrator.max_steps;
    static lag_sim sim;
    if (lag_sim_init(&sim, &sc.sim, err, sizeof err) != LAG_OK)
        die("the core refuses a scene the loader accepted", err);
    const lag_model_info *info = lag_model_info_get(sc.sim.model.kind);
    double tau[LAG_MAX_DOF] = {0};
    int64_t n = sc.ticks_per_period < 16 ? sc.ticks_per_period : 16;
    for (int period = 0; period < 4; period++) {
        for (int i = 0; i < sim.nq; i++)
            tau[i] = info->actuated[i] ? (period % 2 ? -1.0 : 1.0) * sc.realtime.effort_limit[i] *
                                             (period < 2 ? 1e-6 : 1.0)
                                       : 0.0;
        lag_sim_set_input(&sim, tau);
        lag_result r = lag_sim_advance(&sim, n, period % 2 == 0);
        lag_event ev;
        while (lag_sim_poll_event(&sim, &ev))
            if (!isfinite(ev.t))
                die("non-finite event time", NULL);
        if (r != LAG_OK)
            break;
        check_finite("q", sim.nq, sim.q);
        check_finite("qd", sim.nq, sim.qd);
        double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
        lag_sim_observe(&sim, q, qd);
        check_finite("observed q", sim.nq, q);
        check_finite("observed qd", sim.nq, qd);
        double energy = lag_sim_energy(&sim);
        if (!isfinite(energy))
            die("non-finite energy of a good state", NULL);
    }
    free(buf);
    return 0;
}
