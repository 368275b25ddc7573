/*
 * result_history.c - the history output of result.h5 (contract 6.2):
 * /history/time (H), /history/step (H), /history/points/displacement and
 * /history/points/velocity (H, P, dimension) with the point names in the
 * attribute `names` of /history/points, /history/constraint_force and
 * /history/constraint_displacement (H, C, dimension), and
 * /history/energy/<term> (H) for every energy account; with fluid
 * (contract 6.4) also /history/fluid/source_pressure and
 * /history/fluid/injected_volume (H, C) (NaN for a constraint that does
 * not inject) and energy/fluid_work, energy/fluid_dissipation (H). A file
 * written before the fluid's series keeps on without them.
 *
 * The discipline is /snapshots' and /events' (result_h5.c,
 * result_events.c): the datasets are made with the file, before SWMR
 * writing starts; an append extends every other dataset to the same
 * absolute length and flushes, then /history/time, the commit marker,
 * grows and is flushed, so a SWMR reader never sees half a row and a
 * failed append is overwritten by the next. Chunks hold many rows (a row
 * is a few hundred bytes): a row costs one small write per dataset.
 *
 * Reopening (result_reopen.c) keeps the committed rows whose step is at
 * most the checkpoint's, like snapshots; a file written before history
 * existed gets the group, empty.
 *
 * Not thread-safe: the daemon's I/O thread calls all of this.
 */
#include "result_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const history_series_names[HISTORY_SERIES] = {
    "step", "points/displacement", "points/velocity", "constraint_force",
    "constraint_displacement", "energy/kinetic", "energy/elastic", "energy/joint",
    "energy/contact", "energy/friction", "energy/fracture", "energy/damping",
    "energy/gravity_work", "energy/external_work", "energy/excavated", "energy/residual",
    "fluid/source_pressure", "fluid/injected_volume", "energy/fluid_work",
    "energy/fluid_dissipation", "time",
};

#define HISTORY_CHUNK_ROWS 256

static int hist_is_points(int k) { return k == HIST_POINT_DISPLACEMENT || k == HIST_POINT_VELOCITY; }
static int hist_is_vectors(int k)
{
    return hist_is_points(k) || k == HIST_CONSTRAINT_FORCE || k == HIST_CONSTRAINT_DISPLACEMENT;
}
static int hist_is_fluid(int k) { return k >= HIST_FLUID_PRESSURE && k < HIST_TIME; }
/* (H, C) per constraint: the fluid's source pressure and injected volume */
static int hist_is_per_constraint(int k)
{
    return k == HIST_FLUID_PRESSURE || k == HIST_FLUID_INJECTED;
}
static int hist_rank(int k) { return hist_is_vectors(k) ? 3 : hist_is_per_constraint(k) ? 2 : 1; }

/* The items per row of series k (points or constraints) in file f. */
static hsize_t hist_items(const result_file *f, int k)
{
    return hist_is_points(k) ? (hsize_t)f->history_points : (hsize_t)f->history_constraints;
}

/* Series k is in file f (the fluid's only with fluid). */
static int hist_present(const result_file *f, int k) { return f->history[k] >= 0; }

static int hist_create_one(result_file *f, hid_t group, int k)
{
    hsize_t n = hist_items(f, k), D = (hsize_t)f->history_dimension;
    hsize_t dims[3] = {0, n, D}, maxdims[3] = {H5S_UNLIMITED, n ? n : H5S_UNLIMITED, D};
    hsize_t chunk[3] = {HISTORY_CHUNK_ROWS, n ? n : 1, D};
    hid_t space = H5Screate_simple(hist_rank(k), dims, maxdims);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE), lcpl = H5Pcreate(H5P_LINK_CREATE);
    f->history[k] = H5I_INVALID_HID;
    if (space >= 0 && dcpl >= 0 && lcpl >= 0 && H5Pset_create_intermediate_group(lcpl, 1) >= 0 &&
        H5Pset_chunk(dcpl, hist_rank(k), chunk) >= 0)
        f->history[k] = H5Dcreate2(group, history_series_names[k],
                                   k == HIST_STEP ? H5T_STD_I64LE : H5T_IEEE_F64LE, space, lcpl,
                                   dcpl, H5P_DEFAULT);
    if (lcpl >= 0) H5Pclose(lcpl);
    if (dcpl >= 0) H5Pclose(dcpl);
    if (space >= 0) H5Sclose(space);
    return f->history[k] >= 0 ? 0 : -1;
}

