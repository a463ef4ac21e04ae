/*
 * Every process lagsim-eval and lagsim-sweep start ends when they end, however they end.
 *
 * What a tool starts: sweep workers (forks), and commands: lagsimd, a controller through
 * `sh -c` (which may start python3, octave, java, and those what they like), gnuplot.
 *
 * A command runs under a keeper: a small fork of the tool, in a process group of its own,
 * that starts the command in another group of its own and then only waits. The keeper
 *   - is the one the tool waits for and stops: its exit status is the command's (its exit
 *     status, or the signal that ended it, raised again without a core);
 *   - on SIGTERM (SIGINT, SIGHUP) sends SIGTERM to the command's group, then SIGKILL after
 *     EVAL_KEEP_GRACE_S;
 *   - gets SIGTERM itself when the process that started it dies, however it dies
 *     (PR_SET_PDEATHSIG: the kernel sends it, no code of the dead one has to run), and
 *     then stops the command as above;
 *   - when the command ends, ends what it left: its group (the controller's python3 under
 *     `sh -c`, a child it started), and, being a subreaper (PR_SET_CHILD_SUBREAPER), every
 *     descendant that left the group (setsid) and whose parent died: those become the
 *     keeper's children. SIGTERM, then SIGKILL after the grace;
 *   - exits only when the group is empty and it has no child left: when a keeper has
 *     ended, nothing of its command is running.
 * The command itself dies (SIGKILL) if its keeper does. A keeper signals only the group
 * of its command while that group's leader is not reaped or has members (so the group's
 * id cannot be another's) and its own children: never anything the tool did not start.
 *
 * Workers die (SIGKILL) when the tool dies (PR_SET_PDEATHSIG): their keepers then stop
 * their commands. SIGINT, SIGTERM or SIGHUP to the tool (or a worker) stop every keeper
 * and worker it started and wait for them (SIGKILL after STOP_WAIT_S), remove the tool's
 * temporary directory, and end it by the same signal: the handler does it all, with
 * async-signal-safe calls only, so that it works wherever the signal finds the program.
 * Until a child is reaped its pid is in this process's table (it cannot be reused while
 * unreaped); reaping and forgetting it happen with the stop signals blocked.
 *
 * A keeper may be forked from a worker that has threads (LCM's): it calls only
 * async-signal-safe functions, and the command's environment is made before the fork.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "eval_case.h"
#include "lagsim_clock.h"

#define STOP_WAIT_S 5.0 /* a stopped tool or worker waits this long for its children */
#define PROCS_MAX 1024  /* children not reaped yet: -j 256 workers, two keepers each */
#define TMPDIR_MAX 128  /* $TMPDIR longer than this: /tmp instead */

static volatile pid_t procs[PROCS_MAX];
static char tmpdir[TMPDIR_MAX + 64];
static volatile sig_atomic_t have_tmpdir;
static volatile sig_atomic_t deferring, deferred; /* eval_proc_defer: the signal kept */
static const int stop_signals[3] = {SIGINT, SIGTERM, SIGHUP};

/* the one clock (lagsim_clock.c: clock_gettime, async-signal-safe) */
static double mono_s(void) { return lag_clock_mono_s(); }

static struct timespec span(double s)
{
    if (s < 0) s = 0;
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    return ts;
}

static void nap(double s)
{
    struct timespec ts = span(s);
    nanosleep(&ts, NULL);
}

static void block_stop(sigset_t *old)
{
    sigset_t s;
    sigemptyset(&s);
    for (int i = 0; i < 3; i++) sigaddset(&s, stop_signals[i]);
    sigprocmask(SIG_BLOCK, &s, old);
}

static void remember(pid_t pid)
{
    for (int i = 0; i < PROCS_MAX; i++)
        if (procs[i] == 0) {
            procs[i] = pid;
            return;
        }
    /* full (cannot be: PROCS_MAX is above what -j allows): the child still dies with us */
}

static void forget(pid_t pid)
{
    for (int i = 0; i < PROCS_MAX; i++)
        if (procs[i] == pid) procs[i] = 0;
}

/* A new process (a keeper, a worker) starts with nothing of its parent's to stop. */
static void forget_all(void)
{
    for (int i = 0; i < PROCS_MAX; i++) procs[i] = 0;
    have_tmpdir = 0;
    deferring = deferred = 0;
}

