/*
 * worker.h - one thread per running case: steps the model and hands
 * snapshots and checkpoints to the I/O thread.
 *
 * Contract: worker_spawn() is called with the registry lock and the case
 * lock held, with the case in state running; it sets worker_active and the
 * thread takes its own reference. The worker acts on c->command at the next
 * step boundary, sets the final state (paused, stopped, finished, failed),
 * persists the status, clears worker_active, broadcasts c->cv and tells the
 * registry a slot is free.
 */
#ifndef FDEMD_WORKER_H
#define FDEMD_WORKER_H

#include "registry.h"

int worker_spawn(server_case *c);

#endif
