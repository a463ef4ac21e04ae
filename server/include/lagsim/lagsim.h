/*
 * lagsim core: Lagrangian models and integrators, each kept in a table of the core's
 * (lag_model_info_get, lag_method_info_get: kinds 0..LAG_MODEL_COUNT-1, methods
 * 0..LAG_METHOD_COUNT-1), effects (lag_effect_info_get), and a simulation state.
 *
 * The core knows nothing of LCM or YAML. A model is read-only (`const lag_model*`), a
 * simulation (`lag_sim`) is the mutable state; no function here allocates memory, prints,
 * or exits. Errors are result codes; functions that can fail for a reason worth telling
 * write a message into a caller's buffer.
 *
 * Coordinates, T and U are those of docs/models.md; units are SI (m, kg, s, rad, N, N m).
 * Matrices are row-major, n x n with n = model->nq (at most LAG_MAX_DOF).
 *
 * Not a stable ABI: the core is a static library for lagsim's own programs, tests and
 * benchmarks, and its structs (lag_sim, lag_model, ...) change with it. Programs outside
 * the tree talk to a plant through the client library (lagsim_client.h), whose ABI is
 * kept (docs/clients.md, "The ABI").
 */
#ifndef LAGSIM_LAGSIM_H
#define LAGSIM_LAGSIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "lagsim/result.h"
#include "lagsim/version.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The core's lagsim version, LAGSIM_VERSION_NUMBER as it was built (lagsim/version.h). */
int lag_version(void);

#define LAG_MAX_DOF 3
#define LAG_MAX_STATE (2 * LAG_MAX_DOF)
#define LAG_MAX_PARAMS 12

/* ---------------------------------------------------------------- result codes */
/* lag_result, its names, sentences and exit statuses: lagsim/result.h (one space for the
 * core, the scene loader, the client library and the programs). The core returns LAG_OK,
 * LAG_ERR_ARG and the numeric faults LAG_ERR_SINGULAR .. LAG_ERR_MAX_STEPS. */

/* What is wrong with a definition, for a loader to point at (SQLite's habit of a message
 * on the caller's side, plus where): `field` is the path of the offending value in the
 * scene file's own terms, so a loader that keeps the position of each key can attach its
 * file:line:column to the core's message instead of checking the value twice. Grammar:
 * keys joined by '.', a sequence index as [i]; values kept per joint are named by the
 * joint's name (lag_model_info.joint_names):
 *   model                               the model kind, or its number of coordinates
 *   parameters.<name>                   lag_model_info.param_names, e.g. parameters.m1
 *   initial.q[i], initial.qd[i]         initial.q when the fault is of the whole vector
 *   integrator.<key>                    method, dt, rtol, atol, dt_min, max_iter, max_steps,
 *                                       newton_tol
 *   explode_limit
 *   effects                             the set of effects itself (unknown bits)
 *   effects.<effect>...                 a setting of an effect of the table, by its scene
 *                                       key: .<joint> (one number per joint, e.g.
 *                                       effects.damping.theta1), .<joint>.<key>
 *                                       (effects.friction.x.static), .<key>
 *                                       (effects.floor.restitution), [k].<key>
 *                                       (effects.disturbance[0].t), .<key>.<joint>
 *                                       (effects.noise.q.phi); the keys of each:
 *                                       docs/scenes.md, "Numbers and their ranges"
 * `field` is "" when no single value is at fault. `message` says what is expected and
 * what was found, without repeating the field. */
#define LAG_FIELD_MAX 64
#define LAG_MESSAGE_MAX 192
typedef struct lag_diag {
    char field[LAG_FIELD_MAX];
    char message[LAG_MESSAGE_MAX];
} lag_diag;

/* ---------------------------------------------------------------- models */
typedef enum lag_model_kind {
    LAG_MODEL_STICK = 0,       /* q = (x, phi)                  */
    LAG_MODEL_MANIPULATOR = 1, /* q = (q1, q2)                  */
    LAG_MODEL_DIPC = 2,        /* q = (theta0, theta1, theta2)  */
    LAG_MODEL_CARTPOLE = 3,    /* q = (x, theta)                */
    LAG_MODEL_FLYING_STICK = 4, /* q = (x, phi, h): the stick free in the plane, h the
                                   height of one end (the stick's floor flies it) */
    LAG_MODEL_COUNT
} lag_model_kind;

