/*
 * worker_history.c - the worker's side of history output (see
 * worker_history.h for when rows are taken and queued).
 */
#include "worker_history.h"

#include <math.h>
#include <stdlib.h>

#include "io_thread.h"

/* The first history time strictly after `t` on the grid k * interval (as
 * worker_next_output does for snapshots). */
static double history_next(double interval, double t)
{
    double k = floor(t / interval * (1.0 + 1e-12) + 1e-9);
    return (k + 1.0) * interval;
}

static void history_take_row(server_case *c)
{
    if (c->history_pending_count == c->history_pending_capacity) {
        int capacity = c->history_pending_capacity ? 2 * c->history_pending_capacity : 16;
        history_row **grown = realloc(c->history_pending, sizeof *grown * (size_t)capacity);
        if (!grown) return; /* a row lost to memory, never the run */
        c->history_pending = grown;
        c->history_pending_capacity = capacity;
    }
    history_row *row = history_take(c->model, c->info.history_nodes,
                                    c->info.history_point_count);
    if (row) c->history_pending[c->history_pending_count++] = row;
}

void worker_history_start(server_case *c)
{
    double t = fdem_get_time(c->model);
    if (c->info.history_interval > 0) c->next_history = history_next(c->info.history_interval, t);
    if (fdem_get_step(c->model) == 0) history_take_row(c);
}

void worker_history_after_step(server_case *c, double dt, int snapshot_taken, int done)
{
    double interval = c->info.history_interval;
    if (!(interval > 0)) {
        if (snapshot_taken) history_take_row(c);
        return;
    }
    double t = fdem_get_time(c->model);
    if (done || t >= c->next_history - 1e-9 * dt) {
        history_take_row(c);
        c->next_history = history_next(interval, t);
    }
}

int worker_history_batch_full(const server_case *c)
{
    return c->history_pending_count >= WORKER_HISTORY_BATCH;
}

void worker_history_flush(server_case *c)
{
    if (c->history_pending_count == 0) return;
    io_append_history(c, c->history_pending, c->history_pending_count);
    c->history_pending = NULL;
    c->history_pending_count = c->history_pending_capacity = 0;
}

void worker_history_discard(server_case *c)
{
    result_free_history(c->history_pending, c->history_pending_count);
    c->history_pending = NULL;
    c->history_pending_count = c->history_pending_capacity = 0;
}
