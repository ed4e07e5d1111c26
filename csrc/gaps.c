/*
 * gaps.c - runs of NaN down the channels of (frames, stride) arrays: filled
 * where short and bounded (mt_fill_gaps), listed (mt_nan_runs); see mtcore.h.
 *
 * The runs are found row by row (contiguous, a vectorised test per row while
 * no run is open), the rows copied on the way, so that a take with few gaps
 * costs about one copy; filling then touches only the frames around each
 * gap, or for the cubic spline the stretch of its channel that holds it.
 */
#include "lines.h"
#include "mtcore.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

struct run {
    size_t channel, start, stop; /* frames start .. stop-1 of the channel are NaN */
    int fill;
};

struct column {
    const double *x; /* sample t at x[t * stride] */
    double *y;
    size_t n, stride;
};

static double at(const struct column *c, size_t t)
{
    return c->x[t * c->stride];
}

/* A growing list of runs. */
struct runs {
    struct run *items;
    size_t count, capacity;
    int full; /* set when memory ran out */
};

static void add_run(struct runs *r, size_t channel, size_t start, size_t stop)
{
    if (r->count == r->capacity) {
        const size_t more = r->capacity ? 2 * r->capacity : 64;
        struct run *items = more < SIZE_MAX / sizeof *items ? realloc(r->items, more * sizeof *items) : NULL;
        if (items == NULL) {
            r->full = 1;
            return;
        }
        r->items = items;
        r->capacity = more;
    }
    r->items[r->count++] = (struct run){.channel = channel, .start = start, .stop = stop};
}

/*
 * The NaN runs of the rows, in the order they end, row by row: a row without
 * NaN while no run is open costs one vectorised test.  With `out`, the rows
 * are copied there too.  Returns MT_ENOMEM if the list could not grow.
 */
static int find_runs(const double *in, double *out, size_t n, size_t channels, size_t stride, struct runs *r)
{
    size_t *open = malloc(channels * sizeof *open); /* start of the run open in each channel, or SIZE_MAX */
    if (open == NULL)
        return MT_ENOMEM;
    for (size_t k = 0; k < channels; k++)
        open[k] = SIZE_MAX;
    size_t opened = 0;
    for (size_t t = 0; t <= n && !r->full; t++) {
        const double *x = in + (t < n ? t : 0) * stride;
        if (t < n) {
            if (out != NULL)
                memcpy(out + t * stride, x, channels * sizeof *out);
            if (opened == 0) {
                unsigned char row = 0;
                for (size_t k = 0; k < channels; k++)
                    row |= x[k] != x[k];
                if (!row)
                    continue;
            }
        }
        for (size_t k = 0; k < channels; k++) {
            const int nan = t < n && x[k] != x[k];
            if (nan && open[k] == SIZE_MAX) {
                open[k] = t;
                opened++;
            } else if (!nan && open[k] != SIZE_MAX) {
                add_run(r, k, open[k], t);
                open[k] = SIZE_MAX;
                opened--;
            }
        }
    }
    free(open);
    return r->full ? MT_ENOMEM : MT_OK;
}

/* Linear between the valid samples a and b, as numpy.interp computes it. */
static void fill_linear(const struct column *c, const struct run *r)
{
    const size_t a = r->start - 1, b = r->stop;
    const double ya = at(c, a), slope = (at(c, b) - ya) / (double)(b - a);
    for (size_t t = r->start; t < r->stop; t++)
        c->y[t * c->stride] = slope * (double)(t - a) + ya;
}

struct spline_scratch {
    double *x, *y, *s;         /* knots, their values and slopes */
    double *slope, *up, *rhs;  /* each interval's slope; the eliminated system */
    size_t *left;              /* per fillable run: the knot index of the frame before it */
};

/*
 * Slopes s[0 .. k-1] of the not-a-knot cubic spline through the knots (x, y),
 * k >= 2: two knots give the line, three the parabola, more the tridiagonal
 * system of scipy.interpolate.CubicSpline, solved by elimination (it is
 * diagonally dominant but for its two end rows, which elimination leaves
 * well conditioned).
 */
