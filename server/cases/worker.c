/*
 * worker.c - the step loop of one running case.
 *
 * The loop holds model_lock only around fdem_step() and the copies taken
 * right after it (snapshot, checkpoint buffer, published figures), and
 * steps aside whenever a GET /state is waiting (state_waiters), so such a
 * request waits at most one step. Disk work happens on the I/O thread; the
 * worker only blocks when that thread falls far behind (backpressure) or
 * when it pauses/stops and wants its last checkpoint durable before the
 * command is acknowledged.
 */
#include "worker.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "case_feed.h"
#include "case_model.h"
#include "files/checkpoint_file.h"
#include "case_sizing.h"
#include "sizing_probe.h"
#include "io_thread.h"
#include "registry_internal.h"
#include "eta_window.h"
#include "worker_history.h"
#include "worker_ranked.h"
#include "math/clock.h"

#define WORKER_PUBLISH_INTERVAL 0.05   /* s of wall time between status figures */
#define WORKER_MAX_IO_BACKLOG 8        /* snapshot jobs in flight per case */
typedef enum worker_exit {
    EXIT_PAUSE, EXIT_STOP, EXIT_ABANDON, EXIT_FINISHED, EXIT_FAILED,
} worker_exit;

typedef struct worker_clock {
    double last_publish, last_checkpoint;
    /* steps_per_second is measured over windows of its own (0.2 s or 100
     * steps): tying the publish clock to that window published nearly
     * every step once a step took over 0.5 ms (816 energy evaluations in
     * 1,100 steps of a 100k-element block, 9 % of the daemon's CPU) */
    double speed_since;
    int64_t steps_at_speed;
    double steps_per_second;
    /* the stepping thread's CPU and wall seconds read together at the
     * start of the share's window, and its CPU per wall second over the
     * last window: what this case gets of a core while other cases share
     * the machine */
    double cpu_at_speed, wall_at_cpu, cpu_share;
    double run_started;     /* when this run began stepping */
    double elapsed_before;  /* wall seconds spent stepping in earlier runs */
    eta_window eta;         /* this run's (eta_window.h) */
    double io_waited;       /* wall seconds this run waited for its snapshot writes */
    int snapshots_taken;    /* by this run */
} worker_clock;

/* The first output time strictly after `t` on the grid k * interval. */
static double worker_next_output(const server_case *c, double t)
{
    return output_next_time(output_snapshot_interval(&c->info), t);
}

/* Elements the engine found passing into one another since the last
 * publish become status warnings (contract 6.2, status_take_penetrations).
 * With model_lock held. */
static void worker_take_warnings(server_case *c)
{
    pthread_mutex_lock(&c->lock);
    if (!c->warnings)
        c->warnings = json_array();
    status_take_penetrations(c->warnings, c->model);
    pthread_mutex_unlock(&c->lock);
}

/* Called with model_lock held (the figures must belong to one step). */
static void worker_publish(server_case *c, worker_clock *clk, double now, int running)
{
    const fdem_model *m = c->model;
    case_figures fig;
    memset(&fig, 0, sizeof fig);
    fig.step = fdem_get_step(m);
    fig.time = fdem_get_time(m);
    fig.dt = fdem_get_dt(m);
    fig.counts = fdem_get_counts(m);
    fig.energy = fdem_get_energy(m);
    fig.fluid = fdem_get_fluid(m);
    clk->last_publish = now;
    double wall = now - clk->speed_since;
    if (wall > 0.2 || (wall > 0 && fig.step - clk->steps_at_speed > 100))
        clk->steps_per_second = (double)(fig.step - clk->steps_at_speed) / wall;
    if (wall > 0.2 || fig.step - clk->steps_at_speed > 100) {
        /* read side by side: `now` came before the figures were taken, and
         * their varying cost between two windows read against it gave
         * shares of 1.09 */
        double cpu = clock_cpu_seconds(), wall_now = clock_wall_seconds();
        if (wall_now - clk->wall_at_cpu > 0.02) {
            clk->cpu_share = (cpu - clk->cpu_at_speed) / (wall_now - clk->wall_at_cpu);
            clk->cpu_at_speed = cpu;
            clk->wall_at_cpu = wall_now;
        }
        clk->speed_since = now;
        clk->steps_at_speed = fig.step;
    }
    fig.steps_per_second = running ? clk->steps_per_second : 0.0;
    fig.cpu_share = running ? clk->cpu_share : NAN;
    fig.eta = running ? eta_window_take(&clk->eta, now, fig.time, c->info.end_time) : NAN;
    fig.snapshots = -1; /* owned by the I/O thread */
    fig.elapsed = clk->elapsed_before + (now - clk->run_started);
    status_figures_stage(&fig, m, &c->info);
    case_publish(c, &fig);
    worker_take_warnings(c);
}

