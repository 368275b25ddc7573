/*
 * clock.h - the two clocks of the whole tree, in seconds: the engine's
 * stage timings, the daemon's deadlines and rates, fdem-run's status and
 * the benches all read these, so one figure means one thing everywhere.
 *
 * Contract:
 *  - clock_wall_seconds(): CLOCK_MONOTONIC, for deadlines, rates and what
 *    a user waits; never jumps with the date.
 *  - clock_cpu_seconds(): CPU time of the calling thread, what stepping a
 *    model costs whatever else the machine does (the sizing probe, the
 *    per-element bench figures).
 */
#ifndef FDEM_MATH_CLOCK_H
#define FDEM_MATH_CLOCK_H

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
