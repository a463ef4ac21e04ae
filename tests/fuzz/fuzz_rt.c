/*
 * Fuzz target: the real-time server's command and control handlers and its loop, in every
 * mode (realtime, fast, lockstep) and run state (running, paused, fault), on LCM's
 * in-process memq:// provider with a made-up clock (deterministic, no sockets).
 *
 * The first bytes choose a model, a mode, an integrator and the real-time settings (from
 * tables that include absurd values a scene file would refuse: rate 1e25, status_hz
 * 1e-300, lockstep_timeout 1e300, an effort limit of infinity, ...); the rest is a sequence of operations: raw bytes
 * to rt_handle_command / rt_handle_control, well-formed commands and controls with
 * arbitrary numbers (SET with keys and values from a table, against a scene text of the
 * same model and integrator), clock advances with loop wake-ups, signals.
 *
 * Checked for every input: no crash or undefined behaviour (ASan/UBSan), no number that
 * is NaN or Inf in any message published, the sim's state finite unless in the fault
 * state, and bounded output: a handler call publishes at most one message (answers are
 * deferred and coalesced) besides a new generation's scene and a reset's `restore`
 * event, a wake-up at most a burst of periods' worth, and over the
 * input every limited event kind, statuses, scene descriptions and states stay within
 * what their buckets allow for the made-up time that passed.
 */
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>

#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"

#define FZ_MAX_OPS 64
#define FZ_TICK_BUDGET 8    /* ticks per wake-up here (the daemon's is larger): fast inputs */
#define MS 1000000LL

typedef struct bytes {
    const uint8_t *p;
    size_t n;
} bytes;

static unsigned u8(bytes *b)
{
    if (b->n == 0) return 0;
    b->n--;
    return *b->p++;
}

static uint64_t u64(bytes *b)
{
    uint64_t u = 0;
    for (int i = 0; i < 8; i++) u = (u << 8) | u8(b);
    return u;
}

/* Sometimes any bit pattern (NaN, Inf, 1e308, subnormals), mostly a plausible number. */
static double dbl(bytes *b)
{
    unsigned sel = u8(b);
    if (sel < 64) {
        uint64_t u = u64(b);
        double d;
        memcpy(&d, &u, sizeof d);
        return d;
    }
    int16_t mant = (int16_t)(u8(b) << 8 | u8(b));
    return mant / 1000.0 * pow(10.0, (int)(sel % 9) - 3);
}

/* ---------------------------------------------------------------- what is published */
typedef struct counts {
    int64_t state, status, scene, event;
    int64_t restore; /* `restore` events: a RESET to the scene file's values names its undoing */
    int64_t ev_kind[RT_EV_COUNT + 3]; /* limited kinds, then start/stop, set, others */
} counts;
static counts g_c;
static const char *const k_limited[RT_EV_COUNT] = {
    "command_rejected", "control_rejected", "pause", "resume", "step", "step_done", "reset",
    "watchdog_trip", "watchdog_clear", "lockstep_timeout", "overrun_burst", "numeric_fault",
    "events_dropped", "plant_conflict", "error_estimate", "input_limited", "foreign_limited"};

static void bad(const char *what)
{
    fprintf(stderr, "fuzz_rt: %s\n", what);
    abort();
}

static void need_finite(const double *x, int n, const char *what)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i])) bad(what);
}

static const char *suffix(const char *ch)
{
    const char *u = strrchr(ch, '_');
    return u ? u + 1 : ch;
}

