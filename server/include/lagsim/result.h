/*
 * lagsim's result codes: one space for the core, the scene loader, the client library and
 * the programs, and the one place where a code becomes a program's exit status (SQLite's
 * habit: one list of codes, a name and a sentence for each, and a function from code to
 * what the caller does with it).
 *
 * LAG_OK is 0; a result that is no error but says something (LAG_TIMEOUT: nothing arrived
 * in time) is positive; every error is negative. So `rc != LAG_OK` is "not done" and
 * `rc < 0` is "failed", for every function of every part.
 *
 * The exit statuses a program can end with, and what they mean:
 *   0 done; 1 it ran and failed (a numeric fault, a difference above a tolerance, a run
 *   that missed a requirement, the daemon refused, LCM failed); 2 nothing ran: bad usage,
 *   a scene or an argument refused, a file that cannot be read or would be replaced;
 *   3 no answer (lagsimctl: no daemon answered within the timeout).
 * A program ends with `return lag_result_exit(rc)`; the man pages' EXIT STATUS sections
 * say the same (tests/result checks them against this table and the programs).
 */
#ifndef LAGSIM_RESULT_H
#define LAGSIM_RESULT_H

#ifdef __cplusplus
extern "C" {
#endif

/* The one table: X(code, value, exit status, sentence). A code added here has its name,
 * its sentence and its exit status by construction. */
#define LAG_RESULT_LIST(X)                                                                  \
    X(LAG_OK, 0, 0, "ok")                                                                   \
    X(LAG_TIMEOUT, 2, 1, "nothing arrived in time")                                        \
    X(LAG_ERR_ARG, -1, 2, "invalid argument")                                              \
    X(LAG_ERR_LCM, -2, 1, "LCM failed (create, publish or handle)")                        \
    X(LAG_ERR_NOMEM, -3, 1, "out of memory")                                               \
    X(LAG_ERR_AMBIGUOUS, -4, 2, "several plants could be meant")                           \
    X(LAG_ERR_SINGULAR, -5, 1, "mass matrix not positive definite")                        \
    X(LAG_ERR_NONFINITE, -6, 1, "non-finite state")                                        \
    X(LAG_ERR_EXPLODE, -7, 1, "state exceeded explode_limit")                              \
    X(LAG_ERR_NEWTON, -8, 1, "implicit solver (Newton) did not converge")                  \
    X(LAG_ERR_STEPSIZE, -9, 1, "adaptive step size fell below dt_min")                     \
    X(LAG_ERR_LIFTOFF, -10, 1, "stick lifted off the floor (normal force < 0)")            \
    X(LAG_ERR_FORCE, -11, 1, "applied force or impulse too large for one tick")            \
    X(LAG_ERR_MAX_STEPS, -12, 1,                                                           \
      "adaptive method needed more than max_steps steps for one tick")                     \
    X(LAG_ERR_USAGE, -13, 2, "bad usage")                                                  \
    X(LAG_ERR_SCENE, -14, 2, "scene refused")                                              \
    X(LAG_ERR_SYNTAX, -15, 2, "not a plain decimal number")                                \
    X(LAG_ERR_RANGE, -16, 2, "a number too large for a double")                            \
    X(LAG_ERR_FILE, -17, 2, "a file cannot be read, or would be replaced")                 \
    X(LAG_ERR_RUNTIME, -18, 1, "failed while running")                                     \
    X(LAG_ERR_MISMATCH, -19, 1, "the result is outside what was asked")                    \
    X(LAG_ERR_REFUSED, -20, 1, "the daemon refused the request")                           \
    X(LAG_ERR_NOANSWER, -21, 3, "no answer within the timeout")

/* What each code means where it is returned:
 *   LAG_TIMEOUT       nothing arrived in time (the client's waits; not an error)
 *   LAG_ERR_ARG       invalid argument or definition (the message says which)
 *   LAG_ERR_LCM       LCM could not be created, publish or handle failed
 *   LAG_ERR_AMBIGUOUS several plants could be meant (the message names them)
 *   LAG_ERR_SINGULAR  mass matrix not positive definite at this state
 *   LAG_ERR_NONFINITE a step produced NaN or Inf: state left unchanged
 *   LAG_ERR_EXPLODE   |q| or |qd| exceeded lag_sim_def.explode_limit: state unchanged
 *   LAG_ERR_NEWTON    implicit method: Newton did not converge in max_iter
 *   LAG_ERR_STEPSIZE  dopri5: step size fell below dt_min
 *   LAG_ERR_LIFTOFF   stick with a floor: the normal force went negative
 *   LAG_ERR_FORCE     the applied forces (or an impulse) are too large for one tick: at
 *                     the tick's start they give an acceleration that takes the state past
 *                     explode_limit within dt, or a non-finite one. Reported instead of
 *                     what the step then ran into (a non-finite state, a mass matrix
 *                     evaluated at an overflowed q, Newton or dopri5 failing); see
 *                     lag_sim_fault_describe. State unchanged
 *   LAG_ERR_MAX_STEPS dopri5: more than max_steps steps for one tick (bounded work)
 *   LAG_ERR_USAGE     a program's command line is wrong (nothing ran)
 *   LAG_ERR_SCENE     the scene loader refused a file, a --set or a URL (file:line:column)
 *   LAG_ERR_SYNTAX    lag_scene_read_decimal: not a plain decimal
 *   LAG_ERR_RANGE     lag_scene_read_decimal: a plain decimal too large for a double
 *   LAG_ERR_FILE      an input cannot be read or an output would be replaced (nothing ran)
 *   LAG_ERR_RUNTIME   a program failed while running (a fault, a lost record, ...)
 *   LAG_ERR_MISMATCH  a replay's difference above its tolerance, a run that missed a
 *                     requirement
 *   LAG_ERR_REFUSED   the daemon refused a request (its reason is the message)
 *   LAG_ERR_NOANSWER  nobody answered within the timeout */
#define LAG_RESULT_ENUM_(code, value, exit_status, text) code = (value),
typedef enum lag_result { LAG_RESULT_LIST(LAG_RESULT_ENUM_) } lag_result;
#undef LAG_RESULT_ENUM_

/* The code's name ("LAG_ERR_ARG"), or NULL for a value that is no code. */
const char *lag_result_name(lag_result r);
/* A sentence for the code ("invalid argument"); "unknown result" for a value that is no code. */
const char *lag_result_string(lag_result r);
/* The exit status a program ends with for this result (0..3, see above); 1 for a value
 * that is no code. */
int lag_result_exit(lag_result r);

#ifdef __cplusplus
}
#endif

#endif
