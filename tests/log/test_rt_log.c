/*
 * lagsimd --log beside the real-time loop (server/daemon/rt_log.c, rt_record.c). The loop
 * runs on a made-up clock on LCM's in-process memq:// provider (as in test_loop.c); the
 * log is written for real by its thread: to a regular file, to a FIFO that this test
 * reads only when it says so (a disk that stalls), and to /dev/full (a full disk). What
 * reached the file is read back with the wire module's bounded reader.
 *
 *   test_rt_log CASE    CASE: file clock realtime_stalled fast_stalled lockstep_stalled
 *                             full flood_in flood_refused flood_accepted split (--list)
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "lagsim_log.h"
#include "lagsim_test.h"
#include "rt_server.h"
#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_joint_command_t.h"

static char g_fifo[128], g_file[128];
static void cleanup(void)
{
    if (g_fifo[0]) unlink(g_fifo);
    if (g_file[0]) unlink(g_file);
}

#define MS 1000000LL
#define SEC 1000000000LL

static double wall_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---------------------------------------------------------------- the server under test */
static rt_server g_srv;
static lcm_t *g_lcm;
static lag_scene g_sc;
static lagsimd_opts g_opts;
static int64_t g_states, g_statuses, g_ev_dropped, g_ev_error, g_commands_sent;
static bool g_answer; /* lockstep: answer every state at once */

static void command(double sim_time, double effort)
{
    uint8_t buf[256];
    char *names[1] = {"theta0"};
    /* answers the state of the current generation */
    lagsim_joint_command_t m = {0, sim_time, 1, names, &effort, g_srv.pub.generation};
    int n = lagsim_joint_command_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0);
    rt_handle_command(&g_srv, buf, (size_t)n);
    g_commands_sent++;
}

static void control(int req)
{
    uint8_t buf[256];
    lagsim_control_t m = {0, (int8_t)req, 0, 0, NULL, NULL, "", ""};
    int n = lagsim_control_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0);
    rt_handle_control(&g_srv, buf, (size_t)n);
}

static void on_any(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)user;
    const char *sfx = strrchr(ch, '_');
    if (!sfx) return;
    if (!strcmp(sfx, "_STATE")) {
        lag_wire_joint_state m;
        ENSURE(lag_wire_decode_joint_state(rb->data, rb->data_size, 3, &m) == LAG_WIRE_OK);
        g_states++;
        if (g_answer) command(m.sim_time, 0.1 * sin(m.sim_time));
    } else if (!strcmp(sfx, "_STATUS")) {
        g_statuses++;
    } else if (!strcmp(sfx, "_EVENT")) {
        lag_wire_event e;
        ENSURE(lag_wire_decode_event(rb->data, rb->data_size, &e) == LAG_WIRE_OK);
        if (!strcmp(e.kind, "log_dropped")) g_ev_dropped++;
        if (!strcmp(e.kind, "log_error")) g_ev_error++;
    }
}

static void drain(void)
{
    while (lcm_handle_timeout(g_lcm, 0) > 0) {
    }
}

static void scene(lag_rt_mode mode, double publish_hz)
{
    lag_scene_default(&g_sc, LAG_MODEL_DIPC);
    g_sc.sim.q0[1] = 0.1;
    g_sc.sim.q0[2] = -0.05;
    g_sc.realtime.mode = mode;
    g_sc.realtime.command_timeout = 1e9;
    g_sc.publish_hz = publish_hz;
    g_sc.ticks_per_period = (int64_t)llround(1.0 / (publish_hz * g_sc.sim.integrator.dt));
    snprintf(g_sc.lcm.prefix, sizeof g_sc.lcm.prefix, "TRL");
    memset(&g_opts, 0, sizeof g_opts);
    g_opts.quiet = true;
}

static void start(const char *log, size_t ring)
{
    char err[512];
    g_states = g_statuses = g_ev_dropped = g_ev_error = g_commands_sent = 0;
    g_opts.log = log;
    g_opts.log_ring = ring;
    ENSUREF(rt_open(&g_srv, &g_sc, &g_opts, 1 * SEC, true, err, sizeof err) == 0, "%s", err);
    ENSURE(g_srv.rec.log != NULL);
    ENSUREF(rt_attach(&g_srv, g_lcm, g_lcm, err, sizeof err) == 0, "%s", err);
    rt_begin(&g_srv);
    drain();
}

/* Ends the run; returns what rt_log_end said (0: the log is complete). */
static int finish(void)
{
    rt_finish(&g_srv);
    drain();
    int rc = rt_log_end(&g_srv.rec);
    rt_close(&g_srv);
    drain();
    return rc;
}

