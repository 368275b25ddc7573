/*
 * registry.c - the cases the daemon holds, their state machine, their
 * status object and its persistence (storing an uploaded case:
 * registry_create.c; loading a stored case: registry_load.c; one case's
 * record, its reference count and state names: case_record.c).
 *
 * The registry lock guards the list (kept oldest first), the running count
 * and the queue; each case's own lock guards its state and figures. HTTP
 * commands on one case are serialized by its ctl_lock, which is also what
 * lets a pause or stop wait for the worker to leave without another command
 * slipping in between.
 */
#include "registry.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "case_feed.h"
#include "case_model.h"
#include "case_sizing.h"
#include "io_thread.h"
#include "files/persist.h"
#include "registry_internal.h"
#include "worker.h"

static const fdemd_config *reg_cfg;
static pthread_mutex_t reg_lock = PTHREAD_MUTEX_INITIALIZER;
static server_case **reg_cases;
static int reg_count, reg_capacity;
static uint64_t reg_next_seq, reg_next_queue_seq;
static int reg_running;
static int reg_shutting_down;

const fdemd_config *registry_config(void)
{
    return reg_cfg;
}

/* ------------------------------------------------------------- listing */

static int registry_append_locked(server_case *c)
{
    if (reg_count == reg_capacity) {
        int cap = reg_capacity ? 2 * reg_capacity : 16;
        server_case **grown = realloc(reg_cases, (size_t)cap * sizeof *grown);
        if (!grown)
            return -1;
        reg_cases = grown;
        reg_capacity = cap;
    }
    c->seq = reg_next_seq++;
    reg_cases[reg_count++] = c;
    return 0;
}

server_case *registry_find(const char *id)
{
    if (!id_is_valid(id))
        return NULL;
    server_case *found = NULL;
    pthread_mutex_lock(&reg_lock);
    for (int i = 0; i < reg_count; i++)
        if (strcmp(reg_cases[i]->id, id) == 0) {
            found = reg_cases[i];
            case_retain(found);
            break;
        }
    pthread_mutex_unlock(&reg_lock);
    return found;
}

server_case **registry_list(int *count)
{
    pthread_mutex_lock(&reg_lock);
    server_case **out = malloc((size_t)(reg_count ? reg_count : 1) * sizeof *out);
    *count = 0;
    if (out) {
        for (int i = 0; i < reg_count; i++) {
            case_retain(reg_cases[i]);
            out[i] = reg_cases[i];
        }
        *count = reg_count;
    }
    pthread_mutex_unlock(&reg_lock);
    return out;
}

void registry_list_free(server_case **cases, int count)
{
    for (int i = 0; i < count; i++)
        case_release(cases[i]);
    free(cases);
}

void registry_counts(int *cases, int *running)
{
    pthread_mutex_lock(&reg_lock);
    *cases = reg_count;
    *running = reg_running;
    pthread_mutex_unlock(&reg_lock);
}

/* ------------------------------------------------------- state machine */

/* With the registry lock and the case lock held. */
static int case_start_locked(server_case *c)
{
    if (reg_running < reg_cfg->max_running) {
        if (worker_spawn(c) != 0)
            return -1;
        reg_running++;
        c->state = CASE_RUNNING;
        if (!c->started[0])
            status_time_now(c->started, sizeof c->started);
    } else {
        c->state = CASE_QUEUED;
        c->queue_seq = ++reg_next_queue_seq;
    }
    return 0;
}

/* Starts queued cases, first queued first, while slots are free. Returns a
 * reference to a case whose status must be persisted, or NULL. */
