/*
 * footskate.c - footskate cleanup of legs over frames (Kovar, Schreiner &
 * Gleicher, SCA 2002), see mtcore.h.
 *
 * A leg is four joints turning thigh, shin, foot and toes.  Per frame and leg
 * the kernels rebuild the leg from its hip point, its hip's parent rotation
 * and its channels (pose_block), and solve it analytically; frames interact only
 * through the plants' targets (phase 1, in frame order), the blending of
 * adjustments around constraints (phase 2), the root's smoothing (phase 3)
 * and the lifting of a sinking foot (phase 5).  The Python twin in
 * tests/footskate_twin.py computes the same, phase by phase, in numpy.
 */
#include "blocks.h"
#include "clones.h"
#include "mtcore.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double pi = 3.14159265358979323846;
static const double tiny = 1e-12; /* below this a length or sine counts as zero */
enum { HEEL = 0, BALL = 1 };

/* ---------------------------------------------------------------- vectors and rotations */

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double *a, const double *b, double *out)
{
    const double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}

static double norm3(const double *a)
{
    return sqrt(dot3(a, a));
}

static void unit3(const double *a, double *out)
{
    const double n = norm3(a);
    for (int e = 0; e < 3; e++)
        out[e] = n > 0 ? a[e] / n : 0.0;
}

/* out = a with its component along the unit vector e removed */
static void perpendicular(const double *a, const double *e, double *out)
{
    const double d = dot3(a, e);
    for (int c = 0; c < 3; c++)
        out[c] = a[c] - d * e[c];
}

static void mat_vec(const double *m, const double *v, double *out)
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = m[3 * i] * v[0] + m[3 * i + 1] * v[1] + m[3 * i + 2] * v[2];
    memcpy(out, r, sizeof r);
}

/* out = m^T v */
static void mat_tvec(const double *m, const double *v, double *out)
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = m[i] * v[0] + m[3 + i] * v[1] + m[6 + i] * v[2];
    memcpy(out, r, sizeof r);
}

/* out = a b (out may be a or b) */
static void mat_mul(const double *a, const double *b, double *out)
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            r[3 * i + k] = a[3 * i] * b[k] + a[3 * i + 1] * b[3 + k] + a[3 * i + 2] * b[6 + k];
    memcpy(out, r, sizeof r);
}

/* out = a^T b */
static void mat_tmul(const double *a, const double *b, double *out)
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            r[3 * i + k] = a[i] * b[k] + a[3 + i] * b[3 + k] + a[6 + i] * b[6 + k];
    memcpy(out, r, sizeof r);
}

/* out = a b^T */
static void mat_mult(const double *a, const double *b, double *out)
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            r[3 * i + k] = a[3 * i] * b[3 * k] + a[3 * i + 1] * b[3 * k + 1] + a[3 * i + 2] * b[3 * k + 2];
    memcpy(out, r, sizeof r);
}

/* The rotation about the unit axis by the angle of cosine c and sine s (Rodrigues). */
static void about_cs(const double *axis, double c, double s, double *out)
{
    const double x = axis[0], y = axis[1], z = axis[2], t = 1 - c;
    out[0] = c + t * x * x, out[1] = t * x * y - s * z, out[2] = t * x * z + s * y;
    out[3] = t * x * y + s * z, out[4] = c + t * y * y, out[5] = t * y * z - s * x;
    out[6] = t * x * z - s * y, out[7] = t * y * z + s * x, out[8] = c + t * z * z;
}

/* The rotation by angle about the unit axis. */
static void about(const double *axis, double angle, double *out)
{
    about_cs(axis, cos(angle), sin(angle), out);
}