static void on_any(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)user;
    const char *sfx = suffix(ch);
    if (!strcmp(sfx, "STATE")) {
        lag_wire_joint_state m;
        if (lag_wire_decode_joint_state(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK) bad("undecodable state");
        need_finite(&m.sim_time, 1, "state sim_time");
        need_finite(m.position, m.num_joints, "state position");
        need_finite(m.velocity, m.num_joints, "state velocity");
        need_finite(m.effort, m.num_joints, "state effort");
        g_c.state++;
    } else if (!strcmp(sfx, "STATUS")) {
        lag_wire_status m;
        if (lag_wire_decode_status(rb->data, rb->data_size, &m) != LAG_WIRE_OK) bad("undecodable status");
        double d[] = {m.sim_time, m.wall_time, m.rtf, m.step_time_max_us, m.step_time_mean_us,
                      m.energy, m.error_estimate, m.error_budget};
        need_finite(d, 8, "status number");
        g_c.status++;
    } else if (!strcmp(sfx, "EVENT")) {
        lag_wire_event m;
        if (lag_wire_decode_event(rb->data, rb->data_size, &m) != LAG_WIRE_OK) bad("undecodable event");
        double d[] = {m.sim_time, m.value};
        need_finite(d, 2, "event number");
        int k = RT_EV_COUNT + 1;
        for (int i = 0; i < RT_EV_COUNT; i++)
            if (!strcmp(m.kind, k_limited[i])) k = i;
        if (!strcmp(m.kind, "start") || !strcmp(m.kind, "stop")) k = RT_EV_COUNT;
        if (!strcmp(m.kind, "set")) k = RT_EV_COUNT + 1; /* never suppressed: SET's bucket */
        if (!strcmp(m.kind, "restore")) g_c.restore++;
        if (k == RT_EV_COUNT + 2) fprintf(stderr, "fuzz_rt: event of kind %s\n", m.kind);
        g_c.ev_kind[k]++;
        g_c.event++;
    } else if (!strcmp(sfx, "SCENE")) {
        lag_wire_scene m;
        if (lag_wire_decode_scene(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK) bad("undecodable scene");
        need_finite(m.param_value, m.num_params, "scene parameter");
        need_finite(m.initial_q, m.num_joints, "scene q0");
        double d[] = {m.dt, m.control_period, m.rate, m.command_timeout};
        need_finite(d, 4, "scene number");
        g_c.scene++;
    }
}

static int64_t out_total(void) { return g_c.state + g_c.status + g_c.scene + g_c.event; }

/* ---------------------------------------------------------------- the server */
static lcm_t *g_lcm;
static rt_server g_s;
static lag_scene g_sc;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    g_lcm = lcm_create("memq://");
    if (!g_lcm) bad("no memq:// LCM");
    lcm_subscribe(g_lcm, "FZ_.*", on_any, NULL);
    return 0;
}

/* Delivers what the server published. memq:// writes a byte per message to the pipe
 * behind lcm_get_fileno; its count says how many lcm_handle calls will not block. */
static void drain(void)
{
    for (;;) {
        int pending = 0;
        if (ioctl(lcm_get_fileno(g_lcm), FIONREAD, &pending) != 0 || pending <= 0) return;
        for (int i = 0; i < pending; i++) lcm_handle(g_lcm);
    }
}

static void check_state(void)
{
    if (g_s.run == RT_FAULT) return;
    need_finite(g_s.sim.q, g_s.nq, "sim q outside the fault state");
    need_finite(g_s.sim.qd, g_s.nq, "sim qd outside the fault state");
}

/* One wake-up of the loop at s->now; checks its output. */
static void wake(void)
{
    int64_t before = out_total();
    rt_process(&g_s);
    drain();
    /* a burst of periods, each a state and at most a few limited events (no effects in
     * these scenes), plus the answers and the periodic status */
    if (out_total() - before > RT_MAX_BURST * 4 + 6) bad("a wake-up published too much");
    check_state();
}

static void handler_done(int64_t before)
{
    int64_t scenes = g_c.scene, restores = g_c.restore;
    drain();
    /* one answer, and the scene of a new generation (a SET, a kick, a reset) before it;
     * a RESET to the scene file's values first names what it undid: a `restore` event
     * (docs/server.md, RESET) */
    if (g_c.scene - scenes > 1) bad("a handler call published more than one scene");
    if (g_c.restore - restores > 1) bad("a handler call published more than one restore");
    if (out_total() - before - (g_c.scene - scenes) - (g_c.restore - restores) > 1)
        bad("a handler call published more than one message besides a new generation's "
            "scene and a reset's restore");
    check_state();
}

