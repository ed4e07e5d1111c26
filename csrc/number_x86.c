/*
 * number_x86.c - number_shortest's Dragonbox (number.c) in the lanes of x86-64 vectors: eight
 * values at a time with AVX-512 (x86-64-v4), four with AVX2 (x86-64-v3), for format_x86.c.
 * The same tables and constants (number_pow10.h, number.h); what the lanes cannot settle they
 * leave to number_shortest.
 */
#include "number.h"
#include "number_pow10.h"
#include "x86.h"

#if MT_X86
#include <immintrin.h>

/* The divisions of the lanes by KAPPA_BIG and KAPPA_SMALL, by products: x / 1000 =
   ((x / 8) DIVIDE_BIG) / 2^68 for any 64-bit x (as compilers divide); x / 100 =
   (x DIVIDE_SMALL) / 2^19 for the x < 2^13 here. */
#define DIVIDE_BIG INT64_C(0x20c49ba5e353f7cf)
#define DIVIDE_SMALL 5243
_Static_assert(KAPPA_BIG == 1000 && KAPPA_SMALL == 100, "DIVIDE_BIG and DIVIDE_SMALL are for these divisors");

/* The high 64 bits of each lane's 128-bit a * b, and the low 64 to *lo (NULL: not wanted), from
   the four 32 x 32-bit products (AVX-512 multiplies no wider). */
MT_V4_CODE static inline __m512i mul_high(__m512i a, __m512i b, __m512i *lo)
{
    const __m512i low32 = _mm512_set1_epi64(0xffffffff);
    const __m512i a_hi = _mm512_srli_epi64(a, 32), b_hi = _mm512_srli_epi64(b, 32);
    const __m512i ll = _mm512_mul_epu32(a, b), lh = _mm512_mul_epu32(a, b_hi);
    const __m512i hl = _mm512_mul_epu32(a_hi, b), hh = _mm512_mul_epu32(a_hi, b_hi);
    const __m512i mid = _mm512_add_epi64(_mm512_add_epi64(_mm512_srli_epi64(ll, 32), _mm512_and_si512(lh, low32)),
                                         _mm512_and_si512(hl, low32));
    if (lo != NULL)
        *lo = _mm512_or_si512(_mm512_slli_epi64(mid, 32), _mm512_and_si512(ll, low32));
    return _mm512_add_epi64(_mm512_add_epi64(hh, _mm512_srli_epi64(lh, 32)),
                            _mm512_add_epi64(_mm512_srli_epi64(hl, 32), _mm512_srli_epi64(mid, 32)));
}

/* floor(x k / 2^s) of each lane, for the fixed-point logarithms (x k within 64 bits, signed) */
MT_V4_CODE static inline __m512i times_shift(__m512i x, int64_t k, int s)
{
    return _mm512_srai_epi64(_mm512_mullo_epi64(x, _mm512_set1_epi64(k)), (unsigned)s);
}

