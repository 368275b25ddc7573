/*
 * case_continue.c - extend and clone (case_continue.h): the two ways a case
 * goes on past what its document first said.
 *
 * An extended case keeps its files: its document is rewritten with the
 * new end (case.json, and the copy inside result.h5, so GET /case and the
 * file's `case` attribute agree and a restart rebuilds it with the new
 * end), and its next start appends to result.h5. A finished case resumes
 * from the state one step before its old end (CASE_RESUME_CHECKPOINT, see
 * case_model.h), not from the end: the last step of a run is cut to land
 * on time.end, and going on from there would put every later step off the
 * grid of an uninterrupted run. So the continued run is bit for bit the
 * run that was asked for the new end from the start, and the row of the
 * old end stays in the file as it was.
 */
#include "case_continue.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "case_feed.h"
#include "case_model.h"
#include "store/fault_point.h"
#include "io_thread.h"
#include "json/json_patch.h"
#include "common/memory_budget.h"
#include "files/persist.h"
#include "registry_internal.h"

/* ---------------------------------------------------------------- reading */

static json_t *continue_parse(const char *body, size_t size, size_t flags, problems *p)
{
    json_error_t e;
    json_t *root = json_loadb(body, size, JSON_REJECT_DUPLICATES | flags, &e);
    if (!root) {
        snprintf(p->title, sizeof p->title, "Malformed JSON");
        problems_add(p, 400, "", "line %d, column %d: %s", e.line, e.column, e.text);
    }
    return root;
}

/* The new end of {"end": t}: 0, or 400/422 with the problems in p. */
static int continue_read_end(const char *body, size_t size, double *end, problems *p)
{
    json_t *root = continue_parse(body, size, 0, p);
    if (!root)
        return 400;
    snprintf(p->title, sizeof p->title, "Invalid extend request");
    if (!json_is_object(root)) {
        problems_add(p, 422, "", "the body must be an object {\"end\": seconds}");
        json_decref(root);
        return 422;
    }
    const char *key;
    json_t *v;
    json_object_foreach(root, key, v) {
        if (strcmp(key, "end") != 0) {
            char pointer[256];
            pointer_join(pointer, sizeof pointer, "", key);
            problems_add(p, 422, pointer, "unknown member \"%.64s\"; extend takes {\"end\": seconds}",
                         key);
        }
    }
    v = json_object_get(root, "end");
    if (!v)
        problems_add(p, 422, "/end", "missing required \"end\" (the new end time in seconds)");
    else if (!json_is_number(v))
        problems_add(p, 422, "/end", "end must be a number of seconds");
    else if (!isfinite(*end = json_number_value(v)))
        problems_add(p, 422, "/end", "end must be finite");
    json_decref(root);
    return p->count ? 422 : 0;
}

/* The stored document of `c` as a tree, or NULL with err. */
static json_t *continue_load_document(server_case *c, char *err, size_t errlen)
{
    char path[1200], *text = NULL;
    size_t size = 0;
    snprintf(path, sizeof path, "%s/case.json", c->dir);
    if (persist_read_file(path, &text, &size, CASE_MODEL_MAX_DOCUMENT) != 0) {
        snprintf(err, errlen, "the stored case.json could not be read: %s", strerror(errno));
        return NULL;
    }
    json_t *doc = json_loadb(text, size, JSON_REJECT_DUPLICATES, NULL);
    free(text);
    if (!doc)
        snprintf(err, errlen, "the stored case.json is not JSON");
    return doc;
}

/* ---------------------------------------------------------------- extend */

/* 0 when `c` may be extended now; 404, or 409 with a sentence. */
static int continue_extendable(server_case *c, case_state *was, char *msg, size_t msglen)
{
    pthread_mutex_lock(&c->lock);
    int status = 0;
    *was = c->state;
    if (atomic_load(&c->deleted)) {
        status = 404;
    } else if (c->state != CASE_FINISHED && c->state != CASE_PAUSED) {
        snprintf(msg, msglen, "the case is %s; extend is allowed only when it is finished or "
                 "paused%s", case_state_name(c->state),
                 c->state == CASE_RUNNING || c->state == CASE_QUEUED ? " (pause it first)" : "");
        status = 409;
    } else if (c->worker_active) {
        snprintf(msg, msglen, "the case is still winding down its last step; try again");
        status = 409;
    }
    pthread_mutex_unlock(&c->lock);
    return status;
}

/* The last entry of a case's "stages" (contract 6.1), or NULL. */
static json_t *continue_last_stage(json_t *doc)
{
    json_t *stages = json_object_get(doc, "stages");
    size_t n = json_array_size(stages);
    json_t *last = n ? json_array_get(stages, n - 1) : NULL;
    return json_is_object(last) ? last : NULL;
}

