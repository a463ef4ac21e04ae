/*
 * lagsimd --log: what the real-time server puts in its log, and what it says about it.
 *
 * Every message published (rt_wire.c's publish) and every command and control request
 * applied is handed to the log writer (rt_log.c) as it happens, so the log holds them in
 * the order the loop saw them. A received message goes in, as received, once its handler
 * knows its fate and before anything published in answer to it; each is counted, and goes
 * in only while its kind's byte bucket allows (rt_record.h: accepted ones, room for two
 * commands a control period; refused, undecodable ones and queries, a sample), so that no
 * flood can fill the disk. With an actuator
 * lag the effort applied changes within a control period, and the state's `effort` holds
 * only its last value; the log then also holds, at the start of every period, the
 * commanded input the period runs with (<PREFIX>_INPUT, a joint_command_t whose sim_time
 * is the period's start), from which --replay re-simulates the lag exactly.
 *
 * Timestamps (us) follow the log's own clock (rt_record.h): a lockstep or fast run
 * is stamped at the pace of its sim time, so lcm-logplayer plays it back at 1x instead of
 * as one burst; each message's own utime still says when it was sent.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "daemon.h"
#include "lagsim_clock.h"
#include "lagsim_log.h"
#include "lagsim_out.h"
#include "lagsim_wire.h"
#include "rt_record.h"

#define RT_LOG_STALL_MS 5000 /* at exit: a writer without progress this long is given up */

/* The log's clock at `now`, in us since the epoch; never earlier than the last one. */
static int64_t log_clock(rt_record *r, int64_t now)
{
    if (r->base_us == 0) {
        r->base_us = lag_clock_wall_us();
        r->prev_ns = now;
    }
    double sim_us = (double)r->ticks * r->dt * 1e6;
    int64_t idle = r->idle_ns + (r->was_idle ? now - r->prev_ns : 0);
    int64_t ts = rt_sat_add(rt_sat_add(r->base_us, rt_sat_i64(sim_us + 0.5)), idle / 1000);
    if (ts < r->last_us) ts = r->last_us;
    r->last_us = ts;
    return ts;
}

void rt_record_init(rt_record *r, double dt, bool quiet, int64_t now)
{
    r->dt = dt;
    r->quiet = quiet;
    rt_limit_init(&r->lim_said, 1, 1, now);
    rt_limit_init(&r->lim_sample_said, 1, 1, now);
    /* full at start */
    r->sample = (rt_log_bucket){.rate = RT_LOG_SAMPLE_BPS, .credit = RT_LOG_SAMPLE_BPS};
    r->accepted = (rt_log_bucket){.rate = RT_LOG_ACCEPTED_MIN_BPS,
                                  .credit = RT_LOG_ACCEPTED_MIN_BPS};
}

/* The accepted messages' rate: RT_LOG_ACCEPTED_PER_PERIOD full commands (every actuated
 * joint named, as the log holds them) per control period, at least
 * RT_LOG_ACCEPTED_MIN_BPS. */
static double accepted_rate(const lag_scene *sc)
{
    const lag_model_info *info = lag_model_info_get(sc->sim.model.kind);
    char channel[LAG_BUS_CHANNEL_LEN];
    int len = lag_bus_channel_name(channel, sizeof channel, sc->lcm.prefix, LAG_BUS_COMMAND);
    if (!info || len < 0 || (size_t)len >= sizeof channel) return RT_LOG_ACCEPTED_MIN_BPS;
    lag_wire_joint_command m;
    memset(&m, 0, sizeof m);
    for (int i = 0; i < info->nq && m.num_joints < LAG_WIRE_MAX_JOINTS; i++)
        if (info->actuated[i])
            snprintf(m.name[m.num_joints++], sizeof m.name[0], "%s", info->joint_names[i]);
    uint8_t buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode(LAG_WIRE_JOINT_COMMAND, &m, buf, sizeof buf);
    double record = LAG_LOG_HEADER_SIZE + (double)strlen(channel) + (n > 0 ? n : 0);
    double rate = RT_LOG_ACCEPTED_PER_PERIOD * sc->publish_hz * record;
    return rate > RT_LOG_ACCEPTED_MIN_BPS ? rate : RT_LOG_ACCEPTED_MIN_BPS;
}

