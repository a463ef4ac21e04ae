/* The simulation: definition, state, held input, and advancing by ticks of dt.
 * Sim time is tick * dt, always computed from the integer tick count. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "core_internal.h"

lag_sim_def lag_default_sim_def(lag_model_kind kind)
{
    lag_sim_def d;
    memset(&d, 0, sizeof d);
    lag_model_default(&d.model, kind);
    d.integrator = lag_default_integrator_def();
    d.effects = lag_default_effects_def();
    d.explode_limit = 1e6;
    return d;
}

lag_result lag_sim_def_check(const lag_sim_def *def, lag_diag *d)
{
    lag_result r = lag_model_check(&def->model, d);
    if (r != LAG_OK) return r;
    const lag_integrator_def *in = &def->integrator;
    if ((int)in->method < 0 || in->method >= LAG_METHOD_COUNT)
        return lag_diag_fail(d, "integrator.method", "unknown integrator method %d", (int)in->method);
    if (!(isfinite(in->dt) && in->dt > 0))
        return lag_diag_fail(d, "integrator.dt", "expected a finite number > 0 (s), got %g", in->dt);
    if (!(isfinite(in->rtol) && in->rtol > 0))
        return lag_diag_fail(d, "integrator.rtol", "expected a finite number > 0, got %g", in->rtol);
    if (!(isfinite(in->atol) && in->atol > 0))
        return lag_diag_fail(d, "integrator.atol", "expected a finite number > 0, got %g", in->atol);
    if (!(isfinite(in->dt_min) && in->dt_min > 0 && in->dt_min <= in->dt))
        return lag_diag_fail(d, "integrator.dt_min", "expected a number > 0 and <= dt = %g s, got %g",
                             in->dt, in->dt_min);
    if (in->max_iter < 1 || in->max_iter > 1000)
        return lag_diag_fail(d, "integrator.max_iter", "expected an integer in 1..1000, got %d",
                             in->max_iter);
    if (in->max_steps < 1 || in->max_steps > 100000000)
        return lag_diag_fail(d, "integrator.max_steps", "expected an integer in 1..1e8, got %d",
                             in->max_steps);
    if (!(isfinite(in->newton_tol) && in->newton_tol > 0 && in->newton_tol < 1))
        return lag_diag_fail(d, "integrator.newton_tol", "expected a number in (0, 1), got %g",
                             in->newton_tol);
    if (!(isfinite(def->explode_limit) && def->explode_limit > 0))
        return lag_diag_fail(d, "explode_limit", "expected a finite number > 0, got %g",
                             def->explode_limit);
    int n = def->model.nq;
    for (int i = 0; i < n; i++) {
        char field[LAG_FIELD_MAX];
        for (int v = 0; v < 2; v++) {
            double x = v ? def->qd0[i] : def->q0[i];
            snprintf(field, sizeof field, "initial.%s[%d]", v ? "qd" : "q", i);
            if (!isfinite(x)) return lag_diag_fail(d, field, "expected a finite number, got %g", x);
            if (fabs(x) > def->explode_limit)
                return lag_diag_fail(d, field, "%g exceeds explode_limit = %g", x, def->explode_limit);
        }
    }
    if ((r = lag_effects_check(def, d)) != LAG_OK) return r;
    double M[LAG_MAX_DOF * LAG_MAX_DOF], b[LAG_MAX_DOF] = {0}, x[LAG_MAX_DOF];
    lag_model_mass(&def->model, def->q0, M);
    if (lag_spd_solve(n, M, b, x) != LAG_OK)
        return lag_diag_fail(d, "initial.q", "the mass matrix is not positive definite there");
    return LAG_OK;
}

lag_result lag_sim_def_validate(const lag_sim_def *def, char *err, size_t errlen)
{
    lag_diag d;
    lag_result r = lag_sim_def_check(def, &d);
    if (r != LAG_OK) lag_diag_format(&d, err, errlen);
    return r;
}

lag_result lag_sim_init(lag_sim *s, const lag_sim_def *def, char *err, size_t errlen)
{
    lag_result r = lag_sim_def_validate(def, err, errlen);
    if (r != LAG_OK) return r;
    memset(s, 0, sizeof *s);
    s->def = *def;
    lag_effects_sim_model(def, &s->model); /* def's model, or one an effect integrates */
    s->dyn = lag_model_vt(&s->model);
    s->nq = s->model.nq;
    lag_effects_prepare(s);
    lag_sim_reset(s, NULL, NULL);
    return LAG_OK;
}

