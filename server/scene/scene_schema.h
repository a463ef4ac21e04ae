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

#endif
