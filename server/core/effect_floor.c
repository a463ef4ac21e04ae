/*
 * The floor effect: the stick's ends on a frictionless floor at y = 0. One row of the
 * effect table (lag_effect_floor); everything the stick and its floor need beyond a stop
 * of a joint is here, reached by the generic core through the row's hooks only:
 *   sim_model   a stick whose floor lets it fly is integrated as the flying stick
 *               (x, phi, h); which end h measures is run state (lag_sim.mode.floor_end,
 *               set at a reset and switched at a landing of the other end), and the
 *               closed forms integrated follow it (lag_sim.dyn): the model itself, its
 *               parameters included, is never written
 *   reset, init_holds   the end below the centre, held on the floor when h = h_dot = 0
 *   firm_holds  the floor's hold of h outlasts an impulse (it pushes or lets go)
 *   release     the hold of h letting go is a lift-off: the stick flies
 *   land        a located landing put exactly on the floor (Newton on the step)
 *   publish     the published h: the lower end's height
 *   as_initial  the run's state checked as a definition (lag_sim_redefine)
 */
#include <math.h>
#include <string.h>
#include "core_internal.h"

/* The floor with flight: the sim integrates the flying stick. */
static bool flying(const lag_sim *s) { return s->model.kind == LAG_MODEL_FLYING_STICK; }

/* h measures end B (true) or end A: the run state and the closed forms that follow it. */
static void set_end(lag_sim *s, bool end_b)
{
    s->mode.floor_end = end_b ? 1 : 0;
    s->dyn = &lag_flying_stick_ends[s->mode.floor_end];
}

/* Stick only. Without flight (floor_flight false): its end on the floor, impacts of the
 * free end at phi = 0 and pi (reported as impacts), resting contact, and lift-off (the
 * normal force reaching zero, a CUSTOM watcher) is a fault.
 * With flight, the sim integrates the flying stick (x, phi, h), h the height of one end
 * (model_flying_stick.c), and the floor is a stop of h at 0 on the lower side:
 *   - in contact h is held (a resting stop): the stop's hold force is the normal force,
 *     and when it would pull the hold lets go (events.c: a `liftoff`, the stick flies);
 *     the free end's impacts are those of the stick without flight, at phi = k pi and
 *     (k + 1) pi around the contact's interval of phi;
 *   - in flight h's stop is watched (that end landing: a frictionless impact, the
 *     vertical impulse at the end being a generalized impulse on h alone, J = e_h), and
 *     the other end's height h + sigma l sin phi (a GAP watcher): when it reaches the
 *     floor, h is made that end's height (a change of coordinates: x, phi, the velocities
 *     and the energy unchanged) and it lands as h's end does;
 *   - a landing ends in sliding contact (`landing`, h held) when it is slower than
 *     rest_velocity or its bounce would come back within one tick (the Zeno guard), and
 *     the floor then pushes (else the end touches and the stick flies on: `impact`);
 *     otherwise the end bounces (`impact`), J qd+ = -e J qd-. */

static lag_result floor_validate(const lag_sim_def *def, lag_diag *d)
{
    const lag_effects_def *e = &def->effects;
    if (def->model.kind != LAG_MODEL_STICK)
        return lag_diag_fail(d, "effects.floor", "the floor effect is for the stick model only");
    lag_result r = lag_rest_velocity_validate(def, d, "effects.floor.rest_velocity");
    if (r != LAG_OK) return r;
    if (!(e->floor_restitution >= 0 && e->floor_restitution <= 1))
        return lag_diag_fail(d, "effects.floor.restitution", "expected a number in [0, 1], got %g",
                             e->floor_restitution);
    if (def->q0[1] < 0 || def->q0[1] > M_PI)
        return lag_diag_fail(d, "initial.q[1]", "initial phi = %g must be in [0, pi] with a floor",
                             def->q0[1]);
    if (e->floor_flight) {
        double h = def->q0[2], hd = def->qd0[2];
        if (!(isfinite(h) && h >= 0 && h <= def->explode_limit))
            return lag_diag_fail(d, "initial.q[2]",
                                 "the stick's lower end is at height h = %g: expected a number "
                                 "in [0, explode_limit]", h);
        if (!(isfinite(hd) && fabs(hd) <= def->explode_limit))
            return lag_diag_fail(d, "initial.qd[2]", "expected a finite number within "
                                 "explode_limit, got %g", hd);
    } else if (def->q0[2] != 0 || def->qd0[2] != 0) {
        return lag_diag_fail(d, "initial.q[2]", "a height needs a floor the stick may leave "
                             "(flight: true)");
    }
    return LAG_OK;
}

