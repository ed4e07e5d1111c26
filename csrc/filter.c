/*
 * filter.c - median, uniform (moving average) and weighted (correlate)
 * filters along one axis of (outer, n, inner) arrays; see mtcore.h.
 *
 * The driver cuts each line into chunks of output frames.  For a chunk it
 * builds a table with one pointer per input row that the chunk's windows
 * read: rows before the line (filling phase) and after it (draining phase)
 * are mapped by the edge mode, interior rows (steady state) point straight
 * into the array.  A kernel then computes the chunk's output rows from that
 * table, its inner loop running over the contiguous channels of a row, so
 * that it vectorises and never tests for edges.
 *
 * When the filtered axis is (nearly) the last one, rows are only a few
 * values wide; the driver then gathers TILE_LINES lines side by side into a
 * small tile, so that they become the channels, and scatters the results back.
 *
 * A window longer than the line (size > n) would need a table of size rows
 * however short the line.  The median and the mean then take another path
 * (filter_long in filter_kernels.inc): each line keeps how many times each
 * of its samples occurs in the window (window_counts), which the window
 * changes by two counts per step; time and memory grow with n, never with
 * size.  Every size computation is checked for overflow: a product that
 * does not fit is MT_ENOMEM, never a short buffer.
 */
#include "clones.h"
#include "lines.h"
#include "mtcore.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum {
    MIN_CHUNK = 256,       /* output frames per chunk, at least */
    TILE_LINES = 16,       /* lines gathered into a tile when inner is small */
    CHANNEL_BLOCK = 256,   /* channels per kernel call on the direct path */
    SORTED_BUDGET = 1 << 20 /* elements of sorted windows kept at once */
};

/* malloc of count elements of size bytes, NULL when the product does not fit in size_t. */
static void *alloc_array(size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size)
        return NULL;
    return malloc(count * size > 0 ? count * size : 1);
}

/*
 * Frames from t0 to the next multiple of chunk (or to end): chunks start at
 * fixed frames whatever range a call covers, so that the running sums
 * restart at the same frames when a range begins at a multiple of chunk.
 */
static size_t chunk_length(size_t t0, size_t end, size_t chunk)
{
    size_t next = (t0 / chunk + 1) * chunk;
    return (next < end ? next : end) - t0;
}

/*
 * How many times each sample of a line of n occurs among the extended
 * positions lo .. lo+size-1: counts[i] for sample i, counts[n] for the fill
 * value (constant mode).  The periodic modes repeat a pattern of `period`
 * positions that holds every sample once (wrap) or twice (reflect; mirror
 * but for its two end samples): the window holds size / period whole
 * patterns and size % period positions more.  nearest and constant hold the
 * line (or a part) between runs of the edge or fill value.  O(n) time.
 */
static void window_counts(ptrdiff_t lo, size_t size, size_t n, int mode, size_t *counts)
{
    const ptrdiff_t len = (ptrdiff_t)n, hi = lo + (ptrdiff_t)size - 1;
    memset(counts, 0, (n + 1) * sizeof *counts);
    if (mode == MT_MODE_NEAREST || mode == MT_MODE_CONSTANT) {
        const size_t below = lo < 0 ? (size_t)((hi < -1 ? hi : -1) - lo + 1) : 0;
        const size_t above = hi >= len ? (size_t)(hi - (lo > len ? lo : len) + 1) : 0;
        for (ptrdiff_t i = lo > 0 ? lo : 0; i <= hi && i < len; i++)
            counts[i]++;
        counts[mode == MT_MODE_NEAREST ? 0 : n] += below;
        counts[mode == MT_MODE_NEAREST ? n - 1 : n] += above;
        return;
    }
    const size_t period = mode == MT_MODE_WRAP      ? n
                          : mode == MT_MODE_REFLECT ? 2 * n
                          : n == 1                  ? 1
                                                    : 2 * n - 2;
    const size_t whole = size / period, rest = size % period;
    for (size_t p = 0; p < period; p++)
        counts[mt_extend_index((ptrdiff_t)p, len, mode)] += whole;
    for (size_t j = 0; j < rest; j++)
        counts[mt_extend_index(lo + (ptrdiff_t)j, len, mode)]++;
}

/* Sample (or n for the fill value) at position r of the extended line. */
static size_t sample_at(ptrdiff_t r, size_t n, int mode)
{
    const ptrdiff_t i = mt_extend_index(r, (ptrdiff_t)n, mode);
    return i < 0 ? n : (size_t)i;
}

