/*
 * retarget.c - a motion of one skeleton turned into channels of another
 * (see mtcore.h, mt_retarget).
 *
 * Frames are independent: a call computes a range of them, chunk by chunk.
 * Each chunk of source frames goes through mt_forward_kinematics into
 * scratch (world rotations and points), then every target joint, parents
 * first, takes the rotation its plan asks for, reduced to the rotations its
 * channels can make.  The matrix algebra and the Euler angles of joints
 * with three channels run BLOCK frames at a time (structure of arrays, so
 * that they vectorise, atan2 included); the rarer work (re-aiming a bone,
 * swivelling over a hinge, joints with one or two channels) runs frame by
 * frame in the lanes of a block.
 */
#include "clones.h"
#include "lanes.h"
#include "mtcore.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { CHUNK = 8 * BLOCK };

/* Below this sine the direction a channel aims is taken as lying along the channel's axis. */
static const double aim_floor = 1e-6;

/* The rotation by angle about coordinate axis `axis` (0, 1, 2). */
static void axis_rotation(int axis, double angle, double *out)
{
    const double c = cos(angle), s = sin(angle);
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    memcpy(out, identity, sizeof identity);
    out[3 * a + a] = c, out[3 * a + b] = -s;
    out[3 * b + a] = s, out[3 * b + b] = c;
}

/*
 * The smallest rotation taking the direction of u onto the direction of w:
 * R = I + [v]x + [v]x^2 / (1 + c), v = u x w, c = u . w for unit u and w; a
 * half turn about an axis normal to u when they are opposite.  The identity
 * when either is zero or not finite (nothing to aim at).
 */
static void smallest_rotation(const double *u0, const double *w0, double *out)
{
    const double nu = sqrt(dot3(u0, u0)), nw = sqrt(dot3(w0, w0));
    memcpy(out, identity, sizeof identity);
    if (!(nu > 0 && nw > 0 && isfinite(nu) && isfinite(nw)))
        return;
    double u[3] = {u0[0] / nu, u0[1] / nu, u0[2] / nu}, w[3] = {w0[0] / nw, w0[1] / nw, w0[2] / nw}, v[3];
    cross3(u, w, v);
    const double c = dot3(u, w);
    if (c < -1 + 1e-12) {
        /* the axis: u crossed with the coordinate axis least along it */
        const double a0 = fabs(u[0]), a1 = fabs(u[1]), a2 = fabs(u[2]);
        const double e[3] = {a0 <= a1 && a0 <= a2, a1 < a0 && a1 <= a2, a2 < a0 && a2 < a1};
        double n[3];
        cross3(u, e, n);
        const double nn = sqrt(dot3(n, n));
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                out[3 * i + k] = 2 * n[i] * n[k] / (nn * nn) - (i == k);
        return;
    }
    const double k = 1 / (1 + c);
    const double vx[9] = {0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0};
    double vx2[9];
    mat_mul(vx, vx, vx2);
    for (int e = 0; e < 9; e++)
        out[e] += vx[e] + vx2[e] * k;
}

/* The angle about unit axis e that turns d nearest to t (their parts normal to e); NaN when either part vanishes. */
static double aim_angle(const double *e, const double *d, const double *t)
{
    double dp[3], tp[3], x[3];
    const double de = dot3(d, e), te = dot3(t, e);
    for (int i = 0; i < 3; i++)
        dp[i] = d[i] - de * e[i], tp[i] = t[i] - te * e[i];
    const double nd = sqrt(dot3(dp, dp)), nt = sqrt(dot3(tp, tp)), nd0 = sqrt(dot3(d, d)), nt0 = sqrt(dot3(t, t));
    if (!(nd > aim_floor * nd0 && nt > aim_floor * nt0))
        return NAN;
    cross3(dp, tp, x);
    return atan2(dot3(x, e), dot3(dp, tp));
}

