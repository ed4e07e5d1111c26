/*
 * check.c - what is wrong with a take's channels, in one pass over its rows
 * (mt_check_channels), and the pace of its steps (mt_check_roughness, mt_check_pace; see mtcore.h).
 *
 * The rows are walked in order and every channel carries its open events
 * from row to row, so that the values are read once, in the order they lie
 * in memory.  The spike test needs the median of five samples only where a
 * sample is farther than the limit from a neighbour: a sample within the
 * limit of both neighbours is within it of the median too (three of the five
 * samples lie within the limit of it, so the median cannot lie beyond), and
 * that is nearly every sample of a real take.
 */
#include "clones.h"
#include "mtcore.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

enum { SPIKE, STEP, FROZEN, GAP, OPEN_KINDS };

/* An event being extended row by row: rows first .. last, the greatest size at row `at`. */
struct open {
    size_t first, last, at;
    double size;
    int active;
};

struct sink {
    size_t *events;
    double *sizes;
    size_t capacity, count;
};

static void emit(struct sink *s, size_t channel, int kind, const struct open *e)
{
    if (s->count < s->capacity) {
        size_t *row = s->events + 5 * s->count;
        row[0] = channel;
        row[1] = e->first;
        row[2] = e->last;
        row[3] = (size_t)kind;
        row[4] = e->at;
        s->sizes[s->count] = e->size;
    }
    s->count++;
}

/* Extend the event by row t (or open it there); a larger |size| moves its peak. */
static void extend(struct open *e, size_t t, double size)
{
    if (!e->active) {
        *e = (struct open){.first = t, .last = t, .at = t, .size = size, .active = 1};
        return;
    }
    e->last = t;
    if (fabs(size) > fabs(e->size)) {
        e->size = size;
        e->at = t;
    }
}

static void close_event(struct open *e, struct sink *s, size_t channel, int kind)
{
    if (e->active)
        emit(s, channel, kind, e);
    e->active = 0;
}

/* The median of five in six comparisons: of two sorted pairs, the lesser of their minima is
   below three of the values and so not the median; e takes its place, and the median is the
   second least of the four left. */
static void order(double *a, double *b)
{
    if (*a > *b) {
        const double t = *a;
        *a = *b;
        *b = t;
    }
}

static double median5(double a, double b, double c, double d, double e)
{
    order(&a, &b);
    order(&c, &d);
    if (a < c) {
        a = e;
        order(&a, &b);
    } else {
        c = e;
        order(&c, &d);
    }
    return a < c ? (b < c ? b : c) : (a < d ? a : d);
}

/* A frozen run ends: it is listed when long enough, or when it touches the rows checked at
   either end (a piece of a run that a caller checking a take in pieces joins up). */
static void close_frozen(struct open *e, struct sink *s, size_t channel, size_t min_run, size_t begin, size_t end)
{
    if (e->active && (e->last - e->first + 1 >= min_run || e->first < begin || e->last + 1 >= end))
        emit(s, channel, MT_CHECK_FROZEN, e);
    e->active = 0;
}

/* Row i of the line mirrored at its ends (d c b | a b c d | c b a), clamped for short lines. */
static size_t mirrored(ptrdiff_t i, size_t rows)
{
    const ptrdiff_t last = (ptrdiff_t)rows - 1;
    if (i < 0)
        i = -i;
    if (i > last)
        i = 2 * last - i;
    return (size_t)(i < 0 ? 0 : i > last ? last : i);
}

/* What one row tells of every channel, in a loop the compiler vectorises: each channel's
   roughness, whether the row repeats the one before in every channel, and which channels are
   quiet there (a number, moving, within the spike limit of both neighbours, no step): those
   with no event open need nothing more, and that is nearly every channel of nearly every row. */
static MT_CLONES int row_pass(const double *restrict x, const double *restrict before, const double *restrict after,
                              const double *restrict earlier, size_t channels, int interior, int has_before,
                              int has_after, const double *restrict spike_limit, const double *restrict step_limit,
                              double *restrict roughness, size_t *restrict smooth_rows, size_t *restrict quiet)
{
    int same = 1;
    for (size_t k = 0; k < channels; k++) {
        const double v = x[k], b = before[k], a = after[k], limit = spike_limit[k], lim = step_limit[k];
        const double rough = v - 0.5 * (b + a);
        const int smooth = interior && fabs(rough) <= limit;
        roughness[k] += smooth ? rough * rough : 0.0;
        smooth_rows[k] += (size_t)smooth;
        same &= v == b;
        const double change = v - b;
        const int step = (has_before || has_after) && (!has_before || fabs(change - (b - earlier[k])) > lim) &&
                         (!has_after || fabs(change - (a - v)) > lim);
        quiet[k] = (size_t)(v != b && fabs(v - b) <= limit && fabs(v - a) <= limit && !step);
    }
    return same;
}

