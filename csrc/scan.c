/*
 * scan.c - frame text (AMC-style) into a values array, in one pass.
 *
 * Numbers (the grammar of mtcore.h) take an exact fast path: a decimal with at most 19
 * significant digits whose mantissa is at most 2^53 and whose power of ten is at most 22 in
 * magnitude is the mantissa times or divided by an exactly representable power of ten, one
 * correctly rounded operation (Clinger 1990).  Every other token goes to number_parse
 * (number.c), exact for any length, so that every value equals what Python's float() gives
 * for the same text.
 */
#define _POSIX_C_SOURCE 200809L /* sigsetjmp, for the guard */
#include "guard.h"
#include "mtcore.h"
#include "number.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* What each byte is to the scanner: a lookup, not four comparisons, per byte. */
enum { BLANK = 1, EOL = 2 };
static const unsigned char byte_class[256] = {['\t'] = BLANK, ['\v'] = BLANK, ['\f'] = BLANK, [' '] = BLANK,
                                              ['\n'] = EOL,   ['\r'] = EOL};

static int is_blank(char c)
{
    return byte_class[(unsigned char)c] & BLANK;
}

static int is_eol(char c)
{
    return byte_class[(unsigned char)c] & EOL;
}

/* A blank or a line end: what ends a token. */
static int ends_token(char c)
{
    return byte_class[(unsigned char)c] != 0;
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* The end of the token starting at p. */
static const char *token_end(const char *p, const char *end)
{
    while (p < end && !ends_token(*p))
        p++;
    return p;
}

/* Appends the digits at p to *mantissa, two per step to halve the multiply chain. */
static const char *take_digits(const char *p, const char *end, uint64_t *mantissa)
{
    uint64_t m = *mantissa;
    while (p + 1 < end && is_digit(p[0]) && is_digit(p[1])) {
        m = m * 100 + (uint64_t)((p[0] - '0') * 10 + (p[1] - '0'));
        p += 2;
    }
    if (p < end && is_digit(*p))
        m = m * 10 + (uint64_t)(*p++ - '0');
    *mantissa = m;
    return p;
}

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/* The count of digits that begin the eight bytes of w (the first byte lowest), 8 if all are. */
static inline int leading_digits(uint64_t w)
{
    const uint64_t x = w ^ UINT64_C(0x3030303030303030); /* a digit becomes its value, 0 .. 9 */
    const uint64_t other = ((x + UINT64_C(0x0606060606060606)) | x) & UINT64_C(0xf0f0f0f0f0f0f0f0);
    return other ? __builtin_ctzll(other) >> 3 : 8;
}

/* The value of the n (1 .. 8) digits that begin w: all eight at once (Lemire's fast_float). */
static inline uint64_t digits_value(uint64_t w, int n)
{
    uint64_t x = (w ^ UINT64_C(0x3030303030303030)) << (8 * (8 - n)); /* leading zeros instead */
    x = x * 10 + (x >> 8);
    x = ((x & UINT64_C(0x000000ff000000ff)) * UINT64_C(0x000f424000000064) +
         ((x >> 16) & UINT64_C(0x000000ff000000ff)) * UINT64_C(0x0000271000000001)) >>
        32;
    return x;
}

/*
 * The digits of a decimal's whole and fractional parts at *p, eight bytes at a time, where at
 * least eight bytes are left at each step and there are fewer than 8 whole digits and at most
 * 19 in all; returns 0 for the byte-wise reading to do it otherwise.
 */
static inline int take_decimal(const char **pp, const char *end, uint64_t *mantissa, int *count, int *exp10)
{
    const char *p = *pp;
    if (end - p < 8)
        return 0;
    uint64_t w;
    memcpy(&w, p, 8);
    int n = leading_digits(w);
    if (n == 8)
        return 0;
    uint64_t m = n ? digits_value(w, n) : 0;
    int digits = n, e = 0;
    p += n;
    if (*p == '.') {
        for (p++;; p += n) {
            if (end - p < 8)
                return 0;
            memcpy(&w, p, 8);
            n = leading_digits(w);
            if (n == 0)
                break;
            if (digits + n > 19)
                return 0;
            m = m * pow10_u64[n] + digits_value(w, n);
            digits += n;
            e -= n;
            if (n < 8) {
                p += n;
                break;
            }
        }
    }
    *pp = p;
    *mantissa = m;
    *count = digits;
    *exp10 = e;
    return 1;
}
#else
static inline int take_decimal(const char **pp, const char *end, uint64_t *mantissa, int *count, int *exp10)
{
    (void)pp, (void)end, (void)mantissa, (void)count, (void)exp10;
    return 0;
}
#endif

/*
 * Parses the number that starts at p, before end; returns the end of its
 * token, or NULL if the token is not a number.  One pass for the usual
 * decimals; other tokens are measured and handed to number_parse.
 */
static const char *parse_number(const char *p, const char *end, double *out)
{
    const char *start = p;
    int negative = 0;
    if (p < end && (*p == '-' || *p == '+'))
        negative = *p++ == '-';
    uint64_t mantissa = 0;
    int digits, exp10 = 0;
    if (take_decimal(&p, end, &mantissa, &digits, &exp10)) {
        /* the usual decimal: no exponent, a token's end after it (p is before end here) */
        if (digits > 0 && ends_token(*p) && mantissa <= ((uint64_t)1 << 53) && exp10 >= -22) {
            const double v = exact_decimal(mantissa, exp10);
            *out = negative ? -v : v;
            return p;
        }
    } else {
        /* Digits go into the mantissa unchecked; more than 19 of them (leading
           zeros included, which is rare) take the general path below. */
        const char *first = p;
        p = take_digits(p, end, &mantissa);
        digits = (int)(p - first);
        if (p < end && *p == '.') {
            const char *fraction = ++p;
            p = take_digits(p, end, &mantissa);
            exp10 = -(int)(p - fraction);
            digits -= exp10;
        }
    }
    const int exact = digits <= 19;
    if (p < end && (*p == 'e' || *p == 'E') && digits > 0) {
        const char *e = p + 1;
        int eneg = 0, evalue = 0;
        if (e < end && (*e == '-' || *e == '+'))
            eneg = *e++ == '-';
        if (e < end && is_digit(*e)) {
            for (; e < end && is_digit(*e); e++)
                if (evalue < 100000)
                    evalue = evalue * 10 + (*e - '0');
            exp10 += eneg ? -evalue : evalue;
            p = e;
        }
    }
    if (digits > 0 && exact && (p == end || ends_token(*p))) {
        if (mantissa <= ((uint64_t)1 << 53) && exp10 >= -22 && exp10 <= 22) {
            const double v = exact_decimal(mantissa, exp10);
            *out = negative ? -v : v;
            return p;
        }
        uint64_t bits; /* 16 to 19 digits, or large exponents */
        if (number_decimal(mantissa, exp10, &bits)) {
            bits |= (uint64_t)negative << 63;
            memcpy(out, &bits, sizeof bits);
            return p;
        }
    }
    const char *stop = token_end(start, end); /* inf, nan, long or odd forms, ties */
    return number_parse(start, stop, out) ? stop : NULL;
}

int mt_parse_number(const char *text, size_t len, double *value)
{
    if ((text == NULL && len > 0) || value == NULL)
        return MT_EINVAL;
    return len > 0 && number_parse(text, text + len, value) ? MT_OK : MT_ESYNTAX;
}

/*
 * Reads the numbers of the line at *p into dst[0 .. count-1], leaving *p at
 * the line's end; MT_ESYNTAX or MT_ECOUNT (with found/expected) otherwise.
 */
static int line_numbers(const char **p, const char *end, double *dst, size_t count,
                        struct mt_scan_report *r)
{
    const char *q = *p;
    size_t i = 0;
    for (;; i++) {
        while (q < end && is_blank(*q))
            q++;
        if (q == end || is_eol(*q))
            break;
        if (i >= count) { /* too many: count them for the report */
            q = token_end(q, end);
            continue;
        }
        const char *stop = parse_number(q, end, &dst[i]);
        if (stop == NULL) {
            r->found = (long long)i;
            *p = q;
            return MT_ESYNTAX;
        }
        q = stop;
    }
    *p = q;
    if (i != count) {
        r->found = (long long)i;
        r->expected = (long long)count;
        return MT_ECOUNT;
    }
    return MT_OK;
}

/*
 * Whether the line holding the token [tok, tok_end) and then [line_rest, end) is a frame
 * number line (one token of digits); its number to *number, or -1 above MT_FRAME_MAX.
 */
static int frame_line(const char *tok, const char *tok_end, const char *line_rest, const char *end,
                      long long *number)
{
    long long n = 0;
    for (const char *q = tok; q < tok_end; q++) {
        if (!is_digit(*q))
            return 0;
        if (n >= 0)
            n = n > (MT_FRAME_MAX - (*q - '0')) / 10 ? -1 : n * 10 + (*q - '0');
    }
    for (const char *q = line_rest; q < end && !is_eol(*q); q++)
        if (!is_blank(*q))
            return 0;
    *number = n;
    return 1;
}

struct scan {
    const char *const *keys;
    const size_t *key_lens, *offsets, *counts;
    size_t nkeys;
    size_t *seen_in;  /* frame (1-based) in which each key was last seen */
    size_t *order;    /* keys in the order of the first frame, to guess the next key */
    size_t norder;
    uint64_t *words;  /* per key: its first 16 bytes, zero-padded, and the masks of its bytes */
};

/* The words of each key of at most 16 bytes, for expected_key; NULL where malloc fails. */
static uint64_t *key_words(const char *const *keys, const size_t *key_lens, size_t nkeys)
{
    uint64_t *words = calloc(4 * nkeys + 1, sizeof *words);
    if (words == NULL)
        return NULL;
    for (size_t k = 0; k < nkeys; k++) {
        if (key_lens[k] > 16)
            continue; /* a mask of zeros: never found this way */
        unsigned char bytes[16] = {0}, mask[16] = {0};
        memcpy(bytes, keys[k], key_lens[k]);
        memset(mask, 0xff, key_lens[k]);
        memcpy(words + 4 * k, bytes, 16);
        memcpy(words + 4 * k + 2, mask, 16);
    }
    return words;
}

/*
 * The key that frame lines hold at `position` in the first frame, if the line at p begins with
 * it (followed by a blank or the line's end); else -1, for find_key to look.  Two words
 * compared, where the text has 16 bytes left: most lines of a frame come in the first's order.
 */
static long long expected_key(const struct scan *s, const char *p, const char *end, size_t position)
{
    if (position >= s->norder || end - p < 17)
        return -1;
    const size_t k = s->order[position], n = s->key_lens[k];
    const uint64_t *w = s->words + 4 * k;
    uint64_t t0, t1;
    memcpy(&t0, p, 8);
    memcpy(&t1, p + 8, 8);
    if (((t0 & w[2]) ^ w[0]) | ((t1 & w[3]) ^ w[1]) || n > 16 || !ends_token(p[n]))
        return -1;
    return (long long)k;
}

/* Keys are a few bytes long: an inline loop beats a call to memcmp. */
static int same_key(const struct scan *s, size_t k, const char *tok, size_t n)
{
    if (s->key_lens[k] != n)
        return 0;
    const char *key = s->keys[k];
    for (size_t i = 0; i < n; i++)
        if (key[i] != tok[i])
            return 0;
    return 1;
}

static long long find_key(const struct scan *s, const char *tok, size_t n, size_t position)
{
    if (position < s->norder && same_key(s, s->order[position], tok, n))
        return (long long)s->order[position];
    for (size_t k = 0; k < s->nkeys; k++)
        if (same_key(s, k, tok, n))
            return (long long)k;
    return -1;
}

/* The first key with numbers that frame `frame` (1-based) lacks, or -1. */
static long long missing_key(const struct scan *s, size_t frame)
{
    for (size_t k = 0; k < s->nkeys; k++)
        if (s->counts[k] > 0 && s->seen_in[k] != frame)
            return (long long)k;
    return -1;
}

static int scan_text(const char *text, const char *end, struct scan *s, double *values,
                     size_t max_frames, size_t channels, struct mt_scan_report *r)
{
    size_t frames = 0, position = 0;
    long long previous = 0;
    double *row = NULL;
    const char *p = text;
    r->line = 1;
    while (p < end) {
        while (p < end && is_blank(*p))
            p++;
        if (p < end && !is_eol(*p) && *p != '#') {
            long long k = frames > 0 && !is_digit(*p) ? expected_key(s, p, end, position) : -1;
            const char *tok = p, *tok_stop = k >= 0 ? p + s->key_lens[k] : token_end(p, end);
            long long number;
            if (k < 0 && frame_line(tok, tok_stop, tok_stop, end, &number)) {
                if (number < 0)
                    return MT_EFRAMERANGE;
                if (frames > 0 && (r->key = missing_key(s, frames)) >= 0)
                    return MT_EMISSING;
                if (frames > 0 && number != previous + 1) {
                    r->found = number;
                    r->expected = previous + 1;
                    return MT_EFRAME;
                }
                if (frames == max_frames)
                    return MT_ERANGE;
                if (frames == 0)
                    r->first_frame = number;
                row = values + frames * channels;
                previous = number;
                frames++;
                position = 0;
                r->frames = frames;
                p = tok_stop;
            } else {
                if (frames == 0) {
                    r->expected = -1; /* a frame number */
                    return MT_EFRAME;
                }
                if (k < 0 && (k = find_key(s, tok, (size_t)(tok_stop - tok), position)) < 0)
                    return MT_EUNKNOWN;
                r->key = k;
                if (s->seen_in[k] == frames)
                    return MT_EDUPLICATE;
                s->seen_in[k] = frames;
                if (frames == 1)
                    s->order[s->norder++] = (size_t)k;
                position++;
                p = tok_stop;
                const int status = line_numbers(&p, end, row + s->offsets[k], s->counts[k], r);
                if (status != MT_OK)
                    return status;
                r->key = -1;
            }
        }
        while (p < end && !is_eol(*p))
            p++; /* the rest of a comment line */
        if (p < end) {
            p += (*p == '\r' && p + 1 < end && p[1] == '\n') ? 2 : 1;
            r->line++;
            r->offset = (size_t)(p - text);
        }
    }
    r->offset = (size_t)(end - text); /* a frame cut short here is a truncated file */
    if (frames > 0 && (r->key = missing_key(s, frames)) >= 0)
        return MT_EMISSING;
    r->frames = frames;
    return MT_OK;
}

static int scan_table(const char *text, size_t len, size_t rows, size_t columns, double *values,
                      struct mt_scan_report *report)
{
    if (report == NULL)
        return MT_EINVAL;
    memset(report, 0, sizeof *report);
    report->key = -1;
    report->line = 1;
    if ((text == NULL && len > 0) || (values == NULL && rows > 0 && columns > 0))
        return MT_EINVAL;
    const char *p = text, *end = text + len;
    size_t row = 0;
    while (p < end) {
        while (p < end && is_blank(*p))
            p++;
        if (p < end && !is_eol(*p)) {
            if (row == rows)
                return MT_ERANGE;
            const int status = line_numbers(&p, end, values + row * columns, columns, report);
            if (status != MT_OK)
                return status;
            report->frames = ++row;
        }
        if (p < end) {
            p += (*p == '\r' && p + 1 < end && p[1] == '\n') ? 2 : 1;
            report->line++;
            report->offset = (size_t)(p - text);
        }
    }
    if (row < rows) {
        report->found = (long long)row;
        report->expected = (long long)rows;
        return MT_EMISSING;
    }
    return MT_OK;
}

int mt_scan_table(const char *text, size_t len, size_t rows, size_t columns, double *values,
                  struct mt_scan_report *report)
{
    int status;
    MT_GUARDED(status, scan_table(text, len, rows, columns, values, report));
    return status;
}

int mt_scan_frames(const char *text, size_t len, const char *const *keys, const size_t *key_lens,
                   const size_t *offsets, const size_t *counts, size_t nkeys, double *values,
                   size_t max_frames, size_t channels, struct mt_scan_report *report)
{
    if (report == NULL)
        return MT_EINVAL;
    memset(report, 0, sizeof *report);
    report->key = -1;
    if ((text == NULL && len > 0) || (nkeys > 0 && (!keys || !key_lens || !offsets || !counts)) ||
        (values == NULL && max_frames > 0 && channels > 0))
        return MT_EINVAL;
    for (size_t k = 0; k < nkeys; k++)
        if (keys[k] == NULL || key_lens[k] == 0 || offsets[k] > channels ||
            counts[k] > channels - offsets[k])
            return MT_EINVAL;
    struct scan s = {keys, key_lens, offsets, counts, nkeys, NULL, NULL, 0, NULL};
    s.seen_in = calloc(nkeys + 1, sizeof *s.seen_in);
    s.order = malloc((nkeys + 1) * sizeof *s.order);
    s.words = key_words(keys, key_lens, nkeys);
    int status = MT_ENOMEM;
    if (s.seen_in && s.order && s.words)
        MT_GUARDED(status, scan_text(text, text + len, &s, values, max_frames, channels, report));
    free(s.seen_in);
    free(s.order);
    free(s.words);
    return status;
}
