/*
 * Changes made while running (control_t SET key=value), shared by the real-time server,
 * which applies them when asked, and --replay, which applies them again where the log's
 * `set` events say they took effect. Both validate a change the same way: the scene
 * loader itself, on the scene file's bytes with its --set overrides, the changes made so
 * far and this one after them; so a change is accepted exactly when
 * `lagsimd --config FILE --set ... --set key=value` would start.
 */
#ifndef LAGSIMD_LIVE_SET_H
#define LAGSIMD_LIVE_SET_H

#include <stdbool.h>
#include <stddef.h>

#include "daemon.h"
#include "lagsim_wire.h"

#define LIVE_SET_MAX 64               /* distinct keys changed while running */
#define LIVE_SET_LEN LAG_WIRE_TEXT_LEN /* "key=value" with its NUL, as an event's detail */

/* The changes in the order they were applied, each "key=value"; a key set again replaces
 * the entries it overrides (itself and the keys below it), so the list stays short. */
typedef struct live_sets {
    char kv[LIVE_SET_MAX][LIVE_SET_LEN];
    int n;
} live_sets;

/* The cheap checks, before any parse: key is under parameters or effects (a dotted path
 * as --set takes it) and has no '=', value is not empty, "key=value" fits. On success
 * 0 with "key=value" in kv (LIVE_SET_LEN bytes); else -1 with the reason in why. */
int live_set_parse(const char *key, const char *value, char *kv, char *why, size_t whylen);

/* Loads the scene with the change kv after those in ls. On success 0 with the changed
 * scene in *out; else -1 with the loader's reason in why, shaped for the bus: the
 * message's location is said in words (the change itself, or "with the rest of the
 * scene" for a rule that a setting of the file breaks), never as file:line:column. */
int live_set_load(const lagsimd_opts *o, const live_sets *ls, const char *kv, lag_scene *out,
                  char *why, size_t whylen);

/* Records the applied change kv (after live_set_load accepted it): it replaces earlier
 * changes of the same key and of keys below it. */
void live_set_keep(live_sets *ls, const char *kv);

#endif
