/*
 * Changes made while running (control_t SET): validated by the scene loader on the
 * scene's own bytes; see live_set.h.
 */
#include "live_set.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int live_set_parse(const char *key, const char *value, char *kv, char *why, size_t whylen)
{
    if (!lag_scene_key_live(key) || strchr(key, '=')) {
        snprintf(why, whylen, "set: only keys under parameters, effects and reference change "
                              "while running (e.g. parameters.m2, effects.friction.q2.kinetic, "
                              "reference.q1.amplitude)");
        return -1;
    }
    if (!value[0] || snprintf(kv, LIVE_SET_LEN, "%s=%s", key, value) >= LIVE_SET_LEN) {
        snprintf(why, whylen, "set: the value is empty, or key=value is longer than %d bytes",
                 LIVE_SET_LEN - 1);
        return -1;
    }
    return 0;
}

/* Does s start with "name:L:C" (L, C decimal)? Returns its length, else 0. */
static size_t location_at(const char *s, const char *name)
{
    size_t n = strlen(name);
    if (n == 0 || strncmp(s, name, n) != 0) return 0;
    for (int part = 0; part < 2; part++) {
        if (s[n] != ':' || s[n + 1] < '0' || s[n + 1] > '9') return 0;
        n++;
        while (s[n] >= '0' && s[n] <= '9') n++;
    }
    return n;
}

/* The loader's message for the bus: the change's own "--set key: " goes (the answer names
 * the change already); a leading "file:line:column: " (a rule that a setting of the file
 * breaks with the change, e.g. the initial state outside a new stop) becomes words, and
 * so does any other mention of a place in the file. */
static void shape(const char *msg, const char *name, const char *kv, char *out, size_t outlen)
{
    char own[LIVE_SET_LEN + 8];
    size_t klen = strcspn(kv, "=");
    snprintf(own, sizeof own, "--set %.*s: ", (int)klen, kv);
    size_t o = 0;
    const char *p = msg;
    if (!strncmp(p, own, strlen(own))) {
        p += strlen(own);
    } else {
        size_t loc = location_at(p, name);
        if (loc && p[loc] == ':' && p[loc + 1] == ' ') {
            o += (size_t)snprintf(out, outlen, "with the rest of the scene: ");
            p += loc + 2;
        }
    }
    while (*p && o + 1 < outlen) {
        size_t loc = location_at(p, name);
        if (loc) {
            int w = snprintf(out + o, outlen - o, "the scene file");
            o += w < 0 ? 0 : (size_t)w;
            if (o >= outlen) o = outlen - 1;
            p += loc;
        } else {
            out[o++] = *p++;
        }
    }
    if (outlen) out[o < outlen ? o : outlen - 1] = '\0';
}

/* Is entry e overridden by a change of the key that kv sets (the same key, or one below)? */
static bool overrides(const char *kv, const char *e)
{
    size_t klen = strcspn(kv, "=");
    return !strncmp(e, kv, klen) && (e[klen] == '=' || e[klen] == '.');
}

int live_set_load(const lagsimd_opts *o, const live_sets *ls, const char *kv, lag_scene *out,
                  char *why, size_t whylen)
{
    if (!o || !o->scene_text) {
        snprintf(why, whylen, "set: no scene source to validate a change against");
        return -1;
    }
    bool room = ls->n < LIVE_SET_MAX;
    for (int i = 0; !room && i < ls->n; i++) room = overrides(kv, ls->kv[i]);
    if (!room) {
        snprintf(why, whylen, "set %s: %d distinct keys have been changed while running, the "
                              "most: set a whole group instead (e.g. effects.friction)",
                 kv, LIVE_SET_MAX);
        return -1;
    }
    /* the scene's --set overrides, the changes so far, this one */
    int nbase = o->nsets, n = nbase + ls->n + 1;
    const char **all = malloc(sizeof *all * (size_t)n);
    if (!all) {
        snprintf(why, whylen, "set: out of memory");
        return -1;
    }
    for (int i = 0; i < nbase; i++) all[i] = o->sets[i];
    for (int i = 0; i < ls->n; i++) all[nbase + i] = ls->kv[i];
    all[n - 1] = kv;
    char err[512];
    int rc = lag_scene_load_buffer(o->scene_name, o->scene_text, o->scene_len, all, n, out, err,
                                   sizeof err);
    free(all);
    if (rc != 0) {
        char msg[512];
        shape(err, o->scene_name ? o->scene_name : "", kv, msg, sizeof msg);
        snprintf(why, whylen, "set %s: %s", kv, msg);
        return -1;
    }
    /* the kicks not over yet stay: a change of the scene does not undo them */
    if (live_kicks_append(ls, &out->sim, why, whylen) != 0) return -1;
    return 0;
}

