/* Private to lagsim_core: the per-model function table and the integrator entry points. */
#ifndef LAGSIM_CORE_INTERNAL_H
#define LAGSIM_CORE_INTERNAL_H

#include "lagsim/lagsim.h"

/* One model kind: its facts and its closed forms, one row of the core's model table
 * (model.c). All arrays are n x n row-major (n = nq); p is lag_model.p. Every member is
 * required (core.models.info checks that no row has a hole). */
typedef struct lag_model_class {
    const lag_model_info *info;
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
extern const lag_model_class *const lag_models[LAG_MODEL_COUNT];
static inline const lag_model_class *lag_model_vt(const lag_model *m)
{
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

/* One step of size h from y0 = (q, qd) to y1 = (q, qd) with the sim's method (dopri5:
 * adaptive sub-steps landing exactly on h). Touches neither the public state nor tick. */
lag_result lag_step(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_euler(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_semi_implicit_euler(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_rk4(lag_sim *s, double h, const double *y0, double *y1);
lag_result lag_step_gauss(lag_sim *s, int stages, double h, const double *y0, double *y1);
lag_result lag_dopri5_span(lag_sim *s, double h, const double *y0, double *y1);
/* An adaptive method's own advance of n ticks (its row's `advance`). */
lag_result lag_adaptive_advance(lag_sim *s, int64_t n, bool continuous);
/* The method table has no hole: a name, a step, an order for every row, an advance
 * exactly for the adaptive ones, unique names (core.models.info checks it). */
bool lag_method_table_ok(void);
/* dopri5 without events: advances the public state to tick + n (see lag_sim_advance). */
lag_result lag_dopri5_advance(lag_sim *s, int64_t n, bool continuous);

/* Forward dynamics with the effects' locked joints held (qdd_i = qd_i = 0) and the
 * constraint forces lambda_i (M qdd = Q - h + lambda) they need. lambda may be NULL. */
lag_result lag_forward_locked(const lag_sim *s, const double *q, const double *qd,
                              const double *Q, double *qdd, double *lambda);
/* The generalized forces besides gravity and inertia: applied efforts, damping, sliding
 * friction, disturbance forces. OUT: Q */
void lag_applied_forces(const lag_sim *s, const double *q, const double *qd, double *Q);

/* qd from canonical momenta p at q: qd_f = M_ff^-1 p_f on free joints, 0 on locked. */
lag_result lag_qd_from_p(const lag_sim *s, const double *q, const double *p, double *qd);

/* effects.c: per-tick work before the step, the tick with event location, modes. */
void lag_effects_pre_tick(lag_sim *s);
lag_result lag_effects_tick(lag_sim *s, double *y);
void lag_effects_init_modes(lag_sim *s);
lag_result lag_effects_check(const lag_sim_def *def, lag_diag *d);
void lag_sim_record_event(lag_sim *s, lag_event_kind kind, int joint, double t, double value);

/* Fills d with field and a printf-style message; returns LAG_ERR_ARG. d may be NULL. */
lag_result lag_diag_fail(lag_diag *d, const char *field, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Writes "field: message" (or the message alone) into err[errlen]. */
void lag_diag_format(const lag_diag *d, char *err, size_t errlen);

/* True if every entry is finite and |x_i| <= limit. */
bool lag_state_ok(int n, const double *x, double limit);

#endif