static rt_log_stats stats(void)
{
    rt_log_stats st;
    rt_log_get_stats(g_srv.rec.log, &st);
    return st;
}

/* Plays the loop until the made-up clock reaches `until` (or the server stops): each
 * wake-up costs `cost` ns, the loop sleeps until rt_next_wake. A wall-clock guard. */
static void run_until(int64_t until, int64_t cost)
{
    rt_server *s = &g_srv;
    double guard = wall_s() + 60;
    while (!s->stop && s->now < until) {
        int64_t wake = rt_next_wake(s);
        int64_t now = s->now + cost;
        if (wake > now) now = wake;
        if (now > until) {
            s->now = until;
            break;
        }
        s->now = now;
        drain();
        rt_process(s);
        drain();
        ENSUREF(wall_s() < guard, "the loop does not get anywhere");
    }
}

/* ---------------------------------------------------------------- the FIFO (a stalled disk) */
static int g_fifo_rd = -1;
static FILE *g_copy;          /* what the drain thread read, for parsing */
static pthread_t g_drainer;
static bool g_draining;

static const char *fifo_open(void)
{
    snprintf(g_fifo, sizeof g_fifo, "/tmp/lagsim_rt_log_%d.fifo", (int)getpid());
    unlink(g_fifo);
    ENSURE(mkfifo(g_fifo, 0600) == 0);
    g_fifo_rd = open(g_fifo, O_RDONLY | O_NONBLOCK); /* a reader that does not read yet */
    ENSURE(g_fifo_rd >= 0);
    snprintf(g_file, sizeof g_file, "/tmp/lagsim_rt_log_%d.lcm", (int)getpid());
    g_copy = fopen(g_file, "wb");
    ENSURE(g_copy);
    return g_fifo;
}

static void *drainer(void *arg)
{
    (void)arg;
    fcntl(g_fifo_rd, F_SETFL, fcntl(g_fifo_rd, F_GETFL) & ~O_NONBLOCK);
    char buf[65536];
    ssize_t k;
    while ((k = read(g_fifo_rd, buf, sizeof buf)) > 0) fwrite(buf, 1, (size_t)k, g_copy);
    return NULL; /* end of file: the writer closed its end */
}

static void fifo_drain_start(void)
{
    ENSURE(pthread_create(&g_drainer, NULL, drainer, NULL) == 0);
    g_draining = true;
}

static void fifo_close(void)
{
    if (g_draining) pthread_join(g_drainer, NULL);
    g_draining = false;
    close(g_fifo_rd);
    fclose(g_copy);
    g_copy = NULL;
}

/* ---------------------------------------------------------------- reading the log back */
typedef struct logfacts {
    int64_t records, states, commands, controls, events, statuses, scenes, inputs, other;
    int64_t gaps;              /* a state whose step is not one period after the last */
    bool numbered;             /* event numbers 0, 1, 2, ... */
    bool ordered;              /* timestamps never go back */
    int64_t state_ts[4096];    /* timestamps of the first states */
    int64_t damaged, truncated;
    char first[4][16], last[16];
} logfacts;

static void read_log(const char *path, logfacts *f)
{
    memset(f, 0, sizeof *f);
    char err[256];
    lag_log *lg = lag_log_open(path, 65536, err, sizeof err);
    ENSUREF(lg, "%s", err);
    lag_log_record r;
    int64_t prev_ts = INT64_MIN, prev_step = -1;
    f->numbered = f->ordered = true;
    while (lag_log_next(lg, &r) == LAG_LOG_OK) {
        if (r.event_number != f->records) f->numbered = false;
        if (r.timestamp < prev_ts) f->ordered = false;
        prev_ts = r.timestamp;
        const char *sfx = strrchr(r.channel, '_');
        sfx = sfx ? sfx + 1 : r.channel;
        if (f->records < 4) snprintf(f->first[f->records], 16, "%.15s", sfx);
        snprintf(f->last, 16, "%.15s", sfx);
        f->records++;
        if (!strcmp(sfx, "STATE")) {
            lag_wire_joint_state m;
            ENSURE(lag_wire_decode_joint_state(r.data, r.size, 3, &m) == LAG_WIRE_OK);
            if (prev_step >= 0 && m.step != prev_step + g_sc.ticks_per_period) f->gaps++;
            prev_step = m.step;
            if (f->states < 4096) f->state_ts[f->states] = r.timestamp;
            f->states++;
        } else if (!strcmp(sfx, "COMMAND")) f->commands++;
        else if (!strcmp(sfx, "CONTROL")) f->controls++;
        else if (!strcmp(sfx, "EVENT")) f->events++;
        else if (!strcmp(sfx, "STATUS")) f->statuses++;
        else if (!strcmp(sfx, "SCENE")) f->scenes++;
        else if (!strcmp(sfx, "INPUT")) f->inputs++;
        else f->other++;
    }
    lag_log_stats ls;
    lag_log_get_stats(lg, &ls);
    f->damaged = ls.damaged;
    f->truncated = ls.truncated_bytes;
    lag_log_close(lg);
}