/* Lets pending GET /state requests take model_lock before the next step. */
static void worker_yield_to_requesters(server_case *c)
{
    if (atomic_load(&c->state_waiters) == 0)
        return;
    pthread_mutex_lock(&c->yield_lock);
    while (atomic_load(&c->state_waiters) > 0)
        pthread_cond_wait(&c->yield_cv, &c->yield_lock);
    pthread_mutex_unlock(&c->yield_lock);
}

/* Waits until at most max_pending snapshot jobs are left; returns the
 * wall seconds it waited (0 without a wait). */
static double worker_wait_io(server_case *c, int max_pending)
{
    double waited = 0;
    pthread_mutex_lock(&c->lock);
    if (c->io_pending > max_pending) {
        double started = clock_wall_seconds();
        while (c->io_pending > max_pending)
            pthread_cond_wait(&c->cv, &c->lock);
        waited = clock_wall_seconds() - started;
    }
    pthread_mutex_unlock(&c->lock);
    return waited;
}

/* The engine's message already names the step, element and dt (fdem.h);
 * we compose our own sentence only if it left the message empty. */
static void worker_describe_failure(server_case *c, const fdem_error *err, double dt)
{
    char where[64] = "";
    if (err->kind == FDEM_ITEM_ELEMENT && err->item >= 0)
        snprintf(where, sizeof where, " in element %d", err->item);
    else if (err->kind == FDEM_ITEM_NODE && err->item >= 0)
        snprintf(where, sizeof where, " at node %d", err->item);
    pthread_mutex_lock(&c->lock);
    if (err->message[0])
        snprintf(c->error, sizeof c->error, "%s", err->message);
    else
        snprintf(c->error, sizeof c->error,
                 "the solution became non-finite in the step after step %lld (t = %.6g s)%s "
                 "with dt = %.3g s; reduce time.safety or check the material stiffness and penalty",
                 (long long)fdem_get_step(c->model), fdem_get_time(c->model), where, dt);
    pthread_mutex_unlock(&c->lock);
}

/* The fracture events since the last call, for the next I/O job; taken
 * before its checkpoint, which then holds none of them. Without memory
 * they stay in the engine (and its checkpoint) for the next job. */
static fdem_event *worker_drain_events(fdem_model *m, int *count)
{
    *count = fdem_event_count(m);
    fdem_event *events = *count ? malloc(sizeof *events * (size_t)*count) : NULL;
    if (!events) {
        *count = 0;
        return NULL;
    }
    *count = fdem_drain_events(m, events, *count);
    return events;
}

/* The state before the step that is cut to land on time.end: an extend
 * goes on from it, on the step grid of an uninterrupted run, instead of
 * from the end (case_model.h). The events so far go to the file first,
 * so the checkpoint holds none an extend would write twice. With
 * model_lock held. */
static void worker_keep_end_checkpoint(server_case *c)
{
    int event_count = 0;
    fdem_event *events = worker_drain_events(c->model, &event_count);
    size_t size = 0;
    void *ckpt = checkpoint_file_take(c->model, &size);
    io_write_named_checkpoint(c, CASE_END_CHECKPOINT, events, event_count, ckpt, size);
}

