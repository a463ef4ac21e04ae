/*
 * A plant's input read by the loop itself (server/daemon/rt_rx.c), against LCM's own
 * datagrams:
 *   parse     LCM's short-message layout taken apart, and every way a datagram can fail to
 *             be one (too short, another magic, a fragment "LC03", no NUL in it)
 *   socket    a socket of rt_rx_open on a port pair of the tools' allocator receives what
 *             lcm_publish sends there (payload byte for byte), hands each channel to its
 *             handler, counts the others, reads at most what it is asked, and finds its
 *             sync marker after whatever came before it
 *   other     with `other` set, every short message (its channels' and any other's) is
 *             also handed to it with its channel, as a subscription to a pattern would
 *             hear it (the plant's requests for other prefixes: rt_foreign.h), and none
 *             is counted as dropped; a datagram that is no short message still is
 */
#include <lcm/lcm.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lagsim_port.h"
#include "lagsim_test.h"
#include "rt_rx.h"

static void case_parse(int arg)
{
    (void)arg;
    const char *ch;
    const uint8_t *pl;
    size_t len;
    uint8_t d[64] = "LC02\0\0\0\7X_COMMAND\0payload";
    size_t n = 8 + 10 + 7;
    ENSURE(rt_rx_parse(d, n, &ch, &pl, &len));
    ENSURE(!strcmp(ch, "X_COMMAND") && len == 7 && !memcmp(pl, "payload", 7));
    ENSURE(rt_rx_parse(d, 8 + 10, &ch, &pl, &len) && len == 0); /* an empty payload */
    ENSURE(!rt_rx_parse(d, 8 + 9, &ch, &pl, &len));             /* the NUL cut off */
    ENSURE(!rt_rx_parse(d, 8, &ch, &pl, &len));                  /* no channel */
    memcpy(d, "LC03", 4);                                        /* a fragment */
    ENSURE(!rt_rx_parse(d, n, &ch, &pl, &len));
    ENSURE(!rt_rx_parse((const uint8_t *)"LC0", 3, &ch, &pl, &len));
}

typedef struct seen {
    int n[2];
    uint8_t last[2][256];
    size_t len[2];
} seen;
static seen g_seen;

static void on0(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    g_seen.n[0]++;
    memcpy(g_seen.last[0], d, n < 256 ? n : 256);
    g_seen.len[0] = n;
}

static void on1(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    g_seen.n[1]++;
    memcpy(g_seen.last[1], d, n < 256 ? n : 256);
    g_seen.len[1] = n;
}

/* Reads until `want` datagrams came in all or a second passed. */
static int read_all(rt_rx *r, int want)
{
    int got = 0;
    for (int k = 0; k < 1000 && got < want; k++) {
        got += rt_rx_read(r, want - got);
        if (got < want) usleep(1000);
    }
    return got;
}

typedef struct marker_ctx {
    lcm_t *l;
    int sent;
} marker_ctx;

static void send_marker(void *ctx)
{
    marker_ctx *m = ctx;
    m->sent++;
    lcm_publish(m->l, "LCM_SELF_TEST", "mark 1", 6);
}

static void case_socket(int arg)
{
    (void)arg;
    lag_port_lease lease;
    char err[256];
    if (lag_port_take(&lease, err, sizeof err) != 0) {
        lt_skip("no port pair: %s", err);
        return;
    }
    char url[96];
    snprintf(url, sizeof url, "udpm://239.255.76.67:%d?ttl=0", lease.port);
    rt_rx r = {-1, 2, {"X_COMMAND", "X_CONTROL"}, {on0, on1}, NULL, NULL, 0};
    ENSUREF(rt_rx_open(&r, "239.255.76.67", lease.port, 0, err, sizeof err) == 0, "%s", err);
    lcm_t *l = lcm_create(url);
    ENSURE(l != NULL);
    uint8_t payload[200];
    for (int i = 0; i < 200; i++) payload[i] = (uint8_t)(i * 13);
    lcm_publish(l, "X_COMMAND", payload, sizeof payload);
    lcm_publish(l, "Y_COMMAND", payload, 10); /* another channel: counted, dropped */
    lcm_publish(l, "X_CONTROL", payload, 3);
    ENSURE(read_all(&r, 3) == 3);
    ENSURE(g_seen.n[0] == 1 && g_seen.len[0] == 200 && !memcmp(g_seen.last[0], payload, 200));
    ENSURE(g_seen.n[1] == 1 && g_seen.len[1] == 3 && !memcmp(g_seen.last[1], payload, 3));
    ENSURE(r.dropped == 1);
    for (int i = 0; i < 5; i++) lcm_publish(l, "X_COMMAND", payload, 5);
    usleep(50000);
    ENSURE(rt_rx_read(&r, 2) == 2 && g_seen.n[0] == 3); /* at most what it is asked */
    ENSURE(read_all(&r, 3) == 3 && g_seen.n[0] == 6);
    ENSURE(rt_rx_read(&r, 10) == 0);                     /* nothing waiting */
    lcm_publish(l, "X_COMMAND", payload, 5);             /* before the marker: dropped */
    marker_ctx m = {l, 0};
    ENSURE(rt_rx_sync(&r, "LCM_SELF_TEST", "mark 1", send_marker, &m, 3000) == 0 && m.sent >= 1);
    ENSURE(g_seen.n[0] == 6);
    lcm_destroy(l);
    rt_rx_close(&r);
    ENSURE(r.fd == -1);
    lag_port_release(&lease);
}

