/*
 * result_reopen.c - result.h5 files written by an earlier run: reopening
 * one to carry on writing after a restart or a crash, and checking that a
 * closed one is whole before it is served.
 *
 * A crash leaves the superblock marked "open for writing" and its end of
 * allocation short of what was written; reopening clears the mark through
 * the "clear_status_flags" file-access property (the one `h5clear -s`
 * sets), moves the end of allocation to the file's end, then trims every
 * dataset to the committed length (that of /snapshots/time, the commit
 * marker) and to the last checkpoint's step, keeps the fracture events of
 * the joints the resumed model has broken (result_events.c), and resumes
 * SWMR writing (result_h5.c has the discipline).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "result_internal.h"

/* Opens /snapshots/<name> and checks it has the shape this model needs. */
static int series_open(hid_t group, int kind, series *s, char *err, size_t errlen)
{
    if (s->rank == 0) return 0;
    if (H5Lexists(group, series_names[kind], H5P_DEFAULT) <= 0) {
        snprintf(err, errlen, "the result file has no /snapshots/%s; it was written for "
                 "a different case or output fields", series_names[kind]);
        return -1;
    }
    s->id = H5Dopen2(group, series_names[kind], H5P_DEFAULT);
    if (s->id < 0) {
        result_fail(err, errlen, "cannot open /snapshots/%s", series_names[kind]);
        return -1;
    }
    hid_t space = H5Dget_space(s->id);
    hsize_t dims[3] = {0, 0, 0};
    int rank = space >= 0 ? H5Sget_simple_extent_dims(space, dims, NULL) : -1;
    if (space >= 0) H5Sclose(space);
    if (rank != s->rank || (rank >= 2 && dims[1] != s->row[0]) ||
        (rank == 3 && dims[2] != s->row[1])) {
        snprintf(err, errlen, "/snapshots/%s in the result file does not match the model's "
                 "node, element, joint or constraint count", series_names[kind]);
        return -1;
    }
    return 0;
}

static hsize_t series_length(const series *s)
{
    hsize_t dims[3] = {0, 0, 0};
    hid_t space = H5Dget_space(s->id);
    if (space < 0) return 0;
    H5Sget_simple_extent_dims(space, dims, NULL);
    H5Sclose(space);
    return dims[0];
}

/* Reads the first `count` entries of a 1-D series. */
static int series_read_head(const series *s, int kind, hsize_t count, void *out)
{
    if (count == 0) return 0;
    hsize_t start = 0;
    hid_t file_space = H5Dget_space(s->id);
    hid_t mem_space = H5Screate_simple(1, &count, NULL);
    int rc = -1;
    if (file_space >= 0 && mem_space >= 0 &&
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, &start, NULL, &count, NULL) >= 0 &&
        H5Dread(s->id, series_mem_type(kind), mem_space, file_space, H5P_DEFAULT, out) >= 0)
        rc = 0;
    if (mem_space >= 0) H5Sclose(mem_space);
    if (file_space >= 0) H5Sclose(file_space);
    return rc;
}

/* How many snapshots survive: rows every dataset holds (a crash may have
 * left some longer than time), and of those the ones up to keep_until_step.
 * Fills f->times for them. */
static int committed_snapshots(result_file *f, int64_t keep_until_step, hsize_t *keep,
                               char *err, size_t errlen)
{
    hsize_t committed = series_length(&f->ds[SERIES_TIME]);
    for (int k = 0; k < SERIES_COUNT; k++)
        if (f->ds[k].id >= 0 && series_length(&f->ds[k]) < committed)
            committed = series_length(&f->ds[k]);
    int64_t *steps = malloc((committed ? committed : 1) * sizeof *steps);
    double *times = malloc((committed ? committed : 1) * sizeof *times);
    int rc = -1;
    if (!steps || !times) {
        snprintf(err, errlen, "out of memory reading %llu snapshot steps",
                 (unsigned long long)committed);
    } else if (series_read_head(&f->ds[SERIES_STEP], SERIES_STEP, committed, steps) < 0 ||
               series_read_head(&f->ds[SERIES_TIME], SERIES_TIME, committed, times) < 0) {
        result_fail(err, errlen, "cannot read /snapshots/step and /snapshots/time");
    } else {
        hsize_t n = 0;
        while (n < committed && steps[n] <= keep_until_step) n++;
        *keep = n;
        f->times = times;
        f->times_capacity = (int)(committed ? committed : 1);
        f->count = (int)n;
        times = NULL;
        rc = 0;
    }
    free(steps);
    free(times);
    return rc;
}

static int truncate_series(result_file *f, hsize_t length, char *err, size_t errlen)
{
    for (int k = 0; k < SERIES_COUNT; k++) {
        series *s = &f->ds[k];
        if (s->id < 0) continue;
        hsize_t dims[3] = {length, s->row[0], s->row[1]};
        if (H5Dset_extent(s->id, dims) < 0) {
            result_fail(err, errlen, "cannot truncate /snapshots/%s to %llu snapshots",
                        series_names[k], (unsigned long long)length);
            return -1;
        }
    }
    return 0;
}