/* Runs steps until a command, the end time or a failure. */
static worker_exit worker_loop(server_case *c, worker_clock *clk)
{
    fdem_model *m = c->model;
    const double end = c->info.end_time;
    for (;;) {
        int cmd = atomic_load(&c->command);
        if (cmd == WORKER_PAUSE)
            return EXIT_PAUSE;
        if (cmd == WORKER_STOP)
            return EXIT_STOP;
        if (cmd == WORKER_ABANDON)
            return EXIT_ABANDON;
        if (atomic_load(&c->io_failed))
            return EXIT_FAILED; /* a write failed: stop, results so far are kept */
        worker_yield_to_requesters(c);

        pthread_mutex_lock(&c->model_lock);
        double dt = fdem_get_dt(m);
        /* Output never shapes the run: every step has the model's own
         * size, and a snapshot is taken at the first step boundary at or
         * after its output time. Only the last step is cut, to end the case
         * exactly at time.end (a shorter step is always stable, and central
         * difference takes a changing step). */
        double t0 = fdem_get_time(m);
        int cut = output_is_last_step(t0, dt, end);
        if (cut)
            worker_keep_end_checkpoint(c);
        if (cut)
            fdem_set_dt(m, end - t0);
        fdem_error err;
        memset(&err, 0, sizeof err);
        int failed = fdem_step(m, &err) != 0;
        if (cut)
            fdem_set_dt(m, dt);
        if (failed) {
            worker_describe_failure(c, &err, cut ? end - t0 : dt);
            pthread_mutex_unlock(&c->model_lock);
            return EXIT_FAILED;
        }
        double t = fdem_get_time(m), now = clock_wall_seconds();
        int done = cut || t >= end;
        snapshot *snap = NULL;
        void *ckpt = NULL;
        size_t ckpt_size = 0;
        fdem_event *events = NULL;
        int event_count = 0;
        if (done || output_is_due(t, c->next_output, dt)) {
            snap = snapshot_take(m, c->info.fields);
            c->last_snapshot_step = fdem_get_step(m);
            c->next_output = worker_next_output(c, t);
            clk->snapshots_taken++;
        }
        worker_history_after_step(c, cut ? end - t0 : dt, snap != NULL, done);
        /* Every snapshot comes with a checkpoint, so that a restart never
         * drops a snapshot the status has reported (a restart resumes at the
         * last checkpoint and drops the rows after it); --checkpoint-every
         * makes progress between far-apart snapshots survive a crash too. */
        if (snap || now - clk->last_checkpoint >= registry_config()->checkpoint_every) {
            events = worker_drain_events(m, &event_count);
            ckpt = checkpoint_file_take(m, &ckpt_size);
            c->last_checkpoint_step = fdem_get_step(m);
            clk->last_checkpoint = now;
        }
        int published = snap || done || now - clk->last_publish >= WORKER_PUBLISH_INTERVAL;
        if (published)
            worker_publish(c, clk, now, 1);
        pthread_mutex_unlock(&c->model_lock);
        if (published)
            case_feed_progress(c); /* at most CASE_FEED_STATUS_RATE a second */

        /* a checkpoint's rows go before it (worker_history.h) */
        if (ckpt || worker_history_batch_full(c))
            worker_history_flush(c);
        if (snap || ckpt) {
            io_append(c, events, event_count, snap, ckpt, ckpt_size);
            clk->io_waited += worker_wait_io(c, WORKER_MAX_IO_BACKLOG);
        }
        if (done)
            return EXIT_FINISHED;
    }
}

/* Final snapshot/checkpoint for the way the loop ended; waits until they are
 * on disk so the command's answer never runs ahead of the files. */
static void worker_wind_down(server_case *c, worker_exit why, worker_clock *clk)
{
    if (why == EXIT_ABANDON) {
        worker_history_discard(c);
        return;
    }
    snapshot *snap = NULL;
    void *ckpt = NULL;
    size_t ckpt_size = 0;
    int event_count = 0;
    pthread_mutex_lock(&c->model_lock);
    /* a failed case keeps the events up to its last step too */
    fdem_event *events = worker_drain_events(c->model, &event_count);
    int64_t step = fdem_get_step(c->model);
    if (why == EXIT_STOP && step != c->last_snapshot_step) {
        snap = snapshot_take(c->model, c->info.fields);
        c->last_snapshot_step = step;
        worker_history_after_step(c, fdem_get_dt(c->model), 1, 0);
    }
    if ((why == EXIT_PAUSE || why == EXIT_STOP) && step != c->last_checkpoint_step) {
        ckpt = checkpoint_file_take(c->model, &ckpt_size);
        c->last_checkpoint_step = step;
    }
    worker_publish(c, clk, clock_wall_seconds(), 0);
    pthread_mutex_unlock(&c->model_lock);
    worker_history_flush(c);
    if (snap || ckpt || events)
        io_append(c, events, event_count, snap, ckpt, ckpt_size);
    worker_wait_io(c, 0);
    io_close(c); /* a paused case keeps no file open either (case_model.h) */
}