const lag_model_info *lag_sim_info(const lag_sim *s)
{
    return lag_model_info_get(s->model.kind);
}

void lag_sim_reset(lag_sim *s, const double *q, const double *qd)
{
    int n = s->nq;
    for (int i = 0; i < n; i++) {
        s->q[i] = q ? q[i] : s->def.q0[i];
        s->qd[i] = qd ? qd[i] : s->def.qd0[i];
        s->tau[i] = 0.0;
    }
    s->tick = 0;
    s->dp.valid = false;
    s->dp.h = 0.0;
    memset(&s->mode, 0, sizeof s->mode);
    s->dyn = lag_model_vt(&s->model);
    if (s->def.effects.enabled) lag_effects_reset(s); /* the effects' run state (the floor's end) */
    memset(&s->fault, 0, sizeof s->fault);
    for (int i = 0; i < n; i++) s->tau_applied[i] = 0.0;
    s->n_events = 0;
    if (s->def.effects.enabled) lag_effects_init_modes(s);
}

/* Field by field: the struct has padding, whose bytes a copy need not keep. */
static bool same_integrator(const lag_integrator_def *a, const lag_integrator_def *b)
{
    return a->method == b->method && a->dt == b->dt && a->rtol == b->rtol &&
           a->atol == b->atol && a->dt_min == b->dt_min && a->max_iter == b->max_iter &&
           a->max_steps == b->max_steps && a->newton_tol == b->newton_tol;
}

lag_result lag_sim_redefine(lag_sim *s, const lag_sim_def *def, char *err, size_t errlen)
{
    _Static_assert(sizeof(lag_integrator_def) == 8 * 7, "same_integrator compares every field");
    if (def->model.kind != s->def.model.kind || def->model.nq != s->def.model.nq ||
        !same_integrator(&def->integrator, &s->def.integrator) ||
        def->explode_limit != s->def.explode_limit) {
        if (err && errlen)
            snprintf(err, errlen, "only the model's parameters and the effects change while "
                                  "running (not the model, the integrator or explode_limit)");
        return LAG_ERR_ARG;
    }
    lag_model integrated;
    int row = lag_effects_sim_model(def, &integrated);
    if (integrated.kind != s->model.kind) {
        if (row < 0) row = lag_effects_sim_model(&s->def, &(lag_model){0});
        const lag_effect_row *e = row >= 0 ? lag_effect_rows[row] : NULL;
        if (err && errlen)
            snprintf(err, errlen, "effects.%s.%s does not change while running (it decides "
                     "the model integrated: %s now)", e ? e->name : "?",
                     e && e->sim_model_key ? e->sim_model_key : "?",
                     lag_model_info_get(s->model.kind)->name);
        return LAG_ERR_ARG;
    }
    /* checked as a definition that starts where the run is now */
    lag_sim_def at = *def;
    for (int i = 0; i < s->nq; i++) {
        at.q0[i] = s->q[i];
        at.qd0[i] = s->qd[i];
    }
    lag_effects_as_initial(s, &at); /* the floor's: a stick standing on it */
    lag_diag d;
    if (lag_sim_def_check(&at, &d) != LAG_OK) {
        /* the "initial" state checked is where the run is now: said so */
        const char *m = d.message;
        if (!strncmp(m, "initial ", 8)) m += 8;
        if (err && errlen && !strncmp(d.field, "initial.", 8))
            snprintf(err, errlen, "where the run is now, %s", m);
        else if (err && errlen)
            lag_diag_format(&d, err, errlen);
        return LAG_ERR_ARG;
    }
    const uint32_t was = s->def.effects.enabled;
    s->def.model = def->model;
    s->model = integrated; /* the run's state (the floor's end, lag_sim.dyn) is kept */
    s->def.effects = def->effects;
    lag_effects_prepare(s);
    s->dp.valid = false; /* dopri5's internal state was integrated with the old definition */
    const uint32_t now = s->def.effects.enabled;
    if (lag_effects_with_events(was | now)) /* the effects with modes: derived again */
        lag_effects_init_modes(s);
    for (int i = 0; i < s->nq; i++) {
        if ((now & LAG_EFF_ACTUATOR) && !(was & LAG_EFF_ACTUATOR))
            s->mode.act_state[i] = s->tau_applied[i];
        if (!(now & LAG_EFF_ACTUATOR)) {
            s->tau_applied[i] = s->tau[i];
            s->mode.saturated[i] = false;
        }
    }
    return LAG_OK;
}

