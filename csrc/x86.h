/*
 * x86.h - build-internal: what the portable number writer (format.c) shares with its vector code
 * for x86-64 processors (format_x86.c, number_x86.c), and how it calls that code.
 *
 * The writer works the texts of many values out into slots before it lays out the lines that
 * hold them (which may take a row's values in any order): each in a slot of 32 bytes, of which
 * a text takes MT_NUMBER_MAX at most, its length beside.  The vector code fills what its lanes
 * can and leaves the rest (length 0: no text is empty) to the portable code.
 */
#ifndef MT_X86_H
#define MT_X86_H

#include "cpu.h"

#include <stddef.h>
#include <stdint.h>

#define ZEROS_WORD UINT64_C(0x3030303030303030) /* "00000000" */

enum { SLOTS = 512 };
struct texts {
    char text[SLOTS][32];
    unsigned char len[SLOTS];
};

#if MT_X86
/*
 * The shortest texts of values[0 .. count-1] (count <= SLOTS), exponents in at least
 * exponent_digits digits, into the first slots by `code`'s vector code (MT_NUMBER_CODE_AVX2 or
 * _AVX512, which the processor runs: mt_number_code_runs).  Returns how many slots it went
 * through, from the first; among them, those of length 0 are left to the portable code.
 */
size_t texts_x86(const double *values, size_t count, int exponent_digits, int code, struct texts *t);

/*
 * number_shortest of |a[0]| .. |a[7]| at once, in the lanes of AVX-512 vectors: the decimals to d
 * and exp10 for the lanes of the mask returned.  The other lanes are left to number_shortest:
 * zero, subnormal, not finite, a power of two (its narrow interval), or one of the few whose
 * interval ends or middle fall on a step of the decimals (about one value in a hundred).
 */
MT_V4_CODE unsigned number_shortest8(const double *a, uint64_t *d, int64_t *exp10);

/* The same for |a[0]| .. |a[3]|, in the lanes of AVX2 vectors. */
MT_V3_CODE unsigned number_shortest4(const double *a, uint64_t *d, int64_t *exp10);
#else
/* No vector code: nothing done. */
static inline size_t texts_x86(const double *values, size_t count, int exponent_digits, int code, struct texts *t)
{
    (void)values, (void)count, (void)exponent_digits, (void)code, (void)t;
    return 0;
}
#endif

#endif /* MT_X86_H */
