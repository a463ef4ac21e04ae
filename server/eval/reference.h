/*
 * Reference signals: what a joint should follow, r(t), its rate r'(t) and its second
 * derivative r''(t).
 *
 * A scene gives a joint a reference (the scene key `reference:`); the daemon evaluates it
 * at each state's sim time and publishes it beside the state, so a controller in any
 * language tracks the same signal and an evaluation measures against it. Every kind but
 * waypoints starts at `start` (s); before it r = offset and r' = 0:
 *
 *   step       r = offset + amplitude                           (t >= start)
 *   ramp       r = offset + amplitude min(1, (t - start) / duration): from offset to
 *              offset + amplitude in `duration` seconds, then held
 *   sine       r = offset + amplitude sin(2 pi frequency (t - start))
 *   chirp      r = offset + amplitude sin(phi), phi' = 2 pi f(t), f sweeping linearly from
 *              `frequency` to `frequency_end` in `duration` seconds, then staying there
 *   square     r = offset + amplitude (+1 for the first half of each period, -1 for the
 *              second), period 1 / frequency
 *   waypoints  r = offset + amplitude w(t - start), w the straight lines through the
 *              points (t_i, w_i) (t_i counted from `start`), held before the first point and
 *              after the last
 *
 * r' and r'' are the exact derivatives (0 at and across a step's or square's jump, where
 * r' is a delta; r'' is 0 wherever r is piecewise linear or constant, at a ramp's or a
 * waypoint's corner too, where it is a delta):
 *
 *   sine       r'' = -amplitude w^2 sin(w (t - start)),  w = 2 pi frequency
 *   chirp      r'' = amplitude (phi'' cos(phi) - phi'^2 sin(phi)),
 *              phi'' = 2 pi (frequency_end - frequency) / duration during the sweep, 0 after
 *   step, ramp, square, waypoints: r'' = 0
 *
 * so that a computed-torque feedforward M(q) r'' needs no difference of r'. Links only
 * libm; nothing here allocates.
 */
#ifndef LAGSIM_REFERENCE_H
#define LAGSIM_REFERENCE_H

#include <stddef.h>

typedef enum lag_ref_kind {
    LAG_REF_STEP,
    LAG_REF_RAMP,
    LAG_REF_SINE,
    LAG_REF_CHIRP,
    LAG_REF_SQUARE,
    LAG_REF_WAYPOINTS,
    LAG_REF_KIND_COUNT
} lag_ref_kind;

/* The keys a reference may have, as bits of lag_ref_kind_info.keys. */
enum {
    LAG_REF_KEY_FREQUENCY = 1 << 0,
    LAG_REF_KEY_FREQUENCY_END = 1 << 1,
    LAG_REF_KEY_DURATION = 1 << 2,
    LAG_REF_KEY_POINTS = 1 << 3,
};

typedef struct lag_ref_kind_info {
    const char *name; /* "step", ... as written in a scene */
    unsigned keys;    /* LAG_REF_KEY_* it takes beyond start, amplitude and offset */
    unsigned needs;   /* ... and of those the ones it cannot do without */
} lag_ref_kind_info;

extern const lag_ref_kind_info lag_ref_kind_table[LAG_REF_KIND_COUNT];

/* The kind called NAME, or -1. */
int lag_ref_kind_from_name(const char *name);

#define LAG_REF_MAX_POINTS 64

typedef struct lag_reference {
    lag_ref_kind kind;
    double start;         /* s */
    double amplitude;     /* the joint's unit (m or rad) */
    double offset;        /* the joint's unit */
    double frequency;     /* Hz: sine, square; a chirp's first */
    double frequency_end; /* Hz: a chirp's last */
    double duration;      /* s: a ramp's rise, a chirp's sweep */
    int n_points;         /* waypoints: 1..LAG_REF_MAX_POINTS */
    double point_t[LAG_REF_MAX_POINTS]; /* s from start, strictly increasing */
    double point_w[LAG_REF_MAX_POINTS];
} lag_reference;

/* A reference of KIND with its defaults: start 0, amplitude 1, offset 0, frequency 1 Hz,
 * frequency_end 10 Hz, duration 1 s, no points. */
lag_reference lag_reference_default(lag_ref_kind kind);

/*
 * Whether REF can be evaluated: finite numbers, frequencies in (0, 1e6] Hz, durations in
 * (0, 1e9] s, 1..LAG_REF_MAX_POINTS strictly increasing waypoints. Returns 0, or -1 with
 * the offending key ("duration", "points[3]") in key and what is expected in msg.
 */
int lag_reference_check(const lag_reference *ref, char *key, size_t keylen, char *msg,
                        size_t msglen);

/* r(t), r'(t) and r''(t) of a checked reference (OUT: r, rdot, rddot; any may be NULL). */
void lag_reference_eval(const lag_reference *ref, double t, double *r, double *rdot,
                        double *rddot);

#endif