void lag_sim_set_input(lag_sim *s, const double *tau)
{
    const lag_model_info *info = lag_sim_info(s);
    LAG_ASSERT(info != NULL);
    bool changed = false;
    for (int i = 0; i < s->nq; i++) {
        double v = info->actuated[i] ? tau[i] : 0.0;
        if (memcmp(&v, &s->tau[i], sizeof v) != 0) changed = true;
        s->tau[i] = v;
    }
    /* Without actuator dynamics the applied effort is the command itself. */
    if (!(s->def.effects.enabled & LAG_EFF_ACTUATOR))
        for (int i = 0; i < s->nq; i++) s->tau_applied[i] = s->tau[i];
    /* dopri5 may have run ahead of the public state with the old input: restart it. */
    if (changed) s->dp.valid = false;
}

double lag_sim_energy(const lag_sim *s)
{
    double E = s->dyn->kinetic(s->model.p, s->q, s->qd) + s->dyn->potential(s->model.p, s->q);
    return s->fx.n_potential ? E + lag_effects_potential(s, s->q) : E;
}

/* One tick without events: a step of dt (its end state checked by the caller, as every
 * tick's). OUT: y (in place) */
static lag_result plain_tick(lag_sim *s, double *y)
{
    const int N = 2 * s->nq;
    double y1[LAG_MAX_STATE];
    lag_result r = lag_step(s, s->def.integrator.dt, y, y1);
    if (r != LAG_OK) return r;
    for (int i = 0; i < N; i++) y[i] = y1[i];
    return LAG_OK;
}

/* A tick starting at the public state (q, qd) was refused with r. When what the scene
 * applies from outside is what made the step fail, the fault is LAG_ERR_FORCE, whatever
 * the integrator then ran into (a state that overflowed inside the step shows up as a
 * "singular" mass matrix of cos(inf), a diverging Newton iteration or a vanishing dopri5
 * step, none of which says what happened). From outside means: the effort applied
 * (tau_applied) and the disturbance forces, whose acceleration M^-1 Q alone takes a
 * coordinate past explode_limit within one tick (or is not finite), or this tick's
 * impulse, which left a velocity past explode_limit (qd_before: the velocities before the
 * tick's impulses). A state that grows by itself (an unstable method on a stiff scene,
 * damping at an exploding velocity) keeps its own code. Records s->fault. Only on the
 * failure path: a good tick pays nothing for it. */
