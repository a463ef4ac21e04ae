/*
 * End-to-end tests of the real-time LCM server (lagsimd) over real LCM (udpm, ttl=0:
 * this host only, on a multicast port of the test process's own, given to the daemons
 * through LCM_DEFAULT_URL). Each case starts lagsimd as a child with a unique channel
 * prefix, talks to it with the raw LCM C API and the generated types, and always kills it
 * at the end (SIGKILL on our own death too: PR_SET_PDEATHSIG).
 *
 *   server_test CASE LAGSIMD [LCM_LOGGER]   (the cases: server_test --list; those that
 *                                            record a run are skipped without LCM_LOGGER)
 *     CASE: control hostile watchdog lockstep_timeout two_daemons fault replay
 *           replay_dopri5 replay_effects replay_flight sigterm bad_scene effects control_flood
 *           step_flood lockstep_huge status_rate rate_huge long_period duration_huge
 *           signals effort_absurd ttl_warning offline_signal same_prefix plant_conflict
 *           plant_conflict_logplayer
 *
 * Expected states are computed independently of the daemon's loop: a lag_sim of the same
 * scene (loaded with lag_scene_load, as the daemon does) advanced from the published state
 * with the efforts the test sent. Exits 0 on success, 1 with a message on the first
 * failed check (tests/common/lagsim_test.h).
 */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>
#include "lagsim_bus.h"
#include "scene.h"
#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"
#include "lagsim_test.h"
#include "lagsim_wire.h"

static const char *g_case = "?";
static const char *g_stderr_path; /* children's stderr goes there when set */
static pid_t g_children[16];
static int g_nchildren;

static void kill_children(void)
{
    for (int i = 0; i < g_nchildren; i++)
        if (g_children[i] > 0) {
            kill(g_children[i], SIGKILL);
            waitpid(g_children[i], NULL, 0);
        }
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---------------------------------------------------------------- children */
static pid_t spawn(char *const argv[], bool quiet)
{
    pid_t pid = fork();
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (quiet) {
            FILE *f = freopen("/dev/null", "w", stdout);
            (void)f;
        }
        if (g_stderr_path) {
            FILE *f = freopen(g_stderr_path, "w", stderr);
            (void)f;
        }
        execv(argv[0], argv);
        execvp(argv[0], argv);
        _exit(127);
    }
    ENSURE(pid > 0);
    /* a slot freed by reap(), else a new one (retried cases spawn again) */
    int slot = 0;
    while (slot < g_nchildren && g_children[slot] > 0) slot++;
    ENSUREF(slot < (int)(sizeof g_children / sizeof g_children[0]), "too many children");
    g_children[slot] = pid;
    if (slot == g_nchildren) g_nchildren++;
    return pid;
}

