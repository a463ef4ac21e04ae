/*
 * lagsimd's command line: reads the scene (file + --set overrides), then runs the
 * real-time LCM server, an offline run to CSV, or a replay of a recorded log.
 * Exit codes: 0 ok, 1 runtime failure, 2 usage or scene error (nothing ran): each part
 * returns a lag_result and main() ends with lag_result_exit, the one mapping.
 */
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "daemon.h"
#include "host.h"
#include "scene_run.h"
#include "rt_log.h"


/* --help after the synopsis and the models */
static const char k_options[] =
    "Default: the real-time LCM server (states out, effort commands in) until SIGINT.\n"
    "\n"
    "options:\n"
    "  -c, --config FILE      YAML scene file (see config/*.yaml); given several times\n"
    "                         (real-time), one process runs each as a plant of its own\n"
    "      --plants DIR       a host of plants: every DIR/NAME.yaml a plant of its own,\n"
    "                         its prefix NAME in capitals; read again on SIGHUP and when\n"
    "                         a file changes (a new file starts its plant, a changed one\n"
    "                         restarts it, a removed one stops it; no other is touched)\n"
    "      --port-base P      a host's plants whose scene has no lcm.url get port pairs\n"
    "                         of their own: P, P + 2, ... (the first free), on the group\n"
    "                         of LCM_DEFAULT_URL (lagsimctl list shows each plant's URL);\n"
    "                         default with --plants: the pairs after LCM_DEFAULT_URL's\n"
    "      --instance BASE    the unit's form (lagsimd@NAME): BASE.yaml as one plant\n"
    "                         (--config), or BASE.d/ as a host (--plants); not both\n"
    "  -s, --set KEY=VALUE    override a scene key by its dotted path after the file\n"
    "                         is read; VALUE is YAML, e.g. --set integrator.method=dopri5\n"
    "                         --set initial.q=[0,0.1,-0.1]; repeatable, applied in order,\n"
    "                         validated like the file\n"
    "  -d, --duration S       sim seconds to run, 0 to 1e9 (real-time: 0 or absent =\n"
    "                         until stopped; offline: required); time spent waiting\n"
    "                         (for the first command, a lockstep answer, paused) does\n"
    "                         not count: sim time does not advance then; a reset does\n"
    "                         not start it again: the sim time run before it counts\n"
    "      --offline          no LCM: simulate as fast as possible, write CSV rows at\n"
    "                         t = 0 and every 1/publish_hz: t,q...,q_dot...,energy\n"
    "                         (and <joint>_ref,_ref_dot,_ref_ddot with a reference)\n"
    "      --csv PATH|-       offline CSV destination (- = stdout; absent = no CSV,\n"
    "                         only the summary line on stderr)\n"
    "      --log FILE.lcm     real-time server: write every message published and the\n"
    "                         commands and control requests received to FILE (LCM log\n"
    "                         format), in order, from the first state; received ones\n"
    "                         are counted and written while a byte budget allows:\n"
    "                         applied ones, two full commands a control period (8 KiB\n"
    "                         a second at least); refused ones and status/describe\n"
    "                         requests, 8 KiB a second; so no flood fills the disk;\n"
    "                         never makes the loop wait in realtime mode (what a slow\n"
    "                         disk loses is counted and said; exit 1 if anything was\n"
    "                         lost)\n"
    "      --force            --log, --csv, --plot: replace FILE if it exists (else refused,\n"
    "                         exit 2); never a symbolic link (not followed) nor the\n"
    "                         scene file itself, --force or not\n"
    "  -i, --increment        --log: write the next file of the series FILE.000000,\n"
    "                         FILE.000001, ... (one past the highest number there; FILE\n"
    "                         itself untouched), as lcm-logger -i but never running out\n"
    "                         (past 999999 the number widens): a service restarted with\n"
    "                         the same --log keeps every run's record\n"
    "      --keep N           --increment: keep the series' N newest files (this one\n"
    "                         included), 1 to 1000000; the older ones are removed at\n"
    "                         start and at each new file: only regular files of this\n"
    "                         user named exactly FILE.<number> (never a symbolic link)\n"
    "      --split-mb MIB     --increment: go on in the series' next file once a file\n"
    "                         holds MIB mebibytes (at a record's end), as lcm-logger\n"
    "                         --split-mb; 0.0625 to 1048576. With --keep, the log takes\n"
    "                         at most about N x MIB on disk\n"
    "      --log-buffer MIB   memory between the loop and the log writer, 0.25 to 1024\n"
    "                         (default 16; a host's plant: 1); a host's plant with --log\n"
    "                         DIR/FILE writes DIR/NAME/FILE, NAME the plant's own\n"
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
    "      --list WHAT        print the names of the core's table, one a line, and exit:\n"
    "                         models (a scene's model:), methods (integrator.method)\n"
    "                         or effects (the keys under effects:)\n"
    "  -q, --quiet            only warnings and errors on stderr: no live status line,\n"
    "                         no event lines but the losses (a watchdog trip, overruns,\n"
    "                         input limited, commands refused: a line per kind at most\n"
    "                         every 10 s, counted), no waiting lines, no note of where\n"
    "                         it listens (real time); no summary (offline)\n"
    "  -h, --help             this help\n"
    "  -V, --version          print the version\n"
    "\n"
    "exit codes: 0 ok, 1 runtime failure (e.g. a numeric fault), 2 usage or scene\n"
    "error (reported as file:line:column: what was expected; nothing runs)\n"
    "\n"
    "A host of plants (--plants, several --config): a plant that cannot start is said\n"
    "and skipped, the others run; exit status 2 only when none started (and none can\n"
    "come: no --plants), 1 when a plant's --log lost records\n";

