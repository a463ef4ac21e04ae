/*
 * The core's effect table (and its model table, in the docs) against everything that
 * names them: each consumer must agree with it row for row, so that an effect added to
 * the core (or renamed) shows up everywhere or fails here by name.
 *
 *   loader         every row's key turns on exactly its bit (for some model), and every
 *                  effect key of the loader's tables but gravity is a row
 *   scene_message  the daemon's scene message names each row's effect when it is on
 *                  (a scene with that effect alone, through rt_open on memq://), and the
 *                  message's effects field can hold every row's name at once
 *   keeps_state    a row that says it keeps no state of its own restarts exactly from
 *                  (q, qd, tick), state and published state, which is what replay takes
 *                  it at (replay.c)
 *   view           every effect the browser view asks about (view.js, hasEffect) is a row,
 *                  and its table of drawings (DRAW) has one per model of the core's model
 *                  table and none besides
 *   docs           docs/effects.md's table of effects and docs/scenes.md's table of
 *                  ranges list every row, and name no effect the core does not have
 *                  (prose, written by hand; the lists that can be generated are:
 *                  server/lists, structure_lists)
 *   docs_channels  docs/protocol.md's table of channels and lagsimd.1's CHANNELS name the
 *                  bus's channels (lagsim_bus.c's table), each once, and no other
 *   docs_keys      every numeric key of the loader's tables, for every model, has its row
 *                  in docs/scenes.md's table of ranges (reference keys: in the table of
 *                  the reference's keys), by its pattern (<joint>, <name>, [i])
 *
 * Files are read from the source tree (LAGSIM_SOURCE_DIR).
 */
#include <lcm/lcm.h>
#include <stdio.h>
#include <string.h>

#include "lagsim_test.h"
#include "lagsim_wire.h"
#include "rt_server.h"
#include "scene.h"
#include "scene_schema.h"

/* ---------------------------------------------------------------- helpers */

static bool is_row(const char *name, size_t len)
{
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        const char *r = lag_effect_info_get(k).name;
        if (r && strlen(r) == len && strncmp(r, name, len) == 0) return true;
    }
    return false;
}

/* A scene of model `kind` with the effect `name` turned on by the YAML value `value`
 * (memq://, prefix TT); 0 when the loader accepts it. */
static int load_with(lag_scene *sc, int kind, const char *name, const char *value, char *err,
                     size_t errlen)
{
    char text[512];
    snprintf(text, sizeof text,
             "model: %s\nrealtime: {mode: fast}\nlcm: {url: \"memq://\", prefix: TT}\n"
             "effects:\n  %s: %s\n",
             lag_model_info_get((lag_model_kind)kind)->name, name, value);
    return lag_scene_load_buffer("t.yaml", text, strlen(text), NULL, 0, sc, err, errlen);
}

/* Finds a model and an empty value under which the loader accepts effect row k alone;
 * returns the model, or -1. */
static int load_row(lag_scene *sc, int k)
{
    static const char *const values[] = {"{}", "[]", "~"};
    const char *name = lag_effect_info_get(k).name;
    for (int kind = 0; kind < LAG_MODEL_COUNT; kind++)
        for (size_t v = 0; v < sizeof values / sizeof values[0]; v++) {
            char err[512];
            if (load_with(sc, kind, name, values[v], err, sizeof err) == 0) return kind;
        }
    return -1;
}

/* Reads a whole file of the source tree into buf; false if it cannot. */
static bool read_source(const char *rel, char *buf, size_t len)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", LAGSIM_SOURCE_DIR, rel);
    FILE *f = fopen(path, "rb");
    if (!f) {
        LT_FAIL("cannot read %s", path);
        return false;
    }
    size_t n = fread(buf, 1, len - 1, f);
    buf[n] = '\0';
    fclose(f);
    if (n == len - 1) LT_FAIL("%s is larger than the test's buffer", path);
    return n < len - 1;
}

/* ---------------------------------------------------------------- loader */

