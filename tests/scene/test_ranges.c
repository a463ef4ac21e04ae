/*
 * Every numeric scene key has a range that the loader (or the core, through the loader)
 * enforces at the key's file:line:column.
 *
 * The keys come from the loader's own key tables (scene_schema_each_number), for every
 * model of the core's table, so a numeric key added later is checked without editing
 * this test. For each key, a scene with only that key set to a huge positive and a huge
 * negative value (numbers: +-1e300; integers: +-1e20) must be refused, and the message
 * must point into the file at that key (or at a section enclosing it, when the section
 * itself is refused first, e.g. the floor effect on a model without a floor). The same
 * scene with the model's defaults is accepted, which shows that the generated YAML is
 * well formed and that the refusal is the value's.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_test.h"
#include "scene_yaml.h"
#include "scene.h"
#include "scene_schema.h"

typedef struct ctx {
    const char *model;
    int nq;
    int keys, failures;
} ctx;

static void check_key(void *vc, const char *path, bool integer)
{
    ctx *c = vc;
    c->keys++;
    const char *values[2] = {integer ? "100000000000000000000" : "1e300",
                             integer ? "-100000000000000000000" : "-1e300"};
    for (int v = 0; v < 2; v++) {
        char body[768], text[1024], err[1024];
        yaml_for(body, sizeof body, path, values[v], c->nq);
        snprintf(text, sizeof text, "model: %s\n%s\n", c->model, body);
        static lag_scene sc;
        bool accepted = lag_scene_load_buffer("t.yaml", text, strlen(text), NULL, 0, &sc, err,
                                              sizeof err) == 0;
        ENSUREF(!accepted, "%s: %s = %s accepted\n%s", c->model, path, values[v], text);
        if (accepted) {
            c->failures++;
            continue;
        }
        /* "t.yaml:2:C: PATH: ..." with PATH the key or a section enclosing it */
        const char *p = strstr(err, ": ");
        const char *named = p ? p + 2 : "";
        size_t nlen = strcspn(named, ":");
        bool at_key = strncmp(err, "t.yaml:2:", 9) == 0 && nlen > 0 &&
                      strncmp(named, path, nlen) == 0 &&
                      (path[nlen] == '\0' || path[nlen] == '.' || path[nlen] == '[');
        ENSUREF(at_key && !strstr(err, "unknown"), "%s: %s = %s: refused, but not at the key: %s",
                c->model, path, values[v], err);
        if (!at_key || strstr(err, "unknown")) c->failures++;
    }
}

static void case_ranges(int arg)
{
    (void)arg;
    int failures = 0, total = 0;
    for (int k = 0; k < LAG_MODEL_COUNT; k++) {
        const lag_model_info *info = lag_model_info_get((lag_model_kind)k);
        ctx c = {.model = info->name, .nq = info->nq};
        char text[64], err[1024];
        static lag_scene sc;
        snprintf(text, sizeof text, "model: %s\n", info->name);
        bool refused = lag_scene_load_buffer("t.yaml", text, strlen(text), NULL, 0, &sc, err,
                                             sizeof err) != 0;
        ENSUREF(!refused, "the defaults of %s are refused: %s", info->name, err);
        failures += refused;
        scene_schema_each_number((lag_model_kind)k, check_key, &c);
        printf("%s: %d numeric keys, %d failures\n", info->name, c.keys, c.failures);
        /* the walk itself must not come back empty */
        ENSUREF(c.keys >= 30, "only %d numeric keys listed for %s", c.keys, info->name);
        failures += c.keys < 30;
        failures += c.failures;
        total += c.keys;
    }
    printf("%d numeric keys over %d models, %d failures\n", total, LAG_MODEL_COUNT, failures);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"ranges", case_ranges, 0, 0}};
    return lt_main(argc, argv, cases, 1);
}
