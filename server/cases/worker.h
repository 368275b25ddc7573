/*
 * worker.h - one thread per running case: steps the model and hands
 * snapshots and checkpoints to the I/O thread.
 *
 * Contract: worker_spawn() is called with the registry lock and the case
 * lock held, with the case in state running; it sets worker_active and the
 * thread takes its own reference. The worker acts on c->command at the next
 * step boundary, waits until its last snapshot and checkpoint are on disk,
 * hands the final state (paused, stopped, finished, failed) to
 * registry_worker_exited() (slot freed, status persisted, queued cases
 * started), and only then clears worker_active and broadcasts c->cv, so a
 * pause or stop is answered after everything it implies is durable.
 */
#ifndef FDEMD_WORKER_H
#define FDEMD_WORKER_H

#include "registry.h"

int worker_spawn(server_case *c);

#endif