/* ---------------------------------------------------------------- cases */
/* A realtime run to a regular file: everything published and received is there, in the
 * order the loop saw it, numbered, stamped on the run's clock (states exactly one control
 * period apart while running). */
static void case_file(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME, 100);
    snprintf(g_file, sizeof g_file, "/tmp/lagsim_rt_log_%d.lcm", (int)getpid());
    start(g_file, 0);
    ENSURE(stats().ring == RT_LOG_RING_DEFAULT);
    for (int k = 0; k < 300; k++) {
        run_until(g_srv.now + 10 * MS, 1000);
        command(g_srv.ls.waiting_time, 0.2 * sin(0.05 * k));
    }
    control(LAGSIM_CONTROL_T_STATUS);
    run_until(g_srv.now + 5 * MS, 1000);
    int64_t published = g_srv.pub.states_published;
    ENSURE(finish() == 0);
    logfacts f;
    read_log(g_file, &f);
    printf("file: %lld records: %lld states, %lld commands, %lld controls, %lld events, "
           "%lld statuses, %lld scenes\n", (long long)f.records, (long long)f.states,
           (long long)f.commands, (long long)f.controls, (long long)f.events,
           (long long)f.statuses, (long long)f.scenes);
    ENSURE(f.numbered && f.ordered && f.damaged == 0 && f.truncated == 0);
    ENSURE(!strcmp(f.first[0], "SCENE") && !strcmp(f.first[1], "EVENT") &&
           !strcmp(f.first[2], "STATE") && !strcmp(f.first[3], "STATUS"));
    ENSURE(!strcmp(f.last, "STATUS")); /* the final status */
    ENSUREF(f.states == published && f.states == 301, "%lld states", (long long)f.states);
    ENSURE(f.gaps == 0);
    ENSURE(f.commands == g_commands_sent && f.controls == 1);
    ENSURE(f.events == 2 && f.scenes == 1 && f.inputs == 0 && f.other == 0); /* start, stop */
    ENSURE(f.statuses == g_statuses);
    for (int k = 1; k < 301; k++)
        ENSUREF(f.state_ts[k] - f.state_ts[0] == 10000LL * k, "state %d stamped %lld us after "
                "the first", k, (long long)(f.state_ts[k] - f.state_ts[0]));
    /* the log is written whole however long the path: a missing directory is refused */
    char err[512];
    scene(LAG_RT_REALTIME, 100);
    g_opts.log = "/nonexistent-dir/run.lcm";
    ENSURE(rt_open(&g_srv, &g_sc, &g_opts, 1 * SEC, true, err, sizeof err) == LAGSIMD_EXIT_USAGE);
    ENSUREF(strstr(err, "cannot open") && strstr(err, "/nonexistent-dir/run.lcm"), "%s", err);
}

/* Lockstep answered at once: the log's clock is sim time (a state every 10 ms of log time
 * however fast the run went), plus the wall time spent paused; an actuator lag adds the
 * commanded input of each period, stamped before the period's state. */
static void case_clock(int arg)
{
    (void)arg;
    scene(LAG_RT_LOCKSTEP, 100);
    g_sc.sim.effects.enabled |= LAG_EFF_ACTUATOR;
    g_sc.sim.effects.actuator_tau[0] = 0.005;
    snprintf(g_file, sizeof g_file, "/tmp/lagsim_rt_log_%d.lcm", (int)getpid());
    start(g_file, 0);
    g_answer = true;
    drain();
    command(0.0, 0.0);
    while (g_states < 101) run_until(g_srv.now + 1000, 1000); /* 100 periods in ~0.1 ms */
    g_answer = false;
    control(LAGSIM_CONTROL_T_PAUSE);
    run_until(g_srv.now + 3 * SEC, 1000);
    g_answer = true;
    control(LAGSIM_CONTROL_T_RESUME);
    while (g_states < 201) run_until(g_srv.now + 1000, 1000);
    ENSURE(finish() == 0);
    logfacts f;
    read_log(g_file, &f);
    ENSURE(f.numbered && f.ordered && f.gaps == 0);
    ENSUREF(f.inputs >= 200 && f.inputs <= 202, "%lld inputs", (long long)f.inputs);
    for (int k = 1; k <= 100; k++)
        ENSUREF(f.state_ts[k] - f.state_ts[0] == 10000LL * k, "state %d at %lld us", k,
                (long long)(f.state_ts[k] - f.state_ts[0]));
    int64_t paused = f.state_ts[101] - f.state_ts[100] - 10000;
    ENSUREF(paused >= 2999000 && paused <= 3010000, "the pause took %lld us of log time",
            (long long)paused);
    for (int k = 102; k < 200; k++)
        ENSURE(f.state_ts[k] - f.state_ts[k - 1] == 10000);
}

