/*
 * sample_ring.h - the last few samples of a figure and their median, for
 * the estimates' timings (sizing_probe.c, case_sizing.c,
 * io_snapshot_cost.c): one reading held up by a busy disk or a
 * neighbour's burst must not price the next case, and a median of the
 * last SAMPLE_RING_SIZE does that.
 *
 * Contract:
 *  - median_in_place(v, n): sorts v[0..n) and returns v[n / 2] (n >= 1).
 *  - sample_ring_add(r, x): keeps x, dropping the oldest once full; zero
 *    the ring to start it.
 *  - sample_ring_median(r, fallback): the median of what it holds, or
 *    fallback when it holds nothing. No locking: callers that share a ring
 *    between threads hold their own lock.
 */
#ifndef FDEMD_COMMON_SAMPLE_RING_H
#define FDEMD_COMMON_SAMPLE_RING_H

#include <stdlib.h>
#include <string.h>

#define SAMPLE_RING_SIZE 9

typedef struct sample_ring {
    double value[SAMPLE_RING_SIZE];
    int count, next;
} sample_ring;

static inline int sample_compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static inline double median_in_place(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, sample_compare);
    return v[n / 2];
}

static inline void sample_ring_add(sample_ring *r, double x)
{
    r->value[r->next] = x;
    r->next = (r->next + 1) % SAMPLE_RING_SIZE;
    if (r->count < SAMPLE_RING_SIZE) r->count++;
}

static inline double sample_ring_median(const sample_ring *r, double fallback)
{
    if (r->count == 0) return fallback;
    double v[SAMPLE_RING_SIZE];
    memcpy(v, r->value, sizeof(double) * (size_t)r->count);
    return median_in_place(v, r->count);
}

#endif
