/*
 * format_x86.c - the number writer's vector code for x86-64 processors: the shortest texts of
 * values in the lanes of AVX-512 (x86-64-v4) and AVX2 (x86-64-v3) vectors, each text laid out by
 * one byte shuffle from a table of the 20 layouts, for the slots of format.c (x86.h).  What the
 * lanes leave is format.c's portable code's, which writes the same bytes for every value
 * (tests/test_numbers.py compares them).
 */
#include "mtcore.h"
#include "number.h"
#include "x86.h"

#if MT_X86
#include <immintrin.h>
#include <string.h>

/*
 * The layouts of the vector code: the plain ones, one per decimal exponent e10 of -4 .. 14
 * (row e10 + 4), then the exponent form (row 19).  Each says which of the 16 bytes lead digit,
 * digits 2 .. 16 each byte of the text's first 16 takes (0x80: none), and what is put in where
 * none is taken ('.', '0').  From e10 >= 0: the e10 + 1 digits before the point, the point,
 * the others; below: "0.", -e10 - 1 zeros, the digits; the exponent form: the lead digit, the
 * point, the others (and "e-05" after the last).
 */
#define EXPONENT_FORM -1000 /* the row's e10 */
#define TAKE(j, e10)                                                                                 \
    ((e10) == EXPONENT_FORM ? ((j) == 1 ? 0x80 : (j) - ((j) > 0))                                 \
     : (e10) >= 0           ? ((j) <= (e10) ? (j) : (j) == (e10) + 1 ? 0x80 : (j) - 1)            \
                            : ((j) <= -(e10) ? 0x80 : (j) - 1 + (e10)))
#define PUT(j, e10)                                                                                  \
    ((e10) == EXPONENT_FORM ? ((j) == 1 ? '.' : 0)                                                \
     : (e10) >= 0           ? ((j) == (e10) + 1 ? '.' : 0)                                        \
                            : ((j) == 1 ? '.' : (j) <= -(e10) ? '0' : 0))
#define ROW(F, e10)                                                                                  \
    {F(0, e10),  F(1, e10),  F(2, e10),  F(3, e10),  F(4, e10),  F(5, e10),  F(6, e10),  F(7, e10),      \
     F(8, e10),  F(9, e10),  F(10, e10), F(11, e10), F(12, e10), F(13, e10), F(14, e10), F(15, e10)}
#define ROWS(F)                                                                                      \
    {ROW(F, -4), ROW(F, -3), ROW(F, -2), ROW(F, -1), ROW(F, 0),  ROW(F, 1),  ROW(F, 2),             \
     ROW(F, 3),  ROW(F, 4),  ROW(F, 5),  ROW(F, 6),  ROW(F, 7),  ROW(F, 8),  ROW(F, 9),             \
     ROW(F, 10), ROW(F, 11), ROW(F, 12), ROW(F, 13), ROW(F, 14), ROW(F, EXPONENT_FORM)}
static const unsigned char layout_take[20][16] = ROWS(TAKE);
static const unsigned char layout_put[20][16] = ROWS(PUT);
#undef EXPONENT_FORM
#undef TAKE
#undef PUT
#undef ROW
#undef ROWS

/* What the vector code works out in its lanes for each text: the 16 bytes the shuffle takes from
   (the lead digit, digits 2 .. 16), the text from its 17th byte, its length, its layout row, its
   sign (0 or 1), the exponent suffix and where it goes. */
struct lanes {
    uint64_t from[16], tail[8], len[8], row[8], sign[8], suffix[8], suffix_at[8];
};

/* The texts of slots i .. i + count - 1 from the lanes: those of `done` by one byte shuffle each,
   the others left to the portable code (length 0).  SSSE3, which the vector code's processors have. */
