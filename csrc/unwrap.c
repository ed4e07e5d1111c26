/*
 * unwrap.c - angle channels made continuous across wraps (mt_unwrap_angles in mtcore.h), in
 * place over the rows of a (frames, stride) array, each row's columns side by side.
 */
#include "mtcore.h"

#include <math.h>
#include <stddef.h>

int mt_unwrap_angles(double *values, size_t frames, size_t stride, const size_t *columns, size_t ncolumns,
                     double period, double *last, double *turns)
{
    if (ncolumns == 0)
        return MT_OK;
    if (columns == NULL || last == NULL || turns == NULL || (frames > 0 && values == NULL))
        return MT_EINVAL;
    if (!(period > 0.0) || !isfinite(period))
        return MT_EINVAL;
    for (size_t k = 0; k < ncolumns; k++)
        if (columns[k] >= stride)
            return MT_EINVAL;
    const double half = period / 2;
    for (size_t t = 0; t < frames; t++) {
        double *row = values + t * stride;
        for (size_t k = 0; k < ncolumns; k++) {
            const double v = row[columns[k]];
            if (v - v != 0.0) /* NaN or an infinity: stepped over */
                continue;
            const double step = v - last[k]; /* NaN while nothing finite came before */
            if (fabs(step) > half)
                turns[k] -= nearbyint(step / period); /* ties to even, as numpy's round */
            last[k] = v;
            if (turns[k] != 0.0)
                row[columns[k]] = v + turns[k] * period;
        }
    }
    return MT_OK;
}

int mt_finite_ranges(const double *values, size_t frames, size_t channels, double *low, double *high,
                     double *first)
{
    if (channels == 0)
        return MT_OK;
    if (low == NULL || high == NULL || first == NULL || (frames > 0 && values == NULL))
        return MT_EINVAL;
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
    return MT_OK;
}

int mt_wrap_angles(double *values, size_t frames, size_t stride, const size_t *columns, size_t ncolumns,
                   const double *low, const double *high, double period)
{
    if (ncolumns == 0)
        return MT_OK;
    if (columns == NULL || low == NULL || high == NULL || (frames > 0 && values == NULL))
        return MT_EINVAL;
    if (!(period > 0.0) || !isfinite(period))
        return MT_EINVAL;
    for (size_t k = 0; k < ncolumns; k++)
        if (columns[k] >= stride)
            return MT_EINVAL;
    for (size_t t = 0; t < frames; t++) {
        double *row = values + t * stride;
        for (size_t k = 0; k < ncolumns; k++) {
            const double v = row[columns[k]];
            if ((v < low[k] || v > high[k]) && v - v == 0.0) /* rare: a mean across a wrap */
                row[columns[k]] = v - period * floor((v - low[k]) / period);
        }
    }
    return MT_OK;
}
