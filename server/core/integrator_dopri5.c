/*
 * Dormand-Prince 5(4) with the FSAL property, step-size control on the embedded 4th-order
 * error (Hairer, Norsett & Wanner, Solving ODEs I, II.4-II.6, code DOPRI5), and its
 * 4th-order dense output. The internal time/state (s->dp) may run ahead of the public
 * state; the public state at each tick boundary is then interpolated. A step that would
 * cross the stop (the end of the span over which the input holds) is shortened to land on
 * it exactly (needed when the input changes there: the right-hand side is discontinuous
 * at that instant); without a stop (continuous mode) steps run past the end.
 */
#include <math.h>
#include <string.h>
#include "core_internal.h"

/* nodes c = (0, 1/5, 3/10, 4/5, 8/9, 1, 1): autonomous system, not needed */
static const double a21 = 1.0 / 5;
static const double a31 = 3.0 / 40, a32 = 9.0 / 40;
static const double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
static const double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                    a54 = -212.0 / 729;
static const double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247,
                    a64 = 49.0 / 176, a65 = -5103.0 / 18656;
static const double a71 = 35.0 / 384, a73 = 500.0 / 1113, a74 = 125.0 / 192,
                    a75 = -2187.0 / 6784, a76 = 11.0 / 84;
static const double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920,
                    e5 = -17253.0 / 339200, e6 = 22.0 / 525, e7 = -1.0 / 40;
static const double d1 = -12715105075.0 / 11282082432.0, d3 = 87487479700.0 / 32700410799.0,
                    d4 = -10690763975.0 / 1880347072.0, d5 = 701980252875.0 / 199316789632.0,
                    d6 = -1453857185.0 / 822651844.0, d7 = 69997945.0 / 29380423.0;

/* Weighted RMS norm of the error estimate (Hairer's err). */
static double err_norm(int N, const double *err, const double *y0, const double *y1,
                       double rtol, double atol)
{
    double acc = 0.0;
    for (int i = 0; i < N; i++) {
        double sk = atol + rtol * fmax(fabs(y0[i]), fabs(y1[i]));
        double e = err[i] / sk;
        acc += e * e;
    }
    return sqrt(acc / N);
}

/* Initial step (Hairer's HINIT, simplified): h = 0.01 ||y|| / ||f||, bounded by dt. */
static double initial_step(const lag_sim *s, int N, const double *y, const double *f)
{
    const lag_integrator_def *in = &s->def.integrator;
    double dny = 0.0, dnf = 0.0;
    for (int i = 0; i < N; i++) {
        double sk = in->atol + in->rtol * fabs(y[i]);
        dny += (y[i] / sk) * (y[i] / sk);
        dnf += (f[i] / sk) * (f[i] / sk);
    }
    double h = (dny <= 1e-10 || dnf <= 1e-10) ? 1e-6 : 0.01 * sqrt(dny / dnf);
    return fmin(h, in->dt);
}

/* Interpolates the last accepted step at time t (t_prev <= t <= dp.t). OUT: y */
static void dense(const lag_sim *s, int N, double t, double *y)
{
    LAG_ASSERT(t >= s->dp.t_prev && t <= s->dp.t); /* only within the last step */
    double h = s->dp.t - s->dp.t_prev;
    double th = (t - s->dp.t_prev) / h, th1 = 1.0 - th;
    for (int i = 0; i < N; i++)
        y[i] = s->dp.rcont[0][i] +
               th * (s->dp.rcont[1][i] +
                     th1 * (s->dp.rcont[2][i] + th * (s->dp.rcont[3][i] + th1 * s->dp.rcont[4][i])));
}

/* One Dormand-Prince attempt of size h from (y, k1 = f(y)). Writes y1, k7 = f(y1) and,
 * when rc is not NULL, the dense-output coefficients. Returns the weighted error norm
 * (NaN if the attempt failed; *res says why). */
