/*
 * iir.c - zero-phase filtering by cascaded second-order sections, forward
 * then backward (scipy.signal.sosfiltfilt); see mt_sosfiltfilt in mtcore.h.
 *
 * A recursive filter runs down the frames one after the other, so the
 * parallelism is across channels: a block of channels is filtered side by
 * side, a tile of rows at a time, each section's state one vector per four
 * channels, the inner loop over those vectors.
 *
 * Each section is the transposed direct form II of scipy's sosfilt, with
 * its operations in the same order (the build does not contract them into
 * fused multiply-adds), so that the result is scipy's bit for bit:
 *
 *     y  = b0 x + z0
 *     z0 = b1 x - a1 y + z1
 *     z1 = b2 x - a2 y
 *
 * The line is extended by padlen frames at each end (filling phase) and
 * filtered forward from the steady state of its first frame, then backward
 * from the steady state of the last forward output (draining phase).
 *
 * Memory.  Done literally, the forward outputs go out to memory and come
 * back for the backward pass.  Instead, the forward pass only notes its
 * state at the start of every block of BLOCK frames; the backward pass then
 * takes the blocks from the last, recomputes each block's forward outputs
 * from its noted state into a buffer that stays in cache, and runs back
 * through them.  Recomputed from the exact state, the forward outputs are
 * the same bit for bit; the input is read twice and the output written once.
 */
#include "clones.h"
#include "lines.h"
#include "mtcore.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum {
    LANES = 64,  /* channels filtered side by side, at most */
    TILE = 128,  /* rows of a tile */
    BLOCK = 512  /* frames between the forward states noted */
};

/* Four doubles, one vector register (two on a baseline x86-64 build, which the compiler splits into). */
typedef double quad __attribute__((vector_size(4 * sizeof(double))));

/*
 * Runs the m rows of tile (4 quads values each) through one section, in
 * place, from the state s0, s1 (quads each), which it updates.  Each row is
 * `quads` independent recurrences, which keeps the floating-point units
 * busy while each waits for its previous row.
 */
static MT_CLONES void section(const double *q, double *restrict tile, size_t m, size_t quads, quad *restrict s0,
                              quad *restrict s1)
{
    const quad b0 = {q[0], q[0], q[0], q[0]}, b1 = {q[1], q[1], q[1], q[1]}, b2 = {q[2], q[2], q[2], q[2]};
    const quad a1 = {q[4], q[4], q[4], q[4]}, a2 = {q[5], q[5], q[5], q[5]};
    for (size_t t = 0; t < m; t++) {
        double *v = tile + t * quads * 4;
        for (size_t j = 0; j < quads; j++) {
            quad x, y;
            memcpy(&x, v + 4 * j, sizeof x);
            y = b0 * x + s0[j];
            s0[j] = b1 * x - a1 * y + s1[j];
            s1[j] = b2 * x - a2 * y;
            memcpy(v + 4 * j, &y, sizeof y);
        }
    }
}

/* One block of channels: w of them, in rows of lanes = 4 ceil(w / 4) in the buffers (the lanes past w hold 0). */
struct line {
    const double *in;
    double *out;
    size_t n, stride, padlen, w, lanes, sections;
    int padtype;
    const double *sos, *zi;
};

/* The values of a state of every section: 2 x sections x lanes / 4 quads. */
static size_t state_quads(const struct line *l)
{
    return 2 * l->sections * (l->lanes / 4);
}

/* m rows of tile through every section, from the state z. */
static void cascade(const struct line *l, quad *z, double *tile, size_t m)
{
    const size_t quads = l->lanes / 4;
    for (size_t s = 0; s < l->sections; s++)
        section(l->sos + 6 * s, tile, m, quads, z + 2 * s * quads, z + (2 * s + 1) * quads);
}

