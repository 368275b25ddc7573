/*
 * run_case.c - the batch loop: a case stepped to its end with the daemon's
 * output rules and writers, in one process or (through a stepper) on the
 * ranks of an MPI job.
 *
 * Why a loop of its own and not the daemon's worker: the worker is built
 * around a registry, an HTTP side waiting on its locks and one I/O thread
 * shared by every case; a batch job has none of them and writes in line.
 * What must agree with the daemon lives once below both: when outputs fall
 * (proto/state/output_grid.h), what a snapshot, a history row, a
 * checkpoint and the status figures are (proto/state, proto/files) and the
 * HDF5 and XDMF writers (proto/result). tests/integration/test_fdem_run.py
 * compares the two directories dataset by dataset.
 */
#include "run_case.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "case/case.h"
#include "math/clock.h"
#include "files/checkpoint_file.h"
#include "files/persist.h"
#include "result/result.h"
#include "run_files.h"
#include "state/history.h"
#include "state/output_grid.h"
#include "state/snapshot.h"

#define RUN_MAX_DOCUMENT ((size_t)1 << 34)
#define RUN_HISTORY_BATCH 64        /* rows kept before they are appended */
#define RUN_XDMF_EAGER_SNAPSHOTS 200 /* past this many, the sidecar twice a second */
#define RUN_AGREE_EVERY 32          /* steps between the ranks' command checks */
#define RUN_PROGRESS_EVERY 10.0     /* wall seconds between progress lines */
#define RUN_LOOK_EVERY 0.02         /* wall seconds between looks at commands (one process) */

/* A command a run ends on, in the order the ranks agree on (the largest wins). */
enum { CMD_NONE = 0, CMD_STATUS, CMD_PAUSE, CMD_STOP };

/* Set by SIGTERM/SIGINT (a batch system's notice before its kill): a pause. */
static volatile sig_atomic_t run_signalled;

static void run_on_signal(int sig)
{
    (void)sig;
    run_signalled = 1;
}

typedef struct run_ctx {
    const run_options *o;
    runner_stepper *st;
    int writer;
    fdem_model *m;
    case_info info;
    result_file *result;
    char h5_path[1200], xdmf_path[1200];
    double next_output, next_history;
    int64_t last_snapshot_step, last_checkpoint_step;
    int at_end_already;         /* resumed at its end: nothing stepped, nothing to write */
    history_row **rows;
    int row_count, row_capacity;
    run_status status;
    double elapsed_before, run_started, last_status, last_progress, last_xdmf, last_look;
    int steps_since_agree;
    int snapshots;              /* rows in result.h5 (kept after it is closed) */
    int extending;              /* resumed from CHECKPOINT_FILE_RESUME */
    int history_failed;         /* appending history rows failed (the writer) */
    char control_line[64];
    int control_len;
    char error[768];
} run_ctx;

static void run_fail(run_ctx *r, const char *what)
{
    if (!r->error[0])
        snprintf(r->error, sizeof r->error, "%s", what);
}

/* ------------------------------------------------------------ stepping */

static int run_step(run_ctx *r, fdem_error *err)
{
    return r->st ? r->st->step(r->st->ctx, r->m, err) : fdem_step(r->m, err);
}

