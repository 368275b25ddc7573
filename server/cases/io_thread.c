/*
 * io_thread.c - the one thread that writes result.h5, result.xdmf and the
 * checkpoints.
 *
 * HDF5 (high-level and our proto writer) is used from this thread only, so
 * workers never block on disk and HTTP handlers never touch an open HDF5
 * handle. Workers hand over snapshots (copies) and checkpoint buffers; the
 * queue is FIFO over all cases, which gives the ordering guarantees in the
 * header for free.
 */
#include "io_thread.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "case_feed.h"
#include "case_model.h"
#include "files/persist.h"
#include "math/clock.h"
#include "common/memory_budget.h"

typedef enum io_job_kind {
    IO_CREATE, IO_REOPEN, IO_APPEND, IO_CLOSE, IO_FETCH, IO_DESCRIBE, IO_EVENTS, IO_HISTORY,
    IO_HISTORY_READ, IO_FRAME, IO_XDMF, IO_QUIT,
} io_job_kind;

typedef struct io_job {
    io_job_kind kind;
    server_case *c;
    snapshot *snap;
    fdem_event *events;     /* IO_APPEND: written first; IO_EVENTS: the answer */
    int event_count, dimension;
    double since;           /* IO_EVENTS, IO_HISTORY_READ */
    history_row **rows;     /* IO_HISTORY: written; IO_HISTORY_READ: the answer */
    int row_count;
    history_names *names;   /* IO_HISTORY_READ: the point names (the caller's) */
    const result_frame_request *frame_request; /* IO_FRAME: what to read */
    unsigned char *frame;   /* IO_FRAME: the answer (j->size bytes) */
    void *ckpt;
    size_t ckpt_size;
    const char *ckpt_name;     /* IO_APPEND: NULL = checkpoint.bin */
    int64_t keep_until_step;
    int close_after;
    /* completion, for jobs someone waits on */
    int waited, done, rc, fd;
    int held, http_status;     /* IO_FETCH: writes held for a copy; 404/500 */
    size_t size;
    char err[600];
    struct io_job *next;
} io_job;

static pthread_mutex_t io_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t io_wake = PTHREAD_COND_INITIALIZER;
static pthread_cond_t io_done = PTHREAD_COND_INITIALIZER;
static io_job *io_head, *io_tail;
/* Jobs of cases whose result.h5 is being copied for a download; they go
 * back to the front of the queue, in order, when the copy is done. */
static io_job *io_deferred_head, *io_deferred_tail;
static pthread_t io_thread;
static int io_running;

/* GET result.xdmf of a running case: the sidecar listing every row written
 * so far, as a client that has just seen the snapshot count expects. */
static void io_do_xdmf(io_job *j)
{
    if (!j->c->deleted)
        io_sidecar_catch_up(j->c);
}

/* After a failed write no checkpoint may follow: a restart from it would
 * resume past the snapshot that was lost. A new checkpoint.bin is later
 * than the step an extended case resumes from, so the resume file goes
 * (case_model.h). */
static void io_write_checkpoint(server_case *c, const char *name, const void *ckpt, size_t size)
{
    if (c->deleted || atomic_load(&c->io_failed))
        return;
    if (persist_write_atomic(c->dir, name, ckpt, size) != 0) {
        case_record_io_failure(c, name, strerror(errno));
        return;
    }
    if (strcmp(name, CASE_CHECKPOINT) == 0)
        case_model_forget_resume(c);
}

/* result_append() flushes HDF5's buffers to the kernel; the row is on
 * disk, and may be counted, once the file is synced too. */
static void io_sync_result(server_case *c)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/result.h5", c->dir);
    if (persist_fsync_path(path) != 0)
        case_record_io_failure(c, "result.h5", strerror(errno));
}

/* Closes result.h5 after a failed write, so that what was committed stays
 * a readable file (the flags of an open SWMR writer are cleared on close). */
static void io_close_after_failure(server_case *c)
{
    io_sidecar_write(c, 1);
    if (result_close(c->result) != 0)
        fprintf(stderr, "fdemd: case %s: closing result.h5 after a failed write also failed\n",
                c->id);
    c->result = NULL;
}

