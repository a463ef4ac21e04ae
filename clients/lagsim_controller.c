/*
 * What every C example controller shares: see lagsim_controller.h.
 */
#include "lagsim_controller.h"
#include "lagsim_out.h"
#include "lagsim_locate.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define CTL_MAX_OPTIONS 32

static volatile sig_atomic_t g_signal = 0;
static void on_signal(int sig) { g_signal = sig; }

/* ---------------------------------------------------------------- setters */
/* A finite double, the whole string. */
static int parse_double(const char *v, double *x, char *err, size_t errlen)
{
    char *end;
    errno = 0;
    *x = v ? strtod(v, &end) : NAN;
    if (!v || end == v || *end != '\0' || !isfinite(*x)) {
        snprintf(err, errlen, "'%s' is not a finite number", v ? v : "");
        return -1;
    }
    return 0;
}

int lag_ctl_number(const char *value, void *target, char *err, size_t errlen)
{
    return parse_double(value, target, err, errlen);
}

int lag_ctl_positive(const char *value, void *target, char *err, size_t errlen)
{
    double x;
    if (parse_double(value, &x, err, errlen)) return -1;
    if (!(x > 0)) {
        snprintf(err, errlen, "must be > 0, got %s", value);
        return -1;
    }
    *(double *)target = x;
    return 0;
}

int lag_ctl_nonnegative(const char *value, void *target, char *err, size_t errlen)
{
    double x;
    if (parse_double(value, &x, err, errlen)) return -1;
    if (!(x >= 0)) {
        snprintf(err, errlen, "must be >= 0, got %s", value);
        return -1;
    }
    *(double *)target = x;
    return 0;
}

int lag_ctl_flag(const char *value, void *target, char *err, size_t errlen)
{
    (void)value, (void)err, (void)errlen;
    *(bool *)target = true;
    return 0;
}

int lag_ctl_gain_kind(const char *value, void *target, char *err, size_t errlen)
{
    if (!strcmp(value, "continuous")) *(int *)target = 1;
    else if (!strcmp(value, "discrete")) *(int *)target = 0;
    else {
        snprintf(err, errlen, "discrete or continuous, got '%s'", value);
        return -1;
    }
    return 0;
}

int lag_ctl_parse_list(const char *value, double *out, int n, char *err, size_t errlen)
{
    const char *s = value ? value : "";
    for (int i = 0; i < n; i++) {
        char *end;
        out[i] = strtod(s, &end);
        if (end == s || !isfinite(out[i]) || (i < n - 1 && *end != ',')) {
            snprintf(err, errlen, "'%s' is not %d comma-separated finite numbers", value, n);
            return -1;
        }
        s = end + (i < n - 1);
    }
    if (*s != '\0') {
        snprintf(err, errlen, "'%s' is not %d comma-separated finite numbers", value, n);
        return -1;
    }
    return 0;
}

static int set_string(const char *value, void *target, char *err, size_t errlen)
{
    if (!value || !value[0]) {
        snprintf(err, errlen, "needs a non-empty value");
        return -1;
    }
    *(const char **)target = value;
    return 0;
}

/* ---------------------------------------------------------------- options */
void lag_ctl_init(lag_ctl *ctl, const char *name, const char *default_prefix)
{
    memset(ctl, 0, sizeof *ctl);
    ctl->name = name;
    ctl->default_prefix = default_prefix;
    ctl->timeout = 5.0;
    ctl->t_first = NAN;
}

static void usage(const lag_ctl *ctl, FILE *f, const char *what, const lag_ctl_option *all,
                  int n)
{
    fprintf(f, "usage: %s [options]\n%s\n", ctl->name, what);
    for (int i = 0; i < n; i++) {
        char head[64], letter[8] = "";
        if (all[i].letter) snprintf(letter, sizeof letter, "-%c, ", all[i].letter);
        snprintf(head, sizeof head, "%s--%s%s%s", letter, all[i].name,
                 all[i].metavar ? " " : "", all[i].metavar ? all[i].metavar : "");
        fprintf(f, "  %-20s %s\n", head, all[i].help);
    }
    fprintf(f, "A run ends on the daemon's stop event, after --timeout s of silence, after "
               "--duration, or on SIGINT/SIGTERM.\n"
               "Exit status: 0 done, 1 no scene, another model or a client error, 2 bad "
               "usage.\n");
}

