/*
 * kinematics.c - forward kinematics of joint trees over frames (ASF/AMC
 * semantics, see mtcore.h).
 *
 * Frames are independent: a call computes a range of them, so that several
 * threads can share one output.  The joints are visited parents first; a
 * joint's world rotation and end point are kept in scratch for its children.
 */
#include "clones.h"
#include "lanes.h"
#include "mtcore.h"

#include <stdlib.h>
#include <string.h>

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

/* Checks the channel tables of a tree: each joint's dofs of known kinds at columns of the values. */
static int check_channels(const double *values, size_t frames, size_t channels, size_t joints, const double *axis,
                          const size_t *dof_start, const int *dof_kind, const size_t *dof_column)
{
    if (!axis || !dof_start || (frames > 0 && channels > 0 && !values) ||
        (dof_start[joints] > 0 && (!dof_kind || !dof_column)))
        return MT_EINVAL;
    for (size_t c = 0; c < dof_start[joints]; c++)
        if (dof_kind[c] < MT_DOF_RX || dof_kind[c] > MT_DOF_L || dof_column[c] >= channels)
            return MT_EINVAL;
    for (size_t j = 0; j < joints; j++)
        if (dof_start[j] > dof_start[j + 1])
            return MT_EINVAL;
    return MT_OK;
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
    const long long *world_rows;       /* each joint's row of the world output (-1: none), or NULL: its own */
    size_t world_count;                /* the world output's rows a frame */
    double angle_scale;
    double *world; /* scratch: each joint's world rotation over the block (9 BLOCK values a joint) */
    double *end;   /* scratch: each joint's end point over the block (3 BLOCK values a joint) */
};

/* m turned on the left by the rotations about kinds[r] by angles[r BLOCK ..] (radians), r = 0 .. count-1 in
   turn: the sines and cosines of up to three channels in one pass over their lanes */
static MT_INLINE void turn_left(double *m, const double *angles, const int *kinds, int count)
{
    double sn[3 * BLOCK], cs[3 * BLOCK];
    sincos_lanes(angles, sn, cs, count * BLOCK);
    for (int r = 0; r < count; r++)
        rotate_left_n(m, kinds[r], sn + r * BLOCK, cs + r * BLOCK, BLOCK);
}

/* Lanes 0 .. n-1 of a quantity of `width` numbers (lanes[e BLOCK + f]) to frames f0 .. f0+n-1 of
   out, a frame's `rows` quantities side by side, this one at `row` */
static MT_INLINE void put_lanes(double *out, size_t rows, size_t row, size_t f0, size_t n, const double *lanes,
                                int width)
{
    for (size_t f = 0; f < n; f++)
        for (int e = 0; e < width; e++)
            out[(size_t)width * ((f0 + f) * rows + row) + (size_t)e] = lanes[e * BLOCK + f];
}

