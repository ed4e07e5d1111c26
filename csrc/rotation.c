/*
 * rotation.c - rotations n at a time: Euler angles (any sequence of axes,
 * extrinsic or intrinsic), matrices, quaternions and rotation vectors; their
 * continuity along frames; interpolation between keys (see mtcore.h).
 *
 * Angles near 0 and pi are where the textbook formulas lose digits: the
 * conversions below use atan2 of well-conditioned pairs instead of acos and
 * asin, and series where a quotient tends to 0/0.
 *
 * Every conversion is a stage over LANES rotations at a time, each quantity
 * an array over them (as in lanes.h), so that its loops vectorise, sin, cos
 * and atan2 included; enough of them that the stages' long chains of
 * dependent operations overlap.  The entry points run one stage or a few over their
 * arrays; mt_interpolate_euler runs them all, Euler keys to Euler angles, in
 * one pass.
 */
#include "clones.h"
#include "lanes.h"
#include "mtcore.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { LANES = 32 };

/*
 * Below this |cos b| (Tait-Bryan) or |sin b| (proper Euler) the first and
 * last axes count as aligned, and c is set to 0; a is solved for the c
 * chosen, so the matrix is still reproduced, to within this bound.
 */
static const double gimbal_lock = 16 * DBL_EPSILON;

static int is_axis(int axis)
{
    return axis >= MT_DOF_RX && axis <= MT_DOF_RZ;
}

/* Rows 0 .. m-1 of src (width values each) into the lanes of dst; the lanes past m repeat row m-1, so that
   every lane computes what a real row gives, and are not stored. */
static MT_INLINE void load_block(const double *src, size_t width, size_t m, double (*dst)[LANES])
{
    for (size_t l = 0; l < LANES; l++)
        for (size_t c = 0; c < width; c++)
            dst[c][l] = src[(l < m ? l : m - 1) * width + c];
}

/* Lanes 0 .. m-1 of src to rows of width values of dst. */
static MT_INLINE void store_block(double (*src)[LANES], size_t width, size_t m, double *dst)
{
    for (size_t l = 0; l < m; l++)
        for (size_t c = 0; c < width; c++)
            dst[l * width + c] = src[c][l];
}

static MT_CLONES void euler_block(const double *angles, size_t n, const int *axes, size_t count,
                                  int intrinsic, double scale, double *out)
{
    for (size_t f0 = 0; f0 < n; f0 += BLOCK) {
        const size_t m = n - f0 < BLOCK ? n - f0 : BLOCK;
        double r[9 * BLOCK], v[BLOCK], sn[BLOCK], cs[BLOCK];
        spread_n(identity, 9, r, BLOCK);
        for (size_t step = 0; step < count; step++) {
            /* each rotation is applied on the left: intrinsic ones in reverse */
            const size_t a = intrinsic ? count - 1 - step : step;
            for (int f = 0; f < BLOCK; f++)
                v[f] = angles[(f0 + ((size_t)f < m ? (size_t)f : m - 1)) * count + a] * scale;
            sincos_lanes(v, sn, cs, BLOCK);
            rotate_left_n(r, axes[a], sn, cs, BLOCK);
        }
        for (size_t f = 0; f < m; f++)
            for (int e = 0; e < 9; e++)
                out[(f0 + f) * 9 + e] = r[e * BLOCK + f];
    }
}

int mt_euler_to_matrices(const double *angles, size_t n, const int *axes, size_t count, int intrinsic,
                         double scale, double *out)
{
    if (n == 0)
        return MT_OK;
    if (!out || (count > 0 && (!angles || !axes)))
        return MT_EINVAL;
    for (size_t a = 0; a < count; a++)
        if (!is_axis(axes[a]))
            return MT_EINVAL;
    euler_block(angles, n, axes, count, intrinsic, scale, out);
    return MT_OK;
}

static MT_CLONES void atan2_n(const double *y, const double *x, size_t n, double *out)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double a[1][LANES], b[1][LANES], c[1][LANES];
        load_block(y + f0, 1, lanes, a);
        load_block(x + f0, 1, lanes, b);
        atan2_lanes(a[0], b[0], c[0], LANES);
        store_block(c, 1, lanes, out + f0);
    }
}

int mt_atan2(const double *y, const double *x, size_t n, double *out)
{
    if (n > 0 && (y == NULL || x == NULL || out == NULL))
        return MT_EINVAL;
    atan2_n(y, x, n, out);
    return MT_OK;
}

