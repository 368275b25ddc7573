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
#include "store/persist.h"
#include "registry.h"
#include "registry_internal.h"

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

void case_figures_stage(case_figures *fig, const fdem_model *model, const case_info *info)
{
    fig->stage = fdem_stage_index(model);
    const char *name = case_stage_name(info, fig->stage);
    snprintf(fig->stage_name, sizeof fig->stage_name, "%s", name ? name : "");
}

/* Figures straight from the model, for cases no worker is stepping. */
void case_publish_from_model(server_case *c)
{
    if (!c->model)
        return;
    case_figures fig;
    memset(&fig, 0, sizeof fig);
    fig.step = fdem_get_step(c->model);
    fig.time = fdem_get_time(c->model);
    fig.dt = fdem_get_dt(c->model);
    fig.counts = fdem_get_counts(c->model);
    fig.energy = fdem_get_energy(c->model);
    fig.fluid = fdem_get_fluid(c->model);
    fig.snapshots = -1;
    fig.elapsed = -1;
    fig.eta = NAN;
    case_figures_stage(&fig, c->model, &c->info);
    case_publish(c, &fig);
}

/* JSON has no NaN or infinity; a failed case may hold them. */
static json_t *json_number_or_null(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

/* The status' energy object, member by member (contract 5.1): written by
 * case_status_json, read back from status.json by case_load_figures. */
static const struct { const char *key; size_t offset; } energy_accounts[] = {
    {"kinetic", offsetof(fdem_energy, kinetic)}, {"elastic", offsetof(fdem_energy, elastic)},
    {"joint", offsetof(fdem_energy, joint)}, {"contact", offsetof(fdem_energy, contact)},
    {"friction", offsetof(fdem_energy, friction)}, {"fracture", offsetof(fdem_energy, fracture)},
    {"damping", offsetof(fdem_energy, damping)},
    {"gravity_work", offsetof(fdem_energy, gravity_work)},
    {"external_work", offsetof(fdem_energy, external_work)},
    {"excavated", offsetof(fdem_energy, excavated)},
    {"residual", offsetof(fdem_energy, residual)},
};
#define ENERGY_ACCOUNT_COUNT (sizeof energy_accounts / sizeof energy_accounts[0])

void case_energy_from_json(fdem_energy *energy, const json_t *o)
{
    for (size_t i = 0; i < ENERGY_ACCOUNT_COUNT; i++) {
        const json_t *v = json_object_get(o, energy_accounts[i].key);
        /* a status.json from before stages has no "excavated": nothing was */
        double missing = strcmp(energy_accounts[i].key, "excavated") == 0 && o && !v ? 0.0 : NAN;
        *(double *)((char *)energy + energy_accounts[i].offset) =
            json_is_number(v) ? json_number_value(v) : missing;
    }
}

void case_mark_ended_locked(server_case *c, case_state state)
{
    if (case_state_is_terminal(state) && !c->finished_at[0])
        iso_time_now(c->finished_at, sizeof c->finished_at);
}

/* Progress 1 means finished: a case that has stepped to its end but is
 * still writing its last snapshot (or was stopped there) shows just under
 * it, so no client prints "running 100 %". */
#define CASE_PROGRESS_UNFINISHED_MAX 0.999

static double case_progress(case_state state, double time, double end)
{
    if (state == CASE_FINISHED)
        return 1.0;
    double progress = end > 0 ? time / end : 0.0;
    if (!(progress >= 0))
        progress = 0;
    return progress > CASE_PROGRESS_UNFINISHED_MAX ? CASE_PROGRESS_UNFINISHED_MAX : progress;
}

/* A running case shows its current speed; any other the mean over every
 * step it took (step / elapsed), so a finished case does not show 0. */
static double case_steps_per_second(case_state state, const case_figures *f)
{
    if (state == CASE_RUNNING)
        return f->steps_per_second;
    return f->elapsed > 0 ? (double)f->step / f->elapsed : 0.0;
}

static json_t *json_string_or_null(const char *s)
{
    return s[0] ? json_string(s) : json_null();
}

/* "stage": {"index", "name"} of a case with stages (contract 6.1), null
 * without them. Written to status.json too: a case loaded from it shows
 * its last stage without a model (case_stage_from_json). */
static json_t *case_stage_json(const case_figures *f)
{
    if (f->stage < 0) return json_null();
    json_t *o = json_object();
    if (!o) return NULL;
    json_object_set_new(o, "index", json_integer(f->stage));
    json_object_set_new(o, "name", json_string(f->stage_name));
    return o;
}

void case_stage_from_json(case_figures *f, const json_t *stage)
{
    const json_t *given = json_object_get(stage, "index");
    json_int_t index = json_integer_value(given);
    const char *name = json_string_value(json_object_get(stage, "name"));
    f->stage = json_is_integer(given) && index >= 0 && index < CASE_MAX_STAGES ? (int)index : -1;
    snprintf(f->stage_name, sizeof f->stage_name, "%s", f->stage >= 0 && name ? name : "");
}

/* "fluid" (contract 6.4): null without fluid; the flow's step and subcycle
 * count beside the contract's three (docs/api.md). */
static json_t *case_fluid_json(const fdem_fluid_status *f)
{
    if (!f->enabled) return json_null();
    json_t *o = json_object();
    if (!o) return NULL;
    json_object_set_new(o, "injected_volume", json_number_or_null(f->injected_volume));
    json_object_set_new(o, "stored_volume", json_number_or_null(f->stored_volume));
    json_object_set_new(o, "source_pressure", json_number_or_null(f->source_pressure));
    json_object_set_new(o, "fluid_step", json_number_or_null(f->flow_step));
    json_object_set_new(o, "fluid_subcycles", json_integer(f->subcycles));
    json_object_set_new(o, "open_joints", json_integer(f->open_joints));
    return o;
}

/* Read back by case_load_figures: a case loaded from status.json shows its
 * fluid (and writes it again) without a model. */
void case_fluid_from_json(case_figures *f, const json_t *fluid, const json_t *energy)
{
    memset(&f->fluid, 0, sizeof f->fluid);
    if (!json_is_object(fluid)) return;
    static const struct { const char *key; size_t offset; } figures[] = {
        {"injected_volume", offsetof(fdem_fluid_status, injected_volume)},
        {"stored_volume", offsetof(fdem_fluid_status, stored_volume)},
        {"source_pressure", offsetof(fdem_fluid_status, source_pressure)},
        {"fluid_step", offsetof(fdem_fluid_status, flow_step)},
    };
    f->fluid.enabled = 1;
    for (size_t i = 0; i < sizeof figures / sizeof figures[0]; i++) {
        const json_t *v = json_object_get(fluid, figures[i].key);
        *(double *)((char *)&f->fluid + figures[i].offset) =
            json_is_number(v) ? json_number_value(v) : NAN;
    }
    f->fluid.subcycles = (int)json_integer_value(json_object_get(fluid, "fluid_subcycles"));
    f->fluid.open_joints = (int)json_integer_value(json_object_get(fluid, "open_joints"));
    const json_t *work = json_object_get(energy, "fluid_work");
    const json_t *dissipation = json_object_get(energy, "fluid_dissipation");
    f->energy.fluid_work = json_is_number(work) ? json_number_value(work) : NAN;
    f->energy.fluid_dissipation =
        json_is_number(dissipation) ? json_number_value(dissipation) : NAN;
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
    double progress = case_progress(state, f.time, end);
    json_t *energy = json_object();
    for (size_t i = 0; i < ENERGY_ACCOUNT_COUNT; i++)
        json_object_set_new(energy, energy_accounts[i].key,
                            json_number_or_null(*(const double *)((const char *)&f.energy +
                                                                  energy_accounts[i].offset)));
    if (energy && f.fluid.enabled) {
        json_object_set_new(energy, "fluid_work", json_number_or_null(f.energy.fluid_work));
        json_object_set_new(energy, "fluid_dissipation",
                            json_number_or_null(f.energy.fluid_dissipation));
    }
    json_t *o = json_object();
    json_object_set_new(o, "id", json_string(c->id));
    json_object_set_new(o, "name", json_string(c->info.name));
    json_object_set_new(o, "state", json_string(case_state_name(state)));
    json_object_set_new(o, "step", json_integer((json_int_t)f.step));
    json_object_set_new(o, "time", json_number_or_null(f.time));
    json_object_set_new(o, "end_time", json_number_or_null(end));
    json_object_set_new(o, "progress", json_number_or_null(progress));
    json_object_set_new(o, "dt", json_number_or_null(f.dt));
    json_object_set_new(o, "dimension", json_integer(f.counts.dimension ? f.counts.dimension : 2));
    json_object_set_new(o, "nodes", json_integer(f.counts.nodes));
    json_object_set_new(o, "elements", json_integer(f.counts.elements));
    json_object_set_new(o, "joints", json_integer(f.counts.joints));
    json_object_set_new(o, "broken_joints", json_integer(f.counts.broken_joints));
    json_object_set_new(o, "fragments", json_integer(f.counts.fragments));
    json_object_set_new(o, "contacts", json_integer(f.counts.contacts));
    json_object_set_new(o, "stage", case_stage_json(&f));
    json_object_set_new(o, "fluid", case_fluid_json(&f.fluid));
    json_object_set_new(o, "snapshots", json_integer(f.snapshots));
    json_object_set_new(o, "energy", energy ? energy : json_null());
    json_object_set_new(o, "steps_per_second",
                        json_number_or_null(case_steps_per_second(state, &f)));
    json_object_set_new(o, "error", error[0] ? json_string(error) : json_null());
    json_object_set_new(o, "created", json_string(c->created));
    json_object_set_new(o, "started", json_string_or_null(started));
    json_object_set_new(o, "finished_at", json_string_or_null(finished_at));
    json_object_set_new(o, "elapsed", json_number_or_null(f.elapsed > 0 ? f.elapsed : 0.0));
    json_object_set_new(o, "estimated_seconds", json_number_or_null(estimated_seconds));
    json_object_set_new(o, "eta", json_number_or_null(state == CASE_RUNNING ? f.eta : NAN));
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
            iso_time_now(ended, ended_size);
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
