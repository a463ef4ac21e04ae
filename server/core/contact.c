/*
 * Contact: impulses at a joint, holds (a joint held at rest by a stop or by static
 * friction) and the constraint forces that hold them (lag_lock_forces, under the current
 * locks), friction's stick/slip settling, the stop's map that the limits and the floor
 * share, and the check of the rest velocity they share. What the effects' maps and the
 * event engine build on; it calls the right-hand side (rhs.c), the effects' generalized
 * forces (effects.c), the event queue (event_queue.c) and the diagnostics (model.c).
 */
#include <math.h>
#include <string.h>
#include "core_internal.h"

/* x = M^-1 e_i on the free joints (locked ones get no velocity). OUT: x */
lag_result lag_minv_column(const lag_sim *s, const double *q, int i, double *x)
{
    double p[LAG_MAX_DOF] = {0};
    p[i] = 1.0;
    return lag_qd_from_p(s, q, p, x);
}

lag_result lag_impulse_map(lag_sim *s, double *y, int i, double e)
{
    const int n = s->nq;
    double x[LAG_MAX_DOF];
    lag_result r = lag_minv_column(s, y, i, x);
    if (r != LAG_OK) return r;
    if (!(x[i] > 0)) return LAG_ERR_SINGULAR;
    double P = -(1.0 + e) * y[n + i] / x[i];
    for (int k = 0; k < n; k++) y[n + k] += x[k] * P;
    y[n + i] = -e * (y[n + i] - x[i] * P) ; /* exact: avoid rounding leaving a residue */
    return LAG_OK;
}

lag_result lag_lock_forces(lag_sim *s, const double *y, double *lambda)
{
    const int n = s->nq;
    double Q[LAG_MAX_DOF], qdd[LAG_MAX_DOF];
    lag_effects_force(s, y, y + n, Q);
    return lag_forward_locked(s, y, y + n, Q, qdd, lambda);
}

lag_event_kind lag_friction_settle(lag_sim *s, double *y, int i)
{
    const int n = s->nq;
    y[n + i] = 0.0;
    s->mode.slip_dir[i] = 0;
    s->mode.locked |= 1u << i;
    s->mode.lock_side[i] = 0;
    double lambda[LAG_MAX_DOF];
    if (lag_lock_forces(s, y, lambda) == LAG_OK &&
        fabs(lambda[i]) <= s->def.effects.friction_static[i])
        return LAG_EV_STICK;
    s->mode.locked &= ~(1u << i);
    s->mode.slip_dir[i] = (int8_t)(-lag_sgn(lambda[i]));
    return LAG_EV_SLIP;
}

void lag_refresh_slip(lag_sim *s, double *y)
{
    const int n = s->nq;
    for (int i = 0; i < n; i++) {
        if (!lag_has_friction(s, i) || (s->mode.locked & (1u << i))) continue;
        double v = y[n + i];
        if (v != 0.0) s->mode.slip_dir[i] = (int8_t)lag_sgn(v);
        else lag_friction_settle(s, y, i);
    }
}

/* ================================================================== stops: limits (and the floor's) */
/* A stop at position `bound` on one side of a joint: a POSITION watcher; its map is an
 * impact with restitution e, or resting contact (a hold) when the impact is slower than
 * rest_velocity or the bounce would come back within one tick (the Zeno guard). */

lag_result lag_stop_event(lag_sim *s, const lag_watcher *w, double *y, double t,
                             lag_event_kind bounce, lag_event_kind rest_kind)
{
    const int n = s->nq, i = w->joint;
    lag_result r;
    double v = y[n + i];
    /* Zeno guard: rest if slower than rest_velocity, or if the bounce would come back
     * within one tick (e |v| < a dt, a the acceleration into the stop). */
    double Q[LAG_MAX_DOF], qdd[LAG_MAX_DOF];
    lag_effects_force(s, y, y + n, Q);
    if ((r = lag_forward_locked(s, y, y + n, Q, qdd, NULL)) != LAG_OK) return r;
    double a_in = qdd[i] * w->side;
    bool rest = fabs(v) < s->def.effects.rest_velocity ||
                (a_in > 0 && w->e * fabs(v) < a_in * s->def.integrator.dt);
    if (rest) {
        if ((r = lag_impulse_map(s, y, i, 0.0)) != LAG_OK) return r;
        y[n + i] = 0.0;
        s->mode.locked |= 1u << i;
        s->mode.lock_side[i] = (int8_t)w->side;
        s->mode.slip_dir[i] = 0;
        double lambda[LAG_MAX_DOF];
        if (rest_kind == LAG_EV_LANDING &&
            (r = lag_forward_locked(s, y, y + n, Q, qdd, lambda)) == LAG_OK &&
            -w->side * lambda[i] < 0) {
            /* the floor would have to pull: the end touches it and flies on */
            s->mode.locked &= ~(1u << i);
            s->mode.lock_side[i] = 0;
            lag_sim_record_event(s, bounce, i, t, v);
        } else {
            if (r != LAG_OK) return r;
            lag_sim_record_event(s, rest_kind, i, t, v);
        }
    } else {
        if ((r = lag_impulse_map(s, y, i, w->e)) != LAG_OK) return r;
        lag_sim_record_event(s, bounce, i, t, v);
    }
    lag_refresh_slip(s, y);
    return LAG_OK;
}

lag_result lag_rest_velocity_validate(const lag_sim_def *def, lag_diag *d, const char *field)
{
    double v = def->effects.rest_velocity;
    if (!(isfinite(v) && v >= 0)) return lag_diag_fail(d, field, "expected a finite number >= 0, got %g", v);
    return LAG_OK;
}
