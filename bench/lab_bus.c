/*
 * What the bus costs a lab host of many plants (docs/benchmarks.md, "A lab host"): the
 * figures its design was chosen by.
 *
 *   lab_bus instances K        K lcm_t receiving on K ports (as K plants' command URLs):
 *                              threads, resident memory, before and after 1 MiB each
 *   lab_bus publish K ROUNDS   ROUNDS rounds of one 200-byte message to each of K ports
 *                              (K plants' states), each port read by a socket of a child
 *                              process: CPU per message of lcm_publish (K lcm_t), of one
 *                              sendmsg per message in LCM's format, of one sendmmsg per
 *                              round; the receiving side's CPU per message
 *   lab_bus deliver K ROUNDS   the same rounds (plain sendmsg), K readers: each on its own
 *                              port (one port pair per plant) or all on one port (a shared
 *                              group: every reader gets every plant's message): CPU per
 *                              message sent, both sides, and datagrams read
 *   lab_bus format             LCM's own datagram for a message against the one written
 *                              here (LC02, sequence number, channel, payload): equal or not
 *
 * Ports: BASE, BASE + 2, ... (env LAB_BUS_BASE, default 30000), group 239.255.76.67, ttl 0.
 * Nothing is asserted: figures for the docs, each with its load average.
 */

#include <arpa/inet.h>
#include <errno.h>
#include <lcm/lcm.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include "lagsim_clock.h"

#define GROUP "239.255.76.67"
#define PAYLOAD 200 /* about a DIPC joint_state_t */
#define KMAX 1024

static int g_base = 30000;

static int port_of(int i) { return g_base + 2 * i; }

static double cpu_s(int who)
{
    struct rusage ru;
    getrusage(who, &ru);
    return (double)ru.ru_utime.tv_sec + (double)ru.ru_utime.tv_usec * 1e-6 +
           (double)ru.ru_stime.tv_sec + (double)ru.ru_stime.tv_usec * 1e-6;
}

static void loadavg(char *out, size_t cap)
{
    FILE *f = fopen("/proc/loadavg", "r");
    if (!f || !fgets(out, (int)cap, f)) snprintf(out, cap, "?\n");
    if (f) fclose(f);
    out[strcspn(out, "\n")] = '\0';
}

/* A UDP socket bound to port and joined to the group (a reader); -1 on failure. */
static int reader_socket(int port, bool reuse)
{
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    int one = 1;
    if (reuse) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    struct ip_mreq mr = {.imr_interface.s_addr = htonl(INADDR_ANY)};
    inet_pton(AF_INET, GROUP, &mr.imr_multiaddr);
    int big = 4 << 20;
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0 ||
        setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

/* A sending socket as LCM's udpm makes one: multicast ttl 0, looped back. */
static int sender_socket(void)
{
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    unsigned char ttl = 0, loop = 1;
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
    setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop);
    return fd;
}

/* LCM's short message: "LC02", a big-endian sequence number, the channel and its NUL, the
 * payload. Returns its length. */
static size_t lc02(uint8_t *out, uint32_t seq, const char *channel, const uint8_t *data,
                   size_t len)
{
    const uint32_t magic = htonl(0x4c433032u), s = htonl(seq);
    memcpy(out, &magic, 4);
    memcpy(out + 4, &s, 4);
    size_t cl = strlen(channel) + 1;
    memcpy(out + 8, channel, cl);
    memcpy(out + 8 + cl, data, len);
    return 8 + cl + len;
}

/* ---------------------------------------------------------------- readers (a child) */
/* Reads every socket until `expect` datagrams came or 2 s pass without one; writes the
 * count to fd `report`, then exits. */
