/*
 * iir.c - zero-phase filtering by cascaded second-order sections, forward
 * then backward (scipy.signal.sosfiltfilt); see mt_sosfiltfilt in mtcore.h.
 *
 * A recursive filter runs down the frames one after the other, so the
 * parallelism is across channels: the channels of a row are independent
 * lines, side by side in memory.  A section runs over a group of 16
 * channels at a time, four vectors ("quads") of four, its state in
 * registers, down the rows of a tile; four independent recurrences keep the
 * floating-point units busy while each waits for the row before.
 *
 * Each section is the transposed direct form II of scipy's sosfilt, with
 * its operations in the same order (the build does not contract them into
 * fused multiply-adds), so that the result is scipy's bit for bit:
 *
 *     y  = b0 x + z0
 *     z0 = b1 x - a1 y + z1
 *     z1 = b2 x - a2 y
 *
 * A row of a group waits for the one before through y -> a1 y -> - -> + ->
 * y: 12 cycles, which four quads fill (their 20 multiplications take 10).
 * Fused multiply-adds would make that 8 cycles, but the multiplications
 * stay 5 a quad and they move apart from scipy by up to 1.6e-11 of the
 * signal's size where the cut-offs are steep (8th-order band pass 0.1-0.5
 * Hz at 120 Hz; 3e-12 for a 2nd-order high pass at 0.1 Hz), past the
 * 1e-12 that issue 17 allows.
 *
 * The line is extended by padlen frames at each end (filling phase) and
 * filtered forward from the steady state of its first frame, then backward
 * from the steady state of the last forward output (draining phase).  The
 * extensions' rows are built into a small buffer of their own; the left
 * one's backward outputs are never needed, so the backward pass stops at
 * the line.
 *
 * Where the quads are.  The channels of a call are cut into groups of 16
 * side by side; a last group narrower than 16 (at least 4) ends at the
 * last channel, its quads overlapping where they must (they compute the
 * same values there), and one narrower than 4 borrows from the group before:
 *
 *     62 channels:  |0 4 8 12|16 20 24 28|32 36 40 44|48 52 56 58|   (quad 58: 58-61)
 *     17 channels:  |0 4 8 9|13 13 13 13|
 *
 * so a call of 4 or more channels is read and written in whole quads, all
 * inside its channels (a call of fewer takes its lanes one by one).
 * Sections never write the rows they read: the first reads the rows into a
 * tile of the group, the last writes the tile out (a single section writes
 * the tile, which is then copied out), so that overlapping quads all read
 * their input.  Each tile of rows goes through every group before the next,
 * so that the rows stream through memory once a pass however wide they are.
 *
 * Memory.  The forward pass reads each input row once and writes its
 * output row; the backward pass reads the output rows back from the last
 * and overwrites them in place.  While the sections run, they ask for the
 * lines of the rows AHEAD further on (software prefetch, a few at each row), so
 * that memory works while the arithmetic does: the hardware prefetchers do
 * not follow a group's 128 bytes in every 496.
 *
 * Measured on (432000, 62), one core, 4th-order low pass, the best of
 * many calls on a shared machine, into an output written before (and into
 * a new one): the former design (the rows copied whole into a tile of 64
 * lanes and back, 506 M instructions) took 79 ms (91); sections reading and
 * writing the rows themselves, in tiles of 32 rows (454 M), 90-110 ms
 * without the prefetch and 59 ms (67) with it; in tiles of 8 rows (493 M:
 * the states go in and out of registers four times as often) 48 ms (59),
 * as a tile's rows in and out no longer spill from L1 before the last
 * group is done with their shared lines.  Storing each quad only after all
 * four are loaded (the order that would let overlapping quads read and
 * write the same rows) spills the state from registers and costs 40%.
 * A bare read-and-write pass down the rows takes 23-26 ms, up them 13-15
 * ms, down them asking for each block of 128 rows ahead in rising order
 * 16-20 ms; in the backward pass that last gained nothing measurable.
 * With the channels filtered in chunks of at most 64, one chunk's passes
 * after the other's (so that the scratch stayed small), (108000, 248) took
 * 64-81 ms against 45-54 ms in one pass for all.
 * Streaming stores of the forward outputs (through a stage of whole rows)
 * saved 4 ms into an output written before but cost 6-8 ms into a new one,
 * whose pages the kernel has just cleared into the cache, and
 * sosfiltfilt's outputs are new.
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
    TILE = 8,           /* rows a section runs down at a time: 8 rows of 62 channels in and out stay in L1 */
    AHEAD = 16,         /* rows ahead whose lines the sections ask for */
    LINE = 64           /* bytes of a cache line */
};