static server_case *registry_dispatch_one_locked(void)
{
    if (reg_shutting_down || reg_running >= reg_cfg->max_running)
        return NULL;
    server_case *next = NULL;
    for (int i = 0; i < reg_count; i++) {
        server_case *c = reg_cases[i];
        pthread_mutex_lock(&c->lock);
        if (c->state == CASE_QUEUED && !c->stop_pending &&
            (!next || c->queue_seq < next->queue_seq))
            next = c;
        pthread_mutex_unlock(&c->lock);
    }
    if (!next)
        return NULL;
    pthread_mutex_lock(&next->lock);
    int ok = next->state == CASE_QUEUED && !next->worker_active && case_start_locked(next) == 0;
    if (!ok && next->state == CASE_QUEUED) {
        next->state = CASE_FAILED;
        snprintf(next->error, sizeof next->error, "the daemon could not start a thread for this case");
        case_mark_ended_locked(next, CASE_FAILED);
        membudget_release(&next->reserve);
    }
    pthread_mutex_unlock(&next->lock);
    case_retain(next);
    return next;
}

static void registry_dispatch(void)
{
    for (;;) {
        pthread_mutex_lock(&reg_lock);
        server_case *started = registry_dispatch_one_locked();
        pthread_mutex_unlock(&reg_lock);
        if (!started)
            return;
        case_persist_status(started);
        case_feed_status(started);
        case_release(started);
    }
}

/* The state a worker leaves its case in once the storage has had its say:
 * failed (with the write error) if any write of the case failed, and a
 * state is only published after its status.json is durable, so a state a
 * client has seen never turns back after a crash. */
static case_state case_settle_final_state(server_case *c, case_state final_state, char *error,
                                          size_t error_size)
{
    pthread_mutex_lock(&c->lock);
    snprintf(error, error_size, "%s", c->error);
    if (atomic_load(&c->io_failed) && final_state != CASE_STOPPED) {
        final_state = CASE_FAILED;
        snprintf(error, error_size, "%s", c->io_error);
    }
    case_mark_ended_locked(c, final_state);
    pthread_mutex_unlock(&c->lock);
    if (atomic_load(&c->deleted))
        return final_state;
    char reason[128] = "";
    pthread_mutex_lock(&c->persist_lock);
    int rc = case_write_status_json(c, case_status_json_as(c, final_state, error), reason,
                                    sizeof reason);
    if (rc != 0) {
        case_record_io_failure(c, "status.json", reason);
        final_state = CASE_FAILED;
        pthread_mutex_lock(&c->lock);
        snprintf(error, error_size, "%s", c->io_error);
        case_mark_ended_locked(c, final_state);
        pthread_mutex_unlock(&c->lock);
        case_write_status_json(c, case_status_json_as(c, final_state, error), reason, sizeof reason);
    }
    pthread_mutex_unlock(&c->persist_lock);
    return final_state;
}

void registry_worker_exited(server_case *c, case_state final_state)
{
    char error[sizeof c->error];
    final_state = case_settle_final_state(c, final_state, error, sizeof error);
    /* State and running count change together, so /health and the status
     * never disagree about whether the case runs. */
    pthread_mutex_lock(&reg_lock);
    pthread_mutex_lock(&c->lock);
    c->state = final_state;
    snprintf(c->error, sizeof c->error, "%s", error);
    atomic_store(&c->command, WORKER_GO);
    pthread_mutex_unlock(&c->lock);
    reg_running--;
    pthread_mutex_unlock(&reg_lock);
    if (!atomic_load(&c->deleted))
        case_log_state(c, final_state);
    case_feed_status(c);
    registry_dispatch();
}

/* Waits (case lock held) for the worker to leave, at most one step plus
 * its final checkpoint. */
static void case_wait_worker_locked(server_case *c)
{
    while (c->worker_active)
        pthread_cond_wait(&c->cv, &c->lock);
}

/* A case that failed only because a write found the disk full: nothing is
 * wrong with it, and its last checkpoint and the rows before it are intact
 * (no checkpoint follows a lost write), so it may start again from there
 * once there is room, as a restarted case does (issue 30). */
static int case_failed_for_room_locked(const server_case *c)
{
    return c->state == CASE_FAILED &&
           (strstr(c->error, strerror(ENOSPC)) || strstr(c->error, strerror(EDQUOT)));
}