static double dp_try(lag_sim *s, double h, const double *y, const double *k1, double *y1,
                     double *k7, double rc[5][LAG_MAX_STATE], lag_result *res)
{
    const int N = 2 * s->nq;
    const lag_integrator_def *in = &s->def.integrator;
    double k2[LAG_MAX_STATE], k3[LAG_MAX_STATE], k4[LAG_MAX_STATE], k5[LAG_MAX_STATE],
        k6[LAG_MAX_STATE], yt[LAG_MAX_STATE] = {0}, err[LAG_MAX_STATE];
    lag_result r;
    *res = LAG_OK;
    for (int i = 0; i < N; i++) yt[i] = y[i] + h * a21 * k1[i];
    if ((r = lag_rhs(s, yt, k2)) != LAG_OK) { r = lag_stage_fault(s, yt, r); goto fail; }
    for (int i = 0; i < N; i++) yt[i] = y[i] + h * (a31 * k1[i] + a32 * k2[i]);
    if ((r = lag_rhs(s, yt, k3)) != LAG_OK) { r = lag_stage_fault(s, yt, r); goto fail; }
    for (int i = 0; i < N; i++) yt[i] = y[i] + h * (a41 * k1[i] + a42 * k2[i] + a43 * k3[i]);
    if ((r = lag_rhs(s, yt, k4)) != LAG_OK) { r = lag_stage_fault(s, yt, r); goto fail; }
    for (int i = 0; i < N; i++)
        yt[i] = y[i] + h * (a51 * k1[i] + a52 * k2[i] + a53 * k3[i] + a54 * k4[i]);
    if ((r = lag_rhs(s, yt, k5)) != LAG_OK) { r = lag_stage_fault(s, yt, r); goto fail; }
    for (int i = 0; i < N; i++)
        yt[i] = y[i] + h * (a61 * k1[i] + a62 * k2[i] + a63 * k3[i] + a64 * k4[i] + a65 * k5[i]);
    if ((r = lag_rhs(s, yt, k6)) != LAG_OK) { r = lag_stage_fault(s, yt, r); goto fail; }
    for (int i = 0; i < N; i++)
        y1[i] = y[i] + h * (a71 * k1[i] + a73 * k3[i] + a74 * k4[i] + a75 * k5[i] + a76 * k6[i]);
    if ((r = lag_rhs(s, y1, k7)) != LAG_OK) { r = lag_stage_fault(s, y1, r); goto fail; }
    for (int i = 0; i < N; i++)
        err[i] = h * (e1 * k1[i] + e3 * k3[i] + e4 * k4[i] + e5 * k5[i] + e6 * k6[i] + e7 * k7[i]);
    if (rc)
        for (int i = 0; i < N; i++) {
            double ydiff = y1[i] - y[i], bspl = h * k1[i] - ydiff;
            rc[0][i] = y[i];
            rc[1][i] = ydiff;
            rc[2][i] = bspl;
            rc[3][i] = ydiff - h * k7[i] - bspl;
            rc[4][i] = h * (d1 * k1[i] + d3 * k3[i] + d4 * k4[i] + d5 * k5[i] + d6 * k6[i] +
                            d7 * k7[i]);
        }
    return err_norm(N, err, y, y1, in->rtol, in->atol);
fail:
    *res = r;
    return NAN;
}

/* Next step factor: 0.9 err^-1/5 bounded to [0.2, 10], no growth right after a reject. */
static double step_factor(double en, bool last_rejected)
{
    double fac = en > 0.0 ? 0.9 * pow(en, -0.2) : 10.0;
    return fmin(last_rejected ? 1.0 : 10.0, fmax(0.2, fac));
}

/* The adaptive loop shared by both drivers: from (*t, y, k1 = f(y)) up to t_end, in at
 * most max_steps attempts (accepted or rejected; then LAG_ERR_MAX_STEPS). A step that
 * would reach t_stop (>= t_end; INFINITY: none) is shortened to land on it exactly; other
 * steps may step past t_end. Which steps are taken therefore depends on t_stop, not on
 * t_end: a span to t_stop run in pieces takes the steps of one run. With `dense`, each
 * accepted step leaves its dense-output coefficients (and start time) in s->dp for
 * interpolation. An accepted state that is non-finite or beyond explode_limit is an error;
 * y and *t then hold the last good step. */
