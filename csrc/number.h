/*
 * number.h - build-internal: doubles to and from decimal, exactly, without the C library's
 * conversions (printf, strtod: they follow the locale's LC_NUMERIC) and without the locale.
 *
 * The number grammar, one for every format (AMC frames, BVH MOTION and header, ASF):
 *
 *     number  = [sign] (decimal | "inf" | "infinity" | "nan")     words in any case
 *     decimal = (digits ["." [digits]] | "." digits) [("e" | "E") [sign] digits]
 *     sign    = "+" | "-"
 *
 * Any number of digits; the value is the double nearest the decimal (ties to even), as
 * Python's float() gives.  No hexadecimal, no '_', no "nan(...)", no blanks inside.
 *
 * Shared by the scanner (scan.c, which inlines the fast path below) and the formatter
 * (format.c).  number.c holds the rest; number_x86.c number_shortest in vector lanes.
 */
#ifndef MT_NUMBER_H
#define MT_NUMBER_H

#include <stdint.h>

/* The powers of ten that 64-bit integers hold. */
static const uint64_t pow10_u64[20] = {1u,
                                       10u,
                                       100u,
                                       1000u,
                                       10000u,
                                       100000u,
                                       1000000u,
                                       10000000u,
                                       100000000u,
                                       1000000000u,
                                       10000000000u,
                                       100000000000u,
                                       1000000000000u,
                                       10000000000000u,
                                       100000000000000u,
                                       1000000000000000u,
                                       10000000000000000u,
                                       100000000000000000u,
                                       1000000000000000000u,
                                       10000000000000000000u};

/* Powers of ten that doubles hold exactly. */
static const double exact_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/*
 * m * 10^e correctly rounded, for m <= 2^53 and |e| <= 22: both factors are exact doubles, so
 * one correctly rounded operation gives the nearest double (Clinger 1990).
 */
static inline double exact_decimal(uint64_t m, int e)
{
    return e < 0 ? (double)m / exact_pow10[-e] : (double)m * exact_pow10[e];
}

/*
 * The bits of the double nearest w 10^q (any w and q), returning 1, where that takes no big
 * integers (nearly always); else 0, *bits then at most one step off.
 */
int number_decimal(uint64_t w, int64_t q, uint64_t *bits);

/* The token [p, end) read by the grammar above into *out; 1 if it is a number, 0 if not. */
int number_parse(const char *p, const char *end, double *out);

/*
 * The shortest decimal that reads back as a (finite, > 0): its digits D, maybe followed by
 * zeros, and exponent, a ~ D * 10^*exp10; of several shortest, the nearest to a (ties to an
 * even last digit).  These are the digits of Python's repr().
 */
uint64_t number_shortest(double a, int *exp10);

/*
 * a (finite, > 0) correctly rounded to `digits` (1 .. 17) significant digits, ties to even:
 * a ~ D * 10^*exp10 with 10^(digits-1) <= D < 10^digits (trailing zeros kept).
 */
uint64_t number_rounded(double a, int digits, int *exp10);

/* The bits of a double: its fraction; all but its sign. */
#define MASK52 ((UINT64_C(1) << 52) - 1)
#define MASK63 ((UINT64_C(1) << 63) - 1)

/* Dragonbox's kappa (number_shortest and its vector lanes, number_x86.c): the shortest decimal is
   sought among the multiples of 10^(kappa+1) units of 10^k, then of 10^kappa. */
enum { KAPPA = 2, KAPPA_BIG = 1000, KAPPA_SMALL = 100 };

#endif
