/*
 * The conformance controller in C, over the C client library (clients/lagsim_client.h):
 * the conformance law, for tests/protocol/play.py.
 *
 *   conformance_c --prefix P --url URL [--timeout S]
 *
 * Without a URL (or an empty one) it asks a host's directory on LCM's default bus where
 * the plant runs (lag_client_locate: the trace `directory`).
 *
 * For each state the library returns: u = -(kp q + kd qd) on each actuated joint of the
 * scene of that state's generation (lag_client_latest_scene; kp, kd: its parameters of
 * those names), one line "conformance: law generation=G sim_time=T" on stdout before the
 * command goes. It ends on the daemon's stop event (exit 0), or when no state came for
 * --timeout wall seconds (default 60; exit 0); no scene within --timeout: exit 1
 * (docs/protocol.md, "Checking a binding of your own").
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_client.h"

static void on_event(const lag_client_event *ev, void *user)
{
    if (strcmp(ev->kind, "stop") == 0) *(bool *)user = true;
}

/* The conformance law on state st under scene sc: names[] and u[] of the actuated joints
 * in the scene's order; their count (-1: a joint of the scene missing from the state). */
static int conformance_law(const lag_client_scene *sc, const lag_client_state *st,
                           const char **names, double *u)
{
    double kp = lag_client_scene_param(sc, "kp"), kd = lag_client_scene_param(sc, "kd");
    int n = 0;
    for (int j = 0; j < lag_client_scene_num_joints(sc); j++) {
        if (!lag_client_scene_actuated(sc, j)) continue;
        const char *name = lag_client_scene_joint_name(sc, j);
        int i = lag_client_state_joint(st, name);
        if (i < 0) return -1;
        names[n] = name;
        u[n++] = -(kp * st->position[i] + kd * st->velocity[i]);
    }
    return n;
}

int main(int argc, char **argv)
{
    const char *prefix = "CONFORMANCE", *url = NULL;
    double timeout = 60.0;
    for (int i = 1; i < argc; i++) {
        if (i + 1 < argc && strcmp(argv[i], "--prefix") == 0) prefix = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--url") == 0) url = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--timeout") == 0) timeout = atof(argv[++i]);
        else {
            fprintf(stderr, "usage: conformance_c --prefix P --url URL [--timeout S]\n");
            return 2;
        }
    }
    char err[256], located[LAG_CLIENT_URL_LEN];
    /* no URL: where a host's directory on the default bus says the plant runs */
    if ((!url || !url[0]) && lag_client_locate(prefix, LAG_CLIENT_LOCATE_WAIT_S, located,
                                               sizeof located, NULL, 0) == LAG_CLIENT_LOCATE_HOST)
        url = located;
    lag_client *c = lag_client_create(url, prefix, err, sizeof err);
    if (!c) {
        fprintf(stderr, "conformance_c: %s\n", err);
        return 1;
    }
    bool stopped = false;
    lag_client_on_event(c, on_event, &stopped);
    if (lag_client_wait_scene(c, timeout, NULL) != LAG_CLIENT_OK) {
        fprintf(stderr, "conformance_c: %s\n", lag_client_errmsg(c));
        lag_client_destroy(c);
        return 1;
    }
    int laws = 0;
    double heard = lag_client_now();
    lag_client_scene *sc = lag_client_scene_new(); /* the scene of a state's generation */
    while (!stopped && lag_client_now() - heard < timeout) {
        lag_client_state st;
        lag_result rc = lag_client_wait_state(c, 0.1, &st, sizeof st);
        if (rc == LAG_CLIENT_TIMEOUT) continue;
        if (rc != LAG_CLIENT_OK) break;
        heard = lag_client_now();
        if (!sc || !lag_client_latest_scene(c, sc)) break;
        const char *names[LAG_CLIENT_MAX_JOINTS];
        double u[LAG_CLIENT_MAX_JOINTS];
        int n = conformance_law(sc, &st, names, u);
        if (n < 0) continue;
        laws++;
        printf("conformance: law generation=%lld sim_time=%.17g\n", (long long)st.generation,
               st.sim_time);
        fflush(stdout);
        lag_client_send_command(c, st.sim_time, n, names, u);
    }
    lag_client_counters k;
    lag_client_get_counters(c, &k, sizeof k);
    printf("conformance_c: summary end=%s laws=%d held=%lld describes=%lld dropped=%lld "
           "repeats=%lld\n",
           stopped ? "stop" : "silence", laws, (long long)k.held, (long long)k.describes,
           (long long)k.dropped, (long long)k.repeats);
    lag_client_scene_free(sc);
    lag_client_destroy(c);
    return 0;
}
