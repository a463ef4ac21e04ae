/*
 * lagsim work-precision benchmark: scenes, our runner (lag_sim), reference solutions,
 * error measures and CPU timing. See bench.h for how a scene is run.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lagsim_clock.h"

#include "bench.h"

/* ---------------------------------------------------------------- scenes */

/* Manipulator torque profile: the inverse dynamics of a smooth desired swing about the
 * hanging position, q1_d(t) = -pi/2 + a1 (1 - cos w1 t), q2_d(t) = q20 + a2 (1 - cos w2 t):
 * tau = M(q_d) qdd_d + C(q_d, qd_d) qd_d + g(q_d), evaluated from the core's closed forms.
 * Sampled once per period and held, it drives the arm open loop along (not exactly on)
 * the desired motion: a smooth, bounded trajectory. (The slide is open-loop unstable
 * while the arm turns, q2dd ~ q1d^2 q2; the swing keeps q1d small, so errors grow
 * only by a modest factor over the horizon.) OUT: tau (2) */
static void manip_input(const lag_model *m, double t, double *tau)
{
    const double a1 = 0.4, w1 = 2.0, a2 = 0.1, w2 = 3.0, q20 = 0.5;
    const double hang = -1.57079632679489661923;
    double q[2] = {hang + a1 * (1.0 - cos(w1 * t)), q20 + a2 * (1.0 - cos(w2 * t))};
    double qd[2] = {a1 * w1 * sin(w1 * t), a2 * w2 * sin(w2 * t)};
    double qdd[2] = {a1 * w1 * w1 * cos(w1 * t), a2 * w2 * w2 * cos(w2 * t)};
    double M[4], h[2];
    lag_model_mass(m, q, M);
    lag_model_bias(m, q, qd, h);
    tau[0] = M[0] * qdd[0] + M[1] * qdd[1] + h[0];
    tau[1] = M[2] * qdd[0] + M[3] * qdd[1] + h[1];
}

void bench_scenes(bench_scene *s, bool quick)
{
    const double pi = 3.14159265358979323846;
    memset(s, 0, BENCH_SCENE_COUNT * sizeof *s);

    /* Hanging DIPC released from a swing: regular (non-chaotic) motion. */
    s[0].name = "dipc_swing";
    s[0].title = "DIPC hanging, swinging (theta1 = pi+0.5, theta2 = pi-0.3)";
    lag_model_default(&s[0].model, LAG_MODEL_DIPC);
    s[0].q0[1] = pi + 0.5;
    s[0].q0[2] = pi - 0.3;
    s[0].horizon = quick ? 1.0 : 10.0;

    /* Manipulator hanging at rest, then swung by the smooth torque profile above. */
    s[1].name = "manip_torque";
    s[1].title = "manipulator from hanging, smooth torque profile held per 10 ms period";
    lag_model_default(&s[1].model, LAG_MODEL_MANIPULATOR);
    s[1].q0[0] = -pi / 2;
    s[1].q0[1] = 0.5;
    s[1].horizon = quick ? 1.0 : 5.0;
    s[1].input = manip_input;

    /* Stick released from rest 0.2 rad off the vertical; the horizon ends before it
     * reaches the floor (phi = 0). */
    s[2].name = "stick_fall";
    s[2].title = "stick falling from rest (phi = pi/2 - 0.2)";
    lag_model_default(&s[2].model, LAG_MODEL_STICK);
    s[2].q0[1] = pi / 2 - 0.2;
    s[2].horizon = quick ? 0.5 : 1.0;

    /* DIPC near upright: chaotic; short horizon for trajectory error. */
    s[3].name = "dipc_chaos";
    s[3].title = "DIPC near upright (theta1 = 0.1, theta2 = -0.1), chaotic";
    lag_model_default(&s[3].model, LAG_MODEL_DIPC);
    s[3].q0[1] = 0.1;
    s[3].q0[2] = -0.1;
    s[3].horizon = quick ? 1.0 : 2.0;
    s[3].chaotic = true;

    for (int i = 0; i < BENCH_SCENE_COUNT; i++) s[i].period = 0.01;
}

int bench_periods(const bench_scene *sc) { return (int)lround(sc->horizon / sc->period); }

int bench_samples_alloc(bench_samples *s, const bench_scene *sc)
{
    s->n = bench_periods(sc) + 1;
    s->nq = sc->model.nq;
    s->q = calloc((size_t)s->n * LAG_MAX_DOF, sizeof(double));
    s->qd = calloc((size_t)s->n * LAG_MAX_DOF, sizeof(double));
    return (s->q && s->qd) ? 0 : -1;
}

void bench_samples_free(bench_samples *s)
{
    free(s->q);
    free(s->qd);
    s->q = s->qd = NULL;
    s->n = 0;
}

/* ---------------------------------------------------------------- labels */
const char *bench_impl_name(bench_impl impl)
{
    switch (impl) {
    case BENCH_LAGSIM: return "lagsim";
    case BENCH_MUJOCO: return "mujoco";
    case BENCH_SUNDIALS: return "sundials";
    }
    return "?";
}