static void each_effect_key(void *vc, const char *path, bool integer)
{
    (void)integer;
    int *bad = vc;
    if (strncmp(path, "effects.", 8) != 0) return;
    const char *name = path + 8;
    size_t len = strcspn(name, ".[");
    if ((len == 7 && strncmp(name, "gravity", 7) == 0) || is_row(name, len)) return;
    LT_FAIL("loader: scene key %s names an effect '%.*s' the core's table does not have", path,
            (int)len, name);
    (*bad)++;
}

static void case_loader(int arg)
{
    (void)arg;
    static lag_scene sc;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        lag_effect_info e = lag_effect_info_get(k);
        int kind = load_row(&sc, k);
        if (kind < 0) {
            char err[512];
            load_with(&sc, 0, e.name, "{}", err, sizeof err);
            LT_FAIL("loader: effect '%s' of the core's table is refused by the loader for every "
                    "model (%s)", e.name, err);
            continue;
        }
        ENSURE(sc.sim.effects.enabled == e.bit);
        printf("loader: effects.%s turns on its bit (model %s)\n", e.name,
               lag_model_info_get((lag_model_kind)kind)->name);
    }
    int bad = 0;
    for (int kind = 0; kind < LAG_MODEL_COUNT; kind++)
        scene_schema_each_number((lag_model_kind)kind, each_effect_key, &bad);
    ENSURE(bad == 0);
}

/* ---------------------------------------------------------------- scene message */

static lag_wire_scene g_scene;
static int g_scenes;

static void on_scene(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch, (void)user;
    if (lag_wire_decode_scene(rb->data, rb->data_size, LAG_WIRE_MAX_JOINTS, &g_scene) == LAG_WIRE_OK) g_scenes++;
}

static void case_scene_message(int arg)
{
    (void)arg;
    /* every row's name at once, comma-separated, within the message's field */
    size_t all = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) all += strlen(lag_effect_info_get(k).name) + (k ? 1 : 0);
    if (all >= sizeof g_scene.effects)
        LT_FAIL("scene message: the effects field holds %zu bytes, every effect's name takes %zu",
                sizeof g_scene.effects - 1, all);
    else
        ENSURE(all < sizeof g_scene.effects);

    lcm_t *lcm = lcm_create("memq://");
    ENSURE(lcm != NULL);
    if (!lcm) return;
    lcm_subscribe(lcm, "TT_SCENE", on_scene, NULL);
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        lag_effect_info e = lag_effect_info_get(k);
        static lag_scene sc;
        static rt_server srv;
        if (load_row(&sc, k) < 0) {
            LT_FAIL("scene message: no scene turns effect '%s' on (see the loader case)", e.name);
            continue;
        }
        lagsimd_opts o = {.quiet = true};
        char err[512];
        g_scenes = 0;
        memset(&g_scene, 0, sizeof g_scene);
        if (rt_open(&srv, &sc, &o, 1000000000LL, true, err, sizeof err) != 0) {
            LT_FAIL("scene message: rt_open refuses the scene with effect '%s': %s", e.name, err);
            continue;
        }
        ENSURE(rt_attach(&srv, lcm, lcm, err, sizeof err) == 0);
        rt_begin(&srv);
        while (lcm_handle_timeout(lcm, 0) > 0) {
        }
        rt_finish(&srv);
        rt_close(&srv);
        while (lcm_handle_timeout(lcm, 0) > 0) {
        }
        ENSURE(g_scenes >= 1);
        if (strcmp(g_scene.effects, e.name) != 0)
            LT_FAIL("scene message: with only effect '%s' on, the scene message says effects "
                    "\"%s\"", e.name, g_scene.effects);
        else
            ENSURE(true);
        printf("scene message: effect '%s' alone -> effects \"%s\"\n", e.name, g_scene.effects);
    }
    lcm_destroy(lcm);
}

/* ---------------------------------------------------------------- keeps_state */

/* Row k on alone (settings that make it act: damping, a spring, a disturbance at 10 ms...),
 * on the first model whose core accepts them, rk4. */
