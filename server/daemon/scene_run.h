/*
 * The scene as a run uses it (scene_run.c): read from its file's bytes with the --set
 * overrides, with the integrator integrator.error chooses, and LCM_DEFAULT_URL where the
 * scene names no URL. One place for lagsimd's command line (main.c) and a host's plants
 * (host.c), which load a scene at start and again when its file changes.
 */
#ifndef LAGSIMD_SCENE_RUN_H
#define LAGSIMD_SCENE_RUN_H

#include <stdbool.h>
#include <stddef.h>
#include "daemon.h"

/* What the scene is loaded for. */
typedef struct scene_run_how {
    bool cost;     /* --cost: as the file says, nothing chosen */
    bool replay;   /* --replay: integrator.error needs the integrator given by --set */
    bool offline;  /* --offline: a scene no setting meets runs with a warning */
    bool quiet;    /* -q */
} scene_run_how;

/* Loads name's bytes (text, len) with the overrides sets[0..*nsets) and, with
 * integrator.error, the integrator the calibration chooses (appended to sets, which has
 * room for 4 more: lagsimd_choice; *nsets grows by them), into sc. Prints why on failure:
 * LAG_ERR_SCENE (the loader's file:line:column) or LAG_ERR_USAGE (a choice refused).
 * OUT: sc, choice */
lag_result scene_run_load(const char *name, const char *text, size_t len, const char **sets,
                          int *nsets, scene_run_how how, lagsimd_choice *choice, lag_scene *sc);
/* A scene with no lcm.url takes LCM_DEFAULT_URL, checked as the loader checks lcm.url (the
 * scene's allow_lan, its ttl). Returns LAG_OK, or LAG_ERR_SCENE after printing why (exit 2:
 * nothing has run). */
lag_result scene_run_default_url(lag_scene *sc);

#endif
