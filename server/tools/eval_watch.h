/*
 * Watching a run (eval_watch.c): a client on a run's URL and prefix, its states, its
 * daemon's statuses; and eval_say, the tools' lines on stderr.
 */
#ifndef LAGSIM_EVAL_WATCH_H
#define LAGSIM_EVAL_WATCH_H

#include <stdbool.h>

#define EVAL_WAIT_SAY_S 5.0 /* a plant still at t = 0 after this: said once (who) */
typedef struct eval_watch eval_watch;
/* A watch of the plant `prefix` at `url`; `who` starts its line (NULL: say nothing);
 * `timeout` is the run's --timeout, named in the line. NULL when no client could be made
 * (the run goes on without one). */
eval_watch *eval_watch_start(const char *url, const char *prefix, double timeout,
                             const char *who);
/* What came; once the plant has waited EVAL_WAIT_SAY_S at t = 0, a line saying what it
 * waits for (its status's words), once. */
void eval_watch_poll(eval_watch *w);
/* Whether a status of after `since` (wall s) says the daemon waits for a command: with its
 * controller gone, it never ends by itself. Asks for one when due. */
bool eval_watch_stuck(eval_watch *w, double since);
void eval_watch_stop(eval_watch *w);
/* A line on stderr (printf), the terminal's progress line cleared first. */
void eval_say(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
