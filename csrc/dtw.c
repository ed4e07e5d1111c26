/*
 * dtw.c - dynamic time warping in a Sakoe-Chiba band, its LB_Keogh lower
 * bound, and the search of a long series for the windows nearest a query
 * (mt_lb_envelope, mt_lb_keogh, mt_dtw, mt_dtw_search; see mtcore.h).
 *
 * The search follows Rakthanmanon et al., "Searching and mining trillions of
 * time series subsequences under dynamic time warping" (KDD 2012), without
 * their cascade of cheaper bounds: every window's LB_Keogh is computed, and the
 * windows are warped in the order of their bounds, so that the k-th best
 * distance falls fast and most windows are never warped at all.  Once most
 * are pruned, the bounds take nearly all the time, and each stops as soon as
 * it passes the k-th distance of a few windows warped first (the seeds).
 *
 * Exactness.  Pruning a window must never lose one that brute force keeps,
 * after rounding too.  Per frame, LB_Keogh's term sums the squares of
 * differences no larger than those of any cell of DTW's cost matrix in that
 * column of the band, in the same order (MT_SUM4 of search.h); its frames add
 * up in order, as a warping path adds its cells, and a rounded sum of
 * non-negative terms is monotonic in each of them.  So the bound computed never
 * exceeds the distance computed, and a window is pruned only when its bound is
 * strictly above the k-th best (a tie might still win on its start).
 */
#include "mtcore.h"
#include "search.h"

#include <math.h>
#include <stdlib.h>

/* ---------------------------------------------------------------------------
 * The envelope: running maximum and minimum over a window of 2r+1 frames,
 * each frame's index kept in a monotonic deque (Lemire, "Streaming
 * maximum-minimum filter using no more than three comparisons per element",
 * 2006): O(n) whatever the radius.
 */

/* A ring of frame indices whose samples decrease (for the maximum) from front to back. */
struct deque {
    size_t *at;
    size_t head, size, cap;
};

static size_t deque_front(const struct deque *q)
{
    return q->at[q->head];
}

static size_t deque_back(const struct deque *q)
{
    size_t i = q->head + q->size - 1;
    return q->at[i >= q->cap ? i - q->cap : i];
}

static void deque_push(struct deque *q, size_t t)
{
    size_t i = q->head + q->size++;
    q->at[i >= q->cap ? i - q->cap : i] = t;
}

static void deque_pop_front(struct deque *q)
{
    q->head = q->head + 1 == q->cap ? 0 : q->head + 1;
    q->size--;
}

/* The line of one dimension: sample t at x[t * stride]; its envelope likewise. */
struct line {
    const double *x;
    double *upper, *lower;
    size_t stride;
};

/* Frame s enters the window: samples it dominates can never be an extreme again. */
static void enter(const struct line *l, struct deque *up, struct deque *lo, size_t s)
{
    const double v = l->x[s * l->stride];
    while (up->size && l->x[deque_back(up) * l->stride] <= v)
        up->size--;
    deque_push(up, s);
    while (lo->size && l->x[deque_back(lo) * l->stride] >= v)
        lo->size--;
    deque_push(lo, s);
}

/* The window of frame t (t - r .. t + r, within the line) is complete: drop what left it, write its extremes. */
static void emit(const struct line *l, struct deque *up, struct deque *lo, size_t t, size_t r)
{
    while (deque_front(up) + r < t)
        deque_pop_front(up);
    while (deque_front(lo) + r < t)
        deque_pop_front(lo);
    l->upper[t * l->stride] = l->x[deque_front(up) * l->stride];
    l->lower[t * l->stride] = l->x[deque_front(lo) * l->stride];
}

/*
 * One line of n >= 1 frames, r <= n:
 *
 *   filling   s = 0 .. r-1       frames enter, no window is complete yet
 *   steady    s = r .. n-1       frame s enters, the window of s - r is written
 *   draining  s = n .. n+r-1     no frame enters, the windows of n - r .. n - 1 are written
 */
static void envelope_line(const struct line *l, size_t n, size_t r, struct deque *up, struct deque *lo)
{
    up->head = up->size = lo->head = lo->size = 0;
    size_t s = 0;
    for (; s < r; s++)
        enter(l, up, lo, s);
    for (; s < n; s++) {
        enter(l, up, lo, s);
        emit(l, up, lo, s - r, r);
    }
    for (; s < n + r; s++)
        emit(l, up, lo, s - r, r);
}

