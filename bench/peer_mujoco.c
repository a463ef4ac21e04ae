/*
 * MuJoCo peer: the DIPC and the manipulator as MJCF with the same masses, inertias and
 * gravity as the lagsim model; contacts off, armature and damping 0; run with MuJoCo's
 * Euler (semi-implicit), RK4 and implicit integrators at the same dt, with the same
 * piecewise-constant generalized forces (qfrc_applied) held over each period.
 *
 * Coordinates. MuJoCo works in x-z with z up; the lagsim models are planar in x-y with
 * y up, so lagsim's y is MuJoCo's z.
 *  - DIPC: cart = slide along x; rod 1 = hinge about +y at the cart, at angle 0 pointing
 *    up (+z). A rotation by a about +y takes +z to (sin a, 0, cos a): a positive angle
 *    tips the rod toward +x, as lagsim's theta1. MuJoCo's second hinge is relative:
 *    theta2 = hinge1 + hinge2.
 *  - Manipulator: arm 1 = hinge about -y at the origin, pointing along +x at angle 0;
 *    a rotation by a about -y takes +x to (cos a, 0, sin a), so hinge = q1 from the
 *    horizontal, positive up. Arm 2 = slide along arm 1's x axis, its centre of mass at
 *    the slide position: slide = q2.
 * Inertias are explicit <inertial> elements of uniform rods (about the rod's own axis a
 * tiny value, which never enters: nothing rotates about it).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "bench.h"

static mjModel *models[LAG_MODEL_COUNT];
static mjData *datas[LAG_MODEL_COUNT];
static lag_model loaded_params[LAG_MODEL_COUNT];

const char *bench_mujoco_version(void)
{
    static char buf[32];
    int v = mj_version();
    snprintf(buf, sizeof buf, "%d.%d.%d", v / 100, (v / 10) % 10, v % 10);
    return buf;
}

/* MJCF text of the model. OUT: buf */
static int mjcf(const lag_model *m, char *buf, size_t len)
{
    const double *p = m->p;
    if (m->kind == LAG_MODEL_DIPC) {
        double l1 = p[LAG_DIPC_L1], l2 = p[LAG_DIPC_L2];
        double I1 = p[LAG_DIPC_I1], I2 = p[LAG_DIPC_I2];
        return snprintf(buf, len,
            "<mujoco model=\"dipc\">\n"
            "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
            "  <option timestep=\"0.001\" gravity=\"0 0 %.17g\" integrator=\"RK4\">\n"
            "    <flag contact=\"disable\"/>\n"
            "  </option>\n"
            "  <default><joint armature=\"0\" damping=\"0\" limited=\"false\"/></default>\n"
            "  <worldbody>\n"
            "    <body name=\"cart\" pos=\"0 0 0\">\n"
            "      <joint name=\"slider\" type=\"slide\" axis=\"1 0 0\"/>\n"
            "      <inertial pos=\"0 0 0\" mass=\"%.17g\" diaginertia=\"1e-3 1e-3 1e-3\"/>\n"
            "      <body name=\"rod1\" pos=\"0 0 %.17g\">\n"
            "        <joint name=\"hinge1\" type=\"hinge\" axis=\"0 1 0\"/>\n"
            "        <inertial pos=\"0 0 %.17g\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>\n"
            "        <body name=\"rod2\" pos=\"0 0 %.17g\">\n"
            "          <joint name=\"hinge2\" type=\"hinge\" axis=\"0 1 0\"/>\n"
            "          <inertial pos=\"0 0 %.17g\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>\n"
            "        </body>\n"
            "      </body>\n"
            "    </body>\n"
            "  </worldbody>\n"
            "</mujoco>\n",
            -p[LAG_DIPC_G], p[LAG_DIPC_M0], p[LAG_DIPC_H0],
            l1 / 2, p[LAG_DIPC_M1], I1, I1, I1 * 1e-3,
            l1,
            l2 / 2, p[LAG_DIPC_M2], I2, I2, I2 * 1e-3);
    }
    if (m->kind == LAG_MODEL_MANIPULATOR) {
        double I1 = p[LAG_MANIP_I1], I2 = p[LAG_MANIP_I2];
        return snprintf(buf, len,
            "<mujoco model=\"manipulator\">\n"
            "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
            "  <option timestep=\"0.001\" gravity=\"0 0 %.17g\" integrator=\"RK4\">\n"
            "    <flag contact=\"disable\"/>\n"
            "  </option>\n"
            "  <default><joint armature=\"0\" damping=\"0\" limited=\"false\"/></default>\n"
            "  <worldbody>\n"
            "    <body name=\"arm1\" pos=\"0 0 0\">\n"
            "      <joint name=\"q1\" type=\"hinge\" axis=\"0 -1 0\"/>\n"
            "      <inertial pos=\"%.17g 0 0\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>\n"
            "      <body name=\"arm2\" pos=\"0 0 0\">\n"
            "        <joint name=\"q2\" type=\"slide\" axis=\"1 0 0\"/>\n"
            "        <inertial pos=\"0 0 0\" mass=\"%.17g\" diaginertia=\"%.17g %.17g %.17g\"/>\n"
            "      </body>\n"
            "    </body>\n"
            "  </worldbody>\n"
            "</mujoco>\n",
            -p[LAG_MANIP_G], p[LAG_MANIP_L1], p[LAG_MANIP_M1], I1 * 1e-3, I1, I1,
            p[LAG_MANIP_M2], I2 * 1e-3, I2, I2);
    }
    return -1;
}

