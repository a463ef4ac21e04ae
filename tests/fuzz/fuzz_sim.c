/*
 * Fuzz target: the core from a definition made of arbitrary bytes.
 *
 * The bytes choose a model, an integrator, parameters, effects and their settings, an
 * initial state and a schedule of inputs. What lag_sim_def_validate accepts must then
 * run without crashing, without undefined behaviour, in bounded time, and every state
 * the core reports as good must be finite (the daemon publishes it). A refused
 * definition or a step refused with an error code is a correct outcome.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"

typedef struct bytes {
    const uint8_t *p;
    size_t n;
} bytes;

static unsigned take_u8(bytes *b)
{
    if (b->n == 0) return 0;
    b->n--;
    return *b->p++;
}

/* A double that is sometimes anything (raw bits: NaN, Inf, 1e308, subnormals) and
 * mostly a plausible magnitude, so that validation lets some definitions through. */
static double take_double(bytes *b)
{
    unsigned sel = take_u8(b);
    if (sel < 16) {
        uint64_t u = 0;
        for (int i = 0; i < 8; i++) u = (u << 8) | take_u8(b);
        double d;
        memcpy(&d, &u, sizeof d);
        return d;
    }
    int16_t mant = (int16_t)(take_u8(b) << 8 | take_u8(b));
    int e = (int)(sel % 13) - 6; /* 1e-6 .. 1e6 */
    return mant / 1000.0 * pow(10.0, e);
}

static void check_finite(const char *what, int n, const double *x)
{
    for (int i = 0; i < n; i++) {
        if (!isfinite(x[i])) {
            fprintf(stderr, "fuzz_sim: non-finite %s[%d] reported as good\n", what, i);
            abort();
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes b = {data, size};
    lag_model_kind kind = (lag_model_kind)(take_u8(&b) % LAG_MODEL_COUNT);
    lag_sim_def def = lag_default_sim_def(kind);
    int nq = def.model.nq;
    const lag_model_info *info = lag_model_info_get(kind);

    /* parameters: each either kept or replaced */
    unsigned mask = take_u8(&b) | take_u8(&b) << 8;
    for (int i = 0; i < info->np && i < 16; i++)
        if (mask & (1u << i)) def.model.p[i] = take_double(&b);

    def.integrator.method = (lag_method)(take_u8(&b) % LAG_METHOD_COUNT);
    if (take_u8(&b) & 1) def.integrator.dt = take_double(&b);
    if (take_u8(&b) & 1) def.integrator.rtol = take_double(&b);
    if (take_u8(&b) & 1) def.integrator.atol = take_double(&b);

    lag_effects_def *e = &def.effects;
    e->enabled = take_u8(&b);
    for (int i = 0; i < nq; i++) {
        e->damping[i] = fabs(take_double(&b));
        e->friction_kinetic[i] = fabs(take_double(&b));
        e->friction_static[i] = e->friction_kinetic[i] * (1.0 + take_u8(&b) / 64.0);
        e->limit_on[i] = take_u8(&b) & 1;
        e->limit_lower[i] = take_double(&b);
        e->limit_upper[i] = take_double(&b);
        e->restitution[i] = take_u8(&b) / 255.0;
        e->actuator_max[i] = (take_u8(&b) & 1) ? fabs(take_double(&b)) : INFINITY;
        e->actuator_tau[i] = fabs(take_double(&b)) * 1e-3;
        e->noise_q[i] = fabs(take_double(&b)) * 1e-3;
        e->noise_qd[i] = fabs(take_double(&b)) * 1e-3;
    }
    e->floor_restitution = take_u8(&b) / 255.0;
    e->n_disturbances = take_u8(&b) % 4;
    for (int k = 0; k < e->n_disturbances; k++) {
        lag_disturbance *d = &e->disturbances[k];
        d->t = take_double(&b);
        d->joint = (int)(take_u8(&b) % (unsigned)nq);
        d->impulse = take_u8(&b) & 1;
        d->value = take_double(&b);
        d->duration = fabs(take_double(&b));
    }
    for (int i = 0; i < nq; i++) {
        def.q0[i] = take_double(&b);
        def.qd0[i] = take_double(&b);
    }

    /* A dopri5 tick may take max_steps steps (100000 by default): bounded, but seconds
     * under the sanitizers for ticks of minutes, and an input runs up to 128 ticks. A
     * small budget keeps each input well under libFuzzer's timeout and still reaches the
     * limit (LAG_ERR_MAX_STEPS). */
    def.integrator.max_steps = 256;

    char err[256];
    if (lag_sim_def_validate(&def, err, sizeof err) != LAG_OK) return 0;
    static lag_sim sim; /* large: not on the stack */
    if (lag_sim_init(&sim, &def, err, sizeof err) != LAG_OK) return 0;

    /* A few control periods of a few ticks each, with inputs from the bytes. */
    for (int period = 0; period < 8; period++) {
        double tau[LAG_MAX_DOF] = {0};
        for (int i = 0; i < nq; i++) tau[i] = take_double(&b);
        lag_sim_set_input(&sim, tau);
        int64_t n = 1 + take_u8(&b) % 16;
        lag_result r = lag_sim_advance(&sim, n, take_u8(&b) & 1);
        check_finite("q", nq, sim.q);
        check_finite("qd", nq, sim.qd);
        double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
        lag_sim_observe(&sim, q, qd);
        check_finite("observed q", nq, q);
        check_finite("observed qd", nq, qd);
        lag_event ev;
        while (lag_sim_poll_event(&sim, &ev)) {
            if (!isfinite(ev.t)) {
                fprintf(stderr, "fuzz_sim: event at non-finite time\n");
                abort();
            }
        }
        if (r != LAG_OK) break;
    }
    return 0;
}