static void usage(FILE *f)
{
    fputs(
        "usage: lagsimd --config FILE [--set KEY=VALUE ...] [-q] [--duration SECONDS]\n"
        "               [--log FILE.lcm [--log-buffer MIB]\n"
        "                [--force | --increment [--keep N] [--split-mb MIB]]]\n"
        "       lagsimd --plants DIR [--config FILE ...] [--port-base P] [options as above]\n"
        "       lagsimd --config FILE --offline --duration SECONDS [--csv PATH|- [--force]]\n"
        "               [--set ...]\n"
        "       lagsimd --config FILE --replay LOG.lcm [--tolerance X] [--set ...]\n"
        "       lagsimd --config FILE --cost [--plot FILE.png|FILE.gp] [--set ...]\n"
        "       lagsimd --list models|methods|effects\n"
        "\n",
        f);
    char models[256]; /* from the core's table: a model added there is named here */
    fprintf(f, "Steps one Lagrangian model (%s)\ndescribed by a YAML scene.\n",
            lag_model_names(models, sizeof models));
    fputs(k_options, f);
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

/* --list WHAT: the names of one of the core's tables, one a line, in the table's order
 * (what scripts iterate: tests/scene/determinism.sh takes the methods from here). */
static lag_result print_list(const char *what)
{
    enum { MODELS, METHODS, EFFECTS } t;
    if (!strcmp(what, "models")) t = MODELS;
    else if (!strcmp(what, "methods")) t = METHODS;
    else if (!strcmp(what, "effects")) t = EFFECTS;
    else return usage_error("--list: expected models, methods or effects, got '%s'", what);
    int n = t == MODELS ? LAG_MODEL_COUNT : t == METHODS ? LAG_METHOD_COUNT : LAG_EFF_COUNT;
    for (int k = 0; k < n; k++)
        puts(t == MODELS ? lag_model_info_get((lag_model_kind)k)->name
             : t == METHODS ? lag_method_name((lag_method)k) : lag_effect_info_get(k).name);
    return LAG_OK;
}

/* What the command line says. */
typedef struct cmdline {
    const char *config, *replay, *plot, *list;
    const char **configs;   /* every --config, in order */
    int nconfigs;
    const char *plants;     /* --plants DIR */
    const char *instance;   /* --instance BASE */
    char instance_path[4096];
    int port_base;          /* --port-base P, 0: none */
    bool cost, offline;
    bool have_duration, have_tolerance, have_ring; /* given, for the checks of combinations */
    lagsimd_opts opts;
    const char **sets; /* the --set overrides, and room for a calibration's choice */
    int nsets;
} cmdline;

enum { OPT_OFFLINE = 256, OPT_CSV, OPT_REPLAY, OPT_LOG, OPT_LOG_BUFFER, OPT_TOLERANCE,
       OPT_COST, OPT_PLOT, OPT_FORCE, OPT_KEEP, OPT_SPLIT, OPT_LIST, OPT_PLANTS,
       OPT_PORT_BASE, OPT_INSTANCE };
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
    {"list", required_argument, NULL, OPT_LIST},
    {"plants", required_argument, NULL, OPT_PLANTS},
    {"port-base", required_argument, NULL, OPT_PORT_BASE},
    {"instance", required_argument, NULL, OPT_INSTANCE},
    {"increment", no_argument, NULL, 'i'},
    {"keep", required_argument, NULL, OPT_KEEP},
    {"split-mb", required_argument, NULL, OPT_SPLIT},
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
    } else if (c == OPT_KEEP) {
        if (!plain || !(v >= 1) || !(v <= 1000000) || v != floor(v))
            return usage_error("--keep: expected a whole number of files from 1 to 1000000, "
                               "got '%s'", arg);
        cl->opts.log_keep = (int)v;
    } else if (c == OPT_SPLIT) {
        if (!plain || !(v >= 0.0625) || !(v <= 1048576))
            return usage_error("--split-mb: expected a number of MiB from 0.0625 to 1048576, "
                               "got '%s'", arg);
        cl->opts.log_split = (int64_t)(v * 1048576.0);
    } else if (c == OPT_LOG_BUFFER) {
        if (!plain || !(v >= 0.25) || !(v <= 1024))
            return usage_error("--log-buffer: expected a number of MiB from 0.25 to 1024, "
                               "got '%s'", arg);
        cl->opts.log_ring = (size_t)(v * 1048576.0);
        cl->have_ring = true;
    } else if (c == OPT_PORT_BASE) {
        if (!plain || !(v >= 1024) || !(v <= 65534) || v != floor(v))
            return usage_error("--port-base: expected a whole port number from 1024 to 65534, "
                               "got '%s'", arg);
        cl->port_base = (int)v;
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
    case 'c':
        if (!cl->config) cl->config = arg;
        cl->configs[cl->nconfigs++] = arg;
        break;
    case OPT_PLANTS:
        if (cl->plants) return usage_error("--plants: one directory (got a second: '%s')", arg);
        cl->plants = arg;
        break;
    case OPT_INSTANCE: cl->instance = arg; break;
    case 's': cl->sets[cl->nsets++] = arg; break;
    case 'd': case OPT_LOG_BUFFER: case OPT_TOLERANCE: case OPT_KEEP: case OPT_SPLIT:
    case OPT_PORT_BASE:
        return take_number(cl, c, arg);
    case OPT_OFFLINE: cl->offline = true; break;
    case OPT_CSV: cl->opts.csv = arg; break;
    case OPT_REPLAY: cl->replay = arg; break;
    case OPT_LOG: cl->opts.log = arg; break;
    case OPT_COST: cl->cost = true; break;
    case OPT_PLOT: cl->plot = arg; break;
    case OPT_FORCE: cl->opts.force = true; break;
    case OPT_LIST: cl->list = arg; break;
    case 'i': cl->opts.log_increment = true; break;
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

/* --instance BASE: BASE.yaml (one plant) or BASE.d/ (a host), exactly one of them. */
static lag_result take_instance(cmdline *cl)
{
    if (!cl->instance) return LAG_OK;
    if (cl->config || cl->plants)
        return usage_error("%s", "--instance names the scene or the directory: not with --config "
                           "or --plants");
    struct stat y, d;
    char yaml[4096];
    bool has_y = snprintf(yaml, sizeof yaml, "%s.yaml", cl->instance) < (int)sizeof yaml &&
                 stat(yaml, &y) == 0;
    bool has_d = snprintf(cl->instance_path, sizeof cl->instance_path, "%s.d", cl->instance) <
                     (int)sizeof cl->instance_path &&
                 stat(cl->instance_path, &d) == 0 && S_ISDIR(d.st_mode);
    if (has_y == has_d) {
        fprintf(stderr, "lagsimd: --instance %s: %s %s.yaml %s %s.d/ (one plant, or a host of "
                "plants: one of them)\n", cl->instance, has_y ? "both" : "neither",
                cl->instance, has_y ? "and" : "nor", cl->instance);
        return LAGSIMD_EXIT_USAGE;
    }
    if (has_y) {
        snprintf(cl->instance_path, sizeof cl->instance_path, "%s", yaml);
        cl->config = cl->instance_path;
        cl->configs[cl->nconfigs++] = cl->instance_path;
    } else {
        cl->plants = cl->instance_path;
    }
    return LAG_OK;
}

/* The options that need or exclude each other (said as a usage error). */
static lag_result check_options(cmdline *cl)
{
    const lagsimd_opts *o = &cl->opts;
    const char *why = NULL;
    if (cl->list) why = cl->config || cl->plants || cl->instance || cl->port_base || cl->nsets || cl->offline || cl->replay || cl->cost || o->log ||
                            o->csv || cl->plot || cl->have_duration || cl->have_tolerance ||
                            o->log_increment || o->log_keep || o->log_split || o->force
                            ? "--list prints a table and exits: not with other options" : NULL;
    else if (!cl->config && !cl->plants)
        why = "--config FILE is required (or --plants DIR: a host of plants)";
    else if ((cl->plants || cl->nconfigs > 1) && (cl->offline || cl->replay || cl->cost))
        why = "--plants and several --config run a host of real-time plants: not with "
              "--offline, --replay or --cost";
    else if (cl->port_base && !cl->plants && cl->nconfigs < 2)
        why = "--port-base gives a host's plants their ports: give --plants DIR (or several "
              "--config)";
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
    else if (o->log_increment && (!o->log || o->force))
        why = "--increment writes the next file of --log FILE's series: give --log, and not "
              "--force";
    else if ((o->log_keep || o->log_split) && !o->log_increment)
        why = "--keep and --split-mb act on the series of --log FILE --increment: give both";
    else if (o->force && !o->log && !o->csv && !cl->plot)
        why = "--force replaces the file of --log, --csv or --plot: give one";
    return why ? usage_error("%s", why) : LAG_OK;
}

/* The scene as it runs: loaded from its file's bytes and the overrides, with the
 * integrator integrator.error chooses (replay: the one the command line gives). */
static lag_result prepare_scene(cmdline *cl, const char *text, size_t len, lag_scene *sc)
{
    static lagsimd_choice choice;
    scene_run_how how = {cl->cost, cl->replay != NULL, cl->offline, cl->opts.quiet};
    return scene_run_load(cl->config, text, len, cl->sets, &cl->nsets, how, &choice, sc);
}

/* A host of plants: --plants DIR and every --config. */
static lag_result run_host(cmdline *cl)
{
    host_conf c = {cl->plants, cl->configs, cl->nconfigs, cl->sets, cl->nsets, cl->port_base,
                   cl->opts};
    return lagsimd_host(&c);
}

/* Reads the scene file once (the scene and any change made while running come from the
 * same bytes) and runs what the command line asks. */
static lag_result run(cmdline *cl)
{
    if (cl->plants || cl->nconfigs > 1) return run_host(cl);
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
        else if ((rc = scene_run_default_url(&sc)) == LAG_OK)
            rc = lagsimd_realtime(&sc, o);
    }
    free(text);
    return rc;
}

