/*
 * Offline runs: simulate a scene as fast as possible (no LCM) and write CSV.
 *
 * Rows at t = 0 and every output period (ticks_per_period * dt = 1/publish_hz) up to the
 * duration: t, q..., qd..., energy (T + U), every number the shortest decimal that reads
 * back to the same double (lagsim_num.h). A numeric fault stops the run: the rows so far
 * stay, LAG_ERR_RUNTIME (exit 1). So does SIGINT, SIGTERM or SIGHUP: the run stops within one chunk of ticks, the rows so far are
 * flushed and the summary says where it stopped.
 */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "daemon.h"
#include "lagsim_clock.h"
#include "lagsim_num.h"
#include "lagsim_out.h"
#include "rt_pace.h"

#define OFFLINE_CHUNK_TICKS 65536 /* ticks between two looks at the stop flag */

static volatile sig_atomic_t g_stop_signal;
static void on_stop_signal(int signo) { g_stop_signal = signo; }

/* One CSV row: t, q, qd as published (with the noise effect, if on), and the energy of
 * the true state; then, when the scene has a reference, r, r' and r'' of each joint that
 * has one (as lagsimd publishes them on <PREFIX>_REFERENCE). Returns <0 on write error. */
static int write_row(FILE *f, const lag_sim *sim, const lag_scene_reference *ref)
{
    char line[1024], a[LAG_NUM_LEN], b[LAG_NUM_LEN], c[LAG_NUM_LEN];
    double q[LAG_MAX_DOF], qd[LAG_MAX_DOF];
    lag_sim_observe(sim, q, qd);
    int n = snprintf(line, sizeof line, "%s", lag_num(lag_sim_time(sim), a));
    for (int i = 0; i < sim->nq; i++)
        n += snprintf(line + n, sizeof line - (size_t)n, ",%s", lag_num(q[i], a));
    for (int i = 0; i < sim->nq; i++)
        n += snprintf(line + n, sizeof line - (size_t)n, ",%s", lag_num(qd[i], a));
    n += snprintf(line + n, sizeof line - (size_t)n, ",%s", lag_num(lag_sim_energy(sim), a));
    if (ref->n > 0) {
        lag_wire_reference m;
        lagsimd_reference_at(ref, sim->def.model.kind, lag_sim_time(sim), sim->tick, &m);
        for (int k = 0; k < m.num_joints; k++)
            n += snprintf(line + n, sizeof line - (size_t)n, ",%s,%s,%s", lag_num(m.r[k], a),
                          lag_num(m.rdot[k], b), lag_num(m.rddot[k], c));
    }
    n += snprintf(line + n, sizeof line - (size_t)n, "\n");
    return fwrite(line, 1, (size_t)n, f) == (size_t)n ? 0 : -1;
}

/* t, q, q_dot, energy; then <joint>_ref, _ref_dot, _ref_ddot for the joints with a
 * reference (none without one: the columns before stay where they were) */
static void write_header(FILE *f, const lag_model_info *info, const lag_scene_reference *ref)
{
    fputs("t", f);
    for (int i = 0; i < info->nq; i++)
        fprintf(f, ",%s", info->joint_names[i]);
    for (int i = 0; i < info->nq; i++)
        fprintf(f, ",%s_dot", info->joint_names[i]);
    fputs(",energy", f);
    for (int i = 0; i < info->nq && i < LAG_MAX_DOF; i++)
        if (ref->on[i])
            fprintf(f, ",%s_ref,%s_ref_dot,%s_ref_ddot", info->joint_names[i],
                    info->joint_names[i], info->joint_names[i]);
    fputs("\n", f);
}

/* An offline run's state: the scene and options, the simulation, the CSV, where it is. */
typedef struct offline_run {
    const lag_scene *sc;
    const lagsimd_opts *o;
    lag_sim *sim;
    const lag_model_info *info; /* the sim's joints (a stick that may fly: h too) */
    int64_t nperiods;           /* output periods in the duration */
    FILE *f;                    /* the CSV, or NULL */
    bool to_stdout;
    struct sigaction old[3];    /* the signal handlers before the run */
    int64_t k;                  /* periods done */
    int64_t nevents;
    lag_result rc;
} offline_run;