static void reader_child(const int *fds, int n, long expect, int report)
{
    int ep = epoll_create1(EPOLL_CLOEXEC);
    for (int i = 0; i < n; i++) {
        struct epoll_event ev = {.events = EPOLLIN, .data.fd = fds[i]};
        epoll_ctl(ep, EPOLL_CTL_ADD, fds[i], &ev);
    }
    long got = 0;
    uint8_t buf[2048];
    struct epoll_event evs[64];
    while (got < expect) {
        int k = epoll_wait(ep, evs, 64, 2000);
        if (k <= 0) break;
        for (int j = 0; j < k; j++)
            while (recv(evs[j].data.fd, buf, sizeof buf, 0) > 0) got++;
    }
    if (write(report, &got, sizeof got) < 0) _exit(1);
    _exit(0);
}

typedef struct readers {
    pid_t pid;
    int report;
    double cpu;  /* the child's CPU seconds, after reap */
    long got;
} readers;

/* K readers in a child: on K ports, or (shared) all on port_of(0). */
static int readers_start(readers *r, int k, bool shared, long expect)
{
    static int fds[KMAX];
    for (int i = 0; i < k; i++)
        if ((fds[i] = reader_socket(port_of(shared ? 0 : i), shared)) < 0) {
            perror("lab_bus: reader socket");
            return -1;
        }
    int p[2];
    if (pipe(p) != 0) return -1;
    r->pid = fork();
    if (r->pid == 0) {
        close(p[0]);
        reader_child(fds, k, expect, p[1]);
    }
    close(p[1]);
    for (int i = 0; i < k; i++) close(fds[i]);
    r->report = p[0];
    usleep(100000); /* joined */
    return 0;
}

static void readers_reap(readers *r)
{
    r->got = 0;
    if (read(r->report, &r->got, sizeof r->got) != (ssize_t)sizeof r->got) r->got = -1;
    close(r->report);
    int st;
    struct rusage ru;
    wait4(r->pid, &st, 0, &ru);
    r->cpu = (double)ru.ru_utime.tv_sec + (double)ru.ru_utime.tv_usec * 1e-6 +
             (double)ru.ru_stime.tv_sec + (double)ru.ru_stime.tv_usec * 1e-6;
}

/* ---------------------------------------------------------------- sending */
typedef enum method { M_LCM, M_SENDMSG, M_SENDMMSG } method;
static const char *const method_name[] = {"lcm_publish (one lcm_t per plant)",
                                          "sendmsg, one per message", "sendmmsg, one per round"};

typedef struct sender {
    method m;
    int k;
    bool shared;              /* every plant's message to port_of(0) */
    int fd;
    lcm_t *lcm[KMAX];
    char channel[KMAX][32];
    struct sockaddr_in to[KMAX];
    uint8_t pkt[KMAX][PAYLOAD + 64];
    struct mmsghdr mm[KMAX];
    struct iovec iov[KMAX];
    uint32_t seq;
} sender;

