/*
 * nbs_internal.h - what the 2D and 3D Munjiza-NBS detectors share (nbs.c,
 * nbs_3d.c); not part of the engine's interface.
 *
 * Contract: the sphere test, the pair list growth, the list-array helpers, the "old list"
 * encoding of a head (a list already processed but still needed as a
 * neighbour is stored as -2 - head), the validity limit on a centre or
 * radius, the padded cell size and the folding plan of one axis. Both
 * detectors must take the same decisions here, or their exactness
 * arguments (padding, folding) would diverge.
 */
#ifndef FDEM_NBS_INTERNAL_H
#define FDEM_NBS_INTERNAL_H

#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "nbs.h"

#if defined(__GNUC__)
#define NBS_UNLIKELY(c) __builtin_expect(!!(c), 0)
#define NBS_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define NBS_UNLIKELY(c) (c)
#define NBS_ALWAYS_INLINE inline
#endif

#define NBS_EMPTY (-1)
#define NBS_VALUE_LIMIT 1e150
#define NBS_MIN_TABLE 4
/* at most 2^30 circles, so table sizes and indices fit int32 */
#define NBS_MAX_CIRCLES ((size_t)1 << 30)
/* the integer extent is kept below 2^40 cells so int64 never overflows */
#define NBS_MAX_CELLS_PER_AXIS 1099511627776.0

/* Circles and spheres the detectors take: finite enough to square. */
static inline int nbs_circle_valid(double x, double y, double r)
{
    return fabs(x) <= NBS_VALUE_LIMIT && fabs(y) <= NBS_VALUE_LIMIT &&
           r >= 0.0 && r <= NBS_VALUE_LIMIT;
}

/* The one circle test both detectors use. Split into statements so that no
 * compiler contracts it into an FMA in one detector and not in the other. */
static inline int nbs_circles_touch(double xi, double yi, double ri,
                                    double xj, double yj, double rj)
{
    double dx = xi - xj;
    double dy = yi - yj;
    double reach = ri + rj;
    double dx2 = dx * dx;
    double dy2 = dy * dy;
    double dist2 = dx2 + dy2;
    double reach2 = reach * reach;
    return dist2 <= reach2;
}

static inline int nbs3_sphere_valid(double x, double y, double z, double r)
{
    return fabs(x) <= NBS_VALUE_LIMIT && fabs(y) <= NBS_VALUE_LIMIT &&
           fabs(z) <= NBS_VALUE_LIMIT && r >= 0.0 && r <= NBS_VALUE_LIMIT;
}

/* The one sphere test of the 3D detectors (nbs_3d.c's two, and the bench's
 * baseline); split statements so that no compiler contracts it into an FMA
 * in one detector and not the other. */
static inline int nbs_spheres_touch(double xi, double yi, double zi, double ri, double xj,
                                    double yj, double zj, double rj)
{
    double dx = xi - xj;
    double dy = yi - yj;
    double dz = zi - zj;
    double reach = ri + rj;
    double dx2 = dx * dx;
    double dy2 = dy * dy;
    double dz2 = dz * dz;
    double dist2 = dx2 + dy2 + dz2;
    double reach2 = reach * reach;
    return dist2 <= reach2;
}

static inline int nbs_same_body(const int32_t *body, int32_t i, int32_t j)
{
    return body && body[i] >= 0 && body[i] == body[j];
}

static inline int nbs_pairs_grow(nbs_pairs *pairs, size_t want)
{
    if (want <= pairs->capacity) return 0;
    size_t cap = pairs->capacity ? pairs->capacity : NBS_FIRST_PAIRS;
    while (cap < want) cap *= 2;
    int32_t *a = realloc(pairs->a, cap * sizeof *a);
    if (!a) return -1;
    pairs->a = a;
    int32_t *b = realloc(pairs->b, cap * sizeof *b);
    if (!b) return -1;
    pairs->b = b;
    pairs->capacity = cap;
    return 0;
}

static inline int nbs_pairs_push(nbs_pairs *pairs, int32_t i, int32_t j)
{
    if (NBS_UNLIKELY(pairs->count == pairs->capacity) &&
        nbs_pairs_grow(pairs, pairs->count + 1) != 0)
        return -1;
    pairs->a[pairs->count] = i;
    pairs->b[pairs->count] = j;
    pairs->count++;
    return 0;
}

static inline void nbs_fill_empty(int32_t *a, size_t count)
{
    for (size_t k = 0; k < count; k++) a[k] = NBS_EMPTY;
}

static inline int nbs_grow_array(int32_t **array, size_t count)
{
    int32_t *p = realloc(*array, count * sizeof *p);
    if (!p) return -1;
    *array = p;
    return 0;
}

static inline size_t nbs_next_pow2(size_t n)
{
    size_t p = NBS_MIN_TABLE;
    while (p < n) p *= 2;
    return p;
}

/* A list head whether it is still new (h >= 0), old (-2 - h) or empty. */
static inline int32_t nbs_row_list(int32_t mark)
{
    return mark >= NBS_EMPTY ? mark : -2 - mark;
}

/* Cell size d = largest diameter, padded so that (1) rounding of
 * (x - xmin) * (1/d) stays well below one cell even at 1e6 m from the origin
 * (a relative 1e-9 plus 32 ulps of the extent), (2) the integer extent
 * stays below 2^40 cells, (3) all-zero radii still get a positive size.
 * span is the largest extent over the axes. */
static inline double nbs_padded_cell(double rmax, double span)
{
    double cell = 2.0 * rmax * (1.0 + 1e-9) + 32.0 * DBL_EPSILON * span;
    cell = fmax(cell, span / NBS_MAX_CELLS_PER_AXIS);
    if (!(cell > 0.0)) cell = 1.0;
    return cell;
}

/* The cells one axis spans, and whether that is more than the table holds
 * (then the integer coordinate is folded modulo the table). */
static inline void nbs_axis_plan(double span, double inv_cell, int32_t table,
                                 int32_t *size, int *fold)
{
    double real = floor(span * inv_cell) + 1.0;
    *fold = real > (double)table;
    *size = *fold ? table : (int32_t)real;
}

#endif /* FDEM_NBS_INTERNAL_H */
