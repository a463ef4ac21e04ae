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
        "       lagsimd --config FILE --offline --duration SECONDS [--csv PATH|-] [--set ...]\n"
        "       lagsimd --config FILE --replay LOG.lcm [--set ...]\n"
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
        "  -d, --duration S       sim seconds to run (real-time: <= 0 or absent = until\n"
        "                         stopped; offline: required, >= 0)\n"
        "      --offline          no LCM: simulate as fast as possible, write CSV rows at\n"
        "                         t = 0 and every 1/publish_hz: t,q...,q_dot...,energy\n"
        "      --csv PATH|-       offline CSV destination (- = stdout; absent = no CSV,\n"
        "                         only the summary line on stderr)\n"
        "      --replay LOG.lcm   re-simulate a run recorded by lcm-logger from the efforts\n"
        "                         in its logged states; print the largest difference\n"
        "  -q, --quiet            no live status line / offline summary\n"
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
    enum { OPT_OFFLINE = 256, OPT_CSV, OPT_REPLAY };
    static const struct option longopts[] = {
        {"config", required_argument, NULL, 'c'},
        {"set", required_argument, NULL, 's'},
        {"duration", required_argument, NULL, 'd'},
        {"offline", no_argument, NULL, OPT_OFFLINE},
        {"csv", required_argument, NULL, OPT_CSV},
        {"replay", required_argument, NULL, OPT_REPLAY},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {"version", no_argument, NULL, 'V'},
        {NULL, 0, NULL, 0},
    };

    const char *config = NULL, *replay = NULL;
    bool offline = false, have_duration = false;
    lagsimd_opts opts = {.quiet = false, .duration = 0.0, .csv = NULL};
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    int nsets = 0;
    if (!sets) {
        fputs("lagsimd: out of memory\n", stderr);
        return LAGSIMD_EXIT_RUNTIME;
    }

    opterr = 0; /* our own messages */
    int c;
    while ((c = getopt_long(argc, argv, ":c:s:d:qhV", longopts, NULL)) != -1) {
        switch (c) {
        case 'c':
            config = optarg;
            break;
        case 's':
            sets[nsets++] = optarg;
            break;
        case 'd': {
            char *end;
            double d = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !isfinite(d)) {
                free(sets);
                return usage_error("--duration: expected a number of seconds, got '%s'",
                                   optarg);
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
        case ':':
            free(sets);
            return usage_error("option %s needs a value", argv[optind - 1]);
        default:
            free(sets);
            return usage_error("unknown option '%s'", argv[optind - 1]);
        }
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
    } else if (offline && opts.duration < 0.0) {
        rc = usage_error("%s", "--duration: expected seconds >= 0");
    } else {
        static lag_scene sc;
        char err[1024];
        if (lag_scene_load(config, sets, nsets, &sc, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            rc = LAGSIMD_EXIT_USAGE;
        } else if (offline) {
            rc = lagsimd_offline(&sc, &opts);
        } else if (replay) {
            rc = lagsimd_replay(&sc, replay, &opts);
        } else if (resolve_default_url(&sc) == 0) {
            rc = lagsimd_realtime(&sc, &opts);
        }
    }
    free(sets);
    return rc;
}
