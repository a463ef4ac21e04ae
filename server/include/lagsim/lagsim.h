/*
 * lagsim core: three Lagrangian models, six integrators, a simulation state.
 *
 * The core knows nothing of LCM or YAML. A model is read-only (`const lag_model*`), a
 * simulation (`lag_sim`) is the mutable state; no function here allocates memory, prints,
 * or exits. Errors are result codes; functions that can fail for a reason worth telling
 * write a message into a caller's buffer.
 *
 * Coordinates, T and U are those of shared/BRIEF.md; units are SI (m, kg, s, rad, N, N m).
 * Matrices are row-major, n x n with n = model->nq (at most LAG_MAX_DOF).
 */
#ifndef LAGSIM_LAGSIM_H
#define LAGSIM_LAGSIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_MAX_DOF 3
#define LAG_MAX_STATE (2 * LAG_MAX_DOF)
#define LAG_MAX_PARAMS 12

/* ---------------------------------------------------------------- result codes */
typedef enum lag_result {
    LAG_OK = 0,
    LAG_ERR_ARG,       /* invalid argument or definition (message says which) */
    LAG_ERR_SINGULAR,  /* mass matrix not positive definite at this state */
    LAG_ERR_NONFINITE, /* a step produced NaN or Inf: state left unchanged */
    LAG_ERR_EXPLODE,   /* |q| or |qd| exceeded lag_sim_def.explode_limit: state unchanged */
    LAG_ERR_NEWTON,    /* implicit method: Newton did not converge in max_iter */
    LAG_ERR_STEPSIZE   /* dopri5: step size fell below dt_min */
} lag_result;

const char *lag_result_string(lag_result r);

/* ---------------------------------------------------------------- models */
typedef enum lag_model_kind {
    LAG_MODEL_STICK = 0,       /* q = (x, phi)                  */
    LAG_MODEL_MANIPULATOR = 1, /* q = (q1, q2)                  */
    LAG_MODEL_DIPC = 2,        /* q = (theta0, theta1, theta2)  */
    LAG_MODEL_COUNT
} lag_model_kind;

/* Parameter indices into lag_model.p, named as in the brief. */
enum { LAG_STICK_M, LAG_STICK_L, LAG_STICK_I, LAG_STICK_G, LAG_STICK_NP };
enum { LAG_MANIP_M1, LAG_MANIP_M2, LAG_MANIP_L1, LAG_MANIP_I1, LAG_MANIP_I2, LAG_MANIP_G,
       LAG_MANIP_NP };
enum { LAG_DIPC_M0, LAG_DIPC_M1, LAG_DIPC_M2, LAG_DIPC_L1, LAG_DIPC_L2, LAG_DIPC_I1,
       LAG_DIPC_I2, LAG_DIPC_G, LAG_DIPC_H0, LAG_DIPC_NP };

/* Static facts about a model kind. */
typedef struct lag_model_info {
    const char *name;                          /* "stick", "manipulator", "dipc" */
    int nq;                                    /* number of generalized coordinates */
    int np;                                    /* number of parameters */
    const char *param_names[LAG_MAX_PARAMS];   /* "m", "l", "I", "g", ... */
    double param_defaults[LAG_MAX_PARAMS];     /* SI units; NaN = uniform rod m l^2/12 */
    const char *param_units[LAG_MAX_PARAMS];   /* "kg", "m", "kg m^2", "m/s^2" */
    const char *joint_names[LAG_MAX_DOF];      /* "x", "phi", ... */
    bool actuated[LAG_MAX_DOF];                /* which coordinates take an input */
    bool angular[LAG_MAX_DOF];                 /* rad (true) or m (false) */
} lag_model_info;

const lag_model_info *lag_model_info_get(lag_model_kind kind);
/* Returns the kind for a name, or -1. */
int lag_model_kind_from_name(const char *name);

typedef struct lag_model {
    lag_model_kind kind;
    int nq;
    double p[LAG_MAX_PARAMS];
} lag_model;

/* Fills m with the kind's defaults, finished (see lag_model_finish). */
void lag_model_default(lag_model *m, lag_model_kind kind);
/* Fills m with the kind's defaults but leaves the inertias of uniform rods (stick I,
 * DIPC I1, I2) as NaN = "not given": a loader overrides what the scene names, then
 * calls lag_model_finish, which sets each inertia still NaN to m l^2 / 12 of its rod. */
void lag_model_default_unfinished(lag_model *m, lag_model_kind kind);
void lag_model_finish(lag_model *m);
/* Checks every parameter (finite; masses, lengths, inertias > 0; g >= 0 finite).
 * Returns LAG_ERR_ARG with a message naming the parameter. */
lag_result lag_model_validate(const lag_model *m, char *err, size_t errlen);
/* Index of parameter `name` for this kind, or -1. */
int lag_model_param_index(lag_model_kind kind, const char *name);

/* Mass matrix M(q), n x n, from T = 1/2 qd^T M(q) qd. OUT: M */
void lag_model_mass(const lag_model *m, const double *q, double *M);
/* Partial derivatives dM[k*n*n + i*n + j] = d M_ij / d q_k. OUT: dM (n*n*n) */
void lag_model_mass_deriv(const lag_model *m, const double *q, double *dM);
/* Coriolis/centrifugal matrix in Christoffel-symbol form,
 * C_kj = sum_i c_ijk qd_i, c_ijk = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k). OUT: C */
