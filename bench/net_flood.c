/*
 * net_flood: what a command flood does to a controller's states (bench/net_flood.sh).
 *
 *   net_flood flood URL CHANNEL SECONDS
 *       publishes valid, empty joint_command_t messages (they change no effort) on CHANNEL
 *       of URL as fast as it can for SECONDS; prints how many
 *   net_flood listen URL PREFIX SECONDS
 *       subscribes to <PREFIX>_STATE on URL, as a controller does, for SECONDS; prints the
 *       states received, the steps they span, how many steps are missing and the longest
 *       gap between two states received (wall ms)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lagsim_clock.h"

#include <lcm/lcm.h>
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim_bus.h"
#include "lagsim_wire.h"

static double now_s(void)
{
    return lag_clock_mono_s();
}

typedef struct counts {
    long states, missing, tpp;
    long long first_step, last_step;
    double last_t, max_gap;
} counts;

static void on_state(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    counts *c = user;
    lag_wire_joint_state m;
    if (lag_wire_decode_joint_state(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK)
        return;
    double t = now_s();
    if (c->states > 0) {
        long long d = m.step - c->last_step;
        if (c->tpp == 0 && d > 0) c->tpp = (long)d;
        if (c->tpp > 0 && d > c->tpp) c->missing += (long)(d / c->tpp - 1);
        if (t - c->last_t > c->max_gap) c->max_gap = t - c->last_t;
    } else {
        c->first_step = m.step;
    }
    c->states++;
    c->last_step = m.step;
    c->last_t = t;
}

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: net_flood flood URL CHANNEL SECONDS | listen URL PREFIX SECONDS\n");
        return 2;
    }
    double secs = atof(argv[4]);
    lcm_t *lcm = lcm_create(argv[2]);
    if (!lcm) {
        fprintf(stderr, "net_flood: cannot create LCM on %s\n", argv[2]);
        return 1;
    }
    if (!strcmp(argv[1], "flood")) {
        lagsim_joint_command_t hb = {0, 0.0, 0, NULL, NULL};
        long sent = 0;
        for (double end = now_s() + secs; now_s() < end; sent++)
            lagsim_joint_command_t_publish(lcm, argv[3], &hb);
        printf("flood: %ld messages in %g s on %s of %s\n", sent, secs, argv[3], argv[2]);
    } else if (!strcmp(argv[1], "listen")) {
        char ch[96];
        lag_bus_channel_name(ch, sizeof ch, argv[3], LAG_BUS_STATE);
        counts c = {0};
        lcm_subscription_t *sub = lcm_subscribe(lcm, ch, on_state, &c);
        lcm_subscription_set_queue_capacity(sub, 1000);
        for (double end = now_s() + secs, left; (left = end - now_s()) > 0;)
            lcm_handle_timeout(lcm, (int)(left * 1000) + 1);
        long spanned = c.tpp > 0 ? (long)((c.last_step - c.first_step) / c.tpp) + 1 : c.states;
        printf("listen: %ld states of %ld (%.1f %%), %ld missing, longest gap %.1f ms\n",
               c.states, spanned, spanned ? 100.0 * (double)c.states / (double)spanned : 0.0,
               c.missing, c.max_gap * 1e3);
    } else {
        fprintf(stderr, "net_flood: flood or listen, not %s\n", argv[1]);
        return 2;
    }
    lcm_destroy(lcm);
    return 0;
}