void live_set_keep(live_sets *ls, const char *kv)
{
    int k = 0;
    for (int i = 0; i < ls->n; i++) {
        if (overrides(kv, ls->kv[i])) continue;
        if (k != i) memcpy(ls->kv[k], ls->kv[i], sizeof ls->kv[k]);
        k++;
    }
    ls->n = k;
    if (ls->n < LIVE_SET_MAX) /* live_set_load made room sure */
        snprintf(ls->kv[ls->n++], sizeof ls->kv[0], "%s", kv);
}

/* ---------------------------------------------------------------- kicks */

bool live_is_kick(const char *key) { return !strncmp(key, "kick.", 5); }

/* The definition without the kicks the sim carries (the last ls->nk disturbances). */
static void without_kicks(const live_sets *ls, lag_sim_def *def)
{
    int n = def->effects.n_disturbances - ls->nk;
    def->effects.n_disturbances = n < 0 ? 0 : n;
}

/* A kick's disturbance: an impulse at its tick, or a force held over the whole ticks from
 * it that start before its end, n = ceil(duration / dt) of them, at impulse / (n dt): the
 * impulse given is the one asked for, whatever the duration. */
static lag_disturbance kick_disturbance(const live_kick *k, double dt)
{
    lag_disturbance d = {.t = (double)k->step * dt, .joint = k->joint, .impulse = true,
                         .value = k->impulse}; /* lag_ticks_ceil gives k->step back */
    if (k->duration == 0) return d;
    int64_t n = lag_ticks_ceil(k->duration, dt);
    d.impulse = false;
    d.duration = (double)(n > 1 ? n : 1) * dt;
    d.value = k->impulse / d.duration;
    return d;
}

int live_kicks_append(const live_sets *ls, lag_sim_def *def, char *why, size_t whylen)
{
    lag_effects_def *e = &def->effects;
    if (ls->nk == 0) return 0;
    if (e->n_disturbances + ls->nk > LAG_MAX_DISTURBANCES) {
        snprintf(why, whylen, "kick: the scene's %d disturbances and %d kicks not over yet "
                 "exceed %d", e->n_disturbances, ls->nk, LAG_MAX_DISTURBANCES);
        return -1;
    }
    for (int k = 0; k < ls->nk; k++)
        e->disturbances[e->n_disturbances++] = kick_disturbance(&ls->kick[k], def->integrator.dt);
    e->enabled |= LAG_EFF_DISTURBANCE;
    return 0;
}

/* Is the kick over at tick (an impulse: applied; a force: its last tick taken)? As
 * disturbance_pre_tick decides, so that a kick is dropped only when it acts no more. */
static bool kick_over(const live_kick *k, int64_t tick, double dt)
{
    lag_disturbance d = kick_disturbance(k, dt);
    if (d.impulse) return tick > k->step;
    return tick >= lag_ticks_ceil(d.t + d.duration, dt);
}

/* sim's definition with ls's kicks (after its own without those it carried before). */
static int redefine(const live_sets *old, const live_sets *ls, lag_sim *sim, char *why,
                    size_t whylen)
{
    static lag_sim_def def; /* large: not on the stack */
    def = sim->def;
    without_kicks(old, &def);
    if (live_kicks_append(ls, &def, why, whylen) != 0) return -1;
    /* the core's message straight after the prefix: no second buffer to cut it twice */
    int n = snprintf(why, whylen, "kick: ");
    size_t at = n > 0 && (size_t)n < whylen ? (size_t)n : 0;
    if (lag_sim_redefine(sim, &def, why + at, whylen - at) != LAG_OK) return -1;
    return 0;
}

