/*
 * lagsimd --replay LOG: re-simulates a run recorded by lagsimd --log or by lcm-logger and
 * reports how far the re-simulation is from the logged states; a check that fails (exit
 * 1) when the largest difference is above --tolerance (default 0).
 *
 * Reads the <PREFIX>_STATE messages of the log in order. The first one sets the state
 * (q, qd) and the tick; each next one says which effort was applied over the ticks between
 * the two (joint_state_t.effort is the effort of the period that ended at its sim_time),
 * so the replay applies it for those ticks, in chunks of one control period with hard
 * stops at period ends exactly as the server does, and compares q and qd.
 *
 * Published states carry the noise effect (lag_sim_observe) and the applied effort
 * (tau_applied); the replay compares observed with observed. Effects are re-simulated as
 * the scene defines them (disturbances at their times, noise as a function of seed and
 * tick), except the actuator: the logged effort is already its output, so the replay
 * applies it directly. An actuator lag makes the effort change within a period while the
 * state holds its last value; lagsimd --log then also logs the commanded input of every
 * period (<PREFIX>_INPUT, a joint_command_t at the period's start), and with those the
 * replay runs the actuator itself, lag and saturation, from the inputs, and compares the
 * efforts too. A log without them (lcm-logger records only the bus) leaves a lagged run
 * approximate: the replay says so, and re-simulates each period from the logged state
 * before it (an unstable plant would otherwise grow the error of each period without
 * bound), so the difference is that of one period.
 *
 * Restarts. A state whose step goes back (a reset) starts the re-simulation over from it,
 * as does a state after a gap (states missing from the log: lcm-logger loses datagrams
 * under load; the effort in between is unknown), rather than running on with an unknown
 * effort. Each gap is reported with where it is. A restart gives the daemon's numbers
 * exactly when the logged state is all the run carried: always at the scene's initial
 * state, at a reset (step 0) unless the state is noisy, and elsewhere only for a
 * fixed-step method without noise, actuator lag, friction, stops or floor (dopri5 carries
 * its step size from period to period; the effects keep contact modes and lag states the
 * log does not hold). After an inexact restart the states are not compared until the
 * next exact one: they are counted and the reason said.
 *
 * Changes made while running (control_t SET) are in the log as the daemon's `set` events
 * on <PREFIX>_EVENT: detail "key=value", step the tick it took effect at. The replay
 * validates each as the daemon did (live_set.c: the scene file with its --set overrides and
 * the changes before it) and applies it at that tick: a change read before a state
 * happened before it, so a period that holds one is advanced to its tick, changed
 * (lag_sim_redefine), then to its end, as the daemon's chunks were; a restart applies
 * every change read before it first.
 *
 * References. A scene with a `reference:` has <PREFIX>_REFERENCE records, one just before
 * each state; each is compared with the reference computed again (lagsimd_reference_at)
 * at its sim time, from the scene and the `reference.*` changes read before it in the log
 * (log order: a change published before a reference was in force when it was computed).
 *
 * For a run of the same scene and build recorded from its start (lagsimd --log, or a
 * logger started before the daemon), every difference is exactly 0: the daemon and the
 * replay make the same floating-point operations in the same order.
 *
 * The log is untrusted input. It is read by the bounded log reader and the bounded
 * decoders of the wire module (server/wire): no length from the file is trusted, nothing
 * is allocated per record, a damaged stretch is passed over and reported, a file with no
 * record in its first LAG_LOG_SCAN_MAX bytes (or after one) is an error. The replay says
 * "checked" (exit 0) only when at least one state was compared, every re-simulation
 * succeeded and the largest difference is within the tolerance; otherwise it reports why
 * and exits 1.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "daemon.h"
#include "lagsim_bus.h"
#include "lagsim_log.h"
#include "lagsim_num.h"
#include "lagsim_wire.h"
#include "live_set.h"
#include "rt_wire.h"

#define REPLAY_DATA_MAX 65536               /* a record larger than this is no state */
#define REPLAY_STEP_MAX (INT64_C(1) << 53)  /* steps beyond this are not a run's */
#define REPLAY_GAPS_SAID 10                 /* gaps reported one by one, then counted */
#define REPLAY_SETS_PENDING 1024            /* changes read and not yet reached, at most */

/* Why a restart away from the scene's initial state and from a reset cannot be exact for
 * this definition (the scene's, or as changed while running), or NULL when it can. Which
 * effects keep state of their own is the core's table (lag_effect_info.keeps_state): a
 * new effect is taken into account without a change here. */
static const char *restart_inexact(const lag_sim_def *def, bool lagged)
{
    const lag_effects_def *fx = &def->effects;
    const lag_method_info *mi = lag_method_info_get(def->integrator.method);
    if (fx->enabled & LAG_EFF_NOISE)
        return "the logged state carries the noise effect, not the true state";
    if (mi && mi->adaptive)
        return "the adaptive method carries its step size from period to period";
    if (lagged) return "the actuator lag's state is not in the log";
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        lag_effect_info e = lag_effect_info_get(k);
        /* the actuator's state is its lag's, and it has none here (lagged is false) */
        if (e.keeps_state && e.bit != LAG_EFF_ACTUATOR && (fx->enabled & e.bit)) {
            static char why[96];
            snprintf(why, sizeof why, "the %s effect keeps state of its own the log does not "
                     "hold", e.name);
            return why;
        }
    }
    return NULL;
}