__attribute__((target("ssse3"), always_inline)) static inline void put_lanes(size_t i, size_t count, unsigned done,
                                                                             const struct lanes *l, struct texts *t)
{
    for (size_t j = 0; j < count; j++) {
        if (!((done >> j) & 1)) {
            t->len[i + j] = 0;
            continue;
        }
        char *slot = t->text[i + j];
        const __m128i from = _mm_loadu_si128((const __m128i *)(l->from + 2 * j));
        const __m128i take = _mm_loadu_si128((const __m128i *)layout_take[l->row[j]]);
        const __m128i put = _mm_loadu_si128((const __m128i *)layout_put[l->row[j]]);
        const __m128i text = _mm_or_si128(_mm_shuffle_epi8(from, take), put);
        slot[0] = '-'; /* overwritten where there is no sign */
        _mm_storeu_si128((__m128i *)(slot + l->sign[j]), text);
        memcpy(slot + l->sign[j] + 16, &l->tail[j], 8);
        memcpy(slot + l->suffix_at[j], &l->suffix[j], 8); /* past the end of a plain text */
        t->len[i + j] = (unsigned char)l->len[j];
    }
}

/*
 * The texts of values[0 .. count-1] by a vector code of `lanes` (<= 8) lanes: the shortest
 * decimals of `lanes` values by `shortest`, the parts of their texts by `parts`, each text by
 * put_lanes.  Each step for GROUPS groups of lanes before the next: one group's steps are a long
 * chain of operations each waiting for the one before, which the processor runs beside another
 * group's.  Returns how many were done (a multiple of `lanes`).
 */
typedef unsigned shortest_code(const double *a, uint64_t *d, int64_t *exp10);
typedef unsigned parts_code(const double *values, const uint64_t *d, const int64_t *e, unsigned done,
                            int exponent_digits, struct lanes *l);
enum { GROUPS = 2 };

__attribute__((target("ssse3"), always_inline)) static inline size_t
texts_vector(const double *values, size_t count, int exponent_digits, struct texts *t, size_t lanes,
             shortest_code *shortest, parts_code *parts)
{
    size_t i = 0;
    for (; i + GROUPS * lanes <= count; i += GROUPS * lanes) {
        uint64_t d[GROUPS * 8];
        int64_t e[GROUPS * 8];
        unsigned done[GROUPS];
        struct lanes l[GROUPS];
        for (size_t g = 0; g < GROUPS; g++)
            done[g] = shortest(values + i + g * lanes, d + g * lanes, e + g * lanes);
        for (size_t g = 0; g < GROUPS; g++)
            done[g] = parts(values + i + g * lanes, d + g * lanes, e + g * lanes, done[g], exponent_digits, &l[g]);
        for (size_t g = 0; g < GROUPS; g++)
            put_lanes(i + g * lanes, lanes, done[g], &l[g], t);
    }
    for (; i + lanes <= count; i += lanes) {
        uint64_t d[8];
        int64_t e[8];
        struct lanes l;
        const unsigned done = parts(values + i, d, e, shortest(values + i, d, e), exponent_digits, &l);
        put_lanes(i, lanes, done, &l, t);
    }
    return i;
}

#define K(x) _mm512_set1_epi64((int64_t)(x)) /* x in every lane */

/* Lane by lane: x for x < 16 from table[0 .. 15] of two vectors, else from the third. */
MT_V4_CODE static inline __m512i pick(__m512i x, __m512i t0, __m512i t1, __m512i t2)
{
    return _mm512_mask_permutexvar_epi64(_mm512_permutex2var_epi64(t0, x, t1),
                                         _mm512_cmpge_epu64_mask(x, _mm512_set1_epi64(16)), x, t2);
}