/* number_shortest's Dragonbox, lane by lane, for normal values other than powers of two. */
MT_V4_CODE unsigned number_shortest8(const double *a, uint64_t *d, int64_t *exp10)
{
    const __m512i bits = _mm512_and_si512(_mm512_loadu_si512(a), _mm512_set1_epi64((int64_t)MASK63));
    const __m512i biased = _mm512_srli_epi64(bits, 52), fraction = _mm512_and_si512(bits, _mm512_set1_epi64(MASK52));
    __mmask8 done = _mm512_cmpneq_epi64_mask(biased, _mm512_setzero_si512()) &
                    _mm512_cmpneq_epi64_mask(biased, _mm512_set1_epi64(0x7ff)) &
                    _mm512_cmpneq_epi64_mask(fraction, _mm512_setzero_si512());
    const __m512i c = _mm512_or_si512(fraction, _mm512_set1_epi64(INT64_C(1) << 52));
    const __m512i q = _mm512_sub_epi64(biased, _mm512_set1_epi64(1075));
    const __m512i minus_k = _mm512_sub_epi64(times_shift(q, LOG10_2, LOG10_2_SHIFT), _mm512_set1_epi64(KAPPA));
    const __m512i beta_minus_1 = _mm512_add_epi64(q, times_shift(_mm512_sub_epi64(_mm512_setzero_si512(), minus_k),
                                                                 LOG2_10, LOG2_10_SHIFT)); /* 6 .. 9 */
    /* phi(-minus_k): lanes outside the table (not done) read its first row */
    __m512i row = _mm512_sub_epi64(_mm512_set1_epi64(-CACHE_MIN), minus_k);
    row = _mm512_maskz_mov_epi64(done, _mm512_slli_epi64(row, 1));
    const long long *table = (const long long *)&pow10_phi[0][0];
    const __m512i phi0 = _mm512_i64gather_epi64(row, table, 8);
    const __m512i phi1 = _mm512_i64gather_epi64(_mm512_add_epi64(row, _mm512_set1_epi64(1)), table, 8);
    const __m512i delta = _mm512_srlv_epi64(phi0, _mm512_sub_epi64(_mm512_set1_epi64(63), beta_minus_1));
    const __m512i x = _mm512_sllv_epi64(_mm512_add_epi64(_mm512_slli_epi64(c, 1), _mm512_set1_epi64(1)), beta_minus_1);
    /* z = floor(x phi / 2^128) */
    __m512i low0;
    const __m512i high0 = mul_high(x, phi0, &low0), high1 = mul_high(x, phi1, NULL);
    const __m512i middle = _mm512_add_epi64(low0, high1);
    const __m512i z = _mm512_mask_add_epi64(high0, _mm512_cmplt_epu64_mask(middle, high1), high0,
                                            _mm512_set1_epi64(1));
    /* z / KAPPA_BIG as compilers divide: (z / 8) DIVIDE_BIG / 2^68 */
    const __m512i quotient = _mm512_srli_epi64(
        mul_high(_mm512_srli_epi64(z, 3), _mm512_set1_epi64(DIVIDE_BIG), NULL), 4);
    const __m512i r = _mm512_sub_epi64(z, _mm512_mullo_epi64(quotient, _mm512_set1_epi64(KAPPA_BIG)));
    const __mmask8 larger = _mm512_cmplt_epu64_mask(r, delta);
    /* at the interval's ends number_shortest tests exactly */
    done &= _mm512_cmpneq_epi64_mask(r, _mm512_setzero_si512()) & _mm512_cmpneq_epi64_mask(r, delta);
    const __m512i dist =
        _mm512_add_epi64(_mm512_sub_epi64(r, _mm512_srli_epi64(delta, 1)), _mm512_set1_epi64(KAPPA_SMALL / 2));
    const __m512i dist_q = _mm512_srli_epi64(_mm512_mullo_epi64(dist, _mm512_set1_epi64(DIVIDE_SMALL)), 19);
    /* a tie or a step past the nearest: the parity tells, in number_shortest */
    done &= ~(_mm512_cmpeq_epi64_mask(dist, _mm512_mullo_epi64(dist_q, _mm512_set1_epi64(KAPPA_SMALL))) & ~larger);
    const __m512i tens = _mm512_mullo_epi64(quotient, _mm512_set1_epi64(10));
    _mm512_storeu_si512(d, _mm512_mask_add_epi64(tens, (__mmask8)~larger, tens, dist_q));
    _mm512_storeu_si512(exp10, _mm512_add_epi64(minus_k, _mm512_set1_epi64(KAPPA)));
    return done;
}
#define K4(x) _mm256_set1_epi64x((int64_t)(x)) /* x in every lane */

/* mul_high in AVX2 lanes: the high 64 bits of each lane's a * b, the low 64 to *lo (NULL: not wanted). */
MT_V3_CODE static inline __m256i mul_high4(__m256i a, __m256i b, __m256i *lo)
{
    const __m256i low32 = K4(0xffffffff);
    const __m256i a_hi = _mm256_srli_epi64(a, 32), b_hi = _mm256_srli_epi64(b, 32);
    const __m256i ll = _mm256_mul_epu32(a, b), lh = _mm256_mul_epu32(a, b_hi);
    const __m256i hl = _mm256_mul_epu32(a_hi, b), hh = _mm256_mul_epu32(a_hi, b_hi);
    const __m256i mid = _mm256_add_epi64(_mm256_add_epi64(_mm256_srli_epi64(ll, 32), _mm256_and_si256(lh, low32)),
                                         _mm256_and_si256(hl, low32));
    if (lo != NULL)
        *lo = _mm256_or_si256(_mm256_slli_epi64(mid, 32), _mm256_and_si256(ll, low32));
    return _mm256_add_epi64(_mm256_add_epi64(hh, _mm256_srli_epi64(lh, 32)),
                            _mm256_add_epi64(_mm256_srli_epi64(hl, 32), _mm256_srli_epi64(mid, 32)));
}

/* floor(x k / 2^s) of each lane, where x k fits in 32 bits, signed: floor_log10_pow2 and
   floor_log2_pow10 with Jeon's smaller constants (checked equal over the exponents of doubles).
   The product of the low halves is exact in 64 bits; its high half, all sign, stays so shifted. */
MT_V3_CODE static inline __m256i times_shift4(__m256i x, int32_t k, int s)
{
    return _mm256_srai_epi32(_mm256_mul_epi32(x, _mm256_set1_epi32(k)), s);
}

