/*
 * lagsimctl: the control requests of a running lagsimd from a shell.
 *
 *   lagsimctl [--prefix P] [--url URL] [--timeout S] [--json] COMMAND [ARGS...]
 *   COMMAND: list, status, describe, pause, resume, step N, reset [--scene] [--wait],
 *            reset-to Q... QD... [--wait], set KEY=VALUE, kick JOINT IMPULSE [--duration S],
 *            watch
 *
 * Sends one control request on <P>_CONTROL and prints the daemon's answer as text lines
 * (an event, a status, a scene), or with `watch` prints what the daemon publishes until
 * it stops; `list` shows every plant on the bus. Without --prefix: the only plant on the
 * bus (lag_client_pick_plant; several: exit 2 naming them). Exit status: 0 the daemon did
 * it; 1 the daemon refused (its reason on stderr); 2 bad usage; 3 no answer within
 * --timeout (no daemon with that prefix?).
 *
 * Output, one message each:
 *   event <kind> t=<sim s> step=<ticks> [joint=<name>] value=<v> detail="<sentence>"
 *   status: a block for people, one field a line, aligned, with units; the counters
 *           that are 0 named on one line
 * With --json every message is one JSON object on a line, {"type": "status", <every
 * field of its .lcm type by name>}, for scripts. Key=value lines:
 * The fields come from the wire module's tables: a field added to a .lcm file shows up.
 *   scene model=... prefix=... mode=... ...      then one line per parameter and joint:
 *   param <name>=<value>
 *   joint <name> actuated=... initial_q=... ...  (every per-joint field of scene_t)
 *   state t=... step=... <joint>=<q> ... <joint>_dot=<qd> ... <joint>_effort=<effort> ...
 * Numbers are printed as the shortest decimal that reads back to the same double
 * (lagsim_num.h: 0.1, not 0.10000000000000001) unless --digits says otherwise.
 */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_client.h"
#include "lagsim_client_wire.h"
#include "lagsim_bus.h"
#include "lagsim_locate.h"
#include "lagsim_num.h"
#include "lagsim_wire.h"

/* What lagsimctl ends with: codes of the one space (lagsim/result.h); main() turns them
 * into exit statuses with lag_result_exit (0, 1, 2, 3 for these four). */
#define EXIT_OK LAG_OK
#define EXIT_REFUSED LAG_ERR_REFUSED
#define EXIT_USAGE LAG_ERR_USAGE
#define EXIT_NOANSWER LAG_ERR_NOANSWER

static volatile sig_atomic_t g_signal = 0;
static void on_signal(int sig) { g_signal = sig; }

static int g_digits = 0; /* 0: the shortest that reads back */
static bool g_json = false;
static bool g_digits_set = false;
static const char *g_prefix = "";  /* the plant's, for the status's first line */
static bool g_watch_lines = false; /* watch: a status is one key=value line among states */

static void usage(FILE *f)
{
    fprintf(f,
            "usage: lagsimctl [options] COMMAND [ARGS...]\n"
            "Sends a control request to a running lagsimd and prints its answer.\n"
            "commands:\n"
            "  list                 every plant on the bus: prefix, model, mode, run state,\n"
            "                       sim time, host, URL (listens 1 s, then waits for each\n"
            "                       plant heard to answer, up to --timeout s, default 5;\n"
            "                       ? for what a plant has not said by then)\n"
            "  status               the daemon's status, one field a line with units\n"
            "  describe             the scene description (model, parameters, joints, timing)\n"
            "  pause | resume       stop / go on advancing sim time\n"
            "  step N               while paused: advance N control periods, then pause\n"
            "  reset [--scene] [--wait]\n"
            "                       back to the scene's initial state at sim time 0, keeping\n"
            "                       the changes made by set (it says which) and the run state\n"
            "                       (running or paused); --scene: back to the scene file's\n"
            "                       values too; --wait: then wait at t = 0 for the first\n"
            "                       command, as at the daemon's start (run state waiting: the\n"
            "                       next controller's first command or resume starts the run)\n"
            "  reset-to Q... QD... [--wait]\n"
            "                       back to this state: all positions, then all velocities\n"
            "  set KEY=VALUE        change a parameter, an effect's setting or the reference\n"
            "                       while running, e.g. set parameters.m2=1.5, set\n"
            "                       reference.q1.amplitude=0.2 (validated as the scene file)\n"
            "  kick JOINT IMPULSE [--duration S]\n"
            "                       a disturbance now: IMPULSE (N s, or N m s on an angle)\n"
            "                       on JOINT at the current sim time, or spread as a force\n"
            "                       over the whole ticks within S s (S >= the scene's dt;\n"
            "                       the impulse given is IMPULSE); refused as the scene\n"
            "                       file would refuse the disturbance, and in a fault;\n"
            "                       kicks add to each other and to the scene's disturbances\n"
            "  watch                print states, events and statuses until the daemon stops\n"
            "options:\n"
            "  -p, --prefix P       the daemon's channel prefix (default: the only plant on\n"
            "                       the bus; several: they are named, choose one)\n"
            "  -j, --json           one JSON object a message (for scripts)\n"
            "  -u, --url URL        LCM URL (default: LCM's default, honours LCM_DEFAULT_URL)\n"
            "  -t, --timeout S      wall s to wait for the answer (default 2)\n"
            "  -d, --digits N       significant digits of numbers (default: exact, the\n"
            "                       shortest decimal that reads back; the status for\n"
            "                       people: 6)\n"
            "  -h, --help           this text\n"
            "  -V, --version        print the version\n"
            "exit status: 0 done, 1 the daemon refused (its reason on stderr), 2 bad usage\n"
            "(several plants and no --prefix too), 3 no answer within the timeout (list: no\n"
            "plant heard)\n");
}