/* Waits up to timeout s for the child; returns its exit code, or -1 (then kills it). */
static int reap(pid_t pid, double timeout)
{
    double t_end = now_s() + timeout;
    int st;
    for (;;) {
        pid_t r = waitpid(pid, &st, WNOHANG);
        if (r == pid) break;
        if (now_s() > t_end) {
            kill(pid, SIGKILL);
            waitpid(pid, &st, 0);
            st = -1;
            break;
        }
        usleep(10000);
    }
    for (int i = 0; i < g_nchildren; i++)
        if (g_children[i] == pid) g_children[i] = 0;
    if (st == -1) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

/* Ends a case's daemon: SIGTERM, after which it must exit 0 within 5 s. */
static void stop_daemon(pid_t d)
{
    kill(d, SIGTERM);
    ENSUREF(reap(d, 5.0) == 0, "the daemon did not exit 0 within 5 s of SIGTERM");
}

/* ---------------------------------------------------------------- a client */
#define MAX_EVENTS 4096
#define MAX_REC 4096
typedef struct rec_state {
    int64_t step;
    double t, q[LAG_MAX_DOF], qd[LAG_MAX_DOF], eff[LAG_MAX_DOF];
} rec_state;

typedef struct client {
    lcm_t *lcm;      /* the plant's state URL: states, status, events, scene */
    lcm_t *lcm_in;   /* its command URL: commands and control (lagsim_bus.h) */
    char prefix[64];
    char ch_state[96], ch_command[96], ch_control[96];
    int nq;
    /* latest state, all states ever non-finite? */
    int64_t n_states;
    rec_state last;
    bool nonfinite_seen;
    double max_abs; /* largest |q| or |qd| seen */
    /* status */
    int64_t n_status;
    lag_wire_status *status;        /* NULL until the first, then &status_buf */
    lag_wire_status status_buf, status_live;
    /* events */
    int n_events;
    char ev_kind[MAX_EVENTS][32];
    double ev_time[MAX_EVENTS];
    char ev_detail[MAX_EVENTS][192];
    double ev_value[MAX_EVENTS];
    int64_t n_events_total;         /* also those beyond MAX_EVENTS */
    /* scene */
    int64_t n_scene;
    lag_wire_scene *scene;          /* NULL until the first, then &scene_buf */
    lag_wire_scene scene_buf;
    lcm_subscription_t *sub_state, *sub_status, *sub_event, *sub_scene;
    /* states missing between two received ones (steps not a period apart), counted when
     * tpp (ticks per period) is set */
    int64_t tpp, prev_step, missing;
    /* messages on the state URL that are not this plant's output (".*" subscription) */
    int64_t foreign_on_state_url;
    /* messages with a utime before this (us; 0: none) are not the live plant's: a log played
     * back onto the bus (plant_conflict_logplayer); counted, not kept */
    int64_t min_utime, n_old;
    int64_t gen;               /* the generation of the last state */
    /* lockstep controller (replay case): answers each state, records it */
    bool controller;
    int n_rec;
    rec_state rec[MAX_REC];
} client;

/* What the daemon publishes is decoded by the wire module (never by lcm-gen's decoders);
 * a message that does not decode fails the test. */
static void on_state(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    client *c = u;
    static lag_wire_joint_state mm;
    const lag_wire_joint_state *m = &mm;
    int rc = lag_wire_decode_joint_state(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &mm);
    ENSUREF(rc == LAG_WIRE_OK, "a state from the daemon: %s", lag_wire_result_string(rc));
    if (m->utime < c->min_utime) {
        c->n_old++;
        return;
    }
    c->n_states++;
    rec_state r = {.step = m->step, .t = m->sim_time};
    for (int i = 0; i < m->num_joints && i < LAG_MAX_DOF; i++) {
        r.q[i] = m->position[i];
        r.qd[i] = m->velocity[i];
        r.eff[i] = m->effort[i];
        if (!isfinite(r.q[i]) || !isfinite(r.qd[i]) || !isfinite(r.eff[i])) c->nonfinite_seen = true;
        if (fabs(r.q[i]) > c->max_abs) c->max_abs = fabs(r.q[i]);
        if (fabs(r.qd[i]) > c->max_abs) c->max_abs = fabs(r.qd[i]);
    }
    if (!isfinite(r.t)) c->nonfinite_seen = true;
    if (c->tpp > 0 && c->n_states > 1 && m->step > c->prev_step)
        c->missing += (m->step - c->prev_step) / c->tpp - 1;
    c->prev_step = m->step;
    c->last = r;
    c->gen = m->generation; /* what a command answering it carries */
    if (c->controller) {
        /* every state is answered; a copy of the last one (a lockstep retry) is not
         * recorded again */
        bool copy = c->n_rec > 0 && c->rec[c->n_rec - 1].step == r.step &&
                    c->rec[c->n_rec - 1].t == r.t;
        if (!copy && c->n_rec < MAX_REC) c->rec[c->n_rec++] = r;
        /* answered 3 ms later: lockstep would otherwise run a period in ~50 us, and
         * lcm-logger, whose LCM queue holds a few dozen messages, lost some whenever a
         * loaded machine kept it off a core for a millisecond or two; paced so, it may be
         * kept off for ~40 ms */
        usleep(3000);
        /* a deterministic controller: PD on the cart and the lower rod plus a sinusoid */
        double u_eff = -2.0 * r.q[0] - 1.0 * r.qd[0] + 3.0 * r.q[1] + 0.5 * sin(7.0 * r.t);
        /* (the stick of replay_flight takes it on x) */
        char *names[1] = {strcmp(g_case, "replay_flight") ? "theta0" : "x"};
        lagsim_joint_command_t cmd = {0, r.t, 1, names, &u_eff, c->gen};
        lagsim_joint_command_t_publish(c->lcm_in, c->ch_command, &cmd);
    }
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    client *c = u;
    int rc = lag_wire_decode_status(rb->data, rb->data_size, &c->status_buf);
    ENSUREF(rc == LAG_WIRE_OK, "a status from the daemon: %s", lag_wire_result_string(rc));
    if (c->status_buf.utime < c->min_utime) { /* an old one played back: the live one again */
        c->n_old++;
        c->status_buf = c->status_live;
        return;
    }
    c->status_live = c->status_buf;
    const lag_wire_status *m = c->status = &c->status_buf;
    c->n_status++;
    if (!isfinite(m->sim_time) || !isfinite(m->rtf) || !isfinite(m->energy)) c->nonfinite_seen = true;
}

static void on_event(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    client *c = u;
    static lag_wire_event mm;
    const lag_wire_event *m = &mm;
    int rc = lag_wire_decode_event(rb->data, rb->data_size, &mm);
    ENSUREF(rc == LAG_WIRE_OK, "an event from the daemon: %s", lag_wire_result_string(rc));
    if (m->utime < c->min_utime) {
        c->n_old++;
        return;
    }
    if (!isfinite(m->sim_time) || !isfinite(m->value)) c->nonfinite_seen = true;
    c->n_events_total++;
    if (c->n_events < MAX_EVENTS) {
        snprintf(c->ev_kind[c->n_events], 32, "%.31s", m->kind);
        snprintf(c->ev_detail[c->n_events], sizeof c->ev_detail[0], "%.191s", m->detail);
        c->ev_time[c->n_events] = m->sim_time;
        c->ev_value[c->n_events] = m->value;
        c->n_events++;
    }
}

static void on_scene(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    client *c = u;
    int rc = lag_wire_decode_scene(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &c->scene_buf);
    ENSUREF(rc == LAG_WIRE_OK, "a scene from the daemon: %s", lag_wire_result_string(rc));
    c->scene = &c->scene_buf;
    c->n_scene++;
}

static client *g_clients[8];
static int g_nclients;

static void client_free_all(void)
{
    for (int i = 0; i < g_nclients; i++) {
        client *c = g_clients[i];
        lcm_unsubscribe(c->lcm, c->sub_state);
        lcm_unsubscribe(c->lcm, c->sub_status);
        lcm_unsubscribe(c->lcm, c->sub_event);
        lcm_unsubscribe(c->lcm, c->sub_scene);
        lcm_destroy(c->lcm_in);
        lcm_destroy(c->lcm);
    }
    g_nclients = 0;
}

/* A client (static storage: it is large), freed at exit by client_free_all. */
static void client_init(client *c, const char *prefix, int nq)
{
    memset(c, 0, sizeof *c);
    g_clients[g_nclients++] = c;
    lag_bus bus;
    char berr[256];
    ENSUREF(lag_bus_init(&bus, NULL, prefix, berr, sizeof berr) == 0, "%s", berr);
    c->lcm = lcm_create(bus.state_url);
    c->lcm_in = lcm_create(bus.command_url);
    ENSUREF(c->lcm && c->lcm_in, "lcm_create(%s) failed: no multicast on loopback?", bus.state_url);
    snprintf(c->prefix, sizeof c->prefix, "%s", prefix);
    c->nq = nq;
    char ch[96];
    snprintf(c->ch_state, sizeof c->ch_state, "%s", bus.channel[LAG_BUS_STATE]);
    snprintf(c->ch_command, sizeof c->ch_command, "%s", bus.channel[LAG_BUS_COMMAND]);
    snprintf(c->ch_control, sizeof c->ch_control, "%s", bus.channel[LAG_BUS_CONTROL]);
    c->sub_state = lcm_subscribe(c->lcm, c->ch_state, on_state, c);
    lcm_subscription_set_queue_capacity(c->sub_state, 100000);
    snprintf(ch, sizeof ch, "%s_STATUS", prefix);
    c->sub_status = lcm_subscribe(c->lcm, ch, on_status, c);
    snprintf(ch, sizeof ch, "%s_EVENT", prefix);
    c->sub_event = lcm_subscribe(c->lcm, ch, on_event, c);
    lcm_subscription_set_queue_capacity(c->sub_event, 100000);
    snprintf(ch, sizeof ch, "%s_SCENE", prefix);
    c->sub_scene = lcm_subscribe(c->lcm, ch, on_scene, c);
}

static void pump(client *c, double seconds)
{
    double t_end = now_s() + seconds;
    for (double t = now_s(); t < t_end; t = now_s()) {
        int ms = (int)((t_end - t) * 1000) + 1;
        lcm_handle_timeout(c->lcm, ms);
    }
}

/* Pumps until cond(c, arg) or timeout; fails the test on timeout. */
#define WAIT_FOR(c, cond, timeout)                                                  \
    do {                                                                            \
        double t_end_ = now_s() + (timeout);                                        \
        while (!(cond)) {                                                           \
            ENSUREF(now_s() < t_end_, "timed out waiting for %s", #cond);           \
            lcm_handle_timeout((c)->lcm, 20);                                       \
        }                                                                           \
    } while (0)

static int count_events(const client *c, const char *kind)
{
    int n = 0;
    for (int i = 0; i < c->n_events; i++) n += strcmp(c->ev_kind[i], kind) == 0;
    return n;
}

static void control(client *c, int req, int64_t count, int n, double *q, double *qd)
{
    lagsim_control_t m = {0, (int8_t)req, count, (int16_t)n, q, qd, "", ""};
    lagsim_control_t_publish(c->lcm_in, c->ch_control, &m);
}

static void command(client *c, double sim_time, int n, const char **names, double *eff)
{
    lagsim_joint_command_t m = {0, sim_time, (int16_t)n, (char **)names, eff, c->gen};
    lagsim_joint_command_t_publish(c->lcm_in, c->ch_command, &m);
}

/* Asks for a fresh status and waits for it. */
static void fresh_status(client *c)
{
    int64_t n0 = c->n_status;
    control(c, LAGSIM_CONTROL_T_STATUS, 0, 0, NULL, NULL);
    WAIT_FOR(c, c->n_status > n0, 3.0);
}

/* ---------------------------------------------------------------- scenes */
static char g_lagsimd[512];
static char g_scene_path[256];
static char g_prefix[64];

static void write_scene(const char *text)
{
    snprintf(g_scene_path, sizeof g_scene_path, "/tmp/lagsim_server_test_%d_%s.yaml",
             (int)getpid(), g_case);
    FILE *f = fopen(g_scene_path, "w");
    ENSURE(f);
    fputs(text, f);
    fclose(f);
}

/* Starts lagsimd on g_scene_path with prefix and extra --set arguments (NULL-ended). */
static pid_t start_daemon(const char *prefix, ...)
{
    char *argv[40];
    static char sets[20][128];
    int n = 0, k = 0;
    argv[n++] = g_lagsimd;
    argv[n++] = "--config";
    argv[n++] = g_scene_path;
    argv[n++] = "-q";
    snprintf(sets[k], sizeof sets[k], "lcm.prefix=%s", prefix);
    argv[n++] = "--set";
    argv[n++] = sets[k++];
    va_list ap;
    va_start(ap, prefix);
    for (const char *a = va_arg(ap, const char *); a && n < 38; a = va_arg(ap, const char *))
        argv[n++] = (char *)a;
    va_end(ap);
    argv[n] = NULL;
    return spawn(argv, false);
}

/* The same scene, loaded as the daemon loads it, for reference simulations. */
static void load_ref(lag_scene *sc, const char *prefix)
{
    char err[512], set[128];
    snprintf(set, sizeof set, "lcm.prefix=%s", prefix);
    const char *sets[1] = {set};
    ENSUREF(lag_scene_load(g_scene_path, sets, 1, sc, err, sizeof err) == 0, "%s", err);
}

/* Reference: from a published state, `periods` control periods with effort tau. */
static void ref_advance(const lag_scene *sc, const rec_state *from, const double *tau,
                        int periods, lag_sim *out)
{
    char err[256];
    ENSURE(lag_sim_init(out, &sc->sim, err, sizeof err) == LAG_OK);
    lag_sim_reset(out, from->q, from->qd);
    out->tick = from->step;
    for (int k = 0; k < periods; k++) {
        lag_sim_set_input(out, tau);
        ENSURE(lag_sim_advance(out, sc->ticks_per_period, false) == LAG_OK);
    }
}

static void ensure_state_equals(const client *c, const lag_sim *ref)
{
    ENSUREF(c->last.step == ref->tick, "step %lld, expected %lld", (long long)c->last.step,
            (long long)ref->tick);
    for (int i = 0; i < c->nq; i++) {
        ENSUREF(c->last.q[i] == ref->q[i] && c->last.qd[i] == ref->qd[i],
                "joint %d: q %.17g qd %.17g, expected %.17g %.17g", i, c->last.q[i],
                c->last.qd[i], ref->q[i], ref->qd[i]);
        ENSUREF(c->last.eff[i] == ref->tau[i], "joint %d effort %g, expected %g", i,
                c->last.eff[i], ref->tau[i]);
    }
}

static const char *DIPC_MOVING =
    "model: dipc\n"
    "initial:\n"
    "  q: [0, 0.1, -0.05]\n"
    "publish_hz: 100\n";

/* ---------------------------------------------------------------- cases */
/* pause / step / reset / reset_to / resume / describe do what they say. */
static void case_control(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, NULL);
    lag_scene sc;
    load_ref(&sc, g_prefix);
    WAIT_FOR(&c, c.n_scene > 0 && c.last.t > 0.1, 5.0);
    ENSURE(strcmp(c.scene->model, "dipc") == 0 && c.scene->num_joints == 3);
    ENSURE(strcmp(c.scene->joint_name[0], "theta0") == 0 && c.scene->actuated[0] &&
           !c.scene->actuated[1] && !c.scene->actuated[2]);
    ENSURE(fabs(c.scene->control_period - 0.01) < 1e-15 && c.scene->dt == sc.sim.integrator.dt);
    ENSURE(count_events(&c, "start") == 1);

    /* pause: sim time stops, the same state keeps being published */
    control(&c, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "pause") == 1, 3.0);
    pump(&c, 0.1);
    rec_state held = c.last;
    int64_t n0 = c.n_states;
    pump(&c, 0.3);
    /* 30 deadlines at 100 Hz; a loaded machine may keep the daemon off a core for a while
     * (it then republishes once, not once per missed deadline): a few suffice to show it */
    ENSUREF(c.n_states >= n0 + 5, "paused: %lld states republished in 0.3 s",
            (long long)(c.n_states - n0));
    ENSURE(c.last.step == held.step && c.last.q[1] == held.q[1] && c.last.qd[1] == held.qd[1]);
    fresh_status(&c);
    ENSURE(strcmp(c.status->run_state, "paused") == 0 && c.status->rtf == 0);

    /* step 5 while paused: exactly 5 periods, state = an independent re-simulation */
    double zero[3] = {0, 0, 0};
    lag_sim ref;
    ref_advance(&sc, &held, zero, 5, &ref);
    control(&c, LAGSIM_CONTROL_T_STEP, 5, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "step_done") == 1, 3.0);
    pump(&c, 0.05);
    ensure_state_equals(&c, &ref);
    ENSURE(c.last.step == held.step + 5 * sc.ticks_per_period);

    /* reset: back to the scene's initial state at t = 0 */
    control(&c, LAGSIM_CONTROL_T_RESET, 0, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "reset") == 1, 3.0);
    pump(&c, 0.05);
    ENSURE(c.last.step == 0 && c.last.t == 0.0);
    ENSURE(c.last.q[0] == 0.0 && c.last.q[1] == 0.1 && c.last.q[2] == -0.05);
    ENSURE(c.last.qd[0] == 0.0 && c.last.qd[1] == 0.0 && c.last.qd[2] == 0.0);

    /* reset_to a given state */
    double q[3] = {0.2, -0.3, 0.4}, qd[3] = {0.1, 0.0, -0.2};
    control(&c, LAGSIM_CONTROL_T_RESET_TO, 0, 3, q, qd);
    WAIT_FOR(&c, count_events(&c, "reset") == 2, 3.0);
    pump(&c, 0.05);
    ENSURE(c.last.step == 0 && c.last.t == 0.0);
    for (int i = 0; i < 3; i++) ENSURE(c.last.q[i] == q[i] && c.last.qd[i] == qd[i]);
    ref_advance(&sc, &c.last, zero, 2, &ref);
    control(&c, LAGSIM_CONTROL_T_STEP, 2, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "step_done") == 2, 3.0);
    pump(&c, 0.05);
    ensure_state_equals(&c, &ref);

    /* nonsense is rejected and counted, and changes nothing */
    rec_state before = c.last;
    double qbad[3] = {0, NAN, 0};
    control(&c, LAGSIM_CONTROL_T_RESET_TO, 0, 2, q, qd);     /* wrong length */
    control(&c, LAGSIM_CONTROL_T_RESET_TO, 0, 3, qbad, qd);  /* NaN */
    control(&c, LAGSIM_CONTROL_T_STEP, 0, 0, NULL, NULL);    /* count < 1 */
    control(&c, 99, 0, 0, NULL, NULL);                       /* unknown request */
    WAIT_FOR(&c, count_events(&c, "control_rejected") == 4, 3.0);
    fresh_status(&c);
    ENSURE(c.status->controls_rejected == 4);
    ENSURE(c.last.step == before.step && c.last.q[1] == before.q[1]);

    /* resume: time advances again; step is refused while running */
    control(&c, LAGSIM_CONTROL_T_RESUME, 0, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "resume") == 1, 3.0);
    WAIT_FOR(&c, c.last.step > before.step + 10 * sc.ticks_per_period, 3.0);
    control(&c, LAGSIM_CONTROL_T_STEP, 3, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "control_rejected") == 5, 3.0);

    /* describe: a fresh scene description */
    int64_t ns = c.n_scene;
    control(&c, LAGSIM_CONTROL_T_DESCRIBE, 0, 0, NULL, NULL);
    WAIT_FOR(&c, c.n_scene > ns, 3.0);
    ENSURE(!c.nonfinite_seen);
    stop_daemon(d);
}