/* The place p (1-based) in sorted order of the element of rank `target` (0-based): the first p
   whose prefix count exceeds target (Fenwick 1994). */
static size_t fenwick_find(const size_t *tree, size_t len, size_t target)
{
    size_t step = 1, at = 0;
    while (step <= len / 2)
        step *= 2;
    for (; step > 0; step /= 2)
        if (at + step <= len && tree[at + step] <= target) {
            at += step;
            target -= tree[at];
        }
    return at + 1;
}

static void fenwick_add(size_t *tree, size_t len, size_t at, size_t delta)
{
    for (; at <= len; at += at & (~at + 1))
        tree[at] += delta; /* delta SIZE_MAX subtracts one: unsigned arithmetic wraps */
}

/* Copies of non-finite samples in a window: the mean is NaN, +inf or -inf by these. */
struct nonfinite {
    size_t nan, pos, neg;
};

/* Adds (delta 1) or removes (delta SIZE_MAX) copies of the value v: to the sum, or to the count of its kind. */
static void nonfinite_add(struct nonfinite *bad, double v, size_t delta)
{
    if (v != v)
        bad->nan += delta;
    else if (v > 0)
        bad->pos += delta;
    else
        bad->neg += delta;
}

/* Whether every a[0 .. n-1] is finite. */
static int all_finite(const double *a, size_t n)
{
    int bad = 0;
    for (size_t k = 0; k < n; k++)
        bad |= a[k] - a[k] != 0; /* x - x is 0 for every finite x */
    return !bad;
}

/* Median sizes with a fixed selection network (Paeth; Devillard 1998). */
static int has_network(size_t size)
{
    return size == 1 || size == 3 || size == 5 || size == 7 || size == 9;
}

struct job {
    int filter, mode;
    size_t outer, n, inner, begin, end, size;
    ptrdiff_t lead; /* output frame t reads input frames t - lead .. t - lead + size - 1 */
    double cval;
    const double *weights;
    const void *in;
    void *out;
};

#define MT_CAT_(a, b) a##_##b
#define MT_CAT(a, b) MT_CAT_(a, b)
#define FN(name) MT_CAT(name, SUFFIX)
#define MIN(a, b) ((a) < (b) ? (a) : (b))

/* Orders a pair in place; min/max form, so that it compiles to branchless vector code. */
#define SORT2(a, b)                                                                                \
    do {                                                                                           \
        T lo_ = (a) < (b) ? (a) : (b);                                                             \
        (b) = (a) < (b) ? (b) : (a);                                                               \
        (a) = lo_;                                                                                 \
    } while (0)

/*
 * A kernel for the median of N using the selection network NETWORK on p[0..N-1],
 * which leaves the median in p[N/2].  Min/max order NaN arbitrarily, so the
 * kernel first notes which table rows hold NaN (one pass over each row, not
 * one per window) and sets the outputs of windows holding NaN afterwards.
 */
#define NETWORK_KERNEL(N, NETWORK)                                                                 \
    static MT_CLONES void FN(median##N)(const T *const *rows, T *out, size_t ostride, size_t m,    \
                                        size_t nch, unsigned char *nanrow)                         \
    {                                                                                              \
        for (size_t r = 0; r < m + N - 1; r++)                                                     \
            nanrow[r] = FN(row_has_nan)(rows[r], nch);                                             \
        for (size_t t = 0; t < m; t++) {                                                           \
            const T *r[N];                                                                         \
            int dirty = 0;                                                                         \
            for (int j = 0; j < N; j++) {                                                          \
                r[j] = rows[t + j];                                                                \
                dirty |= nanrow[t + j];                                                            \
            }                                                                                      \
            T *o = out + t * ostride;                                                              \
            MT_IVDEP for (size_t k = 0; k < nch; k++)                                              \
            {                                                                                      \
                T p[N];                                                                            \
                for (int j = 0; j < N; j++)                                                        \
                    p[j] = r[j][k];                                                                \
                NETWORK;                                                                           \
                o[k] = p[N / 2];                                                                   \
            }                                                                                      \
            if (dirty)                                                                             \
                FN(nan_windows)(rows + t, N, o, nch);                                              \
        }                                                                                          \
    }

#define NETWORK1 (void)0
#define NETWORK3                                                                                   \
    SORT2(p[0], p[1]);                                                                             \
    SORT2(p[1], p[2]);                                                                             \
    SORT2(p[0], p[1])
