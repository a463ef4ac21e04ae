/*
 * The one test harness of the C tests: plain C, no framework (Box2D's ENSURE), one copy
 * for every program. A test file defines no check macro or case dispatch of its own
 * (the ctest structure_harness fails when one does).
 *
 *   ENSURE(cond)                        counts a check; prints the expression if false
 *   ENSUREF(cond, fmt...)               the same, with a printf-style message if false
 *   ENSURE_NEAR(got, want, tol, fmt...) |got - want| <= tol, else prints both and context
 *   LT_FAIL(fmt...)                     counts a failed check with a message
 *
 * A program lists its cases in a table and hands it to lt_main (or lt_run, for a program
 * that takes arguments, sets up before its case or stops at the first failed check),
 * which
 *   - with no argument runs every case but those marked LT_BY_NAME (slow ones);
 *   - with `--list` prints one case a line ("name" or "name slow"): tests/common/cases.cmake
 *     turns that list into one ctest per case (PREFIX_name), so a case added to a table
 *     is a ctest without anyone listing it again;
 *   - with a name (and the program's arguments after it: lt_arg) runs that case; a name
 *     it does not know is an error (exit 2), never a pass;
 *   - fails when the cases run made no check at all ("0 checks" is not a pass), unless a
 *     case said why it could not run here (lt_skip): then it exits 77, which ctest
 *     reports as skipped, not passed.
 * main returns non-zero when anything failed.
 *
 *   LT_SANITIZED, lt_span(full, sanitized)   a long horizon or count, shortened under the
 *                                            sanitizers (see "the sanitizer pass" below)
 */
#ifndef LAGSIM_TEST_H
#define LAGSIM_TEST_H

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

static int lt_failures = 0;
static int lt_checks = 0;
#define LT_QUIET_AFTER 30 /* failures printed in detail; the rest are only counted */

static const char *lt_case_name = "all"; /* the case running */
static bool lt_stop_on_failure;          /* lt_run's stop_on_failure */
static void (*lt_teardown)(void);        /* lt_run's teardown */

/* After a failed check: a program that stops at the first one (its later steps need what
 * failed: a child to talk to, a file written) tears down and exits 1 here. */
static inline void lt_failed(void)
{
    if (!lt_stop_on_failure) return;
    fprintf(stderr, "%s: stopped at the first failed check (%d checks)\n", lt_case_name,
            lt_checks);
    if (lt_teardown) lt_teardown();
    exit(1);
}

