/*
 * check_spikes.c - the take check's spikes of a joint's rotation trimmed to the frames that
 * leave their path (mt_check_trim), and what they move (mt_check_seen; see mtcore.h).
 *
 * A candidate's ends are trimmed one frame at a time, each time against the path between the
 * frames around what is left: only its two ends are measured until it keeps them both, and
 * only then every frame of it.  The runs still trimming are measured together, a round of
 * SLERPs at a time, so that mt_slerp fills its lanes.
 *
 * What a spike of a joint's rotation moves (mt_check_seen) is measured on the points the joint
 * turns, at the run's frames, from the take's forward kinematics.
 */
#include "lanes.h"
#include "mtcore.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* The angle of the rotation between unit quaternions, in degrees (NaN for NaN): the products
   summed in order, as numpy sums an axis of four. */
static double angle_deg(const double *a, const double *b)
{
    const double dot = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
    return 2 * acos(dot > 1.0 ? 1.0 : dot) * (180.0 / pi);
}

/* The larger of a and b where b is a number (fmax leaves NaN out as numpy's fmax does). */
static double larger(double a, double b)
{
    return b > a ? b : a;
}

/* Points on paths, one a row: row[k]'s place on the SLERP from its key rows' rotations (q0, q1)
   at `share` of the way, into out. */
struct paths {
    double *q0, *q1, *share, *out;
    size_t *row;
};

/* Row r's point on the SLERP from row `before` to row `after` (the rows around a run r is in:
   r - first + 1 of last - first + 2 of the way; or two rows before r, extrapolated). */
static void add_row(const double *q, struct paths *p, size_t k, size_t before, size_t after, size_t r)
{
    for (int c = 0; c < 4; c++)
        p->q0[4 * k + c] = q[4 * before + c], p->q1[4 * k + c] = q[4 * after + c];
    p->share[k] = ((double)r - (double)before) / (double)(after - before);
    p->row[k] = r;
}

/* How far row[k]'s rotation lies from its path's point, for the n rows added. */
static void measure(const double *q, struct paths *p, size_t n, double *off)
{
    mt_slerp(p->q0, p->q1, p->share, n, p->out);
    for (size_t k = 0; k < n; k++)
        off[k] = angle_deg(q + 4 * p->row[k], p->out + 4 * k);
}

int mt_check_trim(const double *q, size_t frames, size_t runs, const size_t *first, const size_t *last,
                  const double *limit, size_t *first_out, size_t *last_out, double *largest)
{
    if (runs == 0)
        return MT_OK;
    if (!q || !first || !last || !limit || !first_out || !last_out || !largest)
        return MT_EINVAL;
    size_t rows = 2 * runs; /* every run's two ends, and at the last every row of the runs */
    for (size_t i = 0; i < runs; i++) {
        if (first[i] > last[i] || last[i] >= frames)
            return MT_EINVAL;
        rows += last[i] - first[i] + 1;
    }
    if (rows > SIZE_MAX / (14 * sizeof(double)))
        return MT_ENOMEM;
    double *scratch = malloc(rows * 14 * sizeof *scratch);
    size_t *trimming = malloc(2 * runs * sizeof *trimming), *kept = trimming + runs;
    if (!scratch || !trimming) {
        free(scratch), free(trimming);
        return MT_ENOMEM;
    }
    struct paths p = {scratch, scratch + 4 * rows, scratch + 8 * rows, scratch + 9 * rows,
                      (size_t *)(scratch + 13 * rows)};
    double *off = p.share; /* each measure reads the shares before it writes the offsets */
    size_t n = 0, whole_runs = 0;
    for (size_t i = 0; i < runs; i++) {
        first_out[i] = first[i], last_out[i] = last[i], largest[i] = NAN;
        int whole = first[i] >= 1 && last[i] + 2 <= frames; /* a frame on either side */
        for (size_t r = first[i] - whole; whole && r <= last[i] + 1; r++)
            whole = !isnan(q[4 * r] + q[4 * r + 1] + q[4 * r + 2] + q[4 * r + 3]);
        if (whole)
            trimming[n++] = i;
    }
    while (n > 0) {
        for (size_t k = 0; k < n; k++) {
            const size_t i = trimming[k];
            add_row(q, &p, 2 * k, first_out[i] - 1, last_out[i] + 1, first_out[i]);
            add_row(q, &p, 2 * k + 1, first_out[i] - 1, last_out[i] + 1, last_out[i]);
        }
        measure(q, &p, 2 * n, off);
        size_t still = 0;
        for (size_t k = 0; k < n; k++) {
            const size_t i = trimming[k];
            const int head = off[2 * k] <= limit[i];
            if (first_out[i] < last_out[i] && (head || off[2 * k + 1] <= limit[i])) {
                first_out[i] += head, last_out[i] -= !head;
                trimming[still++] = i;
            } else {
                kept[whole_runs++] = i;
            }
        }
        n = still;
    }
    for (size_t k = 0; k < whole_runs; k++) {
        const size_t i = kept[k];
        for (size_t r = first_out[i]; r <= last_out[i]; r++)
            add_row(q, &p, n++, first_out[i] - 1, last_out[i] + 1, r);
    }
    measure(q, &p, n, off);
    n = 0;
    for (size_t k = 0; k < whole_runs; k++) {
        const size_t i = kept[k];
        double worst = -INFINITY;
        for (size_t r = first_out[i]; r <= last_out[i]; r++, n++)
            worst = larger(worst, off[n]);
        largest[i] = worst;
    }
    free(scratch), free(trimming);
    return MT_OK;
}