/* ---------------------------------------------------------------- printing */
static void put_num(double x)
{
    char b[LAG_NUM_LEN];
    if (g_digits) printf("%.*g", g_digits, x);
    else printf("%s", lag_num(x, b));
}

/* A string as a token: bare if it has no space, quote or '=', else in double quotes with
 * '"' and '\' escaped. */
static void put_str(const char *s)
{
    if (*s && !strpbrk(s, " \t\"=\\")) {
        fputs(s, stdout);
        return;
    }
    putchar('"');
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') putchar('\\');
        putchar(*s);
    }
    putchar('"');
}

/* Every scalar field of a message as " name=value", in .lcm order (arrays skipped). */
static void put_fields(lag_wire_type t, const void *m, const char *const *skip)
{
    int n;
    const lag_wire_field *f = lag_wire_fields(t, &n);
    for (int i = 0; i < n; i++) {
        if (f[i].count_field >= 0) continue;
        bool skipped = false;
        for (const char *const *s = skip; s && *s; s++)
            if (!strcmp(*s, f[i].name)) skipped = true;
        if (skipped) continue;
        const char *p = (const char *)m + f[i].offset;
        printf(" %s=", f[i].name);
        switch (f[i].kind) {
        case LAG_WIRE_INT8: printf("%d", *(const int8_t *)p); break;
        case LAG_WIRE_INT16: printf("%d", *(const int16_t *)p); break;
        case LAG_WIRE_INT64: printf("%lld", (long long)*(const int64_t *)p); break;
        case LAG_WIRE_DOUBLE: put_num(*(const double *)p); break;
        case LAG_WIRE_BOOLEAN: printf("%s", *(const bool *)p ? "true" : "false"); break;
        case LAG_WIRE_STRING: put_str(p); break;
        }
    }
}

/* A string as JSON. */
static void put_json_str(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') printf("\\%c", ch);
        else if (ch < 0x20) printf("\\u%04x", ch);
        else putchar(ch);
    }
    putchar('"');
}

/* One value of a field as JSON (numbers exact, the shortest that reads back; the decoder
 * keeps only finite ones). */
static void put_json_value(const lag_wire_field *f, const char *p)
{
    char num[LAG_NUM_LEN];
    switch (f->kind) {
    case LAG_WIRE_INT8: printf("%d", *(const int8_t *)p); break;
    case LAG_WIRE_INT16: printf("%d", *(const int16_t *)p); break;
    case LAG_WIRE_INT64: printf("%lld", (long long)*(const int64_t *)p); break;
    case LAG_WIRE_DOUBLE: printf("%s", lag_num(*(const double *)p, num)); break;
    case LAG_WIRE_BOOLEAN: printf("%s", *(const bool *)p ? "true" : "false"); break;
    case LAG_WIRE_STRING: put_json_str(p); break;
    }
}

/* A message as one JSON object: {"type": <type>, every field of the .lcm type by name},
 * arrays as JSON arrays of their count's length. */
static void print_json(const char *type, lag_wire_type t, const void *m)
{
    int n;
    const lag_wire_field *f = lag_wire_fields(t, &n);
    printf("{\"type\": ");
    put_json_str(type);
    for (int i = 0; i < n; i++) {
        printf(", ");
        put_json_str(f[i].name);
        printf(": ");
        const char *p = (const char *)m + f[i].offset;
        if (f[i].count_field < 0) {
            put_json_value(&f[i], p);
            continue;
        }
        const lag_wire_field *cf = &f[f[i].count_field];
        const char *cp = (const char *)m + cf->offset;
        long long cnt = cf->kind == LAG_WIRE_INT16 ? *(const int16_t *)cp
                        : cf->kind == LAG_WIRE_INT8 ? *(const int8_t *)cp
                                                    : *(const int64_t *)cp;
        if (cnt > f[i].capacity) cnt = f[i].capacity;
        printf("[");
        for (long long k = 0; k < cnt; k++) {
            if (k) printf(", ");
            put_json_value(&f[i], p + (size_t)k * f[i].size);
        }
        printf("]");
    }
    printf("}\n");
    fflush(stdout);
}

/* The unit of a status field, for people ("" for counts and words). One table: a field
 * added to status_t shows up without a unit until it gets one here. */
static const char *status_unit(const char *name)
{
    static const struct { const char *name, *unit; } units[] = {
        {"sim_time", "s"}, {"wall_time", "s"}, {"step", "ticks"}, {"rtf", "x real time"},
        {"step_time_max_us", "us"}, {"step_time_mean_us", "us"}, {"energy", "J"},
        {"overruns", "periods"}, {"states_published", "states"}, {"waiting_s", "wall s"},
        {"error_estimate", "m or rad per period"}, {"error_budget", "m or rad per period"},
    };
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (!strcmp(units[i].name, name)) return units[i].unit;
    return "";
}

