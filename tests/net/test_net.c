/*
 * The daemon's socket filter and network helpers (server/wire/lagsim_net.c) on this host:
 * which LCM datagrams the filter keeps (exact channel names of every length, short
 * messages only, from this host), that it finds LCM's own receive socket, that a marker
 * sent after the filter comes back (and does not when the filter keeps it out), and the
 * interface of the route to a group; with suffixes, every channel that ends in one of them
 * after a prefix, at every length LCM allows, and no other. That a datagram from another host is dropped needs
 * a second host: tests/net/two_hosts.sh (net_two_hosts).
 *
 *   test_net [CASE]      cases: channels suffixes lcm_socket sync route
 */
#include <arpa/inet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "lagsim_test.h"
#include "lagsim_net.h"

#define GROUP "239.255.76.67"

/* Port k (0..3) of four of this process's own (lt_lcm_ports, lagsim_test.h). */
static int test_port(int k)
{
    static int base = -1;
    if (base < 0) base = lt_lcm_ports(4);
    if (base < 0) {
        fprintf(stderr, "no four free UDP ports in a row (lt_lcm_ports)\n");
        exit(1);
    }
    return base + k;
}

/* A UDP socket bound to port, member of GROUP (as LCM's receive socket is). */
static int member_socket(int port)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0), one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_ANY);
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0) return -1;
    struct ip_mreq m;
    m.imr_multiaddr.s_addr = inet_addr(GROUP);
    m.imr_interface.s_addr = htonl(INADDR_ANY);
    if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &m, sizeof m) != 0) return -1;
    return fd;
}

/* Sends an LCM-like datagram: magic, sequence number, channel, NUL, payload. */
static void send_lcm(int tx, int port, uint32_t magic, const char *channel, size_t cut)
{
    uint8_t b[256];
    uint32_t mg = htonl(magic), seq = htonl(7);
    memcpy(b, &mg, 4);
    memcpy(b + 4, &seq, 4);
    size_t n = strlen(channel) + 1;
    memcpy(b + 8, channel, n);
    memcpy(b + 8 + n, "payload", 7);
    size_t len = 8 + n + 7;
    if (cut && cut < len) len = cut;
    struct sockaddr_in d = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    d.sin_addr.s_addr = inet_addr(GROUP);
    sendto(tx, b, len, 0, (struct sockaddr *)&d, sizeof d);
}

/* Datagrams waiting on fd (read and counted; waits up to ms for the first). */
static int drain(int fd, int ms)
{
    int n = 0;
    struct pollfd p = {fd, POLLIN, 0};
    while (poll(&p, 1, n ? 20 : ms) > 0) {
        uint8_t b[512];
        if (recv(fd, b, sizeof b, 0) < 0) break;
        n++;
    }
    return n;
}

static int sender(void)
{
    int tx = socket(AF_INET, SOCK_DGRAM, 0);
    unsigned char ttl = 0, loop = 1;
    setsockopt(tx, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, 1);
    setsockopt(tx, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, 1);
    return tx;
}

/* The filter keeps exactly the named channels, at every name length (the program
 * compares words, then a half word, then a byte), only short messages, whole. */