static MT_CLONES void sincos_n(const double *x, size_t n, double *sin_out, double *cos_out)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double a[1][LANES], s[1][LANES], c[1][LANES];
        load_block(x + f0, 1, lanes, a);
        sincos_lanes(a[0], s[0], c[0], LANES);
        store_block(s, 1, lanes, sin_out + f0);
        store_block(c, 1, lanes, cos_out + f0);
    }
}

int mt_sincos(const double *x, size_t n, double *sin_out, double *cos_out)
{
    if (n > 0 && (x == NULL || sin_out == NULL || cos_out == NULL))
        return MT_EINVAL;
    sincos_n(x, n, sin_out, cos_out);
    return MT_OK;
}

/*
 * A convention of three Euler angles, Tait-Bryan or proper, and what solving
 * a matrix for its angles takes of it.
 *
 * Solved as extrinsic, R = R_k'(c) R_j(b) R_i(a), k' = k (Tait-Bryan) or i
 * (proper), k the axis other than i and j.  Intrinsic angles are minus the
 * extrinsic angles of the transpose R^T = R_k'(-c) R_j(-b) R_i(-a), solved
 * with b of the opposite sign so that proper b stays in [0, pi].
 *
 * b comes from the entries it alone decides, c from the column i of R;
 * a from the row j of R_k'(-c) R, which equals row j of R_i(a): then R is
 * reproduced for whatever c was taken, noisy c near gimbal lock included.
 */
struct convention {
    int axes[3], intrinsic, proper;
    int i, j, k, o; /* row j of R_k'(-c) R is cos c R[j] + f sin c R[o] */
    double e, f, s; /* the parity of (i, j, k); f; -1 for intrinsic angles, else 1 */
    double scale;   /* radians per unit of the angles */
};

static int convention(const int *axes, int intrinsic, double scale, struct convention *cv)
{
    if (axes == NULL)
        return MT_EINVAL;
    const int i = axes[0], j = axes[1];
    if (!is_axis(i) || !is_axis(j) || !is_axis(axes[2]) || i == j || j == axes[2])
        return MT_EINVAL;
    const int proper = axes[2] == i, k = 3 - i - j;
    const double e = (j - i + 3) % 3 == 1 ? 1.0 : -1.0;
    *cv = (struct convention){.axes = {i, j, axes[2]}, .intrinsic = intrinsic != 0, .proper = proper,
                              .i = i, .j = j, .k = k, .o = proper ? k : i, .e = e, .f = proper ? e : -e,
                              .s = intrinsic ? -1.0 : 1.0, .scale = scale};
    return MT_OK;
}

/* The unit quaternions of Euler angles (in units of the convention): the product of the quaternions
   (cos h, sin h axis) of the half angles h, each applied on the left, as the matrices of euler_block. */
static MT_INLINE void euler_quaternion_block(double angles[3][LANES], const struct convention *cv,
                                             double q[4][LANES])
{
    double h[LANES], sn[LANES], cs[LANES];
    for (int l = 0; l < LANES; l++)
        q[0][l] = 1, q[1][l] = 0, q[2][l] = 0, q[3][l] = 0;
    for (int step = 0; step < 3; step++) {
        const int a = cv->intrinsic ? 2 - step : step;
        for (int l = 0; l < LANES; l++)
            h[l] = angles[a][l] * cv->scale * 0.5;
        sincos_lanes(h, sn, cs, LANES);
        turn_quaternion_n(q[0], q[1], q[2], q[3], cv->axes[a], sn, cs, LANES);
    }
}

static MT_CLONES void euler_quaternions(const double *angles, size_t n, const struct convention *cv, double *out)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double a[3][LANES], q[4][LANES];
        load_block(angles + 3 * f0, 3, lanes, a);
        euler_quaternion_block(a, cv, q);
        for (int l = 0; l < LANES; l++) {
            const double sign = q[0][l] < 0 ? -1.0 : 1.0;
            for (int e = 0; e < 4; e++)
                q[e][l] *= sign;
        }
        store_block(q, 4, lanes, out + 4 * f0);
    }
}

int mt_euler_to_quaternions(const double *angles, size_t n, const int *axes, int intrinsic, double scale,
                            double *out)
{
    struct convention cv;
    if (convention(axes, intrinsic, scale, &cv) != MT_OK || (n > 0 && (!angles || !out)))
        return MT_EINVAL;
    euler_quaternions(angles, n, &cv, out);
    return MT_OK;
}

