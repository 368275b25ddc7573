/*
 * case_status.c - a case's published figures and its status object: the
 * JSON every status route answers with, and status.json, written before a
 * state change is acknowledged. A write that fails ends the case failed
 * with the file and the reason (case_record_io_failure).
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "case_feed.h"
#include "files/persist.h"
#include "registry.h"
#include "registry_internal.h"
#include "state/status_json.h"

void case_publish(server_case *c, const case_figures *fig)
{
    pthread_mutex_lock(&c->lock);
    int snapshots = c->fig.snapshots;
    double elapsed = c->fig.elapsed;
    c->fig = *fig;
    if (fig->snapshots < 0)
        c->fig.snapshots = snapshots;
    if (fig->elapsed < 0)
        c->fig.elapsed = elapsed;
    pthread_mutex_unlock(&c->lock);
}

void case_set_snapshots(server_case *c, int snapshots)
{
    pthread_mutex_lock(&c->lock);
    c->fig.snapshots = snapshots;
    pthread_mutex_unlock(&c->lock);
}

/* Figures straight from the model, for cases no worker is stepping. */
void case_publish_from_model(server_case *c)
{
    if (!c->model)
        return;
    case_figures fig;
    status_figures_of_model(&fig, c->model, &c->info);
    case_publish(c, &fig);
}

void case_mark_ended_locked(server_case *c, case_state state)
{
    if (case_state_is_terminal(state) && !c->finished_at[0])
        status_time_now(c->finished_at, sizeof c->finished_at);
}

static double case_progress(case_state state, double time, double end)
{
    return status_progress(state == CASE_FINISHED, time, end);
}

static double case_steps_per_second(case_state state, const case_figures *f)
{
    return status_steps_per_second(state == CASE_RUNNING, f);
}

static json_t *json_string_or_null(const char *s)
{
    return s[0] ? json_string(s) : json_null();
}

json_t *case_status_json(server_case *c)
{
    pthread_mutex_lock(&c->lock);
    case_state state = c->state;
    case_figures f = c->fig;
    char error[sizeof c->error], started[sizeof c->started], finished_at[sizeof c->finished_at];
    memcpy(error, c->error, sizeof error);
    memcpy(started, c->started, sizeof started);
    memcpy(finished_at, c->finished_at, sizeof finished_at);
    double estimated_seconds = c->estimated_seconds;
    pthread_mutex_unlock(&c->lock);

    double end = c->info.end_time;
    json_t *o = json_object();
    json_object_set_new(o, "id", json_string(c->id));
    json_object_set_new(o, "name", json_string(c->info.name));
    json_object_set_new(o, "state", json_string(case_state_name(state)));
    status_put_figures(o, &f, end, case_progress(state, f.time, end),
                       case_steps_per_second(state, &f));
    json_object_set_new(o, "ranks", json_integer(c->info.ranks > 1 ? c->info.ranks : 1));
    json_object_set_new(o, "error", error[0] ? json_string(error) : json_null());
    json_object_set_new(o, "created", json_string(c->created));
    json_object_set_new(o, "started", json_string_or_null(started));
    json_object_set_new(o, "finished_at", json_string_or_null(finished_at));
    json_object_set_new(o, "elapsed", status_number_or_null(f.elapsed > 0 ? f.elapsed : 0.0));
    json_object_set_new(o, "estimated_seconds", status_number_or_null(estimated_seconds));
    json_object_set_new(o, "eta", status_number_or_null(state == CASE_RUNNING ? f.eta : NAN));
    json_object_set_new(o, "cpu_share",
                        status_number_or_null(state == CASE_RUNNING ? f.cpu_share : NAN));
    json_object_set_new(o, "warnings", case_warnings_json(c));
    return o;
}

void case_record_io_failure(server_case *c, const char *file, const char *reason)
{
    pthread_mutex_lock(&c->lock);
    if (!c->io_error[0])
        snprintf(c->io_error, sizeof c->io_error,
                 "writing %s failed: %s; the results up to the last snapshot reported are kept",
                 file, reason);
    pthread_mutex_unlock(&c->lock);
    atomic_store(&c->io_failed, 1);
    fprintf(stderr, "fdemd: case %s: writing %s failed: %s\n", c->id, file, reason);
}

/* Writes `o` (consumed) as status.json; on a full disk the case's reserve
 * is given up once so that at least this state becomes durable. */
int case_write_status_json(server_case *c, json_t *o, char *reason, size_t reason_size)
{
    char *text = o ? json_dumps(o, JSON_COMPACT) : NULL;
    json_decref(o);
    int rc = -1;
    if (!text) {
        snprintf(reason, reason_size, "out of memory");
        return -1;
    }
    rc = persist_write_atomic(c->dir, "status.json", text, strlen(text));
    int saved = errno;
    if (rc != 0 && (saved == ENOSPC || saved == EDQUOT) && persist_release_reserve(c->dir) == 0) {
        rc = persist_write_atomic(c->dir, "status.json", text, strlen(text));
        saved = errno;
    }
    if (rc != 0)
        snprintf(reason, reason_size, "%s", strerror(saved));
    free(text);
    return rc;
}

/* The status object with `state` (and, when failed, `error`) as they are
 * about to become; used to make a state durable before it is shown. */