/* eight_digits of each lane */
MT_V4_CODE static inline __m512i eight_digits8(__m512i v)
{
    const __m512i high = _mm512_srli_epi64(_mm512_mullo_epi64(v, K(109951163)), 40); /* v / 10000 */
    const __m512i low = _mm512_sub_epi64(v, _mm512_mullo_epi64(high, K(10000)));
    const __m512i merged = _mm512_or_si512(high, _mm512_slli_epi64(low, 32));
    const __m512i top = _mm512_and_si512(_mm512_srli_epi64(_mm512_mullo_epi64(merged, K(10486)), 20),
                                         K((UINT64_C(0x7f) << 32) | 0x7f)); /* / 100 */
    const __m512i hundreds =
        _mm512_add_epi64(_mm512_slli_epi64(_mm512_sub_epi64(merged, _mm512_mullo_epi64(top, K(100))), 16), top);
    __m512i tens = _mm512_and_si512(_mm512_srli_epi64(_mm512_mullo_epi64(hundreds, K(103)), 10),
                                    K(0x000f000f000f000f)); /* / 10 */
    tens = _mm512_add_epi64(tens, _mm512_slli_epi64(_mm512_sub_epi64(hundreds, _mm512_mullo_epi64(tens, K(10))), 8));
    return _mm512_add_epi64(tens, K(ZEROS_WORD));
}

/* Each lane's q = x / unit and x - q unit, for x < 10 unit < 2^60, by a product in doubles
   (off by one at most) and a correction. */
MT_V4_CODE static inline __m512i divide8(__m512i x, uint64_t unit, __m512i *rest)
{
    const __m512d estimate = _mm512_mul_pd(_mm512_cvtepu64_pd(x), _mm512_set1_pd(1.0 / (double)unit));
    __m512i q = _mm512_cvttpd_epu64(estimate);
    __m512i r = _mm512_sub_epi64(x, _mm512_mullo_epi64(q, K(unit)));
    const __mmask8 under = _mm512_cmplt_epi64_mask(r, _mm512_setzero_si512());
    q = _mm512_mask_sub_epi64(q, under, q, K(1));
    r = _mm512_mask_add_epi64(r, under, r, K(unit));
    const __mmask8 over = _mm512_cmpge_epi64_mask(r, K(unit));
    *rest = _mm512_mask_sub_epi64(r, over, r, K(unit));
    return _mm512_mask_add_epi64(q, over, q, K(1));
}

/* 1 where the mask says, else 0 */
MT_V4_CODE static inline __m512i ones_where(__mmask8 mask)
{
    return _mm512_maskz_mov_epi64(mask, K(1));
}

/* The bytes of each lane's exponent suffix: "e", the sign, then |e10| in at least `least` digits;
   their count to *width. */
MT_V4_CODE static inline __m512i exponent_suffix(__m512i e10, int least, __m512i *width)
{
    const __m512i power = _mm512_abs_epi64(e10); /* < 1000 */
    const __m512i natural = _mm512_add_epi64(
        K(1), _mm512_add_epi64(ones_where(_mm512_cmpge_epi64_mask(power, K(10))),
                               ones_where(_mm512_cmpge_epi64_mask(power, K(100)))));
    *width = _mm512_max_epi64(natural, K(least));
    const __m512i hundreds = _mm512_srli_epi64(_mm512_mullo_epi64(power, K(5243)), 19); /* / 100 */
    const __m512i below = _mm512_sub_epi64(power, _mm512_mullo_epi64(hundreds, K(100)));
    const __m512i tens = _mm512_srli_epi64(_mm512_mullo_epi64(below, K(103)), 10); /* / 10 */
    const __m512i ones = _mm512_sub_epi64(below, _mm512_mullo_epi64(tens, K(10)));
    /* the three digits in bytes 0, 1, 2; the last `width` of them */
    const __m512i three = _mm512_or_si512(_mm512_or_si512(hundreds, _mm512_slli_epi64(tens, 8)),
                                          _mm512_slli_epi64(ones, 16));
    const __m512i digits = _mm512_add_epi64(
        _mm512_srlv_epi64(three, _mm512_slli_epi64(_mm512_sub_epi64(K(3), *width), 3)), K(0x303030));
    const __m512i e_sign = _mm512_mask_blend_epi64(_mm512_cmplt_epi64_mask(e10, _mm512_setzero_si512()),
                                                   K('e' | '+' << 8), K('e' | '-' << 8));
    return _mm512_or_si512(e_sign, _mm512_slli_epi64(digits, 16));
}