/* getopt_long found no option (c is '?' or ':'): says which, returns 2 (bad usage). */
static int bad_option(const lag_ctl *ctl, int c, char **argv)
{
    if (c == ':' && optopt && optopt < 256)
        fprintf(stderr, "%s: option -%c needs a value\n", ctl->name, optopt);
    else if (c == ':')
        fprintf(stderr, "%s: option %s needs a value\n", ctl->name, argv[optind - 1]);
    else if (optopt)
        fprintf(stderr, "%s: unknown option '-%c'\n", ctl->name, optopt);
    else
        fprintf(stderr, "%s: unknown option '%s'\n", ctl->name, argv[optind - 1]);
    fprintf(stderr, "%s: --help lists the options\n", ctl->name);
    return lag_result_exit(LAG_ERR_USAGE);
}

int lag_ctl_parse(lag_ctl *ctl, int argc, char **argv, const char *what,
                  const lag_ctl_option *extra, int nextra)
{
    bool help = false;
    char prefix_help[96];
    if (ctl->default_prefix)
        snprintf(prefix_help, sizeof prefix_help, "channel prefix (default: the only plant "
                 "of the model on the bus; none yet: %s)", ctl->default_prefix);
    else
        snprintf(prefix_help, sizeof prefix_help, "channel prefix (default: the only plant "
                                                  "on the bus)");
    const lag_ctl_option common[] = {
        {"prefix", "P", prefix_help, set_string, &ctl->prefix},
        {"url", "URL", "LCM URL (default: the URL a host's directory on LCM's default bus "
         "names for --prefix, else LCM's default; honours LCM_DEFAULT_URL)", set_string, &ctl->url},
        {"duration", "S", "end after S s of sim time from the first state (default 0: "
                          "until the daemon stops)", lag_ctl_nonnegative, &ctl->duration},
        {"timeout", "S", "wall s without a scene, or without any message from the daemon, "
                         "before ending (default 5)", lag_ctl_positive, &ctl->timeout},
        {"trace", "FILE", "write each answered state and the efforts sent to FILE",
         set_string, &ctl->trace_path},
        {"quiet", NULL, "design and summary only", lag_ctl_flag, &ctl->quiet, 'q'},
        {"help", NULL, "this text", lag_ctl_flag, &help, 'h'},
    };
    int ncommon = (int)(sizeof common / sizeof common[0]);
    lag_ctl_option all[CTL_MAX_OPTIONS];
    struct option longopts[CTL_MAX_OPTIONS + 1];
    int n = 0;
    for (int i = 0; i < ncommon + nextra && n < CTL_MAX_OPTIONS; i++)
        all[n++] = i < ncommon ? common[i] : extra[i - ncommon];
    char shorts[2 * CTL_MAX_OPTIONS + 2] = ":";
    size_t ns = 1;
    for (int i = 0; i < n; i++) {
        longopts[i] = (struct option){all[i].name, all[i].metavar ? required_argument : no_argument,
                                      NULL, 256 + i};
        if (all[i].letter) {
            shorts[ns++] = all[i].letter;
            if (all[i].metavar) shorts[ns++] = ':';
        }
    }
    longopts[n] = (struct option){NULL, 0, NULL, 0};
    shorts[ns] = '\0';

    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, shorts, longopts, NULL)) != -1) {
        const lag_ctl_option *o = NULL;
        if (c >= 256) o = &all[c - 256];
        for (int i = 0; i < n && !o && c != '?' && c != ':'; i++)
            if (all[i].letter == c) o = &all[i];
        if (!o) return bad_option(ctl, c, argv);
        char err[256];
        if (o->set(optarg, o->target, err, sizeof err) != 0) {
            fprintf(stderr, "%s: --%s: %s\n", ctl->name, o->name, err);
            return lag_result_exit(LAG_ERR_USAGE);
        }
    }
    if (optind < argc) {
        fprintf(stderr, "%s: unexpected argument '%s' (--help lists the options)\n", ctl->name,
                argv[optind]);
        return lag_result_exit(LAG_ERR_USAGE);
    }
    if (help) {
        usage(ctl, stdout, what, all, n);
        return lag_result_exit(LAG_OK);
    }
    return -1;
}

/* ---------------------------------------------------------------- the run */
/* The silence that ends a run counts what the plant itself publishes: its states, its
 * status, its events; not a host's directory's `plant` events, which go on whether or
 * not the plant runs. */