/* The angle about coordinate axis `axis` of m's twist about it (swing-twist decomposition). */
static double twist_angle(const double *m, int axis)
{
    double q[4];
    mt_matrices_to_quaternions(m, 1, q);
    return 2 * atan2(q[1 + axis], q[0]);
}

/* Full swivel above this bend between a joint's bone and its hinged child's, none below a fifth of it. */
static const double swivel_bend = 0.17364817766693033; /* sin 10 degrees */

/* out = the rotation by angle about unit axis u. */
static void turn_about(const double *u, double angle, double *out)
{
    const double c = cos(angle), s = sin(angle), k = 1 - c;
    out[0] = c + k * u[0] * u[0], out[1] = k * u[0] * u[1] - s * u[2], out[2] = k * u[0] * u[2] + s * u[1];
    out[3] = k * u[1] * u[0] + s * u[2], out[4] = c + k * u[1] * u[1], out[5] = k * u[1] * u[2] - s * u[0];
    out[6] = k * u[2] * u[0] - s * u[1], out[7] = k * u[2] * u[1] + s * u[0], out[8] = c + k * u[2] * u[2];
}

/*
 * Turns want (a joint's wanted world rotation) about its own bone (want
 * bone, bone its rest key vector) by the angle nearest to none that lets a
 * child with one rotation channel aim its bone (rest vector child_bone,
 * hinge axis hinge at rest, both in rest world axes) at direction goal: the
 * hinge axis must make with goal the angle it makes with the child's bone.
 * The turn fades out as the bend between the bones nears none, where any
 * turn serves and the best one is ill-defined.
 */
static void swivel(double *want, const double *bone, const double *child_bone, const double *hinge,
                   const double *goal)
{
    double d[3], n[3], a[3], g[3], side[3], perp[3];
    mat_vec(want, bone, d);
    mat_vec(want, hinge, n);
    mat_vec(want, child_bone, a);
    const double nd = sqrt(dot3(d, d)), nn = sqrt(dot3(n, n)), na = sqrt(dot3(a, a)), ng = sqrt(dot3(goal, goal));
    if (!(nd > 0 && nn > 0 && na > 0 && ng > 0))
        return;
    for (int e = 0; e < 3; e++)
        d[e] /= nd, n[e] /= nn, a[e] /= na, g[e] = goal[e] / ng;
    double across[3];
    cross3(d, g, across);
    const double bend = sqrt(dot3(across, across));
    const double weight = bend >= swivel_bend ? 1.0 : bend <= swivel_bend / 5 ? 0.0 : (bend / swivel_bend - 0.2) / 0.8;
    if (weight == 0)
        return;
    /* (R(d, psi) n) . g = n . a, with R(d, psi) n = (n.d) d + cos psi n_perp + sin psi (d x n_perp) */
    const double along = dot3(n, d);
    for (int e = 0; e < 3; e++)
        perp[e] = n[e] - along * d[e];
    cross3(d, perp, side);
    const double beta = dot3(perp, g), gamma = dot3(side, g), rho = hypot(beta, gamma);
    if (!(rho > 0))
        return;
    const double phi = atan2(gamma, beta), c = (dot3(n, a) - along * dot3(d, g)) / rho;
    const double spread = acos(c > 1 ? 1 : c < -1 ? -1 : c);
    double psi = remainder(phi - spread, 2 * pi);
    const double other = remainder(phi + spread, 2 * pi);
    if (fabs(other) < fabs(psi))
        psi = other;
    double r[9], turned[9];
    turn_about(d, weight * psi, r);
    mat_mul(r, want, turned);
    memcpy(want, turned, sizeof turned);
}

/* trace(x^T y): how near two rotations are (3 when equal). */
static double agreement(const double *x, const double *y)
{
    double s = 0;
    for (int e = 0; e < 9; e++)
        s += x[e] * y[e];
    return s;
}

