/*
 * lanes.h - build-internal: small vector and matrix algebra over lanes of
 * frames, shared by the kernels that solve frames side by side
 * (kinematics.c, retarget.c, rotation.c, footskate.c), and its one-lane
 * forms by those that take a frame at a time (ground.c, check_legs.c).
 *
 * Frames are computed BLOCK at a time, every quantity an array over the
 * block (structure of arrays), so that the inner loops run over frames and
 * vectorise: sin, cos and atan2 included, with the polynomials below instead
 * of libm's scalar calls.  Over n lanes l = 0 .. n - 1 (frames side by side)
 * a number is x[l], a vector v[e n + l], a matrix m[e n + l] (its entries
 * row-major).  With n = 1 that is the plain layout of a number, a vector or
 * a matrix: code that takes a frame at a time shares these functions (and
 * has one-lane forms at the end), while the kernels run them BLOCK frames at
 * a time, n a constant where they are inlined.  Functions that keep lanes of
 * their own take n <= BLOCK.  An output may be an input of the same lane only
 * where said.
 */
#ifndef MT_LANES_H
#define MT_LANES_H

#include "clones.h"
#include "mtcore.h"

#include <math.h>

enum { BLOCK = 8 };

static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
static const double pi = 3.14159265358979323846;
static const double tiny = 1e-12; /* below this a length or sine counts as zero */

/* ---------------------------------------------------------------- elementary functions */

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

/* acos of x in [-1, 1]: (1 - x)(1 + x) keeps the digits of 1 - x^2 near either end */
static MT_INLINE void acos_n(const double *x, double *out, int n)
{
    double y[BLOCK];
    for (int l = 0; l < n; l++)
        y[l] = sqrt((1 - x[l]) * (1 + x[l]));
    atan2_lanes(y, x, out, n);
}

/* ---------------------------------------------------------------- vectors and matrices */

static MT_INLINE void dot_n(const double *a, const double *b, double *out, int n)
{
    for (int l = 0; l < n; l++)
        out[l] = a[l] * b[l] + a[n + l] * b[n + l] + a[2 * n + l] * b[2 * n + l];
}

/* out may be a or b */
static MT_INLINE void cross_n(const double *a, const double *b, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        const double x = a[n + l] * b[2 * n + l] - a[2 * n + l] * b[n + l];
        const double y = a[2 * n + l] * b[l] - a[l] * b[2 * n + l];
        const double z = a[l] * b[n + l] - a[n + l] * b[l];
        out[l] = x, out[n + l] = y, out[2 * n + l] = z;
    }
}

/* out may be a */
static MT_INLINE void unit_n(const double *a, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        const double m = sqrt(a[l] * a[l] + a[n + l] * a[n + l] + a[2 * n + l] * a[2 * n + l]);
        for (int e = 0; e < 3; e++)
            out[e * n + l] = m > 0 ? a[e * n + l] / m : 0.0;
    }
}

/* out = a with its component along the unit vector e (the same in every lane) removed; out may be a */
static MT_INLINE void perpendicular_n(const double *a, const double *e, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        const double d = a[l] * e[0] + a[n + l] * e[1] + a[2 * n + l] * e[2];
        for (int c = 0; c < 3; c++)
            out[c * n + l] = a[c * n + l] - d * e[c];
    }
}

/* out (count entries over the lanes) = v, the same in every lane */
static MT_INLINE void spread_n(const double *v, int count, double *out, int n)
{
    for (int e = 0; e < count; e++)
        for (int l = 0; l < n; l++)
            out[e * n + l] = v[e];
}

/* out (count entries of lane l) = those of x, and back: between the lanes and one frame's plain layout */
static MT_INLINE void lane_get(const double *x, int count, int l, double *out, int n)
{
    for (int e = 0; e < count; e++)
        out[e] = x[e * n + l];
}

static MT_INLINE void lane_set(double *x, int count, int l, const double *in, int n)
{
    for (int e = 0; e < count; e++)
        x[e * n + l] = in[e];
}

/* out = m v (out may be v) */
static MT_INLINE void mat_vec_n(const double *m, const double *v, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        double r[3];
        for (int i = 0; i < 3; i++)
            r[i] = m[3 * i * n + l] * v[l] + m[(3 * i + 1) * n + l] * v[n + l] +
                   m[(3 * i + 2) * n + l] * v[2 * n + l];
        for (int i = 0; i < 3; i++)
            out[i * n + l] = r[i];
    }
}