/* Realtime with a disk that stops (a FIFO nobody reads) and a ring of 256 KiB: the loop
 * never waits (a state at every deadline), the records that do not fit are counted and
 * said (a log_dropped event at most once a second), the end says the log is incomplete;
 * what reached the file is whole records, numbered without holes. */
static void case_realtime_stalled(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME, 1000);
    start(fifo_open(), RT_LOG_RING_MIN);
    run_until(g_srv.now + 10 * SEC, 1000);
    rt_log_stats st = stats();
    printf("realtime, stalled: %lld states published, %lld records put, %lld dropped (ring "
           "full), %lld log_dropped events\n", (long long)g_states, (long long)st.records,
           (long long)st.dropped_full, (long long)g_ev_dropped);
    ENSUREF(g_states == 10001, "%lld states: the loop waited for the log", (long long)g_states);
    ENSURE(g_srv.overruns == 0 && g_srv.sim.tick == 10000);
    ENSURE(st.dropped_full > 5000 && st.error == 0);
    ENSUREF(g_ev_dropped >= 5 && g_ev_dropped <= 11, "%lld log_dropped events",
            (long long)g_ev_dropped);
    fifo_drain_start(); /* the disk comes back: what the ring holds is written */
    ENSURE(finish() == -1);
    fifo_close();
    logfacts f;
    read_log(g_file, &f);
    ENSURE(f.numbered && f.ordered && f.damaged == 0 && f.truncated == 0);
    ENSUREF(f.states > 500 && f.states < 10001, "%lld states reached the file", (long long)f.states);
    /* what is there is the run from its start, every state one period after the last */
    ENSURE(f.records <= st.records + 2 && f.gaps == 0 && f.scenes == 1);
}

/* Fast or lockstep with a disk that stops: the loop holds the next period while the ring
 * is more than half full (no record lost), sleeps meanwhile instead of spinning, and
 * still serves the bus (a status request is answered); when the disk comes back the run
 * goes on to its end and the log is complete, every state one period after the last. */
static void stalled_no_deadline(lag_rt_mode mode)
{
    scene(mode, 100);
    g_opts.duration = 20.0;
    ENSURE(rt_ticks_for(20.0, g_sc.sim.integrator.dt, &(int64_t){0}));
    start(fifo_open(), RT_LOG_RING_MIN);
    /* rt_open set the stop tick from g_opts.duration */
    ENSURE(g_srv.stop_tick == 20000);
    g_answer = mode == LAG_RT_LOCKSTEP;
    if (g_answer) command(0.0, 0.0);
    /* fill the ring: the writer has stalled once the FIFO's buffer is full */
    double guard = wall_s() + 30;
    while (rt_log_room(g_srv.rec.log)) {
        run_until(g_srv.now + 1 * MS, 1000);
        ENSUREF(wall_s() < guard && !g_srv.stop, "the ring never fills (%lld states)",
                (long long)g_states);
    }
    run_until(g_srv.now + 2 * SEC, 1000);
    int64_t held = g_states;
    ENSURE(!rt_log_room(g_srv.rec.log));
    ENSUREF(rt_next_wake(&g_srv) > g_srv.now, "wake in %lld ns: waiting %d answered %d "
            "period_left %lld want %d%d%d", (long long)(rt_next_wake(&g_srv) - g_srv.now),
            g_srv.ls.waiting, g_srv.ls.answered, (long long)g_srv.period_left, g_srv.pub.want_state,
            g_srv.pub.want_scene, g_srv.pub.want_status); /* it sleeps while held */
    run_until(g_srv.now + 2 * SEC, 1000);
    ENSUREF(g_states == held, "%lld states while held, then %lld", (long long)held,
            (long long)g_states);
    int64_t st0 = g_statuses;
    control(LAGSIM_CONTROL_T_STATUS);
    run_until(g_srv.now + 100 * MS, 1000);
    ENSURE(g_statuses > st0);
    rt_log_stats st = stats();
    printf("%s, stalled: held at %lld states, %lld records put, %lld dropped\n",
           lag_rt_mode_name(mode), (long long)held, (long long)st.records,
           (long long)(st.dropped_full + st.dropped_in + st.too_large));
    ENSURE(st.dropped_full == 0 && st.dropped_in == 0 && st.too_large == 0 && st.error == 0);
    ENSURE(held > 100 && held < 2001);
    fifo_drain_start(); /* the disk comes back */
    guard = wall_s() + 60;
    while (!g_srv.stop) {
        run_until(g_srv.now + 1 * MS, 1000);
        if (!rt_log_room(g_srv.rec.log)) usleep(200); /* let the writer write */
        ENSUREF(wall_s() < guard, "the run does not end (%lld states)", (long long)g_states);
    }
    ENSURE(g_states == 2001);
    ENSURE(finish() == 0);
    fifo_close();
    logfacts f;
    read_log(g_file, &f);
    ENSURE(f.numbered && f.ordered && f.damaged == 0 && f.truncated == 0);
    ENSUREF(f.states == 2001 && f.gaps == 0, "%lld states, %lld gaps", (long long)f.states,
            (long long)f.gaps);
    ENSURE(f.commands == g_commands_sent);
}

