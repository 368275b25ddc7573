/*
 * output_grid.c - the step grid of a run's output (output_grid.h): where
 * snapshots and history rows fall, and the last step's cut.
 */
#include "output_grid.h"

#include <math.h>

int output_is_last_step(double t0, double dt, double end)
{
    return t0 + dt >= end - 1e-9 * dt; /* no sliver of a step left over */
}

int output_at_end(double t, double dt, double end)
{
    return !(end - t > 1e-9 * dt);
}

double output_snapshot_interval(const case_info *info)
{
    double interval = info->output_interval;
    if (!(interval > 0))
        interval = info->end_time / 100.0;
    return interval > 0 ? interval : 1.0;
}

double output_next_time(double interval, double t)
{
    double k = floor(t / interval * (1.0 + 1e-12) + 1e-9);
    return (k + 1.0) * interval;
}

int output_is_due(double t, double next, double dt)
{
    return t >= next - 1e-9 * dt;
}

int output_history_start(double interval, double t, int64_t step, double *next)
{
    if (interval > 0)
        *next = output_next_time(interval, t);
    return step == 0;
}

int output_history_due(double interval, double t, double dt, int snapshot_taken, int done,
                       double *next)
{
    if (!(interval > 0))
        return snapshot_taken;
    if (!done && !output_is_due(t, *next, dt))
        return 0;
    *next = output_next_time(interval, t);
    return 1;
}
