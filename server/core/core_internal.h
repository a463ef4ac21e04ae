/* Private to lagsim_core: the per-model function table and the integrator entry points. */
#ifndef LAGSIM_CORE_INTERNAL_H
#define LAGSIM_CORE_INTERNAL_H

#include "lagsim/lagsim.h"

/* Internal invariants: checked where assert is on (the Debug builds of the sanitizer
 * pass), free in release builds (NDEBUG). SQLite's assert(): what must hold whatever the
 * input, never a check of the input (that is validation's, with a message). */
#include <assert.h>
#define LAG_ASSERT(cond) assert(cond)

/* One model kind: its facts and its closed forms, one row of the core's model table
 * (model.c). All arrays are n x n row-major (n = nq); p is lag_model.p. Every member is
 * required (core_models_info checks that no row has a hole). */
/* What the documentation says of a model, written in the model's file beside its facts:
 * every list of models in the man pages and the docs is generated from the table and
 * these (server/lists: `cmake --build build --target lists`), never written by hand. */
typedef struct lag_model_doc {
    const char *title;                  /* a noun phrase, no article: "cart-pole" */
    const char *summary;                /* a few words, with its article: "a pendulum on a
                                           cart" (lagsimd.1's list of models) */
    const char *params[LAG_MAX_PARAMS]; /* each parameter's meaning: "cart mass" */
    const char *joints[LAG_MAX_DOF];    /* each coordinate's meaning: "cart position" */
} lag_model_doc;

typedef struct lag_model_class {
    const lag_model_info *info;
    const lag_model_doc *doc;
    void (*mass)(const double *p, const double *q, double *M);
    void (*mass_deriv)(const double *p, const double *q, double *dM);
    void (*coriolis)(const double *p, const double *q, const double *qd, double *C);
    void (*gravity)(const double *p, const double *q, double *g);
    /* M(q) and h = C qd + g together: what the step needs, sharing the trig. */
    void (*mass_bias)(const double *p, const double *q, const double *qd, double *M, double *h);
    /* M qdd = tau - C qd - g, closed form (the step's hot path). tau is not NULL. */
    lag_result (*forward)(const double *p, const double *q, const double *qd,
                          const double *tau, double *qdd);
    double (*kinetic)(const double *p, const double *q, const double *qd);
    double (*potential)(const double *p, const double *q);
} lag_model_class;

/* The model table, indexed by lag_model_kind (model.c). */
/* Declared without its size, so that the definition's own count of rows is what the
 * _Static_assert there compares with LAG_MODEL_COUNT. */
extern const lag_model_class *const lag_models[];
/* The flying stick measured from end A [0] and from end B [1], whatever its
 * p[LAG_FSTICK_END]: what the floor has the sim integrate (lag_sim.dyn). */
extern const lag_model_class lag_flying_stick_ends[2];
/* The stick's parameters, one rod, as both its models (sliding, flying) describe them in
 * their lag_model_info. */
/* ... and their meanings (lag_model_doc.params). */
#define LAG_STICK_PARAMS_DOC                                                       \
    .params = {"mass", "length", "inertia about the centre of mass", "gravity"}
#define LAG_STICK_PARAMS_INFO                                                      \
    .np = LAG_STICK_NP, .param_names = {"m", "l", "I", "g"},                       \
    .param_defaults = {1.0, 1.0, NAN, 9.81},                                       \
    .param_units = {"kg", "m", "kg m^2", "m/s^2"},                                 \
    .param_rules = {[LAG_STICK_G] = LAG_PARAM_NONNEGATIVE}, .n_rods = 1,           \
    .rods = {{LAG_STICK_I, LAG_STICK_M, LAG_STICK_L}}

static inline const lag_model_class *lag_model_vt(const lag_model *m)
{
    LAG_ASSERT((unsigned)m->kind < LAG_MODEL_COUNT && lag_models[m->kind]);
    return lag_models[m->kind];
}

/* Closed-form LDL^T solves for the sizes the models have (no sqrt, no loops): the
 * forward dynamics spend most of their time here. A non-positive pivot (NaN included)
 * means A is not numerically SPD. */