/* At row r, how far the points lie from where the joint's rotation `instead` (a matrix) would
   put them, in the points' unit: their offsets from the origin, in the joint's channels' axes
   (its world rotation times axis), turned by actual^T instead less themselves; the farthest,
   NaN left out, 0 for none. */
static double shift_at(const struct mt_turned *k, size_t r, const double *actual, const double *instead)
{
    const double *w = k->world + 9 * (k->turned * r + k->row), *c = k->axis;
    double frame[9], error[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            frame[3 * i + j] = w[3 * i] * c[j] + w[3 * i + 1] * c[3 + j] + w[3 * i + 2] * c[6 + j];
            error[3 * i + j] = actual[i] * instead[j] + actual[3 + i] * instead[3 + j] + actual[6 + i] * instead[6 + j];
        }
    const double *at = k->places + 3 * k->joints * r, *origin = at + 3 * k->origin;
    double farthest = 0.0;
    for (size_t p = 0; p < k->count; p++) {
        double offset[3], local[3], shift[3];
        for (int e = 0; e < 3; e++)
            offset[e] = at[3 * k->points[p] + e] - origin[e];
        for (int i = 0; i < 3; i++)
            local[i] = frame[i] * offset[0] + frame[3 + i] * offset[1] + frame[6 + i] * offset[2];
        for (int i = 0; i < 3; i++)
            shift[i] = error[3 * i] * local[0] + error[3 * i + 1] * local[1] + error[3 * i + 2] * local[2] - local[i];
        farthest = larger(farthest, sqrt(shift[0] * shift[0] + shift[1] * shift[1] + shift[2] * shift[2]));
    }
    return farthest;
}

/* How far the points lie at row r from midway between where they are at rows r - 1 and r + 1,
   in metres: the farthest, NaN left out, 0 for none. */
static double off_midway(const struct mt_turned *k, size_t r, double meters)
{
    const double *before = k->places + 3 * k->joints * (r - 1), *at = before + 3 * k->joints,
                 *after = at + 3 * k->joints;
    double farthest = 0.0;
    for (size_t p = 0; p < k->count; p++) {
        double d[3];
        for (int e = 0; e < 3; e++) {
            const size_t i = 3 * k->points[p] + e;
            d[e] = at[i] * meters - 0.5 * (before[i] * meters + after[i] * meters);
        }
        farthest = larger(farthest, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    return farthest;
}

int mt_check_seen(const struct mt_turned *k, const double *q, size_t runs, const size_t *first, const size_t *last,
                  const size_t *before, const size_t *after, double meters, double *off, double *filled)
{
    if (runs == 0)
        return MT_OK;
    if (!k || !q || !first || !last || !before || !after || !off || !filled || !k->places || !k->world || !k->axis ||
        (k->count > 0 && !k->points) || k->joint >= k->joints || k->origin >= k->joints || k->row >= k->turned)
        return MT_EINVAL;
    for (size_t p = 0; p < k->count; p++)
        if (k->points[p] >= k->joints)
            return MT_EINVAL;
    size_t rows = 0;
    for (size_t i = 0; i < runs; i++) {
        if (first[i] < 1 || first[i] > last[i] || last[i] + 2 > k->frames || before[i] >= after[i] ||
            after[i] >= k->frames)
            return MT_EINVAL;
        rows += last[i] - first[i] + 1;
    }
    if (rows > SIZE_MAX / (27 * sizeof(double)))
        return MT_ENOMEM;
    /* per row: its path's keys and share (9), point (4) and row (1), its actual rotation (4) and
       the path's matrix (9); the actual rotation's matrix takes the keys' place once done with */
    double *scratch = malloc(rows * 27 * sizeof *scratch);
    if (!scratch)
        return MT_ENOMEM;
    struct paths p = {scratch, scratch + 4 * rows, scratch + 8 * rows, scratch + 9 * rows,
                      (size_t *)(scratch + 13 * rows)};
    double *actual = scratch + 14 * rows, *turned = actual + 4 * rows, *m_actual = scratch;
    size_t n = 0;
    for (size_t i = 0; i < runs; i++)
        for (size_t r = first[i]; r <= last[i]; r++, n++) {
            add_row(q, &p, n, before[i], after[i], r);
            for (int c = 0; c < 4; c++)
                actual[4 * n + c] = q[4 * r + c];
        }
    mt_slerp(p.q0, p.q1, p.share, rows, p.out);
    mt_quaternions_to_matrices(p.out, rows, turned);
    mt_quaternions_to_matrices(actual, rows, m_actual);
    n = 0;
    for (size_t i = 0; i < runs; i++) {
        double where = 0.0, instead = 0.0;
        for (size_t r = first[i]; r <= last[i]; r++, n++) {
            where = larger(where, off_midway(k, r, meters));
            instead = larger(instead, shift_at(k, r, m_actual + 9 * n, turned + 9 * n));
        }
        off[i] = where * (last[i] > first[i] ? 2.0 : 1.0);
        filled[i] = instead * meters;
    }
    free(scratch);
    return MT_OK;
}