/*
 * number_shortest8's Dragonbox in four lanes.  AVX2 has neither 64-bit products (from 32-bit
 * ones, as there), unsigned 64-bit comparisons (signed ones with the sign bit flipped), nor masks
 * (lanes of all ones), nor 64-bit arithmetic shifts (the logarithms' products fit in 32 bits).
 */
MT_V3_CODE unsigned number_shortest4(const double *a, uint64_t *d, int64_t *exp10)
{
    const __m256i zero = _mm256_setzero_si256();
    const __m256i bits = _mm256_and_si256(_mm256_loadu_si256((const __m256i *)a), K4(MASK63));
    const __m256i biased = _mm256_srli_epi64(bits, 52), fraction = _mm256_and_si256(bits, K4(MASK52));
    __m256i skip = _mm256_or_si256(_mm256_cmpeq_epi64(biased, zero), _mm256_cmpeq_epi64(biased, K4(0x7ff)));
    skip = _mm256_or_si256(skip, _mm256_cmpeq_epi64(fraction, zero));
    const __m256i c = _mm256_or_si256(fraction, K4(UINT64_C(1) << 52));
    const __m256i q = _mm256_sub_epi64(biased, K4(1075));
    const __m256i minus_k = _mm256_sub_epi64(times_shift4(q, LOG10_2_32, LOG10_2_32_SHIFT), K4(KAPPA));
    const __m256i beta_minus_1 =
        _mm256_add_epi64(q, times_shift4(_mm256_sub_epi64(zero, minus_k), LOG2_10_32, LOG2_10_32_SHIFT));
    /* phi(-minus_k): lanes outside the table (skipped) read its first row */
    const __m256i row = _mm256_andnot_si256(skip, _mm256_slli_epi64(_mm256_sub_epi64(K4(-CACHE_MIN), minus_k), 1));
    const long long *table = (const long long *)&pow10_phi[0][0];
    const __m256i phi0 = _mm256_i64gather_epi64(table, row, 8);
    const __m256i phi1 = _mm256_i64gather_epi64(table + 1, row, 8);
    const __m256i delta = _mm256_srlv_epi64(phi0, _mm256_sub_epi64(K4(63), beta_minus_1));
    const __m256i x = _mm256_sllv_epi64(_mm256_add_epi64(_mm256_slli_epi64(c, 1), K4(1)), beta_minus_1);
    /* z = floor(x phi / 2^128); middle < high1 (unsigned) is the carry */
    __m256i low0;
    const __m256i high0 = mul_high4(x, phi0, &low0), high1 = mul_high4(x, phi1, NULL);
    const __m256i middle = _mm256_add_epi64(low0, high1), sign = K4(UINT64_C(1) << 63);
    const __m256i carry = _mm256_cmpgt_epi64(_mm256_xor_si256(high1, sign), _mm256_xor_si256(middle, sign));
    const __m256i z = _mm256_sub_epi64(high0, carry);
    /* z / KAPPA_BIG as compilers divide; the remainder (< KAPPA_BIG) from the low 32 bits alone */
    const __m256i quotient = _mm256_srli_epi64(mul_high4(_mm256_srli_epi64(z, 3), K4(DIVIDE_BIG), NULL), 4);
    const __m256i r = _mm256_and_si256(_mm256_sub_epi64(z, _mm256_mul_epu32(quotient, K4(KAPPA_BIG))), K4(0xffffffff));
    const __m256i larger = _mm256_cmpgt_epi64(delta, r);
    /* at the interval's ends number_shortest tests exactly */
    skip = _mm256_or_si256(skip, _mm256_or_si256(_mm256_cmpeq_epi64(r, zero), _mm256_cmpeq_epi64(r, delta)));
    const __m256i dist = _mm256_add_epi64(_mm256_sub_epi64(r, _mm256_srli_epi64(delta, 1)), K4(KAPPA_SMALL / 2));
    const __m256i dist_q = _mm256_srli_epi64(_mm256_mul_epu32(dist, K4(DIVIDE_SMALL)), 19); /* unused where larger */
    /* a tie or a step past the nearest: the parity tells, in number_shortest */
    const __m256i step = _mm256_cmpeq_epi64(dist, _mm256_mul_epu32(dist_q, K4(KAPPA_SMALL)));
    skip = _mm256_or_si256(skip, _mm256_andnot_si256(larger, step));
    const __m256i tens = _mm256_add_epi64(_mm256_slli_epi64(quotient, 3), _mm256_slli_epi64(quotient, 1));
    _mm256_storeu_si256((__m256i *)d, _mm256_add_epi64(tens, _mm256_andnot_si256(larger, dist_q)));
    _mm256_storeu_si256((__m256i *)exp10, _mm256_add_epi64(minus_k, K4(KAPPA)));
    return ~(unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(skip)) & 15u;
}
#undef K4
#endif /* MT_X86 */
