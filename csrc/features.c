/*
 * features.c - boolean relational features of motions (Müller, Röder and
 * Clausen, "Efficient content-based retrieval of motion capture data",
 * SIGGRAPH 2005): thresholds with hysteresis, bits packed into one word per
 * frame, runs of equal words as segments, and an inverted index from words to
 * the segments that hold them (mt_relations, mt_hysteresis, mt_pack_bits,
 * mt_segments, mt_feature_index_build, mt_feature_index_find; see mtcore.h).
 */
#include "mtcore.h"
#include "search.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

static const double DEGREES = 57.295779513082320876798154814105; /* 180 / pi, as numpy's degrees takes it */

int mt_hysteresis(const double *values, size_t n, size_t features, const double *low, const double *high,
                  const unsigned char *initial, unsigned char *on)
{
    if (!mt_fits(n, features))
        return MT_EINVAL;
    if (n == 0 || features == 0)
        return MT_OK;
    if (values == NULL || low == NULL || high == NULL || on == NULL)
        return MT_EINVAL;
    for (size_t f = 0; f < features; f++)
        if (!(low[f] <= high[f]))
            return MT_EINVAL;
    /* frame by frame, the features contiguous: each frame reads the one before it */
    for (size_t f = 0; f < features; f++) {
        const unsigned char state = initial != NULL && initial[f];
        const double v = values[f];
        on[f] = v > high[f] ? 1 : v < low[f] ? 0 : state;
    }
    for (size_t t = 1; t < n; t++) {
        const double *v = values + t * features;
        const unsigned char *before = on + (t - 1) * features;
        unsigned char *now = on + t * features;
        for (size_t f = 0; f < features; f++)
            now[f] = v[f] > high[f] ? 1 : v[f] < low[f] ? 0 : before[f];
    }
    return MT_OK;
}

/* NaN where either is (numpy's minimum and maximum propagate it; fmin and fmax drop it). */
static double lower(double x, double y)
{
    return isnan(x) || x < y ? x : y;
}

static double higher(double x, double y)
{
    return isnan(x) || x > y ? x : y;
}

/* |v| as numpy's norm sums it: in axis order. */
static double length3(const double *v)
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static int point_ok(int i, size_t npoints)
{
    return i >= 0 && (size_t)i < npoints;
}

static int relation_ok(const struct mt_relation *r, size_t npoints, size_t nscalars)
{
    if (!(r->off <= r->on) || !isfinite(r->sign))
        return 0;
    switch (r->kind) {
    case MT_RELATION_DIFFERENCE:
        return point_ok(r->a, npoints) && r->axis >= 0 && r->axis <= 2 &&
               (r->b < 0 ? r->c < 0 : point_ok(r->b, npoints) && (r->c < 0 || point_ok(r->c, npoints)));
    case MT_RELATION_BEND:
        return point_ok(r->a, npoints) && point_ok(r->b, npoints) && point_ok(r->c, npoints);
    case MT_RELATION_SPEED:
    case MT_RELATION_LEAN:
        return point_ok(r->a, npoints);
    case MT_RELATION_SCALAR:
        return r->a >= 0 && (size_t)r->a < nscalars;
    default:
        return 0;
    }
}

/* The value of relation r in frame t of the body (points: frames of npoints x 3). */
static double relation_value(const struct mt_relation *r, const double *points, size_t n, size_t npoints,
                             const double *scalars, size_t nscalars, double rate, size_t t)
{
    const size_t frame = 3 * npoints;
    const double *p = points + t * frame;
    double v;
    switch (r->kind) {
    case MT_RELATION_DIFFERENCE: {
        double base = 0.0;
        if (r->b >= 0) {
            base = p[3 * r->b + r->axis];
            if (r->c >= 0)
                base = lower(base, p[3 * r->c + r->axis]);
        }
        v = p[3 * r->a + r->axis] - base;
        break;
    }
    case MT_RELATION_BEND: {
        const double *a = p + 3 * r->a, *b = p + 3 * r->b, *c = p + 3 * r->c;
        const double u[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]}, w[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
        const double cosine = (u[0] * w[0] + u[1] * w[1] + u[2] * w[2]) / higher(length3(u) * length3(w), 1e-12);
        v = 180.0 - acos(lower(higher(cosine, -1.0), 1.0)) * DEGREES;
        break;
    }
    case MT_RELATION_SPEED: {
        if (n < 2) {
            v = 0.0;
            break;
        }
        const size_t after = t + 1 < n ? t + 1 : t, before = t > 0 ? t - 1 : t;
        const double *x = points + after * frame + 3 * r->a, *y = points + before * frame + 3 * r->a;
        const double span = (double)(after - before);
        const double d[3] = {(x[0] - y[0]) / span, (x[1] - y[1]) / span, (x[2] - y[2]) / span};
        v = length3(d) * rate;
        break;
    }
    case MT_RELATION_LEAN: {
        const double *a = p + 3 * r->a;
        v = atan2(sqrt(a[0] * a[0] + a[2] * a[2]), a[1]) * DEGREES;
        break;
    }
    default: /* MT_RELATION_SCALAR, as relation_ok allows */
        v = scalars[t * nscalars + (size_t)r->a];
    }
    return r->sign * (r->absolute ? fabs(v) : v);
}

