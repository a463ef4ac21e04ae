/*
 * Models against an independent computation from T and U.
 *
 * For each model, at NSTATES random states with random parameters (seeded), the core's
 * M, dM/dq, C, g, bias, kinetic and potential energy and forward dynamics are compared
 * with the same quantities derived here from the body kinematics (tests/common/ref_models.h) by complex steps
 * (see test_core.h), and for the stick and the manipulator with the course assignment's closed forms.
 *
 * Usage: test_core_models [--list | info | MODEL | assignment_dipc]   (no argument: all)
 */
#include "test_core.h"
#include "core_internal.h" /* the model table itself */

#define NSTATES 300

static const char *kname(lag_model_kind k) { return lag_model_info_get(k)->name; }

/* Prints the state of a failing check (printf-style context of ENSURE_NEAR). */
#define CTXF "%s state %d q=(%.6g %.6g %.6g) qd=(%.6g %.6g %.6g)"
#define CTXA kname(md.kind), it, q[0], q[1], md.nq > 2 ? q[2] : 0.0, qd[0], qd[1], \
             md.nq > 2 ? qd[2] : 0.0

/* v_c written by hand in test_core.h equals d r_c/dt, taken by a complex step of the
 * positions along qd: r(q + i h qd) = r(q) + i h J(q) qd + O(h^2). Exact to rounding,
 * so the tolerance is 1e-14 of the velocity scale |qd| (max(l, |q|) ~ 1). */
static void check_kinematics(const lag_model *mdp, int it, const double *q, const double *qd)
{
    lag_model md = *mdp;
    int n = md.nq;
    cplx qc[3], qdc[3], zero[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
        qc[i] = CMPLX(q[i], TC_CSTEP * qd[i]);
        qdc[i] = qd[i];
    }
    tc_bodies bstep, bhand;
    tc_kinematics(&md, qc, zero, &bstep);
    cplx qr[3];
    tc_to_c(n, q, qr);
    tc_kinematics(&md, qr, qdc, &bhand);
    double vs = 10 * (1 + tc_maxabs(n, qd)) * (1 + tc_maxabs(n, q));
    for (int b = 0; b < bhand.nb; ++b) {
        ENSURE_NEAR(creal(bhand.vx[b]), cimag(bstep.x[b]) / TC_CSTEP, 1e-14 * vs, "vx body %d " CTXF, b, CTXA);
        ENSURE_NEAR(creal(bhand.vy[b]), cimag(bstep.y[b]) / TC_CSTEP, 1e-14 * vs, "vy body %d " CTXF, b, CTXA);
    }
}

/* The course assignment's closed forms (TTK4130 assignment 8). */
static void check_assignment(const lag_model *mdp, int it, const double *q, const double *qd,
                       const double *qdd, const double *Ml, const double *Cl, const double *gl,
                       const double *hl)
{
    lag_model md = *mdp;
    int n = md.nq;
    double lhs[3];
    tc_matvec(n, Ml, qdd, lhs);
    for (int i = 0; i < n; ++i) lhs[i] += hl[i];
    if (md.kind == LAG_MODEL_STICK) {
        /* Problem 1 (d): d/dt(dL/dx_dot) - dL/dx = m x_ddot, and
         * (m l^2/4 cos^2 phi + I) phi_ddot - m l^2/4 phi_dot^2 cos phi sin phi
         *    + m g l/2 cos phi. Rounding of a handful of O(scale) terms: 1e-13. */
        double m = md.p[LAG_STICK_M], l = md.p[LAG_STICK_L], Iz = md.p[LAG_STICK_I],
               g = md.p[LAG_STICK_G];
        double c = cos(q[1]), s = sin(q[1]);
        double e0 = m * qdd[0];
        double e1 = (m * l * l / 4 * c * c + Iz) * qdd[1] - m * l * l / 4 * qd[1] * qd[1] * c * s +
                    m * g * l / 2 * c;
        double sc = fabs(m * qdd[0]) + fabs((m * l * l / 4 + Iz) * qdd[1]) +
                    m * l * l / 4 * qd[1] * qd[1] + m * g * l;
        ENSURE_NEAR(lhs[0], e0, 1e-13 * sc, "assignment stick (d) x " CTXF, CTXA);
        ENSURE_NEAR(lhs[1], e1, 1e-13 * sc, "assignment stick (d) phi " CTXF, CTXA);
    } else if (md.kind == LAG_MODEL_MANIPULATOR) {
        /* Problem 2: M (3), C (5), g(q) of part (d). */
        double m1 = md.p[LAG_MANIP_M1], m2 = md.p[LAG_MANIP_M2], l1 = md.p[LAG_MANIP_L1],
               I1 = md.p[LAG_MANIP_I1], I2 = md.p[LAG_MANIP_I2], g = md.p[LAG_MANIP_G];
        double M[4] = {m1 * l1 * l1 + I1 + I2 + m2 * q[1] * q[1], 0, 0, m2};
        double C[4] = {m2 * q[1] * qd[1], m2 * q[1] * qd[0], -m2 * q[1] * qd[0], 0};
        double G[2] = {(m1 * l1 + m2 * q[1]) * g * cos(q[0]), m2 * g * sin(q[0])};
        double sM = tc_maxabs(4, M), sC = tc_maxabs(4, C) + 1e-300, sG = (m1 * l1 + m2 * fabs(q[1]) + m2) * g;
        for (int i = 0; i < 4; ++i) {
            ENSURE_NEAR(Ml[i], M[i], 1e-13 * sM, "assignment manipulator M(3) entry %d " CTXF, i, CTXA);
            ENSURE_NEAR(Cl[i], C[i], 1e-13 * sC, "assignment manipulator C(5) entry %d " CTXF, i, CTXA);
        }
        for (int i = 0; i < 2; ++i) ENSURE_NEAR(gl[i], G[i], 1e-13 * sG, "assignment manipulator g entry %d " CTXF, i, CTXA);
    }
}