static void case_channels(int arg)
{
    (void)arg;
    int port = test_port(0), fd = member_socket(port), tx = sender();
    ENSURE(fd >= 0 && tx >= 0);
    if (fd < 0 || tx < 0) return;
    char err[256];
    for (int len = 1; len <= 71; len++) {
        char name[80], other[80], longer[96], shorter[80];
        for (int i = 0; i < len; i++) name[i] = (char)('A' + (i * 7 + len) % 26);
        name[len] = '\0';
        snprintf(other, sizeof other, "%s", name);
        other[len - 1] = other[len - 1] == 'Z' ? 'Y' : 'Z'; /* the last byte differs */
        snprintf(longer, sizeof longer, "%sQ", name);
        snprintf(shorter, sizeof shorter, "%.*s", len - 1, name);
        const char *chans[2] = {name, "SECOND_CHANNEL"};
        int n = lag_net_filter(port, len % 2 == 0, chans, 2, err, sizeof err);
        ENSURE(n == 1);
        if (n != 1) {
            fprintf(stderr, "filter: %s\n", n < 0 ? err : "no socket found");
            break;
        }
        send_lcm(tx, port, 0x4c433032u, name, 0);             /* kept */
        send_lcm(tx, port, 0x4c433032u, "SECOND_CHANNEL", 0); /* kept */
        send_lcm(tx, port, 0x4c433032u, other, 0);
        send_lcm(tx, port, 0x4c433032u, longer, 0);
        if (len > 1) send_lcm(tx, port, 0x4c433032u, shorter, 0);
        send_lcm(tx, port, 0x4c433033u, name, 0);             /* LC03: a fragment */
        send_lcm(tx, port, 0x4c433032u, name, 8 + (size_t)len); /* cut before the NUL */
        int got = drain(fd, 500);
        if (got != 2) LT_FAIL("channel of %d bytes: %d datagrams kept, expected 2", len, got);
        else ENSURE(got == 2);
    }
    close(tx);
    close(fd);
}

/* With suffixes (lag_net_filter_suffixes): the named channels, and every channel that
 * ends in a suffix after at least one byte of prefix, at every prefix length up to LCM's
 * longest name (63); not the suffix alone, not a channel that only starts with one, not
 * a fragment, not one without its NUL. */
static void case_suffixes(int arg)
{
    (void)arg;
    int port = test_port(3), fd = member_socket(port), tx = sender();
    ENSURE(fd >= 0 && tx >= 0);
    if (fd < 0 || tx < 0) return;
    char err[256];
    const char *chans[] = {"OWN_STATE"}, *sfx[] = {"_CONTROL", "_SCENE"};
    for (int host_only = 0; host_only < 2; host_only++) {
        int n = lag_net_filter_suffixes(port, host_only, chans, 1, sfx, 2, err, sizeof err);
        ENSUREF(n == 1, "filter: %s", n < 0 ? err : "no socket found");
        if (n != 1) break;
        int want = 0;
        for (int len = 1; len + 8 <= 63; len++) { /* a prefix of len bytes */
            char pre[64], ch[80];
            for (int i = 0; i < len; i++) pre[i] = (char)('A' + (i * 5 + len) % 26);
            pre[len] = '\0';
            snprintf(ch, sizeof ch, "%s_CONTROL", pre);
            send_lcm(tx, port, 0x4c433032u, ch, 0), want++;          /* kept */
            if (len + 6 <= 63) {
                snprintf(ch, sizeof ch, "%s_SCENE", pre);
                send_lcm(tx, port, 0x4c433032u, ch, 0), want++;      /* kept */
            }
            snprintf(ch, sizeof ch, "%s_CONTROLS", pre);
            send_lcm(tx, port, 0x4c433032u, ch, 0);                  /* longer: no */
            snprintf(ch, sizeof ch, "%s_CONTROL", pre);
            ch[strlen(ch) - 1] = 'X';
            send_lcm(tx, port, 0x4c433032u, ch, 0);                  /* last byte: no */
            snprintf(ch, sizeof ch, "%s_STATE", pre);
            send_lcm(tx, port, 0x4c433032u, ch, 0);                  /* another suffix */
            snprintf(ch, sizeof ch, "%s_CONTROL", pre);
            send_lcm(tx, port, 0x4c433033u, ch, 0);                  /* a fragment */
            send_lcm(tx, port, 0x4c433032u, ch, 8 + strlen(ch));     /* cut before the NUL */
            int got = drain(fd, 300);
            if (got != want) {
                LT_FAIL("prefix of %d bytes: %d datagrams kept, expected %d", len, got, want);
                break;
            }
            want = 0;
        }
        send_lcm(tx, port, 0x4c433032u, "_CONTROL", 0);  /* no prefix */
        send_lcm(tx, port, 0x4c433032u, "_SCENE", 0);
        send_lcm(tx, port, 0x4c433032u, "OWN_STATE", 0); /* the channel named: kept */
        char huge[80];                                   /* 64 bytes and more: no NUL seen */
        memset(huge, 'Q', sizeof huge);
        snprintf(huge + 56, sizeof huge - 56, "_CONTROL");
        send_lcm(tx, port, 0x4c433032u, huge, 0);
        int got = drain(fd, 300);
        ENSUREF(got == 1, "the suffixes alone, a 64-byte channel: %d kept, expected 1 (OWN_STATE)",
                got);
    }
    close(tx);
    close(fd);
}

