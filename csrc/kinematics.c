/*
 * kinematics.c - forward kinematics of joint trees over frames (ASF/AMC
 * semantics, see mtcore.h), and rotation matrices to quaternions.
 *
 * Frames are independent: a call computes a range of them, so that several
 * threads can share one output.  The joints are visited parents first; a
 * joint's world rotation and end point are kept in scratch for its children.
 */
#include "clones.h"
#include "mtcore.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* m = R(axis, angle) m: a rotation about a fixed axis, applied after m. */
static void rotate_left(double m[9], int axis, double angle)
{
    const double c = cos(angle), s = sin(angle);
    /* Rows a and b of m mix; the row of the axis itself stays. */
    const int a = axis == MT_DOF_RX ? 1 : axis == MT_DOF_RY ? 2 : 0;
    const int b = axis == MT_DOF_RX ? 2 : axis == MT_DOF_RY ? 0 : 1;
    for (int k = 0; k < 3; k++) {
        const double ra = m[3 * a + k], rb = m[3 * b + k];
        m[3 * a + k] = c * ra - s * rb;
        m[3 * b + k] = s * ra + c * rb;
    }
}

static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

int mt_axis_rotations(const int *axes, const double *angles, size_t count, double scale,
                      double *out)
{
    if (out == NULL || (count > 0 && (axes == NULL || angles == NULL)))
        return MT_EINVAL;
    memcpy(out, identity, sizeof identity);
    for (size_t i = 0; i < count; i++) {
        if (axes[i] < MT_DOF_RX || axes[i] > MT_DOF_RZ)
            return MT_EINVAL;
        rotate_left(out, axes[i], angles[i] * scale);
    }
    return MT_OK;
}

/* Checks that order[] is a permutation visiting parents first. */
static int check_tree(size_t joints, const long long *parent, const long long *order)
{
    unsigned char *seen = calloc(joints ? joints : 1, 1);
    if (seen == NULL)
        return MT_ENOMEM;
    int status = MT_OK;
    for (size_t i = 0; i < joints && status == MT_OK; i++) {
        long long j = order[i];
        if (j < 0 || (size_t)j >= joints || seen[j])
            status = MT_EINVAL;
        else if (parent[j] >= 0 && ((size_t)parent[j] >= joints || !seen[parent[j]]))
            status = MT_EINVAL;
        else
            seen[j] = 1;
    }
    free(seen);
    return status;
}

/*
 * Frames are computed BLOCK at a time, every quantity an array over the
 * block (structure of arrays), so that the inner loops run over frames and
 * vectorise: sin and cos included, with the polynomial below instead of
 * libm's scalar calls.
 */
enum { BLOCK = 8 };

/*
 * sin and cos of x (radians), branch-free: reduction by pi/4 in three parts
 * and the minimax polynomials of Cephes (Moshier), to about 1e-16 for
 * |x| < 2^30.  Larger angles (where the reduction fails) go to libm.
 */
static MT_INLINE void sincos_block(const double *x, double *sin_out, double *cos_out)
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
    for (int b = 0; b < BLOCK; b++) {
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
        sin_out[b] = ((q & 2) ? -sa : sa) * (x[b] < 0 ? -1.0 : 1.0);
        cos_out[b] = ((q == 1 || q == 2) ? -ca : ca);
    }
    if (large)
        for (int b = 0; b < BLOCK; b++)
            if (!(fabs(x[b]) < 1073741824.0)) {
                sin_out[b] = sin(x[b]);
                cos_out[b] = cos(x[b]);
            }
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

/* out = x y for block matrices. */
static MT_INLINE void multiply_block(double x[9][BLOCK], double y[9][BLOCK], double out[9][BLOCK])
{
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            for (int f = 0; f < BLOCK; f++)
                out[3 * i + k][f] = x[3 * i][f] * y[k][f] + x[3 * i + 1][f] * y[3 + k][f] +
                                    x[3 * i + 2][f] * y[6 + k][f];
}

/* out = C m C^T for a constant C and block matrices m. */
static MT_INLINE void conjugate_block(const double *c9, double m[9][BLOCK], double out[9][BLOCK])
{
    double cm[9][BLOCK];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            for (int f = 0; f < BLOCK; f++)
                cm[3 * i + k][f] = c9[3 * i] * m[k][f] + c9[3 * i + 1] * m[3 + k][f] + c9[3 * i + 2] * m[6 + k][f];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            for (int f = 0; f < BLOCK; f++)
                out[3 * i + k][f] = cm[3 * i][f] * c9[3 * k] + cm[3 * i + 1][f] * c9[3 * k + 1] +
                                    cm[3 * i + 2][f] * c9[3 * k + 2];
}

