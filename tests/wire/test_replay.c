/*
 * lagsimd --replay on logs written here, good and hostile: the replay reads an untrusted
 * file, so it must never crash, hang, leak or report a check it could not make.
 *
 * The logs are written with this file's own LCM log writer (sync word, event number,
 * timestamp, channel and data lengths, channel, data; big-endian) and lcm-gen's encoder,
 * from a run of the core on the same scene (the one given on the command line), so the
 * exact answer of a replay is known: difference 0 on every state one period after
 * another.
 *
 * usage: test_replay CASE LAGSIMD SCENE.yaml                (the cases: test_replay --list)
 *        test_replay LAGSIMD SCENE.yaml write_logs DIR   (each case's log into DIR/CASE.lcm,
 *                                                          nothing run: fuzzing corpora)
 * Cases:
 *   valid                 a clean log: every state compared, difference 0, exit 0
 *   nothing_to_check      one state: nothing compared, exit 1
 *   negative_name_length  a state whose name length is -1: counted undecodable, exit 0
 *   name_fills_buffer     a name whose bytes fill its length without a NUL: undecodable
 *   huge_data_length      a record header claiming 0x7fffffff data bytes, in the middle
 *                         and at the end: passed over and reported, exit 0
 *   step_jump             steps of 2^62 and 2^52 among good states: not re-simulated
 *                         across (no hang), exit 0
 *   step_int64_min        a step of INT64_MIN: no signed overflow, no hang, exit 0
 *   set_step_int64_min    a change (`set` event) at step INT64_MIN: not the daemon's, said,
 *                         no signed overflow, never "max difference = 0"
 *   dev_zero              /dev/zero: "not an LCM log", exit 1, promptly
 *   not_a_log             the scene file itself: no records, exit 1
 *   undecodable_flood     2000 undecodable states claiming 32767 joints each: counted,
 *                         memory bounded (address space limited to 256 MB outside
 *                         sanitizer builds; LeakSanitizer in them), exit 0
 *   resim_failure         a logged effort of 1e300: the re-simulation fails; the replay
 *                         says so and exits 1, never "max difference = 0"
 *   garbage_between       junk bytes and a fake sync word between records: resynced,
 *                         reported as damage, every state still compared
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "lagsim/lagsim.h"
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim_test.h"
#include "scene.h"

static const char *g_lagsimd, *g_scene;
static const char *g_write_dir; /* write_logs: keep the logs, run nothing */
static char g_log[1024];
static lag_scene g_sc;
static char g_channel[96];

/* ---------------------------------------------------------------- log writing */
static void be(FILE *f, uint64_t v, int n)
{
    for (int i = n - 1; i >= 0; i--) fputc((int)((v >> (8 * i)) & 0xff), f);
}

static int64_t g_event = 0;

/* One record as lcm-logger writes it. */
static void record(FILE *f, const char *channel, const void *data, uint32_t len)
{
    be(f, 0xEDA1DA01u, 4);
    be(f, (uint64_t)g_event++, 8);
    be(f, (uint64_t)(1700000000000000 + g_event * 10000), 8);
    be(f, strlen(channel), 4);
    be(f, len, 4);
    fwrite(channel, 1, strlen(channel), f);
    fwrite(data, 1, len, f);
}

/* A state as the daemon publishes it. */
static void state(FILE *f, int64_t step, const double *q, const double *qd, const double *eff)
{
    const lag_model_info *info = lag_model_info_get(g_sc.sim.model.kind);
    char *names[LAG_MAX_DOF];
    for (int i = 0; i < info->nq; i++) names[i] = (char *)info->joint_names[i];
    lagsim_joint_state_t m = {0, (double)step * g_sc.sim.integrator.dt, step,
                              (int16_t)info->nq, names, (double *)q, (double *)qd,
                              (double *)eff};
    static uint8_t buf[4096];
    int n = lagsim_joint_state_t_encode(buf, 0, sizeof buf, &m);
    record(f, g_channel, buf, (uint32_t)n);
}