/* The envelope of x (n x dims, n >= 1) for radius r <= n; scratch for the deques, or MT_ENOMEM. */
static int envelope(const double *x, size_t n, size_t dims, size_t r, double *upper, double *lower)
{
    /* a deque holds frames t - r .. s of the window being completed and the one entering: 2r + 2 at most */
    const size_t cap = n < 2 * r + 2 ? n : 2 * r + 2;
    size_t *at = malloc(2 * cap * sizeof *at);
    if (at == NULL)
        return MT_ENOMEM;
    struct deque up = {.at = at, .cap = cap}, lo = {.at = at + cap, .cap = cap};
    for (size_t k = 0; k < dims; k++) {
        const struct line l = {.x = x + k, .upper = upper + k, .lower = lower + k, .stride = dims};
        envelope_line(&l, n, r, &up, &lo);
    }
    free(at);
    return MT_OK;
}

int mt_lb_envelope(const double *x, size_t n, size_t dims, size_t radius, double *upper, double *lower)
{
    if (!mt_fits(n, dims))
        return MT_EINVAL;
    if (n == 0 || dims == 0)
        return MT_OK;
    if (x == NULL || upper == NULL || lower == NULL || !mt_all_finite(x, n * dims))
        return MT_EINVAL;
    return envelope(x, n, dims, radius < n ? radius : n, upper, lower);
}

/* ---------------------------------------------------------------------------
 * LB_Keogh: per frame, the squared distance of the candidate's sample to the
 * query's envelope there, summed.  It stops as soon as the sum passes
 * `threshold`, the partial sum being a lower bound too.
 */
static double lb_keogh(struct mt_rows c, size_t first, const double *upper, const double *lower, size_t n,
                       double threshold)
{
    const size_t dims = c.dims;
    double sum = 0;
    for (size_t t = 0; t < n; t++) {
        const double *u = upper + t * dims, *l = lower + t * dims;
        double term;
        MT_WITH_ROW(c, first + t, x, MT_SUM4(dims, k, x[k] > u[k] ? x[k] - u[k] : x[k] < l[k] ? l[k] - x[k] : 0.0, term));
        sum += term;
        if (sum > threshold)
            break;
    }
    return sum;
}

int mt_lb_keogh(const double *candidate, const double *upper, const double *lower, size_t n, size_t dims,
                double threshold, double *bound)
{
    if (bound == NULL || threshold != threshold || !mt_fits(n, dims))
        return MT_EINVAL;
    *bound = 0;
    if (n == 0 || dims == 0)
        return MT_OK;
    if (candidate == NULL || upper == NULL || lower == NULL || !mt_all_finite(candidate, n * dims) ||
        !mt_all_finite(upper, n * dims) || !mt_all_finite(lower, n * dims))
        return MT_EINVAL;
    *bound = lb_keogh((struct mt_rows){MT_FLOAT64, candidate, dims}, 0, upper, lower, n, threshold);
    return MT_OK;
}

/* ---------------------------------------------------------------------------
 * DTW: D(i, j) = cost(i, j) + min(D(i-1, j), D(i, j-1), D(i-1, j-1)) over the
 * band |i - j| <= r, row by row (a row: one frame i of a), two rows kept.
 */

/*
 * The distance, or +inf when some row's every cell exceeds threshold (the path
 * crosses each row, and its cost only grows).  Requires r <= max(m, n);
 * prev and cur hold n doubles each.
 *
 * Row i covers columns lo_i = max(0, i - r) .. hi_i = min(n - 1, i + r).  Row i
 * reads row i-1 at lo_i - 1 .. hi_i: below lo_{i-1} it reads nothing (lo grows by
 * at most one a row), and above hi_{i-1} the cells are still the +inf they
 * start as (hi grows too, so no earlier row wrote them).
 */
