/*
 * One lagsimd and one controller kept for many runs of a case (eval_case.h, "reused
 * processes"). A run:
 *
 *   SET key=value      each varied key under parameters, effects or reference, resent until
 *                      its `set` event is heard (SET is idempotent)
 *   RESET_TO q0, qd0   resent until the state at sim time 0 with exactly q0, qd0 is heard
 *   STEP n             the case's periods; the states are taken from the bus as they come
 *
 * The bus may lose a datagram; the daemon's --log does not. A run whose states from the
 * bus are not all there (one missing, a reference missing), or that faulted or stalled, is
 * read again from the log, from its last RESET_TO on (eval_take), once the log's writer
 * has written it. So a run's series is always the one its daemon computed.
 *
 * The worker's daemon starts paused at the scene's initial state; one period is stepped
 * first. Lockstep matches an answer to its state by the state's generation and sim time
 * (the generation changes at every SET and reset: docs/server.md), so an answer to an
 * earlier run's state can never be taken for an answer to this run's; and the client
 * library answers a state only with the scene of its generation, so a controller that
 * reads its parameters from the scene computes every run with that run's. Before each
 * run the worker hears the controller's answer to the paused state (the last state of the
 * run before, which the daemon publishes again until it is answered): a run never starts
 * while the controller is still busy with the run before. A controller that does not
 * answer it within W_PAUSED_S fails the run, with that reason (the sweep starts a new
 * worker pair and runs it again, as for a stalled run).
 */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "eval_case.h"
#include "lagsim/lagsim.h"
#include "lagsim_bus.h"
#include "lagsim_client.h"
#include "lagsim_client_wire.h"
#include "lagsim_wire.h"

#define W_ANSWER_S 0.5  /* a SET or RESET_TO unanswered this long is sent again */
#define W_TRIES 8       /* ... this many times at most */
#define W_SET_REFUSALS 500 /* SETs refused for the daemon's rate, 20 ms apart: 10 s */
#define W_QUIET_S 0.25  /* a run with no new state for this long: a status is asked for */
#define W_LOG_WAIT_S 3.0 /* the log's writer writes within 0.1 s; this is its margin */
#define W_PAUSED_S 10.0 /* the controller's answer to the paused state, at most this late */
#define W_FIRST_S 30.0  /* a new pair's controller answers its first state within this, or
                         * within a run's wall time (--timeout) when that is shorter: the
                         * first run could not end within it either */

struct eval_worker {
    eval_env env;
    eval_scene sc;
    char log[1024];
    char cerr[1100], derr[1100]; /* the pair's stderr without -v (eval_stderr_paths) */
    pid_t dpid, cpid;
    lag_client *cl;
    lag_client_status *status; /* the latest status, read whole (lagsim_client_wire.h) */
    long runs;
    /* the run in progress, from the bus */
    eval_series s;
    bool armed, started, fault;
    long missing_refs;   /* states whose reference did not come before them */
    double q0[EVAL_JOINTS_MAX], qd0[EVAL_JOINTS_MAX];
    const char *set_wait; /* "key=value" whose set event is awaited */
    bool set_heard, set_refused;
    double t_heard;       /* the sim time of the last state heard */
    int64_t g_heard;      /* and its generation */
    bool moved;           /* a state after sim time 0 heard since the STEP */
    lcm_t *cmd;           /* the command URL: the controller's answers, as the daemon gets
                           * them */
    double t_answered;    /* the sim time of the last answer heard */
    int64_t g_answered;   /* and the generation it carried */
    char ended[96];       /* the controller has ended: how ("the controller ended (exit
                           * status 3)"); "" while it runs */
};

/* Whether the controller has ended (its keeper reaped): how, in w->ended. Nothing answers
 * the daemon then: the pair is lost (eval_worker_lost). */
static bool controller_gone(eval_worker *w)
{
    int st;
    if (w->ended[0]) return true;
    if (w->cpid <= 0 || !eval_wait_until(w->cpid, 0, &st)) return false;
    w->cpid = 0;
    snprintf(w->ended, sizeof w->ended, "the controller ended (%s %d)",
             WIFEXITED(st) ? "exit status" : "signal",
             WIFEXITED(st) ? WEXITSTATUS(st) : WTERMSIG(st));
    return true;
}

