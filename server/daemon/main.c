/*
 * lagsimd's command line: reads the scene (file + --set overrides), then runs the
 * real-time LCM server, an offline run to CSV, or a replay of a recorded log.
 * Exit codes: 0 ok, 1 runtime failure, 2 usage or scene error (nothing ran): each part
 * returns a lag_result and main() ends with lag_result_exit, the one mapping.
 */
#include <getopt.h>
#include <sys/stat.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "daemon.h"


static void usage(FILE *f)
{
    fputs(
        "usage: lagsimd --config FILE [--set KEY=VALUE ...] [-q] [--duration SECONDS]\n"
        "               [--log FILE.lcm [--log-buffer MIB] [--force | --increment]]\n"
        "       lagsimd --config FILE --offline --duration SECONDS [--csv PATH|- [--force]]\n"
        "               [--set ...]\n"
        "       lagsimd --config FILE --replay LOG.lcm [--tolerance X] [--set ...]\n"
        "       lagsimd --config FILE --cost [--plot FILE.png|FILE.gp] [--set ...]\n"
        "\n",
        f);
    char models[256]; /* from the core's table: a model added there is named here */
    fprintf(f, "Steps one Lagrangian model (%s)\ndescribed by a YAML scene.\n",
            lag_model_names(models, sizeof models));
    fputs(
        "Default: the real-time LCM server (states out, effort commands in) until SIGINT.\n"
        "\n"
        "options:\n"
        "  -c, --config FILE      YAML scene file (required; see config/*.yaml)\n"
        "  -s, --set KEY=VALUE    override a scene key by its dotted path after the file\n"
        "                         is read; VALUE is YAML, e.g. --set integrator.method=dopri5\n"
        "                         --set initial.q=[0,0.1,-0.1]; repeatable, applied in order,\n"
        "                         validated like the file\n"
        "  -d, --duration S       sim seconds to run, 0 to 1e9 (real-time: 0 or absent =\n"
        "                         until stopped; offline: required); time spent waiting\n"
        "                         (for the first command, a lockstep answer, paused) does\n"
        "                         not count: sim time does not advance then\n"
        "      --offline          no LCM: simulate as fast as possible, write CSV rows at\n"
        "                         t = 0 and every 1/publish_hz: t,q...,q_dot...,energy\n"
        "                         (and <joint>_ref,<joint>_ref_dot with a reference)\n"
        "      --csv PATH|-       offline CSV destination (- = stdout; absent = no CSV,\n"
        "                         only the summary line on stderr)\n"
        "      --log FILE.lcm     real-time server: write every message published and\n"
        "                         every command and control request applied to FILE (LCM\n"
        "                         log format), in order, from the first state; refused and\n"
        "                         undecodable ones and status/describe requests are counted\n"
        "                         and a sample of them written (at most 64 KiB a second);\n"
        "                         never makes the loop wait in realtime mode (what a slow\n"
        "                         disk loses is counted and said; exit 1 if anything was\n"
        "                         lost)\n"
        "      --force            --log, --csv, --plot: replace FILE if it exists (else refused,\n"
        "                         exit 2); never a symbolic link (not followed) nor the\n"
        "                         scene file itself, --force or not\n"
        "  -i, --increment        --log: if FILE exists, write FILE.00, FILE.01, ... (the\n"
        "                         first free name), as lcm-logger -i: a service restarted\n"
        "                         with the same --log keeps every run's record\n"
        "      --log-buffer MIB   memory between the loop and the log writer, 0.25 to 1024\n"
        "                         (default 16)\n"
        "      --replay LOG.lcm   re-simulate a run recorded by --log or lcm-logger from the\n"
        "                         efforts in its logged states; print the largest difference\n"
        "      --tolerance X      --replay: exit 1 when the largest difference is above X\n"
        "                         (default 0: a log of the same scene and build is exact)\n"
        "      --cost             measure what accuracy costs on this scene and machine: each\n"
        "                         integrator setting's error over integrator.horizon against\n"
        "                         a tight reference, its CPU per sim-second, its margin to\n"
        "                         real time; the error asked for is integrator.error (if the\n"
        "                         scene gives none: the error its own integrator reaches).\n"
        "                         A horizon beyond what two references agree on is cut, and\n"
        "                         said. A scene with integrator.error runs with the cheapest\n"
        "                         setting that meets it\n"
        "      --plot FILE.png    --cost: draw the work-precision diagram (gnuplot); FILE.gp:\n"
        "                         write the gnuplot script that draws it, data inline\n"
        "  -q, --quiet            no live status line or event lines / offline summary\n"
        "  -h, --help             this help\n"
        "  -V, --version          print the version\n"
        "\n"
        "exit codes: 0 ok, 1 runtime failure (e.g. a numeric fault), 2 usage or scene\n"
        "error (reported as file:line:column: what was expected; nothing runs)\n",
        f);
}