struct fk {
    const double *values;
    size_t channels, joints;
    const long long *parent, *order;
    const double *axis, *direction, *segment;
    const size_t *dof_start, *dof_column;
    const int *dof_kind;
    const unsigned char *parent_frame; /* the segment turns with the parent (BVH), or NULL */
    const unsigned char *plain;        /* C is the identity: L = M */
    double angle_scale;
    double (*world)[9][BLOCK]; /* scratch: each joint's world rotation over the block */
    double (*end)[3][BLOCK];   /* scratch: each joint's end point over the block */
};

/* Frames f0 .. f0+n-1 (n <= BLOCK); lanes past n repeat the last frame and are not written. */
static MT_CLONES void fk_block(const struct fk *k, size_t f0, size_t n, double *positions,
                               double *world_out, double *local_out)
{
    const double *rows[BLOCK];
    for (int f = 0; f < BLOCK; f++)
        rows[f] = k->values + (f0 + ((size_t)f < n ? (size_t)f : n - 1)) * k->channels;
    for (size_t i = 0; i < k->joints; i++) {
        const size_t j = (size_t)k->order[i];
        double m[9][BLOCK], t[3][BLOCK] = {{0}}, stretch[BLOCK] = {0}, v[BLOCK], sn[BLOCK], cs[BLOCK];
        for (int e = 0; e < 9; e++)
            for (int f = 0; f < BLOCK; f++)
                m[e][f] = identity[e];
        for (size_t c = k->dof_start[j]; c < k->dof_start[j + 1]; c++) {
            const size_t column = k->dof_column[c];
            const int kind = k->dof_kind[c];
            for (int f = 0; f < BLOCK; f++)
                v[f] = rows[f][column];
            if (kind <= MT_DOF_RZ) {
                for (int f = 0; f < BLOCK; f++)
                    v[f] *= k->angle_scale;
                sincos_block(v, sn, cs);
                rotate_left_block(m, kind, sn, cs);
            } else if (kind <= MT_DOF_TZ) {
                for (int f = 0; f < BLOCK; f++)
                    t[kind - MT_DOF_TX][f] += v[f];
            } else {
                for (int f = 0; f < BLOCK; f++)
                    stretch[f] += v[f];
            }
        }
        const double *c9 = k->axis + 9 * j;
        double l[9][BLOCK];
        if (k->plain[j])
            memcpy(l, m, sizeof l);
        else
            conjugate_block(c9, m, l);
        double(*w)[BLOCK] = k->world[j];
        double(*p)[BLOCK] = k->end[j];
        const double *seg = k->segment + 3 * j, *dir = k->direction + 3 * j;
        if (k->parent[j] < 0) {
            memcpy(w, l, sizeof l);
            for (int e = 0; e < 3; e++)
                for (int f = 0; f < BLOCK; f++)
                    p[e][f] = seg[e] + t[e][f];
        } else {
            const size_t q = (size_t)k->parent[j];
            multiply_block(k->world[q], l, w);
            double vec[3][BLOCK];
            for (int e = 0; e < 3; e++)
                for (int f = 0; f < BLOCK; f++)
                    vec[e][f] = seg[e] + dir[e] * stretch[f] + c9[3 * e] * t[0][f] + c9[3 * e + 1] * t[1][f] +
                                c9[3 * e + 2] * t[2][f];
            double(*turn)[BLOCK] = k->parent_frame && k->parent_frame[j] ? k->world[q] : w;
            for (int e = 0; e < 3; e++)
                for (int f = 0; f < BLOCK; f++)
                    p[e][f] = k->end[q][e][f] + turn[3 * e][f] * vec[0][f] + turn[3 * e + 1][f] * vec[1][f] +
                              turn[3 * e + 2][f] * vec[2][f];
        }
        for (size_t f = 0; f < n; f++) {
            const size_t at = (f0 + f) * k->joints + j;
            for (int e = 0; e < 3; e++)
                positions[3 * at + e] = p[e][f];
            for (int e = 0; e < 9; e++) {
                if (world_out)
                    world_out[9 * at + e] = w[e][f];
                if (local_out)
                    local_out[9 * at + e] = l[e][f];
            }
        }
    }
}