#define NETWORK5                                                                                   \
    SORT2(p[0], p[1]);                                                                             \
    SORT2(p[3], p[4]);                                                                             \
    SORT2(p[0], p[3]);                                                                             \
    SORT2(p[1], p[4]);                                                                             \
    SORT2(p[1], p[2]);                                                                             \
    SORT2(p[2], p[3]);                                                                             \
    SORT2(p[1], p[2])
#define NETWORK7                                                                                   \
    SORT2(p[0], p[5]);                                                                             \
    SORT2(p[0], p[3]);                                                                             \
    SORT2(p[1], p[6]);                                                                             \
    SORT2(p[2], p[4]);                                                                             \
    SORT2(p[0], p[1]);                                                                             \
    SORT2(p[3], p[5]);                                                                             \
    SORT2(p[2], p[6]);                                                                             \
    SORT2(p[2], p[3]);                                                                             \
    SORT2(p[3], p[6]);                                                                             \
    SORT2(p[4], p[5]);                                                                             \
    SORT2(p[1], p[4]);                                                                             \
    SORT2(p[1], p[3]);                                                                             \
    SORT2(p[3], p[4])
#define NETWORK9                                                                                   \
    SORT2(p[1], p[2]);                                                                             \
    SORT2(p[4], p[5]);                                                                             \
    SORT2(p[7], p[8]);                                                                             \
    SORT2(p[0], p[1]);                                                                             \
    SORT2(p[3], p[4]);                                                                             \
    SORT2(p[6], p[7]);                                                                             \
    SORT2(p[1], p[2]);                                                                             \
    SORT2(p[4], p[5]);                                                                             \
    SORT2(p[7], p[8]);                                                                             \
    SORT2(p[0], p[3]);                                                                             \
    SORT2(p[5], p[8]);                                                                             \
    SORT2(p[4], p[7]);                                                                             \
    SORT2(p[3], p[6]);                                                                             \
    SORT2(p[1], p[4]);                                                                             \
    SORT2(p[2], p[5]);                                                                             \
    SORT2(p[4], p[7]);                                                                             \
    SORT2(p[4], p[2]);                                                                             \
    SORT2(p[6], p[4]);                                                                             \
    SORT2(p[4], p[2])

#define T double
#define SUFFIX f64
#include "filter_kernels.inc"
#undef T
#undef SUFFIX

#define T float
#define SUFFIX f32
#include "filter_kernels.inc"
#undef T
#undef SUFFIX

size_t mt_filter1d_block(size_t size)
{
    return size > MIN_CHUNK ? size : MIN_CHUNK;
}

int mt_filter1d(int filter, int dtype, const void *in, void *out, size_t outer, size_t n,
                size_t inner, size_t begin, size_t end, size_t size, ptrdiff_t origin, int mode, double cval,
                const double *weights)
{
    if (filter < MT_FILTER_MEDIAN || filter > MT_FILTER_CORRELATE)
        return MT_EINVAL;
    if (dtype != MT_FLOAT32 && dtype != MT_FLOAT64)
        return MT_EDTYPE;
    if (mode < MT_MODE_REFLECT || mode > MT_MODE_WRAP || size < 1 || size > PTRDIFF_MAX / 4)
        return MT_EINVAL;
    ptrdiff_t half = (ptrdiff_t)(size / 2);
    if (origin < -half || origin > (ptrdiff_t)((size - 1) / 2))
        return MT_EINVAL;
    if (filter == MT_FILTER_CORRELATE && weights == NULL)
        return MT_EINVAL;
    if (begin > end || end > n)
        return MT_EINVAL;
    if (outer == 0 || begin == end || inner == 0)
        return MT_OK;
    /* No array holds more than PTRDIFF_MAX bytes: larger dimensions are a caller's error. */
    const size_t item = dtype == MT_FLOAT64 ? sizeof(double) : sizeof(float);
    if (in == NULL || out == NULL || n > PTRDIFF_MAX / 4 || inner > (size_t)PTRDIFF_MAX / item / n ||
        outer > (size_t)PTRDIFF_MAX / item / (n * inner))
        return MT_EINVAL;

    struct job job = {.filter = filter, .mode = mode, .outer = outer, .n = n, .inner = inner,
                      .begin = begin, .end = end, .size = size, .lead = half + origin,
                      .cval = cval, .weights = weights, .in = in, .out = out};
    return dtype == MT_FLOAT64 ? filter1d_f64(&job) : filter1d_f32(&job);
}
