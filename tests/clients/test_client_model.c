/*
 * The client library's model dynamics (lag_client_model_mass, lag_client_model_bias),
 * through liblagsim_client.so as a controller links it, against the models written again
 * from their bodies' kinematics (tests/common/ref_models.h, tests/core/test_core.h): M(q)
 * as the Hessian of T in qd, and h(q, qd) = C qd + g as Lagrange's left side
 * d/dt(dL/dqd) - dL/dq at qdd = 0, by complex steps of T and U alone (no code of the core).
 *
 * One case per model of the core's table: 300 random physical parameter sets and states,
 * each made into a scene_t as the daemon publishes it (every parameter by name, the joints
 * in the model's order) and fed to a client (lag_client_feed); then the scene's model as a
 * stick whose floor lets it fly publishes it (model stick, joints x, phi, h: the flying
 * stick from end A); and the refusals: n not the model's, an unknown model, a parameter
 * missing or out of range, a NaN in q or qd, each LAG_CLIENT_ERR_ARG with a message.
 * Tolerance: 1e-13 of the size of the terms (M: max |M_ij|; h: |dM| |qd|^2 + the gravity
 * scale), as in tests/core/test_models.c: both sides are exact to the rounding of a few
 * dozen such terms, and a wrong coefficient shows as an O(1e-2..1) relative error.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lagsim/lagsim_scene_t.h"
#include "lagsim_client.h"
#include "test_core.h" /* the reference models, complex steps, lagsim_test.h */

#define CTXF "%s draw %d q=(%.6g %.6g %.6g) qd=(%.6g %.6g %.6g)"
#define CTXA info->name, it, q[0], q[1], n > 2 ? q[2] : 0.0, qd[0], qd[1], n > 2 ? qd[2] : 0.0

/* A scene of model `name` with md's parameters (the first np of them, by the names of
 * `info`, skipping parameter `skip`) and the joints `joints`, fed to c as the daemon's
 * <PREFIX>_SCENE of generation gen; returns the client's copy in sc. */
static void feed_scene(lag_client *c, lag_client_scene *sc, const char *name,
                       const lag_model_info *info, const lag_model *md, const char *skip,
                       int nj, const char *const *joints, int64_t gen)
{
    char *pn[LAG_MAX_PARAMS], *jn[LAG_MAX_DOF];
    double pv[LAG_MAX_PARAMS], zero[LAG_MAX_DOF] = {0};
    int8_t act[LAG_MAX_DOF] = {0}, off[LAG_MAX_DOF] = {0};
    int np = 0;
    for (int i = 0; i < info->np; i++) {
        if (skip && !strcmp(skip, info->param_names[i])) continue;
        pn[np] = (char *)info->param_names[i];
        pv[np++] = md->p[i];
    }
    for (int i = 0; i < nj; i++) jn[i] = (char *)joints[i];
    lagsim_scene_t s = {.utime = 1, .model = (char *)name, .prefix = "TMODEL",
                        .num_params = (int16_t)np, .param_name = pn, .param_value = pv,
                        .num_joints = (int16_t)nj, .joint_name = jn, .actuated = act,
                        .initial_q = zero, .initial_qd = zero, .dt = 0.001,
                        .control_period = 0.01, .integrator = "rk4", .mode = "lockstep",
                        .rate = 1.0, .command_timeout = 0.5, .effects = "", .limit_on = off,
                        .limit_lower = zero, .limit_upper = zero, .generation = gen};
    static unsigned char buf[8192];
    int len = lagsim_scene_t_encode(buf, 0, (int)sizeof buf, &s);
    ENSURE(len > 0);
    ENSURE(lag_client_feed(c, "TMODEL_SCENE", buf, (size_t)len) == LAG_CLIENT_OK);
    ENSURE(lag_client_latest_scene(c, sc) && lag_client_scene_generation(sc) == gen);
}

/* M and h of the client library against T and U at one (q, qd). */
static void check_draw(const lag_client_scene *sc, const lag_model *md, const lag_model_info *info,
                       int it, const double *q, const double *qd)
{
    const int n = md->nq;
    double M[9], h[3], Mt[9], dMt[27], ht[3], zero[3] = {0, 0, 0};
    char err[256];
    ENSUREF(lag_client_model_mass(sc, n, q, M, err, sizeof err) == LAG_CLIENT_OK, "%s", err);
    ENSUREF(lag_client_model_bias(sc, n, q, qd, h, err, sizeof err) == LAG_CLIENT_OK, "%s", err);
    tc_mass(md, q, Mt);
    tc_mass_deriv(md, q, dMt);
    tc_lagrange_lhs(md, q, qd, zero, ht); /* d/dt(dL/dqd) - dL/dq at qdd = 0: C qd + g */
    double sM = tc_maxabs(n * n, Mt), sdM = tc_maxabs(n * n * n, dMt) + sM;
    tc_bodies b;
    cplx qc[3], zc[3] = {0, 0, 0};
    tc_to_c(n, q, qc);
    tc_kinematics(md, qc, zc, &b);
    double sg = 0;
    for (int k = 0; k < b.nb; ++k) sg += b.mass[k] * tc_p(md, "g") * (1 + cabs(b.x[k]) + cabs(b.y[k]));
    double sh = sdM * tc_maxabs(n, qd) * tc_maxabs(n, qd) * n + sg;
    for (int i = 0; i < n * n; i++)
        ENSURE_NEAR(M[i], Mt[i], 1e-13 * sM, "M entry %d " CTXF, i, CTXA);
    for (int i = 0; i < n; i++) ENSURE_NEAR(h[i], ht[i], 1e-13 * sh, "h entry %d " CTXF, i, CTXA);
}