/* sigma of the flying stick: +1 when h is end A's height, -1 for end B's */
static double floor_sigma(const lag_sim *s)
{
    return s->mode.floor_end != 0 ? -1.0 : 1.0;
}

/* In contact on h's end, the interval [k pi, (k + 1) pi] of phi in which the stick is
 * above the floor: k even for end A (sin phi >= 0), odd for end B; the one whose middle
 * is nearest phi (phi may lie a rounding outside it after a landing). */
static double floor_k(const lag_sim *s, double phi)
{
    double off = s->mode.floor_end != 0 ? 1.0 : 0.0;
    return 2.0 * round((phi / M_PI - off - 0.5) / 2.0) + off;
}

static bool floor_watch(const lag_sim *s, int joint, int self, lag_watch_set *ws)
{
    const double e = s->def.effects.floor_restitution;
    if (flying(s)) {
        const bool contact = s->mode.locked & (1u << 2);
        lag_watcher w = {.kind = LAG_WATCH_POSITION, .owner = (uint8_t)self, .strict = true,
                         .e = e, .side = -1};
        if (joint == 2) { /* h's end landing (h is free: a held joint has its hold only) */
            w.joint = 2;
            w.bound = 0.0;
            return lag_watch_add(ws, w);
        }
        if (joint == 1 && contact) { /* the free end reaching the floor */
            double k = floor_k(s, s->q[1]);
            w.joint = 1;
            w.bound = k * M_PI;
            if (!lag_watch_add(ws, w)) return false;
            w.side = +1;
            w.bound = (k + 1.0) * M_PI;
            return lag_watch_add(ws, w);
        }
        if (joint < 0 && !contact) /* the other end landing */
            return lag_watch_add(ws, (lag_watcher){.kind = LAG_WATCH_GAP, .owner = (uint8_t)self,
                                                   .joint = 2, .strict = true, .e = e});
        return true;
    }
    if (joint < 0) /* lift-off: the normal force, with the dynamics (value below) */
        return lag_watch_add(ws, (lag_watcher){.kind = LAG_WATCH_CUSTOM, .owner = (uint8_t)self,
                                               .joint = 1, .strict = false});
    if (joint != 1) return true;
    lag_watcher w = {.kind = LAG_WATCH_POSITION, .owner = (uint8_t)self, .joint = 1,
                     .strict = true, .e = e};
    w.side = -1;
    w.bound = 0.0;
    if (!lag_watch_add(ws, w)) return false;
    w.side = +1;
    w.bound = M_PI;
    return lag_watch_add(ws, w);
}

/* N = m (g + d2/dt2 ((l/2) sin phi)), divided by m */
static double floor_normal(lag_sim *s, const lag_watcher *w, const double *y, const double *qdd)
{
    (void)w;
    const double *p = s->def.model.p;
    const int n = s->nq;
    double ph = y[1], phd = y[n + 1];
    return p[LAG_STICK_G] + 0.5 * p[LAG_STICK_L] * (cos(ph) * qdd[1] - sin(ph) * phd * phd);
}

/* The other end's height h + sigma l sin phi, its rate and its second derivative. */
static double floor_gap(const lag_sim *s, const lag_watcher *w, const double *y,
                        const double *qdd, double *rate, double *accel)
{
    (void)w;
    const int n = s->nq;
    const double sl = floor_sigma(s) * s->model.p[LAG_STICK_L];
    double sn = sin(y[1]), c = cos(y[1]), phd = y[n + 1];
    if (rate) *rate = y[n + 2] + sl * c * phd;
    if (accel && qdd) *accel = qdd[2] + sl * (c * qdd[1] - sn * phd * phd);
    return y[2] + sl * sn;
}