/* Parameter indices into lag_model.p, named as in docs/models.md. */
enum { LAG_STICK_M, LAG_STICK_L, LAG_STICK_I, LAG_STICK_G, LAG_STICK_NP };
/* The flying stick has the stick's parameters; p[LAG_FSTICK_END] is not a parameter a
 * scene gives but which end h measures: 0 end A (at r_c - l/2 (cos phi, sin phi), the end
 * the stick model stands on), 1 end B (the other). A run never writes it: a sim whose
 * floor switches ends keeps the end in its state (lag_sim.mode.floor_end; the model with
 * that end: lag_sim_dynamics). */
enum { LAG_FSTICK_END = LAG_STICK_NP };
enum { LAG_MANIP_M1, LAG_MANIP_M2, LAG_MANIP_L1, LAG_MANIP_I1, LAG_MANIP_I2, LAG_MANIP_G,
       LAG_MANIP_NP };
enum { LAG_DIPC_M0, LAG_DIPC_M1, LAG_DIPC_M2, LAG_DIPC_L1, LAG_DIPC_L2, LAG_DIPC_I1,
       LAG_DIPC_I2, LAG_DIPC_G, LAG_DIPC_H0, LAG_DIPC_NP };

/* What values a parameter may take; every parameter must be finite. The zero value is
 * the strictest, so a rule left out of a table is "positive". */
typedef enum lag_param_rule {
    LAG_PARAM_POSITIVE = 0, /* > 0: masses, lengths, inertias */
    LAG_PARAM_NONNEGATIVE,  /* >= 0: g (0 switches gravity off) */
    LAG_PARAM_ANY           /* any finite number: heights, offsets */
} lag_param_rule;

/* A uniform rod: parameter `inertia` defaults to m l^2 / 12 of parameters `mass` and
 * `length` (its inertia about its centre), computed when the model is finished. */
typedef struct lag_rod {
    int inertia, mass, length; /* parameter indices */
} lag_rod;
#define LAG_MAX_RODS LAG_MAX_DOF

/* Static facts about a model kind: everything a loader, a client or a test needs to
 * know about its coordinates and parameters, as data. */
typedef struct lag_model_info {
    const char *name;                          /* "stick", "manipulator", "dipc", ... */
    int nq;                                    /* number of generalized coordinates */
    int np;                                    /* number of parameters */
    const char *param_names[LAG_MAX_PARAMS];   /* "m", "l", "I", "g", ... */
    double param_defaults[LAG_MAX_PARAMS];     /* SI units; NaN: a rod's inertia (rods) */
    const char *param_units[LAG_MAX_PARAMS];   /* "kg", "m", "kg m^2", "m/s^2" */
    lag_param_rule param_rules[LAG_MAX_PARAMS];
    int n_rods;                                /* uniform-rod inertia defaults */
    lag_rod rods[LAG_MAX_RODS];
    const char *joint_names[LAG_MAX_DOF];      /* "x", "phi", ... */
    bool actuated[LAG_MAX_DOF];                /* which coordinates take an input */
    bool angular[LAG_MAX_DOF];                 /* rad (true) or m (false) */
} lag_model_info;

/* The facts of a kind, or NULL for a kind outside 0..LAG_MODEL_COUNT-1. Loaders and
 * tests iterate kinds 0..LAG_MODEL_COUNT-1: a model added to the core's table is then
 * known to them by name without another list. */
const lag_model_info *lag_model_info_get(lag_model_kind kind);
/* The first model whose joints are names[0..n-1], in order, or NULL: how a tool that has
 * only a scene description (joint names) finds each joint's unit (angular) and actuation.
 * (A stick that may fly publishes the flying stick's x, phi, h.) */
const lag_model_info *lag_model_info_by_joints(const char *const *names, int n);
/* Returns the kind for a name, or -1. */
int lag_model_kind_from_name(const char *name);
/* Every model's name, in the table's order, joined by ", " (the first of the table's
 * kinds: "stick, manipulator, ..."), for messages and --help. Returns buf; truncated to
 * len - 1 characters when that is too small. */
const char *lag_model_names(char *buf, size_t len);

typedef struct lag_model {
    lag_model_kind kind;
    int nq;
    double p[LAG_MAX_PARAMS];
} lag_model;

