/*
 * lagsim-view [--prefix P] [--port 8765] [--url LCM_URL] [--listen ADDR] [--hz N]
 *             [--max-views N] [--allow-host NAME]... [--allow-lan]
 *
 * Watches a lagsimd daemon in a browser: subscribes to its channels and serves one page
 * that draws the model from the scene description, animates it from the states, charts
 * coordinates, velocities, efforts and energy, shows status and events, and sends
 * pause / resume / step / reset. See view.h for the design, docs/view.md for use.
 * Exit codes (lag_result_exit): 0 stopped by a signal, 1 runtime failure, 2 usage.
 */
#include <errno.h>
#include <getopt.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include "lagsim_client.h"
#include "view.h"

static void usage(FILE *f)
{
    fputs("usage: lagsim-view [--prefix P] [--port 8765] [--url LCM_URL] [--listen ADDR]\n"
          "                   [--hz N] [--max-views N] [--allow-host NAME]... [--allow-lan]\n"
          "\n"
          "Serves a live view of a lagsimd daemon to browsers: the model drawn to scale from\n"
          "its scene description and animated from its states, strip charts (the last seconds\n"
          "at once: it keeps the newest 6000 states and energies; m and rad on separate axes;\n"
          "a legend click hides a trace), status, events, and pause / resume / step / reset\n"
          "and kick controls.\n"
          "\n"
          "  -p, --prefix P     the daemon's channel prefix (default: the only plant on the\n"
          "                     bus; several: they are named, exit 2; none: DIPC)\n"
          "      --port N       TCP port (default 8765; 0: any free port, printed)\n"
          "      --url URL      LCM URL (default: LCM's default, which honours LCM_DEFAULT_URL)\n"
          "      --listen ADDR  address to listen on (default 127.0.0.1: this machine only).\n"
          "                     Anything else lets every host that reaches it watch the run\n"
          "                     and pause, step and reset it: there is no authentication\n"
          "      --hz N         stream frames per second per browser at most (default 60)\n"
          "      --max-views N  browsers streaming at once (default 16)\n"
          "      --allow-host NAME  a name browsers may reach the view by, besides the\n"
          "                     --listen address (and localhost on loopback; this host's\n"
          "                     name and, on 0.0.0.0 or ::, its addresses): any other Host\n"
          "                     header gets 421 (DNS rebinding). Repeatable, up to 16\n"
          "      --allow-lan    also take the plant's messages from other hosts (default:\n"
          "                     this host's only, as lagsimd's lcm.allow_lan: false)\n"
          "  -q, --quiet        print only the address\n"
          "  -h, --help         this help\n"
          "\n"
          "HTTP: GET / (the page), GET /api/state (latest scene, state, status, events as\n"
          "JSON), GET /api/history?of=state|energy[&from=SEQ] (the kept states or energies,\n"
          "in pieces of at most 64 kB), GET /events (server-sent events),\n"
          "POST /api/control?request=pause|resume|step|reset[&count=N] and\n"
          "POST /api/kick?joint=J&impulse=I[&duration=S] with the header X-Lagsim: 1.\n"
          "\n"
          "exit codes: 0 stopped by a signal, 1 runtime failure (LCM, the port), 2 usage\n",
          f);
}

static bool parse_uint(const char *s, unsigned lo, unsigned hi, unsigned *out)
{
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || end == s || *end || s[0] == '-' || v < lo || v > hi) return false;
    *out = (unsigned)v;
    return true;
}

static bool is_loopback(const char *a)
{
    return strncmp(a, "127.", 4) == 0 || strcmp(a, "::1") == 0;
}