static void io_do_create(io_job *j)
{
    server_case *c = j->c;
    char path[1200];
    snprintf(path, sizeof path, "%s/result.h5", c->dir);
    /* case.json is stored before the result is created (registry.c); the
     * file carries it so that it explains itself (contract 5.4). */
    char document_path[1200], *document = NULL;
    size_t document_size = 0;
    snprintf(document_path, sizeof document_path, "%s/case.json", c->dir);
    if (persist_read_file(document_path, &document, &document_size, CASE_MODEL_MAX_DOCUMENT) != 0) {
        snprintf(j->err, sizeof j->err, "case.json could not be read for result.h5: %s",
                 strerror(errno));
        j->rc = -1;
        return;
    }
    c->result = result_create_described(path, c->model, &c->info, document, document_size,
                                        j->err, sizeof j->err);
    free(document);
    if (!c->result) {
        j->rc = -1;
        return;
    }
    if (j->snap && result_append(c->result, j->snap, j->err, sizeof j->err) != 0) {
        j->rc = -1;
        return;
    }
    case_set_snapshots(c, result_snapshot_count(c->result));
    io_sidecar_write(c, 1);
    if (j->ckpt && persist_write_atomic(c->dir, "checkpoint.bin", j->ckpt, j->ckpt_size) != 0) {
        snprintf(j->err, sizeof j->err, "writing checkpoint.bin: %s", strerror(errno));
        j->rc = -1;
    }
}

static void io_do_reopen(io_job *j)
{
    server_case *c = j->c;
    char path[1200];
    snprintf(path, sizeof path, "%s/result.h5", c->dir);
    c->result = result_reopen(path, c->model, &c->info, j->keep_until_step, j->err, sizeof j->err);
    if (!c->result) {
        j->rc = -1;
        return;
    }
    case_set_snapshots(c, result_snapshot_count(c->result));
    io_sidecar_write(c, 1);
    if (j->close_after) {
        result_close(c->result);
        c->result = NULL;
    }
}

/* The snapshot an extended case writes at the step after its old end
 * can lie at or (by a rounding) before that end's own row, and a restart
 * can replay steps whose rows were kept: /snapshots/time only ever grows. */
static int io_snapshot_is_new(const server_case *c, const snapshot *s)
{
    int count = result_snapshot_count(c->result);
    return count == 0 || s->time > result_snapshot_time(c->result, count - 1);
}

static void io_do_append(io_job *j)
{
    server_case *c = j->c;
    if (j->event_count && c->result && !c->deleted) {
        char err[256] = "";
        if (result_append_events(c->result, j->events, j->event_count, err, sizeof err) != 0) {
            case_record_io_failure(c, "result.h5", err);
            io_close_after_failure(c);
        }
    }
    int appended = -1;
    if (j->snap && c->result && !c->deleted && io_snapshot_is_new(c, j->snap)) {
        char err[256] = "";
        if (result_append(c->result, j->snap, err, sizeof err) != 0) {
            case_record_io_failure(c, "result.h5", err);
            io_close_after_failure(c);
        } else {
            appended = result_snapshot_count(c->result);
            io_sidecar_write(c, 0);
            io_sync_result(c);
        }
    }
    if (j->ckpt && !atomic_load(&c->io_failed))
        io_write_checkpoint(c, j->ckpt_name ? j->ckpt_name : CASE_CHECKPOINT, j->ckpt,
                            j->ckpt_size);
    /* A restart resumes at checkpoint.bin and cuts result.h5 back to it, so
     * a count shown before the checkpoint holding its row is durable is
     * turned back by a crash: it is shown only now, after status.json
     * (which a restart lists before it checks the case) has it too. After
     * a failed write the case ends failed, keeping every row written (it
     * is never cut back), so the count shows them too. */
    if (j->ckpt && !atomic_load(&c->io_failed))
        case_persist_status_counting(c, appended);
    if (appended >= 0) {
        case_set_snapshots(c, appended);
        case_feed_snapshot(c, appended - 1, j->snap->time);
    }
    pthread_mutex_lock(&c->lock);
    c->io_pending--;
    pthread_cond_broadcast(&c->cv);
    pthread_mutex_unlock(&c->lock);
}

/* The document travels in j->ckpt (a text buffer). */
static void io_do_describe(io_job *j)
{
    server_case *c = j->c;
    char path[1200];
    snprintf(path, sizeof path, "%s/result.h5", c->dir);
    if (c->result) {
        snprintf(j->err, sizeof j->err, "result.h5 is open for writing");
        j->rc = -1;
        return;
    }
    j->rc = result_replace_document(path, j->ckpt, j->ckpt_size, j->err, sizeof j->err);
}

