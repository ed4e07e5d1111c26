/*
 * search.h - build-internal: what the search-by-example kernels (dtw.c, knn.c,
 * features.c) share.
 */
#ifndef MT_SEARCH_H
#define MT_SEARCH_H

#include "mtcore.h"

#include <stddef.h>
#include <stdint.h>

/* Whether rows x cols doubles fit in memory: their byte count is below SIZE_MAX. */
static inline int mt_fits(size_t rows, size_t cols)
{
    return cols == 0 || rows <= SIZE_MAX / sizeof(double) / cols;
}

/* Whether every a[0 .. n-1] is finite; branch-free, so that the loop vectorises. */
static inline int mt_all_finite(const double *a, size_t n)
{
    unsigned char bad = 0;
    for (size_t i = 0; i < n; i++)
        bad |= a[i] - a[i] != 0; /* x - x is 0 for every finite x, NaN for the others */
    return !bad;
}

/*
 * The squared Euclidean distance of two rows of `dims`: four running sums over
 * the dimensions k = 0, 1, 2, 3 mod 4, added as (s0 + s1) + (s2 + s3).  Every
 * kernel sums squares in this one order (MT_SUM4: `term` of index `k`), so that a lower bound of
 * smaller terms never exceeds a distance after rounding: each rounded step of
 * the sum is monotonic in its terms.  Four sums let the compiler keep them in
 * vector registers; one sum would be a chain of dependent additions.
 */
#define MT_SUM4(dims, k, term, result)                                                                                 \
    do {                                                                                                               \
        double mt_s_[4] = {0, 0, 0, 0};                                                                                \
        size_t mt_b_ = 0;                                                                                              \
        for (; mt_b_ + 4 <= (dims); mt_b_ += 4)                                                                        \
            for (size_t mt_j_ = 0; mt_j_ < 4; mt_j_++) {                                                               \
                const size_t k = mt_b_ + mt_j_;                                                                        \
                const double mt_t_ = (term);                                                                           \
                mt_s_[mt_j_] += mt_t_ * mt_t_;                                                                         \
            }                                                                                                          \
        for (size_t mt_j_ = 0; mt_b_ + mt_j_ < (dims); mt_j_++) {                                                      \
            const size_t k = mt_b_ + mt_j_;                                                                            \
            const double mt_t_ = (term);                                                                               \
            mt_s_[mt_j_] += mt_t_ * mt_t_;                                                                             \
        }                                                                                                              \
        (result) = (mt_s_[0] + mt_s_[1]) + (mt_s_[2] + mt_s_[3]);                                                      \
    } while (0)

static inline double mt_squared_distance(const double *a, const double *b, size_t dims)
{
    double s;
    MT_SUM4(dims, k, a[k] - b[k], s);
    return s;
}

/*
 * Rows of dims values as a search stores them: float64, or float32 where half
 * the memory matters more than the digits (a database's rows).  Every
 * computation is in double from the stored values, so a float32 row is
 * exactly the double it rounds to.
 */
struct mt_rows {
    int dtype; /* MT_FLOAT64 or MT_FLOAT32 */
    const void *data;
    size_t dims;
};

/* Runs `body` with `x` the typed pointer to row i of rows (one branch per row, none per value). */
#define MT_WITH_ROW(rows, i, x, body)                                                                                  \
    do {                                                                                                               \
        if ((rows).dtype == MT_FLOAT32) {                                                                              \
            const float *x = (const float *)(rows).data + (i) * (rows).dims;                                           \
            body;                                                                                                      \
        } else {                                                                                                       \
            const double *x = (const double *)(rows).data + (i) * (rows).dims;                                         \
            body;                                                                                                      \
        }                                                                                                              \
    } while (0)

/* The squared distance of a (dims doubles) and row i of rows. */
static inline double mt_row_distance(const double *a, struct mt_rows rows, size_t i)
{
    double s;
    MT_WITH_ROW(rows, i, x, MT_SUM4(rows.dims, k, a[k] - x[k], s));
    return s;
}

/* Value k of row i. */
static inline double mt_row_value(struct mt_rows rows, size_t i, size_t k)
{
    double v;
    MT_WITH_ROW(rows, i, x, v = x[k]);
    return v;
}

/* The bytes of one value of rows; 0 for a dtype that is not one of mt_dtype. */
static inline size_t mt_row_item(struct mt_rows rows)
{
    return rows.dtype == MT_FLOAT32 ? sizeof(float) : rows.dtype == MT_FLOAT64 ? sizeof(double) : 0;
}

/* Whether every value of rows 0 .. n-1 is finite. */
static inline int mt_rows_finite(struct mt_rows rows, size_t n)
{
    if (rows.dtype == MT_FLOAT64)
        return mt_all_finite(rows.data, n * rows.dims);
    unsigned char bad = 0;
    const float *x = rows.data;
    for (size_t i = 0; i < n * rows.dims; i++)
        bad |= x[i] - x[i] != 0;
    return !bad;
}

#endif /* MT_SEARCH_H */