/* Starts over from logged state m: from the scene's initial state if that is what was
 * published (a start or a plain reset: the published one may carry noise), else from
 * the logged one. Returns true when it started from the scene's initial state. */
static bool restart(lag_sim *sim, const lag_wire_joint_state *m)
{
    double sq[LAG_MAX_DOF], sqd[LAG_MAX_DOF];
    lag_sim_reset(sim, NULL, NULL);
    lag_sim_observe(sim, sq, sqd);
    bool initial = m->step == 0;
    for (int i = 0; initial && i < sim->nq; i++)
        initial = sq[i] == m->position[i] && sqd[i] == m->velocity[i];
    if (!initial) lag_sim_reset(sim, m->position, m->velocity);
    sim->tick = m->step;
    return initial;
}

/* Does the log hold a record on `channel`? (A first pass, for scenes with an actuator
 * lag: the inputs decide how the replay runs the actuator.) */
static bool log_has_channel(const char *path, const char *channel)
{
    char err[256];
    lag_log *log = lag_log_open(path, REPLAY_DATA_MAX, err, sizeof err);
    if (!log) return false;
    lag_log_record rec;
    bool found = false;
    while (!found && lag_log_next(log, &rec) == LAG_LOG_OK)
        found = strcmp(rec.channel, channel) == 0;
    lag_log_close(log);
    return found;
}

/* The commanded input a <PREFIX>_INPUT record holds, by joint (zero where it names
 * none); false when it does not decode or names a joint the model lacks. OUT: u, t */
static bool decode_input(const lag_log_record *rec, const lag_model_info *info, int nq,
                         double *u, double *t)
{
    lag_wire_joint_command c;
    if (!rec->data || lag_wire_decode_any(LAG_WIRE_JOINT_COMMAND, rec->data, rec->size, nq, &c, NULL) != LAG_WIRE_OK ||
        !lag_wire_all_finite(LAG_WIRE_JOINT_COMMAND, &c))
        return false;
    for (int i = 0; i < nq; i++) u[i] = 0.0;
    for (int k = 0; k < c.num_joints; k++) {
        int j = -1;
        for (int i = 0; i < nq; i++)
            if (strcmp(c.name[k], info->joint_names[i]) == 0) j = i;
        if (j < 0) return false;
        u[j] = c.effort[k];
    }
    *t = c.sim_time;
    return true;
}

/* The changes made while running, as the log's `set` events say. */
typedef struct replay_sets {
    live_sets live;                         /* applied so far: the validation source */
    int64_t step[REPLAY_SETS_PENDING];      /* read, not yet applied: where, what */
    char kv[REPLAY_SETS_PENDING][LIVE_SET_LEN];
    char kind[REPLAY_SETS_PENDING];         /* 's' set, 'k' kick, 'c' kicks_cleared,
                                             * 'r' restore */
    const lag_sim_def *base;                /* the scene's definition, as replayed */
    int head, n;
    int64_t applied;
    bool failed;                            /* one could not be applied: said, exit 1 */
    /* references: the scene's with the reference.* changes read so far (in log order) */
    const lag_scene_reference *base_ref;
    live_sets ref_live;
    lag_scene_reference ref;
} replay_sets;

/* The replay's definition of a scene: with an actuator lag and the inputs in the log
 * (use_input), the scene's own; otherwise the logged effort is the actuator's output,
 * applied as it is: the actuator stays on with neither lag nor bound, so that the ticks
 * are taken exactly as the daemon took them (an actuator makes every tick a separate
 * step). */
static void replay_def(lag_sim_def *def, bool use_input)
{
    if ((def->effects.enabled & LAG_EFF_ACTUATOR) && !use_input)
        for (int i = 0; i < def->model.nq; i++) {
            def->effects.actuator_tau[i] = 0.0;
            def->effects.actuator_max[i] = INFINITY;
        }
}

/* The reference in force from here on in the log: a `set` of a reference.* key read (kv)
 * or a `restore` (kv NULL). False (said once) when the change cannot be applied. */
static bool ref_read(replay_sets *rs, const char *kv, const lagsimd_opts *o)
{
    if (!kv) {
        memset(&rs->ref_live, 0, sizeof rs->ref_live);
        rs->ref = *rs->base_ref;
        return true;
    }
    static lag_scene ns; /* large: not on the stack */
    char key[LIVE_SET_LEN], checked[LIVE_SET_LEN], why[1024];
    size_t klen = strcspn(kv, "=");
    snprintf(key, sizeof key, "%.*s", (int)klen, kv);
    if (kv[klen] != '=' || live_set_parse(key, kv + klen + 1, checked, why, sizeof why) != 0 ||
        live_set_load(o, &rs->ref_live, checked, &ns, why, sizeof why) != 0) {
        if (!rs->failed)
            fprintf(stderr, "lagsimd: --replay: the log's change '%s' cannot be applied to "
                            "this scene: %s (wrong --config or --set?)\n", kv, why);
        rs->failed = true;
        return false;
    }
    live_set_keep(&rs->ref_live, checked);
    rs->ref = ns.reference;
    return true;
}

