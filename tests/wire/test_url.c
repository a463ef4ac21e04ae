/*
 * lagsim's one LCM URL reader (server/wire/lagsim_url.c) and its two users: the plant's
 * URLs (lag_bus_init: the options kept as given) and a scene's lcm.url
 * (lag_scene_check_url: the options checked, ttl above 0 only with lcm.allow_lan).
 *
 * The cases are the grammar of docs/scenes.md and docs/network.md, one URL a line, with
 * what each user does with it. Where the two users differ, they differ only in the
 * options (a plant passes them to LCM as given; a scene allows ttl and recv_buf_size
 * alone): the address part is one rule for both.
 *
 *   test_url [--list | CASE]
 */
#include "lagsim_test.h"

#include "lagsim_bus.h"
#include "lagsim_url.h"
#include "scene.h"

#define OK NULL
#define REFUSED "" /* refused; the message is not pinned */

typedef struct url_case {
    const char *url;
    const char *bus_state;    /* the plant's state URL, or NULL: refused */
    const char *bus_command;  /* its command URL */
    const char *scene;        /* lcm.url without allow_lan: OK, or a piece of the message */
    const char *scene_lan;    /* with lcm.allow_lan: true */
    int ttl;                  /* what the scene reads when accepted */
} url_case;

static const url_case cases[] = {
    /* memq: one in-process bus, nothing after it */
    {"memq://", "memq://", "memq://", OK, OK, 0},
    {"memq://x", NULL, NULL, "memq:// takes no address or options", "memq:// takes no address", 0},
    /* udpm: LCM's group and port when absent, commands on the next port */
    {"udpm://", "udpm://239.255.76.67:7667", "udpm://239.255.76.67:7668", OK, OK, 0},
    {"udpm://?ttl=0", "udpm://239.255.76.67:7667?ttl=0", "udpm://239.255.76.67:7668?ttl=0", OK, OK, 0},
    {"udpm://239.255.76.67", "udpm://239.255.76.67:7667", "udpm://239.255.76.67:7668", OK, OK, 0},
    {"udpm://239.255.76.67:7667?ttl=0", "udpm://239.255.76.67:7667?ttl=0",
     "udpm://239.255.76.67:7668?ttl=0", OK, OK, 0},
    {"udpm://224.0.0.251:1", "udpm://224.0.0.251:1", "udpm://224.0.0.251:2", OK, OK, 0},
    {"udpm://239.255.76.67:65534", "udpm://239.255.76.67:65534", "udpm://239.255.76.67:65535",
     OK, OK, 0},
    {"udpm://239.0.0.1:7667", "udpm://239.0.0.1:7667", "udpm://239.0.0.1:7668", OK, OK, 0},
    /* ttl above 0 leaves the host: a scene says it means it */
    {"udpm://?ttl=1", "udpm://239.255.76.67:7667?ttl=1", "udpm://239.255.76.67:7668?ttl=1",
     "set lcm.allow_lan: true if that is meant", OK, 1},
    {"udpm://239.1.2.3:7700?ttl=1&recv_buf_size=2097152",
     "udpm://239.1.2.3:7700?ttl=1&recv_buf_size=2097152",
     "udpm://239.1.2.3:7701?ttl=1&recv_buf_size=2097152", "ttl=1 sends every message", OK, 1},
    {"udpm://239.255.76.67?ttl=255", "udpm://239.255.76.67:7667?ttl=255",
     "udpm://239.255.76.67:7668?ttl=255", "lcm.allow_lan", OK, 255},
    {"udpm://239.255.76.67?recv_buf_size=4096&ttl=0", "udpm://239.255.76.67:7667?recv_buf_size=4096&ttl=0",
     "udpm://239.255.76.67:7668?recv_buf_size=4096&ttl=0", OK, OK, 0},
    {"udpm://239.255.76.67?recv_buf_size=268435456", "udpm://239.255.76.67:7667?recv_buf_size=268435456",
     "udpm://239.255.76.67:7668?recv_buf_size=268435456", OK, OK, 0},
    /* the address: refused by both */
    {"udpm://239.255.76.67:65535", NULL, NULL, "expected a port from 1 to 65534 (commands go to the next port)",
     "expected a port from 1 to 65534", 0},
    {"udpm://239.255.76.67:0", NULL, NULL, "expected a port from 1 to 65534", "expected a port", 0},
    {"udpm://239.255.76.67:70000", NULL, NULL, "expected a port from 1 to 65534", "expected a port", 0},
    {"udpm://239.255.76.67:07667", NULL, NULL, "expected a port from 1 to 65534", "expected a port", 0},
    {"udpm://239.255.76.67:", NULL, NULL, "expected a port from 1 to 65534", "expected a port", 0},
    {"udpm://239.255.076.67:7667", NULL, NULL,
     "expected udpm://GROUP:PORT with GROUP a dotted IPv4 multicast address", "dotted IPv4", 0},
    {"udpm://239.255.76:7667", NULL, NULL, "dotted IPv4 multicast address", "dotted IPv4", 0},
    {"udpm://239.255.76.256", NULL, NULL, "dotted IPv4 multicast address", "dotted IPv4", 0},
    {"udpm://239.255.76.67.1", NULL, NULL, "unexpected '.' after the address", "unexpected '.'", 0},
    {"udpm://:7700", NULL, NULL, "dotted IPv4 multicast address", "dotted IPv4", 0},
    {"udpm://192.168.1.10:7667", NULL, NULL, "192.168.1.10 is not a multicast address",
     "is not a multicast address", 0},
    {"udpm://223.255.255.255", NULL, NULL, "is not a multicast address", "not a multicast", 0},
    {"udpm://240.0.0.1", NULL, NULL, "240.0.0.1 is not a multicast address", "not a multicast", 0},
    {"udpm://239.255.76.67:7667x", NULL, NULL, "unexpected 'x' after the address",
     "unexpected 'x'", 0},
    /* other providers, and no provider */
    {"tcpq://127.0.0.1:7700", NULL, NULL, "LCM provider 'tcpq://' is not accepted in a scene",
     "LCM provider 'tcpq://'", 0},
    {"file:///tmp/run.lcm?mode=w", NULL, NULL, "LCM provider 'file://' is not accepted in a scene",
     "LCM provider 'file://'", 0},
    {"UDPM://239.255.76.67", NULL, NULL, "LCM provider 'UDPM://'", "LCM provider 'UDPM://'", 0},
    {"239.255.76.67:7667", NULL, NULL, "expected an LCM URL udpm://GROUP:PORT?ttl=0",
     "expected an LCM URL", 0},
    /* the options: a plant keeps them as given, a scene allows two, once each, decimal */
    {"udpm://239.255.76.67:7700?ttl=0&x", "udpm://239.255.76.67:7700?ttl=0&x",
     "udpm://239.255.76.67:7701?ttl=0&x", "unknown udpm option 'x'", "unknown udpm option 'x'", 0},
    {"udpm://239.255.76.67?mode=w", "udpm://239.255.76.67:7667?mode=w",
     "udpm://239.255.76.67:7668?mode=w", "unknown udpm option 'mode'", "unknown udpm option", 0},
    {"udpm://239.255.76.67?", "udpm://239.255.76.67:7667?", "udpm://239.255.76.67:7668?",
     "unknown udpm option ''", "unknown udpm option ''", 0},
    {"udpm://239.255.76.67?ttl=0&ttl=1", "udpm://239.255.76.67:7667?ttl=0&ttl=1",
     "udpm://239.255.76.67:7668?ttl=0&ttl=1", "udpm option 'ttl' given twice",
     "udpm option 'ttl' given twice", 0},
    {"udpm://239.255.76.67?ttl=010", "udpm://239.255.76.67:7667?ttl=010",
     "udpm://239.255.76.67:7668?ttl=010", "expected ttl=<integer>", "expected ttl=<integer>", 0},
    {"udpm://239.255.76.67?ttl", "udpm://239.255.76.67:7667?ttl", "udpm://239.255.76.67:7668?ttl",
     "expected ttl=<integer>", "expected ttl=<integer>", 0},
    {"udpm://239.255.76.67?ttl=1x", "udpm://239.255.76.67:7667?ttl=1x",
     "udpm://239.255.76.67:7668?ttl=1x", "expected ttl=<integer>", "expected ttl=<integer>", 0},
    {"udpm://239.255.76.67?ttl=256", "udpm://239.255.76.67:7667?ttl=256",
     "udpm://239.255.76.67:7668?ttl=256", "ttl must be 0 to 255, got 256",
     "ttl must be 0 to 255, got 256", 0},
    {"udpm://239.255.76.67?recv_buf_size=4095", "udpm://239.255.76.67:7667?recv_buf_size=4095",
     "udpm://239.255.76.67:7668?recv_buf_size=4095",
     "recv_buf_size must be 4096 to 268435456 bytes, got 4095", "recv_buf_size must be", 0},
    {"udpm://239.255.76.67?recv_buf_size=268435457", "udpm://239.255.76.67:7667?recv_buf_size=268435457",
     "udpm://239.255.76.67:7668?recv_buf_size=268435457", "recv_buf_size must be",
     "recv_buf_size must be", 0},
    /* each option is read where it stands: a ttl the scene may not have is said first */
    {"udpm://?ttl=1&foo=2", "udpm://239.255.76.67:7667?ttl=1&foo=2",
     "udpm://239.255.76.67:7668?ttl=1&foo=2", "lcm.allow_lan", "unknown udpm option 'foo'", 0},
};
enum { N_CASES = (int)(sizeof cases / sizeof cases[0]) };

