/*
 * check_spikes.c - the take check's spikes of a joint's rotation trimmed to the frames that
 * leave their path (mt_check_trim; see mtcore.h).
 *
 * A candidate's ends are trimmed one frame at a time, each time against the path between the
 * frames around what is left: only its two ends are measured until it keeps them both, and
 * only then every frame of it.  The runs still trimming are measured together, a round of
 * SLERPs at a time, so that mt_slerp fills its lanes.
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

/* Points on the paths, one a row: row[k] of the run first[k] .. last[k], between the rows around it. */
struct paths {
    double *q0, *q1, *share, *out;
    size_t *row;
};

static void add_row(const double *q, struct paths *p, size_t k, size_t a, size_t b, size_t r)
{
    for (int c = 0; c < 4; c++)
        p->q0[4 * k + c] = q[4 * (a - 1) + c], p->q1[4 * k + c] = q[4 * (b + 1) + c];
    p->share[k] = (double)(r - a + 1) / (double)(b - a + 2);
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
            add_row(q, &p, 2 * k, first_out[i], last_out[i], first_out[i]);
            add_row(q, &p, 2 * k + 1, first_out[i], last_out[i], last_out[i]);
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
            add_row(q, &p, n++, first_out[i], last_out[i], r);
    }
    measure(q, &p, n, off);
    n = 0;
    for (size_t k = 0; k < whole_runs; k++) {
        const size_t i = kept[k];
        double worst = -INFINITY;
        for (size_t r = first_out[i]; r <= last_out[i]; r++, n++)
            worst = off[n] > worst ? off[n] : worst;
        largest[i] = worst;
    }
    free(scratch), free(trimming);
    return MT_OK;
}