/* ---- raw payloads for hostile commands */
static size_t put_be(uint8_t *b, size_t pos, uint64_t v, int n)
{
    for (int i = n - 1; i >= 0; i--) b[pos++] = (uint8_t)(v >> (8 * i));
    return pos;
}
static size_t raw_header(uint8_t *b, int16_t num_joints)
{
    size_t p = put_be(b, 0, (uint64_t)__lagsim_joint_command_t_get_hash(), 8);
    p = put_be(b, p, 0, 8);          /* utime */
    p = put_be(b, p, 0, 8);          /* sim_time 0.0 */
    return put_be(b, p, (uint16_t)num_joints, 2);
}
static void publish_raw(client *c, const uint8_t *b, size_t n)
{
    lcm_publish(c->lcm_in, c->ch_command, b, (unsigned)n);
}

/* Malformed and hostile commands are rejected and counted by reason; the state stays
 * finite and is unchanged by them. */
static void case_hostile(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, "--set", "realtime.command_timeout=1000", NULL);
    lag_scene sc;
    load_ref(&sc, g_prefix);
    WAIT_FOR(&c, c.n_states > 0, 5.0);
    control(&c, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "pause") == 1, 3.0);

    const char *n0[] = {"theta0"};
    double e15[] = {1.5};
    command(&c, 0, 1, n0, e15); /* the one good command */
    pump(&c, 0.05);

    int exp_unknown = 0, exp_unact = 0, exp_nonfin = 0, exp_len = 0, exp_undec = 0;
#define SEND(stmt, counter) do { stmt; counter++; pump(&c, 0.005); } while (0)
    const char *unk[] = {"theta9"}, *mix[] = {"theta0", "bogus"}, *un1[] = {"theta1"},
               *un2[] = {"theta2"}, *four[] = {"theta0", "theta1", "theta2", "theta3"},
               *dup[] = {"theta0", "theta0"}, *empty[] = {""};
    double e1[] = {1.0}, e2[] = {9.0, 9.0}, e4[] = {1, 1, 1, 1};
    double enan[] = {NAN}, einf[] = {INFINITY}, eninf[] = {-INFINITY};
    SEND(command(&c, 0, 1, unk, e1), exp_unknown);
    SEND(command(&c, 0, 2, mix, e2), exp_unknown);   /* one good name does not save it */
    SEND(command(&c, 0, 1, empty, e1), exp_unknown);
    SEND(command(&c, 0, 1, un1, e1), exp_unact);
    SEND(command(&c, 0, 1, un2, e1), exp_unact);
    SEND(command(&c, 0, 1, n0, enan), exp_nonfin);
    SEND(command(&c, 0, 1, n0, einf), exp_nonfin);
    SEND(command(&c, 0, 1, n0, eninf), exp_nonfin);
    SEND(command(&c, 0, 4, four, e4), exp_len);
    SEND(command(&c, 0, 2, dup, e2), exp_len);
    uint8_t b[256];
    size_t p;
    p = raw_header(b, -1);
    SEND(publish_raw(&c, b, p), exp_len);             /* negative num_joints */
    p = raw_header(b, 30000);
    SEND(publish_raw(&c, b, p), exp_len);             /* absurd num_joints */
    SEND(publish_raw(&c, (const uint8_t *)"abc", 3), exp_undec);
    memset(b, 0xA5, sizeof b);
    SEND(publish_raw(&c, b, 200), exp_undec);         /* wrong fingerprint */
    p = raw_header(b, 1);
    SEND(publish_raw(&c, b, p), exp_undec);           /* truncated: no name */
    p = raw_header(b, 1);
    p = put_be(b, p, (uint32_t)-5, 4);                /* negative string length */
    SEND(publish_raw(&c, b, p + 16), exp_undec);
    p = raw_header(b, 1);
    p = put_be(b, p, 0x7fffffff, 4);                  /* string longer than the payload */
    SEND(publish_raw(&c, b, p + 16), exp_undec);
    p = raw_header(b, 1);
    p = put_be(b, p, 7, 4);
    memcpy(b + p, "theta0X", 7);                      /* no terminating NUL */
    p = put_be(b, p + 7, 0, 8);
    SEND(publish_raw(&c, b, p), exp_undec);
    p = raw_header(b, 1);
    p = put_be(b, p, 7, 4);
    memcpy(b + p, "theta0", 7);                       /* good name, effort cut short */
    SEND(publish_raw(&c, b, p + 7 + 4), exp_undec);
#undef SEND
    pump(&c, 0.2);
    fresh_status(&c);
    lag_wire_status *st = c.status;
    ENSURE(st->commands_accepted == 1);
    ENSUREF(st->rejected_unknown_joint == exp_unknown, "unknown %lld", (long long)st->rejected_unknown_joint);
    ENSUREF(st->rejected_unactuated == exp_unact, "unact %lld", (long long)st->rejected_unactuated);
    ENSUREF(st->rejected_nonfinite == exp_nonfin, "nonfin %lld", (long long)st->rejected_nonfinite);
    ENSUREF(st->rejected_bad_length == exp_len, "len %lld", (long long)st->rejected_bad_length);
    ENSUREF(st->rejected_undecodable == exp_undec, "undec %lld", (long long)st->rejected_undecodable);
    ENSURE(count_events(&c, "command_rejected") >= 10); /* rate limited: 10 per second */

    /* the state moved only by the good command */
    double tau[3] = {1.5, 0, 0};
    lag_sim ref;
    ref_advance(&sc, &c.last, tau, 3, &ref);
    control(&c, LAGSIM_CONTROL_T_STEP, 3, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "step_done") == 1, 3.0);
    pump(&c, 0.05);
    ensure_state_equals(&c, &ref);

    /* a flood: thousands of bad commands as fast as we can send them */
    int64_t rej0 = c.status->rejected_undecodable + c.status->rejected_nonfinite;
    for (int i = 0; i < 3000; i++) {
        publish_raw(&c, (const uint8_t *)"garbage!", 8);
        command(&c, 0, 1, n0, enan);
        if (i % 200 == 0) lcm_handle_timeout(c.lcm, 0);
    }
    pump(&c, 0.5);
    fresh_status(&c);
    st = c.status;
    int64_t flood = st->rejected_undecodable + st->rejected_nonfinite - rej0;
    ENSUREF(flood > 1000 && flood <= 6000, "flood: %lld of 6000 counted", (long long)flood);
    ENSURE(st->commands_accepted == 1);
    ref_advance(&sc, &c.last, tau, 2, &ref);
    control(&c, LAGSIM_CONTROL_T_STEP, 2, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "step_done") == 2, 3.0);
    pump(&c, 0.05);
    ensure_state_equals(&c, &ref);
    ENSURE(!c.nonfinite_seen);
    printf("hostile: flood of 6000 bad commands: %lld counted (rest dropped by the socket)\n",
           (long long)flood);
    stop_daemon(d);
}

/* The watchdog zeroes a stale command's effort, with an event and a status flag; the next
 * good command clears it. */
static void case_watchdog(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, "--set", "realtime.command_timeout=0.2", NULL);
    WAIT_FOR(&c, c.n_states > 0, 5.0);
    const char *n0[] = {"theta0"};
    double e2[] = {2.0}, e3[] = {3.0};
    command(&c, 0, 1, n0, e2);
    WAIT_FOR(&c, c.last.eff[0] == 2.0, 3.0);
    double t_applied = c.last.t;
    WAIT_FOR(&c, count_events(&c, "watchdog_trip") == 1, 3.0);
    int k = 0;
    while (strcmp(c.ev_kind[k], "watchdog_trip") != 0) k++;
    /* tripped after command_timeout of sim time, within one period more (+ arrival) */
    double age = c.ev_time[k] - t_applied;
    ENSUREF(age > 0.19 && age < 0.25, "watchdog tripped after %g s", age);
    pump(&c, 0.1);
    ENSURE(c.last.eff[0] == 0.0);
    fresh_status(&c);
    ENSURE(c.status->watchdog_tripped && c.status->watchdog_trips == 1);
    command(&c, 0, 1, n0, e3);
    WAIT_FOR(&c, count_events(&c, "watchdog_clear") == 1, 3.0);
    WAIT_FOR(&c, c.last.eff[0] == 3.0, 3.0);
    fresh_status(&c);
    ENSURE(!c.status->watchdog_tripped && c.status->watchdog_trips == 1);
    ENSURE(!c.nonfinite_seen);
    stop_daemon(d);
}

/* Lockstep waits for its controller and never steps without it.
 * 1. Started with the loader's default for lockstep (realtime.start: first_command), it
 *    waits at t = 0 (run_state waiting, no lockstep_timeout event however long), the
 *    state republished every lockstep_timeout so a late controller gets it.
 * 2. The first answer starts the run; five answered states are five periods.
 * 3. The controller goes away: after lockstep_timeout one lockstep_timeout event, then the
 *    daemon waits (waiting, sim time still), republishing that same state, never stepping:
 *    no crawl of one period per timeout.
 * 4. A command answering it resumes the run (a resume event, running). */
static void case_lockstep_timeout(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, "--set", "realtime.mode=lockstep", "--set",
                           "realtime.lockstep_timeout=0.05", NULL);
    WAIT_FOR(&c, c.n_states >= 4, 5.0);
    fresh_status(&c);
    ENSURE(strcmp(c.status->mode, "lockstep") == 0);
    ENSUREF(strcmp(c.status->run_state, "waiting") == 0 && c.status->step == 0 &&
                c.status->lockstep_timeouts == 0,
            "at start: %s, step %lld, %lld timeouts", c.status->run_state,
            (long long)c.status->step, (long long)c.status->lockstep_timeouts);
    ENSURE(count_events(&c, "lockstep_timeout") == 0 && c.last.t == 0.0);

    const char *n0[] = {"theta0"};
    double e[] = {0.5};
    for (int k = 0; k < 5; k++) { /* answer t = 0, 0.01, ..., 0.04 */
        double t = c.last.t;
        command(&c, t, 1, n0, e);
        WAIT_FOR(&c, c.last.t > t, 3.0);
    }
    double t_wait = c.last.t; /* 0.05: published, never answered */
    ENSURE(c.last.step == 50);
    /* an answer above may itself have come later than 0.05 s (this process not scheduled
     * in time on a loaded machine): a timeout of its own, its event published before the
     * next state */
    int late = count_events(&c, "lockstep_timeout");
    WAIT_FOR(&c, count_events(&c, "lockstep_timeout") == late + 1, 3.0);
    int64_t n0_states = c.n_states;
    pump(&c, 0.5); /* ten timeouts' worth of waiting */
    fresh_status(&c);
    ENSUREF(count_events(&c, "lockstep_timeout") == late + 1 &&
                c.status->lockstep_timeouts == late + 1,
            "%d lockstep_timeout events, %lld counted (%d of late answers before)",
            count_events(&c, "lockstep_timeout"), (long long)c.status->lockstep_timeouts, late);
    ENSUREF(strcmp(c.status->run_state, "waiting") == 0 && c.status->step == 50 &&
                c.last.t == t_wait,
            "after the timeout: %s at step %lld, last state at %g s", c.status->run_state,
            (long long)c.status->step, c.last.t);
    ENSUREF(c.n_states - n0_states >= 3, "the waited-on state republished %lld times in 0.5 s",
            (long long)(c.n_states - n0_states));

    int resumes = count_events(&c, "resume");
    command(&c, t_wait, 1, n0, e);
    WAIT_FOR(&c, c.last.t > t_wait, 3.0);
    ENSURE(c.last.step == 60);
    WAIT_FOR(&c, count_events(&c, "resume") == resumes + 1, 3.0);
    fresh_status(&c);
    ENSURE(strcmp(c.status->run_state, "running") == 0);
    ENSURE(!c.nonfinite_seen);
    stop_daemon(d);
}