static inline lag_result lag_spd_solve2(const double *A, const double *b, double *x)
{
    double d0 = A[0];
    if (!(d0 > 0.0)) return LAG_ERR_SINGULAR;
    double l10 = A[2] / d0;
    double d1 = A[3] - l10 * A[2];
    if (!(d1 > 0.0)) return LAG_ERR_SINGULAR;
    double z1 = b[1] - l10 * b[0];
    x[1] = z1 / d1;
    x[0] = b[0] / d0 - l10 * x[1];
    return LAG_OK;
}

static inline lag_result lag_spd_solve3(const double *A, const double *b, double *x)
{
    double d0 = A[0];
    if (!(d0 > 0.0)) return LAG_ERR_SINGULAR;
    double i0 = 1.0 / d0;
    double l10 = A[3] * i0, l20 = A[6] * i0;
    double d1 = A[4] - l10 * A[3];
    if (!(d1 > 0.0)) return LAG_ERR_SINGULAR;
    double l21 = (A[7] - l20 * A[3]) / d1;
    double d2 = A[8] - l20 * A[6] - l21 * l21 * d1;
    if (!(d2 > 0.0)) return LAG_ERR_SINGULAR;
    double z0 = b[0], z1 = b[1] - l10 * z0, z2 = b[2] - l20 * z0 - l21 * z1;
    x[2] = z2 / d2;
    x[1] = z1 / d1 - l21 * x[2];
    x[0] = z0 * i0 - l10 * x[1] - l20 * x[2];
    return LAG_OK;
}

/* Solves A x = b for symmetric positive definite A (n <= LAG_MAX_STATE) by Cholesky.
 * A is not modified. Returns LAG_ERR_SINGULAR if a pivot is not positive. OUT: x */
lag_result lag_spd_solve(int n, const double *A, const double *b, double *x);
/* Solves A x = b by LU with partial pivoting (n <= 4 * LAG_MAX_STATE); A is overwritten.
 * Returns LAG_ERR_SINGULAR on a zero pivot. b is overwritten with x. */
lag_result lag_lu_solve_inplace(int n, double *A, double *b);

/* First-order right-hand side in (q, qd) and in canonical (q, p) coordinates. */
lag_result lag_sim_rhs_qp(lag_sim *s, const double *y, double *ydot);

/* The generalized forces besides gravity and inertia: the applied effort plus each
 * enabled effect's force (damping, sliding friction, disturbance forces, springs). OUT: Q */
void lag_effects_force(const lag_sim *s, const double *q, const double *qd, double *Q);
/* Forward dynamics with the effects' locked joints held (qdd_i = qd_i = 0) and the
 * constraint forces lambda_i (M qdd = Q - h + lambda) they need. lambda may be NULL. */
lag_result lag_forward_locked(const lag_sim *s, const double *q, const double *qd,
                              const double *Q, double *qdd, double *lambda);

/* lag_sim_rhs without naming its failure (the integrators' hot path: a tail call into the
 * forward dynamics); a caller that gets an error passes it through lag_stage_fault. */
static inline lag_result lag_rhs(lag_sim *s, const double *y, double *ydot)
{
    const int n = s->nq;
    s->stats.rhs_evals++;
    for (int i = 0; i < n; i++) ydot[i] = y[n + i];
    if (s->def.effects.enabled || s->mode.locked) {
        double Q[LAG_MAX_DOF];
        lag_effects_force(s, y, y + n, Q);
        return lag_forward_locked(s, y, y + n, Q, ydot + n, NULL);
    }
    /* The bare model, the hot path: the model's closed-form forward dynamics. */
    return s->dyn->forward(s->model.p, y, y + n, s->tau_applied, ydot + n);
}
/* A right-hand side failed with r at stage state y: a "singular" mass matrix of a
 * non-finite q (a stage that overflowed: cos(inf)) is a non-finite state, not a singular
 * configuration. For failure paths only. */
lag_result lag_stage_fault(const lag_sim *s, const double *y, lag_result r);

/* One step of size h from y0 = (q, qd) to y1 = (q, qd) with the sim's method (dopri5:
 * adaptive sub-steps landing exactly on h). Touches neither the public state nor tick. */
