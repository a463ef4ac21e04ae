/*
 * lagsimd internals shared by the command line (main.c), offline runs (offline.c), the
 * real-time LCM server (realtime.c) and replay (replay.c).
 */
#ifndef LAGSIMD_DAEMON_H
#define LAGSIMD_DAEMON_H

#include <stdbool.h>
#include <stdint.h>
#include "lagsim_wire.h"
#include "scene.h"

typedef struct lagsimd_opts {
    bool quiet;          /* -q: only warnings and errors on stderr */
    double duration;     /* --duration: sim seconds to run, <= 0 = until stopped */
    const char *csv;     /* --offline: CSV path, "-" = stdout, NULL = no CSV */
    /* where the scene came from, for changes made while running (control_t SET): the
     * file's bytes, its name and the --set overrides, in order */
    const char *scene_name;
    const char *scene_text;
    size_t scene_len;
    const char *const *sets;
    int nsets;
    const char *log;     /* --log: the real-time server's LCM log, NULL = none */
    size_t log_ring;     /* --log-buffer: bytes between the loop and the writer, 0 = default */
    bool log_increment;  /* --increment: the next file of the series FILE.000000, ... */
    int log_keep;        /* --keep N: the series' newest N files kept, 0 = all */
    int64_t log_split;   /* --split-mb: bytes per file of the series, 0 = one file */
    double tolerance;    /* --replay: the largest difference that passes (default 0) */
    bool force;          /* --force: --log and --csv may replace an existing file */
} lagsimd_opts;

/* What lagsimd's parts return: codes of the one space (lagsim/result.h), which main turns
 * into the exit status with lag_result_exit (0, 1 and 2 for these three). */
#define LAGSIMD_EXIT_OK LAG_OK
#define LAGSIMD_EXIT_RUNTIME LAG_ERR_RUNTIME /* exit 1 */
#define LAGSIMD_EXIT_USAGE LAG_ERR_USAGE     /* exit 2: nothing ran */

/* The reference of a scene's joints (ref, its `reference:` with the changes made while
 * running) at sim time t and tick step, as published on <PREFIX>_REFERENCE: the joints
 * with a reference in the model's order, r and r' from lag_reference_eval (utime 0: the
 * publisher sets it). num_joints 0 when the scene has none. OUT: m */
void lagsimd_reference_at(const lag_scene_reference *ref, lag_model_kind kind, double t,
                          int64_t step, lag_wire_reference *m);

/* Offline: simulate as fast as possible, write CSV. Returns a lag_result. */
lag_result lagsimd_offline(const lag_scene *sc, const lagsimd_opts *o);
/* The real-time LCM server until SIGINT/SIGTERM (or opts->duration). Returns a lag_result. */
lag_result lagsimd_realtime(const lag_scene *sc, const lagsimd_opts *o);
/* Re-simulates a run recorded by lagsimd --log or lcm-logger from the efforts in its
 * logged states (and the commanded inputs, when the log has them) and prints the largest
 * difference from the logged states. Returns LAG_OK when it is at most o->tolerance,
 * LAG_ERR_MISMATCH when it is larger, LAG_ERR_RUNTIME when nothing could be checked. */
lag_result lagsimd_replay(const lag_scene *sc, const char *log_path, const lagsimd_opts *o);
/* The integrator a calibration chose, as scene overrides ("integrator.method=rk4",
 * "integrator.dt=0.0025", dopri5's rtol and atol): applied after the scene's own --set,
 * so that every reload of the scene (a change made while running) gives the same. */
typedef struct lagsimd_choice {
    int n;
    char kv[4][64];
} lagsimd_choice;
/* A scene with integrator.error: measures the integrator settings on it and chooses the
 * cheapest that meets the error (in a paced real-time run, one that also keeps a margin
 * to real time), printing the choice in one line unless quiet. Offline, a scene no
 * setting meets runs with the most accurate one and a warning; paced, it is refused.
 * Returns LAGSIMD_EXIT_OK when the scene may run; ch->n = 0 without
 * integrator.error. OUT: ch */
lag_result lagsimd_choose_integrator(const lag_scene *sc, bool offline, bool quiet,
                                      lagsimd_choice *ch);
/* --cost: the table of what each setting costs on this scene and machine, on stdout;
 * with png, gnuplot's work-precision diagram too, written by lag_out_open's rules (force:
 * replace an existing file). Returns a lag_result. */
lag_result lagsimd_cost(const lag_scene *sc, const char *png, bool force);

#endif