static double dtw(const double *a, size_t m, struct mt_rows b, size_t first, size_t n, size_t r, double threshold,
                  double *prev, double *cur)
{
    if (m == 0 || n == 0)
        return m == n ? 0.0 : INFINITY;
    if (m > n + r || n > m + r) /* the band misses the corner (m-1, n-1) */
        return INFINITY;
    for (size_t j = 0; j < n; j++)
        prev[j] = cur[j] = INFINITY;
    const size_t dims = b.dims, hi0 = n - 1 < r ? n - 1 : r;
    double row_min = cur[0] = mt_row_distance(a, b, first);
    for (size_t j = 1; j <= hi0; j++)
        cur[j] = mt_row_distance(a, b, first + j) + cur[j - 1];
    if (row_min > threshold)
        return INFINITY;
    for (size_t i = 1; i < m; i++) {
        double *t = prev;
        prev = cur;
        cur = t;
        const double *ai = a + i * dims;
        const size_t lo = i > r ? i - r : 0, hi = i + r < n - 1 ? i + r : n - 1;
        double left = INFINITY;
        row_min = INFINITY;
        for (size_t j = lo; j <= hi; j++) {
            double best = prev[j];
            if (j > 0 && prev[j - 1] < best)
                best = prev[j - 1];
            if (left < best)
                best = left;
            left = cur[j] = mt_row_distance(ai, b, first + j) + best;
            if (left < row_min)
                row_min = left;
        }
        if (row_min > threshold)
            return INFINITY;
    }
    return cur[n - 1];
}

int mt_dtw(const double *a, size_t m, const double *b, size_t n, size_t dims, size_t radius, double threshold,
           double *distance)
{
    if (distance == NULL || threshold != threshold || !mt_fits(m, dims) || !mt_fits(n, dims) ||
        n > SIZE_MAX / 2 / sizeof(double))
        return MT_EINVAL;
    if ((m && dims && (a == NULL || !mt_all_finite(a, m * dims))) ||
        (n && dims && (b == NULL || !mt_all_finite(b, n * dims))))
        return MT_EINVAL;
    const size_t longer = m > n ? m : n;
    double *rows = n ? malloc(2 * n * sizeof *rows) : NULL;
    if (n && rows == NULL)
        return MT_ENOMEM;
    *distance = dtw(a, m, (struct mt_rows){MT_FLOAT64, b, dims}, 0, n, radius < longer ? radius : longer, threshold,
                    rows, rows + n);
    free(rows);
    return MT_OK;
}

/* ---------------------------------------------------------------------------
 * The search.
 */

/* Whether candidate (bound_a, a) comes before (bound_b, b): by bound, then by index (so by start). */
static int before(const double *bounds, size_t a, size_t b)
{
    return bounds[a] < bounds[b] || (bounds[a] == bounds[b] && a < b);
}

/* Sifts heap[i] down the min-heap heap[0 .. size-1] of candidate indices. */
static void sift_down(size_t *heap, size_t size, size_t i, const double *bounds)
{
    for (;;) {
        size_t least = i;
        const size_t l = 2 * i + 1, r = l + 1;
        if (l < size && before(bounds, heap[l], heap[least]))
            least = l;
        if (r < size && before(bounds, heap[r], heap[least]))
            least = r;
        if (least == i)
            return;
        const size_t t = heap[i];
        heap[i] = heap[least];
        heap[least] = t;
        i = least;
    }
}

/* Candidates whose bounds choose the seeds of mt_dtw_search: about this many (4 k if more), spread evenly. */
enum { SEED_SAMPLE = 1024 };

