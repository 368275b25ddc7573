/*
 * case_model.h - a case holds its model only while it runs (contract 5.5).
 *
 * Contract:
 *  - case_model_build() rebuilds a case's model from DIR/ID/case.json and
 *    checkpoint.bin (the path both a start and a restart take), charging
 *    the file, its JSON tree and the model to `lease`; on success the lease
 *    holds exactly case_model_cost() of the model. It never marks the case:
 *    it says whether memory was short (try again later) or the stored files
 *    are broken (err says which and why).
 *  - case_model_attach() makes a built model the case's and opens its
 *    result file at the model's step (snapshots a crash left after the
 *    checkpoint are dropped); a result.h5 that is there but cannot be
 *    reopened is an error and is left as found (only a missing one is made
 *    anew from the checkpoint); case_model_drop() closes the result file,
 *    frees the model and releases c->reserve.
 *  - Extend (case_continue.c): the worker keeps, besides checkpoint.bin,
 *    the state one step before the step it cut to land on time.end
 *    (CASE_END_CHECKPOINT). Extending a finished case renames it to
 *    CASE_RESUME_CHECKPOINT, and case_model_build() then resumes from it
 *    (c->resume_rows_until: the end's row and those before it are kept),
 *    so the run goes on on the step grid of an uninterrupted run; the
 *    first checkpoint.bin written after it makes it go
 *    (case_model_forget_resume).
 *  - case_model_state_from_disk() answers GET /state of a case that is not
 *    running from a temporary rebuild under the budget: the state of its
 *    last checkpoint, which for a paused, finished or stopped case is the
 *    step it stopped at.
 */
#ifndef FDEMD_CASE_MODEL_H
#define FDEMD_CASE_MODEL_H

#include "common/memory_budget.h"
#include "files/checkpoint_file.h"
#include "registry.h"

#define CASE_CHECKPOINT CHECKPOINT_FILE_LATEST
#define CASE_END_CHECKPOINT CHECKPOINT_FILE_END
#define CASE_RESUME_CHECKPOINT CHECKPOINT_FILE_RESUME

/* The largest case.json read back (the upload limit is far below it). */
#define CASE_MODEL_MAX_DOCUMENT ((size_t)1 << 34)

typedef enum case_model_rc {
    CASE_MODEL_OK = 0,
    CASE_MODEL_NO_MEMORY, /* the budget is short now; nothing changed */
    CASE_MODEL_BROKEN,    /* case.json or checkpoint.bin cannot give a model */
} case_model_rc;

/* What holding a model of about `estimate` bytes (fdem_memory_estimate)
 * is charged: the model, one checkpoint copy on its way to disk, and the
 * contact lists of each thread it runs on. */
size_t case_model_cost(double estimate);
/* The same from the counts the case last published. */
size_t case_model_cost_of(server_case *c);

/* The gate case_build_gated() calls: ctx is a case_model_gate_ctx. */
typedef struct case_model_gate_ctx {
    membudget_lease *lease;
    size_t kept; /* bytes of the lease still in use while the model is built */
    double estimate; /* the builder's estimate of the model's bytes, once asked */
} case_model_gate_ctx;
int case_model_gate(void *ctx, double estimate);

/* case_build() of an upload: `lease` already holds the request's admission
 * (membudget_upload_cost); the JSON tree and the model are charged to it.
 * Memory short now is one problem with status 503. model_bytes (may be
 * NULL) gets the builder's estimate of the model (proto/case/case_memory.c). */
fdem_model *case_model_build_upload(const char *body, size_t size, membudget_lease *lease,
                                    case_info *info, problems *p, double *model_bytes,
                                    problems *warnings);
case_model_rc case_model_build(server_case *c, membudget_lease *lease, fdem_model **model,
                               case_info *info, char *err, size_t errlen);
/* 0, or -1 with err when no result file could be opened or made. */
int case_model_attach(server_case *c, fdem_model *model, const case_info *info, int close_after,
                      char *err, size_t errlen);
void case_model_drop(server_case *c);
/* case_model_drop() but for the reserve, which stays: a ranked case's
 * ranks hold the model in their own processes meanwhile. */
void case_model_free(server_case *c);
/* Removes CASE_RESUME_CHECKPOINT (a newer checkpoint.bin is durable). */
void case_model_forget_resume(server_case *c);

/* NULL with *status 503 (no memory now) or 409 (cannot be rebuilt). */
snapshot *case_model_state_from_disk(server_case *c, unsigned fields, int *status,
                                     char *stage_name, size_t stage_name_size);

#endif