static void case_fast_stalled(int arg) { (void)arg; stalled_no_deadline(LAG_RT_FAST); }
static void case_lockstep_stalled(int arg) { (void)arg; stalled_no_deadline(LAG_RT_LOCKSTEP); }

/* A full disk (/dev/full: every write fails with ENOSPC): said once (a log_error event),
 * the run goes on at its pace, the end says the log is incomplete and why. */
static void case_full(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME, 100);
    start("/dev/full", 0);
    run_until(g_srv.now + 1 * SEC, 1000);
    double guard = wall_s() + 10; /* the writer writes within its batch interval */
    while (stats().error == 0) {
        usleep(10000);
        ENSURE(wall_s() < guard);
    }
    run_until(g_srv.now + 1 * SEC, 1000);
    rt_log_stats st = stats();
    ENSUREF(st.error == ENOSPC, "error %d", st.error);
    ENSURE(g_ev_error == 1 && g_states == 201 && g_srv.overruns == 0);
    ENSURE(st.dropped_failed > 0);
    run_until(g_srv.now + 2 * SEC, 1000);
    ENSURE(g_ev_error == 1 && g_states == 401);
    ENSURE(finish() == -1);
}

/* A flood on the input channels cannot push the states out: received messages go in
 * only while the ring is at most 3/4 full, what the daemon publishes up to the full ring.
 * (The ring's own rule, below the buckets that bound what the loop hands it: records put
 * straight into the ring as the loop puts received ones.) */
static void case_flood_in(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME, 100);
    start(fifo_open(), RT_LOG_RING_MIN);
    uint8_t buf[256];
    char *names[1] = {"theta0"};
    double effort = 0.0;
    lagsim_joint_command_t m = {0, 0.0, 1, names, &effort};
    int n = lagsim_joint_command_t_encode(buf, 0, sizeof buf, &m);
    ENSURE(n > 0);
    int64_t put = 0;
    for (int k = 0; k < 10000; k++)
        put += rt_log_put(g_srv.rec.log, RT_LOG_IN, 1, "TRL_COMMAND", buf, (size_t)n);
    rt_log_stats st = stats();
    printf("flood: 10000 commands put, %lld logged, %lld not (ring 3/4 full)\n",
           (long long)put, (long long)st.dropped_in);
    ENSURE(st.dropped_in > 1000 && st.dropped_in == 10000 - put && st.dropped_full == 0);
    int64_t r0 = st.records;
    run_until(g_srv.now + 500 * MS, 1000);
    st = stats();
    ENSURE(g_states == 51 && st.dropped_full == 0 && st.records >= r0 + 50);
    fifo_drain_start();
    ENSURE(finish() == -1); /* the flood was not all logged */
    fifo_close();
    logfacts f;
    read_log(g_file, &f);
    ENSURE(f.numbered && f.states == 51 && f.gaps == 0);
}

/* A flood of refused messages cannot fill the disk: for 3 s of the made-up clock, every
 * millisecond 10 commands for an unknown joint, 2 undecodable ones and a status request,
 * and every 10 ms a good command answering the state. Every good command, state and event
 * is logged; of the rest, counted exactly, a sample whose bytes are within the bucket:
 * 64 KiB at start and 64 KiB a second after (<= 4 x 64 KiB over 3 s, and all of it used);
 * the log's own log_sampled events say so; the replay of the log gives difference 0. */
