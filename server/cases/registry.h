/*
 * server/cases/ - the case lifecycle: a case from upload to deletion.
 *  - Owns: the case record and its reference count (case_record.c); the
 *    registry table and state machine (this header, registry.c); storing an
 *    upload (registry_create.c) and loading a stored case
 *    (registry_load.c, registry_internal.h between them); status objects
 *    and status.json (case_status.c); building, sizing and dropping models
 *    (case_model.c, case_sizing.c); extend and clone (case_continue.c); one
 *    worker thread per running case (worker.c); the one HDF5 I/O thread
 *    (io_thread.c); the feed of case events GET /stream serves
 *    (case_feed.c). The state machine, the workers and the I/O thread call
 *    each other: that circle stays inside this folder.
 *  - May call: store/ (fault_point.h), proto/files/ (persist.h, checkpoint_file.h),
 *    common/ (config.h, memory_budget.h), proto/ and core/.
 *  - Called by: http/ and main.c; it never calls http/.
 */
/*
 * registry.h - the set of cases the daemon holds and their state machine.
 *
 * Contract:
 *  - A case is reference counted: registry_find() and registry_list() hand
 *    out references that the caller returns with case_release(); a deleted
 *    case is freed when its last reference goes.
 *  - States: created -> running <-> paused -> finished | stopped | failed,
 *    plus "queued": a start while --max-running cases run puts the case in
 *    "queued"; queued cases start automatically in the order they were
 *    queued as soon as a slot frees; pause (-> paused) and stop (-> stopped)
 *    work on them. (We chose a queued state over 429 so a script can submit
 *    a whole batch and let the daemon pace it.)
 *  - Lock order: registry lock -> case lock. The worker holds model_lock
 *    only while it steps; GET /state takes it between two steps (see
 *    case_take_state), so a request never waits longer than one step.
 *  - Every state change is written to DIR/ID/status.json before the request
 *    that caused it is answered.
 */
#ifndef FDEMD_REGISTRY_H
#define FDEMD_REGISTRY_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <jansson.h>

#include "case/case.h"
#include "common/config.h"
#include "fdem.h"
#include "common/memory_budget.h"
#include "json/problems.h"
#include "result/result.h"
#include "state/snapshot.h"
#include "state/status_json.h"

typedef enum case_state {
    CASE_CREATED, CASE_QUEUED, CASE_RUNNING, CASE_PAUSED,
    CASE_FINISHED, CASE_STOPPED, CASE_FAILED,
} case_state;

/* What the HTTP side asks a worker to do at its next step boundary. */
typedef enum worker_command {
    WORKER_GO = 0, WORKER_PAUSE, WORKER_STOP, WORKER_ABANDON, /* abandon: case is being deleted */
} worker_command;

/* Figures of the last published step (status object, proto/state/status_json.h). */
typedef run_figures case_figures;

#define CASE_ID_LEN 16

typedef struct server_case {
    char id[CASE_ID_LEN + 1];
    char dir[1100];
    char created[40];          /* ISO 8601 UTC, sorts like time */
    char started[40];          /* first start (ISO 8601), "" = never (guarded by `lock`) */
    char finished_at[40];      /* reached a terminal state, "" = not yet (`lock`) */
    uint64_t seq;              /* creation order (oldest first listings) */
    atomic_int refs;

    fdem_model *model;         /* only while a worker runs the case (model_lock) */
    case_info info;
    membudget_lease reserve;   /* the model's share of --max-memory: running or queued */
    case_state queued_from;    /* where a queued case goes back to if it cannot start */

    pthread_mutex_t lock;      /* guards the fields down to `io_pending` */
    pthread_cond_t cv;         /* worker exit, I/O backlog drained */
    case_state state;
    char error[768];           /* "" = no error */
    case_figures fig;
    double estimated_seconds;  /* the sizing's wall time for the whole run (case_sizing.h)
                                  at submission, scaled by an extend; NAN: unknown */
    int worker_active;
    _Atomic int deleted;
    uint64_t queue_seq;
    int io_pending;            /* snapshot jobs not yet written */
    _Atomic int command;       /* worker_command */

    pthread_mutex_t ctl_lock;  /* serializes commands (start/pause/stop/delete) */

    pthread_mutex_t model_lock; /* the worker holds it while stepping */
    atomic_int state_waiters;   /* requesters that want model_lock */
    pthread_mutex_t yield_lock;
    pthread_cond_t yield_cv;

    pthread_mutex_t persist_lock; /* one status.json writer at a time */

    /* touched by the I/O thread only */
    result_file *result;
    double xdmf_written_at;    /* monotonic seconds */
    double xdmf_write_seconds; /* what the last rewrite of result.xdmf took */
    int xdmf_listed;           /* the rows the sidecar lists */

    /* storage faults (section 5.5): the first failed write of this case,
     * set by whoever hit it; the worker ends the case failed with it */
    _Atomic int io_failed;
    char io_error[512];        /* guarded by `lock` */
    _Atomic int io_hold;       /* downloads copying result.h5: writes wait */
    _Atomic int ranks_running; /* a ranked case's processes write its files (worker_ranked.c) */

    json_t *warnings;          /* contract 6.2 "warnings" (`lock`, case_warnings.c) */
    int stop_pending;          /* a stop is making `stopped` durable: the queue skips the
                                  case meanwhile (`lock`) */
    int paused_by_shutdown;    /* running or queued when the daemon stopped (`lock`):
                                  status.json says so, and the restart logs it as resumed */
    int load_broken;           /* its stored files could not be loaded at start-up: they are
                                  kept as found (so that, mended, the case comes back) */
    _Atomic int unchecked;     /* loaded at start-up, its stored files not checked yet: the
                                  daemon listens first (registry_ensure_checked) */
    case_state stored_state;   /* the state status.json had at start-up (for the log) */
    double feed_status_at;     /* its last status event (monotonic s; case_feed.c's lock) */

    /* worker-private */
    int64_t resume_rows_until; /* >= 0: resumed from the step before an extended case's
                                  old end, whose row (this step) is kept (case_model.h) */
    double next_output;
    int64_t last_snapshot_step, last_checkpoint_step;
    /* history rows (contract 6.2, worker_history.c): the next row's time
     * (with a "history" interval) and the rows taken but not yet queued */
    double next_history;
    history_row **history_pending;
    int history_pending_count, history_pending_capacity;
} server_case;

