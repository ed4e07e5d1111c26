/*
 * kinematics.c - forward kinematics of joint trees over frames (ASF/AMC
 * semantics, see mtcore.h).
 *
 * Frames are independent: a call computes a range of them, so that several
 * threads can share one output.  The joints are visited parents first; a
 * joint's world rotation and end point are kept in scratch for its children.
 */
#include "blocks.h"
#include "clones.h"
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
