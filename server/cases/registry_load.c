/*
 * registry_load.c - a stored case read back from the data directory at
 * start-up: its status.json (state, figures), a check of its stored files
 * (rebuilt once when the memory budget allows, then freed), and the sweep
 * of half-made cases. The check of a case that may run again is left until
 * the daemon listens (a thread of its own, or the first request for the
 * case, registry_ensure_checked): a big model takes seconds to rebuild.
 *
 * Memory short for a moment never makes a case fail; a case whose files
 * cannot be loaded keeps them as found (load_broken), so that once mended
 * it comes back as it was.
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "case_feed.h"
#include "case_model.h"
#include "case_continue.h"
#include "common/memory_budget.h"
#include "files/persist.h"
#include "registry.h"
#include "registry_internal.h"

/* The case lock is taken: a check runs while requests read the status. */
static void case_fail_loading(server_case *c, const char *fmt, const char *detail)
{
    pthread_mutex_lock(&c->lock);
    c->state = CASE_FAILED;
    snprintf(c->error, sizeof c->error, fmt, detail);
    case_mark_ended_locked(c, CASE_FAILED);
    pthread_mutex_unlock(&c->lock);
    fprintf(stderr, "fdemd: case %s: %s\n", c->id, c->error);
}

/* A number of status.json; null (a non-finite figure) reads as NaN. */
static double status_number(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

/* The figures the case last published: what its status shows until it
 * runs again (no model is built to find them). */
static void case_load_figures(server_case *c, const json_t *st)
{
    status_figures_from_json(&c->fig, st);
    const char *name = json_string_value(json_object_get(st, "name"));
    snprintf(c->info.name, sizeof c->info.name, "%s", name ? name : "");
    c->info.end_time = status_number(st, "end_time");
    json_int_t ranks = json_integer_value(json_object_get(st, "ranks"));
    c->info.ranks = ranks > 1 && ranks <= CASE_MAX_RANKS ? (int)ranks : 1;
    c->estimated_seconds = status_number(st, "estimated_seconds"); /* NAN before it was kept */
}

/* The state the case was in when the daemon stopped: a case the shutdown
 * paused was running (or queued). A status.json that cannot be read fails
 * the case with *broken set: the file is kept as found. */
static case_state case_load_status(server_case *c, const char *path, int *broken)
{
    json_error_t jerr;
    json_t *st = json_load_file(path, JSON_REJECT_DUPLICATES, &jerr);
    const char *state = st ? json_string_value(json_object_get(st, "state")) : NULL;
    const char *created = st ? json_string_value(json_object_get(st, "created")) : NULL;
    const char *error = st ? json_string_value(json_object_get(st, "error")) : NULL;
    *broken = !st || case_state_parse(state, &c->state) != 0;
    if (*broken) {
        case_fail_loading(c, "status.json could not be read (%s); it is kept as found",
                          st ? "no valid state" : jerr.text);
    } else if (error) {
        snprintf(c->error, sizeof c->error, "%s", error);
    }
    if (created)
        snprintf(c->created, sizeof c->created, "%s", created);
    const char *started = st ? json_string_value(json_object_get(st, "started")) : NULL;
    const char *finished_at = st ? json_string_value(json_object_get(st, "finished_at")) : NULL;
    snprintf(c->started, sizeof c->started, "%s", started ? started : "");
    snprintf(c->finished_at, sizeof c->finished_at, "%s", finished_at ? finished_at : "");
    if (st) {
        case_load_figures(c, st);
        case_warnings_from_json(c, json_object_get(st, "warnings"));
    }
    case_state was = c->state;
    if (c->state == CASE_PAUSED && json_is_true(json_object_get(st, "paused_by_shutdown")))
        was = CASE_RUNNING;
    json_decref(st);
    return was;
}

/* A case whose restored time is already at its end (a status.json that
 * says running, e.g. edited by hand) is finished: it must never step on. */
static void case_finish_if_at_end(server_case *c)
{
    if (!c->model || case_state_is_terminal(c->state))
        return;
    double dt = fdem_get_dt(c->model);
    if (fdem_get_time(c->model) >= c->info.end_time - 1e-6 * dt) {
        fprintf(stderr, "fdemd: case %s: its checkpoint is at the end time; it is finished\n", c->id);
        pthread_mutex_lock(&c->lock);
        c->state = CASE_FINISHED;
        case_mark_ended_locked(c, CASE_FINISHED);
        pthread_mutex_unlock(&c->lock);
    }
}

/* A case that may run again is rebuilt once at start-up, when the budget
 * allows, to check its stored files and cut result.h5 back to its
 * checkpoint (a crash leaves later snapshots); the model is freed at once.
 * Short of memory the check waits for the case's start: it stays as it was
 * (memory short for a moment never makes a case fail). */
static int case_check_stored(server_case *c)
{
    if (case_state_is_terminal(c->state))
        return 0;
    membudget_lease lease = {0};
    fdem_model *model = NULL;
    case_info info;
    char err[512] = "";
    case_model_rc rc = CASE_MODEL_NO_MEMORY;
    if (membudget_grow(&lease, case_model_cost_of(c)) == 0)
        rc = case_model_build(c, &lease, &model, &info, err, sizeof err);
    int broken = 0;
    if (rc == CASE_MODEL_BROKEN) {
        case_fail_loading(c, "%s", err);
        broken = 1;
    } else if (rc == CASE_MODEL_OK) {
        if (case_model_attach(c, model, &info, 1, err, sizeof err) != 0) {
            case_fail_loading(c, "%s", err);
            broken = 1;
        }
        case_finish_if_at_end(c);
        if (c->resume_rows_until < 0) /* resumed before an old end: the status shows that end */
            case_publish_from_model(c);
        case_model_drop(c);
    } else {
        fprintf(stderr, "fdemd: case %s: not checked at start-up (--max-memory is short); it "
                "stays %s and is checked when it starts\n", c->id, case_state_name(c->state));
    }
    membudget_release(&lease);
    return broken ? -1 : 0;
}

/* The restart's line for the log: a case that was running or queued is
 * resumed paused at its last checkpoint (its figures are that step's). */
static void case_log_restored(server_case *c, case_state stored)
{
    if (stored == CASE_RUNNING || stored == CASE_QUEUED)
        case_log(c, "resumed after a restart: was %s when fdemd stopped, now %s at its "
                 "checkpoint, step %lld (t = %.6g of %.6g s, %.3f s stepping so far); start it "
                 "to go on", case_state_name(stored), case_state_name(c->state),
                 (long long)c->fig.step, c->fig.time, c->info.end_time, c->fig.elapsed);
    else
        case_log(c, "restored after a restart: %s at step %lld (t = %.6g s)",
                 case_state_name(c->state), (long long)c->fig.step, c->fig.time);
}

server_case *registry_load_case(const fdemd_config *cfg, const char *id)
{
    server_case *c = case_new();
    if (!c)
        return NULL;
    snprintf(c->id, sizeof c->id, "%s", id);
    snprintf(c->dir, sizeof c->dir, "%s/%s", cfg->data_dir, id);
    char path[1200];
    snprintf(path, sizeof path, "%s/case.json", c->dir);
    struct stat st;
    if (stat(path, &st) != 0) {
        /* Never acknowledged (the 201 follows case.json and status.json). */
        fprintf(stderr, "fdemd: skipping %s: no case.json\n", c->dir);
        case_release(c);
        return NULL;
    }
    snprintf(path, sizeof path, "%s/status.json", c->dir);
    if (stat(path, &st) != 0 && errno == ENOENT) {
        /* Left by a crash during POST /cases of an older fdemd, which
         * wrote status.json last before its 201: never acknowledged. */
        fprintf(stderr, "fdemd: skipping %s: no status.json (a case never acknowledged)\n", c->dir);
        case_release(c);
        return NULL;
    }
    int status_broken = 0;
    case_state stored = case_load_status(c, path, &status_broken);
    if (!c->created[0])
        status_time_now(c->created, sizeof c->created);
    if (c->state == CASE_RUNNING || c->state == CASE_QUEUED)
        c->state = CASE_PAUSED;
    registry_extend_recover(c); /* before the check: it rebuilds with the new end */
    persist_reserve(c->dir);
    c->stored_state = stored;
    /* A case that could not be loaded keeps its files as they are, so that
     * once the damage is mended it comes back as it was. */
    c->load_broken = status_broken;
    if (!status_broken && !case_state_is_terminal(c->state)) {
        atomic_store(&c->unchecked, 1); /* rebuilt once the daemon listens */
        return c;
    }
    if (!c->load_broken)
        case_persist_status(c);
    case_log_restored(c, stored);
    return c;
}

void registry_ensure_checked(server_case *c)
{
    if (!atomic_load(&c->unchecked))
        return;
    pthread_mutex_lock(&c->ctl_lock);
    int changed = 0;
    if (atomic_load(&c->unchecked)) {
        pthread_mutex_lock(&c->lock);
        case_state before = c->state;
        pthread_mutex_unlock(&c->lock);
        c->load_broken = case_check_stored(c) != 0;
        if (!c->load_broken)
            case_persist_status(c);
        case_log_restored(c, c->stored_state);
        atomic_store(&c->unchecked, 0);
        pthread_mutex_lock(&c->lock);
        changed = c->state != before;
        pthread_mutex_unlock(&c->lock);
    }
    pthread_mutex_unlock(&c->ctl_lock);
    if (changed) /* the check found its files broken */
        case_feed_status(c);
}

/* Start-up's rebuilds run here, after the daemon listens: three stored
 * 384k-tetrahedron cases kept it unreachable for 17 s when they ran before. */
static pthread_t check_thread;
static int check_running;
static atomic_int check_quit;

static void *check_main(void *arg)
{
    (void)arg;
    int count = 0;
    server_case **cases = registry_list(&count);
    for (int i = 0; cases && i < count && !atomic_load(&check_quit); i++)
        registry_ensure_checked(cases[i]);
    registry_list_free(cases, count);
    return NULL;
}

int registry_check_in_background(void)
{
    if (pthread_create(&check_thread, NULL, check_main, NULL) != 0) {
        fprintf(stderr, "fdemd: cannot start the thread that checks stored cases; each is "
                "checked when it is first asked for\n");
        return -1;
    }
    check_running = 1;
    return 0;
}

void registry_stop_checks(void)
{
    if (!check_running)
        return;
    atomic_store(&check_quit, 1);
    pthread_join(check_thread, NULL);
    check_running = 0;
}

/* A case being created or deleted when the daemon stopped: never
 * acknowledged (or already deleted), so it goes. */
void registry_sweep_half_made(const fdemd_config *cfg, const char *name)
{
    char path[sizeof cfg->data_dir + 300];
    snprintf(path, sizeof path, "%s/%s", cfg->data_dir, name);
    if (persist_remove_dir(path) != 0)
        fprintf(stderr, "fdemd: cannot remove the half-made case %s: %s\n", path, strerror(errno));
    else
        fprintf(stderr, "fdemd: removed the half-made case %s\n", path);
}
