/*
 * iir.c - zero-phase filtering by cascaded second-order sections, forward
 * then backward (scipy.signal.sosfiltfilt); see mt_sosfiltfilt in mtcore.h.
 *
 * A recursive filter runs down the frames one after the other, so the
 * parallelism is across channels: the channels of a row are independent
 * lines, side by side in memory.  A section runs over GROUP channels at a
 * time, four vectors of four, its state in registers, down the rows of a
 * tile; four independent recurrences keep the floating-point units busy
 * while each waits for the row before.
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
 * Memory.  The rows stream through a tile of TILE rows that stays in the
 * first-level cache: the forward pass reads each input row once and writes
 * its forward output to the output row; the backward pass reads the output
 * rows back from the last and overwrites them.  The right extension's
 * forward outputs wait in a buffer of their own; the left extension's
 * backward outputs are never needed, so the backward pass stops at the line.
 *
 * Measured on (432000, 62), one core, against the alternatives: noting the
 * forward state every few hundred rows and recomputing each block's forward
 * outputs in cache before running back through it (the input read twice,
 * the output written once) was 10-15% slower, its extra cascade costing
 * more than the memory it saves; sections reading and writing the rows in
 * place, without the tile, were slower still (their loads wait behind the
 * recurrences, few misses in flight).  Streaming stores, software prefetch
 * and reading the backward blocks in rising order gained nothing measurable.
 */
#include "clones.h"
#include "mtcore.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Four doubles, one vector register (two on a baseline x86-64 build, which the compiler splits into). */
typedef double quad __attribute__((vector_size(4 * sizeof(double))));

enum {
    QUADS = 4,          /* vectors of channels that one section filters side by side */
    GROUP = 4 * QUADS,  /* their channels */
    LANES = 64,         /* channels of a tile, at most: GROUP * (LANES / GROUP) */
    TILE = 32           /* rows of a tile: 32 x 64 doubles, 16 KiB */
};

/*
 * Runs the m rows of a group (GROUP values at v, rows `stride` values apart)
 * through the section of coefficients c, in place, from the state z (z0 of
 * each vector, then z1), which it updates.  The state stays in registers.
 */
static MT_INLINE void section(const double *c, double *v, size_t m, size_t stride, quad *restrict z)
{
    const quad b0 = {c[0], c[0], c[0], c[0]}, b1 = {c[1], c[1], c[1], c[1]}, b2 = {c[2], c[2], c[2], c[2]};
    const quad a1 = {c[4], c[4], c[4], c[4]}, a2 = {c[5], c[5], c[5], c[5]};
    quad z0[QUADS], z1[QUADS];
    for (int j = 0; j < QUADS; j++)
        z0[j] = z[j], z1[j] = z[QUADS + j];
    for (size_t t = 0; t < m; t++, v += stride)
        for (int j = 0; j < QUADS; j++) {
            quad x, y;
            memcpy(&x, v + 4 * j, sizeof x);
            y = b0 * x + z0[j];
            z0[j] = b1 * x - a1 * y + z1[j];
            z1[j] = b2 * x - a2 * y;
            memcpy(v + 4 * j, &y, sizeof y);
        }
    for (int j = 0; j < QUADS; j++)
        z[j] = z0[j], z[QUADS + j] = z1[j];
}

/* The channels of one call at a time: w of them, in tile rows of lanes = GROUP ceil(w / GROUP) values (the
   lanes past w hold 0, and stay 0). */
struct line {
    const double *in;
    double *out;
    size_t n, stride, padlen, w, lanes, sections;
    int padtype;
    const double *sos, *zi;
};

/* Scratch of one call. */
struct scratch {
    quad *state; /* group g, section s: 2 QUADS vectors at (g sections + s) 2 QUADS */
    double *tile, *pad; /* TILE rows; the forward outputs of the right extension, padlen rows */
};

/* m rows of tile through every section, each group of channels in turn. */
static MT_CLONES void cascade(const struct line *l, quad *state, double *tile, size_t m)
{
    for (size_t g = 0; g < l->lanes / GROUP; g++)
        for (size_t s = 0; s < l->sections; s++)
            section(l->sos + 6 * s, tile + g * GROUP, m, l->lanes, state + (g * l->sections + s) * 2 * QUADS);
}

