/*
 * rotation.c - rotations n at a time: Euler angles (any sequence of axes,
 * extrinsic or intrinsic), matrices, quaternions and rotation vectors; their
 * continuity along frames; interpolation between keys (see mtcore.h).
 *
 * Angles near 0 and pi are where the textbook formulas lose digits: the
 * conversions below use atan2 of well-conditioned pairs instead of acos and
 * asin, and series where a quotient tends to 0/0.
 */
#include "blocks.h"
#include "clones.h"
#include "mtcore.h"

#include <float.h>
#include <math.h>
#include <string.h>

static const double pi = 3.14159265358979323846;

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

static MT_CLONES void euler_block(const double *angles, size_t n, const int *axes, size_t count,
                                  int intrinsic, double scale, double *out)
{
    for (size_t f0 = 0; f0 < n; f0 += BLOCK) {
        const size_t m = n - f0 < BLOCK ? n - f0 : BLOCK;
        double r[9][BLOCK], v[BLOCK], sn[BLOCK], cs[BLOCK];
        for (int e = 0; e < 9; e++)
            for (int f = 0; f < BLOCK; f++)
                r[e][f] = identity[e];
        for (size_t step = 0; step < count; step++) {
            /* each rotation is applied on the left: intrinsic ones in reverse */
            const size_t a = intrinsic ? count - 1 - step : step;
            for (int f = 0; f < BLOCK; f++)
                v[f] = angles[(f0 + ((size_t)f < m ? (size_t)f : m - 1)) * count + a] * scale;
            sincos_block(v, sn, cs);
            rotate_left_block(r, axes[a], sn, cs);
        }
        for (size_t f = 0; f < m; f++)
            for (int e = 0; e < 9; e++)
                out[(f0 + f) * 9 + e] = r[e][f];
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

/*
 * Solved as extrinsic, R = R_k'(c) R_j(b) R_i(a), k' = k (Tait-Bryan) or i
 * (proper), k the axis other than i and j.  Intrinsic angles are minus the
 * extrinsic angles of the transpose R^T = R_k'(-c) R_j(-b) R_i(-a), solved
 * with b of the opposite sign so that proper b stays in [0, pi].
 *
 * b comes from the entries it alone decides, c from the column i of R;
 * a from the row j of R_k'(-c) R, which equals row j of R_i(a): then R is
 * reproduced for whatever c was taken, noisy c near gimbal lock included.
 */
int mt_matrices_to_euler(const double *m, size_t n, const int *axes, int intrinsic, double scale,
                         double *angles)
{
    if (n == 0)
        return MT_OK;
    if (!m || !axes || !angles)
        return MT_EINVAL;
    const int i = axes[0], j = axes[1];
    if (!is_axis(i) || !is_axis(j) || !is_axis(axes[2]) || i == j || j == axes[2])
        return MT_EINVAL;
    const int k = 3 - i - j, proper = axes[2] == i;
    const double e = (j - i + 3) % 3 == 1 ? 1.0 : -1.0; /* parity of (i, j, k) */
    const double s = intrinsic ? -1.0 : 1.0;
    /* row j of R_k'(-c) R is cos c R[j] + f sin c R[o] */
    const int o = proper ? k : i;
    const double f = proper ? e : -e;
    for (size_t t = 0; t < n; t++, m += 9, angles += 3) {
        double r[3][3];
        for (int u = 0; u < 3; u++)
            for (int v = 0; v < 3; v++)
                r[u][v] = intrinsic ? m[3 * v + u] : m[3 * u + v];
        double b, y, x; /* c = atan2(y, x) */
        if (proper) {
            b = s * atan2(hypot(r[i][j], r[i][k]), r[i][i]);
            y = s * r[j][i], x = -s * e * r[k][i];
        } else {
            b = atan2(-e * r[k][i], hypot(r[k][j], r[k][k]));
            y = e * r[j][i], x = r[i][i];
        }
        const double h = hypot(x, y);
        const int lock = h <= gimbal_lock;
        const double cc = lock ? 1.0 : x / h, sc = lock ? 0.0 : y / h;
        const double a = atan2(-e * (cc * r[j][k] + f * sc * r[o][k]), cc * r[j][j] + f * sc * r[o][j]);
        angles[0] = s * a / scale;
        angles[1] = s * b / scale;
        angles[2] = lock ? 0.0 : s * atan2(y, x) / scale;
    }
    return MT_OK;
}

int mt_matrices_to_quaternions(const double *m, size_t n, double *q)
{
    if (n > 0 && (m == NULL || q == NULL))
        return MT_EINVAL;
    for (size_t i = 0; i < n; i++, m += 9, q += 4) {
        const double trace = m[0] + m[4] + m[8];
        double w, x, y, z;
        if (trace > 0) { /* Shepperd: divide by the largest of 4w^2, 4x^2, 4y^2, 4z^2 */
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
    return MT_OK;
}

static MT_CLONES void quaternion_matrices(const double *restrict q, size_t n, double *restrict m)
{
    for (size_t i = 0; i < n; i++, q += 4, m += 9) {
        const double w = q[0], x = q[1], y = q[2], z = q[3];
        const double s = 2 / (w * w + x * x + y * y + z * z); /* normalises */
        m[0] = 1 - s * (y * y + z * z), m[1] = s * (x * y - w * z), m[2] = s * (x * z + w * y);
        m[3] = s * (x * y + w * z), m[4] = 1 - s * (x * x + z * z), m[5] = s * (y * z - w * x);
        m[6] = s * (x * z - w * y), m[7] = s * (y * z + w * x), m[8] = 1 - s * (x * x + y * y);
    }
}

int mt_quaternions_to_matrices(const double *q, size_t n, double *m)
{
    if (n > 0 && (q == NULL || m == NULL))
        return MT_EINVAL;
    quaternion_matrices(q, n, m);
    return MT_OK;
}

/* sin(x/2) / x, by its series where the quotient tends to 0/0 (the next term, x^4/3840, is below an ulp). */
static double half_sinc(double x)
{
    return x < 1e-4 ? 0.5 - x * x / 48 : sin(x / 2) / x;
}

/* The quaternion of a rotation vector, w of either sign. */
static void exp_map(const double *v, double *q)
{
    const double angle = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), k = half_sinc(angle);
    q[0] = cos(angle / 2), q[1] = k * v[0], q[2] = k * v[1], q[3] = k * v[2];
}

int mt_rotvecs_to_quaternions(const double *v, size_t n, double *q)
{
    if (n > 0 && (v == NULL || q == NULL))
        return MT_EINVAL;
    for (size_t i = 0; i < n; i++, v += 3, q += 4) {
        exp_map(v, q);
        const double sign = q[0] < 0 ? -1.0 : 1.0; /* angles past pi */
        for (int c = 0; c < 4; c++)
            q[c] *= sign;
    }
    return MT_OK;
}

/*
 * The half angle h = atan2(|xyz|, |w|) in [0, pi/2] is accurate at both
 * ends, where acos(w) and asin(|xyz|) are not; v = xyz 2h / (|q| sin h).
 */
int mt_quaternions_to_rotvecs(const double *q, size_t n, double *v)
{
    if (n > 0 && (q == NULL || v == NULL))
        return MT_EINVAL;
    for (size_t i = 0; i < n; i++, q += 4, v += 3) {
        const double xyz = sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        const double norm = sqrt(q[0] * q[0] + xyz * xyz);
        const double h = atan2(xyz, fabs(q[0]));
        /* h / sin h by its series (the next term, 7 h^4 / 360, is below an ulp) */
        const double k = h < 1e-4 ? 2 * (1 + h * h / 6) / norm : 2 * h / xyz;
        const double sign = q[0] < 0 ? -1.0 : 1.0; /* the angle in [0, pi] */
        for (int c = 0; c < 3; c++)
            v[c] = sign * k * q[c + 1];
    }
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

int mt_unroll_euler(const double *in, size_t outer, size_t n, size_t inner, int proper, double half_turn,
                    double *out)
{
    if (!(half_turn > 0) || isinf(half_turn))
        return MT_EINVAL;
    const struct unroll_rule rule = {.width = 3, .half_turn = half_turn,
                                     .flip = proper ? 0.0 : half_turn};
    return unroll(in, outer, n, inner, euler_step, &rule, out);
}

/* sin(x theta) / sin(theta), by its series where it tends to 0/0; theta in [0, pi/2]. */
static double sin_ratio(double x, double theta)
{
    return theta < 1e-5 ? x * (1 + (1 - x * x) * theta * theta / 6) : sin(x * theta) / sin(theta);
}

int mt_slerp(const double *q0, const double *q1, const double *t, size_t n, double *out)
{
    if (n > 0 && (q0 == NULL || q1 == NULL || t == NULL || out == NULL))
        return MT_EINVAL;
    for (size_t i = 0; i < n; i++, q0 += 4, q1 += 4, out += 4) {
        const double n0 = sqrt(q0[0] * q0[0] + q0[1] * q0[1] + q0[2] * q0[2] + q0[3] * q0[3]);
        const double n1 = sqrt(q1[0] * q1[0] + q1[1] * q1[1] + q1[2] * q1[2] + q1[3] * q1[3]);
        const double dot = q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3];
        const double s1 = dot < 0 ? -1.0 / n1 : 1.0 / n1; /* the shorter arc */
        double a[4], b[4], diff = 0, sum = 0;
        for (int c = 0; c < 4; c++) {
            a[c] = q0[c] / n0, b[c] = s1 * q1[c];
            diff += (a[c] - b[c]) * (a[c] - b[c]), sum += (a[c] + b[c]) * (a[c] + b[c]);
        }
        /* the angle between a and b, accurate where acos(a . b) is not */
        const double theta = 2 * atan2(sqrt(diff), sqrt(sum));
        const double ka = sin_ratio(1 - t[i], theta), kb = sin_ratio(t[i], theta);
        for (int c = 0; c < 4; c++)
            out[c] = ka * a[c] + kb * b[c];
    }
    return MT_OK;
}

int mt_interpolate_rotvecs(const double *v0, const double *v1, const double *t, size_t n, int aligned,
                           double *out)
{
    if (n > 0 && (v0 == NULL || v1 == NULL || t == NULL || out == NULL))
        return MT_EINVAL;
    for (size_t i = 0; i < n; i++, v0 += 3, v1 += 3, out += 3) {
        double start[3] = {v0[0], v0[1], v0[2]};
        if (aligned) {
            double q0[4], q1[4];
            exp_map(v0, q0);
            exp_map(v1, q1);
            if (q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3] < 0) {
                const double a0 = sqrt(v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]);
                const double a1 = sqrt(v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2]);
                /* -q0 turns by |v0| - 2 pi about v0; by 2 pi about v1 when v0 = 0 (then |v1| > pi) */
                for (int c = 0; c < 3; c++)
                    start[c] = a0 > 0 ? v0[c] * (1 - 2 * pi / a0) : v1[c] * (2 * pi / a1);
            }
        }
        for (int c = 0; c < 3; c++)
            out[c] = start[c] + t[i] * (v1[c] - start[c]);
    }
    return MT_OK;
}