int mt_check_channels(const double *values, size_t rows, size_t channels, size_t stride, size_t begin, size_t end,
                      const double *spike_limit, const double *step_limit, size_t min_run, size_t *events,
                      double *sizes, size_t capacity, size_t *count, double *roughness, size_t *smooth_rows)
{
    if (count == NULL || stride < channels || begin > end || end > rows || (capacity > 0 && (events == NULL || sizes == NULL)))
        return MT_EINVAL;
    if (channels > 0 && (spike_limit == NULL || step_limit == NULL || roughness == NULL || smooth_rows == NULL))
        return MT_EINVAL;
    if (rows > 0 && channels > 0 && values == NULL)
        return MT_EINVAL;
    if (channels > 0 && stride > SIZE_MAX / (rows > 0 ? rows : 1))
        return MT_EINVAL;
    *count = 0;
    if (channels == 0)
        return MT_OK;
    struct open *open = calloc(channels * OPEN_KINDS, sizeof *open);
    /* quiet in this row (as wide as the values, so that row_pass's loop runs 8 lanes of doubles
       and not 32 of bytes, whose remainder of a take's 62 channels runs one at a time); an event
       open */
    size_t *flags = calloc(2 * channels, sizeof *flags);
    if (open == NULL || flags == NULL) {
        free(open);
        free(flags);
        return MT_ENOMEM;
    }
    size_t *quiet = flags, *busy = flags + channels;
    struct sink sink = {.events = events, .sizes = sizes, .capacity = capacity};
    struct open repeat = {0};
    for (size_t k = 0; k < channels; k++) {
        roughness[k] = 0.0;
        smooth_rows[k] = 0;
    }
#define AT(t, k) values[(size_t)(t) * stride + (k)]
    for (size_t t = begin; t < end; t++) {
        const double *row = values + t * stride;
        const double *before = t > 0 ? row - stride : row, *after = t + 1 < rows ? row + stride : row;
        const double *earlier = t > 1 ? row - 2 * stride : before;
        const int same_row = row_pass(row, before, after, earlier, channels, t > 0 && t + 1 < rows, t > 1, t + 1 < rows,
                                      spike_limit, step_limit, roughness, smooth_rows, quiet) && t > 0;
        for (size_t k = 0; k < channels; k++) {
            if (quiet[k] && !busy[k])
                continue;
            struct open *o = open + k * OPEN_KINDS;
            const double x = row[k];
            /* a value held on into the next row, with nothing else open: its run only grows (a
               channel that never moves comes here every row; no spike or step is told in a row
               whose neighbours equal it) */
            if (o[FROZEN].active && !o[GAP].active && !o[SPIKE].active && !o[STEP].active && t + 1 < rows &&
                x == before[k] && x == after[k]) {
                o[FROZEN].last = t;
                continue;
            }
            if (x != x) {
                extend(&o[GAP], t, 0.0);
                close_frozen(&o[FROZEN], &sink, k, min_run, begin, end);
                close_event(&o[SPIKE], &sink, k, MT_CHECK_SPIKE);
                close_event(&o[STEP], &sink, k, MT_CHECK_STEP);
                busy[k] = 1;
                continue;
            }
            close_event(&o[GAP], &sink, k, MT_CHECK_GAP);
            /* a frozen run: rows equal to the row before; its first row is the one they repeat */
            if (t > 0 && x == before[k]) {
                if (!o[FROZEN].active)
                    extend(&o[FROZEN], t - 1, x);
                o[FROZEN].last = t;
            } else {
                close_frozen(&o[FROZEN], &sink, k, min_run, begin, end);
            }
            const double limit = spike_limit[k];
            double deviation = 0.0;
            if (rows >= 3 && (fabs(x - before[k]) > limit || fabs(x - after[k]) > limit)) {
                const double a = AT(mirrored((ptrdiff_t)t - 2, rows), k);
                const double b = AT(mirrored((ptrdiff_t)t - 1, rows), k);
                const double c = AT(mirrored((ptrdiff_t)t + 1, rows), k);
                const double d = AT(mirrored((ptrdiff_t)t + 2, rows), k);
                const int finite = a == a && b == b && c == c && d == d;
                deviation = finite ? x - median5(a, b, c, d, x) : 0.0;
            }
            if (fabs(deviation) > limit)
                extend(&o[SPIKE], t, deviation);
            else
                close_event(&o[SPIKE], &sink, k, MT_CHECK_SPIKE);
            /* a step: the change into this row differs from both changes beside it */
            double jump = 0.0;
            if (t > 0) {
                const double change = x - before[k];
                const int has_before = t > 1, has_after = t + 1 < rows;
                const double change_before = has_before ? before[k] - earlier[k] : change;
                const double change_after = has_after ? after[k] - x : change;
                const double lim = step_limit[k];
                if ((has_before || has_after) && (!has_before || fabs(change - change_before) > lim) &&
                    (!has_after || fabs(change - change_after) > lim)) {
                    const double usual = has_before && has_after ? 0.5 * (change_before + change_after)
                                         : has_before            ? change_before
                                                                 : change_after;
                    jump = change - usual;
                    if (!(fabs(jump) > lim))
                        jump = 0.0;
                }
            }
            if (jump != 0.0)
                extend(&o[STEP], t, jump);
            else
                close_event(&o[STEP], &sink, k, MT_CHECK_STEP);
            busy[k] = (size_t)(o[GAP].active | o[FROZEN].active | o[SPIKE].active | o[STEP].active);
        }
        if (same_row)
            extend(&repeat, t, 0.0);
        else
            close_event(&repeat, &sink, channels, MT_CHECK_REPEAT);
    }
#undef AT
    for (size_t k = 0; k < channels; k++) {
        struct open *o = open + k * OPEN_KINDS;
        close_event(&o[SPIKE], &sink, k, MT_CHECK_SPIKE);
        close_event(&o[STEP], &sink, k, MT_CHECK_STEP);
        close_frozen(&o[FROZEN], &sink, k, min_run, begin, end);
        close_event(&o[GAP], &sink, k, MT_CHECK_GAP);
    }
    close_event(&repeat, &sink, channels, MT_CHECK_REPEAT);
    free(open);
    free(flags);
    *count = sink.count;
    return MT_OK;
}

