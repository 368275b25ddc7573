/*
 * result_frame.c - one snapshot of result.h5 as the web page's binary frame
 * (GET /cases/ID/mesh.bin, docs/api.md "Binary mesh frames").
 *
 * The page draws a 1e5-element mesh at every snapshot; as JSON that is tens
 * of MB of text and seconds of parsing, so it gets the mesh, the deformed
 * positions and the fields it colours by as little-endian float32 arrays
 * (u32 for node indices) behind a fixed header, which a browser maps with
 * typed arrays and no parsing. HDF5 converts to float32 as it reads, so no
 * float64 copy of a field is ever held.
 *
 * Reads the open file of a running case (its handle, between two appends:
 * only the I/O thread calls this) or the closed file on disk.
 */
#include "result_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FRAME_MAGIC "FDEMMESH"
#define FRAME_VERSION 1u
#define FRAME_HEADER_BYTES 64u
#define FRAME_FIELD_HEADER_BYTES 24u
#define FRAME_NAME_BYTES 16u

const char *const result_frame_field_names[RESULT_FRAME_FIELDS] = {
    "velocity", "displacement", "stress", "strain", "principal_stress", "damage", "fragment",
    "active",
};

/* The /snapshots series of each frame field, in result_frame_field_names order. */
static const int frame_series[RESULT_FRAME_FIELDS] = {
    SERIES_VELOCITY, SERIES_DISPLACEMENT, SERIES_STRESS, SERIES_STRAIN,
    SERIES_PRINCIPAL_STRESS, SERIES_DAMAGE, SERIES_FRAGMENT, SERIES_ACTIVE,
};

/* Where a field lives: the header's location codes. */
enum { FRAME_AT_NODE = 0, FRAME_AT_ELEMENT = 1, FRAME_AT_JOINT = 2 };

typedef struct frame_array {
    hid_t ds;      /* open dataset, or H5I_INVALID_HID */
    hsize_t items; /* rows (mesh) or items per snapshot (snapshots) */
    hsize_t width; /* components per item */
} frame_array;

typedef struct frame_source {
    hid_t file;
    int dimension, snapshots;
    frame_array cells, joints, position0, position, field[RESULT_FRAME_FIELDS];
} frame_source;

/* ------------------------------------------------------------- datasets */

/* Opens `name` if the file has it and reads its shape: a /mesh array is
 * (items, width) or (items); a /snapshots series (S, items, width),
 * (S, items) or (S) (one item). Missing is not an error. */
static void frame_open(hid_t file, const char *name, int per_snapshot, frame_array *a)
{
    a->ds = H5I_INVALID_HID;
    a->items = a->width = 0;
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0)
        return;
    a->ds = H5Dopen2(file, name, H5P_DEFAULT);
    if (a->ds < 0)
        return;
    hsize_t dims[3] = {0, 0, 0};
    hid_t space = H5Dget_space(a->ds);
    int rank = space >= 0 ? H5Sget_simple_extent_dims(space, dims, NULL) : -1;
    if (space >= 0)
        H5Sclose(space);
    int base = per_snapshot ? 1 : 0;
    if (rank < 1 || rank > base + 2) {
        H5Dclose(a->ds);
        a->ds = H5I_INVALID_HID;
        return;
    }
    a->items = rank > base ? dims[base] : 1;
    a->width = rank == base + 2 ? dims[base + 1] : 1;
}

static void frame_close(frame_array *a)
{
    if (a->ds >= 0)
        H5Dclose(a->ds);
    a->ds = H5I_INVALID_HID;
}

/* Reads row `index` of a /snapshots series (or the whole of a /mesh array
 * when index < 0) converted to `type` into dst. */
static int frame_read(const frame_array *a, int index, hid_t type, void *dst)
{
    hsize_t count = a->items * a->width;
    if (count == 0)
        return 0;
    hid_t file_space = H5Dget_space(a->ds);
    hid_t mem_space = H5Screate_simple(1, &count, NULL);
    int ok = file_space >= 0 && mem_space >= 0;
    if (ok && index >= 0) {
        hsize_t start[3] = {(hsize_t)index, 0, 0}, rows[3] = {1, a->items, a->width};
        ok = H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, NULL, rows, NULL) >= 0;
    }
    ok = ok && H5Dread(a->ds, type, mem_space, file_space, H5P_DEFAULT, dst) >= 0;
    if (mem_space >= 0) H5Sclose(mem_space);
    if (file_space >= 0) H5Sclose(file_space);
    return ok ? 0 : -1;
}

static int frame_read_scalar(hid_t file, const char *name, int index, hid_t type, void *dst)
{
    frame_array a;
    frame_open(file, name, 1, &a);
    if (a.ds < 0)
        return -1;
    a.items = a.width = 1;
    int rc = frame_read(&a, index, type, dst);
    frame_close(&a);
    return rc;
}