/* out = m^T v (out may be v) */
static MT_INLINE void mat_tvec_n(const double *m, const double *v, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        double r[3];
        for (int i = 0; i < 3; i++)
            r[i] = m[i * n + l] * v[l] + m[(3 + i) * n + l] * v[n + l] + m[(6 + i) * n + l] * v[2 * n + l];
        for (int i = 0; i < 3; i++)
            out[i * n + l] = r[i];
    }
}

/* out = a b, a^T b, a b^T (out may be a or b) */
static MT_INLINE void mat_mul_n(const double *a, const double *b, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        double r[9];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                r[3 * i + k] = a[3 * i * n + l] * b[k * n + l] + a[(3 * i + 1) * n + l] * b[(3 + k) * n + l] +
                               a[(3 * i + 2) * n + l] * b[(6 + k) * n + l];
        for (int e = 0; e < 9; e++)
            out[e * n + l] = r[e];
    }
}

static MT_INLINE void mat_tmul_n(const double *a, const double *b, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        double r[9];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                r[3 * i + k] = a[i * n + l] * b[k * n + l] + a[(3 + i) * n + l] * b[(3 + k) * n + l] +
                               a[(6 + i) * n + l] * b[(6 + k) * n + l];
        for (int e = 0; e < 9; e++)
            out[e * n + l] = r[e];
    }
}

static MT_INLINE void mat_mult_n(const double *a, const double *b, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        double r[9];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                r[3 * i + k] = a[3 * i * n + l] * b[3 * k * n + l] + a[(3 * i + 1) * n + l] * b[(3 * k + 1) * n + l] +
                               a[(3 * i + 2) * n + l] * b[(3 * k + 2) * n + l];
        for (int e = 0; e < 9; e++)
            out[e * n + l] = r[e];
    }
}

/* out = c x, c one matrix for every lane (out may be x) */
static MT_INLINE void const_mat_mul_n(const double *c, const double *x, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        double r[9];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                r[3 * i + k] = c[3 * i] * x[k * n + l] + c[3 * i + 1] * x[(3 + k) * n + l] + c[3 * i + 2] * x[(6 + k) * n + l];
        for (int e = 0; e < 9; e++)
            out[e * n + l] = r[e];
    }
}

/* out = x c, c one matrix for every lane (out may be x) */
static MT_INLINE void mat_mul_const_n(const double *x, const double *c, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        double r[9];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                r[3 * i + k] = x[3 * i * n + l] * c[k] + x[(3 * i + 1) * n + l] * c[3 + k] + x[(3 * i + 2) * n + l] * c[6 + k];
        for (int e = 0; e < 9; e++)
            out[e * n + l] = r[e];
    }
}

/* out = c x c^T, c one matrix for every lane (out may be x) */
static MT_INLINE void conjugate_n(const double *c, const double *x, double *out, int n)
{
    const double ct[9] = {c[0], c[3], c[6], c[1], c[4], c[7], c[2], c[5], c[8]};
    const_mat_mul_n(c, x, out, n);
    mat_mul_const_n(out, ct, out, n);
}

/* ---------------------------------------------------------------- rotations */

/* the rows (or columns) p, q that a turn about a coordinate axis mixes */
static MT_INLINE int mixed_first(int axis)
{
    return axis == 0 ? 1 : axis == 1 ? 2 : 0;
}

static MT_INLINE int mixed_second(int axis)
{
    return axis == 0 ? 2 : axis == 1 ? 0 : 1;
}

/* q = (c, s e_axis) q over n lanes, q given by its rows w, x, y, z: a turn about a coordinate axis
 * (c, s: cosine and sine of half its angle) after the rotation q.
 * (c, s e) (w, v) = (w c - v.e s, v c + e w s + e x v s) */
static MT_INLINE void turn_quaternion_n(double *w, double *x, double *y, double *z, int axis, const double *s,
                                        const double *c, int n)
{
    double *rows[3] = {x, y, z};
    double *a = rows[axis], *p = rows[mixed_first(axis)], *r = rows[mixed_second(axis)];
    for (int l = 0; l < n; l++) {
        const double w0 = w[l], a0 = a[l], p0 = p[l], r0 = r[l];
        w[l] = c[l] * w0 - s[l] * a0;
        a[l] = c[l] * a0 + s[l] * w0;
        p[l] = c[l] * p0 - s[l] * r0;
        r[l] = c[l] * r0 + s[l] * p0;
    }
}