/* Fills m with the kind's defaults, finished (see lag_model_finish). */
void lag_model_default(lag_model *m, lag_model_kind kind);
/* Fills m with the kind's defaults but leaves the inertias of uniform rods (info.rods:
 * stick I, DIPC I1, I2) as NaN = "not given": a loader overrides what the scene names,
 * then calls lag_model_finish, which sets each inertia still NaN to m l^2 / 12 of its
 * rod. */
void lag_model_default_unfinished(lag_model *m, lag_model_kind kind);
void lag_model_finish(lag_model *m);
/* Checks every parameter against its rule (info.param_rules; all finite). Returns
 * LAG_ERR_ARG and fills d (see lag_diag; field "parameters.<name>"). OUT: d */
lag_result lag_model_check(const lag_model *m, lag_diag *d);
/* The same, with "field: message" written into err. */
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

/* Static facts about a method: what a loader, a benchmark or a test may rely on without
 * naming the method (tests iterate methods 0..LAG_METHOD_COUNT-1 and use these). */
typedef struct lag_method_info {
    const char *name;  /* "euler", "semi-implicit-euler", "rk4", ... */
    int order;         /* global order of accuracy */
    bool adaptive;     /* steps chosen by rtol, atol, dt_min, max_steps; dt is the tick */
    bool implicit;     /* stage equations solved by Newton (max_iter, newton_tol) */
    bool canonical;    /* steps (q, p), p = M(q) qd: symplectic, and a linear function of
                          (q, p) that is invariant (the momentum of a cyclic coordinate)
                          is kept to the Newton tolerance */
} lag_method_info;

/* NULL for a method outside 0..LAG_METHOD_COUNT-1. */
const lag_method_info *lag_method_info_get(lag_method m);
const char *lag_method_name(lag_method m); /* "euler", ...; "unknown" outside the table */
int lag_method_from_name(const char *name); /* -1 if unknown */
int lag_method_order(lag_method m);         /* 0 outside the table */
/* "euler, semi-implicit-euler, ...": every method's name, for messages. Returns buf. */
const char *lag_method_names(char *buf, size_t len);

typedef struct lag_integrator_def {
    lag_method method; /* default rk4 */
    double dt;         /* s; the step of fixed-step methods, the tick of dopri5. default 1e-3 */
    double rtol;       /* dopri5 relative tolerance, default 1e-8 */
    double atol;       /* dopri5 absolute tolerance, default 1e-10 */
    double dt_min;     /* dopri5 smallest step before LAG_ERR_STEPSIZE, default 1e-12 */
    int max_iter;      /* implicit methods: Newton iterations per step, default 20 */
    int max_steps;     /* dopri5: steps (accepted or rejected) per tick before
                          LAG_ERR_MAX_STEPS, so that a tick's work is bounded whatever dt
                          and the tolerances ask for (Hairer's NMAX); default 100000 */
    double newton_tol; /* implicit methods: convergence on the scaled update, default 1e-13 */
} lag_integrator_def;

lag_integrator_def lag_default_integrator_def(void);

/* ---------------------------------------------------------------- effects
 * Each effect is off unless its bit is set in lag_effects_def.enabled; an effect that is
 * off is never called (MuJoCo's enable flags). Gravity is the model parameter g (0 = off).
 * Units: forces N on linear coordinates, N m on angles (the coordinate's generalized force).
 * The core keeps them in one table (lag_effect_info_get lists it, by row; a row's bit is
 * its own, the rows' order is that in which the step applies them).
 */
enum {
    LAG_EFF_DAMPING = 1u << 0,     /* Q_i = -b_i qd_i                                       */
    LAG_EFF_FRICTION = 1u << 1,    /* Coulomb per joint: stick while |force| <= mu_s, else   */
                                   /* slide against the motion with mu_k (hybrid modes)      */
    LAG_EFF_LIMITS = 1u << 2,      /* per-joint stops located in time, restitution impulse   */
    LAG_EFF_FLOOR = 1u << 3,       /* stick only: its ends on a frictionless floor at y = 0:  */
                                   /* impacts, resting contact, lift-off into flight and     */
                                   /* landing (floor_flight), or lift-off as a fault         */
                                   /* (LAG_ERR_LIFTOFF) without flight                       */
    LAG_EFF_ACTUATOR = 1u << 4,    /* per-input saturation and first-order lag              */
    LAG_EFF_DISTURBANCE = 1u << 5, /* scheduled impulses / forces                          */
    LAG_EFF_NOISE = 1u << 6,       /* Gaussian noise on the published state only            */
    LAG_EFF_SPRING = 1u << 7       /* Q_i = -k_i (q_i - rest_i), storing 1/2 k_i (q_i -      */
                                   /* rest_i)^2, which lag_sim_energy includes              */
};
#define LAG_EFF_COUNT 8

