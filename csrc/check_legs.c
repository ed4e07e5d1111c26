/*
 * check_legs.c - the take check's measures of the legs, frame by frame (mt_check_legs; see
 * mtcore.h): planted feet that drift, feet below the floor and knees bent backwards.
 *
 * Each leg is walked once over its frames for the knees and the depth; each foot point (heel,
 * ball) once more for its height along up, whose running minimum (mt_lb_envelope) tells where
 * the point rests around each frame, and once for its drift over the runs of frames on the
 * floor.
 */
#include "lanes.h"
#include "mtcore.h"
#include "speed.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

enum { KNEE, ANKLE, BALL, HEEL, TIP, POINTS };

static void difference(const double *a, const double *b, double *out)
{
    for (int c = 0; c < 3; c++)
        out[c] = a[c] - b[c];
}

/* Degrees the knee bends backwards at one frame (see mtcore.h), NaN comparing false. */
static double knee_back(const double *hip, const double *p, const struct mt_leg_check *check)
{
    double thigh[3], shin[3], foot[3], a[3], b[3];
    difference(p + 3 * KNEE, hip, thigh);
    difference(p + 3 * ANKLE, p + 3 * KNEE, shin);
    difference(p + 3 * BALL, p + 3 * ANKLE, foot);
    double cosine = dot3(thigh, shin) / (norm3(thigh) * norm3(shin));
    cosine = cosine < -1.0 ? -1.0 : cosine > 1.0 ? 1.0 : cosine;
    const double bend = acos(cosine) * (180.0 / pi);
    const double across = fabs(dot3(shin, foot) / (norm3(shin) * norm3(foot)));
    cross3(thigh, shin, a);
    cross3(shin, foot, b);
    return dot3(a, b) > 0 && across < check->foot_across && bend < check->folded ? bend : 0.0;
}

/* Which signed axis the leg stands along at one frame: the axis of the largest coordinate of
   hip - ankle (the first of equals), 2k for +k and 2k + 1 for -k; -1 where one is not a number. */
static int standing_axis(const double *hip, const double *ankle)
{
    double rise[3];
    difference(hip, ankle, rise);
    if (!(isfinite(rise[0]) && isfinite(rise[1]) && isfinite(rise[2])))
        return -1;
    int axis = 0;
    for (int c = 1; c < 3; c++)
        if (fabs(rise[c]) > fabs(rise[axis]))
            axis = c;
    return 2 * axis + (rise[axis] < 0);
}

/* The point's height along up at each frame into h, and how far above its lowest within the
   window it lies into lift (scratch: 2 x frames); NaN heights are left out of the lowest. */
static int lifts(const double *p, size_t frames, const struct mt_leg_check *check, double *h, double *lift,
                 double *scratch)
{
    double highest = -INFINITY;
    for (size_t t = 0; t < frames; t++) {
        h[t] = dot3(p + t * 3 * POINTS, check->up);
        if (isfinite(h[t]) && h[t] > highest)
            highest = h[t];
    }
    if (highest == -INFINITY) {
        for (size_t t = 0; t < frames; t++)
            lift[t] = NAN;
        return MT_OK;
    }
    for (size_t t = 0; t < frames; t++)
        lift[t] = isfinite(h[t]) ? h[t] : highest;
    const int status = mt_lb_envelope(lift, frames, 1, check->window, scratch, scratch + frames);
    if (status != MT_OK)
        return status;
    for (size_t t = 0; t < frames; t++)
        lift[t] = h[t] - scratch[frames + t];
    return MT_OK;
}

/* Where the point (frames x POINTS x 3 apart) lies across up at frame t. */
static void across_up(const double *p, size_t t, const double *h, const double *up, double *out)
{
    for (int c = 0; c < 3; c++)
        out[c] = p[t * 3 * POINTS + c] - h[t] * up[c];
}

/* The drift of one foot point over its runs of frames on the floor (see mtcore.h); speed:
   scratch of frames, its speed across up. */
static void drift_of(const double *p, size_t frames, const double *h, const double *lift,
                     const struct mt_leg_check *check, double *speed, double *drift)
{
    const double meters = check->meters_per_unit;
    double start[3] = {0, 0, 0}, here[3], d[3];
    point_speed(p, frames, 3 * POINTS, check->up, h, check->frame_rate, speed);
    int on = 0;
    for (size_t t = 0; t < frames; t++) {
        if (!(lift[t] * meters < check->floor_height && speed[t] * meters < check->floor_speed)) {
            drift[t] = NAN;
            on = 0;
            continue;
        }
        across_up(p, t, h, check->up, here);
        if (!on)
            for (int c = 0; c < 3; c++)
                start[c] = here[c];
        on = 1;
        difference(here, start, d);
        drift[t] = norm3(d);
    }
}

int mt_check_legs(const double *points, const double *hips, size_t nlegs, size_t frames, const double *rest,
                  const int *tips, const struct mt_leg_check *check, double *drift, double *depth, double *back,
                  size_t *standing)
{
    if (!standing)
        return MT_EINVAL;
    for (int a = 0; a < 6; a++)
        standing[a] = 0;
    if (nlegs == 0 || frames == 0)
        return MT_OK;
    if (!points || !hips || !rest || !tips || !check || !drift || !depth || !back ||
        frames > SIZE_MAX / sizeof(double) / 4)
        return MT_EINVAL;
    double *scratch = malloc(4 * frames * sizeof *scratch);
    if (scratch == NULL)
        return MT_ENOMEM;
    double *h = scratch + 2 * frames, *lift = scratch + 3 * frames;
    double floor_up[3];
    for (int c = 0; c < 3; c++)
        floor_up[c] = check->up[c] - check->slope[c];
    const int order[3] = {HEEL, BALL, TIP}; /* the order of rest's heights */
    int status = MT_OK;
    for (size_t i = 0; i < nlegs && status == MT_OK; i++) {
        const double *leg = points + i * frames * 3 * POINTS;
        for (size_t t = 0; t < frames; t++) {
            const double *p = leg + t * 3 * POINTS;
            const double *hip = hips + (i * frames + t) * 3;
            back[i * frames + t] = knee_back(hip, p, check);
            const int axis = standing_axis(hip, p + 3 * ANKLE);
            if (axis >= 0)
                standing[axis]++;
            double lowest = NAN;
            for (int k = 0; k < (tips[i] ? 3 : 2); k++) {
                const double above = (dot3(p + 3 * order[k], floor_up) - check->level) - rest[3 * i + k];
                if (above == above && !(above >= lowest))
                    lowest = above;
            }
            depth[i * frames + t] = -lowest;
        }
        for (int k = 0; k < 2 && status == MT_OK; k++) {
            const double *p = leg + 3 * order[k];
            status = lifts(p, frames, check, h, lift, scratch);
            if (status == MT_OK)
                drift_of(p, frames, h, lift, check, scratch, drift + (2 * i + k) * frames);
        }
    }
    free(scratch);
    return status;
}
