/*
 * case_model.c - building a case's model from its stored files when it
 * starts, and freeing it when it stops running.
 *
 * A stored 2000 x 2000 case used to keep ~1 GB in RAM from creation to
 * deletion. Now only running cases hold a model; every other figure a user
 * reads (status, results) is on disk or in the published figures, and GET
 * /state of a case that is not running rebuilds the model for the moment
 * it takes to copy the state (the same rebuild a start does, under the
 * same budget).
 */
#include "case_model.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "files/checkpoint_file.h"
#include "io_thread.h"
#include "files/persist.h"

#define CASE_MODEL_MAX_CHECKPOINT ((size_t)1 << 40)

size_t case_model_cost(double estimate)
{
    /* Each thread of a running case may hold contact touch lists of its own
     * (fdem_memory_per_thread; the 3D figure, as the gate does not know the
     * dimension): ~0.4 MB a thread, outside the one-thread estimate. */
    const fdemd_config *cfg = registry_config();
    int threads = cfg && cfg->threads > 1 ? cfg->threads : 0;
    double cost = estimate * 1.25 + (double)threads * (double)fdem_memory_per_thread(3);
    return cost >= (double)((size_t)-1 / 2) ? (size_t)-1 / 2 : (size_t)cost;
}

size_t case_model_cost_of(server_case *c)
{
    pthread_mutex_lock(&c->lock);
    fdem_counts n = c->fig.counts;
    pthread_mutex_unlock(&c->lock);
    return case_model_cost((double)fdem_memory_estimate_of(&n));
}

int case_model_gate(void *ctx, double estimate)
{
    case_model_gate_ctx *g = ctx;
    g->estimate = estimate;
    size_t cost = case_model_cost(estimate);
    /* The tree is gone by now; what the lease held for it is the model's. */
    size_t spare = g->lease->bytes > g->kept ? g->lease->bytes - g->kept : 0;
    return cost <= spare ? 0 : membudget_grow(g->lease, cost - spare);
}

/* Allocation failures anywhere in the builder and the engine say this. */
static int case_model_out_of_memory(const char *message)
{
    return strstr(message, "out of memory") != NULL;
}

static int case_model_problems_out_of_memory(const problems *p)
{
    for (int i = 0; i < p->count; i++)
        if (case_model_out_of_memory(p->items[i].message))
            return 1;
    return 0;
}

/* The file and the meshes read from it stay while the model is built. */
static size_t case_model_document_cost(size_t bytes)
{
    return bytes > (size_t)-1 / 4 ? (size_t)-1 / 2 : 2 * bytes;
}

static case_model_rc case_model_parse(server_case *c, membudget_lease *lease, fdem_model **model,
                                      case_info *info, char *err, size_t errlen)
{
    char path[1200], *doc = NULL;
    size_t size = 0;
    struct stat st;
    snprintf(path, sizeof path, "%s/case.json", c->dir);
    if (stat(path, &st) == 0 && membudget_grow(lease, case_model_document_cost((size_t)st.st_size)) != 0)
        return CASE_MODEL_NO_MEMORY;
    if (persist_read_file(path, &doc, &size, CASE_MODEL_MAX_DOCUMENT) != 0) {
        snprintf(err, errlen, "case.json could not be read: %s", strerror(errno));
        return CASE_MODEL_BROKEN;
    }
    problems p;
    problems_init(&p);
    case_model_gate_ctx gate = {lease, case_model_document_cost(size), 0};
    /* No --max-case-memory here: the case was admitted when it was stored,
     * and a lower limit since must not turn it into a broken case. */
    membudget_meter_begin(lease, 0);
    *model = case_build_gated(doc, size, (size_t)-1, case_model_gate, &gate, info, &p, NULL);
    membudget_meter_end();
    free(doc);
    case_model_rc rc = CASE_MODEL_OK;
    if (!*model && (membudget_meter_refused() || p.status == 503 ||
                    case_model_problems_out_of_memory(&p))) {
        rc = CASE_MODEL_NO_MEMORY;
    } else if (!*model) {
        snprintf(err, errlen, "the stored case could not be rebuilt: %s",
                 p.count ? p.items[0].message : "unknown problem");
        rc = CASE_MODEL_BROKEN;
    }
    problems_free(&p);
    return rc;
}