/* A `set` event of the log: queued until the replay reaches its step. */
static void set_read(replay_sets *rs, const lag_log_record *rec, const lagsimd_opts *o)
{
    lag_wire_event ev;
    if (!rec->data || lag_wire_decode_event(rec->data, rec->size, &ev) != LAG_WIRE_OK ||
        (strcmp(ev.kind, "set") && strcmp(ev.kind, "kick") && strcmp(ev.kind, "restore") &&
         strcmp(ev.kind, "kicks_cleared")))
        return;
    if (!strcmp(ev.kind, "restore")) ref_read(rs, NULL, o);
    if (!strcmp(ev.kind, "set") && !strncmp(ev.detail, "reference", 9) &&
        (ev.detail[9] == '.' || ev.detail[9] == '=') && !ref_read(rs, ev.detail, o))
        return;
    /* the daemon's changes are at steps from 0, as its states: one outside [0, 2^53] was
     * not published by it, and the run cannot be followed past it */
    if (ev.step < 0 || ev.step > REPLAY_STEP_MAX) {
        if (!rs->failed)
            fprintf(stderr, "lagsimd: --replay: a %s event at step %lld, outside [0, 2^53]: "
                            "not the daemon's, the log could not be checked\n",
                    ev.kind, (long long)ev.step);
        rs->failed = true;
        return;
    }
    if (rs->n == REPLAY_SETS_PENDING) {
        if (!rs->failed)
            fprintf(stderr, "lagsimd: --replay: more than %d changes (set events) between two "
                            "states: the log could not be checked\n", REPLAY_SETS_PENDING);
        rs->failed = true;
        return;
    }
    int k = (rs->head + rs->n++) % REPLAY_SETS_PENDING;
    rs->step[k] = ev.step;
    rs->kind[k] = !strcmp(ev.kind, "kick")            ? 'k'
                  : !strcmp(ev.kind, "kicks_cleared") ? 'c'
                  : !strcmp(ev.kind, "restore")       ? 'r'
                                                      : 's';
    snprintf(rs->kv[k], sizeof rs->kv[k], "%s", ev.detail);
}

/* Applies the oldest pending change to sim: validated as the daemon validated it, then
 * lag_sim_redefine at the current state, as the daemon did (so whatever the run carries,
 * dopri5's step size among it, goes on as in the daemon). Before a restart (restarting:
 * the state is reset next), a state the change does not fit (the replay's, after states
 * missing from the log, is not the daemon's) makes a fresh simulation of the changed scene
 * instead. False (said once) when it cannot be applied. */
static bool set_apply(replay_sets *rs, lag_sim *sim, const lagsimd_opts *o, bool use_input,
                      bool restarting)
{
    const char *kv = rs->kv[rs->head];
    int64_t step = rs->step[rs->head];
    char kind = rs->kind[rs->head];
    rs->head = (rs->head + 1) % REPLAY_SETS_PENDING;
    rs->n--;
    char key[LIVE_SET_LEN], checked[LIVE_SET_LEN], why[1024], err[512];
    if (kind != 's') {
        /* a kick, at this tick as the daemon's; a restore: the scene's own definition */
        live_kick k;
        int ok = 1;
        if (kind == 'k') {
            ok = live_kick_apply(&rs->live, sim, kv, &k, why, sizeof why) == 0;
        } else if (kind == 'c') {
            live_kicks_clear(&rs->live, sim);
        } else if (lag_sim_redefine(sim, rs->base, err, sizeof err) != LAG_OK &&
                   (!restarting || lag_sim_init(sim, rs->base, err, sizeof err) != LAG_OK)) {
            snprintf(why, sizeof why, "%s", err);
            ok = 0;
        } else {
            memset(&rs->live, 0, sizeof rs->live);
        }
        if (!ok) {
            if (!rs->failed)
                fprintf(stderr, "lagsimd: --replay: the log's %s '%s' (step %lld) cannot be "
                                "applied to this scene: %s (wrong --config or --set?)\n",
                        kind == 'k' ? "kick" : kind == 'c' ? "kicks_cleared" : "restore", kv,
                        (long long)step, why);
            rs->failed = true;
            return false;
        }
        rs->applied++;
        return true;
    }
    size_t klen = strcspn(kv, "=");
    snprintf(key, sizeof key, "%.*s", (int)klen, kv);
    static lag_scene ns; /* large: not on the stack */
    int ok = kv[klen] == '=' && live_set_parse(key, kv + klen + 1, checked, why, sizeof why) == 0 &&
             live_set_load(o, &rs->live, checked, &ns, why, sizeof why) == 0;
    if (ok) {
        replay_def(&ns.sim, use_input);
        lag_result r = lag_sim_redefine(sim, &ns.sim, err, sizeof err);
        if (r != LAG_OK && restarting) r = lag_sim_init(sim, &ns.sim, err, sizeof err);
        if (r != LAG_OK) {
            snprintf(why, sizeof why, "%s", err);
            ok = 0;
        }
    }
    if (!ok) {
        if (!rs->failed)
            fprintf(stderr, "lagsimd: --replay: the log's change '%s' (step %lld) cannot be "
                            "applied to this scene: %s (wrong --config or --set?)\n",
                    kv, (long long)step, why);
        rs->failed = true;
        return false;
    }
    live_set_keep(&rs->live, checked);
    rs->applied++;
    return true;
}

/* Advances sim by n ticks (hard stop at the end, as the daemon's period), applying the
 * pending changes at their ticks on the way (one whose tick has passed: now). */