/* Two daemons with different prefixes do not hear each other. */
static void case_two_daemons(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    char pa[80], pb[80];
    snprintf(pa, sizeof pa, "%sA", g_prefix);
    snprintf(pb, sizeof pb, "%sB", g_prefix);
    static client a, b;
    client_init(&a, pa, 3);
    client_init(&b, pb, 3);
    pid_t da = start_daemon(pa, NULL);
    pid_t db = start_daemon(pb, NULL);
    WAIT_FOR(&a, a.n_states > 0, 5.0);
    WAIT_FOR(&b, b.n_states > 0, 5.0);
    control(&a, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL);
    WAIT_FOR(&a, count_events(&a, "pause") == 1, 3.0);
    const char *n0[] = {"theta0"};
    double e5[] = {5.0};
    command(&a, 0, 1, n0, e5);
    pump(&a, 0.1);
    double tb0 = b.last.t;
    rec_state ha = a.last;
    pump(&b, 0.3);
    pump(&a, 0.1);
    ENSURE(b.last.t > tb0 + 0.05);         /* B was not paused by A's control (0.3 s) */
    ENSURE(b.last.eff[0] == 0.0);          /* nor driven by A's command */
    ENSURE(a.last.step == ha.step);        /* A stays paused */
    ENSURE(count_events(&b, "pause") == 0);
    fresh_status(&a);
    fresh_status(&b);
    ENSURE(a.status->commands_accepted == 1 && b.status->commands_accepted == 0);
    ENSURE(strcmp(a.status->run_state, "paused") == 0 && strcmp(b.status->run_state, "running") == 0);
    kill(da, SIGTERM);
    kill(db, SIGTERM);
    ENSURE(reap(da, 5.0) == 0 && reap(db, 5.0) == 0);
}

/* A numeric fault pauses in the fault state with an event; no bad state is ever
 * published; reset recovers. The cart starts at 20 m/s with explode_limit 30 (the rods
 * upright at rest stay so): |theta0| passes 30 m after 1.5 s. */
static void case_fault(int arg)
{
    (void)arg;
    write_scene("model: dipc\n"
                "initial:\n"
                "  qd: [20, 0, 0]\n"
                "explode_limit: 30\n"
                "publish_hz: 100\n");
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, count_events(&c, "numeric_fault") == 1, 5.0);
    WAIT_FOR(&c, c.status && strcmp(c.status->run_state, "fault") == 0, 3.0);
    ENSURE(c.status->numeric_faults == 1);
    ENSUREF(c.max_abs <= 30.0 && c.last.q[0] <= 30.0, "published |x| up to %g, last x %g",
            c.max_abs, c.last.q[0]);
    ENSUREF(c.last.t >= 1.4 && c.last.t <= 1.5, "last state published at %g s", c.last.t);
    int64_t n0 = c.n_states;
    pump(&c, 0.3);
    ENSURE(c.n_states == n0); /* nothing more is published in the fault state */
    control(&c, LAGSIM_CONTROL_T_RESUME, 0, 0, NULL, NULL);
    WAIT_FOR(&c, count_events(&c, "control_rejected") == 1, 3.0);
    double q[3] = {0, 0, 0}, qd[3] = {0.5, 0, 0};
    control(&c, LAGSIM_CONTROL_T_RESET_TO, 0, 3, q, qd);
    WAIT_FOR(&c, count_events(&c, "reset") == 1, 3.0);
    pump(&c, 0.05);
    ENSURE(c.last.step == 0 && c.last.qd[0] == 0.5);
    fresh_status(&c);
    ENSURE(strcmp(c.status->run_state, "paused") == 0);
    control(&c, LAGSIM_CONTROL_T_RESUME, 0, 0, NULL, NULL);
    WAIT_FOR(&c, c.last.t >= 0.5, 3.0);
    /* upright at rest with the cart coasting: x = 0.5 t exactly in theory */
    ENSUREF(fabs(c.last.q[0] - 0.5 * c.last.t) < 1e-9, "x %.17g at t %g", c.last.q[0], c.last.t);
    ENSURE(count_events(&c, "numeric_fault") == 1);
    ENSURE(!c.nonfinite_seen);
    stop_daemon(d);
}

/* Runs one lockstep run of 2 s sim time with the test's deterministic controller.
 * Returns the number of states recorded into c->rec. */
static void lockstep_run(client *c, const char *prefix, const char *method)
{
    char set_m[96];
    snprintf(set_m, sizeof set_m, "integrator.method=%s", method);
    pid_t d = start_daemon(prefix, "--set", "realtime.mode=lockstep", "--set", set_m,
                           "--duration", "2", NULL);
    double t_end = now_s() + 30;
    while (waitpid(d, NULL, WNOHANG) == 0) {
        ENSURE(now_s() < t_end);
        lcm_handle_timeout(c->lcm, 20);
    }
    for (int i = 0; i < g_nchildren; i++)
        if (g_children[i] == d) g_children[i] = 0;
    pump(c, 0.1);
}

/* Whether the file at path holds the bytes needle (n of them): a log small enough to read */
static bool file_holds(const char *path, const char *needle, size_t n)
{
    static char buf[1 << 22];
    FILE *f = fopen(path, "rb");
    if (!f) return false;
    size_t got = fread(buf, 1, sizeof buf, f);
    fclose(f);
    for (size_t i = 0; i + n <= got; i++)
        if (memcmp(buf + i, needle, n) == 0) return true;
    return false;
}

/* One attempt of the replay case. Returns false when UDP lost messages (the logger or
 * this client missed some: on a loaded machine with parallel tests flooding the same
 * multicast group, the socket buffers overflow), so the caller retries; any real
 * mismatch fails the test at once. */
static bool replay_attempt(const char *logger, const char *method, int attempt)
{
    char log_path[256], chan[96], prefix[80];
    snprintf(prefix, sizeof prefix, "%sR%d", g_prefix, attempt);
    snprintf(log_path, sizeof log_path, "/tmp/lagsim_server_test_%d_%s.lcm", (int)getpid(), g_case);
    remove(log_path);
    snprintf(chan, sizeof chan, "%s_.*", prefix);
    char *largv[] = {(char *)logger, "-q", "-f", "-c", chan, log_path, NULL};
    static client c1, c2;
    client_free_all();
    client_init(&c1, prefix, 3);
    c1.controller = true;
    pid_t lg = spawn(largv, true);
    /* wait until the logger records: a probe shows up in its file (flushed every 100 ms) */
    char probe_ch[96];
    snprintf(probe_ch, sizeof probe_ch, "%s_PROBE", prefix);
    double t_probe = now_s() + 30;
    for (;;) {
        lcm_publish(c1.lcm, probe_ch, "probe", 5);
        usleep(50000);
        FILE *lf = fopen(log_path, "rb");
        long sz = 0;
        if (lf) {
            fseek(lf, 0, SEEK_END);
            sz = ftell(lf);
            fclose(lf);
        }
        if (sz > 0) break;
        ENSUREF(now_s() < t_probe, "lcm-logger does not record");
    }
    lockstep_run(&c1, prefix, method);
    /* the logger has written what it heard of the run once a probe sent after the run is
     * in its file (one socket, read in order; flushed every 100 ms): on a loaded machine
     * it may be seconds behind the bus, not 0.3 s */
    t_probe = now_s() + 30;
    char end[32];
    int n_end = snprintf(end, sizeof end, "end-of-run-%d", attempt);
    while (!file_holds(log_path, end, (size_t)n_end)) {
        lcm_publish(c1.lcm, probe_ch, end, n_end);
        usleep(50000);
        ENSUREF(now_s() < t_probe, "lcm-logger did not write a probe sent after the run");
    }
    kill(lg, SIGINT);
    ENSURE(reap(lg, 5.0) >= 0);
    ENSURE(!c1.nonfinite_seen);
    ENSURE(c1.status);
    if (c1.n_rec != 201 || c1.status->lockstep_timeouts != 0) {
        printf("attempt %d: this client missed states (%d of 201, %lld lockstep timeouts): retry\n",
               attempt, c1.n_rec, (long long)c1.status->lockstep_timeouts);
        return false;
    }
    ENSURE(c1.status->commands_accepted == 200);

    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s --config %s --set lcm.prefix=%s --set integrator.method=%s "
             "--replay %s", g_lagsimd, g_scene_path, prefix, method, log_path);
    FILE *p = popen(cmd, "r");
    ENSURE(p);
    char line[512];
    long compared = -1, gaps = -1;
    double diff = -1;
    while (fgets(line, sizeof line, p)) {
        fputs(line, stdout);
        if (strncmp(line, "replay ", 7) == 0) {
            char *colon = strstr(line, ": ");
            char *g = strstr(line, "resets, ");
            if (colon) compared = strtol(colon + 2, NULL, 10);
            if (g) gaps = strtol(g + 8, NULL, 10);
        }
        if (strncmp(line, "max difference = ", 17) == 0) diff = strtod(line + 17, NULL);
    }
    ENSURE(pclose(p) == 0);
    remove(log_path);
    /* Every state at least once and no gap: lcm-logger records what the bus carries, and a
     * state the client answered later than the daemon's first retry (20 ms: a loaded
     * machine) is on the bus again, byte for byte, and compared again (seen: 201 to 234
     * compared, 0 gaps, difference 0). Fewer, or a gap, is what UDP lost. */
    if (compared < 200 || gaps != 0) {
        printf("attempt %d: the logger missed states (%ld compared, %ld gaps): retry\n",
               attempt, compared, gaps);
        return false;
    }
    ENSUREF(diff == 0.0, "replay difference %.17g", diff);

    /* the same again: bit-identical states */
    client_init(&c2, prefix, 3);
    c2.controller = true;
    lockstep_run(&c2, prefix, method);
    if (c2.n_rec != c1.n_rec) {
        printf("attempt %d: this client missed states in the second run: retry\n", attempt);
        return false;
    }
    for (int i = 0; i < c1.n_rec; i++)
        ENSUREF(memcmp(&c1.rec[i], &c2.rec[i], sizeof c1.rec[i]) == 0, "state %d differs", i);
    /* and the run did something: the controller moved the cart */
    ENSURE(fabs(c1.rec[c1.n_rec - 1].q[0]) > 1e-3);
    return true;
}

