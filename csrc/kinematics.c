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
    double *world; /* scratch: each joint's world rotation over the block (9 BLOCK values a joint) */
    double *end;   /* scratch: each joint's end point over the block (3 BLOCK values a joint) */
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
        double m[9 * BLOCK], t[3 * BLOCK] = {0}, stretch[BLOCK] = {0}, v[BLOCK], sn[BLOCK], cs[BLOCK];
        spread_n(identity, 9, m, BLOCK);
        for (size_t c = k->dof_start[j]; c < k->dof_start[j + 1]; c++) {
            const size_t column = k->dof_column[c];
            const int kind = k->dof_kind[c];
            for (int f = 0; f < BLOCK; f++)
                v[f] = rows[f][column];
            if (kind <= MT_DOF_RZ) {
                for (int f = 0; f < BLOCK; f++)
                    v[f] *= k->angle_scale;
                sincos_lanes(v, sn, cs, BLOCK);
                rotate_left_n(m, kind, sn, cs, BLOCK);
            } else if (kind <= MT_DOF_TZ) {
                for (int f = 0; f < BLOCK; f++)
                    t[(kind - MT_DOF_TX) * BLOCK + f] += v[f];
            } else {
                for (int f = 0; f < BLOCK; f++)
                    stretch[f] += v[f];
            }
        }
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
            for (int e = 0; e < 3; e++)
                for (int f = 0; f < BLOCK; f++)
                    vec[e * BLOCK + f] = seg[e] + dir[e] * stretch[f] + c9[3 * e] * t[f] + c9[3 * e + 1] * t[BLOCK + f] +
                                         c9[3 * e + 2] * t[2 * BLOCK + f];
            const double *turn = k->parent_frame && k->parent_frame[j] ? up : w, *from = k->end + 3 * BLOCK * q;
            for (int e = 0; e < 3; e++)
                for (int f = 0; f < BLOCK; f++)
                    p[e * BLOCK + f] = from[e * BLOCK + f] + turn[3 * e * BLOCK + f] * vec[f] +
                                       turn[(3 * e + 1) * BLOCK + f] * vec[BLOCK + f] +
                                       turn[(3 * e + 2) * BLOCK + f] * vec[2 * BLOCK + f];
        }
        for (size_t f = 0; f < n; f++) {
            const size_t at = (f0 + f) * k->joints + j;
            for (int e = 0; e < 3; e++)
                positions[3 * at + e] = p[e * BLOCK + f];
            for (int e = 0; e < 9; e++) {
                if (world_out)
                    world_out[9 * at + e] = w[e * BLOCK + f];
                if (local_out)
                    local_out[9 * at + e] = l[e * BLOCK + f];
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
