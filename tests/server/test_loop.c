/*
 * The real-time server's loop with a made-up clock, on LCM's in-process memq:// provider:
 * no sockets, no sleeping, no dependence on the machine's load. The test plays the loop
 * (rt_next_wake, "sleep" by moving the clock, deliver messages, rt_process) and counts
 * every message the server publishes, decoding each and checking that no number in it is
 * NaN or Inf.
 *
 * Scenes are built in code, not loaded, so that settings a scene file would refuse
 * (rate 1e25, status_hz 1e-300, lockstep_timeout 1e300, a period of 1e12 ticks) reach the
 * server: it must stay bounded for any value.
 *
 *   test_loop CASE    CASE: pacing rate_huge status_hz lockstep_wait start set set_replay
 *                           long_period chunks
 *                           step_paced control_flood command_flood duration signals
 *                           fault_effort lockstep_retry lockstep_loss late_controller
 *                           other_plant
 *                           reject_names waits foreign copy_rule (--list)
 */
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <fcntl.h>
#include <string.h>
#include <unistd.h>
#include <lcm/eventlog.h>

#include "lagsim_test.h"
#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"

/* states a second of republication may publish: the state bucket's rate and burst
 * (realtime.c: RT_STATE_PER_S 20, RT_STATE_BURST 5) */
#define RT_TEST_STATE_BUCKET (20 + 5)
#define MS 1000000LL
#define SEC 1000000000LL

/* ---------------------------------------------------------------- what the server publishes */
#define MAX_KINDS 40
typedef struct outputs {
    int64_t state, status, event, scene;
    int nkinds;
    char kind[MAX_KINDS][32];
    int64_t kind_n[MAX_KINDS];
    char kind_detail[MAX_KINDS][320]; /* the last detail of each kind */
    double kind_value[MAX_KINDS];
    int64_t kind_suppressed[MAX_KINDS]; /* the sum of "(N more ... suppressed ...)" */
    bool nonfinite;
    double last_t;                    /* sim_time of the last state */
    int64_t last_step;
    int64_t last_gen, scene_gen;      /* the generation of the last state, of the last scene */
    int64_t state_before_scene;       /* states of a generation whose scene had not come */
    double last_q[LAG_MAX_DOF];
    int64_t status_controls_rejected, status_states, status_overrun_bursts, status_conflicts;
    int64_t status_err_warnings;
    double status_err_estimate, status_err_budget;
    char status_err_joint[16];
    char status_run[16];
    char status_waiting_for[256], status_waiting_got[256]; /* the last status's */
    double status_waiting_s;
    uint8_t scene_bytes[4096]; /* the last scene, as published */
    size_t scene_len;
} outputs;

static outputs g_out;
static bool g_junk_scenes; /* scenes that do not decode are the test's own */

/* A lockstep controller played by the test (lockstep_retry, lockstep_loss): it answers
 * every state it receives (duplicates included) with u = -K x, and a deterministic
 * generator loses a share of the states on their way to it and of its commands on their
 * way to the server. Every state it receives is recorded by step. */
#define CTL_MAX_STEPS 4096
typedef struct controller {
    bool on;
    double loss;                  /* each way */
    uint64_t rng;
    int64_t received, lost_states, sent, lost_commands;
    int64_t steps;                /* distinct steps received */
    bool have[CTL_MAX_STEPS];
    double x[CTL_MAX_STEPS][2 * LAG_MAX_DOF];
    int64_t last_step;
    int64_t end_step;             /* states from this step on are not answered (0: all) */
} controller;
static controller g_ctl;
static void command(double sim_time, const char *joint, double effort);
static void command_gen(int64_t gen, double sim_time, const char *joint, double effort);

static bool ctl_lose(void)
{
    g_ctl.rng = g_ctl.rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(g_ctl.rng >> 11) * 0x1p-53 < g_ctl.loss;
}

static void ctl_state(const lag_wire_joint_state *m)
{
    if (ctl_lose()) {
        g_ctl.lost_states++;
        return;
    }
    g_ctl.received++;
    int64_t k = m->step / 10; /* periods of 10 ticks */
    if (k >= 0 && k < CTL_MAX_STEPS) {
        double x[2 * LAG_MAX_DOF] = {0};
        for (int i = 0; i < m->num_joints; i++) {
            x[i] = m->position[i];
            x[LAG_MAX_DOF + i] = m->velocity[i];
        }
        if (g_ctl.have[k] && memcmp(g_ctl.x[k], x, sizeof x) != 0)
            LT_FAIL("step %lld received twice with different values", (long long)m->step);
        if (!g_ctl.have[k]) g_ctl.steps++;
        g_ctl.have[k] = true;
        memcpy(g_ctl.x[k], x, sizeof x);
    }
    g_ctl.last_step = m->step;
    if (g_ctl.end_step > 0 && m->step >= g_ctl.end_step) return; /* the run is over */
    /* a balancing law of the DIPC, from the state alone */
    double u = 1.67 * m->position[0] - 396.4 * m->position[1] + 448.4 * m->position[2] +
               6.17 * m->velocity[0] - 16.3 * m->velocity[1] + 68.4 * m->velocity[2];
    if (ctl_lose()) {
        g_ctl.lost_commands++;
        return;
    }
    g_ctl.sent++;
    command(m->sim_time, "theta0", -u);
}

static bool finite_all(const double *x, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i])) return false;
    return true;
}

static int kind_index(const char *kind)
{
    for (int i = 0; i < g_out.nkinds; i++)
        if (!strcmp(g_out.kind[i], kind)) return i;
    if (g_out.nkinds == MAX_KINDS) LT_FAIL("too many event kinds");
    snprintf(g_out.kind[g_out.nkinds], 32, "%s", kind);
    return g_out.nkinds++;
}

static int64_t n_events(const char *kind)
{
    for (int i = 0; i < g_out.nkinds; i++)
        if (!strcmp(g_out.kind[i], kind)) return g_out.kind_n[i];
    return 0;
}

static int64_t n_suppressed(const char *kind)
{
    for (int i = 0; i < g_out.nkinds; i++)
        if (!strcmp(g_out.kind[i], kind)) return g_out.kind_suppressed[i];
    return 0;
}

static const char *last_detail(const char *kind)
{
    for (int i = 0; i < g_out.nkinds; i++)
        if (!strcmp(g_out.kind[i], kind)) return g_out.kind_detail[i];
    return "";
}

static const char *suffix(const char *ch)
{
    const char *u = strrchr(ch, '_');
    return u ? u + 1 : ch;
}

/* Every message the server publishes (memq delivers them to this subscription). */
/* A recorder of the bus, as lcm-logger records it (every message published, in order):
 * g_rec[0] all of it, g_rec[1] all but the `set` events. */
static lcm_eventlog_t *g_rec[2];
static int64_t g_rec_n;

static void record(const lcm_recv_buf_t *rb, const char *ch, bool is_set)
{
    for (int k = 0; k < 2; k++) {
        if (!g_rec[k] || (k == 1 && is_set)) continue;
        lcm_eventlog_event_t ev = {.eventnum = 0, .timestamp = g_rec_n, .channellen = (int32_t)strlen(ch),
                                   .datalen = (int32_t)rb->data_size, .channel = (char *)ch,
                                   .data = rb->data};
        if (lcm_eventlog_write_event(g_rec[k], &ev) != 0) LT_FAIL("cannot write the log");
    }
    g_rec_n++;
}

static void on_any(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)user;
    const char *sfx = suffix(ch);
    bool is_set = false;
    if (!strcmp(sfx, "EVENT")) {
        lag_wire_event m;
        is_set = lag_wire_decode_event(rb->data, rb->data_size, &m) == LAG_WIRE_OK &&
                 !strcmp(m.kind, "set");
    }
    record(rb, ch, is_set);
    if (!strcmp(sfx, "STATE")) {
        lag_wire_joint_state m;
        if (lag_wire_decode_joint_state(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK) LT_FAIL("bad state");
        g_out.state++;
        if (!isfinite(m.sim_time) || !finite_all(m.position, m.num_joints) ||
            !finite_all(m.velocity, m.num_joints) || !finite_all(m.effort, m.num_joints))
            g_out.nonfinite = true;
        g_out.last_t = m.sim_time;
        g_out.last_step = m.step;
        g_out.last_gen = m.generation;
        if (m.generation != g_out.scene_gen) g_out.state_before_scene++;
        for (int i = 0; i < m.num_joints && i < LAG_MAX_DOF; i++) g_out.last_q[i] = m.position[i];
        if (g_ctl.on) ctl_state(&m);
    } else if (!strcmp(sfx, "STATUS")) {
        lag_wire_status m;
        if (lag_wire_decode_status(rb->data, rb->data_size, &m) != LAG_WIRE_OK) LT_FAIL("bad status");
        g_out.status++;
        double d[] = {m.sim_time, m.wall_time, m.rtf, m.step_time_max_us, m.step_time_mean_us, m.energy};
        if (!finite_all(d, 6)) g_out.nonfinite = true;
        g_out.status_controls_rejected = m.controls_rejected;
        g_out.status_states = m.states_published;
        g_out.status_overrun_bursts = m.overrun_bursts;
        g_out.status_conflicts = m.plant_conflicts;
        if (!isfinite(m.error_estimate) || !isfinite(m.error_budget)) g_out.nonfinite = true;
        g_out.status_err_warnings = m.error_warnings;
        g_out.status_err_estimate = m.error_estimate;
        g_out.status_err_budget = m.error_budget;
        snprintf(g_out.status_err_joint, sizeof g_out.status_err_joint, "%.15s", m.error_joint);
        snprintf(g_out.status_run, sizeof g_out.status_run, "%.15s", m.run_state);
        snprintf(g_out.status_waiting_for, sizeof g_out.status_waiting_for, "%s", m.waiting_for);
        snprintf(g_out.status_waiting_got, sizeof g_out.status_waiting_got, "%s", m.waiting_got);
        g_out.status_waiting_s = m.waiting_s;
    } else if (!strcmp(sfx, "EVENT")) {
        lag_wire_event m;
        if (lag_wire_decode_event(rb->data, rb->data_size, &m) != LAG_WIRE_OK) LT_FAIL("bad event");
        g_out.event++;
        if (!isfinite(m.sim_time) || !isfinite(m.value)) g_out.nonfinite = true;
        int k = kind_index(m.kind);
        g_out.kind_n[k]++;
        g_out.kind_value[k] = m.value;
        snprintf(g_out.kind_detail[k], sizeof g_out.kind_detail[k], "%s", m.detail);
        const char *sup = strstr(m.detail, " more ");
        if (sup && strstr(sup, "suppressed")) {
            const char *p = sup;
            while (p > m.detail && p[-1] >= '0' && p[-1] <= '9') p--;
            g_out.kind_suppressed[k] += strtoll(p, NULL, 10);
        }
    } else if (!strcmp(sfx, "SCENE")) {
        lag_wire_scene m;
        if (lag_wire_decode_scene(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK) {
            if (g_junk_scenes) return; /* other_plant sends some */
            LT_FAIL("bad scene");
        }
        if (strcmp(m.prefix, "TL") != 0) return; /* another prefix's (other_plant) */
        g_out.scene++;
        g_out.scene_gen = m.generation;
        if (rb->data_size <= sizeof g_out.scene_bytes) {
            memcpy(g_out.scene_bytes, rb->data, rb->data_size);
            g_out.scene_len = rb->data_size;
        }
    }
}


/* ---------------------------------------------------------------- the server under test */
static rt_server g_srv;
static lcm_t *g_lcm;
static lag_scene g_sc;
static lagsimd_opts g_opts;
static int64_t g_wakeups;

static void drain(void)
{
    while (lcm_handle_timeout(g_lcm, 0) > 0) {
    }
}

/* A DIPC scene (dt 1 ms, 100 Hz, realtime) to be changed by the case before start(). */
static void scene(lag_rt_mode mode)
{
    lag_scene_default(&g_sc, LAG_MODEL_DIPC);
    g_sc.sim.q0[1] = 0.1;
    g_sc.sim.q0[2] = -0.05;
    g_sc.realtime.mode = mode;
    snprintf(g_sc.lcm.prefix, sizeof g_sc.lcm.prefix, "TL");
    memset(&g_opts, 0, sizeof g_opts);
    g_opts.quiet = true;
}

static int try_start(int64_t t0)
{
    char err[512];
    memset(&g_out, 0, sizeof g_out);
    g_wakeups = 0;
    int rc = rt_open(&g_srv, &g_sc, &g_opts, t0, true, err, sizeof err);
    if (rc != 0) return rc;
    ENSUREF(rt_attach(&g_srv, g_lcm, g_lcm, err, sizeof err) == 0, "%s", err);
    rt_begin(&g_srv);
    drain();
    return 0;
}

static void start(void) { ENSURE(try_start(1 * SEC) == 0); }

static void stop_server(void)
{
    rt_finish(&g_srv);
    rt_close(&g_srv);
    drain();
    ENSURE(!g_out.nonfinite);
}

/* Plays the loop until the clock reaches `until`: each wake-up costs `cost` ns; the loop
 * sleeps until rt_next_wake. */
static void run_until(int64_t until, int64_t cost)
{
    rt_server *s = &g_srv;
    while (!s->stop && s->now < until) {
        int64_t wake = rt_next_wake(s);
        int64_t now = s->now + cost;
        if (wake > now) now = wake;
        if (now > until) {
            s->now = until;
            break;
        }
        s->now = now;
        drain();            /* messages sent to the server are handled here, at s->now */
        rt_process(s);
        drain();
        g_wakeups++;
        if (g_wakeups > 50000000) LT_FAIL("the loop does not get anywhere");
    }
}

static void control(int req, int64_t count)
{
    uint8_t buf[256];
    lagsim_control_t m = {0, (int8_t)req, count, 0, NULL, NULL, "", ""};
    int n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0);
    rt_handle_control(&g_srv, buf, (size_t)n);
}

static void command(double sim_time, const char *joint, double effort)
{
    uint8_t buf[256];
    char *names[1] = {(char *)joint};
    /* answers the state of the current generation */
    lagsim_joint_command_t m = {0, sim_time, 1, names, &effort, g_srv.pub.generation};
    int n = lagsim_joint_command_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0);
    rt_handle_command(&g_srv, buf, (size_t)n);
}

