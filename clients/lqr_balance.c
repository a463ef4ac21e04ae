/*
 * lqr_balance: holds any model of a running lagsimd at an equilibrium with LQR, the model
 * taken from the daemon's scene description (the cart-pole upright, the DIPC upright, ...).
 *
 * From the scene: the model and its parameters (the core's closed forms, as the daemon
 * runs them), the joints and which of them are actuated (the inputs), the control period
 * h. It linearizes about the equilibrium (q = --q0, default 0, qd = 0, no input; it refuses
 * a point that is not one), designs the discrete LQR of the zero-order-hold plant with the
 * Riemann sum of the continuous cost (Q h, R h; --gain continuous: the CARE gain), checks
 * that the sampled loop is stable, and answers every state with u = -K (q - q0, qd) on the
 * actuated joints. Works in realtime, fast and lockstep modes.
 *
 * Summary: per joint <j>, max_abs_<j>, end_<j> and pred_max_abs_<j> (the peak of the
 * linearized sampled loop x+ = (Ad - Bd K) x run from the first state answered, over as
 * many periods), and max_abs_effort.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_controller.h"
#include "lqr.h"

#define NS LAG_MAX_STATE
#define NI LAG_MAX_DOF

typedef struct {
    double v[NS];
    int n; /* 0: not given */
} weights;

/* a comma-separated list of 1 to NS numbers >= 0 (checked against the model later) */
static int set_list(const char *v, void *target, char *err, size_t errlen)
{
    weights *w = target;
    int n = 1;
    for (const char *c = v; *c; c++) n += *c == ',';
    if (n > NS) {
        snprintf(err, errlen, "at most %d numbers, got %d", NS, n);
        return -1;
    }
    if (lag_ctl_parse_list(v, w->v, n, err, errlen)) return -1;
    w->n = n;
    return 0;
}

static double eig_bound(int n, const double *M, int discrete)
{
    double re[2 * NS], im[2 * NS], b = -INFINITY;
    if (lag_lqr_eig(n, M, re, im)) return NAN;
    for (int i = 0; i < n; i++) b = fmax(b, discrete ? hypot(re[i], im[i]) : re[i]);
    return b;
}

static void print_eig(const char *what, int n, const double *M)
{
    double re[2 * NS], im[2 * NS];
    if (lag_lqr_eig(n, M, re, im)) return;
    printf("%s:", what);
    for (int i = 0; i < n; i++) {
        if (im[i] == 0.0) printf(" %.4f", re[i]);
        else printf(" %.4f%+.4fi", re[i], im[i]);
    }
    printf("\n");
}

/* The plant as the scene describes it: its joints, which are inputs, the equilibrium. */
typedef struct plant {
    const lag_model_info *info;
    int nq, n, m;                     /* coordinates, states (2 nq), inputs */
    int inputs[NI];                   /* the actuated joints' indices */
    const char *in_names[NI];
    double q0[NI];                    /* the equilibrium's positions */
} plant;

/* The joints, the inputs and --q0 from the scene and the options; prints them. */
static int plant_from_scene(plant *p, const lag_ctl *ctl, const weights *qw, const weights *q0w)
{
    const lag_model_info *info = lag_model_info_get(ctl->kind);
    p->info = info;
    p->nq = info->nq;
    p->n = 2 * info->nq;
    if ((qw->n && qw->n != p->n) || (q0w->n && q0w->n != p->nq)) {
        fprintf(stderr, "lqr_balance: model %s has %d coordinates: --q takes %d weights, "
                        "--q0 %d positions\n", info->name, p->nq, p->n, p->nq);
        return -1;
    }
    p->m = 0;
    for (int i = 0; i < p->nq; i++)
        if (info->actuated[i]) {
            p->inputs[p->m] = i;
            p->in_names[p->m++] = info->joint_names[i];
        }
    const lag_client_scene *sc = ctl->scene;
    printf("lqr_balance: scene %s on %s_*: mode %s, dt %g s, control period %g s, integrator "
           "%s\n", lag_client_scene_model(sc), ctl->prefix, lag_client_scene_mode(sc),
           lag_client_scene_dt(sc), lag_client_scene_control_period(sc),
           lag_client_scene_integrator(sc));
    printf("parameters:");
    for (int k = 0; k < info->np; k++) printf(" %s=%g", info->param_names[k], ctl->model.p[k]);
    printf("\ninputs:");
    for (int k = 0; k < p->m; k++) printf(" %s", p->in_names[k]);
    printf("\n");
    memset(p->q0, 0, sizeof p->q0);
    for (int i = 0; i < q0w->n; i++) p->q0[i] = q0w->v[i];
    return 0;
}

