/*
 * worker_history.c - the worker's side of history output (see
 * worker_history.h for when rows are taken and queued).
 */
#include "worker_history.h"

#include <stdlib.h>

#include "io_thread.h"
#include "state/output_grid.h"

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
    if (output_history_start(c->info.history_interval, fdem_get_time(c->model),
                             fdem_get_step(c->model), &c->next_history))
        history_take_row(c);
}

void worker_history_after_step(server_case *c, double dt, int snapshot_taken, int done)
{
    if (output_history_due(c->info.history_interval, fdem_get_time(c->model), dt, snapshot_taken,
                           done, &c->next_history))
        history_take_row(c);
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