/* The attribute `names` of /history/points: one UTF-8 string per point. */
static int hist_write_names(hid_t group, const case_info *info)
{
    hid_t points = H5Gopen2(group, "points", H5P_DEFAULT);
    if (points < 0) return -1;
    int P = info->history_point_count;
    const char *names[CASE_MAX_HISTORY_POINTS];
    for (int p = 0; p < P; p++) names[p] = info->history_names[p];
    hsize_t dims[1] = {(hsize_t)P};
    hid_t type = utf8_string_type();
    hid_t space = H5Screate_simple(1, dims, NULL);
    int rc = -1;
    if (type >= 0 && space >= 0) {
        hid_t attr = H5Acreate2(points, "names", type, space, H5P_DEFAULT, H5P_DEFAULT);
        if (attr >= 0) {
            rc = P == 0 || H5Awrite(attr, type, names) >= 0 ? 0 : -1;
            H5Aclose(attr);
        }
    }
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    H5Gclose(points);
    return rc;
}

int history_create(result_file *f, const fdem_model *model, const case_info *info, char *err,
                   size_t errlen)
{
    f->history_dimension = fdem_get_dimension(model);
    f->history_points = info->history_point_count;
    f->history_constraints = fdem_get_counts(model).constraints;
    f->history_fluid = fdem_has_fluid(model);
    f->history_last_time = -INFINITY;
    hid_t group = H5Gcreate2(f->file, "history", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (group < 0) {
        result_fail(err, errlen, "cannot create group /history");
        return -1;
    }
    int rc = 0;
    for (int k = 0; k < HISTORY_SERIES && rc == 0; k++)
        if (hist_is_fluid(k) && !f->history_fluid) f->history[k] = H5I_INVALID_HID;
        else if (hist_create_one(f, group, k) < 0) {
            result_fail(err, errlen, "cannot create /history/%s", history_series_names[k]);
            rc = -1;
        }
    if (rc == 0 && hist_write_names(group, info) < 0) {
        result_fail(err, errlen, "cannot write the names of /history/points");
        rc = -1;
    }
    H5Gclose(group);
    return rc;
}

static hsize_t hist_length(hid_t id)
{
    hsize_t dims[3] = {0, 0, 0};
    hid_t space = H5Dget_space(id);
    if (space < 0) return 0;
    H5Sget_simple_extent_dims(space, dims, NULL);
    H5Sclose(space);
    return dims[0];
}

static int hist_set_length(const result_file *f, int k, hsize_t length)
{
    if (!hist_present(f, k)) return 0;
    hsize_t dims[3] = {length, hist_items(f, k), (hsize_t)f->history_dimension};
    return H5Dset_extent(f->history[k], dims) < 0 ? -1 : 0;
}

/* Rows [start, start + count) of series k to or from buf. */
static int hist_rows(const result_file *f, int k, hsize_t start, hsize_t count, void *buf,
                     int write)
{
    hsize_t n = hist_items(f, k), D = (hsize_t)f->history_dimension;
    if (count == 0 || !hist_present(f, k) || (hist_rank(k) > 1 && n == 0)) return 0;
    hsize_t offset[3] = {start, 0, 0}, extent[3] = {count, n, D};
    hid_t id = f->history[k];
    hid_t file_space = H5Dget_space(id), mem_space = H5Screate_simple(hist_rank(k), extent, NULL);
    hid_t mem = k == HIST_STEP ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE;
    int rc = -1;
    if (file_space >= 0 && mem_space >= 0 &&
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, offset, NULL, extent, NULL) >= 0)
        rc = (write ? H5Dwrite(id, mem, mem_space, file_space, H5P_DEFAULT, buf)
                    : H5Dread(id, mem, mem_space, file_space, H5P_DEFAULT, buf)) < 0 ? -1 : 0;
    if (mem_space >= 0) H5Sclose(mem_space);
    if (file_space >= 0) H5Sclose(file_space);
    return rc;
}