static lag_result classify_fault(lag_sim *s, lag_result r, const double *qd_before)
{
    const int n = s->nq;
    const double dt = s->def.integrator.dt, lim = s->def.explode_limit;
    lag_fault f = {r, s->tick, -1, 0.0, 0.0, -1, 0.0};
    if (r != LAG_ERR_LIFTOFF && r != LAG_ERR_ARG) {
        double Q[LAG_MAX_DOF] = {0}, a[LAG_MAX_DOF] = {0};
        const bool dist = s->def.effects.enabled & LAG_EFF_DISTURBANCE;
        bool finite = true;
        for (int i = 0; i < n; i++) {
            Q[i] = s->tau_applied[i] + (dist ? s->mode.dist_force[i] : 0.0);
            finite = finite && isfinite(Q[i]);
        }
        if (finite && lag_qd_from_p(s, s->q, Q, a) != LAG_OK)
            for (int i = 0; i < n; i++) a[i] = 0.0;
        double worst = 1.0; /* a cause must go past explode_limit */
        for (int i = 0; i < n; i++) {
            double ai = finite ? fabs(a[i]) : INFINITY;
            double v = fabs(s->qd[i]) > lim && fabs(qd_before[i]) <= lim ? fabs(s->qd[i]) : 0.0;
            double reach = fmax(fmax(ai * dt, v), 0.5 * ai * dt * dt) / lim;
            if (!isfinite(reach)) reach = INFINITY;
            if (reach > worst) {
                worst = reach;
                f.code = LAG_ERR_FORCE;
                f.joint = i;
                f.accel = finite ? a[i] : NAN;
                f.velocity = s->qd[i];
            }
        }
        /* The applied force that contributes most to that acceleration: Q_j contributes
         * (M^-1 e_j)_i Q_j to joint i's (a non-finite one is the cause outright). */
        double most = 0.0;
        for (int j = 0; j < n && f.code == LAG_ERR_FORCE; j++) {
            double e[LAG_MAX_DOF] = {0}, x[LAG_MAX_DOF];
            e[j] = 1.0;
            if (Q[j] == 0.0) continue;
            double c = !isfinite(Q[j]) ? INFINITY
                     : lag_qd_from_p(s, s->q, e, x) == LAG_OK ? fabs(x[f.joint] * Q[j]) : 0.0;
            if (c > most) { most = c; f.cause = j; f.force = Q[j]; }
        }
    }
    s->fault = f;
    s->stats.faults++;
    return f.code;
}

void lag_sim_fault_describe(const lag_sim *s, char *buf, size_t len)
{
    if (!buf || len == 0) return;
    buf[0] = '\0';
    const lag_fault *f = &s->fault;
    if (f->code == LAG_OK) return;
    const double dt = s->def.integrator.dt, t = (double)f->tick * dt, lim = s->def.explode_limit;
    if (f->code != LAG_ERR_FORCE || f->joint < 0) {
        snprintf(buf, len, "%s, at t = %.9g s (tick %lld)", lag_result_string(f->code), t,
                 (long long)f->tick);
        return;
    }
    const lag_model_info *info = lag_sim_info(s);
    const char *j = info->joint_names[f->joint];
    const bool ang = info->angular[f->joint];
    const char *vu = ang ? "rad/s" : "m/s", *au = ang ? "rad/s^2" : "m/s^2";
    if (!(fabs(f->velocity) <= lim)) {
        snprintf(buf, len, "applied impulse too large: %s has a velocity of %g %s, past "
                 "explode_limit = %g, at t = %.9g s", j, f->velocity, vu, lim, t);
    } else if (f->cause >= 0) {
        const char *c = info->joint_names[f->cause];
        const char *fu = info->angular[f->cause] ? "N m" : "N";
        if (f->cause == f->joint)
            snprintf(buf, len, "applied force too large: %s %g %s, an acceleration of %g %s "
                     "that takes it past explode_limit = %g within one tick (dt = %g s), at "
                     "t = %.9g s", c, f->force, fu, f->accel, au, lim, dt, t);
        else
            snprintf(buf, len, "applied force too large: %s %g %s gives %s an acceleration "
                     "of %g %s that takes it past explode_limit = %g within one tick (dt = "
                     "%g s), at t = %.9g s", c, f->force, fu, j, f->accel, au, lim, dt, t);
    } else {
        snprintf(buf, len, "forces too large for one tick: %s has an acceleration of %g %s "
                 "at a velocity of %g %s, past explode_limit = %g within dt = %g s, at "
                 "t = %.9g s", j, f->accel, au, f->velocity, vu, lim, dt, t);
    }
}

