/* Private to lagsim_core: the per-model function table and the integrator entry points. */
#ifndef LAGSIM_CORE_INTERNAL_H
#define LAGSIM_CORE_INTERNAL_H

#include "lagsim/lagsim.h"

/* One model kind's closed forms. All arrays are n x n row-major (n = nq). */
typedef struct lag_model_vtable {
    void (*mass)(const double *p, const double *q, double *M);
    void (*mass_deriv)(const double *p, const double *q, double *dM);
    void (*coriolis)(const double *p, const double *q, const double *qd, double *C);
    void (*gravity)(const double *p, const double *q, double *g);
    /* M(q) and h = C qd + g together: what the step needs, sharing the trig. */
    void (*mass_bias)(const double *p, const double *q, const double *qd, double *M, double *h);
    double (*kinetic)(const double *p, const double *q, const double *qd);
    double (*potential)(const double *p, const double *q);
} lag_model_vtable;

extern const lag_model_vtable lag_stick_vtable;
extern const lag_model_vtable lag_manipulator_vtable;
extern const lag_model_vtable lag_dipc_vtable;
extern const lag_model_info lag_stick_info;
extern const lag_model_info lag_manipulator_info;
extern const lag_model_info lag_dipc_info;

const lag_model_vtable *lag_model_vt(const lag_model *m);

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
lag_result lag_effects_validate(const lag_sim_def *def, char *err, size_t errlen);
void lag_sim_record_event(lag_sim *s, lag_event_kind kind, int joint, double t, double value);

/* True if every entry is finite and |x_i| <= limit. */
bool lag_state_ok(int n, const double *x, double limit);

#endif