lag_result lag_step(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_euler(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_semi_implicit_euler(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_rk4(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_gauss(lag_sim *s, int stages, double h, const double *y0, double *y1);
lag_result lag_dopri5_span(lag_sim *s, double h, const double *y0, double *y1);
/* An adaptive method's own advance of n ticks of a span that ends at tick `stop`, where the
 * input may change (INT64_MAX: none; see lag_sim_advance_within). Its row's `advance`. */
lag_result lag_adaptive_advance(lag_sim *s, int64_t n, int64_t stop);
/* The method table has no hole: a name, a step, an order for every row, an advance
 * exactly for the adaptive ones, unique names (core_models_info checks it). */
bool lag_method_table_ok(void);
/* dopri5 without events: advances the public state to tick + n (see lag_sim_advance). */
lag_result lag_dopri5_advance(lag_sim *s, int64_t n, int64_t stop);

/* qd from canonical momenta p at q: qd_f = M_ff^-1 p_f on free joints, 0 on locked. */
lag_result lag_qd_from_p(const lag_sim *s, const double *q, const double *p, double *qd);

/* Fills d with field and a printf-style message; returns LAG_ERR_ARG. d may be NULL. */
lag_result lag_diag_fail(lag_diag *d, const char *field, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Writes "field: message" (or the message alone) into err[errlen]. */
void lag_diag_format(const lag_diag *d, char *err, size_t errlen);

/* True if every entry is finite and |x_i| <= limit. */
bool lag_state_ok(int n, const double *x, double limit);
/* The one check of a state: LAG_OK when lag_state_ok(n, x, limit), else LAG_ERR_NONFINITE
 * for a NaN or Inf, LAG_ERR_EXPLODE for a finite value past limit. */
lag_result lag_state_check(int n, const double *x, double limit);

/* ================================================================ events.c: the engine;
 * contact.c: impulses, holds, stops; event_queue.c: the sim's events */
#define LAG_MAX_WATCHERS 16        /* watchers of one tick (checked: core_events_capacity) */
#define LAG_MAX_EVENTS_PER_TICK 16 /* then LAG_EV_EVENT_LIMIT and no more location */

typedef enum lag_watch_kind {
    LAG_WATCH_POSITION,      /* q_joint against `bound` on `side` (-1 lower, +1 upper) */
    LAG_WATCH_VELOCITY_ZERO, /* a sliding joint's velocity reaching zero */
    LAG_WATCH_HOLD,          /* a held joint's constraint force (the engine's own) */
    LAG_WATCH_CUSTOM,        /* the owner's `value` with the dynamics (lift-off) */
    LAG_WATCH_GAP            /* the owner's gap g(q) >= 0 (an end above the floor, `gap`):
                                fires as a stop does; due at its start when closed (<= 0)
                                and closing */
} lag_watch_kind;

/* One event function of a tick: positive while nothing happens. */
typedef struct lag_watcher {
    uint8_t kind;   /* lag_watch_kind */
    uint8_t owner;  /* the effect row whose on_event applies its map (not for HOLD) */
    int8_t joint;
    int8_t side;    /* POSITION: -1 lower bound, +1 upper */
    bool strict;    /* fires on a > 0, b <= 0 (reaching a bound); else on a >= 0, b < 0 */
    double bound;   /* POSITION: the stop's position */
    double e;       /* POSITION: restitution */
} lag_watcher;

typedef struct lag_watch_set {
    int n;
    lag_watcher w[LAG_MAX_WATCHERS];
} lag_watch_set;

/* Adds w; false (and nothing written) when the set holds LAG_MAX_WATCHERS already. */
static inline bool lag_watch_add(lag_watch_set *ws, lag_watcher w)
{
    if (ws->n >= LAG_MAX_WATCHERS) return false;
    ws->w[ws->n++] = w;
    return true;
}
/* Has w fired between values a (earlier) and b (later)? */
static inline bool lag_watch_fired(const lag_watcher *w, double a, double b)
{
    if (w->strict) return a > 0 && b <= 0;
    return a >= 0 && b < 0;
}
/* Cubic Hermite interpolant of a step of h from (y0, f0) to (y1, f1), at theta in [0, 1].
 * Exact for cubics. OUT: y */
void lag_hermite(int N, double h, const double *y0, const double *f0, const double *y1,
                 const double *f1, double th, double *y);
/* Event function values of the set at state y. OUT: vals[ws->n] */
typedef lag_result (*lag_watch_eval_fn)(void *ctx, const double *y, double *vals);
/* The earliest event of the set along the step y0 -> y1 (slopes f0, f1, length H; v0 the
 * values at y0): the interpolant is sampled at 4 points for a sign change, then each
 * watcher that fired in the first such segment is located by Illinois to 1e-15 s (at most
 * 80 iterations) and the earliest kept. *which = its index (-1: none fired), *theta = the
 * right end of its final bracket (the event has happened there; 1 if none). */
lag_result lag_event_locate(int N, double H, const double *y0, const double *f0,
                            const double *y1, const double *f1, const lag_watch_set *ws,
                            const double *v0, lag_watch_eval_fn eval, void *ctx, int *which,
                            double *theta);
/* x = M^-1 e_i on the free joints. OUT: x */
lag_result lag_minv_column(const lag_sim *s, const double *q, int i, double *x);
/* The impulse at joint i that leaves J qd+ = -e J qd- (y = (q, qd), in place). */
lag_result lag_impulse_map(lag_sim *s, double *y, int i, double e);
/* Friction's modes: does joint i have friction; settle joint i at rest (held, or sliding
 * against the force: returns LAG_EV_STICK or LAG_EV_SLIP); after an impulse, point each
 * sliding joint's friction against its new velocity. */
static inline bool lag_has_friction(const lag_sim *s, int i)
{
    const lag_effects_def *e = &s->def.effects;
    return (e->enabled & LAG_EFF_FRICTION) &&
           (e->friction_static[i] > 0 || e->friction_kinetic[i] > 0);
}
static inline int lag_sgn(double v) { return (v > 0) - (v < 0); }
/* Constraint forces with the current locks at state y (contact.c). OUT: lambda */
lag_result lag_lock_forces(lag_sim *s, const double *y, double *lambda);
lag_event_kind lag_friction_settle(lag_sim *s, double *y, int i);
void lag_refresh_slip(lag_sim *s, double *y);
void lag_effects_init_modes(lag_sim *s);
/* One tick with event location, from y (in place). The state it ends with, after the
 * last step or the last event's map, is checked by its caller (lag_sim_advance_within). */
lag_result lag_events_tick(lag_sim *s, double *y);
void lag_sim_record_event(lag_sim *s, lag_event_kind kind, int joint, double t, double value);

/* ================================================================ effects.c: the table */
/* One effect (see effects.c's header). validate is required; any other hook may be NULL,
 * and what the effect takes part in follows from which are there. */
typedef struct lag_effect_row {
    uint32_t bit;
    const char *name;
    int max_watch_joint;  /* watchers it adds per free joint, at most */
    int max_watch_global; /* watchers of no joint it adds, at most */
    lag_result (*validate)(const lag_sim_def *def, lag_diag *d);
    void (*force)(const lag_sim *s, const double *q, const double *qd, double *Q); /* adds */
    double (*potential)(const lag_sim *s, const double *q);
    void (*pre_tick)(lag_sim *s);
    /* adds its watchers of `joint` (-1: those of no joint) as owner `self` */
    bool (*watch)(const lag_sim *s, int joint, int self, lag_watch_set *ws);
    /* a CUSTOM watcher's event function at y, with the accelerations qdd there */
    double (*value)(lag_sim *s, const lag_watcher *w, const double *y, const double *qdd);
    /* a GAP watcher's gap at y = (q, qd) and its rate; with qdd (not NULL) also its second
     * derivative (accel) */
    double (*gap)(const lag_sim *s, const lag_watcher *w, const double *y, const double *qdd,
                  double *rate, double *accel);
    lag_result (*on_event)(lag_sim *s, const lag_watcher *w, double *y, double t);
    void (*observe)(const lag_sim *s, double *q, double *qd);
    /* does it keep state of its own from tick to tick under these settings (modes, a lag
     * state: not in q, qd, tick and the definition)? NULL: never */
    bool (*keeps_state)(const lag_effects_def *e);
    /* The hooks of an effect that changes what the sim integrates (the floor's flight,
     * effect_floor.c); each is called for the enabled rows that have it, in table order. */
    /* the model def has the sim integrate (IN: def's model; OUT: the one integrated) */
    void (*sim_model)(const lag_sim_def *def, lag_model *m);
    const char *sim_model_key; /* the setting that decides it ("flight"), for messages */
    /* at a reset, the state set and the modes cleared: its run state from the state */
    void (*reset)(lag_sim *s);
    /* the holds it starts with at the current state (after friction's modes), at a reset
     * and when a redefinition derives the modes again */
    void (*init_holds)(lag_sim *s);
    /* the joints whose holds a generalized impulse does not break (bits) */
    uint32_t (*firm_holds)(const lag_sim *s);
    /* joint i's hold on a stop let go (the force would pull; lambda: the holds' forces at
     * y): true if the hold is this effect's and what follows is done (events recorded) */
    bool (*release)(lag_sim *s, int i, double *y, double t, const double *lambda);
    /* the landing hook: refines the step from y0 to its watcher w's located event (length
     * hs of at most H, state ys there) before the event's map. IN/OUT: hs, ys */
    lag_result (*land)(lag_sim *s, const lag_watcher *w, const double *y0, double H,
                       double *hs, double *ys);
    /* the published state in its own coordinates, before observe's changes */
    void (*publish)(const lag_sim *s, double *q, double *qd);
    /* the run's state as the initial state of a definition (lag_sim_redefine's check) */
    void (*as_initial)(const lag_sim *s, lag_sim_def *at);
} lag_effect_row;

/* Without its size, as lag_models: effects.c's _Static_assert counts the rows. */
extern const lag_effect_row *const lag_effect_rows[];
/* The rows defined in units of their own (the others are effects.c's). */
extern const lag_effect_row lag_effect_floor; /* effect_floor.c */

/* A stop of joint w->joint reached (limits, the floor): an impact with restitution w->e,
 * or resting contact (rest_kind; a LAG_EV_LANDING that the floor would have to hold by
 * pulling is an impact, `bounce`) when slower than rest_velocity or when the bounce would
 * come back within one tick. IN/OUT: y */
lag_result lag_stop_event(lag_sim *s, const lag_watcher *w, double *y, double t,
                          lag_event_kind bounce, lag_event_kind rest_kind);
/* rest_velocity: finite, >= 0 (field: the effect's key for it). */
lag_result lag_rest_velocity_validate(const lag_sim_def *def, lag_diag *d, const char *field);
/* The dispatch of the hooks above (lag_effect_row), over the enabled rows. */
int lag_effects_sim_model(const lag_sim_def *def, lag_model *m); /* row that changed m, -1 */
void lag_effects_reset(lag_sim *s);
void lag_effects_init_holds(lag_sim *s);
uint32_t lag_effects_firm_holds(const lag_sim *s);
bool lag_effects_release(lag_sim *s, int i, double *y, double t, const double *lambda);
void lag_effects_as_initial(const lag_sim *s, lag_sim_def *at);

lag_result lag_effects_check(const lag_sim_def *def, lag_diag *d);
/* Fills s->fx (the rows the enabled effects use, per hook) from s->def. */
void lag_effects_prepare(lag_sim *s);
/* Energy stored by the enabled effects at q. */
double lag_effects_potential(const lag_sim *s, const double *q);
void lag_effects_pre_tick(lag_sim *s);
/* Every enabled row's watchers of `joint` (-1: of no joint), in table order; false when
 * the set is full. */
bool lag_effects_watch(const lag_sim *s, int joint, lag_watch_set *ws);
/* The bits of all rows; of the enabled ones that are per-tick; that have events. */
uint32_t lag_effects_known(void);
uint32_t lag_effects_per_tick(uint32_t enabled);
uint32_t lag_effects_with_events(uint32_t enabled);

#endif
