/*
 * server_latency: lagsimd's timing on this machine, beside this machine's floors measured
 * in the same run.
 *
 *   server_latency LAGSIMD [--seconds S] [--lockstep-seconds S] [--hz HZ]
 *
 * 1. floor, paced publisher: a child process publishes a joint_state_t-sized message at
 *    HZ with the daemon's clock call (timerfd, CLOCK_MONOTONIC, TFD_TIMER_ABSTIME, poll);
 *    we measure the period error at the receiver: |arrival_k - arrival_k-1 - 1/HZ|.
 * 2. floor, LCM ping-pong: a child echoes each ping; round-trip time.
 * 3. lagsimd in real time at HZ (DIPC, rk4, 1 ms ticks) for S seconds with this process as
 *    the controller: it answers every state at once with an effort that marks the state
 *    it answers. Measured: state period error (as in 1.), command-to-applied latency =
 *    utime of the first state whose effort carries the command's mark minus the command's
 *    send time (both CLOCK_REALTIME on this host; includes by design the wait for the next
 *    period deadline, see docs/server.md "Timing"), the share of commands applied
 *    to the very period that follows the state they answer, overruns (daemon status).
 * 4. lockstep throughput: lagsimd in lockstep, this process answering every state;
 *    control cycles per second, beside the ping-pong rate (1 / RTT).
 *
 * Prints a Markdown table. Timing figures are machine- and load-dependent: nothing here
 * asserts them.
 */
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/timerfd.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>
#include "lagsim_bus.h"
#include "lagsim_clock.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_status_t.h"
#include "lagsim_wire.h"

static int64_t mono_ns(void) { return lag_clock_mono_ns(); }
static int64_t wall_us(void) { return lag_clock_wall_us(); }

/* ---------------------------------------------------------------- samples */
typedef struct samples {
    double *v;
    size_t n, cap;
} samples;
static void add(samples *s, double x)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 4096;
        s->v = realloc(s->v, s->cap * sizeof *s->v);
        if (!s->v) abort();
    }
    s->v[s->n++] = x;
}
static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}
/* p in [0, 1]: nearest-rank percentile; p = 1 is the max. */
static double pct(samples *s, double p)
{
    if (s->n == 0) return NAN;
    qsort(s->v, s->n, sizeof *s->v, cmpd);
    size_t k = (size_t)ceil(p * (double)s->n);
    if (k < 1) k = 1;
    return s->v[k - 1];
}

/* ---------------------------------------------------------------- children */
static pid_t child(void)
{
    pid_t p = fork();
    if (p == 0) prctl(PR_SET_PDEATHSIG, SIGKILL);
    return p;
}

/* Child: publishes a 3-joint state at hz for seconds, paced like the daemon. */
static void paced_publisher(const char *chan, double hz, double seconds)
{
    lcm_t *lcm = lcm_create(NULL);
    int tfd = timerfd_create(CLOCK_MONOTONIC, 0);
    char *names[3] = {"theta0", "theta1", "theta2"};
    double z[3] = {0, 0, 0};
    lagsim_joint_state_t m = {0, 0, 0, 3, names, z, z, z};
    int64_t base = mono_ns(), period = (int64_t)(1e9 / hz);
    int64_t n = (int64_t)(seconds * hz);
    for (int64_t k = 1; k <= n; k++) {
        int64_t d = base + k * period;
        struct itimerspec its = {{0, 0}, {d / 1000000000, d % 1000000000}};
        timerfd_settime(tfd, TFD_TIMER_ABSTIME, &its, NULL);
        struct pollfd pf = {tfd, POLLIN, 0};
        poll(&pf, 1, -1);
        uint64_t x;
        if (read(tfd, &x, sizeof x) < 0) break;
        m.utime = wall_us();
        m.step = k;
        lagsim_joint_state_t_publish(lcm, chan, &m);
    }
    lcm_destroy(lcm);
    _exit(0);
}

static void on_echo(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    lcm_publish(u, "LAGSIM_BENCH_PONG", rb->data, rb->data_size);
}

/* ---------------------------------------------------------------- measurement state */
typedef struct bench {
    lcm_t *lcm;
    lcm_t *lcm_cmd;   /* the plant's command URL (lagsim_bus.h) */
    double period_s;
    int64_t last_arrival_ns;
    int64_t n_states;
    samples period_err_us;
    /* controller */
    bool control;
    char ch_command[96];
    int64_t send_utime[1000];  /* by mark */
    int64_t pending_mark;      /* mark of the last command sent, -1 none */
    samples latency_us;
    int64_t on_time, late, answered;
    lag_wire_status *status;   /* NULL until the first, then &status_buf */
    lag_wire_status status_buf;
    /* ping-pong */
    int64_t pong_ns;
} bench;