/* The end a stored document says: time.end, or its last stage's end when
 * it leaves time.end out; 0 when it says none. */
static double continue_document_end(json_t *doc)
{
    json_t *time_end = json_object_get(json_object_get(doc, "time"), "end");
    return json_number_value(time_end ? time_end : json_object_get(continue_last_stage(doc), "end"));
}

/* `doc` with time.end = end, and output.interval pinned when it was left
 * to its default. A case with stages ends with its last stage, which
 * time.end may leave out and must agree with: that stage's end becomes
 * the new end too (its last stage runs on; the engine puts the steps
 * after a last stage's end in it). 0, or 409/422/500 with msg (422 also
 * in p). */
static int continue_set_end(json_t *doc, double end, problems *p, char *msg, size_t msglen)
{
    json_t *time = json_object_get(doc, "time");
    json_t *last = continue_last_stage(doc);
    json_t *time_end = json_object_get(time, "end");
    double old_end = continue_document_end(doc);
    if (!(old_end > 0)) {
        snprintf(msg, msglen, "the stored case.json has no time.end");
        return 500;
    }
    if (!(end > old_end)) {
        char new_text[40], old_text[40];
        format_shortest_real(new_text, sizeof new_text, end);
        format_shortest_real(old_text, sizeof old_text, old_end);
        snprintf(msg, msglen, "the new end %s s is not beyond the current end %s s", new_text,
                 old_text);
        return 409;
    }
    json_t *output = json_object_get(doc, "output");
    if (!output) {
        output = json_object();
        json_object_set_new(doc, "output", output);
    }
    if (!json_is_object(output)) {
        snprintf(msg, msglen, "the stored case.json has an output that is not an object");
        return 500;
    }
    json_t *given = json_object_get(output, "interval");
    double interval = json_is_number(given) ? json_number_value(given)
                                            : old_end / CASE_DEFAULT_SNAPSHOTS;
    if (end / interval > CASE_MAX_SNAPSHOTS) {
        snprintf(p->title, sizeof p->title, "Invalid extend request");
        problems_add(p, 422, "/end", "an end of %g s at the output interval of %g s would write "
                     "%.3g snapshots; the limit is %.0f", end, interval, end / interval,
                     CASE_MAX_SNAPSHOTS);
        return 422;
    }
    if ((!given && json_object_set_new(output, "interval", json_real(interval)) != 0) ||
        (time_end && json_object_set_new(time, "end", json_real(end)) != 0) ||
        (last && json_object_set_new(last, "end", json_real(end)) != 0)) {
        snprintf(msg, msglen, "out of memory rewriting the case document");
        return 500;
    }
    return 0;
}

/* An extended finished case goes on from the step before its old end. */
static int continue_keep_resume_point(server_case *c, char *msg, size_t msglen)
{
    char from[1200], to[1200];
    snprintf(from, sizeof from, "%s/%s", c->dir, CASE_END_CHECKPOINT);
    snprintf(to, sizeof to, "%s/%s", c->dir, CASE_RESUME_CHECKPOINT);
    if (rename(from, to) != 0 && errno != ENOENT) {
        snprintf(msg, msglen, "cannot keep %s: %s", CASE_END_CHECKPOINT, strerror(errno));
        return -1;
    }
    persist_fsync_dir(c->dir);
    return 0;
}

/* The extend's one durable record (case_continue.h), written before any of
 * its files changes: from then on the extend is carried out, now or, after
 * a crash between its writes, at the next start-up. */
#define STAGES_INTENT "extend.json"

static int continue_write_intent(server_case *c, double end, char *msg, size_t msglen)
{
    json_t *o = json_pack("{s:f}", "end", end);
    char *text = o ? json_dumps(o, JSON_COMPACT) : NULL;
    json_decref(o);
    int rc = text ? persist_write_atomic(c->dir, STAGES_INTENT, text, strlen(text)) : -1;
    if (rc != 0)
        snprintf(msg, msglen, "cannot store %s: %s", STAGES_INTENT,
                 text ? strerror(errno) : "out of memory");
    free(text);
    return rc;
}

/* 1 with the end of an extend begun and not completed, else 0. */
static int continue_read_intent(server_case *c, double *end)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", c->dir, STAGES_INTENT);
    json_t *o = json_load_file(path, JSON_REJECT_DUPLICATES, NULL);
    const json_t *v = json_object_get(o, "end");
    int found = json_is_number(v) && isfinite(json_number_value(v));
    if (found)
        *end = json_number_value(v);
    json_decref(o);
    return found;
}