/* The matrices of quaternions, normalised. */
static MT_INLINE void quaternion_matrix_block(double q[4][LANES], double m[9][LANES])
{
    for (int l = 0; l < LANES; l++) {
        const double w = q[0][l], x = q[1][l], y = q[2][l], z = q[3][l];
        const double s = 2 / (w * w + x * x + y * y + z * z);
        m[0][l] = 1 - s * (y * y + z * z), m[1][l] = s * (x * y - w * z), m[2][l] = s * (x * z + w * y);
        m[3][l] = s * (x * y + w * z), m[4][l] = 1 - s * (x * x + z * z), m[5][l] = s * (y * z - w * x);
        m[6][l] = s * (x * z - w * y), m[7][l] = s * (y * z + w * x), m[8][l] = 1 - s * (x * x + y * y);
    }
}

/* The Euler angles (in units of the convention) of matrices; see struct convention. */
static MT_INLINE void matrix_euler_block(double m[9][LANES], const struct convention *cv, double out[3][LANES])
{
#define R(u, v) m[cv->intrinsic ? 3 * (v) + (u) : 3 * (u) + (v)]
    const int i = cv->i, j = cv->j, k = cv->k, o = cv->o;
    const double *rii = R(i, i), *rij = R(i, j), *rik = R(i, k), *rji = R(j, i), *rjj = R(j, j), *rjk = R(j, k);
    const double *rki = R(k, i), *rkj = R(k, j), *rkk = R(k, k), *roj = R(o, j), *rok = R(o, k);
#undef R
    const double e = cv->e, f = cv->f, s = cv->s, unit = s / cv->scale;
    double b[LANES], y[LANES], x[LANES], h[LANES], num[LANES], den[LANES], a[LANES], c[LANES];
    if (cv->proper) {
        for (int l = 0; l < LANES; l++) {
            num[l] = sqrt(rij[l] * rij[l] + rik[l] * rik[l]), den[l] = rii[l];
            y[l] = s * rji[l], x[l] = -s * e * rki[l];
        }
        atan2_lanes(num, den, b, LANES);
        for (int l = 0; l < LANES; l++)
            b[l] *= s;
    } else {
        for (int l = 0; l < LANES; l++) {
            num[l] = -e * rki[l], den[l] = sqrt(rkj[l] * rkj[l] + rkk[l] * rkk[l]);
            y[l] = e * rji[l], x[l] = rii[l];
        }
        atan2_lanes(num, den, b, LANES);
    }
    for (int l = 0; l < LANES; l++) {
        h[l] = sqrt(x[l] * x[l] + y[l] * y[l]);
        const int lock = h[l] <= gimbal_lock;
        const double inverse = 1 / h[l], cc = lock ? 1.0 : x[l] * inverse, sc = lock ? 0.0 : y[l] * inverse;
        num[l] = -e * (cc * rjk[l] + f * sc * rok[l]), den[l] = cc * rjj[l] + f * sc * roj[l];
    }
    atan2_lanes(num, den, a, LANES);
    atan2_lanes(y, x, c, LANES);
    for (int l = 0; l < LANES; l++) {
        out[0][l] = a[l] * unit;
        out[1][l] = b[l] * unit;
        out[2][l] = h[l] <= gimbal_lock ? 0.0 : c[l] * unit;
    }
}

static MT_CLONES void matrices_euler(const double *m, size_t n, const struct convention *cv, double *angles)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double r[9][LANES], out[3][LANES];
        load_block(m + 9 * f0, 9, lanes, r);
        matrix_euler_block(r, cv, out);
        store_block(out, 3, lanes, angles + 3 * f0);
    }
}

int mt_matrices_to_euler(const double *m, size_t n, const int *axes, int intrinsic, double scale,
                         double *angles)
{
    if (n == 0)
        return MT_OK;
    struct convention cv;
    if (!m || !angles || convention(axes, intrinsic, scale, &cv) != MT_OK)
        return MT_EINVAL;
    matrices_euler(m, n, &cv, angles);
    return MT_OK;
}

int mt_matrices_to_quaternions(const double *m, size_t n, double *q)
{
    if (n > 0 && (m == NULL || q == NULL))
        return MT_EINVAL;
    for (size_t i = 0; i < n; i++)
        matrix_quaternion(m + 9 * i, q + 4 * i);
    return MT_OK;
}

static MT_CLONES void quaternions_matrices(const double *q, size_t n, double *m)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double in[4][LANES], out[9][LANES];
        load_block(q + 4 * f0, 4, lanes, in);
        quaternion_matrix_block(in, out);
        store_block(out, 9, lanes, m + 9 * f0);
    }
}