/* States and status are decoded by the wire module (bounded, no allocation). */
static void on_state(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    bench *b = u;
    int64_t now = mono_ns();
    static lag_wire_joint_state mm;
    const lag_wire_joint_state *m = &mm;
    if (lag_wire_decode_joint_state(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &mm) != LAG_WIRE_OK)
        return;
    if (b->last_arrival_ns)
        add(&b->period_err_us, fabs((double)(now - b->last_arrival_ns) * 1e-3 - b->period_s * 1e6));
    b->last_arrival_ns = now;
    b->n_states++;
    if (!b->control) return;
    /* effort mark: (k % 1000 + 1) mN, k = this state's period index */
    double e = m->num_joints > 0 ? m->effort[0] : 0;
    int mark = (int)lround(e * 1000.0) - 1;
    if (mark >= 0 && mark < 1000 && b->send_utime[mark] > 0) {
        add(&b->latency_us, (double)(m->utime - b->send_utime[mark]));
        if (mark == b->pending_mark) b->on_time++;
        else b->late++;
        b->send_utime[mark] = 0;
    }
    int64_t k = (int64_t)llround(m->sim_time / b->period_s);
    int newmark = (int)(k % 1000);
    double eff = (newmark + 1) * 1e-3;
    char *names[1] = {"theta0"};
    lagsim_joint_command_t c = {wall_us(), m->sim_time, 1, names, &eff};
    b->send_utime[newmark] = c.utime;
    b->pending_mark = newmark;
    lagsim_joint_command_t_publish(b->lcm_cmd, b->ch_command, &c);
    b->answered++;
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    bench *b = u;
    if (lag_wire_decode_status(rb->data, rb->data_size, &b->status_buf) == LAG_WIRE_OK)
        b->status = &b->status_buf;
}

static void on_pong(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)rb; (void)ch;
    ((bench *)u)->pong_ns = mono_ns();
}

static void pump_until_exit(bench *b, pid_t pid)
{
    while (waitpid(pid, NULL, WNOHANG) == 0) lcm_handle_timeout(b->lcm, 50);
    for (int i = 0; i < 20; i++) lcm_handle_timeout(b->lcm, 10);
}

static pid_t run_daemon(const char *lagsimd, const char *scene, const char *prefix,
                        const char *mode, double hz, double seconds)
{
    char s_prefix[96], s_mode[64], s_hz[64], dur[32];
    snprintf(s_prefix, sizeof s_prefix, "lcm.prefix=%s", prefix);
    snprintf(s_mode, sizeof s_mode, "realtime.mode=%s", mode);
    snprintf(s_hz, sizeof s_hz, "publish_hz=%g", hz);
    snprintf(dur, sizeof dur, "%g", seconds);
    pid_t p = child();
    if (p == 0) {
        execl(lagsimd, lagsimd, "--config", scene, "-q", "--set", s_prefix, "--set", s_mode,
              "--set", s_hz, "--set", "realtime.command_timeout=10", "--set",
              "realtime.status_hz=2", "--duration", dur, (char *)NULL);
        _exit(127);
    }
    return p;
}

/* ---------------------------------------------------------------- the four phases */
/* What the run is asked to do, and what each phase measured. */
typedef struct latency_run {
    const char *lagsimd;
    double seconds, ls_seconds, hz, floor_seconds;
    char scene[128];            /* the DIPC scene file, removed at the end */
    char prefix[64];
    /* 1. */
    samples floor_err;
    int64_t floor_n;
    /* 2. */
    samples rtt;
    /* 3. */
    samples period_err, latency;
    int64_t rt_states, overruns, on_time, late;
    double step_max, rtf_mean;
    /* 4. */
    double cycles_per_s;
} latency_run;

static int parse_args(latency_run *r, int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: server_latency LAGSIMD [--seconds S] [--lockstep-seconds S] [--hz HZ]\n");
        return 2;
    }
    r->lagsimd = argv[1];
    r->seconds = 60, r->ls_seconds = 10, r->hz = 1000;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--seconds")) r->seconds = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--lockstep-seconds")) r->ls_seconds = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--hz")) r->hz = atof(argv[i + 1]);
    }
    r->floor_seconds = r->seconds < 10 ? r->seconds : 10;
    return -1;
}

