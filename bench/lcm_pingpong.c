/*
 * The bus's own limit for a lockstep loop: two processes that do nothing but answer each
 * other over LCM (udpm, loopback), as lagsimd and a controller do once per control
 * period. Prints the round trips per second.
 *
 *   lcm_pingpong [CYCLES] [URL]      (default 20000 cycles, a port of its own)
 */
#include <lcm/lcm.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include "lagsim_clock.h"
#include <unistd.h>

static int got;
static void on_msg(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)rbuf, (void)channel, (void)user;
    got = 1;
}

static double now_s(void)
{
    return lag_clock_mono_s();
}

int main(int argc, char **argv)
{
    long cycles = argc > 1 ? atol(argv[1]) : 20000;
    char url[160];
    snprintf(url, sizeof url, "%s", argc > 2 ? argv[2] : "");
    if (!url[0])
        snprintf(url, sizeof url, "udpm://239.255.76.67:%d?ttl=0",
                 40000 + 2 * (int)(getpid() % 9000));
    uint8_t payload[200] = {0}; /* about a joint_state_t of the DIPC */
    pid_t pid = fork();
    if (pid == 0) { /* the answering side */
        lcm_t *l = lcm_create(url);
        if (!l) _exit(1);
        lcm_subscribe(l, "BENCH_PING", on_msg, NULL);
        for (;;) {
            got = 0;
            if (lcm_handle_timeout(l, 2000) <= 0) break;
            if (got) lcm_publish(l, "BENCH_PONG", payload, 64);
        }
        lcm_destroy(l);
        _exit(0);
    }
    lcm_t *l = lcm_create(url);
    if (!l) return 1;
    lcm_subscribe(l, "BENCH_PONG", on_msg, NULL);
    usleep(200000); /* the other side subscribed */
    long done = 0;
    double t0 = now_s();
    for (long i = 0; i < cycles; i++) {
        got = 0;
        lcm_publish(l, "BENCH_PING", payload, sizeof payload);
        while (!got) /* a lost datagram is sent again, as lockstep's retry does */
            if (lcm_handle_timeout(l, 20) == 0)
                lcm_publish(l, "BENCH_PING", payload, sizeof payload);
        done++;
    }
    double t = now_s() - t0;
    printf("lcm_pingpong: %ld round trips in %.3f s: %.0f per second\n", done, t, done / t);
    lcm_destroy(l);
    kill(pid, SIGTERM);
    waitpid(pid, NULL, 0);
    return 0;
}