/* ----------------------------------------------------------- the source */

static void frame_source_close(frame_source *s)
{
    frame_close(&s->cells);
    frame_close(&s->joints);
    frame_close(&s->position0);
    frame_close(&s->position);
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
        frame_close(&s->field[k]);
}

/* Opens what the frame reads; `wanted` bit k asks for field k. */
static int frame_source_open(frame_source *s, hid_t file, const result_file *f, unsigned wanted,
                             char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    s->file = file;
    frame_open(file, "/mesh/position0", 0, &s->position0);
    s->dimension = (int)s->position0.width;
    frame_open(file, s->dimension == 3 ? "/mesh/tetrahedra" : "/mesh/triangles", 0, &s->cells);
    frame_open(file, "/mesh/joints", 0, &s->joints);
    frame_open(file, "/snapshots/position", 1, &s->position);
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++) {
        char name[64];
        snprintf(name, sizeof name, "/snapshots/%s", series_names[frame_series[k]]);
        if (wanted & (1u << k))
            frame_open(file, name, 1, &s->field[k]);
        else
            s->field[k].ds = H5I_INVALID_HID;
    }
    frame_array time;
    frame_open(file, "/snapshots/time", 1, &time);
    hsize_t stored = 0;
    if (time.ds >= 0) {
        hsize_t dims[1] = {0};
        hid_t space = H5Dget_space(time.ds);
        H5Sget_simple_extent_dims(space, dims, NULL);
        H5Sclose(space);
        stored = dims[0];
    }
    frame_close(&time);
    s->snapshots = f ? f->count : (int)stored;
    if (s->position0.ds < 0 || s->cells.ds < 0 || (s->dimension != 2 && s->dimension != 3) ||
        s->cells.width != (hsize_t)s->dimension + 1) {
        snprintf(err, errlen, "the result file has no readable /mesh");
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ the bytes */

static void put_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static void put_u64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

/* The arrays are written in the host's order: the frame is little-endian,
 * which every machine fdemd builds on is (checked at compile time). */
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "result_frame.c writes float32 arrays as the host stores them: little-endian only"
#endif

static int frame_location(int k)
{
    int kind = frame_series[k];
    if (kind == SERIES_VELOCITY || kind == SERIES_DISPLACEMENT)
        return FRAME_AT_NODE;
    return kind == SERIES_DAMAGE ? FRAME_AT_JOINT : FRAME_AT_ELEMENT;
}

static size_t frame_bytes(const frame_source *s)
{
    size_t n = FRAME_HEADER_BYTES;
    n += 4 * (size_t)(s->cells.items * s->cells.width);
    n += 4 * (size_t)(s->joints.ds >= 0 ? s->joints.items * s->joints.width : 0);
    n += 2 * 4 * (size_t)(s->position0.items * s->position0.width);
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
        if (s->field[k].ds >= 0)
            n += FRAME_FIELD_HEADER_BYTES + 4 * (size_t)(s->field[k].items * s->field[k].width);
    return n;
}

/* The deformed positions: /snapshots/position, else position0 plus
 * /snapshots/displacement, else position0 (header flag 0). */
static int frame_positions(const frame_source *s, int index, float *x0, float *x, int *deformed)
{
    size_t n = (size_t)(s->position0.items * s->position0.width);
    if (frame_read(&s->position0, -1, H5T_NATIVE_FLOAT, x0) != 0)
        return -1;
    const frame_array *disp = &s->field[1];
    frame_array own_disp = {H5I_INVALID_HID, 0, 0};
    if (s->position.ds >= 0 && s->position.items * s->position.width == n) {
        *deformed = 1;
        return frame_read(&s->position, index, H5T_NATIVE_FLOAT, x);
    }
    if (disp->ds < 0) {
        frame_open(s->file, "/snapshots/displacement", 1, &own_disp);
        disp = &own_disp;
    }
    int rc = 0;
    *deformed = disp->ds >= 0 && disp->items * disp->width == n;
    if (*deformed) {
        rc = frame_read(disp, index, H5T_NATIVE_FLOAT, x);
        for (size_t i = 0; rc == 0 && i < n; i++)
            x[i] += x0[i];
    } else {
        memcpy(x, x0, n * sizeof *x);
    }
    frame_close(&own_disp);
    return rc;
}

static int frame_fill(const frame_source *s, int index, unsigned char *buf, char *err,
                      size_t errlen)
{
    double time = NAN;
    int64_t step = 0;
    if (frame_read_scalar(s->file, "/snapshots/time", index, H5T_NATIVE_DOUBLE, &time) != 0 ||
        frame_read_scalar(s->file, "/snapshots/step", index, H5T_NATIVE_INT64, &step) != 0) {
        result_fail(err, errlen, "cannot read the time of snapshot %d", index);
        return -1;
    }
    int fields = 0;
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
        fields += s->field[k].ds >= 0;
    unsigned char *p = buf + FRAME_HEADER_BYTES;
    uint32_t joints = s->joints.ds >= 0 ? (uint32_t)s->joints.items : 0;
    int ok = frame_read(&s->cells, -1, H5T_NATIVE_UINT32, p) == 0;
    p += 4 * s->cells.items * s->cells.width;
    if (ok && joints)
        ok = frame_read(&s->joints, -1, H5T_NATIVE_UINT32, p) == 0;
    p += 4 * (size_t)joints * (size_t)s->joints.width;
    float *x0 = (float *)(void *)p;
    p += 4 * s->position0.items * s->position0.width;
    int deformed = 0;
    ok = ok && frame_positions(s, index, x0, (float *)(void *)p, &deformed) == 0;
    p += 4 * s->position0.items * s->position0.width;
    for (int k = 0; ok && k < RESULT_FRAME_FIELDS; k++) {
        const frame_array *a = &s->field[k];
        if (a->ds < 0)
            continue;
        memset(p, 0, FRAME_FIELD_HEADER_BYTES);
        memcpy(p, result_frame_field_names[k], strlen(result_frame_field_names[k]));
        put_u32(p + FRAME_NAME_BYTES, (uint32_t)frame_location(k));
        put_u32(p + FRAME_NAME_BYTES + 4, (uint32_t)a->width);
        p += FRAME_FIELD_HEADER_BYTES;
        ok = frame_read(a, index, H5T_NATIVE_FLOAT, p) == 0;
        p += 4 * a->items * a->width;
    }
    if (!ok) {
        result_fail(err, errlen, "cannot read snapshot %d of the result file", index);
        return -1;
    }
    memcpy(buf, FRAME_MAGIC, 8);
    put_u32(buf + 8, FRAME_VERSION);
    put_u32(buf + 12, (uint32_t)s->dimension);
    put_u32(buf + 16, (uint32_t)s->position0.items);
    put_u32(buf + 20, (uint32_t)s->cells.items);
    put_u32(buf + 24, joints);
    put_u32(buf + 28, (uint32_t)index);
    put_u32(buf + 32, (uint32_t)s->snapshots);
    put_u32(buf + 36, (uint32_t)fields);
    uint64_t time_bits;
    memcpy(&time_bits, &time, sizeof time_bits);
    put_u64(buf + 40, time_bits);
    put_u64(buf + 48, (uint64_t)step);
    put_u32(buf + 56, (uint32_t)deformed);
    put_u32(buf + 60, 0);
    return 0;
}

/* ------------------------------------------------------------ the entry */

static int frame_build(hid_t file, const result_file *f, const result_frame_request *q,
                       unsigned char **out, size_t *size, char *err, size_t errlen)
{
    frame_source s;
    int rc = frame_source_open(&s, file, f, q->fields, err, errlen);
    int index = q->snapshot < 0 ? s.snapshots - 1 : q->snapshot;
    if (rc == 0 && (index < 0 || index >= s.snapshots)) {
        snprintf(err, errlen, "the case has %d snapshots (0 to %d); there is no snapshot %d",
                 s.snapshots, s.snapshots - 1, q->snapshot);
        rc = 404;
    }
    size_t bytes = rc == 0 ? frame_bytes(&s) : 0;
    if (rc == 0 && q->reserve && q->reserve(q->reserve_ctx, bytes) != 0) {
        snprintf(err, errlen, "a frame of %zu bytes would take the daemon past its memory budget",
                 bytes);
        rc = 503;
    }
    unsigned char *buf = rc == 0 ? malloc(bytes) : NULL;
    if (rc == 0 && !buf) {
        snprintf(err, errlen, "out of memory for a frame of %zu bytes", bytes);
        rc = 503;
    }
    if (rc == 0 && frame_fill(&s, index, buf, err, errlen) != 0)
        rc = -1;
    frame_source_close(&s);
    if (rc != 0) {
        free(buf);
        return rc;
    }
    *out = buf;
    *size = bytes;
    return 0;
}

int result_read_frame(result_file *f, const char *path, const result_frame_request *q,
                      unsigned char **out, size_t *size, char *err, size_t errlen)
{
    h5_quiet();
    *out = NULL;
    *size = 0;
    if (err && errlen) err[0] = '\0';
    if (f)
        return frame_build(f->file, f, q, out, size, err, errlen);
    hid_t file = result_open_read(path);
    if (file < 0) {
        result_fail(err, errlen, "cannot open %s to read a snapshot", path);
        return -1;
    }
    int rc = frame_build(file, NULL, q, out, size, err, errlen);
    H5Fclose(file);
    return rc;
}
