/*
 * check_arms.c - the take check's measure of the elbows, frame by frame (mt_check_elbows; see
 * mtcore.h): how the forearm turns from the upper arm, in the upper arm's own axes.
 */
#include "lanes.h"
#include "mtcore.h"

int mt_check_elbows(const double *positions, size_t frames, size_t joints, const double *world, size_t turned,
                    const size_t *turning, const size_t *place, size_t arms, double *turn, double *straight)
{
    if (arms == 0 || frames == 0)
        return MT_OK;
    if (!positions || !world || !turning || !place || !turn || !straight)
        return MT_EINVAL;
    for (size_t a = 0; a < arms; a++)
        if (turning[a] >= turned || place[3 * a] >= joints || place[3 * a + 1] >= joints || place[3 * a + 2] >= joints)
            return MT_EINVAL;
    for (size_t a = 0; a < arms; a++) {
        const size_t *p = place + 3 * a;
        for (size_t t = 0; t < frames; t++) {
            const double *at = positions + 3 * joints * t, *w = world + 9 * (turned * t + turning[a]);
            double arm[3], forearm[3], across[3];
            for (int c = 0; c < 3; c++) {
                arm[c] = at[3 * p[1] + c] - at[3 * p[0] + c];
                forearm[c] = at[3 * p[2] + c] - at[3 * p[1] + c];
            }
            cross3(arm, forearm, across);
            double *out = turn + 3 * (frames * a + t);
            for (int c = 0; c < 3; c++) /* W^T across: into the turning joint's axes */
                out[c] = w[c] * across[0] + w[3 + c] * across[1] + w[6 + c] * across[2];
            straight[frames * a + t] = dot3(arm, forearm);
        }
    }
    return MT_OK;
}