/* The plant's URLs: accepted with exactly these two URLs, or refused with a message. */
static void case_bus(int arg)
{
    (void)arg;
    unsetenv("LCM_DEFAULT_URL");
    for (int i = 0; i < N_CASES; i++) {
        const url_case *c = &cases[i];
        lag_bus b;
        char err[512];
        int rc = lag_bus_init(&b, c->url, "T", err, sizeof err);
        if (!c->bus_state) {
            if (rc == 0) LT_FAIL("bus: '%s' accepted (%s)", c->url, b.state_url);
            else ENSURE(err[0] != '\0');
            continue;
        }
        if (rc != 0) {
            LT_FAIL("bus: '%s' refused: %s", c->url, err);
            continue;
        }
        if (strcmp(b.state_url, c->bus_state) != 0 || strcmp(b.command_url, c->bus_command) != 0)
            LT_FAIL("bus: '%s' gave %s and %s, expected %s and %s", c->url, b.state_url,
                    b.command_url, c->bus_state, c->bus_command);
        ENSURE(b.udpm == (strncmp(c->url, "udpm", 4) == 0));
    }
}

static void check_scene(const url_case *c, bool lan, const char *want)
{
    int ttl = -1;
    char err[512] = "";
    int rc = lag_scene_check_url(c->url, lan, &ttl, err, sizeof err);
    const char *how = lan ? " (allow_lan)" : "";
    if (want == OK) {
        if (rc != 0) LT_FAIL("scene%s: '%s' refused: %s", how, c->url, err);
        else ENSURE(ttl == c->ttl);
    } else {
        bool said = rc != 0 && strstr(err, want) != NULL;
        if (!said)
            fprintf(stderr, "scene%s: '%s': %s; expected a refusal saying '%s'\n", how, c->url,
                    rc != 0 ? err : "accepted", want);
        ENSURE(said);
    }
}