/* ---------------------------------------------------------------- from the bus */
static void w_on_command(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    eval_worker *w = user;
    lag_wire_joint_command c;
    if (lag_wire_decode_joint_command(rbuf->data, rbuf->data_size, EVAL_JOINTS_MAX, &c) == 0) {
        w->t_answered = c.sim_time;
        w->g_answered = c.generation;
    }
}

/* The controller's answers that have come, without waiting. */
static void drain_answers(eval_worker *w)
{
    struct pollfd pf = {w->cmd ? lcm_get_fileno(w->cmd) : -1, POLLIN, 0};
    while (w->cmd && poll(&pf, 1, 0) > 0 && (pf.revents & POLLIN)) lcm_handle(w->cmd);
}

/* What came, waiting up to ms for a message on the state URL, or on either URL when
 * `answers` (between runs: a run's states wake the worker, its answers need not). */
static int w_handle_on(eval_worker *w, int ms, bool answers)
{
    struct pollfd pf[2] = {{lag_client_fileno(w->cl), POLLIN, 0},
                           {w->cmd ? lcm_get_fileno(w->cmd) : -1, POLLIN, 0}};
    if (poll(pf, answers ? 2 : 1, ms) < 0 && errno != EINTR) return -1;
    int rc = (pf[0].revents & POLLIN) ? lag_client_handle(w->cl, 0) : LAG_CLIENT_TIMEOUT;
    drain_answers(w);
    return rc;
}

static int w_handle(eval_worker *w, int ms) { return w_handle_on(w, ms, true); }

static bool is_run_start(const eval_worker *w, const lag_client_state *st)
{
    if (st->sim_time != 0) return false;
    for (int j = 0; j < w->sc.nj; j++)
        if (st->position[j] != w->q0[j] || st->velocity[j] != w->qd0[j]) return false;
    return true;
}

/* The reference of the state at sim time t, joint by joint; false if it did not come. */
static bool reference_at(const eval_worker *w, double t, double *r)
{
    lag_client_reference ref;
    for (int j = 0; j < w->sc.nj; j++) r[j] = 0;
    if (!lag_client_latest_reference(w->cl, &ref, sizeof ref) || ref.sim_time != t) return false;
    for (int j = 0; j < w->sc.nj; j++) {
        int k = lag_client_reference_joint(&ref, w->sc.joint[j]);
        if (k >= 0 && isfinite(ref.r[k])) r[j] = ref.r[k];
    }
    return true;
}

static void w_on_state(const lag_client_state *st, void *user)
{
    eval_worker *w = user;
    w->t_heard = st->sim_time;
    w->g_heard = st->generation;
    if (st->sim_time > 0) w->moved = true;
    if (!w->armed || st->num_joints != w->sc.nj) return;
    if (!w->started && !(w->started = is_run_start(w, st))) return;
    eval_series *s = &w->s;
    /* a state published again (a retry, a paused state) is one sample, as in a log */
    if (s->n && st->sim_time <= s->t[s->n - 1]) return;
    if (eval_series_grow(s, w->sc.nj)) return;
    size_t k = s->n++;
    double r[EVAL_JOINTS_MAX];
    if (reference_at(w, st->sim_time, r)) s->has_reference = true;
    else w->missing_refs++;
    s->t[k] = st->sim_time;
    for (int j = 0; j < w->sc.nj; j++) {
        s->q[j][k] = st->position[j];
        s->r[j][k] = r[j];
        if (k) s->u[j][k - 1] = st->effort[j];
        s->u[j][k] = st->effort[j];
    }
}

