/*
 * The event-location engine: hybrid effects (stops, the stick's floor, friction's
 * stick/slip, lift-off) as watchers on a tick, located in time, with their maps.
 *
 * Each tick with watchers is integrated, the watchers' event functions (positive =
 * nothing happening) are sampled along the cubic Hermite interpolant of the step (the
 * order of rk4; a continuous extension needs no more), the earliest zero is found by the
 * Illinois method (modified regula falsi), the step is redone up to that instant, the
 * event's map is applied (an impulse or a mode change, by the effect that owns the
 * watcher) and the rest of the tick is integrated from there. At most
 * LAG_MAX_EVENTS_PER_TICK events per tick (then LAG_EV_EVENT_LIMIT and the rest of the
 * tick without location); sim time stays tick * dt.
 *
 * Impulse map at joint i (frictionless impact, J = e_i^T; contact.c):
 *   P = -(1 + e) (J qd-) / (J M^-1 J^T),  qd+ = qd- + M^-1 J^T P
 * so J qd+ = -e J qd- and the kinetic energy never increases for e in [0, 1].
 *
 * Holds: a locked joint (resting at a stop, or held by static friction) has qd_i = qdd_i
 * = 0; the constraint force lambda_i it needs is watched: a stop releases when lambda_i
 * would have to pull, static friction lets go when |lambda_i| > mu_s.
 *
 * What the effect table's rows give the engine: watchers (lag_effect_row.watch) and the
 * maps of their events (on_event), built on contact.c (impulses, holds, the stop's map).
 * The pieces are separate functions so that they can be tested on their own
 * (tests/core/test_events.c): lag_hermite, lag_watch_add, lag_event_locate, and
 * contact.c's lag_impulse_map.
 */
#include <math.h>
#include <string.h>
#include "core_internal.h"

#define NSEG 4 /* samples of the interpolant per step for sign changes */

/* ------------------------------------------------------------------ watchers */

/* ------------------------------------------------------------------ interpolation, location */