/* A scene's lcm.url, with and without lcm.allow_lan; "" is LCM's default. */
static void case_scene(int arg)
{
    (void)arg;
    for (int i = 0; i < N_CASES; i++) {
        check_scene(&cases[i], false, cases[i].scene);
        check_scene(&cases[i], true, cases[i].scene_lan);
    }
    int ttl = -1;
    char err[64];
    ENSURE(lag_scene_check_url("", false, &ttl, err, sizeof err) == 0 && ttl == 0);
    ENSURE(lag_scene_check_url(NULL, false, &ttl, err, sizeof err) == 0 && ttl == 0);
}

/* The two users read one rule: every address the plant refuses the scene refuses, and
 * every URL a scene accepts the plant accepts with its group and port. */
static void case_one_rule(int arg)
{
    (void)arg;
    for (int i = 0; i < N_CASES; i++) {
        const url_case *c = &cases[i];
        ENSURE(c->bus_state || (c->scene != OK && c->scene_lan != OK));
        if (c->scene_lan == OK) ENSURE(c->bus_state != NULL);
    }
    /* and the table covers both ways of each: accepted and refused by each user */
    int bus_ok = 0, bus_no = 0, sc_ok = 0, sc_no = 0, differ = 0;
    for (int i = 0; i < N_CASES; i++) {
        bus_ok += cases[i].bus_state != NULL;
        bus_no += cases[i].bus_state == NULL;
        sc_ok += cases[i].scene_lan == OK;
        sc_no += cases[i].scene_lan != OK;
        differ += cases[i].bus_state && cases[i].scene_lan != OK;
    }
    ENSURE(bus_ok > 5 && bus_no > 5 && sc_ok > 5 && sc_no > 5 && differ > 5);
}

