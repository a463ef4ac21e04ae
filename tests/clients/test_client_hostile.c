/*
 * Forged messages on a controller's channels must be dropped and counted by the C client
 * library, never crash it, never leak, never be returned. Real LCM on loopback (default
 * URL, ttl=0, a prefix unique to this process); a second lcm_t publishes raw payloads
 * with the right fingerprints and hostile lengths:
 *   - a 145-byte joint_state_t whose first name has length -1;
 *   - a joint_state_t whose first name fills its length without a NUL;
 *   - a joint_state_t claiming 32767 joints, cut short;
 *   - a status_t whose integrator string has length -1;
 *   - an event_t whose kind has length 0x7fffffff;
 *   - a scene_t claiming 32767 parameters, cut short;
 * then one valid state, which must arrive. Uses only functions whose meaning every
 * version of the library shares (create, handle, counters, destroy).
 */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"
#include "lagsim_client.h"
#include "lagsim_test.h"

static size_t put(uint8_t *b, size_t p, uint64_t v, int n)
{
    for (int i = n - 1; i >= 0; i--) b[p++] = (uint8_t)(v >> (8 * i));
    return p;
}

/* A joint_state_t head: fingerprint, utime, sim_time, step, num_joints. */
static size_t state_head(uint8_t *b, uint16_t n)
{
    size_t p = put(b, 0, (uint64_t)__lagsim_joint_state_t_get_hash(), 8);
    p = put(b, p, 0, 8);
    p = put(b, p, 0, 8);
    p = put(b, p, 0, 8);
    return put(b, p, n, 2);
}

static void case_hostile_messages(int arg)
{
    (void)arg;
    char prefix[64], ch[128], err[256];
    snprintf(prefix, sizeof prefix, "CLHOSTILE_%d", (int)getpid());
    lt_private_lcm(); /* the default URL: a port pair of this process's own */
    lag_client *c = lag_client_create(NULL, prefix, err, sizeof err);
    lcm_t *peer = lcm_create(NULL);
    ENSURE(c != NULL && peer != NULL);
    if (!c || !peer) return;

    uint8_t b[512];
    size_t p;
    int sent = 0;
    snprintf(ch, sizeof ch, "%s_STATE", prefix);
    /* name length -1, the payload padded to 145 bytes */
    p = state_head(b, 3);
    p = put(b, p, 0xffffffffu, 4);
    memset(b + p, 'A', 145 - p);
    lcm_publish(peer, ch, b, 145), sent++;
    /* "theta0" without its NUL, then two good names and nine doubles */
    p = state_head(b, 3);
    p = put(b, p, 6, 4);
    memcpy(b + p, "theta0", 6), p += 6;
    p = put(b, p, 7, 4);
    memcpy(b + p, "theta1", 7), p += 7;
    p = put(b, p, 7, 4);
    memcpy(b + p, "theta2", 7), p += 7;
    memset(b + p, 0, 72), p += 72;
    lcm_publish(peer, ch, b, (unsigned)p), sent++;
    /* 32767 joints, cut short */
    p = state_head(b, 32767);
    p = put(b, p, 7, 4);
    memcpy(b + p, "theta0", 7), p += 7;
    lcm_publish(peer, ch, b, (unsigned)p), sent++;

    snprintf(ch, sizeof ch, "%s_STATUS", prefix);
    p = put(b, 0, (uint64_t)__lagsim_status_t_get_hash(), 8);
    memset(b + p, 0, 72), p += 72; /* utime .. energy */
    p = put(b, p, 0xffffffffu, 4);
    memset(b + p, 'B', 100), p += 100;
    lcm_publish(peer, ch, b, (unsigned)p), sent++;

    snprintf(ch, sizeof ch, "%s_EVENT", prefix);
    p = put(b, 0, (uint64_t)__lagsim_event_t_get_hash(), 8);
    memset(b + p, 0, 24), p += 24;
    p = put(b, p, 0x7fffffffu, 4);
    memset(b + p, 'C', 40), p += 40;
    lcm_publish(peer, ch, b, (unsigned)p), sent++;

    snprintf(ch, sizeof ch, "%s_SCENE", prefix);
    p = put(b, 0, (uint64_t)__lagsim_scene_t_get_hash(), 8);
    p = put(b, p, 0, 8);
    p = put(b, p, 2, 4);
    memcpy(b + p, "m", 2), p += 2;
    p = put(b, p, 2, 4);
    memcpy(b + p, "P", 2), p += 2;
    p = put(b, p, 32767, 2);
    p = put(b, p, 3, 4);
    memcpy(b + p, "m0", 3), p += 3;
    lcm_publish(peer, ch, b, (unsigned)p), sent++;

    /* then a valid state */
    snprintf(ch, sizeof ch, "%s_STATE", prefix);
    char *names[3] = {"theta0", "theta1", "theta2"};
    double z[3] = {0.5, 0, 0};
    lagsim_joint_state_t m = {1, 0.01, 10, 3, names, z, z, z};
    lagsim_joint_state_t_publish(peer, ch, &m);

    lag_client_counters cnt = {0};
    for (int i = 0; i < 400 && cnt.states + cnt.dropped < sent + 1; i++) {
        lag_client_handle(c, 5);
        lag_client_get_counters(c, &cnt, sizeof cnt);
    }
    printf("test_client_hostile: %lld dropped, %lld states kept\n", (long long)cnt.dropped,
           (long long)cnt.states);
    ENSURE(cnt.dropped == sent);
    ENSURE(cnt.states == 1 && cnt.statuses == 0 && cnt.events == 0 && cnt.scenes == 0);
    lag_client_destroy(c);
    lcm_destroy(peer);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"hostile_messages", case_hostile_messages, 0, 0}};
    return lt_main(argc, argv, cases, 1);
}