static void case_flood_refused(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME, 100);
    g_sc.realtime.start = LAG_RT_START_RUNNING;
    snprintf(g_file, sizeof g_file, "/tmp/lagsim_rt_log_%d.lcm", (int)getpid());
    unlink(g_file);
    start(g_file, 0);
    const int64_t t0 = g_srv.now;
    uint8_t bad[256], junk[40];
    memset(junk, 0xff, sizeof junk);
    char *names[1] = {"bogus"};
    double e = 1.0;
    lagsim_joint_command_t m = {0, 0.0, 1, names, &e};
    int nbad = lagsim_joint_command_t_encode(bad, 0, sizeof bad, &m);
    ENSURE(nbad > 0);
    int64_t good = 0;
    for (int ms = 1; ms <= 3000; ms++) {
        run_until(t0 + ms * MS, 1000);
        for (int k = 0; k < 10; k++) rt_handle_command(&g_srv, bad, (size_t)nbad);
        for (int k = 0; k < 2; k++) rt_handle_command(&g_srv, junk, sizeof junk);
        control(LAGSIM_CONTROL_T_STATUS);
        if (ms % 10 == 5) {
            command(g_srv.ls.waiting_time, 0.1 * sin(0.01 * ms));
            good++;
        }
    }
    run_until(t0 + 3500 * MS, 1000);
    ENSURE(g_srv.rec.rx_refused == 36000 && g_srv.rec.rx_undecodable == 6000 &&
           g_srv.rec.rx_queries == 3000);
    int64_t sampled = g_srv.rec.rx_sampled, sampled_bytes = g_srv.rec.rx_sampled_bytes;
    ENSURE(finish() == 0); /* complete: nothing lost, the rest was counted by design */
    logfacts f;
    read_log(g_file, &f);
    /* the bytes of the sample: each refused command or query record in the file */
    char err[256];
    lag_log *lg = lag_log_open(g_file, 65536, err, sizeof err);
    ENSUREF(lg, "%s", err);
    lag_log_record r;
    int64_t in_bytes = 0, in_good = 0, in_other = 0, ev_sampled = 0;
    while (lag_log_next(lg, &r) == LAG_LOG_OK) {
        const char *sfx = strrchr(r.channel, '_');
        if (!strcmp(sfx, "_COMMAND")) {
            lag_wire_joint_command c;
            bool ok = lag_wire_decode_joint_command(r.data, r.size, 3, &c) == LAG_WIRE_OK &&
                      !strcmp(c.name[0], "theta0");
            if (ok) in_good++;
            else {
                in_other++;
                in_bytes += LAG_LOG_HEADER_SIZE + (int64_t)strlen(r.channel) + (int64_t)r.size;
            }
        } else if (!strcmp(sfx, "_CONTROL")) {
            in_other++;
            in_bytes += LAG_LOG_HEADER_SIZE + (int64_t)strlen(r.channel) + (int64_t)r.size;
        } else if (!strcmp(sfx, "_EVENT")) {
            lag_wire_event ev;
            ENSURE(lag_wire_decode_event(r.data, r.size, &ev) == LAG_WIRE_OK);
            ev_sampled += !strcmp(ev.kind, "log_sampled");
        }
    }
    lag_log_close(lg);
    printf("flood: 45000 refused or queries and %lld good commands in 3 s: %lld good and %lld "
           "others logged (%lld bytes of sample), %lld log_sampled events; log of %lld records\n",
           (long long)good, (long long)in_good, (long long)in_other, (long long)in_bytes,
           (long long)ev_sampled, (long long)f.records);
    ENSURE(in_good == good && f.states == 351 && f.gaps == 0);
    ENSURE(in_other == sampled && in_bytes == sampled_bytes);
    ENSUREF(in_bytes <= 4 * RT_LOG_SAMPLE_BPS && in_bytes > 4 * RT_LOG_SAMPLE_BPS - 200,
            "%lld bytes of sample (the bucket: 64 KiB + 3 s x 64 KiB/s)", (long long)in_bytes);
    ENSURE(ev_sampled >= 3 && ev_sampled <= 5); /* at most one a second */
    lagsimd_opts ro = g_opts;
    ro.log = NULL;
    ENSURE(lagsimd_replay(&g_sc, g_file, &ro) == 0);
}

