/*
 * lagsimd's command line: reads the scene (file + --set overrides), then runs the
 * real-time LCM server, an offline run to CSV, or a replay of a recorded log.
 * Exit codes: 0 ok, 1 runtime failure, 2 usage or scene error (nothing ran).
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
        "       lagsimd --config FILE --cost [--plot FILE.png] [--set ...]\n"
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
        "                         real time; the error asked for is integrator.error (1e-6\n"
        "                         if the scene gives none). A scene with integrator.error\n"
        "                         runs with the cheapest setting that meets it\n"
        "      --plot FILE.png    --cost: draw the work-precision diagram (gnuplot)\n"
        "  -q, --quiet            no live status line or event lines / offline summary\n"
        "  -h, --help             this help\n"
        "  -V, --version          print the version\n"
        "\n"
        "exit codes: 0 ok, 1 runtime failure (e.g. a numeric fault), 2 usage or scene\n"
        "error (reported as file:line:column: what was expected; nothing runs)\n",
        f);
}

static int usage_error(const char *fmt, const char *arg)
{
    fputs("lagsimd: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\n(try lagsimd --help)\n", stderr);
    return LAGSIMD_EXIT_USAGE;
}

/* Names what getopt_long refused. argv[at] is the element it was reading when it answered
 * c ('?' unknown, ':' value missing): options are not permuted ('+'), so that is the
 * option's own element, even inside a cluster like -zq (where argv[optind - 1] is not). */
static int option_error(const struct option *longopts, char **argv, int at, int c)
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
 * Returns 0, or -1 after printing why (exit 2: nothing has run). */
static int resolve_default_url(lag_scene *sc)
{
    const char *env = getenv("LCM_DEFAULT_URL");
    if (sc->lcm.url[0] != '\0' || !env || env[0] == '\0')
        return 0;
    char err[512];
    if (strlen(env) >= sizeof sc->lcm.url) {
        fprintf(stderr, "lagsimd: LCM_DEFAULT_URL: longer than %zu characters\n",
                sizeof sc->lcm.url - 1);
        return -1;
    }
    if (lag_scene_check_url(env, sc->lcm.allow_lan, &sc->lcm.ttl, err, sizeof err) != 0) {
        fprintf(stderr, "lagsimd: LCM_DEFAULT_URL: %s\n", err);
        return -1;
    }
    snprintf(sc->lcm.url, sizeof sc->lcm.url, "%s", env);
    return 0;
}

/* --increment: *path, or when it exists the first of path.00 ... path.99 that does not
 * (lstat: a dangling symbolic link is a name taken too). Returns 0, or -1 after saying why. */