static lag_result usage_error(const char *fmt, const char *arg)
{
    fputs("lagsimd: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\n(try lagsimd --help)\n", stderr);
    return LAGSIMD_EXIT_USAGE;
}

/* Names what getopt_long refused. argv[at] is the element it was reading when it answered
 * c ('?' unknown, ':' value missing): options are not permuted ('+'), so that is the
 * option's own element, even inside a cluster like -zq (where argv[optind - 1] is not). */
static lag_result option_error(const struct option *longopts, char **argv, int at, int c)
{
    char msg[256];
    const char *arg = argv[at];
    if (arg[0] == '-' && arg[1] == '-') {
        const char *name = arg + 2;
        int len = (int)strcspn(name, "=");
        int exact = -1, matches = 0, last = -1;
        char cands[160] = "";
        for (int i = 0; longopts[i].name; i++) {
            if (strncmp(longopts[i].name, name, (size_t)len) != 0)
                continue;
            if ((int)strlen(longopts[i].name) == len)
                exact = i;
            matches++;
            last = i;
            size_t used = strlen(cands);
            snprintf(cands + used, sizeof cands - used, "%s--%s", used ? ", " : "",
                     longopts[i].name);
        }
        int known = exact >= 0 ? exact : matches == 1 ? last : -1;
        if (known >= 0 && c == ':')
            snprintf(msg, sizeof msg, "option --%s needs a value", longopts[known].name);
        else if (known >= 0)
            snprintf(msg, sizeof msg, "option --%s takes no value", longopts[known].name);
        else if (matches > 1)
            snprintf(msg, sizeof msg, "ambiguous option '--%.*s' (%s)", len > 64 ? 64 : len,
                     name, cands);
        else
            snprintf(msg, sizeof msg, "unknown option '--%.*s'", len > 64 ? 64 : len, name);
    } else if (c == ':') {
        snprintf(msg, sizeof msg, "option -%c needs a value", optopt);
    } else {
        snprintf(msg, sizeof msg, "unknown option '-%c'", optopt);
    }
    return usage_error("%s", msg);
}

/* A scene without lcm.url leaves the choice to LCM, which reads LCM_DEFAULT_URL: that
 * URL gets the scene's checks too (no file:// logs, no ttl above 0 without
 * lcm.allow_lan) and becomes the scene's, so what runs is what was checked.
 * Returns LAG_OK, or LAG_ERR_SCENE after printing why (exit 2: nothing has run). */
static lag_result resolve_default_url(lag_scene *sc)
{
    const char *env = getenv("LCM_DEFAULT_URL");
    if (sc->lcm.url[0] != '\0' || !env || env[0] == '\0')
        return LAG_OK;
    char err[512];
    if (strlen(env) >= sizeof sc->lcm.url) {
        fprintf(stderr, "lagsimd: LCM_DEFAULT_URL: longer than %zu characters\n",
                sizeof sc->lcm.url - 1);
        return LAG_ERR_SCENE;
    }
    if (lag_scene_check_url(env, sc->lcm.allow_lan, &sc->lcm.ttl, err, sizeof err) != 0) {
        fprintf(stderr, "lagsimd: LCM_DEFAULT_URL: %s\n", err);
        return LAG_ERR_SCENE;
    }
    snprintf(sc->lcm.url, sizeof sc->lcm.url, "%s", env);
    return LAG_OK;
}