static void spline_slopes(const struct spline_scratch *w, size_t k)
{
    const double *x = w->x, *y = w->y;
    double *s = w->s, *m = w->slope, *up = w->up, *rhs = w->rhs;
    for (size_t i = 0; i + 1 < k; i++)
        m[i] = (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
#define DX(i) (x[(i) + 1] - x[(i)])
    if (k == 2) {
        s[0] = s[1] = m[0];
        return;
    }
    if (k == 3) {
        const double c = (m[1] - m[0]) / (x[2] - x[0]);
        s[0] = m[0] - c * DX(0);
        s[1] = m[0] + c * DX(0);
        s[2] = m[1] + c * DX(1);
        return;
    }
    /* row i: lower s[i-1] + diag s[i] + upper s[i+1] = b; eliminated downwards (Thomas) */
    double d = x[2] - x[0], diag = DX(1);
    up[0] = d / diag;
    rhs[0] = ((DX(0) + 2 * d) * DX(1) * m[0] + DX(0) * DX(0) * m[1]) / d / diag;
    for (size_t i = 1; i + 1 < k; i++) {
        const double lower = DX(i), b = 3 * (DX(i) * m[i - 1] + DX(i - 1) * m[i]);
        const double inverse = 1.0 / (2 * (DX(i - 1) + DX(i)) - lower * up[i - 1]);
        up[i] = DX(i - 1) * inverse;
        rhs[i] = (b - lower * rhs[i - 1]) * inverse;
    }
    d = x[k - 1] - x[k - 3];
    const double b = (DX(k - 2) * DX(k - 2) * m[k - 3] + (2 * d + DX(k - 2)) * DX(k - 3) * m[k - 2]) / d;
    s[k - 1] = (b - d * rhs[k - 2]) / (DX(k - 3) - d * up[k - 2]);
    for (size_t i = k - 1; i-- > 0;)
        s[i] = rhs[i] - up[i] * s[i + 1];
#undef DX
}

/* Fills the fillable runs runs[0 .. count-1] of frames lo .. hi-1, which hold no other NaN. */
static void fill_cubic(const struct column *c, const struct run *runs, size_t count, size_t lo, size_t hi,
                       const struct spline_scratch *w)
{
    size_t k = 0, r = 0;
    for (size_t t = lo; t < hi; t++) {
        if (r < count && t == runs[r].start) {
            w->left[r] = k - 1;
            t = runs[r++].stop - 1;
            continue;
        }
        w->x[k] = (double)t;
        w->y[k++] = at(c, t);
    }
    spline_slopes(w, k);
    for (r = 0; r < count; r++) {
        const size_t i = w->left[r];
        const double h = w->x[i + 1] - w->x[i], slope = w->slope[i];
        const double tt = (w->s[i] + w->s[i + 1] - 2 * slope) / h;
        const double c0 = tt / h, c1 = (slope - w->s[i]) / h - tt, c2 = w->s[i], c3 = w->y[i];
        for (size_t t = runs[r].start; t < runs[r].stop; t++) {
            const double u = (double)t - w->x[i];
            c->y[t * c->stride] = ((c0 * u + c1) * u + c2) * u + c3;
        }
    }
}

/* Fills the fillable runs of a column (runs[0 .. count-1], in order); for cubic, each stretch between
 * unfilled runs gets its own spline. */
static void fill_column(const struct column *c, int method, const struct run *runs, size_t count,
                        const struct spline_scratch *w)
{
    if (method == MT_FILL_LINEAR) {
        for (size_t r = 0; r < count; r++)
            if (runs[r].fill)
                fill_linear(c, &runs[r]);
        return;
    }
    size_t first = 0, lo = 0; /* the stretch's first run and first frame */
    for (size_t r = 0; r <= count; r++) {
        if (r < count && runs[r].fill)
            continue;
        const size_t hi = r < count ? runs[r].start : c->n;
        if (r > first)
            fill_cubic(c, runs + first, r - first, lo, hi, w);
        if (r < count) {
            first = r + 1;
            lo = runs[r].stop;
        }
    }
}

int mt_fill_gaps(const double *in, double *out, size_t n, size_t channels, size_t stride, size_t max_gap,
                 int method)
{
    if ((method != MT_FILL_LINEAR && method != MT_FILL_CUBIC) || stride < channels)
        return MT_EINVAL;
    if (n == 0 || channels == 0)
        return MT_OK;
    if (in == NULL || out == NULL || stride > SIZE_MAX / n || n > SIZE_MAX / (8 * sizeof(double)))
        return MT_EINVAL;

    struct runs found = {0};
    int status = find_runs(in, out, n, channels, stride, &found);
    struct run *sorted = NULL;
    size_t *first = NULL;
    struct spline_scratch w = {0};
    if (status != MT_OK || found.count == 0)
        goto done;
    /* the runs by channel, each channel's in order of frames (counting sort, stable) */
    sorted = malloc(found.count * sizeof *sorted);
    first = calloc(channels + 1, sizeof *first);
    if (method == MT_FILL_CUBIC) {
        w.x = malloc(n * sizeof *w.x);
        w.y = malloc(n * sizeof *w.y);
        w.s = malloc(n * sizeof *w.s);
        w.slope = malloc(n * sizeof *w.slope);
        w.up = malloc(n * sizeof *w.up);
        w.rhs = malloc(n * sizeof *w.rhs);
        w.left = malloc((n / 2 + 1) * sizeof *w.left);
    }
    if (sorted == NULL || first == NULL ||
        (method == MT_FILL_CUBIC &&
         (w.x == NULL || w.y == NULL || w.s == NULL || w.slope == NULL || w.up == NULL || w.rhs == NULL ||
          w.left == NULL))) {
        status = MT_ENOMEM;
        goto done;
    }
    for (size_t i = 0; i < found.count; i++)
        first[found.items[i].channel + 1]++;
    for (size_t k = 0; k < channels; k++)
        first[k + 1] += first[k];
    for (size_t i = 0; i < found.count; i++) {
        struct run r = found.items[i];
        r.fill = r.start > 0 && r.stop < n && r.stop - r.start <= max_gap;
        sorted[first[r.channel]++] = r;
    }
    /* first[k] now ends channel k's runs */
    for (size_t k = 0, begin = 0; k < channels; begin = first[k++]) {
        const size_t count = first[k] - begin;
        size_t fill = 0;
        for (size_t i = begin; i < first[k]; i++)
            fill += (size_t)sorted[i].fill;
        if (fill > 0) {
            const struct column c = {.x = in + k, .y = out + k, .n = n, .stride = stride};
            fill_column(&c, method, sorted + begin, count, &w);
        }
    }
done:
    free(found.items);
    free(sorted);
    free(first);
    free(w.x);
    free(w.y);
    free(w.s);
    free(w.slope);
    free(w.up);
    free(w.rhs);
    free(w.left);
    return status;
}

int mt_nan_runs(const double *in, size_t n, size_t channels, size_t stride, size_t *runs, size_t capacity,
                size_t *count)
{
    if (count == NULL || stride < channels || (capacity > 0 && runs == NULL))
        return MT_EINVAL;
    *count = 0;
    if (n == 0 || channels == 0)
        return MT_OK;
    if (in == NULL || stride > SIZE_MAX / n)
        return MT_EINVAL;
    struct runs found = {0};
    const int status = find_runs(in, NULL, n, channels, stride, &found);
    if (status == MT_OK) {
        for (size_t i = 0; i < found.count && i < capacity; i++) {
            runs[3 * i] = found.items[i].channel;
            runs[3 * i + 1] = found.items[i].start;
            runs[3 * i + 2] = found.items[i].stop;
        }
        *count = found.count;
    }
    free(found.items);
    return status;
}
