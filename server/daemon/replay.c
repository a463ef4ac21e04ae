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
#include <stdio.h>
#include <string.h>

#include "daemon.h"
#include "lagsim_log.h"
#include "lagsim_wire.h"
#include "live_set.h"

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
    if (!rec->data || lag_wire_decode_joint_command(rec->data, rec->size, nq, &c) != LAG_WIRE_OK ||
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

int lagsimd_replay(const lag_scene *sc, const char *log_path, const lagsimd_opts *o)
{
    char err[512];
    const double tolerance = o ? o->tolerance : 0.0;
    const lag_model_info *info; /* the sim's joints (a stick that may fly: h too), below */
    char channel[96], ch_input[96], ch_event[96], ch_ref[96];
    snprintf(channel, sizeof channel, "%s_STATE", sc->lcm.prefix);
    snprintf(ch_ref, sizeof ch_ref, "%s_REFERENCE", sc->lcm.prefix);
    snprintf(ch_input, sizeof ch_input, "%s_INPUT", sc->lcm.prefix);
    snprintf(ch_event, sizeof ch_event, "%s_EVENT", sc->lcm.prefix);
    static replay_sets sets;
    memset(&sets, 0, sizeof sets);

    /* With an actuator lag and the inputs in the log, the replay runs the actuator from
     * them. Otherwise the logged effort is the actuator's output, applied as it is: the
     * actuator stays on with neither lag nor bound, so that the ticks are taken exactly as
     * the daemon took them (an actuator makes every tick a separate step). */
    lag_sim_def def = sc->sim;
    bool lagged = false;
    if (def.effects.enabled & LAG_EFF_ACTUATOR)
        for (int i = 0; i < def.model.nq; i++) lagged |= def.effects.actuator_tau[i] > 0;
    const bool use_input = lagged && log_has_channel(log_path, ch_input);
    const bool anchor = lagged && !use_input;
    replay_def(&def, use_input);
    sets.base = &def;
    sets.base_ref = &sc->reference;
    sets.ref = sc->reference;
    int64_t refs_seen = 0, refs_compared = 0, refs_bad = 0;
    double max_dr = 0.0;
    lag_sim sim;
    if (lag_sim_init(&sim, &def, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "lagsimd: bad scene: %s\n", err);
        return LAGSIMD_EXIT_USAGE;
    }
    info = lag_sim_info(&sim);
    lag_log *log = lag_log_open(log_path, REPLAY_DATA_MAX, err, sizeof err);
    if (!log) {
        fprintf(stderr, "lagsimd: --replay: %s\n", err);
        return LAGSIMD_EXIT_RUNTIME;
    }
    if (use_input)
        printf("actuator lag: re-simulated from the commanded inputs logged on %s\n", ch_input);
    else if (lagged)
        printf("note: this scene has an actuator lag and the log has no %s records (lagsimd "
               "--log writes them; lcm-logger records only the bus): the applied effort "
               "changes within a control period and the log holds its last value, so each "
               "state is re-simulated from the logged one a period before it and the "
               "difference is approximate (give --tolerance)\n", ch_input);
    const int nq = sim.nq;
    const int64_t tpp = sc->ticks_per_period;
    const double dt = sc->sim.integrator.dt;
    const char *inexact = restart_inexact(&sim.def, lagged);

    int64_t seen = 0, compared = 0, restarts = 0, gaps = 0, undecodable = 0, invalid = 0;
    int64_t errors = 0, error_step = -1, unchecked = 0;
    const char *unchecked_why = NULL;
    lag_result error_kind = LAG_OK;
    double max_dq = 0, max_dqd = 0, max_deff = 0;
    bool have = false;       /* the sim holds a logged state to go on from */
    bool checking = false;   /* the sim's history is the daemon's: states are compared */
    bool have_u = false;     /* use_input: the input of the period starting at u_t */
    double u[LAG_MAX_DOF], u_t = 0;
    lag_log_record rec;
    int rc;
    while ((rc = lag_log_next(log, &rec)) == LAG_LOG_OK && !sets.failed) {
        if (strcmp(rec.channel, ch_event) == 0) {
            set_read(&sets, &rec, o);
            continue;
        }
        if (strcmp(rec.channel, ch_ref) == 0) {
            /* the reference as published, against the one computed again at its time */
            refs_seen++;
            lag_wire_reference lr, cr;
            if (!rec.data || lag_wire_decode_reference(rec.data, rec.size, LAG_WIRE_MAX_JOINTS,
                                                       &lr) != LAG_WIRE_OK) {
                refs_bad++;
                continue;
            }
            lagsimd_reference_at(&sets.ref, sc->sim.model.kind, lr.sim_time, lr.step, &cr);
            bool same = cr.num_joints == lr.num_joints && lr.sim_time == (double)lr.step * dt;
            for (int k = 0; same && k < lr.num_joints; k++) same = !strcmp(cr.name[k], lr.name[k]);
            if (!same) {
                refs_bad++;
                continue;
            }
            for (int k = 0; k < lr.num_joints; k++) {
                double a = fabs(cr.r[k] - lr.r[k]), b = fabs(cr.rdot[k] - lr.rdot[k]);
                if (!(a <= max_dr)) max_dr = a;
                if (!(b <= max_dr)) max_dr = b;
            }
            refs_compared++;
            continue;
        }
        if (use_input && strcmp(rec.channel, ch_input) == 0) {
            have_u = decode_input(&rec, info, nq, u, &u_t);
            continue;
        }
        if (strcmp(rec.channel, channel) != 0) continue;
        seen++;
        lag_wire_joint_state m;
        if (!rec.data ||
            lag_wire_decode_joint_state(rec.data, rec.size, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK) {
            undecodable++;
            continue;
        }
        bool ok = m.num_joints == nq;
        for (int i = 0; ok && i < nq; i++) ok = strcmp(m.name[i], info->joint_names[i]) == 0;
        if (!ok) {
            fprintf(stderr, "lagsimd: --replay: a state on %s does not match this scene's "
                            "joints (%s); wrong --config?\n", channel,
                    lag_model_info_get(sc->sim.model.kind)->name);
            lag_log_close(log);
            return LAGSIMD_EXIT_RUNTIME;
        }
        /* the daemon publishes finite numbers and steps from 0: anything else was not
         * published by it and cannot be checked */
        if (!lag_wire_all_finite(LAG_WIRE_JOINT_STATE, &m) || m.step < 0 ||
            m.step > REPLAY_STEP_MAX) {
            invalid++;
            continue;
        }
        /* both steps lie in [0, 2^53]: the difference cannot overflow */
        int64_t dticks = have ? m.step - sim.tick : -1;
        bool same = dticks == 0;
        double oq[LAG_MAX_DOF], oqd[LAG_MAX_DOF];
        lag_sim_observe(&sim, oq, oqd);
        for (int i = 0; same && i < nq; i++)
            same = oq[i] == m.position[i] && oqd[i] == m.velocity[i];
        /* a period with an actuator lag needs its logged input */
        bool input_missing = use_input && dticks == tpp && !(have_u && u_t == lag_sim_time(&sim));
        bool is_gap = have && dticks > 0 && (dticks != tpp || input_missing);
        if (!have || dticks < 0 || (dticks == 0 && !same) || is_gap) {
            /* changes read before this state happened before it */
            while (sets.n > 0 && set_apply(&sets, &sim, o, use_input, true)) {
            }
            if (sets.failed) break;
            inexact = restart_inexact(&sim.def, lagged);
            /* the first state, a reset (the step went back, or the state changed in
             * place), or a gap: start over from this state */
            if (is_gap) {
                gaps++;
                if (gaps <= REPLAY_GAPS_SAID)
                    printf("gap: %s between t = %.9g s and t = %.9g s (step %lld to %lld): "
                           "restarted from t = %.9g s%s\n",
                           input_missing ? "the period's logged input is missing"
                                         : "states missing",
                           lag_sim_time(&sim), (double)m.step * dt, (long long)sim.tick,
                           (long long)m.step, (double)m.step * dt,
                           checking && inexact ? ", not checked until the next reset" : "");
                else if (gaps == REPLAY_GAPS_SAID + 1)
                    printf("gap: more gaps follow, counted below\n");
            } else if (have) {
                restarts++;
            }
            bool initial = restart(&sim, &m);
            checking = initial || (m.step == 0 && !(sim.def.effects.enabled & LAG_EFF_NOISE)) ||
                       !inexact;
            if (!checking && !unchecked_why)
                unchecked_why = m.step == 0 ? "the logged state carries the noise effect, not "
                                              "the true state" : inexact;
            have = true;
            have_u = false;
            continue;
        }
        if (dticks > 0) {
            lag_sim_set_input(&sim, use_input ? u : m.effort);
            have_u = false;
            const int64_t applied = sets.applied;
            lag_result r = advance_with_sets(&sim, dticks, &sets, o, use_input);
            if (sets.failed) break;
            if (sets.applied != applied) inexact = restart_inexact(&sim.def, lagged);
            if (r != LAG_OK || sim.tick != m.step) {
                if (errors++ == 0) {
                    error_step = m.step;
                    error_kind = r;
                }
                restart(&sim, &m); /* go on from the logged state */
                checking = false;
                continue;
            }
        }
        if (!checking) {
            unchecked++;
            continue;
        }
        lag_sim_observe(&sim, oq, oqd); /* as the daemon published it (noise effect) */
        for (int i = 0; i < nq; i++) {
            double a = fabs(oq[i] - m.position[i]), b = fabs(oqd[i] - m.velocity[i]);
            if (!(a <= max_dq)) max_dq = a; /* NaN propagates as the max */
            if (!(b <= max_dqd)) max_dqd = b;
            if (use_input) {
                double c = fabs(sim.tau_applied[i] - m.effort[i]);
                if (!(c <= max_deff)) max_deff = c;
            }
        }
        compared++;
        /* a lag without its inputs: each period from the logged state before it, so that
         * the difference is that of one period, not one grown by an unstable plant */
        if (anchor) restart(&sim, &m);
    }
    lag_log_stats ls;
    lag_log_get_stats(log, &ls);
    if (rc == LAG_LOG_ERROR) {
        fprintf(stderr, "lagsimd: --replay: %s\n", lag_log_errmsg(log));
        lag_log_close(log);
        return LAGSIMD_EXIT_RUNTIME;
    }
    lag_log_close(log);
    if (sets.failed) return LAGSIMD_EXIT_RUNTIME;
    if (ls.damaged > 0)
        fprintf(stderr, "lagsimd: --replay: warning: %s is damaged in %lld place(s): %lld "
                        "bytes passed over\n",
                log_path, (long long)ls.damaged, (long long)ls.bytes_skipped);
    if (ls.truncated_bytes > 0)
        fprintf(stderr, "lagsimd: --replay: warning: the last record of %s is cut short "
                        "(%lld bytes; was the logger stopped while writing?)\n",
                log_path, (long long)ls.truncated_bytes);
    if (seen == 0) {
        fprintf(stderr, "lagsimd: --replay: no %s messages in %s (%lld records read)\n",
                channel, log_path, (long long)ls.records);
        return LAGSIMD_EXIT_RUNTIME;
    }
    printf("replay %s: %lld states compared on %s (%lld restarts at resets, %lld gaps, "
           "%lld undecodable, %lld integrator errors)\n",
           log_path, (long long)compared, channel, (long long)restarts, (long long)gaps,
           (long long)undecodable, (long long)errors);
    if (sets.applied > 0)
        printf("%lld change(s) made while running applied at their steps (set, kick, "
               "kicks_cleared and restore events on %s)\n",
               (long long)sets.applied, ch_event);
    if (unchecked > 0)
        printf("%lld states after a restart were not compared: %s\n", (long long)unchecked,
               unchecked_why ? unchecked_why : "the re-simulation failed before them");
    if (invalid > 0)
        printf("%lld states with a non-finite number or a step outside [0, 2^53] were "
               "not checked\n", (long long)invalid);
    if (errors > 0) {
        fprintf(stderr, "lagsimd: --replay: the re-simulation failed %lld time(s), first "
                        "towards step %lld (%s): the log could not be checked\n",
                (long long)errors, (long long)error_step,
                error_kind == LAG_OK ? "stopped at another step" : lag_result_string(error_kind));
        return LAGSIMD_EXIT_RUNTIME;
    }
    double max_diff = max_dq > max_dqd || isnan(max_dq) ? max_dq : max_dqd;
    if (max_deff > max_diff || isnan(max_deff)) max_diff = max_deff;
    if (isnan(max_diff)) {
        fprintf(stderr, "lagsimd: --replay: the re-simulation produced a non-finite state: "
                        "the log could not be checked\n");
        return LAGSIMD_EXIT_RUNTIME;
    }
    if (compared == 0) {
        fprintf(stderr, "lagsimd: --replay: %s: no state of %s follows another by one "
                        "control period (%lld ticks) from a state the re-simulation can "
                        "start from exactly: nothing could be checked\n",
                log_path, channel, (long long)tpp);
        return LAGSIMD_EXIT_RUNTIME;
    }
    printf("max |q - q_log| = %.17g\nmax |qd - qd_log| = %.17g\n", max_dq, max_dqd);
    if (use_input) printf("max |effort - effort_log| = %.17g\n", max_deff);
    if (refs_seen > 0 || sc->reference.n > 0) {
        printf("%lld references compared on %s (%lld of other joints, another time or "
               "undecodable)\nmax |r - r_log|, |rdot - rdot_log| = %.17g\n",
               (long long)refs_compared, ch_ref, (long long)refs_bad, max_dr);
        if (max_dr > max_diff || isnan(max_dr)) max_diff = max_dr;
        if (refs_bad > 0) {
            fprintf(stderr, "lagsimd: --replay: FAILED: %lld reference(s) on %s are not "
                            "this scene's (wrong --config or --set?)\n", (long long)refs_bad,
                    ch_ref);
            return LAGSIMD_EXIT_RUNTIME;
        }
    }
    printf("max difference = %.17g\n", max_diff);
    if (!(max_diff <= tolerance)) {
        fprintf(stderr, "lagsimd: --replay: FAILED: the largest difference %.17g is above "
                        "the tolerance %.17g: %s\n", max_diff, tolerance,
                anchor ? "the replay of this log is approximate (see the note above)"
                       : "the log does not match this scene and build (wrong --config or "
                         "--set, another build, or a changed log)");
        return LAGSIMD_EXIT_RUNTIME;
    }
    return LAGSIMD_EXIT_OK;
}
