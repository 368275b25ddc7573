/*
 * result_h5.c - result.h5 (contract section 4): the mesh once, then one row
 * per snapshot in chunked, extendible datasets, written under HDF5 SWMR so
 * readers (h5py with swmr=True, a download copy) see a valid file while the
 * case runs.
 *
 * The discipline that keeps readers consistent:
 *  - every append extends each /snapshots dataset to the same absolute
 *    length, writes its row and flushes; only then is /snapshots/time
 *    extended, written and flushed again. len(time) is therefore the number
 *    of complete snapshots, and a reader that refreshes time first and
 *    reads that many rows of the other datasets never sees a half-written
 *    snapshot. A failed append leaves time alone, and the next append
 *    overwrites the partial rows because extents are absolute.
 *  - a crash leaves the superblock marked "open for writing"; reopening
 *    (result_reopen.c) clears the mark through the "clear_status_flags" file-access property
 *    (the one `h5clear -s` sets; present in HDF5 1.10 and later), then
 *    trims every dataset to the committed length and to keep_until_step.
 *  - a download copy is a byte copy taken between appends (the writer has
 *    flushed, and appends of that case wait) with the copy's status flags
 *    cleared, so a plain h5py.File(copy) opens it (result_image.c).
 *
 * Chunks: per-snapshot rows of at least 8 KiB get one snapshot per chunk,
 * split into ~1 MiB pieces along the node/element axis for huge models;
 * smaller rows (energies, time, small models) are grouped up to 8 KiB (at
 * most 1024 snapshots) per chunk so they do not become thousands of tiny
 * chunks. The group stays small because every flush rewrites the partly
 * filled chunk whole.
 *
 * A model without constraints still gets /snapshots/constraint_force with
 * shape (S, 0, dimension) (axis 1 declared unlimited, since a chunk cannot
 * be wider than a fixed zero extent), so readers can index it uniformly.
 *
 * Both dimensions share the layout (contract 5.2): node rows (position,
 * velocity, displacement) and constraint forces have `dimension` columns,
 * stress rows fdem_stress_components(), and the elements are
 * /mesh/triangles (E, 3) in 2D or /mesh/tetrahedra (E, 4) in 3D; the root
 * attribute `dimension` says which.
 *
 * Not thread-safe: one I/O thread owns every result_file (see result.h).
 */
#include "result.h"
#include "result_internal.h"

#include <hdf5.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define CHUNK_SMALL_BYTES (8u * 1024u)
#define CHUNK_MAX_BYTES (1024u * 1024u)
#define CHUNK_MAX_SNAPSHOTS 1024u

const char *const series_names[SERIES_COUNT] = {
    "step", "position", "velocity", "stress", "damage", "fragment", "strain", "principal_stress",
    "displacement", "stage", "active", "excavated_energy", "constraint_force", "kinetic_energy", "elastic_energy", "contact_energy",
    "friction_energy", "joint_energy", "fracture_energy", "damping_energy", "gravity_work",
    "external_work", "fluid_pressure", "aperture", "time",
};

/* ------------------------------------------------------------------ errors */

typedef struct h5_message {
    char text[256];
} h5_message;

/* Keeps the innermost description: it names the cause (errno, bad name),
 * the outer ones only repeat which API call failed. */
static herr_t h5_error_visit(unsigned n, const H5E_error2_t *e, void *data)
{
    h5_message *m = data;
    if (e->desc && e->desc[0]) snprintf(m->text, sizeof m->text, "%s", e->desc);
    (void)n;
    return 0;
}

/* Formats "what: innermost HDF5 message" into err and clears the stack. */
void result_fail(char *err, size_t errlen, const char *fmt, ...)
{
    h5_message m = {{0}};
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, h5_error_visit, &m);
    H5Eclear2(H5E_DEFAULT);
    if (!err || errlen == 0) return;
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (m.text[0])
        snprintf(err, errlen, "%s (HDF5: %s)", what, m.text);
    else
        snprintf(err, errlen, "%s", what);
}

/* HDF5 prints its error stack to stderr by default; the daemon reports
 * errors through `err` instead. The setting is per thread in thread-safe
 * builds, so every entry point repeats it. */
