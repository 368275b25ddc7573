/*
 * run_files.c - status.json, checkpoints and the stored document of a case
 * directory the batch runner writes (run_files.h). The bytes go through
 * the daemon's own writers (proto/files, proto/state/status_json), so the
 * daemon reads such a directory as one of its cases.
 */
#include "run_files.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <jansson.h>

#include "files/checkpoint_file.h"
#include "files/persist.h"

#define RUN_MAX_CHECKPOINT ((size_t)1 << 40)

static json_t *string_or_null(const char *s)
{
    return s && s[0] ? json_string(s) : json_null();
}

/* The case's id is its directory's name (a daemon lists DIR/<16 hex>). */
static const char *dir_name(const char *dir, char *name, size_t size)
{
    const char *end = dir + strlen(dir);
    while (end > dir && end[-1] == '/')
        end--;
    const char *start = end;
    while (start > dir && start[-1] != '/')
        start--;
    snprintf(name, size, "%.*s", (int)(end - start), start);
    return name;
}

int run_status_write(const char *dir, const case_info *info, const run_figures *f,
                     const run_status *s, char *err, size_t errlen)
{
    int finished = strcmp(s->state, "finished") == 0, running = strcmp(s->state, "running") == 0;
    char id[256];
    json_t *o = json_object();
    if (!o) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    json_object_set_new(o, "id", json_string(dir_name(dir, id, sizeof id)));
    json_object_set_new(o, "name", json_string(info->name));
    json_object_set_new(o, "state", json_string(s->state));
    status_put_figures(o, f, info->end_time, status_progress(finished, f->time, info->end_time),
                       status_steps_per_second(running, f));
    json_object_set_new(o, "ranks", json_integer(s->ranks > 0 ? s->ranks : 1));
    json_object_set_new(o, "error", string_or_null(s->error));
    json_object_set_new(o, "created", json_string(s->created));
    json_object_set_new(o, "started", string_or_null(s->started));
    json_object_set_new(o, "finished_at", string_or_null(s->finished_at));
    json_object_set_new(o, "elapsed", status_number_or_null(f->elapsed > 0 ? f->elapsed : 0.0));
    json_object_set_new(o, "estimated_seconds", json_null());
    json_object_set_new(o, "eta", status_number_or_null(running ? s->eta : NAN));
    json_object_set_new(o, "warnings", s->warnings ? json_deep_copy(s->warnings) : json_array());
    json_object_set_new(o, "runner", json_string("fdem-run"));
    char *text = json_dumps(o, JSON_COMPACT);
    json_decref(o);
    if (!text || persist_write_atomic(dir, "status.json", text, strlen(text)) != 0) {
        snprintf(err, errlen, "writing %.400s/status.json: %s", dir,
                 text ? strerror(errno) : "out of memory");
        free(text);
        return -1;
    }
    free(text);
    return 0;
}

void run_status_read_times(const char *dir, run_status *s, double *elapsed)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/status.json", dir);
    json_t *st = json_load_file(path, 0, NULL);
    if (!st)
        return;
    const char *created = json_string_value(json_object_get(st, "created"));
    const char *started = json_string_value(json_object_get(st, "started"));
    const json_t *e = json_object_get(st, "elapsed");
    if (created)
        snprintf(s->created, sizeof s->created, "%s", created);
    if (started)
        snprintf(s->started, sizeof s->started, "%s", started);
    if (json_is_number(e) && json_number_value(e) >= 0)
        *elapsed = json_number_value(e);
    size_t i;
    const json_t *w;
    json_array_foreach(json_object_get(st, "warnings"), i, w) {
        const char *pointer = json_string_value(json_object_get(w, "pointer"));
        const char *message = json_string_value(json_object_get(w, "message"));
        if (pointer && message)
            status_warning_add(s->warnings, pointer, message);
    }
    json_decref(st);
}

int run_checkpoint_write(const char *dir, const char *name, const fdem_model *m, char *err,
                         size_t errlen)
{
    size_t size = 0;
    void *bytes = checkpoint_file_take(m, &size);
    if (!bytes) {
        snprintf(err, errlen, "no memory for the checkpoint");
        return -1;
    }
    int rc = persist_write_atomic(dir, name, bytes, size);
    if (rc != 0)
        snprintf(err, errlen, "writing %.400s/%s: %s", dir, name, strerror(errno));
    free(bytes);
    return rc;
}

int run_checkpoint_restore(const char *dir, const char *name, fdem_model *m, char *err,
                           size_t errlen)
{
    char path[1200], *bytes = NULL;
    size_t size = 0, payload = 0;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (persist_read_file(path, &bytes, &size, RUN_MAX_CHECKPOINT) != 0) {
        snprintf(err, errlen, "%.400s could not be read: %s", path, strerror(errno));
        return -1;
    }
    char damage[256] = "";
    if (checkpoint_file_open(bytes, size, &payload, damage, sizeof damage) ==
        CHECKPOINT_FILE_DAMAGED) {
        snprintf(err, errlen, "%.400s could not be restored: %s", path, damage);
        free(bytes);
        return -1;
    }
    fdem_error e;
    memset(&e, 0, sizeof e);
    int rc = fdem_checkpoint_read(m, bytes, payload, &e);
    free(bytes);
    if (rc != 0)
        snprintf(err, errlen, "%.400s could not be restored: %.400s", path, e.message);
    return rc != 0 ? -1 : 0;
}

int run_has_file(const char *dir, const char *name)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return access(path, F_OK) == 0;
}

int run_dir_resumable(const char *dir)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/case.json", dir);
    if (access(path, R_OK) != 0)
        return 0;
    snprintf(path, sizeof path, "%s/%s", dir, CHECKPOINT_FILE_LATEST);
    return access(path, R_OK) == 0;
}
