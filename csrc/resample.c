/*
 * resample.c - polyphase rational resampling (upsample, FIR, downsample:
 * scipy.signal.upfirdn); see mt_upfirdn in mtcore.h.
 *
 * Output row j is the sum over input rows i of v[i] h[J down - i up],
 * J = skip + j: the rows i with 0 <= J down - i up < taps, which take every
 * up-th tap from phase (J down) mod up on.  Rows before the line come from
 * `before`, rows after it from `after` (the edge extension the caller
 * chose) and rows beyond those are zero, so their taps are left out.  Each
 * output row is a weighted sum of whole input rows, taken four taps at a
 * time, its inner loop over the contiguous channels.
 */
#include "clones.h"
#include "lines.h"
#include "mtcore.h"

#include <stdint.h>
#include <stdlib.h>

struct source {
    const double *in, *before, *after, *zeros;
    ptrdiff_t n, nbefore, nafter;
    size_t channels;
};

static const double *source_row(const struct source *s, ptrdiff_t i)
{
    if (i < 0)
        return s->before + (size_t)(s->nbefore + i) * s->channels;
    if (i < s->n)
        return s->in + (size_t)i * s->channels;
    return s->after + (size_t)(i - s->n) * s->channels;
}

/* o = sum of the count taps coef[m * up] * row(i_hi - m), m = 0 .. count-1. */
static MT_CLONES void weighted_rows(const struct source *s, const double *coef, size_t up, ptrdiff_t i_hi,
                                    size_t count, double *restrict o)
{
    const size_t nch = s->channels;
    if (count == 0) {
        for (size_t k = 0; k < nch; k++)
            o[k] = 0.0;
        return;
    }
    for (size_t m = 0; m < count; m += 4) {
        const double *q[4];
        double w[4];
        for (size_t g = 0; g < 4; g++) {
            /* missing taps of the last group read a row of zeros with weight 0 (0 * inf would be NaN) */
            q[g] = m + g < count ? source_row(s, i_hi - (ptrdiff_t)(m + g)) : s->zeros;
            w[g] = m + g < count ? coef[(m + g) * up] : 0.0;
        }
        if (m == 0) {
            MT_IVDEP for (size_t k = 0; k < nch; k++) o[k] = w[0] * q[0][k] + w[1] * q[1][k] + w[2] * q[2][k] + w[3] * q[3][k];
        } else {
            MT_IVDEP for (size_t k = 0; k < nch; k++) o[k] += w[0] * q[0][k] + w[1] * q[1][k] + w[2] * q[2][k] + w[3] * q[3][k];
        }
    }
}

int mt_upfirdn(const double *h, size_t taps, size_t up, size_t down, const double *in, size_t n, size_t channels,
               const double *before, size_t nbefore, const double *after, size_t nafter, size_t skip, size_t begin,
               size_t end, double *out)
{
    if (h == NULL || taps == 0 || up == 0 || down == 0 || begin > end)
        return MT_EINVAL;
    if ((nbefore > 0 && before == NULL) || (nafter > 0 && after == NULL))
        return MT_EINVAL;
    const size_t limit = PTRDIFF_MAX / 4;
    if (n > limit || nbefore > limit || nafter > limit || taps > limit || up > limit || skip > limit ||
        end > limit || skip + end > limit / down)
        return MT_EINVAL;
    if (begin == end || channels == 0)
        return MT_OK;
    if (out == NULL || (n > 0 && in == NULL))
        return MT_EINVAL;

    double *zeros = calloc(channels, sizeof *zeros);
    if (zeros == NULL)
        return MT_ENOMEM;
    const struct source s = {.in = in, .before = before, .after = after, .zeros = zeros, .n = (ptrdiff_t)n,
                             .nbefore = (ptrdiff_t)nbefore, .nafter = (ptrdiff_t)nafter, .channels = channels};
    const ptrdiff_t first = -(ptrdiff_t)nbefore, last = (ptrdiff_t)(n + nafter) - 1;
    for (size_t j = begin; j < end; j++) {
        const size_t pos = (skip + j) * down, phase = pos % up;
        ptrdiff_t i_hi = (ptrdiff_t)(pos / up);
        size_t m0 = 0, count = phase < taps ? (taps - 1 - phase) / up + 1 : 0;
        /* keep the rows first .. last: drop taps from the top, then from the bottom */
        if (i_hi > last) {
            m0 = (size_t)(i_hi - last);
            count = count > m0 ? count - m0 : 0;
            i_hi = last;
        }
        const ptrdiff_t lowest = i_hi - (ptrdiff_t)count + 1;
        if (count > 0 && lowest < first)
            count = i_hi >= first ? (size_t)(i_hi - first + 1) : 0;
        weighted_rows(&s, count ? h + phase + m0 * up : h, up, i_hi, count, out + j * channels);
    }
    free(zeros);
    return MT_OK;
}