static bool acting_def(int k, lag_sim_def *out)
{
    for (int kind = 0; kind < LAG_MODEL_COUNT; kind++) {
        lag_sim_def d = lag_default_sim_def((lag_model_kind)kind);
        d.q0[0] = 0.2; d.q0[1] = 0.7; d.qd0[0] = 0.3; d.qd0[1] = -0.4;
        lag_effects_def *e = &d.effects;
        for (int i = 0; i < LAG_MAX_DOF; i++) {
            e->damping[i] = 3.0; e->friction_static[i] = 2.0; e->friction_kinetic[i] = 1.0;
            e->limit_on[i] = true; e->limit_lower[i] = d.q0[i] - 0.01; e->limit_upper[i] = d.q0[i] + 0.01;
            e->restitution[i] = 0.5; e->actuator_max[i] = 0.1; e->actuator_tau[i] = 0.3;
            e->noise_q[i] = 0.1; e->noise_qd[i] = 0.1; e->spring_k[i] = 4.0; e->spring_rest[i] = 0.1;
        }
        e->n_disturbances = 2;
        e->disturbances[0] = (lag_disturbance){0.01, 0, true, 5.0, 0.0};
        e->disturbances[1] = (lag_disturbance){0.1, 0, false, 2.0, 0.1};
        e->enabled = lag_effect_info_get(k).bit;
        lag_diag dg;
        if (lag_sim_def_check(&d, &dg) == LAG_OK) {
            *out = d;
            return true;
        }
    }
    return false;
}

static void case_keeps_state(int arg)
{
    (void)arg;
    int checked = 0;
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        lag_effect_info e = lag_effect_info_get(k);
        if (e.keeps_state) continue;
        lag_sim_def d;
        if (!acting_def(k, &d)) {
            LT_FAIL("keeps_state: no model accepts effect '%s' with the test's settings", e.name);
            continue;
        }
        /* one run of 3 s; another stopped at 1.5 s (a stop, friction holding) and restarted */
        static lag_sim a, b, c;
        char err[256];
        double u[3] = {0.5, -0.3, 0.0};
        ENSURE(lag_sim_init(&a, &d, err, sizeof err) == LAG_OK);
        ENSURE(lag_sim_init(&b, &d, err, sizeof err) == LAG_OK);
        ENSURE(lag_sim_init(&c, &d, err, sizeof err) == LAG_OK);
        lag_sim_set_input(&a, u);
        lag_sim_set_input(&b, u);
        ENSURE(lag_sim_advance(&a, 3000, true) == LAG_OK);
        ENSURE(lag_sim_advance(&b, 1500, true) == LAG_OK);
        lag_sim_reset(&c, b.q, b.qd);
        c.tick = b.tick;
        lag_sim_set_input(&c, u);
        ENSURE(lag_sim_advance(&c, 1500, true) == LAG_OK);
        size_t nb = (size_t)a.nq * sizeof(double);
        double oa[6] = {0}, oc[6] = {0}; /* the published state too (noise) */
        lag_sim_observe(&a, oa, oa + 3);
        lag_sim_observe(&c, oc, oc + 3);
        if (memcmp(a.q, c.q, nb) != 0 || memcmp(a.qd, c.qd, nb) != 0 || memcmp(oa, oc, sizeof oa) != 0)
            LT_FAIL("keeps_state: effect '%s' says it keeps no state, but a restart from (q, qd, "
                    "tick) departs from the run (q[0] %.17g vs %.17g, observed %.17g vs %.17g)",
                    e.name, c.q[0], a.q[0], oc[0], oa[0]);
        else
            ENSURE(true);
        checked++;
    }
    printf("keeps_state: %d effects without state of their own restart exactly\n", checked);
}

/* ---------------------------------------------------------------- view, docs */

static char g_text[1 << 20];

/* view.js's DRAW = { name: function, "a-name": function, ... }: its keys are exactly the
 * core's models (a model without a drawing shows only its numbers; a key no model has is
 * dead code). */