/* z = the states of every section for a constant input equal to row (lanes values): zi times it. */
static void steady(const struct line *l, quad *z, const double *row)
{
    const size_t quads = l->lanes / 4;
    for (size_t s = 0; s < l->sections; s++)
        for (size_t j = 0; j < quads; j++) {
            quad x;
            memcpy(&x, row + 4 * j, sizeof x);
            z[2 * s * quads + j] = l->zi[2 * s] * x;
            z[(2 * s + 1) * quads + j] = l->zi[2 * s + 1] * x;
        }
}

/* Row e (0 <= e < n + 2 padlen) of the line extended by padtype, into v (w values). */
static void extended_row(const struct line *l, ptrdiff_t e, double *restrict v)
{
    const ptrdiff_t last = (ptrdiff_t)l->n - 1, r = e - (ptrdiff_t)l->padlen;
    const double *x = l->in + (size_t)(r < 0 ? 0 : r > last ? last : r) * l->stride;
    if ((r >= 0 && r <= last) || l->padtype == MT_PAD_CONSTANT) {
        memcpy(v, x, l->w * sizeof *v);
        return;
    }
    const ptrdiff_t mirrored = r < 0 ? -r : 2 * last - r; /* the sample as far inside as r is outside */
    const double *restrict m = l->in + (size_t)mirrored * l->stride;
    if (l->padtype == MT_PAD_EVEN)
        memcpy(v, m, l->w * sizeof *v);
    else
        for (size_t k = 0; k < l->w; k++)
            v[k] = 2.0 * x[k] - m[k];
}

/* The forward pass over extended rows e0 .. e1-1 from state z, a tile at a time; the results to buf (lanes
 * apart), or dropped when buf is NULL. */
static void forward(const struct line *l, quad *z, ptrdiff_t e0, ptrdiff_t e1, double *buf, double *tile)
{
    for (ptrdiff_t e = e0; e < e1; e += TILE) {
        const size_t m = (size_t)(e1 - e < TILE ? e1 - e : TILE);
        double *rows = buf != NULL ? buf + (size_t)(e - e0) * l->lanes : tile;
        for (size_t t = 0; t < m; t++)
            extended_row(l, e + (ptrdiff_t)t, rows + t * l->lanes);
        cascade(l, z, rows, m);
    }
}

/*
 * The backward pass from state z over the m rows of src (lanes apart) from the
 * last down, through tile; row i of the result to dst + i * stride (w values),
 * or dropped when dst is NULL.
 */
static void backward(const struct line *l, quad *z, const double *src, size_t m, double *tile, double *dst,
                     size_t stride)
{
    for (size_t top = m; top > 0;) {
        const size_t k = top < TILE ? top : TILE;
        for (size_t t = 0; t < k; t++) /* tile row t = source row top - 1 - t */
            memcpy(tile + t * l->lanes, src + (top - 1 - t) * l->lanes, l->lanes * sizeof *tile);
        cascade(l, z, tile, k);
        if (dst != NULL)
            for (size_t t = k; t-- > 0;)
                memcpy(dst + (top - 1 - t) * stride, tile + t * l->lanes, l->w * sizeof *tile);
        top -= k;
    }
}

/* Scratch of one call. */
struct scratch {
    quad *forward, *backward, *noted; /* states: of each pass, and the forward state at each block start */
    double *pad, *buf, *tile;         /* the forward outputs after the line; a block; a tile */
};

