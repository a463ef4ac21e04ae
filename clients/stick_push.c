/*
 * stick_push: pushes the sliding stick sideways and reports what the floor does to it.
 *
 * For the first --push-time s of sim time it applies a horizontal force --force (N) on x
 * (the generalized force on the centre of mass's horizontal coordinate), then nothing.
 * The stick falls, hits the floor and bounces until it rests (the scene's floor effect:
 * config/stick.yaml); every impact, rest or lift-off event the daemon publishes on
 * <prefix>_EVENT is printed as it comes.
 *
 * What the run shows, from T and U (docs/models.md):
 *   - x does not appear in U and T has no x-phi coupling, so m x_dd = F_x exactly, and a
 *     frictionless floor pushes only vertically, through every impact: after the push,
 *     x_dot = x_dot0 + F T / m and stays so (summary: x_dot_end, x_dot_expected);
 *   - between impacts the stick lying near phi = 0 swings up and falls back with the
 *     speed it left with, so each impact's phi_dot is the restitution times the one before
 *     (summary: the smallest and largest ratio of successive impacts).
 * Answers every state (lockstep-safe) with F_x (and 0 on phi); the summary line has
 * states, impacts, the first impact time, the rest time and these figures.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_controller.h"

#define MAX_IMPACTS 64

typedef struct seen {
    bool quiet;
    int impacts;
    double impact_t[MAX_IMPACTS], impact_v[MAX_IMPACTS];
    double rest_t;        /* NaN until a rest event */
    int liftoffs;
} seen;

/* Prints and keeps the effects' events (the controller setup handles stop). */
static void on_event(const lag_client_event *ev, void *user)
{
    seen *s = user;
    bool mine = !strcmp(ev->kind, "impact") || !strcmp(ev->kind, "rest") ||
                !strcmp(ev->kind, "liftoff");
    if (!mine) return;
    if (!strcmp(ev->kind, "impact") && s->impacts < MAX_IMPACTS) {
        s->impact_t[s->impacts] = ev->sim_time;
        s->impact_v[s->impacts] = ev->value;
        s->impacts++;
    } else if (!strcmp(ev->kind, "rest") && isnan(s->rest_t)) {
        s->rest_t = ev->sim_time;
    } else if (!strcmp(ev->kind, "liftoff")) {
        s->liftoffs++;
    }
    if (!s->quiet) {
        printf("%-7s t=%.9f s  joint %s  value %+.6g  %s\n", ev->kind, ev->sim_time,
               ev->joint[0] ? ev->joint : "-", ev->value, ev->detail);
        fflush(stdout);
    }
}

int main(int argc, char **argv)
{
    double force = 2.0, push_time = 0.1;
    const lag_ctl_option mine[] = {
        {"force", "F", "horizontal push on x, N (default 2)", lag_ctl_number, &force},
        {"push-time", "T", "push for the first T s of sim time (default 0.1)",
         lag_ctl_nonnegative, &push_time},
    };
    lag_ctl ctl;
    lag_ctl_init(&ctl, "stick_push", "STICK");
    int rc = lag_ctl_parse(&ctl, argc, argv,
                           "Pushes the sliding stick sideways and prints the floor's impact "
                           "events.",
                           mine, (int)(sizeof mine / sizeof mine[0]));
    if (rc >= 0) return rc;
    seen s = {.quiet = ctl.quiet, .rest_t = NAN};
    ctl.on_event = on_event;
    ctl.event_user = &s;

    if (lag_ctl_start(&ctl, "stick")) return lag_ctl_fail(&ctl);
    int jx = lag_client_scene_joint(ctl.scene, "x");
    if (!lag_client_scene_actuated(ctl.scene, jx)) {
        fprintf(stderr, "stick_push: joint x takes no force in this scene\n");
        return lag_ctl_fail(&ctl);
    }
    const double m = ctl.model.p[LAG_STICK_M], h = lag_client_scene_control_period(ctl.scene);
    printf("stick_push: scene on %s_*: mode %s, control period %g s, m = %g kg; pushing x with "
           "%g N for %g s\n", ctl.prefix, lag_client_scene_mode(ctl.scene), h, m, force, push_time);
    fflush(stdout);

    const char *jn[1] = {"x"};
    lag_client_state st;
    int64_t states = 0, pushed = 0;
    double t_first = NAN, t_last = NAN, xd0 = NAN, xd_end = NAN, phi_end = NAN;
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        int ix = lag_client_state_joint(&st, "x"), ip = lag_client_state_joint(&st, "phi");
        if (ix < 0 || ip < 0) continue;
        if (states == 0) {
            t_first = st.sim_time;
            xd0 = st.velocity[ix];
        }
        /* the period that starts at this state is pushed if it starts before push_time */
        bool push = st.sim_time - t_first < push_time - 0.5 * h;
        double f = push ? force : 0.0;
        pushed += push;
        lag_ctl_command(&ctl, &st, 1, jn, &f);
        states++;
        t_last = st.sim_time;
        xd_end = st.velocity[ix];
        phi_end = st.position[ip];
    }
    /* each impact's phi_dot over the one before: the restitution, if the model holds */
    double rmin = NAN, rmax = NAN;
    for (int k = 1; k < s.impacts; k++) {
        double r = s.impact_v[k] / s.impact_v[k - 1];
        rmin = k == 1 ? r : fmin(rmin, r);
        rmax = k == 1 ? r : fmax(rmax, r);
    }
    double impulse = force * (double)pushed * h;
    return lag_ctl_finish(&ctl,
                          "states=%lld t_first=%.6f t_last=%.6f pushed_periods=%lld impulse=%.17g "
                          "x_dot_end=%.17g x_dot_expected=%.17g phi_end=%.6g impacts=%d "
                          "first_impact=%.12g last_impact=%.12g rest=%.12g liftoffs=%d "
                          "ratio_min=%.12g ratio_max=%.12g",
                          (long long)states, t_first, t_last, (long long)pushed, impulse, xd_end,
                          xd0 + impulse / m, phi_end, s.impacts,
                          s.impacts ? s.impact_t[0] : NAN,
                          s.impacts ? s.impact_t[s.impacts - 1] : NAN, s.rest_t, s.liftoffs,
                          rmin, rmax);
}
