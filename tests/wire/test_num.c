/*
 * lag_num (server/wire/lagsim_num.c): every number a program prints to be read back is
 * the shortest decimal that strtod turns into the same double.
 *
 *   readback  2 000 000 doubles of random bits (every exponent, subnormals, signs): each
 *             printed form reads back to the same bits, and no printf %.Ng with fewer
 *             digits does (the form is the shortest of printf's); the first 500 000 of
 *             them under the sanitizers (lt_span: still every exponent, a few hundred
 *             subnormals);
 *   python    values whose shortest round-trip form Python's repr gives (an independent
 *             implementation: David Gay's), written here as repr printed them, and the
 *             specials.
 */
#include <float.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_num.h"
#include "lagsim_test.h"

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static uint64_t next_bits(void) /* xorshift64* */
{
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return rng * 2685821657736338717ull;
}

/* The significant digits of a %g form: its digits without leading and trailing zeros
 * (132770585930220 has 14), the exponent left out. */
static int significant(const char *s)
{
    int n = 0, zeros = 0;
    bool lead = true;
    for (; *s && *s != 'e'; s++) {
        if (*s < '0' || *s > '9') continue;
        if (lead && *s == '0') continue;
        lead = false;
        n++;
        zeros = *s == '0' ? zeros + 1 : 0;
    }
    return n - zeros;
}

static void case_readback(int arg)
{
    (void)arg;
    int bad = 0, longer = 0, checked = 0;
    const int n = (int)lt_span(2000000, 500000);
    for (int i = 0; i < n; i++) {
        uint64_t b = next_bits();
        double x;
        memcpy(&x, &b, sizeof x);
        if (!isfinite(x)) continue;
        char buf[LAG_NUM_LEN];
        lag_num(x, buf);
        double y = strtod(buf, NULL);
        if (memcmp(&x, &y, sizeof x) != 0 && bad++ < 5)
            LT_FAIL("%s does not read back to %a (it reads %a)", buf, x, y);
        /* shorter forms: none of printf's reads back */
        int k = significant(buf);
        if (i % 10 != 0 || k <= 1) continue;
        checked++;
        char shorter[400];
        snprintf(shorter, sizeof shorter, "%.*g", k - 1, x);
        if (strtod(shorter, NULL) == x && longer++ < 5)
            LT_FAIL("%a: %s (%d digits), but %s reads back too", x, buf, k, shorter);
    }
    ENSUREF(bad == 0 && longer == 0, "%d forms did not read back, %d were not the shortest "
            "(of %d checked)", bad, longer, checked);
    printf("%d random doubles read back; %d checked for a shorter form\n", n, checked);
}

static void case_python(int arg)
{
    (void)arg;
    /* the value, and repr(value) in Python 3 */
    static const struct {
        double x;
        const char *repr;
    } table[] = {
        {0.1, "0.1"},
        {0.2, "0.2"},
        {0.1 + 0.2, "0.30000000000000004"},
        {1.0 / 3.0, "0.3333333333333333"},
        {2.0 / 3.0, "0.6666666666666666"},
        {0.3, "0.3"},
        {1.1, "1.1"},
        {4.35, "4.35"},
        {123456.789, "123456.789"},
        {0.01 * 3, "0.03"},
        {1e23, "1e+23"},
        {1e-7, "1e-07"},
        {5e-324, "5e-324"},                       /* the smallest subnormal */
        {3 * 5e-324, "1.5e-323"},
        {2.2250738585072014e-308, "2.2250738585072014e-308"}, /* DBL_MIN */
        {1.7976931348623157e308, "1.7976931348623157e+308"},  /* DBL_MAX */
    };
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        char buf[LAG_NUM_LEN];
        lag_num(table[i].x, buf);
        ENSUREF(strcmp(buf, table[i].repr) == 0, "%a: '%s', Python's repr '%s'", table[i].x, buf,
                table[i].repr);
        lag_num(-table[i].x, buf);
        ENSUREF(buf[0] == '-' && strcmp(buf + 1, table[i].repr) == 0, "-%a: '%s'", table[i].x,
                buf);
    }
    char buf[LAG_NUM_LEN];
    ENSURE(strcmp(lag_num(0.0, buf), "0") == 0);
    ENSURE(strcmp(lag_num(-0.0, buf), "-0") == 0);
    ENSURE(strcmp(lag_num(INFINITY, buf), "inf") == 0);
    ENSURE(strcmp(lag_num(-INFINITY, buf), "-inf") == 0);
    ENSURE(strcmp(lag_num(NAN, buf), "nan") == 0 || strcmp(buf, "-nan") == 0);
    ENSURE(strcmp(lag_num(1e15, buf), "1e+15") == 0);
    ENSURE(strcmp(lag_num(1e16, buf), "1e+16") == 0);
    ENSURE(strcmp(lag_num(100, buf), "100") == 0);
}

int main(int argc, char **argv)
{
    static const lt_case all[] = {
        {"readback", case_readback, 0, 0},
        {"python", case_python, 0, 0},
    };
    return lt_main(argc, argv, all, (int)(sizeof all / sizeof all[0]));
}
