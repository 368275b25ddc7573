/*
 * worker_ranked.h - the worker of a case with "parallel": {"ranks": N > 1}
 * (contract 6.5): instead of stepping the model in this process, it starts
 * the case's ranks with the --launcher line (runner/launch.h) running
 * bin/fdem-rank on the case directory, and follows them.
 *
 * Contract:
 *  - Called by worker.c's thread with the case's model taken and its
 *    result.h5 already cut back to checkpoint.bin (the start's own
 *    checks); it closes the file and frees the model, then launches. The
 *    ranks resume from checkpoint.bin and write result.h5, result.xdmf,
 *    checkpoint.bin and status.json in the case directory with the
 *    daemon's writers; their output goes to ranks.log there.
 *  - While they run, the case's published figures follow their
 *    status.json (step, time, snapshots, energy...).
 *  - Commands go down a pipe on the launcher's stdin (which mpirun and
 *    srun hand to rank 0): pause ("pause": the ranks checkpoint and exit),
 *    stop ("stop": a last snapshot and checkpoint), delete (SIGTERM to the
 *    launcher's process group: mpirun ends its ranks before it exits). If the daemon dies, the pipe's end of file makes
 *    the ranks checkpoint and exit paused: they never step on unseen, and
 *    the restarted daemon lists the case paused at that checkpoint.
 *  - Returns the final state; a launcher that cannot be started or ranks
 *    that fail set c->error to a sentence that says what to do.
 */
#ifndef FDEMD_WORKER_RANKED_H
#define FDEMD_WORKER_RANKED_H

#include "registry.h"

case_state worker_ranked_run(server_case *c);

#endif
