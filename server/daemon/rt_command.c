/*
 * What a command must be to be applied (rt_command.h). A command is applied whole or not
 * at all; every refusal names what would be accepted.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "rt_command.h"

const char *const rt_reject_name[RT_REJ_COUNT] = {
    [RT_REJ_UNKNOWN_JOINT] = "unknown joint",
    [RT_REJ_UNACTUATED] = "unactuated joint",
    [RT_REJ_NONFINITE] = "non-finite effort",
    [RT_REJ_BAD_LENGTH] = "bad length",
    [RT_REJ_UNDECODABLE] = "undecodable payload",
    [RT_REJ_STALE] = "stale (lockstep: answers another state)",
    [RT_REJ_EFFORT_LIMIT] = "effort beyond realtime.effort_limit"};
_Static_assert(sizeof rt_reject_name / sizeof rt_reject_name[0] == RT_REJ_COUNT,
               "one name per reason");

const char *rt_joint_list(const lag_model_info *info, int nq, bool actuated_only, char *buf,
                          size_t n)
{
    size_t k = 0;
    buf[0] = '\0';
    for (int i = 0; i < nq && k < n; i++) {
        if (actuated_only && !info->actuated[i]) continue;
        int w = snprintf(buf + k, n - k, "%s%s%s", k ? ", " : "", info->joint_names[i],
                         !actuated_only && info->actuated[i] ? " (actuated)" : "");
        if (w < 0) break;
        k += (size_t)w;
    }
    if (!buf[0]) snprintf(buf, n, "none");
    return buf;
}

/* A refusal into v; returns false (what the checks return). */
static bool refuse(rt_verdict *v, rt_reject why, const char *joint, double value,
                   const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static bool refuse(rt_verdict *v, rt_reject why, const char *joint, double value,
                   const char *fmt, ...)
{
    v->why = why;
    v->joint = joint;
    v->value = value;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->what, sizeof v->what, fmt, ap);
    va_end(ap);
    return false;
}

bool rt_command_decode(const lag_model_info *info, int nq, const uint8_t *data, size_t len,
                       lag_wire_joint_command *c, rt_verdict *v)
{
    int d = lag_wire_decode_joint_command(data, len, nq, c);
    char all[160];
    if (d == LAG_WIRE_ECOUNT)
        return refuse(v, RT_REJ_BAD_LENGTH, "", c->num_joints,
                      "num_joints %d (in value); accepted: 0 to %d, joints of %s: %s",
                      c->num_joints, nq, info->name,
                      rt_joint_list(info, nq, false, all, sizeof all));
    if (d == LAG_WIRE_ETOOLONG) /* a well-formed name longer than any joint's */
        return refuse(v, RT_REJ_UNKNOWN_JOINT, "", 0, "a name of 64 bytes or more; joints of "
                      "%s: %s", info->name, rt_joint_list(info, nq, false, all, sizeof all));
    const char *old = NULL;
    if (d == LAG_WIRE_EFINGERPRINT && lag_wire_identify_any(data, len, &old) ==
        LAG_WIRE_JOINT_COMMAND && old)
        return refuse(v, RT_REJ_UNDECODABLE, "", (double)len,
                      "a joint_command_t of lagsim %s: the controller was built with lagsim "
                      "%s's types and must be rebuilt with lagsim %s's (client library and "
                      "lcmtypes)", old, old, lag_wire_version());
    if (d != LAG_WIRE_OK)
        return refuse(v, RT_REJ_UNDECODABLE, "", (double)len,
                      "%zu bytes (in value) that are no lagsim.joint_command_t; accepted: a "
                      "joint_command_t as lcm-gen encodes it (lcmtypes/joint_command_t.lcm)", len);
    return true;
}

/* Entry i of c (see rt_command_entries). */
static bool entry(const lag_model_info *info, int nq, const double *effort_limit,
                  const lag_wire_joint_command *c, int i, int *idx, rt_verdict *v)
{
    const char *name = c->name[i];
    idx[i] = -1;
    for (int j = 0; j < nq; j++)
        if (strcmp(name, info->joint_names[j]) == 0) idx[i] = j;
    char all[160];
    if (idx[i] < 0)
        return refuse(v, RT_REJ_UNKNOWN_JOINT, name, 0, "'%s'; joints of %s: %s", name,
                      info->name, rt_joint_list(info, nq, false, all, sizeof all));
    for (int k = 0; k < i; k++)
        if (idx[k] == idx[i])
            return refuse(v, RT_REJ_BAD_LENGTH, name, c->num_joints,
                          "'%s' named twice; accepted: each joint at most once (%s)", name,
                          rt_joint_list(info, nq, false, all, sizeof all));
    if (!info->actuated[idx[i]])
        return refuse(v, RT_REJ_UNACTUATED, name, 0, "'%s' takes no input; actuated joints of "
                      "%s: %s", name, info->name, rt_joint_list(info, nq, true, all, sizeof all));
    /* a bound on what a command may ask, not the plant's saturation (that is the actuator
     * effect): an effort beyond it is a controller's bug, refused whole */
    double lim = effort_limit[idx[i]];
    if (!isfinite(c->effort[i]))
        return refuse(v, RT_REJ_NONFINITE, name, 0, "%g for '%s'; accepted: a finite effort "
                      "within +-%g", c->effort[i], name, lim);
    if (fabs(c->effort[i]) > lim)
        return refuse(v, RT_REJ_EFFORT_LIMIT, name, c->effort[i],
                      "%g for '%s' (in value); accepted: |effort| <= %g", c->effort[i], name, lim);
    return true;
}

bool rt_command_entries(const lag_model_info *info, int nq, const double *effort_limit,
                        const lag_wire_joint_command *c, int *idx, rt_verdict *v)
{
    for (int i = 0; i < c->num_joints; i++)
        if (!entry(info, nq, effort_limit, c, i, idx, v)) return false;
    return true;
}