/* lcm-logger records a lockstep run; lagsimd --replay re-simulates it with difference
 * exactly 0; a second run gives a bit-identical state stream. */
enum { REPLAY_RK4, REPLAY_DOPRI5, REPLAY_EFFECTS, REPLAY_FLIGHT };
static void case_replay(int variant)
{
    const char *logger = lt_arg(1), *method = variant == REPLAY_DOPRI5 ? "dopri5" : "rk4";
    if (!logger) {
        lt_skip("no LCM_LOGGER given");
        return;
    }
    if (variant == REPLAY_EFFECTS)
        /* effects the replay must re-simulate exactly: damping, a stop on the cart,
         * scheduled disturbances, actuator saturation, noise on the published state */
        write_scene("model: dipc\n"
                    "initial:\n  q: [0, 0.1, -0.05]\n"
                    "publish_hz: 100\n"
                    "effects:\n"
                    "  damping: {theta1: 0.01, theta2: 0.01}\n"
                    "  limits: {theta0: {lower: -0.05, upper: 0.05, restitution: 0.5}}\n"
                    "  disturbance:\n"
                    "    - {t: 0.5, joint: theta1, impulse: 0.02}\n"
                    "    - {t: 1.0, joint: theta0, force: 1.0, duration: 0.2}\n"
                    "  actuator: {theta0: {max: 0.8}}\n"
                    "  noise: {seed: 11, q: {theta1: 1e-3}, qd: {theta0: 1e-2}}\n");
    else if (variant == REPLAY_FLIGHT)
        /* a stick that lifts off, flies, lands and slides, pushed along x: three joints
         * published (x, phi, h), the floor's events located inside the ticks */
        write_scene("model: stick\n"
                    "initial:\n  q: [0, 0.5]\n  qd: [0.4, 12]\n"
                    "publish_hz: 100\n"
                    "effects:\n  floor: {restitution: 0.5}\n");
    else
        write_scene(DIPC_MOVING);
    for (int attempt = 1; attempt <= 6; attempt++)
        if (replay_attempt(logger, method, attempt)) return;
    LT_FAIL("UDP lost messages in every attempt");
}

/* SIGTERM: a final status, exit 0. */
static void case_sigterm(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, c.n_states > 5 && c.n_status > 0, 5.0);
    pump(&c, 0.1);
    int64_t ns = c.n_status;
    stop_daemon(d);
    pump(&c, 0.2);
    ENSURE(c.n_status > ns);
    ENSURE(count_events(&c, "stop") == 1);
    ENSURE(c.status->sim_time > 0 && strcmp(c.status->run_state, "running") == 0);
}

/* A bad scene exits 2 before anything is published. */
/* The effects' events go out on _EVENT with the sim time the step located them at: the
 * stick's floor impacts and its resting contact must be exactly those of the core run by
 * itself on the same scene; a lift-off is an event and then a numeric fault. */
static void ref_events(const lag_scene *sc, int periods, const char *kind, double *t, int *n,
                       lag_result *last)
{
    char err[256];
    static lag_sim ref;
    ENSURE(lag_sim_init(&ref, &sc->sim, err, sizeof err) == LAG_OK);
    *n = 0;
    *last = LAG_OK;
    for (int k = 0; k < periods && *last == LAG_OK; k++) {
        *last = lag_sim_advance(&ref, sc->ticks_per_period, false);
        lag_event ev;
        while (lag_sim_poll_event(&ref, &ev))
            if (!strcmp(lag_event_kind_name(ev.kind), kind) && *n < 64) t[(*n)++] = ev.t;
    }
}

static void ensure_event_times(const client *c, const char *kind, const double *t, int n)
{
    int j = 0;
    for (int i = 0; i < c->n_events; i++) {
        if (strcmp(c->ev_kind[i], kind) != 0) continue;
        ENSUREF(j < n, "more '%s' events than the core located (%d)", kind, n);
        ENSUREF(c->ev_time[i] == t[j], "'%s' %d at %.17g s, the core located it at %.17g s",
                kind, j, c->ev_time[i], t[j]);
        j++;
    }
    ENSUREF(j == n, "%d '%s' events published, the core located %d", j, kind, n);
}

static void case_effects(int arg)
{
    (void)arg;
    write_scene("model: stick\n"
                "initial:\n  q: [0, 1.2]\n"
                "realtime:\n  mode: fast\n"
                "effects:\n  floor: {restitution: 0.5}\n");
    static client c;
    client_init(&c, g_prefix, 2);
    pid_t d = start_daemon(g_prefix, "--duration", "2", NULL);
    ENSURE(reap(d, 20.0) == 0);
    pump(&c, 0.5);
    lag_scene sc;
    load_ref(&sc, g_prefix);
    double t_imp[64], t_rest[64];
    int n_imp, n_rest;
    lag_result r;
    ref_events(&sc, 200, "impact", t_imp, &n_imp, &r);
    ENSURE(r == LAG_OK);
    ref_events(&sc, 200, "rest", t_rest, &n_rest, &r);
    ENSURE(n_imp >= 3 && n_rest == 1);
    ensure_event_times(&c, "impact", t_imp, n_imp);
    ensure_event_times(&c, "rest", t_rest, n_rest);
    ENSURE(!c.nonfinite_seen);
    printf("effects: %d impacts (first at %.12f s) and a rest at %.12f s, as the core located them\n",
           n_imp, t_imp[0], t_rest[0]);

    /* spun fast enough to lift off, on a floor it may not leave: an event, then a fault;
     * nothing bad published */
    write_scene("model: stick\n"
                "initial:\n  q: [0, 0.6]\n  qd: [0, 5]\n"
                "realtime:\n  mode: fast\n"
                "effects:\n  floor: {flight: false}\n");
    char prefix2[80];
    snprintf(prefix2, sizeof prefix2, "%s_L", g_prefix);
    static client c2;
    client_init(&c2, prefix2, 2);
    start_daemon(prefix2, NULL);
    WAIT_FOR(&c2, count_events(&c2, "numeric_fault") >= 1, 10.0);
    pump(&c2, 0.2);
    load_ref(&sc, prefix2);
    double t_lift[64];
    int n_lift;
    ref_events(&sc, 100, "liftoff", t_lift, &n_lift, &r);
    ENSURE(r == LAG_ERR_LIFTOFF && n_lift == 1);
    ensure_event_times(&c2, "liftoff", t_lift, n_lift);
    fresh_status(&c2);
    ENSUREF(!strcmp(c2.status->run_state, "fault"), "run_state %s", c2.status->run_state);
    ENSUREF(!strcmp(c2.status->contact, ""), "contact '%s' without flight", c2.status->contact);
    ENSURE(!c2.nonfinite_seen && c2.last.t < t_lift[0]);
    printf("effects: lift-off at %.12f s published, then the fault state; last state %.2f s\n",
           t_lift[0], c2.last.t);

    /* the same spin on a floor it may leave: it flies and lands; the scene and the states
     * carry the third joint h (the lower end's height), the events come at the core's
     * instants, and it ends lying on the floor */
    write_scene("model: stick\n"
                "initial:\n  q: [0, 0.5]\n  qd: [0.4, 12]\n"
                "realtime:\n  mode: fast\n"
                "effects:\n  floor: {restitution: 0.5}\n");
    char prefix3[80];
    snprintf(prefix3, sizeof prefix3, "%s_F", g_prefix);
    static client c3;
    client_init(&c3, prefix3, 3);
    d = start_daemon(prefix3, "--duration", "3", NULL);
    ENSURE(reap(d, 20.0) == 0);
    pump(&c3, 0.5);
    load_ref(&sc, prefix3);
    double t_land[64];
    int n_land;
    ref_events(&sc, 300, "liftoff", t_lift, &n_lift, &r);
    ENSURE(r == LAG_OK && n_lift >= 1);
    ref_events(&sc, 300, "landing", t_land, &n_land, &r);
    ENSURE(r == LAG_OK && n_land >= 1);
    ensure_event_times(&c3, "liftoff", t_lift, n_lift);
    ensure_event_times(&c3, "landing", t_land, n_land);
    ENSURE(c3.scene && strcmp(c3.scene->model, "stick") == 0 && c3.scene->num_joints == 3);
    ENSURE(c3.scene && strcmp(c3.scene->joint_name[2], "h") == 0 && !c3.scene->actuated[2]);
    ENSURE(!c3.nonfinite_seen && c3.last.t == 3.0 && c3.last.q[2] == 0.0 && c3.last.qd[1] == 0.0);
    ENSUREF(c3.status && !strcmp(c3.status->contact, "flat"), "contact '%s' in the last status",
            c3.status ? c3.status->contact : "(none)");
    printf("effects: a stick spun up flies: lift-off at %.12f s, landing at %.12f s, as the core "
           "located them; joints x, phi, h; at 3 s h = %g\n",
           t_lift[0], t_land[0], c3.last.q[2]);
}

static void case_bad_scene(int arg)
{
    (void)arg;
    write_scene("model: dipc\nparameters:\n  m0: -1.5\n");
    static client c;
    client_init(&c, g_prefix, 3);
    int n_any = 0;
    pid_t d = start_daemon(g_prefix, NULL);
    ENSURE(reap(d, 10.0) == 2);
    write_scene("model: dipc\nrealtime:\n  mode: sometimes\n");
    d = start_daemon(g_prefix, NULL);
    ENSURE(reap(d, 10.0) == 2);
    /* a prefix too long for LCM's 63-character channel names with _COMMAND */
    write_scene("model: dipc\n");
    char longp[61];
    memset(longp, 'P', 60);
    memcpy(longp, g_prefix, strlen(g_prefix) < 40 ? strlen(g_prefix) : 40);
    longp[60] = '\0';
    d = start_daemon(longp, NULL);
    ENSURE(reap(d, 10.0) == 2);
    pump(&c, 0.3);
    n_any = (int)(c.n_states + c.n_status + c.n_events + c.n_scene);
    ENSURE(n_any == 0);
}


/* ---------------------------------------------------------------- bounded output, any settings */
/* The last event of a kind (its index), or -1. */
static int last_event(const client *c, const char *kind)
{
    for (int i = c->n_events - 1; i >= 0; i--)
        if (!strcmp(c->ev_kind[i], kind)) return i;
    return -1;
}

/* CPU seconds (user + system) a child has used so far. */
static double cpu_of(pid_t pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    ENSURE(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    char *p = strrchr(buf, ')');
    ENSURE(p);
    unsigned long ut = 0, st = 0;
    /* after "pid (comm)": state ppid pgrp session tty tpgid flags minflt cminflt majflt
     * cmajflt utime stime */
    ENSURE(sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &ut, &st) == 2);
    return (double)(ut + st) / (double)sysconf(_SC_CLK_TCK);
}