static void w_on_event(const lag_client_event *ev, void *user)
{
    eval_worker *w = user;
    if (!strcmp(ev->kind, "step_done")) w->moved = true;
    else if (!strcmp(ev->kind, "numeric_fault") && w->armed) w->fault = true;
    else if (!strcmp(ev->kind, "set") && w->set_wait && !strcmp(ev->detail, w->set_wait))
        w->set_heard = true;
    /* over the daemon's rate of SETs: sent again a moment later */
    else if (!strcmp(ev->kind, "control_rejected") && w->set_wait &&
             strstr(ev->detail, w->set_wait) && strstr(ev->detail, "changes a second"))
        w->set_refused = true;
}

/* Handles messages until *flag or `seconds`; -1 on timeout or a client error. */
static int w_wait(eval_worker *w, const bool *flag, double seconds)
{
    double end = eval_now() + seconds;
    while (!*flag) {
        if (eval_now() > end || w_handle(w, 5) < 0) return -1;
    }
    return 0;
}

/* A status newer than now; false when none came within W_ANSWER_S or a state after sim
 * time 0 came first (the daemon moved: the question is answered). OUT: st */
static bool fresh_status(eval_worker *w, lag_wire_status *st, bool stop_on_move)
{
    int64_t asked = (int64_t)(eval_now_wall() * 1e6);
    if (lag_client_request_status(w->cl) != LAG_CLIENT_OK) return false;
    double end = eval_now() + W_ANSWER_S;
    while (eval_now() < end) {
        w_handle(w, 5);
        if (stop_on_move && w->moved) return false;
        if (lag_client_latest_status(w->cl, w->status) &&
            (*st = *lag_wire_of_status(w->status)).utime >= asked)
            return true;
    }
    return false;
}

/* Is the daemon paused at sim time 0 waiting for a STEP (the STEP was lost; while a STEP
 * is under way it waits for answers instead)? */
static bool still_at_start(eval_worker *w)
{
    lag_wire_status st;
    return fresh_status(w, &st, true) && st.sim_time == 0 &&
           !strncmp(st.waiting_for, "RESUME or STEP", 14);
}

/* STEP n, sent again only when a fresh status says the daemon has not moved from sim
 * time 0 (a second STEP that arrived would step twice); waits up to `seconds` for the
 * first state after 0 (a controller may take seconds to answer its first state). */