/* The run a daemon would make: the initial state, then `periods` states, effort
 * u_k = 0.5 sin(0.1 k) on every actuated joint over period k. Calls hook(f, k) before
 * writing state k (k = 0 .. periods), so a case can insert records. */
static void run(FILE *f, int periods, void (*hook)(FILE *, int))
{
    char err[256];
    static lag_sim sim;
    if (lag_sim_init(&sim, &g_sc.sim, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "scene: %s\n", err);
        exit(1);
    }
    const lag_model_info *info = lag_model_info_get(g_sc.sim.model.kind);
    double q[LAG_MAX_DOF], qd[LAG_MAX_DOF], u[LAG_MAX_DOF];
    for (int k = 0; k <= periods; k++) {
        if (k > 0) {
            for (int i = 0; i < info->nq; i++) u[i] = info->actuated[i] ? 0.5 * sin(0.1 * k) : 0;
            lag_sim_set_input(&sim, u);
            if (lag_sim_advance(&sim, g_sc.ticks_per_period, false) != LAG_OK) {
                fprintf(stderr, "reference run failed\n");
                exit(1);
            }
        }
        if (hook) hook(f, k);
        lag_sim_observe(&sim, q, qd);
        state(f, sim.tick, q, qd, sim.tau_applied);
    }
}

static FILE *log_create(void)
{
    FILE *f = fopen(g_log, "wb");
    if (!f) {
        perror(g_log);
        exit(1);
    }
    g_event = 0;
    return f;
}

/* ---------------------------------------------------------------- running lagsimd */
typedef struct result {
    int status;        /* exit code, or 128 + signal, or -1 when it had to be killed */
    char out[65536];   /* stdout and stderr */
    double seconds;
} result;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Runs lagsimd --config SCENE --replay log_path, at most timeout_s seconds; as_limit > 0
 * limits its address space (bytes). False (nothing run) when only writing logs. */
static bool replay(const char *log_path, double timeout_s, long as_limit, result *r)
{
    memset(r, 0, sizeof *r);
    if (g_write_dir) return false;
    int pfd[2];
    if (pipe(pfd) != 0) exit(1);
    double t0 = now_s();
    pid_t pid = fork();
    if (pid == 0) {
        dup2(pfd[1], 1);
        dup2(pfd[1], 2);
        close(pfd[0]);
        if (as_limit > 0) {
            struct rlimit rl = {(rlim_t)as_limit, (rlim_t)as_limit};
            setrlimit(RLIMIT_AS, &rl);
        }
        execl(g_lagsimd, g_lagsimd, "--config", g_scene, "--replay", log_path, (char *)NULL);
        _exit(127);
    }
    close(pfd[1]);
    fcntl(pfd[0], F_SETFL, O_NONBLOCK);
    size_t n = 0;
    int status = 0;
    bool done = false;
    while (!done) {
        ssize_t k = read(pfd[0], r->out + n, sizeof r->out - 1 - n);
        if (k > 0) n += (size_t)k;
        if (waitpid(pid, &status, WNOHANG) == pid) done = true;
        else if (now_s() - t0 > timeout_s) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            r->status = -1;
            break;
        } else if (k <= 0) {
            usleep(2000);
        }
    }
    ssize_t k;
    while ((k = read(pfd[0], r->out + n, sizeof r->out - 1 - n)) > 0) n += (size_t)k;
    close(pfd[0]);
    r->out[n] = '\0';
    r->seconds = now_s() - t0;
    if (r->status != -1)
        r->status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    printf("---- lagsimd --replay %s: status %d after %.2f s\n%s", log_path, r->status,
           r->seconds, r->out);
    return true;
}

/* N of the summary line "replay LOG: N states compared on ...", or -1. */
static long long compared(const result *r)
{
    const char *p = strstr(r->out, " states compared on ");
    if (!p) return -1;
    while (p > r->out && p[-1] >= '0' && p[-1] <= '9') p--;
    return strtoll(p, NULL, 10);
}