static const int offline_signals[3] = {SIGINT, SIGTERM, SIGHUP};

/* Output periods in the duration: floor(duration / period), with a relative guard so that
 * 1 s at 100 Hz is 100 periods, not 99.999... A duration of more ticks than a run counts
 * exactly (2^53) is refused before anything is written. */
static lag_result offline_periods(offline_run *run)
{
    const double dt = run->sc->sim.integrator.dt;
    const double period = (double)run->sc->ticks_per_period * dt;
    const double duration = run->o->duration > 0.0 ? run->o->duration : 0.0;
    int64_t ticks = 0;
    if (duration > 0.0 && !rt_ticks_for(duration, dt, &ticks)) {
        fprintf(stderr, "lagsimd: --duration %g s is more than 2^53 ticks of dt %g s (the "
                        "longest run whose sim time is exact)\n", run->o->duration, dt);
        return LAG_ERR_USAGE;
    }
    run->nperiods = (int64_t)floor(duration / period * (1.0 + 1e-12) + 1e-9);
    return LAG_OK;
}

/* Opens --csv (by lag_out_open's rules; "-" is stdout) and writes the header and the row
 * at t = 0. A refused file is LAG_ERR_FILE (exit 2), one that cannot be opened
 * LAG_ERR_RUNTIME. */
static lag_result offline_open_csv(offline_run *run)
{
    static char csvbuf[1 << 20]; /* the CSV is written in large blocks */
    const lagsimd_opts *o = run->o;
    if (!o->csv) return LAG_OK;
    run->to_stdout = strcmp(o->csv, "-") == 0;
    if (!run->to_stdout) {
        const char *inputs[1] = {o->scene_name};
        char oerr[512];
        int fd = lag_out_open("--csv", o->csv, o->force, inputs, 1, 0, oerr, sizeof oerr);
        run->f = fd >= 0 ? fdopen(fd, "w") : NULL;
        if (!run->f) {
            if (fd >= 0) {
                snprintf(oerr, sizeof oerr, "--csv %s: %s", o->csv, strerror(errno));
                close(fd);
            }
            fprintf(stderr, "lagsimd: %s\n", oerr);
            return fd == LAG_OUT_REFUSED ? LAG_ERR_FILE : LAG_ERR_RUNTIME;
        }
    } else {
        run->f = stdout;
    }
    setvbuf(run->f, csvbuf, _IOFBF, sizeof csvbuf);
    write_header(run->f, run->info, &run->sc->reference);
    write_row(run->f, run->sim, &run->sc->reference);
    return LAG_OK;
}

/* A signal stops the run cleanly: the rows so far are flushed. on: install, else restore. */
static void offline_catch_signals(offline_run *run, bool on)
{
    struct sigaction sa = {.sa_handler = on_stop_signal};
    sigemptyset(&sa.sa_mask);
    if (on) g_stop_signal = 0;
    for (int i = 0; i < 3; i++)
        sigaction(offline_signals[i], on ? &sa : &run->old[i], on ? &run->old[i] : NULL);
}

/* One output period: its ticks in chunks, so that a signal is seen within one chunk;
 * continuous, as the whole period was before: dopri5 steps across chunk ends. Then the
 * effects' events (impacts, stops, stick/slip, ...): the first few on stderr. */
static lag_result offline_period(offline_run *run)
{
    lag_result r = LAG_OK;
    for (int64_t left = run->sc->ticks_per_period; left > 0 && r == LAG_OK && !g_stop_signal;) {
        int64_t n = left < OFFLINE_CHUNK_TICKS ? left : OFFLINE_CHUNK_TICKS;
        r = lag_sim_advance(run->sim, n, true);
        left -= n;
    }
    lag_event ev;
    while (lag_sim_poll_event(run->sim, &ev)) {
        if (!run->o->quiet && run->nevents < 20)
            fprintf(stderr, "lagsimd: event %s at t = %.9f s, joint %s, value %g\n",
                    lag_event_kind_name(ev.kind), ev.t,
                    ev.joint >= 0 ? run->info->joint_names[ev.joint] : "-", ev.value);
        run->nevents++;
    }
    return r;
}

/* The periods, a row after each, until the duration, a numeric fault (the rows so far
 * stay), a signal or a write error (reported when the CSV is closed). */