/* --log under a file-size limit (RLIMIT_FSIZE; a unit's LimitFSIZE): the limit is an error
 * said (EFBIG: SIGXFSZ is ignored), never a kill. A series split where a file can reach the
 * limit is refused; a log that cannot split is told where it stops. */
static lag_result check_file_limit(const lagsimd_opts *o)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_FSIZE, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return LAG_OK;
    double ring = (double)(o->log_ring ? o->log_ring : RT_LOG_RING_DEFAULT);
    double lim = (double)rl.rlim_cur;
    if (o->log_split > 0 && (double)o->log_split + ring > lim) {
        fprintf(stderr, "lagsimd: --split-mb %.6g: a file of the series may hold it plus the "
                "--log-buffer ring (%.6g MiB), above the file-size limit of this process "
                "(RLIMIT_FSIZE, a unit's LimitFSIZE): %.6g MiB; give a smaller --split-mb\n",
                (double)o->log_split / 1048576.0, ring / 1048576.0, lim / 1048576.0);
        return LAG_ERR_USAGE;
    }
    if (o->log_split == 0)
        fprintf(stderr, "lagsimd: --log %s: files are limited to %.6g MiB here (RLIMIT_FSIZE): "
                "the log stops there, said (--increment --split-mb goes on in a new file "
                "before it)\n", o->log, lim / 1048576.0);
    return LAG_OK;
}