static int sender_open(sender *s, method m, int k, bool shared)
{
    s->m = m;
    s->k = k;
    s->shared = shared;
    s->fd = sender_socket();
    for (int i = 0; i < k; i++) {
        snprintf(s->channel[i], sizeof s->channel[i], "PLANT%03d_STATE", i);
        int port = port_of(shared ? 0 : i);
        s->to[i] = (struct sockaddr_in){.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
        inet_pton(AF_INET, GROUP, &s->to[i].sin_addr);
        if (m == M_LCM) {
            char url[96];
            snprintf(url, sizeof url, "udpm://%s:%d?ttl=0", GROUP, port);
            if (!(s->lcm[i] = lcm_create(url))) return -1;
        }
    }
    return s->fd < 0 ? -1 : 0;
}

static void sender_close(sender *s)
{
    for (int i = 0; i < s->k; i++)
        if (s->lcm[i]) lcm_destroy(s->lcm[i]);
    close(s->fd);
}

/* One round: a message to each plant's port. */
static void sender_round(sender *s, const uint8_t *payload)
{
    if (s->m == M_LCM) {
        for (int i = 0; i < s->k; i++) lcm_publish(s->lcm[i], s->channel[i], payload, PAYLOAD);
        return;
    }
    for (int i = 0; i < s->k; i++) {
        size_t n = lc02(s->pkt[i], s->seq++, s->channel[i], payload, PAYLOAD);
        if (s->m == M_SENDMSG) {
            if (sendto(s->fd, s->pkt[i], n, 0, (struct sockaddr *)&s->to[i], sizeof s->to[i]) < 0)
                perror("lab_bus: sendto");
            continue;
        }
        s->iov[i] = (struct iovec){s->pkt[i], n};
        s->mm[i].msg_hdr = (struct msghdr){.msg_name = &s->to[i], .msg_namelen = sizeof s->to[i],
                                           .msg_iov = &s->iov[i], .msg_iovlen = 1};
    }
    for (int done = 0; s->m == M_SENDMMSG && done < s->k;) {
        int r = sendmmsg(s->fd, s->mm + done, (unsigned)(s->k - done), 0);
        if (r <= 0) {
            perror("lab_bus: sendmmsg");
            return;
        }
        done += r;
    }
}

/* ROUNDS rounds at full speed (a pause of 1 ms every 20 rounds, so that the readers keep
 * up and nothing is lost to a full socket buffer); prints the CPU per message sent. */
static int run_rounds(method m, int k, long rounds, bool shared)
{
    static sender s;
    memset(&s, 0, sizeof s);
    readers r;
    long expect = rounds * k * (shared ? k : 1);
    if (readers_start(&r, k, shared, expect) != 0 || sender_open(&s, m, k, shared) != 0) return 1;
    uint8_t payload[PAYLOAD];
    memset(payload, 0x5a, sizeof payload);
    double c0 = cpu_s(RUSAGE_SELF), w0 = lag_clock_mono_s();
    for (long j = 0; j < rounds; j++) {
        sender_round(&s, payload);
        if (j % 20 == 19) usleep(1000);
    }
    double c1 = cpu_s(RUSAGE_SELF), w1 = lag_clock_mono_s();
    readers_reap(&r);
    sender_close(&s);
    double msgs = (double)rounds * k;
    char la[64];
    loadavg(la, sizeof la);
    printf("%-36s K=%4d %s: sender %6.2f us/msg, readers %6.2f us/msg sent, datagrams read "
           "%ld of %ld (%.2f s; load %s)\n", method_name[m], k, shared ? "one shared port  " :
           "a port per plant", (c1 - c0) / msgs * 1e6, r.cpu / msgs * 1e6, r.got, expect,
           w1 - w0, la);
    return 0;
}

/* ---------------------------------------------------------------- instances */
static long status_kb(const char *key)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long v = -1;
    size_t kl = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, key, kl)) v = atol(line + kl);
    if (f) fclose(f);
    return v;
}

static void on_any(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)rb, (void)ch;
    (*(long *)u)++;
}

/* K lcm_t, each subscribed (a receive socket and LCM's thread for it): threads and memory,
 * then after 1 MiB of 200-byte messages through each. */