/* The equilibrium: qdd(q0, 0, 0) = 0. */
static int check_equilibrium(const plant *p, const lag_model *model)
{
    double zero[NI] = {0}, qdd[NI];
    if (lag_model_forward(model, p->q0, zero, zero, qdd) != LAG_OK) {
        fprintf(stderr, "lqr_balance: the model's dynamics fail at q0\n");
        return -1;
    }
    for (int i = 0; i < p->nq; i++)
        if (!(fabs(qdd[i]) <= 1e-9)) { /* m/s^2 or rad/s^2 */
            fprintf(stderr, "lqr_balance: q0 is not an equilibrium without input (%s'' = %g)\n",
                    p->info->joint_names[i], qdd[i]);
            return -1;
        }
    return 0;
}

/* The design: the continuous and discrete gains, the gain applied and its sampled loop. */
typedef struct design {
    double A[NS * NS], B[NS * NI], Q[NS * NS], R[NI * NI]; /* x' = A x + B u, weights */
    double Kc[NI * NS];                                     /* continuous LQR (CARE) */
    double Ad[NS * NS], Bd[NS * NI], Kd[NI * NS];           /* ZOH plant, discrete LQR */
    const double *K;                                        /* the gain applied */
    double Adcl[NS * NS];                                   /* its sampled loop Ad - Bd K */
} design;

/* Continuous LQR of the plant linearized about the equilibrium; prints its poles. */
static int design_continuous(design *d, const plant *p, const lag_model *model,
                             const weights *qw, double r)
{
    const int n = p->n, m = p->m;
    double zero[NI] = {0}, X[NS * NS], Acl[NS * NS];
    memset(d->Q, 0, sizeof d->Q);
    memset(d->R, 0, sizeof d->R);
    for (int i = 0; i < n; i++) d->Q[i * n + i] = qw->n ? qw->v[i] : 1.0;
    for (int k = 0; k < m; k++) d->R[k * m + k] = r;
    int rc = lag_lqr_linearize(model, p->q0, zero, NULL, m, p->inputs, d->A, d->B);
    if (rc == LAG_LQR_OK) rc = lag_lqr_care(n, m, d->A, d->B, d->Q, d->R, X, d->Kc);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "lqr_balance: continuous LQR design failed (%d)\n", rc);
        return -1;
    }
    print_eig("open-loop poles (1/s)", n, d->A);
    lag_lqr_closed_loop(n, m, d->A, d->B, d->Kc, Acl);
    printf("continuous LQR: CARE residual %.2e\n",
           lag_lqr_care_residual(n, m, d->A, d->B, d->Q, d->R, X));
    print_eig("continuous closed-loop poles (1/s)", n, Acl);
    return 0;
}

/* Discrete LQR of the zero-order-hold plant at the control period h, cost (Q h, R h). */
static int design_discrete(design *d, const plant *p, double h)
{
    const int n = p->n, m = p->m;
    double Qd[NS * NS], Rd[NI * NI], Xd[NS * NS];
    for (int i = 0; i < n * n; i++) Qd[i] = d->Q[i] * h;
    for (int i = 0; i < m * m; i++) Rd[i] = d->R[i] * h;
    int rc = lag_lqr_c2d(n, m, d->A, d->B, h, d->Ad, d->Bd);
    if (rc == LAG_LQR_OK) rc = lag_lqr_dare(n, m, d->Ad, d->Bd, Qd, Rd, Xd, d->Kd);
    if (rc != LAG_LQR_OK) {
        fprintf(stderr, "lqr_balance: discrete LQR design failed (%d)\n", rc);
        return -1;
    }
    printf("discrete LQR (h = %g s): DARE residual %.2e\n", h,
           lag_lqr_dare_residual(n, m, d->Ad, d->Bd, Qd, Rd, Xd));
    return 0;
}