/* Whether the loader (or the daemon) refused a setting at start: it exits with 2 before
 * publishing anything. Otherwise its first state arrives and the caller checks how it
 * runs. Waits for one or the other (a loaded machine may take seconds to start it). */
static bool refused_at_start(pid_t d, client *c)
{
    double t_end = now_s() + 20.0;
    int st;
    while (c->n_states == 0) {
        ENSUREF(now_s() < t_end, "the daemon neither exited nor published a state");
        pid_t r = waitpid(d, &st, WNOHANG);
        if (r == d) {
            for (int i = 0; i < g_nchildren; i++)
                if (g_children[i] == d) g_children[i] = 0;
            ENSUREF(WIFEXITED(st) && WEXITSTATUS(st) == 2, "the daemon ended at start, not with exit 2");
            ENSURE(c->n_states == 0);
            return true;
        }
        lcm_handle_timeout(c->lcm, 20);
    }
    return false;
}

/* A flood on _CONTROL (bad requests and valid STATUS, DESCRIBE and RESET ones, several
 * thousand in about a second) is answered by a bounded number of messages: each event kind
 * by its bucket (10, then 10 per second), statuses and scene descriptions coalesced and
 * limited. Everything is counted. */
static void case_control_flood(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, c.n_states > 5 && c.n_status > 0 && c.n_scene > 0, 5.0);
    pump(&c, 0.3);
    int64_t ev0 = c.n_events_total, st0 = c.n_status, sc0 = c.n_scene;
    double t0 = now_s();
    uint8_t garbage[16] = "not a control";
    int sent = 0, bad = 0, resets = 0;
    for (int k = 0; k < 4000; k++) {
        switch (k % 5) {
        case 0: lcm_publish(c.lcm_in, c.ch_control, garbage, sizeof garbage); bad++; break;
        case 1: control(&c, 99, 0, 0, NULL, NULL); bad++; break;
        case 2: control(&c, LAGSIM_CONTROL_T_STATUS, 0, 0, NULL, NULL); break;
        case 3: control(&c, LAGSIM_CONTROL_T_DESCRIBE, 0, 0, NULL, NULL); break;
        case 4: control(&c, LAGSIM_CONTROL_T_RESET, 0, 0, NULL, NULL); resets++; break;
        }
        sent++;
        if (k % 100 == 99) lcm_handle_timeout(c.lcm, 5);
    }
    pump(&c, 1.5);
    double window = now_s() - t0;
    int64_t ev = c.n_events_total - ev0, st = c.n_status - st0, sc = c.n_scene - sc0;
    printf("control flood: %d requests, then %lld events, %lld statuses, %lld scenes in %.1f s\n",
           sent, (long long)ev, (long long)st, (long long)sc, window);
    /* control_rejected and reset: 10 + 10/s each; statuses 5 + 20/s + 5/s periodic;
     * scenes 2 + 5/s for DESCRIBE, and one per reset applied, which RESET's bucket bounds
     * (50 + 50/s: rt_control.h) (window rounded up to 3 s) */
    ENSUREF(ev <= 2 * (10 + 10 * 3), "%lld events", (long long)ev);
    ENSUREF(st <= 5 + 25 * 3, "%lld statuses", (long long)st);
    ENSUREF(sc <= 2 + 5 * 3 + 50 + 50 * 3, "%lld scenes", (long long)sc);
    fresh_status(&c);
    /* counted (UDP and LCM's queue drop some of a flood: what reached the daemon), and
     * more than were answered one by one */
    int64_t rej = c.status->controls_rejected;
    printf("control flood: %lld of %d bad requests counted, %d control_rejected events\n",
           (long long)rej, bad, count_events(&c, "control_rejected"));
    /* the bad ones, and the resets over RESET's bucket */
    ENSUREF(rej > count_events(&c, "control_rejected") && rej <= bad + resets,
            "%lld controls rejected of %d sent", (long long)rej, bad + resets);
    /* and it still answers */
    control(&c, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL);
    WAIT_FOR(&c, last_event(&c, "pause") >= 0, 3.0);
    ENSURE(!c.nonfinite_seen);
    stop_daemon(d);
}

/* Anything on the state URL but the plant's four output channels (and LCM's self-test,
 * which every lcm_t sends once on its own URL). */
static void on_any_state_url(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)rb;
    client *c = u;
    size_t n = strlen(c->prefix);
    const char *outs[] = {"_STATE", "_STATUS", "_EVENT", "_SCENE"};
    if (!strcmp(ch, "LCM_SELF_TEST")) return;
    if (!strncmp(ch, c->prefix, n))
        for (int k = 0; k < 4; k++)
            if (!strcmp(ch + n, outs[k])) return;
    c->foreign_on_state_url++;
}

/* A flood of commands (a child publishing valid heartbeats as fast as it can for 2 s)
 * reaches the daemon on the command URL and never the sockets of those who listen on the
 * state URL: a state subscriber receives none of it and misses no state meanwhile. */
static void case_command_flood_ports(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    lag_scene sc;
    load_ref(&sc, g_prefix);
    c.tpp = sc.ticks_per_period;
    lcm_subscription_t *all = lcm_subscribe(c.lcm, ".*", on_any_state_url, &c);
    lcm_subscription_set_queue_capacity(all, 100000);
    pid_t d = start_daemon(g_prefix, "--set", "realtime.command_timeout=100", NULL);
    WAIT_FOR(&c, c.n_states > 5 && c.n_scene > 0, 5.0);
    pump(&c, 0.2);
    fresh_status(&c);
    int64_t acc0 = c.status->commands_accepted, n0 = c.n_states, step0 = c.last.step;
    c.missing = 0;
    pid_t fl = fork();
    if (fl == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        lag_bus bus;
        char berr[256];
        if (lag_bus_init(&bus, NULL, g_prefix, berr, sizeof berr) != 0) _exit(2);
        lcm_t *in = lcm_create(bus.command_url);
        if (!in) _exit(2);
        lagsim_joint_command_t hb = {0, 0.0, 0, NULL, NULL}; /* valid: changes no effort */
        long sent = 0;
        for (double t_end = now_s() + 2.0; now_s() < t_end; sent++)
            lagsim_joint_command_t_publish(in, bus.channel[LAG_BUS_COMMAND], &hb);
        printf("command flood: %ld heartbeats in 2 s\n", sent);
        fflush(stdout);
        lcm_destroy(in);
        _exit(0);
    }
    ENSURE(fl > 0);
    pump(&c, 2.5);
    int st;
    ENSURE(waitpid(fl, &st, 0) == fl && WIFEXITED(st) && WEXITSTATUS(st) == 0);
    pump(&c, 0.3);
    fresh_status(&c);
    int64_t acc = c.status->commands_accepted - acc0;
    printf("command flood: daemon accepted %lld; state subscriber: %lld states (steps %lld to "
           "%lld), %lld missing, %lld messages of other channels\n", (long long)acc,
           (long long)(c.n_states - n0), (long long)step0, (long long)c.last.step,
           (long long)c.missing, (long long)c.foreign_on_state_url);
    ENSUREF(acc > 1000, "the daemon accepted only %lld of the flood's commands", (long long)acc);
    ENSUREF(c.foreign_on_state_url == 0, "%lld commands reached a socket on the state URL",
            (long long)c.foreign_on_state_url);
    ENSUREF(c.missing == 0, "the state subscriber missed %lld states during the flood",
            (long long)c.missing);
    ENSURE(c.n_states - n0 >= 200 && !c.nonfinite_seen);
    lcm_unsubscribe(c.lcm, all);
    stop_daemon(d);
}

/* STEP with count 2^62 while paused goes at the mode's pace (realtime: 100 periods a
 * second at 100 Hz), not as fast as the machine can publish; PAUSE ends it. */
static void case_step_flood(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, c.n_states > 2, 5.0);
    control(&c, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL);
    WAIT_FOR(&c, last_event(&c, "pause") >= 0, 3.0);
    pump(&c, 0.1);
    control(&c, LAGSIM_CONTROL_T_STEP, (int64_t)1 << 62, 0, NULL, NULL);
    WAIT_FOR(&c, last_event(&c, "step") >= 0, 3.0);
    int64_t n0 = c.n_states, step0 = c.last.step;
    double t0 = now_s();
    pump(&c, 1.0);
    double wall = now_s() - t0;
    int64_t n = c.n_states - n0;
    printf("step 2^62: %lld states in %.2f s\n", (long long)n, wall);
    /* at most one state per 10 ms deadline, counting those since the step began (up to
     * 0.5 s before the window on a loaded machine), and the one republished at the step */
    ENSUREF(n <= (int64_t)((wall + 0.5) * 100) + 2, "%lld states in %.2f s", (long long)n, wall);
    ENSURE(c.last.step > step0); /* and it does step */
    control(&c, LAGSIM_CONTROL_T_PAUSE, 0, 0, NULL, NULL);
    pump(&c, 0.2);
    int64_t held = c.last.step;
    pump(&c, 0.3);
    ENSURE(c.last.step == held);
    stop_daemon(d);
}

/* lockstep_timeout 1e10 s (or 1e300): the daemon waits for its controller, quietly and
 * without spinning: no lockstep_timeout event, no period, little CPU. */
static void case_lockstep_huge(int arg)
{
    (void)arg;
    const char *values[] = {"realtime.lockstep_timeout=1e10", "realtime.lockstep_timeout=1e300"};
    for (int i = 0; i < 2; i++) {
        write_scene(DIPC_MOVING);
        static client c;
        client_free_all();
        char prefix[80];
        snprintf(prefix, sizeof prefix, "%s%d", g_prefix, i);
        client_init(&c, prefix, 3);
        pid_t d = start_daemon(prefix, "--set", "realtime.mode=lockstep", "--set", values[i], NULL);
        if (refused_at_start(d, &c)) {
            printf("%s: refused at start\n", values[i]);
            continue;
        }
        WAIT_FOR(&c, c.n_states >= 1, 5.0);
        double cpu0 = cpu_of(d);
        pump(&c, 1.0);
        double cpu = cpu_of(d) - cpu0;
        fresh_status(&c);
        printf("%s: %lld states, %d events, %.3f s CPU in 1 s\n", values[i],
               (long long)c.n_states, c.n_events, cpu);
        ENSURE(c.n_states == 1 && c.status->step == 0 && c.status->lockstep_timeouts == 0);
        ENSURE(last_event(&c, "lockstep_timeout") < 0);
        ENSUREF(cpu < 0.2, "%.3f s of CPU in 1 s of waiting", cpu);
        stop_daemon(d);
    }
}

