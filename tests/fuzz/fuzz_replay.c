/*
 * Fuzz target: lagsimd --replay end to end on an arbitrary log, with the scene of
 * config/dipc.yaml, and again with an actuator lag added to it (the replay then reads the
 * log's <PREFIX>_INPUT records, in a first pass and among the states). The bytes are written to an anonymous in-memory file (memfd) whose
 * /proc/self/fd path is given to the replay, as a user would give a log's path.
 *
 * The replay must end with exit status 0 or 1 (never 2: the scene is valid), without
 * crashing, hanging, leaking or undefined behaviour. Its report (stdout and stderr) goes
 * to /dev/null while it runs; sanitizer reports go to the real stderr.
 */
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

#include "daemon.h"

/* In sanitizer builds: where their reports go (absent otherwise). */
extern void __sanitizer_set_report_fd(void *fd) __attribute__((weak));

static lag_scene g_scene, g_lagged;
/* the scene file's bytes: the source the log's changes made while running (set events)
 * are validated against, as lagsimd --replay has them */
static char *g_text;
static size_t g_len;
static const char **g_lag_sets; /* g_lagged's --set */
static int g_null = -1, g_out = -1, g_err = -1;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    char err[512];
    static const char *lag[] = {"effects.actuator={theta0: {lag: 0.004, max: 40}}"};
    g_lag_sets = lag;
    if (lag_scene_load(LAGSIM_SOURCE_DIR "/config/dipc.yaml", NULL, 0, &g_scene, err,
                       sizeof err) != 0 ||
        lag_scene_load(LAGSIM_SOURCE_DIR "/config/dipc.yaml", lag, 1, &g_lagged, err,
                       sizeof err) != 0) {
        fprintf(stderr, "fuzz_replay: %s\n", err);
        exit(1);
    }
    if (lag_scene_read(LAGSIM_SOURCE_DIR "/config/dipc.yaml", &g_text, &g_len, err, sizeof err) != 0) {
        fprintf(stderr, "fuzz_replay: %s\n", err);
        exit(1);
    }
    /* the replay's report is not what is checked: /dev/null while it runs */
    g_null = open("/dev/null", O_WRONLY);
    g_out = dup(1);
    g_err = dup(2);
    if (g_null < 0 || g_out < 0 || g_err < 0) exit(1);
    if (__sanitizer_set_report_fd) __sanitizer_set_report_fd((void *)(intptr_t)g_err);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    int fd = memfd_create("fuzz_replay", 0);
    if (fd < 0) abort();
    size_t done = 0;
    while (done < size) {
        ssize_t k = write(fd, data + done, size - done);
        if (k <= 0) abort();
        done += (size_t)k;
    }
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    lagsimd_opts o = {.quiet = true, .scene_name = "dipc.yaml", .scene_text = g_text,
                      .scene_len = g_len};
    fflush(stdout);
    fflush(stderr);
    dup2(g_null, 1);
    dup2(g_null, 2);
    lag_result rc = lagsimd_replay(&g_scene, path, &o);
    lagsimd_opts ol = o;
    ol.sets = g_lag_sets;
    ol.nsets = 1;
    lag_result rc_lagged = lagsimd_replay(&g_lagged, path, &ol);
    fflush(stdout);
    fflush(stderr);
    dup2(g_out, 1);
    dup2(g_err, 2);
    close(fd);
    /* a log is checked or not (exit 0 or 1), never a usage or scene error */
    if (lag_result_exit(rc) > 1) abort();
    if (lag_result_exit(rc_lagged) > 1) abort();
    return 0;
}