/* The gain --gain names, refused unless it stabilizes the sampled loop; prints it. */
static int choose_gain(design *d, const plant *p, int continuous)
{
    const int n = p->n, m = p->m;
    d->K = continuous ? d->Kc : d->Kd;
    lag_lqr_closed_loop(n, m, d->Ad, d->Bd, d->K, d->Adcl);
    print_eig("sampled closed-loop eigenvalues (z)", n, d->Adcl);
    double rho = eig_bound(n, d->Adcl, 1);
    if (!(rho < 1.0)) {
        fprintf(stderr, "lqr_balance: the %s gain does not stabilize the sampled loop "
                        "(spectral radius %.6f)\n", continuous ? "continuous" : "discrete", rho);
        return -1;
    }
    for (int k = 0; k < m; k++) {
        /* u, not the joint's name: a joint may be called x (the cart-pole's), the state's name */
        printf("applying the %s gain on %s: u = -K x, K =", continuous ? "continuous" : "discrete",
               p->in_names[k]);
        for (int j = 0; j < n; j++) printf(" %.17g", d->K[k * n + j]);
        printf("\n");
    }
    fflush(stdout);
    return 0;
}

/* What the run did: its states, peaks and end positions for the summary. */
typedef struct balance {
    int idx[NI];                      /* the model's joints in the state's (-1: look up) */
    int64_t states;
    double t_first, t_last, t_report, max_u;
    double x_first[NS];               /* the first state answered: the prediction's start */
    double max_abs[NI], end[NI];
} balance;

/* x = (q - q0, qd) from a state; -1 if it lacks one of the model's joints. */
static int state_vector(balance *b, const plant *p, const lag_client_state *st, double x[NS])
{
    bool have = true;
    for (int i = 0; i < p->nq; i++) {
        if (b->idx[i] < 0 || b->idx[i] >= st->num_joints ||
            strcmp(st->name[b->idx[i]], p->info->joint_names[i]) != 0)
            b->idx[i] = lag_client_state_joint(st, p->info->joint_names[i]);
        have = have && b->idx[i] >= 0;
    }
    if (!have) {
        fprintf(stderr, "lqr_balance: a state without the model's joints; ignored\n");
        return -1;
    }
    for (int i = 0; i < p->nq; i++) {
        x[i] = st->position[b->idx[i]] - p->q0[i];
        x[p->nq + i] = st->velocity[b->idx[i]];
    }
    return 0;
}

static void record(balance *b, const plant *p, const lag_ctl *ctl, double t, const double x[NS])
{
    if (b->states == 0) {
        b->t_first = t;
        memcpy(b->x_first, x, sizeof b->x_first);
    }
    b->states++;
    b->t_last = t;
    for (int i = 0; i < p->nq; i++) {
        b->max_abs[i] = fmax(b->max_abs[i], fabs(x[i]));
        b->end[i] = x[i];
    }
    if (!ctl->quiet && t - b->t_report >= 1.0) {
        b->t_report = t;
        printf("t=%8.3f", t);
        for (int i = 0; i < p->nq; i++) printf("  %s=%+.6f", p->info->joint_names[i], x[i]);
        printf("\n");
        fflush(stdout);
    }
}

/* Linear prediction from the first state answered: the same sampled loop on the
 * linearized plant over the same number of periods (near the equilibrium, the
 * daemon's nonlinear run should come close to it). */
static void predict(const design *d, const plant *p, const balance *b, double pred[NI])
{
    const int n = p->n;
    double xl[NS], xn[NS];
    memset(pred, 0, NI * sizeof *pred);
    memcpy(xl, b->x_first, sizeof xl);
    for (int64_t k = 0; k < b->states; k++) {
        for (int i = 0; i < p->nq; i++) pred[i] = fmax(pred[i], fabs(xl[i]));
        for (int i = 0; i < n; i++) {
            xn[i] = 0.0;
            for (int j = 0; j < n; j++) xn[i] += d->Adcl[i * n + j] * xl[j];
        }
        memcpy(xl, xn, sizeof xl);
    }
}