/* status_hz 1e9: at most 100 statuses a second; 1e-300: none but the first. */
static void case_status_rate(int arg)
{
    (void)arg;
    const char *values[] = {"realtime.status_hz=1e9", "realtime.status_hz=1e-300"};
    const int64_t most[] = {100 + 5, 1};
    for (int i = 0; i < 2; i++) {
        write_scene(DIPC_MOVING);
        static client c;
        client_free_all();
        char prefix[80];
        snprintf(prefix, sizeof prefix, "%s%d", g_prefix, i);
        client_init(&c, prefix, 3);
        pid_t d = start_daemon(prefix, "--set", values[i], NULL);
        if (refused_at_start(d, &c)) {
            printf("%s: refused at start\n", values[i]);
            continue;
        }
        WAIT_FOR(&c, c.n_states >= 2, 5.0);
        int64_t s0 = c.n_status;
        double t0 = now_s();
        pump(&c, 1.0);
        double wall = now_s() - t0;
        int64_t n = c.n_status - s0;
        printf("%s: %lld statuses in %.2f s\n", values[i], (long long)n, wall);
        ENSUREF(n <= (int64_t)(most[i] * wall) + 1, "%lld statuses in %.2f s", (long long)n, wall);
        stop_daemon(d);
    }
}

/* realtime.rate 1e25 (a wall period of 1e-27 s) or 1e6: sim time advances as fast as the
 * loop goes; the overrun_burst events stay within their bucket (3, then 1 per second). */
static void case_rate_huge(int arg)
{
    (void)arg;
    const char *values[] = {"realtime.rate=1e25", "realtime.rate=1e6"};
    for (int i = 0; i < 2; i++) {
        write_scene(DIPC_MOVING);
        static client c;
        client_free_all();
        char prefix[80];
        snprintf(prefix, sizeof prefix, "%s%d", g_prefix, i);
        client_init(&c, prefix, 3);
        pid_t d = start_daemon(prefix, "--set", values[i], NULL);
        if (refused_at_start(d, &c)) {
            printf("%s: refused at start\n", values[i]);
            continue;
        }
        WAIT_FOR(&c, c.n_states >= 1, 5.0);
        double t0 = now_s();
        pump(&c, 1.0);
        fresh_status(&c);
        double wall = now_s() - t0;
        int bursts = count_events(&c, "overrun_burst");
        printf("%s: sim time %.2f s after %.2f s, %d overrun_burst events (%lld re-bases)\n",
               values[i], c.status->sim_time, wall, bursts, (long long)c.status->overrun_bursts);
        ENSUREF(c.status->sim_time > 0.5, "sim time %g", c.status->sim_time);
        ENSUREF(bursts <= 3 + (int)wall + 2, "%d overrun_burst events", bursts);
        stop_daemon(d);
    }
}

/* A control period of 1e12 ticks (fast mode, publish_hz 1e-9): the daemon still serves
 * signals: SIGTERM stops it at once, with its stop event and final status. */
static void case_long_period(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, "--set", "realtime.mode=fast", "--set", "publish_hz=1e-9", NULL);
    if (refused_at_start(d, &c)) {
        printf("publish_hz 1e-9: refused at start\n");
        return;
    }
    WAIT_FOR(&c, c.n_states >= 1 && c.n_status >= 1, 5.0);
    pump(&c, 0.5);
    fresh_status(&c); /* LCM is served too */
    ENSURE(c.status->step > 0);
    kill(d, SIGTERM);
    ENSUREF(reap(d, 3.0) == 0, "SIGTERM did not stop a daemon inside a long period");
    pump(&c, 0.2);
    ENSURE(count_events(&c, "stop") == 1);
}

/* --duration beyond what a run can count (1e300 s, 1e16 s) is refused (exit 2), in real
 * time and offline, instead of ending at once with exit 0. */
static void case_duration_huge(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    const char *durations[] = {"1e300", "1e16"};
    for (int i = 0; i < 2; i++) {
        pid_t d = start_daemon(g_prefix, "--set", "realtime.mode=fast", "--duration", durations[i], NULL);
        int rc = reap(d, 5.0);
        ENSUREF(rc == 2, "--duration %s: exit %d", durations[i], rc);
        char *argv[] = {g_lagsimd, "--config", g_scene_path, "--offline", "--duration",
                        (char *)durations[i], NULL};
        d = spawn(argv, true);
        rc = reap(d, 5.0);
        ENSUREF(rc == 2, "--offline --duration %s: exit %d", durations[i], rc);
    }
    pump(&c, 0.2);
    ENSURE(c.n_states == 0);
}

/* SIGHUP stops like SIGTERM (stop event naming it, final status, exit 0); SIGUSR1 asks
 * for a status and stops nothing; SIGQUIT stops. */
static void case_signals(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, c.n_states > 5 && c.n_status > 0, 5.0);
    pump(&c, 0.1);
    int64_t ns = c.n_status;
    kill(d, SIGUSR1);
    WAIT_FOR(&c, c.n_status > ns, 3.0);
    kill(d, SIGUSR2);
    pump(&c, 0.3);
    ENSURE(waitpid(d, NULL, WNOHANG) == 0); /* still running */
    ns = c.n_status;
    kill(d, SIGHUP);
    ENSURE(reap(d, 5.0) == 0);
    pump(&c, 0.2);
    ENSURE(c.n_status > ns);
    int k = last_event(&c, "stop");
    ENSUREF(k >= 0 && strstr(c.ev_detail[k], "SIGHUP") && c.ev_value[k] == SIGHUP, "stop event '%s'",
            k >= 0 ? c.ev_detail[k] : "none");
    d = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, count_events(&c, "start") == 2, 5.0);
    pump(&c, 0.1);
    kill(d, SIGQUIT);
    ENSURE(reap(d, 5.0) == 0);
    pump(&c, 0.2);
    ENSURE(count_events(&c, "stop") == 2);
}

/* An effort of 1e308 is refused whole by realtime.effort_limit (default 1e6): counted,
 * announced, the plant untouched. With the limit at 1e12, an effort of 1e12 drives the
 * state past explode_limit in one tick: the fault event names the efforts that were
 * held, so the cause is plain. */
static void case_effort_absurd(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t d = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, c.n_states > 2, 5.0);
    const char *n0[] = {"theta0"};
    double big[] = {1e308};
    command(&c, 0, 1, n0, big);
    WAIT_FOR(&c, last_event(&c, "command_rejected") >= 0, 3.0);
    int k = last_event(&c, "command_rejected");
    printf("command_rejected: %s\n", c.ev_detail[k]);
    ENSUREF(strstr(c.ev_detail[k], "effort_limit"), "detail '%s'", c.ev_detail[k]);
    pump(&c, 0.2);
    fresh_status(&c);
    ENSURE(c.status->rejected_effort_limit == 1 && c.status->commands_accepted == 0);
    ENSURE(strcmp(c.status->run_state, "running") == 0 && c.last.eff[0] == 0.0);
    ENSURE(last_event(&c, "numeric_fault") < 0);
    stop_daemon(d);

    d = start_daemon(g_prefix, "--set", "realtime.effort_limit={theta0: 1e12}", NULL);
    WAIT_FOR(&c, count_events(&c, "start") == 2 && c.last.t > 0.05, 5.0);
    double huge[] = {1e12};
    command(&c, 0, 1, n0, huge);
    WAIT_FOR(&c, last_event(&c, "numeric_fault") >= 0, 3.0);
    k = last_event(&c, "numeric_fault");
    printf("numeric_fault: %s\n", c.ev_detail[k]);
    ENSUREF(strstr(c.ev_detail[k], "theta0 = 1e+12"), "detail '%s'", c.ev_detail[k]);
    ENSURE(!c.nonfinite_seen);
    stop_daemon(d);
}

/* An LCM URL with ttl > 0 is said at start: the daemon's messages leave this host. */
static void case_ttl_warning(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    char err_path[256];
    snprintf(err_path, sizeof err_path, "/tmp/lagsim_server_test_%d_%s.err", (int)getpid(), g_case);
    g_stderr_path = err_path;
    pid_t d = start_daemon(g_prefix, "--set", "lcm.url=udpm://239.255.76.67:7667?ttl=1", "--set",
                           "lcm.allow_lan=true", "--set", "realtime.mode=fast", "--duration",
                           "0.05", NULL);
    g_stderr_path = NULL;
    int rc = reap(d, 5.0);
    FILE *f = fopen(err_path, "r");
    ENSURE(f);
    char text[4096];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    remove(err_path);
    printf("exit %d, stderr: %s", rc, text);
    if (rc == 2) return; /* refused by the loader: also safe */
    ENSURE(rc == 0);
    ENSUREF(strstr(text, "ttl=1") && strstr(text, "leave this host"), "no warning: '%s'", text);
}

/* One plant per prefix: a second daemon on a prefix where one runs hears it before it
 * publishes anything (its answer to a DESCRIBE, its states) and refuses to start, exit 1,
 * saying why; the first runs on untouched (no stop, its states go on, nothing from the
 * second on the prefix). */
static void case_same_prefix(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t a = start_daemon(g_prefix, NULL);
    WAIT_FOR(&c, c.n_states > 0, 5.0);
    char err_path[256];
    snprintf(err_path, sizeof err_path, "/tmp/lagsim_server_test_%d_%s.err", (int)getpid(), g_case);
    g_stderr_path = err_path;
    pid_t b = start_daemon(g_prefix, NULL);
    g_stderr_path = NULL;
    double t0 = now_s();
    int rc = reap(b, 10.0);
    double took = now_s() - t0;
    FILE *f = fopen(err_path, "r");
    ENSURE(f);
    char text[4096];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    remove(err_path);
    printf("second daemon: exit %d after %.2f s, stderr: %s", rc, took, text);
    ENSUREF(rc == 1, "the second daemon on prefix %s: exit %d", g_prefix, rc);
    ENSUREF(strstr(text, "another plant publishes on prefix") && strstr(text, "refusing to start"),
            "no reason given: '%s'", text);
    int64_t before = c.n_states;
    pump(&c, 0.5);
    ENSURE(c.n_states > before + 20);                    /* the first goes on */
    ENSURE(count_events(&c, "stop") == 0 && count_events(&c, "start") == 1);
    kill(a, SIGTERM);
    ENSURE(reap(a, 5.0) == 0);
}

static int64_t wall_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* Reads a file whole into text[cap] (NUL-terminated). */
static void slurp(const char *path, char *text, size_t cap)
{
    FILE *f = fopen(path, "r");
    ENSURE(f);
    size_t n = fread(text, 1, cap - 1, f);
    fclose(f);
    text[n] = '\0';
}

/* A forged scene on a running plant's prefix (any local process can send one): the plant
 * runs on, its states continue, the conflict is counted in status and said once (an
 * event, a line on stderr even with -q); then a flood of 2000 forged scenes as fast as this
 * process publishes: still running, still one event (one in 5 s), the count grows (the
 * daemon's scene queue holds 16: what it drops is never seen); SIGTERM ends it, exit 0. */