/* A flood of accepted messages cannot fill the disk either: for 3 s of the made-up clock,
 * every millisecond 10 good commands (each applied: the efforts change) and every 10 ms
 * one answering the state as a controller does. Every state and event is logged, every
 * command counted; the commands' bytes in the log are within their bucket (room for
 * RT_LOG_ACCEPTED_PER_PERIOD full commands a control period, the size computed here from
 * the wire format; at least RT_LOG_ACCEPTED_MIN_BPS), all of it used; log_sampled events
 * say how many were not written; the replay gives difference 0. */
static void case_flood_accepted(int arg)
{
    (void)arg;
    scene(LAG_RT_REALTIME, 100);
    g_sc.realtime.start = LAG_RT_START_RUNNING;
    snprintf(g_file, sizeof g_file, "/tmp/lagsim_rt_log_%d.lcm", (int)getpid());
    unlink(g_file);
    start(g_file, 0);
    const int64_t t0 = g_srv.now;
    for (int ms = 1; ms <= 3000; ms++) {
        run_until(t0 + ms * MS, 1000);
        for (int k = 0; k < 10; k++) command(g_srv.ls.waiting_time, 0.01 * k);
    }
    run_until(t0 + 3500 * MS, 1000);
    ENSURE(g_srv.rec.rx_accepted == 30000 && g_srv.rec.rx_refused == 0);
    int64_t written = g_srv.rec.rx_accepted_written, bytes = g_srv.rec.rx_accepted_bytes;
    ENSURE(finish() == 0); /* complete: the rest was counted by design */
    logfacts f;
    read_log(g_file, &f);
    /* a full command of the DIPC: its one actuated joint named, as lcm-gen encodes it */
    uint8_t buf[256];
    char *names[1] = {"theta0"};
    double e = 0.0;
    lagsim_joint_command_t m = {0, 0.0, 1, names, &e};
    int n = lagsim_joint_command_t_encode(buf, 0, sizeof buf, &m);
    double record = LAG_LOG_HEADER_SIZE + (double)strlen("TRL_COMMAND") + n;
    double rate = RT_LOG_ACCEPTED_PER_PERIOD * 100 * record;
    if (rate < RT_LOG_ACCEPTED_MIN_BPS) rate = RT_LOG_ACCEPTED_MIN_BPS;
    int64_t in_bytes = f.commands * (int64_t)record, ev_sampled = 0;
    char err[256];
    lag_log *lg = lag_log_open(g_file, 65536, err, sizeof err);
    ENSUREF(lg, "%s", err);
    lag_log_record r;
    while (lag_log_next(lg, &r) == LAG_LOG_OK) {
        lag_wire_event ev;
        if (strcmp(r.channel, "TRL_EVENT") == 0 &&
            lag_wire_decode_event(r.data, r.size, &ev) == LAG_WIRE_OK &&
            !strcmp(ev.kind, "log_sampled") &&
            strstr(ev.detail, "applied") && strstr(ev.detail, "counted only"))
            ev_sampled++;
    }
    lag_log_close(lg);
    printf("flood: 30000 commands applied in 3 s: %lld written (%lld bytes; bucket %.0f bytes "
           "a second), %lld log_sampled events; log of %lld records, %lld states\n",
           (long long)f.commands, (long long)in_bytes, rate, (long long)ev_sampled,
           (long long)f.records, (long long)f.states);
    ENSURE(f.commands == written && in_bytes == bytes);
    /* a full bucket at start and 3 s of the log's clock (sim time: the run is running) */
    ENSUREF(in_bytes <= 4 * rate + record && in_bytes > 4 * rate - 2 * record,
            "%lld bytes of commands (the bucket: %.0f at start + 3 s x %.0f/s)",
            (long long)in_bytes, rate, rate);
    ENSURE(f.states == 351 && f.gaps == 0 && f.other == 0);
    ENSURE(ev_sampled >= 3 && ev_sampled <= 5); /* at most one a second */
    lagsimd_opts ro = g_opts;
    ro.log = NULL;
    ENSURE(lagsimd_replay(&g_sc, g_file, &ro) == 0);
}

/* --increment --split-mb --keep: a run of 3 s (about 60 kB) split every 8 KiB. Each file
 * is a whole LCM log (nothing damaged or cut short), holds at most 8 KiB plus its last
 * record, and follows the one before: record numbers and state steps go on across files,
 * every state of the run is in one of them. With --keep 3 only the 3 newest are left. */