/* Static facts about an effect, from the core's table: its bit, its name (the scene's
 * key), and what it takes part in (which follows from what it does). */
typedef struct lag_effect_info {
    uint32_t bit;    /* LAG_EFF_*; 0 for an index outside the table */
    const char *name; /* "damping", "friction", ...; NULL outside the table */
    bool force;      /* adds a generalized force to the equations of motion */
    bool potential;  /* stores energy: part of lag_sim_energy */
    bool per_tick;   /* works at every tick boundary (the step stops at each) */
    bool events;     /* has events located in time within a tick */
    bool observe;    /* changes the published state only */
    bool keeps_state; /* may keep state of its own from tick to tick that q, qd, tick and
                         the definition do not hold (contact and stick/slip modes: limits,
                         floor, friction; the actuator's lag state, only while a lag is
                         set): a run restarted from a logged (q, qd, tick) is then not the
                         same run. Whether it does under given settings:
                         lag_effects_keeping_state */
} lag_effect_info;

/* The table's row `index` of 0..LAG_EFF_COUNT-1 (a zeroed struct outside). */
lag_effect_info lag_effect_info_get(int index);
/* Index of the effect named `name`, or -1. */
int lag_effect_from_name(const char *name);
#define LAG_MAX_DISTURBANCES 16

/* The largest magnitude of a disturbance's impulse (N s or N m s) or force (N or N m), and
 * of every force-like value of a scene: far beyond any load these models are meant for (a
 * 1e6 kg mass under 1e3 m/s^2 weighs 1e9 N), small enough that accelerations and energies
 * computed from it stay finite. */
#define LAG_FORCE_MAX 1e12
/* The longest sim time a disturbance (its t, a force's duration) or a scene may name:
 * about 31.7 years. With a dt >= 1e-6 s any such time is at most 1e15 ticks, an exact
 * integer in a double far from int64's limit, so no conversion to ticks can overflow. */
#define LAG_TIME_MAX 1e9

typedef struct lag_disturbance {
    double t;        /* sim time it starts, s (applied at the tick boundary at or after t) */
    int joint;       /* coordinate index */
    bool impulse;    /* true: generalized impulse `value` (N s or N m s) at t;
                        false: force `value` held over [t, t + duration) */
    double value;
    double duration; /* s, forces only */
} lag_disturbance;

typedef struct lag_effects_def {
    uint32_t enabled;                       /* LAG_EFF_* bits */
    double damping[LAG_MAX_DOF];            /* b_i >= 0 (N s/m or N m s/rad) */
    double friction_static[LAG_MAX_DOF];    /* mu_s,i >= mu_k,i: largest holding force */
    double friction_kinetic[LAG_MAX_DOF];   /* mu_k,i >= 0: sliding force magnitude */
    bool limit_on[LAG_MAX_DOF];             /* which joints have stops */
    double limit_lower[LAG_MAX_DOF];        /* m or rad */
    double limit_upper[LAG_MAX_DOF];
    double restitution[LAG_MAX_DOF];        /* e in [0, 1] at that joint's stops */
    double floor_restitution;               /* stick: e in [0, 1] when the stick lands */
    bool floor_flight;                      /* stick: when the normal force reaches zero
                                               the stick flies (true, the default) and
                                               lands again; false: LAG_ERR_LIFTOFF */
    double rest_velocity;                   /* impacts slower than this (m/s, rad/s) end in
                                               resting contact: the Zeno guard. default 1e-3 */
    double actuator_max[LAG_MAX_DOF];       /* |effort_i| <= max (INFINITY: no saturation) */
    double actuator_tau[LAG_MAX_DOF];       /* first-order lag time constant, s (0: none) */
    int n_disturbances;
    lag_disturbance disturbances[LAG_MAX_DISTURBANCES];
    double noise_q[LAG_MAX_DOF];            /* std dev of noise on published q */
    double noise_qd[LAG_MAX_DOF];           /* std dev of noise on published qd */
    uint64_t noise_seed;
    double spring_k[LAG_MAX_DOF];           /* k_i >= 0 (N/m or N m/rad) */
    double spring_rest[LAG_MAX_DOF];        /* rest position (m or rad) */
} lag_effects_def;

