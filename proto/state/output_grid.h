/*
 * output_grid.h - when a run writes: the steps that take a snapshot or a
 * history row, and the one step that is cut to land on time.end. The
 * daemon's worker, its sizing (a dry run's step and snapshot counts) and
 * the batch runner (runner/run_case.c) follow these rules from one copy,
 * so the same case writes its rows at the same steps wherever it runs.
 *
 * Contract:
 *  - output_is_last_step(t0, dt, end): the step from t0 is the last; it is
 *    cut to end - t0 (no sliver of a step is left over).
 *  - output_at_end(t, dt, end): a run at t has no step left (the cut step
 *    lands on end up to rounding, within 1e-9 dt).
 *  - output_snapshot_interval(info): the case's output interval, else a
 *    hundredth of its end time.
 *  - output_next_time(interval, t): the first multiple of `interval`
 *    strictly after t (rounding-tolerant), for snapshots and history rows.
 *  - output_is_due(t, next, dt): the step boundary t is at or past `next`
 *    (within 1e-9 dt).
 *  - History rows (contract 6.2): a case with a "history" interval takes a
 *    row at the first step boundary at or after each multiple of it and at
 *    the end; one without takes a row with every snapshot; a run starting
 *    at step 0 takes one there. output_history_start() before the first
 *    step (returns whether to take the row of the start), then
 *    output_history_due() after each step (advances *next).
 *
 * Folder: proto/state/ (its contract: snapshot.h).
 */
#ifndef FDEM_OUTPUT_GRID_H
#define FDEM_OUTPUT_GRID_H

#include <stdint.h>
#include "case/case.h"

int output_is_last_step(double t0, double dt, double end);
int output_at_end(double t, double dt, double end);
double output_snapshot_interval(const case_info *info);
double output_next_time(double interval, double t);
int output_is_due(double t, double next, double dt);
int output_history_start(double interval, double t, int64_t step, double *next);
int output_history_due(double interval, double t, double dt, int snapshot_taken, int done,
                       double *next);

#endif
