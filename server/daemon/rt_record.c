/*
 * lagsimd --log: what the real-time server puts in its log, and what it says about it.
 *
 * Every message published (rt_wire.c's publish) and every command and control request
 * applied is handed to the log writer (rt_log.c) as it happens, so the log holds them in
 * the order the loop saw them. A received message goes in, as received, once its handler
 * knows its fate and before anything published in answer to it; refused and undecodable
 * ones and queries (status, describe) are counted and go in only while the sample's byte
 * bucket allows (RT_LOG_SAMPLE_BPS), so that a flood cannot fill the disk. With an actuator
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

#include "lagsim_clock.h"
#include "lagsim_log.h"
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
    r->sample_credit = RT_LOG_SAMPLE_BPS; /* a full bucket at start */
    r->sample_ns = now;
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

/* The sample's byte bucket at `now`: RT_LOG_SAMPLE_BPS bytes a second, as much in a
 * burst. Takes `bytes` and returns true when it holds them. */
static bool sample_take(rt_record *r, int64_t now, size_t bytes)
{
    if (now < r->sample_ns) r->sample_ns = now;
    r->sample_credit += (double)(now - r->sample_ns) * 1e-9 * RT_LOG_SAMPLE_BPS;
    if (r->sample_credit > RT_LOG_SAMPLE_BPS) r->sample_credit = RT_LOG_SAMPLE_BPS;
    r->sample_ns = now;
    if (r->sample_credit < (double)bytes) return false;
    r->sample_credit -= (double)bytes;
    return true;
}

void rt_log_rx_fate(rt_record *r, int64_t now, rt_rx_fate fate)
{
    if (!r->log || !r->rx_pending) return;
    r->rx_pending = false;
    if (fate != RT_RX_ACCEPTED) {
        if (fate == RT_RX_QUERY) r->rx_queries++;
        else r->rx_refused++;
        if (fate == RT_RX_UNDECODABLE) r->rx_undecodable++;
        size_t bytes = LAG_LOG_HEADER_SIZE + strlen(r->rx_channel) + r->rx_len;
        if (!sample_take(r, now, bytes)) return; /* counted only */
        r->rx_sampled++;
        r->rx_sampled_bytes += (int64_t)bytes;
    }
    rt_log_put(r->log, RT_LOG_IN, log_clock(r, now), r->rx_channel, r->rx_data,
               r->rx_len);
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

/* Refused messages and queries received and not written (the sample's bucket was empty). */
static int64_t unsampled(const rt_record *r)
{
    return r->rx_refused + r->rx_queries - r->rx_sampled;
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
        notes[nn] = (rt_record_note){"log_error", (double)st.error, ""};
        detail = notes[nn++].detail;
        snprintf(detail, sizeof notes->detail, "--log %s: writing failed after %lld bytes: "
                 "%s; the rest of the run is not logged", path, (long long)st.written,
                 strerror(st.error));
        if (r->quiet) fprintf(stderr, "lagsimd: %s\n", detail); /* else: the event's line */
    }
    /* a flood of refused messages: said in the log (and on the bus) at most once a
     * second, how many were counted without being written */
    if (unsampled(r) > r->unsampled_said && rt_limit_take(&r->lim_sample_said, now)) {
        notes[nn] = (rt_record_note){"log_sampled", (double)unsampled(r), ""};
        detail = notes[nn++].detail;
        snprintf(detail, sizeof notes->detail, "--log %s: received so far %lld refused "
                 "commands and control requests (%lld undecodable) and %lld status or describe "
                 "requests: %lld written as a sample (%lld bytes, at most %d a second), %lld "
                 "counted only",
                 path, (long long)r->rx_refused, (long long)r->rx_undecodable,
                 (long long)r->rx_queries, (long long)r->rx_sampled,
                 (long long)r->rx_sampled_bytes, RT_LOG_SAMPLE_BPS, (long long)unsampled(r));
        r->unsampled_said = unsampled(r);
    }
    if (lost(&st) > lost(&r->seen) && rt_limit_take(&r->lim_said, now)) {
        notes[nn] = (rt_record_note){"log_dropped", (double)lost(&st), ""};
        detail = notes[nn++].detail;
        snprintf(detail, sizeof notes->detail, "--log %s: %lld records not written so far (%lld "
                 "published and %lld received while the ring of %zu bytes was full, %lld too "
                 "large): the disk is slower than the run", path, (long long)lost(&st),
                 (long long)st.dropped_full, (long long)st.dropped_in, st.ring,
                 (long long)st.too_large);
        r->seen = st;
        if (r->quiet) fprintf(stderr, "lagsimd: %s\n", detail); /* else: the event's line */
    }
    return nn;
}

int rt_log_end(rt_record *r)
{
    if (!r->log) return 0;
    char path[256];
    snprintf(path, sizeof path, "%s", rt_log_path(r->log));
    rt_log_stats st;
    int rc = rt_log_close(r->log, RT_LOG_STALL_MS, &st);
    r->log = NULL;
    char refused[256] = "";
    if (unsampled(r) > 0)
        snprintf(refused, sizeof refused, "; received %lld refused commands and control "
                 "requests (%lld undecodable) and %lld status or describe requests: %lld "
                 "written as a sample, %lld counted only", (long long)r->rx_refused,
                 (long long)r->rx_undecodable, (long long)r->rx_queries,
                 (long long)r->rx_sampled, (long long)unsampled(r));
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