static void check_model(lag_model_kind kind, uint64_t seed)
{
    lt_rng rng = {seed};
    int f0 = lt_failures;
    double worst_M = 0, worst_dM = 0, worst_C = 0, worst_g = 0, worst_lag = 0, worst_fwd = 0;
    for (int it = 0; it < NSTATES; ++it) {
        lag_model md;
        tc_random_model(&rng, kind, &md);
        int n = md.nq;
        ENSURE(n == tc_nq(kind));
        double q[3] = {0}, qd[3] = {0}, qdd[3] = {0}, tau[3] = {0};
        tc_random_state(&rng, &md, q, qd);
        for (int i = 0; i < n; ++i) {
            qdd[i] = lt_uniform(&rng, -20, 20);
            tau[i] = lt_uniform(&rng, -20, 20);
        }
        check_kinematics(&md, it, q, qd);

        /* ---- the core's quantities */
        double Ml[9], dMl[27], Cl[9], gl[3], hl[3];
        lag_model_mass(&md, q, Ml);
        lag_model_mass_deriv(&md, q, dMl);
        lag_model_coriolis(&md, q, qd, Cl);
        lag_model_gravity(&md, q, gl);
        lag_model_bias(&md, q, qd, hl);

        /* ---- the same from T and U */
        double Mt[9], dMt[27], Ct[9], gt[3];
        tc_mass(&md, q, Mt);
        tc_mass_deriv(&md, q, dMt);
        tc_christoffel(n, dMt, qd, Ct);
        tc_dU_dq(&md, q, gt);

        /* Scales. Both sides are closed forms / complex steps exact to rounding of a few
         * dozen terms, each at most of the size below, so 1e-13 (~450 eps) of it is a
         * generous bound; a wrong coefficient shows as an O(1e-2..1) relative error. */
        double sM = tc_maxabs(n * n, Mt);
        double sdM = tc_maxabs(n * n * n, dMt) + sM; /* complex-step terms are O(|M|) each */
        double sC = sdM * tc_maxabs(n, qd) * n;
        tc_bodies b;
        cplx qc[3], zc[3] = {0, 0, 0};
        tc_to_c(n, q, qc);
        tc_kinematics(&md, qc, zc, &b);
        double sg = 0;
        for (int k = 0; k < b.nb; ++k)
            sg += b.mass[k] * tc_p(&md, "g") * (1 + cabs(b.x[k]) + cabs(b.y[k]));

        for (int i = 0; i < n * n; ++i) {
            ENSURE_NEAR(Ml[i], Mt[i], 1e-13 * sM, "M entry %d " CTXF, i, CTXA);
            worst_M = fmax(worst_M, fabs(Ml[i] - Mt[i]) / sM);
        }
        for (int i = 0; i < n * n * n; ++i) {
            ENSURE_NEAR(dMl[i], dMt[i], 1e-13 * sdM, "dM/dq_%d entry %d " CTXF, i / (n * n), i % (n * n), CTXA);
            worst_dM = fmax(worst_dM, fabs(dMl[i] - dMt[i]) / sdM);
        }
        for (int i = 0; i < n * n; ++i) {
            ENSURE_NEAR(Cl[i], Ct[i], 1e-13 * sC, "C (Christoffel) entry %d " CTXF, i, CTXA);
            worst_C = fmax(worst_C, fabs(Cl[i] - Ct[i]) / sC);
        }
        for (int i = 0; i < n; ++i) {
            ENSURE_NEAR(gl[i], gt[i], 1e-13 * sg, "g = dU/dq entry %d " CTXF, i, CTXA);
            worst_g = fmax(worst_g, fabs(gl[i] - gt[i]) / sg);
        }
        /* bias = C qd + g (the core's own C and g): same rounding argument. */
        double Cqd[3];
        tc_matvec(n, Cl, qd, Cqd);
        for (int i = 0; i < n; ++i)
            ENSURE_NEAR(hl[i], Cqd[i] + gl[i], 1e-13 * (sC * tc_maxabs(n, qd) + sg), "bias entry %d " CTXF, i, CTXA);

        /* Energies: kinetic equals T exactly (to rounding); potential up to a constant,
         * so compare U(q) - U(q') with a second random state q'. */
        double Tt = tc_T(&md, q, qd);
        ENSURE_NEAR(lag_model_kinetic(&md, q, qd), Tt, 1e-13 * (Tt + sM * tc_maxabs(n, qd) * tc_maxabs(n, qd)),
                    "kinetic " CTXF, CTXA);
        double q2[3] = {0}, qd2[3] = {0};
        tc_random_state(&rng, &md, q2, qd2);
        double dUl = lag_model_potential(&md, q) - lag_model_potential(&md, q2);
        double dUt = tc_U(&md, q) - tc_U(&md, q2);
        ENSURE_NEAR(dUl, dUt, 1e-13 * sg * 4, "potential difference " CTXF, CTXA);

        /* Lagrange's equations at a random qdd: d/dt(dL/dqd) - dL/dq (exact to rounding, see
         * tc_lagrange_lhs) equals M qdd + C qd + g from the core. Tolerance 1e-12 of the
         * largest term (~4500 eps: rounding of a few dozen terms, cancellations included). */
        double lhs[3], Mqdd[3];
        tc_lagrange_lhs(&md, q, qd, qdd, lhs);
        tc_matvec(n, Ml, qdd, Mqdd);
        double sL = sM * tc_maxabs(n, qdd) + sC * tc_maxabs(n, qd) + sg;
        for (int i = 0; i < n; ++i) {
            double rhs = Mqdd[i] + Cqd[i] + gl[i];
            ENSURE_NEAR(rhs, lhs[i], 1e-12 * sL, "Lagrange eq %d (M qdd + C qd + g) " CTXF, i, CTXA);
            worst_lag = fmax(worst_lag, fabs(rhs - lhs[i]) / sL);
        }

        /* Forward dynamics: qdd = forward(q, qd, tau) must satisfy Lagrange's equations
         * with right side tau. The residual of a backward-stable solve is ~ n eps |M| |qdd|
         * whatever the conditioning of M, so the same 1e-12 of the largest term holds. */
        double qddf[3];
        lag_result r = lag_model_forward(&md, q, qd, tau, qddf);
        ENSURE(r == LAG_OK);
        if (r == LAG_OK) {
            tc_lagrange_lhs(&md, q, qd, qddf, lhs);
            double sF = sM * tc_maxabs(n, qddf) + sC * tc_maxabs(n, qd) + sg + tc_maxabs(n, tau);
            for (int i = 0; i < n; ++i) {
                ENSURE_NEAR(lhs[i], tau[i], 1e-12 * sF, "forward: Lagrange residual eq %d " CTXF, i, CTXA);
                worst_fwd = fmax(worst_fwd, fabs(lhs[i] - tau[i]) / sF);
            }
        }
        /* NULL tau means zero input */
        double qdd0[3], qdd0z[3];
        double zero[3] = {0, 0, 0};
        ENSURE(lag_model_forward(&md, q, qd, NULL, qdd0) == LAG_OK);
        ENSURE(lag_model_forward(&md, q, qd, zero, qdd0z) == LAG_OK);
        for (int i = 0; i < n; ++i) ENSURE(qdd0[i] == qdd0z[i]);

        check_assignment(&md, it, q, qd, qdd, Ml, Cl, gl, hl);
    }
    printf("%-12s %d states: worst relative |core - from T,U|: M %.1e  dM %.1e  C %.1e  g %.1e  "
           "Lagrange %.1e  forward %.1e  (%s)\n",
           kname(kind), NSTATES, worst_M, worst_dM, worst_C, worst_g, worst_lag, worst_fwd,
           lt_failures == f0 ? "ok" : "FAILED");
}

