/*
 * ground.c - where the feet rest, and the floor they rest on (mt_resting_points, mt_fit_floor;
 * see mtcore.h): the samples of heel, ball and toe tip that stand still, and the plane and rest
 * heights that fit them.
 */
#include "lanes.h"
#include "mtcore.h"
#include "speed.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { BALL = 2, HEEL = 3, TIP = 4, POINTS = 5, CONTACTS = 3 };
static const int contact[CONTACTS] = {HEEL, BALL, TIP};

/* The value at fraction q of the sorted values (n >= 1), linearly between the two around it,
   as numpy's percentile computes it. */
static double quantile(const double *sorted, size_t n, double q)
{
    const double at = (double)(n - 1) * q;
    if (at >= (double)(n - 1))
        return sorted[n - 1];
    const size_t i = (size_t)floor(at);
    const double gamma = at - (double)i, a = sorted[i], b = sorted[i + 1], diff = b - a;
    return gamma >= 0.5 ? b - diff * (1.0 - gamma) : a + diff * gamma;
}

static int ascending(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A frame and the key it is chosen by. */
struct keyed {
    double key;
    size_t frame;
};

/* By key, NaN last, then by frame. */
static int by_key(const void *a, const void *b)
{
    const struct keyed *x = a, *y = b;
    const int nx = x->key != x->key, ny = y->key != y->key;
    if (nx != ny)
        return nx - ny;
    if (!nx && x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->frame > y->frame) - (x->frame < y->frame);
}

/* A point that rests in too few frames rests in the `needed` slowest of its low frames (see
   mtcore.h); heights and speeds of its frames; scratch of frames doubles and keyed. */
static void slowest_low(const double *height, const double *speed, size_t frames, size_t needed,
                        unsigned char *resting, double *sorted, struct keyed *keyed)
{
    size_t n = 0;
    for (size_t t = 0; t < frames; t++)
        if (height[t] == height[t])
            sorted[n++] = height[t];
    const double low = n ? (qsort(sorted, n, sizeof *sorted, ascending), quantile(sorted, n, 0.2)) : NAN;
    for (size_t t = 0; t < frames; t++)
        keyed[t] = (struct keyed){.key = height[t] <= low ? speed[t] : INFINITY, .frame = t};
    qsort(keyed, frames, sizeof *keyed, by_key);
    for (size_t r = 0; r < needed && r < frames; r++)
        resting[keyed[r].frame * CONTACTS] = 1;
}

int mt_resting_points(const double *points, size_t nlegs, size_t frames, const int *tips, const double *up,
                      double frame_rate, double meters_per_unit, double rest_speed, size_t needed,
                      unsigned char *resting)
{
    if (nlegs == 0 || frames == 0)
        return MT_OK;
    if (!points || !tips || !up || !resting || frames > SIZE_MAX / (2 * sizeof(double) + sizeof(struct keyed)))
        return MT_EINVAL;
    double *scratch = malloc(frames * (3 * sizeof(double) + sizeof(struct keyed)));
    if (scratch == NULL)
        return MT_ENOMEM;
    double *height = scratch, *speed = scratch + frames, *sorted = scratch + 2 * frames;
    struct keyed *keyed = (struct keyed *)(scratch + 3 * frames);
    for (size_t i = 0; i < nlegs; i++)
        for (int k = 0; k < CONTACTS; k++) {
            const double *p = points + (i * frames * POINTS + (size_t)contact[k]) * 3;
            unsigned char *rests = resting + i * frames * CONTACTS + (size_t)k;
            size_t count = 0;
            point_speed(p, frames, POINTS * 3, NULL, NULL, frame_rate, speed);
            for (size_t t = 0; t < frames; t++) {
                height[t] = dot3(p + t * POINTS * 3, up);
                speed[t] *= meters_per_unit;
                rests[t * CONTACTS] = speed[t] < rest_speed;
                count += rests[t * CONTACTS];
            }
            if (count < needed)
                slowest_low(height, speed, frames, needed, rests, sorted, keyed);
            for (size_t t = 0; t < frames; t++)
                rests[t * CONTACTS] &= (k < 2 || tips[i]) && isfinite(height[t]);
        }
    free(scratch);
    return MT_OK;
}

/* Solve a x = b (m x m, row-major, both overwritten) by elimination with partial pivoting;
   MT_EINVAL where a is singular. */
static int solve(double *a, double *b, size_t m, double *x)
{
    for (size_t c = 0; c < m; c++) {
        size_t pivot = c;
        for (size_t r = c + 1; r < m; r++)
            if (fabs(a[r * m + c]) > fabs(a[pivot * m + c]))
                pivot = r;
        if (!(a[pivot * m + c] != 0.0))
            return MT_EINVAL;
        if (pivot != c) {
            for (size_t k = 0; k < m; k++) {
                const double t = a[c * m + k];
                a[c * m + k] = a[pivot * m + k], a[pivot * m + k] = t;
            }
            const double t = b[c];
            b[c] = b[pivot], b[pivot] = t;
        }
        for (size_t r = c + 1; r < m; r++) {
            const double f = a[r * m + c] / a[c * m + c];
            for (size_t k = c; k < m; k++)
                a[r * m + k] -= f * a[c * m + k];
            b[r] -= f * b[c];
        }
    }
    for (size_t c = m; c-- > 0;) {
        double s = b[c];
        for (size_t k = c + 1; k < m; k++)
            s -= a[c * m + k] * x[k];
        x[c] = s / a[c * m + c];
    }
    return MT_OK;
}

/* A resting sample: its horizontal coordinates, height and the unknown of its contact point. */
struct sample {
    double x, y, z;
    size_t unknown;
};

/* The normal equations of the plane and rest heights over the samples kept (see mt_fit_floor):
   a (m x m) and b (m); unknowns 0 and 1 the gradient, 2.. the rest heights. */
static void normal_equations(const struct sample *s, const unsigned char *keep, size_t n, size_t m, double ridge,
                             double *a, double *b)
{
    memset(a, 0, m * m * sizeof *a);
    memset(b, 0, m * sizeof *b);
    a[0] = a[m + 1] = ridge * ridge;
    for (size_t j = 0; j < n; j++) {
        if (!keep[j])
            continue;
        const double x = s[j].x, y = s[j].y, z = s[j].z;
        const size_t c = s[j].unknown;
        a[0] += x * x, a[1] += x * y, a[m + 1] += y * y;
        a[c] += x, a[m + c] += y, a[c * m + c] += 1.0;
        b[0] += x * z, b[1] += y * z, b[c] += z;
    }
    a[m] = a[1];
    for (size_t c = 2; c < m; c++)
        a[c * m] = a[c], a[c * m + 1] = a[m + c];
}

int mt_fit_floor(const double *points, const unsigned char *resting, size_t nlegs, size_t frames, const int *tips,
                 const double *up, double band, double prior, size_t samples, double max_tilt, double *level,
                 double *slope, double *clearance)
{
    if (!points || !resting || !tips || !up || !level || !slope || !clearance || samples == 0 || nlegs == 0 ||
        frames == 0 || nlegs > SIZE_MAX / CONTACTS / frames / sizeof(struct sample))
        return MT_EINVAL;
    int horizontal[2], axes = 0;
    for (int c = 0; c < 3; c++)
        if (up[c] == 0.0 && axes < 2)
            horizontal[axes++] = c;
    if (axes != 2)
        return MT_EINVAL;
    const size_t cells = nlegs * frames * CONTACTS, points_in_all = nlegs * CONTACTS;
    size_t count = 0;
    for (size_t i = 0; i < cells; i++)
        count += resting[i] != 0;
    const size_t every = count > samples ? (count + samples - 1) / samples : 1;
    const size_t taken = count ? (count - 1) / every + 1 : 0;
    const size_t m_most = 2 + points_in_all;
    struct sample *s = malloc(taken * sizeof *s + (m_most * m_most + 2 * m_most) * sizeof(double) +
                              points_in_all * sizeof(size_t) + taken + 1);
    if (s == NULL)
        return MT_ENOMEM;
    double *a = (double *)(s + taken), *b = a + m_most * m_most, *coef = b + m_most;
    size_t *unknown = (size_t *)(coef + m_most); /* of each contact point, 0 where it has no sample */
    unsigned char *keep = (unsigned char *)(unknown + points_in_all);
    size_t n = 0, seen = 0;
    for (size_t i = 0; i < points_in_all; i++)
        unknown[i] = 0;
    for (size_t i = 0; i < cells; i++)
        if (resting[i] && seen++ % every == 0)
            unknown[i / (frames * CONTACTS) * CONTACTS + i % CONTACTS] = 1;
    size_t m = 2;
    for (size_t i = 0; i < points_in_all; i++)
        unknown[i] = unknown[i] ? m++ : 0;
    double cx = 0, cy = 0;
    seen = 0;
    for (size_t i = 0; i < cells; i++) {
        if (!resting[i] || seen++ % every)
            continue;
        const size_t point = i / (frames * CONTACTS) * CONTACTS + i % CONTACTS;
        const double *p = points + (i / CONTACTS * POINTS + (size_t)contact[i % CONTACTS]) * 3;
        s[n] = (struct sample){.x = p[horizontal[0]], .y = p[horizontal[1]], .z = dot3(p, up), .unknown = unknown[point]};
        cx += s[n].x, cy += s[n].y;
        keep[n++] = 1;
    }
    if (n == 0) {
        free(s);
        return MT_EINVAL;
    }
    cx /= (double)n, cy /= (double)n;
    for (size_t j = 0; j < n; j++)
        s[j].x -= cx, s[j].y -= cy;
    const double ridge = sqrt((double)n) * prior;
    int status = MT_OK;
    for (int pass = 0; pass < 3 && status == MT_OK; pass++) {
        normal_equations(s, keep, n, m, ridge, a, b);
        status = solve(a, b, m, coef);
        for (size_t j = 0; j < n && status == MT_OK; j++)
            keep[j] = s[j].z - (coef[0] * s[j].x + coef[1] * s[j].y + coef[s[j].unknown]) < band;
    }
    if (status == MT_OK) {
        double gx = coef[0], gy = coef[1];
        const double norm = sqrt(gx * gx + gy * gy);
        if (norm > max_tilt)
            gx *= max_tilt / norm, gy *= max_tilt / norm;
        slope[0] = slope[1] = slope[2] = 0.0;
        slope[horizontal[0]] = gx, slope[horizontal[1]] = gy;
        double base = coef[2];
        for (size_t c = 3; c < m; c++)
            base = coef[c] < base ? coef[c] : base;
        for (size_t leg = 0; leg < nlegs; leg++) {
            double *out = clearance + leg * CONTACTS;
            for (size_t k = 0; k < CONTACTS; k++) {
                const size_t c = unknown[leg * CONTACTS + k];
                out[k] = c ? coef[c] - base : 0.0;
            }
            if (!tips[leg])
                out[2] = out[1];
        }
        *level = base - (slope[horizontal[0]] * cx + slope[horizontal[1]] * cy);
    }
    free(s);
    return status;
}
