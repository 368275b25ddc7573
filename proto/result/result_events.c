/*
 * result_events.c - the fracture events of result.h5 (contract 5.4):
 * /events/time (K) f64, /events/joint (K) i32, /events/position
 * (K, dimension) f64, /events/mode (K) i8, /events/energy (K) f64, one row
 * per joint that broke, in the order they broke.
 *
 * The discipline is /snapshots' (result_h5.c): the datasets are created
 * with the file, before SWMR writing starts (a SWMR writer cannot add
 * objects); an append extends every other dataset to the same absolute
 * length and flushes, then /events/time, the commit marker, grows and is
 * flushed. len(/events/time) is the number of complete events, and a
 * failed append is overwritten by the next because extents are absolute.
 * The daemon appends a step's events before the snapshot that follows
 * them, so a reader that sees a snapshot at time T sees every event with
 * time <= T.
 *
 * Reopening (result_reopen.c): a file written before events existed gets
 * the group, empty; of a file that has it, the events kept are the first
 * ones whose joints are broken in the model the run resumes from, so an
 * event written after that model's checkpoint (its joint will break again)
 * is dropped and no joint gets two.
 *
 * Not thread-safe: the daemon's I/O thread calls all of this.
 */
#include "result_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const event_series_names[EVENT_SERIES] = {"joint", "position", "mode", "energy",
                                                      "time"};

#define EVENT_CHUNK_ROWS 1024

static hid_t event_file_type(int kind)
{
    return kind == EVENT_JOINT ? H5T_STD_I32LE : kind == EVENT_MODE ? H5T_STD_I8LE
                                                                    : H5T_IEEE_F64LE;
}

static hid_t event_mem_type(int kind)
{
    return kind == EVENT_JOINT ? H5T_NATIVE_INT32 : kind == EVENT_MODE ? H5T_NATIVE_INT8
                                                                       : H5T_NATIVE_DOUBLE;
}

static int event_rank(int kind) { return kind == EVENT_POSITION ? 2 : 1; }

static int event_create(hid_t group, int kind, int dimension, hid_t *id)
{
    hsize_t dims[2] = {0, (hsize_t)dimension}, maxdims[2] = {H5S_UNLIMITED, (hsize_t)dimension};
    hsize_t chunk[2] = {EVENT_CHUNK_ROWS, (hsize_t)dimension};
    hid_t space = H5Screate_simple(event_rank(kind), dims, maxdims);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    *id = H5I_INVALID_HID;
    if (space >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, event_rank(kind), chunk) >= 0)
        *id = H5Dcreate2(group, event_series_names[kind], event_file_type(kind), space,
                         H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (dcpl >= 0) H5Pclose(dcpl);
    if (space >= 0) H5Sclose(space);
    return *id >= 0 ? 0 : -1;
}

int events_create(result_file *f, int dimension, char *err, size_t errlen)
{
    hid_t group = H5Gcreate2(f->file, "events", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (group < 0) {
        result_fail(err, errlen, "cannot create group /events");
        return -1;
    }
    int rc = 0;
    for (int k = 0; k < EVENT_SERIES && rc == 0; k++)
        if (event_create(group, k, dimension, &f->events[k]) < 0) {
            result_fail(err, errlen, "cannot create /events/%s", event_series_names[k]);
            rc = -1;
        }
    H5Gclose(group);
    f->event_dimension = dimension;
    return rc;
}

static hsize_t event_length(hid_t id)
{
    hsize_t dims[2] = {0, 0};
    hid_t space = H5Dget_space(id);
    if (space < 0) return 0;
    H5Sget_simple_extent_dims(space, dims, NULL);
    H5Sclose(space);
    return dims[0];
}

static int event_set_length(hid_t id, int kind, int dimension, hsize_t length)
{
    hsize_t dims[2] = {length, (hsize_t)dimension};
    (void)kind;
    return H5Dset_extent(id, dims) < 0 ? -1 : 0;
}

/* Rows [start, start + count) of one series to or from buf. */
static int event_rows(hid_t id, int kind, int dimension, hsize_t start, hsize_t count, void *buf,
                      int write)
{
    if (count == 0) return 0;
    hsize_t offset[2] = {start, 0}, extent[2] = {count, (hsize_t)dimension};
    hid_t file_space = H5Dget_space(id);
    hid_t mem_space = H5Screate_simple(event_rank(kind), extent, NULL);
    int rc = -1;
    if (file_space >= 0 && mem_space >= 0 &&
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, offset, NULL, extent, NULL) >= 0) {
        herr_t h = write ? H5Dwrite(id, event_mem_type(kind), mem_space, file_space, H5P_DEFAULT, buf)
                         : H5Dread(id, event_mem_type(kind), mem_space, file_space, H5P_DEFAULT, buf);
        rc = h < 0 ? -1 : 0;
    }
    if (mem_space >= 0) H5Sclose(mem_space);
    if (file_space >= 0) H5Sclose(file_space);
    return rc;
}