static int run_instances(int k)
{
    static lcm_t *l[KMAX];
    long got = 0;
    long t0 = status_kb("Threads:"), r0 = status_kb("VmRSS:");
    for (int i = 0; i < k; i++) {
        char url[96];
        snprintf(url, sizeof url, "udpm://%s:%d?ttl=0", GROUP, port_of(i));
        if (!(l[i] = lcm_create(url)) || !lcm_subscribe(l[i], ".*", on_any, &got)) return 1;
    }
    long t1 = status_kb("Threads:"), r1 = status_kb("VmRSS:");
    int fd = sender_socket();
    uint8_t pkt[PAYLOAD + 64], payload[PAYLOAD] = {0};
    for (int i = 0; i < k; i++) {
        struct sockaddr_in to = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port_of(i))};
        inet_pton(AF_INET, GROUP, &to.sin_addr);
        for (int j = 0; j < (1 << 20) / PAYLOAD; j++) {
            size_t n = lc02(pkt, (uint32_t)j, "X_COMMAND", payload, sizeof payload);
            if (sendto(fd, pkt, n, 0, (struct sockaddr *)&to, sizeof to) < 0) break;
            if (j % 64 == 63) while (lcm_handle_timeout(l[i], 0) > 0) {}
        }
        while (lcm_handle_timeout(l[i], 20) > 0) {}
    }
    long r2 = status_kb("VmRSS:");
    printf("%d lcm_t subscribed: threads %ld -> %ld (+%.2f each); resident %ld -> %ld KiB "
           "(+%.0f KiB each); after 1 MiB through each: %ld KiB (+%.0f KiB each); %ld "
           "messages handled\n", k, t0, t1, (double)(t1 - t0) / k, r0, r1,
           (double)(r1 - r0) / k, r2, (double)(r2 - r0) / k, got);
    close(fd);
    for (int i = 0; i < k; i++) lcm_destroy(l[i]);
    return 0;
}

/* ---------------------------------------------------------------- format */
/* LCM's datagrams for two messages of a fresh lcm_t, read by a plain socket, against
 * lc02()'s with sequence numbers 0 and 1. */
static int run_format(void)
{
    int fd = reader_socket(port_of(0), true);
    char url[96];
    snprintf(url, sizeof url, "udpm://%s:%d?ttl=0", GROUP, port_of(0));
    lcm_t *l = lcm_create(url);
    if (fd < 0 || !l) return 1;
    uint8_t payload[PAYLOAD], got[2048], mine[2048];
    for (int i = 0; i < PAYLOAD; i++) payload[i] = (uint8_t)(i * 7);
    int same = 0;
    for (uint32_t seq = 0; seq < 2; seq++) {
        lcm_publish(l, "LAB_FORMAT_STATE", payload, sizeof payload);
        ssize_t n = -1;
        for (int t = 0; t < 200 && n < 0; t++) {
            n = recv(fd, got, sizeof got, 0);
            if (n < 0) usleep(1000);
        }
        size_t m = lc02(mine, seq, "LAB_FORMAT_STATE", payload, sizeof payload);
        bool eq = n == (ssize_t)m && !memcmp(got, mine, m);
        same += eq;
        printf("message %u: LCM's datagram %zd bytes, lc02's %zu bytes: %s\n", seq, n, m,
               eq ? "byte for byte equal" : "DIFFERENT");
    }
    lcm_destroy(l);
    close(fd);
    return same == 2 ? 0 : 1;
}

int main(int argc, char **argv)
{
    const char *b = getenv("LAB_BUS_BASE");
    if (b && atoi(b) > 0) g_base = atoi(b);
    signal(SIGPIPE, SIG_IGN);
    const char *what = argc > 1 ? argv[1] : "";
    int k = argc > 2 ? atoi(argv[2]) : 100;
    long rounds = argc > 3 ? atol(argv[3]) : 1000;
    if (k < 1 || k > KMAX || rounds < 1) {
        fprintf(stderr, "lab_bus: K from 1 to %d, ROUNDS >= 1\n", KMAX);
        return 2;
    }
    if (!strcmp(what, "instances")) return run_instances(k);
    if (!strcmp(what, "format")) return run_format();
    if (!strcmp(what, "publish")) {
        for (method m = M_LCM; m <= M_SENDMMSG; m++)
            if (run_rounds(m, k, rounds, false) != 0) return 1;
        return 0;
    }
    if (!strcmp(what, "deliver")) {
        if (run_rounds(M_SENDMSG, k, rounds, false) != 0) return 1;
        return run_rounds(M_SENDMSG, k, rounds, true);
    }
    fprintf(stderr, "usage: lab_bus instances K | publish K ROUNDS | deliver K ROUNDS | format\n");
    return 2;
}