lag_result lag_sim_advance_within(lag_sim *s, int64_t nticks, int64_t stop)
{
    if (nticks <= 0) return LAG_OK;
    const int n = s->nq;
    LAG_ASSERT(n == s->model.nq && s->tick >= 0 && s->n_events >= 0);
    /* the enabled effects that need each tick boundary, and whether some have events
     * (from the effect table's hooks: an effect with per-tick work or watchers is
     * per-tick by construction) */
    LAG_ASSERT(s->fx.enabled == s->def.effects.enabled);
    const uint32_t per_tick = s->fx.per_tick;
    const bool events = s->fx.n_watch > 0;
    const bool adaptive = lag_method_info_get(s->def.integrator.method)->adaptive;
    if (!per_tick && adaptive) {
        if (stop < s->tick + nticks) stop = s->tick + nticks;
        lag_result r = lag_adaptive_advance(s, nticks, stop);
        /* the method checks every step it accepts and the state it interpolates */
        LAG_ASSERT(r != LAG_OK || (lag_state_ok(n, s->q, s->def.explode_limit) &&
                                   lag_state_ok(n, s->qd, s->def.explode_limit)));
        return r == LAG_OK ? r : classify_fault(s, r, s->qd);
    }
    for (int64_t k = 0; k < nticks; k++) {
        double y[LAG_MAX_STATE];
        lag_result r;
        /* pre_tick first: a scheduled impulse changes s->qd, so the copy comes after it
         * (the velocities before it are kept to restore the last good tick on a fault) */
        double qd_good[LAG_MAX_DOF];
        memcpy(qd_good, s->qd, sizeof qd_good);
        if (per_tick) lag_effects_pre_tick(s);
        for (int i = 0; i < n; i++) { y[i] = s->q[i]; y[n + i] = s->qd[i]; }
        r = events ? lag_events_tick(s, y) : plain_tick(s, y);
        /* The one check of a tick's end state, whatever ended the tick: a step, or an
         * event's map (an impulse, a hold, a change of coordinates), which no step checks */
        if (r == LAG_OK) r = lag_state_check(2 * n, y, s->def.explode_limit);
        if (r != LAG_OK) {
            r = classify_fault(s, r, qd_good); /* at the tick's start, after its impulses */
            memcpy(s->qd, qd_good, sizeof qd_good);
            return r; /* public state is still that of the last good tick */
        }
        for (int i = 0; i < n; i++) { s->q[i] = y[i]; s->qd[i] = y[n + i]; }
        /* a good tick is finite, within explode_limit, and still for held joints */
        LAG_ASSERT(lag_state_ok(2 * n, y, s->def.explode_limit));
        for (int i = 0; i < n; i++) LAG_ASSERT(!(s->mode.locked & (1u << i)) || s->qd[i] == 0.0);
        s->tick++;
        if (!adaptive) s->stats.steps_accepted++; /* an adaptive method counts its own */
    }
    return LAG_OK;
}

lag_result lag_sim_advance(lag_sim *s, int64_t nticks, bool continuous)
{
    return lag_sim_advance_within(s, nticks, continuous ? INT64_MAX : s->tick + nticks);
}

lag_result lag_sim_shadow_error(const lag_sim *start, const lag_sim *end, double *err)
{
    const int n = start->nq;
    for (int i = 0; i < n; i++) err[i] = 0.0;
    const lag_integrator_def *in = &start->def.integrator;
    const bool adaptive = lag_method_info_get(in->method)->adaptive;
    const int64_t ticks = end->tick - start->tick;
    if (ticks < 1 || ticks > INT64_MAX / 4 || end->nq != n ||
        memcmp(in, &end->def.integrator, sizeof *in) != 0)
        return LAG_ERR_ARG;
    lag_sim sh = *start;
    double k; /* the shadow's error is the main one's / k */
    int64_t span = ticks;
    if (adaptive) {
        sh.def.integrator.rtol = in->rtol / LAG_SHADOW_TOL_DIV;
        sh.def.integrator.atol = in->atol / LAG_SHADOW_TOL_DIV;
        int64_t steps = end->stats.steps_accepted - start->stats.steps_accepted;
        sh.dp.h_max = 0.5 * (double)ticks * in->dt / (double)(steps > 1 ? steps : 1);
        k = 32.0; /* order 5, steps halved; a tolerance-bound step gains more */
    } else {
        /* ticks of dt/2: sim time tick * dt stays that of START */
        sh.def.integrator.dt = 0.5 * in->dt;
        sh.tick = 2 * start->tick;
        span = 2 * ticks;
        k = ldexp(1.0, lag_method_order(in->method)); /* 2^p */
    }
    lag_result r = lag_sim_advance_within(&sh, span, sh.tick + span);
    if (r != LAG_OK) return r;
    for (int i = 0; i < n; i++) err[i] = fabs(end->q[i] - sh.q[i]) * k / (k - 1.0);
    return LAG_OK;
}