static lag_result advance_with_sets(lag_sim *sim, int64_t n, replay_sets *rs,
                                    const lagsimd_opts *o, bool use_input)
{
    const int64_t end = sim->tick + n;
    /* steps and ticks lie in [0, 2^53] (set_read): the differences cannot overflow */
    while (rs->n > 0 && rs->step[rs->head] < end) {
        int64_t k = rs->step[rs->head] - sim->tick;
        if (k > 0) {
            lag_result r = lag_sim_advance_within(sim, k, end);
            if (r != LAG_OK) return r;
        }
        if (!set_apply(rs, sim, o, use_input, false)) return LAG_ERR_ARG;
    }
    return sim->tick < end ? lag_sim_advance_within(sim, end - sim->tick, end) : LAG_OK;
}

/* A replay's state: what it reads, the re-simulation, where it stands, what it counted. */
typedef struct replay_run {
    const lag_scene *sc;
    const lagsimd_opts *o;
    const char *log_path;
    char channel[96], ch_input[96], ch_event[96], ch_ref[96], ch_scene[96];
    bool have_scene;            /* the log's first scene (the one its run started with) */
    replay_sets sets;
    lag_sim_def def;            /* the scene's definition, as replayed (replay_def) */
    lag_sim sim;
    const lag_model_info *info; /* the sim's joints (a stick that may fly: h too) */
    bool lagged;                /* the scene has an actuator lag */
    bool use_input;             /* ... and the log its inputs: the actuator is re-simulated */
    bool anchor;                /* ... but not: each period from the logged state before it */
    int nq;
    int64_t tpp;                /* ticks per control period */
    double dt;
    const char *inexact;        /* why a restart here is not exact, or NULL */
    /* where it stands */
    bool have;                  /* the sim holds a logged state to go on from */
    bool checking;              /* the sim's history is the daemon's: states are compared */
    bool have_u;                /* use_input: the input of the period starting at u_t */
    double u[LAG_MAX_DOF], u_t;
    /* what it counted */
    int64_t seen, compared, restarts, gaps, undecodable, invalid, errors, unchecked;
    int64_t refs_seen, refs_compared, refs_bad;
    int64_t error_step;         /* the first failed re-simulation: towards this step */
    lag_result error_kind;      /* ... with this result */
    const char *unchecked_why;
    double max_dq, max_dqd, max_deff, max_dr;
} replay_run;

/* What the loop does after a record. */
typedef enum { REPLAY_NEXT, REPLAY_STOP, REPLAY_FAIL } replay_step;

/* The channels, the replay's definition (with an actuator lag and the inputs in the log,
 * the replay runs the actuator from them; otherwise the logged effort is the actuator's
 * output, applied as it is: replay_def) and the simulation. */
static lag_result replay_setup(replay_run *run)
{
    const lag_scene *sc = run->sc;
    char err[512];
    lag_bus_channel_name(run->channel, sizeof run->channel, sc->lcm.prefix, LAG_BUS_STATE);
    lag_bus_channel_name(run->ch_ref, sizeof run->ch_ref, sc->lcm.prefix, LAG_BUS_REFERENCE);
    lag_bus_channel_name(run->ch_input, sizeof run->ch_input, sc->lcm.prefix, LAG_BUS_INPUT);
    lag_bus_channel_name(run->ch_event, sizeof run->ch_event, sc->lcm.prefix, LAG_BUS_EVENT);
    lag_bus_channel_name(run->ch_scene, sizeof run->ch_scene, sc->lcm.prefix, LAG_BUS_SCENE);
    run->def = sc->sim;
    lag_sim_def *def = &run->def;
    if (def->effects.enabled & LAG_EFF_ACTUATOR)
        for (int i = 0; i < def->model.nq; i++) run->lagged |= def->effects.actuator_tau[i] > 0;
    run->use_input = run->lagged && log_has_channel(run->log_path, run->ch_input);
    run->anchor = run->lagged && !run->use_input;
    replay_def(def, run->use_input);
    run->sets.base = def;
    run->sets.base_ref = &sc->reference;
    run->sets.ref = sc->reference;
    if (lag_sim_init(&run->sim, def, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "lagsimd: bad scene: %s\n", err);
        return LAG_ERR_SCENE;
    }
    run->info = lag_sim_info(&run->sim);
    run->nq = run->sim.nq;
    run->tpp = sc->ticks_per_period;
    run->dt = sc->sim.integrator.dt;
    run->error_step = -1;
    return LAG_OK;
}

/* Says how the actuator is replayed, for a scene with an actuator lag. */
static void replay_say_actuator(const replay_run *run)
{
    if (run->use_input)
        printf("actuator lag: re-simulated from the commanded inputs logged on %s\n",
               run->ch_input);
    else if (run->lagged)
        printf("note: this scene has an actuator lag and the log has no %s records (lagsimd "
               "--log writes them; lcm-logger records only the bus): the applied effort "
               "changes within a control period and the log holds its last value, so each "
               "state is re-simulated from the logged one a period before it and the "
               "difference is approximate (give --tolerance)\n", run->ch_input);
}

/* A <PREFIX>_REFERENCE record: the reference as published, against the one computed
 * again at its time. */