/* Lists the stored cases from their status.json; the rebuild that checks
 * the files of a case that may run again is left to
 * registry_check_in_background() (called once the daemon listens) or to
 * the first request for the case, whichever comes first. */
int registry_init(const fdemd_config *cfg);
/* Checks every case loaded unchecked, oldest first, on a thread of its own
 * (stopped and joined by registry_shutdown). 0, or -1 if no thread could be
 * made (the cases are then checked as requests come). */
int registry_check_in_background(void);
/* A case's stored files checked now if start-up has not yet (waits for a
 * check in progress): every request on one case calls it first, so it
 * never acts on files a crash left uncut. */
void registry_ensure_checked(server_case *c);
const fdemd_config *registry_config(void);
void registry_shutdown(void);  /* pauses running cases, closes results */

server_case *registry_find(const char *id);
void case_retain(server_case *c);
void case_release(server_case *c);
/* References to every case, oldest first; free the array with registry_list_free. */
server_case **registry_list(int *count);
void registry_list_free(server_case **cases, int count);
void registry_counts(int *cases, int *running);

/* Validates and stores a case. Returns the new case (a reference), or NULL
 * with `p` filled (400/422), or NULL with *http_status = 500 and `err`.
 * `warning` gets a sentence when the case will run for hours, else "". */
server_case *registry_create(const char *body, size_t size, int start, problems *p,
                             int *http_status, char *warning, size_t warning_size,
                             char *err, size_t errlen);
/* Validates and sizes a case without storing it (?dry_run=true): the
 * answer of case_sizing_json with *http_status 200, or NULL with `p` filled
 * and *http_status 400/422/503. */
json_t *registry_dry_run(const char *body, size_t size, problems *p, int *http_status);

/* start/pause/stop: 0, or 409 (or 503: no memory for the model now, or no
 * room on disk for a case that failed for a full disk, which start takes
 * back to its last checkpoint) with a sentence in msg; stop also 500 when
 * `stopped` could not be stored (the case is then failed with the write
 * error). */
int registry_start(server_case *c, char *msg, size_t msglen);
int registry_pause(server_case *c, char *msg, size_t msglen);
int registry_stop(server_case *c, char *msg, size_t msglen);
/* 0 once the files are gone; 404; or 500 with the reason in msg (the case
 * stays listed, stopped). */
int registry_delete(server_case *c, char *msg, size_t msglen);

/* The state at one step boundary: the running model's, else the last
 * checkpoint's (a temporary rebuild), with the name of its stage in
 * stage_name ("" without stages). NULL with *status 503 (memory short
 * now) or 409 (the stored case cannot be rebuilt). */
snapshot *case_take_state(server_case *c, unsigned fields, int *status, char *stage_name,
                          size_t stage_name_size);
/* Whether the case holds its model now (running, or being stepped): its
 * state is then a copy, not a rebuild. Waits at most one step. */
int case_holds_model(server_case *c);

json_t *case_status_json(server_case *c);
const char *case_state_name(case_state s);
int case_state_parse(const char *name, case_state *out);
/* Stamps finished_at the first time the case reaches a terminal `state`
 * (with the case lock held; a no-op for other states). */
void case_mark_ended_locked(server_case *c, case_state state);
/* One line on stderr per case event (submitted, started, paused, ...):
 * "fdemd: case ID "name": <event>". */
void case_log(server_case *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The event line of a case that has just settled in `state`, with its figures. */
void case_log_state(server_case *c, case_state state);
/* Writes status.json durably; 0, or -1 after recording the failure with
 * case_record_io_failure (a case with no worker becomes failed at once). */
int case_persist_status(server_case *c);
/* The same with `snapshots` (>= 0) as the stored count: the I/O thread
 * stores a new count before it shows it, so that a restart's listing,
 * made from status.json, never shows less than a client has seen. */
int case_persist_status_counting(server_case *c, int snapshots);
/* Records that writing `file` of the case failed for `reason` (the first
 * failure is kept); the running case ends `failed` with this error. */
void case_record_io_failure(server_case *c, const char *file, const char *reason);

/* Called by the worker and the I/O thread. */
void case_publish(server_case *c, const case_figures *fig);
void case_set_snapshots(server_case *c, int snapshots);
/* The worker's last words: sets the final state, frees its slot, persists
 * the status and starts queued cases (the worker then clears worker_active). */
void registry_worker_exited(server_case *c, case_state final_state);
int id_is_valid(const char *s);

#endif