static lag_result lagsimd_main(int argc, char **argv)
{
    signal(SIGXFSZ, SIG_IGN); /* a file-size limit: EFBIG, said by the writer, not a kill */
    cmdline cl = {.opts = {.quiet = false, .duration = 0.0, .csv = NULL}};
    /* the --set overrides, and room for a calibration's choice (lagsimd_choice) */
    cl.sets = calloc((size_t)argc + 1 + 4, sizeof *cl.sets);
    cl.configs = calloc((size_t)argc + 1, sizeof *cl.configs);
    if (!cl.sets || !cl.configs) {
        free(cl.sets);
        free(cl.configs);
        fputs("lagsimd: out of memory\n", stderr);
        return LAG_ERR_NOMEM;
    }
    bool done = false;
    lag_result rc = read_options(&cl, argc, argv, &done);
    if (rc == LAG_OK && !done) rc = take_instance(&cl);
    if (rc == LAG_OK && !done) rc = check_options(&cl);
    if (rc == LAG_OK && !done && cl.opts.log && !cl.list) rc = check_file_limit(&cl.opts);
    if (rc == LAG_OK && !done) rc = cl.list ? print_list(cl.list) : run(&cl);
    free(cl.sets);
    free(cl.configs);
    return rc;
}

int main(int argc, char **argv)
{
    return lag_result_exit(lagsimd_main(argc, argv));
}