static void replay_reference(replay_run *run, const lag_log_record *rec)
{
    run->refs_seen++;
    lag_wire_reference lr, cr;
    const char *old = NULL; /* an earlier version's: without r'' (0.1.0) */
    if (!rec->data || lag_wire_decode_any(LAG_WIRE_REFERENCE, rec->data, rec->size,
                                          LAG_WIRE_MAX_JOINTS, &lr, &old) != LAG_WIRE_OK) {
        run->refs_bad++;
        return;
    }
    lagsimd_reference_at(&run->sets.ref, run->sc->sim.model.kind, lr.sim_time, lr.step, &cr);
    bool same = cr.num_joints == lr.num_joints && lr.sim_time == (double)lr.step * run->dt;
    for (int k = 0; same && k < lr.num_joints; k++) same = !strcmp(cr.name[k], lr.name[k]);
    if (!same) {
        run->refs_bad++;
        return;
    }
    for (int k = 0; k < lr.num_joints; k++) {
        double a = fabs(cr.r[k] - lr.r[k]), b = fabs(cr.rdot[k] - lr.rdot[k]);
        double c = old ? 0.0 : fabs(cr.rddot[k] - lr.rddot[k]);
        if (!(a <= run->max_dr)) run->max_dr = a;
        if (!(b <= run->max_dr)) run->max_dr = b;
        if (!(c <= run->max_dr)) run->max_dr = c;
    }
    run->refs_compared++;
}

/* Starts over from logged state m (the first state, a reset: the step went back or the
 * state changed in place, or a gap), after the changes read before it (they happened
 * before it). REPLAY_STOP when one of them cannot be applied. */
static replay_step replay_restart(replay_run *run, const lag_wire_joint_state *m, bool is_gap,
                                  bool input_missing)
{
    while (run->sets.n > 0 && set_apply(&run->sets, &run->sim, run->o, run->use_input, true)) {
    }
    if (run->sets.failed) return REPLAY_STOP;
    run->inexact = restart_inexact(&run->sim.def, run->lagged);
    if (is_gap) {
        run->gaps++;
        if (run->gaps <= REPLAY_GAPS_SAID)
            printf("gap: %s between t = %.9g s and t = %.9g s (step %lld to %lld): "
                   "restarted from t = %.9g s%s\n",
                   input_missing ? "the period's logged input is missing" : "states missing",
                   lag_sim_time(&run->sim), (double)m->step * run->dt,
                   (long long)run->sim.tick, (long long)m->step, (double)m->step * run->dt,
                   run->checking && run->inexact ? ", not checked until the next reset" : "");
        else if (run->gaps == REPLAY_GAPS_SAID + 1)
            printf("gap: more gaps follow, counted below\n");
    } else if (run->have) {
        run->restarts++;
    }
    bool initial = restart(&run->sim, m);
    run->checking = initial ||
                    (m->step == 0 && !(run->sim.def.effects.enabled & LAG_EFF_NOISE)) ||
                    !run->inexact;
    if (!run->checking && !run->unchecked_why)
        run->unchecked_why = m->step == 0 ? "the logged state carries the noise effect, not "
                                            "the true state"
                                          : run->inexact;
    run->have = true;
    run->have_u = false;
    return REPLAY_NEXT;
}

/* Re-simulates the dticks before logged state m with its effort (or the logged input),
 * applying the changes on the way. A failure is counted and the replay goes on from the
 * logged state, unchecked: then false. */
static bool replay_advance(replay_run *run, const lag_wire_joint_state *m, int64_t dticks)
{
    lag_sim_set_input(&run->sim, run->use_input ? run->u : m->effort);
    run->have_u = false;
    const int64_t applied = run->sets.applied;
    lag_result r = advance_with_sets(&run->sim, dticks, &run->sets, run->o, run->use_input);
    if (run->sets.failed) return false;
    if (run->sets.applied != applied) run->inexact = restart_inexact(&run->sim.def, run->lagged);
    if (r != LAG_OK || run->sim.tick != m->step) {
        if (run->errors++ == 0) {
            run->error_step = m->step;
            run->error_kind = r;
        }
        restart(&run->sim, m); /* go on from the logged state */
        run->checking = false;
        return false;
    }
    return true;
}

/* Compares the re-simulated state, as the daemon published it (noise effect), with m. */
static void replay_compare(replay_run *run, const lag_wire_joint_state *m)
{
    double oq[LAG_MAX_DOF], oqd[LAG_MAX_DOF];
    lag_sim_observe(&run->sim, oq, oqd);
    for (int i = 0; i < run->nq; i++) {
        double a = fabs(oq[i] - m->position[i]), b = fabs(oqd[i] - m->velocity[i]);
        if (!(a <= run->max_dq)) run->max_dq = a; /* NaN propagates as the max */
        if (!(b <= run->max_dqd)) run->max_dqd = b;
        if (run->use_input) {
            double c = fabs(run->sim.tau_applied[i] - m->effort[i]);
            if (!(c <= run->max_deff)) run->max_deff = c;
        }
    }
    run->compared++;
    /* a lag without its inputs: each period from the logged state before it, so that the
     * difference is that of one period, not one grown by an unstable plant */
    if (run->anchor) restart(&run->sim, m);
}

/* Decodes a <PREFIX>_STATE record into m: false (counted) when it cannot be checked;
 * REPLAY_FAIL in *step when its joints are not this scene's. */