/*
 * The parts of the texts of values[0 .. 7] in lanes, for put_lanes: their shortest decimals d and
 * exponents e from number_shortest8 (done: its mask), their digits scaled to 17 (the lead digit and
 * two words of eight), the layout of their exponent, their 17th byte on from a shift, the exponent
 * form's suffix.  Returns done less what the lanes leave to put_number: besides number_shortest8's,
 * the plain texts from 1e15, whose point follows the 16th digit.
 */
MT_V4_CODE static inline unsigned lanes_avx512(const double *values, const uint64_t *d, const int64_t *e,
                                                   unsigned done_by_shortest, int exponent_digits, struct lanes *l)
{
    const __m512i pow10_0 = _mm512_loadu_si512(pow10_u64), pow10_1 = _mm512_loadu_si512(pow10_u64 + 8);
    const __m512i pow10_2 = _mm512_maskz_loadu_epi64(0x0f, pow10_u64 + 16);
    const __m512i zero = _mm512_setzero_si512();
    __mmask8 done = (__mmask8)done_by_shortest;
    const __m512i digits = _mm512_loadu_si512(d);
    /* the count of digits, from the bit length (or one more), then the digits scaled to 17 */
    const __m512i bits = _mm512_sub_epi64(K(64), _mm512_lzcnt_epi64(digits));
    const __m512i guess = _mm512_srli_epi64(_mm512_mullo_epi64(bits, K(1233)), 12);
    const __mmask8 more = _mm512_cmpge_epu64_mask(digits, pick(guess, pow10_0, pow10_1, pow10_2));
    const __m512i length = _mm512_add_epi64(guess, ones_where(more));
    done &= _mm512_cmple_epu64_mask(length, K(17));
    const __m512i scale = pick(_mm512_sub_epi64(K(17), length), pow10_0, pow10_1, pow10_2);
    const __m512i full = _mm512_mullo_epi64(digits, scale); /* 10^16 <= full < 10^17 */
    __m512i rest, low;
    const __m512i first = divide8(full, UINT64_C(10000000000000000), &rest);
    const __m512i high = eight_digits8(divide8(rest, 100000000, &low));
    low = eight_digits8(low);
    /* significant digits: 17 less the trailing '0's */
    const __m512i low_set = _mm512_xor_si512(low, K(ZEROS_WORD));
    const __m512i high_set = _mm512_xor_si512(high, K(ZEROS_WORD));
    const __m512i low_zeros = _mm512_srli_epi64(_mm512_lzcnt_epi64(low_set), 3);
    const __m512i high_zeros = _mm512_maskz_srli_epi64(_mm512_cmpeq_epi64_mask(low_set, zero),
                                                       _mm512_lzcnt_epi64(high_set), 3);
    const __m512i n = _mm512_sub_epi64(_mm512_sub_epi64(K(17), low_zeros), high_zeros);
    const __m512i e10 = _mm512_add_epi64(_mm512_loadu_si512(e), _mm512_sub_epi64(length, K(1)));
    /* plain from 1e-4 to below 1e15 (from there to 1e16 the point follows the 16th digit:
       put_number's), else the exponent form */
    const __mmask8 exponent_form = _mm512_cmplt_epi64_mask(e10, K(-4)) | _mm512_cmpge_epi64_mask(e10, K(16));
    done &= exponent_form | _mm512_cmple_epi64_mask(e10, K(14));
    const __m512i sign = _mm512_srli_epi64(_mm512_loadu_si512(values), 63);
    /* plain: "0." and zeros before the digits below 1, the point after `whole` digits */
    const __m512i zeros = _mm512_maskz_max_epi64((__mmask8)~exponent_form, _mm512_sub_epi64(zero, e10), zero);
    const __m512i whole = _mm512_max_epi64(_mm512_add_epi64(e10, K(1)), K(1));
    const __m512i shown = _mm512_add_epi64(zeros, n);
    const __m512i plain = _mm512_mask_add_epi64(whole, _mm512_cmpgt_epi64_mask(shown, whole), shown, K(1));
    /* the exponent form: d.ddd (d alone for one digit), then its suffix */
    const __m512i mantissa = _mm512_mask_add_epi64(K(1), _mm512_cmpgt_epi64_mask(n, K(1)), n, K(1));
    __m512i width;
    const __m512i suffix = exponent_suffix(e10, exponent_digits, &width);
    const __m512i suffix_at = _mm512_add_epi64(sign, _mm512_mask_mov_epi64(plain, exponent_form, mantissa));
    const __m512i len = _mm512_add_epi64(
        sign, _mm512_mask_add_epi64(plain, exponent_form, mantissa, _mm512_add_epi64(width, K(2))));
    /* the 16 bytes the shuffle takes from: the lead digit and digits 2 .. 16 */
    const __m512i w0 = _mm512_or_si512(_mm512_add_epi64(first, K('0')), _mm512_slli_epi64(high, 8));
    const __m512i w1 = _mm512_or_si512(_mm512_srli_epi64(high, 56), _mm512_slli_epi64(low, 8));
    /* and the text from its 17th byte: the digits from the (16 - zeros)th */
    const __m512i tail = _mm512_srlv_epi64(low, _mm512_sub_epi64(K(48), _mm512_slli_epi64(zeros, 3)));
    _mm512_storeu_si512(l->from, _mm512_permutex2var_epi64(w0, _mm512_set_epi64(11, 3, 10, 2, 9, 1, 8, 0), w1));
    _mm512_storeu_si512(l->from + 8, _mm512_permutex2var_epi64(w0, _mm512_set_epi64(15, 7, 14, 6, 13, 5, 12, 4), w1));
    _mm512_storeu_si512(l->tail, tail);
    _mm512_storeu_si512(l->len, len);
    _mm512_storeu_si512(l->row, _mm512_mask_blend_epi64(exponent_form, _mm512_add_epi64(e10, K(4)), K(19)));
    _mm512_storeu_si512(l->suffix, suffix);
    _mm512_storeu_si512(l->suffix_at, suffix_at);
    _mm512_storeu_si512(l->sign, sign);
    return done;
}