void lag_model_coriolis(const lag_model *m, const double *q, const double *qd, double *C);
/* Gravity vector g(q) = dU/dq. OUT: g */
void lag_model_gravity(const lag_model *m, const double *q, double *g);
/* Bias h = C(q,qd) qd + g(q), the cheap path used by the step. OUT: h */
void lag_model_bias(const lag_model *m, const double *q, const double *qd, double *h);
double lag_model_kinetic(const lag_model *m, const double *q, const double *qd);
double lag_model_potential(const lag_model *m, const double *q);
/* Forward dynamics: solves M(q) qdd = tau - C qd - g by Cholesky.
 * tau may be NULL (zero). Returns LAG_ERR_SINGULAR if M is not numerically SPD. OUT: qdd */
lag_result lag_model_forward(const lag_model *m, const double *q, const double *qd,
                             const double *tau, double *qdd);

/* ---------------------------------------------------------------- integrators */
typedef enum lag_method {
    LAG_EULER = 0,             /* explicit Euler, order 1 */
    LAG_SEMI_IMPLICIT_EULER,   /* qd += h qdd(q, qd); q += h qd_new, order 1 */
    LAG_RK4,                   /* classical Runge-Kutta, order 4 */
    LAG_DOPRI5,                /* Dormand-Prince 5(4), adaptive, dense output, order 5 */
    LAG_IMPLICIT_MIDPOINT,     /* 1-stage Gauss, symplectic in (q, p), order 2 */
    LAG_GAUSS4,                /* 2-stage Gauss-Legendre, symplectic in (q, p), order 4 */
    LAG_METHOD_COUNT
} lag_method;

const char *lag_method_name(lag_method m); /* "euler", "semi-implicit-euler", ... */
int lag_method_from_name(const char *name); /* -1 if unknown */
int lag_method_order(lag_method m);

typedef struct lag_integrator_def {
    lag_method method; /* default rk4 */
    double dt;         /* s; the step of fixed-step methods, the tick of dopri5. default 1e-3 */
    double rtol;       /* dopri5 relative tolerance, default 1e-8 */
    double atol;       /* dopri5 absolute tolerance, default 1e-10 */
    double dt_min;     /* dopri5 smallest step before LAG_ERR_STEPSIZE, default 1e-12 */
    int max_iter;      /* implicit methods: Newton iterations per step, default 20 */
    double newton_tol; /* implicit methods: convergence on the scaled update, default 1e-13 */
} lag_integrator_def;

lag_integrator_def lag_default_integrator_def(void);

/* ---------------------------------------------------------------- simulation */
typedef struct lag_sim_def {
    lag_model model;
    lag_integrator_def integrator;
    double q0[LAG_MAX_DOF];   /* initial positions */
    double qd0[LAG_MAX_DOF];  /* initial velocities */
    double explode_limit;     /* a step whose |q_i| or |qd_i| exceeds this is a fault; 1e6 */
} lag_sim_def;

/* Model kind's defaults, rk4 at 1 ms, at rest at q = 0. */
lag_sim_def lag_default_sim_def(lag_model_kind kind);
/* Validates the whole definition (model, integrator, initial state). */
lag_result lag_sim_def_validate(const lag_sim_def *def, char *err, size_t errlen);

/* Counters, for status and benchmarks. */
typedef struct lag_sim_stats {
    int64_t rhs_evals;        /* forward-dynamics evaluations */
    int64_t steps_accepted;   /* integrator steps (dopri5: accepted adaptive steps) */
    int64_t steps_rejected;   /* dopri5 rejected steps */
    int64_t newton_iters;     /* implicit methods: total Newton iterations */
    int64_t faults;           /* steps refused for a numeric fault */
} lag_sim_stats;

/* The mutable simulation. Sim time is tick * dt, computed, never accumulated. */
typedef struct lag_sim {
    lag_sim_def def;
    int nq;
    int64_t tick;                 /* number of dt ticks taken */
    double q[LAG_MAX_DOF];
    double qd[LAG_MAX_DOF];
    double tau[LAG_MAX_DOF];      /* input held over the next ticks (zero where unactuated) */
    lag_sim_stats stats;
    /* dopri5 internals: internal time/state may run ahead of the public one in
     * continuous mode (dense output gives the public state). */
    struct {
        double h;                  /* next step size to try */
        double t;                  /* internal time */
        double y[LAG_MAX_STATE];   /* internal state at t */
        double k1[LAG_MAX_STATE];  /* f(t, y) (FSAL) */
        double t_prev;             /* start of the last accepted step */
        double rcont[5][LAG_MAX_STATE]; /* dense-output coefficients of the last step */
        bool valid;                /* internal state valid and continuous with public */
    } dp;
} lag_sim;

lag_result lag_sim_init(lag_sim *s, const lag_sim_def *def, char *err, size_t errlen);
/* Resets to (q, qd) at tick 0 (NULL: the definition's initial state); input to zero. */
void lag_sim_reset(lag_sim *s, const double *q, const double *qd);
/* Sets the held input tau (n entries; entries of unactuated coordinates are ignored
 * and stored as zero). */
void lag_sim_set_input(lag_sim *s, const double *tau);
/* Advances n ticks (n * dt) with the held input. On error the public state is that of
 * the last good tick and the error is returned; stats.faults counts it.
 * continuous: for dopri5 only, the integrator may step past the end and deliver the
 * end state by dense output (valid while the input stays the same); otherwise the last
 * step is shortened to land on the end exactly. Fixed-step methods ignore it. */
lag_result lag_sim_advance(lag_sim *s, int64_t n, bool continuous);
double lag_sim_time(const lag_sim *s);
double lag_sim_energy(const lag_sim *s); /* T + U at the public state */

/* Right-hand side of the first-order system y = (q, qd): ydot = (qd, qdd) with the
 * sim's held input. Exposed for tests and benchmarks. OUT: ydot (2n) */
lag_result lag_sim_rhs(lag_sim *s, const double *y, double *ydot);

#ifdef __cplusplus
}
#endif
#endif