/* state = the states of every section for a constant input equal to row (lanes values): zi times it. */
static void steady(const struct line *l, quad *state, const double *row)
{
    for (size_t g = 0; g < l->lanes / GROUP; g++)
        for (size_t s = 0; s < l->sections; s++)
            for (int j = 0; j < QUADS; j++) {
                quad x;
                memcpy(&x, row + g * GROUP + 4 * j, sizeof x);
                quad *z = state + (g * l->sections + s) * 2 * QUADS;
                z[j] = l->zi[2 * s] * x;
                z[QUADS + j] = l->zi[2 * s + 1] * x;
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

/*
 * Forward over the extended rows 0 .. n + 2 padlen - 1 from the steady state
 * of the first: the line's outputs to out, the right extension's to pad.
 */
static void forward(const struct line *l, const struct scratch *sc)
{
    const ptrdiff_t p = (ptrdiff_t)l->padlen, n = (ptrdiff_t)l->n, rows = n + 2 * p;
    extended_row(l, 0, sc->tile);
    steady(l, sc->state, sc->tile);
    for (ptrdiff_t e = 0; e < rows; e += TILE) {
        const size_t m = (size_t)(rows - e < TILE ? rows - e : TILE);
        for (size_t t = 0; t < m; t++)
            extended_row(l, e + (ptrdiff_t)t, sc->tile + t * l->lanes);
        cascade(l, sc->state, sc->tile, m);
        for (size_t t = 0; t < m; t++) {
            const ptrdiff_t r = e + (ptrdiff_t)t - p;
            if (r >= n)
                memcpy(sc->pad + (size_t)(r - n) * l->lanes, sc->tile + t * l->lanes, l->lanes * sizeof *sc->pad);
            else if (r >= 0)
                memcpy(l->out + (size_t)r * l->stride, sc->tile + t * l->lanes, l->w * sizeof *l->out);
        }
    }
}

/* Row r (0 <= r < n + padlen) of the forward outputs, into the tile row v (lanes values, those past w 0). */
static void forward_row(const struct line *l, const struct scratch *sc, ptrdiff_t r, double *restrict v)
{
    if (r >= (ptrdiff_t)l->n)
        memcpy(v, sc->pad + (size_t)(r - (ptrdiff_t)l->n) * l->lanes, l->lanes * sizeof *v);
    else
        memcpy(v, l->out + (size_t)r * l->stride, l->w * sizeof *v);
}

/* Backward from the steady state of the last forward output, down to the line's first row, in place in out. */
static void backward(const struct line *l, const struct scratch *sc)
{
    const ptrdiff_t n = (ptrdiff_t)l->n, rows = n + (ptrdiff_t)l->padlen;
    forward_row(l, sc, rows - 1, sc->tile);
    steady(l, sc->state, sc->tile);
    for (ptrdiff_t top = rows; top > 0;) {
        const size_t m = (size_t)(top < TILE ? top : TILE);
        for (size_t t = 0; t < m; t++) /* tile row t = forward row top - 1 - t */
            forward_row(l, sc, top - 1 - (ptrdiff_t)t, sc->tile + t * l->lanes);
        cascade(l, sc->state, sc->tile, m);
        for (size_t t = 0; t < m; t++) {
            const ptrdiff_t r = top - 1 - (ptrdiff_t)t;
            if (r < n)
                memcpy(l->out + (size_t)r * l->stride, sc->tile + t * l->lanes, l->w * sizeof *l->out);
        }
        top -= (ptrdiff_t)m;
    }
}

int mt_sosfiltfilt(const double *sos, size_t sections, const double *zi, const double *in, double *out, size_t n,
                   size_t channels, size_t stride, size_t padlen, int padtype)
{
    if (sos == NULL || zi == NULL || sections == 0 || sections > SIZE_MAX / (2 * sizeof(quad) * LANES))
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

    const size_t lanes = channels < LANES ? (channels + GROUP - 1) / GROUP * GROUP : LANES;
    struct scratch sc = {0};
    /* vectors need their alignment (and aligned_alloc a size that is a multiple of it) */
    sc.state = aligned_alloc(sizeof(quad), sections * 2 * LANES / 4 * sizeof(quad));
    sc.tile = aligned_alloc(sizeof(quad), TILE * LANES * sizeof *sc.tile);
    if (padlen <= SIZE_MAX / sizeof(double) / lanes)
        sc.pad = malloc((padlen ? padlen : 1) * lanes * sizeof *sc.pad);
    int status = sc.state && sc.tile && sc.pad ? MT_OK : MT_ENOMEM;
    for (size_t c0 = 0; status == MT_OK && c0 < channels; c0 += LANES) {
        const size_t w = channels - c0 < LANES ? channels - c0 : LANES;
        const struct line l = {.in = in + c0, .out = out + c0, .n = n, .stride = stride, .padlen = padlen,
                               .w = w, .lanes = (w + GROUP - 1) / GROUP * GROUP, .sections = sections,
                               .padtype = padtype, .sos = sos, .zi = zi};
        memset(sc.tile, 0, TILE * LANES * sizeof *sc.tile); /* the lanes past w */
        forward(&l, &sc);
        backward(&l, &sc);
    }
    free(sc.state);
    free(sc.tile);
    free(sc.pad);
    return status;
}