/* m = R(axis) m, R the rotations about a coordinate axis of the given sines and cosines: they mix two rows */
static MT_INLINE void rotate_left_n(double *m, int axis, const double *s, const double *c, int n)
{
    const int p = mixed_first(axis), q = mixed_second(axis);
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < n; l++) {
            const double a = m[(3 * p + k) * n + l], b = m[(3 * q + k) * n + l];
            m[(3 * p + k) * n + l] = c[l] * a - s[l] * b;
            m[(3 * q + k) * n + l] = s[l] * a + c[l] * b;
        }
}

/* v = R(axis) v, R as for rotate_left_n */
static MT_INLINE void rotate_vector_n(double *v, int axis, const double *s, const double *c, int n)
{
    const int p = mixed_first(axis), q = mixed_second(axis);
    for (int l = 0; l < n; l++) {
        const double a = v[p * n + l], b = v[q * n + l];
        v[p * n + l] = c[l] * a - s[l] * b;
        v[q * n + l] = s[l] * a + c[l] * b;
    }
}

/* m = m R(axis), R as for rotate_left_n: it mixes two columns */
static MT_INLINE void rotate_right_n(double *m, int axis, const double *s, const double *c, int n)
{
    const int p = mixed_first(axis), q = mixed_second(axis);
    for (int k = 0; k < 9; k += 3)
        for (int l = 0; l < n; l++) {
            const double a = m[(k + p) * n + l], b = m[(k + q) * n + l];
            m[(k + p) * n + l] = c[l] * a + s[l] * b;
            m[(k + q) * n + l] = -s[l] * a + c[l] * b;
        }
}

/* The rotations about the unit axes by the angles of cosines c and sines s (Rodrigues). */
static MT_INLINE void about_cs_n(const double *axis, const double *c, const double *s, double *out, int n)
{
    for (int l = 0; l < n; l++) {
        const double x = axis[l], y = axis[n + l], z = axis[2 * n + l], cl = c[l], sl = s[l], t = 1 - cl;
        const double r[9] = {cl + t * x * x,     t * x * y - sl * z, t * x * z + sl * y,
                             t * x * y + sl * z, cl + t * y * y,     t * y * z - sl * x,
                             t * x * z - sl * y, t * y * z + sl * x, cl + t * z * z};
        for (int e = 0; e < 9; e++)
            out[e * n + l] = r[e];
    }
}

/* The rotations by the angles about the unit axes. */
static MT_INLINE void about_n(const double *axis, const double *angle, double *out, int n)
{
    double s[BLOCK], c[BLOCK];
    sincos_lanes(angle, s, c, n);
    about_cs_n(axis, c, s, out, n);
}

/* The smallest rotations taking the directions of u onto those of v (half turns for opposite ones). */
static MT_INLINE void between_n(const double *u0, const double *v0, double *out, int n)
{
    double u[3 * BLOCK], v[3 * BLOCK], k[3 * BLOCK], s[BLOCK], c[BLOCK];
    unit_n(u0, u, n);
    unit_n(v0, v, n);
    cross_n(u, v, k, n);
    dot_n(k, k, s, n);
    dot_n(u, v, c, n);
    int wide = 0;
    for (int l = 0; l < n; l++) { /* R = c I + [k]x + k k^T / (1 + c), k = u x v: no trigonometry */
        const double f = 1 / (1 + c[l]), x = k[l], y = k[n + l], z = k[2 * n + l], cl = c[l];
        const double r[9] = {cl + f * x * x, -z + f * x * y, y + f * x * z,  z + f * y * x, cl + f * y * y,
                             -x + f * y * z, -y + f * z * x, x + f * z * y, cl + f * z * z};
        for (int e = 0; e < 9; e++)
            out[e * n + l] = r[e];
        s[l] = sqrt(s[l]);
        wide |= !(cl > -0.5);
    }
    if (!wide)
        return;
    /* a turn of 120 degrees or more, where 1 + c loses digits: about the axis by atan2(s, c), or
     * for opposite directions a half turn about an axis perpendicular to u */
    double axis[3 * BLOCK], angle[BLOCK], turn[9 * BLOCK];
    for (int l = 0; l < n; l++) {
        const int along = s[l] > tiny, low = fabs(u[l]) < 0.9;
        const double other[3] = {low, low ? 0.0 : 1.0, 0.0};
        const double p[3] = {u[n + l] * other[2] - u[2 * n + l] * other[1],
                             u[2 * n + l] * other[0] - u[l] * other[2], u[l] * other[1] - u[n + l] * other[0]};
        for (int e = 0; e < 3; e++)
            axis[e * n + l] = along ? k[e * n + l] : p[e];
    }
    unit_n(axis, axis, n);
    atan2_lanes(s, c, angle, n);
    for (int l = 0; l < n; l++)
        angle[l] = s[l] > tiny ? angle[l] : c[l] < 0 ? pi : 0.0;
    about_n(axis, angle, turn, n);
    for (int l = 0; l < n; l++)
        if (!(c[l] > -0.5))
            for (int e = 0; e < 9; e++)
                out[e * n + l] = turn[e * n + l];
}