static void ensure_checked(const result *r, long long n)
{
    ENSUREF(r->status == 0, "status %d", r->status);
    ENSUREF(compared(r) == n, "%lld states compared, expected %lld", compared(r), n);
    ENSURE(strstr(r->out, "max difference = 0\n") != NULL);
}

/* ---------------------------------------------------------------- cases */
static void case_valid(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 100, NULL);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ensure_checked(&r, 100);
    ENSURE(strstr(r.out, "0 gaps, 0 undecodable, 0 integrator errors") != NULL);
}

static void case_nothing_to_check(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 0, NULL);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ENSUREF(r.status == 1, "status %d", r.status);
    ENSURE(strstr(r.out, "nothing could be checked") != NULL);
    ENSURE(strstr(r.out, "max difference") == NULL);
}

/* A joint_state_t of the scene's joints at step 0, well formed except that the first
 * name is written as length `len` followed by the n bytes `bytes` (the other names and
 * the doubles follow as usual). */
static void forged_state(FILE *f, uint32_t len, const char *bytes, size_t n)
{
    const lag_model_info *info = lag_model_info_get(g_sc.sim.model.kind);
    uint8_t b[1024];
    size_t p = 0;
    uint64_t hash = (uint64_t)__lagsim_joint_state_t_get_hash();
    for (int i = 7; i >= 0; i--) b[p++] = (uint8_t)(hash >> (8 * i));
    memset(b + p, 0, 24); /* utime, sim_time, step */
    p += 24;
    b[p++] = 0;
    b[p++] = (uint8_t)info->nq;
    for (int j = 0; j < info->nq; j++) {
        const char *s = j == 0 ? bytes : info->joint_names[j];
        uint32_t l = j == 0 ? len : (uint32_t)strlen(s) + 1;
        size_t nb = j == 0 ? n : l;
        for (int i = 3; i >= 0; i--) b[p++] = (uint8_t)(l >> (8 * i));
        memcpy(b + p, s, nb);
        p += nb;
    }
    memset(b + p, 0, 3 * 8 * (size_t)info->nq); /* position, velocity, effort */
    p += 3 * 8 * (size_t)info->nq;
    record(f, g_channel, b, (uint32_t)p);
}

static void hook_negative_name(FILE *f, int k)
{
    if (k == 50) forged_state(f, 0xffffffffu, "theta0", 6); /* length -1 */
}

static void case_negative_name_length(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 100, hook_negative_name);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ensure_checked(&r, 100);
    ENSURE(strstr(r.out, "1 undecodable") != NULL);
}

static void hook_name_fills(FILE *f, int k)
{
    /* the first name's 6 bytes are "theta0" without its NUL: a reader that trusts the
     * length gets a string that runs on past its buffer */
    if (k == 50) forged_state(f, 6, lag_model_info_get(g_sc.sim.model.kind)->joint_names[0], 6);
}

static void case_name_fills_buffer(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 100, hook_name_fills);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ensure_checked(&r, 100);
    ENSURE(strstr(r.out, "1 undecodable") != NULL);
}

/* A header claiming 0x7fffffff data bytes, followed by a few. */
static void huge_header(FILE *f)
{
    be(f, 0xEDA1DA01u, 4);
    be(f, (uint64_t)g_event++, 8);
    be(f, 0, 8);
    be(f, strlen(g_channel), 4);
    be(f, 0x7fffffffu, 4);
    fwrite(g_channel, 1, strlen(g_channel), f);
    fwrite("0123456789abcdef", 1, 16, f);
}

static void hook_huge(FILE *f, int k)
{
    if (k == 50) huge_header(f);
}

static void case_huge_data_length(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 100, hook_huge);
    huge_header(f); /* and one at the end: a record cut short */
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ensure_checked(&r, 100);
    ENSURE(strstr(r.out, "damaged in 1 place") != NULL);
    ENSURE(strstr(r.out, "cut short") != NULL);
}