static void heard_state(const lag_client_state *st, void *user)
{
    (void)st;
    ((lag_ctl *)user)->heard = lag_client_now();
}

static void heard_status(const lag_client_status *st, void *user)
{
    (void)st;
    ((lag_ctl *)user)->heard = lag_client_now();
}

static void heard_event(const lag_client_event *ev, void *user)
{
    lag_ctl *ctl = user;
    if (strcmp(ev->kind, "plant") != 0) ctl->heard = lag_client_now();
    if (!strcmp(ev->kind, "stop")) ctl->stopped = true;
    if (ctl->on_event) ctl->on_event(ev, ctl->event_user);
}

/* --trace: replaced if it exists (a trace is rewritten run after run), but never written
 * through a symbolic link (lagsim_out.h). */
static int open_trace(lag_ctl *ctl)
{
    char oerr[512];
    int fd = lag_out_open("--trace", ctl->trace_path, true, NULL, 0, 0, oerr, sizeof oerr);
    ctl->trace = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!ctl->trace) {
        if (fd >= 0) {
            snprintf(oerr, sizeof oerr, "--trace %s: %s", ctl->trace_path, strerror(errno));
            close(fd);
        }
        fprintf(stderr, "%s: %s\n", ctl->name, oerr);
        return 1;
    }
    return 0;
}

/* Without --prefix: the only plant (of this model) on the bus; with a default prefix a
 * controller may start before its plant: a short look, then that prefix is waited on. */
static int pick_prefix(lag_ctl *ctl, const char *model)
{
    char perr[1200];
    lag_client_plant p;
    double look = ctl->default_prefix ? 1.0 : ctl->timeout;
    int rc = lag_client_pick_plant(ctl->url, model, look, &p, sizeof p, perr, sizeof perr);
    if (rc == LAG_CLIENT_OK) {
        snprintf(ctl->found_prefix, sizeof ctl->found_prefix, "%s", p.prefix);
        ctl->prefix = ctl->found_prefix;
        if (!ctl->url && lag_locate_elsewhere(p.url)) { /* a host's plant */
            snprintf(ctl->found_url, sizeof ctl->found_url, "%s", p.url);
            ctl->url = ctl->found_url;
        }
        printf("%s: the only %s%splant on the bus: prefix %s (%s, %s)\n", ctl->name,
               model ? model : "", model ? " " : "", p.prefix, p.mode, p.run_state);
    } else if (rc == LAG_CLIENT_TIMEOUT && ctl->default_prefix) {
        ctl->prefix = ctl->default_prefix;
        printf("%s: %s; waiting for prefix %s\n", ctl->name, perr, ctl->prefix);
    } else {
        fprintf(stderr, "%s: %s\n", ctl->name, perr);
        /* several: --prefix */
        ctl->fail_code = lag_result_exit(rc == LAG_CLIENT_ERR_AMBIGUOUS ? LAG_ERR_AMBIGUOUS
                                                                    : LAG_ERR_RUNTIME);
        return ctl->fail_code;
    }
    return 0;
}

/* The client, its callbacks and the signal handlers. */
static int connect_client(lag_ctl *ctl)
{
    char err[LAG_CLIENT_URL_LEN + 256];
    ctl->client = lag_client_create(ctl->url, ctl->prefix, err, sizeof err);
    /* --prefix without --url: subscribed first (nothing of a plant of the default bus is
     * missed while the directory is asked), then moved to the URL a host's directory
     * names, if it names one */
    int where = ctl->client && ctl->prefix && !ctl->url
                    ? lag_client_locate(ctl->prefix, LAG_CLIENT_LOCATE_WAIT_S, ctl->found_url,
                                        sizeof ctl->found_url, err, sizeof err)
                    : LAG_CLIENT_LOCATE_HERE;
    if (where == LAG_CLIENT_LOCATE_NONE) printf("%s: %s\n", ctl->name, err);
    if (where == LAG_CLIENT_LOCATE_HOST) {
        ctl->url = ctl->found_url;
        printf("%s: prefix %s runs on %s (the host's directory)\n", ctl->name, ctl->prefix,
               ctl->url);
        lag_client_destroy(ctl->client);
        ctl->client = lag_client_create(ctl->url, ctl->prefix, err, sizeof err);
    }
    if (!ctl->client) {
        fprintf(stderr, "%s: %s\n", ctl->name, err);
        return 1;
    }
    lag_client_on_state(ctl->client, heard_state, ctl);
    lag_client_on_status(ctl->client, heard_status, ctl);
    lag_client_on_event(ctl->client, heard_event, ctl);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    return 0;
}

