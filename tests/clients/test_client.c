/*
 * Unit test of the C client library (clients/lagsim_client.c) over real LCM on loopback
 * (default URL, ttl=0) with a channel prefix unique to this process. A second lcm_t
 * plays the daemon: it publishes odd and valid messages and decodes what the client
 * sends (with the wire module's decoders). Checks: odd messages (undecodable, too many
 * joints, over-long names, NaN) are dropped and counted, never returned; valid ones are
 * copied exactly, the status with all its fields; commands and control requests arrive
 * as sent; bad arguments (NaN efforts, over-long names) are refused with a message and
 * nothing is sent; the scene wait sends DESCRIBE requests and times out cleanly when
 * nobody answers; every function follows one return convention. Commands and control
 * requests go to the plant's command URL (the next port), never to the state URL.
 * small_stack: the discovery's helper that names the plants instead of a misspelt prefix,
 * called from a thread of a 256 KiB stack (a controller's worker, a JVM's or a Python
 * thread), runs: its LAG_CLIENT_MAX_PLANTS plants (a lab host's 1024) are not on the
 * caller's stack.
 * first_burst: the daemon's first scene, reference and state published at each moment of
 * lag_client_create (after each of its subscriptions, through a wrapper of lcm_subscribe
 * on memq://, where a message no subscription takes is dropped at once): a state the
 * client keeps has its reference.
 */
#include <dlfcn.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_reference_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"
#include "lagsim_bus.h"
#include "lagsim_client.h"
#include "lagsim_test.h"
#include "lagsim_wire.h"

static int describes = 0, commands = 0, controls = 0, on_state_url = 0;
static lag_wire_joint_command last_cmd;
static lag_wire_control last_ctl;

static void on_control(const lcm_recv_buf_t *rbuf, const char *ch, void *u)
{
    (void)ch; (void)u;
    lag_wire_control m;
    if (lag_wire_decode_control(rbuf->data, rbuf->data_size, LAG_WIRE_MAX_JOINTS, &m)) return;
    controls++;
    last_ctl = m;
    if (m.request == LAGSIM_CONTROL_T_DESCRIBE) describes++;
}

static void on_command(const lcm_recv_buf_t *rbuf, const char *ch, void *u)
{
    (void)ch; (void)u;
    lag_wire_joint_command m;
    if (lag_wire_decode_joint_command(rbuf->data, rbuf->data_size, LAG_WIRE_MAX_JOINTS, &m))
        return;
    commands++;
    last_cmd = m;
}

/* Anything on _COMMAND or _CONTROL heard on the state URL. */
static void on_wrong_url(const lcm_recv_buf_t *rbuf, const char *ch, void *u)
{
    (void)rbuf; (void)ch; (void)u;
    on_state_url++;
}

/* The daemon's side: publishes on the state URL, listens on the command URL. */
static lcm_t *peer_in;

/* Pumps the LCM instances for about `ms` milliseconds. */
static void pump(lcm_t *peer, lag_client *c, int ms)
{
    double end = lag_client_now() + ms * 1e-3;
    while (lag_client_now() < end) {
        lcm_handle_timeout(peer_in, 1);
        lcm_handle_timeout(peer, 0);
        lag_client_handle(c, 1);
    }
}

static int64_t g_gen; /* the generation of the states publish_state sends */
static int64_t g_utime = 42; /* their utime */

static void publish_state(lcm_t *peer, const char *ch, int n, const char *long_name, double t,
                          double p0)
{
    char *names[20];
    double pos[20], vel[20], eff[20];
    for (int i = 0; i < n; i++) {
        names[i] = (char *)(i == 0 && long_name ? long_name : (i == 0 ? "theta0" : "x"));
        pos[i] = i == 0 ? p0 : 0.1 * (i + 1);
        vel[i] = -0.2 * (i + 1);
        eff[i] = 3.0 * i;
    }
    lagsim_joint_state_t m = {.utime = g_utime, .sim_time = t, .step = (int64_t)(t * 1000),
                              .num_joints = (int16_t)n, .name = names, .position = pos,
                              .velocity = vel, .effort = eff, .generation = g_gen};
    lagsim_joint_state_t_publish(peer, ch, &m);
}

