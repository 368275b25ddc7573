/*
 * amplitude.h - piecewise-linear amplitude tables a(t) of loads (contract
 * 5.3): (t, a) pairs with strictly increasing times, a held constant
 * before the first and after the last pair. A load without a table keeps
 * its plain value (callers skip the multiplication), so cases without
 * amplitudes step with exactly the arithmetic they had before.
 */
#ifndef FDEM_AMPLITUDE_H
#define FDEM_AMPLITUDE_H

#include <math.h>

/* 0 when every number is finite and the times strictly increase, else the
 * index of the first bad pair (1-based, so the caller can name it). */
static inline int amplitude_bad_pair(const double *pairs, int count)
{
    for (int k = 0; k < count; k++) {
        if (!isfinite(pairs[2 * k]) || !isfinite(pairs[2 * k + 1])) return k + 1;
        if (k > 0 && !(pairs[2 * k] > pairs[2 * k - 2])) return k + 1;
    }
    return 0;
}

static inline double amplitude_at(const double *pairs, int count, double t)
{
    if (t <= pairs[0]) return pairs[1];
    for (int k = 1; k < count; k++)
        if (t < pairs[2 * k]) {
            double t0 = pairs[2 * k - 2], a0 = pairs[2 * k - 1];
            double t1 = pairs[2 * k], a1 = pairs[2 * k + 1];
            return a0 + (a1 - a0) * (t - t0) / (t1 - t0);
        }
    return pairs[2 * count - 1];
}

#endif
