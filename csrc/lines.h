/*
 * lines.h - build-internal: helpers of the kernels that walk lines of samples
 * down the rows of a (frames, stride) array: the smoothing filters (filter.c)
 * and the signal kernels (bands.c, iir.c, resample.c, gaps.c).
 */
#ifndef MT_LINES_H
#define MT_LINES_H

#include "mtcore.h"

#include <stddef.h>

/* Tells the compiler that the pointers of the loop that follows do not overlap. */
#ifndef MT_IVDEP
#if defined(__clang__)
#define MT_IVDEP _Pragma("clang loop vectorize(assume_safety)")
#elif defined(__GNUC__)
#define MT_IVDEP _Pragma("GCC ivdep")
#else
#define MT_IVDEP
#endif
#endif

/*
 * The sample of 0 .. n-1 (n >= 1) that position r of the line extended by
 * `mode` (enum mt_mode) repeats, or -1 where the extension is the fill value
 * (constant mode).  An extension longer than the line repeats the pattern.
 */
static inline ptrdiff_t mt_extend_index(ptrdiff_t r, ptrdiff_t n, int mode)
{
    if (r >= 0 && r < n)
        return r;
    switch (mode) {
    case MT_MODE_NEAREST:
        return r < 0 ? 0 : n - 1;
    case MT_MODE_WRAP: {
        ptrdiff_t m = r % n;
        return m < 0 ? m + n : m;
    }
    case MT_MODE_REFLECT: {
        ptrdiff_t period = 2 * n, m = r % period;
        if (m < 0)
            m += period;
        return m < n ? m : period - 1 - m;
    }
    case MT_MODE_MIRROR: {
        if (n == 1)
            return 0;
        ptrdiff_t period = 2 * n - 2, m = r % period;
        if (m < 0)
            m += period;
        return m < n ? m : period - m;
    }
    default:
        return -1;
    }
}

#endif /* MT_LINES_H */
