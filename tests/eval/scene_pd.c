/*
 * scene_pd: a controller that reads its parameters from every scene description, as the
 * protocol has it (docs/clients.md): PD on both joints of the manipulator towards a set
 * point, its gains scaled by the scene's m2, the m2 of the last <PREFIX>_SCENE received
 * (lag_client_on_scene). Against a daemon whose runs change m2 (lagsim-sweep --vary
 * parameters.m2=...), its answers are reproducible only when every state reaches it after
 * the scene of its own run: the client library's scene rule (lagsim_client.h).
 * tests/eval/test_sweep.py's `scene` cases run it; scene_pd.py is the same in Python.
 *
 *   tau_k = m2 (KP (target_k - q_k) - KD qd_k),  KP = 40, KD = 12, targets 0.3 rad, 0.6 m
 *
 * --think S sleeps S s before each answer: a lockstep run then lasts at least S s a period
 * of wall time at no CPU, whatever the machine's speed (test_sweep.py: `interrupt` signals
 * a sweep while most of its runs are still to come; `progress` draws a line of many runs'
 * ends over seconds).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "lagsim_controller.h"

#define KP 40.0
#define KD 12.0

/* the scene's m2, from every scene that arrives */
static void on_scene(const lag_client_scene *sc, void *user)
{
    double m2 = lag_client_scene_param(sc, "m2");
    if (isfinite(m2)) *(double *)user = m2;
}

int main(int argc, char **argv)
{
    lag_ctl ctl;
    lag_ctl_init(&ctl, "scene_pd", "MANIPULATOR");
    double think = 0;
    const lag_ctl_option mine[] = {{"think", "S", "sleep S s before each answer (default 0)",
                                    lag_ctl_nonnegative, &think, 0}};
    int rc = lag_ctl_parse(&ctl, argc, argv, "PD on the manipulator, gains scaled by the "
                           "scene's m2 (a test's scene-reactive controller).", mine, 1);
    if (rc >= 0) return rc;
    if (lag_ctl_start(&ctl, "manipulator")) return lag_ctl_fail(&ctl);
    double m2 = lag_client_scene_param(ctl.scene, "m2");
    lag_client_on_scene(ctl.client, on_scene, &m2);
    static const char *const names[2] = {"q1", "q2"};
    static const double target[2] = {0.3, 0.6};
    lag_client_state st;
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        double tau[2];
        if (think > 0) {
            struct timespec ts = {(time_t)think, (long)((think - floor(think)) * 1e9)};
            nanosleep(&ts, NULL);
        }
        for (int k = 0; k < 2; k++) {
            int i = lag_client_state_joint(&st, names[k]);
            tau[k] = i < 0 ? 0.0 : m2 * (KP * (target[k] - st.position[i]) - KD * st.velocity[i]);
        }
        lag_ctl_command(&ctl, &st, 2, names, tau);
    }
    return lag_ctl_finish(&ctl, "states=%lld m2=%.17g", (long long)ctl.states, m2);
}