/*
 * The angles of rotation channels about axes[0..count-1] (applied in that
 * order about fixed axes) that come nearest to m, and the rotation they
 * make (achieved).  `aim` (the joint's rest direction in m's frame, or
 * zero) says what matters most where the channels cannot make m: one
 * channel turns aim as near as it can to m aim, two channels turn it
 * exactly there when they can (of the two ways, the one nearer to m);
 * without an aim, one channel takes m's twist about its axis and two
 * channels the Euler angles of m with the missing axis between them,
 * dropped.
 */
static int reduce(const double *m, const int *axes, size_t count, const double *aim, double *angles,
                  double *achieved)
{
    if (count == 0) {
        memcpy(achieved, identity, sizeof identity);
        return MT_OK;
    }
    double t[3];
    mat_vec(m, aim, t);
    const int aims = dot3(aim, aim) > 0;
    if (count == 1) {
        const double e[3] = {axes[0] == 0, axes[0] == 1, axes[0] == 2};
        double a = aims ? aim_angle(e, aim, t) : NAN;
        angles[0] = isnan(a) ? twist_angle(m, axes[0]) : a;
        axis_rotation(axes[0], angles[0], achieved);
        return MT_OK;
    }
    const int i = axes[0], k = axes[1], j = 3 - i - k;
    if (i == k)
        return MT_EINVAL;
    const double e1[3] = {i == 0, i == 1, i == 2}, e2[3] = {k == 0, k == 1, k == 2};
    /* solve e2 . R1(a) aim = e2 . t for a (rotation about e2 keeps that part), then b about e2 */
    double perp[3], side[3];
    const double along = dot3(aim, e1);
    for (int n = 0; n < 3; n++)
        perp[n] = aim[n] - along * e1[n];
    cross3(e1, perp, side);
    const double beta = dot3(e2, perp), gamma = dot3(e2, side), rho = hypot(beta, gamma);
    const double want = dot3(e2, t) - along * dot3(e2, e1);
    if (aims && rho > aim_floor * sqrt(dot3(aim, aim))) {
        const double phi = atan2(gamma, beta), c = want / rho;
        const double spread = acos(c > 1 ? 1 : c < -1 ? -1 : c);
        double best = -INFINITY;
        for (int sign = -1; sign <= 1; sign += 2) {
            const double a = phi + sign * spread;
            double r1[9], r2[9], r[9], w[3];
            axis_rotation(i, a, r1);
            mat_vec(r1, aim, w);
            double b = aim_angle(e2, w, t);
            if (isnan(b))
                b = 0;
            axis_rotation(k, b, r2);
            mat_mul(r2, r1, r);
            const double near = agreement(r, m);
            if (near > best) {
                best = near;
                angles[0] = a, angles[1] = b;
                memcpy(achieved, r, sizeof r);
            }
        }
        return MT_OK;
    }
    /* no aim: Euler angles about i, j, k (extrinsic), the middle one dropped */
    const int full[3] = {i, j, k};
    double three[3], r1[9], r2[9];
    int status = mt_matrices_to_euler(m, 1, full, 0, 1.0, three);
    angles[0] = three[0], angles[1] = three[2];
    axis_rotation(i, angles[0], r1);
    axis_rotation(k, angles[1], r2);
    mat_mul(r2, r1, achieved);
    return status;
}

/* Below this the first and last Euler axes count as aligned (as in rotation.c). */
static const double gimbal_lock = 16 * DBL_EPSILON;

/*
 * cond ? a : b by bit masks.  GCC keeps floating-point selects as branches
 * (they might trap, by its default -ftrapping-math), which stops a loop from
 * vectorising; selects of bits do not.
 */
static MT_INLINE double pick(int cond, double a, double b)
{
    union {
        double d;
        unsigned long long u;
    } x = {a}, y = {b}, out;
    const unsigned long long mask = -(unsigned long long)(cond != 0);
    out.u = (x.u & mask) | (y.u & ~mask);
    return out.d;
}