static void view_drawings(void)
{
    const char *p = strstr(g_text, "const DRAW = {");
    const char *end = p ? strstr(p, "};") : NULL;
    if (!p || !end) {
        LT_FAIL("view: view.js has no `const DRAW = { ... };` any more (the test's landmark)");
        return;
    }
    bool drawn[LAG_MODEL_COUNT] = {false};
    for (p += strlen("const DRAW = {"); p < end;) {
        p += strspn(p, " \n,\"");
        size_t len = strcspn(p, "\": ");
        if (p >= end || len == 0) break;
        int k = -1;
        for (int m = 0; m < LAG_MODEL_COUNT; m++) {
            const char *name = lag_model_info_get((lag_model_kind)m)->name;
            if (strlen(name) == len && strncmp(name, p, len) == 0) k = m;
        }
        if (k < 0)
            LT_FAIL("view: view.js draws a model '%.*s' the core's table does not have", (int)len, p);
        else
            drawn[k] = true;
        p = strchr(p, ',') ? strchr(p, ',') : end; /* past its function */
    }
    int n = 0;
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        if (!drawn[k])
            LT_FAIL("view: view.js has no drawing for model '%s' (a DRAW entry, "
                    "server/view/page/view.js)", lag_model_info_get((lag_model_kind)k)->name);
        else
            ENSURE(drawn[k]);
        n += drawn[k];
    }
    printf("view: a drawing for %d of the %d models of the core's table\n", n, LAG_MODEL_COUNT);
}

static void case_view(int arg)
{
    (void)arg;
    if (!read_source("server/view/page/view.js", g_text, sizeof g_text)) return;
    int asked = 0;
    for (const char *p = g_text; (p = strstr(p, "hasEffect(\"")) != NULL; p++) {
        const char *name = p + strlen("hasEffect(\"");
        size_t len = strcspn(name, "\"");
        asked++;
        if (!is_row(name, len))
            LT_FAIL("view: view.js asks for an effect '%.*s' the core's table does not have",
                    (int)len, name);
        else
            ENSURE(true);
    }
    printf("view: %d questions about effects, each by a name of the core's table\n", asked);
    view_drawings();
}

/* The part of `file` from `start` to the next `end`: every row of the core's table appears
 * there as `before NAME` followed by one of the characters `after`, and every such
 * `before WORD` is a row (or one of `others`, which ends with NULL). */
static void doc_lists(const char *file, const char *start, const char *end, const char *before,
                      const char *after, const char *const *others)
{
    if (!read_source(file, g_text, sizeof g_text)) return;
    char *from = strstr(g_text, start);
    if (!from) {
        LT_FAIL("docs: %s has no \"%s\" any more (the test's landmark)", file, start);
        return;
    }
    char *to = strstr(from + strlen(start), end);
    if (to) *to = '\0';
    size_t bl = strlen(before);
    bool listed[LAG_EFF_COUNT] = {false};
    for (const char *p = from; (p = strstr(p, before)) != NULL; p += bl) {
        const char *w = p + bl;
        size_t len = 0;
        while ((w[len] >= 'a' && w[len] <= 'z') || w[len] == '_') len++;
        if (len == 0 || !w[len] || !strchr(after, w[len])) continue;
        bool other = false;
        for (int a = 0; others[a]; a++) other |= strlen(others[a]) == len && strncmp(others[a], w, len) == 0;
        for (int k = 0; k < LAG_EFF_COUNT; k++) {
            const char *r = lag_effect_info_get(k).name;
            if (strlen(r) == len && strncmp(r, w, len) == 0) listed[k] = other = true;
        }
        if (!other)
            LT_FAIL("docs: %s lists an effect '%.*s' the core's table does not have", file, (int)len, w);
    }
    for (int k = 0; k < LAG_EFF_COUNT; k++) {
        if (!listed[k])
            LT_FAIL("docs: %s does not list effect '%s' of the core's table (after \"%s\")", file,
                    lag_effect_info_get(k).name, start);
        else
            ENSURE(listed[k]);
    }
}

static void case_docs(int arg)
{
    (void)arg;
    /* gravity is the model's parameter g, not a row of the table */
    static const char *const others[] = {"gravity", NULL};
    /* effects.md: its table of effects and its example `effects:` section */
    doc_lists("docs/effects.md", "| effect | keys |", "\n\n", "\n| ", " ", others);
    doc_lists("docs/effects.md", "```yaml\neffects:\n", "```", "\n  ", ":", others);
    /* scenes.md: the table of ranges */
    doc_lists("docs/scenes.md", "| key | range | unit |", "\n\n", "`effects.", ".[`", others);
}