/* What a bad call gets: LAG_CLIENT_ERR_ARG and a message naming the trouble. */
static void check_refused(lag_result rc, const char *err, const char *want)
{
    ENSUREF(rc == LAG_CLIENT_ERR_ARG, "rc %d (%s), want LAG_CLIENT_ERR_ARG", (int)rc, err);
    ENSUREF(strstr(err, want) != NULL, "message '%s' does not say '%s'", err, want);
}

static void case_model(int kind)
{
    const lag_model_info *info = lag_model_info_get((lag_model_kind)kind);
    const int n = info->nq;
    char err[256];
    lag_client *c = lag_client_create("memq://", "TMODEL", err, sizeof err);
    lag_client_scene *sc = lag_client_scene_new();
    ENSUREF(c && sc, "%s", err);
    if (!c || !sc) return;
    lt_rng rng = {0x5eed0000u + (uint64_t)kind};
    lag_model md;
    int64_t gen = 1;
    double q[3] = {0}, qd[3] = {0};
    int it = 0;
    for (; it < 300; it++) {
        tc_random_model(&rng, (lag_model_kind)kind, &md);
        tc_random_state(&rng, &md, q, qd);
        feed_scene(c, sc, info->name, info, &md, NULL, n, info->joint_names, gen++);
        check_draw(sc, &md, info, it, q, qd);
    }

    /* refusals, with the last draw's scene */
    check_refused(lag_client_model_mass(sc, n + 1, q, (double[16]){0}, err, sizeof err), err,
                  "coordinates");
    double bad[3] = {q[0], NAN, q[2]};
    check_refused(lag_client_model_bias(sc, n, q, bad, (double[3]){0}, err, sizeof err), err, "qd[1]");
    check_refused(lag_client_model_mass(sc, n, bad, (double[9]){0}, err, sizeof err), err, "q[1]");
    check_refused(lag_client_model_mass(NULL, n, q, (double[9]){0}, err, sizeof err), err, "no scene");
    feed_scene(c, sc, info->name, info, &md, info->param_names[0], n, info->joint_names, gen++);
    check_refused(lag_client_model_mass(sc, n, q, (double[9]){0}, err, sizeof err), err,
                  info->param_names[0]);
    lag_model neg = md;
    neg.p[0] = -1.0; /* every model's first parameter is a mass: > 0 */
    feed_scene(c, sc, info->name, info, &neg, NULL, n, info->joint_names, gen++);
    check_refused(lag_client_model_bias(sc, n, q, qd, (double[3]){0}, err, sizeof err), err,
                  info->param_names[0]);
    feed_scene(c, sc, "no-such-model", info, &md, NULL, n, info->joint_names, gen++);
    check_refused(lag_client_model_mass(sc, n, q, (double[9]){0}, err, sizeof err), err,
                  "no-such-model");
    lag_client_scene_free(sc);
    lag_client_destroy(c);
}

/* A stick whose floor lets it fly publishes model stick with the flying stick's joints: its
 * dynamics are the flying stick's, h measured from end A (the reference's sigma = +1). */
static void case_stick_in_flight(int arg)
{
    (void)arg;
    const lag_model_info *stick = lag_model_info_get(LAG_MODEL_STICK);
    const lag_model_info *info = lag_model_info_get(LAG_MODEL_FLYING_STICK);
    char err[256];
    lag_client *c = lag_client_create("memq://", "TMODEL", err, sizeof err);
    lag_client_scene *sc = lag_client_scene_new();
    ENSUREF(c && sc, "%s", err);
    if (!c || !sc) return;
    ENSURE(info->nq == 3 && stick->nq == 2);
    lt_rng rng = {0xf1f1u};
    lag_model md;
    double q[3] = {0}, qd[3] = {0};
    for (int it = 0; it < 300; it++) {
        tc_random_model(&rng, LAG_MODEL_FLYING_STICK, &md); /* p[LAG_FSTICK_END] = 0: end A */
        ENSURE(md.p[LAG_FSTICK_END] == 0.0);
        tc_random_state(&rng, &md, q, qd);
        feed_scene(c, sc, stick->name, stick, &md, NULL, 3, info->joint_names, it + 1);
        check_draw(sc, &md, info, it, q, qd);
    }
    lag_client_scene_free(sc);
    lag_client_destroy(c);
}

int main(int argc, char **argv)
{
    static char names[LAG_MODEL_COUNT][64];
    lt_cases cs = {0};
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        snprintf(names[k], sizeof names[k], "%s", lag_model_info_get((lag_model_kind)k)->name);
        for (char *p = names[k]; *p; p++) *p = *p == '-' ? '_' : *p;
        lt_add(&cs, names[k], case_model, k, 0);
    }
    lt_add(&cs, "stick_in_flight", case_stick_in_flight, 0, 0);
    return lt_main(argc, argv, cs.c, cs.n);
}
