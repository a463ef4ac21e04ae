/*
 * A plant's input read by the loop itself (server/daemon/rt_rx.c), against LCM's own
 * datagrams:
 *   parse     LCM's short-message layout taken apart, and every way a datagram can fail to
 *             be one (too short, another magic, a fragment "LC03", no NUL in it)
 *   socket    a socket of rt_rx_open on a port pair of the tools' allocator receives what
 *             lcm_publish sends there (payload byte for byte), hands each channel to its
 *             handler, counts the others, reads at most what it is asked, and finds its
 *             sync marker after whatever came before it
 */
#include <lcm/lcm.h>
#include <stdio.h>
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
    rt_rx r = {-1, 2, {"X_COMMAND", "X_CONTROL"}, {on0, on1}, NULL, 0};
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

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"parse", case_parse, 0, 0}, {"socket", case_socket, 0, 0}};
    const lt_program p = {.cases = cases, .n = (int)(sizeof cases / sizeof cases[0]),
                          .stop_on_failure = true};
    return lt_run(argc, argv, &p);
}