/* The texts of values[0 .. count-1] by the AVX-512 code, eight at a time (texts_vector). */
MT_V4_CODE static size_t texts_avx512(const double *values, size_t count, int exponent_digits, struct texts *t)
{
    return texts_vector(values, count, exponent_digits, t, 8, number_shortest8, lanes_avx512);
}
#undef K

#define K4(x) _mm256_set1_epi64x((int64_t)(x)) /* x in every lane */

/* Each lane as a double, correctly rounded: its two halves exact, then one addition. */
MT_V3_CODE static inline __m256d to_double4(__m256i x)
{
    const __m256i high = _mm256_or_si256(_mm256_srli_epi64(x, 32), K4(0x4530000000000000)); /* 2^84 + high 2^32 */
    const __m256i low = _mm256_blend_epi32(x, K4(0x4330000000000000), 0xaa);                 /* 2^52 + low */
    const __m256d high_part = _mm256_sub_pd(_mm256_castsi256_pd(high), _mm256_set1_pd(0x1p84 + 0x1p52));
    return _mm256_add_pd(high_part, _mm256_castsi256_pd(low));
}

/* The eight digits of each lane v < 10^8 in its bytes, as eight_digits8, in 32- and 16-bit lanes. */
MT_V3_CODE static inline __m256i eight_digits4(__m256i v)
{
    const __m256i high = _mm256_srli_epi64(_mm256_mul_epu32(v, K4(109951163)), 40); /* v / 10000 */
    const __m256i low = _mm256_sub_epi64(v, _mm256_mul_epu32(high, K4(10000)));
    const __m256i merged = _mm256_or_si256(high, _mm256_slli_epi64(low, 32)); /* x < 10000 in each 32 bits */
    const __m256i top = _mm256_srli_epi16(_mm256_mulhi_epu16(merged, _mm256_set1_epi16(5243)), 3); /* x / 100 */
    const __m256i hundreds = _mm256_add_epi32(
        _mm256_slli_epi32(_mm256_sub_epi16(merged, _mm256_mullo_epi16(top, _mm256_set1_epi16(100))), 16), top);
    __m256i tens = _mm256_mulhi_epu16(hundreds, _mm256_set1_epi16(6554)); /* x / 10 for x < 100 */
    tens = _mm256_add_epi16(
        tens, _mm256_slli_epi16(_mm256_sub_epi16(hundreds, _mm256_mullo_epi16(tens, _mm256_set1_epi16(10))), 8));
    return _mm256_add_epi64(tens, K4(ZEROS_WORD));
}

