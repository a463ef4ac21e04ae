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
#include "lagsim/lagsim.h"
#include "lagsim_wire.h"

#define LIVE_SET_MAX 64               /* distinct keys changed while running */
#define LIVE_SET_LEN LAG_WIRE_TEXT_LEN /* "key=value" with its NUL, as an event's detail */

/* A kick: a disturbance applied at the tick it was asked for (control_t SET with key
 * "kick.<joint>"), added to the scene's own disturbances and to the other kicks. */
typedef struct live_kick {
    int64_t step;      /* the tick it starts at */
    int joint;         /* index among the model's joints */
    double impulse;    /* N s or N m s */
    double duration;   /* s; 0: an impulse at that tick, else a force impulse/duration */
} live_kick;

/* The changes in the order they were applied, each "key=value"; a key set again replaces
 * the entries it overrides (itself and the keys below it), so the list stays short. The
 * kicks are kept beside them: they are not scene keys (live_kick_apply). */
typedef struct live_sets {
    char kv[LIVE_SET_MAX][LIVE_SET_LEN];
    int n;
    live_kick kick[LAG_MAX_DISTURBANCES]; /* kicks not over yet, oldest first */
    int nk;
} live_sets;

/* The cheap checks, before any parse: key is under parameters, effects or reference (a dotted path
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

/* Is kv (or key) a kick, "kick.<joint>=<impulse>[,<duration>]"? */
bool live_is_kick(const char *key);

/* A kick, at the tick sim is at: "kick.<joint>=<impulse>[,<duration>]" (N s or N m s; s,
 * default 0: an impulse at this tick, else a force impulse/duration held for duration s).
 * It adds to the scene's disturbances and to the kicks not over yet (those over are
 * dropped first); the definition is changed with lag_sim_redefine, as a SET's. The
 * daemon and --replay call it at the same tick with the same kv, so a replay is exact.
 * On success 0 with the kick in *k; else -1 with the reason in why. */
int live_kick_apply(live_sets *ls, lag_sim *sim, const char *kv, live_kick *k, char *why,
                    size_t whylen);

/* Adds the kicks not over yet to def's disturbances (after a SET's reload: a change of
 * the scene keeps them). -1 with a reason when they do not fit. */
int live_kicks_append(const live_sets *ls, lag_sim_def *def, char *why, size_t whylen);

/* At a reset: drops every kick (sim time starts over: they belong to the run before it)
 * from ls and from sim's definition. The daemon says so with a `kicks_cleared` event,
 * which --replay applies where the log has it (a kick after the reset stays). */
void live_kicks_clear(live_sets *ls, lag_sim *sim);

/* The changes kept, "key=value, key=value" (kicks not counted), for a reset's answer. */
void live_set_describe(const live_sets *ls, char *out, size_t outlen);

#endif