/* Restores checkpoint.bin, or when `resume` and an extended case has one,
 * CASE_RESUME_CHECKPOINT (case_model.h). */
static case_model_rc case_model_restore(server_case *c, fdem_model *model, int resume, char *err,
                                        size_t errlen)
{
    char path[1200], *ckpt = NULL;
    size_t size = 0;
    const char *name = CASE_CHECKPOINT;
    c->resume_rows_until = -1;
    snprintf(path, sizeof path, "%s/%s", c->dir, CASE_RESUME_CHECKPOINT);
    int resuming = resume && access(path, F_OK) == 0;
    if (resuming)
        name = CASE_RESUME_CHECKPOINT;
    snprintf(path, sizeof path, "%s/%s", c->dir, name);
    if (persist_read_file(path, &ckpt, &size, CASE_MODEL_MAX_CHECKPOINT) != 0) {
        /* Only a file that is not there means "from t = 0". One that is
         * there but cannot be read (EIO, past the size limit, not a
         * regular file) restored as step 0 would cut result.h5 back to its
         * first row; it fails the case with its files kept instead, and a
         * failed allocation waits for memory like the engine's own. */
        if (errno == ENOMEM)
            return CASE_MODEL_NO_MEMORY;
        if (errno != ENOENT) {
            snprintf(err, errlen, "%s could not be read: %s", name, strerror(errno));
            return CASE_MODEL_BROKEN;
        }
        pthread_mutex_lock(&c->lock);
        int started = c->fig.step != 0;
        pthread_mutex_unlock(&c->lock);
        if (started)
            fprintf(stderr, "fdemd: case %s: no checkpoint (%s), resuming from t = 0\n", c->id,
                    strerror(errno));
        return CASE_MODEL_OK;
    }
    size_t payload = 0;
    char damage[256] = "";
    checkpoint_file_kind kind = checkpoint_file_open(ckpt, size, &payload, damage, sizeof damage);
    if (kind == CHECKPOINT_FILE_DAMAGED) {
        free(ckpt);
        snprintf(err, errlen, "%s could not be restored: %s", name, damage);
        return CASE_MODEL_BROKEN;
    }
    if (kind == CHECKPOINT_FILE_BARE)
        fprintf(stderr, "fdemd: case %s: %s has no checksum (written before fdemd sealed its "
                "checkpoints); restoring it on the engine's own checks\n", c->id, name);
    fdem_error e;
    memset(&e, 0, sizeof e);
    int failed = fdem_checkpoint_read(model, ckpt, payload, &e) != 0;
    free(ckpt);
    if (failed && case_model_out_of_memory(e.message))
        return CASE_MODEL_NO_MEMORY;
    if (failed) {
        snprintf(err, errlen, "%s could not be restored: %s", name, e.message);
        return CASE_MODEL_BROKEN;
    }
    if (resuming)
        c->resume_rows_until = fdem_get_step(model) + 1; /* the old end's row */
    return CASE_MODEL_OK;
}

void case_model_forget_resume(server_case *c)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", c->dir, CASE_RESUME_CHECKPOINT);
    if (unlink(path) == 0)
        persist_fsync_dir(c->dir);
}

fdem_model *case_model_build_upload(const char *body, size_t size, membudget_lease *lease,
                                    case_info *info, problems *p, double *model_bytes,
                                    problems *warnings)
{
    size_t kept = case_model_document_cost(size);
    case_model_gate_ctx gate = {lease, kept, 0};
    membudget_meter_begin(lease, lease->bytes > kept ? lease->bytes - kept : 0);
    /* the warnings come from the build's own tree: one parse of any size */
    fdem_model *model = case_build_gated(body, size, registry_config()->max_case_memory,
                                         case_model_gate, &gate, info, p, warnings);
    membudget_meter_end();
    /* The tree is freed by now. Its pages go back at once: with the one
     * parse (no second tree before this one) glibc otherwise kept up to
     * 0.7 MiB of them per upload (test_memory's stored cases). */
    membudget_give_back();
    if (!model && membudget_meter_refused()) {
        /* jansson saw its allocation refused and called the body malformed */
        problems_free(p);
        problems_init(p);
        snprintf(p->title, sizeof p->title, "Service unavailable");
        problems_add(p, 503, "", "parsing this case needs more memory than the daemon has to "
                                 "spare now (--max-memory); try again later");
    }
    if (model_bytes)
        *model_bytes = gate.estimate;
    return model;
}