static lag_result floor_event(lag_sim *s, const lag_watcher *w, double *y, double t)
{
    if (w->kind == LAG_WATCH_CUSTOM) {
        lag_sim_record_event(s, LAG_EV_LIFTOFF, 1, t, 0.0);
        return LAG_ERR_LIFTOFF;
    }
    if (w->kind == LAG_WATCH_GAP) {
        /* h becomes the landing end's height: y = h + sigma a s = h' - sigma a s */
        const int n = s->nq;
        double rate, gap = floor_gap(s, w, y, NULL, &rate, NULL);
        y[2] = gap;
        y[n + 2] = rate;
        set_end(s, !s->mode.floor_end);
        s->dp.valid = false;
        lag_watcher h = {.kind = LAG_WATCH_POSITION, .owner = w->owner, .joint = 2, .side = -1,
                         .strict = true, .bound = 0.0, .e = w->e};
        return lag_stop_event(s, &h, y, t, LAG_EV_IMPACT, LAG_EV_LANDING);
    }
    if (w->joint == 2) return lag_stop_event(s, w, y, t, LAG_EV_IMPACT, LAG_EV_LANDING);
    return lag_stop_event(s, w, y, t, LAG_EV_IMPACT, LAG_EV_REST);
}

/* At a reset: h is the lower end's height, end B's when it is below the centre. */
static void floor_reset(lag_sim *s)
{
    if (flying(s)) set_end(s, sin(s->q[1]) < 0);
}

/* The published h: the lower end's height and vertical velocity (0 in contact). */
static void floor_publish(const lag_sim *s, double *q, double *qd)
{
    if (!flying(s)) return;
    if (s->mode.locked & (1u << 2)) {
        q[2] = 0.0;
        qd[2] = 0.0;
        return;
    }
    double rate, other = floor_gap(s, NULL, (const double[]){s->q[0], s->q[1], s->q[2],
                                                             s->qd[0], s->qd[1], s->qd[2]},
                                   NULL, &rate, NULL);
    if (other < s->q[2]) {
        q[2] = other;
        qd[2] = rate;
    }
}


/* The model a definition has the sim integrate: the flying stick for a stick whose floor
 * lets it fly (its parameters the stick's; h measures end A until a reset says). */
static void floor_sim_model(const lag_sim_def *def, lag_model *m)
{
    if (def->model.kind != LAG_MODEL_STICK || !def->effects.floor_flight) return;
    m->kind = LAG_MODEL_FLYING_STICK;
    m->nq = 3;
    m->p[LAG_FSTICK_END] = 0.0;
}

/* A stick that can fly starts on the floor when h and h_dot are 0 (it lifts off at once
 * if the floor would have to pull). */
static void floor_init_holds(lag_sim *s)
{
    if (flying(s) && s->q[2] == 0.0 && s->qd[2] == 0.0) {
        s->mode.locked |= 1u << 2;
        s->mode.lock_side[2] = -1;
    }
}

static uint32_t floor_firm_holds(const lag_sim *s) { return flying(s) ? 1u << 2 : 0u; }

/* The floor's normal force reached zero: the stick flies (its free end, if held on the
 * floor too, is released with it: no end is held in flight). */
static bool floor_release(lag_sim *s, int i, double *y, double t, const double *lambda)
{
    if (!flying(s) || i != 2) return false;
    const int n = s->nq;
    lag_sim_record_event(s, LAG_EV_LIFTOFF, i, t, lambda[i]);
    s->mode.released |= 1u << i;
    if (s->mode.locked & (1u << 1)) {
        s->mode.locked &= ~(1u << 1);
        s->mode.lock_side[1] = 0;
        y[n + 1] = 0.0;
    }
    return true;
}

/* The watcher's value at y and its rate (the landing end's height and vertical velocity,
 * or h's). OUT: val */