static int write_scene(latency_run *r)
{
    snprintf(r->scene, sizeof r->scene, "/tmp/lagsim_server_latency_%d.yaml", (int)getpid());
    FILE *f = fopen(r->scene, "w");
    if (!f) return 1;
    fputs("model: dipc\nintegrator:\n  method: rk4\n  dt: 0.001\n", f);
    fclose(f);
    return 0;
}

/* 1. paced publisher floor */
static void floor_paced(latency_run *r, bench *b)
{
    char pubchan[96];
    snprintf(pubchan, sizeof pubchan, "%s_PACED", r->prefix);
    lcm_subscription_t *ps = lcm_subscribe(b->lcm, pubchan, on_state, b);
    pid_t pp = child();
    if (pp == 0) paced_publisher(pubchan, r->hz, r->floor_seconds);
    pump_until_exit(b, pp);
    lcm_unsubscribe(b->lcm, ps);
    r->floor_err = b->period_err_us;
    r->floor_n = b->n_states;
    memset(&b->period_err_us, 0, sizeof b->period_err_us);
    b->last_arrival_ns = 0;
    b->n_states = 0;
}

/* 2. ping-pong floor */
static void floor_pingpong(latency_run *r, bench *b)
{
    pid_t pe = child();
    if (pe == 0) {
        lcm_t *l = lcm_create(NULL);
        lcm_subscribe(l, "LAGSIM_BENCH_PING", on_echo, l);
        for (;;) lcm_handle(l);
    }
    lcm_subscription_t *pong = lcm_subscribe(b->lcm, "LAGSIM_BENCH_PONG", on_pong, b);
    usleep(300000);
    uint8_t payload[120] = {0};
    int64_t t_end = mono_ns() + (int64_t)(r->floor_seconds * 1e9);
    while (mono_ns() < t_end) {
        b->pong_ns = 0;
        int64_t t0 = mono_ns();
        lcm_publish(b->lcm, "LAGSIM_BENCH_PING", payload, sizeof payload);
        while (b->pong_ns == 0 && mono_ns() - t0 < 100000000) lcm_handle_timeout(b->lcm, 100);
        if (b->pong_ns) add(&r->rtt, (double)(b->pong_ns - t0) * 1e-3);
    }
    kill(pe, SIGKILL);
    waitpid(pe, NULL, 0);
    lcm_unsubscribe(b->lcm, pong);
}

/* 3. lagsimd in real time with this process as the controller; returns the state
 * subscription (phase 4 replaces it). */
static lcm_subscription_t *realtime_run(latency_run *r, bench *b)
{
    char ch[96];
    lag_bus_channel_name(ch, sizeof ch, r->prefix, LAG_BUS_STATE);
    lcm_subscription_t *ss = lcm_subscribe(b->lcm, ch, on_state, b);
    lcm_subscription_set_queue_capacity(ss, 100000);
    lag_bus_channel_name(ch, sizeof ch, r->prefix, LAG_BUS_STATUS);
    lcm_subscribe(b->lcm, ch, on_status, b);
    lag_bus_channel_name(b->ch_command, sizeof b->ch_command, r->prefix, LAG_BUS_COMMAND);
    b->control = true;
    b->pending_mark = -1;
    pid_t d = run_daemon(r->lagsimd, r->scene, r->prefix, "realtime", r->hz, r->seconds);
    pump_until_exit(b, d);
    r->rt_states = b->n_states;
    r->overruns = b->status ? b->status->overruns : -1;
    r->step_max = b->status ? b->status->step_time_max_us : NAN;
    r->rtf_mean = b->status && b->status->wall_time > 0 ? b->status->sim_time / r->seconds : NAN;
    r->latency = b->latency_us;
    r->on_time = b->on_time, r->late = b->late;
    memset(&b->latency_us, 0, sizeof b->latency_us);
    r->period_err = b->period_err_us;
    memset(&b->period_err_us, 0, sizeof b->period_err_us);
    return ss;
}