static void offline_loop(offline_run *run)
{
    const lag_scene *sc = run->sc;
    for (; run->k < run->nperiods && !g_stop_signal; run->k++) {
        lag_result r = offline_period(run);
        if (r != LAG_OK) {
            char t[LAG_NUM_LEN], dt[LAG_NUM_LEN];
            fprintf(stderr, "lagsimd: numeric fault at t = %s s (last good state): %s "
                            "(method %s, dt %s s)\n",
                    lag_num(lag_sim_time(run->sim), t), lag_result_string(r),
                    lag_method_name(sc->sim.integrator.method),
                    lag_num(sc->sim.integrator.dt, dt));
            run->rc = LAG_ERR_RUNTIME;
            break;
        }
        if (g_stop_signal) break; /* mid-period: no row */
        if (run->f && write_row(run->f, run->sim, &sc->reference) < 0)
            break; /* reported by offline_close_csv */
    }
    if (g_stop_signal) {
        char t[LAG_NUM_LEN];
        fprintf(stderr, "lagsimd: stopped by signal %d at t = %s s (%lld of %lld periods)\n",
                (int)g_stop_signal, lag_num(lag_sim_time(run->sim), t), (long long)run->k,
                (long long)run->nperiods);
        run->rc = LAG_ERR_RUNTIME;
    }
}

/* Flushes and closes the CSV: an error writing it fails the run. */
static void offline_close_csv(offline_run *run)
{
    if (!run->f) return;
    if (fflush(run->f) != 0 || ferror(run->f)) {
        fprintf(stderr, "lagsimd: error writing %s: %s\n",
                run->to_stdout ? "stdout" : run->o->csv, strerror(errno));
        run->rc = LAG_ERR_RUNTIME;
    }
    if (!run->to_stdout && fclose(run->f) != 0 && run->rc == LAG_OK) {
        fprintf(stderr, "lagsimd: error closing %s: %s\n", run->o->csv, strerror(errno));
        run->rc = LAG_ERR_RUNTIME;
    }
}

/* The summary line on stderr (not with -q). */
static void offline_summary(const offline_run *run, double e0, double cpu)
{
    const lag_scene *sc = run->sc;
    const lag_sim *sim = run->sim;
    double e1 = lag_sim_energy(sim);
    char dt[LAG_NUM_LEN], a[LAG_NUM_LEN], b[LAG_NUM_LEN];
    fprintf(stderr,
            "lagsimd: offline %s, %s dt %s s: %.6g s of sim time, %lld rows, "
            "%lld steps (%lld rejected), %lld rhs evals, %lld events, %.3g s CPU; "
            "energy %s -> %s J (change %.3g)\n",
            lag_model_info_get(sc->sim.model.kind)->name, lag_method_name(sc->sim.integrator.method),
            lag_num(sc->sim.integrator.dt, dt), lag_sim_time(sim), (long long)(run->k + 1),
            (long long)sim->stats.steps_accepted, (long long)sim->stats.steps_rejected,
            (long long)sim->stats.rhs_evals, (long long)run->nevents, cpu, lag_num(e0, a),
            lag_num(e1, b), e1 - e0);
}

lag_result lagsimd_offline(const lag_scene *sc, const lagsimd_opts *o)
{
    char err[512];
    static lag_sim sim; /* large-ish; static keeps it off the stack */
    if (lag_sim_init(&sim, &sc->sim, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "lagsimd: %s: %s\n", sc->path, err);
        return LAG_ERR_SCENE;
    }
    offline_run run = {.sc = sc, .o = o, .sim = &sim, .info = lag_sim_info(&sim), .rc = LAG_OK};
    lag_result r = offline_periods(&run);
    if (r == LAG_OK) r = offline_open_csv(&run);
    if (r != LAG_OK) return r;

    offline_catch_signals(&run, true);
    const double e0 = lag_sim_energy(&sim);
    const double c0 = lag_clock_process_cpu_s();
    offline_loop(&run);
    const double cpu = lag_clock_process_cpu_s() - c0;
    offline_catch_signals(&run, false);
    offline_close_csv(&run);
    if (!o->quiet) offline_summary(&run, e0, cpu);
    return run.rc;
}