/* ---------------------------------------------------------------- docs_channels */

/* Counts, in `text` from `start` to `end`, each `before SUFFIX after` of the bus's channels
 * and any other `before X after` of capitals; fails on a channel named other than once. */
static void doc_channels(const char *file, const char *start, const char *end, const char *before,
                         const char *after)
{
    if (!read_source(file, g_text, sizeof g_text)) return;
    char *from = strstr(g_text, start), *to = from ? strstr(from, end) : NULL;
    if (!from || !to) {
        LT_FAIL("docs_channels: %s has no \"%s\" ... \"%s\" any more (the test's landmarks)", file,
                start, end);
        return;
    }
    *to = '\0';
    int seen[LAG_BUS_CHANNEL_COUNT] = {0};
    for (const char *p = from; (p = strstr(p, before)) != NULL; p++) {
        const char *w = p + strlen(before);
        size_t len = strspn(w, "_ABCDEFGHIJKLMNOPQRSTUVWXYZ");
        if (len == 0 || strncmp(w + len, after, strlen(after)) != 0) continue;
        int c = -1;
        for (int k = 0; k < LAG_BUS_CHANNEL_COUNT; k++) {
            const char *suf = lag_bus_suffix((lag_bus_channel)k);
            if (strlen(suf) == len && strncmp(suf, w, len) == 0) c = k;
        }
        if (c < 0)
            LT_FAIL("docs_channels: %s names a channel %.*s the bus's table does not have", file,
                    (int)len, w);
        else
            seen[c]++;
    }
    for (int k = 0; k < LAG_BUS_CHANNEL_COUNT; k++) {
        if (seen[k] != 1)
            LT_FAIL("docs_channels: %s names channel <PREFIX>%s %d times (once, in its list)", file,
                    lag_bus_suffix((lag_bus_channel)k), seen[k]);
        else
            ENSURE(seen[k] == 1);
    }
}

static void case_docs_channels(int arg)
{
    (void)arg;
    doc_channels("docs/protocol.md", "| channel | type |", "\n\n", "\n| `<PREFIX>", "` |");
    doc_channels("docs/man/lagsimd.1", ".SH CHANNELS", ".SH SIGNALS", "\n.IB PREFIX ", "\n");
    printf("docs_channels: the bus's %d channels looked for in protocol.md's table and lagsimd.1\n",
           LAG_BUS_CHANNEL_COUNT);
}

/* ---------------------------------------------------------------- docs_keys */

#define MAX_KEYS 256
typedef struct keyset {
    int n;
    char key[MAX_KEYS][96];
} keyset;

static void keyset_add(keyset *ks, const char *k)
{
    for (int i = 0; i < ks->n; i++)
        if (strcmp(ks->key[i], k) == 0) return;
    if (ks->n < MAX_KEYS) snprintf(ks->key[ks->n++], sizeof ks->key[0], "%s", k);
}

static bool keyset_has(const keyset *ks, const char *k)
{
    for (int i = 0; i < ks->n; i++)
        if (strcmp(ks->key[i], k) == 0) return true;
    return false;
}

/* A loader path as the docs write it: a joint of the model as <joint>, a parameter as
 * <name>, an index as [*] ("effects.damping.theta1" -> "effects.damping.<joint>"). */
typedef struct key_walk {
    const lag_model_info *info;
    keyset *out;
} key_walk;

static void each_key(void *vc, const char *path, bool integer)
{
    (void)integer;
    key_walk *w = vc;
    char out[96] = "", part[96];
    bool params = strncmp(path, "parameters.", 11) == 0;
    for (const char *p = path; *p;) {
        size_t len = strcspn(p, ".[");
        snprintf(part, sizeof part, "%.*s", (int)len, p);
        bool joint = false;
        for (int j = 0; j < w->info->nq; j++) joint |= strcmp(part, w->info->joint_names[j]) == 0;
        const char *as = p != path && params ? "<name>" : joint ? "<joint>" : part;
        snprintf(out + strlen(out), sizeof out - strlen(out), "%s", as);
        p += len;
        if (*p == '[') {
            snprintf(out + strlen(out), sizeof out - strlen(out), "[*]");
            p = strchr(p, ']') ? strchr(p, ']') + 1 : p + strlen(p);
        }
        if (*p == '.') {
            snprintf(out + strlen(out), sizeof out - strlen(out), ".");
            p++;
        }
    }
    keyset_add(w->out, out);
}