/* --increment: *path, or when it exists the first of path.00 ... path.99 that does not
 * (lstat: a dangling symbolic link is a name taken too). Returns LAG_OK, or LAG_ERR_FILE
 * after saying why. */
static lag_result next_free_name(const char **path)
{
    static char name[4096];
    struct stat st;
    if (lstat(*path, &st) != 0) return LAG_OK;
    for (int k = 0; k < 100; k++) {
        if (snprintf(name, sizeof name, "%s.%02d", *path, k) >= (int)sizeof name) break;
        if (lstat(name, &st) != 0) {
            fprintf(stderr, "lagsimd: --log %s exists: writing %s\n", *path, name);
            *path = name;
            return LAG_OK;
        }
    }
    fprintf(stderr, "lagsimd: --log %s and %s.00 to .99 exist: move them away or give --force\n",
            *path, *path);
    return LAG_ERR_FILE;
}

/* Whether the --set overrides give integrator.method (a scene's integrator.error then
 * chooses nothing: the run is told). */
static bool integrator_given(const char *const *sets, int nsets)
{
    for (int i = 0; i < nsets; i++)
        if (strncmp(sets[i], "integrator.method=", 18) == 0) return true;
    return false;
}

/* integrator.error: the integrator the calibration chooses, or the one the command line
 * names with --set integrator.method=... (a rerun of a choice, or the user's own): then
 * said, and not measured. OUT: ch */
static lag_result choose(const lag_scene *sc, const char *const *sets, int nsets, bool offline,
                         bool quiet, lagsimd_choice *ch)
{
    ch->n = 0;
    if (sc->accuracy.error > 0 && integrator_given(sets, nsets)) {
        fprintf(stderr, "lagsimd: integrator.error %g: the integrator given by --set (%s, dt %g "
                "s) is used, not measured\n", sc->accuracy.error,
                lag_method_name(sc->sim.integrator.method), sc->sim.integrator.dt);
        return LAGSIMD_EXIT_OK;
    }
    return lagsimd_choose_integrator(sc, offline, quiet, ch);
}

/* Appends the calibration's choice to the overrides (main made room for its 4) and
 * loads the scene again with it. */
static lag_result reload_with(const char *config, const char *text, size_t len,
                              const char **sets, int *nsets, const lagsimd_choice *ch,
                              lag_scene *sc)
{
    char err[1024];
    for (int i = 0; i < ch->n; i++) sets[(*nsets)++] = ch->kv[i];
    if (lag_scene_load_buffer(config, text, len, sets, *nsets, sc, err, sizeof err) != 0) {
        fprintf(stderr, "lagsimd: the integrator chosen for integrator.error: %s\n", err);
        return LAG_ERR_SCENE;
    }
    return LAG_OK;
}

/* What the command line says. */
typedef struct cmdline {
    const char *config, *replay, *plot;
    bool cost, increment, offline;
    bool have_duration, have_tolerance, have_ring; /* given, for the checks of combinations */
    lagsimd_opts opts;
    const char **sets; /* the --set overrides, and room for a calibration's choice */
    int nsets;
} cmdline;

enum { OPT_OFFLINE = 256, OPT_CSV, OPT_REPLAY, OPT_LOG, OPT_LOG_BUFFER, OPT_TOLERANCE,
       OPT_COST, OPT_PLOT, OPT_FORCE };
static const struct option longopts[] = {
    {"config", required_argument, NULL, 'c'},
    {"set", required_argument, NULL, 's'},
    {"duration", required_argument, NULL, 'd'},
    {"offline", no_argument, NULL, OPT_OFFLINE},
    {"csv", required_argument, NULL, OPT_CSV},
    {"replay", required_argument, NULL, OPT_REPLAY},
    {"log", required_argument, NULL, OPT_LOG},
    {"log-buffer", required_argument, NULL, OPT_LOG_BUFFER},
    {"tolerance", required_argument, NULL, OPT_TOLERANCE},
    {"cost", no_argument, NULL, OPT_COST},
    {"plot", required_argument, NULL, OPT_PLOT},
    {"force", no_argument, NULL, OPT_FORCE},
    {"increment", no_argument, NULL, 'i'},
    {"quiet", no_argument, NULL, 'q'},
    {"help", no_argument, NULL, 'h'},
    {"version", no_argument, NULL, 'V'},
    {NULL, 0, NULL, 0},
};