/* The bits of the effects enabled in e that keep state of their own under e's settings
 * (lag_effect_info.keeps_state: a mode, or an actuator with a lag time > 0): 0 when a run
 * restarted from its (q, qd, tick) goes on as the run itself did. */
uint32_t lag_effects_keeping_state(const lag_effects_def *e);

/* All effects off, neutral parameters (no saturation, no lag, rest_velocity 1e-3, a
 * floor the stick may leave). */
lag_effects_def lag_default_effects_def(void);

/* Something the step noticed, recorded with its sim time (see lag_sim_poll_event). */
typedef enum lag_event_kind {
    LAG_EV_LIMIT = 1,    /* a stop was hit; value = impact velocity */
    LAG_EV_IMPACT,       /* the stick hit the floor and bounced: its free end (joint phi,
                            value = impact phi_dot), or in flight an end (joint h, value =
                            that end's vertical velocity, m/s) */
    LAG_EV_REST,         /* an impact slower than rest_velocity: resting contact begins */
    LAG_EV_RELEASE,      /* a resting contact ends (the force pulls away) */
    LAG_EV_STICK,        /* friction: the joint stopped and static friction holds it */
    LAG_EV_SLIP,         /* friction: the joint starts or keeps sliding; value = direction */
    LAG_EV_LIFTOFF,      /* stick: normal force reached zero: it flies from here (joint
                            h), or without flight the model no longer holds (a fault) */
    LAG_EV_SATURATION,   /* an actuator hit its limit; value = commanded effort */
    LAG_EV_DISTURBANCE,  /* a scheduled disturbance was applied; value = its value */
    LAG_EV_EVENT_LIMIT,  /* more events in one tick than the engine handles: rest of the
                            tick taken without event location (a warning) */
    LAG_EV_LANDING       /* stick: an end reached the floor from flight and stays on it
                            (sliding contact); joint h, value = its vertical velocity */
} lag_event_kind;

typedef struct lag_event {
    lag_event_kind kind;
    int joint;      /* coordinate index, -1 if none */
    double t;       /* sim time, s */
    double value;
} lag_event;

const char *lag_event_kind_name(lag_event_kind k); /* "limit", "impact", ... */

/* ---------------------------------------------------------------- simulation */
typedef struct lag_sim_def {
    lag_model model;
    lag_integrator_def integrator;
    lag_effects_def effects;
    double q0[LAG_MAX_DOF];   /* initial positions, of the model's joints; a stick whose
                                 floor lets it fly also has h = q0[2] >= 0, the height of
                                 its lower end (0: on the floor) */
    double qd0[LAG_MAX_DOF];  /* initial velocities (and h_dot = qd0[2]) */
    double explode_limit;     /* a step whose |q_i| or |qd_i| exceeds this is a fault; 1e6 */
} lag_sim_def;

/* Model kind's defaults, rk4 at 1 ms, at rest at q = 0. */
lag_sim_def lag_default_sim_def(lag_model_kind kind);
/* Validates the whole definition (model, integrator, effects, initial state). Returns
 * LAG_ERR_ARG and fills d with the first fault found (see lag_diag). OUT: d */
lag_result lag_sim_def_check(const lag_sim_def *def, lag_diag *d);
/* The same, with "field: message" written into err (what lag_sim_init reports). */
lag_result lag_sim_def_validate(const lag_sim_def *def, char *err, size_t errlen);

/* The one check of a disturbance, whether a scene's schedule, a change made while running
 * or a kick asks for it (lag_effects_check calls it for each of def's; the scene loader
 * reports its message at the key, the daemon on the bus): t in [0, LAG_TIME_MAX]; joint
 * one of def's model's; an impulse has no duration; a force is held for a duration from
 * def's integrator.dt (a force acts over whole ticks: a shorter push is an impulse) to
 * LAG_TIME_MAX; the value a number of magnitude at most LAG_FORCE_MAX. Returns LAG_OK, or
 * LAG_ERR_ARG with d's field `at`.<key> (key: t, joint, duration, impulse or force; the key
 * alone when `at` is NULL or ""). OUT: d */