static void filtfilt_line(const struct line *l, const struct scratch *sc)
{
    const ptrdiff_t p = (ptrdiff_t)l->padlen, n = (ptrdiff_t)l->n, lanes = (ptrdiff_t)l->lanes;
    const size_t size = state_quads(l), blocks = (l->n + BLOCK - 1) / BLOCK;
    extended_row(l, 0, sc->tile);
    steady(l, sc->forward, sc->tile);
    forward(l, sc->forward, 0, p, NULL, sc->tile);
    for (size_t k = 0; k < blocks; k++) {
        const ptrdiff_t ea = p + (ptrdiff_t)(k * BLOCK), eb = ea + BLOCK < p + n ? ea + BLOCK : p + n;
        memcpy(sc->noted + k * size, sc->forward, size * sizeof *sc->forward);
        forward(l, sc->forward, ea, eb, NULL, sc->tile);
    }
    forward(l, sc->forward, p + n, n + 2 * p, sc->pad, sc->tile);
    /* the backward pass starts from the last forward output: the extension's, or the last block's */
    if (p > 0) {
        steady(l, sc->backward, sc->pad + (p - 1) * lanes);
        backward(l, sc->backward, sc->pad, (size_t)p, sc->tile, NULL, 0);
    }
    for (size_t k = blocks; k-- > 0;) {
        const ptrdiff_t ea = p + (ptrdiff_t)(k * BLOCK), eb = ea + BLOCK < p + n ? ea + BLOCK : p + n;
        memcpy(sc->forward, sc->noted + k * size, size * sizeof *sc->forward);
        forward(l, sc->forward, ea, eb, sc->buf, sc->tile);
        if (p == 0 && k + 1 == blocks)
            steady(l, sc->backward, sc->buf + (eb - 1 - ea) * lanes);
        backward(l, sc->backward, sc->buf, (size_t)(eb - ea), sc->tile, l->out + (size_t)(ea - p) * l->stride,
                 l->stride);
    }
}

int mt_sosfiltfilt(const double *sos, size_t sections, const double *zi, const double *in, double *out, size_t n,
                   size_t channels, size_t stride, size_t padlen, int padtype)
{
    if (sos == NULL || zi == NULL || sections == 0 || sections > SIZE_MAX / (2 * sizeof(quad) * LANES) / 2)
        return MT_EINVAL;
    if (padtype < MT_PAD_NONE || padtype > MT_PAD_CONSTANT || stride < channels)
        return MT_EINVAL;
    for (size_t s = 0; s < sections; s++)
        if (sos[6 * s + 3] != 1.0)
            return MT_EINVAL;
    if (padtype == MT_PAD_NONE)
        padlen = 0;
    if (n <= padlen || n > PTRDIFF_MAX / 4 || padlen > PTRDIFF_MAX / 4)
        return MT_EINVAL;
    if (channels == 0)
        return MT_OK;
    if (in == NULL || out == NULL || stride > SIZE_MAX / n)
        return MT_EINVAL;

    const size_t lanes = channels < LANES ? (channels + 3) / 4 * 4 : LANES;
    const size_t size = 2 * sections * (lanes / 4), blocks = (n + BLOCK - 1) / BLOCK;
    struct scratch sc = {0};
    /* vectors need their alignment (and aligned_alloc a size that is a multiple of it) */
    if (blocks <= SIZE_MAX / sizeof(quad) / size - 2 && padlen <= SIZE_MAX / sizeof(double) / lanes) {
        sc.forward = aligned_alloc(sizeof(quad), (blocks + 2) * size * sizeof(quad));
        sc.pad = malloc((padlen ? padlen : 1) * lanes * sizeof *sc.pad);
    }
    sc.buf = calloc(BLOCK * lanes, sizeof *sc.buf);
    sc.tile = calloc(TILE * lanes, sizeof *sc.tile);
    int status = MT_OK;
    if (sc.forward == NULL || sc.pad == NULL || sc.buf == NULL || sc.tile == NULL) {
        status = MT_ENOMEM;
    } else {
        sc.backward = sc.forward + size;
        sc.noted = sc.backward + size;
    }
    for (size_t c0 = 0; status == MT_OK && c0 < channels; c0 += LANES) {
        const size_t w = channels - c0 < LANES ? channels - c0 : LANES;
        const struct line l = {.in = in + c0, .out = out + c0, .n = n, .stride = stride, .padlen = padlen,
                               .w = w, .lanes = (w + 3) / 4 * 4, .sections = sections, .padtype = padtype,
                               .sos = sos, .zi = zi};
        filtfilt_line(&l, &sc);
    }
    free(sc.forward);
    free(sc.pad);
    free(sc.buf);
    free(sc.tile);
    return status;
}