/* lag_url_parse's fields. */
static void case_fields(int arg)
{
    (void)arg;
    lag_url u;
    char err[256];
    ENSURE(lag_url_parse("memq://", 0, &u, err, sizeof err) == 0 && u.provider == LAG_URL_MEMQ);
    ENSURE(lag_url_parse("udpm://", 0, &u, err, sizeof err) == 0);
    ENSURE(u.provider == LAG_URL_UDPM && !u.has_group && !u.has_port);
    ENSURE(strcmp(u.group, "239.255.76.67") == 0 && u.port == 7667 && strcmp(u.query, "") == 0);
    ENSURE(lag_url_parse("udpm://239.1.2.3?x=y", 0, &u, err, sizeof err) == 0);
    ENSURE(u.has_group && !u.has_port && u.port == 7667 && strcmp(u.query, "?x=y") == 0);
    ENSURE(lag_url_parse("udpm://239.1.2.3:7700?ttl=1&recv_buf_size=65536",
                         LAG_URL_SCENE_RULES | LAG_URL_ALLOW_LAN, &u, err, sizeof err) == 0);
    ENSURE(strcmp(u.group, "239.1.2.3") == 0 && u.has_port && u.port == 7700);
    ENSURE(u.ttl == 1 && u.recv_buf_size == 65536);
    ENSURE(strcmp(u.query, "?ttl=1&recv_buf_size=65536") == 0);
    /* a message for every refusal, and none on success; a NULL err is allowed */
    ENSURE(lag_url_parse("udpm://1.2.3.4", 0, &u, err, sizeof err) == -1 && err[0] != '\0');
    ENSURE(lag_url_parse("udpm://1.2.3.4", 0, &u, NULL, 0) == -1);
    ENSURE(lag_url_parse("udpm://239.1.2.3", 0, &u, err, sizeof err) == 0 && err[0] == '\0');
    /* the provider message says who refuses */
    lag_url_parse("tcpq://h", 0, &u, err, sizeof err);
    ENSURE(strstr(err, "by a lagsim plant") != NULL);
    lag_url_parse("tcpq://h", LAG_URL_SCENE_RULES, &u, err, sizeof err);
    ENSURE(strstr(err, "in a scene") != NULL);
}

int main(int argc, char **argv)
{
    static const lt_case all[] = {
        {"bus", case_bus, 0, 0},
        {"scene", case_scene, 0, 0},
        {"one_rule", case_one_rule, 0, 0},
        {"fields", case_fields, 0, 0},
    };
    return lt_main(argc, argv, all, (int)(sizeof all / sizeof all[0]));
}
