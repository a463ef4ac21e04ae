/*
 * Listens to N plants at once and reports how well they kept their period
 * (bench/lab_host.sh; docs/benchmarks.md, "A lab host").
 *
 *   lab_probe GROUP BASE N SECONDS PERIOD_US
 *
 * Plant i is prefix P%03d on state port BASE + 2 i. Its datagrams are read from plain
 * sockets (no LCM threads: the probe must cost the host little): each state's utime, each
 * status's overruns. The period error of plant i is |utime_k - utime_(k-1) - PERIOD| over
 * its consecutive states (one period apart in steps). Reads for SECONDS after the first
 * state came, or until every plant sent its stop status. Prints one line:
 *
 *   plants N heard H states S overruns O (plants with overruns: P, the most: M)
 *   period error p50 A us p99 B us max C us
 */
#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "lagsim_bus.h"
#include "lagsim_clock.h"
#include "lagsim_wire.h"

#define NMAX 1024

typedef struct probe_plant {
    int fd;
    char prefix[16];
    char ch_state[LAG_BUS_CHANNEL_LEN], ch_status[LAG_BUS_CHANNEL_LEN], ch_event[LAG_BUS_CHANNEL_LEN];
    bool heard, stop_seen, stopped; /* stopped: the status after the stop event came */
    int64_t last_utime, last_step, states, overruns;
    int64_t step_per_period;
} probe_plant;

static probe_plant g_p[NMAX];
static double *g_err;            /* every period error, us */
static size_t g_nerr, g_caperr;

static int open_port(const char *group, int port)
{
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    int one = 1, big = 1 << 20;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    struct ip_mreq mr = {.imr_interface.s_addr = htonl(INADDR_ANY)};
    inet_pton(AF_INET, group, &mr.imr_multiaddr);
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) != 0 ||
        setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) != 0) {
        perror("lab_probe: socket");
        exit(1);
    }
    return fd;
}

static void add_err(double e)
{
    if (g_nerr == g_caperr) {
        g_caperr = g_caperr ? 2 * g_caperr : 65536;
        g_err = realloc(g_err, g_caperr * sizeof *g_err);
        if (!g_err) exit(1);
    }
    g_err[g_nerr++] = e;
}