/* ---------------------------------------------------------------- cases */
/* Realtime at 100 Hz: one state per 10 ms deadline exactly, no overrun, sim time = wall
 * time; a wake-up 25 ms late (deadline at T + 10 ms, woken at T + 35 ms) makes three
 * periods due, two of which started late. */
static void case_pacing(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    start();
    const int64_t t0 = g_srv.now;
    run_until(t0 + 10 * SEC, 0);
    ENSUREF(g_srv.sim.tick == 10000, "tick %lld", (long long)g_srv.sim.tick);
    ENSURE(g_out.state == 1 + 1000 && g_srv.overruns == 0 && g_srv.overrun_bursts == 0);
    ENSURE(g_out.last_t == 10.0);
    /* statuses at 5 Hz: 50 plus the first */
    ENSUREF(g_out.status == 51, "%lld statuses", (long long)g_out.status);
    /* the stall */
    g_srv.now = rt_pace_next(&g_srv.pace) + 25 * MS;
    rt_process(&g_srv);
    drain();
    ENSURE(g_srv.overruns == 2 && g_srv.sim.tick == 10030);
    run_until(t0 + 11 * SEC, 0);
    ENSURE(g_srv.sim.tick == 11000 && g_srv.overruns == 2);
    stop_server();
}

/* A rate so high that a period lasts nanoseconds (1e25: 1e-27 s; 1e6: 10 ns) runs as fast
 * as the loop goes (here: 0.4 ms per wake-up), and sim time advances; the clock re-bases
 * again and again, but overrun_burst events stay within their bucket (3, then 1/s). */
static void case_rate_huge(int arg)
{
    (void)arg;
    const double rates[] = {1e25, 1e20, 1e6, 1e300};
    for (size_t i = 0; i < sizeof rates / sizeof rates[0]; i++) {
        scene(LAG_RT_REALTIME);
        g_sc.realtime.rate = rates[i];
        start();
        run_until(g_srv.now + 2 * SEC, 400000);
        ENSUREF(g_out.last_t > 10.0, "rate %g: sim time %g after 2 s", rates[i], g_out.last_t);
        ENSURE(g_srv.overrun_bursts > 1000);
        ENSUREF(n_events("overrun_burst") <= 3 + 2, "rate %g: %lld overrun_burst events",
                rates[i], (long long)n_events("overrun_burst"));
        ENSURE(g_out.status <= 1 + 10 + 1);
        stop_server();
        printf("rate %g: sim time %.1f s in 2 s, %lld re-bases, %lld overrun_burst events\n",
               rates[i], g_out.last_t, (long long)g_srv.overrun_bursts,
               (long long)n_events("overrun_burst"));
    }
}

/* status_hz 1e-300: no periodic status (the first one only); 1e9: at most 100 per second. */
static void case_status_hz(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    g_sc.realtime.status_hz = 1e-300;
    start();
    run_until(g_srv.now + 10 * SEC, 10000);
    ENSUREF(g_out.status == 1, "%lld statuses", (long long)g_out.status);
    ENSURE(g_out.state == 1001);
    stop_server();
    scene(LAG_RT_FAST);
    g_sc.realtime.status_hz = 1e9;
    start();
    run_until(g_srv.now + 1 * SEC, 100000);
    ENSUREF(g_out.status <= 1 + 100, "%lld statuses", (long long)g_out.status);
    ENSURE(g_out.status >= 90);
    stop_server();
}

/* A scene built in code meets the scene's rules as a loaded one does: rt_open refuses each
 * bad real-time value with the rule's text, naming the key (lag_scene_check), and a prefix
 * too long with the very text the loader gives for it in a file. */
static void case_scene_rules(int arg)
{
    (void)arg;
    static const struct {
        const char *key, *rule;
        double v;
    } bad[] = {
        {"publish_hz", "expected > 0 and finite, 1/publish_hz a whole number of ticks", -1},
        {"publish_hz", "expected > 0 and finite, 1/publish_hz a whole number of ticks", NAN},
        {"realtime.rate", "expected > 0 and finite (sim s per wall s), got 0", 0},
        {"realtime.rate", "expected > 0 and finite (sim s per wall s), got inf", INFINITY},
        {"realtime.status_hz", "expected > 0 and finite (Hz), got -5", -5},
        {"realtime.lockstep_retry", "expected >= 0 and finite (wall s), got -0.5", -0.5},
        {"realtime.lockstep_timeout", "expected >= 0 and finite (wall s), got inf", INFINITY},
        {"realtime.command_timeout", "expected >= 0 (sim s; inf: never), got -1", -1},
        {"realtime.command_timeout", "expected >= 0 (sim s; inf: never), got nan", NAN},
    };
    char err[512], want[256];
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        scene(LAG_RT_REALTIME);
        const char *k = bad[i].key;
        double *at = !strcmp(k, "publish_hz")            ? &g_sc.publish_hz
                   : !strcmp(k, "realtime.rate")         ? &g_sc.realtime.rate
                   : !strcmp(k, "realtime.status_hz")    ? &g_sc.realtime.status_hz
                   : !strcmp(k, "realtime.lockstep_retry") ? &g_sc.realtime.lockstep_retry
                   : !strcmp(k, "realtime.lockstep_timeout") ? &g_sc.realtime.lockstep_timeout
                                                         : &g_sc.realtime.command_timeout;
        *at = bad[i].v;
        ENSURE(rt_open(&g_srv, &g_sc, &g_opts, 1 * SEC, true, err, sizeof err) ==
               LAGSIMD_EXIT_USAGE);
        snprintf(want, sizeof want, "bad scene: %s: %s", k, bad[i].rule);
        ENSUREF(strstr(err, want), "%s = %g: \"%s\", expected \"%s\"", k, bad[i].v, err, want);
    }
    /* a period of no tick (ticks_per_period 0), and of more than 2^53 ticks */
    static const int64_t ticks[] = {0, (1LL << 53) + 1};
    for (int i = 0; i < 2; i++) {
        scene(LAG_RT_REALTIME);
        g_sc.ticks_per_period = ticks[i];
        ENSURE(rt_open(&g_srv, &g_sc, &g_opts, 1 * SEC, true, err, sizeof err) ==
               LAGSIMD_EXIT_USAGE);
        ENSUREF(strstr(err, "bad scene: publish_hz: expected > 0 and finite, 1/publish_hz a "
                            "whole number of ticks (1 to 2^53)"), "%s", err);
    }
    /* lcm.prefix: empty, and 54 characters, in code and in a file */
    const char *rule = "lcm.prefix: expected a channel prefix of 1 to 53 characters, got ";
    scene(LAG_RT_REALTIME);
    g_sc.lcm.prefix[0] = '\0';
    ENSURE(rt_open(&g_srv, &g_sc, &g_opts, 1 * SEC, true, err, sizeof err) == LAGSIMD_EXIT_USAGE);
    snprintf(want, sizeof want, "bad scene: %s0 ", rule);
    ENSUREF(strstr(err, want), "\"%s\", expected \"%s\"", err, want);
    char p54[55];
    memset(p54, 'P', 54);
    p54[54] = '\0';
    scene(LAG_RT_REALTIME);
    snprintf(g_sc.lcm.prefix, sizeof g_sc.lcm.prefix, "%s", p54);
    ENSURE(rt_open(&g_srv, &g_sc, &g_opts, 1 * SEC, true, err, sizeof err) == LAGSIMD_EXIT_USAGE);
    const char *tail = strstr(err, rule);
    ENSUREF(tail && !strncmp(err, "bad scene: ", 11), "%s", err);
    char yaml[256], lerr[512];
    snprintf(yaml, sizeof yaml, "model: dipc\nlcm:\n  prefix: %s\n", p54);
    static lag_scene loaded;
    ENSURE(lag_scene_load_buffer("rules.yaml", yaml, strlen(yaml), NULL, 0, &loaded, lerr,
                                 sizeof lerr) != LAG_OK);
    ENSUREF(strstr(lerr, tail), "the loader: \"%s\"; rt_open: \"%s\"", lerr, tail);
}

/* lockstep_timeout 1e10 or 1e300 s: the wait is (practically) for ever; no timeout event,
 * no period, and the loop sleeps (a wake-up per status). lockstep_timeout 0: the first
 * wait times out at once, then the server waits without stepping (it never steps without
 * an answer), republishing the state within the state bucket, and does not spin. */
static void case_lockstep_wait(int arg)
{
    (void)arg;
    const double waits[] = {1e10, 1e300, 9e9};
    for (size_t i = 0; i < sizeof waits / sizeof waits[0]; i++) {
        scene(LAG_RT_LOCKSTEP);
        g_sc.realtime.lockstep_timeout = waits[i];
        g_sc.realtime.lockstep_retry = waits[i]; /* the wait alone (retries: lockstep_retry) */
        start();
        run_until(g_srv.now + 10 * SEC, 10000);
        ENSURE(g_srv.sim.tick == 0 && g_srv.lockstep_timeouts == 0);
        ENSURE(n_events("lockstep_timeout") == 0 && g_out.state == 1);
        ENSUREF(g_wakeups <= 60, "%lld wake-ups in 10 s", (long long)g_wakeups);
        /* answered: it steps */
        command(0.0, "theta0", 0.5);
        run_until(g_srv.now + 1 * MS, 10000);
        ENSURE(g_srv.sim.tick == 10 && g_out.state == 2);
        stop_server();
    }
    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.lockstep_timeout = 0.0;
    start();
    run_until(g_srv.now + 1 * SEC, 100000);
    ENSUREF(g_srv.lockstep_timeouts == 1 && g_srv.sim.tick == 0 && g_srv.run == RT_WAITING,
            "%lld timeouts, tick %lld", (long long)g_srv.lockstep_timeouts,
            (long long)g_srv.sim.tick);
    ENSUREF(n_events("lockstep_timeout") == 1, "%lld events", (long long)n_events("lockstep_timeout"));
    ENSUREF(g_out.state >= 2 && g_out.state <= 1 + RT_TEST_STATE_BUCKET,
            "%lld states in 1 s", (long long)g_out.state);
    ENSUREF(g_wakeups <= 200, "%lld wake-ups in 1 s", (long long)g_wakeups);
    command(0.0, "theta0", 0.5); /* an answer: one period, then (timeout 0) waiting again */
    run_until(g_srv.now + 1 * MS, 10000);
    ENSUREF(g_srv.sim.tick == 10 && n_events("resume") == 1 && g_srv.lockstep_timeouts == 2,
            "tick %lld, %lld resume events, %lld timeouts", (long long)g_srv.sim.tick,
            (long long)n_events("resume"), (long long)g_srv.lockstep_timeouts);
    stop_server();
}

/* realtime.start, in each mode:
 *  - first_command (realtime, fast): the state at t = 0 is published every period while
 *    nothing advances (run_state waiting) however long; the first valid command starts the
 *    run, its deadlines counted from that moment (realtime: 50 periods in the next 0.5 s);
 *  - paused: the same, but a command does not start it; RESUME does;
 *  - first_command (lockstep): no lockstep_timeout however long the wait, the state
 *    republished every lockstep_timeout; the first answer starts the run;
 *  - running: the former behaviour (realtime: 100 periods in 1 s). */
static void case_start(int arg)
{
    (void)arg;
    const lag_rt_mode modes[] = {LAG_RT_REALTIME, LAG_RT_FAST};
    for (int i = 0; i < 2; i++) {
        scene(modes[i]);
        g_sc.realtime.start = LAG_RT_START_FIRST_COMMAND;
        start();
        run_until(g_srv.now + 3 * SEC, 1000);
        ENSUREF(g_srv.sim.tick == 0 && g_srv.run == RT_WAITING && g_out.last_t == 0.0,
                "%s: tick %lld, run %d", lag_rt_mode_name(modes[i]), (long long)g_srv.sim.tick,
                g_srv.run);
        ENSUREF(g_out.state >= 250 && g_out.state <= 302, "%s: %lld states while waiting 3 s",
                lag_rt_mode_name(modes[i]), (long long)g_out.state);
        ENSURE(strcmp(g_out.status_run, "waiting") == 0 && n_events("resume") == 0);
        command(0.0, "theta0", 0.25);
        ENSURE(g_srv.run == RT_RUNNING && n_events("resume") == 0); /* the event goes out below */
        /* fast: a period per wake-up of 1 us, so 1 ms is plenty */
        run_until(g_srv.now + (modes[i] == LAG_RT_REALTIME ? SEC / 2 + MS : MS), 1000);
        ENSURE(n_events("resume") == 1 && strstr(last_detail("resume"), "a command arrived"));
        if (modes[i] == LAG_RT_REALTIME)
            ENSUREF(g_srv.sim.tick == 500, "realtime: tick %lld 0.5 s after the first command",
                    (long long)g_srv.sim.tick);
        else
            ENSURE(g_srv.sim.tick >= 500);
        stop_server();
    }

    scene(LAG_RT_REALTIME);
    g_sc.realtime.start = LAG_RT_START_PAUSED;
    start();
    run_until(g_srv.now + 1 * SEC, 1000);
    command(0.0, "theta0", 0.25);
    run_until(g_srv.now + 1 * SEC, 1000);
    ENSURE(g_srv.sim.tick == 0 && g_srv.run == RT_PAUSED && strcmp(g_out.status_run, "paused") == 0);
    control(LAGSIM_CONTROL_T_RESUME, 0);
    run_until(g_srv.now + SEC / 2 + MS, 1000);
    ENSUREF(g_srv.sim.tick == 500 && g_srv.run == RT_RUNNING, "tick %lld after resume",
            (long long)g_srv.sim.tick);
    stop_server();

    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.start = LAG_RT_START_FIRST_COMMAND;
    g_sc.realtime.lockstep_timeout = 0.5;
    start();
    run_until(g_srv.now + 10 * SEC, 1000);
    ENSUREF(g_srv.sim.tick == 0 && g_srv.lockstep_timeouts == 0 && n_events("lockstep_timeout") == 0,
            "lockstep: tick %lld, %lld timeouts", (long long)g_srv.sim.tick,
            (long long)g_srv.lockstep_timeouts);
    ENSUREF(g_out.state >= 19 && g_out.state <= 21, "lockstep: %lld states in 10 s of waiting",
            (long long)g_out.state);
    ENSUREF(g_wakeups <= 200, "lockstep: %lld wake-ups in 10 s", (long long)g_wakeups);
    command(0.0, "theta0", 0.25);
    run_until(g_srv.now + 1 * MS, 1000);
    ENSURE(g_srv.sim.tick == 10 && g_srv.run == RT_RUNNING && g_out.last_t == 0.01);
    stop_server();

    scene(LAG_RT_REALTIME);
    ENSURE(g_sc.realtime.start == LAG_RT_START_RUNNING);
    start();
    run_until(g_srv.now + 1 * SEC, 1000);
    ENSURE(g_srv.sim.tick == 1000 && g_srv.run == RT_RUNNING);
    stop_server();
}