/* The status for people: one field a line, names aligned, numbers with 6 significant
 * digits (--digits N: N) and their units; the counters that are 0 on one line. */
static void print_status_human(const lag_wire_status *st)
{
    int n, width = 0;
    const lag_wire_field *f = lag_wire_fields(LAG_WIRE_STATUS, &n);
    for (int i = 0; i < n; i++)
        if ((int)strlen(f[i].name) > width) width = (int)strlen(f[i].name);
    int digits = g_digits_set ? g_digits : 6;
    char zeros[1024] = "";
    size_t zl = 0;
    printf("status of %s\n", g_prefix);
    for (int i = 0; i < n; i++) {
        if (f[i].count_field >= 0 || !strcmp(f[i].name, "utime")) continue;
        const char *p = (const char *)st + f[i].offset;
        if (f[i].kind == LAG_WIRE_INT64 && strcmp(f[i].name, "step") &&
            *(const int64_t *)p == 0) {
            int w = snprintf(zeros + zl, sizeof zeros - zl, "%s%s", zl ? ", " : "", f[i].name);
            if (w > 0 && (size_t)w < sizeof zeros - zl) zl += (size_t)w;
            continue;
        }
        if (f[i].kind == LAG_WIRE_STRING && !*p) continue; /* an empty word: nothing to say */
        printf("  %-*s  ", width, f[i].name);
        switch (f[i].kind) {
        case LAG_WIRE_DOUBLE: printf("%.*g", digits, *(const double *)p); break;
        case LAG_WIRE_INT64: printf("%lld", (long long)*(const int64_t *)p); break;
        case LAG_WIRE_INT16: printf("%d", *(const int16_t *)p); break;
        case LAG_WIRE_INT8: printf("%d", *(const int8_t *)p); break;
        case LAG_WIRE_BOOLEAN: printf("%s", *(const bool *)p ? "yes" : "no"); break;
        case LAG_WIRE_STRING: printf("%s", p); break;
        }
        const char *u = status_unit(f[i].name);
        printf("%s%s\n", *u ? " " : "", u);
    }
    if (zl) printf("  %-*s  %s\n", width, "zero", zeros);
    fflush(stdout);
}

static void print_event(const lag_client_event *ev)
{
    if (g_json) {
        lag_wire_event w;
        lag_wire_of_event(ev, &w);
        print_json("event", LAG_WIRE_EVENT, &w);
        return;
    }
    printf("event %s t=", ev->kind);
    put_num(ev->sim_time);
    printf(" step=%lld", (long long)ev->step);
    if (ev->joint[0]) printf(" joint=%s", ev->joint);
    printf(" value=");
    put_num(ev->value);
    printf(" detail=");
    put_str(ev->detail);
    printf("\n");
    fflush(stdout);
}

static void print_status(const lag_client_status *status)
{
    static const char *const skip[] = {"utime", "sim_time", "step", NULL};
    const lag_wire_status *st = lag_wire_of_status(status); /* every field, from its table */
    if (g_json) {
        print_json("status", LAG_WIRE_STATUS, st);
        return;
    }
    if (!g_watch_lines) {
        print_status_human(st);
        return;
    }
    printf("status t=");
    put_num(st->sim_time);
    printf(" step=%lld", (long long)st->step);
    put_fields(LAG_WIRE_STATUS, st, skip);
    printf("\n");
    fflush(stdout);
}

static void print_state(const lag_client_state *st)
{
    if (g_json) {
        lag_wire_joint_state w;
        lag_wire_of_state(st, &w);
        print_json("state", LAG_WIRE_JOINT_STATE, &w);
        return;
    }
    printf("state t=");
    put_num(st->sim_time);
    printf(" step=%lld", (long long)st->step);
    for (int i = 0; i < st->num_joints; i++) {
        printf(" %s=", st->name[i]);
        put_num(st->position[i]);
    }
    for (int i = 0; i < st->num_joints; i++) {
        printf(" %s_dot=", st->name[i]);
        put_num(st->velocity[i]);
    }
    for (int i = 0; i < st->num_joints; i++) {
        printf(" %s_effort=", st->name[i]);
        put_num(st->effort[i]);
    }
    printf("\n");
    fflush(stdout);
}

/* One element of an array field as a value token. */
static void put_elem(const lag_wire_field *f, const void *m, int i)
{
    const char *p = (const char *)m + f->offset + (size_t)i * f->size;
    switch (f->kind) {
    case LAG_WIRE_DOUBLE: put_num(*(const double *)p); break;
    case LAG_WIRE_BOOLEAN: printf("%s", *(const bool *)p ? "true" : "false"); break;
    case LAG_WIRE_STRING: put_str(p); break;
    case LAG_WIRE_INT8: printf("%d", *(const int8_t *)p); break;
    case LAG_WIRE_INT16: printf("%d", *(const int16_t *)p); break;
    case LAG_WIRE_INT64: printf("%lld", (long long)*(const int64_t *)p); break;
    }
}

/* The scene: a line of its scalar fields, then one line per parameter
 * ("param <name>=<value>") and one per joint ("joint <name> <field>=<value>..." for every
 * array counted by num_joints), so that fields added to scene_t show up by themselves. */
