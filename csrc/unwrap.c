/*
 * unwrap.c - angle channels made continuous across wraps (mt_unwrap_angles in mtcore.h) and put
 * back into a range after smoothing (mt_wrap_angles), in place over the rows of a (frames,
 * stride) array, each row's columns side by side; and the finite ranges of channels that tell
 * which range (mt_finite_ranges).
 */
#include "clones.h"
#include "mtcore.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

/* The arguments the angle kernels share, checked: columns within the rows, a finite period > 0. */
static int valid_columns(const double *values, size_t frames, size_t stride, const size_t *columns, size_t ncolumns,
                         double period)
{
    if (columns == NULL || (frames > 0 && values == NULL) || !(period > 0.0) || !isfinite(period))
        return 0;
    for (size_t k = 0; k < ncolumns; k++)
        if (columns[k] >= stride)
            return 0;
    return 1;
}

/*
 * Where columns run on (c, c+1, ...): the index k of each run's first column, then the next
 * run's, ..., ncolumns last, into runs (ncolumns + 1 entries); returns how many runs.  A run is
 * what one vector loop takes.
 */
static size_t column_runs(const size_t *columns, size_t ncolumns, size_t *runs)
{
    size_t count = 0;
    for (size_t k = 0; k < ncolumns; k++)
        if (k == 0 || columns[k] != columns[k - 1] + 1)
            runs[count++] = k;
    runs[count] = ncolumns;
    return count;
}

/*
 * One row's run of n angle columns, unwrapped: without a branch, so that the loop vectorises (a
 * whole turn is rare; its quotient is worked out for every sample and kept for the jumps).
 */
static MT_CLONES void unwrap_run(double *restrict row, size_t n, double period, double *restrict last,
                                 double *restrict turns)
{
    const double half = period / 2;
    for (size_t k = 0; k < n; k++) {
        const double v = row[k];
        const int finite = v - v == 0.0;  /* NaN and infinities are stepped over */
        const double step = v - last[k]; /* NaN while nothing finite came before */
        const int jump = finite && fabs(step) > half;
        turns[k] -= jump ? nearbyint(step / period) : 0.0; /* ties to even, as numpy's round */
        last[k] = finite ? v : last[k];
        row[k] = finite && turns[k] != 0.0 ? v + turns[k] * period : v;
    }
}

int mt_unwrap_angles(double *values, size_t frames, size_t stride, const size_t *columns, size_t ncolumns,
                     double period, double *last, double *turns)
{
    if (ncolumns == 0)
        return MT_OK;
    if (last == NULL || turns == NULL || !valid_columns(values, frames, stride, columns, ncolumns, period))
        return MT_EINVAL;
    size_t *runs = malloc((ncolumns + 1) * sizeof *runs);
    if (runs == NULL)
        return MT_ENOMEM;
    const size_t count = column_runs(columns, ncolumns, runs);
    for (size_t t = 0; t < frames; t++) {
        double *row = values + t * stride;
        for (size_t r = 0; r < count; r++) {
            const size_t k = runs[r];
            unwrap_run(row + columns[k], runs[r + 1] - k, period, last + k, turns + k);
        }
    }
    free(runs);
    return MT_OK;
}

/* The rows of mt_finite_ranges; the arrays do not overlap (the caller's are distinct). */
static MT_CLONES void widen(const double *restrict values, size_t frames, size_t channels, double *restrict low,
                            double *restrict high, double *restrict first)
{
    for (size_t t = 0; t < frames; t++) {
        const double *row = values + t * channels;
        for (size_t c = 0; c < channels; c++) { /* no branch: the loop vectorises */
            const double v = row[c];
            const int finite = v - v == 0.0;
            low[c] = finite && v < low[c] ? v : low[c];
            high[c] = finite && v > high[c] ? v : high[c];
            first[c] = finite && first[c] != first[c] ? v : first[c];
        }
    }
}

int mt_finite_ranges(const double *values, size_t frames, size_t channels, double *low, double *high,
                     double *first)
{
    if (channels == 0)
        return MT_OK;
    if (low == NULL || high == NULL || first == NULL || (frames > 0 && values == NULL))
        return MT_EINVAL;
    widen(values, frames, channels, low, high, first);
    return MT_OK;
}

/* One row's run of n angle columns put into [least, least + period] (least NaN: left), as
   unwrap_run without a branch. */
static MT_CLONES void wrap_run(double *restrict row, size_t n, const double *restrict least, double period)
{
    for (size_t k = 0; k < n; k++) {
        const double v = row[k];
        const int outside = (v < least[k] || v > least[k] + period) && v - v == 0.0; /* rare: a mean across a wrap */
        row[k] = outside ? v - period * floor((v - least[k]) / period) : v;
    }
}

int mt_wrap_angles(double *values, size_t frames, size_t stride, const size_t *columns, size_t ncolumns,
                   const double *low, const double *high, double period)
{
    if (ncolumns == 0)
        return MT_OK;
    if (low == NULL || high == NULL || !valid_columns(values, frames, stride, columns, ncolumns, period))
        return MT_EINVAL;
    /* scratch: the runs of consecutive columns, then each column's least value */
    size_t *runs = malloc((ncolumns + 1) * sizeof *runs);
    double *least = malloc(ncolumns * sizeof *least);
    if (runs == NULL || least == NULL) {
        free(runs);
        free(least);
        return MT_ENOMEM;
    }
    const double half = period / 2;
    for (size_t k = 0; k < ncolumns; k++) {
        const int centred = low[k] >= -half && high[k] <= half;
        const int positive = low[k] >= 0.0 && high[k] <= period;
        least[k] = centred ? -half : positive ? 0.0 : NAN;
    }
    const size_t count = column_runs(columns, ncolumns, runs);
    for (size_t t = 0; t < frames; t++) {
        double *row = values + t * stride;
        for (size_t r = 0; r < count; r++) {
            const size_t k = runs[r];
            wrap_run(row + columns[k], runs[r + 1] - k, least + k, period);
        }
    }
    free(runs);
    free(least);
    return MT_OK;
}