/* RESET and RESET_TO with count bit 2 (LAG_WIRE_RESET_WAIT): back to waiting for the first
 * command, as realtime.start: first_command, from running, paused and the fault state, in
 * each mode: nothing advances however long (the state at t = 0 republished: realtime 250
 * to 302 states in 3 s as at the start; lockstep no lockstep_timeout), the first command
 * starts the run, realtime deadlines counted from it (500 periods in the next 0.5 s).
 * Counts with other bits (4, -1; 1 on RESET_TO) are refused and reset nothing. */
static void reset_wait_from(lag_rt_mode mode, rt_run from)
{
    scene(mode);
    g_sc.realtime.effort_limit[0] = INFINITY;
    g_sc.realtime.lockstep_timeout = 0.5;
    start();
    for (int k = 0; k < 20; k++) { /* lockstep: every state answered */
        command(g_out.last_t, "theta0", from == RT_FAULT && k == 19 ? 1e308 : 0.25);
        run_until(g_srv.now + 10 * MS, 1000);
    }
    if (from == RT_PAUSED) control(LAGSIM_CONTROL_T_PAUSE, 0);
    run_until(g_srv.now + 1 * MS, 1000);
    ENSUREF(g_srv.run == from && g_srv.sim.tick > 0, "%s: run %d, tick %lld",
            lag_rt_mode_name(mode), g_srv.run, (long long)g_srv.sim.tick);
    int64_t resets = n_events("reset"), timeouts = n_events("lockstep_timeout");
    control(LAGSIM_CONTROL_T_RESET, LAG_WIRE_RESET_SCENE | LAG_WIRE_RESET_WAIT);
    ENSUREF(g_srv.run == RT_WAITING && g_srv.sim.tick == 0, "%s from %s: run %d",
            lag_rt_mode_name(mode), rt_run_name(from), g_srv.run);
    drain();
    int64_t states = g_out.state;
    run_until(g_srv.now + 3 * SEC, 1000);
    ENSUREF(g_srv.sim.tick == 0 && g_srv.run == RT_WAITING && g_out.last_t == 0.0 &&
                strcmp(g_out.status_run, "waiting") == 0,
            "%s from %s: tick %lld, run %d 3 s after the reset", lag_rt_mode_name(mode),
            rt_run_name(from), (long long)g_srv.sim.tick, g_srv.run);
    ENSURE(n_events("reset") == resets + 1 &&
           strstr(last_detail("reset"), "waiting for the first command"));
    if (mode == LAG_RT_LOCKSTEP)
        ENSUREF(n_events("lockstep_timeout") == timeouts && g_out.state - states >= 5,
                "lockstep: %lld timeouts, %lld states while waiting",
                (long long)(n_events("lockstep_timeout") - timeouts),
                (long long)(g_out.state - states));
    else if (mode == LAG_RT_REALTIME)
        ENSUREF(g_out.state - states >= 250 && g_out.state - states <= 302,
                "%lld states while waiting 3 s", (long long)(g_out.state - states));
    command(0.0, "theta0", 0.25);
    ENSURE(g_srv.run == RT_RUNNING);
    run_until(g_srv.now + (mode == LAG_RT_FAST ? MS : SEC / 2 + MS), 1000);
    if (mode == LAG_RT_REALTIME)
        ENSUREF(g_srv.sim.tick == 500, "realtime: tick %lld 0.5 s after the first command",
                (long long)g_srv.sim.tick);
    else
        ENSUREF(g_srv.sim.tick >= 10, "%s: tick %lld after the first command",
                lag_rt_mode_name(mode), (long long)g_srv.sim.tick);
    stop_server();
}

static void case_reset_wait(int arg)
{
    (void)arg;
    const lag_rt_mode modes[] = {LAG_RT_REALTIME, LAG_RT_FAST, LAG_RT_LOCKSTEP};
    const rt_run from[] = {RT_RUNNING, RT_PAUSED, RT_FAULT};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) reset_wait_from(modes[i], from[j]);

    /* a reset without the bit keeps the run state; other bits are refused */
    scene(LAG_RT_REALTIME);
    start();
    run_until(g_srv.now + SEC / 2, 1000);
    int64_t tick = g_srv.sim.tick, rejected = g_srv.ctl.controls_rejected;
    const int64_t bad[] = {4, -1, 8, 7, INT64_MIN};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        control(LAGSIM_CONTROL_T_RESET, bad[k]);
        drain();
        ENSUREF(strstr(last_detail("control_rejected"), "reset: count ") &&
                    strstr(last_detail("control_rejected"), "accepted: 0, 1 (the scene file's "
                                                             "values too), 2 (then wait for "
                                                             "the first command) or 3 (both)"),
                "count %lld: '%s'", (long long)bad[k], last_detail("control_rejected"));
    }
    uint8_t buf[512];
    double q[3] = {0, 0.1, 0}, qd[3] = {0, 0, 0};
    lagsim_control_t m = {0, LAGSIM_CONTROL_T_RESET_TO, LAG_WIRE_RESET_SCENE, 3, q, qd, "", ""};
    int n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0);
    rt_handle_control(&g_srv, buf, (size_t)n);
    drain();
    ENSUREF(strstr(last_detail("control_rejected"), "reset_to: count 1; accepted: 0 or 2 "
                                                    "(then wait for the first command)"),
            "'%s'", last_detail("control_rejected"));
    ENSUREF(g_srv.sim.tick == tick && g_srv.run == RT_RUNNING && n_events("reset") == 0 &&
                g_srv.ctl.controls_rejected == rejected + 6,
            "tick %lld (was %lld), %lld resets", (long long)g_srv.sim.tick, (long long)tick,
            (long long)n_events("reset"));
    m.count = LAG_WIRE_RESET_WAIT;
    n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
    rt_handle_control(&g_srv, buf, (size_t)n);
    ENSURE(g_srv.run == RT_WAITING && g_srv.sim.tick == 0 && g_srv.sim.q[1] == 0.1);
    control(LAGSIM_CONTROL_T_RESUME, 0);
    control(LAGSIM_CONTROL_T_RESET, 0);
    ENSURE(g_srv.run == RT_RUNNING);
    stop_server();
}

/* A control request SET key=value, as lagsimctl sends it. */
static void set_request(const char *key, const char *value)
{
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    m.request = LAGSIM_CONTROL_T_SET;
    snprintf(m.key, sizeof m.key, "%s", key);
    snprintf(m.value, sizeof m.value, "%s", value);
    uint8_t buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode_control(&m, buf, sizeof buf);
    ENSURE(n > 0);
    rt_handle_control(&g_srv, buf, (size_t)n);
}

/* Changes while running (control_t SET) on a manipulator scene given as text, paused, run
 * by STEP in fast mode:
 *  - parameters.m2 = 1.25 after 500 ticks: the `set` event's detail is exactly
 *    "parameters.m2=1.25", the scene is published again, and the next 500 ticks equal, bit
 *    for bit, a fresh simulation of the scene loaded with --set parameters.m2=1.25 and
 *    started from the state at the change (no hidden state is carried over);
 *  - a value the loader refuses is refused with the loader's own message for the same
 *    --set on the same text, and nothing changes;
 *  - keys outside parameters and effects are refused; so is a stop that excludes where
 *    the joint is now (the core's check at the current state), though it includes the
 *    initial state;
 *  - an actuator lag the scene did not start with is refused, an actuator without one not;
 *  - a burst of 30 requests: 10 are validated, the rest refused (each is a scene parse). */
static void case_set(int arg)
{
    (void)arg;
    static const char text[] =
        "model: manipulator\n"
        "parameters: {m1: 2.0, m2: 0.5, l1: 0.3, I1: 0.02, I2: 0.05, g: 9.81}\n"
        "initial: {q: [0.3, 0.5], qd: [0, 0]}\n"
        "realtime: {mode: fast, start: paused}\n"
        "lcm: {prefix: TL}\n";
    char err[1024];
    ENSURE(lag_scene_load_buffer("set.yaml", text, sizeof text - 1, NULL, 0, &g_sc, err, sizeof err) == 0);
    memset(&g_opts, 0, sizeof g_opts);
    g_opts.quiet = true;
    g_opts.scene_name = "set.yaml";
    g_opts.scene_text = text;
    g_opts.scene_len = sizeof text - 1;
    start();
    control(LAGSIM_CONTROL_T_STEP, 50);
    run_until(g_srv.now + 10 * MS, 1000);
    ENSURE(g_srv.sim.tick == 500);
    double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
    memcpy(q, g_srv.sim.q, sizeof q);
    memcpy(qd, g_srv.sim.qd, sizeof qd);
    int64_t scenes = g_out.scene, sets;
    set_request("parameters.m2", "1.25");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("set") == 1 && !strcmp(last_detail("set"), "parameters.m2=1.25"),
            "%lld set events, detail '%s'", (long long)n_events("set"), last_detail("set"));
    ENSURE(g_out.scene == scenes + 1 && g_srv.sim.def.model.p[LAG_MANIP_M2] == 1.25);
    control(LAGSIM_CONTROL_T_STEP, 50);
    run_until(g_srv.now + 10 * MS, 1000);
    ENSURE(g_srv.sim.tick == 1000);
    /* the reference: the scene with the change, from the state at the change */
    static lag_scene ref_sc;
    const char *set1[] = {"parameters.m2=1.25"};
    ENSURE(lag_scene_load_buffer("set.yaml", text, sizeof text - 1, set1, 1, &ref_sc, err, sizeof err) == 0);
    static lag_sim ref;
    ENSURE(lag_sim_init(&ref, &ref_sc.sim, err, sizeof err) == LAG_OK);
    lag_sim_reset(&ref, q, qd);
    for (int k = 0; k < 50; k++) ENSURE(lag_sim_advance(&ref, 10, false) == LAG_OK);
    ENSUREF(!memcmp(ref.q, g_srv.sim.q, sizeof ref.q) && !memcmp(ref.qd, g_srv.sim.qd, sizeof ref.qd),
            "after the change: q1 %.17g vs %.17g", g_srv.sim.q[0], ref.q[0]);

    /* refused as the loader refuses it, with its message; nothing changes */
    const char *bad[] = {"parameters.m2=-1"};
    char lerr[1024], want[1200];
    ENSURE(lag_scene_load_buffer("set.yaml", text, sizeof text - 1, bad, 1, &ref_sc, lerr, sizeof lerr) != 0);
    /* the loader's reason, without its "--set parameters.m2: " (the answer names the change) */
    static const char own[] = "--set parameters.m2: ";
    ENSUREF(!strncmp(lerr, own, sizeof own - 1), "the loader says '%s'", lerr);
    snprintf(want, sizeof want, "set parameters.m2=-1: %s", lerr + sizeof own - 1);
    int64_t rejected = n_events("control_rejected");
    set_request("parameters.m2", "-1");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("control_rejected") == rejected + 1 && !strcmp(last_detail("control_rejected"), want),
            "refusal '%s', the loader says '%s'", last_detail("control_rejected"), want);
    ENSURE(g_srv.sim.def.model.p[LAG_MANIP_M2] == 1.25);

    /* outside parameters and effects */
    const char *keys[] = {"integrator.dt", "initial.q", "parametersx.m2", "effects_", "realtime.rate"};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        rejected = n_events("control_rejected");
        set_request(keys[i], "1");
        run_until(g_srv.now + 10 * MS, 1000);
        ENSUREF(n_events("control_rejected") == rejected + 1 &&
                    strstr(last_detail("control_rejected"), "only keys under parameters, effects and reference"),
                "%s: '%s'", keys[i], last_detail("control_rejected"));
    }
    /* a stop around the initial q2 = 0.5 that leaves out where q2 is now */
    ENSUREF(g_srv.sim.q[1] > 0.52 || g_srv.sim.q[1] < 0.48, "q2 = %g", g_srv.sim.q[1]);
    rejected = n_events("control_rejected");
    set_request("effects.limits", "{q2: {lower: 0.48, upper: 0.52}}");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("control_rejected") == rejected + 1 &&
                strstr(last_detail("control_rejected"), ": where the run is now, q2 = ") &&
                strstr(last_detail("control_rejected"), " is outside its limits [0.48, 0.52]"),
            "'%s'", last_detail("control_rejected"));
    ENSURE(!(g_srv.sim.def.effects.enabled & LAG_EFF_LIMITS));
    /* a stop around where q2 is now that leaves out the initial q2 = 0.5 (a reset would go
     * there): the loader's rule on the file's initial state, said without file:line:col */
    char stop[128];
    snprintf(stop, sizeof stop, "{q2: {lower: %.17g, upper: %.17g}}", g_srv.sim.q[1] - 0.01,
             g_srv.sim.q[1] + 0.01);
    rejected = n_events("control_rejected");
    set_request("effects.limits", stop);
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("control_rejected") == rejected + 1 &&
                strstr(last_detail("control_rejected"), ": with the rest of the scene: initial") &&
                !strstr(last_detail("control_rejected"), "set.yaml"),
            "'%s'", last_detail("control_rejected"));
    ENSURE(!(g_srv.sim.def.effects.enabled & LAG_EFF_LIMITS));
    /* an actuator lag the scene did not start with (a replay could not run it: the log
     * holds the commanded inputs only when the scene starts with a lag); an actuator
     * without a lag is a change like any other */
    rejected = n_events("control_rejected");
    set_request("effects.actuator", "{q1: {max: 5, lag: 0.05}}");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("control_rejected") == rejected + 1 &&
                strstr(last_detail("control_rejected"), "an actuator lag cannot be switched on"),
            "'%s'", last_detail("control_rejected"));
    ENSURE(!(g_srv.sim.def.effects.enabled & LAG_EFF_ACTUATOR));
    sets = n_events("set");
    set_request("effects.actuator", "{q1: {max: 5}}");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("set") == sets + 1 && (g_srv.sim.def.effects.enabled & LAG_EFF_ACTUATOR),
            "'%s'", last_detail("control_rejected"));

    /* a burst */
    sets = n_events("set");
    rejected = n_events("control_rejected");
    run_until(g_srv.now + 2 * SEC, 1000); /* the bucket fills up again */
    for (int k = 0; k < RT_SET_BURST + 20; k++)
        set_request("parameters.m1", k % 2 ? "2.5" : "2.0");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("set") - sets == RT_SET_BURST, "%lld of %d applied",
            (long long)(n_events("set") - sets), RT_SET_BURST + 20);
    ENSURE(g_srv.ctl.controls_rejected >= 20);
    ENSURE(g_srv.ctl.live.n == 3); /* m2, the actuator and m1: a key set again replaces itself */
    stop_server();
}

