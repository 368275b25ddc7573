/*
 * stream.h - single-core memory bandwidth, STREAM-style (McCalpin), shared
 * by the benches so that their ns/element figures can be set beside what
 * the memory system can move at all.
 *
 * Contract:
 *  - stream_bandwidth_gbs(): best-of-several triad a[i] = b[i] + s*c[i]
 *    over arrays much larger than the last-level cache of a small machine,
 *    in GB/s (1e9 bytes/s), counting 24 bytes per index as STREAM does
 *    (no write-allocate traffic). stream_copy_gbs(): the same for a[i] = b[i]
 *    (16 bytes per index). Both run on the calling thread only.
 *  - Takes about 0.3 s and 3 x 32 MB; returns 0 if memory is short.
 */
#ifndef FDEM_BENCH_STREAM_H
#define FDEM_BENCH_STREAM_H

#include <stdlib.h>
#include <time.h>

#include "math/clock.h"

#define STREAM_LENGTH ((size_t)4 << 20) /* doubles per array: 32 MB */
#define STREAM_REPEATS 8

/* kernel 0 = copy, 1 = triad; returns the best GB/s over the repeats */
static inline double stream_run(int kernel)
{
    size_t n = STREAM_LENGTH;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
    if (!a || !b || !c) {
        free(a), free(b), free(c);
        return 0.0;
    }
    for (size_t i = 0; i < n; i++) { /* touch every page before timing */
        a[i] = 0.0;
        b[i] = 1.0 + (double)(i & 7);
        c[i] = 2.0;
    }
    double best = 1e30, scalar = 3.0;
    for (int rep = 0; rep < STREAM_REPEATS; rep++) {
        double t0 = clock_wall_seconds();
        if (kernel == 0)
            for (size_t i = 0; i < n; i++) a[i] = b[i];
        else
            for (size_t i = 0; i < n; i++) a[i] = b[i] + scalar * c[i];
        double t = clock_wall_seconds() - t0;
        if (t < best) best = t;
        /* keep the result observable so the loop is not optimised away */
        scalar += a[(size_t)rep * 977 % n] * 1e-300;
    }
    volatile double sink = a[n / 2];
    (void)sink;
    free(a), free(b), free(c);
    double bytes = (kernel == 0 ? 16.0 : 24.0) * (double)n;
    return best > 0 ? bytes / best * 1e-9 : 0.0;
}

static inline double stream_bandwidth_gbs(void) { return stream_run(1); }
static inline double stream_copy_gbs(void) { return stream_run(0); }

#endif /* FDEM_BENCH_STREAM_H */
