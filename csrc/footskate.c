/*
 * footskate.c - footskate cleanup of legs over frames (Kovar, Schreiner &
 * Gleicher, SCA 2002), see mtcore.h.
 *
 * A leg is four joints turning thigh, shin, foot and toes.  Per frame and leg
 * the kernels rebuild the leg from its hip point, its hip's parent rotation
 * and its channels (pose_block), and solve it analytically; frames interact
 * only through the plants' targets (phase 1, in frame order), the blending
 * of adjustments around constraints (phase 2), the root's smoothing (phase
 * 3) and the lifting of a sinking foot (phase 5).  The per-frame work runs
 * BLOCK frames side by side, each quantity an array over them (lanes.h), so
 * that it vectorises.  The Python twin in tests/twins/footskate.py computes
 * the same, phase by phase, in numpy.
 */
#include "clones.h"
#include "lanes.h"
#include "mtcore.h"
#include "speed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { HEEL = 0, BALL = 1 };

/* The rotation vector (angle in [0, pi]) of a rotation. */
static void rotvec_of(const double *m, double *v)
{
    const double w[3] = {m[7] - m[5], m[2] - m[6], m[3] - m[1]};
    const double s = norm3(w) / 2, c = (m[0] + m[4] + m[8] - 1) / 2, angle = atan2(s, c);
    const int small = s < 1e-6;
    if (c < -0.99 && !small) { /* the axis from the symmetric part, its sign from the antisymmetric one */
        double b[9], best = -1, axis[3] = {0, 0, 0};
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                b[3 * i + k] = (m[3 * i + k] + m[3 * k + i]) / 2 - (i == k ? c : 0.0);
        for (int k = 0; k < 3; k++) {
            const double col[3] = {b[k], b[3 + k], b[6 + k]}, n = norm3(col);
            if (n > best)
                best = n, axis[0] = col[0], axis[1] = col[1], axis[2] = col[2];
        }
        unit3(axis, axis);
        const double sign = dot3(axis, w) < 0 ? -1.0 : 1.0;
        for (int e = 0; e < 3; e++)
            v[e] = sign * axis[e] * angle;
        return;
    }
    const double factor = small ? 0.5 + angle * angle / 12 : angle / (2 * s);
    for (int e = 0; e < 3; e++)
        v[e] = w[e] * factor;
}

/* whole turns nearest to x / 2 pi; below 3 (0.48 turn) that is 0, the common case, without the call */
static MT_INLINE double round_turns(double x)
{
    return fabs(x) < 3.0 ? 0.0 : nearbyint(x / (2 * pi));
}

/* angle plus the whole turns that bring it nearest to ref */
static MT_INLINE double wrap_near(double angle, double ref)
{
    return angle + 2 * pi * round_turns(ref - angle);
}

static MT_INLINE double wrap(double angle)
{
    return angle - 2 * pi * round_turns(angle);
}

/* sqrt(x^2 + y^2) without hypot's care for overflow, which costs a call: the arguments here are
 * coordinates of unit vectors and of a human's limbs, far from the limits of a double */
static MT_INLINE double length2(double x, double y)
{
    return sqrt(x * x + y * y);
}

