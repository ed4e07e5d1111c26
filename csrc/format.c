/*
 * format.c - numbers and frame text out, shortest round trip.
 *
 * A double is written with the fewest significant digits that read back to
 * exactly the same double.  For at most 15 digits the candidate is found by
 * rounding value * 10^k to an integer m and checked exactly: m < 2^53 and
 * |k| <= 22, so m / 10^k is one correctly rounded operation (the reading
 * side's fast path).  Fifteen digits are too few for two decimals to round
 * to one double, so a checked candidate is the correctly rounded one, and
 * the shortest text is it with trailing zeros dropped.  Values needing 16 or
 * 17 digits, or out of that exponent range, go through snprintf and strtod.
 */
#include "decimal.h"
#include "mtcore.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/*
 * The digits (without trailing zeros) and decimal exponent of the shortest
 * text of a > 0, finite: a = 0.d1d2d3... * 10^(e10+1).  Returns the digit count.
 */
static int shortest_fast(double a, char *digits, int *e10)
{
    /* floor(log10(a)) from the binary exponent, off by one at most; a wrong guess shows as a
       mantissa of p+1 or p-1 digits below, and is tried once more */
    uint64_t bits;
    memcpy(&bits, &a, sizeof bits);
    const int e2 = (int)((bits >> 52) & 0x7ff) - 1023;
    /* floor(e2 * log10(2)) in integers, for |e2| < 1700 (a shift of a negative is not portable) */
    int e = e2 >= 0 ? (e2 * 78913) >> 18 : -((-e2 * 78913 + (1 << 18) - 1) >> 18);
    for (int attempt = 0; attempt < 3; attempt++) {
        int p = 15 < 23 + e ? 15 : 23 + e; /* digits, so that k = p - 1 - e <= 22 */
        int k = p - 1 - e;
        if (p < 1 || k < -22)
            return 0;
        double scaled = k >= 0 ? a * exact_pow10[k] : a / exact_pow10[-k];
        uint64_t m = (uint64_t)llround(scaled);
        uint64_t low = 1, high;
        for (int i = 1; i < p; i++)
            low *= 10;
        high = low * 10;
        if (m >= high || m < low) { /* log10 was off by one at a power of ten */
            e += m >= high ? 1 : -1;
            continue;
        }
        if (exact_decimal(m, -k) != a)
            return 0;
        int n = p;
        while (m % 10 == 0) {
            m /= 10;
            n--;
        }
        int i = n;
        for (; i >= 2; i -= 2) { /* two digits per division */
            const unsigned pair = (unsigned)(m % 100);
            m /= 100;
            digits[i - 1] = (char)('0' + pair % 10);
            digits[i - 2] = (char)('0' + pair / 10);
        }
        if (i == 1)
            digits[0] = (char)('0' + m);
        *e10 = e;
        return n;
    }
    return 0;
}

/* The same through printf's correctly rounded %e and strtod. */
static int shortest_slow(double a, char *digits, int *e10)
{
    char buf[40];
    for (int p = 1; p <= 17; p++) {
        snprintf(buf, sizeof buf, "%.*e", p - 1, a);
        if (strtod(buf, NULL) != a)
            continue;
        int n = 0;
        for (const char *q = buf; *q != 'e'; q++)
            if (*q != '.')
                digits[n++] = *q;
        while (n > 1 && digits[n - 1] == '0')
            n--;
        *e10 = atoi(strchr(buf, 'e') + 1);
        return n;
    }
    return 0; /* unreachable: 17 digits always read back */
}

size_t mt_format_double(double value, char *buf)
{
    char *out = buf;
    if (signbit(value))
        *out++ = '-';
    if (isnan(value)) { /* the sign survives text; a NaN's payload does not */
        memcpy(out, "nan", 3);
        return (size_t)(out - buf) + 3;
    }
    double a = fabs(value);
    if (isinf(a)) {
        memcpy(out, "inf", 3);
        return (size_t)(out - buf) + 3;
    }
    if (a == 0.0) {
        *out++ = '0';
        return (size_t)(out - buf);
    }
    char digits[20] = {0};
    int e10 = 0, n = shortest_fast(a, digits, &e10);
    if (n == 0)
        n = shortest_slow(a, digits, &e10);
    if (e10 < -4 || e10 >= 16) { /* d.ddde-XX, as printf %g and Python repr */
        *out++ = digits[0];
        if (n > 1) {
            *out++ = '.';
            memcpy(out, digits + 1, (size_t)(n - 1));
            out += n - 1;
        }
        out += snprintf(out, 8, "e%c%02d", e10 < 0 ? '-' : '+', abs(e10));
    } else if (e10 < 0) { /* 0.000ddd */
        *out++ = '0';
        *out++ = '.';
        for (int i = -1; i > e10; i--)
            *out++ = '0';
        memcpy(out, digits, (size_t)n);
        out += n;
    } else { /* ddd.ddd or ddd000 */
        for (int i = 0; i <= e10 || i < n; i++) {
            if (i == e10 + 1)
                *out++ = '.';
            *out++ = i < n ? digits[i] : '0';
        }
    }
    return (size_t)(out - buf);
}

size_t mt_format_bound(size_t frames, const size_t *key_lens, const size_t *counts, size_t nkeys)
{
    size_t per_frame = 24; /* frame number line */
    for (size_t k = 0; k < nkeys; k++)
        per_frame += key_lens[k] + 2 + counts[k] * (MT_NUMBER_MAX + 1);
    return frames * per_frame;
}

int mt_format_frames(const double *values, size_t frames, size_t channels, long long first_frame,
                     const char *const *keys, const size_t *key_lens, const size_t *offsets,
                     const size_t *counts, size_t nkeys, char *buf, size_t cap, size_t *written)
{
    if (written == NULL || (frames > 0 && (values == NULL || buf == NULL)) ||
        (nkeys > 0 && (!keys || !key_lens || !offsets || !counts)))
        return MT_EINVAL;
    *written = 0;
    for (size_t k = 0; k < nkeys; k++)
        if (keys[k] == NULL || offsets[k] > channels || counts[k] > channels - offsets[k])
            return MT_EINVAL;
    if (cap < mt_format_bound(frames, key_lens, counts, nkeys))
        return MT_ERANGE;
    char *out = buf;
    for (size_t f = 0; f < frames; f++) {
        out += snprintf(out, 24, "%lld\n", first_frame + (long long)f);
        const double *row = values + f * channels;
        for (size_t k = 0; k < nkeys; k++) {
            memcpy(out, keys[k], key_lens[k]);
            out += key_lens[k];
            for (size_t i = 0; i < counts[k]; i++) {
                *out++ = ' ';
                out += mt_format_double(row[offsets[k] + i], out);
            }
            *out++ = '\n';
        }
    }
    *written = (size_t)(out - buf);
    return MT_OK;
}

int mt_format_table(const double *values, size_t rows, size_t columns, char *buf, size_t cap,
                    size_t *written)
{
    if (written == NULL || (rows > 0 && columns > 0 && (values == NULL || buf == NULL)))
        return MT_EINVAL;
    *written = 0;
    if (columns > 0 && cap / (columns * (MT_NUMBER_MAX + 1) + 1) < rows)
        return MT_ERANGE;
    char *out = buf;
    for (size_t r = 0; r < rows; r++) {
        for (size_t c = 0; c < columns; c++) {
            if (c > 0)
                *out++ = ' ';
            out += mt_format_double(values[r * columns + c], out);
        }
        *out++ = '\n';
    }
    *written = (size_t)(out - buf);
    return MT_OK;
}
