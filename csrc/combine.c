/*
 * combine.c - the per-frame loop of the motion combiner (see mtcore.h).
 *
 * Python works out the borders, blend depths and the frame map (which rows
 * of the old and new motions each output frame takes, with what weights);
 * this loop computes every output value from them.  Each frame is one of
 * three cases decided once per frame, so that the loop over channels has no
 * branches: old only, new only, or a cross-fade.
 */
#include "clones.h"
#include "mtcore.h"

static MT_INLINE int row_ok(long long row, size_t frames)
{
    return row >= 0 && (size_t)row < frames;
}

static MT_CLONES void combine_frames(const double *old_values, const double *new_values, size_t channels,
                                     const long long *old_row, const long long *new_row,
                                     const long long *next_row, const double *ramp, const double *weight,
                                     const unsigned char *selected, const long long *offset_row,
                                     const double *offsets, const size_t *offset_channel, size_t noffsets,
                                     size_t begin, size_t end, double *out)
{
    for (size_t f = begin; f < end; f++) {
        double *o = out + f * channels;
        const double u = weight[f], a = ramp ? ramp[f] : 0.0;
        const double *po = old_row[f] >= 0 ? old_values + (size_t)old_row[f] * channels : NULL;
        const double *pn = new_row[f] >= 0 ? new_values + (size_t)new_row[f] * channels : NULL;
        const double *pm = next_row && next_row[f] >= 0 ? new_values + (size_t)next_row[f] * channels : pn;
        if (u == 0.0) {
            for (size_t c = 0; c < channels; c++)
                o[c] = po[c];
        } else if (u == 1.0 && a == 0.0) {
            for (size_t c = 0; c < channels; c++)
                o[c] = selected[c] ? pn[c] : po[c];
        } else if (u == 1.0) {
            for (size_t c = 0; c < channels; c++)
                o[c] = selected[c] ? (1.0 - a) * pn[c] + a * pm[c] : po[c];
        } else {
            for (size_t c = 0; c < channels; c++) {
                const double fresh = a == 0.0 ? pn[c] : (1.0 - a) * pn[c] + a * pm[c];
                o[c] = selected[c] ? (1.0 - u) * po[c] + u * fresh : po[c];
            }
        }
        if (offset_row[f] >= 0)
            for (size_t j = 0; j < noffsets; j++)
                o[offset_channel[j]] += offsets[(size_t)offset_row[f] * noffsets + j];
    }
}

int mt_combine(const double *old_values, size_t old_frames, const double *new_values,
               size_t new_frames, size_t channels, size_t out_frames, const long long *old_row,
               const long long *new_row, const long long *next_row, const double *ramp,
               const double *weight, const unsigned char *selected, const long long *offset_row,
               const double *offsets, size_t offset_rows, const size_t *offset_channel,
               size_t noffsets, size_t begin, size_t end, double *out)
{
    if (begin > end || end > out_frames)
        return MT_EINVAL;
    if (begin == end || channels == 0)
        return MT_OK;
    if (!old_row || !new_row || (!next_row) != (!ramp) || !weight || !selected || !offset_row || !out ||
        (noffsets > 0 && (!offsets || !offset_channel)))
        return MT_EINVAL;
    for (size_t j = 0; j < noffsets; j++)
        if (offset_channel[j] >= channels)
            return MT_EINVAL;
    int any_unselected = 0;
    for (size_t c = 0; c < channels; c++)
        any_unselected |= !selected[c];
    /* Every row a frame will read must exist: checked here, not trusted. */
    for (size_t f = begin; f < end; f++) {
        const double u = weight[f], a = ramp ? ramp[f] : 0.0;
        const int needs_old = u != 1.0 || any_unselected, needs_new = u != 0.0;
        if (!(u >= 0.0 && u <= 1.0) || !(a >= 0.0 && a <= 1.0))
            return MT_EINVAL;
        if (needs_old && (!old_values || !row_ok(old_row[f], old_frames)))
            return MT_EINVAL;
        if (needs_new && (!new_values || !row_ok(new_row[f], new_frames) ||
                          (a != 0.0 && !row_ok(next_row[f], new_frames))))
            return MT_EINVAL;
        if (offset_row[f] >= 0 && (size_t)offset_row[f] >= offset_rows)
            return MT_EINVAL;
    }
    combine_frames(old_values, new_values, channels, old_row, new_row, next_row, ramp, weight, selected,
                   offset_row, offsets, offset_channel, noffsets, begin, end, out);
    return MT_OK;
}