/* The rows of one group: row t at p + t step, quad j of it at off[j] (GROUP values apart in a tile). */
struct rows {
    double *p;
    ptrdiff_t step;
    const ptrdiff_t *off;
};

static const ptrdiff_t tiled[QUADS] = {0, 4, 8, 12};

/* The quad at p, of which k lanes (1 to 4) are real: the others read as 0 and are not written.  (Through
   pointers: a vector passed by value draws a warning about the ABI without AVX, although these are inlined.) */
static MT_INLINE void load(quad *x, const double *p, size_t k)
{
    if (k >= 4) {
        memcpy(x, p, sizeof *x);
        return;
    }
    *x = (quad){0, 0, 0, 0};
    for (size_t i = 0; i < k; i++)
        (*x)[i] = p[i];
}

static MT_INLINE void store(double *p, const quad *y, size_t k)
{
    if (k >= 4)
        memcpy(p, y, sizeof *y);
    else
        for (size_t i = 0; i < k; i++)
            p[i] = (*y)[i];
}

/* Asks for the cache lines of a group's row: its first byte, the one 64 further, and its last. */
static MT_INLINE void prefetch(const double *row, const ptrdiff_t *off, size_t k)
{
    const uintptr_t first = (uintptr_t)(row + off[0]), last = (uintptr_t)(row + off[QUADS - 1] + k - 1);
    __builtin_prefetch((const void *)first);
    __builtin_prefetch((const void *)(first + LINE < last ? first + LINE : last));
    __builtin_prefetch((const void *)last);
}

/*
 * Runs m rows of a group from src (quads of sk real lanes) through the section of coefficients c to dst (dk),
 * never the same rows, from the state z (z0 of each quad, then z1), which it updates; the state stays in
 * registers.  For its first ahead_src rows it asks for the row of src AHEAD further on, for its first
 * ahead_dst that of dst.
 */
static MT_INLINE void section(const double *c, struct rows src, size_t sk, struct rows dst, size_t dk, size_t m,
                              quad *restrict z, size_t ahead_src, size_t ahead_dst)
{
    const quad b0 = {c[0], c[0], c[0], c[0]}, b1 = {c[1], c[1], c[1], c[1]}, b2 = {c[2], c[2], c[2], c[2]};
    const quad a1 = {c[4], c[4], c[4], c[4]}, a2 = {c[5], c[5], c[5], c[5]};
    quad z0[QUADS], z1[QUADS];
    for (int j = 0; j < QUADS; j++)
        z0[j] = z[j], z1[j] = z[QUADS + j];
    const double *s = src.p;
    double *d = dst.p;
    for (size_t t = 0; t < m; t++, s += src.step, d += dst.step) {
        if (t < ahead_src)
            prefetch(s + AHEAD * src.step, src.off, sk);
        if (t < ahead_dst)
            prefetch(d + AHEAD * dst.step, dst.off, dk);
        for (int j = 0; j < QUADS; j++) {
            quad x;
            load(&x, s + src.off[j], sk);
            const quad y = b0 * x + z0[j];
            z0[j] = b1 * x - a1 * y + z1[j];
            z1[j] = b2 * x - a2 * y;
            store(d + dst.off[j], &y, dk);
        }
    }
    for (int j = 0; j < QUADS; j++)
        z[j] = z0[j], z[QUADS + j] = z1[j];
}

/* m rows of the tile of a group to dst (quads of k real lanes), asking for dst's rows like section. */
static MT_INLINE void untile(const double *tile, struct rows dst, size_t k, size_t m, size_t ahead_dst)
{
    double *d = dst.p;
    for (size_t t = 0; t < m; t++, d += dst.step, tile += GROUP) {
        if (t < ahead_dst)
            prefetch(d + AHEAD * dst.step, dst.off, k);
        for (int j = 0; j < QUADS; j++) {
            quad y;
            load(&y, tile + 4 * j, 4);
            store(d + dst.off[j], &y, k);
        }
    }
}

/* What the sections of a call share. */
struct line {
    const double *in;
    double *out;
    size_t n, stride, padlen, sections;
    int padtype;
    const double *sos, *zi;
    size_t groups, k; /* groups of channels, and the real lanes of their quads */
    ptrdiff_t *off;   /* group g's quads at channels off[4 g] .. off[4 g + 3] */
};

/* m rows of one group from src through every section to dst (quads of k real lanes), by way of its tile
   (TILE x GROUP), asking for the rows AHEAD further on for the first ahead[0] of src and ahead[1] of dst. */