static int next_free_name(const char **path)
{
    static char name[4096];
    struct stat st;
    if (lstat(*path, &st) != 0) return 0;
    for (int k = 0; k < 100; k++) {
        if (snprintf(name, sizeof name, "%s.%02d", *path, k) >= (int)sizeof name) break;
        if (lstat(name, &st) != 0) {
            fprintf(stderr, "lagsimd: --log %s exists: writing %s\n", *path, name);
            *path = name;
            return 0;
        }
    }
    fprintf(stderr, "lagsimd: --log %s and %s.00 to .99 exist: move them away or give --force\n",
            *path, *path);
    return -1;
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
 * said, and not measured. Returns an exit code. OUT: ch */
static int choose(const lag_scene *sc, const char *const *sets, int nsets, bool offline,
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
static int reload_with(const char *config, const char *text, size_t len, const char **sets,
                       int *nsets, const lagsimd_choice *ch, lag_scene *sc)
{
    char err[1024];
    for (int i = 0; i < ch->n; i++) sets[(*nsets)++] = ch->kv[i];
    if (lag_scene_load_buffer(config, text, len, sets, *nsets, sc, err, sizeof err) != 0) {
        fprintf(stderr, "lagsimd: the integrator chosen for integrator.error: %s\n", err);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
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

    const char *config = NULL, *replay = NULL, *plot = NULL;
    bool cost = false, increment = false;
    bool offline = false, have_duration = false, have_tolerance = false, have_ring = false;
    lagsimd_opts opts = {.quiet = false, .duration = 0.0, .csv = NULL};
    /* the --set overrides, and room for a calibration's choice (lagsimd_choice) */
    const char **sets = calloc((size_t)argc + 1 + 4, sizeof *sets);
    int nsets = 0;
    if (!sets) {
        fputs("lagsimd: out of memory\n", stderr);
        return LAGSIMD_EXIT_RUNTIME;
    }

    opterr = 0; /* our own messages */
    int c, at = optind;
    /* '+': stop at the first argument that is not an option (reported below), so that
     * argv[at] is always the element an error concerns */
    while ((c = getopt_long(argc, argv, "+:c:s:d:iqhV", longopts, NULL)) != -1) {
        switch (c) {
        case 'c':
            config = optarg;
            break;
        case 's':
            sets[nsets++] = optarg;
            break;
        case 'd': {
            /* a plain decimal; at most LAG_SCENE_MAX_TIME, so that the run's tick count
             * is exact and cannot overflow */
            double d = 0.0;
            if (lag_scene_read_decimal(optarg, &d) != 0 || !(d >= 0.0) ||
                !(d <= LAG_SCENE_MAX_TIME)) {
                free(sets);
                return usage_error("--duration: expected a number of seconds from 0 to "
                                   "1e9, got '%s'", optarg);
            }
            opts.duration = d;
            have_duration = true;
            break;
        }
        case OPT_OFFLINE:
            offline = true;
            break;
        case OPT_CSV:
            opts.csv = optarg;
            break;
        case OPT_REPLAY:
            replay = optarg;
            break;
        case OPT_LOG:
            opts.log = optarg;
            break;
        case OPT_LOG_BUFFER: {
            double mib = 0.0;
            if (lag_scene_read_decimal(optarg, &mib) != 0 || !(mib >= 0.25) || !(mib <= 1024)) {
                free(sets);
                return usage_error("--log-buffer: expected a number of MiB from 0.25 to 1024, "
                                   "got '%s'", optarg);
            }
            opts.log_ring = (size_t)(mib * 1048576.0);
            have_ring = true;
            break;
        }
        case OPT_TOLERANCE: {
            double tol = 0.0;
            if (lag_scene_read_decimal(optarg, &tol) != 0 || !(tol >= 0.0) || !isfinite(tol)) {
                free(sets);
                return usage_error("--tolerance: expected a number >= 0, got '%s'", optarg);
            }
            opts.tolerance = tol;
            have_tolerance = true;
            break;
        }
        case OPT_COST:
            cost = true;
            break;
        case OPT_PLOT:
            plot = optarg;
            break;
        case OPT_FORCE:
            opts.force = true;
            break;
        case 'i':
            increment = true;
            break;
        case 'q':
            opts.quiet = true;
            break;
        case 'h':
            usage(stdout);
            free(sets);
            return LAGSIMD_EXIT_OK;
        case 'V':
            printf("lagsimd %s\n", LAGSIM_VERSION);
            free(sets);
            return LAGSIMD_EXIT_OK;
        default: /* '?' or ':' */
            free(sets);
            return option_error(longopts, argv, at, c);
        }
        at = optind;
    }
    if (optind < argc) {
        free(sets);
        return usage_error("unexpected argument '%s'", argv[optind]);
    }
    int rc = LAGSIMD_EXIT_USAGE;
    if (!config) {
        rc = usage_error("%s", "--config FILE is required");
    } else if (offline && replay) {
        rc = usage_error("%s", "--offline and --replay exclude each other");
    } else if (opts.csv && !offline) {
        rc = usage_error("%s", "--csv needs --offline");
    } else if (offline && !have_duration) {
        rc = usage_error("%s", "--offline needs --duration SECONDS");
    } else if (opts.log && (offline || replay)) {
        rc = usage_error("%s", "--log records the real-time server: not with --offline or --replay");
    } else if (have_ring && !opts.log) {
        rc = usage_error("%s", "--log-buffer needs --log FILE");
    } else if (have_tolerance && !replay) {
        rc = usage_error("%s", "--tolerance needs --replay LOG");
    } else if (cost && (offline || replay || opts.log)) {
        rc = usage_error("%s", "--cost measures the scene and exits: not with --offline, --replay or --log");
    } else if (plot && !cost) {
        rc = usage_error("%s", "--plot needs --cost");
    } else if (increment && (!opts.log || opts.force)) {
        rc = usage_error("%s", "--increment picks a free name for --log FILE: give --log, and not --force");
    } else if (increment && next_free_name(&opts.log) != 0) {
        rc = LAGSIMD_EXIT_USAGE;
    } else if (opts.force && !opts.log && !opts.csv && !plot) {
        rc = usage_error("%s", "--force replaces the file of --log, --csv or --plot: give one");
    } else {
        static lag_scene sc;
        char err[1024];
        /* the file is read once: the scene and any change made while running come from
         * the same bytes */
        char *text = NULL;
        size_t len = 0;
        static lagsimd_choice choice;
        if (lag_scene_read(config, &text, &len, err, sizeof err) != 0 ||
            lag_scene_load_buffer(config, text, len, sets, nsets, &sc, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            rc = LAGSIMD_EXIT_USAGE;
        } else if (cost) {
            rc = lagsimd_cost(&sc, plot, opts.force);
        } else if (replay && sc.accuracy.error > 0 && !integrator_given(sets, nsets)) {
            fprintf(stderr, "lagsimd: %s: integrator.error: the recorded run chose its integrator "
                    "when it started; give the same with --set integrator.method=... --set "
                    "integrator.dt=... (and rtol, atol for dopri5), as the run printed them\n",
                    config);
            rc = LAGSIMD_EXIT_USAGE;
        } else if (!replay && choose(&sc, sets, nsets, offline, opts.quiet, &choice) != LAGSIMD_EXIT_OK) {
            rc = LAGSIMD_EXIT_USAGE; /* said why */
        } else if (choice.n > 0 && reload_with(config, text, len, sets, &nsets, &choice, &sc) != 0) {
            rc = LAGSIMD_EXIT_USAGE;
        } else {
            opts.scene_name = config;
            opts.scene_text = text;
            opts.scene_len = len;
            opts.sets = sets;
            opts.nsets = nsets;
            if (offline)
                rc = lagsimd_offline(&sc, &opts);
            else if (replay)
                rc = lagsimd_replay(&sc, replay, &opts);
            else if (resolve_default_url(&sc) == 0)
                rc = lagsimd_realtime(&sc, &opts);
        }
        free(text);
    }
    free(sets);
    return rc;
}