static void continue_drop_intent(server_case *c)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", c->dir, STAGES_INTENT);
    if (unlink(path) == 0)
        persist_fsync_dir(c->dir);
}

/* Rewrites the stored files for the new end; 0 or an HTTP status. `redo`:
 * completing an extend whose record is already stored, so a case.json that
 * already says `end` is left as it is and every step may be one a crash
 * had already done. */
static int continue_store_extension(server_case *c, double end, case_state was, int redo,
                                  problems *p, char *msg, size_t msglen)
{
    json_t *doc = continue_load_document(c, msg, msglen);
    if (!doc)
        return 500;
    double stored_end = continue_document_end(doc);
    int stored = redo && stored_end >= end;
    int status = stored ? 0 : continue_set_end(doc, end, p, msg, msglen);
    size_t length = 0;
    char *text = status == 0 ? json_dump_document(doc, &length) : NULL;
    json_decref(doc);
    if (status != 0)
        return status;
    char err[600] = "";
    if (!text) {
        snprintf(msg, msglen, "out of memory writing the case document");
        return 500;
    }
    status = 500;
    if (!redo && continue_write_intent(c, end, msg, msglen) != 0)
        goto done;
    fault_point("extend:intent");
    if (!stored && persist_write_atomic(c->dir, "case.json", text, length) != 0) {
        snprintf(msg, msglen, "cannot store case.json: %s", strerror(errno));
        goto done;
    }
    fault_point("extend:case.json");
    if (io_replace_document(c, text, length, err, sizeof err) != 0) {
        /* Not a storage fault of a run (case_record_io_failure would fail
         * the case's next start): the record stays, and the next extend
         * or start-up completes it. */
        snprintf(msg, msglen, "case.json has the new end, but result.h5 could not take it: %s; "
                 "the extend is completed by the next extend of this case or at the daemon's "
                 "next start", err);
        fprintf(stderr, "fdemd: case %s: %s\n", c->id, msg);
        goto done;
    }
    fault_point("extend:result.h5");
    if (was == CASE_FINISHED && continue_keep_resume_point(c, msg, msglen) != 0)
        goto done;
    fault_point("extend:resume-point");
    status = 0;
done:
    free(text);
    return status;
}

/* The case shows paused with the new end; once status.json says so the
 * record goes. A failed status write leaves the record for a restart. */
static void continue_settle(server_case *c, double end)
{
    pthread_mutex_lock(&c->lock);
    /* the run's estimate, for the longer run: at the same pace per
     * simulated second (the sizing priced the whole run, not a phase) */
    if (c->info.end_time > 0)
        c->estimated_seconds *= end / c->info.end_time;
    c->info.end_time = end;
    c->state = CASE_PAUSED;
    c->finished_at[0] = '\0';
    pthread_mutex_unlock(&c->lock);
    int stored = case_persist_status(c) == 0;
    case_feed_status(c);
    if (!stored)
        return;
    fault_point("extend:status.json");
    continue_drop_intent(c);
}

/* Completes an extend whose record is stored (cut short by a crash, or by
 * a failed write of an earlier request); 0, 1 when there is none, or an
 * HTTP status with msg. */
static int continue_complete_stored(server_case *c, double *end, char *msg, size_t msglen)
{
    if (!continue_read_intent(c, end))
        return 1;
    problems p;
    problems_init(&p);
    pthread_mutex_lock(&c->lock);
    case_state was = c->state;
    pthread_mutex_unlock(&c->lock);
    int status = continue_store_extension(c, *end, was, 1, &p, msg, msglen);
    if (status == 0) {
        continue_settle(c, *end);
        case_log(c, "completed an extend to end = %.6g s that was cut short (was %s); now "
                 "paused", *end, case_state_name(was));
    } else if (p.count) {
        status = 500; /* the record holds an end the document refuses */
        snprintf(msg, msglen, "%s", p.items[0].message);
    }
    problems_free(&p);
    return status;
}

void registry_extend_recover(server_case *c)
{
    double end = 0;
    char msg[640] = "";
    if (c->state != CASE_FINISHED && c->state != CASE_PAUSED)
        return; /* a case failed at loading keeps its files as found */
    int status = continue_complete_stored(c, &end, msg, sizeof msg);
    if (status > 1)
        fprintf(stderr, "fdemd: case %s: an extend to end = %.6g s cut short by a crash could "
                "not be completed: %s; %s is kept for the next start-up\n", c->id, end, msg,
                STAGES_INTENT);
}