/*
 * atan2 of BLOCK pairs, branch-free so that it vectorises: the octant by
 * selects, then atan of a ratio in [0, 1] by Cephes' rational approximation
 * (Moshier), reduced by pi/4 above 0.66; within a few ulp of libm's.  NaN
 * in either gives NaN; atan2(+-0, x) follows the signs as libm's does.
 */
static MT_INLINE void atan2_block(const double *y, const double *x, double *out)
{
    static const double p0 = -8.750608600031904122785e-1, p1 = -1.615753718733365076637e1,
                        p2 = -7.500855792314704667340e1, p3 = -1.228866684490136173410e2,
                        p4 = -6.485021904942025371773e1, q0 = 2.485846490142306297962e1,
                        q1 = 1.650270098316988542046e2, q2 = 4.328810604912902668951e2,
                        q3 = 4.853903996359136964868e2, q4 = 1.945506571482613964425e2,
                        more_bits = 6.123233995736765886130e-17;
    for (int b = 0; b < BLOCK; b++) {
        const double ax = fabs(x[b]), ay = fabs(y[b]);
        const int swap = ay > ax;
        const double num = pick(swap, ax, ay), den = pick(swap, ay, ax);
        const double ratio = num / pick(den > 0, den, 1.0), reduced = (ratio - 1) / (ratio + 1);
        const int high = ratio > 0.66;
        const double t = pick(high, reduced, ratio), z = t * t;
        const double p = (((p0 * z + p1) * z + p2) * z + p3) * z + p4;
        const double q = ((((z + q0) * z + q1) * z + q2) * z + q3) * z + q4;
        const double base = t + t * (z * p / q) + pick(high, pi / 4 + 0.5 * more_bits, 0.0);
        const double octant = pick(swap, (pi / 2 - base) + more_bits, base);
        const double half = pick(copysign(1.0, x[b]) < 0, (pi - octant) + 2 * more_bits, octant);
        out[b] = pick((x[b] != x[b]) | (y[b] != y[b]), x[b] + y[b], copysign(half, y[b]));
    }
}

/*
 * Extrinsic Euler angles about axes (Tait-Bryan or proper) of block
 * matrices r, as mt_matrices_to_euler computes them (see rotation.c).
 */
static MT_INLINE void euler_block(const double *r, const int *axes, double *angles)
{
    const int i = axes[0], j = axes[1], k = 3 - i - j, proper = axes[2] == i;
    const double e = (j - i + 3) % 3 == 1 ? 1.0 : -1.0;
    const int o = proper ? k : i;
    const double f = proper ? e : -e;
    double by[BLOCK], bx[BLOCK], y[BLOCK], x[BLOCK], ay[BLOCK], ax[BLOCK], squares[BLOCK], root[BLOCK];
    for (int b = 0; b < BLOCK; b++) {
        const double u = proper ? r[(3 * i + j) * BLOCK + b] : r[(3 * k + j) * BLOCK + b], v = proper ? r[(3 * i + k) * BLOCK + b] : r[(3 * k + k) * BLOCK + b];
        squares[b] = u * u + v * v;
    }
    for (int b = 0; b < BLOCK; b++) /* alone: sqrt may set errno, which keeps a loop from vectorising */
        root[b] = sqrt(squares[b]);
    for (int b = 0; b < BLOCK; b++) {
        const double rki = r[(3 * k + i) * BLOCK + b], rji = r[(3 * j + i) * BLOCK + b], rii = r[(3 * i + i) * BLOCK + b];
        by[b] = proper ? root[b] : -e * rki;
        bx[b] = proper ? rii : root[b];
        const double yb = proper ? rji : e * rji, xb = proper ? -e * rki : rii;
        /* (cos c, sin c) times cos b: a's atan2 below needs their direction only */
        const int lock = xb * xb + yb * yb <= gimbal_lock * gimbal_lock;
        const double cc = pick(lock, 1.0, xb), sc = pick(lock, 0.0, yb);
        ay[b] = -e * (cc * r[(3 * j + k) * BLOCK + b] + f * sc * r[(3 * o + k) * BLOCK + b]);
        ax[b] = cc * r[(3 * j + j) * BLOCK + b] + f * sc * r[(3 * o + j) * BLOCK + b];
        y[b] = pick(lock, 0.0, yb), x[b] = pick(lock, 1.0, xb);
    }
    atan2_block(ay, ax, angles);
    atan2_block(by, bx, angles + BLOCK);
    atan2_block(y, x, angles + 2 * BLOCK);
}

