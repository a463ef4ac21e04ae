/*
 * Unit test of the C client library (clients/lagsim_client.c) over real LCM on loopback
 * (default URL, ttl=0) with a channel prefix unique to this process. A second lcm_t
 * plays the daemon: it publishes odd and valid messages and decodes what the client
 * sends. Checks: odd messages (undecodable, too many joints, over-long names) are
 * dropped and counted, never returned; valid ones are copied exactly; commands and
 * control requests arrive as sent; bad arguments are refused with a message; the scene
 * wait sends DESCRIBE requests and times out cleanly when nobody answers.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim_client.h"

static int failures = 0;
#define ENSURE(cond)                                                                   \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: ENSURE(%s) failed\n", __FILE__, __LINE__, #cond);  \
            failures++;                                                                \
        }                                                                              \
    } while (0)

static int describes = 0, commands = 0;
static lagsim_joint_command_t last_cmd;
static char last_names[4][32];
static double last_effort[4];

static void on_control(const lcm_recv_buf_t *rbuf, const char *ch, void *u)
{
    (void)ch; (void)u;
    lagsim_control_t m;
    if (lagsim_control_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) return;
    if (m.request == LAGSIM_CONTROL_T_DESCRIBE) describes++;
    lagsim_control_t_decode_cleanup(&m);
}

static void on_command(const lcm_recv_buf_t *rbuf, const char *ch, void *u)
{
    (void)ch; (void)u;
    lagsim_joint_command_t m;
    if (lagsim_joint_command_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) return;
    commands++;
    last_cmd = m;
    for (int i = 0; i < m.num_joints && i < 4; i++) {
        snprintf(last_names[i], sizeof last_names[i], "%s", m.name[i]);
        last_effort[i] = m.effort[i];
    }
    lagsim_joint_command_t_decode_cleanup(&m);
}

/* Pumps both LCM instances for about `ms` milliseconds. */
static void pump(lcm_t *peer, lag_client *c, int ms)
{
    double end = lag_client_now() + ms * 1e-3;
    while (lag_client_now() < end) {
        lcm_handle_timeout(peer, 1);
        lag_client_handle(c, 1);
    }
}

static void publish_state(lcm_t *peer, const char *ch, int n, const char *long_name, double t)
{
    char *names[20];
    double pos[20], vel[20], eff[20];
    for (int i = 0; i < n; i++) {
        names[i] = (char *)(i == 0 && long_name ? long_name : (i == 0 ? "theta0" : "x"));
        pos[i] = 0.1 * (i + 1);
        vel[i] = -0.2 * (i + 1);
        eff[i] = 3.0 * i;
    }
    lagsim_joint_state_t m = {.utime = 42, .sim_time = t, .step = (int64_t)(t * 1000),
                              .num_joints = (int16_t)n, .name = names, .position = pos,
                              .velocity = vel, .effort = eff};
    lagsim_joint_state_t_publish(peer, ch, &m);
}