/* ---------------------------------------------------------------- stopping */
/* SIGTERM (and SIGCONT: a stopped one too) to every child, STOP_WAIT_S for them, then
 * SIGKILL; all reaped. Async-signal-safe. */
static void stop_children(void)
{
    bool any = false;
    for (int i = 0; i < PROCS_MAX; i++)
        if (procs[i] > 0) {
            kill(procs[i], SIGTERM);
            kill(procs[i], SIGCONT);
            any = true;
        }
    double until = mono_s() + STOP_WAIT_S;
    while (any) {
        any = false;
        for (int i = 0; i < PROCS_MAX; i++) {
            pid_t p = procs[i];
            if (p <= 0) continue;
            int st;
            pid_t r = waitpid(p, &st, WNOHANG);
            if (r == p || (r < 0 && errno == ECHILD)) procs[i] = 0;
            else any = true;
        }
        if (!any) break;
        if (mono_s() >= until) {
            for (int i = 0; i < PROCS_MAX; i++)
                if (procs[i] > 0) {
                    kill(procs[i], SIGKILL);
                    waitpid(procs[i], NULL, 0);
                    procs[i] = 0;
                }
            break;
        }
        nap(0.01);
    }
}

/* The temporary directory and its files (no subdirectories are made in it), with
 * getdents64: async-signal-safe, unlike readdir. */
static void remove_tmpdir(void)
{
    if (!have_tmpdir) return;
    int fd = open(tmpdir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        char buf[4096] __attribute__((aligned(8)));
        for (int pass = 0; pass < 64; pass++) { /* again from the start until none is left */
            bool removed = false;
            lseek(fd, 0, SEEK_SET);
            ssize_t n;
            while ((n = getdents64(fd, buf, sizeof buf)) > 0)
                for (ssize_t o = 0; o < n;) {
                    struct dirent64 *d = (struct dirent64 *)(void *)(buf + o);
                    o += d->d_reclen;
                    if (strcmp(d->d_name, ".") && strcmp(d->d_name, "..") &&
                        unlinkat(fd, d->d_name, 0) == 0)
                        removed = true;
                }
            if (!removed) break;
        }
        close(fd);
    }
    rmdir(tmpdir);
    have_tmpdir = 0;
}

static void (*volatile at_stop)(void);

void eval_proc_at_stop(void (*fn)(void)) { at_stop = fn; }

static void on_stop(int sig)
{
    if (deferring) { /* the tool stops itself (eval_proc_pending), writing what it has */
        if (!deferred) deferred = sig;
        return;
    }
    stop_children();
    remove_tmpdir();
    if (at_stop) at_stop();
    signal(sig, SIG_DFL);
    raise(sig); /* pending (sig is blocked in its handler) until the mask is restored */
    sigset_t s;
    sigemptyset(&s);
    sigaddset(&s, sig);
    sigprocmask(SIG_UNBLOCK, &s, NULL);
    _exit(128 + sig); /* not reached */
}

static void at_exit_stop(void) { stop_children(); }

void eval_proc_defer(bool on) { deferring = on; }

int eval_proc_pending(void) { return deferred; }

void eval_proc_stop_children(void)
{
    sigset_t old;
    block_stop(&old);
    stop_children();
    sigprocmask(SIG_SETMASK, &old, NULL);
}

void eval_proc_end(int sig)
{
    deferring = 0;
    on_stop(sig);
    _exit(128 + sig); /* not reached: on_stop ends the process by sig */
}

