/*
 * sizing_probe.h - timing a model's steps on this machine for the run-time
 * estimate (case_sizing.h).
 *
 * Contract:
 *  - sizing_probe_step_seconds() steps the model (ADVANCES it: only a
 *    throwaway model) through an untimed warm-up and several short timed
 *    windows, at most steps_left steps in all (*taken says how many), and
 *    returns the median window's wall seconds per step: NAN when a step
 *    failed. It takes about 0.05 s for a small model, and on one whose
 *    step is slow a handful of steps (at least 5 when there are that many).
 *  - sizing_clock() is the monotonic clock it times with, in seconds.
 */
#ifndef FDEMD_SIZING_PROBE_H
#define FDEMD_SIZING_PROBE_H

#include "fdem.h"

double sizing_probe_step_seconds(fdem_model *model, double steps_left, int *taken);
double sizing_clock(void);

#endif