void h5_quiet(void)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

/* --------------------------------------------------------------- attributes */

/* Variable length so that h5py hands back a str, not bytes. */
hid_t utf8_string_type(void)
{
    hid_t type = H5Tcopy(H5T_C_S1);
    if (type >= 0 && (H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0)) {
        H5Tclose(type);
        return H5I_INVALID_HID;
    }
    return type;
}

int write_string_attribute(hid_t obj, const char *name, const char *value)
{
    hid_t type = utf8_string_type();
    hid_t space = H5Screate(H5S_SCALAR);
    hid_t attr = H5I_INVALID_HID;
    int rc = -1;
    if (type < 0 || space < 0) goto done;
    attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    if (attr < 0) goto done;
    if (H5Awrite(attr, type, &value) < 0) goto done;
    rc = 0;
done:
    if (attr >= 0) H5Aclose(attr);
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    return rc;
}

static int write_scalar_attribute(hid_t obj, const char *name, hid_t file_type,
                                  hid_t mem_type, const void *value)
{
    hid_t space = H5Screate(H5S_SCALAR);
    if (space < 0) return -1;
    hid_t attr = H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT);
    int rc = attr >= 0 && H5Awrite(attr, mem_type, value) >= 0 ? 0 : -1;
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(space);
    return rc;
}

static int write_root_attributes(hid_t file, const case_info *info, int dimension, double dt)
{
    const char *name = info && info->name[0] ? info->name : "";
    if (write_string_attribute(file, "format", RESULT_FORMAT) < 0) return -1;
    if (write_string_attribute(file, "name", name) < 0) return -1;
    if (write_scalar_attribute(file, "dimension", H5T_STD_I32LE, H5T_NATIVE_INT, &dimension) < 0)
        return -1;
    return write_scalar_attribute(file, "dt", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &dt);
}

/* 1 when the file's root says format = "fdem-result/1". */
int has_result_format(hid_t file)
{
    if (H5Aexists(file, "format") <= 0) return 0;
    hid_t attr = H5Aopen(file, "format", H5P_DEFAULT);
    if (attr < 0) return 0;
    hid_t type = utf8_string_type();
    char *value = NULL;
    int ok = 0;
    if (type >= 0 && H5Aread(attr, type, &value) >= 0) {
        ok = value && strcmp(value, RESULT_FORMAT) == 0;
        H5free_memory(value);
    }
    if (type >= 0) H5Tclose(type);
    H5Aclose(attr);
    return ok;
}

/* --------------------------------------------------------------------- mesh */

/* A fixed-size (rows, width) dataset, or (rows) when width is 0. */
static int write_mesh_array(hid_t group, const char *name, hid_t file_type, hid_t mem_type,
                            const void *data, int rows, int width)
{
    hsize_t dims[2] = {(hsize_t)rows, (hsize_t)width};
    hid_t space = H5Screate_simple(width ? 2 : 1, dims, NULL);
    if (space < 0) return -1;
    hid_t ds = H5Dcreate2(group, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int rc = ds >= 0 ? 0 : -1;
    if (rc == 0 && rows > 0 && data)
        rc = H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0 ? -1 : 0;
    if (ds >= 0) H5Dclose(ds);
    H5Sclose(space);
    return rc;
}

static int write_mesh(hid_t file, const fdem_model *model, char *err, size_t errlen)
{
    fdem_counts c = fdem_get_counts(model);
    int dim = fdem_get_dimension(model);
    const char *elements = dim == 3 ? "tetrahedra" : "triangles";
    hid_t group = H5Gcreate2(file, "mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (group < 0) {
        result_fail(err, errlen, "cannot create group /mesh");
        return -1;
    }
    struct {
        const char *name;
        hid_t file_type, mem_type;
        const void *data;
        int rows, width;
    } arrays[] = {
        {"position0", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, fdem_initial_positions(model), c.nodes,
         dim},
        {elements, H5T_STD_I32LE, H5T_NATIVE_INT32, fdem_element_nodes(model), c.elements,
         fdem_nodes_per_element(model)},
        {"node_mass", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, fdem_node_masses(model), c.nodes, 0},
        {"node_part", H5T_STD_I32LE, H5T_NATIVE_INT32, fdem_node_parts(model), c.nodes, 0},
        {"element_part", H5T_STD_I32LE, H5T_NATIVE_INT32, fdem_element_parts(model), c.elements, 0},
        {"joints", H5T_STD_I32LE, H5T_NATIVE_INT32, fdem_joints(model), c.joints, 2 * dim},
    };
    int rc = 0;
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0] && rc == 0; i++) {
        if (strcmp(arrays[i].name, "joints") == 0 && c.joints <= 0) continue;
        if (!arrays[i].data) {
            snprintf(err, errlen, "the model has no %s to write to /mesh", arrays[i].name);
            rc = -1;
        } else if (write_mesh_array(group, arrays[i].name, arrays[i].file_type,
                                    arrays[i].mem_type, arrays[i].data, arrays[i].rows,
                                    arrays[i].width) < 0) {
            result_fail(err, errlen, "cannot write /mesh/%s", arrays[i].name);
            rc = -1;
        }
    }
    H5Gclose(group);
    return rc;
}