/* A manipulator scene of generation gen, as the daemon publishes it. */
static void publish_scene(lcm_t *peer, const char *prefix, int64_t gen, double m2)
{
    char ch[128];
    snprintf(ch, sizeof ch, "%s_SCENE", prefix);
    char *pn[3] = {"m1", "g", "m2"}, *jn[2] = {"q1", "q2"};
    double pv[3] = {2.0, 9.81, m2}, iq[2] = {0.0, 0.5}, iqd[2] = {0, 0};
    int8_t act[2] = {1, 0}, lim_on[2] = {0, 0};
    double lim[2] = {0, 0};
    lagsim_scene_t s = {.utime = 1, .model = "manipulator", .prefix = (char *)prefix,
                        .num_params = 3, .param_name = pn, .param_value = pv, .num_joints = 2,
                        .joint_name = jn, .actuated = act, .initial_q = iq,
                        .initial_qd = iqd, .dt = 0.001, .control_period = 0.01,
                        .integrator = "rk4", .mode = "lockstep", .rate = 1.0,
                        .command_timeout = 0.5, .effects = "", .limit_on = lim_on,
                        .limit_lower = lim, .limit_upper = lim, .generation = gen};
    lagsim_scene_t_publish(peer, ch, &s);
}

static void case_library(int arg)
{
    (void)arg;
    char prefix[64], ch[128], err[256];
    snprintf(prefix, sizeof prefix, "CLTCLIENT_%d", (int)getpid());
    lt_private_lcm(); /* the default URL: a port pair of this process's own */

    ENSURE(lag_client_create(NULL, "", err, sizeof err) == NULL && err[0] != '\0');
    ENSURE(lag_client_create("nosuchprovider://x", prefix, err, sizeof err) == NULL);
    ENSURE(strlen(err) > 0);

    lag_client *c = lag_client_create(NULL, prefix, err, sizeof err);
    lag_bus bus;
    ENSURE(lag_bus_init(&bus, NULL, prefix, err, sizeof err) == 0);
    lcm_t *peer = lcm_create(bus.state_url);
    peer_in = lcm_create(bus.command_url);
    ENSURE(c != NULL && peer != NULL && peer_in != NULL && bus.udpm);
    if (!c || !peer || !peer_in) return;
    lcm_subscribe(peer_in, bus.channel[LAG_BUS_CONTROL], on_control, NULL);
    lcm_subscribe(peer_in, bus.channel[LAG_BUS_COMMAND], on_command, NULL);
    lcm_subscribe(peer, bus.channel[LAG_BUS_CONTROL], on_wrong_url, NULL);
    lcm_subscribe(peer, bus.channel[LAG_BUS_COMMAND], on_wrong_url, NULL);

    /* nobody answers DESCRIBE: timeout, requests were sent, message names the prefix */
    lag_client_scene *sc = lag_client_scene_new();
    ENSURE(sc && lag_client_wait_scene(c, 0.6, sc) == LAG_CLIENT_TIMEOUT);
    ENSURE(strstr(lag_client_errmsg(c), prefix) != NULL);
    pump(peer, c, 50);
    ENSURE(describes >= 2); /* at once and every 0.25 s */

    /* the scene of the states below (generation 0): a state is returned only with it */
    publish_scene(peer, prefix, 0, 0.5);
    pump(peer, c, 50);
    /* odd states, then a valid one */
    snprintf(ch, sizeof ch, "%s_STATE", prefix);
    const char junk[] = "not an LCM message at all";
    lcm_publish(peer, ch, junk, sizeof junk);
    publish_state(peer, ch, 20, NULL, 1.0, 0.1); /* too many joints */
    char longname[100];
    memset(longname, 'a', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    publish_state(peer, ch, 3, longname, 2.0, 0.1); /* name does not fit */
    publish_state(peer, ch, 3, NULL, 2.5, NAN);     /* a NaN position */
    publish_state(peer, ch, 3, NULL, 3.0, 0.1);     /* valid */
    lag_client_state st;
    ENSURE(lag_client_wait_state(c, 2.0, &st, sizeof st) == LAG_CLIENT_OK);
    pump(peer, c, 50);
    ENSURE(st.sim_time == 3.0 && st.step == 3000 && st.num_joints == 3 && st.utime == 42);
    ENSURE(strcmp(st.name[0], "theta0") == 0 && lag_client_state_joint(&st, "theta0") == 0);
    ENSURE(st.position[2] == 0.1 * 3 && st.velocity[1] == -0.2 * 2 && st.effort[2] == 6.0);
    lag_client_counters cnt;
    lag_client_get_counters(c, &cnt, sizeof cnt);
    ENSURE(cnt.states == 1 && cnt.dropped == 4);
    /* no new state: wait_state times out, latest_state still has the valid one */
    ENSURE(lag_client_wait_state(c, 0.1, &st, sizeof st) == LAG_CLIENT_TIMEOUT);
    ENSURE(strstr(lag_client_errmsg(c), "no state") != NULL);
    ENSURE(lag_client_latest_state(c, &st, sizeof st) && st.sim_time == 3.0);
    ENSURE(lag_client_handle(c, 0) == LAG_CLIENT_TIMEOUT);
    /* a state already queued when the wait's time has passed (a process stalled past its
     * deadline on a busy machine) is read, not reported as none */
    publish_state(peer, ch, 3, NULL, 3.5, 0.1);
    struct pollfd pf = {lag_client_fileno(c), POLLIN, 0};
    ENSURE(poll(&pf, 1, 5000) == 1); /* it is in the socket */
    ENSURE(lag_client_wait_state(c, 0.0, &st, sizeof st) == LAG_CLIENT_OK && st.sim_time == 3.5);

    /* a status, every field different: every one of them reaches the client */
    snprintf(ch, sizeof ch, "%s_STATUS", prefix);
    lagsim_status_t gs = {1, 2.5, 3, 4.5, 5.5, 6, 7.5, 8.5, 9.5, "dopri5", "lockstep", "paused",
                          13, 14, 15, 16, 17, 18, 19, 1, 21, 22, 23, 24, 25, 26, 27, 28, 29,
                          "flat", 30, "the first command", 30.5, "", 31, 31.5, "q2", 33.5, 34};
    lagsim_status_t_publish(peer, ch, &gs);
    pump(peer, c, 100);
    /* through the accessors, by the field's name (numbers; texts) */
    lag_client_status *ss = lag_client_status_new();
    ENSURE(ss && lag_client_latest_status(c, ss));
#define SN(f) lag_client_status_number(ss, #f)
#define ST(f) lag_client_status_text(ss, #f)
    ENSURE(SN(utime) == 1 && SN(sim_time) == 2.5 && SN(step) == 3 && SN(wall_time) == 4.5);
    ENSURE(SN(rtf) == 5.5 && SN(overruns) == 6 && SN(step_time_max_us) == 7.5);
    ENSURE(SN(step_time_mean_us) == 8.5 && SN(energy) == 9.5);
    ENSURE(!strcmp(ST(integrator), "dopri5") && !strcmp(ST(mode), "lockstep"));
    ENSURE(!strcmp(ST(run_state), "paused") && SN(commands_accepted) == 13);
    ENSURE(SN(rejected_unknown_joint) == 14 && SN(rejected_unactuated) == 15);
    ENSURE(SN(rejected_nonfinite) == 16 && SN(rejected_bad_length) == 17);
    ENSURE(SN(rejected_undecodable) == 18 && SN(controls_rejected) == 19);
    ENSURE(SN(watchdog_tripped) && SN(watchdog_trips) == 21 && SN(lockstep_timeouts) == 22);
    ENSURE(SN(numeric_faults) == 23 && SN(rejected_stale) == 24 && SN(overrun_bursts) == 25);
    ENSURE(SN(states_published) == 26 && SN(rejected_effort_limit) == 27);
    ENSURE(SN(lockstep_retries) == 28 && SN(commands_ignored) == 29 && !strcmp(ST(contact), "flat"));
    ENSURE(SN(plant_conflicts) == 30);
    ENSURE(!strcmp(ST(waiting_for), "the first command") && SN(waiting_s) == 30.5);
    ENSURE(!strcmp(ST(waiting_got), "") && SN(commands_wrong_port) == 31);
    ENSURE(SN(error_estimate) == 31.5 && !strcmp(ST(error_joint), "q2"));
    ENSURE(SN(error_budget) == 33.5 && SN(error_warnings) == 34);

    ENSURE(isnan(SN(no_such_field)) && isnan(SN(mode)) && ST(no_such_field) == NULL &&
           ST(rtf) == NULL);
    ENSURE(lag_client_status_fields() >= 39 &&
           !strcmp(lag_client_status_field_name(0), "utime") &&
           lag_client_status_field_name(lag_client_status_fields()) == NULL);
#undef SN
#undef ST
    lag_client_status_free(ss);

    /* commands */
    const char *names[2] = {"q1", "q2"};
    double eff[2] = {1.5, -2.25};
    ENSURE(lag_client_send_command(c, 3.0, 2, names, eff) == LAG_CLIENT_OK);
    pump(peer, c, 100);
    ENSURE(commands == 1 && last_cmd.sim_time == 3.0 && last_cmd.num_joints == 2);
    ENSURE(strcmp(last_cmd.name[1], "q2") == 0 && last_cmd.effort[0] == 1.5 &&
           last_cmd.effort[1] == -2.25);
    ENSURE(lag_client_send_command(c, 3.0, -1, names, eff) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_send_command(c, 3.0, 2, NULL, eff) == LAG_CLIENT_ERR_ARG);
    /* never a NaN on the bus; never a name the daemon could not read */
    double enan[2] = {1.0, NAN}, einf[2] = {INFINITY, 0};
    ENSURE(lag_client_send_command(c, 3.0, 2, names, enan) == LAG_CLIENT_ERR_ARG);
    ENSURE(strstr(lag_client_errmsg(c), "NaN") != NULL);
    ENSURE(lag_client_send_command(c, 3.0, 2, names, einf) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_send_command(c, NAN, 2, names, eff) == LAG_CLIENT_ERR_ARG);
    const char *longnames[1] = {longname};
    ENSURE(lag_client_send_command(c, 3.0, 1, longnames, eff) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_step(c, 0) == LAG_CLIENT_ERR_ARG);
    ENSURE(strstr(lag_client_errmsg(c), "count") != NULL);
    ENSURE(lag_client_reset_to(c, 0, eff, eff) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_reset_to(c, 2, enan, eff) == LAG_CLIENT_ERR_ARG);
    pump(peer, c, 100);
    ENSURE(commands == 1); /* none of the refused ones went out */
    lag_client_get_counters(c, &cnt, sizeof cnt);
    ENSURE(cnt.commands_sent == 1);
    double q2[2] = {0.25, -0.5}, qd2[2] = {1.0, 2.0};
    ENSURE(lag_client_reset_to(c, 2, q2, qd2) == LAG_CLIENT_OK);
    /* until it is heard, 3 s at most (a loaded machine under ASan took over 100 ms) */
    for (int k = 0; k < 30 && last_ctl.request != LAGSIM_CONTROL_T_RESET_TO; k++) pump(peer, c, 100);
    ENSURE(last_ctl.request == LAGSIM_CONTROL_T_RESET_TO && last_ctl.num_joints == 2);
    ENSURE(last_ctl.q[1] == -0.5 && last_ctl.qd[0] == 1.0);
    ENSURE(lag_client_step(c, 7) == LAG_CLIENT_OK);
    pump(peer, c, 100);
    ENSURE(last_ctl.request == LAGSIM_CONTROL_T_STEP && last_ctl.count == 7);
    ENSURE(lag_client_pause(c) == LAG_CLIENT_OK && lag_client_resume(c) == LAG_CLIENT_OK);

    /* Each state once (the law runs once per state): a copy of the latest state (the same
     * utime, step and sim_time: the daemon re-sends a state in lockstep until an answer
     * arrives) is not returned; once a command answered the state, a copy gets that very
     * command again, at once. */
    snprintf(ch, sizeof ch, "%s_STATE", prefix);
    publish_state(peer, ch, 3, NULL, 4.0, 0.1);
    ENSURE(lag_client_wait_state(c, 2.0, &st, sizeof st) == LAG_CLIENT_OK && st.sim_time == 4.0);
    publish_state(peer, ch, 3, NULL, 4.0, 0.1); /* a copy before the answer */
    ENSURE(lag_client_wait_state(c, 0.3, &st, sizeof st) == LAG_CLIENT_TIMEOUT);
    int before = commands;
    ENSURE(lag_client_send_command(c, 4.0, 2, names, eff) == LAG_CLIENT_OK);
    pump(peer, c, 100);
    ENSURE(commands == before + 1 && last_cmd.sim_time == 4.0);
    int64_t utime_answer = last_cmd.utime;
    publish_state(peer, ch, 3, NULL, 4.0, 0.1); /* a copy after it: answered again */
    pump(peer, c, 100);
    ENSURE(lag_client_wait_state(c, 0.1, &st, sizeof st) == LAG_CLIENT_TIMEOUT);
    ENSURE(commands == before + 2 && last_cmd.sim_time == 4.0 && last_cmd.utime == utime_answer &&
           last_cmd.effort[1] == -2.25);
    lag_client_get_counters(c, &cnt, sizeof cnt);
    ENSURE(cnt.copies == 2 && cnt.repeats == 1 && cnt.commands_sent == 2);
    /* the same state published again with a new utime (a paused real-time plant, a
     * lockstep plant waiting at its start): a copy too, the law not run again for it */
    g_utime = 43;
    publish_state(peer, ch, 3, NULL, 4.0, 0.1);
    pump(peer, c, 100);
    ENSURE(lag_client_wait_state(c, 0.1, &st, sizeof st) == LAG_CLIENT_TIMEOUT);
    ENSURE(commands == before + 3 && last_cmd.utime == utime_answer);
    lag_client_get_counters(c, &cnt, sizeof cnt);
    ENSURE(cnt.copies == 3 && cnt.repeats == 2 && cnt.commands_sent == 2);
    g_utime = 42;
    publish_state(peer, ch, 3, NULL, 4.01, 0.1); /* the next state: returned */
    ENSURE(lag_client_wait_state(c, 2.0, &st, sizeof st) == LAG_CLIENT_OK && st.sim_time == 4.01);

    /* lag_client_feed: the same path as the bus; another channel is refused */
    ENSURE(lag_client_feed(c, "OTHER_STATE", junk, sizeof junk) == LAG_CLIENT_ERR_ARG);
    snprintf(ch, sizeof ch, "%s_EVENT", prefix);
    lag_client_get_counters(c, &cnt, sizeof cnt);
    ENSURE(lag_client_feed(c, ch, junk, sizeof junk) == LAG_CLIENT_OK);
    lag_client_counters cnt2;
    lag_client_get_counters(c, &cnt2, sizeof cnt2);
    ENSURE(cnt2.dropped == cnt.dropped + 1 && cnt2.events == cnt.events);

    /* a scene description */
    publish_scene(peer, prefix, 0, 0.5);
    ENSURE(lag_client_wait_scene(c, 2.0, sc) == LAG_CLIENT_OK);
    ENSURE(strcmp(lag_client_scene_prefix(sc), prefix) == 0 &&
           lag_client_scene_num_params(sc) == 3 && lag_client_scene_num_joints(sc) == 2);
    ENSURE(strcmp(lag_client_scene_model(sc), "manipulator") == 0 &&
           strcmp(lag_client_scene_mode(sc), "lockstep") == 0);
    ENSURE(lag_client_scene_param(sc, "g") == 9.81 && isnan(lag_client_scene_param(sc, "zz")));
    ENSURE(lag_client_scene_joint(sc, "q2") == 1 && lag_client_scene_actuated(sc, 0) &&
           !lag_client_scene_actuated(sc, 1));
    ENSURE(lag_client_scene_initial_q(sc, 1) == 0.5 && lag_client_scene_control_period(sc) == 0.01);
    /* out of range: NULL, NaN, false, -1 */
    ENSURE(lag_client_scene_joint_name(sc, 2) == NULL && lag_client_scene_param_name(sc, -1) == NULL);
    ENSURE(isnan(lag_client_scene_initial_q(sc, 8)) && !lag_client_scene_actuated(sc, -1));
    ENSURE(lag_client_scene_joint(sc, "q9") == -1 && lag_client_scene_joint(sc, NULL) == -1);
    lag_client_scene *copy = lag_client_scene_new();
    lag_client_scene_copy(copy, sc);
    ENSURE(copy && !strcmp(lag_client_scene_model(copy), "manipulator") &&
           lag_client_scene_param_value(copy, 2) == lag_client_scene_param_value(sc, 2));
    lag_client_scene_free(copy);
    lag_client_scene_free(sc);

    pump(peer, c, 100);
    ENSURE(controls > 0 && commands > 0 && on_state_url == 0); /* each on its own port */

    lag_client_destroy(c);
    lcm_destroy(peer);
    lcm_destroy(peer_in);
}

/* A state is known by its generation (one more at every reset and SET) and its step and
 * sim time: a state of the next run at the same step, sim time and utime as the one
 * answered last is no copy of it. A state whose generation is not the scene's is held,
 * not returned, until the scene of its generation came; meanwhile the client asks for it
 * (DESCRIBE, at once and every LAG_CLIENT_DESCRIBE_S). Commands carry the generation of
 * the state they answer. */
static void case_generation(int arg)
{
    (void)arg;
    char prefix[64], ch[128], err[256];
    snprintf(prefix, sizeof prefix, "CLTGEN_%d", (int)getpid());
    lag_client *c = lag_client_create(NULL, prefix, err, sizeof err);
    lag_bus bus;
    ENSURE(c && lag_bus_init(&bus, NULL, prefix, err, sizeof err) == 0);
    lcm_t *peer = lcm_create(bus.state_url);
    peer_in = lcm_create(bus.command_url);
    ENSURE(peer != NULL && peer_in != NULL);
    lcm_subscribe(peer_in, bus.channel[LAG_BUS_CONTROL], on_control, NULL);
    lcm_subscribe(peer_in, bus.channel[LAG_BUS_COMMAND], on_command, NULL);
    snprintf(ch, sizeof ch, "%s_STATE", prefix);
    const char *names[1] = {"q1"};
    double u1 = 1.5, u2 = -2.5;
    lag_client_state st;
    lag_client_scene *sc = lag_client_scene_new();
    lag_client_counters cnt;

    /* generation 1: the scene, then its state, returned */
    publish_scene(peer, prefix, 1, 0.5);
    g_gen = 1;
    publish_state(peer, ch, 2, NULL, 0.0, 0.1);
    ENSURE(lag_client_wait_state(c, 2.0, &st, sizeof st) == LAG_CLIENT_OK && st.generation == 1);
    ENSURE(lag_client_latest_scene(c, sc) && lag_client_scene_generation(sc) == 1);
    ENSURE(lag_client_send_command(c, 0.0, 1, names, &u1) == LAG_CLIENT_OK);
    pump(peer, c, 100);
    ENSUREF(last_cmd.generation == 1 && last_cmd.sim_time == 0.0 && last_cmd.effort[0] == 1.5,
            "the command carries generation %lld", (long long)last_cmd.generation);
    int cmds = commands, asked = describes;

    /* generation 2, the same step, sim time and utime, its scene lost: no copy (no answer
     * sent again), held, its scene asked for */
    g_gen = 2;
    publish_state(peer, ch, 2, NULL, 0.0, 0.1);
    ENSURE(lag_client_wait_state(c, 0.6, &st, sizeof st) == LAG_CLIENT_TIMEOUT);
    pump(peer, c, 50);
    lag_client_get_counters(c, &cnt, sizeof cnt);
    ENSUREF(commands == cmds && cnt.repeats == 0 && cnt.held == 1,
            "a state of the next generation taken for a copy: %d answers sent again, %lld "
            "repeats, %lld held", commands - cmds, (long long)cnt.repeats, (long long)cnt.held);
    ENSUREF(describes >= asked + 2 && cnt.describes >= 2,
            "%d DESCRIBE while the scene of generation 2 was awaited", describes - asked);
    /* still the last returned */
    ENSURE(lag_client_latest_state(c, &st, sizeof st) && st.generation == 1);
    /* its scene: the held state is returned, with the new scene */
    publish_scene(peer, prefix, 2, 1.25);
    ENSURE(lag_client_wait_state(c, 2.0, &st, sizeof st) == LAG_CLIENT_OK && st.generation == 2);
    ENSURE(lag_client_latest_scene(c, sc) && lag_client_scene_generation(sc) == 2 &&
           lag_client_scene_param(sc, "m2") == 1.25);
    ENSURE(lag_client_send_command(c, 0.0, 1, names, &u2) == LAG_CLIENT_OK);
    pump(peer, c, 100);
    ENSURE(last_cmd.generation == 2 && last_cmd.effort[0] == -2.5);
    /* a copy of it (same generation): answered again with that command, not returned */
    cmds = commands;
    publish_state(peer, ch, 2, NULL, 0.0, 0.1);
    pump(peer, c, 100);
    ENSURE(lag_client_wait_state(c, 0.1, &st, sizeof st) == LAG_CLIENT_TIMEOUT);
    lag_client_get_counters(c, &cnt, sizeof cnt);
    ENSURE(commands == cmds + 1 && last_cmd.generation == 2 && last_cmd.effort[0] == -2.5 &&
           cnt.repeats == 1);

    /* generation 3 with its scene first (as the daemon sends them): returned at once, no
     * DESCRIBE */
    asked = describes;
    publish_scene(peer, prefix, 3, 0.75);
    g_gen = 3;
    publish_state(peer, ch, 2, NULL, 0.0, 0.1);
    ENSURE(lag_client_wait_state(c, 2.0, &st, sizeof st) == LAG_CLIENT_OK && st.generation == 3);
    pump(peer, c, 300);
    ENSURE(describes == asked);
    ENSURE(lag_client_latest_scene(c, sc) && lag_client_scene_param(sc, "m2") == 0.75);
    lag_client_scene_free(sc);
    g_gen = 0;
    lag_client_destroy(c);
    lcm_destroy(peer);
    lcm_destroy(peer_in);
}

static void *instead_in_thread(void *arg)
{
    char *out = arg;
    /* memq://: this process's own bus, where nobody is */
    return (void *)(intptr_t)lag_client_plants_instead("memq://", "NOBODY", 0.05, out, 512);
}

static void case_small_stack(int arg)
{
    (void)arg;
    pthread_attr_t a;
    ENSURE(pthread_attr_init(&a) == 0);
    ENSURE(pthread_attr_setstacksize(&a, 256 * 1024) == 0);
    static char out[512];
    pthread_t t;
    void *n = (void *)(intptr_t)-1;
    ENSURE(pthread_create(&t, &a, instead_in_thread, out) == 0);
    ENSURE(pthread_join(t, &n) == 0);
    pthread_attr_destroy(&a);
    ENSUREF((intptr_t)n == 0 && strstr(out, "no plant heard on memq://"), "%d: %s",
            (int)(intptr_t)n, out);
}

/* lag_client_locate's answers without a directory, and its refusals (a host's directory
 * itself: clients_<language>_host_prefix). memq:// as the default bus: this process's own,
 * where nobody is. */
static void case_locate(int arg)
{
    (void)arg;
    char url[LAG_CLIENT_URL_LEN], err[256];
    ENSURE(setenv("LCM_DEFAULT_URL", "memq://", 1) == 0);
    double t0 = lag_client_now();
    int where = lag_client_locate("ALICE", 0.1, url, sizeof url, err, sizeof err);
    /* nothing heard: err says what was waited for, where and how long (a program prints
     * it: a busy host can miss the window) */
    ENSUREF(where == LAG_CLIENT_LOCATE_NONE && !strcmp(url, "memq://") &&
                strstr(err, "prefix ALICE") && strstr(err, "on memq://") &&
                strstr(err, "within 0.1 s") && strstr(err, "no host's directory named it"),
            "%d %s %s", where, url, err);
    ENSURE(lag_client_now() - t0 >= 0.1); /* the whole wait: nothing decided it */
    static const char *const bad[] = {"", "A-B", "A.*", "ALICE_STATE|BOB",
                                      "P123456789012345678901234567890123456789012345678901234"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        where = lag_client_locate(bad[k], 0.1, url, sizeof url, err, sizeof err);
        ENSUREF(where == LAG_CLIENT_ERR_ARG && strstr(err, "prefix") && !url[0], "'%s': %d %s",
                bad[k], where, err);
    }
    ENSURE(lag_client_locate(NULL, 0.1, url, sizeof url, NULL, 0) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_locate("ALICE", NAN, url, sizeof url, NULL, 0) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_locate("ALICE", -1.0, url, sizeof url, NULL, 0) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_locate("ALICE", 0.0, NULL, 0, NULL, 0) == LAG_CLIENT_ERR_ARG);
    char small[4];
    where = lag_client_locate("ALICE", 0.0, small, sizeof small, err, sizeof err);
    ENSUREF(where == LAG_CLIENT_ERR_ARG && !small[0] && strstr(err, "too short"), "%d %s",
            where, err);
    ENSURE(setenv("LCM_DEFAULT_URL", "tcpq://nowhere", 1) == 0);
    where = lag_client_locate("ALICE", 0.0, url, sizeof url, err, sizeof err);
    ENSUREF(where == LAG_CLIENT_ERR_ARG && strstr(err, "LCM_DEFAULT_URL"), "%d %s", where, err);
    ENSURE(unsetenv("LCM_DEFAULT_URL") == 0);
}

/* lcm_subscribe, wrapped: while g_burst_at > 0, the g_burst_at-th subscription to a
 * channel of g_burst_prefix is followed at once by the daemon's first burst (its scene,
 * the reference at t = 0, the state at t = 0) on the subscribing lcm_t. Otherwise LCM's. */
static const char *g_burst_prefix;
static int g_burst_at, g_burst_seen;
static lcm_t *g_burst_lcm;
#define BURST_GEN 7

static void publish_reference(lcm_t *lcm, const char *prefix, double t)
{
    char ch[128];
    snprintf(ch, sizeof ch, "%s_REFERENCE", prefix);
    char *names[1] = {"q1"};
    double r[1] = {0.25}, rd[1] = {0.5}, rdd[1] = {0.0};
    lagsim_reference_t m = {.utime = 1, .sim_time = t, .step = (int64_t)(t * 1000),
                            .num_joints = 1, .name = names, .r = r, .rdot = rd,
                            .generation = BURST_GEN, .rddot = rdd};
    lagsim_reference_t_publish(lcm, ch, &m);
}

static void publish_burst(lcm_t *lcm, const char *prefix)
{
    char ch[128];
    snprintf(ch, sizeof ch, "%s_STATE", prefix);
    publish_scene(lcm, prefix, BURST_GEN, 1.0);
    publish_reference(lcm, prefix, 0.0);
    publish_state(lcm, ch, 2, NULL, 0.0, 0.1);
}

lcm_subscription_t *lcm_subscribe(lcm_t *lcm, const char *channel, lcm_msg_handler_t handler,
                                  void *userdata)
{
    typedef lcm_subscription_t *(*subscribe_fn)(lcm_t *, const char *, lcm_msg_handler_t,
                                                void *);
    static subscribe_fn real;
    if (!real) {
        void *sym = dlsym(RTLD_NEXT, "lcm_subscribe");
        if (!sym) abort(); /* no LCM to wrap: nothing of this program can run */
        memcpy(&real, &sym, sizeof real);
    }
    lcm_subscription_t *sub = real(lcm, channel, handler, userdata);
    if (sub && g_burst_at > 0 && strstr(channel, g_burst_prefix) &&
        ++g_burst_seen == g_burst_at) {
        g_burst_lcm = lcm;
        publish_burst(lcm, g_burst_prefix);
    }
    return sub;
}

static void case_first_burst(int arg)
{
    (void)arg;
    char err[256];
    int kept = 0, moments = 0;
    g_gen = BURST_GEN;
    for (int at = 1;; at++) {
        g_burst_prefix = "BURST";
        g_burst_at = at;
        g_burst_seen = 0;
        g_burst_lcm = NULL;
        lag_client *c = lag_client_create("memq://", g_burst_prefix, err, sizeof err);
        ENSUREF(c != NULL, "%s", err);
        if (!c) break;
        int subscriptions = g_burst_seen;
        g_burst_at = 0;
        if (!g_burst_lcm) { /* after the last subscription: every moment was tried */
            lag_client_destroy(c);
            break;
        }
        moments++;
        /* what was kept, then the scene again (the daemon's answer to DESCRIBE) */
        while (lag_client_handle(c, 0) == LAG_CLIENT_OK) {}
        publish_scene(g_burst_lcm, g_burst_prefix, BURST_GEN, 1.0);
        while (lag_client_handle(c, 0) == LAG_CLIENT_OK) {}
        lag_client_state st;
        lag_client_reference ref;
        if (lag_client_wait_state(c, 0.0, &st, sizeof st) == LAG_CLIENT_OK) {
            kept++;
            ENSUREF(st.sim_time == 0.0 && st.generation == BURST_GEN, "%g %lld", st.sim_time,
                    (long long)st.generation);
            ENSUREF(lag_client_reference_of(c, &st, &ref, sizeof ref) && ref.r[0] == 0.25,
                    "the burst after subscription %d of %d: its state kept, its reference "
                    "not",
                    at, subscriptions);
        }
        lag_client_destroy(c);
    }
    /* the burst after the last subscription reaches every channel */
    ENSUREF(moments >= 5 && kept >= 1, "%d moments, %d states kept", moments, kept);
    g_gen = 0;
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"library", case_library, 0, 0},
                                    {"generation", case_generation, 0, 0},
                                    {"small_stack", case_small_stack, 0, 0},
                                    {"locate", case_locate, 0, 0},
                                    {"first_burst", case_first_burst, 0, 0}};
    return lt_main(argc, argv, cases, 5);
}
