/*
 * registry_create.c - storing an uploaded case (POST /cases, a clone) and
 * sizing one without storing it (dry_run).
 *
 * A case is built, its t = 0 written (case.json, result.h5, checkpoint,
 * status.json) in DIR/.tmp-ID and made durable before the directory is
 * renamed into place: the rename is the moment the case exists, so a crash
 * while storing leaves nothing start-up would list. Only then does it join
 * the registry (registry_admit), which is the one step that takes its lock.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>

#include "case_feed.h"
#include "case_model.h"
#include "files/checkpoint_file.h"
#include "case_sizing.h"
#include "io_thread.h"
#include "files/persist.h"
#include "registry_internal.h"

/* A case id: CASE_ID_LEN hex digits from the kernel's random source. */
static int id_generate(char out[CASE_ID_LEN + 1])
{
    unsigned char raw[CASE_ID_LEN / 2];
    size_t got = 0;
    while (got < sizeof raw) {
        ssize_t n = getrandom(raw + got, sizeof raw - got, 0);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return -1;
        }
        got += (size_t)n;
    }
    for (size_t i = 0; i < sizeof raw; i++)
        snprintf(out + 2 * i, 3, "%02x", raw[i]);
    return 0;
}

/* A new case is built in DIR/.tmp-ID and renamed into place once whole,
 * so a crash while storing it leaves nothing that start-up would list. */
static int case_make_dir(server_case *c, char *final_dir, size_t final_size)
{
    for (int attempt = 0; attempt < 16; attempt++) {
        if (id_generate(c->id) != 0)
            return -1;
        snprintf(final_dir, final_size, "%s/%s", registry_config()->data_dir, c->id);
        snprintf(c->dir, sizeof c->dir, "%s/.tmp-%s", registry_config()->data_dir, c->id);
        struct stat st;
        if (stat(final_dir, &st) == 0)
            continue;
        if (mkdir(c->dir, 0755) == 0)
            return 0;
        if (errno != EEXIST)
            return -1;
    }
    errno = EEXIST;
    return -1;
}

/* Makes the files of the new case durable, then renames its directory
 * into place (the rename is the moment the case exists). */
static int case_publish_dir(server_case *c, const char *final_dir, char *err, size_t errlen)
{
    static const char *const files[] = {"result.h5", "result.xdmf"};
    char path[1300];
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        snprintf(path, sizeof path, "%s/%s", c->dir, files[i]);
        if (persist_fsync_path(path) != 0 && errno != ENOENT) {
            snprintf(err, errlen, "cannot sync %s: %s", files[i], strerror(errno));
            return -1;
        }
    }
    if (persist_fsync_dir(c->dir) != 0 || rename(c->dir, final_dir) != 0) {
        snprintf(err, errlen, "cannot move the new case into %s: %s", final_dir, strerror(errno));
        return -1;
    }
    snprintf(c->dir, sizeof c->dir, "%s", final_dir);
    if (persist_fsync_dir(registry_config()->data_dir) != 0) {
        snprintf(err, errlen, "cannot sync the data directory: %s", strerror(errno));
        return -1;
    }
    return 0;
}

/* The model of an uploaded case, or NULL with `p` and *http_status; the
 * document's warnings (values far outside rock and steel) into `warnings`. */
static fdem_model *registry_build_upload(const char *body, size_t size, membudget_lease *lease,
                                         case_info *info, double *model_bytes, problems *p,
                                         int *http_status, problems *warnings)
{
    memset(info, 0, sizeof *info);
    fdem_model *model = case_model_build_upload(body, size, lease, info, p, model_bytes,
                                                warnings);
    if (!model) {
        *http_status = p->status ? p->status : 422;
        if (p->count == 0)
            problems_add(p, 422, "", "the case could not be built");
    }
    int max_ranks = registry_config()->max_ranks;
    if (model && info->ranks > max_ranks) {
        /* the document is a valid case; this daemon runs it on fewer ranks */
        fdem_model_destroy(model);
        model = NULL;
        *http_status = 422;
        problems_add(p, 422, "/parallel/ranks", "this daemon runs a case on at most %d ranks "
                     "(--max-ranks), got %d", max_ranks, info->ranks);
    }
    return model;
}

static void registry_log_submitted(server_case *c, const case_sizing *z)
{
    case_log(c, "submitted: %d nodes, %d elements, %d joints, dt = %.3g s, end = %.6g s, "
             "%.4g steps, %.4g snapshots, about %.3g s to run (%.3g ms of CPU a step as built, "
             "%.3g ms with %d joints cracked)", z->nodes, z->elements, z->joints,
             z->dt, c->info.end_time, z->steps, z->snapshots, z->estimated_seconds,
             1e3 * z->step_seconds, 1e3 * z->cracked_step_seconds, z->cracked_joints);
}