static void io_do_close(io_job *j)
{
    server_case *c = j->c;
    if (!c->result)
        return;
    if (!c->deleted && c->model && !atomic_load(&c->io_failed)) {
        /* The views let every ParaView XDMF reader open the sidecar. Not
         * after a failed write (a full disk): they grow the file, and a
         * close that cannot flush leaves it flagged as open for writing,
         * which h5py and the other readers then refuse. */
        char path[1200], err[256] = "";
        snprintf(path, sizeof path, "%s/result.h5", c->dir);
        if (result_finish(c->result, path, fdem_get_dimension(c->model), err, sizeof err) != 0)
            case_record_io_failure(c, "result.h5", err);
        io_sidecar_write(c, 1);
    }
    if (result_close(c->result) != 0 && !c->deleted)
        case_record_io_failure(c, "result.h5", "its final flush failed (disk full or I/O error)");
    c->result = NULL;
}

/* A finished file is served as it is, once HDF5 has opened it (a file
 * truncated or replaced on disk is refused, not sent). A file still open
 * for SWMR writing is flushed and this case's writes are held, so that the
 * caller can copy it off this thread (result_image_copy_step) and then
 * calls io_release_hold(). Both cost metadata I/O only. */
static void io_do_fetch(io_job *j)
{
    server_case *c = j->c;
    char path[1200];
    snprintf(path, sizeof path, "%s/result.h5", c->dir);
    struct stat st;
    j->rc = -1;
    j->http_status = 500;
    if (!c->result && atomic_load(&c->ranks_running)) {
        /* another process writes it: a byte copy could catch a write half done */
        snprintf(j->err, sizeof j->err, "the case runs on %d ranks, which write result.h5 "
                 "themselves: read it in place (HDF5 SWMR, e.g. h5py's swmr=True) or download "
                 "it once the case is paused, stopped or finished", c->info.ranks);
        j->http_status = 409;
        return;
    }
    if (c->result) {
        if (result_flush(c->result, j->err, sizeof j->err) != 0)
            return;
        j->held = 1;
        atomic_fetch_add(&c->io_hold, 1);
    } else if (stat(path, &st) != 0 && errno == ENOENT) {
        snprintf(j->err, sizeof j->err, "the case has no result.h5");
        j->http_status = 404;
        return;
    } else if (result_check_file(path, j->err, sizeof j->err) != 0) {
        char detail[sizeof j->err];
        snprintf(detail, sizeof detail, "%s", j->err);
        snprintf(j->err, sizeof j->err, "result.h5 is damaged: %.560s", detail);
        return;
    }
    j->fd = open(path, O_RDONLY | O_CLOEXEC);
    if (j->fd < 0 || fstat(j->fd, &st) != 0) {
        snprintf(j->err, sizeof j->err, "opening result.h5: %s", strerror(errno));
        if (j->fd >= 0)
            close(j->fd);
        j->fd = -1;
        if (j->held)
            io_release_hold(c);
        j->held = 0;
        return;
    }
    j->size = (size_t)st.st_size;
    j->rc = 0;
}

/* A read of result.h5 has nothing to read yet: no file is open and none
 * is on disk (the case has written nothing). Its path goes to `path`. */
static int io_result_absent(const server_case *c, char *path, size_t size)
{
    snprintf(path, size, "%s/result.h5", c->dir);
    struct stat st;
    return !c->result && stat(path, &st) != 0 && errno == ENOENT;
}

/* The events of the open file, or of the one on disk; none before it exists. */
static void io_do_events(io_job *j)
{
    server_case *c = j->c;
    char path[1200];
    if (io_result_absent(c, path, sizeof path)) {
        j->rc = 0;
        return;
    }
    j->rc = result_read_events(c->result, path, j->since, &j->events, &j->event_count,
                               &j->dimension, j->err, sizeof j->err);
}

static void io_do_history(io_job *j)
{
    server_case *c = j->c;
    if (!j->row_count || !c->result || c->deleted || atomic_load(&c->io_failed))
        return;
    char err[256] = "";
    if (result_append_history(c->result, j->rows, j->row_count, err, sizeof err) != 0) {
        case_record_io_failure(c, "result.h5", err);
        io_close_after_failure(c);
    }
}