/* Frames f0 .. f0+n-1 (n <= BLOCK); lanes past n repeat the last frame and are not written. */
static MT_CLONES void fk_block(const struct fk *k, size_t f0, size_t n, double *positions,
                               double *world_out, double *local_out)
{
    const double *rows[BLOCK];
    for (int f = 0; f < BLOCK; f++)
        rows[f] = k->values + (f0 + ((size_t)f < n ? (size_t)f : n - 1)) * k->channels;
    for (size_t i = 0; i < k->joints; i++) {
        const size_t j = (size_t)k->order[i];
        double m[9 * BLOCK], t[3 * BLOCK] = {0}, stretch[BLOCK] = {0}, v[BLOCK], angles[3 * BLOCK];
        /* shifted: the joint has translation or stretch channels (most have none); the rotations
           of kinds[0 .. turns-1] by angles are yet to be applied, up to three at a time */
        int shifted = 0, kinds[3], turns = 0;
        spread_n(identity, 9, m, BLOCK);
        for (size_t c = k->dof_start[j]; c < k->dof_start[j + 1]; c++) {
            const size_t column = k->dof_column[c];
            const int kind = k->dof_kind[c];
            for (int f = 0; f < BLOCK; f++)
                v[f] = rows[f][column];
            shifted |= kind > MT_DOF_RZ;
            if (kind <= MT_DOF_RZ) {
                for (int f = 0; f < BLOCK; f++)
                    angles[turns * BLOCK + f] = v[f] * k->angle_scale;
                kinds[turns++] = kind;
                if (turns == 3) {
                    turn_left(m, angles, kinds, turns);
                    turns = 0;
                }
            } else if (kind <= MT_DOF_TZ) {
                for (int f = 0; f < BLOCK; f++)
                    t[(kind - MT_DOF_TX) * BLOCK + f] += v[f];
            } else {
                for (int f = 0; f < BLOCK; f++)
                    stretch[f] += v[f];
            }
        }
        if (turns)
            turn_left(m, angles, kinds, turns);
        const double *c9 = k->axis + 9 * j;
        double l[9 * BLOCK];
        if (k->plain[j])
            memcpy(l, m, sizeof l);
        else
            conjugate_n(c9, m, l, BLOCK);
        double *w = k->world + 9 * BLOCK * j, *p = k->end + 3 * BLOCK * j;
        const double *seg = k->segment + 3 * j, *dir = k->direction + 3 * j;
        if (k->parent[j] < 0) {
            memcpy(w, l, sizeof l);
            for (int e = 0; e < 3; e++)
                for (int f = 0; f < BLOCK; f++)
                    p[e * BLOCK + f] = seg[e] + t[e * BLOCK + f];
        } else {
            const size_t q = (size_t)k->parent[j];
            const double *up = k->world + 9 * BLOCK * q;
            mat_mul_n(up, l, w, BLOCK);
            double vec[3 * BLOCK];
            if (shifted)
                for (int e = 0; e < 3; e++)
                    for (int f = 0; f < BLOCK; f++)
                        vec[e * BLOCK + f] = seg[e] + dir[e] * stretch[f] + c9[3 * e] * t[f] +
                                             c9[3 * e + 1] * t[BLOCK + f] + c9[3 * e + 2] * t[2 * BLOCK + f];
            else
                spread_n(seg, 3, vec, BLOCK);
            const double *turn = k->parent_frame && k->parent_frame[j] ? up : w, *from = k->end + 3 * BLOCK * q;
            for (int e = 0; e < 3; e++)
                for (int f = 0; f < BLOCK; f++)
                    p[e * BLOCK + f] = from[e * BLOCK + f] + turn[3 * e * BLOCK + f] * vec[f] +
                                       turn[(3 * e + 1) * BLOCK + f] * vec[BLOCK + f] +
                                       turn[(3 * e + 2) * BLOCK + f] * vec[2 * BLOCK + f];
        }
        put_lanes(positions, k->joints, j, f0, n, p, 3);
        const long long row = k->world_rows ? k->world_rows[j] : (long long)j;
        if (world_out && row >= 0)
            put_lanes(world_out, k->world_count, (size_t)row, f0, n, w, 9);
        if (local_out)
            put_lanes(local_out, k->joints, j, f0, n, l, 9);
    }
}