/* A command of generation gen answering the state at sim_time. */
static void command_gen(int64_t gen, double sim_time, const char *joint, double effort)
{
    uint8_t buf[256];
    char *names[1] = {(char *)joint};
    lagsim_joint_command_t m = {0, sim_time, 1, names, &effort, gen};
    int n = lagsim_joint_command_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0);
    rt_handle_command(&g_srv, buf, (size_t)n);
}

/* A state is known by its generation and its sim time. The generation is 1 at the start
 * and one more at every SET and reset; the scene of a new generation goes out before any
 * state of it; lockstep takes an answer only when both are those of the state waited on:
 * an answer of the generation before at the same sim time (a SET's, a reset's) is stale,
 * never applied, never a step. A 0.1.0 command is refused, saying to rebuild. */
static void case_generation(int arg)
{
    (void)arg;
    static const char text[] =
        "model: manipulator\n"
        "parameters: {m1: 2.0, m2: 0.5, l1: 0.3, I1: 0.02, I2: 0.05, g: 9.81}\n"
        "initial: {q: [0.3, 0.5], qd: [0, 0]}\n"
        "realtime: {mode: lockstep, start: paused, lockstep_timeout: 30}\n"
        "lcm: {prefix: TL}\n";
    char err[1024];
    ENSURE(lag_scene_load_buffer("gen.yaml", text, sizeof text - 1, NULL, 0, &g_sc, err,
                                 sizeof err) == 0);
    memset(&g_opts, 0, sizeof g_opts);
    g_opts.quiet = true;
    g_opts.scene_name = "gen.yaml";
    g_opts.scene_text = text;
    g_opts.scene_len = sizeof text - 1;
    start();
    ENSURE(g_srv.pub.generation == 1 && g_out.scene_gen == 1 && g_out.last_gen == 1);
    /* SET while the state at t = 0 is waited on: generation 2, its scene first, and the
     * state again in generation 2 */
    set_request("parameters.m2", "1.25");
    run_until(g_srv.now + 100 * MS, 1000);
    ENSUREF(g_srv.pub.generation == 2 && g_out.scene_gen == 2 && g_out.last_gen == 2 &&
                g_out.last_t == 0.0 && g_out.state_before_scene == 0,
            "generation %lld, scene %lld, state %lld at %g, %lld states before their scene",
            (long long)g_srv.pub.generation, (long long)g_out.scene_gen,
            (long long)g_out.last_gen, g_out.last_t, (long long)g_out.state_before_scene);
    /* an answer to the state of generation 1 at the same sim time: stale */
    int64_t stale = g_srv.rejected[RT_REJ_STALE];
    command_gen(1, 0.0, "q1", 9.0);
    control(LAGSIM_CONTROL_T_STEP, 1);
    run_until(g_srv.now + 300 * MS, 1000);
    ENSUREF(g_srv.rejected[RT_REJ_STALE] == stale + 1 && g_srv.sim.tick == 0 &&
                g_srv.held[0] == 0.0 && strstr(last_detail("command_rejected"), "generation 1"),
            "stale %lld, tick %lld, held %g: '%s'", (long long)(g_srv.rejected[RT_REJ_STALE] - stale),
            (long long)g_srv.sim.tick, g_srv.held[0], last_detail("command_rejected"));
    command_gen(2, 0.0, "q1", 0.5); /* the state's own: the period runs */
    run_until(g_srv.now + 300 * MS, 1000);
    ENSURE(g_srv.sim.tick == 10 && g_srv.held[0] == 0.5 && g_out.last_t == 0.01);
    command_gen(2, 0.01, "q1", 0.25); /* answers the paused state */
    run_until(g_srv.now + 50 * MS, 1000);
    /* RESET_TO: generation 3, sim time 0 again; the run before's answer to its own state
     * at sim time 0, late, is stale */
    double q[2] = {0.2, 0.4}, qd[2] = {0, 0};
    lagsim_control_t rm = {0, LAGSIM_CONTROL_T_RESET_TO, 0, 2, q, qd, "", ""};
    uint8_t buf[512];
    int n = lagsim_control_t_encode(buf, 0, sizeof buf, &rm);
    ENSURE(n > 0);
    rt_handle_control(&g_srv, buf, (size_t)n);
    run_until(g_srv.now + 100 * MS, 1000);
    ENSURE(g_srv.pub.generation == 3 && g_out.scene_gen == 3 && g_out.last_gen == 3 &&
           g_out.last_t == 0.0 && g_out.state_before_scene == 0);
    command_gen(2, 0.0, "q1", 9.0);
    control(LAGSIM_CONTROL_T_STEP, 1);
    run_until(g_srv.now + 300 * MS, 1000);
    ENSURE(g_srv.rejected[RT_REJ_STALE] == stale + 2 && g_srv.sim.tick == 0);
    command_gen(3, 0.0, "q1", 0.5);
    run_until(g_srv.now + 300 * MS, 1000);
    ENSURE(g_srv.sim.tick == 10 && g_srv.held[0] == 0.5);
    /* generation 0 answers no state: never a step in lockstep */
    command_gen(0, 0.01, "q1", 9.0);
    ENSURE(g_srv.rejected[RT_REJ_STALE] == stale + 3 && g_srv.held[0] == 0.5);
    /* a command of lagsim 0.1.0's types: refused, and the reason says to rebuild */
    lag_wire_joint_command jc;
    memset(&jc, 0, sizeof jc);
    jc.sim_time = 0.01;
    jc.num_joints = 1;
    snprintf(jc.name[0], sizeof jc.name[0], "q1");
    n = lag_wire_encode(LAG_WIRE_JOINT_COMMAND, &jc, buf, sizeof buf);
    int64_t fp;
    ENSURE(n > 8 && lag_wire_old_version(LAG_WIRE_JOINT_COMMAND, 0, NULL, &fp));
    for (int b = 0; b < 8; b++) buf[b] = (uint8_t)((uint64_t)fp >> (56 - 8 * b));
    int64_t undecodable = g_srv.rejected[RT_REJ_UNDECODABLE];
    rt_handle_command(&g_srv, buf, (size_t)n - 8); /* without the generation */
    run_until(g_srv.now + 300 * MS, 1000);
    ENSUREF(g_srv.rejected[RT_REJ_UNDECODABLE] == undecodable + 1 &&
                strstr(last_detail("command_rejected"), "built with lagsim 0.1.0's types and "
                       "must be rebuilt"),
            "'%s'", last_detail("command_rejected"));
    stop_server();
}

/* One period of 1e12 ticks (publish_hz 1e-9 at dt 1 ms, fast mode): each wake-up advances
 * at most tick_budget ticks, so a signal stops it after the wake-up it arrives in. */
/* lagsimd --replay on a log (as lcm-logger records the bus) at tolerance 0; returns its
 * exit status and the "max difference" it printed (-1 if none). */
static int replay(const lag_scene *sc, const char *path, double *diff)
{
    char out_path[128];
    snprintf(out_path, sizeof out_path, "/tmp/lagsim_test_loop_%d_replay.txt", (int)getpid());
    fflush(stdout);
    int saved = dup(1), fd = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ENSURE(saved >= 0 && fd >= 0);
    dup2(fd, 1);
    close(fd);
    int rc = lagsimd_replay(sc, path, &g_opts);
    fflush(stdout);
    dup2(saved, 1);
    close(saved);
    FILE *f = fopen(out_path, "r");
    ENSURE(f);
    char line[1024];
    *diff = -1;
    while (fgets(line, sizeof line, f)) {
        printf("  replay: %s", line);
        if (!strncmp(line, "max difference = ", 17)) *diff = strtod(line + 17, NULL);
    }
    fclose(f);
    remove(out_path);
    return rc;
}

/* Replay reproduces a run that changed parameters: a manipulator driven by commands, its
 * periods (100 ticks) longer than a wake-up's budget (30 ticks), changed while running:
 * parameters.m2 in the middle of a period, damping at a period's end, m1 just before a
 * reset (which keeps the changes). The
 * bus recorded as lcm-logger records it replays with difference exactly 0 (the `set`
 * events say what changed and at which step); the same log without its `set` events does
 * not (so the changes mattered and the check can fail). With rk4 and dopri5. */
static void case_set_replay(int arg)
{
    (void)arg;
    static const char text[] =
        "model: manipulator\n"
        "parameters: {m1: 2.0, m2: 0.5, l1: 0.3, I1: 0.02, I2: 0.05, g: 9.81}\n"
        "initial: {q: [0.3, 0.5], qd: [0, 0]}\n"
        "publish_hz: 10\n"
        "realtime: {mode: fast, command_timeout: 100}\n"
        "lcm: {prefix: TL}\n";
    static const char *const methods[] = {"integrator.method=rk4", "integrator.method=dopri5"};
    for (int mth = 0; mth < 2; mth++) {
        const char *sets[] = {methods[mth]};
        char err[1024], path[2][128];
        ENSURE(lag_scene_load_buffer("set.yaml", text, sizeof text - 1, sets, 1, &g_sc, err,
                                     sizeof err) == 0);
        memset(&g_opts, 0, sizeof g_opts);
        g_opts.quiet = true;
        g_opts.scene_name = "set.yaml";
        g_opts.scene_text = text;
        g_opts.scene_len = sizeof text - 1;
        g_opts.sets = sets;
        g_opts.nsets = 1;
        for (int k = 0; k < 2; k++) {
            snprintf(path[k], sizeof path[k], "/tmp/lagsim_test_loop_%d_%d.lcm", (int)getpid(), k);
            g_rec[k] = lcm_eventlog_create(path[k], "w");
            ENSURE(g_rec[k]);
        }
        start();
        g_srv.tick_budget = 30;
        command(0.0, "q1", 0.4);
        command(0.0, "q2", -0.2);
        /* into the third period, in its middle */
        while (g_srv.sim.tick < 230) run_until(g_srv.now + 1, 1);
        ENSUREF(g_srv.period_left > 0 && g_srv.sim.tick % 100 != 0, "tick %lld, %lld left",
                (long long)g_srv.sim.tick, (long long)g_srv.period_left);
        int64_t at = g_srv.sim.tick;
        set_request("parameters.m2", "1.25");
        drain();
        ENSUREF(n_events("set") == 1, "%s", last_detail("control_rejected"));
        while (g_srv.sim.tick < 600) run_until(g_srv.now + 1, 1);
        while (g_srv.period_left > 0) run_until(g_srv.now + 1, 1);
        ENSURE(g_srv.sim.tick % 100 == 0);
        set_request("effects.damping", "{q1: 0.5, q2: 2}");
        drain();
        ENSUREF(n_events("set") == 2, "%s", last_detail("control_rejected"));
        while (g_srv.sim.tick < 900) run_until(g_srv.now + 1, 1);
        while (g_srv.period_left > 0) run_until(g_srv.now + 1, 1);
        /* paused (so that the reset's state goes out before the next period: a fast run
         * goes on at once), a change, then at once a reset: the reset keeps the changes */
        control(LAGSIM_CONTROL_T_PAUSE, 0);
        set_request("parameters.m1", "3");
        control(LAGSIM_CONTROL_T_RESET, 0);
        drain();
        ENSUREF(n_events("set") == 3 && n_events("reset") == 1, "%s",
                last_detail("control_rejected"));
        run_until(g_srv.now + 100 * MS, 1);
        ENSUREF(g_out.last_step == 0, "the reset's state: step %lld", (long long)g_out.last_step);
        control(LAGSIM_CONTROL_T_RESUME, 0);
        command(0.0, "q1", -0.3);
        while (g_srv.sim.tick < 500) run_until(g_srv.now + 1, 1);
        stop_server();
        for (int k = 0; k < 2; k++) {
            lcm_eventlog_destroy(g_rec[k]);
            g_rec[k] = NULL;
        }
        printf("%s: changes at ticks %lld (mid-period), 600 and 900 (then a reset); %lld states\n", methods[mth],
               (long long)at, (long long)g_out.state);
        /* the replay starts from the scene as loaded, not as changed */
        ENSURE(lag_scene_load_buffer("set.yaml", text, sizeof text - 1, sets, 1, &g_sc, err,
                                     sizeof err) == 0);
        double d_all, d_none;
        int rc_all = replay(&g_sc, path[0], &d_all);
        ENSUREF(rc_all == 0 && d_all == 0.0, "%s: replay exit %d, difference %.17g",
                methods[mth], rc_all, d_all);
        (void)replay(&g_sc, path[1], &d_none);
        ENSUREF(d_none > 1e-6, "%s: without the set events the difference is %.17g",
                methods[mth], d_none);
        /* a change the replay cannot validate (no scene source): said, exit 1 */
        g_opts.scene_text = NULL;
        ENSURE(replay(&g_sc, path[0], &d_all) == LAGSIMD_EXIT_RUNTIME);
        remove(path[0]);
        remove(path[1]);
    }
}