/* The history rows of the open file, or of the one on disk; none before it exists. */
static void io_do_history_read(io_job *j)
{
    server_case *c = j->c;
    char path[1200];
    if (io_result_absent(c, path, sizeof path)) {
        j->rc = 0;
        return;
    }
    j->rc = result_read_history(c->result, path, j->since, &j->rows, &j->row_count, j->names,
                                j->err, sizeof j->err);
}

/* A snapshot as the page's binary frame, from the open file or the one on disk. */
/* The mesh tables of the last case whose frames were asked for, kept so
 * that its next frames skip reading and matching its mesh (~0.5 s for 1e5
 * tetrahedra); one case's at a time, charged to the memory budget. */
static result_frame_cache *io_frames;
static membudget_lease io_frames_lease;

static void io_frames_charge(void)
{
    size_t held = result_frame_cache_bytes(io_frames);
    if (held > io_frames_lease.bytes &&
        membudget_grow(&io_frames_lease, held - io_frames_lease.bytes) != 0) {
        result_frame_cache_clear(io_frames); /* no room: the next frame reads the mesh again */
        held = 0;
    }
    if (held < io_frames_lease.bytes)
        membudget_shrink(&io_frames_lease, io_frames_lease.bytes - held);
}

static void io_do_frame(io_job *j)
{
    server_case *c = j->c;
    char path[1200];
    if (io_result_absent(c, path, sizeof path)) {
        snprintf(j->err, sizeof j->err, "the case has no result file (yet)");
        j->rc = 404;
        return;
    }
    if (!io_frames)
        io_frames = result_frame_cache_new();
    result_frame_request q = *j->frame_request;
    q.cache = io_frames;
    q.cache_owner = c->id;
    j->rc = result_read_frame(c->result, path, &q, &j->frame, &j->size, j->err, sizeof j->err);
    io_frames_charge();
}

static void io_run_job(io_job *j)
{
    double started = clock_wall_seconds();
    int writes_snapshot = j->kind == IO_APPEND && j->snap && j->ckpt;
    switch (j->kind) {
    case IO_CREATE: io_do_create(j); break;
    case IO_REOPEN: io_do_reopen(j); break;
    case IO_APPEND: io_do_append(j); break;
    case IO_CLOSE: io_do_close(j); break;
    case IO_FETCH: io_do_fetch(j); break;
    case IO_DESCRIBE: io_do_describe(j); break;
    case IO_EVENTS: io_do_events(j); break;
    case IO_HISTORY: io_do_history(j); break;
    case IO_HISTORY_READ: io_do_history_read(j); break;
    case IO_FRAME: io_do_frame(j); break;
    case IO_XDMF: io_do_xdmf(j); break;
    case IO_QUIT: break;
    }
    if (writes_snapshot && j->rc == 0)
        io_note_snapshot_cost(clock_wall_seconds() - started, (double)j->ckpt_size);
}

static void io_job_free(io_job *j)
{
    if (j->snap)
        snapshot_free(j->snap);
    free(j->events);
    result_free_history(j->rows, j->row_count);
    free(j->ckpt);
    free(j->frame);
    if (j->c)
        case_release(j->c);
    free(j);
}

static void io_list_append(io_job **head, io_job **tail, io_job *j)
{
    j->next = NULL;
    if (*tail)
        (*tail)->next = j;
    else
        *head = j;
    *tail = j;
}

/* The next job to run; a held case's jobs (but for fetches, which write
 * nothing, and the sidecar's refresh, which writes no result.h5) are set
 * aside. */
static io_job *io_next_locked(void)
{
    for (;;) {
        while (!io_head)
            pthread_cond_wait(&io_wake, &io_lock);
        io_job *j = io_head;
        io_head = j->next;
        if (!io_head)
            io_tail = NULL;
        if (j->c && j->kind != IO_FETCH && j->kind != IO_XDMF &&
            atomic_load(&j->c->io_hold) > 0) {
            io_list_append(&io_deferred_head, &io_deferred_tail, j);
            continue;
        }
        return j;
    }
}