int mt_forward_kinematics(const double *values, size_t frames, size_t channels, size_t joints,
                          const long long *parent, const long long *order, const double *axis,
                          const double *direction, const double *segment, const size_t *dof_start,
                          const int *dof_kind, const size_t *dof_column,
                          const unsigned char *parent_frame, double angle_scale, size_t begin,
                          size_t end, double *positions, double *world, double *local,
                          const long long *world_rows, size_t world_count)
{
    if (begin > end || end > frames)
        return MT_EINVAL;
    if (joints == 0 || begin == end)
        return MT_OK;
    if (!parent || !order || !direction || !segment || !positions ||
        check_channels(values, frames, channels, joints, axis, dof_start, dof_kind, dof_column) != MT_OK)
        return MT_EINVAL;
    if (world_rows)
        for (size_t j = 0; j < joints; j++)
            if (world_rows[j] < -1 || (world_rows[j] >= 0 && (size_t)world_rows[j] >= world_count))
                return MT_EINVAL;
    int status = check_tree(joints, parent, order);
    if (status != MT_OK)
        return status;
    struct fk k = {.values = values,
                   .channels = channels,
                   .joints = joints,
                   .parent = parent,
                   .order = order,
                   .axis = axis,
                   .direction = direction,
                   .segment = segment,
                   .dof_start = dof_start,
                   .dof_column = dof_column,
                   .dof_kind = dof_kind,
                   .parent_frame = parent_frame,
                   .world_rows = world_rows,
                   .world_count = world_rows ? world_count : joints,
                   .angle_scale = angle_scale};
    unsigned char *plain = malloc(joints);
    k.world = malloc(joints * 9 * BLOCK * sizeof *k.world);
    k.end = malloc(joints * 3 * BLOCK * sizeof *k.end);
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

/* out = a q b over lanes, a and b one quaternion for every lane (out may be q) */
static MT_INLINE void sandwich_n(const double *a, double q[4][BLOCK], const double *b, double out[4][BLOCK])
{
    for (int f = 0; f < BLOCK; f++) {
        const double w = q[0][f], x = q[1][f], y = q[2][f], z = q[3][f];
        const double mw = a[0] * w - a[1] * x - a[2] * y - a[3] * z, mx = a[0] * x + a[1] * w + a[2] * z - a[3] * y,
                     my = a[0] * y - a[1] * z + a[2] * w + a[3] * x, mz = a[0] * z + a[1] * y - a[2] * x + a[3] * w;
        out[0][f] = mw * b[0] - mx * b[1] - my * b[2] - mz * b[3];
        out[1][f] = mw * b[1] + mx * b[0] + my * b[3] - mz * b[2];
        out[2][f] = mw * b[2] - mx * b[3] + my * b[0] + mz * b[1];
        out[3][f] = mw * b[3] + mx * b[2] - my * b[1] + mz * b[0];
    }
}

enum { SPAN = 256 }; /* frames whose channels stay in cache while every chosen joint reads them */

static MT_CLONES void local_quaternions(const double *values, size_t frames, size_t channels, const size_t *dof_start,
                                        const int *dof_kind, const size_t *dof_column, double angle_scale,
                                        size_t count, const long long *chosen, const double *outer,
                                        const double *inner, double *before, float *out)
{
    for (size_t s0 = 0; s0 < frames; s0 += SPAN) {
        const size_t s1 = frames - s0 < SPAN ? frames : s0 + SPAN;
        for (size_t i = 0; i < count; i++) {
            const size_t j = (size_t)chosen[i];
            double *last = before + 4 * i;
            for (size_t f0 = s0; f0 < s1; f0 += BLOCK) {
                const size_t n = s1 - f0 < BLOCK ? s1 - f0 : BLOCK;
                double q[4][BLOCK], v[BLOCK], sn[BLOCK], cs[BLOCK];
                for (int f = 0; f < BLOCK; f++)
                    q[0][f] = 1, q[1][f] = q[2][f] = q[3][f] = 0;
                for (size_t c = dof_start[j]; c < dof_start[j + 1]; c++) {
                    if (dof_kind[c] > MT_DOF_RZ)
                        continue;
                    for (int f = 0; f < BLOCK; f++)
                        v[f] = values[(f0 + ((size_t)f < n ? (size_t)f : n - 1)) * channels + dof_column[c]] *
                               (angle_scale / 2);
                    sincos_lanes(v, sn, cs, BLOCK);
                    turn_quaternion_n(q[0], q[1], q[2], q[3], dof_kind[c], sn, cs, BLOCK);
                }
                sandwich_n(outer + 4 * i, q, inner + 4 * i, q);
                for (size_t f = 0; f < n; f++) {
                    double dot = 0;
                    for (int e = 0; e < 4; e++)
                        dot += q[e][f] * last[e];
                    const double sign = (f0 + f == 0 ? q[0][f] < 0 : dot < 0) ? -1.0 : 1.0;
                    float *to = out + 4 * (i * frames + f0 + f);
                    for (int e = 0; e < 4; e++)
                        last[e] = sign * q[e][f];
                    to[0] = (float)last[1], to[1] = (float)last[2], to[2] = (float)last[3], to[3] = (float)last[0];
                }
            }
        }
    }
}

int mt_local_quaternions(const double *values, size_t frames, size_t channels, size_t joints, const double *axis,
                         const size_t *dof_start, const int *dof_kind, const size_t *dof_column, double angle_scale,
                         size_t count, const long long *chosen, const double *turn, float *out)
{
    if (count == 0 || frames == 0)
        return MT_OK;
    if (joints == 0 || !chosen || !out ||
        check_channels(values, frames, channels, joints, axis, dof_start, dof_kind, dof_column) != MT_OK)
        return MT_EINVAL;
    for (size_t i = 0; i < count; i++)
        if (chosen[i] < 0 || (size_t)chosen[i] >= joints)
            return MT_EINVAL;
    /* L = C M C^T is the quaternion product c q_M c*; the turn T L is t c q_M c* */
    double *outer = malloc(12 * count * sizeof *outer), *inner = outer + 4 * count, *before = inner + 4 * count;
    if (outer == NULL)
        return MT_ENOMEM;
    for (size_t i = 0; i < count; i++) {
        double c[4], t[4] = {1, 0, 0, 0};
        matrix_quaternion(axis + 9 * (size_t)chosen[i], c);
        if (i == 0 && turn)
            matrix_quaternion(turn, t);
        outer[4 * i] = t[0] * c[0] - t[1] * c[1] - t[2] * c[2] - t[3] * c[3];
        outer[4 * i + 1] = t[0] * c[1] + t[1] * c[0] + t[2] * c[3] - t[3] * c[2];
        outer[4 * i + 2] = t[0] * c[2] - t[1] * c[3] + t[2] * c[0] + t[3] * c[1];
        outer[4 * i + 3] = t[0] * c[3] + t[1] * c[2] - t[2] * c[1] + t[3] * c[0];
        inner[4 * i] = c[0], inner[4 * i + 1] = -c[1], inner[4 * i + 2] = -c[2], inner[4 * i + 3] = -c[3];
    }
    local_quaternions(values, frames, channels, dof_start, dof_kind, dof_column, angle_scale, count, chosen, outer,
                      inner, before, out);
    free(outer);
    return MT_OK;
}