/* Checks a tree's tables: sizes, kinds, columns, and an order that visits parents first. */
static int check_tree(const struct mt_tree *tree)
{
    if (!tree || !tree->parent || !tree->order || !tree->axis || !tree->dof_start ||
        (tree->dof_start[tree->joints] > 0 && (!tree->dof_kind || !tree->dof_column)))
        return MT_EINVAL;
    for (size_t c = 0; c < tree->dof_start[tree->joints]; c++)
        if (tree->dof_kind[c] < MT_DOF_RX || tree->dof_kind[c] > MT_DOF_L || tree->dof_column[c] >= tree->channels)
            return MT_EINVAL;
    unsigned char *seen = calloc(tree->joints ? tree->joints : 1, 1);
    if (!seen)
        return MT_ENOMEM;
    int status = MT_OK;
    for (size_t n = 0; n < tree->joints && status == MT_OK; n++) {
        const long long j = tree->order[n];
        if (j < 0 || (size_t)j >= tree->joints || seen[j] || tree->dof_start[j] > tree->dof_start[j + 1])
            status = MT_EINVAL;
        else if (tree->parent[j] >= 0 && ((size_t)tree->parent[j] >= tree->joints || !seen[tree->parent[j]]))
            status = MT_EINVAL;
        else
            seen[j] = 1;
    }
    free(seen);
    return status;
}

/* A target joint's rotation channels, worked out once per call. */
struct channels {
    size_t count;      /* 0 to 3 */
    int axes[3];       /* in the order the tree applies them */
    size_t columns[3]; /* of a frame's row of target values */
    int plain;         /* its axis frame C is the identity */
};

static int rotation_channels(const struct mt_tree *tree, size_t j, struct channels *out)
{
    out->count = 0;
    for (size_t c = tree->dof_start[j]; c < tree->dof_start[j + 1]; c++)
        if (tree->dof_kind[c] <= MT_DOF_RZ) {
            if (out->count == 3)
                return MT_EINVAL;
            out->axes[out->count] = tree->dof_kind[c];
            out->columns[out->count++] = tree->dof_column[c];
        }
    const int *a = out->axes;
    if ((out->count >= 2 && a[0] == a[1]) || (out->count == 3 && a[1] == a[2]))
        return MT_EINVAL;
    out->plain = memcmp(tree->axis + 9 * j, identity, sizeof identity) == 0;
    return MT_OK;
}

/* A (p_b - p_a): the direction between two source points, in target axes. */
static void source_direction(const double *align, const double *points, long long a, long long b, double *out)
{
    double d[3];
    for (int e = 0; e < 3; e++)
        d[e] = points[3 * b + e] - points[3 * a + e];
    mat_vec(align, d, out);
}

struct job {
    const struct mt_tree *target;
    const struct mt_retarget_plan *plan;
    const struct channels *channels; /* per target joint */
    size_t sources;
    int plain_align;                /* A is the identity */
    const double *unit;             /* the identity over the block: what a root's rotations start from */
    const double **global;          /* each target joint's world rotation over the block: its store or its parent's */
    double *store;                  /* scratch: the world rotations of mapped joints (9 BLOCK values a joint) */
};

/*
 * Frames f0 .. f0+n-1 of a chunk (n <= BLOCK): world and points hold the
 * chunk's source FK, frame by frame; lanes past n repeat the last frame and
 * are not written.
 */
