/*
 * runner/ - drivers of the engine outside the daemon: the batch loop of
 *    bin/fdem-run and bin/fdem-rank (this header, run_case.c, the case
 *    directory's files in run_files.c) and, in runner/mpi/, the rank
 *    engine that steps one model on N MPI ranks.
 *  - May call: core/ and proto/ (the same writers the daemon uses, so a
 *    directory written here is a daemon's case directory). Never server/.
 *  - Called by: bin/fdem-run's and bin/fdem-rank's mains (runner/fdem_run_main.c, runner/fdem_rank_main.c).
 */
/*
 * run_case.h - one case run to its end (or to a pause) without a daemon.
 *
 * Contract:
 *  - run_case() reads the case document, builds the model and steps it to
 *    time.end, writing into `out_dir` what a daemon's case directory holds:
 *    case.json, result.h5 (+ result.xdmf), checkpoint.bin (sealed,
 *    proto/files/checkpoint_file.h), checkpoint-end.bin and status.json.
 *    Snapshots, history rows and the cut last step fall on the daemon's
 *    grid (proto/state/output_grid.h), so result.h5's datasets are the
 *    daemon's bit for bit at the same steps.
 *  - An `out_dir` holding case.json and checkpoint.bin is resumed: the
 *    model is rebuilt from them and result.h5 is cut back to the
 *    checkpoint's step, as a daemon's start does (a pause, a SIGKILL).
 *  - Commands: SIGTERM/SIGINT, or "pause"/"stop" lines on control_fd,
 *    end the run at the next step boundary with a checkpoint (state
 *    paused; a stop also takes a last snapshot, state stopped). End of file
 *    on control_fd (the daemon that launched us is gone) is a pause: the
 *    run never goes on unseen, and a later start resumes from it.
 *  - With a stepper (rank engines), stepper->step replaces fdem_step,
 *    stepper->gather runs on every rank before any output, stepper->agree
 *    (may be NULL) makes a command seen by one rank every rank's, and only
 *    the rank with is_writer touches files. NULL: fdem_step, one process.
 *  - Returns the outcome; on RUN_BAD_CASE the problems are printed to
 *    stderr at their JSON Pointers and nothing is written but status.json.
 */
#ifndef FDEM_RUN_CASE_H
#define FDEM_RUN_CASE_H

#include "fdem.h"

typedef struct runner_stepper {
    void *ctx;
    int (*step)(void *ctx, fdem_model *m, fdem_error *err);   /* one step, collective */
    int (*gather)(void *ctx, fdem_model *m, fdem_error *err); /* make rank 0's model whole
                                                                 before output/checkpoint */
    int is_writer;                                            /* rank 0: writes files */
    /* the largest `local` over the ranks (collective); NULL: one process */
    int (*agree)(void *ctx, int local);
} runner_stepper;

typedef struct run_options {
    const char *case_path;   /* the case document */
    const char *out_dir;     /* the case directory (made when missing) */
    int threads;             /* OpenMP threads (fdem_set_threads); < 1: 1 */
    int ranks;               /* shown in status.json (the launcher's -np) */
    int control_fd;          /* -1: none (see the contract) */
    double status_every;     /* wall seconds between status.json writes; <= 0: 0.5 */
    int quiet;               /* no progress lines on stderr */
    long long pause_at_step; /* > 0: pause at this step boundary (tests, chunked batch jobs) */
} run_options;

typedef enum run_outcome {
    RUN_FINISHED = 0, RUN_PAUSED, RUN_STOPPED, RUN_FAILED, RUN_BAD_CASE,
} run_outcome;

run_outcome run_case(const run_options *o, runner_stepper *stepper);
/* The process exit status of an outcome: 0 finished, 3 paused, 4 stopped,
 * 1 failed, 2 bad case (documented in docs/cluster.md). */
int run_exit_status(run_outcome outcome);
const char *run_outcome_state(run_outcome outcome);

#endif