json_t *case_status_json_as(server_case *c, case_state state, const char *error)
{
    json_t *o = case_status_json(c);
    if (!o)
        return NULL;
    json_object_set_new(o, "state", json_string(case_state_name(state)));
    if (error && error[0])
        json_object_set_new(o, "error", json_string(error));
    pthread_mutex_lock(&c->lock);
    case_figures f = c->fig;
    double end = c->info.end_time;
    pthread_mutex_unlock(&c->lock);
    json_object_set_new(o, "progress", json_real(case_progress(state, f.time, end)));
    json_object_set_new(o, "steps_per_second", json_real(case_steps_per_second(state, &f)));
    return o;
}

/* A status.json that cannot be written is a storage fault like any other:
 * a case no worker is stepping becomes failed at once (and we try to make
 * that durable), a running one is ended by its worker. */
static void case_status_write_failed(server_case *c, const char *reason)
{
    case_record_io_failure(c, "status.json", reason);
    pthread_mutex_lock(&c->lock);
    int idle = !c->worker_active && !case_state_is_terminal(c->state);
    if (idle) {
        c->state = CASE_FAILED;
        snprintf(c->error, sizeof c->error, "%s", c->io_error);
        case_mark_ended_locked(c, CASE_FAILED);
    }
    pthread_mutex_unlock(&c->lock);
    char again[128];
    if (idle) {
        case_write_status_json(c, case_status_json(c), again, sizeof again);
        case_feed_status(c);
    }
}

int case_persist_status(server_case *c)
{
    return case_persist_status_counting(c, -1);
}

/* Writes status object o (consumed) as the case's status.json under its
 * persist lock; a failed write is recorded on the case. */
static int case_status_store(server_case *c, json_t *o)
{
    char reason[128] = "";
    pthread_mutex_lock(&c->persist_lock);
    int rc = case_write_status_json(c, o, reason, sizeof reason);
    pthread_mutex_unlock(&c->persist_lock);
    if (rc != 0)
        case_status_write_failed(c, reason);
    return rc;
}

int case_persist_status_counting(server_case *c, int snapshots)
{
    if (atomic_load(&c->deleted))
        return 0;
    json_t *o = case_status_json(c);
    if (o && snapshots >= 0)
        json_object_set_new(o, "snapshots", json_integer(snapshots));
    pthread_mutex_lock(&c->lock);
    int paused_by_shutdown = c->paused_by_shutdown;
    pthread_mutex_unlock(&c->lock);
    if (o && paused_by_shutdown)
        json_object_set_new(o, "paused_by_shutdown", json_true());
    return case_status_store(c, o);
}

int case_persist_status_as(server_case *c, case_state state, char *ended, size_t ended_size)
{
    json_t *o = case_status_json_as(c, state, NULL);
    ended[0] = '\0';
    if (case_state_is_terminal(state)) {
        pthread_mutex_lock(&c->lock);
        snprintf(ended, ended_size, "%s", c->finished_at);
        pthread_mutex_unlock(&c->lock);
        if (!ended[0])
            status_time_now(ended, ended_size);
        if (o)
            json_object_set_new(o, "finished_at", json_string(ended));
    }
    return case_status_store(c, o);
}

/* ------------------------------------------------------------- the log */

/* Copies `in` with every control character (C0, DEL, C1) written as
 * \xNN or \uNNNN: a log line is one line whatever text a user put into
 * it. Names are refused with control characters (case_check_name_text),
 * but names stored by an older daemon and messages quoting a document
 * still reach the log. */
static void case_log_escape(char *out, size_t size, const char *in)
{
    size_t n = 0;
    const unsigned char *u = (const unsigned char *)in;
    for (size_t i = 0; u[i] && n + 7 < size; i++) {
        if (u[i] == 0xC2 && u[i + 1] >= 0x80 && u[i + 1] <= 0x9F)
            n += (size_t)snprintf(out + n, size - n, "\\u%04X", u[++i]);
        else if (u[i] < 0x20 || u[i] == 0x7F || u[i] == '\\')
            n += (size_t)snprintf(out + n, size - n, "\\x%02X", u[i]);
        else
            out[n++] = (char)u[i];
    }
    out[n] = '\0';
}

void case_log(server_case *c, const char *fmt, ...)
{
    char line[1400], safe_line[1400], name[sizeof c->info.name * 4];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    case_log_escape(safe_line, sizeof safe_line, line);
    case_log_escape(name, sizeof name, c->info.name);
    /* One fprintf per line: lines of concurrent cases never interleave. */
    fprintf(stderr, "fdemd: case %s \"%s\": %s\n", c->id, name, safe_line);
}

void case_log_state(server_case *c, case_state state)
{
    pthread_mutex_lock(&c->lock);
    case_figures f = c->fig;
    char error[sizeof c->error];
    memcpy(error, c->error, sizeof error);
    pthread_mutex_unlock(&c->lock);
    double rate = f.elapsed > 0 ? (double)f.step / f.elapsed : 0.0;
    switch (state) {
    case CASE_FAILED:
        case_log(c, "failed at step %lld (t = %.6g s) after %.3f s: %s", (long long)f.step, f.time,
                 f.elapsed, error[0] ? error : "no reason recorded");
        break;
    case CASE_PAUSED: case CASE_STOPPED: case CASE_FINISHED:
        case_log(c, "%s at step %lld (t = %.6g of %.6g s): %d snapshots, %.3f s stepping, "
                 "%.4g steps/s", case_state_name(state), (long long)f.step, f.time,
                 c->info.end_time, f.snapshots, f.elapsed, rate);
        break;
    default: /* a queued case whose model found no memory goes back */
        case_log(c, "back to %s at step %lld (t = %.6g s)", case_state_name(state),
                 (long long)f.step, f.time);
        break;
    }
}
