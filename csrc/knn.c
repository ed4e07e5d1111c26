/*
 * knn.c - exact k nearest neighbours among the rows of a matrix, under squared
 * Euclidean distance, by a k-d tree with leaf buckets (mt_kdtree_depth,
 * mt_kdtree_build, mt_kdtree_query; see mtcore.h).
 *
 * The tree is implicit: the rows' indices are permuted so that every node's
 * rows are a contiguous range, split at its middle (node i's children are
 * 2i+1 and 2i+2, ranges halve level by level), so that a node stores only the
 * dimension it splits and the value of its middle row there.  The rows are
 * then copied in that order: a leaf is scanned from contiguous memory (through
 * the index it took 120 ns a row on 30 dimensions, one cache miss after
 * another; in order 15 ns).  The dimension is
 * the one of widest spread, estimated on a sample of the node's rows (it
 * decides speed, never results).
 *
 * A query visits the child on its own side first, then the other only while
 * the distance from the query to that child's cell can still beat the k-th
 * best: the cell's distance is summed over the dimensions in the order and
 * rounding of the rows' distances (MT_SUM4 of search.h) from per-dimension gaps
 * no larger than any row's, so that it never exceeds the distance of a row in
 * the cell after rounding and the pruning loses no neighbour, ties included
 * (a cell at exactly the k-th best distance is still visited).
 */
#include "mtcore.h"
#include "search.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Rows whose spread is measured when choosing a node's split dimension. */
enum { SPREAD_SAMPLE = 256 };

int mt_kdtree_depth(size_t n, size_t leaf_size, size_t *depth)
{
    if (depth == NULL || leaf_size == 0)
        return MT_EINVAL;
    size_t d = 0;
    for (size_t largest = n; largest > leaf_size; largest = largest / 2 + largest % 2)
        d++;
    *depth = d;
    return MT_OK;
}

/* The tree's rows, or its points, as the rows they are. */
static struct mt_rows stored(const struct mt_kdtree *t, const void *data)
{
    return (struct mt_rows){t->dtype, data, t->dims};
}

/* Whether the tree's sizes and pointers are what its n, dims and leaf_size make them. */
static int valid_tree(const struct mt_kdtree *t)
{
    size_t depth;
    if (t == NULL || mt_kdtree_depth(t->n, t->leaf_size, &depth) != MT_OK || depth != t->depth || depth >= 63 ||
        !mt_fits(t->n, t->dims))
        return 0;
    if (t->n == 0)
        return 1;
    return t->dims > 0 && t->rows != NULL && t->index != NULL &&
           (depth == 0 || (t->split_dim != NULL && t->split_value != NULL));
}

/* ---------------------------------------------------------------------------
 * Building.
 */

struct builder {
    const struct mt_kdtree *t;
    struct mt_rows points;
    double *low, *high; /* dims each: the spread being measured */
    uint64_t random;    /* xorshift state of the pivots */
};

static double key(const struct builder *b, size_t row, size_t dim)
{
    return mt_row_value(b->points, row, dim);
}

/* The dimension in which index[lo .. hi-1] spread most (a sample of them), the first of equals. */
static size_t widest(struct builder *b, size_t lo, size_t hi)
{
    const size_t dims = b->t->dims, step = (hi - lo) / SPREAD_SAMPLE + 1;
    MT_WITH_ROW(b->points, b->t->index[lo], first, for (size_t k = 0; k < dims; k++) b->low[k] = b->high[k] = first[k]);
    for (size_t i = lo + step; i < hi; i += step)
        MT_WITH_ROW(b->points, b->t->index[i], p, for (size_t k = 0; k < dims; k++) {
            b->low[k] = p[k] < b->low[k] ? p[k] : b->low[k];
            b->high[k] = p[k] > b->high[k] ? p[k] : b->high[k];
        });
    size_t best = 0;
    for (size_t k = 1; k < dims; k++)
        if (b->high[k] - b->low[k] > b->high[best] - b->low[best])
            best = k;
    return best;
}

static size_t next_random(struct builder *b, size_t below)
{
    b->random ^= b->random << 13;
    b->random ^= b->random >> 7;
    b->random ^= b->random << 17;
    return (size_t)(b->random % below);
}

static void swap(size_t *index, size_t i, size_t j)
{
    const size_t t = index[i];
    index[i] = index[j];
    index[j] = t;
}

/*
 * Permutes index[lo .. hi-1] so that index[nth] holds the row of rank nth - lo
 * by dimension dim, those before it no greater and those after no less
 * (quickselect, three-way partitions around random pivots: equal keys, which
 * motion data has plenty of, end a round at once).
 */
