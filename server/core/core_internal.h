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

/* One step of each fixed-step method from the public state (s->q, s->qd), h = dt.
 * Writes the new state into q1, qd1; does not touch the public state. */
lag_result lag_step_euler(lag_sim *s, double *q1, double *qd1);
lag_result lag_step_semi_implicit_euler(lag_sim *s, double *q1, double *qd1);
lag_result lag_step_rk4(lag_sim *s, double *q1, double *qd1);
lag_result lag_step_gauss(lag_sim *s, int stages, double *q1, double *qd1);
/* dopri5: advances the public state to tick + n (see lag_sim_advance). */
lag_result lag_dopri5_advance(lag_sim *s, int64_t n, bool continuous);

/* True if every entry is finite and |x_i| <= limit. */
bool lag_state_ok(int n, const double *x, double limit);

#endif