static MT_CLONES int retarget_block(const struct job *k, const double *world, const double *points, size_t f0,
                                    size_t n, double *out)
{
    const struct mt_tree *target = k->target;
    const struct mt_retarget_plan *plan = k->plan;
    const size_t js = k->sources;
    double *rows[BLOCK];
    const double *wsrc[BLOCK], *psrc[BLOCK];
    for (int f = 0; f < BLOCK; f++) {
        const size_t lane = f0 + ((size_t)f < n ? (size_t)f : n - 1);
        rows[f] = out + lane * target->channels;
        wsrc[f] = world + lane * js * 9;
        psrc[f] = points + lane * js * 3;
    }
    for (size_t i = 0; i < target->joints; i++) {
        const size_t j = (size_t)target->order[i];
        const long long p = target->parent[j], s = plan->follow[j];
        const double *up = p >= 0 ? k->global[p] : k->unit;
        const struct channels *ch = k->channels + j;
        if (s < 0) {
            k->global[j] = up; /* its world rotation is its parent's */
            for (size_t c = 0; c < ch->count; c++)
                for (size_t f = 0; f < n; f++)
                    rows[f][ch->columns[c]] = 0.0;
            continue;
        }
        double *g = k->store + 9 * BLOCK * j, w[9 * BLOCK], local[9 * BLOCK], m[9 * BLOCK];
        double *want = g; /* three channels make it exactly; fewer overwrite it below */
        k->global[j] = g;
        for (int f = 0; f < BLOCK; f++)
            lane_set(w, 9, f, wsrc[f] + 9 * s, BLOCK);
        if (k->plain_align) {
            mat_mul_const_n(w, plan->correction + 9 * j, want, BLOCK);
        } else {
            mat_mul_const_n(w, plan->correction + 9 * j, local, BLOCK);
            const_mat_mul_n(plan->align, local, want, BLOCK);
        }
        const long long a = plan->key_points[2 * j], b = plan->key_points[2 * j + 1];
        const long long h = plan->hinge[j];
        const int refit = plan->refit[j] && a >= 0 && b >= 0;
        const int hinged = h >= 0 && ch->count == 3 && k->channels[h].count == 1 && plan->key_points[2 * h] >= 0 &&
                           plan->key_points[2 * h + 1] >= 0;
        if (refit || hinged) {
            for (int f = 0; f < BLOCK; f++) {
                double x[9], turned[9];
                lane_get(want, 9, f, x, BLOCK);
                if (refit) {
                    double u[3], v[3], fix[9];
                    source_direction(plan->align, psrc[f], a, b, u);
                    mat_vec(x, plan->key_vector + 3 * j, v);
                    smallest_rotation(v, u, fix);
                    mat_mul(fix, x, turned);
                    memcpy(x, turned, sizeof turned);
                }
                if (hinged) {
                    double goal[3], hinge[3];
                    const double *c9 = target->axis + 9 * h;
                    for (int e = 0; e < 3; e++)
                        hinge[e] = c9[3 * e + k->channels[h].axes[0]];
                    source_direction(plan->align, psrc[f], plan->key_points[2 * h], plan->key_points[2 * h + 1], goal);
                    swivel(x, plan->key_vector + 3 * j, plan->aim + 3 * h, hinge, goal);
                }
                lane_set(want, 9, f, x, BLOCK);
            }
        }
        const double *c9 = target->axis + 9 * j;
        if (ch->plain) {
            mat_tmul_n(up, want, m, BLOCK);
        } else { /* C^T (U^T W) C */
            const double ct[9] = {c9[0], c9[3], c9[6], c9[1], c9[4], c9[7], c9[2], c9[5], c9[8]};
            mat_tmul_n(up, want, local, BLOCK);
            conjugate_n(ct, local, m, BLOCK);
        }
        if (ch->count == 3) {
            double angles[3 * BLOCK];
            euler_block(m, ch->axes, angles);
            for (size_t c = 0; c < 3; c++)
                for (size_t f = 0; f < n; f++)
                    rows[f][ch->columns[c]] = angles[c * BLOCK + f] / target->angle_scale;
            continue;
        }
        double aim[3];
        const double *rest = plan->aim + 3 * j;
        for (int e = 0; e < 3; e++)
            aim[e] = c9[e] * rest[0] + c9[3 + e] * rest[1] + c9[6 + e] * rest[2];
        for (int f = 0; f < BLOCK; f++) {
            double x[9], angles[3], achieved[9], cm[9], turn[9], u[9], gf[9];
            lane_get(m, 9, f, x, BLOCK);
            int status = reduce(x, ch->axes, ch->count, aim, angles, achieved);
            if (status != MT_OK)
                return status;
            if ((size_t)f < n)
                for (size_t c = 0; c < ch->count; c++)
                    rows[f][ch->columns[c]] = angles[c] / target->angle_scale;
            mat_mul(c9, achieved, cm);
            mat_mult(cm, c9, turn);
            lane_get(up, 9, f, u, BLOCK);
            mat_mul(u, turn, gf);
            lane_set(g, 9, f, gf, BLOCK);
        }
    }
    return MT_OK;
}