/* The options with a number: a plain decimal in range, else a usage error. */
static lag_result take_number(cmdline *cl, int c, const char *arg)
{
    double v = 0.0;
    const bool plain = lag_scene_read_decimal(arg, &v) == LAG_OK;
    if (c == 'd') {
        /* at most LAG_SCENE_MAX_TIME, so that the run's tick count is exact and cannot
         * overflow */
        if (!plain || !(v >= 0.0) || !(v <= LAG_SCENE_MAX_TIME))
            return usage_error("--duration: expected a number of seconds from 0 to 1e9, "
                               "got '%s'", arg);
        cl->opts.duration = v;
        cl->have_duration = true;
    } else if (c == OPT_LOG_BUFFER) {
        if (!plain || !(v >= 0.25) || !(v <= 1024))
            return usage_error("--log-buffer: expected a number of MiB from 0.25 to 1024, "
                               "got '%s'", arg);
        cl->opts.log_ring = (size_t)(v * 1048576.0);
        cl->have_ring = true;
    } else { /* OPT_TOLERANCE */
        if (!plain || !(v >= 0.0) || !isfinite(v))
            return usage_error("--tolerance: expected a number >= 0, got '%s'", arg);
        cl->opts.tolerance = v;
        cl->have_tolerance = true;
    }
    return LAG_OK;
}

/* One option that getopt_long returned (not -h, -V nor an error). */
static lag_result take_option(cmdline *cl, int c, const char *arg)
{
    switch (c) {
    case 'c': cl->config = arg; break;
    case 's': cl->sets[cl->nsets++] = arg; break;
    case 'd': case OPT_LOG_BUFFER: case OPT_TOLERANCE: return take_number(cl, c, arg);
    case OPT_OFFLINE: cl->offline = true; break;
    case OPT_CSV: cl->opts.csv = arg; break;
    case OPT_REPLAY: cl->replay = arg; break;
    case OPT_LOG: cl->opts.log = arg; break;
    case OPT_COST: cl->cost = true; break;
    case OPT_PLOT: cl->plot = arg; break;
    case OPT_FORCE: cl->opts.force = true; break;
    case 'i': cl->increment = true; break;
    case 'q': cl->opts.quiet = true; break;
    }
    return LAG_OK;
}

/* Reads the options into cl. *done: --help or --version answered (LAG_OK). */
static lag_result read_options(cmdline *cl, int argc, char **argv, bool *done)
{
    opterr = 0; /* our own messages */
    int c, at = optind;
    /* '+': stop at the first argument that is not an option (reported below), so that
     * argv[at] is always the element an error concerns */
    while ((c = getopt_long(argc, argv, "+:c:s:d:iqhV", longopts, NULL)) != -1) {
        if (c == 'h' || c == 'V') {
            if (c == 'h') usage(stdout);
            else printf("lagsimd %s\n", LAGSIM_VERSION);
            *done = true;
            return LAG_OK;
        }
        if (c == '?' || c == ':') return option_error(longopts, argv, at, c);
        lag_result r = take_option(cl, c, optarg);
        if (r != LAG_OK) return r;
        at = optind;
    }
    if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
    return LAG_OK;
}

/* The options that need or exclude each other (said as a usage error), and --increment's
 * free name. */
static lag_result check_options(cmdline *cl)
{
    const lagsimd_opts *o = &cl->opts;
    const char *why = NULL;
    if (!cl->config) why = "--config FILE is required";
    else if (cl->offline && cl->replay) why = "--offline and --replay exclude each other";
    else if (o->csv && !cl->offline) why = "--csv needs --offline";
    else if (cl->offline && !cl->have_duration) why = "--offline needs --duration SECONDS";
    else if (o->log && (cl->offline || cl->replay))
        why = "--log records the real-time server: not with --offline or --replay";
    else if (cl->have_ring && !o->log) why = "--log-buffer needs --log FILE";
    else if (cl->have_tolerance && !cl->replay) why = "--tolerance needs --replay LOG";
    else if (cl->cost && (cl->offline || cl->replay || o->log))
        why = "--cost measures the scene and exits: not with --offline, --replay or --log";
    else if (cl->plot && !cl->cost) why = "--plot needs --cost";
    else if (cl->increment && (!o->log || o->force))
        why = "--increment picks a free name for --log FILE: give --log, and not --force";
    else if (cl->increment && next_free_name(&cl->opts.log) != LAG_OK) return LAG_ERR_FILE;
    else if (o->force && !o->log && !o->csv && !cl->plot)
        why = "--force replaces the file of --log, --csv or --plot: give one";
    return why ? usage_error("%s", why) : LAG_OK;
}