static MT_INLINE double clip(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

static double smoothstep(double x)
{
    x = clip(x, 0.0, 1.0);
    return x * x * (3 - 2 * x);
}

/* ---------------------------------------------------------------- joints */

static int channels(const struct mt_leg *leg, int j)
{
    int n = 0;
    while (n < 3 && leg->axes[j][n] >= 0)
        n++;
    return n;
}

static int is_identity(const double *m)
{
    return m[0] == 1 && m[1] == 0 && m[2] == 0 && m[3] == 0 && m[4] == 1 && m[5] == 0 && m[6] == 0 && m[7] == 0 &&
           m[8] == 1;
}

/* L = C M C^T of joint j, M its channels' rotations (given by the sines and cosines of their angles,
 * channel c's at c n), each about a fixed axis after the ones before: C M built by turning C's
 * columns, the last first. */
static MT_INLINE void local_rotation_of_n(const struct mt_leg *leg, int j, const double *sines, const double *cosines,
                                          double *out, int n)
{
    const int count = channels(leg, j);
    if (is_identity(leg->axis[j])) {
        spread_n(identity, 9, out, n);
        for (int c = 0; c < count; c++)
            rotate_left_n(out, leg->axes[j][c], sines + c * n, cosines + c * n, n);
        return;
    }
    if (count == 1) { /* C R C^T is the turn about C's column of the channel's axis: Rodrigues, no products */
        const double *c = leg->axis[j];
        const int a = leg->axes[j][0];
        const double u[3] = {c[a], c[3 + a], c[6 + a]};
        double axis[3 * BLOCK];
        spread_n(u, 3, axis, n);
        about_cs_n(axis, cosines, sines, out, n);
        return;
    }
    double m[9 * BLOCK], cb[9 * BLOCK];
    spread_n(leg->axis[j], 9, cb, n);
    memcpy(m, cb, 9 * (size_t)n * sizeof *m);
    for (int c = count - 1; c >= 0; c--)
        rotate_right_n(m, leg->axes[j][c], sines + c * n, cosines + c * n, n);
    mat_mult_n(m, cb, out, n);
}

static void local_rotation(const struct mt_leg *leg, int j, const double *angles, double *out)
{
    double sines[3], cosines[3];
    for (int c = 0; c < channels(leg, j); c++)
        sines[c] = sin(angles[c]), cosines[c] = cos(angles[c]);
    local_rotation_of_n(leg, j, sines, cosines, out, 1);
}

/*
 * Angles about fixed axes (i, j, k) applying in order, M = R_k(c) R_j(b) R_i(a),
 * of the rotations m (proper Euler when k = i): of the two solutions, the one
 * nearest ref, each angle whole turns from it.  b and c come from column i of
 * m, a from row j of R_last(-c) m, which is row j of R_i(a); at gimbal lock c
 * is ref's and a makes up the rest.
 */
static MT_INLINE void euler_nearest_n(const double *m, const int *axes, const double *ref, double *out, int n)
{
    const int i = axes[0], j = axes[1], proper = axes[2] == i, k = proper ? 3 - i - j : axes[2];
    const int last = proper ? i : k, p = mixed_first(last), q = mixed_second(last);
    const double eps = (j - i + 3) % 3 == 1 ? 1.0 : -1.0;
    double h[BLOCK], by[BLOCK], bx[BLOCK], cy[BLOCK], cx[BLOCK], a[BLOCK], b[BLOCK], c[BLOCK];
    double cc[BLOCK], sc[BLOCK], ay[BLOCK], ax[BLOCK];
#define M(r, col) m[(3 * (r) + (col)) * n + l]
    int locked = 0;
    for (int l = 0; l < n; l++) {
        h[l] = proper ? length2(M(j, i), M(k, i)) : length2(M(i, i), M(j, i));
        by[l] = proper ? h[l] : -eps * M(k, i), bx[l] = proper ? M(i, i) : h[l];
        cy[l] = proper ? M(j, i) : eps * M(j, i), cx[l] = proper ? -eps * M(k, i) : M(i, i);
        /* the cosine and sine of c, unless locked */
        cc[l] = cx[l] / h[l], sc[l] = cy[l] / h[l];
        locked |= h[l] < 1e-9;
    }
    atan2_lanes(by, bx, b, n);
    atan2_lanes(cy, cx, c, n);
    if (locked) {
        double sn[BLOCK], cs[BLOCK];
        for (int l = 0; l < n; l++)
            c[l] = h[l] < 1e-9 ? ref[2 * n + l] : c[l];
        sincos_lanes(c, sn, cs, n);
        for (int l = 0; l < n; l++)
            if (h[l] < 1e-9)
                cc[l] = cs[l], sc[l] = sn[l];
    }
    for (int l = 0; l < n; l++) { /* row j of R_last(-c) m: rows p' = c p + s q, q' = -s p + c q */
        const double rj = j == p ? cc[l] * M(p, j) + sc[l] * M(q, j) : -sc[l] * M(p, j) + cc[l] * M(q, j);
        const double rk = j == p ? cc[l] * M(p, k) + sc[l] * M(q, k) : -sc[l] * M(p, k) + cc[l] * M(q, k);
        ay[l] = -eps * rk, ax[l] = rj;
    }
#undef M
    atan2_lanes(ay, ax, a, n);
    for (int l = 0; l < n; l++) {
        const double r0 = ref[l], r1 = ref[n + l], r2 = ref[2 * n + l];
        const double first[3] = {wrap_near(a[l], r0), wrap_near(b[l], r1), wrap_near(c[l], r2)};
        const double second[3] = {wrap_near(a[l] + pi, r0), wrap_near((proper ? 0.0 : pi) - b[l], r1),
                                  wrap_near(c[l] + pi, r2)};
        const double d1 = (first[0] - r0) * (first[0] - r0) + (first[1] - r1) * (first[1] - r1) +
                          (first[2] - r2) * (first[2] - r2);
        const double d2 = (second[0] - r0) * (second[0] - r0) + (second[1] - r1) * (second[1] - r1) +
                          (second[2] - r2) * (second[2] - r2);
        const int pick = d2 < d1 && !(h[l] < 1e-9);
        for (int e = 0; e < 3; e++)
            out[e * n + l] = pick ? second[e] : first[e];
    }
}

/*
 * The angles (ref, out: 3 over the lanes) of joint j nearest to the wanted
 * local rotations that its channels can take: three give them exactly; two
 * turn the body vectors aim where wanted turns them; one turns aim as near
 * as its axis allows; none keep ref.  Angles are whole turns from ref.  With
 * one or two channels, sines and cosines (2 over the lanes) receive those of
 * the angles found (for local_rotation_of_n).
 */
static MT_INLINE void realize_n(const struct mt_leg *leg, int j, const double *wanted, const double *aim,
                                const double *ref, double *out, double *sines, double *cosines, int n)
{
    const int count = channels(leg, j);
    memcpy(out, ref, 3 * (size_t)n * sizeof *out);
    if (count == 0)
        return;
    double c[9 * BLOCK];
    spread_n(leg->axis[j], 9, c, n);
    if (count == 3) {
        double m[9 * BLOCK];
        mat_tmul_n(c, wanted, m, n);
        mat_mul_n(m, c, m, n);
        euler_nearest_n(m, leg->axes[j], ref, out, n);
        return;
    }
    double p[3 * BLOCK], q[3 * BLOCK], y[BLOCK], x[BLOCK], h[BLOCK], angle[BLOCK];
    mat_tvec_n(c, aim, p, n);
    unit_n(p, p, n);
    mat_vec_n(wanted, aim, q, n);
    mat_tvec_n(c, q, q, n);
    unit_n(q, q, n);
    if (count == 1) {
        const int axis = leg->axes[j][0];
        const double e[3] = {axis == 0, axis == 1, axis == 2};
        double pp[3 * BLOCK], qq[3 * BLOCK], nn[3 * BLOCK];
        perpendicular_n(p, e, pp, n);
        perpendicular_n(q, e, qq, n);
        cross_n(pp, qq, nn, n);
        for (int l = 0; l < n; l++) {
            y[l] = e[0] * nn[l] + e[1] * nn[n + l] + e[2] * nn[2 * n + l];
            x[l] = pp[l] * qq[l] + pp[n + l] * qq[n + l] + pp[2 * n + l] * qq[2 * n + l];
            h[l] = length2(x[l], y[l]);
        }
        atan2_lanes(y, x, angle, n);
        for (int l = 0; l < n; l++) {
            out[l] = wrap_near(angle[l], ref[l]);
            sines[l] = h[l] > 0 ? y[l] / h[l] : 0.0, cosines[l] = h[l] > 0 ? x[l] / h[l] : 1.0;
        }
        return;
    }
    const int ai = leg->axes[j][0], aj = leg->axes[j][1];
    const double ej[3] = {aj == 0, aj == 1, aj == 2};
    const double ei[3] = {ai == 0, ai == 1, ai == 2};
    double eip[3 * BLOCK], big_a[BLOCK], big_b[BLOCK], rho[BLOCK], kappa[BLOCK], base[BLOCK], spread[BLOCK];
    spread_n(ei, 3, eip, n);
    cross_n(eip, p, eip, n);
    int flat = 0;
    for (int l = 0; l < n; l++) {
        big_a[l] = p[aj * n + l], big_b[l] = eip[aj * n + l];
        rho[l] = length2(big_a[l], big_b[l]);
        kappa[l] = clip(q[aj * n + l] / rho[l], -1.0, 1.0);
        flat |= !(rho[l] > tiny);
    }
    atan2_lanes(big_b, big_a, base, n);
    acos_n(kappa, spread, n);
    /* sines and cosines of base +- spread by the angle sums, from base's (B, A) / rho and spread's cosine */
    double best[6][BLOCK] = {{0}}, cost[BLOCK] = {0}; /* a, b, sin a, cos a, sin b, cos b */
    for (int s = 0; s < 2; s++) {
        double v[3 * BLOCK], rp[3 * BLOCK], qp[3 * BLOCK], nn[3 * BLOCK], sa[BLOCK], ca[BLOCK], a[BLOCK], b[BLOCK];
        const double sign = s == 0 ? 1.0 : -1.0;
        for (int l = 0; l < n; l++) {
            const double cb = big_a[l] / rho[l], sb = big_b[l] / rho[l], ss = sqrt(1 - kappa[l] * kappa[l]);
            a[l] = wrap_near(base[l] + sign * spread[l], ref[l]);
            sa[l] = sb * kappa[l] + sign * cb * ss, ca[l] = cb * kappa[l] - sign * sb * ss;
        }
        memcpy(v, p, 3 * (size_t)n * sizeof *v);
        rotate_vector_n(v, ai, sa, ca, n);
        perpendicular_n(v, ej, rp, n);
        perpendicular_n(q, ej, qp, n);
        cross_n(rp, qp, nn, n);
        for (int l = 0; l < n; l++) {
            y[l] = ej[0] * nn[l] + ej[1] * nn[n + l] + ej[2] * nn[2 * n + l];
            x[l] = rp[l] * qp[l] + rp[n + l] * qp[n + l] + rp[2 * n + l] * qp[2 * n + l];
            h[l] = length2(x[l], y[l]);
        }
        atan2_lanes(y, x, b, n);
        for (int l = 0; l < n; l++) {
            b[l] = wrap_near(b[l], ref[n + l]);
            const double d = (a[l] - ref[l]) * (a[l] - ref[l]) + (b[l] - ref[n + l]) * (b[l] - ref[n + l]);
            if (s == 0 || d < cost[l]) {
                best[0][l] = a[l], best[1][l] = b[l], best[2][l] = sa[l], best[3][l] = ca[l];
                best[4][l] = h[l] > 0 ? y[l] / h[l] : 0.0, best[5][l] = h[l] > 0 ? x[l] / h[l] : 1.0;
                cost[l] = d;
            }
        }
    }
    for (int l = 0; l < n; l++) {
        out[l] = best[0][l], out[n + l] = best[1][l];
        sines[l] = best[2][l], cosines[l] = best[3][l], sines[n + l] = best[4][l], cosines[n + l] = best[5][l];
    }
    if (flat) { /* aim along the first axis: nothing to turn, the angles kept */
        double sn[2 * BLOCK], cs[2 * BLOCK];
        sincos_lanes(ref, sn, cs, 2 * n);
        for (int l = 0; l < n; l++)
            if (!(rho[l] > tiny))
                for (int e = 0; e < 2; e++) {
                    const int at = e * n + l;
                    out[at] = ref[at], sines[at] = sn[at], cosines[at] = cs[at];
                }
    }
}

/* ---------------------------------------------------------------- legs */

/* The poses of up to BLOCK consecutive frames, over the lanes. */
struct pose_block {
    double local[4][9 * BLOCK]; /* hip, knee, ankle and toe joints' local rotations */
    double foot[9 * BLOCK];     /* the foot's world rotation */
    double point[5][3 * BLOCK]; /* knee, ankle, ball, heel, tip */
};

/*
 * The poses of frames 0 .. n-1 (n <= BLOCK) of hips, parents and angles
 * (lanes past n repeat the last frame), side by side: the joints' local
 * rotations by local_rotation_of_n, as the solve builds those it solves.
 */
static MT_CLONES void pose_block(const struct mt_leg *leg, size_t n, const double *hips, const double *parents,
                                 const double *angles, struct pose_block *out)
{
    enum { L = BLOCK };
    size_t row[L];
    for (size_t l = 0; l < L; l++)
        row[l] = l < n ? l : n - 1;
    for (int j = 0; j < 4; j++) {
        const int count = channels(leg, j);
        double v[3 * L], sn[3 * L], cs[3 * L];
        for (int c = 0; c < count; c++)
            for (size_t l = 0; l < L; l++)
                v[(size_t)c * L + l] = angles[12 * row[l] + 3 * (size_t)j + (size_t)c];
        sincos_lanes(v, sn, cs, count * L);
        local_rotation_of_n(leg, j, sn, cs, out->local[j], L);
    }
    double hip[3 * L], parent[9 * L], thigh[9 * L], shin[9 * L], toes[9 * L], s[3 * L], v[3 * L];
    for (size_t l = 0; l < L; l++) {
        for (size_t e = 0; e < 3; e++)
            hip[e * L + l] = hips[3 * row[l] + e];
        for (size_t e = 0; e < 9; e++)
            parent[e * L + l] = parents[9 * row[l] + e];
    }
    mat_mul_n(parent, out->local[0], thigh, L);
    mat_mul_n(thigh, out->local[1], shin, L);
    mat_mul_n(shin, out->local[2], out->foot, L);
    mat_mul_n(out->foot, out->local[3], toes, L);
    /* each point: the one it hangs from plus its segment turned by the rotation that turns it */
    const double *turned_by[5] = {thigh, shin, out->foot, out->foot, toes};
    const double *from[5] = {hip, out->point[0], out->point[1], out->point[1], out->point[2]};
    for (int k = 0; k < 5; k++) {
        spread_n(leg->segment[k], 3, s, L);
        mat_vec_n(turned_by[k], s, v, L);
        for (int e = 0; e < 3 * L; e++)
            out->point[k][e] = from[k][e] + v[e];
    }
}

static int check_leg(const struct mt_leg *leg)
{
    if (!leg)
        return MT_EINVAL;
    for (int j = 0; j < 4; j++) {
        const int n = channels(leg, j);
        for (int c = 0; c < 3; c++) {
            const int a = leg->axes[j][c];
            if (c < n ? a > 2 : a != -1)
                return MT_EINVAL;
        }
        if ((n == 2 && leg->axes[j][0] == leg->axes[j][1]) ||
            (n == 3 && (leg->axes[j][0] == leg->axes[j][1] || leg->axes[j][1] == leg->axes[j][2])))
            return MT_EINVAL;
        if (j < 2 && n == 0)
            return MT_EINVAL;
    }
    return MT_OK;
}

int mt_leg_points(const struct mt_leg *legs, size_t nlegs, size_t frames, const double *hips, const double *parents,
                  const double *angles, double *points, double *feet)
{
    if (nlegs == 0 || frames == 0)
        return MT_OK;
    if (!legs || !hips || !parents || !angles || !points)
        return MT_EINVAL;
    for (size_t i = 0; i < nlegs; i++)
        if (check_leg(legs + i) != MT_OK)
            return MT_EINVAL;
    for (size_t i = 0; i < nlegs; i++)
        for (size_t t0 = 0; t0 < frames; t0 += BLOCK) {
            const size_t n = frames - t0 < BLOCK ? frames - t0 : BLOCK, f0 = i * frames + t0;
            struct pose_block block;
            pose_block(legs + i, n, hips + 3 * f0, parents + 9 * f0, angles + 12 * f0, &block);
            for (size_t f = 0; f < n; f++) {
                for (int k = 0; k < 5; k++)
                    for (int e = 0; e < 3; e++)
                        points[15 * (f0 + f) + 3 * (size_t)k + (size_t)e] = block.point[k][(size_t)e * BLOCK + f];
                if (feet)
                    for (int e = 0; e < 9; e++)
                        feet[9 * (f0 + f) + (size_t)e] = block.foot[(size_t)e * BLOCK + f];
            }
        }
    return MT_OK;
}

int mt_placed_legs(const double *positions, size_t frames, size_t joints, const double *world, size_t world_count,
                   size_t nlegs, const long long *at, const double *heels, double *hips, double *points)
{
    if (nlegs == 0 || frames == 0)
        return MT_OK;
    if (!positions || !world || !at || !heels || !hips || !points)
        return MT_EINVAL;
    for (size_t i = 0; i < nlegs; i++) {
        const long long *a = at + 6 * i;
        for (int k = 0; k < 5; k++)
            if (a[k] < (k == 4 ? -1 : 0) || a[k] >= (long long)joints)
                return MT_EINVAL;
        if (a[5] < 0 || (unsigned long long)a[5] >= world_count)
            return MT_EINVAL;
    }
    for (size_t i = 0; i < nlegs; i++) {
        const long long *a = at + 6 * i;
        const double *heel = heels + 3 * i;
        /* knee, ankle, ball, the heel's ankle and the tip (the ball where there is none) */
        const size_t from[5] = {(size_t)a[1], (size_t)a[2], (size_t)a[3], (size_t)a[2], (size_t)(a[4] >= 0 ? a[4] : a[3])};
        for (size_t f = 0; f < frames; f++) {
            const double *p = positions + f * joints * 3, *w = world + (f * world_count + (size_t)a[5]) * 9;
            double *out = points + (i * frames + f) * 15, *hip = hips + (i * frames + f) * 3;
            for (int e = 0; e < 3; e++) {
                hip[e] = p[3 * (size_t)a[0] + (size_t)e];
                for (int k = 0; k < 5; k++)
                    out[3 * k + e] = p[3 * from[k] + (size_t)e];
                out[9 + e] += w[3 * e] * heel[0] + w[3 * e + 1] * heel[1] + w[3 * e + 2] * heel[2];
            }
        }
    }
    return MT_OK;
}

/* ---------------------------------------------------------------- the floor */

static double height(const struct mt_footskate *opt, const double *p)
{
    return p[0] * (opt->up[0] - opt->slope[0]) + p[1] * (opt->up[1] - opt->slope[1]) +
           p[2] * (opt->up[2] - opt->slope[2]) - opt->level;
}

/* p moved along up until its height is h (vertical: the slope is perpendicular to up) */
static void lift(const struct mt_footskate *opt, const double *p, double h, double *out)
{
    const double by = h - height(opt, p);
    for (int e = 0; e < 3; e++)
        out[e] = p[e] + by * opt->up[e];
}

static int check_options(const struct mt_footskate *opt)
{
    if (!opt || !(fabs(norm3(opt->up) - 1) <= 1e-9) || !isfinite(opt->level) || !isfinite(norm3(opt->slope)) ||
        !(fabs(dot3(opt->slope, opt->up)) <= 1e-9) || !(opt->knee_soft >= 0 && opt->knee_soft < pi / 2) ||
        !(opt->knee_keep >= 0 && opt->knee_keep <= 1))
        return MT_EINVAL;
    return MT_OK;
}

/* ---------------------------------------------------------------- phase 1: targets */

static size_t switch_gap(const struct mt_footskate *opt)
{
    return opt->blend / 4 > 1 ? opt->blend / 4 : 1;
}

/*
 * Frame by frame: a point planted at the frame before keeps its target; a new
 * one takes the given target on the floor, set at the foot's length from the
 * other point's target when that one is planted too (both new: both move
 * about their middle) or was planted at most switch_gap frames before (a
 * roll from heel to ball, or back); for a roll, partner (frames x 3, else
 * NaN) receives the other point's last target at the roll's first frame.
 */
static void enforce_targets(const unsigned char *planted, const double *targets, const double *clearance,
                            double foot_length, const struct mt_footskate *opt, size_t frames, double *out,
                            double *partner)
{
    const double nan = NAN;
    const size_t gap = switch_gap(opt);
    long long last[2] = {-1, -1}; /* the last frame each point was planted */
    for (size_t i = 0; i < 6 * frames; i++)
        out[i] = nan;
    for (size_t i = 0; i < 3 * frames; i++)
        partner[i] = nan;
    for (size_t t = 0; t < frames; t++) {
        const unsigned char *now = planted + 2 * t;
        double *target = out + 6 * t;
        int fresh[2] = {0, 0};
        for (int p = HEEL; p <= BALL; p++) {
            if (!now[p])
                continue;
            if (t > 0 && planted[2 * (t - 1) + p]) {
                memcpy(target + 3 * p, target - 6 + 3 * p, 3 * sizeof *target);
            } else {
                lift(opt, targets + 6 * t + 3 * p, clearance[p], target + 3 * p);
                fresh[p] = 1;
            }
        }
        int rolled[2];
        for (int p = HEEL; p <= BALL; p++)
            rolled[p] = fresh[p] && !now[1 - p] && last[1 - p] >= 0 && t - (size_t)last[1 - p] <= gap + 1;
        if ((now[HEEL] && now[BALL] && (fresh[HEEL] || fresh[BALL])) || rolled[HEEL] || rolled[BALL]) {
            const double *heel = rolled[BALL] ? out + 6 * last[HEEL] : target;
            const double *ball = rolled[HEEL] ? out + 6 * last[BALL] + 3 : target + 3;
            double step[3], direction[3];
            for (int e = 0; e < 3; e++)
                step[e] = ball[e] - heel[e];
            perpendicular(step, opt->up, direction);
            unit3(direction, direction);
            const double gamma = dot3(opt->slope, direction); /* the floor's rise per unit along direction */
            const double rise = clearance[BALL] - clearance[HEEL];
            /* |x direction + (rise + gamma x) up| = foot length: the horizontal distance x */
            const double qa = 1 + gamma * gamma, qb = 2 * gamma * rise, qc = rise * rise - foot_length * foot_length;
            const double disc = qb * qb - 4 * qa * qc;
            const double x = fmax(0.0, (-qb + sqrt(disc > 0 ? disc : 0.0)) / (2 * qa));
            double h[3], b[3], p[3];
            memcpy(h, heel, sizeof h);
            memcpy(b, ball, sizeof b);
            if (fresh[HEEL] && fresh[BALL]) {
                for (int e = 0; e < 3; e++)
                    p[e] = (h[e] + b[e]) / 2 - direction[e] * x / 2;
                lift(opt, p, clearance[HEEL], target);
                for (int e = 0; e < 3; e++)
                    p[e] = (h[e] + b[e]) / 2 + direction[e] * x / 2;
                lift(opt, p, clearance[BALL], target + 3);
            } else if (fresh[BALL]) {
                for (int e = 0; e < 3; e++)
                    p[e] = h[e] + direction[e] * x;
                lift(opt, p, clearance[BALL], target + 3);
            } else {
                for (int e = 0; e < 3; e++)
                    p[e] = b[e] - direction[e] * x;
                lift(opt, p, clearance[HEEL], target);
            }
            if (rolled[BALL])
                memcpy(partner + 3 * t, h, sizeof h);
            if (rolled[HEEL])
                memcpy(partner + 3 * t, b, sizeof b);
        }
        for (int p = HEEL; p <= BALL; p++)
            if (now[p])
                last[p] = (long long)t;
    }
}

/* ---------------------------------------------------------------- phase 2: blending */

/*
 * Walks the frames in order, knowing for each the nearest masked frames
 * before and after it (strictly), and their blend weights: s(1 - distance /
 * w) with w = min(window, next - previous) and s the smoothstep.
 */
struct neighbours {
    const unsigned char *mask;
    size_t frames, window;
    long long prev, next;
};

static void neighbours_start(struct neighbours *n, const unsigned char *mask, size_t frames, size_t window)
{
    n->mask = mask, n->frames = frames, n->window = window, n->prev = -1, n->next = -1;
}

/* Moves to frame t (called for t = 0, 1, ... in order); weights of the masked frames around it. */
static void neighbours_at(struct neighbours *n, size_t t, double *wp, double *wn)
{
    if (t > 0 && n->mask[t - 1])
        n->prev = (long long)t - 1;
    if (n->next <= (long long)t) {
        n->next = -1;
        for (size_t u = t + 1; u < n->frames; u++)
            if (n->mask[u]) {
                n->next = (long long)u;
                break;
            }
    }
    const int has_prev = n->prev >= 0, has_next = n->next >= 0;
    double w = (double)n->window;
    if (has_prev && has_next && (double)(n->next - n->prev) < w)
        w = (double)(n->next - n->prev);
    *wp = has_prev && w > 0 ? smoothstep(1 - ((double)t - (double)n->prev) / w) : 0.0;
    *wn = has_next && w > 0 ? smoothstep(1 - ((double)n->next - (double)t) / w) : 0.0;
}

/* the lever's far end, below its resting height, lifted onto it by the smallest turn about the pivot */
static void raise_lever(const double *lever, const double *pivot, double rest, const struct mt_footskate *opt,
                        double *out)
{
    const double n[3] = {opt->up[0] - opt->slope[0], opt->up[1] - opt->slope[1], opt->up[2] - opt->slope[2]};
    double axis[3], side[3];
    cross3(lever, n, axis);
    const double across = norm3(axis);
    unit3(axis, axis);
    cross3(axis, lever, side);
    const double need = rest - height(opt, pivot); /* n . R lever must reach this */
    const double x = dot3(n, lever), y = dot3(n, side), rho = length2(x, y), phi = atan2(y, x);
    const double spread = acos(clip(need / (rho > tiny ? rho : 1.0), -1.0, 1.0));
    const double first = wrap(phi - spread), second = wrap(phi + spread);
    const int low = x < need && rho > tiny && across > tiny;
    about(axis, low ? (fabs(first) <= fabs(second) ? first : second) : 0.0, out);
}

/* ---------------------------------------------------------------- knee */

/* over the lanes: |hip -> ankle|^2 = base + 2 rho cos(delta - phi) turning the knee by delta */
struct hinge {
    double base[BLOCK], rho[BLOCK], phi[BLOCK], cos_phi[BLOCK], sin_phi[BLOCK];
};

static MT_INLINE void hinge_n(const struct mt_leg *leg, const double *knee_local, const double *axis, struct hinge *h,
                              int n)
{
    const double *s1 = leg->segment[0];
    double s2[3 * BLOCK], a[3 * BLOCK], u[3 * BLOCK], au[3 * BLOCK], x[BLOCK], y[BLOCK];
    spread_n(leg->segment[1], 3, s2, n);
    spread_n(axis, 3, a, n);
    mat_vec_n(knee_local, s2, u, n);
    cross_n(a, u, au, n);
    const double s1a = dot3(s1, axis), s1s1 = dot3(s1, s1);
    for (int l = 0; l < n; l++) {
        const double u0 = u[l], u1 = u[n + l], u2 = u[2 * n + l];
        const double c0 = s1a * (u0 * axis[0] + u1 * axis[1] + u2 * axis[2]);
        x[l] = s1[0] * u0 + s1[1] * u1 + s1[2] * u2 - c0;
        y[l] = s1[0] * au[l] + s1[1] * au[n + l] + s1[2] * au[2 * n + l];
        const double rho = length2(x[l], y[l]);
        h->base[l] = s1s1 + (u0 * u0 + u1 * u1 + u2 * u2) + 2 * c0;
        h->rho[l] = rho, h->cos_phi[l] = rho > 0 ? x[l] / rho : 1.0, h->sin_phi[l] = rho > 0 ? y[l] / rho : 0.0;
    }
    atan2_lanes(y, x, h->phi, n);
}

/* the longest hip -> ankle distance with the knee bent at least min(soft, its bend now), and keep times it */
static MT_INLINE void reach_n(const struct hinge *h, double soft, double keep, double *out, int n)
{
    double now[BLOCK], bend[BLOCK], sn[BLOCK], cs[BLOCK];
    for (int l = 0; l < n; l++) {
        now[l] = fabs(wrap(-h->phi[l]));
        const double least = now[l] < soft ? now[l] : soft;
        bend[l] = keep * now[l] > least ? keep * now[l] : least;
    }
    sincos_lanes(bend, sn, cs, n);
    for (int l = 0; l < n; l++) {
        /* the bend now is phi's (cos is even and whole turns round): its cosine is known */
        const double r2 = h->base[l] + 2 * h->rho[l] * (bend[l] == now[l] ? h->cos_phi[l] : cs[l]);
        out[l] = sqrt(r2 > 0 ? r2 : 0.0);
    }
}

/*
 * The knees of frames 0 .. n-1 (n <= BLOCK; lanes past n repeat the last) of
 * angles, about the hinge axis: their reaches (reach_n with soft and keep)
 * and the bends wrap(-phi), whose signs tell the side the knee bends to.
 */
static MT_CLONES void knee_block(const struct mt_leg *leg, size_t n, const double *angles, const double *axis,
                                 double soft, double keep, double *reaches, double *bends)
{
    const int count = channels(leg, 1);
    double v[3 * BLOCK], sines[3 * BLOCK], cosines[3 * BLOCK], knee_local[9 * BLOCK], r[BLOCK];
    for (int c = 0; c < count; c++)
        for (size_t f = 0; f < BLOCK; f++)
            v[(size_t)c * BLOCK + f] = angles[12 * (f < n ? f : n - 1) + 3 + (size_t)c];
    sincos_lanes(v, sines, cosines, count * BLOCK);
    local_rotation_of_n(leg, 1, sines, cosines, knee_local, BLOCK);
    struct hinge h;
    hinge_n(leg, knee_local, axis, &h, BLOCK);
    reach_n(&h, soft, keep, r, BLOCK);
    for (size_t f = 0; f < n; f++)
        reaches[f] = r[f], bends[f] = wrap(-h.phi[f]);
}

/* ---------------------------------------------------------------- phases 1 and 2 */

/* The knee's hinge axis: its channel's axis, or the mean bend axis of the take, since the reach
 * and the solve turn the knee about one axis whatever channels it has. */
static void knee_hinge(const struct mt_leg *leg, size_t frames, const double *angles, double *axis)
{
    if (channels(leg, 1) == 1) {
        const int a = leg->axes[1][0];
        for (int e = 0; e < 3; e++)
            axis[e] = leg->axis[1][3 * e + a];
        return;
    }
    const double *s = leg->segment[0];
    double total[3] = {0, 0, 0};
    for (size_t t = 0; t < frames; t++) {
        double l[9], u[3], c[3];
        local_rotation(leg, 1, angles + 12 * t + 3, l);
        mat_vec(l, leg->segment[1], u);
        cross3(s, u, c);
        for (int e = 0; e < 3; e++)
            total[e] += c[e];
    }
    const double scale = norm3(s) * norm3(leg->segment[1]);
    if (!(norm3(total) > tiny * (scale > 1 ? scale : 1.0) * (double)frames)) {
        double down[3];
        for (int e = 0; e < 3; e++)
            down[e] = leg->segment[1][e] + leg->segment[2][e];
        cross3(s, down, total);
    }
    unit3(total, axis);
}

/* The knee's reach in each frame and the side (+1 or -1) most frames bend it to: the root and
 * the solve keep each hip within the reach, and bend the knee to the side the take does. */
static double knee_reaches(const struct mt_leg *leg, size_t frames, const double *angles, const double *axis,
                           const struct mt_footskate *opt, double *reaches)
{
    double sides = 0;
    for (size_t t0 = 0; t0 < frames; t0 += BLOCK) {
        const size_t n = frames - t0 < BLOCK ? frames - t0 : BLOCK;
        double bends[BLOCK];
        knee_block(leg, n, angles + 12 * t0, axis, opt->knee_soft, opt->knee_keep, reaches + t0, bends);
        for (size_t f = 0; f < n; f++)
            sides += (bends[f] > 0) - (bends[f] < 0);
    }
    return sides >= 0 ? 1.0 : -1.0;
}

/* What the steps of phase 2 share (see mt_footskate_plan), and its scratch. */
struct plan {
    const struct mt_footskate *opt;
    size_t frames;
    const double *points, *clearance;
    const unsigned char *planted;
    const double *enforced; /* the targets of phase 1 */
    double *partner;        /* a roll's other target at its first frame, else NaN (frames x 3) */
    double *pinlog;         /* the pinned turns as rotation vectors, else zero (frames x 3) */
    unsigned char *pins;    /* frames that pin the foot's turn */
    unsigned char *some;    /* frames with a point planted */
};

/* The foot's turns where both points are planted, or it rolls from one to the other: the two
 * targets fix its direction there, and the turns of the other planted frames blend from them. */
static void pin_turns(const struct plan *p)
{
    for (size_t t = 0; t < p->frames; t++) {
        const unsigned char *now = p->planted + 2 * t;
        const double *ball = p->points + 15 * t + 6, *heel = p->points + 15 * t + 9;
        const int rolled = !isnan(p->partner[3 * t]);
        p->some[t] = now[HEEL] || now[BALL];
        p->pins[t] = (now[HEEL] && now[BALL]) || rolled;
        memset(p->pinlog + 3 * t, 0, 3 * sizeof *p->pinlog);
        if (!p->pins[t])
            continue;
        const double *heel_goal = rolled && now[BALL] ? p->partner + 3 * t : p->enforced + 6 * t;
        const double *ball_goal = rolled && now[HEEL] ? p->partner + 3 * t : p->enforced + 6 * t + 3;
        double from[3], to[3], r[9];
        for (int e = 0; e < 3; e++)
            from[e] = ball[e] - heel[e], to[e] = ball_goal[e] - heel_goal[e];
        between(from, to, r);
        rotvec_of(r, p->pinlog + 3 * t);
    }
}

/* The turns (and, in goal, the ankle's shifts) of the frames with a point planted: the turn
 * blended from the pins, raised about the pivot where one point is planted and the other would
 * sink below the floor, and the ankle following the planted point, so that it lands on its target. */
static void turn_planted(const struct plan *p, double *goal, double *turn)
{
    struct neighbours around;
    neighbours_start(&around, p->pins, p->frames, p->opt->blend);
    for (size_t t = 0; t < p->frames; t++) {
        double wp, wn;
        neighbours_at(&around, t, &wp, &wn);
        if (!p->some[t])
            continue;
        const unsigned char *now = p->planted + 2 * t;
        const double *ankle = p->points + 15 * t + 3;
        double log[3], q[9];
        if (p->pins[t])
            memcpy(log, p->pinlog + 3 * t, sizeof log);
        else
            for (int e = 0; e < 3; e++)
                log[e] = (around.prev >= 0 ? wp * p->pinlog[3 * around.prev + e] : 0.0) +
                         (around.next >= 0 ? wn * p->pinlog[3 * around.next + e] : 0.0);
        rotvec_exp(log, q);
        const int on_ball = now[BALL] && !now[HEEL];
        const double *pivot = p->points + 15 * t + (on_ball ? 6 : 9), *other = p->points + 15 * t + (on_ball ? 9 : 6);
        const double *target = p->enforced + 6 * t + 3 * on_ball;
        if ((!now[HEEL] || !now[BALL]) && isnan(p->partner[3 * t])) {
            double arm[3], lever[3], r[9];
            for (int e = 0; e < 3; e++)
                arm[e] = other[e] - pivot[e];
            mat_vec(q, arm, lever);
            raise_lever(lever, target, p->clearance[on_ball ? HEEL : BALL], p->opt, r);
            mat_mul(r, q, q);
        }
        double arm[3], moved[3];
        for (int e = 0; e < 3; e++)
            arm[e] = ankle[e] - pivot[e];
        mat_vec(q, arm, moved);
        for (int e = 0; e < 3; e++)
            goal[3 * t + e] = target[e] + moved[e] - ankle[e];
        rotvec_of(q, turn + 3 * t);
    }
}

/* The shifts and turns of the free frames, and every frame's weight: blended from the planted
 * frames (which this pass does not change), so that a foot eases into and out of a plant. */
static void blend_free(const struct plan *p, double *goal, double *turn, double *weight)
{
    struct neighbours around;
    neighbours_start(&around, p->some, p->frames, p->opt->blend);
    for (size_t t = 0; t < p->frames; t++) {
        double wp, wn;
        neighbours_at(&around, t, &wp, &wn);
        if (p->some[t]) {
            weight[t] = 1.0;
            continue;
        }
        for (int e = 0; e < 3; e++) {
            goal[3 * t + e] = (around.prev >= 0 ? wp * goal[3 * around.prev + e] : 0.0) +
                              (around.next >= 0 ? wn * goal[3 * around.next + e] : 0.0);
            turn[3 * t + e] = (around.prev >= 0 ? wp * turn[3 * around.prev + e] : 0.0) +
                              (around.next >= 0 ? wn * turn[3 * around.next + e] : 0.0);
        }
        weight[t] = wp > wn ? wp : wn;
    }
}

/* goal = the ankle plus its shift: the later phases aim the ankle at a point, not by a shift */
static void shifts_to_goals(const struct plan *p, double *goal)
{
    for (size_t t = 0; t < p->frames; t++)
        for (int e = 0; e < 3; e++)
            goal[3 * t + e] += p->points[15 * t + 3 + e];
}

int mt_footskate_plan(const struct mt_leg *leg, size_t frames, const double *angles, const double *points,
                      const unsigned char *planted, const double *targets, const double *clearance,
                      const struct mt_footskate *opt, double *enforced, double *goal, double *turn, double *weight,
                      double *reaches, double *knee)
{
    if (check_leg(leg) != MT_OK || check_options(opt) != MT_OK || !clearance || !knee)
        return MT_EINVAL;
    if (frames > 0 && (!angles || !points || !planted || !targets || !enforced || !goal || !turn || !weight ||
                       !reaches))
        return MT_EINVAL;
    knee_hinge(leg, frames, angles, knee);
    knee[3] = 1.0;
    if (frames == 0)
        return MT_OK;
    double *partner = malloc(3 * frames * sizeof *partner), *pinlog = malloc(3 * frames * sizeof *pinlog);
    unsigned char *masks = malloc(2 * frames + 1);
    if (!partner || !pinlog || !masks) {
        free(partner), free(pinlog), free(masks);
        return MT_ENOMEM;
    }
    const struct plan p = {opt, frames, points, clearance, planted, enforced, partner, pinlog, masks, masks + frames};
    knee[3] = knee_reaches(leg, frames, angles, knee, opt, reaches);
    double foot[3];
    for (int e = 0; e < 3; e++)
        foot[e] = leg->segment[2][e] - leg->segment[3][e];
    enforce_targets(planted, targets, clearance, norm3(foot), opt, frames, enforced, partner);
    pin_turns(&p);
    turn_planted(&p, goal, turn);
    blend_free(&p, goal, turn, weight);
    shifts_to_goals(&p, goal);
    free(partner), free(pinlog), free(masks);
    return MT_OK;
}

/* ---------------------------------------------------------------- phase 3: the root */

/*
 * The root offset nearest to o that puts each active leg's hip within its
 * radius of its ankle goal (centre: the offset that would put the hip on
 * it).  One sphere: the projection onto it; two: the projection onto one
 * that lies in the other ball (the nearer if both do), else onto their
 * circle (on the line of centres for balls apart).
 */
static void project_root(const double *o, const double (*centre)[3], const double *radius, const int *active,
                         size_t legs, double *out)
{
    double proj[2][3];
    int inside[2] = {1, 1}, count = 0;
    for (size_t i = 0; i < legs; i++) {
        double d[3], u[3];
        for (int e = 0; e < 3; e++)
            d[e] = o[e] - centre[i][e];
        inside[i] = !active[i] || norm3(d) <= radius[i];
        unit3(d, u);
        for (int e = 0; e < 3; e++)
            proj[i][e] = centre[i][e] + u[e] * radius[i];
        count += active[i] != 0;
    }
    memcpy(out, o, 3 * sizeof *out);
    if (count == 1) {
        for (size_t i = 0; i < legs; i++)
            if (active[i] && !inside[i])
                memcpy(out, proj[i], 3 * sizeof *out);
        return;
    }
    if (count != 2 || (inside[0] && inside[1]))
        return;
    const double *c1 = centre[0], *c2 = centre[1], r1 = radius[0], r2 = radius[1];
    double p1[3], p2[3], a[3], b[3];
    memcpy(p1, inside[0] ? o : proj[0], sizeof p1);
    memcpy(p2, inside[1] ? o : proj[1], sizeof p2);
    for (int e = 0; e < 3; e++)
        a[e] = p1[e] - c2[e], b[e] = p2[e] - c1[e];
    const int ok1 = norm3(a) <= r2 * (1 + 1e-12), ok2 = norm3(b) <= r1 * (1 + 1e-12);
    for (int e = 0; e < 3; e++)
        a[e] = p1[e] - o[e], b[e] = p2[e] - o[e];
    const double d1 = norm3(a), d2 = norm3(b);
    if ((ok1 && ok2 && d1 <= d2) || (ok1 && !ok2)) {
        memcpy(out, p1, sizeof p1);
        return;
    }
    if (ok2) {
        memcpy(out, p2, sizeof p2);
        return;
    }
    double normal[3], n[3], q[3];
    for (int e = 0; e < 3; e++)
        normal[e] = c2[e] - c1[e];
    const double gap = norm3(normal);
    unit3(normal, n);
    const double x = clip(gap > tiny ? (gap * gap + r1 * r1 - r2 * r2) / (2 * gap) : 0.0, -r1, r1);
    const double r2c = r1 * r1 - x * x, radius_c = sqrt(r2c > 0 ? r2c : 0.0);
    double middle[3];
    for (int e = 0; e < 3; e++)
        middle[e] = c1[e] + n[e] * x, q[e] = o[e] - middle[e];
    perpendicular(q, n, q);
    if (!(norm3(q) > tiny)) {
        const double other[3] = {fabs(n[0]) < 0.9, fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
        cross3(n, other, q);
    }
    unit3(q, q);
    for (int e = 0; e < 3; e++)
        out[e] = middle[e] + q[e] * radius_c;
}

/* out = mean of in over frames t - half .. t + half (edges held), summed in window order; a window
 * of zeros (most of a take: the root moves where legs fall short) gives 0 without the sum */
static void moving_mean(const double *in, size_t frames, size_t half, double *out)
{
    if (half == 0) {
        memcpy(out, in, 3 * frames * sizeof *out);
        return;
    }
    size_t nonzero = 0; /* rows of in[t + half] back to in[t - half], edges held, that are not zero */
#define ROW_NONZERO(u) (in[3 * (u)] != 0 || in[3 * (u) + 1] != 0 || in[3 * (u) + 2] != 0)
    for (long long k = -(long long)half; k <= (long long)half; k++)
        nonzero += ROW_NONZERO(k < 0 ? 0 : (size_t)k < frames ? (size_t)k : frames - 1);
    for (size_t t = 0; t < frames; t++) {
        if (t > 0) { /* slide the window by one frame */
            const long long leaving = (long long)t - 1 - (long long)half, entering = (long long)(t + half);
            nonzero -= ROW_NONZERO(leaving < 0 ? 0 : (size_t)leaving);
            nonzero += ROW_NONZERO((size_t)entering < frames ? (size_t)entering : frames - 1);
        }
        for (int e = 0; e < 3; e++) {
            double total = 0;
            if (nonzero)
                for (long long k = -(long long)half; k <= (long long)half; k++) {
                    long long u = (long long)t + k;
                    u = u < 0 ? 0 : u >= (long long)frames ? (long long)frames - 1 : u;
                    total += in[3 * u + e];
                }
            out[3 * t + e] = total / (double)(2 * half + 1);
        }
    }
#undef ROW_NONZERO
}

/* x = two moving means of x: a triangular window of half-width 2 half */
static void smooth_root(double *x, size_t frames, size_t half, double *work)
{
    moving_mean(x, frames, half, work);
    moving_mean(work, frames, half, x);
}

/* out (frames x 3) = the projection of each frame of in (in may be out) */
static void project_frames(size_t legs, size_t frames, const double *hips, const double *goals, const double *reaches,
                           const double *weights, const double *in, double *out)
{
    for (size_t t = 0; t < frames; t++) {
        double centre[2][3], radius[2];
        int active[2] = {0, 0};
        for (size_t i = 0; i < legs; i++) {
            const size_t f = i * frames + t;
            for (int e = 0; e < 3; e++)
                centre[i][e] = goals[3 * f + e] - hips[3 * f + e];
            radius[i] = reaches[f];
            active[i] = weights[f] > 0;
        }
        double o[3];
        memcpy(o, in + 3 * t, sizeof o);
        project_root(o, (const double(*)[3])centre, radius, active, legs, out + 3 * t);
    }
}

int mt_footskate_root(size_t legs, size_t frames, const double *hips, const double *goals, const double *reaches,
                      const double *weights, const struct mt_footskate *opt, double *root)
{
    if (legs < 1 || legs > 2 || check_options(opt) != MT_OK)
        return MT_EINVAL;
    if (frames == 0)
        return MT_OK;
    if (!hips || !goals || !reaches || !weights || !root)
        return MT_EINVAL;
    double *work = malloc(6 * frames * sizeof *work);
    if (!work)
        return MT_ENOMEM;
    double *residual = work + 3 * frames;
    memset(root, 0, 3 * frames * sizeof *root);
    project_frames(legs, frames, hips, goals, reaches, weights, root, root);
    smooth_root(root, frames, opt->root_window, work);
    for (size_t pass = 0; pass < opt->root_passes; pass++) {
        project_frames(legs, frames, hips, goals, reaches, weights, root, residual);
        int any = 0;
        for (size_t i = 0; i < 3 * frames; i++) {
            residual[i] -= root[i];
            any |= residual[i] != 0;
        }
        if (!any)
            break;
        smooth_root(residual, frames, opt->root_window, work);
        for (size_t i = 0; i < 3 * frames; i++)
            root[i] += residual[i];
    }
    project_frames(legs, frames, hips, goals, reaches, weights, root, root);
    free(work);
    return MT_OK;
}

/* ---------------------------------------------------------------- phases 4 and 5: the legs */

/* the legs solved, over the lanes */
struct solved {
    double angles[12 * BLOCK];
    double knee_delta[BLOCK];    /* the turn about the knee's hinge */
    double wanted[3][9 * BLOCK]; /* the local rotations asked of hip, knee and ankle */
    double foot[9 * BLOCK];
    double ankle[3 * BLOCK];
};

/*
 * Two-bone IK over the lanes (angles: 12 over them; local0, local1: the hip's
 * and the knee's local rotations now): the knee bends about its hinge so that
 * hip -> ankle has the goal's length (within the knee's reach, never past
 * straight, to the side it bends), the hip turns the leg onto the goal, the
 * ankle takes foot_goal (its aim exactly, with fewer than three channels).
 * Joints that take the rotation asked exactly (three channels; a one-channel
 * knee turning about its channel's axis) are left for finish_angles_n: a foot
 * re-aimed solves the leg again, and their Euler angles are needed once.
 */
static MT_INLINE void two_bone_n(const struct mt_leg *leg, const double *hip, const double *parent,
                                 const double *angles, const double *local0, const double *local1,
                                 const struct hinge *h, const double *knee, double soft, const double *ankle_goal,
                                 const double *foot_goal, const double *aim, struct solved *out, int n)
{
    double s1[3 * BLOCK], s2[3 * BLOCK], axis[3 * BLOCK], goal[3 * BLOCK], longest[BLOCK], cosine[BLOCK];
    double bend[BLOCK], c[BLOCK], s[BLOCK], r[9 * BLOCK], knee_local[9 * BLOCK], thigh[9 * BLOCK], shin[9 * BLOCK];
    double v[3 * BLOCK], leg_vector[3 * BLOCK], world[3 * BLOCK], hip_local[9 * BLOCK];
    double sines[3 * BLOCK], cosines[3 * BLOCK];
    spread_n(leg->segment[0], 3, s1, n);
    spread_n(leg->segment[1], 3, s2, n);
    spread_n(knee, 3, axis, n);
    memcpy(out->angles, angles, 12 * (size_t)n * sizeof *angles);
    for (int e = 0; e < 3; e++)
        for (int l = 0; l < n; l++)
            goal[e * n + l] = ankle_goal[e * n + l] - hip[e * n + l];
    reach_n(h, soft, 0.0, longest, n);
    for (int l = 0; l < n; l++) {
        const double low2 = h->base[l] - 2 * h->rho[l], shortest = sqrt(low2 > 0 ? low2 : 0.0);
        const double d = clip(sqrt(goal[l] * goal[l] + goal[n + l] * goal[n + l] + goal[2 * n + l] * goal[2 * n + l]),
                              shortest, longest[l]);
        cosine[l] = clip((d * d - h->base[l]) / (2 * (h->rho[l] > tiny ? h->rho[l] : 1.0)), -1.0, 1.0);
    }
    acos_n(cosine, bend, n);
    for (int l = 0; l < n; l++) {
        const int bends = h->rho[l] > tiny;
        bend[l] = bends ? bend[l] : 0.0;
        out->knee_delta[l] = h->phi[l] + knee[3] * bend[l];
        /* cos and sin of phi + side bend by the angle sums: phi's from the hinge, bend's from its cosine */
        const double sin_bend = sqrt(1 - cosine[l] * cosine[l]) * bends, cos_bend = bends ? cosine[l] : 1.0;
        c[l] = h->cos_phi[l] * cos_bend - knee[3] * h->sin_phi[l] * sin_bend;
        s[l] = h->sin_phi[l] * cos_bend + knee[3] * h->cos_phi[l] * sin_bend;
    }
    about_cs_n(axis, c, s, r, n);
    mat_mul_n(r, local1, out->wanted[1], n);
    if (channels(leg, 1) == 2) {
        realize_n(leg, 1, out->wanted[1], s2, angles + 3 * n, out->angles + 3 * n, sines, cosines, n);
        local_rotation_of_n(leg, 1, sines, cosines, knee_local, n);
    } else {
        memcpy(knee_local, out->wanted[1], 9 * (size_t)n * sizeof *knee_local);
    }
    mat_mul_n(parent, local0, thigh, n);
    mat_vec_n(knee_local, s2, v, n);
    for (int e = 0; e < 3 * n; e++)
        leg_vector[e] = s1[e] + v[e];
    mat_vec_n(thigh, leg_vector, world, n);
    between_n(world, goal, r, n);
    mat_mul_n(r, thigh, out->wanted[0], n);
    mat_tmul_n(parent, out->wanted[0], out->wanted[0], n);
    if (channels(leg, 0) < 3) {
        realize_n(leg, 0, out->wanted[0], leg_vector, angles, out->angles, sines, cosines, n);
        local_rotation_of_n(leg, 0, sines, cosines, hip_local, n);
    } else {
        memcpy(hip_local, out->wanted[0], 9 * (size_t)n * sizeof *hip_local);
    }
    mat_mul_n(parent, hip_local, thigh, n);
    mat_mul_n(thigh, knee_local, shin, n);
    mat_tmul_n(shin, foot_goal, out->wanted[2], n);
    if (channels(leg, 2) < 3) {
        realize_n(leg, 2, out->wanted[2], aim, angles + 6 * n, out->angles + 6 * n, sines, cosines, n);
        local_rotation_of_n(leg, 2, sines, cosines, r, n);
        mat_mul_n(shin, r, out->foot, n);
    } else {
        mat_mul_n(shin, out->wanted[2], out->foot, n);
    }
    double a[3 * BLOCK], b[3 * BLOCK];
    mat_vec_n(thigh, s1, a, n);
    mat_vec_n(shin, s2, b, n);
    for (int e = 0; e < 3 * n; e++)
        out->ankle[e] = hip[e] + a[e] + b[e];
}

/* The Euler angles two_bone_n left: joints of three channels, and a one-channel knee (its angle plus
 * the turn about its hinge, which is its channel's axis). */
static MT_INLINE void finish_angles_n(const struct mt_leg *leg, const double *angles, const double *aim,
                                      struct solved *solved, int n)
{
    double sines[3 * BLOCK], cosines[3 * BLOCK];
    for (int j = 0; j < 3; j++)
        if (channels(leg, j) == 3)
            realize_n(leg, j, solved->wanted[j], aim, angles + 3 * j * n, solved->angles + 3 * j * n, sines,
                      cosines, n);
    if (channels(leg, 1) == 1)
        for (int l = 0; l < n; l++)
            solved->angles[3 * n + l] = angles[3 * n + l] + wrap(solved->knee_delta[l]);
}

/* how far the lower of heel and ball, of feet at ankle turned to foot, are above where they rest */
static MT_INLINE void foot_low_n(const struct mt_leg *leg, const double *ankle, const double *foot,
                                 const double *clearance, const struct mt_footskate *opt, double *out, int n)
{
    double heel[3 * BLOCK], ball[3 * BLOCK];
    spread_n(leg->segment[3], 3, heel, n);
    spread_n(leg->segment[2], 3, ball, n);
    mat_vec_n(foot, heel, heel, n);
    mat_vec_n(foot, ball, ball, n);
    const double g[3] = {opt->up[0] - opt->slope[0], opt->up[1] - opt->slope[1], opt->up[2] - opt->slope[2]};
    for (int l = 0; l < n; l++) {
        double low[2];
        for (int k = 0; k < 2; k++) {
            const double *v = k == HEEL ? heel : ball;
            const double p0 = ankle[l] + v[l], p1 = ankle[n + l] + v[n + l], p2 = ankle[2 * n + l] + v[2 * n + l];
            low[k] = p0 * g[0] + p1 * g[1] + p2 * g[2] - opt->level - clearance[k];
        }
        out[l] = low[HEEL] < low[BALL] ? low[HEEL] : low[BALL];
    }
}

/* the toe angles that raise a toe tip below the floor onto it, about the toe joint's axis */
static void bend_toes(const struct mt_leg *leg, const double *foot, const double *ball, const double *toe_local,
                      double clearance_tip, const struct mt_footskate *opt, double *angles)
{
    const double *t = leg->segment[4];
    if (channels(leg, 3) == 0 || (t[0] == 0 && t[1] == 0 && t[2] == 0))
        return;
    double axis[3];
    if (channels(leg, 3) == 1) {
        const int a = leg->axes[3][0];
        for (int e = 0; e < 3; e++)
            axis[e] = leg->axis[3][3 * e + a];
    } else {
        cross3(leg->segment[2], leg->segment[3], axis);
        unit3(axis, axis);
    }
    const double n[3] = {opt->up[0] - opt->slope[0], opt->up[1] - opt->slope[1], opt->up[2] - opt->slope[2]};
    double k[3], u[3], au[3];
    mat_tvec(foot, n, k); /* the height's gradient in the foot's frame */
    mat_vec(toe_local, t, u);
    cross3(axis, u, au);
    const double c0 = dot3(k, axis) * dot3(u, axis), base = height(opt, ball);
    if (!(base + dot3(k, u) < clearance_tip))
        return;
    const double x = dot3(k, u) - c0, y = dot3(k, au), rho = length2(x, y), phi = atan2(y, x);
    if (!(rho > tiny))
        return;
    const double need = clearance_tip - base - c0; /* rho cos(delta - phi) must reach this */
    const double spread = acos(clip(need / rho, -1.0, 1.0));
    const double first = wrap(phi - spread), second = wrap(phi + spread);
    double r[9], wanted[9], ref[3];
    about(axis, fabs(first) <= fabs(second) ? first : second, r);
    mat_mul(r, toe_local, wanted);
    double sines[3], cosines[3];
    memcpy(ref, angles, sizeof ref);
    realize_n(leg, 3, wanted, t, ref, angles, sines, cosines, 1);
}

/* What the solve of a block of frames reads (see mt_footskate_solve), and the lifts worked out before it. */
struct solve_job {
    const struct mt_leg *leg;
    const struct mt_footskate *opt;
    const double *hips, *parents, *angles, *goal, *turn, *knee, *root, *clearance, *lift_by;
    const unsigned char *planted;
};

/*
 * Phases 4 and 5 of frames t0 .. t0 + n - 1 side by side (n <= BLOCK; lanes
 * past n repeat the last frame), their poses given: the legs solved, and the
 * balls where they put them (3 over the lanes).  A lane's leg is solved again
 * with a re-aimed or lifted goal when any lane's is; the others' goals stay,
 * and their results with them.
 */
static MT_CLONES void solve_block(const struct solve_job *job, size_t t0, size_t n, const struct pose_block *pose,
                                  struct solved *out, double *ball)
{
    enum { L = BLOCK };
    const struct mt_leg *leg = job->leg;
    const struct mt_footskate *opt = job->opt;
    double hip[3 * L], parent[9 * L], angles[12 * L], first[3 * L], target[3 * L], turn[3 * L], q[9 * L];
    double foot_goal[9 * L], aim[3 * L], low[L];
    size_t row[L];
    int some[L], any_some = 0, sinking = 0;
    for (size_t l = 0; l < L; l++) {
        const size_t t = row[l] = t0 + (l < n ? l : n - 1);
        for (int e = 0; e < 3; e++) {
            hip[e * L + l] = job->hips[3 * t + e] + job->root[3 * t + e];
            first[e * L + l] = job->goal[3 * t + e] + job->lift_by[t] * opt->up[e];
            turn[e * L + l] = job->turn[3 * t + e];
        }
        for (int e = 0; e < 9; e++)
            parent[e * L + l] = job->parents[9 * t + e];
        for (int c = 0; c < 12; c++)
            angles[c * L + l] = job->angles[12 * t + c];
        some[l] = job->planted[2 * t] || job->planted[2 * t + 1];
        any_some |= some[l];
    }
    for (int e = 0; e < 3; e++) /* heel -> ball: what a two-channel ankle keeps */
        for (int l = 0; l < L; l++)
            aim[e * L + l] = leg->segment[2][e] - leg->segment[3][e];
    const double *local0 = pose->local[0], *local1 = pose->local[1];
    rotvec_exp_n(turn, q, L);
    mat_mul_n(q, pose->foot, foot_goal, L);
    struct hinge h;
    hinge_n(leg, local1, job->knee, &h, L);
    two_bone_n(leg, hip, parent, angles, local0, local1, &h, job->knee, opt->knee_soft, first, foot_goal, aim, out,
               L);
    memcpy(target, first, sizeof target);
    if (channels(leg, 2) < 3 && any_some) { /* the ankle cannot roll: re-aim it so that the pivot lands */
        double pivot[3 * L], want[3 * L], got[3 * L]; /* once: the miss after it is a few micrometres */
        for (int l = 0; l < L; l++) {
            const double *p = leg->segment[job->planted[2 * row[l]] ? 3 : 2];
            for (int e = 0; e < 3; e++)
                pivot[e * L + l] = p[e];
        }
        mat_vec_n(foot_goal, pivot, want, L);
        mat_vec_n(out->foot, pivot, got, L);
        for (int e = 0; e < 3; e++)
            for (int l = 0; l < L; l++)
                target[e * L + l] = some[l] ? first[e * L + l] + want[e * L + l] - got[e * L + l] : target[e * L + l];
        two_bone_n(leg, hip, parent, angles, local0, local1, &h, job->knee, opt->knee_soft, target, foot_goal, aim,
                   out, L);
    }
    /* what the leg could not quite reach is lifted frame by frame */
    foot_low_n(leg, out->ankle, out->foot, job->clearance, opt, low, L);
    for (int l = 0; l < L; l++)
        if (!some[l] && low[l] < 0) {
            for (int e = 0; e < 3; e++)
                target[e * L + l] -= low[l] * opt->up[e];
            sinking = 1;
        }
    if (sinking)
        two_bone_n(leg, hip, parent, angles, local0, local1, &h, job->knee, opt->knee_soft, target, foot_goal, aim,
                   out, L);
    finish_angles_n(leg, angles, aim, out, L);
    double s2[3 * L];
    spread_n(leg->segment[2], 3, s2, L);
    mat_vec_n(out->foot, s2, s2, L);
    for (int e = 0; e < 3 * L; e++)
        ball[e] = out->ankle[e] + s2[e];
}

int mt_footskate_solve(const struct mt_leg *leg, size_t frames, const double *hips, const double *parents,
                       const double *angles, const double *points, const unsigned char *planted, const double *goal,
                       const double *turn, const double *weight, const double *knee, const double *root,
                       const double *clearance, const struct mt_footskate *opt, double *out)
{
    if (check_leg(leg) != MT_OK || check_options(opt) != MT_OK || !clearance || !knee)
        return MT_EINVAL;
    if (frames == 0)
        return MT_OK;
    if (!hips || !parents || !angles || !points || !planted || !goal || !turn || !weight || !root || !out)
        return MT_EINVAL;
    double *lift_by = malloc(2 * frames * sizeof *lift_by);
    if (!lift_by)
        return MT_ENOMEM;
    double *depth = lift_by + frames;
    /* a free foot that its goals put below the floor is lifted, smoothly: by the upper envelope of
     * the depths under the bump smoothstep(1 - |distance| / (half + 1)), half = blend / 2 */
    for (size_t t = 0; t < frames; t++) {
        depth[t] = 0;
        if (planted[2 * t] || planted[2 * t + 1])
            continue;
        const double *p = points + 15 * t, *ankle = p + 3;
        double q[9], low = 0;
        rotvec_exp(turn + 3 * t, q);
        for (int k = HEEL; k <= BALL; k++) { /* the point where the goals put it: goal + turn (point - ankle) */
            const double *point = p + (k == HEEL ? 9 : 6);
            double arm[3], at[3];
            for (int e = 0; e < 3; e++)
                arm[e] = point[e] - ankle[e];
            mat_vec(q, arm, at);
            for (int e = 0; e < 3; e++)
                at[e] += goal[3 * t + e];
            const double h = height(opt, at) - clearance[k];
            low = k == HEEL || h < low ? h : low;
        }
        depth[t] = low < 0 ? -low : 0.0;
    }
    const size_t half = opt->blend / 2;
    double *bump = malloc((half + 1) * sizeof *bump);
    if (!bump) {
        free(lift_by);
        return MT_ENOMEM;
    }
    for (size_t k = 1; k <= half; k++)
        bump[k] = smoothstep(1 - (double)k / (double)(half + 1));
    for (size_t t = 0; t < frames; t++) {
        double best = depth[t];
        if (!(planted[2 * t] || planted[2 * t + 1]))
            for (size_t k = 1; k <= half; k++) {
                if (t >= k && bump[k] * depth[t - k] > best)
                    best = bump[k] * depth[t - k];
                if (t + k < frames && bump[k] * depth[t + k] > best)
                    best = bump[k] * depth[t + k];
            }
        lift_by[t] = planted[2 * t] || planted[2 * t + 1] ? 0.0 : best;
    }
    free(bump);
    const struct solve_job job = {leg,  opt,  hips, parents,   angles,  goal,
                                  turn, knee, root, clearance, lift_by, planted};
    memcpy(out, angles, 12 * frames * sizeof *out);
    for (size_t t0 = 0; t0 < frames; t0 += BLOCK) {
        const size_t n = frames - t0 < BLOCK ? frames - t0 : BLOCK;
        /* frames to solve, frames with the toe tip below the floor */
        int todo[BLOCK], low_toes[BLOCK], solving = 0, touched = 0;
        for (size_t f = 0; f < n; f++) {
            const size_t t = t0 + f;
            const double *r = root + 3 * t;
            todo[f] = planted[2 * t] || planted[2 * t + 1] || weight[t] > 0 || r[0] != 0 || r[1] != 0 || r[2] != 0 ||
                      lift_by[t] > 0;
            low_toes[f] = height(opt, points + 15 * t + 12) < clearance[2];
            solving |= todo[f];
            touched |= todo[f] || low_toes[f];
        }
        if (!touched)
            continue; /* untouched, toes above the floor */
        struct pose_block pose;
        struct solved solved;
        double ball[3 * BLOCK];
        pose_block(leg, n, hips + 3 * t0, parents + 9 * t0, angles + 12 * t0, &pose);
        if (solving)
            solve_block(&job, t0, n, &pose, &solved, ball);
        for (size_t f = 0; f < n; f++) {
            if (!todo[f] && !low_toes[f])
                continue;
            double *result = out + 12 * (t0 + f), foot_now[9], ball_now[3], toe_local[9];
            for (int e = 0; e < 9; e++) {
                foot_now[e] = todo[f] ? solved.foot[e * BLOCK + f] : pose.foot[e * BLOCK + f];
                toe_local[e] = pose.local[3][e * BLOCK + f];
            }
            for (int e = 0; e < 3; e++)
                ball_now[e] = todo[f] ? ball[e * BLOCK + f] : pose.point[2][e * BLOCK + f];
            if (todo[f])
                for (int c = 0; c < 12; c++)
                    result[c] = solved.angles[c * BLOCK + f];
            bend_toes(leg, foot_now, ball_now, toe_local, clearance[2], opt, result + 9);
        }
    }
    free(lift_by);
    return MT_OK;
}

/* ---------------------------------------------------------------- the channels */

int mt_footskate_write(size_t legs, size_t frames, size_t channels, const double *values, const double *angles,
                       const double *solved, const long long *columns, double angle_scale, const double *root,
                       const long long *root_columns, double *out)
{
    if (legs > 2 || !columns || !root_columns || !(angle_scale != 0 && isfinite(angle_scale)))
        return MT_EINVAL;
    /* the slots written, as (leg, slot) and column: each column once */
    size_t slot[24], column[27], count = 0;
    for (size_t i = 0; i < 12 * legs; i++) {
        if (columns[i] < -1 || columns[i] >= (long long)channels)
            return MT_EINVAL;
        if (columns[i] >= 0)
            slot[count] = i, column[count++] = (size_t)columns[i];
    }
    for (int e = 0; e < 3; e++) {
        if (root_columns[e] < 0 || root_columns[e] >= (long long)channels)
            return MT_EINVAL;
        column[count + (size_t)e] = (size_t)root_columns[e];
    }
    for (size_t a = 0; a < count + 3; a++)
        for (size_t b = 0; b < a; b++)
            if (column[a] == column[b])
                return MT_EINVAL;
    if (frames == 0)
        return MT_OK;
    if (!values || !out || (count > 0 && (!angles || !solved)) || !root)
        return MT_EINVAL;
    for (size_t t = 0; t < frames; t++) {
        const double *in = values + t * channels;
        double *row = out + t * channels;
        memcpy(row, in, channels * sizeof *row);
        for (size_t k = 0; k < count; k++) {
            const size_t at = ((slot[k] / 12) * frames + t) * 12 + slot[k] % 12;
            if (solved[at] != angles[at])
                row[column[k]] = solved[at] / angle_scale;
        }
        for (int e = 0; e < 3; e++)
            if (root[3 * t + e] != 0)
                row[column[count + (size_t)e]] = in[column[count + (size_t)e]] + root[3 * t + e];
    }
    return MT_OK;
}

/* ---------------------------------------------------------------- speeds */

/* |a - b| * rate, scaled by half for a central difference */
static double step_length(const double *a, const double *b, double half, double rate)
{
    const double x = (a[0] - b[0]) / half, y = (a[1] - b[1]) / half, z = (a[2] - b[2]) / half;
    return sqrt(x * x + y * y + z * z) * rate;
}

int mt_point_speeds(const double *points, size_t tracks, size_t frames, size_t per_frame, const size_t *which,
                    size_t count, double rate, double *speed, double *central)
{
    if (tracks == 0 || frames == 0 || count == 0)
        return MT_OK;
    if (!points || !which || !speed)
        return MT_EINVAL;
    for (size_t k = 0; k < count; k++)
        if (which[k] >= per_frame)
            return MT_EINVAL;
    for (size_t i = 0; i < tracks; i++)
        for (size_t k = 0; k < count; k++) {
            const double *p = points + 3 * (i * frames * per_frame + which[k]);
            double *s = speed + (i * count + k) * frames, *c = central ? central + (i * count + k) * frames : NULL;
            const size_t stride = 3 * per_frame;
            point_speed(p, frames, stride, NULL, NULL, rate, s);
            if (!c)
                continue;
            c[0] = s[0];
            for (size_t t = 1; t + 1 < frames; t++)
                c[t] = step_length(p + (t + 1) * stride, p + (t - 1) * stride, 2.0, rate);
            c[frames - 1] = s[frames - 1];
        }
    return MT_OK;
}

/* ---------------------------------------------------------------- footplants */

struct plant_row {
    const double *h, *speed, *central;
    const struct mt_plant_thresholds *th;
    unsigned char *mask;
};

static int sure_at(const struct plant_row *r, size_t t)
{
    return r->h[t] < r->th->sure_height && r->central[t] < r->th->sure_speed;
}

static int close_at(const struct plant_row *r, size_t t)
{
    return (r->h[t] < r->th->height && r->speed[t] < r->th->speed) || sure_at(r, t);
}

static int firm_at(const struct plant_row *r, size_t t)
{
    return (r->h[t] < r->th->firm_height && r->speed[t] < r->th->firm_speed) || sure_at(r, t);
}

/* plant [s, e): cut back to its still frames, kept if long enough or sure somewhere */
static void finish_plant(const struct plant_row *r, size_t s, size_t e)
{
    double lowest = r->h[s];
    for (size_t t = s + 1; t < e; t++) /* as numpy.minimum: NaN if any is */
        lowest = lowest != lowest || r->h[t] != r->h[t] ? lowest + r->h[t] : r->h[t] < lowest ? r->h[t] : lowest;
    size_t first = e, last = s;
    for (size_t t = s; t < e; t++)
        if (r->h[t] <= lowest + r->th->rise || sure_at(r, t)) {
            first = first < t ? first : t;
            last = t + 1;
        }
    if (last <= first)
        return;
    int sure = 0;
    for (size_t t = first; t < last && !sure; t++)
        sure = sure_at(r, t);
    if (last - first >= r->th->shortest || sure)
        memset(r->mask + first, 1, last - first);
}

int mt_plant_masks(const double *heights, const double *speed, const double *central, size_t rows, size_t n,
                   const struct mt_plant_thresholds *th, unsigned char *mask)
{
    if (!th)
        return MT_EINVAL;
    if (rows == 0 || n == 0)
        return MT_OK;
    if (!heights || !speed || !central || !mask)
        return MT_EINVAL;
    for (size_t i = 0; i < rows; i++) {
        const struct plant_row r = {heights + i * n, speed + i * n, central + i * n, th, mask + i * n};
        memset(r.mask, 0, n);
        int open = 0; /* a plant [s, e) is being gathered */
        size_t s = 0, e = 0;
        for (size_t t = 0; t < n;) {
            if (!close_at(&r, t)) {
                t++;
                continue;
            }
            size_t end = t, firm = 0; /* the run of close frames [t, end) */
            for (; end < n && close_at(&r, end); end++)
                firm += (size_t)firm_at(&r, end);
            if (firm) {
                int slow = open && t - e <= th->gap;
                for (size_t u = e; slow && u < t; u++)
                    slow = r.speed[u] < th->merge_speed;
                if (!slow) {
                    if (open)
                        finish_plant(&r, s, e);
                    s = t, open = 1;
                }
                e = end;
            }
            t = end;
        }
        if (open)
            finish_plant(&r, s, e);
    }
    return MT_OK;
}