/* ---------------------------------------------------------------- snapshots */

hid_t series_file_type(int kind)
{
    return kind == SERIES_STEP                             ? H5T_STD_I64LE
         : kind == SERIES_FRAGMENT || kind == SERIES_STAGE ? H5T_STD_I32LE
         : kind == SERIES_ACTIVE                           ? H5T_STD_U8LE
                                                           : H5T_IEEE_F64LE;
}

hid_t series_mem_type(int kind)
{
    return kind == SERIES_STEP                             ? H5T_NATIVE_INT64
         : kind == SERIES_FRAGMENT || kind == SERIES_STAGE ? H5T_NATIVE_INT32
         : kind == SERIES_ACTIVE                           ? H5T_NATIVE_UINT8
                                                           : H5T_NATIVE_DOUBLE;
}

/* Which datasets this model has and their per-snapshot shape. Damage is
 * stored whenever the model has joints (contract: "when some part
 * fractures"), the fragment id of every element always (contract 5.4), the
 * stage, every element's active flag and the excavated energy account
 * whenever the case has stages (contract 6.1), the node and element fields
 * only when requested. */
void series_layout(series ds[SERIES_COUNT], const fdem_model *model, unsigned fields)
{
    fdem_counts c = fdem_get_counts(model);
    int dim = fdem_get_dimension(model);
    int staged = fdem_stage_index(model) >= 0;
    int fluid = fdem_get_fluid(model).enabled && c.joints > 0;
    for (int k = 0; k < SERIES_COUNT; k++) {
        ds[k].id = H5I_INVALID_HID;
        ds[k].rank = 1;
        ds[k].row[0] = ds[k].row[1] = 0;
    }
    struct { int kind, present, rows, width; } shapes[] = {
        {SERIES_POSITION, (fields & CASE_FIELD_POSITION) != 0, c.nodes, dim},
        {SERIES_VELOCITY, (fields & CASE_FIELD_VELOCITY) != 0, c.nodes, dim},
        {SERIES_STRESS, (fields & CASE_FIELD_STRESS) != 0, c.elements,
         fdem_stress_components(model)},
        {SERIES_DAMAGE, c.joints > 0, c.joints, 0},
        {SERIES_FRAGMENT, 1, c.elements, 0},
        {SERIES_STRAIN, (fields & CASE_FIELD_STRAIN) != 0, c.elements,
         fdem_stress_components(model)},
        {SERIES_PRINCIPAL_STRESS, (fields & CASE_FIELD_PRINCIPAL_STRESS) != 0, c.elements, dim},
        {SERIES_DISPLACEMENT, (fields & CASE_FIELD_DISPLACEMENT) != 0, c.nodes, dim},
        {SERIES_ACTIVE, staged, c.elements, 0},
        {SERIES_CONSTRAINT_FORCE, 1, c.constraints, dim},
        {SERIES_FLUID_PRESSURE, fluid, c.joints, 0},
        {SERIES_APERTURE, fluid, c.joints, 0},
    };
    for (size_t i = 0; i < sizeof shapes / sizeof shapes[0]; i++) {
        series *s = &ds[shapes[i].kind];
        s->rank = shapes[i].present ? (shapes[i].width ? 3 : 2) : 0;
        s->row[0] = (hsize_t)shapes[i].rows;
        s->row[1] = (hsize_t)shapes[i].width;
    }
    ds[SERIES_STAGE].rank = staged ? 1 : 0; /* one number a snapshot, like step */
    ds[SERIES_EXCAVATED].rank = staged ? 1 : 0;
}

