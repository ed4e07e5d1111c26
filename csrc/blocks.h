/*
 * blocks.h - build-internal: rotations of BLOCK frames at a time, shared by
 * forward kinematics (kinematics.c) and the rotation kernels (rotation.c).
 *
 * Frames are computed BLOCK at a time, every quantity an array over the
 * block (structure of arrays), so that the inner loops run over frames and
 * vectorise: sin and cos included, with the polynomial below instead of
 * libm's scalar calls.
 */
#ifndef MT_BLOCKS_H
#define MT_BLOCKS_H

#include "clones.h"
#include "mtcore.h"

#include <math.h>

enum { BLOCK = 8 };

static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

/*
 * sin and cos of the n values x (radians), branch-free: reduction by pi/4 in
 * three parts and the minimax polynomials of Cephes (Moshier), to about 1e-16
 * for |x| < 2^30.  Larger angles (where the reduction fails) go to libm.  n is
 * a constant where this is inlined, BLOCK or the lanes of a caller's own blocks.
 */
static MT_INLINE void sincos_lanes(const double *x, double *sin_out, double *cos_out, int n)
{
    static const double s1 = 1.58962301576546568060e-10, s2 = -2.50507477628578072866e-8,
                        s3 = 2.75573136213857245213e-6, s4 = -1.98412698295895385996e-4,
                        s5 = 8.33333333332211858878e-3, s6 = -1.66666666666666307295e-1;
    static const double c1 = -1.13585365213876817300e-11, c2 = 2.08757008419747316778e-9,
                        c3 = -2.75573141792967388112e-7, c4 = 2.48015872888517045348e-5,
                        c5 = -1.38888888888730564116e-3, c6 = 4.16666666666665929218e-2;
    static const double dp1 = 7.85398125648498535156e-1, dp2 = 3.77489470793079817668e-8,
                        dp3 = 2.69515142907905952645e-15, four_over_pi = 1.27323954473516268615;
    int large = 0;
    for (int b = 0; b < n; b++) {
        const double a = fabs(x[b]);
        large |= !(a < 1073741824.0); /* 2^30, and NaN */
        int j = (int)(a < 1073741824.0 ? a * four_over_pi : 0.0);
        j += j & 1; /* round the octant up to even */
        const double y = (double)j;
        const double z = ((a - y * dp1) - y * dp2) - y * dp3, zz = z * z;
        const double ps = z + z * zz * (((((s1 * zz + s2) * zz + s3) * zz + s4) * zz + s5) * zz + s6);
        const double pc = 1.0 - 0.5 * zz + zz * zz * (((((c1 * zz + c2) * zz + c3) * zz + c4) * zz + c5) * zz + c6);
        const int q = (j >> 1) & 3; /* quadrant of a */
        const double sa = (q & 1) ? pc : ps, ca = (q & 1) ? ps : pc;
        sin_out[b] = ((q & 2) ? -sa : sa) * copysign(1.0, x[b]);
        cos_out[b] = ((q == 1 || q == 2) ? -ca : ca);
    }
    if (large)
        for (int b = 0; b < n; b++)
            if (!(fabs(x[b]) < 1073741824.0)) {
                sin_out[b] = sin(x[b]);
                cos_out[b] = cos(x[b]);
            }
}

/*
 * atan2(y, x) (radians, in [-pi, pi]), branch-free: t = atan w by the rational
 * approximation of Cephes (Moshier), w = z or (z - 1) / (z + 1) above 0.66
 * for z = min / max of |x| and |y| in [0, 1], so that atan z = m pi/4 + t
 * (m = 0 or 1); the octant of (x, y) makes the angle K pi/4 +- t, K in 0..4,
 * summed as K pi/4 in two parts and t, rounded once.  Within an ulp of pi of
 * libm's; the same at zeros of either sign and infinities, NaN for NaN.  n
 * values, as for sincos_lanes.
 */
static MT_INLINE void atan2_lanes(const double *y, const double *x, double *out, int n)
{
    static const double p0 = -8.750608600031904122785e-1, p1 = -1.615753718733365076637e1,
                        p2 = -7.500855792314704667340e1, p3 = -1.228866684490136173410e2,
                        p4 = -6.485021904942025371773e1;
    static const double q0 = 2.485846490142306297962e1, q1 = 1.650270098316988542046e2,
                        q2 = 4.328810604912902668951e2, q3 = 4.853903996359136964868e2,
                        q4 = 1.945506571482613964425e2;
    /* K pi/4 = high + low, high the double nearest: K times those of pi/4 but for K = 3 */
    static const double high1 = 7.853981633974483e-01, low1 = 3.061616997868383e-17;
    static const double high3 = 2.356194490192345, low3 = 9.184850993605148e-17;
    for (int b = 0; b < n; b++) {
        const double yb = y[b], xb = x[b], ay = fabs(yb), ax = fabs(xb);
        const int steep = ay > ax, negative = copysign(1.0, xb) < 0;
        double hi = steep ? ay : ax, lo = steep ? ax : ay;
        /* z = lo / hi, but 0 for 0/0 and 1 for inf/inf; scaled (exactly) so that neither
           lo + hi overflows nor 0.66 hi loses digits below the normal range */
        const int infinite = lo == INFINITY;
        const double scale = hi > 0x1p1000 ? 0x1p-100 : hi < 0x1p-900 ? 0x1p1000 : 1.0;
        hi = infinite || hi == 0 ? 1.0 : hi * scale, lo = infinite ? 1.0 : lo * scale;
        const int upper = lo > 0.66 * hi;
        const double w = (upper ? lo - hi : lo) / (upper ? lo + hi : hi), ww = w * w;
        const double p = (((p0 * ww + p1) * ww + p2) * ww + p3) * ww + p4;
        const double q = ((((ww + q0) * ww + q1) * ww + q2) * ww + q3) * ww + q4;
        const double t = w * (ww * p / q) + w;
        /* m pi/4 + t, then pi/2 minus that when steep, then pi minus that when x < 0 */
        const int m = upper, k = steep ? 2 - m : m, kk = negative ? 4 - k : k;
        const double sign = steep != negative ? -1.0 : 1.0;
        const double high = kk == 3 ? high3 : kk * high1, low = kk == 3 ? low3 : kk * low1;
        const double u = high + (low + sign * t);
        out[b] = (xb != xb) | (yb != yb) ? xb + yb : copysign(u, yb);
    }
}

static MT_INLINE void sincos_block(const double *x, double *sin_out, double *cos_out)
{
    sincos_lanes(x, sin_out, cos_out, BLOCK);
}

/* m = R(axis, angle) m for BLOCK matrices m[entry][frame]. */
static MT_INLINE void rotate_left_block(double m[9][BLOCK], int axis, const double *s, const double *c)
{
    const int a = axis == MT_DOF_RX ? 1 : axis == MT_DOF_RY ? 2 : 0;
    const int b = axis == MT_DOF_RX ? 2 : axis == MT_DOF_RY ? 0 : 1;
    for (int k = 0; k < 3; k++)
        for (int f = 0; f < BLOCK; f++) {
            const double ra = m[3 * a + k][f], rb = m[3 * b + k][f];
            m[3 * a + k][f] = c[f] * ra - s[f] * rb;
            m[3 * b + k][f] = s[f] * ra + c[f] * rb;
        }
}

#endif /* MT_BLOCKS_H */
