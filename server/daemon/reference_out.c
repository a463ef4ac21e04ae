/*
 * The reference a daemon publishes beside each state (<PREFIX>_REFERENCE): the scene's
 * `reference:` evaluated by the reference library at the state's sim time. One routine
 * for the real-time server, offline CSV and --replay, so that all three give the same
 * numbers.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "daemon.h"

void lagsimd_reference_at(const lag_scene_reference *ref, lag_model_kind kind, double t,
                          int64_t step, lag_wire_reference *m)
{
    memset(m, 0, sizeof *m);
    m->sim_time = t;
    m->step = step;
    const lag_model_info *mi = lag_model_info_get(kind);
    if (!mi) return;
    for (int i = 0; i < mi->nq && i < LAG_MAX_DOF && m->num_joints < LAG_WIRE_MAX_JOINTS; i++) {
        if (!ref->on[i]) continue;
        int k = m->num_joints++;
        snprintf(m->name[k], sizeof m->name[k], "%s", mi->joint_names[i]);
        double r = 0.0, rdot = 0.0, rddot = 0.0;
        lag_reference_eval(&ref->joint[i], t, &r, &rdot, &rddot);
        /* a checked reference is finite everywhere; 0 is the last line of defence */
        m->r[k] = isfinite(r) ? r : 0.0;
        m->rdot[k] = isfinite(rdot) ? rdot : 0.0;
        m->rddot[k] = isfinite(rddot) ? rddot : 0.0;
    }
}
