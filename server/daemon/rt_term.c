/*
 * The real-time server on its terminal (stderr), as offline runs print their events:
 *
 *   lagsimd: event start at t = 0.000000000 s: dipc, rk4, dt 0.001 s, ...
 *   lagsimd: event watchdog_trip at t = 3.210000000 s: no command for 0.51 s ...
 *   lagsimd: event impact at t = 0.426664059 s, joint phi, value -1.234
 *   DIPC t=12.340 s RTF 1.000 q=(+0.001 +0.050 -0.030) 100 cmd/s E=+7.661 J ovr 0 running
 *
 * Every event the daemon publishes gets a line (without -q, terminal or not), the
 * limited kinds in their limited form (the published event says what its bucket
 * suppressed); at most 20 lines a second get printed, and the next line says how many
 * were not. On a terminal the live line (refreshed four times a second) is cleared
 * before an event line and drawn again below it, cut to the terminal's width so that it
 * never wraps: the coordinates, and the commands accepted per second over the last
 * second, or "no controller" when no command is held (none yet since start or reset, or
 * the watchdog tripped).
 *
 * With -q no event line is printed but for the losses (the kinds rt_publish.c's table
 * marks: the watchdog tripped, overruns, input left unread, commands refused, ...), which
 * a journal must show: the first of a kind at once, then at most one line of that kind
 * every RT_TERM_JOURNAL_S seconds, saying how many came since and in all, and the last:
 *
 *   lagsimd: ALICE: watchdog_trip: 4 more in 10.0 s (9 in all), the last at t = 31.200 s: ...
 */
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "rt_term.h"

#define RT_TERM_WINDOW_NS RT_NS_PER_S /* commands per second: over the last second */

/* Clears the live line, if it is on screen, so that what follows starts a fresh line. */
static void clear_line(rt_term *t)
{
    if (t->line_shown) fputs("\r\033[K", stderr);
    t->line_shown = false;
}

void rt_term_init(rt_term *t, bool quiet, const char *ch_event, int64_t now)
{
    t->quiet = quiet;
    t->who = "";
    t->ch_event = ch_event;
    rt_limit_init(&t->lim_print, 20, 20, now);
}

/* The journal's line of loss kind k: what came since its last line. */
static void journal_line(rt_term *t, int64_t now, rt_term_loss *l)
{
    if (l->pending == 1 && l->total == 1)
        fprintf(stderr, "lagsimd: %s%s at t = %.3f s: %s\n", t->who, l->kind, l->t, l->detail);
    else
        fprintf(stderr, "lagsimd: %s%s: %lld more in %.1f s (%lld in all), the last at t = "
                "%.3f s: %s\n", t->who, l->kind, (long long)l->pending,
                (double)(now - l->line_ns) * 1e-9, (long long)l->total, l->t, l->detail);
    fflush(stderr);
    l->pending = 0;
    l->line_ns = now > 0 ? now : 1;
}

static void journal(rt_term *t, int64_t now, int k, double sim_time, const char *kind,
                    const char *detail)
{
    if (k < 0 || k >= RT_TERM_LOSS_KINDS) return;
    rt_term_loss *l = &t->loss[k];
    l->pending++;
    l->total++;
    l->t = sim_time;
    snprintf(l->kind, sizeof l->kind, "%s", kind);
    snprintf(l->detail, sizeof l->detail, "%s", detail ? detail : "");
    if (!l->line_ns || now - l->line_ns >= (int64_t)RT_TERM_JOURNAL_S * RT_NS_PER_S)
        journal_line(t, now, l);
}

void rt_term_tick(rt_term *t, int64_t now)
{
    for (int k = 0; t->quiet && k < RT_TERM_LOSS_KINDS; k++) {
        rt_term_loss *l = &t->loss[k];
        if (l->pending > 0 && now - l->line_ns >= (int64_t)RT_TERM_JOURNAL_S * RT_NS_PER_S)
            journal_line(t, now, l);
    }
}