/* The model table itself, for every row: no hole (a NULL row or function would crash
 * only when that model is used), names unique and found again, counts that match the
 * lists (a name past np, or a missing one before it, is a wrong count), units and rules
 * for every parameter, rods that name a mass, a length and an inertia whose default is
 * NaN, and defaults that pass the model's own check. */
static void check_table(void)
{
    /* lag_model_names: exactly the table's names, in its order, joined by ", " */
    char names[256], expect[256] = "";
    lag_model_names(names, sizeof names);
    for (int k = 0; k < LAG_MODEL_COUNT; ++k) {
        if (k) strcat(expect, ", ");
        strcat(expect, lag_model_info_get((lag_model_kind)k)->name);
    }
    ENSURE(strcmp(names, expect) == 0);
    for (int k = 0; k < LAG_MODEL_COUNT; ++k) {
        const lag_model_class *c = lag_models[k];
        ENSURE(c && c->info && c->mass && c->mass_deriv && c->coriolis && c->gravity &&
               c->mass_bias && c->forward && c->kinetic && c->potential);
        if (!c || !c->info) continue;
        const lag_model_info *inf = c->info;
        ENSURE(lag_model_info_get((lag_model_kind)k) == inf);
        ENSURE(inf->name && inf->name[0] && lag_model_kind_from_name(inf->name) == k);
        /* found again by its joints: the first model with those names, whose units and
         * actuation are this one's (what lagsim-log2csv and lagsim-view read) */
        const lag_model_info *by = lag_model_info_by_joints(inf->joint_names, inf->nq);
        ENSURE(by != NULL);
        for (int j = 0; by && j < inf->nq; ++j)
            ENSURE(by->angular[j] == inf->angular[j] && by->actuated[j] == inf->actuated[j]);
        /* a name: [a-z][a-z0-9-]*, what a scene's `model:` key holds */
        ENSURE(inf->name && inf->name[0] >= 'a' && inf->name[0] <= 'z' &&
               strspn(inf->name, "abcdefghijklmnopqrstuvwxyz0123456789-") == strlen(inf->name));
        ENSURE(inf->nq >= 1 && inf->nq <= LAG_MAX_DOF && inf->np >= 1 && inf->np <= LAG_MAX_PARAMS);
        bool any_actuated = false;
        for (int j = 0; j < LAG_MAX_DOF; ++j) {
            if (j >= inf->nq) {
                ENSURE(inf->joint_names[j] == NULL && !inf->actuated[j]);
                continue;
            }
            ENSURE(inf->joint_names[j] && inf->joint_names[j][0]);
            for (int i = 0; i < j; ++i) ENSURE(strcmp(inf->joint_names[i], inf->joint_names[j]) != 0);
            any_actuated |= inf->actuated[j];
        }
        ENSURE(any_actuated);
        for (int i = 0; i < LAG_MAX_PARAMS; ++i) {
            if (i >= inf->np) {
                ENSURE(inf->param_names[i] == NULL && inf->param_units[i] == NULL);
                continue;
            }
            ENSURE(inf->param_names[i] && inf->param_names[i][0] && inf->param_units[i]);
            ENSURE(lag_model_param_index((lag_model_kind)k, inf->param_names[i]) == i);
            ENSURE(inf->param_rules[i] == LAG_PARAM_POSITIVE ||
                   inf->param_rules[i] == LAG_PARAM_NONNEGATIVE || inf->param_rules[i] == LAG_PARAM_ANY);
            bool rod_inertia = false;
            for (int r = 0; r < inf->n_rods; ++r) rod_inertia |= inf->rods[r].inertia == i;
            /* NaN default exactly for the rods' inertias */
            ENSURE(isnan(inf->param_defaults[i]) == rod_inertia);
        }
        /* what the docs say of it (the generated lists, server/lists): a title, a
         * summary, the meaning of each parameter and coordinate, and nothing beyond */
        const lag_model_doc *doc = c->doc;
        ENSUREF(doc && doc->title && doc->title[0] && doc->summary && doc->summary[0],
                "model %s: its row has no doc (title, summary)", inf->name);
        for (int i = 0; doc && i < LAG_MAX_PARAMS; ++i)
            ENSUREF((i < inf->np) == (doc->params[i] != NULL && doc->params[i][0] != '\0'),
                    "model %s: doc.params[%d] %s", inf->name, i,
                    i < inf->np ? "is missing" : "is beyond the parameters");
        for (int j = 0; doc && j < LAG_MAX_DOF; ++j)
            ENSUREF((j < inf->nq) == (doc->joints[j] != NULL && doc->joints[j][0] != '\0'),
                    "model %s: doc.joints[%d] %s", inf->name, j,
                    j < inf->nq ? "is missing" : "is beyond the coordinates");
        /* g is a parameter of every model (the scene's effects.gravity sets it) */
        int g = lag_model_param_index((lag_model_kind)k, "g");
        ENSURE(g >= 0 && inf->param_rules[g] == LAG_PARAM_NONNEGATIVE &&
               strcmp(inf->param_units[g], "m/s^2") == 0);
        ENSURE(inf->n_rods >= 0 && inf->n_rods <= LAG_MAX_RODS);
        for (int r = 0; r < inf->n_rods; ++r) {
            lag_rod rod = inf->rods[r];
            bool in = rod.inertia >= 0 && rod.inertia < inf->np && rod.mass >= 0 && rod.mass < inf->np &&
                      rod.length >= 0 && rod.length < inf->np;
            ENSURE(in);
            if (!in) continue;
            ENSURE(strcmp(inf->param_units[rod.inertia], "kg m^2") == 0 &&
                   strcmp(inf->param_units[rod.mass], "kg") == 0 &&
                   strcmp(inf->param_units[rod.length], "m") == 0);
            lag_model m;
            lag_model_default(&m, (lag_model_kind)k);
            ENSURE_NEAR(m.p[rod.inertia], m.p[rod.mass] * m.p[rod.length] * m.p[rod.length] / 12,
                        1e-15 * m.p[rod.inertia], "%s rod %d default inertia", inf->name, r);
        }
        lag_model m;
        lag_model_default(&m, (lag_model_kind)k);
        lag_diag dg;
        ENSURE(m.nq == inf->nq && lag_model_check(&m, &dg) == LAG_OK);
        /* each rule is enforced: the boundary value is refused or accepted as the rule says */
        for (int i = 0; i < inf->np; ++i) {
            lag_model b = m;
            b.p[i] = 0.0;
            lag_result r = lag_model_check(&b, &dg);
            ENSURE((r == LAG_OK) == (inf->param_rules[i] != LAG_PARAM_POSITIVE));
            b.p[i] = -1.0;
            r = lag_model_check(&b, &dg);
            ENSURE((r == LAG_OK) == (inf->param_rules[i] == LAG_PARAM_ANY));
        }
    }
    ENSURE(lag_model_info_get(LAG_MODEL_COUNT) == NULL && lag_model_info_get((lag_model_kind)-1) == NULL);
}