/* The scene as it runs: loaded from its file's bytes and the overrides, with the
 * integrator integrator.error chooses (replay: the one the command line gives). */
static lag_result prepare_scene(cmdline *cl, const char *text, size_t len, lag_scene *sc)
{
    static lagsimd_choice choice;
    char err[1024];
    if (lag_scene_load_buffer(cl->config, text, len, cl->sets, cl->nsets, sc, err,
                              sizeof err) != LAG_OK) {
        fprintf(stderr, "%s\n", err);
        return LAG_ERR_SCENE;
    }
    if (cl->cost) return LAG_OK;
    if (cl->replay && sc->accuracy.error > 0 && !integrator_given(cl->sets, cl->nsets)) {
        fprintf(stderr, "lagsimd: %s: integrator.error: the recorded run chose its integrator "
                "when it started; give the same with --set integrator.method=... --set "
                "integrator.dt=... (and rtol, atol for dopri5), as the run printed them\n",
                cl->config);
        return LAG_ERR_USAGE;
    }
    choice.n = 0;
    if (!cl->replay && choose(sc, cl->sets, cl->nsets, cl->offline, cl->opts.quiet,
                              &choice) != LAG_OK)
        return LAG_ERR_USAGE; /* said why */
    if (choice.n > 0)
        return reload_with(cl->config, text, len, cl->sets, &cl->nsets, &choice, sc);
    return LAG_OK;
}

/* Reads the scene file once (the scene and any change made while running come from the
 * same bytes) and runs what the command line asks. */
static lag_result run(cmdline *cl)
{
    static lag_scene sc;
    char err[1024];
    char *text = NULL;
    size_t len = 0;
    lag_result rc;
    if (lag_scene_read(cl->config, &text, &len, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "%s\n", err);
        rc = LAG_ERR_SCENE;
    } else if ((rc = prepare_scene(cl, text, len, &sc)) != LAG_OK) {
        /* said why */
    } else if (cl->cost) {
        rc = lagsimd_cost(&sc, cl->plot, cl->opts.force);
    } else {
        lagsimd_opts *o = &cl->opts;
        o->scene_name = cl->config;
        o->scene_text = text;
        o->scene_len = len;
        o->sets = cl->sets;
        o->nsets = cl->nsets;
        if (cl->offline)
            rc = lagsimd_offline(&sc, o);
        else if (cl->replay)
            rc = lagsimd_replay(&sc, cl->replay, o);
        else if ((rc = resolve_default_url(&sc)) == LAG_OK)
            rc = lagsimd_realtime(&sc, o);
    }
    free(text);
    return rc;
}

static lag_result lagsimd_main(int argc, char **argv)
{
    cmdline cl = {.opts = {.quiet = false, .duration = 0.0, .csv = NULL}};
    /* the --set overrides, and room for a calibration's choice (lagsimd_choice) */
    cl.sets = calloc((size_t)argc + 1 + 4, sizeof *cl.sets);
    if (!cl.sets) {
        fputs("lagsimd: out of memory\n", stderr);
        return LAG_ERR_NOMEM;
    }
    bool done = false;
    lag_result rc = read_options(&cl, argc, argv, &done);
    if (rc == LAG_OK && !done) rc = check_options(&cl);
    if (rc == LAG_OK && !done) rc = run(&cl);
    free(cl.sets);
    return rc;
}

int main(int argc, char **argv)
{
    return lag_result_exit(lagsimd_main(argc, argv));
}