int mt_quaternions_to_matrices(const double *q, size_t n, double *m)
{
    if (n > 0 && (q == NULL || m == NULL))
        return MT_EINVAL;
    quaternions_matrices(q, n, m);
    return MT_OK;
}

/* The quaternions of rotation vectors, w of either sign: (cos(x/2), v sin(x/2) / x), x = |v|, by the series
   of sin(x/2) / x where it tends to 0/0 (the next term, x^4/3840, is below an ulp). */
static MT_INLINE void exp_map_block(double v[3][LANES], double q[4][LANES])
{
    double angle[LANES], half[LANES], sn[LANES], cs[LANES];
    for (int l = 0; l < LANES; l++) {
        angle[l] = sqrt(v[0][l] * v[0][l] + v[1][l] * v[1][l] + v[2][l] * v[2][l]);
        half[l] = angle[l] / 2;
    }
    sincos_lanes(half, sn, cs, LANES);
    for (int l = 0; l < LANES; l++) {
        const double x = angle[l], k = x < 1e-4 ? 0.5 - x * x / 48 : sn[l] / x;
        q[0][l] = cs[l], q[1][l] = k * v[0][l], q[2][l] = k * v[1][l], q[3][l] = k * v[2][l];
    }
}

static MT_CLONES void rotvecs_quaternions(const double *v, size_t n, double *q)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double in[3][LANES], out[4][LANES];
        load_block(v + 3 * f0, 3, lanes, in);
        exp_map_block(in, out);
        for (int l = 0; l < LANES; l++) {
            const double sign = out[0][l] < 0 ? -1.0 : 1.0; /* angles past pi */
            for (int c = 0; c < 4; c++)
                out[c][l] *= sign;
        }
        store_block(out, 4, lanes, q + 4 * f0);
    }
}

int mt_rotvecs_to_quaternions(const double *v, size_t n, double *q)
{
    if (n > 0 && (v == NULL || q == NULL))
        return MT_EINVAL;
    rotvecs_quaternions(v, n, q);
    return MT_OK;
}

/*
 * The rotation vectors of quaternions, angles in [0, pi].  The half angle
 * h = atan2(|xyz|, |w|) in [0, pi/2] is accurate at both ends, where acos(w)
 * and asin(|xyz|) are not; v = xyz 2h / (|q| sin h), h / sin h by its series
 * where it tends to 0/0 (the next term, 7 h^4 / 360, is below an ulp).
 */
static MT_INLINE void rotvec_block(double q[4][LANES], double v[3][LANES])
{
    double xyz[LANES], w[LANES], h[LANES];
    for (int l = 0; l < LANES; l++) {
        xyz[l] = sqrt(q[1][l] * q[1][l] + q[2][l] * q[2][l] + q[3][l] * q[3][l]);
        w[l] = fabs(q[0][l]);
    }
    atan2_lanes(xyz, w, h, LANES);
    for (int l = 0; l < LANES; l++) {
        const double norm = sqrt(q[0][l] * q[0][l] + xyz[l] * xyz[l]);
        const double k = h[l] < 1e-4 ? 2 * (1 + h[l] * h[l] / 6) / norm : 2 * h[l] / xyz[l];
        const double sign = q[0][l] < 0 ? -1.0 : 1.0;
        for (int c = 0; c < 3; c++)
            v[c][l] = sign * k * q[c + 1][l];
    }
}

static MT_CLONES void quaternions_rotvecs(const double *q, size_t n, double *v)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double in[4][LANES], out[3][LANES];
        load_block(q + 4 * f0, 4, lanes, in);
        rotvec_block(in, out);
        store_block(out, 3, lanes, v + 3 * f0);
    }
}

int mt_quaternions_to_rotvecs(const double *q, size_t n, double *v)
{
    if (n > 0 && (q == NULL || v == NULL))
        return MT_EINVAL;
    quaternions_rotvecs(q, n, v);
    return MT_OK;
}

/* A continuity pass's kind of rotation. */
struct unroll_rule {
    size_t width;           /* values per rotation */
    double half_turn, flip; /* Euler angles only */
};
/* to = the rotation equal to cur that is nearest prev. */
typedef void unroll_step(const double *prev, const double *cur, double *to, const struct unroll_rule *rule);

/*
 * Keeps the first frame of each outer slice and steps every later one from
 * its predecessor's output.  Inlined into each caller, where step is a known
 * function that is inlined in turn.
 */