static void select_nth(struct builder *b, size_t lo, size_t hi, size_t nth, size_t dim)
{
    size_t *index = b->t->index;
    while (hi - lo > 1) {
        const double pivot = key(b, index[lo + next_random(b, hi - lo)], dim);
        size_t less = lo, i = lo, more = hi;
        while (i < more) {
            const double v = key(b, index[i], dim);
            if (v < pivot)
                swap(index, less++, i++);
            else if (v > pivot)
                swap(index, i, --more);
            else
                i++;
        }
        if (nth < less)
            hi = less;
        else if (nth >= more)
            lo = more;
        else
            return;
    }
}

static void build(struct builder *b, size_t node, size_t lo, size_t hi, size_t level)
{
    const struct mt_kdtree *t = b->t;
    if (level == t->depth)
        return;
    const size_t mid = lo + (hi - lo) / 2;
    if (hi > lo) {
        const size_t dim = widest(b, lo, hi);
        select_nth(b, lo, hi, mid, dim);
        t->split_dim[node] = dim;
        t->split_value[node] = key(b, t->index[mid], dim);
    } else { /* an empty range (n below leaf_size * 2^depth): any split serves */
        t->split_dim[node] = 0;
        t->split_value[node] = 0;
    }
    build(b, 2 * node + 1, lo, mid, level + 1);
    build(b, 2 * node + 2, mid, hi, level + 1);
}

int mt_kdtree_build(struct mt_kdtree *tree)
{
    if (tree != NULL && mt_row_item(stored(tree, NULL)) == 0)
        return MT_EDTYPE;
    if (!valid_tree(tree))
        return MT_EINVAL;
    if (tree->n == 0)
        return MT_OK;
    const struct mt_rows points = stored(tree, tree->points);
    if (tree->points == NULL || !mt_rows_finite(points, tree->n) || tree->dims > SIZE_MAX / 2 / sizeof(double))
        return MT_EINVAL;
    for (size_t i = 0; i < tree->n; i++)
        tree->index[i] = i;
    double *spread = malloc(2 * tree->dims * sizeof *spread);
    if (spread == NULL)
        return MT_ENOMEM;
    struct builder b = {.t = tree, .points = points, .low = spread, .high = spread + tree->dims, .random = 0x9e3779b97f4a7c15u};
    build(&b, 0, 0, tree->n, 0);
    free(spread);
    const size_t row = tree->dims * mt_row_item(points);
    for (size_t i = 0; i < tree->n; i++)
        memcpy((char *)tree->rows + i * row, (const char *)tree->points + tree->index[i] * row, row);
    return MT_OK;
}

/* ---------------------------------------------------------------------------
 * Queries.
 */

struct query {
    const struct mt_kdtree *t;
    const double *q;
    double *gap;               /* dims: the query's distance to the current cell, per dimension */
    size_t *rows;              /* the best so far: a max-heap by (distance, row), size of k */
    double *distances;
    size_t size, k;
    size_t skip_lo, skip_hi;   /* rows skip_lo .. skip_hi-1 are excluded */
    int bad;                   /* the tree holds a dimension or row out of range */
};

/* Whether (da, ra) ranks after (db, rb): farther, or as far with a higher row. */
static int after(double da, size_t ra, double db, size_t rb)
{
    return da > db || (da == db && ra > rb);
}

/* Exchange entries a and b of the heap. */
static void heap_swap(size_t *rows, double *d, size_t a, size_t b)
{
    const size_t row = rows[a];
    const double distance = d[a];
    rows[a] = rows[b];
    d[a] = d[b];
    rows[b] = row;
    d[b] = distance;
}

static void heap_down(size_t *rows, double *d, size_t size, size_t i)
{
    for (;;) {
        size_t top = i;
        const size_t l = 2 * i + 1, r = l + 1;
        if (l < size && after(d[l], rows[l], d[top], rows[top]))
            top = l;
        if (r < size && after(d[r], rows[r], d[top], rows[top]))
            top = r;
        if (top == i)
            return;
        heap_swap(rows, d, i, top);
        i = top;
    }
}

static void heap_up(size_t *rows, double *d, size_t i)
{
    while (i > 0) {
        const size_t parent = (i - 1) / 2;
        if (!after(d[i], rows[i], d[parent], rows[parent]))
            return;
        heap_swap(rows, d, i, parent);
        i = parent;
    }
}

