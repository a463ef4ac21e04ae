/*
 * What accuracy costs (server/accuracy/cost.c): for every shipped scene (config/NAME.yaml,
 * read at run time, so a new scene is a new case) and an error E of 1e-4, 1e-6 and 1e-9,
 * the setting the calibration chooses is run over the horizon and compared with an
 * independent reference: 2-stage Gauss-Legendre (an implicit, symplectic method, not the
 * dopri5 the calibration measures against) at dt = period / 1024, whose own error over
 * one second is below 1e-12 on these scenes (its order-4 convergence is checked in
 * tests/core/test_convergence.c). The claim checked: max |q - q_ref| <= E over the horizon
 * at every publish time. Also: the table's rows are what they say (each fixed dt divides
 * the period, the chosen row is the cheapest that meets, rows that meet do).
 */
#include <dirent.h>

#include "lagsim_test.h"
#include "cost.h"
#include "scene.h"

#define MAX_SCENES 16
static char scene_names[MAX_SCENES][64];
static char case_names[MAX_SCENES * 3][96];
static const double targets[3] = {1e-4, 1e-6, 1e-9};

/* max |q_a - q_b| at every period end over the horizon between two integrator settings
 * of the scene, or INFINITY on a fault. */
static double compare(const lag_scene *sc, const lag_integrator_def *a, const lag_integrator_def *b,
                      double period, double horizon)
{
    static lag_sim sa, sb;
    lag_sim_def da = sc->sim, db = sc->sim;
    da.integrator = *a;
    db.integrator = *b;
    char err[256];
    if (lag_sim_init(&sa, &da, err, sizeof err) != LAG_OK || lag_sim_init(&sb, &db, err, sizeof err) != LAG_OK) {
        LT_FAIL("init: %s", err);
        return INFINITY;
    }
    const int64_t na = llround(period / a->dt), nb = llround(period / b->dt);
    const int64_t nper = (int64_t)floor(horizon / period * (1 + 1e-12) + 1e-9);
    double emax = 0;
    for (int64_t k = 0; k < nper; k++) {
        if (lag_sim_advance(&sa, na, true) != LAG_OK || lag_sim_advance(&sb, nb, true) != LAG_OK)
            return INFINITY;
        lag_event ev;
        while (lag_sim_poll_event(&sa, &ev)) {}
        while (lag_sim_poll_event(&sb, &ev)) {}
        for (int i = 0; i < sa.nq; i++) emax = fmax(emax, fabs(sa.q[i] - sb.q[i]));
    }
    return emax;
}

static void case_scene(int arg)
{
    const int s = arg / 3;
    const double target = targets[arg % 3];
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/config/%s", LAGSIM_SOURCE_DIR, scene_names[s]);
    static lag_scene sc;
    if (lag_scene_load(path, NULL, 0, &sc, err, sizeof err) != 0) {
        LT_FAIL("%s", err);
        return;
    }
    lag_cost_opts o = lag_cost_opts_default();
    o.target = target;
    o.period = 1.0 / sc.publish_hz;
#ifdef LAGSIM_SANITIZED
    o.budget *= 10; /* ASan and UBSan at -O0 run the same work 10 to 30 times slower */
#endif
    lag_cost_table t;
    lag_result r = lag_cost_measure(&sc.sim, &o, &t, err, sizeof err);
    ENSURE(r == LAG_OK);
    if (r != LAG_OK) {
        LT_FAIL("%s: %s", scene_names[s], err);
        return;
    }
    printf("%s, E = %g: %d rows in %.3f s of CPU%s\n", scene_names[s], target, t.n, t.spent,
           t.budget_hit ? " (budget hit)" : "");
    for (int i = 0; i < t.n; i++) {
        char d[64];
        lag_cost_row_describe(&t.row[i], d, sizeof d);
        printf("  %-32s error %-10.3g cpu/sim-s %-10.3g %s%s\n", d, t.row[i].error,
               t.row[i].cpu_per_sim_s, t.row[i].meets ? "meets" : "",
               i == t.chosen ? " <- chosen" : "");
        if (t.row[i].tol == 0) { /* a fixed dt divides the period */
            double k = o.period / t.row[i].dt;
            ENSURE(fabs(k - round(k)) < 1e-9 * k);
        }
        ENSURE(t.row[i].meets == (t.row[i].error * o.safety <= target));
    }
    ENSURE(t.chosen >= 0);
    if (t.chosen < 0) return;
    for (int i = 0; i < t.n; i++)
        if (t.row[i].meets) ENSURE(t.row[t.chosen].cpu_per_sim_s <= t.row[i].cpu_per_sim_s);

    /* the claim, against an independent reference */
    lag_integrator_def chosen = lag_cost_row_integrator(&sc.sim, &t.row[t.chosen]);
    lag_integrator_def ref = sc.sim.integrator;
    ref.method = LAG_GAUSS4;
    ref.dt = o.period / 1024;
    double e = compare(&sc, &chosen, &ref, o.period, o.horizon);
    char d[64];
    lag_cost_row_describe(&t.row[t.chosen], d, sizeof d);
    ENSURE_NEAR(e, 0, target, "%s: %s against gauss4 at period/1024 over %g s", scene_names[s], d,
                o.horizon);
}

static void case_bad_options(int arg)
{
    (void)arg;
    lag_sim_def def = lag_default_sim_def(LAG_MODEL_DIPC);
    lag_cost_opts o = lag_cost_opts_default();
    lag_cost_table t;
    char err[256];
    o.target = 0;
    ENSURE(lag_cost_measure(&def, &o, &t, err, sizeof err) == LAG_ERR_ARG);
    o = lag_cost_opts_default();
    o.horizon = 1e-4; /* shorter than a period */
    ENSURE(lag_cost_measure(&def, &o, &t, err, sizeof err) == LAG_ERR_ARG);
    ENSURE(strstr(err, "period") != NULL);
    ENSURE(t.chosen == -1 && t.n == 0);
}

static int by_name(const void *a, const void *b)
{
    return strcmp((const char *)a, (const char *)b);
}

int main(int argc, char **argv)
{
    static lt_cases cs;
    int ns = 0;
    DIR *d = opendir(LAGSIM_SOURCE_DIR "/config");
    if (d) {
        struct dirent *e;
        while ((e = readdir(d)) && ns < MAX_SCENES) {
            size_t len = strlen(e->d_name);
            if (len > 5 && len < sizeof scene_names[0] && strcmp(e->d_name + len - 5, ".yaml") == 0)
                snprintf(scene_names[ns++], sizeof scene_names[0], "%s", e->d_name);
        }
        closedir(d);
    }
    qsort(scene_names, (size_t)ns, sizeof scene_names[0], by_name);
    for (int s = 0; s < ns; s++)
        for (int j = 0; j < 3; j++) {
            char base[64];
            snprintf(base, sizeof base, "%.*s", (int)strlen(scene_names[s]) - 5, scene_names[s]);
            snprintf(case_names[s * 3 + j], sizeof case_names[0], "%s_%.0e", base, targets[j]);
            lt_add(&cs, case_names[s * 3 + j], case_scene, s * 3 + j, 0);
        }
    lt_add(&cs, "bad_options", case_bad_options, 0, 0);
    if (ns == 0) fprintf(stderr, "no scenes in %s/config\n", LAGSIM_SOURCE_DIR);
    return lt_main(argc, argv, cs.c, cs.n);
}