/* 0 when `c` may start now, else 404 or 409 with a sentence in msg. With
 * the registry lock and the case lock held. */
static int case_startable_locked(server_case *c, char *msg, size_t msglen)
{
    if (atomic_load(&c->deleted))
        return 404;
    if (reg_shutting_down) {
        snprintf(msg, msglen, "the daemon is shutting down");
        return 409;
    }
    if (c->state != CASE_CREATED && c->state != CASE_PAUSED && !case_failed_for_room_locked(c)) {
        snprintf(msg, msglen, "the case is %s; start is allowed only when it is created or paused "
                 "(or failed because the disk was full)", case_state_name(c->state));
        return 409;
    }
    if (c->worker_active) {
        snprintf(msg, msglen, "the case is still winding down its last step; try again");
        return 409;
    }
    return 0;
}

/* A rebuild showed the stored files cannot give a model: that does not pass. */
static void case_mark_broken(server_case *c, const char *why)
{
    pthread_mutex_lock(&c->lock);
    c->state = CASE_FAILED;
    snprintf(c->error, sizeof c->error, "%s", why);
    case_mark_ended_locked(c, CASE_FAILED);
    pthread_mutex_unlock(&c->lock);
    case_log_state(c, CASE_FAILED);
    case_persist_status(c);
    case_feed_status(c);
}

/* Reserves the model's memory and, when it will run at once (not queued),
 * builds it. 0, or 503/409 with msg; on failure nothing is held. */
static int case_prepare_start(server_case *c, int will_run, fdem_model **model, char *msg,
                              size_t msglen)
{
    size_t cost = case_model_cost_of(c);
    char need[32], limit[32], free_now[32];
    membudget_describe(cost, need, sizeof need);
    membudget_describe(membudget_limit(), limit, sizeof limit);
    if (cost > membudget_limit()) {
        snprintf(msg, msglen, "the model of this case needs about %s, more than the daemon's "
                 "whole memory budget (--max-memory, %s)", need, limit);
        return 503;
    }
    if (membudget_grow(&c->reserve, cost) != 0) {
        snprintf(msg, msglen, "the model of this case needs about %s and the daemon's memory "
                 "budget (--max-memory, %s) has %s free now; try again when other cases stop",
                 need, limit,
                 membudget_describe(membudget_limit() - membudget_used(), free_now, sizeof free_now));
        return 503;
    }
    if (!will_run)
        return 0;
    case_info info;
    char err[512] = "";
    case_model_rc rc = case_model_build(c, &c->reserve, model, &info, err, sizeof err);
    if (rc == CASE_MODEL_OK) {
        c->info = info;
        return 0;
    }
    membudget_release(&c->reserve);
    if (rc == CASE_MODEL_NO_MEMORY) {
        snprintf(msg, msglen, "rebuilding the model of this case would take the daemon past its "
                 "memory budget (--max-memory) now; try again when other cases stop");
        return 503;
    }
    case_mark_broken(c, err);
    snprintf(msg, msglen, "the case cannot run: %s", err);
    return 409;
}