/* Chunk shape, see the comment at the top of the file. */
static void series_chunk(const series *s, hsize_t chunk[3])
{
    hsize_t width = s->rank == 3 ? s->row[1] : 1;
    hsize_t rows = s->rank >= 2 ? s->row[0] : 1;
    hsize_t row_bytes = rows * width * 8;
    if (row_bytes == 0) row_bytes = 8;
    hsize_t per_chunk = 1, split = rows;
    if (row_bytes < CHUNK_SMALL_BYTES) {
        per_chunk = CHUNK_SMALL_BYTES / row_bytes;
        if (per_chunk > CHUNK_MAX_SNAPSHOTS) per_chunk = CHUNK_MAX_SNAPSHOTS;
    } else if (row_bytes > CHUNK_MAX_BYTES) {
        split = CHUNK_MAX_BYTES / (width * 8);
    }
    chunk[0] = per_chunk;
    chunk[1] = split > 0 ? split : 1;
    chunk[2] = width;
}

int series_create(hid_t group, int kind, series *s)
{
    if (s->rank == 0) return 0;
    hsize_t dims[3] = {0, s->row[0], s->row[1]};
    hsize_t maxdims[3] = {H5S_UNLIMITED, s->row[0], s->row[1]};
    if (s->rank >= 2 && s->row[0] == 0) maxdims[1] = H5S_UNLIMITED;
    hsize_t chunk[3];
    series_chunk(s, chunk);
    hid_t space = H5Screate_simple(s->rank, dims, maxdims);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    int rc = -1;
    /* fragment ids not recorded (rows of a file written before fragments
     * existed, see result_reopen.c) read as -1, never as a real id */
    const int32_t unrecorded = -1;
    if (space >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, s->rank, chunk) >= 0 &&
        (kind != SERIES_FRAGMENT || H5Pset_fill_value(dcpl, H5T_NATIVE_INT32, &unrecorded) >= 0)) {
        s->id = H5Dcreate2(group, series_names[kind], series_file_type(kind), space,
                           H5P_DEFAULT, dcpl, H5P_DEFAULT);
        rc = s->id >= 0 ? 0 : -1;
    }
    if (dcpl >= 0) H5Pclose(dcpl);
    if (space >= 0) H5Sclose(space);
    return rc;
}

static const void *series_row_data(int kind, const snapshot *s)
{
    switch (kind) {
    case SERIES_STEP: return &s->step;
    case SERIES_POSITION: return s->position;
    case SERIES_VELOCITY: return s->velocity;
    case SERIES_STRESS: return s->stress;
    case SERIES_DAMAGE: return s->damage;
    case SERIES_FRAGMENT: return s->fragment;
    case SERIES_STRAIN: return s->strain;
    case SERIES_PRINCIPAL_STRESS: return s->principal_stress;
    case SERIES_DISPLACEMENT: return s->displacement;
    case SERIES_STAGE: return &s->stage;
    case SERIES_ACTIVE: return s->active;
    case SERIES_EXCAVATED: return &s->energy.excavated;
    case SERIES_CONSTRAINT_FORCE: return s->constraint_force;
    case SERIES_KINETIC: return &s->energy.kinetic;
    case SERIES_ELASTIC: return &s->energy.elastic;
    case SERIES_CONTACT: return &s->energy.contact;
    case SERIES_FRICTION: return &s->energy.friction;
    case SERIES_JOINT: return &s->energy.joint;
    case SERIES_FRACTURE: return &s->energy.fracture;
    case SERIES_DAMPING: return &s->energy.damping;
    case SERIES_GRAVITY_WORK: return &s->energy.gravity_work;
    case SERIES_EXTERNAL_WORK: return &s->energy.external_work;
    case SERIES_FLUID_PRESSURE: return s->fluid_pressure;
    case SERIES_APERTURE: return s->aperture;
    case SERIES_TIME: return &s->time;
    }
    return NULL;
}