/* 4. lockstep throughput */
static void lockstep_run(latency_run *r, bench *b, lcm_subscription_t *ss)
{
    int64_t n0 = b->n_states;
    char lprefix[80], ch[96];
    snprintf(lprefix, sizeof lprefix, "%sL", r->prefix);
    lag_bus_channel_name(ch, sizeof ch, lprefix, LAG_BUS_STATE);
    lcm_unsubscribe(b->lcm, ss);
    lcm_subscribe(b->lcm, ch, on_state, b);
    lag_bus_channel_name(b->ch_command, sizeof b->ch_command, lprefix, LAG_BUS_COMMAND);
    /* run long enough in sim time; we stop it after ls_seconds of wall time */
    int64_t tl0 = mono_ns();
    pid_t dl = run_daemon(r->lagsimd, r->scene, lprefix, "lockstep", r->hz, 1e6);
    int64_t first_ns = 0, first_n = 0;
    while (mono_ns() - tl0 < (int64_t)((r->ls_seconds + 1) * 1e9)) {
        lcm_handle_timeout(b->lcm, 50);
        if (!first_ns && b->n_states > n0 + 100) { first_ns = mono_ns(); first_n = b->n_states; }
    }
    int64_t last_ns = mono_ns(), last_n = b->n_states;
    kill(dl, SIGTERM);
    waitpid(dl, NULL, 0);
    r->cycles_per_s = first_ns ? (double)(last_n - first_n) / ((double)(last_ns - first_ns) * 1e-9) : 0;
}

static void print_report(latency_run *r, double period_s)
{
    double f50 = pct(&r->floor_err, 0.5), f99 = pct(&r->floor_err, 0.99), fmx = pct(&r->floor_err, 1);
    double d50 = pct(&r->period_err, 0.5), d99 = pct(&r->period_err, 0.99), dmx = pct(&r->period_err, 1);
    double r50 = pct(&r->rtt, 0.5), r99 = pct(&r->rtt, 0.99), rmx = pct(&r->rtt, 1);
    double l50 = pct(&r->latency, 0.5), l99 = pct(&r->latency, 0.99), lmx = pct(&r->latency, 1);
    int64_t on_time = r->on_time, late = r->late;
    printf("## lagsimd timing at %g Hz, %g s real time (DIPC, rk4, dt 1 ms), floors over %g s\n\n",
           r->hz, r->seconds, r->floor_seconds);
    printf("| figure (us) | p50 | p99 | max | samples |\n|---|---:|---:|---:|---:|\n");
    printf("| floor: bare paced publisher, period error | %.1f | %.1f | %.1f | %lld |\n", f50, f99, fmx, (long long)r->floor_n);
    printf("| lagsimd state period error | %.1f | %.1f | %.1f | %lld |\n", d50, d99, dmx, (long long)r->rt_states);
    printf("| ratio lagsimd / floor | %.2f | %.2f | %.2f | |\n", d50 / f50, d99 / f99, dmx / fmx);
    printf("| floor: bare LCM ping-pong round trip | %.1f | %.1f | %.1f | %zu |\n", r50, r99, rmx, r->rtt.n);
    printf("| lagsimd command-to-applied (send -> state that applied it) | %.1f | %.1f | %.1f | %zu |\n", l50, l99, lmx, r->latency.n);
    printf("| ratio command-to-applied / (period + ping-pong RTT) | %.2f | %.2f | %.2f | |\n",
           l50 / (period_s * 1e6 + r50), l99 / (period_s * 1e6 + r99), lmx / (period_s * 1e6 + rmx));
    printf("\n- commands applied to the period right after the state they answer: %lld of %lld (%.3f%%); later: %lld\n",
           (long long)on_time, (long long)(on_time + late),
           100.0 * (double)on_time / (double)(on_time + late > 0 ? on_time + late : 1), (long long)late);
    printf("- overruns over %g s: %lld (daemon status; worst period compute %.1f us; sim time / requested duration %.4f)\n",
           r->seconds, (long long)r->overruns, r->step_max, r->rtf_mean);
    printf("- lockstep throughput with this controller: %.0f control cycles/s (ping-pong rate 1/RTT p50: %.0f /s)\n",
           r->cycles_per_s, 1e6 / r50);
}

int main(int argc, char **argv)
{
    static latency_run r;
    int code = parse_args(&r, argc, argv);
    if (code >= 0) return code;
    if (write_scene(&r)) return 1;

    static bench b;
    lag_bus bus;
    char berr[256];
    if (lag_bus_init(&bus, NULL, "BENCH", berr, sizeof berr) != 0) {
        fprintf(stderr, "server_latency: %s\n", berr);
        return 1;
    }
    b.lcm = lcm_create(bus.state_url);
    b.lcm_cmd = lcm_create(bus.command_url);
    if (!b.lcm || !b.lcm_cmd) return 1;
    b.period_s = 1.0 / r.hz;
    snprintf(r.prefix, sizeof r.prefix, "LAGSIM_BENCH%d", (int)getpid());

    floor_paced(&r, &b);
    floor_pingpong(&r, &b);
    lockstep_run(&r, &b, realtime_run(&r, &b));
    print_report(&r, b.period_s);
    remove(r.scene);
    return 0;
}