static bool replay_decode_state(replay_run *run, const lag_log_record *rec,
                                lag_wire_joint_state *m, replay_step *step)
{
    run->seen++;
    if (!rec->data ||
        lag_wire_decode_any(LAG_WIRE_JOINT_STATE, rec->data, rec->size, LAG_WIRE_MAX_JOINTS, m, NULL) != LAG_WIRE_OK) {
        run->undecodable++;
        return false;
    }
    bool ok = m->num_joints == run->nq;
    for (int i = 0; ok && i < run->nq; i++) ok = strcmp(m->name[i], run->info->joint_names[i]) == 0;
    if (!ok) {
        fprintf(stderr, "lagsimd: --replay: a state on %s does not match this scene's "
                        "joints (%s); wrong --config?\n", run->channel,
                lag_model_info_get(run->sc->sim.model.kind)->name);
        *step = REPLAY_FAIL;
        return false;
    }
    /* the daemon publishes finite numbers and steps from 0: anything else was not
     * published by it and cannot be checked */
    if (!lag_wire_all_finite(LAG_WIRE_JOINT_STATE, m) || m->step < 0 ||
        m->step > REPLAY_STEP_MAX) {
        run->invalid++;
        return false;
    }
    return true;
}

/* A <PREFIX>_STATE record: a restart, or the period before it re-simulated and compared. */
static replay_step replay_state(replay_run *run, const lag_log_record *rec)
{
    lag_wire_joint_state m;
    replay_step step = REPLAY_NEXT;
    if (!replay_decode_state(run, rec, &m, &step)) return step;
    /* both steps lie in [0, 2^53]: the difference cannot overflow */
    int64_t dticks = run->have ? m.step - run->sim.tick : -1;
    bool same = dticks == 0;
    double oq[LAG_MAX_DOF], oqd[LAG_MAX_DOF];
    lag_sim_observe(&run->sim, oq, oqd);
    for (int i = 0; same && i < run->nq; i++)
        same = oq[i] == m.position[i] && oqd[i] == m.velocity[i];
    /* a period with an actuator lag needs its logged input */
    bool input_missing = run->use_input && dticks == run->tpp &&
                         !(run->have_u && run->u_t == lag_sim_time(&run->sim));
    bool is_gap = run->have && dticks > 0 && (dticks != run->tpp || input_missing);
    if (!run->have || dticks < 0 || (dticks == 0 && !same) || is_gap)
        return replay_restart(run, &m, is_gap, input_missing);
    if (dticks > 0 && !replay_advance(run, &m, dticks))
        return run->sets.failed ? REPLAY_STOP : REPLAY_NEXT;
    if (!run->checking) {
        run->unchecked++;
        return REPLAY_NEXT;
    }
    replay_compare(run, &m);
    return REPLAY_NEXT;
}

/* ---------------------------------------------------------------- the log's scene */
static lag_wire_scene g_logged, g_here; /* large: not on the stack */

/* One difference: "KEY: log A, here B" into the list, and "--set KEY=A" into the sets
 * when a --set can give it (set_key not NULL). */
/* printf at the end of out (len its size), cut short when it is full */
static void __attribute__((format(printf, 3, 4))) appendf(char *out, size_t len,
                                                          const char *fmt, ...)
{
    size_t o = strlen(out);
    if (o + 1 >= len) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(out + o, len - o, fmt, ap);
    va_end(ap);
}

static void differ(char *out, size_t len, char *sets, size_t slen, const char *key,
                   const char *set_key, const char *logv, const char *herev)
{
    appendf(out, len, "%s%s: log %s, here %s", out[0] ? "; " : "", key, logv, herev);
    if (set_key) appendf(sets, slen, " --set %s=%s", set_key, logv);
}

/* A vector as a YAML flow sequence, each number exact. */
static void vec_text(const double *x, int n, char *out, size_t len)
{
    char a[LAG_NUM_LEN];
    size_t o = (size_t)snprintf(out, len, "[");
    for (int i = 0; i < n && o < len; i++)
        o += (size_t)snprintf(out + o, len - o, "%s%s", i ? "," : "", lag_num(x[i], a));
    if (o < len) snprintf(out + o, len - o, "]");
}

/* The numbers the scene's keys hold, each compared (parameters by name, initial state by
 * joint, integrator and period, real-time settings). */
static void diff_numbers(const lag_wire_scene *l, const lag_wire_scene *h, char *out,
                         size_t len, char *sets, size_t slen)
{
    char a[LAG_NUM_LEN], b[LAG_NUM_LEN], key[96];
    for (int i = 0; i < l->num_params; i++)
        for (int j = 0; j < h->num_params; j++)
            if (!strcmp(l->param_name[i], h->param_name[j]) &&
                l->param_value[i] != h->param_value[j]) {
                snprintf(key, sizeof key, "parameters.%s", l->param_name[i]);
                differ(out, len, sets, slen, key, key, lag_num(l->param_value[i], a),
                       lag_num(h->param_value[j], b));
            }
    if (l->num_joints == h->num_joints) {
        char va[512], vb[512];
        const double *lv[2] = {l->initial_q, l->initial_qd}, *hv[2] = {h->initial_q, h->initial_qd};
        const char *names[2] = {"initial.q", "initial.qd"};
        for (int k = 0; k < 2; k++)
            if (memcmp(lv[k], hv[k], sizeof(double) * (size_t)l->num_joints) != 0) {
                vec_text(lv[k], l->num_joints, va, sizeof va);
                vec_text(hv[k], h->num_joints, vb, sizeof vb);
                differ(out, len, sets, slen, names[k], names[k], va, vb);
            }
    }
    const double ln[4] = {l->dt, l->control_period > 0 ? 1.0 / l->control_period : 0, l->rate,
                          l->command_timeout};
    const double hn[4] = {h->dt, h->control_period > 0 ? 1.0 / h->control_period : 0, h->rate,
                          h->command_timeout};
    const char *keys[4] = {"integrator.dt", "publish_hz", "realtime.rate",
                           "realtime.command_timeout"};
    for (int k = 0; k < 4; k++)
        if (ln[k] != hn[k])
            differ(out, len, sets, slen, keys[k], keys[k], lag_num(ln[k], a), lag_num(hn[k], b));
}

