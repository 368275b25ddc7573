/*
 * clock.h - the daemon's two clocks, in seconds (every folder may read
 * common/).
 *
 * Contract:
 *  - clock_wall_seconds(): CLOCK_MONOTONIC, for deadlines, rates and the
 *    wall time of a run; never jumps with the date.
 *  - clock_cpu_seconds(): CPU time of the calling thread, what stepping a
 *    model costs whatever else the machine does (the sizing probe).
 */
#ifndef FDEMD_COMMON_CLOCK_H
#define FDEMD_COMMON_CLOCK_H

#include <time.h>

static inline double clock_seconds_of(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline double clock_wall_seconds(void)
{
    return clock_seconds_of(CLOCK_MONOTONIC);
}

static inline double clock_cpu_seconds(void)
{
    return clock_seconds_of(CLOCK_THREAD_CPUTIME_ID);
}

#endif