/* Where series k of `row` lives (energy terms in history_energy_names order). */
static void *hist_field(history_row *row, int k)
{
    switch (k) {
    case HIST_STEP: return &row->step;
    case HIST_POINT_DISPLACEMENT: return row->point_displacement;
    case HIST_POINT_VELOCITY: return row->point_velocity;
    case HIST_CONSTRAINT_FORCE: return row->constraint_force;
    case HIST_CONSTRAINT_DISPLACEMENT: return row->constraint_displacement;
    case HIST_TIME: return &row->time;
    case HIST_FLUID_PRESSURE: return row->source_pressure;
    case HIST_FLUID_INJECTED: return row->injected_volume;
    }
    if (k >= HIST_FLUID_ENERGY) return &row->fluid_energy[k - HIST_FLUID_ENERGY];
    return &row->energy[k - HIST_ENERGY];
}

/* Rows a replay writes again (an extend's first step, a restart) come at
 * or before the last committed time: /history/time only ever grows. */
static int hist_fits(const result_file *f, const history_row *row)
{
    return row->points == f->history_points && row->constraints == f->history_constraints &&
           row->dimension == f->history_dimension && (row->fluid || !f->history_fluid);
}

int result_append_history(result_file *f, history_row *const *rows, int count, char *err,
                          size_t errlen)
{
    h5_quiet();
    if (!f || count <= 0) return 0;
    hsize_t start = f->history_count, length = start;
    double last = f->history_last_time;
    history_row *const *fresh = rows;
    int first = 0;
    while (first < count && !(rows[first]->time > last)) first++;
    fresh = rows + first;
    count -= first;
    if (count <= 0) return 0;
    for (int i = 0; i < count; i++)
        if (!hist_fits(f, fresh[i])) {
            snprintf(err, errlen, "a history row of %d points and %d constraints does not fit "
                     "/history (%d, %d)", fresh[i]->points, fresh[i]->constraints,
                     f->history_points, f->history_constraints);
            return -1;
        }
    length = start + (hsize_t)count;
    int rc = 0;
    for (int k = 0; k < HISTORY_SERIES && rc == 0; k++) {
        /* every other series is on disk before time, the commit marker, grows */
        if (k == HIST_TIME && H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0) rc = -1;
        else if (hist_set_length(f, k, length) < 0) rc = -1;
        for (int i = 0; rc == 0 && i < count; i++)
            if (hist_rows(f, k, start + (hsize_t)i, 1, hist_field(fresh[i], k), 1) < 0) rc = -1;
    }
    if (rc == 0 && H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0) rc = -1;
    if (rc < 0) {
        result_fail(err, errlen, "cannot append %d history rows to /history", count);
        return -1;
    }
    f->history_count = length;
    f->history_last_time = fresh[count - 1]->time;
    return 0;
}

/* ------------------------------------------------------------- reopening */

/* Opens the /history datasets of file f (0, or -1 when one is missing) and
 * reads its shape from them. */