static void case_long_period(int arg)
{
    (void)arg;
    scene(LAG_RT_FAST);
    g_sc.publish_hz = 1e-9;
    g_sc.ticks_per_period = 1000000000000LL;
    g_sc.sim.integrator.method = LAG_EULER;
    start();
    for (int k = 0; k < 10; k++) {
        ENSURE(rt_next_wake(&g_srv) <= g_srv.now); /* busy: no sleeping */
        g_srv.now += 1 * MS;
        rt_process(&g_srv);
        drain();
    }
    ENSURE(g_srv.sim.tick == 10 * g_srv.tick_budget && g_out.state == 1);
    rt_signal(&g_srv, SIGTERM);
    ENSURE(g_srv.stop);
    stop_server();
    ENSURE(n_events("stop") == 1 && strstr(last_detail("stop"), "SIGTERM"));
}

/* A period longer than the budget runs in chunks; the state at its end is bit-identical
 * to one call for the whole period, with every method: dopri5's chunks step across their
 * ends (dense output) and land on the period's end, as one call does (dopri5 twice: at the
 * scene's tolerances, and at rtol 1e-3, where it also rejects steps). */
static void case_chunks(int arg)
{
    (void)arg;
    const lag_method methods[] = {LAG_RK4, LAG_DOPRI5, LAG_GAUSS4, LAG_DOPRI5};
    for (size_t i = 0; i < sizeof methods / sizeof methods[0]; i++) {
        scene(LAG_RT_FAST);
        g_sc.sim.integrator.method = methods[i];
        if (i == 3) {
            g_sc.sim.integrator.rtol = 1e-3;
            g_sc.sim.integrator.atol = 1e-5;
        }
        g_sc.publish_hz = 5.0; /* 200 ticks, in chunks of 64, 64, 64 and 8 */
        g_sc.ticks_per_period = 200;
        g_sc.realtime.command_timeout = 1e9;
        start();
        g_srv.tick_budget = 64;
        static lag_sim ref;
        char err[256];
        ENSURE(lag_sim_init(&ref, &g_sc.sim, err, sizeof err) == LAG_OK);
        double tau[LAG_MAX_DOF] = {0.3};
        command(0.0, "theta0", 0.3);
        for (int p = 0; p < 3; p++) {
            lag_sim_set_input(&ref, tau);
            ENSURE(lag_sim_advance(&ref, 200, false) == LAG_OK);
        }
        while (g_out.state < 4) {
            g_srv.now += 1 * MS;
            rt_process(&g_srv);
            drain();
        }
        ENSURE(g_srv.sim.tick == 600 && ref.tick == 600);
        double worst = 0.0;
        for (int k = 0; k < 3; k++) {
            double dq = fabs(g_srv.sim.q[k] - ref.q[k]), dv = fabs(g_srv.sim.qd[k] - ref.qd[k]);
            worst = fmax(worst, fmax(dq, dv));
            ENSUREF(g_srv.sim.q[k] == ref.q[k] && g_srv.sim.qd[k] == ref.qd[k],
                    "%s joint %d: %.17g vs %.17g, %.17g vs %.17g", lag_method_name(methods[i]),
                    k, g_srv.sim.q[k], ref.q[k], g_srv.sim.qd[k], ref.qd[k]);
        }
        printf("%s (rtol %g): chunked period vs one call: largest difference %.3g\n",
               lag_method_name(methods[i]), g_sc.sim.integrator.rtol, worst);
        stop_server();
    }
}

/* STEP 2^62 while paused runs at the mode's pace: realtime, one period per deadline (100
 * in a second, not tens of thousands); lockstep, one per answer or timeout. */
static void case_step_paced(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    start();
    run_until(g_srv.now + 100 * MS, 0);
    control(LAGSIM_CONTROL_T_PAUSE, 0);
    run_until(g_srv.now + 100 * MS, 0);
    int64_t s0 = g_out.state, tick0 = g_srv.sim.tick;
    control(LAGSIM_CONTROL_T_STEP, (int64_t)1 << 62);
    run_until(g_srv.now + 1 * SEC, 0);
    ENSUREF(g_out.state - s0 == 100, "%lld states in a second", (long long)(g_out.state - s0));
    ENSURE(g_srv.sim.tick - tick0 == 1000);
    control(LAGSIM_CONTROL_T_PAUSE, 0);
    ENSURE(g_srv.pending_steps == 0);
    stop_server();

    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.lockstep_timeout = 0.05;
    start();
    control(LAGSIM_CONTROL_T_PAUSE, 0);
    run_until(g_srv.now + 100 * MS, 0);
    ENSURE(g_srv.sim.tick == 0);
    control(LAGSIM_CONTROL_T_STEP, (int64_t)1 << 62);
    run_until(g_srv.now + 1 * SEC, 0);
    ENSUREF(g_srv.sim.tick == 200, "lockstep: tick %lld after 1 s (a period per 50 ms wait)",
            (long long)g_srv.sim.tick);
    stop_server();
}

/* A flood on _CONTROL: 20 000 requests in a second, of every kind (undecodable, unknown,
 * STATUS, DESCRIBE, RESET, refused STEP), against at most a few hundred messages out. The
 * counters count everything; the next control_rejected event says how many were
 * suppressed. */
static void case_control_flood(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    start();
    run_until(g_srv.now + 100 * MS, 0);
    outputs before = g_out;
    const int64_t t_flood = g_srv.now, gen0 = g_srv.pub.generation;
    int bad = 0, resets = 0;
    for (int k = 0; k < 20000; k++) {
        switch (k % 6) {
        case 0: rt_handle_control(&g_srv, (const uint8_t *)"garbage", 7); bad++; break;
        case 1: control(99, 0); bad++; break;
        case 2: control(LAGSIM_CONTROL_T_STATUS, 0); break;
        case 3: control(LAGSIM_CONTROL_T_DESCRIBE, 0); break;
        case 4: control(LAGSIM_CONTROL_T_RESET, 0); resets++; break;
        case 5: control(LAGSIM_CONTROL_T_STEP, 5); bad++; break; /* refused: running */
        }
        if (k % 20 == 19) run_until(t_flood + (k + 1) * 50000, 0); /* 50 us a message */
    }
    run_until(t_flood + 1 * SEC, 0);
    int64_t ev = g_out.event - before.event, st = g_out.status - before.status,
            sc = g_out.scene - before.scene, sa = g_out.state - before.state;
    printf("control flood: 20000 requests in 1 s -> %lld events, %lld statuses, %lld scenes, "
           "%lld states\n", (long long)ev, (long long)st, (long long)sc, (long long)sa);
    /* each limited kind: its burst (10) + 10/s; statuses: burst 5 + 20/s + 5 periodic;
     * scenes: 2 + 5/s for DESCRIBE and one per reset applied (a new generation), which
     * RESET's bucket bounds; states: the 100 periods + resets' 5 + 20/s */
    const int64_t applied = g_srv.pub.generation - gen0;
    ENSUREF(applied >= RT_RESET_BURST && applied <= RT_RESET_BURST + RT_RESET_PER_S + 1,
            "%lld resets applied of %d", (long long)applied, resets);
    ENSURE(n_events("control_rejected") <= 20 && n_events("reset") <= 20);
    ENSURE(ev <= 40);
    ENSUREF(st <= 5 + 20 + 5 + 1 && sc <= 2 + 5 + applied + 1 && sa <= 100 + 5 + 20 + 1,
            "%lld statuses, %lld scenes, %lld states", (long long)st, (long long)sc,
            (long long)sa);
    /* every request refused is counted: the bad ones and the resets over their bucket */
    ENSURE(g_srv.ctl.controls_rejected == bad + (resets - applied));
    /* a while later one more: it says how many went unsaid since the last one, so that
     * the events published plus those they say were suppressed are every rejection */
    run_until(g_srv.now + 2 * SEC, 0);
    int64_t published = n_events("control_rejected");
    control(99, 0);
    drain();
    ENSURE(n_events("control_rejected") == published + 1);
    ENSUREF(strstr(last_detail("control_rejected"), "more control_rejected events suppressed"),
            "detail '%s'", last_detail("control_rejected"));
    const int64_t refused = bad + (resets - applied) + 1;
    ENSUREF(n_events("control_rejected") + n_suppressed("control_rejected") == refused,
            "%lld events + %lld suppressed, %lld rejected", (long long)n_events("control_rejected"),
            (long long)n_suppressed("control_rejected"), (long long)refused);
    run_until(g_srv.now + 100 * MS, 0);
    ENSURE(g_out.status_controls_rejected == refused);
    stop_server();
}

/* A flood on _COMMAND: rejections counted, their events limited. */
static void case_command_flood(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    start();
    for (int k = 0; k < 10000; k++) {
        command(0.0, k % 2 ? "bogus" : "theta1", 1.0);
        if (k % 10 == 9) run_until(g_srv.now + 100000, 0);
    }
    ENSURE(g_srv.rejected[RT_REJ_UNKNOWN_JOINT] == 5000 && g_srv.rejected[RT_REJ_UNACTUATED] == 5000);
    ENSUREF(n_events("command_rejected") <= 10 + 10 + 1, "%lld events",
            (long long)n_events("command_rejected"));
    stop_server();
}

/* --duration: 1e300 s or 1e16 s is refused (more ticks than a run counts exactly);
 * 0.5 s stops after the period that reaches it, the sim time before a reset counted. */
static void case_duration(int arg)
{
    (void)arg;
    scene(LAG_RT_FAST);
    g_opts.duration = 1e300;
    ENSURE(try_start(0) == LAGSIMD_EXIT_USAGE);
    g_opts.duration = 1e16;
    ENSURE(try_start(0) == LAGSIMD_EXIT_USAGE);
    g_opts.duration = 0.5;
    ENSURE(try_start(0) == 0);
    run_until(100 * SEC, 1000);
    ENSURE(g_srv.stop && g_srv.stop_reason == RT_STOP_DURATION && g_srv.sim.tick == 500);
    stop_server();
    ENSURE(n_events("stop") == 1 && !strcmp(last_detail("stop"), "duration reached"));
    /* the run's sim time counts, resets included: 0.3 s, a RESET, 0.1 s, a RESET_TO, and
     * the run of 0.5 s ends 0.1 s after it (realtime: the made-up clock paces it) */
    scene(LAG_RT_REALTIME);
    g_opts.duration = 0.5;
    ENSURE(try_start(0) == 0);
    run_until(g_srv.now + 300 * MS, 1000);
    int64_t t1 = g_srv.sim.tick;
    control(LAGSIM_CONTROL_T_RESET, 0);
    run_until(g_srv.now + 100 * MS, 1000);
    int64_t t2 = g_srv.sim.tick;
    uint8_t buf[256];
    double q[3] = {0, 0.05, 0}, qd[3] = {0};
    lagsim_control_t m = {0, LAGSIM_CONTROL_T_RESET_TO, 0, 3, q, qd, "", ""};
    int n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
    rt_handle_control(&g_srv, buf, (size_t)n);
    run_until(g_srv.now + 100 * SEC, 1000);
    ENSUREF(g_srv.stop && g_srv.stop_reason == RT_STOP_DURATION && t1 > 0 && t2 > 0 &&
                t1 + t2 + g_srv.sim.tick == 500,
            "stopped after %lld + %lld + %lld ticks (500 in all)", (long long)t1, (long long)t2,
            (long long)g_srv.sim.tick);
    stop_server();
}

/* Signals: SIGHUP, SIGQUIT, SIGINT and SIGTERM stop with a stop event naming the signal
 * and a final status; SIGUSR1 and SIGUSR2 ask for a status and stop nothing. */
static void case_signals(int arg)
{
    (void)arg;
    const int stops[] = {SIGHUP, SIGQUIT, SIGINT, SIGTERM};
    const char *names[] = {"SIGHUP", "SIGQUIT", "SIGINT", "SIGTERM"};
    for (int i = 0; i < 4; i++) {
        scene(LAG_RT_REALTIME);
        start();
        run_until(g_srv.now + 50 * MS, 0);
        int64_t st = g_out.status;
        rt_signal(&g_srv, SIGUSR1);
        rt_signal(&g_srv, SIGUSR2);
        ENSURE(!g_srv.stop);
        run_until(g_srv.now + 1 * MS, 0);
        ENSURE(g_out.status == st + 1);
        rt_signal(&g_srv, stops[i]);
        ENSURE(g_srv.stop);
        st = g_out.status;
        stop_server();
        ENSURE(g_out.status == st + 1 && n_events("stop") == 1);
        ENSUREF(strstr(last_detail("stop"), names[i]) && g_out.kind_value[kind_index("stop")] == stops[i],
                "stop event '%s'", last_detail("stop"));
    }
}

/* An effort of 1e308: refused whole by the scene's realtime.effort_limit (default 1e6),
 * counted, the state untouched. With the limit raised, it drives the state past
 * explode_limit: the fault event names the efforts that were held; nothing non-finite is
 * published. */
static void case_fault_effort(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    start();
    run_until(g_srv.now + 50 * MS, 0);
    command(0.0, "theta0", 1e308);
    command(0.0, "theta0", -2e6);
    run_until(g_srv.now + 200 * MS, 0);
    ENSURE(g_srv.run == RT_RUNNING && n_events("numeric_fault") == 0);
    ENSURE(g_srv.rejected[RT_REJ_EFFORT_LIMIT] == 2 && g_srv.accepted == 0 && g_srv.held[0] == 0.0);
    ENSUREF(strstr(last_detail("command_rejected"), "effort_limit"), "detail '%s'",
            last_detail("command_rejected"));
    command(0.0, "theta0", 1e6); /* at the limit: accepted */
    ENSURE(g_srv.accepted == 1 && g_srv.held[0] == 1e6);
    stop_server();

    scene(LAG_RT_REALTIME);
    g_sc.realtime.effort_limit[0] = INFINITY;
    start();
    run_until(g_srv.now + 50 * MS, 0);
    command(0.0, "theta0", 1e308);
    run_until(g_srv.now + 200 * MS, 0);
    ENSURE(g_srv.run == RT_FAULT && n_events("numeric_fault") == 1);
    ENSUREF(strstr(last_detail("numeric_fault"), "theta0 = 1e+308"), "detail '%s'",
            last_detail("numeric_fault"));
    printf("fault: %s\n", last_detail("numeric_fault"));
    stop_server();
}