static hsize_t series_row_elements(const series *s)
{
    hsize_t n = 1;
    for (int d = 1; d < s->rank; d++) n *= s->row[d - 1];
    return n;
}

/* Extends the dataset to `length` rows and writes `data` as row length-1. */
static int series_write_row(const series *s, int kind, hsize_t length, const void *data)
{
    hsize_t dims[3] = {length, s->row[0], s->row[1]};
    if (H5Dset_extent(s->id, dims) < 0) return -1;
    if (series_row_elements(s) == 0) return 0; /* (S, 0, dim): nothing to write */
    hsize_t start[3] = {length - 1, 0, 0};
    hsize_t count[3] = {1, s->row[0], s->row[1]};
    hid_t file_space = H5Dget_space(s->id);
    hid_t mem_space = H5Screate_simple(s->rank, count, NULL);
    int rc = -1;
    if (file_space >= 0 && mem_space >= 0 &&
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
        H5Dwrite(s->id, series_mem_type(kind), mem_space, file_space, H5P_DEFAULT, data) >= 0)
        rc = 0;
    if (mem_space >= 0) H5Sclose(mem_space);
    if (file_space >= 0) H5Sclose(file_space);
    return rc;
}

static int create_snapshot_series(result_file *f, char *err, size_t errlen)
{
    hid_t group = H5Gcreate2(f->file, "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (group < 0) {
        result_fail(err, errlen, "cannot create group /snapshots");
        return -1;
    }
    int rc = 0;
    for (int k = 0; k < SERIES_COUNT && rc == 0; k++)
        if (series_create(group, k, &f->ds[k]) < 0) {
            result_fail(err, errlen, "cannot create /snapshots/%s", series_names[k]);
            rc = -1;
        }
    const series *principal = &f->ds[SERIES_PRINCIPAL_STRESS];
    if (rc == 0 && principal->rank &&
        result_describe_principal_stress(principal->id, (int)principal->row[1]) < 0) {
        result_fail(err, errlen, "cannot describe /snapshots/principal_stress");
        rc = -1;
    }
    H5Gclose(group);
    return rc;
}

/* ------------------------------------------------------------ file handles */

/* Latest format: required for SWMR, and its extensible-array chunk index
 * makes appending one row cheap. */
hid_t file_access_latest(int clear_status_flags)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl < 0) return fapl;
    if (H5Pset_libver_bounds(fapl, H5F_LIBVER_LATEST, H5F_LIBVER_LATEST) < 0) goto fail;
    if (clear_status_flags) {
        /* The property h5clear sets; it bypasses the "already open for
         * writing" check that a crashed writer leaves behind. */
        bool clear = true;
        if (H5Pset(fapl, "clear_status_flags", &clear) < 0) goto fail;
    }
    return fapl;
fail:
    H5Pclose(fapl);
    return H5I_INVALID_HID;
}

/* A reopened file grows when HDF5 closes it, and a close that cannot write
 * leaves the file flagged as open for writing, which h5py and every other
 * reader then refuse. So the room is allocated on disk first, past the end
 * of the file: a full disk fails here, with the file untouched. HDF5 puts
 * what it adds at its own end of allocation, inside that room, and trims
 * the file back to that end when it closes. */
int result_reserve_room(const char *path, off_t bytes, const char *what, char *err, size_t errlen)
{
    int fd = open(path, O_WRONLY | O_CLOEXEC);
    struct stat st;
    int rc = fd < 0 || fstat(fd, &st) != 0 ? errno : posix_fallocate(fd, st.st_size, bytes);
    if (fd >= 0) close(fd);
    if (rc != 0) {
        snprintf(err, errlen, "cannot reserve %lld bytes in %s to %s: %s", (long long)bytes, path,
                 what, strerror(rc));
        return -1;
    }
    return 0;
}

