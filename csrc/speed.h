/*
 * speed.h - build-internal: how fast a point goes at each frame, as the kernels that find where
 * feet rest read it (footskate.c, ground.c, check_legs.c): the larger of its steps to the
 * frames before and after.
 */
#ifndef MT_SPEED_H
#define MT_SPEED_H

#include <math.h>
#include <stddef.h>

/* The larger, NaN if either is (as numpy.maximum). */
static inline double nan_max(double a, double b)
{
    return a != a || b != b ? a + b : a > b ? a : b;
}

/* speed[t] for the frames of a point `stride` doubles apart: the larger of the lengths of its
   steps to frames t - 1 and t + 1 times rate (the one step at the take's ends; 0 in a take of
   one frame).  With `up` (a unit vector) and h, each frame's height along it, the steps are
   taken of the points less h up: across up. */
static inline void point_speed(const double *p, size_t frames, size_t stride, const double *up, const double *h,
                               double rate, double *speed)
{
    if (frames == 1)
        speed[0] = 0.0;
    double before = 0.0;
    for (size_t t = 0; t + 1 < frames; t++) {
        const double *a = p + t * stride, *b = a + stride;
        double d[3];
        for (int c = 0; c < 3; c++)
            d[c] = up ? (b[c] - h[t + 1] * up[c]) - (a[c] - h[t] * up[c]) : b[c] - a[c];
        const double after = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) * rate;
        speed[t] = t == 0 ? after : nan_max(after, before);
        before = after;
        if (t + 2 == frames)
            speed[t + 1] = after;
    }
}

#endif /* MT_SPEED_H */