/* Copies of the state waited on due within `span_ns` of its publication with a first
 * gap of `first` ns that doubles up to `cap` ns: the back-off rule, counted here by its
 * definition (docs/server.md), not by the daemon's code. */
static int64_t copies_within(int64_t span_ns, int64_t first, int64_t cap)
{
    int64_t n = 0, at = 0, gap = first;
    for (;;) {
        at += gap;
        if (at >= span_ns) return n;
        n++;
        gap = 2 * gap < cap ? 2 * gap : cap;
    }
}

/* Lockstep retries: a state not answered within lockstep_retry (20 ms) goes out again,
 * byte for byte, after gaps that double (20, 40, 80 ms, ...) up to a sixteenth of
 * lockstep_timeout; the wait (and lockstep_timeout) still counts from the first
 * publication. A second answer to the state is ignored and counted (commands_ignored),
 * with no event, whether it comes before the period ran or after; an answer to an older
 * state is still a stale rejection. Any answer to the state waited on, even one rejected,
 * ends its copies: the controller has it. */
static void case_lockstep_retry(int arg)
{
    (void)arg;
    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.start = LAG_RT_START_RUNNING;
    g_sc.realtime.lockstep_timeout = 1.0;
    g_sc.realtime.lockstep_retry = 0.02;
    start();
    const int64_t t0 = g_srv.now;
    ENSURE(g_out.state == 1 && g_srv.ls.waiting && !g_srv.ls.answered);
    uint8_t first[RT_BUF_SIZE];
    unsigned first_len = g_srv.pub.state_len;
    memcpy(first, g_srv.pub.state_buf, first_len);
    run_until(t0 + 110 * MS, 1000);
    /* copies at 20 and 60 ms (the next, at 140 ms, is not due) */
    ENSUREF(g_srv.pub.lockstep_retries == 2 && g_out.state == 3, "%lld retries, %lld states in 110 ms",
            (long long)g_srv.pub.lockstep_retries, (long long)g_out.state);
    ENSURE(g_srv.pub.state_len == first_len && memcmp(first, g_srv.pub.state_buf, first_len) == 0);
    ENSURE(g_srv.sim.tick == 0 && g_srv.lockstep_timeouts == 0 && g_out.last_step == 0);
    /* answered twice before the period runs: the second is ignored */
    command(0.0, "theta0", 0.5);
    command(0.0, "theta0", 9.0);
    ENSURE(g_srv.accepted == 1 && g_srv.commands_ignored == 1 && g_srv.held[0] == 0.5);
    run_until(g_srv.now + 1 * MS, 1000);
    ENSURE(g_srv.sim.tick == 10 && g_out.state == 4 && g_out.last_step == 10);
    /* a late copy of the answer to t = 0: ignored, counted, no event */
    command(0.0, "theta0", 9.0);
    ENSURE(g_srv.commands_ignored == 2 && g_srv.held[0] == 0.5);
    ENSURE(g_srv.rejected[RT_REJ_STALE] == 0 && n_events("command_rejected") == 0);
    /* an answer to a state that was never published: stale */
    command(0.5, "theta0", 9.0);
    ENSURE(g_srv.rejected[RT_REJ_STALE] == 1 && g_srv.held[0] == 0.5);
    /* no answer for a second: the backed-off copies (20, 60 ms, then every 62.5 ms),
     * then the timeout */
    int64_t r0 = g_srv.pub.lockstep_retries, want = copies_within(1000 * MS, 20 * MS, 62500000);
    run_until(g_srv.now + 1100 * MS, 1000);
    ENSUREF(g_srv.lockstep_timeouts == 1 && g_srv.run == RT_WAITING, "%lld timeouts",
            (long long)g_srv.lockstep_timeouts);
    ENSUREF(g_srv.pub.lockstep_retries - r0 == want && want == 17,
            "%lld retries before the timeout, %lld by the rule",
            (long long)(g_srv.pub.lockstep_retries - r0), (long long)want);
    /* the status says it */
    control(LAGSIM_CONTROL_T_STATUS, 0);
    run_until(g_srv.now + 1 * MS, 1000);
    stop_server();

    /* an answer that is rejected (a joint the model does not have) still tells the
     * daemon the controller has the state: no copy of it after that */
    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.start = LAG_RT_START_RUNNING;
    g_sc.realtime.lockstep_timeout = 1.0;
    g_sc.realtime.lockstep_retry = 0.02;
    start();
    run_until(g_srv.now + 30 * MS, 1000);
    ENSURE(g_srv.pub.lockstep_retries == 1);
    command(0.0, "cart", 1.0);
    ENSURE(g_srv.rejected[RT_REJ_UNKNOWN_JOINT] == 1 && !g_srv.ls.answered);
    run_until(g_srv.now + 900 * MS, 1000);
    ENSUREF(g_srv.pub.lockstep_retries == 1, "%lld copies after a rejected answer",
            (long long)g_srv.pub.lockstep_retries);
    stop_server();
}

/* A controller that starts after the state it is to answer went out: that state's copies
 * are far apart by then (they double up to lockstep_timeout / 16: 225 s for a lockstep_timeout
 * of 3600 s, lagsim-sweep's kept pairs'), so it would hear the state only at the next one.
 * Its DESCRIBE (every client asks for the scene until it has it) brings the scene and a
 * copy of the state owed, at the scene's pace; once an answer to that state was heard (even
 * a rejected one), the scene alone. Running, paused (the state a kept pair waits on
 * between runs) and waiting for the first command (lockstep's default start). */
static void case_late_controller(int arg)
{
    (void)arg;
    static const struct {
        lag_rt_start start;
        const char *name;
        int64_t states_in_21_s; /* the first, and its copies */
    } starts[] = {
        /* copies at 0.02 (2^k - 1) s: the 10th at 20.46 s, the 11th due at 40.94 s */
        {LAG_RT_START_RUNNING, "running", 11},
        {LAG_RT_START_PAUSED, "paused", 11},
        /* waiting for the first command: the state again every lockstep_timeout only */
        {LAG_RT_START_FIRST_COMMAND, "waiting", 1},
    };
    for (size_t i = 0; i < sizeof starts / sizeof starts[0]; i++) {
        const char *name = starts[i].name;
        scene(LAG_RT_LOCKSTEP);
        g_sc.realtime.start = starts[i].start;
        g_sc.realtime.lockstep_timeout = 3600.0;
        g_sc.realtime.lockstep_retry = 0.02;
        start();
        ENSURE(g_out.state == 1 && g_srv.ls.waiting && !g_srv.ls.answered);
        run_until(g_srv.now + 21 * SEC, 1000);
        ENSUREF(g_out.state == starts[i].states_in_21_s, "%s: %lld states in 21 s", name,
                (long long)g_out.state);
        int64_t states = g_out.state, scenes = g_out.scene;
        control(LAGSIM_CONTROL_T_DESCRIBE, 0);
        run_until(g_srv.now + 1 * MS, 1000);
        ENSUREF(g_out.scene == scenes + 1 && g_out.state == states + 1 && g_out.last_t == 0.0 &&
                    g_out.state_before_scene == 0,
                "%s: a DESCRIBE 21 s after the state at t = 0 brought %lld scenes and %lld "
                "states (1 and 1)", name, (long long)(g_out.scene - scenes),
                (long long)(g_out.state - states));
        /* a flood of DESCRIBEs (1000 a second): a copy with each scene, no more; the
         * scene's limit (a burst, then RT_SCENE_PER_S a second) sends at least its rate */
        run_until(g_srv.now + 1 * SEC, 1000);
        states = g_out.state, scenes = g_out.scene;
        for (int k = 0; k < 1000; k++) {
            control(LAGSIM_CONTROL_T_DESCRIBE, 0);
            run_until(g_srv.now + 1 * MS, 1000);
        }
        ENSUREF(g_out.scene - scenes >= RT_SCENE_PER_S &&
                    g_out.scene - scenes <= RT_SCENE_PER_S + RT_SCENE_BURST &&
                    g_out.state - states == g_out.scene - scenes,
                "%s: 1000 DESCRIBEs in 1 s: %lld scenes, %lld states", name,
                (long long)(g_out.scene - scenes), (long long)(g_out.state - states));
        ENSURE(g_srv.sim.tick == 0);
        /* an answer heard (rejected: a joint the DIPC does not have): the scene alone */
        command(0.0, "cart", 1.0);
        ENSURE(g_srv.ls.answer_heard && !g_srv.ls.answered);
        run_until(g_srv.now + 1 * SEC, 1000);
        states = g_out.state, scenes = g_out.scene;
        control(LAGSIM_CONTROL_T_DESCRIBE, 0);
        run_until(g_srv.now + 1 * MS, 1000);
        ENSUREF(g_out.scene == scenes + 1 && g_out.state == states,
                "%s: after an answer was heard a DESCRIBE brought %lld states (0)", name,
                (long long)(g_out.state - states));
        stop_server();
    }
}

/* A rejection names what would be accepted: the DIPC's joints with the actuated one
 * marked (theta0, the cart: its only input), the actuated joints alone, the effort limit,
 * the sim_time waited on, the requests by value, a count >= 1, the joint count. */
static void expect_detail(const char *kind, const char *want, int line)
{
    drain();
    ENSUREF(strstr(last_detail(kind), want), "(from line %d) %s detail '%s' lacks '%s'", line,
            kind, last_detail(kind), want);
    printf("%s: %s\n", kind, last_detail(kind));
}

static void case_reject_names(int arg)
{
    (void)arg;
    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.start = LAG_RT_START_RUNNING;
    g_sc.realtime.effort_limit[0] = 100;
    start();
    drain();
    command(0.0, "cart", 1.0);
    expect_detail("command_rejected", "unknown joint: 'cart'; joints of dipc: theta0 (actuated), "
                  "theta1, theta2", __LINE__);
    command(0.0, "theta1", 1.0);
    expect_detail("command_rejected", "'theta1' takes no input; actuated joints of dipc: theta0",
                  __LINE__);
    command(0.0, "theta0", 250.0);
    expect_detail("command_rejected", "250 for 'theta0' (in value); accepted: |effort| <= 100",
                  __LINE__);
    command(0.0, "theta0", NAN);
    expect_detail("command_rejected", "accepted: a finite effort within +-100", __LINE__);
    command(0.25, "theta0", 1.0);
    expect_detail("command_rejected", "sim_time 0.25 (in value); accepted: 0, the state waited on",
                  __LINE__);
    control(99, 0);
    expect_detail("control_rejected", "unknown request 99; accepted: PAUSE = 1, RESUME = 2, "
                  "STEP = 3, RESET = 4, RESET_TO = 5, STATUS = 6, DESCRIBE = 7, SET = 8", __LINE__);
    control(LAGSIM_CONTROL_T_PAUSE, 0);
    control(LAGSIM_CONTROL_T_STEP, 0);
    expect_detail("control_rejected", "step: count 0; accepted: a count >= 1", __LINE__);
    {
        uint8_t buf[256];
        double q[2] = {0, 0}, qd[2] = {0, 0};
        lagsim_control_t m = {0, LAGSIM_CONTROL_T_RESET_TO, 0, 2, q, qd, "", ""};
        int n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
        ENSURE(n > 0);
        rt_handle_control(&g_srv, buf, (size_t)n);
    }
    expect_detail("control_rejected", "reset_to: num_joints 2; accepted: 3, the joints of dipc in "
                  "this order: theta0 (actuated), theta1, theta2", __LINE__);
    stop_server();
}

/* No silent waits: the status says what the plant waits for, on which channel and URL,
 * how long it has waited and what came instead, for each wait: the first command, a
 * lockstep answer (after 1 s), paused, the fault state; nothing while it advances. */
static void status_now(void)
{
    control(LAGSIM_CONTROL_T_STATUS, 0);
    run_until(g_srv.now + 60 * MS, 1000);
}

static void expect_has(const char *str, const char *want, int line)
{
    ENSUREF(strstr(str, want), "(from line %d) '%s' lacks '%s'", line, str, want);
    if (strstr(str, want)) printf("ok: ... %s\n", want);
}

