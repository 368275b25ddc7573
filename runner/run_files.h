/*
 * run_files.h - the plain files of a case directory as the batch runner
 * writes and reads them: status.json in the daemon's shape (its figures
 * from proto/state/status_json.h), sealed checkpoints, the stored case
 * document. result.h5 and result.xdmf are proto/result's.
 *
 * Contract:
 *  - run_status_write() writes status.json atomically (proto/files/persist.h):
 *    "id" (the directory's name), "name", "state", the figures, "ranks",
 *    "error", "created", "started", "finished_at", "elapsed",
 *    "estimated_seconds" (null), "eta", "warnings" and "runner":
 *    "fdem-run"; a daemon lists such a directory as one of its cases.
 *  - run_status_read_times() reads back created/started/elapsed and the
 *    warnings (added to s->warnings) of a directory being resumed
 *    (missing: left as they are).
 *  - run_checkpoint_write() seals and writes the model's checkpoint as
 *    `name`; run_checkpoint_restore() restores `name` into a model just
 *    built from the same document. Both 0, or -1 with err.
 */
#ifndef FDEM_RUN_FILES_H
#define FDEM_RUN_FILES_H

#include <stddef.h>
#include <jansson.h>
#include "case/case.h"
#include "fdem.h"
#include "state/status_json.h"

typedef struct run_status {
    const char *state;         /* "running", "paused", "stopped", "finished", "failed" */
    const char *error;         /* NULL or "" = none */
    int ranks;
    double eta;                /* NAN: unknown */
    json_t *warnings;          /* contract 6.2's list (status_json.h); NULL: [] */
    char created[40], started[40], finished_at[40];
} run_status;

int run_status_write(const char *dir, const case_info *info, const run_figures *f,
                     const run_status *s, char *err, size_t errlen);
void run_status_read_times(const char *dir, run_status *s, double *elapsed);
int run_checkpoint_write(const char *dir, const char *name, const fdem_model *m, char *err,
                         size_t errlen);
int run_checkpoint_restore(const char *dir, const char *name, fdem_model *m, char *err,
                           size_t errlen);
int run_has_file(const char *dir, const char *name);
/* Whether `dir` holds a run to resume (case.json and checkpoint.bin). */
int run_dir_resumable(const char *dir);

#endif
