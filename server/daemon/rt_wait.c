/*
 * A plant never waits in silence. Whenever the run does not advance, the daemon knows
 * what it waits for and says so: in every status (waiting_for, waiting_s, waiting_got)
 * and in one line on stderr (unless -q) after 3 s of the wait, 6 s, 12 s, ... doubling up
 * to a line a minute:
 *
 *   lagsimd: DIPC waits 6 s for the first command on DIPC_COMMAND at
 *   udpm://239.255.76.67:7668?ttl=0; got instead: 3 commands rejected (unknown joint 3;
 *   the last: unknown joint: 'cart'; joints of dipc: theta0 (actuated), theta1, theta2)
 *
 * The waits: the first command (realtime.start: first_command, or after a reset), in
 * lockstep a command answering the state published (shown once it lasted RT_WAIT_SHOW_NS:
 * a lockstep round trip is a wait too, a short one), RESUME or STEP while paused, RESET
 * while in the fault state. What came instead, since the wait began: commands rejected
 * (by reason, and the last one's reason), commands heard on the state URL (the port
 * before the command port: a controller that publishes on the wrong port), answers that
 * are stale, by what they answered instead: another sim_time, another generation, or no
 * generation at all (a command of generation 0, which lockstep never takes: a controller
 * that builds its commands by hand and copies the state's sim_time alone), this plant's
 * control requests on the state URL, and control requests for a prefix no plant here
 * has (rt_foreign.h: a controller or a tool on a misspelt prefix), by request:
 *
 *   lagsimd: MANIPULATOR waits 3 s for the first command on MANIPULATOR_COMMAND at
 *   udpm://239.255.76.67:7668?ttl=0; got instead: requests for a prefix no plant here
 *   has, on the command port 7668: MANIPULATR (DESCRIBE 12); this plant is MANIPULATOR
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "lagsim_wire.h"
#include "rt_wait.h"

#define RT_WAIT_SHOW_NS RT_NS_PER_S         /* a lockstep wait is said after 1 s */
#define RT_WAIT_LINE_NS (3 * RT_NS_PER_S)   /* the first line after 3 s of a wait, */
#define RT_WAIT_LINE_MAX_NS (60 * RT_NS_PER_S) /* then at gaps as long as the wait, <= 1 min */

void rt_wait_init(rt_wait *w, const lag_bus *bus, const char *prefix, bool lockstep)
{
    w->bus = bus;
    w->prefix = prefix;
    w->lockstep = lockstep;
}

void rt_wait_update(rt_wait *w, int64_t now, const rt_wait_seen *seen, rt_term *term)
{
    rt_wait_kind k = seen->kind;
    double t = seen->t;
    if (k != w->kind || (k != RT_WAIT_NONE && t != w->t)) {
        w->kind = k;
        w->t = t;
        w->since_ns = now;
        w->next_line_ns = rt_sat_add(now, RT_WAIT_LINE_NS);
        memcpy(w->rejected0, seen->rejected, sizeof w->rejected0);
        memcpy(w->stale0, seen->stale, sizeof w->stale0);
        w->wrong_port0 = seen->wrong_port;
        if (seen->foreign) rt_foreign_copy(&w->foreign0, seen->foreign);
        else memset(&w->foreign0, 0, sizeof w->foreign0);
    }
    if (k == RT_WAIT_NONE || now < w->next_line_ns) return;
    /* 3, 6, 12, 24, 48 s, then every minute: a wait nobody answers does not fill the
     * terminal */
    int64_t gap = now - w->since_ns;
    gap = gap < RT_WAIT_LINE_NS ? RT_WAIT_LINE_NS : gap > RT_WAIT_LINE_MAX_NS ? RT_WAIT_LINE_MAX_NS : gap;
    w->next_line_ns = rt_sat_add(now, gap);
    char what[2 * LAG_WIRE_TEXT_LEN], got[2 * LAG_WIRE_TEXT_LEN]; /* the status cuts them */
    double waited = rt_wait_describe(w, now, seen, what, sizeof what, got, sizeof got);
    char line[5 * LAG_WIRE_TEXT_LEN];
    snprintf(line, sizeof line, "lagsimd: %s waits %.0f s for %s; %s%s", w->prefix,
             waited, what, got[0] ? "got instead: " : "nothing else came", got);
    rt_term_say(term, now, line);
}

int64_t rt_wait_next(const rt_wait *w)
{
    return w->kind == RT_WAIT_NONE ? INT64_MAX : w->next_line_ns;
}