/* "kick.<joint>=<impulse>[,<duration>]" into k (its step: sim's tick), with the rules of
 * any disturbance (lag_disturbance_check: a scene's words), on the kick as asked: an
 * impulse, or a force impulse/duration held for duration s. */
static int kick_parse(const lag_sim *sim, const char *kv, live_kick *k, char *why, size_t whylen)
{
    const char *eq = strchr(kv, '=');
    char name[LIVE_SET_LEN];
    size_t jlen = eq && live_is_kick(kv) ? (size_t)(eq - kv) - 5 : 0;
    snprintf(name, sizeof name, "%.*s", (int)jlen, kv + (jlen ? 5 : 0));
    memset(k, 0, sizeof *k);
    lag_diag d;
    if (lag_disturbance_joint(&sim->def, name, NULL, &k->joint, &d) != LAG_OK) {
        snprintf(why, whylen, "%s: %s", kv, d.message);
        return -1;
    }
    char *end;
    errno = 0;
    k->impulse = strtod(eq + 1, &end);
    bool ok = end != eq + 1 && !errno;
    if (ok && *end == ',') {
        const char *p = end + 1;
        k->duration = strtod(p, &end);
        ok = end != p && !errno;
    }
    if (!ok || *end) {
        snprintf(why, whylen, "%s: expected IMPULSE or IMPULSE,DURATION (numbers: N s or N m "
                 "s, and s)", kv);
        return -1;
    }
    k->step = sim->tick;
    const double dt = sim->def.integrator.dt;
    lag_disturbance asked = {.t = (double)k->step * dt, .joint = k->joint,
                             .impulse = k->duration == 0, .value = k->impulse,
                             .duration = k->duration};
    if (!asked.impulse) asked.value = k->impulse / k->duration;
    if (lag_disturbance_check(&sim->def, &asked, NULL, &d) != LAG_OK) {
        snprintf(why, whylen, "%s: %s%s: %s", kv, d.field,
                 strcmp(d.field, "force") ? "" : " (impulse/duration)", d.message);
        return -1;
    }
    return 0;
}

int live_kick_apply(live_sets *ls, lag_sim *sim, const char *kv, live_kick *k, char *why,
                    size_t whylen)
{
    if (kick_parse(sim, kv, k, why, whylen) != 0) return -1;
    /* a reset ends the fault and every kick: one now would be ended unapplied */
    if (sim->fault.code != LAG_OK) {
        snprintf(why, whylen, "%s: in fault state (reset first)", kv);
        return -1;
    }
    const double dt = sim->def.integrator.dt;
    static live_sets next; /* large: not on the stack */
    next = *ls;
    int n = 0;
    for (int i = 0; i < next.nk; i++)
        if (!kick_over(&next.kick[i], sim->tick, dt)) next.kick[n++] = next.kick[i];
    next.nk = n;
    if (next.nk == LAG_MAX_DISTURBANCES) {
        snprintf(why, whylen, "%s: %d kicks act already; wait until one is over", kv,
                 LAG_MAX_DISTURBANCES);
        return -1;
    }
    next.kick[next.nk++] = *k;
    if (redefine(ls, &next, sim, why, whylen) != 0) return -1;
    *ls = next;
    return 0;
}

void live_kicks_clear(live_sets *ls, lag_sim *sim)
{
    static live_sets next; /* large: not on the stack */
    next = *ls;
    next.nk = 0;
    char why[256];
    if (ls->nk > 0 && redefine(ls, &next, sim, why, sizeof why) == 0) *ls = next;
}

void live_set_describe(const live_sets *ls, char *out, size_t outlen)
{
    size_t o = 0;
    if (outlen) out[0] = '\0';
    for (int i = 0; i < ls->n && o + 1 < outlen; i++) {
        int w = snprintf(out + o, outlen - o, "%s%s", i ? ", " : "", ls->kv[i]);
        if (w < 0) break;
        o += (size_t)w;
    }
}
