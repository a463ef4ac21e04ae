/* Sim time and time to tick conversions (lagsim.h): a leaf of the core, which every
 * other unit may call. Sim time is tick * dt, computed, never accumulated. */
#include <math.h>
#include "core_internal.h"

double lag_sim_time(const lag_sim *s) { return (double)s->tick * s->def.integrator.dt; }

/* A tick count x (a double, already rounded) saturated to 0..INT64_MAX. */
static int64_t ticks_sat(double x)
{
    if (!(x < 0x1p63)) return INT64_MAX; /* also NaN: a double >= 2^63 has no int64_t */
    if (!(x > 0)) return 0;
    return (int64_t)x;
}

int64_t lag_ticks_ceil(double t, double dt) { return ticks_sat(ceil(t / dt - LAG_TICK_TOL)); }

int64_t lag_ticks_floor(double t, double dt) { return ticks_sat(floor(t / dt + LAG_TICK_TOL)); }

bool lag_ticks_exact(double t, double dt, int64_t *n)
{
    double r = t / dt, k = floor(r + 0.5);
    if (!(k >= 0 && k < 0x1p63 && fabs(r - k) <= LAG_TICK_TOL)) return false; /* also NaN */
    if (n) *n = (int64_t)k;
    return true;
}