static MT_INLINE int unroll(const double *in, size_t outer, size_t n, size_t inner, unroll_step *step,
                            const struct unroll_rule *rule, double *out)
{
    if (outer == 0 || n == 0 || inner == 0)
        return MT_OK;
    if (in == NULL || out == NULL)
        return MT_EINVAL;
    const size_t row = rule->width * inner;
    for (size_t o = 0; o < outer; o++) {
        const double *src = in + o * n * row;
        double *dst = out + o * n * row;
        memcpy(dst, src, row * sizeof *dst);
        for (size_t t = 1; t < n; t++)
            for (size_t i = 0; i < row; i += rule->width)
                step(dst + (t - 1) * row + i, src + t * row + i, dst + t * row + i, rule);
    }
    return MT_OK;
}

static MT_INLINE void quaternion_step(const double *prev, const double *cur, double *to,
                                      const struct unroll_rule *rule)
{
    (void)rule;
    const double dot = prev[0] * cur[0] + prev[1] * cur[1] + prev[2] * cur[2] + prev[3] * cur[3];
    const double sign = dot < 0 ? -1.0 : 1.0;
    for (int c = 0; c < 4; c++)
        to[c] = sign * cur[c];
}

int mt_unroll_quaternions(const double *in, size_t outer, size_t n, size_t inner, double *out)
{
    const struct unroll_rule rule = {.width = 4};
    return unroll(in, outer, n, inner, quaternion_step, &rule, out);
}

/* x plus the whole turns that bring it nearest to ref. */
static MT_INLINE double nearest(double x, double ref, double turn)
{
    return x + turn * nearbyint((ref - x) / turn);
}

static MT_INLINE void euler_step(const double *prev, const double *cur, double *to, const struct unroll_rule *rule)
{
    const double half_turn = rule->half_turn, turn = 2 * half_turn;
    const double a[3] = {nearest(cur[0], prev[0], turn), nearest(cur[1], prev[1], turn),
                         nearest(cur[2], prev[2], turn)};
    const double b[3] = {nearest(cur[0] + half_turn, prev[0], turn), nearest(rule->flip - cur[1], prev[1], turn),
                         nearest(cur[2] + half_turn, prev[2], turn)};
    double da = 0, db = 0;
    for (int c = 0; c < 3; c++) {
        da += (a[c] - prev[c]) * (a[c] - prev[c]);
        db += (b[c] - prev[c]) * (b[c] - prev[c]);
    }
    /* NaN in either frame: no nearest, the frame as it is */
    const int other = db < da, restart = isnan(da);
    for (int c = 0; c < 3; c++)
        to[c] = restart ? cur[c] : other ? b[c] : a[c];
}

static struct unroll_rule euler_rule(int proper, double half_turn)
{
    return (struct unroll_rule){.width = 3, .half_turn = half_turn, .flip = proper ? 0.0 : half_turn};
}

int mt_unroll_euler(const double *in, size_t outer, size_t n, size_t inner, int proper, double half_turn,
                    double *out)
{
    if (!(half_turn > 0) || isinf(half_turn))
        return MT_EINVAL;
    const struct unroll_rule rule = euler_rule(proper, half_turn);
    return unroll(in, outer, n, inner, euler_step, &rule, out);
}

/*
 * SLERP from a to b (unit, a . b >= 0) by t: ka a + kb b, ka = sin((1 - t) theta) / sin theta and
 * kb = sin(t theta) / sin theta, by their series where they tend to 0/0 (theta in [0, pi/2]).
 *
 * A pair of keys gives the blend the rows of pair: a, b, theta and sin theta for SLERP; the
 * rotation vectors to interpolate from and to for the others.
 */
enum { PAIR_A = 0, PAIR_B = 4, PAIR_THETA = 8, PAIR_SIN = 9, PAIR_START = 0, PAIR_END = 3, PAIR = 10 };

