/*
 * The test harness of the core's C tests (tests/core, tests/effects): plain C, no
 * framework (Box2D's ENSURE), one copy for every program.
 *
 *   ENSURE(cond)                        counts a check; prints the expression if false
 *   ENSURE_NEAR(got, want, tol, fmt...) |got - want| <= tol, else prints both and context
 *   LT_FAIL(fmt...)                     counts a failed check with a message
 *
 * A program lists its cases in a table and hands it to lt_main, which
 *   - with no argument runs every case but those marked LT_BY_NAME (slow ones);
 *   - with `--list` prints one case a line ("name" or "name slow"): tests/common/cases.cmake
 *     turns that list into one ctest per case, so a case added to a table is a ctest
 *     without anyone listing it again;
 *   - with a name runs that case; a name it does not know is an error (exit 2), never a
 *     pass;
 *   - fails when the cases run made no check at all ("0 checks" is not a pass), unless a
 *     case said why it could not run here (lt_skip): then it exits 77, which ctest
 *     reports as skipped, not passed.
 * main returns non-zero when anything failed.
 */
#ifndef LAGSIM_TEST_H
#define LAGSIM_TEST_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int lt_failures = 0;
static int lt_checks = 0;
#define LT_QUIET_AFTER 30 /* failures printed in detail; the rest are only counted */

#define ENSURE(cond)                                                                       \
    do {                                                                                   \
        lt_checks++;                                                                       \
        if (!(cond)) {                                                                     \
            if (lt_failures++ < LT_QUIET_AFTER)                                            \
                fprintf(stderr, "%s:%d: ENSURE failed: %s\n", __FILE__, __LINE__, #cond);  \
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

/* Runs the cases named by argv (see the header comment). */
static inline int lt_main(int argc, char **argv, const lt_case *cases, int n)
{
    const char *prog = argc > 0 ? argv[0] : "test";
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
    if (argc > 2) {
        fprintf(stderr, "usage: %s [--list | CASE]\n", prog);
        return 2;
    }
    bool ran = false;
    for (int i = 0; i < n; i++) {
        bool named = argc > 1 && strcmp(argv[1], cases[i].name) == 0;
        if (named || (argc == 1 && !(cases[i].flags & LT_BY_NAME))) {
            cases[i].fn(cases[i].arg);
            ran = true;
        }
    }
    if (!ran) {
        fprintf(stderr, "%s: unknown case '%s'; cases:", prog, label);
        for (int i = 0; i < n; i++) fprintf(stderr, " %s", cases[i].name);
        fprintf(stderr, "\n");
        return 2;
    }
    printf("%s: %d checks, %d failed%s\n", label, lt_checks, lt_failures,
           lt_skipped ? ", some skipped" : "");
    if (lt_failures) return 1;
    if (lt_skipped) return 77;
    if (lt_checks == 0) {
        fprintf(stderr, "%s: case '%s' made no check: that is not a pass\n", prog, label);
        return 1;
    }
    return lt_failures ? 1 : 0;
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