static MT_INLINE void cascade_group(const struct line *l, quad *state, struct rows src, struct rows dst, size_t k,
                                    double *tile, size_t m, const size_t ahead[2])
{
    const struct rows t = {tile, GROUP, tiled};
    const size_t last = l->sections - 1;
    section(l->sos, src, k, t, 4, m, state, ahead[0], 0);
    for (size_t s = 1; s < last; s++)
        section(l->sos + 6 * s, t, 4, t, 4, m, state + s * 2 * QUADS, 0, 0);
    if (last)
        section(l->sos + 6 * last, t, 4, dst, k, m, state + last * 2 * QUADS, 0, ahead[1]);
    else
        untile(tile, dst, k, m, ahead[1]);
}

/* m rows of every group, from src to dst (rows sstep and dstep values apart), asking for the rows
   AHEAD further on as cascade_group. */
static MT_CLONES void cascade(const struct line *l, quad *state, double *tile, const double *src, ptrdiff_t sstep,
                              double *dst, ptrdiff_t dstep, size_t m, const size_t ahead[2])
{
    for (size_t g = 0; g < l->groups; g++) {
        const struct rows s = {(double *)src, sstep, l->off + 4 * g}, d = {dst, dstep, l->off + 4 * g};
        quad *z = state + g * l->sections * 2 * QUADS;
        if (l->k == 4) /* whole quads: the loads and stores compiled as such */
            cascade_group(l, z, s, d, 4, tile, m, ahead);
        else
            cascade_group(l, z, s, d, l->k, tile, m, ahead);
    }
}

/* m rows of the extension buffer (group g's rows at ext + g padlen GROUP), from row first, step 1 or -1, in place. */
static MT_CLONES void cascade_ext(const struct line *l, quad *state, double *tile, double *ext, size_t first,
                                  ptrdiff_t step, size_t m)
{
    static const size_t none[2] = {0, 0};
    for (size_t g = 0; g < l->groups; g++) {
        const struct rows r = {ext + (g * l->padlen + first) * GROUP, step * GROUP, tiled};
        cascade_group(l, state + g * l->sections * 2 * QUADS, r, r, 4, tile, m, none);
    }
}

/* state = the states of every section for a constant input equal to a row: of the line at row, or of the
   extension buffer (its row at row). */
static void steady(const struct line *l, quad *state, const double *row, int ext)
{
    for (size_t g = 0; g < l->groups; g++)
        for (size_t s = 0; s < l->sections; s++)
            for (int j = 0; j < QUADS; j++) {
                quad x;
                if (ext)
                    load(&x, row + g * l->padlen * GROUP + 4 * j, 4);
                else
                    load(&x, row + l->off[4 * g + j], l->k);
                quad *z = state + (g * l->sections + s) * 2 * QUADS;
                z[j] = l->zi[2 * s] * x;
                z[QUADS + j] = l->zi[2 * s + 1] * x;
            }
}

/* The left (right = 0) or right extension of the line into ext, group by group, in the order forward meets it. */
static void extension(const struct line *l, int right, double *ext)
{
    const size_t n = l->n, p = l->padlen;
    const double *edge = l->in + (right ? n - 1 : 0) * l->stride;
    for (size_t i = 0; i < p; i++) {
        const double *mirror = l->in + (right ? n - 2 - i : p - i) * l->stride; /* as far inside as i is outside */
        for (size_t g = 0; g < l->groups; g++)
            for (size_t q = 4 * g; q < 4 * g + QUADS; q++)
                for (size_t k = 0; k < 4; k++) {
                    const size_t c = (size_t)l->off[q] + k;
                    double v = 0.0; /* lanes past a call of fewer than 4 channels */
                    if (k < l->k)
                        v = l->padtype == MT_PAD_CONSTANT ? edge[c]
                            : l->padtype == MT_PAD_EVEN   ? mirror[c]
                                                          : 2.0 * edge[c] - mirror[c];
                    ext[(g * p + i) * GROUP + 4 * (q - 4 * g) + k] = v;
                }
    }
}

/* Rows of a tile of m whose row AHEAD further is still in the line of n rows, r rows (this tile's) before. */
static size_t ahead_of(size_t n, size_t r, size_t m)
{
    return r + AHEAD >= n ? 0 : n - r - AHEAD < m ? n - r - AHEAD : m;
}

/* Scratch of one call. */
struct scratch {
    quad *state;  /* group g, section s: 2 QUADS vectors at (g sections + s) 2 QUADS */
    double *tile; /* TILE x GROUP */
    double *ext;  /* groups x padlen x GROUP: an extension, the right one's forward outputs kept */
};