/* The pair of SLERP from q0 to q1 (any norm), along the shorter arc. */
static MT_INLINE void slerp_pair_block(double q0[4][LANES], double q1[4][LANES], double pair[PAIR][LANES])
{
    double lo[LANES], hi[LANES], cs[LANES];
    for (int l = 0; l < LANES; l++) {
        const double n0 = sqrt(q0[0][l] * q0[0][l] + q0[1][l] * q0[1][l] + q0[2][l] * q0[2][l] + q0[3][l] * q0[3][l]);
        const double n1 = sqrt(q1[0][l] * q1[0][l] + q1[1][l] * q1[1][l] + q1[2][l] * q1[2][l] + q1[3][l] * q1[3][l]);
        const double dot = q0[0][l] * q1[0][l] + q0[1][l] * q1[1][l] + q0[2][l] * q1[2][l] + q0[3][l] * q1[3][l];
        const double s1 = (dot < 0 ? -1.0 : 1.0) / n1; /* the shorter arc */
        double diff = 0, sum = 0;
        for (int c = 0; c < 4; c++) {
            const double a = q0[c][l] / n0, b = s1 * q1[c][l];
            pair[PAIR_A + c][l] = a, pair[PAIR_B + c][l] = b;
            diff += (a - b) * (a - b), sum += (a + b) * (a + b);
        }
        lo[l] = sqrt(diff), hi[l] = sqrt(sum);
    }
    /* the angle between a and b, accurate where acos(a . b) is not */
    atan2_lanes(lo, hi, pair[PAIR_THETA], LANES);
    for (int l = 0; l < LANES; l++)
        pair[PAIR_THETA][l] *= 2;
    sincos_lanes(pair[PAIR_THETA], pair[PAIR_SIN], cs, LANES);
}

static MT_INLINE void slerp_blend_block(double pair[PAIR][LANES], const double *t, double q[4][LANES])
{
    double x0[LANES], x1[LANES], s0[LANES], s1[LANES], cs[LANES];
    const double *theta = pair[PAIR_THETA], *sin_theta = pair[PAIR_SIN];
    for (int l = 0; l < LANES; l++)
        x0[l] = (1 - t[l]) * theta[l], x1[l] = t[l] * theta[l];
    sincos_lanes(x0, s0, cs, LANES);
    sincos_lanes(x1, s1, cs, LANES);
    for (int l = 0; l < LANES; l++) {
        const double th = theta[l], u = 1 - t[l], v = t[l], small = th < 1e-5;
        const double ka = small ? u * (1 + (1 - u * u) * th * th / 6) : s0[l] / sin_theta[l];
        const double kb = small ? v * (1 + (1 - v * v) * th * th / 6) : s1[l] / sin_theta[l];
        for (int c = 0; c < 4; c++)
            q[c][l] = ka * pair[PAIR_A + c][l] + kb * pair[PAIR_B + c][l];
    }
}

static MT_CLONES void slerp(const double *q0, const double *q1, const double *t, size_t n, double *out)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double a[4][LANES], b[4][LANES], pair[PAIR][LANES], u[1][LANES], q[4][LANES];
        load_block(q0 + 4 * f0, 4, lanes, a);
        load_block(q1 + 4 * f0, 4, lanes, b);
        load_block(t + f0, 1, lanes, u);
        slerp_pair_block(a, b, pair);
        slerp_blend_block(pair, u[0], q);
        store_block(q, 4, lanes, out + 4 * f0);
    }
}

int mt_slerp(const double *q0, const double *q1, const double *t, size_t n, double *out)
{
    if (n > 0 && (q0 == NULL || q1 == NULL || t == NULL || out == NULL))
        return MT_EINVAL;
    slerp(q0, q1, t, n, out);
    return MT_OK;
}

/* The rotation vector to interpolate from: v0, or when aligned and the keys' quaternions have a negative
   dot product, that of -q0. */
static MT_INLINE void align_block(double v0[3][LANES], double v1[3][LANES], int aligned, double start[3][LANES])
{
    if (!aligned) {
        memcpy(start, v0, 3 * sizeof *start);
        return;
    }
    double q0[4][LANES], q1[4][LANES];
    exp_map_block(v0, q0);
    exp_map_block(v1, q1);
    for (int l = 0; l < LANES; l++) {
        const double a0 = sqrt(v0[0][l] * v0[0][l] + v0[1][l] * v0[1][l] + v0[2][l] * v0[2][l]);
        const double a1 = sqrt(v1[0][l] * v1[0][l] + v1[1][l] * v1[1][l] + v1[2][l] * v1[2][l]);
        const int flip = q0[0][l] * q1[0][l] + q0[1][l] * q1[1][l] + q0[2][l] * q1[2][l] + q0[3][l] * q1[3][l] < 0;
        /* -q0 turns by |v0| - 2 pi about v0; by 2 pi about v1 when v0 = 0 (then |v1| > pi) */
        for (int c = 0; c < 3; c++) {
            const double turned = a0 > 0 ? v0[c][l] * (1 - 2 * pi / a0) : v1[c][l] * (2 * pi / a1);
            start[c][l] = flip ? turned : v0[c][l];
        }
    }
}