static int hist_open(result_file *f, hid_t file)
{
    hid_t group = H5Gopen2(file, "history", H5P_DEFAULT);
    if (group < 0) return -1;
    int rc = 0, fluid = 0;
    for (int k = 0; k < HISTORY_SERIES; k++) {
        /* H5Lexists on "fluid/..." needs the group "fluid" to exist */
        int exists = (!hist_is_per_constraint(k) || H5Lexists(group, "fluid", H5P_DEFAULT) > 0) &&
                     H5Lexists(group, history_series_names[k], H5P_DEFAULT) > 0;
        f->history[k] = exists ? H5Dopen2(group, history_series_names[k], H5P_DEFAULT)
                               : H5I_INVALID_HID;
        if (f->history[k] >= 0) fluid += hist_is_fluid(k);
        else if (!hist_is_fluid(k)) rc = -1; /* the fluid's: only in a file with fluid */
    }
    H5Gclose(group);
    /* all of the fluid's series or none of them */
    f->history_fluid = fluid == HIST_TIME - HIST_FLUID_PRESSURE;
    for (int k = HIST_FLUID_PRESSURE; !f->history_fluid && k < HIST_TIME; k++)
        if (f->history[k] >= 0) {
            H5Dclose(f->history[k]);
            f->history[k] = H5I_INVALID_HID;
        }
    if (rc < 0) return -1;
    hsize_t dims[3] = {0, 0, 0};
    hid_t space = H5Dget_space(f->history[HIST_POINT_DISPLACEMENT]);
    H5Sget_simple_extent_dims(space, dims, NULL);
    H5Sclose(space);
    f->history_points = (int)dims[1];
    f->history_dimension = (int)dims[2];
    space = H5Dget_space(f->history[HIST_CONSTRAINT_FORCE]);
    H5Sget_simple_extent_dims(space, dims, NULL);
    H5Sclose(space);
    f->history_constraints = (int)dims[1];
    hsize_t committed = hist_length(f->history[HIST_TIME]);
    for (int k = 0; k < HISTORY_SERIES; k++)
        if (hist_present(f, k) && hist_length(f->history[k]) < committed)
            committed = hist_length(f->history[k]);
    f->history_count = committed;
    return 0;
}

int history_reopen(result_file *f, const fdem_model *model, const case_info *info,
                   int64_t keep_until_step, char *err, size_t errlen)
{
    if (H5Lexists(f->file, "history", H5P_DEFAULT) <= 0)
        return history_create(f, model, info, err, errlen);
    if (hist_open(f, f->file) < 0) {
        result_fail(err, errlen, "the result file's /history group is incomplete");
        return -1;
    }
    hsize_t n = f->history_count, keep = 0;
    int64_t *steps = malloc((n ? n : 1) * sizeof *steps);
    if (!steps) {
        snprintf(err, errlen, "out of memory reading %llu history rows", (unsigned long long)n);
        return -1;
    }
    if (hist_rows(f, HIST_STEP, 0, n, steps, 0) < 0) {
        free(steps);
        result_fail(err, errlen, "cannot read /history/step");
        return -1;
    }
    while (keep < n && steps[keep] <= keep_until_step) keep++;
    free(steps);
    f->history_last_time = -INFINITY;
    if (keep > 0 && hist_rows(f, HIST_TIME, keep - 1, 1, &f->history_last_time, 0) < 0) {
        result_fail(err, errlen, "cannot read /history/time");
        return -1;
    }
    for (int k = 0; k < HISTORY_SERIES; k++)
        if (hist_set_length(f, k, keep) < 0) {
            result_fail(err, errlen, "cannot truncate /history/%s to %llu rows",
                        history_series_names[k], (unsigned long long)keep);
            return -1;
        }
    f->history_count = keep;
    return 0;
}

/* --------------------------------------------------------------- reading */

/* The attribute `names` of /history/points into `names` (count 0 when it
 * cannot be read: the rows are still served). */
