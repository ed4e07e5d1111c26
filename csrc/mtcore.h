/*
 * mtcore.h - the one contract between the C kernels of motiontheater and Python.
 *
 * Layout.  Every array is C-contiguous and viewed as (outer, n, inner): the
 * filtered axis has length n, `outer` is the product of the axes before it and
 * `inner` the product of the axes after it.  Sample (o, t, i) of such an array
 * is at p[(o * n + t) * inner + i].  A motion (frames, channels) filtered along
 * its frames is the case outer = 1, n = frames, inner = channels.
 *
 * Ownership.  The caller allocates every input and output; the kernels allocate
 * only small scratch buffers, which they free before returning.  Outputs never
 * alias inputs.  Kernels keep no state between calls and are re-entrant (cffi
 * releases the GIL around every call).
 *
 * Status.  Every mt_* function returns MT_OK (0) or a negative MT_E* code and
 * never prints, aborts or exits.  mt_strerror() names a code.
 *
 * The region between the MT_CDEF markers is read by the cffi build
 * (src/mtcore/_cffi_build.py): it must stay plain declarations and enums.
 */
#ifndef MTCORE_H
#define MTCORE_H

#include <stddef.h>

/* MT_CDEF_BEGIN */
enum mt_status {
    MT_OK = 0,
    MT_EINVAL = -1, /* an argument is outside its documented range */
    MT_ENOMEM = -2, /* scratch memory could not be allocated */
    MT_EDTYPE = -3  /* the element type code is not one of mt_dtype */
};

enum mt_dtype {
    MT_FLOAT32 = 0,
    MT_FLOAT64 = 1
};

/*
 * How a line is extended past its ends, for the line a b c d and the fill
 * value k (the five modes of scipy.ndimage).  An extension longer than the
 * line repeats the pattern.
 *
 *   reflect   d c b a | a b c d | d c b a
 *   nearest   a a a a | a b c d | d d d d
 *   mirror      d c b | a b c d | c b a
 *   constant  k k k k | a b c d | k k k k
 *   wrap      a b c d | a b c d | a b c d
 */
enum mt_mode {
    MT_MODE_REFLECT = 0,
    MT_MODE_NEAREST = 1,
    MT_MODE_MIRROR = 2,
    MT_MODE_CONSTANT = 3,
    MT_MODE_WRAP = 4
};

enum mt_filter {
    MT_FILTER_MEDIAN = 0,   /* element of rank size/2 of the window; NaN if the window holds NaN */
    MT_FILTER_UNIFORM = 1,  /* mean of the window */
    MT_FILTER_CORRELATE = 2 /* sum of weights[j] * window[j] */
};

const char *mt_strerror(int status);

/*
 * One-dimensional filter along the middle axis of (outer, n, inner) arrays of
 * element type `dtype`.  Output sample t is computed from the window of input
 * samples t - size/2 - origin + j, j = 0 .. size-1, extended by `mode` with
 * fill value `cval`.  Only output frames begin .. end-1 of every line are
 * written (0 and n for all of them), so that separate calls on disjoint
 * ranges can share one output from several threads; a range that begins at
 * a multiple of mt_filter1d_block(size) gives, bit for bit, what one call
 * over all frames gives there (the running sums of the uniform filter
 * restart at those multiples).  Requires
 * begin <= end <= n, size >= 1 and
 * -(size/2) <= origin <= (size-1)/2; `weights` (size doubles) is read only by
 * MT_FILTER_CORRELATE and may be NULL otherwise.  Means and weighted sums are
 * accumulated in double for float32 data.
 */
int mt_filter1d(int filter, int dtype, const void *in, void *out,
                size_t outer, size_t n, size_t inner, size_t begin, size_t end,
                size_t size, ptrdiff_t origin, int mode, double cval,
                const double *weights);

/* The block length, in frames, of mt_filter1d for a window of `size`. */
size_t mt_filter1d_block(size_t size);
/* MT_CDEF_END */

#endif /* MTCORE_H */