static int finish(lag_ctl *ctl, const design *d, const plant *p, const balance *b)
{
    double pred[NI];
    predict(d, p, b, pred);
    const char *const *jn = p->info->joint_names;
    char joints[1024] = "";
    size_t len = 0;
    for (int i = 0; i < p->nq && len < sizeof joints; i++)
        len += (size_t)snprintf(joints + len, sizeof joints - len,
                                " max_abs_%s=%.6g end_%s=%.3g pred_max_abs_%s=%.6g", jn[i],
                                b->max_abs[i], jn[i], b->end[i], jn[i], pred[i]);
    return lag_ctl_finish(ctl, "states=%lld t_first=%.6f t_last=%.6f max_abs_effort=%.6g%s",
                          (long long)b->states, b->t_first, b->t_last, b->max_u, joints);
}

int main(int argc, char **argv)
{
    double r_weight = 1.0;
    weights qw = {{0}, 0}, q0w = {{0}, 0};
    int continuous = 0;
    const lag_ctl_option mine[] = {
        {"q", "w,...", "state weights, 2 nq of them (positions, then velocities; default 1 "
                       "each)", set_list, &qw},
        {"r", "R", "weight of each input (default 1)", lag_ctl_positive, &r_weight},
        {"q0", "a,...", "the equilibrium's positions, nq of them (default 0 each)", set_list,
         &q0w},
        {"gain", "G", "discrete (default: DARE at the control period) or continuous",
         lag_ctl_gain_kind, &continuous},
    };
    lag_ctl ctl;
    lag_ctl_init(&ctl, "lqr_balance", NULL);
    int rc = lag_ctl_parse(&ctl, argc, argv,
                           "Holds the model of a running lagsimd (from its scene description) "
                           "at an equilibrium with\nLQR on its actuated joints. Answers every "
                           "state (lockstep-safe).",
                           mine, (int)(sizeof mine / sizeof mine[0]));
    if (rc >= 0) return rc;
    for (int i = 0; i < qw.n; i++)
        if (qw.v[i] < 0) {
            fprintf(stderr, "lqr_balance: --q: weights must be >= 0, got %g\n", qw.v[i]);
            return lag_result_exit(LAG_ERR_USAGE);
        }
    if (lag_ctl_start(&ctl, NULL)) return lag_ctl_fail(&ctl);
    plant p;
    if (plant_from_scene(&p, &ctl, &qw, &q0w) || check_equilibrium(&p, &ctl.model))
        return lag_ctl_fail(&ctl);

    /* ---- design */
    design d;
    if (design_continuous(&d, &p, &ctl.model, &qw, r_weight) ||
        design_discrete(&d, &p, lag_client_scene_control_period(ctl.scene)) ||
        choose_gain(&d, &p, continuous))
        return lag_ctl_fail(&ctl);

    /* ---- control loop: answer every state until the run ends */
    lag_client_state st;
    balance b = {.t_first = NAN, .t_last = NAN, .t_report = -INFINITY};
    for (int i = 0; i < p.nq; i++) b.idx[i] = -1;
    while (lag_ctl_next_state(&ctl, &st) == LAG_CLIENT_OK) {
        double x[NS], u[NI];
        if (state_vector(&b, &p, &st, x)) continue;
        for (int k = 0; k < p.m; k++) {
            u[k] = 0.0;
            for (int j = 0; j < p.n; j++) u[k] -= d.K[k * p.n + j] * x[j];
            b.max_u = fmax(b.max_u, fabs(u[k]));
        }
        lag_ctl_command(&ctl, &st, p.m, p.in_names, u); /* a non-finite u is sent as 0 */
        record(&b, &p, &ctl, st.sim_time, x);
    }
    return finish(&ctl, &d, &p, &b);
}