int rt_record_open(rt_record *r, const lag_scene *sc, const lagsimd_opts *o, char *err,
                   size_t errlen)
{
    r->accepted.rate = r->accepted.credit = accepted_rate(sc);
    rt_log_conf c = {.path = o->log, .ring = o->log_ring ? o->log_ring : RT_LOG_RING_DEFAULT,
                     .force = o->force, .series = o->log_increment, .keep = o->log_keep,
                     .split = o->log_split, .input = o->scene_name};
    r->log = rt_log_open(&c, NULL, err, errlen);
    if (!r->log) return -1;
    r->files_said = 1;
    if (!c.series) return 0;
    char name[4096], kept[160] = "";
    rt_log_file(r->log, name, sizeof name);
    rt_log_stats st;
    rt_log_get_stats(r->log, &st);
    if (c.keep > 0)
        snprintf(kept, sizeof kept, "; --keep %d: %lld older removed (%lld bytes)%s%s", c.keep,
                 (long long)st.removed, (long long)st.removed_bytes,
                 st.prune_error ? ", a removal failed: " : "",
                 st.prune_error ? strerror(st.prune_error) : "");
    r->prune_said = st.prune_error;
    /* with -q too: which file of the series this run writes is not said anywhere else */
    fprintf(stderr, "lagsimd: --log %s --increment: writing %s%s\n", o->log, name, kept);
    return 0;
}

void rt_log_record(rt_record *r, int64_t now, rt_log_dir dir, const char *channel,
                   const void *data, size_t len)
{
    if (!r->log) return;
    /* published while a received message is pending: in answer to it, which was accepted */
    if (r->rx_pending) rt_log_rx_fate(r, now, RT_RX_ACCEPTED);
    rt_log_put(r->log, dir, log_clock(r, now), channel, data, len);
}

void rt_log_rx_begin(rt_record *r, const char *channel, const void *data, size_t len)
{
    if (!r->log) return;
    r->rx_channel = channel;
    r->rx_data = data;
    r->rx_len = len;
    r->rx_pending = true;
}

/* A byte bucket at `ts` (the log's clock, us) and `now` (the loop's, ns): it fills with the
 * time since its first take on whichever of the two clocks ran more (the log's runs ahead
 * of the wall in a fast or lockstep run; neither sim time nor the paused state advances
 * while a flood of pauses and resumes holds the run back). Takes `bytes` and returns true
 * when it holds them. */
static bool bucket_take(rt_log_bucket *b, int64_t ts, int64_t now, size_t bytes)
{
    if (b->start_us == 0) {
        b->start_us = ts;
        b->start_ns = now;
    }
    double log_s = (double)(ts - b->start_us) * 1e-6, wall_s = (double)(now - b->start_ns) * 1e-9;
    double t = log_s > wall_s ? log_s : wall_s;
    if (t > b->t) {
        b->credit += (t - b->t) * b->rate;
        b->t = t;
    }
    if (b->credit > b->rate) b->credit = b->rate;
    if (b->credit < (double)bytes) return false;
    b->credit -= (double)bytes;
    return true;
}

void rt_log_rx_fate(rt_record *r, int64_t now, rt_rx_fate fate)
{
    if (!r->log || !r->rx_pending) return;
    r->rx_pending = false;
    size_t bytes = LAG_LOG_HEADER_SIZE + strlen(r->rx_channel) + r->rx_len;
    int64_t ts = log_clock(r, now);
    /* written: counted as such only once the ring took it (a full ring's drop is the
     * log's own count), so that the summary says what the log holds */
    if (fate == RT_RX_ACCEPTED) {
        r->rx_accepted++;
        if (!bucket_take(&r->accepted, ts, now, bytes)) return; /* counted only */
        if (!rt_log_put(r->log, RT_LOG_IN, ts, r->rx_channel, r->rx_data, r->rx_len)) return;
        r->rx_accepted_written++;
        r->rx_accepted_bytes += (int64_t)bytes;
    } else {
        if (fate == RT_RX_QUERY) r->rx_queries++;
        else r->rx_refused++;
        if (fate == RT_RX_UNDECODABLE) r->rx_undecodable++;
        if (!bucket_take(&r->sample, ts, now, bytes)) return; /* counted only */
        if (!rt_log_put(r->log, RT_LOG_IN, ts, r->rx_channel, r->rx_data, r->rx_len)) return;
        r->rx_sampled++;
        r->rx_sampled_bytes += (int64_t)bytes;
    }
}