lag_result lag_disturbance_check(const lag_sim_def *def, const lag_disturbance *dist,
                                 const char *at, lag_diag *d);
/* The joint of def's model named `name`, for a disturbance: its index in *joint, or
 * LAG_ERR_ARG with field `at`.joint and the words that name the model's joints. OUT: joint, d */
lag_result lag_disturbance_joint(const lag_sim_def *def, const char *name, const char *at,
                                 int *joint, lag_diag *d);

/* What the last refused tick ran into (see lag_sim_fault_describe). */
typedef struct lag_fault {
    lag_result code;  /* LAG_OK until a tick is refused */
    int64_t tick;     /* the tick that was refused (the state is that of its start) */
    int joint;        /* LAG_ERR_FORCE: the coordinate that one tick takes furthest past
                         explode_limit; else -1 */
    double accel;     /* LAG_ERR_FORCE: its acceleration at the tick's start (m/s^2, rad/s^2) */
    double velocity;  /* LAG_ERR_FORCE: its velocity there (after any impulse) */
    int cause;        /* LAG_ERR_FORCE: the coordinate whose applied force contributes most
                         to that acceleration, -1 if none does (an impulse's velocity) */
    double force;     /* LAG_ERR_FORCE: that generalized force (N, N m) */
} lag_fault;

/* Counters, for status and benchmarks. */
typedef struct lag_sim_stats {
    int64_t rhs_evals;        /* forward-dynamics evaluations */
    int64_t steps_accepted;   /* integrator steps (dopri5: accepted adaptive steps) */
    int64_t steps_rejected;   /* dopri5 rejected steps */
    int64_t newton_iters;     /* implicit methods: total Newton iterations */
    int64_t faults;           /* steps refused for a numeric fault */
} lag_sim_stats;

struct lag_model_class; /* the core's own (core_internal.h) */

/* The mutable simulation. Sim time is tick * dt, computed, never accumulated. */
typedef struct lag_sim {
    lag_sim_def def;
    /* The model integrated and its coordinates q[0..nq-1]: def.model, except for a stick
     * whose floor lets it fly: the flying stick (x, phi, h), h the height of the end of
     * mode.floor_end, held at h = 0 (a resting stop) while that end is on the floor.
     * Read-only data after lag_sim_init (a redefinition replaces it): what changes while
     * running is the sim's state below. */
    lag_model model;
    /* The closed forms integrated (the core's own): model's row of the core's model table,
     * or the flying stick measured from mode.floor_end. */
    const struct lag_model_class *dyn;
    int nq;
    int64_t tick;                 /* number of dt ticks taken */
    double q[LAG_MAX_DOF];
    double qd[LAG_MAX_DOF];
    double tau[LAG_MAX_DOF];      /* input held over the next ticks (zero where unactuated) */
    double tau_applied[LAG_MAX_DOF]; /* effort actually applied over the last tick: the
                                        actuator's output after lag and saturation (not the
                                        disturbance forces, which are external); what
                                        joint_state_t.effort reports */
    lag_sim_stats stats;
    lag_fault fault;              /* the last refused tick, if any */
    /* effects' hybrid modes */
    struct {
        uint32_t locked;           /* bit i: joint i held (static friction or resting stop) */
        int8_t lock_side[LAG_MAX_DOF]; /* -1 at lower stop, +1 at upper, 0 friction stick */
        int8_t slip_dir[LAG_MAX_DOF];  /* friction: direction of sliding, 0 if stuck */
        double act_state[LAG_MAX_DOF]; /* actuator lag state */
        bool saturated[LAG_MAX_DOF];
        double dist_force[LAG_MAX_DOF]; /* disturbance forces held over this tick */
        uint32_t released;         /* bit i: the floor's hold of joint i let go at this
                                      instant (not a landing again before a step) */
        int8_t floor_end;          /* the floor with flight: the end h measures (0: end A,
                                      1: end B; see LAG_FSTICK_END) */
    } mode;
    /* The effect table's rows that the enabled effects use, per hook, in table order: made
     * once by lag_sim_init from def.effects.enabled, so that the step calls those rows
     * only (the definition must not change after init). */
    struct {
        uint32_t enabled;   /* def.effects.enabled when made */
        uint32_t per_tick;  /* enabled effects with per-tick work or watchers */
        uint8_t n_force, n_pre_tick, n_watch, n_potential, n_observe;
        uint8_t force[LAG_EFF_COUNT], pre_tick[LAG_EFF_COUNT], watch[LAG_EFF_COUNT],
            potential[LAG_EFF_COUNT], observe[LAG_EFF_COUNT];
    } fx;
    /* events recorded by the step, oldest first; lag_sim_poll_event drains them */
    lag_event events[32];
    int n_events;
    int64_t events_dropped;
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
        double h_max;              /* 0, or the largest step (lag_sim_shadow_error's copy) */
    } dp;
} lag_sim;

