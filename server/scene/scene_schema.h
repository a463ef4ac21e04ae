/*
 * The scene schema (private to the scene loader): a YAML tree (scene_yaml.h) -> a checked
 * lag_scene. Every key, its type, its range and its relations to other keys live in
 * scene_schema.c; docs/scenes.md lists them.
 */
#ifndef LAGSIM_SCENE_SCHEMA_H
#define LAGSIM_SCENE_SCHEMA_H

#include "scene.h"
#include "scene_yaml.h"

/* Reads the merged tree into sc (path: the scene file's name, kept in sc->path). Every
 * error names its node ("file:line:column: key.path: what was expected"). OUT: sc */
int scene_schema_convert(const ynode *root, const char *path, lag_scene *sc, errbuf *err);

/* Calls fn for every numeric key a scene of this model may have, by its path
 * ("integrator.dt", "effects.damping.theta1", "initial.q[2]", "effects.disturbance[0].t"),
 * integer says whether it takes an integer. From the key tables themselves, so a key added
 * there is listed here: tests/scene/test_ranges.c checks that each one has a range. */
typedef void (*scene_number_fn)(void *ctx, const char *path, bool integer);
void scene_schema_each_number(lag_model_kind kind, scene_number_fn fn, void *ctx);

#endif