/* No scene came on the prefix: who is on the bus instead (a misspelt --prefix). */
static void say_no_scene(const lag_ctl *ctl)
{
    char instead[1500];
    lag_client_plants_instead(ctl->url, ctl->prefix, 1.0, instead, sizeof instead);
    fprintf(stderr, "%s: no scene description on %s_SCENE within %g s: %s\n", ctl->name,
            ctl->prefix, ctl->timeout, instead);
}

static int wait_scene(lag_ctl *ctl)
{
    if (!ctl->scene && !(ctl->scene = lag_client_scene_new())) {
        fprintf(stderr, "%s: out of memory\n", ctl->name);
        return 1;
    }
    /* subscribed: from here on no state is missed (test harnesses wait for this line) */
    printf("%s: waiting for the scene description on %s_SCENE\n", ctl->name, ctl->prefix);
    fflush(stdout);
    double deadline = lag_client_now() + ctl->timeout;
    for (;;) {
        double left = deadline - lag_client_now();
        int rc = lag_client_wait_scene(ctl->client, left < 0.25 ? left : 0.25, ctl->scene);
        if (rc == LAG_CLIENT_OK) return 0;
        if (g_signal) {
            ctl->end = "signal"; /* lag_ctl_fail: the summary, exit 0 */
            return 1;
        }
        if (rc < 0 || !(left > 0.25)) {
            if (rc < 0)
                fprintf(stderr, "%s: %s\n", ctl->name, lag_client_errmsg(ctl->client));
            else
                say_no_scene(ctl);
            return 1;
        }
    }
}

/* ctl->model from the scene's parameters, if the scene runs `model` (NULL: any). */
static int model_from_scene(lag_ctl *ctl, const char *model)
{
    char err[256];
    const char *runs = lag_client_scene_model(ctl->scene);
    if (!model) model = runs; /* any model this build knows */
    if (strcmp(runs, model) != 0) {
        fprintf(stderr, "%s: prefix %s runs model '%s', not %s\n", ctl->name, ctl->prefix,
                runs, model);
        return 1;
    }
    int kind = lag_model_kind_from_name(model);
    if (kind < 0) {
        fprintf(stderr, "%s: no model '%s' in this build\n", ctl->name, model);
        return 1;
    }
    ctl->kind = (lag_model_kind)kind;
    lag_model_default_unfinished(&ctl->model, ctl->kind);
    for (int i = 0; i < lag_client_scene_num_params(ctl->scene); i++) {
        const char *name = lag_client_scene_param_name(ctl->scene, i);
        int k = lag_model_param_index(ctl->kind, name);
        if (k >= 0) ctl->model.p[k] = lag_client_scene_param_value(ctl->scene, i);
        else fprintf(stderr, "%s: ignoring unknown parameter %s\n", ctl->name, name);
    }
    lag_model_finish(&ctl->model);
    if (lag_model_validate(&ctl->model, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "%s: scene parameters: %s\n", ctl->name, err);
        return 1;
    }
    return 0;
}

int lag_ctl_start(lag_ctl *ctl, const char *model)
{
    int rc;
    if (ctl->trace_path && (rc = open_trace(ctl))) return rc;
    if (!ctl->prefix && (rc = pick_prefix(ctl, model))) return rc;
    if ((rc = connect_client(ctl)) || (rc = wait_scene(ctl)) ||
        (rc = model_from_scene(ctl, model)))
        return rc;
    ctl->heard = lag_client_now();
    return 0;
}

/* A state of another generation (a reset, a SET): the client returned it with its
 * scene (lagsim_client.h, the scene rule), which becomes ctl->scene and ctl->model. */
static int scene_changed(lag_ctl *ctl)
{
    lag_client_latest_scene(ctl->client, ctl->scene);
    if (model_from_scene(ctl, lag_client_scene_model(ctl->scene)) == 0) return 0;
    ctl->failed = true;
    ctl->end = "error";
    return LAG_ERR_RUNTIME;
}