/* The columns of `count` events, as the datasets hold them. */
typedef struct event_columns {
    int32_t *joint;
    double *position, *energy, *time;
    int8_t *mode;
} event_columns;

static void columns_free(event_columns *c)
{
    free(c->joint);
    free(c->position);
    free(c->energy);
    free(c->time);
    free(c->mode);
}

static int columns_alloc(event_columns *c, size_t count, int dimension)
{
    size_t n = count ? count : 1;
    c->joint = malloc(n * sizeof *c->joint);
    c->position = malloc(n * (size_t)dimension * sizeof *c->position);
    c->energy = malloc(n * sizeof *c->energy);
    c->time = malloc(n * sizeof *c->time);
    c->mode = malloc(n * sizeof *c->mode);
    if (c->joint && c->position && c->energy && c->time && c->mode) return 0;
    columns_free(c);
    return -1;
}

static void *column_of(event_columns *c, int kind)
{
    switch (kind) {
    case EVENT_JOINT: return c->joint;
    case EVENT_POSITION: return c->position;
    case EVENT_MODE: return c->mode;
    case EVENT_ENERGY: return c->energy;
    case EVENT_TIME: return c->time;
    }
    return NULL;
}

int result_append_events(result_file *f, const fdem_event *ev, int count, char *err,
                         size_t errlen)
{
    h5_quiet();
    if (!f || count <= 0) return 0;
    int D = f->event_dimension;
    event_columns c = {0};
    if (columns_alloc(&c, (size_t)count, D) < 0) {
        snprintf(err, errlen, "out of memory writing %d fracture events", count);
        return -1;
    }
    for (int i = 0; i < count; i++) {
        c.joint[i] = ev[i].joint;
        c.mode[i] = ev[i].mode;
        c.energy[i] = ev[i].energy;
        c.time[i] = ev[i].time;
        for (int d = 0; d < D; d++) c.position[(size_t)D * (size_t)i + d] = ev[i].position[d];
    }
    hsize_t start = f->event_count, length = start + (hsize_t)count;
    int rc = 0;
    for (int k = 0; k < EVENT_SERIES && rc == 0; k++) {
        /* every other row is on disk before time, the commit marker, grows */
        if (k == EVENT_TIME && H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0) rc = -1;
        else if (event_set_length(f->events[k], k, D, length) < 0 ||
                 event_rows(f->events[k], k, D, start, (hsize_t)count, column_of(&c, k), 1) < 0)
            rc = -1;
    }
    if (rc == 0 && H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0) rc = -1;
    columns_free(&c);
    if (rc < 0) {
        result_fail(err, errlen, "cannot append %d fracture events to /events", count);
        return -1;
    }
    f->event_count = length;
    return 0;
}

/* ------------------------------------------------------------- reopening */

/* Opens the /events datasets of a reopened file (creating them in a file
 * written before events existed) and keeps the committed events whose
 * joints are broken in `model`. Runs before SWMR writing starts. */
int events_reopen(result_file *f, const fdem_model *model, char *err, size_t errlen)
{
    int D = fdem_get_dimension(model);
    if (H5Lexists(f->file, "events", H5P_DEFAULT) <= 0) return events_create(f, D, err, errlen);
    hid_t group = H5Gopen2(f->file, "events", H5P_DEFAULT);
    f->event_dimension = D;
    hsize_t committed = 0;
    int rc = group >= 0 ? 0 : -1;
    for (int k = 0; k < EVENT_SERIES && rc == 0; k++) {
        f->events[k] = H5Lexists(group, event_series_names[k], H5P_DEFAULT) > 0
                           ? H5Dopen2(group, event_series_names[k], H5P_DEFAULT)
                           : H5I_INVALID_HID;
        if (f->events[k] < 0) rc = -1;
    }
    if (group >= 0) H5Gclose(group);
    if (rc < 0) {
        result_fail(err, errlen, "the result file's /events group is incomplete");
        return -1;
    }
    committed = event_length(f->events[EVENT_TIME]);
    for (int k = 0; k < EVENT_SERIES; k++)
        if (event_length(f->events[k]) < committed) committed = event_length(f->events[k]);
    int32_t *joint = malloc((committed ? committed : 1) * sizeof *joint);
    if (!joint) {
        snprintf(err, errlen, "out of memory reading %llu fracture events",
                 (unsigned long long)committed);
        return -1;
    }
    if (event_rows(f->events[EVENT_JOINT], EVENT_JOINT, D, 0, committed, joint, 0) < 0) {
        free(joint);
        result_fail(err, errlen, "cannot read /events/joint");
        return -1;
    }
    const double *damage = fdem_joint_damage(model);
    int joints = fdem_get_counts(model).joints;
    hsize_t keep = 0;
    while (keep < committed && damage && joint[keep] >= 0 && joint[keep] < joints &&
           damage[joint[keep]] >= 1.0)
        keep++;
    free(joint);
    for (int k = 0; k < EVENT_SERIES; k++)
        if (event_set_length(f->events[k], k, D, keep) < 0) {
            result_fail(err, errlen, "cannot truncate /events/%s to %llu events",
                        event_series_names[k], (unsigned long long)keep);
            return -1;
        }
    f->event_count = keep;
    return 0;
}

