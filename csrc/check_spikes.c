/*
 * check_spikes.c - the take check's spikes of a joint's rotation trimmed to the frames that
 * leave their path (mt_check_trim; see mtcore.h).
 *
 * A candidate's ends are trimmed one frame at a time, each time against the path between the
 * frames around what is left: only its two ends are measured until it keeps them both, and
 * only then every frame of it.
 */
#include "lanes.h"
#include "mtcore.h"

#include <math.h>

/* The angle of the rotation between unit quaternions, in degrees (NaN for NaN): the products
   summed in order, as numpy sums an axis of four. */
static double angle_deg(const double *a, const double *b)
{
    const double dot = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
    return 2 * acos(dot > 1.0 ? 1.0 : dot) * (180.0 / pi);
}

/* How far row r's rotation lies from the SLERP between rows a - 1 and b + 1 at r's place. */
static double deviation(const double *q, size_t a, size_t b, size_t r)
{
    const double share = (double)(r - a + 1) / (double)(b - a + 2);
    double on_path[4];
    mt_slerp(q + 4 * (a - 1), q + 4 * (b + 1), &share, 1, on_path);
    return angle_deg(q + 4 * r, on_path);
}

int mt_check_trim(const double *q, size_t frames, size_t runs, const size_t *first, const size_t *last,
                  const double *limit, size_t *first_out, size_t *last_out, double *largest)
{
    if (runs == 0)
        return MT_OK;
    if (!q || !first || !last || !limit || !first_out || !last_out || !largest)
        return MT_EINVAL;
    for (size_t i = 0; i < runs; i++)
        if (first[i] > last[i] || last[i] >= frames)
            return MT_EINVAL;
    for (size_t i = 0; i < runs; i++) {
        size_t a = first[i], b = last[i];
        double worst = NAN;
        int whole = a >= 1 && b + 2 <= frames; /* a frame on either side */
        for (size_t r = a - whole; whole && r <= b + 1; r++)
            whole = !isnan(q[4 * r] + q[4 * r + 1] + q[4 * r + 2] + q[4 * r + 3]);
        while (whole) {
            const int head = deviation(q, a, b, a) <= limit[i];
            if (a < b && (head || deviation(q, a, b, b) <= limit[i])) {
                a += head, b -= !head;
                continue;
            }
            worst = -INFINITY;
            for (size_t r = a; r <= b; r++) {
                const double off = deviation(q, a, b, r);
                worst = off > worst ? off : worst;
            }
            break;
        }
        first_out[i] = a, last_out[i] = b, largest[i] = worst;
    }
    return MT_OK;
}
