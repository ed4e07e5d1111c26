/*
 * format.c - numbers and frame text out: the digits from number.c (exact, in integers, no
 * printf, no locale), laid out in the style of C's %g and Python's repr.
 */
#include "mtcore.h"
#include "number.h"

#include <stdint.h>
#include <string.h>

/* "00" "01" ... "99": two digits per division */
static const char digit_pairs[201] = "00010203040506070809101112131415161718192021222324"
                                     "25262728293031323334353637383940414243444546474849"
                                     "50515253545556575859606162636465666768697071727374"
                                     "75767778798081828384858687888990919293949596979899";

/* The eight digits of v < 10^8 at p, as two independent halves. */
static inline void put_eight(char *p, uint32_t v)
{
    const uint32_t high = v / 10000, low = v % 10000;
    memcpy(p, digit_pairs + 2 * (high / 100), 2);
    memcpy(p + 2, digit_pairs + 2 * (high % 100), 2);
    memcpy(p + 4, digit_pairs + 2 * (low / 100), 2);
    memcpy(p + 6, digit_pairs + 2 * (low % 100), 2);
}

/* Writes the decimal digits of v so that they end at `end`; returns where they begin. */
static char *digits_before(uint64_t v, char *end)
{
    char *p = end;
    while (v >= 100000000) {
        p -= 8;
        put_eight(p, (uint32_t)(v % 100000000));
        v /= 100000000;
    }
    uint32_t rest = (uint32_t)v;
    while (rest >= 100) {
        p -= 2;
        memcpy(p, digit_pairs + 2 * (rest % 100), 2);
        rest /= 100;
    }
    if (rest >= 10) {
        p -= 2;
        memcpy(p, digit_pairs + 2 * rest, 2);
    } else {
        *--p = (char)('0' + rest);
    }
    return p;
}

/* A style checked and unpacked; NULL is the default style. */
struct line_end {
    size_t len;
    char bytes[2];
};

struct style {
    int digits, exponent_digits;
    struct line_end newline, frame_newline;
};

/* The bytes of a line ending code; 0 for a code that is none. */
static int unpack_line_end(int code, struct line_end *end)
{
    switch (code) {
    case MT_NEWLINE_LF:
        *end = (struct line_end){1, {'\n', 0}};
        return 1;
    case MT_NEWLINE_CRLF:
        *end = (struct line_end){2, {'\r', '\n'}};
        return 1;
    case MT_NEWLINE_CR:
        *end = (struct line_end){1, {'\r', 0}};
        return 1;
    default:
        return 0;
    }
}

static int unpack_style(const struct mt_format_style *in, struct style *s)
{
    static const struct mt_format_style fallback = {0, 2, MT_NEWLINE_LF, MT_NEWLINE_LF};
    if (in == NULL)
        in = &fallback;
    if (in->digits < 0 || in->digits > 17 || in->exponent_digits < 1 || in->exponent_digits > 3)
        return 0;
    s->digits = in->digits;
    s->exponent_digits = in->exponent_digits;
    return unpack_line_end(in->newline, &s->newline) && unpack_line_end(in->frame_newline, &s->frame_newline);
}

static inline char *put_newline(const struct line_end *end, char *out)
{
    out[0] = end->bytes[0];
    if (end->len == 2)
        out[1] = end->bytes[1];
    return out + end->len;
}

/*
 * The text of value at out (at most MT_NUMBER_MAX bytes); returns its end.  Exponent form,
 * d.ddde-XX, below 1e-4 and from 10^16 (shortest) or 10^digits (rounded) up, as Python's
 * repr and C's %.<digits>g; else plain, trailing zeros and a trailing point dropped.
 */
static inline char *put_number(double value, const struct style *s, char *out)
{
    uint64_t bits;
    memcpy(&bits, &value, sizeof bits);
    if (bits >> 63)
        *out++ = '-';
    bits &= ~(UINT64_C(1) << 63);
    if (bits >= UINT64_C(0x7ff0000000000000)) { /* a NaN keeps its sign, not its payload */
        memcpy(out, bits == UINT64_C(0x7ff0000000000000) ? "inf" : "nan", 3);
        return out + 3;
    }
    if (bits == 0) {
        *out++ = '0';
        return out;
    }
    double a;
    memcpy(&a, &bits, sizeof a);
    int e;
    uint64_t d = s->digits ? number_rounded(a, s->digits, &e) : number_shortest(a, &e);
    while (d % 100000000 == 0) {
        d /= 100000000;
        e += 8;
    }
    if (d % 10000 == 0) {
        d /= 10000;
        e += 4;
    }
    if (d % 100 == 0) {
        d /= 100;
        e += 2;
    }
    if (d % 10 == 0) {
        d /= 10;
        e += 1;
    }
    char text[24];
    const char *digits = digits_before(d, text + sizeof text);
    const int n = (int)(text + sizeof text - digits);
    const int e10 = e + n - 1; /* value = d.ddd 10^e10 */
    if (e10 < -4 || e10 >= (s->digits ? s->digits : 16)) {
        *out++ = digits[0];
        if (n > 1) {
            *out++ = '.';
            memcpy(out, digits + 1, (size_t)(n - 1));
            out += n - 1;
        }
        *out++ = 'e';
        *out++ = e10 < 0 ? '-' : '+';
        unsigned x = (unsigned)(e10 < 0 ? -e10 : e10);
        int width = x >= 100 ? 3 : x >= 10 ? 2 : 1;
        if (width < s->exponent_digits)
            width = s->exponent_digits;
        for (int i = width - 1; i >= 0; i--, x /= 10)
            out[i] = (char)('0' + x % 10);
        return out + width;
    }
    if (e10 < 0) { /* 0.000ddd */
        *out++ = '0';
        *out++ = '.';
        memset(out, '0', (size_t)(-e10 - 1));
        out += -e10 - 1;
        memcpy(out, digits, (size_t)n);
        return out + n;
    }
    if (n <= e10 + 1) { /* ddd000 */
        memcpy(out, digits, (size_t)n);
        out += n;
        memset(out, '0', (size_t)(e10 + 1 - n));
        return out + (e10 + 1 - n);
    }
    memcpy(out, digits, (size_t)(e10 + 1)); /* ddd.ddd */
    out += e10 + 1;
    *out++ = '.';
    memcpy(out, digits + e10 + 1, (size_t)(n - e10 - 1));
    return out + (n - e10 - 1);
}