lag_result lag_sim_init(lag_sim *s, const lag_sim_def *def, char *err, size_t errlen);
/* The joints the sim publishes, takes inputs on and is reset to: def.model's, or for a
 * stick whose floor lets it fly the flying stick's (x, phi, h), in every contact mode. */
const lag_model_info *lag_sim_info(const lag_sim *s);
/* Resets to (q, qd) at tick 0 (NULL: the definition's initial state); input to zero.
 * q and qd hold lag_sim_info's joints. A stick that can fly: h = q[2] is the height of
 * its lower end (the one below the centre: end B when sin phi < 0); with h and h_dot 0
 * that end is on the floor (sliding contact, left at once if the floor would have to
 * pull), else the stick flies. */
void lag_sim_reset(lag_sim *s, const double *q, const double *qd);
/* Changes the model's parameters and the effects' settings of a running simulation,
 * keeping its state, tick, input and initial state: the run goes on as a run of the new
 * definition started from the current state. def must have the same model kind,
 * integrator settings and explode_limit (else LAG_ERR_ARG: those do not change while
 * running) and must pass lag_sim_def_check with the current state as its initial state
 * (a stop must not exclude where the joint is, ...): else LAG_ERR_ARG and nothing
 * changed, with "where the run is now, <what is wrong>" in err for the state (e.g. "where
 * the run is now, q2 = 0.7 is outside its limits [0.1, 0.5]") and "field: message" else. The effects' holds (a joint at rest on a stop or
 * held by static friction) are derived again from the state, as at a reset; a newly
 * switched-on actuator starts from the effort applied now; dopri5 restarts its step. */
lag_result lag_sim_redefine(lag_sim *s, const lag_sim_def *def, char *err, size_t errlen);
/* The model whose closed forms the sim integrates now: s->model, with p[LAG_FSTICK_END]
 * the end h measures for a flying stick (mode.floor_end). A copy, for tools and tests
 * that evaluate the model at the sim's state (its energy, ...). OUT: m */
void lag_sim_dynamics(const lag_sim *s, lag_model *m);
/* The stick's contact with its floor, for status: "flight" (no end on it), "contact" (an
 * end on it, sliding), "flat" (lying on it: both ends held); "" without a floor that lets
 * it fly. */
const char *lag_sim_contact(const lag_sim *s);
/* Sets the held input tau (s->nq entries, lag_sim_info's joints; entries of unactuated
 * coordinates are ignored and stored as zero). */
void lag_sim_set_input(lag_sim *s, const double *tau);
/* Advances n ticks (n * dt) with the held input. On error the public state is that of
 * the last good tick and the error is returned; stats.faults counts it.
 * continuous: for dopri5 only, the integrator may step past the end and deliver the
 * end state by dense output (valid while the input stays the same); otherwise the last
 * step is shortened to land on the end exactly. Fixed-step methods ignore it. */
lag_result lag_sim_advance(lag_sim *s, int64_t n, bool continuous);
/* Advances n ticks of a span over which the input holds until tick `stop` (taken as
 * tick + n when smaller): the steps are those of lag_sim_advance(s, stop - tick, false),
 * so a span advanced in such chunks ends bit-identical to one call for it. dopri5 steps
 * across the chunks' ends (dense output gives the state there) and lands on `stop`;
 * other methods step tick by tick and do not need it. */