/* registry_create() with the lease that pays for the upload. */
static server_case *registry_store_upload(const char *body, size_t size, int start,
                                          membudget_lease *lease, problems *p, int *http_status,
                                          char *warning, size_t warning_size,
                                          char *err, size_t errlen)
{
    case_info info;
    double model_bytes = 0;
    problems w;
    problems_init(&w);
    fdem_model *model = registry_build_upload(body, size, lease, &info, &model_bytes, p,
                                              http_status, &w);
    if (!model) {
        problems_free(&w);
        return NULL;
    }
    server_case *c = case_new();
    if (!c) {
        problems_free(&w);
        fdem_model_destroy(model);
        *http_status = 500;
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    c->model = model;
    c->info = info;
    c->state = CASE_CREATED;
    /* they join the case before its first status.json is written */
    case_add_warnings(c, &w);
    problems_free(&w);
    status_time_now(c->created, sizeof c->created);
    *http_status = 500;
    char final_dir[sizeof c->dir];
    if (case_make_dir(c, final_dir, sizeof final_dir) != 0) {
        snprintf(err, errlen, "cannot create the case directory: %s", strerror(errno));
        case_release(c);
        return NULL;
    }
    persist_reserve(c->dir);
    if (persist_write_atomic(c->dir, "case.json", body, size) != 0) {
        snprintf(err, errlen, "cannot store case.json: %s", strerror(errno));
        goto fail;
    }
    size_t ckpt_size = 0;
    void *ckpt = checkpoint_file_take(model, &ckpt_size);
    snapshot *first = snapshot_take(model, info.fields);
    c->last_snapshot_step = c->last_checkpoint_step = fdem_get_step(model);
    if (io_create(c, first, ckpt, ckpt_size, err, errlen) != 0)
        goto fail;
    io_close(c); /* a case that is not running keeps no file open */
    case_publish_from_model(c);
    /* Its t = 0 is stored and published: the model is stepped for a
     * moment to time the run (the estimate goes into the first
     * status.json), then freed; a start builds it again from the stored
     * files, as every later start does. */
    case_sizing sizing;
    case_sizing_measure(model, &info, model_bytes, registry_config()->threads,
                        io_snapshot_seconds((double)fdem_checkpoint_size(model)),
                        &sizing);
    case_sizing_warning(&sizing, warning, warning_size);
    pthread_mutex_lock(&c->lock);
    c->estimated_seconds = sizing.estimated_seconds;
    pthread_mutex_unlock(&c->lock);
    if (case_persist_status(c) != 0) {
        snprintf(err, errlen, "cannot store status.json: %s", c->io_error);
        goto fail;
    }
    if (case_publish_dir(c, final_dir, err, errlen) != 0)
        goto fail;
    fdem_counts n = fdem_get_counts(model);
    size_t cost = case_model_cost((double)fdem_memory_estimate_of(&n));
    c->model = NULL;
    fdem_model_destroy(model);
    registry_log_submitted(c, &sizing); /* before a worker can log its start */
    if (registry_admit(c, start, lease, cost) != 0) {
        snprintf(err, errlen, "out of memory");
        goto fail;
    }
    /* The status is durable before the 201 goes out (a running case that
     * is acknowledged comes back after a crash). */
    if (start)
        case_persist_status(c);
    case_feed_status(c);
    *http_status = 201;
    case_retain(c);
    return c;
fail:
    io_close(c);
    atomic_store(&c->deleted, 1);
    persist_remove_dir(c->dir);
    case_release(c);
    return NULL;
}

server_case *registry_create(const char *body, size_t size, int start, problems *p,
                             int *http_status, char *warning, size_t warning_size,
                             char *err, size_t errlen)
{
    membudget_lease own = {0};
    membudget_lease *lease = membudget_request_lease() ? membudget_request_lease() : &own;
    server_case *c = registry_store_upload(body, size, start, lease, p, http_status, warning,
                                           warning_size, err, errlen);
    /* Only the body is left (until the answer is sent); the tree, the meshes
     * and the model are gone, so the client's next request already finds the
     * budget as it will be. */
    membudget_shrink(lease, lease->bytes > size ? lease->bytes - size : 0);
    membudget_release(&own);
    return c;
}

json_t *registry_dry_run(const char *body, size_t size, problems *p, int *http_status)
{
    membudget_lease own = {0};
    membudget_lease *lease = membudget_request_lease() ? membudget_request_lease() : &own;
    case_info info;
    double model_bytes = 0;
    problems w;
    problems_init(&w);
    fdem_model *model = registry_build_upload(body, size, lease, &info, &model_bytes, p,
                                              http_status, &w);
    json_t *answer = NULL;
    if (model) {
        case_sizing sizing;
        case_sizing_measure(model, &info, model_bytes, registry_config()->threads,
                        io_snapshot_seconds((double)fdem_checkpoint_size(model)),
                        &sizing);
        fdem_model_destroy(model);
        answer = case_sizing_json(&sizing);
        if (answer) json_object_set_new(answer, "ranks", json_integer(info.ranks));
        if (answer) json_object_set_new(answer, "warnings", problems_warnings_json(&w));
        *http_status = 200;
    }
    problems_free(&w);
    membudget_shrink(lease, lease->bytes > size ? lease->bytes - size : 0);
    membudget_release(&own);
    return answer;
}