static MT_INLINE void lerp_block(double pair[PAIR][LANES], const double *t, double v[3][LANES])
{
    for (int c = 0; c < 3; c++)
        for (int l = 0; l < LANES; l++) {
            const double start = pair[PAIR_START + c][l];
            v[c][l] = start + t[l] * (pair[PAIR_END + c][l] - start);
        }
}

static MT_CLONES void interpolate_rotvecs(const double *v0, const double *v1, const double *t, size_t n,
                                          int aligned, double *out)
{
    for (size_t f0 = 0; f0 < n; f0 += LANES) {
        const size_t lanes = n - f0 < LANES ? n - f0 : LANES;
        double a[3][LANES], pair[PAIR][LANES], u[1][LANES], v[3][LANES];
        load_block(v0 + 3 * f0, 3, lanes, a);
        load_block(v1 + 3 * f0, 3, lanes, pair + PAIR_END);
        load_block(t + f0, 1, lanes, u);
        align_block(a, pair + PAIR_END, aligned, pair + PAIR_START);
        lerp_block(pair, u[0], v);
        store_block(v, 3, lanes, out + 3 * f0);
    }
}

int mt_interpolate_rotvecs(const double *v0, const double *v1, const double *t, size_t n, int aligned,
                           double *out)
{
    if (n > 0 && (v0 == NULL || v1 == NULL || t == NULL || out == NULL))
        return MT_EINVAL;
    interpolate_rotvecs(v0, v1, t, n, aligned != 0, out);
    return MT_OK;
}

/* The pair of blend (a mt_blend) of the key triples k0, k1. */
static MT_INLINE void pair_block(double k0[3][LANES], double k1[3][LANES], const struct convention *cv, int blend,
                                 double pair[PAIR][LANES])
{
    double q0[4][LANES], q1[4][LANES], v0[3][LANES];
    euler_quaternion_block(k0, cv, q0);
    euler_quaternion_block(k1, cv, q1);
    if (blend == MT_BLEND_SLERP) {
        slerp_pair_block(q0, q1, pair);
        return;
    }
    rotvec_block(q0, v0);
    rotvec_block(q1, pair + PAIR_END);
    align_block(v0, pair + PAIR_END, blend == MT_BLEND_ALIGNED_EXPMAP, pair + PAIR_START);
}

/* The quaternions (any sign) a fraction t of the way along the pairs' interpolations. */
static MT_INLINE void blend_block(double pair[PAIR][LANES], const double *t, int blend, double q[4][LANES])
{
    double v[3][LANES];
    if (blend == MT_BLEND_SLERP) {
        slerp_blend_block(pair, t, q);
        return;
    }
    lerp_block(pair, t, v);
    exp_map_block(v, q);
}

/* The pairs of the key triples k0, k1 (n each), n x PAIR. */
static MT_CLONES void key_pairs(const double *k0, const double *k1, size_t n, const struct convention *cv, int blend,
                                double *pairs)
{
    for (size_t j0 = 0; j0 < n; j0 += LANES) {
        const size_t lanes = n - j0 < LANES ? n - j0 : LANES;
        double a[3][LANES], b[3][LANES], pair[PAIR][LANES];
        load_block(k0 + 3 * j0, 3, lanes, a);
        load_block(k1 + 3 * j0, 3, lanes, b);
        pair_block(a, b, cv, blend, pair);
        store_block(pair, PAIR, lanes, pairs + PAIR * j0);
    }
}

struct interpolation {
    const double *k0, *k1; /* frames x joints key triples; NULL where pairs holds them */
    const double *pairs;   /* joints x PAIR: the same keys for every frame */
    const double *t, *reference;
    size_t frames, joints;
    int blend, continuity;
    struct convention cv;
    double half_turn;
};

/*
 * Lanes lo .. hi-1 of res: of the triples equal to cur, the nearest prev (mt_unroll_euler's step).
 */
static MT_INLINE void path_lanes(double prev[3][LANES], double cur[3][LANES], size_t lo, size_t hi,
                                 const struct unroll_rule *rule, double res[3][LANES])
{
    for (size_t l = lo; l < hi; l++) {
        const double p[3] = {prev[0][l], prev[1][l], prev[2][l]}, c[3] = {cur[0][l], cur[1][l], cur[2][l]};
        double to[3];
        euler_step(p, c, to, rule);
        res[0][l] = to[0], res[1][l] = to[1], res[2][l] = to[2];
    }
}