int registry_start(server_case *c, char *msg, size_t msglen)
{
    pthread_mutex_lock(&c->ctl_lock);
    pthread_mutex_lock(&reg_lock);
    pthread_mutex_lock(&c->lock);
    int status = case_startable_locked(c, msg, msglen);
    int will_run = reg_running < reg_cfg->max_running;
    int retry = status == 0 && c->state == CASE_FAILED;
    pthread_mutex_unlock(&c->lock);
    pthread_mutex_unlock(&reg_lock);

    if (retry && persist_reserve(c->dir) != 0) {
        snprintf(msg, msglen, "the case failed because the disk was full, and there is still no "
                 "room in %s (%s); free some space, then start it again", c->dir, strerror(errno));
        status = 503;
    }
    if (retry && status == 0) {
        /* The failed write is behind it: the rebuild below reopens
         * result.h5 at the last checkpoint, dropping the rows after it. */
        pthread_mutex_lock(&c->lock);
        c->io_error[0] = '\0';
        atomic_store(&c->io_failed, 0);
        pthread_mutex_unlock(&c->lock);
    }

    fdem_model *model = NULL;
    if (status == 0)
        status = case_prepare_start(c, will_run, &model, msg, msglen);
    int queued = 0;
    if (status == 0) {
        /* model_lock first (the worker's order): no GET /state reads c->model
         * while it is handed over or taken back. */
        pthread_mutex_lock(&c->model_lock);
        pthread_mutex_lock(&reg_lock);
        pthread_mutex_lock(&c->lock);
        status = case_startable_locked(c, msg, msglen);
        if (status == 0) {
            /* A retry that cannot get its memory when its turn comes waits
             * paused: its files are a paused case's, the error is behind it. */
            c->queued_from = retry ? CASE_PAUSED : c->state;
            if (retry) {
                c->error[0] = '\0';
                c->finished_at[0] = '\0';
            }
            c->model = model;
            if (case_start_locked(c) != 0) {
                snprintf(msg, msglen, "the daemon could not start a thread for this case");
                status = 503;
            }
        }
        queued = status == 0 && c->state == CASE_QUEUED;
        if (status != 0 || queued)
            c->model = NULL; /* a queued case is built when its turn comes */
        else
            model = NULL;    /* the worker's now */
        pthread_mutex_unlock(&c->lock);
        pthread_mutex_unlock(&reg_lock);
        pthread_mutex_unlock(&c->model_lock);
        if (model)
            fdem_model_destroy(model);
        if (status != 0)
            membudget_release(&c->reserve);
    }
    if (status == 0) {
        case_persist_status(c);
        case_feed_status(c);
    }
    if (status == 0 && retry)
        case_log(c, "started again from its last checkpoint after failing for a full disk");
    if (queued)
        case_log(c, "queued: --max-running (%d) cases are running", reg_cfg->max_running);
    pthread_mutex_unlock(&c->ctl_lock);
    return status;
}

/* A queued case gives its reservation back when it leaves the queue
 * without running. With the case lock held; release it after unlocking. */
static membudget_lease case_take_reserve_locked(server_case *c)
{
    membudget_lease taken = {0};
    membudget_move(&c->reserve, &taken, c->reserve.bytes);
    return taken;
}

/* Asks the worker to leave with `cmd` and waits; returns the state it left in. */
static case_state case_command_worker_locked(server_case *c, worker_command cmd)
{
    atomic_store(&c->command, cmd);
    case_wait_worker_locked(c);
    return c->state;
}

int registry_pause(server_case *c, char *msg, size_t msglen)
{
    int status = 0, logged = 1; /* a worker logs its own exit */
    membudget_lease unreserve = {0};
    pthread_mutex_lock(&c->ctl_lock);
    pthread_mutex_lock(&c->lock);
    if (atomic_load(&c->deleted)) {
        status = 404;
    } else if (c->state == CASE_RUNNING) {
        case_state now = case_command_worker_locked(c, WORKER_PAUSE);
        if (now != CASE_PAUSED) {
            snprintf(msg, msglen, "the case became %s before it could be paused", case_state_name(now));
            status = 409;
        }
    } else if (c->state == CASE_QUEUED) {
        c->state = CASE_PAUSED;
        unreserve = case_take_reserve_locked(c);
        logged = 0;
    } else {
        snprintf(msg, msglen, "the case is %s; pause is allowed only when it is running or queued",
                 case_state_name(c->state));
        status = 409;
    }
    pthread_mutex_unlock(&c->lock);
    membudget_release(&unreserve);
    if (status == 0)
        case_persist_status(c);
    if (status == 0 && !logged) {
        case_log(c, "paused while queued");
        case_feed_status(c); /* a running case's worker said it as it left */
    }
    pthread_mutex_unlock(&c->ctl_lock);
    return status;
}