/* --------------------------------------------------------------- reading */

/* The events of an open file whose time is after `since`. */
static int events_read_open(hid_t file, const hid_t *given, double since, fdem_event **out,
                            int *count, int *dimension, char *err, size_t errlen)
{
    hid_t ids[EVENT_SERIES], group = H5I_INVALID_HID;
    int opened = 0, rc = -1;
    *out = NULL;
    *count = 0;
    if (given) {
        memcpy(ids, given, sizeof ids);
    } else {
        for (int k = 0; k < EVENT_SERIES; k++) ids[k] = H5I_INVALID_HID;
        if (H5Lexists(file, "events", H5P_DEFAULT) <= 0) return 0; /* written before events */
        group = H5Gopen2(file, "events", H5P_DEFAULT);
        for (int k = 0; k < EVENT_SERIES && group >= 0; k++)
            ids[k] = H5Dopen2(group, event_series_names[k], H5P_DEFAULT);
        opened = 1;
    }
    event_columns c = {0};
    hsize_t n = 0, dims[2] = {0, 0};
    for (int k = 0; k < EVENT_SERIES; k++)
        if (ids[k] < 0) goto done;
    hid_t space = H5Dget_space(ids[EVENT_POSITION]);
    if (space < 0) goto done;
    H5Sget_simple_extent_dims(space, dims, NULL);
    H5Sclose(space);
    *dimension = (int)dims[1];
    n = event_length(ids[EVENT_TIME]);
    for (int k = 0; k < EVENT_SERIES; k++)
        if (event_length(ids[k]) < n) n = event_length(ids[k]);
    if (columns_alloc(&c, n, *dimension) < 0) {
        snprintf(err, errlen, "out of memory reading %llu fracture events", (unsigned long long)n);
        goto done;
    }
    for (int k = 0; k < EVENT_SERIES; k++)
        if (event_rows(ids[k], k, *dimension, 0, n, column_of(&c, k), 0) < 0) {
            result_fail(err, errlen, "cannot read /events/%s", event_series_names[k]);
            goto done;
        }
    hsize_t first = 0;
    while (first < n && !(c.time[first] > since)) first++;
    *out = calloc(n - first ? n - first : 1, sizeof **out);
    if (!*out) {
        snprintf(err, errlen, "out of memory reading %llu fracture events", (unsigned long long)n);
        goto done;
    }
    for (hsize_t i = first; i < n; i++) {
        fdem_event *e = &(*out)[i - first];
        e->time = c.time[i];
        e->joint = c.joint[i];
        e->mode = c.mode[i];
        e->energy = c.energy[i];
        for (int d = 0; d < *dimension && d < 3; d++)
            e->position[d] = c.position[(size_t)*dimension * i + (size_t)d];
    }
    *count = (int)(n - first);
    rc = 0;
done:
    if (rc < 0 && err && errlen && !err[0]) result_fail(err, errlen, "the result file's /events cannot be read");
    columns_free(&c);
    if (opened)
        for (int k = 0; k < EVENT_SERIES; k++)
            if (ids[k] >= 0) H5Dclose(ids[k]);
    if (group >= 0) H5Gclose(group);
    return rc;
}

int result_read_events(result_file *f, const char *path, double since, fdem_event **out,
                       int *count, int *dimension, char *err, size_t errlen)
{
    h5_quiet();
    if (err && errlen) err[0] = '\0';
    *dimension = 0;
    if (f) return events_read_open(f->file, f->events, since, out, count, dimension, err, errlen);
    hid_t file = result_open_read(path);
    if (file < 0) {
        result_fail(err, errlen, "cannot open %s to read its events", path);
        return -1;
    }
    int rc = events_read_open(file, NULL, since, out, count, dimension, err, errlen);
    H5Fclose(file);
    return rc;
}