/* Static facts: names, sizes, inputs, defaults as the course assignment gives them for its three
 * models (a model added later has its facts in its own file; check_table covers it). */
static void check_info(void)
{
    check_table();
    static const char *joints[3][3] = {{"x", "phi", NULL}, {"q1", "q2", NULL}, {"theta0", "theta1", "theta2"}};
    static const bool act[3][3] = {{true, true, false}, {true, true, false}, {true, false, false}};
    static const char *models[3] = {"stick", "manipulator", "dipc"};
    for (int k = 0; k < 3; ++k) {
        const lag_model_info *inf = lag_model_info_get((lag_model_kind)lag_model_kind_from_name(models[k]));
        ENSURE(inf != NULL);
        if (!inf) continue;
        ENSURE(strcmp(inf->name, models[k]) == 0);
        ENSURE(inf->nq == (k == 2 ? 3 : 2));
        for (int j = 0; j < inf->nq; ++j) {
            ENSURE(inf->joint_names[j] && strcmp(inf->joint_names[j], joints[k][j]) == 0);
            ENSURE(inf->actuated[j] == act[k][j]);
        }
    }
    /* not a model's name by the rule check_table enforces ([a-z][a-z0-9-]*): never a model */
    ENSURE(lag_model_kind_from_name("no such model!") == -1 && lag_model_kind_from_name("") == -1 &&
           lag_model_kind_from_name(NULL) == -1);
    {   /* joints no model has, in another order, or too few: none */
        const char *odd[2] = {"phi", "x"}, *one[1] = {"x"}, *cp[2] = {"x", "theta"};
        ENSURE(lag_model_info_by_joints(odd, 2) == NULL && lag_model_info_by_joints(one, 1) == NULL);
        ENSURE(lag_model_info_by_joints(cp, 2) && !lag_model_info_by_joints(cp, 2)->angular[0] &&
               lag_model_info_by_joints(cp, 2)->angular[1]);
    }
    /* Parameters named as in the course assignment. */
    ENSURE(lag_model_param_index(LAG_MODEL_STICK, "m") == LAG_STICK_M);
    ENSURE(lag_model_param_index(LAG_MODEL_STICK, "I") == LAG_STICK_I);
    ENSURE(lag_model_param_index(LAG_MODEL_MANIPULATOR, "l1") == LAG_MANIP_L1);
    ENSURE(lag_model_param_index(LAG_MODEL_MANIPULATOR, "I2") == LAG_MANIP_I2);
    ENSURE(lag_model_param_index(LAG_MODEL_DIPC, "m0") == LAG_DIPC_M0);
    ENSURE(lag_model_param_index(LAG_MODEL_DIPC, "h0") == LAG_DIPC_H0);
    ENSURE(lag_model_param_index(LAG_MODEL_DIPC, "nope") == -1);
    /* Uniform rods default to I = m l^2 / 12 (the stick and the DIPC's rods are uniform). */
    lag_model m;
    lag_model_default(&m, LAG_MODEL_STICK);
    ENSURE_NEAR(m.p[LAG_STICK_I], m.p[LAG_STICK_M] * m.p[LAG_STICK_L] * m.p[LAG_STICK_L] / 12,
                1e-15 * m.p[LAG_STICK_I], "stick default I");
    lag_model_default(&m, LAG_MODEL_DIPC);
    ENSURE_NEAR(m.p[LAG_DIPC_I1], m.p[LAG_DIPC_M1] * m.p[LAG_DIPC_L1] * m.p[LAG_DIPC_L1] / 12,
                1e-15 * m.p[LAG_DIPC_I1], "dipc default I1");
    ENSURE_NEAR(m.p[LAG_DIPC_I2], m.p[LAG_DIPC_M2] * m.p[LAG_DIPC_L2] * m.p[LAG_DIPC_L2] / 12,
                1e-15 * m.p[LAG_DIPC_I2], "dipc default I2");
    /* Not given: NaN until finished, then the rod value for the *changed* m and l. */
    lag_model_default_unfinished(&m, LAG_MODEL_DIPC);
    ENSURE(isnan(m.p[LAG_DIPC_I1]) && isnan(m.p[LAG_DIPC_I2]));
    m.p[LAG_DIPC_M1] = 2.0;
    m.p[LAG_DIPC_L1] = 0.9;
    m.p[LAG_DIPC_I2] = 0.123;
    lag_model_finish(&m);
    ENSURE_NEAR(m.p[LAG_DIPC_I1], 2.0 * 0.81 / 12, 1e-15, "dipc I1 after finish");
    ENSURE(m.p[LAG_DIPC_I2] == 0.123);
    char err[128];
    ENSURE(lag_model_validate(&m, err, sizeof err) == LAG_OK);
    m.p[LAG_DIPC_M2] = -1;
    ENSURE(lag_model_validate(&m, err, sizeof err) == LAG_ERR_ARG);
    /* The method table: every row complete (lag_method_table_ok: name, step, order, an
     * advance exactly for the adaptive ones, unique names), names found again, every
     * method in lag_method_names. */
    ENSURE(lag_method_table_ok());
    char mlist[256];
    lag_method_names(mlist, sizeof mlist);
    for (int i = 0; i < LAG_METHOD_COUNT; ++i) {
        const lag_method_info *mi = lag_method_info_get((lag_method)i);
        ENSURE(mi && mi->name && strcmp(lag_method_name((lag_method)i), mi->name) == 0);
        if (!mi) continue;
        ENSURE(lag_method_from_name(mi->name) == i && strstr(mlist, mi->name) != NULL);
        ENSURE(mi->order >= 1 && lag_method_order((lag_method)i) == mi->order);
        /* a name: [a-z][a-z0-9-]*, what a scene's integrator.method holds (so that a name
         * with a space, the scene fixture's unknown method, can never be one) */
        ENSUREF(mi->name[0] >= 'a' && mi->name[0] <= 'z' &&
                strspn(mi->name, "abcdefghijklmnopqrstuvwxyz0123456789-") == strlen(mi->name),
                "method '%s': not a lowercase word that hyphens may join", mi->name);
        ENSURE(!(mi->canonical && !mi->implicit)); /* (q, p) Gauss methods are implicit */
    }
    ENSURE(lag_method_info_get(LAG_METHOD_COUNT) == NULL && strcmp(lag_method_name(LAG_METHOD_COUNT), "unknown") == 0);
    /* Facts of the methods documented in lagsim.h, by name. */
    static const struct { const char *name; int order; bool adaptive, implicit, canonical; } facts[] = {
        {"euler", 1, false, false, false},          {"semi-implicit-euler", 1, false, false, false},
        {"rk4", 4, false, false, false},            {"dopri5", 5, true, false, false},
        {"implicit-midpoint", 2, false, true, true}, {"gauss4", 4, false, true, true},
    };
    for (size_t i = 0; i < sizeof facts / sizeof facts[0]; ++i) {
        const lag_method_info *mi = lag_method_info_get((lag_method)lag_method_from_name(facts[i].name));
        ENSURE(mi && mi->order == facts[i].order && mi->adaptive == facts[i].adaptive &&
               mi->implicit == facts[i].implicit && mi->canonical == facts[i].canonical);
    }
    /* not a method's name (a method is a word with hyphens), not a would-be method */
    ENSURE(lag_method_from_name("no such method!") == -1 && lag_method_from_name("") == -1 &&
           lag_method_from_name(NULL) == -1);
}