/* A file written before fragments were recorded has no /snapshots/fragment:
 * a case paused or cut off by an older daemon must still go on, so the
 * series is added, as long as /snapshots/time, its earlier rows -1 (not
 * recorded). Done before SWMR writing starts, which allows no new objects. */
static int add_fragment_series(hid_t group, result_file *f, char *err, size_t errlen)
{
    series *s = &f->ds[SERIES_FRAGMENT];
    if (s->rank == 0 || H5Lexists(group, series_names[SERIES_FRAGMENT], H5P_DEFAULT) > 0)
        return 0;
    series time = {0};
    time.id = H5Dopen2(group, series_names[SERIES_TIME], H5P_DEFAULT);
    hsize_t rows = time.id >= 0 ? series_length(&time) : 0;
    if (time.id >= 0) H5Dclose(time.id);
    hsize_t dims[3] = {rows, s->row[0], s->row[1]};
    if (time.id < 0 || series_create(group, SERIES_FRAGMENT, s) < 0 || H5Dset_extent(s->id, dims) < 0) {
        result_fail(err, errlen, "cannot add /snapshots/fragment to a result file written "
                    "before fragments were recorded");
        return -1;
    }
    H5Dclose(s->id);
    s->id = -1;
    return 0;
}

static int open_snapshot_series(result_file *f, char *err, size_t errlen)
{
    hid_t group = H5Gopen2(f->file, "snapshots", H5P_DEFAULT);
    if (group < 0) {
        result_fail(err, errlen, "the result file has no /snapshots group");
        return -1;
    }
    int rc = add_fragment_series(group, f, err, errlen);
    for (int k = 0; k < SERIES_COUNT && rc == 0; k++)
        rc = series_open(group, k, &f->ds[k], err, errlen);
    H5Gclose(group);
    return rc;
}

result_file *result_reopen(const char *path, const fdem_model *model,
                           const case_info *info, int64_t keep_until_step,
                           char *err, size_t errlen)
{
    h5_quiet();
    if (!path || !model || !info) {
        snprintf(err, errlen, "result_reopen: missing path, model or case info");
        return NULL;
    }
    if (access(path, F_OK) != 0) {
        snprintf(err, errlen, "cannot reopen result file %s: %s", path, strerror(errno));
        return NULL;
    }
    result_file *f = result_alloc();
    if (!f) {
        snprintf(err, errlen, "out of memory reopening %s", path);
        return NULL;
    }
    hid_t fapl = file_access_latest(1);
    if (fapl < 0) {
        result_fail(err, errlen, "this HDF5 library cannot clear the status flags of %s "
                    "(run `h5clear -s` on it)", path);
        goto fail;
    }
    f->file = H5Fopen(path, H5F_ACC_RDWR, fapl);
    H5Pclose(fapl);
    if (f->file < 0) {
        result_fail(err, errlen, "cannot reopen result file %s", path);
        goto fail;
    }
    /* An SWMR writer updates the superblock's end of allocation only now
     * and then, so a crash can leave chunks and index blocks that the kept
     * rows use beyond it (seen: 1 kill in 4 left bytes past it). Trusting
     * it, the next allocation wrote over them or failed ("addr overflow").
     * Everything written lies before the file's end: the end of
     * allocation is moved there first, before any object is read, as
     * `h5clear --increment=0` does. */
    if (H5Fincrement_filesize(f->file, 0) < 0) {
        result_fail(err, errlen, "cannot extend the end of allocation of %s to its size", path);
        goto fail;
    }
    if (!has_result_format(f->file)) {
        H5Eclear2(H5E_DEFAULT);
        snprintf(err, errlen, "%s is not an fdem result file (no format = \"%s\")", path,
                 RESULT_FORMAT);
        goto fail;
    }
    series_layout(f->ds, model, info->fields);
    if (open_snapshot_series(f, err, errlen) < 0) goto fail;
    hsize_t keep = 0;
    if (committed_snapshots(f, keep_until_step, &keep, err, errlen) < 0) goto fail;
    if (truncate_series(f, keep, err, errlen) < 0) goto fail;
    if (events_reopen(f, model, err, errlen) < 0) goto fail;
    if (history_reopen(f, model, info, keep_until_step, err, errlen) < 0) goto fail;
    if (start_swmr(f, path, err, errlen) < 0) goto fail;
    return f;
fail:
    result_release(f);
    return NULL;
}

int result_check_file(const char *path, char *err, size_t errlen)
{
    h5_quiet();
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "%s is not a regular file", path);
        return -1;
    }
    hid_t file = result_open_read(path);
    if (file < 0) {
        result_fail(err, errlen, "%s does not open as HDF5", path);
        return -1;
    }
    int ok = has_result_format(file) && H5Lexists(file, "snapshots", H5P_DEFAULT) > 0;
    H5Fclose(file);
    H5Eclear2(H5E_DEFAULT);
    if (!ok) {
        snprintf(err, errlen, "%s is not an fdem result file (no format \"%s\" or no /snapshots)",
                 path, RESULT_FORMAT);
        return -1;
    }
    return 0;
}

hid_t result_open_read(const char *path)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, H5P_DEFAULT);
    if (file < 0) {
        H5Eclear2(H5E_DEFAULT);
        file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    }
    return file;
}