/* LCM's own receive socket for a URL is found once the lcm_t has a subscription (and
 * not before: LCM opens it then); the filter then decides what LCM hands over. */
static int handled;
static void on_any(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)rb, (void)ch, (void)u;
    handled++;
}

static void case_lcm_socket(int arg)
{
    (void)arg;
    int port = test_port(1);
    char url[96], err[256];
    snprintf(url, sizeof url, "udpm://" GROUP ":%d?ttl=0", port);
    lcm_t *rx = lcm_create(url), *tx = lcm_create(url);
    ENSURE(rx && tx);
    if (!rx || !tx) return;
    const char *keep[1] = {"NET_KEEP"};
    ENSURE(lag_net_filter(port, true, keep, 1, err, sizeof err) == 0); /* no socket yet */
    lcm_subscribe(rx, ".*", on_any, NULL);
    ENSURE(lag_net_filter(port, true, keep, 1, err, sizeof err) == 1);
    handled = 0;
    for (int k = 0; k < 5; k++) {
        lcm_publish(tx, "NET_KEEP", "x", 1);
        lcm_publish(tx, "NET_DROP", "x", 1);
        lcm_publish(tx, "NET_KEEPX", "x", 1);
    }
    for (int k = 0; k < 50 && handled < 5; k++) lcm_handle_timeout(rx, 20);
    for (int k = 0; k < 10; k++) lcm_handle_timeout(rx, 20);
    if (handled != 5) LT_FAIL("LCM handed over %d messages, expected the 5 on NET_KEEP", handled);
    else ENSURE(handled == 5);
    lcm_destroy(tx);
    lcm_destroy(rx);
}

/* A marker sent after the filter comes back when the filter keeps its channel; when it
 * does not, lag_net_sync says so after its timeout instead of waiting for ever. */
static void case_sync(int arg)
{
    (void)arg;
    int port = test_port(2);
    char url[96], err[256];
    snprintf(url, sizeof url, "udpm://" GROUP ":%d?ttl=0", port);
    lcm_t *lcm = lcm_create(url);
    ENSURE(lcm != NULL);
    if (!lcm) return;
    lcm_subscribe(lcm, "NET_X", on_any, NULL);
    const char *with[2] = {"NET_X", LAG_NET_MARKER_CHANNEL}, *without[1] = {"NET_X"};
    ENSURE(lag_net_filter(port, true, with, 2, err, sizeof err) == 1);
    ENSURE(lag_net_sync(lcm, 3000) == 0);
    ENSURE(lag_net_filter(port, true, without, 1, err, sizeof err) == 1);
    ENSURE(lag_net_sync(lcm, 300) == -1);
    lcm_destroy(lcm);
}

/* The route to the daemon's group names an interface of this host; a unicast or
 * malformed group is refused. */
static void case_route(int arg)
{
    (void)arg;
    char ifname[64];
    int rc = lag_net_group_iface(GROUP, ifname, sizeof ifname);
    printf("route to " GROUP ": %s (%d)\n", ifname, rc);
    ENSURE(rc == 0 && if_nametoindex(ifname) > 0);
    ENSURE(lag_net_group_iface("not an address", ifname, sizeof ifname) == -1);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"channels", case_channels, 0, 0},
        {"suffixes", case_suffixes, 0, 0},
        {"lcm_socket", case_lcm_socket, 0, 0},
        {"sync", case_sync, 0, 0},
        {"route", case_route, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