/* The keys docs/scenes.md's table of ranges names in its first column: each `path` (its
 * [i], [k] as [*]); a `.suffix` after a path replaces as many of that path's last parts
 * ("`effects.friction.<joint>.static`, `.kinetic`"). */
static void documented_keys(const char *table, keyset *doc)
{
    for (const char *row = table; row && row[0] == '|'; row = strchr(row, '\n') ? strchr(row, '\n') + 1 : NULL) {
        const char *cell_end = strchr(row + 1, '|');
        char prev[200] = "";
        for (const char *p = row; (p = strchr(p, '`')) && cell_end && p < cell_end;) {
            const char *e = strchr(p + 1, '`');
            if (!e || e > cell_end) break;
            char tok[96], key[200];
            snprintf(tok, sizeof tok, "%.*s", (int)(e - p - 1), p + 1);
            if (tok[0] == '.' && prev[0]) { /* a suffix of the previous path */
                int parts = 0;
                for (const char *c = tok; *c; c++) parts += *c == '.';
                char *cut = prev + strlen(prev);
                for (; parts > 0 && cut > prev; parts--) { /* back over one ".part" */
                    cut--;
                    while (cut > prev && *cut != '.') cut--;
                }
                snprintf(key, sizeof key, "%.*s%s", (int)(cut - prev), prev, tok);
            } else {
                snprintf(key, sizeof key, "%s", tok);
            }
            char canon[200] = "";
            for (const char *c = key; *c; c++) { /* [i], [k] -> [*] */
                if (*c == '[' && strchr(c, ']')) {
                    strcat(canon, "[*]");
                    c = strchr(c, ']');
                } else {
                    size_t n = strlen(canon);
                    if (n + 1 < sizeof canon) canon[n] = *c, canon[n + 1] = '\0';
                }
            }
            keyset_add(doc, canon);
            snprintf(prev, sizeof prev, "%s", key);
            p = e + 1;
        }
    }
}

static void case_docs_keys(int arg)
{
    (void)arg;
    static keyset loader, doc;
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        key_walk w = {lag_model_info_get((lag_model_kind)k), &loader};
        scene_schema_each_number((lag_model_kind)k, each_key, &w);
    }
    if (!read_source("docs/scenes.md", g_text, sizeof g_text)) return;
    const char *ranges = strstr(g_text, "| key | range | unit |");
    const char *refs = strstr(g_text, "| key | kinds | range | default |");
    if (!ranges || !refs) {
        LT_FAIL("docs_keys: docs/scenes.md has no table of ranges or of the reference's keys "
                "any more (the test's landmarks)");
        return;
    }
    documented_keys(strchr(ranges, '\n') + 1, &doc);
    int found = 0;
    for (int i = 0; i < loader.n; i++) {
        const char *key = loader.key[i];
        char want[128];
        bool ref = strncmp(key, "reference.<joint>.", 18) == 0;
        snprintf(want, sizeof want, "\n| `%s` |", key + (ref ? 18 : 0));
        bool ok = ref ? strstr(refs, want) != NULL : keyset_has(&doc, key);
        if (!ok)
            LT_FAIL("docs_keys: the loader's key %s has no row in docs/scenes.md's %s", key,
                    ref ? "table of the reference's keys" : "table of ranges");
        else
            ENSURE(ok);
        found += ok;
    }
    printf("docs_keys: %d of the loader's %d numeric key patterns documented in docs/scenes.md\n",
           found, loader.n);
}

static const lt_case cases[] = {
    {"loader", case_loader, 0, 0},           {"scene_message", case_scene_message, 0, 0},
    {"keeps_state", case_keeps_state, 0, 0}, {"view", case_view, 0, 0},
    {"docs", case_docs, 0, 0},              {"docs_keys", case_docs_keys, 0, 0},
    {"docs_channels", case_docs_channels, 0, 0},
};

int main(int argc, char **argv)
{
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