static void case_plant_conflict(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    static client c;
    client_init(&c, g_prefix, 3);
    char err_path[256];
    snprintf(err_path, sizeof err_path, "/tmp/lagsim_server_test_%d_%s.err", (int)getpid(), g_case);
    g_stderr_path = err_path;
    pid_t d = start_daemon(g_prefix, "--set", "realtime.start=running", NULL);
    g_stderr_path = NULL;
    WAIT_FOR(&c, c.n_states > 10 && c.scene, 5.0);
    /* the forgery: the plant's own scene with another utime */
    lagsim_scene_t f;
    memset(&f, 0, sizeof f);
    char *pn[1] = {"m0"}, *jn[3] = {"theta0", "theta1", "theta2"};
    double pv[1] = {1.5}, z[3] = {0, 0, 0};
    int8_t act[3] = {1, 0, 0}, off[3] = {0, 0, 0};
    f.utime = 1;
    f.model = "dipc";
    f.prefix = g_prefix;
    f.num_params = 1;
    f.param_name = pn;
    f.param_value = pv;
    f.num_joints = 3;
    f.joint_name = jn;
    f.actuated = act;
    f.initial_q = f.initial_qd = z;
    f.dt = 0.001;
    f.control_period = 0.01;
    f.integrator = "rk4";
    f.mode = "realtime";
    f.rate = 1;
    f.command_timeout = 0.5;
    f.effects = "";
    f.limit_on = off;
    f.limit_lower = f.limit_upper = z;
    char ch_scene[96];
    snprintf(ch_scene, sizeof ch_scene, "%s_SCENE", g_prefix);
    lagsim_scene_t_publish(c.lcm_in, ch_scene, &f); /* on the command URL: not heard */
    lagsim_scene_t_publish(c.lcm, ch_scene, &f);    /* on the state URL, where plants speak */
    int64_t states = c.n_states;
    WAIT_FOR(&c, count_events(&c, "plant_conflict") == 1, 5.0);
    pump(&c, 1.0);
    ENSUREF(c.n_states > states + 50, "%lld states in the second after the forged scene",
            (long long)(c.n_states - states));
    fresh_status(&c);
    ENSUREF(c.status->plant_conflicts == 1, "status plant_conflicts %lld",
            (long long)c.status->plant_conflicts);
    ENSURE(count_events(&c, "stop") == 0 && strcmp(c.status->run_state, "running") == 0);
    /* a flood */
    states = c.n_states;
    double t0 = now_s();
    for (int k = 0; k < 2000; k++) {
        f.utime = 2 + k;
        lagsim_scene_t_publish(c.lcm, ch_scene, &f);
        if (k % 20 == 19) lcm_handle_timeout(c.lcm, 20);
    }
    pump(&c, 0.5);
    double took = now_s() - t0;
    fresh_status(&c);
    printf("flood of 2000 forged scenes in %.2f s: %lld counted, %d plant_conflict events, "
           "%lld states meanwhile\n", took, (long long)c.status->plant_conflicts,
           count_events(&c, "plant_conflict"), (long long)(c.n_states - states));
    ENSURE(c.status->plant_conflicts > 1 && c.status->plant_conflicts <= 2001);
    ENSUREF(count_events(&c, "plant_conflict") <= 1 + (int)(took / 5.0) + 1,
            "%d plant_conflict events in %.1f s", count_events(&c, "plant_conflict"), took);
    ENSURE(c.n_states > states + (int64_t)(took * 50));
    ENSURE(count_events(&c, "stop") == 0 && !c.nonfinite_seen);
    stop_daemon(d);
    char text[8192];
    slurp(err_path, text, sizeof text);
    remove(err_path);
    printf("stderr: %s", text);
    ENSUREF(strstr(text, "another plant publishes on prefix") && strstr(text, "running on"),
            "no line on stderr: '%s'", text);
    const char *first = strstr(text, "running on"); /* one line per event that went out */
    ENSUREF(!strstr(first + 1, "running on") || count_events(&c, "plant_conflict") > 1,
            "more lines than events: '%s'", text);
}

/* lcm-logger records a plant's run; a second plant on the same prefix runs while
 * lcm-logplayer plays that log onto the live bus (its old scene, states, statuses and
 * events, byte for byte): the live plant runs on, and counts and reports the conflict.
 * The live plant's messages are told from the played ones by their utime. */
static void case_plant_conflict_logplayer(int arg)
{
    (void)arg;
    const char *logger = lt_arg(1);
    if (!logger) {
        lt_skip("no LCM_LOGGER given");
        return;
    }
    write_scene(DIPC_MOVING);
    char log_path[256], chan[96];
    snprintf(log_path, sizeof log_path, "/tmp/lagsim_server_test_%d_%s.lcm", (int)getpid(), g_case);
    remove(log_path);
    snprintf(chan, sizeof chan, "%s_.*", g_prefix);
    char *largv[] = {(char *)logger, "-q", "-f", "-c", chan, log_path, NULL};
    static client c;
    client_init(&c, g_prefix, 3);
    pid_t lg = spawn(largv, true);
    usleep(500000); /* the logger subscribes */
    pid_t a = start_daemon(g_prefix, "--set", "realtime.start=running", "--duration", "1", NULL);
    ENSURE(reap(a, 10.0) == 0);
    usleep(300000);
    kill(lg, SIGINT);
    ENSURE(reap(lg, 5.0) >= 0);
    /* the live plant */
    c.min_utime = wall_us();
    c.n_events = 0;
    pid_t b = start_daemon(g_prefix, "--set", "realtime.start=running", NULL);
    WAIT_FOR(&c, c.n_states > 10, 5.0);
    char *pargv[] = {"lcm-logplayer", "-s", "4", log_path, NULL};
    pid_t pl = spawn(pargv, true);
    ENSURE(reap(pl, 10.0) == 0);
    pump(&c, 0.5);
    int64_t states = c.n_states;
    pump(&c, 0.5);
    fresh_status(&c);
    printf("played %lld old messages; live plant: %lld conflicts counted, %d plant_conflict "
           "events, %lld states in the last 0.5 s\n", (long long)c.n_old,
           (long long)c.status->plant_conflicts, count_events(&c, "plant_conflict"),
           (long long)(c.n_states - states));
    ENSURE(c.n_old > 50);                        /* the log was played onto the bus */
    ENSURE(c.status->plant_conflicts >= 1);      /* its scene heard, counted */
    ENSURE(count_events(&c, "plant_conflict") == 1);
    ENSURE(count_events(&c, "stop") == 0 && strcmp(c.status->run_state, "running") == 0);
    ENSURE(c.n_states > states + 20);            /* the live plant runs on */
    kill(b, SIGTERM);
    ENSURE(reap(b, 5.0) == 0);
    remove(log_path);
}

/* An offline run stopped by SIGINT (or SIGTERM, SIGHUP) flushes the rows it computed,
 * whole, says where it stopped and exits 1. */
static void case_offline_signal(int arg)
{
    (void)arg;
    write_scene(DIPC_MOVING);
    char csv[256];
    snprintf(csv, sizeof csv, "/tmp/lagsim_server_test_%d_%s.csv", (int)getpid(), g_case);
    const int sigs[] = {SIGINT, SIGHUP};
    for (int i = 0; i < 2; i++) {
        char *argv[] = {g_lagsimd, "--config", g_scene_path, "--offline", "--duration", "1e7",
                        "--csv", csv, "-q", NULL};
        pid_t d = spawn(argv, true);
        usleep(500000);
        kill(d, sigs[i]);
        int rc = reap(d, 5.0);
        ENSUREF(rc == 1, "offline run stopped by signal %d: exit %d", sigs[i], rc);
        FILE *f = fopen(csv, "r");
        ENSURE(f);
        char line[1024];
        long rows = 0;
        bool whole = true;
        while (fgets(line, sizeof line, f)) {
            size_t n = strlen(line);
            int commas = 0;
            for (size_t j = 0; j < n; j++) commas += line[j] == ',';
            if (n == 0 || line[n - 1] != '\n' || commas != 7) whole = false; /* t, 3 q, 3 qd, E */
            rows++;
        }
        fclose(f);
        remove(csv);
        printf("offline, signal %d after 0.5 s: %ld rows, all whole: %s\n", sigs[i], rows, whole ? "yes" : "no");
        ENSURE(rows > 10 && whole);
    }
}

static void setup(void)
{
    snprintf(g_lagsimd, sizeof g_lagsimd, "%s", lt_arg(0));
    g_case = lt_case_name;
    /* a prefix unique to this process and case: ctest -j never crosstalks */
    snprintf(g_prefix, sizeof g_prefix, "LT%d_%.20s", (int)getpid(), g_case);
    for (char *p = g_prefix; *p; p++)
        if (*p >= 'a' && *p <= 'z') *p = (char)(*p - 'a' + 'A');
    signal(SIGPIPE, SIG_IGN);
    /* LCM's default URL with a multicast port of this process's own (ttl=0: this host),
     * for this test, its daemons and lcm-logger (all read LCM_DEFAULT_URL): on one port
     * every socket gets every datagram, so a flood anywhere on the machine (a fast-mode
     * daemon, a flood test) would fill these sockets and lose their messages. The prefix
     * stays unique as well. Receive buffers of 4 MB (the kernel's rmem_max here; it caps
     * larger requests): a lockstep run publishes hundreds of small datagrams in a few
     * milliseconds, each costing the socket about 1 kB of buffer, and lcm-logger, kept off
     * a core by a loaded machine, lost some with the default 208 kB. */
    lt_private_lcm(); /* and the next port: the command URL (lagsim_test.h) */
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"control", case_control, 0, 0},
        {"hostile", case_hostile, 0, 0},
        {"watchdog", case_watchdog, 0, 0},
        {"lockstep_timeout", case_lockstep_timeout, 0, 0},
        {"two_daemons", case_two_daemons, 0, 0},
        {"fault", case_fault, 0, 0},
        {"replay", case_replay, REPLAY_RK4, 0},
        {"replay_dopri5", case_replay, REPLAY_DOPRI5, 0},
        {"replay_effects", case_replay, REPLAY_EFFECTS, 0},
        {"replay_flight", case_replay, REPLAY_FLIGHT, 0},
        {"sigterm", case_sigterm, 0, 0},
        {"bad_scene", case_bad_scene, 0, 0},
        {"effects", case_effects, 0, 0},
        {"control_flood", case_control_flood, 0, 0},
        {"step_flood", case_step_flood, 0, 0},
        {"lockstep_huge", case_lockstep_huge, 0, 0},
        {"status_rate", case_status_rate, 0, 0},
        {"rate_huge", case_rate_huge, 0, 0},
        {"long_period", case_long_period, 0, 0},
        {"duration_huge", case_duration_huge, 0, 0},
        {"signals", case_signals, 0, 0},
        {"effort_absurd", case_effort_absurd, 0, 0},
        {"ttl_warning", case_ttl_warning, 0, 0},
        {"same_prefix", case_same_prefix, 0, 0},
        {"offline_signal", case_offline_signal, 0, 0},
        {"command_flood_ports", case_command_flood_ports, 0, 0},
        {"plant_conflict", case_plant_conflict, 0, 0},
        {"plant_conflict_logplayer", case_plant_conflict_logplayer, 0, 0},
    };
    /* the first failed check kills the daemons and ends the case */
    const lt_program p = {.cases = cases, .n = (int)(sizeof cases / sizeof cases[0]),
                          .args = "LAGSIMD [LCM_LOGGER]", .min_args = 1, .max_args = 2,
                          .setup = setup, .teardown = kill_children, .stop_on_failure = true};
    int rc = lt_run(argc, argv, &p);
    client_free_all();
    if (g_scene_path[0]) remove(g_scene_path);
    return rc;
}