/* A stop of a case no worker runs (created, queued, paused): `stopped` is
 * made durable first and shown after, so a crash never brings back a
 * startable case whose stop a client has seen. 0, or 500 with msg (the
 * case is then failed with the write error). */
static int case_stop_idle(server_case *c, char *msg, size_t msglen)
{
    io_close(c);
    char ended[sizeof c->finished_at];
    int written = case_persist_status_as(c, CASE_STOPPED, ended, sizeof ended) == 0;
    membudget_lease unreserve = {0};
    pthread_mutex_lock(&c->lock);
    c->stop_pending = 0;
    if (written) {
        c->state = CASE_STOPPED;
        if (!c->finished_at[0])
            snprintf(c->finished_at, sizeof c->finished_at, "%s", ended);
    } else {
        snprintf(msg, msglen, "the stop could not be stored: %s", c->io_error);
    }
    if (case_state_is_terminal(c->state))
        unreserve = case_take_reserve_locked(c);
    case_state now = c->state;
    pthread_mutex_unlock(&c->lock);
    membudget_release(&unreserve);
    case_log_state(c, now);
    case_feed_status(c);
    if (!written)
        registry_dispatch(); /* a queued case that failed leaves its turn */
    return written ? 0 : 500;
}

int registry_stop(server_case *c, char *msg, size_t msglen)
{
    int status = 0, idle = 0;
    pthread_mutex_lock(&c->ctl_lock);
    pthread_mutex_lock(&c->lock);
    if (atomic_load(&c->deleted)) {
        status = 404;
    } else if (c->state == CASE_RUNNING) {
        case_state now = case_command_worker_locked(c, WORKER_STOP);
        if (now != CASE_STOPPED) {
            snprintf(msg, msglen, "the case became %s before it could be stopped", case_state_name(now));
            status = 409;
        }
    } else if (!case_state_is_terminal(c->state)) {
        c->stop_pending = 1; /* a queued case must not start meanwhile */
        idle = 1;
    } else {
        snprintf(msg, msglen,
                 "the case is %s; stop is allowed only when it is created, queued, running or paused",
                 case_state_name(c->state));
        status = 409;
    }
    pthread_mutex_unlock(&c->lock);
    if (idle)
        status = case_stop_idle(c, msg, msglen);
    pthread_mutex_unlock(&c->ctl_lock);
    return status;
}

/* Moves the case directory out of sight (DIR/.tmp-ID, which start-up
 * sweeps) and removes it there; when a file will not go, what is left is
 * moved back so the case stays whole and listed. */
static int case_remove_files(server_case *c, char *msg, size_t msglen)
{
    char trash[sizeof c->dir + 8];
    snprintf(trash, sizeof trash, "%s/.tmp-%s", reg_cfg->data_dir, c->id);
    if (rename(c->dir, trash) != 0) {
        snprintf(msg, msglen, "the files of the case could not be removed: renaming %s: %s",
                 c->dir, strerror(errno));
        return -1;
    }
    if (persist_remove_dir(trash) != 0) {
        int saved = errno;
        rename(trash, c->dir);
        snprintf(msg, msglen, "the files of the case could not all be removed from %s: %s",
                 c->dir, strerror(saved));
        return -1;
    }
    persist_fsync_dir(reg_cfg->data_dir);
    return 0;
}

static void registry_unlist(server_case *c)
{
    int listed = 0;
    pthread_mutex_lock(&reg_lock);
    for (int i = 0; i < reg_count; i++)
        if (reg_cases[i] == c) {
            memmove(reg_cases + i, reg_cases + i + 1, (size_t)(reg_count - i - 1) * sizeof *reg_cases);
            reg_count--;
            listed = 1;
            break;
        }
    pthread_mutex_unlock(&reg_lock);
    if (listed)
        case_release(c); /* the registry's reference */
}

