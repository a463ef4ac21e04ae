/*
 * The shortest decimal that reads back: see lagsim_num.h.
 */
#include "lagsim_num.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *lag_num(double x, char buf[LAG_NUM_LEN])
{
    if (!isfinite(x) || x == 0) { /* nan, inf, -inf, 0, -0 */
        snprintf(buf, LAG_NUM_LEN, "%g", x);
        return buf;
    }
    /* a subnormal number has fewer significant bits: any number of digits may do */
    int digits = fabs(x) < DBL_MIN ? 1 : DBL_DIG;
    for (; digits < 17; digits++) {
        snprintf(buf, LAG_NUM_LEN, "%.*g", digits, x);
        if (strtod(buf, NULL) == x) return buf;
    }
    snprintf(buf, LAG_NUM_LEN, "%.17g", x); /* 17 digits always read back (DBL_DECIMAL_DIG) */
    return buf;
}