static MT_INLINE void rotvec_exp_n(const double *v, double *m, int n)
{
    double axis[3 * BLOCK], angle[BLOCK];
    dot_n(v, v, angle, n);
    for (int l = 0; l < n; l++)
        angle[l] = sqrt(angle[l]);
    unit_n(v, axis, n);
    about_n(axis, angle, m, n);
}

/* ---------------------------------------------------------------- one lane: a frame at a time */

static inline double dot3(const double *a, const double *b)
{
    double d;
    dot_n(a, b, &d, 1);
    return d;
}

static inline void cross3(const double *a, const double *b, double *out)
{
    cross_n(a, b, out, 1);
}

static inline double norm3(const double *a)
{
    return sqrt(dot3(a, a));
}

static inline void unit3(const double *a, double *out)
{
    unit_n(a, out, 1);
}

static inline void perpendicular(const double *a, const double *e, double *out)
{
    perpendicular_n(a, e, out, 1);
}

static inline void mat_vec(const double *m, const double *v, double *out)
{
    mat_vec_n(m, v, out, 1);
}

static inline void mat_tvec(const double *m, const double *v, double *out)
{
    mat_tvec_n(m, v, out, 1);
}

static inline void mat_mul(const double *a, const double *b, double *out)
{
    mat_mul_n(a, b, out, 1);
}

static inline void mat_mult(const double *a, const double *b, double *out)
{
    mat_mult_n(a, b, out, 1);
}

static inline void about(const double *axis, double angle, double *out)
{
    about_n(axis, &angle, out, 1);
}

static inline void between(const double *u, const double *v, double *out)
{
    between_n(u, v, out, 1);
}

static inline void rotvec_exp(const double *v, double *m)
{
    rotvec_exp_n(v, m, 1);
}

/* The unit quaternion (w, x, y, z) of a rotation matrix (row-major), w >= 0: Shepperd's method,
 * dividing by the largest of 4w^2, 4x^2, 4y^2, 4z^2. */
static inline void matrix_quaternion(const double *m, double *q)
{
    const double trace = m[0] + m[4] + m[8];
    double w, x, y, z;
    if (trace > 0) {
        const double s = 2 * sqrt(trace + 1);
        w = s / 4, x = (m[7] - m[5]) / s, y = (m[2] - m[6]) / s, z = (m[3] - m[1]) / s;
    } else if (m[0] > m[4] && m[0] > m[8]) {
        const double s = 2 * sqrt(1 + m[0] - m[4] - m[8]);
        w = (m[7] - m[5]) / s, x = s / 4, y = (m[1] + m[3]) / s, z = (m[2] + m[6]) / s;
    } else if (m[4] > m[8]) {
        const double s = 2 * sqrt(1 + m[4] - m[0] - m[8]);
        w = (m[2] - m[6]) / s, x = (m[1] + m[3]) / s, y = s / 4, z = (m[5] + m[7]) / s;
    } else {
        const double s = 2 * sqrt(1 + m[8] - m[0] - m[4]);
        w = (m[3] - m[1]) / s, x = (m[2] + m[6]) / s, y = (m[5] + m[7]) / s, z = s / 4;
    }
    const double sign = w < 0 ? -1.0 : 1.0;
    q[0] = sign * w, q[1] = sign * x, q[2] = sign * y, q[3] = sign * z;
}

#endif /* MT_LANES_H */