static void print_scene(const lag_client_scene *scene)
{
    static const char *const skip[] = {"utime", NULL};
    const lag_wire_scene *sc = lag_wire_of_scene(scene); /* every field, from its table */
    if (g_json) {
        print_json("scene", LAG_WIRE_SCENE, sc);
        return;
    }
    int n, i_params = -1, i_joints = -1;
    const lag_wire_field *f = lag_wire_fields(LAG_WIRE_SCENE, &n);
    for (int i = 0; i < n; i++) {
        if (!strcmp(f[i].name, "num_params")) i_params = i;
        if (!strcmp(f[i].name, "num_joints")) i_joints = i;
    }
    printf("scene");
    put_fields(LAG_WIRE_SCENE, sc, skip);
    printf("\n");
    for (int k = 0; k < sc->num_params; k++) {
        printf("param %s=", sc->param_name[k]);
        put_num(sc->param_value[k]);
        for (int i = 0; i < n; i++)
            if (f[i].count_field == i_params && strcmp(f[i].name, "param_name") &&
                strcmp(f[i].name, "param_value")) {
                printf(" %s=", f[i].name);
                put_elem(&f[i], sc, k);
            }
        printf("\n");
    }
    for (int k = 0; k < sc->num_joints; k++) {
        printf("joint %s", sc->joint_name[k]);
        for (int i = 0; i < n; i++)
            if (f[i].count_field == i_joints && strcmp(f[i].name, "joint_name")) {
                printf(" %s=", f[i].name);
                put_elem(&f[i], sc, k);
            }
        printf("\n");
    }
    fflush(stdout);
}

/* ---------------------------------------------------------------- answers */
typedef struct answer {
    const char *want;          /* event kind that says "done" (NULL: none) */
    const char *want2;         /* a second event expected after it (step: step_done) */
    bool got_event, got_event2, refused, want_status, got_status, want_scene, got_scene;
    lag_client_event ev;
    bool watch;
    double heard;              /* monotonic s of the last message */
    bool stopped;              /* the daemon's stop event */
} answer;

static void on_event(const lag_client_event *ev, void *user)
{
    answer *a = user;
    a->heard = lag_client_now();
    if (a->watch) {
        print_event(ev);
        if (!strcmp(ev->kind, "stop")) a->stopped = true;
        return;
    }
    if (!strcmp(ev->kind, "restore")) { /* reset --scene: what it undid, before the reset */
        print_event(ev);
        return;
    }
    if (!a->got_event && a->want &&
        (!strcmp(ev->kind, a->want) || !strcmp(ev->kind, "control_rejected"))) {
        a->got_event = true;
        a->refused = !strcmp(ev->kind, "control_rejected");
        a->ev = *ev;
        print_event(ev);
    } else if (a->got_event && a->want2 && !a->got_event2 &&
               (!strcmp(ev->kind, a->want2) || !strcmp(ev->kind, "stop") ||
                !strcmp(ev->kind, "numeric_fault"))) {
        a->got_event2 = true;
        print_event(ev);
    }
}

static void on_status(const lag_client_status *st, void *user)
{
    answer *a = user;
    a->heard = lag_client_now();
    if (a->watch) {
        print_status(st);
        return;
    }
    /* the status that follows the event (or, for `status`, any status) */
    if (a->want_status && !a->got_status && (a->got_event || !a->want) &&
        (!a->want2 || a->got_event2)) {
        a->got_status = true;
        print_status(st);
    }
}

static void on_state(const lag_client_state *st, void *user)
{
    answer *a = user;
    a->heard = lag_client_now();
    if (a->watch) print_state(st);
}

static void on_scene(const lag_client_scene *sc, void *user)
{
    answer *a = user;
    a->heard = lag_client_now();
    if (a->watch) print_scene(sc);
    else if (a->want_scene && a->got_event && !a->refused && !a->got_scene) {
        a->got_scene = true; /* set: the scene with the change */
        print_scene(sc);
    }
}

/* Handles messages until done(), or until `timeout` wall s have passed (since the
 * start, or with `silence`, since the last message from the daemon). */
static lag_result wait_for(lag_client *c, answer *a, double timeout, bool silence,
                           bool (*done)(const answer *))
{
    double t0 = lag_client_now();
    while (!done(a) && !g_signal) {
        if (lag_client_now() - (silence && a->heard > t0 ? a->heard : t0) >= timeout) {
            /* what came while this process was stalled past the time (a busy machine) */
            int rc = LAG_CLIENT_OK;
            for (int i = 0; i < 1000 && !done(a) && rc == LAG_CLIENT_OK; i++)
                rc = lag_client_handle(c, 0);
            if (rc < 0) return rc;
            return done(a) ? LAG_CLIENT_OK : LAG_CLIENT_TIMEOUT;
        }
        int rc = lag_client_handle(c, 50);
        if (rc < 0) return rc;
    }
    return LAG_CLIENT_OK;
}

static bool event_and_status(const answer *a)
{
    return a->got_event && (a->refused || a->got_status);
}
static bool status_only(const answer *a) { return a->got_status; }
static bool event_and_scene(const answer *a) { return a->got_event && (a->refused || a->got_scene); }
static bool event_only(const answer *a) { return a->got_event; }
static bool step_done(const answer *a) { return a->refused || (a->got_event2 && a->got_status); }