result_file *result_alloc(void)
{
    result_file *f = calloc(1, sizeof *f);
    if (!f) return NULL;
    f->file = H5I_INVALID_HID;
    for (int k = 0; k < SERIES_COUNT; k++) f->ds[k].id = H5I_INVALID_HID;
    for (int k = 0; k < EVENT_SERIES; k++) f->events[k] = H5I_INVALID_HID;
    for (int k = 0; k < HISTORY_SERIES; k++) f->history[k] = H5I_INVALID_HID;
    return f;
}

/* Closes every handle; returns -1 if HDF5 reported a failure. */
int result_close_handles(result_file *f)
{
    int rc = 0;
    for (int k = 0; k < SERIES_COUNT; k++)
        if (f->ds[k].id >= 0) {
            if (H5Dclose(f->ds[k].id) < 0) rc = -1;
            f->ds[k].id = H5I_INVALID_HID;
        }
    for (int k = 0; k < EVENT_SERIES; k++)
        if (f->events[k] >= 0) {
            if (H5Dclose(f->events[k]) < 0) rc = -1;
            f->events[k] = H5I_INVALID_HID;
        }
    if (history_close_handles(f) < 0) rc = -1;
    if (f->file >= 0 && H5Fclose(f->file) < 0) rc = -1;
    f->file = H5I_INVALID_HID;
    return rc;
}

int result_release(result_file *f)
{
    int rc = result_close_handles(f);
    free(f->times);
    free(f);
    return rc;
}

static int times_push(result_file *f, double t)
{
    if (f->count >= f->times_capacity) {
        int capacity = f->times_capacity ? 2 * f->times_capacity : 64;
        double *grown = realloc(f->times, (size_t)capacity * sizeof *grown);
        if (!grown) return -1;
        f->times = grown;
        f->times_capacity = capacity;
    }
    f->times[f->count] = t;
    return 0;
}

int start_swmr(result_file *f, const char *path, char *err, size_t errlen)
{
    if (H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0 || H5Fstart_swmr_write(f->file) < 0) {
        result_fail(err, errlen, "cannot start SWMR writing of %s", path);
        return -1;
    }
    return 0;
}

result_file *result_create(const char *path, const fdem_model *model,
                           const case_info *info, char *err, size_t errlen)
{
    return result_create_described(path, model, info, NULL, 0, err, errlen);
}

result_file *result_create_described(const char *path, const fdem_model *model,
                                     const case_info *info, const char *document,
                                     size_t document_length, char *err, size_t errlen)
{
    h5_quiet();
    if (!path || !model || !info) {
        snprintf(err, errlen, "result_create: missing path, model or case info");
        return NULL;
    }
    result_file *f = result_alloc();
    if (!f) {
        snprintf(err, errlen, "out of memory creating %s", path);
        return NULL;
    }
    hid_t fapl = file_access_latest(0);
    if (fapl >= 0) {
        f->file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
        H5Pclose(fapl);
    }
    if (f->file < 0) {
        result_fail(err, errlen, "cannot create result file %s", path);
        goto fail;
    }
    if (write_root_attributes(f->file, info, fdem_get_dimension(model), fdem_get_dt(model)) < 0) {
        result_fail(err, errlen, "cannot write the root attributes of %s", path);
        goto fail;
    }
    if (write_mesh(f->file, model, err, errlen) < 0) goto fail;
    if (result_describe(f->file, document, document_length, info, err, errlen) < 0) goto fail;
    series_layout(f->ds, model, info->fields);
    if (create_snapshot_series(f, err, errlen) < 0) goto fail;
    if (events_create(f, fdem_get_dimension(model), err, errlen) < 0) goto fail;
    if (history_create(f, model, info, err, errlen) < 0) goto fail;
    if (start_swmr(f, path, err, errlen) < 0) goto fail;
    return f;
fail:
    result_release(f);
    return NULL;
}