int lag_ctl_next_state(lag_ctl *ctl, lag_client_state *st)
{
    if (ctl->end) return LAG_CLIENT_TIMEOUT;
    if (ctl->duration > 0 && ctl->states > 0 &&
        ctl->current.sim_time - ctl->t_first >=
            ctl->duration - 0.5 * lag_client_scene_control_period(ctl->scene)) {
        ctl->end = "duration";
        return LAG_CLIENT_TIMEOUT;
    }
    for (;;) {
        if (g_signal) {
            ctl->end = "signal";
            return LAG_CLIENT_TIMEOUT;
        }
        int rc = lag_client_wait_state(ctl->client, 0.05, st, sizeof *st);
        /* a copy of a state already returned never comes back: the client answers it
         * with the same command (lagsim_client.c), so the law runs once per state */
        if (rc == LAG_CLIENT_OK) {
            if (st->generation != lag_client_scene_generation(ctl->scene) &&
                (rc = scene_changed(ctl)) != 0)
                return rc;
            if (ctl->states++ == 0) ctl->t_first = st->sim_time;
            ctl->current = *st;
            return LAG_CLIENT_OK;
        }
        if (rc < 0) {
            fprintf(stderr, "%s: %s\n", ctl->name, lag_client_errmsg(ctl->client));
            ctl->failed = true;
            ctl->end = "error";
            return rc;
        }
        if (ctl->stopped) {
            ctl->end = "stop";
            return LAG_CLIENT_TIMEOUT;
        }
        if (lag_client_now() - ctl->heard > ctl->timeout) {
            ctl->end = "silence";
            return LAG_CLIENT_TIMEOUT;
        }
    }
}

int lag_ctl_command(lag_ctl *ctl, const lag_client_state *st, int n, const char *const *names,
                    const double *effort)
{
    double e[LAG_CLIENT_MAX_JOINTS] = {0};
    if (n < 0 || n > LAG_CLIENT_MAX_JOINTS) n = -1; /* refused by the client, with a message */
    for (int i = 0; i < n; i++) e[i] = isfinite(effort[i]) ? effort[i] : 0.0;
    int rc = lag_client_send_command(ctl->client, st->sim_time, n, names, e);
    if (rc < 0) {
        fprintf(stderr, "%s: %s\n", ctl->name, lag_client_errmsg(ctl->client));
        ctl->failed = true;
        return rc;
    }
    if (ctl->trace) {
        /* %.17g reads back to the same double */
        fprintf(ctl->trace, "%.17g", st->sim_time);
        for (int i = 0; i < st->num_joints; i++) fprintf(ctl->trace, " %.17g", st->position[i]);
        for (int i = 0; i < st->num_joints; i++) fprintf(ctl->trace, " %.17g", st->velocity[i]);
        for (int i = 0; i < n; i++) fprintf(ctl->trace, " %.17g", e[i]);
        fputc('\n', ctl->trace);
    }
    return rc;
}

int lag_ctl_finish(lag_ctl *ctl, const char *fmt, ...)
{
    lag_client_counters cnt = {0};
    if (ctl->client) lag_client_get_counters(ctl->client, &cnt, sizeof cnt);
    printf("%s: summary end=%s ", ctl->name, ctl->end ? ctl->end : "none");
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    printf(" dropped=%lld repeats=%lld\n", (long long)cnt.dropped, (long long)cnt.repeats);
    fflush(stdout);
    if (ctl->trace) fclose(ctl->trace);
    ctl->trace = NULL;
    lag_client_destroy(ctl->client);
    ctl->client = NULL;
    lag_client_scene_free(ctl->scene);
    ctl->scene = NULL;
    return lag_result_exit(ctl->failed ? LAG_ERR_RUNTIME : LAG_OK);
}

int lag_ctl_fail(lag_ctl *ctl)
{
    /* SIGINT or SIGTERM while waiting for the scene: a run that ended, no failure */
    if (ctl->end && strcmp(ctl->end, "signal") == 0) return lag_ctl_finish(ctl, "states=0");
    if (ctl->trace) fclose(ctl->trace);
    ctl->trace = NULL;
    lag_client_destroy(ctl->client);
    ctl->client = NULL;
    lag_client_scene_free(ctl->scene);
    ctl->scene = NULL;
    return ctl->fail_code ? ctl->fail_code : lag_result_exit(LAG_ERR_RUNTIME);
}