/* ---------------------------------------------------------------- list */
/* list: plants are heard for LIST_HEAR_S after the first (a host's directory names each every 0.5 s);
 * then the list waits for every plant heard to answer with its scene and status, up to
 * --timeout (LIST_TIMEOUT_S by default); a plant that has not answered by then shows `?`. */
#define LIST_HEAR_S 1.0
#define LIST_TIMEOUT_S 5.0

/* Every plant on the bus, a table for people (or a JSON array): exit 0, or 3 if none. */
static lag_result list_plants(const char *url, double wait_s)
{
    char num[LAG_NUM_LEN];
    static lag_client_plant p[LAG_CLIENT_MAX_PLANTS];
    int n = 0;
    char err[256];
    int rc = lag_client_discover(url, wait_s, wait_s < LIST_HEAR_S ? -1.0 : LIST_HEAR_S, p,
                                 LAG_CLIENT_MAX_PLANTS, sizeof p[0], &n, err, sizeof err);
    if (rc != LAG_CLIENT_OK) {
        fprintf(stderr, "lagsimctl: %s\n", err);
        return EXIT_NOANSWER;
    }
    if (err[0]) fprintf(stderr, "lagsimctl: %s\n", err);
    if (g_json) {
        printf("[");
        for (int i = 0; i < n; i++) {
            const char *k[] = {"prefix", "model", "mode", "run_state", "host", "url"};
            const char *v[] = {p[i].prefix, p[i].model, p[i].mode, p[i].run_state, p[i].host,
                               p[i].url};
            printf("%s{", i ? ", " : "");
            for (int j = 0; j < 6; j++) {
                printf("%s\"%s\": ", j ? ", " : "", k[j]);
                put_json_str(v[j]);
            }
            printf(", \"sim_time\": %s}", lag_num(p[i].sim_time, num));
        }
        printf("]\n");
    } else if (n > 0) {
        /* columns as wide as their widest entry */
        int w[5] = {6, 5, 4, 9, 4};
        for (int i = 0; i < n; i++) {
            const char *v[] = {p[i].prefix, p[i].model, p[i].mode, p[i].run_state, p[i].host};
            for (int j = 0; j < 5; j++)
                if ((int)strlen(v[j]) > w[j]) w[j] = (int)strlen(v[j]);
        }
        printf("%-*s  %-*s  %-*s  %-*s  %12s  %-*s  %s\n", w[0], "PREFIX", w[1], "MODEL", w[2],
               "MODE", w[3], "RUN STATE", "SIM TIME", w[4], "HOST", "URL");
        for (int i = 0; i < n; i++)
            printf("%-*s  %-*s  %-*s  %-*s  %10.3f s  %-*s  %s\n", w[0], p[i].prefix, w[1],
                   p[i].model[0] ? p[i].model : "?", w[2], p[i].mode[0] ? p[i].mode : "?", w[3],
                   p[i].run_state[0] ? p[i].run_state : "?", p[i].sim_time, w[4],
                   p[i].host[0] ? p[i].host : "?", p[i].url);
    }
    fflush(stdout);
    if (n == 0) {
        lag_bus b;
        char berr[8];
        fprintf(stderr, "lagsimctl: no plant heard on %s within %g s\n",
                lag_bus_init(&b, url, "X", berr, sizeof berr) == 0 ? b.state_url : "?", wait_s);
        return EXIT_NOANSWER;
    }
    return EXIT_OK;
}

/* ---------------------------------------------------------------- main */
static int parse_count(const char *s, long long *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno || v < 1) return -1;
    *out = v;
    return 0;
}

static int parse_doubles(char **argv, int n, double *out)
{
    for (int i = 0; i < n; i++) {
        char *end;
        out[i] = strtod(argv[i], &end);
        if (end == argv[i] || *end || !isfinite(out[i])) return -1;
    }
    return 0;
}

/* What a step of main returns to go on (not a result: lag_result_exit never sees it). */
#define GO_ON 1000

/* The options before the command. */
typedef struct options {
    const char *prefix, *url;   /* NULL: the only plant on the bus; LCM's default */
    double timeout;             /* wall s */
    bool timeout_set;
} options;

/* Parses the options (g_json and g_digits too): GO_ON, else the result to exit with. */
static int parse_options(options *o, int argc, char **argv)
{
    static const struct option longopts[] = {
        {"prefix", required_argument, NULL, 'p'}, {"url", required_argument, NULL, 'u'},
        {"timeout", required_argument, NULL, 't'}, {"digits", required_argument, NULL, 'd'},
        {"json", no_argument, NULL, 'j'}, {"help", no_argument, NULL, 'h'},
        {"version", no_argument, NULL, 'V'}, {NULL, 0, NULL, 0}};
    int opt;
    /* "+": options end at the command, so reset-to's negative numbers stay arguments */
    while ((opt = getopt_long(argc, argv, "+p:u:t:d:jhV", longopts, NULL)) != -1) {
        char *end;
        switch (opt) {
        case 'p': o->prefix = optarg; break;
        case 'j': g_json = true; break;
        case 'u': o->url = optarg; break;
        case 't':
            o->timeout = strtod(optarg, &end);
            if (end == optarg || *end || !(o->timeout > 0) || !isfinite(o->timeout)) {
                fprintf(stderr, "lagsimctl: --timeout wants a number of seconds > 0, not '%s'\n",
                        optarg);
                return EXIT_USAGE;
            }
            o->timeout_set = true;
            break;
        case 'd': {
            long d = strtol(optarg, &end, 10);
            if (end == optarg || *end || d < 1 || d > 17) {
                fprintf(stderr, "lagsimctl: --digits wants 1 to 17, not '%s'\n", optarg);
                return EXIT_USAGE;
            }
            g_digits = (int)d;
            g_digits_set = true;
            break;
        }
        case 'h': usage(stdout); return EXIT_OK;
        case 'V': printf("lagsimctl %s\n", LAGSIM_VERSION); return EXIT_OK;
        default: usage(stderr); return EXIT_USAGE;
        }
    }
    return GO_ON;
}