static lag_result dp_run(lag_sim *s, double *t, double t_end, double t_stop, double *y,
                         double *k1, bool dense, int64_t max_steps)
{
    const int N = 2 * s->nq;
    const lag_integrator_def *in = &s->def.integrator;
    double y1[LAG_MAX_STATE], k7[LAG_MAX_STATE], rc[5][LAG_MAX_STATE];
    bool last_rejected = false;
    lag_result r;
    for (int64_t attempts = 0; *t < t_end; attempts++) {
        if (attempts >= max_steps) return LAG_ERR_MAX_STEPS;
        double h = s->dp.h;
        if (s->dp.h_max > 0.0 && h > s->dp.h_max) h = s->dp.h_max; /* a shadow's cap */
        bool lands = false;
        if (*t + h >= t_stop) {
            h = t_stop - *t;
            lands = true;
        }
        if (h < in->dt_min && !lands) return LAG_ERR_STEPSIZE;
        double en = dp_try(s, h, y, k1, y1, k7, dense ? rc : NULL, &r);
        if (isnan(en)) {
            /* a failed evaluation (e.g. singular M far from y): shrink and retry */
            if (r == LAG_OK) r = LAG_ERR_NONFINITE;
            s->dp.h = 0.25 * h;
            s->stats.steps_rejected++;
            if (s->dp.h < in->dt_min) return r;
            last_rejected = true;
            continue;
        }
        double fac = step_factor(en, last_rejected);
        if (en > 1.0) {
            s->stats.steps_rejected++;
            s->dp.h = h * fac;
            last_rejected = true;
            continue;
        }
        if ((r = lag_state_check(N, y1, s->def.explode_limit)) != LAG_OK) return r;
        if (dense) {
            memcpy(s->dp.rcont, rc, sizeof rc);
            s->dp.t_prev = *t;
        }
        *t = lands ? t_stop : *t + h;
        memcpy(y, y1, sizeof(double) * N);
        memcpy(k1, k7, sizeof(double) * N); /* FSAL */
        s->stats.steps_accepted++;
        /* A step shortened to land keeps the natural proposal for the next one. */
        if (!lands || h * fac > s->dp.h) s->dp.h = h * fac;
        last_rejected = false;
    }
    return LAG_OK;
}

lag_result lag_dopri5_span(lag_sim *s, double H, const double *y0, double *yout)
{
    const int N = 2 * s->nq;
    double y[LAG_MAX_STATE], k1[LAG_MAX_STATE], t = 0.0;
    lag_result r;
    for (int i = 0; i < N; i++) y[i] = y0[i];
    if (H > 0.0) {
        if ((r = lag_sim_rhs(s, y, k1)) != LAG_OK) return r;
        if (!(s->dp.h > 0.0)) s->dp.h = initial_step(s, N, y, k1);
        if ((r = dp_run(s, &t, H, H, y, k1, false, s->def.integrator.max_steps)) != LAG_OK)
            return r;
    }
    for (int i = 0; i < N; i++) yout[i] = y[i];
    return LAG_OK;
}

lag_result lag_dopri5_advance(lag_sim *s, int64_t nticks, int64_t stop)
{
    const int n = s->nq, N = 2 * n;
    const double t_start = lag_sim_time(s);
    const int64_t tick_end = s->tick + nticks;
    const double t_end = (double)tick_end * s->def.integrator.dt;
    const double t_stop = stop == INT64_MAX ? INFINITY : (double)stop * s->def.integrator.dt;
    lag_result r;

    /* (Re)start from the public state when the internal one is not continuous with it. */
    if (!s->dp.valid || s->dp.t < t_start) {
        s->dp.t = t_start;
        memcpy(s->dp.y, s->q, sizeof(double) * n);
        memcpy(s->dp.y + n, s->qd, sizeof(double) * n);
        if ((r = lag_sim_rhs(s, s->dp.y, s->dp.k1)) != LAG_OK) return r;
        if (!(s->dp.h > 0.0)) s->dp.h = initial_step(s, N, s->dp.y, s->dp.k1);
        s->dp.t_prev = s->dp.t;
        s->dp.valid = true;
    }
    /* max_steps per tick over the n ticks (saturated) */
    const int64_t budget = nticks > INT64_MAX / s->def.integrator.max_steps
                               ? INT64_MAX : nticks * s->def.integrator.max_steps;
    if ((r = dp_run(s, &s->dp.t, t_end, t_stop, s->dp.y, s->dp.k1, true, budget)) != LAG_OK) {
        s->dp.valid = false;
        return r;
    }

    /* Public state at t_end: exact if landed, else from the dense output. */
    double ye[LAG_MAX_STATE];
    if (s->dp.t == t_end) {
        memcpy(ye, s->dp.y, sizeof(double) * N);
    } else {
        dense(s, N, t_end, ye);
        if ((r = lag_state_check(N, ye, s->def.explode_limit)) != LAG_OK) {
            s->dp.valid = false;
            return r;
        }
    }
    memcpy(s->q, ye, sizeof(double) * n);
    memcpy(s->qd, ye + n, sizeof(double) * n);
    s->tick = tick_end;
    return LAG_OK;
}
