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
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <lcm/eventlog.h>

#include "daemon.h"
#include "lagsim/lagsim_joint_state_t.h"

int lagsimd_replay(const lag_scene *sc, const char *log_path, const lagsimd_opts *o)
{
    (void)o;
    char err[256];
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
    lcm_eventlog_t *log = lcm_eventlog_create(log_path, "r");
    if (!log) {
        fprintf(stderr, "lagsimd: --replay: cannot open %s\n", log_path);
        return LAGSIMD_EXIT_RUNTIME;
    }
    char channel[96];
    snprintf(channel, sizeof channel, "%s_STATE", sc->lcm.prefix);
    int nq = sim.nq;
    int64_t tpp = sc->ticks_per_period;

    int64_t compared = 0, restarts = 0, gaps = 0, undecodable = 0, errors = 0;
    double max_dq = 0, max_dqd = 0;
    bool have = false;
    lcm_eventlog_event_t *ev;
    while ((ev = lcm_eventlog_read_next_event(log)) != NULL) {
        if (strcmp(ev->channel, channel) != 0) {
            lcm_eventlog_free_event(ev);
            continue;
        }
        lagsim_joint_state_t m;
        if (lagsim_joint_state_t_decode(ev->data, 0, (int)ev->datalen, &m) < 0) {
            undecodable++;
            lcm_eventlog_free_event(ev);
            continue;
        }
        bool ok = m.num_joints == nq;
        for (int i = 0; ok && i < nq; i++)
            ok = strcmp(m.name[i], info->joint_names[i]) == 0 && isfinite(m.position[i]) &&
                 isfinite(m.velocity[i]) && isfinite(m.effort[i]);
        if (!ok) {
            fprintf(stderr, "lagsimd: --replay: a state on %s does not match this scene's "
                            "joints (%s); wrong --config?\n", channel, info->name);
            lagsim_joint_state_t_decode_cleanup(&m);
            lcm_eventlog_free_event(ev);
            lcm_eventlog_destroy(log);
            return LAGSIMD_EXIT_RUNTIME;
        }
        int64_t dticks = have ? m.step - sim.tick : -1;
        bool same = dticks == 0;
        double sq[LAG_MAX_DOF], sqd[LAG_MAX_DOF];
        lag_sim_observe(&sim, sq, sqd);
        for (int i = 0; same && i < nq; i++)
            same = sq[i] == m.position[i] && sqd[i] == m.velocity[i];
        if (dticks < 0 || (dticks == 0 && !same)) {
            /* first state, or a reset: start over from the scene's initial state if that
             * is what was published (a start or a plain reset), else from the logged one */
            lag_sim_reset(&sim, NULL, NULL);
            lag_sim_observe(&sim, sq, sqd);
            bool initial = m.step == 0;
            for (int i = 0; initial && i < nq; i++)
                initial = sq[i] == m.position[i] && sqd[i] == m.velocity[i];
            if (!initial) lag_sim_reset(&sim, m.position, m.velocity);
            sim.tick = m.step;
            if (have) restarts++;
            have = true;
        } else {
            if (dticks > 0) {
                if (dticks != tpp) gaps++; /* states missing from the log, or a fault */
                lag_sim_set_input(&sim, m.effort);
                lag_result r = LAG_OK;
                for (int64_t left = dticks; left > 0 && r == LAG_OK; left -= tpp)
                    r = lag_sim_advance(&sim, left < tpp ? left : tpp, false);
                if (r != LAG_OK) errors++;
            }
            double oq[LAG_MAX_DOF], oqd[LAG_MAX_DOF];
            lag_sim_observe(&sim, oq, oqd); /* as the daemon published it (noise effect) */
            for (int i = 0; i < nq; i++) {
                double a = fabs(oq[i] - m.position[i]), b = fabs(oqd[i] - m.velocity[i]);
                if (!(a <= max_dq)) max_dq = a; /* NaN propagates as the max */
                if (!(b <= max_dqd)) max_dqd = b;
            }
            compared++;
            if (sim.tick != m.step) errors++;
        }
        lagsim_joint_state_t_decode_cleanup(&m);
        lcm_eventlog_free_event(ev);
    }
    lcm_eventlog_destroy(log);
    if (!have) {
        fprintf(stderr, "lagsimd: --replay: no %s messages in %s\n", channel, log_path);
        return LAGSIMD_EXIT_RUNTIME;
    }
    if (lagged)
        printf("note: this scene has an actuator lag: the applied effort changes within a "
               "control period and the log holds its last value, so the difference is "
               "approximate\n");
    double max_diff = max_dq > max_dqd || isnan(max_dq) ? max_dq : max_dqd;
    printf("replay %s: %lld states compared on %s (%lld restarts at resets, %lld gaps, "
           "%lld undecodable, %lld integrator errors)\n",
           log_path, (long long)compared, channel, (long long)restarts, (long long)gaps,
           (long long)undecodable, (long long)errors);
    printf("max |q - q_log| = %.17g\nmax |qd - qd_log| = %.17g\nmax difference = %.17g\n",
           max_dq, max_dqd, max_diff);
    return LAGSIMD_EXIT_OK;
}