/* The smallest rotation taking the direction of u onto that of v (a half turn for opposite ones). */
static void between(const double *u0, const double *v0, double *out)
{
    double u[3], v[3], axis[3];
    unit3(u0, u);
    unit3(v0, v);
    cross3(u, v, axis);
    const double s = norm3(axis), c = dot3(u, v);
    if (c > -0.5) { /* R = c I + [k]x + k k^T / (1 + c), k = u x v: no trigonometry */
        const double f = 1 / (1 + c), *k = axis;
        out[0] = c + f * k[0] * k[0], out[1] = -k[2] + f * k[0] * k[1], out[2] = k[1] + f * k[0] * k[2];
        out[3] = k[2] + f * k[1] * k[0], out[4] = c + f * k[1] * k[1], out[5] = -k[0] + f * k[1] * k[2];
        out[6] = -k[1] + f * k[2] * k[0], out[7] = k[0] + f * k[2] * k[1], out[8] = c + f * k[2] * k[2];
        return;
    }
    if (s > tiny) {
        unit3(axis, axis);
        about(axis, atan2(s, c), out);
        return;
    }
    const double other[3] = {fabs(u[0]) < 0.9, fabs(u[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    cross3(u, other, axis);
    unit3(axis, axis);
    about(axis, c < 0 ? pi : 0.0, out);
}

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

static void rotvec_exp(const double *v, double *m)
{
    double axis[3];
    unit3(v, axis);
    about(axis, norm3(v), m);
}

/* whole turns nearest to x / 2 pi; below 3 (0.48 turn) that is 0, the common case, without the call */
static double round_turns(double x)
{
    return fabs(x) < 3.0 ? 0.0 : nearbyint(x / (2 * pi));
}

/* angle plus the whole turns that bring it nearest to ref */
static double wrap_near(double angle, double ref)
{
    return angle + 2 * pi * round_turns(ref - angle);
}

static double wrap(double angle)
{
    return angle - 2 * pi * round_turns(angle);
}

/* sqrt(x^2 + y^2) without hypot's care for overflow, which costs a call: the arguments here are
 * coordinates of unit vectors and of a human's limbs, far from the limits of a double */
static double length2(double x, double y)
{
    return sqrt(x * x + y * y);
}

static double clip(double x, double lo, double hi)
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

/* m = R(axis) m, R the rotation about a coordinate axis of the given sine and cosine: it mixes two rows */
static void rotate_left(double *m, int axis, double s, double c)
{
    double *ra = m + 3 * (axis == 0 ? 1 : axis == 1 ? 2 : 0), *rb = m + 3 * (axis == 0 ? 2 : axis == 1 ? 0 : 1);
    for (int k = 0; k < 3; k++) {
        const double a = ra[k], b = rb[k];
        ra[k] = c * a - s * b;
        rb[k] = s * a + c * b;
    }
}

/* v = R(axis) v, R as for rotate_left */
static void rotate_vector(double *v, int axis, double s, double c)
{
    const int p = axis == 0 ? 1 : axis == 1 ? 2 : 0, q = axis == 0 ? 2 : axis == 1 ? 0 : 1;
    const double a = v[p], b = v[q];
    v[p] = c * a - s * b;
    v[q] = s * a + c * b;
}

static int is_identity(const double *m)
{
    return m[0] == 1 && m[1] == 0 && m[2] == 0 && m[3] == 0 && m[4] == 1 && m[5] == 0 && m[6] == 0 && m[7] == 0 &&
           m[8] == 1;
}

/* m = m R(axis), R as for rotate_left: it mixes two columns */
static void rotate_right(double *m, int axis, double s, double c)
{
    const int p = axis == 0 ? 1 : axis == 1 ? 2 : 0, q = axis == 0 ? 2 : axis == 1 ? 0 : 1;
    for (int k = 0; k < 9; k += 3) {
        const double a = m[k + p], b = m[k + q];
        m[k + p] = c * a + s * b;
        m[k + q] = -s * a + c * b;
    }
}

/* L = C M C^T of joint j, M its channels' rotations (given by the sines and cosines of their angles),
 * each about a fixed axis after the ones before: C M built by turning C's columns, the last first. */
static void local_rotation_of(const struct mt_leg *leg, int j, const double *sines, const double *cosines, double *out)
{
    const int count = channels(leg, j);
    if (is_identity(leg->axis[j])) {
        double m[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        for (int n = 0; n < count; n++)
            rotate_left(m, leg->axes[j][n], sines[n], cosines[n]);
        memcpy(out, m, sizeof m);
        return;
    }
    if (count == 1) { /* C R C^T is the turn about C's column of the channel's axis: Rodrigues, no products */
        const double *c = leg->axis[j];
        const int a = leg->axes[j][0];
        const double u[3] = {c[a], c[3 + a], c[6 + a]};
        about_cs(u, cosines[0], sines[0], out);
        return;
    }
    double m[9];
    memcpy(m, leg->axis[j], sizeof m);
    for (int n = count - 1; n >= 0; n--)
        rotate_right(m, leg->axes[j][n], sines[n], cosines[n]);
    mat_mult(m, leg->axis[j], out);
}

static void local_rotation(const struct mt_leg *leg, int j, const double *angles, double *out)
{
    double sines[3], cosines[3];
    for (int n = 0; n < channels(leg, j); n++)
        sines[n] = sin(angles[n]), cosines[n] = cos(angles[n]);
    local_rotation_of(leg, j, sines, cosines, out);
}

/*
 * Angles about fixed axes (i, j, k) applying in order, M = R_k(c) R_j(b) R_i(a),
 * of the rotation m (proper Euler when k = i): of the two solutions, the one
 * nearest ref, each angle whole turns from it.  b and c come from column i of
 * m, a from row j of R_last(-c) m, which is row j of R_i(a); at gimbal lock c
 * is ref's and a makes up the rest.
 */
static void euler_nearest(const double *m, const int *axes, const double *ref, double *out)
{
    const int i = axes[0], j = axes[1], proper = axes[2] == i, k = proper ? 3 - i - j : axes[2];
    const double eps = (j - i + 3) % 3 == 1 ? 1.0 : -1.0;
#define M(r, c) m[3 * (r) + (c)]
    double a, b, c, h;
    int last;
    if (proper) {
        h = length2(M(j, i), M(k, i));
        b = atan2(h, M(i, i));
        c = h < 1e-9 ? ref[2] : atan2(M(j, i), -eps * M(k, i));
        last = i;
    } else {
        h = length2(M(i, i), M(j, i));
        b = atan2(-eps * M(k, i), h);
        c = h < 1e-9 ? ref[2] : atan2(eps * M(j, i), M(i, i));
        last = k;
    }
#undef M
    const int lock = h < 1e-9;
    /* row j of R_last(-c) m: R_last turns rows (p, q) of what it multiplies, as rotate_left does */
    const double cc = lock ? cos(c) : (proper ? -eps * m[3 * k + i] : m[3 * i + i]) / h;
    const double sc = lock ? sin(c) : (proper ? m[3 * j + i] : eps * m[3 * j + i]) / h;
    const int p = last == 0 ? 1 : last == 1 ? 2 : 0, q = last == 0 ? 2 : last == 1 ? 0 : 1;
    double row[3];
    for (int e = 0; e < 3; e++) /* R(-c): rows p' = c p + s q, q' = -s p + c q */
        row[e] = j == p ? cc * m[3 * p + e] + sc * m[3 * q + e] : -sc * m[3 * p + e] + cc * m[3 * q + e];
    a = atan2(-eps * row[k], row[j]);
    const double first[3] = {wrap_near(a, ref[0]), wrap_near(b, ref[1]), wrap_near(c, ref[2])};
    const double second[3] = {wrap_near(a + pi, ref[0]), wrap_near((proper ? 0.0 : pi) - b, ref[1]),
                              wrap_near(c + pi, ref[2])};
    double d1 = 0, d2 = 0;
    for (int e = 0; e < 3; e++)
        d1 += (first[e] - ref[e]) * (first[e] - ref[e]), d2 += (second[e] - ref[e]) * (second[e] - ref[e]);
    memcpy(out, d2 < d1 && !lock ? second : first, sizeof first);
}

/*
 * The angles of joint j nearest to the wanted local rotation that its
 * channels can take: three give it exactly; two turn the body vector aim
 * where wanted turns it; one turns aim as near as its axis allows; none keep
 * ref.  Angles are whole turns from ref.  With one or two channels, sines and
 * cosines receive those of the angles found (for local_rotation_of).
 */
static void realize(const struct mt_leg *leg, int j, const double *wanted, const double *aim, const double *ref,
                    double *out, double *sines, double *cosines)
{
    const int count = channels(leg, j);
    const double *c = leg->axis[j];
    memcpy(out, ref, 3 * sizeof *out);
    if (count == 3) {
        double m[9];
        mat_tmul(c, wanted, m);
        mat_mul(m, c, m);
        euler_nearest(m, leg->axes[j], ref, out);
        return;
    }
    if (count == 0)
        return;
    double p[3], q[3], turned[3];
    mat_tvec(c, aim, p);
    unit3(p, p);
    mat_vec(wanted, aim, turned);
    mat_tvec(c, turned, q);
    unit3(q, q);
    if (count == 1) {
        const int axis = leg->axes[j][0];
        const double e[3] = {axis == 0, axis == 1, axis == 2};
        double pp[3], qq[3], n[3];
        perpendicular(p, e, pp);
        perpendicular(q, e, qq);
        cross3(pp, qq, n);
        const double y = dot3(e, n), x = dot3(pp, qq), h = length2(x, y);
        out[0] = wrap_near(atan2(y, x), ref[0]);
        sines[0] = h > 0 ? y / h : 0.0, cosines[0] = h > 0 ? x / h : 1.0;
        return;
    }
    const int ai = leg->axes[j][0], aj = leg->axes[j][1];
    const double ei[3] = {ai == 0, ai == 1, ai == 2}, ej[3] = {aj == 0, aj == 1, aj == 2};
    double eip[3];
    cross3(ei, p, eip);
    const double big_a = p[aj], big_b = eip[aj], rho = length2(big_a, big_b);
    if (!(rho > tiny)) { /* aim along the first axis: nothing to turn, the angles kept */
        for (int n = 0; n < 2; n++)
            sines[n] = sin(ref[n]), cosines[n] = cos(ref[n]);
        return;
    }
    const double kappa = clip(q[aj] / rho, -1.0, 1.0), base = atan2(big_b, big_a), spread = acos(kappa);
    /* sines and cosines of base +- spread by the angle sums, from base's (B, A) / rho and spread's cosine */
    const double cb = big_a / rho, sb = big_b / rho, ss = sqrt(1 - kappa * kappa);
    double best[6] = {0, 0, 0, 1, 0, 1}, best_cost = 0; /* a, b, sin a, cos a, sin b, cos b */
    for (int s = 0; s < 2; s++) {
        double v[3], rp[3], qp[3], n[3];
        const double sign = s == 0 ? 1.0 : -1.0;
        const double a = wrap_near(base + sign * spread, ref[0]);
        const double sa = sb * kappa + sign * cb * ss, ca = cb * kappa - sign * sb * ss;
        memcpy(v, p, sizeof v);
        rotate_vector(v, ai, sa, ca);
        perpendicular(v, ej, rp);
        perpendicular(q, ej, qp);
        cross3(rp, qp, n);
        const double y = dot3(ej, n), x = dot3(rp, qp), h = length2(x, y);
        const double b = wrap_near(atan2(y, x), ref[1]);
        const double cost = (a - ref[0]) * (a - ref[0]) + (b - ref[1]) * (b - ref[1]);
        if (s == 0 || cost < best_cost) {
            const double pick[6] = {a, b, sa, ca, h > 0 ? y / h : 0.0, h > 0 ? x / h : 1.0};
            memcpy(best, pick, sizeof best);
            best_cost = cost;
        }
    }
    out[0] = best[0], out[1] = best[1];
    sines[0] = best[2], cosines[0] = best[3], sines[1] = best[4], cosines[1] = best[5];
}

/* ---------------------------------------------------------------- legs */

struct leg_pose {
    double local[4][9]; /* hip, knee, ankle and toe joints' local rotations */
    double foot[9];     /* the foot's world rotation */
    double point[5][3]; /* knee, ankle, ball, heel, tip */
};

/* The poses of up to BLOCK consecutive frames, each quantity an array over them (see blocks.h). */
struct pose_block {
    double local[4][9][BLOCK];
    double foot[9][BLOCK];
    double point[5][3][BLOCK];
};

/*
 * The poses of frames 0 .. n-1 (n <= BLOCK) of hips, parents and angles
 * (lanes past n repeat the last frame), so that the loops over frames, sin
 * and cos included, vectorise: L = C M C^T as forward kinematics builds it
 * (M turned from the identity, channel by channel).
 */
static MT_CLONES void pose_block(const struct mt_leg *leg, size_t n, const double *hips, const double *parents,
                                 const double *angles, struct pose_block *out)
{
    size_t row[BLOCK];
    for (size_t f = 0; f < BLOCK; f++)
        row[f] = f < n ? f : n - 1;
    for (int j = 0; j < 4; j++) {
        double m[9][BLOCK], v[BLOCK], sn[BLOCK], cs[BLOCK];
        for (int e = 0; e < 9; e++)
            for (int f = 0; f < BLOCK; f++)
                m[e][f] = identity[e];
        for (int c = 0; c < 3 && leg->axes[j][c] >= 0; c++) {
            for (int f = 0; f < BLOCK; f++)
                v[f] = angles[12 * row[f] + 3 * (size_t)j + (size_t)c];
            sincos_block(v, sn, cs);
            rotate_left_block(m, leg->axes[j][c], sn, cs);
        }
        if (memcmp(leg->axis[j], identity, sizeof identity) == 0)
            memcpy(out->local[j], m, sizeof m);
        else
            conjugate_block(leg->axis[j], m, out->local[j]);
    }
    double parent[9][BLOCK], thigh[9][BLOCK], shin[9][BLOCK], toes[9][BLOCK];
    for (int e = 0; e < 9; e++)
        for (int f = 0; f < BLOCK; f++)
            parent[e][f] = parents[9 * row[f] + (size_t)e];
    multiply_block(parent, out->local[0], thigh);
    multiply_block(thigh, out->local[1], shin);
    multiply_block(shin, out->local[2], out->foot);
    multiply_block(out->foot, out->local[3], toes);
    /* each point: the one it hangs from plus its segment turned by the rotation that turns it (the
     * segments and points local, so that the compiler need not fear they alias) */
    double s[5][3], p[5][3][BLOCK];
    memcpy(s, leg->segment, sizeof s);
    for (int e = 0; e < 3; e++)
        for (int f = 0; f < BLOCK; f++) {
            p[0][e][f] = hips[3 * row[f] + (size_t)e] + thigh[3 * e][f] * s[0][0] + thigh[3 * e + 1][f] * s[0][1] +
                         thigh[3 * e + 2][f] * s[0][2];
            p[1][e][f] = p[0][e][f] + shin[3 * e][f] * s[1][0] + shin[3 * e + 1][f] * s[1][1] +
                         shin[3 * e + 2][f] * s[1][2];
            p[2][e][f] = p[1][e][f] + out->foot[3 * e][f] * s[2][0] + out->foot[3 * e + 1][f] * s[2][1] +
                         out->foot[3 * e + 2][f] * s[2][2];
            p[3][e][f] = p[1][e][f] + out->foot[3 * e][f] * s[3][0] + out->foot[3 * e + 1][f] * s[3][1] +
                         out->foot[3 * e + 2][f] * s[3][2];
            p[4][e][f] = p[2][e][f] + toes[3 * e][f] * s[4][0] + toes[3 * e + 1][f] * s[4][1] +
                         toes[3 * e + 2][f] * s[4][2];
        }
    memcpy(out->point, p, sizeof p);
}

/* frame f of a block */
static void pose_at(const struct pose_block *block, size_t f, struct leg_pose *pose)
{
    for (int e = 0; e < 9; e++) {
        for (int j = 0; j < 4; j++)
            pose->local[j][e] = block->local[j][e][f];
        pose->foot[e] = block->foot[e][f];
    }
    for (int k = 0; k < 5; k++)
        for (int e = 0; e < 3; e++)
            pose->point[k][e] = block->point[k][e][f];
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
                        points[15 * (f0 + f) + 3 * (size_t)k + (size_t)e] = block.point[k][e][f];
                if (feet)
                    for (int e = 0; e < 9; e++)
                        feet[9 * (f0 + f) + (size_t)e] = block.foot[e][f];
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

struct hinge {
    double base, rho, phi; /* |hip -> ankle|^2 = base + 2 rho cos(delta - phi) turning the knee by delta */
    double cos_phi, sin_phi;
};

static struct hinge hinge_of(const struct mt_leg *leg, const double *knee_local, const double *axis)
{
    const double *s1 = leg->segment[0];
    double u[3], au[3];
    mat_vec(knee_local, leg->segment[1], u);
    cross3(axis, u, au);
    const double c0 = dot3(s1, axis) * dot3(u, axis), x = dot3(s1, u) - c0, y = dot3(s1, au);
    const double rho = length2(x, y);
    struct hinge h = {dot3(s1, s1) + dot3(u, u) + 2 * c0, rho, atan2(y, x), rho > 0 ? x / rho : 1.0,
                      rho > 0 ? y / rho : 0.0};
    return h;
}

/* the longest hip -> ankle distance with the knee bent at least min(soft, its bend now), and keep times it */
static double reach(struct hinge h, double soft, double keep)
{
    const double now = fabs(wrap(-h.phi)), least = now < soft ? now : soft;
    const double bend = keep * now > least ? keep * now : least;
    /* the bend now is phi's (cos is even and whole turns round): its cosine without a call */
    const double r2 = h.base + 2 * h.rho * (bend == now ? h.cos_phi : cos(bend));
    return sqrt(r2 > 0 ? r2 : 0.0);
}

/* ---------------------------------------------------------------- phases 1 and 2 */

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
    const double *s = leg->segment[0];
    double axis[3];
    /* the knee's hinge: its channel's axis, or the mean bend axis of the take */
    if (channels(leg, 1) == 1) {
        const int a = leg->axes[1][0];
        for (int e = 0; e < 3; e++)
            axis[e] = leg->axis[1][3 * e + a];
    } else {
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
    memcpy(knee, axis, sizeof axis);
    knee[3] = 1.0;
    if (frames == 0)
        return MT_OK;
    double *partner = malloc(3 * frames * sizeof *partner), *pinlog = malloc(3 * frames * sizeof *pinlog);
    unsigned char *masks = malloc(2 * frames + 1);
    if (!partner || !pinlog || !masks) {
        free(partner), free(pinlog), free(masks);
        return MT_ENOMEM;
    }
    /* the knee's reach and the side it bends to */
    double sides = 0;
    for (size_t t = 0; t < frames; t++) {
        double knee_local[9];
        local_rotation(leg, 1, angles + 12 * t + 3, knee_local);
        const struct hinge h = hinge_of(leg, knee_local, axis);
        const double w = wrap(-h.phi);
        sides += (w > 0) - (w < 0);
        reaches[t] = reach(h, opt->knee_soft, opt->knee_keep);
    }
    memcpy(knee, axis, sizeof axis);
    knee[3] = sides >= 0 ? 1.0 : -1.0;
    unsigned char *pins = masks, *some = masks + frames;
    double foot[3];
    for (int e = 0; e < 3; e++)
        foot[e] = leg->segment[2][e] - leg->segment[3][e];
    enforce_targets(planted, targets, clearance, norm3(foot), opt, frames, enforced, partner);

    /* the pinned turns: both points planted, or a roll from one to the other */
    for (size_t t = 0; t < frames; t++) {
        const unsigned char *now = planted + 2 * t;
        const double *ball = points + 15 * t + 6, *heel = points + 15 * t + 9;
        const int rolled = !isnan(partner[3 * t]);
        some[t] = now[HEEL] || now[BALL];
        pins[t] = (now[HEEL] && now[BALL]) || rolled;
        memset(pinlog + 3 * t, 0, 3 * sizeof *pinlog);
        if (!pins[t])
            continue;
        const double *heel_goal = rolled && now[BALL] ? partner + 3 * t : enforced + 6 * t;
        const double *ball_goal = rolled && now[HEEL] ? partner + 3 * t : enforced + 6 * t + 3;
        double from[3], to[3], r[9];
        for (int e = 0; e < 3; e++)
            from[e] = ball[e] - heel[e], to[e] = ball_goal[e] - heel_goal[e];
        between(from, to, r);
        rotvec_of(r, pinlog + 3 * t);
    }
    /* constrained frames: the turn blended from the pins (raised about the pivot where one point is
     * planted and the other below the floor), the ankle following the planted point; goal holds the
     * ankle's shift for now */
    struct neighbours around;
    neighbours_start(&around, pins, frames, opt->blend);
    for (size_t t = 0; t < frames; t++) {
        double wp, wn;
        neighbours_at(&around, t, &wp, &wn);
        if (!some[t])
            continue;
        const unsigned char *now = planted + 2 * t;
        const double *ankle = points + 15 * t + 3;
        double log[3], q[9];
        if (pins[t])
            memcpy(log, pinlog + 3 * t, sizeof log);
        else
            for (int e = 0; e < 3; e++)
                log[e] = (around.prev >= 0 ? wp * pinlog[3 * around.prev + e] : 0.0) +
                         (around.next >= 0 ? wn * pinlog[3 * around.next + e] : 0.0);
        rotvec_exp(log, q);
        const int on_ball = now[BALL] && !now[HEEL];
        const double *pivot = points + 15 * t + (on_ball ? 6 : 9), *other = points + 15 * t + (on_ball ? 9 : 6);
        const double *target = enforced + 6 * t + 3 * on_ball;
        if ((!now[HEEL] || !now[BALL]) && isnan(partner[3 * t])) {
            double arm[3], lever[3], r[9];
            for (int e = 0; e < 3; e++)
                arm[e] = other[e] - pivot[e];
            mat_vec(q, arm, lever);
            raise_lever(lever, target, clearance[on_ball ? HEEL : BALL], opt, r);
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
    /* free frames: shift and turn blended from the constrained frames (which this pass does not change) */
    neighbours_start(&around, some, frames, opt->blend);
    for (size_t t = 0; t < frames; t++) {
        double wp, wn;
        neighbours_at(&around, t, &wp, &wn);
        if (some[t]) {
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
    for (size_t t = 0; t < frames; t++) /* goals from shifts */
        for (int e = 0; e < 3; e++)
            goal[3 * t + e] += points[15 * t + 3 + e];
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

struct solved {
    double angles[12];
    double knee_delta;  /* the turn about the knee's hinge */
    double wanted[3][9]; /* the local rotations asked of hip, knee and ankle */
    double foot[9];
    double ankle[3];
};

/*
 * Two-bone IK of one frame: the knee bends about its hinge so that hip ->
 * ankle has the goal's length (within the knee's reach, never past straight,
 * to the side it bends), the hip turns the leg onto the goal, the ankle
 * takes foot_goal (its aim exactly, with fewer than three channels).  Joints
 * that take the rotation asked exactly (three channels; a one-channel knee
 * turning about its channel's axis) are left for finish_angles: a foot
 * re-aimed solves the leg again, and their Euler angles are needed once.
 */
static void two_bone(const struct mt_leg *leg, const double *hip, const double *parent, const double *angles,
                     const struct leg_pose *pose, const struct hinge *h, const double *knee, double soft,
                     const double *ankle_goal, const double *foot_goal, const double *aim, struct solved *out)
{
    const double *s1 = leg->segment[0], *s2 = leg->segment[1];
    memcpy(out->angles, angles, sizeof out->angles);
    double goal[3];
    for (int e = 0; e < 3; e++)
        goal[e] = ankle_goal[e] - hip[e];
    const double longest = reach(*h, soft, 0.0), low2 = h->base - 2 * h->rho;
    const double shortest = sqrt(low2 > 0 ? low2 : 0.0);
    const double d = clip(norm3(goal), shortest, longest);
    const double cosine = clip((d * d - h->base) / (2 * (h->rho > tiny ? h->rho : 1.0)), -1.0, 1.0);
    const double bend = h->rho > tiny ? acos(cosine) : 0.0;
    double r[9], knee_local[9], thigh[9], shin[9], v[3], leg_vector[3], world[3], hip_local[9], sines[3], cosines[3];
    out->knee_delta = h->phi + knee[3] * bend;
    /* cos and sin of phi + side bend by the angle sums: phi's from the hinge, bend's from its cosine */
    const double sin_bend = sqrt(1 - cosine * cosine) * (h->rho > tiny), cos_bend = h->rho > tiny ? cosine : 1.0;
    about_cs(knee, h->cos_phi * cos_bend - knee[3] * h->sin_phi * sin_bend,
             h->sin_phi * cos_bend + knee[3] * h->cos_phi * sin_bend, r);
    mat_mul(r, pose->local[1], out->wanted[1]);
    if (channels(leg, 1) == 2) {
        realize(leg, 1, out->wanted[1], s2, angles + 3, out->angles + 3, sines, cosines);
        local_rotation_of(leg, 1, sines, cosines, knee_local);
    } else {
        memcpy(knee_local, out->wanted[1], sizeof knee_local);
    }
    mat_mul(parent, pose->local[0], thigh);
    mat_vec(knee_local, s2, v);
    for (int e = 0; e < 3; e++)
        leg_vector[e] = s1[e] + v[e];
    mat_vec(thigh, leg_vector, world);
    between(world, goal, r);
    mat_mul(r, thigh, out->wanted[0]);
    mat_tmul(parent, out->wanted[0], out->wanted[0]);
    if (channels(leg, 0) < 3) {
        realize(leg, 0, out->wanted[0], leg_vector, angles, out->angles, sines, cosines);
        local_rotation_of(leg, 0, sines, cosines, hip_local);
    } else {
        memcpy(hip_local, out->wanted[0], sizeof hip_local);
    }
    mat_mul(parent, hip_local, thigh);
    mat_mul(thigh, knee_local, shin);
    mat_tmul(shin, foot_goal, out->wanted[2]);
    if (channels(leg, 2) < 3) {
        realize(leg, 2, out->wanted[2], aim, angles + 6, out->angles + 6, sines, cosines);
        local_rotation_of(leg, 2, sines, cosines, r);
        mat_mul(shin, r, out->foot);
    } else {
        mat_mul(shin, out->wanted[2], out->foot);
    }
    double a[3], b[3];
    mat_vec(thigh, s1, a);
    mat_vec(shin, s2, b);
    for (int e = 0; e < 3; e++)
        out->ankle[e] = hip[e] + a[e] + b[e];
}

/* The Euler angles two_bone left: joints of three channels, and a one-channel knee (its angle plus
 * the turn about its hinge, which is its channel's axis). */
static void finish_angles(const struct mt_leg *leg, const double *angles, const double *aim, struct solved *solved)
{
    double sines[3], cosines[3];
    for (int j = 0; j < 3; j++)
        if (channels(leg, j) == 3)
            realize(leg, j, solved->wanted[j], aim, angles + 3 * j, solved->angles + 3 * j, sines, cosines);
    if (channels(leg, 1) == 1)
        solved->angles[3] = angles[3] + wrap(solved->knee_delta);
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
    const double c0 = dot3(k, axis) * dot3(u, axis), x = dot3(k, u) - c0, y = dot3(k, au);
    const double rho = length2(x, y), phi = atan2(y, x), base = height(opt, ball);
    if (!(base + dot3(k, u) < clearance_tip && rho > tiny))
        return;
    const double need = clearance_tip - base - c0; /* rho cos(delta - phi) must reach this */
    const double spread = acos(clip(need / rho, -1.0, 1.0));
    const double first = wrap(phi - spread), second = wrap(phi + spread);
    double r[9], wanted[9], ref[3];
    about(axis, fabs(first) <= fabs(second) ? first : second, r);
    mat_mul(r, toe_local, wanted);
    double sines[3], cosines[3];
    memcpy(ref, angles, sizeof ref);
    realize(leg, 3, wanted, t, ref, angles, sines, cosines);
}

/* how far the lower of heel and ball, of a foot at ankle turned to foot, is above where they rest */
static double foot_low(const struct mt_leg *leg, const double *ankle, const double *foot, const double *clearance,
                       const struct mt_footskate *opt)
{
    double v[3], p[3];
    mat_vec(foot, leg->segment[3], v);
    for (int e = 0; e < 3; e++)
        p[e] = ankle[e] + v[e];
    const double heel = height(opt, p) - clearance[HEEL];
    mat_vec(foot, leg->segment[2], v);
    for (int e = 0; e < 3; e++)
        p[e] = ankle[e] + v[e];
    const double ball = height(opt, p) - clearance[BALL];
    return heel < ball ? heel : ball;
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
    double aim[3];
    for (int e = 0; e < 3; e++)
        aim[e] = leg->segment[2][e] - leg->segment[3][e]; /* heel -> ball: what a two-channel ankle keeps */
    memcpy(out, angles, 12 * frames * sizeof *out);
    for (size_t t0 = 0; t0 < frames; t0 += BLOCK) {
        const size_t n = frames - t0 < BLOCK ? frames - t0 : BLOCK;
        int todo_at[BLOCK], low_toes[BLOCK], any = 0; /* frames to solve; frames with the toe tip below the floor */
        for (size_t f = 0; f < n; f++) {
            const size_t t = t0 + f;
            const double *r = root + 3 * t;
            todo_at[f] = planted[2 * t] || planted[2 * t + 1] || weight[t] > 0 || r[0] != 0 || r[1] != 0 ||
                         r[2] != 0 || lift_by[t] > 0;
            low_toes[f] = height(opt, points + 15 * t + 12) < clearance[2];
            any |= todo_at[f] || low_toes[f];
        }
        if (!any)
            continue; /* untouched, toes above the floor */
        struct pose_block block;
        pose_block(leg, n, hips + 3 * t0, parents + 9 * t0, angles + 12 * t0, &block);
        for (size_t f = 0; f < n; f++) {
            if (!todo_at[f] && !low_toes[f])
                continue;
            const size_t t = t0 + f;
            const unsigned char *now = planted + 2 * t;
            const int some = now[HEEL] || now[BALL], todo = todo_at[f];
            const double *r = root + 3 * t;
            double *result = out + 12 * t, foot_now[9], ball_now[3];
            struct leg_pose pose;
            pose_at(&block, f, &pose);
            memcpy(foot_now, pose.foot, sizeof foot_now);
            memcpy(ball_now, pose.point[2], sizeof ball_now);
            if (todo) {
                double hip[3], q[9], foot_goal[9], first[3], target[3];
                for (int e = 0; e < 3; e++) {
                    hip[e] = hips[3 * t + e] + r[e];
                    first[e] = goal[3 * t + e] + lift_by[t] * opt->up[e];
                }
                rotvec_exp(turn + 3 * t, q);
                mat_mul(q, pose.foot, foot_goal);
                struct solved solved;
                const struct hinge h = hinge_of(leg, pose.local[1], knee);
                two_bone(leg, hip, parents + 9 * t, angles + 12 * t, &pose, &h, knee, opt->knee_soft, first,
                         foot_goal, aim, &solved);
                memcpy(target, first, sizeof target);
                if (channels(leg, 2) < 3 && some) { /* the ankle cannot roll: re-aim it so that the pivot lands */
                    const double *pivot = leg->segment[now[HEEL] ? 3 : 2];
                    double want[3], got[3]; /* once: the miss after it is a few micrometres */
                    mat_vec(foot_goal, pivot, want);
                    mat_vec(solved.foot, pivot, got);
                    for (int e = 0; e < 3; e++)
                        target[e] = first[e] + want[e] - got[e];
                    two_bone(leg, hip, parents + 9 * t, angles + 12 * t, &pose, &h, knee, opt->knee_soft, target,
                             foot_goal, aim, &solved);
                }
                /* what the leg could not quite reach is lifted frame by frame */
                const double low = foot_low(leg, solved.ankle, solved.foot, clearance, opt);
                if (!some && low < 0) {
                    for (int e = 0; e < 3; e++)
                        target[e] -= low * opt->up[e];
                    two_bone(leg, hip, parents + 9 * t, angles + 12 * t, &pose, &h, knee, opt->knee_soft, target,
                             foot_goal, aim, &solved);
                }
                finish_angles(leg, angles + 12 * t, aim, &solved);
                memcpy(result, solved.angles, sizeof solved.angles);
                memcpy(foot_now, solved.foot, sizeof foot_now);
                double v[3];
                mat_vec(solved.foot, leg->segment[2], v);
                for (int e = 0; e < 3; e++)
                    ball_now[e] = solved.ankle[e] + v[e];
            }
            bend_toes(leg, foot_now, ball_now, pose.local[3], clearance[2], opt, result + 9);
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