void io_release_hold(server_case *c)
{
    pthread_mutex_lock(&io_lock);
    if (atomic_fetch_sub(&c->io_hold, 1) == 1) {
        io_job *mine = NULL, *mine_tail = NULL, *rest = NULL, *rest_tail = NULL;
        for (io_job *j = io_deferred_head, *next; j; j = next) {
            next = j->next;
            if (j->c == c)
                io_list_append(&mine, &mine_tail, j);
            else
                io_list_append(&rest, &rest_tail, j);
        }
        io_deferred_head = rest;
        io_deferred_tail = rest_tail;
        if (mine) {
            mine_tail->next = io_head;
            io_head = mine;
            if (!io_tail)
                io_tail = mine_tail;
            pthread_cond_signal(&io_wake);
        }
    }
    pthread_mutex_unlock(&io_lock);
}

static void *io_main(void *arg)
{
    (void)arg;
    for (;;) {
        pthread_mutex_lock(&io_lock);
        io_job *j = io_next_locked();
        pthread_mutex_unlock(&io_lock);

        io_run_job(j);
        int quit = j->kind == IO_QUIT;
        if (j->waited) {
            pthread_mutex_lock(&io_lock);
            j->done = 1;
            pthread_cond_broadcast(&io_done);
            pthread_mutex_unlock(&io_lock);
        } else {
            io_job_free(j);
        }
        if (quit) {
            result_frame_cache_free(io_frames);
            io_frames = NULL;
            io_frames_charge();
            return NULL;
        }
    }
}

static io_job *io_job_new(io_job_kind kind, server_case *c)
{
    io_job *j = calloc(1, sizeof *j);
    if (!j)
        return NULL;
    j->kind = kind;
    j->fd = -1;
    if (c) {
        case_retain(c);
        j->c = c;
    }
    return j;
}

static void io_enqueue(io_job *j)
{
    pthread_mutex_lock(&io_lock);
    if (io_tail)
        io_tail->next = j;
    else
        io_head = j;
    io_tail = j;
    pthread_cond_signal(&io_wake);
    pthread_mutex_unlock(&io_lock);
}

/* Queues `j` and waits for it; returns its rc. The caller frees j. */
static int io_run_and_wait(io_job *j)
{
    j->waited = 1;
    io_enqueue(j);
    pthread_mutex_lock(&io_lock);
    while (!j->done)
        pthread_cond_wait(&io_done, &io_lock);
    pthread_mutex_unlock(&io_lock);
    return j->rc;
}

int io_start(void)
{
    if (pthread_create(&io_thread, NULL, io_main, NULL) != 0)
        return -1;
    io_running = 1;
    return 0;
}

void io_stop(void)
{
    if (!io_running)
        return;
    io_job *j = io_job_new(IO_QUIT, NULL);
    if (j) {
        io_enqueue(j); /* freed by the I/O thread on its way out */
        pthread_join(io_thread, NULL);
    }
    io_running = 0;
}