/* Says how the log's scene differs from this one: each key with both values, and the
 * --set that gives the log's (the replay failed: "wrong --config or --set?"). */
static void replay_say_scene(const replay_run *run)
{
    if (!run->have_scene) {
        fprintf(stderr, "lagsimd: --replay: the log holds no scene on %s to compare this one "
                "with\n", run->ch_scene);
        return;
    }
    const lag_wire_scene *l = &g_logged, *h = &g_here;
    rt_scene_fill(&g_here, run->sc, &run->sc->sim, run->nq, run->info);
    static char out[4096], sets[2048];
    out[0] = sets[0] = '\0';
    if (strcmp(l->model, h->model) != 0 || l->num_joints != h->num_joints)
        differ(out, sizeof out, sets, sizeof sets, "model", NULL, l->model, h->model);
    const char *lt[3] = {l->integrator, l->effects, l->mode}, *ht[3] = {h->integrator, h->effects,
                                                                       h->mode};
    const char *keys[3] = {"integrator.method", "effects", "realtime.mode"};
    for (int k = 0; k < 3; k++)
        if (strcmp(lt[k], ht[k]) != 0)
            differ(out, sizeof out, sets, sizeof sets, keys[k], k == 1 ? NULL : keys[k],
                   lt[k][0] ? lt[k] : "(none)", ht[k][0] ? ht[k] : "(none)");
    if (!strcmp(l->model, h->model)) diff_numbers(l, h, out, sizeof out, sets, sizeof sets);
    if (!out[0]) {
        fprintf(stderr, "lagsimd: --replay: the log's scene (its first on %s) is this one\n",
                run->ch_scene);
        return;
    }
    fprintf(stderr, "lagsimd: --replay: the log's scene (its first on %s) differs from this "
            "one: %s\n", run->ch_scene, out);
    if (sets[0])
        fprintf(stderr, "lagsimd: --replay: the log's scene is this one with:%s\n", sets);
}

/* One record of the log, by its channel. */
static replay_step replay_record(replay_run *run, const lag_log_record *rec)
{
    if (!run->have_scene && strcmp(rec->channel, run->ch_scene) == 0) {
        run->have_scene = rec->data && lag_wire_decode_scene(rec->data, rec->size,
                                                             LAG_WIRE_MAX_JOINTS,
                                                             &g_logged) == LAG_WIRE_OK;
        return REPLAY_NEXT;
    }
    if (strcmp(rec->channel, run->ch_event) == 0) {
        set_read(&run->sets, rec, run->o);
        return REPLAY_NEXT;
    }
    if (strcmp(rec->channel, run->ch_ref) == 0) {
        replay_reference(run, rec);
        return REPLAY_NEXT;
    }
    if (run->use_input && strcmp(rec->channel, run->ch_input) == 0) {
        run->have_u = decode_input(rec, run->info, run->nq, run->u, &run->u_t);
        return REPLAY_NEXT;
    }
    if (strcmp(rec->channel, run->channel) != 0) return REPLAY_NEXT;
    return replay_state(run, rec);
}

/* How the log ended (rc: lag_log_next's last answer): a log error, a change that could not
 * be applied, damage, no state at all. LAG_OK when the states can be judged. */
static lag_result replay_log_end(replay_run *run, lag_log *log, int rc)
{
    lag_log_stats ls;
    lag_log_get_stats(log, &ls);
    if (rc == LAG_LOG_ERROR) {
        fprintf(stderr, "lagsimd: --replay: %s\n", lag_log_errmsg(log));
        return LAG_ERR_RUNTIME;
    }
    if (run->sets.failed) return LAG_ERR_RUNTIME;
    if (ls.damaged > 0)
        fprintf(stderr, "lagsimd: --replay: warning: %s is damaged in %lld place(s): %lld "
                        "bytes passed over\n",
                run->log_path, (long long)ls.damaged, (long long)ls.bytes_skipped);
    if (ls.truncated_bytes > 0)
        fprintf(stderr, "lagsimd: --replay: warning: the last record of %s is cut short "
                        "(%lld bytes; was the logger stopped while writing?)\n",
                run->log_path, (long long)ls.truncated_bytes);
    if (run->seen == 0) {
        fprintf(stderr, "lagsimd: --replay: no %s messages in %s (%lld records read)\n",
                run->channel, run->log_path, (long long)ls.records);
        return LAG_ERR_RUNTIME;
    }
    return LAG_OK;
}

/* The counts: states compared, restarts, gaps, changes applied, states not compared. */
static void replay_say_counts(const replay_run *run)
{
    printf("replay %s: %lld states compared on %s (%lld restarts at resets, %lld gaps, "
           "%lld undecodable, %lld integrator errors)\n",
           run->log_path, (long long)run->compared, run->channel, (long long)run->restarts,
           (long long)run->gaps, (long long)run->undecodable, (long long)run->errors);
    if (run->sets.applied > 0)
        printf("%lld change(s) made while running applied at their steps (set, kick, "
               "kicks_cleared and restore events on %s)\n",
               (long long)run->sets.applied, run->ch_event);
    if (run->unchecked > 0)
        printf("%lld states after a restart were not compared: %s\n", (long long)run->unchecked,
               run->unchecked_why ? run->unchecked_why : "the re-simulation failed before them");
    if (run->invalid > 0)
        printf("%lld states with a non-finite number or a step outside [0, 2^53] were "
               "not checked\n", (long long)run->invalid);
}

