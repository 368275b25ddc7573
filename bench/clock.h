/*
 * clock.h - the two clocks every bench reads, in seconds.
 *
 * Contract:
 *  - bench_wall_seconds(): CLOCK_MONOTONIC, for what a user waits.
 *  - bench_cpu_seconds(): CPU time of the calling thread, which leaves out
 *    the time a busy machine's other jobs held the core (wall time cannot):
 *    what the per-element figures are made of.
 */
#ifndef FDEM_BENCH_CLOCK_H
#define FDEM_BENCH_CLOCK_H

#include <time.h>

static inline double bench_clock_seconds(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline double bench_wall_seconds(void)
{
    return bench_clock_seconds(CLOCK_MONOTONIC);
}

static inline double bench_cpu_seconds(void)
{
    return bench_clock_seconds(CLOCK_THREAD_CPUTIME_ID);
}

#endif