static case_state worker_final_state(worker_exit why)
{
    switch (why) {
    case EXIT_PAUSE: return CASE_PAUSED;
    case EXIT_STOP: case EXIT_ABANDON: return CASE_STOPPED;
    case EXIT_FINISHED: return CASE_FINISHED;
    case EXIT_FAILED: return CASE_FAILED;
    }
    return CASE_FAILED;
}

/* The model the start built, or (a case that waited in the queue) one
 * built now from the stored files under the reservation the start made;
 * then the result file is opened at its step. 0, or -1 with the state the
 * case goes back to: where it was when memory is short, failed (with an
 * error) when its files are broken. */
static int worker_take_model(server_case *c, case_state *fallback)
{
    char err[512] = "";
    pthread_mutex_lock(&c->model_lock);
    fdem_model *model = c->model;
    pthread_mutex_unlock(&c->model_lock);
    case_info info = c->info;
    case_model_rc rc = CASE_MODEL_OK;
    if (!model)
        rc = case_model_build(c, &c->reserve, &model, &info, err, sizeof err);
    if (rc == CASE_MODEL_OK && case_model_attach(c, model, &info, 0, err, sizeof err) == 0)
        return 0;
    *fallback = rc == CASE_MODEL_NO_MEMORY ? c->queued_from : CASE_FAILED;
    if (rc == CASE_MODEL_NO_MEMORY) {
        fprintf(stderr, "fdemd: case %s: no memory for its model now (--max-memory); it goes "
                "back to %s\n", c->id, case_state_name(*fallback));
    } else {
        pthread_mutex_lock(&c->lock);
        snprintf(c->error, sizeof c->error, "%s", err);
        pthread_mutex_unlock(&c->lock);
    }
    return -1;
}

static void *worker_main(void *arg)
{
    server_case *c = arg;
    const fdemd_config *cfg = registry_config();
    worker_exit why = EXIT_FAILED;
    case_state final_state = CASE_FAILED;
    int taken = worker_take_model(c, &final_state) == 0;
    if (taken && c->info.ranks > 1) {
        final_state = worker_ranked_run(c); /* the ranks step it (worker_ranked.h) */
        if (atomic_load(&c->command) == WORKER_ABANDON)
            why = EXIT_ABANDON;
    } else if (taken) {
        fdem_set_threads(c->model, cfg->threads);
        double now = clock_wall_seconds();
        pthread_mutex_lock(&c->lock);
        double elapsed_before = c->fig.elapsed > 0 ? c->fig.elapsed : 0.0;
        pthread_mutex_unlock(&c->lock);
        worker_clock clk = {.last_publish = now, .last_checkpoint = now, .speed_since = now,
                            .steps_at_speed = fdem_get_step(c->model), .run_started = now,
                            .cpu_at_speed = clock_cpu_seconds(), .wall_at_cpu = now,
                            .cpu_share = NAN,
                            .elapsed_before = elapsed_before};
        case_log(c, "started at step %lld (t = %.6g of %.6g s, dt = %.3g s)",
                 (long long)fdem_get_step(c->model), fdem_get_time(c->model), c->info.end_time,
                 fdem_get_dt(c->model));
        c->next_output = worker_next_output(c, fdem_get_time(c->model));
        worker_history_start(c);
        double cpu_started = clock_cpu_seconds();
        why = worker_loop(c, &clk);
        /* what this run got of the machine, for the next estimates */
        double wall = clock_wall_seconds() - clk.run_started;
        sizing_note_run(wall - clk.io_waited, clock_cpu_seconds() - cpu_started);
        io_note_paced_run(wall, clk.io_waited, clk.snapshots_taken);
        worker_wind_down(c, why, &clk);
        final_state = worker_final_state(why);
    }
    case_model_drop(c); /* model, result file and reservation go with the worker */

    if (why == EXIT_ABANDON)
        atomic_store(&c->deleted, 1); /* nothing more to persist */
    registry_worker_exited(c, final_state);
    pthread_mutex_lock(&c->lock);
    c->worker_active = 0;
    pthread_cond_broadcast(&c->cv);
    pthread_mutex_unlock(&c->lock);
    case_release(c);
    return NULL;
}

int worker_spawn(server_case *c)
{
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    case_retain(c);
    c->worker_active = 1;
    atomic_store(&c->command, WORKER_GO);
    pthread_t t;
    int rc = pthread_create(&t, &attr, worker_main, c);
    pthread_attr_destroy(&attr);
    if (rc != 0) {
        c->worker_active = 0;
        case_release(c);
        return -1;
    }
    return 0;
}
