/*
 * Requests a plant hears that are not for it where it listens: control requests for a
 * prefix no plant here has (a controller or a tool on a misspelt prefix, MANIPULATR for
 * MANIPULATOR), and this plant's own control requests sent to the state port instead of
 * the command port. The waits name them (rt_wait.c): a plant that waits for its first
 * command says what it heard instead, so that a user sees the misspelling on the
 * daemon's terminal too, not only "nothing else came".
 *
 * Bounded whatever comes: RT_FOREIGN_MAX prefixes, the least recently heard forgotten for
 * a new one (and counted), a fixed count per request. A prefix may have a plant of its own
 * (another daemon on the same bus, asked by a tool): the daemon asks it once for its scene
 * (a DESCRIBE, the probe: at most RT_FOREIGN_PROBES_PER_S a second, so a flood of new
 * prefixes is never answered by a flood), and a prefix whose scene is heard on the state
 * port is that plant's business, never reported. A prefix is reported once its probe went
 * unanswered for RT_FOREIGN_ANSWER_NS. The probes' own DESCRIBEs, heard back, are not
 * counted. What a request is comes from a bounded decode of its control_t; one that does
 * not decode counts as request 0.
 */
#ifndef LAGSIMD_RT_FOREIGN_H
#define LAGSIMD_RT_FOREIGN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define RT_FOREIGN_MAX 8          /* prefixes remembered: the newest heard */
#define RT_FOREIGN_REQUESTS 9     /* by control_t's request: 0 (none, or undecodable), 1..8 */
#define RT_FOREIGN_NAME 64
#define RT_FOREIGN_PROBES_PER_S 4
#define RT_FOREIGN_ANSWER_NS 500000000 /* a plant answers a DESCRIBE well within 0.5 s */
#define RT_FOREIGN_STAMPS 8       /* the probes sent last, known by their utime */

typedef struct rt_foreign_prefix {
    char prefix[RT_FOREIGN_NAME];
    int64_t requests[RT_FOREIGN_REQUESTS]; /* control requests heard, by request */
    int64_t total;
    bool state_port;     /* some came to the state port (two mistakes at once) */
    bool has_plant;      /* its scene was heard: another plant's prefix */
    int64_t heard;       /* the order it was last heard in (the oldest goes first) */
    int64_t probed_ns;   /* when this daemon asked it for its scene (0: not yet) */
} rt_foreign_prefix;

typedef struct rt_foreign {
    rt_foreign_prefix p[RT_FOREIGN_MAX];
    int64_t forgotten;   /* prefixes dropped from the table for newer ones */
    int64_t own_state_port[RT_FOREIGN_REQUESTS]; /* this plant's requests on the state port */
    int64_t own_state_port_total;
    int64_t clock;       /* hearings so far (the order) */
    int64_t stamp[RT_FOREIGN_STAMPS]; /* the utimes of the probes sent last */
    int stamp_next;
} rt_foreign;

/* A control request (data, len: a control_t as sent) on channel `channel`, which ends in
 * the control suffix, heard on the state port or the command port; `own` is this plant's control
 * channel. Ignored when it is this plant's own on the command port (the loop's). */
/* Returns the prefix's entry when it has not been probed yet (the caller may probe it and
 * say so with rt_foreign_probed), else NULL. */
rt_foreign_prefix *rt_foreign_request(rt_foreign *f, const char *channel, const char *own,
                                      bool state_port, const uint8_t *data, size_t len);
/* The probe of e went out at `now`, a DESCRIBE stamped with utime `stamp`. */
void rt_foreign_probed(rt_foreign *f, rt_foreign_prefix *e, int64_t now, int64_t stamp);
/* Whether e is to be reported at `now`: requests came, no plant answered its probe. */
bool rt_foreign_unanswered(const rt_foreign_prefix *e, int64_t now);
/* A scene on channel `channel` (a prefix and the scene suffix, not `own`, this plant's): a prefix in the
 * table has a plant (a scene of a prefix nobody asked for makes no entry). */
void rt_foreign_scene(rt_foreign *f, const char *channel, const char *own);

/* Copies a table (the counts a wait starts from). */
void rt_foreign_copy(rt_foreign *to, const rt_foreign *from);
/* The entry of prefix `prefix` in `f`, or NULL. */
const rt_foreign_prefix *rt_foreign_find(const rt_foreign *f, const char *prefix);

#endif