void rt_log_rx_end(rt_record *r, int64_t now) { rt_log_rx_fate(r, now, RT_RX_ACCEPTED); }

void rt_log_input(rt_record *r, int64_t now, const lag_sim *sim, const lag_model_info *info)
{
    if (!r->log || !r->input) return;
    lag_wire_joint_command m;
    memset(&m, 0, sizeof m);
    m.utime = lag_clock_wall_us();
    m.sim_time = lag_sim_time(sim);
    int k = 0;
    for (int i = 0; i < sim->nq && k < LAG_WIRE_MAX_JOINTS; i++) {
        if (!info->actuated[i]) continue;
        snprintf(m.name[k], sizeof m.name[k], "%s", info->joint_names[i]);
        m.effort[k] = sim->tau[i];
        k++;
    }
    m.num_joints = (int16_t)k;
    uint8_t buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode(LAG_WIRE_JOINT_COMMAND, &m, buf, sizeof buf);
    if (n > 0) rt_log_record(r, now, RT_LOG_OUT, r->ch_input, buf, (size_t)n);
}

/* Records lost so far, but those refused after a failed write (said once, with it). */
static int64_t lost(const rt_log_stats *st)
{
    return st->dropped_full + st->dropped_in + st->too_large;
}

/* Received messages not written (their buckets were empty): refused ones and queries,
 * and accepted ones. */
static int64_t unsampled(const rt_record *r)
{
    return r->rx_refused + r->rx_queries - r->rx_sampled +
           (r->rx_accepted - r->rx_accepted_written);
}

/* What became of the received messages, for the log_sampled event and the summary: the
 * refused ones' part, then the accepted ones' (when any was not written). OUT: out */
static void said_received(const rt_record *r, char *out, size_t n)
{
    int w = snprintf(out, n, "received %lld refused commands and control requests (%lld "
                     "undecodable) and %lld status or describe requests: %lld written as a "
                     "sample, %lld counted only", (long long)r->rx_refused,
                     (long long)r->rx_undecodable, (long long)r->rx_queries,
                     (long long)r->rx_sampled,
                     (long long)(r->rx_refused + r->rx_queries - r->rx_sampled));
    if (w > 0 && (size_t)w < n && r->rx_accepted > r->rx_accepted_written)
        snprintf(out + w, n - (size_t)w, "; applied %lld commands and control requests: %lld "
                 "written (at most %.0f bytes a second), %lld counted only",
                 (long long)r->rx_accepted, (long long)r->rx_accepted_written,
                 r->accepted.rate, (long long)(r->rx_accepted - r->rx_accepted_written));
}

/* A note for the loop to publish: returns its detail, to be written. */
static char *note(rt_record_note *notes, int *nn, const char *kind, double value)
{
    notes[*nn] = (rt_record_note){kind, value, ""};
    return notes[(*nn)++].detail;
}

/* A series that went on in its next file (--split-mb) since the last check, and what
 * --keep removed. */
static void check_split(rt_record *r, const rt_log_stats *st, rt_record_note *notes, int *nn)
{
    if (st->files <= r->files_said && st->prune_error == r->prune_said) return;
    char name[4096];
    rt_log_file(r->log, name, sizeof name);
    char *detail = note(notes, nn, "log_split", (double)st->files);
    snprintf(detail, sizeof notes->detail, "--log %.100s: writing %.120s (file %lld of this "
             "run); older removed by --keep: %lld (%lld bytes)%s%s", rt_log_path(r->log),
             name, (long long)st->files, (long long)st->removed, (long long)st->removed_bytes,
             st->prune_error ? "; a removal failed: " : "",
             st->prune_error ? strerror(st->prune_error) : "");
    r->files_said = st->files;
    r->prune_said = st->prune_error;
    if (r->quiet) fprintf(stderr, "lagsimd: %s\n", detail); /* else: the event's line */
}