/* The command and its arguments, checked before the bus is touched. */
typedef struct request {
    const char *cmd;
    char **args;
    int nargs;
    int want_args;              /* how many arguments the command takes */
    long long count;            /* step */
    double q[LAG_CLIENT_MAX_JOINTS], qd[LAG_CLIENT_MAX_JOINTS];
    int nq;                     /* reset-to */
    const char *kick_joint;
    double kick_impulse, kick_duration;
    int reset_flags;            /* reset --scene --wait, reset-to --wait: LAG_CLIENT_RESET_* */
} request;

/* reset's and reset-to's options, anywhere among the arguments: taken out of them into
 * reset_flags (--scene only where scene_ok). */
static void take_reset_flags(request *r, bool scene_ok)
{
    int k = 0;
    for (int i = 0; i < r->nargs; i++) {
        if (!strcmp(r->args[i], "--wait")) r->reset_flags |= LAG_CLIENT_RESET_WAIT;
        else if (scene_ok && !strcmp(r->args[i], "--scene"))
            r->reset_flags |= LAG_CLIENT_RESET_SCENE;
        else r->args[k++] = r->args[i];
    }
    r->nargs = k;
}

static int check_step(request *r)
{
    r->want_args = 1;
    if (r->nargs == 1 && parse_count(r->args[0], &r->count)) {
        fprintf(stderr, "lagsimctl: step wants a whole number of periods >= 1, not '%s'\n",
                r->args[0]);
        return EXIT_USAGE;
    }
    return GO_ON;
}

static int check_reset_to(request *r)
{
    take_reset_flags(r, false);
    if (r->nargs < 2 || r->nargs % 2 || r->nargs / 2 > LAG_CLIENT_MAX_JOINTS) {
        fprintf(stderr, "lagsimctl: reset-to wants every position, then every velocity "
                        "(2, 4 or 6 numbers for 1 to 3 joints), got %d\n", r->nargs);
        return EXIT_USAGE;
    }
    r->nq = r->nargs / 2;
    if (parse_doubles(r->args, r->nq, r->q) || parse_doubles(r->args + r->nq, r->nq, r->qd)) {
        fprintf(stderr, "lagsimctl: reset-to wants finite numbers\n");
        return EXIT_USAGE;
    }
    r->want_args = r->nargs;
    return GO_ON;
}

static int check_set(request *r)
{
    r->want_args = 1;
    const char *eq = r->nargs == 1 ? strchr(r->args[0], '=') : NULL;
    if (r->nargs == 1 && (!eq || eq == r->args[0] || !eq[1])) {
        fprintf(stderr, "lagsimctl: set wants KEY=VALUE, e.g. parameters.m2=1.5, not '%s'\n",
                r->args[0]);
        return EXIT_USAGE;
    }
    return GO_ON;
}

/* JOINT IMPULSE [--duration S] */
static int check_kick(request *r)
{
    char **args = r->args;
    r->want_args = r->nargs == 4 ? 4 : 2;
    if (r->nargs != 2 && r->nargs != 4) return GO_ON;
    r->kick_joint = args[0];
    if (parse_doubles(args + 1, 1, &r->kick_impulse)) {
        fprintf(stderr, "lagsimctl: kick wants a finite impulse (N s, or N m s on an "
                        "angle), not '%s'\n", args[1]);
        return EXIT_USAGE;
    }
    if (r->nargs == 4 && (strcmp(args[2], "--duration") ||
                          parse_doubles(args + 3, 1, &r->kick_duration) ||
                          !(r->kick_duration > 0))) {
        fprintf(stderr, "lagsimctl: kick JOINT IMPULSE [--duration S]: S is a time > 0 "
                        "(s), not '%s %s'\n", args[2], args[3]);
        return EXIT_USAGE;
    }
    return GO_ON;
}

static int check_reset(request *r)
{
    take_reset_flags(r, true);
    r->want_args = 0;
    if (r->nargs > 0) {
        fprintf(stderr, "lagsimctl: reset takes --scene, --wait or nothing, not '%s'\n",
                r->args[0]);
        return EXIT_USAGE;
    }
    return GO_ON;
}