void rt_term_flush(rt_term *t, int64_t now)
{
    for (int k = 0; t->quiet && k < RT_TERM_LOSS_KINDS; k++)
        if (t->loss[k].pending > 0) journal_line(t, now, &t->loss[k]);
}

void rt_term_event(rt_term *t, int64_t now, double sim_time, const char *kind,
                   const char *joint, double value, const char *detail, bool effect, int loss)
{
    if (t->quiet) {
        journal(t, now, loss, sim_time, kind, detail);
        return;
    }
    int64_t suppressed = t->lim_print.suppressed;
    if (!rt_limit_take(&t->lim_print, now)) return;
    t->lim_print.suppressed = 0;
    clear_line(t);
    if (suppressed > 0)
        fprintf(stderr, "lagsimd: %s(%lld more events not shown: at most 20 lines a second; "
                "every event is on %s)\n", t->who, (long long)suppressed, t->ch_event);
    if (effect)
        fprintf(stderr, "lagsimd: %sevent %s at t = %.9f s, joint %s, value %g\n", t->who, kind,
                sim_time, joint && joint[0] ? joint : "-", value);
    else
        fprintf(stderr, "lagsimd: %sevent %s at t = %.9f s%s%s: %s\n", t->who, kind, sim_time,
                joint && joint[0] ? ", joint " : "", joint ? joint : "", detail ? detail : "");
    if (t->live_line) rt_term_line(t, now, false);
    else fflush(stderr);
}

void rt_term_say(rt_term *t, int64_t now, const char *line)
{
    if (t->quiet) return;
    clear_line(t);
    fprintf(stderr, "%s\n", line);
    if (t->live_line) rt_term_line(t, now, false);
    else fflush(stderr);
}

/* Commands accepted per second: since the newest redraw at least a second ago (or the
 * oldest one kept, when the line is younger than that); the redraw is remembered. */
static double command_rate(rt_term *t, int64_t now, int64_t accepted)
{
    double rate = 0.0;
    for (int k = 0; k < t->nsnap; k++) {
        int i = (t->next_snap - 1 - k + 8) % 8;
        int64_t span = now - t->snap_ns[i];
        if (span > 0 && (span >= RT_TERM_WINDOW_NS || k == t->nsnap - 1))
            rate = (double)(accepted - t->snap_n[i]) / ((double)span * 1e-9);
        if (span >= RT_TERM_WINDOW_NS) break;
    }
    if (t->nsnap == 0 || now >= t->snap_ns[(t->next_snap + 7) % 8] + RT_NS_PER_S / 8) {
        t->snap_ns[t->next_snap] = now;
        t->snap_n[t->next_snap] = accepted;
        t->next_snap = (t->next_snap + 1) % 8;
        if (t->nsnap < 8) t->nsnap++;
    }
    return rate;
}

void rt_term_line(rt_term *t, int64_t now, bool final)
{
    if (!t->live_line || !t->view) return;
    rt_term_view v;
    memset(&v, 0, sizeof v);
    t->view(t->ctx, &v);
    double rate = command_rate(t, now, v.accepted);
    char q[160] = "";
    size_t n = 0;
    for (int i = 0; i < v.nq && n < sizeof q; i++) {
        int k = snprintf(q + n, sizeof q - n, "%s%+.3f", i ? " " : "", v.q[i]);
        if (k < 0) break;
        n += (size_t)k;
    }
    char ctl[32];
    if (!v.controller) snprintf(ctl, sizeof ctl, "no controller");
    else snprintf(ctl, sizeof ctl, "%.0f cmd/s", rate);
    char line[512];
    snprintf(line, sizeof line, "%s t=%.3f s RTF %.3f q=(%s) %s E=%+.4g J ovr %lld %s",
             v.prefix, v.t, v.rtf, q, ctl, v.energy, (long long)v.overruns, v.run);
    /* never wider than the terminal: a wrapped line cannot be redrawn in place */
    struct winsize ws;
    if (ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 1 && ws.ws_col < sizeof line)
        line[ws.ws_col - 1] = '\0';
    fprintf(stderr, "\r\033[K%s%s", line, final ? "\n" : "");
    fflush(stderr);
    t->line_shown = !final;
}