#define ENSURE(cond)                                                                       \
    do {                                                                                   \
        lt_checks++;                                                                       \
        if (!(cond)) {                                                                     \
            if (lt_failures++ < LT_QUIET_AFTER)                                            \
                fprintf(stderr, "%s:%d: ENSURE failed: %s\n", __FILE__, __LINE__, #cond);  \
            lt_failed();                                                                   \
        }                                                                                  \
    } while (0)

/* ENSURE with a printf-style message (what was seen, what was expected) when it fails. */
#define ENSUREF(cond, ...)                                                                 \
    do {                                                                                   \
        lt_checks++;                                                                       \
        if (!(cond)) {                                                                     \
            if (lt_failures++ < LT_QUIET_AFTER) {                                          \
                fprintf(stderr, "%s:%d: ENSURE failed: %s: ", __FILE__, __LINE__, #cond);  \
                fprintf(stderr, __VA_ARGS__);                                              \
                fprintf(stderr, "\n");                                                     \
            }                                                                              \
            lt_failed();                                                                   \
        }                                                                                  \
    } while (0)

/* |got - want| <= tol; on failure prints both values and a printf-style context. A NaN on
 * either side fails. */
#define ENSURE_NEAR(got, want, tol, ...)                                                   \
    do {                                                                                   \
        double lt_g_ = (got), lt_w_ = (want), lt_t_ = (tol);                               \
        lt_checks++;                                                                       \
        if (!(fabs(lt_g_ - lt_w_) <= lt_t_)) {                                             \
            if (lt_failures++ < LT_QUIET_AFTER) {                                          \
                fprintf(stderr, "%s:%d: %s = %.17g, expected %s = %.17g (|diff| %.3g > tol %.3g): ", \
                        __FILE__, __LINE__, #got, lt_g_, #want, lt_w_, fabs(lt_g_ - lt_w_), lt_t_); \
                fprintf(stderr, __VA_ARGS__);                                              \
                fprintf(stderr, "\n");                                                     \
            }                                                                              \
            lt_failed();                                                                   \
        }                                                                                  \
    } while (0)

/* A check that failed for a reason the caller words itself. */
#define LT_FAIL(...)                                                                       \
    do {                                                                                   \
        lt_checks++;                                                                       \
        if (lt_failures++ < LT_QUIET_AFTER) {                                              \
            fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                                \
            fprintf(stderr, __VA_ARGS__);                                                  \
            fprintf(stderr, "\n");                                                         \
        }                                                                                  \
        lt_failed();                                                                       \
    } while (0)

static int lt_skipped = 0;
/* The case cannot run on this machine (the caller returns after it); says why. */
#define lt_skip(...)                                                                       \
    do {                                                                                   \
        lt_skipped++;                                                                      \
        printf("skipped: ");                                                               \
        printf(__VA_ARGS__);                                                               \
        printf("\n");                                                                      \
    } while (0)

/* ------------------------------------------------------------------ cases */
enum { LT_BY_NAME = 1 }; /* run only when named (slow cases); listed as "name slow" */

typedef struct lt_case {
    const char *name;
    void (*fn)(int arg);
    int arg;     /* passed to fn: e.g. a model kind for cases made from the model table */
    int flags;   /* LT_BY_NAME */
} lt_case;

#define LT_MAX_CASES 64

/* A case list that a program fills at run time (cases made from the core's tables). */
typedef struct lt_cases {
    int n;
    lt_case c[LT_MAX_CASES];
} lt_cases;

static inline void lt_add(lt_cases *cs, const char *name, void (*fn)(int), int arg, int flags)
{
    if (cs->n >= LT_MAX_CASES) {
        fprintf(stderr, "lagsim_test.h: more than LT_MAX_CASES (%d) cases\n", LT_MAX_CASES);
        abort();
    }
    cs->c[cs->n++] = (lt_case){name, fn, arg, flags};
}

/* A program's cases and how to run them (lt_main fills only cases and n). */
typedef struct lt_program {
    const lt_case *cases;
    int n;
    const char *args;             /* the arguments after CASE, for the usage line ("LAGSIMD") */
    int min_args, max_args;       /* how many of them it takes */
    void (*setup)(void);          /* before the case(s), once lt_case_name and lt_arg are set */
    void (*teardown)(void);       /* after them, and before exiting on a failed check */
    bool stop_on_failure;         /* the first failed check ends the program */
} lt_program;

static int lt_nargs;
static char **lt_args;
/* The i-th argument after the case's name, NULL when absent. */
static inline const char *lt_arg(int i) { return i >= 0 && i < lt_nargs ? lt_args[i] : NULL; }

/* Runs the cases named by argv (see the header comment). */
static inline int lt_run(int argc, char **argv, const lt_program *p)
{
    const char *prog = argc > 0 ? argv[0] : "test";
    const lt_case *cases = p->cases;
    int n = p->n;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++)
            if (strcmp(cases[i].name, cases[j].name) == 0) {
                fprintf(stderr, "%s: case '%s' is listed twice\n", prog, cases[i].name);
                return 2;
            }
    if (argc > 1 && strcmp(argv[1], "--list") == 0) {
        for (int i = 0; i < n; i++)
            printf("%s%s\n", cases[i].name, (cases[i].flags & LT_BY_NAME) ? " slow" : "");
        return 0;
    }
    const char *label = argc > 1 ? argv[1] : "all";
    lt_nargs = argc > 2 ? argc - 2 : 0;
    lt_args = argv + 2;
    if (lt_nargs < p->min_args || lt_nargs > p->max_args) {
        fprintf(stderr, "usage: %s [--list | CASE%s%s]\n", prog, p->args ? " " : "",
                p->args ? p->args : "");
        return 2;
    }
    int which = -1; /* the case named, or -1 for all */
    if (argc > 1) {
        for (int i = 0; i < n; i++)
            if (strcmp(argv[1], cases[i].name) == 0) which = i;
        if (which < 0) {
            fprintf(stderr, "%s: unknown case '%s'; cases:", prog, label);
            for (int i = 0; i < n; i++) fprintf(stderr, " %s", cases[i].name);
            fprintf(stderr, "\n");
            return 2;
        }
    }
    lt_case_name = label;
    lt_stop_on_failure = p->stop_on_failure;
    lt_teardown = p->teardown;
    if (p->setup) p->setup();
    for (int i = 0; i < n; i++)
        if (i == which || (which < 0 && !(cases[i].flags & LT_BY_NAME)))
            cases[i].fn(cases[i].arg);
    if (p->teardown) p->teardown();
    printf("%s: %d checks, %d failed%s\n", label, lt_checks, lt_failures,
           lt_skipped ? ", some skipped" : "");
    if (lt_failures) return 1;
    if (lt_skipped) return 77;
    if (lt_checks == 0) {
        fprintf(stderr, "%s: case '%s' made no check: that is not a pass\n", prog, label);
        return 1;
    }
    return 0;
}

/* A program of cases that takes no argument after the case's name. */
static inline int lt_main(int argc, char **argv, const lt_case *cases, int n)
{
    const lt_program p = {.cases = cases, .n = n};
    return lt_run(argc, argv, &p);
}

/* ------------------------------------------------------------------ the sanitizer pass */
/* LT_SANITIZED is 1 in a build under AddressSanitizer (gcc: __SANITIZE_ADDRESS__; clang:
 * __has_feature(address_sanitizer)), the build of `-DLAGSIM_SANITIZE=ON` (ASan and
 * UBSan), else 0. The compiler says it: no option or environment a run must remember. */
#if defined(__SANITIZE_ADDRESS__)
#define LT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LT_SANITIZED 1
#endif
#endif
#ifndef LT_SANITIZED
#define LT_SANITIZED 0
#endif

/* The span of a test that integrates a long horizon or repeats a computation many times
 * for numerical evidence alone: FULL in a plain build, SANITIZED under the sanitizers.
 * They check memory and undefined behaviour, which depend on the paths a run takes, not on
 * how long it integrates: the shorter span must take the same paths (every case, model,
 * method and branch of the full one), and the test states its claim for the span it ran,
 * with a tolerance that holds there and still fails on a broken method (docs/testing.md,
 * "The sanitizer pass's spans"). Roughly a quarter of the full span: the sanitized build
 * runs the same work 8 to 11 times slower. */
static inline double lt_span(double full, double sanitized)
{
    return LT_SANITIZED ? sanitized : full;
}

/* ------------------------------------------------------------------ LCM ports */
/* n UDP ports in a row, P .. P + n - 1 (P even, in [20000, 60000) below the kernel's
 * ephemeral ports), this process's own
 * until it ends: the rule of tests/common/lcm_port.py (which says why), held as
 * lagsim-eval and lagsim-sweep hold theirs (server/wire/lagsim_port.h), pair by pair: an
 * exclusive flock on LOCK_DIR/lagsim-udp-P.lock (the first of /run/lock, /var/lock, /tmp),
 * opened read-only and created if missing, and no socket of this host bound to a port
 * (/proc/net/udp, udp6). Returns P, or -1 when none is free. */
static inline bool lt_udp_bound(int port)
{
    static const char *const files[] = {"/proc/net/udp", "/proc/net/udp6"};
    for (int f = 0; f < 2; f++) {
        FILE *in = fopen(files[f], "r");
        if (!in) continue;
        char line[512];
        bool found = false;
        while (!found && fgets(line, sizeof line, in)) {
            char local[128];
            unsigned p;
            if (sscanf(line, " %*s %127s", local) == 1) {
                char *colon = strrchr(local, ':');
                found = colon && sscanf(colon + 1, "%x", &p) == 1 && (int)p == port;
            }
        }
        fclose(in);
        if (found) return true;
    }
    return false;
}

static inline int lt_pair_lock(int port)
{
    static const char *const dirs[] = {"/run/lock", "/var/lock", "/tmp"};
    const char *dir = "/tmp";
    struct stat st;
    for (int k = 0; k < 3; k++)
        if (stat(dirs[k], &st) == 0 && S_ISDIR(st.st_mode)) {
            dir = dirs[k];
            break;
        }
    char path[4096];
    snprintf(path, sizeof path, "%s/lagsim-udp-%d.lock", dir, port);
    const int flags = O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC;
    int fd = open(path, flags);
    if (fd < 0 && errno == ENOENT) fd = open(path, flags | O_CREAT | O_EXCL, 0644);
    if (fd < 0 && errno == EEXIST) fd = open(path, flags); /* another made it meanwhile */
    if (fd < 0) return -1;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || flock(fd, LOCK_EX | LOCK_NB) != 0) {
        close(fd);
        return -1;
    }
    return fd; /* open until the process ends: the lock goes with it */
}

/* The first of the kernel's ephemeral ports (a sender's socket gets one, bound without
 * SO_REUSEADDR: a bus there fails to bind): the tests' range ends below it. */
static inline int lt_ephemeral_low(void)
{
    int low = 32768, high;
    FILE *f = fopen("/proc/sys/net/ipv4/ip_local_port_range", "r");
    if (f) {
        if (fscanf(f, "%d %d", &low, &high) != 2) low = 32768;
        fclose(f);
    }
    return low;
}

static inline int lt_lcm_ports(int n)
{
    const int first = 20000, pairs = (n + 1) / 2;
    int end = lt_ephemeral_low();
    if (end > 60000) end = 60000;
    if (end < first + 2000) end = first + 2000;
    const int blocks = (end - first) / 2 - (pairs - 1);
    const int start = (int)(((long long)getpid() * 7919) % blocks);
    if (pairs > 8) return -1;
    for (int k = 0; k < blocks; k++) {
        int p = first + 2 * ((start + k) % blocks), fds[8], got = 0;
        bool ok = true;
        for (int q = 0; q < 2 * pairs && ok; q++) ok = !lt_udp_bound(p + q);
        for (int q = 0; q < pairs && ok; q++) {
            fds[got] = lt_pair_lock(p + 2 * q);
            ok = fds[got] >= 0;
            if (ok) got++;
        }
        for (int q = 0; q < 2 * pairs && ok; q++) ok = !lt_udp_bound(p + q); /* bound meanwhile */
        if (ok) return p;
        while (got > 0) close(fds[--got]);
    }
    return -1;
}

/* LCM_DEFAULT_URL set to udpm://239.255.76.67:P?ttl=0&recv_buf_size=4194304 on a port pair
 * of this process's own (lt_lcm_ports(2)): every LCM user the test starts or creates that
 * names no URL meets on it, and hears nothing of any other run on the machine. */
static inline void lt_private_lcm(void)
{
    int port = lt_lcm_ports(2);
    if (port < 0) {
        fprintf(stderr, "no free LCM port pair (lt_lcm_ports)\n");
        exit(1);
    }
    char url[96];
    snprintf(url, sizeof url, "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=4194304", port);
    setenv("LCM_DEFAULT_URL", url, 1);
}

/* ------------------------------------------------------------------ seeded RNG */
typedef struct { uint64_t s; } lt_rng;

/* splitmix64: a fixed, portable sequence for a given seed. */
static inline uint64_t lt_next(lt_rng *r)
{
    uint64_t z = (r->s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
/* uniform in [a, b) */
static inline double lt_uniform(lt_rng *r, double a, double b)
{
    return a + (b - a) * (double)(lt_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

#endif