static void hook_jump(FILE *f, int k)
{
    double z[LAG_MAX_DOF] = {0};
    if (k == 20) state(f, INT64_C(1) << 62, z, z, z);
    if (k == 40) state(f, INT64_C(1) << 52, z, z, z);
}

static void case_step_jump(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 60, hook_jump);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ENSUREF(r.status == 0, "status %d", r.status);
    /* 2^62 is out of range (skipped: state 20 still follows 19); 2^52 is a gap (restart
     * there), state 40 a step back (restart): states 1-39 and 41-60 are compared */
    ENSUREF(compared(&r) == 59, "%lld compared", compared(&r));
    ENSURE(strstr(r.out, "1 restarts at resets, 1 gaps") != NULL);
    ENSURE(strstr(r.out, "1 states with a non-finite number or a step outside") != NULL);
    ENSURE(strstr(r.out, "max difference = 0\n") != NULL);
}

static void hook_min(FILE *f, int k)
{
    double z[LAG_MAX_DOF] = {0};
    if (k == 20) state(f, INT64_MIN, z, z, z);
    if (k == 21) state(f, INT64_MAX, z, z, z);
}

static void case_step_int64_min(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 40, hook_min);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ensure_checked(&r, 40);
    ENSURE(strstr(r.out, "2 states with a non-finite number or a step outside") != NULL);
}

static void hook_set_min(FILE *f, int k)
{
    if (k != 20) return;
    char ch[104];
    snprintf(ch, sizeof ch, "%.*s_EVENT", (int)(strlen(g_channel) - strlen("_STATE")), g_channel);
    lagsim_event_t e = {0, 0.0, INT64_MIN, "set", "", 0.0, "parameters.m2=1.0"};
    static uint8_t buf[1024];
    int n = lagsim_event_t_encode(buf, 0, sizeof buf, &e);
    record(f, ch, buf, (uint32_t)n);
}

static void case_set_step_int64_min(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 40, hook_set_min);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ENSUREF(r.status != 0, "status %d", r.status);
    ENSURE(strstr(r.out, "a set event at step -9223372036854775808, outside [0, 2^53]: not "
                         "the daemon's, the log could not be checked") != NULL);
    ENSURE(strstr(r.out, "max difference = 0\n") == NULL);
}

static void case_dev_zero(int arg)
{
    (void)arg;
    result r;
    if (!replay("/dev/zero", 30, 0, &r)) return;
    ENSUREF(r.status == 1, "status %d", r.status);
    ENSURE(strstr(r.out, "not an LCM log") != NULL);
    ENSURE(strstr(r.out, "max difference") == NULL);
}

static void case_not_a_log(int arg)
{
    (void)arg;
    result r;
    if (!replay(g_scene, 30, 0, &r)) return;
    ENSUREF(r.status == 1, "status %d", r.status);
    ENSURE(strstr(r.out, "no ") != NULL && strstr(r.out, "messages in") != NULL);
}

static void hook_flood(FILE *f, int k)
{
    if (k != 10) return;
    /* states claiming 32767 joints, cut short after the count */
    uint8_t b[64];
    size_t p = 0;
    uint64_t hash = (uint64_t)__lagsim_joint_state_t_get_hash();
    for (int i = 7; i >= 0; i--) b[p++] = (uint8_t)(hash >> (8 * i));
    memset(b + p, 0, 24);
    p += 24;
    b[p++] = 0x7f;
    b[p++] = 0xff;
    memcpy(b + p, "\0\0\0\x07theta0\0", 11);
    p += 11;
    for (int i = 0; i < 2000; i++) record(f, g_channel, b, (uint32_t)p);
}

static void case_undecodable_flood(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 20, hook_flood);
    fclose(f);
    result r;
    /* 2000 leaked blocks of 32767 pointers would need 524 MB */
    if (!replay(g_log, 60, LT_SANITIZED ? 0 : 256L << 20, &r)) return;
    ensure_checked(&r, 20); /* state 10 follows the flood: 9 -> 10 is still one period */
    ENSURE(strstr(r.out, "2000 undecodable") != NULL);
}

