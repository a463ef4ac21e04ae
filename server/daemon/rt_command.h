/*
 * What a command must be to be applied (rt_command.c): a joint_command_t that decodes,
 * whose every name is a joint of the model, actuated and named once, and whose every
 * effort is finite and within the scene's realtime.effort_limit.
 *
 * A part of the loop's, without state: it judges and says why (rt_verdict); the loop
 * counts, logs and answers the refusal, and applies what passes.
 */
#ifndef LAGSIMD_RT_COMMAND_H
#define LAGSIMD_RT_COMMAND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "lagsim/lagsim.h"
#include "lagsim_wire.h"

/* Why a command was rejected; indexes the loop's counters (rt_server.rejected). */
typedef enum rt_reject {
    RT_REJ_UNKNOWN_JOINT = 0,
    RT_REJ_UNACTUATED,
    RT_REJ_NONFINITE,
    RT_REJ_BAD_LENGTH,
    RT_REJ_UNDECODABLE,
    RT_REJ_STALE,             /* lockstep: answers a state other than the one waited on */
    RT_REJ_EFFORT_LIMIT,      /* an |effort| beyond the scene's realtime.effort_limit */
    RT_REJ_COUNT
} rt_reject;
/* The reasons of rt_reject, by index. */
extern const char *const rt_reject_name[RT_REJ_COUNT];

/* What a stale command answered instead of the state waited on (RT_REJ_STALE's kinds,
 * indexing rt_server.stale): the waits say which, for the fix of each differs. */
typedef enum rt_stale {
    RT_STALE_SIM_TIME = 0,    /* the right generation, another sim_time */
    RT_STALE_GENERATION,      /* another generation: a state of an earlier run or scene */
    RT_STALE_NO_GENERATION,   /* generation 0: the command carries none (lockstep) */
    RT_STALE_COUNT
} rt_stale;

/* A refusal: its reason, the joint and value its event carries, and what was wrong and
 * what would be accepted (the event's detail after the reason's name). */
typedef struct rt_verdict {
    rt_reject why;
    const char *joint;
    double value;
    char what[192];
} rt_verdict;

/* The model's joints, the actuated ones marked: "theta0 (actuated), theta1, theta2" (or
 * only the actuated ones), as the scene loader lists them; what a rejection offers. */
const char *rt_joint_list(const lag_model_info *info, int nq, bool actuated_only, char *buf,
                          size_t n);
/* Decodes a command for a model of nq joints into c. Returns true, or false with the
 * refusal in v. */
bool rt_command_decode(const lag_model_info *info, int nq, const uint8_t *data, size_t len,
                       lag_wire_joint_command *c, rt_verdict *v);
/* Every entry of c: a joint of the model (its index in idx), named once, actuated, with a
 * finite effort within effort_limit (per joint). Returns true, or false with the first
 * refusal in v. */
bool rt_command_entries(const lag_model_info *info, int nq, const double *effort_limit,
                        const lag_wire_joint_command *c, int *idx, rt_verdict *v);

#endif
