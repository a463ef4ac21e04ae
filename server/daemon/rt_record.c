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
 * Timestamps (us) follow the log's own clock (rt_server.h, s->lg): a lockstep or fast run
 * is stamped at the pace of its sim time, so lcm-logplayer plays it back at 1x instead of
 * as one burst; each message's own utime still says when it was sent.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "lagsim_log.h"
#include "rt_server.h"

#define RT_LOG_STALL_MS 5000 /* at exit: a writer without progress this long is given up */

/* The log's clock at s->now, in us since the epoch; never earlier than the last one. */
static int64_t log_clock(rt_server *s)
{
    if (s->lg.base_us == 0) {
        s->lg.base_us = rt_wall_us();
        s->lg.prev_ns = s->now;
    }
    double sim_us = (double)s->lg.ticks * s->sc->sim.integrator.dt * 1e6;
    int64_t idle = s->lg.idle_ns + (s->lg.was_idle ? s->now - s->lg.prev_ns : 0);
    int64_t ts = rt_sat_add(rt_sat_add(s->lg.base_us, rt_sat_i64(sim_us + 0.5)), idle / 1000);
    if (ts < s->lg.last_us) ts = s->lg.last_us;
    s->lg.last_us = ts;
    return ts;
}

void rt_log_record(rt_server *s, rt_log_dir dir, const char *channel, const void *data,
                   size_t len)
{
    if (!s->lg.log) return;
    /* published while a received message is pending: in answer to it, which was accepted */
    if (s->lg.rx_pending) rt_log_rx_fate(s, RT_RX_ACCEPTED);
    rt_log_put(s->lg.log, dir, log_clock(s), channel, data, len);
}

void rt_log_rx_begin(rt_server *s, const char *channel, const void *data, size_t len)
{
    if (!s->lg.log) return;
    s->lg.rx_channel = channel;
    s->lg.rx_data = data;
    s->lg.rx_len = len;
    s->lg.rx_pending = true;
}

/* The sample's byte bucket at s->now: RT_LOG_SAMPLE_BPS bytes a second, as much in a
 * burst. Takes `bytes` and returns true when it holds them. */
static bool sample_take(rt_server *s, size_t bytes)
{
    if (s->now < s->lg.sample_ns) s->lg.sample_ns = s->now;
    s->lg.sample_credit += (double)(s->now - s->lg.sample_ns) * 1e-9 * RT_LOG_SAMPLE_BPS;
    if (s->lg.sample_credit > RT_LOG_SAMPLE_BPS) s->lg.sample_credit = RT_LOG_SAMPLE_BPS;
    s->lg.sample_ns = s->now;
    if (s->lg.sample_credit < (double)bytes) return false;
    s->lg.sample_credit -= (double)bytes;
    return true;
}

void rt_log_rx_fate(rt_server *s, rt_rx_fate fate)
{
    if (!s->lg.log || !s->lg.rx_pending) return;
    s->lg.rx_pending = false;
    if (fate != RT_RX_ACCEPTED) {
        if (fate == RT_RX_QUERY) s->lg.rx_queries++;
        else s->lg.rx_refused++;
        if (fate == RT_RX_UNDECODABLE) s->lg.rx_undecodable++;
        size_t bytes = LAG_LOG_HEADER_SIZE + strlen(s->lg.rx_channel) + s->lg.rx_len;
        if (!sample_take(s, bytes)) return; /* counted only */
        s->lg.rx_sampled++;
        s->lg.rx_sampled_bytes += (int64_t)bytes;
    }
    rt_log_put(s->lg.log, RT_LOG_IN, log_clock(s), s->lg.rx_channel, s->lg.rx_data,
               s->lg.rx_len);
}

void rt_log_rx_end(rt_server *s) { rt_log_rx_fate(s, RT_RX_ACCEPTED); }

void rt_log_input(rt_server *s)
{
    if (!s->lg.log || !s->lg.input) return;
    lag_wire_joint_command m;
    memset(&m, 0, sizeof m);
    m.utime = rt_wall_us();
    m.sim_time = lag_sim_time(&s->sim);
    int k = 0;
    for (int i = 0; i < s->nq && k < LAG_WIRE_MAX_JOINTS; i++) {
        if (!s->info->actuated[i]) continue;
        snprintf(m.name[k], sizeof m.name[k], "%s", s->info->joint_names[i]);
        m.effort[k] = s->sim.tau[i];
        k++;
    }
    m.num_joints = (int16_t)k;
    uint8_t buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode(LAG_WIRE_JOINT_COMMAND, &m, buf, sizeof buf);
    if (n > 0) rt_log_record(s, RT_LOG_OUT, s->lg.ch_input, buf, (size_t)n);
}