/* ---------------------------------------------------------------- the course assignment's DIPC */
/* The course assignment's Problem 3, transcribed as printed, with each error we found behind a flag.
 * With every fix applied it must agree with our T and U and with the core; with any one
 * fix left out it must not. That proves the list in README.md ("The models") is complete for
 * the printed (b) T_i, (c) U_i, (8) L and (12a-c), and that each item is a real error. */
enum {
    FIX_T0_SQUARE = 1 << 0,  /* (b) T0 = 1/2 m0 th0d  -> 1/2 m0 th0d^2 */
    FIX_U2_L2 = 1 << 1,      /* (a), (c) r2_y, U2: 1/2 cos th2 -> 1/2 l2 cos th2 */
    FIX_L8_J1 = 1 << 2,      /* (8) 1/2 m1 l1^2 th1d^2 -> 1/4 m1 l1^2 (inside 1/2 [...]) */
    FIX_L8_J2 = 1 << 3,      /* (8) 1/2 m2 l2^2 th2d^2 -> 1/4 m2 l2^2 */
    FIX_L8_K2 = 1 << 4,      /* (8) 1/2 m2 l2 th0d th2d cos th2 -> m2 l2 (inside 1/2 [...]) */
    FIX_12A = 1 << 5,        /* (12a) (m1 + 2 m2 l1) -> (m1 + 2 m2) */
    FIX_12B = 1 << 6,        /* (9)-(12b) 1/2 m1 l1^2 -> 1/4 m1 l1^2 */
    FIX_12C = 1 << 7,        /* (9)-(12c) 1/2 m2 l2^2 -> 1/4 m2 l2^2 */
    FIX_ALL = 0xff
};