/* One LCM short message of plant p: a state or a status. */
static void on_datagram(probe_plant *p, const uint8_t *d, size_t n, int64_t period_us)
{
    static union {
        lag_wire_joint_state st;
        lag_wire_status status;
        lag_wire_event ev;
    } m;
    if (n < 9 || memcmp(d, "LC02", 4)) return;
    const char *ch = (const char *)d + 8;
    size_t cl = strnlen(ch, n - 8);
    if (cl == n - 8) return;
    const uint8_t *pay = d + 8 + cl + 1;
    size_t plen = n - 8 - cl - 1;
    if (!strcmp(ch, p->ch_state) &&
        lag_wire_decode(LAG_WIRE_JOINT_STATE, pay, plen, LAG_WIRE_MAX_JOINTS, &m) == LAG_WIRE_OK) {
        if (p->heard && m.st.step > p->last_step) {
            int64_t dsteps = m.st.step - p->last_step;
            if (p->step_per_period == 0 || dsteps < p->step_per_period) p->step_per_period = dsteps;
            if (dsteps == p->step_per_period)
                add_err(fabs((double)(m.st.utime - p->last_utime - period_us)));
        }
        p->heard = true;
        p->states++;
        p->last_utime = m.st.utime;
        p->last_step = m.st.step;
    } else if (!strcmp(ch, p->ch_status) &&
               lag_wire_decode(LAG_WIRE_STATUS, pay, plen, LAG_WIRE_MAX_JOINTS, &m) == LAG_WIRE_OK) {
        p->overruns = m.status.overruns;
        if (p->stop_seen) p->stopped = true;
    } else if (!strcmp(ch, p->ch_event) &&
               lag_wire_decode(LAG_WIRE_EVENT, pay, plen, LAG_WIRE_MAX_JOINTS, &m) == LAG_WIRE_OK &&
               !strcmp(m.ev.kind, "stop")) {
        p->stop_seen = true;
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double pct(double q)
{
    if (g_nerr == 0) return NAN;
    size_t k = (size_t)ceil(q * (double)g_nerr);
    return g_err[k == 0 ? 0 : k - 1];
}

/* Reads until SECONDS after the first state, or every plant stopped. */
static void listen_all(int n, double seconds, int64_t period_us)
{
    int ep = epoll_create1(EPOLL_CLOEXEC);
    for (int i = 0; i < n; i++) {
        struct epoll_event ev = {.events = EPOLLIN, .data.ptr = &g_p[i]};
        epoll_ctl(ep, EPOLL_CTL_ADD, g_p[i].fd, &ev);
    }
    double first = 0, start = lag_clock_mono_s();
    uint8_t buf[65536];
    struct epoll_event evs[64];
    for (;;) {
        double now = lag_clock_mono_s();
        int stopped = 0;
        for (int i = 0; i < n; i++) stopped += g_p[i].stopped;
        if (stopped == n || (first > 0 && now > first + seconds) ||
            (first == 0 && now > start + seconds + 60))
            break;
        int k = epoll_wait(ep, evs, 64, 200);
        for (int j = 0; j < k; j++) {
            probe_plant *p = evs[j].data.ptr;
            ssize_t r;
            while ((r = recv(p->fd, buf, sizeof buf, 0)) > 0) {
                on_datagram(p, buf, (size_t)r, period_us);
                if (first == 0 && p->heard) first = lag_clock_mono_s();
            }
        }
    }
    close(ep);
}

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: lab_probe GROUP BASE N SECONDS PERIOD_US\n");
        return 2;
    }
    int base = atoi(argv[2]), n = atoi(argv[3]);
    double seconds = atof(argv[4]);
    int64_t period_us = atoll(argv[5]);
    if (n < 1 || n > NMAX || base < 1 || base + 2 * n > 65535) {
        fprintf(stderr, "lab_probe: N from 1 to %d, ports within 65535\n", NMAX);
        return 2;
    }
    for (int i = 0; i < n; i++) {
        snprintf(g_p[i].prefix, sizeof g_p[i].prefix, "P%03d", i);
        lag_bus_channel_name(g_p[i].ch_state, LAG_BUS_CHANNEL_LEN, g_p[i].prefix, LAG_BUS_STATE);
        lag_bus_channel_name(g_p[i].ch_status, LAG_BUS_CHANNEL_LEN, g_p[i].prefix, LAG_BUS_STATUS);
        lag_bus_channel_name(g_p[i].ch_event, LAG_BUS_CHANNEL_LEN, g_p[i].prefix, LAG_BUS_EVENT);
        g_p[i].fd = open_port(argv[1], base + 2 * i);
    }
    listen_all(n, seconds, period_us);
    int64_t states = 0, overruns = 0, worst = 0;
    int heard = 0, with = 0;
    for (int i = 0; i < n; i++) {
        heard += g_p[i].heard;
        states += g_p[i].states;
        overruns += g_p[i].overruns;
        with += g_p[i].overruns > 0;
        if (g_p[i].overruns > worst) worst = g_p[i].overruns;
    }
    qsort(g_err, g_nerr, sizeof *g_err, cmp_double);
    printf("plants %d heard %d states %lld overruns %lld (plants with overruns: %d, the most: "
           "%lld) period error p50 %.0f us p99 %.0f us max %.0f us (%zu periods)\n", n, heard,
           (long long)states, (long long)overruns, with, (long long)worst, pct(0.5), pct(0.99),
           g_nerr ? g_err[g_nerr - 1] : NAN, g_nerr);
    return 0;
}
