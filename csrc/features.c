/*
 * features.c - boolean relational features of motions (Müller, Röder and
 * Clausen, "Efficient content-based retrieval of motion capture data",
 * SIGGRAPH 2005): thresholds with hysteresis, bits packed into one word per
 * frame, runs of equal words as segments, and an inverted index from words to
 * the segments that hold them (mt_hysteresis, mt_pack_bits, mt_segments,
 * mt_feature_index_build, mt_feature_index_find; see mtcore.h).
 */
#include "mtcore.h"
#include "search.h"

#include <stdint.h>
#include <stdlib.h>

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