int main(void)
{
    char prefix[64], ch[128], err[256];
    snprintf(prefix, sizeof prefix, "CLTCLIENT_%d", (int)getpid());

    ENSURE(lag_client_create(NULL, "", err, sizeof err) == NULL && err[0] != '\0');
    ENSURE(lag_client_create("nosuchprovider://x", prefix, err, sizeof err) == NULL);
    ENSURE(strlen(err) > 0);

    lag_client *c = lag_client_create(NULL, prefix, err, sizeof err);
    lcm_t *peer = lcm_create(NULL);
    ENSURE(c != NULL && peer != NULL);
    if (!c || !peer) return 1;
    snprintf(ch, sizeof ch, "%s_CONTROL", prefix);
    lcm_subscribe(peer, ch, on_control, NULL);
    snprintf(ch, sizeof ch, "%s_COMMAND", prefix);
    lcm_subscribe(peer, ch, on_command, NULL);

    /* nobody answers DESCRIBE: timeout, requests were sent, message names the prefix */
    lag_client_scene sc;
    ENSURE(lag_client_wait_scene(c, 0.6, &sc) == LAG_CLIENT_TIMEOUT);
    ENSURE(strstr(lag_client_errmsg(c), prefix) != NULL);
    pump(peer, c, 50);
    ENSURE(describes >= 2); /* at once and every 0.25 s */

    /* odd states, then a valid one */
    snprintf(ch, sizeof ch, "%s_STATE", prefix);
    const char junk[] = "not an LCM message at all";
    lcm_publish(peer, ch, junk, sizeof junk);
    publish_state(peer, ch, 20, NULL, 1.0); /* too many joints */
    char longname[100];
    memset(longname, 'a', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    publish_state(peer, ch, 3, longname, 2.0); /* name does not fit */
    publish_state(peer, ch, 3, NULL, 3.0);     /* valid */
    lag_client_state st;
    ENSURE(lag_client_wait_state(c, 2.0, &st) == 1);
    pump(peer, c, 50);
    ENSURE(st.sim_time == 3.0 && st.step == 3000 && st.num_joints == 3 && st.utime == 42);
    ENSURE(strcmp(st.name[0], "theta0") == 0 && lag_client_state_joint(&st, "theta0") == 0);
    ENSURE(st.position[2] == 0.1 * 3 && st.velocity[1] == -0.2 * 2 && st.effort[2] == 6.0);
    lag_client_counters cnt;
    lag_client_get_counters(c, &cnt);
    ENSURE(cnt.states == 1 && cnt.dropped == 3);
    /* no new state: wait_state times out, latest_state still has the valid one */
    ENSURE(lag_client_wait_state(c, 0.1, &st) == 0);
    ENSURE(lag_client_latest_state(c, &st) && st.sim_time == 3.0);

    /* commands */
    const char *names[2] = {"q1", "q2"};
    double eff[2] = {1.5, -2.25};
    ENSURE(lag_client_send_command(c, 3.0, 2, names, eff) == LAG_CLIENT_OK);
    pump(peer, c, 100);
    ENSURE(commands == 1 && last_cmd.sim_time == 3.0 && last_cmd.num_joints == 2);
    ENSURE(strcmp(last_names[1], "q2") == 0 && last_effort[0] == 1.5 && last_effort[1] == -2.25);
    ENSURE(lag_client_send_command(c, 3.0, -1, names, eff) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_send_command(c, 3.0, 2, NULL, eff) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_step(c, 0) == LAG_CLIENT_ERR_ARG);
    ENSURE(strstr(lag_client_errmsg(c), "count") != NULL);
    ENSURE(lag_client_reset_to(c, 0, eff, eff) == LAG_CLIENT_ERR_ARG);
    ENSURE(lag_client_pause(c) == LAG_CLIENT_OK && lag_client_resume(c) == LAG_CLIENT_OK);

    /* a scene description */
    snprintf(ch, sizeof ch, "%s_SCENE", prefix);
    char *pn[2] = {"m1", "g"}, *jn[2] = {"q1", "q2"};
    double pv[2] = {2.0, 9.81}, iq[2] = {0.0, 0.5}, iqd[2] = {0, 0};
    int8_t act[2] = {1, 0}, lim_on[2] = {0, 0};
    double lim[2] = {0, 0};
    lagsim_scene_t s = {.utime = 1, .model = "manipulator", .prefix = prefix, .num_params = 2,
                        .param_name = pn, .param_value = pv, .num_joints = 2,
                        .joint_name = jn, .actuated = act, .initial_q = iq,
                        .initial_qd = iqd, .dt = 0.001, .control_period = 0.01,
                        .integrator = "rk4", .mode = "lockstep", .rate = 1.0,
                        .command_timeout = 0.5, .effects = "", .limit_on = lim_on,
                        .limit_lower = lim, .limit_upper = lim};
    lagsim_scene_t_publish(peer, ch, &s);
    ENSURE(lag_client_wait_scene(c, 2.0, &sc) == LAG_CLIENT_OK);
    ENSURE(strcmp(sc.model, "manipulator") == 0 && strcmp(sc.mode, "lockstep") == 0);
    ENSURE(lag_client_scene_param(&sc, "g") == 9.81 && isnan(lag_client_scene_param(&sc, "zz")));
    ENSURE(lag_client_scene_joint(&sc, "q2") == 1 && sc.actuated[0] && !sc.actuated[1]);
    ENSURE(sc.initial_q[1] == 0.5 && sc.control_period == 0.01);

    lag_client_destroy(c);
    lcm_destroy(peer);
    if (failures) {
        fprintf(stderr, "test_client: %d failure(s)\n", failures);
        return 1;
    }
    printf("test_client: all passed\n");
    return 0;
}