void eval_proc_init(void)
{
    struct sigaction sa = {.sa_handler = on_stop};
    sigemptyset(&sa.sa_mask);
    for (int i = 0; i < 3; i++) sigaddset(&sa.sa_mask, stop_signals[i]);
    for (int i = 0; i < 3; i++) {
        struct sigaction old;
        /* a signal ignored when the tool started (nohup: SIGHUP) stays ignored */
        if (sigaction(stop_signals[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        sigaction(stop_signals[i], &sa, NULL);
    }
    atexit(at_exit_stop);
}

int eval_make_tmpdir(const char *name, char *buf, size_t len)
{
    const char *t = getenv("TMPDIR");
    if (!t || t[0] != '/' || strlen(t) > TMPDIR_MAX) t = "/tmp";
    snprintf(buf, len, "%s/%s.XXXXXX", t, name);
    if (!mkdtemp(buf)) return -1;
    sigset_t old;
    block_stop(&old);
    snprintf(tmpdir, sizeof tmpdir, "%s", buf);
    have_tmpdir = strlen(buf) < sizeof tmpdir;
    sigprocmask(SIG_SETMASK, &old, NULL);
    return 0;
}

void eval_proc_tmpdir_done(void) { have_tmpdir = 0; }

void eval_proc_tmpdir_remove(void) { remove_tmpdir(); }

/* ---------------------------------------------------------------- waiting */
/* Reaps pid if it ended (and forgets it, the stop signals blocked meanwhile): 1 reaped,
 * 0 running, -1 not a child. */
static int reap(pid_t pid, int *status)
{
    sigset_t old;
    block_stop(&old);
    pid_t r;
    do r = waitpid(pid, status, WNOHANG);
    while (r < 0 && errno == EINTR);
    if (r == pid) forget(pid);
    sigprocmask(SIG_SETMASK, &old, NULL);
    return r == pid ? 1 : r == 0 ? 0 : -1;
}

int eval_wait_until(pid_t pid, double deadline, int *status)
{
    for (;;) {
        int r = reap(pid, status);
        if (r != 0) return 1;
        if (mono_s() >= deadline) return 0;
        nap(0.005);
    }
}

int eval_proc_wait(pid_t pid, int *status)
{
    siginfo_t si;
    /* sleeps until it ends (the stop signals free to come), then reaps it */
    while (waitid(P_PID, (id_t)pid, &si, WEXITED | WNOWAIT) < 0)
        if (errno != EINTR) return -1;
    return reap(pid, status) == 1 ? 0 : -1;
}

void eval_stop_group(pid_t pid, int *status)
{
    kill(pid, SIGTERM);
    kill(pid, SIGCONT);
    if (!eval_wait_until(pid, mono_s() + EVAL_KEEP_GRACE_S + 1.0, status)) {
        kill(pid, SIGKILL);
        eval_proc_wait(pid, status);
    }
}

/* ---------------------------------------------------------------- workers */
pid_t eval_proc_fork(void)
{
    sigset_t old;
    block_stop(&old);
    fflush(NULL); /* nothing buffered is written twice */
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid == 0) {
        forget_all();
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent) raise(SIGKILL); /* the tool died before the line above */
    } else if (pid > 0) {
        remember(pid);
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
    return pid;
}

/* ---------------------------------------------------------------- keepers */
typedef struct keep_plan {
    const char *path;     /* execve's path, or NULL: argv[0] looked up on PATH */
    char *const *argv;
    char *const *envp;
    bool null_out, null_err;
    const char *err_file; /* stderr to this file (made 0600, emptied), or NULL */
    sigset_t mask;        /* the spawner's signal mask, the command's again */
    pid_t spawner;
} keep_plan;

/* The command, in the keeper's child: a group of its own, dead with its keeper. */
static void __attribute__((noreturn)) run_command(const keep_plan *p, pid_t keeper)
{
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != keeper) _exit(127);
    /* the tool's handler is not the command's (exec would reset it, but a signal could
     * come before); a signal ignored when the tool started (nohup) stays ignored */
    for (int i = 0; i < 3; i++) {
        struct sigaction cur;
        if (sigaction(stop_signals[i], NULL, &cur) == 0 && cur.sa_handler != SIG_IGN)
            signal(stop_signals[i], SIG_DFL);
    }
    if (p->null_out || p->null_err) {
        int fd = open("/dev/null", O_WRONLY);
        if (fd >= 0 && p->null_out) dup2(fd, 1);
        if (fd >= 0 && p->null_err) dup2(fd, 2);
        if (fd > 2) close(fd);
    }
    if (p->err_file) { /* in the tool's own temporary directory; never through a link */
        int fd = open(p->err_file, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW, 0600);
        if (fd >= 0) dup2(fd, 2);
        if (fd > 2) close(fd);
    }
    sigprocmask(SIG_SETMASK, &p->mask, NULL);
    if (p->path) execve(p->path, p->argv, p->envp);
    else execvpe(p->argv[0], p->argv, p->envp);
    _exit(127);
}

/* The pids of the keeper's children that were sent SIGTERM (a child is sent it once). */
typedef struct sent {
    pid_t pid[256];
    int n;
} sent;

static bool sent_before(sent *s, pid_t pid)
{
    for (int i = 0; i < s->n; i++)
        if (s->pid[i] == pid) return true;
    if (s->n < 256) s->pid[s->n++] = pid;
    return false;
}

/* Signals the keeper's own children (the command, and the orphans of its descendants that
 * were handed to the keeper as their subreaper), each once when `once` is given: children
 * are never reaped behind its back, so their pids are theirs. Numbers read by hand: no
 * stdio here. */
static void kill_children(int sig, sent *once)
{
    char path[64] = "/proc/self/task/", num[16];
    int n = 0;
    for (pid_t v = getpid(); v > 0; v /= 10) num[n++] = (char)('0' + v % 10);
    size_t u = strlen(path);
    while (n > 0) path[u++] = num[--n];
    memcpy(path + u, "/children", 10);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;
    char buf[4096];
    ssize_t len = read(fd, buf, sizeof buf - 1);
    close(fd);
    pid_t pid = 0;
    /* "PID PID ... ": a number counts once the space after it is read (a list longer than
     * the buffer is cut; the rest is signalled on the next call) */
    for (ssize_t i = 0; i < len; i++) {
        if (buf[i] >= '0' && buf[i] <= '9') {
            pid = pid * 10 + (buf[i] - '0');
            continue;
        }
        if (pid > 0 && !(once && sent_before(once, pid))) {
            kill(pid, sig);
            if (sig != SIGKILL) kill(pid, SIGCONT);
        }
        pid = 0;
    }
}

/* Whether the command (pid c) has ended, left unreaped (its group's id stays its own);
 * orphans handed to the keeper that ended meanwhile are reaped. */
static bool command_ended(pid_t c)
{
    for (;;) {
        siginfo_t si;
        si.si_pid = 0;
        if (waitid(P_ALL, 0, &si, WEXITED | WNOHANG | WNOWAIT) != 0 || si.si_pid == 0)
            return false;
        if (si.si_pid == c) return true;
        waitpid(si.si_pid, NULL, 0);
    }
}

/* Until the command (pid c) has ended, left unreaped: its group's id stays its own. A
 * stop signal (or the spawner's death) sends SIGTERM to the group, then SIGKILL after the
 * grace. Returns when the SIGKILL is due (0 when none was asked for). */
static double keep_wait(pid_t c, const sigset_t *sigs)
{
    double kill_at = 0;
    bool killed = false;
    for (;;) {
        if (command_ended(c)) return kill_at;
        if (kill_at > 0 && !killed && mono_s() >= kill_at) {
            kill(-c, SIGKILL);
            killed = true;
        }
        struct timespec ts = span(kill_at - mono_s());
        int sig = sigtimedwait(sigs, NULL, kill_at > 0 && !killed ? &ts : NULL);
        if (sig > 0 && sig != SIGCHLD && kill_at == 0) {
            kill(-c, SIGTERM);
            kill(-c, SIGCONT);
            kill_at = mono_s() + EVAL_KEEP_GRACE_S;
        }
    }
}

/* The command has ended: what it left (its group, the keeper's other children, each new
 * one as it comes) gets SIGTERM, SIGKILL at kill_at; returns once none is left. Its status
 * in *st. */
static void keep_end(pid_t c, double kill_at, const sigset_t *sigs, int *st)
{
    sent once = {.n = 0};
    kill(-c, SIGTERM);
    kill(-c, SIGCONT);
    kill_children(SIGTERM, &once);
    while (waitpid(c, st, 0) < 0 && errno == EINTR) {}
    if (kill_at == 0) kill_at = mono_s() + EVAL_KEEP_GRACE_S;
    for (;;) {
        pid_t r;
        while ((r = waitpid(-1, NULL, WNOHANG)) > 0) {}
        bool children = r == 0; /* -1 (ECHILD): none */
        /* the group still has members (so its id is still theirs), or none: ESRCH */
        bool group = kill(-c, 0) == 0;
        if (!children && !group) return;
        bool late = mono_s() >= kill_at;
        if (late) kill(-c, SIGKILL);
        kill_children(late ? SIGKILL : SIGTERM, late ? NULL : &once);
        struct timespec ts = span(0.01);
        sigtimedwait(sigs, NULL, &ts);
    }
}

/* The keeper: the command started, waited for, stopped when asked or when the spawner
 * dies; exits as the command did once nothing of it is left. Async-signal-safe only. */
static void __attribute__((noreturn)) keeper(const keep_plan *p)
{
    forget_all();
    setpgid(0, 0);
    sigset_t sigs;
    sigemptyset(&sigs);
    for (int i = 0; i < 3; i++) sigaddset(&sigs, stop_signals[i]);
    sigaddset(&sigs, SIGCHLD);
    sigprocmask(SIG_BLOCK, &sigs, NULL); /* taken by sigtimedwait, never by handlers */
    signal(SIGCHLD, SIG_DFL);            /* not ignored: children are waited for */
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != p->spawner) _exit(127); /* the spawner died already: start nothing */
    prctl(PR_SET_CHILD_SUBREAPER, 1);
    close_range(3, ~0U, 0); /* the tool's files and sockets are not the command's */
    pid_t self = getpid();
    pid_t c = fork();
    if (c == 0) run_command(p, self);
    if (c < 0) _exit(127);
    setpgid(c, c);
    int st = 0;
    keep_end(c, keep_wait(c, &sigs), &sigs, &st);
    if (WIFEXITED(st)) _exit(WEXITSTATUS(st));
    int sig = WTERMSIG(st);
    struct rlimit none = {0, 0};
    setrlimit(RLIMIT_CORE, &none); /* the command's signal, not a core of the keeper */
    signal(sig, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, sig);
    sigprocmask(SIG_UNBLOCK, &one, NULL);
    raise(sig);
    _exit(128 + sig);
}

