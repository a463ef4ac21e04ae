/*
 * One rule, one place: a value of the core's definition that the core refuses is refused
 * with the core's own message (lag_sim_def_check's lag_diag), at the key's
 * file:line:column, never first by a second copy of the rule in the loader.
 *
 * For every numeric key of the loader's tables (scene_schema_each_number), for every
 * model: a scene with only that key at a small valid value x is loaded, and the field of
 * the core's definition that x landed in is found by comparing with the defaults. Then
 * -x and 0 are put into that field directly and given to the core: where the core refuses
 * and names this very key, loading the scene with -x (or 0) must give exactly
 * "t.yaml:2:C: <key>: <the core's message>". Keys the core never sees (publish_hz,
 * realtime.*, reference.*) and keys whose values the core names otherwise are the
 * loader's own (docs/scenes.md).
 */
#include <stdio.h>
#include <string.h>

#include "lagsim_test.h"
#include "scene_yaml.h"
#include "scene.h"
#include "scene_schema.h"

typedef struct ctx {
    const lag_model_info *info;
    lag_sim_def defaults;
    int keys, core_keys, compared, skipped;
} ctx;

static int load(const ctx *c, const char *path, const char *value, lag_scene *sc, char *err,
                size_t errlen)
{
    char body[768], text[1024];
    yaml_for(body, sizeof body, path, value, c->info->nq);
    snprintf(text, sizeof text, "model: %s\n%s\n", c->info->name, body);
    return lag_scene_load_buffer("t.yaml", text, strlen(text), NULL, 0, sc, err, errlen);
}

/* Where x landed in def (a double, or an int for integer keys), by comparison with the
 * defaults; -1 if nowhere. */
static long find_field(const lag_sim_def *def, const lag_sim_def *dflt, bool integer, double x)
{
    const unsigned char *a = (const unsigned char *)def, *b = (const unsigned char *)dflt;
    size_t step = integer ? sizeof(int) : sizeof(double);
    for (size_t o = 0; o + step <= sizeof *def; o += step) {
        if (memcmp(a + o, b + o, step) == 0) continue;
        if (integer) {
            int v;
            memcpy(&v, a + o, sizeof v);
            if (v == (int)x) return (long)o;
        } else {
            double v;
            memcpy(&v, a + o, sizeof v);
            if (v == x) return (long)o;
        }
    }
    return -1;
}

static void check_key(void *vc, const char *path, bool integer)
{
    ctx *c = vc;
    c->keys++;
    static const char *const xs_real[] = {"0.001", "0.5", "1"};
    static const char *const xs_int[] = {"1", "2"};
    const char *const *xs = integer ? xs_int : xs_real;
    int nx = integer ? 2 : 3;
    static lag_scene sc;
    char err[1024];
    double x = 0;
    int i = 0;
    for (; i < nx; i++)
        if (load(c, path, xs[i], &sc, err, sizeof err) == 0) break;
    if (i == nx) { /* never accepted alone (a stop needs both ends...): not comparable */
        c->skipped++;
        return;
    }
    x = atof(xs[i]);
    lag_sim_def plus = sc.sim;
    long off = find_field(&plus, &c->defaults, integer, x);
    if (off < 0) return; /* not a field of the core's definition */
    bool counted = false;
    for (int v = 0; v < 2; v++) {
        double bad = v ? 0.0 : -x;
        lag_sim_def d = plus;
        if (integer) {
            int iv = (int)bad;
            memcpy((unsigned char *)&d + off, &iv, sizeof iv);
        } else {
            memcpy((unsigned char *)&d + off, &bad, sizeof bad);
        }
        lag_diag dg;
        if (lag_sim_def_check(&d, &dg) == LAG_OK || strcmp(dg.field, path) != 0) continue;
        if (!counted) c->core_keys++;
        counted = true;
        char value[32], want[LAG_FIELD_MAX + 300];
        snprintf(value, sizeof value, v ? "0" : "-%s", xs[i]);
        snprintf(want, sizeof want, ": %s: %s", dg.field, dg.message);
        int rc = load(c, path, value, &sc, err, sizeof err);
        c->compared++;
        if (rc == 0 || strncmp(err, "t.yaml:2:", 9) != 0 || !strstr(err, want) ||
            strlen(strstr(err, want)) != strlen(want))
            LT_FAIL("%s: %s = %s: the core says \"%s: %s\", the loader said \"%s\"", c->info->name,
                    path, value, dg.field, dg.message, rc == 0 ? "(accepted)" : err);
        else
            ENSURE(true);
    }
}

static void case_core_messages(int arg)
{
    (void)arg;
    int compared = 0;
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        ctx c = {.info = lag_model_info_get((lag_model_kind)k)};
        static lag_scene sc;
        char text[64], err[1024];
        snprintf(text, sizeof text, "model: %s\n", c.info->name);
        ENSURE(lag_scene_load_buffer("t.yaml", text, strlen(text), NULL, 0, &sc, err, sizeof err) == 0);
        c.defaults = sc.sim;
        scene_schema_each_number((lag_model_kind)k, check_key, &c);
        printf("%s: %d numeric keys, %d checked by the core (%d values compared), %d not "
               "settable alone\n", c.info->name, c.keys, c.core_keys, c.compared, c.skipped);
        compared += c.compared;
    }
    ENSURE(compared > 0);
}

static const lt_case cases[] = {
    {"core_messages", case_core_messages, 0, 0},
};

int main(int argc, char **argv)
{
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