int registry_delete(server_case *c, char *msg, size_t msglen)
{
    pthread_mutex_lock(&c->ctl_lock);
    if (atomic_load(&c->deleted)) {
        pthread_mutex_unlock(&c->ctl_lock);
        return 404;
    }
    pthread_mutex_lock(&c->lock);
    case_state before = c->state;
    if (c->worker_active)
        case_command_worker_locked(c, WORKER_ABANDON);
    c->state = CASE_STOPPED;
    case_mark_ended_locked(c, CASE_STOPPED);
    atomic_store(&c->deleted, 1);
    membudget_lease unreserve = case_take_reserve_locked(c);
    pthread_mutex_unlock(&c->lock);
    membudget_release(&unreserve);

    io_close(c); /* FIFO: every earlier job of this case is done after it */
    int status = 0;
    if (case_remove_files(c, msg, msglen) != 0) {
        /* Still there: the case stays listed as it was (a running or
         * queued one stopped, as the DELETE began by stopping it). */
        fprintf(stderr, "fdemd: case %s: %s\n", c->id, msg);
        pthread_mutex_lock(&c->lock);
        if (before != CASE_RUNNING && before != CASE_QUEUED)
            c->state = before;
        pthread_mutex_unlock(&c->lock);
        atomic_store(&c->deleted, 0);
        case_persist_status(c);
        case_feed_status(c);
        status = 500;
    } else {
        case_log(c, "deleted (was %s)", case_state_name(before));
        registry_unlist(c);
        case_feed_deleted(c->id);
    }
    pthread_mutex_unlock(&c->ctl_lock);
    return status;
}

/* model_lock taken by a request that reads the model: counted as a
 * waiter, so the worker yields the lock at its next step instead of taking
 * it again first (a request never waits longer than one step). */
static void case_model_lock_to_read(server_case *c)
{
    atomic_fetch_add(&c->state_waiters, 1);
    pthread_mutex_lock(&c->model_lock);
}

static void case_model_unlock_read(server_case *c)
{
    pthread_mutex_unlock(&c->model_lock);
    pthread_mutex_lock(&c->yield_lock);
    atomic_fetch_sub(&c->state_waiters, 1);
    pthread_cond_broadcast(&c->yield_cv);
    pthread_mutex_unlock(&c->yield_lock);
}

int case_holds_model(server_case *c)
{
    case_model_lock_to_read(c);
    int held = c->model != NULL;
    case_model_unlock_read(c);
    return held;
}

snapshot *case_take_state(server_case *c, unsigned fields, int *status, char *stage_name,
                          size_t stage_name_size)
{
    case_model_lock_to_read(c);
    snapshot *s = c->model ? snapshot_take(c->model, fields) : NULL;
    int held = c->model != NULL;
    const char *name = s ? case_stage_name(&c->info, s->stage) : NULL;
    snprintf(stage_name, stage_name_size, "%s", name ? name : "");
    case_model_unlock_read(c);
    *status = 503;
    if (!held)
        s = case_model_state_from_disk(c, fields, status, stage_name, stage_name_size);
    return s;
}

/* ------------------------------------------------------------- creating */

/* A new, stored case joins the list, and starts (or queues) when asked,
 * its model's memory moved from the upload's lease to its reserve. */
int registry_admit(server_case *c, int start, membudget_lease *lease, size_t cost)
{
    membudget_lease unreserve = {0};
    pthread_mutex_lock(&reg_lock);
    int appended = registry_append_locked(c) == 0;
    pthread_mutex_lock(&c->lock);
    if (appended && start && !reg_shutting_down) {
        membudget_move(lease, &c->reserve, cost);
        c->queued_from = CASE_CREATED;
        case_start_locked(c);
    }
    if (c->state == CASE_CREATED)
        unreserve = case_take_reserve_locked(c);
    int queued = c->state == CASE_QUEUED;
    pthread_mutex_unlock(&c->lock);
    pthread_mutex_unlock(&reg_lock);
    membudget_release(&unreserve);
    if (queued)
        case_log(c, "queued: --max-running (%d) cases are running", reg_cfg->max_running);
    return appended ? 0 : -1;
}