/* Compiles (once per parameter set) the model of this kind. */
static int load(const lag_model *m)
{
    int k = m->kind;
    if (models[k] && memcmp(&loaded_params[k], m, sizeof *m) == 0) return 0;
    if (models[k]) {
        mj_deleteData(datas[k]);
        mj_deleteModel(models[k]);
        models[k] = NULL;
    }
    char xml[4096];
    int n = mjcf(m, xml, sizeof xml);
    if (n < 0 || n >= (int)sizeof xml) return -1;
    mjVFS *vfs = malloc(sizeof *vfs); /* ~2 MB: not on the stack */
    if (!vfs) return -1;
    mj_defaultVFS(vfs);
    if (mj_makeEmptyFileVFS(vfs, "model.xml", n) != 0) {
        free(vfs);
        return -1;
    }
    memcpy(vfs->filedata[0], xml, (size_t)n);
    char err[1000] = "";
    models[k] = mj_loadXML("model.xml", vfs, err, sizeof err);
    mj_deleteVFS(vfs);
    free(vfs);
    if (!models[k]) {
        fprintf(stderr, "bench: mujoco: %s\n", err);
        return -1;
    }
    datas[k] = mj_makeData(models[k]);
    loaded_params[k] = *m;
    return 0;
}

/* lagsim (q, qd) -> MuJoCo (qpos, qvel) and back. */
static void to_mj(const lag_model *m, const double *q, const double *qd, mjData *d)
{
    if (m->kind == LAG_MODEL_DIPC) {
        d->qpos[0] = q[0]; d->qpos[1] = q[1]; d->qpos[2] = q[2] - q[1];
        d->qvel[0] = qd[0]; d->qvel[1] = qd[1]; d->qvel[2] = qd[2] - qd[1];
    } else {
        d->qpos[0] = q[0]; d->qpos[1] = q[1];
        d->qvel[0] = qd[0]; d->qvel[1] = qd[1];
    }
}

static void from_mj(const lag_model *m, const mjData *d, double *q, double *qd)
{
    if (m->kind == LAG_MODEL_DIPC) {
        q[0] = d->qpos[0]; q[1] = d->qpos[1]; q[2] = d->qpos[1] + d->qpos[2];
        qd[0] = d->qvel[0]; qd[1] = d->qvel[1]; qd[2] = d->qvel[1] + d->qvel[2];
    } else {
        q[0] = d->qpos[0]; q[1] = d->qpos[1];
        qd[0] = d->qvel[0]; qd[1] = d->qvel[1];
    }
}

int bench_run_mujoco(const bench_scene *sc, const bench_config *c, bench_samples *out,
                     int64_t *rhs, int64_t *steps)
{
    *rhs = 0;
    *steps = 0;
    if (sc->model.kind != LAG_MODEL_DIPC && sc->model.kind != LAG_MODEL_MANIPULATOR)
        return -2;
    if (load(&sc->model) != 0) return -3;
    mjModel *mm = models[sc->model.kind];
    mjData *d = datas[sc->model.kind];
    mm->opt.timestep = c->dt;
    mm->opt.integrator = c->method == BENCH_MJ_EULER ? mjINT_EULER
                       : c->method == BENCH_MJ_RK4   ? mjINT_RK4
                                                     : mjINT_IMPLICIT;
    mj_resetData(mm, d);
    to_mj(&sc->model, sc->q0, sc->qd0, d);
    const int nq = sc->model.nq;
    const long per = lround(sc->period / c->dt);
    const int np = bench_periods(sc);
    memcpy(out->q, sc->q0, sizeof(double) * (size_t)nq);
    memcpy(out->qd, sc->qd0, sizeof(double) * (size_t)nq);
    double tau[LAG_MAX_DOF] = {0};
    for (int k = 0; k < np; k++) {
        if (sc->input) {
            sc->input(&sc->model, k * sc->period, tau);
            /* Generalized forces: lagsim's inputs are on coordinates MuJoCo shares
             * (DIPC: the cart slide only; manipulator: hinge and slide). */
            for (int i = 0; i < nq; i++) d->qfrc_applied[i] = tau[i];
        }
        for (long s = 0; s < per; s++) mj_step(mm, d);
        double *q = out->q + (size_t)(k + 1) * LAG_MAX_DOF;
        double *qd = out->qd + (size_t)(k + 1) * LAG_MAX_DOF;
        from_mj(&sc->model, d, q, qd);
        for (int i = 0; i < nq; i++)
            if (!isfinite(q[i]) || !isfinite(qd[i]) || fabs(q[i]) > 1e6 || fabs(qd[i]) > 1e6)
                return -4;
    }
    *steps = (int64_t)np * per;
    /* Forward-dynamics evaluations: RK4 evaluates 4 per step, Euler and implicit 1. */
    *rhs = *steps * (c->method == BENCH_MJ_RK4 ? 4 : 1);
    return 0;
}