static void case_waits(int arg)
{
    (void)arg;
    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.start = LAG_RT_START_FIRST_COMMAND;
    g_sc.realtime.lockstep_timeout = 10.0;
    start();
    /* the command URL: the state URL's group on the next port (lagsim_bus.h, tested there) */
    char on_cmd[400];
    snprintf(on_cmd, sizeof on_cmd, "on TL_COMMAND at %s", g_srv.bus.urls.command_url);
    ENSURE(strstr(g_srv.bus.urls.command_url, ":7668"));
    run_until(g_srv.now + 2 * SEC, 1000);
    status_now();
    expect_has(g_out.status_waiting_for, "the first command (sim_time 0) ", __LINE__);
    expect_has(g_out.status_waiting_for, on_cmd, __LINE__);
    ENSUREF(g_out.status_waiting_s >= 2.0 && g_out.status_waiting_s < 2.5, "waited %g s",
            g_out.status_waiting_s);
    ENSURE(!strcmp(g_out.status_waiting_got, ""));
    /* what came instead: two rejections, an answer to another sim_time */
    command(0.0, "cart", 1.0);
    command(0.0, "theta1", 1.0);
    command(0.5, "theta0", 1.0);
    status_now();
    expect_has(g_out.status_waiting_got, "2 commands rejected (unknown joint 1, unactuated joint 1; "
               "the last: unactuated joint: 'theta1' takes no input; actuated joints of dipc: theta0)",
               __LINE__);
    expect_has(g_out.status_waiting_got, "; 1 answer to another sim_time", __LINE__);
    /* the answer: the run goes; a lockstep round trip of less than 1 s is not a wait */
    command(0.0, "theta0", 1.0);
    run_until(g_srv.now + 500 * MS, 1000);
    status_now();
    ENSUREF(!strcmp(g_out.status_waiting_for, "") && g_out.status_waiting_s == 0,
            "'%s' %g s", g_out.status_waiting_for, g_out.status_waiting_s);
    /* unanswered for more than a second: a wait, of its own age, with nothing else come */
    run_until(g_srv.now + 1500 * MS, 1000);
    status_now();
    expect_has(g_out.status_waiting_for, "a command answering sim_time 0.01 ", __LINE__);
    expect_has(g_out.status_waiting_for, on_cmd, __LINE__);
    ENSURE(g_out.status_waiting_s >= 1.5 && g_out.status_waiting_s < 2.2);
    ENSURE(!strcmp(g_out.status_waiting_got, ""));
    /* answers to the right sim_time of another generation, or of none (a command built by
     * hand that copies the sim_time alone): each said as what it is, not "another sim_time" */
    command_gen(0, 0.01, "theta0", 1.0);
    command_gen(0, 0.01, "theta0", 1.0);
    command_gen(g_srv.pub.generation + 7, 0.01, "theta0", 1.0);
    status_now();
    expect_has(g_out.status_waiting_got, "1 answer of another generation (a state of an earlier "
               "run or scene); 2 answers of generation 0 (the command carries none: it copies the "
               "state's generation with its sim_time", __LINE__);
    ENSURE(!strstr(g_out.status_waiting_got, "another sim_time"));
    /* paused */
    control(LAGSIM_CONTROL_T_PAUSE, 0);
    run_until(g_srv.now + 1 * SEC, 1000);
    status_now();
    expect_has(g_out.status_waiting_for, "RESUME or STEP ", __LINE__);
    /* lockstep: paused while the state at 0.01 is waited on, its answer still owed */
    char owed[500];
    snprintf(owed, sizeof owed, "on TL_CONTROL at %s (paused; the answer to sim_time 0.01 "
             "still owed on TL_COMMAND)", g_srv.bus.urls.command_url);
    expect_has(g_out.status_waiting_for, owed, __LINE__);
    ENSURE(g_out.status_waiting_s >= 1.0 && g_out.status_waiting_s < 1.2);
    /* a wait nobody answers: its lines thin out, at 3, 6, 12, 24, 48, 96 s of the wait,
     * then a minute apart */
    run_until(g_srv.now + 20 * SEC, 1000000);
    int64_t since = g_srv.wait.since_ns, next = rt_wait_next(&g_srv.wait);
    ENSUREF(next - since == 24 * SEC, "after %.1f s of a wait the next line at %.1f s of it (24)",
            (double)(g_srv.now - since) / SEC, (double)(next - since) / SEC);
    run_until(g_srv.now + 300 * SEC, 100000000);
    next = rt_wait_next(&g_srv.wait);
    /* (each line comes at the loop's first wake-up after it is due: 100 ms steps here) */
    ENSUREF(next > g_srv.now && next - g_srv.now <= 60 * SEC &&
                (next - since - 96 * SEC) % (60 * SEC) < SEC,
            "after %.1f s of a wait the next line at %.1f s of it (96 + 60 k, within 1 s)",
            (double)(g_srv.now - since) / SEC, (double)(next - since) / SEC);
    stop_server();

    /* realtime: waiting for the first command, then running: nothing to wait for */
    scene(LAG_RT_REALTIME);
    g_sc.realtime.start = LAG_RT_START_FIRST_COMMAND;
    start();
    run_until(g_srv.now + 1 * SEC, 1000);
    status_now();
    expect_has(g_out.status_waiting_for, "the first command on TL_COMMAND at udpm://", __LINE__);
    command(0.0, "theta0", 0.0);
    run_until(g_srv.now + 1 * SEC, 1000);
    status_now();
    ENSURE(!strcmp(g_out.status_waiting_for, "") && !strcmp(g_out.status_run, "running"));
    stop_server();
}

/* Control requests for a prefix no plant here has (a misspelt one) are named in the wait:
 * counted by request since the wait began, once the daemon's own DESCRIBE to that prefix
 * (its probe: one a prefix) went unanswered for 0.5 s; a prefix that answers with its
 * scene is another plant's and is not named; a flood of new prefixes costs a bounded
 * table, at most 4 probes a second (and a burst of 4), at most 3 prefixes named. */
static int64_t g_probes;
static void on_probe(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch, (void)u;
    lag_wire_control m;
    if (lag_wire_decode_control(rb->data, rb->data_size, 0, &m) == LAG_WIRE_OK && m.utime > 0)
        g_probes++; /* the test's own requests carry utime 0 */
}

static void request_on(const char *channel, int req)
{
    uint8_t buf[256];
    lagsim_control_t m = {0, (int8_t)req, 0, 0, NULL, NULL, "", ""};
    int n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0 && lcm_publish(g_lcm, channel, buf, (unsigned)n) == 0);
}

static void case_foreign(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    g_sc.realtime.start = LAG_RT_START_FIRST_COMMAND;
    start();
    lcm_subscription_t *sub = lcm_subscribe(g_lcm, "TLMISPELT_CONTROL", on_probe, NULL);
    g_probes = 0;
    for (int i = 0; i < 5; i++) { /* a controller's DESCRIBE every 0.25 s */
        request_on("TLMISPELT_CONTROL", LAGSIM_CONTROL_T_DESCRIBE);
        run_until(g_srv.now + 250 * MS, 1000);
    }
    status_now();
    ENSUREF(g_probes == 1, "%lld probes of TLMISPELT (one)", (long long)g_probes);
    expect_has(g_out.status_waiting_got, "requests for a prefix no plant here has, on the command "
               "port 7668: TLMISPELT (DESCRIBE 5); this plant is TL", __LINE__);
    /* another plant's prefix: its scene answers the probe; a junk request is undecodable */
    request_on("TLOTHER_CONTROL", LAGSIM_CONTROL_T_STATUS);
    lcm_publish(g_lcm, "TLJUNK_CONTROL", "junk", 4);
    run_until(g_srv.now + 10 * MS, 1000);
    /* its scene (the channel says whose: the daemon does not decode it) */
    ENSURE(lcm_publish(g_lcm, "TLOTHER_SCENE", "scene", 5) == 0);
    run_until(g_srv.now + 600 * MS, 1000);
    status_now();
    ENSUREF(!strstr(g_out.status_waiting_got, "TLOTHER"), "another plant's prefix named: %s",
            g_out.status_waiting_got);
    expect_has(g_out.status_waiting_got, "requests for prefixes no plant here has, on the "
               "command port 7668: TLJUNK (undecodable 1), TLMISPELT (DESCRIBE 5); this plant "
               "is TL", __LINE__);
    /* five misspelt prefixes: three named, the others counted */
    for (int i = 0; i < 5; i++) {
        char ch[64];
        snprintf(ch, sizeof ch, "TLM%d_CONTROL", i);
        request_on(ch, LAGSIM_CONTROL_T_STATUS);
        run_until(g_srv.now + 300 * MS, 1000);
    }
    run_until(g_srv.now + 600 * MS, 1000);
    status_now();
    expect_has(g_out.status_waiting_got, ": TLM4 (STATUS 1), TLM3 (STATUS 1), TLM2 (STATUS 1) "
               "and 4 more; this plant is TL", __LINE__);
    /* a flood of new prefixes for 2 s: at most 4 probes a second, a table of 8 */
    int64_t t0 = g_srv.now, refused0 = g_srv.bus.probes.suppressed;
    int64_t forgotten0 = g_srv.bus.foreign.forgotten;
    for (int i = 0; i < 4000; i++) {
        char ch[64];
        snprintf(ch, sizeof ch, "F%d_CONTROL", i);
        request_on(ch, LAGSIM_CONTROL_T_DESCRIBE);
        if (i % 20 == 19) run_until(g_srv.now + 10 * MS, 1000);
    }
    double secs = (double)(g_srv.now - t0) / SEC;
    int64_t sent = 4000 - (g_srv.bus.probes.suppressed - refused0);
    ENSUREF(sent <= (int64_t)(4 * secs) + 4 + 1 && sent >= 4,
            "%lld probes in %.1f s of 4000 new prefixes", (long long)sent, secs);
    ENSUREF(g_srv.bus.foreign.forgotten - forgotten0 >= 4000 - RT_FOREIGN_MAX,
            "%lld prefixes forgotten", (long long)(g_srv.bus.foreign.forgotten - forgotten0));
    /* and after it, a misspelt prefix is named again */
    for (int i = 0; i < 4; i++) {
        request_on("TLAGAIN_CONTROL", LAGSIM_CONTROL_T_DESCRIBE);
        run_until(g_srv.now + 250 * MS, 1000);
    }
    run_until(g_srv.now + 500 * MS, 1000);
    status_now();
    expect_has(g_out.status_waiting_got, ": TLAGAIN (DESCRIBE 4)", __LINE__);
    printf("after a flood of 4000 prefixes (%lld probes in %.1f s): %s\n", (long long)sent,
           secs, g_out.status_waiting_got);
    lcm_unsubscribe(g_lcm, sub);
    stop_server();
}

/* The copy rule's hint: a controller that runs its law again on every copy answers the
 * copies one law time apart, long after the first answer: once 10 such late answers (and
 * answers to states older than the last answered) make one for every two states
 * answered, a copy_rule event says so, once. A controller that answers the copies it got
 * at once (1 ms after its first answer here) never sees it. */
static void case_copy_rule(int arg)
{
    (void)arg;
    for (int law_again = 0; law_again < 2; law_again++) {
        scene(LAG_RT_LOCKSTEP);
        g_sc.realtime.start = LAG_RT_START_RUNNING;
        g_sc.realtime.lockstep_timeout = 10.0;
        start();
        for (int k = 0; k < 40; k++) {
            double t = g_out.last_t;              /* the state waited on */
            run_until(g_srv.now + 5 * MS, 1000);  /* the law's time */
            command(t, "theta0", 0.0);
            /* a copy answered again: at once by the rule, 50 ms (a law) later without it */
            run_until(g_srv.now + (law_again ? 50 : 1) * MS, 1000);
            command(t, "theta0", 0.0);
            drain();
            rt_process(&g_srv);
        }
        run_until(g_srv.now + 10 * MS, 1000);
        printf("%s: %lld states answered, %lld ignored, %lld late; copy_rule events %lld: %s\n",
               law_again ? "the law again" : "the rule", (long long)g_srv.accepted,
               (long long)g_srv.commands_ignored, (long long)g_srv.late_answers,
               (long long)n_events("copy_rule"), last_detail("copy_rule"));
        ENSURE(g_srv.accepted == 40 && g_srv.commands_ignored == 40);
        if (law_again)
            ENSUREF(n_events("copy_rule") == 1 &&
                        strstr(last_detail("copy_rule"), "the law seems to run again on copies: "
                               "10 answers came 20 ms or more after their state was answered "
                               "(10 states answered); answer a copy (same generation, sim_time) "
                               "at once with the command sent (docs/protocol.md: the copy rule)"),
                    "%lld copy_rule events", (long long)n_events("copy_rule"));
        else
            ENSURE(n_events("copy_rule") == 0 && g_srv.late_answers == 0);
        stop_server();
    }
}

/* Runs a lockstep DIPC for `periods` periods with the test's controller losing `loss` of
 * the states and of the commands; returns the wall time (ns of the made-up clock). */
static int64_t lockstep_run(double loss, int periods)
{
    scene(LAG_RT_LOCKSTEP);
    g_sc.realtime.lockstep_timeout = 1.0;
    g_sc.realtime.lockstep_retry = 0.02;
    memset(&g_ctl, 0, sizeof g_ctl);
    g_ctl.on = true;
    g_ctl.loss = loss;
    g_ctl.rng = 12345;
    g_ctl.end_step = 10 * (int64_t)periods;
    start();
    const int64_t t0 = g_srv.now;
    while (g_srv.sim.tick < 10 * (int64_t)periods && g_srv.now - t0 < 600 * SEC)
        run_until(g_srv.now + 10 * MS, 1 * MS);
    g_ctl.on = false;
    ENSURE(g_srv.sim.tick == 10 * (int64_t)periods);
    return g_srv.now - t0;
}

/* Lockstep under loss: with 10 % of the states and 10 % of the commands lost (and 30 %),
 * the controller receives every state of the run and the states are those of a lossless
 * run bit for bit; each loss costs a retry (20 ms), never a lockstep_timeout. */
static void case_lockstep_loss(int arg)
{
    (void)arg;
    enum { N = 1000 };
    lockstep_run(0.0, N);
    ENSURE(g_srv.pub.lockstep_retries == 0 && g_ctl.lost_states == 0 && g_ctl.steps == N + 1);
    static controller ref;
    ref = g_ctl;
    stop_server();
    const double losses[] = {0.1, 0.3};
    for (int i = 0; i < 2; i++) {
        int64_t wall = lockstep_run(losses[i], N);
        printf("loss %.0f %% each way: %lld states and %lld commands lost, %lld retries, "
               "%lld answers ignored, %lld timeouts, %.2f s of wall time for %d periods\n",
               100 * losses[i], (long long)g_ctl.lost_states, (long long)g_ctl.lost_commands,
               (long long)g_srv.pub.lockstep_retries, (long long)g_srv.commands_ignored,
               (long long)g_srv.lockstep_timeouts, (double)wall * 1e-9, N);
        ENSURE(g_ctl.lost_states > 0 && g_ctl.lost_commands > 0);
        ENSUREF(g_srv.lockstep_timeouts == 0, "%lld lockstep timeouts",
                (long long)g_srv.lockstep_timeouts);
        ENSURE(g_srv.pub.lockstep_retries >= g_ctl.lost_states);
        ENSURE(g_ctl.steps == N + 1);
        for (int k = 0; k <= N; k++)
            if (!g_ctl.have[k] || memcmp(g_ctl.x[k], ref.x[k], sizeof ref.x[k]) != 0)
                LT_FAIL("loss %g: period %d differs from the lossless run", losses[i], k);
        ENSURE(n_events("command_rejected") == 0 && n_events("lockstep_timeout") == 0);
        stop_server();
    }
}