/* The command's arguments: GO_ON, else the result to exit with (a message said why). */
static int check_request(request *r)
{
    int code = GO_ON;
    const char *cmd = r->cmd;
    if (!strcmp(cmd, "step")) code = check_step(r);
    else if (!strcmp(cmd, "reset-to")) code = check_reset_to(r);
    else if (!strcmp(cmd, "set")) code = check_set(r);
    else if (!strcmp(cmd, "kick")) code = check_kick(r);
    else if (!strcmp(cmd, "reset")) code = check_reset(r);
    else if (strcmp(cmd, "status") && strcmp(cmd, "describe") && strcmp(cmd, "pause") &&
             strcmp(cmd, "resume") && strcmp(cmd, "watch") && strcmp(cmd, "list")) {
        fprintf(stderr, "lagsimctl: unknown command '%s'\n", cmd);
        usage(stderr);
        return EXIT_USAGE;
    }
    if (code != GO_ON) return code;
    if (r->nargs != r->want_args) {
        fprintf(stderr, "lagsimctl: %s takes %d argument(s), got %d", cmd, r->want_args,
                r->nargs);
        for (int i = 0; i < r->nargs; i++)
            if (r->args[i][0] == '-') { /* an option after the command: say where it goes */
                const char *a = r->args[i];
                bool valued = !strchr(a, '=') && i + 1 < r->nargs &&
                              strcmp(a, "--json") && strcmp(a, "-j") && strcmp(a, "--help") &&
                              strcmp(a, "-h") && strcmp(a, "--version") && strcmp(a, "-V");
                fprintf(stderr, " (options go before the command: lagsimctl %s%s%s %s)", a,
                        valued ? " " : "", valued ? r->args[i + 1] : "", cmd);
                break;
            }
        fputc('\n', stderr);
        return EXIT_USAGE;
    }
    return GO_ON;
}

/* The client on the plant --prefix names, else on the only plant on the bus; NULL with
 * the exit status in *code. */
static lag_client *connect_plant(options *o, lag_client_plant *chosen, int *code)
{
    char err[1200];
    static char located[LAG_CLIENT_URL_LEN];
    int where = o->prefix && !o->url
                    ? lag_client_locate(o->prefix, LAG_CLIENT_LOCATE_WAIT_S, located,
                                        sizeof located, err, sizeof err)
                    : LAG_CLIENT_LOCATE_HERE;
    if (where == LAG_CLIENT_LOCATE_HOST)
        o->url = located; /* a host's plant: where its directory says it runs */
    else if (where == LAG_CLIENT_LOCATE_NONE)
        fprintf(stderr, "lagsimctl: %s\n", err);
    if (!o->prefix) {
        /* the only plant on the bus */
        int rc = lag_client_pick_plant(o->url, NULL, o->timeout, chosen, sizeof *chosen, err,
                                       sizeof err);
        if (rc != LAG_CLIENT_OK) {
            fprintf(stderr, "lagsimctl: %s\n", err);
            *code = rc == LAG_CLIENT_ERR_AMBIGUOUS ? EXIT_USAGE : EXIT_NOANSWER;
            return NULL;
        }
        o->prefix = chosen->prefix;
        if (!o->url && lag_locate_elsewhere(chosen->url)) o->url = chosen->url;
    }
    g_prefix = o->prefix;
    lag_client *c = lag_client_create(o->url, o->prefix, err, sizeof err);
    if (!c) {
        fprintf(stderr, "lagsimctl: %s\n", err);
        *code = EXIT_NOANSWER;
        return NULL;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGPIPE, &sa, NULL);
    return c;
}

/* A client result that is a usage error (set's key, kick's joint): exit 2, not 3. */
#define RC_USAGE 100

/* set KEY=VALUE: the "set" event, then the new scene. */
static int send_set(lag_client *c, answer *a, const request *r, double timeout)
{
    char key[LAG_WIRE_NAME_LEN];
    size_t klen = (size_t)(strchr(r->args[0], '=') - r->args[0]);
    if (klen >= sizeof key) {
        fprintf(stderr, "lagsimctl: set: the key is longer than %zu bytes\n", sizeof key - 1);
        return RC_USAGE;
    }
    memcpy(key, r->args[0], klen);
    key[klen] = '\0';
    a->want = "set";
    a->want_scene = true;
    int rc = lag_client_set(c, key, r->args[0] + klen + 1);
    if (rc == LAG_CLIENT_ERR_ARG) {
        fprintf(stderr, "lagsimctl: %s\n", lag_client_errmsg(c));
        return RC_USAGE;
    }
    if (rc == LAG_CLIENT_OK) rc = wait_for(c, a, timeout, false, event_and_scene);
    return rc;
}

static int send_kick(lag_client *c, answer *a, const request *r, double timeout)
{
    a->want = "kick";
    a->want_status = true;
    int rc = lag_client_kick(c, r->kick_joint, r->kick_impulse, r->kick_duration);
    if (rc == LAG_CLIENT_ERR_ARG) {
        fprintf(stderr, "lagsimctl: %s\n", lag_client_errmsg(c));
        return RC_USAGE;
    }
    if (rc == LAG_CLIENT_OK) rc = wait_for(c, a, timeout, false, event_and_status);
    return rc;
}

