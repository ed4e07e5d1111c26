/*
 * bands.c - the band equaliser of Bruderlin and Williams ("Motion signal
 * processing", SIGGRAPH 1995); see mt_equalize in mtcore.h.
 *
 * Level G_{k+1} is G_k smoothed by the binomial kernel (1 4 6 4 1) / 16 with
 * its taps s = 2^k frames apart; no level is decimated, so every level has
 * all the frames.  The output is in + sum_k (gains[k] - 1) (G_k - G_{k+1}).
 *
 * Chunks.  Output frames a .. b-1 read G_k only on [a - R_k, b + R_k), where
 * R_k = 2 (2^k + ... + 2^(m-1)) is how far the remaining levels reach, and
 * (for every mode but wrap) the edge extension of a level never points
 * outside that range clipped to the line: an extension reaches at most
 * 2 s <= 2^m <= n frames, so it folds back at most once, onto frames no
 * further from the edge than the extension itself.  So the output is
 * computed in chunks of frames, each level of a chunk held in a small
 * buffer that stays in cache.  Wrap mode (whose extension reads the other
 * end) and levels reaching as far as the line is long take the whole line
 * as one chunk, a few channels at a time.  Each sample of each level is
 * computed by the same expression whatever the chunking, so the result
 * does not depend on it.
 */
#include "clones.h"
#include "lines.h"
#include "mtcore.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum {
    CHUNK_MIN = 512,        /* output frames of a chunk, at least */
    SLAB = 64,              /* channels of a chunk, at most */
    WHOLE_BUDGET = 1 << 22  /* values of a level buffer when a chunk is the whole line */
};

/* A level of one chunk: its frames lo .. hi-1, frame t at rows + (t - lo) * step. */
struct level {
    size_t lo, hi;
    const double *rows;
    size_t step;
};

static const double *row_of(const struct level *g, ptrdiff_t index, const double *fill)
{
    return index < 0 ? fill : g->rows + ((size_t)index - g->lo) * g->step;
}

/* next[t] = the binomial-5 of g at stride s, for t in next->lo .. next->hi-1 (w channels). */
static MT_CLONES void smooth_level(const struct level *g, double *next_rows, const struct level *next, size_t s,
                                   size_t n, int mode, const double *fill, size_t w)
{
    const ptrdiff_t nn = (ptrdiff_t)n, ss = (ptrdiff_t)s;
    for (size_t t = next->lo; t < next->hi; t++) {
        const double *r[5];
        for (ptrdiff_t j = 0; j < 5; j++)
            r[j] = row_of(g, mt_extend_index((ptrdiff_t)t + (j - 2) * ss, nn, mode), fill);
        double *d = next_rows + (t - next->lo) * w;
        MT_IVDEP for (size_t k = 0; k < w; k++)
        {
            d[k] = (r[0][k] + r[4][k]) * 0.0625 + (r[1][k] + r[3][k]) * 0.25 + r[2][k] * 0.375;
        }
    }
}

/* out[t] += gain * (g[t] - next[t]) for t in a .. b-1. */
static MT_CLONES void add_band(const struct level *g, const struct level *next, double gain, size_t a, size_t b,
                               double *out, size_t stride, size_t w)
{
    for (size_t t = a; t < b; t++) {
        const double *p = row_of(g, (ptrdiff_t)t, NULL), *q = row_of(next, (ptrdiff_t)t, NULL);
        double *o = out + t * stride;
        MT_IVDEP for (size_t k = 0; k < w; k++) o[k] += gain * (p[k] - q[k]);
    }
}

struct plan {
    size_t n, stride, levels, chunk;
    const double *gains;
    int mode;
};

/* Output frames a .. b-1 of the w channels at in, out (rows stride apart), levels in buffers cur and nxt. */
static void equalize_chunk(const struct plan *p, const double *in, double *out, size_t w, size_t a, size_t b,
                           double *cur, double *nxt, const double *fill)
{
    for (size_t t = a; t < b; t++)
        memcpy(out + t * p->stride, in + t * p->stride, w * sizeof *out);
    /* reach = R_k, how far beyond a .. b-1 level k is read; starts at R_0 = 2 (2^m - 1) */
    size_t reach = 2 * (((size_t)1 << p->levels) - 1);
    struct level g = {.lo = a > reach ? a - reach : 0, .hi = b + reach < p->n ? b + reach : p->n,
                      .step = p->stride};
    g.rows = in + g.lo * p->stride;
    for (size_t k = 0; k < p->levels; k++) {
        const size_t s = (size_t)1 << k;
        reach -= 2 * s;
        struct level next = {.lo = a > reach ? a - reach : 0, .hi = b + reach < p->n ? b + reach : p->n,
                             .rows = nxt, .step = w};
        smooth_level(&g, nxt, &next, s, p->n, p->mode, fill, w);
        if (p->gains[k] != 1.0)
            add_band(&g, &next, p->gains[k] - 1.0, a, b, out, p->stride, w);
        double *spare = cur;
        cur = nxt;
        nxt = spare;
        g = next;
    }
}

int mt_equalize(const double *in, double *out, size_t n, size_t channels, size_t stride, size_t levels,
                const double *gains, int mode, double cval)
{
    if (mode < MT_MODE_REFLECT || mode > MT_MODE_WRAP || stride < channels)
        return MT_EINVAL;
    if (levels > 0 && (gains == NULL || levels >= sizeof(size_t) * 8 - 2 || ((size_t)1 << levels) > n))
        return MT_EINVAL;
    if (n == 0 || channels == 0)
        return MT_OK;
    if (in == NULL || out == NULL || n > PTRDIFF_MAX / 4 || stride > SIZE_MAX / n)
        return MT_EINVAL;
    /* bands past the last gain that is not 1 leave the sum unchanged */
    while (levels > 0 && gains[levels - 1] == 1.0)
        levels--;

    struct plan p = {.n = n, .stride = stride, .levels = levels, .gains = gains, .mode = mode};
    const size_t reach = levels ? 2 * (((size_t)1 << levels) - 1) : 0;
    p.chunk = 4 * reach > CHUNK_MIN ? 4 * reach : CHUNK_MIN;
    const int whole = mode == MT_MODE_WRAP || p.chunk >= n;
    if (whole)
        p.chunk = n;
    /* rows of the largest buffered level, G_1: a chunk and what the levels after it reach */
    const size_t reach1 = levels > 1 ? reach - 2 : 0, rows = p.chunk + 2 * reach1 < n ? p.chunk + 2 * reach1 : n;
    size_t slab = whole ? WHOLE_BUDGET / rows : SLAB;
    slab = slab < 1 ? 1 : slab > channels ? channels : slab;

    double *cur = NULL, *nxt = NULL, *fill = NULL;
    if (levels > 0) {
        cur = malloc(rows * slab * sizeof *cur);
        nxt = malloc(rows * slab * sizeof *nxt);
        fill = malloc(slab * sizeof *fill);
        if (cur == NULL || nxt == NULL || fill == NULL) {
            free(cur);
            free(nxt);
            free(fill);
            return MT_ENOMEM;
        }
        for (size_t k = 0; k < slab; k++)
            fill[k] = cval;
    }
    for (size_t c0 = 0; c0 < channels; c0 += slab) {
        const size_t w = channels - c0 < slab ? channels - c0 : slab;
        for (size_t a = 0; a < n; a += p.chunk) {
            const size_t b = n - a < p.chunk ? n : a + p.chunk;
            equalize_chunk(&p, in + c0, out + c0, w, a, b, cur, nxt, fill);
        }
    }
    free(cur);
    free(nxt);
    free(fill);
    return MT_OK;
}