/* Whether anything could be checked: no failed re-simulation, a finite difference, at
 * least one state compared. LAG_OK, or LAG_ERR_RUNTIME after saying why. OUT: max_diff */
static lag_result replay_checked(const replay_run *run, double *max_diff)
{
    if (run->errors > 0) {
        fprintf(stderr, "lagsimd: --replay: the re-simulation failed %lld time(s), first "
                        "towards step %lld (%s): the log could not be checked\n",
                (long long)run->errors, (long long)run->error_step,
                run->error_kind == LAG_OK ? "stopped at another step"
                                          : lag_result_string(run->error_kind));
        return LAG_ERR_RUNTIME;
    }
    double d = run->max_dq > run->max_dqd || isnan(run->max_dq) ? run->max_dq : run->max_dqd;
    if (run->max_deff > d || isnan(run->max_deff)) d = run->max_deff;
    *max_diff = d;
    if (isnan(d)) {
        fprintf(stderr, "lagsimd: --replay: the re-simulation produced a non-finite state: "
                        "the log could not be checked\n");
        return LAG_ERR_RUNTIME;
    }
    if (run->compared == 0) {
        fprintf(stderr, "lagsimd: --replay: %s: no state of %s follows another by one "
                        "control period (%lld ticks) from a state the re-simulation can "
                        "start from exactly: nothing could be checked\n",
                run->log_path, run->channel, (long long)run->tpp);
        return LAG_ERR_RUNTIME;
    }
    return LAG_OK;
}

/* The differences and the verdict against the tolerance: LAG_OK, or LAG_ERR_MISMATCH
 * (a reference not this scene's, a difference above the tolerance). */
static lag_result replay_verdict(const replay_run *run, double max_diff)
{
    char a[LAG_NUM_LEN], b[LAG_NUM_LEN];
    printf("max |q - q_log| = %s\nmax |qd - qd_log| = %s\n", lag_num(run->max_dq, a),
           lag_num(run->max_dqd, b));
    if (run->use_input) printf("max |effort - effort_log| = %s\n", lag_num(run->max_deff, a));
    if (run->refs_seen > 0 || run->sc->reference.n > 0) {
        printf("%lld references compared on %s (%lld of other joints, another time or "
               "undecodable)\nmax |r - r_log|, |rdot - rdot_log|, |rddot - rddot_log| = %s\n",
               (long long)run->refs_compared, run->ch_ref, (long long)run->refs_bad,
               lag_num(run->max_dr, a));
        if (run->max_dr > max_diff || isnan(run->max_dr)) max_diff = run->max_dr;
        if (run->refs_bad > 0) {
            fprintf(stderr, "lagsimd: --replay: FAILED: %lld reference(s) on %s are not "
                            "this scene's (wrong --config or --set?)\n",
                    (long long)run->refs_bad, run->ch_ref);
            replay_say_scene(run);
            return LAG_ERR_MISMATCH;
        }
    }
    printf("max difference = %s\n", lag_num(max_diff, a));
    const double tolerance = run->o ? run->o->tolerance : 0.0;
    if (!(max_diff <= tolerance)) {
        fprintf(stderr, "lagsimd: --replay: FAILED: the largest difference %s is above "
                        "the tolerance %s: %s\n", lag_num(max_diff, a), lag_num(tolerance, b),
                run->anchor ? "the replay of this log is approximate (see the note above)"
                            : "the log does not match this scene and build (wrong --config "
                              "or --set, another build, or a changed log)");
        if (!run->anchor) replay_say_scene(run);
        return LAG_ERR_MISMATCH;
    }
    return LAG_OK;
}

lag_result lagsimd_replay(const lag_scene *sc, const char *log_path, const lagsimd_opts *o)
{
    static replay_run run; /* large: not on the stack */
    memset(&run, 0, sizeof run);
    run.sc = sc;
    run.o = o;
    run.log_path = log_path;
    lag_result r = replay_setup(&run);
    if (r != LAG_OK) return r;
    char err[512];
    lag_log *log = lag_log_open(log_path, REPLAY_DATA_MAX, err, sizeof err);
    if (!log) {
        fprintf(stderr, "lagsimd: --replay: %s\n", err);
        return LAG_ERR_RUNTIME;
    }
    replay_say_actuator(&run);
    run.inexact = restart_inexact(&run.sim.def, run.lagged);

    lag_log_record rec;
    int rc;
    replay_step step = REPLAY_NEXT;
    while (step == REPLAY_NEXT && (rc = lag_log_next(log, &rec)) == LAG_LOG_OK &&
           !run.sets.failed)
        step = replay_record(&run, &rec);
    r = step == REPLAY_FAIL ? LAG_ERR_RUNTIME : replay_log_end(&run, log, rc);
    lag_log_close(log);
    if (run.sets.failed) replay_say_scene(&run); /* "wrong --config or --set?": which */
    if (r != LAG_OK) return r;
    replay_say_counts(&run);
    double max_diff = 0.0;
    r = replay_checked(&run, &max_diff);
    if (r != LAG_OK) replay_say_scene(&run); /* a re-simulation that failed: the scene? */
    return r != LAG_OK ? r : replay_verdict(&run, max_diff);
}