int io_create(server_case *c, snapshot *first, void *ckpt, size_t ckpt_size,
              char *err, size_t errlen)
{
    io_job *j = io_job_new(IO_CREATE, c);
    if (!j) {
        snapshot_free(first);
        free(ckpt);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    j->snap = first;
    j->ckpt = ckpt;
    j->ckpt_size = ckpt_size;
    int rc = io_run_and_wait(j);
    if (rc != 0)
        snprintf(err, errlen, "%s", j->err);
    io_job_free(j);
    return rc;
}

int io_reopen(server_case *c, int64_t keep_until_step, int close_after, char *err, size_t errlen)
{
    io_job *j = io_job_new(IO_REOPEN, c);
    if (!j) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    j->keep_until_step = keep_until_step;
    j->close_after = close_after;
    int rc = io_run_and_wait(j);
    if (rc != 0)
        snprintf(err, errlen, "%s", j->err);
    io_job_free(j);
    return rc;
}

static void io_queue_append(server_case *c, fdem_event *events, int event_count, snapshot *s,
                            void *ckpt, size_t ckpt_size, const char *ckpt_name)
{
    io_job *j = io_job_new(IO_APPEND, c);
    if (!j) {
        free(events);
        snapshot_free(s);
        free(ckpt);
        return;
    }
    j->events = events;
    j->event_count = event_count;
    pthread_mutex_lock(&c->lock);
    c->io_pending++;
    pthread_mutex_unlock(&c->lock);
    j->snap = s;
    j->ckpt = ckpt;
    j->ckpt_size = ckpt_size;
    j->ckpt_name = ckpt_name;
    io_enqueue(j);
}

void io_append(server_case *c, fdem_event *events, int event_count, snapshot *s, void *ckpt,
               size_t ckpt_size)
{
    io_queue_append(c, events, event_count, s, ckpt, ckpt_size, NULL);
}

void io_append_history(server_case *c, history_row **rows, int count)
{
    io_job *j = io_job_new(IO_HISTORY, c);
    if (!j) {
        result_free_history(rows, count);
        return;
    }
    j->rows = rows;
    j->row_count = count;
    io_enqueue(j);
}

int io_read_history(server_case *c, double since, history_row ***out, int *count,
                    history_names *names, char *err, size_t errlen)
{
    *out = NULL;
    *count = 0;
    names->count = 0;
    io_job *j = io_job_new(IO_HISTORY_READ, c);
    if (!j) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    j->since = since;
    j->names = names;
    int rc = io_run_and_wait(j);
    if (rc == 0) {
        *out = j->rows;
        *count = j->row_count;
        j->rows = NULL;
        j->row_count = 0;
    } else {
        snprintf(err, errlen, "%s", j->err);
    }
    io_job_free(j);
    return rc;
}

void io_write_named_checkpoint(server_case *c, const char *name, fdem_event *events,
                               int event_count, void *ckpt, size_t ckpt_size)
{
    io_queue_append(c, events, event_count, NULL, ckpt, ckpt_size, name);
}

int io_replace_document(server_case *c, const char *text, size_t length, char *err,
                        size_t errlen)
{
    io_job *j = io_job_new(IO_DESCRIBE, c);
    char *copy = j ? malloc(length + 1) : NULL;
    if (!copy) {
        if (j)
            io_job_free(j);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    memcpy(copy, text, length);
    copy[length] = '\0';
    j->ckpt = copy;
    j->ckpt_size = length;
    int rc = io_run_and_wait(j);
    if (rc != 0)
        snprintf(err, errlen, "%s", j->err);
    io_job_free(j);
    return rc;
}

void io_close(server_case *c)
{
    io_job *j = io_job_new(IO_CLOSE, c);
    if (!j)
        return;
    io_run_and_wait(j);
    io_job_free(j);
}

void io_refresh_xdmf(server_case *c)
{
    /* result.h5 is open only while a worker runs (it closes the file,
     * through this queue, before it clears worker_active): any other
     * case's sidecar was written whole at its close, and its GET need not
     * wait behind the other cases' writes */
    pthread_mutex_lock(&c->lock);
    int running = c->worker_active;
    pthread_mutex_unlock(&c->lock);
    if (!running) return;
    io_job *j = io_job_new(IO_XDMF, c);
    if (!j) return; /* the sidecar as it is: a moment behind at most */
    io_run_and_wait(j);
    io_job_free(j);
}

int io_read_events(server_case *c, double since, fdem_event **out, int *count, int *dimension,
                   char *err, size_t errlen)
{
    *out = NULL;
    *count = 0;
    io_job *j = io_job_new(IO_EVENTS, c);
    if (!j) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    j->since = since;
    int rc = io_run_and_wait(j);
    if (rc == 0) {
        *out = j->events;
        *count = j->event_count;
        *dimension = j->dimension;
        j->events = NULL;
    } else {
        snprintf(err, errlen, "%s", j->err);
    }
    io_job_free(j);
    return rc;
}

int io_read_frame(server_case *c, const result_frame_request *q, unsigned char **out,
                  size_t *size, char *err, size_t errlen)
{
    *out = NULL;
    *size = 0;
    io_job *j = io_job_new(IO_FRAME, c);
    if (!j) {
        snprintf(err, errlen, "out of memory");
        return 503;
    }
    j->frame_request = q;
    int rc = io_run_and_wait(j);
    if (rc == 0) {
        *out = j->frame;
        *size = j->size;
        j->frame = NULL;
    } else {
        snprintf(err, errlen, "%s", j->err);
    }
    io_job_free(j);
    return rc;
}

int io_fetch_result(server_case *c, int *fd, size_t *size, int *held, int *http_status,
                    char *err, size_t errlen)
{
    *fd = -1;
    *held = 0;
    *http_status = 500;
    io_job *j = io_job_new(IO_FETCH, c);
    if (!j) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int rc = io_run_and_wait(j);
    *fd = j->fd;
    *size = j->size;
    *held = j->held;
    *http_status = j->http_status;
    if (rc != 0)
        snprintf(err, errlen, "%s", j->err);
    io_job_free(j);
    return rc;
}