static void hook_explode(FILE *f, int k)
{
    if (k != 21) return;
    double z[LAG_MAX_DOF] = {0}, big[LAG_MAX_DOF];
    for (int i = 0; i < LAG_MAX_DOF; i++) big[i] = 1e300;
    /* an effort of 1e300 over period 21 (a finite number no run could apply) */
    state(f, 21 * g_sc.ticks_per_period, z, z, big);
}

static void case_resim_failure(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 21, hook_explode);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ENSUREF(r.status == 1, "status %d", r.status);
    ENSURE(strstr(r.out, "re-simulation failed") != NULL);
    ENSURE(strstr(r.out, "max difference") == NULL);
}

static void hook_garbage(FILE *f, int k)
{
    if (k == 30) fwrite("garbage between records", 1, 23, f);
    if (k == 60) {
        be(f, 0xEDA1DA01u, 4); /* a fake sync word with a bad header */
        be(f, 0, 8);
        be(f, 0, 8);
        be(f, 0, 4);           /* channel length 0 */
        be(f, 5, 4);
    }
}

static void case_garbage_between(int arg)
{
    (void)arg;
    FILE *f = log_create();
    run(f, 100, hook_garbage);
    fclose(f);
    result r;
    if (!replay(g_log, 30, 0, &r)) return;
    ensure_checked(&r, 100);
    ENSURE(strstr(r.out, "damaged in 2 place") != NULL);
}

static const lt_case cases[] = {
    {"valid", case_valid, 0, 0},
    {"nothing_to_check", case_nothing_to_check, 0, 0},
    {"negative_name_length", case_negative_name_length, 0, 0},
    {"name_fills_buffer", case_name_fills_buffer, 0, 0},
    {"huge_data_length", case_huge_data_length, 0, 0},
    {"step_jump", case_step_jump, 0, 0},
    {"step_int64_min", case_step_int64_min, 0, 0},
    {"set_step_int64_min", case_set_step_int64_min, 0, 0},
    {"dev_zero", case_dev_zero, 0, 0},
    {"not_a_log", case_not_a_log, 0, 0},
    {"undecodable_flood", case_undecodable_flood, 0, 0},
    {"resim_failure", case_resim_failure, 0, 0},
    {"garbage_between", case_garbage_between, 0, 0},
};
#define NCASES ((int)(sizeof cases / sizeof cases[0]))

/* The scene every case's log is made from; exits 1 when it cannot be loaded. */
static void load_scene(const char *lagsimd, const char *scene)
{
    g_lagsimd = lagsimd;
    g_scene = scene;
    char err[512];
    if (lag_scene_load(g_scene, NULL, 0, &g_sc, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    snprintf(g_channel, sizeof g_channel, "%s_STATE", g_sc.lcm.prefix);
}

static void setup(void)
{
    load_scene(lt_arg(0), lt_arg(1));
    snprintf(g_log, sizeof g_log, "/tmp/lagsim_test_replay_%d_%s.lcm", (int)getpid(),
             lt_case_name);
}

static void teardown(void) { remove(g_log); }

int main(int argc, char **argv)
{
    if (argc == 5 && strcmp(argv[3], "write_logs") == 0) { /* each case's log, nothing run */
        load_scene(argv[1], argv[2]);
        g_write_dir = argv[4];
        for (int i = 0; i < NCASES; i++) {
            snprintf(g_log, sizeof g_log, "%s/%s.lcm", g_write_dir, cases[i].name);
            cases[i].fn(cases[i].arg);
        }
        return 0;
    }
    const lt_program p = {.cases = cases, .n = NCASES, .args = "LAGSIMD SCENE.yaml",
                          .min_args = 2, .max_args = 2, .setup = setup, .teardown = teardown};
    return lt_run(argc, argv, &p);
}