int mt_relations(const double *points, size_t n, size_t npoints, const double *scalars, size_t nscalars, double rate,
                 const struct mt_relation *relations, size_t count, double *values, uint64_t *words)
{
    if (count > 64 || npoints > SIZE_MAX / 3 || !mt_fits(n, 3 * npoints) || !mt_fits(n, nscalars) ||
        !mt_fits(n, count) || !(rate > 0.0) || !isfinite(rate) || (count > 0 && relations == NULL))
        return MT_EINVAL;
    for (size_t r = 0; r < count; r++)
        if (!relation_ok(&relations[r], npoints, nscalars))
            return MT_EINVAL;
    if (n == 0)
        return MT_OK;
    if (words == NULL || (npoints > 0 && points == NULL) || (nscalars > 0 && scalars == NULL))
        return MT_EINVAL;
    uint64_t state = 0;
    for (size_t t = 0; t < n; t++) {
        for (size_t r = 0; r < count; r++) {
            const struct mt_relation *rel = &relations[r];
            const double v = relation_value(rel, points, n, npoints, scalars, nscalars, rate, t);
            if (v > rel->on)
                state |= (uint64_t)1 << r;
            else if (v < rel->off)
                state &= ~((uint64_t)1 << r);
            if (values != NULL)
                values[t * count + r] = v;
        }
        words[t] = state;
    }
    return MT_OK;
}

int mt_pack_bits(const unsigned char *bits, size_t n, size_t features, uint64_t *words)
{
    if (features > 64 || !mt_fits(n, features))
        return MT_EINVAL;
    if (n == 0)
        return MT_OK;
    if (words == NULL || (features > 0 && bits == NULL))
        return MT_EINVAL;
    for (size_t t = 0; t < n; t++) {
        const unsigned char *b = bits + t * features;
        uint64_t w = 0;
        for (size_t f = 0; f < features; f++)
            w |= (uint64_t)(b[f] != 0) << f;
        words[t] = w;
    }
    return MT_OK;
}

int mt_segments(const uint64_t *words, size_t n, size_t *first, uint64_t *values, size_t capacity, size_t *count)
{
    if (count == NULL || (capacity > 0 && (first == NULL || values == NULL)))
        return MT_EINVAL;
    *count = 0;
    if (n == 0)
        return MT_OK;
    if (words == NULL)
        return MT_EINVAL;
    size_t c = 0;
    for (size_t t = 0; t < n; t++) {
        if (t > 0 && words[t] == words[t - 1])
            continue;
        if (c < capacity) {
            first[c] = t;
            values[c] = words[t];
        }
        c++;
    }
    *count = c;
    return MT_OK;
}

/* ---------------------------------------------------------------------------
 * The inverted index.
 */

/* Whether segment a ranks after segment b: a higher word, or the same word later. */
static int ranks_after(const uint64_t *words, size_t a, size_t b)
{
    return words[a] > words[b] || (words[a] == words[b] && a > b);
}

static void sift_down(size_t *ids, size_t size, size_t i, const uint64_t *words)
{
    for (;;) {
        size_t top = i;
        const size_t l = 2 * i + 1, r = l + 1;
        if (l < size && ranks_after(words, ids[l], ids[top]))
            top = l;
        if (r < size && ranks_after(words, ids[r], ids[top]))
            top = r;
        if (top == i)
            return;
        const size_t t = ids[i];
        ids[i] = ids[top];
        ids[top] = t;
        i = top;
    }
}