/* Assignment (b): T = T0 + T1 + T2 as printed. */
static double asg_T(const double *p, const double *q, const double *qd, unsigned fix)
{
    double m0 = p[LAG_DIPC_M0], m1 = p[LAG_DIPC_M1], m2 = p[LAG_DIPC_M2], l1 = p[LAG_DIPC_L1],
           l2 = p[LAG_DIPC_L2], I1 = p[LAG_DIPC_I1], I2 = p[LAG_DIPC_I2];
    double T0 = (fix & FIX_T0_SQUARE) ? 0.5 * m0 * qd[0] * qd[0] : 0.5 * m0 * qd[0];
    double T1 = 0.5 * m1 * (qd[0] * qd[0] + l1 * qd[0] * qd[1] * cos(q[1]) + 0.25 * l1 * l1 * qd[1] * qd[1]) +
                0.5 * I1 * qd[1] * qd[1];
    double T2 = 0.5 * m2 * (qd[0] * qd[0] + l1 * l1 * qd[1] * qd[1] + 0.25 * l2 * l2 * qd[2] * qd[2] +
                            2 * l1 * qd[0] * qd[1] * cos(q[1]) + l2 * qd[0] * qd[2] * cos(q[2]) +
                            l1 * l2 * qd[1] * qd[2] * cos(q[1] - q[2])) +
                0.5 * I2 * qd[2] * qd[2];
    return T0 + T1 + T2;
}