int mt_retarget(const double *values, size_t frames, const struct mt_tree *source, const struct mt_tree *target,
                const struct mt_retarget_plan *plan, size_t begin, size_t end, double *out)
{
    if (begin > end || end > frames || !source || !target || !plan)
        return MT_EINVAL;
    if (begin == end || target->joints == 0)
        return MT_OK;
    if (!out || !plan->follow || !plan->correction || !plan->key_points || !plan->key_vector || !plan->refit ||
        !plan->hinge || !plan->aim || source->joints == 0 || (source->channels > 0 && !values) || !target->axis ||
        !(target->angle_scale > 0))
        return MT_EINVAL;
    int status = check_tree(source);
    if (status == MT_OK)
        status = check_tree(target);
    if (status != MT_OK)
        return status;
    const size_t js = source->joints, jt = target->joints;
    struct channels *channels = malloc(jt * sizeof *channels);
    double *points = malloc(CHUNK * js * 3 * sizeof *points);
    double *world = malloc(CHUNK * js * 9 * sizeof *world);
    double *store = malloc(jt * 9 * BLOCK * sizeof *store), unit[9 * BLOCK];
    const double **global = malloc(jt * sizeof *global);
    spread_n(identity, 9, unit, BLOCK);
    if (!channels || !points || !world || !store || !global)
        status = MT_ENOMEM;
    for (size_t j = 0; j < jt && status == MT_OK; j++) {
        const long long *key = plan->key_points + 2 * j;
        if (plan->follow[j] >= (long long)js || key[0] >= (long long)js || key[1] >= (long long)js ||
            plan->hinge[j] >= (long long)jt)
            status = MT_EINVAL;
        else
            status = rotation_channels(target, j, channels + j);
    }
    const struct job k = {target, plan, channels, js, memcmp(plan->align, identity, sizeof identity) == 0, unit, global, store};
    for (size_t c0 = begin; c0 < end && status == MT_OK; c0 += CHUNK) {
        const size_t n = end - c0 < CHUNK ? end - c0 : CHUNK;
        status = mt_forward_kinematics(values + c0 * source->channels, n, source->channels, js, source->parent,
                                       source->order, source->axis, source->direction, source->segment,
                                       source->dof_start, source->dof_kind, source->dof_column,
                                       source->parent_frame, source->angle_scale, 0, n, points, world, NULL, NULL, 0);
        for (size_t f0 = 0; f0 < n && status == MT_OK; f0 += BLOCK)
            status = retarget_block(&k, world, points, f0, n - f0 < BLOCK ? n - f0 : BLOCK, out + c0 * target->channels);
    }
    free(channels);
    free(points);
    free(world);
    free(store);
    free(global);
    return status;
}
