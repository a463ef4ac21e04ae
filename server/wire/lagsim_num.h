/*
 * How every program of lagsim prints a number that must read back: the shortest decimal
 * that strtod turns into exactly the same double. 0.1 prints as "0.1", not as %.17g's
 * "0.10000000000000001"; 0.1 + 0.2 as "0.30000000000000004"; 1/3 as
 * "0.3333333333333333". The daemon, lagsimctl, the client library (a kick's impulse),
 * lagsim-log2csv, lagsim-eval and lagsim-sweep call it wherever they print a user's number
 * or a number a reader may reread (tests/wire/one_place.py: no "%.17g" elsewhere).
 *
 * The form is printf's %g at the fewest significant digits of 15, 16 and 17 that reads
 * back (from 1 digit for a subnormal number, below DBL_MIN): for a normal double every
 * decimal of at most 15 digits reads back to the double it came from (DBL_DIG), so %.15g
 * is the shortest whenever 15 digits or fewer suffice; else 16 or 17 (next to a power of
 * two, where the doubles below are closer than those above, it may be 17 where a
 * 16-digit decimal would do: one digit more, never a different double). NaN and the
 * infinities print as %g prints them: nan, inf, -inf; -0 as -0.
 */
#ifndef LAGSIM_NUM_H
#define LAGSIM_NUM_H

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_NUM_LEN 32 /* "-2.2250738585072014e-308" and its NUL fit with room */

/* Writes x into buf (LAG_NUM_LEN bytes) as above; returns buf (for a printf argument). */
char *lag_num(double x, char buf[LAG_NUM_LEN]);

#ifdef __cplusplus
}
#endif
#endif