static double watch_rate(lag_sim *s, const lag_watcher *w, const double *y, double *val)
{
    const int n = s->nq;
    if (w->kind == LAG_WATCH_GAP) {
        double rate;
        *val = floor_gap(s, w, y, NULL, &rate, NULL);
        return rate;
    }
    *val = w->side < 0 ? y[w->joint] - w->bound : w->bound - y[w->joint];
    return -w->side * y[n + w->joint];
}

/* The landing hook. The step redone up to the located instant ends where the method's own
 * step puts it, which for a low-order method is off the interpolant the instant was found
 * on (an end below the floor by O(h^2) with euler). Newton on the length of the redone
 * step, with the watcher's rate, puts the end on the floor: at most 12 more steps, only at
 * such events, keeping the best. IN/OUT: hs, ys */
static lag_result floor_land(lag_sim *s, const lag_watcher *w, const double *y0, double H,
                             double *hs, double *ys)
{
    if (!flying(s) || (w->kind != LAG_WATCH_POSITION && w->kind != LAG_WATCH_GAP)) return LAG_OK;
    const int N = 2 * s->nq;
    const double tol = 1e-15 * (1.0 + s->def.model.p[LAG_STICK_L]);
    double val, rate = watch_rate(s, w, ys, &val);
    double h = *hs, best = fabs(val), hp = NAN, vp = NAN;
    for (int it = 0; it < 12 && best > tol; it++) {
        /* Newton with the end's rate first, then secant on the method's own steps */
        double hn = (it == 0 || !(val != vp)) ? h - val / rate : h - val * (h - hp) / (val - vp);
        if (!(hn > 0 && hn <= H) || hn == h) break;
        double yt[LAG_MAX_STATE], vn;
        lag_result r = lag_step(s, hn, y0, yt);
        if (r != LAG_OK) return r;
        if ((r = lag_state_check(N, yt, s->def.explode_limit)) != LAG_OK) return r;
        rate = watch_rate(s, w, yt, &vn);
        hp = h; vp = val;
        h = hn; val = vn;
        if (fabs(vn) < best) {
            best = fabs(vn);
            *hs = hn;
            memcpy(ys, yt, sizeof(double) * (size_t)N);
        }
    }
    return LAG_OK;
}

/* A stick in the air or on either end is above its floor by construction: checked as
 * standing on it at the same |sin phi|. */
static void floor_as_initial(const lag_sim *s, lag_sim_def *at)
{
    if (!flying(s)) return;
    at->q0[1] = acos(cos(s->q[1]));
    at->q0[2] = at->qd0[2] = 0.0;
}

static bool floor_keeps_state(const lag_effects_def *e)
{
    (void)e;
    return true;
}

const char *lag_sim_contact(const lag_sim *s)
{
    if (!(s->def.effects.enabled & LAG_EFF_FLOOR) || !flying(s)) return "";
    if (!(s->mode.locked & (1u << 2))) return "flight";
    return (s->mode.locked & (1u << 1)) ? "flat" : "contact";
}

/* The floor is the one effect that changes the closed forms integrated while running. */
void lag_sim_dynamics(const lag_sim *s, lag_model *m)
{
    *m = s->model;
    if (flying(s) && (s->def.effects.enabled & LAG_EFF_FLOOR))
        m->p[LAG_FSTICK_END] = s->mode.floor_end;
}

/* The table's row (effects.c lists it in its place). */
const lag_effect_row lag_effect_floor = {
    .bit = LAG_EFF_FLOOR, .name = "floor", .validate = floor_validate, .watch = floor_watch,
    .value = floor_normal, .gap = floor_gap, .on_event = floor_event, .max_watch_joint = 2,
    .max_watch_global = 1, .keeps_state = floor_keeps_state, .sim_model = floor_sim_model,
    .sim_model_key = "flight",
    .reset = floor_reset, .init_holds = floor_init_holds, .firm_holds = floor_firm_holds,
    .release = floor_release, .land = floor_land, .publish = floor_publish,
    .as_initial = floor_as_initial,
};