/* Assignment (c): U = U0 + U1 + U2 as printed (U0 = m0 g (h0 - b0/2) is a constant: b0 = 0). */
static double asg_U(const double *p, const double *q, unsigned fix)
{
    double m0 = p[LAG_DIPC_M0], m1 = p[LAG_DIPC_M1], m2 = p[LAG_DIPC_M2], l1 = p[LAG_DIPC_L1],
           l2 = p[LAG_DIPC_L2], g = p[LAG_DIPC_G], h0 = p[LAG_DIPC_H0];
    double a2 = (fix & FIX_U2_L2) ? 0.5 * l2 : 0.5;
    return m0 * g * h0 + m1 * g * (h0 + 0.5 * l1 * cos(q[1])) + m2 * g * (h0 + l1 * cos(q[1]) + a2 * cos(q[2]));
}

/* Assignment (8): the Lagrangian as printed. */
static double asg_L(const double *p, const double *q, const double *qd, unsigned fix)
{
    double m0 = p[LAG_DIPC_M0], m1 = p[LAG_DIPC_M1], m2 = p[LAG_DIPC_M2], l1 = p[LAG_DIPC_L1],
           l2 = p[LAG_DIPC_L2], I1 = p[LAG_DIPC_I1], I2 = p[LAG_DIPC_I2], g = p[LAG_DIPC_G],
           h0 = p[LAG_DIPC_H0];
    double c1 = (fix & FIX_L8_J1) ? 0.25 : 0.5, c2 = (fix & FIX_L8_J2) ? 0.25 : 0.5,
           c02 = (fix & FIX_L8_K2) ? 1.0 : 0.5;
    double br = (m0 + m1 + m2) * qd[0] * qd[0] + (c1 * m1 * l1 * l1 + m2 * l1 * l1 + I1) * qd[1] * qd[1] +
                (c2 * m2 * l2 * l2 + I2) * qd[2] * qd[2] + (m1 * l1 + 2 * m2 * l1) * qd[0] * qd[1] * cos(q[1]) +
                c02 * m2 * l2 * qd[0] * qd[2] * cos(q[2]) + m2 * l1 * l2 * qd[1] * qd[2] * cos(q[1] - q[2]);
    return 0.5 * br - (0.5 * m1 + m2) * g * l1 * cos(q[1]) - 0.5 * m2 * g * l2 * cos(q[2]) - (m0 + m1 + m2) * h0 * g;
}

/* Assignment (12a-c): left side minus right side's tau, i.e. what must equal M qdd + C qd + g. */
static void asg_eom(const double *p, const double *q, const double *qd, const double *qdd, unsigned fix,
                     double *out)
{
    double m0 = p[LAG_DIPC_M0], m1 = p[LAG_DIPC_M1], m2 = p[LAG_DIPC_M2], l1 = p[LAG_DIPC_L1],
           l2 = p[LAG_DIPC_L2], I1 = p[LAG_DIPC_I1], I2 = p[LAG_DIPC_I2], g = p[LAG_DIPC_G];
    double s1 = sin(q[1]), c1 = cos(q[1]), s2 = sin(q[2]), c2 = cos(q[2]), s12 = sin(q[1] - q[2]),
           c12 = cos(q[1] - q[2]);
    double k12a = (fix & FIX_12A) ? (m1 + 2 * m2) : (m1 + 2 * m2 * l1);
    double j1 = (fix & FIX_12B) ? 0.25 : 0.5, j2 = (fix & FIX_12C) ? 0.25 : 0.5;
    out[0] = (m0 + m1 + m2) * qdd[0] +
             0.5 * (l1 * k12a * (qdd[1] * c1 - qd[1] * qd[1] * s1) + m2 * l2 * (qdd[2] * c2 - qd[2] * qd[2] * s2));
    out[1] = (j1 * m1 * l1 * l1 + m2 * l1 * l1 + I1) * qdd[1] +
             0.5 * (l1 * (m1 + 2 * m2) * qdd[0] * c1 + m2 * l1 * l2 * (qdd[2] * c12 + qd[2] * qd[2] * s12) -
                    (m1 + 2 * m2) * g * l1 * s1);
    out[2] = (j2 * m2 * l2 * l2 + I2) * qdd[2] +
             0.5 * (m2 * l2 * qdd[0] * c2 + m2 * l1 * l2 * (qdd[1] * c12 - qd[1] * qd[1] * s12) - m2 * g * l2 * s2);
}