static void hist_read_names(hid_t file, history_names *names)
{
    names->count = 0;
    hid_t points = H5Gopen2(file, "history/points", H5P_DEFAULT);
    hid_t attr = points >= 0 ? H5Aopen(points, "names", H5P_DEFAULT) : H5I_INVALID_HID;
    hid_t space = attr >= 0 ? H5Aget_space(attr) : H5I_INVALID_HID;
    hid_t type = utf8_string_type(); /* as written: HDF5 converts no character set */
    hssize_t n = space >= 0 ? H5Sget_simple_extent_npoints(space) : 0;
    if (type >= 0 && n > 0 && n <= CASE_MAX_HISTORY_POINTS) {
        char *text[CASE_MAX_HISTORY_POINTS] = {0};
        if (H5Aread(attr, type, text) >= 0) {
            for (hssize_t i = 0; i < n; i++) {
                snprintf(names->name[i], sizeof names->name[i], "%s", text[i] ? text[i] : "");
                H5free_memory(text[i]);
            }
            names->count = (int)n;
        }
    }
    if (type >= 0) H5Tclose(type);
    if (space >= 0) H5Sclose(space);
    if (attr >= 0) H5Aclose(attr);
    if (points >= 0) H5Gclose(points);
    H5Eclear2(H5E_DEFAULT);
}

static void rows_free(history_row **rows, int count)
{
    for (int i = 0; rows && i < count; i++) history_free(rows[i]);
    free(rows);
}

/* The rows with time > since of f (its datasets open). */
static int hist_read(result_file *f, double since, history_row ***out, int *count, char *err,
                     size_t errlen)
{
    hsize_t n = f->history_count;
    double *time = malloc((n ? n : 1) * sizeof *time);
    if (!time || hist_rows(f, HIST_TIME, 0, n, time, 0) < 0) {
        free(time);
        result_fail(err, errlen, "cannot read /history/time");
        return -1;
    }
    hsize_t first = 0;
    while (first < n && !(time[first] > since)) first++;
    free(time);
    int m = (int)(n - first);
    history_row **rows = calloc(m ? (size_t)m : 1, sizeof *rows);
    int rc = rows ? 0 : -1;
    for (int i = 0; rc == 0 && i < m; i++) {
        rows[i] = history_alloc(f->history_dimension, f->history_points, f->history_constraints,
                                f->history_fluid);
        if (!rows[i]) rc = -1;
        for (int k = 0; rc == 0 && k < HISTORY_SERIES; k++)
            if (hist_rows(f, k, first + (hsize_t)i, 1, hist_field(rows[i], k), 0) < 0) rc = -1;
    }
    if (rc < 0) {
        rows_free(rows, m);
        result_fail(err, errlen, "cannot read %d history rows", m);
        return -1;
    }
    *out = rows;
    *count = m;
    return 0;
}

int result_read_history(result_file *f, const char *path, double since, history_row ***out,
                        int *count, history_names *names, char *err, size_t errlen)
{
    h5_quiet();
    if (err && errlen) err[0] = '\0';
    *out = NULL;
    *count = 0;
    names->count = 0;
    if (f) {
        if (f->history[HIST_TIME] < 0) return 0;
        hist_read_names(f->file, names);
        return hist_read(f, since, out, count, err, errlen);
    }
    hid_t file = result_open_read(path);
    if (file < 0) {
        result_fail(err, errlen, "cannot open %s to read its history", path);
        return -1;
    }
    int rc = 0;
    if (H5Lexists(file, "history", H5P_DEFAULT) > 0) { /* else written before history */
        hist_read_names(file, names);
        result_file *r = result_alloc();
        rc = r && hist_open(r, file) == 0 ? hist_read(r, since, out, count, err, errlen) : -1;
        if (rc < 0 && err && errlen && !err[0])
            snprintf(err, errlen, "the result file's /history cannot be read");
        if (r) {
            history_close_handles(r);
            free(r);
        }
    }
    H5Fclose(file);
    return rc;
}

void result_free_history(history_row **rows, int count) { rows_free(rows, count); }

int history_close_handles(result_file *f)
{
    int rc = 0;
    for (int k = 0; k < HISTORY_SERIES; k++)
        if (f->history[k] >= 0) {
            if (H5Dclose(f->history[k]) < 0) rc = -1;
            f->history[k] = H5I_INVALID_HID;
        }
    return rc;
}
