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

#include "lagsim_bus.h"
#include "lagsim_client.h"
#include "lagsim_locate.h"
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

enum { OPT_PORT = 256, OPT_URL, OPT_LISTEN, OPT_HZ, OPT_MAX_VIEWS, OPT_ALLOW_HOST,
       OPT_ALLOW_LAN };

/* The command line. */
typedef struct view_opts {
    const char *prefix, *url;   /* NULL: the only plant on the bus; LCM's default */
    view_http_opts ho;
    const char *allow_hosts[16];
    bool quiet, allow_lan;
} view_opts;

/* --allow-host NAME: a DNS name or an address literal, without a port. */
static bool add_allow_host(view_opts *o, const char *name)
{
    size_t n = strlen(name);
    bool ok = n > 0 && n < VIEW_HOST_LEN && o->ho.n_allow_hosts < 16;
    for (size_t i = 0; ok && i < n; i++) /* a DNS name or an address literal */
        ok = (name[i] >= 'a' && name[i] <= 'z') || (name[i] >= 'A' && name[i] <= 'Z') ||
             (name[i] >= '0' && name[i] <= '9') || strchr("-._[]:", name[i]);
    /* NAME:PORT (one colon: no IPv6 address has one) or [ADDR]:PORT: a port, which
     * the check compares separately with the port bound */
    const char *colon = strchr(name, ':'), *bracket = strchr(name, ']');
    if (ok && ((colon && !strchr(colon + 1, ':') && name[0] != '[') ||
               (bracket && bracket[1] == ':')))
        ok = false;
    if (!ok) {
        fprintf(stderr, "lagsim-view: --allow-host: expected a host name or address "
                "without a port (letters, digits, '-', '.', '_', an IPv6 address; at "
                "most 16 of them), "
                "got '%s'\n", name);
        return false;
    }
    o->allow_hosts[o->ho.n_allow_hosts++] = name;
    return true;
}

/* A number option's value, else a message; c is the option. */
static bool parse_number_opt(view_http_opts *ho, int c, const char *v)
{
    if (c == OPT_PORT && !parse_uint(v, 0, 65535, &ho->port)) {
        fprintf(stderr, "lagsim-view: --port: expected 0 to 65535, got '%s'\n", v);
        return false;
    }
    if (c == OPT_HZ && !parse_uint(v, 1, 240, &ho->hz)) {
        fprintf(stderr, "lagsim-view: --hz: expected 1 to 240, got '%s'\n", v);
        return false;
    }
    if (c == OPT_MAX_VIEWS && !parse_uint(v, 1, 256, &ho->max_streams)) {
        fprintf(stderr, "lagsim-view: --max-views: expected 1 to 256, got '%s'\n", v);
        return false;
    }
    return true;
}

/* Parses argv: GO_ON, else the result to exit with. */
/* What a step of main returns to go on (not a result: lag_result_exit never sees it). */
#define GO_ON 1000

static int parse_args(view_opts *o, int argc, char **argv)
{
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
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":p:qh", longopts, NULL)) != -1) {
        switch (c) {
        case 'p': o->prefix = optarg; break;
        case OPT_URL: o->url = optarg; break;
        case OPT_LISTEN: o->ho.listen = optarg; break;
        case OPT_PORT:
        case OPT_HZ:
        case OPT_MAX_VIEWS:
            if (!parse_number_opt(&o->ho, c, optarg)) return LAG_ERR_USAGE;
            break;
        case OPT_ALLOW_HOST:
            if (!add_allow_host(o, optarg)) return LAG_ERR_USAGE;
            break;
        case OPT_ALLOW_LAN: o->allow_lan = true; break;
        case 'q': o->quiet = true; break;
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
    o->ho.max_connections = o->ho.max_streams + 240;
    o->ho.allow_hosts = o->allow_hosts;
    return GO_ON;
}

/* Signals through a signalfd, blocked before LCM starts any thread: its fd, or -1. */
static int block_signals(void)
{
    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    sigaddset(&sigs, SIGHUP);
    sigprocmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);
    int sig_fd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    if (sig_fd < 0) perror("lagsim-view: signalfd");
    return sig_fd;
}

/* Without --prefix: the only plant on the bus; none yet: DIPC, watched until it comes.
 * GO_ON, else the result to exit with. */
static int pick_prefix(view_opts *o)
{
    static lag_client_plant found;
    char err[1200];
    int pr = lag_client_pick_plant(o->url, NULL, 2.0, &found, sizeof found, err, sizeof err);
    if (pr == LAG_CLIENT_ERR_AMBIGUOUS) {
        fprintf(stderr, "lagsim-view: %s\n", err);
        return LAG_ERR_AMBIGUOUS;
    }
    if (pr == LAG_CLIENT_OK) {
        o->prefix = found.prefix;
        if (!o->url && lag_locate_elsewhere(found.url)) o->url = found.url; /* a host's plant */
    } else {
        o->prefix = "DIPC";
        fprintf(stderr, "lagsim-view: %s; watching prefix %s\n", err, o->prefix);
    }
    return GO_ON;
}