int mt_format_double(double value, const struct mt_format_style *style, char *buf, size_t *written)
{
    struct style s;
    if (buf == NULL || written == NULL || !unpack_style(style, &s))
        return MT_EINVAL;
    *written = (size_t)(put_number(value, &s, buf) - buf);
    return MT_OK;
}

/* a + b and a * b, or SIZE_MAX where they overflow: a bound that cannot be met. */
static size_t add_sat(size_t a, size_t b)
{
    return a > SIZE_MAX - b ? SIZE_MAX : a + b;
}

static size_t mul_sat(size_t a, size_t b)
{
    return b != 0 && a > SIZE_MAX / b ? SIZE_MAX : a * b;
}

size_t mt_format_bound(size_t frames, const size_t *key_lens, const size_t *counts, size_t nkeys,
                       const struct mt_format_style *style)
{
    struct style s;
    if (!unpack_style(style, &s) || (nkeys > 0 && (key_lens == NULL || counts == NULL)))
        return SIZE_MAX;
    size_t per_frame = 18 + s.frame_newline.len; /* a frame number <= MT_FRAME_MAX has 18 digits */
    for (size_t k = 0; k < nkeys; k++)
        per_frame = add_sat(per_frame, add_sat(add_sat(key_lens[k], s.newline.len),
                                               mul_sat(counts[k], MT_NUMBER_MAX + 1)));
    return mul_sat(frames, per_frame);
}

size_t mt_format_table_bound(size_t rows, size_t columns, const struct mt_format_style *style)
{
    struct style s;
    if (!unpack_style(style, &s))
        return SIZE_MAX;
    return mul_sat(rows, add_sat(mul_sat(columns, MT_NUMBER_MAX + 1), s.newline.len));
}

int mt_format_frames(const double *values, size_t frames, size_t channels, long long first_frame,
                     const char *const *keys, const size_t *key_lens, const size_t *offsets,
                     const size_t *counts, size_t nkeys, const struct mt_format_style *style, char *buf,
                     size_t cap, size_t *written)
{
    struct style s;
    if (written == NULL || (frames > 0 && (values == NULL || buf == NULL)) ||
        (nkeys > 0 && (!keys || !key_lens || !offsets || !counts)) || !unpack_style(style, &s))
        return MT_EINVAL;
    *written = 0;
    for (size_t k = 0; k < nkeys; k++)
        if (keys[k] == NULL || offsets[k] > channels || counts[k] > channels - offsets[k])
            return MT_EINVAL;
    /* every frame number written must read back: 0 .. MT_FRAME_MAX */
    if (first_frame < 0 || first_frame > MT_FRAME_MAX ||
        (frames > 0 && frames - 1 > (unsigned long long)(MT_FRAME_MAX - first_frame)))
        return MT_EFRAMERANGE;
    if (cap < mt_format_bound(frames, key_lens, counts, nkeys, style))
        return MT_ERANGE;
    char *out = buf;
    for (size_t f = 0; f < frames; f++) {
        char number[20];
        const char *start = digits_before((uint64_t)first_frame + f, number + sizeof number);
        memcpy(out, start, (size_t)(number + sizeof number - start));
        out = put_newline(&s.frame_newline, out + (number + sizeof number - start));
        const double *row = values + f * channels;
        for (size_t k = 0; k < nkeys; k++) {
            memcpy(out, keys[k], key_lens[k]);
            out += key_lens[k];
            for (size_t i = 0; i < counts[k]; i++) {
                *out++ = ' ';
                out = put_number(row[offsets[k] + i], &s, out);
            }
            out = put_newline(&s.newline, out);
        }
    }
    *written = (size_t)(out - buf);
    return MT_OK;
}

int mt_format_table(const double *values, size_t rows, size_t columns, const struct mt_format_style *style,
                    char *buf, size_t cap, size_t *written)
{
    struct style s;
    if (written == NULL || (rows > 0 && (buf == NULL || (columns > 0 && values == NULL))) ||
        !unpack_style(style, &s))
        return MT_EINVAL;
    *written = 0;
    if (cap < mt_format_table_bound(rows, columns, style))
        return MT_ERANGE;
    char *out = buf;
    for (size_t r = 0; r < rows; r++) {
        for (size_t c = 0; c < columns; c++) {
            if (c > 0)
                *out++ = ' ';
            out = put_number(values[r * columns + c], &s, out);
        }
        out = put_newline(&s.newline, out);
    }
    *written = (size_t)(out - buf);
    return MT_OK;
}