static const char *const mj_names[BENCH_MJ_COUNT] = {"Euler", "RK4", "implicit"};
static const char *const sun_names[BENCH_SUN_COUNT] = {"ARKODE-DP5", "ARKODE-RK4",
                                                       "CVODE-Adams", "CVODE-BDF"};

const char *bench_method_label(const bench_config *c, char *buf, int len)
{
    const char *m = "?";
    if (c->impl == BENCH_LAGSIM) m = c->continuous ? "dopri5-continuous"
                                                   : lag_method_name((lag_method)c->method);
    else if (c->impl == BENCH_MUJOCO) m = mj_names[c->method];
    else if (c->impl == BENCH_SUNDIALS) m = sun_names[c->method];
    snprintf(buf, (size_t)len, "%s", m);
    return buf;
}

bool bench_config_adaptive(const bench_config *c)
{
    if (c->impl == BENCH_LAGSIM) return c->method == LAG_DOPRI5;
    if (c->impl == BENCH_SUNDIALS) return c->method != BENCH_SUN_ARK_RK4;
    return false;
}

/* ---------------------------------------------------------------- our runner */

/* Runs the scene through lag_sim as the real-time daemon does (server/daemon/realtime.c):
 * per control period, sample the input, lag_sim_set_input, then
 * lag_sim_advance(sim, ticks_per_period, false). Fixed-step methods take period / dt
 * steps; dopri5 (tick c->dt) steps freely inside the period and shortens its last step
 * to land on the period end, where the state is published and the input may change
 * (lag_sim_set_input restarts it when the input did change). With c->continuous,
 * lag_sim_advance(.., true) as lagsimd's offline mode: dopri5 steps past period ends and
 * delivers the state there by dense output. */
int bench_run_lagsim(const bench_scene *sc, const bench_config *c, bench_samples *out,
                     int64_t *rhs, int64_t *steps)
{
    *rhs = 0;
    *steps = 0;
    lag_sim_def def = lag_default_sim_def(sc->model.kind);
    def.model = sc->model;
    def.integrator.method = (lag_method)c->method;
    def.integrator.dt = c->dt;
    if (c->rtol > 0) {
        def.integrator.rtol = c->rtol;
        def.integrator.atol = c->rtol * BENCH_ATOL_FACTOR;
    }
    memcpy(def.q0, sc->q0, sizeof def.q0);
    memcpy(def.qd0, sc->qd0, sizeof def.qd0);
    char err[256];
    static lag_sim sim; /* static: keeps the timed loop free of a large stack frame */
    if (lag_sim_init(&sim, &def, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "bench: lag_sim_init: %s\n", err);
        return -1;
    }
    const int nq = sc->model.nq;
    const int64_t per = llround(sc->period / c->dt);
    const int np = bench_periods(sc);
    double tau[LAG_MAX_DOF] = {0};
    memcpy(out->q, sim.q, sizeof(double) * (size_t)nq);
    memcpy(out->qd, sim.qd, sizeof(double) * (size_t)nq);
    int status = 0;
    for (int k = 0; k < np; k++) {
        if (sc->input) {
            sc->input(&sc->model, k * sc->period, tau);
            lag_sim_set_input(&sim, tau);
        }
        lag_result r = lag_sim_advance(&sim, per, c->continuous);
        if (r != LAG_OK) {
            status = (int)r;
            break;
        }
        memcpy(out->q + (size_t)(k + 1) * LAG_MAX_DOF, sim.q, sizeof(double) * (size_t)nq);
        memcpy(out->qd + (size_t)(k + 1) * LAG_MAX_DOF, sim.qd, sizeof(double) * (size_t)nq);
    }
    *rhs = sim.stats.rhs_evals;
    *steps = sim.stats.steps_accepted;
    return status;
}

/* ---------------------------------------------------------------- timing */
double bench_cpu_now(void)
{
    return lag_clock_process_cpu_s();
}

static bench_runner runner_for(bench_impl impl)
{
    switch (impl) {
    case BENCH_LAGSIM: return bench_run_lagsim;
#ifdef LAGSIM_HAVE_MUJOCO
    case BENCH_MUJOCO: return bench_run_mujoco;
#endif
#ifdef LAGSIM_HAVE_SUNDIALS
    case BENCH_SUNDIALS: return bench_run_sundials;
#endif
    default: return NULL;
    }
}

/* Minimum CPU time of `reps` runs; a run longer than 0.5 s is repeated at most twice
 * (keeps the whole benchmark within a few minutes on a 2-core machine). */