/* --prefix without --url: a plant of a host (lagsimd --plants) runs on a URL of its own,
 * which the host's directory on LCM's default bus names (its `plant` event): the view
 * watches the plant there. A plant of that bus itself, or none heard: the default (and,
 * none heard, it says so: a busy host can miss the window). */
static void plant_url(view_opts *o)
{
    static char url[LAG_CLIENT_URL_LEN];
    char err[LAG_CLIENT_URL_LEN + 256];
    int where = o->url ? LAG_CLIENT_LOCATE_HERE
                       : lag_client_locate(o->prefix, LAG_CLIENT_LOCATE_WAIT_S, url, sizeof url,
                                           err, sizeof err);
    if (where == LAG_CLIENT_LOCATE_HOST) o->url = url;
    else if (where == LAG_CLIENT_LOCATE_NONE && !o->quiet)
        fprintf(stderr, "lagsim-view: %s\n", err);
}

/* The address on stdout; on stderr, who can reach it. */
static void print_address(const view_opts *o, view_http *h)
{
    const char *listen = o->ho.listen;
    bool v6 = strchr(listen, ':') != NULL;
    printf("lagsim-view: http://%s%s%s:%u/  (prefix %s%s%s)\n", v6 ? "[" : "", listen,
           v6 ? "]" : "", view_http_port(h), o->prefix, o->url ? " on " : "",
           o->url ? o->url : "");
    fflush(stdout);
    if (!is_loopback(listen))
        fprintf(stderr,
                "lagsim-view: WARNING: listening on %s, not on this machine only: anyone who "
                "reaches port %u sees the run and can pause, step and reset the simulation "
                "(there is no authentication)\n",
                listen, view_http_port(h));
    else if (!o->quiet)
        fprintf(stderr, "lagsim-view: this machine only (--listen ADDR to open it wider); "
                        "Ctrl-C stops\n");
}

/* Serves LCM and HTTP until a signal: LAG_OK, or LAG_ERR_RUNTIME when poll fails. */
static lag_result serve(view_bridge *vb, view_http *h, unsigned hz, int sig_fd)
{
    int lcm_fd = lcm_get_fileno(vb->lcm), http_fd = view_http_fd(h);
    for (;;) {
        int timeout = view_http_timeout_ms(h);
        /* streams waiting for a frame: wake at the frame rate; otherwise once a second
         * (DESCRIBE while no scene is known, keep-alives) */
        int tick = view_http_streams(h) ? (int)(1000 / hz) : 1000;
        if (timeout < 0 || timeout > tick) timeout = tick;
        struct pollfd pf[3] = {{lcm_fd, POLLIN, 0}, {http_fd, POLLIN, 0}, {sig_fd, POLLIN, 0}};
        int n = poll(pf, 3, timeout);
        if (n < 0 && errno != EINTR) {
            perror("lagsim-view: poll");
            return LAG_ERR_RUNTIME;
        }
        if (n > 0 && (pf[2].revents & POLLIN)) return LAG_OK;
        view_bridge_poll(vb);
        view_http_run(h);
    }
}

static lag_result view_main(int argc, char **argv)
{
    view_opts o = {.ho = {.listen = "127.0.0.1", .port = 8765, .hz = 60, .max_streams = 16,
                          .max_connections = 64}};
    int code = parse_args(&o, argc, argv);
    if (code != GO_ON) return code;
    int sig_fd = block_signals();
    if (sig_fd < 0) return LAG_ERR_RUNTIME;
    if (!o.prefix && (code = pick_prefix(&o)) != GO_ON) return code;
    else if (o.prefix && !o.url) plant_url(&o);

    char err[1200];
    static view_bridge vb; /* large (rings): static, one bridge per process */
    if (!view_bridge_open(&vb, o.url, o.prefix, o.allow_lan, err, sizeof err)) {
        fprintf(stderr, "lagsim-view: %s\n", err);
        return strstr(err, "--prefix") ? LAG_ERR_USAGE : LAG_ERR_RUNTIME;
    }
    view_http *h = view_http_start(&vb, &o.ho, err, sizeof err);
    if (!h) {
        fprintf(stderr, "lagsim-view: %s\n", err);
        view_bridge_close(&vb);
        return strstr(err, "--listen") ? LAG_ERR_USAGE : LAG_ERR_RUNTIME;
    }
    print_address(&o, h);
    lag_result rc = serve(&vb, h, o.ho.hz, sig_fd);
    view_http_stop(h);
    view_bridge_close(&vb);
    close(sig_fd);
    return rc;
}

int main(int argc, char **argv)
{
    return lag_result_exit(view_main(argc, argv));
}