/* Largest relative mismatch of the assignment's forms (with the given fixes) over random states:
 * against our T, our U (differences), our T - U, and the core's M qdd + C qd + g. */
static void asg_mismatch(unsigned fix, double *eT, double *eU, double *eL, double *eE)
{
    lt_rng rng = {0x5eedu};
    *eT = *eU = *eL = *eE = 0;
    for (int it = 0; it < 100; ++it) {
        lag_model md;
        tc_random_model(&rng, LAG_MODEL_DIPC, &md);
        double q[3], qd[3], q2[3], qd2[3], qdd[3];
        tc_random_state(&rng, &md, q, qd);
        tc_random_state(&rng, &md, q2, qd2);
        for (int i = 0; i < 3; ++i) qdd[i] = lt_uniform(&rng, -20, 20);
        double T = tc_T(&md, q, qd), U = tc_U(&md, q), U2 = tc_U(&md, q2), T2 = tc_T(&md, q2, qd2);
        double sc = fabs(T) + fabs(U) + fabs(U2) + fabs(T2) + 1;
        *eT = fmax(*eT, fabs(asg_T(md.p, q, qd, fix) - T) / sc);
        *eU = fmax(*eU, fabs((asg_U(md.p, q, fix) - asg_U(md.p, q2, fix)) - (U - U2)) / sc);
        /* L up to a constant: compare L(q, qd) - L(q2, qd2) */
        *eL = fmax(*eL, fabs((asg_L(md.p, q, qd, fix) - asg_L(md.p, q2, qd2, fix)) - ((T - U) - (T2 - U2))) / sc);
        double M[9], h[3], Mq[3], e[3];
        lag_model_mass(&md, q, M);
        lag_model_bias(&md, q, qd, h);
        tc_matvec(3, M, qdd, Mq);
        asg_eom(md.p, q, qd, qdd, fix, e);
        double sE = tc_maxabs(9, M) * 20 + tc_maxabs(3, h) + 1;
        for (int i = 0; i < 3; ++i) *eE = fmax(*eE, fabs(e[i] - (Mq[i] + h[i])) / sE);
    }
}

static void check_assignment_dipc(void)
{
    double eT, eU, eL, eE;
    /* all fixes: agreement to rounding (1e-13 of the scale) */
    asg_mismatch(FIX_ALL, &eT, &eU, &eL, &eE);
    printf("assignment DIPC with all 8 fixes: max rel. mismatch T %.1e U %.1e L %.1e eqs(12) %.1e\n", eT, eU, eL, eE);
    ENSURE(eT < 1e-13 && eU < 1e-13 && eL < 1e-13 && eE < 1e-13);
    /* any one fix missing: a mismatch of at least 1e-3 of the scale in the form it touches */
    static const char *names[8] = {"T0 square", "U2 l2", "L(8) m1 l1^2/4", "L(8) m2 l2^2/4",
                                   "L(8) m2 l2 th0d th2d", "(12a) m1 + 2 m2", "(12b) m1 l1^2/4",
                                   "(12c) m2 l2^2/4"};
    for (int b = 0; b < 8; ++b) {
        asg_mismatch(FIX_ALL & ~(1u << b), &eT, &eU, &eL, &eE);
        double worst = fmax(fmax(eT, eU), fmax(eL, eE));
        printf("  without fix %-22s: T %.1e U %.1e L %.1e eqs(12) %.1e\n", names[b], eT, eU, eL, eE);
        ENSURE(worst > 1e-3);
    }
}

static void case_info(int arg) { (void)arg; check_info(); }
static void case_model(int kind) { check_model((lag_model_kind)kind, 0x1234u + (uint64_t)kind); }
static void case_assignment_dipc(int arg) { (void)arg; check_assignment_dipc(); }

/* Cases: info, one per model of the core's table (by its name), assignment_dipc. */
int main(int argc, char **argv)
{
    lt_cases cs = {0};
    lt_add(&cs, "info", case_info, 0, 0);
    for (int k = 0; k < LAG_MODEL_COUNT; ++k)
        lt_add(&cs, lag_model_info_get((lag_model_kind)k)->name, case_model, k, 0);
    lt_add(&cs, "assignment_dipc", case_assignment_dipc, 0, 0);
    return lt_main(argc, argv, cs.c, cs.n);
}
