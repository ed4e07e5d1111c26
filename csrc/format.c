/*
 * format.c - numbers and frame text out: the digits from number.c (exact, in integers, no
 * printf, no locale), laid out in the style of C's %g and Python's repr.  Portable C; on x86-64
 * the shortest texts of whole slots of values come from the vector code (x86.h) where the
 * processor runs it, and what it leaves from here.
 */
#include "mtcore.h"
#include "number.h"
#include "x86.h"

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

/* The bytes of a line ending (enum mt_newline); 0 for a value that is none. */
static int unpack_line_end(int newline, struct line_end *end)
{
    switch (newline) {
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
 * The digits of a (finite, > 0) when a decimal of at most 8 or 9 significant digits reads back
 * as it, a = d 10^e, returning 1; else 0.  a 10^k is below 10^9 for the k taken, where a decimal
 * step of 10^-k is a thousandth of a's ulp at most: at most one integer m has m 10^-k reading
 * back as a, and the nearest to a 10^k it is, if any is.  m 10^-k is the shortest decimal then
 * (any with fewer digits is one too, with trailing zeros): number_shortest's answer, at the
 * cost of a product, a quotient and a test.  The quotient m / 10^k is what reading m e-k gives (one
 * correctly rounded operation on exact doubles, Clinger 1990), so the test is exact.
 */
static inline int short_decimal(double a, uint64_t bits, uint64_t *d, int *e)
{
    const int e2 = (int)(bits >> 52) - 1023;  /* 2^e2 <= a < 2^(e2 + 1), for normal a */
    const int k = 8 - ((e2 * 1233) >> 12) - 1; /* (e2 1233) >> 12 is floor(e2 log10 2) or one less */
    if (k < 0 || k > 22 || (bits >> 52) == 0)
        return 0;
    const double scaled = a * exact_pow10[k];
    const uint64_t m = (uint64_t)(scaled + 0.5);
    if ((double)m / exact_pow10[k] != a)
        return 0;
    *d = m;
    *e = -k;
    return 1;
}

/* The count of decimal digits of v > 0. */
static inline int decimal_length(uint64_t v)
{
    const int guess = ((64 - __builtin_clzll(v)) * 1233) >> 12; /* floor(log10 v) or one more */
    return guess + (guess < 20 && v >= pow10_u64[guess]);
}

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/*
 * The eight digits of v < 10^8, zero-padded, at p: in the lanes of one 64-bit word (the first
 * digit in the lowest byte), without a division (Khuong, "Faster integer formatting", 2017).
 */
static inline void put_eight_digits(char *p, uint32_t v)
{
    const uint64_t merged = (v / 10000) | ((uint64_t)(v % 10000) << 32);
    const uint64_t top = ((merged * 10486) >> 20) & ((UINT64_C(0x7f) << 32) | 0x7f); /* / 100 */
    const uint64_t hundreds = ((merged - 100 * top) << 16) + top;
    uint64_t tens = ((hundreds * 103) >> 10) & UINT64_C(0x000f000f000f000f); /* / 10 */
    tens += (hundreds - 10 * tens) << 8;
    tens += ZEROS_WORD;
    memcpy(p, &tens, 8);
}

/* How many of the eight digits at p are '0' at the end. */
static inline int trailing_zeros8(const char *p)
{
    uint64_t w;
    memcpy(&w, p, 8);
    w ^= ZEROS_WORD; /* a '0' becomes 0 */
    return w == 0 ? 8 : __builtin_clzll(w) / 8;
}
#else
static inline void put_eight_digits(char *p, uint32_t v)
{
    put_eight(p, v);
}

static inline int trailing_zeros8(const char *p)
{
    int n = 0;
    while (n < 8 && p[7 - n] == '0')
        n++;
    return n;
}
#endif

/*
 * The 17 digits of d < 10^17, zero-padded, at t[0 .. 16], and seventeen '0' after them; returns
 * how many of d's digits (of n) are trailing zeros.
 */
static inline int put_padded(char *t, uint64_t d, int n)
{
    memset(t, '0', 34);
    if (n > 8) {
        const uint64_t high = d / 100000000;
        if (n > 16)
            t[0] = (char)('0' + high / 100000000);
        put_eight_digits(t + 1, (uint32_t)(high % 100000000));
    }
    put_eight_digits(t + 9, (uint32_t)(d % 100000000));
    int zeros = trailing_zeros8(t + 9);
    if (zeros == 8)
        zeros += trailing_zeros8(t + 1);
    return zeros < n ? zeros : n - 1;
}

/* out[0 .. count-1] = out[1 .. count], count <= 16, the bytes after left: 8 at a time. */
static inline void shift_left(char *out, int count)
{
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    for (int i = 0; i < count; i += 8) {
        uint64_t here, next;
        memcpy(&here, out + i, 8);
        memcpy(&next, out + i + 1, 8);
        const uint64_t mask = count - i >= 8 ? ~UINT64_C(0) : (UINT64_C(1) << (8 * (count - i))) - 1;
        here = (next & mask) | (here & ~mask);
        memcpy(out + i, &here, 8);
    }
#else
    for (int i = 0; i < count; i++)
        out[i] = out[i + 1];
#endif
}

/*
 * The text of value at out; returns its end.  Exponent form, d.ddde-XX, below 1e-4 and from
 * 10^16 (shortest) or 10^digits (rounded) up, as Python's repr and C's %.<digits>g; else plain,
 * trailing zeros and a trailing point dropped.  The digits are laid out from a zero-padded
 * copy by moves of fixed size, which compile to a few instructions; every write stays within
 * MT_NUMBER_MAX bytes of where the text begins (the bounds reserve that much), though it may
 * touch bytes past the text's end there.
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
    uint64_t d;
    if (s->digits)
        d = number_rounded(a, s->digits, &e);
    else if (!short_decimal(a, bits, &d, &e))
        d = number_shortest(a, &e);
    char t[40];
    const int length = decimal_length(d); /* <= 17 */
    const int zeros = put_padded(t, d, length);
    const int n = length - zeros;         /* the significant digits: t[17 - length ..] */
    const char *digits = t + 17 - length;
    const int e10 = e + length - 1;       /* value = d.ddd 10^e10 */
    if (e10 < -4 || e10 >= (s->digits ? s->digits : 16)) {
        out[0] = digits[0];
        out[1] = '.';
        memcpy(out + 2, digits + 1, 16);
        out += n > 1 ? n + 1 : 1;
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
        memcpy(out, "0.000", 5);
        out += 1 - e10;
        memcpy(out, digits, 17);
        return out + n;
    }
    if (n <= e10 + 1) { /* ddd000: the zeros that follow the digits in t */
        memcpy(out, digits, 17);
        return out + e10 + 1;
    }
    memcpy(out + 1, digits, 17);
    shift_left(out, e10 + 1); /* ddd.ddd: the whole part moves before the point */
    out[e10 + 1] = '.';
    return out + n + 1;
}

static inline void put_slot(double value, const struct style *s, struct texts *t, size_t i)
{
    t->len[i] = (unsigned char)(put_number(value, s, t->text[i]) - t->text[i]);
}

/* The text of slot i at out; returns its end.  Copies MT_NUMBER_MAX bytes, which the bounds
   reserve for every number, whatever its length. */
static inline char *copy_slot(const struct texts *t, size_t i, char *out)
{
    memcpy(out, t->text[i], MT_NUMBER_MAX);
    return out + t->len[i];
}

int mt_number_code_runs(int code)
{
    switch (code) {
    case MT_NUMBER_CODE_BEST:
    case MT_NUMBER_CODE_PORTABLE:
        return 1;
    case MT_NUMBER_CODE_AVX2:
        return mt_cpu_runs_v3();
    case MT_NUMBER_CODE_AVX512:
        return mt_cpu_runs_v4();
    default:
        return 0;
    }
}

int mt_number_code(void)
{
    return mt_cpu_runs_v4() ? MT_NUMBER_CODE_AVX512 : mt_cpu_runs_v3() ? MT_NUMBER_CODE_AVX2 : MT_NUMBER_CODE_PORTABLE;
}

/* The code that writes a call's shortest texts: `code` with MT_NUMBER_CODE_BEST made the code it
   stands for; -1 for a code this processor does not run, or none of enum mt_number_code. */
static int chosen_code(int code)
{
    if (!mt_number_code_runs(code))
        return -1;
    return code == MT_NUMBER_CODE_BEST ? mt_number_code() : code;
}

/* The texts of values[0 .. count-1] (count <= SLOTS) into the first count slots, the shortest
   ones by `code` (chosen_code's), which leaves what its lanes do not do to put_number. */
static void put_texts(const double *values, size_t count, const struct style *s, int code, struct texts *t)
{
    const size_t vector = s->digits == 0 && code != MT_NUMBER_CODE_PORTABLE
                              ? texts_x86(values, count, s->exponent_digits, code, t)
                              : 0;
    for (size_t i = 0; i < vector; i++)
        if (t->len[i] == 0)
            put_slot(values[i], s, t, i);
    for (size_t i = vector; i < count; i++)
        put_slot(values[i], s, t, i);
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
                     const size_t *counts, size_t nkeys, const struct mt_format_style *style, int code,
                     char *buf, size_t cap, size_t *written)
{
    struct style s;
    const int chosen = chosen_code(code);
    if (written == NULL || (frames > 0 && (values == NULL || buf == NULL)) ||
        (nkeys > 0 && (!keys || !key_lens || !offsets || !counts)) || !unpack_style(style, &s) || chosen < 0)
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
    /* the texts of as many whole frames as the slots hold, then their lines */
    struct texts texts;
    const size_t group = channels == 0 || channels > SLOTS ? 1 : SLOTS / channels;
    for (size_t f0 = 0; f0 < frames; f0 += group) {
        const size_t rows = frames - f0 < group ? frames - f0 : group;
        const int slotted = channels > 0 && channels <= SLOTS;
        if (slotted)
            put_texts(values + f0 * channels, rows * channels, &s, chosen, &texts);
        for (size_t f = f0; f < f0 + rows; f++) {
            char number[20];
            const char *start = digits_before((uint64_t)first_frame + f, number + sizeof number);
            memcpy(out, start, (size_t)(number + sizeof number - start));
            out = put_newline(&s.frame_newline, out + (number + sizeof number - start));
            const double *row = values + f * channels;
            const size_t slot = (f - f0) * channels;
            for (size_t k = 0; k < nkeys; k++) {
                memcpy(out, keys[k], key_lens[k]);
                out += key_lens[k];
                for (size_t i = 0; i < counts[k]; i++) {
                    *out++ = ' ';
                    out = slotted ? copy_slot(&texts, slot + offsets[k] + i, out)
                                  : put_number(row[offsets[k] + i], &s, out);
                }
                out = put_newline(&s.newline, out);
            }
        }
    }
    *written = (size_t)(out - buf);
    return MT_OK;
}

int mt_format_table(const double *values, size_t rows, size_t columns, const struct mt_format_style *style,
                    int code, char *buf, size_t cap, size_t *written)
{
    struct style s;
    const int chosen = chosen_code(code);
    if (written == NULL || (rows > 0 && (buf == NULL || (columns > 0 && values == NULL))) ||
        !unpack_style(style, &s) || chosen < 0)
        return MT_EINVAL;
    *written = 0;
    if (cap < mt_format_table_bound(rows, columns, style))
        return MT_ERANGE;
    char *out = buf;
    struct texts texts;
    const size_t group = columns == 0 || columns > SLOTS ? 1 : SLOTS / columns;
    const int slotted = columns > 0 && columns <= SLOTS;
    for (size_t r0 = 0; r0 < rows; r0 += group) {
        const size_t n = rows - r0 < group ? rows - r0 : group;
        if (slotted)
            put_texts(values + r0 * columns, n * columns, &s, chosen, &texts);
        for (size_t r = r0; r < r0 + n; r++) {
            for (size_t c = 0; c < columns; c++) {
                if (c > 0)
                    *out++ = ' ';
                out = slotted ? copy_slot(&texts, (r - r0) * columns + c, out)
                              : put_number(values[r * columns + c], &s, out);
            }
            out = put_newline(&s.newline, out);
        }
    }
    *written = (size_t)(out - buf);
    return MT_OK;
}