static int by_value(const void *a, const void *b)
{
    const size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* The k best so far, sorted by (distance, start); found of them. */
struct best {
    size_t *starts;
    double *distances;
    size_t found, k;
};

/* The k-th best distance: what a window must not exceed to enter (+inf while fewer are found). */
static double kth(const struct best *b)
{
    return b->found == b->k ? b->distances[b->k - 1] : INFINITY;
}

static void offer(struct best *b, size_t start, double distance)
{
    size_t i = b->found;
    if (i == b->k) {
        const double worst = b->distances[i - 1];
        if (distance > worst || (distance == worst && start > b->starts[i - 1]))
            return;
        i--;
    } else {
        b->found++;
    }
    for (; i > 0 && (b->distances[i - 1] > distance || (b->distances[i - 1] == distance && b->starts[i - 1] > start));
         i--) {
        b->distances[i] = b->distances[i - 1];
        b->starts[i] = b->starts[i - 1];
    }
    b->distances[i] = distance;
    b->starts[i] = start;
}

int mt_dtw_search(const double *query, size_t m, int dtype, const void *series, size_t n, size_t dims,
                  size_t radius, const size_t *starts, size_t count, size_t k, double *bounds, size_t *order,
                  size_t *hits, double *distances, size_t *found, struct mt_dtw_stats *stats)
{
    const struct mt_rows s = {dtype, series, dims};
    if (mt_row_item(s) == 0)
        return MT_EDTYPE;
    if (found == NULL || k == 0 || dims > SIZE_MAX / 8 || !mt_fits(m, 2 * dims + 2) || !mt_fits(n, dims))
        return MT_EINVAL;
    *found = 0;
    if (stats != NULL)
        *stats = (struct mt_dtw_stats){0};
    if (count == 0)
        return MT_OK;
    if (starts == NULL || bounds == NULL || order == NULL || hits == NULL || distances == NULL || m > n)
        return MT_EINVAL;
    for (size_t i = 0; i < count; i++)
        if (starts[i] > n - m || (i > 0 && starts[i] <= starts[i - 1]))
            return MT_EINVAL;
    if ((m && dims && (query == NULL || !mt_all_finite(query, m * dims))) ||
        (n && dims && (series == NULL || !mt_rows_finite(s, n))))
        return MT_EINVAL;

    const size_t r = radius < m ? radius : m;
    /* the query's envelope, then two rows of the cost matrix */
    double *scratch = m ? malloc((2 * m * dims + 2 * m) * sizeof *scratch) : NULL;
    if (m && scratch == NULL)
        return MT_ENOMEM;
    double *upper = scratch, *lower = m ? scratch + m * dims : NULL, *rows = m ? lower + m * dims : NULL;
    if (m && dims) {
        const int status = envelope(query, m, dims, r, upper, lower);
        if (status != MT_OK) {
            free(scratch);
            return status;
        }
    }

    const size_t nseeds = k < count ? k : count;
    size_t *seeds = malloc(nseeds * sizeof *seeds);
    if (seeds == NULL) {
        free(scratch);
        return MT_ENOMEM;
    }
    struct best best = {.starts = hits, .distances = distances, .k = k};
    struct mt_dtw_stats counted = {0};
    /*
     * The seeds, warped first: the k candidates of least bound in a sample spread evenly over all of them.
     * Good windows have small bounds, so their k-th distance is near the final k-th best, and at it the
     * bounds of the others stop after a few frames.
     */
    const size_t wanted = SEED_SAMPLE > 4 * nseeds ? SEED_SAMPLE : 4 * nseeds;
    const size_t step = count > wanted ? count / wanted : 1;
    size_t sampled = 0;
    for (size_t i = 0; i < count; i += step) {
        bounds[i] = m && dims ? lb_keogh(s, starts[i], upper, lower, m, INFINITY) : 0.0;
        order[sampled++] = i;
    }
    for (size_t i = sampled / 2; i-- > 0;)
        sift_down(order, sampled, i, bounds);
    for (size_t j = 0; j < nseeds; j++) {
        seeds[j] = order[0];
        order[0] = order[--sampled];
        sift_down(order, sampled, 0, bounds);
    }
    qsort(seeds, nseeds, sizeof *seeds, by_value);
    for (size_t j = 0; j < nseeds; j++) {
        offer(&best, starts[seeds[j]], dtw(query, m, s, starts[seeds[j]], m, r, INFINITY, rows, rows + m));
        counted.warped++;
    }
    const double first = kth(&best);
    for (size_t i = 0; i < count; i++) {
        bounds[i] = m && dims ? lb_keogh(s, starts[i], upper, lower, m, first) : 0.0;
        order[i] = i;
    }
    for (size_t i = count / 2; i-- > 0;)
        sift_down(order, count, i, bounds);
    for (size_t size = count; size > 0;) {
        const size_t i = order[0];
        if (bounds[i] > kth(&best))
            break; /* and so is every bound left */
        order[0] = order[--size];
        sift_down(order, size, 0, bounds);
        if (bsearch(&i, seeds, nseeds, sizeof *seeds, by_value) != NULL)
            continue;
        const double threshold = kth(&best);
        const double d = dtw(query, m, s, starts[i], m, r, threshold, rows, rows + m);
        if (d == INFINITY && threshold < INFINITY) {
            counted.abandoned++;
            continue;
        }
        counted.warped++;
        offer(&best, starts[i], d);
    }
    counted.pruned = count - counted.warped - counted.abandoned;
    free(seeds);
    free(scratch);
    *found = best.found;
    if (stats != NULL)
        *stats = counted;
    return MT_OK;
}
