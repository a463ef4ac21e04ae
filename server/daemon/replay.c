/*
 * lagsimd --replay LOG: re-simulates a run recorded by lcm-logger and reports how far the
 * re-simulation is from the logged states.
 *
 * Reads the <PREFIX>_STATE messages of the log in order. The first one sets the state
 * (q, qd) and the tick; each next one says which effort was applied over the ticks between
 * the two (joint_state_t.effort is the effort of the period that ended at its sim_time),
 * so the replay applies it for those ticks, in chunks of one control period with hard
 * stops at period ends exactly as the server does, and compares q and qd. A state whose
 * step goes back (a reset), or that differs at the same step, starts over from it.
 *
 * Published states carry the noise effect (lag_sim_observe) and the applied effort
 * (tau_applied); the replay compares observed with observed. Effects are re-simulated as
 * the scene defines them (disturbances at their times, noise as a function of seed and
 * tick), except the actuator: the logged effort is already its output, so the replay
 * applies it directly. A run that starts from the scene's initial state starts from it
 * (not from the logged, possibly noisy, first state). Only an actuator lag leaves the run
 * undetermined by the log (the effort changes within a period; the log has its last
 * value): the replay says so.
 *
 * For a run of the same scene and build recorded from its start (logger started before
 * the daemon), every difference is exactly 0: the daemon and the replay make the same
 * floating-point operations in the same order.
 *
 * The log is untrusted input. It is read by the bounded log reader and the bounded state
 * decoder of the wire module (server/wire): no length from the file is trusted, nothing
 * is allocated per record, a damaged stretch is passed over and reported, a file with no
 * record in its first LAG_LOG_SCAN_MAX bytes (or after one) is an error. A state is
 * re-simulated only across exactly one control period: a state whose step is not one
 * period after the last (states missing from the log, or a step counter out of range)
 * cannot be checked, so the replay starts over from it and counts it. The replay says
 * "checked" (exit 0) only when at least one state was compared and every re-simulation
 * succeeded; otherwise it reports why it could not check and exits 1.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "daemon.h"
#include "lagsim_log.h"
#include "lagsim_wire.h"

#define REPLAY_DATA_MAX 65536               /* a record larger than this is no state */
#define REPLAY_STEP_MAX (INT64_C(1) << 53)  /* steps beyond this are not a run's */

/* Starts over from logged state m: from the scene's initial state if that is what was
 * published (a start or a plain reset: the published one may carry noise), else from
 * the logged one. */
static void restart(lag_sim *sim, const lag_wire_joint_state *m)
{
    double sq[LAG_MAX_DOF], sqd[LAG_MAX_DOF];
    lag_sim_reset(sim, NULL, NULL);
    lag_sim_observe(sim, sq, sqd);
    bool initial = m->step == 0;
    for (int i = 0; initial && i < sim->nq; i++)
        initial = sq[i] == m->position[i] && sqd[i] == m->velocity[i];
    if (!initial) lag_sim_reset(sim, m->position, m->velocity);
    sim->tick = m->step;
}