/* Until the daemon's stop event or a signal; a daemon that is not there yet is waited for. */
static int watch(lag_client *c, answer *a)
{
    int rc = LAG_CLIENT_OK;
    a->watch = true;
    g_watch_lines = true;
    while (!a->stopped && !g_signal) {
        rc = lag_client_handle(c, 100);
        if (rc < 0) break;
        rc = LAG_CLIENT_OK;
    }
    return rc;
}

/* pause, resume, reset, reset-to, step: the request's event and a status. */
static int send_run_control(lag_client *c, answer *a, const request *r, double timeout)
{
    int rc;
    const char *cmd = r->cmd;
    a->want_status = true;
    if (!strcmp(cmd, "pause")) {
        a->want = "pause";
        rc = lag_client_pause(c);
    } else if (!strcmp(cmd, "resume")) {
        a->want = "resume";
        rc = lag_client_resume(c);
    } else if (!strcmp(cmd, "reset")) {
        a->want = "reset";
        rc = lag_client_reset_with(c, r->reset_flags, 0, NULL, NULL);
    } else if (!strcmp(cmd, "reset-to")) {
        a->want = "reset";
        rc = lag_client_reset_with(c, r->reset_flags, r->nq, r->q, r->qd);
    } else { /* step */
        a->want = "step";
        a->want2 = "step_done";
        rc = lag_client_step(c, r->count);
    }
    if (rc == LAG_CLIENT_OK && !a->want2) {
        rc = wait_for(c, a, timeout, false, event_and_status);
    } else if (rc == LAG_CLIENT_OK) {
        /* step: the "step" event within the timeout, then step_done (or the end of the
         * run) however long the steps take, as long as the daemon is heard from */
        rc = wait_for(c, a, timeout, false, event_only);
        if (rc == LAG_CLIENT_OK && !a->refused) rc = wait_for(c, a, timeout, true, step_done);
    }
    return rc;
}

/* Sends the request and waits for its answer: a client result, or RC_USAGE. */
static int send_request(lag_client *c, answer *a, const request *r, double timeout)
{
    int rc = LAG_CLIENT_OK;
    if (!strcmp(r->cmd, "describe")) {
        lag_client_scene *sc = lag_client_scene_new();
        rc = sc ? lag_client_wait_scene(c, timeout, sc) : LAG_CLIENT_ERR_NOMEM;
        if (rc == LAG_CLIENT_OK) print_scene(sc);
        lag_client_scene_free(sc);
    } else if (!strcmp(r->cmd, "status")) {
        a->want_status = true;
        rc = lag_client_request_status(c);
        if (rc == LAG_CLIENT_OK) rc = wait_for(c, a, timeout, false, status_only);
    } else if (!strcmp(r->cmd, "set")) {
        rc = send_set(c, a, r, timeout);
    } else if (!strcmp(r->cmd, "kick")) {
        rc = send_kick(c, a, r, timeout);
    } else if (!strcmp(r->cmd, "watch")) {
        rc = watch(c, a);
    } else {
        rc = send_run_control(c, a, r, timeout);
    }
    return rc;
}

static lag_result lagsimctl_main(int argc, char **argv)
{
    options o = {.timeout = 2.0};
    int code = parse_options(&o, argc, argv);
    if (code != GO_ON) return code;
    if (optind >= argc) {
        fprintf(stderr, "lagsimctl: which command? (list, status, describe, pause, resume, "
                        "step N, reset [--scene] [--wait], reset-to Q... QD... [--wait], set KEY=VALUE, kick "
                        "JOINT IMPULSE [--duration S], watch)\n");
        usage(stderr);
        return EXIT_USAGE;
    }
    request r = {.cmd = argv[optind], .args = argv + optind + 1, .nargs = argc - optind - 1};
    code = check_request(&r);
    if (code != GO_ON) return code;

    if (!strcmp(r.cmd, "list"))
        return list_plants(o.url, o.timeout_set ? o.timeout : LIST_TIMEOUT_S);
    lag_client_plant chosen;
    lag_client *c = connect_plant(&o, &chosen, &code);
    if (!c) return code;
    answer a = {0};
    a.heard = lag_client_now();
    lag_client_on_event(c, on_event, &a);
    lag_client_on_status(c, on_status, &a);
    lag_client_on_state(c, on_state, &a);
    lag_client_on_scene(c, on_scene, &a);

    int rc = send_request(c, &a, &r, o.timeout);
    code = EXIT_OK;
    if (rc == RC_USAGE) {
        code = EXIT_USAGE;
    } else if (rc < 0) {
        fprintf(stderr, "lagsimctl: %s\n", lag_client_errmsg(c));
        code = EXIT_NOANSWER;
    } else if (rc == LAG_CLIENT_TIMEOUT && !g_signal) {
        /* a prefix nobody has (misspelt): who is on the bus instead */
        char instead[1500];
        lag_client_plants_instead(o.url, o.prefix, 1.0, instead, sizeof instead);
        fprintf(stderr, "lagsimctl: no answer on %s_* within %g s: %s\n", o.prefix, o.timeout,
                instead);
        code = EXIT_NOANSWER;
    } else if (a.refused) {
        fprintf(stderr, "lagsimctl: the daemon refused: %s\n", a.ev.detail);
        code = EXIT_REFUSED;
    }
    lag_client_destroy(c);
    return code;
}

int main(int argc, char **argv)
{
    return lag_result_exit(lagsimctl_main(argc, argv));
}