void lag_hermite(int N, double h, const double *y0, const double *f0, const double *y1,
                 const double *f1, double th, double *y)
{
    double t2 = th * th, t3 = t2 * th;
    double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + th, h01 = -2 * t3 + 3 * t2,
           h11 = t3 - t2;
    for (int i = 0; i < N; i++) y[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
}

/* lag_event_locate's body, inlined into the engine's tick with its evaluator known (so
 * that the evaluations are direct calls there), and called as it is by the unit tests. */
static inline __attribute__((always_inline)) lag_result
locate(int N, double H, const double *y0, const double *f0, const double *y1,
       const double *f1, const lag_watch_set *ws, const double *v0, lag_watch_eval_fn eval,
       void *ctx, int *which, double *theta)
{
    const int nw = ws->n;
    const lag_watcher *w = ws->w;
    lag_result r;
    LAG_ASSERT(nw >= 0 && nw <= LAG_MAX_WATCHERS && N >= 2 && N <= LAG_MAX_STATE);
    *which = -1;
    *theta = 1.0;

    /* first segment of the interpolant in which some watcher fires */
    double vprev[LAG_MAX_WATCHERS], vcur[LAG_MAX_WATCHERS];
    memcpy(vprev, v0, sizeof(double) * (size_t)nw);
    int seg = -1;
    for (int k = 1; k <= NSEG && seg < 0; k++) {
        double yt[LAG_MAX_STATE];
        if (k == NSEG) memcpy(yt, y1, sizeof(double) * (size_t)N);
        else lag_hermite(N, H, y0, f0, y1, f1, (double)k / NSEG, yt);
        if ((r = eval(ctx, yt, vcur)) != LAG_OK) return r;
        for (int j = 0; j < nw; j++)
            if (lag_watch_fired(&w[j], vprev[j], vcur[j])) seg = k;
        if (seg < 0) memcpy(vprev, vcur, sizeof(double) * (size_t)nw);
    }
    if (seg < 0) return LAG_OK;

    /* earliest zero among the watchers that fired in the segment (Illinois); each search
     * ends at the right end b of its bracket, where the event has happened */
    double th_best = 2.0;
    for (int j = 0; j < nw; j++) {
        if (!lag_watch_fired(&w[j], vprev[j], vcur[j])) continue;
        double a = (double)(seg - 1) / NSEG, b = (double)seg / NSEG;
        double fa = vprev[j], fb = vcur[j];
        int last = 0;
        for (int it = 0; it < 80 && (b - a) * H > 1e-15; it++) {
            double c = (fa != fb) ? (a * fb - b * fa) / (fb - fa) : 0.5 * (a + b);
            if (!(c > a && c < b)) c = 0.5 * (a + b);
            double yt[LAG_MAX_STATE], vals[LAG_MAX_WATCHERS];
            lag_hermite(N, H, y0, f0, y1, f1, c, yt);
            if ((r = eval(ctx, yt, vals)) != LAG_OK) return r;
            double fc = vals[j];
            if (lag_watch_fired(&w[j], fa, fc)) {
                b = c; fb = fc;
                if (last == -1) fa *= 0.5;
                last = -1;
            } else {
                a = c; fa = fc;
                if (last == 1) fb *= 0.5;
                last = 1;
            }
        }
        if (b < th_best) { th_best = b; *which = j; }
    }
    *theta = th_best;
    return LAG_OK;
}

lag_result lag_event_locate(int N, double H, const double *y0, const double *f0,
                            const double *y1, const double *f1, const lag_watch_set *ws,
                            const double *v0, lag_watch_eval_fn eval, void *ctx, int *which,
                            double *theta)
{
    return locate(N, H, y0, f0, y1, f1, ws, v0, eval, ctx, which, theta);
}


/* A hold lets go (its watcher fired): a stop releases the joint (which friction may hold
 * at once); static friction gives way to sliding against the force. */
static lag_result release_hold(lag_sim *s, int i, double *y, double t)
{
    const int n = s->nq;
    double lambda[LAG_MAX_DOF];
    lag_result r;
    if ((r = lag_lock_forces(s, y, lambda)) != LAG_OK) return r;
    bool stop = s->mode.lock_side[i] != 0;
    s->mode.locked &= ~(1u << i);
    s->mode.lock_side[i] = 0;
    y[n + i] = 0.0;
    if (stop && lag_effects_release(s, i, y, t, lambda)) {
        /* an effect's own release (the floor's lift-off) */
    } else if (stop) {
        lag_sim_record_event(s, LAG_EV_RELEASE, i, t, lambda[i]);
        if (lag_has_friction(s, i)) {
            lag_event_kind k = lag_friction_settle(s, y, i);
            if (k == LAG_EV_STICK) lag_sim_record_event(s, k, i, t, 0.0);
        }
    } else {
        s->mode.slip_dir[i] = (int8_t)(-lag_sgn(lambda[i]));
        lag_sim_record_event(s, LAG_EV_SLIP, i, t, s->mode.slip_dir[i]);
    }
    return LAG_OK;
}

/* ------------------------------------------------------------------ the watchers of a tick */

/* Per joint: a held joint has its hold's watcher only; a free one every row's watchers
 * for it, in table order; then the rows' watchers of no joint. Fails (LAG_ERR_ARG) if the
 * rows ask for more than LAG_MAX_WATCHERS: their declared maxima are checked against it
 * (core_events_capacity), so this is the safe path of a check that never fails. */
static lag_result build_watchers(const lag_sim *s, lag_watch_set *ws)
{
    const int n = s->nq;
    ws->n = 0;
    for (int i = 0; i < n; i++) {
        if (s->mode.locked & (1u << i)) {
            lag_watcher h = {.kind = LAG_WATCH_HOLD, .joint = (int8_t)i, .strict = false};
            if (!lag_watch_add(ws, h)) return LAG_ERR_ARG;
            continue;
        }
        if (!lag_effects_watch(s, i, ws)) return LAG_ERR_ARG;
    }
    if (!lag_effects_watch(s, -1, ws)) return LAG_ERR_ARG;
    return LAG_OK;
}

static bool needs_dynamics(const lag_watch_set *ws)
{
    for (int k = 0; k < ws->n; k++)
        if (ws->w[k].kind == LAG_WATCH_HOLD || ws->w[k].kind == LAG_WATCH_CUSTOM) return true;
    return false;
}

typedef struct watch_ctx {
    lag_sim *s;
    const lag_watch_set *ws;
    bool dyn;
    double qdd[LAG_MAX_DOF];
} watch_ctx;

/* Event function values at y (positive = nothing happening); the dynamics (qdd and the
 * holds' forces) only when a watcher needs them. OUT: val, ctx->qdd (if dyn) */
static lag_result eval_watchers(void *vctx, const double *y, double *val)
{
    watch_ctx *c = (watch_ctx *)vctx;
    lag_sim *s = c->s;
    const int n = s->nq;
    double lambda[LAG_MAX_DOF] = {0};
    if (c->dyn) {
        double Q[LAG_MAX_DOF];
        lag_effects_force(s, y, y + n, Q);
        lag_result r = lag_forward_locked(s, y, y + n, Q, c->qdd, lambda);
        if (r != LAG_OK) return r;
    }
    for (int k = 0; k < c->ws->n; k++) {
        const lag_watcher *w = &c->ws->w[k];
        int i = w->joint;
        switch (w->kind) {
        case LAG_WATCH_POSITION:
            val[k] = w->side < 0 ? y[i] - w->bound : w->bound - y[i];
            break;
        case LAG_WATCH_VELOCITY_ZERO:
            val[k] = s->mode.slip_dir[i] * y[n + i];
            break;
        case LAG_WATCH_HOLD:
            val[k] = s->mode.lock_side[i] == 0
                         ? s->def.effects.friction_static[i] - fabs(lambda[i])
                         : -s->mode.lock_side[i] * lambda[i];
            break;
        case LAG_WATCH_CUSTOM:
            LAG_ASSERT(c->dyn && w->owner < LAG_EFF_COUNT && lag_effect_rows[w->owner]->value);
            val[k] = lag_effect_rows[w->owner]->value(s, w, y, c->qdd);
            break;
        case LAG_WATCH_GAP:
            LAG_ASSERT(w->owner < LAG_EFF_COUNT && lag_effect_rows[w->owner]->gap);
            val[k] = lag_effect_rows[w->owner]->gap(s, w, y, NULL, NULL, NULL);
            break;
        }
    }
    return LAG_OK;
}

/* The event map of watcher w at state y (in place), by its owner. */
static lag_result handle(lag_sim *s, const lag_watcher *w, double *y, double t)
{
    LAG_ASSERT(w->joint >= 0 && w->joint < s->nq);
    if (w->kind == LAG_WATCH_HOLD) return release_hold(s, w->joint, y, t);
    LAG_ASSERT(w->owner < LAG_EFF_COUNT && lag_effect_rows[w->owner]->on_event);
    return lag_effect_rows[w->owner]->on_event(s, w, y, t);
}

/* At the start of an interval: an event already due (at or past a stop and moving into
 * it, a hold that no longer holds, a custom watcher already negative). Returns its index,
 * -1 if none, or -2 with *err set if the dynamics needed to judge a joint at rest on a
 * stop failed. qdd is the acceleration at y if `have_qdd`; otherwise it is computed here,
 * and only for that case (a joint exactly at rest at or past a stop), so that ticks away
 * from the stops do not pay for it. */
static int due_now(lag_sim *s, const lag_watch_set *ws, const double *y, const double *val,
                   double *qdd, bool have_qdd, lag_result *err)
{
    const int n = s->nq;
    for (int k = 0; k < ws->n; k++) {
        const lag_watcher *w = &ws->w[k];
        int i = w->joint;
        if ((w->kind == LAG_WATCH_POSITION || w->kind == LAG_WATCH_GAP) && val[k] <= 0) {
            /* moving into the stop (qd toward it, or at rest and accelerating toward it) */
            const lag_effect_row *row = lag_effect_rows[w->owner];
            double v, a = 0.0; /* v > 0: moving into the stop */
            if (w->kind == LAG_WATCH_GAP) row->gap(s, w, y, NULL, &v, NULL), v = -v;
            else v = y[n + i] * w->side;
            if (v > 0) return k;
            /* at rest on the floor it just left: its acceleration into the floor is a
             * rounding of the zero normal force (the hold let go as it would pull) */
            if (v == 0 && w->kind == LAG_WATCH_POSITION && (s->mode.released & (1u << i)))
                continue;
            if (v == 0) {
                if (!have_qdd) {
                    double Q[LAG_MAX_DOF];
                    lag_effects_force(s, y, y + n, Q);
                    if ((*err = lag_forward_locked(s, y, y + n, Q, qdd, NULL)) != LAG_OK)
                        return -2;
                    have_qdd = true;
                }
                if (w->kind == LAG_WATCH_GAP) row->gap(s, w, y, qdd, NULL, &a), a = -a;
                else a = qdd[i] * w->side;
                if (a > 0) return k;
            }
        } else if ((w->kind == LAG_WATCH_HOLD || w->kind == LAG_WATCH_CUSTOM) && val[k] < 0) {
            return k;
        }
    }
    return -1;
}

lag_result lag_events_tick(lag_sim *s, double *y)
{
    const int n = s->nq, N = 2 * n;
    const double dt = s->def.integrator.dt;
    const double t_tick = lag_sim_time(s);
    double tloc = 0.0;
    int events = 0;
    lag_result r;

    while (tloc < dt) {
        lag_watch_set ws;
        if ((r = build_watchers(s, &ws)) != LAG_OK) return r;
        const double H = dt - tloc;
        double y1[LAG_MAX_STATE];
        if (ws.n == 0 || events >= LAG_MAX_EVENTS_PER_TICK) {
            if (events >= LAG_MAX_EVENTS_PER_TICK)
                lag_sim_record_event(s, LAG_EV_EVENT_LIMIT, -1, t_tick + tloc, events);
            if ((r = lag_step(s, H, y, y1)) != LAG_OK) return r;
            memcpy(y, y1, sizeof(double) * (size_t)N);
            break;
        }
        watch_ctx ctx = {.s = s, .ws = &ws, .dyn = needs_dynamics(&ws), .qdd = {0}};
        double v0[LAG_MAX_WATCHERS];
        if ((r = eval_watchers(&ctx, y, v0)) != LAG_OK) return r;
        double qdd0[LAG_MAX_DOF];
        memcpy(qdd0, ctx.qdd, sizeof qdd0);
        int k0 = due_now(s, &ws, y, v0, qdd0, ctx.dyn, &r);
        if (k0 == -2) return r;
        if (k0 >= 0) {
            if ((r = handle(s, &ws.w[k0], y, t_tick + tloc)) != LAG_OK) return r;
            events++;
            continue;
        }

        s->mode.released = 0;
        if ((r = lag_step(s, H, y, y1)) != LAG_OK) return r;
        /* a step the watchers are located on and an event mapped from: checked here (the
         * tick's end state is checked by lag_sim_advance_within, whatever ended the tick) */
        if ((r = lag_state_check(N, y1, s->def.explode_limit)) != LAG_OK) return r;
        double f0[LAG_MAX_STATE], f1[LAG_MAX_STATE];
        if ((r = lag_sim_rhs(s, y, f0)) != LAG_OK) return r;
        if ((r = lag_sim_rhs(s, y1, f1)) != LAG_OK) return r;

        int k_best;
        double th_best;
        if ((r = locate(N, H, y, f0, y1, f1, &ws, v0, eval_watchers, &ctx, &k_best, &th_best)) !=
            LAG_OK)
            return r;
        if (k_best < 0) {
            memcpy(y, y1, sizeof(double) * (size_t)N);
            break;
        }

        /* redo the step up to the event, apply its map, go on with the rest of the tick */
        double hs = th_best * H;
        if (th_best >= 1.0) hs = H;
        double ys[LAG_MAX_STATE];
        if (hs > 0) {
            if ((r = lag_step(s, hs, y, ys)) != LAG_OK) return r;
            if ((r = lag_state_check(N, ys, s->def.explode_limit)) != LAG_OK) return r;
        } else {
            memcpy(ys, y, sizeof(double) * (size_t)N);
        }
        bool landed = false; /* the owner's landing hook moved the event's instant */
        const lag_watcher *wb = &ws.w[k_best];
        if (hs > 0 && wb->kind != LAG_WATCH_HOLD && lag_effect_rows[wb->owner]->land) {
            double hs0 = hs;
            if ((r = lag_effect_rows[wb->owner]->land(s, wb, y, H, &hs, ys)) != LAG_OK) return r;
            landed = hs != hs0;
        }
        tloc = (th_best >= 1.0 && !landed) ? dt : tloc + hs;
        if ((r = handle(s, &ws.w[k_best], ys, t_tick + tloc)) != LAG_OK) return r;
        memcpy(y, ys, sizeof(double) * (size_t)N);
        events++;
    }
    return LAG_OK;
}
