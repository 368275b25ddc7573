/*
 * eta_window.h - the running status' eta (contract 6.2): the simulated
 * time left over the simulated seconds per wall second of a recent window.
 * The in-process worker samples it as it publishes; a ranked case's worker
 * as the ranks' status.json moves on. One window for both, so a case gives
 * the same kind of eta whatever steps it.
 *
 * Contract: eta_window_take(w, now, time, end) adds the sample (now, time)
 * when ETA_SAMPLE_EVERY has passed since the last one and returns the wall
 * seconds left at the speed over the last ETA_SAMPLES samples (8 s: long
 * enough that one slow step or a snapshot write does not swing it, short
 * enough to follow a case that slows once it breaks); NAN while the window
 * is shorter than ETA_MIN_WINDOW or the case is not advancing. Zero the
 * struct to start a window.
 */
#ifndef FDEMD_CASES_ETA_WINDOW_H
#define FDEMD_CASES_ETA_WINDOW_H

#include <math.h>

#define ETA_SAMPLES 32
#define ETA_SAMPLE_EVERY 0.25
#define ETA_MIN_WINDOW 0.2

typedef struct eta_window {
    double wall[ETA_SAMPLES], time[ETA_SAMPLES];
    int count, next;
} eta_window;

static inline double eta_window_take(eta_window *w, double now, double time, double end)
{
    int newest = (w->next + ETA_SAMPLES - 1) % ETA_SAMPLES;
    if (w->count == 0 || now - w->wall[newest] >= ETA_SAMPLE_EVERY) {
        w->wall[w->next] = now;
        w->time[w->next] = time;
        w->next = (w->next + 1) % ETA_SAMPLES;
        if (w->count < ETA_SAMPLES) w->count++;
    }
    int oldest = w->count < ETA_SAMPLES ? 0 : w->next;
    double wall = now - w->wall[oldest], advanced = time - w->time[oldest];
    if (!(wall >= ETA_MIN_WINDOW) || !(advanced > 0))
        return NAN;
    double left = end - time;
    return left > 0 ? left * wall / advanced : 0.0;
}

#endif