/* Before any output every rank makes rank 0's model whole. */
static int run_gather(run_ctx *r)
{
    if (!r->st || !r->st->gather)
        return 0;
    fdem_error err;
    memset(&err, 0, sizeof err);
    if (r->st->gather(r->st->ctx, r->m, &err) != 0) {
        run_fail(r, err.message[0] ? err.message : "gathering the model on rank 0 failed");
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ commands */

/* "pause" / "stop" lines on the control descriptor; its end of file (the
 * daemon that launched us is gone) pauses. Non-blocking. */
static int run_read_control(run_ctx *r)
{
    if (r->o->control_fd < 0)
        return CMD_NONE;
    int cmd = CMD_NONE;
    for (;;) {
        char c;
        ssize_t n = read(r->o->control_fd, &c, 1);
        if (n == 0)
            return CMD_PAUSE;
        if (n < 0)
            return cmd; /* EAGAIN: nothing more now */
        if (c != '\n') {
            if (r->control_len < (int)sizeof r->control_line - 1)
                r->control_line[r->control_len++] = c;
            continue;
        }
        r->control_line[r->control_len] = '\0';
        r->control_len = 0;
        if (strcmp(r->control_line, "stop") == 0)
            cmd = CMD_STOP;
        else if (strcmp(r->control_line, "pause") == 0 && cmd < CMD_PAUSE)
            cmd = CMD_PAUSE;
    }
}

/* The command every rank acts on at this step boundary. One process looks
 * at its wall clock; ranks ask each other every RUN_AGREE_EVERY steps (the
 * same steps on every rank), with rank 0's clock and control deciding. */
static int run_poll(run_ctx *r, double now)
{
    int local = CMD_NONE;
    int agreeing = r->st && r->st->agree;
    if (agreeing && ++r->steps_since_agree < RUN_AGREE_EVERY)
        return CMD_NONE;
    r->steps_since_agree = 0;
    /* one process: a read() a step would cost 5 % of a small model's step */
    if (!agreeing && !run_signalled && now - r->last_look < RUN_LOOK_EVERY)
        return CMD_NONE;
    r->last_look = now;
    if (r->writer) {
        if (now - r->last_status >= r->o->status_every)
            local = CMD_STATUS;
        int c = run_read_control(r);
        if (c > local)
            local = c;
        if (run_signalled && local < CMD_PAUSE)
            local = CMD_PAUSE;
    }
    return agreeing ? r->st->agree(r->st->ctx, local) : local;
}

/* ------------------------------------------------------------- writing */

static void run_figures_now(run_ctx *r, run_figures *f, double now)
{
    if (!r->m) { /* a case that could not be built shows none */
        memset(f, 0, sizeof *f);
        f->stage = -1;
        f->eta = NAN;
        return;
    }
    status_figures_of_model(f, r->m, &r->info);
    f->snapshots = r->snapshots;
    f->elapsed = r->elapsed_before + (now - r->run_started);
    int64_t steps = f->step;
    f->steps_per_second = f->elapsed > 0 ? (double)steps / f->elapsed : 0.0;
}

static void run_write_status(run_ctx *r, const char *state, double now)
{
    if (!r->writer)
        return;
    if (r->m)
        status_take_penetrations(r->status.warnings, r->m);
    run_figures f;
    run_figures_now(r, &f, now);
    r->status.state = state;
    r->status.error = r->error;
    char err[300];
    if (run_status_write(r->o->out_dir, &r->info, &f, &r->status, err, sizeof err) != 0)
        fprintf(stderr, "fdem-run: %s\n", err);
    r->last_status = now;
}

static void run_write_xdmf(run_ctx *r, int force, double now)
{
    int count = result_snapshot_count(r->result);
    if (!force && count > RUN_XDMF_EAGER_SNAPSHOTS && now - r->last_xdmf < 0.5)
        return;
    char err[256] = "";
    if (xdmf_write(r->xdmf_path, "result.h5", r->m, &r->info, r->result, err, sizeof err) != 0)
        fprintf(stderr, "fdem-run: result.xdmf: %s\n", err);
    r->last_xdmf = now;
}

static void run_take_history_row(run_ctx *r)
{
    if (!r->writer)
        return;
    if (r->row_count == r->row_capacity) {
        int capacity = r->row_capacity ? 2 * r->row_capacity : 16;
        history_row **grown = realloc(r->rows, sizeof *grown * (size_t)capacity);
        if (!grown)
            return; /* a row lost to memory, never the run */
        r->rows = grown;
        r->row_capacity = capacity;
    }
    history_row *row = history_take(r->m, r->info.history_nodes, r->info.history_point_count);
    if (row)
        r->rows[r->row_count++] = row;
}

static int run_flush_history(run_ctx *r)
{
    if (!r->row_count)
        return 0;
    char err[256] = "";
    int rc = result_append_history(r->result, r->rows, r->row_count, err, sizeof err);
    result_free_history(r->rows, r->row_count);
    r->rows = NULL;
    r->row_count = r->row_capacity = 0;
    if (rc != 0)
        run_fail(r, err);
    return rc;
}

/* The fracture events since the last call go to result.h5 before the
 * snapshot or checkpoint that follows them (a checkpoint holds none). */
static int run_append_events(run_ctx *r)
{
    int count = fdem_event_count(r->m);
    if (!count)
        return 0;
    fdem_event *events = malloc(sizeof *events * (size_t)count);
    if (!events)
        return 0; /* they stay in the engine for the next call */
    count = fdem_drain_events(r->m, events, count);
    char err[256] = "";
    int rc = result_append_events(r->result, events, count, err, sizeof err);
    free(events);
    if (rc != 0)
        run_fail(r, err);
    return rc;
}

/* The other ranks' copies of the events rank 0 writes: dropped where rank 0
 * drains its own, so they never pile up. */
static int run_drop_events(run_ctx *r)
{
    fdem_event dropped[64];
    while (fdem_drain_events(r->m, dropped, 64) > 0) {
    }
    return 0;
}

/* History rows, events, the snapshot (when `snap`), the checkpoint and
 * status.json, in the daemon's order: a checkpoint's rows before it. */
static int run_write_outputs(run_ctx *r, int snap, const char *state, double now)
{
    if (!r->writer)
        return run_drop_events(r);
    if (run_flush_history(r) != 0 || run_append_events(r) != 0)
        return -1;
    if (snap) {
        snapshot *s = snapshot_take(r->m, r->info.fields);
        char err[256] = "";
        int rc = s ? result_append(r->result, s, err, sizeof err) : -1;
        snapshot_free(s);
        if (rc != 0) {
            run_fail(r, s ? err : "no memory for a snapshot");
            return -1;
        }
        r->snapshots = result_snapshot_count(r->result);
        run_write_xdmf(r, 0, now);
        persist_fsync_path(r->h5_path);
    }
    char err[300];
    if (run_checkpoint_write(r->o->out_dir, CHECKPOINT_FILE_LATEST, r->m, err, sizeof err) != 0) {
        run_fail(r, err);
        return -1;
    }
    r->last_checkpoint_step = fdem_get_step(r->m);
    if (r->extending) { /* a later checkpoint.bin is durable: the resume point goes */
        char path[1200];
        snprintf(path, sizeof path, "%s/%s", r->o->out_dir, CHECKPOINT_FILE_RESUME);
        if (unlink(path) == 0)
            persist_fsync_dir(r->o->out_dir);
        r->extending = 0;
    }
    run_write_status(r, state, now);
    return 0;
}

/* The state before the step cut to land on time.end: a daemon's extend
 * goes on from it on the grid of an uninterrupted run (server's
 * case_model.h); the events so far go first, so it holds none. */
static int run_keep_end_checkpoint(run_ctx *r)
{
    if (run_gather(r) != 0)
        return -1;
    if (!r->writer)
        return run_drop_events(r);
    char err[300];
    if (run_append_events(r) != 0 ||
        run_checkpoint_write(r->o->out_dir, CHECKPOINT_FILE_END, r->m, err, sizeof err) != 0) {
        run_fail(r, r->error[0] ? r->error : err);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ the loop */

static void run_progress(run_ctx *r, double now)
{
    if (r->o->quiet || !r->writer || now - r->last_progress < RUN_PROGRESS_EVERY)
        return;
    r->last_progress = now;
    fprintf(stderr, "fdem-run: step %lld, t = %.6g of %.6g s\n", (long long)fdem_get_step(r->m),
            fdem_get_time(r->m), r->info.end_time);
}

/* Whether this rank or any other failed: a rank that stopped alone would
 * leave the others waiting in their next collective call. Called at the
 * same steps on every rank (outputs fall on the same steps). */
static int run_any_failed(run_ctx *r, int failed)
{
    failed |= r->history_failed;
    return r->st && r->st->agree ? r->st->agree(r->st->ctx, failed) : failed;
}

/* Steps until the end, a command or a failure. A directory resumed at
 * its end (run again after it finished) takes no step: it took one past
 * its end before, and wrote it. */
static run_outcome run_loop(run_ctx *r)
{
    const double end = r->info.end_time;
    if (output_at_end(fdem_get_time(r->m), fdem_get_dt(r->m), end)) {
        if (r->writer && !r->o->quiet)
            fprintf(stderr, "fdem-run: %s already finished at step %lld (t = %.6g s): nothing to do\n",
                    r->o->out_dir, (long long)fdem_get_step(r->m), fdem_get_time(r->m));
        r->at_end_already = 1;
        return RUN_FINISHED;
    }
    for (;;) {
        double now = clock_wall_seconds();
        int cmd = run_poll(r, now);
        if (r->o->pause_at_step > 0 && fdem_get_step(r->m) >= r->o->pause_at_step)
            cmd = CMD_PAUSE; /* the same step on every rank */
        if (cmd == CMD_PAUSE)
            return RUN_PAUSED;
        if (cmd == CMD_STOP)
            return RUN_STOPPED;
        double dt = fdem_get_dt(r->m), t0 = fdem_get_time(r->m);
        int cut = output_is_last_step(t0, dt, end);
        if (cut && run_any_failed(r, run_keep_end_checkpoint(r) != 0))
            return RUN_FAILED;
        if (cut)
            fdem_set_dt(r->m, end - t0);
        fdem_error err;
        memset(&err, 0, sizeof err);
        int failed = run_step(r, &err) != 0;
        if (cut)
            fdem_set_dt(r->m, dt);
        if (failed) {
            run_fail(r, err.message[0] ? err.message : "the solution became non-finite");
            return RUN_FAILED;
        }
        double t = fdem_get_time(r->m);
        int done = cut || t >= end;
        int snap = done || output_is_due(t, r->next_output, dt);
        if (snap)
            r->next_output = output_next_time(output_snapshot_interval(&r->info), t);
        int row = output_history_due(r->info.history_interval, t, cut ? end - t0 : dt, snap, done,
                                     &r->next_history);
        if ((snap || row || cmd == CMD_STATUS) && run_gather(r) != 0)
            return RUN_FAILED;
        if (row)
            run_take_history_row(r);
        now = clock_wall_seconds();
        if (snap) {
            r->last_snapshot_step = fdem_get_step(r->m);
            if (run_any_failed(r, run_write_outputs(r, 1, done ? "finished" : "running",
                                                    now) != 0))
                return RUN_FAILED;
        } else if (cmd == CMD_STATUS) {
            run_write_status(r, "running", now);
        }
        if (r->row_count >= RUN_HISTORY_BATCH && run_flush_history(r) != 0)
            r->history_failed = 1; /* ends the run at the next snapshot, on every rank */
        run_progress(r, now);
        if (done)
            return RUN_FINISHED;
    }
}

/* The last snapshot (a stop) and checkpoint (a pause or stop) for the way
 * the loop ended, then result.h5's views and its close. */
static void run_wind_down(run_ctx *r, run_outcome why)
{
    if (r->at_end_already && !r->error[0]) { /* its files are as its finish left them */
        if (r->writer && r->result && result_close(r->result) != 0)
            run_fail(r, "closing result.h5 failed (disk full or I/O error)");
        r->result = NULL;
        result_free_history(r->rows, r->row_count);
        r->rows = NULL;
        if (!r->error[0])
            return;
    }
    int64_t step = fdem_get_step(r->m);
    int stopping = why == RUN_STOPPED, pausing = why == RUN_PAUSED;
    if ((stopping || pausing) && run_gather(r) != 0)
        why = RUN_FAILED;
    double now = clock_wall_seconds();
    if (r->writer && r->result) {
        if (stopping && step != r->last_snapshot_step) {
            r->last_snapshot_step = step;
            if (output_history_due(r->info.history_interval, fdem_get_time(r->m),
                                   fdem_get_dt(r->m), 1, 0, &r->next_history))
                run_take_history_row(r);
            run_write_outputs(r, 1, "stopped", now);
        } else if ((stopping || pausing) && step != r->last_checkpoint_step) {
            run_write_outputs(r, 0, run_outcome_state(why), now);
        } else {
            run_flush_history(r);
            run_append_events(r);
        }
        char err[256] = "";
        if (result_finish(r->result, r->h5_path, fdem_get_dimension(r->m), err, sizeof err) != 0)
            run_fail(r, err);
        run_write_xdmf(r, 1, now);
        if (result_close(r->result) != 0)
            run_fail(r, "the final flush of result.h5 failed (disk full or I/O error)");
        r->result = NULL;
    }
    if (r->error[0] && why != RUN_BAD_CASE)
        why = RUN_FAILED;
    if (why == RUN_FINISHED || why == RUN_STOPPED || why == RUN_FAILED)
        status_time_now(r->status.finished_at, sizeof r->status.finished_at);
    run_write_status(r, run_outcome_state(why), now);
    result_free_history(r->rows, r->row_count);
    r->rows = NULL;
}

/* ------------------------------------------------------------ starting */

static char *run_read_document(const char *path, size_t *size, char *err, size_t errlen)
{
    char *doc = NULL;
    if (persist_read_file(path, &doc, size, RUN_MAX_DOCUMENT) != 0) {
        snprintf(err, errlen, "%.400s could not be read: %s", path, strerror(errno));
        return NULL;
    }
    return doc;
}

/* The model of the document, or NULL with every problem on stderr. */
static fdem_model *run_build(run_ctx *r, const char *doc, size_t size, const char *from)
{
    problems p;
    problems_init(&p);
    memset(&r->info, 0, sizeof r->info);
    problems warnings;
    problems_init(&warnings);
    fdem_model *m = case_build_gated(doc, size, (size_t)-1, NULL, NULL, &r->info, &p, &warnings);
    for (int i = 0; i < warnings.count; i++) /* the document's, as a daemon's upload lists them */
        status_warning_add(r->status.warnings, warnings.items[i].pointer,
                           warnings.items[i].message);
    problems_free(&warnings);
    if (!m && r->writer) {
        fprintf(stderr, "fdem-run: %s is not a valid case (%d problem%s):\n", from, p.count,
                p.count == 1 ? "" : "s");
        for (int i = 0; i < p.count; i++)
            fprintf(stderr, "  %s: %s\n", p.items[i].pointer[0] ? p.items[i].pointer : "/",
                    p.items[i].message);
        snprintf(r->error, sizeof r->error, "%s%s", p.count ? "the case is not valid: " : "",
                 p.count ? p.items[0].message : "the case could not be built");
    }
    problems_free(&p);
    return m;
}

/* A new directory: case.json, then result.h5 with its t = 0, the sidecar
 * and the first checkpoint, as a daemon stores an upload. */
static int run_create_files(run_ctx *r, const char *doc, size_t size, double now)
{
    char err[600] = "";
    if (persist_write_atomic(r->o->out_dir, "case.json", doc, size) != 0) {
        snprintf(err, sizeof err, "storing %.400s/case.json: %s", r->o->out_dir, strerror(errno));
        run_fail(r, err);
        return -1;
    }
    r->result = result_create_described(r->h5_path, r->m, &r->info, doc, size, err, sizeof err);
    if (!r->result) {
        run_fail(r, err);
        return -1;
    }
    r->last_snapshot_step = fdem_get_step(r->m);
    return run_write_outputs(r, 1, "running", now);
}

/* A directory with a checkpoint: the model goes back to it and result.h5
 * is cut back to its step (a missing file is made anew from it). */
static int run_reopen_files(run_ctx *r, double now)
{
    char err[600] = "";
    int64_t step = fdem_get_step(r->m);
    r->last_snapshot_step = r->last_checkpoint_step = step;
    if (access(r->h5_path, F_OK) == 0) {
        int64_t keep = r->extending ? step + 1 : step; /* the old end's row */
        r->result = result_reopen(r->h5_path, r->m, &r->info, keep, err, sizeof err);
        if (!r->result) {
            run_fail(r, err);
            return -1;
        }
        r->snapshots = result_snapshot_count(r->result);
        run_write_xdmf(r, 1, now);
        return 0;
    }
    r->result = result_create(r->h5_path, r->m, &r->info, err, sizeof err);
    if (!r->result) {
        run_fail(r, err);
        return -1;
    }
    return run_write_outputs(r, 1, "running", now);
}

/* Builds (or resumes) the model and opens the files; 0 or a failed outcome. */
static int run_start(run_ctx *r, run_outcome *failed)
{
    const run_options *o = r->o;
    int resume = run_dir_resumable(o->out_dir);
    char path[1200], err[600] = "";
    snprintf(path, sizeof path, "%s/case.json", o->out_dir);
    const char *from = resume ? path : o->case_path;
    size_t size = 0;
    char *doc = run_read_document(from, &size, err, sizeof err);
    *failed = RUN_FAILED;
    if (!doc) {
        run_fail(r, err);
        return -1;
    }
    r->m = run_build(r, doc, size, from);
    if (!r->m) {
        free(doc);
        *failed = RUN_BAD_CASE;
        return -1;
    }
    /* an extended case goes on from the step before its old end, on the
     * grid of an uninterrupted run, as a daemon's start does (server's
     * case_model.h); its end's row is kept */
    r->extending = resume && run_has_file(o->out_dir, CHECKPOINT_FILE_RESUME);
    const char *from_checkpoint = r->extending ? CHECKPOINT_FILE_RESUME : CHECKPOINT_FILE_LATEST;
    if (resume && run_checkpoint_restore(o->out_dir, from_checkpoint, r->m, err, sizeof err) != 0) {
        run_fail(r, err);
        free(doc);
        return -1;
    }
    fdem_set_threads(r->m, o->threads > 0 ? o->threads : 1);
    double now = clock_wall_seconds();
    r->run_started = r->last_status = r->last_progress = now;
    int rc = 0;
    if (r->writer) {
        if (resume)
            run_status_read_times(o->out_dir, &r->status, &r->elapsed_before);
        if (!r->status.started[0])
            status_time_now(r->status.started, sizeof r->status.started);
        rc = resume ? run_reopen_files(r, now) : run_create_files(r, doc, size, now);
    }
    free(doc);
    double t = fdem_get_time(r->m);
    r->next_output = output_next_time(output_snapshot_interval(&r->info), t);
    if (output_history_start(r->info.history_interval, t, fdem_get_step(r->m), &r->next_history))
        run_take_history_row(r);
    if (resume && r->writer && !o->quiet)
        fprintf(stderr, "fdem-run: resumed %s at step %lld (t = %.6g s)\n", o->out_dir,
                (long long)fdem_get_step(r->m), t);
    return rc;
}

run_outcome run_case(const run_options *o, runner_stepper *stepper)
{
    run_options opts = *o;
    if (!(opts.status_every > 0))
        opts.status_every = 0.5;
    run_ctx r;
    memset(&r, 0, sizeof r);
    r.o = &opts;
    r.st = stepper;
    r.writer = !stepper || stepper->is_writer;
    r.status.ranks = opts.ranks;
    r.status.warnings = json_array();
    r.status.eta = NAN;
    status_time_now(r.status.created, sizeof r.status.created);
    snprintf(r.h5_path, sizeof r.h5_path, "%s/result.h5", opts.out_dir);
    snprintf(r.xdmf_path, sizeof r.xdmf_path, "%s/result.xdmf", opts.out_dir);
    if (r.writer && persist_mkdir(opts.out_dir) != 0) {
        fprintf(stderr, "fdem-run: cannot make %s: %s\n", opts.out_dir, strerror(errno));
        return RUN_FAILED;
    }
    if (opts.control_fd >= 0)
        fcntl(opts.control_fd, F_SETFL, fcntl(opts.control_fd, F_GETFL) | O_NONBLOCK);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = run_on_signal;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);

    run_outcome why = RUN_FAILED;
    int started = run_start(&r, &why) == 0;
    if (!run_any_failed(&r, !started))
        why = run_loop(&r);
    else if (started) {
        why = RUN_FAILED;
        run_fail(&r, "another rank could not build the case or open its files (see its output)");
    }
    if (r.m) {
        run_wind_down(&r, why);
        why = r.error[0] && why != RUN_BAD_CASE ? RUN_FAILED : why;
        fdem_model_destroy(r.m);
    } else {
        run_write_status(&r, run_outcome_state(why), clock_wall_seconds());
    }
    if (r.error[0] && r.writer)
        fprintf(stderr, "fdem-run: %s: %s\n", run_outcome_state(why), r.error);
    json_decref(r.status.warnings);
    return why;
}

int run_exit_status(run_outcome outcome)
{
    switch (outcome) {
    case RUN_FINISHED: return 0;
    case RUN_PAUSED: return 3;
    case RUN_STOPPED: return 4;
    case RUN_BAD_CASE: return 2;
    case RUN_FAILED: return 1;
    }
    return 1;
}

const char *run_outcome_state(run_outcome outcome)
{
    switch (outcome) {
    case RUN_FINISHED: return "finished";
    case RUN_PAUSED: return "paused";
    case RUN_STOPPED: return "stopped";
    case RUN_FAILED: case RUN_BAD_CASE: return "failed";
    }
    return "failed";
}