static void offer(struct query *s, size_t row, double distance)
{
    if (s->size < s->k) {
        s->rows[s->size] = row;
        s->distances[s->size] = distance;
        heap_up(s->rows, s->distances, s->size++);
    } else if (after(s->distances[0], s->rows[0], distance, row)) {
        s->rows[0] = row;
        s->distances[0] = distance;
        heap_down(s->rows, s->distances, s->size, 0);
    }
}

static void scan_leaf(struct query *s, size_t lo, size_t hi)
{
    const struct mt_kdtree *t = s->t;
    for (size_t i = lo; i < hi; i++) {
        const size_t row = t->index[i];
        if (row >= t->n) {
            s->bad = 1;
            return;
        }
        if (row >= s->skip_lo && row < s->skip_hi)
            continue;
        offer(s, row, mt_row_distance(s->q, stored(t, t->rows), i));
    }
}

/* Visits node (rows index[lo .. hi-1]) whose cell is at squared distance `bound` from the query. */
static void visit(struct query *s, size_t node, size_t lo, size_t hi, size_t level, double bound)
{
    const struct mt_kdtree *t = s->t;
    if (s->bad || (s->size == s->k && bound > s->distances[0]) || lo == hi)
        return;
    if (level == t->depth) {
        scan_leaf(s, lo, hi);
        return;
    }
    const size_t dim = t->split_dim[node], mid = lo + (hi - lo) / 2;
    if (dim >= t->dims) {
        s->bad = 1;
        return;
    }
    /* rows before mid are at most the split value in dim, rows from mid on at least */
    const double diff = s->q[dim] - t->split_value[node];
    const size_t near = diff < 0 ? 2 * node + 1 : 2 * node + 2, far = near == 2 * node + 1 ? near + 1 : near - 1;
    const size_t near_lo = diff < 0 ? lo : mid, near_hi = diff < 0 ? mid : hi;
    const size_t far_lo = diff < 0 ? mid : lo, far_hi = diff < 0 ? hi : mid;
    visit(s, near, near_lo, near_hi, level + 1, bound);
    /* The far cell is the near one's beyond the split: its gap in dim is the query's to the split value, no
       smaller than the gap there was to the parent's cell. */
    const double kept = s->gap[dim];
    s->gap[dim] = fabs(diff);
    double far_bound;
    MT_SUM4(t->dims, k, s->gap[k], far_bound);
    visit(s, far, far_lo, far_hi, level + 1, far_bound);
    s->gap[dim] = kept;
}

int mt_kdtree_query(const struct mt_kdtree *tree, const double *queries, size_t count, size_t k,
                    const size_t *exclude, size_t *indices, double *distances, size_t *found)
{
    if (tree != NULL && mt_row_item(stored(tree, NULL)) == 0)
        return MT_EDTYPE;
    if (!valid_tree(tree) || k == 0 || !mt_fits(count, k) || !mt_fits(count, tree->dims))
        return MT_EINVAL;
    if (count == 0)
        return MT_OK;
    if (queries == NULL || indices == NULL || distances == NULL || found == NULL || tree->dims == 0 ||
        !mt_all_finite(queries, count * tree->dims))
        return MT_EINVAL;
    double *gap = malloc(tree->dims * sizeof *gap);
    if (gap == NULL)
        return MT_ENOMEM;
    int status = MT_OK;
    for (size_t i = 0; i < count && status == MT_OK; i++) {
        struct query s = {
            .t = tree,
            .q = queries + i * tree->dims,
            .gap = gap,
            .rows = indices + i * k,
            .distances = distances + i * k,
            .k = k,
            .skip_lo = exclude ? exclude[2 * i] : 0,
            .skip_hi = exclude ? exclude[2 * i + 1] : 0,
        };
        for (size_t j = 0; j < tree->dims; j++)
            gap[j] = 0;
        visit(&s, 0, 0, tree->n, 0, 0.0);
        if (s.bad) {
            status = MT_EINVAL;
            break;
        }
        /* heap sort: the best first */
        for (size_t size = s.size; size > 1; size--) {
            const size_t tr = s.rows[0];
            const double td = s.distances[0];
            s.rows[0] = s.rows[size - 1];
            s.distances[0] = s.distances[size - 1];
            s.rows[size - 1] = tr;
            s.distances[size - 1] = td;
            heap_down(s.rows, s.distances, size - 1, 0);
        }
        for (size_t j = s.size; j < k; j++) {
            s.rows[j] = SIZE_MAX;
            s.distances[j] = INFINITY;
        }
        found[i] = s.size;
    }
    free(gap);
    return status;
}
