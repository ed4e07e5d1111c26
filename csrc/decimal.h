/*
 * decimal.h - build-internal: decimals m * 10^e that a double holds after one
 * correctly rounded operation, shared by the scanner (scan.c) and the
 * formatter (format.c), so that what one writes the other reads back alike.
 */
#ifndef MT_DECIMAL_H
#define MT_DECIMAL_H

#include <stdint.h>

static const double exact_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* m * 10^e correctly rounded, for m <= 2^53 and |e| <= 22: both factors are exact doubles. */
static inline double exact_decimal(uint64_t m, int e)
{
    return e < 0 ? (double)m / exact_pow10[-e] : (double)m * exact_pow10[e];
}

#endif