int rt_log_check(rt_record *r, int64_t now, bool running, rt_record_note *notes)
{
    int nn = 0;
    if (r->was_idle) r->idle_ns += now - r->prev_ns;
    r->prev_ns = now;
    r->was_idle = !running;
    if (!r->log) return 0;
    rt_log_stats st;
    rt_log_get_stats(r->log, &st);
    const char *path = rt_log_path(r->log);
    char *detail;
    if (st.error != 0 && !r->error_said) {
        r->error_said = true;
        detail = note(notes, &nn, "log_error", (double)st.error);
        snprintf(detail, sizeof notes->detail, "--log %.160s: writing failed after %lld bytes: "
                 "%s; the rest of the run is not logged", path, (long long)st.written,
                 strerror(st.error));
        if (r->quiet) fprintf(stderr, "lagsimd: %s\n", detail); /* else: the event's line */
    }
    check_split(r, &st, notes, &nn);
    /* a flood: said in the log (and on the bus) at most once a second, how many received
     * messages were counted without being written */
    if (unsampled(r) > r->unsampled_said && rt_limit_take(&r->lim_sample_said, now)) {
        char what[300];
        said_received(r, what, sizeof what);
        detail = note(notes, &nn, "log_sampled", (double)unsampled(r));
        snprintf(detail, sizeof notes->detail, "--log: %s", what);
        r->unsampled_said = unsampled(r);
    }
    if (lost(&st) > lost(&r->seen) && rt_limit_take(&r->lim_said, now)) {
        detail = note(notes, &nn, "log_dropped", (double)lost(&st));
        snprintf(detail, sizeof notes->detail, "--log %.100s: %lld records not written so far "
                 "(%lld published and %lld received while the ring of %zu bytes was full, %lld "
                 "too large): the disk is slower than the run", path, (long long)lost(&st),
                 (long long)st.dropped_full, (long long)st.dropped_in, st.ring,
                 (long long)st.too_large);
        r->seen = st;
        if (r->quiet) fprintf(stderr, "lagsimd: %s\n", detail); /* else: the event's line */
    }
    return nn;
}

/* The files a run wrote: FILE, or the series' first to last. OUT: out */
static void said_files(const char *path, const rt_log_stats *st, char *out, size_t n)
{
    char first[4096], last[4096];
    if (!st->series || lag_out_series_name(path, st->number, last, sizeof last) != 0) {
        snprintf(out, n, "%s", path);
        return;
    }
    if (st->files <= 1) {
        snprintf(out, n, "%s", last);
        return;
    }
    lag_out_series_name(path, st->first, first, sizeof first);
    snprintf(out, n, "%s to %s (%lld files; older removed by --keep: %lld)", first, last,
             (long long)st->files, (long long)st->removed);
}

int rt_log_end(rt_record *r)
{
    if (!r->log) return 0;
    char base[4096], path[8400];
    snprintf(base, sizeof base, "%s", rt_log_path(r->log));
    rt_log_stats st;
    int rc = rt_log_close(r->log, RT_LOG_STALL_MS, &st);
    r->log = NULL;
    said_files(base, &st, path, sizeof path);
    char refused[600] = "";
    if (unsampled(r) > 0) {
        refused[0] = ';';
        refused[1] = ' ';
        said_received(r, refused + 2, sizeof refused - 2);
    }
    if (rc == 0) {
        if (!r->quiet)
            fprintf(stderr, "lagsimd: --log %s: %lld records, %lld bytes, complete%s\n", path,
                    (long long)st.records, (long long)st.bytes, refused);
        return 0;
    }
    fprintf(stderr, "lagsimd: --log %s is INCOMPLETE: %lld of the %lld bytes of the %lld "
            "records handed to the writer reached the file; %lld more were refused (%lld "
            "published and %lld received while the ring of %zu bytes was full, %lld too large, "
            "%lld after the write failed)%s%s\n",
            path, (long long)st.written, (long long)st.bytes, (long long)st.records,
            (long long)(lost(&st) + st.dropped_failed), (long long)st.dropped_full,
            (long long)st.dropped_in, st.ring, (long long)st.too_large,
            (long long)st.dropped_failed, st.error ? ": " : "",
            st.error == ETIMEDOUT ? "the writer made no progress for 5 s and was stopped"
            : st.error ? strerror(st.error) : "");
    return -1;
}
