/*
 * style.c - how a file's text is laid out (line ends, exponents, its first frame line), so
 * that what is written from it can look the same.  Straight passes over the bytes: a take's
 * style costs a small fraction of scanning its numbers.
 */
#define _POSIX_C_SOURCE 200809L /* sigsetjmp, for the guard */
#include "guard.h"
#include "mtcore.h"

#include <stddef.h>

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static int is_eol(char c)
{
    return c == '\n' || c == '\r';
}

/*
 * Counting in loops of their own, without branches, into byte-sized counts of at most 255
 * bytes each: loops the compiler vectorises, many bytes to an instruction.
 */
static void count_line_ends(const char *text, size_t len, struct mt_text_style *style)
{
    size_t lf = 0, cr = 0, crlf = 0;
    for (size_t i = 0; i < len; i += 255) {
        const size_t n = len - i < 255 ? len - i : 255;
        unsigned char lfs = 0, crs = 0;
        for (size_t j = 0; j < n; j++) {
            lfs += text[i + j] == '\n';
            crs += text[i + j] == '\r';
        }
        lf += lfs;
        cr += crs;
    }
    for (size_t i = 0; cr > 0 && i + 1 < len; i += 255) {
        const size_t n = len - 1 - i < 255 ? len - 1 - i : 255;
        unsigned char pairs = 0;
        for (size_t j = 0; j < n; j++)
            pairs += (text[i + j] == '\r') & (text[i + j + 1] == '\n');
        crlf += pairs;
    }
    style->lf = lf - crlf;
    style->crlf = crlf;
    style->cr = cr - crlf;
}

/*
 * An exponent is 'e' or 'E' right after a digit or '.', then a sign and digits.  The first
 * written with a leading zero in more than one digit (1.23246e-013) sets the fewest digits;
 * else 1 where one has a single digit (1e-5), else 2.
 */
static int exponent_digits(const char *text, size_t len)
{
    int single = 0;
    for (size_t i = 1; i + 2 < len; i++) {
        if ((text[i] | 0x20) != 'e' || !(is_digit(text[i - 1]) || text[i - 1] == '.') ||
            (text[i + 1] != '-' && text[i + 1] != '+'))
            continue;
        size_t end = i + 2;
        while (end < len && is_digit(text[end]))
            end++;
        const size_t n = end - (i + 2);
        if (n > 1 && text[i + 2] == '0')
            return n > 3 ? 3 : (int)n;
        single |= n == 1;
        i = end - 1;
    }
    return single ? 1 : 2;
}

/* Where the line at p ends and its ending's kind; p is left at the next line. */
static int line_end(const char **p, const char *end)
{
    const char *q = *p;
    while (q < end && !is_eol(*q))
        q++;
    if (q == end) {
        *p = q;
        return -1;
    }
    if (*q == '\r' && q + 1 < end && q[1] == '\n') {
        *p = q + 2;
        return MT_NEWLINE_CRLF;
    }
    *p = q + 1;
    return *q == '\n' ? MT_NEWLINE_LF : MT_NEWLINE_CR;
}

/* The first line of blanks around digits only; its offset and ending to style. */
static void first_frame_line(const char *text, size_t len, struct mt_text_style *style)
{
    const char *p = text, *end = text + len;
    style->frame_line = -1;
    style->frame_newline = -1;
    while (p < end) {
        const char *line = p, *q = p;
        while (q < end && (*q == ' ' || *q == '\t'))
            q++;
        const char *digits = q;
        while (q < end && is_digit(*q))
            q++;
        int frame = q > digits;
        while (q < end && (*q == ' ' || *q == '\t'))
            q++;
        frame &= q == end || is_eol(*q);
        p = q;
        const int ending = line_end(&p, end);
        if (frame) {
            style->frame_line = (long long)(line - text);
            style->frame_newline = ending;
            return;
        }
    }
}

static int text_style(const char *text, size_t len, struct mt_text_style *style)
{
    count_line_ends(text, len, style);
    style->exponent_digits = exponent_digits(text, len);
    first_frame_line(text, len, style);
    return MT_OK;
}

int mt_text_style(const char *text, size_t len, struct mt_text_style *style)
{
    if (style == NULL || (text == NULL && len > 0))
        return MT_EINVAL;
    int status;
    MT_GUARDED(status, text_style(text, len, style));
    return status;
}