static void forward(const struct line *l, const struct scratch *sc)
{
    const size_t n = l->n, p = l->padlen;
    if (p) {
        extension(l, 0, sc->ext);
        steady(l, sc->state, sc->ext, 1);
        for (size_t e = 0; e < p; e += TILE)
            cascade_ext(l, sc->state, sc->tile, sc->ext, e, 1, p - e < TILE ? p - e : TILE);
    } else
        steady(l, sc->state, l->in, 0);
    for (size_t r = 0; r < n; r += TILE) {
        const size_t m = n - r < TILE ? n - r : TILE, ahead = ahead_of(n, r, m), both[2] = {ahead, ahead};
        cascade(l, sc->state, sc->tile, l->in + r * l->stride, (ptrdiff_t)l->stride, l->out + r * l->stride,
                (ptrdiff_t)l->stride, m, both);
    }
    if (p) {
        extension(l, 1, sc->ext);
        for (size_t e = 0; e < p; e += TILE)
            cascade_ext(l, sc->state, sc->tile, sc->ext, e, 1, p - e < TILE ? p - e : TILE);
    }
}

static void backward(const struct line *l, const struct scratch *sc)
{
    const size_t n = l->n, p = l->padlen;
    if (p) {
        steady(l, sc->state, sc->ext + (p - 1) * GROUP, 1);
        for (size_t e = 0; e < p; e += TILE)
            cascade_ext(l, sc->state, sc->tile, sc->ext, p - 1 - e, -1, p - e < TILE ? p - e : TILE);
    } else
        steady(l, sc->state, l->out + (n - 1) * l->stride, 0);
    const ptrdiff_t up = -(ptrdiff_t)l->stride;
    for (size_t r = 0; r < n; r += TILE) {
        const size_t m = n - r < TILE ? n - r : TILE, src_only[2] = {ahead_of(n, r, m), 0}; /* the same rows */
        double *row = l->out + (n - 1 - r) * l->stride;
        cascade(l, sc->state, sc->tile, row, up, row, up, m, src_only);
    }
}

/* Places the quads of w channels (see the top of the file) in l (l->groups of them). */
static void place(struct line *l, size_t w)
{
    if (w < 4) {
        l->k = w;
        for (int j = 0; j < QUADS; j++)
            l->off[j] = 0;
        return;
    }
    l->k = 4;
    const size_t rest = w - (l->groups - 1) * GROUP;
    for (size_t g = 0; g < l->groups; g++) {
        size_t begin = g * GROUP, width = g + 1 < l->groups ? GROUP : rest;
        if (rest < 4 && g + 2 == l->groups) /* the last group borrows 4 - rest channels from this one */
            width = GROUP - 4 + rest;
        else if (rest < 4 && g + 1 == l->groups)
            begin = w - 4, width = 4;
        for (size_t j = 0; j < QUADS; j++)
            l->off[4 * g + j] = (ptrdiff_t)(begin + (4 * j < width - 4 ? 4 * j : width - 4));
    }
}

int mt_sosfiltfilt(const double *sos, size_t sections, const double *zi, const double *in, double *out, size_t n,
                   size_t channels, size_t stride, size_t padlen, int padtype)
{
    if (sos == NULL || zi == NULL || sections == 0)
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
    const size_t groups = channels / GROUP + (channels % GROUP != 0);
    const size_t group_bytes = 2 * QUADS * sizeof(quad); /* of state per section, of extension per row */
    if (sections > SIZE_MAX / group_bytes / groups || padlen + 1 > SIZE_MAX / group_bytes / groups)
        return MT_ENOMEM;

    struct line l = {.in = in, .out = out, .n = n, .stride = stride, .padlen = padlen, .sections = sections,
                     .padtype = padtype, .sos = sos, .zi = zi, .groups = groups};
    struct scratch sc = {0};
    /* vectors need their alignment (and aligned_alloc a size that is a multiple of it) */
    sc.state = aligned_alloc(sizeof(quad), sections * groups * group_bytes);
    sc.tile = aligned_alloc(sizeof(quad), TILE * GROUP * sizeof *sc.tile);
    sc.ext = malloc((padlen + 1) * groups * GROUP * sizeof *sc.ext);
    l.off = malloc(groups * QUADS * sizeof *l.off);
    int status = sc.state && sc.tile && sc.ext && l.off ? MT_OK : MT_ENOMEM;
    if (status == MT_OK) {
        place(&l, channels);
        forward(&l, &sc);
        backward(&l, &sc);
    }
    free(sc.state);
    free(sc.tile);
    free(sc.ext);
    free(l.off);
    return status;
}