typedef struct other_seen {
    int n;
    char ch[4][80];
    size_t len[4];
} other_seen;
static other_seen g_other;

static void on_other(void *ctx, const char *ch, const uint8_t *d, size_t n)
{
    (void)d;
    ENSURE(ctx == &g_other);
    if (g_other.n < 4) {
        snprintf(g_other.ch[g_other.n], sizeof g_other.ch[0], "%s", ch);
        g_other.len[g_other.n] = n;
    }
    g_other.n++;
}

static void case_other(int arg)
{
    (void)arg;
    lag_port_lease lease;
    char err[256];
    if (lag_port_take(&lease, err, sizeof err) != 0) {
        lt_skip("no port pair: %s", err);
        return;
    }
    char url[96];
    snprintf(url, sizeof url, "udpm://239.255.76.67:%d?ttl=0", lease.port);
    memset(&g_seen, 0, sizeof g_seen);
    rt_rx r = {-1, 2, {"X_COMMAND", "X_CONTROL"}, {on0, on1}, on_other, &g_other, 0};
    ENSUREF(rt_rx_open(&r, "239.255.76.67", lease.port, 0, err, sizeof err) == 0, "%s", err);
    lcm_t *l = lcm_create(url);
    ENSURE(l != NULL);
    uint8_t payload[16] = "0123456789abcde";
    lcm_publish(l, "X_CONTROL", payload, 4);     /* its own: its handler, and other */
    lcm_publish(l, "MISSPELT_CONTROL", payload, 7); /* another prefix's: other only */
    lcm_publish(l, "Y_SCENE", payload, 9);
    ENSURE(read_all(&r, 3) == 3);
    ENSURE(g_seen.n[1] == 1 && g_seen.n[0] == 0);
    ENSUREF(g_other.n == 3, "other heard %d", g_other.n);
    ENSURE(!strcmp(g_other.ch[0], "X_CONTROL") && g_other.len[0] == 4);
    ENSURE(!strcmp(g_other.ch[1], "MISSPELT_CONTROL") && g_other.len[1] == 7);
    ENSURE(!strcmp(g_other.ch[2], "Y_SCENE") && g_other.len[2] == 9);
    ENSURE(r.dropped == 0);
    /* a fragment of a long message (LC03) is no short message: counted, never handed on */
    int big = 70000;
    uint8_t *long_msg = calloc(1, (size_t)big);
    ENSURE(long_msg != NULL);
    lcm_publish(l, "X_CONTROL", long_msg, (unsigned)big);
    free(long_msg);
    int got = read_all(&r, 2);
    ENSUREF(got >= 2 && r.dropped == got && g_other.n == 3,
            "a long message: %d datagrams, %lld dropped, other heard %d", got,
            (long long)r.dropped, g_other.n);
    lcm_destroy(l);
    rt_rx_close(&r);
    lag_port_release(&lease);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"parse", case_parse, 0, 0}, {"socket", case_socket, 0, 0},
                                    {"other", case_other, 0, 0}};
    const lt_program p = {.cases = cases, .n = (int)(sizeof cases / sizeof cases[0]),
                          .stop_on_failure = true};
    return lt_run(argc, argv, &p);
}