static int series_files(const char *dir, char names[][64], int max)
{
    DIR *d = opendir(dir);
    ENSURE(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (e->d_name[0] != '.' && n < max) snprintf(names[n++], 64, "%.63s", e->d_name);
    closedir(d);
    qsort(names, (size_t)n, 64, (int (*)(const void *, const void *))strcmp);
    return n;
}

static void split_run(const char *dir, int keep)
{
    char base[160];
    snprintf(base, sizeof base, "%s/run.lcm", dir);
    scene(LAG_RT_REALTIME, 100);
    g_sc.realtime.start = LAG_RT_START_RUNNING;
    g_opts.log_increment = true;
    g_opts.log_split = 8192;
    g_opts.log_keep = keep;
    start(base, 0);
    for (int k = 0; k < 30; k++) {
        run_until(g_srv.now + 100 * MS, 1000);
        usleep(20000); /* let the writer go on: files are cut where they were due */
    }
    ENSURE(finish() == 0);
}

static void case_split(int arg)
{
    (void)arg;
    char dir[] = "/tmp/lagsim_rt_split_XXXXXX", names[64][64], path[256];
    ENSURE(mkdtemp(dir));
    split_run(dir, 0);
    int n = series_files(dir, names, 64);
    int64_t number = 0, states = 0, prev_step = -1;
    for (int i = 0; i < n; i++) {
        char want[64];
        snprintf(want, sizeof want, "run.lcm.%06d", i);
        ENSUREF(!strcmp(names[i], want), "%s: expected %s", names[i], want);
        snprintf(path, sizeof path, "%.100s/%.63s", dir, names[i]);
        char err[256];
        lag_log *lg = lag_log_open(path, 65536, err, sizeof err);
        ENSUREF(lg, "%s", err);
        lag_log_record r;
        size_t last = 0;
        while (lag_log_next(lg, &r) == LAG_LOG_OK) {
            ENSUREF(r.event_number == number, "%s: record %lld numbered %lld", names[i],
                    (long long)number, (long long)r.event_number);
            number++;
            last = LAG_LOG_HEADER_SIZE + strlen(r.channel) + r.size;
            lag_wire_joint_state m;
            if (strcmp(r.channel, "TRL_STATE") != 0) continue;
            ENSURE(lag_wire_decode_joint_state(r.data, r.size, 3, &m) == LAG_WIRE_OK);
            ENSURE(prev_step < 0 || m.step == prev_step + g_sc.ticks_per_period);
            prev_step = m.step;
            states++;
        }
        lag_log_stats ls;
        lag_log_get_stats(lg, &ls);
        lag_log_close(lg);
        struct stat st;
        ENSURE(stat(path, &st) == 0);
        ENSUREF(ls.damaged == 0 && ls.truncated_bytes == 0 &&
                (i == n - 1 || (st.st_size >= 8192 && (size_t)st.st_size < 8192 + last)),
                "%s: %lld bytes, damaged %lld, cut short %lld", names[i],
                (long long)st.st_size, (long long)ls.damaged, (long long)ls.truncated_bytes);
        unlink(path);
    }
    printf("split: %d files of at most 8 KiB and a record, %lld records, %lld states\n", n,
           (long long)number, (long long)states);
    ENSURE(n >= 6 && states == 301);
    split_run(dir, 3); /* numbers go on from the highest: none left, so 0 again */
    n = series_files(dir, names, 64);
    printf("split --keep 3: %d files left: %s ... %s\n", n, names[0], names[n - 1]);
    ENSURE(n == 3 && strcmp(names[0], "run.lcm.000000") != 0);
    for (int i = 0; i < n; i++) {
        snprintf(path, sizeof path, "%.100s/%.63s", dir, names[i]);
        unlink(path);
    }
    ENSURE(rmdir(dir) == 0);
}

static void setup(void)
{
    signal(SIGPIPE, SIG_IGN);
    g_lcm = lcm_create("memq://");
    ENSURE(g_lcm);
    lcm_subscribe(g_lcm, "TRL_.*", on_any, NULL);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"file", case_file, 0, 0},
        {"clock", case_clock, 0, 0},
        {"realtime_stalled", case_realtime_stalled, 0, 0},
        {"fast_stalled", case_fast_stalled, 0, 0},
        {"lockstep_stalled", case_lockstep_stalled, 0, 0},
        {"full", case_full, 0, 0},
        {"flood_in", case_flood_in, 0, 0},
        {"flood_refused", case_flood_refused, 0, 0},
        {"flood_accepted", case_flood_accepted, 0, 0},
        {"split", case_split, 0, 0},
    };
    /* a failed check ends the case (its files removed): what follows it needs what failed */
    const lt_program p = {.cases = cases, .n = (int)(sizeof cases / sizeof cases[0]),
                          .setup = setup, .teardown = cleanup, .stop_on_failure = true};
    int rc = lt_run(argc, argv, &p);
    if (g_lcm) lcm_destroy(g_lcm);
    return rc;
}
