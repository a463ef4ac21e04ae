/*
 * lagsimd's command line: reads the scene (file + --set overrides), then runs the
 * real-time LCM server, an offline run to CSV, or a replay of a recorded log.
 * Exit codes: 0 ok, 1 runtime failure, 2 usage or scene error (nothing ran).
 */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "daemon.h"

#define LAGSIMD_VERSION "0.1.0" /* keep in step with project(VERSION) in CMakeLists.txt */

static void usage(FILE *f)
{
    fputs(
        "usage: lagsimd --config FILE [--set KEY=VALUE ...] [-q] [--duration SECONDS]\n"
        "               [--log FILE.lcm [--log-buffer MIB]]\n"
        "       lagsimd --config FILE --offline --duration SECONDS [--csv PATH|-] [--set ...]\n"
        "       lagsimd --config FILE --replay LOG.lcm [--tolerance X] [--set ...]\n"
        "\n"
        "Steps one Lagrangian model (stick, manipulator, dipc) described by a YAML scene.\n"
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
        "      --csv PATH|-       offline CSV destination (- = stdout; absent = no CSV,\n"
        "                         only the summary line on stderr)\n"
        "      --log FILE.lcm     real-time server: write every message published and\n"
        "                         received to FILE (LCM log format, replaced if it exists),\n"
        "                         in order, from the first state; never makes the loop wait\n"
        "                         in realtime mode (what a slow disk loses is counted and\n"
        "                         said; exit 1 if anything was lost)\n"
        "      --log-buffer MIB   memory between the loop and the log writer, 0.25 to 1024\n"
        "                         (default 16)\n"
        "      --replay LOG.lcm   re-simulate a run recorded by --log or lcm-logger from the\n"
        "                         efforts in its logged states; print the largest difference\n"
        "      --tolerance X      --replay: exit 1 when the largest difference is above X\n"
        "                         (default 0: a log of the same scene and build is exact)\n"
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

int main(int argc, char **argv)
{
    enum { OPT_OFFLINE = 256, OPT_CSV, OPT_REPLAY, OPT_LOG, OPT_LOG_BUFFER, OPT_TOLERANCE };
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
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {"version", no_argument, NULL, 'V'},
        {NULL, 0, NULL, 0},
    };

    const char *config = NULL, *replay = NULL;
    bool offline = false, have_duration = false, have_tolerance = false, have_ring = false;
    lagsimd_opts opts = {.quiet = false, .duration = 0.0, .csv = NULL};
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    int nsets = 0;
    if (!sets) {
        fputs("lagsimd: out of memory\n", stderr);
        return LAGSIMD_EXIT_RUNTIME;
    }

    opterr = 0; /* our own messages */
    int c, at = optind;
    /* '+': stop at the first argument that is not an option (reported below), so that
     * argv[at] is always the element an error concerns */
    while ((c = getopt_long(argc, argv, "+:c:s:d:qhV", longopts, NULL)) != -1) {
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
        case 'q':
            opts.quiet = true;
            break;
        case 'h':
            usage(stdout);
            free(sets);
            return LAGSIMD_EXIT_OK;
        case 'V':
            printf("lagsimd %s\n", LAGSIMD_VERSION);
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
    } else {
        static lag_scene sc;
        char err[1024];
        /* the file is read once: the scene and any change made while running come from
         * the same bytes */
        char *text = NULL;
        size_t len = 0;
        if (lag_scene_read(config, &text, &len, err, sizeof err) != 0 ||
            lag_scene_load_buffer(config, text, len, sets, nsets, &sc, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
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