/* One plant per prefix: the daemon's own scenes (at start, on DESCRIBE, after a reset)
 * come back on its _SCENE subscription and are known as its own, a copy included; junk,
 * a scene cut short and another prefix's scene are no plant's; a scene it did not send
 * (the same with another utime: another daemon's, or a forgery) while running is a
 * conflict: counted, in status, said at most once in 5 s, and the plant runs on (a flood
 * of them too); at start it is what makes the daemon refuse to start. */
static void case_other_plant(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME);
    g_sc.realtime.start = LAG_RT_START_RUNNING;
    start();
    run_until(g_srv.now + 100 * MS, 0);
    control(LAGSIM_CONTROL_T_DESCRIBE, 0);
    run_until(g_srv.now + 500 * MS, 0);
    control(LAGSIM_CONTROL_T_RESET, 0);
    run_until(g_srv.now + 500 * MS, 0);
    ENSUREF(g_out.scene == 3, "%lld scenes", (long long)g_out.scene);
    uint8_t other[4096];
    size_t len = g_out.scene_len;
    memcpy(other, g_out.scene_bytes, len);
    lcm_publish(g_lcm, "TL_SCENE", other, (unsigned)len); /* a copy of its own */
    run_until(g_srv.now + 100 * MS, 0);
    ENSURE(!g_srv.stop && g_srv.bus.other_plant[0] == '\0' && g_srv.sim.tick > 0);
    other[8 + 7] ^= 1; /* utime, after the fingerprint */
    /* not a plant's: junk, a scene cut short, another prefix's scene */
    g_junk_scenes = true;
    lcm_publish(g_lcm, "TL_SCENE", "junk", 4);
    lcm_publish(g_lcm, "TL_SCENE", other, (unsigned)len - 1);
    uint8_t *pfx = memmem(other, len, "TL", 3);
    ENSURE(pfx != NULL);
    pfx[0] = 'X';
    lcm_publish(g_lcm, "TL_SCENE", other, (unsigned)len);
    run_until(g_srv.now + 100 * MS, 0);
    ENSURE(!g_srv.stop && g_srv.bus.other_plant[0] == '\0');
    pfx[0] = 'T';
    /* another plant's scene (a forgery, an old log played back) while running: the plant
     * runs on, its states continue, the conflict is counted, published in status and said
     * by one plant_conflict event */
    int64_t states = g_out.state;
    lcm_publish(g_lcm, "TL_SCENE", other, (unsigned)len);
    run_until(g_srv.now + 1 * SEC, 0);
    ENSURE(!g_srv.stop);
    ENSUREF(g_out.state >= states + 99, "%lld states in the second after the other plant's scene",
            (long long)(g_out.state - states));
    ENSURE(g_srv.plant_conflicts == 1 && g_out.status_conflicts == 1);
    ENSUREF(n_events("plant_conflict") == 1 &&
                strstr(last_detail("plant_conflict"), "another plant publishes on prefix TL") &&
                strstr(last_detail("plant_conflict"), "model dipc") &&
                strstr(last_detail("plant_conflict"), "running on"),
            "plant_conflict: %lld, '%s'", (long long)n_events("plant_conflict"),
            last_detail("plant_conflict"));
    /* a flood: 3000 forged scenes over 6 s (one every 2 ms): every one counted, events at
     * the bucket's pace (one in 5 s: the first above, one more at 5 s), the states go on */
    states = g_out.state;
    for (int k = 0; k < 3000; k++) {
        lcm_publish(g_lcm, "TL_SCENE", other, (unsigned)len);
        run_until(g_srv.now + 2 * MS, 0);
    }
    ENSURE(!g_srv.stop && g_srv.plant_conflicts == 3001);
    ENSUREF(g_out.state >= states + 599, "%lld states in the 6 s of the flood",
            (long long)(g_out.state - states));
    ENSUREF(n_events("plant_conflict") == 2, "%lld plant_conflict events for 3001 scenes",
            (long long)n_events("plant_conflict"));
    ENSUREF(n_events("plant_conflict") + n_suppressed("plant_conflict") +
                    g_srv.pub.lim_event[RT_EV_PLANT_CONFLICT].suppressed == 3001,
            "said %lld + suppressed %lld + pending %lld", (long long)n_events("plant_conflict"),
            (long long)n_suppressed("plant_conflict"),
            (long long)g_srv.pub.lim_event[RT_EV_PLANT_CONFLICT].suppressed);
    control(LAGSIM_CONTROL_T_STATUS, 0);
    run_until(g_srv.now + 100 * MS, 0);
    ENSURE(g_out.status_conflicts == 3001);
    stop_server();
    ENSUREF(n_events("stop") == 1 && !strstr(last_detail("stop"), "another plant"),
            "stop event: '%s'", last_detail("stop"));
    /* at start (before the daemon publishes: rt_bus_open's look) the same scene is noted,
     * not counted, for rt_bus_open to refuse the start */
    start();
    g_srv.bus.discard = true;
    lcm_publish(g_lcm, "TL_SCENE", other, (unsigned)len);
    drain();
    ENSURE(g_srv.bus.other_plant[0] != '\0' && g_srv.plant_conflicts == 0 && n_events("plant_conflict") == 0);
    g_srv.bus.discard = false;
    stop_server();
}

/* What a refusal says: a null mapping set while running does not poison later sets
 * below it (effects=null, then effects.damping.* is applied, the damping on); every count
 * check names the expected count and the model (reset_to with 4 joints on the 3-joint
 * DIPC, a command of 4 joints, step 0). */
static void case_messages(int arg)
{
    (void)arg;
    static const char text[] =
        "model: dipc\n"
        "initial: {q: [0, 0.1, -0.05]}\n"
        "realtime: {mode: fast, start: paused}\n"
        "effects: {}\n"
        "lcm: {prefix: TL}\n";
    char err[1024];
    ENSURE(lag_scene_load_buffer("msg.yaml", text, sizeof text - 1, NULL, 0, &g_sc, err, sizeof err) == 0);
    memset(&g_opts, 0, sizeof g_opts);
    g_opts.quiet = true;
    g_opts.scene_name = "msg.yaml";
    g_opts.scene_text = text;
    g_opts.scene_len = sizeof text - 1;
    start();
    set_request("effects", "null");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("set") == 1 && n_events("control_rejected") == 0, "effects=null: %lld sets, "
            "rejected '%s'", (long long)n_events("set"), last_detail("control_rejected"));
    set_request("effects.damping.theta1", "0.25");
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("set") == 2 && n_events("control_rejected") == 0,
            "effects.damping.theta1 after effects=null: refused: '%s'", last_detail("control_rejected"));
    ENSURE(g_srv.sim.def.effects.enabled & LAG_EFF_DAMPING);
    ENSURE(g_srv.sim.def.effects.damping[1] == 0.25);

    /* reset_to with 4 joints: names the model and its 3 joints */
    lag_wire_control m;
    memset(&m, 0, sizeof m);
    m.request = LAGSIM_CONTROL_T_RESET_TO;
    m.num_joints = 4;
    uint8_t buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode_control(&m, buf, sizeof buf);
    ENSURE(n > 0);
    rt_handle_control(&g_srv, buf, (size_t)n);
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("control_rejected") == 1 &&
                strstr(last_detail("control_rejected"), "reset_to: num_joints 4; accepted: 3, "
                       "the joints of dipc in this order: theta0 (actuated), theta1, theta2"),
            "reset_to with 4 joints: '%s'", last_detail("control_rejected"));
    /* a command of 4 joints */
    lag_wire_joint_command jc;
    memset(&jc, 0, sizeof jc);
    jc.num_joints = 4;
    for (int i = 0; i < 4; i++) snprintf(jc.name[i], sizeof jc.name[i], "theta%d", i);
    n = lag_wire_encode(LAG_WIRE_JOINT_COMMAND, &jc, buf, sizeof buf);
    ENSURE(n > 0);
    rt_handle_command(&g_srv, buf, (size_t)n);
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("command_rejected") == 1 &&
                strstr(last_detail("command_rejected"), "num_joints 4 (in value); accepted: 0 to 3, "
                       "joints of dipc: theta0 (actuated), theta1, theta2"),
            "command with 4 joints: '%s'", last_detail("command_rejected"));
    control(LAGSIM_CONTROL_T_STEP, 0);
    run_until(g_srv.now + 10 * MS, 1000);
    ENSUREF(n_events("control_rejected") == 2 &&
                strstr(last_detail("control_rejected"), "step: count 0; accepted: a count >= 1"),
            "step 0: '%s'", last_detail("control_rejected"));
    stop_server();
}

/* The live error estimate: rk4 at 10 ms on the DIPC released far off upright (it falls
 * and tumbles: a chaotic phase) asked for an error of 1e-9 over 1 s, estimated every
 * period. Its error per period (about 1e-7 rad) is far over the budget 1e-9 x 0.01 s /
 * 1 s: every period is counted in error_warnings, the error_estimate events stay within
 * their bucket (3, then 1 a second) and name the joint and the size; status carries the
 * estimate, finite. The same run with the estimate off (estimate_every 0) has
 * bit-identical states and says nothing of it. */
static void case_live_error(int arg)
{
    (void)arg;
    static const char text[] =
        "model: dipc\n"
        "initial: {q: [0, 0.8, -0.6]}\n"
        "integrator: {method: rk4, dt: 0.01, error: 1e-9, estimate_every: 1}\n"
        "realtime: {mode: fast, start: running, status_hz: 50}\n"
        "lcm: {prefix: TL}\n";
    double q_on[LAG_MAX_DOF], qd_on[LAG_MAX_DOF];
    for (int on = 1; on >= 0; on--) {
        char err[1024];
        ENSURE(lag_scene_load_buffer("live.yaml", text, sizeof text - 1, NULL, 0, &g_sc, err,
                                     sizeof err) == 0);
        if (!on) g_sc.accuracy.estimate_every = 0;
        memset(&g_opts, 0, sizeof g_opts);
        g_opts.quiet = true;
        g_opts.duration = 3;
        start();
        const int64_t t0 = g_srv.now;
        run_until(t0 + 100 * SEC, 5 * MS); /* 300 periods, 5 ms of wall clock each */
        ENSURE(g_srv.stop && g_srv.sim.tick == 300);
        const double wall_s = (double)(g_srv.now - t0) * 1e-9, budget = 1e-9 * 0.01 / 1.0;
        if (on) {
            memcpy(q_on, g_srv.sim.q, sizeof q_on);
            memcpy(qd_on, g_srv.sim.qd, sizeof qd_on);
            ENSUREF(g_srv.est.warnings >= 290, "%lld periods over the budget",
                    (long long)g_srv.est.warnings);
            const int64_t ev = n_events("error_estimate");
            ENSUREF(ev >= 3 && ev <= 3 + (int64_t)wall_s + 1, "%lld error_estimate events in "
                    "%.2f s", (long long)ev, wall_s);
            const char *d = last_detail("error_estimate");
            printf("%lld error_estimate events in %.2f s, the last: %s\n", (long long)ev, wall_s, d);
            ENSUREF(strstr(d, "to theta") && strstr(d, "integrator.error 1e-09 over 1 s") &&
                        strstr(d, "suppressed"), "detail: %s", d);
            ENSURE(g_out.kind_value[kind_index("error_estimate")] > budget);
        }
        stop_server(); /* every number published finite */
        if (on) {
            ENSURE(g_out.status_err_warnings == g_srv.est.warnings);
            ENSURE(g_out.status_err_budget == budget);
            ENSUREF(g_out.status_err_estimate > budget && g_out.status_err_estimate < 1e-3,
                    "estimate %g", g_out.status_err_estimate);
            ENSURE(!strncmp(g_out.status_err_joint, "theta", 5));
        } else {
            ENSURE(memcmp(q_on, g_srv.sim.q, sizeof q_on) == 0);
            ENSURE(memcmp(qd_on, g_srv.sim.qd, sizeof qd_on) == 0);
            ENSURE(n_events("error_estimate") == 0 && g_out.status_err_warnings == 0);
            ENSURE(g_out.status_err_estimate == 0 && g_out.status_err_joint[0] == '\0');
        }
    }
}

static void setup(void)
{
    /* The loop runs on memq://; the URLs it names in its messages are the scene's, LCM's
     * default (7667, commands 7668) as the cases expect, whatever LCM_DEFAULT_URL the
     * shell that runs the tests has (a developer's own bus) */
    unsetenv("LCM_DEFAULT_URL");
    g_lcm = lcm_create("memq://");
    ENSURE(g_lcm);
    lcm_subscribe(g_lcm, "TL_.*", on_any, NULL);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"pacing", case_pacing, 0, 0},           {"rate_huge", case_rate_huge, 0, 0},
        {"status_hz", case_status_hz, 0, 0},     {"lockstep_wait", case_lockstep_wait, 0, 0},
        {"start", case_start, 0, 0},             {"set", case_set, 0, 0},
        {"set_replay", case_set_replay, 0, 0},
        {"long_period", case_long_period, 0, 0}, {"chunks", case_chunks, 0, 0},
        {"step_paced", case_step_paced, 0, 0},   {"control_flood", case_control_flood, 0, 0},
        {"command_flood", case_command_flood, 0, 0}, {"duration", case_duration, 0, 0},
        {"signals", case_signals, 0, 0},         {"fault_effort", case_fault_effort, 0, 0},
        {"lockstep_retry", case_lockstep_retry, 0, 0}, {"lockstep_loss", case_lockstep_loss, 0, 0},
        {"late_controller", case_late_controller, 0, 0},
        {"other_plant", case_other_plant, 0, 0}, {"messages", case_messages, 0, 0},
        {"reject_names", case_reject_names, 0, 0}, {"waits", case_waits, 0, 0},
        {"foreign", case_foreign, 0, 0},        {"copy_rule", case_copy_rule, 0, 0},
        {"live_error", case_live_error, 0, 0},  {"scene_rules", case_scene_rules, 0, 0},
        {"generation", case_generation, 0, 0},  {"reset_wait", case_reset_wait, 0, 0},
    };
    /* a failed check ends the case: what follows it needs what failed */
    const lt_program p = {.cases = cases, .n = (int)(sizeof cases / sizeof cases[0]),
                          .setup = setup, .stop_on_failure = true};
    int rc = lt_run(argc, argv, &p);
    if (g_lcm) lcm_destroy(g_lcm);
    return rc;
}