static int step_once(eval_worker *w, long n, double seconds)
{
    w->moved = false;
    double end = eval_now() + seconds;
    if (lag_client_step(w->cl, n) != LAG_CLIENT_OK) return -1;
    while (!w->moved) {
        if (eval_now() > end || controller_gone(w)) return -1;
        double next = eval_now() + W_ANSWER_S;
        while (!w->moved && eval_now() < next) w_handle(w, 5);
        if (!w->moved && still_at_start(w) && lag_client_step(w->cl, n) != LAG_CLIENT_OK)
            return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------- start, stop */
static pid_t start_daemon(eval_worker *w, const eval_case *c)
{
    char *argv[2 * (EVAL_SETS_MAX + EVAL_OWN_COUNT) + 16];
    char owned[EVAL_OWN_COUNT][EVAL_SET_LEN]; /* the keys the tools own */
    int na = 0;
    argv[na++] = (char *)w->env.lagsimd;
    argv[na++] = "--config";
    argv[na++] = (char *)w->env.config;
    eval_owned_sets(&w->env, true, owned);
    for (int i = 0; i < EVAL_OWN_COUNT; i++) {
        argv[na++] = "--set";
        argv[na++] = owned[i];
    }
    for (int i = 0; i < c->nsets; i++) {
        argv[na++] = "--set";
        argv[na++] = (char *)c->set[i];
    }
    argv[na++] = "--log";
    argv[na++] = w->log;
    argv[na++] = "-q";
    argv[na] = NULL;
    return eval_spawn(argv, NULL, &w->env, w->derr);
}

/* Stops the pair: the daemon, then the controller (which ends on its stop). */
static void stop_pair(eval_worker *w)
{
    int st;
    if (w->dpid > 0) {
        kill(w->dpid, SIGTERM);
        if (!eval_wait_until(w->dpid, eval_now() + 3.0, &st)) eval_stop_group(w->dpid, &st);
    }
    /* a controller ends on the daemon's stop; one that does not is stopped (on a host's
     * plant, which runs on, at once) */
    if (w->cpid > 0 && (w->env.attach_log || !eval_wait_until(w->cpid, eval_now() + 3.0, &st)))
        eval_stop_group(w->cpid, &st);
    w->dpid = w->cpid = 0;
}

/* A pair that could not start: why, and (without -v) what the two said last. */
static eval_worker *start_failed(eval_worker *w, char *err, size_t errlen, const char *why)
{
    char said[EVAL_OUTPUT_LEN] = "";
    stop_pair(w);
    if (!w->env.verbose && w->cerr[0]) {
        eval_stderr_tail(w->cerr, "the controller", said, sizeof said);
        eval_stderr_tail(w->derr, "lagsimd", said, sizeof said);
    }
    char first[512];
    snprintf(first, sizeof first, "%s", why);
    snprintf(err, errlen, "%s%s%s", first, said[0] ? "\n" : "", said);
    size_t n = strlen(err);
    if (n && err[n - 1] == '\n') err[n - 1] = '\0';
    eval_worker_stop(w);
    return NULL;
}

/* How long a new pair's controller has to answer its first state. */
static double first_wait(const eval_worker *w)
{
    return w->env.wall_timeout < W_FIRST_S ? w->env.wall_timeout : W_FIRST_S;
}

/* The first STEP of a new pair was never answered: the controller ended before it answered
 * the first state, or (alive) never answered it, which the daemon's status says in its
 * words (what it waits for, on which channel and URL, what came instead). Either way
 * the controller cannot run this sweep: *controller set. */
static eval_worker *no_first_answer(eval_worker *w, bool *controller, char *err,
                                    size_t errlen)
{
    char hint[200] = "", why[1024];
    lag_wire_status st;
    *controller = true;
    if (controller_gone(w)) {
        eval_url_hint(w->env.controller, w->env.url, hint, sizeof hint);
        snprintf(why, sizeof why, "%s before it answered the kept lagsimd's first state%s",
                 w->ended, hint);
    } else if (fresh_status(w, &st, false) && st.waiting_for[0]) {
        snprintf(why, sizeof why, "the controller did not answer the kept lagsimd's first "
                 "state within %g s: lagsimd waits %.0f s for %s; %s%s (is the "
                 "controller on the run's prefix: {prefix} or LAGSIM_PREFIX? does it start "
                 "within %g s? --restart gives each run's controller its --timeout to start)",
                 first_wait(w), st.waiting_s, st.waiting_for,
                 st.waiting_got[0] ? "got instead: " : "nothing else came", st.waiting_got,
                 first_wait(w));
    } else {
        snprintf(why, sizeof why, "the kept lagsimd did not step within %g s", first_wait(w));
        *controller = false;
    }
    return start_failed(w, err, errlen, why);
}

eval_worker *eval_worker_start(const eval_env *env, const eval_case *c, const eval_scene *sc,
                               bool *controller, char *err, size_t errlen)
{
    *controller = false;
    eval_worker *w = calloc(1, sizeof *w);
    if (!w) return NULL;
    w->env = *env;
    w->sc = *sc;
    if (env->attach_log) { /* a plant of the sweep's host: its log is the host's */
        snprintf(w->log, sizeof w->log, "%s", env->attach_log);
    } else {
        snprintf(w->log, sizeof w->log, "%s/%s.lcm", env->workdir, env->prefix);
        unlink(w->log);
    }
    char cmd[4096];
    if (eval_expand(env->controller, env, cmd, sizeof cmd, err, errlen)) {
        free(w);
        return NULL;
    }
    eval_stderr_paths(env, w->cerr, w->derr, sizeof w->cerr);
    /* the controller first, as eval_run starts them */
    w->cpid = eval_spawn(NULL, cmd, env, w->cerr);
    w->dpid = env->attach_log ? 0 : start_daemon(w, c);
    w->cl = lag_client_create(env->url, env->prefix, err, errlen);
    w->status = lag_client_status_new();
    if (w->cpid < 0 || w->dpid < 0 || !w->cl || !w->status)
        return start_failed(w, err, errlen, !w->cl      ? err
                                            : w->status ? "cannot start the processes"
                                                        : "out of memory");
    lag_client_on_state(w->cl, w_on_state, w);
    lag_client_on_event(w->cl, w_on_event, w);
    lag_bus bus;
    if (lag_bus_init(&bus, env->url, env->prefix, err, errlen) != 0 ||
        !(w->cmd = lcm_create(bus.command_url)) ||
        !lcm_subscribe(w->cmd, bus.channel[LAG_BUS_COMMAND], w_on_command, w))
        return start_failed(w, err, errlen, "cannot listen to the controller's answers");
    if (lag_client_wait_scene(w->cl, 10.0, NULL) != LAG_CLIENT_OK)
        return start_failed(w, err, errlen, "no scene from the kept lagsimd");
    /* a host's plant a worker before may have left in the middle of a run: paused first
     * (a plant paused already refuses it, harmlessly) */
    if (env->attach_log) lag_client_pause(w->cl);
    if (step_once(w, 1, first_wait(w))) return no_first_answer(w, controller, err, errlen);
    return w;
}

void eval_worker_stop(eval_worker *w)
{
    if (!w) return;
    stop_pair(w);
    if (w->cl) lag_client_destroy(w->cl);
    lag_client_status_free(w->status);
    if (w->cmd) lcm_destroy(w->cmd);
    eval_series_free(&w->s);
    if (!w->env.verbose) {
        if (!w->env.attach_log) unlink(w->log); /* a host's plant's: the sweep's to remove */
        if (w->cerr[0]) unlink(w->cerr);
        if (w->derr[0]) unlink(w->derr);
    }
    free(w);
}

long eval_worker_runs(const eval_worker *w) { return w->runs; }

bool eval_worker_lost(const eval_worker *w) { return w->ended[0] != 0; }

/* ---------------------------------------------------------------- a run */
/* One SET until its `set` event is heard: sent again after W_ANSWER_S without an answer
 * (W_TRIES times), or a moment after the daemon refused it for its rate of SETs. */
static int set_one(eval_worker *w, const char *kv, char *err, size_t errlen)
{
    char key[EVAL_SET_LEN];
    snprintf(key, sizeof key, "%s", kv);
    char *eq = strchr(key, '=');
    if (!eq) return 0;
    *eq = '\0';
    w->set_wait = kv;
    w->set_heard = false;
    int lost = 0, refused = 0;
    while (!w->set_heard && lost < W_TRIES && refused < W_SET_REFUSALS) {
        w->set_refused = false;
        if (lag_client_set(w->cl, key, eq + 1) != LAG_CLIENT_OK) break;
        double end = eval_now() + W_ANSWER_S;
        while (!w->set_heard && !w->set_refused && eval_now() < end && w_handle(w, 5) >= 0) {
        }
        if (w->set_refused) refused++, eval_sleep(0.02);
        else if (!w->set_heard) lost++;
    }
    w->set_wait = NULL;
    if (w->set_heard) return 0;
    snprintf(err, errlen, "the kept lagsimd did not take SET %s", kv);
    return -1;
}

static int set_keys(eval_worker *w, const char *const *sets, int nsets, char *err,
                    size_t errlen)
{
    for (int i = 0; i < nsets; i++)
        if (strncmp(sets[i], "initial.", 8) && set_one(w, sets[i], err, errlen)) return -1;
    return 0;
}

static int reset_to(eval_worker *w, const double *q0, const double *qd0, char *err,
                    size_t errlen)
{
    memcpy(w->q0, q0, sizeof w->q0);
    memcpy(w->qd0, qd0, sizeof w->qd0);
    w->armed = true;
    w->t_answered = NAN;
    w->g_answered = -1;
    for (int t = 0; t < W_TRIES && !w->started; t++)
        if (lag_client_reset_to(w->cl, w->sc.nj, q0, qd0) != LAG_CLIENT_OK ||
            (w_wait(w, &w->started, W_ANSWER_S) && t == W_TRIES - 1)) {
            snprintf(err, errlen, "no state at the run's initial state after RESET_TO");
            return -1;
        }
    return 0;
}

/* The states until the last one, a fault, the daemon's end of the STEP (its last state
 * lost on the way: a status says it is paused past the goal), or no progress within the
 * wall timeout (a controller may think long: a status says whether the daemon still
 * waits for an answer). */
static void follow(eval_worker *w, double t_goal)
{
    double start = eval_now(), last = start;
    size_t seen = w->s.n;
    while (!(w->s.n && w->s.t[w->s.n - 1] >= t_goal) && !w->fault && !controller_gone(w)) {
        if (w_handle_on(w, 20, false) < 0) break;
        if (w->s.n != seen) seen = w->s.n, last = eval_now();
        if (eval_now() - start > w->env.wall_timeout) break;
        if (eval_now() - last < W_QUIET_S) continue;
        lag_wire_status st;
        if (fresh_status(w, &st, false) &&
            (!strcmp(st.run_state, "fault") ||
             (st.sim_time >= t_goal && !strncmp(st.waiting_for, "RESUME or STEP", 14))))
            break; /* what the bus lost, the log has */
        last = eval_now();
    }
}

static bool log_run(eval_worker *w, off_t from, double t_goal, eval_result *res, char *err,
                    size_t errlen, bool *done)
{
    FILE *f = fopen(w->log, "rb");
    if (!f || fseeko(f, from, SEEK_SET) != 0) {
        snprintf(err, errlen, "%s: %s", w->log, strerror(errno));
        if (f) fclose(f);
        return false;
    }
    lag_log *lg = lag_log_open_stream(f, w->log, 1 << 20, err, errlen);
    if (!lg) {
        fclose(f);
        return false;
    }
    eval_take tk;
    eval_take_init(&tk, w->env.prefix, &w->sc, &w->s, res);
    eval_take_from_last_reset(&tk);
    tk.t_stop = t_goal + w->sc.period;
    lag_log_record rec;
    while (lag_log_next(lg, &rec) == LAG_LOG_OK && !tk.oom) eval_take_record(&tk, &rec);
    lag_log_close(lg);
    fclose(f);
    *done = tk.started && (tk.fault || (w->s.n && w->s.t[w->s.n - 1] >= t_goal));
    if (tk.oom) snprintf(err, errlen, "out of memory");
    return !tk.oom;
}

/* The run as the log holds it, from its RESET_TO on: waits for the log's writer. */
static int from_log(eval_worker *w, off_t from, double t_goal, eval_result *res, char *err,
                    size_t errlen)
{
    double end = eval_now() + W_LOG_WAIT_S;
    for (;;) {
        bool done = false;
        eval_series_free(&w->s);
        memset(res, 0, sizeof *res);
        if (!log_run(w, from, t_goal, res, err, errlen, &done)) return -1;
        if (done || eval_now() > end) return 0;
        eval_sleep(0.02);
    }
}

/* Has the answer to the last state heard come (by its generation and sim time)? */
static bool answer_heard(const eval_worker *w)
{
    return w->g_answered == w->g_heard && w->t_answered == w->t_heard;
}

/* Does the daemon say, paused (or in the fault state, which publishes no state), that no
 * answer is owed? What the bus lost on its way to the worker (the run's last states, the
 * answer) the daemon has had: it publishes the paused state again until answered and says
 * in its status while an answer is owed. */
static bool daemon_has_answer(eval_worker *w, double *t)
{
    lag_wire_status st;
    if (!fresh_status(w, &st, false)) return false;
    *t = st.sim_time;
    return (!strcmp(st.run_state, "paused") || !strcmp(st.run_state, "fault")) &&
           !strstr(st.waiting_for, "still owed");
}

/* The controller's answer to the paused state: heard, or said by the daemon's status; else
 * the run fails saying so (true). */
static bool paused_answer(eval_worker *w, eval_result *res)
{
    double end = eval_now() + W_PAUSED_S, t = w->t_heard;
    while (eval_now() < end && !controller_gone(w)) {
        double next = eval_now() + W_ANSWER_S;
        while (!answer_heard(w) && eval_now() < next) w_handle(w, 5);
        if (answer_heard(w) || daemon_has_answer(w, &t)) return false;
    }
    if (w->ended[0]) { /* between runs: the run before had its answers */
        eval_fail(res, "%s between runs, before this one started", w->ended);
        return true;
    }
    eval_fail(res, "the controller did not answer the paused state (generation %lld, sim time "
              "%.9g s, the last of the run before) within %g s: not started, so that no "
              "answer of the run before can reach this one", (long long)w->g_heard, t,
              W_PAUSED_S);
    return true;
}

static int worker_run(eval_worker *w, const eval_case *c, const char *const *sets, int nsets,
                      const double *q0, const double *qd0, eval_result *res, char *err,
                      size_t errlen)
{
    memset(res, 0, sizeof *res);
    eval_series_free(&w->s);
    w->fault = w->armed = w->started = false;
    w->missing_refs = 0;
    w->runs++;
    if (paused_answer(w, res)) return 0;
    /* every varied key is SET in every run, so nothing of the run before stays */
    if (set_keys(w, sets, nsets, err, errlen)) return -1;
    struct stat sb;
    off_t from = stat(w->log, &sb) == 0 ? sb.st_size : 0; /* before the run's RESET_TO */
    if (reset_to(w, q0, qd0, err, errlen)) return -1;
    long periods = lround(c->duration / w->sc.period);
    if (step_once(w, periods, w->env.wall_timeout) && !w->ended[0]) {
        snprintf(err, errlen, "the kept lagsimd did not step");
        return -1;
    }
    double t_goal = c->duration - 0.5 * w->sc.period;
    follow(w, t_goal);
    w->armed = false;
    /* all there: as many states as periods + 1, each with its reference when the scene
     * has one (the reference comes before its state: one missing means it was lost) */
    bool want_ref = w->sc.has_reference;
    for (int i = 0; i < nsets; i++) want_ref |= !strncmp(sets[i], "reference", 9);
    bool whole = !w->fault && w->s.n == (size_t)periods + 1 &&
                 w->s.t[w->s.n - 1] >= t_goal && (!want_ref || !w->missing_refs);
    if (!whole && w->env.verbose)
        fprintf(stderr, "%s: run %ld of this worker read from the log (%s: %zu of %ld states "
                        "from the bus, the last at %.6g s)\n", w->env.prefix, w->runs,
                w->fault ? "a fault" : w->s.n != (size_t)periods + 1
                ? "the bus lost states, or the run stalled" : "the bus lost references",
                w->s.n, periods + 1, w->s.n ? w->s.t[w->s.n - 1] : 0.0);
    if (!whole && from_log(w, from, t_goal, res, err, errlen)) return -1;
    res->nj = w->sc.nj;
    res->states = w->s.n;
    res->t_end = w->s.n ? w->s.t[w->s.n - 1] : 0;
    if (!w->s.n) eval_fail(res, "no state logged");
    else if (res->t_end < t_goal && w->ended[0]) /* the daemon waits for its answer since */
        eval_fail(res, "%s at t = %.6g s, before the run did", w->ended, res->t_end);
    else if (res->t_end < t_goal)
        eval_fail(res, "stopped at t = %.6g s before the duration %.6g s", res->t_end,
                  c->duration);
    return eval_score(&w->s, c, &w->sc, res, err, errlen);
}

int eval_worker_run(eval_worker *w, const eval_case *c, const char *const *sets, int nsets,
                    const double *q0, const double *qd0, eval_result *res, char *err,
                    size_t errlen)
{
    int rc = worker_run(w, c, sets, nsets, q0, qd0, res, err, errlen);
    if ((rc != 0 || res->failed) && !w->env.verbose) { /* what the kept pair said last */
        eval_stderr_tail(w->cerr, "the controller", res->output, sizeof res->output);
        eval_stderr_tail(w->derr, "lagsimd", res->output, sizeof res->output);
    }
    return rc;
}