int registry_extend(server_case *c, const char *body, size_t size, problems *p, char *msg,
                    size_t msglen)
{
    double end = 0, stored_end = 0;
    int status = continue_read_end(body, size, &end, p);
    if (status != 0)
        return status;
    pthread_mutex_lock(&c->ctl_lock);
    case_state was;
    double old_end = c->info.end_time;
    status = continue_extendable(c, &was, msg, msglen);
    if (status == 0) {
        /* An earlier request that failed half way is completed first: a
         * repeat of it is then answered as it would have been. */
        int left = continue_complete_stored(c, &stored_end, msg, msglen);
        if (left == 0 && stored_end == end) {
            pthread_mutex_unlock(&c->ctl_lock);
            return 0;
        }
        status = left == 1 ? 0 : left;
        if (left == 0)
            status = continue_extendable(c, &was, msg, msglen);
    }
    if (status == 0)
        status = continue_store_extension(c, end, was, 0, p, msg, msglen);
    if (status == 0) {
        continue_settle(c, end);
        case_log(c, "extended from end = %.6g s to %.6g s (was %s); now paused, start it to go on",
                 old_end, end, case_state_name(was));
    }
    pthread_mutex_unlock(&c->ctl_lock);
    return status;
}

/* ----------------------------------------------------------------- clone */

/* 0 when `patch` has the form its content type asks for; else 422 in p. */
static int continue_check_patch_form(const json_t *patch, int json_patch, problems *p)
{
    if (json_patch ? json_is_array(patch) : json_is_object(patch))
        return 0;
    /* RFC 7396 would let a number or null replace the whole document, which
     * can never be a case; it is valid JSON, so not "Malformed JSON" but a
     * 422 that says what a patch must be. */
    const char *kind = json_is_null(patch) ? "null" : json_is_array(patch) ? "an array"
                     : json_is_object(patch) ? "an object" : json_is_string(patch) ? "a string"
                     : json_is_boolean(patch) ? "a boolean" : "a number";
    snprintf(p->title, sizeof p->title, "Invalid patch");
    if (json_patch)
        problems_add(p, 422, "", "a clone's body with Content-Type application/json-patch+json "
                     "is a JSON Patch (RFC 6902), an array of operations (e.g. [{\"op\": "
                     "\"replace\", \"path\": \"/name\", \"value\": \"copy\"}]), not %s", kind);
    else
        problems_add(p, 422, "", "a clone's body is a JSON Merge Patch of the case document, "
                     "which must be an object (e.g. {\"name\": \"copy\"}), not %s%s", kind,
                     json_is_array(patch) ? "; send a JSON Patch (RFC 6902) array with "
                     "Content-Type: application/json-patch+json" : "");
    return 422;
}

static char *continue_clone_document(server_case *c, const char *body, size_t size, int json_patch,
                                   size_t *length, problems *p, int *status, char *err,
                                   size_t errlen)
{
    json_t *patch = continue_parse(body, size, JSON_DECODE_ANY, p);
    if (!patch) {
        *status = 400;
        return NULL;
    }
    if ((*status = continue_check_patch_form(patch, json_patch, p)) != 0) {
        json_decref(patch);
        return NULL;
    }
    *status = 500;
    json_t *doc = NULL;
    if (atomic_load(&c->deleted))
        *status = 404;
    else
        doc = continue_load_document(c, err, errlen);
    if (json_patch)
        snprintf(p->title, sizeof p->title, "Invalid patch");
    json_t *patched = !doc ? NULL : json_patch ? json_patch_apply(doc, patch, p)
                                               : json_merge_patch(doc, patch);
    if (doc && !patched && p->count)
        *status = 422; /* an operation failed (json_patch.h): nothing is created */
    char *text = patched ? json_dump_document(patched, length) : NULL;
    if (doc && !text && *status == 500)
        snprintf(err, errlen, "out of memory patching the case document");
    json_decref(patched);
    json_decref(doc);
    json_decref(patch);
    return text;
}

/* The patch's tree, the stored document's, their merge and its text can
 * be many times the patch (issue 30: a 1 MB patch became 1 GB), so all of
 * it is metered against the request's lease; 503 when the budget refuses. */
char *registry_clone_document(server_case *c, const char *body, size_t size, int json_patch,
                              size_t *length, problems *p, int *status, char *err, size_t errlen)
{
    membudget_lease own = {0};
    membudget_lease *lease = membudget_request_lease() ? membudget_request_lease() : &own;
    membudget_meter_begin(lease, lease->bytes);
    char *text = continue_clone_document(c, body, size, json_patch, length, p, status, err,
                                       errlen);
    membudget_meter_end();
    if (!text && *status != 422 && membudget_meter_refused()) {
        *status = 503;
        snprintf(err, errlen, "patching the case document would take the daemon past its "
                 "memory budget (--max-memory) now; try again later");
    }
    membudget_release(&own);
    return text;
}