static lag_result view_main(int argc, char **argv)
{
    enum { OPT_PORT = 256, OPT_URL, OPT_LISTEN, OPT_HZ, OPT_MAX_VIEWS, OPT_ALLOW_HOST,
           OPT_ALLOW_LAN };
    static const struct option longopts[] = {
        {"prefix", required_argument, NULL, 'p'},
        {"port", required_argument, NULL, OPT_PORT},
        {"url", required_argument, NULL, OPT_URL},
        {"listen", required_argument, NULL, OPT_LISTEN},
        {"hz", required_argument, NULL, OPT_HZ},
        {"max-views", required_argument, NULL, OPT_MAX_VIEWS},
        {"allow-host", required_argument, NULL, OPT_ALLOW_HOST},
        {"allow-lan", no_argument, NULL, OPT_ALLOW_LAN},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    const char *prefix = NULL, *url = NULL;
    view_http_opts ho = {.listen = "127.0.0.1", .port = 8765, .hz = 60, .max_streams = 16,
                         .max_connections = 64};
    static const char *allow_hosts[16];
    int n_allow_hosts = 0;
    bool quiet = false, allow_lan = false;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":p:qh", longopts, NULL)) != -1) {
        switch (c) {
        case 'p': prefix = optarg; break;
        case OPT_URL: url = optarg; break;
        case OPT_LISTEN: ho.listen = optarg; break;
        case OPT_PORT:
            if (!parse_uint(optarg, 0, 65535, &ho.port)) {
                fprintf(stderr, "lagsim-view: --port: expected 0 to 65535, got '%s'\n", optarg);
                return LAG_ERR_USAGE;
            }
            break;
        case OPT_HZ:
            if (!parse_uint(optarg, 1, 240, &ho.hz)) {
                fprintf(stderr, "lagsim-view: --hz: expected 1 to 240, got '%s'\n", optarg);
                return LAG_ERR_USAGE;
            }
            break;
        case OPT_MAX_VIEWS:
            if (!parse_uint(optarg, 1, 256, &ho.max_streams)) {
                fprintf(stderr, "lagsim-view: --max-views: expected 1 to 256, got '%s'\n", optarg);
                return LAG_ERR_USAGE;
            }
            break;
        case OPT_ALLOW_HOST: {
            size_t n = strlen(optarg);
            bool ok = n > 0 && n < VIEW_HOST_LEN && n_allow_hosts < 16;
            for (size_t i = 0; ok && i < n; i++) /* a DNS name or an address literal */
                ok = (optarg[i] >= 'a' && optarg[i] <= 'z') || (optarg[i] >= 'A' && optarg[i] <= 'Z') ||
                     (optarg[i] >= '0' && optarg[i] <= '9') || strchr("-._[]:", optarg[i]);
            /* NAME:PORT (one colon: no IPv6 address has one) or [ADDR]:PORT: a port, which
             * the check compares separately with the port bound */
            const char *colon = strchr(optarg, ':'), *bracket = strchr(optarg, ']');
            if (ok && ((colon && !strchr(colon + 1, ':') && optarg[0] != '[') ||
                       (bracket && bracket[1] == ':')))
                ok = false;
            if (!ok) {
                fprintf(stderr, "lagsim-view: --allow-host: expected a host name or address "
                        "without a port (letters, digits, '-', '.', '_', an IPv6 address; at "
                        "most 16 of them), "
                        "got '%s'\n", optarg);
                return LAG_ERR_USAGE;
            }
            allow_hosts[n_allow_hosts++] = optarg;
            break;
        }
        case OPT_ALLOW_LAN: allow_lan = true; break;
        case 'q': quiet = true; break;
        case 'h': usage(stdout); return LAG_OK;
        case ':':
            fprintf(stderr, "lagsim-view: option %s needs a value\n", argv[optind - 1]);
            return LAG_ERR_USAGE;
        default:
            fprintf(stderr, "lagsim-view: unknown option '%s' (try --help)\n", argv[optind - 1]);
            return LAG_ERR_USAGE;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "lagsim-view: unexpected argument '%s' (try --help)\n", argv[optind]);
        return LAG_ERR_USAGE;
    }
    ho.max_connections = ho.max_streams + 240;
    ho.allow_hosts = allow_hosts;
    ho.n_allow_hosts = n_allow_hosts;
    bool local = is_loopback(ho.listen);

    /* signals through a signalfd, blocked before LCM starts any thread */
    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    sigaddset(&sigs, SIGHUP);
    sigprocmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);
    int sig_fd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    if (sig_fd < 0) {
        perror("lagsim-view: signalfd");
        return LAG_ERR_RUNTIME;
    }

    char err[1200];
    static lag_client_plant found;
    if (!prefix) {
        /* the only plant on the bus; none yet: DIPC, watched until it comes */
        int pr = lag_client_pick_plant(url, NULL, 2.0, &found, err, sizeof err);
        if (pr == LAG_CLIENT_ERR_AMBIGUOUS) {
            fprintf(stderr, "lagsim-view: %s\n", err);
            return LAG_ERR_AMBIGUOUS;
        }
        if (pr == LAG_CLIENT_OK) {
            prefix = found.prefix;
        } else {
            prefix = "DIPC";
            fprintf(stderr, "lagsim-view: %s; watching prefix %s\n", err, prefix);
        }
    }
    static view_bridge vb; /* large (rings): static, one bridge per process */
    if (!view_bridge_open(&vb, url, prefix, allow_lan, err, sizeof err)) {
        fprintf(stderr, "lagsim-view: %s\n", err);
        return strstr(err, "--prefix") ? LAG_ERR_USAGE : LAG_ERR_RUNTIME;
    }
    view_http *h = view_http_start(&vb, &ho, err, sizeof err);
    if (!h) {
        fprintf(stderr, "lagsim-view: %s\n", err);
        view_bridge_close(&vb);
        return strstr(err, "--listen") ? LAG_ERR_USAGE : LAG_ERR_RUNTIME;
    }
    bool v6 = strchr(ho.listen, ':') != NULL;
    printf("lagsim-view: http://%s%s%s:%u/  (prefix %s)\n", v6 ? "[" : "", ho.listen,
           v6 ? "]" : "", view_http_port(h), prefix);
    fflush(stdout);
    if (!local)
        fprintf(stderr,
                "lagsim-view: WARNING: listening on %s, not on this machine only: anyone who "
                "reaches port %u sees the run and can pause, step and reset the simulation "
                "(there is no authentication)\n",
                ho.listen, view_http_port(h));
    else if (!quiet)
        fprintf(stderr, "lagsim-view: this machine only (--listen ADDR to open it wider); "
                        "Ctrl-C stops\n");

    int lcm_fd = lcm_get_fileno(vb.lcm), http_fd = view_http_fd(h);
    lag_result rc = LAG_OK;
    for (;;) {
        int timeout = view_http_timeout_ms(h);
        /* streams waiting for a frame: wake at the frame rate; otherwise once a second
         * (DESCRIBE while no scene is known, keep-alives) */
        int tick = view_http_streams(h) ? (int)(1000 / ho.hz) : 1000;
        if (timeout < 0 || timeout > tick) timeout = tick;
        struct pollfd pf[3] = {{lcm_fd, POLLIN, 0}, {http_fd, POLLIN, 0}, {sig_fd, POLLIN, 0}};
        int n = poll(pf, 3, timeout);
        if (n < 0 && errno != EINTR) {
            perror("lagsim-view: poll");
            rc = LAG_ERR_RUNTIME;
            break;
        }
        if (n > 0 && (pf[2].revents & POLLIN)) break;
        view_bridge_poll(&vb);
        view_http_run(h);
    }
    view_http_stop(h);
    view_bridge_close(&vb);
    close(sig_fd);
    return rc;
}

int main(int argc, char **argv)
{
    return lag_result_exit(view_main(argc, argv));
}
