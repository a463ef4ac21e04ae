/* Reference signals (reference.h says what each kind is). */
#include "reference.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const lag_ref_kind_info lag_ref_kind_table[LAG_REF_KIND_COUNT] = {
    [LAG_REF_STEP] = {"step", 0, 0},
    [LAG_REF_RAMP] = {"ramp", LAG_REF_KEY_DURATION, 0},
    [LAG_REF_SINE] = {"sine", LAG_REF_KEY_FREQUENCY, 0},
    [LAG_REF_CHIRP] = {"chirp", LAG_REF_KEY_FREQUENCY | LAG_REF_KEY_FREQUENCY_END | LAG_REF_KEY_DURATION, 0},
    [LAG_REF_SQUARE] = {"square", LAG_REF_KEY_FREQUENCY, 0},
    [LAG_REF_WAYPOINTS] = {"waypoints", LAG_REF_KEY_POINTS, LAG_REF_KEY_POINTS},
};

int lag_ref_kind_from_name(const char *name)
{
    for (int k = 0; k < LAG_REF_KIND_COUNT; k++)
        if (strcmp(lag_ref_kind_table[k].name, name) == 0) return k;
    return -1;
}

lag_reference lag_reference_default(lag_ref_kind kind)
{
    lag_reference r;
    memset(&r, 0, sizeof r);
    r.kind = kind;
    r.amplitude = 1;
    r.frequency = 1;
    r.frequency_end = 10;
    r.duration = 1;
    return r;
}

static int bad(char *key, size_t keylen, char *msg, size_t msglen, const char *k, const char *m)
{
    if (key && keylen) snprintf(key, keylen, "%s", k);
    if (msg && msglen) snprintf(msg, msglen, "%s", m);
    return -1;
}

int lag_reference_check(const lag_reference *ref, char *key, size_t keylen, char *msg,
                        size_t msglen)
{
    if ((unsigned)ref->kind >= LAG_REF_KIND_COUNT)
        return bad(key, keylen, msg, msglen, "type", "an unknown kind of reference");
    const unsigned keys = lag_ref_kind_table[ref->kind].keys;
    if (!isfinite(ref->start) || fabs(ref->start) > 1e9)
        return bad(key, keylen, msg, msglen, "start", "expected a time within +-1e9 s");
    if (!isfinite(ref->amplitude) || fabs(ref->amplitude) > 1e9)
        return bad(key, keylen, msg, msglen, "amplitude", "expected a number within +-1e9");
    if (!isfinite(ref->offset) || fabs(ref->offset) > 1e9)
        return bad(key, keylen, msg, msglen, "offset", "expected a number within +-1e9");
    if ((keys & LAG_REF_KEY_FREQUENCY) && !(ref->frequency > 0 && ref->frequency <= 1e6))
        return bad(key, keylen, msg, msglen, "frequency", "expected a frequency in (0, 1e6] Hz");
    if ((keys & LAG_REF_KEY_FREQUENCY_END) && !(ref->frequency_end > 0 && ref->frequency_end <= 1e6))
        return bad(key, keylen, msg, msglen, "frequency_end", "expected a frequency in (0, 1e6] Hz");
    if ((keys & LAG_REF_KEY_DURATION) && !(ref->duration > 0 && ref->duration <= 1e9))
        return bad(key, keylen, msg, msglen, "duration", "expected a duration in (0, 1e9] s");
    if (keys & LAG_REF_KEY_POINTS) {
        if (ref->n_points < 1 || ref->n_points > LAG_REF_MAX_POINTS) {
            char m[96];
            snprintf(m, sizeof m, "expected 1 to %d points [t, value]", LAG_REF_MAX_POINTS);
            return bad(key, keylen, msg, msglen, "points", m);
        }
        for (int i = 0; i < ref->n_points; i++) {
            char k[32];
            snprintf(k, sizeof k, "points[%d]", i);
            if (!isfinite(ref->point_t[i]) || fabs(ref->point_t[i]) > 1e9 ||
                !isfinite(ref->point_w[i]) || fabs(ref->point_w[i]) > 1e9)
                return bad(key, keylen, msg, msglen, k, "expected [t, value], each within +-1e9");
            if (i > 0 && !(ref->point_t[i] > ref->point_t[i - 1]))
                return bad(key, keylen, msg, msglen, k, "expected times that increase from point to point");
        }
    }
    return 0;
}

/* The phase of a chirp tau seconds after its start (rad), its rate (rad/s) and the rate's
 * rate (rad/s^2: constant during the sweep, 0 after). */
static void chirp_phase(const lag_reference *ref, double tau, double *phi, double *w,
                        double *wdot)
{
    const double f0 = ref->frequency, f1 = ref->frequency_end, d = ref->duration;
    if (tau <= d) {
        *phi = 2 * M_PI * (f0 * tau + 0.5 * (f1 - f0) / d * tau * tau);
        *w = 2 * M_PI * (f0 + (f1 - f0) * tau / d);
        *wdot = 2 * M_PI * (f1 - f0) / d;
    } else {
        *phi = 2 * M_PI * (0.5 * (f0 + f1) * d + f1 * (tau - d));
        *w = 2 * M_PI * f1;
        *wdot = 0;
    }
}

/* The waypoints' straight lines at tau: the shape and its slope (0 outside the points). */
static void waypoints_at(const lag_reference *ref, double tau, double *shape, double *rate)
{
    const int n = ref->n_points;
    const double *pt = ref->point_t, *pw = ref->point_w;
    *rate = 0;
    if (n < 1) *shape = 0;
    else if (tau <= pt[0]) *shape = pw[0];
    else if (tau >= pt[n - 1]) *shape = pw[n - 1];
    else {
        int i = 1;
        while (pt[i] < tau) i++; /* pt[i-1] < tau <= pt[i] */
        double slope = (pw[i] - pw[i - 1]) / (pt[i] - pt[i - 1]);
        *shape = pw[i - 1] + slope * (tau - pt[i - 1]);
        *rate = slope;
    }
}

void lag_reference_eval(const lag_reference *ref, double t, double *r, double *rdot,
                        double *rddot)
{
    const double a = ref->amplitude, tau = t - ref->start;
    /* the signal without offset and amplitude, its rate and its second derivative */
    double shape = 0, rate = 0, accel = 0;
    if (tau >= 0) {
        switch (ref->kind) {
        case LAG_REF_STEP:
            shape = 1;
            break;
        case LAG_REF_RAMP:
            if (tau < ref->duration) shape = tau / ref->duration, rate = 1 / ref->duration;
            else shape = 1;
            break;
        case LAG_REF_SINE: {
            double w = 2 * M_PI * ref->frequency;
            shape = sin(w * tau);
            rate = w * cos(w * tau);
            accel = -w * w * shape;
            break;
        }
        case LAG_REF_CHIRP: {
            double phi, w, wdot;
            chirp_phase(ref, tau, &phi, &w, &wdot);
            shape = sin(phi);
            rate = w * cos(phi);
            accel = wdot * cos(phi) - w * w * shape;
            break;
        }
        case LAG_REF_SQUARE: {
            double cycles = ref->frequency * tau;
            shape = cycles - floor(cycles) < 0.5 ? 1 : -1;
            break;
        }
        case LAG_REF_WAYPOINTS:
        case LAG_REF_KIND_COUNT:
            break;
        }
    }
    /* waypoints: held before the first point too */
    if (ref->kind == LAG_REF_WAYPOINTS) waypoints_at(ref, tau, &shape, &rate);
    if (r) *r = ref->offset + a * shape;
    if (rdot) *rdot = a * rate;
    if (rddot) *rddot = a * accel;
}