/* -q: the terminal shows no event lines, but what the log lost is still said. */
static bool quiet(const rt_server *s) { return s->opts && s->opts->quiet; }

/* Records lost so far, but those refused after a failed write (said once, with it). */
static int64_t lost(const rt_log_stats *st)
{
    return st->dropped_full + st->dropped_in + st->too_large;
}

/* Refused messages and queries received and not written (the sample's bucket was empty). */
static int64_t unsampled(const rt_server *s)
{
    return s->lg.rx_refused + s->lg.rx_queries - s->lg.rx_sampled;
}

void rt_log_check(rt_server *s, bool running)
{
    if (s->lg.was_idle) s->lg.idle_ns += s->now - s->lg.prev_ns;
    s->lg.prev_ns = s->now;
    s->lg.was_idle = !running;
    if (!s->lg.log) return;
    rt_log_stats st;
    rt_log_get_stats(s->lg.log, &st);
    const char *path = rt_log_path(s->lg.log);
    char detail[320];
    if (st.error != 0 && !s->lg.error_said) {
        s->lg.error_said = true;
        snprintf(detail, sizeof detail, "--log %s: writing failed after %lld bytes: %s; the rest "
                 "of the run is not logged", path, (long long)st.written, strerror(st.error));
        if (quiet(s)) fprintf(stderr, "lagsimd: %s\n", detail); /* else: the event's line */
        rt_publish_event(s, "log_error", "", (double)st.error, detail);
    }
    /* a flood of refused messages: said in the log (and on the bus) at most once a
     * second, how many were counted without being written */
    if (unsampled(s) > s->lg.unsampled_said && rt_limit_take(&s->lg.lim_sample_said, s->now)) {
        snprintf(detail, sizeof detail, "--log %s: received so far %lld refused commands and "
                 "control requests (%lld undecodable) and %lld status or describe requests: "
                 "%lld written as a sample (%lld bytes, at most %d a second), %lld counted only",
                 path, (long long)s->lg.rx_refused, (long long)s->lg.rx_undecodable,
                 (long long)s->lg.rx_queries, (long long)s->lg.rx_sampled,
                 (long long)s->lg.rx_sampled_bytes, RT_LOG_SAMPLE_BPS, (long long)unsampled(s));
        s->lg.unsampled_said = unsampled(s);
        rt_publish_event(s, "log_sampled", "", (double)unsampled(s), detail);
    }
    if (lost(&st) > lost(&s->lg.seen) && rt_limit_take(&s->lg.lim_said, s->now)) {
        snprintf(detail, sizeof detail, "--log %s: %lld records not written so far (%lld "
                 "published and %lld received while the ring of %zu bytes was full, %lld too "
                 "large): the disk is slower than the run", path, (long long)lost(&st),
                 (long long)st.dropped_full, (long long)st.dropped_in, st.ring,
                 (long long)st.too_large);
        s->lg.seen = st;
        if (quiet(s)) fprintf(stderr, "lagsimd: %s\n", detail); /* else: the event's line */
        rt_publish_event(s, "log_dropped", "", (double)lost(&st), detail);
    }
}

int rt_log_end(rt_server *s)
{
    if (!s->lg.log) return 0;
    char path[256];
    snprintf(path, sizeof path, "%s", rt_log_path(s->lg.log));
    rt_log_stats st;
    int rc = rt_log_close(s->lg.log, RT_LOG_STALL_MS, &st);
    s->lg.log = NULL;
    char refused[256] = "";
    if (unsampled(s) > 0)
        snprintf(refused, sizeof refused, "; received %lld refused commands and control "
                 "requests (%lld undecodable) and %lld status or describe requests: %lld "
                 "written as a sample, %lld counted only", (long long)s->lg.rx_refused,
                 (long long)s->lg.rx_undecodable, (long long)s->lg.rx_queries,
                 (long long)s->lg.rx_sampled, (long long)unsampled(s));
    if (rc == 0) {
        if (!quiet(s))
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