/* How many of the eight digits in each lane's bytes are '0' at the end (the last byte is the last
   digit): from the exponent of the lane whose bytes are 1 where a digit is not '0', as a double
   (its bits are eight apart: rounding never reaches the next power of two). */
MT_V3_CODE static inline __m256i trailing_zeros4(__m256i digits)
{
    const __m256i set = _mm256_andnot_si256(_mm256_cmpeq_epi8(digits, K4(ZEROS_WORD)), K4(0x0101010101010101));
    const __m256i exponent = _mm256_srli_epi64(_mm256_castpd_si256(to_double4(set)), 52); /* 1023 + 8 top, or 0 */
    return _mm256_min_epu32(_mm256_srli_epi64(_mm256_sub_epi64(K4(1023 + 63), exponent), 3), K4(8));
}

/* Each lane's q = x / unit and x - q unit, for q < 2^31, by a product in doubles (off by one at
   most) and a correction. */
MT_V3_CODE static inline __m256i divide4(__m256i x, uint32_t unit, __m256i *rest)
{
    const __m256d estimate = _mm256_mul_pd(to_double4(x), _mm256_set1_pd(1.0 / unit));
    __m256i q = _mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(estimate));
    __m256i r = _mm256_sub_epi64(x, _mm256_mul_epu32(q, K4(unit)));
    const __m256i under = _mm256_cmpgt_epi64(_mm256_setzero_si256(), r); /* all ones: -1 */
    q = _mm256_add_epi64(q, under);
    r = _mm256_add_epi64(r, _mm256_and_si256(under, K4(unit)));
    const __m256i over = _mm256_cmpgt_epi64(r, K4(unit - 1));
    *rest = _mm256_sub_epi64(r, _mm256_and_si256(over, K4(unit)));
    return _mm256_sub_epi64(q, over);
}

/* exponent_suffix in AVX2 lanes (|e10| < 1000, so 32-bit operations serve). */
MT_V3_CODE static inline __m256i exponent_suffix4(__m256i e10, int least, __m256i *width)
{
    const __m256i power = _mm256_and_si256(_mm256_abs_epi32(e10), K4(0xffffffff));
    const __m256i natural = _mm256_sub_epi64(_mm256_sub_epi64(K4(1), _mm256_cmpgt_epi64(power, K4(9))),
                                             _mm256_cmpgt_epi64(power, K4(99)));
    *width = _mm256_max_epi32(natural, K4(least));
    const __m256i hundreds = _mm256_srli_epi64(_mm256_mul_epu32(power, K4(5243)), 19); /* / 100 */
    const __m256i below = _mm256_sub_epi64(power, _mm256_mul_epu32(hundreds, K4(100)));
    const __m256i tens = _mm256_srli_epi64(_mm256_mul_epu32(below, K4(103)), 10); /* / 10 */
    const __m256i ones = _mm256_sub_epi64(below, _mm256_mul_epu32(tens, K4(10)));
    const __m256i three = _mm256_or_si256(_mm256_or_si256(hundreds, _mm256_slli_epi64(tens, 8)),
                                          _mm256_slli_epi64(ones, 16));
    const __m256i digits = _mm256_add_epi64(
        _mm256_srlv_epi64(three, _mm256_slli_epi64(_mm256_sub_epi64(K4(3), *width), 3)), K4(0x303030));
    const __m256i e_sign = _mm256_blendv_epi8(K4('e' | '+' << 8), K4('e' | '-' << 8),
                                              _mm256_cmpgt_epi64(_mm256_setzero_si256(), e10));
    return _mm256_or_si256(e_sign, _mm256_slli_epi64(digits, 16));
}

