/*
 * sizing_probe.h - timing a model's steps on this machine for the run-time
 * estimate (case_sizing.h).
 *
 * Contract:
 *  - sizing_probe_step_seconds() steps the model (ADVANCES it: only a
 *    throwaway model) through an untimed warm-up and several short timed
 *    windows of one power-of-2 number of steps each (from the warm-up's pace), at most steps_left steps in all (*taken says how many), and
 *    returns the median window's CPU seconds per step of the stepping
 *    thread: NAN when a step failed. The windows' wall and CPU seconds are
 *    added to *load. It takes about 0.05 s for a small model, and on one
 *    whose step is slow a handful of steps (at least 5 when there are
 *    that many).
 *  - sizing_load_factor() turns CPU seconds into the run's wall seconds
 *    on this machine now: the median wall / CPU of the stepping thread
 *    over the daemon's last 9 runs of at least 0.2 s (sizing_note_run,
 *    called by the worker as a run ends), or before any the geometric
 *    mean of (one-minute load average + 1) / cores and the windows' own
 *    wall / CPU seconds (the median of the last 9 probes' including
 *    *load's); at least 1.
 *  - sizing_step() is one untimed step (1 or 0 as fdem_step), for the
 *    estimate's other walks through the model.
 *  The clocks are math/clock.h's.
 */
#ifndef FDEMD_SIZING_PROBE_H
#define FDEMD_SIZING_PROBE_H

#include "fdem.h"

typedef struct sizing_load {
    double wall, cpu;   /* seconds, summed over timed windows */
} sizing_load;

double sizing_probe_step_seconds(fdem_model *model, double steps_left, int *taken,
                                 sizing_load *load);
double sizing_load_factor(const sizing_load *load);
void sizing_note_run(double wall, double cpu);
int sizing_step(fdem_model *model);

#endif