int mt_forward_kinematics(const double *values, size_t frames, size_t channels, size_t joints,
                          const long long *parent, const long long *order, const double *axis,
                          const double *direction, const double *segment, const size_t *dof_start,
                          const int *dof_kind, const size_t *dof_column,
                          const unsigned char *parent_frame, double angle_scale, size_t begin,
                          size_t end, double *positions, double *world, double *local)
{
    if (begin > end || end > frames)
        return MT_EINVAL;
    if (joints == 0 || begin == end)
        return MT_OK;
    if (!parent || !order || !axis || !direction || !segment || !dof_start || !positions ||
        (frames > 0 && channels > 0 && !values) || (dof_start[joints] > 0 && (!dof_kind || !dof_column)))
        return MT_EINVAL;
    for (size_t c = 0; c < dof_start[joints]; c++)
        if (dof_kind[c] < MT_DOF_RX || dof_kind[c] > MT_DOF_L || dof_column[c] >= channels)
            return MT_EINVAL;
    for (size_t j = 0; j < joints; j++)
        if (dof_start[j] > dof_start[j + 1])
            return MT_EINVAL;
    int status = check_tree(joints, parent, order);
    if (status != MT_OK)
        return status;
    struct fk k = {values,    channels,   joints,   parent,       order, axis,        direction, segment,
                   dof_start, dof_column, dof_kind, parent_frame, NULL,  angle_scale, NULL,      NULL};
    unsigned char *plain = malloc(joints);
    k.world = malloc(joints * sizeof *k.world);
    k.end = malloc(joints * sizeof *k.end);
    if (plain && k.world && k.end) {
        for (size_t j = 0; j < joints; j++)
            plain[j] = memcmp(axis + 9 * j, identity, sizeof identity) == 0;
        k.plain = plain;
        for (size_t f0 = begin; f0 < end; f0 += BLOCK)
            fk_block(&k, f0, end - f0 < BLOCK ? end - f0 : BLOCK, positions, world, local);
    } else {
        status = MT_ENOMEM;
    }
    free(plain);
    free(k.world);
    free(k.end);
    return status;
}

static MT_CLONES void euler_block(const double *angles, size_t n, const int *axes, size_t count,
                                  double scale, double *out)
{
    for (size_t f0 = 0; f0 < n; f0 += BLOCK) {
        const size_t m = n - f0 < BLOCK ? n - f0 : BLOCK;
        double r[9][BLOCK], v[BLOCK], sn[BLOCK], cs[BLOCK];
        for (int e = 0; e < 9; e++)
            for (int f = 0; f < BLOCK; f++)
                r[e][f] = identity[e];
        for (size_t a = 0; a < count; a++) {
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

int mt_euler_to_matrices(const double *angles, size_t n, const int *axes, size_t count, double scale,
                         double *out)
{
    if (n == 0)
        return MT_OK;
    if (!out || (count > 0 && (!angles || !axes)))
        return MT_EINVAL;
    for (size_t a = 0; a < count; a++)
        if (axes[a] < MT_DOF_RX || axes[a] > MT_DOF_RZ)
            return MT_EINVAL;
    euler_block(angles, n, axes, count, scale, out);
    return MT_OK;
}

int mt_matrices_to_euler(const double *m, size_t n, const int *axes, double scale, double *angles)
{
    if (n > 0 && (!m || !axes || !angles))
        return MT_EINVAL;
    if (n == 0)
        return MT_OK;
    const int i = axes[0], j = axes[1], k = axes[2];
    if (i < MT_DOF_RX || i > MT_DOF_RZ || j < MT_DOF_RX || j > MT_DOF_RZ || k < MT_DOF_RX ||
        k > MT_DOF_RZ || i == j || j == k || i == k)
        return MT_EINVAL;
    /* R = R_k(c) R_j(b) R_i(a); e is the parity of the axis permutation. */
    const double e = (j - i + 3) % 3 == 1 ? 1.0 : -1.0;
    for (size_t f = 0; f < n; f++, m += 9, angles += 3) {
        /* atan2 against the cosine, not asin: accurate up to gimbal lock */
        angles[1] = atan2(-e * m[3 * k + i], hypot(m[3 * k + j], m[3 * k + k])) / scale;
        angles[0] = atan2(e * m[3 * k + j], m[3 * k + k]) / scale;
        angles[2] = atan2(e * m[3 * j + i], m[3 * i + i]) / scale;
    }
    return MT_OK;
}

int mt_rotations_to_quaternions(const double *m, size_t n, double *q)
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