/* Whether x is a number no motion exceeds (not NaN, not infinite), in a form that vectorises. */
static MT_INLINE int finite(double x)
{
    return fabs(x) <= DBL_MAX;
}

static MT_CLONES void pace_rows(const double *values, size_t rows, size_t channels, size_t stride,
                                const double *weight, double *moved, double *paced, double *stepped)
{
    for (size_t t = 0; t < rows; t++) {
        double m2 = 0.0, dm = 0.0, d2 = 0.0;
        if (t >= 1 && t + 3 <= rows) {
            const double *a = values + (t - 1) * stride, *b = a + stride, *c = b + stride, *d = c + stride;
            /* the channels summed in lanes side by side (in another order than one by one) */
#pragma omp simd reduction(+ : m2, dm, d2)
            for (size_t k = 0; k < channels; k++) {
                const double step = c[k] - b[k], mean = ((b[k] - a[k]) + (d[k] - c[k])) / 2;
                /* a gap, or values no motion reaches: other findings', left out */
                const int ok = finite(mean) && finite(step);
                const double w = ok ? weight[k] : 0.0, s = ok ? step : 0.0, m = ok ? mean : 0.0;
                m2 += w * m * m;
                dm += w * s * m;
                d2 += w * s * s;
            }
        }
        moved[t] = m2;
        paced[t] = dm;
        stepped[t] = d2;
    }
}

int mt_check_pace(const double *values, size_t rows, size_t channels, size_t stride, const double *weight,
                  double *moved, double *paced, double *stepped)
{
    if (stride < channels || (channels > 0 && weight == NULL) ||
        (rows > 0 && (moved == NULL || paced == NULL || stepped == NULL)) || (rows > 0 && channels > 0 && values == NULL) ||
        (channels > 0 && stride > SIZE_MAX / (rows > 0 ? rows : 1)))
        return MT_EINVAL;
    for (size_t k = 0; k < channels; k++)
        if (!(weight[k] >= 0.0) || !isfinite(weight[k]))
            return MT_EINVAL;
    pace_rows(values, rows, channels, stride, weight, moved, paced, stepped);
    return MT_OK;
}

static MT_CLONES void roughness_rows(const double *values, size_t rows, size_t channels, size_t stride,
                                     double *restrict squares, size_t *restrict counts)
{
    for (size_t t = 1; t + 1 < rows; t++) {
        const double *a = values + (t - 1) * stride, *b = a + stride, *c = b + stride;
        for (size_t k = 0; k < channels; k++) {
            const double r = (a[k] + c[k]) * -0.5 + b[k];
            const int ok = finite(r);
            squares[k] += ok ? r * r : 0.0;
            counts[k] += (size_t)ok;
        }
    }
}

int mt_check_roughness(const double *values, size_t rows, size_t channels, size_t stride, double *squares,
                       size_t *counts)
{
    if (stride < channels || (channels > 0 && (squares == NULL || counts == NULL)) ||
        (rows > 0 && channels > 0 && values == NULL) || (channels > 0 && stride > SIZE_MAX / (rows > 0 ? rows : 1)))
        return MT_EINVAL;
    roughness_rows(values, rows, channels, stride, squares, counts);
    return MT_OK;
}