/* Heap sort of ids by (word, id), in place and without scratch: the ids are unique, so its instability never
   shows. */
static void sort_ids(size_t *ids, size_t n, const uint64_t *words)
{
    for (size_t i = n / 2; i-- > 0;)
        sift_down(ids, n, i, words);
    for (size_t end = n; end > 1; end--) {
        const size_t t = ids[0];
        ids[0] = ids[end - 1];
        ids[end - 1] = t;
        sift_down(ids, end - 1, 0, words);
    }
}

static int valid_takes(const struct mt_feature_index *x)
{
    if (x->take_first == NULL || x->take_first[0] != 0 || x->take_first[x->takes] != x->segments)
        return 0;
    for (size_t t = 0; t < x->takes; t++)
        if (x->take_first[t + 1] < x->take_first[t])
            return 0;
    return 1;
}

int mt_feature_index_build(struct mt_feature_index *index)
{
    if (index == NULL || index->offsets == NULL || !valid_takes(index) ||
        (index->segments > 0 && (index->words == NULL || index->keys == NULL || index->ids == NULL)))
        return MT_EINVAL;
    const size_t n = index->segments;
    for (size_t i = 0; i < n; i++)
        index->ids[i] = i;
    sort_ids(index->ids, n, index->words);
    size_t keys = 0;
    for (size_t i = 0; i < n; i++) {
        const uint64_t w = index->words[index->ids[i]];
        if (keys == 0 || index->keys[keys - 1] != w) {
            index->offsets[keys] = i;
            index->keys[keys++] = w;
        }
    }
    index->offsets[keys] = n;
    index->nkeys = keys;
    return MT_OK;
}

/* The posting list of word w: ids[*begin .. *end-1]; empty when no segment has it. */
static void postings(const struct mt_feature_index *x, uint64_t w, size_t *begin, size_t *end)
{
    size_t lo = 0, hi = x->nkeys;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (x->keys[mid] < w)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo < x->nkeys && x->keys[lo] == w) {
        *begin = x->offsets[lo];
        *end = x->offsets[lo + 1];
    } else {
        *begin = *end = 0;
    }
}

/* The take that holds segment s (take_first ascending). */
static size_t take_of(const struct mt_feature_index *x, size_t s)
{
    size_t lo = 0, hi = x->takes; /* the last take t with take_first[t] <= s */
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        if (x->take_first[mid] <= s)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

int mt_feature_index_find(const struct mt_feature_index *index, const uint64_t *query, size_t length, size_t *hits,
                          size_t capacity, size_t *count)
{
    if (index == NULL || count == NULL || length == 0 || query == NULL || (capacity > 0 && hits == NULL) ||
        index->offsets == NULL || index->nkeys > index->segments || !valid_takes(index) ||
        (index->segments > 0 && (index->words == NULL || index->keys == NULL || index->ids == NULL)) ||
        index->offsets[index->nkeys] != index->segments)
        return MT_EINVAL;
    *count = 0;
    /* the query's rarest word: its posting list holds every match, shifted by its place in the query */
    size_t pivot = 0, begin = 0, end = 0;
    for (size_t j = 0; j < length; j++) {
        size_t b, e;
        postings(index, query[j], &b, &e);
        if (j == 0 || e - b < end - begin) {
            pivot = j;
            begin = b;
            end = e;
        }
        if (b > e || e > index->segments)
            return MT_EINVAL;
        if (b == e)
            return MT_OK;
    }
    size_t c = 0;
    for (size_t p = begin; p < end; p++) {
        const size_t id = index->ids[p];
        if (id >= index->segments)
            return MT_EINVAL;
        if (id < pivot)
            continue;
        const size_t s = id - pivot, take = take_of(index, s);
        if (index->take_first[take + 1] - s < length)
            continue; /* the match would run past its take */
        size_t j = 0;
        while (j < length && index->words[s + j] == query[j])
            j++;
        if (j < length)
            continue;
        if (c < capacity)
            hits[c] = s;
        c++;
    }
    *count = c;
    return MT_OK;
}