static pid_t keep_spawn(keep_plan *p)
{
    sigset_t old;
    block_stop(&old);
    p->mask = old;
    fflush(NULL); /* nothing buffered is written twice */
    p->spawner = getpid();
    pid_t pid = fork();
    if (pid == 0) keeper(p);
    if (pid > 0) remember(pid);
    sigprocmask(SIG_SETMASK, &old, NULL);
    return pid;
}

/* environ with LCM_DEFAULT_URL and LAGSIM_PREFIX set to the run's (strings in vars) */
static char **run_environ(const eval_env *env, char vars[2][256])
{
    size_t n = 0;
    while (environ[n]) n++;
    char **e = malloc((n + 3) * sizeof *e);
    if (!e) return NULL;
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (strncmp(environ[i], "LCM_DEFAULT_URL=", 16) && strncmp(environ[i], "LAGSIM_PREFIX=", 14))
            e[k++] = environ[i];
    snprintf(vars[0], 256, "LCM_DEFAULT_URL=%s", env->url);
    snprintf(vars[1], 256, "LAGSIM_PREFIX=%s", env->prefix);
    e[k++] = vars[0];
    e[k++] = vars[1];
    e[k] = NULL;
    return e;
}

pid_t eval_spawn(char *const *argv, const char *cmd, const eval_env *env, const char *err_file)
{
    char vars[2][256];
    char **envp = run_environ(env, vars);
    if (!envp) return -1;
    char *sh[] = {"sh", "-c", (char *)cmd, NULL};
    /* a daemon named without a directory is looked up on PATH */
    const char *path = !argv ? "/bin/sh" : strchr(argv[0], '/') ? argv[0] : NULL;
    keep_plan p = {.path = path, .argv = argv ? argv : sh, .envp = envp,
                   .null_out = !env->verbose, .null_err = !env->verbose && argv && !err_file,
                   .err_file = env->verbose ? NULL : err_file};
    pid_t pid = keep_spawn(&p);
    free(envp);
    return pid;
}

pid_t eval_spawn_plain(char *const *argv)
{
    keep_plan p = {.argv = argv, .envp = environ};
    return keep_spawn(&p);
}

int eval_gnuplot(const char *prog, const char *gp)
{
    char *argv[] = {"gnuplot", (char *)gp, NULL};
    pid_t pid = eval_spawn_plain(argv);
    int st = 0;
    if (pid < 0 || eval_proc_wait(pid, &st) != 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "%s: gnuplot failed on %s\n", prog, gp);
        return -1;
    }
    return 0;
}