/* Appends printf-style text to buf (of cap bytes, holding n), cut at its end. */
static size_t add(char *buf, size_t cap, size_t n, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static size_t add(char *buf, size_t cap, size_t n, const char *fmt, ...)
{
    if (n + 1 >= cap) return n;
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(buf + n, cap - n, fmt, ap);
    va_end(ap);
    if (w < 0) return n;
    return n + (size_t)w < cap ? n + (size_t)w : cap - 1;
}

/* "DESCRIBE 12, STATUS 1": the requests counted since the wait began (now - then). */
static size_t add_requests(char *buf, size_t cap, size_t n, const int64_t *now,
                           const int64_t *then)
{
    bool first = true;
    for (int r = 1; r <= RT_FOREIGN_REQUESTS; r++) {
        int k = r % RT_FOREIGN_REQUESTS; /* 0 (undecodable) last */
        int64_t d = now[k] - (then ? then[k] : 0);
        if (d <= 0) continue;
        const char *name = lag_wire_request_name(k);
        n = add(buf, cap, n, "%s%s %lld", first ? "" : ", ", name ? name : "undecodable",
                (long long)d);
        first = false;
    }
    return n;
}

/* What came for other prefixes, and this plant's requests on the state port, since the
 * wait began: at most 3 prefixes named (the table keeps RT_FOREIGN_MAX). */
static size_t add_foreign(const rt_wait *w, int64_t now, const rt_foreign *f, char *got,
                          size_t gotlen, size_t n)
{
    const rt_foreign *f0 = &w->foreign0;
    int64_t own = f->own_state_port_total - f0->own_state_port_total;
    if (own > 0) {
        n = add(got, gotlen, n, "%s%lld control request%s (", n ? "; " : "", (long long)own,
                own > 1 ? "s" : "");
        n = add_requests(got, gotlen, n, f->own_state_port, f0->own_state_port);
        n = add(got, gotlen, n, ") on %s at the state port %d (requests go to port %d)",
                w->bus->channel[LAG_BUS_CONTROL], w->bus->state_port, w->bus->command_port);
    }
    /* the prefixes to name, the most recently heard first */
    const rt_foreign_prefix *named[RT_FOREIGN_MAX];
    int64_t delta[RT_FOREIGN_MAX];
    const int64_t *then[RT_FOREIGN_MAX];
    int k = 0;
    for (int i = 0; i < RT_FOREIGN_MAX; i++) {
        const rt_foreign_prefix *p = &f->p[i];
        const rt_foreign_prefix *p0 = p->prefix[0] ? rt_foreign_find(f0, p->prefix) : NULL;
        int64_t d = p->total - (p0 ? p0->total : 0);
        if (!rt_foreign_unanswered(p, now) || d <= 0) continue;
        int j = k++;
        for (; j > 0 && named[j - 1]->heard < p->heard; j--) {
            named[j] = named[j - 1], delta[j] = delta[j - 1], then[j] = then[j - 1];
        }
        named[j] = p, delta[j] = d, then[j] = p0 ? p0->requests : NULL;
    }
    if (k == 0) return n;
    n = add(got, gotlen, n, "%srequests for %s no plant here has, on the command port %d: ",
            n ? "; " : "", k > 1 ? "prefixes" : "a prefix", w->bus->command_port);
    for (int j = 0; j < k && j < 3; j++) {
        n = add(got, gotlen, n, "%s%s (", j ? ", " : "", named[j]->prefix);
        n = add_requests(got, gotlen, n, named[j]->requests, then[j]);
        if (named[j]->state_port)
            n = add(got, gotlen, n, ", some to the state port %d", w->bus->state_port);
        n = add(got, gotlen, n, ")");
    }
    if (k > 3) n = add(got, gotlen, n, " and %d more", k - 3);
    return add(got, gotlen, n, "; this plant is %s", w->prefix);
}

/* The stale answers since the wait began, by what they answered: another sim_time, another
 * generation, or none (generation 0: lockstep needs the state's, which the command did not
 * copy). Appended to got (holding n bytes); returns its new length. */
static size_t add_stale(const rt_wait *w, const rt_wait_seen *seen, char *got, size_t gotlen,
                        size_t n)
{
    int64_t d[RT_STALE_COUNT];
    for (int k = 0; k < RT_STALE_COUNT; k++) d[k] = seen->stale[k] - w->stale0[k];
    if (d[RT_STALE_SIM_TIME] > 0)
        n = add(got, gotlen, n, "%s%lld answer%s to another sim_time", n ? "; " : "",
                (long long)d[RT_STALE_SIM_TIME], d[RT_STALE_SIM_TIME] > 1 ? "s" : "");
    if (d[RT_STALE_GENERATION] > 0)
        n = add(got, gotlen, n, "%s%lld answer%s of another generation (a state of an earlier "
                "run or scene)", n ? "; " : "", (long long)d[RT_STALE_GENERATION],
                d[RT_STALE_GENERATION] > 1 ? "s" : "");
    if (d[RT_STALE_NO_GENERATION] > 0)
        n = add(got, gotlen, n, "%s%lld answer%s of generation 0 (the command carries none: "
                "it copies the state's generation with its sim_time; docs/server.md, "
                "Generations)", n ? "; " : "",
                (long long)d[RT_STALE_NO_GENERATION], d[RT_STALE_NO_GENERATION] > 1 ? "s" : "");
    return n;
}

double rt_wait_describe(const rt_wait *w, int64_t now, const rt_wait_seen *seen, char *what,
                        size_t whatlen, char *got, size_t gotlen)
{
    what[0] = got[0] = '\0';
    rt_wait_kind k = seen->kind;
    double t = seen->t;
    /* a wait that began since the last update (a handler changed the run) is 0 s old */
    bool same = k == w->kind && (k == RT_WAIT_NONE || t == w->t);
    double waited = same ? (double)(now - w->since_ns) * 1e-9 : 0.0;
    if (k == RT_WAIT_NONE || (k == RT_WAIT_ANSWER && waited * 1e9 < (double)RT_WAIT_SHOW_NS))
        return 0.0;
    const char *curl = w->bus->command_url;
    const char *ch_command = w->bus->channel[LAG_BUS_COMMAND];
    const char *ch_control = w->bus->channel[LAG_BUS_CONTROL];
    switch (k) {
    case RT_WAIT_FIRST:
        if (w->lockstep)
            snprintf(what, whatlen, "the first command (sim_time %.9g) on %s at %s", t,
                     ch_command, curl);
        else
            snprintf(what, whatlen, "the first command on %s at %s", ch_command, curl);
        break;
    case RT_WAIT_ANSWER:
        snprintf(what, whatlen, "a command answering sim_time %.9g on %s at %s", t,
                 ch_command, curl);
        break;
    case RT_WAIT_RESUME:
        if (seen->owed) /* lockstep: the state waited on goes out again until answered */
            snprintf(what, whatlen, "RESUME or STEP on %s at %s (paused; the answer to "
                     "sim_time %.9g still owed on %s)", ch_control, curl, t, ch_command);
        else
            snprintf(what, whatlen, "RESUME or STEP on %s at %s (paused)", ch_control, curl);
        break;
    case RT_WAIT_RESET:
        snprintf(what, whatlen, "RESET or RESET_TO on %s at %s (numeric fault)", ch_control,
                 curl);
        break;
    case RT_WAIT_NONE: break;
    }
    if (!same) return 0.0;
    /* what came instead, since the wait began */
    size_t n = 0;
    int64_t bad = 0, stale = seen->rejected[RT_REJ_STALE] - w->rejected0[RT_REJ_STALE];
    for (int r = 0; r < RT_REJ_COUNT; r++)
        if (r != RT_REJ_STALE) bad += seen->rejected[r] - w->rejected0[r];
    if (bad > 0) {
        n = add(got, gotlen, n, "%lld command%s rejected (", (long long)bad, bad > 1 ? "s" : "");
        bool first = true;
        for (int r = 0; r < RT_REJ_COUNT; r++) {
            int64_t d = seen->rejected[r] - w->rejected0[r];
            if (r == RT_REJ_STALE || d == 0) continue;
            n = add(got, gotlen, n, "%s%s %lld", first ? "" : ", ", rt_reject_name[r],
                    (long long)d);
            first = false;
        }
        n = add(got, gotlen, n, "; the last: %s)", seen->last_reject);
    }
    int64_t wrong = seen->wrong_port - w->wrong_port0;
    if (wrong > 0)
        n = add(got, gotlen, n, "%s%lld command%s on %s at the state port %d (commands go to "
                "port %d)", n ? "; " : "", (long long)wrong, wrong > 1 ? "s" : "", ch_command,
                w->bus->state_port, w->bus->command_port);
    if (stale > 0) n = add_stale(w, seen, got, gotlen, n);
    if (seen->foreign) add_foreign(w, now, seen->foreign, got, gotlen, n);
    return waited;
}