/*
 * lanes_avx512 in four AVX2 lanes, after number_shortest4.  AVX2 lacks much of what that code uses:
 * for masks, lanes of all ones; for 64-bit products, 32- and 16-bit ones, as the values allow; for
 * lzcnt and conversions between 64-bit integers and doubles, the exponents of doubles made from
 * two exact halves; for picks from a table in registers, gathers; for the exponent suffix, work
 * only where a lane needs it.
 */
MT_V3_CODE static inline unsigned lanes_avx2(const double *values, const uint64_t *d, const int64_t *e,
                                               unsigned done, int exponent_digits, struct lanes *l)
{
    const long long *pow10 = (const long long *)pow10_u64;
    const __m256i zero = _mm256_setzero_si256();
    const __m256i digits = _mm256_loadu_si256((const __m256i *)d);
    /* the count of digits, from the bit length (that of the nearest double: one more at most, the
       guess the same or one less), then the digits scaled to 17 */
    const __m256i exponent = _mm256_srli_epi64(_mm256_castpd_si256(to_double4(digits)), 52);
    const __m256i bits = _mm256_max_epi32(_mm256_sub_epi64(exponent, K4(1022)), zero); /* 0 for 0 */
    const __m256i guess = _mm256_srli_epi64(_mm256_mul_epu32(bits, K4(1233)), 12);    /* <= 19 */
    const __m256i less = _mm256_cmpgt_epi64(_mm256_i64gather_epi64(pow10, guess, 8), digits);
    const __m256i length = _mm256_add_epi64(_mm256_add_epi64(guess, K4(1)), less);
    const __m256i too_long = _mm256_cmpgt_epi64(length, K4(17));
    done &= ~(unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(too_long));
    const __m256i scale =
        _mm256_i64gather_epi64(pow10, _mm256_andnot_si256(too_long, _mm256_sub_epi64(K4(17), length)), 8);
    /* full = digits scale, 10^16 <= full < 10^17, from 32-bit products (scale < 2^54) */
    const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(digits, 32), scale),
                                           _mm256_mul_epu32(digits, _mm256_srli_epi64(scale, 32)));
    const __m256i full = _mm256_add_epi64(_mm256_mul_epu32(digits, scale), _mm256_slli_epi64(cross, 32));
    __m256i low;
    const __m256i upper = divide4(full, 100000000, &low); /* < 10^9: the lead digit and eight */
    const __m256i first = _mm256_srli_epi64(_mm256_mul_epu32(upper, K4(1441151881)), 57); /* / 10^8 */
    const __m256i high = eight_digits4(_mm256_sub_epi64(upper, _mm256_mul_epu32(first, K4(100000000))));
    low = eight_digits4(low);
    /* significant digits: 17 less the trailing '0's */
    const __m256i low_zeros = trailing_zeros4(low);
    const __m256i high_zeros = _mm256_and_si256(_mm256_cmpeq_epi64(low_zeros, K4(8)), trailing_zeros4(high));
    const __m256i n = _mm256_sub_epi64(_mm256_sub_epi64(K4(17), low_zeros), high_zeros);
    const __m256i e10 = _mm256_add_epi64(_mm256_loadu_si256((const __m256i *)e), _mm256_sub_epi64(length, K4(1)));
    /* plain from 1e-4 to below 1e15 (from there to 1e16: put_number's), else the exponent form */
    const __m256i exponent_form = _mm256_or_si256(_mm256_cmpgt_epi64(K4(-4), e10), _mm256_cmpgt_epi64(e10, K4(15)));
    const __m256i shown_here = _mm256_or_si256(exponent_form, _mm256_cmpgt_epi64(K4(15), e10));
    done &= (unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(shown_here));
    const __m256i sign = _mm256_srli_epi64(_mm256_loadu_si256((const __m256i *)values), 63);
    /* plain: "0." and zeros before the digits below 1, the point after `whole` digits.  The maxima
       of 64-bit lanes that 32 bits hold by 32-bit maxima: a negative lane's high half (all ones)
       against a constant's (zero) gives zero. */
    const __m256i zeros = _mm256_andnot_si256(exponent_form, _mm256_max_epi32(_mm256_sub_epi64(zero, e10), zero));
    const __m256i whole = _mm256_max_epi32(_mm256_add_epi64(e10, K4(1)), K4(1));
    const __m256i shown = _mm256_add_epi64(zeros, n);
    const __m256i plain = _mm256_blendv_epi8(whole, _mm256_add_epi64(shown, K4(1)), _mm256_cmpgt_epi64(shown, whole));
    /* the exponent form: d.ddd (d alone for one digit), then its suffix */
    const __m256i mantissa = _mm256_blendv_epi8(K4(1), _mm256_add_epi64(n, K4(1)), _mm256_cmpgt_epi64(n, K4(1)));
    __m256i width = zero, suffix = zero;
    if (!_mm256_testz_si256(exponent_form, exponent_form))
        suffix = exponent_suffix4(e10, exponent_digits, &width);
    const __m256i suffix_at = _mm256_add_epi64(sign, _mm256_blendv_epi8(plain, mantissa, exponent_form));
    const __m256i len = _mm256_add_epi64(
        sign, _mm256_blendv_epi8(plain, _mm256_add_epi64(mantissa, _mm256_add_epi64(width, K4(2))), exponent_form));
    /* the 16 bytes the shuffle takes from, and the text from its 17th byte, as lanes_avx512's */
    const __m256i w0 = _mm256_or_si256(_mm256_add_epi64(first, K4('0')), _mm256_slli_epi64(high, 8));
    const __m256i w1 = _mm256_or_si256(_mm256_srli_epi64(high, 56), _mm256_slli_epi64(low, 8));
    const __m256i tail = _mm256_srlv_epi64(low, _mm256_sub_epi64(K4(48), _mm256_slli_epi64(zeros, 3)));
    const __m256i from01 = _mm256_unpacklo_epi64(w0, w1), from23 = _mm256_unpackhi_epi64(w0, w1);
    _mm256_storeu_si256((__m256i *)l->from, _mm256_permute2x128_si256(from01, from23, 0x20));
    _mm256_storeu_si256((__m256i *)(l->from + 4), _mm256_permute2x128_si256(from01, from23, 0x31));
    _mm256_storeu_si256((__m256i *)l->tail, tail);
    _mm256_storeu_si256((__m256i *)l->len, len);
    _mm256_storeu_si256((__m256i *)l->row, _mm256_blendv_epi8(_mm256_add_epi64(e10, K4(4)), K4(19), exponent_form));
    _mm256_storeu_si256((__m256i *)l->suffix, suffix);
    _mm256_storeu_si256((__m256i *)l->suffix_at, suffix_at);
    _mm256_storeu_si256((__m256i *)l->sign, sign);
    return done;
}

/* The texts of values[0 .. count-1] by the AVX2 code, four at a time (texts_vector). */
MT_V3_CODE static size_t texts_avx2(const double *values, size_t count, int exponent_digits, struct texts *t)
{
    return texts_vector(values, count, exponent_digits, t, 4, number_shortest4, lanes_avx2);
}
#undef K4

size_t texts_x86(const double *values, size_t count, int exponent_digits, int code, struct texts *t)
{
    switch (code) {
    case MT_NUMBER_CODE_AVX512:
        return texts_avx512(values, count, exponent_digits, t);
    case MT_NUMBER_CODE_AVX2:
        return texts_avx2(values, count, exponent_digits, t);
    default:
        return 0;
    }
}
#endif /* MT_X86 */
