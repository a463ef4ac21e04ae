/*
 * How well a controller did: step-response and tracking metrics of one joint's run.
 *
 * One library computes them for every consumer (lagsim-eval's table, CSV and report,
 * lagsim-sweep's summary, the --require checks), from samples a run published:
 *
 *   t[k]  sim time (s), increasing
 *   y[k]  the joint's coordinate (its own unit: m or rad)
 *   r[k]  the reference at t[k] (the same unit; all zero for a regulation case)
 *   u[k]  the effort applied from t[k] to t[k+1] (N or N m; a zero-order hold)
 *
 * Definitions (docs/evaluation.md gives each with its formula):
 *   e = r - y, the tracking error; the step A = r(T) - y(t0), what the run must travel.
 *   rise time      time from the first crossing of y(t0) + 0.1 A to the first later
 *                  crossing of y(t0) + 0.9 A (crossings interpolated linearly)
 *   settling time  time from t0 after which |e| stays within 2 % of |A| (or, when
 *                  there is no step, 2 % of the peak |e|: disturbance rejection)
 *   overshoot      max over the run of (y - r(T)) / A, as a fraction, >= 0
 *   ss_error       the mean of e over the last 10 % of the run
 *   iae, ise       integral of |e| and of e^2 over [t0, T] (trapezoids)
 *   peak_error     max |e|
 *   effort_peak    max |u|; effort_rms the root mean square of the held effort
 * A metric that does not exist for the run is NaN: no rise time or overshoot without a
 * step, no settling time while the run ends outside the band, no rise time when the
 * response never reaches 90 %.
 *
 * The metric names (lag_metric_names) are a table: the terminal table, the CSV's
 * columns, the --require parser and docs/evaluation.md are made from it.
 * Links only libm.
 */
#ifndef LAGSIM_METRICS_H
#define LAGSIM_METRICS_H

#include <stddef.h>

typedef struct lag_metric_opts {
    double t0;          /* s: metrics over the samples with t >= t0 (the case's start) */
    double rise_lo;     /* fraction of the step where the rise starts (0.1) */
    double rise_hi;     /* ... and ends (0.9) */
    double settle_band; /* fraction of |A| (or of the peak |e|) to settle within (0.02) */
    double ss_window;   /* fraction of the run at its end averaged for ss_error (0.1) */
} lag_metric_opts;

/* The usual choices: 10-90 % rise, 2 % settling, the last 10 % for the steady state. */
lag_metric_opts lag_metric_opts_default(void);

/* The metrics, in the order of lag_metric_names. */
typedef enum lag_metric {
    LAG_METRIC_RISE,
    LAG_METRIC_SETTLE,
    LAG_METRIC_OVERSHOOT,
    LAG_METRIC_SS_ERROR,
    LAG_METRIC_IAE,
    LAG_METRIC_ISE,
    LAG_METRIC_PEAK_ERROR,
    LAG_METRIC_EFFORT_PEAK,
    LAG_METRIC_EFFORT_RMS,
    LAG_METRIC_COUNT
} lag_metric;

typedef struct lag_metric_info {
    const char *name;  /* as written in --require and CSV columns: "settle" */
    const char *unit;  /* "s", "", "unit" (the joint's), "unit s", "unit^2 s", "effort" */
    const char *what;  /* one line for tables and --help */
} lag_metric_info;

/* The table of metrics, LAG_METRIC_COUNT rows. */
extern const lag_metric_info lag_metric_table[LAG_METRIC_COUNT];

/* The metric called NAME, or -1. */
int lag_metric_find(const char *name);

typedef struct lag_metrics {
    double step;                   /* A = r(T) - y(t0), the joint's unit */
    double v[LAG_METRIC_COUNT];    /* indexed by lag_metric; NaN where it does not exist */
} lag_metrics;

/*
 * Computes the metrics of n samples (t increasing; r and u may be NULL: zero reference,
 * no effort). Returns 0, or -1 with a message in err when the samples cannot be read as
 * a run: fewer than 2 at or after t0, t not increasing, a non-finite number.
 */
int lag_metrics_compute(const double *t, const double *y, const double *r, const double *u,
                        size_t n, const lag_metric_opts *o, lag_metrics *out /* OUT */,
                        char *err, size_t errlen);

/*
 * A requirement: "JOINT.METRIC OP NUMBER" terms joined by "and", OP one of < <= > >=,
 * e.g. "theta1.settle<2 and theta1.overshoot<0.1". A term on a metric that is NaN for
 * the run fails. Up to LAG_REQUIRE_MAX terms.
 */
#define LAG_REQUIRE_MAX 32
#define LAG_REQUIRE_NAME 64

typedef enum { LAG_REQ_LT, LAG_REQ_LE, LAG_REQ_GT, LAG_REQ_GE } lag_require_op;

typedef struct lag_require_term {
    char joint[LAG_REQUIRE_NAME];
    lag_metric metric;
    lag_require_op op;
    double value;
} lag_require_term;

typedef struct lag_require {
    int n;
    lag_require_term term[LAG_REQUIRE_MAX];
} lag_require;

/* Parses TEXT into REQ. Returns 0, or -1 with a message in err naming the column where
 * the expression went wrong and what was expected there (the metric names included). */
int lag_require_parse(const char *text, lag_require *req /* OUT */, char *err, size_t errlen);

/* Whether the term holds for METRICS (false on NaN). */
int lag_require_term_holds(const lag_require_term *term, const lag_metrics *metrics);

/* "theta1.settle < 2" for messages. */
void lag_require_term_format(const lag_require_term *term, char *buf, size_t len);

#endif