int lagsimd_replay(const lag_scene *sc, const char *log_path, const lagsimd_opts *o)
{
    (void)o;
    char err[512];
    lag_sim sim;
    /* The logged effort is the actuator's output: apply it as it is. The actuator stays
     * on with neither lag nor bound, so that the ticks are taken exactly as the daemon
     * took them (an actuator makes every tick a separate step). */
    lag_sim_def def = sc->sim;
    bool lagged = false;
    if (def.effects.enabled & LAG_EFF_ACTUATOR)
        for (int i = 0; i < def.model.nq; i++) {
            lagged |= def.effects.actuator_tau[i] > 0;
            def.effects.actuator_tau[i] = 0.0;
            def.effects.actuator_max[i] = INFINITY;
        }
    if (lag_sim_init(&sim, &def, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "lagsimd: bad scene: %s\n", err);
        return LAGSIMD_EXIT_USAGE;
    }
    const lag_model_info *info = lag_model_info_get(sc->sim.model.kind);
    lag_log *log = lag_log_open(log_path, REPLAY_DATA_MAX, err, sizeof err);
    if (!log) {
        fprintf(stderr, "lagsimd: --replay: %s\n", err);
        return LAGSIMD_EXIT_RUNTIME;
    }
    char channel[96];
    snprintf(channel, sizeof channel, "%s_STATE", sc->lcm.prefix);
    int nq = sim.nq;
    int64_t tpp = sc->ticks_per_period;

    int64_t seen = 0, compared = 0, restarts = 0, gaps = 0, undecodable = 0, invalid = 0;
    int64_t errors = 0, error_step = -1;
    lag_result error_kind = LAG_OK;
    double max_dq = 0, max_dqd = 0;
    bool have = false;   /* the sim holds a logged state to go on from */
    lag_log_record rec;
    int rc;
    while ((rc = lag_log_next(log, &rec)) == LAG_LOG_OK) {
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
                            "joints (%s); wrong --config?\n", channel, info->name);
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
        if (!have || dticks < 0 || (dticks == 0 && !same)) {
            /* first state, or a reset (the step went back, or the state changed in place) */
            if (have) restarts++;
            restart(&sim, &m);
            have = true;
            continue;
        }
        if (dticks > 0 && dticks != tpp) {
            /* states missing from the log: the efforts in between are unknown */
            gaps++;
            restart(&sim, &m);
            continue;
        }
        if (dticks > 0) {
            lag_sim_set_input(&sim, m.effort);
            lag_result r = lag_sim_advance(&sim, dticks, false);
            if (r != LAG_OK || sim.tick != m.step) {
                if (errors++ == 0) {
                    error_step = m.step;
                    error_kind = r;
                }
                restart(&sim, &m); /* go on from the logged state */
                continue;
            }
        }
        lag_sim_observe(&sim, oq, oqd); /* as the daemon published it (noise effect) */
        for (int i = 0; i < nq; i++) {
            double a = fabs(oq[i] - m.position[i]), b = fabs(oqd[i] - m.velocity[i]);
            if (!(a <= max_dq)) max_dq = a; /* NaN propagates as the max */
            if (!(b <= max_dqd)) max_dqd = b;
        }
        compared++;
    }
    lag_log_stats ls;
    lag_log_get_stats(log, &ls);
    if (rc == LAG_LOG_ERROR) {
        fprintf(stderr, "lagsimd: --replay: %s\n", lag_log_errmsg(log));
        lag_log_close(log);
        return LAGSIMD_EXIT_RUNTIME;
    }
    lag_log_close(log);
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
    if (lagged)
        printf("note: this scene has an actuator lag: the applied effort changes within a "
               "control period and the log holds its last value, so the difference is "
               "approximate\n");
    printf("replay %s: %lld states compared on %s (%lld restarts at resets, %lld gaps, "
           "%lld undecodable, %lld integrator errors)\n",
           log_path, (long long)compared, channel, (long long)restarts, (long long)gaps,
           (long long)undecodable, (long long)errors);
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
    if (isnan(max_diff)) {
        fprintf(stderr, "lagsimd: --replay: the re-simulation produced a non-finite state: "
                        "the log could not be checked\n");
        return LAGSIMD_EXIT_RUNTIME;
    }
    if (compared == 0) {
        fprintf(stderr, "lagsimd: --replay: %s: no state of %s follows another by one "
                        "control period (%lld ticks): nothing could be checked\n",
                log_path, channel, (long long)tpp);
        return LAGSIMD_EXIT_RUNTIME;
    }
    printf("max |q - q_log| = %.17g\nmax |qd - qd_log| = %.17g\nmax difference = %.17g\n",
           max_dq, max_dqd, max_diff);
    return LAGSIMD_EXIT_OK;
}