static case_model_rc case_model_build_from(server_case *c, membudget_lease *lease,
                                           fdem_model **model, case_info *info, int resume,
                                           char *err, size_t errlen)
{
    size_t held = lease->bytes;
    *model = NULL;
    case_model_rc rc = case_model_parse(c, lease, model, info, err, errlen);
    if (rc == CASE_MODEL_OK)
        rc = case_model_restore(c, *model, resume, err, errlen);
    if (rc != CASE_MODEL_OK) {
        if (*model)
            fdem_model_destroy(*model);
        *model = NULL;
        membudget_shrink(lease, lease->bytes - held);
        return rc;
    }
    fdem_counts n = fdem_get_counts(*model);
    size_t cost = case_model_cost((double)fdem_memory_estimate_of(&n));
    if (lease->bytes > cost)
        membudget_shrink(lease, lease->bytes - cost); /* the file and its tree are freed */
    return CASE_MODEL_OK;
}

case_model_rc case_model_build(server_case *c, membudget_lease *lease, fdem_model **model,
                               case_info *info, char *err, size_t errlen)
{
    return case_model_build_from(c, lease, model, info, 1, err, errlen);
}

int case_model_attach(server_case *c, fdem_model *model, const case_info *info, int close_after,
                      char *err, size_t errlen)
{
    pthread_mutex_lock(&c->model_lock);
    c->model = model;
    c->info = *info;
    pthread_mutex_unlock(&c->model_lock);
    int64_t step = fdem_get_step(model);
    c->last_snapshot_step = c->last_checkpoint_step = step;
    int64_t keep = c->resume_rows_until > step ? c->resume_rows_until : step;
    if (io_reopen(c, keep, close_after, err, errlen) == 0)
        return 0;
    /* A file that is there but will not open holds the snapshots the
     * status reported: a new one would silently drop them. It is kept as
     * found (the case fails, as for a damaged checkpoint), so that putting
     * a good copy back brings the case back. Only a missing one is made
     * anew. */
    char path[1200], why[512];
    struct stat st;
    snprintf(path, sizeof path, "%s/result.h5", c->dir);
    if (lstat(path, &st) == 0 || errno != ENOENT) {
        snprintf(why, sizeof why, "%s", err);
        snprintf(err, errlen, "result.h5 could not be reopened (it is kept as found): %s", why);
        return -1;
    }
    fprintf(stderr, "fdemd: case %s: result.h5 is missing; starting a new one from the "
            "checkpoint\n", c->id);
    snapshot *s = snapshot_take(model, info->fields);
    if (io_create(c, s, NULL, 0, err, errlen) != 0)
        return -1;
    if (close_after)
        io_close(c);
    return 0;
}

void case_model_free(server_case *c)
{
    io_close(c);
    pthread_mutex_lock(&c->model_lock);
    fdem_model *model = c->model;
    c->model = NULL;
    pthread_mutex_unlock(&c->model_lock);
    if (model)
        fdem_model_destroy(model);
}

void case_model_drop(server_case *c)
{
    case_model_free(c);
    membudget_release(&c->reserve);
}

snapshot *case_model_state_from_disk(server_case *c, unsigned fields, int *status,
                                     char *stage_name, size_t stage_name_size)
{
    membudget_lease lease = {0};
    *status = 503;
    if (membudget_grow(&lease, case_model_cost_of(c)) != 0)
        return NULL;
    fdem_model *model = NULL;
    case_info info;
    char err[512] = "";
    /* The state the case shows is its checkpoint.bin, also when an extend
     * will resume it from the step before its old end. */
    case_model_rc rc = case_model_build_from(c, &lease, &model, &info, 0, err, sizeof err);
    snapshot *s = NULL;
    if (rc == CASE_MODEL_OK) {
        s = snapshot_take(model, fields);
        const char *name = s ? case_stage_name(&info, s->stage) : NULL;
        snprintf(stage_name, stage_name_size, "%s", name ? name : "");
        fdem_model_destroy(model);
    } else if (rc == CASE_MODEL_BROKEN) {
        fprintf(stderr, "fdemd: case %s: GET /state: %s\n", c->id, err);
        *status = 409;
    }
    membudget_release(&lease);
    return s;
}
