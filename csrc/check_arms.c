/*
 * check_arms.c - the take check's measure of the elbows (mt_check_elbows; see mtcore.h): how
 * the forearm turns from the upper arm, in the upper arm's own axes, about the axis the take's
 * bent frames share, frame by frame.
 */
#include "lanes.h"
#include "mtcore.h"

#include <string.h>

/* The turn n = W^T (u x f) of arm `p` at a frame, in the axes of its upper arm's world rotation
   w, and u . f (u the upper arm, f the forearm). */
static double measure(const double *at, const double *w, const size_t *p, double n[3])
{
    double arm[3], forearm[3], across[3];
    for (int c = 0; c < 3; c++) {
        arm[c] = at[3 * p[1] + c] - at[3 * p[0] + c];
        forearm[c] = at[3 * p[2] + c] - at[3 * p[1] + c];
    }
    cross3(arm, forearm, across);
    for (int c = 0; c < 3; c++)
        n[c] = w[c] * across[0] + w[3 + c] * across[1] + w[6 + c] * across[2];
    return dot3(arm, forearm);
}

/* Whether a frame bends past the angle whose tangent is tan_bent: u . f = s, |n| = length (NaN: no) */
static int bent_past(double s, double length, double tan_bent)
{
    return s < length / tan_bent && length > 0;
}

/* The eigenvalues d and eigenvectors (the columns of v) of the symmetric a (3 x 3, row-major;
   overwritten) by cyclic Jacobi rotations, which converge on any symmetric matrix. */
static void symmetric_eigen3(double a[9], double d[3], double v[9])
{
    memcpy(v, identity, sizeof identity);
    for (int sweep = 0; sweep < 50; sweep++) {
        const double off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
        if (!(off > 1e-36 * (a[0] * a[0] + a[4] * a[4] + a[8] * a[8])))
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                const double apq = a[3 * p + q];
                if (apq == 0)
                    continue;
                const double theta = (a[3 * q + q] - a[3 * p + p]) / (2 * apq);
                const double t = copysign(1.0, theta) / (fabs(theta) + sqrt(theta * theta + 1));
                const double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; k++) { /* a J, then J^T a: the rotation in the plane p, q */
                    const double kp = a[3 * k + p], kq = a[3 * k + q];
                    a[3 * k + p] = c * kp - s * kq, a[3 * k + q] = s * kp + c * kq;
                }
                for (int k = 0; k < 3; k++) {
                    const double pk = a[3 * p + k], qk = a[3 * q + k];
                    a[3 * p + k] = c * pk - s * qk, a[3 * q + k] = s * pk + c * qk;
                }
                for (int k = 0; k < 3; k++) {
                    const double kp = v[3 * k + p], kq = v[3 * k + q];
                    v[3 * k + p] = c * kp - s * kq, v[3 * k + q] = s * kp + c * kq;
                }
            }
    }
    for (int k = 0; k < 3; k++)
        d[k] = a[4 * k];
}

int mt_check_elbows(const double *positions, size_t frames, size_t joints, const double *world, size_t turned,
                    const size_t *turning, const size_t *place, size_t arms, double tan_bent, double least,
                    double hinge, double *bend, unsigned char *judged)
{
    if (arms == 0)
        return MT_OK;
    if (!judged || !(tan_bent > 0) || !(least >= 0) || !(hinge >= 0))
        return MT_EINVAL;
    if (frames > 0 && (!positions || !world || !turning || !place || !bend))
        return MT_EINVAL;
    for (size_t a = 0; a < arms && frames > 0; a++)
        if (turning[a] >= turned || place[3 * a] >= joints || place[3 * a + 1] >= joints || place[3 * a + 2] >= joints)
            return MT_EINVAL;
    for (size_t a = 0; a < arms; a++) {
        const size_t *p = place + 3 * a;
        double *out = bend + frames * a;
        double moment[9] = {0}, n[3];
        size_t count = 0;
        for (size_t t = 0; t < frames; t++) { /* the second moment of the bent frames' unit turns */
            const double s = measure(positions + 3 * joints * t, world + 9 * (turned * t + turning[a]), p, n);
            const double length = sqrt(dot3(n, n));
            if (bent_past(s, length, tan_bent)) {
                for (int i = 0; i < 3; i++)
                    for (int k = 0; k < 3; k++)
                        moment[3 * i + k] += n[i] / length * (n[k] / length);
                count++;
            }
        }
        double shares[3], axes[9];
        if (count > 0) {
            for (int e = 0; e < 9; e++)
                moment[e] /= (double)count;
            symmetric_eigen3(moment, shares, axes);
        }
        const int top = count == 0 ? 0 : shares[0] >= shares[1] ? (shares[0] >= shares[2] ? 0 : 2)
                                                                  : (shares[1] >= shares[2] ? 1 : 2);
        judged[a] = count >= 2 && (double)count >= least && shares[top] > hinge;
        if (!judged[a]) {
            for (size_t t = 0; t < frames; t++)
                out[t] = NAN;
            continue;
        }
        const double axis[3] = {axes[top], axes[3 + top], axes[6 + top]};
        size_t forward = 0; /* the turns again, not kept from the pass above: no scratch of a take's length */
        for (size_t t = 0; t < frames; t++) {
            const double s = measure(positions + 3 * joints * t, world + 9 * (turned * t + turning[a]), p, n);
            const double along = n[0] * axis[0] + n[1] * axis[1] + n[2] * axis[2];
            const double length = sqrt(dot3(n, n));
            forward += bent_past(s, length, tan_bent) && along > 0;
            out[t] = atan2(along, s) * (180.0 / pi);
        }
        if (2 * forward < count) /* forward is the way most of the bent frames turn */
            for (size_t t = 0; t < frames; t++)
                out[t] = -out[t];
    }
    return MT_OK;
}