bench_result bench_measure(const bench_scene *sc, const bench_config *c, int reps,
                           bench_samples *out)
{
    bench_result res = {0};
    bench_runner run = runner_for(c->impl);
    if (!run) {
        res.status = -100;
        return res;
    }
    res.cpu = INFINITY;
    /* Peers load and compile models and allocate on their first use: keep it untimed. */
    static bool warm[3][LAG_MODEL_COUNT];
    if (!warm[c->impl][sc->model.kind]) {
        warm[c->impl][sc->model.kind] = true;
        run(sc, c, out, &res.rhs, &res.steps);
    }
    for (int r = 0; r < reps; r++) {
        double t0 = bench_cpu_now();
        int st = run(sc, c, out, &res.rhs, &res.steps);
        double t1 = bench_cpu_now();
        if (st != 0) {
            res.status = st;
            return res;
        }
        if (t1 - t0 < res.cpu) res.cpu = t1 - t0;
        if (t1 - t0 > 0.5 && r >= 1) break;
    }
    return res;
}

/* ---------------------------------------------------------------- errors */
double bench_energy(const lag_model *m, const double *q, const double *qd)
{
    return lag_model_kinetic(m, q, qd) + lag_model_potential(m, q);
}

double bench_max_pos_err(const bench_samples *a, const bench_samples *b)
{
    double e = 0;
    int n = a->n < b->n ? a->n : b->n;
    for (int k = 0; k < n; k++)
        for (int i = 0; i < a->nq; i++) {
            double d = fabs(a->q[k * LAG_MAX_DOF + i] - b->q[k * LAG_MAX_DOF + i]);
            if (!(d <= e)) e = d; /* NaN propagates */
        }
    return e;
}

double bench_max_energy_err(const bench_scene *sc, const bench_samples *a,
                            const bench_samples *b)
{
    double e = 0;
    int n = a->n < b->n ? a->n : b->n;
    for (int k = 0; k < n; k++) {
        double ea = bench_energy(&sc->model, a->q + k * LAG_MAX_DOF, a->qd + k * LAG_MAX_DOF);
        double eb = bench_energy(&sc->model, b->q + k * LAG_MAX_DOF, b->qd + k * LAG_MAX_DOF);
        double d = fabs(ea - eb);
        if (!(d <= e)) e = d;
    }
    return e;
}

/* ---------------------------------------------------------------- reference */

/* The reference: our dopri5 at rtol 1e-13 (atol 1e-15), landing exactly on every period
 * end (no dense output), checked against our gauss4 (2-stage Gauss-Legendre, an
 * independent implicit method) at a step of period / 200. */
int bench_reference_build(const bench_scene *sc, bench_reference *r)
{
    memset(r, 0, sizeof *r);
    if (bench_samples_alloc(&r->ref, sc) != 0) return -1;
    bench_samples chk;
    if (bench_samples_alloc(&chk, sc) != 0) return -1;
    int64_t rhs, steps;
    /* Lands on every period end (continuous = false), forced or not. */
    int st = 0;
    {
        lag_sim_def def = lag_default_sim_def(sc->model.kind);
        def.model = sc->model;
        def.integrator.method = LAG_DOPRI5;
        def.integrator.dt = sc->period;
        def.integrator.rtol = 1e-13;
        def.integrator.atol = 1e-15;
        def.integrator.dt_min = 1e-14;
        memcpy(def.q0, sc->q0, sizeof def.q0);
        memcpy(def.qd0, sc->qd0, sizeof def.qd0);
        char err[256];
        static lag_sim sim;
        if (lag_sim_init(&sim, &def, err, sizeof err) != LAG_OK) {
            fprintf(stderr, "bench: reference: %s\n", err);
            return -1;
        }
        double tau[LAG_MAX_DOF] = {0};
        const int nq = sc->model.nq;
        memcpy(r->ref.q, sim.q, sizeof(double) * (size_t)nq);
        memcpy(r->ref.qd, sim.qd, sizeof(double) * (size_t)nq);
        for (int k = 0; k < bench_periods(sc) && st == 0; k++) {
            if (sc->input) {
                sc->input(&sc->model, k * sc->period, tau);
                lag_sim_set_input(&sim, tau);
            }
            st = (int)lag_sim_advance(&sim, 1, false);
            memcpy(r->ref.q + (size_t)(k + 1) * LAG_MAX_DOF, sim.q, sizeof(double) * (size_t)nq);
            memcpy(r->ref.qd + (size_t)(k + 1) * LAG_MAX_DOF, sim.qd, sizeof(double) * (size_t)nq);
        }
    }
    if (st != 0) {
        fprintf(stderr, "bench: reference dopri5 failed on %s: %s\n", sc->name,
                lag_result_string((lag_result)st));
        bench_samples_free(&chk);
        return -1;
    }
    r->gauss_dt = sc->period / 200.0;
    bench_config g4 = {BENCH_LAGSIM, LAG_GAUSS4, r->gauss_dt, 0};
    st = bench_run_lagsim(sc, &g4, &chk, &rhs, &steps);
    if (st != 0) {
        fprintf(stderr, "bench: reference gauss4 failed on %s: %s\n", sc->name,
                lag_result_string((lag_result)st));
        bench_samples_free(&chk);
        return -1;
    }
    r->agreement = bench_max_pos_err(&r->ref, &chk);
    bench_samples_free(&chk);
    return 0;
}

void bench_reference_free(bench_reference *r) { bench_samples_free(&r->ref); }