lag_result lag_sim_advance_within(lag_sim *s, int64_t n, int64_t stop);
double lag_sim_time(const lag_sim *s);
/* Time to tick counts, for a tick of dt > 0: the core converts times to ticks only
 * through these three, and so should any other part (one rule, one tolerance). A time
 * within LAG_TICK_TOL ticks (LAG_TICK_TOL dt) of a boundary counts as on it: the rounding
 * of t = k dt, computed or read back from text. Saturated: a count past INT64_MAX (t =
 * 1e300, or NaN) gives INT64_MAX, a tick never reached; t <= 0 gives 0.
 * The tolerance is LAG_TICK_TOL of a tick whatever the count: past a few million ticks
 * the rounding of t / dt itself can pass it (lag_ticks_ceil(18.0405, 1e-6) is 18040501).
 * Two rules grow with the count and so do not call these: the loader's period check
 * (1/publish_hz = k dt within 1e-9 k) and a run's length in ticks (lagsimd's
 * rt_ticks_for, within 1e-12 of the count plus 1e-9); tests/structure/check_structure.py
 * (ticks) keeps every other conversion outside the core on these three. */
#define LAG_TICK_TOL 1e-9
/* The first tick boundary at or after t: ceil(t / dt), t just above a boundary on it
 * (when a disturbance starts; the ticks a run of t seconds takes). */
int64_t lag_ticks_ceil(double t, double dt);
/* The last tick boundary at or before t: floor(t / dt), t just below a boundary on it. */
int64_t lag_ticks_floor(double t, double dt);
/* Is t a whole number of ticks (within LAG_TICK_TOL of one, t >= 0 and finite, the count
 * below INT64_MAX)? Then *n (if not NULL) is that number: how many ticks a control period
 * takes. */
bool lag_ticks_exact(double t, double dt, int64_t *n);
/* T + U at the public state, plus the energy the scene's effects store (springs). */
double lag_sim_energy(const lag_sim *s);

/* One line on the last refused tick: the result, the sim time, and for LAG_ERR_FORCE the
 * joint, its force, acceleration and what one tick of it would do, e.g.
 *   "applied force too large: theta0 has 1e+308 N, an acceleration of 3.6e+307 m/s^2 that
 *    takes it past explode_limit = 1e+06 within one tick (dt = 0.001 s), at t = 0.5 s"
 * Writes "" when no tick was refused. */
void lag_sim_fault_describe(const lag_sim *s, char *buf, size_t len);

/* Right-hand side of the first-order system y = (q, qd): ydot = (qd, qdd) with the
 * sim's held input. Exposed for tests and benchmarks. OUT: ydot (2n) */
lag_result lag_sim_rhs(lag_sim *s, const double *y, double *ydot);

/* The live error estimate: what the steps over some ticks added to the error of q (m or
 * rad, per coordinate of lag_sim_info's joints). START is a copy of a sim taken before
 * the ticks and END the same sim after them (same input, START->tick < END->tick). A
 * scratch copy of START runs the same span again, more accurately, and
 *   err_i = |q_i(END) - q_i(shadow)| K / (K - 1):
 * a fixed-step method of order p with half the tick (step doubling, Richardson: K = 2^p);
 * dopri5 with rtol and atol divided by LAG_SHADOW_TOL_DIV and steps at most half as long
 * as END's were on average over the span (so that a step far within its tolerance, e.g.
 * one cut short to land on the span's end, is refined too; K = 2^5). Neither sim changes; no allocation (the scratch
 * copy is on the stack). LAG_ERR_ARG for a span that is not one or settings that differ;
 * else what the shadow ran into (err then zero). OUT: err (START->nq) */
#define LAG_SHADOW_TOL_DIV 1024.0
lag_result lag_sim_shadow_error(const lag_sim *start, const lag_sim *end, double *err);

/* Pops the oldest recorded event into ev; returns false when there is none. */
bool lag_sim_poll_event(lag_sim *s, lag_event *ev);
/* The state as published, lag_sim_info's joints (s->nq of them): the true state plus the
 * noise effect, if on (deterministic in (noise_seed, tick), so a replay reproduces it).
 * A stick that can fly publishes (x, phi, h), h the height of its lower end and h_dot
 * that end's vertical velocity (both 0 while an end is on the floor). OUT: q, qd */
void lag_sim_observe(const lag_sim *s, double *q, double *qd);

#ifdef __cplusplus
}
#endif
#endif