/*
 * The items (frame, joint) in order, LANES at a time: keys to their pair (or the pair of the joint), the
 * blend at the frame's t, its Euler angles, then the continuity chosen.  Along a path an item follows the
 * output of the item `joints` before it, which a block holds itself when joints < LANES: the lanes then
 * go in groups of `joints`.
 */
static MT_CLONES void interpolate_euler(const struct interpolation *job, double *out)
{
    const size_t joints = job->joints, items = job->frames * joints;
    const struct unroll_rule rule = euler_rule(job->cv.proper, job->half_turn);
    for (size_t g0 = 0; g0 < items; g0 += LANES) {
        const size_t m = items - g0 < LANES ? items - g0 : LANES;
        size_t joint[LANES];
        double pair[PAIR][LANES], t[LANES], q[4][LANES], r[9][LANES], angles[3][LANES], res[3][LANES];
        for (size_t l = 0, f = g0 / joints, j = g0 % joints; l < LANES; l++) {
            joint[l] = j, t[l] = job->t[f];
            if (l + 1 < m && ++j == joints)
                j = 0, f++;
        }
        if (job->pairs != NULL) {
            for (size_t l = 0; l < LANES; l++)
                for (int p = 0; p < PAIR; p++)
                    pair[p][l] = job->pairs[joint[l] * PAIR + p];
        } else {
            double k0[3][LANES], k1[3][LANES];
            load_block(job->k0 + 3 * g0, 3, m, k0);
            load_block(job->k1 + 3 * g0, 3, m, k1);
            pair_block(k0, k1, &job->cv, job->blend, pair);
        }
        blend_block(pair, t, job->blend, q);
        quaternion_matrix_block(q, r);
        matrix_euler_block(r, &job->cv, angles);
        if (job->continuity == MT_CONTINUITY_REFERENCE) {
            double ref[3][LANES];
            load_block(job->reference + 3 * g0, 3, m, ref);
            for (int c = 0; c < 3; c++)
                for (int l = 0; l < LANES; l++)
                    res[c][l] = nearest(angles[c][l], ref[c][l], 2 * job->half_turn);
        } else if (job->continuity == MT_CONTINUITY_PATH) {
            double prev[3][LANES];
            for (size_t lo = 0; lo < m; lo += joints) {
                const size_t hi = m - lo < joints ? m : lo + joints;
                for (size_t l = lo; l < hi; l++)
                    for (int c = 0; c < 3; c++)
                        prev[c][l] = l >= joints           ? res[c][l - joints]
                                     : g0 + l >= joints ? out[3 * (g0 + l - joints) + c]
                                                        : job->reference[3 * joint[l] + c];
                path_lanes(prev, angles, lo, hi, &rule, res);
            }
        } else {
            memcpy(res, angles, sizeof res);
        }
        store_block(res, 3, m, out + 3 * g0);
    }
}

int mt_interpolate_euler(const double *k0, const double *k1, int per_frame, const double *t, size_t frames,
                         size_t joints, const int *axes, int intrinsic, int degrees, int blend, int continuity,
                         const double *reference, double *out)
{
    struct interpolation job = {.k0 = k0, .k1 = k1, .t = t, .reference = reference, .frames = frames,
                                .joints = joints, .blend = blend, .continuity = continuity,
                                .half_turn = degrees ? 180.0 : pi};
    if (blend < MT_BLEND_SLERP || blend > MT_BLEND_ALIGNED_EXPMAP || continuity < MT_CONTINUITY_NONE ||
        continuity > MT_CONTINUITY_REFERENCE || convention(axes, intrinsic, degrees ? pi / 180 : 1.0, &job.cv))
        return MT_EINVAL;
    if (frames == 0 || joints == 0)
        return MT_OK;
    if (!k0 || !k1 || !t || !out || (continuity != MT_CONTINUITY_NONE && !reference) ||
        frames > SIZE_MAX / (PAIR * sizeof(double)) / joints)
        return MT_EINVAL;
    double *pairs = NULL;
    if (!per_frame) {
        pairs = malloc(joints * PAIR * sizeof *pairs);
        if (pairs == NULL)
            return MT_ENOMEM;
        key_pairs(k0, k1, joints, &job.cv, blend, pairs);
        job.pairs = pairs;
    }
    interpolate_euler(&job, out);
    free(pairs);
    return MT_OK;
}