static const double k_rates[] = {1.0, 0.5, 4.0, 1e6, 1e25, 1e-300, 1e300};
static const double k_status[] = {5.0, 100.0, 1e9, 1e-300, 0.01};
static const double k_lockstep[] = {1.0, 0.0, 0.05, 1e10, 1e300, 9e9};
static const double k_cmdto[] = {0.5, 0.0, 1e300, 0.05};
static const int64_t k_ticks[] = {10, 1, 100, 1000, 1000000000000LL};
/* the cheap methods: the integrators have their own fuzz target; here they only move */
static const lag_method k_methods[] = {LAG_RK4, LAG_EULER, LAG_SEMI_IMPLICIT_EULER, LAG_RK4};
#define PICK(tab, b) tab[u8(b) % (sizeof tab / sizeof tab[0])]

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes b = {data, size};
    lag_scene_default(&g_sc, (lag_model_kind)(u8(&b) % LAG_MODEL_COUNT));
    g_sc.realtime.mode = (lag_rt_mode)(u8(&b) % 3);
    g_sc.sim.integrator.method = PICK(k_methods, &b);
    g_sc.ticks_per_period = PICK(k_ticks, &b);
    g_sc.publish_hz = 1.0 / ((double)g_sc.ticks_per_period * g_sc.sim.integrator.dt);
    g_sc.realtime.rate = PICK(k_rates, &b);
    g_sc.realtime.status_hz = PICK(k_status, &b);
    g_sc.realtime.lockstep_timeout = PICK(k_lockstep, &b);
    g_sc.realtime.command_timeout = PICK(k_cmdto, &b);
    static const double k_effort_limit[] = {1e6, INFINITY, 1e12, 0.0};
    double elim = PICK(k_effort_limit, &b);
    for (int i = 0; i < LAG_MAX_DOF; i++)
        if (g_sc.realtime.effort_limit[i] > 0) g_sc.realtime.effort_limit[i] = elim;
    snprintf(g_sc.lcm.prefix, sizeof g_sc.lcm.prefix, "FZ");
    /* the scene's source for SET: the same model and integrator as built above */
    static char text[256];
    int tlen = snprintf(text, sizeof text, "model: %s\nintegrator: {method: %s, dt: 0.001}\n",
                        lag_model_info_get(g_sc.sim.model.kind)->name,
                        lag_method_name(g_sc.sim.integrator.method));
    lagsimd_opts opts = {.quiet = true, .duration = 0.0, .csv = NULL, .scene_name = "fuzz.yaml",
                         .scene_text = text, .scene_len = (size_t)tlen};
    if (u8(&b) % 4 == 0) opts.duration = dbl(&b);

    memset(&g_c, 0, sizeof g_c);
    char err[512];
    const int64_t t0 = 1000 * MS;
    if (rt_open(&g_s, &g_sc, &opts, t0, true, err, sizeof err) != 0) return 0;
    if (rt_attach(&g_s, g_lcm, g_lcm, err, sizeof err) != 0) bad(err);
    g_s.tick_budget = FZ_TICK_BUDGET;
    rt_begin(&g_s);
    drain();
    int64_t wakes = 1;

    const int nq = g_s.nq;
    const lag_model_info *info = g_s.info;
    uint8_t buf[512];
    for (int op = 0; op < FZ_MAX_OPS && b.n > 0 && !g_s.stop; op++) {
        int64_t before = out_total();
        switch (u8(&b) % 8) {
        case 0: { /* raw bytes on _COMMAND */
            size_t n = u8(&b);
            if (n > b.n) n = b.n;
            rt_handle_command(&g_s, b.p, n);
            b.p += n;
            b.n -= n;
            handler_done(before);
            break;
        }
        case 1: { /* raw bytes on _CONTROL */
            size_t n = u8(&b);
            if (n > b.n) n = b.n;
            rt_handle_control(&g_s, b.p, n);
            b.p += n;
            b.n -= n;
            handler_done(before);
            break;
        }
        case 2: { /* a well-formed control request with arbitrary numbers */
            double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
            int req = (int)(u8(&b) % 9);
            int64_t count = (int64_t)u64(&b);
            if (u8(&b) & 1) count = count % 8; /* mostly small counts too */
            int16_t nj = (int16_t)(u8(&b) % 2 ? nq : (int)(u8(&b) % (LAG_MAX_DOF + 2)) - 1);
            int nv = nj < 0 ? 0 : nj > LAG_MAX_DOF ? LAG_MAX_DOF : nj;
            for (int i = 0; i < nv; i++) {
                q[i] = dbl(&b);
                qd[i] = dbl(&b);
            }
            /* SET: a key (parameters, damping: no effect that publishes events, which the
             * bounds above do not count; and keys that are refused) and a value */
            static const char *const k_keys[] = {"parameters.m", "parameters.m1", "parameters.g",
                                                 "parameters.l2", "effects.damping", "effects",
                                                 "integrator.dt", "parametersx", ""};
            static const char *const k_values[] = {"1.5", "-1", "0", "1e300", "{}", "abc", "[1, 2]",
                                                   "{theta0: 0.5}", "{q1: 0.2, q2: 1e9}", "{x: .nan}"};
            char *key = (char *)PICK(k_keys, &b), *value = (char *)PICK(k_values, &b);
            lagsim_control_t m = {0, (int8_t)req, count, (int16_t)nv, q, qd, key, value};
            int n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
            if (n > 0) rt_handle_control(&g_s, buf, (size_t)n);
            handler_done(before);
            break;
        }
        case 3: { /* a well-formed command: a joint (or not), any effort, a sim time */
            char *names[2];
            double eff[2];
            int nj = 1 + (int)(u8(&b) % 2);
            for (int i = 0; i < nj; i++) {
                unsigned j = u8(&b);
                names[i] = (char *)(j % 8 < (unsigned)nq ? info->joint_names[j % 8] : "bogus");
                eff[i] = dbl(&b);
            }
            double t;
            switch (u8(&b) % 3) {
            case 0: t = g_s.ls.waiting_time; break;
            case 1: t = lag_sim_time(&g_s.sim); break;
            default: t = dbl(&b); break;
            }
            lagsim_joint_command_t m = {0, t, (int16_t)nj, names, eff};
            int n = lagsim_joint_command_t_encode(buf, 0, sizeof buf, &m);
            if (n > 0) rt_handle_command(&g_s, buf, (size_t)n);
            handler_done(before);
            break;
        }
        case 4: /* the clock moves on by up to 6.5 s, then a wake-up */
            g_s.now += (int64_t)(u8(&b) << 8 | u8(&b)) * 100000;
            wake();
            wakes++;
            break;
        case 5: { /* the loop sleeps until its next wake-up (at most 10 s), then wakes */
            int64_t w = rt_next_wake(&g_s);
            int64_t cap = g_s.now + 10000 * MS;
            g_s.now = w > cap ? cap : w > g_s.now ? w : g_s.now;
            wake();
            wakes++;
            /* no spinning: a wake-up asked for now must get something done (a tick, a
             * message, a stop) */
            for (int spin = 0; spin < 4 && !g_s.stop && rt_next_wake(&g_s) <= g_s.now; spin++) {
                int64_t tick = g_s.sim.tick, out = out_total();
                wake();
                wakes++;
                if (g_s.sim.tick == tick && out_total() == out && !g_s.stop &&
                    rt_next_wake(&g_s) <= g_s.now)
                    bad("the loop asks to wake at once and then does nothing (a busy spin)");
            }
            break;
        }
        case 6: { /* a signal */
            static const int sigs[] = {SIGUSR1, SIGUSR2, SIGHUP, SIGTERM, SIGINT, SIGQUIT};
            rt_signal(&g_s, sigs[u8(&b) % 6]);
            break;
        }
        case 7: { /* a few wake-ups, 1 ms of compute each */
            int k = (int)(u8(&b) % 8);
            for (int i = 0; i < k && !g_s.stop; i++) {
                int64_t w = rt_next_wake(&g_s);
                g_s.now = w > g_s.now + MS ? (w > g_s.now + 10000 * MS ? g_s.now + 10000 * MS : w)
                                           : g_s.now + MS;
                wake();
                wakes++;
            }
            break;
        }
        }
    }
    if (getenv("FUZZ_RT_VERBOSE"))
        fprintf(stderr, "fuzz_rt: %s %s, %.3f s, tick %lld, %s, faults %lld, accepted %lld, "
                "rejected %lld+%lld, out: %lld states %lld statuses %lld scenes %lld events\n",
                g_s.info->name, lag_rt_mode_name(g_sc.realtime.mode),
                (double)(g_s.now - t0) * 1e-9, (long long)g_s.sim.tick, rt_run_name(g_s.run),
                (long long)g_s.numeric_faults, (long long)g_s.accepted,
                (long long)g_s.rejected[RT_REJ_EFFORT_LIMIT], (long long)g_s.ctl.controls_rejected,
                (long long)g_c.state, (long long)g_c.status, (long long)g_c.scene,
                (long long)g_c.event);
    rt_finish(&g_s);
    rt_close(&g_s);
    drain();

    /* over the whole input: within the buckets for the time that passed */
    double secs = (double)(g_s.now - t0) * 1e-9;
    for (int k = 0; k < RT_EV_COUNT; k++)
        if ((double)g_c.ev_kind[k] > 10 + 10 * secs + 1) {
            fprintf(stderr, "fuzz_rt: %lld %s events in %.3f s\n", (long long)g_c.ev_kind[k],
                    k_limited[k], secs);
            abort();
        }
    if (g_c.ev_kind[RT_EV_COUNT] > 2 || g_c.ev_kind[RT_EV_COUNT + 2] > 0) bad("unexpected event kinds");
    /* a SET is applied (its set event) or refused (a control_rejected) within its bucket */
    if ((double)g_c.ev_kind[RT_EV_COUNT + 1] > RT_SET_BURST + RT_SET_PER_S * secs + 1) bad("too many set events");
    /* statuses: the first and the last, bucket 5 + 20/s, periodic at most 100/s */
    if ((double)g_c.status > 2 + 5 + 20 * secs + 100 * secs + 1) bad("too many statuses");
    /* scenes: the first; DESCRIBE's bucket (2 + 5/s); one per new generation, which SET's
     * and RESET's buckets bound */
    if ((double)g_c.scene > 1 + 2 + 5 * secs + RT_SET_BURST + RT_SET_PER_S * secs +
                                RT_RESET_BURST + RT_RESET_PER_S * secs + 1)
        bad("too many scene descriptions");
    /* states: per wake-up a burst of periods (or a republication), the initial one, and
     * the resets' bucket */
    if ((double)g_c.state > 1 + (double)wakes * RT_MAX_BURST + 5 + 20 * secs + 1) bad("too many states");
    return 0;
}
