/*
 * What a run's bus says while lagsim-eval (and a --restart sweep) waits for its end
 * (eval_watch.h): a client of the run's own prefix and URL that hears its
 * states and asks the daemon for its status now and then. Two uses:
 *
 *   - a run whose plant has not left t = 0 after EVAL_WAIT_SAY_S (its controller never
 *     answered the first state: a controller on another prefix, one that hangs on start)
 *     is said once on stderr, in the daemon's own words (its status's waiting_for and
 *     waiting_got: what it waits for, on which channel and URL, what came instead), so
 *     that it is found in seconds, not at --timeout;
 *   - once the controller has ended, a daemon whose status says it waits for a command
 *     will never end by itself (in lockstep nothing else answers it): it is stopped at
 *     once instead of after the grace a daemon gets to end on its own.
 *
 * The watch only listens and asks for statuses, which change no state of the run: the
 * run's numbers are its log's, as without it.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "eval_watch.h"
#include "lagsim_clock.h"
#include "lagsim_client.h"
#include "lagsim_client_wire.h"

#define WATCH_ASK_S 0.25 /* a status asked for at most this often */

struct eval_watch {
    lag_client *cl;
    lag_client_status *status; /* the latest status's copy */
    const char *who;       /* the line's start ("lagsim-eval: case tilt"), NULL: say nothing */
    double t0;             /* monotonic s when the run's processes started */
    double asked;          /* monotonic s of the last status request */
    bool moved;            /* a state after t = 0 was heard */
    bool said;             /* the wait was said */
    double timeout;        /* --timeout, for the line */
};

void eval_say(const char *fmt, ...)
{
    static int tty = -1;
    if (tty < 0) tty = isatty(STDERR_FILENO);
    va_list ap;
    va_start(ap, fmt);
    if (tty) fputs("\r\033[K", stderr); /* a progress line on the terminal: cleared first */
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fflush(stderr);
}

eval_watch *eval_watch_start(const char *url, const char *prefix, double timeout,
                             const char *who)
{
    eval_watch *w = calloc(1, sizeof *w);
    if (!w) return NULL;
    w->cl = lag_client_create(url, prefix, NULL, 0);
    w->status = lag_client_status_new();
    if (!w->cl || !w->status) { /* the run goes on without it: nothing to say, the grace
                                 * as before */
        if (w->cl) lag_client_destroy(w->cl);
        lag_client_status_free(w->status);
        free(w);
        return NULL;
    }
    w->who = who;
    w->t0 = w->asked = lag_clock_mono_s();
    w->timeout = timeout;
    return w;
}

void eval_watch_stop(eval_watch *w)
{
    if (!w) return;
    lag_client_destroy(w->cl);
    lag_client_status_free(w->status);
    free(w);
}

/* What came, without waiting; a status asked for when one is due. */
static void take(eval_watch *w, bool ask)
{
    while (lag_client_handle(w->cl, 0) == LAG_CLIENT_OK) {}
    lag_client_state st;
    if (lag_client_latest_state(w->cl, &st, sizeof st) && st.sim_time > 0) w->moved = true;
    if (ask && lag_clock_mono_s() >= w->asked + WATCH_ASK_S) {
        w->asked = lag_clock_mono_s();
        lag_client_request_status(w->cl);
    }
}

void eval_watch_poll(eval_watch *w)
{
    if (!w) return;
    bool due = !w->said && !w->moved && w->who && lag_clock_mono_s() >= w->t0 + EVAL_WAIT_SAY_S;
    take(w, due);
    if (!due || w->moved || !lag_client_latest_status(w->cl, w->status)) return;
    const lag_wire_status st = *lag_wire_of_status(w->status);
    if (!st.waiting_for[0] || st.sim_time != 0) return;
    w->said = true;
    eval_say("%s: the plant has not left t = 0 after %.0f s: lagsimd waits %.0f s for %s; "
             "%s%s. A controller on another prefix never answers it: give the command "
             "{prefix} or LAGSIM_PREFIX (else the run ends at --timeout, %g s)\n", w->who,
             EVAL_WAIT_SAY_S, st.waiting_s, st.waiting_for,
             st.waiting_got[0] ? "got instead: " : "nothing else came", st.waiting_got,
             w->timeout);
}

bool eval_watch_stuck(eval_watch *w, double since)
{
    if (!w) return false;
    take(w, true);
    if (!lag_client_latest_status(w->cl, w->status)) return false;
    const lag_wire_status *st = lag_wire_of_status(w->status);
    return 1e-6 * (double)st->utime >= since && !strcmp(st->run_state, "waiting") &&
           st->waiting_for[0];
}
