/*
 * worker_history.h - the history rows (contract 6.2) of a running case,
 * from the worker's side: when a row is due, taking it, and handing the
 * rows taken to the I/O thread in batches.
 *
 * A case with "history" takes a row at the first step boundary at or
 * after each multiple of its interval (and at the end); one without takes
 * a row with every snapshot. Rows are a few hundred bytes: the worker
 * keeps them and queues them before the next checkpoint (so a restart,
 * which cuts /history back to its checkpoint's step, keeps every row it
 * had) or once WORKER_HISTORY_BATCH wait, so a SWMR reader or GET
 * /cases/ID/history sees them soon without an HDF5 flush per row.
 * Taking a row never changes the model: results never depend on it.
 */
#ifndef FDEMD_WORKER_HISTORY_H
#define FDEMD_WORKER_HISTORY_H

#include "registry.h"

#define WORKER_HISTORY_BATCH 64

/* Before the first step of a run: the next row's time after the model's
 * time, and the row at t = 0 of a case that starts there. */
void worker_history_start(server_case *c);
/* After a step (model_lock held): takes a row when one is due; `snapshot_taken`
 * says a snapshot was taken at this step, `done` that it is the last. */
void worker_history_after_step(server_case *c, double dt, int snapshot_taken, int done);
/* Whether the rows waiting should be queued now (a batch is full). */
int worker_history_batch_full(const server_case *c);
/* Queues the rows waiting (model_lock not needed: only the worker touches them). */
void worker_history_flush(server_case *c);
/* Frees the rows waiting (a deleted case writes nothing more). */
void worker_history_discard(server_case *c);

#endif
