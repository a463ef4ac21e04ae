/*
 * The control requests of control_t (rt_control.c): decoded, checked against the run's
 * state, and the changes they make to the scene (SET, kicks, a reset to the scene file's
 * values) applied. What a request does to the run itself (pause, resume, step, reset) is
 * the loop's: rt_control_handle returns it as an rt_act for the loop to carry out.
 *
 * A part of the loop's: it stands on the publisher (rt_publish.h: its events and the
 * answers it asks for), the log (rt_record.h) and the changes made while running
 * (live_set.h). Its state is those changes, the reference they give, the SET bucket and
 * the count of refused requests.
 */
#ifndef LAGSIMD_RT_CONTROL_H
#define LAGSIMD_RT_CONTROL_H

#include <stdbool.h>
#include <stdint.h>
#include "daemon.h"
#include "lagsim/lagsim.h"
#include "live_set.h"
#include "rt_pace.h"
#include "rt_publish.h"
#include "rt_record.h"
#include "scene.h"

/* SET requests validated per second and burst (each parses the scene: about 0.05 ms for
 * the DIPC's, so 50 a second take a quarter of a percent of a core): a SET is either
 * applied and announced by its `set` event, which is never suppressed (replay re-applies
 * it), or refused; so `set` events stay within this bucket. lagsim-sweep's kept daemon
 * takes one SET per varied key and run. */
#define RT_SET_PER_S 50
#define RT_SET_BURST 50
/* RESET and RESET_TO applied per second and burst: each starts a new generation whose
 * scene goes out at once (rt_pub_new_generation), so a flood of resets must not become
 * a flood of scenes; one beyond is refused (control_rejected) and not applied.
 * lagsim-sweep's kept daemon takes one RESET_TO per run. */
#define RT_RESET_PER_S 50
#define RT_RESET_BURST 50

/* RT_WAITING: not advancing, waiting for a command that starts the run (realtime.start:
 * first_command) or, in lockstep, for one that answers the state whose wait timed out; the
 * state is republished meanwhile, and such a command (or RESUME) makes it RT_RUNNING. */
typedef enum rt_run { RT_RUNNING = 0, RT_PAUSED, RT_FAULT, RT_WAITING } rt_run;

const char *rt_run_name(rt_run r);

typedef struct rt_control {
    /* what it reads and acts on (rt_control_init) */
    const lag_scene *sc;
    const lagsimd_opts *opts;
    const lag_model_info *info;
    int nq;
    lag_sim *sim;
    rt_pub *pub;
    rt_record *rec;

    live_sets live;            /* changes made while running (control_t SET), in the
                                * order they were applied */
    /* the scene's reference with the changes made while running (SET reference.*):
     * published on _REFERENCE before each state when ref.n > 0 */
    lag_scene_reference ref;
    rt_limit lim_set;          /* SET requests validated per second */
    rt_limit lim_reset;        /* RESET and RESET_TO applied per second */
    int64_t controls_rejected; /* counted in status */
} rt_control;

/* What a request asks of the run, once checked (RT_ACT_NONE: nothing more to do, the
 * request was answered or refused). */
typedef enum rt_act_kind {
    RT_ACT_NONE = 0,
    RT_ACT_PAUSE,
    RT_ACT_RESUME,
    RT_ACT_STEP,       /* count periods */
    RT_ACT_RESET,      /* to the initial state (to: false) or to q, qd */
} rt_act_kind;

typedef struct rt_act {
    rt_act_kind kind;
    int64_t count;
    bool to;
    double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
    const char *what;  /* RESET: what the reset event says it is */
    bool wait;         /* RESET: then wait for the first command (RT_WAITING) */
} rt_act;

/* What it reads and acts on; the reference is the scene's, the SET bucket full at now. */
void rt_control_init(rt_control *c, const lag_scene *sc, const lagsimd_opts *o,
                     const lag_model_info *info, lag_sim *sim, rt_pub *pub, rt_record *rec,
                     int64_t now);
/* A control request's bytes, with the run in state `run`: decoded and checked (a refusal
 * is counted, and a control_rejected event says why), the scene's changes applied. */
rt_act rt_control_handle(rt_control *c, rt_run run, const uint8_t *data, size_t len);
/* A refused request: counted, its fate noted for --log, a control_rejected event (limited)
 * and a status. */
void rt_control_rejected(rt_control *c, const char *why);
/* Does any joint's actuator have a lag? */
bool rt_actuator_lagged(const lag_effects_def *fx, int nq);

#endif