/* The snapshot must have the model's shape and every row the file stores. */
static int check_snapshot(const result_file *f, const snapshot *s, char *err, size_t errlen)
{
    const series *pos = &f->ds[SERIES_POSITION], *str = &f->ds[SERIES_STRESS];
    const series *dmg = &f->ds[SERIES_DAMAGE], *cf = &f->ds[SERIES_CONSTRAINT_FORCE];
    const series *vel = &f->ds[SERIES_VELOCITY], *dis = &f->ds[SERIES_DISPLACEMENT];
    hsize_t nodes = pos->rank ? pos->row[0] : vel->rank ? vel->row[0] : dis->row[0];
    if ((pos->rank || vel->rank || dis->rank) && (hsize_t)s->nodes != nodes) {
        snprintf(err, errlen, "snapshot has %d nodes, the result file %llu", s->nodes,
                 (unsigned long long)nodes);
        return -1;
    }
    if (str->rank && (hsize_t)s->elements != str->row[0]) {
        snprintf(err, errlen, "snapshot has %d elements, the result file %llu", s->elements,
                 (unsigned long long)str->row[0]);
        return -1;
    }
    if ((hsize_t)s->joints != (dmg->rank ? dmg->row[0] : 0)) {
        snprintf(err, errlen, "snapshot has %d joints, the result file %llu", s->joints,
                 (unsigned long long)(dmg->rank ? dmg->row[0] : 0));
        return -1;
    }
    if ((hsize_t)s->constraints != cf->row[0]) {
        snprintf(err, errlen, "snapshot has %d constraints, the result file %llu",
                 s->constraints, (unsigned long long)cf->row[0]);
        return -1;
    }
    for (int k = 0; k < SERIES_COUNT; k++)
        if (f->ds[k].id >= 0 && series_row_elements(&f->ds[k]) > 0 && !series_row_data(k, s)) {
            snprintf(err, errlen, "snapshot at step %lld has no %s, which the result file stores",
                     (long long)s->step, series_names[k]);
            return -1;
        }
    return 0;
}

int result_append(result_file *f, const snapshot *s, char *err, size_t errlen)
{
    h5_quiet();
    if (!f || !s) {
        snprintf(err, errlen, "result_append: no file or no snapshot");
        return -1;
    }
    if (check_snapshot(f, s, err, errlen) < 0) return -1;
    hsize_t length = (hsize_t)f->count + 1;
    for (int k = 0; k < SERIES_TIME; k++) {
        if (f->ds[k].id < 0) continue;
        if (series_write_row(&f->ds[k], k, length, series_row_data(k, s)) < 0) {
            result_fail(err, errlen, "cannot append snapshot %d to /snapshots/%s", f->count,
                        series_names[k]);
            return -1;
        }
    }
    /* Every other row is on disk before time, the commit marker, grows. */
    if (H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0 ||
        series_write_row(&f->ds[SERIES_TIME], SERIES_TIME, length, &s->time) < 0 ||
        H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0) {
        result_fail(err, errlen, "cannot commit snapshot %d (step %lld)", f->count,
                    (long long)s->step);
        return -1;
    }
    if (times_push(f, s->time) < 0) {
        snprintf(err, errlen, "out of memory recording snapshot %d", f->count);
        return -1;
    }
    f->count++;
    return 0;
}

int result_snapshot_count(const result_file *f)
{
    return f ? f->count : 0;
}

double result_snapshot_time(const result_file *f, int index)
{
    if (!f || index < 0 || index >= f->count) return NAN;
    return f->times[index];
}

int result_close(result_file *f)
{
    if (!f) return 0;
    h5_quiet();
    int rc = 0;
    if (f->file >= 0 && H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0) rc = -1;
    if (result_release(f) < 0) rc = -1;
    H5Eclear2(H5E_DEFAULT);
    return rc;
}
/* ----------------------------------------------------------- downloads */

int result_flush(result_file *f, char *err, size_t errlen)
{
    h5_quiet();
    if (!f || H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0) {
        result_fail(err, errlen, "cannot flush the result file");
        return -1;
    }
    return 0;
}