static int case_order(const void *a, const void *b)
{
    const server_case *x = *(server_case *const *)a, *y = *(server_case *const *)b;
    int d = strcmp(x->created, y->created);
    return d ? d : strcmp(x->id, y->id);
}

int registry_init(const fdemd_config *cfg)
{
    reg_cfg = cfg;
    case_feed_init();
    if (persist_mkdir(cfg->data_dir) != 0) {
        fprintf(stderr, "fdemd: cannot create the data directory %s: %s\n", cfg->data_dir,
                strerror(errno));
        return -1;
    }
    struct timespec before, after;
    clock_gettime(CLOCK_MONOTONIC, &before);
    int writable = persist_check_writable(cfg->data_dir) == 0;
    clock_gettime(CLOCK_MONOTONIC, &after);
    /* One fsynced write, timed: a snapshot makes about four (checkpoint.bin
     * and status.json, each file and directory), until real ones are timed. */
    io_seed_snapshot_seconds(4 * ((double)(after.tv_sec - before.tv_sec) +
                                  1e-9 * (double)(after.tv_nsec - before.tv_nsec)));
    if (!writable) {
        fprintf(stderr, "fdemd: the data directory %s cannot be written (%s); "
                "give fdemd a writable --data directory\n", cfg->data_dir, strerror(errno));
        return -1;
    }
    DIR *d = opendir(cfg->data_dir);
    if (!d) {
        fprintf(stderr, "fdemd: cannot read the data directory %s: %s\n", cfg->data_dir,
                strerror(errno));
        return -1;
    }
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, ".tmp-", 5) == 0) {
            registry_sweep_half_made(cfg, e->d_name);
            continue;
        }
        if (!id_is_valid(e->d_name))
            continue;
        server_case *c = registry_load_case(cfg, e->d_name);
        if (c && registry_append_locked(c) != 0)
            case_release(c);
    }
    closedir(d);
    if (reg_count > 1)
        qsort(reg_cases, (size_t)reg_count, sizeof *reg_cases, case_order);
    for (int i = 0; i < reg_count; i++)
        reg_cases[i]->seq = (uint64_t)i;
    return 0;
}

void registry_shutdown(void)
{
    pthread_mutex_lock(&reg_lock);
    reg_shutting_down = 1;
    pthread_mutex_unlock(&reg_lock);
    registry_stop_checks(); /* it finishes the case it is checking */
    int count = 0;
    server_case **cases = registry_list(&count);
    for (int i = 0; i < count; i++) {
        server_case *c = cases[i];
        pthread_mutex_lock(&c->ctl_lock);
        pthread_mutex_lock(&c->lock);
        c->paused_by_shutdown = c->state == CASE_RUNNING || c->state == CASE_QUEUED;
        if (c->state == CASE_RUNNING)
            case_command_worker_locked(c, WORKER_PAUSE);
        else if (c->state == CASE_QUEUED)
            c->state = CASE_PAUSED;
        membudget_lease unreserve = case_take_reserve_locked(c);
        pthread_mutex_unlock(&c->lock);
        membudget_release(&unreserve);
        /* one that could not be loaded keeps its files as found; one not
         * checked yet keeps the status.json it was loaded from */
        if (!c->load_broken && !atomic_load(&c->unchecked))
            case_persist_status(c);
        io_close(c);
        pthread_mutex_unlock(&c->ctl_lock);
    }
    registry_list_free(cases, count);

    pthread_mutex_lock(&reg_lock);
    for (int i = 0; i < reg_count; i++)
        case_release(reg_cases[i]);
    free(reg_cases);
    reg_cases = NULL;
    reg_count = reg_capacity = 0;
    pthread_mutex_unlock(&reg_lock);
}
