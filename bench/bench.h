/*
 * lagsim work-precision benchmark: shared declarations.
 *
 * A scene is a model, an initial state, a horizon and an input profile. Every
 * implementation (ours through lag_sim, MuJoCo, SUNDIALS) runs a scene the same way:
 * the horizon is cut into output periods of `period` seconds; at the start of period k
 * the input tau(k * period) is sampled and held constant over the period (what the
 * daemon does with a command held over its ticks), and the state (q, qd) is recorded at
 * every period end. Every fixed step dt in the sweep divides the period, so all
 * implementations and the reference integrate exactly the same piecewise-smooth ODE.
 */
#ifndef LAGSIM_BENCH_H
#define LAGSIM_BENCH_H

#include <stdbool.h>
#include <stdint.h>

#include "lagsim/lagsim.h"

/* ---------------------------------------------------------------- scenes */
typedef struct bench_scene {
    const char *name;      /* "dipc_swing", "manip_torque", "stick_fall", "dipc_chaos" */
    const char *title;     /* for plots and tables */
    lag_model model;
    double q0[LAG_MAX_DOF];
    double qd0[LAG_MAX_DOF];
    double horizon;        /* s */
    double period;         /* s, output / input period; every dt divides it */
    bool chaotic;          /* trajectory error meaningful only on the short horizon */
    /* Input sampled at the start of each period (NULL = unforced). OUT: tau (nq) */
    void (*input)(const lag_model *m, double t, double *tau);
} bench_scene;

enum { BENCH_SCENE_COUNT = 4 };
/* The benchmark's scenes; `quick` shortens the horizons (ctest). */
void bench_scenes(bench_scene *scenes, bool quick);

/* ---------------------------------------------------------------- trajectories */
/* Samples at t = k * period, k = 0..n-1 (n = horizon / period + 1). */
typedef struct bench_samples {
    int n;        /* number of samples */
    int nq;
    double *q;    /* n * LAG_MAX_DOF */
    double *qd;   /* n * LAG_MAX_DOF */
} bench_samples;

int bench_samples_alloc(bench_samples *s, const bench_scene *sc);
void bench_samples_free(bench_samples *s);
/* Number of output periods over the horizon. */
int bench_periods(const bench_scene *sc);

/* ---------------------------------------------------------------- one run */
/* What a run is: an implementation, a method and its step or tolerance. */
typedef enum bench_impl { BENCH_LAGSIM, BENCH_MUJOCO, BENCH_SUNDIALS } bench_impl;
const char *bench_impl_name(bench_impl impl);

/* Peer method ids (BENCH_MUJOCO: mjINT_*; BENCH_SUNDIALS: below). */
enum { BENCH_MJ_EULER = 0, BENCH_MJ_RK4 = 1, BENCH_MJ_IMPLICIT = 2, BENCH_MJ_COUNT = 3 };
enum { BENCH_SUN_ARK_DP5 = 0, BENCH_SUN_ARK_RK4, BENCH_SUN_CV_ADAMS, BENCH_SUN_CV_BDF,
       BENCH_SUN_COUNT };

typedef struct bench_config {
    bench_impl impl;
    int method;     /* lag_method, BENCH_MJ_*, BENCH_SUN_* */
    double dt;      /* fixed step (s); for adaptive methods the output tick */
    double rtol;    /* adaptive methods (atol = rtol * BENCH_ATOL_FACTOR); 0 otherwise */
    bool continuous;/* lagsim dopri5 only: lag_sim_advance(.., true), steps past period ends
                     * and delivers the state by dense output (lagsimd's offline mode) */
} bench_config;

#define BENCH_ATOL_FACTOR 1e-2

/* Full display name: "lagsim rk4", "mujoco RK4", "sundials ARKODE DP5" ... */
const char *bench_method_label(const bench_config *c, char *buf, int len);
bool bench_config_adaptive(const bench_config *c);

/* Result of running one config on one scene. */
typedef struct bench_result {
    int status;             /* 0 ok; otherwise the run failed (fault, blow-up, peer error) */
    double cpu;             /* CPU seconds for the whole horizon, minimum over runs */
    int64_t rhs;            /* right-hand-side (forward dynamics) evaluations, horizon */
    int64_t steps;          /* integrator steps over the horizon */
} bench_result;

/* A runner integrates scene `sc` with config `c` over the horizon once and fills the
 * samples. It returns 0 or a nonzero status. OUT: out, rhs, steps */
typedef int (*bench_runner)(const bench_scene *sc, const bench_config *c,
                            bench_samples *out, int64_t *rhs, int64_t *steps);

int bench_run_lagsim(const bench_scene *sc, const bench_config *c, bench_samples *out,
                     int64_t *rhs, int64_t *steps);
#ifdef LAGSIM_HAVE_MUJOCO
int bench_run_mujoco(const bench_scene *sc, const bench_config *c, bench_samples *out,
                     int64_t *rhs, int64_t *steps);
const char *bench_mujoco_version(void);
#endif
#ifdef LAGSIM_HAVE_SUNDIALS
int bench_run_sundials(const bench_scene *sc, const bench_config *c, bench_samples *out,
                       int64_t *rhs, int64_t *steps);
const char *bench_sundials_version(void);
#endif

/* Runs `c` `reps` times (the samples of the last run are kept), CPU time = minimum. */
bench_result bench_measure(const bench_scene *sc, const bench_config *c, int reps,
                           bench_samples *out);

/* ---------------------------------------------------------------- reference, errors */
typedef struct bench_reference {
    bench_samples ref;      /* dopri5 at rtol 1e-13 */
    double agreement;       /* max |q| difference to gauss4 at a tiny step over the horizon */
    double gauss_dt;        /* step of the gauss4 check */
} bench_reference;

int bench_reference_build(const bench_scene *sc, bench_reference *r);
void bench_reference_free(bench_reference *r);

/* Max over samples and coordinates of |q - q_ref| (m or rad). */
double bench_max_pos_err(const bench_samples *a, const bench_samples *b);
/* Max over samples of |E - E_ref| (J), energy evaluated by lag_model_kinetic/potential. */
double bench_max_energy_err(const bench_scene *sc, const bench_samples *a,
                            const bench_samples *b);
double bench_energy(const lag_model *m, const double *q, const double *qd);

/* CPU time, s (CLOCK_PROCESS_CPUTIME_ID). */
double bench_cpu_now(void);

#endif
