/*
 * The processes lagsim-eval and lagsim-sweep start, and the rule they keep: every process
 * a tool starts ends when the tool ends, however it ends (eval_proc.c says how).
 *
 *   eval_proc_init()      in main, first: SIGINT, SIGTERM, SIGHUP stop every process this
 *                         one started (and remove its temporary directory), then end this
 *                         one by that signal (a shell reports 128 + its number)
 *   eval_spawn()          a command under a keeper (its pid stands for the command: its
 *                         exit status is the command's)
 *   eval_proc_fork()      a worker: a fork that dies when the tool dies
 *   eval_wait_until(), eval_proc_wait(), eval_stop_group()   waits and stops, which also
 *                         forget a process once it is reaped
 */
#ifndef LAGSIM_EVAL_PROC_H
#define LAGSIM_EVAL_PROC_H

#include <stdbool.h>
#include <stddef.h>

#include <sys/types.h>

/* A command stopped by its keeper gets this long after SIGTERM before SIGKILL; so does
 * what it leaves running when it ends. */
#define EVAL_KEEP_GRACE_S 2.0

struct eval_env;

/* The stop signals' handler and, at exit, a stop of whatever is still running. */
void eval_proc_init(void);

/* argv (argv[0] a path), or "sh -c cmd" when argv is NULL, with the run's URL and prefix in
 * its environment (LCM_DEFAULT_URL, LAGSIM_PREFIX), under a keeper. Unless env->verbose
 * (which passes both through): stdout to /dev/null, stderr to err_file (emptied; the
 * caller shows its last lines when the run fails: eval_stderr_tail), or with no err_file
 * to /dev/null for argv and through for cmd. The keeper's pid, or -1. */
pid_t eval_spawn(char *const *argv, const char *cmd, const struct eval_env *env,
                 const char *err_file);

/* argv (argv[0] looked up on PATH) under a keeper, its output passed through. */
pid_t eval_spawn_plain(char *const *argv);

/* fork() for a worker process: the child dies (SIGKILL) when this process dies, and its
 * own children are its own to stop. */
pid_t eval_proc_fork(void);

/* Waits for pid until `deadline` (monotonic s); 1 and *status when it ended, 0 if not. */
int eval_wait_until(pid_t pid, double deadline, int *status);
/* Waits for pid as long as it takes; 0 and *status, -1 when pid is no child. */
int eval_proc_wait(pid_t pid, int *status);
/* SIGTERM to a keeper (or a worker), SIGKILL when it has not ended after the grace and a
 * second; reaped. */
void eval_stop_group(pid_t pid, int *status);

/* A temporary directory of this run, under $TMPDIR (when set and at most 128 characters)
 * or /tmp: "DIR/NAME.XXXXXX" in buf; removed with its files when a signal stops the tool
 * (eval_proc_tmpdir_done once it is removed otherwise). 0, or -1 with errno. */
int eval_make_tmpdir(const char *name, char *buf, size_t len);
void eval_proc_tmpdir_done(void);
/* The temporary directory removed with its files now (a tool that ends without -v). */
void eval_proc_tmpdir_remove(void);

/* While deferred, SIGINT, SIGTERM and SIGHUP stop nothing: the first is kept for the tool,
 * which asks eval_proc_pending() (its number, 0: none) where it waits, stops its children
 * (eval_proc_stop_children), writes what it has, and then ends by it (eval_proc_end, as
 * the handler would have: the temporary directory removed, the at_stop function, the
 * signal raised). A worker forked meanwhile starts without it. */
void eval_proc_defer(bool on);
int eval_proc_pending(void);
void eval_proc_stop_children(void);
void eval_proc_end(int sig) __attribute__((noreturn));

/* fn runs when a signal stops the tool, once its children have ended and before it ends
 * by the signal: async-signal-safe work only (unlink the outputs it made and did not
 * finish). One at a time; NULL: none. */
void eval_proc_at_stop(void (*fn)(void));

#endif
